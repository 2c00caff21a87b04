//! The perspective camera (pinhole or thin lens) with Mitsuba 3's conventions, its field-of-view
//! axis and the errors that stop it being built.

use glam::{Mat4, Vec2, Vec3};

use crate::Ray;

/// Which image axis the field of view spans (Mitsuba's `fov_axis`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FovAxis {
    /// Horizontal.
    #[default]
    X,
    /// Vertical.
    Y,
    /// The image diagonal.
    Diagonal,
    /// The smaller of the two image axes.
    Smaller,
    /// The larger of the two image axes.
    Larger,
}

impl FovAxis {
    /// Half the extent of an image of aspect ratio `aspect` (width over height) on the plane
    /// `z = 1` in front of a pinhole, `(tan(fov_x / 2), tan(fov_y / 2))`, when `fov_degrees` spans
    /// this axis: Mitsuba 3's field-of-view rule, which its perspective sensor and its
    /// `projector` emitter share (`smaller` and `larger` pick `x` or `y` by the aspect ratio).
    pub fn tan_half(self, fov_degrees: f32, aspect: f32) -> Vec2 {
        let t = (fov_degrees.to_radians() * 0.5).tan();
        let axis = match self {
            FovAxis::Smaller if aspect > 1.0 => FovAxis::Y,
            FovAxis::Smaller => FovAxis::X,
            FovAxis::Larger if aspect > 1.0 => FovAxis::X,
            FovAxis::Larger => FovAxis::Y,
            a => a,
        };
        match axis {
            FovAxis::X => Vec2::new(t, t / aspect),
            FovAxis::Y => Vec2::new(t * aspect, t),
            _ => {
                let diag = (aspect * aspect + 1.0).sqrt();
                Vec2::new(t * aspect / diag, t / diag)
            }
        }
    }
}

/// Why a camera cannot be built.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraError {
    /// The field of view is not in (0, 180) degrees.
    Fov(f32),
    /// The film has a zero dimension.
    Resolution(u32, u32),
    /// The transform is not invertible or not finite.
    Transform,
    /// Aperture radius or focus distance is negative, zero where it must not be, or not finite.
    Lens,
    /// The clip planes are not `0 ≤ near < far` with a finite near plane.
    Clip(f32, f32),
}

impl core::fmt::Display for CameraError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            CameraError::Fov(v) => write!(f, "field of view {v}° is not between 0 and 180"),
            CameraError::Resolution(w, h) => write!(f, "film resolution {w}×{h} has a zero side"),
            CameraError::Transform => write!(f, "camera transform is degenerate or not finite"),
            CameraError::Lens => write!(f, "aperture radius and focus distance must be positive"),
            CameraError::Clip(n, far) => write!(
                f,
                "near_clip {n} and far_clip {far} must satisfy 0 ≤ near_clip < far_clip"
            ),
        }
    }
}

impl std::error::Error for CameraError {}

/// A perspective camera (pinhole or thin lens) or an orthographic one, with Mitsuba's
/// conventions: in camera space the camera looks along `+z`, `+y` is up and `+x` is left
/// (Mitsuba's `lookat` builds `left = up × dir`); film position `(0, 0)` is the top-left corner.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    to_world: Mat4,
    from_world: Mat4,
    origin: Vec3,
    /// Half the film's extent on the plane `z = 1` (perspective) or in camera space
    /// (orthographic).
    tan_half: Vec2,
    resolution: (u32, u32),
    aperture_radius: f32,
    focus_distance: f32,
    orthographic: bool,
    /// Camera-space depth (`z`) of the near clip plane; 0 for none.
    near_clip: f32,
    /// Camera-space depth of the far clip plane; infinite for none.
    far_clip: f32,
}

impl Camera {
    /// A camera with `fov_degrees` along `fov_axis`, placed by `to_world`.
    pub fn perspective(
        to_world: Mat4,
        fov_degrees: f32,
        fov_axis: FovAxis,
        resolution: (u32, u32),
    ) -> Result<Self, CameraError> {
        Self::thin_lens(to_world, fov_degrees, fov_axis, resolution, 0.0, 1.0)
    }

