//! Environment maps in the integrators.
//!
//! - **Furnace**: a diffuse sphere of albedo ρ under an envmap whose image is one constant
//!   radiance `L` reflects exactly `ρ·L` (a convex object: no interreflection), the same as
//!   under a `constant` emitter. The envmap's direction sampling, its pdf and the MIS weights
//!   of the path tracer all enter; a map scaled by 1.03 must be rejected (negative control).
//! - **ReSTIR DI and ReSTIR PT** on a scene lit only by a strongly varying envmap (a small bright
//!   "sun", a coloured band, a black quadrant) match the path tracer block by block within the
//!   standard error across seeds; the same test rejects a reference rendered with the map 5 %
//!   brighter (negative control).
//! - The corpus's matpreview (plane texture replaced by a plain reflectance, since textured
//!   materials are not wired yet) renders without non-finite pixels.

use std::path::{Path, PathBuf};

use glam::Vec3;
use restir_integrators::Image;
use restir_scene::parse_ron;
use restir_testkit::TempDir;

mod common;
use common::{block_statistics, max_z, render_image};

/// A fresh directory per test (tests run in parallel), removed when the test ends.
fn temp_dir(test: &str) -> TempDir {
    TempDir::new("envmap-int", test)
}

/// Writes a `w × h` EXR with texel `f(x, y)` (row 0 at the top).
fn write_exr(path: &Path, w: usize, h: usize, f: impl Fn(usize, usize) -> [f32; 3]) {
    let mut img = Image::new(w as u32, h as u32);
    for y in 0..h {
        for x in 0..w {
            img.pixels[y * w + x] = Vec3::from(f(x, y));
        }
    }
    img.write(path).unwrap();
}

fn build(ron: &str) -> common::Built {
    let desc = parse_ron(ron, "envmap-test.ron".as_ref()).unwrap();
    common::build(&desc, ".".as_ref(), "envmap-test.ron".as_ref())
}

// ------------------------------------------------------------------------------------------
// Furnace
// ------------------------------------------------------------------------------------------

fn furnace_scene(light: &str) -> common::Built {
    build(&format!(
        r#"(
        camera: (fov: 20, to_world: [LookAt(origin: (0, 0, 5), target: (0, 0, 0), up: (0, 1, 0))]),
        film: (width: 16, height: 16, filter: Box),
        integrator: (max_depth: -1),
        shapes: [(geometry: Sphere(center: (0, 0, 0), radius: 1),
                  material: Some(Inline(Diffuse(reflectance: (0.8, 0.8, 0.8)))))],
        lights: [{light}],
    )"#
    ))
}

/// Largest |z| over four 4×4 blocks of the sphere's central 8×8 pixels and the three channels
/// against `expected`, with each block's standard error estimated across `seeds` renders.
fn furnace_z(scene: &common::Built, expected: [f64; 3], seeds: u64) -> f64 {
    let blocks: Vec<[[f64; 3]; 4]> = (0..seeds)
        .map(|s| {
            let img = render_image(scene, "path", &[], 16, 300 + s);
            let mut b = [[0.0; 3]; 4];
            for y in 4..12 {
                for x in 4..12 {
                    let p = img.get(x, y);
                    let k = ((y - 4) / 4 * 2 + (x - 4) / 4) as usize;
                    for c in 0..3 {
                        b[k][c] += p[c] as f64 / 16.0;
                    }
                }
            }
            b
        })
        .collect();
    let n = seeds as f64;
    let mut worst = 0.0f64;
    for k in 0..4 {
        for (c, want) in expected.iter().enumerate() {
            let mean = blocks.iter().map(|b| b[k][c]).sum::<f64>() / n;
            let var = blocks.iter().map(|b| (b[k][c] - mean).powi(2)).sum::<f64>() / (n - 1.0);
            let se = (var / n).sqrt().max(1e-6 * want);
            worst = worst.max((mean - want).abs() / se);
        }
    }
    worst
}

/// 4 blocks × 3 channels.
const FURNACE_Z: f64 = 4.0;

