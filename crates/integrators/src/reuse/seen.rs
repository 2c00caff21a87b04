//! The emission the camera sees, estimated with more camera rays on emitter silhouettes
//! (`edge_rays` of ReSTIR DI and PT, `docs/RESTIR_DI.md`, `docs/RESTIR_PT.md`).
//!
//! A pixel that an emitter's silhouette crosses averages the emitter's radiance, often hundreds
//! of times its surroundings', over the part of the pixel filter the emitter covers; one camera
//! ray per pass estimates that fraction with a variance no reuse can lower. Such pixels hold
//! most of ReSTIR PT's squared error in scenes with many small visible lamps
//! (`docs/studies/2026-12-03-restir-pt-error-concentration.md`), and a large share of ReSTIR
//! DI's where garlands of small emitters are in view.
//!
//! The pixel integral is the seen emission plus the light the primary hit reflects; both parts
//! can be estimated with their own samples. On the pixels of the silhouette mask the seen
//! emission is the mean of `n` camera rays, the G-buffer's and `n − 1` more drawn from their own
//! stream; elsewhere it is the G-buffer ray's, as before. `n` follows what the silhouette is
//! worth: one ray's variance there is at most a quarter of the squared contrast the pixel
//! straddles (the largest minus the smallest luminance its probes see), so for a given number
//! of rays the summed variance is least with `n` in proportion to that contrast (Neyman's
//! allocation). `n` is `edge_rays` times the pixel's contrast over the mean contrast of the
//! film's silhouette pixels, at least 1 and at most [`MAX_RAYS_FACTOR`] times `edge_rays`: the
//! rays `edge_rays` pays for on average, moved from dim lights' silhouettes to bright ones'.
//! An estimator may give the mask a budget ([`SILHOUETTE_BUDGET`], ReSTIR DI): where the mask
//! is a small part of the film, the mean is raised until the extra rays come to that many per
//! film pixel, at most [`MAX_BUDGET_RAISE`] times `edge_rays`, since there they cost little
//! beside a pass. The counts depend on the camera, the film and the scene only
//! (camera rays every half pixel, no random numbers), never on a pass's samples, so every
//! pixel's estimate stays unbiased and a split render (chains, tiles) gets the same counts.

use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use restir_geometry::{Ray, offset_ray_origin};
use restir_lights::NeeSelection;
use restir_sampling::{Pcg32, luminance};
use restir_scene::Scene;

use crate::film::{FilmSample, Filter, Reconstruction};
use crate::pass::PassContext;
use crate::path::rr_survival;
use crate::reuse::gbuffer::{GBuffer, Receiver};

mod image;
use image::EmitterImage;

/// A film window (width, height, x0, y0) and its mask: each pixel's camera rays for the seen
/// emission (0 off the mask).
type WindowMask = (Window, Arc<Vec<u16>>);

/// A film window: width, height and the film position of its first pixel.
type Window = (u32, u32, u32, u32);

/// How many camera rays a mask pixel of a splatting film gets.
///
/// There every ray of a pass goes through offsets the pass shares, and each reaches the pixels
/// within the filter's reach; a pixel gathers its neighbours' rays through the same offsets, so
/// its seen emission varies with where those offsets fall, about as much as one ray's would on
/// a sampled film (independent positions would lower it by the filter's variance factor, 0.31
/// for the Gaussian of σ = 0.5, but the shared offsets do not). Which count pays depends on
/// what else a pass's pixel estimate costs and holds (measured per estimator: `docs/RESTIR_DI.md`,
/// `docs/RESTIR_PT.md`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplatRays {
    /// `edge_rays` on every mask pixel (ReSTIR DI: its passes are cheap and their reflected
    /// light quiet, so the seen emission is most of a silhouette pixel's error).
    Each,
    /// `edge_rays` times the filter's variance factor, rounded, at least 1 (ReSTIR PT: 32 → 10;
    /// its passes' walks hold most of their error and cost).
    VarianceMatched,
}

/// The most camera rays a silhouette pixel gets, in multiples of its mean count.
pub const MAX_RAYS_FACTOR: u32 = 8;

