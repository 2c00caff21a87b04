//! Wavefront OBJ meshes, read with `tobj`: every model of the file in one mesh, triangulated,
//! with normals and uvs kept only when every model has them. Materials come from the scene, so
//! an `mtllib` line is never followed (its file is not opened).

use std::path::Path;

use glam::{Vec2, Vec3};

use super::{MeshData, MeshError};

/// Reads an OBJ file.
pub(crate) fn load_obj(path: &Path) -> Result<MeshData, MeshError> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // tobj reports a missing file as "open file failed"; say why.
    let read_error = |reason: String| MeshError::Read {
        path: path.to_path_buf(),
        reason,
    };
    let file = restir_image::input::open_regular(path).map_err(|e| read_error(e.to_string()))?;
    let mut reader = std::io::BufReader::new(std::io::Read::take(
        file,
        restir_image::input::MAX_INPUT_BYTES,
    ));
    let (models, _) =
        tobj::load_obj_buf(&mut reader, &opts, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| read_error(e.to_string()))?;
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut indices = Vec::new();
    let all_normals = models
        .iter()
        .all(|m| m.mesh.normals.len() == m.mesh.positions.len());
    let all_uvs = models
        .iter()
        .all(|m| m.mesh.texcoords.len() / 2 == m.mesh.positions.len() / 3);
    for m in &models {
        let base = positions.len() as u32;
        let mesh = &m.mesh;
        if mesh.positions.len() % 3 != 0 || mesh.indices.len() % 3 != 0 {
            return Err(MeshError::Truncated {
                path: path.to_path_buf(),
            });
        }
        positions.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2])),
        );
        if all_normals {
            normals.extend(
                mesh.normals
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2])),
            );
        }
        if all_uvs {
            uvs.extend(
                mesh.texcoords
                    .chunks_exact(2)
                    // OBJ counts v from the bottom of the image; Mitsuba flips it on load.
                    .map(|c| Vec2::new(c[0], 1.0 - c[1])),
            );
        }
        for t in mesh.indices.chunks_exact(3) {
            indices.push([base + t[0], base + t[1], base + t[2]]);
        }
    }
    if indices.is_empty() {
        return Err(MeshError::NoTriangles {
            path: path.to_path_buf(),
        });
    }
    Ok((
        positions,
        (all_normals && !normals.is_empty()).then_some(normals),
        (all_uvs && !uvs.is_empty()).then_some(uvs),
        indices,
    ))
}
