//! Shapes: triangle meshes, analytic spheres and cylinders, and signed distance grids behind one
//! [`Shape`] enum, their area and
//! solid-angle sampling, the built-in rectangle, cube and disk meshes, the octahedral encoding of
//! unit vectors and the area-to-solid-angle pdf conversion.

use core::f32::consts::PI;
use glam::{Vec2, Vec3};
use restir_sampling::warp;

use crate::{Cylinder, Frame, MeshError, SdfGrid, TriangleMesh};

/// An analytic sphere. Its normals point outwards unless `flip_normals`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius (> 0).
    pub radius: f32,
    /// Whether normals point inwards.
    pub flip_normals: bool,
    /// World directions to the sphere's object space (the inverse of its `to_world`'s rotation):
    /// texture coordinates and tangents are those of the object-space direction, as in Mitsuba.
    pub to_local: glam::Mat3,
}

impl Sphere {
    /// A sphere, its object space aligned with the world's.
    pub fn new(center: Vec3, radius: f32, flip_normals: bool) -> Self {
        Self {
            center,
            radius,
            flip_normals,
            to_local: glam::Mat3::IDENTITY,
        }
    }

    /// The sphere with object space turned by `rotation` (object to world, orthonormal).
    pub fn with_rotation(mut self, rotation: glam::Mat3) -> Self {
        self.to_local = rotation.inverse();
        self
    }

    /// Mitsuba's texture coordinates of the point in world direction `n` (unit, outwards) from
    /// the centre: [`Sphere::uv_of`] of the object-space direction.
    #[inline]
    pub fn local_uv(&self, n: Vec3) -> Vec2 {
        Self::uv_of(self.to_local * n)
    }

    /// The tangent along increasing φ of object space at world direction `n` from the centre.
    #[inline]
    pub fn tangent(&self, n: Vec3) -> Vec3 {
        let l = self.to_local * n;
        self.to_local.transpose() * Vec3::new(-l.y, l.x, 0.0)
    }

    /// The surface point named by `param` (see [`Sphere::param_of`]) and its outward normal.
    #[inline]
    pub fn point_at(&self, param: Vec2) -> (Vec3, Vec3) {
        let n = octahedral_decode(param);
        (self.center + self.radius * n, n)
    }

    /// The parameters that name the point in direction `n` (unit) from the centre: its
    /// octahedral encoding, cheap both ways and exact to about 1e-7.
    #[inline]
    pub fn param_of(n: Vec3) -> Vec2 {
        octahedral_encode(n)
    }

    /// A point uniformly distributed over the sphere's area: the point its parameters name
    /// (see [`Sphere::sample_from`]).
    #[inline]
    pub fn sample_uniform_area(&self, u: Vec2) -> PositionSample {
        self.position_at(Sphere::param_of(warp::sample_uniform_sphere(u)))
    }

    /// The surface point named by `param`, with its normal as the sphere orients it.
    #[inline]
    pub fn position_at(&self, param: Vec2) -> PositionSample {
        let (p, dir) = self.point_at(param);
        let n = if self.flip_normals { -dir } else { dir };
        PositionSample {
            p,
            n,
            ng: n,
            prim: 0,
            param,
        }
    }

