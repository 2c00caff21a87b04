//! Tests of the acceleration structure: hits against brute force, self-intersection, grouping.

use super::prims::intersect_triangle;
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
        let r = TRay::new(o.into(), d.into());
        let mut best = f32::INFINITY;
        for i in 0..accel.prims.len() {
            best = best.min(accel.intersect_prim(i, &r, f32::INFINITY));
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
        let r = TRay::new(o.into(), d.into());
        let best = (0..accel.prims.len())
            .map(|i| accel.intersect_prim(i, &r, f32::INFINITY))
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

/// [`scene`] uniformly scaled by `s`.
fn scaled_scene(s: f32) -> Vec<Shape> {
    let mut shapes = scene();
    for shape in &mut shapes {
        match shape {
            Shape::Mesh(m) => m.transform(&glam::Affine3A::from_scale(Vec3::splat(s))),
            Shape::Sphere(sp) => *sp = Sphere::new(sp.center * s, sp.radius * s, false),
            Shape::Cylinder(_) | Shape::SdfGrid(_) => unreachable!("scene() has none"),
        }
    }
    shapes
}

/// The scales a scene may come in (micrometres to thousands of kilometres, in metres).
const SCALES: [f32; 5] = [1e-6, 1e-3, 1.0, 1e3, 1e6];

/// The same rays into the same scene in any unit find the same hits at the scaled distances:
/// no absolute epsilon culls a small scene (the traversal once skipped every box ending within
/// 10⁻⁴ of the ray's origin) or its triangles (a determinant threshold of 10⁻²⁰).
#[test]
fn hits_are_the_same_at_every_scale() {
    for s in SCALES {
        let shapes = scaled_scene(s);
        let accel = Accel::build(&shapes);
        let unit = Accel::build(&scene());
        let mut rng = Pcg32::new(11, 12);
        let (mut same, mut total) = (0, 0);
        for _ in 0..2000 {
            let o = Vec3::new(
                rng.next_f32() * 12.0 - 6.0,
                rng.next_f32() * 12.0 - 6.0,
                rng.next_f32() * 6.0 + 0.1,
            );
            let d = restir_sampling::warp::sample_uniform_sphere(rng.next_2d());
            let want = unit.intersect(&Ray::new(o, d), f32::INFINITY);
            let got = accel.intersect(&Ray::new(o * s, d), f32::INFINITY);
            total += 1;
            match (want, got) {
                (Some(w), Some(g)) => {
                    assert!(
                        (g.t / s - w.t).abs() <= 1e-4 * w.t.max(1.0),
                        "scale {s}: t {} against {}",
                        g.t / s,
                        w.t
                    );
                    same += usize::from((w.shape, w.prim) == (g.shape, g.prim));
                }
                (None, None) => same += 1,
                (w, g) => panic!("scale {s}: {w:?} against {g:?} for o {o} d {d}"),
            }
        }
        // Edges and ties may name a neighbour; nearly all are the same primitive.
        assert!(same * 100 >= total * 99, "scale {s}: {same} of {total}");
    }
}

/// Rays leaving a surface never hit it again, at every scale and at every distance from the
/// origin: points around the world origin on a floor whose vertices are 10 units away (where
/// an offset relative to the point alone is smaller than the intersection test's rounding,
/// which is relative to the vertices), a point exactly at the origin, and points far out.
/// Reflected rays leave the convex shape they start on for good; transmitted rays must not hit
/// the same triangle (or the floor's plane) again, nor the sphere short of its far side.
#[test]
fn no_self_intersection_at_any_scale_near_the_origin() {
    for s in SCALES {
        let shapes = scaled_scene(s);
        let accel = Accel::build(&shapes);
        let mut rng = Pcg32::new(21, 22);
        let mut checked = 0;
        for i in 0..20_000 {
            // Half the targets within 10⁻³ units of the origin (10⁻⁴ of the floor's size),
            // one exactly at it, the rest anywhere.
            let spread = if i % 2 == 0 { 1e-3 } else { 4.0 };
            let target = if i == 0 {
                Vec3::ZERO
            } else {
                Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, 0.0) * (2.0 * spread)
            };
            let o = Vec3::new(rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 8.0 - 4.0, 5.0);
            let o = if i % 5 == 0 {
                // Onto the cube and the sphere too.
                Vec3::new(rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 8.0 - 4.0, -5.0)
            } else {
                o
            };
            let ray = Ray::new(o * s, (target - o).normalize());
            let Some(hit) = accel.intersect(&ray, f32::INFINITY) else {
                continue;
            };
            let si = accel.surface_interaction(&shapes, &hit, &ray);
            let towards = si.ng * -si.ng.dot(ray.d).signum();
            let local = restir_sampling::warp::sample_cosine_hemisphere(rng.next_2d());
            // Reflected: back to the side the ray came from.
            let d = Frame::from_normal(towards).to_world(local);
            let o2 = offset_ray_origin(si.p, si.ng, d);
            if let Some(h2) = accel.intersect(&Ray::new(o2, d), f32::INFINITY) {
                assert!(
                    h2.shape != hit.shape,
                    "scale {s}: reflected ray from {} hit shape {} again at t = {}",
                    si.p,
                    hit.shape,
                    h2.t
                );
            }
            // Shadow ray to a point above, on the reflected side.
            let (r, t_max) = crate::shadow_ray_towards(si.p, si.ng, d, s * 0.05);
            if accel.occluded(&r, t_max) {
                let h = accel.intersect(&r, t_max).unwrap();
                assert!(
                    h.shape != hit.shape,
                    "scale {s}: shadow ray blocked by its own surface"
                );
            }
            // Transmitted: through to the other side.
            let d = Frame::from_normal(-towards).to_world(local);
            let o2 = offset_ray_origin(si.p, si.ng, d);
            if let Some(h2) = accel.intersect(&Ray::new(o2, d), f32::INFINITY) {
                // The sphere's far side is a real hit (a chord of 10⁻⁴ of its radius is a
                // direction within 3·10⁻⁵ of its tangent plane); a triangle, and the floor's
                // plane, are never hit again.
                let sphere = matches!(shapes[hit.shape as usize], Shape::Sphere(_));
                let again = if sphere {
                    h2.shape == hit.shape && h2.t < 0.5e-4 * s
                } else {
                    (h2.shape, h2.prim) == (hit.shape, hit.prim) || (hit.shape, h2.shape) == (0, 0)
                };
                assert!(
                    !again,
                    "scale {s}: transmitted ray from {} hit shape {} prim {} again at t = {}",
                    si.p, hit.shape, hit.prim, h2.t
                );
            }
            checked += 1;
        }
        assert!(checked > 10_000, "scale {s}: {checked}");
    }
}

