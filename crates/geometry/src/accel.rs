//! The acceleration structure: one `obvhs` CWBVH (8-wide, compressed nodes) over every triangle
//! and sphere of the scene. Spheres are analytic primitives intersected in the traversal closure.
//!
//! obvhs's PLOC builder pairs clusters only when both prefer each other; among many primitives
//! with bit-identical bounds every choice ties, almost nothing pairs per sweep, and the build turns
//! quadratic (20 000 coincident triangles: 22 s). When more than [`MAX_SHARED_BOUNDS`] primitives
//! share their bounds, those primitives become one BVH entry (a *group*, tested in a loop, exact
//! duplicates once); scenes without such pile-ups get the plain one-primitive-per-entry BVH.

use std::collections::{HashMap, HashSet};
use std::time::Duration;

use glam::{Vec2, Vec3, Vec3A};
use obvhs::{
    BvhBuildParams,
    aabb::Aabb,
    cwbvh::{CwBvh, builder::build_cwbvh},
    ray::{Ray as BvhRay, RayHit},
};

use crate::{Frame, Ray, Shape};

/// One primitive as stored for traversal, in BVH order.
#[derive(Clone, Copy, Debug)]
enum Prim {
    Triangle { v0: Vec3A, e1: Vec3A, e2: Vec3A },
    Sphere { center: Vec3A, radius: f32 },
}

/// A closest hit: distance and which primitive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// The shape that was hit (index into the slice given to [`Accel::build`]).
    pub shape: u32,
    /// The triangle within the shape (0 for spheres).
    pub prim: u32,
}

/// Everything about a surface point that shading needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceInteraction {
    /// Position.
    pub p: Vec3,
    /// Geometric normal (unit; follows winding and `flip_normals`).
    pub ng: Vec3,
    /// Shading frame; `shading.n` is the interpolated shading normal.
    pub shading: Frame,
    /// Texture coordinates.
    pub uv: Vec2,
    /// Shape index.
    pub shape: u32,
    /// Primitive within the shape.
    pub prim: u32,
    /// Barycentrics (meshes) or [`crate::Sphere::param_of`] parameters (spheres) of the point on its primitive;
    /// with `shape` and `prim` this names the point without storing it.
    pub param: Vec2,
    /// Distance from the ray origin.
    pub t: f32,
}

/// The most primitives that may share bit-identical bounds before they are grouped into one BVH
/// entry (a quad's two triangles share theirs; only degenerate input piles up more).
pub const MAX_SHARED_BOUNDS: usize = 8;

/// A BVH over a list of shapes.
#[derive(Debug)]
pub struct Accel {
    bvh: Option<CwBvh>,
    prims: Vec<Prim>,
    /// (shape, primitive within shape) of each BVH-ordered primitive.
    ids: Vec<(u32, u32)>,
    /// With groups, BVH entry `e` holds `prims[groups[e]..groups[e + 1]]`; without, entry `e` is
    /// primitive `e`.
    groups: Option<Vec<u32>>,
    bounds: (Vec3, Vec3),
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
    }
}

