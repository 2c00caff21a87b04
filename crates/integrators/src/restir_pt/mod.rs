//! ReSTIR PT (Lin et al. 2022): reservoir-based path reuse across pixels with the reconnection,
//! random-replay and hybrid shifts, combined unbiasedly with the MIS schemes of `restir-gris`
//! (`docs/RESTIR_PT.md`).
//!
//! One pass, for every pixel at once (`docs/RESTIR_PT.md`):
//!
//! 1. **Primary hits** ([`GBuffer`]), adding what the camera sees directly.
//! 2. **Initial sampling**: `--candidates` random walks from the primary hit with next-event
//!    estimation and BSDF sampling (power heuristic and Russian roulette as the path tracer);
//!    every light connection is one candidate with resampling weight `lum(contribution)/N`.
//!    Each walk draws from its own generator, whose state the samples keep for replay
//!    ([`walk`]); the reservoir counts as confidence 1.
//!    With `direct = path` the direct-light connections at `x1` are summed per pixel instead.
//! 3. **Temporal reuse** (optional): the pixel's reservoir of the previous pass, its domain the
//!    previous pass's primary hit, generalized balance MIS, confidence capped at `mcap`.
//! 4. **Spatial reuse**: `R` rounds of `k` neighbours (pattern and similarity tests as ReSTIR
//!    DI) resampled through [`restir_gris::resample`] with the shift of `--shift`
//!    ([`shift::PtShift`]). Confidence is capped at `mcap` after every round. Steps 3 and 4
//!    are the shared [`crate::reuse::passes`].
//! 5. **Shading**: the selected path's integrand at the pixel (kept in the sample) times `W`.

mod candidate;
mod diag;
pub mod pilot;
pub mod sample;
mod settings;
pub mod shift;
pub mod walk;

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use restir_gris::{Reservoir, StreamingReservoir};
use restir_materials::LobeFlags;
use restir_sampling::{Pcg32, luminance};
use restir_scene::Scene;

pub use pilot::{GLOSSY_VIEW_MIN, INDIRECT_VIEW_MIN, ViewPilot, view_pilot};
pub use sample::{Kind, PathSample, Reconnection, ShiftKind};
pub use settings::{DirectLight, LARGE_FILM_RADIUS, RestirPtSettings, SHIFT_NAMES};
use shift::PtReuse;
pub use shift::{Frames, PtShift};

use crate::bands::Bands;
use crate::motion::FrameMotion;
use crate::reuse::chain::PassChain;
use crate::reuse::gbuffer::{GBuffer, Receiver};
use crate::reuse::reciprocal;
use crate::reuse::seen::{DeltaChains, SeenEmission, SplatRays};
use restir_reuse::{ScreenReuse, Stages};

use crate::pass::{Integrator, PassContext};
use crate::path::PathSettings;
use crate::restir_di::{RestirDiIntegrator, RestirDiSettings};
use crate::reuse::settings::mis_name;
use crate::stages::StageClock;
use sample::connectible;
use walk::{ScatterVertex, Walker};

/// Random-stream stages (see [`PassContext::stage_rng`]).
const STAGE_INITIAL: u64 = 101;
const STAGES: Stages = Stages {
    temporal: 102,
    spatial: 116,
};

/// The reservoir type.
pub type PtReservoir = Reservoir<PathSample>;

/// The ReSTIR PT estimator (`--integrator restir-pt`).
#[derive(Debug)]
pub struct RestirPtIntegrator {
    settings: RestirPtSettings,
    /// The ReSTIR DI pass that takes the direct light with `direct = restir-di`.
    di: Option<RestirDiIntegrator>,
    /// The neighbour pattern and the history of temporal reuse.
    reuse: ScreenReuse<PathSample, GBuffer>,
    /// Whether a pass continues the passes the history comes from.
    chain: PassChain,
    clock: StageClock,
    /// Where the brightest pixels come from (`RESTIR_PT_DIAG`, [`diag`]); `None` unless asked.
    diag: Option<diag::Diag>,
    /// More camera rays for the seen emission on emitter silhouettes (`edge_rays > 1`).
    seen: Option<SeenEmission>,
    /// The last pass's buffers that no history keeps, reused by the next pass (a fresh buffer
    /// of an image's size is faulted in page by page).
    recycled: std::sync::Mutex<Recycled>,
}

/// A pass's buffers, kept for the next one.
#[derive(Debug, Default)]
struct Recycled {
    gbuf: Option<GBuffer>,
    current: Vec<PtReservoir>,
    radiance: Vec<Vec3>,
    expected: restir_reuse::passes::Expected,
}

