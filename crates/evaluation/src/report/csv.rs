//! `results.csv`: one row per render.

use std::fmt::Write as _;

use crate::analysis::reference_noise;
use crate::records::BenchResults;

pub(crate) fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The CSV header: one row per render, a sequence's frames one row each (`frame` empty for a
/// still render; `flicker` empty for it and for a sequence's first frame).
pub const CSV_HEADER: &str = "scene,label,integrator_settings,width,height,budget_s,seed,seconds,passes,rays,mrays_per_s,relmse,mse,mape,flip,mean_ratio,nonfinite_pixels,rss_before_mib,peak_rss_mib,reference_noise_relmse,frame,flicker,cpu_seconds,top1_share";

pub(crate) fn csv(results: &BenchResults) -> String {
    let mut s = String::from(CSV_HEADER);
    s.push('\n');
    for r in &results.records {
        let noise = reference_noise(results, &r.scene).map_or(String::new(), |n| format!("{n:e}"));
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{:.4},{},{},{:.3},{:e},{:e},{:e},{:.6},{:.6},{},{:.1},{:.1},{},{},{},{:.4},{:.4}",
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
            r.cpu_seconds,
            r.top1_share
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quotes_fields() {
        assert_eq!(csv_field("a,b"), "\"a,b\"");
    }
}
