//! The principled models' constructors on [`Bsdf`], and their parameters by name, for replacing
//! them per shading point with texture values ([`Bsdf::with_principled`]).

use glam::Vec3;

use super::principled::Principled;
use super::principled_thin::PrincipledThin;
use crate::bsdf::one_sided;
use crate::{Bsdf, BsdfKind};

impl Bsdf {
    /// Mitsuba's `principled` with parameters `p`.
    pub fn principled(p: Principled) -> Self {
        one_sided(BsdfKind::Principled(p))
    }

    /// Mitsuba's `principledthin` with parameters `p`.
    pub fn principled_thin(p: PrincipledThin) -> Self {
        one_sided(BsdfKind::PrincipledThin(p))
    }

    /// The same model with the principled parameter `param` replaced by `value` (its first
    /// channel for a scalar), clamped to [`PrincipledParam::range`]; other models, and
    /// parameters the model lacks, are unchanged.
    #[inline]
    pub fn with_principled(mut self, param: PrincipledParam, value: Vec3) -> Self {
        match &mut self.kind {
            BsdfKind::Principled(p) => set_principled(p, param, value),
            BsdfKind::PrincipledThin(p) => set_principled_thin(p, param, value),
            _ => {}
        }
        self
    }
}

/// A parameter of Mitsuba's `principled` or `principledthin` that a texture may give.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PrincipledParam {
    /// `base_color` (a colour; the others are scalars).
    BaseColor,
    /// `roughness`.
    Roughness,
    /// `anisotropic`.
    Anisotropic,
    /// `metallic` (`principled` only).
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
    /// `clearcoat` (`principled` only).
    Clearcoat,
    /// `clearcoat_gloss` (`principled` only).
    ClearcoatGloss,
    /// `diff_trans` (`principledthin` only; 0 to 2).
    DiffTrans,
    /// `eta` (`principledthin` only; `principled` reads a constant).
    Eta,
}

impl PrincipledParam {
    /// Every parameter, in declaration order.
    pub const ALL: [PrincipledParam; 13] = [
        PrincipledParam::BaseColor,
        PrincipledParam::Roughness,
        PrincipledParam::Anisotropic,
        PrincipledParam::Metallic,
        PrincipledParam::SpecTrans,
        PrincipledParam::SpecTint,
        PrincipledParam::Sheen,
        PrincipledParam::SheenTint,
        PrincipledParam::Flatness,
        PrincipledParam::Clearcoat,
        PrincipledParam::ClearcoatGloss,
        PrincipledParam::DiffTrans,
        PrincipledParam::Eta,
    ];

    /// The range a value of the parameter is clamped to when a texture gives it: `[0, 1]`,
    /// `[0, 2]` for `diff_trans`, positive for `eta`.
    pub fn range(self) -> (f32, f32) {
        match self {
            PrincipledParam::DiffTrans => (0.0, 2.0),
            PrincipledParam::Eta => (1e-3, f32::MAX),
            _ => (0.0, 1.0),
        }
    }
}

/// `p` with `param` set to `value` (its first channel for a scalar), clamped to
/// [`PrincipledParam::range`]; a parameter `principled` lacks is ignored.
fn set_principled(p: &mut Principled, param: PrincipledParam, value: Vec3) {
    let (lo, hi) = param.range();
    let x = value.x.clamp(lo, hi);
    match param {
        PrincipledParam::BaseColor => p.base_color = value.clamp(Vec3::ZERO, Vec3::ONE),
        PrincipledParam::Roughness => p.roughness = x,
        PrincipledParam::Anisotropic => p.anisotropic = x,
        PrincipledParam::Metallic => p.metallic = x,
        PrincipledParam::SpecTrans => p.spec_trans = x,
        PrincipledParam::SpecTint => p.spec_tint = x,
        PrincipledParam::Sheen => p.sheen = x,
        PrincipledParam::SheenTint => p.sheen_tint = x,
        PrincipledParam::Flatness => p.flatness = x,
        PrincipledParam::Clearcoat => p.clearcoat = x,
        PrincipledParam::ClearcoatGloss => p.clearcoat_gloss = x,
        PrincipledParam::DiffTrans | PrincipledParam::Eta => {}
    }
}

/// [`set_principled`] for `principledthin`.
fn set_principled_thin(p: &mut PrincipledThin, param: PrincipledParam, value: Vec3) {
    let (lo, hi) = param.range();
    let x = value.x.clamp(lo, hi);
    match param {
        PrincipledParam::BaseColor => p.base_color = value.clamp(Vec3::ZERO, Vec3::ONE),
        PrincipledParam::Roughness => p.roughness = x,
        PrincipledParam::Anisotropic => p.anisotropic = x,
        PrincipledParam::SpecTrans => p.spec_trans = x,
        PrincipledParam::SpecTint => p.spec_tint = x,
        PrincipledParam::Sheen => p.sheen = x,
        PrincipledParam::SheenTint => p.sheen_tint = x,
        PrincipledParam::Flatness => p.flatness = x,
        PrincipledParam::DiffTrans => p.diff_trans = x,
        PrincipledParam::Eta => p.eta = x,
        PrincipledParam::Metallic
        | PrincipledParam::Clearcoat
        | PrincipledParam::ClearcoatGloss => {}
    }
}
