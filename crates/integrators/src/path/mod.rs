//! The reference estimator: unidirectional path tracing with next-event estimation and BSDF
//! sampling combined by multiple importance sampling (power heuristic, Veach 1997 §9.2), and
//! Russian roulette. Depth semantics follow Mitsuba 3's `path` integrator: `max_depth` counts
//! path segments from the camera (1 = directly visible emitters, 2 = direct lighting, -1 =
//! unbounded); Russian roulette starts once `depth ≥ rr_depth` with survival probability
//! `min(max(β)·η², 0.95)`.
//!
//! This file is the walk one path at a time ([`trace_path`]); the integrator's passes run it
//! eight paths at a time in SIMD lanes (`lanes.rs`), every lane giving this walk's bits.

use glam::{DVec3, Vec2, Vec3};
use restir_geometry::{Ray, SurfaceInteraction, offset_ray_origin};
use restir_lights::{LightSet, NeeSelection};
use restir_sampling::Sampler;
use restir_sampling::warp::{power_heuristic, power_share};
use restir_scene::{IntegratorDesc, SamplerKind, Scene, SceneFeatures};

use crate::bands::Bands;
use crate::params::{Param, ParamError};
use crate::pass::{Integrator, PassContext};
use crate::shadow::{ShadowTarget, visible};

mod lanes;

/// Path tracer settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSettings {
    /// Longest path in segments; -1 is unbounded.
    pub max_depth: i32,
    /// Depth at which Russian roulette starts.
    pub rr_depth: u32,
    /// Hide directly visible emitters.
    pub hide_emitters: bool,
    /// Where the path tracer's numbers come from (ReSTIR DI and PT draw independent ones).
    pub sampler: SamplerKind,
    /// How next-event estimation picks its light (the path tracer's and ReSTIR PT's walks;
    /// `--light-sampler`).
    pub nee: NeeSelection,
    /// Whether `nee` was named or is decided from the scene ([`PathSettings::resolve_nee`]).
    pub nee_rule: NeeRule,
}

/// Where next-event estimation's light selection comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NeeRule {
    /// Named (`light_sampler = power | bvh`).
    Named,
    /// `light_sampler = auto` (the default), not decided yet: [`PathSettings::resolve_nee`]
    /// decides it from the scene.
    Auto,
    /// Decided from the scene's local lights and the emitters they hold ([`auto_nee`]).
    Decided {
        /// Lights besides the environment.
        lights: usize,
        /// Entries of the emitter table (emissive triangles, other lights with power).
        emitters: usize,
        /// The entries the typical local light holds (the lower median).
        median: usize,
    },
}

/// `light_sampler = auto` takes the light hierarchy when the scene has at least two local
/// lights and at least half of them hold at most this many emitters (rectangles of two
/// triangles, spheres, points, spots), and the power sampler otherwise (one light; lamps
/// tessellated into many triangles). Chosen on the DI training family at 640×360 (the path tracer, direct
/// light, 16 passes, seeds 11 and 12, 1 thread): with the hierarchy, the seven members of
/// rectangles and spheres (1–2 emitters a light, 10³–10⁵ lights) are 1.16–1.75× as efficient,
/// the five of emissive meshes and garlands (110–12 500 triangles a light) 0.44–1.33×, and
/// 0.51–0.91× in squared error (`docs/RESTIR_PT.md`, "Next-event estimation's light
/// selection").
pub const AUTO_NEE_MAX_EMITTERS_PER_LIGHT: usize = 2;

/// Next-event estimation's light selection for a scene of `lights` local lights (the
/// environment aside), the typical one holding `median` emitter-table entries (the lower
/// median over the lights): see [`AUTO_NEE_MAX_EMITTERS_PER_LIGHT`].
pub fn auto_nee(lights: usize, median: usize) -> NeeSelection {
    if lights >= 2 && median <= AUTO_NEE_MAX_EMITTERS_PER_LIGHT {
        NeeSelection::Hierarchy
    } else {
        NeeSelection::Power
    }
}

/// The names `light_sampler` takes for next-event estimation (`None`: decided from the scene).
const NEE_NAMES: &[(&str, Option<NeeSelection>)] = &[
    ("auto", None),
    ("power", Some(NeeSelection::Power)),
    ("bvh", Some(NeeSelection::Hierarchy)),
    ("hierarchy", Some(NeeSelection::Hierarchy)),
];

