//! ReSTIR PT with the reconnection shift: the shift's contract on real scene paths (identity,
//! round trip, symmetric failure) and unbiasedness against the path tracer on a small room lit
//! mostly indirectly (the light is hidden behind a partition and shines at the ceiling), with
//! diffuse, rough-conductor and rough-plastic surfaces and a dim environment through the open
//! front. Means over independent renders are compared block by block with the standard error
//! measured across seeds (the test pattern of `tests/restir_di.rs`); biased variants must fail.

use restir_gris::ShiftMap;
use restir_integrators::film::Filter;
use restir_integrators::path::PathSettings;
use restir_integrators::restir_pt::{Kind, Reconnection, ShiftKind};
use restir_integrators::reuse::MIS_NAMES;
use restir_integrators::{
    Image, Integrator, IntegratorOptions, PassContext, RestirPtIntegrator, RestirPtSettings,
    make_integrator,
};
use restir_sampling::Pcg32;
use restir_scene::parse_ron;

mod common;
use common::{block_statistics, max_z, pixel_relative_variance};

const SIZE: u32 = 24;
const BLOCK: u32 = 8;

fn scene() -> common::Built {
    scene_with("")
}

/// The room with a smooth glass sphere and a smooth plastic sphere: delta lobes at primary hits
/// (path traced) and at reconnection vertices (paths that cannot be shifted).
fn glass_scene() -> common::Built {
    scene_with(
        r#"(geometry: Sphere(center: (-0.6, 0.45, 0.6), radius: 0.4),
             material: Some(Inline(Dielectric()))),
            (geometry: Sphere(center: (0.9, 1.2, -0.3), radius: 0.3),
             material: Some(Inline(Plastic(diffuse_reflectance: (0.3, 0.6, 0.3))))),"#,
    )
}

fn scene_with(extra: &str) -> common::Built {
    build(&scene_text(extra))
}

fn build(ron: &str) -> common::Built {
    let desc = parse_ron(ron, "pt-test.ron".as_ref()).unwrap();
    common::build(&desc, ".".as_ref(), "pt-test.ron".as_ref())
}

fn scene_text(extra: &str) -> String {
    format!(
        r#"(
        camera: (fov: 55, to_world: [LookAt(origin: (0, 1, 4.5), target: (0, 0.7, 0), up: (0, 1, 0))]),
        film: (width: {SIZE}, height: {SIZE}, filter: Box),
        integrator: (max_depth: 4),
        shapes: [
            (geometry: Rectangle, to_world: [Scale((2, 2, 1)), Rotate(axis: (1, 0, 0), angle: -90)],
             material: Some(Inline(Diffuse(reflectance: (0.7, 0.7, 0.7))))),
            (geometry: Rectangle, to_world: [Scale((2, 2, 1)), Rotate(axis: (1, 0, 0), angle: 90),
             Translate((0, 2, 0))], material: Some(Inline(Diffuse(reflectance: (0.8, 0.8, 0.8))))),
            (geometry: Rectangle, to_world: [Scale((2, 1, 1)), Translate((0, 1, -2))],
             material: Some(Inline(RoughPlastic(diffuse_reflectance: (0.2, 0.4, 0.7),
             roughness: (alpha: 0.15))))),
            (geometry: Rectangle, to_world: [Scale((2, 1, 1)), Rotate(axis: (0, 1, 0), angle: 90),
             Translate((-2, 1, 0))], material: Some(Inline(RoughConductor(ior: (material: Some("Au")),
             roughness: (alpha: 0.25))))),
            (geometry: Rectangle, to_world: [Scale((2, 1, 1)), Rotate(axis: (0, 1, 0), angle: -90),
             Translate((2, 1, 0))], material: Some(Inline(Diffuse(reflectance: (0.7, 0.2, 0.2))))),
            (geometry: Rectangle, to_world: [Scale((2, 0.65, 1)), Translate((0, 0.65, -0.8))],
             material: Some(Inline(TwoSided(Diffuse(reflectance: (0.6, 0.6, 0.5)))))),
            (geometry: Rectangle, to_world: [Scale((0.5, 1, 1)), Rotate(axis: (1, 0, 0), angle: -90),
             Translate((-0.6, 0.002, 1))], material: Some(Inline(Black))),
            (geometry: Cube, to_world: [Scale((0.3, 0.3, 0.3)), Translate((0.7, 0.3, 0.8))],
             material: Some(Inline(RoughPlastic(diffuse_reflectance: (0.6, 0.5, 0.2),
             roughness: (alpha: 0.1))))),
            (geometry: Rectangle, to_world: [Scale((0.5, 0.5, 1)), Rotate(axis: (1, 0, 0), angle: -90),
             Translate((0, 0.05, -1.4))], emission: Some((20, 20, 20))),
            {extra}
        ],
        lights: [
            Constant(radiance: (0.02, 0.03, 0.05)),
        ],
    )"#
    )
}

/// The room with every surface diffuse (the rough plastics and the rough gold replaced by
/// Lambertian reflectors) and a smooth glass sphere in front. With `ceiling_light` the light
/// hangs under the ceiling facing down (the room lit mostly directly, as the Cornell box)
/// instead of lying behind the partition facing up; its radiance is `emission` (20 in the other
/// scenes).
fn diffuse_glass_scene(ceiling_light: bool, emission: &str) -> common::Built {
    let mut ron = scene_text(
        r#"(geometry: Sphere(center: (-0.6, 0.45, 0.6), radius: 0.4),
             material: Some(Inline(Dielectric()))),"#,
    )
    .replace("RoughPlastic(diffuse_reflectance:", "Diffuse(reflectance:")
    .replace(",\n             roughness: (alpha: 0.15)", "")
    .replace(",\n             roughness: (alpha: 0.1)", "")
    .replace(
        "RoughConductor(ior: (material: Some(\"Au\")),\n             roughness: (alpha: 0.25))",
        "Diffuse(reflectance: (0.8, 0.6, 0.3))",
    )
    .replace(
        "emission: Some((20, 20, 20))",
        &format!("emission: Some(({emission}, {emission}, {emission}))"),
    );
    if ceiling_light {
        ron = ron.replace(
            "Translate((0, 0.05, -1.4))], emission",
            "Rotate(axis: (1, 0, 0), angle: 180), Translate((0, 1.95, 0.3))], emission",
        );
    }
    assert!(!ron.contains("Rough") && ron.contains(emission), "{ron}");
    assert_eq!(ron.contains("1.95, 0.3"), ceiling_light);
    build(&ron)
}