impl RestirPtIntegrator {
    /// An integrator with `settings`.
    pub fn new(settings: RestirPtSettings) -> Self {
        let di = (settings.direct == DirectLight::RestirDi).then(|| {
            // Paths of at most two segments (fewer if max_depth says so), the same reuse.
            let path = PathSettings {
                max_depth: settings.path.max_segments().min(2) as i32,
                ..settings.path
            };
            RestirDiIntegrator::new(RestirDiSettings {
                reuse: settings.reuse,
                ..RestirDiSettings::new(path)
            })
        });
        Self {
            settings,
            di,
            reuse: ScreenReuse::default(),
            chain: PassChain::default(),
            clock: StageClock::default(),
            diag: diag::Diag::from_env(),
            seen: (settings.edge_rays > 1).then(|| {
                SeenEmission::new(
                    settings.edge_rays,
                    SplatRays::VarianceMatched,
                    None,
                    settings.edge_mask_from_pass,
                )
            }),
            recycled: Default::default(),
        }
    }

    /// The settings.
    pub fn settings(&self) -> &RestirPtSettings {
        &self.settings
    }

    /// Bytes per pixel of one reservoir buffer.
    pub const RESERVOIR_BYTES: usize = std::mem::size_of::<PtReservoir>();

    /// Bytes per pixel of the per-pass buffers that follow the film (all but the reciprocal
    /// rounds' table of shifts, which holds a window of rows, and the direct light's buffers).
    fn bytes_per_pixel(&self) -> usize {
        let hit_bytes = GBuffer::BYTES_PER_PIXEL;
        let (reservoirs, hits) = if self.settings.reuse.temporal {
            (3, 2)
        } else {
            (2, 1)
        };
        reservoirs * Self::RESERVOIR_BYTES
            + hits * hit_bytes
            + std::mem::size_of::<Vec3>()
            // Each pixel's expected shading over the last round's selection.
            + if self.settings.reuse.shade_expected {
                std::mem::size_of::<Option<[f32; 3]>>()
            } else {
                0
            }
            // The silhouette mask, a ray count per pixel.
            + self.seen.as_ref().map_or(0, |_| std::mem::size_of::<u16>())
    }

    fn max_depth(&self) -> u32 {
        self.settings.path.max_segments()
    }

    /// The shift used for this scene: `--shift`, except that `hybrid` becomes `reconnection` in
    /// scenes where every material is connectible under the fixed rule (nothing to replay
    /// through; decided once here). The footprint rule keeps the hybrid shift: it turns down
    /// reconnections at glossy vertices on short segments, which the hybrid shift replays.
    pub fn effective_shift(&self, scene: &Scene) -> ShiftKind {
        let s = self.settings.shift;
        if s == ShiftKind::Hybrid
            && self.settings.reconnection == Reconnection::Fixed
            && !has_near_specular(scene)
        {
            ShiftKind::Reconnection
        } else {
            s
        }
    }

    /// Where the walks leave out the emission seen through delta lobes (paths whose every
    /// bounce is a delta lobe, ended on an emitter): when the silhouette stage estimates it
    /// instead, with the camera rays of its mask (`edge_rays` above 1, the camera's emitters
    /// shown, direct light not from ReSTIR DI) and the scene has a delta lobe.
    pub fn delta_chains(&self, scene: &Scene) -> Option<DeltaChains> {
        let s = &self.settings;
        (self.seen.is_some()
            && s.direct != DirectLight::RestirDi
            && !s.path.hide_emitters
            && self.max_depth() >= 2
            && scene.bsdfs().iter().any(|b| b.flags().is_delta()))
        .then(|| DeltaChains {
            max_segments: self.max_depth(),
            rr_depth: s.path.rr_depth,
        })
    }

