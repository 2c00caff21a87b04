//! Numerical stress: weights spanning 1e-30..1e30, long streams, denormals, grazing angles and
//! near-zero distances. Nothing may return NaN or infinity, and nothing may be silently biased.

mod support;

use restir_gris::jacobian::{inverse_jacobian, reconnection_jacobian_solid_angle};
use restir_gris::{
    GrisInput, GrisResampler, MisScheme, Reservoir, StreamingReservoir, mis, resample,
};
use restir_testkit::{RunningStats as Stats, SplitMix64 as Rng, trials};
use support::{PowerShift, TOY_INTEGRAL, toy_domains, toy_integrand};

/// Kahan-compensated reference sum.
fn kahan(values: impl Iterator<Item = f64>) -> f64 {
    let (mut sum, mut c) = (0.0f64, 0.0f64);
    for v in values {
        let y = v - c;
        let t = sum + y;
        c = (t - sum) - y;
        sum = t;
    }
    sum
}

/// 10⁶ candidates: `weight_sum` (f64) matches a compensated sum to 1e-12, confidence is exact,
/// and the selection is still valid.
#[test]
fn long_stream_sum_stays_accurate() {
    let n = 1_000_000usize;
    let mut rng = Rng::new(20);
    let weights: Vec<f32> = (0..n).map(|_| rng.next_f32() * 3.0 + 1e-3).collect();
    let mut s = StreamingReservoir::new();
    for (i, &w) in weights.iter().enumerate() {
        s.add(i, w, rng.next_f32());
    }
    let reference = kahan(weights.iter().map(|&w| f64::from(w)));
    let rel = (s.weight_sum() - reference).abs() / reference;
    assert!(rel < 1e-12, "relative error {rel}");
    assert_eq!(s.confidence(), n as f32);
    let r = s.finalize(1.0);
    assert!((f64::from(r.ucw) / reference - 1.0).abs() < 1e-6);

    // A huge weight first, then many small ones: the small ones still count.
    let mut s = StreamingReservoir::new();
    s.add(0usize, 1e30, 0.5);
    for i in 1..n {
        s.add(i, 1e20, rng.next_f32());
    }
    let expected = f64::from(1e30f32) + (n as f64 - 1.0) * f64::from(1e20f32);
    // Worst-case rounding of naive f64 accumulation is n·ε ≈ 1.1e-10; f32 accumulation would
    // have lost every small weight (1e20 < ulp(1e30) in f32).
    let rel = (s.weight_sum() / expected - 1.0).abs();
    assert!(rel < n as f64 * f64::EPSILON, "relative error {rel}");
}

/// Late candidates in a long stream are selected with the right probability: with 10⁵ equal
/// weights, the chance that the selection lies in the last 10 % is 0.1 (checked over 400 streams
/// at 4σ).
#[test]
fn long_stream_keeps_selecting_late_candidates() {
    let n = 100_000usize;
    let runs = trials(400).max(100);
    let mut rng = Rng::new(21);
    let mut late = 0usize;
    for _ in 0..runs {
        let mut s = StreamingReservoir::new();
        for i in 0..n {
            s.add(i, 1.0, rng.next_f32());
        }
        if *s.selected().unwrap() >= n - n / 10 {
            late += 1;
        }
    }
    let p = 0.1;
    let sd = (p * (1.0 - p) / runs as f64).sqrt();
    let f = late as f64 / runs as f64;
    assert!((f - p).abs() < 4.0 * sd, "late fraction {f}");
}

/// RIS with targets scaled by 1e30 and 1e-30 (so weights and W span 1e-30..1e30) is unbiased
/// and finite: scaling the target must not change the estimate.
#[test]
fn extreme_target_scales_are_unbiased() {
    for (scale, seed) in [(1e30f64, 22u64), (1e-30, 23), (1.0, 24)] {
        let mut rng = Rng::new(seed);
        let mut stats = Stats::default();
        for _ in 0..trials(80_000) {
            let mut s = StreamingReservoir::new();
            let n = 4;
            for _ in 0..n {
                let x = rng.next_f64();
                let t = ((0.25 + x) * scale) as f32;
                s.add_candidate(x, t, t / n as f32, 1.0, rng.next_f32());
            }
            let r = s.finalize_recorded();
            assert!(r.ucw > 0.0 && r.ucw.is_finite());
            stats.push(toy_integrand(r.sample.unwrap()) * f64::from(r.ucw));
        }
        stats.assert_unbiased(TOY_INTEGRAL, &format!("RIS with target scale {scale:e}"));
    }
}

/// Weights from 1e-30 to 1e30 in one stream: the sum is exact in f64 and the huge weight wins
/// with the right probability.
#[test]
fn weights_spanning_sixty_decades() {
    let mut rng = Rng::new(25);
    let weights: Vec<f32> = (-30..=30).map(|e| 10f32.powi(e)).collect();
    let reference = kahan(weights.iter().map(|&w| f64::from(w)));
    let mut wins = 0;
    let runs = 2000;
    for _ in 0..runs {
        let mut s = StreamingReservoir::new();
        for (i, &w) in weights.iter().enumerate() {
            s.add(i, w, rng.next_f32());
        }
        assert!((s.weight_sum() / reference - 1.0).abs() < 1e-12);
        let r = s.finalize(1e-30);
        // W = Σw / 1e-30 ≈ 1.1e60 does not fit in f32: the reservoir must come out empty,
        // never infinite.
        assert!(r.ucw == 0.0 && r.sample.is_none());
        let mut s2 = StreamingReservoir::new();
        for (i, &w) in weights.iter().enumerate() {
            s2.add(i, w, rng.next_f32());
        }
        let r = s2.finalize(1e30);
        assert!(r.ucw.is_finite() && r.ucw > 0.0);
        if r.sample == Some(weights.len() - 1) {
            wins += 1;
        }
    }
    // P(select 1e30) = 1e30 / Σ ≈ 0.9: 2000 runs, 4σ ≈ 0.027.
    let p = f64::from(weights[weights.len() - 1]) / reference;
    let f = f64::from(wins) / f64::from(runs);
    assert!((f - p).abs() < 0.03, "{f} vs {p}");
}

