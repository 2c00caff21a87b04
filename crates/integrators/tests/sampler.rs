//! The path tracer drawing from Owen-scrambled Sobol sequences (`sampler: Sobol`) estimates the
//! same image as with independent numbers, block by block over many seeds (each seed is an
//! independent scramble), and with less variance where the integrand is smooth. The control: a
//! light 1 % brighter, rendered with independent numbers, is told apart by the same statistic.

use restir_scene::parse_ron;

mod common;
use common::{block_statistics, max_z, render_image};

const SIZE: u32 = 32;
const BLOCK: u32 = 8;
const Z_MAX: f64 = 4.5;
const PASSES: u32 = 16;
const SEEDS: u64 = 64;

/// A diffuse floor and a glossy sphere under a rectangular area light, depth 3 (direct light
/// and one indirect bounce): soft shadows, a smooth integrand in the first dimensions.
fn scene(sampler: &str, emission: f32) -> common::Built {
    let ron = format!(
        r#"(
        camera: (fov: 40, to_world: [LookAt(origin: (0, 1.5, 4), target: (0, 0, 0), up: (0, 1, 0))]),
        film: (width: {SIZE}, height: {SIZE}, filter: Box),
        integrator: (max_depth: 3, sampler: {sampler}),
        shapes: [
            (geometry: Rectangle, to_world: [Scale((3, 3, 1)), Rotate(axis: (1, 0, 0), angle: -90), Translate((0, -0.5, 0))],
             material: Some(Inline(Diffuse(reflectance: (0.7, 0.6, 0.5))))),
            (geometry: Sphere(center: (0, 0, 0), radius: 0.5),
             material: Some(Inline(Diffuse(reflectance: (0.3, 0.5, 0.7))))),
            (geometry: Rectangle, to_world: [Scale((0.5, 0.5, 1)), Rotate(axis: (1, 0, 0), angle: 90), Translate((0.4, 1.5, 0.2))],
             emission: Some(({emission}, {emission}, {emission}))),
        ],
    )"#
    );
    let desc = parse_ron(&ron, "sampler.ron".as_ref()).unwrap();
    common::build(&desc, ".".as_ref(), "sampler.ron".as_ref())
}

fn stats(scene: &common::Built, seed_base: u64) -> Vec<(f64, f64)> {
    block_statistics(
        |seed| render_image(scene, "path", &[], PASSES, seed),
        SEEDS,
        seed_base,
        BLOCK,
    )
}

#[test]
fn sobol_samples_estimate_the_independent_image() {
    let independent = stats(&scene("Independent", 10.0), 0x5a);
    let sobol = stats(&scene("Sobol", 10.0), 0x5b);
    let z = max_z(&sobol, &independent);
    eprintln!("sobol against independent: max |z| = {z:.2}");
    assert!(z < Z_MAX, "max |z| = {z:.2}");

    // Stratified over the passes: the mean standard error of a block is smaller.
    let mean_se = |s: &[(f64, f64)]| s.iter().map(|b| b.1).sum::<f64>() / s.len() as f64;
    let ratio = mean_se(&sobol) / mean_se(&independent);
    eprintln!("standard error, sobol / independent: {ratio:.3}");
    assert!(ratio < 0.9, "standard error ratio {ratio:.3}");

    // Control: a 1 % brighter light is seen by the same statistic.
    let brighter = stats(&scene("Independent", 10.1), 0x5c);
    let z = max_z(&sobol, &brighter);
    eprintln!("control, sobol against a 1 % brighter light: max |z| = {z:.2}");
    assert!(z > Z_MAX, "the control was not detected: max |z| = {z:.2}");
}

#[test]
fn sobol_renders_do_not_depend_on_threads() {
    let s = scene("Sobol", 10.0);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| render_image(&s, "path", &[], 4, 9));
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
        .install(|| render_image(&s, "path", &[], 4, 9));
    assert_eq!(one.pixels, two.pixels);
}
