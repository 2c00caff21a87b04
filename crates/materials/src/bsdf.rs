use core::f32::consts::FRAC_1_PI;
use glam::{Vec2, Vec3};
use restir_sampling::warp;

use crate::LobeFlags;

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

/// The scattering models.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BsdfKind {
    /// Lambertian reflection (Mitsuba `diffuse`): `f = ρ/π` above the surface.
    Diffuse {
        /// Albedo, each channel in `[0, 1]`.
        reflectance: Vec3,
    },
    /// Absorbs everything (a black surface; also emitters without a material).
    Black,
}

/// A BSDF: a model and whether it is mirrored onto the back side (Mitsuba `twosided`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    /// The model.
    pub kind: BsdfKind,
    /// When set, a `wo` below the surface sees the model mirrored to the back side.
    pub two_sided: bool,
}

impl Bsdf {
    /// A one-sided Lambertian BSDF.
    pub fn diffuse(reflectance: Vec3) -> Self {
        Self {
            kind: BsdfKind::Diffuse { reflectance },
            two_sided: false,
        }
    }

    /// A BSDF that absorbs everything.
    pub fn black() -> Self {
        Self {
            kind: BsdfKind::Black,
            two_sided: false,
        }
    }

    /// The same model, visible from both sides.
    pub fn two_sided(self) -> Self {
        Self {
            two_sided: true,
            ..self
        }
    }

    /// Every lobe the BSDF has.
    pub fn flags(&self) -> LobeFlags {
        match self.kind {
            BsdfKind::Diffuse { .. } => LobeFlags::DIFFUSE | LobeFlags::REFLECTION,
            BsdfKind::Black => LobeFlags::NONE,
        }
    }

    /// Whether light sampling can help: the BSDF has a lobe that `eval` can evaluate.
    pub fn has_smooth_lobe(&self) -> bool {
        self.flags()
            .intersects(LobeFlags::DIFFUSE | LobeFlags::GLOSSY)
    }

    /// Mirrors `(wo, wi)` to the front side for a two-sided BSDF seen from the back.
    #[inline]
    fn orient(&self, wo: Vec3, wi: Vec3) -> (Vec3, Vec3, bool) {
        if self.two_sided && wo.z < 0.0 {
            (
                Vec3::new(wo.x, wo.y, -wo.z),
                Vec3::new(wi.x, wi.y, -wi.z),
                true,
            )
        } else {
            (wo, wi, false)
        }
    }

    /// `f(wo, wi) · |cos θi|`; zero for delta lobes and for directions the model does not reach.
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let (wo, wi, _) = self.orient(wo, wi);
        match self.kind {
            BsdfKind::Diffuse { reflectance } => {
                if wo.z > 0.0 && wi.z > 0.0 {
                    reflectance * (FRAC_1_PI * wi.z)
                } else {
                    Vec3::ZERO
                }
            }
            BsdfKind::Black => Vec3::ZERO,
        }
    }

    /// Solid-angle density with which [`Bsdf::sample`] returns `wi`; zero for delta lobes.
    #[inline]
    pub fn pdf_sa(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (wo, wi, _) = self.orient(wo, wi);
        match self.kind {
            BsdfKind::Diffuse { .. } => {
                if wo.z > 0.0 {
                    warp::cosine_hemisphere_pdf(wi.z)
                } else {
                    0.0
                }
            }
            BsdfKind::Black => 0.0,
        }
    }

    /// Samples `wi` given `wo`: `u_lobe` chooses a lobe, `u` the direction within it. `None` when
    /// nothing is scattered (below a one-sided surface, an absorber, or a zero-pdf direction).
    #[inline]
    pub fn sample(&self, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let flip = self.two_sided && wo.z < 0.0;
        let wo_f = if flip {
            Vec3::new(wo.x, wo.y, -wo.z)
        } else {
            wo
        };
        let mut s = match self.kind {
            BsdfKind::Diffuse { reflectance } => {
                if wo_f.z <= 0.0 {
                    return None;
                }
                let wi = warp::sample_cosine_hemisphere(u);
                let pdf_sa = warp::cosine_hemisphere_pdf(wi.z);
                if pdf_sa <= 0.0 {
                    return None;
                }
                BsdfSample {
                    wi,
                    f: reflectance * (FRAC_1_PI * wi.z),
                    pdf_sa,
                    lobe: LobeFlags::DIFFUSE | LobeFlags::REFLECTION,
                    roughness: 1.0,
                    eta: 1.0,
                }
            }
            BsdfKind::Black => return None,
        };
        if flip {
            s.wi.z = -s.wi.z;
        }
        Some(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

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

    #[test]
    fn one_sided_is_black_from_behind() {
        let bsdf = Bsdf::diffuse(Vec3::ONE);
        let wo = Vec3::new(0.0, 0.0, -1.0);
        assert_eq!(bsdf.eval(wo, Vec3::Z), Vec3::ZERO);
        assert_eq!(bsdf.eval(wo, -Vec3::Z), Vec3::ZERO);
        assert!(bsdf.sample(wo, 0.5, Vec2::splat(0.5)).is_none());
        let two = bsdf.two_sided();
        assert!(two.eval(wo, -Vec3::Z).x > 0.0);
        assert_eq!(two.eval(wo, Vec3::Z), Vec3::ZERO);
    }
}
