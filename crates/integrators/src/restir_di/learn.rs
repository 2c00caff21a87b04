//! Learning across passes (`--learn on`): what each emitter (an emissive triangle, another
//! light, the environment) delivered to the receivers of a pass, once its shadow ray was traced,
//! is recorded per cell of a world-space grid, and the next passes draw their candidates from a
//! mixture of those records and the power sampler ([`restir_lights::LearnedSampler`]).
//!
//! Pass `k`'s sampler is frozen from the records of passes `0..k` before pass `k` draws anything,
//! so given the earlier passes each pass is the usual unbiased estimator with a fixed candidate
//! distribution whose support is the power sampler's (the defensive share), and so is the
//! average of the passes. Records are gathered per band of image rows and added band after band,
//! so the sums, hence the sampler and the image, do not depend on the thread count. A pass draws
//! its candidates from `CellPools`: per cell, independent draws of the mixture made once, from
//! streams of the pass and the cell.

use std::sync::{Arc, Mutex};

use glam::Vec3;
use rayon::prelude::*;
use restir_lights::{CellKey, EmitterGroups, LearnGrid, LearnedDraw, LearnedSampler, LightRecords};
use restir_scene::Scene;

use crate::pass::PassContext;
use crate::reuse::gbuffer::GBuffer;

/// One record of a pass: a receiver's cell, the emitter of its shaded sample
/// ([`restir_lights::LightSet::emitter_of`]) and what it delivered (shadow ray included).
pub(super) type Record = (CellKey, u32, f32);

/// The records of every pass so far and the sampler frozen from them.
#[derive(Debug, Default)]
pub(super) struct Learning {
    state: Mutex<State>,
}

#[derive(Debug, Default)]
struct State {
    records: LightRecords,
    /// The sampler of the records as they were after the last pass, built on demand.
    sampler: Option<Arc<LearnedSampler>>,
    /// The emitters learned together, made with the first sampler (they depend on the scene
    /// and the grid only).
    groups: Option<Arc<EmitterGroups>>,
    /// Cells with a table and the tables' bytes, of the last sampler built.
    last_tables: (usize, usize),
    /// Passes recorded.
    passes: u32,
}

impl Learning {
    /// The grid for `scene`: cubes of a `cells`th of the scene's diameter.
    pub fn grid(scene: &Scene, cells: f32) -> LearnGrid {
        let diameter = 2.0 * scene.lights.scene_radius();
        LearnGrid {
            cell: if diameter > 0.0 && diameter.is_finite() {
                diameter / cells
            } else {
                1.0
            },
        }
    }

    /// The sampler this pass draws from: the records of the earlier passes only (`None` before
    /// anything was recorded).
    pub fn sampler(
        &self,
        scene: &Scene,
        share: f32,
        prior: f32,
        cells: f32,
        group: f32,
    ) -> Option<Arc<LearnedSampler>> {
        let mut s = self.state.lock().ok()?;
        if s.records.records() == 0 {
            return None;
        }
        if s.sampler.is_none() {
            let grid = Self::grid(scene, cells);
            let groups = s
                .groups
                .get_or_insert_with(|| Arc::new(scene.lights.emitter_groups(group * grid.cell)))
                .clone();
            let sampler = LearnedSampler::new(grid, share, prior, &s.records, groups);
            s.last_tables = (sampler.cells(), sampler.bytes());
            s.sampler = Some(Arc::new(sampler));
        }
        s.sampler.clone()
    }

    /// Adds a pass's records, band after band in image order.
    pub fn record(&self, bands: Vec<Vec<Record>>) {
        if let Ok(mut s) = self.state.lock() {
            for (key, emitter, value) in bands.into_iter().flatten() {
                s.records.add(key, emitter, value);
            }
            s.sampler = None;
            s.passes += 1;
        }
    }

    /// What was learned, one line: records, passes recorded, cells with tables, the groups of
    /// emitters, the sampler's memory.
    pub fn summary(&self) -> String {
        let Ok(s) = self.state.lock() else {
            return String::new();
        };
        let groups = s.groups.as_ref().map_or_else(
            || "no groups yet".to_string(),
            |g| {
                format!(
                    "{} emitters in {} learned groups (runs of a mesh's triangles within a cell)",
                    g.emitters(),
                    g.len()
                )
            },
        );
        let (cells, bytes) = s.last_tables;
        format!(
            "{} records from {} pass{} in {} cells; the last pass drew from tables of {} cells, {:.1} MB; {}",
            s.records.records(),
            s.passes,
            if s.passes == 1 { "" } else { "es" },
            s.records.cells(),
            cells,
            bytes as f64 / 1e6,
            groups
        )
    }

