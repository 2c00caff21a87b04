//! Material descriptions: the models (Mitsuba 3's BSDF plugins of the same names), their
//! roughness and IOR, textures bound to colour parameters, and references from shapes.

use serde::{Deserialize, Serialize};

use super::{TextureDesc, V3, defaults};

/// A material with a name.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NamedMaterial {
    /// The name shapes use.
    pub name: String,
    /// The material.
    pub material: MaterialDesc,
}

/// A microfacet normal distribution (Mitsuba's `distribution`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MicrofacetDesc {
    /// Beckmann (Mitsuba's default).
    #[default]
    Beckmann,
    /// GGX / Trowbridge–Reitz.
    Ggx,
}

/// A conductor's complex IOR: Mitsuba's `material` preset or explicit `eta`/`k`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConductorIorDesc {
    /// A named metal (`Au`, `Ag`, `Cu`, `Al`, `Cr`, …, `none` = perfect mirror); an error when
    /// combined with `eta` or `k`. Default: `none` unless `eta`/`k` are given.
    #[serde(default)]
    pub material: Option<String>,
    /// Real part of the IOR per channel (default 0).
    #[serde(default)]
    pub eta: Option<V3>,
    /// Imaginary part per channel (default 1).
    #[serde(default)]
    pub k: Option<V3>,
}

/// Microfacet roughness: isotropic `alpha`, or `alpha_u` and `alpha_v` together.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoughnessDesc {
    /// Normal distribution (default Beckmann).
    #[serde(default)]
    pub distribution: MicrofacetDesc,
    /// Isotropic roughness (Mitsuba `alpha`, default 0.1; clamped to at least 1e-4).
    #[serde(default = "defaults::alpha")]
    pub alpha: f32,
    /// Anisotropic roughness along the tangent; needs `alpha_v` and replaces `alpha`.
    #[serde(default)]
    pub alpha_u: Option<f32>,
    /// Anisotropic roughness along the bitangent; needs `alpha_u`.
    #[serde(default)]
    pub alpha_v: Option<f32>,
}

impl Default for RoughnessDesc {
    fn default() -> Self {
        Self {
            distribution: MicrofacetDesc::Beckmann,
            alpha: defaults::ALPHA,
            alpha_u: None,
            alpha_v: None,
        }
    }
}