impl PathSettings {
    /// Settings from a scene's integrator description.
    pub fn from_desc(desc: &IntegratorDesc) -> Self {
        Self {
            max_depth: desc.max_depth,
            rr_depth: desc.rr_depth.max(1),
            hide_emitters: desc.hide_emitters,
            sampler: desc.sampler,
            nee: NeeSelection::Power,
            nee_rule: NeeRule::Auto,
        }
    }

    /// One parameter of the path tracer's (`light_sampler`: next-event estimation's light
    /// selection); whether `key` is one.
    pub fn apply_one(&mut self, key: &str, p: &Param) -> Result<bool, ParamError> {
        match key {
            "light_sampler" => {
                match p.choice(NEE_NAMES, "power, bvh or auto")? {
                    Some(nee) => {
                        self.nee = nee;
                        self.nee_rule = NeeRule::Named;
                    }
                    None => self.nee_rule = NeeRule::Auto,
                }
                Ok(true)
            }
            _ => Ok(false),
        }
    }

    /// Decides next-event estimation's light selection for the scene `features` describes,
    /// unless it was named ([`auto_nee`]).
    pub fn resolve_nee(&mut self, features: &SceneFeatures) {
        if self.nee_rule == NeeRule::Named {
            return;
        }
        let lights = features
            .light_count
            .saturating_sub(usize::from(features.has_environment));
        let (emitters, median) = (features.emitter_count, features.median_light_emitters);
        self.nee = auto_nee(lights, median);
        self.nee_rule = NeeRule::Decided {
            lights,
            emitters,
            median,
        };
    }

    /// These settings with next-event estimation decided for the scene `features` describes
    /// when it is still `auto` (estimators made without [`PathSettings::resolve_nee`], as a
    /// library may make them, decide it when they render).
    pub fn resolved(mut self, features: &SceneFeatures) -> Self {
        if self.nee_rule == NeeRule::Auto {
            self.resolve_nee(features);
        }
        self
    }

    /// `light_sampler=NAME`, with what decided it when `auto` did, for settings lines.
    pub fn nee_label(&self) -> String {
        match self.nee_rule {
            NeeRule::Named => format!("light_sampler={}", self.nee.name()),
            NeeRule::Auto => "light_sampler=auto".to_string(),
            NeeRule::Decided {
                lights,
                emitters,
                median,
            } => format!(
                "light_sampler={} (auto: {emitters} emitter{} in {lights} local light{}{})",
                self.nee.name(),
                if emitters == 1 { "" } else { "s" },
                if lights == 1 { "" } else { "s" },
                if lights >= 2 {
                    format!("; the median light {median}")
                } else {
                    String::new()
                }
            ),
        }
    }

    /// The longest path in segments, `u32::MAX` for unbounded (`max_depth = -1`).
    #[inline]
    pub fn max_segments(&self) -> u32 {
        u32::try_from(self.max_depth).unwrap_or(u32::MAX)
    }
}

/// Random numbers each bounce consumes, whatever happens at it: light selection (1), point on the
/// light (2), BSDF lobe (1), BSDF direction (2), Russian roulette (1). A fixed budget keeps the
/// numbers of bounce `k` at a known offset in the stream, so paths can be replayed. The light
/// hierarchy's descent takes the low bits of its selection number from the roulette's number
/// ([`LightSet::sample_nee`]): the two decisions are correlated, each alone uniform, so every
/// term keeps its expectation.
pub const RANDOMS_PER_BOUNCE: usize = 7;

/// The state a path carries from a surface to the next one, enough to weight an emitter the
/// continuation ray hits by MIS.
#[derive(Clone, Copy, Debug)]
pub struct PrevVertex {
    /// Position of the scattering vertex.
    pub p: Vec3,
    /// Its shading normal, as next-event estimation there saw it ([`LightSet::pdf_nee`]).
    pub n: Vec3,
    /// Solid-angle pdf of the sampled direction.
    pub pdf_sa: f32,
    /// Whether the sampled lobe was a delta lobe (no light sampling could have produced it).
    pub delta: bool,
    /// How the direct light at this vertex was split between light and BSDF sampling.
    pub mis: EmissionMis,
}