    /// Forgets everything (a new frame: the lights and receivers have moved; or a pass that
    /// does not continue the passes learned from, [`crate::reuse::chain::PassChain`]).
    pub fn reset(&self) {
        if let Ok(mut s) = self.state.lock() {
            *s = State::default();
        }
    }
}

/// A record of the shaded sample on `emitter` at the receiver at `p` with normal `n`, which
/// delivered `contribution` (its shadow ray found it visible). The record counts the selection
/// (1), not the contribution: the final samples are distributed about as the target with
/// visibility, so how often each emitter is selected and visible estimates its share of the
/// receiver's direct light, with the bounded variance of a count, where the contributions'
/// weights would carry the reservoirs' heavy tails into the tables.
#[inline]
pub(super) fn record(
    grid: &LearnGrid,
    p: Vec3,
    n: Vec3,
    emitter: u32,
    contribution: Vec3,
) -> Record {
    let lit = restir_sampling::luminance(contribution) > 0.0;
    (grid.key(p, n), emitter, if lit { 1.0 } else { 0.0 })
}

/// Candidates of a pass that one entry of a cell's pool serves, on average: a cell of `m`
/// receivers gets `⌈m · N_L / USES_PER_ENTRY⌉` entries, at least `N_L` (a lone receiver still
/// gets `N_L` different draws) and at most [`MAX_POOL`].
pub const USES_PER_ENTRY: usize = 16;

/// At most this many entries in one cell's pool (the power sampler's tile size).
pub const MAX_POOL: usize = super::pool::TILE_SIZE;

/// One pass's draws of the learned mixture: each receiver's cell and each cell's pool
/// ([`LearnedSampler::presample`]), made from the pass's streams before any candidate is drawn.
pub(super) struct CellPools {
    /// Per pixel, its cell's index in `pools`, if the cell has a table.
    pub cell_of: Vec<Option<u32>>,
    /// Per cell of the sampler, its pool (empty for a cell no receiver of this pass is in).
    pub pools: Vec<Vec<Option<LearnedDraw>>>,
}

impl CellPools {
    /// Bytes per pixel of the cell index and the pools, on average (`candidates` per pixel).
    pub fn bytes_per_pixel(candidates: u32) -> usize {
        std::mem::size_of::<Option<u32>>()
            + (candidates as usize * std::mem::size_of::<Option<LearnedDraw>>())
                .div_ceil(USES_PER_ENTRY)
    }

    /// The pools of `learned` for the receivers of `gbuf`, with `candidates` candidates per
    /// receiver, from the streams of stage `stage` of pass `ctx` (one per cell, so the pools do
    /// not depend on the thread count). `defensive` false makes the tests' negative control.
    pub fn build(
        learned: &LearnedSampler,
        scene: &Scene,
        ctx: &PassContext,
        gbuf: &GBuffer,
        candidates: u32,
        defensive: bool,
        stage: u64,
    ) -> Self {
        let cell_of: Vec<Option<u32>> = (0..gbuf.receivers.len())
            .into_par_iter()
            .map(|i| gbuf.receiver(i).and_then(|r| learned.cell(r.p, r.n)))
            .collect();
        let mut receivers = vec![0usize; learned.cells()];
        for c in cell_of.iter().flatten() {
            receivers[*c as usize] += 1;
        }
        let n = candidates.max(1) as usize;
        let pools = receivers
            .into_par_iter()
            .enumerate()
            .map(|(c, m)| {
                if m == 0 {
                    return Vec::new();
                }
                let len = (m * n).div_ceil(USES_PER_ENTRY).clamp(n, MAX_POOL.max(n));
                let mut pool = vec![None; len];
                let mut rng = ctx.pass_stream(stage, c as u64);
                learned.presample(&scene.lights, c as u32, defensive, &mut rng, &mut pool);
                pool
            })
            .collect();
        Self { cell_of, pools }
    }

    /// The pool of pixel `index`'s cell, if it has one.
    #[inline]
    pub fn pool(&self, index: usize) -> Option<&[Option<LearnedDraw>]> {
        let c = self.cell_of[index]?;
        let pool = &self.pools[c as usize];
        (!pool.is_empty()).then_some(&pool[..])
    }
}
