//! The shadow-ray test every estimator makes: whether a point on a light, or a direction to a
//! light at infinity, is visible from a surface point.

use glam::Vec3;
use restir_geometry::{shadow_ray_between, shadow_ray_towards};
use restir_lights::{Contact, LightSample};
use restir_scene::Scene;

/// Where a shadow ray goes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowTarget {
    /// A point at a finite distance.
    Point(Vec3),
    /// A point on primitive `prim` of area light `light`, whose geometric normal there is `ng`:
    /// the ray may end where it enters the clear box of the primitive's part of the light
    /// ([`restir_lights::LightSet::shadow_end`]).
    OnLight {
        /// The point.
        p: Vec3,
        /// The light's geometric normal at `p`.
        ng: Vec3,
        /// Index of the light.
        light: u32,
        /// The primitive of the light's shape that `p` lies on.
        prim: u32,
    },
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

    /// The end of a connection to a light sample seen as `c`.
    #[inline]
    pub fn of_contact(c: &Contact) -> Self {
        match c.light {
            Some((light, prim)) if c.dist.is_finite() => ShadowTarget::OnLight {
                p: c.p,
                ng: c.ng,
                light,
                prim,
            },
            _ => Self::new(c.p, c.wi, c.dist),
        }
    }

    /// The end of a connection to light sample `ls`.
    #[inline]
    pub fn of_sample(ls: &LightSample) -> Self {
        if ls.delta || !ls.dist.is_finite() {
            Self::new(ls.p, ls.wi, ls.dist)
        } else {
            ShadowTarget::OnLight {
                p: ls.p,
                ng: ls.ng,
                light: ls.light,
                prim: ls.prim,
            }
        }
    }
}

/// Whether `target` is visible from surface point `p` with geometric normal `ng` (one shadow
/// ray, offset along `ng`).
#[inline]
pub fn visible(scene: &Scene, p: Vec3, ng: Vec3, target: ShadowTarget) -> bool {
    let (ray, t_max) = match target {
        ShadowTarget::Point(q) => shadow_ray_between(p, ng, q),
        ShadowTarget::OnLight {
            p: q,
            ng: nq,
            light,
            prim,
        } => {
            let (ray, t_max) = shadow_ray_between(p, ng, q);
            let end = scene
                .lights
                .shadow_end(light, prim, ray.o, ray.d, t_max, q, nq);
            (ray, end)
        }
        ShadowTarget::Direction(d) => shadow_ray_towards(p, ng, d, f32::INFINITY),
    };
    !scene.occluded(&ray, t_max)
}