    /// Samples a point on the sphere as seen from `ref_p`, with a solid-angle pdf at `ref_p`:
    /// from outside, the cone of directions it subtends; from inside, uniformly by area
    /// ([`Shape::sample_from`]).
    #[inline]
    pub fn sample_from(&self, ref_p: Vec3, u: Vec2) -> Option<(PositionSample, f32)> {
        let to_c = self.center - ref_p;
        let d2 = to_c.length_squared();
        let r2 = self.radius * self.radius;
        if d2 <= r2 * (1.0 + 1e-4) {
            let ps = self.sample_uniform_area(u);
            let area = 4.0 * PI * self.radius * self.radius;
            let pdf = area_to_solid_angle(1.0 / area, ref_p, ps.p, ps.n)?;
            return Some((ps, pdf));
        }
        let dist = d2.sqrt();
        let one_minus_cos_max = one_minus_cos_max(r2, d2);
        let pdf = warp::uniform_cone_pdf_of(one_minus_cos_max);
        if pdf == 0.0 {
            return None;
        }
        // θ from the axis towards the centre, uniform in solid angle over the cone:
        // 1 − cos θ = u·(1 − cos θmax), and sin²θ = (1 − cos θ)(1 + cos θ), both without the
        // cancellation that `1 − cos` suffers for a small or distant sphere.
        let one_minus_cos = u.x * one_minus_cos_max;
        let cos_theta = 1.0 - one_minus_cos;
        let sin2_theta = one_minus_cos * (2.0 - one_minus_cos);
        // The angle α at the centre between the direction back to `ref_p` and the point where
        // that direction first meets the sphere, from the law of sines (Pharr, Jakob and
        // Humphreys, *Physically Based Rendering*, 4th ed., §6.2.4): no ray-sphere
        // intersection, whose `d² − b²` loses the point on a sphere far smaller than its
        // distance.
        let inv_sin_max = dist / self.radius;
        let cos_alpha = sin2_theta * inv_sin_max
            + cos_theta * (1.0 - (sin2_theta * inv_sin_max * inv_sin_max).min(1.0)).sqrt();
        let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
        let (sin_phi, cos_phi) = warp::sincos_turns(u.y);
        let back = Frame::from_normal(to_c * (-1.0 / dist));
        let n = back.to_world(Vec3::new(
            sin_alpha * cos_phi,
            sin_alpha * sin_phi,
            cos_alpha,
        ));
        // The sample is the point its parameters name, which is what a light sample
        // kept by its name (a reservoir's) resolves to: near the silhouette a rounding
        // of the point changes the cosine at the light by orders of magnitude, and a
        // candidate weighed at one point and shaded at the other would be a firefly.
        let uv = Sphere::param_of(n);
        Some((self.position_at(uv), pdf))
    }

    /// Mitsuba's texture coordinates `(φ/2π, θ/π)` (θ from `+z`) of direction `n` from the
    /// centre.
    #[inline]
    pub fn uv_of(n: Vec3) -> Vec2 {
        let mut phi = n.y.atan2(n.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        Vec2::new(phi / (2.0 * PI), n.z.clamp(-1.0, 1.0).acos() / PI)
    }
}

/// The octahedral encoding of unit vector `n` into `[0, 1]²` (Cigolle et al. 2014, "A Survey of
/// Efficient Representations for Independent Unit Vectors").
#[inline]
pub fn octahedral_encode(n: Vec3) -> Vec2 {
    let l1 = n.x.abs() + n.y.abs() + n.z.abs();
    let (mut x, mut y) = (n.x / l1, n.y / l1);
    if n.z < 0.0 {
        let (ax, ay) = (x.abs(), y.abs());
        x = (1.0 - ay) * if x >= 0.0 { 1.0 } else { -1.0 };
        y = (1.0 - ax) * if y >= 0.0 { 1.0 } else { -1.0 };
    }
    Vec2::new(0.5 * x + 0.5, 0.5 * y + 0.5)
}

/// The unit vector [`octahedral_encode`] maps to `e`.
#[inline]
pub fn octahedral_decode(e: Vec2) -> Vec3 {
    let (x, y) = (2.0 * e.x - 1.0, 2.0 * e.y - 1.0);
    let z = 1.0 - x.abs() - y.abs();
    let t = (-z).max(0.0);
    let x = x + if x >= 0.0 { -t } else { t };
    let y = y + if y >= 0.0 { -t } else { t };
    Vec3::new(x, y, z).normalize()
}

/// `1 − cos θmax` of the cone of directions a sphere of squared radius `r2` subtends from a
/// point at squared distance `d2` from its centre, as `sin²θmax / (1 + cos θmax)`: exact where
/// `1 − cos θmax` would round to a few ulps or to 0 (a sphere a thousand times smaller than its
/// distance).
#[inline]
fn one_minus_cos_max(r2: f32, d2: f32) -> f32 {
    let sin2_max = r2 / d2;
    sin2_max / (1.0 + (1.0 - sin2_max).max(0.0).sqrt())
}

/// A point sampled on a shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionSample {
    /// The point.
    pub p: Vec3,
    /// Shading normal at the point (the normal emission is measured against).
    pub n: Vec3,
    /// Geometric normal at the point.
    pub ng: Vec3,
    /// Primitive (triangle) index within the shape; 0 for a sphere.
    pub prim: u32,
    /// Barycentrics (mesh) or [`Sphere::param_of`] parameters (sphere) locating the point.
    pub param: Vec2,
}

