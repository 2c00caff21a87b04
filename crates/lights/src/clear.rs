//! Where a shadow ray toward a point on a light may stop: at the clear box of the light's part.
//!
//! A shadow ray toward a point `y` on an emissive mesh ends at `y`, so its last stretch runs
//! through the mesh's own part of the scene's BVH: near `y` the traversal descends into the
//! nodes of the light's triangles and tests those nearest `y`, which the ray cannot hit before
//! its end. On the seed report's scene (108 lamps, spheres of 960 triangles) that descent is a
//! large share of every shadow ray's cost.
//!
//! For some lights it can be skipped without changing any answer. Decided once, when the set is
//! built, a mesh light is cut into **parts**, the triangles joined by vertices at the same
//! position (a lamp, or each bulb of a string of bulbs in one mesh), and a part has a **clear
//! box** when
//!
//! 1. **the part is convex**: every vertex lies on the inner side of every triangle's plane
//!    (the side of the part's centroid), so the part is part of the boundary of its convex hull;
//! 2. **nothing else is near it**: no primitive but the part's own (another shape's, or another
//!    part's of the same mesh) has a bounding box that meets the part's bounding box grown by a
//!    margin (the clear box).
//!
//! Then, for a receiver `x` strictly in front of the plane of `y`'s triangle (the side away
//! from the centroid), the segment from `x` to `y` meets no triangle of the part before `y`:
//! the whole part lies in the closed inner half-space of that plane, which the segment touches
//! only at `y`. Nor does any other primitive cross the clear box. So when `x` is outside the
//! clear box, `y` is visible from `x` exactly when nothing blocks the segment up to where it
//! enters the box, and the shadow ray may end there ([`LightSet::shadow_end`]). The answer is
//! the same, not an approximation; only rounding at the very end of the ray, where the part's
//! neighbouring triangles could otherwise be grazed, differs, in the ray's favour.

use glam::Vec3;
use restir_geometry::Shape;

use crate::corners::Corners;
use crate::{Light, LightSet};

/// Parts of more triangles are not checked for convexity (the check costs triangles times
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

/// Where shadow rays toward one light may end: the clear boxes of its mesh's parts (a part: the
/// triangles joined by shared vertices, say one bulb of a string of bulbs).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct LightClear {
    /// The clear parts' boxes.
    boxes: Vec<ClearBox>,
    /// Per triangle, its part's box in `boxes` (`NO_BOX`: its part has none); `None` when the
    /// whole mesh is one clear part, `boxes[0]`.
    of_prim: Option<Vec<u32>>,
}

/// A triangle whose part has no clear box.
const NO_BOX: u32 = u32::MAX;

impl LightClear {
    /// The clear box of the part that triangle `prim` belongs to.
    #[inline]
    fn of(&self, prim: u32) -> Option<&ClearBox> {
        match &self.of_prim {
            None => self.boxes.first(),
            Some(of) => self.boxes.get(*of.get(prim as usize)? as usize),
        }
    }
}

/// Each triangle's part of `mesh` (triangles joined by vertices at the same position), numbered
/// from 0, and the number of parts.
fn parts(positions: &[Vec3], indices: &[[u32; 3]]) -> (Vec<u32>, usize) {
    // Vertices at the same position are one (a seam of a uv-mapped bulb splits its vertices).
    let mut first_at = std::collections::HashMap::with_capacity(positions.len());
    let same: Vec<u32> = positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            *first_at
                .entry(p.to_array().map(f32::to_bits))
                .or_insert(i as u32)
        })
        .collect();
    let mut parent: Vec<u32> = (0..positions.len() as u32).collect();
    fn root(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            let up = parent[parent[v as usize] as usize];
            parent[v as usize] = up;
            v = up;
        }
        v
    }
    for t in indices {
        let a = root(&mut parent, same[t[0] as usize]);
        for &v in &t[1..] {
            let b = root(&mut parent, same[v as usize]);
            if a != b {
                parent[b as usize] = a;
            }
        }
    }
    let mut label = vec![u32::MAX; positions.len()];
    let mut count = 0;
    let of: Vec<u32> = indices
        .iter()
        .map(|t| {
            let r = root(&mut parent, same[t[0] as usize]) as usize;
            if label[r] == u32::MAX {
                label[r] = count;
                count += 1;
            }
            label[r]
        })
        .collect();
    (of, count as usize)
}

/// A mesh light's parts as found: each triangle's part, and each part's box where the part is
/// convex.
type Parts = (Vec<u32>, Vec<Option<ClearBox>>);