fn render_image(
    scene: &common::Built,
    name: &str,
    params: &[(&str, &str)],
    spp: u32,
    seed: u64,
) -> Image {
    // The reuse these tests were written for (one candidate, one round of three neighbours
    // within 8 pixels, independent neighbours: cheaper than the defaults, so each test affords
    // more renders); parameters given in `params` come later and win, and
    // `unbiased_at_the_defaults` checks the defaults themselves.
    let mut all = Vec::with_capacity(params.len() + 5);
    if name == "restir-pt" {
        all.extend_from_slice(&[
            ("radius", "8"),
            ("candidates", "1"),
            ("spatial_rounds", "1"),
            ("neighbors", "3"),
            ("reciprocal", "false"),
        ]);
    }
    all.extend_from_slice(params);
    common::render_image(scene, name, &all, spp, seed)
}

fn statistics(
    scene: &common::Built,
    name: &str,
    params: &[(&str, &str)],
    spp: u32,
    seeds: u64,
) -> Vec<(f64, f64)> {
    let render_one = |seed| render_image(scene, name, params, spp, seed);
    block_statistics(render_one, seeds, 2000, BLOCK)
}

/// 9 blocks × a few configurations: a Bonferroni-style bound of 4.5 standard errors.
const Z_MAX: f64 = 4.5;

fn integrator(max_depth: i32) -> RestirPtIntegrator {
    RestirPtIntegrator::new(RestirPtSettings::new(PathSettings {
        max_depth,
        rr_depth: 3,
        hide_emitters: false,
        sampler: restir_scene::SamplerKind::Independent,
        nee: restir_lights::NeeSelection::Power,
        nee_rule: restir_integrators::path::NeeRule::Named,
    }))
}

fn with_shift(pt: RestirPtIntegrator, shift: ShiftKind) -> RestirPtIntegrator {
    let mut settings = *pt.settings();
    settings.shift = shift;
    RestirPtIntegrator::new(settings)
}

/// Shifting a pixel's own path to itself is the identity (J = 1, the same contribution bit for
/// bit); on pairs of pixels, when the forward shift succeeds the inverse shift of its result
/// succeeds, their Jacobians multiply to 1 and the round trip gives the path's contribution back.
#[test]
fn shift_identity_and_round_trip_on_scene_paths() {
    for shift in [
        ShiftKind::Reconnection,
        ShiftKind::Replay,
        ShiftKind::Hybrid,
    ] {
        let pt = with_shift(integrator(-1), shift);
        let stats = check_shifts(&scene(), &pt);
        assert!(stats.kinds[Kind::DirectNee as usize] + stats.kinds[Kind::Frozen as usize] > 0);
        let stats = check_shifts(&glass_scene(), &pt);
        assert!(stats.kinds[Kind::Frozen as usize] > 0, "{:?}", stats.kinds);
        if shift == ShiftKind::Hybrid {
            // Paths through the glass reconnect after it.
            assert!(stats.rc[3..].iter().sum::<usize>() >= 5, "{:?}", stats.rc);
        }
    }
    // The striped near-specular floor: many hybrid paths replay one or more bounces.
    let stats = check_shifts(
        &striped_floor_scene(0.01),
        &with_shift(integrator(-1), ShiftKind::Hybrid),
    );
    assert!(stats.rc[3..].iter().sum::<usize>() >= 50, "{:?}", stats.rc);
    // Symmetric Jacobian rejection keeps forward and inverse failures together.
    let mut settings = *integrator(-1).settings();
    settings.max_jacobian = 2.0;
    check_shifts(&glass_scene(), &RestirPtIntegrator::new(settings));
    // The footprint reconnection rule: evaluated on the destination's path by the shift, so
    // forward and inverse still succeed and fail together.
    let mut settings = *integrator(-1).settings();
    settings.reconnection = Reconnection::Footprint;
    for shift in [ShiftKind::Reconnection, ShiftKind::Hybrid] {
        let pt = with_shift(RestirPtIntegrator::new(settings), shift);
        check_shifts(&scene(), &pt);
        let stats = check_shifts(&glass_scene(), &pt);
        assert!(stats.kinds[Kind::Frozen as usize] > 0, "{:?}", stats.kinds);
    }
    let stats = check_shifts(
        &striped_floor_scene(0.01),
        &with_shift(RestirPtIntegrator::new(settings), ShiftKind::Hybrid),
    );
    assert!(stats.rc[3..].iter().sum::<usize>() >= 50, "{:?}", stats.rc);
}

#[derive(Debug, Default)]
struct ShiftStats {
    kinds: [usize; 6],
    /// Reservoirs by reconnection index (0 = none).
    rc: [usize; 8],
}

