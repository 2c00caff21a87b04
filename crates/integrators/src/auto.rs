//! The `auto` estimator: the never-worse choice among the path tracer, ReSTIR DI and ReSTIR PT,
//! made once when the integrator is made, from the scene, by the rules measured at equal CPU
//! time. Every named estimator runs as named; only `auto` chooses, and it says what it chose
//! and why ([`AutoIntegrator::why`], hence `RenderOutput::estimator`, `--stats` and the summary
//! line).
//!
//! The rules, in order ([`choose`]):
//!
//! 1. **No lights, or no reflected light** (`max_depth` below 2: only emitters seen by the
//!    camera): the path tracer (nothing for reservoirs to choose among).
//! 2. **ReSTIR PT** when paths longer than two segments are asked for and the view pilot
//!    ([`crate::restir_pt::view_pilot`]) finds at least [`GLOSSY_VIEW_MIN`] of the camera's
//!    paths first reconnecting at a glossy surface, or a mean indirect share of their light of
//!    at least [`INDIRECT_VIEW_MIN`] (`docs/studies/2026-12-02-restir-pt-defaults.md`: 1.8–2.5×
//!    the path tracer where it chose ReSTIR PT, 0.4–0.8× where it did not).
//! 3. **The path tracer** when the emitter table holds at most [`FEW_EMITTERS`] entries and
//!    one light takes at least [`DOMINANT_LIGHT_SHARE`] of the light selections: the reservoirs
//!    have little to choose from and their cost is not repaid
//!    (`docs/studies/2026-12-02-never-worse.md`: ReSTIR DI 0.57–0.60× the path tracer there).
//! 4. **ReSTIR PT** when no light dominates and paths longer than two segments are asked for:
//!    ReSTIR DI estimates the indirect light with one path-traced continuation per pass, at the
//!    cost of its reservoirs' pass. On the DI training family rendered with `max_depth` −1
//!    (640×360, 1 thread; the pilot's indirect shares 6–44 %), ReSTIR PT was 1.97–6.8× the
//!    path tracer and ReSTIR DI 0.85–3.9× (`docs/RESTIR_PT.md`, "Never worse").
//! 5. **ReSTIR DI** otherwise: direct light only (`max_depth` 2) from many lights, or no light
//!    dominating.
//!
//! Rule 2 comes before rule 3 because the glossy rooms where ReSTIR PT gains 2–5× are lit by one
//! area light.
//!
//! `auto` runs the chosen estimator at its defaults and takes no estimator parameters (name the
//! estimator to configure it); the depth settings (`max_depth`, `rr_depth`, `hide_emitters`)
//! apply to whichever it chooses.

use std::sync::Arc;

use glam::DVec3;
use restir_scene::{Scene, SceneFeatures};

use crate::motion::FrameMotion;
use crate::pass::{Integrator, PassContext};
use crate::path::{PathIntegrator, PathSettings};
use crate::restir_di::{RestirDiIntegrator, RestirDiSettings};
use crate::restir_pt::{
    GLOSSY_VIEW_MIN, INDIRECT_VIEW_MIN, RestirPtIntegrator, RestirPtSettings, view_pilot,
};

/// The share of light selections one light must hold for `auto` to choose the path tracer over
/// ReSTIR DI, when the emitter table also holds at most [`FEW_EMITTERS`] entries
/// (`docs/studies/2026-12-02-never-worse.md`). A dominant mesh light of thousands of small
/// triangles is a many-light problem and gets ReSTIR DI.
pub const DOMINANT_LIGHT_SHARE: f32 = 0.5;

/// At most this many emitter-table entries for the dominant-light rule
/// ([`DOMINANT_LIGHT_SHARE`]).
pub const FEW_EMITTERS: usize = 64;

/// The estimators `auto` chooses among.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Choice {
    /// The path tracer.
    Path,
    /// ReSTIR DI at its defaults.
    RestirDi,
    /// ReSTIR PT at its defaults.
    RestirPt,
}

impl Choice {
    /// The estimator's command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Choice::Path => "path",
            Choice::RestirDi => "restir-di",
            Choice::RestirPt => "restir-pt",
        }
    }
}

/// Why ReSTIR DI's reservoirs are not repaid on a scene (the dominant-light rule), or `None`.
/// No commas in the reason: the bench CSV's settings column is split on them.
pub fn dominant_light(features: &SceneFeatures) -> Option<String> {
    let share = features.largest_light_share;
    (features.emitter_count <= FEW_EMITTERS && share >= DOMINANT_LIGHT_SHARE).then(|| {
        format!(
            "one light takes {:.0}% of the light selections (>= {:.0}% with {} emitters <= {})",
            100.0 * share,
            100.0 * DOMINANT_LIGHT_SHARE,
            features.emitter_count,
            FEW_EMITTERS
        )
    })
}

