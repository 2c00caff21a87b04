//! The reuse passes both screen-space ReSTIR estimators run between initial sampling and
//! shading, written once: temporal reuse with the previous pass's reservoirs, the spatial
//! rounds (ping-ponging two buffers, so the result does not depend on scheduling) and the
//! history kept for the next pass.
//!
//! An estimator plugs in through [`ReuseShift`]: its sample type, the domain its shift map
//! works on (a light sample's receiver; a path's pixel) and the map itself; the host's image
//! through [`Surfaces`]. Every pixel's random numbers come from its own stage stream
//! ([`Streams::pixel`]), drawn in the same order whatever the estimator: the neighbour
//! pattern's start, then resampling.

use std::sync::{Arc, Mutex};

use std::borrow::Borrow;

use restir_gris::{MisScheme, Reservoir, ShiftMap, resample, resample_observed};

use crate::bands::Bands;
use crate::duplication;
use crate::neighbors::NeighborPattern;
use crate::reciprocal;
use crate::settings::ReuseSettings;
use crate::shift::ReuseShift;
use crate::surfaces::{Streams, Surfaces};

/// What temporal reuse keeps from the previous pass.
pub struct History<S, G: Surfaces> {
    /// The previous pass's surfaces.
    pub surfaces: G,
    /// Its final reservoirs.
    pub reservoirs: Vec<Reservoir<S>>,
    /// How the scene moved since that pass, if it was the previous frame's last pass (`None`:
    /// a pass of this frame, in this scene).
    pub motion: Option<Arc<G::Motion>>,
}

impl<S, G: Surfaces> History<S, G> {
    /// The previous pass's pixel that saw pixel `index`'s surface of `surfaces`, if it saw a
    /// similar one: the same pixel in the same frame, or the motion vector's pixel in the
    /// previous frame ([`Surfaces::previous_pixel`]).
    #[inline]
    pub fn previous_pixel(
        &self,
        surfaces: &G,
        index: usize,
        settings: &ReuseSettings,
    ) -> Option<usize> {
        surfaces.previous_pixel(
            index,
            &self.surfaces,
            self.motion.as_deref(),
            &settings.similarity(),
        )
    }
}

impl<S, G: Surfaces> std::fmt::Debug for History<S, G> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("History")
            .field("pixels", &self.reservoirs.len())
            .field("moved", &self.motion.is_some())
            .finish()
    }
}

/// The history slot an integrator keeps between passes.
pub struct HistorySlot<S, G: Surfaces>(Mutex<Option<History<S, G>>>);

impl<S, G: Surfaces> std::fmt::Debug for HistorySlot<S, G> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kept = self.0.lock().map(|h| h.is_some()).unwrap_or(false);
        f.debug_struct("HistorySlot").field("kept", &kept).finish()
    }
}

impl<S, G: Surfaces> Default for HistorySlot<S, G> {
    fn default() -> Self {
        Self(Mutex::new(None))
    }
}

impl<S, G: Surfaces> HistorySlot<S, G> {
    /// Takes the previous pass's history when temporal reuse is on and it matches a pass of
    /// `pixels` pixels.
    pub fn take(&self, settings: &ReuseSettings, pixels: usize) -> Option<History<S, G>> {
        if !settings.temporal {
            return None;
        }
        self.0
            .lock()
            .map(|mut h| h.take())
            .unwrap_or(None)
            .filter(|h| h.reservoirs.len() == pixels)
    }

    /// Keeps this pass's surfaces and final reservoirs when temporal reuse is on.
    pub fn store(&self, settings: &ReuseSettings, surfaces: G, reservoirs: Vec<Reservoir<S>>) {
        if settings.temporal
            && let Ok(mut h) = self.0.lock()
        {
            *h = Some(History {
                surfaces,
                reservoirs,
                motion: None,
            });
        }
    }