/// Runs the shift checks on four passes of `scene`.
fn check_shifts(scene: &common::Built, pt: &RestirPtIntegrator) -> ShiftStats {
    let filter = Filter::new(scene.filter);
    let mut stats = ShiftStats::default();
    let (mut identity, mut pairs, mut fwd_ok, mut visible, mut exact) = (0, 0, 0, 0, 0);
    for pass in 0..4 {
        let ctx = PassContext {
            shared_offset: None,
            samples: None,
            seed: 7,
            pass,
            filter: &filter,
            crop: None,
        };
        let (gbuf, reservoirs, _, _) = pt.initial_reservoirs(scene, &ctx);
        let shift = pt.shift_map(scene, &gbuf);
        let n = reservoirs.len();
        let mut rng = Pcg32::new(11, u64::from(pass));
        for (i, res) in reservoirs.iter().enumerate() {
            let Some(x) = res.sample else { continue };
            assert!(x.value.is_finite() && res.ucw.is_finite());
            stats.kinds[x.kind as usize] += 1;
            stats.rc[usize::from(x.rc).min(7)] += 1;
            if let Some((t, j, y)) = shift.shift_full(i, i, &x)
                && t > 0.0
            {
                assert_eq!(j, 1.0, "pixel {i}: self-shift Jacobian");
                // The same RGB contribution as initial sampling computed, bit for bit.
                assert_eq!(
                    y.value, x.value,
                    "pixel {i}: self-shift contribution ({x:?})"
                );
                assert_eq!(t, res.own_target, "pixel {i}: self-shift target");
                identity += 1;
            }
            for _ in 0..8 {
                let k = (rng.next_u32() as usize) % n;
                if k == i || gbuf.receiver(k).is_none() {
                    continue;
                }
                pairs += 1;
                let Some(f) = shift.shift(&i, &k, &x) else {
                    continue;
                };
                fwd_ok += 1;
                let b = shift.shift(&k, &i, &f.sample).unwrap_or_else(|| {
                    panic!("pixels {i}->{k}: forward succeeded, inverse failed ({x:?})")
                });
                let prod = f64::from(f.jacobian) * f64::from(b.jacobian);
                assert!((prod - 1.0).abs() < 1e-4, "pixels {i}->{k}: J·J⁻¹ = {prod}");
                if f.destination_target > 0.0 && b.destination_target > 0.0 {
                    visible += 1;
                    let err =
                        (b.sample.value - x.value).abs().max_element() / x.value.max_element();
                    assert!(
                        err < 1e-4,
                        "pixels {i}->{k}: round trip {:?} vs {:?}",
                        b.sample.value,
                        x.value
                    );
                    exact += usize::from(b.sample.value == x.value);
                }
            }
        }
    }
    eprintln!(
        "{}: identity checks {identity}, kinds {:?}, rc {:?}, pairs {pairs}, forward succeeded \
         {fwd_ok}, visible both ways {visible} (round trip bit-exact {exact})",
        pt.effective_shift(scene).name(),
        stats.kinds,
        stats.rc
    );
    assert!(identity > 500, "too few identity checks: {identity}");
    assert!(visible > 200, "too few successful shifts: {visible}");
    stats
}

#[test]
fn unbiased_against_the_path_tracer() {
    let scene = scene();
    let reference = statistics(&scene, "path", &[], 128, 64);
    for mis in ["defensive-pairwise", "balance"] {
        let pt = statistics(&scene, "restir-pt", &[("mis", mis)], 1, 400);
        let z = max_z(&pt, &reference);
        eprintln!("max_depth 4, {mis}: max |z| = {z:.2}");
        assert!(z < Z_MAX, "{mis}: max |z| = {z:.2}");
    }
    // The other unbiased schemes.
    for (mis, scheme) in MIS_NAMES {
        if !scheme.is_unbiased() || ["defensive-pairwise", "balance"].contains(mis) {
            continue;
        }
        let pt = statistics(&scene, "restir-pt", &[("mis", mis)], 1, 300);
        let z = max_z(&pt, &reference);
        eprintln!("max_depth 4, {mis}: max |z| = {z:.2}");
        assert!(z < Z_MAX, "{mis}: max |z| = {z:.2}");
    }
    // Two rounds of five neighbours and two candidate paths.
    let params = [
        ("spatial_rounds", "2"),
        ("neighbors", "5"),
        ("candidates", "2"),
    ];
    let z = max_z(
        &statistics(&scene, "restir-pt", &params, 1, 200),
        &reference,
    );
    eprintln!("max_depth 4, 2 rounds × 5 neighbours, 2 candidates: max |z| = {z:.2}");
    assert!(z < Z_MAX, "2 rounds: max |z| = {z:.2}");
    // Reciprocal neighbour pairs sharing their shifts (3 rounds of 2 pairs), and their negative
    // control: each pixel reading the other shift of its pair.
    let reciprocal = [
        ("spatial_rounds", "3"),
        ("neighbors", "4"),
        ("radius", "3"),
        ("reciprocal", "true"),
    ];
    let z = max_z(
        &statistics(&scene, "restir-pt", &reciprocal, 1, 300),
        &reference,
    );
    eprintln!("max_depth 4, reciprocal pairs, 3 rounds × 4 neighbours: max |z| = {z:.2}");
    assert!(z < Z_MAX, "reciprocal: max |z| = {z:.2}");
    let params = [&reciprocal[..], &[("reciprocal_mismatched", "true")]].concat();
    let z = max_z(
        &statistics(&scene, "restir-pt", &params, 1, 600),
        &reference,
    );
    eprintln!("reciprocal pairs reading the wrong shift: max |z| = {z:.2}");
    assert!(
        z > Z_MAX,
        "mismatched reciprocal shifts should be biased: {z:.2}"
    );
    // Direct light path traced per pixel, the reservoirs carrying the rest.
    let z = max_z(
        &statistics(&scene, "restir-pt", &[("direct", "path")], 1, 400),
        &reference,
    );
    eprintln!("max_depth 4, direct light path traced: max |z| = {z:.2}");
    assert!(z < Z_MAX, "direct = path: max |z| = {z:.2}");
    // Direct light (and the emitters the camera sees) from a ReSTIR DI pass.
    let z = max_z(
        &statistics(&scene, "restir-pt", &[("direct", "restir-di")], 1, 300),
        &reference,
    );
    eprintln!("max_depth 4, direct light from ReSTIR DI: max |z| = {z:.2}");
    assert!(z < Z_MAX, "direct = restir-di: max |z| = {z:.2}");
    // Temporal reuse across 4 passes (history capped at mcap), then spatial reuse.
    let z = max_z(
        &statistics(&scene, "restir-pt", &[("temporal", "true")], 16, 200),
        &reference,
    );
    eprintln!("max_depth 4, temporal: max |z| = {z:.2}");
    assert!(z < Z_MAX, "temporal: max |z| = {z:.2}");
    // Negative controls: the biased variants are caught by the same statistic.
    let uniform = statistics(&scene, "restir-pt", &[("mis", "uniform")], 1, 2000);
    for (a, b) in uniform.iter().zip(&reference) {
        eprintln!(
            "1/M: {:.4} ± {:.4}   path: {:.4} ± {:.4}",
            a.0, a.1, b.0, b.1
        );
    }
    let z = max_z(&uniform, &reference);
    eprintln!("uniform (1/M) weights: max |z| = {z:.2}");
    assert!(z > Z_MAX, "uniform weights should be biased: {z:.2}");
    let nojac = statistics(&scene, "restir-pt", &[("unit_jacobian", "true")], 1, 2000);
    for (a, b) in nojac.iter().zip(&reference) {
        eprintln!(
            "J = 1: {:.4} ± {:.4}   path: {:.4} ± {:.4}",
            a.0, a.1, b.0, b.1
        );
    }
    let z = max_z(&nojac, &reference);
    eprintln!("Jacobian omitted: max |z| = {z:.2}");
    assert!(z > Z_MAX, "J = 1 should be biased: {z:.2}");
}