    /// The walks' rules for `scene`.
    pub fn walker<'a>(&self, scene: &'a Scene) -> Walker<'a> {
        let d = self.settings.near_distance * scene.lights.scene_radius();
        Walker {
            scene,
            seen_through_delta: self.delta_chains(scene).is_some()
                && !self.settings.delta_emission_twice,
            shift: self.effective_shift(scene),
            max_depth: self.max_depth(),
            rr_depth: self.settings.path.rr_depth,
            near2: d * d,
            rule: self.settings.reconnection,
            footprint2: self.settings.footprint * scene.camera.pixel_angle().powi(2),
            skip_invertibility: self.settings.skip_invertibility,
            nee: self.settings.path.resolved(&scene.features).nee,
        }
    }

    /// The shift map over the pixels of `gbuf`.
    pub fn shift_map<'a>(&'a self, scene: &'a Scene, gbuf: &'a GBuffer) -> PtShift<'a> {
        PtReuse {
            walker: self.walker(scene),
            settings: &self.settings,
            gbuf,
            prev: None,
            frames: None,
            pixels: 0,
        }
        .shift()
    }

    /// The shift map over the pixels of `gbuf` (domains `0..n`, in `scene`) and of the previous
    /// frame's `prev` (domains `n..2n`, in `motion.prev_scene`), the map temporal reuse uses
    /// across frames in which shapes or lights moved.
    pub fn frame_shift_map<'a>(
        &'a self,
        scene: &'a Scene,
        gbuf: &'a GBuffer,
        prev: &'a GBuffer,
        motion: &'a FrameMotion,
    ) -> PtShift<'a> {
        PtReuse {
            walker: self.walker(scene),
            settings: &self.settings,
            gbuf,
            prev: Some(prev),
            frames: Some(self.frames(motion)),
            pixels: gbuf.receivers.len(),
        }
        .shift()
    }

    /// The previous frame for the cross-frame shift, with the negative controls' switches.
    fn frames<'a>(&'a self, motion: &'a FrameMotion) -> shift::Frames<'a> {
        shift::Frames {
            walker: self.walker(&motion.prev_scene),
            motion,
            current_scene: self.settings.reuse.temporal_current_scene,
            stale_suffix: self.settings.temporal_stale_suffix,
        }
    }

    /// The primary hits and the initial reservoirs of pass `ctx` (what reuse starts from), with
    /// the radiance seen directly and the rays traced.
    pub fn initial_reservoirs(
        &self,
        scene: &Scene,
        ctx: &PassContext,
    ) -> (GBuffer, Vec<PtReservoir>, Vec<Vec3>, u64) {
        let s = &self.settings;
        let (w, h) = ctx.resolution(scene);
        let n = w as usize * h as usize;
        let (recycled, mut current, mut radiance) = self
            .recycled
            .lock()
            .map(|mut r| {
                (
                    r.gbuf.take(),
                    std::mem::take(&mut r.current),
                    std::mem::take(&mut r.radiance),
                )
            })
            .unwrap_or_default();
        radiance.clear();
        radiance.resize(n, Vec3::ZERO);
        let keep = self.max_depth() >= 2;
        let (gbuf, mut rays) = self.clock.time("primary", || {
            // With `direct = restir-di` the ReSTIR DI pass adds the emitters the camera sees.
            GBuffer::trace_into(
                scene,
                ctx,
                s.path.hide_emitters,
                s.direct != DirectLight::RestirDi,
                keep,
                &mut radiance,
                recycled,
            )
        });
        if let Some(d) = &self.diag {
            d.seen(&radiance);
        }
        // The seen emission on emitter silhouettes from more camera rays (`radiance` holds the
        // G-buffer's seen emission only, nothing else yet).
        if let Some(seen) = &self.seen
            && s.direct != DirectLight::RestirDi
            && !s.path.hide_emitters
        {
            let chains = self.delta_chains(scene);
            rays += self.clock.time("silhouettes", || {
                seen.supersample(scene, ctx, &gbuf, chains.as_ref(), &mut radiance)
            });
        }
        current.clear();
        current.resize(n, PtReservoir::empty());
        if keep {
            let bands = Bands::new(gbuf.width);
            let start = std::time::Instant::now();
            rays += bands.run(
                (&mut current[..], &mut radiance[..]),
                |first, (out, rad)| {
                    let mut rays = 0;
                    for (i, (res, l)) in out.iter_mut().zip(rad.iter_mut()).enumerate() {
                        let index = first + i;
                        if let Some(r) = gbuf.receiver(index) {
                            let mut rng = ctx.stage_rng(index, STAGE_INITIAL);
                            let (init, direct, nr) =
                                self.initial(scene, r, gbuf.ng[index], &mut rng);
                            *res = init;
                            *l += direct;
                            rays += nr;
                        }
                    }
                    rays
                },
            );
            self.clock.add("initial", start.elapsed());
        }
        (gbuf, current, radiance, rays)
    }

    /// Initial sampling at receiver `r`: `N` walks, every light connection a candidate. Returns
    /// the reservoir, the path-traced direct light (with `direct = path`) and the rays.
    fn initial(
        &self,
        scene: &Scene,
        r: &Receiver,
        ng: Vec3,
        rng: &mut Pcg32,
    ) -> (PtReservoir, Vec3, u64) {
        let x1 = ScatterVertex::primary(scene, r, ng);
        let bsdf = &x1.bsdf;
        let empty = Reservoir {
            confidence: 1.0,
            ..Reservoir::empty()
        };
        if bsdf.flags() == LobeFlags::NONE {
            return (empty, Vec3::ZERO, 0);
        }
        let n = self.settings.candidates;
        let scale = 1.0 / n as f32;
        let direct_path_traced = self.settings.direct == DirectLight::Path;
        let direct_elsewhere = self.settings.direct == DirectLight::RestirDi;
        let mut stream = StreamingReservoir::new();
        let mut direct = Vec3::ZERO;
        let mut rays = 0;
        let walker = self.walker(scene);
        for _ in 0..n {
            // The walk's own generator (stored in its samples for replay); candidate selection
            // draws from `rng`.
            let seed = Pcg32::new(
                (u64::from(rng.next_u32()) << 32) | u64::from(rng.next_u32()),
                u64::from(rng.next_u32()),
            );
            let mut sink = |sample: PathSample, contribution: Vec3| {
                if direct_elsewhere && sample.length == 2 {
                    return; // ReSTIR DI's pass has it
                }
                if direct_path_traced && sample.length == 2 {
                    if contribution.is_finite() {
                        direct += contribution * scale;
                    }
                    return;
                }
                let u = rng.next_f32();
                let target = luminance(sample.value);
                let w = luminance(contribution) * scale;
                if target > 0.0 && target.is_finite() && w > 0.0 && w.is_finite() {
                    stream.add_candidate(sample, target, w, 0.0, u);
                }
            };
            let (_, nr) = walker.walk(&x1, seed, None, &mut sink);
            rays += nr;
        }
        if stream.selected().is_none() {
            return (empty, direct, rays);
        }
        let mut res = stream.finalize_recorded();
        res.confidence = 1.0;
        (res, direct, rays)
    }

    /// Shading: the reservoir's path times `W` (its value is its integrand at this pixel, set by
    /// initial sampling or by the last shift).
    fn shade(res: &PtReservoir) -> Vec3 {
        res.sample
            .as_ref()
            .map_or(Vec3::ZERO, |y| y.value * res.ucw)
    }
}

