//! What the records say: a sequence's frames folded into one record, statistics over seeds per
//! (scene, configuration, budget), the time to reach an error, and flicker between frames.

use restir_image::Image;

use crate::records::{BenchResults, RunRecord};
use crate::suite::SuiteScene;

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
    /// Median share of the squared error in the top 1 % of pixels.
    pub top1_share: f64,
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

pub(crate) fn median(mut v: Vec<f64>) -> f64 {
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
pub(crate) fn mean(values: impl Iterator<Item = f64>) -> f64 {
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
            top1_share: m(|r| r.top1_share),
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
pub(crate) fn suite_entry<'a>(results: &'a BenchResults, name: &str) -> Option<&'a SuiteScene> {
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
                    top1_share: col(|x| x.top1_share),
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

pub(crate) fn reference_noise(results: &BenchResults, scene: &str) -> Option<f64> {
    results
        .references
        .iter()
        .find(|r| r.scene == scene)
        .and_then(|r| r.noise_relmse)
}

/// The flicker between consecutive frames: the mean over pixels and channels of
/// `((I_f − R_f) − (I_{f−1} − R_{f−1}))² / (max(R_f, R_{f−1})² + 0.01)` (see the crate
/// documentation).
pub fn flicker(image: &Image, reference: &Image, prev: &Image, prev_reference: &Image) -> f64 {
    let n = image.pixels.len();
    if n == 0
        || [reference, prev, prev_reference]
            .iter()
            .any(|i| i.pixels.len() != n)
    {
        return f64::NAN;
    }
    let mut sum = 0.0f64;
    for i in 0..n {
        let (a, r, pa, pr) = (
            image.pixels[i].as_dvec3(),
            reference.pixels[i].as_dvec3(),
            prev.pixels[i].as_dvec3(),
            prev_reference.pixels[i].as_dvec3(),
        );
        let d = (a - r) - (pa - pr);
        let m = r.max(pr);
        sum += (d * d / (m * m + 0.01)).element_sum();
    }
    sum / (3 * n) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::utc;

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
}
