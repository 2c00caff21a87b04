//! Outputs of a suite run: CSV, plots, crop strips, the Markdown report and the marked section of
//! another Markdown file.

use std::fmt::Write as _;
use std::path::{Component, Path, PathBuf};

use glam::Vec3;
use restir_image::Image;

use crate::plot::{FrameSeries, Series, frame_plot, relmse_plot};
use crate::{BenchError, BenchResults, RunRecord, Strip, SuiteScene};

/// Start marker of the generated section in a Markdown file.
pub const BEGIN_MARKER: &str = "<!-- restir bench results begin -->";
/// End marker of the generated section.
pub const END_MARKER: &str = "<!-- restir bench results end -->";

/// Statistics over seeds of one (scene, configuration, budget).
#[derive(Clone, Debug)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Configuration label.
    pub label: String,
    /// Budget in seconds.
    pub budget: f64,
    /// Runs (seeds).
    pub runs: usize,
    /// Median render seconds (of a sequence: per frame).
    pub seconds: f64,
    /// Median CPU seconds (of a sequence: per frame).
    pub cpu_seconds: f64,
    /// Median passes.
    pub passes: f64,
    /// Median Mrays/s.
    pub mrays: f64,
    /// Median relMSE.
    pub relmse: f64,
    /// Smallest relMSE.
    pub relmse_min: f64,
    /// Largest relMSE.
    pub relmse_max: f64,
    /// Median MSE.
    pub mse: f64,
    /// Median MAPE.
    pub mape: f64,
    /// Median mean FLIP.
    pub flip: f64,
    /// Median mean ratio.
    pub mean_ratio: f64,
    /// Non-finite pixels over all runs.
    pub nonfinite: usize,
    /// Largest peak resident memory, MiB.
    pub peak_rss_mib: f64,
    /// Median flicker of a sequence (NaN for a still scene).
    pub flicker: f64,
    /// Median over runs of `1 / (relMSE · CPU seconds)` (of a sequence: mean relMSE over its
    /// frames, CPU seconds per frame).
    pub efficiency: f64,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.retain(|x| !x.is_nan());
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The mean of `values`, NaN for none.
fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 { f64::NAN } else { sum / n as f64 }
}

/// The records with each sequence (the frames of one scene, configuration, budget and seed)
/// folded into one record, in order: the mean over its frames of the per-frame relMSE, MSE,
/// MAPE, FLIP, mean ratio, seconds, CPU seconds, passes and rays; the mean flicker over its
/// frames after the first; non-finite pixels summed, the largest peak memory; `frame` `None`.
/// Records of still renders pass unchanged.
pub fn sequence_runs(records: &[RunRecord]) -> Vec<RunRecord> {
    let mut out: Vec<RunRecord> = Vec::new();
    let mut group: Vec<&RunRecord> = Vec::new();
    let same = |a: &RunRecord, b: &RunRecord| {
        a.scene == b.scene && a.label == b.label && a.budget == b.budget && a.seed == b.seed
    };
    let fold = |group: &[&RunRecord]| -> RunRecord {
        let m = |f: fn(&RunRecord) -> f64| mean(group.iter().map(|r| f(r)));
        RunRecord {
            seconds: m(|r| r.seconds),
            cpu_seconds: m(|r| r.cpu_seconds),
            passes: m(|r| f64::from(r.passes)).round() as u32,
            rays: m(|r| r.rays as f64).round() as u64,
            relmse: m(|r| r.relmse),
            mse: m(|r| r.mse),
            mape: m(|r| r.mape),
            flip: m(|r| r.flip),
            mean_ratio: m(|r| r.mean_ratio),
            nonfinite: group.iter().map(|r| r.nonfinite).sum(),
            rss_before_mib: group
                .iter()
                .map(|r| r.rss_before_mib)
                .fold(f64::NAN, f64::min),
            peak_rss_mib: group
                .iter()
                .map(|r| r.peak_rss_mib)
                .fold(f64::NAN, f64::max),
            frame: None,
            flicker: mean(group.iter().map(|r| r.flicker).filter(|f| !f.is_nan())),
            ..group[0].clone()
        }
    };
    for r in records {
        if r.frame.is_none() {
            if !group.is_empty() {
                out.push(fold(&group));
                group.clear();
            }
            out.push(r.clone());
            continue;
        }
        if group.last().is_some_and(|g| !same(g, r)) {
            out.push(fold(&group));
            group.clear();
        }
        group.push(r);
    }
    if !group.is_empty() {
        out.push(fold(&group));
    }
    out
}

