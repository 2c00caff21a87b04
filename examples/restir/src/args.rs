//! The `render` command's arguments: the flags, the ReSTIR settings as typed parameters, and
//! `-D NAME=VALUE` scene variables.

use std::path::PathBuf;

use restir_integrators::{Param, ParamSet, ParamValue};

use crate::{cluster, frames};

#[derive(clap::Args, Debug)]
pub(crate) struct RenderArgs {
    /// Scene file.
    pub(crate) scene: PathBuf,
    /// Output image: .exr (linear float32 RGB) or .png (8-bit sRGB). Default: the film's
    /// filename from the scene, else <scene name>.exr.
    #[arg(short = 'o', long = "output")]
    pub(crate) output: Option<PathBuf>,
    /// Estimator: path, restir-di, restir-pt, or auto, which chooses one of them from the scene
    /// and says which and why (default: the scene's, else path).
    #[arg(long)]
    pub(crate) integrator: Option<String>,
    /// Passes (samples per pixel); overrides the scene.
    #[arg(long)]
    pub(crate) spp: Option<u32>,
    /// Render whole passes until this many seconds have passed (at least one pass).
    #[arg(long, value_name = "SECONDS")]
    pub(crate) time_limit: Option<f64>,
    /// Longest path in segments from the camera (1 = emitters only, 2 = direct light, -1 = no limit).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) max_depth: Option<i32>,
    /// Where the path tracer's numbers come from: `independent` (PCG32) or `sobol`
    /// (Owen-scrambled Sobol points, stratified over each pixel's passes); overrides the
    /// scene's sampler. ReSTIR DI and PT draw independent numbers.
    #[arg(long, value_parser = ["independent", "sobol"])]
    pub(crate) sampler: Option<String>,
    /// Random seed.
    #[arg(long, default_value_t = 0)]
    pub(crate) seed: u64,
    /// Worker threads, 1 to 256 (0 or absent: one per core).
    #[arg(long)]
    pub(crate) threads: Option<usize>,
    /// Refuse scenes and films whose estimated memory (images, meshes, light tables, the film
    /// and the estimator's per-pixel buffers) exceeds this many GiB, before allocating it
    /// [default: 8].
    #[arg(long, value_name = "GIB")]
    pub(crate) max_memory: Option<f64>,
    /// Image width; overrides the scene.
    #[arg(long)]
    pub(crate) width: Option<u32>,
    /// Image height; overrides the scene.
    #[arg(long)]
    pub(crate) height: Option<u32>,
    /// Set a scene <default> variable (XML scenes).
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    pub(crate) defines: Vec<String>,
    /// Write render statistics as JSON.
    #[arg(long, value_name = "FILE.json")]
    pub(crate) stats: Option<PathBuf>,
    /// No progress bar, no warnings, no summary.
    #[arg(long)]
    pub(crate) quiet: bool,
    #[command(flatten)]
    pub(crate) restir: RestirArgs,
    #[command(flatten)]
    pub(crate) cluster: cluster::ClusterArgs,
    #[command(flatten)]
    pub(crate) frames: frames::FrameArgs,
}

