//! The distinct corners of a set of triangles, and whether they all lie behind a plane: the
//! convexity tests of a light's surface (`own.rs`: a light that cannot light itself; `clear.rs`:
//! a part of a mesh that shadow rays toward it need not enter).

use glam::Vec3;

/// The distinct corners of some triangles, by coordinate (so that a test over all of them runs
/// in SIMD lanes), with their bounds and their mean.
pub(crate) struct Corners {
    xs: Vec<f32>,
    ys: Vec<f32>,
    zs: Vec<f32>,
    /// The corners' bounding box.
    pub lo: Vec3,
    pub hi: Vec3,
    /// The mean of the distinct corners.
    pub centroid: Vec3,
}

impl Corners {
    /// The distinct `points` (equal when their coordinates are bit for bit equal); `None` when
    /// there are none or one is not finite.
    pub fn of(points: impl Iterator<Item = Vec3>) -> Option<Self> {
        let mut bits: Vec<[u32; 3]> = points.map(|p| p.to_array().map(f32::to_bits)).collect();
        bits.sort_unstable();
        bits.dedup();
        let points: Vec<Vec3> = bits
            .into_iter()
            .map(|c| Vec3::from_array(c.map(f32::from_bits)))
            .collect();
        if points.is_empty() || !points.iter().all(|p| p.is_finite()) {
            return None;
        }
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        let mut sum = Vec3::ZERO;
        for &p in &points {
            lo = lo.min(p);
            hi = hi.max(p);
            sum += p;
        }
        Some(Self {
            xs: points.iter().map(|p| p.x).collect(),
            ys: points.iter().map(|p| p.y).collect(),
            zs: points.iter().map(|p| p.z).collect(),
            lo,
            hi,
            centroid: sum / points.len() as f32,
        })
    }

    /// Whether every corner lies behind the plane through `a` with normal `n`, or within
    /// `tolerance` of it (along `n`'s length).
    pub fn behind(&self, n: Vec3, a: Vec3, tolerance: f32) -> bool {
        let limit = n.dot(a) + tolerance;
        let outside = self
            .xs
            .iter()
            .zip(&self.ys)
            .zip(&self.zs)
            .filter(|&((&x, &y), &z)| n.x * x + n.y * y + n.z * z > limit)
            .count();
        n.is_finite() && outside == 0
    }
}
