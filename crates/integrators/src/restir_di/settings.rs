//! ReSTIR DI settings and their parsing from named parameters (XML scenes and the command line
//! use the same names; the names Lajolla ReSTIR ports use are accepted too). The reuse settings
//! are [`ReuseSettings`]. Some defaults are rules of the scene summary, decided once when the
//! integrator is made ([`RestirDiSettings::resolve`]): the candidate source
//! ([`AUTO_LIGHT_SAMPLER`] where the scene has a local emitter), learning across passes (up
//! to [`LEARN_MAX_EMITTERS`] emitters) and, from the source, the candidate count
//! ([`TILE_CANDIDATES`] for the tiles' cuts).

use crate::reuse::params::{NEIGHBOR_NAMES, RADIUS_NAMES, ReuseParams, large_film_label};
use restir_scene::SceneFeatures;

use crate::film::Reconstruction;
use crate::params::{Param, ParamError, ParamProblem, ParamSet};
use crate::path::PathSettings;
use crate::reuse::settings::ReuseSettings;
use restir_reuse::settings::DIRECT_RADIUS;

/// The candidate source `light_sampler = auto` takes for a scene with local emitters (emissive
/// triangles and other lights besides the environment): the screen tiles' cuts of the light
/// hierarchy ([`super::tiles`]). On the DI training family at 640×360 (8 passes, equal CPU
/// time, with learning as `auto` decides) they are 1.08× the power sampler's pool at the median
/// (0.88–1.94×) and 0.69–4.78× in squared error, 4.78× on the training Sponza with lamps, whose
/// receivers right under a lamp the power sampler rarely reaches; a scene lit by an environment
/// alone has nothing to cut and keeps the power sampler.
pub const AUTO_LIGHT_SAMPLER: LightSampler = LightSampler::Tiles;

/// Emitter-table entries (emissive triangles and other lights, the environment not counted) up to
/// which `learn = auto` learns across passes. On the DI training family at 640×360 (16 passes,
/// equal CPU time; `docs/RESTIR_DI.md`, "Learning across passes") learning pays on every member
/// of 10³ to 2.4·10⁴ emitters (1.00–1.69×) and loses on the three of 10⁵ and more (0.62–0.88×,
/// variance 1.10–1.27×: a cell's records then spread over more emitters than a table tells
/// apart); the bound sits between the two, where the rule lives.
pub const LEARN_MAX_EMITTERS: usize = 50_000;

/// Light candidates per pixel where the candidates were not named and come from the tiles' cuts
/// (the default light sampler), learning across passes or not; the default
/// [`RestirDiSettings::candidates`] is for the other sources. Chosen on the DI training
/// family (`docs/RESTIR_DI.md`, "Eight neighbours, and 12 candidates from the tiles' cuts"):
/// without learning a tile's cut knows no visibility and, on 10⁵ lights, spreads over many of
/// similar unshadowed contribution, so more candidates pay (1.25× eight at 640×360); with
/// learning 12 pay too (1.07× eight at the median of the nine learning members at 640×360 and
/// at 320×240, up to 1.31× on the glossy hall and 1.52× on 10⁴ spheres at the smaller film).
pub const TILE_CANDIDATES: u32 = 12;

/// Spatial neighbours per round where they were not named and the film has at least
/// [`LARGE_FILM_PIXELS`] pixels (else [`restir_reuse::settings::DIRECT_NEIGHBORS`], 8). A film of
/// smaller pixels sees more alike surfaces within the reuse radius, so more neighbours pay:
/// chosen on the DI training family at 1280×720 (`docs/RESTIR_DI.md`, "Twelve neighbours on
/// large films").
pub const LARGE_FILM_NEIGHBORS: u32 = 12;

pub use crate::reuse::params::LARGE_FILM_PIXELS;

/// Where initial candidates' lights come from (`--light-sampler`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightSampler {
    /// Decided from the scene: [`AUTO_LIGHT_SAMPLER`] where it has a local emitter, else
    /// [`LightSampler::Power`] (the default; [`RestirDiSettings::resolve`]).
    Auto,
    /// The power-based light sampler (the paper's choice), its draws presampled once per pass
    /// into a pool that blocks of pixels share (see [`super::pool`]).
    Power,
    /// Per 16×16-pixel tile, a cut of the light hierarchy for the tile's primary hits, drawn
    /// from by an alias table (see [`super::tiles`]).
    Tiles,
    /// The light hierarchy: per receiver, a descent of a light BVH by power, distance and
    /// orientation, with its exact probability (`restir_lights::LightSet::sample_hierarchy`).
    Bvh,
    /// A negative control for the tests, never a choice: candidates from the hierarchy weighted
    /// as if the power table had drawn them (biased).
    #[doc(hidden)]
    BvhWithPowerPmf,
    /// A negative control for the tests, never a choice: candidates from the tiles' cuts
    /// weighted as if the power table had drawn them (biased).
    #[doc(hidden)]
    TilesWithPowerPmf,
    /// A negative control for the tests, never a choice: the tiles' cuts leaving every light no
    /// selection for the receivers on it, whether or not it can light itself (biased where one
    /// does).
    #[doc(hidden)]
    TilesDroppingOwnLight,
    /// A negative control for the tests, never a choice: the power sampler's pool with the
    /// selection probability of whole lights (spheres, point lights, the environment) left out
    /// of their candidates' density (biased).
    #[doc(hidden)]
    PoolWithoutSelection,
}

