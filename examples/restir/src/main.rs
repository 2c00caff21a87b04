//! `restir`: the command-line front end. Parsing arguments, a progress bar and writing files;
//! everything else lives in the library crates.

// The argument structs' doc comments are clap's `--help` text, where `<scene>` is a placeholder
// for the user, not an HTML tag.
#![allow(rustdoc::invalid_html_tags)]

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use clap::{Parser, Subcommand};
use restir_geometry::Shape;
use restir_image::Image;
use restir_integrators::{
    EstimatorReport, IntegratorOptions, Param, ParamSet, ParamValue, RenderJob, make_integrator,
};
use restir_scene::{LoadOptions, load_scene};

mod bench;
mod cluster;
mod convert;
mod frames;
mod generate;
mod interrupt;
mod merge;
mod preview;
mod progress;
mod say;
mod strict;

use say::{say, say_err};

#[derive(Parser, Debug)]
#[command(
    name = "restir",
    version,
    about = "Path tracing, ReSTIR DI and ReSTIR PT on the CPU"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene (.xml in Mitsuba format, or .ron) to an image.
    Render(Box<RenderArgs>),
    /// Compare a rendered EXR with a reference EXR: relMSE, MSE, mean ratio, non-finite pixels,
    /// MAPE and FLIP.
    Compare {
        /// The image to judge.
        test: PathBuf,
        /// The reference.
        reference: PathBuf,
        /// Also write an interactive comparison page (split view, zoom, pixel values, exposure,
        /// error maps): one self-contained HTML file.
        #[arg(long, value_name = "OUT.html")]
        html: Option<PathBuf>,
    },
    /// Write a procedurally generated scene (RON).
    #[command(subcommand)]
    Generate(generate::Generate),
    /// Write a scene (.ron or .xml) as Mitsuba 3 XML, which Mitsuba 3 and restir read to the
    /// same scene.
    ///
    /// The film size, sample count and max depth become <default> variables resx, resy, spp and
    /// max_depth (restir render -D resx=128; in Mitsuba, mi.load_file(path, resx=128)). What
    /// Mitsuba 3 cannot express is an error naming it: an animation, a ReSTIR integrator or its
    /// parameters, an inline triangle mesh. See docs/SCENES.md, "Writing Mitsuba 3 XML".
    Convert(convert::ConvertArgs),
    /// Equal-time evaluation: render a suite of scenes × integrators × time budgets × seeds,
    /// compare with references, write a CSV, relMSE-versus-time plots, crops and a report.
    Bench(Box<bench::BenchArgs>),
    /// Merge the parts of a split render (--chain/--crop) into one image (docs/CLUSTER.md).
    Merge(merge::MergeArgs),
}

#[derive(clap::Args, Debug)]
struct RenderArgs {
    /// Scene file.
    scene: PathBuf,
    /// Output image: .exr (linear float32 RGB) or .png (8-bit sRGB). Default: the film's
    /// filename from the scene, else <scene name>.exr.
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Estimator: path, restir-di, restir-pt, or auto, which chooses one of them from the scene
    /// and says which and why (default: the scene's, else path).
    #[arg(long)]
    integrator: Option<String>,
    /// Passes (samples per pixel); overrides the scene.
    #[arg(long)]
    spp: Option<u32>,
    /// Render whole passes until this many seconds have passed (at least one pass).
    #[arg(long, value_name = "SECONDS")]
    time_limit: Option<f64>,
    /// Longest path in segments from the camera (1 = emitters only, 2 = direct light, -1 = no limit).
    #[arg(long, allow_negative_numbers = true)]
    max_depth: Option<i32>,
    /// Random seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Worker threads, 1 to 256 (0 or absent: one per core).
    #[arg(long)]
    threads: Option<usize>,
    /// Refuse films whose estimated memory (film, images and the estimator's per-pixel
    /// buffers) exceeds this many GiB, before allocating anything [default: 8].
    #[arg(long, value_name = "GIB")]
    max_memory: Option<f64>,
    /// Image width; overrides the scene.
    #[arg(long)]
    width: Option<u32>,
    /// Image height; overrides the scene.
    #[arg(long)]
    height: Option<u32>,
    /// Set a scene <default> variable (XML scenes).
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    defines: Vec<String>,
    /// Write render statistics as JSON.
    #[arg(long, value_name = "FILE.json")]
    stats: Option<PathBuf>,
    /// No progress bar, no warnings, no summary.
    #[arg(long)]
    quiet: bool,
    #[command(flatten)]
    restir: RestirArgs,
    #[command(flatten)]
    cluster: cluster::ClusterArgs,
    #[command(flatten)]
    frames: frames::FrameArgs,
}

