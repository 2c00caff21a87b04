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
//! `x_k` is connectible ([`connectible`]: rough, no delta lobe) or is the path's light vertex,
//! and the segment `x_{k−1} → x_k` passes the rule of [`Reconnection`] ([`Walker::segment_ok`]):
//!
//! * fixed (default): `x_{k−1}` is connectible and `|x_k − x_{k−1}| ≥ d_near`;
//! * footprint: `x_{k−1}` has no delta lobe ([`smooth`]) and
//!   `d² · |cos θ_k| ≥ T · w² · p_ω`, where `d = |x_k − x_{k−1}|`, `θ_k` the angle at `x_k`
//!   (geometric normal; 1 for a point light), `p_ω` the BSDF density at `x_{k−1}` of the
//!   direction to `x_k` (the lobe mixture, given the direction the path arrived from), and
//!   `w = θ_pixel · L` the width of the pixel's ray cone at `x_{k−1}`, `L` the path length from
//!   the camera to `x_{k−1}` (`ScatterVertex::reach`). Directions (the environment) pass when
//!   `x_{k−1}` is connectible.
//!
//! [`ShiftKind::Reconnection`] only allows `k = 2`, [`ShiftKind::Replay`] none. Either rule is
//! a function of the path (its vertices, materials, directions and length), so a shifted path
//! has the same `k` iff the shift checks it (the invertibility checks of [`Walker::walk`] in
//! replay mode, and of the reconnection from `y_{k−1}` in the shift).
//!
//! The rule and the reconnection live in `reconnect.rs`, the light connections (light sampling,
//! the emitter a BSDF ray reaches) in `light_connect.rs`; this file holds the walk itself.

use glam::{Vec2, Vec3};
use restir_geometry::{Frame, Ray, SurfaceInteraction, offset_ray_origin};
use restir_lights::NeeSelection;
use restir_materials::{Bsdf, LobeFlags};
use restir_sampling::Pcg32;
use restir_scene::Scene;

use super::sample::{Kind, PathSample, Reconnection, ShiftKind, Vertex, connectible, smooth};
use crate::path::{EmissionMis, PrevVertex, rr_survival};
use crate::reuse::gbuffer::Receiver;
use crate::shadow::{ShadowTarget, visible};

pub use crate::path::RANDOMS_PER_BOUNCE;

mod light_connect;
mod reconnect;

/// A vertex a walk scatters from (`x1`, the primary hit, or a later surface hit;
/// [`Vertex`] is the reconnection vertex `x_k` resolved from a sample):
/// the shading point as a [`Receiver`] (frame, `wo`, material), its geometric normal, its BSDF
/// with textures resolved, and whether it is connectible.
#[derive(Clone, Copy, Debug)]
pub struct ScatterVertex {
    /// Shading point, frame, direction back along the path, material.
    pub r: Receiver,
    /// The BSDF at the point, textures resolved once (every bounce from the vertex and every
    /// reconnection to it evaluates it).
    pub bsdf: Bsdf,
    /// Geometric normal (ray offsets).
    pub ng: Vec3,
    /// [`connectible`] of its material.
    pub conn: bool,
    /// [`smooth`] of its material (no delta lobe).
    pub smooth: bool,
    /// Path length from the camera to this vertex (the footprint rule's ray-cone width).
    pub reach: f32,
}

impl ScatterVertex {
    /// A primary hit.
    #[inline]
    pub fn primary(scene: &Scene, r: &Receiver, ng: Vec3) -> Self {
        let bsdf = r.resolve_bsdf(scene);
        Self {
            r: *r,
            bsdf,
            ng,
            conn: connectible(&bsdf),
            smooth: smooth(&bsdf),
            reach: r.depth,
        }
    }

    /// A surface hit, reached along `-to_prev`, `reach` from the camera along the path.
    #[inline]
    fn at(scene: &Scene, si: &SurfaceInteraction, to_prev: Vec3, reach: f32) -> Self {
        let r = Receiver::at_hit(scene, si, to_prev, 0.0);
        let resolved = r.resolve_bsdf(scene);
        Self {
            r,
            bsdf: resolved,
            ng: si.ng,
            conn: connectible(&resolved),
            smooth: smooth(&resolved),
            reach,
        }
    }
}