/// ReSTIR DI's budget for the silhouettes' extra camera rays, per film pixel and pass: the
/// mask's mean count (on a splatting film, its one count) is raised to `1 + budget / share`
/// (`share` the film's fraction of mask pixels), at least `edge_rays` and at most
/// [`MAX_BUDGET_RAISE`] times it. Chosen on the DI training family at 640×360 (8 passes, seeds
/// 11 and 12, 1 thread): on its halls (2 and 5 % of the film on silhouettes) 16 rays are
/// 1.03–1.05× the relative efficiency of 4 and 3.0–3.6× its efficiency in squared error, for a
/// pass 1–5 % dearer; on the training Sponza with 2000 lamps (a splatting film, 27 % of it in
/// the mask, which the budget leaves at 4) 8 and 16 rays would cost 0.93× and 0.79×
/// (`docs/RESTIR_DI.md`, "Silhouettes").
pub const SILHOUETTE_BUDGET: f32 = 0.75;

/// How far [`SILHOUETTE_BUDGET`] may raise the mean count, in multiples of `edge_rays`.
pub const MAX_BUDGET_RAISE: u32 = 4;

/// Random-stream stage of the extra camera rays.
const STAGE_SEEN: u64 = 117;

/// The extra camera rays on silhouettes, with the mask of the current film window.
#[derive(Debug)]
pub struct SeenEmission {
    /// Camera rays for the seen emission on a silhouette pixel, the G-buffer's included: the
    /// mean over the film's silhouette pixels (each gets a count in proportion to its contrast).
    rays: u32,
    /// On a splatting film, whether a mask pixel's rays are `rays` times the filter's variance
    /// factor (ReSTIR PT) or `rays` (ReSTIR DI); see [`SplatRays`].
    splat: SplatRays,
    /// Extra camera rays per film pixel the mask may spend ([`SILHOUETTE_BUDGET`]; `None`: the
    /// counts stay as `rays` and `splat` give them).
    budget: Option<f32>,
    /// The mean count the current mask was made with on a sampling film, for `--stats`.
    mean_rays: AtomicU32,
    /// Negative control: the pixels whose own camera ray saw emission instead of the mask.
    from_pass: bool,
    /// The mask and the window it was made for: (width, height, x0, y0).
    mask: Mutex<Option<WindowMask>>,
    /// Whether the last pass followed the camera rays through delta lobes (for `--stats`).
    followed_delta: AtomicBool,
    /// The camera rays of a pixel near emitters on the current mask's splatting film (0: the
    /// film samples), for `--stats`.
    splatted_rays: AtomicU32,
}

/// What a camera ray sees, for the mask, twice: through the delta lobes of the surfaces it
/// meets with `chains` (the first lobe of every bounce, then the last: a smooth dielectric's
/// reflection and its transmission), once without. Each is 0 a surface that does not emit,
/// `1 + light` an emitter's shape, `u32::MAX` the environment (or nothing), with the luminance
/// of the emission seen (through the lobes, times their weights). Also returns the rays traced.
fn seen_id(scene: &Scene, film: Vec2, chains: Option<&DeltaChains>) -> ([(u32, f32); 2], u64) {
    let ray = scene.camera.generate_ray(film, Vec2::splat(0.5));
    let (hit, mut rays) = scene.camera_intersect(&ray, false);
    let lights = &scene.lights;
    let Some(si) = hit else {
        let seen = (u32::MAX, luminance(lights.environment_radiance(ray.d)));
        return ([seen; 2], rays);
    };
    if let Some(l) = lights.light_on_shape(si.shape) {
        let seen = (l + 1, luminance(lights.area_radiance(l, &si, -ray.d)));
        return ([seen; 2], rays);
    }
    let Some(chains) = chains else {
        return ([(0, 0.0); 2], rays);
    };
    let r = Receiver::at_hit(scene, &si, -ray.d, si.t);
    let mut probe = |u_lobe: f32| {
        let (le, id, n) = chains.probe(scene, &r, si.ng, u_lobe);
        rays += n;
        (id, luminance(le))
    };
    let seen = [probe(1e-4), probe(1.0 - 1e-4)];
    (seen, rays)
}

/// The emission the camera sees through delta lobes (smooth glass, mirrors, a smooth plastic's
/// coat): the paths of `max_segments` segments at most whose every bounce is a delta lobe,
/// ended on an emitter or the environment. An estimator whose other samples leave these paths
/// out (ReSTIR PT's walks, `docs/RESTIR_PT.md`) adds them here, with the silhouette mask's
/// camera rays where they show an emitter's edge or where the lobes' choice decides between an
/// emitter and a dark surface.
#[derive(Clone, Copy, Debug)]
pub struct DeltaChains {
    /// Longest path in segments from the camera.
    pub max_segments: u32,
    /// Russian roulette from this bounce on.
    pub rr_depth: u32,
}

impl DeltaChains {
    /// Probe bounces at most (the mask's rays only).
    const PROBE_BOUNCES: u32 = 8;