/// BVH entries when more than [`MAX_SHARED_BOUNDS`] primitives share bounds: each entry's
/// members (indices into the input primitives, exact duplicates left out) and its box. `None`
/// when no bounds are shared that often.
fn group_entries(prims: &[Prim], aabbs: &[Aabb]) -> Option<(Vec<Vec<usize>>, Vec<Aabb>)> {
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
        if !seen.insert(prim_key(&prims[i])) {
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
fn intersect_triangle(v0: Vec3A, e1: Vec3A, e2: Vec3A, o: Vec3A, d: Vec3A, t_max: f32) -> f32 {
    // Möller–Trumbore.
    let pvec = d.cross(e2);
    let det = e1.dot(pvec);
    if det.abs() < 1e-20 {
        return f32::INFINITY;
    }
    let inv_det = 1.0 / det;
    let tvec = o - v0;
    let u = tvec.dot(pvec) * inv_det;
    if !(0.0..=1.0).contains(&u) {
        return f32::INFINITY;
    }
    let qvec = tvec.cross(e1);
    let v = d.dot(qvec) * inv_det;
    if v < 0.0 || u + v > 1.0 {
        return f32::INFINITY;
    }
    let t = e2.dot(qvec) * inv_det;
    if t > 0.0 && t < t_max {
        t
    } else {
        f32::INFINITY
    }
}

#[inline(always)]
fn intersect_sphere(center: Vec3A, radius: f32, o: Vec3A, d: Vec3A, t_max: f32) -> f32 {
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
    let t = if near > 0.0 { near } else { far };
    if t > 0.0 && t < t_max {
        t
    } else {
        f32::INFINITY
    }
}

impl Accel {
    /// Builds the BVH over all shapes.
    pub fn build(shapes: &[Shape]) -> Self {
        let mut prims = Vec::new();
        let mut ids = Vec::new();
        let mut aabbs = Vec::new();
        for (si, shape) in shapes.iter().enumerate() {
            match shape {
                Shape::Mesh(m) => {
                    for ti in 0..m.triangle_count() {
                        let [a, b, c] = m.triangle(ti);
                        prims.push(Prim::Triangle {
                            v0: a.into(),
                            e1: (b - a).into(),
                            e2: (c - a).into(),
                        });
                        ids.push((si as u32, ti as u32));
                        aabbs.push(Aabb::from_points(&[a.into(), b.into(), c.into()]));
                    }
                }
                Shape::Sphere(s) => {
                    prims.push(Prim::Sphere {
                        center: s.center.into(),
                        radius: s.radius,
                    });
                    ids.push((si as u32, 0));
                    let r = Vec3A::splat(s.radius);
                    aabbs.push(Aabb::new(
                        Vec3A::from(s.center) - r,
                        Vec3A::from(s.center) + r,
                    ));
                }
            }
        }
        let mut bounds = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for b in &aabbs {
            bounds.0 = bounds.0.min(b.min.into());
            bounds.1 = bounds.1.max(b.max.into());
        }
        if prims.is_empty() {
            return Self {
                bvh: None,
                prims,
                ids,
                groups: None,
                bounds: (Vec3::ZERO, Vec3::ZERO),
            };
        }
        if let Some((entries, boxes)) = group_entries(&prims, &aabbs) {
            let bvh = build_cwbvh(
                &boxes,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            );
            let mut starts = vec![0];
            let (mut out_prims, mut out_ids) = (Vec::new(), Vec::new());
            for &e in &bvh.primitive_indices {
                for &i in &entries[e as usize] {
                    out_prims.push(prims[i]);
                    out_ids.push(ids[i]);
                }
                starts.push(out_prims.len() as u32);
            }
            return Self {
                bvh: Some(bvh),
                prims: out_prims,
                ids: out_ids,
                groups: Some(starts),
                bounds,
            };
        }
        let bvh = build_cwbvh(
            &aabbs,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        // Lay primitives out in BVH order so the traversal indexes them directly.
        let prims = bvh
            .primitive_indices
            .iter()
            .map(|&i| prims[i as usize])
            .collect();
        let ids = bvh
            .primitive_indices
            .iter()
            .map(|&i| ids[i as usize])
            .collect();
        Self {
            bvh: Some(bvh),
            prims,
            ids,
            groups: None,
            bounds,
        }
    }

    /// The closest hit among the members of group entry `e` before `ray.tmax`: its distance and
    /// primitive, or infinity.
    #[inline]
    fn intersect_group(&self, starts: &[u32], e: usize, ray: &BvhRay) -> (f32, usize) {
        let mut best = (f32::INFINITY, 0);
        for id in starts[e] as usize..starts[e + 1] as usize {
            let t = self.intersect_prim(id, ray);
            if t < best.0 && t < ray.tmax {
                best = (t, id);
            }
        }
        best
    }

    /// The scene's axis-aligned bounds `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    /// Number of primitives (triangles and spheres).
    pub fn primitive_count(&self) -> usize {
        self.prims.len()
    }

    /// The traversal ray. Negative zeros in the direction are made positive: `obvhs` picks the
    /// slab order from `d < 0` but inverts `-0.0` to `-∞`, which misses every box for rays along an
    /// axis (such as `-Vec3::Z`).
    #[inline(always)]
    fn bvh_ray(ray: &Ray, t_max: f32) -> BvhRay {
        let d = Vec3A::from(ray.d) + Vec3A::ZERO;
        BvhRay::new(ray.o.into(), d, 0.0, t_max)
    }

    #[inline(always)]
    fn intersect_prim(&self, id: usize, ray: &BvhRay) -> f32 {
        match self.prims[id] {
            Prim::Triangle { v0, e1, e2 } => {
                intersect_triangle(v0, e1, e2, ray.origin, ray.direction, ray.tmax)
            }
            Prim::Sphere { center, radius } => {
                intersect_sphere(center, radius, ray.origin, ray.direction, ray.tmax)
            }
        }
    }

    /// The closest hit along `ray` with `t < t_max`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let r = Self::bvh_ray(ray, t_max);
        let mut hit = RayHit::none();
        if let Some(starts) = &self.groups {
            // obvhs keeps a hit exactly when the closure returns t < tmax, so the member
            // recorded last is the closest.
            let mut member = 0;
            let found = bvh.ray_traverse(r, &mut hit, |r, e| {
                let (t, id) = self.intersect_group(starts, e, r);
                if t < r.tmax {
                    member = id;
                }
                t
            });
            return found.then(|| {
                let (shape, prim) = self.ids[member];
                Hit {
                    t: hit.t,
                    shape,
                    prim,
                }
            });
        }
        if bvh.ray_traverse(r, &mut hit, |r, id| self.intersect_prim(id, r)) {
            let (shape, prim) = self.ids[hit.primitive_id as usize];
            Some(Hit {
                t: hit.t,
                shape,
                prim,
            })
        } else {
            None
        }
    }

    /// Whether anything blocks `ray` before `t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let r = Self::bvh_ray(ray, t_max);
        if let Some(starts) = &self.groups {
            return !bvh.ray_traverse_miss(r, |r, e| self.intersect_group(starts, e, r).0);
        }
        !bvh.ray_traverse_miss(r, |r, id| self.intersect_prim(id, r))
    }

    /// Surface details of a hit returned by [`Accel::intersect`] for the same `ray`.
    #[inline]
    pub fn surface_interaction(
        &self,
        shapes: &[Shape],
        hit: &Hit,
        ray: &Ray,
    ) -> SurfaceInteraction {
        let shape = &shapes[hit.shape as usize];
        let param = match shape {
            Shape::Mesh(m) => {
                // Barycentrics of the hit point, recomputed on the original vertices.
                let [p0, p1, p2] = m.triangle(hit.prim as usize);
                let (e1, e2) = (p1 - p0, p2 - p0);
                let pvec = ray.d.cross(e2);
                let inv_det = 1.0 / e1.dot(pvec);
                let tvec = ray.o - p0;
                let u = tvec.dot(pvec) * inv_det;
                let v = ray.d.dot(tvec.cross(e1)) * inv_det;
                let u = u.clamp(0.0, 1.0);
                let v = v.clamp(0.0, 1.0 - u);
                Vec2::new(u, v)
            }
            Shape::Sphere(s) => {
                let n = (ray.at(hit.t) - s.center).normalize();
                crate::Sphere::param_of(n)
            }
        };
        let mut si = surface_at(shapes, hit.shape, hit.prim, param);
        si.t = hit.t;
        if let Shape::Sphere(s) = shape {
            // Reproject onto the sphere for accuracy.
            let n = (ray.at(hit.t) - s.center).normalize();
            si.p = s.center + s.radius * n;
        }
        si
    }
}

/// The surface interaction at a point named by `(shape, prim, param)` (see
/// [`SurfaceInteraction::param`]); `t` is left at 0.
#[inline]
pub fn surface_at(shapes: &[Shape], shape: u32, prim: u32, param: Vec2) -> SurfaceInteraction {
    match &shapes[shape as usize] {
        Shape::Mesh(m) => {
            let (p, ng, ns, uv, dpdu) = m.surface_at(prim as usize, param);
            SurfaceInteraction {
                p,
                ng,
                shading: Frame::from_normal_tangent(ns, dpdu),
                uv,
                shape,
                prim,
                param,
                t: 0.0,
            }
        }
        Shape::Sphere(s) => {
            let (p, n) = s.point_at(param);
            let n = if s.flip_normals { -n } else { n };
            // Tangent along increasing φ.
            let dpdu = Vec3::new(-(p.y - s.center.y), p.x - s.center.x, 0.0);
            SurfaceInteraction {
                p,
                ng: n,
                shading: Frame::from_normal_tangent(n, dpdu),
                uv: crate::Sphere::uv_of(if s.flip_normals { -n } else { n }),
                shape,
                prim,
                param,
                t: 0.0,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Sphere, offset_ray_origin};
    use restir_sampling::Pcg32;

    fn scene() -> Vec<Shape> {
        let mut floor = Shape::rectangle();
        floor.transform(&glam::Affine3A::from_scale(Vec3::splat(10.0)));
        let mut cube = Shape::cube();
        cube.transform(&glam::Affine3A::from_translation(Vec3::new(0.0, 0.0, 2.0)));
        vec![
            Shape::Mesh(floor),
            Shape::Mesh(cube),
            Shape::Sphere(Sphere::new(Vec3::new(3.0, 0.0, 1.5), 0.5, false)),
        ]
    }

    /// Every hit the BVH reports is the brute-force closest hit.
    #[test]
    fn bvh_matches_brute_force() {
        let shapes = scene();
        let accel = Accel::build(&shapes);
        let mut rng = Pcg32::new(3, 4);
        for _ in 0..2000 {
            let o = Vec3::new(
                rng.next_f32() * 12.0 - 6.0,
                rng.next_f32() * 12.0 - 6.0,
                rng.next_f32() * 6.0 + 0.1,
            );
            let d = restir_sampling::warp::sample_uniform_sphere(rng.next_2d());
            let ray = Ray::new(o, d);
            let got = accel.intersect(&ray, f32::INFINITY);
            let r = BvhRay::new(o.into(), d.into(), 0.0, f32::INFINITY);
            let mut best = f32::INFINITY;
            for i in 0..accel.prims.len() {
                best = best.min(accel.intersect_prim(i, &r));
            }
            match got {
                Some(h) => assert!((h.t - best).abs() <= 1e-4 * best.max(1.0)),
                None => assert!(best.is_infinite()),
            }
            assert_eq!(accel.occluded(&ray, f32::INFINITY), best.is_finite());
        }
    }

    /// Rays leaving a surface through the offset origin never hit that surface again.
    #[test]
    fn no_self_intersection() {
        let shapes = scene();
        let accel = Accel::build(&shapes);
        let mut rng = Pcg32::new(5, 6);
        let mut checked = 0;
        for _ in 0..5000 {
            let o = Vec3::new(rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 8.0 - 4.0, 5.0);
            let target = Vec3::new(rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 8.0 - 4.0, 0.0);
            let ray = Ray::new(o, (target - o).normalize());
            let Some(hit) = accel.intersect(&ray, f32::INFINITY) else {
                continue;
            };
            let si = accel.surface_interaction(&shapes, &hit, &ray);
            // Reflect off the surface into the hemisphere the ray came from.
            let frame = Frame::from_normal(si.ng * -si.ng.dot(ray.d).signum());
            let d = frame.to_world(restir_sampling::warp::sample_cosine_hemisphere(
                rng.next_2d(),
            ));
            let o2 = offset_ray_origin(si.p, si.ng, d);
            if let Some(h2) = accel.intersect(&Ray::new(o2, d), f32::INFINITY) {
                assert!(
                    !(h2.shape == hit.shape && h2.prim == hit.prim && h2.t < 1e-3),
                    "self-intersection at t = {}",
                    h2.t
                );
            }
            checked += 1;
        }
        assert!(checked > 1000);
    }

    /// Coincident triangles build in linear time and still give the brute-force closest hit
    /// (beside a scene that is not grouped).
    #[test]
    fn coincident_triangles_are_grouped() {
        let n = 20_000;
        let pile = crate::TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(0.0, 0.0, 0.5)],
            None,
            None,
            (0..n)
                .map(|i| if i % 2 == 0 { [0, 1, 2] } else { [1, 2, 3] })
                .collect(),
            false,
        )
        .unwrap();
        let mut shapes = scene();
        shapes.push(Shape::Mesh(pile));
        let start = std::time::Instant::now();
        let accel = Accel::build(&shapes);
        let took = start.elapsed();
        assert!(took.as_secs_f32() < 2.0, "build took {took:?}");
        assert!(accel.groups.is_some());
        // Exact duplicates are kept once.
        assert!(accel.primitive_count() < 100, "{}", accel.primitive_count());
        let plain = Accel::build(&scene());
        assert!(plain.groups.is_none());
        let mut rng = Pcg32::new(7, 8);
        for _ in 0..2000 {
            let o = Vec3::new(
                rng.next_f32() * 4.0 - 2.0,
                rng.next_f32() * 4.0 - 2.0,
                rng.next_f32() * 4.0 + 0.1,
            );
            let d = restir_sampling::warp::sample_uniform_sphere(rng.next_2d());
            let ray = Ray::new(o, d);
            let r = BvhRay::new(o.into(), d.into(), 0.0, f32::INFINITY);
            let best = (0..accel.prims.len())
                .map(|i| accel.intersect_prim(i, &r))
                .fold(f32::INFINITY, f32::min);
            match accel.intersect(&ray, f32::INFINITY) {
                Some(h) => {
                    assert_eq!(h.t, best);
                    let s = &shapes[h.shape as usize];
                    if let Shape::Mesh(m) = s {
                        let [a, b, c] = m.triangle(h.prim as usize);
                        let t = intersect_triangle(
                            a.into(),
                            (b - a).into(),
                            (c - a).into(),
                            o.into(),
                            d.into(),
                            f32::INFINITY,
                        );
                        assert_eq!(t, h.t, "the hit names the primitive it hit");
                    }
                }
                None => assert!(best.is_infinite()),
            }
            assert_eq!(accel.occluded(&ray, f32::INFINITY), best.is_finite());
        }
    }

    #[test]
    fn sphere_hit_from_inside() {
        let shapes = vec![Shape::Sphere(Sphere::new(Vec3::ZERO, 2.0, false))];
        let accel = Accel::build(&shapes);
        let h = accel
            .intersect(&Ray::new(Vec3::ZERO, Vec3::X), f32::INFINITY)
            .unwrap();
        assert!((h.t - 2.0).abs() < 1e-5);
    }
}
