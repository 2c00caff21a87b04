//! Animation description: keyframed tracks for the camera (position, target, up, field of view),
//! rigid motion of shapes (translation and rotation about a pivot) and the radiance of emissive
//! shapes, each with linear or Catmull-Rom interpolation. It is the optional `animation` section
//! of a RON scene, or a sidecar RON file beside a Mitsuba XML scene (`<name>.anim.ron`) that names
//! shapes by their `id`. Key lists are checked while deserialising (non-empty, times finite and
//! strictly increasing, values finite; each checked as it is read), so a RON error names the line of the offending key;
//! evaluation at a time is in [`crate::animation`].

use serde::de::{Error, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};

use super::{Location, V3, limits};

/// The default frame rate (frames per second).
pub const DEFAULT_FPS: f32 = 24.0;

fn default_fps() -> f32 {
    DEFAULT_FPS
}

fn default_up() -> V3 {
    [0.0, 1.0, 0.0]
}

fn positive_fps<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let v = f32::deserialize(d)?;
    if v.is_finite() && v > 0.0 && v <= 1e6 {
        Ok(v)
    } else {
        Err(D::Error::custom(format!(
            "fps {v} must be a positive number of frames per second (at most 1e6)"
        )))
    }
}

/// A scene's animation: what moves and how, over time in seconds (frame `n` is at `n / fps`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnimationDesc {
    /// Frames per second: frame `n` shows time `n / fps` (default 24; `--fps` overrides it).
    #[serde(default = "default_fps", deserialize_with = "positive_fps")]
    pub fps: f32,
    /// The camera's keys, if it moves.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<CameraTrack>,
    /// Moving or changing shapes, by `id`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shapes: Vec<ShapeTrack>,
    /// The file the animation was read from (the scene, or its sidecar); set by the loader.
    #[serde(skip)]
    pub location: Location,
}

/// How values between keys are found. Before the first key and after the last, the first and
/// last key's values hold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Interpolation {
    /// Straight lines between keys.
    #[default]
    Linear,
    /// A Catmull-Rom spline through the keys (tangents from the neighbouring keys, scaled to
    /// uneven key spacing; one-sided at the ends): continuous velocity.
    CatmullRom,
}

/// Keys of the camera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraTrack {
    /// Interpolation between keys.
    #[serde(default)]
    pub interpolation: Interpolation,
    /// The keys, times strictly increasing.
    pub keys: Keys<CameraKey>,
}

/// The camera at one time: a look-at (replacing the camera's `to_world`) and a field of view.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraKey {
    /// Time in seconds.
    #[serde(deserialize_with = "key_time")]
    pub time: f32,
    /// Eye position.
    #[serde(deserialize_with = "limits::coordinates")]
    pub position: V3,
    /// Point looked at.
    #[serde(deserialize_with = "limits::coordinates")]
    pub target: V3,
    /// Up vector (default `(0, 1, 0)`).
    #[serde(default = "default_up", deserialize_with = "limits::finite3")]
    pub up: V3,
    /// Field of view in degrees (default: the scene camera's).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "key_fov"
    )]
    pub fov: Option<f32>,
}

/// What happens to one shape over time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeTrack {
    /// The shape's `id` (RON: its `id` field; XML: its `id` attribute).
    pub id: String,
    /// Interpolation between keys (of both lists).
    #[serde(default)]
    pub interpolation: Interpolation,
    /// The point the rotation turns about, in world space before the motion (default the origin).
    #[serde(default, deserialize_with = "limits::coordinates")]
    pub pivot: V3,
    /// Rigid motion keys, applied after the shape's own `to_world`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<Keys<MotionKey>>,
    /// Emitted radiance keys (the shape must be an emitter).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<Keys<EmissionKey>>,
    /// Index of the shape in the scene's `shapes`; set when the animation is attached to a scene.
    #[serde(skip)]
    pub shape: usize,
}

/// A rigid motion at one time: the shape turned about the pivot by `rotate` (degrees about x,
/// then y, then z), then moved by `translate`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionKey {
    /// Time in seconds.
    #[serde(deserialize_with = "key_time")]
    pub time: f32,
    /// Translation.
    #[serde(default, deserialize_with = "limits::coordinates")]
    pub translate: V3,
    /// Rotation angles in degrees about the x, y and z axes (applied in that order).
    #[serde(default, deserialize_with = "limits::finite3")]
    pub rotate: V3,
}