/// ReSTIR settings; each overrides the scene's `<integrator>` parameter of the same name.
#[derive(clap::Args, Debug)]
#[command(next_help_heading = "ReSTIR")]
pub(crate) struct RestirArgs {
    /// Initial candidates per pixel: light samples for restir-di [default: 12 from the tiles'
    /// cuts, 8 from the other sources], paths for restir-pt [default: 2].
    #[arg(long)]
    candidates: Option<u32>,
    /// restir-di: where candidates' lights come from: power (the power-based sampler), tiles
    /// (per 16×16-pixel tile, a cut of the light hierarchy for the tile's receivers), bvh (the
    /// light hierarchy: per receiver, a descent by power, distance and orientation) or auto
    /// (tiles where the scene has a local light, else power) [default: auto]. path and
    /// restir-pt: how next-event estimation picks its light, power, bvh or auto (bvh where
    /// the scene has two or more local lights of at most two emitters each on average, else
    /// power) [default: auto].
    #[arg(long)]
    light_sampler: Option<String>,
    /// restir-di: on draws candidates' lights, from the second pass on, from a mixture of the
    /// power sampler and what each light delivered (after its shadow ray) to a cell of a
    /// world-space grid in earlier passes; off uses the light sampler alone; auto is on up to
    /// 50000 emitters (emissive triangles and other lights) and off above [default: auto].
    #[arg(long)]
    learn: Option<String>,
    /// restir-di with --learn on: the share of candidate selections drawn from the learned
    /// tables, from 0 to below 1 (the rest from the power sampler) [default: 0.5].
    #[arg(long)]
    learn_share: Option<f32>,
    /// restir-di with --learn on: cells of the learning grid per scene diameter, along each
    /// axis [default: 16].
    #[arg(long)]
    learn_cells: Option<f32>,
    /// restir-di with --learn on: a cell with this many records draws half of --learn-share
    /// from its table (n records: learn_share·n/(n + learn_prior)) [default: 64].
    #[arg(long)]
    learn_prior: Option<f32>,
    /// restir-di with --learn on: consecutive triangles of one mesh light that fit in a box whose
    /// diagonal is this fraction of a learning cell's side, 0 to 1, are also learned as one
    /// (0: each triangle alone) [default: 1].
    #[arg(long)]
    learn_group: Option<f32>,
    /// Removed: a named integrator runs as named, and --integrator auto makes the never-worse
    /// choice. Kept hidden so that old command lines get an error saying so.
    #[arg(long, hide = true)]
    fallback: Option<String>,
    /// BSDF samples per pixel, MIS-combined with the reservoirs [default: 1].
    #[arg(long)]
    bsdf_candidates: Option<u32>,
    /// restir-di and restir-pt: camera rays for the emission seen on pixels that an emitter's
    /// silhouette crosses (1: no more rays): with a sampled filter the pixel's own ray and the
    /// rest; with a splatted one (the Gaussian) that many rays in place of the pixel's own,
    /// divided by the filter's variance factor for restir-pt; restir-di raises the count where
    /// silhouettes are a small part of the film, up to 4 times [default: 4 for restir-di, 32
    /// for restir-pt].
    #[arg(long)]
    edge_rays: Option<u32>,
    /// restir-di: whether receivers without a glossy lobe take the BSDF samples too (off: light
    /// sampling takes their whole direct light); auto is on when the scene has an environment
    /// [default: auto].
    #[arg(long)]
    bsdf_diffuse: Option<String>,
    /// restir-di: where BSDF samples go: candidates of initial resampling beside the light
    /// candidates, spread by reuse (resampled; needs --visibility target), or traced at shading
    /// beside the reservoirs (separate); auto resamples for direct light where an environment
    /// lights the scene beside local lights [default: auto].
    #[arg(long)]
    bsdf_samples: Option<String>,
    /// Spatial neighbours per round, in reciprocal pairs (an odd count is raised to the next
    /// even one) [default: 8 for restir-di, 12 on a film of at least 1280×720 pixels; 4 for
    /// restir-pt].
    #[arg(long, alias = "neighbours")]
    neighbors: Option<u32>,
    /// Spatial reuse radius in pixels [default: 2 for restir-di, widened by the filter's reach on
    /// a film that splats it (4 with Mitsuba's Gaussian); 3 for restir-pt, 5 on a film of at
    /// least 1280×720 pixels].
    #[arg(long)]
    radius: Option<f32>,
    /// Spatial reuse rounds [default: 1 for restir-di, 3 for restir-pt].
    #[arg(long)]
    spatial_rounds: Option<u32>,
    /// Reuse MIS: defensive-pairwise, pairwise, confidence-pairwise, balance, power,
    /// contribution, one-over-z, or uniform (biased) [default: defensive-pairwise].
    #[arg(long)]
    mis: Option<String>,
    /// Temporal reuse's MIS between the pixel and its previous pixel: one of the --mis names
    /// [default: power, or the --mis scheme when it is biased].
    #[arg(long)]
    temporal_mis: Option<String>,
    /// Confidence cap after every reuse step [default: 20].
    #[arg(long)]
    mcap: Option<f32>,
    /// Reuse the previous pass's reservoirs (and across the frames of a sequence, the
    /// previous frame's): `--temporal` or `--temporal true`; `--temporal false` turns off what a
    /// scene file turned on.
    #[arg(long, value_name = "BOOL", num_args = 0..=1, default_missing_value = "true")]
    temporal: Option<bool>,
    /// With --temporal: cap the history's confidence lower where neighbouring pixels hold the
    /// same sample, strength 0 (off) to 1 (biased) [default: 0].
    #[arg(long, value_name = "S")]
    duplication: Option<f32>,
    /// restir-di: where light samples' visibility is tested: shading (once, for the selected
    /// sample), target (in every target, a shadow ray per shift; unbiased) or reuse (the
    /// initial selection only; biased) [default: target].
    #[arg(long)]
    visibility: Option<String>,
    /// restir-di: the same as --visibility reuse (biased at shadow edges).
    #[arg(long)]
    visibility_reuse: bool,
    /// restir-di and restir-pt: what shading takes from the last spatial round: expected (every
    /// input with its resampling weight, the selection's expectation: the same mean, less
    /// noise; restir-di with --visibility target) or selected (the selected sample alone)
    /// [default: expected].
    #[arg(long)]
    shade: Option<String>,
    /// Spatial neighbours in reciprocal pairs that share their shifts (pairwise MIS):
    /// true or false [default: true].
    #[arg(long)]
    reciprocal: Option<bool>,
    /// restir-pt shift map: reconnection, replay or hybrid [default: hybrid; reconnection in
    /// scenes without delta or near-specular materials].
    #[arg(long)]
    shift: Option<String>,
    /// restir-pt: reject shifts with max(J, 1/J) above this (unbiased) [default: none].
    #[arg(long)]
    max_jacobian: Option<f32>,
    /// restir-pt: the rule for a path's reconnection vertex: fixed (roughness and distance
    /// thresholds) or footprint (the lobe's footprint against the pixel's ray cone)
    /// [default: fixed].
    #[arg(long)]
    reconnection: Option<String>,
    /// restir-pt: the footprint rule's threshold T (lobe footprint over squared cone width)
    /// [default: 30].
    #[arg(long)]
    footprint: Option<f32>,
    /// restir-pt: direct light in the reservoirs (reservoir), path traced per pixel (path) or
    /// from a ReSTIR DI pass (restir-di)
    /// [default: reservoir].
    #[arg(long)]
    direct: Option<String>,
}