/// Denormal weights, targets and confidences are handled like any other positive value.
#[test]
fn denormals() {
    let tiny = f32::from_bits(1); // smallest positive denormal, 1.4e-45
    let small = 1e-40f32;
    assert!(small < f32::MIN_POSITIVE && small > 0.0);
    let mut s = StreamingReservoir::new();
    assert!(s.add_candidate(1u8, small, small, tiny, 0.9));
    assert!(!s.add_candidate(2u8, small, tiny, tiny, 0.9));
    assert!(s.weight_sum() > f64::from(small));
    let r = s.finalize_recorded();
    assert!(r.ucw.is_finite() && r.ucw > 0.0 && (r.ucw - 1.0).abs() < 1e-3);
    assert!(r.confidence > 0.0);

    let c = [tiny, small, 1.0];
    let p = [small, tiny, tiny];
    let sum: f32 = (0..3).map(|i| mis::generalized_balance(i, &c, &p)).sum();
    assert!((sum - 1.0).abs() < 1e-6);
    let m = mis::pairwise_canonical(tiny, tiny, &[tiny], &[tiny]);
    assert!(m.is_finite() && (0.0..=1.0).contains(&m));
}

/// Grazing angles and near-zero distances never give NaN/Inf Jacobians, forward and inverse are
/// rejected together, and a GRIS step fed with such shifts stays finite.
#[test]
fn grazing_angles_and_tiny_distances() {
    let values: Vec<f32> = [
        0.0,
        f32::from_bits(1),
        1e-40,
        1e-30,
        1e-20,
        1e-10,
        1e-5,
        0.01,
        0.5,
        1.0,
        1e5,
        1e10,
        1e20,
        1e30,
        f32::MAX,
    ]
    .to_vec();
    let mut resampler = GrisResampler::new();
    let mut rng = Rng::new(26);
    for &cy in &values[..10] {
        for &dy in &values {
            for &cx in &values[..10] {
                for &dx in &values {
                    let fwd = reconnection_jacobian_solid_angle(cy, dy, cx, dx);
                    let inv = reconnection_jacobian_solid_angle(cx, dx, cy, dy);
                    assert!(fwd >= 0.0 && fwd.is_finite());
                    assert!(inv >= 0.0 && inv.is_finite());
                    // Both accepted or both rejected (the band is symmetric under J ↔ 1/J); allow
                    // a disagreement only exactly at the band edge.
                    if (fwd == 0.0) != (inv == 0.0) {
                        let j = fwd.max(inv);
                        assert!(
                            !(1e-29..=1e29).contains(&j),
                            "asymmetric rejection at J = {j}"
                        );
                    }
                    if fwd > 0.0 && inv > 0.0 {
                        let prod = f64::from(fwd) * f64::from(inv);
                        assert!((prod - 1.0).abs() < 1e-6);
                        assert!(inverse_jacobian(fwd) > 0.0);
                    }
                    resampler.add(
                        GrisInput {
                            sample: (cy, dy, cx, dx),
                            receiver_target: dy,
                            ucw: dx,
                            jacobian: fwd,
                            confidence: 1.0,
                        },
                        0.5,
                        rng.next_f32(),
                    );
                }
            }
        }
    }
    let r = resampler.finalize();
    assert!(r.ucw.is_finite() && r.ucw >= 0.0);
}

/// The GRIS driver stays finite and unbiased when the canonical's confidence is tiny and a
/// neighbour's is huge (MIS weights near 0 and 1), for every unbiased scheme.
#[test]
fn gris_with_extreme_confidences_is_finite_and_unbiased() {
    let (mut canonical, mut neighbors) = toy_domains();
    canonical.confidence = 1e-20;
    neighbors[0].confidence = 1e20;
    neighbors[2].confidence = 1e-30;
    for (i, scheme) in MisScheme::ALL.into_iter().enumerate() {
        if !scheme.is_unbiased() {
            continue;
        }
        let mut rng = Rng::new(500 + i as u64);
        let mut stats = Stats::default();
        for _ in 0..trials(80_000) {
            let rc = canonical.sample(&mut rng);
            let rn: Vec<Reservoir<f64>> = neighbors.iter().map(|d| d.sample(&mut rng)).collect();
            let list: Vec<_> = neighbors.iter().zip(&rn).collect();
            let out = resample(&PowerShift, scheme, &canonical, &rc, &list, || {
                rng.next_f32()
            });
            assert!(out.ucw.is_finite() && out.ucw >= 0.0);
            assert!(out.confidence.is_finite());
            stats.push(
                out.sample
                    .map_or(0.0, |y| toy_integrand(y) * f64::from(out.ucw)),
            );
        }
        stats.assert_unbiased(
            TOY_INTEGRAL,
            &format!("{scheme:?} with extreme confidences"),
        );
    }
}
