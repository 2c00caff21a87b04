//! [`Renderer`]: the library's one-line render, `Renderer::new(&loaded).spp(16).render()`.
//!
//! A builder over the full driver ([`crate::render`], which the command line uses with its
//! cancel flag and progress display): it picks the scene's integrator (or a named one), applies
//! parameters given by the caller, and renders in the current rayon pool without cancellation
//! or progress reports. Errors are typed ([`RenderError`]).

use std::sync::atomic::AtomicBool;
use std::time::Duration;

use restir_scene::{IntegratorDesc, LoadedScene, Scene};

use crate::params::{Param, ParamSource, ParamValue};
use crate::{IntegratorError, IntegratorOptions, RenderJob, RenderOutput, make_integrator};

/// Why [`Renderer::render`] could not start.
#[derive(Clone, Debug, PartialEq)]
pub enum RenderError {
    /// The integrator could not be built (unknown name, bad parameter value, bad depth).
    Integrator(IntegratorError),
    /// A parameter given with [`Renderer::param`] that the chosen integrator does not use.
    UnusedParam {
        /// The parameter's name as given.
        name: String,
        /// The integrator that does not use it.
        integrator: String,
    },
}

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RenderError::Integrator(e) => e.fmt(f),
            RenderError::UnusedParam { name, integrator } => {
                write!(
                    f,
                    "parameter '{name}' is not used by integrator {integrator}"
                )
            }
        }
    }
}

impl std::error::Error for RenderError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            RenderError::Integrator(e) => Some(e),
            RenderError::UnusedParam { .. } => None,
        }
    }
}

impl From<IntegratorError> for RenderError {
    fn from(e: IntegratorError) -> Self {
        RenderError::Integrator(e)
    }
}

/// A render of one scene, configured by chained calls and run by [`Renderer::render`].
///
/// ```no_run
/// use restir_integrators::Renderer;
/// use restir_scene::{LoadOptions, load_scene};
///
/// let loaded = load_scene("scenes/cornell-box.xml".as_ref(), &LoadOptions::default())?;
/// let out = Renderer::new(&loaded).spp(16).render()?;
/// let (w, h) = (out.image.width, out.image.height);
/// let pixels: &[restir_integrators::glam::Vec3] = &out.image.pixels;
/// assert_eq!(pixels.len(), (w * h) as usize);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// Defaults: what the scene file asks for: its integrator and parameters, its sample count
/// ([`RenderJob::from_desc`]); seed 0, no time limit. [`Renderer::of`] renders a scene built
/// by the caller.
#[derive(Clone, Debug)]
pub struct Renderer<'a> {
    scene: &'a Scene,
    integrator: &'a IntegratorDesc,
    options: IntegratorOptions,
    job: RenderJob,
}

impl<'a> Renderer<'a> {
    /// A render of a loaded scene as its file asks: its integrator, its sample count.
    pub fn new(loaded: &'a LoadedScene) -> Self {
        Self {
            job: RenderJob::from_desc(&loaded.desc),
            ..Self::of(&loaded.scene, &loaded.desc.integrator)
        }
    }

    /// A render of `scene` (built with [`Scene::build`]) with `integrator`, the integrator
    /// of the description it was built from; one pass, seed 0 ([`RenderJob::default`]).
    pub fn of(scene: &'a Scene, integrator: &'a IntegratorDesc) -> Self {
        Self {
            scene,
            integrator,
            options: IntegratorOptions::default(),
            job: RenderJob::default(),
        }
    }

    /// Passes to render (one sample per pixel each; at least one is rendered).
    #[must_use]
    pub fn spp(mut self, spp: u32) -> Self {
        self.job.spp = spp;
        self
    }

    /// The seed of every random stream (the same seed gives the same image).
    #[must_use]
    pub fn seed(mut self, seed: u64) -> Self {
        self.job.seed = seed;
        self
    }

    /// Stops starting new passes once `limit` has passed.
    #[must_use]
    pub fn time_limit(mut self, limit: Duration) -> Self {
        self.job.time_limit = Some(limit);
        self
    }

    /// The whole job at once (pass count, time limit, seed; its `output` is not written).
    #[must_use]
    pub fn job(mut self, job: RenderJob) -> Self {
        self.job = job;
        self
    }

    /// The integrator by command-line name (one of [`crate::INTEGRATORS`]); the scene's own
    /// parameters then apply only if it names the same one. A named estimator runs as named;
    /// `"auto"` chooses one from the scene ([`crate::auto`]), and [`RenderOutput::estimator`]
    /// says which ran and why.
    #[must_use]
    pub fn integrator(mut self, name: &str) -> Self {
        self.options.name = Some(name.to_string());
        self
    }

    /// The longest path (-1: unbounded).
    #[must_use]
    pub fn max_depth(mut self, depth: i32) -> Self {
        self.options.max_depth = Some(depth);
        self
    }

    /// An estimator parameter by its command-line name (`"spatial-rounds"`, `"mis"`, ...),
    /// applied after the scene's. A parameter the integrator does not use is an error.
    #[must_use]
    pub fn param(mut self, name: &str, value: impl Into<ParamValue>) -> Self {
        self.options
            .params
            .push(Param::new(name, value, ParamSource::Caller));
        self
    }

    /// Renders: builds the integrator, then every pass. The image is in
    /// [`RenderOutput::image`] (linear RGB, row-major `Vec<glam::Vec3>`); what rendered it, and
    /// why, in [`RenderOutput::estimator`].
    pub fn render(&self) -> Result<RenderOutput, RenderError> {
        let made = make_integrator(self.scene, self.integrator, &self.options)?;
        if let Some(p) = made
            .unused_params
            .iter()
            .find(|p| p.source == ParamSource::Caller)
        {
            return Err(RenderError::UnusedParam {
                name: p.name.clone(),
                integrator: made.integrator.name().to_string(),
            });
        }
        let never = AtomicBool::new(false);
        Ok(crate::render(
            self.scene,
            made.integrator.as_ref(),
            &self.job,
            &never,
            &mut |_, _| {},
        ))
    }
}