#[test]
fn furnace_constant_envmap_equals_constant_emitter() {
    let dir = temp_dir("furnace");
    let l = [0.5f32, 1.0, 2.0];
    let map = dir.join("const.exr");
    write_exr(&map, 32, 16, |_, _| l);
    let expected = l.map(|c| 0.8 * c as f64);
    let constant = furnace_scene(&format!(
        "Constant(radiance: ({}, {}, {}))",
        l[0], l[1], l[2]
    ));
    let z = furnace_z(&constant, expected, 32);
    eprintln!("constant emitter: max |z| = {z:.2}");
    assert!(z < FURNACE_Z, "constant emitter: max |z| = {z:.2}");
    let envmap = furnace_scene(&format!(
        "Envmap(filename: \"{}\", to_world: [Rotate(axis: (1, 2, 0), angle: 30)])",
        map.display()
    ));
    let z = furnace_z(&envmap, expected, 32);
    eprintln!("constant envmap: max |z| = {z:.2}");
    assert!(z < FURNACE_Z, "constant envmap: max |z| = {z:.2}");
    // Negative control: 3 % more radiance is detected.
    let brighter = furnace_scene(&format!(
        "Envmap(filename: \"{}\", scale: 1.03)",
        map.display()
    ));
    let z = furnace_z(&brighter, expected, 32);
    eprintln!("envmap × 1.03: max |z| = {z:.2}");
    assert!(
        z > 2.0 * FURNACE_Z,
        "a 3 % error went unnoticed: max |z| = {z:.2}"
    );
}

// ------------------------------------------------------------------------------------------
// ReSTIR against the path tracer
// ------------------------------------------------------------------------------------------

const SIZE: u32 = 32;
const BLOCK: u32 = 8;

/// A floor, a wall and a cube lit only by a strongly varying envmap.
fn sky_scene(map: &Path, scale: f32, max_depth: i32) -> common::Built {
    build(&sky_scene_text(map, scale, max_depth))
}

/// The RON text of [`sky_scene`].
fn sky_scene_text(map: &Path, scale: f32, max_depth: i32) -> String {
    format!(
        r#"(
        camera: (fov: 50, to_world: [LookAt(origin: (0, 4, 3), target: (0, 0, 0), up: (0, 1, 0))]),
        film: (width: {SIZE}, height: {SIZE}, filter: Box),
        integrator: (max_depth: {max_depth}),
        shapes: [
            (geometry: Rectangle, to_world: [Scale((3, 3, 1)), Rotate(axis: (1, 0, 0), angle: -90)],
             material: Some(Inline(Diffuse(reflectance: (0.6, 0.5, 0.4))))),
            (geometry: Rectangle, to_world: [Scale((3, 1.5, 1)), Rotate(axis: (0, 1, 0), angle: -90),
             Translate((1.8, 1.5, 0))], material: Some(Inline(Diffuse(reflectance: (0.9, 0.9, 0.9))))),
            (geometry: Cube, to_world: [Scale((0.5, 0.5, 0.5)), Translate((-0.4, 0.5, 0.2))],
             material: Some(Inline(RoughConductor(roughness: (alpha: 0.3))))),
        ],
        lights: [Envmap(filename: "{}", scale: {scale}, to_world: [Rotate(axis: (0, 1, 0), angle: 40)])],
    )"#,
        map.display()
    )
}

