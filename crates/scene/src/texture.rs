//! Textures: `bitmap` (PNG, JPEG, EXR), `checkerboard` and `mesh_attribute` ([`AttributeTexture`]),
//! decoded once when the scene is built and evaluated at a hit ([`TexturePoint`]: its texture
//! coordinates, or for a mesh attribute its triangle and barycentrics) by
//! [`crate::Scene::bsdf_at`].
//!
//! Conventions are Mitsuba 3's: `uv = (0, 0)` is the top-left corner of the image (the first
//! row), `v` grows downwards; texel centres are at `(i + ½)/size`; lookups are bilinear with
//! repeat wrapping unless the bitmap says otherwise (`filter_type`, [`FilterType`]; `wrap_mode`,
//! [`WrapMode`]). OBJ files count `v` from the bottom, so the OBJ reader flips it (as Mitsuba's
//! does); PLY and `.serialized` texture coordinates are used as stored.

use std::path::Path;

use glam::{Vec2, Vec3};
use restir_image::{Image, IntegerEncoding};
use serde::{Deserialize, Serialize};

mod attribute;
mod lookup;
pub(crate) use attribute::bind;
pub use attribute::{AttributeTexture, TexturePoint};
pub use lookup::{FilterType, WrapMode};
use restir_geometry::Shape;

/// The `uv` transform of a texture: `uv' = uv · scale + offset` (Mitsuba 0.6 `uscale`/`vscale`/
/// `uoffset`/`voffset`, Mitsuba 3 `to_uv` with scale and translate).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct UvTransform {
    /// Per-axis scale.
    pub scale: Vec2,
    /// Offset added after scaling.
    pub offset: Vec2,
}

impl Default for UvTransform {
    fn default() -> Self {
        Self {
            scale: Vec2::ONE,
            offset: Vec2::ZERO,
        }
    }
}

impl UvTransform {
    /// Applies the transform.
    #[inline]
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        uv * self.scale + self.offset
    }
}

/// A texture as the scene file describes it (file not yet read). In RON:
/// `Bitmap(filename: "wood.png")` (optional `raw: true`, `uv: (scale: (4, 4), offset: (0, 0))`),
/// `Checkerboard(color0: (1, 1, 1), color1: (0, 0, 0))` (defaults 0.4 and 0.2, as Mitsuba) or
/// `MeshAttribute(name: "vertex_color")` (optional `scale: 0.5`; the attribute of a PLY mesh).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum TextureDesc {
    /// An image file, relative to the scene file.
    Bitmap {
        /// Path.
        filename: String,
        /// `raw = true`: 8-bit values are used as they are, not sRGB-decoded.
        #[serde(default)]
        raw: bool,
        /// uv transform.
        #[serde(default)]
        uv: UvTransform,
        /// What a lookup outside `[0, 1)` reads (Mitsuba's `wrap_mode`, default repeat).
        #[serde(default)]
        wrap: WrapMode,
        /// Interpolation between texels (Mitsuba's `filter_type`, default bilinear).
        #[serde(default)]
        filter: FilterType,
    },
    /// Two colours alternating in a 2×2 pattern per unit square of (transformed) uv.
    Checkerboard {
        /// Colour where `u mod 1` and `v mod 1` are on the same side of ½.
        #[serde(default = "checker0")]
        color0: [f32; 3],
        /// The other colour.
        #[serde(default = "checker1")]
        color1: [f32; 3],
        /// uv transform.
        #[serde(default)]
        uv: UvTransform,
    },
    /// The named attribute of the mesh that was hit (Mitsuba's `mesh_attribute`): `vertex_…`
    /// interpolated across the triangle, `face_…` constant on it; PLY files carry attributes.
    MeshAttribute {
        /// The attribute's name, starting with `vertex_` or `face_`.
        name: String,
        /// A factor on the attribute's value (Mitsuba's default 1).
        #[serde(default = "unit_scale")]
        scale: f32,
    },
}

fn unit_scale() -> f32 {
    1.0
}

fn checker0() -> [f32; 3] {
    crate::desc::defaults::CHECKER_COLOR0
}
fn checker1() -> [f32; 3] {
    crate::desc::defaults::CHECKER_COLOR1
}

