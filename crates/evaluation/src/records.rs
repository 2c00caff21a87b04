//! What a suite run records: one [`RunRecord`] per render, the references, crop strips and
//! images of every scene, the machine, and the options and progress of [`crate::run_suite`].

use std::path::PathBuf;

use restir_image::Image;

use crate::suite::{Suite, SuiteLines};

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
    /// MAPE against the reference ([`crate::metrics`]).
    pub mape: f64,
    /// Mean FLIP error of the tone-mapped image against the tone-mapped reference ([`crate::metrics`]).
    pub flip: f64,
    /// Mean of the image over mean of the reference.
    pub mean_ratio: f64,
    /// Share of the squared error in the 1 % of pixels with the most ([`crate::metrics::top_share`]).
    pub top1_share: f64,
    /// Pixels with NaN or infinite values.
    pub nonfinite: usize,
    /// Resident memory just before the render, MiB (`VmHWM` right after the reset).
    pub rss_before_mib: f64,
    /// Peak resident memory during the render, MiB (see the crate documentation).
    pub peak_rss_mib: f64,
    /// The frame, for a frame of a sequence (`None`: a still render, or a whole sequence folded
    /// by [`crate::sequence_runs`]).
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

/// What [`crate::run_suite`] reports as it goes.
#[derive(Clone, Debug)]
pub struct Progress {
    /// Steps done (references and renders).
    pub done: u64,
    /// All steps.
    pub total: u64,
    /// What is being done next.
    pub message: String,
}

/// Options of [`crate::run_suite`] beyond the suite itself.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Directory of the suite file: scene and reference paths are relative to it.
    pub suite_dir: PathBuf,
    /// Output directory (references are cached in its `references/`).
    pub out: PathBuf,
    /// The command line, for the report.
    pub command_line: String,
    /// The most memory a scene's renders may need, in GiB (`--max-memory`), estimated before
    /// anything of the size of the image is allocated ([`crate::BYTES_PER_PIXEL`]); a scene's
    /// meshes and images are checked against it while it loads.
    pub max_memory_gib: f64,
    /// Where the suite's entries are in its file, so that errors name the line.
    pub lines: SuiteLines,
}