/// What a replay ended with.
#[derive(Clone, Copy, Debug)]
#[allow(clippy::large_enum_variant)] // `Prefix` is the usual outcome; boxing it would allocate per replay
pub enum Replayed {
    /// The replayed path leaves the sample's subspace (different lobes, an earlier connectible
    /// vertex, a miss, or a zero throughput): the shift fails.
    Fail,
    /// The prefix reached `y_{k−1}`; `beta` is the throughput of the bounces before it.
    Prefix {
        /// `y_{k−1}`.
        v: ScatterVertex,
        /// Product of `f·|cos|/pdf` over the replayed bounces.
        beta: Vec3,
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
    /// Square of the shortest reconnection segment (the fixed rule).
    pub near2: f32,
    /// The rule for the reconnection segment.
    pub rule: Reconnection,
    /// The footprint rule's `T · θ_pixel²` (see the module doc).
    pub footprint2: f32,
    /// Negative control only: skip the invertibility checks (the replayed prefix has no earlier
    /// reconnection vertex; the vertex reconnected from is rough), which makes the shift
    /// non-bijective (biased).
    pub skip_invertibility: bool,
    /// Whether the walks leave out the emission seen through delta lobes (a path whose every
    /// bounce took a delta lobe, ended on an emitter or the environment): the silhouette stage
    /// estimates it with the camera rays of its mask (`reuse/seen.rs`).
    pub seen_through_delta: bool,
    /// How light sampling at a vertex picks its light.
    pub nee: NeeSelection,
}

/// The two bits of a bounce's lobe stored in [`PathSample::lobes`].
#[inline]
fn lobe_bits(l: LobeFlags) -> u32 {
    u32::from(l.is_delta()) | (u32::from(l.contains(LobeFlags::TRANSMISSION)) << 1)
}

impl Walker<'_> {
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
    /// Every bounce is `Walker::bounce`: light sampling, BSDF sampling, the emitter the BSDF
    /// ray hits, and the step to the next vertex. Returns the outcome and the rays traced.
    pub fn walk(
        &self,
        x1: &ScatterVertex,
        seed: Pcg32,
        replay: Option<&PathSample>,
        sink: &mut dyn FnMut(PathSample, Vec3),
    ) -> (Replayed, u64) {
        let mut w = Walk {
            replay,
            terminal: replay.filter(|s| s.kind == Kind::Frozen),
            check: !self.skip_invertibility,
            seed,
            rng: seed,
            rays: 0,
            cur: *x1,
            j: 1,
            beta: Vec3::ONE,
            inv_q: 1.0,
            eta_scale: 1.0,
            lobes: 0,
            all_delta: true,
            rc: None,
        };
        if let Some(s) = replay
            && s.kind != Kind::Frozen
            && s.rc < 3
        {
            return (
                Replayed::Prefix {
                    v: w.cur,
                    beta: w.beta,
                },
                0,
            );
        }
        loop {
            if let Some(outcome) = self.bounce(&mut w, sink) {
                return (outcome, w.rays);
            }
        }
    }

    /// One bounce at `w.cur`; returns the walk's outcome if it ends here.
    fn bounce(&self, w: &mut Walk, sink: &mut dyn FnMut(PathSample, Vec3)) -> Option<Replayed> {
        let bsdf = &{ w.cur.bsdf };
        let frame = w.cur.r.frame();
        let u = BounceRandoms::draw(&mut w.rng);

        // Light sampling at `cur`: a path of j + 1 segments.
        let nee_here = w
            .terminal
            .is_some_and(|s| s.nee && u32::from(s.length) == w.j + 1);
        if (w.replay.is_none() || nee_here)
            && w.j < self.max_depth
            && bsdf.has_smooth_lobe()
            && let Some(end) = self.sample_light(w, bsdf, &frame, &u, nee_here, sink)
        {
            return Some(end);
        }
        if nee_here {
            return Some(Replayed::Value(Vec3::ZERO));
        }

        // BSDF sampling at `cur`, and the ray it traces.
        let Some(step) = self.sample_bsdf(w, bsdf, &frame, &u) else {
            return Some(Replayed::Fail);
        };
        let ray = Ray::new(offset_ray_origin(w.cur.r.p, w.cur.ng, step.d), step.d);
        w.rays += 1;
        let hit = self.scene.intersect(&ray);

        // Emission reached by the BSDF ray: a path of j + 1 segments.
        let hit_here = w
            .terminal
            .is_some_and(|s| !s.nee && u32::from(s.length) == w.j + 1);
        if (w.replay.is_none() || hit_here)
            && let Some(end) = self.hit_emitter(w, &step, hit.as_ref(), hit_here, sink)
        {
            return Some(end);
        }
        if hit_here {
            return Some(Replayed::Value(Vec3::ZERO));
        }
        let Some(si) = hit else {
            return Some(Replayed::Fail);
        };
        self.advance(w, &step, &si)
    }

