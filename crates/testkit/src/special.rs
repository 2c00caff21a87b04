//! Special functions for goodness-of-fit tests: `ln Γ`, the regularised incomplete gamma
//! functions, the chi-square survival function (statistic → p-value) and Šidák's per-test
//! significance level.

use core::f64::consts::PI;

// ------------------------------------------------------------------------------------------
// Special functions
// ------------------------------------------------------------------------------------------

const GAMMA_EPS: f64 = 1e-15;
const GAMMA_MAX_ITER: usize = 100_000;
const LENTZ_TINY: f64 = 1e-300;

/// `ln Γ(x)` for `x > 0` (NaN otherwise), by Stirling's series after shifting the argument to
/// `x ≥ 10` with `Γ(x) = Γ(x + n) / (x (x+1) ⋯ (x+n−1))`. Absolute error below 1e-13.
pub fn ln_gamma(x: f64) -> f64 {
    if x.is_nan() || x <= 0.0 {
        return f64::NAN;
    }
    if x.is_infinite() {
        return f64::INFINITY;
    }
    let mut z = x;
    let mut shift = 0.0;
    while z < 10.0 {
        shift += z.ln();
        z += 1.0;
    }
    // Stirling: (z − ½) ln z − z + ½ ln 2π + Σ B₂ₖ / (2k (2k−1) z^(2k−1)).
    let inv = 1.0 / z;
    let inv2 = inv * inv;
    let series = inv
        * (1.0 / 12.0
            - inv2
                * (1.0 / 360.0
                    - inv2
                        * (1.0 / 1260.0
                            - inv2
                                * (1.0 / 1680.0
                                    - inv2 * (1.0 / 1188.0 - inv2 * (691.0 / 360_360.0))))));
    (z - 0.5) * z.ln() - z + 0.5 * (2.0 * PI).ln() + series - shift
}

/// `ln(x^a e^(−x) / Γ(a))`, the common prefactor of both expansions of the incomplete gamma
/// function.
fn gamma_prefactor_ln(a: f64, x: f64) -> f64 {
    a * x.ln() - x - ln_gamma(a)
}

/// `P(a, x)` by its power series `e^(−x) x^a / Γ(a) · Σₙ xⁿ / (a (a+1) ⋯ (a+n))`; converges
/// quickly for `x < a + 1`.
fn gamma_p_series(a: f64, x: f64) -> f64 {
    let mut denom = a;
    let mut term = 1.0 / a;
    let mut sum = term;
    for _ in 0..GAMMA_MAX_ITER {
        denom += 1.0;
        term *= x / denom;
        sum += term;
        if term.abs() <= sum.abs() * GAMMA_EPS {
            break;
        }
    }
    (sum.ln() + gamma_prefactor_ln(a, x)).exp()
}

/// `Q(a, x)` by Legendre's continued fraction
/// `e^(−x) x^a / Γ(a) · 1 / (x + 1 − a − 1·(1 − a) / (x + 3 − a − 2·(2 − a) / (x + 5 − a − ⋯)))`,
/// evaluated with the modified Lentz method; converges quickly for `x ≥ a + 1`.
fn gamma_q_continued_fraction(a: f64, x: f64) -> f64 {
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / LENTZ_TINY;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..GAMMA_MAX_ITER {
        let i = i as f64;
        let an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if d.abs() < LENTZ_TINY {
            d = LENTZ_TINY;
        }
        c = b + an / c;
        if c.abs() < LENTZ_TINY {
            c = LENTZ_TINY;
        }
        d = 1.0 / d;
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() <= GAMMA_EPS {
            break;
        }
    }
    (h.ln() + gamma_prefactor_ln(a, x)).exp()
}

/// The regularized lower incomplete gamma function `P(a, x) = γ(a, x) / Γ(a)` for `a > 0`,
/// `x ≥ 0` (NaN outside that domain).
pub fn gamma_p(a: f64, x: f64) -> f64 {
    if a.is_nan() || x.is_nan() || a <= 0.0 || x < 0.0 {
        return f64::NAN;
    }
    if x == 0.0 {
        0.0
    } else if x.is_infinite() {
        1.0
    } else if x < a + 1.0 {
        gamma_p_series(a, x)
    } else {
        1.0 - gamma_q_continued_fraction(a, x)
    }
}

/// The regularized upper incomplete gamma function `Q(a, x) = Γ(a, x) / Γ(a) = 1 − P(a, x)` for
/// `a > 0`, `x ≥ 0` (NaN outside that domain). Accurate in relative terms also when `Q` is tiny,
/// which is what small p-values need.
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if a.is_nan() || x.is_nan() || a <= 0.0 || x < 0.0 {
        return f64::NAN;
    }
    if x == 0.0 {
        1.0
    } else if x.is_infinite() {
        0.0
    } else if x < a + 1.0 {
        1.0 - gamma_p_series(a, x)
    } else {
        gamma_q_continued_fraction(a, x)
    }
}

/// The chi-square survival function: the probability that a chi-square variable with `dof`
/// degrees of freedom is at least `x`, `Q(dof/2, x/2)`. This is the p-value of a chi-square
/// statistic `x`. `x ≤ 0` gives 1; `dof ≤ 0` or NaN input gives NaN.
pub fn chi2_sf(x: f64, dof: f64) -> f64 {
    if x.is_nan() || dof.is_nan() || dof <= 0.0 {
        return f64::NAN;
    }
    if x <= 0.0 {
        return 1.0;
    }
    gamma_q(0.5 * dof, 0.5 * x)
}