/// The suite's entry of scene `name`.
fn entry<'a>(results: &'a BenchResults, name: &str) -> Option<&'a SuiteScene> {
    results
        .suite
        .scenes
        .iter()
        .find(|e| e.display_name() == name)
}

/// Summaries in suite order: scenes, then configurations, then budgets ascending; a sequence's
/// runs folded first ([`sequence_runs`]).
pub fn summarize(results: &BenchResults) -> Vec<Summary> {
    let mut budgets = results.suite.budgets.clone();
    budgets.sort_by(|a, b| a.total_cmp(b));
    budgets.dedup();
    let all = sequence_runs(&results.records);
    let mut out = Vec::new();
    for r in &results.references {
        for c in &results.suite.integrators {
            for &b in &budgets {
                let runs: Vec<&RunRecord> = all
                    .iter()
                    .filter(|x| x.scene == r.scene && x.label == c.label && x.budget == b)
                    .collect();
                if runs.is_empty() {
                    continue;
                }
                let col = |f: fn(&RunRecord) -> f64| median(runs.iter().map(|x| f(x)).collect());
                out.push(Summary {
                    scene: r.scene.clone(),
                    label: c.label.clone(),
                    budget: b,
                    runs: runs.len(),
                    seconds: col(|x| x.seconds),
                    cpu_seconds: col(|x| x.cpu_seconds),
                    passes: col(|x| x.passes as f64),
                    mrays: col(|x| x.mrays_per_second()),
                    relmse: col(|x| x.relmse),
                    relmse_min: runs.iter().map(|x| x.relmse).fold(f64::INFINITY, f64::min),
                    relmse_max: runs.iter().map(|x| x.relmse).fold(0.0, f64::max),
                    mse: col(|x| x.mse),
                    mape: col(|x| x.mape),
                    flip: col(|x| x.flip),
                    mean_ratio: col(|x| x.mean_ratio),
                    nonfinite: runs.iter().map(|x| x.nonfinite).sum(),
                    peak_rss_mib: runs.iter().map(|x| x.peak_rss_mib).fold(0.0, f64::max),
                    flicker: col(|x| x.flicker),
                    efficiency: col(|x| 1.0 / (x.relmse * x.cpu_seconds)),
                });
            }
        }
    }
    out
}

/// The time a configuration needs to reach a target relMSE.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeToError {
    /// Seconds.
    pub seconds: f64,
    /// Whether the target lies outside the measured errors, so that the time was extrapolated
    /// from the nearest measurement assuming relMSE ∝ 1/time.
    pub extrapolated: bool,
}

