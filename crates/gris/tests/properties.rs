//! Property tests (proptest, fixed RNG seed) for the invariants listed in docs/GRIS.md §7:
//! MIS partition of unity, defensive bounds, merge order/grouping invariance, confidence
//! bookkeeping, `W ≥ 0` and finite for every finite input, and Jacobian round trips.
// Uses `reconnection_jacobian_from_points`, which needs the `std` feature (square roots).
#![cfg(feature = "std")]

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use restir_gris::jacobian::{
    inverse_jacobian, reconnection_jacobian_from_points, reconnection_jacobian_pss,
    reconnection_jacobian_pss_area, reconnection_jacobian_solid_angle, reject_jacobian,
    solid_angle_to_area,
};
use restir_gris::{
    GrisInput, GrisResampler, PairwiseNeighbor, PairwiseResampler, PairwiseVariant, Reservoir,
    Shifted, StreamingReservoir, mis,
};
use restir_testkit::SplitMix64 as Rng;

fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        rng_seed: RngSeed::Fixed(0x5EED_0001),
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// Non-negative values over 60 decades, with exact zeros.
fn magnitude() -> impl Strategy<Value = f32> {
    prop_oneof![
        1 => Just(0.0f32),
        4 => (-30.0f32..30.0).prop_map(|e| 10f32.powf(e)),
    ]
}

/// Any finite f32 (negative, zero, tiny, huge).
fn finite() -> impl Strategy<Value = f32> {
    prop_oneof![
        1 => Just(0.0f32),
        1 => Just(-1.0f32),
        1 => Just(f32::MAX),
        1 => Just(f32::MIN_POSITIVE / 8.0),
        6 => (-38.0f32..38.0).prop_map(|e| 10f32.powf(e)),
        2 => (-38.0f32..38.0).prop_map(|e| -(10f32.powf(e))),
    ]
}

fn techniques() -> impl Strategy<Value = (Vec<f32>, Vec<f32>)> {
    (0usize..=6).prop_flat_map(|k| {
        (
            prop::collection::vec(magnitude(), k + 1),
            prop::collection::vec(magnitude(), k + 1),
        )
    })
}

fn assert_unit(m: f32) {
    assert!((0.0..=1.0).contains(&m), "weight {m} outside [0, 1]");
}

