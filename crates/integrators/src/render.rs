//! The render driver: a [`RenderJob`] (how many passes, how long, which seed, where to) run on a
//! scene with an [`Integrator`], pass after pass into a [`Film`] until the sample count, the time
//! limit or a cancellation ends it. A pass is one sample per pixel of an integrator's final
//! estimator. [`render_part`] renders one part of a render, for splitting it across machines: a
//! range of its passes (the same `(seed, pixel, pass)` streams), and optionally a window of the
//! film ([`PixelWindow`]) rendered with a halo wide enough for the estimator's spatial reuse.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use restir_scene::{Scene, SceneDesc};

use crate::Image;
use crate::film::{Film, Reconstruction};
use crate::pass::{Crop, Integrator, PassContext, PixelWindow};

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
    /// Also keep each pixel's mean and second moment over the passes, under this name
    /// (Mitsuba's `moment` integrator: [`RenderOutput::moment`]).
    pub moment: Option<String>,
}

impl Default for RenderJob {
    /// One pass, no time limit, seed 0, no output file.
    fn default() -> Self {
        Self {
            spp: 1,
            time_limit: None,
            seed: 0,
            output: None,
            moment: None,
        }
    }
}

impl RenderJob {
    /// The job a scene description asks for: its sample count (at least one), its film's
    /// file name and its second moment (a `moment` integrator); seed 0 and no time limit.
    pub fn from_desc(desc: &SceneDesc) -> Self {
        Self {
            spp: desc.spp.max(1),
            output: desc.film.filename.as_ref().map(PathBuf::from),
            moment: desc.integrator.moment.clone(),
            ..Self::default()
        }
    }
}

/// Which estimator rendered, what was asked for, and why that one ran.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EstimatorReport {
    /// What was asked for: an estimator's name, or `auto`.
    pub asked: String,
    /// The estimator that rendered every pass: `path`, `restir-di` or `restir-pt`.
    pub ran: String,
    /// Its settings in one line ([`Integrator::describe`]).
    pub settings: String,
    /// Why it ran: `asked for by name`, or what `auto`'s rules measured of the scene.
    pub why: String,
}

impl EstimatorReport {
    /// What `integrator` is: the estimator that renders, and whether `auto` chose it and why
    /// ([`Integrator::auto_choice`]).
    pub fn of(integrator: &dyn Integrator) -> Self {
        let ran = integrator.name().to_string();
        let (asked, why) = match integrator.auto_choice() {
            Some(why) => ("auto".to_string(), format!("chosen by auto: {why}")),
            None => (ran.clone(), "asked for by name".to_string()),
        };
        Self {
            asked,
            ran,
            settings: integrator.describe(),
            why,
        }
    }
}

/// One line: `ran restir-di (asked for by name)` or `ran path (chosen by auto: …)`.
impl std::fmt::Display for EstimatorReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ran {} ({})", self.ran, self.why)
    }
}

/// The result of a render.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    /// The estimator that rendered it, and why that one.
    pub estimator: EstimatorReport,
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
    /// Each pixel's mean and second moment, when the job asked for them
    /// ([`RenderJob::moment`]).
    pub moment: Option<MomentImages>,
}

/// Each pixel's mean and second moment over the passes of a render, in CIE XYZ, as Mitsuba 3's
/// `moment` integrator writes them beside the image (`name.X`, `name.Y`, `name.Z`,
/// `m2_name.X`, …: [`MomentImages::channels`]). With `N` passes, `(m₂ − m²)/(N − 1)` estimates
/// the variance of a pixel's value.
#[derive(Clone, Debug, PartialEq)]
pub struct MomentImages {
    /// The channels' name (the nested integrator's in Mitsuba).
    pub name: String,
    /// The mean per pixel (the image in XYZ), row-major.
    pub mean: Vec<glam::DVec3>,
    /// The mean of the passes' estimates squared per pixel and channel, row-major.
    pub second: Vec<glam::DVec3>,
}

