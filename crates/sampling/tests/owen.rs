//! Owen-scrambled Sobol samples are uniform: for a fixed sample index, over random scramble
//! seeds, the numbers of one sample (a 2-D dimension then a 1-D one) are jointly uniform in the
//! unit cube, which is what keeps every estimator that draws from them unbiased. The control: a
//! sequence whose scramble forgets the seed (the same numbers for every pixel) is rejected.

use restir_sampling::{OwenSobol, mix64};
use restir_testkit::{chi2_test, sidak_level};

/// Cells per axis of the 3-D histogram.
const CELLS: usize = 4;
const SEEDS: u64 = 8192;
/// Indices tested (each a hypothesis test).
const INDICES: [u32; 4] = [0, 3, 64, 1001];

/// The histogram of `(u0, u1, u2)` of sample `index` over `SEEDS` scrambles from `seed_of`.
fn histogram(index: u32, seed_of: impl Fn(u64) -> u64) -> Vec<u64> {
    let mut counts = vec![0u64; CELLS * CELLS * CELLS];
    for s in 0..SEEDS {
        let mut q = OwenSobol::new(seed_of(s), index);
        let a = q.next_2d();
        let b = q.next_f32();
        let cell = |x: f32| ((x * CELLS as f32) as usize).min(CELLS - 1);
        counts[cell(a.x) + CELLS * (cell(a.y) + CELLS * cell(b))] += 1;
    }
    counts
}

fn expected() -> Vec<f64> {
    vec![SEEDS as f64 / (CELLS * CELLS * CELLS) as f64; CELLS * CELLS * CELLS]
}

#[test]
fn one_sample_is_uniform_over_scrambles() {
    let level = sidak_level(0.01, INDICES.len());
    for index in INDICES {
        let outcome = chi2_test(&histogram(index, |s| mix64(s ^ 0x0e3e)), &expected()).unwrap();
        eprintln!("index {index}: {outcome}");
        assert!(outcome.accepts(level), "index {index}: {outcome}");
    }
}

#[test]
fn control_a_scramble_without_the_seed_is_rejected() {
    let outcome = chi2_test(&histogram(3, |_| 0x0e3e), &expected()).unwrap();
    eprintln!("control: {outcome}");
    assert!(outcome.p_value < 1e-6, "{outcome}");
}
