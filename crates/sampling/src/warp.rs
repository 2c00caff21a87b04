//! Warps from the unit square to common domains, each with its pdf and, where it exists, its
//! inverse. Directions are in a local frame with `z` up; pdfs over directions are per unit solid
//! angle, pdfs over points per unit area.

use core::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};
use glam::{Vec2, Vec3};

const INV_4PI: f32 = 0.25 * FRAC_1_PI;
const INV_2PI: f32 = 0.5 * FRAC_1_PI;

/// Shirley–Chiu concentric map from the square to the unit disk (area-preserving up to a constant).
#[inline]
pub fn sample_concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    // The angle is π/4·(y/x), or π/2 − π/4·(x/y), whose cosine and sine are the sine and
    // cosine of π/4·(x/y): either way a sine and cosine on [−π/4, π/4].
    if o.x.abs() > o.y.abs() {
        let (s, c) = sincos_quarter(FRAC_PI_4 * (o.y / o.x));
        o.x * Vec2::new(c, s)
    } else {
        let (s, c) = sincos_quarter(FRAC_PI_4 * (o.x / o.y));
        o.y * Vec2::new(s, c)
    }
}

/// The Taylor coefficients of `sin x / x − 1` in powers of `x²`, the highest first (Horner's
/// order): `x²·(−1/3! + x²·(1/5! − …))`. With [`COS_TAYLOR`] the polynomials of
/// [`sincos_quarter`] and of its lanes ([`crate::lanes::sincos_quarter`]).
pub(crate) const SIN_TAYLOR: [f32; 5] = [
    -1.0 / 39_916_800.0,
    1.0 / 362_880.0,
    -1.0 / 5040.0,
    1.0 / 120.0,
    -1.0 / 6.0,
];

/// The Taylor coefficients of `cos x − 1` in powers of `x²`, the highest first.
pub(crate) const COS_TAYLOR: [f32; 6] = [
    1.0 / 479_001_600.0,
    -1.0 / 3_628_800.0,
    1.0 / 40_320.0,
    -1.0 / 720.0,
    1.0 / 24.0,
    -0.5,
];

/// `(sin x, cos x)` for `|x| ≤ π/4`: the Taylor polynomials of degree 11 and 12 (the first
/// omitted terms are below 2·10⁻¹⁰ there, under `f32`'s resolution) by Horner's rule, within
/// an `f32` step of the exact values and a few times cheaper than the library's `sin_cos`.
#[inline(always)]
pub fn sincos_quarter(x: f32) -> (f32, f32) {
    let x2 = x * x;
    let mut s = 0.0;
    for c in SIN_TAYLOR {
        s = s * x2 + c;
    }
    let mut k = 0.0;
    for c in COS_TAYLOR {
        k = k * x2 + c;
    }
    (x + x * (s * x2), k * x2 + 1.0)
}

/// `(sin 2πt, cos 2πt)` for `t ∈ [0, 1]` (an angle in turns, as a uniform number gives it):
/// reduced to the nearest quarter turn exactly (`t − k/4` is exact in `f32`), then
/// [`sincos_quarter`]. Closer to the exact values than `(2π·t).sin_cos()`, which first rounds
/// the angle.
#[inline(always)]
pub fn sincos_turns(t: f32) -> (f32, f32) {
    debug_assert!((0.0..=1.0).contains(&t), "{t} is not in [0, 1]");
    // The nearest quarter: `t·4 + ½ ≥ ½`, so truncation is the floor.
    let k = (t * 4.0 + 0.5) as u32;
    let (s, c) = sincos_quarter((t - k as f32 * 0.25) * (2.0 * PI));
    match k & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// The inverse of [`sample_concentric_disk`].
pub fn invert_concentric_disk(p: Vec2) -> Vec2 {
    let r = p.length();
    if r == 0.0 {
        return Vec2::splat(0.5);
    }
    let mut phi = p.y.atan2(p.x);
    if phi < -FRAC_PI_4 {
        phi += 2.0 * PI;
    }
    let (a, b) = if phi < FRAC_PI_4 {
        (r, phi * r / FRAC_PI_4)
    } else if phi < 3.0 * FRAC_PI_4 {
        (-(phi - FRAC_PI_2) * r / FRAC_PI_4, r)
    } else if phi < 5.0 * FRAC_PI_4 {
        (-r, -(phi - PI) * r / FRAC_PI_4)
    } else {
        ((phi - 3.0 * FRAC_PI_2) * r / FRAC_PI_4, -r)
    };
    (Vec2::new(a, b) + Vec2::ONE) * 0.5
}

/// Uniform density on the unit disk, per unit area.
pub const UNIT_DISK_PDF: f32 = FRAC_1_PI;

/// Cosine-weighted direction on the upper hemisphere (Malley's method over the concentric disk).
#[inline]
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = sample_concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Solid-angle pdf of [`sample_cosine_hemisphere`]: `cos θ / π` for `cos θ > 0`, else 0.
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    if cos_theta > 0.0 {
        cos_theta * FRAC_1_PI
    } else {
        0.0
    }
}

