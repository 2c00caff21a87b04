//! Every [`LightSampler`] draws candidates whose densities are the ones it reports: the
//! importance-sampled estimate `Σ g(x) / source_pdf(x)` of the same integral (the receiver's
//! unoccluded irradiance-like sum `∫ L_e max(0, n·ω) dω` over every light) agrees between the
//! power sampler and each other sampler (|z| < 4, fixed seeds), and the power sampler's
//! solid-angle density it reports with every candidate is the power sampler's own.
//!
//! Negative controls, each rejected (|z| > 8): the hierarchy and a pool of a cut of it
//! claiming the power sampler's density, a pool forgetting a whole light's selection probability, the learned cell forgetting
//! its defensive share, the learned cell in groups claiming the probabilities of single emitters.
//!
//! The scene: 30 emissive spheres over two decades of radiance, two emissive rectangles (mesh
//! triangles), a point light, a directional light and a constant environment.

use std::sync::Arc;

use glam::{Affine3A, Quat, Vec2, Vec3};
use restir_geometry::{Shape, Sphere};
use restir_lights::{
    At, CandidateU, Claim, HierarchySampler, LearnGrid, LearnedCellSampler, LearnedDraw,
    LearnedSampler, Light, LightCandidate, LightRecords, LightSampler, LightSet, PoolSampler,
    PowerSampler, Presampled,
};
use restir_sampling::{ONE_MINUS_EPSILON, Pcg32, luminance};

fn scene() -> LightSet {
    let mut rng = Pcg32::new(11, 5);
    let mut shapes = Vec::new();
    let mut lights = Vec::new();
    for i in 0..30 {
        let c = Vec3::new(
            8.0 * rng.next_f32() - 4.0,
            8.0 * rng.next_f32() - 4.0,
            1.0 + 2.0 * rng.next_f32(),
        );
        shapes.push(Shape::Sphere(Sphere::new(c, 0.15, false)));
        lights.push(Light::Area {
            shape: i,
            radiance: Vec3::splat(10f32.powf(2.0 * rng.next_f32())),
            texture: None,
        });
    }
    for (k, x) in [-2.0f32, 2.5].into_iter().enumerate() {
        let mut quad = Shape::rectangle();
        quad.transform(&Affine3A::from_scale_rotation_translation(
            Vec3::splat(0.5),
            Quat::from_rotation_x(std::f32::consts::PI),
            Vec3::new(x, 0.5, 2.5),
        ));
        shapes.push(Shape::Mesh(quad));
        lights.push(Light::Area {
            shape: 30 + k as u32,
            radiance: Vec3::splat(3.0 + k as f32),
            texture: None,
        });
    }
    lights.push(Light::Point {
        position: Vec3::new(0.5, -1.0, 2.0),
        intensity: Vec3::splat(4.0),
    });
    lights.push(Light::Directional {
        direction: Vec3::new(0.2, 0.1, -1.0),
        irradiance: Vec3::splat(0.5),
    });
    lights.push(Light::Constant {
        radiance: Vec3::splat(0.05),
    });
    LightSet::new(lights, &shapes[..], (Vec3::splat(-5.0), Vec3::splat(5.0))).unwrap()
}

const AT: At = At {
    p: Vec3::new(0.3, -0.2, 0.0),
    n: Vec3::Z,
};

/// The summand of candidate `c`: its emission times the receiver's cosine over its density.
fn g(c: &LightCandidate) -> f64 {
    let cos = AT.n.dot(c.contact.wi).max(0.0);
    (luminance(c.contact.le) * cos * c.contact.measure / c.source_pdf) as f64
}

const RECEIVERS: usize = 40_000;
const CANDIDATES: u32 = 8;

/// Mean and standard error of the per-receiver estimates `(1/N) Σ g` of `sampler`, made anew
/// for each receiver by `make` (so per-pass tables, such as a pool's tile, are redrawn).
fn estimate<S: LightSampler>(
    lights: &LightSet,
    seed: u64,
    mut make: impl FnMut(&mut Pcg32) -> S,
) -> (f64, f64) {
    let mut rng = Pcg32::new(seed, 3);
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..RECEIVERS {
        let mut sampler = make(&mut rng);
        let u0 = rng.next_f32();
        sampler.begin(&mut rng, CANDIDATES);
        let mut est = 0.0;
        for i in 0..CANDIDATES {
            let u = CandidateU::new(i, CANDIDATES, u0, rng.next_2d());
            if let Some(c) = sampler.candidate(lights, AT, &u, &mut rng) {
                assert!(c.source_pdf > 0.0 && c.power_pdf_sa > 0.0);
                est += g(&c);
            }
        }
        est /= CANDIDATES as f64;
        sum += est;
        sum2 += est * est;
    }
    let n = RECEIVERS as f64;
    let mean = sum / n;
    (mean, ((sum2 / n - mean * mean) / (n - 1.0)).sqrt())
}

