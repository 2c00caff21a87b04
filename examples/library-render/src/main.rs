//! Renders a scene through the restir crates as a library, in a few lines: load the scene,
//! `Renderer::new(&loaded).spp(n).render()`, use the image.
//!
//! ```sh
//! cargo run --release -p library-render -- scenes/cornell-box.xml 16 out.exr
//! ```
//!
//! Arguments: the scene file, the number of passes (default 4), and an optional output image
//! (`.exr`, `.png`, ...). Prints the image size and its mean radiance. Any error is printed and
//! the exit status is 1.

use std::process::ExitCode;

use restir_integrators::Renderer;
use restir_scene::{LoadOptions, load_scene};

fn run(args: &[String]) -> Result<(), Box<dyn std::error::Error>> {
    let [scene, rest @ ..] = args else {
        return Err("usage: library-render SCENE [SPP] [OUTPUT]".into());
    };
    let spp: u32 = match rest.first() {
        Some(n) => n
            .parse()
            .map_err(|_| format!("SPP must be a whole number, not '{n}'"))?,
        None => 4,
    };
    // Small by default so that the example is quick; drop the override for the scene's size.
    let options = LoadOptions {
        width: Some(64),
        height: Some(64),
        ..LoadOptions::default()
    };
    let loaded = load_scene(scene.as_ref(), &options)?;

    // The one line that renders.
    let out = Renderer::new(&loaded).spp(spp).render()?;

    let mean = out.image.mean();
    println!(
        "{}x{} pixels, {} passes, mean radiance ({:.4}, {:.4}, {:.4})",
        out.image.width, out.image.height, out.passes, mean.x, mean.y, mean.z
    );
    if let Some(path) = rest.get(1) {
        out.image.write(path.as_ref())?;
        println!("-> {path}");
    }
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("library-render: {e}");
            ExitCode::FAILURE
        }
    }
}
