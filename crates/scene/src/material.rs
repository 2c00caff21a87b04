//! Material descriptions to BSDFs: the one conversion from [`MaterialDesc`] to
//! `restir_materials::Bsdf` and the checks that go with it (colours in `[0, 1]`, positive IORs,
//! known conductors, valid roughness, textures only on colour parameters). The XML importer uses
//! it to report a bad material at its line; the builder uses it to make the scene's BSDFs.

use glam::Vec3;
use restir_materials::{Bsdf, Distribution, Microfacet, ReflectanceParams};

use crate::desc::*;

/// Why a material description cannot become a BSDF.
#[derive(Clone, Debug, PartialEq)]
pub enum MaterialError {
    /// A colour parameter outside `[0, 1]` (or not finite).
    ColorOutOfRange {
        /// The parameter (`diffuse reflectance`, `specular_reflectance`, …).
        what: &'static str,
        /// Its value.
        value: V3,
    },
    /// `int_ior` or `ext_ior` not a positive number.
    BadIor {
        /// `int_ior` or `ext_ior`.
        name: &'static str,
        /// Its value.
        value: f32,
    },
    /// A named conductor together with explicit `eta` or `k`.
    ConductorPresetWithEtaK {
        /// The conductor's name.
        name: String,
    },
    /// A conductor name not in the table.
    UnknownConductor {
        /// The name given.
        name: String,
    },
    /// A negative or non-finite conductor `eta` or `k`.
    BadConductorIor {
        /// `eta` or `k`.
        name: &'static str,
        /// Its value.
        value: Vec3,
    },
    /// A negative or non-finite roughness.
    BadRoughness {
        /// `alpha`, `alpha_u` or `alpha_v`.
        name: &'static str,
        /// Its value.
        value: f32,
    },
    /// `alpha_u`/`alpha_v` on an isotropic model.
    Isotropic,
    /// Only one of `alpha_u` and `alpha_v`.
    AlphaPair,
    /// A rough plastic whose coating has the IOR of its surroundings.
    RoughPlasticSameIor,
    /// `twosided` around a transmitting model.
    TwoSidedTransmitting,
    /// A textured material inside a textured material.
    NestedTextured,
    /// A texture for a parameter the model does not have.
    NoSuchParameter {
        /// The parameter textured.
        param: ColorParam,
        /// The model's colour parameters.
        allowed: &'static [ColorParam],
    },
    /// Two textures for one parameter.
    TwoTextures {
        /// The parameter.
        param: ColorParam,
    },
    /// A `mask` directly inside a `mask`.
    NestedMask,
    /// A `mask` opacity outside `[0, 1]` (or not finite).
    BadOpacity {
        /// Its value.
        value: f32,
    },
    /// A `normalmap` around a `mask` or another `normalmap`, or inside a `twosided`.
    NormalMapNesting,
    /// A `normalmap` value that is not finite.
    BadNormal {
        /// Its value.
        value: V3,
    },
    /// A principled parameter outside its range.
    PrincipledRange {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f32,
        /// Its range, as text.
        range: &'static str,
    },
    /// `principled` with both `eta` and `specular`.
    PrincipledEtaAndSpecular,
    /// A checkerboard colour outside the range of the parameter it gives.
    TextureRange {
        /// The parameter.
        name: &'static str,
        /// The colour.
        value: V3,
        /// The parameter's range.
        range: (f32, f32),
    },
    /// A `bumpmap` inside another normal or bump map or a `twosided`, or around a `mask`.
    BumpMapNesting,
    /// A `bumpmap` scale that is not finite.
    BadBumpScale {
        /// Its value.
        value: f32,
    },
    /// A `blendbsdf` weight outside `[0, 1]` (or not finite).
    BadBlendWeight {
        /// Its value.
        value: f32,
    },
    /// A `blendbsdf` component with textured parameters (or a bump map, whose height is one).
    BlendTexturedComponent,
    /// `blendbsdf`s nested deeper than [`MAX_BLEND_DEPTH`].
    BlendTooDeep,
}

/// How many `blendbsdf`s may nest inside one another (each level is one more recursive call
/// in every evaluation).
pub const MAX_BLEND_DEPTH: usize = 8;

