//! Goodness-of-fit tests for samplers: Pearson's chi-square test on histograms, the chi-square
//! survival function that turns its statistic into a p-value, and the grids and quadrature that
//! produce the histograms.
//!
//! The recipe follows the approach of Mitsuba 3's `chi2` test helper:
//!
//! 1. Draw `N` samples with a fixed seed and bin them on a grid ([`Grid2D`], or [`SphereGrid`]
//!    for directions) into a [`Histogram`]. A sample the grid cannot place (non-finite, outside
//!    the domain, not unit length) is counted as *outside*; a sample the density does not describe
//!    (the sampler returned `None`, or produced a delta-lobe sample) as *remainder*.
//! 2. Integrate the density the sampler claims over every cell ([`Grid2D::integrate`],
//!    [`SphereGrid::integrate`]); `N` times these probabilities are the expected counts.
//! 3. [`Histogram::chi2`] (or [`chi2_test`] on raw counts) computes Pearson's statistic. Cells
//!    whose expected count is below [`POOL_THRESHOLD`] are pooled into one cell; a sample in a
//!    cell with zero expected count, or outside the domain, is an immediate failure
//!    ([`Chi2Error`]). The p-value is the chi-square survival function [`chi2_sf`] at the
//!    statistic with (used cells − 1) degrees of freedom.
//! 4. **Significance level.** A file that runs `m` such tests rejects a test when
//!    `p < sidak_level(0.01, m) = 1 − (1 − 0.01)^(1/m) ≈ 0.01 / m` (Šidák's correction, Mitsuba's
//!    convention): the probability that a correct sampler fails *any* test of the file is 1 %.
//!    Seeds are fixed, so a passing test keeps passing; the correction keeps the chance of having
//!    picked an unlucky seed small.
//!
//! A chi-square test can only prove something if it can fail: every test file pairs its tests with
//! a negative control (a deliberately wrong density) that must be rejected with a tiny p-value.
//!
//! ```
//! use restir_sampling::stats::{Histogram, Quadrature, SphereGrid, sidak_level};
//! use restir_sampling::{Pcg32, warp};
//!
//! let grid = SphereGrid::default(); // 10 cos θ bins × 20 φ bins over the whole sphere
//! let mut hist = Histogram::new(grid.len());
//! let mut rng = Pcg32::new(1, 0);
//! for _ in 0..20_000 {
//!     hist.record(grid.bin(warp::sample_cosine_hemisphere(rng.next_2d())));
//! }
//! let probabilities =
//!     grid.integrate(|w| warp::cosine_hemisphere_pdf(w.z) as f64, &Quadrature::default());
//! let outcome = hist.chi2(&probabilities).unwrap();
//! assert!(outcome.p_value >= sidak_level(0.01, 1), "{outcome}");
//!
//! // The same samples against the wrong density are rejected.
//! let wrong = grid.integrate(
//!     |w| if w.z >= 0.0 { warp::UNIFORM_HEMISPHERE_PDF as f64 } else { 0.0 },
//!     &Quadrature::default(),
//! );
//! assert!(hist.chi2(&wrong).unwrap().p_value < 1e-6);
//! ```

use core::f64::consts::PI;
use glam::Vec3;

/// Cells with an expected count below this are pooled into one cell (the usual rule of thumb for
/// the chi-square approximation to hold, also Mitsuba's).
pub const POOL_THRESHOLD: f64 = 5.0;

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

/// Why a chi-square test could not produce a p-value. Every variant is a failed test: the first
/// three mean the sampler (or the density) is wrong, the others that the test is malformed.
#[derive(Clone, Debug, PartialEq)]
pub enum Chi2Error {
    /// Samples fell into cells whose expected count is zero: the sampler produces values the
    /// density says are impossible. `bin` is the first such cell, `observed` the total over all of
    /// them.
    SampleInZeroBin {
        /// The first cell with zero expected count but samples in it.
        bin: usize,
        /// How many samples fell into zero-expectation cells.
        observed: u64,
    },
    /// Samples that the grid could not place: outside its domain, not finite, or (for
    /// [`SphereGrid`]) not unit length.
    OutsideDomain {
        /// How many.
        observed: u64,
    },
    /// An expected count is negative or not finite (the density returned garbage).
    InvalidExpected {
        /// The cell.
        bin: usize,
        /// Its expected count.
        value: f64,
    },
    /// The observed and expected arrays differ in length.
    LengthMismatch {
        /// Observed cells.
        observed: usize,
        /// Expected cells.
        expected: usize,
    },
    /// After pooling fewer than two cells remain, so there is nothing to test.
    TooFewCells {
        /// Cells left after pooling.
        cells: usize,
    },
}

