//! ReSTIR PT (Lin et al. 2022): reservoir-based path reuse across pixels with the reconnection
//! shift, combined unbiasedly with the MIS schemes of `restir-gris` (`docs/RESTIR_PT.md`).
//!
//! One pass, for every pixel at once (ALGORITHMS.md §4):
//!
//! 1. **Primary hits** ([`GBuffer`]), adding what the camera sees directly.
//! 2. **Initial sampling**: `--candidates` random walks from the primary hit with next-event
//!    estimation and BSDF sampling (power heuristic and Russian roulette as the path tracer);
//!    every light connection is one candidate with resampling weight `lum(contribution)/N`.
//!    Only paths whose first bounce used a non-delta lobe are sampled here; the reservoir counts
//!    as confidence 1.
//!    With `direct = path` the direct-light connections at `x1` are summed per pixel instead.
//! 3. **Temporal reuse** (optional): the pixel's reservoir of the previous pass, its domain the
//!    previous pass's primary hit, generalized balance MIS, confidence capped at `mcap`.
//! 4. **Spatial reuse**: `R` rounds of `k` neighbours (pattern and similarity tests as ReSTIR
//!    DI) resampled through [`restir_gris::resample`] with the reconnection shift
//!    ([`sample::PtShift`]). Confidence is capped at `mcap` after every round.
//! 5. **Shading**: the selected path's integrand at the pixel times `W`, plus the paths whose
//!    first bounce is a delta lobe, path traced.

pub mod sample;
mod settings;

use std::cell::Cell;
use std::sync::Mutex;

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use restir_geometry::{Ray, offset_ray_origin, shadow_ray_between, shadow_ray_towards};
use restir_gris::{MisScheme, Reservoir, StreamingReservoir, resample};
use restir_materials::LobeFlags;
use restir_sampling::{Pcg32, luminance, warp::power_heuristic};
use restir_scene::Scene;

pub use sample::{Kind, PathSample, PtShift};
pub use settings::{RestirPtSettings, SHIFT_NAMES};

use crate::gbuffer::{GBuffer, Receiver};
use crate::neighbors::{NeighborPattern, NeighborRule};
use crate::path::{EmissionMis, PrevVertex, trace_path};
use crate::render::{BAND_ROWS, Integrator, PassContext};
use crate::restir_di::light_point::LightPoint;
use crate::restir_di::mis_name;
use sample::{evaluate_unshadowed, resolve_vertex};

/// Random-stream stages (see [`PassContext::stage_rng`]).
const STAGE_INITIAL: u64 = 101;
const STAGE_TEMPORAL: u64 = 102;
const STAGE_SHADE: u64 = 103;
const STAGE_SPATIAL: u64 = 116;

/// The reservoir type.
pub type PtReservoir = Reservoir<PathSample>;

/// What temporal reuse keeps from the previous pass.
#[derive(Debug)]
struct History {
    gbuffer: GBuffer,
    reservoirs: Vec<PtReservoir>,
}

/// The ReSTIR PT estimator (`--integrator restir-pt`).
#[derive(Debug)]
pub struct RestirPtIntegrator {
    settings: RestirPtSettings,
    pattern: NeighborPattern,
    history: Mutex<Option<History>>,
}

/// Collects a walk's candidates.
struct Candidates<'a> {
    stream: &'a mut StreamingReservoir<PathSample>,
    scale: f32,
    /// Whether direct-light paths are path traced instead of resampled.
    direct_path_traced: bool,
    /// Their sum (already divided by the number of walks).
    direct: Vec3,
}

impl Candidates<'_> {
    #[inline]
    fn push(&mut self, sample: PathSample, contribution: Vec3, rng: &mut Pcg32) {
        if self.direct_path_traced && sample.is_direct() {
            if contribution.is_finite() {
                self.direct += contribution * self.scale;
            }
            return;
        }
        let u = rng.next_f32();
        let w = luminance(contribution) * self.scale;
        if w > 0.0 && w.is_finite() {
            self.stream.add(sample, w, u);
        }
    }
}

impl RestirPtIntegrator {
    /// An integrator with `settings`.
    pub fn new(settings: RestirPtSettings) -> Self {
        Self {
            settings,
            pattern: NeighborPattern::new(),
            history: Mutex::new(None),
        }
    }

    /// The settings.
    pub fn settings(&self) -> &RestirPtSettings {
        &self.settings
    }

