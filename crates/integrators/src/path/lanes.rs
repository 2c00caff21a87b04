//! The path tracer over eight paths at once ([`LanePass`]): the estimator of
//! [`super::trace_path`], each lane one pixel's path drawing that pixel's numbers in the same
//! order and doing the same arithmetic, so that every lane's estimate is the scalar walk's, to
//! the bit.
//!
//! The lanes carry paths across diffuse surfaces of meshes (Mitsuba's `diffuse` without a mask,
//! normal map or bump map, textured or not), rough conductors and rough plastics of meshes
//! (`roughconductor`, `roughplastic`, untextured) and absorbers. In lanes ([`F8`]): the hit's
//! point and shading frame, light samples on triangles and spheres of uniform radiance, the
//! diffuse and microfacet models' values, densities and sampling ([`GlossyLanes`]), the power
//! heuristic, the shadow rays and continuations off the surface, the throughput and Russian
//! roulette. Lane by lane: traversal, each hit's material and emission, other lights' samples,
//! the Beckmann distribution's transcendental functions and the plastic's coating tables, the
//! random numbers. At any other surface (another material, a mask, normal or bump map, an
//! analytic shape) a lane makes the scalar walk's bounce ([`super::scatter`]) and its path goes
//! on in the lanes from there.

use glam::Vec3;
use restir_geometry::lanes::{
    MeshHits, RayLanes, SurfaceLanes, offset_ray_origins, shadow_rays_between,
};
use restir_geometry::{Ray, Shape, SurfaceInteraction};
use restir_lights::NeeSelection;
use restir_materials::lanes::GlossyLanes;
use restir_materials::{Bsdf, BsdfKind, Microfacet, RoughPlastic};
use restir_sampling::Sampler;
use restir_sampling::lanes::{self, F8, LANES, M8, V3};
use restir_scene::{Scene, TexturePoint};

use super::{
    EmissionMis, PathSettings, PrevVertex, Walk, emission_mis, environment_mis, rr_survival,
    scatter,
};
use crate::shadow::{ShadowTarget, visible};

const FRAC_1_PI: f32 = core::f32::consts::FRAC_1_PI;

/// What a lane does at a surface.
#[derive(Clone, Copy, PartialEq)]
enum Surface {
    /// A plain diffuse surface of reflectance `albedo`, mirrored to the front when `two_sided`.
    Diffuse { albedo: Vec3, two_sided: bool },
    /// A plain rough conductor (Mitsuba's `roughconductor`), mirrored to the front when
    /// `two_sided`.
    RoughConductor {
        eta: Vec3,
        k: Vec3,
        specular: Vec3,
        microfacet: Microfacet,
        two_sided: bool,
    },
    /// A plain rough plastic (Mitsuba's `roughplastic`), mirrored to the front when
    /// `two_sided`.
    RoughPlastic {
        plastic: RoughPlastic,
        two_sided: bool,
    },
    /// An absorber (an emitter without a material): the path ends after its emission.
    Black,
    /// Anything else: the scalar walk's bounce there.
    Other,
}

impl Surface {
    /// The class of a mesh surface whose BSDF is `bsdf` everywhere.
    #[inline(always)]
    fn of(bsdf: Option<Bsdf>) -> Self {
        match bsdf {
            Some(b) if !b.is_masked() && b.normal_map.is_none() => match b.kind {
                BsdfKind::Diffuse { reflectance } => Surface::Diffuse {
                    albedo: reflectance,
                    two_sided: b.two_sided,
                },
                BsdfKind::RoughConductor {
                    eta,
                    k,
                    specular_reflectance,
                    microfacet,
                } => Surface::RoughConductor {
                    eta,
                    k,
                    specular: specular_reflectance,
                    microfacet,
                    two_sided: b.two_sided,
                },
                BsdfKind::RoughPlastic(plastic) => Surface::RoughPlastic {
                    plastic,
                    two_sided: b.two_sided,
                },
                BsdfKind::Black => Surface::Black,
                _ => Surface::Other,
            },
            _ => Surface::Other,
        }
    }
}

/// What the lanes do at a hit on a shape, decided once for the scene ([`shape_classes`]).
#[derive(Clone, Copy, PartialEq)]
enum Class {
    /// A mesh whose BSDF is the same everywhere.
    Uniform(Surface),
    /// A mesh of material `bsdf`, a diffuse model with textures that change only its colours
    /// (no mask, normal map or bump map, blend weight or principled parameters): its
    /// reflectance alone is looked up at each hit.
    TexturedDiffuse { bsdf: u32, two_sided: bool },
    /// Anything else: a path that reaches it bounces there as the scalar walk does.
    Other,
}

