//! The reuse passes both screen-space ReSTIR estimators run between initial sampling and
//! shading, written once: temporal reuse with the previous pass's reservoirs, the spatial
//! rounds (ping-ponging two buffers, so the result does not depend on scheduling) and the
//! history kept for the next pass.
//!
//! An estimator plugs in through [`ReuseShift`]: its sample type, the domain its shift map
//! works on (DI: the receiver; PT: a pixel index) and the map itself. Every pixel's random
//! numbers come from its own stage stream ([`PassContext::stage_rng`]), drawn in the same order
//! whatever the estimator: the neighbour pattern's start, then resampling.

use std::sync::{Arc, Mutex};

use std::borrow::Borrow;

use restir_gris::{Reservoir, ShiftMap, resample};

use crate::bands::Bands;
use crate::motion::FrameMotion;
use crate::pass::PassContext;
use crate::reuse::duplication;
use crate::reuse::gbuffer::GBuffer;
use crate::reuse::neighbors::NeighborPattern;
use crate::reuse::reciprocal;
use crate::reuse::settings::ReuseSettings;

/// What an estimator's reuse needs for one pass: its shift map between the pixels of this pass
/// and the previous one.
pub trait ReuseShift: Sync {
    /// The reservoirs' sample.
    type Sample: Copy + Send + Sync;
    /// What the shift map calls a domain.
    type Domain: Sync + ?Sized;
    /// The shift map resampling a pixel uses.
    type Map<'m>: ShiftMap<Self::Sample, Domain = Self::Domain>
    where
        Self: 'm;

    /// The shift map for resampling into a pixel whose reservoir is `canonical`.
    fn map(&self, canonical: &Reservoir<Self::Sample>) -> Self::Map<'_>;

    /// Rays `map`'s shifts traced.
    fn rays(map: &Self::Map<'_>) -> u64 {
        let _ = map;
        0
    }

    /// How [`Self::domain`] hands a domain out: a reference into the estimator's buffers, or a
    /// small value (a pixel index) that needs no buffer to lend it.
    type DomainRef<'d>: Borrow<Self::Domain> + Copy
    where
        Self: 'd;

    /// The domain of pixel `index` (which has a primary hit) in this pass, or in the previous
    /// pass with `previous`.
    fn domain(&self, index: usize, previous: bool) -> Self::DomainRef<'_>;

    /// Whether two pixels hold the same sample (one of them shifted from the other, or both
    /// from a common one), for the duplication-aware history cap ([`super::duplication`]).
    fn same_sample(a: &Self::Sample, b: &Self::Sample) -> bool;
}

/// What temporal reuse keeps from the previous pass.
#[derive(Debug)]
pub struct History<S> {
    /// The previous pass's primary hits.
    pub gbuffer: GBuffer,
    /// Its final reservoirs.
    pub reservoirs: Vec<Reservoir<S>>,
    /// How the scene moved since that pass, if it was the previous frame's last pass (`None`:
    /// a pass of this frame, in this scene).
    pub motion: Option<Arc<FrameMotion>>,
}

impl<S> History<S> {
    /// The previous pass's pixel that saw pixel `index`'s primary hit of `gbuf`, if it saw a
    /// similar one: the same pixel in the same frame, or the motion vector's pixel in the
    /// previous frame ([`GBuffer::previous_pixel`]).
    #[inline]
    pub fn previous_pixel(
        &self,
        gbuf: &GBuffer,
        index: usize,
        settings: &ReuseSettings,
    ) -> Option<usize> {
        match &self.motion {
            Some(m) => gbuf.previous_pixel(index, m, &self.gbuffer, settings),
            None => {
                let (r, prev) = (gbuf.receiver(index)?, self.gbuffer.receiver(index)?);
                r.is_similar(prev, settings.normal_cos, settings.depth_tolerance)
                    .then_some(index)
            }
        }
    }
}

/// The history slot an integrator keeps between passes.
#[derive(Debug)]
pub struct HistorySlot<S>(Mutex<Option<History<S>>>);

impl<S> Default for HistorySlot<S> {
    fn default() -> Self {
        Self(Mutex::new(None))
    }
}

impl<S> HistorySlot<S> {
    /// Takes the previous pass's history when temporal reuse is on and it matches a pass of
    /// `pixels` pixels.
    pub fn take(&self, settings: &ReuseSettings, pixels: usize) -> Option<History<S>> {
        if !settings.temporal {
            return None;
        }
        self.0
            .lock()
            .map(|mut h| h.take())
            .unwrap_or(None)
            .filter(|h| h.reservoirs.len() == pixels)
    }