/// A decoded texture.
#[derive(Clone, Debug)]
pub enum Texture {
    /// Linear RGB texels, rows top to bottom, filtered and wrapped as `filter` and `wrap` say.
    Bitmap {
        /// Width in texels.
        width: usize,
        /// Height in texels.
        height: usize,
        /// `width × height` linear RGB texels, the first row at the top of the image.
        texels: Texels,
        /// uv transform.
        uv: UvTransform,
        /// Wrap mode.
        wrap: WrapMode,
        /// Filter.
        filter: FilterType,
    },
    /// See [`TextureDesc::Checkerboard`].
    Checkerboard {
        /// First colour.
        color0: Vec3,
        /// Second colour.
        color1: Vec3,
        /// uv transform.
        uv: UvTransform,
    },
    /// See [`TextureDesc::MeshAttribute`].
    MeshAttribute(AttributeTexture),
}

/// Why a texture could not be made.
#[derive(Debug)]
pub enum TextureError {
    /// The uv transform has a non-finite scale or offset.
    UvNotFinite {
        /// The scale given.
        scale: Vec2,
        /// The offset given.
        offset: Vec2,
    },
    /// A checkerboard colour leaves `[0, 1]`.
    CheckerColor {
        /// `color0` or `color1`.
        name: &'static str,
        /// The colour given.
        color: [f32; 3],
    },
    /// The bitmap's file could not be read.
    Image(restir_image::ImageError),
    /// A mesh attribute's name starts with neither `vertex_` nor `face_`.
    AttributeName(String),
    /// A mesh attribute's scale is not finite.
    AttributeScale(f32),
}

impl std::fmt::Display for TextureError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TextureError::UvNotFinite { scale, offset } => write!(
                f,
                "texture uv transform (scale {scale}, offset {offset}) is not finite"
            ),
            TextureError::CheckerColor { name, color } => {
                write!(
                    f,
                    "checkerboard {name} {color:?} must be finite and non-negative"
                )
            }
            TextureError::Image(e) => write!(f, "{e}"),
            TextureError::AttributeName(n) => write!(
                f,
                "mesh_attribute texture: the name \"{n}\" must start with \"vertex_\" or \"face_\""
            ),
            TextureError::AttributeScale(s) => {
                write!(f, "mesh_attribute texture: scale {s} is not finite")
            }
        }
    }
}

impl std::error::Error for TextureError {}

impl Texture {
    /// Reads the files a description names; `base_dir` resolves relative paths.
    pub fn load(desc: &TextureDesc, base_dir: &Path) -> Result<Texture, TextureError> {
        let uv = match desc {
            TextureDesc::Bitmap { uv, .. } | TextureDesc::Checkerboard { uv, .. } => uv,
            TextureDesc::MeshAttribute { name, scale } => return mesh_attribute(name, *scale),
        };
        if !(uv.scale.is_finite() && uv.offset.is_finite()) {
            return Err(TextureError::UvNotFinite {
                scale: uv.scale,
                offset: uv.offset,
            });
        }
        if let TextureDesc::Checkerboard { color0, color1, .. } = desc {
            for (name, c) in [("color0", color0), ("color1", color1)] {
                // The parameter it is bound to bounds it further (a reflectance to [0, 1]).
                if !c.iter().all(|x| x.is_finite() && *x >= 0.0) {
                    return Err(TextureError::CheckerColor { name, color: *c });
                }
            }
        }
        match desc {
            TextureDesc::Checkerboard { color0, color1, uv } => Ok(Texture::Checkerboard {
                color0: Vec3::from(*color0),
                color1: Vec3::from(*color1),
                uv: *uv,
            }),
            TextureDesc::MeshAttribute { name, scale } => mesh_attribute(name, *scale),
            TextureDesc::Bitmap {
                filename,
                raw,
                uv,
                wrap,
                filter,
            } => {
                let path = base_dir.join(filename);
                let (width, height, texels) =
                    read_image(&path, *raw).map_err(TextureError::Image)?;
                Ok(Texture::Bitmap {
                    width,
                    height,
                    texels: Texels::new(texels, *raw),
                    uv: *uv,
                    wrap: *wrap,
                    filter: *filter,
                })
            }
        }
    }

    /// The texture's value at lookup point `at` (what a material reads): a mesh attribute's
    /// value there, or [`Texture::eval`] at its texture coordinates.
    #[inline]
    pub fn eval_at(&self, shapes: &[Shape], at: &TexturePoint) -> Vec3 {
        match self {
            Texture::MeshAttribute(a) => a.eval(shapes, at),
            _ => self.eval(at.uv),
        }
    }