fn sky_map(dir: &Path) -> PathBuf {
    let path = dir.join("sky.exr");
    write_exr(&path, 64, 32, |x, y| {
        if (40..43).contains(&x) && (7..9).contains(&y) {
            return [400.0, 350.0, 300.0]; // the sun
        }
        if x < 16 && y < 16 {
            return [0.0; 3];
        }
        let band = if (10..14).contains(&y) { 0.6 } else { 0.0 };
        [0.2 + band, 0.3, 0.5 + 0.3 * (x as f32 * 0.3).sin()]
    });
    path
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

/// 16 blocks per comparison.
const Z_MAX: f64 = 4.0;

#[test]
fn restir_di_and_pt_with_envmap_match_path_tracer() {
    let dir = temp_dir("sky");
    let map = sky_map(&dir);

    // Direct light (max_depth 2): ReSTIR DI.
    let scene = sky_scene(&map, 1.0, 2);
    let reference = statistics(&scene, "path", &[], 64, 24);
    let di = statistics(&scene, "restir-di", &[("candidates", "8")], 1, 120);
    let z = max_z(&di, &reference);
    eprintln!("restir-di: max |z| = {z:.2}");
    assert!(z < Z_MAX, "restir-di: max |z| = {z:.2}");
    // Negative control: the same test rejects a 5 % brighter map.
    let brighter = statistics(&sky_scene(&map, 1.05, 2), "path", &[], 64, 24);
    let z = max_z(&di, &brighter);
    eprintln!("restir-di vs map × 1.05: max |z| = {z:.2}");
    assert!(z > Z_MAX, "a 5 % error went unnoticed: max |z| = {z:.2}");
    // BSDF candidates that reach the map, resampled with the light candidates.
    let params = [
        ("candidates", "8"),
        ("bsdf_samples", "resampled"),
        ("bsdf_diffuse", "on"),
    ];
    let z = max_z(
        &statistics(&scene, "restir-di", &params, 1, 120),
        &reference,
    );
    eprintln!("restir-di, resampled BSDF samples: max |z| = {z:.2}");
    assert!(
        z < Z_MAX,
        "restir-di, resampled BSDF samples: max |z| = {z:.2}"
    );

    // Global illumination (max_depth 4): ReSTIR PT.
    let scene = sky_scene(&map, 1.0, 4);
    let reference = statistics(&scene, "path", &[], 64, 24);
    let pt = statistics(&scene, "restir-pt", &[], 1, 120);
    let z = max_z(&pt, &reference);
    eprintln!("restir-pt: max |z| = {z:.2}");
    assert!(z < Z_MAX, "restir-pt: max |z| = {z:.2}");
}

/// The sky scene with two small bright area lights beside the envmap: the scene build picks the
/// environment's share of light samples from a pilot. Whatever the share, every estimator
/// converges to the same image: the path tracer, ReSTIR DI and ReSTIR PT at the pilot's share
/// match the path tracer at a share of one half.
#[test]
fn environment_share_beside_area_lights_is_unbiased() {
    let dir = temp_dir("sky-lights");
    let map = sky_map(&dir);
    let lit = |max_depth: i32| {
        let base = sky_scene_text(&map, 1.0, max_depth);
        let lights = r#"
            (geometry: Rectangle, to_world: [Scale((0.1, 0.1, 1)), Rotate(axis: (1, 0, 0), angle: 90),
             Translate((-0.8, 1.2, -0.6))], emission: Some((60, 50, 40))),
            (geometry: Rectangle, to_world: [Scale((0.05, 0.05, 1)), Rotate(axis: (1, 0, 0), angle: 90),
             Translate((0.6, 0.9, 0.8))], emission: Some((40, 60, 80))),
        ],
        lights: ["#;
        build(&base.replacen("],\n        lights: [", lights, 1))
    };
    for (max_depth, name, params, seeds) in [
        (2, "path", vec![], 24),
        (2, "restir-di", vec![("candidates", "8")], 120),
        (4, "restir-pt", vec![], 120),
    ] {
        let scene = lit(max_depth);
        let decided = scene
            .features
            .environment_share
            .expect("a share is decided");
        assert!(decided.receivers > 0);
        assert!(
            (decided.share - decided.power_share).abs() > 0.01,
            "the pilot moved the share: {decided:?}"
        );
        let mut half = lit(max_depth);
        half.lights.set_environment_share(0.5);
        let reference = statistics(&half, "path", &[], 64, 24);
        let spp = if name == "path" { 64 } else { 1 };
        let test = statistics(&scene, name, &params, spp, seeds);
        let z = max_z(&test, &reference);
        eprintln!(
            "{name} at share {:.3} (power share {:.3}) vs path at 0.5: max |z| = {z:.2}",
            decided.share, decided.power_share
        );
        assert!(z < Z_MAX, "{name}: max |z| = {z:.2}");
    }
}

// ------------------------------------------------------------------------------------------
// Corpus
// ------------------------------------------------------------------------------------------

restir_testkit::corpus_test! {
/// The corpus's matpreview with its envmap, glass and meshes (the plane's checkerboard replaced
/// by a grey reflectance, file paths made absolute) renders at 32×24 without non-finite pixels
/// in every estimator.
fn matpreview_renders() {
    let corpus = restir_testkit::corpus_dir().join("lajolla/matpreview");
    let xml = std::fs::read_to_string(corpus.join("matpreview.xml")).unwrap();
    let abs = |f: &str| corpus.join(f).display().to_string();
    let xml = xml
        .replace(
            "value=\"matpreview.serialized\"",
            &format!("value=\"{}\"", abs("matpreview.serialized")),
        )
        .replace(
            "value=\"envmap.exr\"",
            &format!("value=\"{}\"", abs("envmap.exr")),
        )
        .replace(
            "<ref name=\"reflectance\" id=\"__planetex\"/>",
            "<rgb name=\"reflectance\" value=\"0.3\"/>",
        )
        .replace("value=\"683\"", "value=\"32\"")
        .replace("value=\"512\"", "value=\"24\"");
    let dir = temp_dir("matpreview");
    let path = dir.join("matpreview.xml");
    std::fs::write(&path, xml).unwrap();
    let loaded = restir_scene::load_scene(&path, &restir_scene::LoadOptions::default()).unwrap();
    let scene = common::Built::from(loaded);
    assert!(scene.features.has_environment);
    for name in ["path", "restir-di", "restir-pt"] {
        let img = render_image(&scene, name, &[], 4, 1);
        let mean = img.pixels.iter().map(|p| p.x + p.y + p.z).sum::<f32>();
        assert!(mean > 0.0, "{name}: black image");
    }
}
}
