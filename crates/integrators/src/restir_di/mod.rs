//! ReSTIR DI (Bitterli et al. 2020): reservoir-based direct lighting with spatial (and optional
//! temporal) reuse, combined unbiasedly with the MIS schemes of `restir-gris`.
//!
//! One pass, for every pixel at once (`docs/RESTIR_DI.md`):
//!
//! 1. **Primary hits** ([`GBuffer`]), adding what the camera sees directly.
//! 2. **Initial resampling**: `N_L` light candidates from the screen tile's cut of the light
//!    hierarchy ([`tiles`], the default where the scene has a local emitter), the power-based
//!    light sampler or the hierarchy's descent per receiver (stratified selection each way;
//!    with `learn` on, from the second pass on, a mixture of what lights delivered to the
//!    receiver's cell in earlier passes, [`learn`], and the tile's cut or the power sampler),
//!    streamed into a
//!    reservoir with weights `p̂/(N_L·p_L)` (with `--bsdf-samples resampled`, `N_B` BSDF
//!    candidates beside them, both weighted by their shares of the light/BSDF split); the result
//!    counts as confidence 1. Optional visibility reuse drops an occluded selection (biased).
//! 3. **Temporal reuse** (optional): the same pixel's reservoir from the previous pass.
//! 4. **Spatial reuse**: `R` rounds of `k` neighbours from a low-discrepancy disk pattern with a
//!    per-pixel random start, rejected by normal and depth similarity, resampled with the chosen
//!    MIS scheme ([`restir_gris::resample`]; the shift is the identity, see
//!    [`restir_lights::LightPoint`]).
//!    Each round reads the previous round's buffer and writes a new one, so the result does not
//!    depend on scheduling. Confidence is capped at `mcap` after every step. Steps 3 and 4
//!    are the shared [`crate::reuse::passes`]; this module plugs in the identity shift.
//! 5. **Shading**: the selected sample with a shadow ray, times its `W`; plus, unless they were
//!    resampled, `N_B` BSDF samples weighted by the power heuristic against the light strategy
//!    (the exact split is explained in [`mod@target`]); the first BSDF sample continues as a
//!    path-traced path when
//!    `max_depth > 2` (indirect light) or when it followed a delta lobe.

mod candidates;
pub mod learn;
pub mod pool;
mod settings;
mod shift;
pub mod target;
pub mod tiles;

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use restir_geometry::{Ray, offset_ray_origin};
use restir_gris::Reservoir;
use restir_lights::{
    Claim, HierarchySampler, LearnedCellSampler, LightPoint, PoolSampler, PowerSampler, Resolved,
};
use restir_materials::Bsdf;
use restir_sampling::Pcg32;
use restir_scene::Scene;

pub use settings::{
    AUTO_LIGHT_SAMPLER, BsdfDiffuse, BsdfSamples, LARGE_FILM_NEIGHBORS, LARGE_FILM_PIXELS,
    LEARN_MAX_EMITTERS, Learn, LightSampler, RestirDiSettings, TILE_CANDIDATES, Visibility,
};

use crate::bands::Bands;
use crate::motion::FrameMotion;
use crate::pass::{Integrator, PassContext};
use crate::path::{EmissionMis, PathSettings, PrevVertex, rr_survival, trace_path};
use crate::reuse::chain::PassChain;
use crate::reuse::gbuffer::{GBuffer, Receiver};
use crate::reuse::reciprocal;
use crate::reuse::seen::{SILHOUETTE_BUDGET, SeenEmission, SplatRays};
use crate::reuse::settings::mis_name;
use crate::stages::StageClock;
use restir_reuse::{ScreenReuse, Stages};
pub use shift::DiSample;
use shift::{DiReuse, visible};
use target::{StrategyCounts, evaluate};

/// Random-stream stages (see [`PassContext::stage_rng`]).
const STAGE_INITIAL: u64 = 1;
const STAGE_SHADE: u64 = 3;
const STAGE_POOL: u64 = 4;
const STAGE_LEARN_POOL: u64 = 5;
const STAGE_TILE_POOL: u64 = 6;
const STAGES: Stages = Stages {
    temporal: 2,
    spatial: 16,
};