/// Where shadow rays toward each light may end (`None` for lights without a clear part), for
/// `lights` on `shapes`.
pub(crate) fn clear_boxes(lights: &[Light], shapes: &[Shape]) -> Vec<Option<LightClear>> {
    // Per light on a valid mesh: each triangle's part, and each part's box if it is convex.
    let mut found: Vec<Option<Parts>> = lights
        .iter()
        .map(|l| {
            let Light::Area { shape, .. } = *l else {
                return None;
            };
            let Some(Shape::Mesh(m)) = shapes.get(shape as usize) else {
                return None;
            };
            let (of, count) = parts(m.positions(), m.indices());
            let mut members: Vec<Vec<[u32; 3]>> = vec![Vec::new(); count];
            for (t, &k) in m.indices().iter().zip(&of) {
                members[k as usize].push(*t);
            }
            let boxes: Vec<Option<ClearBox>> = members
                .iter()
                .map(|tris| convex_box(m.positions(), tris))
                .collect();
            boxes.iter().any(Option::is_some).then_some((of, boxes))
        })
        .collect();
    // Which boxes another primitive's box meets: the boxes sorted by their low x, each
    // primitive's box compared with those whose x-range can meet it.
    let mut order: Vec<(f32, u32, u32)> = Vec::new();
    for (light, f) in found.iter().enumerate() {
        if let Some((_, boxes)) = f {
            for (k, b) in boxes.iter().enumerate() {
                if let Some(b) = b {
                    order.push((b.lo.x, light as u32, k as u32));
                }
            }
        }
    }
    if order.is_empty() {
        return vec![None; lights.len()];
    }
    order.sort_by(|a, b| a.0.total_cmp(&b.0));
    let box_of = |found: &[Option<Parts>], light: u32, k: u32| {
        found[light as usize]
            .as_ref()
            .and_then(|(_, b)| b[k as usize])
    };
    let widest = order
        .iter()
        .filter_map(|&(_, l, k)| box_of(&found, l, k).map(|b| b.hi.x - b.lo.x))
        .fold(0.0f32, f32::max);
    let own_shape = |light: u32| match lights[light as usize] {
        Light::Area { shape, .. } => shape,
        _ => u32::MAX,
    };
    let mut met = Vec::new();
    for (si, shape) in shapes.iter().enumerate() {
        for ti in 0..shape.primitive_count() as u32 {
            let (lo, hi) = shape.primitive_bounds(ti);
            let first = order.partition_point(|&(x, _, _)| x < lo.x - widest);
            let last = order.partition_point(|&(x, _, _)| x <= hi.x);
            for &(_, light, k) in &order[first..last.max(first)] {
                let Some(b) = box_of(&found, light, k) else {
                    continue;
                };
                // A part's own triangles do not count.
                if own_shape(light) == si as u32
                    && found[light as usize]
                        .as_ref()
                        .is_some_and(|(of, _)| of[ti as usize] == k)
                {
                    continue;
                }
                // Not provably apart (NaN bounds count as meeting).
                if !(lo.cmpgt(b.hi).any() || hi.cmplt(b.lo).any()) {
                    met.push((light, k));
                }
            }
        }
    }
    for (light, k) in met {
        if let Some((_, boxes)) = &mut found[light as usize] {
            boxes[k as usize] = None;
        }
    }
    found
        .into_iter()
        .map(|f| {
            let (of, boxes) = f?;
            if boxes.len() == 1 {
                return boxes[0].map(|b| LightClear {
                    boxes: vec![b],
                    of_prim: None,
                });
            }
            let mut index = vec![NO_BOX; boxes.len()];
            let mut kept = Vec::new();
            for (k, b) in boxes.iter().enumerate() {
                if let Some(b) = b {
                    index[k] = kept.len() as u32;
                    kept.push(*b);
                }
            }
            (!kept.is_empty()).then(|| LightClear {
                boxes: kept,
                of_prim: Some(of.iter().map(|&k| index[k as usize]).collect()),
            })
        })
        .collect()
}