/// Each shape's [`Class`].
fn shape_classes(scene: &Scene) -> Vec<Class> {
    (0..scene.shapes.len())
        .map(|s| {
            if !matches!(scene.shapes[s], Shape::Mesh(_)) {
                return Class::Other;
            }
            if let Some(b) = scene.uniform_bsdf(s as u32) {
                return match Surface::of(Some(b)) {
                    Surface::Other => Class::Other,
                    surface => Class::Uniform(surface),
                };
            }
            let b = scene.shape_bsdf()[s];
            let colours_only = scene.bsdf_textures()[b as usize].as_ref().is_none_or(|t| {
                t.opacity.is_none()
                    && t.normal.is_none()
                    && t.bump.is_none()
                    && t.weight.is_none()
                    && !t.principled.any()
            });
            match Surface::of(Some(scene.bsdfs()[b as usize])) {
                // An absorber stays one whatever its textures.
                Surface::Black if colours_only => Class::Uniform(Surface::Black),
                Surface::Diffuse { two_sided, .. } if colours_only => {
                    Class::TexturedDiffuse { bsdf: b, two_sided }
                }
                _ => Class::Other,
            }
        })
        .collect()
}

/// Radiance along the camera rays `rays` (one a lane, at most [`LANES`]), each estimated with one
/// path drawing its numbers from the same lane of `rngs`: [`super::trace_path`] from depth 0, lane
/// by lane. Writes the estimates to `out` and returns the number of rays traced.
#[inline(always)]
fn trace_camera_paths<S: Sampler>(
    scene: &Scene,
    settings: &PathSettings,
    classes: &[Class],
    rays: &[Ray],
    rngs: &mut [S],
    out: &mut [Vec3],
) -> u64 {
    let n = rays.len();
    debug_assert!(n <= LANES && rngs.len() == n && out.len() == n);
    let max_depth = settings.max_segments();
    if max_depth == 0 {
        out.fill(Vec3::ZERO);
        return 0;
    }
    let lights = &scene.lights;
    let has_env = scene.features.has_environment;
    let mut traced = 0u64;
    // The rays in lanes: a bounce in lanes selects its continuations into them whole.
    let mut ray = RayLanes::from_fn(|i| rays[i.min(n - 1)]);
    let mut active = M8::from_fn(|i| i < n);
    let mut beta = V3::splat(Vec3::ONE);
    let mut radiance = V3::ZERO;
    let mut prev: [Option<PrevVertex>; LANES] = [None; LANES];
    // The squared product of the relative indices of refraction crossed (by the scalar walk's
    // bounces on other surfaces).
    let mut eta = F8::splat(1.0);
    let mut depth = 0u32;
    loop {
        // The hits, lane by lane: what they emit, the surface data of mesh hits gathered for
        // the lanes (computed here for emitters, whose emission needs it, and for other
        // surfaces, where the scalar walk's bounce needs it).
        let hide = depth == 0 && settings.hide_emitters;
        let mut gather = MeshHits::default();
        let mut computed = [None::<SurfaceInteraction>; LANES];
        let mut albedo = V3::ZERO;
        let mut glossy = GlossyLanes::default();
        let mut glossy_here = M8::default();
        let mut two_sided = M8::default();
        // Lanes whose surface this bounce is not for the lanes: the walk's own bounce there.
        let mut one_lane = M8::default();
        for i in 0..n {
            if !active.get(i) {
                continue;
            }
            let r = ray.get(i);
            let hit = if hide {
                let (si, k) = scene.intersect_past_emitters(&r);
                traced += k;
                si.map(Err)
            } else {
                traced += 1;
                scene.accel.intersect(&r, r.t_max).map(Ok)
            };
            let Some(hit) = hit else {
                active.set(i, false);
                if has_env && !hide {
                    let le = lights.environment_radiance(r.d);
                    let w = environment_mis(prev[i], lights, settings.nee, r.d);
                    radiance.set(i, radiance.get(i) + beta.get(i) * le * w);
                }
                continue;
            };
            let shape = match &hit {
                Ok(h) => h.shape,
                Err(si) => si.shape,
            };
            let surface = match (classes[shape as usize], &hit, &scene.shapes[shape as usize]) {
                (Class::Uniform(surface), ..) => surface,
                (Class::TexturedDiffuse { bsdf, two_sided }, Ok(h), Shape::Mesh(m)) => {
                    // Looked up at the point the hit names.
                    let bary = h.triangle_param();
                    let at = TexturePoint {
                        uv: m.uv_at(h.prim as usize, bary),
                        shape,
                        prim: h.prim,
                        bary,
                    };
                    // (Always a value: the class is given only where textures are looked up.)
                    match scene.textured_diffuse_at(bsdf, &at) {
                        Some(albedo) => Surface::Diffuse { albedo, two_sided },
                        None => Surface::Other,
                    }
                }
                (Class::TexturedDiffuse { .. }, Err(si), _) => Surface::of(Some(scene.bsdf(si))),
                _ => Surface::Other,
            };
            let light = lights.light_on_shape(shape).filter(|_| !hide);
            if let (
                Ok(h),
                None,
                Surface::Diffuse { .. }
                | Surface::RoughConductor { .. }
                | Surface::RoughPlastic { .. },
                Shape::Mesh(m),
            ) = (&hit, light, surface, &scene.shapes[shape as usize])
            {
                gather.set(i, m, h.prim as usize, h.bary);
            } else {
                let s = match hit {
                    Ok(h) => scene.accel.surface_interaction(&scene.shapes, &h, &r),
                    Err(si) => si,
                };
                if let Some(light) = light {
                    let le = lights.area_radiance(light, &s, -r.d);
                    if le != Vec3::ZERO {
                        let w =
                            emission_mis(prev[i], lights, settings.nee, (light, s.prim), s.p, s.ng);
                        radiance.set(i, radiance.get(i) + beta.get(i) * le * w);
                    }
                }
                if surface == Surface::Black {
                    active.set(i, false);
                    continue;
                }
                one_lane.set(i, surface == Surface::Other);
                computed[i] = Some(s);
            }
            match surface {
                Surface::Diffuse {
                    albedo: a,
                    two_sided: t,
                } => {
                    albedo.set(i, a);
                    two_sided.set(i, t);
                }
                Surface::RoughConductor {
                    eta,
                    k,
                    specular,
                    microfacet,
                    two_sided: t,
                } => {
                    glossy.set_rough_conductor(i, eta, k, specular, &microfacet);
                    glossy_here.set(i, true);
                    two_sided.set(i, t);
                }
                Surface::RoughPlastic {
                    plastic,
                    two_sided: t,
                } => {
                    glossy.set_rough_plastic(i, &plastic);
                    glossy_here.set(i, true);
                    two_sided.set(i, t);
                }
                _ => {}
            }
        }
        if !active.any() || depth + 1 >= max_depth {
            break;
        }
        let mut surf: SurfaceLanes = gather.surface();
        for (i, s) in computed.iter().enumerate() {
            let Some(s) = s else { continue };
            if one_lane.get(i) {
                // Any other surface: the scalar walk's bounce, its numbers included.
                let mut w = Walk {
                    ray: ray.get(i),
                    depth,
                    beta: beta.get(i),
                    eta_scale: eta.0[i],
                    prev: prev[i],
                    radiance: radiance.get(i),
                    rays: 0,
                };
                active.set(i, scatter(scene, settings, s, &mut w, &mut rngs[i]));
                (prev[i], eta.0[i]) = (w.prev, w.eta_scale);
                ray.set(i, w.ray);
                beta.set(i, w.beta);
                radiance.set(i, w.radiance);
                traced += w.rays;
            } else {
                surf.set(i, s.p, s.ng, &s.shading);
            }
        }
        // The lanes that bounce in lanes.
        let here = active & !one_lane;

        // The fixed per-bounce budget of numbers.
        let mut u = [[0.0f32; 7]; LANES];
        for i in 0..n {
            if !here.get(i) {
                continue;
            }
            let rng = &mut rngs[i];
            let u_select = rng.next_1d();
            let u_light = rng.next_2d();
            let u_lobe = rng.next_1d();
            let u_bsdf = rng.next_2d();
            let u_rr = rng.next_1d();
            u[i] = [
                u_select, u_light.x, u_light.y, u_lobe, u_bsdf.x, u_bsdf.y, u_rr,
            ];
        }
        let lane = |k: usize| F8::from_fn(|i| u[i][k]);
        let zero = F8::splat(0.0);
        let wo = surf.to_local(-ray.d);
        // A two-sided surface seen from behind is mirrored to the front.
        let flip = two_sided & wo.z.lt(zero);
        let v = V3 {
            x: wo.x,
            y: wo.y,
            z: flip.select(-wo.z, wo.z),
        };
        let front = v.z.gt(zero);

        // Next-event estimation.
        let nee_u = core::array::from_fn(|i| [u[i][0], u[i][6], u[i][1], u[i][2]]);
        let ls = lights.sample_nee_lanes(settings.nee, surf.p, surf.n, &nee_u, here);
        let wi = surf.to_local(ls.wi);
        let lz = flip.select(-wi.z, wi.z);
        let reach = front & lz.gt(zero);
        let mut f = reach.select3(albedo.scale(F8::splat(FRAC_1_PI) * lz), V3::ZERO);
        let mut b_pdf = reach.select(lz * FRAC_1_PI, zero);
        if glossy_here.any() {
            let l = V3 {
                x: wi.x,
                y: wi.y,
                z: lz,
            };
            let (f_l, pdf_l) = glossy.eval_pdf(v, l);
            f = glossy_here.select3(f_l, f);
            b_pdf = glossy_here.select(pdf_l, b_pdf);
        }
        let w = ls
            .delta
            .select(F8::splat(1.0), lanes::power_heuristic(ls.pdf_sa, b_pdf));
        let direct = (beta * f * ls.le).scale(w / ls.pdf_sa);
        // The shadow rays toward points (`visible`'s, `shadow_ray_between` in lanes).
        let (s_o, s_d, s_t) = shadow_rays_between(surf.p, surf.ng, ls.p);
        for i in 0..n {
            let Some(l) = ls.get(i) else {
                continue;
            };
            if f.get(i) == Vec3::ZERO {
                continue;
            }
            traced += 1;
            let shadow = Ray::new(s_o.get(i), s_d.get(i));
            let seen = match ShadowTarget::of_sample(&l) {
                ShadowTarget::OnLight { p, ng, light, prim } => {
                    let end = lights.shadow_end(light, prim, shadow.o, shadow.d, s_t.0[i], p, ng);
                    !scene.occluded(&shadow, end)
                }
                ShadowTarget::Point(_) => !scene.occluded(&shadow, s_t.0[i]),
                target @ ShadowTarget::Direction(_) => {
                    visible(scene, surf.p.get(i), surf.ng.get(i), target)
                }
            };
            if seen {
                radiance.set(i, radiance.get(i) + direct.get(i));
            }
        }

        // The continuation: cosine-weighted, or the microfacet models' sample.
        let mut sampled = lanes::sample_cosine_hemisphere(lane(4), lane(5));
        let mut pdf = sampled.z.gt(zero).select(sampled.z * FRAC_1_PI, zero);
        let mut f_c = albedo.scale(F8::splat(FRAC_1_PI) * sampled.z);
        let mut ok = front & pdf.gt(zero) & pdf.is_finite() & f_c.is_finite() & sampled.is_finite();
        if glossy_here.any() {
            let (l, f, p, some) = glossy.sample(v, lane(3), lane(4), lane(5));
            sampled = glossy_here.select3(l, sampled);
            f_c = glossy_here.select3(f, f_c);
            pdf = glossy_here.select(p, pdf);
            ok = (glossy_here & some) | (!glossy_here & ok);
        }
        let mut go_on = here & ok;
        beta = here.select3(beta * (f_c / pdf), beta);
        let local = V3 {
            x: sampled.x,
            y: sampled.y,
            z: flip.select(-sampled.z, sampled.z),
        };
        let dir = surf.to_world(local);
        let origin = offset_ray_origins(surf.p, surf.ng, dir);
        for (i, prev) in prev.iter_mut().enumerate().take(n) {
            if !go_on.get(i) {
                continue;
            }
            *prev = Some(PrevVertex {
                p: surf.p.get(i),
                n: surf.n.get(i),
                pdf_sa: pdf.0[i],
                delta: false,
                mis: EmissionMis::Power,
            });
        }
        ray.set_where(go_on, origin, dir);
        depth += 1;

        // Russian roulette (a reflection leaves the relative index of refraction as it was).
        let bmax = beta.max_element();
        go_on = go_on & bmax.gt(zero) & beta.is_finite();
        if depth >= settings.rr_depth {
            let q = F8::from_fn(|i| rr_survival(bmax.0[i], eta.0[i]));
            beta = here.select3(beta / q, beta);
            go_on = go_on & lane(6).lt(q);
        }
        active = (active & one_lane) | go_on;
        if !active.any() {
            break;
        }
    }
    for (i, o) in out.iter_mut().enumerate() {
        *o = radiance.get(i);
    }
    traced
}

