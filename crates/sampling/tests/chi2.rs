//! Chi-square goodness-of-fit tests of every warp and distribution against the density it claims
//! (`restir_testkit`, after Mitsuba 3's chi-square test).
//!
//! Each test draws samples from a fixed seed, bins them, integrates the claimed pdf/pmf over the
//! same cells and runs Pearson's test. A test fails when its p-value is below
//! `sidak_level(0.01, CHI2_TESTS)` (Šidák correction over the tests of this file: a correct
//! sampler fails any of them with probability 1 %), or immediately when a sample lands where the
//! density is zero. The negative controls at the end feed the same machinery a wrong density and
//! must be rejected with p < 1e-6, so a pass above means something.

use glam::{Vec2, Vec3};
use restir_sampling::{AliasTable, Distribution1D, Distribution2D, Pcg32, warp};
use restir_testkit::{
    Chi2Error, Chi2Outcome, Grid2D, Histogram, Quadrature, SphereGrid, sidak_level,
};

/// Number of chi-square hypothesis tests in this file (negative controls excluded), for the
/// Šidák correction.
const CHI2_TESTS: usize = 14;

/// p-values below this reject a test.
fn level() -> f64 {
    sidak_level(0.01, CHI2_TESTS)
}

/// Negative controls must reach at least this.
const CONTROL_P: f64 = 1e-6;

fn assert_accepted(what: &str, outcome: Result<Chi2Outcome, Chi2Error>) {
    match outcome {
        Ok(o) => {
            eprintln!("{what}: {o}");
            assert!(
                o.accepts(level()),
                "{what}: rejected at level {:.2e}: {o}",
                level()
            );
        }
        Err(e) => panic!("{what}: {e}"),
    }
}

fn assert_rejected(what: &str, outcome: Result<Chi2Outcome, Chi2Error>) {
    let o = outcome.unwrap_or_else(|e| panic!("{what}: expected a p-value, got {e}"));
    eprintln!("{what}: {o}");
    assert!(o.p_value < CONTROL_P, "{what}: a wrong density passed: {o}");
}

/// Histogram of `n` directions from `sample` on `grid`.
fn direction_histogram(
    grid: &SphereGrid,
    seed: u64,
    n: usize,
    sample: impl Fn(Vec2) -> Vec3,
) -> Histogram {
    let mut rng = Pcg32::new(seed, 0);
    let mut hist = Histogram::new(grid.len());
    for _ in 0..n {
        hist.record(grid.bin(sample(rng.next_2d())));
    }
    hist
}

fn hemisphere_pdf(w: Vec3) -> f64 {
    if w.z >= 0.0 {
        warp::UNIFORM_HEMISPHERE_PDF as f64
    } else {
        0.0
    }
}

// ------------------------------------------------------------------------------------------
// Warps to directions
// ------------------------------------------------------------------------------------------

#[test]
fn cosine_hemisphere() {
    let grid = SphereGrid::default();
    let hist = direction_histogram(&grid, 1, 1_000_000, warp::sample_cosine_hemisphere);
    let p = grid.integrate(
        |w| warp::cosine_hemisphere_pdf(w.z) as f64,
        &Quadrature::default(),
    );
    assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-6);
    assert_accepted("cosine hemisphere", hist.chi2(&p));
}

#[test]
fn uniform_sphere() {
    let grid = SphereGrid::default();
    let hist = direction_histogram(&grid, 2, 1_000_000, warp::sample_uniform_sphere);
    let p = grid.integrate(|_| warp::UNIFORM_SPHERE_PDF as f64, &Quadrature::default());
    assert_accepted("uniform sphere", hist.chi2(&p));
}

#[test]
fn uniform_hemisphere() {
    let grid = SphereGrid::default();
    let hist = direction_histogram(&grid, 3, 1_000_000, warp::sample_uniform_hemisphere);
    let p = grid.integrate(hemisphere_pdf, &Quadrature::default());
    assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-6);
    assert_accepted("uniform hemisphere", hist.chi2(&p));
}

/// Cones narrower and wider than a hemisphere; the edges fall inside grid cells.
#[test]
fn uniform_cone() {
    let grid = SphereGrid::default();
    for (k, cos_max) in [0.75f32, 0.1, -0.65].into_iter().enumerate() {
        let hist = direction_histogram(&grid, 4 + k as u64, 1_000_000, |u| {
            warp::sample_uniform_cone(u, cos_max)
        });
        let pdf = warp::uniform_cone_pdf(cos_max) as f64;
        let p = grid.integrate(
            |w| if w.z >= cos_max { pdf } else { 0.0 },
            &Quadrature::default(),
        );
        assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-4);
        assert_accepted(&format!("uniform cone, cos_max {cos_max}"), hist.chi2(&p));
    }
}

// ------------------------------------------------------------------------------------------
// Triangle
// ------------------------------------------------------------------------------------------

