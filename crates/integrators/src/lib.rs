//! Estimators for the `restir` renderer and the code around them: the render driver, pixel
//! filters, image I/O and error metrics.
//!
//! The simplest render is one line with [`Renderer`]:
//!
//! ```no_run
//! use restir_integrators::Renderer;
//! use restir_scene::{LoadOptions, load_scene};
//! let loaded = load_scene("scenes/cornell-box.xml".as_ref(), &LoadOptions::default())?;
//! let out = Renderer::new(&loaded).spp(16).integrator("restir-di").render()?;
//! out.image.write("cbox.exr".as_ref())?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! A named estimator runs as named. The never-worse choice is an estimator of its own, `auto`
//! ([`auto`]): it decides from the scene which of the path tracer, ReSTIR DI and ReSTIR PT
//! renders, and [`RenderOutput::estimator`] says what ran and why:
//!
//! ```no_run
//! # use restir_integrators::Renderer;
//! # use restir_scene::{LoadOptions, load_scene};
//! # let loaded = load_scene("scenes/cornell-box.xml".as_ref(), &LoadOptions::default())?;
//! let out = Renderer::new(&loaded).integrator("auto").render()?;
//! println!("{}", out.estimator); // ran path (chosen by auto: ... one light takes 100% ...)
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Images are `Vec<glam::Vec3>`; this crate re-exports [`glam`] so a caller need not depend on
//! a matching version. A complete program: `examples/library-render` in the repository.
//!
//! The full form, which the command line uses, is [`render`]: give it a built
//! [`Scene`], an [`Integrator`], a [`RenderJob`], a cancel flag and a progress callback, and it
//! returns the averaged image with statistics. A *pass* is one sample per pixel of the integrator's final
//! estimator; images are bit-identical whatever the thread count, because every pixel's random
//! numbers come from `(seed, pixel, pass)`.
//!
//! ```no_run
//! use std::sync::atomic::AtomicBool;
//! use restir_integrators::{make_integrator, render, IntegratorOptions, RenderJob};
//! use restir_scene::{LoadOptions, load_scene};
//! let loaded = load_scene("scenes/cornell-box.xml".as_ref(), &LoadOptions::default()).unwrap();
//! let options = IntegratorOptions { name: Some("restir-di".into()), ..Default::default() };
//! let made = make_integrator(&loaded.scene, &loaded.desc.integrator, &options).unwrap();
//! let job = RenderJob { spp: 16, ..RenderJob::from_desc(&loaded.desc) };
//! let out = render(&loaded.scene, made.integrator.as_ref(), &job, &AtomicBool::new(false), &mut |_, _| {});
//! out.image.write("cbox.exr".as_ref()).unwrap();
//! ```

#![deny(missing_docs)]

pub mod auto;
use restir_reuse::bands;
pub mod film;
pub mod motion;
pub mod params;
mod pass;
pub mod path;
mod render;
mod renderer;
pub mod restir_di;
pub mod restir_pt;
pub mod reuse;
pub mod sequence;
pub mod shadow;
pub mod stages;

pub use auto::AutoIntegrator;
/// The vector types of images and scenes (`Image::pixels` is a `Vec<glam::Vec3>`).
pub use glam;
pub use motion::FrameMotion;
pub use params::{Param, ParamError, ParamSet, ParamSource, ParamValue};
pub use pass::{CROP_ALIGN, Crop, Integrator, PassContext, PixelWindow};
pub use path::PathIntegrator;
pub use render::{
    EstimatorReport, MomentImages, RenderJob, RenderOutput, RenderPart, part_halo, render,
    render_part,
};
pub use renderer::{RenderError, Renderer};
pub use restir_di::{RestirDiIntegrator, RestirDiSettings};
pub use restir_image::{ErrorMetrics, Image, ImageError, compare};
pub use restir_pt::{RestirPtIntegrator, RestirPtSettings};
pub use sequence::FrameSequence;

use params::ParamProblem;
use restir_scene::{IntegratorDesc, SamplerKind, Scene};

/// The integrators this crate provides, by command-line name: three estimators, and `auto`,
/// which chooses one of them from the scene ([`auto`]).
pub const INTEGRATORS: &[&str] = &["path", "restir-di", "restir-pt", "auto"];

/// What `fallback`, a parameter of ReSTIR DI and ReSTIR PT until they ran as named, became.
const FALLBACK_REMOVED: &str = "a named integrator runs as named; the integrator auto chooses the \
     path tracer where ReSTIR does not pay (integrators: path, restir-di, restir-pt, auto)";

/// Command-line choices that override the scene's integrator settings.
#[derive(Clone, Debug, Default)]
pub struct IntegratorOptions {
    /// Estimator name; `None` takes the scene's.
    pub name: Option<String>,
    /// Longest path; `None` takes the scene's.
    pub max_depth: Option<i32>,
    /// Estimator parameters, applied after the scene's.
    pub params: ParamSet,
    /// The path tracer's numbers; `None` takes the scene's. Only the path tracer (and `auto`
    /// when it chooses the path tracer) draws from a sequence: asking ReSTIR DI or PT for one is
    /// an error.
    pub sampler: Option<SamplerKind>,
}

/// A built integrator and the scene parameters it did not recognise.
#[derive(Debug)]
pub struct MadeIntegrator {
    /// The estimator.
    pub integrator: Box<dyn Integrator>,
    /// Scene or command-line parameters the estimator does not use, with where they were given.
    pub unused_params: Vec<Param>,
    /// What was decided from the scene summary that a user should hear about (one line each;
    /// the binary prints them unless `--quiet`).
    pub notes: Vec<String>,
}

