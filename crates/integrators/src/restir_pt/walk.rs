//! Random walks from a primary hit: initial sampling of ReSTIR PT paths, and their replay from
//! another primary hit with the same random numbers (the random-replay part of the replay and
//! hybrid shifts). Both are one function, so a replay at the pixel that generated a path
//! recomputes it bit for bit.
//!
//! # Fixed random budget
//!
//! Every vertex draws exactly [`RANDOMS_PER_BOUNCE`] numbers from the walk's own generator,
//! whatever happens there: light selection (1), point on the light (2), BSDF lobe (1), BSDF
//! direction (2), Russian roulette (1). The numbers of vertex `j` are therefore at a known
//! offset in the stream, and a replay that skips light sampling or roulette stays in step.
//! Candidate selection draws from a different generator.
//!
//! # Reconnection vertex
//!
//! The reconnection vertex of a path `x1 … x_n` is its first vertex `x_k`, `k ≥ 2`, such that
//! `x_{k−1}` is connectible ([`connectible`]: rough, no delta lobe), `x_k` is connectible or
//! is the path's light vertex, and `|x_k − x_{k−1}| ≥ d_near`. [`ShiftKind::Reconnection`]
//! only allows `k = 2`, [`ShiftKind::Replay`] none. The rule is a function of the path (its
//! vertices, materials and length), so a shifted path has the same `k` iff the shift checks it
//! (the invertibility checks of [`Walker::walk`] in replay mode).

use glam::Vec3;
use restir_geometry::{
    Ray, SurfaceInteraction, offset_ray_origin, shadow_ray_between, shadow_ray_towards,
};
use restir_gris::jacobian::geometry_term;
use restir_materials::LobeFlags;
use restir_sampling::{Pcg32, warp::power_heuristic};
use restir_scene::Scene;

use super::sample::resolve_vertex;
use super::sample::{Kind, PathSample, ShiftKind, Vertex, connectible, evaluate_unshadowed};
use crate::path::{EmissionMis, PrevVertex};
use crate::reuse::gbuffer::Receiver;
use crate::reuse::light_point::LightPoint;

pub use crate::path::RANDOMS_PER_BOUNCE;

/// A scattering vertex of a walk: the shading point as a [`Receiver`] (frame, `wo`, material),
/// its geometric normal and whether it is connectible.
#[derive(Clone, Copy, Debug)]
pub struct Vtx {
    /// Shading point, frame, direction back along the path, material.
    pub r: Receiver,
    /// Geometric normal (ray offsets).
    pub ng: Vec3,
    /// [`connectible`] of its material.
    pub conn: bool,
}

impl Vtx {
    /// A primary hit.
    #[inline]
    pub fn primary(scene: &Scene, r: &Receiver, ng: Vec3) -> Self {
        Self {
            r: *r,
            ng,
            conn: connectible(&r.resolve_bsdf(scene)),
        }
    }

    /// A surface hit, reached along `-to_prev`.
    #[inline]
    fn at(scene: &Scene, si: &SurfaceInteraction, to_prev: Vec3) -> Self {
        let bsdf = scene.shape_bsdf[si.shape as usize];
        Self {
            r: Receiver::new(si.p, &si.shading, si.uv, to_prev, bsdf, 0.0),
            ng: si.ng,
            conn: connectible(&scene.bsdf_at(bsdf, si.uv)),
        }
    }
}

/// What a replay ended with.
#[derive(Clone, Copy, Debug)]
pub enum Replayed {
    /// The replayed path leaves the sample's subspace (different lobes, an earlier connectible
    /// vertex, a miss, or a zero throughput): the shift fails.
    Fail,
    /// The prefix reached `y_{k−1}`; `thp` is the throughput of the bounces before it.
    Prefix {
        /// `y_{k−1}`.
        v: Vtx,
        /// Product of `f·|cos|/pdf` over the replayed bounces.
        thp: Vec3,
    },
    /// The whole path was replayed ([`Kind::Frozen`]): its integrand (zero when the light
    /// connection is occluded or carries nothing).
    Value(Vec3),
}