impl core::fmt::Display for Chi2Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Chi2Error::SampleInZeroBin { bin, observed } => write!(
                f,
                "{observed} samples fell into cells with expected count 0 (first: cell {bin})"
            ),
            Chi2Error::OutsideDomain { observed } => write!(
                f,
                "{observed} samples were outside the grid's domain, not finite or not unit length"
            ),
            Chi2Error::InvalidExpected { bin, value } => {
                write!(
                    f,
                    "cell {bin}: expected count {value} is negative or not finite"
                )
            }
            Chi2Error::LengthMismatch { observed, expected } => {
                write!(f, "{observed} observed cells but {expected} expected cells")
            }
            Chi2Error::TooFewCells { cells } => write!(
                f,
                "only {cells} cell(s) left after pooling: no degrees of freedom to test"
            ),
        }
    }
}

impl std::error::Error for Chi2Error {}

/// The cell that contributes most to a chi-square statistic (for failure messages).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorstCell {
    /// Index of the cell in the arrays passed to [`chi2_test`].
    pub bin: usize,
    /// Its observed count.
    pub observed: u64,
    /// Its expected count.
    pub expected: f64,
}

/// The result of Pearson's chi-square test.
#[derive(Clone, Debug, PartialEq)]
pub struct Chi2Outcome {
    /// Pearson's statistic `Σ (observed − expected)² / expected` over the cells used.
    pub statistic: f64,
    /// Degrees of freedom: cells used (after pooling) minus one.
    pub dof: usize,
    /// `P(χ²_dof ≥ statistic)`: the probability of a statistic at least this large if the
    /// samples follow the expected distribution.
    pub p_value: f64,
    /// How many cells had an expected count below [`POOL_THRESHOLD`] and were pooled.
    pub pooled_cells: usize,
    /// Cells with zero expected and zero observed count; they carry no information.
    pub empty_cells: usize,
    /// Total observed count.
    pub observed_total: u64,
    /// Total expected count.
    pub expected_total: f64,
    /// The unpooled cell with the largest contribution to the statistic.
    pub worst: Option<WorstCell>,
}

impl Chi2Outcome {
    /// Whether the test accepts the null hypothesis ("the samples follow the expected
    /// distribution") at significance level `level`, i.e. `p_value ≥ level`.
    pub fn accepts(&self, level: f64) -> bool {
        self.p_value >= level
    }
}

impl core::fmt::Display for Chi2Outcome {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "chi2 = {:.3}, dof = {}, p = {:.3e} (observed {}, expected {:.1}, {} cells pooled, \
             {} empty)",
            self.statistic,
            self.dof,
            self.p_value,
            self.observed_total,
            self.expected_total,
            self.pooled_cells,
            self.empty_cells
        )?;
        if let Some(w) = self.worst {
            write!(
                f,
                "; worst cell {}: observed {}, expected {:.2}",
                w.bin, w.observed, w.expected
            )?;
        }
        Ok(())
    }
}

