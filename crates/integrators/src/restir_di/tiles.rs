//! Screen-tile light selection for ReSTIR DI's initial candidates (`--light-sampler tiles`).
//!
//! The power sampler ignores distance, so in a scene of many small lights most candidates land
//! on lights far from the pixel; the light hierarchy's descent knows distance but costs a chain
//! of node tests per candidate, at random places in memory, which grows with the emitter count.
//! Here, once per pass, every 16×16-pixel tile of the film gets a cut of the light hierarchy for
//! its primary hits ([`LightSet::light_cut`](restir_lights::LightSet::light_cut)): near lights
//! one by one, far clusters whole, each weighted by its importance for every receiver of the
//! tile. The cut is drawn from once per tile into a pool of points on lights
//! ([`LightSet::presample_cut`](restir_lights::LightSet::presample_cut)), and the tile's pixels
//! take their candidates from the pool as the learned cells' receivers take theirs: a read
//! from a small array per candidate.
//!
//! **Unbiased.** The cut's importance is conservative for the whole tile, so an emitter that
//! can light any of its receivers keeps a positive probability; each pool entry is an
//! independent draw of the cut carrying the cut's probability exactly. Targets, reuse and the
//! light/BSDF split (which weighs by the power sampler's density) are untouched.
//!
//! **Deterministic.** A tile's pool comes from a stream of the pass named by the tile's place
//! on the film, and a cropped render's region is aligned to the tiles
//! ([`PixelWindow::with_halo`](crate::PixelWindow::with_halo)), so every tile it holds sees the
//! same receivers as in the whole render: crops, chains and thread counts give the same image.

use glam::Vec3;
use rayon::prelude::*;
use restir_lights::LearnedDraw;
use restir_scene::Scene;

use crate::pass::PassContext;
use crate::reuse::gbuffer::GBuffer;

/// Tile side in pixels (a multiple of the crop alignment's divisor, so crops hold whole tiles).
pub const TILE: usize = 16;
/// Nodes per tile's cut.
pub const CUT_NODES: usize = 256;
/// How many candidates of a pass one pool entry serves on average.
pub const USES_PER_ENTRY: usize = 8;
/// A tile's normals count as one (the cut weighs the receivers' cosine) when every one is
/// within about 2.6° of their mean.
const SAME_NORMAL: f32 = 0.999;

/// Per-tile pools of draws from the tiles' light cuts, for one pass.
#[derive(Debug)]
pub struct LightTiles {
    tiles_x: usize,
    pools: Vec<Vec<Option<LearnedDraw>>>,
    nodes: usize,
    hierarchy_nodes: usize,
}

/// What one pass's tiles held, for `--stats`.
#[derive(Clone, Copy, Debug)]
pub struct CutSummary {
    /// Tiles with a cut.
    pub tiles: usize,
    /// Nodes over all their cuts.
    pub nodes: usize,
    /// Entries over all their pools.
    pub entries: usize,
    /// Nodes of the whole hierarchy.
    pub hierarchy_nodes: usize,
}

impl CutSummary {
    /// One line: how the tiles cut the hierarchy and how large their pools were.
    pub fn describe(&self) -> String {
        let per = |n: usize| n as f64 / self.tiles.max(1) as f64;
        format!(
            "last pass: {} tiles of {TILE}×{TILE} pixels (those with a receiver outside the learned \
             cells), each a cut of the light hierarchy ({} nodes) into at most {CUT_NODES} nodes \
             (mean {:.0}) and a pool of {:.0} draws from it (mean)",
            self.tiles,
            self.hierarchy_nodes,
            per(self.nodes),
            per(self.entries)
        )
    }
}

impl LightTiles {
    /// Bytes per pixel of the pools, on average (`candidates` per pixel).
    pub fn bytes_per_pixel(candidates: u32) -> usize {
        (candidates as usize * std::mem::size_of::<Option<LearnedDraw>>()).div_ceil(USES_PER_ENTRY)
    }

