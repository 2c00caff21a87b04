//! The ReSTIR PT sample (a path from the primary hit, stored compactly), its integrand at any
//! pixel and the shift map between pixels (reconnection, random replay, hybrid).
//!
//! # Sample space and measure
//!
//! A pixel's domain is its primary hit `x1`. A sample is a path `x1 → x2 → …` ending in one light
//! connection, together with the technique of that connection (light sampling or BSDF
//! sampling), and its reconnection vertex `x_k` if it has one ([`super::walk`]). The sample space
//! is split by length, technique and `k`; the measure of each part is the product of
//!
//! * primary sample space (the random numbers) for the bounces at `x1 … x_{k−2}`,
//! * the solid angle of the direction `ω_{k−1}` from `x_{k−1}` to `x_k` (counting measure when
//!   `x_k` is a point light; the direction itself for lights at infinity),
//! * the solid angle of the direction `ω_k` leaving `x_k` (area measure of the light point turned
//!   into solid angle at `x_k`, which does not move), and
//! * for everything after `x_{k+1}`, the base path's own sampling density without Russian
//!   roulette (`μ_rest`): it depends only on vertices from `x_k` on, which the shift keeps.
//!
//! Paths without a reconnection vertex ([`Kind::Frozen`]) are in primary sample space
//! throughout. The integrand is `Π f_s|cos|/p (replayed bounces) · f_s(x_{k−1})·|cos|·
//! V(x_{k−1}, x_k) · f_s(x_k)·|cos| · L_rest · m`, where `m` is the NEE/BSDF power-heuristic
//! weight of the path's light connection. When that connection is at `x_{k−1}` or `x_k` the
//! weight depends on the incoming direction and is recomputed at every pixel; further down it
//! is part of the stored suffix radiance.
//!
//! # Shifts
//!
//! `T_{i→c}` replays the bounces at `x1 … x_{k−2}` from pixel `c`'s primary hit `y1` with the
//! sample's random numbers (nothing for `k = 2`: the reconnection shift), keeps `x_k` and
//! everything after it, and reconnects `y_{k−1} → x_k`. Replayed bounces have Jacobian 1
//! (primary sample space); the reconnection has the solid-angle Jacobian
//! `(cos θ_y / cos θ_x)·(d_x² / d_y²) = G_y / G_x` with `x_k`'s geometric normal (1 for point
//! lights and lights at infinity), from the `G_x` cached in the sample. Frozen paths are replayed
//! whole (Jacobian 1). The shift fails, in both directions alike, when the replayed prefix leaves
//! the sample's subspace (different lobes, an earlier reconnection vertex), when `y_{k−1}` is
//! not rough or closer than `d_near` to `x_k`, or by the symmetric Jacobian bound. Visibility of
//! `y_{k−1} → x_k` is part of the target.

use std::cell::Cell;

use glam::{Vec2, Vec3};
use restir_geometry::{SurfaceInteraction, shadow_ray_between, shadow_ray_towards, surface_at};
use restir_gris::jacobian::{reconnection_jacobian_from_geometry, reject_jacobian};
use restir_gris::{ShiftMap, Shifted};
use restir_materials::{Bsdf, BsdfKind};
use restir_sampling::{Pcg32, luminance, warp::power_heuristic};
use restir_scene::Scene;

use crate::reuse::gbuffer::{GBuffer, Receiver};
use crate::reuse::light_point::{LightPoint, Resolved, resolve};

use super::walk::{Replayed, Vtx, Walker};

/// Smallest microfacet roughness (Mitsuba `alpha`) a surface may have to reconnect at.
pub const ROUGH_ALPHA: f32 = 0.04;

/// How a stored path ends, relative to its reconnection vertex `x_k` (the names are those of
/// `k = 2`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Kind {
    /// Light sampling at `x_{k−1}`; `x_k` is the light point.
    DirectNee,
    /// The BSDF ray from `x_{k−1}` hit an emitter (or left the scene) at `x_k`.
    DirectHit,
    /// Light sampling at `x_k` towards `dir`.
    NeeAtX2,
    /// The BSDF ray from `x_k` along `dir` hit an emitter (or left the scene).
    HitAtX3,
    /// The path continues from `x_k` along `dir`; its light connection is further down.
    Continue,
    /// The path has no reconnection vertex: the hybrid and replay shifts replay all of it, the
    /// reconnection shift never moves it.
    Frozen,
}

/// The shift between pixels (`--shift`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShiftKind {
    /// Reconnection at `x2` only (paths whose `x1`/`x2` are not rough or too close stay put).
    Reconnection,
    /// Random replay of the whole path from the destination's primary hit.
    Replay,
    /// Replay up to `x_{k−1}`, then reconnection at the first connectible vertex `x_k`.
    Hybrid,
}

