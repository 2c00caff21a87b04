//! Mitsuba 3's `dielectric` and `roughdielectric`: an interface between two dielectrics of
//! relative IOR `eta = int_ior / ext_ior`, two-sided by nature (seen from below, the relative IOR
//! is `1/eta`). The smooth one reflects and refracts as delta lobes chosen by the Fresnel
//! reflectance; the rough one is Walter et al.'s (2007) microfacet BSDF with the generalised half
//! vector, sampled from the visible normals. Transmitted radiance carries Mitsuba's radiance
//! scale `1/η'²` (see the crate docs). Mitsuba's `thindielectric` is a sheet of such glass too
//! thin to offset what it transmits: delta reflection by both faces, the rest straight through.

use glam::{Vec2, Vec3};

use super::{BsdfSample, delta, mirror, smooth};
use crate::fresnel::{fresnel_dielectric, reflect, refract};
use crate::lobe::{REFLECT_DELTA, REFLECT_GLOSSY, TRANSMIT_DELTA, TRANSMIT_GLOSSY};
use crate::microfacet::Microfacet;

/// A smooth interface's sample: the mirror direction with probability `r` (weighted by `ks`),
/// else the transmitted direction `wt` (weighted by `kt` times the radiance scale `scale`, and
/// seen through relative IOR `eta_t`).
#[inline]
#[allow(clippy::too_many_arguments)] // the two lobes' directions, weights and IOR
fn reflect_or_transmit(
    u_lobe: f32,
    r: f32,
    v: Vec3,
    ks: Vec3,
    wt: Vec3,
    kt: Vec3,
    scale: f32,
    eta_t: f32,
) -> BsdfSample {
    if u_lobe < r {
        delta(mirror(v), ks * r, r, REFLECT_DELTA, 1.0)
    } else {
        let t = 1.0 - r;
        delta(wt, kt * (scale * t), t, TRANSMIT_DELTA, eta_t)
    }
}

/// The smooth dielectric's sample: reflection with probability `F`, else refraction (radiance
/// scaled by `1/η'²`); `None` for a grazing `v`.
#[inline]
pub(crate) fn sample_smooth(
    eta: f32,
    specular_reflectance: Vec3,
    specular_transmittance: Vec3,
    v: Vec3,
    u_lobe: f32,
) -> Option<BsdfSample> {
    if v.z == 0.0 {
        return None;
    }
    let fr = fresnel_dielectric(v.z, eta);
    let wt = Vec3::new(-fr.eta_ti * v.x, -fr.eta_ti * v.y, fr.cos_theta_t);
    // Radiance scales by 1/η² across the interface (η_ti = 1/η_it).
    Some(reflect_or_transmit(
        u_lobe,
        fr.r,
        v,
        specular_reflectance,
        wt,
        specular_transmittance,
        fr.eta_ti * fr.eta_ti,
        fr.eta_it,
    ))
}

/// The thin dielectric's reflectance: a sheet's two faces reflect `r` each, and the light bounced
/// between them adds `t·r·t / (1 − r²)` (`t = 1 − r`), `2r / (1 + r)` in all, with `r` the
/// Fresnel reflectance of the angle `v` makes with the sheet (from either side).
#[inline]
pub(crate) fn thin_reflectance(eta: f32, v: Vec3) -> f32 {
    let r = fresnel_dielectric(v.z.abs(), eta).r;
    r * 2.0 / (1.0 + r)
}

/// The thin dielectric's sample (Mitsuba `thindielectric`): a sheet of glass too thin to offset
/// the light it lets through. Reflection with probability [`thin_reflectance`], else straight
/// through (`−v`, no refraction and no radiance scale), each weighted by its multiplier alone.
#[inline]
pub(crate) fn sample_thin(
    eta: f32,
    specular_reflectance: Vec3,
    specular_transmittance: Vec3,
    v: Vec3,
    u_lobe: f32,
) -> Option<BsdfSample> {
    if v.z == 0.0 {
        return None;
    }
    Some(reflect_or_transmit(
        u_lobe,
        thin_reflectance(eta, v),
        v,
        specular_reflectance,
        -v,
        specular_transmittance,
        1.0,
        1.0,
    ))
}

/// The generalised half vector of a rough dielectric (Walter et al. 2007), in `+z`; `None` if
/// degenerate. Returns `(m, reflect, η')` with `η'` the relative IOR seen from `v`'s side.
#[inline]
fn dielectric_half(eta: f32, v: Vec3, l: Vec3) -> Option<(Vec3, bool, f32)> {
    if v.z == 0.0 || l.z == 0.0 {
        return None;
    }
    let reflect = v.z * l.z > 0.0;
    let eta_p = if v.z > 0.0 { eta } else { 1.0 / eta };
    let m = (v + l * if reflect { 1.0 } else { eta_p }).normalize();
    if !m.is_finite() {
        return None;
    }
    let m = if m.z < 0.0 { -m } else { m };
    Some((m, reflect, eta_p))
}

