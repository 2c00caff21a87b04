//! Mitsuba's `projector` through the light set: where its power goes over the image (a
//! chi-square test), its power (an unbiasedness test against the closed form), the
//! receiver-independent path ReSTIR uses (`LightPoint` → `Resolved` → `Contact`) against
//! `sample`, and the image's orientation.
//!
//! Mitsuba 3 (`src/emitters/projector.cpp`) sends `π·scale·E(uv) / (z² cos θ)` to a receiver at
//! depth `z` in the light's frame, `θ` off the axis: the irradiance on the plane `z = 1` is
//! `π·scale·E(uv)`, with `uv` the perspective sensor's film position of the receiver (`u` along
//! the frame's `−x`, `v` along its `−y`). Written here again from that description, not taken
//! from the crate.

mod common;

use core::f32::consts::PI;
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};
use restir_geometry::{FovAxis, Shape};
use restir_lights::{Light, LightError, LightSet, LightTexture, Projector};
use restir_sampling::{Pcg32, luminance, warp};
use restir_testkit::{Grid2D, Histogram, Quadrature, RunningStats, sidak_level, trials};

const POSITION: Vec3 = Vec3::new(0.2, -0.1, 0.3);
const IRRADIANCE: Vec3 = Vec3::new(1.0, 0.8, 0.5);
const SCALE: f32 = 2.0;
/// Horizontal field of view in degrees of a 4 × 3 image.
const FOV: f32 = 60.0;
const RESOLUTION: (u32, u32) = (4, 3);
/// Distance of the receivers from the light.
const R: f32 = 2.0;

/// The light's frame: Mitsuba's look-at from `POSITION` towards a tilted axis (`x = up × z`, the
/// image's left).
fn to_world() -> Mat4 {
    common::tilted_frame(POSITION)
}

/// Half the image's extent on the plane `z = 1`: `tan 30°` across, ¾ of it up and down.
fn tan_half() -> (f64, f64) {
    let tx = f64::from(FOV / 2.0).to_radians().tan();
    (tx, tx * 3.0 / 4.0)
}

/// A grey texture `u·(1 + v)`, mean ¾, brighter to the right (`u`) and at the bottom (`v`).
#[derive(Debug)]
struct Ramp;
impl LightTexture for Ramp {
    fn eval(&self, uv: Vec2) -> Vec3 {
        Vec3::splat(uv.x * (1.0 + uv.y))
    }
    fn mean(&self) -> Vec3 {
        Vec3::splat(0.75)
    }
}
fn ramp(u: f64, v: f64) -> f64 {
    u * (1.0 + v)
}

fn set_with(texture: Option<Arc<dyn LightTexture>>) -> LightSet {
    let projector = Projector::new(
        to_world(),
        IRRADIANCE,
        SCALE,
        FOV,
        FovAxis::X,
        RESOLUTION,
        texture.as_ref().map(|_| 0),
    )
    .unwrap();
    let shapes: Vec<Shape> = Vec::new();
    LightSet::with_textures(
        vec![Light::Projector(projector)],
        None,
        texture.into_iter().collect(),
        &shapes[..],
        (Vec3::splat(-3.0), Vec3::splat(3.0)),
    )
    .unwrap()
}

/// The film position of world direction `w` from the light, and the cosine of its angle from
/// the axis; `None` off the image.
fn film(w: Vec3) -> Option<(f64, f64, f64)> {
    let m = to_world();
    let (x, y, z) = (
        m.x_axis.truncate(),
        m.y_axis.truncate(),
        m.z_axis.truncate(),
    );
    let (lx, ly, lz) = (
        f64::from(w.dot(x)),
        f64::from(w.dot(y)),
        f64::from(w.dot(z)),
    );
    if lz <= 0.0 {
        return None;
    }
    let (tx, ty) = tan_half();
    let u = 0.5 - 0.5 * lx / (lz * tx);
    let v = 0.5 - 0.5 * ly / (lz * ty);
    let cos = lz / (lx * lx + ly * ly + lz * lz).sqrt();
    ((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)).then_some((u, v, cos))
}

/// The cosine from the axis of the direction through film position `(u, v)`.
fn cos_at(u: f64, v: f64) -> f64 {
    let (tx, ty) = tan_half();
    let (x, y) = ((1.0 - 2.0 * u) * tx, (1.0 - 2.0 * v) * ty);
    1.0 / (1.0 + x * x + y * y).sqrt()
}

