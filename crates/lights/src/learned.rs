//! A light selection learned from what emitters delivered: per cell of a world-space grid (over
//! positions and the dominant axis of the receiver's normal), the sum of what each emitter (an
//! emissive triangle, another light, the environment: [`LightSet::pick_emitter`]'s numbering)
//! contributed to receivers in that cell once its shadow ray was traced, turned into a
//! distribution and sampled in a mixture with the power sampler. Emitters rather than lights, so
//! that of a mesh light only the triangles a cell sees are drawn there.
//!
//! The grid is ReGIR's (Boksansky et al., *Ray Tracing Gems II*, 2021: cells of world space,
//! each with its own light distribution); what fills it follows Vévoda, Kondapaneni and
//! Křivánek, "Bayesian online regression for adaptive direct illumination sampling" (SIGGRAPH
//! 2018): lights are weighted by their measured contribution with visibility, so lights that are
//! blocked from a cell stop being drawn there.
//!
//! [`LightRecords`] gathers `(cell, emitter, contribution)` records in the order they are given;
//! [`LearnedSampler::new`] freezes them into one table per cell: an alias table over the
//! emitters it recorded and, where a scene's meshes have triangles learned together
//! ([`EmitterGroups`]), another over those groups, each taking half. A selection at a receiver
//! picks the cell's table with probability `share · n / (n + prior)` (`n` the cell's records,
//! so a cell that has seen little leans on the power sampler) and the power sampler
//! ([`LightSet::pick_emitter`]) otherwise, so every emitter with power keeps a positive
//! probability whatever was learned (the defensive share, Hesterberg 1995), and
//! [`LearnedSampler::pmf`] is the mixture's probability, exactly, for any receiver and emitter.
//! A receiver whose cell has no records selects by power alone.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::Arc;

use glam::Vec3;
use restir_sampling::{AliasTable, ONE_MINUS_EPSILON, Pcg32, mix64};

use crate::{LightSet, Presampled};

/// A draw of the learned mixture made without a receiver ([`LearnedSampler::presample`]): the
/// power sampler's presampled draw of the picked emitter ([`LightSet::presample_emitter`]) and
/// the ratio of the mixture's probability of that emitter to the power sampler's, by which its
/// density is multiplied.
pub type LearnedDraw = (Presampled, f32);

/// Emitters learned as one: runs of consecutive triangles of one mesh light (in the mesh's own
/// order, in which neighbours are mostly neighbours in space) that fit in a box of a given
/// diagonal ([`LightSet::emitter_groups`]); every other light, and the environment, alone. A
/// cell's table picks a group and the group an emitter by power, so a compact lamp of many
/// triangles is learned from one count per lamp rather than from a few counts per triangle,
/// while a long garland mesh is still learned piece by piece.
#[derive(Clone, Debug, Default)]
pub struct EmitterGroups {
    /// Per emitter its group's first emitter.
    pub(crate) start: Vec<u32>,
    /// Per emitter its group's end (one past its last emitter).
    pub(crate) end: Vec<u32>,
    /// Per emitter `e` the power sampler's probability of the emitters before it (`n + 1`
    /// values): a group's power is a difference, and an emitter is found in it by bisection.
    pub(crate) cumulative: Vec<f64>,
    /// Groups.
    pub(crate) count: usize,
}

impl EmitterGroups {
    /// The emitters `[start, end)` of `e`'s group (`e` alone past the table).
    #[inline]
    pub fn group(&self, e: usize) -> (usize, usize) {
        match (self.start.get(e), self.end.get(e)) {
            (Some(&s), Some(&t)) => (s as usize, t as usize),
            _ => (e, e + 1),
        }
    }

    /// Groups.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether some group holds more than one emitter.
    pub fn any_grouped(&self) -> bool {
        self.count < self.start.len()
    }

    /// Emitters (the environment included).
    pub fn emitters(&self) -> usize {
        self.start.len()
    }

    /// Whether there are no emitters.
    pub fn is_empty(&self) -> bool {
        self.start.is_empty()
    }

    /// The group's share of the power sampler's probability.
    #[inline]
    fn power(&self, start: usize, end: usize) -> f64 {
        self.cumulative[end] - self.cumulative[start]
    }

