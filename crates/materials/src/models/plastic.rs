//! Mitsuba 3's `plastic` and `roughplastic`: a diffuse base under a dielectric coating of
//! relative IOR `eta`. The smooth coating adds a delta mirror lobe weighted by the Fresnel
//! reflectance; the rough coating a microfacet reflection lobe, with the transmittance into the
//! base and the base's internal reflectance precomputed in [`tables`]. The diffuse part is
//! `ρ'/η² · (1 − F_i)(1 − F_o)/π` (smooth) or `ρ'/η² · T_i T_o/π` (rough), where `ρ'` sums the
//! internal reflections. Lobes are chosen by Mitsuba's specular sampling weight, scaled by the
//! coating's reflectance at `v`.

use core::f32::consts::FRAC_1_PI;
use glam::{Vec2, Vec3};
use restir_sampling::warp;

use super::{BsdfSample, delta, mirror, rough_reflection_pdf, smooth};
use crate::fresnel::{fresnel_dielectric, fresnel_diffuse_reflectance, reflect};
use crate::lobe::{REFLECT_DELTA, REFLECT_DIFFUSE, REFLECT_GLOSSY};
use crate::microfacet::{Distribution, Microfacet};

pub mod cache;
pub mod tables;

use tables::{RoughPlasticTable, rough_plastic_table};

/// Parameters of Mitsuba's smooth `plastic`, with the quantities it precomputes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    /// Relative IOR of the coating, `int_ior / ext_ior`.
    pub eta: f32,
    /// `ρ' / η²`: the base's reflectance after the internal-reflection series, times the
    /// radiance scale `1/η²` of refracting out of the coating.
    pub diffuse_scaled: Vec3,
    /// Multiplier of the specular lobe (Mitsuba `specular_reflectance`, default 1).
    pub specular_reflectance: Vec3,
    /// Probability weight of the specular lobe, `mean(ks) / (mean(ρd) + mean(ks))`.
    pub specular_weight: f32,
}

/// Parameters of Mitsuba's `roughplastic`, with its precomputed coating tables.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughPlastic {
    /// Relative IOR of the coating, `int_ior / ext_ior`.
    pub eta: f32,
    /// `ρ' / η²` with `ρ' = ρd / (1 − R_int)` (or `ρd / (1 − ρd R_int)` if nonlinear).
    pub diffuse_scaled: Vec3,
    /// Multiplier of the specular lobe.
    pub specular_reflectance: Vec3,
    /// Probability weight of the specular lobe, as for [`Plastic`].
    pub specular_weight: f32,
    /// The coating's (isotropic) microfacet distribution.
    pub microfacet: Microfacet,
    /// `T(cos θ)` and `R_int`, shared between materials with the same (distribution, α, η).
    pub table: &'static RoughPlasticTable,
}

fn mean(v: Vec3) -> f32 {
    (v.x + v.y + v.z) / 3.0
}

/// Mitsuba's specular sampling weight `mean(ks) / (mean(ρd) + mean(ks))` (1 when both are 0).
fn specular_weight(diffuse: Vec3, specular: Vec3) -> f32 {
    let (d, s) = (mean(diffuse), mean(specular));
    if d + s > 0.0 { s / (d + s) } else { 1.0 }
}

/// A plastic's `ρ' / η²`: the base reflectance `ρd` after the internal-reflection series
/// (`ρd / (1 − R_int)`, or `ρd / (1 − ρd R_int)` if `nonlinear`) times the radiance scale `1/η²`.
///
/// With `r_int` `None` (or outside `[0, 1)`), `R_int` is the value reciprocity gives,
/// `1 − (1 − R_ext(η))/η²`, used in `f64` in the form `(1 − R_int) η² = 1 − R_ext(η)` so that the
/// result stays finite for any legal `η` (it rounds to 1 in `f32` for large `η`). The result is
/// never negative.
#[inline]
fn plastic_diffuse_scaled(eta: f32, diffuse: Vec3, r_int: Option<f32>, nonlinear: bool) -> Vec3 {
    if let Some(r_int) = r_int.filter(|r| (0.0..1.0).contains(r)) {
        let rho = if nonlinear {
            diffuse / (Vec3::ONE - diffuse * r_int)
        } else {
            diffuse / (1.0 - r_int)
        };
        return (rho / (eta * eta)).max(Vec3::ZERO);
    }
    let eta2 = f64::from(eta) * f64::from(eta);
    // (1 − R_int) η², from reciprocity.
    let t_scaled = (1.0 - f64::from(fresnel_diffuse_reflectance(eta).clamp(0.0, 1.0))).max(1e-30);
    let channel = |rho: f32| {
        let rho = f64::from(rho);
        // ρ / ((1 − ρ R_int) η²) with 1 − ρ R_int = (1 − ρ) + ρ (1 − R_int).
        let denom = if nonlinear {
            (1.0 - rho) * eta2 + rho * t_scaled
        } else {
            t_scaled
        };
        let v = rho / denom;
        if v.is_finite() {
            v.max(0.0) as f32
        } else {
            0.0
        }
    };
    Vec3::new(channel(diffuse.x), channel(diffuse.y), channel(diffuse.z))
}

