//! Transforms: the steps a scene file writes ([`TransformOp`]) and their composition into one
//! matrix ([`transform_matrix`]), shared by the importer's checks and the builder.

use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

use super::{V3, limits};

/// One step of a transform; steps apply in order (the first is applied to the object first),
/// as in Mitsuba's `<transform>`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum TransformOp {
    /// Translation.
    Translate(#[serde(deserialize_with = "limits::coordinates")] V3),
    /// Per-axis scale.
    Scale(#[serde(deserialize_with = "limits::coordinates")] V3),
    /// Rotation by `angle` degrees about `axis` (counter-clockwise looking down the axis).
    Rotate {
        /// Rotation axis (need not be unit length).
        #[serde(deserialize_with = "limits::finite3")]
        axis: V3,
        /// Angle in degrees.
        #[serde(deserialize_with = "limits::finite")]
        angle: f32,
    },
    /// Camera-style look-at: `+z` towards `target`, `+y` towards `up`, `+x = up × z`.
    LookAt {
        /// Eye position.
        #[serde(deserialize_with = "limits::coordinates")]
        origin: V3,
        /// Point looked at.
        #[serde(deserialize_with = "limits::coordinates")]
        target: V3,
        /// Up vector.
        #[serde(deserialize_with = "limits::finite3")]
        up: V3,
    },
    /// A row-major 4×4 matrix.
    Matrix(#[serde(deserialize_with = "limits::matrix")] [f32; 16]),
}

/// Why transform steps do not compose into a usable matrix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransformError {
    /// A rotation about a zero (or non-finite) axis.
    ZeroAxis,
    /// A look-at whose origin equals its target or whose up is parallel to the view.
    DegenerateLookAt,
    /// The composed matrix has non-finite entries.
    NonFinite,
}

impl core::fmt::Display for TransformError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            TransformError::ZeroAxis => "rotation axis is zero",
            TransformError::DegenerateLookAt => {
                "lookat is degenerate: origin equals target or up is parallel to the view direction"
            }
            TransformError::NonFinite => "transform has non-finite entries",
        })
    }
}

impl std::error::Error for TransformError {}

/// Composes transform steps (first step applied first) into one matrix.
pub fn transform_matrix(ops: &[TransformOp]) -> Result<Mat4, TransformError> {
    let mut m = Mat4::IDENTITY;
    for op in ops {
        let step = match op {
            TransformOp::Translate(t) => Mat4::from_translation(Vec3::from(*t)),
            TransformOp::Scale(s) => Mat4::from_scale(Vec3::from(*s)),
            TransformOp::Rotate { axis, angle } => {
                let a = Vec3::from(*axis);
                if a.length_squared() == 0.0 || !a.is_finite() {
                    return Err(TransformError::ZeroAxis);
                }
                Mat4::from_axis_angle(a.normalize(), angle.to_radians())
            }
            TransformOp::LookAt { origin, target, up } => {
                let (o, t, u) = (Vec3::from(*origin), Vec3::from(*target), Vec3::from(*up));
                let dir = (t - o).normalize_or_zero();
                let left = u.cross(dir).normalize_or_zero();
                if dir == Vec3::ZERO || left == Vec3::ZERO {
                    return Err(TransformError::DegenerateLookAt);
                }
                let new_up = dir.cross(left);
                Mat4::from_cols(
                    left.extend(0.0),
                    new_up.extend(0.0),
                    dir.extend(0.0),
                    o.extend(1.0),
                )
            }
            TransformOp::Matrix(v) => Mat4::from_cols_array(v).transpose(),
        };
        m = step * m;
    }
    if !m.is_finite() {
        return Err(TransformError::NonFinite);
    }
    Ok(m)
}
