//! Equal-time evaluation of the restir estimators (`restir bench`).
//!
//! A [`Suite`] lists scenes, integrator configurations, time budgets and seeds. [`run_suite`]
//! renders every combination with the library [`render`] (`spp: u32::MAX`, the budget as time
//! limit), compares each image with a reference and records time, passes, rays, errors and peak
//! memory. [`write_outputs`] then writes the CSV, one log-log relMSE-versus-time plot per scene
//! (SVG), one strip of crops per scene (PNG), a Markdown report and an interactive HTML page
//! ([`html`]); [`update_doc`] puts the report into a marked section of another Markdown file.
//! Besides relMSE every run records MAPE and FLIP ([`metrics`]).
//!
//! **Animation suites.** A suite scene with `frames` is a sequence: each configuration renders
//! its frames in order with one estimator (made for the first frame's scene and told of each
//! next frame's motion through [`FrameSequence`], so temporal reuse carries across frames),
//! every frame with the budget (equal time per frame), frame `n` of seed `s` with the seed
//! `FrameSequence::seed(s, n)` as `restir render --frames` does. Every frame has its own
//! cached reference. The records are per frame (relMSE against that frame's reference, and
//! flicker: the mean over pixels and channels of the squared change of the error from the
//! previous frame, `((I_f − R_f) − (I_{f−1} − R_{f−1}))² / (max(R_f, R_{f−1})² + 0.01)`, which
//! independent noise per frame puts near twice the relMSE and errors that persist across frames
//! below it); [`sequence_runs`] folds each sequence into one record (means over its frames),
//! which the summaries, the relMSE-versus-time plot and the report use like a still render's.
//! The report adds a per-frame relMSE plot per sequence, efficiency `1/(relMSE · CPU s per
//! frame)` and flicker relative to the suite's first configuration.
//!
//! **References.** A scene's `reference` EXR is used as given (its noise is unknown). Otherwise
//! the path tracer renders the scene at the suite's `reference_spp`, as two halves of
//! `reference_spp / 2` passes with two seeds that no benchmark run uses, and the average is the
//! reference. It is cached in `<out>/references/` under a key that hashes the scene file's bytes,
//! the resolution, the max-depth override and the pass count, so changing any of them renders a
//! new one (files the scene includes, such as meshes, are not hashed). The reference's own error
//! is estimated from the halves: if `a` and `b` are independent with per-pixel variance `v`, the
//! reference `(a + b)/2` has variance `v/2` while `E[(a − b)²] = 2v`, so
//! `relMSE(a, b) / 4` estimates the relMSE the reference itself carries. Since a test image is
//! independent of the reference, its measured relMSE is, in expectation, its true relMSE plus
//! this amount: errors within a few times the reference noise are not meaningful.
//!
//! **Peak memory.** Before each render the process's peak resident set (`VmHWM` in
//! `/proc/self/status`) is reset by writing `5` to `/proc/self/clear_refs` (Linux 4.0 and
//! later), then read before and after the render. `peak_rss_mib` is the peak resident memory of
//! the whole process during that render: the scene, its BVH, the reference and whatever the
//! allocator still holds from earlier runs are included; `peak_rss_mib − rss_before_mib`
//! approximates what the render itself added (accumulation buffer, reservoirs, primary hits).
//! Where the reset is not allowed, `VmHWM` is the peak since the process started and only grows
//! from run to run; the report says which case applied.
//!
//! **CPU time.** Besides its wall time every render records the CPU time the process spent
//! while it ran (the sum over its threads of their time on a CPU, from `/proc`; NaN where
//! `/proc` is missing): on a shared machine it is what a render costs, whatever else runs.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use restir_image::{Image, compare};

use crate::metrics::evaluate;
use restir_integrators::reuse::motion::FrameSequence;
use restir_integrators::{Integrator, IntegratorOptions, RenderJob, make_integrator, render};
use restir_scene::{LoadOptions, Scene, SceneDesc, load_scene};

mod error;
pub mod html;
pub mod metrics;
mod plot;
mod report;
pub mod suite;

