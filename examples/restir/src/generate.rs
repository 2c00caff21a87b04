//! `restir generate`: the subcommand's arguments and writing the file; the scenes themselves
//! come from [`restir_scene::generate`], the environment map (a procedural sky, the asset of
//! `scenes/envmap-spheres.xml`) from [`sky`].

use std::path::PathBuf;

use glam::Vec3;
use restir_image::Image;
use restir_scene::generate::many_lights_ron;

use crate::say::say;

/// Scenes the generator can write.
#[derive(clap::Subcommand, Debug)]
pub enum Generate {
    /// A floor with boxes and pillars lit only by many small coloured sphere lights.
    ManyLights(ManyLightsArgs),
    /// A latitude-longitude environment map (EXR): a sky with a sun over a dark ground, the map
    /// of scenes/envmap-spheres.xml.
    Envmap(EnvmapArgs),
    /// A 6×8 uv test pattern (PNG, sRGB): every texel a different colour, so a flipped or
    /// shifted lookup shows. The bitmap of scenes/textured/textured-shapes.xml.
    UvPattern(UvPatternArgs),
}

/// Options of `restir generate uv-pattern`.
#[derive(clap::Args, Debug)]
pub struct UvPatternArgs {
    /// Output PNG file.
    #[arg(
        short = 'o',
        long = "output",
        default_value = "scenes/textured/tex.png"
    )]
    output: PathBuf,
}

/// Options of `restir generate envmap`.
#[derive(clap::Args, Debug)]
pub struct EnvmapArgs {
    /// Width in texels (the height is half of it).
    #[arg(long, default_value_t = 256)]
    width: u32,
    /// Output EXR file.
    #[arg(short = 'o', long = "output", default_value = "scenes/envmap/sky.exr")]
    output: PathBuf,
}

/// Options of `restir generate many-lights`.
#[derive(clap::Args, Debug)]
pub struct ManyLightsArgs {
    /// Number of sphere lights.
    #[arg(long, default_value_t = 400)]
    lights: u32,
    /// Seed of the layout (lights and occluders).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output RON file.
    #[arg(short = 'o', long = "output", default_value = "scenes/many-lights.ron")]
    output: PathBuf,
}

/// Runs a `generate` subcommand.
pub fn run(what: Generate) -> Result<(), String> {
    match what {
        Generate::ManyLights(args) => {
            if !(1..=1_000_000).contains(&args.lights) {
                return Err(format!(
                    "--lights {}: expected 1 to 1000000 lights",
                    args.lights
                ));
            }
            let text = many_lights_ron(args.lights, args.seed).map_err(|e| e.to_string())?;
            std::fs::write(&args.output, text)
                .map_err(|e| format!("{}: {e}", args.output.display()))?;
            say!(
                "many-lights: {} lights, seed {} -> {}",
                args.lights,
                args.seed,
                args.output.display()
            );
            Ok(())
        }
        Generate::Envmap(args) => {
            if !(4..=8192).contains(&args.width) || args.width % 2 != 0 {
                return Err(format!(
                    "--width {}: expected an even width from 4 to 8192 texels",
                    args.width
                ));
            }
            create_parent(&args.output)?;
            sky(args.width, args.width / 2)
                .write(&args.output)
                .map_err(|e| e.to_string())?;
            say!(
                "envmap: sky {}×{} -> {}",
                args.width,
                args.width / 2,
                args.output.display()
            );
            Ok(())
        }
        Generate::UvPattern(args) => {
            create_parent(&args.output)?;
            uv_pattern()
                .write(&args.output)
                .map_err(|e| e.to_string())?;
            say!("uv-pattern: 6×8 -> {}", args.output.display());
            Ok(())
        }
    }
}

/// Creates the directory `path` goes in.
fn create_parent(path: &std::path::Path) -> Result<(), String> {
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create directory: {e}", dir.display())),
        None => Ok(()),
    }
}

/// A 6-wide, 8-high test pattern: red grows with the column, green with the row, blue marks a
/// checkerboard and the top-left texel is white, so every texel differs and the orientation
/// shows.
pub fn uv_pattern() -> Image {
    let (w, h) = (6u32, 8u32);
    let mut img = Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            let c = if (x, y) == (0, 0) {
                Vec3::ONE
            } else {
                Vec3::new(
                    0.1 + 0.8 * x as f32 / (w - 1) as f32,
                    0.1 + 0.8 * y as f32 / (h - 1) as f32,
                    if (x + y) % 2 == 0 { 0.8 } else { 0.1 },
                )
            };
            img.pixels[(y * w + x) as usize] = c;
        }
    }
    img
}

/// Direction of the sun in the map's frame (+Y up): 35° above the horizon.
fn sun_direction() -> Vec3 {
    let (elevation, azimuth) = (35f32.to_radians(), 0.3 * std::f32::consts::TAU);
    Vec3::new(
        azimuth.sin() * elevation.cos(),
        elevation.sin(),
        -azimuth.cos() * elevation.cos(),
    )
}

/// `0` below `a`, `1` above `b`, a smooth cubic between.
fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A procedural sky as a latitude-longitude map in Mitsuba's `envmap` layout (column `x` at
/// `u = (x + ½)/W`, row `y` at `θ = π·y/(H − 1)`, `+Y` up; see `restir_lights::envmap`): a blue
/// zenith fading to a pale horizon, a dark ground below it, and a sun of 2.5° radius with a glow.
/// Made here so the shipped scene needs nothing from outside the repository.
pub fn sky(width: u32, height: u32) -> Image {
    use std::f32::consts::{PI, TAU};
    let sun = sun_direction();
    let zenith = Vec3::new(0.06, 0.13, 0.35);
    let horizon = Vec3::new(0.4, 0.42, 0.45);
    let ground = Vec3::new(0.12, 0.1, 0.08);
    let sun_radius = 2.5f32.to_radians();
    let mut img = Image::new(width, height);
    for y in 0..height {
        let theta = PI * y as f32 / (height - 1) as f32;
        for x in 0..width {
            let phi = TAU * (x as f32 + 0.5) / width as f32;
            let d = Vec3::new(
                phi.sin() * theta.sin(),
                theta.cos(),
                -phi.cos() * theta.sin(),
            );
            let up = d.y.max(0.0);
            let sky = horizon.lerp(zenith, up.sqrt());
            let mut c = ground.lerp(sky, smoothstep(-0.04, 0.02, d.y));
            let angle = d.dot(sun).clamp(-1.0, 1.0).acos();
            c += Vec3::new(1.0, 0.92, 0.8)
                * (200.0 * (1.0 - smoothstep(0.8 * sun_radius, 1.2 * sun_radius, angle))
                    + 1.5 * (-angle / 0.12).exp());
            img.pixels[(y * width + x) as usize] = c;
        }
    }
    img
}
