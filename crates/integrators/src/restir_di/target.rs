//! ReSTIR DI's target: the light strategy's share of the direct light at a receiver.
//!
//! The direct light at receiver `x` is split exactly between the two strategies that cover it,
//! light sampling and BSDF sampling, by power-heuristic
//! weights with sample counts that depend only on `x` and `y`:
//!
//! ```text
//! m_L(y) = (N_L·p_L(y))² / ((N_L·p_L(y))² + (N_B·p_B(y))²),   m_B = 1 − m_L   (solid angle at x)
//! ```
//!
//! The power heuristic, not the balance heuristic, because light sampling cannot find a narrow
//! glossy lobe that BSDF sampling covers almost exactly: the balance heuristic still gives the
//! light strategy about `N_L·p_L/p_B` of such a lobe, which a candidate hits rarely and then
//! with a large weight (on a Beckmann α = 0.05 conductor under a constant environment, 8
//! candidates, a per-sample variance about 25 times the path tracer's); the power heuristic
//! leaves it the square of that share.
//!
//! With BSDF samples traced at shading (`separate`) the reservoirs estimate
//! `∫ F(y)·m_L(y)·V(x, y) dy` with `F = f_s·|cos θ_x|·L_e·G` (the unshadowed contribution) and
//! target `p̂(y) = lum(F(y)·m_L(y))`. Because `m_L` needs no visibility, every pixel's target is
//! a fixed function and reservoirs stay valid at their neighbours. With BSDF samples resampled
//! among the candidates (`resampled`, [`StrategyCounts::resampled_at`]) the target is `lum(F)`
//! and the split only weights the two kinds of candidates; that needs visibility in every
//! target, since a BSDF candidate's density on a light is zero wherever the light is occluded
//! (`docs/RESTIR_DI.md`, "How light and BSDF samples are combined").

use glam::Vec3;
use restir_materials::{Bsdf, LobeFlags};
use restir_sampling::luminance;
use restir_scene::Scene;

use crate::reuse::gbuffer::Receiver;
use restir_lights::{Contact, LightPoint};
use restir_sampling::warp::power_share;

/// The two strategy counts of the direct-light split, and where BSDF samples go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrategyCounts {
    /// Light candidates per pixel, `N_L`.
    pub light: f32,
    /// BSDF samples per pixel, `N_B`.
    pub bsdf: f32,
    /// Whether receivers without a glossy lobe take the BSDF samples too; when not, `N_B` is 0
    /// at them and light sampling takes their whole direct light.
    pub bsdf_on_diffuse: bool,
    /// The negative control [`BsdfDiffuse::OffKeepingShare`](super::BsdfDiffuse): receivers
    /// without a glossy lobe take no BSDF samples but their light strategy keeps its share.
    pub keep_share: bool,
    /// Whether the BSDF samples are candidates of initial resampling (the reservoirs hold the
    /// whole direct light).
    pub resampled: bool,
}

impl StrategyCounts {
    /// The counts at a receiver whose BSDF is `bsdf`, as its target sees them: no BSDF samples
    /// where they are resampled (the target is the whole direct light).
    #[inline]
    pub fn at(self, bsdf: &Bsdf) -> Self {
        if self.resampled_at(bsdf).is_some() {
            return Self { bsdf: 0.0, ..self };
        }
        if self.keep_share {
            return self;
        }
        self.split_at(bsdf)
    }

    /// The counts at a receiver whose BSDF is `bsdf`, as its shading draws them: none where they
    /// are resampled.
    #[inline]
    pub fn samples_at(self, bsdf: &Bsdf) -> Self {
        if self.resampled_at(bsdf).is_some() {
            return Self { bsdf: 0.0, ..self };
        }
        self.split_at(bsdf)
    }