/// The MIS weight an emitter reached by BSDF sampling gets, against the light-sampling strategy
/// that also covered it at the previous vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EmissionMis {
    /// One light sample and one BSDF sample, power heuristic (the path tracer).
    Power,
    /// `light_samples` light-strategy samples and `bsdf_samples` BSDF samples combined by the
    /// power heuristic with sample counts ([`power_share`]); this continuation is one of the
    /// BSDF samples (or, with `bsdf_samples = 0`, an indirect-only continuation whose direct
    /// emission counts zero). ReSTIR DI uses it: its reservoirs cover the light strategy's share.
    Counted {
        /// Light-strategy sample count `N_L`.
        light_samples: f32,
        /// BSDF sample count `N_B`.
        bsdf_samples: f32,
    },
}

impl PrevVertex {
    /// The density with which light sampling at this vertex would have produced the point `p`
    /// (normal `n`) of `light`'s primitive `prim`: next-event estimation's selection `nee` for
    /// [`EmissionMis::Power`], the power sampler's for [`EmissionMis::Counted`] (ReSTIR DI's
    /// light strategy weighs by it, whatever drew its candidates).
    #[inline]
    pub fn light_pdf(
        &self,
        lights: &LightSet,
        nee: NeeSelection,
        light: (u32, u32),
        p: Vec3,
        n: Vec3,
    ) -> f32 {
        let how = match self.mis {
            EmissionMis::Power => nee,
            EmissionMis::Counted { .. } => NeeSelection::Power,
        };
        lights.pdf_nee(how, light, self.p, self.n, p, n)
    }

    /// The weight of emission reached from this vertex, whose light-sampling density (solid
    /// angle, selection included) is `light_pdf_sa`. Emission behind a delta lobe gets 1.
    #[inline]
    pub fn emission_weight(&self, light_pdf_sa: f32) -> f32 {
        if self.delta {
            return 1.0;
        }
        match self.mis {
            EmissionMis::Power => power_heuristic(self.pdf_sa, light_pdf_sa),
            EmissionMis::Counted {
                light_samples,
                bsdf_samples,
            } => bsdf_sample_share(self.pdf_sa, bsdf_samples, light_pdf_sa, light_samples),
        }
    }
}

/// The MIS weight of emission from the point `p` (geometric normal `ng`) of primitive `prim` of
/// area light `light`, reached from `prev` (`None`: a camera ray; behind a delta lobe: 1).
#[inline]
pub(crate) fn emission_mis(
    prev: Option<PrevVertex>,
    lights: &LightSet,
    nee: NeeSelection,
    light: (u32, u32),
    p: Vec3,
    ng: Vec3,
) -> f32 {
    match prev {
        Some(pv) if !pv.delta => pv.emission_weight(pv.light_pdf(lights, nee, light, p, ng)),
        _ => 1.0,
    }
}

/// The MIS weight of the environment's emission along the unit direction `d` from `prev`
/// (`None`: a camera ray; behind a delta lobe: 1). The scene must have an environment.
#[inline]
pub(crate) fn environment_mis(
    prev: Option<PrevVertex>,
    lights: &LightSet,
    nee: NeeSelection,
    d: Vec3,
) -> f32 {
    match prev {
        Some(pv) if !pv.delta => {
            let env = lights
                .environment()
                .expect("feature summary says there is one");
            pv.emission_weight(pv.light_pdf(lights, nee, (env, 0), pv.p + d, -d))
        }
        _ => 1.0,
    }
}

/// The weight `m_B / N_b` of one of `N_b` BSDF samples of density `p_b` against `N_l` light
/// samples of density `p_l`, `m_B` their power-heuristic share ([`power_share`]): the sample
/// contributes `f·L_e·m_B / (N_b·p_b)` (0 when there are no BSDF samples).
#[inline]
pub fn bsdf_sample_share(
    bsdf_pdf: f32,
    bsdf_samples: f32,
    light_pdf: f32,
    light_samples: f32,
) -> f32 {
    if !(bsdf_samples > 0.0 && bsdf_pdf > 0.0) {
        return 0.0;
    }
    power_share(bsdf_samples * bsdf_pdf, light_samples * light_pdf) / bsdf_samples
}

