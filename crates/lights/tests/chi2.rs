//! Chi-square tests of light sampling (`restir_testkit`, after Mitsuba 3's chi-square
//! test) on a small scene of area lights (rectangles, a sphere, a cube) and a point light.
//!
//! - **Selection**: the light index [`LightSet::sample`] picks follows [`LightSet::pmf`], and the
//!   pmf is proportional to each light's power.
//! - **Directions**: the directions `wi` of [`LightSet::sample`] from a reference point follow the
//!   mixture density `Σ_l pmf(l) · pdf_sa_l(wi)` that [`LightSet::pdf_sa`] reports (binned on a
//!   `(cos θ, φ)` grid around the reference point). The density of a direction is found by
//!   tracing it to the light's surface: the nearest hit on the light's shape, if that hit faces
//!   the reference point (lights are one-sided; the test shapes are convex). Delta-light samples
//!   are tested as one more cell with probability `Σ_delta pmf`; failed samples (back faces) as
//!   the remainder `1 − Σ`.
//! - **Sphere lights** seen from inside (uniform area sampling) and from outside (cone sampling),
//!   also a sphere thousands of times smaller than its distance.
//!
//! A test fails when `p < sidak_level(0.01, CHI2_TESTS)` or at once when a sample lands where the
//! density is zero. The negative control (uniform light selection instead of power-proportional)
//! must be rejected with p < 1e-6.

use core::f32::consts::PI;
use glam::{Affine3A, Quat, Vec2, Vec3};
use restir_geometry::{Shape, Sphere, TriangleMesh};
use restir_lights::{Light, LightSet};
use restir_sampling::{Pcg32, luminance};
use restir_testkit::{Chi2Error, Chi2Outcome, Histogram, Quadrature, SphereGrid, sidak_level};

/// Chi-square hypothesis tests in this file (negative controls excluded).
const CHI2_TESTS: usize = 8;

fn assert_accepted(what: &str, outcome: Result<Chi2Outcome, Chi2Error>) {
    let level = sidak_level(0.01, CHI2_TESTS);
    match outcome {
        Ok(o) => {
            eprintln!("{what}: {o}");
            assert!(
                o.accepts(level),
                "{what}: rejected at level {level:.2e}: {o}"
            );
        }
        Err(e) => panic!("{what}: {e}"),
    }
}

// ------------------------------------------------------------------------------------------
// Scene
// ------------------------------------------------------------------------------------------

/// Mitsuba's `rectangle` scaled to half-extents `(sx, sy)`, centred at `center`, its normal
/// turned to `normal`.
fn rectangle(sx: f32, sy: f32, center: Vec3, normal: Vec3) -> Shape {
    let mut mesh = Shape::rectangle();
    mesh.transform(&Affine3A::from_scale_rotation_translation(
        Vec3::new(sx, sy, 1.0),
        Quat::from_rotation_arc(Vec3::Z, normal.normalize()),
        center,
    ));
    Shape::Mesh(mesh)
}

/// The reference point all lights are seen from.
const REF_P: Vec3 = Vec3::new(0.05, -0.1, 0.1);

