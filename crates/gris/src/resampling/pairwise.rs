//! Pairwise MIS as a streaming GRIS step: [`PairwiseResampler`] and what it needs per neighbour.
//!
//! The spatial-reuse form of pairwise, defensive pairwise and confidence-weighted pairwise MIS:
//! the canonical technique's weight is accumulated pair by pair while the neighbours stream in,
//! so nothing has to be stored per neighbour. The weights themselves are in [`crate::mis`].

use super::{GrisInput, GrisResampler};
use crate::mis::{self, PairTerms, clean};
use crate::reservoir::{Reservoir, Uniform};
use crate::shift::Shifted;

/// Which pairwise MIS variant a [`PairwiseResampler`] uses (`docs/GRIS.md` §4.5–4.7).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PairwiseVariant {
    /// Non-defensive pairwise: [`mis::pairwise_neighbor`] / [`mis::pairwise_canonical`].
    Plain,
    /// Defensive pairwise (canonical keeps `≥ 1/(n+1)`): [`mis::defensive_pairwise_neighbor`] /
    /// [`mis::defensive_pairwise_canonical`].
    Defensive,
    /// Confidence-weighted defensive pairwise: [`mis::confidence_weighted_pairwise_neighbor`] /
    /// [`mis::confidence_weighted_pairwise_canonical`]. `neighbor_confidence_sum` is `C_N`, the
    /// sum of the confidences of **all** neighbours that will be added.
    ConfidenceWeighted {
        /// `C_N = Σ_i c_i` over the neighbours of this step.
        neighbor_confidence_sum: f32,
    },
}

/// What a [`PairwiseResampler`] needs to know about one neighbour `i`, built with
/// [`PairwiseNeighbor::new`] from the neighbour's own reservoir.
///
/// Three targets of three different domains/points meet in one pairwise step; each has one
/// source here, so none can silently take another's place:
///
/// * `p̂_i(X_i)`, the neighbour's target at its own sample: the reservoir's
///   [`own_target`](Reservoir::own_target);
/// * `p̂_c(Y_i)`, the canonical target at the shifted neighbour sample: the forward shift's
///   [`destination_target`](Shifted::destination_target);
/// * `p̂_{←i}(X_c)`, the neighbour's target pulled back to the canonical sample: the one number
///   passed explicitly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairwiseNeighbor<S> {
    shifted: Option<Shifted<S>>,
    ucw: f32,
    confidence: f32,
    own_target: f32,
    pulled_back_target_at_canonical: f32,
}

impl<S> PairwiseNeighbor<S> {
    /// Neighbour `i` of a pairwise step:
    ///
    /// * `reservoir`: the neighbour's own reservoir (its `W_i`, `c_i` and own target `p̂_i(X_i)`
    ///   are taken from it); empty reservoirs are allowed and must still be added;
    /// * `shifted`: the forward shift `T_{i→c}(X_i)` of its sample into the canonical domain, or
    ///   `None` if the reservoir is empty or the shift failed;
    /// * `pulled_back_target_at_canonical`: the canonical sample shifted into the neighbour's
    ///   domain and pulled back, `p̂_{←i}(X_c) = p̂_i(T_{c→i}(X_c)) · J_{c→i}(X_c)`
    ///   ([`Shifted::pulled_back_target_pdf`] of the inverse shift, or
    ///   [`ShiftMap::pulled_back_target_pdf`](crate::ShiftMap::pulled_back_target_pdf)); 0 if that
    ///   shift fails or there is no canonical sample.
    pub fn new(
        reservoir: &Reservoir<S>,
        shifted: Option<Shifted<S>>,
        pulled_back_target_at_canonical: f32,
    ) -> Self {
        Self {
            shifted,
            ucw: reservoir.ucw,
            confidence: reservoir.confidence,
            own_target: reservoir.own_target,
            pulled_back_target_at_canonical,
        }
    }

    /// The forward shift of the neighbour's sample into the canonical domain, if any.
    pub fn shifted(&self) -> Option<&Shifted<S>> {
        self.shifted.as_ref()
    }

    /// `p̂_{←i}(X_c)`, as given to [`Self::new`].
    pub fn pulled_back_target_at_canonical(&self) -> f32 {
        self.pulled_back_target_at_canonical
    }
}

/// Streaming pairwise-MIS GRIS step (Bitterli 2022, PhD thesis §9.1; Lin et al. 2022;
/// `docs/GRIS.md` §4.5–4.7).
///
/// Create it with the canonical reservoir, add every neighbour **including empty ones and ones
/// whose shifts failed** (each contributes its canonical pair share; skipping one breaks the
/// partition of unity), then [`finalize`](Self::finalize), which streams the canonical sample
/// last with the accumulated canonical weight. Two shifts per neighbour: forward (neighbour
/// sample into the canonical domain) and inverse (canonical sample into the neighbour's domain).
///
/// `neighbor_count` is the configured `k` used inside the pair weights; the normalisation uses
/// the number of neighbours actually added (still a partition of unity).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairwiseResampler<S> {
    stream: GrisResampler<S>,
    canonical: Reservoir<S>,
    variant: PairwiseVariant,
    neighbor_count: f32,
    added: u32,
    canonical_weight: f64,
}

impl<S> PairwiseResampler<S> {
    /// Starts a step for the canonical reservoir `canonical` (whose `own_target` is
    /// `p̂_c(X_c)`) with `neighbor_count` configured neighbours.
    pub fn new(variant: PairwiseVariant, neighbor_count: usize, canonical: Reservoir<S>) -> Self {
        let canonical_weight = match variant {
            PairwiseVariant::Plain => 0.0,
            PairwiseVariant::Defensive => 1.0,
            PairwiseVariant::ConfidenceWeighted {
                neighbor_confidence_sum,
            } => {
                let cc = clean(canonical.confidence);
                let total = cc + clean(neighbor_confidence_sum);
                if total > 0.0 { cc / total } else { 1.0 }
            }
        };
        Self {
            stream: GrisResampler::new(),
            canonical,
            variant,
            neighbor_count: neighbor_count.max(1) as f32,
            added: 0,
            canonical_weight,
        }
    }