/// A floor, a tilted cylinder and a signed distance grid of a sphere.
fn analytic_scene() -> Vec<Shape> {
    let mut floor = Shape::rectangle();
    floor.transform(&glam::Affine3A::from_scale(Vec3::splat(10.0)));
    let cylinder = crate::Cylinder::new(
        Vec3::ZERO,
        Vec3::Z,
        0.7,
        glam::Affine3A::from_rotation_translation(
            glam::Quat::from_rotation_x(0.6),
            Vec3::new(-1.5, 0.0, 0.5),
        ) * glam::Affine3A::from_scale(Vec3::new(1.0, 1.0, 2.0)),
        false,
    )
    .unwrap();
    let n = 16u32;
    let mut values = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let p = Vec3::new(x as f32, y as f32, z as f32) / (n - 1) as f32;
                values.push((p - Vec3::splat(0.5)).length() - 0.35);
            }
        }
    }
    let grid = crate::SdfGrid::new(
        n,
        values,
        glam::Affine3A::from_scale_rotation_translation(
            Vec3::splat(2.0),
            glam::Quat::from_rotation_z(0.4),
            Vec3::new(1.0, -1.0, 0.2),
        ),
        crate::SdfNormals::Smooth,
    )
    .unwrap();
    vec![
        Shape::Mesh(floor),
        Shape::Cylinder(cylinder),
        Shape::SdfGrid(grid),
    ]
}

