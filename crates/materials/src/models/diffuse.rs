//! Mitsuba 3's `diffuse`: Lambertian reflection `f = ρ/π` above the surface, sampled from the
//! cosine-weighted hemisphere (so `f/pdf` is exactly the reflectance `ρ`).

use core::f32::consts::FRAC_1_PI;
use glam::{Vec2, Vec3};
use restir_sampling::warp;

use super::BsdfSample;
use crate::lobe::REFLECT_DIFFUSE;

/// `ρ/π · cos θl` when both directions are above the surface, else zero.
#[inline]
pub(crate) fn eval(reflectance: Vec3, v: Vec3, l: Vec3) -> Vec3 {
    if v.z > 0.0 && l.z > 0.0 {
        reflectance * (FRAC_1_PI * l.z)
    } else {
        Vec3::ZERO
    }
}

/// The cosine-hemisphere density of `l` (zero when `v` is below the surface).
#[inline]
pub(crate) fn pdf(v: Vec3, l: Vec3) -> f32 {
    if v.z > 0.0 {
        warp::cosine_hemisphere_pdf(l.z)
    } else {
        0.0
    }
}

/// A cosine-weighted direction; `None` when `v` is below the surface.
#[inline]
pub(crate) fn sample(reflectance: Vec3, v: Vec3, u: Vec2) -> Option<BsdfSample> {
    if v.z <= 0.0 {
        return None;
    }
    let wi = warp::sample_cosine_hemisphere(u);
    Some(BsdfSample {
        wi,
        f: reflectance * (FRAC_1_PI * wi.z),
        pdf_sa: warp::cosine_hemisphere_pdf(wi.z),
        lobe: REFLECT_DIFFUSE,
        roughness: 1.0,
        eta: 1.0,
    })
}

#[cfg(test)]
mod tests {
    use crate::Bsdf;
    use glam::{Vec2, Vec3};
    use proptest::prelude::*;
    use restir_sampling::warp;

    fn dir(x: f32, y: f32) -> Vec3 {
        warp::sample_uniform_sphere(Vec2::new(x, y))
    }

    proptest! {
        /// `sample` agrees with `eval` and `pdf_sa`, and reciprocity holds.
        #[test]
        fn sample_eval_pdf_agree(a in 0.0f32..1.0, b in 0.0f32..1.0, c in 0.0f32..1.0,
                                 d in 0.0f32..1.0, two in proptest::bool::ANY) {
            let mut bsdf = Bsdf::diffuse(Vec3::new(0.8, 0.5, 0.2));
            if two { bsdf = bsdf.two_sided(); }
            let wo = dir(a, b);
            if let Some(s) = bsdf.sample(wo, 0.5, Vec2::new(c, d)) {
                prop_assert!((bsdf.eval(wo, s.wi) - s.f).abs().max_element() < 1e-5);
                prop_assert!((bsdf.pdf_sa(wo, s.wi) - s.pdf_sa).abs() < 1e-4 * s.pdf_sa.max(1.0));
                // Reciprocity of f = eval/|cos θi|.
                let f_ab = bsdf.eval(wo, s.wi) / s.wi.z.abs();
                let f_ba = bsdf.eval(s.wi, wo) / wo.z.abs();
                prop_assert!((f_ab - f_ba).abs().max_element() < 1e-4);
            } else {
                prop_assert!(!two && wo.z <= 0.0);
            }
        }
    }
}