impl core::fmt::Display for MaterialError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            MaterialError::ColorOutOfRange { what, value } => {
                write!(f, "{what} {value:?} must lie in [0, 1]")
            }
            MaterialError::BadIor { name, value } => {
                write!(f, "{name} {value} must be a positive number")
            }
            MaterialError::ConductorPresetWithEtaK { name } => write!(
                f,
                "conductor material '{name}' cannot be combined with explicit eta or k"
            ),
            MaterialError::UnknownConductor { name } => write!(
                f,
                "unknown conductor material '{name}' (known: {})",
                restir_materials::ior::conductor_names()
            ),
            MaterialError::BadConductorIor { name, value } => write!(
                f,
                "conductor {name} {value} must be finite and non-negative"
            ),
            MaterialError::BadRoughness { name, value } => write!(
                f,
                "{name} {value} must be a finite non-negative roughness"
            ),
            MaterialError::Isotropic => {
                f.write_str("this material is isotropic: give alpha, not alpha_u/alpha_v")
            }
            MaterialError::AlphaPair => f.write_str("alpha_u and alpha_v must be given together"),
            MaterialError::RoughPlasticSameIor => {
                f.write_str("roughplastic: int_ior must differ from ext_ior")
            }
            MaterialError::TwoSidedTransmitting => f.write_str(
                "twosided cannot wrap a transmitting material (dielectric, roughdielectric, null, principledthin, principled with spec_trans), as in Mitsuba",
            ),
            MaterialError::NestedTextured => {
                f.write_str("a textured material cannot wrap another textured material")
            }
            MaterialError::NoSuchParameter { param, allowed } => {
                let names: Vec<&str> = allowed.iter().map(|p| p.name()).collect();
                write!(
                    f,
                    "texture for '{}': this material has no such parameter (its colour parameters: {})",
                    param.name(),
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    }
                )
            }
            MaterialError::TwoTextures { param } => {
                write!(f, "two textures for '{}'", param.name())
            }
            MaterialError::NestedMask => f.write_str("a mask cannot wrap another mask"),
            MaterialError::BadOpacity { value } => {
                write!(f, "mask opacity {value} must lie in [0, 1]")
            }
            MaterialError::NormalMapNesting => f.write_str(
                "a normalmap may wrap any material but a mask or a normalmap, and only a mask may wrap it (write mask(normalmap(twosided(...))))",
            ),
            MaterialError::BadNormal { value } => {
                write!(f, "normalmap value {value:?} must be finite")
            }
            MaterialError::PrincipledRange { name, value, range } => {
                write!(f, "{name} {value} must lie in {range}")
            }
            MaterialError::PrincipledEtaAndSpecular => f.write_str(
                "give either eta or specular, not both (specular sets the IOR: eta = 2/(1 - sqrt(0.08 specular)) - 1)",
            ),
            MaterialError::TextureRange { name, value, range } => {
                if range.1 == f32::MAX {
                    write!(f, "texture for '{name}': colour {value:?} must be positive")
                } else {
                    write!(
                        f,
                        "texture for '{name}': colour {value:?} must lie in [{}, {}]",
                        range.0, range.1
                    )
                }
            }
            MaterialError::BumpMapNesting => f.write_str(
                "a bumpmap may wrap any material but a mask, a normalmap or a bumpmap, and only a mask may wrap it (write mask(bumpmap(twosided(...))))",
            ),
            MaterialError::BadBumpScale { value } => {
                write!(f, "bumpmap scale {value} must be finite")
            }
            MaterialError::BadBlendWeight { value } => {
                write!(f, "blendbsdf weight {value} must lie in [0, 1]")
            }
            MaterialError::BlendTexturedComponent => f.write_str(
                "a blendbsdf's two bsdfs must have constant parameters: only the weight may be a texture (a textured bsdf or a bumpmap inside a blendbsdf is not supported)",
            ),
            MaterialError::BlendTooDeep => write!(
                f,
                "blendbsdfs nest at most {MAX_BLEND_DEPTH} deep"
            ),
        }
    }
}

impl std::error::Error for MaterialError {}

type Result<T> = core::result::Result<T, MaterialError>;

fn unit_color(what: &'static str, c: &V3) -> Result<Vec3> {
    let v = Vec3::from(*c);
    if !v.is_finite() || v.min_element() < 0.0 || v.max_element() > 1.0 {
        return Err(MaterialError::ColorOutOfRange { what, value: *c });
    }
    Ok(v)
}