/// Walks paths for one render: the scene and the rules.
#[derive(Clone, Copy, Debug)]
pub struct Walker<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// Which reconnection vertices are allowed.
    pub shift: ShiftKind,
    /// Longest path in segments.
    pub max_depth: u32,
    /// Depth at which Russian roulette starts.
    pub rr_depth: u32,
    /// Square of the shortest reconnection segment.
    pub near2: f32,
    /// Negative control only: skip the invertibility checks (the replayed prefix has no earlier
    /// reconnection vertex; the vertex reconnected from is rough), which makes the shift
    /// non-bijective (biased).
    pub skip_invertibility: bool,
}

/// The reconnection vertex found along a walk.
#[derive(Clone, Copy, Debug)]
struct Rc {
    k: u32,
    /// `x_{k−1}` and the throughput of the bounces before it.
    prev: Vtx,
    thp: Vec3,
    /// The sample fields naming `x_k`.
    base: PathSample,
    /// Direction leaving `x_k` (set once sampled).
    dir: Vec3,
    /// Throughput of the bounces after `x_k`.
    rest: Vec3,
}

/// The two bits of a bounce's lobe stored in [`PathSample::lobes`].
#[inline]
fn lobe_bits(l: LobeFlags) -> u32 {
    u32::from(l.is_delta()) | (u32::from(l.contains(LobeFlags::TRANSMISSION)) << 1)
}

