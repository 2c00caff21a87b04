//! Mesh files: Wavefront OBJ ([`obj`]), PLY ([`ply`], ASCII and binary) and Mitsuba's
//! `.serialized` ([`serialized`]).
//!
//! Each returns positions, optional normals, optional uvs and triangles in object space (PLY
//! also the mesh attributes its other properties hold); the builder applies `to_world`, `flip_normals` and `face_normals`. Every malformed input is a
//! [`MeshError`] naming the file (the builder prefixes the scene file and line), never a panic;
//! sizes read from a file are checked against the bytes actually present before anything is
//! allocated.

mod obj;
mod ply;
mod ply_attributes;
mod serialized;

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use restir_geometry::MeshAttribute;

/// Positions, optional normals, optional uvs and triangles of a mesh file.
pub(crate) type MeshData = (
    Vec<Vec3>,
    Option<Vec<Vec3>>,
    Option<Vec<Vec2>>,
    Vec<[u32; 3]>,
);

/// Why a mesh file could not be loaded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MeshError {
    /// The file could not be opened or read (or, for OBJ, parsed by the OBJ reader).
    Read {
        /// The mesh file.
        path: PathBuf,
        /// What the reader said.
        reason: String,
    },
    /// An OBJ model's coordinate or index lists are not whole triples.
    Truncated {
        /// The mesh file.
        path: PathBuf,
    },
    /// An OBJ file holds no triangles.
    NoTriangles {
        /// The mesh file.
        path: PathBuf,
    },
    /// The contents are malformed (a PLY or `.serialized` file).
    Malformed {
        /// The mesh file.
        path: PathBuf,
        /// What is wrong.
        problem: String,
    },
}

impl core::fmt::Display for MeshError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            MeshError::Read { path, reason } => {
                write!(f, "cannot read mesh '{}': {reason}", path.display())
            }
            MeshError::Truncated { path } => write!(f, "mesh '{}' is truncated", path.display()),
            MeshError::NoTriangles { path } => {
                write!(f, "mesh '{}' has no triangles", path.display())
            }
            MeshError::Malformed { path, problem } => {
                write!(f, "mesh '{}': {problem}", path.display())
            }
        }
    }
}

impl std::error::Error for MeshError {}

pub(crate) use obj::load_obj;

/// Reads a PLY file, with its mesh attributes (Mitsuba's `vertex_…` and `face_…`).
pub(crate) fn load_ply(path: &Path) -> Result<(MeshData, Vec<MeshAttribute>), MeshError> {
    ply::read_ply(&read_file(path)?).map_err(|problem| malformed(path, problem))
}

/// Reads shape `index` of a Mitsuba `.serialized` file.
pub(crate) fn load_serialized(path: &Path, index: usize) -> Result<MeshData, MeshError> {
    serialized::read_serialized(&read_file(path)?, index)
        .map_err(|problem| malformed(path, problem))
}

/// Reads a whole mesh file (a regular file of at most 2 GiB).
fn read_file(path: &Path) -> Result<Vec<u8>, MeshError> {
    restir_image::input::read_regular(path).map_err(|e| MeshError::Read {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })
}

fn malformed(path: &Path, problem: String) -> MeshError {
    MeshError::Malformed {
        path: path.to_path_buf(),
        problem,
    }
}

/// Checks indices and attribute counts and assembles the result.
pub(super) fn finish(
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    indices: Vec<[u32; 3]>,
) -> Result<MeshData, String> {
    if indices.is_empty() {
        return Err("the mesh has no triangles".into());
    }
    let n = positions.len();
    if let Some((i, t)) = indices
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&v| v as usize >= n))
    {
        return Err(format!(
            "triangle {i} refers to vertex {} but there are only {n} vertices",
            t.iter().max().copied().unwrap_or(0)
        ));
    }
    if positions.iter().any(|p| !p.is_finite()) {
        return Err("the mesh has non-finite vertex positions".into());
    }
    let normals = (normals.len() == n && normals.iter().all(|v| v.is_finite())).then_some(normals);
    let uvs = (uvs.len() == n && uvs.iter().all(|v| v.is_finite())).then_some(uvs);
    Ok((positions, normals, uvs, indices))
}
