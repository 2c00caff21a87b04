//! The streaming selection law at the edges of `f32`: 10⁷ candidates whose weights span
//! 10⁻³⁰…10³⁰, the heaviest first (the worst case for the running sum), chi-square against the
//! exact law `w_i / Σ w`. With a 53-bit `f64` uniform ([`uniform_f64`]) the law holds; the
//! negative control streams the same candidates with a 24-bit `f32` uniform and must fail
//! (candidates below `2^-24` of the running sum are then taken with probability `≈ 2^-24`).
//!
//! Release-only: 10⁹ reservoir updates (a few seconds in release, minutes in debug).

use restir_gris::{StreamingReservoir, uniform_f64};
use restir_testkit::{SplitMix64 as Rng, chi_square, chi_square_critical};

const CANDIDATES: usize = 10_000_000;
const HEAVY: f32 = 1e30;
/// Light weights are log-uniform in `[1e-30, 1e25)`.
const LIGHT_EXPONENTS: (f64, f64) = (-30.0, 25.0);
/// Cells: the heavy candidate, the light ones with `w ≥ SPLIT`, the rest.
const SPLIT: f32 = 1e24;

fn weights() -> Vec<f32> {
    let mut rng = Rng::new(0x005e_1ec7);
    let (lo, hi) = LIGHT_EXPONENTS;
    let mut w = Vec::with_capacity(CANDIDATES);
    w.push(HEAVY);
    w.extend((1..CANDIDATES).map(|_| 10f64.powf(lo + (hi - lo) * rng.next_f64()) as f32));
    w
}

fn cell(weights: &[f32], i: usize) -> usize {
    if i == 0 {
        0
    } else if weights[i] >= SPLIT {
        1
    } else {
        2
    }
}

/// Exact probabilities of the three cells.
fn law(weights: &[f32]) -> Vec<f64> {
    let mut mass = [0.0f64; 3];
    for i in 0..weights.len() {
        mass[cell(weights, i)] += f64::from(weights[i]);
    }
    let total: f64 = mass.iter().sum();
    mass.iter().map(|m| m / total).collect()
}

/// Streams every candidate once per trial (two threads) and counts the selected cell.
fn counts(weights: &[f32], trials: u64, wide_uniform: bool) -> Vec<u64> {
    let run = |seed: u64, n: u64| -> [u64; 3] {
        let mut rng = Rng::new(seed);
        let mut counts = [0u64; 3];
        for _ in 0..n {
            let mut s = StreamingReservoir::new();
            for (i, &w) in weights.iter().enumerate() {
                if wide_uniform {
                    s.add(i, w, uniform_f64(rng.next_u64()));
                } else {
                    s.add(i, w, rng.next_f32());
                }
            }
            counts[cell(weights, *s.selected().unwrap())] += 1;
        }
        counts
    };
    let (a, b) = std::thread::scope(|scope| {
        let a = scope.spawn(|| run(1, trials / 2));
        let b = run(2, trials - trials / 2);
        (a.join().unwrap(), b)
    });
    (0..3).map(|c| a[c] + b[c]).collect()
}

fn statistic(wide_uniform: bool, trials: u64) -> (f64, f64, Vec<u64>, Vec<f64>) {
    let w = weights();
    let probs = law(&w);
    // Every cell must be populated enough for the chi-square approximation.
    assert!(probs.iter().all(|&p| p * trials as f64 >= 5.0), "{probs:?}");
    let counts = counts(&w, trials, wide_uniform);
    let (stat, df) = chi_square(&counts, &probs, trials);
    (stat, chi_square_critical(df), counts, probs)
}

#[test]
#[cfg_attr(debug_assertions, ignore = "10⁹ reservoir updates: run in release")]
fn selection_law_holds_across_60_decades_with_a_53_bit_uniform() {
    let (stat, critical, counts, probs) = statistic(true, 200);
    assert!(
        stat < critical,
        "chi-square {stat:.1} ≥ {critical:.1}: counts {counts:?}, law {probs:?}"
    );
}

#[test]
#[cfg_attr(debug_assertions, ignore = "10⁹ reservoir updates: run in release")]
fn negative_control_a_24_bit_uniform_breaks_the_law() {
    let (stat, critical, counts, probs) = statistic(false, 120);
    assert!(
        stat > critical,
        "the 24-bit control passed (chi-square {stat:.1} < {critical:.1}): counts {counts:?}, law {probs:?}"
    );
}