/// The quality-per-sample options against the path tracer: symmetric
/// Jacobian rejection and the footprint reconnection rule, alone and together; and their
/// negative controls: a rejection of `J > τ` only (not symmetric, so a shift can succeed while
/// its inverse fails) and the footprint rule without the Jacobian.
#[test]
fn jacobian_rejection_and_footprint_rule_unbiased() {
    let scene = scene();
    let reference = statistics(&scene, "path", &[], 128, 64);
    let configurations: [&[(&str, &str)]; 3] = [
        &[("max_jacobian", "2")],
        &[("reconnection", "footprint")],
        &[("reconnection", "footprint"), ("max_jacobian", "2")],
    ];
    for params in configurations {
        let z = max_z(&statistics(&scene, "restir-pt", params, 1, 400), &reference);
        eprintln!("max_depth 4, {params:?}: max |z| = {z:.2}");
        assert!(z < Z_MAX, "{params:?}: max |z| = {z:.2}");
    }
    // More reuse (3 rounds of 6 neighbours) makes the bias of the negative controls visible.
    let reuse = [("spatial_rounds", "3"), ("neighbors", "6")];
    let one_sided = [
        reuse[0],
        reuse[1],
        ("max_jacobian", "1.1"),
        ("one_sided_jacobian", "true"),
    ];
    let z = max_z(
        &statistics(&scene, "restir-pt", &one_sided, 1, 2000),
        &reference,
    );
    eprintln!("one-sided Jacobian rejection (J > 1.1 only): max |z| = {z:.2}");
    assert!(z > Z_MAX, "a one-sided rejection should be biased: {z:.2}");
    let nojac = [
        reuse[0],
        reuse[1],
        ("reconnection", "footprint"),
        ("unit_jacobian", "true"),
    ];
    let z = max_z(
        &statistics(&scene, "restir-pt", &nojac, 1, 2000),
        &reference,
    );
    eprintln!("footprint rule, Jacobian omitted: max |z| = {z:.2}");
    assert!(z > Z_MAX, "J = 1 should be biased: {z:.2}");
}

/// The emission seen on emitter silhouettes from more camera rays (`edge_rays`): a small lamp in
/// view, whose edge crosses a few pixels of one block. Unbiased with the mask made from
/// pixel-centre rays; choosing the pixels by what the pass's own camera ray saw (the negative
/// control) darkens the edge (a pixel whose ray missed the lamp never gets the extra rays).
#[test]
fn edge_rays_unbiased() {
    let scene = scene_with(
        r#"(geometry: Sphere(center: (0.6, 1.45, 0.4), radius: 0.25), emission: Some((20, 20, 20))),"#,
    );
    let reference = statistics(&scene, "path", &[], 128, 64);
    for rays in ["1", "32"] {
        let z = max_z(
            &statistics(&scene, "restir-pt", &[("edge_rays", rays)], 1, 300),
            &reference,
        );
        eprintln!("edge_rays = {rays}: max |z| = {z:.2}");
        assert!(z < Z_MAX, "edge_rays = {rays}: max |z| = {z:.2}");
    }
    let control = [("edge_rays", "8"), ("edge_mask_from_pass", "true")];
    let z = max_z(
        &statistics(&scene, "restir-pt", &control, 1, 300),
        &reference,
    );
    eprintln!("edge rays where the pass's own ray saw the lamp: max |z| = {z:.2}");
    assert!(
        z > Z_MAX,
        "a mask from the pass's own rays should be biased: {z:.2}"
    );
}

/// The same on a splatting film (Mitsuba's default Gaussian): the pixels within the filter's
/// reach of any pixel whose filter sees the lamp get `edge_rays` times the filter's variance
/// factor camera rays (32 → 10) in place of the G-buffer's, through offsets the mask's pixels
/// share, each splatted from there with its share. Unbiased; the mask from the pass's own rays is caught.
#[test]
fn edge_rays_on_a_splatting_film_unbiased() {
    let scene = build(
        &scene_text(
            r#"(geometry: Sphere(center: (0.6, 1.45, 0.4), radius: 0.25), emission: Some((20, 20, 20))),"#,
        )
        .replace("filter: Box", "filter: Gaussian(stddev: 0.5)"),
    );
    // The extra rays change the image.
    let one = |rays| render_image(&scene, "restir-pt", &[("edge_rays", rays)], 1, 5);
    assert_ne!(one("1"), one("32"));
    let reference = statistics(&scene, "path", &[], 128, 64);
    for rays in ["1", "32"] {
        let z = max_z(
            &statistics(&scene, "restir-pt", &[("edge_rays", rays)], 1, 300),
            &reference,
        );
        eprintln!("splatting, edge_rays = {rays}: max |z| = {z:.2}");
        assert!(z < Z_MAX, "splatting, edge_rays = {rays}: max |z| = {z:.2}");
    }
    let control = [("edge_rays", "32"), ("edge_mask_from_pass", "true")];
    let z = max_z(
        &statistics(&scene, "restir-pt", &control, 1, 300),
        &reference,
    );
    eprintln!("splatting, edge rays where the pass's own ray saw the lamp: max |z| = {z:.2}");
    assert!(
        z > Z_MAX,
        "a mask from the pass's own rays should be biased: {z:.2}"
    );
}