/// Russian roulette's survival probability after a bounce: the largest channel of the
/// throughput `beta_max` times the squared product of the relative indices of refraction crossed
/// (radiance scales with it through a refraction, so glass does not end paths early), at most
/// 0.95. Every estimator's walks use it.
#[inline]
pub fn rr_survival(beta_max: f32, eta_scale: f32) -> f32 {
    (beta_max * eta_scale * eta_scale).min(0.95)
}

/// Radiance arriving along `ray` (a camera ray, or a continuation from `prev`), estimated with one
/// path. `depth` is the number of segments already traced before `ray`. Returns the estimate and
/// the number of rays traced.
pub fn trace_path<S: Sampler>(
    scene: &Scene,
    settings: &PathSettings,
    ray: Ray,
    depth: u32,
    beta: Vec3,
    prev: Option<PrevVertex>,
    rng: &mut S,
) -> (Vec3, u64) {
    let max_depth = settings.max_segments();
    if depth >= max_depth {
        return (Vec3::ZERO, 0);
    }
    let lights = &scene.lights;
    let has_env = scene.features.has_environment;
    let mut w = Walk {
        ray,
        depth,
        beta,
        eta_scale: 1.0,
        prev,
        radiance: Vec3::ZERO,
        rays: 0,
    };
    loop {
        // With hidden emitters the camera sees through area lights (as in Mitsuba 3).
        let hide = w.depth == 0 && settings.hide_emitters;
        let (hit, n) = scene.camera_intersect(&w.ray, hide);
        w.rays += n;
        let Some(si) = hit else {
            if has_env && !hide {
                let le = lights.environment_radiance(w.ray.d);
                w.radiance += w.beta * le * environment_mis(w.prev, lights, settings.nee, w.ray.d);
            }
            break;
        };

        // Emission from the surface the ray hit.
        if let Some(light) = lights.light_on_shape(si.shape)
            && !hide
        {
            let le = lights.area_radiance(light, &si, -w.ray.d);
            if le != Vec3::ZERO {
                let mis = emission_mis(w.prev, lights, settings.nee, (light, si.prim), si.p, si.ng);
                w.radiance += w.beta * le * mis;
            }
        }

        if w.depth + 1 >= max_depth || !scatter(scene, settings, &si, &mut w, rng) {
            break;
        }
    }
    (w.radiance, w.rays)
}

/// What a path carries from one vertex to the next.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Walk {
    /// The ray to trace next.
    pub ray: Ray,
    /// Segments traced before `ray`.
    pub depth: u32,
    /// Throughput.
    pub beta: Vec3,
    /// The squared product of the relative indices of refraction crossed, for Russian roulette
    /// ([`rr_survival`]).
    pub eta_scale: f32,
    /// The vertex `ray` leaves, for the MIS weight of emission it reaches.
    pub prev: Option<PrevVertex>,
    /// The estimate so far.
    pub radiance: Vec3,
    /// Rays traced so far.
    pub rays: u64,
}

/// The bounce at `si`, the hit of `w.ray` (its emission already counted; the depth below the
/// limit): the bounce's fixed budget of numbers, next-event estimation, the BSDF's continuation
/// and Russian roulette. Updates the walk (`w.ray` becomes the continuation) and returns whether
/// the path goes on.
#[inline]
pub(crate) fn scatter<S: Sampler>(
    scene: &Scene,
    settings: &PathSettings,
    si: &SurfaceInteraction,
    w: &mut Walk,
    rng: &mut S,
) -> bool {
    // The fixed per-bounce budget of random numbers.
    let u_select = rng.next_1d();
    let u_light = rng.next_2d();
    let u_lobe = rng.next_1d();
    let u_bsdf = rng.next_2d();
    let u_rr = rng.next_1d();

    let lights = &scene.lights;
    let bsdf = scene.bsdf(si);
    let wo = si.shading.to_local(-w.ray.d);

    // Next-event estimation.
    if bsdf.has_smooth_lobe()
        && let Some(ls) =
            lights.sample_nee(settings.nee, si.p, si.shading.n, (u_select, u_rr), u_light)
    {
        let wi = si.shading.to_local(ls.wi);
        let f = bsdf.eval(wo, wi);
        if f != Vec3::ZERO {
            w.rays += 1;
            if visible(scene, si.p, si.ng, ShadowTarget::of_sample(&ls)) {
                let mis = if ls.delta {
                    1.0
                } else {
                    power_heuristic(ls.pdf_sa, bsdf.pdf_sa(wo, wi))
                };
                w.radiance += w.beta * f * ls.le * (mis / ls.pdf_sa);
            }
        }
    }

    // BSDF sampling.
    let Some(bs) = bsdf.sample(wo, u_lobe, u_bsdf) else {
        return false;
    };
    w.beta *= bs.f / bs.pdf_sa;
    w.eta_scale *= bs.eta;
    let d = si.shading.to_world(bs.wi);
    w.prev = Some(PrevVertex {
        p: si.p,
        n: si.shading.n,
        pdf_sa: bs.pdf_sa,
        delta: bs.lobe.is_delta(),
        mis: EmissionMis::Power,
    });
    w.ray = Ray::new(offset_ray_origin(si.p, si.ng, d), d);
    w.depth += 1;

    let bmax = w.beta.max_element();
    if bmax <= 0.0 || !w.beta.is_finite() {
        return false;
    }
    if w.depth >= settings.rr_depth {
        let q = rr_survival(bmax, w.eta_scale);
        if u_rr >= q {
            return false;
        }
        w.beta /= q;
    }
    true
}

