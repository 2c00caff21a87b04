//! Pearson's chi-square test on histograms: [`Histogram`] counts samples per cell,
//! [`chi2_test`] (or [`Histogram::chi2`]) pools sparse cells and turns the statistic into a
//! p-value with [`chi2_sf`].

use crate::special::chi2_sf;

/// Cells with an expected count below this are pooled into one cell (the usual rule of thumb for
/// the chi-square approximation to hold, also Mitsuba's).
pub const POOL_THRESHOLD: f64 = 5.0;

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
    /// [`SphereGrid`](crate::SphereGrid)) not unit length.
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

    /// Counts one sample in `cell`; `None` (what [`Grid2D::bin`](crate::Grid2D::bin) and
    /// [`SphereGrid::bin`](crate::SphereGrid::bin) return for samples they cannot place) or an
    /// out-of-range index counts it as outside.
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
    /// [`Grid2D::integrate`](crate::Grid2D::integrate) or
    /// [`SphereGrid::integrate`](crate::SphereGrid::integrate), or a pmf), with `N =` [`total`]
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
// A quick fixed-level check
// ------------------------------------------------------------------------------------------

/// Upper `p = 1e-4` quantile of χ² with `df` degrees of freedom (Wilson–Hilferty approximation),
/// the bound of the quick check [`chi_square`] (used by the GRIS selection tests).
pub fn chi_square_critical(df: usize) -> f64 {
    let z = 3.719; // standard normal upper 1e-4 quantile
    let k = df as f64;
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

/// Pearson χ² statistic of `counts` against probabilities `probs` over `n` draws, and its degrees
/// of freedom (used cells − 1). Cells with probability 0 must have count 0 (panics otherwise); no
/// pooling: for the full test with p-values see [`chi2_test`].
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