/// The inverse of [`sample_cosine_hemisphere`].
pub fn invert_cosine_hemisphere(w: Vec3) -> Vec2 {
    invert_concentric_disk(Vec2::new(w.x, w.y))
}

/// Uniform direction on the upper hemisphere.
pub fn sample_uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = sincos_turns(u.y);
    Vec3::new(r * c, r * s, z)
}

/// Solid-angle pdf of [`sample_uniform_hemisphere`]: `1 / (2π)`.
pub const UNIFORM_HEMISPHERE_PDF: f32 = INV_2PI;

/// Uniform direction on the unit sphere.
#[inline]
pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = sincos_turns(u.y);
    Vec3::new(r * c, r * s, z)
}

/// Solid-angle pdf of [`sample_uniform_sphere`]: `1 / (4π)`.
pub const UNIFORM_SPHERE_PDF: f32 = INV_4PI;

/// The inverse of [`sample_uniform_sphere`].
pub fn invert_uniform_sphere(w: Vec3) -> Vec2 {
    let mut phi = w.y.atan2(w.x);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    Vec2::new((1.0 - w.z) * 0.5, phi * INV_2PI)
}

/// Uniform direction inside the cone around `+z` with half-angle `acos(cos_theta_max)`.
#[inline]
pub fn sample_uniform_cone(u: Vec2, cos_theta_max: f32) -> Vec3 {
    let cos_theta = (1.0 - u.x) + u.x * cos_theta_max;
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (s, c) = sincos_turns(u.y);
    Vec3::new(sin_theta * c, sin_theta * s, cos_theta)
}

/// Solid-angle pdf of [`sample_uniform_cone`]: `1 / (2π (1 − cos θmax))` inside the cone.
#[inline]
pub fn uniform_cone_pdf(cos_theta_max: f32) -> f32 {
    uniform_cone_pdf_of(1.0 - cos_theta_max)
}

/// [`uniform_cone_pdf`] of a cone given by `1 − cos θmax` (which a narrow cone should compute
/// without cancellation, e.g. as `sin²θmax / (1 + cos θmax)`); 0 for an empty cone or one too
/// narrow for the density to be finite.
#[inline]
pub fn uniform_cone_pdf_of(one_minus_cos_theta_max: f32) -> f32 {
    let solid_angle = 2.0 * PI * one_minus_cos_theta_max;
    let pdf = 1.0 / solid_angle;
    if solid_angle > 0.0 && pdf.is_finite() {
        pdf
    } else {
        0.0
    }
}

/// The inverse of [`sample_uniform_cone`].
pub fn invert_uniform_cone(w: Vec3, cos_theta_max: f32) -> Vec2 {
    let mut phi = w.y.atan2(w.x);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    let denom = 1.0 - cos_theta_max;
    let ux = if denom > 0.0 {
        (1.0 - w.z) / denom
    } else {
        0.0
    };
    Vec2::new(ux.clamp(0.0, crate::ONE_MINUS_EPSILON), phi * INV_2PI)
}

/// Uniform barycentrics `(b1, b2)` on a triangle (the point is `(1−b1−b2)·p0 + b1·p1 + b2·p2`),
/// by the square-root parameterisation. The area pdf is `1 / area`.
#[inline]
pub fn sample_uniform_triangle(u: Vec2) -> Vec2 {
    let su0 = u.x.sqrt();
    Vec2::new(1.0 - su0, u.y * su0)
}

/// The inverse of [`sample_uniform_triangle`].
pub fn invert_uniform_triangle(b: Vec2) -> Vec2 {
    let su0 = 1.0 - b.x;
    let ux = su0 * su0;
    let uy = if su0 > 0.0 { b.y / su0 } else { 0.0 };
    Vec2::new(ux, uy)
}

/// Tent on `[-radius, radius]` with density `(radius − |x|) / radius²`.
#[inline]
pub fn sample_tent(u: f32, radius: f32) -> f32 {
    if u < 0.5 {
        let v = 2.0 * u;
        radius * ((v.sqrt()) - 1.0)
    } else {
        let v = 2.0 * (1.0 - u);
        radius * (1.0 - v.sqrt())
    }
}

/// Density of [`sample_tent`].
#[inline]
pub fn tent_pdf(x: f32, radius: f32) -> f32 {
    if x.abs() >= radius {
        0.0
    } else {
        (radius - x.abs()) / (radius * radius)
    }
}

/// The power heuristic with exponent 2 (Veach 1997, eq. 9.13) for one sample of strategy `a`:
/// `pdf_a² / (pdf_a² + pdf_b²)`. Infinite `pdf_a` (a delta strategy) gives 1; non-finite results 0.
#[inline]
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    if pdf_a.is_infinite() {
        return 1.0;
    }
    let a2 = pdf_a * pdf_a;
    let b2 = pdf_b * pdf_b;
    let w = a2 / (a2 + b2);
    if w.is_finite() { w } else { 0.0 }
}

