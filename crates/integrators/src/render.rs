//! The render driver: a [`RenderJob`] (how many passes, how long, which seed, where to) run on a
//! scene with an [`Integrator`], pass after pass into a [`Film`] until the sample count, the time
//! limit or a cancellation ends it. A pass is one sample per pixel of an integrator's final
//! estimator.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use glam::{DVec3, Vec2};
use rayon::prelude::*;
use restir_sampling::Pcg32;
use restir_scene::{Scene, SceneDesc};

use crate::Image;
use crate::bands::Bands;
use crate::film::{Film, Filter};
use crate::path::{PathSettings, trace_camera_path};

/// What an integrator needs to know about the current pass.
#[derive(Debug)]
pub struct PassContext<'a> {
    /// The render's seed.
    pub seed: u64,
    /// Index of this pass (0-based).
    pub pass: u32,
    /// The pixel filter, for jittering camera rays.
    pub filter: &'a Filter,
}

impl PassContext<'_> {
    /// The random stream of pixel `index` in this pass, the same whatever thread renders it.
    #[inline]
    pub fn pixel_rng(&self, index: usize) -> Pcg32 {
        Pcg32::for_pixel_sample(self.seed, index as u64, self.pass as u64)
    }

    /// A second, independent stream of pixel `index` in this pass, for estimator stage `stage`
    /// (stage 0 is [`PassContext::pixel_rng`]'s stream).
    #[inline]
    pub fn stage_rng(&self, index: usize, stage: u64) -> Pcg32 {
        let seed = if stage == 0 {
            self.seed
        } else {
            restir_sampling::mix64(self.seed ^ stage.wrapping_mul(0xa076_1d64_78bd_642f))
        };
        Pcg32::for_pixel_sample(seed, index as u64, self.pass as u64)
    }

    /// The film position (pixel units) of a filter-jittered camera ray through pixel `(x, y)`.
    #[inline]
    pub fn film_position(&self, x: u32, y: u32, rng: &mut Pcg32) -> Vec2 {
        Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + self.filter.sample(rng.next_2d())
    }
}

/// An estimator that renders whole passes.
pub trait Integrator: Sync + Send + std::fmt::Debug {
    /// Name as given on the command line.
    fn name(&self) -> &'static str;
    /// Renders one pass, adding one estimate per pixel to `accum` (row-major). Returns the number
    /// of rays traced.
    fn render_pass(&self, scene: &Scene, ctx: &PassContext, accum: &mut [DVec3]) -> u64;
    /// The estimator's settings in one line, for logs and statistics.
    fn describe(&self) -> String {
        self.name().to_string()
    }
    /// Bytes per pixel of the per-pass buffers the estimator keeps besides the image (reservoirs,
    /// primary hits).
    fn buffer_bytes_per_pixel(&self) -> usize {
        0
    }
}

/// The path tracer as an [`Integrator`].
#[derive(Clone, Debug)]
pub struct PathIntegrator {
    /// Settings.
    pub settings: PathSettings,
}

impl Integrator for PathIntegrator {
    fn name(&self) -> &'static str {
        "path"
    }

    fn describe(&self) -> String {
        format!(
            "path max_depth={} rr_depth={}",
            self.settings.max_depth, self.settings.rr_depth
        )
    }

    fn render_pass(&self, scene: &Scene, ctx: &PassContext, accum: &mut [DVec3]) -> u64 {
        let (w, _) = scene.camera.resolution();
        let w = w as usize;
        let bands = Bands::new(w);
        accum
            .par_chunks_mut(bands.pixels())
            .enumerate()
            .map(|(band, chunk)| {
                let mut rays = 0;
                for (i, px) in chunk.iter_mut().enumerate() {
                    let index = bands.first(band) + i;
                    let (x, y) = ((index % w) as u32, (index / w) as u32);
                    let mut rng = ctx.pixel_rng(index);
                    let film = ctx.film_position(x, y, &mut rng);
                    let (l, r) = trace_camera_path(scene, &self.settings, film, &mut rng);
                    *px += l.as_dvec3();
                    rays += r;
                }
                rays
            })
            .sum()
    }
}

/// One render of a scene: what belongs to this render rather than to the scene. A scene
/// description's sample count and output file name are the defaults ([`RenderJob::from_desc`]).
/// The film size is not here: the camera is built for it when the scene is loaded
/// (`restir_scene::LoadOptions`).
#[derive(Clone, Debug, PartialEq)]
pub struct RenderJob {
    /// Passes to render (at least one is always rendered).
    pub spp: u32,
    /// Stop starting new passes once this much time has passed.
    pub time_limit: Option<Duration>,
    /// Seed of every random stream.
    pub seed: u64,
    /// Where the image is to be written; [`render`] does not write it.
    pub output: Option<PathBuf>,
}

impl Default for RenderJob {
    /// One pass, no time limit, seed 0, no output file.
    fn default() -> Self {
        Self {
            spp: 1,
            time_limit: None,
            seed: 0,
            output: None,
        }
    }
}

impl RenderJob {
    /// The job a scene description asks for: its sample count (at least one) and its film's
    /// file name; seed 0 and no time limit.
    pub fn from_desc(desc: &SceneDesc) -> Self {
        Self {
            spp: desc.spp.max(1),
            output: desc.film.filename.as_ref().map(PathBuf::from),
            ..Self::default()
        }
    }
}

/// The result of a render.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    /// The average of the passes.
    pub image: Image,
    /// Passes made.
    pub passes: u32,
    /// Render time in seconds (excluding scene loading).
    pub seconds: f64,
    /// Rays traced: camera, continuation and shadow rays.
    pub rays: u64,
    /// Pixels with a NaN or infinite value.
    pub nonfinite_pixels: usize,
}

/// Renders `scene` with `integrator` in the current rayon pool. `cancel` stops the render after
/// the current pass; `progress` is called after each pass with `(passes done, elapsed)`.
pub fn render(
    scene: &Scene,
    integrator: &dyn Integrator,
    job: &RenderJob,
    cancel: &AtomicBool,
    progress: &mut dyn FnMut(u32, Duration),
) -> RenderOutput {
    let (w, h) = scene.camera.resolution();
    let mut film = Film::new(w, h, scene.filter);
    let start = Instant::now();
    let mut rays = 0u64;
    let spp = job.spp.max(1);
    while film.passes() < spp {
        let pass = film.passes();
        rays += film.add_pass(|filter, sums| {
            let ctx = PassContext {
                seed: job.seed,
                pass,
                filter,
            };
            integrator.render_pass(scene, &ctx, sums)
        });
        let elapsed = start.elapsed();
        progress(film.passes(), elapsed);
        if cancel.load(Ordering::Relaxed) {
            break;
        }
        if job.time_limit.is_some_and(|t| elapsed >= t) {
            break;
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    let image = film.image();
    let nonfinite_pixels = image.nonfinite_count();
    RenderOutput {
        image,
        passes: film.passes(),
        seconds,
        rays,
        nonfinite_pixels,
    }
}