pub use error::BenchError;
pub use report::{
    BEGIN_MARKER, END_MARKER, Summary, TimeToError, check_doc, sequence_runs, summarize,
    time_to_error, update_doc, write_outputs,
};
pub use suite::{IntegratorConfig, Suite, SuiteError, SuiteScene};

/// Seeds of the two reference halves; benchmark runs use seeds `0..seeds`.
pub const REFERENCE_SEEDS: [u64; 2] = [0x5eed_0000_0000_0001, 0x5eed_0000_0000_0002];

/// One render of the suite.
#[derive(Clone, Debug)]
pub struct RunRecord {
    /// Scene name.
    pub scene: String,
    /// Integrator configuration label.
    pub label: String,
    /// What the integrator reports about its settings (`Integrator::describe`).
    pub describe: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Time budget in seconds.
    pub budget: f64,
    /// Seed.
    pub seed: u64,
    /// Render time in seconds (whole passes: at least the budget, unless one pass is longer).
    pub seconds: f64,
    /// The process's user + system CPU seconds during the render (NaN where unknown).
    pub cpu_seconds: f64,
    /// Passes rendered.
    pub passes: u32,
    /// Rays traced.
    pub rays: u64,
    /// relMSE against the reference.
    pub relmse: f64,
    /// MSE against the reference.
    pub mse: f64,
    /// MAPE against the reference ([`metrics`]).
    pub mape: f64,
    /// Mean FLIP error of the tone-mapped image against the tone-mapped reference ([`metrics`]).
    pub flip: f64,
    /// Mean of the image over mean of the reference.
    pub mean_ratio: f64,
    /// Pixels with NaN or infinite values.
    pub nonfinite: usize,
    /// Resident memory just before the render, MiB (`VmHWM` right after the reset).
    pub rss_before_mib: f64,
    /// Peak resident memory during the render, MiB (see the crate documentation).
    pub peak_rss_mib: f64,
    /// The frame, for a frame of a sequence (`None`: a still render, or a whole sequence folded
    /// by [`sequence_runs`]).
    pub frame: Option<u32>,
    /// Flicker against the previous frame of the sequence (see the crate documentation; for a
    /// folded sequence the mean over its frames after the first); NaN for a still render and
    /// a sequence's first frame.
    pub flicker: f64,
}

impl RunRecord {
    /// Millions of rays per second.
    pub fn mrays_per_second(&self) -> f64 {
        self.rays as f64 / self.seconds.max(1e-9) / 1e6
    }
}

/// Where a scene's reference came from and how noisy it is. For a sequence: the last frame's
/// file, the mean of the frames' noise estimates, and the seconds of all of them.
#[derive(Clone, Debug)]
pub struct ReferenceInfo {
    /// Scene name.
    pub scene: String,
    /// The EXR file.
    pub path: PathBuf,
    /// Passes, for a path-traced reference.
    pub spp: Option<u32>,
    /// relMSE the reference itself carries (estimated from its halves), when known.
    pub noise_relmse: Option<f64>,
    /// Whether it came from the cache (or was given) rather than rendered by this run.
    pub reused: bool,
    /// Seconds spent rendering it in this run.
    pub seconds: f64,
}

/// A scene's strip of crops: the reference first, then each configuration in suite order (of a
/// sequence: its last frame).
#[derive(Clone, Debug)]
pub struct Strip {
    /// Scene name.
    pub scene: String,
    /// Crop rectangle `(x, y, width, height)`.
    pub crop: (u32, u32, u32, u32),
    /// Budget of the cropped renders.
    pub budget: f64,
    /// Reference crop, then one crop per configuration that rendered the scene.
    pub crops: Vec<Image>,
    /// `"reference"`, then the label of each configuration crop.
    pub labels: Vec<String>,
}

/// A scene's full images for the HTML report: the reference, then seed 0 of every configuration
/// at every budget (of a sequence: its last frame).
#[derive(Clone, Debug)]
pub struct SceneImages {
    /// Scene name.
    pub scene: String,
    /// The reference.
    pub reference: Image,
    /// `(configuration label, budget, image)` in suite order, budgets ascending.
    pub renders: Vec<(String, f64, Image)>,
}

