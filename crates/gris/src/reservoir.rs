//! Stored reservoirs and streaming weighted reservoir sampling (WRS).
//!
//! Implements the reservoir definitions in the course-notes / GRIS form (Lin et al. 2022,
//! "Generalized Resampled Importance Sampling"; Wyman et al. 2023, "A Gentle Introduction to
//! ReSTIR"), with RIS from Talbot et al. 2005 and streaming from Bitterli et al. 2020;
//! derivations in `docs/GRIS.md` §2.
//!
//! Two types, kept apart on purpose:
//!
//! * [`StreamingReservoir`] is the *running* state of one resampling pass: the selected candidate,
//!   the running `weight_sum` (accumulated in `f64`) and the accumulated confidence. It can take
//!   more candidates ([`StreamingReservoir::add`]) or be concatenated with another stream over a
//!   disjoint candidate set ([`StreamingReservoir::merge`]).
//! * [`Reservoir`] is the *finalised*, storable result: a sample with its unbiased contribution
//!   weight `ucw` (`W`), its `confidence` (`M`) and the target value `target_pdf` at the selected
//!   sample. Reservoirs are what a renderer keeps between passes and what GRIS resamples.
//!
//! Converting one into the other is [`StreamingReservoir::finalize`] (`W = weight_sum / p̂(Y)`).

/// A finalised reservoir: one selected sample and its unbiased contribution weight.
///
/// Invariants kept by every constructor in this crate:
///
/// * `ucw` (`W`) is finite and `≥ 0`; `sample == None` implies `ucw == 0`;
/// * `confidence` (`M`) is finite and `≥ 0`; it is a float because capping and pairwise
///   heuristics produce fractional values;
/// * `target_pdf` is `p̂(Y)`, the target function of the domain that owns the reservoir evaluated
///   at the selected sample (0 when empty). The MIS helpers in [`crate::resampling`] use it as
///   `p̂_i(X_i)`, so it must be the same function the shift map evaluates for that domain.
///
/// `E[f(Y)·W] = ∫ f` over the support of the target whenever the reservoir came out of an
/// unbiased (G)RIS step (see the crate docs for what the caller must guarantee).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reservoir<S> {
    /// The selected sample `Y`, or `None` for an empty reservoir.
    pub sample: Option<S>,
    /// Unbiased contribution weight `W_Y` (an unbiased estimate of `1/p(Y)`, in the measure of the
    /// domain's target function).
    pub ucw: f32,
    /// Confidence weight `M` (historically the number of candidates summarised).
    pub confidence: f32,
    /// Target function value `p̂(Y)` at the selected sample, in the owning domain.
    pub target_pdf: f32,
}

impl<S> Default for Reservoir<S> {
    fn default() -> Self {
        Self::empty()
    }
}

impl<S> Reservoir<S> {
    /// An empty reservoir: no sample, `W = 0`, `M = 0`.
    pub const fn empty() -> Self {
        Self {
            sample: None,
            ucw: 0.0,
            confidence: 0.0,
            target_pdf: 0.0,
        }
    }

    /// A reservoir holding one sample drawn directly from a source pdf `pdf` (in the measure of the
    /// domain's target), i.e. `W = 1/pdf`, with confidence 1.
    ///
    /// Returns an empty reservoir (confidence 1) when `pdf` is not finite and positive.
    pub fn from_source_sample(sample: S, pdf: f32, target_pdf: f32) -> Self {
        let ucw = if pdf > 0.0 && pdf.is_finite() {
            1.0 / pdf
        } else {
            0.0
        };
        if !(ucw > 0.0 && ucw.is_finite()) {
            return Self {
                confidence: 1.0,
                ..Self::empty()
            };
        }
        Self {
            sample: Some(sample),
            ucw,
            confidence: 1.0,
            target_pdf: sanitize_non_negative(target_pdf),
        }
    }

    /// `true` when no sample is selected (or its weight is zero).
    pub fn is_empty(&self) -> bool {
        self.sample.is_none() || !(self.ucw > 0.0)
    }

    /// The selected sample, if any.
    pub fn sample(&self) -> Option<&S> {
        self.sample.as_ref()
    }