/// Whether this CPU runs the lanes with AVX2 and FMA (else with the baseline's SSE2).
fn avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// What runs in lanes for `scene`, for `--stats`: the lane count and instructions, how many of
/// its shapes the lanes carry paths across, and whether light samples (selected as `nee`) are
/// drawn in lanes.
pub(crate) fn describe(scene: &Scene, nee: NeeSelection) -> String {
    let carried = shape_classes(scene)
        .iter()
        .filter(|&&c| c != Class::Other)
        .count();
    format!(
        "{LANES} paths at a time ({}); {carried} of {} shapes (meshes of diffuse materials, \
         textured or not, of rough conductors, rough plastics and absorbers) bounce in lanes, \
         the others one lane at a time; {}",
        if avx2() { "AVX2 and FMA" } else { "SSE2" },
        scene.shapes.len(),
        match nee {
            NeeSelection::Power => {
                "light samples in lanes on triangles and spheres of uniform radiance, on other \
                 lights one lane at a time"
            }
            _ => "light samples one lane at a time (the light hierarchy picks them)",
        }
    )
}

/// A pass of the path tracer in lanes over a scene, with what it decided about the scene's
/// shapes.
pub(crate) struct LanePass<'a> {
    scene: &'a Scene,
    settings: &'a PathSettings,
    classes: Vec<Class>,
}