    /// The passes that follow render the next frame of a sequence: the history (the previous
    /// frame's last pass) is kept with `motion`, how the scene moved since, or dropped when
    /// `motion` is `None` (an estimator that cannot shift its samples across frames) or when
    /// the history is older than one frame.
    pub fn next_frame(&self, motion: Option<Arc<G::Motion>>) {
        if let Ok(mut h) = self.0.lock() {
            match (h.as_mut(), motion) {
                (Some(hist), Some(m)) if hist.motion.is_none() => hist.motion = Some(m),
                _ => *h = None,
            }
        }
    }
}

/// Temporal reuse: every pixel whose surface was seen by a similar one in the previous pass
/// ([`History::previous_pixel`]: the same pixel, or across frames the motion vector's)
/// resamples its reservoir with that pixel's (confidence capped at `mcap`, or lower where its
/// sample is duplicated with `duplication` on: [`crate::duplication`]); the previous domain
/// is `reuse.domain(previous pixel, true)`. Returns the rays traced.
pub fn temporal<R: ReuseShift, G: Surfaces>(
    reuse: &R,
    settings: &ReuseSettings,
    streams: &impl Streams,
    surfaces: &G,
    history: &History<R::Sample, G>,
    stage: u64,
    current: &mut [Reservoir<R::Sample>],
) -> u64 {
    let mis = settings.temporal_mis();
    let caps = (settings.duplication > 0.0).then(|| {
        duplication::history_caps(
            &history.reservoirs,
            history.surfaces.width(),
            settings.halo().max(1) as usize,
            settings.duplication,
            settings.mcap,
            R::same_sample,
        )
    });
    let bands = Bands::new(surfaces.width());
    bands.run(current, |first, out| {
        let mut rays = 0;
        for (i, res) in out.iter_mut().enumerate() {
            let index = first + i;
            let Some(q) = history.previous_pixel(surfaces, index, settings) else {
                continue;
            };
            let cap = caps.as_ref().map_or(settings.mcap, |c| c[q]);
            let prev = history.reservoirs[q].with_confidence_cap(cap);
            let mut rng = streams.pixel(index, stage);
            let map = reuse.map(res);
            *res = resample(
                &map,
                mis,
                reuse.domain(index, false).borrow(),
                res,
                &[(reuse.domain(q, true), &prev)],
                || rng.next_f32(),
            )
            .with_confidence_cap(settings.mcap);
            rays += R::rays(&map);
        }
        rays
    })
}

/// The buffers the spatial rounds write, kept from one pass to the next so that a pass does not
/// allocate them again (a fresh buffer of an image's size is mapped and faulted in page by
/// page: a few per cent of a pass).
pub struct Scratch<S> {
    /// The round's output reservoirs (after a pass: the buffer the last round read).
    pub(crate) next: Vec<Reservoir<S>>,
    /// The reciprocal rounds' shift table.
    pub(crate) table: Vec<Option<reciprocal::PairShifts<S>>>,
}

impl<S> Default for Scratch<S> {
    fn default() -> Self {
        Self {
            next: Vec::new(),
            table: Vec::new(),
        }
    }
}

impl<S> std::fmt::Debug for Scratch<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Scratch")
            .field("pixels", &self.next.len())
            .finish_non_exhaustive()
    }
}

impl<S: Copy> Scratch<S> {
    /// `next` as `n` empty reservoirs, its memory reused.
    pub(crate) fn next(&mut self, n: usize) -> Vec<Reservoir<S>> {
        let mut next = std::mem::take(&mut self.next);
        next.clear();
        next.resize(n, Reservoir::empty());
        next
    }
}

/// Per pixel, the expectation of its shading over the last spatial round's selection
/// ([`ReuseShift::ratio`]), `None` where it is not known (no surface, a sample without its
/// ratio, an MIS whose normalisation depends on the selection).
pub type Expected = Vec<Option<[f32; 3]>>;

