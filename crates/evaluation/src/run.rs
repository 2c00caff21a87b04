//! Running a suite: every (scene, configuration, budget, seed) rendered and measured against its
//! reference, a sequence frame after frame with one estimator.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use restir_image::Image;
use restir_integrators::FrameSequence;
use restir_integrators::film::Reconstruction;
use restir_integrators::{Integrator, RenderJob, RenderOutput, render};
use restir_scene::Scene;

use crate::analysis::flicker;
use crate::error::BenchError;
use crate::load::{LoadedSuiteScene, build_integrator, load_suite_scene, render_once};
use crate::measure::{
    cpu_model, load_average, mib, process_cpu_seconds, reset_peak_rss, vm_hwm_kib,
};
use crate::metrics::evaluate;
use crate::records::{
    BenchResults, Machine, Progress, ReferenceInfo, RunOptions, RunRecord, SceneImages, Strip,
};
use crate::reference::{References, reference_for};
use crate::suite::{Clock, IntegratorConfig, Suite, SuiteScene};

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

/// One render measured: what the record of a still image or a sequence's frame holds besides
/// its scene, configuration, budget, seed and frame.
struct Measured {
    out: RenderOutput,
    cpu_seconds: f64,
    before: Option<u64>,
    after: Option<u64>,
}

/// Renders `job` with the peak memory reset before and the CPU time around it; with
/// `cpu_budget`, no further pass starts once the process has spent that many CPU seconds on it.
fn measured_render(
    scene: &Scene,
    integrator: &dyn Integrator,
    job: &RenderJob,
    cpu_budget: Option<f64>,
) -> Measured {
    reset_peak_rss();
    let before = vm_hwm_kib();
    let cpu = process_cpu_seconds();
    let out = match cpu_budget {
        None => render_once(scene, integrator, job),
        Some(budget) => {
            let spent = AtomicBool::new(false);
            let mut after_pass = |_, _| {
                if process_cpu_seconds() - cpu >= budget {
                    spent.store(true, Ordering::Relaxed);
                }
            };
            render(scene, integrator, job, &spent, &mut after_pass)
        }
    };
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
    (budget, clock): (f64, Clock),
    seed: u64,
    step: &mut dyn FnMut(Option<u32>),
) -> Result<Rendered, BenchError> {
    let job = |seed| RenderJob {
        spp: u32::MAX,
        time_limit: (clock == Clock::Wall).then(|| Duration::from_secs_f64(budget)),
        seed,
        output: None,
        moment: None,
    };
    let cpu_budget = (clock == Clock::Cpu).then_some(budget);
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
                top1_share: e.top1_share,
                nonfinite: e.nonfinite,
                rss_before_mib: mib(m.before),
                peak_rss_mib: mib(m.after),
                frame,
                flicker,
            })
    };
    let Some(mut sequence) = loaded.sequence().filter(|_| loaded.frames.is_some()) else {
        let integrator = integrator.expect("a still scene's integrator is built once");
        step(None);
        let m = measured_render(&loaded.scene, integrator, &job(seed), cpu_budget);
        let mut r = record(&m, &*references.get(0)?, None, f64::NAN)?;
        r.describe = integrator.describe();
        return Ok(Rendered {
            records: vec![r],
            image: m.out.image,
        });
    };
    // A fresh estimator per sequence: its history starts empty at the first frame.
    let estimator = build_integrator(loaded, config, entry)?;
    let mut records = Vec::with_capacity(loaded.view_count());
    // The previous frame's image and reference, for the flicker; each frame's scene is built
    // here and dropped once the next one has entered the sequence.
    let mut prev: Option<(Image, Image)> = None;
    for (i, view) in loaded.views().into_iter().enumerate() {
        let frame = view.expect("a sequence's views are frames");
        step(Some(frame));
        let scene = loaded.frame(view)?;
        sequence.enter(estimator.as_ref(), scene.clone(), frame);
        let m = measured_render(
            &scene,
            estimator.as_ref(),
            &job(FrameSequence::seed(seed, frame)),
            cpu_budget,
        );
        drop(scene);
        let reference = references.get(i)?.into_owned();
        let flicker = prev
            .as_ref()
            .map_or(f64::NAN, |(p, pr)| flicker(&m.out.image, &reference, p, pr));
        let mut r = record(&m, &reference, Some(frame), flicker)?;
        r.describe = estimator.describe();
        records.push(r);
        prev = Some((m.out.image, reference));
    }
    Ok(Rendered {
        records,
        image: prev.expect("a sequence has at least one frame").0,
    })
}

/// Bytes per pixel a scene's renders need besides the largest estimator's own buffers: the
/// film's sums (3 × f64), one pass's image and the output image (3 × f32 each), and six more
/// images of 3 × f32 (a reference's two halves and their average while it renders; the
/// reference, the previous frame and its reference while a frame is compared). Each image kept
/// for the HTML page (seed 0 of every configuration and budget) adds 12.
pub const BYTES_PER_PIXEL: u64 = 24 + 12 + 12 + 6 * 12;