    /// Keeps this pass's primary hits and final reservoirs when temporal reuse is on.
    pub fn store(&self, settings: &ReuseSettings, gbuffer: GBuffer, reservoirs: Vec<Reservoir<S>>) {
        if settings.temporal
            && let Ok(mut h) = self.0.lock()
        {
            *h = Some(History {
                gbuffer,
                reservoirs,
                motion: None,
            });
        }
    }

    /// The passes that follow render the next frame of a sequence: the history (the previous
    /// frame's last pass) is kept with `motion`, how the scene moved since, or dropped when
    /// `motion` is `None` (an estimator that cannot shift its samples across frames) or when
    /// the history is older than one frame.
    pub fn next_frame(&self, motion: Option<Arc<FrameMotion>>) {
        if let Ok(mut h) = self.0.lock() {
            match (h.as_mut(), motion) {
                (Some(hist), Some(m)) if hist.motion.is_none() => hist.motion = Some(m),
                _ => *h = None,
            }
        }
    }
}

/// Temporal reuse: every pixel whose primary hit was seen by a similar one in the previous pass
/// ([`History::previous_pixel`]: the same pixel, or across frames the motion vector's)
/// resamples its reservoir with that pixel's (confidence capped at `mcap`, or lower where its
/// sample is duplicated with `duplication` on: [`super::duplication`]); the previous domain
/// is `reuse.domain(previous pixel, true)`. Returns the rays traced.
pub fn temporal<R: ReuseShift>(
    reuse: &R,
    settings: &ReuseSettings,
    ctx: &PassContext,
    gbuf: &GBuffer,
    history: &History<R::Sample>,
    stage: u64,
    current: &mut [Reservoir<R::Sample>],
) -> u64 {
    let mis = settings.temporal_mis();
    let caps = (settings.duplication > 0.0).then(|| {
        duplication::history_caps(
            &history.reservoirs,
            history.gbuffer.width,
            settings.halo().max(1) as usize,
            settings.duplication,
            settings.mcap,
            R::same_sample,
        )
    });
    let bands = Bands::new(gbuf.width);
    bands.run(current, |first, out| {
        let mut rays = 0;
        for (i, res) in out.iter_mut().enumerate() {
            let index = first + i;
            let Some(q) = history.previous_pixel(gbuf, index, settings) else {
                continue;
            };
            let cap = caps.as_ref().map_or(settings.mcap, |c| c[q]);
            let prev = history.reservoirs[q].with_confidence_cap(cap);
            let mut rng = ctx.stage_rng(index, stage);
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

/// `R` spatial rounds: each pixel with a primary hit resamples its reservoir with up to `k`
/// similar neighbours of the previous round's buffer, writing a new buffer. Returns the rays
/// traced.
pub fn spatial<R: ReuseShift>(
    reuse: &R,
    settings: &ReuseSettings,
    pattern: &NeighborPattern,
    ctx: &PassContext,
    gbuf: &GBuffer,
    first_stage: u64,
    current: &mut Vec<Reservoir<R::Sample>>,
) -> u64 {
    if settings.neighbors == 0 || settings.spatial_rounds == 0 {
        return 0;
    }
    if settings.reciprocal && reciprocal::shares_pair_shifts(settings.mis) {
        return reciprocal::spatial(reuse, settings, ctx, gbuf, first_stage, current);
    }
    let rule = settings.neighbor_rule();
    let bands = Bands::new(gbuf.width);
    let mut next = vec![Reservoir::empty(); current.len()];
    let mut rays = 0;
    for round in 0..settings.spatial_rounds {
        let input = &*current;
        rays += bands.run(&mut next[..], |first, out| {
            let mut rays = 0;
            let mut picked = Vec::with_capacity(rule.count);
            let mut neighbors = Vec::with_capacity(rule.count);
            for (i, res) in out.iter_mut().enumerate() {
                let index = first + i;
                let canonical = &input[index];
                if gbuf.receiver(index).is_none() {
                    *res = *canonical;
                    continue;
                }
                let mut rng = ctx.stage_rng(index, first_stage + u64::from(round));
                pattern.select(gbuf, index, &rule, &mut rng, &mut picked);
                neighbors.clear();
                neighbors.extend(picked.iter().map(|&q| (reuse.domain(q, false), &input[q])));
                let map = reuse.map(canonical);
                *res = resample(
                    &map,
                    settings.mis,
                    reuse.domain(index, false).borrow(),
                    canonical,
                    &neighbors,
                    || rng.next_f32(),
                )
                .with_confidence_cap(settings.mcap);
                rays += R::rays(&map);
            }
            rays
        });
        std::mem::swap(current, &mut next);
    }
    rays
}