    /// One estimate of the emission reached from receiver `r` (geometric normal `ng`) through
    /// delta lobes: each bounce draws a lobe with `rng`; the walk ends at a lobe that is not
    /// delta (what lies behind belongs to the other samples), a miss, Russian roulette or the
    /// segment limit. Returns it and the rays traced.
    pub fn follow(&self, scene: &Scene, r: &Receiver, ng: Vec3, rng: &mut Pcg32) -> (Vec3, u64) {
        let (le, _, rays) = self.walk(scene, r, ng, self.max_segments, || {
            (rng.next_f32(), rng.next_2d(), rng.next_f32())
        });
        (le, rays)
    }

    /// The emission through the delta lobes drawn with `u_lobe` at every bounce (no Russian
    /// roulette, at most [`Self::PROBE_BOUNCES`]), the id of what the last ray saw as
    /// [`seen_id`] gives it, and the rays.
    fn probe(&self, scene: &Scene, r: &Receiver, ng: Vec3, u_lobe: f32) -> (Vec3, u32, u64) {
        let segments = self.max_segments.min(Self::PROBE_BOUNCES + 1);
        let chains = Self {
            rr_depth: u32::MAX,
            ..*self
        };
        chains.walk(scene, r, ng, segments, || (u_lobe, Vec2::splat(0.5), 0.0))
    }

    /// The walk behind [`Self::follow`] and [`Self::probe`]: `u()` gives each bounce's lobe
    /// number, direction numbers and roulette number.
    fn walk(
        &self,
        scene: &Scene,
        r: &Receiver,
        ng: Vec3,
        max_segments: u32,
        mut u: impl FnMut() -> (f32, Vec2, f32),
    ) -> (Vec3, u32, u64) {
        let (mut r, mut ng) = (*r, ng);
        let (mut beta, mut sum, mut eta_scale) = (Vec3::ONE, Vec3::ZERO, 1.0f32);
        let (mut id, mut rays) = (0, 0);
        // `j`: the vertex the bounce leaves; its ray's emission ends a path of j + 1 segments.
        let mut j = 1;
        while j < max_segments {
            let bsdf = r.resolve_bsdf(scene);
            if !bsdf.flags().is_delta() {
                break;
            }
            let (u_lobe, u_dir, u_rr) = u();
            let Some(bs) = bsdf.sample(r.wo, u_lobe, u_dir) else {
                break;
            };
            if !bs.lobe.is_delta() || bs.pdf_sa.is_nan() || bs.pdf_sa <= 0.0 {
                break;
            }
            beta *= bs.f / bs.pdf_sa;
            eta_scale *= bs.eta;
            if j >= self.rr_depth {
                let q = rr_survival(beta.max_element(), eta_scale);
                if q.is_nan() || q <= 0.0 || u_rr >= q {
                    break;
                }
                beta /= q;
            }
            if !(beta.max_element() > 0.0 && beta.is_finite()) {
                break;
            }
            let d = r.frame().to_world(bs.wi);
            let hit = scene.intersect(&Ray::new(offset_ray_origin(r.p, ng, d), d));
            rays += 1;
            if let Some((_, le, _)) =
                scene
                    .lights
                    .reached(NeeSelection::Power, (r.p, r.n), d, hit.as_ref())
            {
                sum += beta * le;
            }
            let Some(si) = hit else {
                id = u32::MAX;
                break;
            };
            id = scene.lights.light_on_shape(si.shape).map_or(0, |l| l + 1);
            r = Receiver::at_hit(scene, &si, -d, si.t);
            ng = si.ng;
            j += 1;
        }
        (sum, id, rays)
    }
}

/// The largest value within `r` pixels (along each axis) of every pixel of a `w × h` image.
fn spread_max(v: &[f32], (w, h): (usize, usize), r: usize) -> Vec<f32> {
    let window = |line: &[f32], i: usize| {
        line[i.saturating_sub(r)..(i + r + 1).min(line.len())]
            .iter()
            .fold(0.0f32, |a, &b| a.max(b))
    };
    let rows: Vec<f32> = v
        .chunks(w)
        .flat_map(|row| (0..w).map(move |x| window(row, x)))
        .collect();
    let mut out = vec![0.0; w * h];
    for x in 0..w {
        let column: Vec<f32> = (0..h).map(|y| rows[y * w + x]).collect();
        for y in 0..h {
            out[y * w + x] = window(&column, y);
        }
    }
    out
}

