//! The primitives the BVH holds (triangles with precomputed edges, analytic spheres, the
//! primitives of cylinders and signed distance grids by reference), their ray tests, and the
//! grouping of primitives with bit-identical bounds.

use std::collections::{HashMap, HashSet};

use glam::Vec3A;
use obvhs::aabb::Aabb;

use super::MAX_SHARED_BOUNDS;
use crate::Shape;

/// One primitive as stored for traversal, in BVH order.
#[derive(Clone, Copy, Debug)]
pub(super) enum Prim {
    Triangle {
        v0: Vec3A,
        e1: Vec3A,
        e2: Vec3A,
    },
    Sphere {
        center: Vec3A,
        radius: f32,
    },
    /// Primitive `prim` of the analytic shape in slot `slot` of the structure's copies.
    Analytic {
        slot: u32,
        prim: u32,
    },
}

/// The bit pattern of a box, for finding boxes that are exactly equal.
fn aabb_key(b: &Aabb) -> [u32; 6] {
    let (lo, hi) = (b.min.to_array(), b.max.to_array());
    [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]].map(f32::to_bits)
}

/// The bit pattern of a primitive, for dropping exact duplicates inside a group.
fn prim_key(p: &Prim) -> [u32; 9] {
    match *p {
        Prim::Triangle { v0, e1, e2 } => {
            let (a, b, c) = (v0.to_array(), e1.to_array(), e2.to_array());
            [a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]].map(f32::to_bits)
        }
        Prim::Sphere { center, radius } => {
            let c = center.to_array();
            [c[0], c[1], c[2], radius, 0.0, 0.0, 0.0, 0.0, f32::NAN].map(f32::to_bits)
        }
        Prim::Analytic { slot, prim } => [slot, prim, 0, 0, 0, 0, 0, 1, f32::NAN.to_bits()],
    }
}

/// BVH entries when more than [`MAX_SHARED_BOUNDS`] primitives share bounds: each entry's
/// members (indices into the input primitives, exact duplicates left out) and its box. `None`
/// when no bounds are shared that often. `prim(i)` is input primitive `i` (asked only for those
/// that share their bounds too often).
pub(super) fn group_entries(
    aabbs: &[Aabb],
    prim: impl Fn(usize) -> Prim,
) -> Option<(Vec<Vec<usize>>, Vec<Aabb>)> {
    let mut counts: HashMap<[u32; 6], usize> = HashMap::new();
    for b in aabbs {
        *counts.entry(aabb_key(b)).or_default() += 1;
    }
    if counts.values().all(|&c| c <= MAX_SHARED_BOUNDS) {
        return None;
    }
    let mut entries: Vec<Vec<usize>> = Vec::new();
    let mut boxes = Vec::new();
    let mut entry_of: HashMap<[u32; 6], usize> = HashMap::new();
    let mut seen: HashSet<[u32; 9]> = HashSet::new();
    for (i, b) in aabbs.iter().enumerate() {
        let key = aabb_key(b);
        if counts[&key] <= MAX_SHARED_BOUNDS {
            entries.push(vec![i]);
            boxes.push(*b);
            continue;
        }
        if !seen.insert(prim_key(&prim(i))) {
            continue;
        }
        match entry_of.get(&key) {
            Some(&e) => entries[e].push(i),
            None => {
                entry_of.insert(key, entries.len());
                entries.push(vec![i]);
                boxes.push(*b);
            }
        }
    }
    Some((entries, boxes))
}

#[inline(always)]
pub(super) fn intersect_triangle(
    v0: Vec3A,
    e1: Vec3A,
    e2: Vec3A,
    o: Vec3A,
    d: Vec3A,
    t_max: f32,
) -> f32 {
    triangle_hit(v0, e1, e2, o, d, t_max).map_or(f32::INFINITY, |(t, _, _)| t)
}

