//! Writing a run's files: the CSV, the plots, the strips, `report.md` and `report.html`.

use std::path::Path;

use crate::analysis::{median, sequence_runs, suite_entry, summarize};
use crate::error::BenchError;
use crate::records::BenchResults;
use crate::report::csv::csv;
use crate::report::html::bench_page;
use crate::report::markdown::report_markdown;
use crate::report::plot::{FrameSeries, Series, frame_plot, relmse_plot};
use crate::report::strip::strip_image;

pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), BenchError> {
    std::fs::write(path, bytes).map_err(BenchError::io(path, ""))
}

/// Writes `results.csv`, `relmse-<scene>.svg`, `strip-<scene>.png`, for a sequence
/// `frames-<scene>.svg` (relMSE of every frame), `report.md` and the interactive `report.html`
/// ([`crate::html`]) into `out`.
pub fn write_outputs(results: &BenchResults, out: &Path) -> Result<(), BenchError> {
    std::fs::create_dir_all(out).map_err(BenchError::io(out, "cannot create directory: "))?;
    write_file(&out.join("results.csv"), csv(results).as_bytes())?;
    let summaries = summarize(results);
    let runs = sequence_runs(&results.records);
    for r in &results.references {
        let series: Vec<Series> = results
            .suite
            .integrators
            .iter()
            .map(|c| Series {
                label: c.label.clone(),
                medians: summaries
                    .iter()
                    .filter(|x| x.scene == r.scene && x.label == c.label)
                    .map(|x| (x.seconds, x.relmse, x.relmse_min, x.relmse_max))
                    .collect(),
                points: runs
                    .iter()
                    .filter(|x| x.scene == r.scene && x.label == c.label)
                    .map(|x| (x.seconds, x.relmse))
                    .collect(),
            })
            .collect();
        let series: Vec<Series> = series
            .into_iter()
            .filter(|s| !s.points.is_empty())
            .collect();
        let sequence = suite_entry(results, &r.scene).is_some_and(|e| e.frames.is_some());
        relmse_plot(
            &out.join(format!("relmse-{}.svg", r.scene)),
            &if sequence {
                format!("{}: mean relMSE against render time per frame", r.scene)
            } else {
                format!("{}: relMSE against render time", r.scene)
            },
            &series,
            r.noise_relmse,
        )?;
        if sequence {
            let budget = results
                .strips
                .iter()
                .find(|s| s.scene == r.scene)
                .map_or(f64::NAN, |s| s.budget);
            frame_plot(
                &out.join(format!("frames-{}.svg", r.scene)),
                &format!("{}: relMSE of every frame ({budget} s per frame)", r.scene),
                &frame_series(results, &r.scene, budget),
            )?;
        }
    }
    for strip in &results.strips {
        strip_image(strip).write(&out.join(format!("strip-{}.png", strip.scene)))?;
    }
    write_file(
        &out.join("report.md"),
        report_markdown(results, "#", "").as_bytes(),
    )?;
    write_file(&out.join("report.html"), bench_page(results)?.as_bytes())
}

/// Per configuration, the median over seeds of each frame's relMSE of sequence `scene` at
/// `budget`.
pub(crate) fn frame_series(results: &BenchResults, scene: &str, budget: f64) -> Vec<FrameSeries> {
    results
        .suite
        .integrators
        .iter()
        .map(|c| {
            let mut frames: Vec<u32> = results
                .records
                .iter()
                .filter(|x| x.scene == scene && x.label == c.label && x.budget == budget)
                .filter_map(|x| x.frame)
                .collect();
            frames.sort_unstable();
            frames.dedup();
            FrameSeries {
                label: c.label.clone(),
                points: frames
                    .into_iter()
                    .map(|f| {
                        let per_seed = results
                            .records
                            .iter()
                            .filter(|x| {
                                x.scene == scene
                                    && x.label == c.label
                                    && x.budget == budget
                                    && x.frame == Some(f)
                            })
                            .map(|x| x.relmse)
                            .collect();
                        (f, median(per_seed))
                    })
                    .collect(),
            }
        })
        .filter(|s| !s.points.is_empty())
        .collect()
}