fn z((a, sa): (f64, f64), (b, sb): (f64, f64)) -> f64 {
    (a - b) / (sa * sa + sb * sb).sqrt()
}

/// A tile of presampled power-sampler draws, stratified as the renderer's pools are.
fn tile(lights: &LightSet, rng: &mut Pcg32) -> Vec<Option<Presampled>> {
    const S: usize = 64;
    let u0 = rng.next_f32();
    (0..S)
        .map(|j| {
            let u = ((j as f32 + u0) / S as f32).min(ONE_MINUS_EPSILON);
            lights.presample(u, rng.next_2d())
        })
        .collect()
}

/// The learned sampler of a cell's records, over emitters grouped within boxes of diagonal
/// `group` ([`LightSet::emitter_groups`]: 0 keeps every emitter alone, 10 makes each
/// rectangle's two triangles one group).
fn learned_sampler(lights: &LightSet, group: f32) -> (LearnedSampler, u32) {
    let grid = LearnGrid { cell: 0.5 };
    let key = grid.key(AT.p, AT.n);
    let mut records = LightRecords::default();
    let mut rng = Pcg32::new(9, 0);
    for _ in 0..400 {
        // Spheres, triangles of both rectangles (30–33), the environment (36).
        let e = (rng.next_u32() % 13) * 3;
        records.add(key, e, rng.next_f32() * (e as f32 + 1.0));
    }
    let sampler = LearnedSampler::new(
        grid,
        0.5,
        16.0,
        &records,
        Arc::new(lights.emitter_groups(group)),
    );
    let cell = sampler.cell(AT.p, AT.n).unwrap();
    assert_eq!(lights.emitters_with_environment(), 37);
    (sampler, cell)
}

/// One pool of `len` presampled draws of `cell`'s mixture per receiver, as a pass makes them
/// (`defensive` false: the negative control's probabilities).
fn cell_pools(
    lights: &LightSet,
    learned: &LearnedSampler,
    cell: u32,
    defensive: bool,
    len: usize,
) -> Vec<Vec<Option<LearnedDraw>>> {
    let mut rng = Pcg32::new(21, 7);
    (0..RECEIVERS)
        .map(|_| {
            let mut pool = vec![None; len];
            learned.presample(lights, cell, defensive, &mut rng, &mut pool);
            pool
        })
        .collect()
}

/// A skewed table over the lights (every third light, growing weights).
/// Per receiver, a pool of draws from a cut of the light hierarchy made for a region around
/// the receiver (as a screen tile's), of `len` entries; `claim_power` weighs them as the power
/// sampler's (the negative control).
fn cut_pools(lights: &LightSet, nodes: usize, claim_power: bool) -> Vec<Vec<Option<LearnedDraw>>> {
    let claim = if claim_power {
        Claim::Power
    } else {
        Claim::Exact
    };
    mixed_pools(lights, nodes, None, claim)
}

/// As [`cut_pools`], the cut mixed with a learned cell's table when `learned` is given.
fn mixed_pools(
    lights: &LightSet,
    nodes: usize,
    learned: Option<(&LearnedSampler, u32)>,
    claim: Claim,
) -> Vec<Vec<Option<LearnedDraw>>> {
    let cut = lights
        .light_cut(AT.p + Vec3::new(0.2, 0.1, 0.0), AT.n, 0.5, nodes, None)
        .unwrap();
    let mut rng = Pcg32::new(23, 7);
    (0..RECEIVERS)
        .map(|_| {
            let mut pool = vec![None; 32];
            lights.presample_cut(&cut, learned, &mut rng, claim, &mut pool);
            pool
        })
        .collect()
}