/// Whether some material of `scene` is not connectible (a delta or near-specular lobe) and can
/// be scattered from.
pub fn has_near_specular(scene: &Scene) -> bool {
    scene
        .bsdfs()
        .iter()
        .any(|b| !connectible(b) && b.flags() != LobeFlags::NONE)
}

impl Integrator for RestirPtIntegrator {
    fn name(&self) -> &'static str {
        "restir-pt"
    }

    fn describe(&self) -> String {
        let s = &self.settings;
        format!(
            "restir-pt max_depth={} {} candidates={} neighbors={} {} spatial_rounds={} \
             reciprocal={} mis={} mcap={} {} {} shift={} reconnection={} max_jacobian={} \
             direct={}{}{}",
            s.path.max_depth,
            s.path.nee_label(),
            s.candidates,
            s.reuse.neighbors,
            s.radius_label(),
            s.reuse.spatial_rounds,
            s.reuse.reciprocal,
            mis_name(s.reuse.mis),
            s.reuse.mcap,
            s.reuse.describe_temporal(),
            s.reuse.describe_shading(true),
            s.shift.name(),
            match s.reconnection {
                Reconnection::Fixed => format!("fixed near_distance={}", s.near_distance),
                Reconnection::Footprint => format!("footprint({})", s.footprint),
            },
            s.max_jacobian,
            s.direct.name(),
            if s.edge_rays > 1 {
                format!(" edge_rays={}", s.edge_rays)
            } else {
                String::new()
            },
            if s.is_unbiased() { "" } else { " (biased)" }
        )
    }

    fn halo(&self) -> u32 {
        self.settings.reuse.halo()
    }

    fn silhouettes(&self) -> Option<String> {
        self.seen.as_ref().and_then(SeenEmission::summary)
    }

    fn stage_seconds(&self) -> Vec<(&'static str, f64)> {
        self.clock.seconds()
    }

    /// The previous frame's reservoirs are reused through motion vectors. Where only the camera
    /// moved, every vertex, light index and cached suffix of a path means the same in both
    /// frames and the shift is the one between pixels; where shapes or lights moved, the shift
    /// between the two frames' domains walks in the destination frame's scene, `x_k` moving with
    /// its shape and what follows it evaluated there ([`shift::PtShift::shift_full`],
    /// `docs/ANIMATION.md`). `temporal_ignore_motion` (negative control only) shifts as if
    /// nothing but the camera had moved.
    fn next_frame(&self, motion: std::sync::Arc<FrameMotion>) {
        if let Some(di) = &self.di {
            di.next_frame(motion.clone()); // its light samples move with their lights
        }
        self.chain.next_frame();
        self.reuse.next_frame(Some(motion));
        if let Some(seen) = &self.seen {
            seen.clear();
        }
    }

    fn buffer_bytes(&self, width: u32, height: u32, threads: usize) -> u64 {
        let (w, h) = (width as usize, height as usize);
        (w * h) as u64 * self.bytes_per_pixel() as u64
            + reciprocal::table_bytes::<PathSample>(&self.settings.reuse, w, h, threads)
            + self
                .di
                .as_ref()
                .map_or(0, |d| d.buffer_bytes(width, height, threads))
    }

    fn render_pass(&self, scene: &Scene, ctx: &PassContext, accum: &mut [DVec3]) -> u64 {
        let s = &self.settings.reuse;
        if !self.chain.advance(ctx.seed, ctx.pass) {
            // Another render: the history of the passes before does not carry over, nor the
            // silhouette mask (the scene may have changed).
            self.reuse.next_frame(None);
            if let Some(seen) = &self.seen {
                seen.clear();
            }
        }
        let n = accum.len();
        // Emitters seen by the camera and the direct light at the primary hit (paths of one and
        // two segments) from ReSTIR DI; the reservoirs below carry the longer paths.
        let mut rays = self.di.as_ref().map_or(0, |di| {
            self.clock
                .time("direct (restir-di)", || di.render_pass(scene, ctx, accum))
        });
        let (gbuf, mut current, mut radiance, nr) = self.initial_reservoirs(scene, ctx);
        rays += nr;
        if self.max_depth() >= 2 {
            let history = self.reuse.take_history(s, n);
            // The previous frame, when the history is its last pass and more than the camera
            // moved.
            let frames = history
                .as_ref()
                .and_then(|h| h.motion.as_deref())
                .filter(|m| !m.scene_is_still() && !self.settings.temporal_ignore_motion)
                .map(|m| self.frames(m));
            let shift = PtReuse {
                walker: self.walker(scene),
                settings: &self.settings,
                gbuf: &gbuf,
                prev: history.as_ref().map(|h| &h.surfaces),
                frames,
                // Domains: pixel `i` of this pass is `i`, of the previous pass `n + i`.
                pixels: n,
            };
            let initial = self.diag.as_ref().map(|_| current.clone());
            let mut expected = self
                .recycled
                .lock()
                .map(|mut r| std::mem::take(&mut r.expected))
                .unwrap_or_default();
            let report = self.reuse.reuse_expected(
                &shift,
                s,
                ctx,
                &gbuf,
                history.as_ref(),
                STAGES,
                &mut current,
                s.shade_expected.then_some(&mut expected),
            );
            rays += self.clock.add_reuse(&report);
            if let (Some(d), Some(initial)) = (&self.diag, &initial) {
                let reach = s.radius.ceil() as i32 * s.spatial_rounds as i32;
                d.record(scene, &gbuf, initial, &current, reach);
            }
            self.clock.time("shade", || {
                radiance
                    .par_iter_mut()
                    .zip(current.par_iter())
                    .enumerate()
                    .for_each(|(i, (l, res))| {
                        // Every input of the last round with its weight, where known.
                        *l += match expected.get(i).copied().flatten() {
                            Some(e) => Vec3::from_array(e),
                            None => Self::shade(res),
                        }
                    })
            });
            if s.temporal {
                self.reuse.keep(s, gbuf, current);
            } else if let Ok(mut r) = self.recycled.lock() {
                r.gbuf = Some(gbuf);
                r.current = current;
            }
            if let Ok(mut r) = self.recycled.lock() {
                r.expected = expected;
            }
        }
        accum
            .par_iter_mut()
            .zip(radiance.par_iter())
            .for_each(|(a, l)| *a += l.as_dvec3());
        if let Ok(mut r) = self.recycled.lock() {
            r.radiance = radiance;
        }
        rays
    }
}
