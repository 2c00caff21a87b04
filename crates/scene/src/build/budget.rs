//! What a scene's build may take of memory (`--max-memory`), counted before each mesh or image
//! is built or decoded.

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::desc::limits;

/// The memory the build may use (`--max-memory`) and what meshes and images already take of it;
/// each is counted before it is built or decoded, so the one that crosses the limit is named.
#[derive(Default)]
pub(super) struct Budget {
    pub(super) limit: Option<u64>,
    pub(super) used: u64,
}

impl Budget {
    /// Counts `kept` bytes more, refusing when they and `transient` bytes on top of what is used
    /// exceed the limit; `what` names the input.
    pub(super) fn take(
        &mut self,
        kept: u64,
        transient: u64,
        what: impl FnOnce() -> String,
    ) -> Result<(), String> {
        let need = self.used.saturating_add(kept).saturating_add(transient);
        if let Some(limit) = self.limit
            && need > limit
        {
            let size = |b: u64| match b as f64 / (1u64 << 30) as f64 {
                g if g >= 1.0 => format!("{g:.2} GiB"),
                g => format!("{:.1} MiB", g * 1024.0),
            };
            return Err(format!(
                "{} would bring the scene's meshes and images to about {}, more than the limit \
                 of {}: raise --max-memory",
                what(),
                size(need),
                size(limit)
            ));
        }
        self.used = self.used.saturating_add(kept);
        Ok(())
    }

    /// Counts an image file's texels (read from its header) before it is decoded.
    pub(super) fn take_image(&mut self, path: &Path) -> Result<(), String> {
        if self.limit.is_none() {
            return Ok(());
        }
        let (w, h) = restir_image::Image::read_dimensions(path).map_err(|e| e.to_string())?;
        let texels = w as u64 * h as u64;
        self.take(
            texels * limits::TEXTURE_BYTES_PER_TEXEL,
            texels * limits::DECODE_BYTES_PER_TEXEL,
            || format!("image '{}' ({w}×{h} texels)", path.display()),
        )
    }

    /// Counts a mesh of `triangles` with `vertex_bytes` of vertex data before its tables and
    /// BVH are built.
    pub(super) fn take_mesh(
        &mut self,
        triangles: usize,
        vertex_bytes: usize,
        what: impl FnOnce() -> String,
    ) -> Result<(), String> {
        self.take(
            (triangles as u64 * limits::MESH_BYTES_PER_TRIANGLE)
                .saturating_add(vertex_bytes as u64),
            0,
            || format!("{} ({triangles} triangles)", what()),
        )
    }
}

/// The bytes of a mesh's positions, normals and uvs.
pub(super) fn vertex_bytes(p: &[Vec3], n: &Option<Vec<Vec3>>, uv: &Option<Vec<Vec2>>) -> usize {
    12 * p.len() + n.as_ref().map_or(0, |n| 12 * n.len()) + uv.as_ref().map_or(0, |u| 8 * u.len())
}
