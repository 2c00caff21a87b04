//! Standard shift-map Jacobians (derivations and a summary table: `docs/GRIS.md` §6).
//!
//! Notation for a reconnection at vertex `x_k` (geometric normal `n_k`): the base path arrives
//! from `x_{k−1}`, the shifted path from `y_{k−1}`;
//! `d_x = |x_k − x_{k−1}|`, `d_y = |x_k − y_{k−1}|`, `cos θ_x = |n_k·(x_{k−1} − x_k)|/d_x`,
//! `cos θ_y = |n_k·(y_{k−1} − x_k)|/d_y`.
//!
//! Every function returns a finite positive Jacobian, or **0 meaning "the shift fails"**. A
//! Jacobian is rejected when an input is NaN, negative or zero (a grazing angle, a zero
//! distance), or when the result lies outside `[1/JACOBIAN_LIMIT, JACOBIAN_LIMIT]`. That band is
//! symmetric under `J ↔ 1/J`, so the forward shift is rejected iff the inverse one is, which
//! keeps the shift's domain consistent (unbiased, given a canonical technique) instead of
//! clamping (biased). The computation is done in `f64`; only `+ − × /` are used, so everything
//! works without `std` except `reconnection_jacobian_from_points` and `geometry_term`, which need
//! a square root (feature `std`).

/// Results outside `[1/JACOBIAN_LIMIT, JACOBIAN_LIMIT]` are rejected (returned as 0).
pub const JACOBIAN_LIMIT: f32 = 1e30;

/// Jacobian of the identity shift (a domain's own sample), in any measure.
pub const IDENTITY_JACOBIAN: f32 = 1.0;

/// Jacobian of random replay (random-number reuse) in primary sample space: replaying the same
/// random numbers is the identity on primary samples.
pub const RANDOM_REPLAY_JACOBIAN: f32 = 1.0;

/// Jacobian of reconnection in the **area-product (path-space vertex) measure**: the vertex `x_k`
/// is copied, so the map on vertex areas is the identity. The `cos/d²` factors then belong in the
/// geometry terms of the targets. Also the Jacobian of an environment-direction copy in solid
/// angle.
pub const RECONNECTION_JACOBIAN_AREA: f32 = 1.0;

#[inline]
fn positive(x: f32) -> Option<f64> {
    let x = f64::from(x);
    (x > 0.0 && x.is_finite()).then_some(x)
}

/// |x| without `std`.
#[inline]
fn abs(x: f32) -> f32 {
    if x < 0.0 { -x } else { x }
}

/// Accepts `j` iff it is finite and in `[1/JACOBIAN_LIMIT, JACOBIAN_LIMIT]`; 0 otherwise.
#[inline]
fn finish(j: f64) -> f32 {
    let limit = f64::from(JACOBIAN_LIMIT);
    if j > 0.0 && j <= limit && j * limit >= 1.0 {
        j as f32
    } else {
        0.0
    }
}

/// Reconnection Jacobian in **solid angle** at the predecessor vertex:
///
/// ```text
/// |∂ω_y/∂ω_x| = (cos θ_y / cos θ_x) · (d_x² / d_y²)
/// ```
///
/// mapping solid angle at `x_{k−1}` to solid angle at `y_{k−1}` (Lin et al. 2022, reconnection
/// shift; `docs/GRIS.md` §6.2). Cosines are taken in absolute value. The inverse shift's
/// Jacobian is obtained by swapping the roles (`= 1/J`). Returns 0 (shift fails) for a grazing
/// angle, a zero distance, or a non-finite result.
#[inline]
pub fn reconnection_jacobian_solid_angle(
    cos_y: f32,
    dist2_y: f32,
    cos_x: f32,
    dist2_x: f32,
) -> f32 {
    let (Some(cy), Some(dy), Some(cx), Some(dx)) = (
        positive(abs(cos_y)),
        positive(dist2_y),
        positive(abs(cos_x)),
        positive(dist2_x),
    ) else {
        return 0.0;
    };
    finish((cy * dx) / (cx * dy))
}

