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
//! take their candidates from the pool: a read from a small array per candidate. With learning
//! across passes ([`super::learn`]) a tile has one pool per learned cell its receivers are in,
//! drawn from the mixture of the cell's table and the tile's cut: the cut is the learned
//! table's defensive part, in place of the power sampler.
//!
//! **Unbiased.** The cut's importance is conservative for the whole tile, so an emitter that
//! can light any of its receivers keeps a positive probability (with learning, the cut's share
//! of the mixture keeps it); each pool entry is an independent draw carrying its mixture's
//! probability exactly. Targets, reuse and the light/BSDF split (which weighs by the power
//! sampler's density) are untouched.
//!
//! **Deterministic.** A tile's pools come from streams of the pass named by the tile's place
//! on the film (and the cell), and a cropped render's region is aligned to the tiles
//! ([`PixelWindow::with_halo`](crate::PixelWindow::with_halo)), so every tile it holds sees the
//! same receivers as in the whole render: crops, chains and thread counts give the same image.

use glam::Vec3;
use rayon::prelude::*;
use restir_lights::{Claim, LearnedDraw, LearnedSampler};
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

/// A tile's pools: per learned cell its receivers are in (`None`: the cut alone), the draws.
type TilePools = Vec<(Option<u32>, Vec<Option<LearnedDraw>>)>;

/// What one tile's build gives: its cut's node count, its pools, and per receiver (a pixel of
/// the G-buffer) the index of its pool.
type TileBuild = (usize, TilePools, Vec<(usize, u16)>);

/// Per-tile pools of draws from the tiles' light cuts, for one pass: per tile, one pool for
/// each learned cell its receivers are in (and one for those in no cell).
#[derive(Debug)]
pub struct LightTiles {
    tiles_x: usize,
    /// Per tile, its pools: the cell they mix with the cut (`None`: the cut alone) and the draws.
    pools: Vec<TilePools>,
    /// Per pixel of the G-buffer, the index of its pool in its tile's list.
    pool_of: Vec<u16>,
    nodes: usize,
    hierarchy_nodes: usize,
}

/// What one pass's tiles held, for `--stats`.
#[derive(Clone, Copy, Debug)]
pub struct CutSummary {
    /// Tiles with a cut.
    pub tiles: usize,
    /// Pools over all tiles (one per learned cell a tile's receivers are in).
    pub pools: usize,
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
            "last pass: {} tiles of {TILE}×{TILE} pixels, each a cut of the light hierarchy ({} \
             nodes) into at most {CUT_NODES} nodes (mean {:.0}); {:.1} pools per tile (one per \
             learned cell its receivers are in, mixing the cell's table with the cut; one \
             without learning), {:.0} draws per tile",
            self.tiles,
            self.hierarchy_nodes,
            per(self.nodes),
            per(self.pools),
            per(self.entries)
        )
    }
}

impl LightTiles {
    /// Bytes per pixel of the pools, on average (`candidates` per pixel), and of the pixel's
    /// pool index.
    pub fn bytes_per_pixel(candidates: u32) -> usize {
        (candidates as usize * std::mem::size_of::<Option<LearnedDraw>>()).div_ceil(USES_PER_ENTRY)
            + std::mem::size_of::<u16>()
    }

