//! Mitsuba 3's `projector` emitter (plugin page "Projection light source (`projector`)", mitsuba3
//! `src/emitters/projector.cpp`): a pinhole at the origin of its `to_world` frame throwing an
//! irradiance image through a perspective frustum along the frame's `+z`, the reciprocal of the
//! `perspective` sensor with the same field-of-view rule (`fov` along `fov_axis`, or a 50 mm lens
//! on the diagonal; the image's aspect ratio is the irradiance texture's, 1 for a constant).
//!
//! A receiver at `p` is taken to the light's frame, `q = to_world⁻¹·p`, and reads the texture at
//! the sensor's film position of `q`:
//! `uv = (½ − ½·qₓ / (q_z·tan(fov_x/2)), ½ − ½·q_y / (q_z·tan(fov_y/2)))`
//! (`u` grows towards the frame's `−x`, `v` towards its `−y`: the image appears upright and
//! unmirrored to someone looking along the projector with the frame's `+y` up). Nothing is sent
//! where `q_z ≤ 0` or `uv` leaves `[0, 1]²`. What arrives is, as in Mitsuba,
//! `π·scale·E(uv) / (q_z² · cos θ)` with `cos θ = n·ω`, `n = to_world·ẑ` and `ω` the unit
//! direction from the light to the receiver: for a rigid frame the intensity
//! `π·scale·E(uv) / cos³θ`, which makes the irradiance on the plane `z = 1` in front of the
//! pinhole `π·scale·E(uv)`, whatever the angle. Its power is that irradiance over the image's
//! rectangle on that plane, `π·scale·mean(E)·4·tan(fov_x/2)·tan(fov_y/2)`.

use core::f32::consts::PI;
use std::sync::Arc;

use glam::{Mat3, Mat4, Vec2, Vec3};
use restir_geometry::FovAxis;
use restir_sampling::luminance;

use crate::LightTexture;

/// Why a projector's parameters are unusable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ProjectorError {
    /// The field of view (degrees) is outside `(0, 180)`.
    Fov(f32),
    /// The irradiance image has a zero side.
    Resolution(u32, u32),
    /// `scale` or the irradiance is negative or not finite.
    Irradiance,
    /// `to_world` is not invertible (or not finite).
    Transform,
}

impl core::fmt::Display for ProjectorError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            ProjectorError::Fov(v) => write!(f, "fov {v}° must be in (0°, 180°)"),
            ProjectorError::Resolution(w, h) => {
                write!(f, "the irradiance image {w}×{h} has a zero side")
            }
            ProjectorError::Irradiance => {
                write!(f, "scale and irradiance must be finite and non-negative")
            }
            ProjectorError::Transform => write!(f, "to_world must be finite and invertible"),
        }
    }
}

impl std::error::Error for ProjectorError {}

/// A projector ([`crate::Light::Projector`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projector {
    /// Position (the origin of the light's frame in the world).
    pub position: Vec3,
    /// `π · scale · irradiance`: the intensity on the axis (W/sr) of an untextured projector,
    /// which the texture multiplies.
    pub intensity: Vec3,
    /// World directions to the light's frame: the inverse of `to_world`'s linear part.
    to_local: Mat3,
    /// `to_world·ẑ`, not normalised (Mitsuba's normal of the emitter).
    normal: Vec3,
    /// `(tan(fov_x/2), tan(fov_y/2))`: half the image's extent on the plane `z = 1`.
    tan_half: Vec2,
    /// Index of the irradiance texture in the light set's projected textures.
    pub texture: Option<u32>,
}

