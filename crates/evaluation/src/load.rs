//! A suite scene loaded with the suite's overrides, and the integrators its configurations
//! build for it.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use restir_image::input::read_regular;
use restir_integrators::FrameSequence;
use restir_integrators::{Integrator, IntegratorOptions, RenderJob, make_integrator, render};
use restir_scene::{LoadOptions, Scene, SceneDesc, load_scene};

use crate::error::BenchError;
use crate::suite::{IntegratorConfig, SuiteScene};

/// A scene loaded with the suite's overrides. A sequence keeps its first frame's scene; every
/// other frame is built when it is rendered and dropped after ([`LoadedSuiteScene::frame`]), so
/// memory does not grow with the number of frames.
pub(crate) struct LoadedSuiteScene {
    pub(crate) name: String,
    /// The scene as written (a still entry), or its first frame (a sequence).
    pub(crate) scene: Arc<Scene>,
    pub(crate) file_bytes: Vec<u8>,
    /// The file and the description (with the overrides), for a sequence's frames.
    pub(crate) path: PathBuf,
    pub(crate) desc: SceneDesc,
    /// A sequence's frames `(first, last)`; `None` for a still entry.
    pub(crate) frames: Option<(u32, u32)>,
    /// A sequence's frame rate.
    pub(crate) fps: f32,
}

impl LoadedSuiteScene {
    /// What gets a reference and a record: the scene (`[None]`), or each frame of a sequence.
    pub(crate) fn views(&self) -> Vec<Option<u32>> {
        match self.frames {
            None => vec![None],
            Some((first, last)) => (first..=last).map(Some).collect(),
        }
    }

    /// Frames of a sequence (1 for a still scene).
    pub(crate) fn view_count(&self) -> usize {
        self.frames
            .map_or(1, |(first, last)| (last - first) as usize + 1)
    }

    /// The scene of a view: the still scene, the kept first frame, or another frame built now.
    pub(crate) fn frame(&self, view: Option<u32>) -> Result<Arc<Scene>, BenchError> {
        match (view, self.frames) {
            (Some(f), Some((first, _))) if f != first => {
                let sequence = self
                    .sequence()
                    .ok_or(BenchError::NoAnimation(self.path.clone()))?;
                Ok(Arc::new(sequence.build(f)?))
            }
            _ => Ok(self.scene.clone()),
        }
    }

    pub(crate) fn sequence(&self) -> Option<FrameSequence<'_>> {
        FrameSequence::new(&self.desc, &self.path, self.fps)
    }
}

/// Loads a suite scene, its meshes and images checked against `max_memory` bytes
/// (`--max-memory`, as `restir render` checks them) before each is built. Every frame of a
/// sequence is built once here, so that a bad frame fails before any rendering, and dropped
/// before the next is built.
pub(crate) fn load_suite_scene(
    entry: &SuiteScene,
    suite_dir: &Path,
    max_memory: Option<u64>,
) -> Result<LoadedSuiteScene, BenchError> {
    let path = suite_dir.join(&entry.path);
    let file_bytes = read_regular(&path).map_err(BenchError::io(&path, "cannot read scene: "))?;
    let options = LoadOptions {
        width: entry.width,
        height: entry.height,
        max_memory,
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
        frames: None,
    };
    if let Some((first, last)) = entry.frames {
        let Some(anim) = &out.desc.animation else {
            return Err(BenchError::NoAnimation(out.path));
        };
        out.fps = entry.fps.unwrap_or(anim.fps);
        let first_scene = {
            let sequence = out
                .sequence()
                .ok_or(BenchError::NoAnimation(out.path.clone()))?;
            for f in first + 1..=last {
                drop(sequence.build(f)?);
            }
            Arc::new(sequence.build(first)?)
        };
        out.scene = first_scene;
        out.frames = Some((first, last));
    }
    Ok(out)
}

pub(crate) fn options_for(config: &IntegratorConfig, entry: &SuiteScene) -> IntegratorOptions {
    IntegratorOptions {
        name: Some(config.integrator.clone()),
        max_depth: entry.max_depth,
        params: config.params.as_slice().into(),
        sampler: None,
    }
}

/// Builds a configuration's integrator for a loaded scene (its file's integrator settings under
/// the configuration's); parameters it does not use are an error (a typo would otherwise
/// benchmark the defaults under the wrong label).
pub(crate) fn build_integrator(
    loaded: &LoadedSuiteScene,
    config: &IntegratorConfig,
    entry: &SuiteScene,
) -> Result<Box<dyn Integrator>, BenchError> {
    let options = options_for(config, entry);
    let made = make_integrator(&loaded.scene, &loaded.desc.integrator, &options).map_err(|e| {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn still_life(frames: Option<(u32, u32)>) -> SuiteScene {
        SuiteScene {
            path: "glossy-still-life.xml".into(),
            name: None,
            width: Some(16),
            height: Some(12),
            max_depth: Some(3),
            reference: None,
            reference_spp: None,
            crop: None,
            integrators: None,
            frames,
            fps: None,
        }
    }

    fn scenes_dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
    }

    /// A sequence keeps only its first frame: every other frame is built on request and held by
    /// no one else (memory independent of the frame count), the same scene the sequence builds.
    #[test]
    fn a_sequence_builds_its_frames_one_at_a_time() {
        let loaded = load_suite_scene(&still_life(Some((0, 5))), &scenes_dir(), None).unwrap();
        assert_eq!(loaded.view_count(), 6);
        assert_eq!(loaded.views().first(), Some(&Some(0)));
        let first = loaded.frame(Some(0)).unwrap();
        assert!(Arc::ptr_eq(&first, &loaded.scene));
        let sequence = loaded.sequence().unwrap();
        for f in 1..=5 {
            let scene = loaded.frame(Some(f)).unwrap();
            assert_eq!(Arc::strong_count(&scene), 1, "frame {f} is kept elsewhere");
            let again = sequence.build(f).unwrap();
            assert_eq!(
                format!("{:?}", scene.camera),
                format!("{:?}", again.camera),
                "frame {f}"
            );
        }
        // Negative control: the first frame is the kept one.
        assert!(Arc::strong_count(&first) > 1);
    }

    #[test]
    fn a_still_scene_has_one_view() {
        let loaded = load_suite_scene(&still_life(None), &scenes_dir(), None).unwrap();
        assert_eq!(loaded.views(), vec![None]);
        assert_eq!(loaded.view_count(), 1);
    }
}
