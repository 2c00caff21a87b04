//! How often next-event estimation picks the environment next to local lights, decided once
//! per scene from what the camera's receivers see.
//!
//! A light sample picks the environment with probability `s` and a local emitter (by power) with
//! `1 − s`. The two are disjoint sets of light points, so a one-sample estimate is
//! `f_env / s` or `f_loc / (1 − s)`, with second moment `A/s + B/(1 − s)`, where `A` and `B` are
//! the second moments of each strategy's own estimate. It is smallest at
//! `s = √A / (√A + √B)` (the variance-optimal one-sample mixture weights, Veach 1997, §9.2.2
//! for the one-sample model).
//!
//! Power says nothing about `A`: an environment's power through the scene's bounding sphere
//! counts light that walls, roofs and occluders block, and next to many small bright lights it
//! took a far larger share than it contributes. So `A` and `B` are estimated at the primary hits
//! of a fixed grid of camera rays (cosine-weighted irradiance from each strategy, with
//! visibility), which costs a few thousand rays at scene build. The share is clamped to
//! `[SHARE_MIN, 1 − SHARE_MIN]`, so every light point stays reachable whatever the pilot missed.

use crate::Scene;
use glam::Vec2;
use restir_geometry::shadow_ray_towards;
use restir_sampling::{Pcg32, luminance};

/// Camera rays per side of the pilot grid.
const GRID: u32 = 32;
/// Samples of each strategy per receiver.
const SAMPLES: u32 = 2;
/// The smallest share either side gets.
pub const SHARE_MIN: f32 = 0.01;

/// What the scene build decided about the environment's share of light samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvironmentShare {
    /// The environment's share of the lights' power (what power-proportional selection gives).
    pub power_share: f32,
    /// The share chosen from the pilot.
    pub share: f32,
    /// Camera rays of the pilot that hit a surface.
    pub receivers: u32,
    /// The fraction of the pilot's environment samples above a receiver's surface that reach
    /// the environment unoccluded: near 1 under an open sky, small in a room lit through
    /// windows.
    pub visible: f32,
}

impl Scene {
    /// How light samples are drawn, in one line for `--stats`: the emitter table's size, the
    /// lights whose shadow rays end at their clear boxes, and the environment's share, with what
    /// decided it.
    pub fn light_selection(&self) -> String {
        let lights = &self.lights;
        let mut table = format!(
            "{} lights, {} entries in one alias table (one per emissive triangle or other light)",
            lights.len(),
            lights.emitter_count()
        );
        let (clear, parts) = lights.clear_parts();
        if clear > 0 {
            table += &format!(
                "; shadow rays toward {parts} parts of {clear} of them (convex parts of at most \
                 {} triangles that nothing else comes near) end where they enter the part's \
                 bounds",
                restir_lights::MAX_CLEAR_TRIANGLES
            );
        }
        match (lights.environment(), self.features.environment_share) {
            (None, _) => table,
            (Some(_), Some(d)) => format!(
                "{table}; environment share {:.4} from a pilot at {} camera hits (power share \
                 {:.4}; {:.0} % of its samples there unoccluded)",
                d.share,
                d.receivers,
                d.power_share,
                100.0 * d.visible
            ),
            (Some(env), None) => format!(
                "{table}; environment share {:.4} (power share)",
                lights.pmf(env)
            ),
        }
    }

    /// Estimates the variance-optimal environment share at the camera's primary hits and sets
    /// it on the light set. `None` (nothing changed) without both an environment and local
    /// lights, or when no camera ray hits a surface. `hide_emitters`: whether the camera sees
    /// area emitters (the scene's integrator setting).
    pub(crate) fn decide_environment_share(
        &mut self,
        hide_emitters: bool,
    ) -> Option<EnvironmentShare> {
        let env = self.lights.environment()?;
        let power_share = self.lights.environment_power_share();
        if self.lights.pmf(env) == 0.0 || self.lights.emitter_count() == 0 {
            return None;
        }
        // Local lights alone while the pilot samples them (the environment is sampled directly).
        self.lights.set_environment_share(0.0);
        let (w, h) = self.camera.resolution();
        let mut rng = Pcg32::new(0x5eed_0e4e, 0);
        let (mut second_env, mut second_local) = (0.0f64, 0.0f64);
        let mut receivers = 0u32;
        let (mut env_above, mut env_visible) = (0u32, 0u32);
        for j in 0..GRID {
            for i in 0..GRID {
                let film = Vec2::new(
                    (i as f32 + rng.next_f32()) / GRID as f32 * w as f32,
                    (j as f32 + rng.next_f32()) / GRID as f32 * h as f32,
                );
                let ray = self.camera.generate_ray(film, Vec2::splat(0.5));
                let (hit, _) = self.camera_intersect(&ray, hide_emitters);
                let Some(si) = hit else {
                    continue;
                };
                receivers += 1;
                // The side of the surface the camera sees.
                let n = if si.ng.dot(ray.d) < 0.0 {
                    si.ng
                } else {
                    -si.ng
                };
                for k in 0..2 * SAMPLES {
                    let u = rng.next_2d();
                    let s = if k < SAMPLES {
                        self.lights.sample_light(env, si.p, u)
                    } else {
                        self.lights.sample(si.p, rng.next_f32(), u)
                    };
                    let Some(s) = s else { continue };
                    let cos = n.dot(s.wi);
                    if cos <= 0.0 || s.pdf_sa <= 0.0 {
                        continue;
                    }
                    env_above += u32::from(k < SAMPLES);
                    let (r, t_max) = shadow_ray_towards(si.p, n, s.wi, s.dist);
                    if self.occluded(&r, t_max) {
                        continue;
                    }
                    env_visible += u32::from(k < SAMPLES);
                    let f = (luminance(s.le) * cos / s.pdf_sa) as f64;
                    if k < SAMPLES {
                        second_env += f * f;
                    } else {
                        second_local += f * f;
                    }
                }
            }
        }
        if receivers == 0 {
            self.lights.set_environment_share(power_share);
            return None;
        }
        let (a, b) = (second_env.sqrt(), second_local.sqrt());
        let share = if a + b > 0.0 {
            (a / (a + b)) as f32
        } else {
            power_share
        };
        let share = share.clamp(SHARE_MIN, 1.0 - SHARE_MIN);
        self.lights.set_environment_share(share);
        Some(EnvironmentShare {
            power_share,
            share,
            receivers,
            visible: env_visible as f32 / env_above.max(1) as f32,
        })
    }
}
