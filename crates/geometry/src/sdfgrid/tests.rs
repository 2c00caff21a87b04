//! Tests of the signed distance grid: the voxel test against the trilinear interpolant sampled
//! along the ray, a sphere's grid seen from every side, misses, rays from inside, grazing rays,
//! the parameters' round trip and the normals.

use super::*;
use proptest::prelude::*;

/// The grid of `n³` samples of the distance to a sphere of radius `r` at the cube's centre.
fn sphere_grid(n: u32, r: f32, normals: SdfNormals, to_world: Affine3A) -> SdfGrid {
    let m = (n - 1) as f32;
    let mut v = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let p = Vec3::new(x as f32, y as f32, z as f32) / m;
                v.push((p - Vec3::splat(0.5)).length() - r);
            }
        }
    }
    SdfGrid::new(n, v, to_world, normals).unwrap()
}

/// The closest hit over every voxel (what the BVH returns).
fn closest(g: &SdfGrid, o: Vec3, d: Vec3) -> Option<(f32, u32)> {
    (0..g.voxel_count() as u32)
        .map(|i| (g.intersect(i, o.into(), d.into(), f32::INFINITY), i))
        .filter(|(t, _)| t.is_finite())
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// The interpolant at object point `p`.
fn field(g: &SdfGrid, p: Vec3) -> f32 {
    g.sample(p * (g.resolution() - 1) as f32)
}

#[test]
fn sphere_hits_from_outside_and_inside() {
    let g = sphere_grid(24, 0.3, SdfNormals::Analytic, Affine3A::IDENTITY);
    // Straight at the centre along each axis: the trilinear sphere is within a voxel's
    // interpolation error of the true one.
    for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
        let o = Vec3::splat(0.5) - 2.0 * d;
        let (t, prim) = closest(&g, o, d).expect("hit");
        assert!((t - 1.7).abs() < 0.01, "{d}: {t}");
        let p = o + t * d;
        assert!(field(&g, p).abs() < 1e-4, "{p}");
        let (q, ng, ns) = g.point_at(prim, g.param_of(prim, p));
        assert!((q - p).length() < 1e-5, "{q} vs {p}");
        assert!(ng.dot(-d) > 0.99 && ns.dot(-d) > 0.99, "{ng} {ns}");
    }
    // From the centre (inside): the wall at the radius.
    let (t, _) = closest(&g, Vec3::splat(0.5), Vec3::X).expect("hit from inside");
    assert!((t - 0.3).abs() < 0.01, "{t}");
    // Misses: beside the sphere, and a ray pointing away.
    assert!(closest(&g, Vec3::new(-1.0, 0.9, 0.5), Vec3::X).is_none());
    assert!(closest(&g, Vec3::new(-1.0, 0.5, 0.5), -Vec3::X).is_none());
    // t_max stops short of the surface.
    let o = Vec3::new(-1.0, 0.5, 0.5);
    assert!(
        (0..g.voxel_count() as u32).all(|i| g.intersect(i, o.into(), Vec3A::X, 1.1).is_infinite())
    );
}

/// A ray grazing the sphere's top just above and just below it: the one below hits, near the
/// top, the one above does not.
#[test]
fn grazing_rays() {
    let g = sphere_grid(32, 0.3, SdfNormals::Smooth, Affine3A::IDENTITY);
    let top = 0.5 + 0.3;
    assert!(closest(&g, Vec3::new(-1.0, 0.5, top + 0.01), Vec3::X).is_none());
    let (t, _) = closest(&g, Vec3::new(-1.0, 0.5, top - 0.01), Vec3::X).expect("grazing hit");
    assert!((t - 1.5).abs() < 0.1, "{t}");
}

/// A placed grid: hits and normals follow `to_world` (normals by the inverse transpose).
#[test]
fn transformed_grid() {
    let to_world = Affine3A::from_scale_rotation_translation(
        Vec3::new(2.0, 2.0, 4.0),
        glam::Quat::IDENTITY,
        Vec3::new(1.0, 0.0, 0.0),
    );
    let g = sphere_grid(24, 0.3, SdfNormals::Analytic, to_world);
    // The sphere becomes an ellipsoid with semi-axes 0.6, 0.6, 1.2 around (2, 1, 2).
    let (t, prim) = closest(&g, Vec3::new(2.0, 1.0, 6.0), -Vec3::Z).expect("hit");
    assert!((t - 2.8).abs() < 0.03, "{t}");
    let p = Vec3::new(2.0, 1.0, 6.0 - t);
    let (_, ng, _) = g.point_at(prim, g.param_of(prim, p));
    assert!(ng.dot(Vec3::Z) > 0.99, "{ng}");
    let (t, prim) = closest(&g, Vec3::new(2.0 + 0.5, -3.0, 2.0 + 0.4), Vec3::Y).expect("hit");
    let p = Vec3::new(2.5, -3.0 + t, 2.4);
    let (_, ng, _) = g.point_at(prim, g.param_of(prim, p));
    // The ellipsoid's normal at p: ∇((x/a)² + (y/a)² + (z/c)²).
    let c = p - Vec3::new(2.0, 1.0, 2.0);
    let want = Vec3::new(c.x / 0.36, c.y / 0.36, c.z / 1.44).normalize();
    assert!(ng.dot(want) > 0.995, "{ng} vs {want}");
}