/// The machine the suite ran on.
#[derive(Clone, Debug)]
pub struct Machine {
    /// `/proc/cpuinfo` model name.
    pub cpu: String,
    /// Logical cores.
    pub cores: usize,
    /// Worker threads of the render pool.
    pub threads: usize,
    /// `/proc/loadavg` at the start and end of the suite.
    pub load_start: String,
    /// See `load_start`.
    pub load_end: String,
    /// Whether peak memory could be reset before each render.
    pub peak_reset: bool,
}

/// Everything a suite run produced.
#[derive(Clone, Debug)]
pub struct BenchResults {
    /// The suite (with command-line overrides applied).
    pub suite: Suite,
    /// Every render.
    pub records: Vec<RunRecord>,
    /// One per scene.
    pub references: Vec<ReferenceInfo>,
    /// One per scene.
    pub strips: Vec<Strip>,
    /// One per scene (seed 0 only).
    pub images: Vec<SceneImages>,
    /// Where it ran.
    pub machine: Machine,
    /// The command that ran it.
    pub command_line: String,
    /// UTC start time (seconds since the Unix epoch).
    pub started_unix: u64,
    /// Wall-clock seconds of the whole suite.
    pub wall_seconds: f64,
}

/// What [`run_suite`] reports as it goes.
#[derive(Clone, Debug)]
pub struct Progress {
    /// Steps done (references and renders).
    pub done: u64,
    /// All steps.
    pub total: u64,
    /// What is being done next.
    pub message: String,
}

/// Options of [`run_suite`] beyond the suite itself.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Directory of the suite file: scene and reference paths are relative to it.
    pub suite_dir: PathBuf,
    /// Output directory (references are cached in its `references/`).
    pub out: PathBuf,
    /// The command line, for the report.
    pub command_line: String,
}

