//! Next-event estimation by the light hierarchy (`light_sampler = bvh` for the path tracer and
//! ReSTIR PT) estimates the image the power sampler does, block by block over many seeds: the
//! light samples divide by the hierarchy's density, and an emitter a BSDF ray reaches is weighed
//! against that same density. The scene has what the hierarchy decides by: a large dim light
//! near a glossy floor, small bright lights far above it (some facing away), a sphere light (a
//! light sampled whole) and an environment (which keeps its share). The control weighs BSDF
//! rays' emitters against the power sampler's density while the hierarchy draws the light
//! samples: the two strategies' weights no longer sum to one, and the statistic sees it.

use restir_integrators::path::{PathIntegrator, PathSettings};
use restir_integrators::{Integrator, IntegratorOptions, Param, ParamSource, make_integrator};
use restir_lights::NeeSelection;
use restir_scene::parse_ron;

mod common;
use common::{block_statistics, make, max_z, render_image, render_with};

const SIZE: u32 = 32;
const BLOCK: u32 = 8;
const Z_MAX: f64 = 4.5;

fn scene(max_depth: i32) -> common::Built {
    let mut small = String::new();
    for i in 0..16 {
        let (x, z) = ((i % 4) as f32 - 1.5, (i / 4) as f32 - 1.5);
        // Every fourth faces up, away from everything below it.
        let angle = if i % 4 == 3 { -90 } else { 90 };
        small.push_str(&format!(
            "(geometry: Rectangle, to_world: [Scale((0.06, 0.06, 1)), Rotate(axis: (1, 0, 0), angle: {angle}), \
             Translate(({x}, 3.0, {z}))], emission: Some(({r}, 200, 150))),\n",
            r = 100 + 20 * i
        ));
    }
    let ron = format!(
        r#"(
        camera: (fov: 45, to_world: [LookAt(origin: (0, 2, 4), target: (0, 0, 0), up: (0, 1, 0))]),
        film: (width: {SIZE}, height: {SIZE}, filter: Box),
        integrator: (max_depth: {max_depth}),
        shapes: [
            (geometry: Rectangle, to_world: [Scale((3, 3, 1)), Rotate(axis: (1, 0, 0), angle: -90)],
             material: Some(Inline(RoughConductor(roughness: (alpha: 0.15))))),
            (geometry: Cube, to_world: [Scale((0.4, 0.4, 0.4)), Translate((0.6, 0.4, -0.4))],
             material: Some(Inline(Diffuse(reflectance: (0.6, 0.5, 0.4))))),
            (geometry: Rectangle, to_world: [Scale((0.8, 0.5, 1)), Rotate(axis: (1, 0, 0), angle: 30),
             Translate((-0.6, 0.7, -1.0))], emission: Some((1.5, 1.2, 1.0))),
            (geometry: Sphere(center: (1.2, 0.9, 0.6), radius: 0.1), emission: Some((60, 80, 100))),
            {small}
        ],
        lights: [Constant(radiance: (0.05, 0.06, 0.08))],
    )"#
    );
    let desc = parse_ron(&ron, "nee.ron".as_ref()).unwrap();
    common::build(&desc, ".".as_ref(), "nee.ron".as_ref())
}

#[test]
fn hierarchy_nee_is_unbiased_and_weighing_against_the_power_density_is_caught() {
    let s = scene(3);
    let stats = |render: &dyn Fn(u64) -> restir_image::Image, seeds, base| {
        block_statistics(render, seeds, base, BLOCK)
    };
    let reference = stats(
        &|seed| render_image(&s, "path", &[("light_sampler", "power")], 64, seed),
        32,
        0x1000,
    );

    let bvh = stats(
        &|seed| render_image(&s, "path", &[("light_sampler", "bvh")], 64, seed),
        32,
        0x2000,
    );
    let z = max_z(&bvh, &reference);
    eprintln!("path, bvh against power: max |z| = {z:.2}");
    assert!(z < Z_MAX, "path with bvh: max |z| = {z:.2}");

    let pt = make(&s, "restir-pt", &[("light_sampler", "bvh")]);
    let pt_stats = stats(&|seed| render_with(&s, pt.as_ref(), 2, seed), 200, 0x3000);
    let z = max_z(&pt_stats, &reference);
    eprintln!("restir-pt, bvh against path, power: max |z| = {z:.2}");
    assert!(z < Z_MAX, "restir-pt with bvh: max |z| = {z:.2}");

    let control = PathIntegrator {
        settings: PathSettings {
            nee: NeeSelection::HierarchyWeighedByPower,
            nee_rule: restir_integrators::path::NeeRule::Named,
            ..PathSettings::from_desc(&s.integrator)
        },
    };
    let wrong = stats(&|seed| render_with(&s, &control, 64, seed), 32, 0x4000);
    let z = max_z(&wrong, &reference);
    eprintln!("control, weighed against the power density: max |z| = {z:.2}");
    assert!(z > Z_MAX, "the control was not detected: max |z| = {z:.2}");
}

