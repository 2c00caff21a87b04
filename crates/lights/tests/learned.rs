//! The learned light selection (`LearnedSampler`), over emitters (here one per light: spheres,
//! a point and a directional light, the environment last):
//!
//! - at receivers in cells with records, in a cell without records and where nothing was
//!   recorded at all, its picks follow `pmf` (chi-square over every light), and the probability
//!   it reports with a pick is `pmf`'s bit for bit;
//! - `pmf` sums to 1 and is positive for every light with power (the defensive share), also for
//!   lights the cell never recorded;
//! - the same records added in the same order give the same sampler bits;
//! - the negative control: the picks tested against the cell's table alone (the mixture's pmf
//!   without its defensive share) are rejected.
//!
//! The scene: 40 emissive spheres of powers over two decades, a point light, a directional
//! light and a constant environment, so every kind of light takes part.

use std::sync::Arc;

use glam::Vec3;
use restir_geometry::{Shape, Sphere};
use restir_lights::{LearnGrid, LearnedSampler, Light, LightRecords, LightSet};
use restir_sampling::Pcg32;
use restir_testkit::{Histogram, sidak_level};

fn scene() -> LightSet {
    let mut rng = Pcg32::new(3, 5);
    let mut shapes = Vec::new();
    let mut lights = Vec::new();
    for i in 0..40 {
        let c = Vec3::new(
            8.0 * rng.next_f32() - 4.0,
            8.0 * rng.next_f32() - 4.0,
            1.0 + 2.0 * rng.next_f32(),
        );
        shapes.push(Shape::Sphere(Sphere::new(c, 0.1, false)));
        lights.push(Light::Area {
            shape: i,
            radiance: Vec3::splat(10f32.powf(2.0 * rng.next_f32())),
            texture: None,
        });
    }
    lights.push(Light::Point {
        position: Vec3::new(0.5, -1.0, 2.0),
        intensity: Vec3::splat(4.0),
    });
    lights.push(Light::Directional {
        direction: Vec3::new(0.2, 0.1, -1.0),
        irradiance: Vec3::splat(0.05),
    });
    lights.push(Light::Constant {
        radiance: Vec3::splat(0.02),
    });
    LightSet::new(lights, &shapes[..], (Vec3::splat(-5.0), Vec3::splat(5.0))).unwrap()
}

const GRID: LearnGrid = LearnGrid { cell: 0.5 };

/// Receivers: (point, normal). The first two share a cell with records, the third is in a cell
/// with other records, the last in a cell without any.
const RECEIVERS: [(Vec3, Vec3); 4] = [
    (Vec3::new(0.1, 0.1, 0.0), Vec3::Z),
    (Vec3::new(0.4, 0.2, 0.1), Vec3::new(0.1, 0.2, 0.9)),
    (Vec3::new(2.2, -1.3, 0.0), Vec3::X),
    (Vec3::new(-3.0, 3.0, 0.0), Vec3::Z),
];

/// Records as passes would leave them: a few lights per cell, with skewed values, one of them
/// far more than the rest (as a nearby bright light would be).
fn records(seed: u64) -> LightRecords {
    let mut rng = Pcg32::new(seed, 0);
    let mut r = LightRecords::default();
    for _ in 0..500 {
        let light = (rng.next_u32() % 12) * 3; // only some lights recorded
        r.add(
            GRID.key(RECEIVERS[0].0, RECEIVERS[0].1),
            light,
            rng.next_f32() * (light as f32 + 1.0),
        );
    }
    for _ in 0..50 {
        let light = 40 + rng.next_u32() % 3; // point, directional, environment
        r.add(
            GRID.key(RECEIVERS[2].0, RECEIVERS[2].1),
            light,
            rng.next_f32(),
        );
    }
    r.add(GRID.key(RECEIVERS[2].0, RECEIVERS[2].1), 7, 30.0);
    r
}

const SAMPLES: usize = 400_000;

fn histogram(learned: &LearnedSampler, set: &LightSet, cell: Option<u32>, seed: u64) -> Histogram {
    let mut rng = Pcg32::new(seed, 1);
    let mut hist = Histogram::new(set.emitters_with_environment());
    for _ in 0..SAMPLES {
        let (e, pmf) = learned.sample(set, cell, rng.next_f32()).unwrap();
        assert_eq!(pmf, learned.pmf(set, cell, e), "emitter {e}");
        assert!(pmf > 0.0);
        hist.record(Some(e));
    }
    hist
}

/// The sampler of `records` on the test grid, every emitter alone (the scene has no meshes).
fn sampler(set: &LightSet, records: &LightRecords) -> LearnedSampler {
    LearnedSampler::new(GRID, 0.5, 16.0, records, Arc::new(set.emitter_groups(0.0)))
}

#[test]
fn picks_follow_the_pmf_and_keep_every_light() {
    let set = scene();
    let learned = sampler(&set, &records(1));
    assert_eq!(learned.cells(), 2);
    let empty = sampler(&set, &LightRecords::default());
    let level = sidak_level(0.01, RECEIVERS.len() + 1);
    let mut cases: Vec<(&LearnedSampler, Vec3, Vec3)> =
        RECEIVERS.iter().map(|&(p, n)| (&learned, p, n)).collect();
    cases.push((&empty, RECEIVERS[0].0, RECEIVERS[0].1));
    for (i, (sampler, p, n)) in cases.into_iter().enumerate() {
        let cell = sampler.cell(p, n);
        assert_eq!(cell.is_some(), i < 3, "case {i}");
        let pmf: Vec<f64> = (0..set.emitters_with_environment())
            .map(|e| sampler.pmf(&set, cell, e) as f64)
            .collect();
        assert!((pmf.iter().sum::<f64>() - 1.0).abs() < 1e-4, "case {i}");
        for (l, &q) in pmf.iter().enumerate() {
            // The defensive share: at least half the power sampler's probability.
            assert!(
                q >= 0.5 * set.emitter_pmf(l) as f64 * (1.0 - 1e-5),
                "case {i} light {l}"
            );
        }
        let outcome = histogram(sampler, &set, cell, 200 + i as u64)
            .chi2(&pmf)
            .unwrap();
        eprintln!("case {i}: {outcome}");
        assert!(outcome.accepts(level), "case {i}: {outcome}");
    }
}

#[test]
fn same_records_same_sampler() {
    let set = scene();
    let (a, b) = (sampler(&set, &records(4)), sampler(&set, &records(4)));
    let (p, n) = RECEIVERS[0];
    let (ca, cb) = (a.cell(p, n), b.cell(p, n));
    for l in 0..set.emitters_with_environment() {
        assert_eq!(a.pmf(&set, ca, l).to_bits(), b.pmf(&set, cb, l).to_bits());
    }
}

/// Negative control: the same picks judged by the cell's table alone (the pmf forgetting the
/// power sampler's share) are rejected.
#[test]
fn negative_control_pmf_without_defensive_share_is_rejected() {
    let set = scene();
    let learned = sampler(&set, &records(1));
    let (p, n) = RECEIVERS[0];
    let cell = learned.cell(p, n);
    let wrong: Vec<f64> = (0..set.emitters_with_environment())
        .map(|l| learned.pmf_without_defensive_share(&set, cell, l) as f64)
        .collect();
    let total: f64 = wrong.iter().sum();
    let wrong: Vec<f64> = wrong.iter().map(|q| q / total).collect();
    let outcome = histogram(&learned, &set, cell, 77).chi2(&wrong).unwrap();
    eprintln!("without the defensive share: {outcome}");
    assert!(!outcome.accepts(1e-6), "{outcome}");
}
