//! Environment-map light: chi-square test of its direction sampling against the density it
//! reports (`restir_testkit`, binned on a `(cos θ, φ)` grid), through [`LightSet`] as the
//! integrators use it, with two negative controls (the map turned by one texel: samples land
//! where that density is zero; the sun 20 % dimmer: same support, p < 1e-6); and its power,
//! which must be consistent with the constant environment's.

use glam::{Mat3, Vec3};
use restir_lights::{EnvMap, Light, LightSet};
use restir_sampling::Pcg32;
use restir_testkit::{Histogram, Quadrature, SphereGrid, sidak_level};

/// A 32×16 map with a bright sun, a coloured band and a dark quadrant, rotated off the axes.
fn map(scale: f32) -> EnvMap {
    map_with_sun(scale, 200.0)
}

fn map_with_sun(scale: f32, sun: f32) -> EnvMap {
    let (w, h) = (32, 16);
    let mut texels = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let mut l = Vec3::new(0.3, 0.4, 0.6) * (1.0 + 0.5 * (x as f32 * 0.7).sin());
            if (5..8).contains(&y) {
                l += Vec3::new(2.0, 1.0, 0.2);
            }
            if x < w / 4 && y > h / 2 {
                l = Vec3::ZERO;
            }
            if (x, y) == (20, 4) || (x, y) == (21, 4) {
                l = Vec3::splat(sun);
            }
            texels.push(l);
        }
    }
    let r = Mat3::from_rotation_x(0.5) * Mat3::from_rotation_z(-0.3) * Mat3::from_rotation_y(1.0);
    EnvMap::new(w, h, texels, scale, r).unwrap()
}

/// The map's discontinuities cut many cells: subdivide finely.
const QUAD: Quadrature = Quadrature {
    subdivisions: 6,
    tolerance: 1e-8,
    max_depth: 7,
};

const TESTS: usize = 1;

fn set() -> LightSet {
    LightSet::with_envmap(
        vec![Light::Envmap],
        Some(map(2.0)),
        Vec::new(),
        (Vec3::splat(-1.0), Vec3::splat(1.0)),
    )
    .unwrap()
}

/// Samples through `LightSet::sample` (checking each sample's pdf against `pdf_sa`) into `grid`.
fn histogram(set: &LightSet, grid: &SphereGrid, n: usize) -> Histogram {
    let mut rng = Pcg32::new(77, 0);
    let mut hist = Histogram::new(grid.len());
    let mut off = 0;
    for _ in 0..n {
        let u_select = rng.next_f32();
        let Some(s) = set.sample(Vec3::ZERO, u_select, rng.next_2d()) else {
            hist.record_remainder();
            continue;
        };
        assert!(!s.delta && s.dist.is_infinite());
        // Near the poles the round trip through a direction moves u (and so the radiance
        // of the top or bottom row); allow that for a few samples.
        let le = set.environment_radiance(s.wi);
        if (s.le - le).length() > 1e-3 * s.le.length().max(1e-2) {
            off += 1;
        }
        let pdf = set.pdf_sa(s.light, Vec3::ZERO, s.p, s.ng);
        if (pdf - s.pdf_sa).abs() > 1e-3 * pdf {
            off += 1; // within rounding of a patch boundary
        }
        hist.record(grid.bin(s.wi));
    }
    assert!(
        off * 1000 < n,
        "{off} of {n} sampled pdfs or radiances disagree with pdf_sa / environment_radiance"
    );
    hist
}

/// Directions from `LightSet::sample` follow `LightSet::pdf_sa`; the density integrates to one.
#[test]
fn envmap_directions_follow_pdf() {
    let set = set();
    let grid = SphereGrid::new(24, 48).unwrap();
    let p = grid.integrate(|w| set.pdf_sa(0, Vec3::ZERO, w, -w) as f64, &QUAD);
    let mass: f64 = p.iter().sum();
    assert!((mass - 1.0).abs() < 2e-3, "∫ pdf = {mass}");
    let hist = histogram(&set, &grid, 1_000_000);
    let o = hist.chi2(&p).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("envmap directions: {o}");
    assert!(o.accepts(sidak_level(0.01, TESTS)), "rejected: {o}");

    // Negative control: the density of the same map turned by one texel about its axis
    // (the half-texel bookkeeping of the patches gone wrong by two) must be rejected.
    let axis = map(1.0);
    let turn = Mat3::from_rotation_y(2.0 * core::f32::consts::PI / 32.0);
    let r = Mat3::from_rotation_x(0.5) * Mat3::from_rotation_z(-0.3) * Mat3::from_rotation_y(1.0);
    let wrong = grid.integrate(|w| axis.pdf(r * turn * r.transpose() * w) as f64, &QUAD);
    // Samples where the wrong density is zero (the dark quadrant moved) reject it outright.
    match hist.chi2(&wrong) {
        Ok(o) => {
            eprintln!("control (map turned by one texel): {o}");
            assert!(o.p_value < 1e-6, "control passed: {o}");
        }
        Err(e) => eprintln!("control (map turned by one texel) rejected: {e}"),
    }
    // Negative control with the same support: the density of the map with a sun 20 % dimmer.
    let dimmer = map_with_sun(1.0, 160.0);
    let wrong = grid.integrate(|w| dimmer.pdf(w) as f64, &QUAD);
    let o = hist.chi2(&wrong).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("control (sun 20 % dimmer): {o}");
    assert!(o.p_value < 1e-6, "control passed: {o}");
}

/// Power: `π R² ∫ lum(L) dω`, so a constant image has the power of a `constant` emitter of
/// the same radiance (up to the sampling grid's quadrature of `sin θ`).
#[test]
fn envmap_power_matches_constant() {
    let bounds = (Vec3::splat(-1.0), Vec3::splat(1.0));
    let l = Vec3::new(0.5, 1.0, 2.0);
    let env = EnvMap::new(64, 32, vec![l; 64 * 32], 1.0, Mat3::IDENTITY).unwrap();
    let a = LightSet::with_envmap(vec![Light::Envmap], Some(env), Vec::new(), bounds).unwrap();
    let b = LightSet::new(vec![Light::Constant { radiance: l }], Vec::new(), bounds).unwrap();
    let (pa, pb) = (a.power(0), b.power(0));
    assert!((pa / pb - 1.0).abs() < 1e-3, "{pa} vs {pb}");
    assert_eq!(a.environment(), Some(0));
    assert!((a.environment_radiance(Vec3::new(0.3, -0.8, 0.1).normalize()) - l).length() < 1e-5);
    // Two environments, or an Envmap light without its image, are errors.
    let env = EnvMap::new(2, 2, vec![l; 4], 1.0, Mat3::IDENTITY).unwrap();
    let two = vec![Light::Constant { radiance: l }, Light::Envmap];
    assert!(LightSet::with_envmap(two, Some(env), Vec::new(), bounds).is_err());
    assert!(LightSet::new(vec![Light::Envmap], Vec::new(), bounds).is_err());
}