    /// An emitter of the group `[start, end)` picked in proportion to its power with uniform
    /// `u` (`None` if none has power).
    #[inline]
    fn pick(&self, start: usize, end: usize, u: f32) -> Option<usize> {
        if end - start == 1 {
            return Some(start);
        }
        let c = &self.cumulative;
        let (lo, hi) = (c[start], c[end]);
        if hi <= lo {
            return None;
        }
        let target = lo + f64::from(u) * (hi - lo);
        // The first emitter whose interval ends past the target; emitters without power have
        // empty intervals and are never found.
        let i = c[start + 1..=end].partition_point(|&x| x <= target);
        let mut e = (start + i).min(end - 1);
        while e > start && c[e + 1] <= c[e] {
            e -= 1;
        }
        (c[e + 1] > c[e]).then_some(e)
    }
}

/// A cell of the grid: integer coordinates and the receiver normal's dominant axis and sign.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct CellKey {
    x: i32,
    y: i32,
    z: i32,
    face: u8,
}

/// The hash of the learning's maps: a multiply-xor over the key's integers and one final mix
/// ([`mix64`]). The keys are small integers made by this module, not input an adversary chooses,
/// so the standard library's keyed SipHash (several times the cost, once per receiver and per
/// record) buys nothing here. Nothing iterates these maps in their hash order: the determinism
/// of the tables comes from sorting ([`LearnedSampler::new`]).
#[derive(Clone, Copy, Debug, Default)]
struct KeyHasher(u64);

impl Hasher for KeyHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }

    #[inline]
    fn write_u8(&mut self, v: u8) {
        self.write_u64(u64::from(v));
    }

    #[inline]
    fn write_u32(&mut self, v: u32) {
        self.write_u64(u64::from(v));
    }

    #[inline]
    fn write_i32(&mut self, v: i32) {
        self.write_u64(u64::from(v as u32));
    }

    #[inline]
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x517c_c1b7_2722_0a95);
    }

    #[inline]
    fn finish(&self) -> u64 {
        mix64(self.0)
    }
}

type KeyMap<K, V> = HashMap<K, V, BuildHasherDefault<KeyHasher>>;

/// `⌊v⌋` as an integer, clamped to ±10⁹ (the cast itself, without a call to `floorf` on targets
/// without SSE4.1's rounding instruction).
#[inline]
fn floor_i32(v: f32) -> i32 {
    let v = v.clamp(-1.0e9, 1.0e9);
    let t = v as i32;
    if (t as f32) > v { t - 1 } else { t }
}

/// The grid: cubes of side `cell` in world space, split by the receiver normal's dominant axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LearnGrid {
    /// Side of a cell in world units.
    pub cell: f32,
}

impl LearnGrid {
    /// The cell of a receiver at `p` with normal `n` (zero if unknown).
    #[inline]
    pub fn key(&self, p: Vec3, n: Vec3) -> CellKey {
        let q = p / self.cell;
        let a = n.abs();
        let (axis, sign) = if a.x >= a.y && a.x >= a.z {
            (0, n.x < 0.0)
        } else if a.y >= a.z {
            (1, n.y < 0.0)
        } else {
            (2, n.z < 0.0)
        };
        CellKey {
            x: floor_i32(q.x),
            y: floor_i32(q.y),
            z: floor_i32(q.z),
            face: 2 * axis + u8::from(sign),
        }
    }
}

/// What emitters delivered, per cell: the sum of the contributions recorded for each emitter.
#[derive(Clone, Debug, Default)]
pub struct LightRecords {
    /// Per cell its slot in `cells`.
    slots: KeyMap<CellKey, u32>,
    cells: Vec<CellRecords>,
    records: u64,
}

/// One cell's records: per emitter (in the order they were first recorded) its sum.
#[derive(Clone, Debug)]
struct CellRecords {
    key: CellKey,
    /// Per emitter its slot in `emitters` and `sums`.
    slots: KeyMap<u32, u32>,
    emitters: Vec<u32>,
    sums: Vec<f64>,
    /// Records added.
    count: u64,
}

