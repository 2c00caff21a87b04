//! Presampled light candidates: once per pass, tiles of light samples drawn by the power
//! sampler without a receiver; each block of pixels draws its initial candidates from one tile
//! (RTXDI's presampled light tiles; Wyman and Panteleev 2021, "Rearchitecting Spatiotemporal
//! Resampling for Production").
//!
//! A candidate used to be drawn per pixel: an alias-table lookup, a triangle of the emitter
//! table, a point on it (and for an environment map a 2-D distribution lookup and a texel
//! fetch), all at random places in memory. A tile holds [`TILE_SIZE`] such draws made once, in a
//! few tens of kilobytes that the pixels of a block share, so a candidate costs a read from a
//! cached tile and what depends on the receiver (direction, distance, the BSDF).
//!
//! **Unbiased.** Every entry is an independent draw of the power sampler, so whichever entries a
//! pixel takes (the choice never looks at their values), each of its candidates is distributed
//! exactly as a candidate of [`restir_lights::LightSet::sample`], with the same density: the
//! RIS weights are unchanged. Candidates of one pixel, and of pixels sharing a tile, are no longer
//! independent of each other; resampling needs each candidate's own distribution only, so this
//! correlates the noise of a pass (it averages out over passes) without biasing it. Sphere lights,
//! whose points the power sampler draws from the receiver (the cone a sphere subtends), are
//! presampled as a selection only and get their point per pixel.
//!
//! **Stratified.** Entry `j` of a tile draws its light with the selection number `(j + u₀)/S`;
//! a pixel takes the entries `start + i·S/N_L` (mod `S`) for a uniform `start`, one from each of
//! `N_L` strata of the selection, as the per-pixel sampler stratified its `N_L` selections.
//!
//! **Deterministic.** Tiles come from streams of the pass, a block's tile from its position on
//! the film, so a cropped render (`--crop`) and any thread count give the same image.

use rayon::prelude::*;
use restir_lights::Presampled;
use restir_sampling::ONE_MINUS_EPSILON;
use restir_scene::Scene;

use crate::pass::PassContext;

/// Entries per tile (RTXDI's default).
pub const TILE_SIZE: usize = 1024;

/// At most this many tiles: 8192 entries, about 590 KB, which stay in a core's cache. On the
/// training family a pass is as good with 2 tiles as with 128 (the samples are reused more,
/// never biased), while 128 tiles cost as many draws per pass as the candidates at 160×120
/// and, at 640×480, a working set of 9 MB (`docs/studies/2026-12-02-restir-di-light-pool-and-defaults.md`).
pub const MAX_TILES: usize = 8;

/// Blocks of `BLOCK × BLOCK` pixels share a tile.
pub const BLOCK: u32 = 8;

/// How many candidates of a pass, on average, one entry serves: the pool has
/// `pixels · N_L / USES_PER_ENTRY` entries (rounded up to whole tiles, within
/// `1..=`[`MAX_TILES`] tiles).
pub const USES_PER_ENTRY: usize = 8;

/// One pass's tiles of presampled candidates.
#[derive(Debug)]
pub struct LightPool {
    entries: Vec<Option<Presampled>>,
    tiles: usize,
}

impl LightPool {
    /// Tiles for a film of `pixels` pixels with `candidates` candidates each (the whole film's
    /// pixels, so that a crop builds the same pool).
    pub fn tiles_for(pixels: usize, candidates: usize) -> usize {
        (pixels * candidates)
            .div_ceil(TILE_SIZE * USES_PER_ENTRY)
            .clamp(1, MAX_TILES)
    }

    /// Draws `tiles` tiles for pass `ctx`; `stage` names the pass's streams.
    pub fn build(scene: &Scene, ctx: &PassContext, tiles: usize, stage: u64) -> Self {
        let mut entries = vec![None; tiles * TILE_SIZE];
        entries
            .par_chunks_mut(TILE_SIZE)
            .enumerate()
            .for_each(|(t, tile)| {
                let mut rng = ctx.pass_stream(stage, t as u64);
                let u0 = rng.next_f32();
                for (j, e) in tile.iter_mut().enumerate() {
                    let u_select = ((j as f32 + u0) / TILE_SIZE as f32).min(ONE_MINUS_EPSILON);
                    *e = scene.lights.presample(u_select, rng.next_2d());
                }
            });
        Self { entries, tiles }
    }

    /// The tile of the block holding film pixel `(x, y)` in this pass.
    #[inline]
    pub fn tile_of(&self, ctx: &PassContext, x: u32, y: u32) -> &[Option<Presampled>] {
        let block = (u64::from(y / BLOCK) << 32) | u64::from(x / BLOCK);
        let h =
            restir_sampling::mix64(block ^ (ctx.pass as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let t = (h % self.tiles as u64) as usize;
        &self.entries[t * TILE_SIZE..(t + 1) * TILE_SIZE]
    }
}
