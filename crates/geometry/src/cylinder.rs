//! Mitsuba 3's `cylinder` (plugin page "Cylinder (cylinder)"): the open tube around the segment
//! from `p0` to `p1` with radius `radius`, placed by `to_world`; no end caps, normals outwards
//! unless `flip_normals`.
//!
//! Object space is the unit tube `x² + y² = 1`, `0 ≤ z ≤ 1`; `p0`, `p1` and `radius` are folded
//! into the object-to-world transform as Mitsuba does (`to_world · translate(p0) · frame(p1 − p0)
//! · scale(r, r, |p1 − p0|)`, the frame built around the axis by [`Frame::from_normal`], the same
//! construction as Mitsuba's `coordinate_system`, so texture coordinates agree). A point is named
//! by its texture coordinates `(φ/2π, z)` in object space, which are also its parameters.

use core::f32::consts::PI;

use glam::{Affine3A, Mat3A, Vec2, Vec3, Vec3A};

use crate::Frame;

/// An open cylinder (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    to_world: Affine3A,
    to_object: Affine3A,
    radius: f32,
    length: f32,
    flip_normals: bool,
}

impl Cylinder {
    /// The cylinder around `p0 → p1` with `radius`, then placed by `to_world`. Refused (with the
    /// reason) when the segment or the radius is degenerate, or when the transform shears, scales
    /// the tube's cross-section unevenly (an elliptic tube: Mitsuba warns and misstates its area)
    /// or mirrors it (Mitsuba then decides the normals' side from a polar decomposition).
    pub fn new(
        p0: Vec3,
        p1: Vec3,
        radius: f32,
        to_world: Affine3A,
        flip_normals: bool,
    ) -> Result<Self, String> {
        let d = p1 - p0;
        let length = d.length();
        if !(length.is_finite() && length > 0.0) {
            return Err(format!(
                "cylinder p0 {p0} and p1 {p1} must be distinct finite points"
            ));
        }
        if !(radius.is_finite() && radius > 0.0) {
            return Err(format!("cylinder radius {radius} must be positive"));
        }
        let f = Frame::from_normal(d / length);
        let local = Affine3A::from_translation(p0)
            * Affine3A::from_mat3(glam::Mat3::from_cols(f.s, f.t, f.n))
            * Affine3A::from_scale(Vec3::new(radius, radius, length));
        let m = to_world * local;
        let (a, b, c) = (
            Vec3::from(m.matrix3.x_axis),
            Vec3::from(m.matrix3.y_axis),
            Vec3::from(m.matrix3.z_axis),
        );
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let det = m.matrix3.determinant();
        if !(det.is_finite() && det.abs() > 1e-6 * la * lb * lc) {
            return Err("cylinder transform is degenerate (zero scale)".into());
        }
        let tol = 1e-4;
        if (la - lb).abs() > tol * la.max(lb) {
            return Err(format!(
                "cylinder to_world scales the cross-section unevenly ({la} and {lb}): only \
                 circular cylinders are supported (scale x and y alike)"
            ));
        }
        if a.dot(b).abs() > tol * la * lb
            || a.dot(c).abs() > tol * la * lc
            || b.dot(c).abs() > tol * lb * lc
        {
            return Err("cylinder to_world must not shear".into());
        }
        if det < 0.0 {
            return Err("cylinder to_world must not mirror (a negative scale); use \
                        flip_normals to turn the normals inwards"
                .into());
        }
        Ok(Self {
            to_world: m,
            to_object: m.inverse(),
            radius: la,
            length: lc,
            flip_normals,
        })
    }

    /// World-space radius.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// World-space length of the axis.
    pub fn length(&self) -> f32 {
        self.length
    }

    /// Whether normals point inwards.
    pub fn flip_normals(&self) -> bool {
        self.flip_normals
    }

    /// The object-to-world transform (unit tube to world).
    pub fn to_world(&self) -> Affine3A {
        self.to_world
    }

    /// Surface area `2π r l`.
    pub fn area(&self) -> f32 {
        2.0 * PI * self.radius * self.length
    }

