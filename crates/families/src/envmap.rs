//! Procedural environment maps: latitude-longitude [`Image`]s (Mitsuba's orientation, `+Y` up,
//! `u = 0` towards `−Z`, row 0 at the zenith) that a generated scene writes beside its RON file
//! as EXR and names in an `Envmap` light.
//!
//! [`sky`] is a clear sky (zenith blue to a pale horizon, a dim ground) with a small sun disk and
//! its glow; [`studio`] is a dark studio with a few bright soft boxes. Both are deterministic in
//! their arguments, so that a scene's seed fixes its environment too.

use glam::Vec3;
use restir_image::Image;
use restir_sampling::Pcg32;

use super::util::uniform;
use super::{Asset, AssetContents};
use restir_scene::LightDesc;

/// The unit direction of the centre of texel-space point `(u, v)` in `[0, 1]²`.
pub fn direction(u: f32, v: f32) -> Vec3 {
    let theta = v * core::f32::consts::PI;
    let phi = u * core::f32::consts::TAU;
    Vec3::new(
        theta.sin() * phi.sin(),
        theta.cos(),
        -theta.sin() * phi.cos(),
    )
}

/// The direction at elevation `elevation` (degrees above the horizon) and azimuth `azimuth`
/// (degrees, 0 towards `−Z`, 90 towards `+X`).
pub fn direction_at(elevation: f32, azimuth: f32) -> Vec3 {
    let (e, a) = (elevation.to_radians(), azimuth.to_radians());
    Vec3::new(e.cos() * a.sin(), e.sin(), -e.cos() * a.cos())
}

fn fill(width: u32, height: u32, f: impl Fn(Vec3) -> Vec3) -> Image {
    let mut image = Image::new(width, height);
    for y in 0..height {
        for x in 0..width {
            let d = direction(
                (x as f32 + 0.5) / width as f32,
                (y as f32 + 0.5) / height as f32,
            );
            image.pixels[(y * width + x) as usize] = f(d);
        }
    }
    image
}

/// Where [`sky`] puts its sun for `seed` when no direction is given: elevation 15°–45°, any
/// azimuth.
pub fn sky_sun(seed: u64) -> Vec3 {
    let mut rng = Pcg32::new(seed, 0x736b_7900); // "sky"
    let elevation = uniform(&mut rng, 15.0, 45.0);
    let azimuth = uniform(&mut rng, 0.0, 360.0);
    direction_at(elevation, azimuth)
}

/// A scene's sky: a 512×256 [`sky`] image written beside the scene as `filename`, and the
/// environment light that shows it at `scale`.
pub fn sky_light(
    filename: String,
    seed: u64,
    sun: Vec3,
    sun_radiance: f32,
    scale: f32,
) -> (Asset, LightDesc) {
    let asset = Asset {
        filename: filename.clone(),
        contents: AssetContents::Image(sky(seed, 512, 256, sun, sun_radiance)),
    };
    let light = LightDesc::Envmap {
        filename,
        scale,
        to_world: Vec::new(),
        location: Default::default(),
    };
    (asset, light)
}

/// A clear sky with a sun in direction `sun` (unit, above the horizon): radiance about 0.3–0.6
/// in the sky, 0.05 on the ground, `sun_radiance` in a disk of about 2.5° and a glow around it.
/// `seed` varies the sky's tint slightly.
pub fn sky(seed: u64, width: u32, height: u32, sun: Vec3, sun_radiance: f32) -> Image {
    let mut rng = Pcg32::new(seed, 0x736b_7901);
    let warmth = uniform(&mut rng, 0.0, 0.15);
    let zenith = Vec3::new(0.12 + warmth * 0.3, 0.25, 0.55);
    let horizon = Vec3::new(0.6 + warmth, 0.62 + warmth * 0.5, 0.65);
    let ground = Vec3::new(0.06, 0.05, 0.04);
    let sun = sun.normalize();
    let sun_colour = Vec3::new(1.0, 0.92 - warmth, 0.8 - warmth);
    let cos_disk = 2.5f32.to_radians().cos();
    fill(width, height, |d| {
        let base = if d.y >= 0.0 {
            let t = d.y.sqrt();
            horizon.lerp(zenith, t)
        } else {
            // A short blend below the horizon so the seam is not a hard edge.
            horizon.lerp(ground, (-d.y * 8.0).min(1.0))
        };
        let c = d.dot(sun);
        let glow = if d.y > -0.05 {
            0.4 * sun_colour * (8.0 * (c - 1.0)).exp()
        } else {
            Vec3::ZERO
        };
        let disk = if c > cos_disk {
            sun_colour * sun_radiance
        } else {
            Vec3::ZERO
        };
        base + glow + disk
    })
}

