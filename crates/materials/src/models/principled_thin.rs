//! Mitsuba 3's `principledthin` BSDF (plugin reference, "The Thin Principled BSDF"): Burley's
//! thin-surface variant ("Extending the Disney BRDF to a BSDF with Integrated Subsurface
//! Scattering", 2015, §4) for sheets with no inside, the same from both sides.
//!
//! Seen from either side (directions mirrored so that `v` is above), with `dt = diff_trans/2`,
//! `f·|cos θl|` is the sum of
//! - the specular reflection `spec_trans · F_thin · D G / (4 cos θv)` (anisotropic GGX,
//!   `F_thin = lerp(F_dielectric, Schlick(tint · R0(η)), spec_tint)`);
//! - the specular transmission `spec_trans · base_color · (1 − F) D' G' / (4 cos θv)`: a
//!   reflection about the microfacet mirrored through the sheet, with the roughness scaled by
//!   `0.65 η − 0.35` (Burley 2015, Figure 15);
//! - the diffuse reflection `(1 − spec_trans)(1 − dt) · base_color/π · lerp(f_diffuse + f_retro,
//!   f_subsurface, flatness) · |cos θl|` with the sheen `sheen (1 − spec_trans)(1 − dt)
//!   (1 − cos θd)⁵ c_sheen |cos θl|`;
//! - the diffuse transmission `(1 − spec_trans) dt · base_color/π · |cos θl|`.
//!
//! Sampling is Mitsuba's mixture (specular reflection and transmission `∝ spec_trans/2` each,
//! diffuse reflection `∝ (1 − spec_trans)(1 − dt)`, diffuse transmission `∝ (1 − spec_trans)
//! dt`), and [`pdf`] is its exact density.

use glam::{Vec2, Vec3};
use restir_sampling::warp;

use super::principled_lobes::{
    diffuse_lobe, facet_compatible, r0_of_eta, schlick, sheen_lobe, specular_distribution,
    tint_color,
};
use super::{BsdfSample, smooth};
use crate::LobeFlags;
use crate::fresnel::{fresnel_dielectric, reflect};
use crate::lobe::{REFLECT_DIFFUSE, REFLECT_GLOSSY, TRANSMIT_GLOSSY};
use crate::microfacet::Microfacet;

/// Parameters of Mitsuba's `principledthin` (its defaults in [`PrincipledThin::default`]). The
/// weights lie in `[0, 1]`, `diff_trans` in `[0, 2]`; `eta` is positive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipledThin {
    /// `base_color` (default 0.5).
    pub base_color: Vec3,
    /// `roughness` (default 0.5).
    pub roughness: f32,
    /// `anisotropic` (default 0).
    pub anisotropic: f32,
    /// `spec_trans`: the specular share (half reflected, half transmitted; default 0).
    pub spec_trans: f32,
    /// `spec_tint` (default 0).
    pub spec_tint: f32,
    /// `sheen` (default 0).
    pub sheen: f32,
    /// `sheen_tint` (default 0).
    pub sheen_tint: f32,
    /// `flatness` (default 0).
    pub flatness: f32,
    /// `diff_trans`: diffuse transmission, 0 to 2 (default 0).
    pub diff_trans: f32,
    /// `eta`, the sheet's relative IOR (default 1.5).
    pub eta: f32,
}

impl Default for PrincipledThin {
    fn default() -> Self {
        Self {
            base_color: Vec3::splat(0.5),
            roughness: 0.5,
            anisotropic: 0.0,
            spec_trans: 0.0,
            spec_tint: 0.0,
            sheen: 0.0,
            sheen_tint: 0.0,
            flatness: 0.0,
            diff_trans: 0.0,
            eta: 1.5,
        }
    }
}

/// The diffuse lobe of a transmission (through the sheet).
const TRANSMIT_DIFFUSE: LobeFlags = LobeFlags::DIFFUSE.union(LobeFlags::TRANSMISSION);

impl PrincipledThin {
    /// The transmission lobe's distribution: the roughness scaled by `0.65 η − 0.35`.
    #[inline]
    fn transmission_distribution(&self) -> Microfacet {
        specular_distribution((0.65 * self.eta - 0.35) * self.roughness, self.anisotropic)
    }

    /// The lobe probabilities `(specular reflection, specular transmission, diffuse reflection,
    /// diffuse transmission)`.
    #[inline]
    fn lobe_probabilities(&self) -> Option<[f32; 4]> {
        let st = self.spec_trans;
        let dt = self.diff_trans / 2.0;
        let probs = [st / 2.0, st / 2.0, (1.0 - st) * (1.0 - dt), (1.0 - st) * dt];
        let total: f32 = probs.iter().sum();
        (total > 0.0).then(|| probs.map(|x| x / total))
    }
}

