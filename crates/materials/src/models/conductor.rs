//! Mitsuba 3's `conductor` and `roughconductor`: a metal with complex IOR `eta + i·k`, weighted by
//! the conductor Fresnel reflectance. The smooth one is a delta mirror; the rough one is the
//! microfacet BRDF `F(v·h) D(h) G1(v,h) G1(l,h) / (4 cos θv)`, sampled from the visible normals.
//! Both are one-sided (black unless `v` and `l` are above the surface).

use glam::{Vec2, Vec3};

use super::{BsdfSample, delta, mirror, rough_reflection_pdf, smooth};
use crate::fresnel::{fresnel_conductor, reflect};
use crate::lobe::{REFLECT_DELTA, REFLECT_GLOSSY};
use crate::microfacet::Microfacet;

/// The smooth conductor's mirror sample, weighted by `F(cos θv) · specular_reflectance`;
/// `None` below the surface.
#[inline]
pub(crate) fn sample_smooth(
    eta: Vec3,
    k: Vec3,
    specular_reflectance: Vec3,
    v: Vec3,
) -> Option<BsdfSample> {
    if v.z <= 0.0 {
        return None;
    }
    let f = fresnel_conductor(v.z, eta, k) * specular_reflectance;
    Some(delta(mirror(v), f, 1.0, REFLECT_DELTA, 1.0))
}

/// Mitsuba's `roughconductor` eval without `specular_reflectance`: `v` towards the viewer, `l`
/// towards the light; `F(v·h) D(h) G1(v,h) G1(l,h) / (4 cos θv)`.
#[inline]
fn rough_conductor_eval(mf: &Microfacet, eta: Vec3, k: Vec3, v: Vec3, l: Vec3) -> Vec3 {
    if v.z <= 0.0 || l.z <= 0.0 {
        return Vec3::ZERO;
    }
    let h = (v + l).normalize();
    let d = mf.d(h);
    if d == 0.0 {
        return Vec3::ZERO;
    }
    let g = mf.g(v, l, h);
    fresnel_conductor(v.dot(h), eta, k) * (d * g / (4.0 * v.z))
}

/// The rough conductor's `f · cos θl`.
#[inline]
pub(crate) fn eval_rough(
    mf: &Microfacet,
    eta: Vec3,
    k: Vec3,
    specular_reflectance: Vec3,
    v: Vec3,
    l: Vec3,
) -> Vec3 {
    rough_conductor_eval(mf, eta, k, v, l) * specular_reflectance
}

/// The rough conductor's density: reflection about a visible normal.
#[inline]
pub(crate) fn pdf_rough(mf: &Microfacet, v: Vec3, l: Vec3) -> f32 {
    rough_reflection_pdf(mf, v, l)
}

/// Reflects `v` about a visible normal sampled with `u`; `None` below the surface or when the
/// reflection leaves the hemisphere.
#[inline]
pub(crate) fn sample_rough(
    mf: &Microfacet,
    eta: Vec3,
    k: Vec3,
    specular_reflectance: Vec3,
    v: Vec3,
    u: Vec2,
) -> Option<BsdfSample> {
    if v.z <= 0.0 {
        return None;
    }
    let m = mf.sample(v, u)?;
    let l = reflect(v, m);
    if l.z <= 0.0 {
        return None;
    }
    Some(smooth(
        l,
        eval_rough(mf, eta, k, specular_reflectance, v, l),
        pdf_rough(mf, v, l),
        REFLECT_GLOSSY,
        mf.alpha(),
        1.0,
    ))
}

#[cfg(test)]
mod tests {
    use crate::models::test_util::sph;
    use crate::{Bsdf, Distribution, LobeFlags, Microfacet, ior};
    use glam::{Vec2, Vec3};

    /// Mitsuba's default conductor (`eta = 0, k = 1`) is a perfect mirror: weight 1, mirrored
    /// direction; nothing from below.
    #[test]
    fn smooth_conductor_is_a_mirror() {
        let bsdf = Bsdf::conductor(Vec3::ZERO, Vec3::ONE, Vec3::ONE);
        let wo = sph(40.0, 30.0);
        let s = bsdf.sample(wo, 0.5, Vec2::splat(0.5)).unwrap();
        assert!(s.lobe.is_delta() && s.lobe.contains(LobeFlags::REFLECTION));
        assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).abs().max_element() < 1e-6);
        assert!(((s.f / s.pdf_sa) - Vec3::ONE).abs().max_element() < 1e-5);
        assert_eq!(bsdf.eval(wo, s.wi), Vec3::ZERO);
        assert!(bsdf.sample(-wo, 0.5, Vec2::splat(0.5)).is_none());
    }

    /// A rough conductor's sample carries its own `eval` and `pdf_sa`, for both distributions.
    #[test]
    fn rough_conductor_sample_matches_eval_and_pdf() {
        let (eta, k) = ior::conductor("Au").unwrap();
        for dist in [Distribution::Beckmann, Distribution::Ggx] {
            let bsdf = Bsdf::rough_conductor(eta, k, Vec3::ONE, Microfacet::new(dist, 0.3));
            let wo = sph(50.0, 10.0);
            let mut n = 0;
            for i in 0..64 {
                let u = Vec2::new((i % 8) as f32 / 8.0 + 0.06, (i / 8) as f32 / 8.0 + 0.06);
                let Some(s) = bsdf.sample(wo, 0.5, u) else {
                    continue;
                };
                n += 1;
                assert!(s.lobe.contains(LobeFlags::GLOSSY) && (s.roughness - 0.3).abs() < 1e-6);
                assert_eq!(s.f, bsdf.eval(wo, s.wi), "{dist:?}");
                assert_eq!(s.pdf_sa, bsdf.pdf_sa(wo, s.wi), "{dist:?}");
            }
            assert!(n > 32, "{dist:?}: {n} samples");
        }
    }
}