impl LightSampler {
    /// The names `--light-sampler` takes.
    pub const NAMES: &[(&str, LightSampler)] = &[
        ("auto", LightSampler::Auto),
        ("power", LightSampler::Power),
        ("tiles", LightSampler::Tiles),
        ("bvh", LightSampler::Bvh),
    ];

    /// Whether candidates come from the tiles' light cuts ([`super::tiles`]).
    pub fn is_tiles(self) -> bool {
        matches!(
            self,
            LightSampler::Tiles
                | LightSampler::TilesWithPowerPmf
                | LightSampler::TilesDroppingOwnLight
        )
    }

    /// Whether candidates come from the light hierarchy.
    pub fn is_hierarchy(self) -> bool {
        matches!(self, LightSampler::Bvh | LightSampler::BvhWithPowerPmf)
    }

    /// The name `--light-sampler` takes.
    pub fn name(self) -> &'static str {
        match self {
            LightSampler::Auto => "auto",
            LightSampler::Power => "power",
            LightSampler::Tiles => "tiles",
            LightSampler::Bvh => "bvh",
            LightSampler::BvhWithPowerPmf => "bvh-with-power-pmf",
            LightSampler::TilesWithPowerPmf => "tiles-with-power-pmf",
            LightSampler::TilesDroppingOwnLight => "tiles-dropping-own-light",
            LightSampler::PoolWithoutSelection => "pool-without-selection",
        }
    }

    /// Whether candidates come from the power sampler's pool ([`super::pool`]).
    pub fn is_pool(self) -> bool {
        matches!(
            self,
            LightSampler::Power | LightSampler::PoolWithoutSelection
        )
    }
}

/// Whether candidates' lights come from a distribution learned in earlier passes (`--learn`,
/// [`super::learn`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Learn {
    /// Decided from the scene summary ([`RestirDiSettings::resolve`]): on up to
    /// [`LEARN_MAX_EMITTERS`] emitters, off above (off where nothing resolves it).
    Auto,
    /// The light sampler alone.
    Off,
    /// From the second pass on, per cell of a world-space grid, a mixture of what lights
    /// delivered there in earlier passes (after their shadow rays) and the power sampler.
    On,
    /// A negative control for the tests, never a choice: the learned mixture's candidates
    /// weighted by the cell's table alone, forgetting the power sampler's defensive share
    /// (biased).
    #[doc(hidden)]
    WithoutDefensiveShare,
}

impl Learn {
    /// The names `--learn` takes.
    pub const NAMES: &[(&str, Learn)] = &[
        ("auto", Learn::Auto),
        ("off", Learn::Off),
        ("on", Learn::On),
    ];

    /// The name `--learn` takes.
    pub fn name(self) -> &'static str {
        match self {
            Learn::Auto => "auto",
            Learn::Off => "off",
            Learn::On => "on",
            Learn::WithoutDefensiveShare => "without-defensive-share",
        }
    }

    /// Whether passes learn and later passes draw from what was learned.
    pub fn is_on(self) -> bool {
        matches!(self, Learn::On | Learn::WithoutDefensiveShare)
    }
}

/// Whether receivers without a glossy lobe take the BSDF samples (`--bsdf-diffuse`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BsdfDiffuse {
    /// Decided from the scene summary ([`RestirDiSettings::resolve`]): on when the scene has an
    /// environment (on where nothing resolves it).
    Auto,
    /// Only receivers with a glossy lobe take BSDF samples; at the others light sampling takes
    /// the whole direct light.
    Off,
    /// Every receiver takes `bsdf_candidates` BSDF samples.
    On,
    /// A negative control for the tests, never a choice: receivers without a glossy lobe skip
    /// their BSDF samples, but their light strategy keeps only its power-heuristic share, as if
    /// they took them (biased: the BSDF samples' share of their direct light is lost).
    #[doc(hidden)]
    OffKeepingShare,
}

impl BsdfDiffuse {
    /// The names `--bsdf-diffuse` takes.
    pub const NAMES: &[(&str, BsdfDiffuse)] = &[
        ("auto", BsdfDiffuse::Auto),
        ("off", BsdfDiffuse::Off),
        ("on", BsdfDiffuse::On),
    ];

    /// The name `--bsdf-diffuse` takes.
    pub fn name(self) -> &'static str {
        match self {
            BsdfDiffuse::Auto => "auto",
            BsdfDiffuse::Off => "off",
            BsdfDiffuse::On => "on",
            BsdfDiffuse::OffKeepingShare => "off-keeping-share",
        }
    }
}