#[test]
fn every_sampler_estimates_the_same_integral() {
    let lights = scene();
    let power = estimate(&lights, 1, |_| PowerSampler);
    eprintln!("power: {:.6} ± {:.6}", power.0, power.1);
    let (grouped, grouped_cell) = learned_sampler(&lights, 10.0);
    let (learned, cell) = learned_sampler(&lights, 0.0);
    let cut_pool = cut_pools(&lights, 16, false);
    let mixed_pool = mixed_pools(&lights, 16, Some((&learned, cell)), Claim::Exact);
    let mut tiles: Vec<Vec<Option<Presampled>>> = Vec::new();
    let mut rng = Pcg32::new(4, 4);
    for _ in 0..RECEIVERS {
        tiles.push(tile(&lights, &mut rng));
    }
    let mut k = 0;
    let mut next_tile = || {
        k += 1;
        &tiles[k - 1][..]
    };
    let cases: Vec<(&str, (f64, f64))> = vec![
        (
            "hierarchy",
            estimate(&lights, 2, |_| HierarchySampler::default()),
        ),
        (
            "pool",
            estimate(&lights, 3, |_| PoolSampler::new(next_tile())),
        ),
    ];
    let mut k = 0;
    let cut = estimate(&lights, 14, |_| {
        k += 1;
        LearnedCellSampler::new(&cut_pool[k - 1])
    });
    let mut k = 0;
    let mixed = estimate(&lights, 16, |_| {
        k += 1;
        LearnedCellSampler::new(&mixed_pool[k - 1])
    });
    let pools = cell_pools(&lights, &learned, cell, true, 64);
    let mut k = 0;
    let learned_pool = estimate(&lights, 5, |_| {
        k += 1;
        LearnedCellSampler::new(&pools[k - 1])
    });
    // A pool smaller than the candidates: entries are taken more than once.
    let small = cell_pools(&lights, &learned, cell, true, 3);
    let mut k = 0;
    let learned_small = estimate(&lights, 6, |_| {
        k += 1;
        LearnedCellSampler::new(&small[k - 1])
    });
    let grouped_pools = cell_pools(&lights, &grouped, grouped_cell, true, 64);
    let mut k = 0;
    let learned_grouped = estimate(&lights, 7, |_| {
        k += 1;
        LearnedCellSampler::new(&grouped_pools[k - 1])
    });
    for (name, e) in cases.into_iter().chain([
        ("pool of a cut of the hierarchy", cut),
        (
            "pool of a learned table with a cut as its defensive part",
            mixed,
        ),
        ("learned cell pool", learned_pool),
        ("learned cell pool of 3", learned_small),
        (
            "learned cell pool, each rectangle one group",
            learned_grouped,
        ),
    ]) {
        let z = z(e, power);
        eprintln!("{name}: {:.6} ± {:.6}, z {z:.2}", e.0, e.1);
        assert!(z.abs() < 4.0, "{name}: z {z}");
    }
}

#[test]
fn negative_controls_are_rejected() {
    let lights = scene();
    let power = estimate(&lights, 1, |_| PowerSampler);
    let (learned, cell) = learned_sampler(&lights, 0.0);
    let mut rng = Pcg32::new(4, 4);
    let tiles: Vec<_> = (0..RECEIVERS).map(|_| tile(&lights, &mut rng)).collect();
    let forgetful = cell_pools(&lights, &learned, cell, false, 64);
    // Draws of the grouped tables claiming the probabilities of the ungrouped ones (a pmf that
    // forgets the groups).
    let (grouped, grouped_cell) = learned_sampler(&lights, 10.0);
    assert_eq!(grouped_cell, cell);
    let mut ungrouped_claims = cell_pools(&lights, &grouped, cell, true, 64);
    for pool in &mut ungrouped_claims {
        for (draw, ratio) in pool.iter_mut().flatten() {
            if let Presampled::Fixed { point, .. } = draw
                && let Some(e) = lights.emitter_of(point.light, point.prim)
            {
                *ratio = learned.pmf(&lights, Some(cell), e) / lights.emitter_pmf(e);
            }
        }
    }
    let power_claims = cut_pools(&lights, 16, true);
    let table_claims = mixed_pools(&lights, 16, Some((&learned, cell)), Claim::TableAlone);
    let (mut k, mut j, mut i, mut c, mut t) = (0, 0, 0, 0, 0);
    let controls = [
        (
            "learned table over a cut claiming the table alone",
            estimate(&lights, 17, |_| {
                t += 1;
                LearnedCellSampler::new(&table_claims[t - 1])
            }),
        ),
        (
            "cut pool claiming the power density",
            estimate(&lights, 15, |_| {
                c += 1;
                LearnedCellSampler::new(&power_claims[c - 1])
            }),
        ),
        (
            "hierarchy claiming the power density",
            estimate(&lights, 2, |_| HierarchySampler {
                claim_power_density: true,
            }),
        ),
        (
            "pool without the selection",
            estimate(&lights, 3, |_| {
                k += 1;
                PoolSampler::without_selection(&tiles[k - 1])
            }),
        ),
        (
            "learned without its defensive share",
            estimate(&lights, 5, |_| {
                j += 1;
                LearnedCellSampler::new(&forgetful[j - 1])
            }),
        ),
        (
            "learned in groups, claiming the ungrouped probabilities",
            estimate(&lights, 7, |_| {
                i += 1;
                LearnedCellSampler::new(&ungrouped_claims[i - 1])
            }),
        ),
    ];
    for (name, e) in controls {
        let z = z(e, power);
        eprintln!("{name}: {:.6} ± {:.6}, z {z:.2}", e.0, e.1);
        assert!(z.abs() > 8.0, "{name}: z {z}");
    }
}

