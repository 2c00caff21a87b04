//! Mitsuba 3's `normalmap` (<https://mitsuba.readthedocs.io/en/latest/src/generated/plugin_reference.html#normal-map-bsdf-normalmap>):
//! the wrapped model evaluated in a perturbed shading frame. The map's value `t` (a raw colour)
//! gives the perturbed normal `n = 2t − 1` relative to the shading frame (`(0.5, 0.5, 1)` changes
//! nothing). As in Mitsuba 3.9:
//!
//! * with `flip_invalid_normals` (default on), a normal that faces away from the viewer
//!   (`cos θo · (wo · n) ≤ 0`) is mirrored to `(−n.x, −n.y, n.z)`;
//! * the perturbed frame is `n` (normalised), the first tangent `s = normalize(x̂ − n·n.x)` (the
//!   shading frame's own first tangent made orthogonal to `n`) and `t = n × s`;
//! * a direction `wi` counts only when it lies on the same side in both frames
//!   (`cos θi · cos θi' > 0`), for `eval`, `pdf` and `sample` alike;
//! * with `use_shadowing_function` (default on), `eval` and the sample weight are multiplied by
//!   the shadowing term of Estévez et al. 2019 ("A Microfacet-Based Shadowing Function to Solve
//!   the Bump Terminator Problem"): `G = 2 / (1 + √(1 + α²·tan²θi))` with
//!   `α² = min(tan²θn / 8, 1)`, `θn` the perturbed normal's angle and `θi` the light direction's
//!   in the unperturbed frame. `pdf` is not changed.
//!
//! The normal is stored quantised to 16 bits per component (a few 10⁻⁵, far below an 8-bit
//! map's step), which keeps [`crate::Bsdf`] small.

use glam::Vec3;

/// A normal map at one shading point: the perturbed normal and the two switches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NormalMap {
    /// The normal `n = 2t − 1`, normalised, each component times `i16::MAX`.
    n: [i16; 3],
    /// Mirror normals that face away from the viewer (Mitsuba's `flip_invalid_normals`).
    pub flip_invalid: bool,
    /// Apply the shadowing term (Mitsuba's `use_shadowing_function`).
    pub shadowing: bool,
}

/// The perturbed frame in the coordinates of the shading frame.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Perturbed {
    s: Vec3,
    t: Vec3,
    pub(crate) n: Vec3,
}