/// A dark studio (radiance 0.02) with 2–4 soft boxes: rectangles in (azimuth, elevation) of
/// radiance 2–8, warm to cool white, at elevations 10°–70°.
pub fn studio(seed: u64, width: u32, height: u32) -> Image {
    let mut rng = Pcg32::new(seed, 0x7374_7564); // "stud"
    let boxes: Vec<(f32, f32, f32, f32, Vec3)> = (0..2 + rng.next_bounded(3))
        .map(|_| {
            let azimuth = uniform(&mut rng, 0.0, 360.0);
            let elevation = uniform(&mut rng, 10.0, 70.0);
            let half_az = uniform(&mut rng, 6.0, 15.0);
            let half_el = uniform(&mut rng, 4.0, 10.0);
            let level = uniform(&mut rng, 2.0, 8.0);
            let tint = uniform(&mut rng, -0.1, 0.1);
            let colour = Vec3::new(1.0 + tint, 1.0, 1.0 - tint) * level;
            (azimuth, elevation, half_az, half_el, colour)
        })
        .collect();
    fill(width, height, |d| {
        let elevation = d.y.clamp(-1.0, 1.0).asin().to_degrees();
        let azimuth = d.x.atan2(-d.z).to_degrees().rem_euclid(360.0);
        let mut c = Vec3::splat(0.02);
        for &(az, el, half_az, half_el, colour) in &boxes {
            let daz = ((azimuth - az + 540.0).rem_euclid(360.0) - 180.0).abs();
            if daz < half_az && (elevation - el).abs() < half_el {
                c += colour;
            }
        }
        c
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direction_matches_the_envmap_convention() {
        // u = atan2(x, −z) / 2π, v = θ / π: u = 0 is −Z, u = ¼ is +X, v = 0 is +Y.
        assert!((direction(0.0, 0.5) - Vec3::NEG_Z).length() < 1e-6);
        assert!((direction(0.25, 0.5) - Vec3::X).length() < 1e-6);
        assert!((direction(0.3, 0.0) - Vec3::Y).length() < 1e-6);
        assert!((direction_at(0.0, 90.0) - Vec3::X).length() < 1e-6);
    }

    #[test]
    fn sky_is_finite_deterministic_and_brightest_at_the_sun() {
        let sun = sky_sun(3);
        let a = sky(3, 64, 32, sun, 500.0);
        assert_eq!(a, sky(3, 64, 32, sun, 500.0));
        assert_eq!(a.nonfinite_count(), 0);
        let (brightest, _) = a
            .pixels
            .iter()
            .enumerate()
            .max_by(|x, y| x.1.x.total_cmp(&y.1.x))
            .unwrap();
        let (x, y) = (brightest as u32 % 64, brightest as u32 / 64);
        let d = direction((x as f32 + 0.5) / 64.0, (y as f32 + 0.5) / 32.0);
        assert!(
            d.dot(sun) > 0.98,
            "brightest texel {d} far from the sun {sun}"
        );
        let s = studio(3, 64, 32);
        assert_eq!(s.nonfinite_count(), 0);
        assert!(s.pixels.iter().any(|p| p.x > 1.0));
    }
}