fn relative_ior(int_ior: f32, ext_ior: f32) -> Result<f32> {
    for (name, value) in [("int_ior", int_ior), ("ext_ior", ext_ior)] {
        if !(value.is_finite() && value > 0.0) {
            return Err(MaterialError::BadIor { name, value });
        }
    }
    Ok(int_ior / ext_ior)
}

fn conductor_ior(d: &ConductorIorDesc) -> Result<(Vec3, Vec3)> {
    if let Some(name) = &d.material {
        if name != "none" && (d.eta.is_some() || d.k.is_some()) {
            return Err(MaterialError::ConductorPresetWithEtaK { name: name.clone() });
        }
        if d.eta.is_none() && d.k.is_none() {
            return restir_materials::ior::conductor(name)
                .ok_or_else(|| MaterialError::UnknownConductor { name: name.clone() });
        }
    }
    let eta = Vec3::from(d.eta.unwrap_or(defaults::CONDUCTOR_ETA));
    let k = Vec3::from(d.k.unwrap_or(defaults::CONDUCTOR_K));
    for (name, value) in [("eta", eta), ("k", k)] {
        if !value.is_finite() || value.min_element() < 0.0 {
            return Err(MaterialError::BadConductorIor { name, value });
        }
    }
    Ok((eta, k))
}

fn microfacet(r: &RoughnessDesc, anisotropy_allowed: bool) -> Result<Microfacet> {
    let dist = match r.distribution {
        MicrofacetDesc::Beckmann => Distribution::Beckmann,
        MicrofacetDesc::Ggx => Distribution::Ggx,
    };
    let check = |name: &'static str, value: f32| {
        if value.is_finite() && value >= 0.0 {
            Ok(value)
        } else {
            Err(MaterialError::BadRoughness { name, value })
        }
    };
    match (r.alpha_u, r.alpha_v) {
        (None, None) => Ok(Microfacet::new(dist, check("alpha", r.alpha)?)),
        (Some(u), Some(v)) => {
            if !anisotropy_allowed {
                return Err(MaterialError::Isotropic);
            }
            Ok(Microfacet::anisotropic(
                dist,
                check("alpha_u", u)?,
                check("alpha_v", v)?,
            ))
        }
        _ => Err(MaterialError::AlphaPair),
    }
}

/// Checks a material the way [`crate::Scene::build`] would, without keeping the result.
pub(crate) fn check(m: &MaterialDesc) -> Result<()> {
    bsdf(m).map(|_| ())
}

/// The BSDF of a material with its constant parameters (textures are applied per shading point;
/// see [`colors`]).
pub(crate) fn bsdf(m: &MaterialDesc) -> Result<Bsdf> {
    bsdf_in(m, false)
}

