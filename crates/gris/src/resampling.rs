//! Resampling finalised reservoirs from several domains into one receiving domain (GRIS).
//!
//! Implements one generalized-RIS step (Lin et al. 2022, "Generalized Resampled Importance
//! Sampling: Foundations of ReSTIR"; `ALGORITHMS.md` §3.1): every input reservoir
//! `(X_i, W_i, c_i)` is shifted into the receiving (canonical) domain `c`, `Y_i = T_{i→c}(X_i)`,
//! and resampled with weight
//!
//! ```text
//! w_i = m_i(Y_i) · p̂_c(Y_i) · W_i · J_{i→c}(X_i)
//! ```
//!
//! The output is `Y = Y_s` with `s` chosen ∝ `w_i`, `W_Y = Σ w_i / p̂_c(Y)` and confidence `Σ c_i`
//! (cap it afterwards with [`crate::confidence`]).
//!
//! Three levels of API:
//!
//! * [`GrisResampler`]: you compute each input's MIS weight (with [`crate::mis`]) and feed
//!   [`GrisInput`]s. Most flexible.
//! * [`PairwiseResampler`]: streaming (defensive / confidence-weighted) pairwise MIS, the way a
//!   renderer's spatial pass uses it: it accumulates the canonical weight across neighbours.
//! * [`resample`]: the whole step for any [`MisScheme`], given a [`ShiftMap`] implementation.

use crate::mis::{self, MisScheme, clean};
use crate::reservoir::{Reservoir, StreamingReservoir, sanitize_non_negative};
use crate::shift::{ShiftMap, Shifted};

/// One input of a GRIS step, already shifted into the receiving domain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GrisInput<S> {
    /// The shifted sample `Y_i = T_{i→c}(X_i)`.
    pub sample: S,
    /// Receiving domain's target at the shifted sample, `p̂_c(Y_i)`.
    pub target_pdf: f32,
    /// The input reservoir's unbiased contribution weight `W_i` (in its own domain's measure).
    pub ucw: f32,
    /// Jacobian `|∂T_{i→c}/∂x|` at `X_i` (1 for the canonical input).
    pub jacobian: f32,
    /// The input reservoir's confidence `c_i`.
    pub confidence: f32,
}

impl<S> GrisInput<S> {
    /// The canonical input: the receiving domain's own reservoir (identity shift, `J = 1`).
    /// `None` if the reservoir is empty.
    pub fn canonical(reservoir: Reservoir<S>) -> Option<Self> {
        let target_pdf = reservoir.target_pdf;
        let (ucw, confidence) = (reservoir.ucw, reservoir.confidence);
        reservoir.sample.map(|sample| Self {
            sample,
            target_pdf,
            ucw,
            jacobian: 1.0,
            confidence,
        })
    }

    /// An input from a successful shift of a reservoir with weight `ucw` and confidence
    /// `confidence`.
    pub fn from_shift(shifted: Shifted<S>, ucw: f32, confidence: f32) -> Self {
        Self {
            sample: shifted.sample,
            target_pdf: shifted.target_pdf,
            ucw,
            jacobian: shifted.jacobian,
            confidence,
        }
    }

    /// `w_i = m_i · p̂_c(Y_i) · W_i · J_i` in `f64`. Negative, NaN and infinite factors give 0.
    #[inline]
    pub fn resampling_weight(&self, mis_weight: f32) -> f64 {
        let w = clean(mis_weight) * clean(self.target_pdf) * clean(self.ucw) * clean(self.jacobian);
        if w.is_finite() { w } else { 0.0 }
    }
}