impl Walker<'_> {
    /// Whether vertex index `k` may be a reconnection vertex under this shift.
    #[inline]
    fn may_rc(&self, k: u32) -> bool {
        match self.shift {
            ShiftKind::Reconnection => k == 2,
            ShiftKind::Hybrid => true,
            ShiftKind::Replay => false,
        }
    }

    /// Whether `q` (if at a finite distance) is at least `d_near` from `p`.
    #[inline]
    fn far(&self, p: Vec3, q: Option<Vec3>) -> bool {
        q.is_none_or(|q| (q - p).length_squared() >= self.near2)
    }

    /// Whether the light vertex `v` (index `k`, the path's last) is the reconnection vertex of a
    /// path arriving from `prev`, given that no earlier vertex was.
    #[inline]
    fn end_eligible(&self, k: u32, prev: &Vtx, v: &Vertex) -> bool {
        self.may_rc(k) && prev.conn && self.far(prev.r.p, v.position())
    }

    /// Whether the surface vertex `next` (index `k`, not the path's last) is the reconnection
    /// vertex of a path arriving from `prev`, given that no earlier vertex was. `shape`, `prim`,
    /// `param` name it (its position is taken from them, as the shifts do).
    #[inline]
    fn mid_eligible(&self, k: u32, prev: &Vtx, next: &Vtx, si: &SurfaceInteraction) -> bool {
        if !(self.may_rc(k) && prev.conn && next.conn) {
            return false;
        }
        let p = restir_geometry::surface_at(&self.scene.shapes, si.shape, si.prim, si.param).p;
        self.far(prev.r.p, Some(p))
    }

    /// The reconnection of sample `s` from `prev` (throughput `thp` before it): the geometry
    /// term of `x_k` seen from `prev`, and the integrand without the visibility of
    /// `prev → x_k`, with where the shadow ray goes.
    #[inline]
    pub fn reconnect(
        &self,
        prev: &Vtx,
        thp: Vec3,
        s: &PathSample,
        v: &Vertex,
    ) -> (f32, Vec3, super::sample::Target) {
        let geometry = match v.area_point() {
            Some((p, n)) => geometry_term(prev.r.p.into(), p.into(), n.into()),
            None => 0.0,
        };
        let (f, target) = evaluate_unshadowed(self.scene, &prev.r, s, v);
        (geometry, thp * f, target)
    }

    /// Completes a candidate that reconnects at `rc` and computes its value.
    #[inline]
    fn rc_candidate(&self, rc: &Rc, mut s: PathSample) -> PathSample {
        let v = resolve_vertex(self.scene, &s);
        let (g, f, _) = self.reconnect(&rc.prev, rc.thp, &s, &v);
        s.geometry = g;
        s.value = f;
        s
    }

    /// One random walk from `x1` with the generator `seed`.
    ///
    /// * `replay = None`: initial sampling. Every light connection is passed to `sink` as
    ///   (sample, contribution estimate with Russian roulette); returns [`Replayed::Fail`].
    /// * `replay = Some(s)`: replays `s`'s random numbers from `x1` (another primary hit):
    ///   up to `y_{k−1}` for a sample with a reconnection vertex `k ≥ 3`
    ///   ([`Replayed::Prefix`]), the whole path for [`Kind::Frozen`] ([`Replayed::Value`]).
    ///   Light sampling happens only at the last vertex, Russian roulette never ends the path,
    ///   and the replay fails if a bounce picks a different lobe (delta / transmission) or, with
    ///   the hybrid shift, a vertex before `k` is eligible as a reconnection vertex.
    ///
    /// Returns the outcome and the rays traced.
    #[allow(clippy::too_many_lines)]
    pub fn walk(
        &self,
        x1: &Vtx,
        seed: Pcg32,
        replay: Option<&PathSample>,
        sink: &mut dyn FnMut(PathSample, Vec3),
    ) -> (Replayed, u64) {
        use Replayed::{Fail, Prefix, Value};
        let scene = self.scene;
        let lights = &scene.lights;
        let shapes = &scene.shapes;
        let check = !self.skip_invertibility;
        let mut rng = seed;
        let mut rays = 0u64;
        let mut cur = *x1;
        // Index of `cur` = segments from the camera to it.
        let mut j = 1u32;
        let mut thp = Vec3::ONE;
        let mut inv_q = 1.0f32;
        let mut eta_scale = 1.0f32;
        let mut lobes = 0u32;
        let mut rc: Option<Rc> = None;
        let frozen = PathSample {
            seed,
            rc: 0,
            kind: Kind::Frozen,
            ..PathSample::direct(
                LightPoint {
                    light: 0,
                    prim: 0,
                    param: glam::Vec2::ZERO,
                },
                Kind::Frozen,
            )
        };
        // The light connection a replay of a frozen path evaluates.
        let terminal = replay.filter(|s| s.kind == Kind::Frozen);
        if let Some(s) = replay
            && s.kind != Kind::Frozen
            && s.rc < 3
        {
            return (Prefix { v: cur, thp }, 0);
        }
        loop {
            let bsdf = &cur.r.resolve_bsdf(scene);
            let frame = cur.r.frame();
            let (u_select, u_light) = (rng.next_f32(), rng.next_2d());
            let (u_lobe, u_dir) = (rng.next_f32(), rng.next_2d());
            let u_rr = rng.next_f32();
            let len = (j + 1).min(255) as u8;

            // Light sampling at `cur`: a path of j + 1 segments.
            let nee_here = terminal.is_some_and(|s| s.nee && u32::from(s.length) == j + 1);
            if (replay.is_none() || nee_here)
                && j < self.max_depth
                && bsdf.has_smooth_lobe()
                && let Some(ls) = lights.sample(shapes, cur.r.p, u_select, u_light)
            {
                let direct =
                    PathSample::direct(LightPoint::from_light_sample(&ls), Kind::DirectNee);
                let eligible =
                    rc.is_none() && self.end_eligible(j + 1, &cur, &resolve_vertex(scene, &direct));
                if nee_here && eligible && check {
                    return (Fail, rays);
                }
                let wi = frame.to_local(ls.wi);
                let f = bsdf.eval(cur.r.wo, wi);
                if f != Vec3::ZERO {
                    rays += 1;
                    if shadow_visible(scene, cur.r.p, cur.ng, ls.p, ls.wi, ls.dist) {
                        let w = if ls.delta {
                            1.0
                        } else {
                            power_heuristic(ls.pdf_sa, bsdf.pdf_sa(cur.r.wo, wi))
                        };
                        let l = f * ls.le * (w / ls.pdf_sa);
                        if nee_here {
                            return (Value(thp * l), rays);
                        }
                        let sample = if let Some(rc) = &rc {
                            let s = if rc.k == j {
                                PathSample {
                                    dir: ls.wi,
                                    radiance: ls.le,
                                    light_pdf: if ls.delta { 0.0 } else { ls.pdf_sa },
                                    kind: Kind::NeeAtX2,
                                    length: len,
                                    nee: true,
                                    lobes,
                                    ..rc.base
                                }
                            } else {
                                PathSample {
                                    dir: rc.dir,
                                    radiance: rc.rest * l,
                                    kind: Kind::Continue,
                                    length: len,
                                    nee: true,
                                    lobes,
                                    ..rc.base
                                }
                            };
                            self.rc_candidate(rc, s)
                        } else if eligible {
                            let here = Rc {
                                k: j + 1,
                                prev: cur,
                                thp,
                                base: direct,
                                dir: Vec3::ZERO,
                                rest: Vec3::ONE,
                            };
                            let s = PathSample {
                                seed,
                                lobes,
                                length: len,
                                rc: len,
                                ..direct
                            };
                            self.rc_candidate(&here, s)
                        } else {
                            PathSample {
                                value: thp * l,
                                lobes,
                                length: len,
                                nee: true,
                                ..frozen
                            }
                        };
                        sink(sample, thp * inv_q * l);
                    }
                }
            }
            if nee_here {
                return (Value(Vec3::ZERO), rays);
            }

            // BSDF sampling at `cur`.
            let Some(bs) = bsdf.sample(cur.r.wo, u_lobe, u_dir) else {
                return (Fail, rays);
            };
            let bits = lobe_bits(bs.lobe);
            if j <= 16 {
                let shift = 2 * (j - 1);
                if let Some(s) = replay
                    && (s.lobes >> shift) & 3 != bits
                {
                    return (Fail, rays);
                }
                lobes |= bits << shift;
            }
            let factor = bs.f / bs.pdf_sa;
            let next_thp = thp * factor;
            let beta = next_thp * inv_q;
            let bmax = beta.max_element();
            if !(bmax > 0.0 && beta.is_finite()) {
                return (Fail, rays);
            }
            eta_scale *= bs.eta;
            if replay.is_none() && j >= self.rr_depth {
                let q = (bmax * eta_scale * eta_scale).min(0.95);
                if u_rr >= q {
                    return (Fail, rays);
                }
                inv_q /= q;
            }
            let d = frame.to_world(bs.wi);
            if let Some(rc) = &mut rc {
                if rc.k == j {
                    rc.dir = d;
                } else {
                    rc.rest *= factor;
                }
            }
            let prev = PrevVertex {
                p: cur.r.p,
                pdf_sa: bs.pdf_sa,
                delta: bs.lobe.is_delta(),
                mis: EmissionMis::Power,
            };
            let ray = Ray::new(offset_ray_origin(cur.r.p, cur.ng, d), d);
            rays += 1;
            let hit = scene.intersect(&ray);

            // Emission reached by the BSDF ray: a path of j + 1 segments.
            let hit_here = terminal.is_some_and(|s| !s.nee && u32::from(s.length) == j + 1);
            if replay.is_none() || hit_here {
                let emitted = match &hit {
                    None => lights.environment().map(|env| {
                        let le = lights.environment_radiance(d);
                        let lp = lights.pdf_sa(shapes, env, cur.r.p, cur.r.p + d, -d);
                        (LightPoint::environment(env, d), le, lp)
                    }),
                    Some(si) => lights.light_on_shape(si.shape).and_then(|light| {
                        let le = lights.area_radiance(light, si.shading.n, -d);
                        (le != Vec3::ZERO).then(|| {
                            let lp = lights.pdf_sa(shapes, light, cur.r.p, si.p, si.ng);
                            let y = LightPoint {
                                light,
                                prim: si.prim,
                                param: si.param,
                            };
                            (y, le, lp)
                        })
                    }),
                };
                if let Some((y, le, lp)) = emitted {
                    let w = prev.emission_weight(lp);
                    let direct = PathSample::direct(y, Kind::DirectHit);
                    let eligible = rc.is_none()
                        && self.end_eligible(j + 1, &cur, &resolve_vertex(scene, &direct));
                    if hit_here {
                        if eligible && check {
                            return (Fail, rays);
                        }
                        return (Value(next_thp * le * w), rays);
                    }
                    let sample = if let Some(rc) = &rc {
                        let s = if rc.k == j {
                            PathSample {
                                dir: rc.dir,
                                radiance: le,
                                light_pdf: if prev.delta { 0.0 } else { lp },
                                kind: Kind::HitAtX3,
                                length: len,
                                nee: false,
                                lobes,
                                ..rc.base
                            }
                        } else {
                            PathSample {
                                dir: rc.dir,
                                radiance: rc.rest * le * w,
                                kind: Kind::Continue,
                                length: len,
                                nee: false,
                                lobes,
                                ..rc.base
                            }
                        };
                        self.rc_candidate(rc, s)
                    } else if eligible {
                        let here = Rc {
                            k: j + 1,
                            prev: cur,
                            thp,
                            base: direct,
                            dir: Vec3::ZERO,
                            rest: Vec3::ONE,
                        };
                        let s = PathSample {
                            seed,
                            lobes,
                            length: len,
                            rc: len,
                            ..direct
                        };
                        self.rc_candidate(&here, s)
                    } else {
                        PathSample {
                            value: next_thp * le * w,
                            lobes,
                            length: len,
                            nee: false,
                            ..frozen
                        }
                    };
                    sink(sample, next_thp * inv_q * le * w);
                }
            }
            if hit_here {
                return (Value(Vec3::ZERO), rays);
            }
            let Some(si) = hit else {
                return (Fail, rays);
            };
            // Connections from the next vertex have j + 2 segments.
            if j + 2 > self.max_depth {
                return (Fail, rays);
            }
            let next = Vtx::at(scene, &si, -d);
            if rc.is_none() && self.mid_eligible(j + 1, &cur, &next, &si) {
                match replay {
                    None => {
                        let base = PathSample {
                            id: si.shape,
                            prim: si.prim,
                            param: si.param,
                            seed,
                            rc: (j + 1).min(255) as u8,
                            kind: Kind::Continue,
                            nee: false,
                            ..frozen
                        };
                        rc = Some(Rc {
                            k: j + 1,
                            prev: cur,
                            thp,
                            base,
                            dir: Vec3::ZERO,
                            rest: Vec3::ONE,
                        });
                    }
                    // An earlier reconnection vertex than the base path's: not invertible.
                    Some(s) if check && (s.kind == Kind::Frozen || j + 1 < u32::from(s.rc)) => {
                        return (Fail, rays);
                    }
                    Some(_) => {}
                }
            }
            thp = next_thp;
            cur = next;
            j += 1;
            if let Some(s) = replay
                && s.kind != Kind::Frozen
                && j + 1 == u32::from(s.rc)
            {
                return (Prefix { v: cur, thp }, rays);
            }
        }
    }
}

/// Whether a light sample is visible from surface point `p`.
#[inline]
pub(crate) fn shadow_visible(
    scene: &Scene,
    p: Vec3,
    ng: Vec3,
    lp: Vec3,
    wi: Vec3,
    dist: f32,
) -> bool {
    let (ray, t_max) = if dist.is_finite() {
        shadow_ray_between(p, ng, lp)
    } else {
        shadow_ray_towards(p, ng, wi, f32::INFINITY)
    };
    !scene.occluded(&ray, t_max)
}