/// Pearson's chi-square goodness-of-fit test of `observed` counts against `expected` counts.
///
/// - A cell with expected count 0 and samples in it is an immediate failure
///   ([`Chi2Error::SampleInZeroBin`]); cells with neither are skipped (counted in
///   [`Chi2Outcome::empty_cells`]).
/// - Cells with expected count below [`POOL_THRESHOLD`] are pooled into one cell. If that pooled
///   cell's expected count is itself below the threshold it is merged into the cell with the
///   smallest expected count among the others, so no sample is ever dropped.
/// - Degrees of freedom are the cells used minus one: the test assumes that the totals agree, so
///   the expected counts must account for every sample (including a cell for failed samples when
///   the density does not integrate to one; [`Histogram::chi2`] does this).
pub fn chi2_test(observed: &[u64], expected: &[f64]) -> Result<Chi2Outcome, Chi2Error> {
    if observed.len() != expected.len() {
        return Err(Chi2Error::LengthMismatch {
            observed: observed.len(),
            expected: expected.len(),
        });
    }
    let mut zero_hits: Option<(usize, u64)> = None;
    for (i, (&o, &e)) in observed.iter().zip(expected).enumerate() {
        if !e.is_finite() || e < 0.0 {
            return Err(Chi2Error::InvalidExpected { bin: i, value: e });
        }
        if e == 0.0 && o > 0 {
            let (first, total) = zero_hits.unwrap_or((i, 0));
            zero_hits = Some((first, total + o));
        }
    }
    if let Some((bin, observed)) = zero_hits {
        return Err(Chi2Error::SampleInZeroBin { bin, observed });
    }

    let contribution = |o: u64, e: f64| {
        let d = o as f64 - e;
        d * d / e
    };
    let mut statistic = 0.0;
    let mut cells = 0usize;
    let mut empty_cells = 0usize;
    let (mut pooled_cells, mut pooled_o, mut pooled_e) = (0usize, 0u64, 0.0f64);
    let mut worst: Option<(WorstCell, f64)> = None;
    // The regular cell with the smallest expected count, for merging a too-small pool.
    let mut smallest: Option<(u64, f64)> = None;
    for (i, (&o, &e)) in observed.iter().zip(expected).enumerate() {
        if e == 0.0 {
            empty_cells += 1;
        } else if e < POOL_THRESHOLD {
            pooled_cells += 1;
            pooled_o += o;
            pooled_e += e;
        } else {
            let c = contribution(o, e);
            statistic += c;
            cells += 1;
            if worst.is_none_or(|(_, wc)| c > wc) {
                let cell = WorstCell {
                    bin: i,
                    observed: o,
                    expected: e,
                };
                worst = Some((cell, c));
            }
            if smallest.is_none_or(|(_, se)| e < se) {
                smallest = Some((o, e));
            }
        }
    }
    if pooled_cells > 0 {
        match smallest {
            Some((so, se)) if pooled_e < POOL_THRESHOLD => {
                statistic += contribution(so + pooled_o, se + pooled_e) - contribution(so, se);
            }
            _ => {
                statistic += contribution(pooled_o, pooled_e);
                cells += 1;
            }
        }
    }
    if cells < 2 {
        return Err(Chi2Error::TooFewCells { cells });
    }
    let dof = cells - 1;
    Ok(Chi2Outcome {
        statistic,
        dof,
        p_value: chi2_sf(statistic, dof as f64),
        pooled_cells,
        empty_cells,
        observed_total: observed.iter().sum(),
        expected_total: expected.iter().sum(),
        worst: worst.map(|(w, _)| w),
    })
}

// ------------------------------------------------------------------------------------------
// Histograms
// ------------------------------------------------------------------------------------------

/// Sample counts over the cells of a grid, plus two tallies that make sure no sample is ignored:
/// `outside` (samples the grid could not place, an immediate failure) and `remainder` (samples
/// the density does not describe: the sampler failed, or returned a delta-lobe sample).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Histogram {
    counts: Vec<u64>,
    outside: u64,
    remainder: u64,
}

impl Histogram {
    /// An empty histogram over `cells` cells.
    pub fn new(cells: usize) -> Self {
        Self {
            counts: vec![0; cells],
            outside: 0,
            remainder: 0,
        }
    }

    /// Counts one sample in `cell`; `None` (what [`Grid2D::bin`] and [`SphereGrid::bin`] return
    /// for samples they cannot place) or an out-of-range index counts it as outside.
    #[inline]
    pub fn record(&mut self, cell: Option<usize>) {
        match cell.and_then(|c| self.counts.get_mut(c)) {
            Some(count) => *count += 1,
            None => self.outside += 1,
        }
    }

    /// Counts one sample that the density does not describe: the sampler returned nothing, or a
    /// sample from a delta lobe. Its expected count is `N · (1 − Σ probabilities)`.
    #[inline]
    pub fn record_remainder(&mut self) {
        self.remainder += 1;
    }

    /// Counts per cell.
    pub fn counts(&self) -> &[u64] {
        &self.counts
    }

    /// Samples that could not be placed on the grid.
    pub fn outside(&self) -> u64 {
        self.outside
    }

    /// Samples recorded with [`Histogram::record_remainder`].
    pub fn remainder(&self) -> u64 {
        self.remainder
    }

    /// Every sample recorded: `N`.
    pub fn total(&self) -> u64 {
        self.counts.iter().sum::<u64>() + self.outside + self.remainder
    }

