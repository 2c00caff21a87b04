//! Where a shadow ray toward a point on a light may stop: at the light's clear box.
//!
//! A shadow ray toward a point `y` on an emissive mesh ends at `y`, so its last stretch runs
//! through the mesh's own part of the scene's BVH: near `y` the traversal descends into the
//! nodes of the light's triangles and tests those nearest `y`, which the ray cannot hit before
//! its end. On the seed report's scene (108 lamps, spheres of 960 triangles) that descent is a
//! large share of every shadow ray's cost.
//!
//! For some lights it can be skipped without changing any answer. Decided once, when the set is
//! built, a light on a mesh has a **clear box** when
//!
//! 1. **the mesh is convex**: every vertex lies on the inner side of every triangle's plane
//!    (the side of the mesh's centroid), so the mesh is part of the boundary of its convex hull;
//! 2. **nothing else is near it**: no primitive of another shape has a bounding box that meets
//!    the mesh's bounding box grown by a margin (the clear box).
//!
//! Then, for a receiver `x` strictly in front of the plane of `y`'s triangle (the side away
//! from the centroid), the segment from `x` to `y` meets no triangle of the mesh before `y`:
//! the whole mesh lies in the closed inner half-space of that plane, which the segment touches
//! only at `y`. Nor does any other primitive cross the clear box. So when `x` is outside the
//! clear box, `y` is visible from `x` exactly when nothing blocks the segment up to where it
//! enters the box, and the shadow ray may end there ([`LightSet::shadow_end`]). The answer is
//! the same, not an approximation; only rounding at the very end of the ray, where the mesh's
//! neighbouring triangles could otherwise be grazed, differs, in the ray's favour.

use glam::Vec3;
use restir_geometry::Shape;

use crate::{Light, LightSet};

/// Meshes of more triangles are not checked for convexity (the check costs triangles times
/// vertices).
pub const MAX_CLEAR_TRIANGLES: usize = 1024;

/// A light's clear box and the centroid that orients its triangles' planes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ClearBox {
    lo: Vec3,
    hi: Vec3,
    centroid: Vec3,
}

impl ClearBox {
    /// [`LightSet::shadow_end`] for a light with this box.
    #[inline]
    fn end(&self, o: Vec3, d: Vec3, t_max: f32, y: Vec3, ng: Vec3) -> f32 {
        // `o` on the outer side of the plane of `y`'s triangle (the side away from the
        // centroid).
        let front = ng.dot(y - self.centroid) * ng.dot(o - y);
        if front.is_nan() || front <= 0.0 {
            return t_max;
        }
        let inv = d.recip();
        let (t0, t1) = ((self.lo - o) * inv, (self.hi - o) * inv);
        let enter = t0.min(t1).max_element();
        if enter > 0.0 && enter < t_max {
            enter
        } else {
            t_max
        }
    }
}

/// The clear box of each light (`None` for lights without one), for `lights` on `shapes`.
pub(crate) fn clear_boxes(lights: &[Light], shapes: &[Shape]) -> Vec<Option<ClearBox>> {
    let mut boxes: Vec<Option<ClearBox>> = lights
        .iter()
        .map(|l| match *l {
            Light::Area { shape, .. } => match shapes.get(shape as usize) {
                Some(Shape::Mesh(m)) => convex_box(m.positions(), m.indices()),
                _ => None,
            },
            _ => None,
        })
        .collect();
    // Whose box is met by another shape's primitive: the candidates sorted by the low x of
    // their boxes, each primitive's box compared with those whose x-range can meet it.
    let mut order: Vec<(f32, u32)> = boxes
        .iter()
        .enumerate()
        .filter_map(|(i, b)| b.map(|b| (b.lo.x, i as u32)))
        .collect();
    if order.is_empty() {
        return boxes;
    }
    order.sort_by(|a, b| a.0.total_cmp(&b.0));
    let widest = order
        .iter()
        .filter_map(|&(_, i)| boxes[i as usize].map(|b| b.hi.x - b.lo.x))
        .fold(0.0f32, f32::max);
    let own_shape = |light: u32| match lights[light as usize] {
        Light::Area { shape, .. } => shape,
        _ => u32::MAX,
    };
    let mut met = vec![false; lights.len()];
    for (si, shape) in shapes.iter().enumerate() {
        for ti in 0..shape.primitive_count() as u32 {
            let (lo, hi) = shape.primitive_bounds(ti);
            let first = order.partition_point(|&(x, _)| x < lo.x - widest);
            let last = order.partition_point(|&(x, _)| x <= hi.x);
            for &(_, light) in &order[first..last.max(first)] {
                if met[light as usize] || own_shape(light) == si as u32 {
                    continue;
                }
                let Some(b) = boxes[light as usize] else {
                    continue;
                };
                // Not provably apart (NaN bounds count as meeting).
                let apart = lo.cmpgt(b.hi).any() || hi.cmplt(b.lo).any();
                if !apart {
                    met[light as usize] = true;
                }
            }
        }
    }
    for (b, met) in boxes.iter_mut().zip(met) {
        if met {
            *b = None;
        }
    }
    boxes
}

