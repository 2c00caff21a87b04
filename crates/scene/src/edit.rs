//! The materials of a built scene: reading them, and the edits that keep
//! [`Scene::features`](crate::Scene) true to them.

use restir_materials::{Bsdf, LobeFlags};

use crate::texture::Texture;
use crate::{Scene, TexturedParams};

/// Why an edit of a built scene was refused.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum EditError {
    /// No material with this index.
    NoMaterial {
        /// The index given.
        index: u32,
        /// How many materials the scene has.
        count: usize,
    },
    /// No shape with this index.
    NoShape {
        /// The index given.
        index: usize,
        /// How many shapes the scene has.
        count: usize,
    },
    /// The material reads a mesh attribute that the shape does not have.
    Attribute {
        /// The shape.
        shape: usize,
        /// What is missing.
        reason: String,
    },
}

impl std::fmt::Display for EditError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EditError::NoMaterial { index, count } => write!(
                f,
                "no material {index}: the scene has {count} (indices 0 to {})",
                count.saturating_sub(1)
            ),
            EditError::NoShape { index, count } => write!(
                f,
                "no shape {index}: the scene has {count} (indices 0 to {})",
                count.saturating_sub(1)
            ),
            EditError::Attribute { shape, reason } => write!(f, "shape {shape}: {reason}"),
        }
    }
}

impl std::error::Error for EditError {}

/// Reading the materials, and the edits that keep [`Scene::features`] true to them.
impl Scene {
    /// The materials, by index (with their constant parameters; [`Scene::bsdf_at`] applies
    /// textures). Index 0 is the default diffuse material, 1 the black one of emitters without
    /// a material.
    pub fn bsdfs(&self) -> &[Bsdf] {
        &self.bsdfs
    }

    /// For each shape, the index of its material in [`Scene::bsdfs`].
    pub fn shape_bsdf(&self) -> &[u32] {
        &self.shape_bsdf
    }

    /// For each material, the textures of its parameters, if it has any.
    pub fn bsdf_textures(&self) -> &[Option<TexturedParams>] {
        &self.bsdf_textures
    }

    /// The decoded textures that [`Scene::bsdf_textures`] refer to.
    pub fn textures(&self) -> &[Texture] {
        &self.textures
    }

    /// Replaces material `material` by `bsdf`, on every shape that uses it. The new material's
    /// parameters are constant: textures the old one had are dropped. Updates the summary.
    ///
    /// ```
    /// # let ron = r#"(camera: (fov: 40, to_world: [LookAt(origin: (0, 0, 4), target: (0, 0, 0), up: (0, 1, 0))]),
    /// #     film: (width: 8, height: 8, filter: Box),
    /// #     shapes: [(geometry: Rectangle, material: Some(Inline(Diffuse(reflectance: (0.5, 0.5, 0.5)))))])"#;
    /// # let desc = restir_scene::parse_ron(ron, "inline.ron".as_ref()).unwrap();
    /// use restir_materials::Bsdf;
    /// let mut scene = restir_scene::Scene::build(&desc, ".".as_ref(), "inline.ron".as_ref())?;
    /// assert!(!scene.features.has_delta_lobes);
    /// let m = scene.shape_bsdf()[0];
    /// scene.set_material(m, Bsdf::dielectric(1.5, glam::Vec3::ONE, glam::Vec3::ONE))?;
    /// assert!(scene.features.has_delta_lobes);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn set_material(&mut self, material: u32, bsdf: Bsdf) -> Result<(), EditError> {
        let count = self.bsdfs.len();
        let slot = self
            .bsdfs
            .get_mut(material as usize)
            .ok_or(EditError::NoMaterial {
                index: material,
                count,
            })?;
        *slot = bsdf;
        self.bsdf_textures[material as usize] = None;
        self.update_material_features();
        Ok(())
    }

    /// Adds `bsdf` as a new material (constant parameters) and returns its index, for
    /// [`Scene::set_shape_material`]. No shape uses it yet, so the summary does not change.
    pub fn add_material(&mut self, bsdf: Bsdf) -> u32 {
        self.bsdfs.push(bsdf);
        self.bsdf_textures.push(None);
        self.bsdfs.len() as u32 - 1
    }

    /// Gives shape `shape` material `material` (an index into [`Scene::bsdfs`]). Updates the
    /// summary. A material whose `mesh_attribute` textures read an attribute the shape does not
    /// have is refused.
    pub fn set_shape_material(&mut self, shape: usize, material: u32) -> Result<(), EditError> {
        if material as usize >= self.bsdfs.len() {
            return Err(EditError::NoMaterial {
                index: material,
                count: self.bsdfs.len(),
            });
        }
        let count = self.shape_bsdf.len();
        if shape >= count {
            return Err(EditError::NoShape {
                index: shape,
                count,
            });
        }
        if let Some(t) = &self.bsdf_textures[material as usize] {
            crate::texture::bind(&mut self.textures, t, shape as u32, &self.shapes[shape])
                .map_err(|reason| EditError::Attribute { shape, reason })?;
        }
        self.shape_bsdf[shape] = material;
        self.update_material_features();
        Ok(())
    }

    /// The summary's material flags from the materials the shapes use: delta and glossy lobes,
    /// textured parameters.
    pub(crate) fn update_material_features(&mut self) {
        let used = || self.shape_bsdf.iter().map(|&b| b as usize);
        let lobes = |flag| used().any(|b| self.bsdfs[b].flags().contains(flag));
        let has_delta_lobes = lobes(LobeFlags::DELTA);
        let has_glossy_lobes = lobes(LobeFlags::GLOSSY);
        let has_textures = used().any(|b| self.bsdf_textures[b].is_some());
        let f = &mut self.features;
        (f.has_delta_lobes, f.has_glossy_lobes, f.has_textures) =
            (has_delta_lobes, has_glossy_lobes, has_textures);
    }
}