/// The largest intensity luminance: the texture's maximum (2) at the image's corner.
fn max_intensity() -> f64 {
    f64::from(PI * SCALE * luminance(IRRADIANCE)) * 2.0 / cos_at(1.0, 1.0).powi(3)
}

const NX: usize = 8;
const NY: usize = 6;

/// Directions from the light, uniform on the sphere, each kept with probability `I(ω)/I_max` as
/// `LightSet::sample` reports it from a receiver at `POSITION + R·ω`; the kept ones binned by
/// their film position, the others in the remainder.
fn film_histogram(set: &LightSet, seed: u64, n: usize) -> Histogram {
    let grid = Grid2D::unit_square(NX, NY).unwrap();
    let mut rng = Pcg32::new(seed, 0);
    let mut hist = Histogram::new(grid.len());
    let i_max = max_intensity();
    for _ in 0..n {
        let w = warp::sample_uniform_sphere(rng.next_2d());
        let x = POSITION + R * w;
        let keep = f64::from(rng.next_f32());
        let Some(s) = set.sample(x, rng.next_f32(), rng.next_2d()) else {
            assert!(film(w).is_none_or(|(u, v, _)| ramp(u, v) < 1e-6));
            hist.record_remainder();
            continue;
        };
        assert!(s.delta && s.pdf_sa == 1.0);
        assert!((s.wi + w).length() < 1e-4 && (s.dist - R).abs() < 1e-4);
        let f = f64::from(luminance(s.le) * R * R) / i_max;
        assert!((0.0..=1.0 + 1e-5).contains(&f), "{f}");
        if keep < f {
            let (u, v, _) = film(w).expect("light only on the image");
            hist.record(grid.bin(u, v));
        } else {
            hist.record_remainder();
        }
    }
    hist
}

/// Probability of landing in each film cell: `(1/4π) ∫ I/I_max dω` over the cell's directions,
/// with `dω = cos³θ dA` on the plane `z = 1`, `dA = 4 tan(fov_x/2) tan(fov_y/2) du dv`, and
/// `I = π·scale·E·w(cos θ)` for the intensity's angular factor `w` (Mitsuba: `1/cos³θ`).
fn expected(texture: impl Fn(f64, f64) -> f64, angular: impl Fn(f64) -> f64) -> Vec<f64> {
    let (tx, ty) = tan_half();
    let k = f64::from(PI * SCALE * luminance(IRRADIANCE)) * 4.0 * tx * ty
        / (4.0 * std::f64::consts::PI * max_intensity());
    Grid2D::unit_square(NX, NY).unwrap().integrate(
        |u, v| {
            let c = cos_at(u, v);
            k * texture(u, v) * angular(c) * c.powi(3)
        },
        &Quadrature::default(),
    )
}

#[test]
fn power_goes_where_the_image_says() {
    let set = set_with(Some(Arc::new(Ramp)));
    let hist = film_histogram(&set, 11, trials(1_000_000));
    let o = hist.chi2(&expected(ramp, |c: f64| c.powi(-3))).unwrap();
    eprintln!("projector film distribution: {o}");
    assert!(o.accepts(sidak_level(0.01, 1)), "{o}");
    // Negative controls: the image mirrored left to right, and an intensity without the
    // 1/cos³θ that keeps the plane's irradiance flat.
    let mirrored = hist.chi2(&expected(|u, v| ramp(1.0 - u, v), |c: f64| c.powi(-3)));
    eprintln!("control (mirrored image): {mirrored:?}");
    assert!(mirrored.is_err() || !mirrored.unwrap().accepts(1e-6));
    let flat = hist.chi2(&expected(ramp, |_| 1.0));
    eprintln!("control (no 1/cos³θ): {flat:?}");
    assert!(flat.is_err() || !flat.unwrap().accepts(1e-6));
}