/// The grown bounding box of a convex mesh, or `None` when the mesh is too large to check,
/// flat, degenerate, not finite or not convex.
fn convex_box(positions: &[Vec3], indices: &[[u32; 3]]) -> Option<ClearBox> {
    if indices.is_empty() || indices.len() > MAX_CLEAR_TRIANGLES {
        return None;
    }
    // Only the vertices the triangles use.
    let mut ids: Vec<u32> = indices.iter().flatten().copied().collect();
    ids.sort_unstable();
    ids.dedup();
    let used: Vec<Vec3> = ids
        .iter()
        .map(|&v| positions.get(v as usize).copied())
        .collect::<Option<_>>()?;
    if !used.iter().all(|v| v.is_finite()) {
        return None;
    }
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let mut sum = Vec3::ZERO;
    for &v in &used {
        lo = lo.min(v);
        hi = hi.max(v);
        sum += v;
    }
    let centroid = sum / used.len() as f32;
    let size = (hi - lo).length();
    if !(size > 0.0 && size.is_finite()) {
        return None;
    }
    // Rounding in the planes' normals and offsets, relative to the mesh's size.
    let tol = 1e-5 * size;
    // The vertices by coordinate, for a loop over them that runs in SIMD lanes.
    let xs: Vec<f32> = used.iter().map(|v| v.x).collect();
    let ys: Vec<f32> = used.iter().map(|v| v.y).collect();
    let zs: Vec<f32> = used.iter().map(|v| v.z).collect();
    for t in indices {
        let [a, b, c] = t.map(|v| positions[v as usize]);
        let n = (b - a).cross(c - a);
        let len = n.length();
        if len.is_nan() || len <= 0.0 {
            return None;
        }
        let n = n / len;
        // Outward: away from the centroid. A plane through the centroid has no inside.
        let h = n.dot(a - centroid);
        if h.abs() <= tol {
            return None;
        }
        let n = if h > 0.0 { n } else { -n };
        let limit = n.dot(a) + tol;
        let outside = xs
            .iter()
            .zip(&ys)
            .zip(&zs)
            .filter(|&((&x, &y), &z)| n.x * x + n.y * y + n.z * z > limit)
            .count();
        if outside > 0 {
            return None;
        }
    }
    // Grown so that the BVH's conservatively rounded node boxes of the mesh stay inside it,
    // and by an absolute floor against coordinates far from the origin.
    let scale = lo.abs().max(hi.abs()).max_element();
    let margin = 0.02 * size + 1e-4 * scale;
    Some(ClearBox {
        lo: lo - Vec3::splat(margin),
        hi: hi + Vec3::splat(margin),
        centroid,
    })
}

impl LightSet {
    /// Where a shadow ray from `o` along unit `d` toward point `y` on light `light` (whose
    /// surface's geometric normal there is `ng`, either orientation) may end instead of
    /// `t_max`: where it enters the light's clear box, when the light has one (see the
    /// module's documentation), `o` lies outside it and in front of `y`'s triangle; `t_max`
    /// otherwise. Whether the segment up to the returned distance is blocked is whether `y`
    /// is visible from `o`.
    #[inline]
    pub fn shadow_end(&self, light: u32, o: Vec3, d: Vec3, t_max: f32, y: Vec3, ng: Vec3) -> f32 {
        match self.clear.get(light as usize) {
            Some(Some(b)) => b.end(o, d, t_max, y, ng),
            _ => t_max,
        }
    }