/// A geometric shape.
#[derive(Clone, Debug)]
pub enum Shape {
    /// A triangle mesh.
    Mesh(TriangleMesh),
    /// An analytic sphere.
    Sphere(Sphere),
    /// Mitsuba's open cylinder; its parameters are its uv `(φ/2π, z)`.
    Cylinder(Cylinder),
    /// A signed distance grid, one primitive per voxel holding surface; it has no area to emit
    /// from (as in Mitsuba, its area is 0 and it cannot be sampled).
    SdfGrid(SdfGrid),
}

impl Shape {
    /// Surface area.
    pub fn area(&self) -> f32 {
        match self {
            Shape::Mesh(m) => m.area(),
            Shape::Sphere(s) => 4.0 * PI * s.radius * s.radius,
            Shape::Cylinder(c) => c.area(),
            Shape::SdfGrid(_) => 0.0,
        }
    }

    /// The number of primitives the BVH holds for the shape (triangles, voxels; 1 otherwise).
    pub fn primitive_count(&self) -> usize {
        match self {
            Shape::Mesh(m) => m.triangle_count(),
            Shape::SdfGrid(g) => g.voxel_count(),
            Shape::Sphere(_) | Shape::Cylinder(_) => 1,
        }
    }

    /// World-space bounds `(min, max)` of primitive `prim`.
    pub fn primitive_bounds(&self, prim: u32) -> (Vec3, Vec3) {
        match self {
            Shape::Mesh(m) => {
                let [a, b, c] = m.triangle(prim as usize);
                (a.min(b).min(c), a.max(b).max(c))
            }
            Shape::Sphere(s) => (s.center - s.radius, s.center + s.radius),
            Shape::Cylinder(c) => c.bounds(),
            Shape::SdfGrid(g) => g.voxel_bounds(prim),
        }
    }