/// Refuses a scene whose renders would need more than `max_gib` GiB: [`BYTES_PER_PIXEL`] and
/// the splatting film's `film_per_pixel`, the largest buffers of the configurations that render
/// it (`largest_buffers` bytes), and the images kept for the page.
fn check_memory(
    name: &str,
    (w, h): (u32, u32),
    film_per_pixel: u64,
    largest_buffers: u64,
    kept_images: u64,
    max_gib: f64,
) -> Result<(), BenchError> {
    let pixels = w as u64 * h as u64;
    let need = pixels
        .saturating_mul(BYTES_PER_PIXEL + film_per_pixel + 12 * kept_images)
        .saturating_add(largest_buffers);
    let per_pixel = need.div_ceil(pixels.max(1));
    if need as f64 / (1u64 << 30) as f64 > max_gib {
        return Err(BenchError::Memory {
            scene: name.to_string(),
            size: (w, h),
            bytes_per_pixel: per_pixel,
            max_gib,
        });
    }
    Ok(())
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
    // A sequence's frames are built one at a time and dropped. Errors name the entry's line in
    // the suite file: a configuration's for its integrator, else the scene's.
    let file = opts.lines.file.as_ref();
    let scene_line = |i: usize| opts.lines.scenes.get(i).copied().flatten();
    let config_line = |i: usize| opts.lines.integrators.get(i).copied().flatten();
    let mut scenes = Vec::new();
    for (si, entry) in suite.scenes.iter().enumerate() {
        let at_scene = |e: BenchError| e.at(file, scene_line(si));
        let max_bytes = opts.max_memory_gib * (1u64 << 30) as f64;
        let loaded =
            load_suite_scene(entry, &opts.suite_dir, Some(max_bytes as u64)).map_err(at_scene)?;
        let (w, h) = loaded.scene.camera.resolution();
        let threads = rayon::current_num_threads();
        let mut largest_buffers = 0u64;
        let mut configs = 0u64;
        for (ci, config) in suite.integrators.iter().enumerate() {
            if !entry.runs(&config.label) {
                continue;
            }
            let integrator = build_integrator(&loaded, config, entry)
                .map_err(|e| e.at(file, config_line(ci)))?;
            largest_buffers = largest_buffers.max(integrator.buffer_bytes(w, h, threads));
            configs += 1;
        }
        let film = Reconstruction::decide(loaded.scene.filter).buffer_bytes_per_pixel() as u64;
        check_memory(
            &loaded.name,
            (w, h),
            film,
            largest_buffers,
            configs * suite.budgets.len() as u64,
            opts.max_memory_gib,
        )
        .map_err(at_scene)?;
        let rect = crop_rect(entry, w, h).map_err(at_scene)?;
        scenes.push((si, entry, loaded, rect));
    }

    let per_config = suite.budgets.len() as u64 * suite.seeds as u64;
    let total: u64 = scenes
        .iter()
        .map(|(_, entry, loaded, _)| {
            let configs = suite.integrators.iter().filter(|c| entry.runs(&c.label));
            let views = loaded.view_count() as u64;
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
    for (si, entry, loaded, rect) in &scenes {
        let at_scene = |e: BenchError| e.at(file, scene_line(*si));
        let mut refs = References {
            still: None,
            frames: Vec::new(),
        };
        let mut info: Option<ReferenceInfo> = None;
        let mut reference: Option<Image> = None;
        for frame in loaded.views() {
            progress(&Progress {
                done,
                total,
                message: match frame {
                    Some(f) => format!("{}: reference of frame {f}", loaded.name),
                    None => format!("{}: reference", loaded.name),
                },
            });
            let scene = loaded.frame(frame).map_err(at_scene)?;
            let (image, i) =
                reference_for(entry, loaded, (frame, &scene), suite, opts).map_err(at_scene)?;
            drop(scene);
            done += 1;
            if frame.is_some() {
                refs.frames.push(i.path.clone());
            }
            reference = Some(image);
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
            *n /= loaded.view_count() as f64;
        }
        references.push(info);
        let reference = reference.expect("a reference");
        if loaded.frames.is_none() {
            refs.still = Some(reference.clone());
        }
        let mut strip_crops: Vec<Option<Image>> = vec![None; suite.integrators.len()];
        let mut renders: Vec<(usize, String, f64, Image)> = Vec::new();
        // A still scene's estimators are built once; a sequence builds one per sequence.
        let integrators = suite
            .integrators
            .iter()
            .map(|c| {
                (entry.runs(&c.label) && loaded.frames.is_none())
                    .then(|| build_integrator(loaded, c, entry))
                    .transpose()
            })
            .collect::<Result<Vec<_>, _>>()
            .map_err(at_scene)?;
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
                        (budget, suite.clock),
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
                    )
                    .map_err(at_scene)?;
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
