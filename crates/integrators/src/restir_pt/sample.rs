//! The ReSTIR PT sample (a path from the primary hit, stored compactly), its integrand at any
//! pixel and the reconnection shift between pixels.
//!
//! # Sample space and measure
//!
//! A pixel's domain is its primary hit `x1`. A sample is a path `x1 → x2 → …` ending in one light
//! connection, together with the technique of that connection (light sampling or BSDF
//! sampling). Its measure is the product of
//!
//! * the solid angle of the direction `ω1` from `x1` to `x2` (counting measure when `x2` is a
//!   point light; the direction itself for lights at infinity),
//! * the solid angle of the direction `ω2` leaving `x2` (area measure of the light point turned
//!   into solid angle at `x2`, which does not move), and
//! * for everything after `x3`, the base path's own sampling density without Russian roulette
//!   (`μ_rest`): it depends only on vertices from `x2` on, which the shift keeps.
//!
//! The integrand is `f_s(x1)·|cos|·V(x1, x2) · f_s(x2)·|cos| · L_rest · m`, where `m` is the
//! NEE/BSDF power-heuristic weight of the path's light connection. When that connection is at
//! `x1` or `x2` the weight depends on the incoming direction and is recomputed at every pixel;
//! further down it is part of the stored suffix radiance.
//!
//! # Reconnection shift
//!
//! `T_{i→c}` keeps `x2` and everything after it and replaces `x1` by pixel `c`'s primary hit
//! `y1`. Only `ω1` changes, so the Jacobian is the solid-angle reconnection Jacobian
//! `(cos θ_y / cos θ_x)·(d_x² / d_y²)` with `x2`'s geometric normal (1 for point lights and
//! lights at infinity). The shift fails, in both directions alike, unless both primary hits and
//! `x2` are rough, both primary hits are at least `d_near` from `x2`, and `x2` did not scatter by
//! a delta lobe. Visibility of `y1 → x2` is part of the target.

use std::cell::Cell;

use glam::{Vec2, Vec3};
use restir_geometry::{SurfaceInteraction, shadow_ray_between, shadow_ray_towards, surface_at};
use restir_gris::jacobian::{reconnection_jacobian_from_points, reject_jacobian};
use restir_gris::{ShiftMap, Shifted};
use restir_materials::{Bsdf, BsdfKind};
use restir_sampling::{luminance, warp::power_heuristic};
use restir_scene::Scene;

use crate::gbuffer::{GBuffer, Receiver};
use crate::restir_di::light_point::{LightPoint, Resolved, resolve};

/// Smallest microfacet roughness (Mitsuba `alpha`) a surface may have to reconnect at.
pub const ROUGH_ALPHA: f32 = 0.04;

/// How a stored path ends, relative to its reconnection vertex `x2`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Kind {
    /// Light sampling at `x1`; `x2` is the light point.
    DirectNee,
    /// The BSDF ray from `x1` hit an emitter (or left the scene) at `x2`.
    DirectHit,
    /// Light sampling at `x2` towards `dir`.
    NeeAtX2,
    /// The BSDF ray from `x2` along `dir` hit an emitter (or left the scene).
    HitAtX3,
    /// The path continues from `x2` along `dir`; its light connection is at `x3` or later.
    Continue,
    /// `x2` scattered by a delta lobe: the path cannot be reconnected at `x2`; `radiance` holds
    /// everything after `x1`.
    Frozen,
}

/// A path sample: 48 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSample {
    /// The light (direct kinds) or the shape of `x2`.
    pub id: u32,
    /// Primitive of `x2`.
    pub prim: u32,
    /// Barycentrics / sphere parameters of `x2` (for the environment: the direction's encoding).
    pub param: Vec2,
    /// Direction leaving `x2` (world space; unused by the direct kinds).
    pub dir: Vec3,
    /// Radiance arriving at `x2` along `dir`: the light's for [`Kind::NeeAtX2`] and
    /// [`Kind::HitAtX3`], the suffix estimate (throughput over sampling densities, times the
    /// emission and its MIS weight) for [`Kind::Continue`], everything after `x1` for
    /// [`Kind::Frozen`].
    pub radiance: Vec3,
    /// Light-sampling density (solid angle at `x2`, selection included) of the light connection
    /// at `x2`, for its MIS weight; 0 for delta lights.
    pub light_pdf: f32,
    /// How the path ends.
    pub kind: Kind,
    /// Path length in segments from the camera.
    pub length: u8,
}

