//! Monte Carlo test helpers: a tiny seeded generator ([`SplitMix64`]), a running mean with its
//! standard error and an unbiasedness check ([`RunningStats`]), and trial counts that shrink in
//! unoptimised builds ([`trials`]).

/// SplitMix64 (Steele, Lea & Flood 2014): tiny, fast, good enough for Monte Carlo tests.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator whose first output is determined by `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
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
pub struct RunningStats {
    n: u64,
    mean: f64,
    m2: f64,
}

impl RunningStats {
    /// Adds one estimate; panics if it is not finite.
    pub fn push(&mut self, x: f64) {
        assert!(x.is_finite(), "non-finite estimate {x}");
        self.n += 1;
        let d = x - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (x - self.mean);
    }

    /// Mean of the estimates so far.
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
/// tolerances are derived from the measured standard error either way. The build profile is that
/// of this crate, which Cargo compiles with the same profile as the tests using it.
pub fn trials(release: usize) -> usize {
    if cfg!(debug_assertions) {
        release / 8
    } else {
        release
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn running_mean_and_error() {
        let mut s = RunningStats::default();
        for x in [1.0, 2.0, 3.0, 4.0] {
            s.push(x);
        }
        assert!((s.mean() - 2.5).abs() < 1e-12);
        // Sample variance 5/3, standard error sqrt(5/3 / 4).
        assert!((s.std_error() - (5.0f64 / 12.0).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn uniform_in_unit_interval() {
        let mut rng = SplitMix64::new(7);
        let mut s = RunningStats::default();
        for _ in 0..10_000 {
            let (a, b) = (rng.next_f32(), rng.next_f64());
            assert!((0.0..1.0).contains(&a) && (0.0..1.0).contains(&b));
            s.push(b);
        }
        assert!((s.mean() - 0.5).abs() < 4.0 * s.std_error());
    }
}