/// Three rectangles facing (roughly) the reference point, a sphere, a rotated cube and a
/// cylinder, all emitting with different radiances, a non-emitting rectangle, and a point light.
fn scene() -> (Vec<Shape>, LightSet) {
    let mut cube = Shape::cube();
    cube.transform(&Affine3A::from_scale_rotation_translation(
        Vec3::splat(0.35),
        Quat::from_euler(glam::EulerRot::XYZ, 0.4, -0.7, 0.2),
        Vec3::new(0.2, -1.5, 0.9),
    ));
    let shapes = vec![
        rectangle(1.0, 0.6, Vec3::new(0.0, 0.0, 1.5), -Vec3::Z),
        rectangle(
            0.5,
            0.8,
            Vec3::new(-1.8, 0.3, 0.2),
            Vec3::new(1.0, -0.3, 0.2),
        ),
        rectangle(
            0.7,
            0.7,
            Vec3::new(0.4, 1.6, -0.8),
            Vec3::new(-0.1, -1.0, 0.6),
        ),
        Shape::Sphere(Sphere::new(Vec3::new(1.6, -0.4, -0.9), 0.5, false)),
        Shape::Mesh(cube),
        // Not a light.
        rectangle(3.0, 3.0, Vec3::new(0.0, 0.0, -3.0), Vec3::Z),
        // A tilted open cylinder, seen partly from inside through its open end.
        Shape::Cylinder(
            restir_geometry::Cylinder::new(
                Vec3::new(-1.2, 1.0, 0.6),
                Vec3::new(-0.4, 1.6, 1.4),
                0.3,
                Affine3A::IDENTITY,
                false,
            )
            .unwrap(),
        ),
    ];
    let lights = vec![
        Light::Area {
            shape: 0,
            radiance: Vec3::splat(1.0),
            texture: None,
        },
        Light::Point {
            position: Vec3::new(0.3, 0.2, -1.7),
            intensity: Vec3::splat(1.0),
        },
        Light::Area {
            shape: 1,
            radiance: Vec3::new(4.0, 2.0, 1.0),
            texture: None,
        },
        Light::Area {
            shape: 2,
            radiance: Vec3::splat(0.5),
            texture: None,
        },
        Light::Area {
            shape: 3,
            radiance: Vec3::splat(3.0),
            texture: None,
        },
        Light::Area {
            shape: 4,
            radiance: Vec3::new(2.0, 0.5, 0.5),
            texture: None,
        },
        Light::Area {
            shape: 6,
            radiance: Vec3::new(1.0, 2.0, 3.0),
            texture: None,
        },
    ];
    let set = LightSet::new(lights, &shapes[..], (Vec3::splat(-3.0), Vec3::splat(3.0))).unwrap();
    (shapes, set)
}

// ------------------------------------------------------------------------------------------
// Tracing a direction to a light
// ------------------------------------------------------------------------------------------

/// The nearest intersection of the ray `o + t w` (t > 0) with `shape`: point, shading normal and
/// geometric normal.
fn first_hit(shape: &Shape, o: Vec3, w: Vec3) -> Option<(Vec3, Vec3, Vec3)> {
    match shape {
        Shape::Sphere(s) => {
            let oc = o - s.center;
            let b = oc.dot(w);
            let c = oc.length_squared() - s.radius * s.radius;
            let disc = b * b - c;
            if disc < 0.0 {
                return None;
            }
            let sq = disc.sqrt();
            let t = if -b - sq > 0.0 { -b - sq } else { -b + sq };
            if t <= 0.0 {
                return None;
            }
            let p = o + t * w;
            let n = (p - s.center).normalize();
            let n = if s.flip_normals { -n } else { n };
            Some((p, n, n))
        }
        Shape::Cylinder(c) => {
            let t = c.intersect(o.into(), w.into(), f32::INFINITY);
            if !t.is_finite() {
                return None;
            }
            let ps = shape.position_at(0, c.param_of(o + t * w));
            Some((ps.p, ps.n, ps.ng))
        }
        Shape::SdfGrid(_) => None,
        Shape::Mesh(mesh) => {
            let mut best: Option<(f32, usize, Vec2)> = None;
            for i in 0..mesh.triangle_count() {
                // Möller–Trumbore.
                let [p0, p1, p2] = mesh.triangle(i);
                let (e1, e2) = (p1 - p0, p2 - p0);
                let pv = w.cross(e2);
                let det = e1.dot(pv);
                if det.abs() < 1e-12 {
                    continue;
                }
                let inv = 1.0 / det;
                let tv = o - p0;
                let b1 = tv.dot(pv) * inv;
                let qv = tv.cross(e1);
                let b2 = w.dot(qv) * inv;
                let t = e2.dot(qv) * inv;
                if b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0 || t <= 0.0 {
                    continue;
                }
                if best.is_none_or(|(bt, _, _)| t < bt) {
                    best = Some((t, i, Vec2::new(b1, b2)));
                }
            }
            let (_, tri, b) = best?;
            let ps = shape.position_at(tri as u32, b);
            Some((ps.p, ps.n, ps.ng))
        }
    }
}

