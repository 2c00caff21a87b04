//! Screen-tile light selection for ReSTIR DI's initial candidates (`--light-sampler tiles`).
//!
//! The power sampler ignores distance, so in a scene of many small lights most candidates land
//! on lights far from the pixel; the light hierarchy's descent knows distance but costs a chain
//! of node tests per candidate, at random places in memory, which grows with the emitter count.
//! Here, once per render, every 16×16-pixel tile of the film gets a region (what camera rays
//! through its pixels' corners hit) and a cut of the light hierarchy for it
//! ([`LightSet::light_cut`](restir_lights::LightSet::light_cut)): near lights one by one, far
//! clusters whole, each weighted by its importance for every receiver of the region
//! ([`TileCuts`]). Once per pass, the cut is drawn from into a pool of points on lights
//! ([`LightSet::presample_cut`](restir_lights::LightSet::presample_cut)), and the tile's pixels
//! take their candidates from the pool: a read from a small array per candidate. A pass's
//! receivers outside their tile's region (hits the corner rays missed) get a cut of their own,
//! made in that pass. The probes that hit a light which cannot light its own surface (a lamp
//! in view, [`LightSet::self_unlit`](restir_lights::LightSet::self_unlit)) make a second region
//! of the tile, whose cut leaves that light a small share of its selections
//! ([`OwnLight`]): it is the nearest light of every receiver on it, and would otherwise take
//! most of them without lighting any. With learning across passes ([`super::learn`]) a tile has one pool per
//! cut and learned cell its receivers are in, drawn from the mixture of the cell's table and
//! the cut: the cut is the learned table's defensive part, in place of the power sampler.
//!
//! **Unbiased.** A cut's importance is conservative for its whole region, and a receiver draws
//! from a cut only if it lies in the cut's region (for a region on a light, only if it lies on
//! that light, which keeps its positive share), so an emitter that can light it keeps a
//! positive probability (with learning, the cut's share of the mixture keeps it); each pool
//! entry is an independent draw carrying its mixture's probability exactly. The regions depend
//! on no pass's random numbers, so each pass is unbiased given them. Targets, reuse and the
//! light/BSDF split (which weighs by the power sampler's density) are untouched.
//!
//! **Deterministic.** The regions' rays are fixed by the film; a tile's pools come from
//! streams of the pass named by the tile's place on the film (and the cut and the cell), and a
//! cropped render's region is aligned to the tiles
//! ([`PixelWindow::with_halo`](crate::PixelWindow::with_halo)), so every tile it holds sees the
//! same receivers as in the whole render: crops, chains and thread counts give the same image.

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use restir_lights::{Claim, LearnedDraw, LearnedSampler, LightCut, OWN_LIGHT_SHARE, OwnLight};
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

/// A tile's pools: per cut and learned cell its receivers are in (`None`: the cut alone), the
/// draws.
type TilePools = Vec<(Option<u32>, Vec<Option<LearnedDraw>>)>;

/// What one tile's build gives: its pools, per receiver (a pixel of the G-buffer) the index of
/// its pool, and the cut made in the pass for the receivers outside the tile's region.
#[derive(Debug, Default)]
struct TileBuild {
    pools: TilePools,
    index: Vec<(usize, u16)>,
    fresh_nodes: usize,
    fresh_receivers: usize,
}

impl TileBuild {
    /// Adds the pools of receivers `members` (pixel, learned cell) drawing from `cut`: one per
    /// cell, `k` candidates per receiver, from the streams `(tile, which cut)` names.
    #[allow(clippy::too_many_arguments)]
    fn add(
        &mut self,
        lights: &restir_lights::LightSet,
        ctx: &PassContext,
        cut: &LightCut,
        members: &[(usize, Option<u32>)],
        (key, which): (u64, u64),
        k: usize,
        learned: Option<&LearnedSampler>,
        claim: Claim,
        stage: u64,
    ) {
        // The members' cells in order (no cell first), each with its receivers' count.
        let mut distinct: Vec<(Option<u32>, usize)> = Vec::new();
        for &(_, c) in members {
            match distinct.binary_search_by_key(&c, |&(d, _)| d) {
                Ok(j) => distinct[j].1 += 1,
                Err(j) => distinct.insert(j, (c, 1)),
            }
        }
        let first = self.pools.len();
        for &(c, m) in &distinct {
            let mut pool = vec![None; (m * k).div_ceil(USES_PER_ENTRY).max(k)];
            let stream =
                restir_sampling::mix64(key ^ (which << 63)) ^ c.map_or(0, |c| u64::from(c) + 1);
            let mut rng = ctx.pass_stream(stage, stream);
            lights.presample_cut(cut, learned.zip(c), &mut rng, claim, &mut pool);
            self.pools.push((c, pool));
        }
        for &(i, c) in members {
            let j = distinct.binary_search_by_key(&c, |&(d, _)| d).unwrap_or(0);
            self.index.push((i, (first + j) as u16));
        }
    }
}