/// One pixel's resampling, with the expectation of its shading over the selection when
/// `expect` asks for it and every input carries its ratio.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn resample_pixel<R: ReuseShift, M: ShiftMap<R::Sample>, D: Borrow<M::Domain>>(
    map: &M,
    mis: MisScheme,
    canonical_domain: &M::Domain,
    canonical: &Reservoir<R::Sample>,
    neighbors: &[(D, &Reservoir<R::Sample>)],
    next_u: impl FnMut() -> f32,
    expect: bool,
) -> (Reservoir<R::Sample>, Option<[f32; 3]>) {
    if !expect {
        let out = resample(map, mis, canonical_domain, canonical, neighbors, next_u);
        return (out, None);
    }
    let mut sum = [0.0f64; 3];
    let mut complete = true;
    let (out, scale) = resample_observed(
        map,
        mis,
        canonical_domain,
        canonical,
        neighbors,
        next_u,
        &mut |y: &R::Sample, w: f64| match R::ratio(y) {
            Some(r) => {
                for (s, r) in sum.iter_mut().zip(r) {
                    *s += w * f64::from(r);
                }
            }
            None => complete = false,
        },
    );
    let expected = scale
        .filter(|_| complete)
        .map(|s| sum.map(|v| (v * f64::from(s)) as f32))
        .filter(|e| e.iter().all(|v| v.is_finite()));
    (out, expected)
}

/// `R` spatial rounds: each pixel with a surface resamples its reservoir with up to `k`
/// similar neighbours of the previous round's buffer, writing a new buffer. With `expected`,
/// the last round also writes each pixel's expectation of its shading over the selection
/// ([`Expected`]). The buffers come from `scratch` and go back to it. Returns the rays traced.
#[allow(clippy::too_many_arguments)]
pub fn spatial<R: ReuseShift, G: Surfaces>(
    reuse: &R,
    settings: &ReuseSettings,
    pattern: &NeighborPattern,
    streams: &impl Streams,
    surfaces: &G,
    first_stage: u64,
    current: &mut Vec<Reservoir<R::Sample>>,
    mut expected: Option<&mut Expected>,
    scratch: &mut Scratch<R::Sample>,
) -> u64 {
    if settings.neighbors == 0 || settings.spatial_rounds == 0 {
        return 0;
    }
    if let Some(e) = expected.as_deref_mut() {
        e.clear();
        e.resize(current.len(), None);
    }
    if settings.runs_reciprocal() {
        return reciprocal::spatial(
            reuse,
            settings,
            streams,
            surfaces,
            first_stage,
            current,
            expected,
            scratch,
        );
    }
    let rule = settings.neighbor_rule();
    let bands = Bands::new(surfaces.width());
    let mut next = scratch.next(current.len());
    let mut rays = 0;
    for round in 0..settings.spatial_rounds {
        let input = &*current;
        let last = round + 1 == settings.spatial_rounds;
        // The expectation's slots, in the last round only.
        let slots = expected.as_deref_mut().filter(|_| last).map(|e| &mut e[..]);
        let expect = slots.is_some();
        rays += bands.run((&mut next[..], slots), |first, (out, mut slots)| {
            let mut rays = 0;
            let mut picked = Vec::with_capacity(rule.count);
            let mut neighbors = Vec::with_capacity(rule.count);
            for (i, res) in out.iter_mut().enumerate() {
                let index = first + i;
                let canonical = &input[index];
                if !surfaces.has_surface(index) {
                    *res = *canonical;
                    continue;
                }
                let mut rng = streams.pixel(index, first_stage + u64::from(round));
                pattern.select(surfaces, index, &rule, &mut rng, &mut picked);
                neighbors.clear();
                neighbors.extend(picked.iter().map(|&q| (reuse.domain(q, false), &input[q])));
                let map = reuse.map(canonical);
                let (out, e) = resample_pixel::<R, _, _>(
                    &map,
                    settings.mis,
                    reuse.domain(index, false).borrow(),
                    canonical,
                    &neighbors,
                    || rng.next_f32(),
                    expect,
                );
                *res = out.with_confidence_cap(settings.mcap);
                if let Some(slots) = slots.as_deref_mut() {
                    slots[i] = e;
                }
                rays += R::rays(&map);
            }
            rays
        });
        std::mem::swap(current, &mut next);
    }
    scratch.next = next;
    rays
}