/// The grown bounding box of a convex part (triangles `indices` of a mesh's `positions`), or
/// `None` when the part is too large to check, flat, degenerate, not finite or not convex.
fn convex_box(positions: &[Vec3], indices: &[[u32; 3]]) -> Option<ClearBox> {
    if indices.is_empty() || indices.len() > MAX_CLEAR_TRIANGLES {
        return None;
    }
    // Only the vertices the triangles use.
    let ids = indices.iter().flatten().map(|&v| v as usize);
    if ids.clone().any(|v| v >= positions.len()) {
        return None;
    }
    let corners = Corners::of(ids.map(|v| positions[v]))?;
    let (lo, hi, centroid) = (corners.lo, corners.hi, corners.centroid);
    let size = (hi - lo).length();
    if !(size > 0.0 && size.is_finite()) {
        return None;
    }
    // Rounding in the planes' normals and offsets, relative to the part's size.
    let tol = 1e-5 * size;
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
        if !corners.behind(if h > 0.0 { n } else { -n }, a, tol) {
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
    /// Where a shadow ray from `o` along unit `d` toward point `y` on triangle `prim` of light
    /// `light` (whose geometric normal there is `ng`, either orientation) may end instead of
    /// `t_max`: where it enters the clear box of the triangle's part, when it has one (see the
    /// module's documentation), `o` lies outside it and in front of `y`'s triangle; `t_max`
    /// otherwise. Whether the segment up to the returned distance is blocked is whether `y`
    /// is visible from `o`, given that the set's shapes are all that can block a ray
    /// ([`LightSet::new`]).
    #[inline]
    #[allow(clippy::too_many_arguments)] // the ray, its end and the point it ends on
    pub fn shadow_end(
        &self,
        light: u32,
        prim: u32,
        o: Vec3,
        d: Vec3,
        t_max: f32,
        y: Vec3,
        ng: Vec3,
    ) -> f32 {
        match self.clear.get(light as usize) {
            Some(Some(c)) => c.of(prim).map_or(t_max, |b| b.end(o, d, t_max, y, ng)),
            _ => t_max,
        }
    }

    /// How many lights have a part with a clear box, and how many such parts they have
    /// (shadow rays toward a point on one end where they enter its box).
    pub fn clear_parts(&self) -> (usize, usize) {
        let lights = self.clear.iter().flatten();
        (lights.clone().count(), lights.map(|c| c.boxes.len()).sum())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use restir_geometry::{Accel, TriangleMesh, shadow_ray_between};
    use restir_sampling::Pcg32;

    /// A sphere of `around × rows` quads (two triangles each, fans at the poles) around `c`.
    fn bulb(c: Vec3, r: f32, around: u32, rows: u32) -> TriangleMesh {
        let (p, t) = restir_testkit::meshes::uv_sphere(c, r, around, rows);
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
            Light::Area {
                shape: 0,
                radiance,
                texture: None,
            },
            Light::Area {
                shape: 1,
                radiance,
                texture: None,
            },
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
            let lamp_box = boxes[0].as_ref().unwrap().boxes[0];
            for (mesh, b) in [(&lamp, lamp_box), (&crowded, forged)] {
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
                let (ray, t_max) = shadow_ray_between(x, Vec3::ZERO, y);
                let end = b.end(ray.o, ray.d, t_max, y, ng);
                if ng.dot(x - y) <= 0.0 {
                    // Behind the point's triangle the ray crosses the bulb: it must keep its
                    // whole length (a shading normal could still make this a contact).
                    assert_eq!(end, t_max, "x {x} y {y}");
                    continue;
                }
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

    /// One mesh of three bulbs, each split along a seam into two halves that share no vertex
    /// index, only positions (as a uv-mapped mesh has them), one of them with an occluder
    /// beside it: three parts, two with clear boxes, the crowded one none, and each triangle
    /// finds its own part's box.
    #[test]
    fn each_part_of_a_string_of_bulbs_has_its_own_box() {
        let centres = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(4.0, 0.0, 0.0),
        ];
        let (mut p, mut t) = (Vec::new(), Vec::new());
        for c in centres {
            let b = bulb(c, 0.3, 12, 8);
            // The bulb's vertices twice: the half with x above the centre uses the copy.
            let base = p.len() as u32;
            p.extend_from_slice(b.positions());
            p.extend_from_slice(b.positions());
            let n = b.positions().len() as u32;
            for tri in b.indices() {
                let mid = tri
                    .iter()
                    .map(|&v| b.positions()[v as usize].x)
                    .sum::<f32>()
                    / 3.0;
                let copy = if mid > c.x { n } else { 0 };
                t.push(tri.map(|v| base + copy + v));
            }
        }
        let string = TriangleMesh::new(p, None, None, t, false).unwrap();
        let per_bulb = string.triangle_count() / 3;
        let (of, count) = parts(string.positions(), string.indices());
        assert_eq!(count, 3);
        assert!((0..3).all(|k| {
            of[k * per_bulb..(k + 1) * per_bulb]
                .iter()
                .all(|&x| x == of[k * per_bulb])
        }));
        let shapes = vec![
            Shape::Mesh(string),
            tri(
                Vec3::new(4.31, -0.2, -0.2),
                Vec3::new(4.31, 0.2, -0.2),
                Vec3::new(4.31, 0.0, 0.3),
            ),
        ];
        let lights = vec![Light::Area {
            shape: 0,
            radiance: Vec3::ONE,
            texture: None,
        }];
        let clear = clear_boxes(&lights, &shapes);
        let c = clear[0].as_ref().expect("two clear parts");
        assert_eq!(c.boxes.len(), 2);
        for (k, centre) in centres.iter().enumerate() {
            let b = c.of((k * per_bulb + 5) as u32);
            if k == 2 {
                assert!(b.is_none());
            } else {
                let b = b.unwrap();
                assert!(b.lo.cmplt(*centre).all() && b.hi.cmpgt(*centre).all());
                assert!((b.hi - b.lo).max_element() < 0.7);
            }
        }
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
