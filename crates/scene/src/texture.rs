//! Textures: `bitmap` (PNG, JPEG, EXR) and `checkerboard`, decoded once when the scene is built
//! and evaluated at a hit's texture coordinates by [`crate::Scene::bsdf_at`].
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

mod lookup;
pub use lookup::{FilterType, WrapMode};

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
/// `Bitmap(filename: "wood.png")` (optional `raw: true`, `uv: (scale: (4, 4), offset: (0, 0))`)
/// or `Checkerboard(color0: (1, 1, 1), color1: (0, 0, 0))` (defaults 0.4 and 0.2, as Mitsuba).
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
}

impl std::fmt::Display for TextureError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TextureError::UvNotFinite { scale, offset } => write!(
                f,
                "texture uv transform (scale {scale}, offset {offset}) is not finite"
            ),
            TextureError::CheckerColor { name, color } => {
                write!(f, "checkerboard {name} {color:?} must lie in [0, 1]")
            }
            TextureError::Image(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for TextureError {}

impl Texture {
    /// Reads the files a description names; `base_dir` resolves relative paths.
    pub fn load(desc: &TextureDesc, base_dir: &Path) -> Result<Texture, TextureError> {
        let uv = match desc {
            TextureDesc::Bitmap { uv, .. } | TextureDesc::Checkerboard { uv, .. } => uv,
        };
        if !(uv.scale.is_finite() && uv.offset.is_finite()) {
            return Err(TextureError::UvNotFinite {
                scale: uv.scale,
                offset: uv.offset,
            });
        }
        if let TextureDesc::Checkerboard { color0, color1, .. } = desc {
            for (name, c) in [("color0", color0), ("color1", color1)] {
                if !c.iter().all(|x| (0.0..=1.0).contains(x)) {
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

    /// The texture's value at surface coordinates `uv` (`v = 0` is the image's top row, as in
    /// Mitsuba 3).
    pub fn eval(&self, uv: Vec2) -> Vec3 {
        match self {
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
        }
    }

    /// The gradient of [`Texture::eval_1`] in `(u, v)`, as Mitsuba's `eval_1_grad` (what a
    /// `bumpmap` reads): for a bitmap the derivative of its bilinear lookup of the luminance
    /// (zero with the nearest filter), through the `uv` transform; `None` for a checkerboard,
    /// whose gradient Mitsuba does not define.
    pub fn eval_1_grad(&self, uv: Vec2) -> Option<Vec2> {
        match self {
            Texture::Checkerboard { .. } => None,
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

    /// The mean texel value (the average reflectance of a bitmap, or the checkerboard's).
    pub fn mean(&self) -> Vec3 {
        match self {
            Texture::Checkerboard { color0, color1, .. } => 0.5 * (*color0 + *color1),
            Texture::Bitmap { texels, .. } => {
                let n = texels.len();
                (0..n).map(|i| texels.get(i)).sum::<Vec3>() / n.max(1) as f32
            }
        }
    }
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
mod tests {
    use super::*;
    use restir_image::srgb::decode as srgb_to_linear;

    /// 8-bit texels are kept as codes with exactly the values the reader decoded; other values
    /// stay floats.
    #[test]
    fn texels_in_bytes_hold_the_same_values() {
        for raw in [false, true] {
            let level = |k: u8| {
                let c = k as f32 / 255.0;
                if raw {
                    c
                } else {
                    restir_image::srgb::decode(c)
                }
            };
            let values: Vec<Vec3> = (0..=255u8)
                .map(|k| Vec3::new(level(k), level(255 - k), level(k / 2)))
                .collect();
            let t = Texels::new(values.clone(), raw);
            assert!(matches!(t, Texels::Levels { .. }), "raw {raw}");
            assert_eq!(t.len(), values.len());
            for (i, v) in values.iter().enumerate() {
                assert_eq!(
                    t.get(i).to_array().map(f32::to_bits),
                    v.to_array().map(f32::to_bits)
                );
            }
            // One value that is no 8-bit level (a 16-bit or float image): floats.
            let mut other = values.clone();
            other[7].y = 0.123_456_7;
            let t = Texels::new(other.clone(), raw);
            assert!(matches!(t, Texels::Float(_)), "raw {raw}");
            assert_eq!(t.get(7), other[7]);
        }
    }

    #[test]
    fn checkerboard_pattern_and_scale() {
        let t = Texture::Checkerboard {
            color0: Vec3::ONE,
            color1: Vec3::ZERO,
            uv: UvTransform {
                scale: Vec2::splat(2.0),
                offset: Vec2::ZERO,
            },
        };
        assert_eq!(t.eval(Vec2::new(0.1, 0.1)), Vec3::ONE);
        assert_eq!(t.eval(Vec2::new(0.3, 0.1)), Vec3::ZERO);
        assert_eq!(t.eval(Vec2::new(0.3, 0.3)), Vec3::ONE);
        assert_eq!(t.eval(Vec2::new(-0.1, 0.1)), Vec3::ZERO);
        assert_eq!(t.mean(), Vec3::splat(0.5));
    }

    fn temp_dir(tag: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("restir-tex-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Checkerboard values agree with Mitsuba 3's at points read off its `checkerboard` (also for
    /// negative coordinates and on the ½ lines), with a uv offset.
    #[test]
    fn checkerboard_matches_mitsuba_and_offsets() {
        let t = Texture::Checkerboard {
            color0: Vec3::X,
            color1: Vec3::Z,
            uv: UvTransform::default(),
        };
        for (u, v, want) in [
            (0.25, 0.25, Vec3::X),
            (0.75, 0.25, Vec3::Z),
            (0.25, 0.75, Vec3::Z),
            (0.75, 0.75, Vec3::X),
            (-0.25, 0.25, Vec3::Z),
            (-0.75, -0.25, Vec3::Z),
            (1.25, 0.25, Vec3::X),
            (0.5, 0.25, Vec3::X),
            (0.25, 0.5, Vec3::X),
        ] {
            assert_eq!(t.eval(Vec2::new(u, v)), want, "({u}, {v})");
        }
        let shifted = Texture::Checkerboard {
            color0: Vec3::X,
            color1: Vec3::Z,
            uv: UvTransform {
                scale: Vec2::ONE,
                offset: Vec2::new(0.5, 0.0),
            },
        };
        assert_eq!(shifted.eval(Vec2::new(0.25, 0.25)), Vec3::Z);
    }

    /// `uv = (0, 0)` is the image's top-left corner (Mitsuba 3: its bitmap at uv (0.25, 0.25)
    /// of a 2×2 image is the first texel of the first row); scale and offset apply before the
    /// lookup; lookups repeat.
    #[test]
    fn bitmap_orientation_scale_offset_and_wrap() {
        let dir = temp_dir("orient");
        // Row 0 (top): red, green; row 1: blue, white. Raw, so values are exact.
        let img =
            image::RgbImage::from_raw(2, 2, vec![255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255])
                .unwrap();
        img.save(dir.join("q.png")).unwrap();
        let load = |scale: Vec2, offset: Vec2| {
            let desc = TextureDesc::Bitmap {
                filename: "q.png".into(),
                raw: true,
                uv: UvTransform { scale, offset },
                wrap: WrapMode::Repeat,
                filter: FilterType::Bilinear,
            };
            Texture::load(&desc, &dir).unwrap()
        };
        let t = load(Vec2::ONE, Vec2::ZERO);
        let (red, green, blue) = (Vec3::X, Vec3::Y, Vec3::Z);
        assert_eq!(t.eval(Vec2::new(0.25, 0.25)), red);
        assert_eq!(t.eval(Vec2::new(0.75, 0.25)), green);
        assert_eq!(t.eval(Vec2::new(0.25, 0.75)), blue);
        assert_eq!(t.eval(Vec2::new(0.75, 0.75)), Vec3::ONE);
        // Repeat: one period further in each direction (and negative) is the same.
        assert_eq!(t.eval(Vec2::new(1.25, -0.75)), red);
        assert_eq!(t.eval(Vec2::new(-1.25, 2.25)), green);
        // Bilinear: the centre of the image is the mean of the four texels.
        let centre = t.eval(Vec2::splat(0.5));
        assert!((centre - Vec3::new(0.5, 0.5, 0.5)).abs().max_element() < 1e-6);
        // Halfway between the two texel centres of the top row.
        let top = t.eval(Vec2::new(0.5, 0.25));
        assert!((top - Vec3::new(0.5, 0.5, 0.0)).abs().max_element() < 1e-6);
        // uv' = uv · scale + offset.
        let scaled = load(Vec2::splat(2.0), Vec2::ZERO);
        assert_eq!(scaled.eval(Vec2::new(0.375, 0.125)), green);
        assert_eq!(scaled.eval(Vec2::new(0.625, 0.125)), red);
        let offset = load(Vec2::ONE, Vec2::new(0.5, 0.5));
        assert_eq!(offset.eval(Vec2::new(0.25, 0.25)), Vec3::ONE);
        assert_eq!(offset.eval(Vec2::new(0.75, 0.75)), red);
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// `wrap_mode` mirror and clamp, and `filter_type` nearest, on the same 2×2 image.
    #[test]
    fn bitmap_mirror_clamp_and_nearest() {
        let dir = temp_dir("modes");
        let img =
            image::RgbImage::from_raw(2, 2, vec![255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255])
                .unwrap();
        img.save(dir.join("q.png")).unwrap();
        let load = |wrap: WrapMode, filter: FilterType| {
            let desc = TextureDesc::Bitmap {
                filename: "q.png".into(),
                raw: true,
                uv: UvTransform::default(),
                wrap,
                filter,
            };
            Texture::load(&desc, &dir).unwrap()
        };
        let (red, green, blue) = (Vec3::X, Vec3::Y, Vec3::Z);
        // Mirror: just right of the image is its right column again, then the left one.
        let m = load(WrapMode::Mirror, FilterType::Bilinear);
        assert_eq!(m.eval(Vec2::new(1.25, 0.25)), green);
        assert_eq!(m.eval(Vec2::new(1.75, 0.25)), red);
        assert_eq!(m.eval(Vec2::new(-0.25, 0.75)), blue);
        // Bilinear across the mirrored edge: both texels are the edge texel.
        assert_eq!(m.eval(Vec2::new(1.0, 0.25)), green);
        // Clamp: the edge texels extend outwards.
        let c = load(WrapMode::Clamp, FilterType::Bilinear);
        assert_eq!(c.eval(Vec2::new(7.0, -3.0)), green);
        assert_eq!(c.eval(Vec2::new(-7.0, 9.0)), blue);
        // Nearest: no blending, whichever texel the point is in.
        let n = load(WrapMode::Repeat, FilterType::Nearest);
        assert_eq!(n.eval(Vec2::new(0.49, 0.49)), red);
        assert_eq!(n.eval(Vec2::new(0.51, 0.49)), green);
        assert_eq!(n.eval(Vec2::new(1.51, -0.49)), Vec3::ONE);
        let r = load(WrapMode::Repeat, FilterType::Bilinear);
        assert_ne!(r.eval(Vec2::new(1.0, 0.25)), green);
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// 8-bit values go through the exact sRGB curve (both branches), unless `raw`.
    #[test]
    fn srgb_decoding_of_8_bit_values() {
        let dir = temp_dir("srgb");
        let codes = [0u8, 5, 10, 11, 64, 128, 200, 255];
        let img = image::GrayImage::from_raw(codes.len() as u32, 1, codes.to_vec()).unwrap();
        img.save(dir.join("g.png")).unwrap();
        let desc = TextureDesc::Bitmap {
            filename: "g.png".into(),
            raw: false,
            uv: UvTransform::default(),
            wrap: WrapMode::default(),
            filter: FilterType::default(),
        };
        let t = Texture::load(&desc, &dir).unwrap();
        let n = codes.len() as f32;
        for (i, &c) in codes.iter().enumerate() {
            let x = c as f32 / 255.0;
            let want = if x <= 0.04045 {
                x / 12.92
            } else {
                ((x + 0.055) / 1.055).powf(2.4)
            };
            // At the texel centre, bilinear filtering returns the texel itself.
            let got = t.eval(Vec2::new((i as f32 + 0.5) / n, 0.5));
            assert!(
                (got - Vec3::splat(want)).abs().max_element() < 1e-6,
                "code {c}: {got} vs {want}"
            );
        }
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn bad_texture_parameters_are_errors() {
        let bad = TextureDesc::Checkerboard {
            color0: [1.5, 0.0, 0.0],
            color1: [0.0; 3],
            uv: UvTransform::default(),
        };
        assert!(
            Texture::load(&bad, Path::new("."))
                .unwrap_err()
                .to_string()
                .contains("color0")
        );
        let bad = TextureDesc::Checkerboard {
            color0: [0.5; 3],
            color1: [0.0; 3],
            uv: UvTransform {
                scale: Vec2::new(f32::NAN, 1.0),
                offset: Vec2::ZERO,
            },
        };
        assert!(
            Texture::load(&bad, Path::new("."))
                .unwrap_err()
                .to_string()
                .contains("not finite")
        );
    }

    #[test]
    fn png_is_srgb_decoded_and_bilinear() {
        let dir = std::env::temp_dir().join(format!("restir-tex-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // 2×1 image: black | sRGB 188 (≈ linear 0.5).
        let img = image::RgbImage::from_raw(2, 1, vec![0, 0, 0, 188, 188, 188]).unwrap();
        img.save(dir.join("t.png")).unwrap();
        let desc = TextureDesc::Bitmap {
            filename: "t.png".into(),
            raw: false,
            uv: UvTransform::default(),
            wrap: WrapMode::default(),
            filter: FilterType::default(),
        };
        let t = Texture::load(&desc, &dir).unwrap();
        let lin = srgb_to_linear(188.0 / 255.0);
        assert!((lin - 0.5).abs() < 0.01);
        // Texel centres at u = 0.25 and 0.75; halfway between is the average.
        assert!((t.eval(Vec2::new(0.75, 0.5)).x - lin).abs() < 1e-5);
        assert!(t.eval(Vec2::new(0.25, 0.5)).x.abs() < 1e-6);
        assert!((t.eval(Vec2::new(0.5, 0.5)).x - 0.5 * lin).abs() < 1e-5);
        // Wrapping: u = 0 is halfway between the last and the first texel.
        assert!((t.eval(Vec2::new(0.0, 0.5)).x - 0.5 * lin).abs() < 1e-5);
        let raw = TextureDesc::Bitmap {
            filename: "t.png".into(),
            raw: true,
            uv: UvTransform::default(),
            wrap: WrapMode::default(),
            filter: FilterType::default(),
        };
        let t = Texture::load(&raw, &dir).unwrap();
        assert!((t.eval(Vec2::new(0.75, 0.5)).x - 188.0 / 255.0).abs() < 1e-5);
        // Missing and malformed files are errors.
        let missing = TextureDesc::Bitmap {
            filename: "nope.png".into(),
            raw: false,
            uv: UvTransform::default(),
            wrap: WrapMode::default(),
            filter: FilterType::default(),
        };
        assert!(
            Texture::load(&missing, &dir)
                .unwrap_err()
                .to_string()
                .contains("nope.png")
        );
        std::fs::write(dir.join("bad.png"), b"not a png").unwrap();
        let bad = TextureDesc::Bitmap {
            filename: "bad.png".into(),
            raw: false,
            uv: UvTransform::default(),
            wrap: WrapMode::default(),
            filter: FilterType::default(),
        };
        assert!(Texture::load(&bad, &dir).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