    /// The texture's scalar value at `at`, as Mitsuba's `eval_1`: a (one-channel) mesh
    /// attribute's value, or [`Texture::eval_1`] at the texture coordinates.
    #[inline]
    pub fn eval_1_at(&self, shapes: &[Shape], at: &TexturePoint) -> f32 {
        match self {
            Texture::MeshAttribute(a) => a.eval(shapes, at).x,
            _ => self.eval_1(at.uv),
        }
    }

    /// The texture's value at surface coordinates `uv` (`v = 0` is the image's top row, as in
    /// Mitsuba 3). A mesh attribute, which needs a hit ([`Texture::eval_at`]), reads zero.
    pub fn eval(&self, uv: Vec2) -> Vec3 {
        match self {
            Texture::MeshAttribute(_) => Vec3::ZERO,
            Texture::Checkerboard {
                color0,
                color1,
                uv: t,
            } => {
                if same_half(t.apply(uv)) {
                    *color0
                } else {
                    *color1
                }
            }
            Texture::Bitmap {
                width,
                height,
                texels,
                uv: t,
                wrap,
                filter,
            } => lookup::lookup(texels, (*width, *height), t.apply(uv), *wrap, *filter),
        }
    }

    /// The texture's scalar value at `uv`, as Mitsuba's `eval_1` (what a mask's opacity or a
    /// microfacet roughness reads): the luminance of [`Texture::eval`], except that Mitsuba's
    /// checkerboard puts its colours the other way round in its scalar lookup (`color0` where
    /// exactly one of `u`, `v` has a fractional part above ½), which is followed here.
    pub fn eval_1(&self, uv: Vec2) -> f32 {
        match self {
            Texture::Checkerboard {
                color0,
                color1,
                uv: t,
            } => {
                let c = if !same_half(t.apply(uv)) {
                    color0
                } else {
                    color1
                };
                restir_sampling::luminance(*c)
            }
            Texture::Bitmap { .. } => restir_sampling::luminance(self.eval(uv)),
            Texture::MeshAttribute(_) => 0.0,
        }
    }

    /// The gradient of [`Texture::eval_1`] in `(u, v)`, as Mitsuba's `eval_1_grad` (what a
    /// `bumpmap` reads): for a bitmap the derivative of its bilinear lookup of the luminance
    /// (zero with the nearest filter), through the `uv` transform; `None` for a checkerboard,
    /// whose gradient Mitsuba does not define.
    pub fn eval_1_grad(&self, uv: Vec2) -> Option<Vec2> {
        match self {
            // A checkerboard's gradient Mitsuba does not define; a mesh attribute's is not one in
            // texture space.
            Texture::Checkerboard { .. } | Texture::MeshAttribute(_) => None,
            Texture::Bitmap {
                width,
                height,
                texels,
                uv: t,
                wrap,
                filter,
            } => Some(
                lookup::lookup_grad(texels, (*width, *height), t.apply(uv), *wrap, *filter)
                    * t.scale,
            ),
        }
    }

    /// The largest value per channel (of the texels, or the checkerboard's two colours); zero for
    /// a mesh attribute, whose values are the meshes'.
    pub fn max(&self) -> Vec3 {
        match self {
            Texture::MeshAttribute(_) => Vec3::ZERO,
            Texture::Checkerboard { color0, color1, .. } => color0.max(*color1),
            Texture::Bitmap { texels, .. } => {
                (0..texels.len()).fold(Vec3::ZERO, |m, i| m.max(texels.get(i)))
            }
        }
    }

    /// The mean texel value (the average reflectance of a bitmap, or the checkerboard's); zero
    /// for a mesh attribute, whose values are the meshes'.
    pub fn mean(&self) -> Vec3 {
        match self {
            Texture::MeshAttribute(_) => Vec3::ZERO,
            Texture::Checkerboard { color0, color1, .. } => 0.5 * (*color0 + *color1),
            Texture::Bitmap { texels, .. } => {
                let n = texels.len();
                (0..n).map(|i| texels.get(i)).sum::<Vec3>() / n.max(1) as f32
            }
        }
    }
}

