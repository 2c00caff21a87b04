//! When ReSTIR PT at its defaults hands a scene to the path tracer (`fallback = auto`), decided
//! once when the integrator is made from a pilot at the camera's paths.
//!
//! ReSTIR PT pays where the integrand at the vertex a path reconnects from is peaked in
//! direction: on a glossy (microfacet) surface the path tracer's light sample ignores the lobe
//! and its BSDF sample ignores where the light comes from, while resampling over the
//! neighbours' paths draws from their product. On a diffuse surface the path tracer's next-event
//! estimation is already close to the product, and a default ReSTIR PT pass (about six times a
//! path-tracer pass, `docs/BENCHMARKS.md`) is not repaid: the diffuse Cornell box gained 0.76×,
//! matpreview (smooth glass over diffuse surfaces) 0.52×, the glossy rooms 1.2–4.7×.
//! A delta or near-specular surface is not where a path reconnects (the hybrid shift replays
//! through it), so the pilot follows the camera path through such surfaces to the first one a
//! path can reconnect at ([`connectible`]) and asks whether that surface has a glossy lobe.

use glam::Vec2;
use restir_geometry::{Ray, offset_ray_origin};
use restir_materials::LobeFlags;
use restir_sampling::Pcg32;
use restir_scene::Scene;

use super::sample::connectible;

/// The share of the pilot's camera paths (among those that reach a surface a path can
/// reconnect at) whose first such surface must be glossy for ReSTIR PT to keep a scene at its
/// defaults. Below it the path tracer renders the scene (`docs/BENCHMARKS.md`, "Never worse").
pub const GLOSSY_VIEW_MIN: f32 = 0.05;

/// Camera rays per side of the pilot grid.
const GRID: u32 = 32;
/// Delta or near-specular bounces the pilot follows before giving a path up.
const MAX_BOUNCES: u32 = 8;

/// What the pilot saw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlossyView {
    /// Camera paths whose first connectible surface has a glossy lobe.
    pub glossy: u32,
    /// Camera paths that reached a connectible surface.
    pub reached: u32,
    /// Camera rays traced.
    pub rays: u32,
}

impl GlossyView {
    /// The glossy share of the paths that reached a connectible surface (0 when none did).
    pub fn share(&self) -> f32 {
        if self.reached == 0 {
            0.0
        } else {
            self.glossy as f32 / self.reached as f32
        }
    }
}

/// Traces a fixed jittered grid of [`GRID`]² camera rays through delta and near-specular
/// surfaces (one sampled lobe each, at most [`MAX_BOUNCES`]) to the first surface a path can
/// reconnect at, and counts those with a glossy lobe. Deterministic (fixed seed).
pub fn glossy_view(scene: &Scene) -> GlossyView {
    let (w, h) = scene.camera.resolution();
    let mut rng = Pcg32::new(0x9105_5e1e, 0);
    let mut view = GlossyView {
        glossy: 0,
        reached: 0,
        rays: 0,
    };
    for j in 0..GRID {
        for i in 0..GRID {
            let film = Vec2::new(
                (i as f32 + rng.next_f32()) / GRID as f32 * w as f32,
                (j as f32 + rng.next_f32()) / GRID as f32 * h as f32,
            );
            let mut ray = scene.camera.generate_ray(film, Vec2::splat(0.5));
            view.rays += 1;
            for _ in 0..=MAX_BOUNCES {
                let Some(si) = scene.intersect(&ray) else {
                    break;
                };
                let bsdf = scene.bsdf(&si);
                let flags = bsdf.flags();
                if flags == LobeFlags::NONE {
                    break;
                }
                if connectible(&bsdf) {
                    view.reached += 1;
                    view.glossy += u32::from(flags.contains(LobeFlags::GLOSSY));
                    break;
                }
                let wo = si.shading.to_local(-ray.d);
                let (u_lobe, u) = (rng.next_f32(), rng.next_2d());
                let Some(bs) = bsdf.sample(wo, u_lobe, u) else {
                    break;
                };
                let d = si.shading.to_world(bs.wi);
                ray = Ray::new(offset_ray_origin(si.p, si.ng, d), d);
            }
        }
    }
    view
}
