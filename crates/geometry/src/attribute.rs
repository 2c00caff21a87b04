//! Named per-vertex and per-face values that a mesh carries beside its geometry (Mitsuba 3's
//! mesh attributes: `vertex_color`, `face_weight`, …), read by the scene's `mesh_attribute`
//! texture. A vertex attribute is interpolated with a hit's barycentrics; a face attribute is
//! constant over its triangle.

use glam::{Vec2, Vec3};

/// Whether an attribute has one row per vertex or one per triangle (its name starts with
/// `vertex_` or `face_`, as in Mitsuba 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AttributeRate {
    /// One row per vertex, interpolated across each triangle.
    Vertex,
    /// One row per triangle.
    Face,
}

impl AttributeRate {
    /// The rate a Mitsuba attribute name implies (`vertex_…` or `face_…`), or `None`.
    pub fn of_name(name: &str) -> Option<AttributeRate> {
        if name.starts_with("vertex_") {
            Some(AttributeRate::Vertex)
        } else if name.starts_with("face_") {
            Some(AttributeRate::Face)
        } else {
            None
        }
    }
}

/// One named attribute: `channels` floats per row, rows one per vertex or per triangle.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshAttribute {
    name: String,
    rate: AttributeRate,
    channels: usize,
    values: Vec<f32>,
}

/// Why an attribute cannot be attached to a mesh.
#[derive(Clone, Debug, PartialEq)]
pub enum AttributeError {
    /// The name starts with neither `vertex_` nor `face_`.
    Name(String),
    /// The channel count is not 1 to 4.
    Channels {
        /// The attribute.
        name: String,
        /// Its channel count.
        channels: usize,
    },
    /// The number of values is not one row per vertex (or triangle).
    Rows {
        /// The attribute.
        name: String,
        /// How many values it has.
        values: usize,
        /// Channels per row.
        channels: usize,
        /// How many rows it needs.
        rows: usize,
    },
    /// A value is NaN or infinite.
    NonFinite {
        /// The attribute.
        name: String,
        /// The row.
        row: usize,
    },
    /// Two attributes have the same name.
    Duplicate(String),
}

impl core::fmt::Display for AttributeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            AttributeError::Name(n) => write!(
                f,
                "mesh attribute \"{n}\": a name starts with \"vertex_\" or \"face_\""
            ),
            AttributeError::Channels { name, channels } => write!(
                f,
                "mesh attribute \"{name}\" has {channels} channels (1 to 4 are supported)"
            ),
            AttributeError::Rows {
                name,
                values,
                channels,
                rows,
            } => write!(
                f,
                "mesh attribute \"{name}\" has {values} values, but {rows} rows of {channels} are needed"
            ),
            AttributeError::NonFinite { name, row } => {
                write!(f, "mesh attribute \"{name}\": row {row} is not finite")
            }
            AttributeError::Duplicate(n) => write!(f, "mesh attribute \"{n}\" is given twice"),
        }
    }
}

impl std::error::Error for AttributeError {}

impl MeshAttribute {
    /// An attribute named `name` (its rate from the name's `vertex_`/`face_` prefix) with
    /// `channels` (1 to 4) values per row, rows one after the other.
    pub fn new(name: &str, channels: usize, values: Vec<f32>) -> Result<Self, AttributeError> {
        let rate = AttributeRate::of_name(name).ok_or(AttributeError::Name(name.into()))?;
        if !(1..=4).contains(&channels) {
            return Err(AttributeError::Channels {
                name: name.into(),
                channels,
            });
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(AttributeError::NonFinite {
                name: name.into(),
                row: i / channels,
            });
        }
        Ok(Self {
            name: name.into(),
            rate,
            channels,
            values,
        })
    }

