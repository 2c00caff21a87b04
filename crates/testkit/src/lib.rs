//! The statistics the `restir` workspace's tests share, kept out of the libraries' public APIs
//! (`publish = false`; every crate takes it as a dev-dependency). It depends on no `restir`
//! crate, so it sits below all of them without a dev-dependency cycle.
//!
//! - [`chi2`], [`grid`], [`special`]: goodness-of-fit tests for samplers (Pearson's chi-square on
//!   histograms, the grids and quadrature that produce them, the survival function that turns the
//!   statistic into a p-value). The recipe is described below.
//! - [`running`]: a small seeded generator ([`SplitMix64`]), a running mean with its standard error
//!   and an unbiasedness check ([`RunningStats`]), a quick fixed-level chi-square check
//!   ([`chi_square`], [`chi_square_critical`]), trial counts that shrink in debug builds
//!   ([`trials`]).
//! - [`corpus`]: the shared scene corpus beside the clone ([`corpus_dir`]) and
//!   [`corpus_test!`](crate::corpus_test), which ignores a test that needs it when it is absent
//!   (outside CI).
//! - [`blocks`]: per-block means of images and their mean and standard error over independent
//!   renders ([`block_statistics`], [`max_z`]), for comparing two estimators of the same image.
//! - [`tempdir`]: a fresh temporary directory per test, removed when dropped ([`TempDir`]).
//! - [`alloc`]: a counting global allocator and [`measure`] for tests of memory ([`CountingAllocator`]).
//! - [`meshes`]: a UV sphere of triangles ([`meshes::uv_sphere`]) for tests of meshes and lights.
//!
//! # Chi-square tests of samplers
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
//! use restir_testkit::{Grid2D, Histogram, Quadrature, SplitMix64, sidak_level};
//!
//! // Samples of the density 2x on [0, 1) (inverse CDF: √u), binned on 16 cells.
//! let grid = Grid2D::new((0.0, 1.0), 16, (0.0, 1.0), 1).unwrap();
//! let mut hist = Histogram::new(grid.len());
//! let mut rng = SplitMix64::new(1);
//! for _ in 0..20_000 {
//!     hist.record(grid.bin(rng.next_f64().sqrt(), 0.5));
//! }
//! let probabilities = grid.integrate(|x, _| 2.0 * x, &Quadrature::default());
//! let outcome = hist.chi2(&probabilities).unwrap();
//! assert!(outcome.p_value >= sidak_level(0.01, 1), "{outcome}");
//!
//! // The same samples against the uniform density are rejected.
//! let wrong = grid.integrate(|_, _| 1.0, &Quadrature::default());
//! assert!(hist.chi2(&wrong).unwrap().p_value < 1e-6);
//! ```
//!
//! The tests of the libraries' samplers (`restir-sampling`, `restir-materials`, `restir-lights`)
//! use exactly this recipe with their own generators.

pub mod alloc;
pub mod blocks;
pub mod chi2;
pub mod corpus;
pub mod grid;
pub mod meshes;
pub mod running;
pub mod special;
pub mod tempdir;

pub use alloc::{CountingAllocator, measure};
pub use blocks::{block_means, block_statistics, max_z};
pub use chi2::{
    Chi2Error, Chi2Outcome, Histogram, POOL_THRESHOLD, WorstCell, chi_square, chi_square_critical,
    chi2_test,
};
pub use corpus::{CORPUS_IGNORE_REASON, corpus_dir};
pub use grid::{Grid2D, Quadrature, SphereGrid};
pub use running::{RunningStats, SplitMix64, trials};
pub use special::{chi2_sf, gamma_p, gamma_q, ln_gamma, sidak_level};
pub use tempdir::TempDir;