/// Stable 64-bit FNV-1a hash (for cache keys that must not change between Rust versions).
pub fn fnv1a(chunks: &[&[u8]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for chunk in chunks {
        for &b in *chunk {
            h ^= b as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        // Separate chunks so that ("ab", "c") and ("a", "bc") differ.
        h ^= 0xff;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// `VmHWM` of this process in KiB, if `/proc` has it.
fn vm_hwm_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Resets `VmHWM` to the current resident set; `false` where the kernel does not allow it.
fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// CPU seconds this process has run so far: the sum over its threads of the time each has
/// spent on a CPU (`/proc/self/task/*/schedstat`, nanoseconds; the render pool's threads live
/// as long as the run), else user + system time from `/proc/self/stat` (fields 14 and 15, in
/// the 1/100 s ticks Linux reports them in); NaN without either.
fn process_cpu_seconds() -> f64 {
    let schedstat = || -> Option<f64> {
        let mut ns = 0u64;
        for task in std::fs::read_dir("/proc/self/task").ok()? {
            let text = std::fs::read_to_string(task.ok()?.path().join("schedstat")).ok()?;
            ns += text.split_whitespace().next()?.parse::<u64>().ok()?;
        }
        Some(ns as f64 * 1e-9)
    };
    let stat = || -> Option<f64> {
        let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
        // The command name (field 2) may hold spaces; the fields after it start at 3 (state).
        let rest = &stat[stat.rfind(')')? + 1..];
        let f: Vec<&str> = rest.split_whitespace().collect();
        let ticks = f.get(11)?.parse::<u64>().ok()? + f.get(12)?.parse::<u64>().ok()?;
        Some(ticks as f64 / 100.0)
    };
    schedstat().or_else(stat).unwrap_or(f64::NAN)
}

fn mib(kib: Option<u64>) -> f64 {
    kib.map_or(f64::NAN, |k| k as f64 / 1024.0)
}

fn cpu_model() -> (String, usize) {
    let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let model = info
        .lines()
        .find(|l| l.starts_with("model name"))
        .and_then(|l| l.split_once(':'))
        .map(|(_, v)| v.trim().to_string())
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = info
        .lines()
        .filter(|l| l.starts_with("processor"))
        .count()
        .max(std::thread::available_parallelism().map_or(1, |n| n.get()));
    (model, cores)
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|| "unknown".into())
}

/// A scene loaded with the suite's overrides.
struct LoadedSuiteScene {
    name: String,
    /// The scene as written (a still entry), or its first frame (a sequence).
    scene: Arc<Scene>,
    file_bytes: Vec<u8>,
    /// The file and the description (with the overrides), for a sequence's frames.
    path: PathBuf,
    desc: SceneDesc,
    /// A sequence's frames `(frame, scene)`; empty for a still entry.
    frames: Vec<(u32, Arc<Scene>)>,
    /// A sequence's frame rate.
    fps: f32,
}

impl LoadedSuiteScene {
    /// What gets a reference: the scene (`None`), or each frame of a sequence.
    fn views(&self) -> Vec<(Option<u32>, Arc<Scene>)> {
        if self.frames.is_empty() {
            vec![(None, self.scene.clone())]
        } else {
            self.frames
                .iter()
                .map(|(f, s)| (Some(*f), s.clone()))
                .collect()
        }
    }

    fn sequence(&self) -> Option<FrameSequence<'_>> {
        FrameSequence::new(&self.desc, &self.path, self.fps)
    }
}

fn load_suite_scene(entry: &SuiteScene, suite_dir: &Path) -> Result<LoadedSuiteScene, BenchError> {
    let path = suite_dir.join(&entry.path);
    let file_bytes = std::fs::read(&path).map_err(BenchError::io(&path, "cannot read scene: "))?;
    let options = LoadOptions {
        width: entry.width,
        height: entry.height,
        ..LoadOptions::default()
    };
    let loaded = load_scene(&path, &options)?;
    let mut out = LoadedSuiteScene {
        name: entry.display_name(),
        scene: Arc::new(loaded.scene),
        file_bytes,
        path,
        fps: 0.0,
        desc: loaded.desc,
        frames: Vec::new(),
    };
    if let Some((first, last)) = entry.frames {
        let Some(anim) = &out.desc.animation else {
            return Err(BenchError::NoAnimation(out.path));
        };
        out.fps = entry.fps.unwrap_or(anim.fps);
        let sequence = out
            .sequence()
            .ok_or(BenchError::NoAnimation(out.path.clone()))?;
        let frames = (first..=last)
            .map(|f| Ok((f, Arc::new(sequence.build(f)?))))
            .collect::<Result<Vec<_>, BenchError>>()?;
        out.scene = frames[0].1.clone();
        out.frames = frames;
    }
    Ok(out)
}

fn options_for(config: &IntegratorConfig, entry: &SuiteScene) -> IntegratorOptions {
    IntegratorOptions {
        name: Some(config.integrator.clone()),
        max_depth: entry.max_depth,
        params: config.params.as_slice().into(),
    }
}

/// Builds a configuration's integrator for a scene; parameters it does not use are an error
/// (a typo would otherwise benchmark the defaults under the wrong label).
fn build_integrator(
    scene: &Scene,
    config: &IntegratorConfig,
    entry: &SuiteScene,
) -> Result<Box<dyn restir_integrators::Integrator>, BenchError> {
    let made = make_integrator(scene, &options_for(config, entry)).map_err(|e| {
        BenchError::Integrator {
            label: config.label.clone(),
            message: e.to_string(),
        }
    })?;
    if let Some(p) = made
        .unused_params
        .iter()
        .find(|p| config.params.iter().any(|(k, _)| *k == p.name))
    {
        let p = &p.name;
        return Err(BenchError::Integrator {
            label: config.label.clone(),
            message: format!("{} does not use the parameter '{p}'", config.integrator),
        });
    }
    Ok(made.integrator)
}

fn crop_rect(
    entry: &SuiteScene,
    width: u32,
    height: u32,
) -> Result<(u32, u32, u32, u32), BenchError> {
    match entry.crop {
        Some((x, y, w, h)) => {
            if x.checked_add(w).is_none_or(|r| r > width)
                || y.checked_add(h).is_none_or(|b| b > height)
            {
                Err(BenchError::Crop {
                    scene: entry.path.clone(),
                    rect: (x, y, w, h),
                    size: (width, height),
                })
            } else {
                Ok((x, y, w, h))
            }
        }
        None => {
            let (w, h) = ((width / 2).max(1), (height / 2).max(1));
            Ok(((width - w) / 2, (height - h) / 2, w, h))
        }
    }
}

fn crop(image: &Image, (x0, y0, w, h): (u32, u32, u32, u32)) -> Image {
    let mut out = Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            out.pixels[(y * w + x) as usize] = image.get(x0 + x, y0 + y);
        }
    }
    out
}

