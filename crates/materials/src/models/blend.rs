//! Mitsuba 3's `blendbsdf`
//! (<https://mitsuba.readthedocs.io/en/latest/src/generated/plugins_bsdfs.html#blended-material-blendbsdf>):
//! a linear mix of two nested BSDFs by a `weight` in `[0, 1]` (a value or a texture, clamped
//! as Mitsuba clamps it; default 0.5). Weight 0 is the first BSDF, weight 1 the second:
//!
//! `f = (1 − w)·f₀ + w·f₁`, `pdf = (1 − w)·pdf₀ + w·pdf₁`.
//!
//! Sampling picks a component by weight, as Mitsuba does (the second when `u_lobe < w`, with
//! `u_lobe` rescaled for the component), and samples it. A non-delta sample carries the whole
//! mix's `eval` and `pdf_sa` at the sampled direction (one-sample MIS over the components, the
//! crate's convention for models with several lobes, so `f / pdf_sa = eval / pdf_sa` and a
//! reconnection evaluates exactly what was sampled); a delta sample keeps its component's
//! weight `f / pdf_sa`, with `f` and `pdf_sa` scaled by the component's selection probability
//! (as a `mask`'s model samples are). The lobes are the union of the components' lobes.
//!
//! The components are whole [`Bsdf`]s (two-sided, masked, normal-mapped or blended in turn),
//! evaluated in the blend's frame. They are stored once per distinct pair, interned for the
//! life of the program (as the rough plastic's tables are), so that a blend is a small `Copy`
//! value like every other model: 16 bytes in [`crate::BsdfKind`], which does not make the enum
//! larger. A texture can therefore give the weight per shading point, but not the components'
//! parameters (those are constant; `restir-scene` refuses a textured component).

use std::sync::{Mutex, OnceLock};

use glam::{Vec2, Vec3};

use super::BsdfSample;
use crate::{Bsdf, LobeFlags};

/// Mitsuba's `blendbsdf`: two BSDFs mixed by `weight`. Build with [`Bsdf::blend`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blend {
    /// The weight of the second component, in `[0, 1]`.
    pub weight: f32,
    /// The two components, interned.
    parts: &'static [Bsdf; 2],
}

/// `w` clamped to `[0, 1]` (Mitsuba clamps the texture value); NaN becomes 0.
#[inline]
pub(crate) fn clamp_weight(w: f32) -> f32 {
    if w.is_nan() { 0.0 } else { w.clamp(0.0, 1.0) }
}

/// The one stored copy of `parts` (a new one the first time this pair is seen).
fn intern(parts: [Bsdf; 2]) -> &'static [Bsdf; 2] {
    static PAIRS: OnceLock<Mutex<Vec<&'static [Bsdf; 2]>>> = OnceLock::new();
    let pairs = PAIRS.get_or_init(|| Mutex::new(Vec::new()));
    let mut guard = pairs.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(p) = guard.iter().find(|p| ***p == parts) {
        return p;
    }
    let stored: &'static [Bsdf; 2] = Box::leak(Box::new(parts));
    guard.push(stored);
    stored
}

impl Blend {
    /// `first` and `second` mixed by `weight` (clamped to `[0, 1]`).
    pub fn new(weight: f32, first: Bsdf, second: Bsdf) -> Self {
        Self {
            weight: clamp_weight(weight),
            parts: intern([first, second]),
        }
    }

    /// The same components with another weight (clamped to `[0, 1]`): what a weight texture
    /// gives at a shading point.
    #[inline]
    pub fn with_weight(self, weight: f32) -> Self {
        Self {
            weight: clamp_weight(weight),
            ..self
        }
    }

    /// The two components: weight 0 is the first, weight 1 the second.
    #[inline]
    pub fn parts(&self) -> &'static [Bsdf; 2] {
        self.parts
    }

    /// The components with their weights `(1 − w, w)`.
    #[inline]
    fn weighted(&self) -> [(f32, &'static Bsdf); 2] {
        [
            (1.0 - self.weight, &self.parts[0]),
            (self.weight, &self.parts[1]),
        ]
    }

    /// The union of the components' lobes.
    #[inline]
    pub(crate) fn flags(&self) -> LobeFlags {
        self.parts[0].flags() | self.parts[1].flags()
    }

    /// Whether a component transmits.
    #[inline]
    pub(crate) fn transmits(&self) -> bool {
        self.parts.iter().any(|p| p.kind.transmits())
    }
}

/// `(1 − w)·eval₀ + w·eval₁` (a component of weight 0 is not evaluated).
#[inline]
pub(crate) fn eval(b: &Blend, v: Vec3, l: Vec3) -> Vec3 {
    let mut f = Vec3::ZERO;
    for (w, p) in b.weighted() {
        if w > 0.0 {
            f += w * p.eval(v, l);
        }
    }
    f
}

/// `(1 − w)·pdf₀ + w·pdf₁`.
#[inline]
pub(crate) fn pdf(b: &Blend, v: Vec3, l: Vec3) -> f32 {
    let mut pdf = 0.0;
    for (w, p) in b.weighted() {
        if w > 0.0 {
            pdf += w * p.pdf_sa(v, l);
        }
    }
    pdf
}

/// Picks a component by weight and samples it (see the module docs for what the sample
/// carries).
#[inline]
pub(crate) fn sample(b: &Blend, v: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
    let w = b.weight;
    let (chosen, u_c) = if u_lobe < w {
        (1, u_lobe / w)
    } else {
        (0, (u_lobe - w) / (1.0 - w))
    };
    let prob = if chosen == 1 { w } else { 1.0 - w };
    let u_c = u_c.clamp(0.0, 1.0 - f32::EPSILON / 2.0);
    let mut s = b.parts[chosen].sample(v, u_c, u)?;
    if s.lobe.is_delta() {
        s.f *= prob;
        s.pdf_sa *= prob;
    } else {
        s.f = eval(b, v, s.wi);
        s.pdf_sa = pdf(b, v, s.wi);
    }
    Some(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weight_is_clamped_and_pairs_are_interned() {
        let (a, c) = (Bsdf::diffuse(Vec3::splat(0.2)), Bsdf::black());
        assert_eq!(Blend::new(2.0, a, c).weight, 1.0);
        assert_eq!(Blend::new(-1.0, a, c).weight, 0.0);
        assert_eq!(Blend::new(f32::NAN, a, c).weight, 0.0);
        let (x, y) = (Blend::new(0.3, a, c), Blend::new(0.7, a, c));
        assert!(core::ptr::eq(x.parts(), y.parts()));
        assert_eq!(x.with_weight(0.7), y);
    }
}