/// Barycentrics `(b1, b2)` are uniform on the triangle `b1, b2 ≥ 0, b1 + b2 ≤ 1`: density 2 per
/// unit `(b1, b2)` area, binned on a 20 × 20 grid over the unit square.
#[test]
fn uniform_triangle() {
    let grid = Grid2D::unit_square(20, 20).unwrap();
    let mut rng = Pcg32::new(7, 0);
    let mut hist = Histogram::new(grid.len());
    for _ in 0..1_000_000 {
        let b = warp::sample_uniform_triangle(rng.next_2d());
        hist.record(grid.bin(b.x as f64, b.y as f64));
    }
    let p = grid.integrate(
        |b1, b2| if b1 + b2 <= 1.0 { 2.0 } else { 0.0 },
        &Quadrature::default(),
    );
    assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-4);
    assert_accepted("uniform triangle", hist.chi2(&p));
}

// ------------------------------------------------------------------------------------------
// Distributions
// ------------------------------------------------------------------------------------------

/// Bin values with zeros (including at both ends), a tiny bin and a dominant one.
const STEPS: [f32; 13] = [
    0.0, 0.5, 0.0, 3.0, 1e-3, 7.0, 0.0, 0.0, 0.25, 2.0, 0.125, 4.5, 0.0,
];

#[test]
fn distribution1d_discrete() {
    let d = Distribution1D::new(&STEPS).unwrap();
    let mut rng = Pcg32::new(8, 0);
    let mut hist = Histogram::new(d.len());
    for _ in 0..1_000_000 {
        let (i, pmf, rem) = d.sample_discrete(rng.next_f32());
        assert_eq!(pmf, d.pmf(i));
        assert!((0.0..1.0).contains(&rem));
        hist.record(Some(i));
    }
    let p: Vec<f64> = (0..d.len()).map(|i| d.pmf(i) as f64).collect();
    assert_accepted("Distribution1D::sample_discrete", hist.chi2(&p));
}

/// The continuous samples on a 64-cell grid that does not line up with the 13 steps, so that the
/// position within a step is tested too.
#[test]
fn distribution1d_continuous() {
    let d = Distribution1D::new(&STEPS).unwrap();
    let grid = Grid2D::unit_square(64, 1).unwrap();
    let mut rng = Pcg32::new(9, 0);
    let mut hist = Histogram::new(grid.len());
    for _ in 0..1_000_000 {
        let (x, pdf, _) = d.sample_continuous(rng.next_f32());
        assert!(
            (pdf - d.pdf(x)).abs() <= 1e-5 * pdf,
            "x {x}: {pdf} vs {}",
            d.pdf(x)
        );
        hist.record(grid.bin(x as f64, 0.5));
    }
    let p = grid.integrate(|x, _| d.pdf(x as f32) as f64, &Quadrature::default());
    assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-4);
    assert_accepted("Distribution1D::sample_continuous", hist.chi2(&p));
}

/// A 7 × 5 grid with zero cells and an all-zero row, sampled on a 25 × 17 histogram that does not
/// line up with it.
#[test]
fn distribution2d() {
    let (w, h) = (7usize, 5usize);
    let values: Vec<f32> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if y == 2 || (x + y) % 4 == 0 {
                0.0
            } else {
                (1 + (x * 3 + y * 5) % 7) as f32 * if x == 6 { 10.0 } else { 1.0 }
            }
        })
        .collect();
    let d = Distribution2D::new(&values, w, h).unwrap();
    let grid = Grid2D::unit_square(25, 17).unwrap();
    let mut rng = Pcg32::new(10, 0);
    let mut hist = Histogram::new(grid.len());
    for _ in 0..1_000_000 {
        let (p, pdf) = d.sample(rng.next_2d());
        assert!(
            (pdf - d.pdf(p)).abs() <= 1e-4 * pdf,
            "{p}: {pdf} vs {}",
            d.pdf(p)
        );
        hist.record(grid.bin(p.x as f64, p.y as f64));
    }
    let p = grid.integrate(
        |x, y| d.pdf(Vec2::new(x as f32, y as f32)) as f64,
        &Quadrature::default(),
    );
    assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-4);
    assert_accepted("Distribution2D::sample", hist.chi2(&p));
}

fn alias_test(what: &str, weights: &[f32], seed: u64, n: usize) {
    let table = AliasTable::new(weights).unwrap();
    let mut rng = Pcg32::new(seed, 0);
    let mut hist = Histogram::new(table.len());
    for _ in 0..n {
        let (i, pmf, rem) = table.sample(rng.next_f32());
        assert_eq!(pmf, table.pmf(i));
        assert!((0.0..1.0).contains(&rem));
        hist.record(Some(i));
    }
    // The pmf is the normalised weight; a zero weight has pmf 0, so a single sample of it fails.
    let sum: f64 = weights.iter().map(|&w| w as f64).sum();
    let p: Vec<f64> = (0..table.len()).map(|i| table.pmf(i) as f64).collect();
    for (i, (&w, &pi)) in weights.iter().zip(&p).enumerate() {
        assert!(
            (pi - w as f64 / sum).abs() <= 1e-6 * pi + 1e-12,
            "{what}: pmf({i})"
        );
    }
    assert_accepted(what, hist.chi2(&p));
}