/// The density per unit solid angle, including the selection probability, with which
/// `LightSet::sample` returns direction `w` from `ref_p` on light `light`, from `LightSet::pdf_sa`
/// at the point the direction reaches. Zero for delta lights, directions that miss, and the back
/// of one-sided emitters (which the sampler rejects).
fn light_density(set: &LightSet, shapes: &[Shape], light: u32, ref_p: Vec3, w: Vec3) -> f64 {
    let Light::Area { shape, .. } = set.lights()[light as usize] else {
        return 0.0;
    };
    let Some((p, n, ng)) = first_hit(&shapes[shape as usize], ref_p, w) else {
        return 0.0;
    };
    if n.dot(w) >= 0.0 {
        return 0.0;
    }
    set.pdf_sa(light, ref_p, p, ng) as f64
}

fn is_delta(light: &Light) -> bool {
    matches!(light, Light::Point { .. } | Light::Directional { .. })
}

/// Silhouettes cut many cells: finer sub-cells, shallower refinement (the edge error stays below
/// ~1e-4 of a cell's mass, far below the statistical error of these sample counts).
const LIGHT_QUAD: Quadrature = Quadrature {
    subdivisions: 6,
    tolerance: 1e-8,
    max_depth: 7,
};

/// Per-cell probabilities of each light's directions from `ref_p` (including `pmf`), on `grid`.
fn per_light_cells(
    set: &LightSet,
    shapes: &[Shape],
    ref_p: Vec3,
    grid: &SphereGrid,
) -> Vec<Vec<f64>> {
    (0..set.len() as u32)
        .map(|l| {
            if is_delta(&set.lights()[l as usize]) {
                vec![0.0; grid.len()]
            } else {
                grid.integrate(|w| light_density(set, shapes, l, ref_p, w), &LIGHT_QUAD)
            }
        })
        .collect()
}

/// The mixture: grid cells, then one cell for all delta lights; each light weighted by
/// `weight(l) / pmf(l)` (so `pmf` itself gives the density the sampler claims).
fn mixture(set: &LightSet, per_light: &[Vec<f64>], weight: impl Fn(u32) -> f64) -> Vec<f64> {
    let cells = per_light[0].len();
    let mut p = vec![0.0; cells + 1];
    for (l, h) in per_light.iter().enumerate() {
        let l = l as u32;
        let scale = weight(l) / set.pmf(l) as f64;
        if is_delta(&set.lights()[l as usize]) {
            p[cells] += weight(l);
        } else {
            for (pi, hi) in p.iter_mut().zip(h) {
                *pi += scale * hi;
            }
        }
    }
    p
}

/// Directions of `n` samples of `LightSet::sample` from `ref_p`: grid cells, a delta cell, and
/// failed samples in the remainder. Also checks each sample's reported pdf.
fn sample_directions(
    set: &LightSet,
    ref_p: Vec3,
    grid: &SphereGrid,
    seed: u64,
    n: usize,
) -> Histogram {
    let mut rng = Pcg32::new(seed, 0);
    let mut hist = Histogram::new(grid.len() + 1);
    for _ in 0..n {
        let u_select = rng.next_f32();
        let Some(s) = set.sample(ref_p, u_select, rng.next_2d()) else {
            hist.record_remainder();
            continue;
        };
        if s.delta {
            assert!(
                (s.pdf_sa - set.pmf(s.light)).abs() <= 1e-6,
                "delta pdf {}",
                s.pdf_sa
            );
            hist.record(Some(grid.len()));
        } else {
            let pdf = set.pdf_sa(s.light, ref_p, s.p, s.ng);
            assert!(
                (pdf - s.pdf_sa).abs() <= 1e-3 * pdf,
                "light {}: sampled pdf {} vs pdf_sa {pdf}",
                s.light,
                s.pdf_sa
            );
            assert!((s.wi - (s.p - ref_p).normalize()).length() < 1e-4);
            hist.record(grid.bin(s.wi));
        }
    }
    hist
}

// ------------------------------------------------------------------------------------------
// Tests
// ------------------------------------------------------------------------------------------