/// A surface material. Every model and default is Mitsuba 3's plugin of the same name (see
/// `docs/SCENES.md`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MaterialDesc {
    /// Lambertian reflection, black from the back.
    Diffuse {
        /// Albedo in `[0, 1]`.
        reflectance: V3,
    },
    /// Smooth conductor (a delta mirror with the conductor Fresnel term), black from the back.
    Conductor {
        /// Complex IOR (default: `none`, a perfect mirror).
        #[serde(default)]
        ior: ConductorIorDesc,
        /// Multiplier in `[0, 1]` (default 1).
        #[serde(default = "defaults::specular")]
        specular_reflectance: V3,
    },
    /// Rough conductor (microfacet), black from the back.
    RoughConductor {
        /// Complex IOR (default: `none`, a perfect mirror).
        #[serde(default)]
        ior: ConductorIorDesc,
        /// Multiplier in `[0, 1]` (default 1).
        #[serde(default = "defaults::specular")]
        specular_reflectance: V3,
        /// Distribution and roughness.
        #[serde(default)]
        roughness: RoughnessDesc,
    },
    /// Smooth dielectric interface (glass): delta reflection and refraction, from both sides.
    Dielectric {
        /// IOR inside (default 1.5046, `bk7`).
        #[serde(default = "defaults::bk7_ior")]
        int_ior: f32,
        /// IOR outside (default 1.000277, `air`).
        #[serde(default = "defaults::air_ior")]
        ext_ior: f32,
        /// Reflection multiplier in `[0, 1]` (default 1).
        #[serde(default = "defaults::specular")]
        specular_reflectance: V3,
        /// Transmission multiplier in `[0, 1]` (default 1).
        #[serde(default = "defaults::specular")]
        specular_transmittance: V3,
    },
    /// A sheet of glass too thin to offset what it transmits (Mitsuba `thindielectric`):
    /// delta reflection with the reflectance of both faces and the light bounced between them,
    /// transmission straight through, the same from both sides (windows modelled as one face).
    ThinDielectric {
        /// IOR inside (default 1.5046, `bk7`).
        #[serde(default = "defaults::bk7_ior")]
        int_ior: f32,
        /// IOR outside (default 1.000277, `air`).
        #[serde(default = "defaults::air_ior")]
        ext_ior: f32,
        /// Reflection multiplier in `[0, 1]` (default 1).
        #[serde(default = "defaults::specular")]
        specular_reflectance: V3,
        /// Transmission multiplier in `[0, 1]` (default 1).
        #[serde(default = "defaults::specular")]
        specular_transmittance: V3,
    },
    /// Rough dielectric interface (microfacet), from both sides.
    RoughDielectric {
        /// IOR inside (default 1.5046, `bk7`).
        #[serde(default = "defaults::bk7_ior")]
        int_ior: f32,
        /// IOR outside (default 1.000277, `air`).
        #[serde(default = "defaults::air_ior")]
        ext_ior: f32,
        /// Reflection multiplier in `[0, 1]` (default 1).
        #[serde(default = "defaults::specular")]
        specular_reflectance: V3,
        /// Transmission multiplier in `[0, 1]` (default 1).
        #[serde(default = "defaults::specular")]
        specular_transmittance: V3,
        /// Distribution and roughness.
        #[serde(default)]
        roughness: RoughnessDesc,
    },
    /// Diffuse base under a smooth dielectric coating, black from the back.
    Plastic {
        /// IOR of the coating (default 1.49, `polypropylene`).
        #[serde(default = "defaults::polypropylene_ior")]
        int_ior: f32,
        /// IOR outside (default 1.000277, `air`).
        #[serde(default = "defaults::air_ior")]
        ext_ior: f32,
        /// Base albedo in `[0, 1]` (default 0.5).
        #[serde(default = "defaults::diffuse_reflectance")]
        diffuse_reflectance: V3,
        /// Specular multiplier in `[0, 1]` (default 1).
        #[serde(default = "defaults::specular")]
        specular_reflectance: V3,
        /// Mitsuba's `nonlinear` internal-scattering model (default false).
        #[serde(default)]
        nonlinear: bool,
    },
    /// Diffuse base under a rough dielectric coating, black from the back. Isotropic only.
    RoughPlastic {
        /// IOR of the coating (default 1.49, `polypropylene`); must differ from `ext_ior`.
        #[serde(default = "defaults::polypropylene_ior")]
        int_ior: f32,
        /// IOR outside (default 1.000277, `air`).
        #[serde(default = "defaults::air_ior")]
        ext_ior: f32,
        /// Base albedo in `[0, 1]` (default 0.5).
        #[serde(default = "defaults::diffuse_reflectance")]
        diffuse_reflectance: V3,
        /// Specular multiplier in `[0, 1]` (default 1).
        #[serde(default = "defaults::specular")]
        specular_reflectance: V3,
        /// Mitsuba's `nonlinear` internal-scattering model (default false).
        #[serde(default)]
        nonlinear: bool,
        /// Distribution and roughness (`alpha_u`/`alpha_v` are an error).
        #[serde(default)]
        roughness: RoughnessDesc,
    },
    /// Burley's Disney BSDF (Mitsuba `principled`; every weight in `[0, 1]`). One-sided unless
    /// it transmits (`spec_trans > 0`, or a texture gives `spec_trans`).
    Principled {
        /// Base colour in `[0, 1]` (default 0.5).
        #[serde(default = "defaults::diffuse_reflectance")]
        base_color: V3,
        /// Roughness of the main specular lobes (default 0.5).
        #[serde(default = "defaults::principled_roughness")]
        roughness: f32,
        /// Anisotropy (default 0).
        #[serde(default)]
        anisotropic: f32,
        /// Metallic weight (default 0).
        #[serde(default)]
        metallic: f32,
        /// Share of the dielectric part that transmits (default 0).
        #[serde(default)]
        spec_trans: f32,
        /// Tint of the dielectric reflection towards the base colour (default 0).
        #[serde(default)]
        spec_tint: f32,
        /// Sheen weight (default 0).
        #[serde(default)]
        sheen: f32,
        /// Tint of the sheen towards the base colour (default 0).
        #[serde(default)]
        sheen_tint: f32,
        /// Diffuse (0) to fake subsurface (1) (default 0).
        #[serde(default)]
        flatness: f32,
        /// Clearcoat weight (default 0).
        #[serde(default)]
        clearcoat: f32,
        /// Clearcoat glossiness (default 0).
        #[serde(default)]
        clearcoat_gloss: f32,
        /// Relative IOR; not together with `specular` (default: from `specular`).
        #[serde(default)]
        eta: Option<f32>,
        /// Fresnel reflectance control in `[0, 1]`, `η = 2/(1 − √(0.08 specular)) − 1`; not
        /// together with `eta` (default 0.5 when neither is given).
        #[serde(default)]
        specular: Option<f32>,
    },
    /// Burley's thin-sheet BSDF (Mitsuba `principledthin`), the same from both sides.
    PrincipledThin {
        /// Base colour in `[0, 1]` (default 0.5).
        #[serde(default = "defaults::diffuse_reflectance")]
        base_color: V3,
        /// Roughness (default 0.5).
        #[serde(default = "defaults::principled_roughness")]
        roughness: f32,
        /// Anisotropy (default 0).
        #[serde(default)]
        anisotropic: f32,
        /// Specular share, half reflected and half transmitted (default 0).
        #[serde(default)]
        spec_trans: f32,
        /// Tint of the specular reflection towards the base colour (default 0).
        #[serde(default)]
        spec_tint: f32,
        /// Sheen weight (default 0).
        #[serde(default)]
        sheen: f32,
        /// Tint of the sheen towards the base colour (default 0).
        #[serde(default)]
        sheen_tint: f32,
        /// Diffuse (0) to fake subsurface (1) (default 0).
        #[serde(default)]
        flatness: f32,
        /// Diffuse transmission in `[0, 2]` (default 0).
        #[serde(default)]
        diff_trans: f32,
        /// Relative IOR of the sheet, positive (default 1.5).
        #[serde(default = "defaults::principled_thin_eta")]
        eta: f32,
    },
    /// A surface light passes through unchanged (Mitsuba `null`).
    Null,
    /// The wrapped material on both sides (an error around transmitting materials, as in
    /// Mitsuba).
    TwoSided(Box<MaterialDesc>),
    /// Absorbs all light.
    Black,
    /// Mitsuba's `mask`: `material` with probability `opacity`, and otherwise nothing (light
    /// passes straight through); a texture may give the opacity (`Textured` with the parameter
    /// `Opacity` around the mask).
    Mask {
        /// Opacity in `[0, 1]` (default 0.5).
        #[serde(default = "defaults::mask_opacity")]
        opacity: f32,
        /// The material where the surface is there.
        material: Box<MaterialDesc>,
    },
    /// Mitsuba's `normalmap`: `material` in the shading frame perturbed by the normal
    /// `2·normal − 1` (relative to the shading frame; `(0.5, 0.5, 1)` changes nothing); a texture
    /// may give it (`Textured` with the parameter `NormalMap` around this).
    NormalMap {
        /// The raw map value (what a `rawconstant` texture gives).
        #[serde(default = "defaults::flat_normal")]
        normal: V3,
        /// Mirror normals that face away from the viewer (default true).
        #[serde(default = "defaults::yes")]
        flip_invalid_normals: bool,
        /// Apply the shadowing term against the bump terminator (default true).
        #[serde(default = "defaults::yes")]
        use_shadowing_function: bool,
        /// The perturbed material.
        material: Box<MaterialDesc>,
    },
    /// Mitsuba's `bumpmap`: `material` in the shading frame perturbed by the gradient of a
    /// height texture (`Textured` with the parameter `BumpMap` around this gives it; a bitmap,
    /// its luminance), times `scale`.
    BumpMap {
        /// The gradient's multiplier (default 1).
        #[serde(default = "defaults::bump_scale")]
        scale: f32,
        /// Mirror normals that face away from the viewer (default true).
        #[serde(default = "defaults::yes")]
        flip_invalid_normals: bool,
        /// Apply the shadowing term against the bump terminator (default true).
        #[serde(default = "defaults::yes")]
        use_shadowing_function: bool,
        /// The perturbed material.
        material: Box<MaterialDesc>,
    },
    /// Mitsuba's `blendbsdf`: `(1 − weight)·bsdfs.0 + weight·bsdfs.1`. A texture may give the
    /// weight (`Textured` with the parameter `Weight` around this); the two materials'
    /// parameters are constant (a textured component is an error). In RON: `Blend(weight: 0.3,
    /// bsdfs: (Diffuse(reflectance: (0.5, 0.5, 0.5)), Conductor()))`.
    Blend {
        /// The second material's share, in `[0, 1]` (required, as in Mitsuba).
        weight: f32,
        /// The two materials: weight 0 is the first, weight 1 the second.
        bsdfs: Box<(MaterialDesc, MaterialDesc)>,
    },
    /// `material` with some of its colour parameters given by textures, looked up at each
    /// shading point's texture coordinates; the constant values in `material` are unused for
    /// those parameters. In RON: `Textured(material: Diffuse(reflectance: (0.5, 0.5, 0.5)),
    /// textures: [(param: Reflectance, texture: Bitmap(filename: "wood.png"))])`.
    Textured {
        /// The material (any model with the parameters named in `textures`).
        material: Box<MaterialDesc>,
        /// Which parameter each texture replaces.
        textures: Vec<TextureBinding>,
    },
}

