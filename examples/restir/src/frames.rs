//! `restir render SCENE --frames A..B`: an animated scene rendered frame by frame. Each frame is
//! the scene at time `frame / fps` (`restir_scene::animation::build_at`, a whole new scene per
//! frame), rendered with the job's passes or time limit and written as `NAME_0001.exr` (or
//! `.png`) through the atomic writer; `--preview OUT.png` also writes an animated PNG of the
//! frames, and `--preview OUT.mp4` (`.webm`, `.mkv`, `.mov`, `.gif`) a video through `ffmpeg`
//! when it is on `PATH` ([`crate::preview`]: written as the frames come, in memory independent
//! of their number). The flags are checked before anything renders.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use restir_integrators::FrameSequence;
use restir_integrators::{
    EstimatorReport, Integrator, IntegratorOptions, RenderJob, make_integrator, render,
};
use restir_scene::SceneDesc;
use restir_scene::animation::FRAME_REBUILDS;

/// The frames to render, checked.
#[derive(Clone, Debug)]
pub struct FramePlan {
    /// First frame number.
    pub first: u32,
    /// Last frame number (inclusive).
    pub last: u32,
    /// Frames per second.
    pub fps: f32,
    /// Where the animated preview goes, and how it is written.
    pub preview: Option<(PathBuf, Preview)>,
}

/// How the preview of a sequence is written, from its file name's extension.
#[derive(Clone, Debug, PartialEq)]
pub enum Preview {
    /// An animated PNG, written by us.
    Apng,
    /// A video (or GIF) encoded by `ffmpeg`, found on `PATH` before rendering.
    Video {
        /// The `ffmpeg` executable.
        ffmpeg: PathBuf,
        /// ffmpeg's name of the container (`-f`).
        format: &'static str,
    },
}

/// The preview's extensions and ffmpeg's container for each (`None`: an animated PNG).
const PREVIEW_FORMATS: [(&str, Option<&str>); 6] = [
    ("png", None),
    ("gif", Some("gif")),
    ("mp4", Some("mp4")),
    ("webm", Some("webm")),
    ("mkv", Some("matroska")),
    ("mov", Some("mov")),
];

impl Preview {
    /// The preview `path` asks for: an animated PNG for `.png`, else a video through the
    /// `ffmpeg` found on `search_path` (the `PATH` variable).
    fn of(path: &Path, search_path: Option<&std::ffi::OsStr>) -> Result<Self, String> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let Some(&(_, format)) = PREVIEW_FORMATS
            .iter()
            .find(|(e, _)| Some(*e) == ext.as_deref())
        else {
            let names: Vec<String> = PREVIEW_FORMATS
                .iter()
                .map(|(e, _)| format!(".{e}"))
                .collect();
            return Err(format!(
                "{}: --preview must end in one of {} (.png: an animated PNG; the others: a video through ffmpeg)",
                path.display(),
                names.join(", ")
            ));
        };
        let Some(format) = format else {
            return Ok(Preview::Apng);
        };
        // As a shell searches: the first executable file named ffmpeg.
        let candidates: Vec<PathBuf> = search_path
            .into_iter()
            .flat_map(std::env::split_paths)
            .map(|dir| dir.join("ffmpeg"))
            .filter(|p| p.is_file())
            .collect();
        let Some(ffmpeg) = candidates.iter().find(|p| executable(p)).cloned() else {
            return Err(match candidates.first() {
                Some(p) => format!(
                    "{}: a video preview needs ffmpeg, and {} is not executable (chmod +x it, or write an animated PNG with --preview NAME.png)",
                    path.display(),
                    p.display()
                ),
                None => format!(
                    "{}: a video preview needs ffmpeg on PATH, and there is none (install it, or write an animated PNG with --preview NAME.png)",
                    path.display()
                ),
            });
        };
        Ok(Preview::Video { ffmpeg, format })
    }
}

