//! The shift map of ReSTIR PT between pixels (reconnection, random replay and hybrid), and
//! its part in the shared reuse passes (`PtReuse`).
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

use glam::Vec3;
use restir_gris::jacobian::{reconnection_jacobian_from_geometry, reject_jacobian};
use restir_gris::{ShiftMap, Shifted};
use restir_sampling::luminance;

use restir_scene::Scene;

use crate::motion::FrameMotion;
use crate::reuse::gbuffer::GBuffer;
use crate::reuse::shift::ReuseShift;
use crate::shadow::visible;

use super::sample::{
    Kind, PathSample, Reconnection, ShiftKind, Vertex, connectible, resolve_vertex,
};
use super::walk::{Replayed, ScatterVertex, Walker};
use super::{PtReservoir, RestirPtSettings};

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
    /// When the previous pass was the previous frame of a sequence in which shapes or lights
    /// moved: that frame and how it relates to this one.
    pub frames: Option<Frames<'a>>,
    /// Rays traced by this map's shifts (shadow rays and replayed segments).
    pub rays: Cell<u64>,
    /// Symmetric Jacobian rejection bound (`max(J, 1/J)`); 0 for none.
    pub max_jacobian: f32,
    /// Negative control: Jacobian 1 (biased).
    pub unit_jacobian: bool,
    /// Negative control: reject only `J > max_jacobian` (biased).
    pub one_sided_jacobian: bool,
}

/// The previous frame, for shifts between the domains of two frames (`docs/ANIMATION.md`,
/// "ReSTIR PT across frames").
#[derive(Clone, Copy, Debug)]
pub struct Frames<'a> {
    /// The walks' rules in the previous frame's scene (its geometry, lights and `d_near`).
    pub walker: Walker<'a>,
    /// Each shape's rigid motion and the light correspondence between the frames.
    pub motion: &'a FrameMotion,
    /// Negative control only: a shift into a previous domain is taken in the current frame's
    /// scene, as if the previous pixel's primary hit lay there (biased).
    pub current_scene: bool,
    /// Negative control only: a shift across frames keeps the suffix the path cached in its
    /// own frame (the radiance beyond `x_k`, its direction and light density) instead of
    /// evaluating it in the destination frame (biased).
    pub stale_suffix: bool,
}

impl PtShift<'_> {
    /// The primary hit of domain `d`, as a vertex of `scene`.
    #[inline]
    fn hit(&self, d: usize, scene: &Scene) -> Option<ScatterVertex> {
        let n = self.gbuf.receivers.len();
        let (buf, i) = if d < n {
            (self.gbuf, d)
        } else {
            (self.prev?, d - n)
        };
        buf.receiver(i)
            .map(|r| ScatterVertex::primary(scene, r, buf.ng[i]))
    }

    #[inline]
    fn count(&self, rays: u64) {
        self.rays.set(self.rays.get() + rays);
    }

    /// The target (luminance, with visibility), the Jacobian and the shifted sample (its
    /// `value` the integrand at `to`) of shifting `s` from pixel `from` to pixel `to`; `None` if
    /// the shift is not defined there.
    ///
    /// Between the domains of two frames in which shapes or lights moved ([`Frames`]), the
    /// destination's walk is in the destination frame's scene: the replayed prefix, `x_k`
    /// (named by shape, primitive and parameters, so it moved with its shape; a light vertex's
    /// light renamed through the frames' correspondence, failing where the light does not
    /// exist), the reconnection and its visibility, and what follows `x_k`
    /// ([`Walker::suffix_in_frame`]). The reconnection Jacobian `G_y / G_x` takes `G_x` as the
    /// source frame cached it and `G_y` in the destination frame (a rigid motion keeps area on
    /// `x_k`'s shape); the suffix contributes its own factor.
    pub fn shift_full(
        &self,
        from: usize,
        to: usize,
        s: &PathSample,
    ) -> Option<(f32, f32, PathSample)> {
        let n = self.gbuf.receivers.len();
        let to_prev = to >= n;
        // Across frames: the motion and its direction (towards the previous frame or not).
        let across = self
            .frames
            .filter(|f| (from >= n) != to_prev && !(to_prev && f.current_scene));
        let walker = match (&self.frames, to_prev) {
            (Some(f), true) if !f.current_scene => &f.walker,
            _ => &self.walker,
        };
        let scene = walker.scene;
        let y1 = self.hit(to, scene)?;
        if s.kind == Kind::Frozen {
            // Primary sample space throughout: replayed in the destination's scene, J = 1.
            if walker.shift == ShiftKind::Reconnection {
                return None;
            }
            let (out, rays) = walker.walk(&y1, s.seed, Some(s), &mut |_, _| {});
            self.count(rays);
            let Replayed::Value(f) = out else {
                return None;
            };
            let p = luminance(f);
            let p = if p > 0.0 && p.is_finite() { p } else { 0.0 };
            let value = if p > 0.0 { f } else { Vec3::ZERO };
            return Some((p, 1.0, PathSample { value, ..*s }));
        }
        let (prev, beta) = if s.rc <= 2 {
            (y1, Vec3::ONE)
        } else {
            let (out, rays) = walker.walk(&y1, s.seed, Some(s), &mut |_, _| {});
            self.count(rays);
            match out {
                Replayed::Prefix { v, beta } => (v, beta),
                _ => return None,
            }
        };
        // The sample as the destination's frame names it.
        let mut s = *s;
        if let Some(f) = &across
            && s.is_direct()
        {
            s.id = f.motion.map_light(s.id, to_prev)?;
        }
        let v = resolve_vertex(scene, &s);
        // `x_k` was connectible on the base path; within one scene its material is the same
        // at every pixel, so only a shift across frames (another scene) tests it again.
        if across.is_some()
            && let Vertex::Surface(si) = &v
            && !connectible(&scene.bsdf(si))
        {
            return None;
        }
        // Invertibility (ii): the inverse shift reconnects from `y_{k−1}` only if the segment
        // `y_{k−1} → x_k` passes the reconnection rule (the fixed rule's roughness test of
        // `y_{k−1}` is what `skip_invertibility` skips).
        let segment_ok = match walker.rule {
            Reconnection::Fixed => {
                (prev.conn || walker.skip_invertibility)
                    && v.position()
                        .is_none_or(|p| (p - prev.r.p).length_squared() >= walker.near2)
            }
            Reconnection::Footprint => walker.skip_invertibility || walker.segment_ok(&prev, &v),
        };
        if !segment_ok {
            return None;
        }
        let mut suffix_jacobian = 1.0;
        if let Some(f) = &across
            && let Vertex::Surface(si) = &v
            && !f.stale_suffix
        {
            let dir = f.motion.turn_direction(si.shape, s.dir, to_prev);
            let mut rays = 0;
            let j = walker.suffix_in_frame(si, &mut s, dir, &mut rays);
            self.count(rays);
            suffix_jacobian = j?;
        }
        let (geometry, f, target) = walker.reconnect(&prev, beta, &s, &v);
        let jacobian = if v.area_point().is_some() {
            reconnection_jacobian_from_geometry(geometry, s.geometry)
        } else {
            1.0
        } * suffix_jacobian;
        if jacobian.is_nan() || jacobian <= 0.0 || jacobian.is_infinite() {
            return None;
        }
        if self.max_jacobian > 0.0 {
            let reject = if self.one_sided_jacobian {
                jacobian > self.max_jacobian
            } else {
                reject_jacobian(jacobian, self.max_jacobian)
            };
            if reject {
                return None;
            }
        }
        let jacobian = if self.unit_jacobian { 1.0 } else { jacobian };
        let mut p = luminance(f);
        if !(p > 0.0 && p.is_finite()) {
            p = 0.0;
        } else {
            self.count(1);
            if !target.is_some_and(|t| visible(scene, prev.r.p, prev.ng, t)) {
                p = 0.0;
            }
        }
        let shifted = PathSample {
            geometry,
            value: if p > 0.0 { f } else { Vec3::ZERO },
            ..s
        };
        Some((p, jacobian, shifted))
    }
}