/// The reservoir type: a light point with its colour at the receiver ([`DiSample`]), `W`, `M`,
/// `p̂`.
pub type DiReservoir = Reservoir<DiSample>;

/// The ReSTIR DI estimator (`--integrator restir-di`).
#[derive(Debug)]
pub struct RestirDiIntegrator {
    settings: RestirDiSettings,
    /// The strategy counts of the direct-light split and where BSDF samples go.
    counts: StrategyCounts,
    /// The neighbour pattern and the history of temporal reuse.
    reuse: ScreenReuse<DiSample, GBuffer>,
    clock: StageClock,
    /// What earlier passes recorded, with `learn` on.
    learning: learn::Learning,
    /// Whether a pass continues the passes the history and the learning come from.
    chain: PassChain,
    /// The per-pixel lookups of the last pass, kept so the next pass reuses their memory.
    lookups: std::sync::Mutex<Lookups>,
    /// More camera rays for the seen emission on emitter silhouettes (`edge_rays > 1`).
    seen: Option<SeenEmission>,
    /// What the last pass's tiles' light cuts held (`light_sampler = tiles`).
    cuts: std::sync::Mutex<Option<tiles::CutSummary>>,
    /// The tiles' regions and cuts, found once per render (`light_sampler = tiles`).
    tile_cuts: std::sync::Mutex<Option<std::sync::Arc<tiles::TileCuts>>>,
}

/// What a pass looks up once per pixel: the initial sample resolved in world space and the BSDF.
#[derive(Debug, Default)]
struct Lookups {
    resolved: Vec<Option<(LightPoint, Resolved)>>,
    bsdfs: Vec<Option<Bsdf>>,
    /// Each pixel's expected shading over the last spatial round's selection.
    expected: restir_reuse::passes::Expected,
    /// The pass's radiance, its reservoirs and its G-buffer, when no history keeps them.
    radiance: Vec<Vec3>,
    current: Vec<DiReservoir>,
    gbuf: Option<GBuffer>,
}

impl RestirDiIntegrator {
    /// An integrator with `settings`.
    pub fn new(settings: RestirDiSettings) -> Self {
        Self {
            counts: StrategyCounts {
                light: settings.candidates as f32,
                bsdf: settings.bsdf_candidates as f32,
                bsdf_on_diffuse: matches!(
                    settings.bsdf_diffuse,
                    BsdfDiffuse::Auto | BsdfDiffuse::On
                ),
                keep_share: settings.bsdf_diffuse == BsdfDiffuse::OffKeepingShare,
                // An unresolved `auto` is `separate`.
                resampled: settings.bsdf_samples.is_resampled(),
            },
            settings,
            reuse: ScreenReuse::default(),
            clock: StageClock::default(),
            learning: learn::Learning::default(),
            chain: PassChain::default(),
            lookups: Default::default(),
            cuts: Default::default(),
            tile_cuts: Default::default(),
            seen: (settings.edge_rays > 1).then(|| {
                SeenEmission::new(
                    settings.edge_rays,
                    SplatRays::Each,
                    Some(SILHOUETTE_BUDGET),
                    settings.edge_mask_from_pass,
                )
            }),
        }
    }

    /// The settings.
    pub fn settings(&self) -> &RestirDiSettings {
        &self.settings
    }

    /// The tiles' regions and cuts for this render's buffers, found at its first pass; adds
    /// the rays that found them to `rays`. `None` if the scene has no local light.
    fn tile_cuts(
        &self,
        scene: &Scene,
        ctx: &PassContext,
        gbuf: &GBuffer,
        rays: &mut u64,
    ) -> Option<std::sync::Arc<tiles::TileCuts>> {
        let mut kept = self.tile_cuts.lock().ok()?;
        if let Some(cuts) = kept
            .as_ref()
            .filter(|c| c.fits(ctx, gbuf.width, gbuf.height))
        {
            return Some(cuts.clone());
        }
        let hide = self.settings.path.hide_emitters;
        let own = if self.settings.light_sampler == LightSampler::TilesDroppingOwnLight {
            tiles::OwnLights::DroppedEverywhere
        } else {
            tiles::OwnLights::Apart
        };
        let cuts = tiles::TileCuts::probe(scene, ctx, gbuf.width, gbuf.height, hide, own)?;
        *rays += cuts.rays();
        let cuts = std::sync::Arc::new(cuts);
        *kept = Some(cuts.clone());
        Some(cuts)
    }