/// Where ReSTIR DI's BSDF samples go (`--bsdf-samples`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BsdfSamples {
    /// Decided from the scene summary ([`RestirDiSettings::resolve`]): `resampled` for direct
    /// light (`max_depth` 2) with visibility in every target when the scene has an environment
    /// beside its local lights (where diffuse receivers take BSDF samples), else `separate`
    /// (also where nothing resolves it): with indirect light the continuation traces a BSDF ray
    /// of its own, which resampling does not save.
    Auto,
    /// Traced at shading and added to the reservoir's light strategy with their MIS weights; the
    /// reservoirs hold the light strategy's share of the direct light.
    Separate,
    /// Candidates of initial resampling beside the light candidates, MIS-weighted against them;
    /// the reservoirs hold the whole direct light and reuse spreads what BSDF samples found
    /// (needs visibility in every target).
    Resampled,
    /// A negative control for the tests, never a choice: resampled, but a BSDF candidate's weight
    /// ignores its MIS share, as if the light candidates could not find its point (biased: the
    /// light found by both strategies counts twice where both reach it).
    #[doc(hidden)]
    ResampledWithoutShare,
}

impl BsdfSamples {
    /// The names `--bsdf-samples` takes.
    pub const NAMES: &[(&str, BsdfSamples)] = &[
        ("auto", BsdfSamples::Auto),
        ("separate", BsdfSamples::Separate),
        ("resampled", BsdfSamples::Resampled),
    ];

    /// The name `--bsdf-samples` takes.
    pub fn name(self) -> &'static str {
        match self {
            BsdfSamples::Auto => "auto",
            BsdfSamples::Separate => "separate",
            BsdfSamples::Resampled => "resampled",
            BsdfSamples::ResampledWithoutShare => "resampled-without-share",
        }
    }

    /// Whether BSDF samples are candidates of initial resampling.
    pub fn is_resampled(self) -> bool {
        matches!(
            self,
            BsdfSamples::Resampled | BsdfSamples::ResampledWithoutShare
        )
    }
}

/// Where ReSTIR DI tests the visibility of its light samples (`--visibility`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visibility {
    /// Once, at shading: the targets have no visibility term (Bitterli et al. 2020's unbiased
    /// configuration). Every reuse step is free of rays; the selected sample is occluded as often
    /// as the unshadowed target makes it.
    Shading,
    /// In every target: `p̂·V`, a shadow ray from the receiver a target is evaluated at (the
    /// initial selection, and each shift of the reuse passes, in the scene of the shift's
    /// domain). Unbiased; shading needs no shadow ray (a selected sample is visible).
    Target,
    /// The initial selection only, reuse targets without it (Bitterli et al.'s visibility
    /// reuse): biased wherever neighbours differ in visibility.
    ReuseBiased,
}

impl Visibility {
    /// The names `--visibility` takes.
    pub const NAMES: &[(&str, Visibility)] = &[
        ("shading", Visibility::Shading),
        ("target", Visibility::Target),
        ("reuse", Visibility::ReuseBiased),
    ];

    /// The name `--visibility` takes.
    pub fn name(self) -> &'static str {
        match self {
            Visibility::Shading => "shading",
            Visibility::Target => "target",
            Visibility::ReuseBiased => "reuse",
        }
    }

    /// Whether the initial selection is tested (and an occluded one dropped).
    pub fn tests_initial(self) -> bool {
        self != Visibility::Shading
    }
}