/// ReSTIR settings; each overrides the scene's `<integrator>` parameter of the same name.
#[derive(clap::Args, Debug)]
#[command(next_help_heading = "ReSTIR")]
struct RestirArgs {
    /// Initial candidates per pixel: light samples for restir-di [default: 8], paths for
    /// restir-pt [default: 2].
    #[arg(long)]
    candidates: Option<u32>,
    /// Where candidates' lights come from: power (the power-based sampler), tiles (per
    /// 16×16-pixel tile, mixed with a distance-aware table), bvh (the light hierarchy: per
    /// receiver, by power, distance and orientation) or auto (decided from the scene; power at
    /// every light count measured so far) [default: auto].
    #[arg(long)]
    light_sampler: Option<String>,
    /// restir-di: on draws candidates' lights, from the second pass on, from a mixture of the
    /// power sampler and what each light delivered (after its shadow ray) to a cell of a
    /// world-space grid in earlier passes; off uses the light sampler alone [default: off].
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
    /// Removed: a named integrator runs as named, and --integrator auto makes the never-worse
    /// choice. Kept hidden so that old command lines get an error saying so.
    #[arg(long, hide = true)]
    fallback: Option<String>,
    /// BSDF samples per pixel, MIS-combined with the reservoirs [default: 1].
    #[arg(long)]
    bsdf_candidates: Option<u32>,
    /// Spatial neighbours per round [default: 4].
    #[arg(long, alias = "neighbours")]
    neighbors: Option<u32>,
    /// Spatial reuse radius in pixels [default: 3].
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
    fn params(&self) -> ParamSet {
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
        put("fallback", self.fallback.clone().map(ParamValue::Text));
        put(
            "bsdf_candidates",
            self.bsdf_candidates.map(ParamValue::Count),
        );
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

#[derive(serde::Serialize)]
struct Stats<'a> {
    scene: String,
    /// The estimator that rendered (for `auto`, the one it chose).
    integrator: &'a str,
    integrator_settings: String,
    /// What was asked for, what ran and why.
    estimator: EstimatorStats,
    buffer_bytes_per_pixel: usize,
    /// Triangles and analytic spheres in the scene.
    triangles: usize,
    spheres: usize,
    lights: usize,
    seconds: f64,
    load_seconds: f64,
    spp: u32,
    width: u32,
    height: u32,
    rays: u64,
    mrays_per_second: f64,
    nonfinite_pixels: usize,
    seed: u64,
    threads: usize,
    /// How light samples are drawn, as the scene build decided it.
    light_selection: String,
    /// Wall seconds per stage of the estimator's passes, summed over the passes (empty for
    /// the path tracer).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    stage_seconds: Vec<StageSeconds>,
    /// The part of a split render this process rendered (--chain, --crop).
    #[serde(skip_serializing_if = "Option::is_none")]
    part: Option<cluster::PartStats>,
}

/// What `--stats` says of the estimator: what was asked for (a name or `auto`), what ran and
/// why.
#[derive(serde::Serialize, Debug)]
pub(crate) struct EstimatorStats {
    pub(crate) asked: String,
    pub(crate) ran: String,
    pub(crate) why: String,
}

impl From<&EstimatorReport> for EstimatorStats {
    fn from(r: &EstimatorReport) -> Self {
        Self {
            asked: r.asked.clone(),
            ran: r.ran.clone(),
            why: r.why.clone(),
        }
    }
}

/// One stage's summed wall time in `--stats`.
#[derive(serde::Serialize, Debug)]
pub(crate) struct StageSeconds {
    pub(crate) stage: &'static str,
    pub(crate) seconds: f64,
}

/// How a render ended: completely, or stopped by an interrupt (the partial image written).
enum Rendered {
    Complete,
    Interrupted,
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

fn run_render(args: RenderArgs) -> Result<Rendered, String> {
    let load_start = Instant::now();
    let defines = parse_defines(&args.defines)?;
    let options = LoadOptions {
        defines,
        width: args.width,
        height: args.height,
        // The command line has never warned about unlit scenes.
        warn_no_lights: false,
        max_memory: Some((strict::max_memory(args.max_memory)? * (1u64 << 30) as f64) as u64),
    };
    let spinner = progress::load_spinner(&args.scene, args.quiet);
    let loaded = load_scene(&args.scene, &options);
    if let Some(s) = spinner {
        s.finish_and_clear();
    }
    let mut loaded = loaded.map_err(|e| e.to_string())?;
    args.frames.check_needs_frames()?;
    if let Some(a) = &args.frames.animation {
        restir_scene::animation::load_animation(&mut loaded.desc, a).map_err(|e| e.to_string())?;
    }
    let split = args.cluster.chain.is_some() || args.cluster.crop.is_some();
    let frame_plan = args.frames.plan(&args.scene, &loaded.desc, split)?;
    if !args.quiet {
        for w in &loaded.warnings {
            say_err!("{w}");
        }
    }
    let scene = loaded.scene;
    // The scene's sample count and file name are the job's defaults.
    let mut job = RenderJob::from_desc(&loaded.desc);
    job.seed = args.seed;
    let load_seconds = load_start.elapsed().as_secs_f64();

    let options = IntegratorOptions {
        name: args.integrator.clone(),
        max_depth: args.max_depth,
        params: args.restir.params(),
    };
    let made = make_integrator(&scene, &options).map_err(|e| e.to_string())?;
    strict::check_flags_used(&scene, &made)?;
    if !args.quiet {
        for note in &made.notes {
            say_err!("{note}");
        }
        for p in &made.unused_params {
            say_err!(
                "warning: integrator '{}' does not use the parameter '{}'",
                made.integrator.name(),
                p.name
            );
        }
    }
    let integrator = made.integrator;
    let spp = args.spp.unwrap_or(job.spp);
    if spp == 0 {
        return Err("--spp must be at least 1".into());
    }
    let time_limit = match args.time_limit {
        Some(t) if t.is_finite() && t > 0.0 => Some(
            Duration::try_from_secs_f64(t).map_err(|_| format!("--time-limit {t:e}: too large"))?,
        ),
        Some(t) => {
            return Err(format!(
                "--time-limit {t}: expected a positive number of seconds"
            ));
        }
        None => None,
    };
    // With only a time limit, keep rendering until it runs out.
    job.spp = if args.time_limit.is_some() && args.spp.is_none() {
        u32::MAX
    } else {
        spp
    };
    job.time_limit = time_limit;
    let spp = job.spp;
    let output = match args.output.clone().or(job.output.take()) {
        Some(o) => o,
        None => PathBuf::from(format!(
            "{}.exr",
            args.scene
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("render")
        )),
    };
    job.output = Some(output.clone());
    let plan = args.cluster.plan(
        spp,
        time_limit.is_some(),
        &output,
        scene.camera.resolution(),
    )?;
    if let Some(plan) = &plan {
        job.spp = plan.passes.len() as u32;
    }
    let spp = job.spp;
    match output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("exr") | Some("png") => {}
        _ => {
            return Err(format!(
                "{}: output must end in .exr or .png",
                output.display()
            ));
        }
    }
    let (width, height) = scene.camera.resolution();
    strict::check_memory(
        width,
        height,
        integrator.as_ref(),
        strict::max_memory(args.max_memory)?,
    )?;