    /// How many lights have a clear box (shadow rays toward them end where they enter it).
    pub fn clear_lights(&self) -> usize {
        self.clear.iter().filter(|b| b.is_some()).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use restir_geometry::{Accel, TriangleMesh, shadow_ray_between};
    use restir_sampling::Pcg32;

    /// A sphere of `around × rows` quads (two triangles each, fans at the poles) around `c`.
    fn bulb(c: Vec3, r: f32, around: u32, rows: u32) -> TriangleMesh {
        let mut p = vec![c + Vec3::Y * r, c - Vec3::Y * r];
        for i in 1..rows {
            let theta = std::f32::consts::PI * i as f32 / rows as f32;
            for j in 0..around {
                let phi = std::f32::consts::TAU * j as f32 / around as f32;
                let s = theta.sin();
                p.push(c + r * Vec3::new(s * phi.cos(), theta.cos(), s * phi.sin()));
            }
        }
        let ring = |i: u32, j: u32| 2 + (i - 1) * around + j % around;
        let mut t = Vec::new();
        for j in 0..around {
            t.push([0, ring(1, j + 1), ring(1, j)]);
            t.push([1, ring(rows - 1, j), ring(rows - 1, j + 1)]);
            for i in 1..rows - 1 {
                let (a, b, c2, d) = (
                    ring(i, j),
                    ring(i, j + 1),
                    ring(i + 1, j + 1),
                    ring(i + 1, j),
                );
                t.push([a, b, c2]);
                t.push([a, c2, d]);
            }
        }
        TriangleMesh::new(p, None, None, t, false).unwrap()
    }

    fn tri(a: Vec3, b: Vec3, c: Vec3) -> Shape {
        Shape::Mesh(TriangleMesh::new(vec![a, b, c], None, None, vec![[0, 1, 2]], false).unwrap())
    }

    /// Shadow rays toward points on a bulb nothing comes near give the same answer ending at
    /// its clear box as at the point, over receivers all around it with occluders between
    /// (but for rounding where the full ray grazes the bulb's own triangles edge-on);
    /// a box forged around a bulb that an occluder does come near gives wrong answers (the
    /// negative control), and the set gives that bulb none.
    #[test]
    fn ending_at_the_clear_box_changes_no_answer() {
        let lamp = bulb(Vec3::new(0.0, 2.0, 0.0), 0.3, 16, 12);
        let crowded = bulb(Vec3::new(3.0, 2.0, 0.0), 0.3, 16, 12);
        let mut shapes = vec![Shape::Mesh(lamp.clone()), Shape::Mesh(crowded.clone())];
        // A sliver just beside the crowded bulb, inside its box, and occluders around both.
        shapes.push(tri(
            Vec3::new(2.69, 1.6, -0.2),
            Vec3::new(2.69, 2.4, -0.2),
            Vec3::new(2.69, 2.0, 0.3),
        ));
        let mut rng = Pcg32::new(7, 3);
        for _ in 0..200 {
            let c = Vec3::new(
                rng.next_f32() * 8.0 - 2.5,
                rng.next_f32() * 4.0,
                rng.next_f32() * 6.0 - 3.0,
            );
            if (c - Vec3::new(0.0, 2.0, 0.0)).length() < 0.9
                || (c - Vec3::new(3.0, 2.0, 0.0)).length() < 0.9
            {
                continue;
            }
            let e = |rng: &mut Pcg32| {
                (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5) * 0.6
            };
            shapes.push(tri(c + e(&mut rng), c + e(&mut rng), c + e(&mut rng)));
        }
        let radiance = Vec3::ONE;
        let lights = vec![
            Light::Area { shape: 0, radiance },
            Light::Area { shape: 1, radiance },
        ];
        let boxes = clear_boxes(&lights, &shapes);
        assert!(boxes[0].is_some() && boxes[1].is_none(), "{boxes:?}");
        let accel = Accel::build(&shapes);
        let forged = convex_box(crowded.positions(), crowded.indices()).unwrap();
        let (mut checked, mut ended, mut blocked, mut grazes, mut forged_wrong) = (0, 0, 0, 0, 0);
        for _ in 0..20_000 {
            let x = Vec3::new(
                rng.next_f32() * 10.0 - 3.5,
                rng.next_f32() * 5.0 - 0.5,
                rng.next_f32() * 8.0 - 4.0,
            );
            for (mesh, b) in [(&lamp, boxes[0].unwrap()), (&crowded, forged)] {
                let k = (rng.next_f32() * mesh.triangle_count() as f32) as usize;
                let [a, bb, c] = mesh.triangle(k.min(mesh.triangle_count() - 1));
                let (u, v) = (rng.next_f32(), rng.next_f32());
                let (u, v) = if u + v > 1.0 {
                    (1.0 - u, 1.0 - v)
                } else {
                    (u, v)
                };
                let y = a + u * (bb - a) + v * (c - a);
                let ng = (bb - a).cross(c - a).normalize();
                if ng.dot(x - y) <= 0.0 {
                    continue; // the back of the bulb's triangle: no contact
                }
                let (ray, t_max) = shadow_ray_between(x, Vec3::ZERO, y);
                let end = b.end(ray.o, ray.d, t_max, y, ng);
                let full = accel.occluded(&ray, t_max);
                let short = accel.occluded(&ray, end);
                if std::ptr::eq(mesh, &lamp) {
                    // Where they differ, the full ray grazed the bulb's own neighbouring
                    // triangle by rounding, at a contact almost edge-on (which the shorter ray
                    // rightly ignores).
                    if full != short {
                        let hit = accel.intersect(&ray, t_max).map(|h| h.shape);
                        let cos = ng.dot((x - y).normalize());
                        assert!(hit == Some(0) && cos < 1e-3, "x {x} y {y}: {hit:?} {cos}");
                        grazes += 1;
                    }
                    checked += 1;
                    ended += (end < t_max) as u32;
                    blocked += short as u32;
                } else {
                    forged_wrong += (full != short) as u32;
                }
            }
        }
        assert!(
            checked > 5000 && ended as f32 > 0.9 * checked as f32,
            "{checked} {ended}"
        );
        assert!(
            blocked > 500 && blocked < checked - 500,
            "{blocked} of {checked}"
        );
        assert!(grazes * 1000 < checked, "{grazes} of {checked}");
        assert!(forged_wrong > 20, "{forged_wrong}");
    }

    /// An octahedron around `c` with radius `r`, outward winding.
    fn octahedron(c: Vec3, r: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let p = vec![
            c + Vec3::X * r,
            c - Vec3::X * r,
            c + Vec3::Y * r,
            c - Vec3::Y * r,
            c + Vec3::Z * r,
            c - Vec3::Z * r,
        ];
        let mut t = Vec::new();
        for &x in &[0u32, 1] {
            for &y in &[2u32, 3] {
                for &z in &[4u32, 5] {
                    t.push([x, y, z]);
                }
            }
        }
        (p, t)
    }

    #[test]
    fn a_convex_mesh_has_a_box_and_a_dented_one_does_not() {
        let (p, t) = octahedron(Vec3::new(1.0, 2.0, 3.0), 0.5);
        let b = convex_box(&p, &t).expect("convex");
        assert!(b.lo.cmplt(Vec3::new(0.5, 1.5, 2.5)).all());
        assert!((b.centroid - Vec3::new(1.0, 2.0, 3.0)).length() < 1e-6);
        // One vertex pushed inside the square of its four neighbours: a dent.
        let mut dented = p.clone();
        dented[0] = Vec3::new(0.8, 2.0, 3.0);
        assert!(convex_box(&dented, &t).is_none());
        // A flat mesh (a quad) has no inside.
        let quad = [Vec3::ZERO, Vec3::X, Vec3::X + Vec3::Y, Vec3::Y];
        assert!(convex_box(&quad, &[[0, 1, 2], [0, 2, 3]]).is_none());
    }
}