    /// The same reservoir with its confidence replaced by `min(confidence, cap)`
    /// (see [`crate::confidence::cap_confidence`]). `W` is untouched: capping changes only the
    /// MIS weights of later resampling steps, never the unbiasedness of this reservoir.
    #[must_use]
    pub fn with_confidence_cap(mut self, cap: f32) -> Self {
        self.confidence = crate::confidence::cap_confidence(self.confidence, cap);
        self
    }

    /// Maps the sample payload, keeping `W`, `M` and `p̂`.
    pub fn map_sample<T>(self, f: impl FnOnce(S) -> T) -> Reservoir<T> {
        Reservoir {
            sample: self.sample.map(f),
            ucw: self.ucw,
            confidence: self.confidence,
            target_pdf: self.target_pdf,
        }
    }
}

/// Running state of one weighted-reservoir-sampling pass (streaming RIS).
///
/// Each candidate comes with its *resampling weight* `w` (for RIS, `w = m·p̂(x)·W_x`, e.g.
/// `p̂(x)/(N·p(x))` for `N` i.i.d. candidates from pdf `p`), a confidence increment and a uniform
/// random number `u ∈ [0, 1)` supplied by the caller. A candidate is selected with probability
/// `w / weight_sum`, which makes the final selection law `w_i / Σ_j w_j` (tested by a chi-square
/// test in `tests/statistics.rs`).
///
/// Candidates whose weight is zero, negative, NaN or infinite still add their confidence but are
/// never selected and never enter `weight_sum`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StreamingReservoir<S> {
    selected: Option<S>,
    selected_target_pdf: f32,
    weight_sum: f64,
    confidence: f32,
}

impl<S> Default for StreamingReservoir<S> {
    fn default() -> Self {
        Self::new()
    }
}

impl<S> StreamingReservoir<S> {
    /// An empty stream (`weight_sum = 0`, `M = 0`).
    pub const fn new() -> Self {
        Self {
            selected: None,
            selected_target_pdf: 0.0,
            weight_sum: 0.0,
            confidence: 0.0,
        }
    }

    /// Streams one candidate with confidence increment 1. Returns `true` if it was selected.
    ///
    /// `u` must be uniform in `[0, 1)` and independent of everything else in the stream. The
    /// target value of the selected sample is not recorded; pass it to [`Self::finalize`], or use
    /// [`Self::add_candidate`] to have it recorded.
    #[inline]
    pub fn add(&mut self, sample: S, resampling_weight: f32, u: f32) -> bool {
        self.push(sample, 0.0, f64::from(resampling_weight), 1.0, u)
    }

    /// Streams one candidate, recording its target value `target_pdf` (`p̂` of this stream's
    /// domain at `sample`) and adding `confidence` to the stream's confidence.
    ///
    /// Returns `true` if the candidate was selected. See [`Self::add`] for the contract on `u`.
    #[inline]
    pub fn add_candidate(
        &mut self,
        sample: S,
        target_pdf: f32,
        resampling_weight: f32,
        confidence: f32,
        u: f32,
    ) -> bool {
        self.push(
            sample,
            target_pdf,
            f64::from(resampling_weight),
            confidence,
            u,
        )
    }

    /// Core update in `f64` (products of `f32` factors cannot overflow here).
    #[inline]
    pub(crate) fn push(
        &mut self,
        sample: S,
        target_pdf: f32,
        resampling_weight: f64,
        confidence: f32,
        u: f32,
    ) -> bool {
        self.confidence += sanitize_non_negative(confidence);
        // NaN fails `> 0`; infinity fails `is_finite`: neither may poison the sum.
        if !(resampling_weight > 0.0 && resampling_weight.is_finite()) {
            return false;
        }
        self.weight_sum += resampling_weight;
        // Strict `<` with an explicit `w > 0` above: a zero-weight candidate is never selected.
        // The first positive candidate is always taken, even if the caller passed `u = 1`.
        if self.selected.is_none() || f64::from(u) * self.weight_sum < resampling_weight {
            self.selected = Some(sample);
            self.selected_target_pdf = target_pdf;
            true
        } else {
            false
        }
    }