/// Φ = ∮ E dA over a sphere of radius `R` around the light (uniform points, `E = I/R²`) against
/// the closed form `π·scale·mean(E)·4·tan(fov_x/2)·tan(fov_y/2)`, with and without a texture.
#[test]
fn power_is_unbiased() {
    let (tx, ty) = tan_half();
    for (texture, mean) in [
        (None, 1.0),
        (Some(Arc::new(Ramp) as Arc<dyn LightTexture>), 0.75),
    ] {
        let textured = texture.is_some();
        let set = set_with(texture);
        let truth = f64::from(PI * SCALE * luminance(IRRADIANCE)) * mean * 4.0 * tx * ty;
        // The set's selection weight is the same power.
        assert!(
            (f64::from(set.power(0)) - truth).abs() < 1e-5 * truth,
            "{} vs {truth}",
            set.power(0)
        );
        let mut rng = Pcg32::new(5, 0);
        let mut stats = RunningStats::default();
        for _ in 0..trials(2_000_000) {
            let w = warp::sample_uniform_sphere(rng.next_2d());
            let le = set
                .sample(POSITION + R * w, rng.next_f32(), rng.next_2d())
                .map_or(0.0, |s| luminance(s.le));
            stats.push(f64::from(4.0 * PI * R * R * le));
        }
        stats.assert_unbiased(truth, "projector power");
        // Negative control: the power of an intensity without the 1/cos³θ (π·scale·E over the
        // frustum's solid angle) is many standard errors off.
        let flat: f64 = expected(|u, v| if textured { ramp(u, v) } else { 1.0 }, |_| 1.0)
            .iter()
            .sum::<f64>()
            * 4.0
            * std::f64::consts::PI
            * max_intensity();
        let z = (stats.mean() - flat) / stats.std_error();
        eprintln!(
            "projector power (textured {textured}): {} vs {truth}; flat control z = {z:.1}",
            stats.mean()
        );
        assert!(z.abs() > 10.0, "{z}");
    }
}

/// The sample a reservoir holds, resolved once and seen from the receiver, is what `sample`
/// returned; a presampled pool draws it per receiver; nothing beyond the frustum.
#[test]
fn reservoir_path_agrees_with_sample() {
    common::reservoir_path_agrees_with_sample(&set_with(Some(Arc::new(Ramp))), POSITION);
}

/// The image is upright and unmirrored seen along the projector: `u` grows to the right (the
/// frame's `−x`), `v` downwards (the frame's `−y`); the plane `z = 1` is lit with
/// `π·scale·irradiance·E` wherever it is hit.
#[test]
fn image_is_projected_upright() {
    let set = set_with(Some(Arc::new(common::UvRamp)));
    let m = to_world();
    let (x, y, z) = (
        m.x_axis.truncate(),
        m.y_axis.truncate(),
        m.z_axis.truncate(),
    );
    let (tx, ty) = tan_half();
    let (tx, ty) = (tx as f32, ty as f32);
    for (right, up, want) in [
        (0.0f32, 0.0f32, Vec2::splat(0.5)),
        (0.5, 0.0, Vec2::new(0.75, 0.5)),
        (-0.5, 0.0, Vec2::new(0.25, 0.5)),
        (0.0, 0.5, Vec2::new(0.5, 0.25)),
        (-0.9, -0.9, Vec2::new(0.05, 0.95)),
    ] {
        // The point of the plane z = 1 at film position `want`, at distance `d` along its ray.
        let p = z - right * tx * x + up * ty * y;
        let d = 1.7;
        let s = set
            .sample(POSITION + d * p, 0.5, Vec2::ZERO)
            .expect("on the image");
        // Irradiance on the plane z = d: I cos θ / dist² = le · cos θ.
        let cos = 1.0 / p.length();
        let e = s.le * cos * d * d / (PI * SCALE * IRRADIANCE);
        assert!(
            (e.truncate() - want).length() < 1e-4 && (e.z - 1.0).abs() < 1e-4,
            "right {right}, up {up}: {e} vs {want}"
        );
    }
    // Beyond the image's edge, and behind the projector: nothing.
    assert!(
        set.sample(POSITION + z + 1.01 * tx * x, 0.5, Vec2::ZERO)
            .is_none()
    );
    assert!(
        set.sample(POSITION + z + 1.01 * ty * y, 0.5, Vec2::ZERO)
            .is_none()
    );
    assert!(set.sample(POSITION - z, 0.5, Vec2::ZERO).is_none());
    // A textured projector needs its texture.
    let p = Projector::new(
        to_world(),
        IRRADIANCE,
        SCALE,
        FOV,
        FovAxis::X,
        RESOLUTION,
        Some(0),
    )
    .unwrap();
    let shapes: Vec<Shape> = Vec::new();
    assert_eq!(
        LightSet::new(
            vec![Light::Projector(p)],
            &shapes[..],
            (Vec3::ZERO, Vec3::ONE)
        )
        .err(),
        Some(LightError::MissingLightTexture(0, 0))
    );
}