/// The emission seen through delta lobes: a small lamp and the environment seen through a
/// smooth glass sphere. The walks leave those paths out and the silhouette stage adds them
/// (with the mask's camera rays where the lamp's image in the glass has an edge, and where the
/// glass's reflection and transmission see different things): unbiased. The negative control
/// keeps them in the walks too, so they count twice (brighter where the glass shows the lamp).
#[test]
fn emission_through_delta_lobes_unbiased() {
    let scene = scene_with(
        r#"(geometry: Sphere(center: (0.6, 1.45, 0.4), radius: 0.25), emission: Some((20, 20, 20))),
            (geometry: Sphere(center: (0.3, 1.22, 2.45), radius: 0.45),
             material: Some(Inline(Dielectric()))),"#,
    );
    let reference = statistics(&scene, "path", &[], 128, 64);
    let z = max_z(&statistics(&scene, "restir-pt", &[], 1, 300), &reference);
    eprintln!("lamp through glass: max |z| = {z:.2}");
    assert!(z < Z_MAX, "lamp through glass: max |z| = {z:.2}");
    let control = [("delta_emission_twice", "true")];
    let z = max_z(
        &statistics(&scene, "restir-pt", &control, 1, 300),
        &reference,
    );
    eprintln!("emission through glass counted twice: max |z| = {z:.2}");
    assert!(z > Z_MAX, "counting it twice should be biased: {z:.2}");
}

/// The defaults (two candidates, three rounds of two reciprocal pairs within 3 pixels).
#[test]
fn unbiased_at_the_defaults() {
    let scene = scene();
    let reference = statistics(&scene, "path", &[], 128, 64);
    let defaults = [
        ("radius", "3"),
        ("candidates", "2"),
        ("spatial_rounds", "3"),
        ("neighbors", "4"),
        ("reciprocal", "true"),
    ];
    let settings = *integrator(4).settings();
    assert_eq!(
        (
            settings.reuse.radius,
            settings.candidates,
            settings.reuse.spatial_rounds,
            settings.reuse.neighbors,
            settings.reuse.reciprocal
        ),
        (3.0, 2, 3, 4, true),
        "the defaults changed: update this test's parameters"
    );
    let z = max_z(
        &statistics(&scene, "restir-pt", &defaults, 1, 200),
        &reference,
    );
    eprintln!("max_depth 4, the defaults: max |z| = {z:.2}");
    assert!(z < Z_MAX, "defaults: max |z| = {z:.2}");
}

/// Shading every input of the last spatial round with its resampling weight (`shade =
/// expected`, the default, which every other test here runs) and the selected sample alone are
/// both unbiased, and the first has no more per-pixel variance (the selection it averages over
/// only changes a path's colour, never its luminance, and this room is nearly grey: on the PT
/// test family's rooms it is 1.07–1.97× the efficiency). The negative controls are the other
/// tests' (the Jacobian omitted, uniform weights, mismatched reciprocal shifts), which run with
/// the default.
#[test]
fn shading_every_input_is_unbiased_and_less_noisy() {
    let scene = scene();
    let reference = statistics(&scene, "path", &[], 128, 64);
    let mut variances = Vec::new();
    let mut images = Vec::new();
    for shade in ["expected", "selected"] {
        // The defaults' reuse (as `unbiased_at_the_defaults`).
        let params = [
            ("radius", "3"),
            ("candidates", "2"),
            ("spatial_rounds", "3"),
            ("neighbors", "4"),
            ("reciprocal", "true"),
            ("shade", shade),
        ];
        let z = max_z(
            &statistics(&scene, "restir-pt", &params, 1, 200),
            &reference,
        );
        eprintln!("shade {shade}: max |z| = {z:.2}");
        assert!(z < Z_MAX, "shade {shade}: max |z| = {z:.2}");
        let render_one = |seed| render_image(&scene, "restir-pt", &params, 1, seed);
        variances.push(pixel_relative_variance(render_one, 24, 2000));
        images.push(render_one(2000).pixels);
    }
    assert!(
        images[0] != images[1],
        "shading every input changed nothing"
    );
    let ratio = variances[0] / variances[1];
    eprintln!("per-pixel relative variance, expected / selected: {ratio:.3}");
    assert!(ratio < 1.01, "{variances:?}");
}

#[test]
fn unbiased_with_unbounded_depth() {
    let scene = scene();
    let reference = statistics(&scene, "path", &[("max_depth", "-1")], 64, 32);
    let pt = statistics(&scene, "restir-pt", &[("max_depth", "-1")], 1, 160);
    let z = max_z(&pt, &reference);
    eprintln!("max_depth -1: max |z| = {z:.2}");
    assert!(z < Z_MAX, "max_depth -1: max |z| = {z:.2}");
    // Direct light only differs from it: the comparison can fail.
    let direct = statistics(&scene, "path", &[("max_depth", "2")], 64, 32);
    let z = max_z(&pt, &direct);
    eprintln!("against direct light only: max |z| = {z:.2}");
    assert!(
        z > 2.0 * Z_MAX,
        "indirect light should be detectable: {z:.2}"
    );
}

