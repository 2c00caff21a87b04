//! What temporal reuse needs to reuse the previous *frame* of a moving sequence: the previous
//! frame's scene (its camera, geometry, lights and materials, where the previous domains'
//! targets are evaluated), the rigid motion of every shape between the two frames (motion
//! vectors), and which light of one frame is which light of the other.
//!
//! A pixel's previous pixel is found by moving its primary hit back with its shape's motion and
//! projecting it with the previous camera ([`FrameMotion::previous_pixel`]); the previous hit
//! there must lie on the same shape, face the same way (the moved shading normal within the
//! similarity angle) and lie at the expected distance from the previous camera (within the
//! relative depth tolerance), or the pixel is disoccluded and has no history. These tests only
//! choose which domain takes part; the estimators stay unbiased whatever they decide
//! (`docs/ANIMATION.md`, "Across frames").

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::{Mat4, Vec3};
use restir_lights::Light;
use restir_scene::animation::{build_at, frame_time};
use restir_scene::{AnimationDesc, Scene, SceneDesc, SceneError};

use crate::render::Integrator;
use crate::reuse::gbuffer::GBuffer;
use crate::reuse::settings::ReuseSettings;

/// How the previous frame relates to the current one.
#[derive(Debug)]
pub struct FrameMotion {
    /// The previous frame's scene.
    pub prev_scene: Arc<Scene>,
    /// Per shape (the two frames' shapes are the same list): the rigid map taking a point of
    /// the shape in the current frame to where it was in the previous frame.
    to_prev: Vec<Mat4>,
    /// Per shape, the inverse map (previous frame to current).
    from_prev: Vec<Mat4>,
    /// Per light of the current frame, the same light in the previous frame (`None`: it did
    /// not emit then).
    light_to_prev: Vec<Option<u32>>,
    /// Per light of the previous frame, the same light now.
    light_from_prev: Vec<Option<u32>>,
    /// Whether only the camera moved: every shape in place, the same lights with the same
    /// radiance and the same light selection (everything a sample names or caches is then the
    /// same in both frames).
    scene_still: bool,
}

/// Which light a light is across frames: an area light by its shape, any other light by its
/// kind and its rank among the lights of that kind (they do not animate).
fn light_keys(lights: &[Light]) -> Vec<(u8, u32)> {
    let mut ranks = [0u32; 5];
    lights
        .iter()
        .map(|l| {
            let kind = match l {
                Light::Area { shape, .. } => return (0, *shape),
                Light::Point { .. } => 1,
                Light::Directional { .. } => 2,
                Light::Constant { .. } => 3,
                Light::Envmap => 4,
            };
            ranks[kind as usize] += 1;
            (kind, ranks[kind as usize] - 1)
        })
        .collect()
}

/// For each light of `from`, the light of `to` with the same key.
fn light_map(from: &[Light], to: &[Light]) -> Vec<Option<u32>> {
    let index: HashMap<(u8, u32), u32> = light_keys(to)
        .into_iter()
        .enumerate()
        .map(|(i, k)| (k, i as u32))
        .collect();
    light_keys(from)
        .iter()
        .map(|k| index.get(k).copied())
        .collect()
}

impl FrameMotion {
    /// The motion from `prev_scene` (the frame at `t_prev` seconds) to `scene` (at `t`), both
    /// built from one description whose animation is `anim`.
    pub fn new(
        prev_scene: Arc<Scene>,
        scene: &Scene,
        anim: &AnimationDesc,
        t_prev: f32,
        t: f32,
    ) -> Self {
        let to_prev = (0..scene.shapes.len())
            .map(|s| anim.shape_motion(s, t, t_prev))
            .collect();
        Self::with_shape_motion(prev_scene, scene, to_prev)
    }