impl PathSample {
    /// A path whose light connection is at `x1` (light point `y`).
    pub fn direct(y: LightPoint, kind: Kind) -> Self {
        Self {
            id: y.light,
            prim: y.prim,
            param: y.param,
            dir: Vec3::ZERO,
            radiance: Vec3::ZERO,
            light_pdf: 0.0,
            kind,
            length: 2,
        }
    }

    /// Whether `x2` is a light point (the path ends there).
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
            let term = if s.kind == Kind::Frozen {
                s.radiance
            } else {
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

/// The reconnection shift between pixels; a domain is a pixel index into `gbuf`, or, from the
/// pixel count on, `pixel count + index` into `prev` (the previous pass, for temporal reuse).
#[derive(Debug)]
pub struct PtShift<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The primary hits.
    pub gbuf: &'a GBuffer,
    /// The previous pass's primary hits (temporal reuse).
    pub prev: Option<&'a GBuffer>,
    /// Shadow rays traced by this map's shifts.
    pub rays: Cell<u64>,
    /// Square of the shortest reconnection segment.
    pub near_distance2: f32,
    /// Symmetric Jacobian rejection bound (`max(J, 1/J)`); 0 for none.
    pub max_jacobian: f32,
    /// Negative control: Jacobian 1 (biased).
    pub unit_jacobian: bool,
}

impl PtShift<'_> {
    /// The primary hit and geometric normal of domain `d`.
    #[inline]
    fn hit(&self, d: usize) -> Option<(&Receiver, Vec3)> {
        let n = self.gbuf.receivers.len();
        let (buf, i) = if d < n {
            (self.gbuf, d)
        } else {
            (self.prev?, d - n)
        };
        buf.receiver(i).map(|r| (r, buf.ng[i]))
    }

    /// The target (with visibility) and the Jacobian of shifting `s` from pixel `from` to pixel
    /// `to`; `None` if the shift is not defined there.
    pub fn shift_full(&self, from: usize, to: usize, s: &PathSample) -> Option<(f32, f32, Vec3)> {
        if s.kind == Kind::Frozen {
            return None;
        }
        let ((src, _), (dst, dst_ng)) = (self.hit(from)?, self.hit(to)?);
        if !connectible(&src.resolve_bsdf(self.scene))
            || !connectible(&dst.resolve_bsdf(self.scene))
        {
            return None;
        }
        let v = resolve_vertex(self.scene, s);
        if let Vertex::Surface(si) = &v
            && !connectible(&self.scene.bsdf(si))
        {
            return None;
        }
        if let Some(p) = v.position()
            && ((p - src.p).length_squared() < self.near_distance2
                || (p - dst.p).length_squared() < self.near_distance2)
        {
            return None;
        }
        let jacobian = match v.area_point() {
            Some((p, n)) => {
                reconnection_jacobian_from_points(src.p.into(), dst.p.into(), p.into(), n.into())
            }
            None => 1.0,
        };
        if jacobian.is_nan() || jacobian <= 0.0 {
            return None;
        }
        if self.max_jacobian > 0.0 && reject_jacobian(jacobian, self.max_jacobian) {
            return None;
        }
        let jacobian = if self.unit_jacobian { 1.0 } else { jacobian };
        let (f, target) = evaluate_unshadowed(self.scene, dst, s, &v);
        let mut p = luminance(f);
        if !(p > 0.0 && p.is_finite()) {
            p = 0.0;
        } else {
            self.rays.set(self.rays.get() + 1);
            if !visible(self.scene, dst, dst_ng, target) {
                p = 0.0;
            }
        }
        Some((p, jacobian, if p > 0.0 { f } else { Vec3::ZERO }))
    }
}

impl ShiftMap<PathSample> for PtShift<'_> {
    type Domain = usize;

    #[inline]
    fn shift(&self, from: &usize, to: &usize, x: &PathSample) -> Option<Shifted<PathSample>> {
        let (target_pdf, jacobian, _) = self.shift_full(*from, *to, x)?;
        Some(Shifted {
            sample: *x,
            jacobian,
            target_pdf,
        })
    }
}