impl MaterialDesc {
    /// The material without its textures, and the textures: a wrapper (a mask, a normal map)
    /// around a textured material holds the textures outside itself, also through a
    /// `TwoSided`.
    pub fn split_textures(self) -> (MaterialDesc, Vec<TextureBinding>) {
        match self {
            MaterialDesc::Textured { material, textures } => (*material, textures),
            MaterialDesc::TwoSided(t) => match *t {
                MaterialDesc::Textured { material, textures } => {
                    (MaterialDesc::TwoSided(material), textures)
                }
                t => (MaterialDesc::TwoSided(Box::new(t)), Vec::new()),
            },
            m => (m, Vec::new()),
        }
    }

    /// The material with `textures` bound (itself when there are none).
    pub fn with_textures(self, textures: Vec<TextureBinding>) -> MaterialDesc {
        if textures.is_empty() {
            self
        } else {
            MaterialDesc::Textured {
                material: Box::new(self),
                textures,
            }
        }
    }
}

/// A colour parameter of a material that a texture can provide.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ColorParam {
    /// `Diffuse`'s `reflectance`.
    Reflectance,
    /// The plastics' `diffuse_reflectance`.
    DiffuseReflectance,
    /// `specular_reflectance` (conductors, dielectrics, plastics).
    SpecularReflectance,
    /// The dielectrics' `specular_transmittance`.
    SpecularTransmittance,
    /// A `mask`'s `opacity` (a scalar: a colour texture gives its luminance).
    Opacity,
    /// A `normalmap`'s `normalmap` (raw values, not clamped).
    NormalMap,
    /// A `bumpmap`'s height field (a bitmap; its luminance's gradient).
    BumpMap,
    /// A rough conductor's or rough dielectric's isotropic `alpha` (a scalar: a colour texture
    /// gives its luminance).
    Alpha,
    /// Their `alpha_u` (with `alpha_v`, given as a value or a texture).
    AlphaU,
    /// Their `alpha_v` (with `alpha_u`).
    AlphaV,
    /// A `blendbsdf`'s `weight` (a scalar: a colour texture gives its luminance).
    Weight,
    /// The principled models' `base_color`.
    BaseColor,
    /// The principled models' `roughness` (a scalar, as every principled parameter below).
    Roughness,
    /// `anisotropic`.
    Anisotropic,
    /// `principled`'s `metallic`.
    Metallic,
    /// `spec_trans`.
    SpecTrans,
    /// `spec_tint`.
    SpecTint,
    /// `sheen`.
    Sheen,
    /// `sheen_tint`.
    SheenTint,
    /// `flatness`.
    Flatness,
    /// `principled`'s `clearcoat`.
    Clearcoat,
    /// `principled`'s `clearcoat_gloss`.
    ClearcoatGloss,
    /// `principledthin`'s `diff_trans` (0 to 2).
    DiffTrans,
    /// `principledthin`'s `eta`.
    Eta,
}

