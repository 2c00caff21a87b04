//! Animated scenes: attaching an [`AnimationDesc`] to a scene description (shape ids resolved,
//! with `file:line` errors), evaluating its tracks at a time (linear or Catmull-Rom
//! interpolation), and the scene at a time: the description with the camera, shape transforms
//! and emitted radiance of that moment, built by the one builder ([`Scene::build`]). Every frame
//! is a whole new [`Scene`] (meshes, BVH, light tables); [`FRAME_REBUILDS`] says so in `--stats`.

use std::path::Path;

use glam::Mat4;

use crate::desc::{
    AnimationDesc, CameraTrack, Interpolation, Keyed, Location, SceneDesc, ShapeTrack, TransformOp,
    transform_matrix,
};
use crate::{Scene, SceneError};

/// What is rebuilt for every frame of an animation (reported by the command line's `--stats`).
pub const FRAME_REBUILDS: &str = "whole scene per frame: meshes transformed, BVH, light tables";

/// The time in seconds frame `frame` shows at `fps` frames per second.
pub fn frame_time(frame: u32, fps: f32) -> f32 {
    (f64::from(frame) / f64::from(fps)) as f32
}

/// Parses a sidecar animation file (the [`AnimationDesc`] alone, in RON).
pub fn parse_animation(text: &str, file: &Path) -> Result<AnimationDesc, SceneError> {
    let mut anim = ron::Options::default()
        .from_str::<AnimationDesc>(text)
        .map_err(|e| {
            SceneError::new(
                Location {
                    file: file.to_path_buf(),
                    line: e.span.start.line as u32,
                },
                e.code.to_string(),
            )
        })?;
    anim.location = Location {
        file: file.to_path_buf(),
        line: 0,
    };
    Ok(anim)
}

/// The byte offset of a RON scene's `animation:` field (the first `animation` followed by a
/// colon outside a `//` comment), or 0.
pub(crate) fn section_start(text: &str) -> usize {
    text.match_indices("animation")
        .find(|&(i, w)| {
            let line_start = text[..i].rfind('\n').map_or(0, |n| n + 1);
            !text[line_start..i].contains("//") && text[i + w.len()..].trim_start().starts_with(':')
        })
        .map_or(0, |(i, _)| i)
}

/// The 1-based line of the `nth` occurrence (0-based) of `needle` in `text` at or after byte
/// `from`, or 0.
fn line_of(text: &str, needle: &str, from: usize, nth: usize) -> u32 {
    let Some(rest) = text.get(from..) else {
        return 0;
    };
    match rest.match_indices(needle).nth(nth) {
        Some((i, _)) => text[..from + i].matches('\n').count() as u32 + 1,
        None => 0,
    }
}

/// Attaches `anim` to `desc`: every track's shape id resolved to its index. `text` is the text
/// the animation was read from (for the lines of errors) and `from` the byte offset where the
/// animation starts in it.
pub fn attach(
    desc: &mut SceneDesc,
    mut anim: AnimationDesc,
    text: &str,
    from: usize,
) -> Result<(), SceneError> {
    let file = anim.location.file.clone();
    let mut seen: Vec<&str> = Vec::new();
    let ids: Vec<&str> = desc.shapes.iter().filter_map(|s| s.id.as_deref()).collect();
    for track in &mut anim.shapes {
        let quoted = format!("\"{}\"", track.id);
        let nth = seen.iter().filter(|s| **s == track.id).count();
        let at = |msg: String| {
            SceneError::new(
                Location {
                    file: file.clone(),
                    line: line_of(text, &quoted, from, nth),
                },
                msg,
            )
        };
        if nth > 0 {
            return Err(at(format!(
                "shape '{}' is animated twice: give one track per shape",
                track.id
            )));
        }
        let mut matching = desc
            .shapes
            .iter()
            .enumerate()
            .filter(|(_, s)| s.id.as_deref() == Some(&track.id));
        let Some((index, shape)) = matching.next() else {
            let choices = if ids.is_empty() {
                "the scene's shapes have no ids".to_string()
            } else {
                format!("shape ids: {}", ids.join(", "))
            };
            return Err(at(format!("unknown shape id '{}' ({choices})", track.id)));
        };
        if let Some((other, _)) = matching.next() {
            return Err(at(format!(
                "shape id '{}' names shapes {index} and {other}: ids must be unique",
                track.id
            )));
        }
        if track.motion.is_none() && track.emission.is_none() {
            return Err(at(format!(
                "shape '{}' has neither motion nor emission keys",
                track.id
            )));
        }
        if track.emission.is_some() && shape.emission.is_none() {
            return Err(at(format!(
                "shape '{}' has emission keys but is not an emitter",
                track.id
            )));
        }
        track.shape = index;
        seen.push(track.id.as_str());
    }
    drop(seen);
    desc.animation = Some(anim);
    Ok(())
}

