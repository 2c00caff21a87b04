//! Whether ReSTIR PT at its defaults is expected to pay on a scene, from a pilot at the camera's
//! paths: the rule by which the `auto` estimator ([`crate::auto`]) chooses ReSTIR PT, decided
//! once when the integrator is made.
//!
//! ReSTIR PT pays where the path tracer's estimate at the vertex a path reconnects from is poor
//! and the neighbours' paths are good candidates for it:
//!
//! - on a **glossy** (microfacet) surface the path tracer's light sample ignores the lobe and
//!   its BSDF sample ignores where the light comes from, while resampling over the neighbours'
//!   paths draws from their product;
//! - where **indirect light** dominates, a diffuse bounce rarely finds the lit surfaces, while
//!   the neighbours' paths that did are reused.
//!
//! On a diffuse surface lit mostly directly, next-event estimation is already close to the
//! product, and a default ReSTIR PT pass (3–6 path-tracer passes) is not repaid: at equal CPU
//! time (`docs/studies/2026-12-02-restir-pt-defaults.md`) the Cornell boxes gained 0.42–0.78×,
//! matpreview (smooth glass over diffuse surfaces under an environment) 0.41–0.52×, against
//! 1.2–4.7× in the glossy rooms and 1.8–1.9× in Sponza (diffuse, mostly in the shadow of its
//! one small light).
//!
//! A delta or near-specular surface is not where a path reconnects (the hybrid shift replays
//! through it), so the pilot follows each camera path through such surfaces to the first one a
//! path can reconnect at ([`connectible`]), asks whether that surface has a glossy lobe, and
//! estimates there the direct light (light sampling) and the light of one more bounce (a BSDF
//! sample, then light sampling at the surface it hits), with visibility. The indirect share of
//! a path is the second over their sum; the pilot reports its mean over the camera paths where
//! it found light, as relMSE weighs every pixel alike whatever its brightness.

use glam::{Vec2, Vec3};
use restir_geometry::{Ray, SurfaceInteraction, offset_ray_origin};
use restir_materials::{Bsdf, LobeFlags};
use restir_sampling::{Pcg32, luminance};
use restir_scene::Scene;

use super::sample::connectible;
use crate::shadow::{ShadowTarget, visible};

/// The share of the pilot's camera paths (among those that reach a surface a path can
/// reconnect at) whose first such surface must be glossy for `auto` to choose ReSTIR PT,
/// unless [`INDIRECT_VIEW_MIN`] does (`docs/studies/2026-12-02-restir-pt-defaults.md`).
pub const GLOSSY_VIEW_MIN: f32 = 0.05;

/// The mean indirect share (one more bounce over direct plus one more bounce) of the light at
/// the camera paths' first reconnectable surfaces for `auto` to choose ReSTIR PT on a scene
/// without glossy surfaces in view (`docs/studies/2026-12-02-restir-pt-defaults.md`).
pub const INDIRECT_VIEW_MIN: f32 = 0.65;

/// Camera rays per side of the pilot grid.
const GRID: u32 = 32;
/// Delta or near-specular bounces the pilot follows before giving a path up.
const MAX_BOUNCES: u32 = 8;
/// Samples of the direct and of the one-bounce light per pilot path.
const SAMPLES: u32 = 16;

/// What the pilot saw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewPilot {
    /// Camera paths whose first connectible surface has a glossy lobe.
    pub glossy: u32,
    /// Camera paths that reached a connectible surface.
    pub reached: u32,
    /// Of those, the paths where the pilot found some light (direct or by one more bounce).
    pub lit: u32,
    /// The sum over the lit paths of their indirect share.
    pub indirect: f32,
    /// Camera rays traced.
    pub rays: u32,
}

impl ViewPilot {
    /// The glossy share of the paths that reached a connectible surface (0 when none did).
    pub fn glossy_share(&self) -> f32 {
        if self.reached == 0 {
            0.0
        } else {
            self.glossy as f32 / self.reached as f32
        }
    }

    /// The mean indirect share of the light over the lit paths (0 when none was).
    pub fn indirect_share(&self) -> f32 {
        if self.lit == 0 {
            0.0
        } else {
            self.indirect / self.lit as f32
        }
    }

