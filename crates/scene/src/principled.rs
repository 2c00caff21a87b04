//! The principled materials (Mitsuba 3's `principled` and `principledthin`): their descriptions
//! to BSDFs with Mitsuba's defaults and adjustments and this project's range checks, and the
//! textures of their parameters, applied per shading point by [`crate::Scene::bsdf_at`].

use glam::Vec3;
use restir_materials::{Bsdf, Principled, PrincipledParam, PrincipledThin, eta_of_specular};

use crate::desc::{ColorParam, MaterialDesc, TextureBinding, defaults};
use crate::material::MaterialError;
use crate::texture::{Texture, TexturePoint};
use restir_geometry::Shape;

/// A weight outside its range: an error naming the parameter and the range.
fn weight(name: &'static str, value: f32, hi: f32) -> Result<f32, MaterialError> {
    if value.is_finite() && (0.0..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(MaterialError::PrincipledRange {
            name,
            value,
            range: if hi == 1.0 { "[0, 1]" } else { "[0, 2]" },
        })
    }
}

/// The BSDF of a principled material `m` (`None` for another model). `spec_trans_textured`: a
/// texture gives `spec_trans`, which makes the material transmitting as a non-zero constant
/// does (Mitsuba decides from the parameter's presence, not from its values).
pub(crate) fn bsdf(
    m: &MaterialDesc,
    spec_trans_textured: bool,
) -> Option<Result<Bsdf, MaterialError>> {
    Some(match m {
        MaterialDesc::Principled {
            base_color,
            roughness,
            anisotropic,
            metallic,
            spec_trans,
            spec_tint,
            sheen,
            sheen_tint,
            flatness,
            clearcoat,
            clearcoat_gloss,
            eta,
            specular,
        } => (|| {
            let transmits = *spec_trans != 0.0 || spec_trans_textured;
            let eta = match (eta, specular) {
                (Some(_), Some(_)) => return Err(MaterialError::PrincipledEtaAndSpecular),
                (Some(e), None) => {
                    if !(e.is_finite() && *e > 0.0) {
                        return Err(MaterialError::BadIor {
                            name: "eta",
                            value: *e,
                        });
                    }
                    // η = 1 makes no refraction: Mitsuba nudges it when the model transmits.
                    if transmits && *e == 1.0 { 1.001 } else { *e }
                }
                (None, s) => {
                    let s = weight("specular", s.unwrap_or(defaults::PRINCIPLED_SPECULAR), 1.0)?;
                    // specular 0 is η = 1: Mitsuba nudges it when the model transmits.
                    eta_of_specular(if transmits && s == 0.0 { 1e-3 } else { s })
                }
            };
            let spec_trans = weight("spec_trans", *spec_trans, 1.0)?;
            Ok(Bsdf::principled(Principled {
                base_color: unit_color(base_color)?,
                roughness: weight("roughness", *roughness, 1.0)?,
                anisotropic: weight("anisotropic", *anisotropic, 1.0)?,
                metallic: weight("metallic", *metallic, 1.0)?,
                // A placeholder the texture replaces at every point; non-zero so that the
                // material counts as transmitting.
                spec_trans: if spec_trans_textured && spec_trans == 0.0 {
                    1.0
                } else {
                    spec_trans
                },
                spec_tint: weight("spec_tint", *spec_tint, 1.0)?,
                sheen: weight("sheen", *sheen, 1.0)?,
                sheen_tint: weight("sheen_tint", *sheen_tint, 1.0)?,
                flatness: weight("flatness", *flatness, 1.0)?,
                clearcoat: weight("clearcoat", *clearcoat, 1.0)?,
                clearcoat_gloss: weight("clearcoat_gloss", *clearcoat_gloss, 1.0)?,
                eta,
            }))
        })(),
        MaterialDesc::PrincipledThin {
            base_color,
            roughness,
            anisotropic,
            spec_trans,
            spec_tint,
            sheen,
            sheen_tint,
            flatness,
            diff_trans,
            eta,
        } => (|| {
            if !(eta.is_finite() && *eta > 0.0) {
                return Err(MaterialError::BadIor {
                    name: "eta",
                    value: *eta,
                });
            }
            Ok(Bsdf::principled_thin(PrincipledThin {
                base_color: unit_color(base_color)?,
                roughness: weight("roughness", *roughness, 1.0)?,
                anisotropic: weight("anisotropic", *anisotropic, 1.0)?,
                spec_trans: weight("spec_trans", *spec_trans, 1.0)?,
                spec_tint: weight("spec_tint", *spec_tint, 1.0)?,
                sheen: weight("sheen", *sheen, 1.0)?,
                sheen_tint: weight("sheen_tint", *sheen_tint, 1.0)?,
                flatness: weight("flatness", *flatness, 1.0)?,
                diff_trans: weight("diff_trans", *diff_trans, 2.0)?,
                eta: *eta,
            }))
        })(),
        _ => return None,
    })
}