/// Reads the animation file `file` and attaches it to `desc` (an XML scene's sidecar, or the
/// command line's `--animation FILE`). An error when `desc` already has an animation.
pub fn load_animation(desc: &mut SceneDesc, file: &Path) -> Result<(), SceneError> {
    let whole = |msg: String| {
        SceneError::new(
            Location {
                file: file.to_path_buf(),
                line: 0,
            },
            msg,
        )
    };
    if let Some(a) = &desc.animation {
        return Err(whole(format!(
            "the scene already has an animation (from {}): give one animation",
            a.location.file.display()
        )));
    }
    let bytes = restir_image::input::read_regular(file)
        .map_err(|e| whole(format!("cannot read animation: {e}")))?;
    let text = String::from_utf8(bytes)
        .map_err(|_| whole("cannot read animation: stream did not contain valid UTF-8".into()))?;
    let anim = parse_animation(&text, file)?;
    attach(desc, anim, &text, 0)
}

/// The value of a track of `N` numbers at time `t`: `keys` are `(time, values)` in increasing
/// time; values hold before the first and after the last key.
pub fn interpolate<const N: usize>(
    keys: &[(f32, [f32; N])],
    mode: Interpolation,
    t: f32,
) -> [f32; N] {
    let n = keys.len();
    if n == 1 || t <= keys[0].0 {
        return keys[0].1;
    }
    if t >= keys[n - 1].0 {
        return keys[n - 1].1;
    }
    // keys[i].0 <= t < keys[i + 1].0
    let i = keys.partition_point(|k| k.0 <= t) - 1;
    let (t0, p0) = keys[i];
    let (t1, p1) = keys[i + 1];
    let h = t1 - t0;
    let u = (t - t0) / h;
    let mut out = [0.0; N];
    match mode {
        Interpolation::Linear => {
            for c in 0..N {
                out[c] = p0[c] + (p1[c] - p0[c]) * u;
            }
        }
        Interpolation::CatmullRom => {
            // Tangents dp/dt from the neighbours (one-sided at the ends), scaled to the segment.
            let slope = |j: usize, c: usize| {
                let (a, b) = (j.saturating_sub(1), (j + 1).min(n - 1));
                (keys[b].1[c] - keys[a].1[c]) / (keys[b].0 - keys[a].0)
            };
            let (u2, u3) = (u * u, u * u * u);
            let h00 = 2.0 * u3 - 3.0 * u2 + 1.0;
            let h10 = u3 - 2.0 * u2 + u;
            let h01 = -2.0 * u3 + 3.0 * u2;
            let h11 = u3 - u2;
            for c in 0..N {
                out[c] =
                    h00 * p0[c] + h10 * h * slope(i, c) + h01 * p1[c] + h11 * h * slope(i + 1, c);
            }
        }
    }
    out
}

fn sampled<K: Keyed, const N: usize>(
    keys: &[K],
    values: impl Fn(&K) -> [f32; N],
    mode: Interpolation,
    t: f32,
) -> [f32; N] {
    let k: Vec<(f32, [f32; N])> = keys.iter().map(|k| (k.time(), values(k))).collect();
    interpolate(&k, mode, t)
}

impl CameraTrack {
    /// The camera's `(origin, target, up, fov)` at `t`; keys without a field of view take
    /// `scene_fov`.
    pub fn at(&self, t: f32, scene_fov: f32) -> ([f32; 3], [f32; 3], [f32; 3], f32) {
        let v = sampled(
            self.keys.keys(),
            |k| {
                let (p, q, u) = (k.position, k.target, k.up);
                [
                    p[0],
                    p[1],
                    p[2],
                    q[0],
                    q[1],
                    q[2],
                    u[0],
                    u[1],
                    u[2],
                    k.fov.unwrap_or(scene_fov),
                ]
            },
            self.interpolation,
            t,
        );
        (
            [v[0], v[1], v[2]],
            [v[3], v[4], v[5]],
            [v[6], v[7], v[8]],
            v[9],
        )
    }
}

