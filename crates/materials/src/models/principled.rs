//! Mitsuba 3's `principled` BSDF (plugin reference, "The Principled BSDF"): Burley's Disney BSDF
//! ("Physically Based Shading at Disney", 2012; "Extending the Disney BRDF to a BSDF with
//! Integrated Subsurface Scattering", 2015) without subsurface scattering.
//!
//! With `brdf = (1 − metallic)(1 − spec_trans)` and `bsdf = (1 − metallic)·spec_trans`, seen
//! from the front (`v` above the surface), `f·|cos θl|` is the sum of
//! - the main specular reflection `F_p D G / (4 |cos θv|)`: anisotropic GGX
//!   ([`specular_distribution`]) with the separable Smith term, and the blended Fresnel
//!   `F_p = (1 − metallic)(1 − spec_tint) F_dielectric + metallic · Schlick(base_color)
//!   + (1 − metallic) spec_tint · Schlick(tint · R0(η))`;
//! - the specular transmission `√base_color · bsdf · (1 − F) D G |v·h| |l·h| /
//!   (|cos θv| (v·h + η' l·h)²)` (Walter et al. 2007 in radiance form);
//! - the clearcoat `clearcoat/4 · Schlick(0.04) · D_GTR1 · G_GGX(0.25) · |cos θl|` (as Mitsuba
//!   writes it, without the microfacet denominator `4 cos θv cos θl`);
//! - the diffuse `brdf · base_color/π · lerp(f_diffuse + f_retro, f_subsurface, flatness)
//!   · |cos θl|` and the sheen `sheen (1 − metallic) (1 − cos θd)⁵ c_sheen · |cos θl|`.
//!
//! From behind only the specular lobes remain: reflection with Fresnel `bsdf · F_dielectric`,
//! and transmission. `η` is the relative IOR (`eta`, or `2/(1 − √(0.08 specular)) − 1`).
//!
//! Sampling is Mitsuba's mixture (diffuse `∝ brdf`, clearcoat `∝ clearcoat/4`, specular
//! reflection and transmission `∝ 1 − bsdf(1 − F)` and `bsdf(1 − F)`, with `F` at the sampled
//! visible normal; from behind, reflection or transmission by `F`), and [`pdf`] is its exact
//! density, so `f/pdf` is an unbiased weight.

use glam::{Vec2, Vec3};
use restir_sampling::warp;

use super::principled_lobes::{
    clearcoat_alpha, diffuse_lobe, facet_compatible, gtr1_d, gtr1_pdf, gtr1_sample, r0_of_eta,
    schlick, schlick_1, sheen_lobe, smith_ggx1, specular_distribution, tint_color,
};
use super::{BsdfSample, smooth};
use crate::fresnel::{fresnel_dielectric, reflect, refract};
use crate::lobe::{REFLECT_DIFFUSE, REFLECT_GLOSSY, TRANSMIT_GLOSSY};

/// Parameters of Mitsuba's `principled` (its defaults in [`Principled::default`]). Every weight
/// lies in `[0, 1]`; `eta` is the relative IOR, positive and not 1 when `spec_trans > 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Principled {
    /// `base_color` (default 0.5).
    pub base_color: Vec3,
    /// `roughness` of the main specular lobes (default 0.5).
    pub roughness: f32,
    /// `anisotropic` (default 0).
    pub anisotropic: f32,
    /// `metallic` (default 0).
    pub metallic: f32,
    /// `spec_trans`: the share of the dielectric part that transmits (default 0).
    pub spec_trans: f32,
    /// `spec_tint`: how much the dielectric reflection leans to the base colour (default 0).
    pub spec_tint: f32,
    /// `sheen` (default 0).
    pub sheen: f32,
    /// `sheen_tint` (default 0).
    pub sheen_tint: f32,
    /// `flatness`: diffuse (0) to fake subsurface (1) (default 0).
    pub flatness: f32,
    /// `clearcoat` (default 0).
    pub clearcoat: f32,
    /// `clearcoat_gloss` (default 0).
    pub clearcoat_gloss: f32,
    /// Relative IOR (default: from `specular` 0.5, about 1.4899).
    pub eta: f32,
}