/// [`bsdf`] of a material inside a `Textured` that gives its `spec_trans` when
/// `spec_trans_textured` (a principled material then transmits).
fn bsdf_in(m: &MaterialDesc, spec_trans_textured: bool) -> Result<Bsdf> {
    if let Some(b) = crate::principled::bsdf(m, spec_trans_textured) {
        return b;
    }
    let bsdf = |m| bsdf_in(m, spec_trans_textured);
    Ok(match m {
        MaterialDesc::Diffuse { reflectance } => {
            Bsdf::diffuse(unit_color("diffuse reflectance", reflectance)?)
        }
        MaterialDesc::Conductor {
            ior,
            specular_reflectance,
        } => {
            let (eta, k) = conductor_ior(ior)?;
            Bsdf::conductor(
                eta,
                k,
                unit_color("specular_reflectance", specular_reflectance)?,
            )
        }
        MaterialDesc::RoughConductor {
            ior,
            specular_reflectance,
            roughness,
        } => {
            let (eta, k) = conductor_ior(ior)?;
            Bsdf::rough_conductor(
                eta,
                k,
                unit_color("specular_reflectance", specular_reflectance)?,
                microfacet(roughness, true)?,
            )
        }
        MaterialDesc::Dielectric {
            int_ior,
            ext_ior,
            specular_reflectance,
            specular_transmittance,
        } => Bsdf::dielectric(
            relative_ior(*int_ior, *ext_ior)?,
            unit_color("specular_reflectance", specular_reflectance)?,
            unit_color("specular_transmittance", specular_transmittance)?,
        ),
        MaterialDesc::ThinDielectric {
            int_ior,
            ext_ior,
            specular_reflectance,
            specular_transmittance,
        } => Bsdf::thin_dielectric(
            relative_ior(*int_ior, *ext_ior)?,
            unit_color("specular_reflectance", specular_reflectance)?,
            unit_color("specular_transmittance", specular_transmittance)?,
        ),
        MaterialDesc::RoughDielectric {
            int_ior,
            ext_ior,
            specular_reflectance,
            specular_transmittance,
            roughness,
        } => Bsdf::rough_dielectric(
            relative_ior(*int_ior, *ext_ior)?,
            unit_color("specular_reflectance", specular_reflectance)?,
            unit_color("specular_transmittance", specular_transmittance)?,
            microfacet(roughness, true)?,
        ),
        MaterialDesc::Plastic {
            int_ior,
            ext_ior,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
        } => Bsdf::plastic(
            relative_ior(*int_ior, *ext_ior)?,
            unit_color("diffuse_reflectance", diffuse_reflectance)?,
            unit_color("specular_reflectance", specular_reflectance)?,
            *nonlinear,
        ),
        MaterialDesc::RoughPlastic {
            int_ior,
            ext_ior,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            roughness,
        } => {
            let eta = relative_ior(*int_ior, *ext_ior)?;
            if eta == 1.0 {
                return Err(MaterialError::RoughPlasticSameIor);
            }
            let mf = microfacet(roughness, false)?;
            Bsdf::rough_plastic(
                eta,
                unit_color("diffuse_reflectance", diffuse_reflectance)?,
                unit_color("specular_reflectance", specular_reflectance)?,
                *nonlinear,
                mf.distribution,
                mf.alpha_u,
            )
        }
        MaterialDesc::Null => Bsdf::null(),
        MaterialDesc::Principled { .. } | MaterialDesc::PrincipledThin { .. } => {
            unreachable!("converted by crate::principled::bsdf above")
        }
        MaterialDesc::NormalMap {
            normal,
            flip_invalid_normals,
            use_shadowing_function,
            material,
        } => {
            if matches!(
                **material,
                MaterialDesc::Mask { .. } | MaterialDesc::NormalMap { .. }
            ) {
                return Err(MaterialError::NormalMapNesting);
            }
            let n = Vec3::from(*normal);
            if !n.is_finite() {
                return Err(MaterialError::BadNormal { value: *normal });
            }
            bsdf(material)?.normal_mapped(restir_materials::NormalMap::new(
                n,
                *flip_invalid_normals,
                *use_shadowing_function,
            ))
        }
        MaterialDesc::BumpMap {
            scale,
            flip_invalid_normals,
            use_shadowing_function,
            material,
        } => {
            if matches!(
                **material,
                MaterialDesc::Mask { .. }
                    | MaterialDesc::NormalMap { .. }
                    | MaterialDesc::BumpMap { .. }
            ) {
                return Err(MaterialError::BumpMapNesting);
            }
            if !scale.is_finite() {
                return Err(MaterialError::BadBumpScale { value: *scale });
            }
            // The normal map's frame with the flat normal; the bump's normal replaces it at
            // each hit (`Scene::bsdf`).
            bsdf(material)?.normal_mapped(restir_materials::NormalMap::new(
                Vec3::from(defaults::FLAT_NORMAL),
                *flip_invalid_normals,
                *use_shadowing_function,
            ))
        }
        MaterialDesc::TwoSided(inner) => {
            if matches!(**inner, MaterialDesc::NormalMap { .. }) {
                return Err(MaterialError::NormalMapNesting);
            }
            if matches!(**inner, MaterialDesc::BumpMap { .. }) {
                return Err(MaterialError::BumpMapNesting);
            }
            let b = bsdf(inner)?;
            if b.kind.transmits() {
                return Err(MaterialError::TwoSidedTransmitting);
            }
            b.two_sided()
        }
        MaterialDesc::Black => Bsdf::black(),
        MaterialDesc::Blend { weight, bsdfs } => {
            if !(0.0..=1.0).contains(weight) {
                return Err(MaterialError::BadBlendWeight { value: *weight });
            }
            if blend_depth(m) > MAX_BLEND_DEPTH {
                return Err(MaterialError::BlendTooDeep);
            }
            let (first, second) = &**bsdfs;
            for c in [first, second] {
                if contains_textured(c) || bump_scale(c).is_some() {
                    return Err(MaterialError::BlendTexturedComponent);
                }
            }
            Bsdf::blend(*weight, bsdf(first)?, bsdf(second)?)
        }
        MaterialDesc::Mask { opacity, material } => {
            if matches!(**material, MaterialDesc::Mask { .. }) {
                return Err(MaterialError::NestedMask);
            }
            if !(0.0..=1.0).contains(opacity) {
                return Err(MaterialError::BadOpacity { value: *opacity });
            }
            bsdf(material)?.masked(*opacity)
        }
        MaterialDesc::Textured { material, textures } => {
            let spec_trans = textures.iter().any(|t| t.param == ColorParam::SpecTrans);
            let b = bsdf_in(material, spec_trans)?;
            let allowed = color_params(material);
            if contains_textured(material) {
                return Err(MaterialError::NestedTextured);
            }
            for (i, t) in textures.iter().enumerate() {
                let mask_opacity = t.param == ColorParam::Opacity && is_mask(material);
                let normal_map = t.param == ColorParam::NormalMap && has_normal_map(material);
                let bump_map = t.param == ColorParam::BumpMap && bump_scale(material).is_some();
                let weight = t.param == ColorParam::Weight && is_blend(material);
                if !(allowed.contains(&t.param) || mask_opacity || normal_map || bump_map || weight)
                {
                    return Err(MaterialError::NoSuchParameter {
                        param: t.param,
                        allowed,
                    });
                }
                if textures[..i].iter().any(|u| u.param == t.param) {
                    return Err(MaterialError::TwoTextures { param: t.param });
                }
                crate::principled::check_binding(t)?;
            }
            b
        }
    })
}