/// With cylinders and grid voxels in the BVH, every hit is the brute-force closest hit, the
/// occlusion answer agrees, and rays leaving a hit through the offset origin do not hit the
/// same surface again right away.
#[test]
fn analytic_shapes_in_the_bvh() {
    let shapes = analytic_scene();
    let accel = Accel::build(&shapes);
    assert_eq!(accel.primitive_count(), 2 + 1 + shapes[2].primitive_count());
    let mut rng = Pcg32::new(31, 32);
    let mut seen = [0usize; 3];
    for _ in 0..4000 {
        let o = Vec3::new(
            rng.next_f32() * 8.0 - 4.0,
            rng.next_f32() * 8.0 - 4.0,
            rng.next_f32() * 4.0 + 0.1,
        );
        let d = restir_sampling::warp::sample_uniform_sphere(rng.next_2d());
        let ray = Ray::new(o, d);
        let r = TRay::new(o.into(), d.into());
        let best = (0..accel.prims.len())
            .map(|i| accel.intersect_prim(i, &r, f32::INFINITY))
            .fold(f32::INFINITY, f32::min);
        let got = accel.intersect(&ray, f32::INFINITY);
        match got {
            Some(h) => assert!((h.t - best).abs() <= 1e-4 * best.max(1.0)),
            None => assert!(best.is_infinite()),
        }
        assert_eq!(accel.occluded(&ray, f32::INFINITY), best.is_finite());
        let Some(hit) = got else { continue };
        seen[hit.shape as usize] += 1;
        let si = accel.surface_interaction(&shapes, &hit, &ray);
        assert!(
            (si.p - ray.at(hit.t)).length() < 1e-4,
            "{} vs {}",
            si.p,
            ray.at(hit.t)
        );
        let towards = si.ng * -si.ng.dot(ray.d).signum();
        let d = Frame::from_normal(towards).to_world(
            restir_sampling::warp::sample_cosine_hemisphere(rng.next_2d()),
        );
        let o2 = offset_ray_origin(si.p, si.ng, d);
        if let Some(h2) = accel.intersect(&Ray::new(o2, d), f32::INFINITY) {
            assert!(
                !(h2.shape == hit.shape && h2.t < 1e-3),
                "shape {} hit again at t = {} from {}",
                hit.shape,
                h2.t,
                si.p
            );
        }
    }
    assert!(seen.iter().all(|&n| n > 50), "{seen:?}");
}

/// Rays aimed at the edge where two walls meet (each wall a flat box, the ray leaving one box's
/// slab exactly where it enters the other's) find a wall whenever one of the walls' own triangle
/// tests is hit. The traversal this replaced (obvhs's quantized boxes, decoded at each test, and
/// its clamped reciprocal) culled the box of 82 of these 19 489 rays, which escaped through the
/// corner.
#[test]
fn rays_into_the_edge_of_two_walls_are_not_culled() {
    // A Cornell box's ceiling (y = 2) and left wall (x = −1), 2 units across.
    let mut ceiling = Shape::rectangle();
    ceiling.transform(
        &(glam::Affine3A::from_translation(Vec3::new(0.0, 2.0, 0.0))
            * glam::Affine3A::from_rotation_x(std::f32::consts::FRAC_PI_2)),
    );
    let mut wall = Shape::rectangle();
    wall.transform(
        &(glam::Affine3A::from_translation(Vec3::new(-1.0, 1.0, 0.0))
            * glam::Affine3A::from_rotation_y(std::f32::consts::FRAC_PI_2)),
    );
    let shapes = vec![Shape::Mesh(ceiling), Shape::Mesh(wall)];
    for accel in [Accel::build(&shapes), {
        let mut a = Accel::build(&shapes);
        a.force_scalar();
        a
    }] {
        let mut rng = Pcg32::new(11, 12);
        let (mut posed, mut found) = (0, 0);
        for _ in 0..20_000 {
            // From around a camera in front of the box to a point on the shared edge.
            let o = Vec3::new(
                rng.next_f32() * 0.02 - 0.01,
                1.0 + rng.next_f32() * 0.02 - 0.01,
                3.6,
            );
            let target = Vec3::new(-1.0, 2.0, rng.next_f32() * 1.8 - 0.9);
            let ray = Ray::new(o, (target - o).normalize());
            let r = TRay::new(ray.o.into(), ray.d.into());
            let brute = (0..accel.prims.len())
                .map(|i| accel.intersect_prim(i, &r, f32::INFINITY))
                .fold(f32::INFINITY, f32::min);
            if brute.is_finite() {
                posed += 1;
                found += accel.intersect(&ray, f32::INFINITY).is_some() as u32;
            }
        }
        assert!(posed > 10_000, "{posed}");
        assert_eq!(
            found, posed,
            "rays that hit a wall's triangle but not its box"
        );
    }
}