    /// World-space bounds: the boxes of the two end circles.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let a = Vec3::from(self.to_world.matrix3.x_axis);
        let b = Vec3::from(self.to_world.matrix3.y_axis);
        let ext = (a * a + b * b).powf(0.5);
        let p0 = self.to_world.transform_point3(Vec3::ZERO);
        let p1 = self.to_world.transform_point3(Vec3::Z);
        (p0.min(p1) - ext, p0.max(p1) + ext)
    }

    /// The distance along `o + t·d` (world space) of the first hit with `t_min < t < t_max`,
    /// where `t_min` is the test's own rounding bound; infinity when none.
    #[inline]
    pub fn intersect(&self, o: Vec3A, d: Vec3A, t_max: f32) -> f32 {
        let lo = self.to_object.transform_point3a(o);
        let ld = self.to_object.matrix3 * d;
        // In f64, as Mitsuba solves it on the CPU.
        let (ox, oy, oz) = (lo.x as f64, lo.y as f64, lo.z as f64);
        let (dx, dy, dz) = (ld.x as f64, ld.y as f64, ld.z as f64);
        let a = dx * dx + dy * dy;
        let b = 2.0 * (dx * ox + dy * oy);
        let c = ox * ox + oy * oy - 1.0;
        let Some((near, far)) = solve_quadratic(a, b, c) else {
            return f32::INFINITY;
        };
        // The rounding of the object-space origin, as a distance along the ray.
        let t_min = (crate::accel::REL_T_MIN * (lo.abs().max_element() + 1.0) / ld.length()) as f64;
        for t in [near, far] {
            let z = oz + dz * t;
            if t > t_min && t < t_max as f64 && (0.0..=1.0).contains(&z) {
                return t as f32;
            }
        }
        f32::INFINITY
    }

    /// The parameters `(φ/2π, z)` of the point of the tube nearest world point `p` (the point
    /// reprojected onto the tube, as Mitsuba reprojects a hit).
    #[inline]
    pub fn param_of(&self, p: Vec3) -> Vec2 {
        let l = self.to_object.transform_point3(p);
        let mut phi = l.y.atan2(l.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        Vec2::new(phi / (2.0 * PI), l.z)
    }

    /// The partial derivatives `(∂p/∂u, ∂p/∂v)` at parameters `param` (Mitsuba's, what a bump
    /// map moves).
    #[inline]
    pub fn uv_derivatives(&self, param: Vec2) -> (Vec3, Vec3) {
        let (sin, cos) = (2.0 * PI * param.x).sin_cos();
        let m: Mat3A = self.to_world.matrix3;
        (
            Vec3::from(m * Vec3A::new(-sin, cos, 0.0)) * (2.0 * PI),
            Vec3::from(m.z_axis),
        )
    }

    /// The world point at parameters `param`, its normal (outwards unless `flip_normals`) and
    /// its tangent `∂p/∂u`.
    #[inline]
    pub fn point_at(&self, param: Vec2) -> (Vec3, Vec3, Vec3) {
        let (sin, cos) = (2.0 * PI * param.x).sin_cos();
        let p = self.to_world.transform_point3(Vec3::new(cos, sin, param.y));
        let m: Mat3A = self.to_world.matrix3;
        let dpdu = Vec3::from(m * Vec3A::new(-sin, cos, 0.0)) * (2.0 * PI);
        let dpdv = Vec3::from(m.z_axis);
        let n = dpdu.cross(dpdv).normalize();
        let n = if self.flip_normals { -n } else { n };
        (p, n, dpdu)
    }
}