/// The estimator `auto` runs on `scene` with paths of `path` (module docs), and why in one line
/// (no commas). Runs the view pilot (at most 1024 × 57 rays) when paths of more than two
/// segments are asked for and the scene has lights.
pub fn choose(scene: &Scene, path: &PathSettings) -> (Choice, String) {
    let f = &scene.features;
    if f.light_count == 0 {
        return (Choice::Path, "the scene has no lights".into());
    }
    if path.max_segments() < 2 {
        return (
            Choice::Path,
            format!(
                "max_depth {}: no reflected light (emitters seen by the camera only)",
                path.max_depth
            ),
        );
    }
    let pilot = (path.max_segments() > 2).then(|| view_pilot(scene, path.hide_emitters));
    let view = pilot.map(|v| {
        format!(
            "of {} camera paths {:.1}% first reconnect at a glossy surface (ReSTIR PT from {:.0}%) \
             and {:.0}% of their light is indirect (from {:.0}%)",
            v.reached,
            100.0 * v.glossy_share(),
            100.0 * GLOSSY_VIEW_MIN,
            100.0 * v.indirect_share(),
            100.0 * INDIRECT_VIEW_MIN
        )
    });
    if let (Some(v), Some(view)) = (pilot, &view)
        && v.keeps_restir_pt()
    {
        return (Choice::RestirPt, view.clone());
    }
    let view = view.map_or("direct light only (max_depth 2)".to_string(), |v| v);
    if let Some(why) = dominant_light(f) {
        return (Choice::Path, format!("{view}; {why}"));
    }
    let many = format!(
        "no light dominates the selections among {} emitters (the largest takes {:.0}%; the path \
         tracer from {:.0}% with at most {} emitters)",
        f.emitter_count,
        100.0 * f.largest_light_share,
        100.0 * DOMINANT_LIGHT_SHARE,
        FEW_EMITTERS
    );
    if path.max_segments() > 2 {
        // Rule 4: ReSTIR DI would estimate the indirect light with one path-traced
        // continuation per pass, at the cost of its reservoirs' pass.
        return (
            Choice::RestirPt,
            format!("{view}; {many}; indirect light asked for (max_depth above 2)"),
        );
    }
    (Choice::RestirDi, format!("{view}; {many}"))
}

/// The `auto` estimator: the estimator [`choose`] picked, at its defaults, and why.
#[derive(Debug)]
pub struct AutoIntegrator {
    chosen: Box<dyn Integrator>,
    choice: Choice,
    why: String,
}

impl AutoIntegrator {
    /// Chooses for `scene` with paths of `path` and makes the chosen estimator.
    pub fn new(scene: &Scene, mut path: PathSettings) -> Self {
        path.resolve_nee(&scene.features);
        let (choice, why) = choose(scene, &path);
        let chosen: Box<dyn Integrator> = match choice {
            Choice::Path => Box::new(PathIntegrator { settings: path }),
            Choice::RestirDi => {
                let mut s = RestirDiSettings::new(path);
                s.resolve(
                    &scene.features,
                    &crate::film::Reconstruction::decide(scene.filter),
                    scene.camera.pixel_count(),
                );
                Box::new(RestirDiIntegrator::new(s))
            }
            Choice::RestirPt => {
                let mut s = RestirPtSettings::new(path);
                s.resolve(&scene.features, scene.camera.pixel_count());
                Box::new(RestirPtIntegrator::new(s))
            }
        };
        Self {
            chosen,
            choice,
            why,
        }
    }

    /// The estimator chosen.
    pub fn choice(&self) -> Choice {
        self.choice
    }

    /// Why, in one line: what the rules measured of the scene.
    pub fn why(&self) -> &str {
        &self.why
    }
}

/// Everything is the chosen estimator's; [`Integrator::name`] is its name, and
/// [`Integrator::auto_choice`] says that `auto` chose it and why.
impl Integrator for AutoIntegrator {
    fn name(&self) -> &'static str {
        self.chosen.name()
    }

    fn render_pass(&self, scene: &Scene, ctx: &PassContext, accum: &mut [DVec3]) -> u64 {
        self.chosen.render_pass(scene, ctx, accum)
    }

    /// The chosen estimator's settings ([`Integrator::auto_choice`] says that `auto` chose it).
    fn describe(&self) -> String {
        self.chosen.describe()
    }

    fn buffer_bytes(&self, width: u32, height: u32, threads: usize) -> u64 {
        self.chosen.buffer_bytes(width, height, threads)
    }

    fn halo(&self) -> u32 {
        self.chosen.halo()
    }

    fn stage_seconds(&self) -> Vec<(&'static str, f64)> {
        self.chosen.stage_seconds()
    }

    fn learned(&self) -> Option<String> {
        self.chosen.learned()
    }

    fn silhouettes(&self) -> Option<String> {
        self.chosen.silhouettes()
    }

    fn light_cuts(&self) -> Option<String> {
        self.chosen.light_cuts()
    }

    fn lanes(&self, scene: &Scene) -> Option<String> {
        self.chosen.lanes(scene)
    }

    fn next_frame(&self, motion: Arc<FrameMotion>) {
        self.chosen.next_frame(motion);
    }

    fn auto_choice(&self) -> Option<&str> {
        Some(&self.why)
    }
}