/// The smooth plastic's internal diffuse reflectance: Mitsuba's fit `R_ext(1/η)`, unless it
/// strays more than 5 % from reciprocity in `(1 − R_int) η²` (it does above `η` ≈ 2.5, and
/// exceeds 1 above 3.9, which made the diffuse part negative); then `None`, reciprocity's value.
fn smooth_internal_reflectance(eta: f32) -> Option<f32> {
    let fit = fresnel_diffuse_reflectance(1.0 / eta);
    let eta2 = f64::from(eta) * f64::from(eta);
    let from_fit = (1.0 - f64::from(fit)) * eta2;
    let from_reciprocity = 1.0 - f64::from(fresnel_diffuse_reflectance(eta));
    ((from_fit - from_reciprocity).abs() <= 0.05 * from_reciprocity.abs()).then_some(fit)
}

/// Normalised lobe probabilities `(a, b) / (a + b)` (`(1, 0)` when both vanish).
#[inline]
fn lobe_probabilities(a: f32, b: f32) -> (f32, f32) {
    let s = a + b;
    if s > 0.0 { (a / s, b / s) } else { (1.0, 0.0) }
}

impl Plastic {
    /// Mitsuba's precomputation for coating IOR `eta`, base `diffuse` and specular multiplier
    /// `specular` (the internal reflectance is the fitted diffuse Fresnel reflectance).
    pub(crate) fn new(eta: f32, diffuse: Vec3, specular: Vec3, nonlinear: bool) -> Self {
        let fdr_int = smooth_internal_reflectance(eta);
        Plastic {
            eta,
            diffuse_scaled: plastic_diffuse_scaled(eta, diffuse, fdr_int, nonlinear),
            specular_reflectance: specular,
            specular_weight: specular_weight(diffuse, specular),
        }
    }

    /// The same coating with the colour parameters replaced.
    pub(crate) fn with_reflectance(&self, diffuse: Vec3, specular: Vec3, nonlinear: bool) -> Self {
        Self::new(self.eta, diffuse, specular, nonlinear)
    }
}

impl RoughPlastic {
    /// Mitsuba's precomputation for an isotropic coating roughness `alpha`; builds (or reuses)
    /// the coating tables.
    pub(crate) fn new(
        eta: f32,
        diffuse: Vec3,
        specular: Vec3,
        nonlinear: bool,
        distribution: Distribution,
        alpha: f32,
    ) -> Self {
        let microfacet = Microfacet::new(distribution, alpha);
        let table = rough_plastic_table(distribution, microfacet.alpha_u, eta);
        RoughPlastic {
            eta,
            diffuse_scaled: plastic_diffuse_scaled(
                eta,
                diffuse,
                Some(table.internal_reflectance),
                nonlinear,
            ),
            specular_reflectance: specular,
            specular_weight: specular_weight(diffuse, specular),
            microfacet,
            table,
        }
    }

    /// The same coating (and tables) with the colour parameters replaced.
    pub(crate) fn with_reflectance(&self, diffuse: Vec3, specular: Vec3, nonlinear: bool) -> Self {
        RoughPlastic {
            diffuse_scaled: plastic_diffuse_scaled(
                self.eta,
                diffuse,
                Some(self.table.internal_reflectance),
                nonlinear,
            ),
            specular_reflectance: specular,
            specular_weight: specular_weight(diffuse, specular),
            ..*self
        }
    }
}