    /// The chi-square test of this histogram against per-cell `probabilities` (from
    /// [`Grid2D::integrate`] or [`SphereGrid::integrate`], or a pmf), with `N =` [`total`]
    /// samples. The remainder is tested as one more cell with probability
    /// `max(0, 1 − Σ probabilities)`; any sample outside the domain fails the test.
    ///
    /// [`total`]: Histogram::total
    pub fn chi2(&self, probabilities: &[f64]) -> Result<Chi2Outcome, Chi2Error> {
        if probabilities.len() != self.counts.len() {
            return Err(Chi2Error::LengthMismatch {
                observed: self.counts.len(),
                expected: probabilities.len(),
            });
        }
        if self.outside > 0 {
            return Err(Chi2Error::OutsideDomain {
                observed: self.outside,
            });
        }
        let n = self.total() as f64;
        let mut expected: Vec<f64> = probabilities.iter().map(|p| p * n).collect();
        let mass: f64 = probabilities.iter().sum();
        expected.push(n * (1.0 - mass).max(0.0));
        let mut observed = self.counts.clone();
        observed.push(self.remainder);
        chi2_test(&observed, &expected)
    }
}

// ------------------------------------------------------------------------------------------
// Grids and quadrature
// ------------------------------------------------------------------------------------------

/// How [`Grid2D::integrate`] integrates a density over each cell: a tensor-product Simpson rule,
/// made adaptive so that densities with discontinuities (the edge of a cone, a light's
/// silhouette) are still integrated accurately.
///
/// Each cell is split into `subdivisions × subdivisions` sub-cells. On each, the 3×3-point Simpson
/// rule is compared with the composite rule on its four quarters (5×5 points); if they differ by
/// more than `15 · tol` the quarters are refined recursively (each with half the parent's `tol`),
/// down to `max_depth` levels, else the Richardson-extrapolated fine value is kept. `tolerance` is
/// the target absolute error per cell in units of the density's integral (a probability): with
/// `N` samples the expected counts are off by about `N · tolerance`. Smooth densities meet it
/// with few evaluations; across a discontinuity the refinement stops at `max_depth`, where the
/// error is about `jump · cell area · 2^−(max_depth + 2) / subdivisions`.
///
/// Points on a cell's boundary are evaluated `1e-7` of the cell's width inside it, so that a
/// discontinuity exactly on a cell boundary (the horizon of a hemisphere, a step of a
/// piecewise-constant density) costs nothing and is attributed to the correct cell.
///
/// Features narrower than a sub-cell can fall between the sample points and be missed; the
/// chi-square test then fails (samples in cells with zero expected count) rather than passing
/// silently. Raise `subdivisions` for small features.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadrature {
    /// Sub-cells per axis in every cell before any refinement (at least 1).
    pub subdivisions: usize,
    /// Target absolute error per cell.
    pub tolerance: f64,
    /// Maximum number of adaptive refinements of a sub-cell.
    pub max_depth: u32,
}

impl Default for Quadrature {
    /// 4 × 4 sub-cells, tolerance 1e-8, depth 10: smooth densities are exact to ~1e-8, and a cell
    /// cut by a discontinuity is within ~1e-4 of its mass for the default grids.
    fn default() -> Self {
        Self {
            subdivisions: 4,
            tolerance: 1e-8,
            max_depth: 10,
        }
    }
}

/// Weights of the 1-D Simpson rule on three points, times 6.
const SIMPSON: [f64; 3] = [1.0, 4.0, 1.0];

/// Simpson's rule on a `w × h` rectangle from its 3 × 3 values `v[ix][iy]`.
#[inline]
fn simpson_3x3(v: &[[f64; 3]; 3], w: f64, h: f64) -> f64 {
    let mut s = 0.0;
    for (ix, row) in v.iter().enumerate() {
        for (iy, value) in row.iter().enumerate() {
            s += SIMPSON[ix] * SIMPSON[iy] * value;
        }
    }
    s * w * h / 36.0
}

/// Adaptive Simpson on `[x0, x0 + w] × [y0, y0 + h]` given the values at its 3 × 3 points.
#[allow(clippy::too_many_arguments)]
fn adaptive_simpson<F: Fn(f64, f64) -> f64>(
    f: &F,
    x0: f64,
    y0: f64,
    w: f64,
    h: f64,
    v: &[[f64; 3]; 3],
    tol: f64,
    depth: u32,
    max_depth: u32,
) -> f64 {
    let mut g = [[0.0f64; 5]; 5];
    for (ix, row) in g.iter_mut().enumerate() {
        for (iy, value) in row.iter_mut().enumerate() {
            *value = if ix % 2 == 0 && iy % 2 == 0 {
                v[ix / 2][iy / 2]
            } else {
                f(x0 + 0.25 * w * ix as f64, y0 + 0.25 * h * iy as f64)
            };
        }
    }
    let quarter = |qx: usize, qy: usize| {
        let mut q = [[0.0f64; 3]; 3];
        for (ix, row) in q.iter_mut().enumerate() {
            for (iy, value) in row.iter_mut().enumerate() {
                *value = g[2 * qx + ix][2 * qy + iy];
            }
        }
        q
    };
    let quarters = [quarter(0, 0), quarter(1, 0), quarter(0, 1), quarter(1, 1)];
    let (hw, hh) = (0.5 * w, 0.5 * h);
    let coarse = simpson_3x3(v, w, h);
    let fine: f64 = quarters.iter().map(|q| simpson_3x3(q, hw, hh)).sum();
    let diff = fine - coarse;
    if !diff.is_finite() || depth >= max_depth || diff.abs() <= 15.0 * tol {
        return fine + diff / 15.0;
    }
    let origins = [(x0, y0), (x0 + hw, y0), (x0, y0 + hh), (x0 + hw, y0 + hh)];
    quarters
        .iter()
        .zip(origins)
        .map(|(q, (qx, qy))| {
            adaptive_simpson(f, qx, qy, hw, hh, q, 0.5 * tol, depth + 1, max_depth)
        })
        .sum()
}

