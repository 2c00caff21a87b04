//! What a scene's build may take of memory (`--max-memory`): every image counted from its
//! header before any is decoded, then each mesh before it is built and each emitter's light
//! tables before they are made.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use crate::desc::{LightDesc, Location, MaterialRef, SceneDesc, TextureDesc, limits};

/// The memory the build may use (`--max-memory`) and what images, meshes and light tables already
/// take of it; each is counted before it is decoded, built or made, so the one that crosses the
/// limit is named.
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
            return Err(format!(
                "{} would bring the scene's images, meshes and light tables to about {}, more than \
                 the limit of {}: raise --max-memory",
                what(),
                size(need),
                size(limit)
            ));
        }
        self.used = self.used.saturating_add(kept);
        Ok(())
    }

    /// Counts every image of `images` (their texels read from the headers) before any is
    /// decoded. The error names the image that crosses the limit, where the scene names it, and
    /// what all the images need together.
    pub(super) fn take_images(&mut self, images: &[ImageUse]) -> Result<(), (Location, String)> {
        let Some(limit) = self.limit else {
            return Ok(());
        };
        let mut sizes = Vec::with_capacity(images.len());
        for im in images {
            let (w, h) = restir_image::Image::read_dimensions(&im.path)
                .map_err(|e| (im.location.clone(), format!("{}: {e}", im.what)))?;
            let texels = w as u64 * h as u64;
            let (kept, transient) = if im.envmap {
                (
                    limits::TEXTURE_BYTES_PER_TEXEL + limits::ENVMAP_TABLE_BYTES_PER_TEXEL,
                    limits::DECODE_BYTES_PER_TEXEL + limits::ENVMAP_BUILD_BYTES_PER_TEXEL,
                )
            } else {
                (
                    limits::TEXTURE_BYTES_PER_TEXEL,
                    limits::DECODE_BYTES_PER_TEXEL,
                )
            };
            sizes.push((
                w,
                h,
                texels.saturating_mul(kept),
                texels.saturating_mul(transient),
            ));
        }
        // What the images keep together, and the most decoding one of them needs on top.
        let total = sizes.iter().fold(0u64, |t, s| t.saturating_add(s.2));
        let peak = sizes.iter().map(|s| s.3).max().unwrap_or(0);
        for (im, &(w, h, kept, transient)) in images.iter().zip(&sizes) {
            let need = self.used.saturating_add(kept).saturating_add(transient);
            if need > limit {
                return Err((
                    im.location.clone(),
                    format!(
                        "{}: image '{}' ({w}×{h} texels) would bring the scene's images, \
                         meshes and light tables to about {}, more than the limit of {} (the \
                         scene's {} image{} need about {} together, checked before any is \
                         decoded): raise --max-memory",
                        im.what,
                        im.path.display(),
                        size(need),
                        size(limit),
                        images.len(),
                        if images.len() == 1 { "" } else { "s" },
                        size(total.saturating_add(peak)),
                    ),
                ));
            }
            self.used = self.used.saturating_add(kept);
        }
        Ok(())
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

impl Budget {
    /// Counts the light tables of an emitter of `entries` entries (one per emissive triangle,
    /// one for any other light) before they are made: the emitter table, and the light
    /// hierarchy a light sampler may build over it.
    pub(super) fn take_emitters(
        &mut self,
        entries: usize,
        what: impl FnOnce() -> String,
    ) -> Result<(), String> {
        self.take(
            (entries as u64).saturating_mul(limits::EMITTER_BYTES_PER_ENTRY),
            0,
            || {
                format!(
                    "{} ({entries} light table entr{})",
                    what(),
                    if entries == 1 { "y" } else { "ies" }
                )
            },
        )
    }
}

/// `b` bytes in MiB or GiB.
fn size(b: u64) -> String {
    match b as f64 / (1u64 << 30) as f64 {
        g if g >= 1.0 => format!("{g:.2} GiB"),
        g => format!("{:.1} MiB", g * 1024.0),
    }
}

/// The bytes of a mesh's positions, normals (read, or `computed_normals` for a mesh given
/// them at load) and uvs.
pub(super) fn vertex_bytes(
    p: &[Vec3],
    n: &Option<Vec<Vec3>>,
    uv: &Option<Vec<Vec2>>,
    computed_normals: bool,
) -> usize {
    let normals =
        n.as_ref().map_or(0, |n| 12 * n.len()) + if computed_normals { 12 * p.len() } else { 0 };
    12 * p.len() + normals + uv.as_ref().map_or(0, |u| 8 * u.len())
}

/// An image file the build decodes: its path, where the scene names it and how the error says
/// which use it is.
pub(super) struct ImageUse {
    pub(super) path: PathBuf,
    pub(super) location: Location,
    pub(super) what: String,
    /// An environment map, which keeps its sampling tables beside its texels.
    pub(super) envmap: bool,
}

/// Every image file the build of `desc` decodes, in the order it decodes them: the bitmap
/// textures of the named materials, of the shapes' inline materials (each distinct texture
/// once, as the build loads it), of area emitters (each distinct radiance texture once), of
/// spot lights and projectors, and the environment map.
/// A named material's texture is placed at the first shape that uses the material.
pub(super) fn images(desc: &SceneDesc, base_dir: &Path) -> Vec<ImageUse> {
    let mut seen: Vec<&TextureDesc> = Vec::new();
    let mut emission_seen: Vec<&TextureDesc> = Vec::new();
    let mut out = Vec::new();
    let bitmap = |t: &TextureDesc, location: &Location, what: String, out: &mut Vec<ImageUse>| {
        if let TextureDesc::Bitmap { filename, .. } = t {
            out.push(ImageUse {
                path: base_dir.join(filename),
                location: location.clone(),
                what,
                envmap: false,
            });
        }
    };
    for nm in &desc.materials {
        let user =
            desc.shapes.iter().enumerate().find(
                |(_, s)| matches!(&s.material, Some(MaterialRef::Ref(name)) if *name == nm.name),
            );
        let (location, what) = match user {
            Some((i, s)) => (
                s.location.clone(),
                format!("shape {i}: material '{}'", nm.name),
            ),
            None => (Location::default(), format!("material '{}'", nm.name)),
        };
        for b in crate::material::colors(&nm.material).1 {
            if !seen.contains(&&b.texture) {
                seen.push(&b.texture);
                bitmap(&b.texture, &location, what.clone(), &mut out);
            }
        }
    }
    for (i, s) in desc.shapes.iter().enumerate() {
        if let Some(MaterialRef::Inline(m)) = &s.material {
            for b in crate::material::colors(m).1 {
                if !seen.contains(&&b.texture) {
                    seen.push(&b.texture);
                    bitmap(&b.texture, &s.location, format!("shape {i}"), &mut out);
                }
            }
        }
        // Area emitters that name the same radiance texture share one copy.
        if let Some(t) = &s.emission_texture
            && !emission_seen.contains(&t)
        {
            emission_seen.push(t);
            bitmap(
                t,
                &s.location,
                format!("shape {i}: emitter radiance texture"),
                &mut out,
            );
        }
    }
    for l in &desc.lights {
        match l {
            LightDesc::Spot {
                texture: Some(t),
                location,
                ..
            } => bitmap(t, location, "spot emitter texture".into(), &mut out),
            LightDesc::Projector {
                texture: Some(t),
                location,
                ..
            } => bitmap(t, location, "projector emitter texture".into(), &mut out),
            LightDesc::Envmap {
                filename, location, ..
            } => out.push(ImageUse {
                path: base_dir.join(filename),
                location: location.clone(),
                what: "envmap".into(),
                envmap: true,
            }),
            _ => {}
        }
    }
    out
}