impl Default for Principled {
    fn default() -> Self {
        Self {
            base_color: Vec3::splat(0.5),
            roughness: 0.5,
            anisotropic: 0.0,
            metallic: 0.0,
            spec_trans: 0.0,
            spec_tint: 0.0,
            sheen: 0.0,
            sheen_tint: 0.0,
            flatness: 0.0,
            clearcoat: 0.0,
            clearcoat_gloss: 0.0,
            eta: eta_of_specular(0.5),
        }
    }
}

/// Mitsuba's IOR of a `specular` value: `2 / (1 − √(0.08·specular)) − 1`.
pub fn eta_of_specular(specular: f32) -> f32 {
    2.0 / (1.0 - (0.08 * specular).sqrt()) - 1.0
}

impl Principled {
    /// `(brdf, bsdf)`: the weights of the opaque dielectric and of the transmitting part.
    #[inline]
    fn weights(&self) -> (f32, f32) {
        let d = 1.0 - self.metallic;
        (d * (1.0 - self.spec_trans), d * self.spec_trans)
    }

    /// Whether the model has a transmission lobe (and so is two-sided by nature).
    #[inline]
    pub(crate) fn transmits(&self) -> bool {
        self.spec_trans > 0.0
    }
}

/// The half vector of `(v, l)`, turned to the upper hemisphere: `v + l` for a reflection,
/// `v + η' l` for a transmission (`η'` the relative IOR seen from `v`).
#[inline]
fn half_vector(v: Vec3, l: Vec3, reflect: bool, eta_path: f32) -> Vec3 {
    let h = (v + l * if reflect { 1.0 } else { eta_path }).normalize();
    if h.z < 0.0 { -h } else { h }
}

/// The lobe probabilities `(diffuse, clearcoat, reflection, transmission)` at `v` for the
/// dielectric Fresnel reflectance `f` of the facet; `None` where nothing is sampled.
#[inline]
fn lobe_probabilities(p: &Principled, front: bool, f: f32) -> Option<[f32; 4]> {
    let (brdf, bsdf) = p.weights();
    let probs = if front {
        [
            brdf,
            0.25 * p.clearcoat,
            1.0 - bsdf * (1.0 - f),
            bsdf * (1.0 - f),
        ]
    } else if bsdf > 0.0 {
        [0.0, 0.0, f, 1.0 - f]
    } else {
        return None;
    };
    let total: f32 = probs.iter().sum();
    (total > 0.0).then(|| probs.map(|x| x / total))
}

/// `f(v, l)·|cos θl|`.
pub(crate) fn eval(p: &Principled, v: Vec3, l: Vec3) -> Vec3 {
    let cos_v = v.z;
    let cos_l = l.z;
    if cos_v == 0.0 {
        return Vec3::ZERO;
    }
    let (brdf, bsdf) = p.weights();
    let reflect = cos_v * cos_l > 0.0;
    let refract = cos_v * cos_l < 0.0;
    let front = cos_v > 0.0;
    let eta_path = if front { p.eta } else { 1.0 / p.eta };
    let mf = specular_distribution(p.roughness, p.anisotropic);
    let h = half_vector(v, l, reflect, eta_path);
    let vh = v.dot(h);
    let lh = l.dot(h);
    let f_dielectric = fresnel_dielectric(vh, p.eta).r;
    let reflect_ok = reflect && facet_compatible(h, v, l, cos_v, true);
    let refract_ok = refract && facet_compatible(h, v, l, cos_v, false);

    let mut value = Vec3::ZERO;
    if reflect_ok && f_dielectric > 0.0 {
        let fresnel = if front {
            let eta_it = if vh >= 0.0 { p.eta } else { 1.0 / p.eta };
            let metal = schlick(p.base_color, vh, p.eta) * p.metallic;
            let tinted = schlick(tint_color(p.base_color) * r0_of_eta(eta_it), vh, p.eta)
                * ((1.0 - p.metallic) * p.spec_tint);
            Vec3::splat((1.0 - p.metallic) * (1.0 - p.spec_tint) * f_dielectric) + metal + tinted
        } else {
            Vec3::splat(bsdf * f_dielectric)
        };
        value += fresnel * (mf.d(h) * mf.g(v, l, h) / (4.0 * cos_v.abs()));
    }
    if refract_ok && bsdf > 0.0 && f_dielectric < 1.0 {
        let denom = vh + eta_path * lh;
        let t = (1.0 - f_dielectric) * mf.d(h) * mf.g(v, l, h) * (vh * lh).abs()
            / (cos_v.abs() * denom * denom);
        value += p.base_color.max(Vec3::ZERO).powf(0.5) * (bsdf * t);
    }
    if reflect_ok && front && p.clearcoat > 0.0 {
        let fcc = schlick_1(0.04, vh, p.eta);
        let dcc = gtr1_d(clearcoat_alpha(p.clearcoat_gloss), h);
        let gcc = smith_ggx1(v, h, 0.25) * smith_ggx1(l, h, 0.25);
        value += Vec3::splat(0.25 * p.clearcoat * fcc * dcc * gcc * cos_l.abs());
    }
    if reflect && front {
        let cos_d = h.dot(l);
        if brdf > 0.0 {
            value +=
                diffuse_lobe(p.base_color, p.roughness, p.flatness, cos_v, cos_l, cos_d) * brdf;
        }
        if p.sheen > 0.0 && p.metallic < 1.0 {
            value += sheen_lobe(p.base_color, p.sheen_tint, cos_l, cos_d)
                * (p.sheen * (1.0 - p.metallic));
        }
    }
    value
}

