//! Mitsuba's `spot` light through the light set: its angular profile (a chi-square test), its
//! power (an unbiasedness test against the closed form), the receiver-independent path ReSTIR
//! uses (`LightPoint` → `Resolved` → `Contact`) against `sample`, and the projected texture's
//! orientation.
//!
//! The profile is Mitsuba 3's (`src/emitters/spot.cpp`): 1 within `beam_width` of the axis, then
//! `(cutoff − θ)/(cutoff − beam)`, 0 beyond `cutoff`; written here again from that description,
//! not taken from the crate.

mod common;

use core::f32::consts::PI;
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};
use restir_geometry::Shape;
use restir_lights::{Light, LightError, LightSet, LightTexture, Spot};
use restir_sampling::{Pcg32, luminance, warp};
use restir_testkit::{Histogram, RunningStats, sidak_level, trials};

const CUTOFF: f32 = 30.0;
const BEAM: f32 = 18.0;
const POSITION: Vec3 = Vec3::new(0.2, -0.1, 0.3);
const INTENSITY: Vec3 = Vec3::new(2.0, 1.0, 0.5);
/// Distance of the receivers from the light.
const R: f32 = 2.0;

/// The light's frame: a look-at from `POSITION` towards a tilted axis.
fn to_world() -> Mat4 {
    common::tilted_frame(POSITION)
}

fn set_with(texture: Option<Arc<dyn LightTexture>>) -> LightSet {
    let spot = Spot::new(
        to_world(),
        INTENSITY,
        CUTOFF,
        BEAM,
        texture.as_ref().map(|_| 0),
    )
    .unwrap();
    let shapes: Vec<Shape> = Vec::new();
    LightSet::with_textures(
        vec![Light::Spot(spot)],
        None,
        texture.into_iter().collect(),
        &shapes[..],
        (Vec3::splat(-3.0), Vec3::splat(3.0)),
    )
    .unwrap()
}

/// Mitsuba's profile at angle `theta` (radians) from the axis.
fn profile(theta: f64) -> f64 {
    let (c, b) = (f64::from(CUTOFF).to_radians(), f64::from(BEAM).to_radians());
    if theta >= c {
        0.0
    } else if theta <= b {
        1.0
    } else {
        (c - theta) / (c - b)
    }
}

/// A wrong profile for the negative control: linear in cos θ between the beam and the cutoff.
fn profile_linear_in_cos(theta: f64) -> f64 {
    let (c, b) = (f64::from(CUTOFF).to_radians(), f64::from(BEAM).to_radians());
    if theta >= c {
        0.0
    } else if theta <= b {
        1.0
    } else {
        (theta.cos() - c.cos()) / (b.cos() - c.cos())
    }
}

/// Angle bins from the axis: 40 over [0, cutoff + 10°].
const BINS: usize = 40;
fn bin_width() -> f64 {
    f64::from(CUTOFF + 10.0).to_radians() / BINS as f64
}

/// Probability that a uniform direction lands in bin `k` and is accepted with probability
/// `profile(θ)`: `½ ∫ profile(θ) sin θ dθ` over the bin.
fn expected(profile: impl Fn(f64) -> f64) -> Vec<f64> {
    let h = bin_width();
    (0..BINS)
        .map(|k| {
            let n = 2000;
            (0..n)
                .map(|i| {
                    let t = (k as f64 + (i as f64 + 0.5) / n as f64) * h;
                    0.5 * profile(t) * t.sin() * h / n as f64
                })
                .sum()
        })
        .collect()
}

/// Directions from the light, uniform on the sphere, each kept with probability
/// `I(ω)/I_axis` as `LightSet::sample` reports it from a receiver at `POSITION + R·ω`; the kept
/// ones binned by their angle from the axis, the others in the remainder.
fn profile_histogram(set: &LightSet, seed: u64, n: usize) -> Histogram {
    let axis = to_world().z_axis.truncate();
    let mut rng = Pcg32::new(seed, 0);
    let mut hist = Histogram::new(BINS);
    for _ in 0..n {
        let w = warp::sample_uniform_sphere(rng.next_2d());
        let x = POSITION + R * w;
        let keep = rng.next_f32();
        let Some(s) = set.sample(x, rng.next_f32(), rng.next_2d()) else {
            hist.record_remainder();
            continue;
        };
        assert!(s.delta && s.pdf_sa == 1.0);
        assert!((s.wi + w).length() < 1e-4 && (s.dist - R).abs() < 1e-4);
        let f = luminance(s.le) * R * R / luminance(INTENSITY);
        assert!((0.0..=1.0 + 1e-5).contains(&f), "{f}");
        if keep < f {
            let theta = f64::from(w.dot(axis).clamp(-1.0, 1.0)).acos();
            let k = (theta / bin_width()) as usize;
            hist.record(Some(k.min(BINS - 1)).filter(|_| k < BINS));
        } else {
            hist.record_remainder();
        }
    }
    hist
}

