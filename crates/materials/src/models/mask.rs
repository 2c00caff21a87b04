//! Mitsuba 3's `mask` (<https://mitsuba.readthedocs.io/en/latest/src/generated/plugin_reference.html#opacity-mask-mask>):
//! a surface that is only partly there. With probability `opacity` the wrapped model scatters;
//! otherwise light passes straight through, unchanged, from either side (a delta transmission,
//! Mitsuba's `Null` component). So `eval` and `pdf_sa` are the model's scaled by `opacity`, and
//! a pass-through sample has weight `1 − opacity` and selection probability `1 − opacity`
//! (its `f / pdf_sa` is 1). Mitsuba's default opacity is 0.5; values are clamped to `[0, 1]`.
//!
//! As in Mitsuba, the pass-through is a scattering event like any other: a path that crosses a
//! mask spends one bounce on it, and a shadow ray is blocked by a mask whatever its opacity.

use glam::Vec3;

use super::{BsdfSample, delta};
use crate::lobe::TRANSMIT_DELTA;

/// `opacity` clamped to `[0, 1]` (Mitsuba clamps the texture value); NaN becomes 0.
#[inline]
pub(crate) fn clamp_opacity(opacity: f32) -> f32 {
    if opacity.is_nan() {
        0.0
    } else {
        opacity.clamp(0.0, 1.0)
    }
}

/// Samples a mask of opacity `opacity < 1` seen from `wo`: `model(u)` samples the wrapped model
/// with the lobe number `u` rescaled to `[0, 1)`.
#[inline]
pub(crate) fn sample(
    opacity: f32,
    wo: Vec3,
    u_lobe: f32,
    model: impl FnOnce(f32) -> Option<BsdfSample>,
) -> Option<BsdfSample> {
    if u_lobe < opacity {
        let u = (u_lobe / opacity).min(1.0 - f32::EPSILON / 2.0);
        let mut s = model(u)?;
        s.f *= opacity;
        s.pdf_sa *= opacity;
        return Some(s);
    }
    let pass = 1.0 - opacity;
    Some(delta(-wo, Vec3::splat(pass), pass, TRANSMIT_DELTA, 1.0))
}

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3};

    use crate::Bsdf;

    /// A pass-through sample continues straight on with weight 1; the model's samples keep
    /// their weight `f / pdf`.
    #[test]
    fn pass_through_and_model_weights() {
        let inner = Bsdf::diffuse(Vec3::new(0.2, 0.6, 0.9));
        let m = inner.masked(0.3);
        let wo = Vec3::new(0.3, -0.1, 0.8).normalize();
        let s = m.sample(wo, 0.9, Vec2::splat(0.4)).unwrap();
        assert!(s.lobe.is_delta());
        assert_eq!(s.wi, -wo);
        assert!((s.f / s.pdf_sa - Vec3::ONE).abs().max_element() < 1e-6);
        assert!((s.pdf_sa - 0.7).abs() < 1e-6);
        let s = m.sample(wo, 0.15, Vec2::splat(0.4)).unwrap();
        let t = inner.sample(wo, 0.5, Vec2::splat(0.4)).unwrap();
        assert_eq!(s.wi, t.wi);
        assert!((s.f / s.pdf_sa - t.f / t.pdf_sa).abs().max_element() < 1e-6);
        assert!(
            (m.eval(wo, t.wi) - inner.eval(wo, t.wi) * 0.3)
                .abs()
                .max_element()
                < 1e-6
        );
        assert!((m.pdf_sa(wo, t.wi) - inner.pdf_sa(wo, t.wi) * 0.3).abs() < 1e-6);
        // From behind a one-sided model: only the pass-through.
        let back = -wo;
        assert!(m.sample(back, 0.15, Vec2::splat(0.4)).is_none());
        assert_eq!(m.sample(back, 0.5, Vec2::splat(0.4)).unwrap().wi, wo);
    }

    /// Opacity 1 is the model itself; values outside `[0, 1]` are clamped.
    #[test]
    fn opacity_is_clamped() {
        let inner = Bsdf::diffuse(Vec3::splat(0.5));
        assert_eq!(inner.masked(1.0), inner);
        assert_eq!(inner.masked(3.0), inner);
        assert_eq!(inner.masked(-1.0).opacity, 0.0);
        assert_eq!(inner.masked(f32::NAN).opacity, 0.0);
        assert!(!inner.masked(1.0).flags().is_delta());
        assert!(inner.masked(0.5).flags().is_delta());
        assert!(inner.masked(0.5).has_smooth_lobe());
    }
}