impl ColorParam {
    /// The parameter's name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            ColorParam::Reflectance => "reflectance",
            ColorParam::DiffuseReflectance => "diffuse_reflectance",
            ColorParam::SpecularReflectance => "specular_reflectance",
            ColorParam::SpecularTransmittance => "specular_transmittance",
            ColorParam::Opacity => "opacity",
            ColorParam::NormalMap => "normalmap",
            ColorParam::BumpMap => "bumpmap",
            ColorParam::Alpha => "alpha",
            ColorParam::AlphaU => "alpha_u",
            ColorParam::AlphaV => "alpha_v",
            ColorParam::BaseColor => "base_color",
            ColorParam::Roughness => "roughness",
            ColorParam::Anisotropic => "anisotropic",
            ColorParam::Metallic => "metallic",
            ColorParam::SpecTrans => "spec_trans",
            ColorParam::SpecTint => "spec_tint",
            ColorParam::Sheen => "sheen",
            ColorParam::SheenTint => "sheen_tint",
            ColorParam::Flatness => "flatness",
            ColorParam::Clearcoat => "clearcoat",
            ColorParam::ClearcoatGloss => "clearcoat_gloss",
            ColorParam::DiffTrans => "diff_trans",
            ColorParam::Eta => "eta",
            ColorParam::Weight => "weight",
        }
    }

    /// The parameter named `name` (snake_case), if it is one.
    pub fn from_name(name: &str) -> Option<Self> {
        [
            ColorParam::Reflectance,
            ColorParam::DiffuseReflectance,
            ColorParam::SpecularReflectance,
            ColorParam::SpecularTransmittance,
            ColorParam::Opacity,
            ColorParam::NormalMap,
            ColorParam::BumpMap,
            ColorParam::Alpha,
            ColorParam::AlphaU,
            ColorParam::AlphaV,
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
            ColorParam::DiffTrans,
            ColorParam::Eta,
            ColorParam::Weight,
        ]
        .into_iter()
        .find(|p| p.name() == name)
    }
}