impl LightRecords {
    /// Adds what `emitter` delivered to a receiver in cell `key` (non-positive and non-finite
    /// values are ignored). Sums are `f64` and taken in the order of the calls, so the same
    /// records in the same order give the same bits.
    #[inline]
    pub fn add(&mut self, key: CellKey, emitter: u32, value: f32) {
        if !(value > 0.0 && value.is_finite()) {
            return;
        }
        let next = self.cells.len() as u32;
        let slot = *self.slots.entry(key).or_insert(next) as usize;
        if slot == self.cells.len() {
            self.cells.push(CellRecords {
                key,
                slots: KeyMap::default(),
                emitters: Vec::new(),
                sums: Vec::new(),
                count: 0,
            });
        }
        let cell = &mut self.cells[slot];
        let next = cell.emitters.len() as u32;
        let e = *cell.slots.entry(emitter).or_insert(next) as usize;
        if e == cell.emitters.len() {
            cell.emitters.push(emitter);
            cell.sums.push(0.0);
        }
        cell.sums[e] += value as f64;
        cell.count += 1;
        self.records += 1;
    }

    /// Cells with records.
    pub fn cells(&self) -> usize {
        self.cells.len()
    }

    /// Records added.
    pub fn records(&self) -> u64 {
        self.records
    }
}

/// One level of a cell's table: a distribution over units (single emitters, or groups of
/// emitters), each named by its first emitter, ascending.
#[derive(Clone, Debug)]
struct Level {
    starts: Vec<u32>,
    alias: AliasTable,
}

impl Level {
    /// The level of `sums` (per emitter, ascending, its records) with each emitter counted in
    /// the unit `unit` names (by its first emitter).
    fn new(sums: &[(u32, f64)], unit: impl Fn(u32) -> u32) -> Option<Self> {
        let mut by_unit: Vec<(u32, f64)> = sums.iter().map(|&(e, v)| (unit(e), v)).collect();
        // Stable, so each unit's sum is taken in emitter order.
        by_unit.sort_by_key(|&(g, _)| g);
        let mut starts = Vec::with_capacity(by_unit.len());
        let mut weights = Vec::with_capacity(by_unit.len());
        let mut acc = 0.0f64;
        for (i, &(g, v)) in by_unit.iter().enumerate() {
            acc += v;
            if by_unit.get(i + 1).is_none_or(|&(next, _)| next != g) {
                starts.push(g);
                weights.push(acc as f32);
                acc = 0.0;
            }
        }
        Some(Self {
            alias: AliasTable::new(&weights)?,
            starts,
        })
    }

    /// The probability the level picks the unit starting at emitter `start`.
    #[inline]
    fn pmf(&self, start: u32) -> f32 {
        self.starts
            .binary_search(&start)
            .map_or(0.0, |i| self.alias.pmf(i))
    }
}

/// One cell's distribution over what it recorded: over single emitters and, where the scene has
/// groups of several emitters ([`EmitterGroups`]), half over the groups (a group picked from
/// the table, an emitter within it by power).
#[derive(Clone, Debug)]
struct CellTable {
    emitters: Level,
    groups: Option<Level>,
    /// The share of selections the table takes in this cell: the sampler's share times
    /// `n / (n + prior)` for `n` records, so a cell of few records leans on the power sampler.
    share: f32,
}

/// The learned selection: per cell a table over the emitters (and groups) recorded there, mixed
/// with the power sampler (module documentation).
#[derive(Clone, Debug)]
pub struct LearnedSampler {
    grid: LearnGrid,
    share: f32,
    /// Emitters learned together.
    groups: Arc<EmitterGroups>,
    index: KeyMap<CellKey, u32>,
    tables: Vec<CellTable>,
}