/// The node test is conservative: a ray whose exact line passes through a child box (built
/// around a point of the ray, its bounds rounded outward, so the point lies within an `f32` step
/// of up to three faces, or on a flat face) is reported as entering it, for rays in every
/// octant, grazing and axis-parallel ones included. Without [`wide::EXIT_SCALE`] rounding puts
/// the entry after the exit for some of them. And a box the ray does not reach (the rounding
/// hull of a point behind its origin) is reported missed, also when the ray is parallel to an
/// axis and its origin lies on the box's faces there: the NaN that slab gives must be passed
/// over, not let through in place of the other slabs' distances.
#[test]
fn the_node_test_enters_every_box_the_ray_passes_through() {
    use wide::{Kernel, Node};
    let mut rng = Pcg32::new(21, 22);
    let (mut missed, mut entered) = (0, 0);
    let total = 200_000;
    for k in 0..total {
        let o = Vec3::new(
            rng.next_f32() * 20.0 - 10.0,
            rng.next_f32() * 20.0 - 10.0,
            rng.next_f32() * 20.0 - 10.0,
        );
        let mut d = restir_sampling::warp::sample_uniform_sphere(rng.next_2d());
        if k % 5 == 0 {
            d[(k / 5) % 3] = 0.0; // parallel to a plane
            d = d.normalize();
        }
        let r = TRay::new(o.into(), d.into());
        let t = rng.next_f32() * 10.0;
        let t_behind = -0.5 - rng.next_f32() * 10.0;
        let mut node = Node::default();
        for a in 0..3 {
            // The point at `t`, exactly (f64), and the box's bounds on either side of it.
            let p = o[a] as f64 + t as f64 * d[a] as f64;
            let (lo, hi) = (round_down(p), round_up(p));
            let extent = if rng.next_f32() < 0.3 {
                0.0
            } else {
                rng.next_f32() * 2.0
            };
            let (lo, hi) = if rng.next_f32() < 0.5 {
                (lo, hi + extent)
            } else {
                (lo - extent, hi)
            };
            node.b[2 * a] = [f32::INFINITY; 8];
            node.b[2 * a + 1] = [f32::NEG_INFINITY; 8];
            node.b[2 * a][3] = lo;
            node.b[2 * a + 1][3] = hi;
            let behind = o[a] as f64 + t_behind as f64 * d[a] as f64;
            node.b[2 * a][5] = round_down(behind);
            node.b[2 * a + 1][5] = round_up(behind);
        }
        let (mask, entry) = wide::Scalar::node_hits(&node, &r, f32::INFINITY);
        #[cfg(target_arch = "x86_64")]
        if Accel::build(&[]).uses_avx2() {
            // SAFETY: `uses_avx2` is set only when the CPU has AVX2, POPCNT, BMI1 and LZCNT.
            #[allow(unsafe_code)]
            let (m, e) = unsafe { super::avx2::node_hits_avx2(&node, &r, f32::INFINITY) };
            assert_eq!(m, mask, "the AVX2 node test differs from the scalar one");
            assert_eq!(e.map(f32::to_bits), entry.map(f32::to_bits));
        }
        if mask & 1 << 3 == 0 {
            missed += 1;
        }
        if mask & 1 << 5 != 0 {
            entered += 1;
        }
    }
    assert_eq!(
        missed, 0,
        "boxes the ray passes through, reported missed (of {total})"
    );
    assert_eq!(
        entered, 0,
        "boxes behind the ray's origin, reported entered (of {total})"
    );
}

fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x { f.next_down() } else { f }
}

fn round_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x { f.next_up() } else { f }
}