    /// BSDF sampling at `w.cur` with the bounce's numbers `u`: the lobe check of a replay,
    /// Russian roulette (initial sampling only) and the throughput update of the reconnection
    /// vertex's suffix. `None` when the walk fails here.
    fn sample_bsdf(
        &self,
        w: &mut Walk,
        bsdf: &Bsdf,
        frame: &Frame,
        u: &BounceRandoms,
    ) -> Option<BsdfStep> {
        let (p, n, wo) = (w.cur.r.p, w.cur.r.n, w.cur.r.wo);
        let bs = bsdf.sample(wo, u.lobe, u.dir)?;
        let bits = lobe_bits(bs.lobe);
        if w.j <= 16 {
            let shift = 2 * (w.j - 1);
            if let Some(s) = w.replay
                && (s.lobes >> shift) & 3 != bits
            {
                return None;
            }
            w.lobes |= bits << shift;
        }
        w.all_delta &= bs.lobe.is_delta();
        let factor = bs.f / bs.pdf_sa;
        let next_beta = w.beta * factor;
        let beta_rr = next_beta * w.inv_q;
        let bmax = beta_rr.max_element();
        if !(bmax > 0.0 && beta_rr.is_finite()) {
            return None;
        }
        w.eta_scale *= bs.eta;
        if w.replay.is_none() && w.j >= self.rr_depth {
            let q = rr_survival(bmax, w.eta_scale);
            if u.rr >= q {
                return None;
            }
            w.inv_q /= q;
        }
        let d = frame.to_world(bs.wi);
        if let Some(rc) = &mut w.rc {
            if rc.k == w.j {
                rc.dir = d;
            } else {
                rc.rest *= factor;
            }
        }
        Some(BsdfStep {
            d,
            next_beta,
            prev: PrevVertex {
                p,
                n,
                pdf_sa: bs.pdf_sa,
                delta: bs.lobe.is_delta(),
                mis: EmissionMis::Power,
            },
        })
    }