impl LearnedSampler {
    /// The sampler of `records` on `grid`, taking a cell's table with probability
    /// `share · n / (n + prior)` for a cell of `n` records (`share` in `[0, 1)`: the rest goes
    /// to the power sampler). The tables are over `groups` ([`EmitterGroups`]): what a cell
    /// recorded of a group's emitters is pooled, and an emitter is drawn within its group by
    /// power.
    pub fn new(
        grid: LearnGrid,
        share: f32,
        prior: f32,
        records: &LightRecords,
        groups: Arc<EmitterGroups>,
    ) -> Self {
        let share = share.clamp(0.0, ONE_MINUS_EPSILON);
        let prior = prior.max(0.0);
        // Cells in key order and each cell's emitters ascending, so that the tables (and the
        // cell numbers the pools' streams are named by) depend on the records, not on the order
        // in which cells and emitters first appeared.
        let mut cells: Vec<&CellRecords> = records.cells.iter().collect();
        cells.sort_unstable_by_key(|c| c.key);
        let mut index = KeyMap::default();
        index.reserve(cells.len());
        let mut tables = Vec::with_capacity(cells.len());
        let grouped = groups.any_grouped();
        for cell in cells {
            let mut sums: Vec<(u32, f64)> = cell
                .emitters
                .iter()
                .copied()
                .zip(cell.sums.iter().copied())
                .collect();
            sums.sort_by_key(|&(e, _)| e);
            let n = cell.count as f32;
            if let Some(emitters) = Level::new(&sums, |e| e) {
                let group_level = grouped
                    .then(|| Level::new(&sums, |e| groups.group(e as usize).0 as u32))
                    .flatten();
                index.insert(cell.key, tables.len() as u32);
                tables.push(CellTable {
                    emitters,
                    groups: group_level,
                    share: share * n / (n + prior),
                });
            }
        }
        Self {
            grid,
            share,
            groups,
            index,
            tables,
        }
    }

    /// The largest share of selections a cell's table takes (the share of a cell of very many
    /// records).
    pub fn share(&self) -> f32 {
        self.share
    }

    /// Cells with a table.
    pub fn cells(&self) -> usize {
        self.tables.len()
    }

    /// Approximate heap bytes of the tables and the cell index.
    pub fn bytes(&self) -> usize {
        let entries: usize = self
            .tables
            .iter()
            .map(|t| t.emitters.starts.len() + t.groups.as_ref().map_or(0, |g| g.starts.len()))
            .sum();
        // Per entry a unit's first emitter and an alias bin (probability, alias, pmf); per cell its
        // key, index slot and table header.
        entries * (4 + 12) + self.tables.len() * (16 + 4 + 64)
    }

    /// The cell (its table) of a receiver at `p` with normal `n`, if it has one.
    #[inline]
    pub fn cell(&self, p: Vec3, n: Vec3) -> Option<u32> {
        if self.tables.is_empty() {
            return None;
        }
        self.index.get(&self.grid.key(p, n)).copied()
    }

    /// Picks an emitter for a receiver in `cell` ([`LearnedSampler::cell`]) with uniform `u`:
    /// `(emitter, probability)`, the probability being [`LearnedSampler::pmf`]'s.
    #[inline]
    pub fn sample(&self, lights: &LightSet, cell: Option<u32>, u: f32) -> Option<(usize, f32)> {
        let Some(c) = cell else {
            return lights.pick_emitter(u);
        };
        let share = self.tables[c as usize].share;
        let emitter = if u < share {
            self.sample_table(c, (u / share).min(ONE_MINUS_EPSILON))?
        } else {
            let v = ((u - share) / (1.0 - share)).min(ONE_MINUS_EPSILON);
            lights.pick_emitter(v)?.0
        };
        Some((emitter, self.pmf(lights, cell, emitter)))
    }

    /// The share of selections `cell`'s table takes (`share · n / (n + prior)`), the rest
    /// going to the defensive sampler; 0 for no cell.
    #[inline]
    pub fn table_share(&self, cell: Option<u32>) -> f32 {
        cell.map_or(0.0, |c| self.tables[c as usize].share)
    }

    /// Picks an emitter from `cell`'s table alone with uniform `u` (no defensive part; its
    /// probability is [`LearnedSampler::table_probability`]'s).
    #[inline]
    pub fn sample_table(&self, cell: u32, u: f32) -> Option<usize> {
        let table = &self.tables[cell as usize];
        Some(match &table.groups {
            Some(g) if u >= 0.5 => {
                let v = (2.0 * u - 1.0).min(ONE_MINUS_EPSILON);
                let (i, _, rest) = g.alias.sample(v);
                let start = g.starts[i] as usize;
                let (_, end) = self.groups.group(start);
                self.groups.pick(start, end, rest)?
            }
            Some(_) => {
                let v = (2.0 * u).min(ONE_MINUS_EPSILON);
                table.emitters.starts[table.emitters.alias.sample(v).0] as usize
            }
            None => table.emitters.starts[table.emitters.alias.sample(u).0] as usize,
        })
    }