/// Per-tile pools of draws from the tiles' light cuts, for one pass: per tile, one pool for
/// each cut and learned cell its receivers are in.
#[derive(Debug)]
pub struct LightTiles {
    tiles_x: usize,
    /// Per tile, its pools: the cell they mix with the cut (`None`: the cut alone) and the draws.
    pools: Vec<TilePools>,
    /// Per pixel of the G-buffer, the index of its pool in its tile's list.
    pool_of: Vec<u16>,
    summary: CutSummary,
}

/// What one pass's tiles held, for `--stats`.
#[derive(Clone, Copy, Debug, Default)]
pub struct CutSummary {
    /// Tiles with a cut found once per render.
    pub tiles: usize,
    /// Nodes over those cuts.
    pub nodes: usize,
    /// Receivers of the pass.
    pub receivers: usize,
    /// Cuts made in the pass for receivers outside their tile's region.
    pub fresh_cuts: usize,
    /// Nodes over those cuts.
    pub fresh_nodes: usize,
    /// Receivers outside their tile's region.
    pub fresh_receivers: usize,
    /// Pools over all tiles (one per cut and learned cell a tile's receivers are in).
    pub pools: usize,
    /// Entries over all their pools.
    pub entries: usize,
    /// Nodes of the whole hierarchy.
    pub hierarchy_nodes: usize,
    /// Tiles with a region of receivers on a light that cannot light itself.
    pub on_light: usize,
    /// Lights that cannot light their own surface.
    pub self_unlit: usize,
}

impl CutSummary {
    /// One line: how the tiles cut the hierarchy and how large their pools were.
    pub fn describe(&self) -> String {
        let per = |n: usize, of: usize| n as f64 / of.max(1) as f64;
        format!(
            "{} tiles of {TILE}×{TILE} pixels, each with a cut of the light hierarchy ({} nodes) \
             into at most {CUT_NODES} nodes per region (mean {:.0} nodes per tile), found once \
             from camera rays through its pixels' corners; last pass: {:.2}% of receivers \
             outside their tile's regions, on {} \
             cuts of their own (mean {:.0} nodes); {:.1} pools per tile (one per cut and learned \
             cell its receivers are in, mixing the cell's table with the cut), {:.0} draws per \
             tile; {} lights cannot light their own surface, and {} tiles have a region of \
             receivers on one, whose cut leaves it {:.1}% of the selections",
            self.tiles,
            self.hierarchy_nodes,
            per(self.nodes, self.tiles),
            100.0 * per(self.fresh_receivers, self.receivers),
            self.fresh_cuts,
            per(self.fresh_nodes, self.fresh_cuts),
            per(self.pools, self.tiles),
            per(self.entries, self.tiles),
            self.self_unlit,
            self.on_light,
            100.0 * OWN_LIGHT_SHARE
        )
    }
}

/// A tile's receivers summed up: their mean position, how far they spread from it, their
/// normal where they agree (zero where they do not), and the light they all lie on where its
/// cut treats it apart ([`OwnLight`]).
#[derive(Clone, Copy, Debug)]
struct Region {
    p: Vec3,
    n: Vec3,
    /// The largest squared distance of a point from `p`.
    spread2: f32,
    /// The light every receiver of the region lies on, and the share its own emitters keep.
    on: Option<OwnLight>,
}

impl Region {
    /// The region of points `(position, shading normal)`, `None` for none.
    fn of(points: impl Iterator<Item = (Vec3, Vec3)> + Clone) -> Option<Self> {
        let (mut sum_p, mut sum_n, mut count) = (Vec3::ZERO, Vec3::ZERO, 0usize);
        for (p, n) in points.clone() {
            sum_p += p;
            sum_n += n;
            count += 1;
        }
        if count == 0 {
            return None;
        }
        let p = sum_p / count as f32;
        let mean_n = sum_n.normalize_or_zero();
        let (mut spread2, mut same) = (0.0f32, mean_n != Vec3::ZERO);
        for (q, n) in points {
            spread2 = spread2.max((q - p).length_squared());
            same &= n.dot(mean_n) >= SAME_NORMAL;
        }
        Some(Self {
            p,
            n: if same { mean_n } else { Vec3::ZERO },
            spread2,
            on: None,
        })
    }

