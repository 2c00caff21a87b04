//! Furnace test: a convex diffuse sphere of albedo ρ under a constant environment of radiance 1
//! reflects exactly ρ in every direction (no interreflection), whatever the path depth. Every
//! pixel that sees the sphere must average to ρ within 4 standard errors of the pixel mean.

use std::sync::atomic::AtomicBool;

use restir_integrators::{IntegratorOptions, RenderSettings, make_integrator, render};
use restir_scene::{Scene, parse_ron};

fn furnace(rho: f32, max_depth: i32) -> (f64, f64) {
    let ron = format!(
        r#"(
        camera: (fov: 20, to_world: [LookAt(origin: (0, 0, 5), target: (0, 0, 0), up: (0, 1, 0))]),
        film: (width: 16, height: 16, filter: Box),
        integrator: (max_depth: {max_depth}),
        shapes: [(geometry: Sphere(center: (0, 0, 0), radius: 1), material: Some(Inline(Diffuse(reflectance: ({rho}, {rho}, {rho})))))],
        lights: [Constant(radiance: (1, 1, 1))],
    )"#
    );
    let desc = parse_ron(&ron, "furnace.ron".as_ref()).unwrap();
    let scene = Scene::build(&desc, ".".as_ref(), "furnace.ron".as_ref()).unwrap();
    let integrator = make_integrator(&scene, &IntegratorOptions::default())
        .unwrap()
        .integrator;
    let settings = RenderSettings {
        spp: 256,
        time_limit: None,
        seed: 1,
    };
    let out = render(
        &scene,
        integrator.as_ref(),
        &settings,
        &AtomicBool::new(false),
        &mut |_, _| {},
    );
    assert_eq!(out.nonfinite_pixels, 0);
    // The sphere (radius 1 at distance 5, fov 20°) covers the central 8×8 pixels entirely.
    let vals: Vec<f64> = (4..12)
        .flat_map(|y| (4..12).map(move |x| (x, y)))
        .map(|(x, y)| out.image.get(x, y).x as f64)
        .collect();
    let n = vals.len() as f64;
    let mean = vals.iter().sum::<f64>() / n;
    let var = vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[test]
fn white_furnace_sphere() {
    for (rho, depth) in [(0.8, -1), (0.5, 2), (1.0, -1)] {
        let (mean, se) = furnace(rho, depth);
        assert!(
            (mean - rho as f64).abs() < 4.0 * se.max(1e-4),
            "rho {rho}, depth {depth}: mean {mean} (se {se})"
        );
    }
}

/// With max_depth 1 only emitters are visible: the sphere is black.
#[test]
fn depth_one_shows_only_emitters() {
    let (mean, _) = furnace(0.8, 1);
    assert_eq!(mean, 0.0);
}