fn render_once(
    scene: &Scene,
    integrator: &dyn restir_integrators::Integrator,
    job: &RenderJob,
) -> restir_integrators::RenderOutput {
    render(
        scene,
        integrator,
        job,
        &AtomicBool::new(false),
        &mut |_, _| {},
    )
}

/// Loads, or renders and caches, the reference of one scene (`frame = None`) or of one frame of
/// a sequence (`scene` the frame's).
fn reference_for(
    entry: &SuiteScene,
    loaded: &LoadedSuiteScene,
    (frame, scene): (Option<u32>, &Scene),
    suite: &Suite,
    opts: &RunOptions,
) -> Result<(Image, ReferenceInfo), BenchError> {
    let (w, h) = scene.camera.resolution();
    if let Some(given) = &entry.reference {
        let path = opts.suite_dir.join(given);
        let image = Image::read_exr(&path)?;
        if (image.width, image.height) != (w, h) {
            return Err(BenchError::ReferenceSize {
                path,
                reference: (image.width, image.height),
                scene: (w, h),
            });
        }
        return Ok((
            image,
            ReferenceInfo {
                scene: loaded.name.clone(),
                path,
                spp: None,
                noise_relmse: None,
                reused: true,
                seconds: 0.0,
            },
        ));
    }
    let spp = entry.reference_spp.unwrap_or(suite.reference_spp);
    let depth = entry
        .max_depth
        .map_or("scene".to_string(), |d| d.to_string());
    // A frame's key adds its number and the frame rate (which decide its time); a still
    // scene's is what it always was, so cached references stay valid.
    let frame_key = frame.map_or(String::new(), |f| format!(" frame={f} fps={}", loaded.fps));
    let key = fnv1a(&[
        &loaded.file_bytes,
        format!("{w}x{h} max_depth={depth} spp={spp} path-halves-v1{frame_key}").as_bytes(),
    ]);
    let dir = opts.out.join("references");
    let stem = match frame {
        Some(f) => format!("{}-{f:04}-{key:016x}", loaded.name),
        None => format!("{}-{key:016x}", loaded.name),
    };
    let exr = dir.join(format!("{stem}.exr"));
    let noise_file = dir.join(format!("{stem}.noise"));
    // A cached reference needs its EXR (of the right size) and its noise estimate.
    let cached = || -> Option<(Image, f64)> {
        let noise = std::fs::read_to_string(&noise_file)
            .ok()?
            .trim()
            .parse::<f64>()
            .ok()?;
        let image = Image::read_exr(&exr).ok()?;
        ((image.width, image.height) == (w, h)).then_some((image, noise))
    };
    if let Some((image, noise)) = cached() {
        return Ok((
            image,
            ReferenceInfo {
                scene: loaded.name.clone(),
                path: exr,
                spp: Some(spp),
                noise_relmse: Some(noise),
                reused: true,
                seconds: 0.0,
            },
        ));
    }
    std::fs::create_dir_all(&dir).map_err(BenchError::io(&dir, "cannot create directory: "))?;
    let path_config = IntegratorConfig {
        label: "reference".into(),
        integrator: "path".into(),
        params: Vec::new(),
    };
    let integrator = build_integrator(scene, &path_config, entry)?;
    let start = Instant::now();
    let halves: Vec<Image> = REFERENCE_SEEDS
        .iter()
        .map(|&seed| {
            let job = RenderJob {
                spp: spp / 2,
                seed,
                ..RenderJob::default()
            };
            render_once(scene, integrator.as_ref(), &job).image
        })
        .collect();
    let seconds = start.elapsed().as_secs_f64();
    let mut image = Image::new(w, h);
    for (i, p) in image.pixels.iter_mut().enumerate() {
        *p = 0.5 * (halves[0].pixels[i] + halves[1].pixels[i]);
    }
    let noise = compare(&halves[0], &halves[1]).map_or(f64::NAN, |m| m.relmse / 4.0);
    image.write(&exr)?;
    std::fs::write(&noise_file, format!("{noise:e}\n")).map_err(BenchError::io(&noise_file, ""))?;
    Ok((
        image,
        ReferenceInfo {
            scene: loaded.name.clone(),
            path: exr,
            spp: Some(spp),
            noise_relmse: Some(noise),
            reused: false,
            seconds,
        },
    ))
}