impl ShiftMap<PathSample> for PtShift<'_> {
    type Domain = usize;

    #[inline]
    fn shift(&self, from: &usize, to: &usize, x: &PathSample) -> Option<Shifted<PathSample>> {
        let (destination_target, jacobian, sample) = self.shift_full(*from, *to, x)?;
        Some(Shifted {
            sample,
            jacobian,
            destination_target,
        })
    }
}

/// ReSTIR PT's part in the reuse passes: its shift map between pixels, whose domains are pixel
/// indices (`n + i` for pixel `i` of the previous pass).
pub(super) struct PtReuse<'p> {
    /// The walks' rules.
    pub(super) walker: Walker<'p>,
    /// The settings (the Jacobian options).
    pub(super) settings: &'p RestirPtSettings,
    /// This pass's primary hits.
    pub(super) gbuf: &'p GBuffer,
    /// The previous pass's primary hits.
    pub(super) prev: Option<&'p GBuffer>,
    /// The previous frame, when the previous pass was its last and shapes or lights moved.
    pub(super) frames: Option<Frames<'p>>,
    /// Pixels per pass: pixel `i` of the previous pass is domain `n + i`.
    pub(super) pixels: usize,
}

impl<'p> PtReuse<'p> {
    /// A shift map with its own ray count.
    #[inline]
    pub(super) fn shift(&self) -> PtShift<'p> {
        PtShift {
            walker: self.walker,
            gbuf: self.gbuf,
            prev: self.prev,
            frames: self.frames,
            rays: Cell::new(0),
            max_jacobian: self.settings.max_jacobian,
            unit_jacobian: self.settings.unit_jacobian,
            one_sided_jacobian: self.settings.one_sided_jacobian,
        }
    }
}

impl ReuseShift for PtReuse<'_> {
    type Sample = PathSample;
    type Domain = usize;
    type DomainRef<'d>
        = usize
    where
        Self: 'd;
    type Map<'m>
        = PtShift<'m>
    where
        Self: 'm;

    #[inline]
    fn map(&self, _canonical: &PtReservoir) -> PtShift<'_> {
        self.shift()
    }

    #[inline]
    fn rays(map: &PtShift<'_>) -> u64 {
        map.rays.get()
    }

    #[inline]
    fn domain(&self, index: usize, previous: bool) -> usize {
        if previous { self.pixels + index } else { index }
    }

    /// The same initial path: shifts keep the walk's random-number state.
    #[inline]
    fn same_sample(a: &PathSample, b: &PathSample) -> bool {
        a.seed == b.seed && a.kind == b.kind && a.length == b.length
    }

    /// A path's value at its pixel over its target there, `luminance(value)`.
    #[inline]
    fn ratio(sample: &PathSample) -> Option<[f32; 3]> {
        let p = luminance(sample.value);
        Some(if p > 0.0 && p.is_finite() {
            (sample.value / p).to_array()
        } else {
            [0.0; 3]
        })
    }
}