    /// World-space bounds `(min, max)` of the whole shape.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        match self {
            Shape::SdfGrid(g) => g.bounds(),
            Shape::Mesh(m) => m
                .positions()
                .iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), &p| {
                    (a.min(p), b.max(p))
                }),
            _ => self.primitive_bounds(0),
        }
    }

    /// The partial derivatives `(dp/du, dp/dv)` of the surface in its texture coordinates at
    /// primitive `prim` and parameters `param`, as Mitsuba 3 computes them (a bump map's
    /// frame): on a mesh triangle's with texture coordinates, the edges taken to the `uv` basis
    /// (zero when its `uv` triangle is degenerate), without them the edges themselves; on a
    /// sphere the derivatives of `(φ/2π, θ/π)`'s inverse, `2π·(−Δy, Δx, 0)` and
    /// `π·(Δz cos φ, Δz sin φ, −ρ)` (`Δ` from the centre in the sphere's object space, `ρ` its
    /// distance from the axis, both turned back to the world); on a cylinder
    /// [`Cylinder::uv_derivatives`]. An SDF grid has no texture coordinates: zero (a bump map on
    /// one is refused when the scene is built).
    pub fn uv_derivatives(&self, prim: u32, param: Vec2) -> (Vec3, Vec3) {
        match self {
            Shape::Mesh(m) => m.uv_derivatives(prim as usize),
            Shape::Cylinder(c) => c.uv_derivatives(param),
            Shape::SdfGrid(_) => (Vec3::ZERO, Vec3::ZERO),
            Shape::Sphere(s) => {
                let (p, _) = s.point_at(param);
                let d = s.to_local * (p - s.center);
                let rho = (d.x * d.x + d.y * d.y).sqrt();
                let (cos_phi, sin_phi) = if rho > 0.0 {
                    (d.x / rho, d.y / rho)
                } else {
                    (1.0, 0.0)
                };
                let to_world = s.to_local.transpose();
                (
                    to_world * (2.0 * PI * Vec3::new(-d.y, d.x, 0.0)),
                    to_world * (PI * Vec3::new(d.z * cos_phi, d.z * sin_phi, -rho)),
                )
            }
        }
    }

    /// The surface point at primitive `prim` and parameters `param` (barycentrics for meshes,
    /// [`Sphere::param_of`] for spheres, [`Cylinder::param_of`], [`SdfGrid::param_of`]).
    #[inline]
    pub fn position_at(&self, prim: u32, param: Vec2) -> PositionSample {
        match self {
            Shape::Mesh(m) => {
                let (p, ng, ns) = m.point_at(prim as usize, param);
                PositionSample {
                    p,
                    n: ns,
                    ng,
                    prim,
                    param,
                }
            }
            Shape::Sphere(s) => s.position_at(param),
            Shape::Cylinder(c) => {
                let (p, n, _) = c.point_at(param);
                PositionSample {
                    p,
                    n,
                    ng: n,
                    prim: 0,
                    param,
                }
            }
            Shape::SdfGrid(g) => {
                let (p, ng, n) = g.point_at(prim, param);
                PositionSample {
                    p,
                    n,
                    ng,
                    prim,
                    param,
                }
            }
        }
    }

    /// A uniformly distributed point on the surface; the area pdf is `1 / area()`. `None` for a
    /// signed distance grid (it has no area to sample, as in Mitsuba).
    #[inline]
    pub fn sample_uniform_area(&self, u: Vec2) -> Option<PositionSample> {
        match self {
            Shape::Mesh(m) => {
                let (tri, b, _) = m.sample_point(u)?;
                let (p, ng, n) = m.point_at(tri, b);
                Some(PositionSample {
                    p,
                    n,
                    ng,
                    prim: tri as u32,
                    param: b,
                })
            }
            Shape::Sphere(s) => Some(s.sample_uniform_area(u)),
            // Mitsuba's sample: φ = 2π·u.y, z = u.x.
            Shape::Cylinder(_) => Some(self.position_at(0, Vec2::new(u.y, u.x))),
            Shape::SdfGrid(_) => None,
        }
    }

    /// Samples a point on the shape as seen from `ref_p`, with a solid-angle pdf at `ref_p`.
    /// Meshes and cylinders sample uniformly by area; spheres seen from outside sample the cone of directions
    /// they subtend, from inside uniformly by area. [`Shape::pdf_sa_from`] returns the same pdf.
    #[inline]
    pub fn sample_from(&self, ref_p: Vec3, u: Vec2) -> Option<(PositionSample, f32)> {
        match self {
            Shape::Sphere(s) => s.sample_from(ref_p, u),
            Shape::Mesh(_) | Shape::Cylinder(_) => {
                let ps = self.sample_uniform_area(u)?;
                // Uniform by area: the solid-angle density uses the geometric normal.
                let pdf = area_to_solid_angle(1.0 / self.area(), ref_p, ps.p, ps.ng)?;
                Some((ps, pdf))
            }
            Shape::SdfGrid(_) => None,
        }
    }

    /// The solid-angle pdf at `ref_p` with which [`Shape::sample_from`] returns point `p` with
    /// *geometric* normal `n`.
    #[inline]
    pub fn pdf_sa_from(&self, ref_p: Vec3, p: Vec3, n: Vec3) -> f32 {
        match self {
            Shape::Sphere(s) => {
                let d2 = (s.center - ref_p).length_squared();
                let r2 = s.radius * s.radius;
                if d2 <= r2 * (1.0 + 1e-4) {
                    return area_to_solid_angle(1.0 / self.area(), ref_p, p, n).unwrap_or(0.0);
                }
                warp::uniform_cone_pdf_of(one_minus_cos_max(r2, d2))
            }
            Shape::Mesh(_) | Shape::Cylinder(_) => {
                area_to_solid_angle(1.0 / self.area(), ref_p, p, n).unwrap_or(0.0)
            }
            Shape::SdfGrid(_) => 0.0,
        }
    }

    /// Mitsuba's `rectangle`: `[-1, 1]²` in the `z = 0` plane, normal `+z`, uv over `[0, 1]²`.
    pub fn rectangle() -> TriangleMesh {
        let positions = vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ];
        let normals = vec![Vec3::Z; 4];
        let uvs = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ];
        TriangleMesh::new(
            positions,
            Some(normals),
            Some(uvs),
            vec![[0, 1, 2], [2, 3, 0]],
            false,
        )
        .expect("the unit rectangle is a valid mesh")
    }

    /// Mitsuba's `cube`: `[-1, 1]³` with outward normals, four vertices per face.
    pub fn cube() -> TriangleMesh {
        let mut positions = Vec::with_capacity(24);
        let mut normals = Vec::with_capacity(24);
        let mut uvs = Vec::with_capacity(24);
        let mut indices = Vec::with_capacity(12);
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let mut n = Vec3::ZERO;
                n[axis] = sign;
                // Two tangents with (t1 × t2) = n so that the winding faces outwards.
                let a = Vec3::from_array({
                    let mut v = [0.0; 3];
                    v[(axis + 1) % 3] = 1.0;
                    v
                });
                let b = n.cross(a);
                let base = positions.len() as u32;
                for (sa, sb) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                    let p = n + sa * a + sb * b;
                    positions.push(p);
                    normals.push(n);
                    uvs.push(cube_uv(p, axis, sign));
                }
                indices.push([base, base + 1, base + 2]);
                indices.push([base + 2, base + 3, base]);
            }
        }
        TriangleMesh::new(positions, Some(normals), Some(uvs), indices, false)
            .expect("the unit cube is a valid mesh")
    }

    /// A disk of radius 1 in the `z = 0` plane, normal `+z`, as a fan of `segments` triangles.
    /// Texture coordinates are Mitsuba's `(r, φ/2π)`: every triangle has its own centre vertex
    /// (at `v` of the middle of its segment) and the seam has two rim vertices (`v = 0` and
    /// `v = 1`), so `u` is exact to `1 − cos(π/segments)` and `v` to `½/segments` near the centre.
    pub fn disk(segments: u32) -> Result<TriangleMesh, MeshError> {
        let segments = segments.max(3);
        let n = segments as usize;
        let mut positions = Vec::with_capacity(2 * n + 1);
        let mut uvs = Vec::with_capacity(2 * n + 1);
        // Rim vertices 0..=n (the last one closes the seam at v = 1), then the centres.
        for i in 0..=n {
            let phi = 2.0 * PI * (i % n) as f32 / segments as f32;
            positions.push(Vec3::new(phi.cos(), phi.sin(), 0.0));
            uvs.push(Vec2::new(1.0, i as f32 / segments as f32));
        }
        for i in 0..n {
            positions.push(Vec3::ZERO);
            uvs.push(Vec2::new(0.0, (i as f32 + 0.5) / segments as f32));
        }
        let normals = vec![Vec3::Z; positions.len()];
        let indices = (0..segments)
            .map(|i| [segments + 1 + i, i, i + 1])
            .collect();
        TriangleMesh::new(positions, Some(normals), Some(uvs), indices, false)
    }
}