impl RestirArgs {
    /// The flags given, as typed parameters (the integrator checks their ranges).
    pub(crate) fn params(&self) -> ParamSet {
        let mut p = ParamSet::new();
        let mut put = |k: &str, v: Option<ParamValue>| {
            if let Some(v) = v {
                p.push(Param::flag(k, v));
            }
        };
        put("candidates", self.candidates.map(ParamValue::Count));
        put(
            "light_sampler",
            self.light_sampler.clone().map(ParamValue::Text),
        );
        put("learn", self.learn.clone().map(ParamValue::Text));
        put("learn_share", self.learn_share.map(ParamValue::Number));
        put("learn_cells", self.learn_cells.map(ParamValue::Number));
        put("learn_prior", self.learn_prior.map(ParamValue::Number));
        put("learn_group", self.learn_group.map(ParamValue::Number));
        put("fallback", self.fallback.clone().map(ParamValue::Text));
        put(
            "bsdf_candidates",
            self.bsdf_candidates.map(ParamValue::Count),
        );
        put(
            "bsdf_diffuse",
            self.bsdf_diffuse.clone().map(ParamValue::Text),
        );
        put(
            "bsdf_samples",
            self.bsdf_samples.clone().map(ParamValue::Text),
        );
        put("edge_rays", self.edge_rays.map(ParamValue::Count));
        put("neighbors", self.neighbors.map(ParamValue::Count));
        put("radius", self.radius.map(ParamValue::Number));
        put("spatial_rounds", self.spatial_rounds.map(ParamValue::Count));
        put("mis", self.mis.clone().map(ParamValue::Text));
        put(
            "temporal_mis",
            self.temporal_mis.clone().map(ParamValue::Text),
        );
        put("mcap", self.mcap.map(ParamValue::Number));
        put("duplication", self.duplication.map(ParamValue::Number));
        put("temporal", self.temporal.map(ParamValue::Bool));
        put("reciprocal", self.reciprocal.map(ParamValue::Bool));
        put("visibility", self.visibility.clone().map(ParamValue::Text));
        put(
            "visibility_reuse",
            self.visibility_reuse.then_some(ParamValue::Bool(true)),
        );
        put("shade", self.shade.clone().map(ParamValue::Text));
        put("shift", self.shift.clone().map(ParamValue::Text));
        put("max_jacobian", self.max_jacobian.map(ParamValue::Number));
        put(
            "reconnection",
            self.reconnection.clone().map(ParamValue::Text),
        );
        put("footprint", self.footprint.map(ParamValue::Number));
        put("direct", self.direct.clone().map(ParamValue::Text));
        p
    }
}

/// `-D NAME=VALUE` flags as (name, value) pairs for the XML loader's `<default>` variables.
pub(crate) fn parse_defines(flags: &[String]) -> Result<Vec<(String, String)>, String> {
    flags
        .iter()
        .map(|d| {
            let (k, v) = d
                .split_once('=')
                .filter(|(k, _)| !k.trim().is_empty())
                .ok_or_else(|| format!("-D {d}: expected NAME=VALUE"))?;
            Ok((k.trim().to_string(), v.trim().to_string()))
        })
        .collect()
}
