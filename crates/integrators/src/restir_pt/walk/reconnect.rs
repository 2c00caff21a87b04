//! The rule of a path's reconnection vertex (the `walk` module's doc), applied alike by initial
//! sampling, replays and the shifts, and the reconnection to that vertex.

use glam::Vec3;
use restir_geometry::SurfaceInteraction;
use restir_gris::jacobian::geometry_term;

use super::{ScatterVertex, Walker};
use crate::restir_pt::sample::{PathSample, Reconnection, ShiftKind, Vertex, evaluate_unshadowed};
use crate::shadow::ShadowTarget;

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

    /// Whether `prev → v` may be a path's reconnection segment under [`Walker::rule`] (the
    /// test of `v` itself, [`connectible`](crate::restir_pt::sample::connectible) for a
    /// surface, is separate). Used alike by initial
    /// sampling, by replays and by the shift's reconnection from `y_{k−1}`, so it is one
    /// function of the path.
    #[inline]
    pub fn segment_ok(&self, prev: &ScatterVertex, v: &Vertex) -> bool {
        match self.rule {
            Reconnection::Fixed => prev.conn && self.far(prev.r.p, v.position()),
            Reconnection::Footprint => prev.smooth && self.footprint_ok(prev, v),
        }
    }

    /// The footprint test of `prev → v` (the `walk` module doc).
    #[inline]
    fn footprint_ok(&self, prev: &ScatterVertex, v: &Vertex) -> bool {
        let (p, n) = match (v.area_point(), v.position()) {
            (Some((p, n)), _) => (p, Some(n)),
            (None, Some(p)) => (p, None),
            // A direction (the environment): no distance to judge by.
            (None, None) => return prev.conn,
        };
        let to = p - prev.r.p;
        let d2 = to.length_squared();
        if !(d2 > 0.0 && d2.is_finite()) {
            return false;
        }
        let wi = to / d2.sqrt();
        let cos = n.map_or(1.0, |n| n.dot(wi).abs());
        let pdf = prev.bsdf.pdf_sa(prev.r.wo, prev.r.frame().to_local(wi));
        d2 * cos >= self.footprint2 * prev.reach * prev.reach * pdf
    }

    /// Whether the light vertex `v` (index `k`, the path's last) is the reconnection vertex of a
    /// path arriving from `prev`, given that no earlier vertex was.
    #[inline]
    pub(super) fn end_eligible(&self, k: u32, prev: &ScatterVertex, v: &Vertex) -> bool {
        self.may_rc(k) && self.segment_ok(prev, v)
    }

    /// Whether the surface vertex `next` (index `k`, not the path's last) is the reconnection
    /// vertex of a path arriving from `prev`, given that no earlier vertex was. `shape`, `prim`,
    /// `param` name it (its position is taken from them, as the shifts do).
    #[inline]
    pub(super) fn mid_eligible(
        &self,
        k: u32,
        prev: &ScatterVertex,
        next: &ScatterVertex,
        si: &SurfaceInteraction,
    ) -> Option<Vertex> {
        if !(self.may_rc(k) && next.conn) {
            return None;
        }
        let at = restir_geometry::surface_at(&self.scene.shapes, si.shape, si.prim, si.param);
        let v = Vertex::Surface(at);
        self.segment_ok(prev, &v).then_some(v)
    }

    /// The reconnection of sample `s` from `prev` (throughput `beta` before it): the geometry
    /// term of `x_k` seen from `prev`, and the integrand without the visibility of
    /// `prev → x_k`, with where the shadow ray goes.
    #[inline]
    pub fn reconnect(
        &self,
        prev: &ScatterVertex,
        beta: Vec3,
        s: &PathSample,
        v: &Vertex,
    ) -> (f32, Vec3, Option<ShadowTarget>) {
        let geometry = match v.area_point() {
            Some((p, n)) => geometry_term(prev.r.p.into(), p.into(), n.into()),
            None => 0.0,
        };
        let (f, target) = evaluate_unshadowed(self.scene, self.nee, &prev.r, &prev.bsdf, s, v);
        (geometry, beta * f, target)
    }
}
