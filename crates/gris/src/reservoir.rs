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
//!   weight `ucw` (`W`), its `confidence` (`M`) and its own domain's target value `own_target`
//!   at the selected sample. Reservoirs are what a renderer keeps between passes and what GRIS resamples.
//!
//! Converting one into the other is [`StreamingReservoir::finalize`] (`W = weight_sum / p̂(Y)`).

/// A finalised reservoir: one selected sample and its unbiased contribution weight.
///
/// Invariants kept by every constructor in this crate:
///
/// * `ucw` (`W`) is finite and `≥ 0`; `sample == None` implies `ucw == 0`;
/// * `confidence` (`M`) is finite and `≥ 0`; it is a float because capping and pairwise
///   heuristics produce fractional values. Sums of confidences saturate at `f32::MAX` (they are
///   accumulated in `f64`, so unit increments count exactly far past `2^24`);
/// * `own_target` is `p̂_own(Y)`: the target function of the domain that **owns** the reservoir,
///   evaluated at the selected sample, in that domain's measure (0 when empty). It is finite.
///   The resampling drivers use it as the neighbour's `p̂_i(X_i)` (or the canonical `p̂_c(X_c)`),
///   so it must be the same function the shift map evaluates for that domain. It is **not** the
///   receiver's target at a shifted sample (that is [`GrisInput::receiver_target`]) nor a
///   pulled-back target.
///
/// [`GrisInput::receiver_target`]: crate::GrisInput::receiver_target
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
    /// The owning domain's target `p̂_own(Y)` at the selected sample (its own measure).
    pub own_target: f32,
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
            own_target: 0.0,
        }
    }

    /// A reservoir holding one sample drawn directly from a source pdf `pdf` (in the measure of the
    /// domain's target), i.e. `W = 1/pdf`, with confidence 1; `own_target` is the owning domain's
    /// target at `sample` (NaN and negative values are stored as 0).
    ///
    /// Returns an empty reservoir (confidence 1) when `pdf` is not finite and positive, when
    /// `1/pdf` overflows `f32`, or when `own_target` is infinite (rejected, never stored).
    pub fn from_source_sample(sample: S, pdf: f32, own_target: f32) -> Self {
        let ucw = if pdf > 0.0 && pdf.is_finite() {
            1.0 / pdf
        } else {
            0.0
        };
        if !(ucw > 0.0 && ucw.is_finite() && own_target < f32::INFINITY) {
            return Self {
                confidence: 1.0,
                ..Self::empty()
            };
        }
        Self {
            sample: Some(sample),
            ucw,
            confidence: 1.0,
            own_target: sanitize_non_negative(own_target),
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
            own_target: self.own_target,
        }
    }
}

/// A uniform random number in `[0, 1)` passed to a selection step: `f32` or `f64`.
///
/// The selection test is `u · weight_sum < w` in `f64`, so a candidate is taken with probability
/// `w / weight_sum` only to the resolution of `u`. A typical `f32` uniform has 24 random bits:
/// a candidate whose weight is below about `2^-24` of the running sum is then taken with
/// probability `≈ 2^-24` instead (one heavy candidate followed by 10⁷ light ones: the light
/// ones together are taken with probability 0.45 instead of 0.0099). Pass an `f64` with 53
/// random bits ([`uniform_f64`]) when weights may span more than about 7 decades within one
/// stream; both give identical results for the same value.
///
/// Sealed: only `f32` and `f64` implement it, so a raw integer random number cannot be passed
/// by mistake.
pub trait Uniform: Copy + sealed::Sealed {
    /// The value as `f64`.
    fn to_f64(self) -> f64;
}

impl Uniform for f32 {
    #[inline]
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
}

