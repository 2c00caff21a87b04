//! Resampling finalised reservoirs from several domains into one receiving domain (GRIS).
//!
//! Implements one generalized-RIS step (Lin et al. 2022, "Generalized Resampled Importance
//! Sampling: Foundations of ReSTIR"; derivation in `docs/GRIS.md` §3): every input reservoir
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
//! * [`resample`]: the whole step for any [`MisScheme`](crate::MisScheme), given a [`ShiftMap`](crate::ShiftMap) implementation;
//!   [`resample_observed`] also gives what shading every input instead of the selected one
//!   would give (the selection's expectation).

mod pairwise;
mod step;

pub use pairwise::{PairwiseNeighbor, PairwiseResampler, PairwiseVariant};
pub use step::{resample, resample_observed};

use crate::mis::clean;
use crate::reservoir::{Reservoir, StreamingReservoir, Uniform};
use crate::shift::Shifted;

/// One input of a GRIS step, already shifted into the receiving domain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GrisInput<S> {
    /// The shifted sample `Y_i = T_{i→c}(X_i)`.
    pub sample: S,
    /// The **receiving** domain's target at the shifted sample, `p̂_c(Y_i)` (receiver's measure;
    /// [`Shifted::destination_target`] of the shift into the receiver). Not the input
    /// reservoir's own target `p̂_i(X_i)`.
    pub receiver_target: f32,
    /// The input reservoir's unbiased contribution weight `W_i` (in its own domain's measure).
    pub ucw: f32,
    /// Jacobian `|∂T_{i→c}/∂x|` at `X_i` (1 for the canonical input).
    pub jacobian: f32,
    /// The input reservoir's confidence `c_i`.
    pub confidence: f32,
}

impl<S> GrisInput<S> {
    /// The canonical input: the receiving domain's own reservoir (identity shift, `J = 1`; its
    /// own target is the receiver's target). `None` if the reservoir is empty.
    pub fn canonical(reservoir: Reservoir<S>) -> Option<Self> {
        let receiver_target = reservoir.own_target;
        let (ucw, confidence) = (reservoir.ucw, reservoir.confidence);
        reservoir.sample.map(|sample| Self {
            sample,
            receiver_target,
            ucw,
            jacobian: 1.0,
            confidence,
        })
    }

    /// An input from a successful shift `shifted` (into the receiver) of the reservoir `source`:
    /// the receiver's target and the Jacobian come from the shift, `W_i` and `c_i` from the
    /// reservoir, so none of them can take another's place.
    pub fn from_shift(shifted: Shifted<S>, source: &Reservoir<S>) -> Self {
        Self {
            sample: shifted.sample,
            receiver_target: shifted.destination_target,
            ucw: source.ucw,
            jacobian: shifted.jacobian,
            confidence: source.confidence,
        }
    }

    /// `w_i = m_i · p̂_c(Y_i) · W_i · J_i` in `f64`. Negative, NaN and infinite factors give 0.
    #[inline]
    pub fn resampling_weight(&self, mis_weight: f32) -> f64 {
        let w = clean(mis_weight)
            * clean(self.receiver_target)
            * clean(self.ucw)
            * clean(self.jacobian);
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
/// let canonical = Reservoir { sample: Some(0.5f32), ucw: 2.0, confidence: 1.0, own_target: 0.5 };
/// let neighbor = GrisInput { sample: 0.8f32, receiver_target: 0.8, ucw: 1.5, jacobian: 1.0, confidence: 1.0 };
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

    /// Streams one input with MIS weight `mis_weight = m_i(Y_i)` and uniform `u ∈ [0, 1)`
    /// (`f32` or `f64`, see [`Uniform`]). Adds `input.confidence` to the output confidence.
    /// Returns `true` if it was selected.
    #[inline]
    pub fn add(&mut self, input: GrisInput<S>, mis_weight: f32, u: impl Uniform) -> bool {
        self.add_observed(input, mis_weight, u, &mut |_: &S, _: f64| {})
    }

    /// [`add`](Self::add), telling `observe` the input's shifted sample and its resampling
    /// weight `w_i` first (see [`resample_observed`]).
    #[inline]
    pub fn add_observed(
        &mut self,
        input: GrisInput<S>,
        mis_weight: f32,
        u: impl Uniform,
        observe: &mut impl FnMut(&S, f64),
    ) -> bool {
        let w = input.resampling_weight(mis_weight);
        if w > 0.0 {
            observe(&input.sample, w);
        }
        let index = self.inputs;
        self.inputs += 1;
        let taken = self.stream.push(
            input.sample,
            input.receiver_target,
            w,
            input.confidence,
            u.to_f64(),
        );
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

    /// The receiver's target `p̂_c` at the selected sample.
    pub fn selected_receiver_target(&self) -> f32 {
        self.stream.selected_target()
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
    /// after selection (`1/Σc` for constant MIS, [`crate::mis::one_over_z`],
    /// [`crate::mis::contribution_scale`], `1/n` or `1/(n+1)` for pairwise).
    pub fn finalize_scaled(self, scale: f32) -> Reservoir<S> {
        let t = self.stream.selected_target();
        self.stream.finalize_scaled(t, scale)
    }
}