proptest! {
    #![proptest_config(config(2000))]

    /// Generalized balance / contribution MIS: Σ_i m_i(y) = 1 whenever some c_j·p̂_{←j}(y) > 0,
    /// else all weights are 0.
    #[test]
    fn balance_is_a_partition_of_unity((c, p) in techniques()) {
        let ms: Vec<f32> = (0..c.len()).map(|i| mis::generalized_balance(i, &c, &p)).collect();
        ms.iter().copied().for_each(assert_unit);
        let sum: f64 = ms.iter().map(|&m| f64::from(m)).sum();
        let any = c.iter().zip(&p).any(|(&c, &p)| f64::from(c) * f64::from(p) > 0.0);
        if any {
            prop_assert!((sum - 1.0).abs() < 1e-5, "sum {sum}");
        } else {
            prop_assert_eq!(sum, 0.0);
        }
        // Contribution MIS is the same weight; its finalisation factor is m_s / c_s.
        for s in 0..c.len() {
            prop_assert_eq!(mis::contribution(s, &c, &p), ms[s]);
            let scale = f64::from(mis::contribution_scale(s, &c, &p));
            prop_assert!(scale >= 0.0 && scale.is_finite());
            if c[s] > 0.0 && ms[s] > 1e-30 {
                let m = scale * f64::from(c[s]);
                prop_assert!((m - f64::from(ms[s])).abs() <= 1e-5 * f64::from(ms[s]) + 1e-12);
            }
        }
        // 1/Z: the implied weights c_i/Z over covering techniques sum to one.
        let inv_z = f64::from(mis::one_over_z(&c, &p));
        let covered: f64 = c.iter().zip(&p).filter(|&(_, &p)| p > 0.0).map(|(&c, _)| f64::from(c)).sum();
        if covered > 0.0 && covered < 1e38 {
            prop_assert!((covered * inv_z - 1.0).abs() < 1e-5);
        }
    }

    /// Pairwise, defensive pairwise and confidence-weighted pairwise: Σ m = 1 for any targets and
    /// confidences (zeros included); defensive canonical ≥ 1/(k+1); confidence-weighted canonical
    /// ≥ c_c/(c_c + C_N).
    #[test]
    fn pairwise_weights_are_partitions_of_unity((c, p) in techniques()) {
        let (cc, pc) = (c[0], p[0]);
        let (nc, np) = (&c[1..], &p[1..]);
        let k = nc.len();
        let pair = |i: usize| mis::PairTerms { neighbor_confidence: nc[i], neighbor_target_pdf: np[i], canonical_confidence: cc, canonical_target_pdf: pc };

        let mc = mis::pairwise_canonical(cc, pc, nc, np);
        let mut sum = f64::from(mc);
        assert_unit(mc);
        for i in 0..k {
            let m = mis::pairwise_neighbor(pair(i), k);
            assert_unit(m);
            sum += f64::from(m);
        }
        prop_assert!((sum - 1.0).abs() < 1e-5, "pairwise sum {sum}");

        let mc = mis::defensive_pairwise_canonical(cc, pc, nc, np);
        prop_assert!(f64::from(mc) >= 1.0 / (k as f64 + 1.0) - 1e-6, "defensive canonical {mc}");
        let mut sum = f64::from(mc);
        for i in 0..k {
            let m = mis::defensive_pairwise_neighbor(pair(i), k);
            assert_unit(m);
            sum += f64::from(m);
        }
        prop_assert!((sum - 1.0).abs() < 1e-5, "defensive sum {sum}");

        let cn: f32 = nc.iter().sum();
        let mc = mis::confidence_weighted_pairwise_canonical(cc, pc, nc, np);
        assert_unit(mc);
        let total = f64::from(cc) + f64::from(cn);
        if total > 0.0 {
            prop_assert!(f64::from(mc) >= f64::from(cc) / total - 1e-6);
        }
        let mut sum = f64::from(mc);
        for i in 0..k {
            let m = mis::confidence_weighted_pairwise_neighbor(pair(i), cn);
            assert_unit(m);
            sum += f64::from(m);
        }
        prop_assert!((sum - 1.0).abs() < 1e-5, "confidence-weighted sum {sum}");
    }

    /// The streaming `PairwiseResampler` accumulates exactly the canonical weight of the slice
    /// functions (all three variants), so its implied weights also sum to one.
    #[test]
    fn streaming_pairwise_matches_slice_functions((c, p) in techniques()) {
        let (cc, pc) = (c[0], p[0]);
        let (nc, np) = (&c[1..], &p[1..]);
        let k = nc.len();
        let canonical = Reservoir { sample: Some(0u8), ucw: 1.0, confidence: cc, own_target: pc };
        let cn: f32 = nc.iter().sum();
        for variant in [
            PairwiseVariant::Plain,
            PairwiseVariant::Defensive,
            PairwiseVariant::ConfidenceWeighted { neighbor_confidence_sum: cn },
        ] {
            let mut step = PairwiseResampler::new(variant, k, canonical);
            for i in 0..k {
                let empty = Reservoir { confidence: nc[i], ..Reservoir::empty() };
                step.add_neighbor(PairwiseNeighbor::new(&empty, None, np[i]), 0.5);
            }
            let (expected, normaliser) = match variant {
                PairwiseVariant::Plain if k == 0 => (1.0, 1.0),
                PairwiseVariant::Plain => (f64::from(mis::pairwise_canonical(cc, pc, nc, np)), k as f64),
                PairwiseVariant::Defensive => (f64::from(mis::defensive_pairwise_canonical(cc, pc, nc, np)), k as f64 + 1.0),
                PairwiseVariant::ConfidenceWeighted { .. } => (f64::from(mis::confidence_weighted_pairwise_canonical(cc, pc, nc, np)), 1.0),
            };
            let got = if matches!(variant, PairwiseVariant::Plain) && k == 0 {
                1.0
            } else {
                (step.canonical_weight() / normaliser).min(1.0)
            };
            prop_assert!((got - expected).abs() < 1e-5, "{variant:?}: {got} vs {expected}");
        }
    }

    /// Confidence out = Σ confidence in (before capping), for streams, merges and GRIS steps,
    /// whether candidates are selected, rejected or failed.
    #[test]
    fn confidence_out_is_the_sum_of_confidences_in(
        inputs in prop::collection::vec((0.0f32..50.0, finite(), any::<bool>()), 0..12),
    ) {
        let expected: f32 = inputs.iter().map(|(c, _, _)| c).sum();
        let mut stream = StreamingReservoir::new();
        let mut gris = GrisResampler::new();
        let mut rng = Rng::new(3);
        for (i, &(c, w, fail)) in inputs.iter().enumerate() {
            stream.add_candidate(i, 1.0, w, c, rng.next_f32());
            if fail {
                gris.add_failed(c);
            } else {
                gris.add(GrisInput { sample: i, receiver_target: 1.0, ucw: w, jacobian: 1.0, confidence: c }, 1.0, rng.next_f32());
            }
        }
        let mut half = StreamingReservoir::new();
        half.merge(stream, 0.5);
        let tolerance = 1e-5 * expected.max(1.0);
        prop_assert!((half.confidence() - expected).abs() <= tolerance);
        prop_assert!((half.finalize(1.0).confidence - expected).abs() <= tolerance);
        prop_assert!((gris.finalize().confidence - expected).abs() <= tolerance);
    }

    /// W ≥ 0 and finite (and W = 0 when empty) for arbitrary finite targets, weights, Jacobians,
    /// confidences and MIS weights.
    #[test]
    fn ucw_is_non_negative_and_finite_for_finite_inputs(
        inputs in prop::collection::vec((finite(), finite(), finite(), finite(), finite()), 0..8),
        canonical in (finite(), finite(), finite()),
        scale in finite(),
    ) {
        let mut rng = Rng::new(4);
        let mut stream = StreamingReservoir::new();
        let mut gris = GrisResampler::new();
        for (i, &(t, w, j, c, m)) in inputs.iter().enumerate() {
            stream.add_candidate(i, t, w, c, rng.next_f32());
            gris.add(GrisInput { sample: i, receiver_target: t, ucw: w, jacobian: j, confidence: c }, m, rng.next_f32());
        }
        let (cu, ct, cc) = canonical;
        let canonical = Reservoir { sample: Some(99usize), ucw: cu, confidence: cc, own_target: ct };
        let mut pairs = [
            PairwiseResampler::new(PairwiseVariant::Plain, inputs.len(), canonical),
            PairwiseResampler::new(PairwiseVariant::Defensive, inputs.len(), canonical),
            PairwiseResampler::new(PairwiseVariant::ConfidenceWeighted { neighbor_confidence_sum: scale }, inputs.len(), canonical),
        ];
        for pair in &mut pairs {
            for (i, &(t, w, j, c, m)) in inputs.iter().enumerate() {
                let own = Reservoir { sample: Some(i), ucw: w, confidence: c, own_target: m };
                let shifted = Shifted { sample: i, jacobian: j, destination_target: t };
                pair.add_neighbor(PairwiseNeighbor::new(&own, Some(shifted), scale), rng.next_f32());
            }
        }
        let mut outs = vec![
            stream.finalize_recorded(),
            stream.finalize(scale),
            stream.finalize_scaled(canonical.own_target, scale),
            gris.finalize(),
            gris.finalize_scaled(scale),
        ];
        outs.extend(pairs.into_iter().map(|p| p.finalize(0.5)));
        for r in outs {
            prop_assert!(r.ucw >= 0.0 && r.ucw.is_finite(), "W = {}", r.ucw);
            prop_assert!(r.confidence >= 0.0 && !r.confidence.is_nan());
            if r.sample.is_none() {
                prop_assert_eq!(r.ucw, 0.0);
            }
        }
    }

    /// MIS weights are finite and in [0, 1] for any f32 input, including NaN and infinities.
    #[test]
    fn mis_weights_never_return_nan(
        c in prop::collection::vec(prop_oneof![finite(), Just(f32::NAN), Just(f32::INFINITY)], 1..5),
        p in prop::collection::vec(prop_oneof![finite(), Just(f32::NAN), Just(f32::INFINITY)], 1..5),
    ) {
        let n = c.len().min(p.len());
        let (c, p) = (&c[..n], &p[..n]);
        let k = n - 1;
        let mut ws = vec![
            mis::pairwise_canonical(c[0], p[0], &c[1..], &p[1..]),
            mis::defensive_pairwise_canonical(c[0], p[0], &c[1..], &p[1..]),
            mis::confidence_weighted_pairwise_canonical(c[0], p[0], &c[1..], &p[1..]),
            mis::constant_biased(c[0], c.iter().sum()),
        ];
        for i in 0..n {
            ws.push(mis::generalized_balance(i, c, p));
            ws.push(mis::contribution(i, c, p));
            if i > 0 {
                let pair = mis::PairTerms { neighbor_confidence: c[i], neighbor_target_pdf: p[i], canonical_confidence: c[0], canonical_target_pdf: p[0] };
                ws.push(mis::pairwise_neighbor(pair, k));
                ws.push(mis::defensive_pairwise_neighbor(pair, k));
                ws.push(mis::confidence_weighted_pairwise_neighbor(pair, c[1..].iter().sum()));
            }
        }
        for w in ws {
            assert_unit(w);
        }
        let s = mis::contribution_scale(0, c, p);
        prop_assert!(s >= 0.0 && s.is_finite());
        let z = mis::one_over_z(c, p);
        prop_assert!(z >= 0.0 && z.is_finite());
    }
}

