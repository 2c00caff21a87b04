//! Thread-count determinism: every pixel's random numbers come from `(seed, pixel, pass)`, so the
//! same seed gives a bit-identical image (and ray count) with 1, 2 or 3 worker threads, while a
//! different seed gives a different image.

mod common;

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use restir_integrators::{
    Image, IntegratorOptions, RenderJob, RenderOutput, make_integrator, render,
};
use restir_scene::load_desc;

fn scene_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name)
}

/// Loads a shipped scene at `size`×`size` pixels.
fn load(name: &str, size: u32) -> common::Built {
    let path = scene_path(name);
    let (mut desc, _) = load_desc(&path, &[]).unwrap();
    desc.film.width = size;
    desc.film.height = size;
    common::build(&desc, path.parent().unwrap(), &path)
}

fn render_with_threads(scene: &common::Built, threads: usize, seed: u64, spp: u32) -> RenderOutput {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    assert_eq!(pool.current_num_threads(), threads);
    let integrator = make_integrator(scene, &scene.integrator, &IntegratorOptions::default())
        .unwrap()
        .integrator;
    let settings = RenderJob {
        spp,
        seed,
        ..RenderJob::default()
    };
    pool.install(|| {
        render(
            scene,
            integrator.as_ref(),
            &settings,
            &AtomicBool::new(false),
            &mut |_, _| {},
        )
    })
}

fn bits(image: &Image) -> Vec<[u32; 3]> {
    image
        .pixels
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect()
}

fn check(name: &str, size: u32, spp: u32) {
    let scene = load(name, size);
    let one = render_with_threads(&scene, 1, 7, spp);
    assert_eq!(one.nonfinite_pixels, 0, "{name}");
    assert!(
        one.image.pixels.iter().any(|p| p.max_element() > 0.0),
        "{name}: black image"
    );
    for threads in [2, 3] {
        let many = render_with_threads(&scene, threads, 7, spp);
        assert_eq!(one.rays, many.rays, "{name}: rays with {threads} threads");
        assert!(
            bits(&one.image) == bits(&many.image),
            "{name}: 1 thread and {threads} threads differ"
        );
    }
    // Negative control: another seed must change the image (so the comparison above can fail).
    let other = render_with_threads(&scene, 2, 8, spp);
    let differing = bits(&one.image)
        .iter()
        .zip(bits(&other.image))
        .filter(|(a, b)| **a != *b)
        .count();
    assert!(
        differing > one.image.pixels.len() / 2,
        "{name}: seed 8 changed only {differing} pixels"
    );
}

#[test]
fn cornell_box_is_bit_identical_across_thread_counts() {
    check("cornell-box.xml", 40, 4);
}

#[test]
fn many_lights_is_bit_identical_across_thread_counts() {
    check("many-lights.ron", 40, 4);
}
