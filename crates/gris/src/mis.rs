//! Resampling MIS weights `m_i(y)` for GRIS.
//!
//! Every function here evaluates weights at **one point** `y` of the receiving (canonical) domain
//! `Ω_c`. Its inputs are, per technique `j`, a confidence `c_j ≥ 0` and the *pulled-back target*
//!
//! ```text
//! p̂_{←j}(y) = p̂_j(T_{c→j}(y)) · J_{c→j}(y)        (= p̂_j(x) / J_{j→c}(x) with x = T_{c→j}(y))
//! ```
//!
//! i.e. domain `j`'s target expressed in the canonical domain's measure, and 0 when the inverse
//! shift `T_{c→j}` fails. For the canonical technique `p̂_{←c} = p̂_c`. Write
//! `P_j(y) = c_j · p̂_{←j}(y)`. See `docs/GRIS.md` §4 for the derivations and §3.1 for the
//! conditions under which the estimator is unbiased.
//!
//! Numerics: products and sums are formed in `f64`, so confidences and targets anywhere in the
//! finite `f32` range give finite weights in `[0, 1]`. NaN, negative and infinite inputs are
//! treated as 0 (a technique that cannot produce `y`).
//!
//! | scheme | function(s) | unbiased | source |
//! |---|---|---|---|
//! | constant `c_i/Σc` ("1/M") | [`constant_biased`] | **no** | Bitterli et al. 2020, Alg. 4 (RTXDI `OFF`) |
//! | 1/Z | [`one_over_z`] | yes | Bitterli et al. 2020 (unbiased ReSTIR) |
//! | contribution MIS ("MIS-like") | [`contribution`], [`contribution_scale`] | yes | Bitterli et al. 2020; RTXDI `BASIC` |
//! | generalized balance | [`generalized_balance`] | yes | Lin et al. 2022 (GRIS), balance heuristic |
//! | generalized power (targets squared, confidences linear) | [`generalized_power`] | yes | Veach 1997 §9.2 (power heuristic), applied to GRIS's targets |
//! | pairwise | [`pairwise_neighbor`], [`pairwise_canonical`] | yes | Bitterli 2022, PhD thesis §9.1; RTXDI `PAIRWISE` |
//! | defensive pairwise | [`defensive_pairwise_neighbor`], [`defensive_pairwise_canonical`] | yes | Lin et al. 2022 (GRIS / ReSTIR PT) |
//! | confidence-weighted defensive pairwise | [`confidence_weighted_pairwise_neighbor`], [`confidence_weighted_pairwise_canonical`] | yes | Wyman et al. 2023, "A Gentle Introduction to ReSTIR" course notes |

/// Selects an MIS scheme for the drivers in [`crate::resampling`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MisScheme {
    /// Constant weights `c_i/Σc` (legacy "1/M"). **Biased** whenever the domains differ in support
    /// (some technique cannot produce `y`). Fast; kept for comparisons and as a negative control.
    ConstantBiased,
    /// Constant resampling weights, finalised with `1/Z` where `Z` sums the confidences of the
    /// techniques that can produce the selected sample. Unbiased.
    OneOverZ,
    /// Contribution MIS ("MIS-like", RTXDI `BASIC`): constant resampling weights, balance
    /// heuristic applied at finalisation. Unbiased.
    Contribution,
    /// Generalized balance heuristic: `m_i = P_i / Σ_j P_j` for every candidate. Unbiased,
    /// O(k²) shifts.
    GeneralizedBalance,
    /// Generalized power heuristic: `m_i = c_i·p̂_{←i}² / Σ_j c_j·p̂_{←j}²` for every candidate
    /// ([`generalized_power`]). Unbiased, O(k²) shifts. Equal to the balance heuristic where
    /// the domains' targets agree; where they disagree it bounds how much a high-confidence
    /// domain whose target is far below the receiver's can weigh (temporal reuse under motion).
    GeneralizedPower,
    /// Pairwise MIS (non-defensive). Unbiased, 2 shifts per neighbour.
    Pairwise,
    /// Defensive pairwise MIS: the canonical technique keeps at least `1/(k+1)`. Unbiased.
    DefensivePairwise,
    /// Confidence-weighted defensive pairwise MIS. Unbiased.
    ConfidenceWeightedPairwise,
}

