//! Rays and the ray-origin offsets (relative to the magnitude of the hit point, after pbrt-v4's
//! floating-point error bounds and Mitsuba 3's relative epsilon) for spawning rays and shadow
//! rays from surfaces without hitting them again.

use glam::Vec3;

/// A ray `o + t·d` for `0 < t < t_max`. `d` need not be normalised, but every ray the renderer
/// spawns has a unit `d`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub o: Vec3,
    /// Direction.
    pub d: Vec3,
    /// Where the ray ends ([`f32::INFINITY`] but for camera rays with a far clip plane):
    /// [`Camera::generate_ray`](crate::Camera::generate_ray) sets it, the scene's closest-hit
    /// queries honour it.
    pub t_max: f32,
}

impl Ray {
    /// A ray from `o` along `d`, unbounded.
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        Self {
            o,
            d,
            t_max: f32::INFINITY,
        }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + t * self.d
    }
}

/// The offset distance used at `p`: `max|pᵢ| · RAY_EPSILON`, relative to the magnitude of the
/// coordinates and so to their rounding error, with no absolute floor, so that a scene and the
/// same scene in other units (10⁻⁶ or 10⁶ times larger) are traced alike.
///
/// This follows the error analysis of Pharr, Jakob and Humphreys, *Physically Based Rendering*,
/// 4th ed., §6.8 "Managing Rounding Error": a computed hit point is off its surface by at most
/// its rounding error, which is relative to the magnitudes of the positions it was computed from
/// (pbrt's `γₙ·Σ|bᵢ·pᵢ|` for a triangle, `γₙ·|p|` for a reprojected sphere point), and a ray
/// spawned from it is offset along the normal by more than that bound. Mitsuba 3's `offset_p`
/// uses the same relative epsilon (`1500 · 2⁻²⁴`) but adds 1 to the magnitude, an absolute floor
/// of 8.9·10⁻⁵ scene units that swallows scenes in small units; here the floor is dropped, and
/// what it guarded against — a point near the origin on a primitive whose vertices are far from
/// it, where the intersection test's own rounding (relative to the vertices) exceeds the offset —
/// is handled where that rounding happens: the triangle and sphere tests refuse distances within
/// their own error bound (see `REL_T_MIN` in the traversal), as pbrt-v4's triangle test refuses
/// `t ≤ δt`.
#[inline]
pub fn ray_epsilon(p: Vec3) -> f32 {
    p.abs().max_element() * crate::RAY_EPSILON
}

/// Moves `p` off its surface along the geometric normal `ng`, to the side that `d` leaves towards,
/// so that a ray from the result does not hit the surface it starts on.
#[inline]
pub fn offset_ray_origin(p: Vec3, ng: Vec3, d: Vec3) -> Vec3 {
    let side = if ng.dot(d) >= 0.0 { 1.0 } else { -1.0 };
    p + (side * ray_epsilon(p)) * ng
}

/// A shadow ray from surface point `p` (geometric normal `ng`) to point `target`; returns the ray
/// (unit direction) and the `t_max` to test, shortened so the target's own surface is not hit.
#[inline]
pub fn shadow_ray_between(p: Vec3, ng: Vec3, target: Vec3) -> (Ray, f32) {
    let o = offset_ray_origin(p, ng, target - p);
    let to = target - o;
    let dist = to.length();
    let d = to / dist;
    (Ray::new(o, d), dist * (1.0 - crate::SHADOW_EPSILON))
}

/// A shadow ray from surface point `p` towards a direction at infinity or to a target at distance
/// `dist` along unit `d`.
#[inline]
pub fn shadow_ray_towards(p: Vec3, ng: Vec3, d: Vec3, dist: f32) -> (Ray, f32) {
    let o = offset_ray_origin(p, ng, d);
    (Ray::new(o, d), dist * (1.0 - crate::SHADOW_EPSILON))
}
