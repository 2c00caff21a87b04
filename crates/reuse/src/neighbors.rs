//! Spatial-reuse neighbour selection shared by the screen-space ReSTIR estimators
//! (Bitterli et al. 2020, §6).
//!
//! A fixed table of points of the R2 low-discrepancy sequence inside the unit disk; each pixel
//! walks it from its own random start, so neighbour sets differ between pixels (no correlation
//! aliasing) while staying well spread. Candidates off the image, on the pixel itself, without a
//! surface or failing the host's similarity test are skipped; up to `2k` points are
//! tried for `k` neighbours. The choice depends only on the surfaces and the pixel's random
//! stream, never on reservoirs, so it does not bias the reuse.

use glam::Vec2;
use restir_sampling::{Pcg32, sequences::r2};

use crate::surfaces::{Similarity, Surfaces};

/// Points in the table; a power of two, so that indices wrap with a mask.
const OFFSET_COUNT: usize = 8192;

/// How neighbours are picked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeighborRule {
    /// Neighbours wanted, `k`.
    pub count: usize,
    /// Disk radius in pixels.
    pub radius: f32,
    /// Which pixels may be neighbours.
    pub similarity: Similarity,
}

/// The table of disk offsets.
#[derive(Clone, Debug)]
pub struct NeighborPattern {
    offsets: Vec<Vec2>,
}

impl Default for NeighborPattern {
    fn default() -> Self {
        Self::new()
    }
}

impl NeighborPattern {
    /// The R2 points inside the unit disk.
    pub fn new() -> Self {
        let mut offsets = Vec::with_capacity(OFFSET_COUNT);
        let mut i = 0u64;
        while offsets.len() < OFFSET_COUNT {
            let [u, v] = r2(i, [0.5, 0.5]);
            i += 1;
            let p = Vec2::new(2.0 * u - 1.0, 2.0 * v - 1.0);
            if p.length_squared() <= 1.0 {
                offsets.push(p);
            }
        }
        Self { offsets }
    }

    /// Writes into `out` the pixel indices of up to `rule.count` neighbours of pixel `index`
    /// (none when it has no surface), drawing the start point from `rng`.
    pub fn select<G: Surfaces>(
        &self,
        surfaces: &G,
        index: usize,
        rule: &NeighborRule,
        rng: &mut Pcg32,
        out: &mut Vec<usize>,
    ) {
        out.clear();
        if !surfaces.has_surface(index) {
            return;
        }
        let (w, h) = (surfaces.width() as i64, surfaces.height() as i64);
        let (x, y) = ((index as i64) % w, (index as i64) / w);
        let mask = self.offsets.len() - 1;
        let start = rng.next_u32() as usize;
        for attempt in 0..2 * rule.count {
            if out.len() == rule.count {
                break;
            }
            let o = self.offsets[(start + attempt) & mask] * rule.radius;
            let (nx, ny) = (x + round(o.x), y + round(o.y));
            if nx < 0 || ny < 0 || nx >= w || ny >= h || (nx == x && ny == y) {
                continue;
            }
            let q = (ny * w + nx) as usize;
            if surfaces.similar(index, q, &rule.similarity) {
                out.push(q);
            }
        }
    }
}

/// Nearest integer (half away from zero) without a libm call.
#[inline]
fn round(v: f32) -> i64 {
    (v + 0.5f32.copysign(v)) as i64
}
