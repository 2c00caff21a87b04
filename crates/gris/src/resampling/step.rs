//! [`resample`]: one complete GRIS step for any [`MisScheme`], given a [`ShiftMap`].
//!
//! The dispatch picks one of three strategies, each its own function: the pairwise family
//! (streamed through [`PairwiseResampler`]), the generalized balance heuristic (every candidate
//! weighted by inverse shifts into every domain), and the constant-weight family (constant
//! resampling weights, the MIS normalisation applied to the selected sample only).

use core::borrow::Borrow;

use super::{GrisInput, GrisResampler, PairwiseNeighbor, PairwiseResampler, PairwiseVariant};
use crate::mis::{MisScheme, clean};
use crate::reservoir::{Reservoir, Uniform, sanitize_non_negative};
use crate::shift::{ShiftMap, Shifted};

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
/// * `canonical` is the receiving domain's own reservoir; its `own_target` is `p̂_c(X_c)`.
/// * `neighbors` lists each neighbour's domain and reservoir (`own_target = p̂_i(X_i)`); empty
///   reservoirs are allowed and still count as techniques. A domain is anything that borrows as
///   `M::Domain`: a reference (`&Receiver`) or, for a small `Copy` domain such as a pixel index,
///   the value itself (`(usize, &Reservoir<S>)`), so the caller does not have to keep the domains
///   alive elsewhere just to lend them. An empty list needs its element type spelled out, e.g.
///   `let none: &[(&Domain, &Reservoir<S>)] = &[];`.
/// * `next_u` supplies independent uniform numbers in `[0, 1)` (one per input), `f32` or `f64`
///   (see [`Uniform`]: `f64` with 53 bits when weights may span more than ~7 decades).
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
/// let ra = Reservoir { sample: Some(0.25f32), ucw: 0.9, confidence: 1.0, own_target: 1.25 };
/// let rb = Reservoir { sample: Some(0.75f32), ucw: 0.6, confidence: 2.0, own_target: 3.25 };
/// let mut us = [0.1f32, 0.9].into_iter();
/// let out = resample(&Identity, MisScheme::DefensivePairwise, &a, &ra, &[(&b, &rb)],
///                    || us.next().unwrap_or(0.5));
/// assert_eq!(out.confidence, 3.0);
/// assert!(out.sample.is_some() && out.ucw > 0.0);
/// ```
pub fn resample<S, M, D, U>(
    map: &M,
    scheme: MisScheme,
    canonical_domain: &M::Domain,
    canonical: &Reservoir<S>,
    neighbors: &[(D, &Reservoir<S>)],
    next_u: impl FnMut() -> U,
) -> Reservoir<S>
where
    S: Clone,
    M: ShiftMap<S>,
    D: Borrow<M::Domain>,
    U: Uniform,
{
    resample_observed(
        map,
        scheme,
        canonical_domain,
        canonical,
        neighbors,
        next_u,
        &mut |_: &S, _: f64| {},
    )
    .0
}

/// [`resample`], also telling `observe` every input that can be selected, `(Y_i, w_i)`: its
/// sample shifted into the receiver and its resampling weight. Returns the output reservoir
/// and, where the MIS normalisation is common to all inputs, the scale `s` that makes
///
/// ```text
/// E[ f(Y)·W_Y | the inputs ] = s · Σ_i w_i · f(Y_i) / p̂_c(Y_i)
/// ```
///
/// for any integrand `f` whose support the target covers: the estimate shading every input
/// with its weight gives in place of the selected sample's `f(Y)·W_Y`. It has the same
/// expectation and no more variance (it is the selection's conditional expectation; the
/// Rao–Blackwell theorem). `None` for [`MisScheme::OneOverZ`] and [`MisScheme::Contribution`],
/// whose normalisation depends on the selected sample; `Some(0.0)` when the output is empty.
pub fn resample_observed<S, M, D, U>(
    map: &M,
    scheme: MisScheme,
    canonical_domain: &M::Domain,
    canonical: &Reservoir<S>,
    neighbors: &[(D, &Reservoir<S>)],
    next_u: impl FnMut() -> U,
    observe: &mut impl FnMut(&S, f64),
) -> (Reservoir<S>, Option<f32>)
where
    S: Clone,
    M: ShiftMap<S>,
    D: Borrow<M::Domain>,
    U: Uniform,
{
    let (out, scale) = match scheme {
        MisScheme::Pairwise => pairwise(
            map,
            PairwiseVariant::Plain,
            canonical_domain,
            canonical,
            neighbors,
            next_u,
            observe,
        ),
        MisScheme::DefensivePairwise => pairwise(
            map,
            PairwiseVariant::Defensive,
            canonical_domain,
            canonical,
            neighbors,
            next_u,
            observe,
        ),
        MisScheme::ConfidenceWeightedPairwise => {
            let variant = PairwiseVariant::ConfidenceWeighted {
                neighbor_confidence_sum: neighbors
                    .iter()
                    .map(|(_, r)| sanitize_non_negative(r.confidence))
                    .sum(),
            };
            pairwise(
                map,
                variant,
                canonical_domain,
                canonical,
                neighbors,
                next_u,
                observe,
            )
        }
        MisScheme::GeneralizedBalance => generalized_balance(
            map,
            Heuristic::Balance,
            canonical_domain,
            canonical,
            neighbors,
            next_u,
            observe,
        ),
        MisScheme::GeneralizedPower => generalized_balance(
            map,
            Heuristic::Power,
            canonical_domain,
            canonical,
            neighbors,
            next_u,
            observe,
        ),
        MisScheme::ConstantBiased | MisScheme::OneOverZ | MisScheme::Contribution => {
            constant_weights(
                map,
                scheme,
                canonical_domain,
                canonical,
                neighbors,
                next_u,
                observe,
            )
        }
    };
    let scale = if out.sample.is_none() {
        Some(0.0)
    } else {
        scale
    };
    (out, scale)
}

