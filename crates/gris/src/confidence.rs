//! Confidence weights (`M`) and M-capping.
//!
//! Confidence weights enter only the MIS weights of later resampling steps, so any non-negative
//! choice keeps GRIS unbiased as long as those MIS weights form a partition of unity and the
//! confidences do not depend on the samples being resampled (Lin et al. 2022; `docs/GRIS.md`
//! §5): counts of candidates and caps of them are fine; a confidence computed from a reservoir's
//! own sample ([`confidence_similarity_factor`], a duplication count) is not. Capping bounds how much stale history can dominate
//! the reuse (lag, ghosting, correlation); a lower cap means more noise.
//!
//! Every function here maps NaN and negative inputs to 0 and never returns NaN.

/// Absolute M-cap: `min(confidence, cap)`.
///
/// Typical caps: 20 for ReSTIR DI, 8 for path reuse. A non-positive or NaN `cap` gives 0; a NaN or
/// negative `confidence` gives 0.
#[inline]
pub fn cap_confidence(confidence: f32, cap: f32) -> f32 {
    let c = if confidence > 0.0 { confidence } else { 0.0 };
    let cap = if cap > 0.0 { cap } else { 0.0 };
    if c > cap { cap } else { c }
}

/// Relative (temporal) M-cap: `min(previous, history_limit · current)`.
///
/// `previous` is the confidence of the history reservoir, `current` that of the current frame's
/// canonical reservoir, `history_limit` the allowed ratio `H` (e.g. 20). Applied before the
/// history reservoir is resampled.
#[inline]
pub fn cap_confidence_relative(previous: f32, current: f32, history_limit: f32) -> f32 {
    let current = if current > 0.0 { current } else { 0.0 };
    let limit = if history_limit > 0.0 {
        history_limit
    } else {
        0.0
    };
    let cap = current * limit;
    // `inf * 0` cannot happen with the guards above unless an input is infinite.
    cap_confidence(previous, if cap.is_nan() { 0.0 } else { cap })
}

/// Confidence similarity factor `MF(q0, q1)` used by RTXDI/Falcor with pairwise MIS to grow the
/// output confidence less for dissimilar neighbours:
/// `MF = 1` if `q0 ≤ 0`, else `clamp(min(q1/q0, 1)^8, 0, 1)`.
///
/// `q0` is the neighbour's target at its own sample, `q1` the canonical target at the same
/// (shifted) sample. The output confidence then adds `M_i · min(MF(..at y_i), MF(..at y_c))`
/// instead of `M_i`. This changes only future MIS weights, which stay a partition of unity;
/// but the factor is a function of the selected sample, so in a later step the weight of that
/// sample depends on the sample itself, which the unbiasedness argument excludes: a bias (not measured here),
/// accepted by the renderers that use it.
#[inline]
pub fn confidence_similarity_factor(q0: f32, q1: f32) -> f32 {
    if !(q0 > 0.0) {
        return 1.0;
    }
    let r = q1 / q0;
    let r = if r > 1.0 {
        1.0
    } else if r > 0.0 {
        r
    } else {
        0.0
    };
    let r2 = r * r;
    let r4 = r2 * r2;
    r4 * r4
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absolute_cap() {
        assert_eq!(cap_confidence(30.0, 20.0), 20.0);
        assert_eq!(cap_confidence(3.5, 20.0), 3.5);
        assert_eq!(cap_confidence(f32::NAN, 20.0), 0.0);
        assert_eq!(cap_confidence(-1.0, 20.0), 0.0);
        assert_eq!(cap_confidence(5.0, f32::NAN), 0.0);
        assert_eq!(cap_confidence(f32::INFINITY, 8.0), 8.0);
    }

    #[test]
    fn relative_cap() {
        assert_eq!(cap_confidence_relative(100.0, 2.0, 20.0), 40.0);
        assert_eq!(cap_confidence_relative(10.0, 2.0, 20.0), 10.0);
        assert_eq!(cap_confidence_relative(10.0, 0.0, 20.0), 0.0);
        assert_eq!(cap_confidence_relative(10.0, f32::INFINITY, 0.0), 0.0);
    }

    #[test]
    fn similarity_factor() {
        assert_eq!(confidence_similarity_factor(0.0, 5.0), 1.0);
        assert_eq!(confidence_similarity_factor(1.0, 2.0), 1.0);
        assert_eq!(confidence_similarity_factor(1.0, 0.5), 0.5f32.powi(8));
        assert_eq!(confidence_similarity_factor(1.0, f32::NAN), 0.0);
    }
}