/// Delta lobes: glass and smooth plastic at primary hits and at reconnection vertices.
#[test]
fn unbiased_with_glass() {
    let scene = glass_scene();
    let reference = statistics(&scene, "path", &[("max_depth", "5")], 128, 64);
    let pt = statistics(&scene, "restir-pt", &[("max_depth", "5")], 1, 400);
    let z = max_z(&pt, &reference);
    eprintln!("glass, max_depth 5: max |z| = {z:.2}");
    assert!(z < Z_MAX, "glass: max |z| = {z:.2}");
}

/// Blends (Mitsuba's `blendbsdf`): one of a diffuse and a rough conductor (connectible, so paths
/// reconnect at it and the shift evaluates the mix), one of a diffuse and a smooth mirror (a
/// delta component: not connectible), and a two-sided blend in a blend as the partition.
#[test]
fn unbiased_with_blends() {
    let scene = build(
        &scene_text(
            r#"(geometry: Sphere(center: (-0.6, 0.45, 0.6), radius: 0.4),
             material: Some(Inline(Blend(weight: 0.4, bsdfs: (Diffuse(reflectance: (0.2, 0.6, 0.3)),
             RoughConductor(ior: (material: Some("Cu")), roughness: (alpha: 0.3))))))),
            (geometry: Sphere(center: (0.9, 1.2, -0.3), radius: 0.3),
             material: Some(Inline(Blend(weight: 0.5, bsdfs: (Diffuse(reflectance: (0.6, 0.6, 0.6)),
             Conductor()))))),"#,
        )
        .replace(
            "Inline(TwoSided(Diffuse(reflectance: (0.6, 0.6, 0.5))))",
            "Inline(TwoSided(Blend(weight: 0.7, bsdfs: (Diffuse(reflectance: (0.6, 0.6, 0.5)), \
             Blend(weight: 0.5, bsdfs: (Diffuse(reflectance: (0.9, 0.2, 0.2)), \
             RoughPlastic(roughness: (alpha: 0.2))))))))",
        ),
    );
    let reference = statistics(&scene, "path", &[("max_depth", "5")], 128, 64);
    let pt = statistics(&scene, "restir-pt", &[("max_depth", "5")], 1, 400);
    let z = max_z(&pt, &reference);
    eprintln!("blends, max_depth 5: max |z| = {z:.2}");
    assert!(z < Z_MAX, "blends: max |z| = {z:.2}");
}

/// A floor of eight strips, near-specular (a rough conductor with alpha 0.01, not connectible)
/// alternating with diffuse ones, under most of the view: paths from neighbouring pixels often
/// bounce off different kinds of strip, which is what the hybrid shift's invertibility checks
/// are for. No delta lobes.
fn striped_floor_scene(alpha: f32) -> common::Built {
    let conductor = format!("RoughConductor(roughness: (alpha: {alpha}))");
    let strips: String = (0..8)
        .map(|i| {
            let x = -1.75 + 0.5 * i as f32;
            let material = if i % 2 == 0 {
                &conductor
            } else {
                "Diffuse(reflectance: (0.5, 0.6, 0.5))"
            };
            format!(
                "(geometry: Rectangle, to_world: [Scale((0.25, 2, 1)), \
                 Rotate(axis: (1, 0, 0), angle: -90), Translate(({x}, 0.001, 0))], \
                 material: Some(Inline({material}))),"
            )
        })
        .collect();
    scene_with(&strips)
}

/// Pixels brighter than 100× the image mean, summed over renders.
fn fireflies(scene: &common::Built, name: &str, params: &[(&str, &str)], renders: u64) -> usize {
    (0..renders)
        .map(|s| {
            let img = render_image(scene, name, params, 1, 5000 + s);
            let lum = |p: &glam::Vec3| f64::from(p.x + p.y + p.z) / 3.0;
            let mean = img.pixels.iter().map(lum).sum::<f64>() / img.pixels.len() as f64;
            img.pixels.iter().filter(|p| lum(p) > 100.0 * mean).count()
        })
        .sum()
}