/// Whether `path` may be run (an execute bit is set; elsewhere than Unix, whether it exists).
fn executable(path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::metadata(path).is_ok_and(|m| m.permissions().mode() & 0o111 != 0)
    }
    #[cfg(not(unix))]
    {
        path.is_file()
    }
}

/// The flags of an animation render.
#[derive(clap::Args, Debug)]
#[command(next_help_heading = "Animation")]
pub struct FrameArgs {
    /// Render frames A to B (inclusive) of an animated scene, one image per frame
    /// (NAME_0001.exr, …); frame N shows time N / fps.
    #[arg(long, value_name = "A..B")]
    pub frames: Option<String>,
    /// Frames per second [default: the animation's, else 24].
    #[arg(long, value_name = "F")]
    pub fps: Option<f32>,
    /// The scene's animation from this RON file (for XML scenes, instead of NAME.anim.ron
    /// beside the scene).
    #[arg(long, value_name = "FILE")]
    pub animation: Option<PathBuf>,
    /// Also write the frames as one preview played at the frame rate: an animated PNG (8-bit
    /// sRGB) for .png; a video for .mp4, .webm, .mkv, .mov or .gif, encoded by ffmpeg (which
    /// must be on PATH).
    #[arg(long, value_name = "OUT.png|OUT.mp4")]
    pub preview: Option<PathBuf>,
}

impl FrameArgs {
    /// The flags that mean nothing without `--frames` are refused without it.
    pub fn check_needs_frames(&self) -> Result<(), String> {
        if self.frames.is_some() {
            return Ok(());
        }
        if let Some(f) = self.fps {
            return Err(format!("--fps {f}: needs --frames A..B"));
        }
        if let Some(p) = &self.preview {
            return Err(format!("--preview {}: needs --frames A..B", p.display()));
        }
        if let Some(a) = &self.animation {
            return Err(format!("--animation {}: needs --frames A..B", a.display()));
        }
        Ok(())
    }

    /// Checks the flags against the scene; `None` without `--frames`. `split` says whether
    /// `--chain` or `--crop` was given.
    pub fn plan(
        &self,
        scene: &Path,
        desc: &SceneDesc,
        split: bool,
    ) -> Result<Option<FramePlan>, String> {
        self.check_needs_frames()?;
        let Some(range) = &self.frames else {
            return Ok(None);
        };
        let bad = || {
            format!(
                "--frames {range}: expected A..B, the first and last frame numbers with A <= B (e.g. 1..48)"
            )
        };
        let (a, b) = range.split_once("..").ok_or_else(bad)?;
        let first: u32 = a.trim().parse().map_err(|_| bad())?;
        let last: u32 = b.trim().parse().map_err(|_| bad())?;
        if first > last {
            return Err(bad());
        }
        if last - first == u32::MAX {
            return Err(format!(
                "--frames {range}: {} frames, more than the most a sequence may have ({})",
                u64::from(last - first) + 1,
                u32::MAX
            ));
        }
        if split {
            return Err("--frames cannot be combined with --chain or --crop".into());
        }
        let Some(anim) = &desc.animation else {
            return Err(format!(
                "{}: --frames: the scene has no animation (give it an `animation` section, a sidecar {}, or --animation FILE)",
                scene.display(),
                restir_scene::sidecar_path(scene).display()
            ));
        };
        let fps = match self.fps {
            Some(f) if f.is_finite() && f > 0.0 && f <= 1e6 => f,
            Some(f) => {
                return Err(format!(
                    "--fps {f}: expected a positive number of frames per second (at most 1e6)"
                ));
            }
            None => anim.fps,
        };
        let preview = match &self.preview {
            Some(p) => Some((
                p.clone(),
                Preview::of(p, std::env::var_os("PATH").as_deref())?,
            )),
            None => None,
        };
        Ok(Some(FramePlan {
            first,
            last,
            fps,
            preview,
        }))
    }
}