    // Fail before rendering, not after, when the output cannot be written.
    let output = match &frame_plan {
        Some(f) => frames::frame_path(&output, f.first),
        None => output,
    };
    if let Some((p, _)) = frame_plan.as_ref().and_then(|f| f.preview.as_ref()) {
        if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .map_err(|e| format!("{}: cannot create output directory: {e}", dir.display()))?;
        }
        restir_image::check_writable(p).map_err(|e| e.to_string())?;
    }
    if let Some(dir) = output.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create output directory: {e}", dir.display()))?;
    }
    if output.is_dir() {
        return Err(format!("{}: is a directory", output.display()));
    }
    Image::check_output(&output).map_err(|e| e.to_string())?;
    if let Some(stats) = &args.stats {
        if restir_image::same_destination(stats, &output) {
            return Err(format!(
                "--stats {}: the same file as the output image",
                stats.display()
            ));
        }
        restir_image::check_writable(stats).map_err(|e| e.to_string())?;
    }

    let pool = strict::thread_pool(args.threads)?;
    let threads = pool.current_num_threads();

    // Ctrl-C finishes the current pass and still writes the image; a second one aborts.
    let cancel = interrupt::install(output.clone(), args.quiet);

    if let Some(plan) = &frame_plan {
        let stopped = pool.install(|| {
            frames::run(
                &args.scene,
                &loaded.desc,
                &options,
                &job,
                plan,
                &cancel,
                args.quiet,
                args.stats.as_deref(),
            )
        })?;
        return Ok(if stopped {
            Rendered::Interrupted
        } else {
            Rendered::Complete
        });
    }

    let show_bar = !args.quiet && std::io::stderr().is_terminal();
    let bar = if show_bar {
        let bar = match time_limit {
            Some(t) if spp == u32::MAX => {
                let b = indicatif::ProgressBar::new(t.as_millis() as u64);
                b.set_style(
                    indicatif::ProgressStyle::with_template(
                        "{bar:40} {elapsed_precise} / time limit, {msg}",
                    )
                    .expect("valid template"),
                );
                b
            }
            _ => {
                let b = indicatif::ProgressBar::new(spp as u64);
                b.set_style(
                    indicatif::ProgressStyle::with_template(
                        "{bar:40} {pos}/{len} passes, {elapsed_precise} elapsed, ETA {eta_precise}",
                    )
                    .expect("valid template"),
                );
                b
            }
        };
        Some(bar)
    } else {
        None
    };

    let out = pool.install(|| {
        cluster::render(
            &scene,
            integrator.as_ref(),
            &job,
            plan.as_ref(),
            &cancel,
            &mut |passes, elapsed| {
                if let Some(b) = &bar {
                    if spp == u32::MAX {
                        b.set_position(elapsed.as_millis() as u64);
                        b.set_message(format!("{passes} passes"));
                    } else {
                        b.set_position(passes as u64);
                    }
                }
            },
        )
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }

    // An interrupted part holds only the passes it rendered, and says so.
    let plan = plan.map(|p| cluster::Plan {
        passes: p.passes.start..p.passes.start + out.passes,
        ..p
    });
    match &plan {
        Some(p) => p.write(
            &out.image,
            &output,
            &args.scene,
            &loaded.desc,
            integrator.as_ref(),
            args.seed,
        )?,
        None => out.image.write(&output).map_err(|e| e.to_string())?,
    }

    let mrays = out.rays as f64 / out.seconds.max(1e-9) / 1e6;
    if let Some(path) = &args.stats {
        let stats = Stats {
            scene: args.scene.display().to_string(),
            integrator: integrator.name(),
            integrator_settings: integrator.describe(),
            estimator: (&out.estimator).into(),
            buffer_bytes_per_pixel: integrator.buffer_bytes_per_pixel(),
            triangles: scene
                .shapes
                .iter()
                .map(|s| match s {
                    Shape::Mesh(m) => m.triangle_count(),
                    Shape::Sphere(_) => 0,
                })
                .sum(),
            spheres: scene
                .shapes
                .iter()
                .filter(|s| matches!(s, Shape::Sphere(_)))
                .count(),
            lights: scene.lights.len(),
            seconds: out.seconds,
            load_seconds,
            spp: out.passes,
            width: out.image.width,
            height: out.image.height,
            rays: out.rays,
            mrays_per_second: mrays,
            nonfinite_pixels: out.nonfinite_pixels,
            seed: args.seed,
            threads,
            light_selection: scene.light_selection(),
            stage_seconds: integrator
                .stage_seconds()
                .into_iter()
                .map(|(stage, seconds)| StageSeconds { stage, seconds })
                .collect(),
            part: plan.as_ref().map(|p| p.stats(integrator.as_ref())),
        };
        let json = serde_json::to_string_pretty(&stats).map_err(|e| e.to_string())?;
        restir_image::write_file_atomically(path, (json + "\n").as_bytes())
            .map_err(|e| e.to_string())?;
    }
    let interrupted = cancel.load(Ordering::SeqCst);
    if interrupted {
        // Said even with --quiet: the exit code alone does not tell what was written.
        say_err!(
            "interrupted after {} passes: wrote what was rendered -> {}",
            out.passes,
            output.display()
        );
    }
    if !args.quiet {
        let stopped = if interrupted { " (interrupted)" } else { "" };
        say!(
            "{} [{}]: {} passes in {:.2} s{stopped}, {:.1} Mrays/s, {} threads, loaded in {:.2} s -> {}",
            out.estimator.settings,
            out.estimator.why,
            out.passes,
            out.seconds,
            mrays,
            threads,
            load_seconds,
            output.display()
        );
        if out.nonfinite_pixels > 0 {
            say_err!(
                "warning: {} pixels are NaN or infinite",
                out.nonfinite_pixels
            );
        }
    }
    Ok(if interrupted {
        Rendered::Interrupted
    } else {
        Rendered::Complete
    })
}