/// Streaming GRIS resampler with caller-supplied MIS weights.
///
/// Feed every input with [`add`](Self::add) (or [`add_failed`](Self::add_failed) when its shift
/// failed), then [`finalize`](Self::finalize). Inputs are numbered in the order they are given
/// (failed ones included), which [`selected_input`](Self::selected_input) reports.
///
/// ```
/// use restir_gris::{GrisInput, GrisResampler, Reservoir, mis};
///
/// let canonical = Reservoir { sample: Some(0.5f32), ucw: 2.0, confidence: 1.0, target_pdf: 0.5 };
/// let neighbor = GrisInput { sample: 0.8f32, target_pdf: 0.8, ucw: 1.5, jacobian: 1.0, confidence: 1.0 };
/// // Constant MIS with two equally confident inputs: m = 1/2 each.
/// let mut r = GrisResampler::new();
/// r.add(GrisInput::canonical(canonical).unwrap(), 0.5, 0.3);
/// r.add(neighbor, 0.5, 0.7);
/// let out = r.finalize();
/// assert_eq!(out.confidence, 2.0);
/// assert!(out.ucw > 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GrisResampler<S> {
    stream: StreamingReservoir<S>,
    inputs: usize,
    selected_input: Option<usize>,
}

impl<S> Default for GrisResampler<S> {
    fn default() -> Self {
        Self::new()
    }
}

impl<S> GrisResampler<S> {
    /// An empty resampler.
    pub const fn new() -> Self {
        Self {
            stream: StreamingReservoir::new(),
            inputs: 0,
            selected_input: None,
        }
    }

    /// Streams one input with MIS weight `mis_weight = m_i(Y_i)` and uniform `u ∈ [0, 1)`.
    /// Adds `input.confidence` to the output confidence. Returns `true` if it was selected.
    #[inline]
    pub fn add(&mut self, input: GrisInput<S>, mis_weight: f32, u: f32) -> bool {
        let w = input.resampling_weight(mis_weight);
        let index = self.inputs;
        self.inputs += 1;
        let taken = self
            .stream
            .push(input.sample, input.target_pdf, w, input.confidence, u);
        if taken {
            self.selected_input = Some(index);
        }
        taken
    }

    /// Records an input whose shift failed (or whose reservoir was empty): it cannot be selected,
    /// but its confidence counts towards the output, as in the references. Pass 0 to exclude it.
    #[inline]
    pub fn add_failed(&mut self, confidence: f32) {
        self.inputs += 1;
        self.stream.add_confidence(confidence);
    }

    /// The currently selected (shifted) sample.
    pub fn selected(&self) -> Option<&S> {
        self.stream.selected()
    }

    /// Index (in call order) of the input whose sample is selected.
    pub fn selected_input(&self) -> Option<usize> {
        self.selected_input
    }

    /// `p̂_c` at the selected sample.
    pub fn selected_target_pdf(&self) -> f32 {
        self.stream.selected_target_pdf()
    }

    /// Running `Σ w_i` in `f64`.
    pub fn weight_sum(&self) -> f64 {
        self.stream.weight_sum()
    }

    /// Accumulated output confidence `Σ c_i` (before capping).
    pub fn confidence(&self) -> f32 {
        self.stream.confidence()
    }

    /// Finalises with `W = Σ w_i / p̂_c(Y)`: use when the MIS weights passed to `add` were
    /// already normalised (they sum to one at every point).
    pub fn finalize(self) -> Reservoir<S> {
        self.stream.finalize_recorded()
    }

    /// Finalises with `W = Σ w_i · scale / p̂_c(Y)`: use when the MIS normalisation is applied
    /// after selection (`1/Σc` for constant MIS, [`mis::one_over_z`],
    /// [`mis::contribution_scale`], `1/n` or `1/(n+1)` for pairwise).
    pub fn finalize_scaled(self, scale: f32) -> Reservoir<S> {
        let t = self.stream.selected_target_pdf();
        self.stream.finalize_scaled(t, scale)
    }
}

/// Which pairwise MIS variant a [`PairwiseResampler`] uses (`ALGORITHMS.md` §3.3 (e), (f)).
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