/// `light_sampler = auto` (the default) gives the path tracer and ReSTIR PT the hierarchy for
/// this scene's 18 small lights (rectangles and a sphere, at most two emitters each) and the
/// power sampler to a scene whose one light is a tessellated box (12 triangles), and to one of
/// two such boxes and a point light; the hierarchy again where two point lights join one box
/// (most lights compact, though the box's triangles make the mean 4.7 a light); it says which
/// and why in the settings line; a named selection stays as named.
#[test]
fn auto_decides_by_the_emitters_a_light_holds() {
    let s = scene(3);
    for name in ["path", "restir-pt"] {
        let line = make(&s, name, &[]).describe();
        assert!(
            line.contains(
                "light_sampler=bvh (auto: 35 emitters in 18 local lights; the median light 2)"
            ),
            "{line}"
        );
        let line = make(&s, name, &[("light_sampler", "power")]).describe();
        assert!(
            line.contains("light_sampler=power") && !line.contains("auto:"),
            "{line}"
        );
    }
    // A path tracer made without `make_integrator` (as a library may make one) decides when it
    // renders: the same image as the one `make_integrator` decided for.
    let made = make(&s, "path", &[]);
    let direct = PathIntegrator {
        settings: PathSettings::from_desc(&s.integrator),
    };
    assert!(direct.describe().contains("light_sampler=auto"));
    let (a, b) = (
        render_with(&s, made.as_ref(), 2, 7),
        render_with(&s, &direct, 2, 7),
    );
    assert!(
        a.pixels == b.pixels,
        "an undecided selection renders another image"
    );
    let ron = r#"(
        camera: (fov: 45, to_world: [LookAt(origin: (0, 2, 4), target: (0, 0, 0), up: (0, 1, 0))]),
        film: (width: 8, height: 8, filter: Box),
        integrator: (max_depth: 3),
        shapes: [
            (geometry: Rectangle, to_world: [Scale((3, 3, 1)), Rotate(axis: (1, 0, 0), angle: -90)],
             material: Some(Inline(Diffuse(reflectance: (0.5, 0.5, 0.5))))),
            (geometry: Cube, to_world: [Scale((0.2, 0.2, 0.2)), Translate((0, 1.5, 0))],
             emission: Some((5, 5, 5))),
        ],
    )"#;
    let desc = parse_ron(ron, "lamp.ron".as_ref()).unwrap();
    let lamp = common::build(&desc, ".".as_ref(), "lamp.ron".as_ref());
    let line = make(&lamp, "path", &[]).describe();
    assert!(
        line.contains("light_sampler=power (auto: 12 emitters in 1 local light)"),
        "{line}"
    );
    let line = make(&lamp, "path", &[("light_sampler", "bvh")]).describe();
    assert!(
        line.contains("light_sampler=bvh") && !line.contains("auto:"),
        "{line}"
    );
    let options = IntegratorOptions {
        name: Some("path".into()),
        max_depth: None,
        params: vec![Param::new("light_sampler", "near", ParamSource::Caller)]
            .into_iter()
            .collect(),
        sampler: None,
    };
    let err = make_integrator(&lamp, &lamp.integrator, &options)
        .unwrap_err()
        .to_string();
    assert!(err.contains("expected power, bvh or auto"), "{err}");

    let point = |x: f32| format!("Point(position: ({x}, 1, 0), intensity: (1, 1, 1))");
    let cube = |x: f32| {
        format!(
            "(geometry: Cube, to_world: [Scale((0.2, 0.2, 0.2)), Translate(({x}, 1.5, 0))], \
             emission: Some((5, 5, 5)))"
        )
    };
    for (shapes, lights, expected) in [
        (
            vec![cube(0.0)],
            vec![point(1.0), point(-1.0)],
            "light_sampler=bvh (auto: 14 emitters in 3 local lights; the median light 1)",
        ),
        (
            vec![cube(0.0), cube(1.0)],
            vec![point(-1.0)],
            "light_sampler=power (auto: 25 emitters in 3 local lights; the median light 12)",
        ),
    ] {
        let ron = format!(
            "(camera: (fov: 45), integrator: (max_depth: 3), shapes: [{}], lights: [{}])",
            shapes.join(", "),
            lights.join(", ")
        );
        let desc = parse_ron(&ron, "mixed.ron".as_ref()).unwrap();
        let mixed = common::build(&desc, ".".as_ref(), "mixed.ron".as_ref());
        let line = make(&mixed, "path", &[]).describe();
        assert!(line.contains(expected), "{line}");
    }
}
