//! ReSTIR DI's initial resampling: a receiver's light candidates, drawn by any
//! [`restir_lights::LightSampler`] (the power sampler, its presampled pool, the light
//! hierarchy, a light tile, the distribution learned in earlier passes; which one is decided per
//! pass and per pixel in `mod.rs`), streamed into a reservoir.

use glam::Vec3;
use restir_gris::{Reservoir, StreamingReservoir};
use restir_lights::{At, CandidateU, LightPoint, LightSampler, Resolved};
use restir_materials::Bsdf;
use restir_sampling::Pcg32;
use restir_scene::Scene;

use super::shift::visible;
use super::target::evaluate;
use super::{DiReservoir, RestirDiIntegrator};
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
            let w = e.target / (nf * cand.source_pdf);
            stream.add_candidate(cand.point, e.target, w, 0.0, u_pick);
        }
        let mut res = stream.finalize_recorded();
        res.confidence = 1.0;
        let mut rays = 0;
        let resolved = res.sample.map(|y| (y, scene.lights.resolve(&y)));
        if self.settings.visibility.tests_initial()
            && let Some((_, y)) = &resolved
        {
            let visible = y.contact(&scene.lights, r.p).is_some_and(|c| {
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