impl Uniform for f64 {
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

/// A uniform number in `[0, 1)` with 53 random bits from the top bits of a random `u64` (for
/// the selection steps' `u`, see [`Uniform`]).
#[inline]
pub fn uniform_f64(bits: u64) -> f64 {
    (bits >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Target value stored for a candidate streamed with [`StreamingReservoir::add`], which records
/// none: NaN, so that [`StreamingReservoir::finalize_recorded`] can tell.
const UNRECORDED: f32 = f32::NAN;

/// Saturating `f64 → f32` for confidences: `[0, f32::MAX]`, never infinite.
#[inline]
pub(crate) fn saturate_confidence(c: f64) -> f32 {
    if c < f64::from(f32::MAX) {
        c as f32
    } else {
        f32::MAX
    }
}

/// Running state of one weighted-reservoir-sampling pass (streaming RIS).
///
/// Each candidate comes with its *resampling weight* `w` (for RIS, `w = m·p̂(x)·W_x`, e.g.
/// `p̂(x)/(N·p(x))` for `N` i.i.d. candidates from pdf `p`), a confidence increment and a uniform
/// random number `u ∈ [0, 1)` supplied by the caller (`f32` or `f64`, see [`Uniform`]). A
/// candidate is selected with probability `w / weight_sum`, which makes the final selection law
/// `w_i / Σ_j w_j` (tested by chi-square tests in `tests/statistics.rs`, one of them over 10⁷
/// candidates whose weights span 10⁻³⁰…10³⁰ with [`uniform_f64`]).
///
/// Candidates whose weight is zero, negative, NaN or infinite still add their confidence but are
/// never selected and never enter `weight_sum`. Confidence is accumulated in `f64` (exact for
/// unit increments up to `2^53`) and read out saturated to `f32::MAX`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StreamingReservoir<S> {
    selected: Option<S>,
    selected_target: f32,
    weight_sum: f64,
    confidence: f64,
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
            selected_target: 0.0,
            weight_sum: 0.0,
            confidence: 0.0,
        }
    }

    /// Streams one candidate with confidence increment 1. Returns `true` if it was selected.
    ///
    /// `u` must be uniform in `[0, 1)` and independent of everything else in the stream (checked
    /// by a `debug_assert!`). The target value of the selected sample is **not** recorded: finish
    /// with [`Self::finalize`] (which takes it), not [`Self::finalize_recorded`] (a
    /// `debug_assert!` catches that mix-up), or use [`Self::add_candidate`] to have it recorded.
    #[inline]
    pub fn add(&mut self, sample: S, resampling_weight: f32, u: impl Uniform) -> bool {
        self.push(
            sample,
            UNRECORDED,
            f64::from(resampling_weight),
            1.0,
            u.to_f64(),
        )
    }

    /// Streams one candidate, recording its target value `own_target` (`p̂` of this stream's
    /// domain at `sample`) and adding `confidence` to the stream's confidence.
    ///
    /// Returns `true` if the candidate was selected. See [`Self::add`] for the contract on `u`.
    #[inline]
    pub fn add_candidate(
        &mut self,
        sample: S,
        own_target: f32,
        resampling_weight: f32,
        confidence: f32,
        u: impl Uniform,
    ) -> bool {
        self.push(
            sample,
            own_target,
            f64::from(resampling_weight),
            confidence,
            u.to_f64(),
        )
    }

    /// Core update in `f64` (products of `f32` factors cannot overflow here).
    #[inline]
    pub(crate) fn push(
        &mut self,
        sample: S,
        target: f32,
        resampling_weight: f64,
        confidence: f32,
        u: f64,
    ) -> bool {
        debug_assert!(
            (0.0..1.0).contains(&u),
            "restir-gris: the uniform u = {u} passed to a selection step is not in [0, 1)"
        );
        self.confidence += f64::from(sanitize_non_negative(confidence));
        // NaN fails `> 0`; infinity fails `is_finite`: neither may poison the sum.
        if !(resampling_weight > 0.0 && resampling_weight.is_finite()) {
            return false;
        }
        self.weight_sum += resampling_weight;
        // Strict `<` with an explicit `w > 0` above: a zero-weight candidate is never selected.
        // The first positive candidate is always taken, even if the caller passed `u = 1`.
        if self.selected.is_none() || u * self.weight_sum < resampling_weight {
            self.selected = Some(sample);
            self.selected_target = target;
            true
        } else {
            false
        }
    }