/// (a) The light `sample` picks with `u_select` follows `pmf`, which is proportional to power.
#[test]
fn light_selection_follows_pmf() {
    let (shapes, set) = scene();
    let n_lights = set.len();
    // pmf ∝ power: π · area · luminance(radiance) for area lights, 4π · luminance(I) for points.
    let power = |l: &Light| match *l {
        Light::Area {
            shape, radiance, ..
        } => PI * shapes[shape as usize].area() * luminance(radiance),
        Light::Point { intensity, .. } => 4.0 * PI * luminance(intensity),
        _ => unreachable!(),
    };
    let powers: Vec<f64> = set.lights().iter().map(|l| power(l) as f64).collect();
    let total: f64 = powers.iter().sum();
    let pmf: Vec<f64> = (0..n_lights as u32).map(|l| set.pmf(l) as f64).collect();
    for (l, (p, w)) in pmf.iter().zip(&powers).enumerate() {
        assert!(
            (p - w / total).abs() <= 1e-5 * p,
            "light {l}: pmf {p} vs power share"
        );
    }
    assert!((pmf.iter().sum::<f64>() - 1.0).abs() < 1e-5);

    // The light is a function of `u_select` alone (which of a mesh's triangles, too: a back face
    // of the cube fails whatever the point), and `sample` picks what `select` picks.
    let mut rng = Pcg32::new(21, 0);
    let mut hist = Histogram::new(n_lights);
    let mut sampled = 0;
    for _ in 0..1_000_000 {
        let u_select = rng.next_f32();
        let (light, p) = set.select(u_select).expect("the set has lights");
        assert_eq!(p, set.pmf(light));
        if let Some(s) = set.sample(REF_P, u_select, rng.next_2d()) {
            assert_eq!(s.light, light);
            sampled += 1;
        }
        hist.record(Some(light as usize));
    }
    assert!(sampled > 500_000, "{sampled} samples succeeded");
    assert_accepted("light selection vs pmf", hist.chi2(&pmf));
}

/// (b) Directions of all non-delta lights against `Σ_l pmf(l) · pdf_sa_l`.
#[test]
fn light_directions_follow_mixture_pdf() {
    let (shapes, set) = scene();
    let grid = SphereGrid::new(16, 32).unwrap();
    let per_light = per_light_cells(&set, &shapes, REF_P, &grid);
    let p = mixture(&set, &per_light, |l| set.pmf(l) as f64);
    let hist = sample_directions(&set, REF_P, &grid, 22, 1_000_000);
    assert!(
        hist.remainder() > 0,
        "the cube's back faces must be rejected"
    );
    assert_accepted("light directions vs mixture pdf", hist.chi2(&p));
}

/// (c) A sphere light seen from inside (it emits inwards: normals flipped) is sampled uniformly by
/// area; from outside (normals out), uniformly in the cone it subtends, far and close.
#[test]
fn sphere_light_inside_and_outside() {
    let center = Vec3::new(0.2, -0.1, 0.3);
    let cases = [
        ("inside", Vec3::new(-0.3, 0.2, -0.25), true),
        ("outside far", center + Vec3::new(1.5, -1.5, 1.0), false),
        (
            "outside close",
            center + Vec3::new(0.0, 0.6, -0.8) * 1.05,
            false,
        ),
    ];
    for (k, (name, ref_p, flip)) in cases.into_iter().enumerate() {
        let shapes = vec![Shape::Sphere(Sphere::new(center, 1.0, flip))];
        let light = Light::Area {
            shape: 0,
            radiance: Vec3::splat(2.0),
            texture: None,
        };
        let set = LightSet::new(
            vec![light],
            &shapes[..],
            (Vec3::splat(-2.0), Vec3::splat(2.0)),
        )
        .unwrap();
        let grid = SphereGrid::default();
        let per_light = per_light_cells(&set, &shapes, ref_p, &grid);
        let p = mixture(&set, &per_light, |l| set.pmf(l) as f64);
        let mass: f64 = p.iter().sum();
        assert!((mass - 1.0).abs() < 1e-3, "{name}: ∫ pdf_sa = {mass}");
        let hist = sample_directions(&set, ref_p, &grid, 30 + k as u64, 500_000);
        assert_accepted(&format!("sphere light, {name}"), hist.chi2(&p));
    }
}