impl MisScheme {
    /// All schemes, in declaration order.
    pub const ALL: [MisScheme; 8] = [
        MisScheme::ConstantBiased,
        MisScheme::OneOverZ,
        MisScheme::Contribution,
        MisScheme::GeneralizedBalance,
        MisScheme::GeneralizedPower,
        MisScheme::Pairwise,
        MisScheme::DefensivePairwise,
        MisScheme::ConfidenceWeightedPairwise,
    ];

    /// `false` only for [`MisScheme::ConstantBiased`].
    pub const fn is_unbiased(self) -> bool {
        !matches!(self, MisScheme::ConstantBiased)
    }
}

/// Non-negative finite `f64` from an `f32` (NaN, negative and infinite map to 0).
#[inline]
pub(crate) fn clean(x: f32) -> f64 {
    if x > 0.0 && x.is_finite() {
        f64::from(x)
    } else {
        0.0
    }
}

/// `P_j = c_j · p̂_{←j}` in `f64`.
#[inline]
fn technique(confidence: f32, target_pdf: f32) -> f64 {
    clean(confidence) * clean(target_pdf)
}

#[inline]
fn ratio(num: f64, den: f64) -> f32 {
    if den > 0.0 && den.is_finite() {
        let r = num / den;
        if r > 0.0 { r.min(1.0) as f32 } else { 0.0 }
    } else {
        0.0
    }
}

/// **(a) Constant MIS weight** `m_i = c_i / Σ_j c_j` — **BIASED** across differing domains.
///
/// `confidence_sum` is `Σ_j c_j` over all participating techniques (canonical included). The
/// weights sum to one everywhere, but a technique that cannot produce `y` still takes its share,
/// so the estimate loses (or gains) energy wherever supports differ (`docs/GRIS.md` §4.1;
/// Bitterli et al. 2020, Alg. 4 (RTXDI `OFF`)). Use only as a fast approximation or a negative control.
#[inline]
pub fn constant_biased(confidence_i: f32, confidence_sum: f32) -> f32 {
    ratio(clean(confidence_i), clean(confidence_sum))
}

/// **(b) 1/Z normalisation**: returns `1/Z` with `Z = Σ_{j : p̂_{←j}(y) > 0} c_j`, or 0 if `Z = 0`.
///
/// Resample with constant weights `w_i = c_i·p̂_c(Y_i)·W_i·J_i`, then finalise the selected `y`
/// with `W = weight_sum / (p̂_c(y)·Z)`, i.e. pass the returned value as `scale` to
/// [`crate::StreamingReservoir::finalize_scaled`]. The implied MIS weight is `m_i = c_i/Z(y)` for
/// every technique that can produce `y` — a partition of unity, hence unbiased, provided
/// `p̂_{←j}(y) > 0` exactly on the image of domain `j`'s sample support (Bitterli et al. 2020;
/// `docs/GRIS.md` §4.2).
///
/// `confidences[j]` and `target_pdfs[j]` describe the same technique; extra entries of the
/// longer slice are ignored. When `Z > 0` is so small that `1/Z` overflows `f32`, the result
/// saturates at `f32::MAX` (it is never 0 for `Z > 0`, never infinite).
pub fn one_over_z(confidences: &[f32], target_pdfs: &[f32]) -> f32 {
    let z: f64 = confidences
        .iter()
        .zip(target_pdfs)
        .filter(|&(_, &p)| clean(p) > 0.0)
        .map(|(&c, _)| clean(c))
        .sum();
    if z > 0.0 { saturate(1.0 / z) } else { 0.0 }
}

/// `f64 → f32` for a positive finite ratio: saturates at `f32::MAX` instead of overflowing.
#[inline]
fn saturate(r: f64) -> f32 {
    if r < f64::from(f32::MAX) {
        r as f32
    } else {
        f32::MAX
    }
}

