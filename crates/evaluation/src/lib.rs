//! Equal-time evaluation of the restir estimators (`restir bench`).
//!
//! A [`Suite`] lists scenes, integrator configurations, time budgets and seeds. [`run_suite`]
//! renders every combination with the library [`render`](restir_integrators::render) (`spp: u32::MAX`, the budget as time
//! limit; with the suite's `clock: Cpu`, [`Clock::Cpu`], the budget counts the process's CPU
//! seconds instead of wall seconds), compares each image with a reference and records time, passes, rays, errors and peak
//! memory. [`write_outputs`] then writes the CSV, one log-log relMSE-versus-time plot per scene
//! (SVG), one strip of crops per scene (PNG), a Markdown report and an interactive HTML page
//! ([`html`]); [`update_doc`] puts the report into a marked section of another Markdown file.
//! Besides relMSE every run records MAPE and FLIP ([`metrics`]).
//!
//! **Animation suites.** A suite scene with `frames` is a sequence: each configuration renders
//! its frames in order with one estimator (made for the first frame's scene and told of each
//! next frame's motion through [`FrameSequence`](restir_integrators::FrameSequence), so temporal reuse carries across frames),
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
//! A sequence keeps only its first frame's scene: every other frame is built when its
//! reference or render needs it and dropped after, and each frame's reference is read back from
//! its cached file when the frame is compared, so memory does not grow with the frame count.
//!
//! **Memory and errors.** Each scene's meshes and images are checked against the same limit
//! while it loads, before each is built or decoded, as `restir render` checks them. Before
//! anything of the size of an image is allocated, each scene's renders are estimated ([`BYTES_PER_PIXEL`], the largest estimator buffers, the images kept for
//! the page) against [`RunOptions::max_memory_gib`]. Errors about one entry of the suite name
//! its line in the suite file ([`suite::SuiteLines`]).
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

mod analysis;
mod error;
mod load;
mod measure;
pub mod metrics;
mod records;
mod reference;
mod report;
mod run;
pub mod suite;

pub use analysis::{Summary, TimeToError, flicker, sequence_runs, summarize, time_to_error};
pub use error::BenchError;
pub use measure::process_cpu_seconds;
pub use records::{
    BenchResults, Machine, Progress, ReferenceInfo, RunOptions, RunRecord, SceneImages, Strip,
};
pub use reference::{REFERENCE_SEEDS, fnv1a};
pub use report::doc::{BEGIN_MARKER, END_MARKER, check_doc, update_doc};
pub use report::files::write_outputs;
pub use report::html;
pub use run::{BYTES_PER_PIXEL, run_suite};
pub use suite::{Clock, IntegratorConfig, Suite, SuiteError, SuiteLines, SuiteScene};