    /// Bytes per pixel of one reservoir buffer.
    pub const RESERVOIR_BYTES: usize = std::mem::size_of::<PtReservoir>();

    fn max_depth(&self) -> u32 {
        let d = self.settings.path.max_depth;
        if d < 0 { u32::MAX } else { d as u32 }
    }

    /// The shift map over the pixels of `gbuf`.
    pub fn shift_map<'a>(&self, scene: &'a Scene, gbuf: &'a GBuffer) -> PtShift<'a> {
        let d = self.settings.near_distance * scene.lights.scene_radius();
        PtShift {
            scene,
            gbuf,
            prev: None,
            rays: Cell::new(0),
            near_distance2: d * d,
            max_jacobian: self.settings.max_jacobian,
            unit_jacobian: self.settings.unit_jacobian,
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
        let (w, h) = scene.camera.resolution();
        let n = w as usize * h as usize;
        let mut radiance = vec![Vec3::ZERO; n];
        let keep = self.max_depth() >= 2;
        let (gbuf, mut rays) =
            GBuffer::trace(scene, ctx, s.path.hide_emitters, keep, &mut radiance);
        let mut current = vec![PtReservoir::empty(); n];
        if keep {
            let w = gbuf.width;
            rays += current
                .par_chunks_mut(w * BAND_ROWS)
                .zip(radiance.par_chunks_mut(w * BAND_ROWS))
                .enumerate()
                .map(|(band, (out, rad))| {
                    let mut rays = 0;
                    for (i, (res, l)) in out.iter_mut().zip(rad.iter_mut()).enumerate() {
                        let index = band * w * BAND_ROWS + i;
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
                })
                .sum::<u64>();
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
        let bsdf = &r.resolve_bsdf(scene);
        let empty = Reservoir {
            confidence: 1.0,
            ..Reservoir::empty()
        };
        if !bsdf.has_smooth_lobe() {
            return (empty, Vec3::ZERO, 0);
        }
        let n = self.settings.candidates;
        let mut stream = StreamingReservoir::new();
        let mut cands = Candidates {
            stream: &mut stream,
            scale: 1.0 / n as f32,
            direct_path_traced: self.settings.direct_path_traced,
            direct: Vec3::ZERO,
        };
        let mut rays = 0;
        for _ in 0..n {
            rays += self.walk(scene, r, ng, rng, &mut cands);
        }
        let direct = cands.direct;
        let Some(y) = stream.selected().copied() else {
            return (empty, direct, rays);
        };
        let v = resolve_vertex(scene, &y);
        let (f, _) = evaluate_unshadowed(scene, r, &y, &v);
        let mut res = stream.finalize(luminance(f));
        res.confidence = 1.0;
        (res, direct, rays)
    }

    /// One random walk from the primary hit; streams its light connections. Returns the rays.
    #[allow(clippy::too_many_lines)]
    fn walk(
        &self,
        scene: &Scene,
        r: &Receiver,
        ng: Vec3,
        rng: &mut Pcg32,
        cands: &mut Candidates,
    ) -> u64 {
        let lights = &scene.lights;
        let shapes = &scene.shapes;
        let max_depth = self.max_depth();
        let rr_depth = self.settings.path.rr_depth;
        let mut rays = 0u64;
        let frame1 = r.frame();
        let bsdf1 = &r.resolve_bsdf(scene);

        // Light sampling at x1: the path reconnects at its light point.
        let (u_select, u_light) = (rng.next_f32(), rng.next_2d());
        if let Some(ls) = lights.sample(shapes, r.p, u_select, u_light) {
            let wi = frame1.to_local(ls.wi);
            let f = bsdf1.eval(r.wo, wi);
            if f != Vec3::ZERO {
                rays += 1;
                if shadow_visible(scene, r.p, ng, ls.p, ls.wi, ls.dist) {
                    let w = if ls.delta {
                        1.0
                    } else {
                        power_heuristic(ls.pdf_sa, bsdf1.pdf_sa(r.wo, wi))
                    };
                    let sample =
                        PathSample::direct(LightPoint::from_light_sample(&ls), Kind::DirectNee);
                    cands.push(sample, f * ls.le * (w / ls.pdf_sa), rng);
                }
            }
        }

        // BSDF sampling at x1 (the delta part of x1 is path traced at shading).
        let Some(bs) = bsdf1.sample(r.wo, rng.next_f32(), rng.next_2d()) else {
            return rays;
        };
        if bs.lobe.is_delta() {
            return rays;
        }
        let mut beta = bs.f / bs.pdf_sa;
        let mut eta_scale = bs.eta;
        if !russian_roulette(&mut beta, eta_scale, 1, rr_depth, rng) {
            return rays;
        }
        let d1 = frame1.to_world(bs.wi);
        let ray = Ray::new(offset_ray_origin(r.p, ng, d1), d1);
        rays += 1;
        let Some(si2) = scene.intersect(&ray) else {
            if let Some(env) = lights.environment() {
                let le = lights.environment_radiance(d1);
                let lp = lights.pdf_sa(shapes, env, r.p, r.p + d1, -d1);
                let w = power_heuristic(bs.pdf_sa, lp);
                let sample = PathSample::direct(LightPoint::environment(env, d1), Kind::DirectHit);
                cands.push(sample, beta * le * w, rng);
            }
            return rays;
        };
        if let Some(light) = lights.light_on_shape(si2.shape) {
            let le = lights.area_radiance(light, si2.shading.n, -d1);
            if le != Vec3::ZERO {
                let lp = lights.pdf_sa(shapes, light, r.p, si2.p, si2.ng);
                let w = power_heuristic(bs.pdf_sa, lp);
                let sample = PathSample::direct(
                    LightPoint {
                        light,
                        prim: si2.prim,
                        param: si2.param,
                    },
                    Kind::DirectHit,
                );
                cands.push(sample, beta * le * w, rng);
            }
        }
        if max_depth < 3 {
            return rays;
        }

        // x2: the reconnection vertex.
        let base = PathSample {
            id: si2.shape,
            prim: si2.prim,
            param: si2.param,
            dir: Vec3::ZERO,
            radiance: Vec3::ZERO,
            light_pdf: 0.0,
            kind: Kind::Continue,
            length: 3,
        };
        let bsdf2 = scene.bsdf(&si2);
        let wo2 = si2.shading.to_local(-d1);
        let (u_select, u_light) = (rng.next_f32(), rng.next_2d());
        if bsdf2.has_smooth_lobe()
            && let Some(ls) = lights.sample(shapes, si2.p, u_select, u_light)
        {
            let wi = si2.shading.to_local(ls.wi);
            let f = bsdf2.eval(wo2, wi);
            if f != Vec3::ZERO {
                rays += 1;
                if shadow_visible(scene, si2.p, si2.ng, ls.p, ls.wi, ls.dist) {
                    let w = if ls.delta {
                        1.0
                    } else {
                        power_heuristic(ls.pdf_sa, bsdf2.pdf_sa(wo2, wi))
                    };
                    let sample = PathSample {
                        dir: ls.wi,
                        radiance: ls.le,
                        light_pdf: if ls.delta { 0.0 } else { ls.pdf_sa },
                        kind: Kind::NeeAtX2,
                        ..base
                    };
                    cands.push(sample, beta * f * ls.le * (w / ls.pdf_sa), rng);
                }
            }
        }
        let Some(bs2) = bsdf2.sample(wo2, rng.next_f32(), rng.next_2d()) else {
            return rays;
        };
        let frozen = bs2.lobe.is_delta();
        let t2 = bs2.f; // x2's term of a frozen path
        beta *= bs2.f / bs2.pdf_sa;
        eta_scale *= bs2.eta;
        if !russian_roulette(&mut beta, eta_scale, 2, rr_depth, rng) {
            return rays;
        }
        let d2 = si2.shading.to_world(bs2.wi);
        let suffix = |kind: Kind, radiance: Vec3, light_pdf: f32, length: u32| {
            if frozen {
                PathSample {
                    radiance: t2 * radiance,
                    kind: Kind::Frozen,
                    length: length.min(255) as u8,
                    ..base
                }
            } else {
                PathSample {
                    dir: d2,
                    radiance,
                    light_pdf,
                    kind,
                    length: length.min(255) as u8,
                    ..base
                }
            }
        };

        // The rest of the walk: `rest` is the throughput after x2 (without Russian roulette).
        let mut rest = Vec3::ONE;
        let mut prev = PrevVertex {
            p: si2.p,
            pdf_sa: bs2.pdf_sa,
            delta: bs2.lobe.is_delta(),
            mis: EmissionMis::Power,
        };
        let mut ray = Ray::new(offset_ray_origin(si2.p, si2.ng, d2), d2);
        // Segments from the camera to the vertex the ray will hit.
        let mut length = 3u32;
        loop {
            rays += 1;
            let Some(si) = scene.intersect(&ray) else {
                if let Some(env) = lights.environment() {
                    let le = lights.environment_radiance(ray.d);
                    let lp = lights.pdf_sa(shapes, env, prev.p, prev.p + ray.d, -ray.d);
                    let w = prev.emission_weight(lp);
                    let sample = if length == 3 {
                        suffix(Kind::HitAtX3, le, lp, length)
                    } else {
                        suffix(Kind::Continue, rest * le * w, 0.0, length)
                    };
                    cands.push(sample, beta * le * w, rng);
                }
                break;
            };
            if let Some(light) = lights.light_on_shape(si.shape) {
                let le = lights.area_radiance(light, si.shading.n, -ray.d);
                if le != Vec3::ZERO {
                    let lp = lights.pdf_sa(shapes, light, prev.p, si.p, si.ng);
                    let w = prev.emission_weight(lp);
                    let sample = if length == 3 {
                        suffix(Kind::HitAtX3, le, if prev.delta { 0.0 } else { lp }, length)
                    } else {
                        suffix(Kind::Continue, rest * le * w, 0.0, length)
                    };
                    cands.push(sample, beta * le * w, rng);
                }
            }
            // Connections from this vertex have `length + 1` segments.
            if length + 1 > max_depth {
                break;
            }
            let bsdf = scene.bsdf(&si);
            let wo = si.shading.to_local(-ray.d);
            let (u_select, u_light) = (rng.next_f32(), rng.next_2d());
            if bsdf.has_smooth_lobe()
                && let Some(ls) = lights.sample(shapes, si.p, u_select, u_light)
            {
                let wi = si.shading.to_local(ls.wi);
                let f = bsdf.eval(wo, wi);
                if f != Vec3::ZERO {
                    rays += 1;
                    if shadow_visible(scene, si.p, si.ng, ls.p, ls.wi, ls.dist) {
                        let w = if ls.delta {
                            1.0
                        } else {
                            power_heuristic(ls.pdf_sa, bsdf.pdf_sa(wo, wi))
                        };
                        let l = f * ls.le * (w / ls.pdf_sa);
                        let sample = suffix(Kind::Continue, rest * l, 0.0, length + 1);
                        cands.push(sample, beta * l, rng);
                    }
                }
            }
            let Some(bs) = bsdf.sample(wo, rng.next_f32(), rng.next_2d()) else {
                break;
            };
            let t = bs.f / bs.pdf_sa;
            rest *= t;
            beta *= t;
            eta_scale *= bs.eta;
            if !russian_roulette(&mut beta, eta_scale, length, rr_depth, rng) {
                break;
            }
            let d = si.shading.to_world(bs.wi);
            prev = PrevVertex {
                p: si.p,
                pdf_sa: bs.pdf_sa,
                delta: bs.lobe.is_delta(),
                mis: EmissionMis::Power,
            };
            ray = Ray::new(offset_ray_origin(si.p, si.ng, d), d);
            length += 1;
        }
        rays
    }

    /// One spatial round at pixel `index`.
    #[allow(clippy::too_many_arguments)]
    fn spatial<'a>(
        &self,
        shift: &PtShift,
        gbuf: &GBuffer,
        input: &'a [PtReservoir],
        indices: &'a [usize],
        index: usize,
        rng: &mut Pcg32,
        picked: &mut Vec<usize>,
        neighbors: &mut Vec<(&'a usize, &'a PtReservoir)>,
    ) -> PtReservoir {
        let canonical = &input[index];
        if gbuf.receiver(index).is_none() {
            return *canonical;
        }
        let rule = NeighborRule {
            count: self.settings.neighbors as usize,
            radius: self.settings.radius,
            normal_cos: self.settings.normal_cos,
            depth_tolerance: self.settings.depth_tolerance,
        };
        self.pattern.select(gbuf, index, &rule, rng, picked);
        neighbors.clear();
        neighbors.extend(picked.iter().map(|&q| (&indices[q], &input[q])));
        resample(
            shift,
            self.settings.mis,
            &indices[index],
            canonical,
            neighbors,
            || rng.next_f32(),
        )
        .with_confidence_cap(self.settings.mcap)
    }

    /// Shading: the reservoir's path times `W`, plus the delta part of the primary hit.
    fn shade(
        &self,
        scene: &Scene,
        r: &Receiver,
        ng: Vec3,
        res: &PtReservoir,
        rng: &mut Pcg32,
    ) -> (Vec3, u64) {
        let mut l = Vec3::ZERO;
        let mut rays = 0;
        if let Some(y) = &res.sample {
            let v = resolve_vertex(scene, y);
            let (f, _) = evaluate_unshadowed(scene, r, y, &v);
            l += f * res.ucw;
        }
        let bsdf = &r.resolve_bsdf(scene);
        if bsdf.flags().intersects(LobeFlags::DELTA) {
            let settings = &self.settings.path;
            let (u_lobe, u_dir, u_rr) = (rng.next_f32(), rng.next_2d(), rng.next_f32());
            if let Some(bs) = bsdf.sample(r.wo, u_lobe, u_dir)
                && bs.lobe.is_delta()
            {
                let mut beta = bs.f / bs.pdf_sa;
                let mut alive = true;
                if settings.rr_depth <= 1 {
                    let q = (beta.max_element() * bs.eta * bs.eta).min(0.95);
                    alive = u_rr < q;
                    beta /= q;
                }
                if alive && beta.is_finite() && beta.max_element() > 0.0 {
                    let d = r.frame().to_world(bs.wi);
                    let ray = Ray::new(offset_ray_origin(r.p, ng, d), d);
                    let prev = PrevVertex {
                        p: r.p,
                        pdf_sa: bs.pdf_sa,
                        delta: true,
                        mis: EmissionMis::Power,
                    };
                    let (li, n) = trace_path(scene, settings, ray, 1, beta, Some(prev), rng);
                    l += li;
                    rays += n;
                }
            }
        }
        (l, rays)
    }
}

/// Russian roulette after the bounce that made the path `depth` segments long, as the path
/// tracer does it. Returns whether the path survives (`beta` is divided by the survival
/// probability).
#[inline]
fn russian_roulette(
    beta: &mut Vec3,
    eta_scale: f32,
    depth: u32,
    rr_depth: u32,
    rng: &mut Pcg32,
) -> bool {
    let u = rng.next_f32();
    let bmax = beta.max_element();
    if !(bmax > 0.0 && beta.is_finite()) {
        return false;
    }
    if depth >= rr_depth {
        let q = (bmax * eta_scale * eta_scale).min(0.95);
        if u >= q {
            return false;
        }
        *beta /= q;
    }
    true
}

/// Whether a light sample is visible from surface point `p`.
#[inline]
fn shadow_visible(scene: &Scene, p: Vec3, ng: Vec3, lp: Vec3, wi: Vec3, dist: f32) -> bool {
    let (ray, t_max) = if dist.is_finite() {
        shadow_ray_between(p, ng, lp)
    } else {
        shadow_ray_towards(p, ng, wi, f32::INFINITY)
    };
    !scene.occluded(&ray, t_max)
}

impl Integrator for RestirPtIntegrator {
    fn name(&self) -> &'static str {
        "restir-pt"
    }

    fn describe(&self) -> String {
        let s = &self.settings;
        format!(
            "restir-pt max_depth={} candidates={} neighbors={} radius={} spatial_rounds={} \
             mis={} mcap={} temporal={} shift=reconnection near_distance={} max_jacobian={} direct={}{}",
            s.path.max_depth,
            s.candidates,
            s.neighbors,
            s.radius,
            s.spatial_rounds,
            mis_name(s.mis),
            s.mcap,
            s.temporal,
            s.near_distance,
            s.max_jacobian,
            if s.direct_path_traced {
                "path"
            } else {
                "reservoir"
            },
            if s.is_unbiased() { "" } else { " (biased)" }
        )
    }

    fn buffer_bytes_per_pixel(&self) -> usize {
        let hit_bytes = std::mem::size_of::<Receiver>() + std::mem::size_of::<Vec3>();
        let (reservoirs, hits) = if self.settings.temporal {
            (3, 2)
        } else {
            (2, 1)
        };
        reservoirs * Self::RESERVOIR_BYTES + hits * hit_bytes + std::mem::size_of::<Vec3>()
    }

    fn render_pass(&self, scene: &Scene, ctx: &PassContext, accum: &mut [DVec3]) -> u64 {
        let s = &self.settings;
        let n = accum.len();
        let (gbuf, mut current, mut radiance, mut rays) = self.initial_reservoirs(scene, ctx);
        if self.max_depth() >= 2 {
            let w = gbuf.width;
            let history = if s.temporal {
                self.history.lock().map(|mut h| h.take()).unwrap_or(None)
            } else {
                None
            };
            let history = history.filter(|h| h.reservoirs.len() == n);
            // One shift map per band: it counts the shadow rays its shifts trace.
            let shift_for = |temporal: bool| {
                let mut shift = self.shift_map(scene, &gbuf);
                if temporal {
                    shift.prev = history.as_ref().map(|h| &h.gbuffer);
                }
                shift
            };
            // Domains: pixel `i` of this pass is `i`, of the previous pass `n + i`.
            let indices: Vec<usize> = (0..2 * n).collect();
            if let Some(hist) = &history {
                // Two techniques, one carrying up to `mcap` passes of history: the generalized
                // balance heuristic, as ReSTIR DI's temporal reuse.
                let temporal_mis = if s.mis.is_unbiased() {
                    MisScheme::GeneralizedBalance
                } else {
                    s.mis
                };
                rays += current
                    .par_chunks_mut(w * BAND_ROWS)
                    .enumerate()
                    .map(|(band, out)| {
                        let shift = shift_for(true);
                        for (i, res) in out.iter_mut().enumerate() {
                            let index = band * w * BAND_ROWS + i;
                            let (Some(r), Some(prev_r)) =
                                (gbuf.receiver(index), hist.gbuffer.receiver(index))
                            else {
                                continue;
                            };
                            if !r.is_similar(prev_r, s.normal_cos, s.depth_tolerance) {
                                continue;
                            }
                            let prev = hist.reservoirs[index].with_confidence_cap(s.mcap);
                            let mut rng = ctx.stage_rng(index, STAGE_TEMPORAL);
                            *res = resample(
                                &shift,
                                temporal_mis,
                                &indices[index],
                                res,
                                &[(&indices[n + index], &prev)],
                                || rng.next_f32(),
                            )
                            .with_confidence_cap(s.mcap);
                        }
                        shift.rays.get()
                    })
                    .sum::<u64>();
            }
            if s.neighbors > 0 && s.spatial_rounds > 0 {
                let mut next = vec![PtReservoir::empty(); n];
                for round in 0..s.spatial_rounds {
                    let input = &current;
                    rays += next
                        .par_chunks_mut(w * BAND_ROWS)
                        .enumerate()
                        .map(|(band, out)| {
                            let shift = shift_for(false);
                            let mut picked = Vec::with_capacity(s.neighbors as usize);
                            let mut scratch = Vec::with_capacity(s.neighbors as usize);
                            for (i, res) in out.iter_mut().enumerate() {
                                let index = band * w * BAND_ROWS + i;
                                let mut rng =
                                    ctx.stage_rng(index, STAGE_SPATIAL + u64::from(round));
                                *res = self.spatial(
                                    &shift,
                                    &gbuf,
                                    input,
                                    &indices,
                                    index,
                                    &mut rng,
                                    &mut picked,
                                    &mut scratch,
                                );
                            }
                            shift.rays.get()
                        })
                        .sum::<u64>();
                    std::mem::swap(&mut current, &mut next);
                }
            }
            rays += radiance
                .par_chunks_mut(w * BAND_ROWS)
                .enumerate()
                .map(|(band, out)| {
                    let mut rays = 0;
                    for (i, l) in out.iter_mut().enumerate() {
                        let index = band * w * BAND_ROWS + i;
                        if let Some(r) = gbuf.receiver(index) {
                            let mut rng = ctx.stage_rng(index, STAGE_SHADE);
                            let (li, nr) =
                                self.shade(scene, r, gbuf.ng[index], &current[index], &mut rng);
                            *l += li;
                            rays += nr;
                        }
                    }
                    rays
                })
                .sum::<u64>();
            if s.temporal
                && let Ok(mut h) = self.history.lock()
            {
                *h = Some(History {
                    gbuffer: gbuf,
                    reservoirs: current,
                });
            }
        }
        accum
            .par_iter_mut()
            .zip(radiance.par_iter())
            .for_each(|(a, l)| *a += l.as_dvec3());
        rays
    }
}