/// **(d) Generalized balance heuristic** `m_i(y) = c_i·p̂_{←i}(y) / Σ_j c_j·p̂_{←j}(y)`.
///
/// Needs every technique's pulled-back target at every candidate: O((k+1)²) shifts
/// (Lin et al. 2022; `docs/GRIS.md` §4.4). Returns 0 when the denominator is 0 or
/// `i` is out of range. The weights over all `i` sum to 1 whenever some `P_j(y) > 0`.
pub fn generalized_balance(i: usize, confidences: &[f32], target_pdfs: &[f32]) -> f32 {
    let (Some(&ci), Some(&pi)) = (confidences.get(i), target_pdfs.get(i)) else {
        return 0.0;
    };
    let den: f64 = confidences
        .iter()
        .zip(target_pdfs)
        .map(|(&c, &p)| technique(c, p))
        .sum();
    ratio(technique(ci, pi), den)
}

/// **(d′) Generalized power heuristic** `m_i(y) = c_i·p̂_{←i}(y)² / Σ_j c_j·p̂_{←j}(y)²`.
///
/// Veach's power heuristic (exponent 2) on the pulled-back targets, with the confidences kept
/// linear: where every domain's target agrees (`p̂_{←j}(y)` all equal) the weights are the
/// balance heuristic's `c_i/Σc`, so a history of confidence 20 weighs as 20 fresh samples, not
/// 400. Where they disagree, weight moves to the larger target faster than with the balance
/// heuristic, which bounds a reused sample's resampling weight `m_i·p̂_c·W_i`: with two domains
/// of confidences `c_c`, `c_i` and ratio `r = p̂_c/p̂_{←i}`, it is at most `√(c_i/c_c)/2` times
/// domain `i`'s own estimate `p̂_{←i}·W_i` (the balance heuristic allows `c_i/c_c` times).
/// A partition of unity that is zero where `p̂_{←i} = 0`, hence unbiased under the same
/// conditions as [`generalized_balance`] (`docs/GRIS.md` §4.4). Same cost: O((k+1)²) shifts.
pub fn generalized_power(i: usize, confidences: &[f32], target_pdfs: &[f32]) -> f32 {
    let (Some(&ci), Some(&pi)) = (confidences.get(i), target_pdfs.get(i)) else {
        return 0.0;
    };
    let den: f64 = confidences
        .iter()
        .zip(target_pdfs)
        .map(|(&c, &p)| power_technique(c, p))
        .sum();
    ratio(power_technique(ci, pi), den)
}

/// `c_j · p̂_{←j}²` in `f64`.
#[inline]
pub(crate) fn power_technique(confidence: f32, target_pdf: f32) -> f64 {
    let p = clean(target_pdf);
    clean(confidence) * p * p
}

/// **(c) Contribution MIS weight** ("MIS-like"): the balance heuristic applied to the
/// *contribution* of the selected sample, `m_s(y) = c_s·p̂_{←s}(y) / Σ_j c_j·p̂_{←j}(y)`.
///
/// Numerically identical to [`generalized_balance`]; the difference is where it is applied:
/// candidates are resampled with constant weights `w_i = c_i·p̂_c(Y_i)·W_i·J_i`, and only the
/// selected sample's technique `s` is weighted, at finalisation (see [`contribution_scale`]).
/// O(k) inverse shifts of one sample (Bitterli et al. 2020; RTXDI `BASIC`; `docs/GRIS.md` §3.2, §4.3).
pub fn contribution(selected: usize, confidences: &[f32], target_pdfs: &[f32]) -> f32 {
    generalized_balance(selected, confidences, target_pdfs)
}

/// Finalisation factor of contribution MIS: `p̂_{←s}(y) / Σ_j c_j·p̂_{←j}(y)` `(= m_s / c_s)`.
///
/// With resampling weights `w_i = c_i·p̂_c(Y_i)·W_i·J_i`, finalise the selected `y` (from
/// technique `s`) with `W = weight_sum · factor / p̂_c(y)`, i.e. pass it as `scale` to
/// [`crate::StreamingReservoir::finalize_scaled`]. Returns 0 if the denominator is 0; saturates
/// at `f32::MAX` when the factor overflows `f32`.
pub fn contribution_scale(selected: usize, confidences: &[f32], target_pdfs: &[f32]) -> f32 {
    let Some(&ps) = target_pdfs.get(selected) else {
        return 0.0;
    };
    let den: f64 = confidences
        .iter()
        .zip(target_pdfs)
        .map(|(&c, &p)| technique(c, p))
        .sum();
    let num = clean(ps);
    if den > 0.0 && num > 0.0 && den.is_finite() {
        saturate(num / den)
    } else {
        0.0
    }
}