/// Density of [`sample`] per unit solid angle of `l`.
pub(crate) fn pdf(p: &Principled, v: Vec3, l: Vec3) -> f32 {
    let cos_v = v.z;
    let cos_l = l.z;
    if cos_v == 0.0 {
        return 0.0;
    }
    let reflect = cos_v * cos_l > 0.0;
    let refract = cos_v * cos_l < 0.0;
    let front = cos_v > 0.0;
    let eta_path = if front { p.eta } else { 1.0 / p.eta };
    let h = half_vector(v, l, reflect, eta_path);
    let vh = v.dot(h);
    let lh = l.dot(h);
    let f_dielectric = fresnel_dielectric(vh, p.eta).r;
    let Some([p_diffuse, p_clearcoat, p_reflect, p_transmit]) =
        lobe_probabilities(p, front, f_dielectric)
    else {
        return 0.0;
    };
    // |dh/dl|: 1/(4 |l·h|) for a reflection, η'² |l·h| / (v·h + η' l·h)² for a transmission.
    let jacobian = if reflect {
        1.0 / (4.0 * lh.abs())
    } else {
        let denom = vh + eta_path * lh;
        (eta_path * eta_path * lh / (denom * denom)).abs()
    };
    let v_up = if front { v } else { -v };
    let mf = specular_distribution(p.roughness, p.anisotropic);
    let mut pdf = 0.0;
    if reflect {
        if facet_compatible(h, v, l, cos_v, true) {
            pdf += p_reflect * mf.pdf(v_up, h) * jacobian;
            if p_clearcoat > 0.0 {
                pdf += p_clearcoat * gtr1_pdf(clearcoat_alpha(p.clearcoat_gloss), h) * jacobian;
            }
        }
        pdf += p_diffuse * warp::cosine_hemisphere_pdf(cos_l);
    } else if refract && p_transmit > 0.0 && facet_compatible(h, v, l, cos_v, false) {
        pdf += p_transmit * mf.pdf(v_up, h) * jacobian;
    }
    pdf
}

