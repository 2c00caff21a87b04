//! Where a texture is looked up ([`TexturePoint`]), and Mitsuba 3's `mesh_attribute` texture
//! (<https://mitsuba.readthedocs.io/en/latest/src/generated/plugins_textures.html#mesh-attribute-texture-mesh-attribute>):
//! the value of a named attribute of the mesh that was hit (`vertex_…` interpolated with the
//! hit's barycentrics, `face_…` constant per triangle), times `scale`.
//!
//! A texture description is shared by every shape whose material uses it, and each mesh keeps its
//! attributes in its own order, so the texture holds, per shape, the index of its attribute in
//! that shape's mesh: [`bind`] sets it when the scene is built (and when a shape is given another
//! material), and refuses a shape that is not a mesh or lacks the attribute. A lookup on a shape
//! it was not bound to reads zero, as Mitsuba reads an attribute a shape does not carry.

use glam::{Vec2, Vec3};
use restir_geometry::{Shape, SurfaceInteraction};

use super::Texture;
use crate::TexturedParams;

/// Where on a surface a material's textures are looked up: texture coordinates for `bitmap` and
/// `checkerboard`; the shape, its triangle and the barycentrics there for `mesh_attribute`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TexturePoint {
    /// Texture coordinates.
    pub uv: Vec2,
    /// The shape (index into `Scene::shapes`).
    pub shape: u32,
    /// The triangle within the shape.
    pub prim: u32,
    /// Barycentrics `(b1, b2)` of the point on the triangle (weights of its second and third
    /// corners).
    pub bary: Vec2,
}

impl TexturePoint {
    /// The lookup point of a surface interaction.
    #[inline(always)]
    pub fn of(si: &SurfaceInteraction) -> Self {
        Self {
            uv: si.uv,
            shape: si.shape,
            prim: si.prim,
            bary: si.param,
        }
    }

    /// A point known only by its texture coordinates (no mesh attribute reads anything there).
    pub fn at_uv(uv: Vec2) -> Self {
        Self {
            uv,
            shape: u32::MAX,
            prim: 0,
            bary: Vec2::ZERO,
        }
    }
}

/// A `mesh_attribute` texture: the attribute's name, the scale, and per shape the index of the
/// attribute in that shape's mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct AttributeTexture {
    name: String,
    scale: f32,
    /// Per shape index, the attribute's index in the mesh's list, or [`UNBOUND`].
    bound: Vec<u32>,
}

const UNBOUND: u32 = u32::MAX;

impl AttributeTexture {
    /// The texture for attribute `name`, not yet bound to any shape.
    pub(crate) fn new(name: String, scale: f32) -> Self {
        Self {
            name,
            scale,
            bound: Vec::new(),
        }
    }

    /// The attribute's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The factor applied to the attribute's value.
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// The attribute at `at` (a one-channel attribute in all three components), times the
    /// scale; zero on a shape the texture is not bound to.
    #[inline]
    pub fn eval(&self, shapes: &[Shape], at: &TexturePoint) -> Vec3 {
        let k = self
            .bound
            .get(at.shape as usize)
            .copied()
            .unwrap_or(UNBOUND);
        match shapes.get(at.shape as usize) {
            Some(Shape::Mesh(m)) if k != UNBOUND => {
                m.eval_attribute(k as usize, at.prim, at.bary) * self.scale
            }
            _ => Vec3::ZERO,
        }
    }

    /// Points the texture at shape `shape`'s attribute, checking that a lookup as `scalar`
    /// (a one-channel read) or as a colour can read it. The error says what the mesh has.
    fn bind(&mut self, shape: u32, s: &Shape, scalar: bool, param: &str) -> Result<(), String> {
        let what = format!(
            "texture 'mesh_attribute' \"{}\" (the material's {param})",
            self.name
        );
        let Shape::Mesh(m) = s else {
            return Err(format!(
                "{what}: the shape is not a mesh, and only meshes have attributes"
            ));
        };
        let attributes = m.attributes();
        let Some(k) = attributes.iter().position(|a| a.name() == self.name) else {
            let names: Vec<&str> = attributes.iter().map(|a| a.name()).collect();
            return Err(if names.is_empty() {
                format!("{what}: the mesh has no attributes")
            } else {
                format!(
                    "{what}: the mesh has no attribute of that name (its attributes: {})",
                    names.join(", ")
                )
            });
        };
        let channels = attributes[k].channels();
        let fits = if scalar {
            channels == 1
        } else {
            channels == 1 || channels == 3
        };
        if !fits {
            return Err(format!(
                "{what}: the attribute has {channels} channels, and the {param} reads {}",
                if scalar { "1" } else { "1 or 3" }
            ));
        }
        let i = shape as usize;
        if self.bound.len() <= i {
            self.bound.resize(i + 1, UNBOUND);
        }
        self.bound[i] = k as u32;
        Ok(())
    }
}

/// Binds the `mesh_attribute` textures among `params` (a material's textures, indices into
/// `textures`) to shape `shape`, `s`, which uses the material. Other textures need nothing.
pub(crate) fn bind(
    textures: &mut [Texture],
    params: &TexturedParams,
    shape: u32,
    s: &Shape,
) -> Result<(), String> {
    // Every slot, named, and whether it is read as one channel; written out field by field so
    // that a slot added to `TexturedParams` must be added here too.
    let TexturedParams {
        base: _,
        diffuse,
        specular,
        transmittance,
        opacity,
        normal,
        alpha_u,
        alpha_v,
        principled,
        bump,
        weight,
    } = *params;
    for (slot, param, scalar) in [
        (diffuse, "reflectance", false),
        (specular, "specular_reflectance", false),
        (transmittance, "specular_transmittance", false),
        (opacity, "opacity", true),
        (normal, "normal map", false),
        (alpha_u, "alpha_u", true),
        (alpha_v, "alpha_v", true),
        (weight, "weight", true),
    ] {
        if let Some(i) = slot
            && let Some(Texture::MeshAttribute(t)) = textures.get_mut(i as usize)
        {
            t.bind(shape, s, scalar, param)?;
        }
    }
    if bump.is_some() && matches!(s, Shape::SdfGrid(_)) {
        return Err(
            "bumpmap on an sdfgrid: the grid has no texture coordinates to bump along".into(),
        );
    }
    if let Some((i, _)) = bump
        && let Some(Texture::MeshAttribute(t)) = textures.get(i as usize)
    {
        return Err(format!(
            "bumpmap: a 'mesh_attribute' texture (\"{}\") has no gradient in texture space to \
             bump with; use a bitmap",
            t.name()
        ));
    }
    for (param, name, i) in principled.bound() {
        if let Some(Texture::MeshAttribute(t)) = textures.get_mut(i as usize) {
            let scalar = param != restir_materials::PrincipledParam::BaseColor;
            t.bind(shape, s, scalar, name)?;
        }
    }
    Ok(())
}
