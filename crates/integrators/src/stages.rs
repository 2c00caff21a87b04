//! Where a pass's time goes: [`StageClock`] adds up the wall time of each named stage of an
//! estimator's passes (primary hits, initial candidates, temporal and spatial reuse, shading),
//! so `--stats` can report a per-stage cost beside the total. Stages run one after another and
//! each uses the whole thread pool, so a stage's wall time is its cost at that thread count.

use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The summed wall time of each stage, in the order the stages first ran.
#[derive(Debug, Default)]
pub struct StageClock {
    totals: Mutex<Vec<(&'static str, Duration)>>,
}

impl StageClock {
    /// Runs `f`, adding its wall time to stage `name`.
    pub fn time<T>(&self, name: &'static str, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let value = f();
        self.add(name, start.elapsed());
        value
    }

    /// Adds `elapsed` to stage `name`.
    pub fn add(&self, name: &'static str, elapsed: Duration) {
        let mut totals = self.totals.lock().unwrap_or_else(|e| e.into_inner());
        match totals.iter_mut().find(|(n, _)| *n == name) {
            Some((_, d)) => *d += elapsed,
            None => totals.push((name, elapsed)),
        }
    }

    /// Adds the temporal and spatial steps of a pass's reuse; returns their rays.
    pub fn add_reuse(&self, report: &restir_reuse::ReuseReport) -> u64 {
        if let Some((_, t)) = report.temporal {
            self.add("temporal", t);
        }
        self.add("spatial", report.spatial.1);
        report.rays()
    }

    /// Every stage's total in seconds, in the order the stages first ran.
    pub fn seconds(&self) -> Vec<(&'static str, f64)> {
        let totals = self.totals.lock().unwrap_or_else(|e| e.into_inner());
        totals.iter().map(|(n, d)| (*n, d.as_secs_f64())).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stages_add_up_in_first_run_order() {
        let clock = StageClock::default();
        clock.add("b", Duration::from_millis(3));
        clock.add("a", Duration::from_millis(1));
        clock.add("b", Duration::from_millis(2));
        assert_eq!(clock.time("c", || 7), 7);
        let s = clock.seconds();
        let names: Vec<_> = s.iter().map(|(n, _)| *n).collect();
        assert_eq!(names, ["b", "a", "c"]);
        assert!((s[0].1 - 0.005).abs() < 1e-9 && (s[1].1 - 0.001).abs() < 1e-9);
    }
}