/// The flicker between consecutive frames: the mean over pixels and channels of
/// `((I_f − R_f) − (I_{f−1} − R_{f−1}))² / (max(R_f, R_{f−1})² + 0.01)` (see the crate
/// documentation).
pub fn flicker(image: &Image, reference: &Image, prev: &Image, prev_reference: &Image) -> f64 {
    let n = image.pixels.len();
    if n == 0
        || [reference, prev, prev_reference]
            .iter()
            .any(|i| i.pixels.len() != n)
    {
        return f64::NAN;
    }
    let mut sum = 0.0f64;
    for i in 0..n {
        let (a, r, pa, pr) = (
            image.pixels[i].as_dvec3(),
            reference.pixels[i].as_dvec3(),
            prev.pixels[i].as_dvec3(),
            prev_reference.pixels[i].as_dvec3(),
        );
        let d = (a - r) - (pa - pr);
        let m = r.max(pr);
        sum += (d * d / (m * m + 0.01)).element_sum();
    }
    sum / (3 * n) as f64
}

/// One render measured: what the record of a still image or a sequence's frame holds besides
/// its scene, configuration, budget, seed and frame.
struct Measured {
    out: restir_integrators::RenderOutput,
    cpu_seconds: f64,
    before: Option<u64>,
    after: Option<u64>,
}

/// Renders `job` with the peak memory reset before and the CPU time around it.
fn measured_render(scene: &Scene, integrator: &dyn Integrator, job: &RenderJob) -> Measured {
    reset_peak_rss();
    let before = vm_hwm_kib();
    let cpu = process_cpu_seconds();
    let out = render_once(scene, integrator, job);
    Measured {
        cpu_seconds: process_cpu_seconds() - cpu,
        after: vm_hwm_kib(),
        before,
        out,
    }
}

/// What one (scene, configuration, budget, seed) rendered: its records (one, or one per frame)
/// and the image for the strip and the page (a sequence's last frame).
struct Rendered {
    records: Vec<RunRecord>,
    image: Image,
}

/// The references of a scene's views (one, or one per frame), in order.
struct References {
    images: Vec<Image>,
}

/// Renders one (configuration, budget, seed) of a scene: a still image, or the frames of a
/// sequence in order with one estimator made for the first frame (history carried across
/// frames through [`FrameSequence`]), each frame with the budget. `step` is called before each
/// frame.
#[allow(clippy::too_many_arguments)]
fn render_entry(
    entry: &SuiteScene,
    loaded: &LoadedSuiteScene,
    references: &References,
    config: &IntegratorConfig,
    integrator: Option<&dyn Integrator>,
    budget: f64,
    seed: u64,
    step: &mut dyn FnMut(Option<u32>),
) -> Result<Rendered, BenchError> {
    let job = |seed| RenderJob {
        spp: u32::MAX,
        time_limit: Some(Duration::from_secs_f64(budget)),
        seed,
        output: None,
    };
    let record = |m: &Measured, reference: &Image, frame, flicker| {
        let (w, h) = (reference.width, reference.height);
        evaluate(&m.out.image, reference)
            .ok_or(BenchError::ReferenceMismatch)
            .map(|e| RunRecord {
                scene: loaded.name.clone(),
                label: config.label.clone(),
                describe: String::new(),
                width: w,
                height: h,
                budget,
                seed,
                seconds: m.out.seconds,
                cpu_seconds: m.cpu_seconds,
                passes: m.out.passes,
                rays: m.out.rays,
                relmse: e.relmse,
                mse: e.mse,
                mape: e.mape,
                flip: e.flip,
                mean_ratio: e.mean_ratio,
                nonfinite: e.nonfinite,
                rss_before_mib: mib(m.before),
                peak_rss_mib: mib(m.after),
                frame,
                flicker,
            })
    };
    let Some(mut sequence) = loaded.sequence().filter(|_| !loaded.frames.is_empty()) else {
        let integrator = integrator.expect("a still scene's integrator is built once");
        step(None);
        let m = measured_render(&loaded.scene, integrator, &job(seed));
        let mut r = record(&m, &references.images[0], None, f64::NAN)?;
        r.describe = integrator.describe();
        return Ok(Rendered {
            records: vec![r],
            image: m.out.image,
        });
    };
    // A fresh estimator per sequence: its history starts empty at the first frame.
    let estimator = build_integrator(&loaded.scene, config, entry)?;
    let mut records = Vec::with_capacity(loaded.frames.len());
    let mut prev: Option<Image> = None;
    for (i, (frame, scene)) in loaded.frames.iter().enumerate() {
        step(Some(*frame));
        sequence.enter(estimator.as_ref(), scene.clone(), *frame);
        let m = measured_render(
            scene,
            estimator.as_ref(),
            &job(FrameSequence::seed(seed, *frame)),
        );
        let reference = &references.images[i];
        let flicker = prev.as_ref().map_or(f64::NAN, |p| {
            flicker(&m.out.image, reference, p, &references.images[i - 1])
        });
        let mut r = record(&m, reference, Some(*frame), flicker)?;
        r.describe = estimator.describe();
        records.push(r);
        prev = Some(m.out.image);
    }
    Ok(Rendered {
        records,
        image: prev.expect("a sequence has at least one frame"),
    })
}

