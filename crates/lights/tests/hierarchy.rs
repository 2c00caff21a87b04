//! The light hierarchy (`LightSet::sample_hierarchy`, `hierarchy_select`, `hierarchy_pmf`):
//!
//! - its descent picks local entries with the probabilities `hierarchy_pmf` reports, by a
//!   chi-square test at several receivers (above, below and beside the lights, with normals
//!   towards and away from them);
//! - `hierarchy_pmf` sums to 1 over the entries wherever some light can reach the receiver,
//!   and the probability the descent reports with a pick equals it bit for bit;
//! - a point sampled through the hierarchy carries the density `pmf(entry) / area` (times the
//!   local share), and the power density it reports is what `LightSet::pdf_sa` says;
//! - the negative control: the same descent tested against the power table's pmf is rejected.
//!
//! Cuts of the hierarchy for a region of receivers (`LightSet::light_cut`, `pick_from_cut`,
//! `cut_pmf`, `presample_cut`, `sample_cut`), at cuts of 1 to 2000 nodes:
//!
//! - picks follow `cut_pmf` (chi-square), which sums to 1, and a pick's probability equals it;
//! - every entry that can light some receiver of the region (the hierarchy gives it a positive
//!   probability there) keeps a positive probability in the cut;
//! - presampled draws and samples carry the cut's density;
//! - the negative control: the cut's picks tested against the power table's pmf are rejected.
//!
//! The scene: 300 one-sided emissive rectangles (600 triangle entries) of powers spread over
//! three decades, facing up, down and sideways, two emissive spheres, a point light and a
//! directional light (kept beside the tree).

use glam::{Affine3A, Quat, Vec3};
use restir_geometry::{Shape, Sphere};
use restir_lights::{Light, LightSet, NeeSelection};
use restir_sampling::Pcg32;
use restir_testkit::{Histogram, sidak_level};