    /// Builds the tiles' pools for the primary hits of `gbuf` with `candidates` candidates per
    /// receiver, from the streams of stage `stage` of pass `ctx`: per tile, for the receivers
    /// in each cell of `learned` (the distribution learned in earlier passes), draws from the
    /// mixture of the cell's table and the tile's cut, and for receivers in no cell (or without
    /// learning) from the cut alone. `None` if the scene has no local light. `claim` is
    /// [`Claim::Exact`] but in the tests' negative controls.
    #[allow(clippy::too_many_arguments)]
    pub fn build(
        scene: &Scene,
        ctx: &PassContext,
        gbuf: &GBuffer,
        candidates: u32,
        learned: Option<&LearnedSampler>,
        claim: Claim,
        stage: u64,
    ) -> Option<Self> {
        let lights = &scene.lights;
        if lights.emitter_count() == 0 {
            return None;
        }
        let hierarchy_nodes = lights.build_hierarchy();
        let tiles_x = gbuf.width.div_ceil(TILE);
        let tiles_y = gbuf.height.div_ceil(TILE);
        let k = candidates.max(1) as usize;
        let per_tile: Vec<TileBuild> = (0..tiles_x * tiles_y)
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
                // Mean position and normal of the tile's hits, how far they spread, and the
                // learned cell of each.
                let (mut sum_p, mut sum_n) = (Vec3::ZERO, Vec3::ZERO);
                let mut cells: Vec<(usize, Option<u32>)> = Vec::new();
                for i in receivers() {
                    if let Some(r) = gbuf.receiver(i) {
                        sum_p += r.p;
                        sum_n += r.n;
                        cells.push((i, learned.and_then(|l| l.cell(r.p, r.n))));
                    }
                }
                let count = cells.len();
                if count == 0 {
                    return (0, Vec::new(), Vec::new());
                }
                let p = sum_p / count as f32;
                let mean_n = sum_n.normalize_or_zero();
                let (mut spread2, mut same) = (0.0f32, mean_n != Vec3::ZERO);
                for &(i, _) in &cells {
                    if let Some(r) = gbuf.receiver(i) {
                        spread2 = spread2.max((r.p - p).length_squared());
                        same &= r.n.dot(mean_n) >= SAME_NORMAL;
                    }
                }
                let n = if same { mean_n } else { Vec3::ZERO };
                let Some(cut) = lights.light_cut(p, n, spread2.sqrt(), CUT_NODES) else {
                    return (0, Vec::new(), Vec::new());
                };
                // The tile's cells in order (no cell first), each with its receivers' count.
                let mut distinct: Vec<(Option<u32>, usize)> = Vec::new();
                for &(_, c) in &cells {
                    match distinct.binary_search_by_key(&c, |&(d, _)| d) {
                        Ok(j) => distinct[j].1 += 1,
                        Err(j) => distinct.insert(j, (c, 1)),
                    }
                }
                // The tile's streams are named by its place on the film and the cell.
                let (fx, fy) = ctx.film_xy(rows.start * gbuf.width + cols.start, gbuf.width);
                let key = ((u64::from(fy) / TILE as u64) << 32) | (u64::from(fx) / TILE as u64);
                let pools: TilePools = distinct
                    .iter()
                    .map(|&(c, m)| {
                        let mut pool = vec![None; (m * k).div_ceil(USES_PER_ENTRY).max(k)];
                        let stream =
                            c.map_or(key, |c| restir_sampling::mix64(key) ^ (u64::from(c) + 1));
                        let mut rng = ctx.pass_stream(stage, stream);
                        let mixed = learned.zip(c);
                        lights.presample_cut(&cut, mixed, &mut rng, claim, &mut pool);
                        (c, pool)
                    })
                    .collect();
                let index = cells
                    .iter()
                    .map(|&(i, c)| {
                        let j = distinct.binary_search_by_key(&c, |&(d, _)| d).unwrap_or(0);
                        (i, j as u16)
                    })
                    .collect();
                (cut.len(), pools, index)
            })
            .collect();
        let mut pool_of = vec![0u16; gbuf.width * gbuf.height];
        let mut nodes = 0;
        let mut pools = Vec::with_capacity(per_tile.len());
        for (n, tile, index) in per_tile {
            nodes += n;
            for (i, j) in index {
                pool_of[i] = j;
            }
            pools.push(tile);
        }
        Some(Self {
            tiles_x,
            pools,
            pool_of,
            nodes,
            hierarchy_nodes,
        })
    }

    /// The pool of pixel `index` (at `(x, y)`) of the G-buffer, if its tile has one.
    #[inline]
    pub fn pool(&self, index: usize, x: usize, y: usize) -> Option<&[Option<LearnedDraw>]> {
        let tile = &self.pools[(y / TILE) * self.tiles_x + x / TILE];
        let (_, pool) = tile.get(self.pool_of[index] as usize)?;
        (!pool.is_empty()).then_some(&pool[..])
    }

    /// What the tiles hold, for `--stats`.
    pub fn summary(&self) -> CutSummary {
        let with_pool = self.pools.iter().filter(|p| !p.is_empty());
        CutSummary {
            tiles: with_pool.clone().count(),
            pools: with_pool.clone().map(Vec::len).sum(),
            nodes: self.nodes,
            entries: with_pool.flatten().map(|(_, p)| p.len()).sum(),
            hierarchy_nodes: self.hierarchy_nodes,
        }
    }
}