/// Šidák's per-test significance level for `test_count` independent tests whose family-wise
/// error rate is `alpha`: `1 − (1 − alpha)^(1 / test_count)`, slightly above Bonferroni's
/// `alpha / test_count`. Mitsuba's chi-square tests use it with `alpha = 0.01`; a test fails when
/// its p-value is below the result. A `test_count` of 0 is treated as 1.
pub fn sidak_level(alpha: f64, test_count: usize) -> f64 {
    let m = test_count.max(1) as f64;
    -((-alpha).ln_1p() / m).exp_m1()
}

// ------------------------------------------------------------------------------------------
// Pearson's chi-square test
// ------------------------------------------------------------------------------------------

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs().max(f64::MIN_POSITIVE)
    }

    #[test]
    fn ln_gamma_known_values() {
        assert!(ln_gamma(1.0).abs() < 1e-14);
        assert!(ln_gamma(2.0).abs() < 1e-14);
        assert!((ln_gamma(0.5) - 0.5 * PI.ln()).abs() < 1e-14);
        assert!((ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-13);
        assert!((ln_gamma(1e-8) - (1e-8f64).recip().ln()).abs() < 1e-7);
        // Γ(x + 1) = x Γ(x) far from the shift point.
        for x in [0.3, 3.7, 9.99, 10.0, 57.25, 1234.5] {
            let tol = 1e-13 + 4.0 * f64::EPSILON * ln_gamma(x + 1.0).abs();
            assert!(
                (ln_gamma(x + 1.0) - ln_gamma(x) - f64::ln(x)).abs() < tol,
                "x = {x}"
            );
        }
        assert!(ln_gamma(0.0).is_nan() && ln_gamma(-1.0).is_nan());
    }

    /// Quantiles from tables (computed with mpmath to 30 digits): sf(ppf(1 − α, k), k) = α.
    #[test]
    fn chi2_sf_at_table_quantiles() {
        let table = [
            (3.841458820694124, 1.0, 0.05),
            (6.6348966010212145, 1.0, 0.01),
            (10.827566170662733, 1.0, 0.001),
            (7.814727903251178, 3.0, 0.05),
            (15.08627246938899, 5.0, 0.01),
            (18.307038053275146, 10.0, 0.05),
            (124.34211340400407, 100.0, 0.05),
        ];
        for (x, k, alpha) in table {
            let p = chi2_sf(x, k);
            assert!(close(p, alpha, 1e-10), "sf({x}, {k}) = {p}, want {alpha}");
        }
        assert!((chi2_sf(3.84, 1.0) - 0.05).abs() < 1e-4);
        assert!((chi2_sf(18.31, 10.0) - 0.05).abs() < 1e-4);
    }

    /// More mpmath reference values: both expansions, tiny tails, fractional dof.
    #[test]
    fn chi2_sf_reference_values() {
        let table = [
            (0.5, 1.0, 0.4795001221869535),
            (1e-3, 1.0, 0.9747728793699604),
            (100.0, 100.0, 0.48119168452795672),
            (1000.0, 900.0, 0.010994608942135848),
            (40.0, 3.0, 1.0655090334255861e-8),
            (200.0, 30.0, 4.952733529003191e-27),
            (5.0, 0.5, 0.009213748479540033),
        ];
        for (x, k, want) in table {
            let p = chi2_sf(x, k);
            assert!(close(p, want, 1e-10), "sf({x}, {k}) = {p:e}, want {want:e}");
        }
    }

    /// For even dof the survival function is a finite Poisson sum:
    /// sf(x, 2m) = e^(−x/2) Σ_{j<m} (x/2)^j / j!.
    #[test]
    fn chi2_sf_even_dof_closed_form() {
        for m in [1usize, 2, 3, 7, 25, 100] {
            for x in [0.01, 0.7, 2.0, 9.5, 30.0, 150.0, 400.0] {
                let h: f64 = 0.5 * x;
                let (mut term, mut sum) = (1.0f64, 0.0f64);
                for j in 0..m {
                    if j > 0 {
                        term *= h / j as f64;
                    }
                    sum += term;
                }
                let want = (-h).exp() * sum;
                let got = chi2_sf(x, 2.0 * m as f64);
                assert!(
                    close(got, want, 1e-9),
                    "sf({x}, {}) = {got:e}, want {want:e}",
                    2 * m
                );
            }
        }
    }

    #[test]
    fn chi2_sf_edges() {
        for k in [1.0, 2.0, 10.0, 333.0] {
            assert_eq!(chi2_sf(0.0, k), 1.0);
            assert_eq!(chi2_sf(-3.0, k), 1.0);
            assert_eq!(chi2_sf(f64::INFINITY, k), 0.0);
        }
        assert!(chi2_sf(1.0, 0.0).is_nan());
        assert!(chi2_sf(f64::NAN, 3.0).is_nan());
        // P + Q = 1 on both sides of the branch point x = a + 1.
        for (a, x) in [(0.5, 0.2), (3.0, 3.9), (3.0, 4.1), (50.0, 70.0)] {
            assert!((gamma_p(a, x) + gamma_q(a, x) - 1.0).abs() < 1e-14);
        }
        // Monotone in x.
        let mut last = 1.0;
        for i in 1..200 {
            let p = chi2_sf(i as f64 * 0.25, 7.0);
            assert!(p <= last);
            last = p;
        }
    }

    #[test]
    fn sidak() {
        assert!((sidak_level(0.01, 1) - 0.01).abs() < 1e-15);
        let l = sidak_level(0.01, 10);
        assert!((1.0 - (1.0 - l).powi(10) - 0.01).abs() < 1e-15);
        assert!(l > 0.001 && l < 0.00101);
        assert_eq!(sidak_level(0.01, 0), sidak_level(0.01, 1));
    }
}