    /// Forgets the tiles' regions (another render, or the next frame).
    fn forget_tile_cuts(&self) {
        if let Ok(mut kept) = self.tile_cuts.lock() {
            *kept = None;
        }
    }

    /// Bytes per pixel of one reservoir buffer.
    pub const RESERVOIR_BYTES: usize = std::mem::size_of::<DiReservoir>();

    /// Bytes per pixel of the per-pass buffers that follow the film (all but the reciprocal
    /// rounds' table of shifts, which holds a window of rows).
    fn bytes_per_pixel(&self) -> usize {
        let reservoirs = if self.settings.reuse.temporal { 3 } else { 2 };
        let hits = if self.settings.reuse.temporal { 2 } else { 1 };
        let hit_bytes = GBuffer::BYTES_PER_PIXEL;
        reservoirs * Self::RESERVOIR_BYTES
            + hits * hit_bytes
            + std::mem::size_of::<Vec3>()
            + std::mem::size_of::<Option<(LightPoint, Resolved)>>()
            + std::mem::size_of::<Option<Bsdf>>()
            + if self.settings.reuse.shade_expected {
                std::mem::size_of::<Option<[f32; 3]>>()
            } else {
                0
            }
            + if self.settings.learn.is_on() && !self.settings.light_sampler.is_tiles() {
                learn::CellPools::bytes_per_pixel(self.settings.candidates)
            } else {
                0
            }
            + if self.settings.light_sampler.is_tiles() {
                tiles::LightTiles::bytes_per_pixel(self.settings.candidates)
                    + tiles::TileCuts::bytes_per_pixel()
            } else {
                0
            }
            + self.seen.as_ref().map_or(0, |_| std::mem::size_of::<u16>())
    }