fn run_compare(test: &Path, reference: &Path, html: Option<&Path>) -> Result<(), String> {
    if let Some(out) = html {
        if let Some(input) = [test, reference]
            .into_iter()
            .find(|i| restir_image::same_destination(out, i))
        {
            return Err(format!(
                "--html {}: the same file as the input {}",
                out.display(),
                input.display()
            ));
        }
        restir_image::check_writable(out).map_err(|e| e.to_string())?;
    }
    let t = Image::read_exr(test).map_err(|e| e.to_string())?;
    let r = Image::read_exr(reference).map_err(|e| e.to_string())?;
    let m = restir_evaluation::metrics::evaluate(&t, &r).ok_or_else(|| {
        format!(
            "{}: size {}×{} differs from the reference's {}×{}",
            test.display(),
            t.width,
            t.height,
            r.width,
            r.height
        )
    })?;
    if m.mse.is_nan() {
        return Err(format!(
            "{} against {}: no pixel is finite in both ({} NaN or infinite in the image, {} in the reference)",
            test.display(),
            reference.display(),
            m.nonfinite,
            m.reference_nonfinite
        ));
    }
    for (n, which) in [(m.nonfinite, test), (m.reference_nonfinite, reference)] {
        if n > 0 {
            say_err!(
                "warning: {}: {n} pixels are NaN or infinite (left out of every metric)",
                which.display()
            );
        }
    }
    if let Some(out) = html {
        let name = |p: &Path| {
            p.file_name()
                .map_or(p.display().to_string(), |n| n.to_string_lossy().into())
        };
        let page = restir_evaluation::html::compare_page(&name(test), &t, &name(reference), &r)
            .map_err(|e| e.to_string())?;
        restir_image::write_file_atomically(out, page.as_bytes()).map_err(|e| e.to_string())?;
    }
    say!(
        "relmse={:.6e} mse={:.6e} mean_ratio={:.6} nonfinite={} reference_nonfinite={} mape={:.6e} flip={:.6} top1_share={:.4}",
        m.relmse,
        m.mse,
        m.mean_ratio,
        m.nonfinite,
        m.reference_nonfinite,
        m.mape,
        m.flip,
        m.top1_share
    );
    Ok(())
}

