//! Primary hits for a whole image (a G-buffer), the first stage of the screen-space ReSTIR
//! estimators. Camera rays are jittered by the film's filter with the pixel's pass stream, the
//! same numbers the path tracer draws first, so both see the same pixel footprint.

use glam::Vec3;
use rayon::prelude::*;
use restir_geometry::Frame;
use restir_scene::Scene;

use crate::render::{BAND_ROWS, PassContext};

/// What a reuse pass needs to know about a pixel's primary hit: the shading point, its material,
/// the direction to the camera, and what the neighbour-similarity tests compare.
#[derive(Clone, Copy, Debug)]
pub struct Receiver {
    /// Hit position.
    pub p: Vec3,
    /// Geometric normal (for ray offsets).
    pub ng: Vec3,
    /// Shading frame.
    pub frame: Frame,
    /// Direction towards the camera in the shading frame.
    pub wo: Vec3,
    /// Index of the BSDF in `Scene::bsdfs`.
    pub bsdf: u32,
    /// Distance from the camera.
    pub depth: f32,
}

impl Receiver {
    /// Whether `other` is similar enough to be a reuse neighbour: shading normals within
    /// `normal_cos` (cosine of the largest angle) and camera distances within a relative
    /// `depth_tolerance` (ALGORITHMS.md §2.4). These tests only pick participating domains;
    /// the estimators stay unbiased whatever they decide.
    #[inline]
    pub fn is_similar(&self, other: &Receiver, normal_cos: f32, depth_tolerance: f32) -> bool {
        self.frame.n.dot(other.frame.n) >= normal_cos
            && (self.depth - other.depth).abs() <= depth_tolerance * self.depth.max(other.depth)
    }
}

/// One pass's primary hits.
#[derive(Clone, Debug, Default)]
pub struct GBuffer {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Per pixel (row-major), the primary hit, or `None` where the camera ray left the scene or
    /// the path ends there.
    pub receivers: Vec<Option<Receiver>>,
}

impl GBuffer {
    /// Traces the camera rays of pass `ctx`. Adds what the camera sees directly (emitters and
    /// the environment, unless `hide_emitters`) to `radiance`, which must have one entry per
    /// pixel. With `keep_hits = false` (`max_depth ≤ 1`) no receivers are stored. Returns the
    /// buffer and the number of rays traced.
    pub fn trace(
        scene: &Scene,
        ctx: &PassContext,
        hide_emitters: bool,
        keep_hits: bool,
        radiance: &mut [Vec3],
    ) -> (Self, u64) {
        let (w, h) = scene.camera.resolution();
        let (w, h) = (w as usize, h as usize);
        let mut receivers = vec![None; w * h];
        let lights = &scene.lights;
        let rays = receivers
            .par_chunks_mut(w * BAND_ROWS)
            .zip(radiance.par_chunks_mut(w * BAND_ROWS))
            .enumerate()
            .map(|(band, (recv, rad))| {
                for (i, (r, l)) in recv.iter_mut().zip(rad.iter_mut()).enumerate() {
                    let index = band * w * BAND_ROWS + i;
                    let (x, y) = ((index % w) as u32, (index / w) as u32);
                    let mut rng = ctx.pixel_rng(index);
                    let film = ctx.film_position(x, y, &mut rng);
                    let ray = scene.camera.generate_ray(film, rng.next_2d());
                    let Some(si) = scene.intersect(&ray) else {
                        if !hide_emitters {
                            *l += lights.environment_radiance(ray.d);
                        }
                        continue;
                    };
                    if !hide_emitters && let Some(light) = lights.light_on_shape(si.shape) {
                        *l += lights.area_radiance(light, si.shading.n, -ray.d);
                    }
                    if keep_hits {
                        *r = Some(Receiver {
                            p: si.p,
                            ng: si.ng,
                            frame: si.shading,
                            wo: si.shading.to_local(-ray.d),
                            bsdf: scene.shape_bsdf[si.shape as usize],
                            depth: si.t,
                        });
                    }
                }
                recv.len() as u64
            })
            .sum();
        (
            Self {
                width: w,
                height: h,
                receivers,
            },
            rays,
        )
    }
}