impl ShiftKind {
    /// The name `--shift` takes.
    pub fn name(self) -> &'static str {
        match self {
            ShiftKind::Reconnection => "reconnection",
            ShiftKind::Replay => "replay",
            ShiftKind::Hybrid => "hybrid",
        }
    }
}

/// A path sample: a path from the primary hit `x1`, named by its walk's random-number state
/// and, when it has one, its reconnection vertex `x_k` (the "rc vertex"; `k ≥ 2`, `x1` is the
/// primary hit). Geometry is never copied: `x_k` is named by (shape, primitive, parameters).
/// The kinds are relative to `x_k`; `id`, `prim`, `param`, `dir`, `radiance` and `light_pdf`
/// describe `x_k` and what follows it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSample {
    /// The light (direct kinds) or the shape of `x_k`.
    pub id: u32,
    /// Primitive of `x_k`.
    pub prim: u32,
    /// Barycentrics / sphere parameters of `x_k` (for the environment: the direction's encoding).
    pub param: Vec2,
    /// Direction leaving `x_k` (world space; unused by the direct kinds).
    pub dir: Vec3,
    /// Radiance arriving at `x_k` along `dir`: the light's for [`Kind::NeeAtX2`] and
    /// [`Kind::HitAtX3`], the suffix estimate (throughput over sampling densities, times the
    /// emission and its MIS weight) for [`Kind::Continue`].
    pub radiance: Vec3,
    /// Light-sampling density (solid angle at `x_k`, selection included) of the light connection
    /// at `x_k`, for its MIS weight; 0 for delta lights.
    pub light_pdf: f32,
    /// The integrand (RGB, in the sample's measure) at the domain the sample currently lives in:
    /// set by initial sampling and by every shift, so shading needs no re-evaluation.
    pub value: Vec3,
    /// Geometry term `|cos θ| / d²` of `x_k` (geometric normal) seen from `x_{k−1}` on this
    /// path: the cached part of the reconnection Jacobian (0 for point lights and directions).
    pub geometry: f32,
    /// The walk's random-number state before its first number: replaying it from another
    /// primary hit regenerates the prefix (`x2 … x_{k−1}`, or the whole path for
    /// [`Kind::Frozen`]).
    pub seed: Pcg32,
    /// Lobe flags of the first 16 bounces (`x1`, `x2`, …), 2 bits each: delta, transmission.
    pub lobes: u32,
    /// How the path ends.
    pub kind: Kind,
    /// Path length in segments from the camera.
    pub length: u8,
    /// Index `k` of the reconnection vertex (2: the first bounce vertex); 0 for [`Kind::Frozen`].
    pub rc: u8,
    /// Whether the path's light connection is light sampling (else a BSDF ray hit an emitter).
    pub nee: bool,
}

impl PathSample {
    /// A path whose light connection is at `x_{k−1}` (light point `y`, which is `x_k`).
    pub fn direct(y: LightPoint, kind: Kind) -> Self {
        Self {
            id: y.light,
            prim: y.prim,
            param: y.param,
            dir: Vec3::ZERO,
            radiance: Vec3::ZERO,
            light_pdf: 0.0,
            value: Vec3::ZERO,
            geometry: 0.0,
            seed: Pcg32::default(),
            lobes: 0,
            kind,
            length: 2,
            rc: 2,
            nee: kind == Kind::DirectNee,
        }
    }

    /// Whether `x_k` is a light point (the path ends there).
    #[inline]
    pub fn is_direct(&self) -> bool {
        matches!(self.kind, Kind::DirectNee | Kind::DirectHit)
    }

    fn light_point(&self) -> LightPoint {
        LightPoint {
            light: self.id,
            prim: self.prim,
            param: self.param,
        }
    }
}

/// `x2` in world space.
#[derive(Clone, Copy, Debug)]
pub enum Vertex {
    /// A light point (direct kinds).
    Light(Resolved),
    /// A surface point.
    Surface(SurfaceInteraction),
}

/// Resolves `x2` of `s`.
#[inline]
pub fn resolve_vertex(scene: &Scene, s: &PathSample) -> Vertex {
    if s.is_direct() {
        Vertex::Light(resolve(scene, &s.light_point()))
    } else {
        Vertex::Surface(surface_at(&scene.shapes, s.id, s.prim, s.param))
    }
}

impl Vertex {
    /// Position and geometric normal when the vertex is at a finite distance and not a point
    /// light (the reconnection Jacobian is 1 otherwise).
    #[inline]
    pub fn area_point(&self) -> Option<(Vec3, Vec3)> {
        match *self {
            Vertex::Light(Resolved::Surface { p, ng, .. }) => Some((p, ng)),
            Vertex::Surface(si) => Some((si.p, si.ng)),
            _ => None,
        }
    }