impl MomentImages {
    /// The six channels as Mitsuba 3 names them, for [`Image::write_with`].
    pub fn channels(&self) -> Vec<restir_image::Channel> {
        let mut out = Vec::with_capacity(6);
        for (prefix, values) in [("", &self.mean), ("m2_", &self.second)] {
            for (i, axis) in ["X", "Y", "Z"].iter().enumerate() {
                out.push(restir_image::Channel {
                    name: format!("{prefix}{}.{axis}", self.name),
                    values: values.iter().map(|v| v[i] as f32).collect(),
                });
            }
        }
        out
    }
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
    render_part(
        scene,
        integrator,
        job,
        &RenderPart::default(),
        cancel,
        progress,
    )
}

/// Which part of a render this process makes: passes `first_pass..first_pass + job.spp` of the
/// same random streams, over the whole film or a window of it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderPart {
    /// Index of the first pass.
    pub first_pass: u32,
    /// The window of the film to render, or `None` for all of it.
    pub window: Option<PixelWindow>,
}

impl RenderPart {
    /// The region rendered for the window: the window with the integrator's halo, aligned
    /// ([`PixelWindow::with_halo`]); the whole film without a window.
    pub fn region(&self, integrator: &dyn Integrator, scene: &Scene) -> PixelWindow {
        let film = scene.camera.resolution();
        match &self.window {
            None => PixelWindow::full(film),
            Some(w) => w.with_halo(part_halo(integrator, scene), film),
        }
    }
}

/// How far, in pixels, a pixel of the image reaches for the estimates of others in one pass:
/// the integrator's spatial reuse ([`Integrator::halo`]) beyond the film's splatting reach
/// ([`Reconstruction::reach`]). A cropped render renders its window with this halo.
pub fn part_halo(integrator: &dyn Integrator, scene: &Scene) -> u32 {
    integrator.halo() + Reconstruction::decide(scene.filter).reach()
}

/// [`render`] for one part of a render: passes from `part.first_pass` on, and with a window only
/// its region (the window plus halo) is rendered and the image is the window's. Temporal reuse
/// starts afresh at the part's first pass. `part.window` must fit the film.
pub fn render_part(
    scene: &Scene,
    integrator: &dyn Integrator,
    job: &RenderJob,
    part: &RenderPart,
    cancel: &AtomicBool,
    progress: &mut dyn FnMut(u32, Duration),
) -> RenderOutput {
    let film_size = scene.camera.resolution();
    let region = part.region(integrator, scene);
    let crop = part.window.map(|_| Crop {
        region,
        film_width: film_size.0,
    });
    let mut film = Film::new(region.width, region.height, scene.filter);
    let splats = matches!(film.reconstruction(), Reconstruction::Splatted { .. });
    if job.moment.is_some() {
        film = film.with_second_moment();
    }
    let start = Instant::now();
    let mut rays = 0u64;
    let spp = job.spp.max(1);
    while film.passes() < spp {
        let pass = part.first_pass + film.passes();
        let offset = film.shared_offset(PassContext::shared_offset_of(job.seed, pass));
        rays += film.add_pass(offset, |filter, samples, sums| {
            let ctx = PassContext {
                seed: job.seed,
                pass,
                filter,
                shared_offset: splats.then_some(offset),
                samples,
                crop,
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
    let image = match &part.window {
        None => film.image(),
        Some(window) => region.extract(&film.image(), window),
    };
    let nonfinite_pixels = image.nonfinite_count();
    let moment = job.moment.as_ref().and_then(|name| {
        let m = film.moments()?;
        let window = |v: Vec<glam::DVec3>| match &part.window {
            None => v,
            Some(window) => region.extract_values(&v, window),
        };
        Some(MomentImages {
            name: name.clone(),
            mean: window(m.mean),
            second: window(m.second),
        })
    });
    RenderOutput {
        estimator: EstimatorReport::of(integrator),
        image,
        passes: film.passes(),
        seconds,
        rays,
        nonfinite_pixels,
        moment,
    }
}
