//! The documented limits on scene input (docs/SCENES.md, "Limits") and the RON field checks that
//! enforce them while deserialising, so that a RON error names the line of the offending value as
//! an XML error does.
//!
//! Coordinates are stored as `f32`; the renderer's ray offsets, squared distances and the BVH
//! builder's surface-area arithmetic need headroom above the largest coordinate (obvhs's CWBVH
//! build fails once a box's extent squared overflows, near 1.8e19). [`MAX_COORDINATE`] leaves
//! seven orders of magnitude of that headroom.

use serde::{Deserialize, Deserializer, de::Error};

use super::V3;

/// The largest magnitude of any coordinate, radius, translation, scale or matrix entry, given or
/// after the object-to-world transform.
pub const MAX_COORDINATE: f32 = 1e12;

/// The narrowest reconstruction filter (tent radius or gaussian standard deviation, in pixels).
pub const MIN_FILTER_WIDTH: f32 = 1e-4;

/// The widest reconstruction filter (tent radius or gaussian standard deviation, in pixels).
pub const MAX_FILTER_WIDTH: f32 = 1e4;

/// The most vertices, and the most triangles, one mesh (file or inline) may have: 2^25.
pub const MAX_MESH_ELEMENTS: u64 = 1 << 25;

/// The most shapes Mitsuba `instance`s may place in one scene: 2^18. Instances are copied into
/// the scene when it is read (each copy a shape of its own, an instanced mesh loaded once per
/// copy and counted against `--max-memory`), so a small file of many instances of a large group
/// is refused here before any copy is made.
pub const MAX_INSTANCED_SHAPES: u64 = 1 << 18;

/// What one triangle of a mesh costs while the scene is built, in bytes, beside its vertices:
/// its indices, per-triangle faces and area table, and the BVH while obvhs builds it (its
/// temporary memory included; the build peaks when obvhs converts its binary tree to the wide
/// one, at 264 bytes per triangle). A 1M-triangle PLY (half a vertex per triangle, positions
/// only) peaks at 314 bytes per triangle, 308 beside its positions
/// (`crates/scene/tests/mesh_memory.rs`); meshes are checked against `--max-memory` with this
/// and their vertex data before the BVH is built. An emissive mesh's light tables are counted
/// apart ([`EMITTER_BYTES_PER_ENTRY`]).
pub const MESH_BYTES_PER_TRIANGLE: u64 = 320;

/// What one entry of the light tables costs, in bytes: an emissive triangle's (or any other
/// light's) emitter-table entry and alias-table bin (76), and its share of the light hierarchy
/// the light samplers build (two tree nodes and their leaf spans, its path, its leaf's place,
/// power prefix and guide for cuts, and the build's item: about 212 at the build's peak, 156
/// kept). Counted against `--max-memory` for each emitter before the tables are made; a
/// 1M-triangle emissive PLY with its hierarchy built peaks at 437 bytes per triangle, within
/// this and [`MESH_BYTES_PER_TRIANGLE`] (`crates/scene/tests/mesh_memory.rs`).
pub const EMITTER_BYTES_PER_ENTRY: u64 = 290;

/// What an environment map keeps per texel beside its texels, in bytes: the bin of its
/// conditional alias table.
pub const ENVMAP_TABLE_BYTES_PER_TEXEL: u64 = 12;

/// What building an environment map's sampling needs per texel at its peak beside the decode,
/// in bytes: its grid of patch weights.
pub const ENVMAP_BUILD_BYTES_PER_TEXEL: u64 = 8;

/// What a texel of a bitmap texture keeps, in bytes, at most (a float texel; 8-bit images keep
/// 4).
pub const TEXTURE_BYTES_PER_TEXEL: u64 = 12;

/// What decoding a texel of an image file needs at its peak, in bytes, beside what the texture
/// keeps: the decoder's own buffer (up to 16 bytes, RGBA `f32`) and its conversion to RGB `f32`
/// (12).
pub const DECODE_BYTES_PER_TEXEL: u64 = 28;

/// The largest file the loader reads (scene, mesh, texture or environment map): 2 GiB.
pub const MAX_FILE_BYTES: u64 = 2 << 30;