/// The rough dielectric's `f · |cos θl|`: `ks F D G / (4 |cos θv|)` for reflection, Walter et
/// al.'s BTDF (times the radiance scale) for transmission.
pub(crate) fn eval_rough(mf: &Microfacet, eta: f32, ks: Vec3, kt: Vec3, v: Vec3, l: Vec3) -> Vec3 {
    let Some((m, reflect, eta_p)) = dielectric_half(eta, v, l) else {
        return Vec3::ZERO;
    };
    let d = mf.d(m);
    if d == 0.0 {
        return Vec3::ZERO;
    }
    let g = mf.g(v, l, m);
    if g == 0.0 {
        return Vec3::ZERO;
    }
    let (vm, lm) = (v.dot(m), l.dot(m));
    let f = fresnel_dielectric(vm, eta).r;
    if reflect {
        ks * (f * d * g / (4.0 * v.z.abs()))
    } else {
        // Walter et al.'s BTDF times |cos θl|, times η'² and by the radiance scale 1/η'²,
        // which cancel (Mitsuba's radiance mode).
        let denom = vm + eta_p * lm;
        kt * ((1.0 - f) * d * g * vm * lm / (v.z * denom * denom)).abs()
    }
}

/// The rough dielectric's density: a visible normal seen from `v`'s side, the Fresnel choice
/// between reflection and refraction, and the Jacobian of the half-vector map.
pub(crate) fn pdf_rough(mf: &Microfacet, eta: f32, v: Vec3, l: Vec3) -> f32 {
    let Some((m, reflect, eta_p)) = dielectric_half(eta, v, l) else {
        return 0.0;
    };
    let (vm, lm) = (v.dot(m), l.dot(m));
    if vm * v.z <= 0.0 || lm * l.z <= 0.0 {
        return 0.0;
    }
    let dwh_dwo = if reflect {
        1.0 / (4.0 * lm)
    } else {
        let denom = vm + eta_p * lm;
        eta_p * eta_p * lm / (denom * denom)
    };
    let side = v.z.signum();
    let f = fresnel_dielectric(vm, eta).r;
    let choose = if reflect { f } else { 1.0 - f };
    (mf.pdf(v * side, m) * choose * dwh_dwo).abs()
}

/// Samples a visible normal from `v`'s side, then reflects about it with probability `F` or
/// refracts through it; `None` when the direction lands on the wrong side.
#[inline]
pub(crate) fn sample_rough(
    mf: &Microfacet,
    eta: f32,
    ks: Vec3,
    kt: Vec3,
    v: Vec3,
    u_lobe: f32,
    u: Vec2,
) -> Option<BsdfSample> {
    if v.z == 0.0 {
        return None;
    }
    let side = v.z.signum();
    let m = mf.sample(v * side, u)?;
    let fr = fresnel_dielectric(v.dot(m), eta);
    let (l, lobe, eta_s) = if u_lobe < fr.r {
        (reflect(v, m), REFLECT_GLOSSY, 1.0)
    } else {
        (
            refract(v, m, fr.cos_theta_t, fr.eta_ti),
            TRANSMIT_GLOSSY,
            fr.eta_it,
        )
    };
    let reflected = l.z * v.z > 0.0;
    if reflected != (lobe == REFLECT_GLOSSY) || l.z == 0.0 {
        return None;
    }
    Some(smooth(
        l,
        eval_rough(mf, eta, ks, kt, v, l),
        pdf_rough(mf, eta, v, l),
        lobe,
        mf.alpha(),
        eta_s,
    ))
}

#[cfg(test)]
mod tests {
    use crate::models::test_util::sph;
    use crate::{Bsdf, LobeFlags};
    use glam::{Vec2, Vec3};

    /// Smooth dielectric: Mitsuba's transmission weight at 30° is 1/η² = 0.441976, reflection
    /// weight 1, and R + T = 1.
    #[test]
    fn dielectric_weights() {
        let eta = 1.5046 / 1.000_277;
        let bsdf = Bsdf::dielectric(eta, Vec3::ONE, Vec3::ONE);
        let wo = sph(30.0, 40.0);
        let r = bsdf.sample(wo, 0.0, Vec2::ZERO).unwrap();
        let t = bsdf.sample(wo, 0.999, Vec2::ZERO).unwrap();
        assert!(r.lobe.contains(LobeFlags::REFLECTION) && t.lobe.contains(LobeFlags::TRANSMISSION));
        assert!(((r.f / r.pdf_sa) - Vec3::ONE).abs().max_element() < 1e-6);
        assert!(
            ((t.f / t.pdf_sa) - Vec3::splat(0.441_976))
                .abs()
                .max_element()
                < 1e-5
        );
        assert!((r.pdf_sa + t.pdf_sa - 1.0).abs() < 1e-6);
        assert!((t.eta - eta).abs() < 1e-6 && r.eta == 1.0);
        // Snell's law and the refracted side.
        assert!(t.wi.z < 0.0);
        let (si, st) = ((1.0 - wo.z * wo.z).sqrt(), (1.0 - t.wi.z * t.wi.z).sqrt());
        assert!((si - eta * st).abs() < 1e-5);
        // From inside, the weight is η² and eta is 1/η.
        let t_in = bsdf.sample(-Vec3::Z, 0.999, Vec2::ZERO).unwrap();
        assert!(
            ((t_in.f / t_in.pdf_sa) - Vec3::splat(eta * eta))
                .abs()
                .max_element()
                < 1e-4
        );
        assert!((t_in.eta - 1.0 / eta).abs() < 1e-6);
    }
}