/// What the pairwise weights of one neighbour `i` need at a point `y` of the canonical domain:
/// both techniques' confidences and targets, named so that a neighbour's value cannot silently
/// take a canonical one's place. Both targets are in the canonical domain's measure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairTerms {
    /// Neighbour `i`'s confidence `c_i`.
    pub neighbor_confidence: f32,
    /// Neighbour `i`'s target pulled back into the canonical domain, `p̂_{←i}(y)` (0 where the
    /// shift into domain `i` fails).
    pub neighbor_target_pdf: f32,
    /// The canonical technique's confidence `c_c`.
    pub canonical_confidence: f32,
    /// The canonical domain's own target at `y`, `p̂_c(y)`.
    pub canonical_target_pdf: f32,
}

/// Pairwise pair weight `a_i(y) = P_i / (P_i + P_c/k)` of neighbour `i` against the canonical
/// technique, where the canonical spends `1/k` of its confidence on each of the `k` pairs.
///
/// `neighbor_count` is the configured `k` (values below 1 are treated as 1). Returns 0 when both
/// terms are 0. This is the building block of every pairwise variant (`docs/GRIS.md` §4.5).
#[inline]
pub fn pairwise_pair_weight(pair: PairTerms, neighbor_count: f32) -> f32 {
    let k = if neighbor_count > 1.0 {
        f64::from(neighbor_count)
    } else {
        1.0
    };
    let pi = technique(pair.neighbor_confidence, pair.neighbor_target_pdf);
    let pc = technique(pair.canonical_confidence, pair.canonical_target_pdf) / k;
    if pi > 0.0 { ratio(pi, pi + pc) } else { 0.0 }
}

/// **(e) Pairwise MIS**, neighbour weight `m_i(y) = a_i(y)/k` with `a_i` from
/// [`pairwise_pair_weight`] (Bitterli 2022, PhD thesis §9.1; RTXDI DI `PAIRWISE`;
/// `docs/GRIS.md` §4.5).
///
/// Together with [`pairwise_canonical`] over the same `k` neighbours the weights sum to one.
/// Non-defensive: the canonical weight can approach 0 where neighbours dominate.
#[inline]
pub fn pairwise_neighbor(pair: PairTerms, neighbor_count: usize) -> f32 {
    if neighbor_count == 0 {
        return 0.0;
    }
    let k = neighbor_count as f32;
    pairwise_pair_weight(pair, k) / k
}

/// Sum `Σ_i (1 − a_i(y))` of the canonical pair shares over `k = neighbor_confidences.len()`
/// neighbours (shorter of the two slices).
fn canonical_pair_shares(
    canonical_confidence: f32,
    canonical_target_pdf: f32,
    neighbor_confidences: &[f32],
    neighbor_target_pdfs: &[f32],
) -> (f64, usize) {
    let k = neighbor_confidences.len().min(neighbor_target_pdfs.len());
    let sum = neighbor_confidences
        .iter()
        .zip(neighbor_target_pdfs)
        .map(|(&c, &p)| {
            let pair = PairTerms {
                neighbor_confidence: c,
                neighbor_target_pdf: p,
                canonical_confidence,
                canonical_target_pdf,
            };
            1.0 - f64::from(pairwise_pair_weight(pair, k as f32))
        })
        .sum();
    (sum, k)
}