/// The longest attribute value after `<default>` substitution: 1 MiB.
pub const MAX_SUBSTITUTED_BYTES: usize = 1 << 20;

/// Why a number is unacceptable, or `None`.
pub fn coordinate_problem(v: f32) -> Option<String> {
    if !v.is_finite() {
        Some(format!("{v} is not a finite number"))
    } else if v.abs() > MAX_COORDINATE {
        Some(format!(
            "{v:e} is beyond the coordinate limit ±{MAX_COORDINATE:e}"
        ))
    } else {
        None
    }
}

fn check_coordinates<'de, D: Deserializer<'de>>(vs: &[f32]) -> Result<(), D::Error> {
    match vs.iter().find_map(|&v| coordinate_problem(v)) {
        Some(p) => Err(D::Error::custom(p)),
        None => Ok(()),
    }
}

/// A point or vector within [`MAX_COORDINATE`].
pub(crate) fn coordinates<'de, D: Deserializer<'de>>(d: D) -> Result<V3, D::Error> {
    let v = V3::deserialize(d)?;
    check_coordinates::<D>(&v)?;
    Ok(v)
}

/// A length (radius) within [`MAX_COORDINATE`].
pub(crate) fn coordinate<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let v = f32::deserialize(d)?;
    check_coordinates::<D>(&[v])?;
    Ok(v)
}

/// A list of points within [`MAX_COORDINATE`], at most [`MAX_MESH_ELEMENTS`] long.
pub(crate) fn point_list<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<V3>, D::Error> {
    let v = Vec::<V3>::deserialize(d)?;
    if v.len() as u64 > MAX_MESH_ELEMENTS {
        return Err(D::Error::custom(format!(
            "{} vertices are more than the limit of {MAX_MESH_ELEMENTS}",
            v.len()
        )));
    }
    check_coordinates::<D>(v.as_flattened())?;
    Ok(v)
}

/// A 4×4 matrix whose entries are within [`MAX_COORDINATE`].
pub(crate) fn matrix<'de, D: Deserializer<'de>>(d: D) -> Result<[f32; 16], D::Error> {
    let v = <[f32; 16]>::deserialize(d)?;
    check_coordinates::<D>(&v)?;
    Ok(v)
}

/// A finite number.
pub(crate) fn finite<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let v = f32::deserialize(d)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(D::Error::custom(format!("{v} is not a finite number")))
    }
}

/// Three finite numbers (a colour or a direction).
pub(crate) fn finite3<'de, D: Deserializer<'de>>(d: D) -> Result<V3, D::Error> {
    let v = V3::deserialize(d)?;
    match v.iter().find(|x| !x.is_finite()) {
        Some(x) => Err(D::Error::custom(format!("{x} is not a finite number"))),
        None => Ok(v),
    }
}

/// Why a filter width is unacceptable, or `None`.
pub fn filter_width_problem(v: f32) -> Option<String> {
    (!(MIN_FILTER_WIDTH..=MAX_FILTER_WIDTH).contains(&v)).then(|| {
        format!("{v:e} is outside the range [{MIN_FILTER_WIDTH:e}, {MAX_FILTER_WIDTH:e}] pixels")
    })
}

/// A filter width within [`MIN_FILTER_WIDTH`]..=[`MAX_FILTER_WIDTH`].
pub(crate) fn filter_width<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let v = f32::deserialize(d)?;
    match filter_width_problem(v) {
        Some(p) => Err(D::Error::custom(p)),
        None => Ok(v),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_accept_the_range_and_reject_beyond() {
        assert!(coordinate_problem(1e12).is_none());
        assert!(coordinate_problem(-1e12).is_none());
        assert!(coordinate_problem(0.0).is_none());
        assert_eq!(
            coordinate_problem(2e12).unwrap(),
            "2e12 is beyond the coordinate limit ±1e12"
        );
        assert_eq!(
            coordinate_problem(f32::NAN).unwrap(),
            "NaN is not a finite number"
        );
        assert!(filter_width_problem(0.5).is_none());
        assert!(filter_width_problem(1e30).is_some());
        assert!(filter_width_problem(1e-23).is_some());
        assert!(filter_width_problem(f32::NAN).is_some());
    }
}
