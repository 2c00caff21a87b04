//! ReSTIR DI's initial candidates: where a pixel's light candidates come from (the power
//! sampler, its presampled pool, the light hierarchy, a light tile, the distribution learned in
//! earlier passes), each with the density that
//! drew it, and the initial resampling that streams them into a reservoir.

use glam::Vec3;
use restir_gris::{Reservoir, StreamingReservoir};
use restir_lights::{Contact, LearnedSampler, LightPoint, LightSample, Presampled};
use restir_sampling::Pcg32;
use restir_scene::Scene;

use super::shift::visible;
use super::target::evaluate;
use super::{DiReservoir, Learn, LightSampler, RestirDiIntegrator, pool, tiles};
use crate::reuse::gbuffer::Receiver;

/// Where a pixel's initial candidates come from.
#[derive(Clone, Copy)]
pub(super) enum Candidates<'a> {
    /// The power sampler, drawn per pixel.
    Power,
    /// The power sampler's draws presampled for the pass: the tile of the pixel's block.
    Pool(&'a [Option<Presampled>]),
    /// The light hierarchy.
    Hierarchy,
    /// The pixel's 16×16 light tile (mixed with the power sampler).
    Tile(&'a restir_sampling::AliasTable),
    /// The distribution learned in earlier passes at the receiver's cell, mixed with the power
    /// sampler, whose share is drawn from the pass's pool when there is one.
    Learned {
        learned: &'a LearnedSampler,
        cell: u32,
        pool: Option<&'a [Option<Presampled>]>,
    },
}

/// An initial candidate seen from a receiver.
struct Candidate {
    sample: LightPoint,
    contact: Contact,
    /// The density that drew it, in the sample's measure (area, counting or solid angle).
    source_pdf: f32,
    /// The power sampler's solid-angle density (the light/BSDF split's).
    power_pdf_sa: f32,
}

impl Candidate {
    /// A light sample with its source and power-sampler solid-angle densities.
    #[inline]
    fn from_sample(ls: &LightSample, source_pdf_sa: f32, power_pdf_sa: f32) -> Option<Self> {
        let measure = if ls.delta || !ls.dist.is_finite() {
            1.0
        } else {
            ls.ng.dot(ls.wi).abs() / (ls.dist * ls.dist)
        };
        Some(Self {
            sample: LightPoint::from_light_sample(ls),
            contact: Contact {
                wi: ls.wi,
                p: ls.p,
                dist: ls.dist,
                le: ls.le,
                measure,
                delta: ls.delta,
                ng: ls.ng,
                pdf_sa: Some(power_pdf_sa),
            },
            source_pdf: if ls.delta {
                source_pdf_sa
            } else {
                source_pdf_sa * measure
            },
            power_pdf_sa,
        })
    }

    /// A pool entry seen from `x` (a sphere light gets its point here, with `u`).
    #[inline]
    fn presampled(scene: &Scene, e: &Presampled, x: Vec3, u: glam::Vec2) -> Option<Self> {
        let (sample, resolved, pdf) = match *e {
            Presampled::Fixed {
                point,
                resolved,
                pdf,
            } => (point, resolved, pdf),
            Presampled::Light { light, pmf } => {
                let ls = scene.lights.sample_light(light, x, u)?;
                return Self::from_sample(&ls, ls.pdf_sa * pmf, ls.pdf_sa * pmf);
            }
        };
        let contact = resolved.contact(&scene.lights, x)?;
        // Area lights: the area density over the measure factor is the solid-angle density.
        let power_pdf_sa = if contact.measure > 0.0 {
            pdf / contact.measure
        } else {
            return None;
        };
        Some(Self {
            sample,
            contact,
            source_pdf: pdf,
            power_pdf_sa,
        })
    }
}

impl RestirDiIntegrator {
    /// Initial resampling at receiver `r`, with candidates from `source`. Returns the reservoir
    /// and the rays traced.
    #[inline(never)]
    pub(super) fn initial(
        &self,
        scene: &Scene,
        r: &Receiver,
        ng: Vec3,
        source: Candidates<'_>,
        rng: &mut Pcg32,
    ) -> (DiReservoir, u64) {
        let bsdf = &r.resolve_bsdf(scene);
        if !bsdf.has_smooth_lobe() || scene.lights.is_empty() {
            return (
                Reservoir {
                    confidence: 1.0,
                    ..Reservoir::empty()
                },
                0,
            );
        }
        let n = self.settings.candidates;
        let nf = n as f32;
        let mut stream = StreamingReservoir::new();
        let u0 = rng.next_f32();
        // A pool tile's entries `start + i·S/N_L`: one from each of N_L strata of the selection.
        let (start, stride) = match source {
            Candidates::Pool(tile)
            | Candidates::Learned {
                pool: Some(tile), ..
            } => (
                rng.next_u32() as usize % tile.len(),
                (tile.len() / n as usize).max(1),
            ),
            _ => (0, 0),
        };
        for i in 0..n {
            let u_select = ((i as f32 + u0) / nf).min(restir_sampling::ONE_MINUS_EPSILON);
            let u_light = rng.next_2d();
            let u_pick = rng.next_f32();
            // The candidate, its source density in the sample's measure (selection included)
            // and the power sampler's solid-angle density (which the light/BSDF split uses,
            // whatever drew the candidate).
            let drawn = match source {
                Candidates::Power => scene
                    .lights
                    .sample(r.p, u_select, u_light)
                    .and_then(|ls| Candidate::from_sample(&ls, ls.pdf_sa, ls.pdf_sa)),
                Candidates::Pool(tile) => tile[(start + i as usize * stride) % tile.len()]
                    .and_then(|mut e| {
                        if self.settings.light_sampler == LightSampler::PoolWithoutSelection {
                            e = pool::without_selection(scene, e); // the negative control
                        }
                        Candidate::presampled(scene, &e, r.p, u_light)
                    }),
                Candidates::Hierarchy => {
                    // 48 bits for the descent: the stratified number and 24 more random ones.
                    let u =
                        (i as f64 + u0 as f64 + rng.next_f32() as f64 / 16_777_216.0) / n as f64;
                    scene
                        .lights
                        .sample_hierarchy(r.p, r.n, u.min(1.0 - f64::EPSILON), u_light)
                        .and_then(|(ls, power_pdf_sa)| {
                            let source = if self.settings.light_sampler == LightSampler::Bvh {
                                ls.pdf_sa
                            } else {
                                power_pdf_sa // the negative control's wrong density
                            };
                            Candidate::from_sample(&ls, source, power_pdf_sa)
                        })
                }
                Candidates::Learned {
                    learned,
                    cell,
                    pool: Some(tile),
                } if u_select >= learned.cell_share(Some(cell)) => {
                    // The power sampler's share, from the pool: its density times the mixture's
                    // probability of the light over the power sampler's.
                    tile[(start + i as usize * stride) % tile.len()]
                        .and_then(|e| Candidate::presampled(scene, &e, r.p, u_light))
                        .and_then(|mut c| {
                            let light = c.sample.light;
                            let power_pmf = scene.lights.pmf(light);
                            if power_pmf <= 0.0 {
                                return None;
                            }
                            c.source_pdf *=
                                self.learned_pmf(scene, learned, cell, light) / power_pmf;
                            Some(c)
                        })
                }
                Candidates::Learned { learned, cell, .. } => learned
                    .sample(&scene.lights, Some(cell), u_select)
                    .and_then(|(light, _)| {
                        let ls = scene.lights.sample_light(light, r.p, u_light)?;
                        let pmf = self.learned_pmf(scene, learned, cell, light);
                        let power_pmf = scene.lights.pmf(light);
                        Candidate::from_sample(&ls, pmf * ls.pdf_sa, power_pmf * ls.pdf_sa)
                    }),
                Candidates::Tile(table) => {
                    tiles::select(scene, table, u_select).and_then(|(light, pmf, power_pmf)| {
                        let ls = scene.lights.sample_light(light, r.p, u_light)?;
                        Candidate::from_sample(&ls, pmf * ls.pdf_sa, power_pmf * ls.pdf_sa)
                    })
                }
            };
            let Some(cand) = drawn else {
                continue;
            };
            let e = evaluate(
                scene,
                r,
                bsdf,
                &cand.sample,
                &cand.contact,
                Some(cand.power_pdf_sa),
                self.counts,
            );
            let w = e.target / (nf * cand.source_pdf);
            stream.add_candidate(cand.sample, e.target, w, 0.0, u_pick);
        }
        let mut res = stream.finalize_recorded();
        res.confidence = 1.0;
        let mut rays = 0;
        if self.settings.visibility.tests_initial()
            && let Some(y) = res.sample
        {
            let visible = scene.lights.contact(&y, r.p).is_some_and(|c| {
                rays += 1;
                visible(scene, r, ng, &c)
            });
            if !visible {
                res.sample = None;
                res.ucw = 0.0;
                res.own_target = 0.0;
            }
        }
        (res, rays)
    }

    /// The learned mixture's probability of `light` in `cell` (or, for the negative control, the
    /// cell's table alone).
    #[inline]
    fn learned_pmf(&self, scene: &Scene, learned: &LearnedSampler, cell: u32, light: u32) -> f32 {
        if self.settings.learn == Learn::WithoutDefensiveShare {
            learned.pmf_without_defensive_share(&scene.lights, Some(cell), light)
        } else {
            learned.pmf(&scene.lights, Some(cell), light)
        }
    }
}