    /// The position, when at a finite distance (point lights included).
    #[inline]
    pub fn position(&self) -> Option<Vec3> {
        match *self {
            Vertex::Light(Resolved::Surface { p, .. } | Resolved::Point { p, .. }) => Some(p),
            Vertex::Surface(si) => Some(si.p),
            Vertex::Light(Resolved::Direction { .. }) => None,
        }
    }
}

/// Whether a BSDF is rough enough to reconnect at: no delta lobe, and a diffuse lobe or a
/// microfacet roughness of at least [`ROUGH_ALPHA`].
pub fn connectible(bsdf: &Bsdf) -> bool {
    match bsdf.kind {
        BsdfKind::Diffuse { .. } => true,
        BsdfKind::RoughConductor { microfacet, .. }
        | BsdfKind::RoughDielectric { microfacet, .. } => microfacet.alpha() >= ROUGH_ALPHA,
        BsdfKind::RoughPlastic(p) => p.microfacet.alpha() >= ROUGH_ALPHA,
        _ => false,
    }
}

/// The integrand of sample `s` at receiver `r` without the visibility of `r → x2` (RGB, in the
/// sample's measure), and the point a shadow ray must reach (`None` with a direction for lights
/// at infinity).
#[inline]
pub fn evaluate_unshadowed(
    scene: &Scene,
    r: &Receiver,
    s: &PathSample,
    v: &Vertex,
) -> (Vec3, Target) {
    let bsdf1 = &r.resolve_bsdf(scene);
    let frame1 = r.frame();
    match v {
        Vertex::Light(resolved) => {
            let Some(c) = resolved.contact(r.p) else {
                return (Vec3::ZERO, Target::None);
            };
            let wi = frame1.to_local(c.wi);
            let f = bsdf1.eval(r.wo, wi);
            if f == Vec3::ZERO {
                return (Vec3::ZERO, Target::None);
            }
            let light_pdf = || scene.lights.pdf_sa(&scene.shapes, s.id, r.p, c.p, c.ng);
            let w = match (s.kind, c.delta) {
                (Kind::DirectNee, true) => 1.0,
                (Kind::DirectNee, false) => power_heuristic(light_pdf(), bsdf1.pdf_sa(r.wo, wi)),
                (_, true) => 0.0,
                (_, false) => power_heuristic(bsdf1.pdf_sa(r.wo, wi), light_pdf()),
            };
            let target = if c.dist.is_finite() {
                Target::Point(c.p)
            } else {
                Target::Direction(c.wi)
            };
            (f * c.le * w, target)
        }
        Vertex::Surface(si) => {
            let to = si.p - r.p;
            let d2 = to.length_squared();
            if d2.is_nan() || d2 <= 0.0 {
                return (Vec3::ZERO, Target::None);
            }
            let w1 = to / d2.sqrt();
            let f1 = bsdf1.eval(r.wo, frame1.to_local(w1));
            if f1 == Vec3::ZERO {
                return (Vec3::ZERO, Target::None);
            }
            let term = {
                let bsdf2 = scene.bsdf(si);
                let wo2 = si.shading.to_local(-w1);
                let wi2 = si.shading.to_local(s.dir);
                let f2 = bsdf2.eval(wo2, wi2);
                if f2 == Vec3::ZERO {
                    return (Vec3::ZERO, Target::None);
                }
                let w = match s.kind {
                    Kind::NeeAtX2 if s.light_pdf > 0.0 => {
                        power_heuristic(s.light_pdf, bsdf2.pdf_sa(wo2, wi2))
                    }
                    Kind::HitAtX3 => power_heuristic(bsdf2.pdf_sa(wo2, wi2), s.light_pdf),
                    _ => 1.0,
                };
                f2 * s.radiance * w
            };
            (f1 * term, Target::Point(si.p))
        }
    }
}

/// Where the shadow ray of a reconnection goes.
#[derive(Clone, Copy, Debug)]
pub enum Target {
    /// Nothing to test (the integrand is zero).
    None,
    /// A point at a finite distance.
    Point(Vec3),
    /// A direction to infinity.
    Direction(Vec3),
}

/// Whether `target` is visible from receiver `r` (geometric normal `ng`).
#[inline]
pub fn visible(scene: &Scene, r: &Receiver, ng: Vec3, target: Target) -> bool {
    let (ray, t_max) = match target {
        Target::None => return false,
        Target::Point(p) => shadow_ray_between(r.p, ng, p),
        Target::Direction(d) => shadow_ray_towards(r.p, ng, d, f32::INFINITY),
    };
    !scene.occluded(&ray, t_max)
}