impl Perturbed {
    /// `v` (shading frame) in the perturbed frame.
    #[inline]
    pub(crate) fn to_local(self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// `v` (perturbed frame) in the shading frame.
    #[inline]
    pub(crate) fn to_shading(self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

const Q: f32 = i16::MAX as f32;

impl NormalMap {
    /// The map's raw value `texel` (each channel usually in `[0, 1]`); a zero or non-finite
    /// normal becomes the unperturbed `(0, 0, 1)`.
    pub fn new(texel: Vec3, flip_invalid: bool, shadowing: bool) -> Self {
        let n = texel * 2.0 - Vec3::ONE;
        let n = if n.is_finite() && n.length_squared() > 0.0 {
            n.normalize()
        } else {
            Vec3::Z
        };
        Self {
            n: [
                (n.x * Q).round() as i16,
                (n.y * Q).round() as i16,
                (n.z * Q).round() as i16,
            ],
            flip_invalid,
            shadowing,
        }
    }

    /// The same switches with another texel.
    pub fn with_texel(&self, texel: Vec3) -> Self {
        Self::new(texel, self.flip_invalid, self.shadowing)
    }

    /// The stored normal (unit length up to the quantisation).
    pub fn normal(&self) -> Vec3 {
        Vec3::new(
            f32::from(self.n[0]),
            f32::from(self.n[1]),
            f32::from(self.n[2]),
        ) / Q
    }

    /// The perturbed frame seen from `wo` (shading frame).
    #[inline]
    pub(crate) fn frame(&self, wo: Vec3) -> Perturbed {
        let mut n = self.normal();
        if self.flip_invalid && wo.z * wo.dot(n) <= 0.0 {
            n = Vec3::new(-n.x, -n.y, n.z);
        }
        let n = n.try_normalize().unwrap_or(Vec3::Z);
        let s = (Vec3::X - n * n.x).try_normalize().unwrap_or(Vec3::Y);
        Perturbed {
            s,
            t: n.cross(s),
            n,
        }
    }

    /// The shadowing factor for light direction `wi` (shading frame) under normal `n`.
    #[inline]
    pub(crate) fn shadowing(&self, n: Vec3, wi: Vec3) -> f32 {
        if !self.shadowing {
            return 1.0;
        }
        let tan2 = |v: Vec3| (1.0 - v.z * v.z).max(0.0) / (v.z * v.z);
        let alpha2 = (0.125 * tan2(n)).min(1.0);
        if alpha2 <= 0.0 {
            return 1.0;
        }
        let g = 2.0 / (1.0 + (1.0 + alpha2 * tan2(wi)).sqrt());
        if g.is_finite() { g } else { 0.0 }
    }
}

/// Whether `wi` (shading frame) and its perturbed version `wi_p` lie on the same side.
#[inline]
pub(crate) fn same_side(wi: Vec3, wi_p: Vec3) -> bool {
    wi.z * wi_p.z > 0.0
}

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3};

    use super::NormalMap;
    use crate::{Bsdf, Distribution, Microfacet};

    fn dir(x: f32, y: f32, z: f32) -> Vec3 {
        Vec3::new(x, y, z).normalize()
    }

    /// `(0.5, 0.5, 1)` is the identity: eval, pdf and samples equal the wrapped model's, for an
    /// anisotropic model too (the tangent stays the shading frame's).
    #[test]
    fn flat_map_changes_nothing() {
        let inner = Bsdf::rough_conductor(
            Vec3::new(1.3, 0.9, 0.6),
            Vec3::new(7.5, 6.4, 5.3),
            Vec3::ONE,
            Microfacet::anisotropic(Distribution::Ggx, 0.25, 0.05),
        );
        let m = inner.normal_mapped(NormalMap::new(Vec3::new(0.5, 0.5, 1.0), true, true));
        let wo = dir(0.3, -0.2, 0.8);
        for wi in [dir(-0.3, 0.25, 0.9), dir(0.5, 0.1, 0.3), dir(0.1, 0.7, 0.2)] {
            let (a, b) = (m.eval(wo, wi), inner.eval(wo, wi));
            assert!((a - b).abs().max_element() <= 1e-5 * b.max_element().max(1.0));
            assert!((m.pdf_sa(wo, wi) - inner.pdf_sa(wo, wi)).abs() <= 1e-4);
        }
        let (s, t) = (
            m.sample(wo, 0.3, Vec2::new(0.2, 0.7)).unwrap(),
            inner.sample(wo, 0.3, Vec2::new(0.2, 0.7)).unwrap(),
        );
        assert!((s.wi - t.wi).abs().max_element() < 1e-4);
    }

    /// A tilted normal: a diffuse surface's `eval` is `ρ/π · cos` against the perturbed normal,
    /// times the shadowing term; a direction below either frame gets nothing.
    #[test]
    fn tilted_diffuse_follows_the_perturbed_normal() {
        let rho = Vec3::new(0.2, 0.5, 0.8);
        let texel = Vec3::new(0.7, 0.5, 0.9);
        let nm = NormalMap::new(texel, true, false);
        let n = (texel * 2.0 - Vec3::ONE).normalize();
        let m = Bsdf::diffuse(rho).normal_mapped(nm);
        let wo = dir(0.1, 0.2, 0.9);
        let wi = dir(0.6, -0.1, 0.5);
        let want = rho / std::f32::consts::PI * wi.dot(n);
        assert!((m.eval(wo, wi) - want).abs().max_element() < 1e-4);
        // Above the shading frame, below the perturbed one (and the other way round).
        let below_p = dir(-0.9, 0.0, 0.1);
        assert!(below_p.dot(n) < 0.0 && below_p.z > 0.0);
        assert_eq!(m.eval(wo, below_p), Vec3::ZERO);
        assert_eq!(m.pdf_sa(wo, below_p), 0.0);
        let under = dir(0.95, 0.0, -0.05);
        assert!(under.dot(n) > 0.0 && under.z < 0.0);
        assert_eq!(m.eval(wo, under), Vec3::ZERO);
        // With the shadowing term: α² = min(tan²θn / 8, 1).
        let shadowed = Bsdf::diffuse(rho).normal_mapped(NormalMap::new(texel, true, true));
        let tan2 = |v: Vec3| (1.0 - v.z * v.z) / (v.z * v.z);
        let a2 = (tan2(n) / 8.0).min(1.0);
        let g = 2.0 / (1.0 + (1.0 + a2 * tan2(wi)).sqrt());
        assert!((shadowed.eval(wo, wi) - want * g).abs().max_element() < 1e-4);
    }

    /// A normal facing away from the viewer is mirrored about the shading normal's plane of
    /// `(x, y)` (`flip_invalid_normals`); without the switch it stays.
    #[test]
    fn invalid_normals_are_flipped() {
        let texel = Vec3::new(0.95, 0.5, 0.6); // n leans far towards +x
        let wo = dir(-0.9, 0.0, 0.2); // sees it from behind
        let n = NormalMap::new(texel, true, false).normal();
        assert!(wo.dot(n) < 0.0);
        let f = NormalMap::new(texel, true, false).frame(wo);
        assert!((f.n - Vec3::new(-n.x, -n.y, n.z)).length() < 1e-4);
        let g = NormalMap::new(texel, false, false).frame(wo);
        assert!((g.n - n).length() < 1e-4);
    }

    /// Sampling and evaluation agree: the sampled `f / pdf` equals `eval / pdf_sa` at the
    /// sampled direction, and samples that cross between the frames are rejected.
    #[test]
    fn sample_matches_eval_and_pdf() {
        let m = Bsdf::rough_conductor(
            Vec3::new(0.2, 0.9, 1.1),
            Vec3::new(3.9, 2.4, 2.2),
            Vec3::ONE,
            Microfacet::new(Distribution::Ggx, 0.3),
        )
        .normal_mapped(NormalMap::new(Vec3::new(0.3, 0.6, 0.85), true, true));
        let wo = dir(0.2, 0.4, 0.8);
        let mut rng = 0x1234_5678_u64;
        let mut next = || {
            rng = rng
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((rng >> 40) as f32) / (1u64 << 24) as f32
        };
        let mut n = 0;
        for _ in 0..2000 {
            let Some(s) = m.sample(wo, next(), Vec2::new(next(), next())) else {
                continue;
            };
            n += 1;
            assert!(s.wi.z > 0.0);
            let (e, p) = (m.eval(wo, s.wi), m.pdf_sa(wo, s.wi));
            assert!(
                (s.pdf_sa - p).abs() <= 1e-3 * p.max(1.0),
                "{} {p}",
                s.pdf_sa
            );
            assert!((s.f - e).abs().max_element() <= 1e-3 * e.max_element().max(1.0));
        }
        assert!(n > 1000);
    }
}
