//! Running a suite: every (scene, configuration, budget, seed) rendered and measured against its
//! reference, a sequence frame after frame with one estimator.

use std::time::{Duration, Instant};

use restir_image::Image;
use restir_integrators::reuse::motion::FrameSequence;
use restir_integrators::{Integrator, RenderJob, RenderOutput};
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
use crate::suite::{IntegratorConfig, Suite, SuiteScene};

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