/// `(v, l)` mirrored so that `v` is above the sheet, and the half vector of `v` and `l` mirrored
/// above (`l` itself for a reflection, its mirror image through the sheet for a transmission).
#[inline]
fn oriented(v: Vec3, l: Vec3) -> (Vec3, Vec3, Vec3) {
    let (v, l) = if v.z < 0.0 { (-v, -l) } else { (v, l) };
    let l_up = Vec3::new(l.x, l.y, l.z.abs());
    (v, l, (v + l_up).normalize())
}

/// `f(v, l)·|cos θl|`.
pub(crate) fn eval(p: &PrincipledThin, v: Vec3, l: Vec3) -> Vec3 {
    if v.z == 0.0 {
        return Vec3::ZERO;
    }
    let (v, l, h) = oriented(v, l);
    let (cos_v, cos_l) = (v.z, l.z);
    let reflect = cos_l > 0.0;
    let refract = cos_l < 0.0;
    let st = p.spec_trans;
    let dt = p.diff_trans / 2.0;
    let mut value = Vec3::ZERO;
    if st > 0.0 {
        let vh = v.dot(h);
        let f = fresnel_dielectric(vh, p.eta).r;
        if reflect && facet_compatible(h, v, l, cos_v, true) {
            let mf = specular_distribution(p.roughness, p.anisotropic);
            let fresnel = if p.spec_tint == 0.0 {
                Vec3::splat(f)
            } else {
                let tinted = schlick(tint_color(p.base_color) * r0_of_eta(p.eta), vh, p.eta);
                Vec3::splat(f * (1.0 - p.spec_tint)) + tinted * p.spec_tint
            };
            value += fresnel * (st * mf.d(h) * mf.g(v, l, h) / (4.0 * cos_v));
        }
        if refract && facet_compatible(h, v, l, cos_v, false) {
            let mf = p.transmission_distribution();
            value += p.base_color * (st * (1.0 - f) * mf.d(h) * mf.g(v, l, h) / (4.0 * cos_v));
        }
    }
    if reflect && st < 1.0 && dt < 1.0 {
        let cos_d = h.dot(l);
        let w = (1.0 - st) * (1.0 - dt);
        value += diffuse_lobe(p.base_color, p.roughness, p.flatness, cos_v, cos_l, cos_d) * w;
        if p.sheen > 0.0 {
            value += sheen_lobe(p.base_color, p.sheen_tint, cos_l, cos_d) * (p.sheen * w);
        }
    }
    if refract && st < 1.0 && dt > 0.0 {
        value += p.base_color * ((1.0 - st) * dt * core::f32::consts::FRAC_1_PI * cos_l.abs());
    }
    value
}

/// Density of [`sample`] per unit solid angle of `l`.
pub(crate) fn pdf(p: &PrincipledThin, v: Vec3, l: Vec3) -> f32 {
    if v.z == 0.0 {
        return 0.0;
    }
    let Some([p_sr, p_st, p_dr, p_dt]) = p.lobe_probabilities() else {
        return 0.0;
    };
    let (v, l, h) = oriented(v, l);
    let cos_l = l.z;
    // |dh/dl| of reflecting about h (the transmission reflects, then mirrors through the sheet).
    let jacobian = 1.0 / (4.0 * Vec3::new(l.x, l.y, cos_l.abs()).dot(h)).abs();
    let mut pdf = 0.0;
    if cos_l > 0.0 {
        if p_sr > 0.0 && facet_compatible(h, v, l, v.z, true) {
            let mf = specular_distribution(p.roughness, p.anisotropic);
            pdf += p_sr * mf.pdf(v, h) * jacobian;
        }
        pdf += p_dr * warp::cosine_hemisphere_pdf(cos_l);
    } else if cos_l < 0.0 {
        if p_st > 0.0 && facet_compatible(h, v, l, v.z, false) {
            let mf = p.transmission_distribution();
            pdf += p_st * mf.pdf(v, h) * jacobian;
        }
        pdf += p_dt * warp::cosine_hemisphere_pdf(-cos_l);
    }
    pdf
}