/// Everything ReSTIR DI can be told.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestirDiSettings {
    /// Path settings: depth semantics, Russian roulette, hidden emitters.
    pub path: PathSettings,
    /// Spatial and temporal reuse.
    pub reuse: ReuseSettings,
    /// Light candidates per pixel in initial resampling, `N_L` (default 8 from the power
    /// sampler's pool or the light hierarchy, chosen by an equal-CPU-time sweep on a training family of generated
    /// scenes, `docs/studies/2026-12-01-restir-di-defaults.md`; [`TILE_CANDIDATES`] where
    /// [`RestirDiSettings::resolve`] finds the tiles' cuts the source).
    pub candidates: u32,
    /// Whether `candidates` was named (a parameter or the command line); else
    /// [`RestirDiSettings::resolve`] decides it from the light sampler.
    pub candidates_named: bool,
    /// Whether [`RestirDiSettings::resolve`] raised the count to
    /// [`TILE_CANDIDATES`] (`--stats` says why).
    pub candidates_decided: bool,
    /// Whether the reuse radius was named; else [`RestirDiSettings::resolve`] widens it by a
    /// splatting film's reach.
    pub radius_named: bool,
    /// Whether the neighbour count was named; else [`RestirDiSettings::resolve`] raises it to
    /// [`LARGE_FILM_NEIGHBORS`] on a film of at least [`LARGE_FILM_PIXELS`] pixels.
    pub neighbors_named: bool,
    /// Whether [`RestirDiSettings::resolve`] raised the neighbour count (`--stats` says why).
    pub neighbors_raised: bool,
    /// The splatting film's reach [`RestirDiSettings::resolve`] widened the radius by, if it
    /// did (`--stats` says why).
    pub radius_widened_by: Option<u32>,
    /// Where candidates' lights come from (default the power sampler).
    pub light_sampler: LightSampler,
    /// Whether candidates come from a light distribution learned across passes (default `auto`:
    /// on up to [`LEARN_MAX_EMITTERS`] emitters, chosen on the training family at 640×360;
    /// `docs/RESTIR_DI.md`, "Learning across passes").
    pub learn: Learn,
    /// With `learn` on, the share of candidate selections that go to the learned tables, in
    /// `[0, 1)` (the rest, the defensive share, to the power sampler; default 0.5).
    pub learn_share: f32,
    /// With `learn` on, grid cells per scene diameter along each axis (default 16).
    pub learn_cells: f32,
    /// With `learn` on, the records a cell needs for its table to take half of `learn_share`
    /// (a cell of `n` records takes `learn_share · n / (n + learn_prior)`; default 64).
    pub learn_prior: f32,
    /// With `learn` on, consecutive triangles of one mesh light that fit in a box whose diagonal
    /// is this fraction of a cell's side are learned as one too ([`restir_lights::EmitterGroups`];
    /// 0: each emitter alone; default 1, chosen on the training family).
    pub learn_group: f32,
    /// When `learn` was `auto` and [`RestirDiSettings::resolve`] decided it: the emitter count
    /// it decided from (`--stats` says why learning is on or off).
    pub learn_decided_from: Option<usize>,
    /// BSDF samples per pixel, `N_B` (default 1), combined with the reservoirs' light strategy
    /// by the power heuristic with sample counts.
    pub bsdf_candidates: u32,
    /// Whether receivers without a glossy lobe take the BSDF samples too (default auto: when
    /// the scene has an environment; chosen on the training family, `docs/RESTIR_DI.md`).
    pub bsdf_diffuse: BsdfDiffuse,
    /// Whether `bsdf_diffuse` was auto and [`RestirDiSettings::resolve`] decided it (`--stats`
    /// says why).
    pub bsdf_diffuse_decided: bool,
    /// Where the BSDF samples go (default auto: resampled with the light candidates for the
    /// direct light of a scene with an environment beside its local lights;
    /// `docs/RESTIR_DI.md`).
    pub bsdf_samples: BsdfSamples,
    /// When `bsdf_samples` was auto and [`RestirDiSettings::resolve`] decided it: whether the
    /// scene has an environment beside local lights.
    pub bsdf_samples_decided_from: Option<bool>,
    /// Camera rays for the emission seen on emitter silhouettes, the G-buffer's included
    /// (`crate::reuse::seen`; 1: the G-buffer's only; default 4, chosen on the training family:
    /// a hall's squared error 3.6× lower at the same cost; where the mask is a small part of
    /// the film, raised by [`crate::reuse::seen::SILHOUETTE_BUDGET`]).
    pub edge_rays: u32,
    /// Negative control only: choose the pixels that get `edge_rays` by what the pass's own
    /// camera ray saw (an emitter) instead of a mask made without the pass's samples (biased).
    #[doc(hidden)]
    pub edge_mask_from_pass: bool,
    /// Where visibility is tested (default in every target: chosen on the training family with
    /// the reuse defaults, `docs/studies/2026-12-02-restir-di-light-pool-and-defaults.md`).
    pub visibility: Visibility,
    /// Negative control only: shading takes every input of the last spatial round with its
    /// weight also where the targets lack visibility, which then counts occluded inputs
    /// (biased).
    #[doc(hidden)]
    pub shade_ignoring_visibility: bool,
}

impl RestirDiSettings {
    /// The defaults: 8 candidates (12 from the tiles' cuts, decided by
    /// [`RestirDiSettings::resolve`]), one round of reuse over four reciprocal pairs within 2
    /// pixels ([`ReuseSettings::direct`]), visibility in every target, one BSDF sample (chosen
    /// on a training family of generated scenes; `docs/RESTIR_DI.md`).
    pub fn new(path: PathSettings) -> Self {
        Self {
            path,
            reuse: ReuseSettings::direct(),
            candidates: 8,
            candidates_named: false,
            candidates_decided: false,
            radius_named: false,
            neighbors_named: false,
            neighbors_raised: false,
            radius_widened_by: None,
            light_sampler: LightSampler::Auto,
            learn: Learn::Auto,
            learn_share: 0.5,
            learn_cells: 16.0,
            learn_prior: 64.0,
            learn_group: 1.0,
            learn_decided_from: None,
            bsdf_candidates: 1,
            bsdf_diffuse: BsdfDiffuse::Auto,
            bsdf_diffuse_decided: false,
            bsdf_samples: BsdfSamples::Auto,
            bsdf_samples_decided_from: None,
            edge_rays: 4,
            edge_mask_from_pass: false,
            shade_ignoring_visibility: false,
            visibility: Visibility::Target,
        }
    }

