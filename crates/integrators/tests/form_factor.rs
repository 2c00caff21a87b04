//! Analytic test of the whole renderer (camera, BVH, NEE + BSDF sampling with MIS): a small patch
//! of a diffuse plane (albedo ρ) lit by a one-sided rectangle emitter of radiance L parallel to
//! it. The irradiance is E = π·L·F with F the closed-form form factor from a differential planar
//! element to a parallel rectangle (Howell's catalogue, "plane element to parallel rectangle;
//! normal to element passes through corner of rectangle", extended to any rectangle by signed
//! superposition of four corner rectangles), so the outgoing radiance is ρ/π·E = ρ·L·F.
//!
//! The camera looks at a tiny region around the point (fov 0.05°), so every pixel estimates the
//! same value. Independent seeds × pixels give independent estimates; the mean must agree with the
//! closed form within 4 standard errors (from their sample variance), per channel. The negative
//! control requires the same statistic to reject an expected value 2 % too high, so the test
//! has the power to see a 2 % bias. A sphere light far smaller than its distance is checked the
//! same way against its closed form, for the path tracer and ReSTIR DI.

mod common;

use std::sync::atomic::AtomicBool;

use restir_integrators::{IntegratorOptions, RenderJob, make_integrator, render};
use restir_scene::parse_ron;

/// Form factor from a differential element at the origin (normal towards the rectangle) to the
/// rectangle `[0, x] × [0, z]` in a parallel plane at distance `h`, for `x, z ≥ 0`:
/// F = 1/(2π)·[A/√(1+A²)·atan(B/√(1+A²)) + B/√(1+B²)·atan(A/√(1+B²))], A = x/h, B = z/h.
fn corner_form_factor(x: f64, z: f64, h: f64) -> f64 {
    let (a, b) = (x / h, z / h);
    let sa = (1.0 + a * a).sqrt();
    let sb = (1.0 + b * b).sqrt();
    (a / sa * (b / sa).atan() + b / sb * (a / sb).atan()) / (2.0 * std::f64::consts::PI)
}

/// Form factor to the rectangle `[x0, x1] × [z0, z1]` (coordinates relative to the foot of the
/// element's normal) at distance `h`: the corner factor is odd in each coordinate, so signed
/// corner rectangles add up to any rectangle.
fn rectangle_form_factor(x0: f64, x1: f64, z0: f64, z1: f64, h: f64) -> f64 {
    let g = |x: f64, z: f64| x.signum() * z.signum() * corner_form_factor(x.abs(), z.abs(), h);
    g(x1, z1) - g(x0, z1) - g(x1, z0) + g(x0, z0)
}

/// The plane `y = 0` (diffuse, `albedo`, facing up: the rectangle `[-1, 1]²` turned −90° about
/// x) under `emitter` (a RON shape), seen by a camera that looks at a tiny region around the
/// origin, direct light only.
fn plane_scene(albedo: [f64; 3], emitter: &str) -> common::Built {
    let [ar, ag, ab] = albedo;
    let ron = format!(
        r#"(
        camera: (fov: 0.05, to_world: [LookAt(origin: (-2, 0.3, 0.1), target: (0, 0, 0), up: (0, 1, 0))]),
        film: (width: 8, height: 8, filter: Box),
        integrator: (max_depth: 2),
        shapes: [
            (geometry: Rectangle, to_world: [Scale((4, 4, 1)), Rotate(axis: (1, 0, 0), angle: -90)],
             material: Some(Inline(Diffuse(reflectance: ({ar}, {ag}, {ab}))))),
            {emitter},
        ],
    )"#
    );
    let desc = parse_ron(&ron, "form-factor.ron".as_ref()).unwrap();
    common::build(&desc, ".".as_ref(), "form-factor.ron".as_ref())
}

/// A rectangle emitter `[x0, x1] × [z0, z1]` at height `h` facing down onto the plane `y = 0`.
struct Setup {
    x: (f64, f64),
    z: (f64, f64),
    h: f64,
    radiance: [f64; 3],
    albedo: [f64; 3],
}