#[test]
fn candidates_carry_the_power_samplers_density() {
    let lights = scene();
    let mut rng = Pcg32::new(8, 1);
    let sampler = HierarchySampler::default();
    let mut checked = 0;
    for i in 0..2000 {
        let u = CandidateU::new(
            i % 8,
            8,
            rng.next_f32(),
            Vec2::new(rng.next_f32(), rng.next_f32()),
        );
        let Some(c) = sampler.candidate(&lights, AT, &u, &mut rng) else {
            continue;
        };
        if c.contact.delta || !c.contact.dist.is_finite() {
            continue;
        }
        let want = lights.pdf_sa(c.point.light, AT.p, c.contact.p, c.contact.ng);
        let rel = (c.power_pdf_sa - want).abs() / want;
        assert!(rel < 1e-3, "candidate {i}: {} vs {want}", c.power_pdf_sa);
        checked += 1;
    }
    assert!(checked > 1000);
}

/// Every emitter's samples name it back: `emitter_of` of a point drawn on emitter `e` is `e`, and
/// the power probabilities of the emitters sum to 1.
#[test]
fn emitters_are_named_back() {
    let lights = scene();
    let mut total = 0.0f64;
    let mut named = 0;
    for e in 0..lights.emitters_with_environment() {
        total += lights.emitter_pmf(e) as f64;
        for k in 0..4 {
            let u = Vec2::new(0.1 + 0.2 * k as f32, 0.7 - 0.15 * k as f32);
            // From above and from below, so one-sided emitters are seen from their front.
            for p in [AT.p, Vec3::new(0.0, 0.0, 9.0)] {
                if let Some((ls, _)) = lights.sample_entry(e, 1.0, p, u) {
                    let point = restir_lights::LightPoint::from_light_sample(&ls);
                    assert_eq!(lights.emitter_of(point.light, point.prim), Some(e));
                    named += 1;
                }
            }
        }
    }
    assert!((total - 1.0).abs() < 1e-5, "{total}");
    assert!(named >= 4 * lights.emitters_with_environment(), "{named}");
}

/// A candidate on a sphere is the point its name resolves to (as reuse and shading evaluate
/// it), so its weight is the same function of its name whichever sampler drew it (the power
/// sampler, the hierarchy, a pool's entry). Receivers
/// beside the spheres see them near their silhouettes, where a rounding of the point changes
/// the cosine at the light most.
#[test]
fn sphere_candidates_are_the_points_their_names_resolve_to() {
    let lights = scene();
    let mut rng = Pcg32::new(21, 4);
    let mut checked = 0;
    for i in 0..4000u32 {
        let at = At {
            p: Vec3::new(8.0 * rng.next_f32() - 4.0, 8.0 * rng.next_f32() - 4.0, 2.0),
            n: Vec3::Z,
        };
        let u = CandidateU::new(i % 8, 8, rng.next_f32(), rng.next_2d());
        let power = PowerSampler.candidate(&lights, at, &u, &mut rng);
        let tree = HierarchySampler::default().candidate(&lights, at, &u, &mut rng);
        // A pool's entry carries its sphere and draws the point from that copy.
        let pooled = lights
            .presample(u.select, u.point)
            .and_then(|e| LightCandidate::presampled(&lights, &e, at.p, rng.next_2d()));
        // The scene's first 30 lights are the spheres.
        for c in [power, tree, pooled]
            .into_iter()
            .flatten()
            .filter(|c| c.point.light < 30)
        {
            let resolved = lights
                .resolve(&c.point)
                .contact(&lights, &c.point, at.p)
                .unwrap();
            assert_eq!(c.contact.p, resolved.p, "candidate {i}");
            assert_eq!(c.contact.wi, resolved.wi, "candidate {i}");
            let rel = (c.contact.measure - resolved.measure).abs() / resolved.measure;
            assert!(
                rel < 1e-5,
                "candidate {i}: {} vs {}",
                c.contact.measure,
                resolved.measure
            );
            let power_sa = lights.pdf_sa(c.point.light, at.p, resolved.p, resolved.ng);
            let rel = (c.power_pdf_sa - power_sa).abs() / power_sa;
            assert!(
                rel < 1e-5,
                "candidate {i}: {} vs {power_sa}",
                c.power_pdf_sa
            );
            checked += 1;
        }
    }
    assert!(checked > 2000, "{checked}");
}
