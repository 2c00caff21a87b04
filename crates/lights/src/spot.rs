//! Mitsuba 3's `spot` emitter (plugin page "Spot light source (`spot`)", mitsuba3
//! `src/emitters/spot.cpp`): a point light at the origin of its `to_world` frame, shining along
//! that frame's `+z`, whose intensity falls off with the angle θ from the axis:
//!
//! - full intensity for θ up to `beam_width`,
//! - a linear ramp in θ from 1 at `beam_width` to 0 at `cutoff_angle`,
//!   `(cutoff − θ) / (cutoff − beam_width)`,
//! - nothing beyond `cutoff_angle` (Mitsuba's defaults: 20°, and `beam_width` ¾ of the cutoff).
//!
//! The direction is taken to the light's frame with the inverse of `to_world` and normalised, as
//! Mitsuba does, so a scaling `to_world` reshapes the cone. An optional texture is projected
//! along the axis: the direction `d` (light frame) reads it at
//! `uv = (½ + ½·d.x / (d.z·tan cutoff), ½ + ½·d.y / (d.z·tan cutoff))`, so the cone's cutoff
//! circle touches the edges of the unit square. The emitted intensity towards `d` is
//! `intensity · texture(uv) · falloff(θ)`, a delta light seen from a receiver at distance `r` as
//! `I / r²`.

use core::f32::consts::PI;
use std::sync::Arc;

use crate::LightTexture;
use glam::{Mat3, Vec2, Vec3};

/// Why a spot light's parameters are unusable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpotError {
    /// `cutoff_angle` (degrees) outside `(0, 180)`, or at or beyond 90 with a texture (whose
    /// projection needs `tan cutoff > 0`).
    Cutoff(f32),
    /// `beam_width` (degrees) outside `[0, cutoff_angle]`.
    BeamWidth(f32, f32),
    /// `to_world` is not invertible (or not finite).
    Transform,
}

impl core::fmt::Display for SpotError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            SpotError::Cutoff(c) => write!(
                f,
                "cutoff_angle {c}° must be in (0°, 180°), and below 90° with a texture"
            ),
            SpotError::BeamWidth(b, c) => write!(
                f,
                "beam_width {b}° must be in [0°, cutoff_angle] = [0°, {c}°]"
            ),
            SpotError::Transform => write!(f, "to_world must be finite and invertible"),
        }
    }
}

impl std::error::Error for SpotError {}

/// A spot light ([`crate::Light::Spot`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spot {
    /// Position (the origin of the light's frame in the world).
    pub position: Vec3,
    /// Radiant intensity on the axis (W/sr).
    pub intensity: Vec3,
    /// World directions to the light's frame: the inverse of `to_world`'s linear part.
    to_local: Mat3,
    /// The light's axis in the world (unit).
    axis: Vec3,
    cos_cutoff: f32,
    cos_beam: f32,
    /// Cutoff angle in radians.
    cutoff: f32,
    /// `1 / (cutoff − beam_width)` in 1/radians; 0 when the two are equal.
    inv_transition: f32,
    /// `tan(cutoff)`, the texture projection's scale.
    uv_factor: f32,
    /// Index of the projected texture in the light set's spot textures.
    pub texture: Option<u32>,
}

impl Spot {
    /// A spot light with `to_world` (a 4×4 affine matrix: the light at its origin, the axis its
    /// `+z`), angles in degrees, and the index of its texture among the set's spot textures.
    pub fn new(
        to_world: glam::Mat4,
        intensity: Vec3,
        cutoff_deg: f32,
        beam_deg: f32,
        texture: Option<u32>,
    ) -> Result<Self, SpotError> {
        let max_cutoff = if texture.is_some() { 90.0 } else { 180.0 };
        if !(cutoff_deg > 0.0 && cutoff_deg < max_cutoff) {
            return Err(SpotError::Cutoff(cutoff_deg));
        }
        if !(beam_deg >= 0.0 && beam_deg <= cutoff_deg) {
            return Err(SpotError::BeamWidth(beam_deg, cutoff_deg));
        }
        let linear = Mat3::from_mat4(to_world);
        let det = linear.determinant();
        if !to_world.is_finite() || !det.is_normal() {
            return Err(SpotError::Transform);
        }
        let to_local = linear.inverse();
        let axis = (linear * Vec3::Z).normalize();
        let cutoff = cutoff_deg.to_radians();
        let beam = beam_deg.to_radians();
        Ok(Self {
            position: to_world.w_axis.truncate(),
            intensity,
            to_local,
            axis,
            cos_cutoff: cutoff.cos(),
            cos_beam: beam.cos(),
            cutoff,
            inv_transition: if cutoff > beam {
                1.0 / (cutoff - beam)
            } else {
                0.0
            },
            uv_factor: cutoff.tan(),
            texture,
        })
    }

    /// The light's axis in the world (unit).
    pub fn axis(&self) -> Vec3 {
        self.axis
    }

    /// The falloff factor in `[0, 1]` for direction `local` in the light's frame (any length).
    #[inline]
    pub fn falloff(&self, local: Vec3) -> f32 {
        let cos_theta = local.normalize_or_zero().z;
        if cos_theta <= self.cos_cutoff {
            0.0
        } else if cos_theta >= self.cos_beam {
            1.0
        } else {
            ((self.cutoff - cos_theta.clamp(-1.0, 1.0).acos()) * self.inv_transition)
                .clamp(0.0, 1.0)
        }
    }