/// Solid-angle to area conversion factor `G = |cos θ| / d²` at a vertex: `pdf_area = pdf_sa · G`
/// and `pdf_sa = pdf_area / G`. Returns 0 for a grazing angle or a zero/non-finite distance.
#[inline]
pub fn solid_angle_to_area(cos: f32, dist2: f32) -> f32 {
    let (Some(c), Some(d)) = (positive(abs(cos)), positive(dist2)) else {
        return 0.0;
    };
    let g = (c / d) as f32;
    if g > 0.0 && g.is_finite() { g } else { 0.0 }
}

/// Reconnection Jacobian in **primary sample space**, from solid-angle pdfs:
///
/// ```text
/// J_PSS = (pdf_sa_y / pdf_sa_x) · J_sa · (continuation_pdf_y / continuation_pdf_x)
/// ```
///
/// * `pdf_sa_y`, `pdf_sa_x`: pdf (solid angle, of the lobe that was sampled) of the direction
///   towards `x_k` at `y_{k−1}` (shifted) and `x_{k−1}` (base);
/// * `jacobian_solid_angle`: [`reconnection_jacobian_solid_angle`] of the same reconnection;
/// * `continuation_pdf_y/x`: pdf of `x_k`'s outgoing direction given the new / old incoming
///   direction when `x_k` continues by BSDF sampling; pass `1, 1` when the path ends at `x_k`
///   (NEE there, or `x_k` is the emitter).
///
/// (`docs/GRIS.md` §6.4.) Returns 0 if any factor is invalid.
#[inline]
pub fn reconnection_jacobian_pss(
    pdf_sa_y: f32,
    pdf_sa_x: f32,
    jacobian_solid_angle: f32,
    continuation_pdf_y: f32,
    continuation_pdf_x: f32,
) -> f32 {
    let (Some(py), Some(px), Some(j), Some(qy), Some(qx)) = (
        positive(pdf_sa_y),
        positive(pdf_sa_x),
        positive(jacobian_solid_angle),
        positive(continuation_pdf_y),
        positive(continuation_pdf_x),
    ) else {
        return 0.0;
    };
    finish((py / px) * j * (qy / qx))
}

/// Reconnection Jacobian in **primary sample space**, from area-measure pdfs of the
/// reconnection vertex:
///
/// ```text
/// J_PSS = (pdf_area_y / pdf_area_x) · (continuation_pdf_y / continuation_pdf_x)
/// ```
///
/// where `pdf_area_· = pdf_sa_· · cos θ_· / d_·²` is the density with which the predecessor
/// generated `x_k`, per unit area at `x_k` (equal to [`reconnection_jacobian_pss`] with the
/// geometry folded into the pdfs; also the PSS Jacobian of a light-sample or environment-direction
/// copy, with `1, 1` continuation pdfs). Returns 0 if any factor is invalid.
#[inline]
pub fn reconnection_jacobian_pss_area(
    pdf_area_y: f32,
    pdf_area_x: f32,
    continuation_pdf_y: f32,
    continuation_pdf_x: f32,
) -> f32 {
    let (Some(py), Some(px), Some(qy), Some(qx)) = (
        positive(pdf_area_y),
        positive(pdf_area_x),
        positive(continuation_pdf_y),
        positive(continuation_pdf_x),
    ) else {
        return 0.0;
    };
    finish((py / px) * (qy / qx))
}

/// Reconnection Jacobian in **solid angle** from the two geometry terms `G = |cos θ| / d²` of the
/// reconnection vertex seen from the shifted (`geometry_y`) and base (`geometry_x`) predecessors
/// (see [`solid_angle_to_area`]): `J = G_y / G_x`, equal to
/// [`reconnection_jacobian_solid_angle`]. A shift that caches its base path's `G_x` in the sample
/// and stores `G_y` in the shifted sample gets `J·J⁻¹ = 1` without recomputing the base path,
/// and exactly `J = 1` for the identity. Returns 0 (shift fails) if either term is invalid.
#[inline]
pub fn reconnection_jacobian_from_geometry(geometry_y: f32, geometry_x: f32) -> f32 {
    let (Some(gy), Some(gx)) = (positive(geometry_y), positive(geometry_x)) else {
        return 0.0;
    };
    finish(gy / gx)
}