    /// Decides the scene-dependent defaults from the scene summary: the continuations'
    /// next-event estimation takes the path tracer's rule ([`PathSettings::resolve_nee`]), an
    /// `auto` light sampler becomes [`AUTO_LIGHT_SAMPLER`] where the scene has a local emitter
    /// (else the power table), `auto` learning is on up to [`LEARN_MAX_EMITTERS`] emitters (else
    /// off), receivers without a glossy lobe take BSDF samples when the scene has an environment,
    /// and candidates that were not named become [`TILE_CANDIDATES`] where they come
    /// from the tiles' cuts (with learning or without). On a film that splats its filter
    /// (`film`), a radius that was not named becomes [`DIRECT_RADIUS`] plus the filter's reach:
    /// chosen on the DI training family's halls and Sponza with lamps under Mitsuba's Gaussian
    /// (reach 2), where 3 pixels are 1.11× 2 and 4 are 1.03× 3 at the median
    /// (`docs/RESTIR_DI.md`). On a film of `pixels` ≥ [`LARGE_FILM_PIXELS`] (the camera's whole
    /// film, so that the parts of a split render agree) neighbours that were not named become
    /// [`LARGE_FILM_NEIGHBORS`].
    pub fn resolve(&mut self, features: &SceneFeatures, film: &Reconstruction, pixels: u64) {
        self.path.resolve_nee(features);
        if !self.neighbors_named && pixels >= LARGE_FILM_PIXELS {
            self.reuse.neighbors = LARGE_FILM_NEIGHBORS;
            self.neighbors_raised = true;
        }
        if !self.radius_named
            && let Reconstruction::Splatted { reach, .. } = *film
            && reach > 0
        {
            // A splatting film already blends each pixel with those within its reach, so the
            // reuse reaches past it.
            self.reuse.radius = DIRECT_RADIUS + reach as f32;
            self.radius_widened_by = Some(reach);
        }
        if self.learn == Learn::Auto {
            self.learn_decided_from = Some(features.emitter_count);
            self.learn = if features.emitter_count <= LEARN_MAX_EMITTERS {
                Learn::On
            } else {
                Learn::Off
            };
        }
        if self.bsdf_diffuse == BsdfDiffuse::Auto {
            self.bsdf_diffuse_decided = true;
            self.bsdf_diffuse = if features.has_environment {
                BsdfDiffuse::On
            } else {
                BsdfDiffuse::Off
            };
        }
        if self.bsdf_samples == BsdfSamples::Auto {
            let beside = features.environment_share.is_some();
            self.bsdf_samples_decided_from = Some(beside);
            self.bsdf_samples =
                if self.visibility == Visibility::Target && self.path.max_segments() <= 2 && beside
                {
                    BsdfSamples::Resampled
                } else {
                    BsdfSamples::Separate
                };
        }
        if self.light_sampler == LightSampler::Auto {
            self.light_sampler = if features.emitter_count > 0 {
                AUTO_LIGHT_SAMPLER
            } else {
                LightSampler::Power
            };
        }
        if !self.candidates_named && self.light_sampler == LightSampler::Tiles {
            self.candidates = TILE_CANDIDATES;
            self.candidates_decided = true;
        }
    }

    /// `neighbors=N`, with why when [`RestirDiSettings::resolve`] raised it, for the settings
    /// line.
    pub fn neighbors_label(&self) -> String {
        large_film_label("neighbors", self.reuse.neighbors, self.neighbors_raised)
    }

    /// `radius=R`, with why when [`RestirDiSettings::resolve`] widened it, for the settings
    /// line.
    pub fn radius_label(&self) -> String {
        match self.radius_widened_by {
            Some(reach) => format!(
                "radius={} (auto: {DIRECT_RADIUS} + a splatting film's reach of {reach})",
                self.reuse.radius
            ),
            None => format!("radius={}", self.reuse.radius),
        }
    }

    /// `candidates=N`, with why when [`RestirDiSettings::resolve`] raised it, for the settings
    /// line.
    pub fn candidates_label(&self) -> String {
        let why = if self.candidates_decided {
            " (auto: the tiles' cuts)"
        } else {
            ""
        };
        format!("candidates={}{why}", self.candidates)
    }

    /// Why learning is on or off when `auto` decided it (`auto: N emitters <= 50000`), for the
    /// settings line (ASCII: it is written into image attributes); `None` when it was asked for.
    pub fn learn_reason(&self) -> Option<String> {
        self.learn_decided_from.map(|n| {
            let cmp = if n <= LEARN_MAX_EMITTERS { "<=" } else { ">" };
            format!("auto: {n} emitters {cmp} {LEARN_MAX_EMITTERS}")
        })
    }