impl ColorParam {
    /// The parameter of the principled models this is, if it is one.
    pub fn principled(self) -> Option<restir_materials::PrincipledParam> {
        use restir_materials::PrincipledParam as P;
        Some(match self {
            ColorParam::BaseColor => P::BaseColor,
            ColorParam::Roughness => P::Roughness,
            ColorParam::Anisotropic => P::Anisotropic,
            ColorParam::Metallic => P::Metallic,
            ColorParam::SpecTrans => P::SpecTrans,
            ColorParam::SpecTint => P::SpecTint,
            ColorParam::Sheen => P::Sheen,
            ColorParam::SheenTint => P::SheenTint,
            ColorParam::Flatness => P::Flatness,
            ColorParam::Clearcoat => P::Clearcoat,
            ColorParam::ClearcoatGloss => P::ClearcoatGloss,
            ColorParam::DiffTrans => P::DiffTrans,
            ColorParam::Eta => P::Eta,
            _ => return None,
        })
    }
}

/// A texture bound to a material parameter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureBinding {
    /// The parameter.
    pub param: ColorParam,
    /// The texture.
    pub texture: TextureDesc,
}

/// A shape's material: by name or inline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum MaterialRef {
    /// A material from [`SceneDesc::materials`](super::SceneDesc::materials).
    Ref(String),
    /// An inline material.
    Inline(MaterialDesc),
}