    /// Whether a receiver at `q` with normal `n`, on light `on` (if on one), lies in the
    /// region (and, where the region has one normal, shares it; where it lies on a light, lies
    /// on it too): then the region's cut gives every light that can reach it the probability
    /// the cut was made to give.
    #[inline]
    fn holds(&self, q: Vec3, n: Vec3, on: Option<u32>) -> bool {
        (q - self.p).length_squared() <= self.spread2
            && (self.n == Vec3::ZERO || n.dot(self.n) >= SAME_NORMAL)
            && self.on.is_none_or(|o| on == Some(o.light))
    }

    /// The region's cut of the light hierarchy.
    fn cut(&self, lights: &restir_lights::LightSet) -> Option<LightCut> {
        // `light_cut` widens the radius by more than its rounding.
        lights.light_cut(self.p, self.n, self.spread2.sqrt(), CUT_NODES, self.on)
    }
}

/// How the tiles treat receivers on a light ([`OwnLight`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OwnLights {
    /// Receivers on a light that cannot light its own surface get a region of their own, whose
    /// cut leaves that light [`OWN_LIGHT_SHARE`] of its selections.
    Apart,
    /// Every light, whether or not it can light itself, is left no selection at all for the
    /// receivers on it (a negative control of the tests: biased where a light lights itself).
    #[doc(hidden)]
    DroppedEverywhere,
}

impl OwnLights {
    /// The own-light rule for a region on light `light`, if it has one.
    fn of(self, lights: &restir_lights::LightSet, light: u32) -> Option<OwnLight> {
        match self {
            OwnLights::Apart => lights.self_unlit(light).then_some(OwnLight {
                light,
                share: OWN_LIGHT_SHARE,
            }),
            OwnLights::DroppedEverywhere => Some(OwnLight { light, share: 0.0 }),
        }
    }
}

/// A tile's regions with their cuts: the one of its receivers on a light that its cut treats
/// apart (the light the most of its probes hit, if any), and the one of the others.
#[derive(Debug, Default)]
struct TileRegions {
    on_light: Option<(Region, LightCut)>,
    rest: Option<(Region, LightCut)>,
}

impl TileRegions {
    /// The regions of the probes' hits `(position, shading normal, the light the hit lies on)`.
    fn of(
        lights: &restir_lights::LightSet,
        hits: &[(Vec3, Vec3, Option<u32>)],
        own: OwnLights,
    ) -> Self {
        // The light the most hits lie on, among those whose cut treats it apart (the lowest
        // index on a tie).
        let mut counts: Vec<(u32, usize)> = Vec::new();
        for &(_, _, on) in hits {
            if let Some(l) = on {
                match counts.binary_search_by_key(&l, |&(k, _)| k) {
                    Ok(j) => counts[j].1 += 1,
                    Err(j) => counts.insert(j, (l, 1)),
                }
            }
        }
        counts.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        let own_light = counts.iter().find_map(|&(l, _)| own.of(lights, l));
        let on =
            |hit: &&(Vec3, Vec3, Option<u32>)| own_light.is_some_and(|o| hit.2 == Some(o.light));
        let with_cut =
            |region: Option<Region>| region.and_then(|region| Some((region, region.cut(lights)?)));
        let on_light = own_light.and_then(|o| {
            let region = Region::of(hits.iter().filter(on).map(|h| (h.0, h.1)))?;
            with_cut(Some(Region {
                on: Some(o),
                ..region
            }))
        });
        let rest = with_cut(Region::of(
            hits.iter().filter(|h| !on(h)).map(|h| (h.0, h.1)),
        ));
        Self { on_light, rest }
    }

    /// The region that holds a receiver at `q` with normal `n` on light `on`, if one does, as
    /// its pools' stream key (2: the one on a light, 0: the rest, whose key a tile without a
    /// light in view has always had) with its cut.
    fn holding(&self, q: Vec3, n: Vec3, on: Option<u32>) -> Option<(u64, &LightCut)> {
        [&self.on_light, &self.rest]
            .into_iter()
            .zip([2, 0])
            .find_map(|(t, which)| {
                t.as_ref()
                    .filter(|(region, _)| region.holds(q, n, on))
                    .map(|(_, cut)| (which, cut))
            })
    }
}