/// The roots `(near, far)` of `a t² + b t + c` (the linear case when `a = 0`), or `None`.
fn solve_quadratic(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    if a == 0.0 {
        if b == 0.0 {
            return None;
        }
        let t = -c / b;
        return Some((t, t));
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn unit() -> Cylinder {
        Cylinder::new(Vec3::ZERO, Vec3::Z, 1.0, Affine3A::IDENTITY, false).unwrap()
    }

    fn hit(c: &Cylinder, o: Vec3, d: Vec3) -> f32 {
        c.intersect(o.into(), d.into(), f32::INFINITY)
    }

    #[test]
    fn hits_misses_inside_and_grazing() {
        let c = unit();
        // Straight on, from outside.
        assert!((hit(&c, Vec3::new(-3.0, 0.0, 0.5), Vec3::X) - 2.0).abs() < 1e-6);
        // Missing above the open top and beside it.
        assert!(hit(&c, Vec3::new(-3.0, 0.0, 1.5), Vec3::X).is_infinite());
        assert!(hit(&c, Vec3::new(-3.0, 1.5, 0.5), Vec3::X).is_infinite());
        // Along the axis: through the open ends, nothing.
        assert!(hit(&c, Vec3::new(0.0, 0.0, -2.0), Vec3::Z).is_infinite());
        // From inside: the far wall.
        assert!((hit(&c, Vec3::new(0.0, 0.0, 0.5), Vec3::X) - 1.0).abs() < 1e-6);
        // Entering through the open top, leaving through the wall from inside.
        let d = Vec3::new(1.0, 0.0, -1.0).normalize();
        let t = hit(&c, Vec3::new(0.0, 0.0, 1.5), d);
        assert!((t - 2.0f32.sqrt()).abs() < 1e-5, "{t}");
        // Near wall above the top, far wall inside the tube: the far one.
        let d = Vec3::new(1.0, 0.0, -0.25).normalize();
        let t = hit(&c, Vec3::new(-2.0, 0.0, 1.5), d);
        let p = Vec3::new(-2.0, 0.0, 1.5) + t * d;
        assert!((p.x - 1.0).abs() < 1e-5 && p.z < 1.0, "{p}");
        // Grazing the wall tangentially hits it once, just beyond misses.
        assert!(hit(&c, Vec3::new(-3.0, 1.0, 0.5), Vec3::X).is_finite());
        assert!(hit(&c, Vec3::new(-3.0, 1.0001, 0.5), Vec3::X).is_infinite());
        // t_max bounds the hit.
        assert!(
            c.intersect(Vec3A::new(-3.0, 0.0, 0.5), Vec3A::X, 1.9)
                .is_infinite()
        );
    }

    /// Mitsuba's parameterisation: uv `(φ/2π, z)`, normal outwards, `∂p/∂u` along increasing φ.
    #[test]
    fn parameterisation_and_normals() {
        let c = unit();
        let (p, n, dpdu) = c.point_at(Vec2::new(0.25, 0.3));
        assert!((p - Vec3::new(0.0, 1.0, 0.3)).length() < 1e-6);
        assert!((n - Vec3::Y).length() < 1e-6);
        assert!((dpdu.normalize() + Vec3::X).length() < 1e-6);
        assert!((c.param_of(p) - Vec2::new(0.25, 0.3)).length() < 1e-6);
        let f = Cylinder::new(Vec3::ZERO, Vec3::Z, 1.0, Affine3A::IDENTITY, true).unwrap();
        assert!((f.point_at(Vec2::new(0.25, 0.3)).1 + Vec3::Y).length() < 1e-6);
        // p0, p1, radius: a tube along x of radius 2 from x = 1 to x = 4.
        let c = Cylinder::new(
            Vec3::X,
            Vec3::new(4.0, 0.0, 0.0),
            2.0,
            Affine3A::IDENTITY,
            false,
        )
        .unwrap();
        assert!((c.area() - 2.0 * PI * 2.0 * 3.0).abs() < 1e-4);
        let t = hit(&c, Vec3::new(2.5, 0.0, 5.0), -Vec3::Z);
        assert!((t - 3.0).abs() < 1e-5, "{t}");
        let (lo, hi) = c.bounds();
        assert!((lo - Vec3::new(1.0, -2.0, -2.0)).length() < 1e-5, "{lo}");
        assert!((hi - Vec3::new(4.0, 2.0, 2.0)).length() < 1e-5, "{hi}");
    }

    #[test]
    fn refuses_what_it_cannot_render() {
        let id = Affine3A::IDENTITY;
        assert!(Cylinder::new(Vec3::ZERO, Vec3::ZERO, 1.0, id, false).is_err());
        assert!(Cylinder::new(Vec3::ZERO, Vec3::Z, 0.0, id, false).is_err());
        let uneven = Affine3A::from_scale(Vec3::new(1.0, 2.0, 1.0));
        assert!(Cylinder::new(Vec3::ZERO, Vec3::Z, 1.0, uneven, false).is_err());
        let mirror = Affine3A::from_scale(Vec3::new(-1.0, -1.0, -1.0));
        assert!(Cylinder::new(Vec3::ZERO, Vec3::Z, 1.0, mirror, false).is_err());
        // Scaling along the axis is allowed.
        let long = Affine3A::from_scale(Vec3::new(1.5, 1.5, 2.0));
        let c = Cylinder::new(Vec3::ZERO, Vec3::Z, 1.0, long, false).unwrap();
        assert!((c.radius() - 1.5).abs() < 1e-6 && (c.length() - 2.0).abs() < 1e-6);
    }

    /// Sampling by area for an area light: `sample_from`'s solid-angle density equals
    /// `pdf_sa_from`, and the mean of its reciprocal (the solid angle the tube covers, each
    /// direction counted once per crossing) matches the crossings counted along uniform
    /// directions, within four standard errors; the same estimate with the density 5 % off (the
    /// negative control) does not.
    #[test]
    fn area_sampling_density_is_consistent() {
        let to_world = Affine3A::from_rotation_translation(
            glam::Quat::from_rotation_x(0.7),
            Vec3::new(0.2, 0.1, -0.3),
        );
        let c = Cylinder::new(Vec3::ZERO, Vec3::Z * 1.5, 0.6, to_world, false).unwrap();
        let shape = crate::Shape::Cylinder(c);
        let ref_p = Vec3::new(1.8, -1.2, 0.9);
        let n = 400_000;
        let mut rng = restir_sampling::Pcg32::new(17, 3);
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let (ps, pdf) = shape.sample_from(ref_p, rng.next_2d()).unwrap();
            assert!((pdf - shape.pdf_sa_from(ref_p, ps.p, ps.ng)).abs() <= 1e-4 * pdf);
            let w = 1.0 / pdf as f64;
            sum += w;
            sum2 += w * w;
        }
        let a = sum / n as f64;
        let var_a = (sum2 / n as f64 - a * a) / n as f64;
        // Crossings along uniform directions: 4π · E[count].
        let (mut cnt, mut cnt2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let d = restir_sampling::warp::sample_uniform_sphere(rng.next_2d());
            let mut o = ref_p;
            let mut k = 0.0;
            loop {
                let t = c.intersect(o.into(), d.into(), f32::INFINITY);
                if !t.is_finite() {
                    break;
                }
                k += 1.0;
                o += (t + 1e-4) * d;
            }
            cnt += k;
            cnt2 += k * k;
        }
        let m = cnt / n as f64;
        let b = 4.0 * core::f64::consts::PI * m;
        let var_b = (4.0 * core::f64::consts::PI).powi(2) * (cnt2 / n as f64 - m * m) / n as f64;
        let sigma = (var_a + var_b).sqrt();
        assert!((a - b).abs() < 4.0 * sigma, "{a} vs {b} (σ {sigma})");
        let wrong = a / 1.05;
        assert!(
            (wrong - b).abs() > 4.0 * sigma,
            "the control {wrong} vs {b} (σ {sigma}) should fail"
        );
    }

    proptest! {
        /// Any hit lies on the tube within its height, the ray before it does not cross the tube
        /// within its height, and the reprojected parameters name the same point.
        #[test]
        fn hits_lie_on_the_tube(
            ox in -3.0f32..3.0, oy in -3.0f32..3.0, oz in -2.0f32..3.0,
            dx in -1.0f32..1.0, dy in -1.0f32..1.0, dz in -1.0f32..1.0,
            rx in -1.0f32..1.0, ry in -1.0f32..1.0, rz in -1.0f32..1.0, angle in 0.0f32..6.0,
            radius in 0.2f32..2.0, length in 0.2f32..3.0,
        ) {
            let d = Vec3::new(dx, dy, dz);
            let axis = Vec3::new(rx, ry, rz);
            prop_assume!(d.length() > 1e-2 && axis.length() > 1e-2);
            let d = d.normalize();
            let to_world = Affine3A::from_rotation_translation(
                glam::Quat::from_axis_angle(axis.normalize(), angle),
                Vec3::new(0.3, -0.2, 0.1),
            );
            let c = Cylinder::new(Vec3::ZERO, Vec3::Z * length, radius, to_world, false).unwrap();
            let o = Vec3::new(ox, oy, oz);
            let t = hit(&c, o, d);
            let inv = to_world.inverse();
            let lo = inv.transform_point3(o);
            let ld = inv.transform_vector3(d);
            let on_tube = |t: f32| {
                let p = lo + t * ld;
                (p.x * p.x + p.y * p.y).sqrt() - radius
            };
            if t.is_finite() {
                let p = lo + t * ld;
                prop_assert!(on_tube(t).abs() < 1e-4 * (1.0 + t), "{p}");
                prop_assert!(p.z >= -1e-4 && p.z <= length + 1e-4);
                let q = c.point_at(c.param_of(o + t * d)).0;
                prop_assert!((q - (o + t * d)).length() < 1e-4 * (1.0 + t));
            }
            // No crossing inside the height before t (sampled along the ray).
            let end = if t.is_finite() { t } else { 10.0 };
            let steps = 400;
            let mut prev = on_tube(1e-3 * end);
            let mut prev_z = (lo + 1e-3 * end * ld).z;
            for i in 2..steps {
                let s = end * i as f32 / steps as f32;
                let cur = on_tube(s);
                let z = (lo + s * ld).z;
                // Both samples inside the height: a sign change between them is a crossing
                // within it (a crossing just outside the height can lie between a sample
                // below it and one just inside it).
                let inside = |z: f32| (0.01..length - 0.01).contains(&z);
                if i < steps - 2 && inside(z) && inside(prev_z) {
                    prop_assert!(prev.signum() == cur.signum() || cur.abs() < 1e-3 || prev.abs() < 1e-3,
                        "crossed at {s} before {t}");
                }
                prev = cur;
                prev_z = z;
            }
        }
    }
}
