//! Geometry for the `restir` renderer: rays, orthonormal frames, triangle meshes, analytic spheres
//! and cylinders, signed distance grids, cameras, and the acceleration structure (an 8-wide
//! compressed BVH from `obvhs`).
//!
//! Conventions: right-handed world space, `f32`. Normals are unit length. A shape's geometric
//! normal follows its winding (counter-clockwise front faces, as in Mitsuba and OBJ) unless the
//! shape was built with `flip_normals`. Surface pdfs are per unit area (`pdf_area`), direction
//! pdfs per unit solid angle (`pdf_sa`).
//!
//! ```
//! use restir_geometry::{Accel, Ray, Shape, Sphere};
//! use glam::Vec3;
//! let shapes = vec![Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0, false))];
//! let accel = Accel::build(&shapes);
//! let hit = accel.intersect(&Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z), f32::INFINITY).unwrap();
//! assert!((hit.t - 4.0).abs() < 1e-5);
//! let si = accel.surface_interaction(&shapes, &hit, &Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z));
//! assert!((si.p.z - 1.0).abs() < 1e-5);
//! ```

#![deny(missing_docs)]

mod accel;
mod attribute;
mod camera;
mod cylinder;
mod frame;
pub mod lanes;
mod mesh;
mod ray;
mod sdfgrid;
mod shape;

pub use accel::{Accel, Hit, SurfaceInteraction, surface_at};
pub use attribute::{AttributeError, AttributeRate, MeshAttribute};
pub use camera::{Camera, CameraError, FovAxis};
pub use cylinder::Cylinder;
pub use frame::Frame;
pub use mesh::{MeshError, TriangleMesh, angle_weighted_normals};
pub use ray::{Ray, offset_ray_origin, ray_epsilon, shadow_ray_between, shadow_ray_towards};
pub use sdfgrid::{SdfGrid, SdfNormals};
pub use shape::{PositionSample, Shape, Sphere, area_to_solid_angle};

/// Mitsuba 3's relative ray epsilon, `1500 · 2⁻²⁴`.
pub const RAY_EPSILON: f32 = 1500.0 / 16_777_216.0;
/// Shadow rays stop this fraction short of their target.
pub const SHADOW_EPSILON: f32 = 10.0 * RAY_EPSILON;