/// Jacobian of the inverse shift at the shifted point: `1 / J`, or 0 if `J` is invalid.
#[inline]
pub fn inverse_jacobian(jacobian: f32) -> f32 {
    match positive(jacobian) {
        Some(j) => finish(1.0 / j),
        None => 0.0,
    }
}

/// **Symmetric Jacobian rejection**: `true` (reject the shift) if `max(J, 1/J) > max_ratio`, or
/// if `J` is not finite and positive.
///
/// Because the test is symmetric under `J ↔ 1/J` and the inverse shift's Jacobian is `1/J`,
/// the forward and inverse shifts are rejected together, so the restriction keeps GRIS unbiased
/// given a canonical technique (`docs/GRIS.md` §6.6). Clamping `J` instead is
/// biased. `max_ratio ≤ 1` rejects everything except `J = 1`.
#[inline]
pub fn reject_jacobian(jacobian: f32, max_ratio: f32) -> bool {
    let Some(j) = positive(jacobian) else {
        return true;
    };
    let r = f64::from(if max_ratio > 1.0 { max_ratio } else { 1.0 });
    j > r || j * r < 1.0
}

/// Reconnection Jacobian in solid angle computed from points (**requires the `std` feature**
/// for square roots): base predecessor `prev_x` (= `x_{k−1}`), shifted predecessor `prev_y`
/// (= `y_{k−1}`), reconnection vertex `vertex` (= `x_k`) and its geometric normal `normal`
/// (any length). Same conventions and failure rules as [`reconnection_jacobian_solid_angle`].
///
/// Computed entirely in `f64` (squared distances of `f32` points cannot overflow there), so it
/// is scale invariant: scaling all three points about any origin by any factor that keeps them
/// finite `f32` values leaves `J` unchanged up to rounding (tested from 10⁻¹⁵ to 10³⁰ in
/// `tests/stress.rs`).
#[cfg(feature = "std")]
pub fn reconnection_jacobian_from_points(
    prev_x: [f32; 3],
    prev_y: [f32; 3],
    vertex: [f32; 3],
    normal: [f32; 3],
) -> f32 {
    let (cos_x, dist2_x) = cos_and_dist2(prev_x, vertex, normal);
    let (cos_y, dist2_y) = cos_and_dist2(prev_y, vertex, normal);
    let (cx, cy) = (cos_x.abs(), cos_y.abs());
    let usable = |d2: f64| d2 > 0.0 && d2.is_finite();
    if !(cx > 0.0 && cy > 0.0 && usable(dist2_x) && usable(dist2_y)) {
        return 0.0;
    }
    finish((cy * dist2_x) / (cx * dist2_y))
}

/// The geometry term `G = |cos θ| / d²` of `vertex` (geometric normal `normal`, any length) seen
/// from `prev` (**requires the `std` feature**), for [`reconnection_jacobian_from_geometry`].
/// Computed in `f64`; 0 for a grazing angle or a zero distance.
#[cfg(feature = "std")]
pub fn geometry_term(prev: [f32; 3], vertex: [f32; 3], normal: [f32; 3]) -> f32 {
    let (cos, d2) = cos_and_dist2(prev, vertex, normal);
    let g = (cos.abs() / d2) as f32;
    if g > 0.0 && g.is_finite() { g } else { 0.0 }
}