    /// Adds confidence without a candidate (e.g. a neighbour whose shift failed, when the caller
    /// decides it still counts towards `M`).
    #[inline]
    pub fn add_confidence(&mut self, confidence: f32) {
        self.confidence += f64::from(sanitize_non_negative(confidence));
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
    pub fn merge(&mut self, other: StreamingReservoir<S>, u: impl Uniform) -> bool {
        let u = u.to_f64();
        debug_assert!(
            (0.0..1.0).contains(&u),
            "restir-gris: the uniform u = {u} passed to merge is not in [0, 1)"
        );
        self.confidence += other.confidence;
        let Some(sample) = other.selected else {
            return false;
        };
        let w = other.weight_sum;
        if !(w > 0.0 && w.is_finite()) {
            return false;
        }
        self.weight_sum += w;
        if self.selected.is_none() || u * self.weight_sum < w {
            self.selected = Some(sample);
            self.selected_target = other.selected_target;
            true
        } else {
            false
        }
    }

    /// Running sum of the accepted resampling weights, in `f64`.
    pub fn weight_sum(&self) -> f64 {
        self.weight_sum
    }

    /// Accumulated confidence `M` (sum of all increments, selected or not), saturated to
    /// `f32::MAX`: never infinite.
    pub fn confidence(&self) -> f32 {
        saturate_confidence(self.confidence)
    }

    /// The currently selected candidate.
    pub fn selected(&self) -> Option<&S> {
        self.selected.as_ref()
    }

    /// The target value recorded with the selected candidate (0 if it was added with
    /// [`Self::add`], which records none, or if nothing is selected).
    pub fn selected_target(&self) -> f32 {
        if self.selected_target.is_nan() {
            0.0
        } else {
            self.selected_target
        }
    }

    /// Finalises with `W = weight_sum / own_target`, where `own_target = p̂(Y)` is the target of
    /// this stream's domain at the selected sample.
    ///
    /// This is the GRIS form: the resampling weights must already contain normalised MIS weights
    /// (e.g. `1/N` for `N` i.i.d. candidates). For the legacy `1/M` form use
    /// [`Self::finalize_scaled`] with `scale = 1/M`.
    ///
    /// The result is empty (`W = 0`, sample dropped, confidence kept) if nothing was selected, if
    /// `own_target` is not finite and positive, or if `W` would not be a finite `f32`
    /// (`weight_sum / own_target > f32::MAX`). The last case cannot happen with consistent inputs
    /// unless the true `1/p(Y)` itself exceeds `f32::MAX`. The output confidence is finite
    /// (saturated at `f32::MAX`).
    pub fn finalize(self, own_target: f32) -> Reservoir<S> {
        self.finalize_scaled(own_target, 1.0)
    }

    /// Finalises with the target value recorded by [`Self::add_candidate`].
    ///
    /// Every candidate must have been streamed with [`Self::add_candidate`] (or merged from such
    /// a stream): if the selected one came from [`Self::add`], which records no target, this is
    /// a `debug_assert!` failure in debug builds and an empty reservoir in release builds. Use
    /// [`Self::finalize`] with the target for streams built with `add`.
    pub fn finalize_recorded(self) -> Reservoir<S> {
        debug_assert!(
            self.selected.is_none() || !self.selected_target.is_nan(),
            "restir-gris: finalize_recorded() after add(), which records no target: \
             use add_candidate(), or finalize(target)"
        );
        let target = self.selected_target;
        self.finalize_scaled(target, 1.0)
    }

    /// Finalises with `W = weight_sum · scale / own_target`.
    ///
    /// `scale` carries a normalisation that is common to all candidates and applied after
    /// selection: `1/M` for the (biased) constant scheme, `1/Z` for [`crate::mis::one_over_z`],
    /// the contribution-MIS factor of [`crate::mis::contribution_scale`], or `1/(n+1)` for
    /// defensive pairwise MIS. Same emptiness rules as [`Self::finalize`].
    pub fn finalize_scaled(self, own_target: f32, scale: f32) -> Reservoir<S> {
        let confidence = saturate_confidence(self.confidence);
        let empty = Reservoir {
            confidence,
            ..Reservoir::empty()
        };
        let Some(sample) = self.selected else {
            return empty;
        };
        if !(own_target > 0.0 && own_target.is_finite() && scale >= 0.0 && scale.is_finite()) {
            return empty;
        }
        let ucw = (self.weight_sum * f64::from(scale) / f64::from(own_target)) as f32;
        if !(ucw > 0.0 && ucw.is_finite()) {
            return empty;
        }
        Reservoir {
            sample: Some(sample),
            ucw,
            confidence,
            own_target,
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
        assert_eq!(r.own_target, 2.0);
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
            (r.sample, r.ucw, r.confidence, r.own_target),
            (Some(7), 4.0, 1.0, 3.0)
        );
        let r = Reservoir::from_source_sample(7u8, 0.0, 3.0);
        assert!(r.is_empty() && r.ucw == 0.0 && r.confidence == 1.0);
    }
}
