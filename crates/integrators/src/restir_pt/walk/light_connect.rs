//! A walk's light connections: light sampling at a vertex, and the emitter (or the
//! environment) a BSDF ray reaches. Each is a candidate in initial sampling and the outcome of a
//! replay that ends there.

use glam::Vec3;
use restir_geometry::{Frame, SurfaceInteraction};
use restir_lights::LightPoint;
use restir_materials::Bsdf;
use restir_sampling::warp::power_heuristic;

use super::{BounceRandoms, BsdfStep, Replayed, Walk, Walker};
use crate::restir_pt::candidate::Connection;
use crate::restir_pt::sample::{Kind, PathSample, resolve_vertex};
use crate::shadow::{ShadowTarget, visible};

impl Walker<'_> {
    /// Light sampling at `w.cur` with the bounce's numbers `u`: a candidate for `sink`, or, in a
    /// replay whose light connection this is (`nee_here`), the outcome.
    pub(super) fn sample_light(
        &self,
        w: &mut Walk,
        bsdf: &Bsdf,
        frame: &Frame,
        u: &BounceRandoms,
        nee_here: bool,
        sink: &mut dyn FnMut(PathSample, Vec3),
    ) -> Option<Replayed> {
        let scene = self.scene;
        let cur = w.cur;
        let ls = scene
            .lights
            .sample_nee(self.nee, cur.r.p, cur.r.n, (u.select, u.rr), u.light)?;
        let direct = PathSample::direct(LightPoint::from_light_sample(&ls), Kind::DirectNee);
        let eligible =
            w.rc.is_none() && self.end_eligible(w.j + 1, &cur, &resolve_vertex(scene, &direct));
        if nee_here && eligible && w.check {
            return Some(Replayed::Fail);
        }
        let wi = frame.to_local(ls.wi);
        let f = bsdf.eval(cur.r.wo, wi);
        if f == Vec3::ZERO {
            return None;
        }
        w.rays += 1;
        if !visible(scene, cur.r.p, cur.ng, ShadowTarget::of_sample(&ls)) {
            return None;
        }
        let mis = if ls.delta {
            1.0
        } else {
            power_heuristic(ls.pdf_sa, bsdf.pdf_sa(cur.r.wo, wi))
        };
        let connection = Connection::Nee {
            wi: ls.wi,
            le: ls.le,
            light_pdf_sa: if ls.delta { 0.0 } else { ls.pdf_sa },
            l: f * ls.le * (mis / ls.pdf_sa),
        };
        if nee_here {
            return Some(Replayed::Value(connection.value(w.beta)));
        }
        let sample = self.candidate(w, &connection, direct, eligible);
        sink(sample, connection.contribution(w.beta, w.inv_q));
        None
    }

    /// The emitter (or the environment) the BSDF ray of `step` reached (`hit`, `None` for a
    /// miss): a candidate for `sink`, or, in a replay whose light connection this is
    /// (`hit_here`), the outcome.
    pub(super) fn hit_emitter(
        &self,
        w: &mut Walk,
        step: &BsdfStep,
        hit: Option<&SurfaceInteraction>,
        hit_here: bool,
        sink: &mut dyn FnMut(PathSample, Vec3),
    ) -> Option<Replayed> {
        if self.seen_through_delta && w.all_delta {
            // The silhouette stage's (a replay ending here has no value).
            return None;
        }
        let scene = self.scene;
        let (y, le, light_pdf_sa) =
            self.scene
                .lights
                .reached(self.nee, (w.cur.r.p, w.cur.r.n), step.d, hit)?;
        let mis = step.prev.emission_weight(light_pdf_sa);
        let direct = PathSample::direct(y, Kind::DirectHit);
        let eligible =
            w.rc.is_none() && self.end_eligible(w.j + 1, &w.cur, &resolve_vertex(scene, &direct));
        let connection = Connection::Hit {
            le,
            mis,
            light_pdf_sa: if step.prev.delta { 0.0 } else { light_pdf_sa },
            next_beta: step.next_beta,
        };
        if hit_here {
            if eligible && w.check {
                return Some(Replayed::Fail);
            }
            return Some(Replayed::Value(connection.value(w.beta)));
        }
        let sample = self.candidate(w, &connection, direct, eligible);
        sink(sample, connection.contribution(w.beta, w.inv_q));
        None
    }
}