/// Distances below `REL_T_MIN` times the magnitude of the operands of a primitive test (for a
/// triangle `max|o − v0|`, for a sphere `max|o − c| + r`) are refused as the test's own rounding
/// noise: the computed `t` of a ray leaving a surface it starts on is the true `t ≈ 0` plus an
/// error of a few ulps of those magnitudes. 32 units of roundoff (2⁻¹⁹ ≈ 1.9·10⁻⁶), a margin
/// over the few ulps of Möller–Trumbore's and the sphere test's operations; pbrt-v4 refuses
/// `t ≤ δt` from its bound `δt` the same way (PBR 4th ed., §6.8.7). Relative, so the same scene
/// in any unit is traced alike; a real surface this close to the origin of a ray is closer than
/// the positions' own rounding can tell.
pub(crate) const REL_T_MIN: f32 = 32.0 / 16_777_216.0;

/// Möller–Trumbore: the distance and the barycentrics `(u, v)` of the hit (weights of `v0 + e1`
/// and `v0 + e2`) when `REL_T_MIN · max|o − v0| < t < t_max`.
#[inline(always)]
pub(super) fn triangle_hit(
    v0: Vec3A,
    e1: Vec3A,
    e2: Vec3A,
    o: Vec3A,
    d: Vec3A,
    t_max: f32,
) -> Option<(f32, f32, f32)> {
    let pvec = d.cross(e2);
    let det = e1.dot(pvec);
    // Zero or subnormal: no plane to hit (relative: a determinant scales with the square of
    // the scene's unit, so an absolute threshold would refuse small scenes).
    if det.abs() < f32::MIN_POSITIVE {
        return None;
    }
    let inv_det = 1.0 / det;
    let tvec = o - v0;
    let u = tvec.dot(pvec) * inv_det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qvec = tvec.cross(e1);
    let v = d.dot(qvec) * inv_det;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(qvec) * inv_det;
    let t_min = REL_T_MIN * tvec.abs().max_element();
    (t > t_min && t < t_max).then_some((t, u, v))
}

#[inline(always)]
pub(super) fn intersect_sphere(center: Vec3A, radius: f32, o: Vec3A, d: Vec3A, t_max: f32) -> f32 {
    // Numerically robust form (Haines et al., "Precision Improvements for Ray/Sphere
    // Intersection", Ray Tracing Gems 2019): the discriminant from the closest-approach vector.
    let f = o - center;
    let a = d.length_squared();
    let b = -f.dot(d);
    let l = f + (b / a) * d;
    let disc = a * (radius * radius - l.length_squared());
    if disc < 0.0 {
        return f32::INFINITY;
    }
    let c = f.length_squared() - radius * radius;
    let q = b + b.signum() * disc.sqrt();
    if q == 0.0 {
        return f32::INFINITY;
    }
    let t0 = c / q;
    let t1 = q / a;
    let (near, far) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
    let t_min = REL_T_MIN * (f.abs().max_element() + radius);
    let t = if near > t_min { near } else { far };
    if t > t_min && t < t_max {
        t
    } else {
        f32::INFINITY
    }
}

impl Prim {
    /// The distance along the ray `(o, d)` if below `t_max`, else infinity; `analytic` holds
    /// the shapes [`Prim::Analytic`] names.
    #[inline(always)]
    pub(super) fn intersect(&self, analytic: &[Shape], o: Vec3A, d: Vec3A, t_max: f32) -> f32 {
        match *self {
            Prim::Triangle { v0, e1, e2 } => intersect_triangle(v0, e1, e2, o, d, t_max),
            Prim::Sphere { center, radius } => intersect_sphere(center, radius, o, d, t_max),
            Prim::Analytic { slot, prim } => match &analytic[slot as usize] {
                Shape::Cylinder(c) => c.intersect(o, d, t_max),
                Shape::SdfGrid(g) => g.intersect(prim, o, d, t_max),
                _ => f32::INFINITY,
            },
        }
    }
}