impl Setup {
    fn exact(&self) -> [f64; 3] {
        let f = rectangle_form_factor(self.x.0, self.x.1, self.z.0, self.z.1, self.h);
        [0, 1, 2].map(|c| self.albedo[c] * self.radiance[c] * f)
    }

    fn scene(&self) -> common::Built {
        let (cx, cz) = ((self.x.0 + self.x.1) / 2.0, (self.z.0 + self.z.1) / 2.0);
        let (sx, sz) = ((self.x.1 - self.x.0) / 2.0, (self.z.1 - self.z.0) / 2.0);
        let [lr, lg, lb] = self.radiance;
        let h = self.h;
        // Rectangle: [-1, 1]² in z = 0 with normal +z. Rotating +90° about x sends +z to −y
        // (facing down) and y to z.
        plane_scene(
            self.albedo,
            &format!(
                "(geometry: Rectangle, to_world: [Scale(({sx}, {sz}, 1)), Rotate(axis: (1, 0, 0), angle: 90), \
                 Translate(({cx}, {h}, {cz}))], emission: Some(({lr}, {lg}, {lb})))"
            ),
        )
    }

    /// Per channel: the mean of all pixel estimates over `seeds` renders and its standard error.
    fn estimate(&self, seeds: u64, spp: u32) -> [(f64, f64); 3] {
        let scene = self.scene();
        let integrator = make_integrator(&scene, &scene.integrator, &IntegratorOptions::default())
            .unwrap()
            .integrator;
        let mut values: [Vec<f64>; 3] = Default::default();
        for seed in 0..seeds {
            let settings = RenderJob {
                spp,
                seed: 1000 + seed,
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
            for p in &out.image.pixels {
                for (c, v) in values.iter_mut().enumerate() {
                    v.push(p[c] as f64);
                }
            }
        }
        values.map(|v| mean_and_se(&v))
    }
}

/// The mean of `v` and its standard error from the sample variance.
fn mean_and_se(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Asserts that each channel's estimate `(mean, se)` of `what` lies within 4 standard errors of
/// `exact`, and (the negative control) that a value off by the factor `1 + off` does not: the
/// statistic can see an error of that size. `se` is floored at `floor` times the value.
fn assert_matches(what: &str, est: [(f64, f64); 3], exact: [f64; 3], off: f64, floor: f64) {
    for c in 0..3 {
        let (mean, se) = est[c];
        let se = se.max(floor * exact[c]);
        let z = (mean - exact[c]) / se;
        eprintln!(
            "{what} channel {c}: mean {mean:.6} exact {:.6} (ratio {:.5}), se {se:.2e}, z {z:.2}",
            exact[c],
            mean / exact[c]
        );
        assert!(
            z.abs() < 4.0,
            "{what} channel {c}: {mean} vs exact {} ({z:.2} standard errors)",
            exact[c]
        );
        let z_wrong = (mean - (1.0 + off) * exact[c]) / se;
        assert!(
            z_wrong.abs() > 4.0,
            "{what} channel {c}: the test cannot tell an error of {off} ({z_wrong:.2} standard errors)"
        );
    }
}

const SETUPS: [Setup; 2] = [
    // The point below the rectangle (not at its centre).
    Setup {
        x: (-0.5, 0.7),
        z: (-0.4, 0.6),
        h: 0.8,
        radiance: [4.0, 2.0, 1.0],
        albedo: [0.8, 0.5, 0.2],
    },
    // The rectangle off to one side: only signed corner terms reach it.
    Setup {
        x: (0.3, 1.3),
        z: (-0.2, 0.9),
        h: 0.6,
        radiance: [3.0, 3.0, 6.0],
        albedo: [0.6, 0.6, 0.6],
    },
];

#[test]
fn closed_form_matches_numerical_integration() {
    // F = 1/π ∫∫ h² / (x² + z² + h²)² dx dz over the rectangle, by the midpoint rule.
    let numeric = |s: &Setup| {
        let n = 1500;
        let (dx, dz) = ((s.x.1 - s.x.0) / n as f64, (s.z.1 - s.z.0) / n as f64);
        let mut sum = 0.0;
        for i in 0..n {
            let x = s.x.0 + (i as f64 + 0.5) * dx;
            for j in 0..n {
                let z = s.z.0 + (j as f64 + 0.5) * dz;
                let r2 = x * x + z * z + s.h * s.h;
                sum += s.h * s.h / (r2 * r2);
            }
        }
        sum * dx * dz / std::f64::consts::PI
    };
    for s in &SETUPS {
        let closed = rectangle_form_factor(s.x.0, s.x.1, s.z.0, s.z.1, s.h);
        let num = numeric(s);
        assert!((closed - num).abs() < 1e-6 * closed, "{closed} vs {num}");
    }
    // An infinite parallel plane has form factor 1.
    let inf = rectangle_form_factor(-1e9, 1e9, -1e9, 1e9, 1.0);
    assert!((inf - 1.0).abs() < 1e-6, "{inf}");
}

#[test]
fn rectangle_light_over_diffuse_plane_matches_form_factor() {
    for (i, setup) in SETUPS.iter().enumerate() {
        let exact = setup.exact();
        // Negative control: a value 2 % off must be rejected by the same statistic.
        assert_matches(
            &format!("setup {i}"),
            setup.estimate(12, 512),
            exact,
            0.02,
            0.0,
        );
    }
}

/// A sphere light of radius `r` and radiance `radiance`, its centre at `center` above the plane
/// `y = 0` (seen from the origin wholly above the horizon): the irradiance at the origin is
/// `π·L·(r/D)²·cos θ` (`D` the distance to the centre, θ its angle from the normal), so the
/// outgoing radiance is `ρ·L·(r/D)²·cos θ`.
struct SphereSetup {
    center: [f64; 3],
    r: f64,
    radiance: [f64; 3],
    albedo: [f64; 3],
}

impl SphereSetup {
    fn exact(&self) -> [f64; 3] {
        let [x, y, z] = self.center;
        let d2 = x * x + y * y + z * z;
        let k = self.r * self.r / d2 * (y / d2.sqrt());
        [0, 1, 2].map(|c| self.albedo[c] * self.radiance[c] * k)
    }

    fn scene(&self) -> common::Built {
        let [cx, cy, cz] = self.center;
        let [lr, lg, lb] = self.radiance;
        let r = self.r;
        plane_scene(
            self.albedo,
            &format!(
                "(geometry: Sphere(center: ({cx}, {cy}, {cz}), radius: {r}), emission: Some(({lr}, {lg}, {lb})))"
            ),
        )
    }
}

/// Per channel: the mean over `seeds` renders of estimator `name` of each render's mean pixel,
/// and its standard error from the spread of those means (a render's pixels share reused
/// samples, its renders do not).
fn render_means(scene: &common::Built, name: &str, seeds: u64, spp: u32) -> [(f64, f64); 3] {
    let options = IntegratorOptions {
        name: Some(name.into()),
        ..Default::default()
    };
    let integrator = make_integrator(scene, &scene.integrator, &options)
        .unwrap()
        .integrator;
    let mut means: [Vec<f64>; 3] = Default::default();
    for seed in 0..seeds {
        let settings = RenderJob {
            spp,
            seed: 2000 + seed,
            ..RenderJob::default()
        };
        let out = render(
            scene,
            integrator.as_ref(),
            &settings,
            &AtomicBool::new(false),
            &mut |_, _| {},
        );
        assert_eq!(out.nonfinite_pixels, 0);
        let n = out.image.pixels.len() as f64;
        for (c, m) in means.iter_mut().enumerate() {
            m.push(out.image.pixels.iter().map(|p| p[c] as f64).sum::<f64>() / n);
        }
    }
    means.map(|v| mean_and_se(&v))
}

/// A sphere light a thousand times smaller than its distance (sin θmax = 10⁻³: a lamp of 4 cm
/// seen from 40 m), which the path tracer and ReSTIR DI draw in the cone it subtends: both
/// match the closed form within 4 standard errors, and a value 1 % off is rejected by the same
/// statistic. (Drawing the cone by a ray intersected with the sphere lost the point there and
/// made the images too bright: ReSTIR DI by 5 % on a scene of 10⁵ such lamps.)
#[test]
fn small_distant_sphere_light_matches_closed_form() {
    let setup = SphereSetup {
        center: [12.0, 36.0, -16.0],
        r: 0.04,
        radiance: [8.0e4, 6.0e4, 3.0e4],
        albedo: [0.7, 0.5, 0.3],
    };
    let exact = setup.exact();
    let scene = setup.scene();
    for (name, seeds, spp) in [("path", 16, 64), ("restir-di", 16, 16)] {
        // The estimates hardly vary here (se ~10⁻⁶ of the value): rounding of the order of
        // 10⁻⁵ is allowed beside the 4 standard errors; a value 1 % off must be rejected.
        let est = render_means(&scene, name, seeds, spp);
        assert_matches(name, est, exact, 0.01, 2.5e-6);
    }
}

/// A rectangle emitter whose radiance is a checkerboard texture times a factor (Mitsuba's area
/// emitter with a `radiance` texture): the rectangle's uv `[0, 1]²` is one 2×2 checker, so its
/// light is that of four rectangles of constant radiance, and the closed form is the sum of
/// their form factors. The path tracer, ReSTIR DI and ReSTIR PT match it within 4 standard
/// errors, with the light near and large (BSDF samples carry most of the path tracer's weight)
/// and off to one side (light samples carry it). Negative control: the same statistic rejects
/// the image the texture's mean would give (the radiance the light's selection weights count),
/// so a lookup that missed the texture, or read it at another point, could not pass.
#[test]
fn textured_rectangle_light_matches_the_sum_of_its_cells() {
    let factor = [2.0, 1.0, 0.5];
    let (color0, color1) = ([2.0, 2.0, 2.0], [0.25, 1.0, 6.0]);
    let albedo = [0.7, 0.6, 0.5];
    let [fr, fg, fb] = factor;
    let ([a0, a1, a2], [b0, b1, b2]) = (color0, color1);
    for (x, z, h) in [
        ((-0.6, 1.0), (-0.5, 0.9), 0.5),
        ((0.0, 1.0), (0.0, 1.0), 1.2),
    ] {
        let (cx, cz) = ((x.0 + x.1) / 2.0, (z.0 + z.1) / 2.0);
        let (sx, sz) = ((x.1 - x.0) / 2.0, (z.1 - z.0) / 2.0);
        // u runs with x and v with z; colour 0 where u and v are on the same side of ½.
        let mut exact = [0.0; 3];
        let mut uniform = [0.0; 3];
        for (xs, low_u) in [((x.0, cx), true), ((cx, x.1), false)] {
            for (zs, low_v) in [((z.0, cz), true), ((cz, z.1), false)] {
                let f = rectangle_form_factor(xs.0, xs.1, zs.0, zs.1, h);
                let color = if low_u == low_v { color0 } else { color1 };
                for c in 0..3 {
                    exact[c] += albedo[c] * factor[c] * color[c] * f;
                    uniform[c] += albedo[c] * factor[c] * (color0[c] + color1[c]) / 2.0 * f;
                }
            }
        }
        let scene = plane_scene(
            albedo,
            &format!(
                "(geometry: Rectangle, to_world: [Scale(({sx}, {sz}, 1)), Rotate(axis: (1, 0, 0), angle: 90), \
                 Translate(({cx}, {h}, {cz}))], emission: Some(({fr}, {fg}, {fb})), \
                 emission_texture: Some(Checkerboard(color0: ({a0}, {a1}, {a2}), color1: ({b0}, {b1}, {b2}))))"
            ),
        );
        for (name, seeds, spp) in [
            ("path", 96, 256),
            ("restir-di", 48, 64),
            ("restir-pt", 48, 64),
        ] {
            let what = format!("{name}, height {h}");
            let est = render_means(&scene, name, seeds, spp);
            assert_matches(&what, est, exact, 0.02, 0.0);
            for c in [0, 2] {
                let (mean, se) = est[c];
                let z_uniform = (mean - uniform[c]) / se;
                assert!(
                    z_uniform.abs() > 4.0,
                    "{what} channel {c}: the test cannot tell the texture from its mean ({z_uniform:.2} standard errors)"
                );
            }
        }
    }
}
