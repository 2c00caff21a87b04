//! Renders the host renderer's scene with ReSTIR DI (from `restir-reuse`) and with its own
//! direct-lighting estimator at equal passes, writes both as PNG and prints their times.
//!
//! `cargo run --release -p host-renderer -- [width height passes out-dir]`

use std::path::PathBuf;
use std::time::Instant;

use host_renderer::{Lights, Scene, render_reference, render_restir};
use restir_reuse::direct::DirectSettings;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, default: usize| -> usize {
        match args.get(i) {
            None => default,
            Some(a) => a.parse().unwrap_or_else(|_| {
                eprintln!("error: argument {} ({a:?}) is not a whole number", i + 1);
                std::process::exit(1)
            }),
        }
    };
    let (width, height, passes) = (arg(0, 640), arg(1, 360), arg(2, 4) as u32);
    let out = PathBuf::from(args.get(3).map_or(".", String::as_str));
    let scene = Scene::demo(5, 16);
    let lights = Lights {
        scene: &scene,
        wrong_pdf: false,
    };
    let start = Instant::now();
    let restir = render_restir(&lights, width, height, passes, 1, DirectSettings::default());
    let t_restir = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let reference = render_reference(&scene, width, height, passes, 1);
    let t_reference = start.elapsed().as_secs_f64();
    for (image, name) in [
        (&restir, "restir-di.png"),
        (&reference, "light-sampling.png"),
    ] {
        let path = out.join(name);
        if let Err(e) = image.write_png(&path) {
            eprintln!("error: cannot write {}: {e}", path.display());
            std::process::exit(1);
        }
    }
    println!(
        "{width}×{height}, {passes} passes, {} lights: ReSTIR DI {t_restir:.2} s, light sampling {t_reference:.2} s; images in {}",
        scene.lights.len(),
        out.display()
    );
}