impl<'a> LanePass<'a> {
    /// The pass over `scene` with `settings` (next-event estimation decided).
    pub(crate) fn new(scene: &'a Scene, settings: &'a PathSettings) -> Self {
        Self {
            scene,
            settings,
            classes: shape_classes(scene),
        }
    }

    /// The path tracer's estimates for the pixels `first..first + out.len()` of a film `width`
    /// pixels wide, added to `out`, eight pixels at a time: `start` gives a pixel's numbers and
    /// its film position (the caller's pixel sampler). Returns the rays traced. Runs with AVX2
    /// and FMA where the CPU has them (the same bits as without).
    pub(crate) fn render_pixels<S: Sampler>(
        &self,
        (width, first): (usize, usize),
        out: &mut [glam::DVec3],
        start: &impl Fn(usize, (u32, u32)) -> (S, glam::Vec2),
    ) -> u64 {
        #[cfg(target_arch = "x86_64")]
        if avx2() {
            // SAFETY: the CPU reported AVX2 and FMA, the features the function is compiled with.
            #[allow(unsafe_code)]
            return unsafe { self.render_pixels_avx2((width, first), out, start) };
        }
        self.render_pixels_with((width, first), out, start)
    }

    /// [`LanePass::render_pixels`] compiled for AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[allow(unsafe_code)]
    unsafe fn render_pixels_avx2<S: Sampler>(
        &self,
        at: (usize, usize),
        out: &mut [glam::DVec3],
        start: &impl Fn(usize, (u32, u32)) -> (S, glam::Vec2),
    ) -> u64 {
        self.render_pixels_with(at, out, start)
    }