    /// The canonical reservoir this step was created with.
    pub fn canonical(&self) -> &Reservoir<S> {
        &self.canonical
    }

    /// Adds one neighbour with uniform `u ∈ [0, 1)`; returns `true` if its sample was selected.
    pub fn add_neighbor(&mut self, neighbor: PairwiseNeighbor<S>, u: impl Uniform) -> bool {
        self.add_neighbor_observed(neighbor, u, &mut |_: &S, _: f64| {})
    }

    /// [`add_neighbor`](Self::add_neighbor), telling `observe` the shifted sample and its
    /// resampling weight (see [`super::resample_observed`]).
    pub fn add_neighbor_observed(
        &mut self,
        neighbor: PairwiseNeighbor<S>,
        u: impl Uniform,
        observe: &mut impl FnMut(&S, f64),
    ) -> bool {
        self.added += 1;
        let cc = self.canonical.confidence;
        let pc = self.canonical.own_target;
        let ci = neighbor.confidence;
        // Canonical share at the canonical sample X_c.
        let p_ic = neighbor.pulled_back_target_at_canonical;
        match self.variant {
            PairwiseVariant::Plain | PairwiseVariant::Defensive => {
                let pair = PairTerms {
                    neighbor_confidence: ci,
                    neighbor_target_pdf: p_ic,
                    canonical_confidence: cc,
                    canonical_target_pdf: pc,
                };
                let a = mis::pairwise_pair_weight(pair, self.neighbor_count);
                self.canonical_weight += 1.0 - f64::from(a);
            }
            PairwiseVariant::ConfidenceWeighted {
                neighbor_confidence_sum,
            } => {
                let cn = clean(neighbor_confidence_sum);
                let (cc, pc, ci) = (clean(cc), clean(pc), clean(ci));
                let total = cc + cn;
                if total > 0.0 {
                    let den = cn * clean(p_ic) + cc * pc;
                    let share = if den > 0.0 { cc * pc / den } else { 1.0 };
                    self.canonical_weight += ci / total * share;
                }
            }
        }
        // Forward direction: the neighbour's own sample in the canonical domain.
        let Some(shifted) = neighbor.shifted.filter(Shifted::is_valid) else {
            self.stream.add_failed(ci);
            return false;
        };
        let p_i = shifted.source_target_pdf_at_receiver(neighbor.own_target);
        let p_c = shifted.destination_target;
        let pair = PairTerms {
            neighbor_confidence: ci,
            neighbor_target_pdf: p_i,
            canonical_confidence: cc,
            canonical_target_pdf: p_c,
        };
        let m = match self.variant {
            PairwiseVariant::Plain | PairwiseVariant::Defensive => {
                mis::pairwise_pair_weight(pair, self.neighbor_count)
            }
            PairwiseVariant::ConfidenceWeighted {
                neighbor_confidence_sum,
            } => mis::confidence_weighted_pairwise_neighbor(pair, neighbor_confidence_sum),
        };
        let input = GrisInput {
            sample: shifted.sample,
            receiver_target: p_c,
            ucw: neighbor.ucw,
            jacobian: shifted.jacobian,
            confidence: ci,
        };
        self.stream.add_observed(input, m, u, observe)
    }

    /// Unnormalised canonical weight accumulated so far (`Σ(1 − a_i)`, `1 + Σ(1 − a_i)`, or the
    /// confidence-weighted canonical weight).
    pub fn canonical_weight(&self) -> f64 {
        self.canonical_weight
    }

    /// Streams the canonical sample last (with uniform `u ∈ [0, 1)`) and finalises:
    /// `W = Σ w_i · scale / p̂_c(Y)` with `scale = 1/n` (plain, 1 if `n = 0`), `1/(n+1)`
    /// (defensive) or 1 (confidence-weighted), `n` = neighbours added.
    pub fn finalize(self, u: impl Uniform) -> Reservoir<S> {
        self.finalize_observed(u, &mut |_: &S, _: f64| {}).0
    }

    /// [`finalize`](Self::finalize), telling `observe` the canonical sample and its resampling
    /// weight; also returns the scale that turns the observed weights into the expectation
    /// over the selection (see [`super::resample_observed`]).
    pub fn finalize_observed(
        self,
        u: impl Uniform,
        observe: &mut impl FnMut(&S, f64),
    ) -> (Reservoir<S>, f32) {
        let n = self.added as f32;
        let (canonical_mis, scale) = match self.variant {
            PairwiseVariant::Plain if self.added == 0 => (1.0, 1.0),
            PairwiseVariant::Plain => (self.canonical_weight as f32, 1.0 / n),
            PairwiseVariant::Defensive => (self.canonical_weight as f32, 1.0 / (n + 1.0)),
            PairwiseVariant::ConfidenceWeighted { .. } => {
                (self.canonical_weight.clamp(0.0, 1.0) as f32, 1.0)
            }
        };
        let mut stream = self.stream;
        let canonical_confidence = self.canonical.confidence;
        match GrisInput::canonical(self.canonical) {
            Some(input) => {
                stream.add_observed(input, canonical_mis, u, observe);
            }
            None => stream.add_failed(canonical_confidence),
        }
        (stream.finalize_scaled(scale), scale)
    }
}