/// The time at which the curve `points` = `(seconds, relMSE)` (ordered by budget) first reaches
/// `target`, interpolating linearly in log-log between measurements and extrapolating with slope
/// −1 outside them; `None` without usable points.
pub fn time_to_error(points: &[(f64, f64)], target: f64) -> Option<TimeToError> {
    let ok = |v: f64| v.is_finite() && v > 0.0;
    let pts: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|&(t, e)| ok(t) && ok(e))
        .collect();
    if pts.is_empty() || !ok(target) {
        return None;
    }
    let (t0, e0) = pts[0];
    if e0 <= target {
        return Some(TimeToError {
            seconds: t0 * e0 / target,
            extrapolated: e0 < target,
        });
    }
    for w in pts.windows(2) {
        let ((ta, ea), (tb, eb)) = (w[0], w[1]);
        if ea > target && eb <= target {
            let f = (target.ln() - ea.ln()) / (eb.ln() - ea.ln());
            return Some(TimeToError {
                seconds: (ta.ln() + f * (tb.ln() - ta.ln())).exp(),
                extrapolated: false,
            });
        }
    }
    let (tl, el) = pts[pts.len() - 1];
    Some(TimeToError {
        seconds: tl * el / target,
        extrapolated: true,
    })
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The CSV header: one row per render, a sequence's frames one row each (`frame` empty for a
/// still render; `flicker` empty for it and for a sequence's first frame).
pub const CSV_HEADER: &str = "scene,label,integrator_settings,width,height,budget_s,seed,seconds,passes,rays,mrays_per_s,relmse,mse,mape,flip,mean_ratio,nonfinite_pixels,rss_before_mib,peak_rss_mib,reference_noise_relmse,frame,flicker,cpu_seconds";

fn csv(results: &BenchResults) -> String {
    let mut s = String::from(CSV_HEADER);
    s.push('\n');
    for r in &results.records {
        let noise = reference_noise(results, &r.scene).map_or(String::new(), |n| format!("{n:e}"));
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{:.4},{},{},{:.3},{:e},{:e},{:e},{:.6},{:.6},{},{:.1},{:.1},{},{},{},{:.4}",
            csv_field(&r.scene),
            csv_field(&r.label),
            csv_field(&r.describe),
            r.width,
            r.height,
            r.budget,
            r.seed,
            r.seconds,
            r.passes,
            r.rays,
            r.mrays_per_second(),
            r.relmse,
            r.mse,
            r.mape,
            r.flip,
            r.mean_ratio,
            r.nonfinite,
            r.rss_before_mib,
            r.peak_rss_mib,
            noise,
            r.frame.map_or(String::new(), |f| f.to_string()),
            if r.flicker.is_nan() {
                String::new()
            } else {
                format!("{:e}", r.flicker)
            },
            r.cpu_seconds
        );
    }
    s
}

fn reference_noise(results: &BenchResults, scene: &str) -> Option<f64> {
    results
        .references
        .iter()
        .find(|r| r.scene == scene)
        .and_then(|r| r.noise_relmse)
}

/// Pixels of gap between crops in a strip.
pub const STRIP_GAP: u32 = 4;

/// Each crop's pixels are drawn as `k × k` blocks, `k` making the crop about 128 pixels tall.
fn strip_scale(strip: &Strip) -> u32 {
    let (_, _, w, h) = strip.crop;
    (128 / w.max(h).max(1)).clamp(1, 8)
}

fn strip_image(strip: &Strip) -> Image {
    let k = strip_scale(strip);
    let (_, _, cw, ch) = strip.crop;
    let n = strip.crops.len() as u32;
    let width = n * cw * k + n.saturating_sub(1) * STRIP_GAP;
    let mut out = Image::new(width, ch * k);
    for p in &mut out.pixels {
        *p = Vec3::splat(1.0);
    }
    for (i, c) in strip.crops.iter().enumerate() {
        let x0 = i as u32 * (cw * k + STRIP_GAP);
        for y in 0..ch * k {
            for x in 0..cw * k {
                out.pixels[(y * width + x0 + x) as usize] = c.get(x / k, y / k);
            }
        }
    }
    out
}

pub(crate) fn utc(unix: u64) -> String {
    // Days since 1970-01-01 to a proleptic Gregorian date (era-based civil calendar arithmetic).
    let days = (unix / 86_400) as i64;
    let secs = unix % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02} {:02}:{:02} UTC",
        secs / 3600,
        secs / 60 % 60
    )
}

