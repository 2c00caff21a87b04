//! One pass's reuse in the order every screen-space estimator runs it: take the history, the
//! temporal round, the spatial rounds, keep the history for the next pass. An estimator builds
//! its shift map between the two first steps (the map may read the previous pass's surfaces), and
//! shades between the last two.

use std::sync::Arc;
use std::time::{Duration, Instant};

use restir_gris::Reservoir;

use crate::neighbors::NeighborPattern;
use crate::passes::{self, History, HistorySlot};
use crate::settings::ReuseSettings;
use crate::shift::ReuseShift;
use crate::surfaces::{Streams, Surfaces};

/// The random-stream stages of a pass's reuse ([`Streams::pixel`]): the temporal round draws
/// from `temporal`, spatial round `r` from `spatial + r`. Distinct from the estimator's other
/// stages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stages {
    /// The temporal round's stage.
    pub temporal: u64,
    /// The first spatial round's stage.
    pub spatial: u64,
}

/// What one pass's reuse did: rays its shifts traced and the wall time of each step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReuseReport {
    /// The temporal round's rays and time, when it ran.
    pub temporal: Option<(u64, Duration)>,
    /// The spatial rounds' rays and time.
    pub spatial: (u64, Duration),
}

impl ReuseReport {
    /// Rays traced by both steps.
    pub fn rays(&self) -> u64 {
        self.temporal.map_or(0, |t| t.0) + self.spatial.0
    }
}

/// The state a screen-space estimator keeps across passes: the neighbour pattern and the
/// history of the previous pass (reservoirs of sample type `S` over surfaces `G`).
pub struct ScreenReuse<S, G: Surfaces> {
    pattern: NeighborPattern,
    history: HistorySlot<S, G>,
    /// The spatial rounds' buffers, kept between passes.
    scratch: std::sync::Mutex<passes::Scratch<S>>,
}

impl<S, G: Surfaces> std::fmt::Debug for ScreenReuse<S, G> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ScreenReuse")
            .field("history", &self.history)
            .finish_non_exhaustive()
    }
}

impl<S, G: Surfaces> Default for ScreenReuse<S, G> {
    fn default() -> Self {
        Self {
            pattern: NeighborPattern::new(),
            history: HistorySlot::default(),
            scratch: Default::default(),
        }
    }
}

impl<S: Copy + Send + Sync, G: Surfaces> ScreenReuse<S, G> {
    /// Takes the previous pass's history when temporal reuse is on and it covers `pixels`
    /// pixels (its surfaces are what a shift map into the previous pass reads).
    pub fn take_history(&self, settings: &ReuseSettings, pixels: usize) -> Option<History<S, G>> {
        self.history.take(settings, pixels)
    }

    /// Temporal reuse with `history` (when given), then the spatial rounds, in place on
    /// `current` (one reservoir per pixel, from initial sampling), with `shift`'s map.
    #[allow(clippy::too_many_arguments)]
    pub fn reuse<R: ReuseShift<Sample = S>>(
        &self,
        shift: &R,
        settings: &ReuseSettings,
        streams: &impl Streams,
        surfaces: &G,
        history: Option<&History<S, G>>,
        stages: Stages,
        current: &mut Vec<Reservoir<S>>,
    ) -> ReuseReport {
        self.reuse_expected(
            shift, settings, streams, surfaces, history, stages, current, None,
        )
    }

    /// [`reuse`](Self::reuse); with `expected`, the last spatial round also writes each
    /// pixel's expectation of its shading over that round's selection, `Σ_i w_i·f(Y_i)/p̂(Y_i)`
    /// scaled by the MIS normalisation ([`restir_gris::resample_observed`]), where the samples
    /// carry their ratio ([`ReuseShift::ratio`]). Shading with it in place of the selected
    /// sample's `f(Y)·W_Y` has the same expectation and no more variance; the reservoirs are
    /// the same either way. Left empty without spatial rounds.
    #[allow(clippy::too_many_arguments)]
    pub fn reuse_expected<R: ReuseShift<Sample = S>>(
        &self,
        shift: &R,
        settings: &ReuseSettings,
        streams: &impl Streams,
        surfaces: &G,
        history: Option<&History<S, G>>,
        stages: Stages,
        current: &mut Vec<Reservoir<S>>,
        mut expected: Option<&mut crate::passes::Expected>,
    ) -> ReuseReport {
        if let Some(e) = expected.as_deref_mut() {
            e.clear();
        }
        let temporal = history.map(|h| {
            let start = Instant::now();
            let rays = passes::temporal(
                shift,
                settings,
                streams,
                surfaces,
                h,
                stages.temporal,
                current,
            );
            (rays, start.elapsed())
        });
        let start = Instant::now();
        // A pass of another thread (a split render's parts share nothing but this) or a
        // poisoned lock gets buffers of its own.
        let mut own = passes::Scratch::default();
        let mut kept = self.scratch.try_lock();
        let scratch = match kept.as_deref_mut() {
            Ok(s) => s,
            Err(_) => &mut own,
        };
        let rays = passes::spatial(
            shift,
            settings,
            &self.pattern,
            streams,
            surfaces,
            stages.spatial,
            current,
            expected,
            scratch,
        );
        ReuseReport {
            temporal,
            spatial: (rays, start.elapsed()),
        }
    }

    /// Keeps this pass's surfaces and final reservoirs for the next pass when temporal reuse is
    /// on.
    pub fn keep(&self, settings: &ReuseSettings, surfaces: G, reservoirs: Vec<Reservoir<S>>) {
        self.history.store(settings, surfaces, reservoirs);
    }

    /// The passes that follow render the next frame of a sequence, which moved from this one as
    /// `motion` says (`None`: samples cannot follow the motion; the history is dropped).
    pub fn next_frame(&self, motion: Option<Arc<G::Motion>>) {
        self.history.next_frame(motion);
    }
}