    /// Whether ReSTIR PT is expected to pay: enough glossy or indirectly lit surfaces in view.
    pub fn keeps_restir_pt(&self) -> bool {
        self.glossy_share() >= GLOSSY_VIEW_MIN || self.indirect_share() >= INDIRECT_VIEW_MIN
    }
}

/// Traces a fixed jittered grid of 32² camera rays through delta and near-specular
/// surfaces (one sampled lobe each, at most 8) to the first surface a path can
/// reconnect at, counts those with a glossy lobe and sums the indirect share of their light
/// (16 samples each of the direct and the one-bounce light). Deterministic (fixed
/// seed); at most 32² · (8 + 1 + 3 · 16) rays.
pub fn view_pilot(scene: &Scene, hide_emitters: bool) -> ViewPilot {
    let (w, h) = scene.camera.resolution();
    let mut rng = Pcg32::new(0x9105_5e1e, 0);
    let mut view = ViewPilot {
        glossy: 0,
        reached: 0,
        lit: 0,
        indirect: 0.0,
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
            for bounce in 0..=MAX_BOUNCES {
                let (hit, _) = scene.camera_intersect(&ray, bounce == 0 && hide_emitters);
                let Some(si) = hit else {
                    break;
                };
                let bsdf = scene.bsdf(&si);
                let flags = bsdf.flags();
                if flags == LobeFlags::NONE {
                    break;
                }
                let wo = si.shading.to_local(-ray.d);
                if connectible(&bsdf) {
                    view.reached += 1;
                    view.glossy += u32::from(flags.contains(LobeFlags::GLOSSY));
                    let (direct, bounce) = direct_and_bounce(scene, &si, &bsdf, wo, &mut rng);
                    if direct + bounce > 0.0 {
                        view.lit += 1;
                        view.indirect += bounce / (direct + bounce);
                    }
                    break;
                }
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

/// Light sampling at `si` towards `wo` (the reflected radiance, visibility included), one
/// sample.
fn direct(scene: &Scene, si: &SurfaceInteraction, bsdf: &Bsdf, wo: Vec3, rng: &mut Pcg32) -> Vec3 {
    let (u_select, u) = (rng.next_f32(), rng.next_2d());
    let Some(ls) = scene.lights.sample(si.p, u_select, u) else {
        return Vec3::ZERO;
    };
    let f = bsdf.eval(wo, si.shading.to_local(ls.wi));
    if ls.pdf_sa <= 0.0
        || f == Vec3::ZERO
        || !visible(scene, si.p, si.ng, ShadowTarget::of_sample(&ls))
    {
        return Vec3::ZERO;
    }
    let l = f * ls.le / ls.pdf_sa;
    if l.is_finite() { l } else { Vec3::ZERO }
}

/// [`SAMPLES`]-sample estimates of the direct light reflected at `si` and of the light one more
/// bounce brings (a BSDF sample, then light sampling where it lands).
fn direct_and_bounce(
    scene: &Scene,
    si: &SurfaceInteraction,
    bsdf: &Bsdf,
    wo: Vec3,
    rng: &mut Pcg32,
) -> (f32, f32) {
    let (mut d, mut b) = (Vec3::ZERO, Vec3::ZERO);
    for _ in 0..SAMPLES {
        d += direct(scene, si, bsdf, wo, rng);
        let (u_lobe, u) = (rng.next_f32(), rng.next_2d());
        let Some(bs) = bsdf.sample(wo, u_lobe, u) else {
            continue;
        };
        let dir = si.shading.to_world(bs.wi);
        let Some(next) = scene.intersect(&Ray::new(offset_ray_origin(si.p, si.ng, dir), dir))
        else {
            continue;
        };
        let bsdf2 = scene.bsdf(&next);
        if !bsdf2.has_smooth_lobe() {
            continue;
        }
        let l = bs.f / bs.pdf_sa * direct(scene, &next, &bsdf2, next.shading.to_local(-dir), rng);
        if l.is_finite() {
            b += l;
        }
    }
    (luminance(d), luminance(b))
}