/// The colour parameters of a material that textures may replace.
pub(crate) fn color_params(m: &MaterialDesc) -> &'static [ColorParam] {
    use ColorParam::*;
    match m {
        MaterialDesc::Diffuse { .. } => &[Reflectance],
        MaterialDesc::Conductor { .. } => &[SpecularReflectance],
        MaterialDesc::RoughConductor { .. } => &[SpecularReflectance, Alpha, AlphaU, AlphaV],
        MaterialDesc::Dielectric { .. } | MaterialDesc::ThinDielectric { .. } => {
            &[SpecularReflectance, SpecularTransmittance]
        }
        MaterialDesc::RoughDielectric { .. } => &[
            SpecularReflectance,
            SpecularTransmittance,
            Alpha,
            AlphaU,
            AlphaV,
        ],
        MaterialDesc::Plastic { .. } | MaterialDesc::RoughPlastic { .. } => {
            &[DiffuseReflectance, SpecularReflectance]
        }
        MaterialDesc::TwoSided(inner) => color_params(inner),
        MaterialDesc::Textured { material, .. } => color_params(material),
        MaterialDesc::Mask { material, .. }
        | MaterialDesc::NormalMap { material, .. }
        | MaterialDesc::BumpMap { material, .. } => color_params(material),
        MaterialDesc::Principled { .. } => crate::principled::PRINCIPLED_PARAMS,
        MaterialDesc::PrincipledThin { .. } => crate::principled::PRINCIPLED_THIN_PARAMS,
        MaterialDesc::Null | MaterialDesc::Black | MaterialDesc::Blend { .. } => &[],
    }
}

/// The material a wrapper holds: `twosided`, `mask`, `normalmap`, `bumpmap` or a textured
/// model's constant part; `None` for a model.
fn wrapped(m: &MaterialDesc) -> Option<&MaterialDesc> {
    match m {
        MaterialDesc::TwoSided(inner)
        | MaterialDesc::Mask {
            material: inner, ..
        }
        | MaterialDesc::NormalMap {
            material: inner, ..
        }
        | MaterialDesc::BumpMap {
            material: inner, ..
        }
        | MaterialDesc::Textured {
            material: inner, ..
        } => Some(inner),
        _ => None,
    }
}

/// Whether `m` is a `blendbsdf` (perhaps inside a `twosided`, a `mask`, a normal or bump
/// map), whose weight a texture may give.
pub(crate) fn is_blend(m: &MaterialDesc) -> bool {
    matches!(m, MaterialDesc::Blend { .. }) || wrapped(m).is_some_and(is_blend)
}

/// How many `blendbsdf`s nest in `m` at most (0 without one).
fn blend_depth(m: &MaterialDesc) -> usize {
    match m {
        MaterialDesc::Blend { bsdfs, .. } => 1 + blend_depth(&bsdfs.0).max(blend_depth(&bsdfs.1)),
        _ => wrapped(m).map_or(0, blend_depth),
    }
}