#[test]
fn angular_profile_is_mitsubas() {
    let set = set_with(None);
    let hist = profile_histogram(&set, 11, trials(1_000_000));
    let o = hist.chi2(&expected(profile)).unwrap();
    eprintln!("spot profile: {o}");
    assert!(o.accepts(sidak_level(0.01, 1)), "{o}");
    // Negative control: a falloff linear in cos θ (a plausible mistake) is rejected.
    let wrong = hist.chi2(&expected(profile_linear_in_cos));
    eprintln!("control (linear in cos θ): {wrong:?}");
    assert!(wrong.is_err() || !wrong.unwrap().accepts(1e-6));
}

/// `∫ I(ω) dω` in closed form: `2π I [(1 − cos b) + ((c − b) cos b + sin b − sin c)/(c − b)]`.
fn closed_form_power(c_deg: f32, b_deg: f32) -> f64 {
    let (c, b) = (f64::from(c_deg).to_radians(), f64::from(b_deg).to_radians());
    let ramp = if c > b {
        ((c - b) * b.cos() + b.sin() - c.sin()) / (c - b)
    } else {
        0.0
    };
    2.0 * std::f64::consts::PI * ((1.0 - b.cos()) + ramp)
}

#[test]
fn power_is_unbiased() {
    let set = set_with(None);
    let truth = closed_form_power(CUTOFF, BEAM) * f64::from(luminance(INTENSITY));
    // The set's selection weight is the same power.
    assert!((f64::from(set.power(0)) - truth).abs() < 1e-4 * truth);
    // Φ = ∮ E dA over a sphere of radius R around the light: uniform points, E = I/R².
    let mut rng = Pcg32::new(5, 0);
    let mut stats = RunningStats::default();
    for _ in 0..trials(2_000_000) {
        let w = warp::sample_uniform_sphere(rng.next_2d());
        let le = set
            .sample(POSITION + R * w, rng.next_f32(), rng.next_2d())
            .map_or(0.0, |s| luminance(s.le));
        stats.push(f64::from(4.0 * PI * R * R * le));
    }
    stats.assert_unbiased(truth, "spot power");
    // Negative control: a hard-edged cone at the cutoff is many standard errors off.
    let hard = 2.0
        * std::f64::consts::PI
        * (1.0 - f64::from(CUTOFF).to_radians().cos())
        * f64::from(luminance(INTENSITY));
    let z = (stats.mean() - hard) / stats.std_error();
    eprintln!(
        "spot power: {} vs {truth}; hard-cone control z = {z:.1}",
        stats.mean()
    );
    assert!(z.abs() > 10.0, "{z}");
}

/// The sample a reservoir holds, resolved once and seen from the receiver, is what `sample`
/// returned; a presampled pool draws it per receiver; nothing beyond the cutoff.
#[test]
fn reservoir_path_agrees_with_sample() {
    common::reservoir_path_agrees_with_sample(&set_with(None), POSITION);
}

/// The texture is read at `(½ + ½ tan θₓ / tan c, ½ + ½ tan θ_y / tan c)` in the light's frame
/// (the frame's `+x` and `+y` as `to_world` gives them).
#[test]
fn texture_is_projected_along_the_frame() {
    let set = set_with(Some(Arc::new(common::UvRamp)));
    let m = to_world();
    let (x, y, z) = (
        m.x_axis.truncate(),
        m.y_axis.truncate(),
        m.z_axis.truncate(),
    );
    let tan_c = CUTOFF.to_radians().tan();
    for (t, dir, want) in [
        (0.0f32, x, Vec2::splat(0.5)),
        (
            10.0,
            x,
            Vec2::new(0.5 + 0.5 * 10f32.to_radians().tan() / tan_c, 0.5),
        ),
        (
            -10.0,
            x,
            Vec2::new(0.5 - 0.5 * 10f32.to_radians().tan() / tan_c, 0.5),
        ),
        (
            15.0,
            y,
            Vec2::new(0.5, 0.5 + 0.5 * 15f32.to_radians().tan() / tan_c),
        ),
    ] {
        let w = (z + t.to_radians().tan() * dir).normalize();
        let s = set.sample(POSITION + R * w, 0.5, Vec2::ZERO).unwrap();
        let uv = s.le * R * R / INTENSITY;
        assert!(
            (uv.truncate() - want).length() < 1e-4 && (uv.z - 1.0).abs() < 1e-4,
            "{t}° along {dir}: {uv} vs {want}"
        );
    }
    // A textured spot needs its texture.
    let spot = Spot::new(to_world(), INTENSITY, CUTOFF, BEAM, Some(0)).unwrap();
    let shapes: Vec<Shape> = Vec::new();
    assert_eq!(
        LightSet::new(
            vec![Light::Spot(spot)],
            &shapes[..],
            (Vec3::ZERO, Vec3::ONE)
        )
        .err(),
        Some(LightError::MissingLightTexture(0, 0))
    );
}
