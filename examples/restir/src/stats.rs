//! What a finished render reports: the `--stats` JSON and the summary line.

use std::path::Path;

use restir_geometry::Shape;
use restir_integrators::film::Reconstruction;
use restir_integrators::{EstimatorReport, Integrator, RenderOutput};
use restir_scene::Scene;

use crate::cluster;
use crate::say::{say, say_err};

/// The `--stats` JSON of a single-image render.
#[derive(serde::Serialize)]
struct Stats<'a> {
    scene: String,
    /// The estimator that rendered (for `auto`, the one it chose).
    integrator: &'a str,
    integrator_settings: String,
    /// What was asked for, what ran and why.
    estimator: EstimatorStats,
    /// The estimator's per-pass buffers for this film on these threads, at most: in all and
    /// per pixel (rounded up).
    buffer_bytes: u64,
    buffer_bytes_per_pixel: u64,
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
    /// The ray-tracing structure the scene build made (its size and the CPU's kernel).
    bvh: String,
    /// How light samples are drawn, as the scene build decided it.
    light_selection: String,
    /// The pixel filter and how the film uses it (sampled or splatted), and why.
    film: String,
    /// Wall seconds per stage of the estimator's passes, summed over the passes (empty for
    /// the path tracer).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    stage_seconds: Vec<StageSeconds>,
    /// What the estimator learned across passes (ReSTIR DI with `--learn on`).
    #[serde(skip_serializing_if = "Option::is_none")]
    learned: Option<String>,
    /// The camera rays given to emitter silhouettes (ReSTIR DI and PT with `--edge-rays` above 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    silhouettes: Option<String>,
    /// How screen tiles cut the light hierarchy (ReSTIR DI with `--light-sampler tiles`).
    #[serde(skip_serializing_if = "Option::is_none")]
    light_cuts: Option<String>,
    /// What the estimator runs in SIMD lanes (the path tracer).
    #[serde(skip_serializing_if = "Option::is_none")]
    lanes: Option<String>,
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

/// A finished single-image render, with what it is reported with.
pub(crate) struct Report<'a> {
    /// The scene file.
    pub(crate) scene_file: &'a Path,
    pub(crate) scene: &'a Scene,
    pub(crate) integrator: &'a dyn Integrator,
    pub(crate) out: &'a RenderOutput,
    /// The part of a split render rendered (its passes those rendered).
    pub(crate) plan: Option<&'a cluster::Plan>,
    pub(crate) load_seconds: f64,
    pub(crate) seed: u64,
    pub(crate) threads: usize,
}

impl Report<'_> {
    /// Million rays per second of render time.
    fn mrays_per_second(&self) -> f64 {
        self.out.rays as f64 / self.out.seconds.max(1e-9) / 1e6
    }

    /// Writes the `--stats` JSON to `path`.
    pub(crate) fn write_stats(&self, path: &Path) -> Result<(), String> {
        let (scene, integrator, out) = (self.scene, self.integrator, self.out);
        let (width, height) = (out.image.width, out.image.height);
        let buffer_bytes = integrator.buffer_bytes(width, height, self.threads);
        let stats = Stats {
            scene: self.scene_file.display().to_string(),
            integrator: integrator.name(),
            integrator_settings: integrator.describe(),
            estimator: (&out.estimator).into(),
            buffer_bytes,
            buffer_bytes_per_pixel: buffer_bytes.div_ceil((width as u64 * height as u64).max(1)),
            triangles: scene
                .shapes
                .iter()
                .map(|s| match s {
                    Shape::Mesh(m) => m.triangle_count(),
                    _ => 0,
                })
                .sum(),
            spheres: scene
                .shapes
                .iter()
                .filter(|s| matches!(s, Shape::Sphere(_)))
                .count(),
            lights: scene.lights.len(),
            seconds: out.seconds,
            load_seconds: self.load_seconds,
            spp: out.passes,
            width,
            height,
            rays: out.rays,
            mrays_per_second: self.mrays_per_second(),
            nonfinite_pixels: out.nonfinite_pixels,
            seed: self.seed,
            threads: self.threads,
            bvh: scene.accel.describe(),
            light_selection: scene.light_selection(),
            film: Reconstruction::decide(scene.filter).describe(scene.filter),
            stage_seconds: integrator
                .stage_seconds()
                .into_iter()
                .map(|(stage, seconds)| StageSeconds { stage, seconds })
                .collect(),
            learned: integrator.learned(),
            silhouettes: integrator.silhouettes(),
            light_cuts: integrator.light_cuts(),
            lanes: integrator.lanes(scene),
            part: self.plan.map(|p| p.stats(integrator, scene)),
        };
        let json = serde_json::to_string_pretty(&stats).map_err(|e| e.to_string())?;
        restir_image::write_file_atomically(path, (json + "\n").as_bytes())
            .map_err(|e| e.to_string())
    }

    /// Says how the render went: an interrupt (even when `quiet`), then unless `quiet` the
    /// summary line and a warning about non-finite pixels.
    pub(crate) fn say(&self, interrupted: bool, quiet: bool, output: &Path) {
        let out = self.out;
        if interrupted {
            // Said even with --quiet: the exit code alone does not tell what was written.
            say_err!(
                "interrupted after {} passes: wrote what was rendered -> {}",
                out.passes,
                output.display()
            );
        }
        if quiet {
            return;
        }
        let stopped = if interrupted { " (interrupted)" } else { "" };
        say!(
            "{} [{}]: {} passes in {:.2} s{stopped}, {:.1} Mrays/s, {} threads, loaded in {:.2} s -> {}",
            out.estimator.settings,
            out.estimator.why,
            out.passes,
            out.seconds,
            self.mrays_per_second(),
            self.threads,
            self.load_seconds,
            output.display()
        );
        if out.nonfinite_pixels > 0 {
            say_err!(
                "warning: {} pixels are NaN or infinite",
                out.nonfinite_pixels
            );
        }
    }
}