/// Smooth shading normals are continuous across voxel faces, where the geometric normals jump.
#[test]
fn smooth_normals_are_continuous() {
    let g = sphere_grid(12, 0.3, SdfNormals::Smooth, Affine3A::IDENTITY);
    let mut worst_smooth = 0.0f32;
    let mut worst_geometric = 0.0f32;
    let m = 11.0;
    // Rays in the y = 0.5 plane aimed at points of the sphere on both sides of each voxel face
    // x = k/m.
    for k in 4..8 {
        let x = k as f32 / m;
        let mut sides = Vec::new();
        for dx in [-1e-4f32, 1e-4] {
            let o = Vec3::new(x + dx, 0.5, 2.0);
            let (t, prim) = closest(&g, o, -Vec3::Z).expect("hit");
            let p = o - t * Vec3::Z;
            let (_, ng, ns) = g.point_at(prim, g.param_of(prim, p));
            sides.push((ng, ns));
        }
        worst_geometric = worst_geometric.max((sides[0].0 - sides[1].0).length());
        worst_smooth = worst_smooth.max((sides[0].1 - sides[1].1).length());
    }
    assert!(worst_smooth < 2e-3, "smooth normals jump by {worst_smooth}");
    assert!(
        worst_geometric > 5.0 * worst_smooth,
        "the geometric normals should jump more ({worst_geometric} vs {worst_smooth})"
    );
}

#[test]
fn refuses_bad_grids() {
    let id = Affine3A::IDENTITY;
    assert!(SdfGrid::new(1, vec![0.0], id, SdfNormals::Smooth).is_err());
    assert!(SdfGrid::new(2, vec![0.0; 7], id, SdfNormals::Smooth).is_err());
    assert!(SdfGrid::new(2, vec![1.0; 8], id, SdfNormals::Smooth).is_err());
    let mut v = vec![1.0; 8];
    v[0] = f32::NAN;
    assert!(SdfGrid::new(2, v, id, SdfNormals::Smooth).is_err());
    let mut v = vec![1.0; 8];
    v[3] = -1.0;
    assert_eq!(
        SdfGrid::new(2, v, id, SdfNormals::Smooth)
            .unwrap()
            .voxel_count(),
        1
    );
}

proptest! {
    /// In one random voxel, the reported hit is where the interpolant changes sign first along
    /// the ray: zero there, one sign from the voxel's entry up to it.
    #[test]
    fn first_crossing_in_a_voxel(
        values in prop::array::uniform8(-1.0f32..1.0),
        ox in -1.0f32..2.0, oy in -1.0f32..2.0, oz in -1.0f32..2.0,
        dx in -1.0f32..1.0, dy in -1.0f32..1.0, dz in -1.0f32..1.0,
    ) {
        let d = Vec3::new(dx, dy, dz);
        prop_assume!(d.length() > 1e-2);
        let d = d.normalize();
        prop_assume!(!(values.iter().all(|&v| v > 0.0) || values.iter().all(|&v| v < 0.0)));
        let g = SdfGrid::new(2, values.to_vec(), Affine3A::IDENTITY, SdfNormals::Analytic).unwrap();
        let o = Vec3::new(ox, oy, oz);
        let t = g.intersect(0, o.into(), d.into(), f32::INFINITY);
        // The part of the ray inside the voxel.
        let inside = |p: Vec3| p.cmpge(Vec3::ZERO).all() && p.cmple(Vec3::ONE).all();
        let steps = 2000;
        let far = 6.0;
        let mut first = None;
        let mut prev: Option<(f32, f32)> = None;
        for i in 0..=steps {
            let s = far * i as f32 / steps as f32;
            let p = o + s * d;
            if !inside(p) {
                if prev.is_some() { break; }
                continue;
            }
            let f = field(&g, p);
            if let Some((ps, pf)) = prev
                && (pf > 0.0) != (f > 0.0) && first.is_none() {
                first = Some((ps, s));
            }
            prev = Some((s, f));
        }
        if t.is_finite() {
            let p = o + t * d;
            prop_assert!(field(&g, p).abs() < 1e-4, "f({p}) = {}", field(&g, p));
            // No sign change before t (a tangency may hide one from the sampling, not the
            // other way round).
            if let Some((a, _)) = first {
                prop_assert!(t <= a + far / steps as f32 + 1e-4, "crossing at {a} before {t}");
            }
        } else if let Some((a, b)) = first {
            // Missed a sign change the sampling saw: only allowed at the voxel's boundary or
            // where the ray starts (within the rounding bound).
            prop_assert!(a < 1e-3 || b > far - 1e-3, "missed the crossing in [{a}, {b}]");
        }
    }
}