    /// Shading at receiver `r` with its final reservoir: the reservoir's sample with a shadow
    /// ray, the BSDF samples, and the continuation (paths of `settings`, their light selection
    /// decided for the scene once per pass). Returns radiance, rays, and the reservoir's sample with what
    /// it delivered (when it was visible and lit the receiver).
    #[allow(clippy::too_many_arguments)] // the pixel and what the pass looked up for it
    fn shade(
        &self,
        scene: &Scene,
        settings: &PathSettings,
        r: &Receiver,
        bsdf: &Bsdf,
        ng: Vec3,
        res: &DiReservoir,
        expected: Option<[f32; 3]>,
        cached: &Option<(LightPoint, Resolved)>,
        rng: &mut Pcg32,
    ) -> (Vec3, u64, Option<(LightPoint, Vec3)>) {
        let mut l = Vec3::ZERO;
        let mut delivered = None;
        let mut rays = 0;
        let target_visibility = self.settings.visibility == Visibility::Target;
        if let Some(e) = expected {
            // Every input of the last spatial round shaded with its weight: the selection's
            // expectation (`ScreenReuse::reuse_expected`).
            l += Vec3::from_array(e);
        }
        if target_visibility {
            // The target includes visibility, so the selected sample's contribution here is
            // its ratio times its target (0 where occluded), with no ray and no evaluation.
            if let Some(y) = &res.sample {
                let selected = y.ratio * (res.own_target * res.ucw);
                delivered = Some((y.point, selected));
                if expected.is_none() {
                    l += selected;
                }
            }
        } else if expected.is_none()
            && let Some(y) = &res.sample
            && let Some(c) = match cached {
                Some((x, resolved)) if *x == y.point => *resolved,
                _ => scene.lights.resolve(&y.point),
            }
            .contact(&scene.lights, &y.point, r.p)
        {
            let e = evaluate(scene, r, bsdf, &y.point, &c, None, self.counts);
            if e.target > 0.0 && {
                rays += 1;
                visible(scene, r, ng, &c)
            } {
                l += e.contribution * res.ucw;
                delivered = Some((y.point, e.contribution * res.ucw));
            }
        }

        // BSDF samples; the first continues the path when indirect light or delta lobes need it.
        let max_depth = settings.max_segments();
        let continues = max_depth > 2 || scene.features.has_delta_lobes;
        let n_b = self.counts.samples_at(bsdf).bsdf as u32;
        let counts = self.counts.at(bsdf);
        let samples = n_b.max(u32::from(continues));
        // BSDF samples after the first only look for emitters at their first hit.
        let direct_only = PathSettings {
            max_depth: 2,
            ..*settings
        };
        for b in 0..samples {
            let u_lobe = rng.next_f32();
            let u_dir = rng.next_2d();
            let u_rr = rng.next_f32();
            let Some(bs) = bsdf.sample(r.wo, u_lobe, u_dir) else {
                continue;
            };
            let delta = bs.lobe.is_delta();
            let cont = b == 0 && continues;
            if !cont && n_b == 0 {
                continue;
            }
            if cont && !delta && max_depth <= 2 && n_b == 0 {
                continue; // nothing this ray could add
            }
            let mut beta = bs.f / bs.pdf_sa;
            let d = r.frame().to_world(bs.wi);
            let ray = Ray::new(offset_ray_origin(r.p, ng, d), d);
            let prev = PrevVertex {
                p: r.p,
                n: r.n,
                pdf_sa: bs.pdf_sa,
                delta,
                mis: EmissionMis::Counted {
                    light_samples: counts.light,
                    bsdf_samples: counts.bsdf,
                },
            };
            let path = if cont { settings } else { &direct_only };
            if cont && settings.rr_depth <= 1 {
                let q = rr_survival(beta.max_element(), bs.eta);
                if u_rr >= q {
                    continue;
                }
                beta /= q;
            }
            if !beta.is_finite() || beta.max_element() <= 0.0 {
                continue;
            }
            let (li, n) = trace_path(scene, path, ray, 1, beta, Some(prev), rng);
            l += li;
            rays += n;
        }
        (l, rays, delivered)
    }
}

