//! Estimators for the `restir` renderer and the code around them: the render driver, pixel
//! filters, image I/O and error metrics.
//!
//! The entry point for programs and tests is [`render`]: give it a built
//! [`Scene`](restir_scene::Scene), an [`Integrator`] and [`RenderSettings`], and it returns the
//! averaged image with statistics. A *pass* is one sample per pixel of the integrator's final
//! estimator; images are bit-identical whatever the thread count, because every pixel's random
//! numbers come from `(seed, pixel, pass)`.
//!
//! ```no_run
//! use std::sync::atomic::AtomicBool;
//! use restir_integrators::{make_integrator, render, RenderSettings};
//! let loaded = restir_scene::load_scene("scenes/cornell-box.xml".as_ref(), &[]).unwrap();
//! let integrator = make_integrator("path", &loaded.scene, None).unwrap();
//! let settings = RenderSettings { spp: 16, time_limit: None, seed: 0 };
//! let out = render(&loaded.scene, integrator.as_ref(), &settings, &AtomicBool::new(false), &mut |_, _| {});
//! out.image.write("cbox.exr".as_ref()).unwrap();
//! ```

pub mod film;
mod image_io;
pub mod metrics;
pub mod path;
mod render;

pub use image_io::{Image, ImageError};
pub use metrics::{ErrorMetrics, compare};
pub use render::{Integrator, PassContext, PathIntegrator, RenderOutput, RenderSettings, render};

use restir_scene::Scene;

/// The integrators this crate provides, by command-line name.
pub const INTEGRATORS: &[&str] = &["path"];

/// Builds the integrator called `name` for `scene`; `max_depth` overrides the scene's.
pub fn make_integrator(
    name: &str,
    scene: &Scene,
    max_depth: Option<i32>,
) -> Result<Box<dyn Integrator>, String> {
    let mut settings = path::PathSettings::from_scene(scene);
    if let Some(d) = max_depth {
        if d < -1 {
            return Err(format!(
                "max depth {d} must be -1 (unbounded) or non-negative"
            ));
        }
        settings.max_depth = d;
    }
    match name {
        "path" => Ok(Box::new(PathIntegrator { settings })),
        other => Err(format!(
            "unknown integrator '{other}' (available: {})",
            INTEGRATORS.join(", ")
        )),
    }
}
