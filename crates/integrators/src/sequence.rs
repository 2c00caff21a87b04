//! A sequence of frames of an animated scene description, rendered one after the other by one
//! estimator: each frame's scene, and the motion since the previous frame handed to the
//! estimator so temporal reuse can carry across frames.

use std::path::Path;
use std::sync::Arc;

use restir_scene::animation::{build_at, frame_time};
use restir_scene::{AnimationDesc, Scene, SceneDesc, SceneError};

use crate::motion::FrameMotion;
use crate::pass::Integrator;

/// Steps one estimator through the frames of an animated scene description: each frame's scene
/// (the description at the frame's time, built by the one builder) and, before every frame
/// after the first, the motion since the previous one told to the estimator
/// ([`Integrator::next_frame`]). `restir render --frames` and `restir bench`'s animation suites
/// both render sequences through it.
#[derive(Debug)]
pub struct FrameSequence<'a> {
    desc: &'a SceneDesc,
    anim: &'a AnimationDesc,
    path: &'a Path,
    fps: f32,
    /// The last frame entered and its time.
    previous: Option<(Arc<Scene>, f32)>,
}

impl<'a> FrameSequence<'a> {
    /// The frames of `desc` (read from `path`, which relative files are resolved against) at
    /// `fps` frames per second; `None` when the description has no animation.
    pub fn new(desc: &'a SceneDesc, path: &'a Path, fps: f32) -> Option<Self> {
        Some(Self {
            anim: desc.animation.as_ref()?,
            desc,
            path,
            fps,
            previous: None,
        })
    }

    /// The time frame `frame` shows, in seconds.
    pub fn time(&self, frame: u32) -> f32 {
        frame_time(frame, self.fps)
    }

    /// The scene of frame `frame`.
    pub fn build(&self, frame: u32) -> Result<Scene, SceneError> {
        build_at(self.desc, self.path, self.time(frame))
    }

    /// Makes `scene` (frame `frame`, from [`Self::build`]) the current frame: `estimator`,
    /// which rendered the previous frame entered (if any), is told how the scene moved since.
    pub fn enter(&mut self, estimator: &dyn Integrator, scene: Arc<Scene>, frame: u32) {
        let time = self.time(frame);
        if let Some((prev, t_prev)) = self.previous.take() {
            estimator.next_frame(Arc::new(FrameMotion::new(
                prev, &scene, self.anim, t_prev, time,
            )));
        }
        self.previous = Some((scene, time));
    }

    /// The seed frame `frame` renders with, from the sequence's `seed`: its own random streams,
    /// so the noise of consecutive frames is independent rather than the same pattern.
    pub fn seed(seed: u64, frame: u32) -> u64 {
        seed ^ u64::from(frame).wrapping_mul(0x9e37_79b9_7f4a_7c15)
    }
}