    /// A thin-lens camera; `aperture_radius = 0` is a pinhole.
    pub fn thin_lens(
        to_world: Mat4,
        fov_degrees: f32,
        fov_axis: FovAxis,
        resolution: (u32, u32),
        aperture_radius: f32,
        focus_distance: f32,
    ) -> Result<Self, CameraError> {
        if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
            return Err(CameraError::Fov(fov_degrees));
        }
        let (w, h) = resolution;
        if w == 0 || h == 0 {
            return Err(CameraError::Resolution(w, h));
        }
        if !to_world.is_finite() || to_world.determinant().abs() < 1e-20 {
            return Err(CameraError::Transform);
        }
        let lens_ok = aperture_radius >= 0.0
            && aperture_radius.is_finite()
            && focus_distance > 0.0
            && focus_distance.is_finite();
        if !lens_ok {
            return Err(CameraError::Lens);
        }
        let tan_half = fov_axis.tan_half(fov_degrees, w as f32 / h as f32);
        Ok(Self {
            to_world,
            from_world: to_world.inverse(),
            origin: to_world.transform_point3(Vec3::ZERO),
            tan_half,
            resolution,
            aperture_radius,
            focus_distance,
            orthographic: false,
            near_clip: 0.0,
            far_clip: f32::INFINITY,
        })
    }

    /// The camera with clip planes at camera-space depths `near` and `far` (Mitsuba's
    /// `near_clip` and `far_clip`): a camera ray sees only what lies between the two planes
    /// perpendicular to the viewing axis, so a camera ray starts on the near plane and ends on
    /// the far one. `0` and infinity clip nothing (the default).
    pub fn with_clip(mut self, near: f32, far: f32) -> Result<Self, CameraError> {
        if !(near >= 0.0 && near.is_finite() && far > near) {
            return Err(CameraError::Clip(near, far));
        }
        self.near_clip = near;
        self.far_clip = far;
        Ok(self)
    }

    /// The clip planes' camera-space depths `(near, far)` ([`Camera::with_clip`]).
    pub fn clip(&self) -> (f32, f32) {
        (self.near_clip, self.far_clip)
    }

    /// Mitsuba 3's `orthographic` sensor
    /// (<https://mitsuba.readthedocs.io/en/latest/src/generated/plugins_sensors.html#orthographic-camera-orthographic>):
    /// parallel rays along camera `+z` from the plane `z = 0`, the film spanning `[−1, 1]` in
    /// camera `x` and `[−1/aspect, 1/aspect]` in `y`, so `to_world`'s scale sets the extent.
    pub fn orthographic(to_world: Mat4, resolution: (u32, u32)) -> Result<Self, CameraError> {
        let mut cam = Self::perspective(to_world, 90.0, FovAxis::X, resolution)?;
        cam.orthographic = true;
        Ok(cam)
    }

    /// Whether the camera is orthographic.
    pub fn is_orthographic(&self) -> bool {
        self.orthographic
    }

    /// Film resolution `(width, height)`.
    pub fn resolution(&self) -> (u32, u32) {
        self.resolution
    }

    /// The film's pixel count, `width × height` (the whole film, also where a render covers a
    /// part of it: what the estimators' film-size defaults ask about).
    pub fn pixel_count(&self) -> u64 {
        u64::from(self.resolution.0) * u64::from(self.resolution.1)
    }

    /// The angle one pixel spans at the centre of the film, vertically (radians, small-angle):
    /// the spread of a primary ray's cone (for an orthographic camera, the pixel's width in
    /// camera units over a unit distance: its rays do not spread).
    pub fn pixel_angle(&self) -> f32 {
        2.0 * self.tan_half.y / self.resolution.1 as f32
    }

    /// Whether every ray passes through one point (a pinhole or an orthographic camera, no
    /// lens): then a point's film position is where every camera ray that reaches it starts.
    pub fn is_pinhole(&self) -> bool {
        self.orthographic || self.aperture_radius <= 0.0
    }

    /// The camera position.
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// The camera-to-world matrix.
    pub fn to_world(&self) -> Mat4 {
        self.to_world
    }

    /// Where the camera sees world point `p`: the film position (in pixels, `(0, 0)` at the
    /// top-left corner, possibly outside the film) of the ray through the lens centre towards
    /// `p`, the inverse of [`Camera::generate_ray`] for a pinhole (for a thin lens, the
    /// position where `p` is in focus at its depth). `None` for points not in front of the
    /// camera. Motion vectors use it: where a point seen now was seen by the previous frame's
    /// camera.
    #[inline]
    pub fn film_position_of(&self, p: Vec3) -> Option<Vec2> {
        let local = self.from_world.transform_point3(p);
        if local.z.is_nan() || local.z <= 0.0 {
            return None;
        }
        let (w, h) = self.resolution;
        let z = if self.orthographic { 1.0 } else { local.z };
        let x = local.x / (z * self.tan_half.x);
        let y = local.y / (z * self.tan_half.y);
        let film = Vec2::new((1.0 - x) * 0.5 * w as f32, (1.0 - y) * 0.5 * h as f32);
        film.is_finite().then_some(film)
    }

    /// The primary ray through film position `film` (in pixels, `(0, 0)` at the top-left corner),
    /// with `u_lens` choosing the point on the aperture. The direction is unit length; the ray
    /// starts on the near clip plane and its `t_max` ends it on the far one
    /// ([`Camera::with_clip`]; without clip planes, at the lens and unbounded).
    #[inline]
    pub fn generate_ray(&self, film: Vec2, u_lens: Vec2) -> Ray {
        let (w, h) = self.resolution;
        let s = Vec2::new(film.x / w as f32, film.y / h as f32);
        let local = Vec3::new(
            (1.0 - 2.0 * s.x) * self.tan_half.x,
            (1.0 - 2.0 * s.y) * self.tan_half.y,
            1.0,
        );
        // The ray in camera space: from `o_local` along `d_local`, whose `z` is positive.
        let ray = if self.orthographic {
            let o = self
                .to_world
                .transform_point3(Vec3::new(local.x, local.y, 0.0));
            let d = self.to_world.transform_vector3(Vec3::Z).normalize();
            (Ray::new(o, d), Vec3::new(local.x, local.y, 0.0), Vec3::Z)
        } else if self.aperture_radius > 0.0 {
            let lens = self.aperture_radius * restir_sampling::warp::sample_concentric_disk(u_lens);
            let focus = local * self.focus_distance;
            let o_local = Vec3::new(lens.x, lens.y, 0.0);
            let o = self.to_world.transform_point3(o_local);
            let d = self.to_world.transform_vector3(focus - o_local).normalize();
            (Ray::new(o, d), o_local, focus - o_local)
        } else {
            let d = self.to_world.transform_vector3(local).normalize();
            (Ray::new(self.origin, d), Vec3::ZERO, local)
        };
        self.clipped(ray)
    }

    /// A camera ray (world space, and its origin and direction in camera space) moved to start
    /// on the near clip plane and to end on the far one, both measured in camera space so that
    /// a scaled `to_world` scales them alike.
    #[inline]
    fn clipped(&self, (mut ray, o_local, d_local): (Ray, Vec3, Vec3)) -> Ray {
        if self.near_clip == 0.0 && self.far_clip == f32::INFINITY {
            return ray;
        }
        let at_depth = |z: f32| {
            self.to_world
                .transform_point3(o_local + d_local * (z / d_local.z))
        };
        let near = if self.near_clip > 0.0 {
            at_depth(self.near_clip)
        } else {
            ray.o
        };
        if self.far_clip.is_finite() {
            ray.t_max = (at_depth(self.far_clip) - near).dot(ray.d);
        }
        ray.o = near;
        ray
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookat_conventions() {
        // Mitsuba's lookat from +z looking at the origin with +y up.
        let origin = Vec3::new(0.0, 0.0, 5.0);
        let dir = (Vec3::ZERO - origin).normalize();
        let left = Vec3::Y.cross(dir).normalize();
        let up = dir.cross(left);
        let m = Mat4::from_cols(
            left.extend(0.0),
            up.extend(0.0),
            dir.extend(0.0),
            origin.extend(1.0),
        );
        let cam = Camera::perspective(m, 90.0, FovAxis::X, (100, 50)).unwrap();
        let centre = cam.generate_ray(Vec2::new(50.0, 25.0), Vec2::ZERO);
        assert!((centre.d - dir).length() < 1e-6);
        // Left edge of the image looks towards -x in world space (camera +x is world -x here).
        let l = cam.generate_ray(Vec2::new(0.0, 25.0), Vec2::ZERO);
        assert!(l.d.x < 0.0 && (l.d.x / l.d.z - 1.0).abs() < 1e-5);
        // Top edge looks up; vertical half-extent is tan(45°)/aspect.
        let t = cam.generate_ray(Vec2::new(50.0, 0.0), Vec2::ZERO);
        assert!(t.d.y > 0.0 && (t.d.y / -t.d.z - 0.5).abs() < 1e-5);
    }

    #[test]
    fn film_position_inverts_generate_ray() {
        let m = Mat4::from_rotation_translation(
            glam::Quat::from_euler(glam::EulerRot::YXZ, 0.4, -0.3, 0.1),
            Vec3::new(1.0, 2.0, 5.0),
        );
        for axis in [FovAxis::X, FovAxis::Y, FovAxis::Diagonal] {
            let cam = Camera::perspective(m, 50.0, axis, (64, 48)).unwrap();
            for film in [
                Vec2::new(0.5, 0.5),
                Vec2::new(31.2, 7.9),
                Vec2::new(63.9, 47.1),
            ] {
                let ray = cam.generate_ray(film, Vec2::ZERO);
                let back = cam.film_position_of(ray.o + 3.7 * ray.d).unwrap();
                assert!((back - film).length() < 1e-3, "{film} -> {back}");
            }
            // Behind the camera: nowhere on the film.
            let ray = cam.generate_ray(Vec2::new(10.0, 10.0), Vec2::ZERO);
            assert!(cam.film_position_of(ray.o - ray.d).is_none());
        }
    }

    /// Parallel rays over `[−1, 1] × [−1/aspect, 1/aspect]` in camera space, scaled by
    /// `to_world`; `film_position_of` inverts them. Negative control: the perspective camera
    /// of the same transform sends diverging rays.
    #[test]
    fn orthographic_rays_are_parallel() {
        let m = Mat4::from_rotation_translation(
            glam::Quat::from_euler(glam::EulerRot::YXZ, 0.4, -0.3, 0.1),
            Vec3::new(1.0, 2.0, 5.0),
        ) * Mat4::from_scale(Vec3::new(1.5, 1.5, 1.0));
        let cam = Camera::orthographic(m, (200, 120)).unwrap();
        let persp = Camera::perspective(m, 90.0, FovAxis::X, (200, 120)).unwrap();
        let a = cam.generate_ray(Vec2::new(0.0, 0.0), Vec2::ZERO);
        let b = cam.generate_ray(Vec2::new(200.0, 120.0), Vec2::ZERO);
        assert!((a.d - b.d).length() < 1e-6);
        let local = |p: Vec3| m.inverse().transform_point3(p);
        assert!(
            (local(a.o) - Vec3::new(1.0, 0.6, 0.0)).length() < 1e-5,
            "{}",
            local(a.o)
        );
        assert!((local(b.o) - Vec3::new(-1.0, -0.6, 0.0)).length() < 1e-5);
        // The world-space extent is the scale's: 3 across.
        assert!(((a.o - b.o).length() - (3.0f32.powi(2) + 1.8f32.powi(2)).sqrt()).abs() < 1e-4);
        for film in [Vec2::new(3.5, 9.25), Vec2::new(150.0, 60.0)] {
            let r = cam.generate_ray(film, Vec2::ZERO);
            let back = cam.film_position_of(r.o + 4.2 * r.d).unwrap();
            assert!((back - film).length() < 1e-3, "{film} -> {back}");
        }
        let (pa, pb) = (
            persp.generate_ray(Vec2::ZERO, Vec2::ZERO),
            persp.generate_ray(Vec2::new(200.0, 120.0), Vec2::ZERO),
        );
        assert!((pa.d - pb.d).length() > 0.1);
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(Camera::perspective(Mat4::IDENTITY, 0.0, FovAxis::X, (1, 1)).is_err());
        assert!(Camera::perspective(Mat4::IDENTITY, 180.0, FovAxis::X, (1, 1)).is_err());
        assert!(Camera::perspective(Mat4::IDENTITY, 45.0, FovAxis::X, (0, 1)).is_err());
        assert!(Camera::perspective(Mat4::ZERO, 45.0, FovAxis::X, (1, 1)).is_err());
    }
}
