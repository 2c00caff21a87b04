//! What temporal reuse needs to reuse the previous *frame* of a moving sequence: the previous
//! frame's scene (its camera, geometry, lights and materials, where the previous domains'
//! targets are evaluated), the rigid motion of every shape between the two frames (motion
//! vectors), and which light of one frame is which light of the other.
//!
//! The reuse passes find a pixel's previous pixel with it
//! (`reuse::gbuffer::GBuffer::previous_pixel`); [`crate::sequence::FrameSequence`] makes one
//! per frame of a sequence.

use std::collections::HashMap;
use std::sync::Arc;

use glam::{Mat4, Vec3};
use restir_lights::Light;
use restir_scene::{AnimationDesc, Scene};

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
    let mut ranks = [0u32; 7];
    lights
        .iter()
        .map(|l| {
            let kind = match l {
                Light::Area { shape, .. } => return (0, *shape),
                Light::Point { .. } => 1,
                Light::Directional { .. } => 2,
                Light::Constant { .. } => 3,
                Light::Envmap => 4,
                Light::Spot(_) => 5,
                Light::Projector(_) => 6,
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

    /// The rigid map taking a point of shape `shape` in the current frame to where it was in
    /// the previous frame (`None` for an index past the shapes).
    #[inline]
    pub fn shape_to_prev(&self, shape: u32) -> Option<&Mat4> {
        self.to_prev.get(shape as usize)
    }
}