/// Samples `l`: a lobe by the mixture's probabilities (`u_lobe`), then a visible GGX normal to
/// reflect about (for the transmission, mirrored through the sheet) or a cosine-weighted
/// direction on either side (`u`). `f` and `pdf_sa` are the whole model's [`eval`] and [`pdf`].
pub(crate) fn sample(p: &PrincipledThin, v: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
    if v.z == 0.0 || !v.is_finite() {
        return None;
    }
    let sign = if v.z < 0.0 { -1.0 } else { 1.0 };
    let v_up = v * sign;
    let [p_sr, p_st, p_dr, _] = p.lobe_probabilities()?;
    let (l_up, lobe, roughness) = if u_lobe < p_sr {
        let mf = specular_distribution(p.roughness, p.anisotropic);
        let m = mf.sample(v_up, u)?;
        let l = reflect(v_up, m);
        if !(l.z > 0.0 && facet_compatible(m, v_up, l, v_up.z, true)) {
            return None;
        }
        (l, REFLECT_GLOSSY, mf.alpha())
    } else if u_lobe < p_sr + p_st {
        let mf = p.transmission_distribution();
        let m = mf.sample(v_up, u)?;
        let r = reflect(v_up, m);
        let l = Vec3::new(r.x, r.y, -r.z);
        if !(l.z < 0.0 && facet_compatible(m, v_up, l, v_up.z, false)) {
            return None;
        }
        (l, TRANSMIT_GLOSSY, mf.alpha())
    } else if u_lobe < p_sr + p_st + p_dr {
        (warp::sample_cosine_hemisphere(u), REFLECT_DIFFUSE, 1.0)
    } else {
        (-warp::sample_cosine_hemisphere(u), TRANSMIT_DIFFUSE, 1.0)
    };
    let l = l_up * sign;
    let pdf_sa = pdf(p, v, l);
    if pdf_sa.is_nan() || pdf_sa <= 0.0 {
        return None;
    }
    Some(smooth(l, eval(p, v, l), pdf_sa, lobe, roughness, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mitsuba 3's own regression values (its `test_principledthin.py`, `test03_eval_pdf_thin`):
    /// `eval` (first channel) and `pdf` at the unnormalised viewer `(1, 0, 1)` for lights in the
    /// `xz` plane, with eta 1.5, anisotropic 0.5, sheen 0.5, sheen_tint 0.2, spec_trans 0.5,
    /// flatness 0.5, diff_trans 0.6.
    #[test]
    #[allow(clippy::excessive_precision)] // Mitsuba's values as its test prints them.
    fn matches_mitsuba_eval_and_pdf() {
        let want_pdf = [
            0.182_303_89,
            0.170_719_31,
            0.160_463_6,
            0.151_136_41,
            0.142_421_39,
            0.134_072_53,
            0.125_902_22,
            0.117_770_49,
            0.109_576_16,
            0.101_249_58,
            0.092_746_74,
            0.084_044_46,
            0.075_136_5,
            0.066_030_56,
            0.056_745_67,
            0.047_310_12,
            0.037_759_79,
            0.028_136_68,
            0.018_487_74,
            0.008_863_82,
        ];
        let want = [
            0.049_443_34,
            0.048_721_4,
            0.047_846_24,
            0.046_802_82,
            0.045_578_77,
            0.044_164_17,
            0.042_551_25,
            0.040_734_22,
            0.038_709_23,
            0.036_474_5,
            0.034_030_11,
            0.031_376_92,
            0.028_513_6,
            0.025_431_11,
            0.022_105_02,
            0.018_488_25,
            0.014_510_63,
            0.010_096_28,
            0.005_216_2,
            3.899_415e-18,
        ];
        let p = PrincipledThin {
            eta: 1.5,
            anisotropic: 0.5,
            sheen: 0.5,
            sheen_tint: 0.2,
            spec_trans: 0.5,
            flatness: 0.5,
            diff_trans: 0.6,
            ..PrincipledThin::default()
        };
        let v = Vec3::new(1.0, 0.0, 1.0);
        for i in 0..20 {
            // As Mitsuba's test: the angles in double precision, then rounded to f32.
            let theta = i as f64 / 19.0 * core::f64::consts::FRAC_PI_2;
            let l = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32);
            let (got, w) = (eval(&p, v, l).x, want[i]);
            assert!(
                (got - w).abs() <= 1e-5 * w.abs() + 1e-8,
                "θ {theta}: eval {got} vs Mitsuba {w}"
            );
            let (got, w) = (pdf(&p, v, l), want_pdf[i]);
            assert!(
                (got - w).abs() <= 1e-5 * w,
                "θ {theta}: pdf {got} vs Mitsuba {w}"
            );
        }
    }
}