/// The file of frame `frame` for output `output`: `NAME_0001.EXT`.
pub fn frame_path(output: &Path, frame: u32) -> PathBuf {
    let stem = output
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("frame");
    let ext = output.extension().and_then(|e| e.to_str()).unwrap_or("exr");
    output.with_file_name(format!("{stem}_{frame:04}.{ext}"))
}

/// What one frame took.
#[derive(serde::Serialize, Debug)]
pub struct FrameStats {
    /// Frame number.
    pub frame: u32,
    /// The time it shows, in seconds.
    pub time: f32,
    /// Building the frame's scene.
    pub build_seconds: f64,
    /// Rendering it.
    pub seconds: f64,
    /// Passes rendered.
    pub passes: u32,
    /// Rays traced.
    pub rays: u64,
    /// The image written.
    pub output: String,
}

/// `--stats` of an animation render.
#[derive(serde::Serialize, Debug)]
pub struct SequenceStats {
    /// The scene file.
    pub scene: String,
    /// The estimator's settings.
    pub integrator_settings: String,
    /// What was asked for, what ran and why.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub estimator: Option<crate::stats::EstimatorStats>,
    /// What was rebuilt for each frame.
    pub rebuilt: &'static str,
    /// Frames per second.
    pub fps: f32,
    /// Seed of the render (frame `n` renders with its own streams derived from it).
    pub seed: u64,
    /// Per frame.
    pub frames: Vec<FrameStats>,
    /// Wall seconds of each stage of the estimator's passes, summed over the frames (empty for
    /// the path tracer).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stage_seconds: Vec<crate::stats::StageSeconds>,
}

/// Renders the frames of `plan`: per frame, the scene at its time, rendered with `job`'s passes
/// or time limit by one estimator made from `options` for the first frame and told of each
/// next frame's motion ([`FrameSequence`]: with temporal reuse, the ReSTIR estimators carry
/// their reservoirs across frames), and the image at [`frame_path`]. `progress` gets `(frame
/// index, frames, passes of this frame)`. Stops after the current frame when `cancel` is set;
/// returns the statistics and whether it was stopped.
#[allow(clippy::too_many_arguments)]
pub fn render_frames(
    scene_path: &Path,
    desc: &SceneDesc,
    options: &IntegratorOptions,
    job: &RenderJob,
    output: &Path,
    plan: &FramePlan,
    cancel: &AtomicBool,
    progress: &mut dyn FnMut(u32, u32, u32),
) -> Result<(SequenceStats, bool), String> {
    let count = plan.last - plan.first + 1;
    let mut sequence = FrameSequence::new(desc, scene_path, plan.fps)
        .ok_or_else(|| format!("{}: the scene has no animation", scene_path.display()))?;
    let mut frames = Vec::new();
    let mut preview = plan
        .preview
        .as_ref()
        .map(|(p, how)| crate::preview::PreviewWriter::new(p, how, plan.fps));
    let mut integrator: Option<Box<dyn Integrator>> = None;
    let mut stopped = false;
    for (i, frame) in (plan.first..=plan.last).enumerate() {
        let build = Instant::now();
        let scene = Arc::new(sequence.build(frame).map_err(|e| e.to_string())?);
        let build_seconds = build.elapsed().as_secs_f64();
        let estimator = match &integrator {
            Some(e) => e,
            None => integrator.insert(
                make_integrator(&scene, &desc.integrator, options)
                    .map_err(|e| e.to_string())?
                    .integrator,
            ),
        };
        sequence.enter(estimator.as_ref(), scene.clone(), frame);
        let frame_job = RenderJob {
            seed: FrameSequence::seed(job.seed, frame),
            ..job.clone()
        };
        let out = render(
            &scene,
            estimator.as_ref(),
            &frame_job,
            cancel,
            &mut |passes, _| progress(i as u32, count, passes),
        );
        let path = frame_path(output, frame);
        out.image.write(&path).map_err(|e| e.to_string())?;
        if let Some(p) = &mut preview {
            p.push(&out.image)?;
        }
        frames.push(FrameStats {
            frame,
            time: sequence.time(frame),
            build_seconds,
            seconds: out.seconds,
            passes: out.passes,
            rays: out.rays,
            output: path.display().to_string(),
        });
        if cancel.load(Ordering::SeqCst) {
            stopped = true;
            break;
        }
    }
    if let Some(p) = preview {
        p.finish()?;
    }
    Ok((
        SequenceStats {
            scene: scene_path.display().to_string(),
            stage_seconds: integrator
                .as_ref()
                .map_or(Vec::new(), |e| e.stage_seconds())
                .into_iter()
                .map(|(stage, seconds)| crate::stats::StageSeconds { stage, seconds })
                .collect(),
            estimator: integrator
                .as_ref()
                .map(|e| (&EstimatorReport::of(e.as_ref())).into()),
            integrator_settings: integrator.map(|e| e.describe()).unwrap_or_default(),
            rebuilt: FRAME_REBUILDS,
            fps: plan.fps,
            seed: job.seed,
            frames,
        },
        stopped,
    ))
}