/// A regular grid of `nx × ny` cells over the rectangle `[x0, x1) × [y0, y1)`. Cell `(ix, iy)`
/// has index `iy · nx + ix`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid2D {
    x: (f64, f64),
    y: (f64, f64),
    nx: usize,
    ny: usize,
}

impl Grid2D {
    /// A grid over `[x.0, x.1) × [y.0, y.1)`. `None` if a count is zero or a range is empty or
    /// not finite.
    pub fn new(x: (f64, f64), nx: usize, y: (f64, f64), ny: usize) -> Option<Self> {
        let ok = |r: (f64, f64)| r.0.is_finite() && r.1.is_finite() && r.0 < r.1;
        (nx > 0 && ny > 0 && ok(x) && ok(y)).then_some(Self { x, y, nx, ny })
    }

    /// The unit square `[0, 1)²` with `nx × ny` cells (`None` if a count is zero).
    pub fn unit_square(nx: usize, ny: usize) -> Option<Self> {
        Self::new((0.0, 1.0), nx, (0.0, 1.0), ny)
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// Always false: a grid has at least one cell.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Cells per axis `(nx, ny)`.
    pub fn size(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// The cell containing `(x, y)`, or `None` if the point is outside `[x0, x1) × [y0, y1)` or
    /// not finite.
    #[inline]
    pub fn bin(&self, x: f64, y: f64) -> Option<usize> {
        let ix = Self::axis_bin(x, self.x, self.nx)?;
        let iy = Self::axis_bin(y, self.y, self.ny)?;
        Some(iy * self.nx + ix)
    }

    #[inline]
    fn axis_bin(v: f64, range: (f64, f64), n: usize) -> Option<usize> {
        if !(range.0..range.1).contains(&v) {
            return None;
        }
        let t = (v - range.0) / (range.1 - range.0) * n as f64;
        Some((t as usize).min(n - 1))
    }

    /// The bounds `((x_lo, x_hi), (y_lo, y_hi))` of cell `cell` (`None` if out of range).
    pub fn cell_bounds(&self, cell: usize) -> Option<((f64, f64), (f64, f64))> {
        if cell >= self.len() {
            return None;
        }
        let (ix, iy) = (cell % self.nx, cell / self.nx);
        let edge = |r: (f64, f64), n: usize, i: usize| r.0 + (r.1 - r.0) * i as f64 / n as f64;
        Some((
            (edge(self.x, self.nx, ix), edge(self.x, self.nx, ix + 1)),
            (edge(self.y, self.ny, iy), edge(self.y, self.ny, iy + 1)),
        ))
    }

    /// `∫ density` over every cell (see [`Quadrature`] for the rule and its accuracy). For a
    /// probability density these are the cell probabilities; multiplied by the sample count they
    /// are the expected counts.
    pub fn integrate<F: Fn(f64, f64) -> f64>(&self, density: F, quad: &Quadrature) -> Vec<f64> {
        (0..self.len())
            .map(|cell| {
                let ((x0, x1), (y0, y1)) = self.cell_bounds(cell).expect("cell index in range");
                integrate_rect(&density, (x0, x1), (y0, y1), quad)
            })
            .collect()
    }
}

/// How far inside a cell, relative to its width, the quadrature evaluates points on its boundary.
const EDGE_NUDGE: f64 = 1e-7;

/// Adaptive Simpson over one rectangle split into `quad.subdivisions²` sub-cells.
fn integrate_rect<F: Fn(f64, f64) -> f64>(
    f: &F,
    x: (f64, f64),
    y: (f64, f64),
    quad: &Quadrature,
) -> f64 {
    // Points on the cell's boundary are evaluated a hair inside it, so that a discontinuity lying
    // exactly on a cell boundary (the horizon of a hemisphere) is attributed to the right cell.
    let (ex, ey) = (EDGE_NUDGE * (x.1 - x.0), EDGE_NUDGE * (y.1 - y.0));
    let f = &|px: f64, py: f64| f(px.clamp(x.0 + ex, x.1 - ex), py.clamp(y.0 + ey, y.1 - ey));
    let s = quad.subdivisions.max(1);
    let (w, h) = ((x.1 - x.0) / s as f64, (y.1 - y.0) / s as f64);
    // Values on the (2s + 1)² lattice shared by neighbouring sub-cells.
    let m = 2 * s + 1;
    let mut lattice = vec![0.0f64; m * m];
    for ix in 0..m {
        for iy in 0..m {
            let px = if ix == m - 1 {
                x.1
            } else {
                x.0 + 0.5 * w * ix as f64
            };
            let py = if iy == m - 1 {
                y.1
            } else {
                y.0 + 0.5 * h * iy as f64
            };
            lattice[ix * m + iy] = f(px, py);
        }
    }
    let tol = quad.tolerance / (s * s) as f64;
    let mut total = 0.0;
    for sx in 0..s {
        for sy in 0..s {
            let mut v = [[0.0f64; 3]; 3];
            for (ix, row) in v.iter_mut().enumerate() {
                for (iy, value) in row.iter_mut().enumerate() {
                    *value = lattice[(2 * sx + ix) * m + 2 * sy + iy];
                }
            }
            let (x0, y0) = (x.0 + w * sx as f64, y.0 + h * sy as f64);
            total += adaptive_simpson(f, x0, y0, w, h, &v, tol, 0, quad.max_depth);
        }
    }
    total
}

/// A grid over the unit sphere of directions in `(cos θ, φ)`: `cos θ = z ∈ [−1, 1]` in equal
/// steps and `φ = atan2(y, x) ∈ [0, 2π)` in equal steps. Since `dω = d(cos θ) dφ`, every cell
/// has the same solid angle `4π / len()`, and a density per unit solid angle is also the density
/// over `(cos θ, φ)`, so cells are integrated without a Jacobian.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereGrid {
    grid: Grid2D,
}

impl Default for SphereGrid {
    /// 10 `cos θ` bins × 20 `φ` bins over the whole sphere.
    fn default() -> Self {
        Self::new(10, 20).expect("non-zero bin counts")
    }
}

impl SphereGrid {
    /// Directions whose length differs from 1 by more than this are rejected by
    /// [`SphereGrid::bin`]: a sampler of directions must return unit vectors.
    pub const UNIT_TOLERANCE: f32 = 1e-3;