    /// What follows the reconnection vertex `x_k` of `s` (a sample whose `x_k` is a surface:
    /// [`Kind::NeeAtX2`], [`Kind::HitAtX3`], [`Kind::Continue`]), evaluated afresh in this
    /// walker's scene — another frame of a moving sequence than the one `s` was found in.
    /// `xk` is `x_k` resolved in this scene (it moved with its shape) and `dir` the direction
    /// that left it, turned with its shape. Updates `s.dir`, `s.radiance` and
    /// `s.light_pdf_sa` (zero radiance where the suffix is now occluded) and returns the
    /// Jacobian of the map of the direction leaving `x_k` (solid angle to solid angle), or
    /// `None` when the suffix leaves the sample's subspace; `rays` counts the rays traced.
    ///
    /// * Light sampling at `x_k` ([`Kind::NeeAtX2`]) is drawn again with the path's stored
    ///   numbers of that bounce (selection, point): primary sample space in between, so the
    ///   direction's Jacobian is the ratio of the two frames' light-sampling densities,
    ///   `p_from(ω) / p_to(ω')` (the stored `light_pdf_sa` over the new one). A delta light in
    ///   either frame has no density: the shift fails, in both directions alike.
    /// * Otherwise the direction is kept on the shape (`dir`, a rotation: Jacobian 1) and traced:
    ///   an emitter reached along it ([`Kind::HitAtX3`]), or `x_{k+1}`, from which the rest of
    ///   the path is replayed with its stored numbers (primary sample space: Jacobian 1) to its
    ///   light connection, which must end as the stored one (length, technique, lobes).
    pub fn suffix_in_frame(
        &self,
        xk: &SurfaceInteraction,
        s: &mut PathSample,
        dir: Vec3,
        rays: &mut u64,
    ) -> Option<f32> {
        let scene = self.scene;
        let k = u32::from(s.rc);
        let mut rng = s.seed;
        rng.advance(RANDOMS_PER_BOUNCE as u64 * u64::from(k.saturating_sub(1)));
        let u = BounceRandoms::draw(&mut rng); // x_k's; `rng` is now at x_{k+1}'s
        match s.kind {
            Kind::NeeAtX2 => {
                if s.light_pdf_sa <= 0.0 {
                    return None;
                }
                let ls = scene.lights.sample_nee(
                    self.nee,
                    xk.p,
                    xk.shading.n,
                    (u.select, u.rr),
                    u.light,
                )?;
                if ls.delta || !(ls.pdf_sa > 0.0 && ls.pdf_sa.is_finite()) {
                    return None;
                }
                *rays += 1;
                let seen = visible(scene, xk.p, xk.ng, ShadowTarget::of_sample(&ls));
                let jacobian = s.light_pdf_sa / ls.pdf_sa;
                s.dir = ls.wi;
                s.radiance = if seen { ls.le } else { Vec3::ZERO };
                s.light_pdf_sa = ls.pdf_sa;
                Some(jacobian)
            }
            Kind::HitAtX3 | Kind::Continue => {
                if dir == Vec3::ZERO {
                    return None;
                }
                *rays += 1;
                let hit = scene.intersect(&Ray::new(offset_ray_origin(xk.p, xk.ng, dir), dir));
                s.dir = dir;
                if s.kind == Kind::HitAtX3 {
                    let (_, le, light_pdf_sa) = self.scene.lights.reached(
                        self.nee,
                        (xk.p, xk.shading.n),
                        dir,
                        hit.as_ref(),
                    )?;
                    s.radiance = le;
                    s.light_pdf_sa = light_pdf_sa;
                    return Some(1.0);
                }
                let si = hit?;
                let base = *s;
                let mut w = Walk {
                    replay: Some(&base),
                    terminal: Some(&base),
                    // The reconnection vertex is behind: nothing after it can be an earlier one.
                    check: false,
                    seed: base.seed,
                    rng,
                    rays: 0,
                    cur: ScatterVertex::at(scene, &si, -dir, 0.0),
                    j: k + 1,
                    beta: Vec3::ONE,
                    inv_q: 1.0,
                    eta_scale: 1.0,
                    lobes: 0,
                    all_delta: false,
                    rc: None,
                };
                let out = loop {
                    if let Some(out) = self.bounce(&mut w, &mut |_, _| {}) {
                        break out;
                    }
                };
                *rays += w.rays;
                match out {
                    Replayed::Value(l) => {
                        s.radiance = l;
                        Some(1.0)
                    }
                    _ => None,
                }
            }
            _ => Some(1.0),
        }
    }