fn sci(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2e}")
    } else {
        "–".into()
    }
}

/// The report's Markdown. `h` is the top heading level (`#` for report.md, `##` inside another
/// document) and `link` prefixes the file names of the plots and strips.
pub fn report_markdown(results: &BenchResults, h: &str, link: &str) -> String {
    let summaries = summarize(results);
    let m = &results.machine;
    let mut s = String::new();
    let _ = writeln!(s, "{h} `restir bench` results\n");
    let _ = writeln!(
        s,
        "Generated by `restir bench` on {} in {:.1} min. Command:\n\n```\n{}\n```\n",
        utc(results.started_unix),
        results.wall_seconds / 60.0,
        results.command_line
    );
    let _ = writeln!(
        s,
        "Machine: {}, {} logical cores, renders on {} threads; load average (1, 5, 15 min) {} at \
         the start and {} at the end (the machine is shared: times include other people's load).\n",
        m.cpu, m.cores, m.threads, m.load_start, m.load_end
    );
    let budgets: Vec<String> = results
        .suite
        .budgets
        .iter()
        .map(|b| b.to_string())
        .collect();
    let _ = writeln!(
        s,
        "Budgets {} s, {} seed(s) each; every render runs whole passes until its budget is spent \
         (`spp = u32::MAX`, `time_limit = budget`), so its time is at least the budget. \
         Data: [`results.csv`]({link}results.csv).\n",
        budgets.join(", "),
        results.suite.seeds
    );
    let _ = writeln!(
        s,
        "**Definitions.** relMSE is the mean over pixels and channels of (x − r)² / (r² + 0.01), \
         MAPE the mean of |x − r| / (|r| + 0.01), FLIP the mean LDR-FLIP error (Andersson et al. \
         2020, NVIDIA's implementation) of the images clamped to [0, 1] and sRGB-encoded to 8 \
         bits. \
         Curves are medians over seeds; bars span the smallest to largest relMSE, dots are single \
         runs. *Equal-time ratio*: the path tracer's median relMSE over the configuration's, at \
         the largest budget (> 1: the configuration is better). *Time to path's error*: the time \
         the configuration needs to reach the path tracer's median relMSE at the largest budget, \
         interpolated linearly in log-log between budgets (\"≈\": outside the measured range, \
         extrapolated assuming relMSE ∝ 1/time); *speed-up* is the path tracer's time over it. \
         The reference's own relMSE, estimated as relMSE(half A, half B)/4 from two independent \
         halves, adds to every measured relMSE in expectation: errors within a few times it are \
         not meaningful. [`report.html`]({link}report.html) shows every image of seed 0 with a \
         split view, zoom, pixel values, exposure and error maps.\n"
    );
    let _ = writeln!(
        s,
        "Peak memory is the process's `VmHWM` during each render ({}); it includes the scene, \
         BVH and reference, not only the estimator's buffers.\n",
        if m.peak_reset {
            "reset before every render through /proc/self/clear_refs"
        } else {
            "could not be reset: the peak since the process started"
        }
    );
    if results.suite.scenes.iter().any(|e| e.frames.is_some()) {
        let _ = writeln!(
            s,
            "**Sequences.** A scene with frames is rendered by each configuration frame after \
             frame with one estimator, whose history (temporal reuse) carries across frames, \
             every frame with the budget: equal time per frame. Every frame has its own \
             path-traced reference. Its relMSE, MSE, MAPE, FLIP, mean ratio, time, passes and \
             Mrays/s are the means over the frames (times per frame), then medians over seeds. \
             *Flicker* is the mean over consecutive frames of \
             ((I_f − R_f) − (I_f−1 − R_f−1))² / (max(R_f, R_f−1)² + 0.01): independent noise \
             per frame gives about twice the relMSE, errors that persist across frames less. \
             *Efficiency* is 1 / (mean relMSE × CPU seconds per frame), CPU time being the \
             process's user + system time during the frames' renders; both are given relative to \
             the scene's first configuration. Crops and images are of the last frame.\n"
        );
    }

    let path_label = results
        .suite
        .integrators
        .iter()
        .find(|c| c.integrator == "path")
        .map(|c| c.label.clone());
    let top_budget = results
        .suite
        .budgets
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);

    for (r, strip) in results.references.iter().zip(&results.strips) {
        let rows: Vec<&Summary> = summaries.iter().filter(|x| x.scene == r.scene).collect();
        let (w, h_px) = results
            .records
            .iter()
            .find(|x| x.scene == r.scene)
            .map_or((0, 0), |x| (x.width, x.height));
        let frames = entry(results, &r.scene).and_then(|e| e.frames);
        match frames {
            Some((a, b)) => {
                let _ = writeln!(s, "{h}# {} ({w}×{h_px}, frames {a} to {b})\n", r.scene);
            }
            None => {
                let _ = writeln!(s, "{h}# {} ({w}×{h_px})\n", r.scene);
            }
        }
        match (r.spp, r.noise_relmse) {
            (Some(spp), Some(noise)) => {
                let _ = writeln!(
                    s,
                    "Reference: path tracer, {spp} passes{} ({}); its own relMSE ≈ {}{}.\n",
                    if frames.is_some() { " per frame" } else { "" },
                    if r.reused {
                        "cached".to_string()
                    } else {
                        format!("rendered in {:.0} s", r.seconds)
                    },
                    sci(noise),
                    if frames.is_some() {
                        " (mean over the frames)"
                    } else {
                        ""
                    }
                );
            }
            _ => {
                let _ = writeln!(
                    s,
                    "Reference: `{}` (given; its own noise is not known).\n",
                    r.path.display()
                );
            }
        }
        let _ = writeln!(
            s,
            "![relMSE against time, {}]({link}relmse-{}.svg)\n",
            r.scene, r.scene
        );
        if frames.is_some() {
            let _ = writeln!(
                s,
                "![relMSE of every frame, {}]({link}frames-{}.svg)\n\nrelMSE of each frame \
                 (median over seeds) at the {} s budget.\n",
                r.scene, r.scene, strip.budget
            );
        }
        let (cx, cy, cw, ch) = strip.crop;
        let k = strip_scale(strip);
        let names = &strip.labels;
        let _ = writeln!(
            s,
            "![crops, {}]({link}strip-{}.png)\n\nCrops, left to right: {}. Pixels ({cx}, {cy}) to \
             ({}, {}), each pixel drawn as a {k}×{k} block, {STRIP_GAP}-pixel white gaps; renders \
             of seed 0 at the {} s budget; clamped sRGB, no tone mapping.\n",
            r.scene,
            r.scene,
            names.join(", "),
            cx + cw,
            cy + ch,
            strip.budget
        );
        let _ = writeln!(
            s,
            "| configuration | budget (s) | median time (s) | passes | Mrays/s | relMSE median [min, max] | MSE | MAPE | FLIP | mean ratio | non-finite | peak MiB |\n|---|---|---|---|---|---|---|---|---|---|---|---|"
        );
        for x in &rows {
            let _ = writeln!(
                s,
                "| {} | {} | {:.2} | {:.0} | {:.2} | {} [{}, {}] | {} | {:.4} | {:.4} | {:.4} | {} | {:.0} |",
                x.label,
                x.budget,
                x.seconds,
                x.passes,
                x.mrays,
                sci(x.relmse),
                sci(x.relmse_min),
                sci(x.relmse_max),
                sci(x.mse),
                x.mape,
                x.flip,
                x.mean_ratio,
                x.nonfinite,
                x.peak_rss_mib
            );
        }
        s.push('\n');
        if frames.is_some() {
            animation_table(&mut s, &rows);
        }
        let Some(path_label) = &path_label else {
            continue;
        };
        let curve = |label: &str| -> Vec<(f64, f64)> {
            rows.iter()
                .filter(|x| x.label == label)
                .map(|x| (x.seconds, x.relmse))
                .collect()
        };
        let Some(path_top) = rows
            .iter()
            .find(|x| &x.label == path_label && x.budget == top_budget)
        else {
            continue;
        };
        let target = path_top.relmse;
        let _ = writeln!(
            s,
            "Against `{path_label}` at {top_budget} s: median relMSE {} in {:.2} s{}.\n",
            sci(target),
            path_top.seconds,
            match r.noise_relmse {
                Some(n) if n * 3.0 > target => format!(
                    " — only {:.1}× the reference's own relMSE, so these ratios are not reliable",
                    target / n
                ),
                _ => String::new(),
            }
        );
        let _ = writeln!(
            s,
            "| configuration | relMSE at {top_budget} s | equal-time ratio | time to path's error (s) | speed-up |\n|---|---|---|---|---|"
        );
        for c in &results.suite.integrators {
            let Some(top) = rows
                .iter()
                .find(|x| x.label == c.label && x.budget == top_budget)
            else {
                continue;
            };
            let tte = if &c.label == path_label {
                Some(crate::TimeToError {
                    seconds: path_top.seconds,
                    extrapolated: false,
                })
            } else {
                time_to_error(&curve(&c.label), target)
            };
            let (t, speed) = match tte {
                Some(t) => {
                    let mark = if t.extrapolated { "≈ " } else { "" };
                    (
                        format!("{mark}{:.3}", t.seconds),
                        format!("{mark}{:.2}×", path_top.seconds / t.seconds),
                    )
                }
                None => ("–".into(), "–".into()),
            };
            let _ = writeln!(
                s,
                "| {} | {} | {:.2}× | {t} | {speed} |",
                c.label,
                sci(top.relmse),
                target / top.relmse
            );
        }
        s.push('\n');
    }
    s
}