/// How far, in whole pixels, a pixel's filter reaches beyond its own square.
fn filter_reach(filter: &Filter) -> i32 {
    let radius = match filter {
        Filter::Box => 0.5,
        Filter::Tent { radius } | Filter::Tabulated { radius, .. } => *radius,
    };
    (radius - 0.5).max(0.0).ceil() as i32 + 1
}

impl SeenEmission {
    /// `rays` camera rays per silhouette pixel (more than 1), `splat` those of a splatting
    /// film's mask pixel, `budget` the extra rays per film pixel that may raise them.
    pub fn new(rays: u32, splat: SplatRays, budget: Option<f32>, from_pass: bool) -> Self {
        Self {
            rays,
            splat,
            budget,
            mean_rays: AtomicU32::new(rays),
            from_pass,
            mask: Mutex::new(None),
            followed_delta: AtomicBool::new(false),
            splatted_rays: AtomicU32::new(0),
        }
    }

    /// The camera rays of a pixel near emitters on a splatting film (`variance_factor` its
    /// [`Reconstruction::Splatted`] factor), as [`SplatRays`] says.
    fn splat_rays(&self, variance_factor: f64) -> u32 {
        let factor = match self.splat {
            SplatRays::VarianceMatched => variance_factor,
            SplatRays::Each => 1.0,
        };
        (f64::from(self.rays) * factor)
            .round()
            .clamp(1.0, f64::from(u16::MAX)) as u32
    }

    /// The splatting film's [`Self::splat_rays`] for `scene`, `None` when the film samples.
    fn splat_count(&self, scene: &Scene, ctx: &PassContext) -> Option<u32> {
        ctx.shared_offset?;
        match Reconstruction::decide(scene.filter) {
            Reconstruction::Splatted {
                variance_factor, ..
            } => Some(self.splat_rays(variance_factor)),
            Reconstruction::Sampled => None,
        }
    }

    /// What the current mask decided, one line: its pixels and the mean and largest camera-ray
    /// counts on them (`None` before the first pass or in the negative control).
    pub fn summary(&self) -> Option<String> {
        let m = self.mask.lock().ok()?;
        let ((w, h, _, _), mask) = m.as_ref()?;
        let on: Vec<u32> = mask
            .iter()
            .filter(|&&n| n > 0)
            .map(|&n| u32::from(n))
            .collect();
        let most = on.iter().copied().max().unwrap_or(0);
        let mean = on.iter().map(|&n| f64::from(n)).sum::<f64>() / on.len().max(1) as f64;
        let splatted = self.splatted_rays.load(Ordering::Relaxed);
        let decided = self.mean_rays.load(Ordering::Relaxed);
        let budget = self.budget.unwrap_or(0.0);
        let delta = if self.followed_delta.load(Ordering::Relaxed) {
            "; the emission seen through delta lobes (the scene has some) estimated here on every \
             pixel, the probes following each lobe's first and last choice"
        } else {
            ""
        };
        if splatted > 0 {
            return Some(format!(
                "{} of {} pixels within the splatting filter's reach of a pixel whose filter sees \
                 an emitter ({:.2} %), {splatted} camera rays each ({}) for the seen emission in \
                 place of the G-buffer's, through offsets the mask's pixels share that follow one \
                 stratified sequence over the passes{delta}",
                on.len(),
                w * h,
                100.0 * on.len() as f64 / f64::from((w * h).max(1)),
                match self.splat {
                    SplatRays::Each if splatted != self.rays => format!(
                        "edge_rays {}, raised to {splatted} by the budget of {budget} extra rays \
                         per film pixel",
                        self.rays
                    ),
                    SplatRays::Each => format!("edge_rays {}", self.rays),
                    SplatRays::VarianceMatched =>
                        format!("edge_rays {} times the filter's variance factor", self.rays),
                },
            ));
        }
        Some(
            format!(
                "{} of {} pixels on emitter silhouettes ({:.2} %), {mean:.1} camera rays each on average \
             (edge_rays {}{}: in proportion to the luminance contrast each straddles, at most {most} \
             here, at most {} allowed)",
                on.len(),
                w * h,
                100.0 * on.len() as f64 / f64::from((w * h).max(1)),
                self.rays,
                if decided == self.rays {
                    String::new()
                } else {
                    format!(
                        ", raised to {decided} by the budget of {budget} extra rays per film pixel"
                    )
                },
                decided * MAX_RAYS_FACTOR
            ) + delta,
        )
    }

    /// Forgets the mask (the camera or the scene moved).
    pub fn clear(&self) {
        if let Ok(mut m) = self.mask.lock() {
            *m = None;
        }
    }