/// **(e) Pairwise MIS**, canonical weight `m_c(y) = (1/k)·Σ_i (1 − a_i(y))`, or 1 if `k = 0`.
///
/// `neighbor_target_pdfs[i]` is `p̂_{←i}(y)` for the point `y` being weighted (for the canonical
/// sample, the canonical sample shifted into neighbour `i`). Every neighbour counted in `k` must be
/// listed, including ones whose reservoir is empty or whose shift failed (target 0 ⇒ share 1);
/// skipping one breaks the partition of unity (`docs/GRIS.md` §4.5).
pub fn pairwise_canonical(
    canonical_confidence: f32,
    canonical_target_pdf: f32,
    neighbor_confidences: &[f32],
    neighbor_target_pdfs: &[f32],
) -> f32 {
    let (sum, k) = canonical_pair_shares(
        canonical_confidence,
        canonical_target_pdf,
        neighbor_confidences,
        neighbor_target_pdfs,
    );
    if k == 0 {
        1.0
    } else {
        (sum / k as f64).clamp(0.0, 1.0) as f32
    }
}

/// **(f) Defensive pairwise MIS**, neighbour weight `m_i(y) = a_i(y)/(k+1)`
/// (Lin et al. 2022; ReSTIR PT spatial reuse default;
/// `docs/GRIS.md` §4.6).
#[inline]
pub fn defensive_pairwise_neighbor(pair: PairTerms, neighbor_count: usize) -> f32 {
    pairwise_pair_weight(pair, neighbor_count as f32) / (neighbor_count as f32 + 1.0)
}

/// **(f) Defensive pairwise MIS**, canonical weight `m_c(y) = (1 + Σ_i (1 − a_i(y)))/(k+1)`.
///
/// Always `≥ 1/(k+1)`, which bounds the variance by that of the canonical estimator alone. Same
/// listing rule as [`pairwise_canonical`].
pub fn defensive_pairwise_canonical(
    canonical_confidence: f32,
    canonical_target_pdf: f32,
    neighbor_confidences: &[f32],
    neighbor_target_pdfs: &[f32],
) -> f32 {
    let (sum, k) = canonical_pair_shares(
        canonical_confidence,
        canonical_target_pdf,
        neighbor_confidences,
        neighbor_target_pdfs,
    );
    ((1.0 + sum) / (k as f64 + 1.0)).clamp(0.0, 1.0) as f32
}

/// **Confidence-weighted defensive pairwise MIS**, neighbour weight
///
/// ```text
/// m_i = (C_N/(C_N + c_c)) · c_i·p̂_{←i} / (C_N·p̂_{←i} + c_c·p̂_c),   C_N = Σ_{j∈N} c_j
/// ```
///
/// (Wyman et al. 2023 course notes, confidence-weighted pairwise; `docs/GRIS.md`
/// §4.7). Neighbours with more confidence get proportionally more weight; the canonical keeps at
/// least `c_c/(c_c + C_N)`. `neighbor_confidence_sum` is `C_N` over *all* neighbours of this
/// step.
pub fn confidence_weighted_pairwise_neighbor(pair: PairTerms, neighbor_confidence_sum: f32) -> f32 {
    let cn = clean(neighbor_confidence_sum);
    let cc = clean(pair.canonical_confidence);
    let ci = clean(pair.neighbor_confidence);
    let pi = clean(pair.neighbor_target_pdf);
    let pc = clean(pair.canonical_target_pdf);
    let den = cn * pi + cc * pc;
    if !(ci > 0.0 && pi > 0.0 && den > 0.0 && cn + cc > 0.0) {
        return 0.0;
    }
    // (C_N/(C_N + c_c)) · c_i·p_i/den, written to stay in [0, 1] without overflow.
    let r = (cn / (cn + cc)) * ((ci * pi) / den);
    r.clamp(0.0, 1.0) as f32
}