fn scene() -> (Vec<Shape>, LightSet) {
    let mut rng = Pcg32::new(7, 3);
    let mut shapes = Vec::new();
    let mut lights = Vec::new();
    for i in 0..300 {
        let mut quad = Shape::rectangle();
        let rotation = match i % 3 {
            0 => Quat::from_rotation_x(std::f32::consts::PI), // facing down
            1 => Quat::IDENTITY,                              // facing up
            _ => Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        };
        let p = Vec3::new(
            8.0 * rng.next_f32() - 4.0,
            8.0 * rng.next_f32() - 4.0,
            3.0 * rng.next_f32(),
        );
        quad.transform(&Affine3A::from_scale_rotation_translation(
            Vec3::splat(0.05 + 0.1 * rng.next_f32()),
            rotation,
            p,
        ));
        shapes.push(Shape::Mesh(quad));
        let scale = 10f32.powf(3.0 * rng.next_f32());
        lights.push(Light::Area {
            shape: i,
            radiance: Vec3::new(1.0, 0.8, 0.6) * scale,
            texture: None,
        });
    }
    for (c, r) in [
        (Vec3::new(1.0, 1.0, 1.5), 0.2),
        (Vec3::new(-2.0, 3.0, 0.5), 0.05),
    ] {
        shapes.push(Shape::Sphere(Sphere::new(c, r, false)));
        lights.push(Light::Area {
            shape: shapes.len() as u32 - 1,
            radiance: Vec3::splat(20.0),
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
    let set = LightSet::new(lights, &shapes[..], (Vec3::splat(-5.0), Vec3::splat(5.0))).unwrap();
    (shapes, set)
}

/// Receivers: (point, normal).
const RECEIVERS: [(Vec3, Vec3); 5] = [
    (Vec3::new(0.0, 0.0, -0.5), Vec3::Z),
    (Vec3::new(3.0, -2.0, 1.0), Vec3::X),
    (Vec3::new(-1.0, 1.0, 1.2), Vec3::new(0.0, 0.6, 0.8)),
    (Vec3::new(0.0, 0.0, 4.0), Vec3::Z), // above everything, facing away from the down-facing lights
    (Vec3::new(0.2, 0.3, 1.0), Vec3::ZERO), // no receiver normal
];

const SAMPLES: usize = 400_000;

fn seed_offset() -> u64 {
    std::env::var("HIERARCHY_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0)
}

fn pmfs(set: &LightSet, p: Vec3, n: Vec3) -> Vec<f64> {
    (0..set.emitter_count())
        .map(|e| set.hierarchy_pmf(p, n, e) as f64)
        .collect()
}

/// Picks of the descent; `misses` counts the descents that found no light as the remainder
/// (else they are left out).
fn histogram(set: &LightSet, p: Vec3, n: Vec3, seed: u64, misses: bool) -> Histogram {
    let mut rng = Pcg32::new(seed, 1);
    let mut hist = Histogram::new(set.emitter_count());
    for _ in 0..SAMPLES {
        let u = rng.next_f32() as f64 + rng.next_f32() as f64 * (1.0 / 16_777_216.0);
        match set.hierarchy_select(p, n, u.min(1.0 - f64::EPSILON)) {
            Some((e, pmf)) => {
                assert_eq!(pmf, set.hierarchy_pmf(p, n, e), "entry {e}");
                assert!(pmf > 0.0);
                hist.record(Some(e));
            }
            None if misses => hist.record_remainder(),
            None => {}
        }
    }
    hist
}

#[test]
fn descent_follows_its_pmf() {
    let (_, set) = scene();
    assert_eq!(set.emitter_count(), 600 + 4);
    let level = sidak_level(0.01, RECEIVERS.len());
    for (i, &(p, n)) in RECEIVERS.iter().enumerate() {
        // Σ pmf ≤ 1: the rest is the probability that the descent reaches a node none of whose
        // children can light the receiver (then no light is picked), tested as one more cell.
        let pmf = pmfs(&set, p, n);
        let total: f64 = pmf.iter().sum();
        assert!(
            total <= 1.0 + 1e-4 && total > 0.5,
            "receiver {i}: Σ pmf = {total}"
        );
        let outcome = histogram(&set, p, n, 100 + i as u64 + seed_offset(), true)
            .chi2(&pmf)
            .unwrap();
        eprintln!("receiver {i}: {outcome}");
        assert!(outcome.accepts(level), "receiver {i}: {outcome}");
    }
}

/// Lights that face away from a receiver get nothing: the down-facing rectangles all lie below
/// the receiver above everything, so they have probability 0 there (and the chi-square test
/// above shows the other lights share the whole mass).
#[test]
fn back_facing_lights_get_no_probability() {
    let (_, set) = scene();
    let (p, n) = RECEIVERS[3];
    let mut back = 0;
    for e in 0..set.emitter_count() {
        let light = set.entry_light(e) as usize;
        if light < 300 && light.is_multiple_of(3) {
            assert_eq!(set.hierarchy_pmf(p, n, e), 0.0, "entry {e}");
            back += 1;
        }
    }
    assert_eq!(back, 200);
}

/// A sample's density is the hierarchy's entry probability over the triangle's area, converted
/// to solid angle; the power density beside it is `LightSet::pdf_sa`'s.
#[test]
fn sample_densities_agree() {
    let (_, set) = scene();
    let mut rng = Pcg32::new(9, 0);
    for &(p, n) in &RECEIVERS {
        let mut checked = 0;
        for _ in 0..20_000 {
            let u = rng.next_f32() as f64;
            let Some((s, power_pdf)) = set.sample_hierarchy(p, n, u, rng.next_2d()) else {
                continue;
            };
            if s.delta {
                continue;
            }
            let want_power = set.pdf_sa(s.light, p, s.p, s.ng);
            assert!(
                (power_pdf - want_power).abs() <= 1e-3 * want_power,
                "{power_pdf} vs {want_power}"
            );
            // Hierarchy density / power density = hierarchy pmf / power pmf of the entry (a
            // triangle's power weight is its area's share of its mesh's).
            let e = set.emitter_of(s.light, s.prim).unwrap();
            let ratio = s.pdf_sa / power_pdf;
            let want = set.hierarchy_pmf(p, n, e) / set.entry_power_pmf(e);
            assert!((ratio - want).abs() <= 1e-3 * want, "{ratio} vs {want}");
            checked += 1;
        }
        assert!(checked > 1000, "{checked}");
    }
}

/// Next-event estimation's samples (`LightSet::sample_nee`) carry the density `pdf_nee`
/// reports for the same point, by power and by the hierarchy, for triangles and spheres; the
/// two differ (the hierarchy decides by distance and orientation).
#[test]
fn nee_samples_carry_the_density_pdf_nee_reports() {
    let (_, set) = scene();
    let mut rng = Pcg32::new(11, 0);
    for how in [NeeSelection::Power, NeeSelection::Hierarchy] {
        let mut checked = 0;
        let mut differ = 0;
        for &(p, n) in &RECEIVERS {
            for _ in 0..20_000 {
                let u = (rng.next_f32(), rng.next_f32());
                let Some(s) = set.sample_nee(how, p, n, u, rng.next_2d()) else {
                    continue;
                };
                if s.delta {
                    continue;
                }
                let pdf = set.pdf_nee(how, (s.light, s.prim), p, n, s.p, s.ng);
                assert!(
                    (s.pdf_sa - pdf).abs() <= 1e-3 * pdf,
                    "{}: {} vs {pdf}",
                    how.name(),
                    s.pdf_sa
                );
                let power = set.pdf_sa(s.light, p, s.p, s.ng);
                differ += usize::from((power - pdf).abs() > 1e-2 * pdf);
                checked += 1;
            }
        }
        assert!(checked > 10_000, "{checked}");
        if how == NeeSelection::Hierarchy {
            assert!(differ > checked / 2, "{differ} of {checked}");
        }
    }
}

/// Negative control: the descent is far from the power table's probabilities, and the test
/// says so.
#[test]
fn negative_control_power_pmf_is_rejected() {
    let (_, set) = scene();
    let (p, n) = RECEIVERS[0];
    let power: Vec<f64> = (0..set.emitter_count())
        .map(|e| set.entry_power_pmf(e) as f64)
        .collect();
    assert!((power.iter().sum::<f64>() - 1.0).abs() < 1e-4);
    let outcome = histogram(&set, p, n, 77, false).chi2(&power).unwrap();
    eprintln!("power pmf: {outcome}");
    assert!(outcome.p_value < 1e-6, "{outcome}");
}

/// Where no light can be ruled out (lights that radiate all around, a receiver without a
/// normal) the descent never fails and `hierarchy_pmf` sums to 1 over the entries.
#[test]
fn pmf_sums_to_one_over_omnidirectional_lights() {
    let mut rng = Pcg32::new(5, 5);
    let mut shapes = Vec::new();
    let mut lights = Vec::new();
    for i in 0..257u32 {
        let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 6.0 - 3.0;
        if i.is_multiple_of(4) {
            lights.push(Light::Point {
                position: c,
                intensity: Vec3::splat(1.0 + 100.0 * rng.next_f32()),
            });
        } else {
            shapes.push(Shape::Sphere(Sphere::new(
                c,
                0.01 + 0.1 * rng.next_f32(),
                false,
            )));
            lights.push(Light::Area {
                shape: shapes.len() as u32 - 1,
                radiance: Vec3::splat(1.0 + 1000.0 * rng.next_f32()),
                texture: None,
            });
        }
    }
    let set = LightSet::new(lights, &shapes[..], (Vec3::splat(-4.0), Vec3::splat(4.0))).unwrap();
    for p in [Vec3::ZERO, Vec3::new(2.0, -1.0, 0.5), Vec3::splat(10.0)] {
        let total: f64 = pmfs(&set, p, Vec3::ZERO).iter().sum();
        assert!((total - 1.0).abs() < 1e-5, "at {p}: Σ pmf = {total}");
        let hist = histogram(&set, p, Vec3::ZERO, 3, true);
        assert_eq!(hist.remainder(), 0);
    }
}

/// Point lights at `s` times the positions of a unit layout (intensities times `s²`, the same
/// irradiance at the same relative places), in a box of side `s`.
fn point_lights(s: f32) -> LightSet {
    let mut rng = Pcg32::new(11, 5);
    let lights = (0..64)
        .map(|_| Light::Point {
            position: s * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()),
            intensity: Vec3::splat(s * s * (0.5 + rng.next_f32())),
        })
        .collect();
    LightSet::new(lights, Vec::<Shape>::new(), (Vec3::ZERO, Vec3::splat(s))).unwrap()
}

/// The hierarchy weighs the same layout alike in any unit: its probabilities at 10⁻⁶ and 10³
/// are those at unit scale, for receivers among the lights (an absolute floor of 10⁻¹² on the
/// squared distance flattened every node near a receiver at 10⁻⁶, where squared distances are
/// near 10⁻¹²).
#[test]
fn probabilities_do_not_depend_on_the_unit() {
    let unit = point_lights(1.0);
    let receivers = [
        Vec3::new(0.5, 0.5, 0.5),
        Vec3::new(0.1, 0.9, 0.3),
        Vec3::new(0.7, 0.2, 0.95),
    ];
    for s in [1e-6f32, 1e3] {
        let scaled = point_lights(s);
        let mut worst = 0.0f32;
        for p in receivers {
            for e in 0..64 {
                let a = unit.hierarchy_pmf(p, Vec3::ZERO, e);
                let b = scaled.hierarchy_pmf(s * p, Vec3::ZERO, e);
                worst = worst.max((a - b).abs() / a.max(1e-30));
            }
        }
        assert!(
            worst < 1e-3,
            "scale {s:e}: probabilities differ by {worst:e}"
        );
    }
    // Negative control: moving the receiver changes the probabilities by far more.
    let (a, b) = (
        unit.hierarchy_pmf(receivers[0], Vec3::ZERO, 0),
        unit.hierarchy_pmf(receivers[1], Vec3::ZERO, 0),
    );
    assert!((a - b).abs() / a > 1e-2, "{a} {b}");
}

/// Cut sizes: the root alone, a few clusters, most of the tree, every leaf.
const CUT_SIZES: [usize; 4] = [1, 16, 256, 2000];
/// The region's radius around each receiver.
const SPREAD: f32 = 0.4;

fn cut_pmfs(set: &LightSet, cut: &restir_lights::LightCut) -> Vec<f64> {
    (0..set.emitter_count())
        .map(|e| set.cut_pmf(cut, e) as f64)
        .collect()
}

fn cut_histogram(set: &LightSet, cut: &restir_lights::LightCut, seed: u64) -> Histogram {
    let mut rng = Pcg32::new(seed, 2);
    let mut hist = Histogram::new(set.emitter_count());
    for _ in 0..SAMPLES {
        let (e, pmf) = set
            .pick_from_cut(cut, rng.next_f32(), rng.next_f64())
            .expect("a cut with importance always picks");
        assert_eq!(pmf, set.cut_pmf(cut, e), "entry {e}");
        assert!(pmf > 0.0);
        hist.record(Some(e));
    }
    hist
}

#[test]
fn cut_follows_its_pmf() {
    let (_, set) = scene();
    let level = sidak_level(0.01, RECEIVERS.len() * CUT_SIZES.len());
    for (i, &(p, n)) in RECEIVERS.iter().enumerate() {
        for (j, &nodes) in CUT_SIZES.iter().enumerate() {
            let cut = set.light_cut(p, n, SPREAD, nodes, None).unwrap();
            assert!(cut.len() <= nodes.max(1));
            let pmf = cut_pmfs(&set, &cut);
            let total: f64 = pmf.iter().sum();
            assert!(
                (total - 1.0).abs() < 1e-4,
                "receiver {i}, {nodes} nodes: Σ pmf = {total}"
            );
            let seed = 300 + 10 * i as u64 + j as u64 + seed_offset();
            let outcome = cut_histogram(&set, &cut, seed).chi2(&pmf).unwrap();
            eprintln!("receiver {i}, cut of {} nodes: {outcome}", cut.len());
            assert!(
                outcome.accepts(level),
                "receiver {i}, {nodes} nodes: {outcome}"
            );
        }
    }
}

/// The cut's importance holds for the whole region: an entry the hierarchy can pick at any
/// receiver within the spread (with the region's normal) has a positive probability in the
/// cut, at every cut size.
#[test]
fn cut_keeps_every_light_that_can_reach_the_region() {
    let (_, set) = scene();
    let mut rng = Pcg32::new(21, 4);
    let mut zero_somewhere = 0;
    for &(p, n) in &RECEIVERS {
        for &nodes in &CUT_SIZES {
            let cut = set.light_cut(p, n, SPREAD, nodes, None).unwrap();
            for _ in 0..32 {
                let d = restir_sampling::warp::sample_uniform_sphere(rng.next_2d());
                let q = p + d * SPREAD * rng.next_f32().cbrt();
                for e in 0..set.emitter_count() {
                    if set.hierarchy_pmf(q, n, e) > 0.0 {
                        assert!(
                            set.cut_pmf(&cut, e) > 0.0,
                            "entry {e} at {q}, {nodes} nodes"
                        );
                    } else {
                        zero_somewhere += 1;
                    }
                }
            }
        }
    }
    // Some entries cannot light some receivers (the test is not vacuous).
    assert!(zero_somewhere > 0);
}

/// A point sampled from a cut carries the cut's entry probability over the power sampler's
/// times the power density; a presampled draw carries the same ratio.
#[test]
fn cut_samples_carry_the_cut_density() {
    let (_, set) = scene();
    let mut rng = Pcg32::new(13, 1);
    for &(p, n) in &RECEIVERS {
        let cut = set.light_cut(p, n, SPREAD, 64, None).unwrap();
        let mut checked = 0;
        for _ in 0..4000 {
            let Some((s, power_pdf)) =
                set.sample_cut(&cut, p, rng.next_f32(), rng.next_f64(), rng.next_2d())
            else {
                continue;
            };
            if s.delta {
                continue;
            }
            let e = set.emitter_of(s.light, s.prim).unwrap();
            let want = set.cut_pmf(&cut, e) / set.emitter_pmf(e);
            let ratio = s.pdf_sa / power_pdf;
            assert!((ratio - want).abs() <= 1e-3 * want, "{ratio} vs {want}");
            checked += 1;
        }
        assert!(checked > 1000, "{checked}");
        let mut pool = vec![None; 512];
        set.presample_cut(&cut, None, &mut rng, restir_lights::Claim::Exact, &mut pool);
        for (d, ratio) in pool.iter().flatten() {
            let e = match *d {
                restir_lights::Presampled::Fixed { point, .. } => {
                    set.emitter_of(point.light, point.prim)
                }
                restir_lights::Presampled::Light { light, .. }
                | restir_lights::Presampled::Sphere { light, .. } => set.emitter_of(light, 0),
            }
            .unwrap();
            let want = set.cut_pmf(&cut, e) / set.emitter_pmf(e);
            assert!((ratio - want).abs() <= 1e-4 * want, "{ratio} vs {want}");
        }
    }
}

/// Negative control: a fine cut's picks are far from the power table's probabilities, and the
/// test says so.
#[test]
fn negative_control_cut_against_power_pmf_is_rejected() {
    let (_, set) = scene();
    let (p, n) = RECEIVERS[0];
    let cut = set.light_cut(p, n, SPREAD, 256, None).unwrap();
    let power: Vec<f64> = (0..set.emitter_count())
        .map(|e| set.emitter_pmf(e) as f64)
        .collect();
    let outcome = cut_histogram(&set, &cut, 78).chi2(&power).unwrap();
    eprintln!("power pmf: {outcome}");
    assert!(outcome.p_value < 1e-6, "{outcome}");
}

/// A cut for receivers on a light that cannot light its own surface (the larger sphere) leaves
/// that light its small fixed share instead of the most probability (it is the nearest), and
/// its picks still follow its pmf.
#[test]
fn cut_for_receivers_on_a_light_leaves_it_its_share_and_follows_its_pmf() {
    let (_, set) = scene();
    let sphere = 300u32;
    assert!(set.self_unlit(sphere), "an outward sphere");
    assert!(set.self_unlit(0), "a flat quad");
    assert!(!set.self_unlit(302), "a point light has no surface");
    let centre = Vec3::new(1.0, 1.0, 1.5);
    let n = Vec3::new(0.0, 0.6, 0.8);
    let p = centre + 0.2 * n;
    let entry = (0..set.emitter_count())
        .find(|&e| set.entry_light(e) == sphere)
        .unwrap();
    let plain = set.light_cut(p, Vec3::ZERO, 0.1, 256, None).unwrap();
    let own = restir_lights::OwnLight {
        light: sphere,
        share: restir_lights::OWN_LIGHT_SHARE,
    };
    let cut = set.light_cut(p, Vec3::ZERO, 0.1, 256, Some(own)).unwrap();
    let (before, after) = (set.cut_pmf(&plain, entry), set.cut_pmf(&cut, entry));
    eprintln!("the sphere's probability: {before} alone, {after} for receivers on it");
    assert!(before > 0.25, "{before}");
    assert!(
        after > 0.0 && after <= restir_lights::OWN_LIGHT_SHARE,
        "{after}"
    );
    let pmf = cut_pmfs(&set, &cut);
    let total: f64 = pmf.iter().sum();
    assert!((total - 1.0).abs() < 1e-4, "Σ pmf = {total}");
    let outcome = cut_histogram(&set, &cut, 91 + seed_offset())
        .chi2(&pmf)
        .unwrap();
    eprintln!("{outcome}");
    assert!(outcome.accepts(0.01), "{outcome}");
}
