//! ReSTIR DI's initial resampling: a receiver's light candidates, drawn by any
//! [`restir_lights::LightSampler`] (the power sampler, its presampled pool, the light
//! hierarchy, a light tile, the distribution learned in earlier passes; which one is decided per
//! pass and per pixel in `mod.rs`), streamed into a reservoir.

use glam::Vec3;
use restir_geometry::{Ray, offset_ray_origin};
use restir_gris::{Reservoir, StreamingReservoir};
use restir_lights::{At, CandidateU, LightPoint, LightSampler, NeeSelection, Resolved};
use restir_materials::Bsdf;
use restir_sampling::Pcg32;
use restir_scene::Scene;

use super::shift::{DiSample, visible};
use super::target::{evaluate, light_share};
use super::{DiReservoir, RestirDiIntegrator};
use crate::path::bsdf_sample_share;
use crate::reuse::gbuffer::Receiver;

impl RestirDiIntegrator {
    /// Initial resampling at receiver `r` with BSDF `bsdf`, with candidates from `sampler`. Returns the
    /// reservoir, the rays traced, and the reservoir's sample resolved in world space.
    #[inline(never)]
    pub(super) fn initial<S: LightSampler>(
        &self,
        scene: &Scene,
        r: &Receiver,
        bsdf: &Bsdf,
        ng: Vec3,
        mut sampler: S,
        rng: &mut Pcg32,
    ) -> (DiReservoir, u64, Option<(LightPoint, Resolved)>) {
        if !bsdf.has_smooth_lobe() || scene.lights.is_empty() {
            return (
                Reservoir {
                    confidence: 1.0,
                    ..Reservoir::empty()
                },
                0,
                None,
            );
        }
        let n = self.settings.candidates;
        let nf = n as f32;
        // With resampled BSDF samples the candidates of both strategies are weighted by their
        // shares of a split that depends only on the receiver and the sample (`target`).
        let split = self.counts.resampled_at(bsdf);
        let mut stream = StreamingReservoir::new();
        let u0 = rng.next_f32();
        sampler.begin(rng, n);
        let at = At { p: r.p, n: r.n };
        for i in 0..n {
            let u_light = rng.next_2d();
            let u_pick = rng.next_f32();
            let u = CandidateU::new(i, n, u0, u_light);
            let Some(cand) = sampler.candidate(&scene.lights, at, &u, rng) else {
                continue;
            };
            let e = evaluate(
                scene,
                r,
                bsdf,
                &cand.point,
                &cand.contact,
                Some(cand.power_pdf_sa),
                self.counts,
            );
            let m = if let Some(split) = split
                && e.target > 0.0
            {
                let wi = r.frame().to_local(cand.contact.wi);
                light_share(
                    scene,
                    r,
                    bsdf,
                    wi,
                    &cand.point,
                    &cand.contact,
                    Some(cand.power_pdf_sa),
                    split,
                )
            } else {
                1.0
            };
            let w = m * e.target / (nf * cand.source_pdf);
            stream.add_candidate(DiSample::new(cand.point, &e), e.target, w, 0.0, u_pick);
        }
        let mut rays = 0;
        // The BSDF candidates: a found light point is visible from the receiver.
        let mut found = None;
        if let Some(split) = split {
            let share_ignored =
                self.settings.bsdf_samples == super::BsdfSamples::ResampledWithoutShare;
            for _ in 0..split.bsdf as u32 {
                let u_lobe = rng.next_f32();
                let u_dir = rng.next_2d();
                let u_pick = rng.next_f32();
                let Some(bs) = bsdf.sample(r.wo, u_lobe, u_dir) else {
                    continue;
                };
                if bs.lobe.is_delta() || !bs.pdf_sa.is_finite() || bs.pdf_sa <= 0.0 {
                    continue; // delta lobes are shading's continuation
                }
                let d = r.frame().to_world(bs.wi);
                rays += 1;
                let hit = scene.intersect(&Ray::new(offset_ray_origin(r.p, ng, d), d));
                let Some((y, _, power_pdf_sa)) =
                    scene
                        .lights
                        .reached(NeeSelection::Power, (r.p, r.n), d, hit.as_ref())
                else {
                    continue;
                };
                let resolved = scene.lights.resolve(&y);
                let Some(c) = resolved.contact(&scene.lights, &y, r.p) else {
                    continue;
                };
                let e = evaluate(scene, r, bsdf, &y, &c, None, self.counts);
                if e.target <= 0.0 {
                    continue;
                }
                // m_B / N_B, the same split as the light candidates' `m_L`.
                let m = if share_ignored {
                    1.0 / split.bsdf
                } else {
                    let pdf_b = bsdf.pdf_sa(r.wo, r.frame().to_local(c.wi));
                    bsdf_sample_share(pdf_b, split.bsdf, power_pdf_sa, split.light)
                };
                let w = m * e.target / (bs.pdf_sa * c.measure);
                if stream.add_candidate(DiSample::new(y, &e), e.target, w, 0.0, u_pick) {
                    found = Some((y, resolved));
                }
            }
        }
        let mut res = stream.finalize_recorded();
        res.confidence = 1.0;
        let by_bsdf = found.is_some_and(|(y, _)| res.sample.map(|s| s.point) == Some(y));
        let resolved = if by_bsdf {
            found
        } else {
            res.sample
                .map(|y| (y.point, scene.lights.resolve(&y.point)))
        };
        if self.settings.visibility.tests_initial()
            && !by_bsdf
            && let Some((point, y)) = &resolved
        {
            let visible = y.contact(&scene.lights, point, r.p).is_some_and(|c| {
                rays += 1;
                visible(scene, r, ng, &c)
            });
            if !visible {
                res.sample = None;
                res.ucw = 0.0;
                res.own_target = 0.0;
                return (res, rays, None);
            }
        }
        (res, rays, resolved)
    }
}