/// Where a sample `p` from `ref_p` falls in the cone of a sphere at `center` whose
/// `1 − cos θmax` is `one_minus_max`: cell `(bin of (1 − cos θ) / (1 − cos θmax), bin of φ
/// about the axis)` on a `BINS × BINS` grid (uniform in solid angle over the cone: every cell
/// equally likely), in f64 from the point's offset across the axis (`1 − cos θ` without
/// cancellation), or `None` outside the cone.
fn cone_cell(ref_p: Vec3, center: Vec3, one_minus_max: f64, p: Vec3) -> Option<usize> {
    const BINS: usize = 16;
    let axis = (center - ref_p).as_dvec3().normalize();
    let d = (p - ref_p).as_dvec3();
    let across = d - axis * d.dot(axis);
    let sin2 = across.length_squared() / d.length_squared();
    let one_minus = sin2 / (1.0 + (1.0 - sin2).max(0.0).sqrt());
    let t = one_minus / one_minus_max;
    let (s, c) = (
        axis.any_orthonormal_vector(),
        axis.cross(axis.any_orthonormal_vector()),
    );
    let phi = across.dot(c).atan2(across.dot(s)) + std::f64::consts::PI;
    let phi_bin = ((phi / (2.0 * std::f64::consts::PI) * BINS as f64) as usize).min(BINS - 1);
    (t <= 1.0 + 1e-3).then(|| (t * BINS as f64).min(BINS as f64 - 1.0) as usize * BINS + phi_bin)
}

/// A sphere a thousand and ten thousand times smaller than its distance is sampled uniformly in
/// the cone it subtends, on its side facing the receiver, with the density `pdf_sa` reports
/// (`1 / (2π(1 − cos θmax))`, where `1 − cos θmax` is a few ulps of 1 or rounds to 0). The
/// negative control is the former construction, a ray through the cone intersected with the
/// sphere: its `d² − b²` loses the point, and is rejected at the larger sphere; at the smaller
/// its cone rounds to nothing and it draws no sample at all.
#[test]
fn sphere_far_smaller_than_its_distance() {
    let ref_p = Vec3::new(0.3, -0.2, 0.1);
    let dir = Vec3::new(0.48, 0.6, 0.64);
    for (k, sin_max) in [1e-3f32, 1e-4].into_iter().enumerate() {
        let dist = 40.0f32;
        let center = ref_p + dir * dist;
        let sphere = Sphere::new(center, dist * sin_max, false);
        let shape = Shape::Sphere(sphere);
        let one_minus_max = {
            let s2 = (sin_max as f64).powi(2);
            s2 / (1.0 + (1.0 - s2).sqrt())
        };
        let mut rng = Pcg32::new(50 + k as u64, 3);
        let n = 200_000;
        let mut hist = Histogram::new(16 * 16);
        let mut control = Histogram::new(16 * 16);
        for _ in 0..n {
            let u = rng.next_2d();
            let (ps, pdf) = shape.sample_from(ref_p, u).expect("a sample");
            let r = (ps.p - center).length() / sphere.radius;
            assert!((r - 1.0).abs() < 1e-3, "on the sphere: {r}");
            assert!(
                ps.n.dot(ref_p - ps.p) > 0.0,
                "on the side facing the receiver"
            );
            let want = 1.0 / (2.0 * std::f64::consts::PI * one_minus_max);
            assert!((pdf as f64 / want - 1.0).abs() < 1e-4, "{pdf} vs {want}");
            assert!((shape.pdf_sa_from(ref_p, ps.p, ps.n) / pdf - 1.0).abs() < 1e-4);
            hist.record(cone_cell(ref_p, center, one_minus_max, ps.p));
            match intersected_cone_sample(ref_p, center, sphere.radius, u) {
                Some(p) => control.record(cone_cell(ref_p, center, one_minus_max, p)),
                None => control.record_remainder(),
            }
        }
        let uniform = vec![1.0 / 256.0; 256];
        assert_accepted(
            &format!("sphere at sin θmax = {sin_max}"),
            hist.chi2(&uniform),
        );
        let rejected = match control.chi2(&uniform) {
            Ok(o) => {
                eprintln!("intersected cone at sin θmax = {sin_max}: {o}");
                o.p_value < 1e-6
            }
            Err(e) => {
                eprintln!("intersected cone at sin θmax = {sin_max}: {e}");
                true
            }
        };
        assert!(
            rejected,
            "the intersected cone passed at sin θmax = {sin_max}"
        );
    }
}

