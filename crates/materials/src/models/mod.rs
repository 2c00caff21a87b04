//! The scattering models, one file per family, each with its parameters, its `eval`, `pdf` and
//! `sample` and its unit tests: [`diffuse`], [`conductor`] (smooth and rough), [`dielectric`]
//! (smooth and rough), [`plastic`] (smooth and rough, with the rough plastic's coating tables) and
//! [`principled`] and [`principled_thin`] (Burley's Disney BSDF, with their shared lobes in
//! [`principled_lobes`]).
//! [`crate::Bsdf`] dispatches to them with one `match` per method.
//!
//! Every model function works on directions that are already oriented (the two-sided mirroring
//! is done by the dispatch): `v` towards the viewer, `l` towards the light, both in the local
//! shading frame (see the crate docs for the conventions). This module holds what the models
//! share: the sample record and its two constructors, the mirror direction and the density of
//! reflecting about a sampled visible normal.

use glam::Vec3;

use crate::LobeFlags;
use crate::microfacet::Microfacet;

pub mod blend;
pub mod bumpmap;
pub(crate) mod conductor;
pub(crate) mod dielectric;
pub(crate) mod diffuse;
pub(crate) mod mask;
pub mod normalmap;
pub(crate) mod plastic;
pub(crate) mod principled;
pub(crate) mod principled_lobes;
pub(crate) mod principled_params;
pub(crate) mod principled_thin;

/// A sampled scattering direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// The sampled direction towards the light, local frame.
    pub wi: Vec3,
    /// `f(wo, wi) · |cos θi|` (for delta lobes: weight × `pdf_sa`, see the crate docs).
    pub f: Vec3,
    /// Solid-angle density of `wi` (for delta lobes: the lobe's selection probability).
    pub pdf_sa: f32,
    /// The lobe that produced the sample.
    pub lobe: LobeFlags,
    /// That lobe's roughness as Mitsuba's `alpha` (1 for diffuse, 0 for delta lobes).
    pub roughness: f32,
    /// Relative index of refraction along the sampled direction (1 for reflection).
    pub eta: f32,
}

/// A delta-lobe sample (roughness 0): `f` is the lobe's weight times `pdf_sa`, the lobe's
/// selection probability.
#[inline]
pub(crate) fn delta(wi: Vec3, f: Vec3, pdf_sa: f32, lobe: LobeFlags, eta: f32) -> BsdfSample {
    BsdfSample {
        wi,
        f,
        pdf_sa,
        lobe,
        roughness: 0.0,
        eta,
    }
}

/// A sample of a non-delta lobe whose `f` and `pdf_sa` are the model's `eval` and `pdf` at `wi`
/// (for mixtures, the pdf of the whole mixture: one-sample MIS over the lobes, as Mitsuba),
/// with the same clean-up of non-finite values as [`crate::Bsdf::eval`] and
/// [`crate::Bsdf::pdf_sa`].
#[inline]
pub(crate) fn smooth(
    wi: Vec3,
    f: Vec3,
    pdf_sa: f32,
    lobe: LobeFlags,
    roughness: f32,
    eta: f32,
) -> BsdfSample {
    BsdfSample {
        wi,
        f: finite_or_zero(f),
        pdf_sa: finite_pdf(pdf_sa),
        lobe,
        roughness,
        eta,
    }
}

/// `f` if every channel is finite, else zero (what [`crate::Bsdf::eval`] returns).
#[inline]
pub(crate) fn finite_or_zero(f: Vec3) -> Vec3 {
    if f.is_finite() { f } else { Vec3::ZERO }
}

/// `p` if finite, else zero (what [`crate::Bsdf::pdf_sa`] returns).
#[inline]
pub(crate) fn finite_pdf(p: f32) -> f32 {
    if p.is_finite() { p } else { 0.0 }
}

/// The mirror direction of `v` about the normal `+z`.
#[inline]
pub(crate) fn mirror(v: Vec3) -> Vec3 {
    Vec3::new(-v.x, -v.y, v.z)
}

/// Density of reflecting about a visible normal: `D(h) G1(v,h) / (4 cos θv)` (the rough
/// conductor, and the rough plastic's specular lobe).
#[inline]
pub(crate) fn rough_reflection_pdf(mf: &Microfacet, v: Vec3, l: Vec3) -> f32 {
    if v.z <= 0.0 || l.z <= 0.0 {
        return 0.0;
    }
    let h = (v + l).normalize();
    let lh = l.dot(h);
    if v.dot(h) <= 0.0 || lh <= 0.0 {
        return 0.0;
    }
    mf.pdf(v, h) / (4.0 * lh)
}

/// Test helpers shared by the models' unit tests.
#[cfg(test)]
pub(crate) mod test_util {
    use glam::Vec3;

    /// The unit direction at polar angle `theta_deg` and azimuth `phi_deg` (degrees).
    pub(crate) fn sph(theta_deg: f32, phi_deg: f32) -> Vec3 {
        let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
        Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    }
}