fn unit_color(c: &[f32; 3]) -> Result<Vec3, MaterialError> {
    let v = Vec3::from(*c);
    if !v.is_finite() || v.min_element() < 0.0 || v.max_element() > 1.0 {
        return Err(MaterialError::ColorOutOfRange {
            what: "base_color",
            value: *c,
        });
    }
    Ok(v)
}

/// The parameters of `principled` that textures may give.
pub(crate) const PRINCIPLED_PARAMS: &[ColorParam] = &[
    ColorParam::BaseColor,
    ColorParam::Roughness,
    ColorParam::Anisotropic,
    ColorParam::Metallic,
    ColorParam::SpecTrans,
    ColorParam::SpecTint,
    ColorParam::Sheen,
    ColorParam::SheenTint,
    ColorParam::Flatness,
    ColorParam::Clearcoat,
    ColorParam::ClearcoatGloss,
];

/// The parameters of `principledthin` that textures may give.
pub(crate) const PRINCIPLED_THIN_PARAMS: &[ColorParam] = &[
    ColorParam::BaseColor,
    ColorParam::Roughness,
    ColorParam::Anisotropic,
    ColorParam::SpecTrans,
    ColorParam::SpecTint,
    ColorParam::Sheen,
    ColorParam::SheenTint,
    ColorParam::Flatness,
    ColorParam::DiffTrans,
    ColorParam::Eta,
];

/// A checkerboard's colour outside the range of the parameter it gives: `[0, 1]` for the
/// reflectances, transmittances and opacities, [`PrincipledParam::range`] for the principled
/// parameters (a bitmap's values are clamped to the range at each lookup).
pub(crate) fn check_binding(b: &TextureBinding) -> Result<(), MaterialError> {
    let range = match b.param {
        ColorParam::Reflectance
        | ColorParam::DiffuseReflectance
        | ColorParam::SpecularReflectance
        | ColorParam::SpecularTransmittance
        | ColorParam::Opacity => (0.0, 1.0),
        p => match p.principled() {
            Some(p) => p.range(),
            None => return Ok(()),
        },
    };
    if let crate::texture::TextureDesc::Checkerboard { color0, color1, .. } = &b.texture {
        let (lo, hi) = range;
        for c in [color0, color1] {
            if c.iter().any(|x| !(x.is_finite() && (lo..=hi).contains(x))) {
                return Err(MaterialError::TextureRange {
                    name: b.param.name(),
                    value: *c,
                    range: (lo, hi),
                });
            }
        }
    }
    Ok(())
}

/// The textures of a principled material's parameters: for each [`PrincipledParam`] (in
/// [`PrincipledParam::ALL`]'s order), the index of its texture in the scene's textures.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PrincipledTextures {
    slots: [Option<u32>; PrincipledParam::ALL.len()],
}

impl PrincipledTextures {
    /// Binds texture `texture` to `param`.
    pub fn set(&mut self, param: PrincipledParam, texture: u32) {
        if let Some(i) = PrincipledParam::ALL.iter().position(|p| *p == param) {
            self.slots[i] = Some(texture);
        }
    }

    /// Each textured parameter, its name in scene files, and its texture.
    pub(crate) fn bound(&self) -> impl Iterator<Item = (PrincipledParam, &'static str, u32)> + '_ {
        PrincipledParam::ALL
            .iter()
            .zip(&self.slots)
            .filter_map(|(&param, slot)| {
                let name = PRINCIPLED_PARAMS
                    .iter()
                    .chain(PRINCIPLED_THIN_PARAMS)
                    .find(|c| c.principled() == Some(param))
                    .map_or("a principled parameter", |c| c.name());
                slot.map(|t| (param, name, t))
            })
    }

    /// Whether some parameter has a texture.
    pub fn any(&self) -> bool {
        self.slots.iter().any(Option::is_some)
    }

    /// `bsdf` with the textured parameters looked up at `at` (on `shapes`, which mesh attributes
    /// read): `base_color` by the texture's
    /// colour, the others by its scalar value (Mitsuba's `eval` and `eval_1`), each clamped to
    /// the parameter's range.
    #[inline]
    pub fn apply(
        &self,
        mut bsdf: Bsdf,
        textures: &[Texture],
        shapes: &[Shape],
        at: &TexturePoint,
    ) -> Bsdf {
        for (param, slot) in PrincipledParam::ALL.iter().zip(&self.slots) {
            if let Some(t) = slot {
                let t = &textures[*t as usize];
                let value = if *param == PrincipledParam::BaseColor {
                    t.eval_at(shapes, at)
                } else {
                    Vec3::splat(t.eval_1_at(shapes, at))
                };
                bsdf = bsdf.with_principled(*param, value);
            }
        }
        bsdf
    }
}
