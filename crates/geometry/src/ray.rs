//! Rays and the ray-origin offsets (Mitsuba 3's relative epsilon) for spawning rays and shadow
//! rays from surfaces without hitting them again.

use glam::Vec3;

/// A ray `o + t·d`. `d` need not be normalised, but every ray the renderer spawns has a unit `d`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub o: Vec3,
    /// Direction.
    pub d: Vec3,
}

impl Ray {
    /// A ray from `o` along `d`.
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        Self { o, d }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + t * self.d
    }
}

/// The offset distance used at `p`: `(1 + max|pᵢ|) · RAY_EPSILON` (Mitsuba 3, `offset_p`), which
/// scales with the magnitude of the coordinates and so with their rounding error.
#[inline]
pub fn ray_epsilon(p: Vec3) -> f32 {
    (1.0 + p.abs().max_element()) * crate::RAY_EPSILON
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