    /// The motion from `prev_scene` to `scene` given each shape's map from its current to its
    /// previous position (`to_prev[shape]`, rigid).
    pub fn with_shape_motion(prev_scene: Arc<Scene>, scene: &Scene, to_prev: Vec<Mat4>) -> Self {
        assert_eq!(
            to_prev.len(),
            scene.shapes.len(),
            "one motion per shape of the current frame"
        );
        let (now, then) = (scene.lights.lights(), prev_scene.lights.lights());
        // The environment's share of light selections is decided per frame from what the
        // camera sees; a light sample's density (cached in ReSTIR PT's paths for their MIS
        // weights) depends on it.
        let scene_still = to_prev.iter().all(|m| *m == Mat4::IDENTITY)
            && now == then
            && scene.lights.environment_share() == prev_scene.lights.environment_share();
        Self {
            scene_still,
            light_to_prev: light_map(now, then),
            light_from_prev: light_map(then, now),
            from_prev: to_prev.iter().map(Mat4::inverse).collect(),
            to_prev,
            prev_scene,
        }
    }

    /// Whether only the camera moved between the two frames (no shape moved, no light changed).
    #[inline]
    pub fn scene_is_still(&self) -> bool {
        self.scene_still
    }

    /// The previous frame's index of light `light` of the current frame.
    #[inline]
    pub fn light_to_prev(&self, light: u32) -> Option<u32> {
        self.light_to_prev.get(light as usize).copied().flatten()
    }

    /// The current frame's index of light `light` of the previous frame.
    #[inline]
    pub fn light_from_prev(&self, light: u32) -> Option<u32> {
        self.light_from_prev.get(light as usize).copied().flatten()
    }

    /// Where point `p` of shape `shape` (current frame) was in the previous frame.
    #[inline]
    pub fn point_to_prev(&self, shape: u32, p: Vec3) -> Vec3 {
        self.to_prev[shape as usize].transform_point3(p)
    }

    /// Direction `d` (unit) fixed to shape `shape`, turned with the shape's rigid motion: from
    /// the current frame to the previous one (`to_prev`), or back. A rotation, so solid angle
    /// is kept (Jacobian 1).
    #[inline]
    pub fn turn_direction(&self, shape: u32, d: Vec3, to_prev: bool) -> Vec3 {
        let m = if to_prev {
            &self.to_prev
        } else {
            &self.from_prev
        };
        m[shape as usize].transform_vector3(d).normalize_or_zero()
    }

    /// The light of the other frame that is light `light` of this one: of the previous frame
    /// when `to_prev` (`light` is the current frame's), else of the current frame.
    #[inline]
    pub fn map_light(&self, light: u32, to_prev: bool) -> Option<u32> {
        if to_prev {
            self.light_to_prev(light)
        } else {
            self.light_from_prev(light)
        }
    }

    /// The pixel of the previous frame's `prev` G-buffer that saw pixel `index`'s primary hit
    /// of `gbuf`, if it saw the same surface: the hit moved back with its shape, projected by
    /// the previous camera, and tested against the hit found there (same shape, shading normals
    /// within `settings.normal_cos`, distance from the previous camera within
    /// `settings.depth_tolerance`). `None` for a disocclusion or a point outside the previous
    /// film.
    pub fn previous_pixel(
        &self,
        gbuf: &GBuffer,
        index: usize,
        prev: &GBuffer,
        settings: &ReuseSettings,
    ) -> Option<usize> {
        let r = gbuf.receiver(index)?;
        let shape = gbuf.shape[index];
        let m = self.to_prev.get(shape as usize)?;
        let p = m.transform_point3(r.p);
        let camera = &self.prev_scene.camera;
        let film = camera.film_position_of(p)?;
        let (x, y) = (film.x.floor(), film.y.floor());
        if x < 0.0 || y < 0.0 || x >= prev.width as f32 || y >= prev.height as f32 {
            return None;
        }
        let q = y as usize * prev.width + x as usize;
        let pr = prev.receiver(q)?;
        if prev.shape[q] != shape {
            return None;
        }
        let n = m.transform_vector3(r.n).normalize_or_zero();
        let depth = (p - camera.origin()).length();
        let similar = pr.n.dot(n) >= settings.normal_cos
            && (pr.depth - depth).abs() <= settings.depth_tolerance * pr.depth.max(depth);
        similar.then_some(q)
    }
}

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