/// Mitsuba 3's texture coordinates on face `sign·axis` of the cube `[-1, 1]³` (read off
/// Mitsuba's `cube` shape: linear on each face, so exact at the vertices is exact everywhere).
fn cube_uv(p: Vec3, axis: usize, sign: f32) -> Vec2 {
    let h = |x: f32| 0.5 * (1.0 + x);
    let (x, y, z) = (p.x, p.y, p.z);
    match (axis, sign > 0.0) {
        (0, true) => Vec2::new(h(y), h(-z)),
        (0, false) => Vec2::new(h(y), h(z)),
        (1, true) => Vec2::new(h(-x), h(-z)),
        (1, false) => Vec2::new(h(z), h(x)),
        (2, true) => Vec2::new(h(y), h(x)),
        _ => Vec2::new(h(-y), h(x)),
    }
}

/// Converts an area pdf at `p` (normal `n`) to a solid-angle pdf at `ref_p`:
/// `pdf_area · d² / |cos θ|`. `None` when the conversion is degenerate (grazing or coincident).
#[inline]
pub fn area_to_solid_angle(pdf_area: f32, ref_p: Vec3, p: Vec3, n: Vec3) -> Option<f32> {
    let d = p - ref_p;
    let d2 = d.length_squared();
    if d2 <= 0.0 {
        return None;
    }
    let cos = (n.dot(d) / d2.sqrt()).abs();
    let pdf = pdf_area * d2 / cos;
    (pdf.is_finite() && pdf > 0.0).then_some(pdf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octahedral_round_trip() {
        let mut rng = restir_sampling::Pcg32::new(3, 0);
        let axes = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z];
        for i in 0..10_000 {
            let n = if i < axes.len() {
                axes[i]
            } else {
                warp::sample_uniform_sphere(rng.next_2d())
            };
            let e = octahedral_encode(n);
            assert!((0.0..=1.0).contains(&e.x) && (0.0..=1.0).contains(&e.y));
            let m = octahedral_decode(e);
            assert!((m - n).length() < 1e-6, "{n} -> {e} -> {m}");
        }
    }

    /// Texture coordinates of the built-in shapes are Mitsuba 3's (values read off Mitsuba 3.6
    /// `scalar_rgb` with `ray_intersect` at the same points).
    #[test]
    fn builtin_uvs_match_mitsuba() {
        let at = |m: &TriangleMesh, o: Vec3, d: Vec3| -> Vec2 {
            let shapes = vec![Shape::Mesh(m.clone())];
            let accel = crate::Accel::build(&shapes);
            let ray = crate::Ray::new(o, d);
            let hit = accel
                .intersect(&ray, f32::INFINITY)
                .unwrap_or_else(|| panic!("no hit from {o} along {d}"));
            accel.surface_interaction(&shapes, &hit, &ray).uv
        };
        let close =
            |a: Vec2, b: Vec2, tol: f32| assert!((a - b).abs().max_element() < tol, "{a} vs {b}");
        let rect = Shape::rectangle();
        close(
            at(&rect, Vec3::new(-0.5, -0.5, 2.0), -Vec3::Z),
            Vec2::new(0.25, 0.25),
            1e-5,
        );
        close(
            at(&rect, Vec3::new(0.5, 0.5, 2.0), -Vec3::Z),
            Vec2::new(0.75, 0.75),
            1e-5,
        );
        let cube = Shape::cube();
        let cases = [
            ((0.3, 0.6, 3.0), (0.0, 0.0, -1.0), (0.8, 0.65)),
            ((0.3, 0.6, -3.0), (0.0, 0.0, 1.0), (0.2, 0.65)),
            ((3.0, 0.3, 0.6), (-1.0, 0.0, 0.0), (0.65, 0.2)),
            ((-3.0, 0.3, 0.6), (1.0, 0.0, 0.0), (0.65, 0.8)),
            ((0.3, 3.0, 0.6), (0.0, -1.0, 0.0), (0.35, 0.2)),
            ((0.3, -3.0, 0.6), (0.0, 1.0, 0.0), (0.8, 0.65)),
        ];
        for (o, d, uv) in cases {
            close(
                at(&cube, Vec3::from(o), Vec3::from(d)),
                Vec2::from(uv),
                1e-5,
            );
        }
        let disk = Shape::disk(256).unwrap();
        let cases = [
            // Just off the seam at φ = 0, where two sectors share an edge and which one is
            // hit (v = 0 or 1) is the traversal's tie (Mitsuba 3.9.1: 0.000318).
            ((0.5, 1e-3), (0.5, 0.000_318)),
            ((1e-4, 0.5), (0.5, 0.25)),
            ((-0.5, 0.0), (0.5, 0.5)),
            ((1e-4, -0.5), (0.5, 0.75)),
            ((0.25, 0.25), (0.353_553, 0.125)),
            ((0.3, -1e-3), (0.3, 0.999_47)),
        ];
        for ((x, y), uv) in cases {
            close(
                at(&disk, Vec3::new(x, y, 2.0), -Vec3::Z),
                Vec2::from(uv),
                2e-3,
            );
        }
    }

    /// A turned sphere's texture follows it: uv and tangent are those of the object-space
    /// direction (Mitsuba's sphere under a rotating `to_world`).
    #[test]
    fn turned_sphere_uv() {
        let turn = glam::Mat3::from_rotation_z(core::f32::consts::FRAC_PI_2);
        let s = Sphere::new(Vec3::ZERO, 2.0, false).with_rotation(turn);
        let shapes = vec![Shape::Sphere(s)];
        let accel = crate::Accel::build(&shapes);
        // Object direction (cos 30°, sin 30°, 0) (φ = 30°, θ = 90°) is world (−sin 30°, cos 30°, 0).
        let w = Vec3::new(-0.5, 0.75f32.sqrt(), 0.0);
        let ray = crate::Ray::new(5.0 * w, -w);
        let hit = accel.intersect(&ray, f32::INFINITY).unwrap();
        let si = accel.surface_interaction(&shapes, &hit, &ray);
        assert!(
            (si.uv - Vec2::new(1.0 / 12.0, 0.5)).length() < 1e-5,
            "{}",
            si.uv
        );
        // The tangent of increasing φ: object (−sin 30°, cos 30°, 0), world (−cos 30°, −sin 30°, 0).
        let t = Vec3::new(-(0.75f32.sqrt()), -0.5, 0.0);
        assert!((si.shading.s - t).length() < 1e-5, "{}", si.shading.s);
        let plain = Sphere::new(Vec3::ZERO, 2.0, false);
        assert!((plain.local_uv(Vec3::Y) - Vec2::new(0.25, 0.5)).length() < 1e-6);
    }

    #[test]
    fn cube_normals_face_out() {
        let cube = Shape::cube();
        for i in 0..cube.triangle_count() {
            let [a, b, c] = cube.triangle(i);
            let centroid = (a + b + c) / 3.0;
            assert!(cube.face_normal(i).dot(centroid) > 0.0, "face {i}");
        }
        assert!((cube.area() - 24.0).abs() < 1e-4);
    }

    #[test]
    fn rectangle_area_and_normal() {
        let r = Shape::rectangle();
        assert!((r.area() - 4.0).abs() < 1e-6);
        assert!((r.face_normal(0) - Vec3::Z).length() < 1e-6);
        assert!((r.face_normal(1) - Vec3::Z).length() < 1e-6);
    }

    /// The solid-angle pdf `sample_from` returns equals `pdf_sa_from`, and its reciprocal averages
    /// to the solid angle the shape subtends (for a sphere: 2π(1 − cos θmax)).
    #[test]
    fn sphere_cone_sampling_consistent() {
        let shape = Shape::Sphere(Sphere::new(Vec3::new(0.0, 0.0, 3.0), 1.0, false));
        let ref_p = Vec3::ZERO;
        let cos_max = (1.0f32 - 1.0 / 9.0).sqrt();
        let mut rng = restir_sampling::Pcg32::new(1, 1);
        for _ in 0..1000 {
            let (ps, pdf) = shape.sample_from(ref_p, rng.next_2d()).unwrap();
            assert!(((ps.p - Vec3::new(0.0, 0.0, 3.0)).length() - 1.0).abs() < 1e-4);
            assert!(ps.n.dot(ref_p - ps.p) >= -1e-3, "visible side");
            assert!((pdf - shape.pdf_sa_from(ref_p, ps.p, ps.n)).abs() < 1e-4 * pdf);
            assert!((1.0 / pdf - 2.0 * PI * (1.0 - cos_max)).abs() < 1e-4);
        }
    }
}