/// What a [`PairwiseResampler`] needs to know about one neighbour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairwiseNeighbor<S> {
    /// Forward shift `T_{i→c}(X_i)` of the neighbour's sample into the canonical domain, or
    /// `None` if the neighbour's reservoir is empty or the shift failed.
    pub shifted: Option<Shifted<S>>,
    /// Neighbour's `W_i`.
    pub ucw: f32,
    /// Neighbour's confidence `c_i`.
    pub confidence: f32,
    /// Neighbour's target at its own sample, `p̂_i(X_i)` (its `Reservoir::target_pdf`).
    pub target_pdf: f32,
    /// Inverse direction: the canonical sample shifted into the neighbour's domain and pulled
    /// back, `p̂_{←i}(X_c) = p̂_i(T_{c→i}(X_c)) · J_{c→i}(X_c)`
    /// ([`Shifted::pulled_back_target_pdf`]); 0 if that shift fails or there is no canonical
    /// sample.
    pub canonical_sample_target_pdf: f32,
}

/// Streaming pairwise-MIS GRIS step (Bitterli 2022, PhD thesis §9.1; Lin et al. 2022;
/// `ALGORITHMS.md` §3.3 (e)–(f)).
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
    /// Starts a step for the canonical reservoir `canonical` (whose `target_pdf` must be
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
    pub fn add_neighbor(&mut self, neighbor: PairwiseNeighbor<S>, u: f32) -> bool {
        self.added += 1;
        let cc = self.canonical.confidence;
        let pc = self.canonical.target_pdf;
        let ci = neighbor.confidence;
        // Canonical share at the canonical sample X_c.
        let p_ic = neighbor.canonical_sample_target_pdf;
        match self.variant {
            PairwiseVariant::Plain | PairwiseVariant::Defensive => {
                let a = mis::pairwise_pair_weight(ci, p_ic, cc, pc, self.neighbor_count);
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
        let p_i = shifted.source_target_pdf_at_receiver(neighbor.target_pdf);
        let p_c = shifted.target_pdf;
        let m = match self.variant {
            PairwiseVariant::Plain | PairwiseVariant::Defensive => {
                mis::pairwise_pair_weight(ci, p_i, cc, p_c, self.neighbor_count)
            }
            PairwiseVariant::ConfidenceWeighted {
                neighbor_confidence_sum,
            } => mis::confidence_weighted_pairwise_neighbor(
                ci,
                p_i,
                cc,
                p_c,
                neighbor_confidence_sum,
            ),
        };
        let input = GrisInput::from_shift(shifted, neighbor.ucw, ci);
        self.stream.add(input, m, u)
    }

    /// Unnormalised canonical weight accumulated so far (`Σ(1 − a_i)`, `1 + Σ(1 − a_i)`, or the
    /// confidence-weighted canonical weight).
    pub fn canonical_weight(&self) -> f64 {
        self.canonical_weight
    }

    /// Streams the canonical sample last (with uniform `u ∈ [0, 1)`) and finalises:
    /// `W = Σ w_i · scale / p̂_c(Y)` with `scale = 1/n` (plain, 1 if `n = 0`), `1/(n+1)`
    /// (defensive) or 1 (confidence-weighted), `n` = neighbours added.
    pub fn finalize(self, u: f32) -> Reservoir<S> {
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
                stream.add(input, canonical_mis, u);
            }
            None => stream.add_failed(canonical_confidence),
        }
        stream.finalize_scaled(scale)
    }
}

/// Shifts a neighbour's reservoir into the receiver, or `None` if it is empty or the shift fails.
fn shift_in<S, M: ShiftMap<S>>(
    map: &M,
    from: &M::Domain,
    to: &M::Domain,
    reservoir: &Reservoir<S>,
) -> Option<Shifted<S>> {
    let x = reservoir.sample.as_ref()?;
    if !(reservoir.ucw > 0.0) {
        return None;
    }
    map.shift(from, to, x).filter(Shifted::is_valid)
}

