//! Reservoirs and generalized resampled importance sampling (GRIS) as a small, reusable core.
//!
//! `restir-gris` is the renderer-independent heart of a ReSTIR implementation: reservoirs,
//! streaming RIS (weighted reservoir sampling), GRIS resampling of reservoirs across domains,
//! the resampling MIS weights, confidence (M) capping, the shift-map contract and the standard
//! shift Jacobians. It is generic over the sample payload (a light sample, a path descriptor,
//! anything) and has no dependencies.
//!
//! # `no_std`
//!
//! The crate is `no_std` **only with `default-features = false`**: the default `std` feature
//! links `std` and adds the two helpers that need a square root,
#![cfg_attr(
    feature = "std",
    doc = "[`jacobian::reconnection_jacobian_from_points`] and [`jacobian::geometry_term`]."
)]
#![cfg_attr(
    not(feature = "std"),
    doc = "`jacobian::reconnection_jacobian_from_points` and `jacobian::geometry_term` (not built here)."
)]
//! For a `no_std` target depend on it as
//!
//! ```toml
//! restir-gris = { version = "0.1", default-features = false }
//! ```
//!
//! Everything else (reservoirs, resampling, MIS weights, the other Jacobians) is available
//! either way.

//! # Example: RIS on a 1-D integral, then reuse across two domains with GRIS
//!
//! ```
//! use restir_gris::{mis, GrisInput, GrisResampler, Reservoir, StreamingReservoir};
//!
//! // A tiny deterministic RNG for the example (bring your own in a renderer).
//! struct Rng(u64);
//! impl Rng {
//!     fn next_f32(&mut self) -> f32 {
//!         self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
//!         (self.0 >> 40) as f32 / (1u64 << 24) as f32
//!     }
//! }
//!
//! // Integrand on [0, 1] with ∫ f = 1, and two domains A and B whose targets differ.
//! let f = |x: f32| 3.0 * x * x;
//! let target_a = |x: f32| x;
//! let target_b = |x: f32| x * x;
//!
//! // Streaming RIS: N uniform candidates (pdf 1), resampling weight m·p̂(x)/p(x) with m = 1/N.
//! let ris = |rng: &mut Rng, target: &dyn Fn(f32) -> f32| -> Reservoir<f32> {
//!     const N: usize = 4;
//!     let mut stream = StreamingReservoir::new();
//!     for _ in 0..N {
//!         let x = rng.next_f32();
//!         let u = rng.next_f32();
//!         stream.add_candidate(x, target(x), target(x) / N as f32, 1.0, u);
//!     }
//!     stream.finalize_recorded() // W = weight_sum / p̂(Y)
//! };
//!
//! let mut rng = Rng(7);
//! let trials = 20_000;
//! let (mut ris_sum, mut gris_sum) = (0.0f64, 0.0f64);
//! for _ in 0..trials {
//!     // 1. Plain RIS in domain A: E[f(Y)·W] = ∫ f.
//!     let a = ris(&mut rng, &target_a);
//!     if let Some(y) = a.sample {
//!         ris_sum += f64::from(f(y) * a.ucw);
//!     }
//!
//!     // 2. GRIS at receiver A, reusing B's reservoir. The shift is the identity (J = 1), so the
//!     //    pulled-back target of B is p̂_B itself. Generalized balance MIS:
//!     //    m_i(y) = c_i·p̂_{←i}(y) / Σ_j c_j·p̂_{←j}(y).
//!     let b = ris(&mut rng, &target_b);
//!     let confidences = [a.confidence, b.confidence];
//!     let mut step = GrisResampler::new();
//!     if let Some(y) = a.sample {
//!         let m = mis::generalized_balance(0, &confidences, &[target_a(y), target_b(y)]);
//!         step.add(GrisInput::canonical(a).unwrap(), m, rng.next_f32());
//!     }
//!     if let Some(x) = b.sample {
//!         // Shift B → A (identity here): the receiver's target at the shifted sample, J = 1.
//!         let input = GrisInput { sample: x, receiver_target: target_a(x), ucw: b.ucw,
//!                                 jacobian: 1.0, confidence: b.confidence };
//!         let m = mis::generalized_balance(1, &confidences, &[target_a(x), target_b(x)]);
//!         step.add(input, m, rng.next_f32());
//!     }
//!     let out = step.finalize(); // W = Σ w_i / p̂_A(Y), confidence = c_A + c_B
//!     assert_eq!(out.confidence, 8.0);
//!     if let Some(y) = out.sample {
//!         gris_sum += f64::from(f(y) * out.ucw);
//!     }
//! }
//! // Both estimators are unbiased; 0.03 is about 8 standard errors here (SE ≈ 0.004).
//! assert!((ris_sum / trials as f64 - 1.0).abs() < 0.03);
//! assert!((gris_sum / trials as f64 - 1.0).abs() < 0.03);
//! ```
//!
//! With a [`ShiftMap`] implementation, [`resample`] does the whole GRIS step for any
//! [`MisScheme`]; [`PairwiseResampler`] is the streaming form a spatial-reuse pass uses (a
//! runnable spatial-reuse example: `cargo run -p restir-gris --example pairwise`, source in
//! `crates/gris/examples/pairwise.rs`). [`resample_observed`] also reports every input with its
//! resampling weight, from which a renderer shades the selection's expectation instead of the
//! selected sample (the same mean, no more variance; `docs/GRIS.md` §3.3).
//!
//! # Which target is which
//!
//! Four different target values meet in a GRIS step; each has its own name, saying whose target
//! it is and at which sample (all are in the measure of the domain they belong to):
//!
//! | name | value | where |
//! |---|---|---|
//! | [`Reservoir::own_target`] | `p̂_i(X_i)`: the owning domain's target at its own sample | stored reservoirs, [`StreamingReservoir::add_candidate`] |
//! | [`Shifted::destination_target`] | `p̂_j(T_{i→j}(x))`: the destination's target at the shifted sample | what a [`ShiftMap`] returns |
//! | [`GrisInput::receiver_target`] | `p̂_c(Y_i)`: the receiver's target at a shifted input | [`GrisResampler`] inputs (= the forward shift's `destination_target`) |
//! | `pulled_back_target_at_canonical` ([`PairwiseNeighbor::new`]) | `p̂_{←i}(X_c) = p̂_i(T_{c→i}(X_c))·J_{c→i}`: a neighbour's target pulled back to the canonical sample | [`Shifted::pulled_back_target_pdf`], [`ShiftMap::pulled_back_target_pdf`] |
//!
//! # Common mistakes, and what catches them
//!
//! Each is exercised by a test in `tests/mistakes.rs`.
//!
//! 1. **The receiver's target where the neighbour's own target belongs** (pairwise MIS then
//!    weights the wrong pair and is biased by several percent with no other symptom).
//!    [`PairwiseNeighbor`] has private fields and is built by [`PairwiseNeighbor::new`] from the
//!    neighbour's [`Reservoir`]: its own target, `W` and confidence come from there, the
//!    receiver's target from the [`Shifted`] forward shift, and only the pulled-back value is a
//!    bare number, so the two cannot be exchanged. Likewise [`GrisInput::from_shift`] takes the
//!    source [`Reservoir`] rather than loose `ucw` and `confidence` numbers.
//! 2. **[`StreamingReservoir::add`] followed by [`StreamingReservoir::finalize_recorded`]**:
//!    `add` records no target, so there is nothing to divide by. A `debug_assert!` fails in
//!    debug builds (release builds return an empty reservoir, as documented). Use
//!    [`StreamingReservoir::add_candidate`], or [`StreamingReservoir::finalize`] with the target.
//! 3. **A uniform outside `[0, 1)`** (a raw `u32`, or `u = 1`): only `f32` and `f64` are
//!    accepted ([`Uniform`] is sealed), and a `debug_assert!` checks the range.
//! 4. **A 24-bit uniform for a stream whose weights span many decades**: candidates lighter than
//!    `2^-24` of the running sum are then over-selected. Pass an `f64` uniform
//!    ([`uniform_f64`]); see [`Uniform`].
//! 5. **Skipping empty or failed neighbours** in a pairwise step: their canonical share is then
//!    missing and the weights no longer sum to one. Add them with a `None` shift (this cannot be
//!    detected; the statistical tests show the bias).
//!
//! Mistakes 1 and 3 do not compile:
//!
//! ```compile_fail,E0451
//! use restir_gris::PairwiseNeighbor;
//! // The fields are private: a neighbour cannot be assembled from loose (swappable) numbers.
//! let n: PairwiseNeighbor<f32> = PairwiseNeighbor {
//!     shifted: None, ucw: 1.0, confidence: 1.0, own_target: 0.5,
//!     pulled_back_target_at_canonical: 0.2,
//! };
//! ```
//!
//! ```compile_fail,E0277
//! let mut s = restir_gris::StreamingReservoir::new();
//! s.add(0u8, 1.0, 12345u32); // a raw integer is not a uniform in [0, 1)
//! ```
//!
//! # Saturation
//!
//! Confidences are accumulated in `f64` (unit increments are counted exactly far beyond `2^24`)
//! and stored as `f32` saturated at `f32::MAX`, never infinite; an infinite increment saturates
//! too. Targets and weights that would not be finite are rejected (the sample is dropped, the
//! confidence kept): no public function returns NaN or infinity for finite inputs.
//!
//! # Conventions (stated once, used everywhere)
//!
//! * **Targets and measures.** Each domain has a scalar target `p̂ ≥ 0` (e.g. the luminance of its
//!   integrand). A reservoir's `ucw` (`W`) is an unbiased estimate of `1/p(Y)` in the **same
//!   measure** as that domain's target (solid angle, area, or primary sample space), so
//!   `E[f(Y)·W] = ∫ f`. Jacobians convert between the measures of two domains; functions name
//!   their measure (`_solid_angle`, `_area`, `_pss`; arguments `pdf_sa`, `pdf_area`).
//! * **Pulled-back targets.** MIS weights at a point `y` of the receiving domain `c` use
//!   `p̂_{←j}(y) = p̂_j(T_{c→j}(y))·J_{c→j}(y)` (0 if the inverse shift fails) — never the donor's
//!   stale value.
//! * **Random numbers come in as arguments** (`u ∈ [0, 1)`, or a `FnMut() -> f32` source for
//!   whole steps), so results are repeatable and replayable. No RNG lives in this crate.
//! * **Precision.** Stored values are `f32`; running sums (`weight_sum`, confidence) and
//!   products of weights are `f64`. Zero, negative, NaN and infinite candidates count towards
//!   confidence but are never selected and never enter `weight_sum`; no public function returns
//!   NaN or infinity (see *Saturation* above).
//!
//! # What the caller must guarantee for unbiasedness (Lin et al. 2022; `docs/GRIS.md` §3.1)
//!
//! 1. Every input `W_i` is a valid unbiased contribution weight for `X_i` in its own domain
//!    (inputs may be correlated).
//! 2. The MIS weights form a partition of unity over the techniques that can produce each `y`:
//!    use the functions in [`mis`] with the **same** neighbour list and confidences for every
//!    candidate, and list empty/failed neighbours too. [`MisScheme::ConstantBiased`] does not
//!    satisfy this across differing domains and is labelled biased.
//! 3. The canonical (receiving) domain's own reservoir takes part and its target is positive
//!    wherever the integrand is non-zero.
//! 4. Shifts are bijections with true inverses (`J_{c→i}(T_{i→c}(x)) = 1/J_{i→c}(x)`) and fail
//!    symmetrically; see [`ShiftMap`] and [`jacobian::reject_jacobian`].
//! 5. Each domain's target is evaluated with that domain's data (previous-frame data for
//!    temporal neighbours), and the receiver's `p̂_c` in the resampling weights and in
//!    `W = Σ w / p̂_c(Y)` is the same function.
//! 6. The uniform numbers passed in are independent of each other and of the candidates.
//!
//! # References
//!
//! Citations like "`docs/GRIS.md` §4.5" point to the derivations shipped with the source
//! repository (<https://github.com/restir-rs/restir/blob/main/docs/GRIS.md>), written in this
//! crate's notation. The papers:
//!
//! * J. Talbot, D. Cline, P. Egbert, "Importance Resampling for Global Illumination", EGSR 2005
//!   (resampled importance sampling).
//! * B. Bitterli, C. Wyman, M. Pharr, P. Shirley, A. Lefohn, W. Jarosz, "Spatiotemporal reservoir
//!   resampling for real-time ray tracing with dynamic direct lighting", ACM TOG 39(4), 2020
//!   (streaming RIS, reservoir reuse, the 1/Z and MIS-like unbiased combinations).
//! * D. Lin, M. Kettunen, B. Bitterli, J. Pantaleoni, C. Yuksel, C. Wyman, "Generalized Resampled
//!   Importance Sampling: Foundations of ReSTIR", ACM TOG 41(4), 2022 (GRIS, shift maps and
//!   their Jacobians, defensive pairwise MIS, ReSTIR PT).
//! * B. Bitterli, "Correlations and Reuse for Fast and Accurate Physically Based Light
//!   Transport", PhD thesis, Dartmouth College, 2022, §9.1 (pairwise MIS).
//! * C. Wyman, M. Kettunen, D. Lin, B. Bitterli, C. Yuksel, W. Jarosz, P. Kozlowski,
//!   G. De Francesco, "A Gentle Introduction to ReSTIR: Path Reuse in Real-time", SIGGRAPH 2023
//!   Courses (the reservoir conventions used here; confidence-weighted pairwise MIS).
//!
//! # Modules
//!
//! * [`reservoir`] — [`Reservoir`] (stored) and [`StreamingReservoir`] (running WRS state).
//! * [`resampling`] — [`GrisResampler`], [`PairwiseResampler`], [`resample`],
//!   [`resample_observed`].
//! * [`mis`] — every MIS weight with its formula and source; [`MisScheme`].
//! * [`confidence`] — M-capping.
//! * [`shift`] — the [`ShiftMap`] contract and [`Shifted`].
//! * [`jacobian`] — reconnection (solid angle, area, PSS), random replay, symmetric rejection.
#![cfg_attr(not(feature = "std"), no_std)]
#![deny(missing_docs)]
// `!(x > 0.0)` is deliberate throughout: it is true for NaN, which must be rejected too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod confidence;
pub mod jacobian;
pub mod mis;
pub mod resampling;
pub mod reservoir;
pub mod shift;

pub use confidence::{cap_confidence, cap_confidence_relative};
pub use mis::MisScheme;
pub use resampling::{
    GrisInput, GrisResampler, PairwiseNeighbor, PairwiseResampler, PairwiseVariant, resample,
    resample_observed,
};
pub use reservoir::{Reservoir, StreamingReservoir, Uniform, uniform_f64};
pub use shift::{ShiftMap, Shifted};

// Runs the README's example as a doc test.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