/// Reconnection, hybrid and replay against the path tracer with glass (delta lobes) and with a
/// striped near-specular floor (no delta lobes); hybrid without its reconnection Jacobian must
/// fail the same test. Reports the firefly counts against the path tracer's.
#[test]
fn shifts_unbiased_with_glass_and_near_specular() {
    let depth = ("max_depth", "5");
    for (label, scene) in [
        ("glass", glass_scene()),
        ("striped floor", striped_floor_scene(0.01)),
    ] {
        let reference = statistics(&scene, "path", &[depth], 128, 64);
        for shift in ["reconnection", "hybrid", "replay"] {
            let pt = statistics(&scene, "restir-pt", &[depth, ("shift", shift)], 1, 300);
            let z = max_z(&pt, &reference);
            eprintln!("{label}, {shift}: max |z| = {z:.2}");
            assert!(z < Z_MAX, "{label}, {shift}: max |z| = {z:.2}");
        }
        // The footprint reconnection rule with the hybrid shift (which decides more often
        // here than the fixed rule whether a glossy vertex is reconnected at or replayed).
        let params = [depth, ("reconnection", "footprint")];
        let z = max_z(
            &statistics(&scene, "restir-pt", &params, 1, 300),
            &reference,
        );
        eprintln!("{label}, hybrid, footprint rule: max |z| = {z:.2}");
        assert!(z < Z_MAX, "{label}, footprint rule: max |z| = {z:.2}");
        let pt_fireflies = fireflies(&scene, "path", &[depth], 100);
        for shift in ["reconnection", "hybrid"] {
            let f = fireflies(&scene, "restir-pt", &[depth, ("shift", shift)], 100);
            eprintln!(
                "{label}: pixels above 100x the image mean in 100 renders: {shift} {f}, \
                 path tracer {pt_fireflies}"
            );
        }
        if label == "glass" {
            // Temporal reuse (8 passes) with the hybrid shift into the previous pass's pixels.
            let params = [depth, ("temporal", "true")];
            let z = max_z(
                &statistics(&scene, "restir-pt", &params, 8, 150),
                &reference,
            );
            eprintln!("{label}, hybrid, temporal: max |z| = {z:.2}");
            assert!(z < Z_MAX, "{label}, temporal: max |z| = {z:.2}");
            // Direct light (delta reflections of the light included) from ReSTIR DI.
            let params = [depth, ("direct", "restir-di")];
            let z = max_z(
                &statistics(&scene, "restir-pt", &params, 1, 300),
                &reference,
            );
            eprintln!("{label}, hybrid, direct = restir-di: max |z| = {z:.2}");
            assert!(z < Z_MAX, "{label}, direct = restir-di: max |z| = {z:.2}");
            // Reciprocal pairs with the hybrid shift (replayed prefixes shared by a pair).
            let params = [
                depth,
                ("spatial_rounds", "3"),
                ("neighbors", "4"),
                ("radius", "3"),
                ("reciprocal", "true"),
            ];
            let z = max_z(
                &statistics(&scene, "restir-pt", &params, 1, 300),
                &reference,
            );
            eprintln!("{label}, hybrid, reciprocal pairs: max |z| = {z:.2}");
            assert!(z < Z_MAX, "{label}, reciprocal: max |z| = {z:.2}");
            continue;
        }
        // Negative controls, with more reuse (3 rounds of 6 neighbours) to make bias visible.
        let reuse = [depth, ("spatial_rounds", "3"), ("neighbors", "6")];
        let params = [&reuse[..], &[("unit_jacobian", "true")]].concat();
        let z = max_z(
            &statistics(&scene, "restir-pt", &params, 1, 1500),
            &reference,
        );
        eprintln!("{label}, hybrid without the reconnection Jacobian: max |z| = {z:.2}");
        assert!(z > Z_MAX, "J = 1 should be biased: {z:.2}");
        // Skipping the invertibility checks is biased too, but too weakly for this test to
        // see (reported, not asserted; see docs/RESTIR_PT.md).
        let params = [&reuse[..], &[("skip_invertibility", "true")]].concat();
        let z = max_z(
            &statistics(&scene, "restir-pt", &params, 1, 1500),
            &reference,
        );
        eprintln!("{label}, hybrid without invertibility checks: max |z| = {z:.2}");
    }
}

#[test]
fn same_image_for_one_and_two_threads() {
    let scene = scene();
    let run = |threads: usize, params: &[(&str, &str)]| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render_image(&scene, "restir-pt", params, 2, 5))
    };
    for params in [
        &[][..],
        &[
            ("spatial_rounds", "2"),
            ("mis", "balance"),
            ("temporal", "true"),
        ][..],
    ] {
        assert!(
            run(1, params).pixels == run(2, params).pixels,
            "{params:?}: images differ between 1 and 2 threads"
        );
    }
    let c = render_image(&scene, "restir-pt", &[], 2, 6);
    assert!(c.pixels != run(1, &[]).pixels);
}

/// `<integrator type="restir_pt">` selects ReSTIR PT with the XML parameters; command-line
/// options win; an unknown shift is an error naming the supported ones.
#[test]
fn xml_restir_pt_integrator_and_parameters() {
    let xml = r#"<scene version="3.0.0">
        <integrator type="restir_pt">
            <integer name="neighbour_select" value="5"/>
            <integer name="spatial_iteration" value="2"/>
            <integer name="candidates" value="4"/>
            <string name="mis" value="balance"/>
            <integer name="maxDepth" value="6"/>
        </integrator>
        <sensor type="perspective"><float name="fov" value="40"/>
            <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
        </sensor>
        <shape type="rectangle"><bsdf type="diffuse"/></shape>
    </scene>"#;
    let (desc, warnings) = restir_scene::xml::parse_xml(xml, "pt.xml".as_ref(), &[]).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let scene = common::build(&desc, ".".as_ref(), "pt.xml".as_ref());
    let made = make_integrator(&scene, &scene.integrator, &IntegratorOptions::default()).unwrap();
    assert!(made.unused_params.is_empty());
    let d = made.integrator.describe();
    assert!(
        d.starts_with("restir-pt max_depth=6 light_sampler=power (auto: 0 emitters in 0 local lights) candidates=4"),
        "{d}"
    );
    assert!(
        d.contains("neighbors=5") && d.contains("spatial_rounds=2") && d.contains("mis=balance"),
        "{d}"
    );
    let options = IntegratorOptions {
        params: vec![("neighbors", "2")].into(),
        ..Default::default()
    };
    let d = make_integrator(&scene, &scene.integrator, &options)
        .unwrap()
        .integrator
        .describe();
    assert!(
        d.contains("neighbors=2") && d.contains("candidates=4"),
        "{d}"
    );
    let options = IntegratorOptions {
        params: vec![("shift", "replay")].into(),
        ..Default::default()
    };
    let d = make_integrator(&scene, &scene.integrator, &options)
        .unwrap()
        .integrator
        .describe();
    assert!(d.contains("shift=replay"), "{d}");
    let options = IntegratorOptions {
        params: vec![("shift", "manifold")].into(),
        ..Default::default()
    };
    let err = make_integrator(&scene, &scene.integrator, &options).unwrap_err();
    assert!(
        err.to_string().contains("reconnection, replay, hybrid"),
        "{err}"
    );
}