    /// The step to the surface `si` the BSDF ray of `step` hit: the depth limit, the search for
    /// the reconnection vertex (and a replay's invertibility check), and the end of a replayed
    /// prefix at `y_{k−1}`.
    fn advance(&self, w: &mut Walk, step: &BsdfStep, si: &SurfaceInteraction) -> Option<Replayed> {
        // Connections from the next vertex have j + 2 segments.
        if w.j + 2 > self.max_depth {
            return Some(Replayed::Fail);
        }
        let reach = w.cur.reach + (si.p - w.cur.r.p).length();
        let next = ScatterVertex::at(self.scene, si, -step.d, reach);
        if w.rc.is_none()
            && let Some(vertex) = self.mid_eligible(w.j + 1, &w.cur, &next, si)
        {
            match w.replay {
                None => {
                    let base = PathSample {
                        id: si.shape,
                        prim: si.prim,
                        param: si.param,
                        seed: w.seed,
                        rc: (w.j + 1).min(255) as u8,
                        kind: Kind::Continue,
                        nee: false,
                        ..PathSample::frozen(w.seed)
                    };
                    w.rc = Some(Rc {
                        k: w.j + 1,
                        prev: w.cur,
                        beta: w.beta,
                        base,
                        vertex,
                        dir: Vec3::ZERO,
                        rest: Vec3::ONE,
                    });
                }
                // An earlier reconnection vertex than the base path's: not invertible.
                Some(s) if w.check && (s.kind == Kind::Frozen || w.j + 1 < u32::from(s.rc)) => {
                    return Some(Replayed::Fail);
                }
                Some(_) => {}
            }
        }
        w.beta = step.next_beta;
        w.cur = next;
        w.j += 1;
        if let Some(s) = w.replay
            && s.kind != Kind::Frozen
            && w.j + 1 == u32::from(s.rc)
        {
            return Some(Replayed::Prefix {
                v: w.cur,
                beta: w.beta,
            });
        }
        None
    }
}

/// The random numbers of one bounce, drawn in this order whatever happens at it (see
/// [`RANDOMS_PER_BOUNCE`]).
struct BounceRandoms {
    select: f32,
    light: Vec2,
    lobe: f32,
    dir: Vec2,
    rr: f32,
}

impl BounceRandoms {
    #[inline]
    fn draw(rng: &mut Pcg32) -> Self {
        let select = rng.next_f32();
        let light = rng.next_2d();
        let lobe = rng.next_f32();
        let dir = rng.next_2d();
        let rr = rng.next_f32();
        Self {
            select,
            light,
            lobe,
            dir,
            rr,
        }
    }
}

/// The reconnection vertex found along a walk.
#[derive(Clone, Copy, Debug)]
pub(super) struct Rc {
    pub(super) k: u32,
    /// `x_{k−1}` and the throughput of the bounces before it.
    pub(super) prev: ScatterVertex,
    pub(super) beta: Vec3,
    /// The sample fields naming `x_k`.
    pub(super) base: PathSample,
    /// `x_k` resolved from them ([`resolve_vertex`](super::sample::resolve_vertex)), once for all the walk's candidates.
    pub(super) vertex: Vertex,
    /// Direction leaving `x_k` (set once sampled).
    pub(super) dir: Vec3,
    /// Throughput of the bounces after `x_k`.
    pub(super) rest: Vec3,
}

/// The state of one walk.
pub(super) struct Walk<'s> {
    /// The sample being replayed (`None` in initial sampling).
    pub(super) replay: Option<&'s PathSample>,
    /// The replayed sample when it is frozen: the replay evaluates its light connection.
    pub(super) terminal: Option<&'s PathSample>,
    /// Whether the replay checks invertibility (not with `skip_invertibility`).
    pub(super) check: bool,
    /// The generator's state before the walk's first number (stored in the candidates).
    pub(super) seed: Pcg32,
    /// The walk's generator.
    pub(super) rng: Pcg32,
    /// Rays traced so far.
    pub(super) rays: u64,
    /// The current vertex `x_j`.
    pub(super) cur: ScatterVertex,
    /// `j`: segments from the camera to `cur`.
    pub(super) j: u32,
    /// Throughput of the bounces before `cur` (`Π f·|cos|/p`, without Russian roulette).
    pub(super) beta: Vec3,
    /// The inverse of the Russian roulette survival probabilities so far.
    pub(super) inv_q: f32,
    /// Product of the relative indices of refraction crossed (for Russian roulette).
    pub(super) eta_scale: f32,
    /// Lobe bits of the bounces so far ([`PathSample::lobes`]).
    pub(super) lobes: u32,
    /// Whether every bounce from the primary hit so far took a delta lobe.
    pub(super) all_delta: bool,
    /// The reconnection vertex, once found.
    pub(super) rc: Option<Rc>,
}

/// What BSDF sampling at a vertex produced.
struct BsdfStep {
    /// World-space direction of the continuation ray.
    d: Vec3,
    /// Throughput including this bounce.
    next_beta: Vec3,
    /// What MIS needs about this vertex when the ray hits an emitter.
    prev: PrevVertex,
}