    #[inline(always)]
    fn render_pixels_with<S: Sampler>(
        &self,
        (width, first): (usize, usize),
        out: &mut [glam::DVec3],
        start: &impl Fn(usize, (u32, u32)) -> (S, glam::Vec2),
    ) -> u64 {
        let mut traced = 0;
        for (g, group) in out.chunks_mut(LANES).enumerate() {
            let base = first + g * LANES;
            let n = group.len();
            let mut rays = [Ray::new(Vec3::ZERO, Vec3::Z); LANES];
            // Lanes past the end of a short group repeat its last pixel and are not traced.
            let mut rngs: [S; LANES] = core::array::from_fn(|i| {
                let index = base + i.min(n - 1);
                let (mut rng, film) =
                    start(index, ((index % width) as u32, (index / width) as u32));
                // The lens sample comes first, as in `trace_camera_path`.
                let u_lens = rng.next_2d();
                rays[i] = self.scene.camera.generate_ray(film, u_lens);
                rng
            });
            let mut est = [Vec3::ZERO; LANES];
            traced += trace_camera_paths(
                self.scene,
                self.settings,
                &self.classes,
                &rays[..n],
                &mut rngs[..n],
                &mut est[..n],
            );
            for (o, e) in group.iter_mut().zip(est) {
                *o += e.as_dvec3();
            }
        }
        traced
    }
}