/// The smooth plastic's diffuse part (its specular lobe is a delta): `ρ'/η² (1 − F_v)(1 − F_l)/π
/// · cos θl` above the surface.
#[inline]
pub(crate) fn eval_smooth(p: &Plastic, v: Vec3, l: Vec3) -> Vec3 {
    if v.z > 0.0 && l.z > 0.0 {
        let fi = fresnel_dielectric(v.z, p.eta).r;
        let fo = fresnel_dielectric(l.z, p.eta).r;
        // Rounding can put F a hair above 1 for huge IORs.
        p.diffuse_scaled * ((1.0 - fi).max(0.0) * (1.0 - fo).max(0.0) * FRAC_1_PI * l.z)
    } else {
        Vec3::ZERO
    }
}

/// The smooth plastic's density: the diffuse lobe's probability times the cosine density.
#[inline]
pub(crate) fn pdf_smooth(p: &Plastic, v: Vec3, l: Vec3) -> f32 {
    if v.z > 0.0 && l.z > 0.0 {
        let fi = fresnel_dielectric(v.z, p.eta).r;
        let (_, pd) = lobe_probabilities(
            fi * p.specular_weight,
            (1.0 - fi) * (1.0 - p.specular_weight),
        );
        pd * warp::cosine_hemisphere_pdf(l.z)
    } else {
        0.0
    }
}

/// The mirror lobe with probability `∝ F_v · specular_weight`, else the diffuse lobe.
#[inline]
pub(crate) fn sample_smooth(p: &Plastic, v: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
    if v.z <= 0.0 {
        return None;
    }
    let fi = fresnel_dielectric(v.z, p.eta).r;
    let (ps, pd) = lobe_probabilities(
        fi * p.specular_weight,
        (1.0 - fi) * (1.0 - p.specular_weight),
    );
    if u_lobe < ps {
        Some(delta(
            mirror(v),
            p.specular_reflectance * fi,
            ps,
            REFLECT_DELTA,
            1.0,
        ))
    } else if pd > 0.0 {
        let l = warp::sample_cosine_hemisphere(u);
        Some(smooth(
            l,
            eval_smooth(p, v, l),
            pdf_smooth(p, v, l),
            REFLECT_DIFFUSE,
            1.0,
            1.0,
        ))
    } else {
        None
    }
}

/// `(p_spec, p_diffuse)` of a rough plastic at `cos θv`.
#[inline]
fn rough_plastic_lobes(p: &RoughPlastic, cos_v: f32) -> (f32, f32) {
    let t = p.table.transmittance_at(cos_v);
    lobe_probabilities((1.0 - t) * p.specular_weight, t * (1.0 - p.specular_weight))
}

/// The rough plastic's microfacet reflection plus its diffuse part `ρ'/η² T_v T_l/π · cos θl`.
pub(crate) fn eval_rough(p: &RoughPlastic, v: Vec3, l: Vec3) -> Vec3 {
    if v.z <= 0.0 || l.z <= 0.0 {
        return Vec3::ZERO;
    }
    let mf = &p.microfacet;
    let h = (v + l).normalize();
    let d = mf.d(h);
    let spec = if d > 0.0 {
        let f = fresnel_dielectric(v.dot(h), p.eta).r;
        p.specular_reflectance * (f * d * mf.g(v, l, h) / (4.0 * v.z))
    } else {
        Vec3::ZERO
    };
    let (ti, to) = (p.table.transmittance_at(v.z), p.table.transmittance_at(l.z));
    spec + p.diffuse_scaled * (ti * to * FRAC_1_PI * l.z)
}

/// The rough plastic's density: the mixture of visible-normal reflection and cosine sampling.
pub(crate) fn pdf_rough(p: &RoughPlastic, v: Vec3, l: Vec3) -> f32 {
    if v.z <= 0.0 || l.z <= 0.0 {
        return 0.0;
    }
    let (ps, pd) = rough_plastic_lobes(p, v.z);
    ps * rough_reflection_pdf(&p.microfacet, v, l) + pd * warp::cosine_hemisphere_pdf(l.z)
}

/// Reflection about a visible normal with probability `p_spec`, else a cosine-weighted
/// direction; `f` and `pdf_sa` are the whole mixture's.
#[inline]
pub(crate) fn sample_rough(p: &RoughPlastic, v: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
    if v.z <= 0.0 {
        return None;
    }
    let (ps, _) = rough_plastic_lobes(p, v.z);
    let (l, lobe, roughness) = if u_lobe < ps {
        let m = p.microfacet.sample(v, u)?;
        (reflect(v, m), REFLECT_GLOSSY, p.microfacet.alpha())
    } else {
        (warp::sample_cosine_hemisphere(u), REFLECT_DIFFUSE, 1.0)
    };
    if l.z <= 0.0 {
        return None;
    }
    Some(smooth(
        l,
        eval_rough(p, v, l),
        pdf_rough(p, v, l),
        lobe,
        roughness,
        1.0,
    ))
}