/// Runs every render of `suite` in the current rayon pool, calling `progress` before each step.
pub fn run_suite(
    suite: &Suite,
    opts: &RunOptions,
    progress: &mut dyn FnMut(&Progress),
) -> Result<BenchResults, BenchError> {
    suite.validate()?;
    let started_unix = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let wall = Instant::now();
    let (cpu, cores) = cpu_model();
    let load_start = load_average();
    let peak_reset = reset_peak_rss();

    // Load every scene (every frame of a sequence) and build every integrator once up front,
    // so that a bad scene or parameter fails in seconds rather than after an hour of rendering.
    let mut scenes = Vec::new();
    for entry in &suite.scenes {
        let loaded = load_suite_scene(entry, &opts.suite_dir)?;
        for config in suite.integrators.iter().filter(|c| entry.runs(&c.label)) {
            build_integrator(&loaded.scene, config, entry)?;
        }
        let (w, h) = loaded.scene.camera.resolution();
        let rect = crop_rect(entry, w, h)?;
        scenes.push((entry, loaded, rect));
    }

    let per_config = suite.budgets.len() as u64 * suite.seeds as u64;
    let total: u64 = scenes
        .iter()
        .map(|(entry, loaded, _)| {
            let configs = suite.integrators.iter().filter(|c| entry.runs(&c.label));
            let views = loaded.frames.len().max(1) as u64;
            views + configs.count() as u64 * per_config * views
        })
        .sum();
    let mut done = 0u64;
    let strip_budget = suite
        .strip_budget
        .unwrap_or_else(|| suite.budgets.iter().copied().fold(f64::INFINITY, f64::min));

    let mut records = Vec::new();
    let mut references = Vec::new();
    let mut strips = Vec::new();
    let mut images = Vec::new();
    for (entry, loaded, rect) in &scenes {
        let mut refs = References { images: Vec::new() };
        let mut info: Option<ReferenceInfo> = None;
        for (frame, scene) in loaded.views() {
            progress(&Progress {
                done,
                total,
                message: match frame {
                    Some(f) => format!("{}: reference of frame {f}", loaded.name),
                    None => format!("{}: reference", loaded.name),
                },
            });
            let (image, i) = reference_for(entry, loaded, (frame, &scene), suite, opts)?;
            done += 1;
            refs.images.push(image);
            // A sequence's entry: the last frame's file, every frame's time, the mean noise.
            info = Some(match info {
                None => i,
                Some(prev) => ReferenceInfo {
                    seconds: prev.seconds + i.seconds,
                    reused: prev.reused && i.reused,
                    noise_relmse: prev.noise_relmse.zip(i.noise_relmse).map(|(a, b)| a + b),
                    ..i
                },
            });
        }
        let mut info = info.expect("every scene has a view");
        if let Some(n) = &mut info.noise_relmse {
            *n /= refs.images.len() as f64;
        }
        references.push(info);
        let reference = refs.images.last().expect("a reference").clone();
        let mut strip_crops: Vec<Option<Image>> = vec![None; suite.integrators.len()];
        let mut renders: Vec<(usize, String, f64, Image)> = Vec::new();
        // A still scene's estimators are built once; a sequence builds one per sequence.
        let integrators = suite
            .integrators
            .iter()
            .map(|c| {
                (entry.runs(&c.label) && loaded.frames.is_empty())
                    .then(|| build_integrator(&loaded.scene, c, entry))
                    .transpose()
            })
            .collect::<Result<Vec<_>, _>>()?;
        // Seeds outermost, so that a load spike on the shared machine hits every configuration
        // and budget rather than all seeds of one.
        for seed in 0..suite.seeds as u64 {
            for &budget in &suite.budgets {
                for (ci, config) in suite.integrators.iter().enumerate() {
                    if !entry.runs(&config.label) {
                        continue;
                    }
                    let r = render_entry(
                        entry,
                        loaded,
                        &refs,
                        config,
                        integrators[ci].as_deref(),
                        budget,
                        seed,
                        &mut |frame| {
                            progress(&Progress {
                                done,
                                total,
                                message: format!(
                                    "{}: {} {budget} s seed {seed}{}",
                                    loaded.name,
                                    config.label,
                                    frame.map_or(String::new(), |f| format!(" frame {f}"))
                                ),
                            });
                            done += 1;
                        },
                    )?;
                    records.extend(r.records);
                    if seed == 0 && budget == strip_budget {
                        strip_crops[ci] = Some(crop(&r.image, *rect));
                    }
                    if seed == 0 {
                        renders.push((ci, config.label.clone(), budget, r.image));
                    }
                }
            }
        }
        let mut crops = vec![crop(&reference, *rect)];
        let mut labels = vec!["reference".to_string()];
        for (config, c) in suite.integrators.iter().zip(strip_crops) {
            if let Some(c) = c {
                crops.push(c);
                labels.push(config.label.clone());
            }
        }
        strips.push(Strip {
            scene: loaded.name.clone(),
            crop: *rect,
            budget: strip_budget,
            crops,
            labels,
        });
        renders.sort_by(|a, b| a.0.cmp(&b.0).then(a.2.total_cmp(&b.2)));
        images.push(SceneImages {
            scene: loaded.name.clone(),
            reference,
            renders: renders.into_iter().map(|(_, l, b, i)| (l, b, i)).collect(),
        });
    }
    progress(&Progress {
        done,
        total,
        message: "writing outputs".into(),
    });
    Ok(BenchResults {
        suite: suite.clone(),
        records,
        references,
        strips,
        images,
        machine: Machine {
            cpu,
            cores,
            threads: rayon::current_num_threads(),
            load_start,
            load_end: load_average(),
            peak_reset,
        },
        command_line: opts.command_line.clone(),
        started_unix,
        wall_seconds: wall.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv_is_stable_and_chunked() {
        assert_eq!(fnv1a(&[]), 0xcbf2_9ce4_8422_2325);
        assert_ne!(fnv1a(&[b"ab", b"c"]), fnv1a(&[b"a", b"bc"]));
        assert_eq!(fnv1a(&[b"scene"]), fnv1a(&[b"scene"]));
    }

    #[test]
    fn default_crop_is_central_quarter() {
        let entry = SuiteScene {
            path: "a.xml".into(),
            name: None,
            width: None,
            height: None,
            max_depth: None,
            reference: None,
            reference_spp: None,
            crop: None,
            integrators: None,
            frames: None,
            fps: None,
        };
        assert_eq!(crop_rect(&entry, 64, 32).unwrap(), (16, 8, 32, 16));
        let bad = SuiteScene {
            crop: Some((60, 0, 8, 8)),
            ..entry
        };
        assert!(crop_rect(&bad, 64, 32).is_err());
    }
}