    /// The name (`vertex_color`, `face_weight`, …).
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Per vertex or per face.
    pub fn rate(&self) -> AttributeRate {
        self.rate
    }
    /// Values per row.
    pub fn channels(&self) -> usize {
        self.channels
    }
    /// The values, row after row.
    pub fn values(&self) -> &[f32] {
        &self.values
    }
    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.values.len() / self.channels
    }
    /// Bytes of the values.
    pub fn bytes(&self) -> usize {
        4 * self.values.len()
    }

    /// The first three channels of row `i` (one channel is repeated; a missing third is 0).
    #[inline(always)]
    fn row(&self, i: u32) -> Vec3 {
        let c = self.channels;
        let r = &self.values[i as usize * c..][..c];
        match c {
            1 => Vec3::splat(r[0]),
            2 => Vec3::new(r[0], r[1], 0.0),
            _ => Vec3::new(r[0], r[1], r[2]),
        }
    }

    /// The value on triangle `prim` (corners `tri`) at barycentrics `b = (b1, b2)`: the three
    /// corners' rows blended for a vertex attribute, the triangle's row for a face attribute.
    /// A one-channel attribute fills all three components.
    #[inline]
    pub fn eval(&self, tri: [u32; 3], prim: u32, b: Vec2) -> Vec3 {
        match self.rate {
            AttributeRate::Face => self.row(prim),
            AttributeRate::Vertex => {
                let b0 = 1.0 - b.x - b.y;
                b0 * self.row(tri[0]) + b.x * self.row(tri[1]) + b.y * self.row(tri[2])
            }
        }
    }

    /// Keeps the rows of the triangles `keep` marks (a face attribute, after triangles were
    /// removed); a vertex attribute is left as it is.
    pub(crate) fn retain_faces(&mut self, keep: &[bool]) {
        if self.rate == AttributeRate::Face {
            let c = self.channels;
            let mut i = 0;
            self.values.retain(|_| {
                let kept = keep.get(i / c).copied().unwrap_or(true);
                i += 1;
                kept
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_and_vertex_lookups() {
        let v = MeshAttribute::new("vertex_color", 3, vec![1., 0., 0., 0., 1., 0., 0., 0., 1.])
            .unwrap();
        assert_eq!(v.rate(), AttributeRate::Vertex);
        assert_eq!(v.rows(), 3);
        let b = Vec2::new(0.25, 0.5);
        let got = v.eval([0, 1, 2], 0, b);
        assert!((got - Vec3::new(0.25, 0.25, 0.5)).abs().max_element() < 1e-6);
        // The corners' order follows the triangle's indices.
        assert_eq!(v.eval([2, 0, 1], 0, Vec2::ZERO), Vec3::Z);
        let f = MeshAttribute::new("face_weight", 1, vec![0.2, 0.7]).unwrap();
        assert_eq!(f.eval([0, 1, 2], 1, b), Vec3::splat(0.7));
        assert_eq!(f.eval([0, 1, 2], 0, Vec2::ZERO), Vec3::splat(0.2));
    }

    #[test]
    fn removing_triangles_keeps_face_rows_in_step() {
        let mut f = MeshAttribute::new("face_c", 2, vec![0., 1., 2., 3., 4., 5.]).unwrap();
        f.retain_faces(&[true, false, true]);
        assert_eq!(f.values(), &[0., 1., 4., 5.]);
        let mut v = MeshAttribute::new("vertex_c", 1, vec![1., 2., 3.]).unwrap();
        v.retain_faces(&[false, false, true]);
        assert_eq!(v.values(), &[1., 2., 3.]);
    }

    #[test]
    fn bad_attributes_are_errors() {
        assert!(matches!(
            MeshAttribute::new("color", 3, vec![0.; 3]),
            Err(AttributeError::Name(_))
        ));
        assert!(matches!(
            MeshAttribute::new("face_x", 5, vec![0.; 5]),
            Err(AttributeError::Channels { .. })
        ));
        let e = MeshAttribute::new("face_x", 1, vec![0., f32::NAN]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "mesh attribute \"face_x\": row 1 is not finite"
        );
    }
}