impl Projector {
    /// A projector with `to_world` (a 4×4 affine matrix: the pinhole at its origin, looking
    /// along its `+z`), a constant `irradiance` times `scale` (times the texture, if any), the
    /// field of view `fov_degrees` along `fov_axis` of an image of `resolution` (the texture's;
    /// `(1, 1)` without one, as Mitsuba), and the index of the texture among the set's projected
    /// textures.
    pub fn new(
        to_world: Mat4,
        irradiance: Vec3,
        scale: f32,
        fov_degrees: f32,
        fov_axis: FovAxis,
        resolution: (u32, u32),
        texture: Option<u32>,
    ) -> Result<Self, ProjectorError> {
        if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
            return Err(ProjectorError::Fov(fov_degrees));
        }
        let (w, h) = resolution;
        if w == 0 || h == 0 {
            return Err(ProjectorError::Resolution(w, h));
        }
        let intensity = PI * scale * irradiance;
        if !(intensity.is_finite() && intensity.min_element() >= 0.0) {
            return Err(ProjectorError::Irradiance);
        }
        let linear = Mat3::from_mat4(to_world);
        if !to_world.is_finite() || !linear.determinant().is_normal() {
            return Err(ProjectorError::Transform);
        }
        Ok(Self {
            position: to_world.w_axis.truncate(),
            intensity,
            to_local: linear.inverse(),
            normal: linear * Vec3::Z,
            tan_half: fov_axis.tan_half(fov_degrees, w as f32 / h as f32),
            texture,
        })
    }

    /// `(tan(fov_x/2), tan(fov_y/2))`: half the image's extent on the plane `z = 1`.
    pub fn tan_half(&self) -> Vec2 {
        self.tan_half
    }

    /// The texture coordinates of `local`, a point (or direction from the pinhole) in the
    /// light's frame, and whether they fall on the image in front of the pinhole.
    #[inline]
    pub fn uv(&self, local: Vec3) -> Option<Vec2> {
        if local.z <= 0.0 {
            return None;
        }
        let s = Vec2::splat(0.5) / (local.z * self.tan_half);
        let uv = Vec2::new(0.5 - local.x * s.x, 0.5 - local.y * s.y);
        (uv.cmpge(Vec2::ZERO).all() && uv.cmple(Vec2::ONE).all()).then_some(uv)
    }

    /// The intensity the projector sends in world direction `w` (from the light, any length),
    /// with its texture `texture` (the set's entry for [`Projector::texture`]).
    #[inline]
    pub fn intensity_towards(&self, w: Vec3, texture: Option<&Arc<dyn LightTexture>>) -> Vec3 {
        let local = self.to_local * w;
        let Some(uv) = self.uv(local) else {
            return Vec3::ZERO;
        };
        let n_dot = self.normal.dot(w);
        if n_dot <= 0.0 {
            return Vec3::ZERO;
        }
        // π·scale·E / (q_z² cos θ) at the receiver, times the squared distance |w|².
        let len = w.length();
        let factor = len * len * len / (local.z * local.z * n_dot);
        let i = self.intensity * factor;
        match texture {
            Some(t) => i * t.eval(uv),
            None => i,
        }
    }

    /// The emitted power (luminance) when the texture's mean is `mean` (`Vec3::ONE` without one):
    /// the irradiance `π·scale·E` over the image's rectangle on the plane `z = 1`, exact for a
    /// rigid frame (a scaling `to_world` changes it; the value is a selection weight only).
    pub fn power(&self, mean: Vec3) -> f32 {
        4.0 * self.tan_half.x * self.tan_half.y * luminance(self.intensity * mean)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(fov: f32) -> Projector {
        Projector::new(
            Mat4::IDENTITY,
            Vec3::ONE,
            1.0,
            fov,
            FovAxis::X,
            (1, 1),
            None,
        )
        .unwrap()
    }

    /// The image's corners lie on the frustum's edges; `u` runs against `+x`, `v` against `+y`.
    #[test]
    fn uv_spans_the_frustum() {
        let p = Projector::new(
            Mat4::IDENTITY,
            Vec3::ONE,
            1.0,
            90.0,
            FovAxis::X,
            (4, 2),
            None,
        )
        .unwrap();
        assert!((p.tan_half() - Vec2::new(1.0, 0.5)).length() < 1e-6);
        assert_eq!(p.uv(Vec3::Z), Some(Vec2::splat(0.5)));
        let uv = p.uv(Vec3::new(-0.999, -0.499, 1.0)).unwrap();
        assert!((uv - Vec2::new(0.9995, 0.999)).length() < 1e-5, "{uv}");
        let uv = p.uv(Vec3::new(1.0, 0.5, 1.0)).unwrap();
        assert!(uv.length() < 1e-6, "{uv}");
        assert_eq!(p.uv(Vec3::new(1.01, 0.0, 1.0)), None);
        assert_eq!(p.uv(Vec3::new(0.0, 0.51, 1.0)), None);
        assert_eq!(p.uv(-Vec3::Z), None);
    }

    /// On the axis the intensity is `π·scale·E`; off it `1/cos³θ` more.
    #[test]
    fn intensity_keeps_the_plane_irradiance_constant() {
        let p = square(120.0);
        assert!((p.intensity_towards(Vec3::Z, None) - Vec3::splat(PI)).length() < 1e-5);
        let t = 40f32.to_radians();
        let w = 7.0 * Vec3::new(t.sin(), 0.0, t.cos());
        let i = p.intensity_towards(w, None).x;
        assert!((i - PI / t.cos().powi(3)).abs() < 1e-4 * i, "{i}");
        assert_eq!(p.intensity_towards(-Vec3::Z, None), Vec3::ZERO);
        // Beyond the 60° half-angle of the frustum: nothing.
        let t = 61f32.to_radians();
        assert_eq!(
            p.intensity_towards(Vec3::new(t.sin(), 0.0, t.cos()), None),
            Vec3::ZERO
        );
    }

    #[test]
    fn power_is_the_plane_irradiance_over_the_image() {
        let p = square(90.0);
        assert!((p.power(Vec3::ONE) - 4.0 * PI).abs() < 1e-5);
        assert!((p.power(Vec3::splat(0.5)) - 2.0 * PI).abs() < 1e-5);
    }

    #[test]
    fn bad_parameters_are_refused() {
        let m = Mat4::IDENTITY;
        let new = |m: Mat4, e: Vec3, s: f32, fov: f32, res: (u32, u32)| {
            Projector::new(m, e, s, fov, FovAxis::X, res, None)
        };
        assert_eq!(
            new(m, Vec3::ONE, 1.0, 180.0, (1, 1)),
            Err(ProjectorError::Fov(180.0))
        );
        assert_eq!(
            new(m, Vec3::ONE, 1.0, 30.0, (0, 1)),
            Err(ProjectorError::Resolution(0, 1))
        );
        assert_eq!(
            new(m, Vec3::ONE, -1.0, 30.0, (1, 1)),
            Err(ProjectorError::Irradiance)
        );
        assert_eq!(
            new(m, Vec3::splat(f32::NAN), 1.0, 30.0, (1, 1)),
            Err(ProjectorError::Irradiance)
        );
        assert_eq!(
            new(
                Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0)),
                Vec3::ONE,
                1.0,
                30.0,
                (1, 1)
            ),
            Err(ProjectorError::Transform)
        );
    }
}