    /// `cos_theta_bins × phi_bins` cells (`None` if a count is zero).
    pub fn new(cos_theta_bins: usize, phi_bins: usize) -> Option<Self> {
        Grid2D::new((-1.0, 1.0), cos_theta_bins, (0.0, 2.0 * PI), phi_bins)
            .map(|grid| Self { grid })
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.grid.len()
    }

    /// Always false: a grid has at least one cell.
    pub fn is_empty(&self) -> bool {
        self.grid.is_empty()
    }

    /// The underlying grid over `(cos θ, φ)`: cell `iφ · cos_theta_bins + i_cosθ`.
    pub fn grid(&self) -> &Grid2D {
        &self.grid
    }

    /// The unit direction with `cos θ = z` and azimuth `phi`.
    #[inline]
    pub fn direction(z: f64, phi: f64) -> Vec3 {
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (s, c) = phi.sin_cos();
        Vec3::new((r * c) as f32, (r * s) as f32, z as f32)
    }

    /// The cell of unit direction `w`; `None` if `w` is not finite or its length differs from 1
    /// by more than [`SphereGrid::UNIT_TOLERANCE`].
    #[inline]
    pub fn bin(&self, w: Vec3) -> Option<usize> {
        let len = w.length();
        if !len.is_finite() || (len - 1.0).abs() > Self::UNIT_TOLERANCE {
            return None;
        }
        let (x, y, z) = (w.x as f64, w.y as f64, w.z as f64);
        let z = (z / len as f64).clamp(-1.0, 1.0);
        let mut phi = y.atan2(x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        // Keep z = 1 and φ = 2π (rounding) in the last cells.
        let z = z.min(1.0 - f64::EPSILON);
        let phi = phi.min(2.0 * PI * (1.0 - f64::EPSILON));
        self.grid.bin(z, phi)
    }

    /// `∫ pdf_sa dω` over every cell, for a density per unit solid angle (see [`Quadrature`]).
    /// The sum over all cells is the integral over the sphere.
    pub fn integrate<F: Fn(Vec3) -> f64>(&self, pdf_sa: F, quad: &Quadrature) -> Vec<f64> {
        self.grid
            .integrate(|z, phi| pdf_sa(Self::direction(z, phi)), quad)
    }
}

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