/// `auto` chooses ReSTIR PT by the view pilot: in a room where the camera's paths reach only
/// diffuse surfaces (directly or through smooth glass) lit mostly directly it renders with the
/// path tracer (one light: bit for bit its image) and says why, while `restir-pt` asked for by
/// name runs ReSTIR PT (another image); the glossy room, and the diffuse room lit mostly
/// indirectly (its light behind the partition), get ReSTIR PT from `auto`.
#[test]
fn auto_chooses_restir_pt_by_the_view_pilot() {
    use restir_integrators::restir_pt::{GLOSSY_VIEW_MIN, INDIRECT_VIEW_MIN, view_pilot};
    let made = |scene: &common::Built, name: &str| {
        let options = IntegratorOptions {
            name: Some(name.into()),
            ..Default::default()
        };
        make_integrator(scene, &scene.integrator, &options).unwrap()
    };
    let scene = diffuse_glass_scene(true, "20");
    let view = view_pilot(&scene, scene.integrator.hide_emitters);
    eprintln!(
        "diffuse, lit directly: {view:?}, indirect share {:.3}",
        view.indirect_share()
    );
    assert!(view.reached > 500 && view.glossy == 0, "{view:?}");
    assert!(view.indirect_share() < INDIRECT_VIEW_MIN, "{view:?}");
    let m = made(&scene, "auto");
    assert_eq!(m.integrator.name(), "path");
    assert!(m.integrator.describe().starts_with("path max_depth=4"));
    let why = m.integrator.auto_choice().unwrap();
    assert!(why.contains("first reconnect at a glossy surface"), "{why}");
    assert_eq!(m.notes.len(), 1, "{:?}", m.notes);
    let pt = made(&scene, "restir-pt");
    assert_eq!(pt.integrator.name(), "restir-pt");
    assert!(pt.integrator.auto_choice().is_none() && pt.notes.is_empty());
    let image = |name: &str| common::render_image(&scene, name, &[], 2, 7).pixels;
    assert_eq!(image("auto"), image("path"));
    assert_ne!(image("restir-pt"), image("path"));

    // ReSTIR PT: the glossy room (its rough plastic back wall and rough gold wall in view), and
    // the diffuse room whose light shines at the ceiling from behind the partition.
    let glossy = scene_with("");
    let view = view_pilot(&glossy, glossy.integrator.hide_emitters);
    eprintln!("glossy room: {view:?}");
    assert!(view.glossy_share() >= GLOSSY_VIEW_MIN, "{view:?}");
    let hidden = diffuse_glass_scene(false, "20");
    let view = view_pilot(&hidden, hidden.integrator.hide_emitters);
    eprintln!(
        "diffuse, lit indirectly: {view:?}, indirect share {:.3}",
        view.indirect_share()
    );
    assert!(
        view.glossy == 0 && view.indirect_share() >= INDIRECT_VIEW_MIN,
        "{view:?}"
    );
    for kept in [&glossy, &hidden] {
        let m = made(kept, "auto");
        assert_eq!(m.integrator.name(), "restir-pt", "{:?}", m.notes);
        assert_eq!(
            m.integrator.describe(),
            made(kept, "restir-pt").integrator.describe()
        );
    }
}

/// Duplication-aware history confidence (`duplication`, off by default) is labelled biased: the
/// history's cap depends on its own sample (`docs/GRIS.md` §5), and the statistic that passes
/// temporal reuse without it catches the bias with the same renders.
#[test]
fn duplication_aware_confidence_is_biased_and_labelled() {
    let mut settings = *integrator(4).settings();
    assert_eq!(settings.reuse.duplication, 0.0, "off by default");
    settings.reuse.temporal = true;
    settings.reuse.duplication = 0.8;
    assert!(!settings.is_unbiased());
    let pt = RestirPtIntegrator::new(settings);
    assert!(
        pt.describe().contains("duplication=0.8"),
        "{}",
        pt.describe()
    );
    assert!(pt.describe().ends_with("(biased)"), "{}", pt.describe());
    // Without temporal reuse there is no history to cap.
    settings.reuse.temporal = false;
    assert!(settings.is_unbiased());

    let scene = scene();
    let reference = statistics(&scene, "path", &[], 128, 64);
    let mean = |stats: &[(f64, f64)]| stats.iter().map(|b| b.0).sum::<f64>();
    for s in ["0", "1"] {
        let params = [("temporal", "true"), ("duplication", s)];
        let stats = statistics(&scene, "restir-pt", &params, 16, 400);
        let z = max_z(&stats, &reference);
        let ratio = mean(&stats) / mean(&reference);
        eprintln!("max_depth 4, temporal, duplication {s}: max |z| = {z:.2}, mean {ratio:.4}");
        if s == "0" {
            assert!(z < Z_MAX, "temporal: max |z| = {z:.2}");
        } else {
            assert!(z > Z_MAX, "duplication {s} should be biased: {z:.2}");
        }
    }
}

/// With temporal reuse, rendering twice with one estimator gives the same image twice: a render
/// that does not continue the passes before starts without their history; without it, a render
/// of another size in the buffers the one before left is a fresh estimator's image. Control:
/// temporal reuse changes the image.
#[test]
fn a_second_temporal_render_with_the_same_estimator_is_the_same_image() {
    let scene = scene();
    let params = [("max_depth", "3"), ("temporal", "true")];
    let est = common::make(&scene, "restir-pt", &params);
    let a = common::render_with(&scene, est.as_ref(), 3, 9);
    let b = common::render_with(&scene, est.as_ref(), 3, 9);
    assert!(a.pixels == b.pixels, "the second render differs");
    let plain = common::make(&scene, "restir-pt", &params[..1]);
    assert!(common::render_with(&scene, plain.as_ref(), 3, 9).pixels != a.pixels);
    // Without temporal reuse the next pass reuses a pass's buffers: a render of another size
    // in the buffers of the one before is the same image as a fresh estimator's.
    let other = build(&scene_text("").replace(
        &format!("width: {SIZE}, height: {SIZE}"),
        "width: 40, height: 32",
    ));
    let after = common::render_with(&other, plain.as_ref(), 2, 9);
    assert_eq!(
        (after.width, after.height),
        (40, 32),
        "the size did not change"
    );
    let fresh = common::make(&other, "restir-pt", &params[..1]);
    let alone = common::render_with(&other, fresh.as_ref(), 2, 9);
    assert!(
        after.pixels == alone.pixels,
        "a render after one of another size differs"
    );
}