/// A `mesh_attribute` texture, not yet bound to shapes ([`AttributeTexture`]).
fn mesh_attribute(name: &str, scale: f32) -> Result<Texture, TextureError> {
    if restir_geometry::AttributeRate::of_name(name).is_none() {
        return Err(TextureError::AttributeName(name.into()));
    }
    if !scale.is_finite() {
        return Err(TextureError::AttributeScale(scale));
    }
    Ok(Texture::MeshAttribute(AttributeTexture::new(
        name.into(),
        scale,
    )))
}

/// A bitmap's texels. Images read from 8-bit files hold at most 256 values per channel (the
/// decoded codes 0–255), so they are kept as one byte per channel and the table of the 256
/// values: a third of the memory of three floats, so more of a scene's textures stay in cache,
/// and exactly the same values. Anything else (EXR, HDR, 16-bit files) stays in floats.
#[derive(Clone, Debug)]
pub enum Texels {
    /// Linear RGB floats.
    Float(Vec<Vec3>),
    /// Codes into `levels`, three per texel (the fourth byte is padding).
    Levels {
        /// The linear value of each code.
        levels: Box<[f32; 256]>,
        /// Per texel, the codes of red, green and blue.
        codes: Vec<[u8; 4]>,
    },
}

impl Texels {
    /// The texels `values` (linear, as the image reader returns them), in bytes when every channel
    /// value is the decoding of an 8-bit code (sRGB, or linear when `raw`) as the image reader
    /// decodes it, bit for bit.
    pub fn new(values: Vec<Vec3>, raw: bool) -> Self {
        let mut levels = Box::new([0.0f32; 256]);
        for (k, l) in levels.iter_mut().enumerate() {
            // The image reader's 8-bit conversion (`image`: code / 255), then its decoding.
            let c = k as f32 / 255.0;
            *l = if raw {
                c
            } else {
                restir_image::srgb::decode(c)
            };
        }
        // An open-addressing table from a level's bits to its code.
        const SLOTS: usize = 1024;
        let slot = |bits: u32| (bits.wrapping_mul(0x9E37_79B9) >> 22) as usize;
        let mut table = [(u32::MAX, 0u8); SLOTS];
        for (k, l) in levels.iter().enumerate() {
            let mut i = slot(l.to_bits());
            while table[i].0 != u32::MAX {
                i = (i + 1) % SLOTS;
            }
            table[i] = (l.to_bits(), k as u8);
        }
        let code = |v: f32| -> Option<u8> {
            let bits = v.to_bits();
            let mut i = slot(bits);
            loop {
                match table[i] {
                    (b, k) if b == bits => return Some(k),
                    (u32::MAX, _) => return None,
                    _ => i = (i + 1) % SLOTS,
                }
            }
        };
        let codes: Option<Vec<[u8; 4]>> = values
            .iter()
            .map(|t| Some([code(t.x)?, code(t.y)?, code(t.z)?, 0]))
            .collect();
        match codes {
            Some(codes) => Texels::Levels { levels, codes },
            None => Texels::Float(values),
        }
    }

    /// Number of texels.
    pub fn len(&self) -> usize {
        match self {
            Texels::Float(v) => v.len(),
            Texels::Levels { codes, .. } => codes.len(),
        }
    }

    /// Whether there are no texels.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Texel `i`.
    #[inline(always)]
    pub fn get(&self, i: usize) -> Vec3 {
        match self {
            Texels::Float(v) => v[i],
            Texels::Levels { levels, codes } => {
                let [r, g, b, _] = codes[i];
                Vec3::new(levels[r as usize], levels[g as usize], levels[b as usize])
            }
        }
    }
}

/// Reads an image file as linear RGB texels, the first row at the top
/// ([`restir_image::Image::read`]: PNG/JPEG sRGB-decoded unless `raw`, EXR and Radiance HDR linear).
/// Also used for environment maps.
pub(crate) fn read_image(
    path: &Path,
    raw: bool,
) -> Result<(usize, usize, Vec<Vec3>), restir_image::ImageError> {
    let encoding = if raw {
        IntegerEncoding::Raw
    } else {
        IntegerEncoding::Srgb
    };
    let img = Image::read(path, encoding)?;
    Ok((img.width as usize, img.height as usize, img.pixels))
}

/// Whether the fractional parts of both coordinates of `p` lie on the same side of ½ (the
/// checkerboard's `color0` squares in its colour lookup).
#[inline]
fn same_half(p: Vec2) -> bool {
    let (u, v) = (p.x - p.x.floor(), p.y - p.y.floor());
    (u > 0.5) == (v > 0.5)
}

#[cfg(test)]
mod tests;