    /// The split between light and BSDF candidates of initial resampling at a receiver whose
    /// BSDF is `bsdf`, when it resamples its BSDF samples.
    #[inline]
    pub fn resampled_at(self, bsdf: &Bsdf) -> Option<Self> {
        self.resampled.then(|| self.split_at(bsdf))
    }

    /// The strategy counts drawn at a receiver whose BSDF is `bsdf`, wherever they go.
    #[inline]
    fn split_at(self, bsdf: &Bsdf) -> Self {
        if self.bsdf_on_diffuse || bsdf.flags().intersects(LobeFlags::GLOSSY) {
            self
        } else {
            Self { bsdf: 0.0, ..self }
        }
    }
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
    let m_light = light_share(
        scene,
        r,
        bsdf,
        wi,
        sample,
        c,
        known_light_pdf_sa,
        counts.at(bsdf),
    );
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

/// The light strategy's share `m_L(y)` of `sample` (seen as `c`, in local direction `wi`) at
/// receiver `r` against `counts.bsdf` BSDF samples: 1 for delta lights and without BSDF samples.
/// `known_light_pdf_sa` as for [`evaluate`].
#[allow(clippy::too_many_arguments)] // the receiver, the sample and what is known of both
#[inline]
pub fn light_share(
    scene: &Scene,
    r: &Receiver,
    bsdf: &Bsdf,
    wi: Vec3,
    sample: &LightPoint,
    c: &Contact,
    known_light_pdf_sa: Option<f32>,
    counts: StrategyCounts,
) -> f32 {
    if c.delta || counts.bsdf == 0.0 {
        return 1.0;
    }
    let light_pdf_sa = known_light_pdf_sa
        .or(c.pdf_sa)
        .unwrap_or_else(|| scene.lights.pdf_sa(sample.light, r.p, c.p, c.ng));
    power_share(
        counts.light * light_pdf_sa,
        counts.bsdf * bsdf.pdf_sa(r.wo, wi),
    )
}

#[cfg(test)]
mod tests {
    use crate::path::bsdf_sample_share;
    use restir_sampling::warp::power_share;

    /// The light strategy's weight and the `N_B` BSDF samples' weights add up to one wherever a
    /// BSDF sample can land (the split is exact), at any density, never NaN.
    #[test]
    fn light_and_bsdf_weights_add_up_to_one() {
        let pdfs = [0.0, 1e-30, 0.08, 0.3, 1.0, 32.0, 1e12, 1e30, f32::INFINITY];
        for (nl, nb) in [(8.0, 1.0), (1.0, 1.0), (32.0, 4.0)] {
            for pl in pdfs {
                for pb in pdfs.into_iter().filter(|p| *p > 0.0 && p.is_finite()) {
                    let m_l = power_share(nl * pl, nb * pb);
                    let m_b = nb * bsdf_sample_share(pb, nb, pl, nl);
                    assert!(m_l.is_finite() && m_b.is_finite(), "{pl} {pb}");
                    assert!((m_l + m_b - 1.0).abs() < 1e-6, "{pl} {pb}: {m_l} + {m_b}");
                }
            }
        }
        // No BSDF samples: the light strategy takes everything.
        assert_eq!(bsdf_sample_share(1.0, 0.0, 0.5, 8.0), 0.0);
    }

    /// In a narrow lobe that BSDF sampling covers (`p_B = 32`, a Beckmann α = 0.05 peak) and 8
    /// light candidates of a uniform sphere reach with `N_L·p_L ≈ 0.64`, the light strategy keeps
    /// the square of the balance heuristic's share; with a light it finds well it keeps almost
    /// everything.
    #[test]
    fn a_narrow_lobe_is_left_to_bsdf_sampling() {
        let (a, b) = (8.0 * 0.0796, 32.0);
        let balance = a / (a + b);
        let power = power_share(a, b);
        assert!(balance > 0.019 && power < 0.0005, "{balance} {power}");
        assert!(power_share(1e4, 32.0) > 0.9999);
    }
}