/// A sequence's table: per budget, each configuration's mean relMSE, CPU seconds per frame,
/// efficiency and flicker, the last two relative to the first configuration at that budget.
fn animation_table(s: &mut String, rows: &[&Summary]) {
    let Some(first) = rows.first().map(|x| x.label.clone()) else {
        return;
    };
    let _ = writeln!(
        s,
        "| configuration | budget (s) | mean relMSE | CPU s per frame | efficiency × {first} | \
         flicker | flicker × {first} |\n|---|---|---|---|---|---|---|"
    );
    let mut budgets: Vec<f64> = rows.iter().map(|x| x.budget).collect();
    budgets.sort_by(|a, b| a.total_cmp(b));
    budgets.dedup();
    for b in budgets {
        let base = rows.iter().find(|x| x.budget == b && x.label == first);
        for x in rows.iter().filter(|x| x.budget == b) {
            let ratio = |v: f64, of: fn(&Summary) -> f64| {
                base.map_or("–".to_string(), |base| format!("{:.2}", v / of(base)))
            };
            let _ = writeln!(
                s,
                "| {} | {b} | {} | {:.3} | {} | {} | {} |",
                x.label,
                sci(x.relmse),
                x.cpu_seconds,
                ratio(x.efficiency, |y| y.efficiency),
                sci(x.flicker),
                ratio(x.flicker, |y| y.flicker),
            );
        }
    }
    s.push('\n');
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<(), BenchError> {
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
        let sequence = entry(results, &r.scene).is_some_and(|e| e.frames.is_some());
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
    write_file(
        &out.join("report.html"),
        crate::html::bench_page(results)?.as_bytes(),
    )
}

/// Per configuration, the median over seeds of each frame's relMSE of sequence `scene` at
/// `budget`.
fn frame_series(results: &BenchResults, scene: &str, budget: f64) -> Vec<FrameSeries> {
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

/// `to` relative to the directory `from` (both made absolute first).
fn relative(from: &Path, to: &Path) -> PathBuf {
    let abs = |p: &Path| {
        p.canonicalize().unwrap_or_else(|_| {
            std::env::current_dir()
                .map(|d| d.join(p))
                .unwrap_or_else(|_| p.to_path_buf())
        })
    };
    let (from, to) = (abs(from), abs(to));
    let f: Vec<Component> = from.components().collect();
    let t: Vec<Component> = to.components().collect();
    let common = f.iter().zip(&t).take_while(|(a, b)| a == b).count();
    let mut out = PathBuf::new();
    for _ in common..f.len() {
        out.push("..");
    }
    for c in &t[common..] {
        out.push(c.as_os_str());
    }
    out
}

/// Positions just after the begin marker and at the end marker.
fn find_markers(text: &str, doc: &Path) -> Result<(usize, usize), BenchError> {
    let missing = |begin| BenchError::Marker {
        doc: doc.to_path_buf(),
        begin,
    };
    let begin = text.find(BEGIN_MARKER).ok_or_else(|| missing(true))?;
    let after_begin = begin + BEGIN_MARKER.len();
    let end = text[after_begin..]
        .find(END_MARKER)
        .map(|i| after_begin + i)
        .ok_or_else(|| missing(false))?;
    Ok((after_begin, end))
}

/// Checks that `doc` can be read and has both markers (before spending time on a run).
pub fn check_doc(doc: &Path) -> Result<(), BenchError> {
    let text = std::fs::read_to_string(doc).map_err(BenchError::io(doc, "cannot read: "))?;
    find_markers(&text, doc).map(|_| ())
}

/// Replaces the text between [`BEGIN_MARKER`] and [`END_MARKER`] in the Markdown file `doc` with
/// the report (links relative to the document); the rest of the file is kept as it is.
pub fn update_doc(results: &BenchResults, out: &Path, doc: &Path) -> Result<(), BenchError> {
    let text = std::fs::read_to_string(doc).map_err(BenchError::io(doc, "cannot read: "))?;
    let (after_begin, end) = find_markers(&text, doc)?;
    let doc_dir = doc
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut link = relative(doc_dir, out).to_string_lossy().replace('\\', "/");
    if !link.is_empty() && !link.ends_with('/') {
        link.push('/');
    }
    let section = report_markdown(results, "##", &link);
    let new = format!(
        "{}\n<!-- Generated by `restir bench --update-doc`; edits here are overwritten. -->\n\n{}{}",
        &text[..after_begin],
        section,
        &text[end..]
    );
    write_file(doc, new.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_in_log_log() {
        let pts = [(1.0, 1e-2), (4.0, 2.5e-3)];
        let t = time_to_error(&pts, 5e-3).unwrap();
        assert!(!t.extrapolated);
        assert!((t.seconds - 2.0).abs() < 1e-9, "{t:?}");
        let t = time_to_error(&pts, 1e-3).unwrap();
        assert!(t.extrapolated && (t.seconds - 10.0).abs() < 1e-9);
        let t = time_to_error(&pts, 2e-2).unwrap();
        assert!(t.extrapolated && (t.seconds - 0.5).abs() < 1e-9);
        assert!(time_to_error(&[], 1.0).is_none());
    }

    #[test]
    fn medians_and_dates() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(utc(0), "1970-01-01 00:00 UTC");
        assert_eq!(utc(951_782_400 + 3600), "2000-02-29 01:00 UTC");
    }

    #[test]
    fn relative_links() {
        let base = std::env::temp_dir();
        assert_eq!(
            relative(&base.join("docs"), &base.join("docs/bench")),
            PathBuf::from("bench")
        );
        assert_eq!(
            relative(&base.join("docs"), &base.join("out")),
            PathBuf::from("../out")
        );
        assert_eq!(csv_field("a,b"), "\"a,b\"");
    }
}
