//! Furnace tests: a convex object under a constant environment of radiance 1.
//!
//! - A diffuse sphere of albedo ρ reflects exactly ρ in every direction (no interreflection),
//!   whatever the path depth.
//! - A smooth dielectric sphere conserves energy (R + T = 1 at every interface) and, with the
//!   radiance scaling by 1/η² on entering and η² on leaving, is invisible: every pixel is 1.
//! - A null sphere is invisible too.
//! - A rough dielectric or rough mirror sphere loses some energy (single-scattering microfacets)
//!   but never gains any.
//!
//! Pixel means are compared within 4 standard errors of the mean over the covered pixels.

mod common;

use std::sync::atomic::AtomicBool;

use restir_integrators::{IntegratorOptions, RenderJob, make_integrator, render};
use restir_scene::parse_ron;

/// Mean and standard error over the pixels covered by a unit sphere of `material` (RON), seen
/// under a constant environment of radiance 1.
fn furnace(material: &str, max_depth: i32, seed: u64) -> (f64, f64) {
    let ron = format!(
        r#"(
        camera: (fov: 20, to_world: [LookAt(origin: (0, 0, 5), target: (0, 0, 0), up: (0, 1, 0))]),
        film: (width: 16, height: 16, filter: Box),
        integrator: (max_depth: {max_depth}),
        shapes: [(geometry: Sphere(center: (0, 0, 0), radius: 1), material: Some(Inline({material})))],
        lights: [Constant(radiance: (1, 1, 1))],
    )"#
    );
    let desc = parse_ron(&ron, "furnace.ron".as_ref()).unwrap();
    let scene = common::build(&desc, ".".as_ref(), "furnace.ron".as_ref());
    let integrator = make_integrator(&scene, &scene.integrator, &IntegratorOptions::default())
        .unwrap()
        .integrator;
    let settings = RenderJob {
        spp: 256,
        seed,
        ..RenderJob::default()
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
        let (mean, se) = furnace(
            &format!("Diffuse(reflectance: ({rho}, {rho}, {rho}))"),
            depth,
            1,
        );
        assert!(
            (mean - rho).abs() < 4.0 * se.max(1e-4),
            "rho {rho}, depth {depth}: mean {mean} (se {se})"
        );
    }
}

/// With max_depth 1 only emitters are visible: the sphere is black.
#[test]
fn depth_one_shows_only_emitters() {
    let (mean, _) = furnace("Diffuse(reflectance: (0.8, 0.8, 0.8))", 1, 1);
    assert_eq!(mean, 0.0);
}

#[test]
fn smooth_dielectric_and_null_spheres_are_invisible() {
    for m in ["Dielectric()", "Dielectric(int_ior: 2.4)", "Null"] {
        let (mean, se) = furnace(m, -1, 3);
        assert!(
            (mean - 1.0).abs() < 4.0 * se.max(1e-4),
            "{m}: mean {mean} (se {se})"
        );
    }
}

#[test]
fn rough_spheres_do_not_gain_energy() {
    for m in [
        "RoughDielectric(roughness: (alpha: 0.3))",
        "RoughDielectric(roughness: (distribution: ggx, alpha: 0.1))",
        "RoughConductor(roughness: (alpha: 0.3))",
        "TwoSided(RoughPlastic(diffuse_reflectance: (1, 1, 1)))",
    ] {
        let (mean, se) = furnace(m, -1, 3);
        assert!(
            mean <= 1.0 + 4.0 * se.max(1e-4),
            "{m}: mean {mean} (se {se})"
        );
        assert!(mean > 0.7, "{m}: mean {mean} (se {se}) lost too much");
    }
}
