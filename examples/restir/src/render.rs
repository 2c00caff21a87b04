//! The `render` command: load the scene, make the estimator, settle the passes and the output,
//! check everything that can fail before rendering, then render (one image, a part of a split
//! render, or a frame sequence) and report.

use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use restir_image::Image;
use restir_integrators::film::Reconstruction;
use restir_integrators::{Integrator, IntegratorOptions, RenderJob, RenderOutput, make_integrator};
use restir_scene::{LoadOptions, LoadedScene, SamplerKind, Scene, load_scene};

use crate::args::{RenderArgs, parse_defines};
use crate::frames::{self, FramePlan};
use crate::say::say_err;
use crate::stats::Report;
use crate::{cluster, interrupt, progress, strict};

/// How a render ended: completely, or stopped by an interrupt (the partial image written).
pub(crate) enum Rendered {
    Complete,
    Interrupted,
}

impl Rendered {
    fn from_interrupted(interrupted: bool) -> Self {
        if interrupted {
            Rendered::Interrupted
        } else {
            Rendered::Complete
        }
    }
}

/// A loaded scene with what the command line made of it.
struct Loaded {
    loaded: LoadedScene,
    /// The frames to render (`--frames`), if any.
    frame_plan: Option<FramePlan>,
    /// The scene's sample count and file name, and the seed.
    job: RenderJob,
    load_seconds: f64,
}

/// The passes and the output, settled from the flags and the scene.
struct Settled {
    output: PathBuf,
    plan: Option<cluster::Plan>,
    time_limit: Option<Duration>,
}

/// `restir render`.
pub(crate) fn run(args: RenderArgs) -> Result<Rendered, String> {
    let Loaded {
        loaded,
        frame_plan,
        mut job,
        load_seconds,
    } = load(&args)?;
    let scene = &loaded.scene;
    let (integrator, options) = make(&args, &loaded)?;
    let pool = strict::thread_pool(args.threads)?;
    let threads = pool.current_num_threads();
    let Settled {
        output,
        plan,
        time_limit,
    } = settle(&args, &mut job, scene, integrator.as_ref(), threads)?;
    let spp = job.spp;
    let output = prepare_outputs(&args, output, frame_plan.as_ref())?;
    keep_moment_where_written(
        &args,
        &loaded,
        &mut job,
        &output,
        plan.is_some(),
        frame_plan.is_some(),
    );

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
        return Ok(Rendered::from_interrupted(stopped));
    }

    let bar = progress::pass_bar(args.quiet, time_limit, spp);
    let out = pool.install(|| {
        cluster::render(
            scene,
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
    write_image(
        &args,
        &loaded,
        integrator.as_ref(),
        plan.as_ref(),
        &out,
        &output,
    )?;

    let report = Report {
        scene_file: &args.scene,
        scene,
        integrator: integrator.as_ref(),
        out: &out,
        plan: plan.as_ref(),
        load_seconds,
        seed: args.seed,
        threads,
    };
    if let Some(path) = &args.stats {
        report.write_stats(path)?;
    }
    let interrupted = cancel.load(Ordering::SeqCst);
    report.say(interrupted, args.quiet, &output);
    Ok(Rendered::from_interrupted(interrupted))
}

/// Loads the scene with the flags' overrides (and `--animation`), plans the frames and says
/// the loader's warnings.
fn load(args: &RenderArgs) -> Result<Loaded, String> {
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
    // The scene's sample count and file name are the job's defaults.
    let mut job = RenderJob::from_desc(&loaded.desc);
    job.seed = args.seed;
    let load_seconds = load_start.elapsed().as_secs_f64();
    Ok(Loaded {
        loaded,
        frame_plan,
        job,
        load_seconds,
    })
}

/// Makes the estimator the flags and the scene ask for, and says its notes and the parameters
/// it does not use.
fn make(
    args: &RenderArgs,
    loaded: &LoadedScene,
) -> Result<(Box<dyn Integrator>, IntegratorOptions), String> {
    let options = IntegratorOptions {
        name: args.integrator.clone(),
        max_depth: args.max_depth,
        params: args.restir.params(),
        sampler: args.sampler.as_deref().map(|s| match s {
            "sobol" => SamplerKind::Sobol,
            _ => SamplerKind::Independent,
        }),
    };
    let (scene, integrator) = (&loaded.scene, &loaded.desc.integrator);
    let made = make_integrator(scene, integrator, &options).map_err(|e| e.to_string())?;
    strict::check_flags_used(scene, integrator, &made)?;
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
    Ok((made.integrator, options))
}

/// Settles the job's passes and time limit, the output file and the part of a split render,
/// and checks the output's format and the estimator's memory on `threads` threads.
fn settle(
    args: &RenderArgs,
    job: &mut RenderJob,
    scene: &Scene,
    integrator: &dyn Integrator,
    threads: usize,
) -> Result<Settled, String> {
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
    // A second moment is kept for an EXR of a whole image (`keep_moment_where_written`).
    let moment = job.moment.is_some()
        && plan.is_none()
        && output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    strict::check_memory(
        (width, height),
        threads,
        integrator,
        &Reconstruction::decide(scene.filter),
        moment,
        strict::max_memory(args.max_memory)?,
    )?;
    Ok(Settled {
        output,
        plan,
        time_limit,
    })
}

/// A scene's `moment` integrator asks for each pixel's mean and second moment beside the image:
/// channels that only an EXR of a whole image holds. For a PNG, a part of a split render or a
/// frame sequence they are not computed, and a warning says so before rendering.
fn keep_moment_where_written(
    args: &RenderArgs,
    loaded: &LoadedScene,
    job: &mut RenderJob,
    output: &std::path::Path,
    part: bool,
    frames: bool,
) {
    if job.moment.is_none() {
        return;
    }
    let exr = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    let why = if !exr {
        "a PNG holds RGB only"
    } else if part {
        "parts of a split render keep the image only"
    } else if frames {
        "frame sequences keep the image only"
    } else {
        return;
    };
    job.moment = None;
    if !args.quiet {
        say_err!(
            "warning: {}: the moment integrator's second-moment channels are not written ({why}); {} gets the image",
            loaded.desc.integrator.location,
            output.display()
        );
    }
}

/// Fails before rendering, not after, when an output cannot be written: creates the output's
/// (and a frame preview's) directory and checks the files. Returns the first file written (the
/// first frame's with `--frames`).
fn prepare_outputs(
    args: &RenderArgs,
    output: PathBuf,
    frame_plan: Option<&FramePlan>,
) -> Result<PathBuf, String> {
    let output = match frame_plan {
        Some(f) => frames::frame_path(&output, f.first),
        None => output,
    };
    if let Some((p, _)) = frame_plan.and_then(|f| f.preview.as_ref()) {
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
    Ok(output)
}

/// Writes the rendered image: a part with its attributes, or the whole image.
fn write_image(
    args: &RenderArgs,
    loaded: &LoadedScene,
    integrator: &dyn Integrator,
    plan: Option<&cluster::Plan>,
    out: &RenderOutput,
    output: &std::path::Path,
) -> Result<(), String> {
    match plan {
        Some(p) => p.write(
            &out.image,
            output,
            &args.scene,
            &loaded.desc,
            integrator,
            args.seed,
        ),
        None => {
            let channels = out
                .moment
                .as_ref()
                .map(|m| m.channels())
                .unwrap_or_default();
            out.image
                .write_with(output, &channels)
                .map_err(|e| e.to_string())
        }
    }
}