#[test]
fn alias_table_zero_weights() {
    alias_test(
        "alias table with zero weights",
        &[0.0, 1.0, 0.0, 0.0, 3.0, 0.5, 0.0, 2.0, 0.0],
        11,
        1_000_000,
    );
}

/// One weight 10⁵ times the others, a thousand small ones, a tiny one and zeros.
#[test]
fn alias_table_skewed_weights() {
    let mut weights = vec![1.0f32; 1000];
    weights[17] = 1e5;
    weights[500] = 1e-4;
    weights[3] = 0.0;
    weights[999] = 0.0;
    weights[640] = 250.0;
    alias_test("alias table with skewed weights", &weights, 12, 2_000_000);
}

#[test]
fn alias_table_two_extremes() {
    alias_test(
        "alias table [1e5, 1, 0, 1]",
        &[1e5, 1.0, 0.0, 1.0],
        13,
        2_000_000,
    );
}

// ------------------------------------------------------------------------------------------
// Negative controls: wrong densities must be rejected
// ------------------------------------------------------------------------------------------

/// Cosine-weighted samples tested against the uniform-hemisphere pdf.
#[test]
fn control_cosine_samples_vs_uniform_pdf() {
    let grid = SphereGrid::default();
    let hist = direction_histogram(&grid, 1, 1_000_000, warp::sample_cosine_hemisphere);
    let p = grid.integrate(hemisphere_pdf, &Quadrature::default());
    assert_rejected("cosine samples vs uniform hemisphere pdf", hist.chi2(&p));
}

/// A subtle error: cone samples with `cos θmax = 0.75` against the pdf of a cone with 0.76
/// (4 % of the mass in the wrong place).
#[test]
fn control_cone_with_wrong_angle() {
    let grid = SphereGrid::default();
    let hist = direction_histogram(&grid, 4, 1_000_000, |u| warp::sample_uniform_cone(u, 0.75));
    let pdf = warp::uniform_cone_pdf(0.76) as f64;
    let p = grid.integrate(
        |w| if w.z >= 0.76 { pdf } else { 0.0 },
        &Quadrature::default(),
    );
    assert_rejected("cone 0.75 vs pdf of cone 0.76", hist.chi2(&p));
}

/// Alias-table samples against a pmf with two entries swapped.
#[test]
fn control_alias_swapped_pmf() {
    let weights = [0.0f32, 1.0, 0.0, 0.0, 3.0, 0.5, 0.0, 2.0, 0.0];
    let table = AliasTable::new(&weights).unwrap();
    let mut rng = Pcg32::new(11, 0);
    let mut hist = Histogram::new(table.len());
    for _ in 0..100_000 {
        hist.record(Some(table.sample(rng.next_f32()).0));
    }
    let mut p: Vec<f64> = (0..table.len()).map(|i| table.pmf(i) as f64).collect();
    p.swap(5, 7);
    assert_rejected("alias samples vs swapped pmf", hist.chi2(&p));
}

/// A sample where the density is zero is an immediate failure: uniform-sphere samples against
/// the hemisphere pdf.
#[test]
fn control_sample_where_pdf_is_zero() {
    let grid = SphereGrid::default();
    let hist = direction_histogram(&grid, 2, 10_000, warp::sample_uniform_sphere);
    let p = grid.integrate(hemisphere_pdf, &Quadrature::default());
    assert!(matches!(
        hist.chi2(&p),
        Err(Chi2Error::SampleInZeroBin { .. })
    ));
}

/// The chi-square recipe end to end on the cosine-weighted hemisphere (formerly the example of
/// `restir_sampling::stats`, whose code now lives in `restir_testkit`): accepted against its own
/// density at the single-test level, rejected against the uniform hemisphere.
#[test]
fn recipe_example_cosine_hemisphere() {
    let grid = SphereGrid::default(); // 10 cos θ bins × 20 φ bins over the whole sphere
    let mut hist = Histogram::new(grid.len());
    let mut rng = Pcg32::new(1, 0);
    for _ in 0..20_000 {
        hist.record(grid.bin(warp::sample_cosine_hemisphere(rng.next_2d())));
    }
    let probabilities = grid.integrate(
        |w| warp::cosine_hemisphere_pdf(w.z) as f64,
        &Quadrature::default(),
    );
    let outcome = hist.chi2(&probabilities).unwrap();
    assert!(outcome.p_value >= sidak_level(0.01, 1), "{outcome}");

    // The same samples against the wrong density are rejected.
    let wrong = grid.integrate(
        |w| {
            if w.z >= 0.0 {
                warp::UNIFORM_HEMISPHERE_PDF as f64
            } else {
                0.0
            }
        },
        &Quadrature::default(),
    );
    assert!(hist.chi2(&wrong).unwrap().p_value < 1e-6);
}