/// Emitted radiance at one time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EmissionKey {
    /// Time in seconds.
    #[serde(deserialize_with = "key_time")]
    pub time: f32,
    /// Radiance (non-negative).
    #[serde(deserialize_with = "key_radiance")]
    pub radiance: V3,
}

/// Something with a key time.
pub trait Keyed {
    /// The key's time in seconds.
    fn time(&self) -> f32;
}

impl Keyed for CameraKey {
    fn time(&self) -> f32 {
        self.time
    }
}

impl Keyed for MotionKey {
    fn time(&self) -> f32 {
        self.time
    }
}

impl Keyed for EmissionKey {
    fn time(&self) -> f32 {
        self.time
    }
}

std::thread_local! {
    /// The time of the key before the one being read, while a key list is deserialised: the
    /// order is checked as each key's `time` is read, so the error names that key's line.
    static PREVIOUS_TIME: std::cell::Cell<Option<f32>> = const { std::cell::Cell::new(None) };
}

fn key_time<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let t = limits::finite(d)?;
    if let Some(last) = PREVIOUS_TIME.get()
        && t <= last
    {
        return Err(D::Error::custom(format!(
            "key time {t} does not follow the previous key's time {last}: key times must increase strictly"
        )));
    }
    PREVIOUS_TIME.set(Some(t));
    Ok(t)
}

fn key_fov<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    let f = Option::<f32>::deserialize(d)?;
    match f {
        Some(v) if !(v.is_finite() && v > 0.0 && v < 180.0) => Err(D::Error::custom(format!(
            "camera key: fov {v} must be in (0, 180) degrees"
        ))),
        _ => Ok(f),
    }
}

fn key_radiance<'de, D: Deserializer<'de>>(d: D) -> Result<V3, D::Error> {
    let v = limits::finite3(d)?;
    if v.iter().any(|&r| r < 0.0) {
        return Err(D::Error::custom(format!(
            "emission key: radiance {v:?} must be non-negative"
        )));
    }
    // A Catmull-Rom spline through evenly spaced keys overshoots them by at most a quarter, so
    // keys up to 8·10²⁵ stay within the lights' limit (and far from f32's maximum, where the
    // spline's slopes overflowed and the light went dark). A frame whose interpolated emission
    // still exceeds the limit (keys spaced very unevenly) is refused when that frame is built.
    const MAX_KEY: f32 = 8e25;
    const { assert!(MAX_KEY * 1.25 <= restir_lights::MAX_EMISSION * 1.000_001) };
    if v.iter().any(|&r| r > MAX_KEY) {
        return Err(D::Error::custom(format!(
            "emission key: radiance {v:?} exceeds {MAX_KEY:e}, the largest a key may have (lights are limited to {:e}, and a spline overshoots its keys by up to a quarter)",
            restir_lights::MAX_EMISSION
        )));
    }
    Ok(v)
}

/// A non-empty list of keys with strictly increasing times, checked key by key while
/// deserialising (so the error names the offending key's line).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(transparent)]
pub struct Keys<T>(pub Vec<T>);

impl<T> Keys<T> {
    /// The keys in time order.
    pub fn keys(&self) -> &[T] {
        &self.0
    }
}

impl<'de, T: Deserialize<'de> + Keyed> Deserialize<'de> for Keys<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct KeyVisitor<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de> + Keyed> Visitor<'de> for KeyVisitor<T> {
            type Value = Keys<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a list of keys")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Keys<T>, A::Error> {
                let mut keys: Vec<T> = Vec::new();
                PREVIOUS_TIME.set(None);
                while let Some(k) = seq.next_element::<T>()? {
                    keys.push(k);
                }
                PREVIOUS_TIME.set(None);
                if keys.is_empty() {
                    return Err(A::Error::custom(
                        "an empty key list: give at least one key (time and values)",
                    ));
                }
                Ok(Keys(keys))
            }
        }
        d.deserialize_seq(KeyVisitor(std::marker::PhantomData))
    }
}