proptest! {
    #![proptest_config(config(5000))]

    /// Forward·inverse reconnection Jacobian = 1 for random geometry (solid angle from points and
    /// from cosines/distances, and the PSS forms); both fail together.
    #[test]
    fn reconnection_forward_times_inverse_is_one(
        x in prop::array::uniform3(-10.0f32..10.0),
        y in prop::array::uniform3(-10.0f32..10.0),
        v in prop::array::uniform3(-10.0f32..10.0),
        n in prop::array::uniform3(-1.0f32..1.0),
        pdfs in prop::array::uniform4(1e-3f32..1e3),
    ) {
        let fwd = reconnection_jacobian_from_points(x, y, v, n);
        let inv = reconnection_jacobian_from_points(y, x, v, n);
        prop_assert!(fwd >= 0.0 && fwd.is_finite() && inv >= 0.0 && inv.is_finite());
        prop_assert_eq!(fwd == 0.0, inv == 0.0, "forward and inverse must fail together");
        if fwd > 0.0 {
            let prod = f64::from(fwd) * f64::from(inv);
            prop_assert!((prod - 1.0).abs() < 1e-4, "J·J⁻¹ = {prod}");
            prop_assert!((f64::from(inverse_jacobian(fwd)) / f64::from(inv) - 1.0).abs() < 1e-4);

            let [py, px, qy, qx] = pdfs;
            let f = reconnection_jacobian_pss(py, px, fwd, qy, qx);
            let b = reconnection_jacobian_pss(px, py, inv, qx, qy);
            if f > 0.0 && b > 0.0 {
                prop_assert!((f64::from(f) * f64::from(b) - 1.0).abs() < 1e-4);
            }
            let f = reconnection_jacobian_pss_area(py, px, qy, qx);
            let b = reconnection_jacobian_pss_area(px, py, qx, qy);
            prop_assert!((f64::from(f) * f64::from(b) - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn solid_angle_jacobian_round_trip_and_conversion(
        cos_y in -1.0f32..1.0, d2_y in 1e-6f32..1e6, cos_x in -1.0f32..1.0, d2_x in 1e-6f32..1e6,
    ) {
        let fwd = reconnection_jacobian_solid_angle(cos_y, d2_y, cos_x, d2_x);
        let inv = reconnection_jacobian_solid_angle(cos_x, d2_x, cos_y, d2_y);
        prop_assert_eq!(fwd == 0.0, inv == 0.0);
        if fwd > 0.0 {
            prop_assert!((f64::from(fwd) * f64::from(inv) - 1.0).abs() < 1e-5);
            // J_sa = G_y / G_x with G = |cos|/d².
            let g = f64::from(solid_angle_to_area(cos_y, d2_y)) / f64::from(solid_angle_to_area(cos_x, d2_x));
            prop_assert!((g / f64::from(fwd) - 1.0).abs() < 1e-5);
        }
    }

    /// Symmetric rejection: J is rejected iff 1/J is (away from the exact boundary).
    #[test]
    fn jacobian_rejection_is_symmetric(e in -6.0f64..6.0, tau in 1.01f32..100.0) {
        let j = 10f64.powf(e);
        let boundary = (j.ln().abs() - f64::from(tau).ln()).abs() < 1e-5;
        if !boundary {
            prop_assert_eq!(reject_jacobian(j as f32, tau), reject_jacobian((1.0 / j) as f32, tau));
        }
    }
}

proptest! {
    // Each case runs a 3000-draw Monte Carlo comparison, so fewer cases.
    #![proptest_config(config(200))]

    /// Any grouping and order of stream merges gives the same `weight_sum` (up to f64 rounding)
    /// and confidence, and the same selection law w_i/Σw (Monte Carlo, 5σ per cell).
    #[test]
    fn merge_order_and_grouping_do_not_matter(
        weights in prop::collection::vec(prop_oneof![1 => Just(0.0f32), 5 => 0.01f32..10.0], 2..7),
        cut in any::<prop::sample::Index>(),
        seed in any::<u64>(),
    ) {
        let cut = cut.index(weights.len() + 1);
        let mut rng = Rng::new(seed);
        let total: f64 = weights.iter().map(|&w| f64::from(w)).sum();
        let draws = 3000usize;
        let mut counts = [vec![0u32; weights.len()], vec![0u32; weights.len()]];
        for _ in 0..draws {
            // (a) one pass, in order.
            let mut one = StreamingReservoir::new();
            for (i, &w) in weights.iter().enumerate() {
                one.add(i, w, rng.next_f32());
            }
            // (b) two sub-streams, the second streamed in reverse, merged as (second ⊕ first).
            let mut first = StreamingReservoir::new();
            let mut second = StreamingReservoir::new();
            for (i, &w) in weights.iter().enumerate().take(cut) {
                first.add(i, w, rng.next_f32());
            }
            for (i, &w) in weights.iter().enumerate().skip(cut).rev() {
                second.add(i, w, rng.next_f32());
            }
            second.merge(first, rng.next_f32());
            prop_assert!((one.weight_sum() - second.weight_sum()).abs() <= 1e-12 * total);
            prop_assert_eq!(one.confidence(), second.confidence());
            for (c, s) in counts.iter_mut().zip([&one, &second]) {
                match s.selected() {
                    Some(&i) => c[i] += 1,
                    None => prop_assert_eq!(total, 0.0),
                }
            }
        }
        if total > 0.0 {
            for (i, &w) in weights.iter().enumerate() {
                let p = f64::from(w) / total;
                let sd = (p * (1.0 - p) / draws as f64).sqrt();
                for c in &counts {
                    let f = f64::from(c[i]) / draws as f64;
                    prop_assert!((f - p).abs() <= 5.0 * sd + 1e-12, "cell {i}: {f} vs {p}");
                }
            }
        }
    }
}