/// One path-traced estimate for the camera ray through `film` (pixel coordinates).
#[inline]
pub fn trace_camera_path<S: Sampler>(
    scene: &Scene,
    settings: &PathSettings,
    film: Vec2,
    rng: &mut S,
) -> (Vec3, u64) {
    let u_lens = rng.next_2d();
    let ray = scene.camera.generate_ray(film, u_lens);
    trace_path(scene, settings, ray, 0, Vec3::ONE, None, rng)
}

/// The path tracer as an [`Integrator`].
#[derive(Clone, Debug)]
pub struct PathIntegrator {
    /// Settings.
    pub settings: PathSettings,
}

impl Integrator for PathIntegrator {
    fn name(&self) -> &'static str {
        "path"
    }

    fn describe(&self) -> String {
        format!(
            "path max_depth={} rr_depth={} sampler={} {}",
            self.settings.max_depth,
            self.settings.rr_depth,
            self.settings.sampler.name(),
            self.settings.nee_label()
        )
    }

    fn render_pass(&self, scene: &Scene, ctx: &PassContext, accum: &mut [DVec3]) -> u64 {
        let (w, _) = ctx.resolution(scene);
        let w = w as usize;
        let settings = self.settings.resolved(&scene.features);
        let bands = Bands::new(w);
        // Eight pixels at a time, each lane the path `trace_camera_path` draws for its pixel.
        let pass = lanes::LanePass::new(scene, &settings);
        bands.run(accum, |first, chunk| match settings.sampler {
            SamplerKind::Independent => pass.render_pixels((w, first), chunk, &|index, xy| {
                let mut rng = ctx.pixel_rng(index);
                let film = ctx.pixel_film_position(index, xy, &mut rng);
                (rng, film)
            }),
            SamplerKind::Sobol => pass.render_pixels((w, first), chunk, &|index, (x, y)| {
                let mut rng = ctx.pixel_sequence(index);
                let film = ctx.film_position(x, y, &mut rng);
                (rng, film)
            }),
        })
    }

    fn lanes(&self, scene: &Scene) -> Option<String> {
        Some(lanes::describe(
            scene,
            self.settings.resolved(&scene.features).nee,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The hierarchy for two or more local lights, half of them of at most two emitters; the
    /// power sampler for one light, for none and where most lights are lamps of many
    /// triangles.
    #[test]
    fn auto_nee_by_emitters_per_light() {
        assert_eq!(auto_nee(0, 0), NeeSelection::Power);
        assert_eq!(auto_nee(1, 1), NeeSelection::Power);
        assert_eq!(auto_nee(1, 2), NeeSelection::Power);
        assert_eq!(auto_nee(2, 2), NeeSelection::Hierarchy);
        assert_eq!(auto_nee(2, 3), NeeSelection::Power);
        assert_eq!(auto_nee(100_000, 2), NeeSelection::Hierarchy);
        assert_eq!(auto_nee(108, 960), NeeSelection::Power);
    }
}