/// The power heuristic with sample counts: the share `a² / (a² + b²)` of a strategy whose
/// samples have the count-weighted density `a = N_a·p_a` against one with `b = N_b·p_b`
/// (Veach's β = 2), for densities already multiplied by their sample counts. 0 when `a` is 0, 1 when `b` is, never NaN; computed from `b / a`, so huge
/// densities do not overflow.
#[inline]
pub fn power_share(a: f32, b: f32) -> f32 {
    if a.is_nan() || a <= 0.0 {
        return 0.0;
    }
    let r = b / a;
    let w = 1.0 / (1.0 + r * r);
    if w.is_finite() { w } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The polynomial sine and cosine are within an `f32` step of the exact values on the
    /// quarter they cover, and the quarter-turn reduction keeps that over a whole turn (its
    /// boundaries included), where the library's `(2π·t).sin_cos()` is off by its rounding of
    /// the angle.
    #[test]
    fn sincos_is_within_a_step_of_the_exact_values() {
        let n = 400_001;
        let mut worst = [0.0f64; 4];
        for k in 0..n {
            let f = k as f32 / (n - 1) as f32;
            let x = FRAC_PI_4 * (2.0 * f - 1.0);
            let (s, c) = sincos_quarter(x);
            let x = f64::from(x);
            worst[0] = worst[0].max((f64::from(s) - x.sin()).abs());
            worst[1] = worst[1].max((f64::from(c) - x.cos()).abs());
            let (s, c) = sincos_turns(f);
            let a = core::f64::consts::TAU * f64::from(f);
            worst[2] = worst[2].max((f64::from(s) - a.sin()).abs());
            worst[3] = worst[3].max((f64::from(c) - a.cos()).abs());
        }
        for (i, w) in worst.iter().enumerate() {
            assert!(*w < 1.2e-7, "case {i} off by {w}");
        }
        for (t, s, c) in [
            (0.0, 0.0, 1.0),
            (0.25, 1.0, 0.0),
            (0.5, 0.0, -1.0),
            (0.75, -1.0, 0.0),
        ] {
            let (gs, gc) = sincos_turns(t);
            assert!(
                (gs - s).abs() < 1e-7 && (gc - c).abs() < 1e-7,
                "{t}: {gs} {gc}"
            );
        }
        // The library rounds 2π·t first: off by up to half a step of 2π (2.4·10⁻⁷).
        let t = 0.999_999_9f32;
        let lib = (2.0 * PI * t).sin_cos().0;
        let exact = (core::f64::consts::TAU * f64::from(t)).sin();
        assert!((f64::from(sincos_turns(t).0) - exact).abs() < (f64::from(lib) - exact).abs());
    }
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn concentric_roundtrip(x in 0.0f32..1.0, y in 0.0f32..1.0) {
            let u = Vec2::new(x, y);
            let back = invert_concentric_disk(sample_concentric_disk(u));
            prop_assert!((back - u).abs().max_element() < 1e-4, "{u} -> {back}");
        }

        #[test]
        fn sphere_roundtrip(x in 0.001f32..0.999, y in 0.0f32..0.999) {
            let u = Vec2::new(x, y);
            let w = sample_uniform_sphere(u);
            prop_assert!((w.length() - 1.0).abs() < 1e-5);
            let back = invert_uniform_sphere(w);
            prop_assert!((back - u).abs().max_element() < 1e-3, "{u} -> {back}");
        }

        #[test]
        fn cone_roundtrip(x in 0.0f32..1.0, y in 0.0f32..0.999, c in -0.9f32..0.99) {
            let u = Vec2::new(x, y);
            let w = sample_uniform_cone(u, c);
            prop_assert!(w.z >= c - 1e-5);
            let back = invert_uniform_cone(w, c);
            prop_assert!((back - u).abs().max_element() < 2e-3, "{u} -> {back}");
        }

        #[test]
        fn triangle_roundtrip(x in 0.0f32..1.0, y in 0.0f32..1.0) {
            let u = Vec2::new(x, y);
            let b = sample_uniform_triangle(u);
            prop_assert!(b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 + 1e-6);
            let back = invert_uniform_triangle(b);
            prop_assert!((back - u).abs().max_element() < 1e-4);
        }

        #[test]
        fn cosine_hemisphere_is_upper(x in 0.0f32..1.0, y in 0.0f32..1.0) {
            let w = sample_cosine_hemisphere(Vec2::new(x, y));
            prop_assert!(w.z >= 0.0 && (w.length() - 1.0).abs() < 1e-4);
        }

        #[test]
        fn tent_within_radius(u in 0.0f32..1.0, r in 0.1f32..4.0) {
            let x = sample_tent(u, r);
            prop_assert!(x.abs() <= r);
        }
    }

    #[test]
    fn power_heuristic_edges() {
        assert_eq!(power_heuristic(f32::INFINITY, 3.0), 1.0);
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
        assert!((power_heuristic(1.0, 1.0) - 0.5).abs() < 1e-7);
        assert!((power_heuristic(2.0, 1.0) + power_heuristic(1.0, 2.0) - 1.0).abs() < 1e-6);
    }
}
