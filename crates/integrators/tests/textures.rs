//! A textured material renders its texture, through every estimator: a one-sided diffuse plane
//! (Mitsuba's `rectangle`, facing the camera) whose reflectance is a checkerboard, under a
//! constant environment of radiance `L` and nothing else. The plane sees the whole upper
//! hemisphere of the environment, so the radiance it sends to the camera is exactly `ρ(uv)·L`:
//! `color0·L` on one set of checks and `color1·L` on the other.
//!
//! Which check a pixel sees is decided independently of the texture code: the corners of the
//! pixel's footprint (box filter) are traced to the plane and their world positions mapped to
//! Mitsuba's rectangle uv `((x + 1)/2, (y + 1)/2)` and the check parity by hand; pixels whose
//! corners disagree straddle a check boundary and are left out. Per seed, the mean of each
//! region's pixels is one estimate; seeds are independent (ReSTIR's spatial reuse correlates
//! pixels within a render, not across seeds), so the standard error comes from the spread of the
//! seed means. Each region's mean must match its colour within 4 standard errors per channel.
//! The negative control expects the colours swapped (what a flipped `v` or a texture lookup at
//! the wrong point would give) and must fail.

mod common;

use std::sync::atomic::AtomicBool;

use glam::{Vec2, Vec3};
use restir_integrators::{IntegratorOptions, RenderJob, make_integrator, render};
use restir_scene::{Scene, parse_ron};

const COLOR0: [f64; 3] = [0.8, 0.5, 0.2];
const COLOR1: [f64; 3] = [0.1, 0.3, 0.9];
const RADIANCE: f64 = 1.5;
const SIZE: u32 = 24;
/// Checks per unit of uv along each axis (2 × 2 per unit square, Mitsuba's checkerboard).
const UV_SCALE: f32 = 2.0;

fn scene() -> common::Built {
    let [a, b, c] = COLOR0;
    let [d, e, f] = COLOR1;
    let ron = format!(
        r#"(
        camera: (fov: 30, to_world: [LookAt(origin: (0.1, 0.05, 3), target: (0.1, 0.05, 0), up: (0, 1, 0))]),
        film: (width: {SIZE}, height: {SIZE}, filter: Box),
        integrator: (max_depth: 2),
        shapes: [
            (geometry: Rectangle, material: Some(Inline(Textured(
                material: Diffuse(reflectance: (0.5, 0.5, 0.5)),
                textures: [(param: Reflectance, texture: Checkerboard(
                    color0: ({a}, {b}, {c}), color1: ({d}, {e}, {f}),
                    uv: (scale: ({UV_SCALE}, {UV_SCALE}), offset: (0, 0))))],
            )))),
        ],
        lights: [Constant(radiance: ({RADIANCE}, {RADIANCE}, {RADIANCE}))],
    )"#
    );
    let desc = parse_ron(&ron, "textured-plane.ron".as_ref()).unwrap();
    common::build(&desc, ".".as_ref(), "textured-plane.ron".as_ref())
}

/// The check (0 → `color0`, 1 → `color1`) at a world point of the rectangle, by hand.
fn check_at(p: Vec3) -> usize {
    let uv = Vec2::new(0.5 * (p.x + 1.0), 0.5 * (p.y + 1.0)) * UV_SCALE;
    let (fu, fv) = (uv.x - uv.x.floor(), uv.y - uv.y.floor());
    usize::from((fu > 0.5) != (fv > 0.5))
}

/// For each pixel, the check its whole footprint lies in, or `None` if it straddles two or
/// misses the plane.
fn pixel_checks(scene: &Scene) -> Vec<Option<usize>> {
    let mut out = Vec::new();
    for y in 0..SIZE {
        for x in 0..SIZE {
            let mut checks = Vec::new();
            for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5)] {
                let film = Vec2::new(x as f32 + dx, y as f32 + dy);
                let ray = scene.camera.generate_ray(film, Vec2::splat(0.5));
                checks.push(scene.intersect(&ray).map(|si| check_at(si.p)));
            }
            let first = checks[0];
            out.push(if checks.iter().all(|c| *c == first) {
                first
            } else {
                None
            });
        }
    }
    out
}

/// Per region (check 0, check 1) and channel: mean over seeds of the region's pixel mean, and
/// its standard error.
fn estimate(scene: &common::Built, integrator: &str, seeds: u64, spp: u32) -> [[(f64, f64); 3]; 2] {
    let checks = pixel_checks(scene);
    for k in 0..2 {
        let n = checks.iter().filter(|c| **c == Some(k)).count();
        assert!(n >= 40, "region {k} has only {n} whole pixels");
    }
    let options = IntegratorOptions {
        name: Some(integrator.into()),
        ..Default::default()
    };
    let made = make_integrator(scene, &scene.integrator, &options).unwrap();
    let mut seed_means: [[Vec<f64>; 3]; 2] = Default::default();
    for seed in 0..seeds {
        let settings = RenderJob {
            spp,
            seed: 77 + seed,
            ..RenderJob::default()
        };
        let out = render(
            scene,
            made.integrator.as_ref(),
            &settings,
            &AtomicBool::new(false),
            &mut |_, _| {},
        );
        assert_eq!(out.nonfinite_pixels, 0);
        for (k, region) in seed_means.iter_mut().enumerate() {
            let pixels: Vec<_> = out
                .image
                .pixels
                .iter()
                .zip(&checks)
                .filter(|(_, c)| **c == Some(k))
                .map(|(p, _)| *p)
                .collect();
            for (c, means) in region.iter_mut().enumerate() {
                means.push(pixels.iter().map(|p| p[c] as f64).sum::<f64>() / pixels.len() as f64);
            }
        }
    }
    seed_means.map(|region| {
        region.map(|v| {
            let n = v.len() as f64;
            let mean = v.iter().sum::<f64>() / n;
            let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (mean, (var / n).sqrt())
        })
    })
}

/// Whether every region and channel matches `expected[region]·L` within 4 standard errors.
fn matches(est: &[[(f64, f64); 3]; 2], expected: [[f64; 3]; 2]) -> Result<(), String> {
    for k in 0..2 {
        for c in 0..3 {
            let (mean, se) = est[k][c];
            let want = expected[k][c] * RADIANCE;
            if (mean - want).abs() > 4.0 * se {
                return Err(format!(
                    "check {k} channel {c}: {mean:.5} ± {se:.5}, expected {want:.5}"
                ));
            }
        }
    }
    Ok(())
}

fn check_integrator(name: &str, seeds: u64, spp: u32) {
    let scene = scene();
    assert!(scene.features.has_textures);
    let est = estimate(&scene, name, seeds, spp);
    matches(&est, [COLOR0, COLOR1]).unwrap_or_else(|e| panic!("{name}: {e}"));
    // Negative control: the colours the other way round are rejected.
    assert!(
        matches(&est, [COLOR1, COLOR0]).is_err(),
        "{name}: the test cannot tell the checks apart"
    );
}

#[test]
fn textured_plane_path() {
    check_integrator("path", 16, 2);
}

#[test]
fn textured_plane_restir_di() {
    check_integrator("restir-di", 16, 2);
}

#[test]
fn textured_plane_restir_pt() {
    check_integrator("restir-pt", 16, 2);
}