/// The negative control of [`sphere_far_smaller_than_its_distance`]: a direction uniform in the
/// cone (its `1 − cos θmax` as `1 − √(1 − sin²θmax)`) intersected with the sphere, tangential
/// misses clamped to the silhouette; `None` where the cone rounds to nothing.
fn intersected_cone_sample(ref_p: Vec3, center: Vec3, radius: f32, u: Vec2) -> Option<Vec3> {
    let to_c = center - ref_p;
    let d2 = to_c.length_squared();
    let r2 = radius * radius;
    let cos_max = (1.0 - r2 / d2).max(0.0).sqrt();
    if cos_max >= 1.0 {
        return None;
    }
    let w = restir_sampling::warp::sample_uniform_cone(u, cos_max);
    let frame = restir_geometry::Frame::from_normal(to_c / d2.sqrt());
    let d = frame.to_world(w);
    let b = d.dot(to_c);
    let disc = (r2 - (d2 - b * b)).max(0.0);
    Some(ref_p + d * (b - disc.sqrt()))
}

/// A mesh light whose vertex normals differ from its face normal (as in any smooth-shaded mesh):
/// its points are sampled uniformly by area, so the density of directions is
/// `d² / (area · |cos θ_geometric|)`. Guards against converting the area pdf with the *shading*
/// normal (an earlier bug: p ≈ 0 then).
#[test]
fn mesh_light_with_shading_normals() {
    let n = Vec3::new(0.6, 0.0, 1.0).normalize();
    let positions = vec![
        Vec3::new(-1.0, -1.0, -1.0),
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(1.0, 1.0, -1.0),
        Vec3::new(-1.0, 1.0, -1.0),
    ];
    let mesh = TriangleMesh::new(
        positions,
        Some(vec![n; 4]),
        None,
        vec![[0, 1, 2], [2, 3, 0]],
        false,
    )
    .unwrap();
    let shapes = vec![Shape::Mesh(mesh)];
    let light = Light::Area {
        shape: 0,
        radiance: Vec3::ONE,
        texture: None,
    };
    let set = LightSet::new(
        vec![light],
        &shapes[..],
        (Vec3::splat(-2.0), Vec3::splat(2.0)),
    )
    .unwrap();
    let ref_p = Vec3::new(0.3, 0.2, 0.0);
    let grid = SphereGrid::default();
    // The density the sampler claims, from `pdf_sa` at the traced point (as in the other tests).
    let claimed = mixture(&set, &per_light_cells(&set, &shapes, ref_p, &grid), |l| {
        set.pmf(l) as f64
    });
    let hist = sample_directions(&set, ref_p, &grid, 40, 500_000);
    assert_accepted("mesh light with shading normals", hist.chi2(&claimed));
}

/// Negative control: the same samples as (b) against uniform light selection (1 / #lights
/// instead of power-proportional) must be rejected.
#[test]
fn control_uniform_selection_is_rejected() {
    let (shapes, set) = scene();
    let grid = SphereGrid::new(16, 32).unwrap();
    let per_light = per_light_cells(&set, &shapes, REF_P, &grid);
    let uniform = 1.0 / set.len() as f64;
    let wrong = mixture(&set, &per_light, |_| uniform);
    let hist = sample_directions(&set, REF_P, &grid, 22, 1_000_000);
    let o = hist
        .chi2(&wrong)
        .unwrap_or_else(|e| panic!("expected a p-value, got {e}"));
    eprintln!("uniform selection: {o}");
    assert!(o.p_value < 1e-6, "uniform selection passed: {o}");
}
