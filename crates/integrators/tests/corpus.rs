//! Renders every scene of the shared corpus (`../shared/corpus` beside the workspace) at a small
//! size with the path tracer and checks the images: finite, not black, not flat, and (for the
//! Cornell box) the colours where they belong. The scene's own integrator settings are used
//! except the resolution and the sample count. When the corpus was absent at build time the test is
//! ignored (`restir_testkit::corpus_test!`); under CI (`CI` set) it runs and fails without it.

mod common;

use std::path::Path;

use restir_integrators::Image;
use restir_scene::load_desc;

const SIZE: u32 = 24;

/// Loads `rel` with its film set to `SIZE`×`SIZE` (keeping the aspect ratio's orientation is not
/// needed for these checks).
fn small_scene(dir: &Path, rel: &str) -> common::Built {
    let path = dir.join(rel);
    let (mut desc, _) = load_desc(&path, &[]).unwrap_or_else(|e| panic!("{rel}: {e}"));
    desc.film.width = SIZE;
    desc.film.height = SIZE;
    common::try_build(&desc, path.parent().unwrap(), &path).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// Mean and standard deviation of the pixels' channel averages.
fn mean_std(img: &Image) -> (f64, f64) {
    let v: Vec<f64> = img
        .pixels
        .iter()
        .map(|p| f64::from(p.x + p.y + p.z) / 3.0)
        .collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
    (mean, var.sqrt())
}

restir_testkit::corpus_test! {
fn every_corpus_scene_renders() {
    let dir = restir_testkit::corpus_dir();
    for rel in [
        "lajolla/cbox/cbox.xml",
        "lajolla/veach_mi/mi.xml",
        "lajolla/matpreview/matpreview.xml",
        "lajolla/sponza/sponza.xml",
        "lajolla/pixel_filter_test/pixel_filter_test.xml",
        "restir_test_scene/test.xml",
    ] {
        let scene = small_scene(&dir, rel);
        // `render_image` asserts that every pixel is finite.
        let img = common::render_image(&scene, "path", &[], 8, 1);
        let (mean, std) = mean_std(&img);
        assert!(mean > 1e-3, "{rel}: black image (mean {mean})");
        assert!(
            std > 1e-3 * mean,
            "{rel}: flat image (mean {mean}, std {std})"
        );
        if rel.ends_with("cbox.xml") {
            // The red wall is on the image's left, the green one on its right (rows in the
            // middle, outer sixth of the columns).
            let side = |x0: u32, x1: u32| {
                let mut s = glam::Vec3::ZERO;
                for y in SIZE / 3..2 * SIZE / 3 {
                    for x in x0..x1 {
                        s += img.pixels[(y * SIZE + x) as usize];
                    }
                }
                s
            };
            let (left, right) = (side(0, SIZE / 6), side(SIZE - SIZE / 6, SIZE));
            assert!(left.x > 1.5 * left.y, "cbox: left wall not red: {left}");
            assert!(
                right.y > 1.5 * right.x,
                "cbox: right wall not green: {right}"
            );
        }
    }
}
}