/// The shift between pixels (reconnection, replay or hybrid, as [`Walker::shift`] says); a
/// domain is a pixel index into `gbuf`, or, from the pixel count on, `pixel count + index` into
/// `prev` (the previous pass, for temporal reuse).
#[derive(Debug)]
pub struct PtShift<'a> {
    /// The walks' rules (scene, shift, depth, `d_near`).
    pub walker: Walker<'a>,
    /// The primary hits.
    pub gbuf: &'a GBuffer,
    /// The previous pass's primary hits (temporal reuse).
    pub prev: Option<&'a GBuffer>,
    /// Rays traced by this map's shifts (shadow rays and replayed segments).
    pub rays: Cell<u64>,
    /// Symmetric Jacobian rejection bound (`max(J, 1/J)`); 0 for none.
    pub max_jacobian: f32,
    /// Negative control: Jacobian 1 (biased).
    pub unit_jacobian: bool,
}

impl PtShift<'_> {
    /// The primary hit of domain `d`.
    #[inline]
    fn hit(&self, d: usize) -> Option<Vtx> {
        let n = self.gbuf.receivers.len();
        let (buf, i) = if d < n {
            (self.gbuf, d)
        } else {
            (self.prev?, d - n)
        };
        buf.receiver(i)
            .map(|r| Vtx::primary(self.walker.scene, r, buf.ng[i]))
    }

    /// The target (luminance, with visibility), the Jacobian and the shifted sample (its
    /// `value` the integrand at `to`) of shifting `s` from pixel `from` to pixel `to`; `None` if
    /// the shift is not defined there.
    pub fn shift_full(
        &self,
        from: usize,
        to: usize,
        s: &PathSample,
    ) -> Option<(f32, f32, PathSample)> {
        let _ = from;
        let walker = &self.walker;
        let scene = walker.scene;
        let y1 = self.hit(to)?;
        if s.kind == Kind::Frozen {
            if walker.shift == ShiftKind::Reconnection {
                return None;
            }
            let (out, rays) = walker.walk(&y1, s.seed, Some(s), &mut |_, _| {});
            self.rays.set(self.rays.get() + rays);
            let Replayed::Value(f) = out else {
                return None;
            };
            let p = luminance(f);
            let p = if p > 0.0 && p.is_finite() { p } else { 0.0 };
            let value = if p > 0.0 { f } else { Vec3::ZERO };
            return Some((p, 1.0, PathSample { value, ..*s }));
        }
        let (prev, thp) = if s.rc <= 2 {
            (y1, Vec3::ONE)
        } else {
            let (out, rays) = walker.walk(&y1, s.seed, Some(s), &mut |_, _| {});
            self.rays.set(self.rays.get() + rays);
            match out {
                Replayed::Prefix { v, thp } => (v, thp),
                _ => return None,
            }
        };
        // Invertibility (ii): the inverse shift reconnects from `y_{k−1}` only if it is rough.
        if !prev.conn && !walker.skip_invertibility {
            return None;
        }
        let v = resolve_vertex(scene, s);
        if let Vertex::Surface(si) = &v
            && !connectible(&scene.bsdf(si))
        {
            return None;
        }
        if let Some(p) = v.position()
            && (p - prev.r.p).length_squared() < walker.near2
        {
            return None;
        }
        let (geometry, f, target) = walker.reconnect(&prev, thp, s, &v);
        let jacobian = if v.area_point().is_some() {
            reconnection_jacobian_from_geometry(geometry, s.geometry)
        } else {
            1.0
        };
        if jacobian.is_nan() || jacobian <= 0.0 {
            return None;
        }
        if self.max_jacobian > 0.0 && reject_jacobian(jacobian, self.max_jacobian) {
            return None;
        }
        let jacobian = if self.unit_jacobian { 1.0 } else { jacobian };
        let mut p = luminance(f);
        if !(p > 0.0 && p.is_finite()) {
            p = 0.0;
        } else {
            self.rays.set(self.rays.get() + 1);
            if !visible(scene, &prev.r, prev.ng, target) {
                p = 0.0;
            }
        }
        let shifted = PathSample {
            geometry,
            value: if p > 0.0 { f } else { Vec3::ZERO },
            ..*s
        };
        Some((p, jacobian, shifted))
    }
}

impl ShiftMap<PathSample> for PtShift<'_> {
    type Domain = usize;

    #[inline]
    fn shift(&self, from: &usize, to: &usize, x: &PathSample) -> Option<Shifted<PathSample>> {
        let (target_pdf, jacobian, sample) = self.shift_full(*from, *to, x)?;
        Some(Shifted {
            sample,
            jacobian,
            target_pdf,
        })
    }
}
