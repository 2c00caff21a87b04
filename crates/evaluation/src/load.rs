//! A suite scene loaded with the suite's overrides, and the integrators its configurations
//! build for it.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use restir_integrators::reuse::motion::FrameSequence;
use restir_integrators::{Integrator, IntegratorOptions, RenderJob, make_integrator, render};
use restir_scene::{LoadOptions, Scene, SceneDesc, load_scene};

use crate::error::BenchError;
use crate::suite::{IntegratorConfig, SuiteScene};

/// A scene loaded with the suite's overrides.
pub(crate) struct LoadedSuiteScene {
    pub(crate) name: String,
    /// The scene as written (a still entry), or its first frame (a sequence).
    pub(crate) scene: Arc<Scene>,
    pub(crate) file_bytes: Vec<u8>,
    /// The file and the description (with the overrides), for a sequence's frames.
    pub(crate) path: PathBuf,
    pub(crate) desc: SceneDesc,
    /// A sequence's frames `(frame, scene)`; empty for a still entry.
    pub(crate) frames: Vec<(u32, Arc<Scene>)>,
    /// A sequence's frame rate.
    pub(crate) fps: f32,
}

impl LoadedSuiteScene {
    /// What gets a reference: the scene (`None`), or each frame of a sequence.
    pub(crate) fn views(&self) -> Vec<(Option<u32>, Arc<Scene>)> {
        if self.frames.is_empty() {
            vec![(None, self.scene.clone())]
        } else {
            self.frames
                .iter()
                .map(|(f, s)| (Some(*f), s.clone()))
                .collect()
        }
    }

    pub(crate) fn sequence(&self) -> Option<FrameSequence<'_>> {
        FrameSequence::new(&self.desc, &self.path, self.fps)
    }
}

pub(crate) fn load_suite_scene(entry: &SuiteScene, suite_dir: &Path) -> Result<LoadedSuiteScene, BenchError> {
    let path = suite_dir.join(&entry.path);
    let file_bytes = std::fs::read(&path).map_err(BenchError::io(&path, "cannot read scene: "))?;
    let options = LoadOptions {
        width: entry.width,
        height: entry.height,
        ..LoadOptions::default()
    };
    let loaded = load_scene(&path, &options)?;
    let mut out = LoadedSuiteScene {
        name: entry.display_name(),
        scene: Arc::new(loaded.scene),
        file_bytes,
        path,
        fps: 0.0,
        desc: loaded.desc,
        frames: Vec::new(),
    };
    if let Some((first, last)) = entry.frames {
        let Some(anim) = &out.desc.animation else {
            return Err(BenchError::NoAnimation(out.path));
        };
        out.fps = entry.fps.unwrap_or(anim.fps);
        let sequence = out
            .sequence()
            .ok_or(BenchError::NoAnimation(out.path.clone()))?;
        let frames = (first..=last)
            .map(|f| Ok((f, Arc::new(sequence.build(f)?))))
            .collect::<Result<Vec<_>, BenchError>>()?;
        out.scene = frames[0].1.clone();
        out.frames = frames;
    }
    Ok(out)
}

pub(crate) fn options_for(config: &IntegratorConfig, entry: &SuiteScene) -> IntegratorOptions {
    IntegratorOptions {
        name: Some(config.integrator.clone()),
        max_depth: entry.max_depth,
        params: config.params.as_slice().into(),
    }
}

/// Builds a configuration's integrator for a scene; parameters it does not use are an error
/// (a typo would otherwise benchmark the defaults under the wrong label).
pub(crate) fn build_integrator(
    scene: &Scene,
    config: &IntegratorConfig,
    entry: &SuiteScene,
) -> Result<Box<dyn Integrator>, BenchError> {
    let made = make_integrator(scene, &options_for(config, entry)).map_err(|e| {
        BenchError::Integrator {
            label: config.label.clone(),
            message: e.to_string(),
        }
    })?;
    if let Some(p) = made
        .unused_params
        .iter()
        .find(|p| config.params.iter().any(|(k, _)| *k == p.name))
    {
        let p = &p.name;
        return Err(BenchError::Integrator {
            label: config.label.clone(),
            message: format!("{} does not use the parameter '{p}'", config.integrator),
        });
    }
    Ok(made.integrator)
}

pub(crate) fn render_once(
    scene: &Scene,
    integrator: &dyn Integrator,
    job: &RenderJob,
) -> restir_integrators::RenderOutput {
    render(
        scene,
        integrator,
        job,
        &AtomicBool::new(false),
        &mut |_, _| {},
    )
}
