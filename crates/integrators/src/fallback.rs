//! The path tracer standing in for a ReSTIR estimator on a scene that does not suit it, written
//! once for ReSTIR DI and ReSTIR PT: the `fallback` choice, and the stand-in with the reason
//! each estimator's rule of the scene gave (`RestirDiSettings::resolve`,
//! `RestirPtSettings::resolve`), which `describe` (hence `--stats`) reports.

use glam::DVec3;
use restir_scene::Scene;

use crate::pass::{Integrator, PassContext};
use crate::path::PathIntegrator;
use crate::path::PathSettings;

/// Whether a ReSTIR estimator may hand a scene that does not suit it to the path tracer
/// (`fallback`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fallback {
    /// When the estimator's rule of the scene says so (ReSTIR DI: one light holds at least
    /// [`crate::restir_di::DOMINANT_LIGHT_SHARE`] of the selections among at most
    /// [`crate::restir_di::FEW_EMITTERS`] emitters; ReSTIR PT: fewer than
    /// [`crate::restir_pt::GLOSSY_VIEW_MIN`] of the camera's paths first reconnect at a glossy
    /// surface and the indirect share of their light is below
    /// [`crate::restir_pt::INDIRECT_VIEW_MIN`]) and no other parameter of the estimator is
    /// given (default).
    Auto,
    /// Never: the estimator whatever the scene.
    Off,
}

impl Fallback {
    /// The names `fallback` takes.
    pub const NAMES: &[(&str, Fallback)] = &[("auto", Fallback::Auto), ("off", Fallback::Off)];
}

/// The path tracer rendering in place of an estimator, and why.
#[derive(Debug)]
pub struct PathFallback {
    path: PathIntegrator,
    why: String,
}

impl PathFallback {
    /// The path tracer with `settings` standing in for the reason `why`, if there is one.
    pub fn new(settings: PathSettings, why: Option<String>) -> Option<Self> {
        why.map(|why| Self {
            path: PathIntegrator { settings },
            why,
        })
    }

    /// What the estimator's `describe` appends: `; estimator: path … (why)`.
    pub fn describe(&self) -> String {
        format!("; estimator: {} ({})", self.path.describe(), self.why)
    }

    /// One pass of the path tracer.
    #[inline]
    pub fn render_pass(&self, scene: &Scene, ctx: &PassContext, accum: &mut [DVec3]) -> u64 {
        self.path.render_pass(scene, ctx, accum)
    }
}