/// The pairwise family: every neighbour streams through a [`PairwiseResampler`] with its forward
/// shift and the inverse shift of the canonical sample (2k shifts), the canonical sample last.
fn pairwise<S, M, D, U>(
    map: &M,
    variant: PairwiseVariant,
    canonical_domain: &M::Domain,
    canonical: &Reservoir<S>,
    neighbors: &[(D, &Reservoir<S>)],
    mut next_u: impl FnMut() -> U,
    observe: &mut impl FnMut(&S, f64),
) -> (Reservoir<S>, Option<f32>)
where
    S: Clone,
    M: ShiftMap<S>,
    D: Borrow<M::Domain>,
    U: Uniform,
{
    let mut step = PairwiseResampler::new(variant, neighbors.len(), canonical.clone());
    for (domain, reservoir) in neighbors {
        let domain = domain.borrow();
        let canonical_sample_target_pdf = canonical.sample.as_ref().map_or(0.0, |xc| {
            map.pulled_back_target_pdf(canonical_domain, domain, xc)
        });
        let neighbor = PairwiseNeighbor::new(
            reservoir,
            shift_in(map, domain, canonical_domain, reservoir),
            canonical_sample_target_pdf,
        );
        step.add_neighbor_observed(neighbor, next_u(), observe);
    }
    let (out, scale) = step.finalize_observed(next_u(), observe);
    (out, Some(scale))
}

/// What the generalized heuristics weigh a technique by at a sample.
#[derive(Clone, Copy)]
enum Heuristic {
    /// `c · p̂` ([`MisScheme::GeneralizedBalance`]).
    Balance,
    /// `c · p̂²` ([`MisScheme::GeneralizedPower`]).
    Power,
}

impl Heuristic {
    #[inline]
    fn term(self, confidence: f32, target: f32) -> f64 {
        match self {
            Heuristic::Balance => clean(confidence) * clean(target),
            Heuristic::Power => crate::mis::power_technique(confidence, target),
        }
    }
}