/// One complete GRIS step at `canonical_domain` with the MIS scheme `scheme`.
///
/// * `canonical` is the receiving domain's own reservoir; its `target_pdf` must be `p̂_c(X_c)`.
/// * `neighbors` lists each neighbour's domain and reservoir (`target_pdf = p̂_i(X_i)`); empty
///   reservoirs are allowed and still count as techniques.
/// * `next_u` supplies independent uniform numbers in `[0, 1)` (one per input).
///
/// Shift cost per scheme (k neighbours): constant O(k); 1/Z and contribution O(k) + O(k) inverse
/// shifts of the selected sample; pairwise variants 2k; generalized balance O(k²). The output
/// confidence is the sum of all input confidences; cap it afterwards. Unbiased for every scheme
/// except [`MisScheme::ConstantBiased`], provided the [`ShiftMap`] honours its contract and the
/// canonical target covers the integrand's support.
///
/// ```
/// use restir_gris::{resample, MisScheme, Reservoir, ShiftMap, Shifted};
///
/// // Identity shift between two domains that share a sample space but have their own targets.
/// struct Domain { slope: f32 }
/// struct Identity;
/// impl ShiftMap<f32> for Identity {
///     type Domain = Domain;
///     fn shift(&self, _from: &Domain, to: &Domain, x: &f32) -> Option<Shifted<f32>> {
///         Some(Shifted::identity(*x, 1.0 + to.slope * x))
///     }
/// }
/// let (a, b) = (Domain { slope: 1.0 }, Domain { slope: 3.0 });
/// let ra = Reservoir { sample: Some(0.25f32), ucw: 0.9, confidence: 1.0, target_pdf: 1.25 };
/// let rb = Reservoir { sample: Some(0.75f32), ucw: 0.6, confidence: 2.0, target_pdf: 3.25 };
/// let mut us = [0.1f32, 0.9].into_iter();
/// let out = resample(&Identity, MisScheme::DefensivePairwise, &a, &ra, &[(&b, &rb)],
///                    || us.next().unwrap_or(0.5));
/// assert_eq!(out.confidence, 3.0);
/// assert!(out.sample.is_some() && out.ucw > 0.0);
/// ```
pub fn resample<S, M>(
    map: &M,
    scheme: MisScheme,
    canonical_domain: &M::Domain,
    canonical: &Reservoir<S>,
    neighbors: &[(&M::Domain, &Reservoir<S>)],
    mut next_u: impl FnMut() -> f32,
) -> Reservoir<S>
where
    S: Clone,
    M: ShiftMap<S>,
{
    let cc = sanitize_non_negative(canonical.confidence);
    let pc_own = canonical.target_pdf;
    match scheme {
        MisScheme::Pairwise
        | MisScheme::DefensivePairwise
        | MisScheme::ConfidenceWeightedPairwise => {
            let variant = match scheme {
                MisScheme::Pairwise => PairwiseVariant::Plain,
                MisScheme::DefensivePairwise => PairwiseVariant::Defensive,
                _ => PairwiseVariant::ConfidenceWeighted {
                    neighbor_confidence_sum: neighbors
                        .iter()
                        .map(|(_, r)| sanitize_non_negative(r.confidence))
                        .sum(),
                },
            };
            let mut step = PairwiseResampler::new(variant, neighbors.len(), canonical.clone());
            for &(domain, reservoir) in neighbors {
                let canonical_sample_target_pdf = canonical.sample.as_ref().map_or(0.0, |xc| {
                    map.pulled_back_target_pdf(canonical_domain, domain, xc)
                });
                let neighbor = PairwiseNeighbor {
                    shifted: shift_in(map, domain, canonical_domain, reservoir),
                    ucw: reservoir.ucw,
                    confidence: reservoir.confidence,
                    target_pdf: reservoir.target_pdf,
                    canonical_sample_target_pdf,
                };
                step.add_neighbor(neighbor, next_u());
            }
            step.finalize(next_u())
        }
        MisScheme::GeneralizedBalance => {
            // Σ_j P_j(y) over the neighbours j ≠ skip, by inverse shifts of y.
            let others = |y: &S, skip: Option<usize>| -> f64 {
                neighbors
                    .iter()
                    .enumerate()
                    .filter(|&(j, _)| Some(j) != skip)
                    .map(|(_, &(d, r))| {
                        clean(r.confidence)
                            * clean(map.pulled_back_target_pdf(canonical_domain, d, y))
                    })
                    .sum()
            };
            let mut stream = GrisResampler::new();
            match GrisInput::canonical(canonical.clone()) {
                Some(input) => {
                    let own = clean(cc) * clean(pc_own);
                    let m = balance(own, own + others(&input.sample, None));
                    stream.add(input, m, next_u());
                }
                None => stream.add_failed(cc),
            }
            for (i, &(domain, reservoir)) in neighbors.iter().enumerate() {
                let Some(shifted) = shift_in(map, domain, canonical_domain, reservoir) else {
                    stream.add_failed(reservoir.confidence);
                    continue;
                };
                let own = clean(reservoir.confidence)
                    * clean(shifted.source_target_pdf_at_receiver(reservoir.target_pdf));
                let den =
                    own + clean(cc) * clean(shifted.target_pdf) + others(&shifted.sample, Some(i));
                let m = balance(own, den);
                let input = GrisInput::from_shift(shifted, reservoir.ucw, reservoir.confidence);
                stream.add(input, m, next_u());
            }
            stream.finalize()
        }
        MisScheme::ConstantBiased | MisScheme::OneOverZ | MisScheme::Contribution => {
            // Constant resampling weights c_i; the normalisation is applied after selection.
            // Input 0 is the canonical, input i + 1 is neighbour i.
            let mut stream = GrisResampler::new();
            let mut selected_jacobian = 1.0f32;
            let mut selected_source_target = pc_own;
            match GrisInput::canonical(canonical.clone()) {
                Some(input) => {
                    stream.add(input, cc, next_u());
                }
                None => stream.add_failed(cc),
            }
            for &(domain, reservoir) in neighbors {
                match shift_in(map, domain, canonical_domain, reservoir) {
                    Some(shifted) => {
                        let (j, t) = (shifted.jacobian, reservoir.target_pdf);
                        let c = sanitize_non_negative(reservoir.confidence);
                        let input = GrisInput::from_shift(shifted, reservoir.ucw, c);
                        if stream.add(input, c, next_u()) {
                            selected_jacobian = j;
                            selected_source_target = t;
                        }
                    }
                    None => stream.add_failed(reservoir.confidence),
                }
            }
            let (Some(s), Some(y)) = (stream.selected_input(), stream.selected().cloned()) else {
                return stream.finalize_scaled(0.0);
            };
            let scale = match scheme {
                MisScheme::ConstantBiased => {
                    let total = f64::from(stream.confidence());
                    if total > 0.0 {
                        (1.0 / total) as f32
                    } else {
                        0.0
                    }
                }
                _ => {
                    // P_j(y) for every technique, without allocating: canonical, then neighbours.
                    let pc_y = stream.selected_target_pdf();
                    let pulled = |j: usize| -> f32 {
                        if j == 0 {
                            pc_y
                        } else if j == s {
                            // The selected technique's own sample: p̂_s(x_s)/J_s, no extra shift.
                            (f64::from(selected_source_target) / f64::from(selected_jacobian))
                                as f32
                        } else {
                            let (d, _) = neighbors[j - 1];
                            map.pulled_back_target_pdf(canonical_domain, d, &y)
                        }
                    };
                    let conf = |j: usize| -> f32 {
                        if j == 0 {
                            cc
                        } else {
                            neighbors[j - 1].1.confidence
                        }
                    };
                    let mut z = 0.0f64;
                    let mut den = 0.0f64;
                    let mut p_s = 0.0f64;
                    for j in 0..=neighbors.len() {
                        let p = clean(pulled(j));
                        if j == s {
                            p_s = p;
                        }
                        if p > 0.0 {
                            z += clean(conf(j));
                            den += clean(conf(j)) * p;
                        }
                    }
                    let r = if scheme == MisScheme::OneOverZ {
                        if z > 0.0 { 1.0 / z } else { 0.0 }
                    } else if den > 0.0 {
                        p_s / den
                    } else {
                        0.0
                    };
                    r as f32
                }
            };
            stream.finalize_scaled(scale)
        }
    }
}

#[inline]
fn balance(num: f64, den: f64) -> f32 {
    if num > 0.0 && den > 0.0 && den.is_finite() {
        (num / den).min(1.0) as f32
    } else {
        0.0
    }
}