/// The tiles' regions and cuts of the light hierarchy, found once per render from camera rays
/// through the corners of each tile's pixels (at the lens's centre), which no pass's random
/// numbers choose: every pass, every chain and every crop of a render sees the same ones.
#[derive(Debug)]
pub struct TileCuts {
    /// The film coordinates of the buffers' first pixel and their size.
    window: (u32, u32, usize, usize),
    /// Per tile of the buffers, its regions and cuts (none: the probes hit nothing that a
    /// light can reach).
    tiles: Vec<TileRegions>,
    /// Camera rays traced to find them.
    rays: u64,
}

impl TileCuts {
    /// Bytes per pixel of the regions and their cuts, at most.
    pub fn bytes_per_pixel() -> usize {
        let per_tile =
            std::mem::size_of::<TileRegions>() + 2 * CUT_NODES * LightCut::BYTES_PER_NODE;
        per_tile.div_ceil(TILE * TILE)
    }

    /// The tiles' regions and cuts for buffers `width × height` of pass `ctx` (only its crop
    /// matters): per tile, the hits of camera rays through the film corners of its pixels
    /// (`hide_emitters` as the G-buffer's rays), those on a light that `own` treats apart in a
    /// region of their own. `None` if the scene has no local light.
    pub fn probe(
        scene: &Scene,
        ctx: &PassContext,
        width: usize,
        height: usize,
        hide_emitters: bool,
        own: OwnLights,
    ) -> Option<Self> {
        let lights = &scene.lights;
        if lights.emitter_count() == 0 {
            return None;
        }
        lights.build_hierarchy();
        let (x0, y0) = ctx.film_xy(0, width.max(1));
        let tiles_x = width.div_ceil(TILE);
        let tiles_y = height.div_ceil(TILE);
        let per_tile: Vec<(TileRegions, u64)> = (0..tiles_x * tiles_y)
            .into_par_iter()
            .map(|t| {
                let (tx, ty) = (t % tiles_x, t / tiles_x);
                let cols = tx * TILE..=((tx + 1) * TILE).min(width);
                let rows = ty * TILE..=((ty + 1) * TILE).min(height);
                let mut hits = Vec::with_capacity((TILE + 1) * (TILE + 1));
                let mut rays = 0;
                for y in rows {
                    for x in cols.clone() {
                        let film = Vec2::new((x0 as usize + x) as f32, (y0 as usize + y) as f32);
                        let ray = scene.camera.generate_ray(film, Vec2::splat(0.5));
                        let (hit, n) = scene.camera_intersect(&ray, hide_emitters);
                        rays += n;
                        if let Some(si) = hit {
                            hits.push((si.p, si.shading.n, lights.light_on_shape(si.shape)));
                        }
                    }
                }
                (TileRegions::of(lights, &hits, own), rays)
            })
            .collect();
        let rays = per_tile.iter().map(|&(_, n)| n).sum();
        Some(Self {
            window: (x0, y0, width, height),
            tiles: per_tile.into_iter().map(|(t, _)| t).collect(),
            rays,
        })
    }

    /// Whether these are the tiles of buffers `width × height` of pass `ctx`.
    pub fn fits(&self, ctx: &PassContext, width: usize, height: usize) -> bool {
        let (x0, y0) = ctx.film_xy(0, width.max(1));
        self.window == (x0, y0, width, height)
    }