/// A file-size limit (`ulimit -f`) is a write error naming the file, not a silent death by
/// SIGXFSZ: the signal is blocked here, before any thread starts (threads inherit the mask), so
/// the write that crosses the limit returns EFBIG, is reported, and the temporary file is
/// removed. Blocked rather than ignored because blocking is safe code (`sigprocmask`), and a
/// blocked SIGXFSZ has the same effect on `write`.
#[cfg(unix)]
fn report_file_size_limit() {
    use nix::sys::signal::{SigSet, Signal};
    let mut set = SigSet::empty();
    set.add(Signal::SIGXFSZ);
    let _ = set.thread_block();
}

fn main() -> ExitCode {
    #[cfg(unix)]
    report_file_size_limit();
    // Rough-plastic tables are kept between runs (`RESTIR_CACHE_DIR=` turns this off).
    restir_materials::table_cache::set_cache_dir(restir_materials::table_cache::default_cache_dir());
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                let _ = e.print();
                return if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                    ExitCode::FAILURE
                } else {
                    ExitCode::SUCCESS
                };
            }
            // clap's whole message: the error, its hints ("a similar argument exists") and the
            // usage line.
            let _ = e.print();
            return ExitCode::FAILURE;
        }
    };
    let result = match cli.command {
        Command::Render(args) => run_render(*args),
        Command::Compare {
            test,
            reference,
            html,
        } => run_compare(&test, &reference, html.as_deref()).map(|()| Rendered::Complete),
        Command::Generate(what) => generate::run(what).map(|()| Rendered::Complete),
        Command::Convert(args) => convert::run(args).map(|()| Rendered::Complete),
        Command::Bench(args) => bench::run(*args).map(|()| Rendered::Complete),
        Command::Merge(args) => merge::run(args).map(|()| Rendered::Complete),
    };
    match result {
        Ok(Rendered::Complete) => ExitCode::SUCCESS,
        Ok(Rendered::Interrupted) => ExitCode::from(interrupt::EXIT_INTERRUPTED),
        Err(e) => {
            say_err!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