    #[test]
    fn chi2_test_exact_fit_and_pooling() {
        let outcome = chi2_test(
            &[100, 200, 300, 2, 1, 0],
            &[100.0, 200.0, 300.0, 2.0, 1.0, 0.0],
        )
        .unwrap();
        // The pooled cell (3 expected, 3 observed) is below the threshold and merged into the
        // 100-cell; every cell fits exactly.
        assert_eq!(outcome.statistic, 0.0);
        assert_eq!(outcome.dof, 2);
        assert_eq!(outcome.pooled_cells, 2);
        assert_eq!(outcome.empty_cells, 1);
        assert_eq!(outcome.p_value, 1.0);
        // A pool reaching the threshold is a cell of its own.
        let outcome = chi2_test(&[50, 50, 9, 0], &[50.0, 50.0, 4.0, 4.0]).unwrap();
        assert_eq!(outcome.dof, 2);
        assert!((outcome.statistic - 1.0 / 8.0).abs() < 1e-12);
    }

    #[test]
    fn chi2_test_statistic_by_hand() {
        let outcome = chi2_test(&[10, 30, 60], &[20.0, 30.0, 50.0]).unwrap();
        assert!((outcome.statistic - (5.0 + 0.0 + 2.0)).abs() < 1e-12);
        assert_eq!(outcome.dof, 2);
        assert!((outcome.p_value - (-3.5f64).exp()).abs() < 1e-12);
        let worst = outcome.worst.unwrap();
        assert_eq!((worst.bin, worst.observed), (0, 10));
    }

    #[test]
    fn chi2_test_failures() {
        assert_eq!(
            chi2_test(&[5, 1, 0, 2], &[8.0, 0.0, 0.0, 0.0]),
            Err(Chi2Error::SampleInZeroBin {
                bin: 1,
                observed: 3
            })
        );
        assert!(matches!(
            chi2_test(&[5, 5], &[5.0, f64::NAN]),
            Err(Chi2Error::InvalidExpected { bin: 1, .. })
        ));
        assert!(matches!(
            chi2_test(&[5, 5], &[-1.0, 11.0]),
            Err(Chi2Error::InvalidExpected { bin: 0, .. })
        ));
        assert!(matches!(
            chi2_test(&[5], &[5.0, 5.0]),
            Err(Chi2Error::LengthMismatch { .. })
        ));
        assert_eq!(
            chi2_test(&[100, 1], &[100.0, 1.0]),
            Err(Chi2Error::TooFewCells { cells: 1 })
        );
    }

    #[test]
    fn histogram_counts_everything() {
        let mut h = Histogram::new(3);
        for _ in 0..40 {
            h.record(Some(0));
        }
        for _ in 0..60 {
            h.record(Some(2));
        }
        for _ in 0..100 {
            h.record_remainder();
        }
        assert_eq!(h.total(), 200);
        let outcome = h.chi2(&[0.2, 0.0, 0.3]).unwrap();
        assert_eq!(outcome.statistic, 0.0);
        assert_eq!(outcome.dof, 2);
        // A density that claims all the mass leaves nothing for the remainder.
        assert!(matches!(
            h.chi2(&[0.4, 0.0, 0.6]),
            Err(Chi2Error::SampleInZeroBin {
                bin: 3,
                observed: 100
            })
        ));
        h.record(None);
        h.record(Some(7));
        assert_eq!(h.outside(), 2);
        assert_eq!(
            h.chi2(&[0.2, 0.0, 0.3]),
            Err(Chi2Error::OutsideDomain { observed: 2 })
        );
    }