    /// The probability that [`LearnedSampler::sample_table`] picks `emitter` from `cell`'s
    /// table.
    #[inline]
    pub fn table_probability(&self, lights: &LightSet, cell: u32, emitter: usize) -> f32 {
        self.table_pmf(lights, &self.tables[cell as usize], emitter)
    }

    /// The probability that [`LearnedSampler::sample`] picks `emitter` for a receiver in
    /// `cell`: `share · table(emitter) + (1 − share) · power(emitter)`, with `table(emitter)`
    /// the table's probability of its group times its share of the group's power, or the power
    /// sampler's alone ([`LightSet::emitter_pmf`]) in a cell without a table.
    #[inline]
    pub fn pmf(&self, lights: &LightSet, cell: Option<u32>, emitter: usize) -> f32 {
        let power = lights.emitter_pmf(emitter);
        match cell.map(|c| &self.tables[c as usize]) {
            None => power,
            Some(t) => t.share * self.table_pmf(lights, t, emitter) + (1.0 - t.share) * power,
        }
    }

    /// The probability that `table` picks `emitter`: its own, or with groups the mean of its
    /// own and its group's times its share of the group's power.
    #[inline]
    fn table_pmf(&self, lights: &LightSet, table: &CellTable, emitter: usize) -> f32 {
        let own = table.emitters.pmf(emitter as u32);
        let Some(level) = &table.groups else {
            return own;
        };
        let (start, end) = self.groups.group(emitter);
        let p = level.pmf(start as u32);
        let total = self.groups.power(start, end);
        let in_group = if p == 0.0 {
            0.0
        } else if end - start == 1 {
            p
        } else if total > 0.0 {
            (f64::from(p) * f64::from(lights.emitter_pmf(emitter)) / total) as f32
        } else {
            0.0
        };
        0.5 * (own + in_group)
    }

    /// Fills `out` with independent draws of `cell`'s mixture ([`LearnedSampler::sample`], the
    /// selections stratified over `out`), each with the ratio of its probability to the power
    /// sampler's, or with the ratio of the table's probability alone
    /// ([`LearnedSampler::pmf_without_defensive_share`], the tests' negative control) when
    /// `defensive` is false. A pool of such draws serves a cell's receivers as the power
    /// sampler's presampled tiles serve theirs: one read per candidate from a small array
    /// instead of an alias pick, a table lookup and a point on a triangle at random places in
    /// memory (Wyman and Panteleev 2021, presampled cell tables).
    pub fn presample(
        &self,
        lights: &LightSet,
        cell: u32,
        defensive: bool,
        rng: &mut Pcg32,
        out: &mut [Option<LearnedDraw>],
    ) {
        let n = out.len() as f32;
        let u0 = rng.next_f32();
        for (j, slot) in out.iter_mut().enumerate() {
            let u_select = ((j as f32 + u0) / n).min(ONE_MINUS_EPSILON);
            let u = rng.next_2d();
            *slot = self
                .sample(lights, Some(cell), u_select)
                .and_then(|(e, pmf)| {
                    let power = lights.emitter_pmf(e);
                    let claimed = if defensive {
                        pmf
                    } else {
                        self.pmf_without_defensive_share(lights, Some(cell), e)
                    };
                    (power > 0.0)
                        .then(|| lights.presample_emitter(e, u))
                        .flatten()
                        .map(|d| (d, claimed / power))
                });
        }
    }

    /// The probability of the cell's table alone, without the power sampler's share: what a
    /// mixture forgetting its defensive part would claim (the tests' negative control; an
    /// emitter the table lacks falls back to its power probability).
    #[doc(hidden)]
    pub fn pmf_without_defensive_share(
        &self,
        lights: &LightSet,
        cell: Option<u32>,
        emitter: usize,
    ) -> f32 {
        match cell.map(|c| self.table_pmf(lights, &self.tables[c as usize], emitter)) {
            Some(p) if p > 0.0 => p,
            _ => lights.emitter_pmf(emitter),
        }
    }
}
