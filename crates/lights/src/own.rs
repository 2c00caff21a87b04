//! Lights that cannot light their own surface, and how a cut for receivers on one treats it.
//!
//! A receiver on an emitter (a lamp seen by the camera, which reflects the other lamps) is
//! nearest to its own light, so a light cut for it ([`crate::LightCut`]) would spend most of
//! its probability there. Where the light is convex and emits outwards (a sphere, a flat
//! emitter, a closed convex mesh: every corner of the mesh lies behind every triangle's
//! plane), a point on it is behind every one of its emitting triangles, so its own light does
//! not reach it (at most a trace through interpolated shading normals). The bound of the
//! hierarchy cannot tell, because the region's bounding sphere pokes through the planes. A cut
//! made for receivers that all lie on such a light gives the light's own emitters a small fixed
//! share of its selections ([`OWN_LIGHT_SHARE`]) instead of their importance: a positive
//! probability, so every estimate stays unbiased whatever the light turns out to deliver, and
//! the rest goes to the lights that can reach the receivers.

use glam::Vec3;
use restir_geometry::Shape;

use crate::Light;
use crate::corners::Corners;
use crate::table::{Emitter, EmitterTable};

/// The share of a cut's selections that a light keeps for receivers on its own surface when
/// it cannot light them ([`OwnLight`]).
pub const OWN_LIGHT_SHARE: f32 = 1.0 / 32.0;

/// Meshes with more emitting triangles than this are not tested (the test is quadratic).
const MAX_TESTED_TRIANGLES: usize = 4096;

/// The light every receiver of a cut's region lies on, and the share of the cut's selections
/// its own emitters keep ([`crate::LightSet::light_cut`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OwnLight {
    /// The light (index into [`crate::LightSet::lights`]).
    pub light: u32,
    /// The share of selections its emitters keep, in `[0, 1/2]`: [`OWN_LIGHT_SHARE`]; zero only in
    /// the tests' negative controls.
    pub share: f32,
}

/// Per light, whether it cannot light a point of its own surface: an outward sphere, or an
/// area light on a mesh of at most [`MAX_TESTED_TRIANGLES`] emitting triangles every corner of
/// which lies behind (or within rounding of) every one of its triangles' planes.
pub(crate) fn self_unlit(lights: &[Light], shapes: &[Shape], table: &EmitterTable) -> Vec<bool> {
    let mut triangles: Vec<Vec<([Vec3; 3], Vec3)>> = vec![Vec::new(); lights.len()];
    for e in table.entries() {
        if let Emitter::Triangle { light, p, ng, .. } = *e
            && let Some(t) = triangles.get_mut(light as usize)
            && t.len() <= MAX_TESTED_TRIANGLES
        {
            t.push((p, ng));
        }
    }
    lights
        .iter()
        .zip(&triangles)
        .map(|(light, tris)| match *light {
            Light::Area { shape, .. } => match shapes.get(shape as usize) {
                Some(Shape::Sphere(s)) => !s.flip_normals,
                Some(Shape::Mesh(_)) => {
                    !tris.is_empty() && tris.len() <= MAX_TESTED_TRIANGLES && convex(tris)
                }
                _ => false,
            },
            _ => false,
        })
        .collect()
}

/// Whether every corner of `triangles` lies behind every triangle's plane (its normal `ng`
/// pointing out), up to 10⁻⁴ of the triangles' extent.
fn convex(triangles: &[([Vec3; 3], Vec3)]) -> bool {
    let Some(corners) = Corners::of(triangles.iter().flat_map(|(p, _)| p.iter().copied())) else {
        return false;
    };
    let tolerance = 1e-4 * (corners.hi - corners.lo).length();
    triangles
        .iter()
        .all(|&(p, ng)| corners.behind(ng, p[0], tolerance))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The triangles of a box of half-size 1 with normals out (or in).
    fn cube(inward: bool) -> Vec<([Vec3; 3], Vec3)> {
        let mut out = Vec::new();
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let n =
                    Vec3::from_array(std::array::from_fn(|k| if k == axis { sign } else { 0.0 }));
                let (u, v) = (
                    n.any_orthonormal_vector(),
                    n.cross(n.any_orthonormal_vector()),
                );
                let q = [n - u - v, n + u - v, n + u + v, n - u + v];
                let n = if inward { -n } else { n };
                out.push(([q[0], q[1], q[2]], n));
                out.push(([q[0], q[2], q[3]], n));
            }
        }
        out
    }

    #[test]
    fn convex_outward_meshes_are_found_and_others_are_not() {
        assert!(convex(&cube(false)));
        assert!(!convex(&cube(true)), "an inward box lights itself");
        // A flat emitter cannot light itself.
        let flat = &cube(false)[..2];
        assert!(convex(flat));
        // Two facing quads light each other.
        let mut facing = cube(false)[..2].to_vec();
        facing.extend(
            cube(false)[..2]
                .iter()
                .map(|&(p, n)| (p.map(|c| c + 3.0 * n), -n)),
        );
        assert!(!convex(&facing));
    }
}
