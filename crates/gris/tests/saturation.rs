//! Finite in, finite out: confidences saturate at `f32::MAX` instead of overflowing
//! and count unit increments past `2^24`; finalisation, source samples and whole GRIS steps never
//! return an infinite confidence, weight or target from finite inputs; `1/Z` saturates instead of
//! dropping to 0; the reconnection Jacobian from points is scale invariant.

mod support;

use restir_gris::jacobian::reconnection_jacobian_from_points;
use restir_gris::{
    GrisInput, GrisResampler, MisScheme, Reservoir, StreamingReservoir, mis, resample,
};
use support::{PowerShift, toy_domains};

fn assert_finite<S>(r: &Reservoir<S>, what: &str) {
    assert!(
        r.ucw.is_finite() && r.ucw >= 0.0,
        "{what}: ucw {} not finite",
        r.ucw
    );
    assert!(
        r.confidence.is_finite() && r.confidence >= 0.0,
        "{what}: confidence {}",
        r.confidence
    );
    assert!(
        r.own_target.is_finite() && r.own_target >= 0.0,
        "{what}: target {}",
        r.own_target
    );
}

#[test]
fn two_huge_confidence_increments_saturate() {
    let mut s = StreamingReservoir::new();
    s.add_candidate(0u8, 1.0, 1.0, f32::MAX, 0.5);
    s.add_candidate(1u8, 1.0, 1.0, f32::MAX, 0.5);
    assert_eq!(s.confidence(), f32::MAX);
    s.add_confidence(f32::MAX);
    s.add_confidence(f32::INFINITY); // an infinite increment saturates too
    assert_eq!(s.confidence(), f32::MAX);
    let r = s.finalize_recorded();
    assert_eq!(r.confidence, f32::MAX);
    assert_finite(&r, "stream");

    let mut merged = StreamingReservoir::new();
    merged.add_candidate(2u8, 1.0, 1.0, f32::MAX, 0.5);
    merged.merge(s, 0.5);
    assert_eq!(merged.confidence(), f32::MAX);

    let mut g = GrisResampler::new();
    let huge = Reservoir {
        sample: Some(0u8),
        ucw: 1.0,
        confidence: f32::MAX,
        own_target: 1.0,
    };
    g.add(GrisInput::canonical(huge).unwrap(), 1.0, 0.5);
    g.add_failed(f32::MAX);
    assert_eq!(g.confidence(), f32::MAX);
    assert_finite(&g.finalize(), "GrisResampler");
}

/// `2^24 + 2` unit increments are counted exactly (an `f32` sum stops at `2^24`).
#[test]
fn unit_increments_count_past_2_pow_24() {
    let n = (1u32 << 24) + 2;
    let mut s = StreamingReservoir::new();
    for i in 0..n {
        s.add(i, 1.0, 0.5);
    }
    assert_eq!(s.confidence(), n as f32);
    assert_eq!(s.confidence() as u32, n);
    assert_eq!(s.finalize(1.0).confidence as u32, n);
}

#[test]
fn finalize_never_returns_infinity_from_finite_inputs() {
    let extremes = [f32::MIN_POSITIVE, 1e-45, 1e-30, 1.0, 1e30, f32::MAX];
    for &w in &extremes {
        for &t in &extremes {
            for &scale in &[0.0, 1e-30, 1.0, 1e30, f32::MAX] {
                let mut s = StreamingReservoir::new();
                s.add_candidate(0u8, t, w, f32::MAX, 0.5);
                s.add_candidate(1u8, t, w, f32::MAX, 0.25);
                let what = format!("w {w:e} target {t:e} scale {scale:e}");
                assert_finite(&s.finalize_scaled(t, scale), &what);
                assert_finite(&s.finalize_recorded(), &what);
            }
        }
    }
}

#[test]
fn source_samples_are_finite_or_empty() {
    for &pdf in &[1e-45f32, 1e-39, f32::MIN_POSITIVE, 1e-30, 1.0, f32::MAX] {
        for &t in &[0.0f32, 1e-45, 1.0, f32::MAX, f32::INFINITY, f32::NAN, -1.0] {
            let r = Reservoir::from_source_sample(0u8, pdf, t);
            assert_finite(&r, &format!("pdf {pdf:e} target {t:e}"));
            assert_eq!(r.confidence, 1.0);
        }
    }
    // An overflowing 1/pdf and an infinite target are rejected, not stored.
    assert!(Reservoir::from_source_sample(0u8, 1e-45, 1.0).is_empty());
    assert!(Reservoir::from_source_sample(0u8, 1.0, f32::INFINITY).is_empty());
    assert_eq!(
        Reservoir::from_source_sample(0u8, 1.0, f32::MAX).own_target,
        f32::MAX
    );
}

#[test]
fn resample_never_returns_infinity_from_finite_inputs() {
    let (c, rest) = toy_domains();
    let c = &c;
    for &confidence in &[1.0f32, 1e30, f32::MAX] {
        for &ucw in &[1e-30f32, 1.0, 1e30, f32::MAX] {
            let r = |x: f64| Reservoir {
                sample: Some(x),
                ucw,
                confidence,
                own_target: f32::MAX,
            };
            let (rc, rn) = (r(0.3), r(0.6));
            let neighbors: Vec<_> = rest.iter().map(|d| (d, &rn)).collect();
            for scheme in MisScheme::ALL {
                let mut u = 0.1f32;
                let out = resample(&PowerShift, scheme, c, &rc, &neighbors, || {
                    u = (u + 0.37) % 1.0;
                    u
                });
                assert_finite(&out, &format!("{scheme:?} c {confidence:e} W {ucw:e}"));
            }
        }
    }
}

#[test]
fn one_over_z_saturates_instead_of_vanishing() {
    let z = mis::one_over_z(&[1e-45, 1e-45], &[1.0, 1.0]);
    assert_eq!(z, f32::MAX);
    assert_eq!(mis::one_over_z(&[0.0], &[1.0]), 0.0);
    assert_eq!(mis::one_over_z(&[2.0, 2.0], &[1.0, 0.0]), 0.5);
    let s = mis::contribution_scale(0, &[1e-45], &[1e-10]);
    assert_eq!(s, f32::MAX);
}

/// Scaling the whole configuration by any factor that keeps the points finite `f32` values
/// leaves the Jacobian unchanged (it was 0 at scale 1e20 when `d²` was rounded to `f32`).
#[test]
fn reconnection_jacobian_from_points_is_scale_invariant() {
    let (px, py, v, n) = (
        [0.1f32, 0.9, 0.3],
        [-0.7f32, 1.4, 0.2],
        [0.2f32, 0.0, -0.4],
        [0.1f32, 1.0, 0.2],
    );
    let reference = f64::from(reconnection_jacobian_from_points(px, py, v, n));
    assert!(reference > 0.0);
    for e in -15..=30 {
        let s = 10f32.powi(e);
        let scaled = |p: [f32; 3]| p.map(|c| c * s);
        let j = f64::from(reconnection_jacobian_from_points(
            scaled(px),
            scaled(py),
            scaled(v),
            n,
        ));
        assert!(
            (j - reference).abs() <= 1e-5 * reference,
            "scale 1e{e}: J = {j} vs {reference}"
        );
    }
}
