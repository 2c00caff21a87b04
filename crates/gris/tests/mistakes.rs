//! The crate documentation's "common mistakes", one test each, showing that each is caught:
//! at compile time (doc tests with `compile_fail` in `src/lib.rs`), by a `debug_assert!` (these
//! tests run in debug builds: `cargo test -p restir-gris --test mistakes`, which `.ci/run` does),
//! or by what a release build does instead.

use restir_gris::{
    GrisInput, PairwiseNeighbor, PairwiseResampler, PairwiseVariant, Reservoir, Shifted,
    StreamingReservoir,
};

fn reservoir(sample: u8, ucw: f32, confidence: f32, own_target: f32) -> Reservoir<u8> {
    Reservoir {
        sample: Some(sample),
        ucw,
        confidence,
        own_target,
    }
}

/// Mistake 1: the neighbour's own target `p̂_i(X_i)`, `W_i` and `c_i` come from its reservoir,
/// the receiver's target from the shift: a neighbour built from the wrong values cannot be
/// written (the struct's fields are private; see the `compile_fail` doc test in `src/lib.rs`),
/// and the right values are read from the right places.
#[test]
fn pairwise_neighbor_takes_its_own_target_from_its_reservoir() {
    let neighbor = reservoir(1, 1.5, 3.0, 0.25);
    let shifted = Shifted {
        sample: 1u8,
        jacobian: 2.0,
        destination_target: 0.75,
    };
    let n = PairwiseNeighbor::new(&neighbor, Some(shifted), 0.125);
    assert_eq!(n.shifted(), Some(&shifted));
    assert_eq!(n.pulled_back_target_at_canonical(), 0.125);
    let input = GrisInput::from_shift(shifted, &neighbor);
    assert_eq!(
        (
            input.receiver_target,
            input.ucw,
            input.confidence,
            input.jacobian
        ),
        (0.75, 1.5, 3.0, 2.0)
    );

    // The canonical share at the canonical sample uses the pulled-back p̂_{←i}(X_c) = 0.125
    // against the canonical reservoir's own target 0.5 (plain pairwise, k = 1).
    let canonical = reservoir(0, 1.0, 1.0, 0.5);
    let mut step = PairwiseResampler::new(PairwiseVariant::Plain, 1, canonical);
    step.add_neighbor(n, 0.0);
    let a_canonical_sample = 3.0 * 0.125 / (3.0 * 0.125 + 0.5);
    let expected = 1.0 - a_canonical_sample;
    assert!((step.canonical_weight() - expected).abs() < 1e-7);
}

/// Mistake 2, debug builds: `add` then `finalize_recorded` fails a `debug_assert!`.
#[test]
#[cfg_attr(
    not(debug_assertions),
    ignore = "a debug_assert!: run in debug (cargo test -p restir-gris --test mistakes)"
)]
#[should_panic(expected = "finalize_recorded() after add()")]
fn add_then_finalize_recorded_is_caught_in_debug() {
    let mut s = StreamingReservoir::new();
    s.add(1u8, 2.0, 0.5);
    let _ = s.finalize_recorded();
}

/// Mistake 2, release builds: the documented empty reservoir (confidence kept), never a bogus
/// weight; `finalize(target)` is the right call and works.
#[test]
#[cfg_attr(debug_assertions, ignore = "the release behaviour: run in release")]
fn add_then_finalize_recorded_is_empty_in_release() {
    let mut s = StreamingReservoir::new();
    s.add(1u8, 2.0, 0.5);
    let r = s.finalize_recorded();
    assert!(r.is_empty() && r.ucw == 0.0 && r.confidence == 1.0);
    assert_eq!(s.finalize(4.0).ucw, 0.5);
}

/// `add_candidate` then `finalize_recorded`, and a merge of such streams, are fine in every
/// build (the assertion does not fire on correct use).
#[test]
fn add_candidate_then_finalize_recorded_is_fine() {
    let mut a = StreamingReservoir::new();
    a.add_candidate(1u8, 2.0, 3.0, 1.0, 0.5);
    let mut b = StreamingReservoir::new();
    b.add_candidate(2u8, 4.0, 1.0, 1.0, 0.5);
    a.merge(b, 0.9);
    let r = a.finalize_recorded();
    assert_eq!(
        (r.sample, r.ucw, r.own_target, r.confidence),
        (Some(1), 2.0, 2.0, 2.0)
    );
    // Nothing selected: no assertion, an empty reservoir.
    let mut e = StreamingReservoir::new();
    e.add(3u8, 0.0, 0.5);
    assert!(e.finalize_recorded().is_empty());
}

/// Mistake 3: a uniform outside `[0, 1)` fails a `debug_assert!` (a raw integer does not
/// compile: see the `compile_fail` doc test in `src/lib.rs`).
#[test]
#[cfg_attr(
    not(debug_assertions),
    ignore = "a debug_assert!: run in debug (cargo test -p restir-gris --test mistakes)"
)]
#[should_panic(expected = "is not in [0, 1)")]
fn uniform_out_of_range_is_caught_in_debug() {
    let mut s = StreamingReservoir::new();
    s.add(1u8, 2.0, 0.5);
    s.add(2u8, 2.0, 1.0);
}

/// Mistake 3, for the GRIS resampler's inputs too.
#[test]
#[cfg_attr(
    not(debug_assertions),
    ignore = "a debug_assert!: run in debug (cargo test -p restir-gris --test mistakes)"
)]
#[should_panic(expected = "is not in [0, 1)")]
fn uniform_out_of_range_is_caught_in_gris_debug() {
    let mut step = restir_gris::GrisResampler::new();
    let input = GrisInput::canonical(reservoir(0, 1.0, 1.0, 1.0)).unwrap();
    step.add(input, 1.0, -0.25f32);
}