    /// The texture coordinates of direction `local` in the light's frame (`local.z > 0`).
    #[inline]
    pub fn uv(&self, local: Vec3) -> Vec2 {
        let s = 0.5 / (local.z * self.uv_factor);
        Vec2::new(0.5 + local.x * s, 0.5 + local.y * s)
    }

    /// The intensity the light sends in world direction `w` (from the light, any length), with
    /// its texture `texture` (the set's entry for [`Spot::texture`]).
    #[inline]
    pub fn intensity_towards(&self, w: Vec3, texture: Option<&Arc<dyn LightTexture>>) -> Vec3 {
        let local = self.to_local * w;
        let falloff = self.falloff(local);
        if falloff <= 0.0 {
            return Vec3::ZERO;
        }
        let i = self.intensity * falloff;
        match texture {
            Some(t) => i * t.eval(self.uv(local)),
            None => i,
        }
    }

    /// `∫ falloff dω` over the sphere, as if the frame were rigid: the untextured light's power
    /// over its axis intensity (`2π·(1 − cos cutoff)` for a hard-edged cone). A scaling
    /// `to_world` changes the cone's true solid angle; the value is a selection weight only.
    pub fn solid_angle(&self) -> f32 {
        // 2π ∫₀^cutoff falloff(θ) sin θ dθ, the full beam exactly and the ramp by the midpoint
        // rule (smooth, 256 steps: relative error below 10⁻⁵).
        let beam = self.cos_beam.clamp(-1.0, 1.0).acos();
        let mut ramp = 0.0f64;
        if self.inv_transition > 0.0 {
            let n = 256;
            let h = f64::from(self.cutoff - beam) / n as f64;
            for k in 0..n {
                let t = f64::from(beam) + (k as f64 + 0.5) * h;
                let f = (f64::from(self.cutoff) - t) * f64::from(self.inv_transition);
                ramp += f * t.sin() * h;
            }
        }
        (2.0 * PI as f64 * ((1.0 - f64::from(self.cos_beam)) + ramp)) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spot(cutoff: f32, beam: f32) -> Spot {
        Spot::new(glam::Mat4::IDENTITY, Vec3::ONE, cutoff, beam, None).unwrap()
    }

    #[test]
    fn falloff_is_mitsubas_linear_ramp_in_angle() {
        let s = spot(20.0, 15.0);
        let dir = |deg: f32| {
            let t = deg.to_radians();
            Vec3::new(t.sin(), 0.0, t.cos())
        };
        assert_eq!(s.falloff(dir(0.0)), 1.0);
        assert_eq!(s.falloff(dir(14.9)), 1.0);
        assert!((s.falloff(dir(17.5)) - 0.5).abs() < 1e-4);
        assert!((s.falloff(dir(19.0)) - 0.2).abs() < 1e-4);
        assert_eq!(s.falloff(dir(20.1)), 0.0);
        assert_eq!(s.falloff(-Vec3::Z), 0.0);
        // Length does not matter.
        assert!((s.falloff(3.0 * dir(17.5)) - 0.5).abs() < 1e-4);
    }

    #[test]
    fn uv_puts_the_cutoff_circle_on_the_square_edges() {
        let s = spot(20.0, 15.0);
        let t = 20f32.to_radians();
        let uv = s.uv(Vec3::new(t.sin(), 0.0, t.cos()));
        assert!((uv - Vec2::new(1.0, 0.5)).length() < 1e-5, "{uv}");
        let uv = s.uv(Vec3::new(0.0, -t.sin(), t.cos()));
        assert!((uv - Vec2::new(0.5, 0.0)).length() < 1e-5, "{uv}");
        assert_eq!(s.uv(Vec3::Z), Vec2::splat(0.5));
    }

    #[test]
    fn solid_angle_of_hard_and_soft_cones() {
        let c = 30f32.to_radians();
        let hard = spot(30.0, 30.0).solid_angle();
        assert!((hard - 2.0 * PI * (1.0 - c.cos())).abs() < 1e-5 * hard);
        // The ramp over [0, c]: 2π ∫ (c − θ)/c · sin θ dθ = 2π (c − sin c) / c.
        let soft = spot(30.0, 0.0).solid_angle();
        let exact = 2.0 * PI * (c - c.sin()) / c;
        assert!((soft - exact).abs() < 1e-5 * exact, "{soft} vs {exact}");
    }

    #[test]
    fn bad_angles_and_transforms_are_refused() {
        let m = glam::Mat4::IDENTITY;
        assert_eq!(
            Spot::new(m, Vec3::ONE, 0.0, 0.0, None),
            Err(SpotError::Cutoff(0.0))
        );
        assert_eq!(
            Spot::new(m, Vec3::ONE, 90.0, 10.0, Some(0)),
            Err(SpotError::Cutoff(90.0))
        );
        assert!(Spot::new(m, Vec3::ONE, 120.0, 10.0, None).is_ok());
        assert_eq!(
            Spot::new(m, Vec3::ONE, 20.0, 25.0, None),
            Err(SpotError::BeamWidth(25.0, 20.0))
        );
        assert!(matches!(
            Spot::new(m, Vec3::ONE, 20.0, f32::NAN, None),
            Err(SpotError::BeamWidth(..))
        ));
        assert_eq!(
            Spot::new(
                glam::Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0)),
                Vec3::ONE,
                20.0,
                15.0,
                None
            ),
            Err(SpotError::Transform)
        );
    }
}