impl ShapeTrack {
    /// The rigid motion's transform steps at `t` (applied after the shape's `to_world`), none
    /// without motion keys.
    pub fn motion_ops(&self, t: f32) -> Vec<TransformOp> {
        let Some(keys) = &self.motion else {
            return Vec::new();
        };
        let v = sampled(
            keys.keys(),
            |k| {
                let (a, r) = (k.translate, k.rotate);
                [a[0], a[1], a[2], r[0], r[1], r[2]]
            },
            self.interpolation,
            t,
        );
        let p = self.pivot;
        let rot = |axis: [f32; 3], angle: f32| TransformOp::Rotate { axis, angle };
        vec![
            TransformOp::Translate([-p[0], -p[1], -p[2]]),
            rot([1.0, 0.0, 0.0], v[3]),
            rot([0.0, 1.0, 0.0], v[4]),
            rot([0.0, 0.0, 1.0], v[5]),
            TransformOp::Translate([p[0] + v[0], p[1] + v[1], p[2] + v[2]]),
        ]
    }

    /// The rigid motion at `t` as a matrix (identity without motion keys).
    pub fn motion_matrix(&self, t: f32) -> Mat4 {
        transform_matrix(&self.motion_ops(t)).unwrap_or(Mat4::IDENTITY)
    }

    /// The emitted radiance at `t`, if the track has emission keys (clamped at zero: a spline
    /// may undershoot).
    pub fn emission_at(&self, t: f32) -> Option<[f32; 3]> {
        let keys = self.emission.as_ref()?;
        let v = sampled(keys.keys(), |k| k.radiance, self.interpolation, t);
        // NaN stays NaN (the builder refuses it with the shape's line; `max` would make it 0).
        Some(v.map(|x| if x < 0.0 { 0.0 } else { x }))
    }
}

impl AnimationDesc {
    /// The transform taking a point on shape `shape` at time `from` to where it is at time `to`
    /// (identity for a shape that does not move): the motion vector's world-space map.
    pub fn shape_motion(&self, shape: usize, from: f32, to: f32) -> Mat4 {
        match self
            .shapes
            .iter()
            .find(|s| s.shape == shape && s.motion.is_some())
        {
            Some(s) => s.motion_matrix(to) * s.motion_matrix(from).inverse(),
            None => Mat4::IDENTITY,
        }
    }

    /// Whether shape `shape` moves.
    pub fn shape_moves(&self, shape: usize) -> bool {
        self.shapes
            .iter()
            .any(|s| s.shape == shape && s.motion.is_some())
    }
}

impl SceneDesc {
    /// The description at time `t` seconds: the camera, moving shapes and changing emitters of
    /// that moment, without the animation. A description without one is returned unchanged.
    pub fn at_time(&self, t: f32) -> SceneDesc {
        let mut d = self.clone();
        let Some(anim) = d.animation.take() else {
            return d;
        };
        if let Some(cam) = &anim.camera {
            let (origin, target, up, fov) = cam.at(t, d.camera.fov);
            d.camera.to_world = vec![TransformOp::LookAt { origin, target, up }];
            d.camera.fov = fov;
        }
        for track in &anim.shapes {
            let shape = &mut d.shapes[track.shape];
            shape.to_world.extend(track.motion_ops(t));
            if let Some(e) = track.emission_at(t) {
                shape.emission = Some(e);
            }
        }
        d
    }
}

/// The scene at time `t`: [`SceneDesc::at_time`] built by [`Scene::build`] (relative paths
/// resolved beside `scene_path`). Errors name the scene file and the time.
pub fn build_at(desc: &SceneDesc, scene_path: &Path, t: f32) -> Result<Scene, SceneError> {
    let base = scene_path.parent().unwrap_or(Path::new(""));
    Scene::build(&desc.at_time(t), base, scene_path).map_err(|e| SceneError {
        message: format!("at time {t} s: {}", e.message),
        ..e
    })
}
