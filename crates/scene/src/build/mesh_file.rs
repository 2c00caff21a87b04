//! Shapes read from mesh files (OBJ, PLY, Mitsuba's serialized): the file's mesh in object
//! space, its memory taken from the budget, and whether it is to get smooth vertex normals once
//! in world space (the file has none and the shape does not ask for face normals, as Mitsuba 3
//! and Lajolla decide).

use std::path::Path;

use restir_geometry::TriangleMesh;

use super::budget::{Budget, vertex_bytes};
use crate::desc::{GeometryDesc, ShapeDesc};

/// The mesh of `desc`, whose geometry is a mesh file, and whether it is to get computed vertex
/// normals ([`TriangleMesh::compute_vertex_normals`], after its transform).
pub(super) fn read(
    desc: &ShapeDesc,
    base_dir: &Path,
    budget: &mut Budget,
) -> Result<(TriangleMesh, bool), String> {
    let (path, ((p, n, uv, idx), attributes)) = match &desc.geometry {
        GeometryDesc::Obj { filename } => {
            let path = base_dir.join(filename);
            let data = crate::meshio::load_obj(&path).map_err(|e| e.to_string())?;
            (path, (data, Vec::new()))
        }
        GeometryDesc::Ply { filename } => {
            let path = base_dir.join(filename);
            let data = crate::meshio::load_ply(&path).map_err(|e| e.to_string())?;
            (path, data)
        }
        GeometryDesc::Serialized {
            filename,
            shape_index,
        } => {
            let path = base_dir.join(filename);
            let data = crate::meshio::load_serialized(&path, *shape_index as usize)
                .map_err(|e| e.to_string())?;
            (path, (data, Vec::new()))
        }
        _ => return Err("the shape is not read from a mesh file".into()),
    };
    let computed_normals = n.is_none() && !desc.face_normals;
    let attribute_bytes: usize = attributes.iter().map(|a| a.bytes()).sum();
    budget.take_mesh(
        idx.len(),
        vertex_bytes(&p, &n, &uv, computed_normals) + attribute_bytes,
        || format!("mesh '{}'", path.display()),
    )?;
    let n = if desc.face_normals { None } else { n };
    let mesh = TriangleMesh::new(p, n, uv, idx, desc.flip_normals)
        .map_err(|e| e.to_string())
        .and_then(|m| m.with_attributes(attributes).map_err(|e| e.to_string()))
        .map_err(|e| format!("mesh '{}': {e}", path.display()))?;
    Ok((mesh, computed_normals))
}
