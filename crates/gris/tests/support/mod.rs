//! Shared helpers for the integration tests: a small RNG, running statistics, a chi-square bound
//! and the toy GRIS domains.
#![allow(dead_code)]

use restir_gris::{Reservoir, ShiftMap, Shifted, StreamingReservoir};

/// SplitMix64 (Steele, Lea & Flood 2014): tiny, fast, good enough for Monte Carlo tests.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1) with 24 bits.
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }

    /// Uniform in [0, 1) with 53 bits.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// Running mean and standard error (Welford).
#[derive(Clone, Debug, Default)]
pub struct Stats {
    n: u64,
    mean: f64,
    m2: f64,
}

impl Stats {
    pub fn push(&mut self, x: f64) {
        assert!(x.is_finite(), "non-finite estimate {x}");
        self.n += 1;
        let d = x - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (x - self.mean);
    }

    pub fn mean(&self) -> f64 {
        self.mean
    }

    /// Standard error of the mean.
    pub fn std_error(&self) -> f64 {
        (self.m2 / (self.n as f64 - 1.0) / self.n as f64).sqrt()
    }

    /// Asserts |mean − truth| < 4·SE (two-sided false-failure probability ≈ 6e-5 per check, and the
    /// seeds are fixed) and that the test has power: SE < 1 % of the truth.
    pub fn assert_unbiased(&self, truth: f64, what: &str) {
        let se = self.std_error();
        let z = (self.mean - truth) / se;
        assert!(
            se < 0.01 * truth.abs(),
            "{what}: standard error {se} too large to detect bias"
        );
        assert!(
            z.abs() < 4.0,
            "{what}: mean {} vs truth {truth} is {z:.2} standard errors away (SE {se})",
            self.mean
        );
    }
}

/// Trials for the Monte Carlo tests: fewer in unoptimised builds so `cargo test` stays fast; the
/// tolerances are derived from the measured standard error either way.
pub fn trials(release: usize) -> usize {
    if cfg!(debug_assertions) {
        release / 8
    } else {
        release
    }
}

/// Upper `p = 1e-4` quantile of χ² with `df` degrees of freedom (Wilson–Hilferty approximation).
pub fn chi_square_critical(df: usize) -> f64 {
    let z = 3.719; // standard normal upper 1e-4 quantile
    let k = df as f64;
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

/// Pearson χ² statistic of `counts` against probabilities `probs` over `n` draws (cells with
/// probability 0 must have count 0).
pub fn chi_square(counts: &[u64], probs: &[f64], n: u64) -> (f64, usize) {
    let mut stat = 0.0;
    let mut cells = 0;
    for (&c, &p) in counts.iter().zip(probs) {
        if p == 0.0 {
            assert_eq!(c, 0, "a zero-probability cell was selected");
            continue;
        }
        let e = p * n as f64;
        stat += (c as f64 - e) * (c as f64 - e) / e;
        cells += 1;
    }
    (stat, cells - 1)
}

// ---------------------------------------------------------------------------------------------
// The toy GRIS problem (our own construction; docs/GRIS.md §7).
//
// Every domain d lives on [0, support_max_d] ⊂ [0, 1] and carries an exponent s_d; the shift
// T_{a→b}(x) = x^{s_a/s_b} (canonical s = 1) with Jacobian (s_a/s_b)·x^{s_a/s_b − 1}. A shift fails
// iff its input lies outside the source support or its output outside the destination support,
// so forward and inverse shifts fail together. Each domain has its own target; one neighbour has
// partial support, which makes constant 1/M MIS biased.
// ---------------------------------------------------------------------------------------------

/// Target functions used by the toy domains.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ToyTarget {
    /// 0.25 + x (canonical).
    Linear,
    /// x² + 0.1.
    Quadratic,
    /// x.
    Ramp,
    /// 1 − 0.5·x.
    Falling,
}

#[derive(Clone, Copy, Debug)]
pub struct ToyDomain {
    pub exponent: f64,
    pub support_max: f64,
    pub target: ToyTarget,
    pub confidence: f32,
    /// RIS candidates used to build this domain's reservoir.
    pub candidates: usize,
}

impl ToyDomain {
    pub fn target_pdf(&self, x: f64) -> f64 {
        if !(0.0..=self.support_max).contains(&x) {
            return 0.0;
        }
        match self.target {
            ToyTarget::Linear => 0.25 + x,
            ToyTarget::Quadratic => x * x + 0.1,
            ToyTarget::Ramp => x,
            ToyTarget::Falling => 1.0 - 0.5 * x,
        }
    }

    /// RIS with uniform candidates on [0, support_max] (pdf 1/support_max).
    pub fn sample(&self, rng: &mut Rng) -> Reservoir<f64> {
        let n = self.candidates;
        let mut stream = StreamingReservoir::new();
        for _ in 0..n {
            let x = rng.next_f64() * self.support_max;
            let t = self.target_pdf(x);
            let w = t * self.support_max / n as f64;
            stream.add_candidate(x, t as f32, w as f32, 0.0, rng.next_f32());
        }
        let mut r = stream.finalize_recorded();
        r.confidence = self.confidence;
        r
    }
}

/// Integrand of the canonical domain: f(y) = 0.5 + 3y², ∫_0^1 f = 1.5.
pub fn toy_integrand(y: f64) -> f64 {
    0.5 + 3.0 * y * y
}

pub const TOY_INTEGRAL: f64 = 1.5;

/// ∫_{0.5}^{1} f: the part of the integral the partial-support neighbour cannot reach.
pub const TOY_UNCOVERED_INTEGRAL: f64 = 0.25 + 0.875;

#[derive(Clone, Copy, Debug)]
pub struct PowerShift;

impl ShiftMap<f64> for PowerShift {
    type Domain = ToyDomain;

    fn shift(&self, from: &ToyDomain, to: &ToyDomain, x: &f64) -> Option<Shifted<f64>> {
        let x = *x;
        if !(0.0..=from.support_max).contains(&x) {
            return None;
        }
        let a = from.exponent / to.exponent;
        let y = x.powf(a);
        if !(0.0..=to.support_max).contains(&y) {
            return None;
        }
        let jacobian = (a * x.powf(a - 1.0)) as f32;
        let s = Shifted {
            sample: y,
            jacobian,
            target_pdf: to.target_pdf(y) as f32,
        };
        s.is_valid().then_some(s)
    }
}

/// Canonical domain and three neighbours: full support with a different target and exponent 2,
/// partial support [0, 0.5], and exponent 0.5 with a falling target.
pub fn toy_domains() -> (ToyDomain, [ToyDomain; 3]) {
    let canonical = ToyDomain {
        exponent: 1.0,
        support_max: 1.0,
        target: ToyTarget::Linear,
        confidence: 1.0,
        candidates: 4,
    };
    let neighbors = [
        ToyDomain {
            exponent: 2.0,
            support_max: 1.0,
            target: ToyTarget::Quadratic,
            confidence: 2.0,
            candidates: 3,
        },
        ToyDomain {
            exponent: 1.0,
            support_max: 0.5,
            target: ToyTarget::Ramp,
            confidence: 1.5,
            candidates: 3,
        },
        ToyDomain {
            exponent: 0.5,
            support_max: 1.0,
            target: ToyTarget::Falling,
            confidence: 0.5,
            candidates: 2,
        },
    ];
    (canonical, neighbors)
}