    /// The contrast that each pixel of a `w × h` film straddles: the largest
    /// minus the smallest luminance seen by the probes within its filter's reach, on the
    /// pixels where those probes see more than one thing (emitters, the environment, surfaces
    /// that do not emit), an area emitter among them; 0 elsewhere. Probes are camera rays every
    /// half pixel (film coordinates `p / 2`: pixel centres, edge midpoints and corners) over the
    /// film and a border of `reach` pixels (the filter sees past it), so an emitter showing as
    /// a sliver thinner than a pixel between two pixel centres is seen; a pixel's value depends
    /// on its own neighbourhood only. Returns it and the rays traced.
    ///
    /// With `any` (a splatting film), a pixel's value is 1 wherever those probes see an area
    /// emitter at all, edge or not, and 0 elsewhere.
    fn contrast(
        scene: &Scene,
        reach: i32,
        (w, h): (u32, u32),
        chains: Option<&DeltaChains>,
        any: bool,
    ) -> (Vec<f32>, u64) {
        Self::contrast_probing(scene, reach, (w, h), chains, any, true)
    }

    /// [`Self::contrast`], tracing only the probes near an emitter's image (`near_only`, the
    /// same values) or every probe.
    fn contrast_probing(
        scene: &Scene,
        reach: i32,
        (w, h): (u32, u32),
        chains: Option<&DeltaChains>,
        any: bool,
        near_only: bool,
    ) -> (Vec<f32>, u64) {
        let (wi, hi) = (w as i32, h as i32);
        let side = |n: i32| 2 * n - 1 + 4 * reach;
        let (bw, bh) = (side(wi), side(hi));
        let lo = 1 - 2 * reach;
        // Probes whose every neighbour within two reaches sees no emitter decide nothing: a
        // pixel is on the mask only if a probe within its reach sees one, and then its value
        // depends on the probes within its reach alone. So only the probes near an emitter's
        // image are traced; the others are taken as a surface that does not emit.
        let near = near_only
            .then(|| EmitterImage::of(scene, chains, (lo as f32 * 0.5, reach), (bw, bh)))
            .flatten();
        let ids: Vec<([(u32, f32); 2], u64)> = (0..(bw * bh) as usize)
            .into_par_iter()
            .map(|i| {
                let (px, py) = ((i as i32 % bw) + lo, (i as i32 / bw) + lo);
                let film = Vec2::new(px as f32 * 0.5, py as f32 * 0.5);
                if near.as_ref().is_some_and(|n| !n.covers(film)) {
                    return ([(0, 0.0); 2], 0);
                }
                seen_id(scene, film, chains)
            })
            .collect();
        let rays = ids.iter().map(|&(_, r)| r).sum();
        // Only area emitters: an environment behind a silhouette is about as bright as the
        // surface it lights, and there the seen emission and the reflected light of one camera
        // ray are anticorrelated (whichever the ray sees, the pixel gets about the same), so
        // estimating them with separate samples would add variance, not remove it.
        let emits = |v: u32| v != 0 && v != u32::MAX;
        let contrast = (0..(wi * hi) as usize)
            .into_par_iter()
            .map(|i| {
                // The probes within the filter's reach of the pixel's centre.
                let (x, y) = (i as i32 % wi, i as i32 / wi);
                let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                if near.as_ref().is_some_and(|n| !n.covers(centre)) {
                    return 0.0; // no emitter's image within two reaches
                }
                let (qx, qy) = (2 * x, 2 * y);
                let c = ids[((qy + 2 * reach) * bw + qx + 2 * reach) as usize].0[0].0;
                let mut any_emitter = false;
                let mut differs = false;
                let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
                for py in qy..=qy + 4 * reach {
                    let row = &ids[(py * bw + qx) as usize..=(py * bw + qx + 4 * reach) as usize];
                    for &(v, l) in row.iter().flat_map(|(seen, _)| seen) {
                        differs |= v != c;
                        any_emitter |= emits(v);
                        lo = lo.min(l);
                        hi = hi.max(l);
                    }
                    if any && any_emitter {
                        break;
                    }
                }
                if any {
                    f32::from(u8::from(any_emitter))
                } else if differs && any_emitter {
                    (hi - lo).max(0.0)
                } else {
                    0.0
                }
            })
            .collect();
        (contrast, rays)
    }

