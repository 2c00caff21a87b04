//! The ReSTIR PT sample (a path from the primary hit, stored compactly), the shift kinds that
//! decide its reconnection vertex, and its integrand at any pixel.
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
//!
//! The shifts between pixels are in [`super::shift`].

use glam::{Vec2, Vec3};
use restir_geometry::{SurfaceInteraction, surface_at};
use restir_materials::{Bsdf, BsdfKind};
use restir_sampling::{Pcg32, warp::power_heuristic};
use restir_scene::Scene;

use crate::reuse::gbuffer::Receiver;
use restir_lights::{LightPoint, NeeSelection, Resolved};

use crate::shadow::ShadowTarget;

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

/// The rule that picks a path's reconnection vertex (`--reconnection`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reconnection {
    /// Fixed thresholds: `x_{k−1}` and `x_k` [`connectible`] (material roughness) and
    /// `|x_k − x_{k−1}| ≥ d_near` (a fraction of the scene radius).
    Fixed,
    /// The footprint rule (after Lin, Kettunen and Wyman's footprint-based reconnection,
    /// "ReSTIR PT Enhanced"): `x_{k−1}` has no delta lobe, `x_k` is [`connectible`] (or the
    /// light vertex), and the area the BSDF lobe of `x_{k−1}` spreads over at `x_k`,
    /// `d² / (|cos θ_k| · p_ω)`, is at least `T` times the squared width of the pixel's ray
    /// cone at `x_{k−1}` (pixel angle × path length from the camera): the reconnection is made
    /// only where moving `x_{k−1}` by a few pixels' footprint turns the segment by little
    /// compared to the lobe (`walk.rs`).
    Footprint,
}

impl Reconnection {
    /// The name `--reconnection` takes.
    pub fn name(self) -> &'static str {
        match self {
            Reconnection::Fixed => "fixed",
            Reconnection::Footprint => "footprint",
        }
    }
}

/// A path sample: a path from the primary hit `x1`, named by its walk's random-number state
/// and, when it has one, its reconnection vertex `x_k` (the "rc vertex"; `k ≥ 2`, `x1` is the
/// primary hit). Geometry is never copied: `x_k` is named by (shape, primitive, parameters).
/// The kinds are relative to `x_k`; `id`, `prim`, `param`, `dir`, `radiance` and `light_pdf_sa`
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
    pub light_pdf_sa: f32,
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
            light_pdf_sa: 0.0,
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

    /// The template of a path without a reconnection vertex ([`Kind::Frozen`]) walked with the
    /// generator `seed`.
    pub fn frozen(seed: Pcg32) -> Self {
        Self {
            seed,
            rc: 0,
            kind: Kind::Frozen,
            ..Self::direct(
                LightPoint {
                    light: 0,
                    prim: 0,
                    param: Vec2::ZERO,
                },
                Kind::Frozen,
            )
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
        Vertex::Light(scene.lights.resolve(&s.light_point()))
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
            Vertex::Light(
                Resolved::Surface { p, .. } | Resolved::Point { p, .. } | Resolved::Spot { p, .. },
            ) => Some(p),
            Vertex::Surface(si) => Some(si.p),
            Vertex::Light(Resolved::Direction { .. }) => None,
        }
    }
}

/// Whether a BSDF is rough enough to reconnect at: no delta lobe (a `mask`'s pass-through is
/// one), and a diffuse lobe or a microfacet roughness of at least [`ROUGH_ALPHA`]; a blend
/// when both its components are.
pub fn connectible(bsdf: &Bsdf) -> bool {
    if bsdf.is_masked() {
        return false;
    }
    match bsdf.kind {
        BsdfKind::Diffuse { .. } => true,
        BsdfKind::RoughConductor { microfacet, .. }
        | BsdfKind::RoughDielectric { microfacet, .. } => microfacet.alpha() >= ROUGH_ALPHA,
        BsdfKind::RoughPlastic(p) => p.microfacet.alpha() >= ROUGH_ALPHA,
        BsdfKind::Blend(b) => b.parts().iter().all(connectible),
        _ => false,
    }
}

/// Whether a BSDF has no delta lobe and some lobe `eval` can evaluate (the footprint rule's
/// test of the vertex a path reconnects from; its lobe width is judged from the direction's
/// density instead of a roughness threshold).
pub fn smooth(bsdf: &Bsdf) -> bool {
    bsdf.has_smooth_lobe() && !bsdf.flags().is_delta()
}

/// The integrand of sample `s` at receiver `r` (whose BSDF, textures resolved, is `bsdf1`)
/// without the visibility of `r → x2` (RGB, in the sample's measure), and where its shadow ray
/// goes (`None` when the integrand is zero).
#[inline]
pub fn evaluate_unshadowed(
    scene: &Scene,
    nee: NeeSelection,
    r: &Receiver,
    bsdf1: &Bsdf,
    s: &PathSample,
    v: &Vertex,
) -> (Vec3, Option<ShadowTarget>) {
    let frame1 = r.frame();
    match v {
        Vertex::Light(resolved) => {
            let Some(c) = resolved.contact(&scene.lights, &s.light_point(), r.p) else {
                return (Vec3::ZERO, None);
            };
            let wi = frame1.to_local(c.wi);
            let f = bsdf1.eval(r.wo, wi);
            if f == Vec3::ZERO {
                return (Vec3::ZERO, None);
            }
            let light_pdf_sa = || {
                scene
                    .lights
                    .pdf_nee(nee, (s.id, s.prim), r.p, r.n, c.p, c.ng)
            };
            let w = match (s.kind, c.delta) {
                (Kind::DirectNee, true) => 1.0,
                (Kind::DirectNee, false) => power_heuristic(light_pdf_sa(), bsdf1.pdf_sa(r.wo, wi)),
                (_, true) => 0.0,
                (_, false) => power_heuristic(bsdf1.pdf_sa(r.wo, wi), light_pdf_sa()),
            };
            (f * c.le * w, Some(ShadowTarget::of_contact(&c)))
        }
        Vertex::Surface(si) => {
            let to = si.p - r.p;
            let d2 = to.length_squared();
            if d2.is_nan() || d2 <= 0.0 {
                return (Vec3::ZERO, None);
            }
            let w1 = to / d2.sqrt();
            let f1 = bsdf1.eval(r.wo, frame1.to_local(w1));
            if f1 == Vec3::ZERO {
                return (Vec3::ZERO, None);
            }
            let term = {
                let bsdf2 = scene.bsdf(si);
                let wo2 = si.shading.to_local(-w1);
                let wi2 = si.shading.to_local(s.dir);
                let f2 = bsdf2.eval(wo2, wi2);
                if f2 == Vec3::ZERO {
                    return (Vec3::ZERO, None);
                }
                let w = match s.kind {
                    Kind::NeeAtX2 if s.light_pdf_sa > 0.0 => {
                        power_heuristic(s.light_pdf_sa, bsdf2.pdf_sa(wo2, wi2))
                    }
                    Kind::HitAtX3 => power_heuristic(bsdf2.pdf_sa(wo2, wi2), s.light_pdf_sa),
                    _ => 1.0,
                };
                f2 * s.radiance * w
            };
            (f1 * term, Some(ShadowTarget::Point(si.p)))
        }
    }
}
