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
//! use restir_integrators::{make_integrator, render, IntegratorOptions, RenderSettings};
//! let loaded = restir_scene::load_scene("scenes/cornell-box.xml".as_ref(), &[]).unwrap();
//! let options = IntegratorOptions { name: Some("restir-di".into()), ..Default::default() };
//! let made = make_integrator(&loaded.scene, &options).unwrap();
//! let settings = RenderSettings { spp: 16, time_limit: None, seed: 0 };
//! let out = render(&loaded.scene, made.integrator.as_ref(), &settings, &AtomicBool::new(false), &mut |_, _| {});
//! out.image.write("cbox.exr".as_ref()).unwrap();
//! ```

pub mod film;
pub mod gbuffer;
pub mod neighbors;
mod params;
pub mod path;
mod render;
pub mod restir_di;
pub mod restir_pt;

pub use render::{Integrator, PassContext, PathIntegrator, RenderOutput, RenderSettings, render};
pub use restir_di::{RestirDiIntegrator, RestirDiSettings};
pub use restir_image::{ErrorMetrics, Image, ImageError, compare};
pub use restir_pt::{RestirPtIntegrator, RestirPtSettings};

use restir_scene::Scene;

/// The integrators this crate provides, by command-line name.
pub const INTEGRATORS: &[&str] = &["path", "restir-di", "restir-pt"];

/// Command-line choices that override the scene's integrator settings.
#[derive(Clone, Debug, Default)]
pub struct IntegratorOptions {
    /// Estimator name; `None` takes the scene's.
    pub name: Option<String>,
    /// Longest path; `None` takes the scene's.
    pub max_depth: Option<i32>,
    /// Estimator parameters as `name = value`, applied after the scene's.
    pub params: Vec<(String, String)>,
}

/// A built integrator and the scene parameters it did not recognise.
#[derive(Debug)]
pub struct MadeIntegrator {
    /// The estimator.
    pub integrator: Box<dyn Integrator>,
    /// Names of scene or command-line parameters the estimator does not use.
    pub unused_params: Vec<String>,
}

/// A settings type's `apply`: takes `name = value` pairs, returns the names it did not use.
type ApplyParams<'a> = dyn FnMut(&[(String, String)]) -> Result<Vec<String>, String> + 'a;

/// Builds the integrator for `scene`: the scene's choice and parameters, overridden by `options`.
pub fn make_integrator(
    scene: &Scene,
    options: &IntegratorOptions,
) -> Result<MadeIntegrator, String> {
    let mut settings = path::PathSettings::from_scene(scene);
    if let Some(d) = options.max_depth {
        if d < -1 {
            return Err(format!(
                "max depth {d} must be -1 (unbounded) or non-negative"
            ));
        }
        settings.max_depth = d;
    }
    let scene_kind = canonical_name(&scene.integrator.kind);
    let name = options.name.as_deref().map_or(scene_kind, canonical_name);
    // The scene's parameters belong to the scene's estimator; their errors name the scene file.
    let scene_params: &[(String, String)] = if name == scene_kind {
        &scene.integrator.params
    } else {
        &[]
    };
    let location = &scene.integrator.location;
    let apply = |apply: &mut ApplyParams| {
        let mut unused = apply(scene_params).map_err(|e| {
            if location.file.as_os_str().is_empty() {
                e
            } else {
                format!("{location}: integrator: {e}")
            }
        })?;
        unused.extend(apply(&options.params)?);
        Ok::<_, String>(unused)
    };
    match name {
        "path" => Ok(MadeIntegrator {
            integrator: Box::new(PathIntegrator { settings }),
            unused_params: scene_params
                .iter()
                .chain(&options.params)
                .map(|(k, _)| k.clone())
                .collect(),
        }),
        "restir-di" => {
            let mut s = RestirDiSettings::new(settings);
            let unused_params = apply(&mut |p| s.apply(p))?;
            Ok(MadeIntegrator {
                integrator: Box::new(RestirDiIntegrator::new(s)),
                unused_params,
            })
        }
        "restir-pt" => {
            let mut s = RestirPtSettings::new(settings);
            let unused_params = apply(&mut |p| s.apply(p))?;
            Ok(MadeIntegrator {
                integrator: Box::new(RestirPtIntegrator::new(s)),
                unused_params,
            })
        }
        other => Err(format!(
            "unknown integrator '{other}' (available: {})",
            INTEGRATORS.join(", ")
        )),
    }
}

/// The command-line name for the names scene files use (`restir` is ReSTIR DI, as in Lajolla;
/// `restir_pt` is ReSTIR PT).
fn canonical_name(name: &str) -> &str {
    match name {
        "restir" | "restir_di" | "restirdi" => "restir-di",
        "restir_pt" | "restirpt" => "restir-pt",
        other => other,
    }
}