    /// The mean count of the mask's pixels from the count `base` they would get: `base`, or
    /// with a budget `1 + budget / share` (`share` the fraction of the film's pixels in the
    /// mask) between `base` and [`MAX_BUDGET_RAISE`] times it. From the whole film's contrasts,
    /// so a window gets the untiled render's counts.
    fn raised(&self, base: u32, contrast: &[f32]) -> u32 {
        let Some(budget) = self.budget else {
            return base;
        };
        let on = contrast.iter().filter(|&&c| c > 0.0).count();
        if on == 0 {
            return base;
        }
        let share = on as f64 / contrast.len() as f64;
        let most = base.saturating_mul(MAX_BUDGET_RAISE);
        (1.0 + f64::from(budget) / share)
            .round()
            .clamp(f64::from(base), f64::from(most)) as u32
    }

    /// The mean contrast over the pixels of the mask (0 without any), summed in order so that
    /// it does not depend on the thread count.
    fn mean_contrast(contrast: &[f32]) -> f64 {
        let (sum, n) = contrast
            .iter()
            .filter(|&&c| c > 0.0)
            .fold((0.0f64, 0u64), |(s, n), &c| (s + f64::from(c), n + 1));
        if n > 0 { sum / n as f64 } else { 0.0 }
    }

    /// The camera rays for the seen emission of each pixel of pass `ctx`'s window (0 or 1: the
    /// G-buffer's only): `edge_rays` times the contrast the pixel straddles over the mean
    /// contrast of the whole film's silhouette pixels, at least 1 and at most
    /// [`MAX_RAYS_FACTOR`] times `edge_rays`. A window smaller than the film probes the whole
    /// film, for that mean, and takes its pixels' contrasts from it, so a tile gets the untiled
    /// render's counts. Made once per window; returns it and the rays traced.
    fn mask(
        &self,
        scene: &Scene,
        ctx: &PassContext,
        chains: Option<&DeltaChains>,
    ) -> (Arc<Vec<u16>>, u64) {
        let (w, h) = ctx.resolution(scene);
        let (x0, y0) = ctx
            .crop
            .as_ref()
            .map_or((0, 0), |c| (c.region.x0, c.region.y0));
        let key = (w, h, x0, y0);
        if let Ok(m) = self.mask.lock()
            && let Some((k, mask)) = m.as_ref()
            && *k == key
        {
            return (Arc::clone(mask), 0);
        }
        // A splatting film spreads each ray over the pixels within its reach `R`, and a pixel's
        // value stays steady only where all the rays it gathers went through the same offsets:
        // so every pixel whose filter (`R + 1` whole pixels) sees an emitter at all, and the `R`
        // pixels around it, get the same count (below), and what lies beyond sees no emitter.
        let splat = self.splat_count(scene, ctx);
        let splat_reach = splat.map(|_| Reconstruction::decide(scene.filter).reach() as i32);
        let reach = splat_reach.map_or_else(|| filter_reach(ctx.filter), |r| r + 1);
        let (fw, fh) = scene.camera.resolution();
        let (film, rays) = Self::contrast(scene, reach, (fw, fh), chains, splat.is_some());
        let film = match splat_reach {
            Some(r) if r > 0 => spread_max(&film, (fw as usize, fh as usize), r as usize),
            _ => film,
        };
        let mean = Self::mean_contrast(&film);
        let rays_mean = self.raised(self.rays, &film);
        self.mean_rays.store(rays_mean, Ordering::Relaxed);
        let splat = splat.map(|n| self.raised(n, &film));
        self.splatted_rays
            .store(splat.unwrap_or(0), Ordering::Relaxed);
        // A pixel's contrast depends on its own neighbourhood only: a window takes the film's
        // values (none beyond the film).
        let film_contrast = |x: u32, y: u32| {
            let (x, y) = (x0 + x, y0 + y);
            if x < fw && y < fh {
                film[(y * fw + x) as usize]
            } else {
                0.0
            }
        };
        let most = f64::from((rays_mean * MAX_RAYS_FACTOR).min(u32::from(u16::MAX)));
        let mask: Arc<Vec<u16>> = Arc::new(
            (0..w * h)
                .map(|i| {
                    let c = film_contrast(i % w, i / w);
                    if c <= 0.0 || mean <= 0.0 {
                        return 0;
                    }
                    if let Some(n) = splat {
                        // One count: the pixels' rays then share their offsets (`supersample`).
                        return n as u16;
                    }
                    let n = (f64::from(rays_mean) * f64::from(c) / mean).round();
                    n.clamp(1.0, most) as u16
                })
                .collect(),
        );
        if let Ok(mut m) = self.mask.lock() {
            *m = Some((key, Arc::clone(&mask)));
        }
        (mask, rays)
    }