#[cfg(test)]
mod tests {
    use crate::models::test_util::sph;
    use crate::{Bsdf, Distribution};
    use glam::Vec3;

    fn close(got: Vec3, want: Vec3, rel: f32, what: &str) {
        assert!(
            (got - want).abs().max_element() <= rel * want.max_element(),
            "{what}: {got} vs Mitsuba {want}"
        );
    }

    /// Mitsuba 3.9.1 `eval` values (MATERIALS.md §4.3), ρd = (0.2, 0.5, 0.8), η = 1.49/1.000277.
    /// Mitsuba's `wi` (viewer) is our `wo`.
    /// Every legal IOR (up to 1e6) gives finite, non-negative values, diffuse albedo at most 1
    /// (before the fix, IORs above about 3.9 made the diffuse part negative).
    #[test]
    fn plastics_stay_non_negative_for_any_ior() {
        let rho = Vec3::new(0.2, 0.5, 1.0);
        for eta in [1.5f32, 3.0, 4.0, 1e3, 1e6] {
            for nonlinear in [false, true] {
                let models = [
                    Bsdf::plastic(eta, rho, Vec3::ONE, nonlinear),
                    Bsdf::rough_plastic(
                        eta,
                        rho,
                        Vec3::ONE,
                        nonlinear,
                        Distribution::Beckmann,
                        0.1,
                    ),
                    Bsdf::rough_plastic(eta, rho, Vec3::ONE, nonlinear, Distribution::Ggx, 0.5),
                ];
                for (m, b) in models.iter().enumerate() {
                    let mut rng = restir_sampling::Pcg32::new(eta.to_bits() as u64, m as u64);
                    let mut albedo = Vec3::ZERO;
                    let n = 2000;
                    let wo = sph(40.0, 0.0);
                    for _ in 0..n {
                        let wi = sph(rng.next_f32() * 90.0, rng.next_f32() * 360.0);
                        let f = b.eval(wo, wi);
                        assert!(
                            f.is_finite() && f.min_element() >= 0.0,
                            "η {eta}, model {m}: {f}"
                        );
                        if let Some(s) = b.sample(wo, rng.next_f32(), rng.next_2d()) {
                            assert!(
                                s.f.is_finite() && s.f.min_element() >= 0.0,
                                "η {eta}, model {m}: sampled {}",
                                s.f
                            );
                            if s.pdf_sa > 0.0 {
                                albedo += s.f / s.pdf_sa / n as f32;
                            }
                        }
                    }
                    assert!(
                        albedo.max_element() < 1.05,
                        "η {eta}, model {m}: albedo {albedo}"
                    );
                }
            }
        }
    }

    #[test]
    fn plastics_match_mitsuba_eval() {
        let eta = 1.49 / 1.000_277;
        let rho = Vec3::new(0.2, 0.5, 0.8);
        let b = Bsdf::rough_plastic(eta, rho, Vec3::ONE, false, Distribution::Beckmann, 0.1);
        close(
            b.eval(Vec3::Z, Vec3::Z),
            Vec3::new(0.370_087, 0.463_594, 0.557_101),
            1e-3,
            "beckmann 0/0",
        );
        close(
            b.eval(sph(60.0, 0.0), sph(20.0, 90.0)),
            Vec3::new(0.055_477, 0.138_693, 0.221_910),
            1e-3,
            "beckmann 60/20",
        );
        let g = Bsdf::rough_plastic(eta, rho, Vec3::ONE, false, Distribution::Ggx, 0.3);
        close(
            g.eval(Vec3::Z, Vec3::Z),
            Vec3::new(0.078_410, 0.144_733, 0.211_056),
            1e-3,
            "ggx 0/0",
        );
        close(
            g.eval(sph(75.0, 0.0), sph(70.0, 180.0)),
            Vec3::new(0.480_867, 0.497_536, 0.514_205),
            1e-3,
            "ggx 75/70",
        );
        let p = Bsdf::plastic(eta, rho, Vec3::ONE, false);
        close(
            p.eval(Vec3::Z, Vec3::Z),
            Vec3::new(0.064_746, 0.161_866, 0.258_985),
            1e-4,
            "plastic",
        );
    }
}
