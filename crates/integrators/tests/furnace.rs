//! Furnace tests: a convex object under a constant environment of radiance 1.
//!
//! - A diffuse sphere of albedo ρ reflects exactly ρ in every direction (no interreflection),
//!   whatever the path depth.
//! - A smooth dielectric sphere conserves energy (R + T = 1 at every interface) and, with the
//!   radiance scaling by 1/η² on entering and η² on leaving, is invisible: every pixel is 1.
//! - A null sphere is invisible too, and so is a thin dielectric one (its sheets reflect and
//!   transmit all, and transmit without bending or scaling).
//! - A thin dielectric pane that reflects nothing shows the environment through it at its
//!   transmittance `1 − 2r/(1 + r)`, the light bounced between its faces included (negative
//!   control: one face's `1 − r` is rejected).
//! - A rough dielectric or rough mirror sphere loses some energy (single-scattering microfacets)
//!   but never gains any.
//!
//! Pixel means are compared within 4 standard errors of the mean over the covered pixels.

mod common;

use restir_integrators::{IntegratorOptions, make_integrator};
use restir_scene::parse_ron;

/// Mean and standard error over `pixels` of the scene `ron` rendered by its integrator (256
/// passes, seed `seed`).
fn pixel_mean(ron: &str, pixels: &[(u32, u32)], seed: u64) -> (f64, f64) {
    let desc = parse_ron(ron, "furnace.ron".as_ref()).unwrap();
    let scene = common::build(&desc, ".".as_ref(), "furnace.ron".as_ref());
    let integrator = make_integrator(&scene, &scene.integrator, &IntegratorOptions::default())
        .unwrap()
        .integrator;
    let image = common::render_with(&scene, integrator.as_ref(), 256, seed);
    let vals: Vec<f64> = pixels
        .iter()
        .map(|&(x, y)| image.get(x, y).x as f64)
        .collect();
    let n = vals.len() as f64;
    let mean = vals.iter().sum::<f64>() / n;
    let var = vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// The pixels `lo..hi` in both directions.
fn square(lo: u32, hi: u32) -> Vec<(u32, u32)> {
    (lo..hi)
        .flat_map(|y| (lo..hi).map(move |x| (x, y)))
        .collect()
}

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
    // The sphere (radius 1 at distance 5, fov 20°) covers the central 8×8 pixels entirely.
    pixel_mean(&ron, &square(4, 12), seed)
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
    for m in [
        "Dielectric()",
        "Dielectric(int_ior: 2.4)",
        "Null",
        "ThinDielectric()",
        "ThinDielectric(int_ior: 2.4)",
    ] {
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

/// Mean and standard error over the pixels of a film that sees the constant environment of
/// radiance 1 through a pane of `material` (RON) at normal incidence (the view spans 2°, over
/// which the Fresnel reflectance changes by less than 10⁻⁵), rendered by `integrator`.
fn through_pane(material: &str, integrator: &str, seed: u64) -> (f64, f64) {
    let ron = format!(
        r#"(
        camera: (fov: 2, to_world: [LookAt(origin: (0, 0, 5), target: (0, 0, 0), up: (0, 1, 0))]),
        film: (width: 16, height: 16, filter: Box),
        integrator: (kind: "{integrator}", max_depth: -1),
        shapes: [(geometry: Rectangle, to_world: [Scale((2, 2, 1))], material: Some(Inline({material})))],
        lights: [Constant(radiance: (1, 1, 1))],
    )"#
    );
    pixel_mean(&ron, &square(0, 16), seed)
}

/// A thin pane that reflects nothing transmits `1 − 2r/(1 + r)` of what is behind it at
/// normal incidence (bk7 in air: `r` = 0.0405, 0.9221 through; Mitsuba 3.9.1 samples
/// transmission with probability 0.92209), within 4 standard errors; a pane transmitting one
/// face's `1 − r` (0.9595) is 30 standard errors away and rejected. Every estimator shows it
/// (ReSTIR sees a delta surface first and renders the path through it); a clear pane (both
/// multipliers 1) is invisible to each, every pixel exactly 1.
#[test]
fn thin_pane_transmits_both_faces_and_their_interreflection() {
    let eta = 1.5046f32 / 1.000_277;
    let r = restir_materials::fresnel::fresnel_dielectric(1.0, eta).r as f64;
    let thin = 1.0 - 2.0 * r / (1.0 + r);
    let one_face = 1.0 - r;
    for integrator in ["path", "restir-di", "restir-pt"] {
        let (mean, se) = through_pane(
            "ThinDielectric(specular_reflectance: (0, 0, 0))",
            integrator,
            5,
        );
        assert!(se > 1e-4 && se < 2e-3, "{integrator}: se {se}");
        assert!(
            (mean - thin).abs() < 4.0 * se,
            "{integrator}: mean {mean} (se {se}), want {thin}"
        );
        assert!(
            (mean - one_face).abs() > 4.0 * se,
            "{integrator}: the control {one_face} is not rejected (mean {mean}, se {se})"
        );
        let (mean, se) = through_pane("ThinDielectric()", integrator, 6);
        assert!(
            (mean - 1.0).abs() < 1e-5 && se < 1e-5,
            "{integrator}: clear pane {mean}"
        );
    }
}