/// The generalized balance (or power) heuristic: each candidate (canonical first) is weighted
/// by `m_i = P_i / Σ_j P_j` at its shifted sample (`P_j = c_j·p̂_{←j}`, or `c_j·p̂_{←j}²` for the
/// power heuristic), with inverse shifts into every other domain (O(k²) shifts); the weights
/// are normalised, so the step finalises with `W = Σ w_i / p̂_c(Y)`.
fn generalized_balance<S, M, D, U>(
    map: &M,
    heuristic: Heuristic,
    canonical_domain: &M::Domain,
    canonical: &Reservoir<S>,
    neighbors: &[(D, &Reservoir<S>)],
    mut next_u: impl FnMut() -> U,
    observe: &mut impl FnMut(&S, f64),
) -> (Reservoir<S>, Option<f32>)
where
    S: Clone,
    M: ShiftMap<S>,
    D: Borrow<M::Domain>,
    U: Uniform,
{
    let cc = sanitize_non_negative(canonical.confidence);
    let pc_own = canonical.own_target;
    // Σ_j P_j(y) over the neighbours j ≠ skip, by inverse shifts of y.
    let others = |y: &S, skip: Option<usize>| -> f64 {
        neighbors
            .iter()
            .enumerate()
            .filter(|&(j, _)| Some(j) != skip)
            .map(|(_, (d, r))| {
                heuristic.term(
                    r.confidence,
                    map.pulled_back_target_pdf(canonical_domain, d.borrow(), y),
                )
            })
            .sum()
    };
    let mut stream = GrisResampler::new();
    match GrisInput::canonical(canonical.clone()) {
        Some(input) => {
            let own = heuristic.term(cc, pc_own);
            let m = balance(own, own + others(&input.sample, None));
            stream.add_observed(input, m, next_u(), observe);
        }
        None => stream.add_failed(cc),
    }
    for (i, (domain, reservoir)) in neighbors.iter().enumerate() {
        let Some(shifted) = shift_in(map, domain.borrow(), canonical_domain, reservoir) else {
            stream.add_failed(reservoir.confidence);
            continue;
        };
        let own = heuristic.term(
            reservoir.confidence,
            shifted.source_target_pdf_at_receiver(reservoir.own_target),
        );
        let den =
            own + heuristic.term(cc, shifted.destination_target) + others(&shifted.sample, Some(i));
        let m = balance(own, den);
        let input = GrisInput::from_shift(shifted, reservoir);
        stream.add_observed(input, m, next_u(), observe);
    }
    (stream.finalize(), Some(1.0))
}

/// The constant-weight family (`ConstantBiased`, `OneOverZ`, `Contribution`): candidates are
/// resampled with their confidences as weights (O(k) shifts); the MIS normalisation (`1/Σc`,
/// `1/Z(y)` or the contribution factor) is applied to the selected sample `y` only, with O(k)
/// inverse shifts of `y` for the unbiased two.
fn constant_weights<S, M, D, U>(
    map: &M,
    scheme: MisScheme,
    canonical_domain: &M::Domain,
    canonical: &Reservoir<S>,
    neighbors: &[(D, &Reservoir<S>)],
    mut next_u: impl FnMut() -> U,
    observe: &mut impl FnMut(&S, f64),
) -> (Reservoir<S>, Option<f32>)
where
    S: Clone,
    M: ShiftMap<S>,
    D: Borrow<M::Domain>,
    U: Uniform,
{
    let cc = sanitize_non_negative(canonical.confidence);
    let pc_own = canonical.own_target;
    // Constant resampling weights c_i; the normalisation is applied after selection.
    // Input 0 is the canonical, input i + 1 is neighbour i.
    let mut stream = GrisResampler::new();
    let mut selected_jacobian = 1.0f32;
    let mut selected_source_target = pc_own;
    match GrisInput::canonical(canonical.clone()) {
        Some(input) => {
            stream.add_observed(input, cc, next_u(), observe);
        }
        None => stream.add_failed(cc),
    }
    for (domain, reservoir) in neighbors {
        match shift_in(map, domain.borrow(), canonical_domain, reservoir) {
            Some(shifted) => {
                let (j, t) = (shifted.jacobian, reservoir.own_target);
                let c = sanitize_non_negative(reservoir.confidence);
                let input = GrisInput::from_shift(shifted, reservoir);
                if stream.add_observed(input, c, next_u(), observe) {
                    selected_jacobian = j;
                    selected_source_target = t;
                }
            }
            None => stream.add_failed(reservoir.confidence),
        }
    }
    let (Some(s), Some(y)) = (stream.selected_input(), stream.selected().cloned()) else {
        return (stream.finalize_scaled(0.0), Some(0.0));
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
            let pc_y = stream.selected_receiver_target();
            let pulled = |j: usize| -> f32 {
                if j == 0 {
                    pc_y
                } else if j == s {
                    // The selected technique's own sample: p̂_s(x_s)/J_s, no extra shift.
                    (f64::from(selected_source_target) / f64::from(selected_jacobian)) as f32
                } else {
                    let (d, _) = &neighbors[j - 1];
                    map.pulled_back_target_pdf(canonical_domain, d.borrow(), &y)
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
    // Only the biased constant scheme's normalisation is common to every input.
    let common = (scheme == MisScheme::ConstantBiased).then_some(scale);
    (stream.finalize_scaled(scale), common)
}

#[inline]
fn balance(num: f64, den: f64) -> f32 {
    if num > 0.0 && den > 0.0 && den.is_finite() {
        (num / den).min(1.0) as f32
    } else {
        0.0
    }
}