    /// `bsdf_diffuse=on|off`, with why when `auto` decided it (`(auto: environment)`), for the
    /// settings line.
    pub fn bsdf_diffuse_label(&self) -> String {
        let why = match (self.bsdf_diffuse_decided, self.bsdf_diffuse) {
            (false, _) => "",
            (true, BsdfDiffuse::On) => " (auto: environment)",
            (true, _) => " (auto: no environment)",
        };
        format!("bsdf_diffuse={}{why}", self.bsdf_diffuse.name())
    }

    /// `bsdf_samples=separate|resampled`, with why when `auto` decided it, for the settings
    /// line.
    pub fn bsdf_samples_label(&self) -> String {
        let why = match self.bsdf_samples_decided_from {
            None => String::new(),
            Some(true) if self.visibility != Visibility::Target => {
                " (auto: visibility not in every target)".to_string()
            }
            Some(true) if self.path.max_segments() > 2 => " (auto: indirect light)".to_string(),
            Some(false) => " (auto: no environment beside local lights)".to_string(),
            Some(true) => " (auto: an environment beside local lights)".to_string(),
        };
        format!("bsdf_samples={}{why}", self.bsdf_samples.name())
    }

    /// Whether the estimator is unbiased with these settings.
    pub fn is_unbiased(&self) -> bool {
        self.reuse.is_unbiased()
            && self.visibility != Visibility::ReuseBiased
            && self.light_sampler != LightSampler::BvhWithPowerPmf
            && self.light_sampler != LightSampler::PoolWithoutSelection
            && self.learn != Learn::WithoutDefensiveShare
            && self.bsdf_diffuse != BsdfDiffuse::OffKeepingShare
            && self.bsdf_samples != BsdfSamples::ResampledWithoutShare
            && (!self.edge_mask_from_pass || self.edge_rays <= 1)
    }

    /// Applies `params` in order (later ones win). Names are case-insensitive, `-` and `_` are
    /// the same. Returns the parameters it did not know, for the caller to warn about.
    pub fn apply(&mut self, params: &ParamSet) -> Result<Vec<Param>, ParamError> {
        let mut resampled_by = None;
        let unused = params.apply(|key, p| {
            Ok(match key {
                "candidates" | "light_candidates" | "initial_candidates" | "num_candidates"
                | "reservoir_size" | "reservior_size" => {
                    self.candidates = p.count(1)?;
                    self.candidates_named = true;
                    true
                }
                "light_sampler" => {
                    self.light_sampler =
                        p.choice(LightSampler::NAMES, "auto, power, tiles or bvh")?;
                    true
                }
                "learn" => {
                    self.learn = p.choice(Learn::NAMES, "auto, off or on")?;
                    true
                }
                "learn_share" => {
                    let x = p.fraction()?;
                    if x >= 1.0 {
                        // All to the tables would drop every light no cell recorded.
                        return Err(p.error(crate::params::ParamProblem::NotBelowOne));
                    }
                    self.learn_share = x;
                    true
                }
                "learn_prior" => {
                    self.learn_prior = p.positive()?;
                    true
                }
                "learn_cells" => {
                    self.learn_cells = p.positive()?;
                    true
                }
                "learn_group" => {
                    self.learn_group = p.fraction()?;
                    true
                }
                "bsdf_candidates" | "brdf_candidates" => {
                    self.bsdf_candidates = p.count(0)?;
                    true
                }
                "edge_rays" | "silhouette_rays" => {
                    self.edge_rays = p.count(1)?;
                    true
                }
                "edge_mask_from_pass" => {
                    self.edge_mask_from_pass = p.boolean()?;
                    true
                }
                "bsdf_diffuse" => {
                    self.bsdf_diffuse = p.choice(BsdfDiffuse::NAMES, "auto, off or on")?;
                    true
                }
                "bsdf_samples" => {
                    self.bsdf_samples =
                        p.choice(BsdfSamples::NAMES, "auto, separate or resampled")?;
                    resampled_by = self.bsdf_samples.is_resampled().then(|| p.clone());
                    true
                }
                "visibility" => {
                    self.visibility = p.choice(Visibility::NAMES, "shading, target or reuse")?;
                    true
                }
                "visibility_reuse" => {
                    self.visibility = if p.boolean()? {
                        Visibility::ReuseBiased
                    } else {
                        Visibility::Shading
                    };
                    true
                }
                k if RADIUS_NAMES.contains(&k) => {
                    self.radius_named = true;
                    self.reuse.apply(key, p)?
                }
                k if NEIGHBOR_NAMES.contains(&k) => {
                    self.neighbors_named = true;
                    self.reuse.apply(key, p)?
                }
                _ => self.reuse.apply(key, p)?,
            })
        })?;
        // Resampled BSDF samples are unbiased only with visibility in every target: a neighbour's
        // BSDF candidates never land where its view of the light is blocked.
        if let Some(p) = resampled_by
            && self.visibility != Visibility::Target
        {
            return Err(p.error(ParamProblem::Needs {
                needs: "visibility = target".to_string(),
            }));
        }
        Ok(unused)
    }
}

#[cfg(test)]
mod tests {
    use restir_gris::MisScheme;