/// Why [`make_integrator`] failed.
#[derive(Clone, Debug, PartialEq)]
pub enum IntegratorError {
    /// A maximum depth below -1.
    MaxDepth(i32),
    /// An estimator name this crate does not know.
    Unknown(String),
    /// The scene asks for an estimator of another renderer that this crate does not have
    /// (Mitsuba 3's particle tracer `ptracer`); one of [`INTEGRATORS`] renders the same image.
    Unavailable {
        /// The estimator the scene names.
        name: String,
        /// Where the scene names it.
        at: restir_scene::Location,
    },
    /// A parameter with a bad value.
    Param(ParamError),
    /// A sampler asked of an estimator that draws independent numbers only.
    Sampler {
        /// The sampler asked for.
        sampler: SamplerKind,
        /// The estimator.
        integrator: String,
    },
}

impl std::fmt::Display for IntegratorError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IntegratorError::MaxDepth(d) => {
                write!(f, "max depth {d} must be -1 (unbounded) or non-negative")
            }
            IntegratorError::Unknown(name) => write!(
                f,
                "unknown integrator '{name}' (available: {})",
                INTEGRATORS.join(", ")
            ),
            IntegratorError::Unavailable { name, at } => write!(
                f,
                "{at}: the scene's integrator '{name}' is Mitsuba 3's particle tracer, which this \
                 renderer does not have; every estimator here renders the same image: choose one \
                 with --integrator ({})",
                INTEGRATORS.join(", ")
            ),
            IntegratorError::Param(e) => e.fmt(f),
            IntegratorError::Sampler {
                sampler,
                integrator,
            } => write!(
                f,
                "--sampler {}: {integrator} draws independent random numbers only; the {} \
                 sampler is the path tracer's (--integrator path or auto)",
                sampler.name(),
                sampler.name()
            ),
        }
    }
}

impl std::error::Error for IntegratorError {}

impl From<ParamError> for IntegratorError {
    fn from(e: ParamError) -> Self {
        IntegratorError::Param(e)
    }
}

/// Builds the integrator for `scene`: the choice and parameters of the scene file (`desc`, the
/// [`LoadedScene`](restir_scene::LoadedScene)'s `desc.integrator`), overridden by `options`.
pub fn make_integrator(
    scene: &Scene,
    desc: &IntegratorDesc,
    options: &IntegratorOptions,
) -> Result<MadeIntegrator, IntegratorError> {
    let mut settings = path::PathSettings::from_desc(desc);
    if let Some(d) = options.max_depth {
        if d < -1 {
            return Err(IntegratorError::MaxDepth(d));
        }
        settings.max_depth = d;
    }
    let scene_kind = canonical_name(&desc.kind);
    let name = options.name.as_deref().map_or(scene_kind, canonical_name);
    if let Some(sampler) = options.sampler {
        if sampler != SamplerKind::Independent && !matches!(name, "path" | "auto") {
            return Err(IntegratorError::Sampler {
                sampler,
                integrator: name.to_string(),
            });
        }
        settings.sampler = sampler;
    }
    // The scene's parameters belong to the scene's estimator; their errors name the scene file.
    let mut params = if name == scene_kind {
        ParamSet::from_scene(&desc.params, &desc.location)
    } else {
        ParamSet::new()
    };
    params.extend(&options.params);
    if let Some(p) = params.iter().find(|p| p.key() == "fallback") {
        return Err(p
            .error(ParamProblem::Removed {
                instead: FALLBACK_REMOVED.into(),
            })
            .into());
    }
    let mut notes = Vec::new();
    if settings.sampler != SamplerKind::Independent && !matches!(name, "path" | "auto") {
        notes.push(format!(
            "{name} draws independent random numbers: the scene's {} sampler is the path \
             tracer's",
            settings.sampler.name()
        ));
    }
    let (integrator, unused_params): (Box<dyn Integrator>, _) = match name {
        "path" => {
            let mut settings = settings;
            let unused = params.apply(|key, p| settings.apply_one(key, p))?;
            settings.resolve_nee(&scene.features);
            (Box::new(PathIntegrator { settings }), unused)
        }
        "restir-di" => {
            let mut s = RestirDiSettings::new(settings);
            let unused = s.apply(&params)?;
            s.resolve(
                &scene.features,
                &film::Reconstruction::decide(scene.filter),
                scene.camera.pixel_count(),
            );
            notes.extend(s.reuse.pair_neighbors());
            (Box::new(RestirDiIntegrator::new(s)), unused)
        }
        "restir-pt" => {
            let mut s = RestirPtSettings::new(settings);
            let unused = s.apply(&params)?;
            s.resolve(&scene.features, scene.camera.pixel_count());
            notes.extend(s.reuse.pair_neighbors());
            (Box::new(RestirPtIntegrator::new(s)), unused)
        }
        "auto" => {
            if let Some(p) = params.iter().next() {
                return Err(p.error(ParamProblem::NotForAuto).into());
            }
            let auto = AutoIntegrator::new(scene, settings);
            notes.push(format!(
                "auto: {} renders it: {}",
                auto.choice().name(),
                auto.why()
            ));
            (Box::new(auto), Vec::new())
        }
        "ptracer" => {
            return Err(IntegratorError::Unavailable {
                name: name.to_string(),
                at: desc.location.clone(),
            });
        }
        other => return Err(IntegratorError::Unknown(other.to_string())),
    };
    Ok(MadeIntegrator {
        integrator,
        unused_params,
        notes,
    })
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