    /// Camera rays traced to find the regions.
    pub fn rays(&self) -> u64 {
        self.rays
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
    /// receiver, from the streams of stage `stage` of pass `ctx`. A tile's receivers in its
    /// region of `cuts` (found once per render) draw from its cut; the others (hits the corner
    /// rays missed, a pixel filter's tails, a lens) from a cut made in this pass for them
    /// alone. Per cut, the receivers in each cell of `learned` (the distribution learned in
    /// earlier passes) draw from the mixture of the cell's table and the cut, those in no
    /// cell (or without learning) from the cut alone. `None` if the scene has no local light.
    /// `claim` is [`Claim::Exact`] but in the tests' negative controls.
    #[allow(clippy::too_many_arguments)]
    pub fn build(
        scene: &Scene,
        ctx: &PassContext,
        gbuf: &GBuffer,
        cuts: &TileCuts,
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
                let cached = cuts.tiles.get(t);
                // The tile's receivers with their learned cells, per region of the tile that
                // holds them (on a light: 2, the rest: 0), and those outside them.
                let (mut inside, mut on_light, mut outside) = (Vec::new(), Vec::new(), Vec::new());
                for y in rows.clone() {
                    for x in cols.clone() {
                        let i = y * gbuf.width + x;
                        if let Some(r) = gbuf.receiver(i) {
                            let cell = learned.and_then(|l| l.cell(r.p, r.n));
                            let on = lights.light_on_shape(r.at.shape);
                            match cached.and_then(|c| c.holding(r.p, r.n, on)) {
                                Some((2, _)) => on_light.push((i, cell)),
                                Some(_) => inside.push((i, cell)),
                                None => outside.push((i, cell)),
                            }
                        }
                    }
                }
                // The tile's streams are named by its place on the film, the cut and the cell.
                let (fx, fy) = ctx.film_xy(rows.start * gbuf.width + cols.start, gbuf.width);
                let key = ((u64::from(fy) / TILE as u64) << 32) | (u64::from(fx) / TILE as u64);
                let mut build = TileBuild::default();
                for (members, which, region) in [
                    (&inside, 0, cached.and_then(|c| c.rest.as_ref())),
                    (&on_light, 2, cached.and_then(|c| c.on_light.as_ref())),
                ] {
                    if let Some((_, cut)) = region.filter(|_| !members.is_empty()) {
                        build.add(
                            lights,
                            ctx,
                            cut,
                            members,
                            (key, which),
                            k,
                            learned,
                            claim,
                            stage,
                        );
                    }
                }
                let fresh = Region::of(
                    outside
                        .iter()
                        .filter_map(|&(i, _)| gbuf.receiver(i).map(|r| (r.p, r.n))),
                )
                .and_then(|region| region.cut(lights));
                if let Some(cut) = fresh {
                    build.fresh_nodes = cut.len();
                    build.fresh_receivers = outside.len();
                    build.add(
                        lights,
                        ctx,
                        &cut,
                        &outside,
                        (key, 1),
                        k,
                        learned,
                        claim,
                        stage,
                    );
                }
                build
            })
            .collect();
        // A receiver without a pool (no light reaches it) draws from another sampler.
        let mut pool_of = vec![u16::MAX; gbuf.width * gbuf.height];
        let mut summary = CutSummary {
            hierarchy_nodes,
            self_unlit: lights.self_unlit_count(),
            ..CutSummary::default()
        };
        let mut pools = Vec::with_capacity(per_tile.len());
        for (t, build) in per_tile.into_iter().enumerate() {
            if let Some(tile) = cuts.tiles.get(t) {
                let regions =
                    [&tile.rest, &tile.on_light].map(|r| r.as_ref().map(|(_, c)| c.len()));
                summary.tiles += usize::from(regions.iter().any(Option::is_some));
                summary.nodes += regions.iter().flatten().sum::<usize>();
                summary.on_light += usize::from(regions[1].is_some());
            }
            summary.fresh_cuts += usize::from(build.fresh_nodes > 0);
            summary.fresh_nodes += build.fresh_nodes;
            summary.fresh_receivers += build.fresh_receivers;
            for (i, j) in build.index {
                pool_of[i] = j;
                summary.receivers += 1;
            }
            summary.pools += build.pools.len();
            summary.entries += build.pools.iter().map(|(_, p)| p.len()).sum::<usize>();
            pools.push(build.pools);
        }
        Some(Self {
            tiles_x,
            pools,
            pool_of,
            summary,
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
        self.summary
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_region_holds_its_points_and_not_what_lies_beyond() {
        let floor: Vec<(Vec3, Vec3)> = (0..5)
            .flat_map(|i| (0..5).map(move |j| (Vec3::new(i as f32, 0.0, j as f32), Vec3::Y)))
            .collect();
        let region = Region::of(floor.iter().copied()).unwrap();
        assert_eq!(region.n, Vec3::Y);
        assert!(floor.iter().all(|&(p, n)| region.holds(p, n, None)));
        // Beyond the radius, or facing another way: another cut's receiver.
        assert!(!region.holds(Vec3::new(5.0, 0.0, 5.0), Vec3::Y, None));
        assert!(!region.holds(Vec3::new(2.0, 0.0, 2.0), Vec3::X, None));
        // Points whose normals differ: the region has none, and any normal is held.
        let mut corner = floor.clone();
        corner.push((Vec3::new(0.0, 1.0, 0.0), Vec3::X));
        let region = Region::of(corner.iter().copied()).unwrap();
        assert_eq!(region.n, Vec3::ZERO);
        assert!(region.holds(Vec3::new(2.0, 0.0, 2.0), -Vec3::Z, None));
        assert!(Region::of(std::iter::empty()).is_none());
    }
}