    /// Adds confidence without a candidate (e.g. a neighbour whose shift failed, when the caller
    /// decides it still counts towards `M`).
    #[inline]
    pub fn add_confidence(&mut self, confidence: f32) {
        self.confidence += sanitize_non_negative(confidence);
    }

    /// Stream merge: concatenates `other` (a stream over a candidate set disjoint from this one's,
    /// resampled for the **same** target) into `self`.
    ///
    /// Afterwards `weight_sum = w_a + w_b`, `confidence = c_a + c_b`, and `other`'s selection is
    /// taken with probability `w_b / (w_a + w_b)`, which is exactly the law of having streamed
    /// all candidates one by one. Returns `true` if `other`'s sample was taken.
    ///
    /// This is *not* GRIS reservoir reuse; to resample finalised reservoirs from other domains use
    /// [`crate::resampling`].
    pub fn merge(&mut self, other: StreamingReservoir<S>, u: f32) -> bool {
        self.confidence += other.confidence;
        let Some(sample) = other.selected else {
            return false;
        };
        let w = other.weight_sum;
        if !(w > 0.0 && w.is_finite()) {
            return false;
        }
        self.weight_sum += w;
        if self.selected.is_none() || f64::from(u) * self.weight_sum < w {
            self.selected = Some(sample);
            self.selected_target_pdf = other.selected_target_pdf;
            true
        } else {
            false
        }
    }

    /// Running sum of the accepted resampling weights, in `f64`.
    pub fn weight_sum(&self) -> f64 {
        self.weight_sum
    }

    /// Accumulated confidence `M` (sum of all increments, selected or not).
    pub fn confidence(&self) -> f32 {
        self.confidence
    }

    /// The currently selected candidate.
    pub fn selected(&self) -> Option<&S> {
        self.selected.as_ref()
    }

    /// The target value recorded with the selected candidate (0 if it was added with
    /// [`Self::add`], which records none).
    pub fn selected_target_pdf(&self) -> f32 {
        self.selected_target_pdf
    }

    /// Finalises with `W = weight_sum / target_pdf`, where `target_pdf = p̂(Y)` is the target of
    /// this stream's domain at the selected sample.
    ///
    /// This is the GRIS form: the resampling weights must already contain normalised MIS weights
    /// (e.g. `1/N` for `N` i.i.d. candidates). For the legacy `1/M` form use
    /// [`Self::finalize_scaled`] with `scale = 1/M`.
    ///
    /// The result is empty (`W = 0`, sample dropped, confidence kept) if nothing was selected, if
    /// `target_pdf` is not finite and positive, or if `W` would not be a finite `f32`
    /// (`weight_sum / target_pdf > f32::MAX`). The last case cannot happen with consistent inputs
    /// unless the true `1/p(Y)` itself exceeds `f32::MAX`.
    pub fn finalize(self, target_pdf: f32) -> Reservoir<S> {
        self.finalize_scaled(target_pdf, 1.0)
    }

    /// Finalises with the target value recorded by [`Self::add_candidate`].
    pub fn finalize_recorded(self) -> Reservoir<S> {
        let target_pdf = self.selected_target_pdf;
        self.finalize_scaled(target_pdf, 1.0)
    }

    /// Finalises with `W = weight_sum · scale / target_pdf`.
    ///
    /// `scale` carries a normalisation that is common to all candidates and applied after
    /// selection: `1/M` for the (biased) constant scheme, `1/Z` for [`crate::mis::one_over_z`],
    /// the contribution-MIS factor of [`crate::mis::contribution_scale`], or `1/(n+1)` for
    /// defensive pairwise MIS. Same emptiness rules as [`Self::finalize`].
    pub fn finalize_scaled(self, target_pdf: f32, scale: f32) -> Reservoir<S> {
        let empty = Reservoir {
            confidence: self.confidence,
            ..Reservoir::empty()
        };
        let Some(sample) = self.selected else {
            return empty;
        };
        if !(target_pdf > 0.0 && target_pdf.is_finite() && scale >= 0.0 && scale.is_finite()) {
            return empty;
        }
        let ucw = (self.weight_sum * f64::from(scale) / f64::from(target_pdf)) as f32;
        if !(ucw > 0.0 && ucw.is_finite()) {
            return empty;
        }
        Reservoir {
            sample: Some(sample),
            ucw,
            confidence: self.confidence,
            target_pdf,
        }
    }
}

