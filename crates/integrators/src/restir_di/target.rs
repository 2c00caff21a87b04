//! ReSTIR DI's target: the light strategy's share of the direct light at a receiver.
//!
//! The direct light at receiver `x` is split exactly between the two strategies that cover it,
//! light sampling (the reservoirs) and BSDF sampling (traced at shading), by balance-heuristic
//! weights that depend only on `x` and `y`:
//!
//! ```text
//! m_L(y) = N_L·p_L(y) / (N_L·p_L(y) + N_B·p_B(y)),   m_B = 1 − m_L      (solid angle at x)
//! ```
//!
//! The reservoirs estimate `∫ F(y)·m_L(y)·V(x, y) dy` with `F = f_s·|cos θ_x|·L_e·G` (the
//! unshadowed contribution) and target `p̂(y) = lum(F(y)·m_L(y))`; visibility is tested once, at
//! shading. Because `m_L` needs no visibility, every pixel's target is a fixed function and
//! reservoirs stay valid at their neighbours; BSDF samples could not be resampled into the
//! reservoirs without that (their density on a light is zero wherever the light is occluded).

use glam::Vec3;
use restir_materials::Bsdf;
use restir_sampling::luminance;
use restir_scene::Scene;

use crate::reuse::gbuffer::Receiver;
use restir_lights::{Contact, LightPoint};

/// The two strategy counts of the direct-light split.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrategyCounts {
    /// Light candidates per pixel, `N_L`.
    pub light: f32,
    /// BSDF samples per pixel, `N_B`.
    pub bsdf: f32,
}

/// A sample's value at a receiver: the reservoirs' integrand without visibility, and its target.
#[derive(Clone, Copy, Debug)]
pub struct Evaluated {
    /// `F(y)·m_L(y)` (RGB, in the sample's measure).
    pub contribution: Vec3,
    /// `p̂(y) = lum(contribution)`.
    pub target: f32,
}

impl Evaluated {
    const ZERO: Self = Self {
        contribution: Vec3::ZERO,
        target: 0.0,
    };
}

/// Evaluates `sample` at receiver `r` (whose BSDF, textures resolved, is `bsdf`) seen as `c`
/// (from [`LightSet::contact`](restir_lights::LightSet::contact)). `known_light_pdf_sa` is
/// the light-sampling density at `r` if the caller has it (selection included; the pmf for
/// delta lights); otherwise it is computed when the light/BSDF split needs it (`N_B > 0`).
#[inline]
pub fn evaluate(
    scene: &Scene,
    r: &Receiver,
    bsdf: &Bsdf,
    sample: &LightPoint,
    c: &Contact,
    known_light_pdf_sa: Option<f32>,
    counts: StrategyCounts,
) -> Evaluated {
    let wi = r.frame().to_local(c.wi);
    let f = bsdf.eval(r.wo, wi);
    if f == Vec3::ZERO {
        return Evaluated::ZERO;
    }
    let m_light = if c.delta || counts.bsdf == 0.0 {
        1.0
    } else {
        let light_pdf_sa = known_light_pdf_sa
            .or(c.pdf_sa)
            .unwrap_or_else(|| scene.lights.pdf_sa(sample.light, r.p, c.p, c.ng));
        let nl = counts.light * light_pdf_sa;
        let nb = counts.bsdf * bsdf.pdf_sa(r.wo, wi);
        if nl > 0.0 { nl / (nl + nb) } else { 0.0 }
    };
    let contribution = f * c.le * (c.measure * m_light);
    let target = luminance(contribution);
    if !(target > 0.0 && target.is_finite()) {
        return Evaluated::ZERO;
    }
    Evaluated {
        contribution,
        target,
    }
}
