//! Reservoirs and generalized resampled importance sampling (GRIS) as a small, reusable core.
//!
//! `restir-gris` is the renderer-independent heart of a ReSTIR implementation: reservoirs,
//! streaming RIS (weighted reservoir sampling), GRIS resampling of reservoirs across domains,
//! the resampling MIS weights, confidence (M) capping, the shift-map contract and the standard
//! shift Jacobians. It is generic over the sample payload (a light sample, a path descriptor,
//! anything), has no dependencies and is `no_std`: the default `std` feature only adds the two
//! helpers that need a square root, `jacobian::reconnection_jacobian_from_points` and
//! `jacobian::geometry_term`.
//!
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
//!         let input = GrisInput { sample: x, target_pdf: target_a(x), ucw: b.ucw,
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
//! [`MisScheme`]; [`PairwiseResampler`] is the streaming form a spatial-reuse pass uses.
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
//! * **Precision.** Stored values are `f32`; running sums (`weight_sum`) and products of weights
//!   are `f64`. Zero, negative, NaN and infinite candidates count towards confidence but are never
//!   selected and never enter `weight_sum`; no public function returns NaN or infinity.
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
//! * [`resampling`] — [`GrisResampler`], [`PairwiseResampler`], [`resample`].
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
};
pub use reservoir::{Reservoir, StreamingReservoir};
pub use shift::{ShiftMap, Shifted};

// Runs the README's example as a doc test.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