/// Maps NaN and negative values to 0 and keeps everything else (including `+inf`, which callers
/// treat as invalid where it matters).
#[inline]
pub(crate) fn sanitize_non_negative(x: f32) -> f32 {
    if x > 0.0 { x } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_positive_candidate_is_always_selected() {
        let mut s = StreamingReservoir::new();
        assert!(!s.add(0u32, 0.0, 0.0));
        assert!(!s.add(1, f32::NAN, 0.0));
        assert!(!s.add(2, f32::INFINITY, 0.0));
        assert!(!s.add(3, -1.0, 0.0));
        assert!(s.add(4, 2.0, 0.999_999));
        assert_eq!(s.selected(), Some(&4));
        assert_eq!(s.weight_sum(), 2.0);
        assert_eq!(s.confidence(), 5.0);
    }

    #[test]
    fn zero_weight_stream_finalizes_empty_but_keeps_confidence() {
        let mut s = StreamingReservoir::<u8>::new();
        s.add(1, 0.0, 0.5);
        s.add(2, 0.0, 0.5);
        let r = s.finalize(1.0);
        assert!(r.is_empty());
        assert_eq!(r.ucw, 0.0);
        assert_eq!(r.confidence, 2.0);
    }

    #[test]
    fn finalize_divides_by_target() {
        let mut s = StreamingReservoir::new();
        s.add_candidate('a', 2.0, 3.0, 1.0, 0.0);
        let r = s.finalize_recorded();
        assert_eq!(r.sample, Some('a'));
        assert_eq!(r.ucw, 1.5);
        assert_eq!(r.target_pdf, 2.0);
        let mut s = StreamingReservoir::new();
        s.add('a', 3.0, 0.0);
        assert_eq!(s.finalize_scaled(2.0, 0.5).ucw, 0.75);
    }

    #[test]
    fn finalize_rejects_bad_targets_and_overflow() {
        for t in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let mut s = StreamingReservoir::new();
            s.add(1u8, 1.0, 0.0);
            let r = s.finalize(t);
            assert!(r.is_empty() && r.ucw == 0.0 && r.confidence == 1.0);
        }
        let mut s = StreamingReservoir::new();
        s.add(1u8, 1e30, 0.0);
        let r = s.finalize(1e-30);
        assert!(r.is_empty() && r.ucw == 0.0);
    }

    #[test]
    fn merge_adds_sums_and_confidence() {
        let mut a = StreamingReservoir::new();
        a.add(1u8, 1.0, 0.0);
        let mut b = StreamingReservoir::new();
        b.add(2u8, 3.0, 0.0);
        b.add(3u8, 0.0, 0.0);
        // u·4 < 3 ⇔ u < 0.75.
        let mut m = a;
        assert!(m.merge(b, 0.74));
        assert_eq!(m.selected(), Some(&2));
        assert_eq!(m.weight_sum(), 4.0);
        assert_eq!(m.confidence(), 3.0);
        let mut m = a;
        assert!(!m.merge(b, 0.76));
        assert_eq!(m.selected(), Some(&1));
        // Merging into an empty stream always takes the other selection.
        let mut e = StreamingReservoir::new();
        assert!(e.merge(b, 0.99));
        assert_eq!(e.selected(), Some(&2));
    }

    #[test]
    fn source_sample_reservoir() {
        let r = Reservoir::from_source_sample(7u8, 0.25, 3.0);
        assert_eq!(
            (r.sample, r.ucw, r.confidence, r.target_pdf),
            (Some(7), 4.0, 1.0, 3.0)
        );
        let r = Reservoir::from_source_sample(7u8, 0.0, 3.0);
        assert!(r.is_empty() && r.ucw == 0.0 && r.confidence == 1.0);
    }
}