    use super::*;

    /// A film below [`LARGE_FILM_PIXELS`] (640×360).
    const SMALL: u64 = 640 * 360;

    /// `s` resolved for a scene of `emitters` emitters and nothing else, on a small sampled film.
    fn resolve_with_emitters(s: &mut RestirDiSettings, emitters: usize) {
        s.resolve(
            &SceneFeatures {
                emitter_count: emitters,
                ..SceneFeatures::default()
            },
            &Reconstruction::Sampled,
            SMALL,
        );
    }

    fn settings() -> RestirDiSettings {
        RestirDiSettings::new(PathSettings {
            max_depth: 2,
            rr_depth: 5,
            hide_emitters: false,
            sampler: restir_scene::SamplerKind::Independent,
            nee: restir_lights::NeeSelection::Power,
            nee_rule: crate::path::NeeRule::Named,
        })
    }

    #[test]
    fn lajolla_names_and_errors() {
        let mut s = settings();
        let p = |a: &str, b: &str| ParamSet::from(&[(a, b)][..]);
        let unknown = s
            .apply(&ParamSet::from(
                &[
                    ("neighbour_select", "5"),
                    ("spatial_iteration", "2"),
                    ("reservior_size", "16"),
                    ("m-capping", "8"),
                    ("mis", "one_over_z"),
                    ("nearClip", "1"),
                ][..],
            ))
            .unwrap();
        let names: Vec<&str> = unknown.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["nearClip"]);
        assert_eq!(
            (s.reuse.neighbors, s.reuse.spatial_rounds, s.candidates),
            (5, 2, 16)
        );
        assert_eq!((s.reuse.mcap, s.reuse.mis), (8.0, MisScheme::OneOverZ));
        assert!(s.apply(&p("candidates", "0")).is_err());
        assert!(s.apply(&p("radius", "NaN")).is_err());
        assert!(
            s.apply(&p("mis", "magic"))
                .unwrap_err()
                .to_string()
                .contains("defensive-pairwise")
        );
        assert!(s.apply(&p("temporal", "maybe")).is_err());
        assert_eq!(
            s.apply(&p("light_sampler", "near"))
                .unwrap_err()
                .to_string(),
            "light_sampler = 'near': expected auto, power, tiles or bvh"
        );
    }

    /// `bsdf_samples = auto` resamples for direct light with visibility in every target where an
    /// environment lights the scene beside local lights, whatever share of it the receivers see;
    /// `resampled` with another visibility is an error naming what it needs.
    #[test]
    fn auto_bsdf_samples_are_decided_by_an_environment_beside_local_lights() {
        let at = |visible: Option<f32>, max_depth: i32, visibility: Visibility| {
            let mut s = settings();
            s.path.max_depth = max_depth;
            s.visibility = visibility;
            s.resolve(
                &SceneFeatures {
                    environment_share: visible.map(|visible| restir_scene::EnvironmentShare {
                        power_share: 0.5,
                        share: 0.5,
                        receivers: 1000,
                        visible,
                    }),
                    ..SceneFeatures::default()
                },
                &Reconstruction::Sampled,
                SMALL,
            );
            (s.bsdf_samples, s.bsdf_samples_label())
        };
        for visible in [0.05, 0.7] {
            let (samples, label) = at(Some(visible), 2, Visibility::Target);
            assert_eq!(samples, BsdfSamples::Resampled, "{visible}");
            assert_eq!(
                label,
                "bsdf_samples=resampled (auto: an environment beside local lights)"
            );
        }
        let without = at(None, 2, Visibility::Target);
        assert_eq!(without.0, BsdfSamples::Separate);
        assert!(
            without.1.contains("no environment beside local lights"),
            "{}",
            without.1
        );
        let indirect = at(Some(0.05), -1, Visibility::Target);
        assert_eq!(indirect.0, BsdfSamples::Separate);
        assert!(indirect.1.contains("indirect light"), "{}", indirect.1);
        let shading = at(Some(0.05), 2, Visibility::Shading);
        assert_eq!(shading.0, BsdfSamples::Separate);
        assert!(
            shading.1.contains("visibility not in every target"),
            "{}",
            shading.1
        );
        let mut s = settings();
        let err = s
            .apply(&ParamSet::from(
                &[("bsdf_samples", "resampled"), ("visibility", "shading")][..],
            ))
            .unwrap_err()
            .to_string();
        assert_eq!(err, "bsdf_samples = 'resampled' needs visibility = target");
    }

    /// A radius that was not named is widened by a splatting film's reach, and the settings
    /// line says why; a sampled film and a named radius keep theirs.
    #[test]
    fn auto_radius_follows_a_splatting_film() {
        let gaussian = Reconstruction::decide(restir_scene::FilterDesc::Gaussian { stddev: 0.5 });
        assert_eq!(gaussian.reach(), 2);
        let at = |film: &Reconstruction, params: &[(&str, &str)]| {
            let mut s = settings();
            s.apply(&ParamSet::from(params)).unwrap();
            s.resolve(&SceneFeatures::default(), film, SMALL);
            (s.reuse.radius, s.radius_label())
        };
        assert_eq!(
            at(&gaussian, &[]),
            (
                DIRECT_RADIUS + 2.0,
                format!(
                    "radius={} (auto: {DIRECT_RADIUS} + a splatting film's reach of 2)",
                    DIRECT_RADIUS + 2.0
                )
            )
        );
        let plain = (DIRECT_RADIUS, format!("radius={DIRECT_RADIUS}"));
        assert_eq!(at(&Reconstruction::Sampled, &[]), plain);
        assert_eq!(
            at(&gaussian, &[("radius", "2")]),
            (2.0, "radius=2".to_string())
        );
        assert_eq!(
            at(&gaussian, &[("max_radius", "7")]),
            (7.0, "radius=7".to_string())
        );
    }

    /// Neighbours that were not named become `LARGE_FILM_NEIGHBORS` on a film of at least
    /// `LARGE_FILM_PIXELS` pixels, and the settings line says why; smaller films keep eight,
    /// named counts stay.
    #[test]
    fn auto_neighbors_follow_the_film_size() {
        let at = |pixels: u64, params: &[(&str, &str)]| {
            let mut s = settings();
            s.apply(&ParamSet::from(params)).unwrap();
            s.resolve(&SceneFeatures::default(), &Reconstruction::Sampled, pixels);
            (s.reuse.neighbors, s.neighbors_label())
        };
        assert_eq!(
            at(1280 * 720, &[]),
            (
                LARGE_FILM_NEIGHBORS,
                format!(
                    "neighbors={LARGE_FILM_NEIGHBORS} (auto: a film of at least 1280×720 pixels)"
                )
            )
        );
        assert_eq!(at(1800 * 1080, &[]).0, LARGE_FILM_NEIGHBORS);
        let eight = restir_reuse::settings::DIRECT_NEIGHBORS;
        assert_eq!(
            at(1280 * 720 - 1, &[]),
            (eight, format!("neighbors={eight}"))
        );
        assert_eq!(at(SMALL, &[]).0, eight);
        for name in ["neighbors", "spatial_neighbors", "num_neighbors"] {
            assert_eq!(
                at(1800 * 1080, &[(name, "8")]),
                (8, "neighbors=8".to_string()),
                "{name}"
            );
        }
    }

    /// Candidates that were not named become `TILE_CANDIDATES` where they come from the tiles'
    /// cuts, learning or not, and the settings line says why; named ones and the power sampler's
    /// keep their count.
    #[test]
    fn auto_candidates_follow_the_light_sampler() {
        let at = |emitters: usize, params: &[(&str, &str)]| {
            let mut s = settings();
            s.apply(&ParamSet::from(params)).unwrap();
            resolve_with_emitters(&mut s, emitters);
            (s.candidates, s.candidates_label())
        };
        let many = LEARN_MAX_EMITTERS + 1;
        let tiles = (
            TILE_CANDIDATES,
            format!("candidates={TILE_CANDIDATES} (auto: the tiles' cuts)"),
        );
        assert_eq!(at(many, &[]), tiles);
        assert_eq!(at(1000, &[]), tiles);
        assert_eq!(at(1000, &[("learn", "off")]), tiles);
        assert_eq!(at(many, &[("learn", "on")]), tiles);
        assert_eq!(at(0, &[]), (8, "candidates=8".to_string()));
        assert_eq!(at(many, &[("light_sampler", "power")]).0, 8);
        assert_eq!(
            at(many, &[("candidates", "8")]),
            (8, "candidates=8".to_string())
        );
        assert_eq!(at(many, &[("reservior_size", "32")]).0, 32);
    }

    /// `learn = auto` learns up to `LEARN_MAX_EMITTERS` emitters and not above; a named choice
    /// stays as named whatever the scene.
    #[test]
    fn auto_learning_is_decided_by_the_emitter_count() {
        let at = |emitters: usize, learn: Learn| {
            let mut s = settings();
            s.learn = learn;
            resolve_with_emitters(&mut s, emitters);
            s.learn
        };
        assert_eq!(settings().learn, Learn::Auto);
        assert_eq!(at(LEARN_MAX_EMITTERS, Learn::Auto), Learn::On);
        assert_eq!(at(LEARN_MAX_EMITTERS + 1, Learn::Auto), Learn::Off);
        assert_eq!(at(LEARN_MAX_EMITTERS + 1, Learn::On), Learn::On);
        assert_eq!(at(10, Learn::Off), Learn::Off);
        assert!(!Learn::Auto.is_on());
        // The settings line says what auto decided from.
        let mut s = settings();
        resolve_with_emitters(&mut s, 103_680);
        assert_eq!(s.learn_decided_from, Some(103_680));
        assert_eq!(
            s.learn_reason().as_deref(),
            Some("auto: 103680 emitters > 50000")
        );
    }
}
