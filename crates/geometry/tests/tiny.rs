//! Edge cases of the acceleration structure: one primitive, axis-aligned rays (with negative
//! zeros), rays along every axis.
use glam::Vec3;
use restir_geometry::{Accel, Ray, Shape, Sphere};

#[test]
fn axis_aligned_rays_hit() {
    for n in 1..5 {
        let shapes: Vec<Shape> = (0..n)
            .map(|i| Shape::Sphere(Sphere::new(Vec3::splat(i as f32 * 10.0), 1.0, false)))
            .collect();
        let accel = Accel::build(&shapes);
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            for d in [axis, -axis] {
                let ray = Ray::new(-5.0 * d, d);
                let hit = accel.intersect(&ray, f32::INFINITY);
                assert!(
                    hit.is_some_and(|h| (h.t - 4.0).abs() < 1e-4),
                    "{n} prims, d = {d:?}"
                );
                assert!(accel.occluded(&ray, f32::INFINITY));
                assert!(!accel.occluded(&ray, 3.9));
            }
        }
    }
}