    /// Builds the tiles' pools for the primary hits of `gbuf` with `candidates` candidates per
    /// receiver, from the streams of stage `stage` of pass `ctx`, for the tiles with a receiver
    /// for which `needed(pixel)` holds (the others get none); `None` if the scene has no local
    /// light. `claim_power` weighs the draws as the power sampler's (the tests' negative
    /// control).
    pub fn build(
        scene: &Scene,
        ctx: &PassContext,
        gbuf: &GBuffer,
        candidates: u32,
        claim_power: bool,
        stage: u64,
        needed: impl Fn(usize) -> bool + Sync,
    ) -> Option<Self> {
        let lights = &scene.lights;
        if lights.emitter_count() == 0 {
            return None;
        }
        lights.build_hierarchy();
        let tiles_x = gbuf.width.div_ceil(TILE);
        let tiles_y = gbuf.height.div_ceil(TILE);
        let per_tile: Vec<(usize, Vec<Option<LearnedDraw>>)> = (0..tiles_x * tiles_y)
            .into_par_iter()
            .map(|t| {
                let (tx, ty) = (t % tiles_x, t / tiles_x);
                let rows = ty * TILE..((ty + 1) * TILE).min(gbuf.height);
                let cols = tx * TILE..((tx + 1) * TILE).min(gbuf.width);
                let receivers = || {
                    rows.clone().flat_map({
                        let cols = cols.clone();
                        move |y| cols.clone().map(move |x| y * gbuf.width + x)
                    })
                };
                // Mean position and normal of the tile's hits, and how far they spread.
                let (mut sum_p, mut sum_n, mut count, mut need) =
                    (Vec3::ZERO, Vec3::ZERO, 0usize, false);
                for i in receivers() {
                    if let Some(r) = gbuf.receiver(i) {
                        sum_p += r.p;
                        sum_n += r.n;
                        count += 1;
                        need |= needed(i);
                    }
                }
                if count == 0 || !need {
                    return (0, Vec::new());
                }
                let p = sum_p / count as f32;
                let mean_n = sum_n.normalize_or_zero();
                let (mut spread2, mut same) = (0.0f32, mean_n != Vec3::ZERO);
                for i in receivers() {
                    if let Some(r) = gbuf.receiver(i) {
                        spread2 = spread2.max((r.p - p).length_squared());
                        same &= r.n.dot(mean_n) >= SAME_NORMAL;
                    }
                }
                let n = if same { mean_n } else { Vec3::ZERO };
                let Some(cut) = lights.light_cut(p, n, spread2.sqrt(), CUT_NODES) else {
                    return (0, Vec::new());
                };
                let k = candidates.max(1) as usize;
                let mut pool = vec![None; (count * k).div_ceil(USES_PER_ENTRY).max(k)];
                // The tile's stream is named by its place on the film.
                let (fx, fy) = ctx.film_xy(rows.start * gbuf.width + cols.start, gbuf.width);
                let key = (u64::from(fy) / TILE as u64) << 32 | (u64::from(fx) / TILE as u64);
                let mut rng = ctx.pass_stream(stage, key);
                lights.presample_cut(&cut, &mut rng, claim_power, &mut pool);
                (cut.len(), pool)
            })
            .collect();
        let nodes = per_tile.iter().map(|(n, _)| n).sum();
        let pools = per_tile.into_iter().map(|(_, p)| p).collect();
        Some(Self {
            tiles_x,
            pools,
            nodes,
            hierarchy_nodes: lights.build_hierarchy(),
        })
    }

    /// The pool of the tile holding pixel `(x, y)` of the G-buffer, if it has one.
    #[inline]
    pub fn pool(&self, x: usize, y: usize) -> Option<&[Option<LearnedDraw>]> {
        let pool = &self.pools[(y / TILE) * self.tiles_x + x / TILE];
        (!pool.is_empty()).then_some(&pool[..])
    }

    /// What the tiles hold, for `--stats`.
    pub fn summary(&self) -> CutSummary {
        let with_pool = self.pools.iter().filter(|p| !p.is_empty());
        CutSummary {
            tiles: with_pool.clone().count(),
            nodes: self.nodes,
            entries: with_pool.map(Vec::len).sum(),
            hierarchy_nodes: self.hierarchy_nodes,
        }
    }
}
