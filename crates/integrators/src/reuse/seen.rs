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
//! stream; elsewhere it is the G-buffer ray's, as before. The mask depends on the camera, the
//! film window and the scene only (camera rays every half pixel, no random numbers), never on
//! the pass's samples, so every pixel's estimate stays unbiased and a split render gets the
//! same mask.

use std::sync::Mutex;

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use restir_scene::Scene;

use crate::film::Filter;
use crate::pass::PassContext;

/// A film window (width, height, x0, y0) and its silhouette mask.
type WindowMask = ((u32, u32, u32, u32), Vec<bool>);

/// Random-stream stage of the extra camera rays.
const STAGE_SEEN: u64 = 117;

/// The extra camera rays on silhouettes, with the mask of the current film window.
#[derive(Debug)]
pub struct SeenEmission {
    /// Camera rays for the seen emission on a silhouette pixel (the G-buffer's included).
    rays: u32,
    /// Negative control: the pixels whose own camera ray saw emission instead of the mask.
    from_pass: bool,
    /// The mask and the window it was made for: (width, height, x0, y0).
    mask: Mutex<Option<WindowMask>>,
}

/// What a camera ray sees, for the mask: 0 a surface that does not emit, `1 + light` an
/// emitter's shape, `u32::MAX` the environment (or nothing).
fn seen_id(scene: &Scene, film: Vec2) -> (u32, u64) {
    let ray = scene.camera.generate_ray(film, Vec2::splat(0.5));
    let (hit, rays) = scene.camera_intersect(&ray, false);
    let id = match hit {
        None => u32::MAX,
        Some(si) => scene.lights.light_on_shape(si.shape).map_or(0, |l| l + 1),
    };
    (id, rays)
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
    /// `rays` camera rays per silhouette pixel (more than 1).
    pub fn new(rays: u32, from_pass: bool) -> Self {
        Self {
            rays,
            from_pass,
            mask: Mutex::new(None),
        }
    }

    /// Forgets the mask (the camera or the scene moved).
    pub fn clear(&self) {
        if let Ok(mut m) = self.mask.lock() {
            *m = None;
        }
    }

    /// The silhouette mask of pass `ctx`'s window: pixels within whose filter's reach probes
    /// every half pixel see more than one thing (emitters, the environment, surfaces that do not
    /// emit), an area emitter among them. Made once per window; returns
    /// it and the rays traced.
    fn mask(&self, scene: &Scene, ctx: &PassContext) -> (Vec<bool>, u64) {
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
            return (mask.clone(), 0);
        }
        let reach = filter_reach(ctx.filter);
        let (wi, hi) = (w as i32, h as i32);
        // Probes every half pixel (film coordinates `p / 2`: pixel centres, edge midpoints and
        // corners) over the window and a border of `reach` pixels (the filter sees past it), so
        // an emitter showing as a sliver thinner than a pixel between two pixel centres is seen.
        let side = |n: i32| 2 * n - 1 + 4 * reach;
        let (bw, bh) = (side(wi), side(hi));
        let lo = 1 - 2 * reach;
        let ids: Vec<(u32, u64)> = (0..(bw * bh) as usize)
            .into_par_iter()
            .map(|i| {
                let (px, py) = ((i as i32 % bw) + lo, (i as i32 / bw) + lo);
                let film = Vec2::new(x0 as f32 + px as f32 * 0.5, y0 as f32 + py as f32 * 0.5);
                seen_id(scene, film)
            })
            .collect();
        let rays = ids.iter().map(|&(_, r)| r).sum();
        // Only area emitters: an environment behind a silhouette is about as bright as the
        // surface it lights, and there the seen emission and the reflected light of one camera
        // ray are anticorrelated (whichever the ray sees, the pixel gets about the same), so
        // estimating them with separate samples would add variance, not remove it.
        let emits = |v: u32| v != 0 && v != u32::MAX;
        let mask: Vec<bool> = (0..(wi * hi) as usize)
            .into_par_iter()
            .map(|i| {
                // The probes within the filter's reach of the pixel's centre.
                let (x, y) = (i as i32 % wi, i as i32 / wi);
                let (qx, qy) = (2 * x, 2 * y);
                let c = ids[((qy + 2 * reach) * bw + qx + 2 * reach) as usize].0;
                let mut any_emitter = false;
                let mut differs = false;
                for py in qy..=qy + 4 * reach {
                    let row = &ids[(py * bw + qx) as usize..=(py * bw + qx + 4 * reach) as usize];
                    for &(v, _) in row {
                        differs |= v != c;
                        any_emitter |= emits(v);
                    }
                }
                differs && any_emitter
            })
            .collect();
        if let Ok(mut m) = self.mask.lock() {
            *m = Some((key, mask.clone()));
        }
        (mask, rays)
    }

    /// Replaces the seen emission in `radiance` (what the G-buffer's camera rays added, and
    /// nothing else yet) by the mean over this many camera rays on the silhouette pixels.
    /// Returns the rays traced. Does nothing when the film splats: every camera ray of the pass
    /// goes through the pass's shared offset in its pixel, so more rays would repeat the
    /// G-buffer's, and the splatting already averages each pixel over its neighbours' rays.
    pub fn supersample(&self, scene: &Scene, ctx: &PassContext, radiance: &mut [Vec3]) -> u64 {
        if ctx.shared_offset.is_some() {
            return 0;
        }
        let (mask, mut rays) = if self.from_pass {
            (radiance.iter().map(|l| l.max_element() > 0.0).collect(), 0)
        } else {
            self.mask(scene, ctx)
        };
        let (w, _) = ctx.resolution(scene);
        let lights = &scene.lights;
        let extra = self.rays - 1;
        rays += radiance
            .par_iter_mut()
            .enumerate()
            .filter(|(i, _)| mask[*i])
            .map(|(i, l)| {
                let (x, y) = ((i % w as usize) as u32, (i / w as usize) as u32);
                let mut rng = ctx.stage_rng(i, STAGE_SEEN);
                let mut sum = *l;
                let mut rays = 0;
                for _ in 0..extra {
                    let film = ctx.film_position(x, y, &mut rng);
                    let ray = scene.camera.generate_ray(film, rng.next_2d());
                    let (hit, n) = scene.camera_intersect(&ray, false);
                    rays += n;
                    sum += match hit {
                        None => lights.environment_radiance(ray.d),
                        Some(si) => lights.light_on_shape(si.shape).map_or(Vec3::ZERO, |light| {
                            lights.area_radiance(light, si.shading.n, -ray.d)
                        }),
                    };
                }
                *l = sum / self.rays as f32;
                rays
            })
            .sum::<u64>();
        rays
    }
}