/// The signed cosine between `normal` (any length) and the direction from `vertex` to `prev`,
/// and their squared distance, in `f64`.
#[cfg(feature = "std")]
fn cos_and_dist2(prev: [f32; 3], vertex: [f32; 3], normal: [f32; 3]) -> (f64, f64) {
    let v = [
        f64::from(prev[0]) - f64::from(vertex[0]),
        f64::from(prev[1]) - f64::from(vertex[1]),
        f64::from(prev[2]) - f64::from(vertex[2]),
    ];
    let n = normal.map(f64::from);
    let d2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    let nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    (
        (n[0] * v[0] + n[1] * v[1] + n[2] * v[2]) / (d2 * nn).sqrt(),
        d2,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solid_angle_formula_and_inverse() {
        let j = reconnection_jacobian_solid_angle(0.5, 4.0, 0.25, 1.0);
        assert_eq!(j, 0.5);
        let inv = reconnection_jacobian_solid_angle(0.25, 1.0, 0.5, 4.0);
        assert_eq!(inv, 2.0);
        assert_eq!(inverse_jacobian(j), inv);
        // Cosines are used in absolute value.
        assert_eq!(reconnection_jacobian_solid_angle(-0.5, 4.0, 0.25, 1.0), 0.5);
    }

    #[test]
    fn degenerate_geometry_fails_cleanly() {
        for args in [
            (0.0, 1.0, 1.0, 1.0),
            (1.0, 0.0, 1.0, 1.0),
            (1.0, 1.0, 0.0, 1.0),
            (1.0, 1.0, 1.0, 0.0),
            (f32::NAN, 1.0, 1.0, 1.0),
            (1.0, f32::INFINITY, 1.0, 1.0),
            (1.0, 1e-38, 1e-38, 1e38),
            (1e-45, 1.0, 1.0, 1.0),
        ] {
            let j = reconnection_jacobian_solid_angle(args.0, args.1, args.2, args.3);
            assert_eq!(j, 0.0, "{args:?}");
        }
        assert_eq!(inverse_jacobian(0.0), 0.0);
        assert_eq!(solid_angle_to_area(0.0, 1.0), 0.0);
        assert_eq!(solid_angle_to_area(1.0, 0.0), 0.0);
    }

    #[test]
    fn pss_forms_agree() {
        let (cos_y, d2_y, cos_x, d2_x) = (0.8, 2.0, 0.3, 5.0);
        let (pdf_sa_y, pdf_sa_x) = (0.7, 1.9);
        let j_sa = reconnection_jacobian_solid_angle(cos_y, d2_y, cos_x, d2_x);
        let a = reconnection_jacobian_pss(pdf_sa_y, pdf_sa_x, j_sa, 0.4, 0.5);
        let b = reconnection_jacobian_pss_area(
            pdf_sa_y * solid_angle_to_area(cos_y, d2_y),
            pdf_sa_x * solid_angle_to_area(cos_x, d2_x),
            0.4,
            0.5,
        );
        assert!((a - b).abs() <= 1e-5 * a);
    }

    #[test]
    fn rejection_is_symmetric() {
        for j in [0.05f32, 0.09, 0.1, 0.5, 1.0, 2.0, 9.0, 10.0, 11.0, 20.0] {
            assert_eq!(
                reject_jacobian(j, 10.0),
                reject_jacobian(1.0 / j, 10.0),
                "{j}"
            );
        }
        assert!(reject_jacobian(11.0, 10.0));
        assert!(!reject_jacobian(9.0, 10.0));
        assert!(reject_jacobian(f32::NAN, 10.0));
        assert!(reject_jacobian(0.0, 10.0));
    }

    #[test]
    fn geometry_form_agrees() {
        let (px, py, v, n) = (
            [0.1, 0.9, 0.3],
            [-0.7, 1.4, 0.2],
            [0.2, 0.0, -0.4],
            [0.1, 1.0, 0.2],
        );
        let a = reconnection_jacobian_from_points(px, py, v, n);
        let b =
            reconnection_jacobian_from_geometry(geometry_term(py, v, n), geometry_term(px, v, n));
        assert!((a - b).abs() <= 1e-6 * a, "{a} {b}");
        let g = geometry_term(px, v, n);
        assert_eq!(reconnection_jacobian_from_geometry(g, g), 1.0);
        assert_eq!(reconnection_jacobian_from_geometry(0.0, g), 0.0);
        assert_eq!(reconnection_jacobian_from_geometry(g, f32::NAN), 0.0);
    }

    #[test]
    fn constants() {
        assert_eq!(RANDOM_REPLAY_JACOBIAN, 1.0);
        assert_eq!(IDENTITY_JACOBIAN, 1.0);
        assert_eq!(RECONNECTION_JACOBIAN_AREA, 1.0);
    }
}
