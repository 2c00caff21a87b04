//! How a light connection found along a walk becomes a ReSTIR PT candidate sample: relative to
//! the reconnection vertex found earlier, with a new reconnection vertex at the light, or as a
//! frozen path (no reconnection vertex).

use glam::Vec3;

use super::sample::{Kind, PathSample, resolve_vertex};
use super::walk::{Rc, Walk, Walker};

/// A light connection found along a walk, and how its radiance enters the sample.
pub(super) enum Connection {
    /// Light sampling at `x_j` towards `wi`; `l = f·L_e·m/p` (without the throughput before
    /// `x_j`).
    Nee {
        wi: Vec3,
        le: Vec3,
        /// Light-sampling density (solid angle), 0 for delta lights.
        light_pdf_sa: f32,
        l: Vec3,
    },
    /// The BSDF ray from `x_j` reached emission `le` with MIS weight `mis`.
    Hit {
        le: Vec3,
        mis: f32,
        /// Light-sampling density (solid angle) of the emitter point, 0 behind a delta lobe.
        light_pdf_sa: f32,
        /// Throughput including the bounce at `x_j`.
        next_beta: Vec3,
    },
}

impl Connection {
    #[inline]
    pub(super) fn is_nee(&self) -> bool {
        matches!(self, Connection::Nee { .. })
    }

    /// The path's estimate from the camera side with throughput `beta` before `x_j`.
    #[inline]
    pub(super) fn value(&self, beta: Vec3) -> Vec3 {
        match *self {
            Connection::Nee { l, .. } => beta * l,
            Connection::Hit {
                le, mis, next_beta, ..
            } => next_beta * le * mis,
        }
    }

    /// The radiance arriving at a reconnection vertex whose suffix throughput is `rest`.
    #[inline]
    pub(super) fn suffix(&self, rest: Vec3) -> Vec3 {
        match *self {
            Connection::Nee { l, .. } => rest * l,
            Connection::Hit { le, mis, .. } => rest * le * mis,
        }
    }

    /// The candidate's contribution with Russian roulette (`inv_q`).
    #[inline]
    pub(super) fn contribution(&self, beta: Vec3, inv_q: f32) -> Vec3 {
        match *self {
            Connection::Nee { l, .. } => beta * inv_q * l,
            Connection::Hit {
                le, mis, next_beta, ..
            } => next_beta * inv_q * le * mis,
        }
    }
}

impl Walker<'_> {
    /// Completes a candidate that reconnects at `rc` and computes its value.
    #[inline]
    fn rc_candidate(&self, rc: &Rc, mut s: PathSample) -> PathSample {
        let (g, f, _) = self.reconnect(&rc.prev, rc.beta, &s, &rc.vertex);
        s.geometry = g;
        s.value = f;
        s
    }

    /// The candidate sample of a light connection at `w.cur` (a path of `j + 1` segments):
    /// relative to the reconnection vertex found earlier, a new reconnection vertex at the
    /// light (`eligible`), or a frozen path.
    pub(super) fn candidate(
        &self,
        w: &Walk,
        connection: &Connection,
        direct: PathSample,
        eligible: bool,
    ) -> PathSample {
        let length = (w.j + 1).min(255) as u8;
        let nee = connection.is_nee();
        if let Some(rc) = &w.rc {
            let s = if rc.k == w.j {
                // The light connection is at `x_k`: its radiance and density are stored.
                let (dir, radiance, light_pdf_sa, kind) = match *connection {
                    Connection::Nee {
                        wi,
                        le,
                        light_pdf_sa,
                        ..
                    } => (wi, le, light_pdf_sa, Kind::NeeAtX2),
                    Connection::Hit {
                        le, light_pdf_sa, ..
                    } => (rc.dir, le, light_pdf_sa, Kind::HitAtX3),
                };
                PathSample {
                    dir,
                    radiance,
                    light_pdf_sa,
                    kind,
                    length,
                    nee,
                    lobes: w.lobes,
                    ..rc.base
                }
            } else {
                PathSample {
                    dir: rc.dir,
                    radiance: connection.suffix(rc.rest),
                    kind: Kind::Continue,
                    length,
                    nee,
                    lobes: w.lobes,
                    ..rc.base
                }
            };
            self.rc_candidate(rc, s)
        } else if eligible {
            let here = Rc {
                k: w.j + 1,
                prev: w.cur,
                beta: w.beta,
                base: direct,
                vertex: resolve_vertex(self.scene, &direct),
                dir: Vec3::ZERO,
                rest: Vec3::ONE,
            };
            let s = PathSample {
                seed: w.seed,
                lobes: w.lobes,
                length,
                rc: length,
                ..direct
            };
            self.rc_candidate(&here, s)
        } else {
            PathSample {
                value: connection.value(w.beta),
                lobes: w.lobes,
                length,
                nee,
                ..PathSample::frozen(w.seed)
            }
        }
    }
}