impl Integrator for RestirDiIntegrator {
    fn name(&self) -> &'static str {
        "restir-di"
    }

    fn describe(&self) -> String {
        let s = &self.settings;
        format!(
            "restir-di max_depth={}{} {} light_sampler={} bsdf_candidates={} {} {} {} \
             {} spatial_rounds={} reciprocal={} mis={} mcap={} {} \
             visibility={} {}{}{}",
            s.path.max_depth,
            if s.path.max_segments() > 2 {
                format!(" continuation_{}", s.path.nee_label())
            } else {
                String::new()
            },
            s.candidates_label(),
            s.light_sampler.name().to_string()
                + &if s.learn.is_on() {
                    format!(
                        " learn={} learn_share={} learn_prior={} learn_cells={} learn_group={}",
                        s.learn.name(),
                        s.learn_share,
                        s.learn_prior,
                        s.learn_cells,
                        s.learn_group
                    )
                } else {
                    " learn=off".to_string()
                }
                + &s.learn_reason()
                    .map_or(String::new(), |r| format!(" ({r})")),
            s.bsdf_candidates,
            s.bsdf_diffuse_label(),
            s.bsdf_samples_label(),
            s.neighbors_label(),
            s.radius_label(),
            s.reuse.spatial_rounds,
            s.reuse.reciprocal,
            mis_name(s.reuse.mis),
            s.reuse.mcap,
            s.reuse.describe_temporal(),
            s.visibility.name(),
            s.reuse.describe_shading(s.visibility == Visibility::Target),
            if s.edge_rays > 1 {
                format!(" edge_rays={}", s.edge_rays)
            } else {
                String::new()
            },
            if s.is_unbiased() { "" } else { " (biased)" }
        )
    }

    fn stage_seconds(&self) -> Vec<(&'static str, f64)> {
        self.clock.seconds()
    }

    fn learned(&self) -> Option<String> {
        self.settings.learn.is_on().then(|| self.learning.summary())
    }

    fn silhouettes(&self) -> Option<String> {
        self.seen.as_ref().and_then(SeenEmission::summary)
    }

    fn light_cuts(&self) -> Option<String> {
        let summary = *self.cuts.lock().ok()?;
        summary.map(|c| c.describe())
    }

    /// The previous frame's reservoirs are reused with the motion: light samples move with
    /// their lights, receivers are found by motion vectors, targets of previous domains are
    /// evaluated in the previous frame's scene.
    fn next_frame(&self, motion: std::sync::Arc<FrameMotion>) {
        self.chain.next_frame();
        self.reuse.next_frame(Some(motion));
        self.learning.reset();
        self.forget_tile_cuts();
        if let Some(seen) = &self.seen {
            seen.clear();
        }
    }

    fn halo(&self) -> u32 {
        self.settings.reuse.halo()
    }

    fn buffer_bytes(&self, width: u32, height: u32, threads: usize) -> u64 {
        let (w, h) = (width as usize, height as usize);
        (w * h) as u64 * self.bytes_per_pixel() as u64
            + reciprocal::table_bytes::<DiSample>(&self.settings.reuse, w, h, threads)
    }

    fn render_pass(&self, scene: &Scene, ctx: &PassContext, accum: &mut [DVec3]) -> u64 {
        let s = &self.settings;
        if !self.chain.advance(ctx.seed, ctx.pass) {
            // Another render: nothing of the passes before carries over.
            self.reuse.next_frame(None);
            self.learning.reset();
            self.forget_tile_cuts();
            if let Some(seen) = &self.seen {
                seen.clear();
            }
        }
        let reuse = &s.reuse;
        let n = accum.len();
        // The last pass's buffers, reused (a fresh buffer is faulted in page by page).
        let Lookups {
            mut resolved,
            mut bsdfs,
            mut expected,
            mut radiance,
            mut current,
            gbuf: recycled,
        } = self
            .lookups
            .lock()
            .map(|mut l| std::mem::take(&mut *l))
            .unwrap_or_default();
        radiance.clear();
        radiance.resize(n, Vec3::ZERO);
        let keep = s.path.max_segments() >= 2;
        let (gbuf, mut rays) = self.clock.time("primary", || {
            let hide = s.path.hide_emitters;
            GBuffer::trace_into(scene, ctx, hide, true, keep, &mut radiance, recycled)
        });
        // The seen emission on emitter silhouettes from more camera rays (`radiance` holds the
        // G-buffer's seen emission only, nothing else yet).
        if let Some(seen) = &self.seen
            && !s.path.hide_emitters
        {
            rays += self.clock.time("silhouettes", || {
                seen.supersample(scene, ctx, &gbuf, None, &mut radiance)
            });
        }
        let w = gbuf.width;
        let bands = Bands::new(w);
        if keep {
            // Initial resampling.
            let start = std::time::Instant::now();
            if s.light_sampler.is_hierarchy() {
                scene.lights.build_hierarchy();
            }
            let pool = s.light_sampler.is_pool().then(|| {
                let (fw, fh) = scene.camera.resolution();
                let tiles =
                    pool::LightPool::tiles_for(fw as usize * fh as usize, s.candidates as usize);
                pool::LightPool::build(scene, ctx, tiles, STAGE_POOL)
            });
            // The distribution learned in the passes before this one.
            let learned = if s.learn.is_on() {
                self.learning.sampler(
                    scene,
                    s.learn_share,
                    s.learn_prior,
                    s.learn_cells,
                    s.learn_group,
                )
            } else {
                None
            };
            // Candidates from the tiles' cuts of the light hierarchy (mixed with the learned
            // cells' tables), else from the learned cells' pools (mixed with the power sampler).
            let cuts_start = std::time::Instant::now();
            let light_tiles = s.light_sampler.is_tiles().then(|| {
                let cuts = self.tile_cuts(scene, ctx, &gbuf, &mut rays)?;
                let claim = if s.light_sampler == LightSampler::TilesWithPowerPmf {
                    Claim::Power
                } else if s.learn == Learn::WithoutDefensiveShare {
                    Claim::TableAlone
                } else {
                    Claim::Exact
                };
                tiles::LightTiles::build(
                    scene,
                    ctx,
                    &gbuf,
                    &cuts,
                    s.candidates,
                    learned.as_deref(),
                    claim,
                    STAGE_TILE_POOL,
                )
            });
            let light_tiles = light_tiles.flatten();
            if let (Some(t), Ok(mut last)) = (&light_tiles, self.cuts.lock()) {
                *last = Some(t.summary());
            }
            let cuts_time = cuts_start.elapsed();
            if s.light_sampler.is_tiles() {
                self.clock.add("cuts", cuts_time);
            }
            let cell_pools = learned.as_ref().filter(|_| light_tiles.is_none()).map(|l| {
                learn::CellPools::build(
                    l,
                    scene,
                    ctx,
                    &gbuf,
                    s.candidates,
                    s.learn != Learn::WithoutDefensiveShare,
                    STAGE_LEARN_POOL,
                )
            });
            current.clear();
            current.resize(n, DiReservoir::empty());
            // Each pixel's initial sample resolved in world space and its BSDF (textures looked
            // up), which the shifts into its neighbours and its shading would otherwise look up
            // again.
            resolved.clear();
            resolved.resize(n, None);
            bsdfs.clear();
            bsdfs.resize(n, None);
            // Bands of a tile's height, walked tile by tile: a tile's pixels draw from the same
            // pool, which then stays in cache (the pools of a whole row of tiles do not, with
            // many candidates). Each pixel's numbers are its own, so the order changes nothing.
            let tile_bands = Bands::of_rows(w, tiles::TILE);
            rays += tile_bands.run(
                (&mut current[..], (&mut resolved[..], &mut bsdfs[..])),
                |first, (out, (cache, bsdfs))| {
                    let mut rays = 0;
                    let rows = out.len() / w.max(1);
                    let order = (0..w.div_ceil(tiles::TILE)).flat_map(|tx| {
                        let cols = tx * tiles::TILE..((tx + 1) * tiles::TILE).min(w);
                        (0..rows).flat_map(move |y| cols.clone().map(move |x| y * w + x))
                    });
                    for i in order {
                        let (res, cached, pixel_bsdf) = (&mut out[i], &mut cache[i], &mut bsdfs[i]);
                        let index = first + i;
                        if let Some(r) = gbuf.receiver(index) {
                            let bsdf = r.resolve_bsdf(scene);
                            let mut rng = ctx.stage_rng(index, STAGE_INITIAL);
                            let ng = gbuf.ng[index];
                            let pool_tile = || {
                                pool.as_ref().map(|p| {
                                    let (x, y) = ctx.film_xy(index, w);
                                    p.tile_of(ctx, x, y)
                                })
                            };
                            let (init, nr, y) = if let Some(tile_pool) = light_tiles
                                .as_ref()
                                .and_then(|t| t.pool(index, index % w, index / w))
                            {
                                let sampler = LearnedCellSampler::new(tile_pool);
                                self.initial(scene, r, &bsdf, ng, sampler, &mut rng)
                            } else if let Some(cell_pool) =
                                cell_pools.as_ref().and_then(|p| p.pool(index))
                            {
                                let sampler = LearnedCellSampler::new(cell_pool);
                                self.initial(scene, r, &bsdf, ng, sampler, &mut rng)
                            } else if let Some(tile) = pool_tile() {
                                let sampler =
                                    if s.light_sampler == LightSampler::PoolWithoutSelection {
                                        PoolSampler::without_selection(tile)
                                    } else {
                                        PoolSampler::new(tile)
                                    };
                                self.initial(scene, r, &bsdf, ng, sampler, &mut rng)
                            } else if s.light_sampler.is_hierarchy() {
                                let sampler = HierarchySampler {
                                    claim_power_density: s.light_sampler
                                        == LightSampler::BvhWithPowerPmf,
                                };
                                self.initial(scene, r, &bsdf, ng, sampler, &mut rng)
                            } else {
                                self.initial(scene, r, &bsdf, ng, PowerSampler, &mut rng)
                            };
                            *res = init;
                            *cached = y;
                            *pixel_bsdf = Some(bsdf);
                            rays += nr;
                        }
                    }
                    rays
                },
            );
            self.clock
                .add("initial", start.elapsed().saturating_sub(cuts_time));

            // Temporal and spatial reuse.
            let history = self.reuse.take_history(reuse, n);
            let motion = history.as_ref().and_then(|h| h.motion.as_deref());
            let shift = DiReuse {
                scene,
                counts: self.counts,
                gbuf: &gbuf,
                prev: history.as_ref().map(|h| &h.surfaces),
                motion,
                prev_scene: match motion {
                    Some(m) if !reuse.temporal_current_scene => &m.prev_scene,
                    _ => scene,
                },
                visibility: s.visibility == Visibility::Target,
                resolved: &resolved,
                bsdfs: &bsdfs,
            };
            // Shading every input of the last round needs each input's value over its target,
            // which is the sample's colour only when the target includes visibility.
            let expect = (reuse.shade_expected && s.visibility == Visibility::Target)
                || s.shade_ignoring_visibility;
            if !expect {
                expected.clear();
            }
            let report = self.reuse.reuse_expected(
                &shift,
                reuse,
                ctx,
                &gbuf,
                history.as_ref(),
                STAGES,
                &mut current,
                expect.then_some(&mut expected),
            );
            rays += self.clock.add_reuse(&report);

            // Shading; the continuations' light selection decided once for the pass (a no-op
            // where `resolve` decided it).
            let start = std::time::Instant::now();
            let path = s.path.resolved(&scene.features);
            let grid = s
                .learn
                .is_on()
                .then(|| learn::Learning::grid(scene, s.learn_cells));
            let per_band: Vec<(u64, Vec<learn::Record>)> = radiance
                .par_chunks_mut(bands.pixels())
                .enumerate()
                .map(|(band, out)| {
                    let mut rays = 0;
                    let mut records = Vec::new();
                    for (i, l) in out.iter_mut().enumerate() {
                        let index = bands.first(band) + i;
                        if let Some(r) = gbuf.receiver(index) {
                            let mut rng = ctx.stage_rng(index, STAGE_SHADE);
                            let ng = gbuf.ng[index];
                            let looked_up;
                            let bsdf = match &bsdfs[index] {
                                Some(b) => b,
                                None => {
                                    looked_up = r.resolve_bsdf(scene);
                                    &looked_up
                                }
                            };
                            let (li, nr, delivered) = self.shade(
                                scene,
                                &path,
                                r,
                                bsdf,
                                ng,
                                &current[index],
                                expected.get(index).copied().flatten(),
                                &resolved[index],
                                &mut rng,
                            );
                            *l += li;
                            rays += nr;
                            if let (Some(g), Some((y, c))) = (&grid, delivered)
                                && let Some(e) = scene.lights.emitter_of(y.light, y.prim)
                            {
                                records.push(learn::record(g, r.p, r.n, e as u32, c));
                            }
                        }
                    }
                    (rays, records)
                })
                .collect();
            let mut records = Vec::with_capacity(per_band.len());
            for (nr, band) in per_band {
                rays += nr;
                records.push(band);
            }
            self.clock.add("shade", start.elapsed());
            if grid.is_some() {
                // What this pass learned serves the passes after it, never this one.
                self.clock.time("learn", || self.learning.record(records));
            }
        }
        accum
            .par_iter_mut()
            .zip(radiance.par_iter())
            .for_each(|(a, l)| *a += l.as_dvec3());
        // The history keeps the surfaces and reservoirs with temporal reuse; else the next
        // pass reuses their memory.
        let (gbuf, current) = if keep && reuse.temporal {
            self.reuse.keep(reuse, gbuf, current);
            (None, Vec::new())
        } else {
            (Some(gbuf), current)
        };
        if let Ok(mut l) = self.lookups.lock() {
            *l = Lookups {
                resolved,
                bsdfs,
                expected,
                radiance,
                current,
                gbuf,
            };
        }
        rays
    }
}