/// Samples `l`: a lobe by [`lobe_probabilities`] (`u_lobe`), then a cosine-weighted direction,
/// a GTR1 normal or a visible GGX normal (`u`) to reflect or refract about. `f` and `pdf_sa` are
/// the whole model's [`eval`] and [`pdf`].
pub(crate) fn sample(p: &Principled, v: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
    let cos_v = v.z;
    if cos_v == 0.0 || !v.is_finite() {
        return None;
    }
    let front = cos_v > 0.0;
    let v_up = if front { v } else { -v };
    let mf = specular_distribution(p.roughness, p.anisotropic);
    // The specular normal is drawn first: its Fresnel term splits reflection and transmission.
    let m = mf.sample(v_up, u)?;
    let fr = fresnel_dielectric(v.dot(m), p.eta);
    let [p_diffuse, p_clearcoat, _, p_transmit] = lobe_probabilities(p, front, fr.r)?;
    let (l, lobe, roughness, eta) = if u_lobe < p_diffuse {
        (warp::sample_cosine_hemisphere(u), REFLECT_DIFFUSE, 1.0, 1.0)
    } else if u_lobe < p_diffuse + p_clearcoat {
        let alpha = clearcoat_alpha(p.clearcoat_gloss);
        let mc = gtr1_sample(alpha, u);
        let l = reflect(v, mc);
        if !(l.z * cos_v > 0.0 && facet_compatible(mc, v, l, cos_v, true)) {
            return None;
        }
        (l, REFLECT_GLOSSY, alpha, 1.0)
    } else if u_lobe < p_diffuse + p_clearcoat + p_transmit {
        let l = refract(v, m, fr.cos_theta_t, fr.eta_ti);
        if !(l.z * cos_v < 0.0 && facet_compatible(m, v, l, cos_v, false)) {
            return None;
        }
        (l, TRANSMIT_GLOSSY, mf.alpha(), fr.eta_it)
    } else {
        let l = reflect(v, m);
        if !(l.z * cos_v > 0.0 && facet_compatible(m, v, l, cos_v, true)) {
            return None;
        }
        (l, REFLECT_GLOSSY, mf.alpha(), 1.0)
    };
    let pdf_sa = pdf(p, v, l);
    if pdf_sa.is_nan() || pdf_sa <= 0.0 {
        return None;
    }
    Some(smooth(l, eval(p, v, l), pdf_sa, lobe, roughness, eta))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mitsuba 3's own regression values (its `test_principled.py`, `test05_eval_pdf`): `eval`
    /// (first channel) at the unnormalised viewer `(1, 0, 1)` for lights in the `xz` plane,
    /// with metallic 0.3, spec_tint 0.6, specular 0.4, anisotropic 0.3, clearcoat 0.3,
    /// clearcoat_gloss 0.5, sheen 0.9, sheen_tint 0.9, spec_trans 0.5, flatness 0.5; and its
    /// `pdf` values, which this model's sampling density reproduces (the same mixture).
    #[test]
    #[allow(clippy::excessive_precision)] // Mitsuba's values as its test prints them.
    fn matches_mitsuba_eval_and_pdf() {
        let want_pdf = [
            0.170_074_58,
            0.153_985_69,
            0.140_614_48,
            0.129_244_97,
            0.119_330_98,
            0.110_458_12,
            0.102_313_99,
            0.094_664_65,
            0.087_336_65,
            0.080_203_37,
            0.073_174_51,
            0.066_188_16,
            0.059_204_59,
            0.052_201_71,
            0.045_171_34,
            0.038_116_38,
            0.031_048_63,
            0.023_986_96,
            0.016_955_92,
            0.009_984_55,
        ];
        let want = [
            0.068_049_96,
            0.064_256_36,
            0.060_901_23,
            0.057_847_56,
            0.054_986_23,
            0.052_230_95,
            0.049_513_76,
            0.046_781_41,
            0.043_992_5,
            0.041_115_35,
            0.038_125_97,
            0.035_005_43,
            0.031_735_49,
            0.028_291_59,
            0.024_633_21,
            0.020_693_48,
            0.016_372_75,
            0.011_544_8,
            0.006_091_56,
            4.703_66e-18,
        ];
        let p = Principled {
            metallic: 0.3,
            spec_tint: 0.6,
            eta: eta_of_specular(0.4),
            anisotropic: 0.3,
            clearcoat: 0.3,
            clearcoat_gloss: 0.5,
            sheen: 0.9,
            sheen_tint: 0.9,
            spec_trans: 0.5,
            flatness: 0.5,
            ..Principled::default()
        };
        let v = Vec3::new(1.0, 0.0, 1.0);
        for (i, w) in want.iter().enumerate() {
            // As Mitsuba's test: the angles in double precision, then rounded to f32.
            let theta = i as f64 / 19.0 * core::f64::consts::FRAC_PI_2;
            let l = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32);
            let got = eval(&p, v, l).x;
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