/// Whether `m` is textured, or wraps (in `twosided`, `mask`, a normal or bump map) a textured
/// material.
pub(crate) fn contains_textured(m: &MaterialDesc) -> bool {
    matches!(m, MaterialDesc::Textured { .. }) || wrapped(m).is_some_and(contains_textured)
}

/// Whether `m` is a `mask` (perhaps inside `twosided`), whose opacity a texture may give.
pub(crate) fn is_mask(m: &MaterialDesc) -> bool {
    match m {
        MaterialDesc::Mask { .. } => true,
        MaterialDesc::TwoSided(inner) => is_mask(inner),
        _ => false,
    }
}

/// Whether `m` is a `normalmap` (perhaps inside a `mask`), whose normal a texture may give.
pub(crate) fn has_normal_map(m: &MaterialDesc) -> bool {
    match m {
        MaterialDesc::NormalMap { .. } => true,
        MaterialDesc::Mask { material, .. } => has_normal_map(material),
        _ => false,
    }
}

/// The scale of `m`'s `bumpmap` (perhaps inside a `mask`), whose height a texture gives.
pub(crate) fn bump_scale(m: &MaterialDesc) -> Option<f32> {
    match m {
        MaterialDesc::BumpMap { scale, .. } => Some(*scale),
        MaterialDesc::Mask { material, .. } | MaterialDesc::Textured { material, .. } => {
            bump_scale(material)
        }
        _ => None,
    }
}

/// The constant colour parameters of a material as written (defaults where a model has none)
/// and the textures that replace some of them.
pub(crate) fn colors(m: &MaterialDesc) -> (ReflectanceParams, &[TextureBinding]) {
    let mut p = ReflectanceParams {
        diffuse: v3(&defaults::DIFFUSE_REFLECTANCE),
        specular: v3(&defaults::SPECULAR),
        transmittance: v3(&defaults::SPECULAR),
        nonlinear: false,
        opacity: 1.0,
        normal: v3(&defaults::FLAT_NORMAL),
        alpha: None,
    };
    let mut bindings: &[TextureBinding] = &[];
    let mut m = m;
    loop {
        match m {
            MaterialDesc::TwoSided(inner) => m = inner,
            MaterialDesc::Mask { opacity, material } => {
                p.opacity = *opacity;
                m = material;
            }
            MaterialDesc::NormalMap {
                normal, material, ..
            } => {
                p.normal = v3(normal);
                m = material;
            }
            MaterialDesc::BumpMap { material, .. } => m = material,
            MaterialDesc::Textured { material, textures } => {
                bindings = textures;
                m = material;
            }
            _ => break,
        }
    }
    match m {
        MaterialDesc::Diffuse { reflectance } => p.diffuse = v3(reflectance),
        MaterialDesc::Conductor {
            specular_reflectance,
            ..
        }
        | MaterialDesc::RoughConductor {
            specular_reflectance,
            ..
        } => p.specular = v3(specular_reflectance),
        MaterialDesc::Dielectric {
            specular_reflectance,
            specular_transmittance,
            ..
        }
        | MaterialDesc::ThinDielectric {
            specular_reflectance,
            specular_transmittance,
            ..
        }
        | MaterialDesc::RoughDielectric {
            specular_reflectance,
            specular_transmittance,
            ..
        } => {
            p.specular = v3(specular_reflectance);
            p.transmittance = v3(specular_transmittance);
        }
        MaterialDesc::Plastic {
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            ..
        }
        | MaterialDesc::RoughPlastic {
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            ..
        } => {
            p.diffuse = v3(diffuse_reflectance);
            p.specular = v3(specular_reflectance);
            p.nonlinear = *nonlinear;
        }
        _ => {}
    }
    if let MaterialDesc::RoughConductor { roughness, .. }
    | MaterialDesc::RoughDielectric { roughness, .. } = m
    {
        p.alpha = Some((
            roughness.alpha_u.unwrap_or(roughness.alpha),
            roughness.alpha_v.unwrap_or(roughness.alpha),
        ));
    }
    (p, bindings)
}

/// A description vector as a `Vec3`.
pub(crate) fn v3(v: &V3) -> Vec3 {
    Vec3::from(*v)
}