    /// The emission a camera ray through film position `film` sees, through the delta lobes of
    /// the surface it meets with `chains`, and the rays traced.
    fn seen_through(
        scene: &Scene,
        film: Vec2,
        chains: Option<&DeltaChains>,
        rng: &mut Pcg32,
    ) -> (Vec3, u64) {
        let ray = scene.camera.generate_ray(film, rng.next_2d());
        let (hit, mut rays) = scene.camera_intersect(&ray, false);
        let lights = &scene.lights;
        let Some(si) = hit else {
            return (lights.environment_radiance(ray.d), rays);
        };
        let mut le = Vec3::ZERO;
        if let Some(light) = lights.light_on_shape(si.shape) {
            le += lights.area_radiance(light, &si, -ray.d);
        }
        if let Some(c) = chains {
            let r = Receiver::at_hit(scene, &si, -ray.d, si.t);
            let (behind, traced) = c.follow(scene, &r, si.ng, rng);
            le += behind;
            rays += traced;
        }
        (le, rays)
    }

    /// Replaces the seen emission in `radiance` (what the G-buffer's camera rays added, and
    /// nothing else yet) by the mean over this many camera rays on the silhouette pixels, and,
    /// with `chains`, adds on every pixel the emission its camera rays see through delta lobes
    /// (the G-buffer's ray continued from its hit `gbuf`, and each extra ray's). Returns the
    /// rays traced.
    ///
    /// When the film splats, every G-buffer ray of the pass goes through the pass's shared
    /// offset in its pixel, and each ray reaches several pixels. The mask is then every pixel
    /// within the filter's reach of a pixel whose filter sees an area emitter, each with the
    /// camera rays [`SplatRays`] gives (ReSTIR DI's 4 stay 4; ReSTIR PT's 32 become 10 for the
    /// Gaussian of σ = 0.5). These rays take the place of the G-buffer's for the seen emission
    /// (its share in `radiance` is dropped): ray `j` of every mask pixel goes through the same
    /// offset, drawn by the film from point `j` of the pass's block of a stratified sequence
    /// ([`PassContext::film_ray_points`], [`crate::film::FilmSamples::offset`]), so the filter
    /// weights a pixel gathers keep a constant sum and the rays of all passes together cover
    /// the pixel as one sequence's first points do, and is put in `ctx.samples` with its share,
    /// to be splatted from there ([`crate::film::FilmSample`]). Beyond the mask no pixel's
    /// filter sees an emitter, so pixels with one ray and pixels with several never mix where
    /// the emission is not zero. Without `ctx.samples`, or with one ray, no camera ray is
    /// added, and only the delta lobes' continuations of the G-buffer's ray are drawn as many
    /// times as the mask says.
    pub fn supersample(
        &self,
        scene: &Scene,
        ctx: &PassContext,
        gbuf: &GBuffer,
        chains: Option<&DeltaChains>,
        radiance: &mut [Vec3],
    ) -> u64 {
        self.followed_delta
            .store(chains.is_some(), Ordering::Relaxed);
        let splatted = ctx.shared_offset.is_some();
        // Splatting, more camera rays go through offsets of their own, which the film must take
        // ([`PassContext::samples`]); without them (or where one ray gives a pixel the variance
        // `rays` give a sampled film's) only what lies behind the G-buffer ray's delta lobes is
        // drawn again.
        let splat = self.splat_count(scene, ctx).unwrap_or(1);
        let own_offsets = splatted && splat > 1 && ctx.samples.is_some();
        if splatted && !own_offsets && chains.is_none() {
            return 0;
        }
        let (mask, mut rays) = if self.from_pass {
            // The counts the mask would give (a splatting film's for its pixels near emitters).
            let n = if splatted { splat } else { self.rays };
            let n = n.min(u32::from(u16::MAX)) as u16;
            let mask = radiance
                .iter()
                .map(|l| if l.max_element() > 0.0 { n } else { 0 });
            (Arc::new(mask.collect()), 0)
        } else {
            self.mask(scene, ctx, chains)
        };
        // The count the mask decided (the budget may have raised it), the same for every pass.
        let splat = match self.splatted_rays.load(Ordering::Relaxed) {
            n if splatted && !self.from_pass && n > 0 => n,
            _ => splat,
        };
        let (w, _) = ctx.resolution(scene);
        let (crop_x, crop_y) = ctx
            .crop
            .as_ref()
            .map_or((0, 0), |c| (c.region.x0, c.region.y0));
        // Splatting, the mask pixels' rays go through offsets of their own that every mask pixel
        // shares, so that the weights a pixel gathers from its neighbours' rays keep a constant
        // sum, and that over the passes follow one stratified sequence.
        let offsets: Vec<Vec2> = match ctx.samples.filter(|_| own_offsets) {
            Some(film) => ctx
                .film_ray_points(splat)
                .into_iter()
                .map(|v| film.offset(v))
                .collect(),
            None => Vec::new(),
        };
        // Per worker, the rays traced and the samples through offsets of their own (the film
        // orders them by pixel).
        let (traced, own) = radiance
            .par_iter_mut()
            .enumerate()
            .filter(|(i, _)| mask[*i] > 1 || chains.is_some())
            .fold(
                || (0u64, Vec::new()),
                |(mut rays, mut own), (i, l)| {
                    let mut rng = ctx.stage_rng(i, STAGE_SEEN);
                    // The G-buffer's ray: its seen emission, and behind its hit's delta lobes.
                    let receiver = chains.and_then(|c| Some((c, gbuf.receiver(i)?, gbuf.ng[i])));
                    let behind = |rng: &mut Pcg32, rays: &mut u64| {
                        receiver.map_or(Vec3::ZERO, |(c, r, ng)| {
                            let (le, n) = c.follow(scene, r, ng, rng);
                            *rays += n;
                            le
                        })
                    };
                    let n = u32::from(mask[i]).max(1);
                    let (x, y) = ((i % w as usize) as u32, (i / w as usize) as u32);
                    if own_offsets && n > 1 {
                        // Splatting, the G-buffer's ray leaves the seen emission to the pixel's
                        // rays through the offsets of their own, each put in the film with its
                        // share, to be splatted from there.
                        *l = Vec3::ZERO;
                        let corner = Vec2::new((x + crop_x) as f32, (y + crop_y) as f32);
                        let count = offsets.len() as f32;
                        for &offset in &offsets {
                            let (le, traced) =
                                Self::seen_through(scene, corner + offset, chains, &mut rng);
                            rays += traced;
                            own.push(FilmSample {
                                pixel: i as u32,
                                offset,
                                value: le / count,
                            });
                        }
                        return (rays, own);
                    }
                    let first = *l + behind(&mut rng, &mut rays);
                    if splatted {
                        // The same camera ray: only what lies behind delta lobes differs.
                        let mut sum = first;
                        if receiver.is_some() {
                            for _ in 1..n {
                                sum += *l + behind(&mut rng, &mut rays);
                            }
                            *l = sum / n as f32;
                        } else {
                            *l = sum;
                        }
                        return (rays, own);
                    }
                    // Sampling, the G-buffer's ray and `n − 1` more at positions of their own.
                    let mut sum = first;
                    for _ in 1..n {
                        let film = ctx.film_position(x, y, &mut rng);
                        let (le, traced) = Self::seen_through(scene, film, chains, &mut rng);
                        sum += le;
                        rays += traced;
                    }
                    *l = sum / n as f32;
                    (rays, own)
                },
            )
            .reduce(
                || (0, Vec::new()),
                |(a, mut x), (b, y)| {
                    x.extend(y);
                    (a + b, x)
                },
            );
        rays += traced;
        if let Some(sink) = ctx.samples.filter(|_| !own.is_empty()) {
            sink.add(own);
        }
        rays
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A film with `on` of its 1000 pixels on silhouettes.
    fn film(on: usize) -> Vec<f32> {
        (0..1000).map(|i| if i < on { 2.0 } else { 0.0 }).collect()
    }

    /// The budget raises a small mask's mean count to `1 + budget / share`, between `edge_rays`
    /// and `MAX_BUDGET_RAISE` times it; without a budget, or without a mask, it stays.
    #[test]
    fn the_budget_raises_a_small_masks_mean_within_its_bounds() {
        let di = SeenEmission::new(4, SplatRays::Each, Some(0.75), false);
        assert_eq!(di.raised(4, &film(20)), 16, "2 %: 38.5, capped at 4 × 4");
        assert_eq!(di.raised(4, &film(100)), 9, "10 %: 8.5, rounded");
        assert_eq!(di.raised(4, &film(500)), 4, "50 %: 2.5, at least edge_rays");
        assert_eq!(di.raised(4, &film(0)), 4);
        let pt = SeenEmission::new(32, SplatRays::VarianceMatched, None, false);
        assert_eq!(pt.raised(32, &film(20)), 32);
    }
}