/// The command's side of [`render_frames`]: a progress bar (frame and pass), the statistics
/// file and the summary. Returns whether an interrupt stopped the sequence.
#[allow(clippy::too_many_arguments)]
pub fn run(
    scene_path: &Path,
    desc: &SceneDesc,
    options: &IntegratorOptions,
    job: &RenderJob,
    plan: &FramePlan,
    cancel: &AtomicBool,
    quiet: bool,
    stats: Option<&Path>,
) -> Result<bool, String> {
    use std::io::IsTerminal;
    let output = job
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from("frame.exr"));
    let count = plan.last - plan.first + 1;
    let by_passes = job.spp != u32::MAX;
    let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
        let len = if by_passes {
            u64::from(count) * u64::from(job.spp)
        } else {
            u64::from(count)
        };
        let b = indicatif::ProgressBar::new(len);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {msg}, {elapsed_precise} elapsed, ETA {eta_precise}",
            )
            .expect("valid template"),
        );
        b
    });
    let start = Instant::now();
    let (stats_out, stopped) = render_frames(
        scene_path,
        desc,
        options,
        job,
        &output,
        plan,
        cancel,
        &mut |i, n, passes| {
            if let Some(b) = &bar {
                let done = if by_passes {
                    u64::from(i) * u64::from(job.spp) + u64::from(passes)
                } else {
                    u64::from(i)
                };
                b.set_position(done);
                let of = if by_passes {
                    format!("/{}", job.spp)
                } else {
                    String::new()
                };
                b.set_message(format!(
                    "frame {} ({}/{n}), pass {passes}{of}",
                    plan.first + i,
                    i + 1
                ));
            }
        },
    )?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if let Some(path) = stats {
        let json = serde_json::to_string_pretty(&stats_out).map_err(|e| e.to_string())?;
        restir_image::write_file_atomically(path, (json + "\n").as_bytes())
            .map_err(|e| e.to_string())?;
    }
    let written = stats_out.frames.len();
    if stopped {
        crate::say::say_err!(
            "interrupted after {written} of {count} frames: wrote the frames rendered -> {}",
            frame_path(&output, plan.first).display()
        );
    }
    if !quiet {
        let passes: u32 = stats_out.frames.iter().map(|f| f.passes).sum();
        crate::say::say!(
            "{} [{}]: {written} frames ({} to {}) at {} fps, {passes} passes in {:.2} s -> {} …{}",
            stats_out.integrator_settings,
            stats_out.estimator.as_ref().map_or("", |e| e.why.as_str()),
            plan.first,
            plan.first + written.saturating_sub(1) as u32,
            plan.fps,
            start.elapsed().as_secs_f64(),
            frame_path(&output, plan.first).display(),
            match &plan.preview {
                Some((p, _)) => format!(", preview {}", p.display()),
                None => String::new(),
            }
        );
    }
    Ok(stopped)
}