    #[test]
    fn grid_binning() {
        let g = Grid2D::new((-1.0, 3.0), 4, (0.0, 1.0), 2).unwrap();
        assert_eq!(g.bin(-1.0, 0.0), Some(0));
        assert_eq!(g.bin(2.999, 0.99), Some(7));
        assert_eq!(g.bin(0.5, 0.5), Some(5));
        assert_eq!(g.bin(3.0, 0.5), None);
        assert_eq!(g.bin(0.0, f64::NAN), None);
        assert_eq!(g.cell_bounds(5), Some(((0.0, 1.0), (0.5, 1.0))));
        assert!(Grid2D::new((0.0, 0.0), 1, (0.0, 1.0), 1).is_none());
        assert!(Grid2D::unit_square(0, 3).is_none());

        let s = SphereGrid::default();
        assert_eq!(s.len(), 200);
        assert_eq!(s.bin(Vec3::Z), Some(9));
        assert_eq!(s.bin(Vec3::new(0.0, 0.0, -1.0)), Some(0));
        assert_eq!(s.bin(Vec3::new(0.0, -1.0, 0.0)), Some(15 * 10 + 5));
        assert_eq!(
            s.bin(Vec3::new(1.0, -1e-7, 0.0).normalize()),
            Some(19 * 10 + 5)
        );
        assert_eq!(s.bin(Vec3::new(0.0, 0.0, 1.1)), None);
        assert_eq!(s.bin(Vec3::NAN), None);
        for cell in 0..s.len() {
            let ((z0, z1), (p0, p1)) = s.grid().cell_bounds(cell).unwrap();
            let w = SphereGrid::direction(0.5 * (z0 + z1), 0.5 * (p0 + p1));
            assert_eq!(s.bin(w), Some(cell));
        }
    }

    /// Smooth densities are integrated to rounding; each cell has solid angle 4π / 200.
    #[test]
    fn integrate_smooth_densities() {
        let s = SphereGrid::default();
        let q = Quadrature::default();
        let uniform = s.integrate(|_| 0.25 / PI, &q);
        for p in &uniform {
            assert!((p - 1.0 / 200.0).abs() < 1e-12);
        }
        // ∫ z² dω over a cell = Δφ (z1³ − z0³) / 3: cubic in z, exact for Simpson.
        let quad = s.integrate(|w| (w.z as f64).powi(2), &q);
        for (cell, got) in quad.iter().enumerate() {
            let ((z0, z1), (p0, p1)) = s.grid().cell_bounds(cell).unwrap();
            let want = (p1 - p0) * (z1.powi(3) - z0.powi(3)) / 3.0;
            assert!(
                (got - want).abs() < 1e-7 * want.max(1e-3),
                "cell {cell}: {got} vs {want}"
            );
        }
        // A smooth non-polynomial lobe: e^(κ (w·a) − κ) κ / (2π (1 − e^(−2κ))) integrates to 1.
        let a = Vec3::new(0.3, -0.5, 0.81).normalize();
        let kappa = 6.0f64;
        let norm = kappa / (2.0 * PI * (1.0 - (-2.0 * kappa).exp()));
        let vmf = s.integrate(|w| norm * (kappa * (w.dot(a) as f64 - 1.0)).exp(), &q);
        let total: f64 = vmf.iter().sum();
        assert!((total - 1.0).abs() < 1e-6, "{total}");
    }

    /// A density with a discontinuity: the indicator of a cone around +z, whose cell integrals
    /// are known exactly; cells cut by the edge are within 1e-4 of their mass.
    #[test]
    fn integrate_discontinuous_density() {
        let s = SphereGrid::default();
        for cos_max in [0.83f64, 0.3, -0.55] {
            let pdf = 1.0 / (2.0 * PI * (1.0 - cos_max));
            let got = s.integrate(
                |w| if w.z as f64 >= cos_max { pdf } else { 0.0 },
                &Quadrature::default(),
            );
            for (cell, p) in got.iter().enumerate() {
                let ((z0, z1), (p0, p1)) = s.grid().cell_bounds(cell).unwrap();
                let overlap = (z1.min(1.0) - z0.max(cos_max)).max(0.0);
                let want = pdf * overlap * (p1 - p0);
                assert!(
                    (p - want).abs() <= 1e-4 * want + 1e-9,
                    "cos_max {cos_max}, cell {cell}: {p} vs {want}"
                );
            }
        }
        // An off-axis cap: the total is its probability, 1.
        let axis = Vec3::new(0.6, 0.0, 0.8);
        let cos_max = 0.9f64;
        let pdf = 1.0 / (2.0 * PI * (1.0 - cos_max));
        let got = s.integrate(
            |w| {
                if w.dot(axis) as f64 >= cos_max {
                    pdf
                } else {
                    0.0
                }
            },
            &Quadrature::default(),
        );
        let total: f64 = got.iter().sum();
        assert!((total - 1.0).abs() < 1e-4, "{total}");
    }
}