/// **Confidence-weighted defensive pairwise MIS**, canonical weight
///
/// ```text
/// m_c = c_c/(c_c + C_N) + Σ_i (c_i/(c_c + C_N)) · c_c·p̂_c / (C_N·p̂_{←i} + c_c·p̂_c)
/// ```
///
/// with `C_N = Σ_i c_i` over the listed neighbours. A pair whose denominator is 0 (neither side
/// can produce `y`) gives its whole share `c_i/(c_c + C_N)` to the canonical, so the weights
/// still sum to one. Returns 1 when `c_c + C_N = 0`.
pub fn confidence_weighted_pairwise_canonical(
    canonical_confidence: f32,
    canonical_target_pdf: f32,
    neighbor_confidences: &[f32],
    neighbor_target_pdfs: &[f32],
) -> f32 {
    let cc = clean(canonical_confidence);
    let pc = clean(canonical_target_pdf);
    let cn: f64 = neighbor_confidences.iter().map(|&c| clean(c)).sum();
    let total = cc + cn;
    if !(total > 0.0) {
        return 1.0;
    }
    let mut m = cc / total;
    for (&c, &p) in neighbor_confidences.iter().zip(neighbor_target_pdfs) {
        let ci = clean(c);
        let den = cn * clean(p) + cc * pc;
        let share = if den > 0.0 { cc * pc / den } else { 1.0 };
        m += ci / total * share;
    }
    m.clamp(0.0, 1.0) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn balance_partition() {
        let c = [1.0, 2.0, 0.5];
        let p = [0.3, 0.0, 4.0];
        let s: f32 = (0..3).map(|i| generalized_balance(i, &c, &p)).sum();
        assert!((s - 1.0).abs() < 1e-6);
        assert_eq!(generalized_balance(1, &c, &p), 0.0);
        assert_eq!(generalized_balance(7, &c, &p), 0.0);
        assert_eq!(generalized_balance(0, &[1.0], &[0.0]), 0.0);
    }

    #[test]
    fn power_partition_and_agreement_with_balance() {
        let c = [1.0, 2.0, 0.5];
        let p = [0.3, 0.0, 4.0];
        let s: f32 = (0..3).map(|i| generalized_power(i, &c, &p)).sum();
        assert!((s - 1.0).abs() < 1e-6);
        assert_eq!(generalized_power(1, &c, &p), 0.0);
        assert_eq!(generalized_power(7, &c, &p), 0.0);
        // Equal targets: the balance heuristic's confidence shares.
        let q = [0.7, 0.7, 0.7];
        for i in 0..3 {
            let (a, b) = (generalized_power(i, &c, &q), generalized_balance(i, &c, &q));
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
        // The bound on a reused sample's weight m_i·p̂_c (domain i's own estimate is 1).
        let (cc, ci) = (1.0f32, 20.0f32);
        let worst = (1..2000)
            .map(|k| {
                let r = k as f32 * 0.05;
                generalized_power(1, &[cc, ci], &[r, 1.0]) * r
            })
            .fold(0.0f32, f32::max);
        assert!((worst - (ci / cc).sqrt() / 2.0).abs() < 0.01, "{worst}");
    }

    #[test]
    fn pairwise_partition_with_zero_neighbours() {
        assert_eq!(pairwise_canonical(1.0, 1.0, &[], &[]), 1.0);
        assert_eq!(defensive_pairwise_canonical(1.0, 1.0, &[], &[]), 1.0);
        assert_eq!(
            confidence_weighted_pairwise_canonical(1.0, 1.0, &[], &[]),
            1.0
        );
    }

    #[test]
    fn one_over_z_counts_covering_techniques() {
        assert_eq!(one_over_z(&[1.0, 2.0, 4.0], &[1.0, 0.0, 3.0]), 0.2);
        assert_eq!(one_over_z(&[1.0], &[0.0]), 0.0);
    }

    #[test]
    fn huge_and_tiny_inputs_stay_finite() {
        let c = [1e30, 1e-30, 1.0];
        let p = [1e30, 1e30, 1e-30];
        let s: f32 = (0..3).map(|i| generalized_balance(i, &c, &p)).sum();
        assert!((s - 1.0).abs() < 1e-6);
        let pair = PairTerms {
            neighbor_confidence: 1e30,
            neighbor_target_pdf: 1e30,
            canonical_confidence: 1e30,
            canonical_target_pdf: 1e30,
        };
        let a = pairwise_pair_weight(pair, 3.0);
        assert!(a.is_finite() && (a - 0.75).abs() < 1e-6);
    }

    #[test]
    fn constant_is_labelled_biased() {
        assert!(!MisScheme::ConstantBiased.is_unbiased());
        assert_eq!(MisScheme::ALL.iter().filter(|s| s.is_unbiased()).count(), 7);
        assert_eq!(constant_biased(1.0, 4.0), 0.25);
    }
}
