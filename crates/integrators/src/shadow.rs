//! The shadow-ray test every estimator makes: whether a point on a light, or a direction to a
//! light at infinity, is visible from a surface point.

use glam::Vec3;
use restir_geometry::{shadow_ray_between, shadow_ray_towards};
use restir_scene::Scene;

/// Where a shadow ray goes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowTarget {
    /// A point at a finite distance.
    Point(Vec3),
    /// A direction to infinity.
    Direction(Vec3),
}

impl ShadowTarget {
    /// The end of a light connection: point `p` at distance `dist`, or the direction `wi` when
    /// the distance is infinite.
    #[inline]
    pub fn new(p: Vec3, wi: Vec3, dist: f32) -> Self {
        if dist.is_finite() {
            ShadowTarget::Point(p)
        } else {
            ShadowTarget::Direction(wi)
        }
    }
}

/// Whether `target` is visible from surface point `p` with geometric normal `ng` (one shadow
/// ray, offset along `ng`).
#[inline]
pub fn visible(scene: &Scene, p: Vec3, ng: Vec3, target: ShadowTarget) -> bool {
    let (ray, t_max) = match target {
        ShadowTarget::Point(q) => shadow_ray_between(p, ng, q),
        ShadowTarget::Direction(d) => shadow_ray_towards(p, ng, d, f32::INFINITY),
    };
    !scene.occluded(&ray, t_max)
}
