//! Statistical tests: the weighted-reservoir selection law (chi-square) and unbiasedness
//! `E[f(Y)·W_Y] = ∫ f` of RIS, streaming RIS and GRIS under every MIS scheme, with a negative
//! control (constant 1/M across differing domains) that must show its bias.
//!
//! Tolerances: each unbiasedness check asserts |mean − truth| < 4 standard errors (computed from
//! the samples themselves) and that the standard error is below 1 % of the truth, so a biased
//! estimator with a bias above ~4 % cannot pass. Seeds are fixed.

mod support;

use restir_gris::{
    GrisInput, GrisResampler, MisScheme, PairwiseNeighbor, PairwiseResampler, PairwiseVariant,
    Reservoir, ShiftMap, StreamingReservoir, mis, resample,
};
use restir_testkit::{
    RunningStats as Stats, SplitMix64 as Rng, chi_square, chi_square_critical, trials,
};
use support::{
    PowerShift, TOY_INTEGRAL, TOY_UNCOVERED_INTEGRAL, ToyDomain, toy_domains, toy_integrand,
};

// ------------------------------------------------------------------------------------------
// Selection law
// ------------------------------------------------------------------------------------------

const LAW_WEIGHTS: [f32; 10] = [
    0.5,
    2.0,
    0.0,
    1.0,
    f32::NAN,
    3.25,
    0.125,
    f32::INFINITY,
    1.5,
    -1.0,
];

fn law_probs() -> Vec<f64> {
    let valid = |w: f32| w > 0.0 && w.is_finite();
    let total: f64 = LAW_WEIGHTS
        .iter()
        .filter(|&&w| valid(w))
        .map(|&w| f64::from(w))
        .sum();
    LAW_WEIGHTS
        .iter()
        .map(|&w| if valid(w) { f64::from(w) / total } else { 0.0 })
        .collect()
}

fn assert_law(counts: &[u64], n: u64, what: &str) {
    let (stat, df) = chi_square(counts, &law_probs(), n);
    let critical = chi_square_critical(df);
    assert!(
        stat < critical,
        "{what}: chi-square {stat:.2} ≥ critical {critical:.2} (df {df}), counts {counts:?}"
    );
}

/// Streaming `add` selects candidate i with probability w_i/Σw; zero, negative, NaN and infinite
/// candidates are never selected (chi-square at p = 1e-4, fixed seed).
#[test]
fn chi_square_selection_law_of_add() {
    let n = trials(400_000) as u64;
    let mut rng = Rng::new(1);
    let mut counts = [0u64; LAW_WEIGHTS.len()];
    for _ in 0..n {
        let mut s = StreamingReservoir::new();
        for (i, &w) in LAW_WEIGHTS.iter().enumerate() {
            s.add(i, w, rng.next_f32());
        }
        assert_eq!(s.confidence(), LAW_WEIGHTS.len() as f32);
        counts[*s.selected().unwrap()] += 1;
    }
    assert_law(&counts, n, "add");
}

/// Stream merge of sub-streams (random split points, random merge order and nesting) has the
/// same selection law as streaming everything in one pass.
#[test]
fn chi_square_selection_law_of_merge_trees() {
    let n = trials(400_000) as u64;
    let mut rng = Rng::new(2);
    let mut counts = [0u64; LAW_WEIGHTS.len()];
    for _ in 0..n {
        // Split the candidates into 1..=4 contiguous chunks, stream each, merge in a random order,
        // sometimes nesting (merge the last two first).
        let chunks = 1 + (rng.next_u64() % 4) as usize;
        let mut cuts: Vec<usize> = (0..chunks - 1)
            .map(|_| (rng.next_u64() % LAW_WEIGHTS.len() as u64) as usize)
            .collect();
        cuts.push(0);
        cuts.push(LAW_WEIGHTS.len());
        cuts.sort_unstable();
        let mut streams: Vec<StreamingReservoir<usize>> = cuts
            .windows(2)
            .map(|r| {
                let mut s = StreamingReservoir::new();
                for (i, &w) in LAW_WEIGHTS.iter().enumerate().take(r[1]).skip(r[0]) {
                    s.add(i, w, rng.next_f32());
                }
                s
            })
            .collect();
        // Random permutation (Fisher–Yates).
        for i in (1..streams.len()).rev() {
            let j = (rng.next_u64() % (i as u64 + 1)) as usize;
            streams.swap(i, j);
        }
        if streams.len() >= 3 && rng.next_f32() < 0.5 {
            let b = streams.pop().unwrap();
            let mut a = streams.pop().unwrap();
            a.merge(b, rng.next_f32());
            streams.push(a);
        }
        let mut total = StreamingReservoir::new();
        for s in streams {
            total.merge(s, rng.next_f32());
        }
        assert_eq!(total.confidence(), LAW_WEIGHTS.len() as f32);
        counts[*total.selected().unwrap()] += 1;
    }
    assert_law(&counts, n, "merge trees");
}

// ------------------------------------------------------------------------------------------
// RIS and streaming RIS
// ------------------------------------------------------------------------------------------

/// f(x) = 0.5 + 3x² on [0, 1]; source pdf p(x) = 2x (x = sqrt(u)); target p̂(x) = 0.25 + x.
fn ris_candidate(rng: &mut Rng) -> (f64, f64) {
    let x = rng.next_f64().sqrt().max(1e-12);
    (x, 2.0 * x)
}

/// Plain RIS with N candidates and m = 1/N: E[f(Y)·W] = ∫ f. Also N = 1 (W = 1/p, i.e. f/p).
#[test]
fn ris_is_unbiased() {
    for (candidates, seed) in [(1usize, 10u64), (8, 11)] {
        let mut rng = Rng::new(seed);
        let mut stats = Stats::default();
        for _ in 0..trials(200_000) {
            let mut s = StreamingReservoir::new();
            for _ in 0..candidates {
                let (x, pdf) = ris_candidate(&mut rng);
                let t = 0.25 + x;
                s.add(x, (t / (pdf * candidates as f64)) as f32, rng.next_f32());
            }
            let y = *s.selected().unwrap();
            let r = s.finalize((0.25 + y) as f32);
            if candidates == 1 {
                let (_, pdf) = (y, 2.0 * y);
                assert!(
                    (f64::from(r.ucw) * pdf - 1.0).abs() < 1e-5,
                    "N = 1 must give W = 1/p"
                );
            }
            stats.push(toy_integrand(y) * f64::from(r.ucw));
        }
        stats.assert_unbiased(TOY_INTEGRAL, &format!("RIS with N = {candidates}"));
    }
}

/// Streaming RIS over two strategies (uniform and 2x sources, one-sample MIS via the balance
/// heuristic over candidate counts), built as separate sub-streams and stream-merged, then
/// finalised: E[f(Y)·W] = ∫ f.
#[test]
fn streaming_ris_with_merged_sub_streams_is_unbiased() {
    let mut rng = Rng::new(12);
    let mut stats = Stats::default();
    let (n_uniform, n_linear) = (3usize, 5usize);
    let n = (n_uniform + n_linear) as f64;
    let blended = |x: f64| (n_uniform as f64 * 1.0 + n_linear as f64 * 2.0 * x) / n;
    for _ in 0..trials(200_000) {
        let mut a = StreamingReservoir::new();
        for _ in 0..n_uniform {
            let x = rng.next_f64();
            let t = 0.25 + x;
            a.add_candidate(
                x,
                t as f32,
                (t / (n * blended(x))) as f32,
                1.0,
                rng.next_f32(),
            );
        }
        let mut b = StreamingReservoir::new();
        for _ in 0..n_linear {
            let (x, _) = ris_candidate(&mut rng);
            let t = 0.25 + x;
            b.add_candidate(
                x,
                t as f32,
                (t / (n * blended(x))) as f32,
                1.0,
                rng.next_f32(),
            );
        }
        if rng.next_f32() < 0.5 {
            std::mem::swap(&mut a, &mut b);
        }
        a.merge(b, rng.next_f32());
        assert_eq!(a.confidence(), n as f32);
        let r = a.finalize_recorded();
        let y = r.sample.unwrap();
        stats.push(toy_integrand(y) * f64::from(r.ucw));
    }
    stats.assert_unbiased(TOY_INTEGRAL, "streaming RIS with stream merge");
}

// ------------------------------------------------------------------------------------------
// GRIS on the toy domains
// ------------------------------------------------------------------------------------------

fn run_driver(
    scheme: MisScheme,
    seed: u64,
    canonical: ToyDomain,
    neighbors: &[ToyDomain],
) -> Stats {
    let mut rng = Rng::new(seed);
    let mut stats = Stats::default();
    for _ in 0..trials(160_000) {
        let rc = canonical.sample(&mut rng);
        let rn: Vec<Reservoir<f64>> = neighbors.iter().map(|d| d.sample(&mut rng)).collect();
        let list: Vec<(&ToyDomain, &Reservoir<f64>)> = neighbors.iter().zip(&rn).collect();
        let out = resample(&PowerShift, scheme, &canonical, &rc, &list, || {
            rng.next_f32()
        });
        let c_in: f32 = rc.confidence + rn.iter().map(|r| r.confidence).sum::<f32>();
        assert_eq!(out.confidence, c_in, "confidence out = Σ confidence in");
        assert!(out.ucw >= 0.0 && out.ucw.is_finite());
        stats.push(
            out.sample
                .map_or(0.0, |y| toy_integrand(y) * f64::from(out.ucw)),
        );
    }
    stats
}

/// GRIS with a canonical and 3 neighbour domains (own targets, shifts x^s, one with partial
/// support, unequal confidences) is unbiased under every unbiased MIS scheme, via `resample`.
#[test]
fn gris_driver_is_unbiased_for_every_unbiased_scheme() {
    let (canonical, neighbors) = toy_domains();
    for (i, scheme) in MisScheme::ALL.into_iter().enumerate() {
        if !scheme.is_unbiased() {
            continue;
        }
        let stats = run_driver(scheme, 100 + i as u64, canonical, &neighbors);
        stats.assert_unbiased(TOY_INTEGRAL, &format!("GRIS {scheme:?}"));
    }
}

/// k = 0: GRIS with only the canonical reduces to its RIS estimate.
#[test]
fn gris_without_neighbours_reduces_to_ris() {
    let (canonical, _) = toy_domains();
    let mut rng = Rng::new(7);
    for _ in 0..1000 {
        let rc = canonical.sample(&mut rng);
        for scheme in MisScheme::ALL {
            let none: &[(&ToyDomain, &Reservoir<f64>)] = &[];
            let out = resample(&PowerShift, scheme, &canonical, &rc, none, || {
                rng.next_f32()
            });
            assert_eq!(out.sample, rc.sample, "{scheme:?}");
            assert!((out.ucw - rc.ucw).abs() <= 1e-6 * rc.ucw, "{scheme:?}");
        }
    }
    let stats = run_driver(MisScheme::DefensivePairwise, 8, canonical, &[]);
    stats.assert_unbiased(TOY_INTEGRAL, "GRIS with k = 0");
}

/// Negative control: constant 1/M MIS across domains with differing support is biased. The mean
/// must be far from the truth (> 10 SE) and agree with the analytic biased value
/// ∫f − (c_partial/Σc)·∫_{0.5}^{1} f.
#[test]
fn constant_one_over_m_is_biased_negative_control() {
    let (canonical, neighbors) = toy_domains();
    let stats = run_driver(MisScheme::ConstantBiased, 200, canonical, &neighbors);
    let se = stats.std_error();
    let z = (stats.mean() - TOY_INTEGRAL) / se;
    assert!(
        z < -10.0,
        "1/M should be biased low: mean {} (z = {z:.1})",
        stats.mean()
    );
    let total: f32 = canonical.confidence + neighbors.iter().map(|d| d.confidence).sum::<f32>();
    let predicted =
        TOY_INTEGRAL - f64::from(neighbors[1].confidence / total) * TOY_UNCOVERED_INTEGRAL;
    stats.assert_unbiased(predicted, "1/M against its predicted biased mean");
}

/// Confidence weights may be any positive values (e.g. after capping): the mean does not move.
#[test]
fn gris_is_unbiased_for_other_confidences() {
    let (mut canonical, mut neighbors) = toy_domains();
    canonical.confidence = 20.0;
    neighbors[0].confidence = 0.01;
    neighbors[1].confidence = restir_gris::cap_confidence(50.0, 8.0);
    neighbors[2].confidence = restir_gris::cap_confidence_relative(100.0, 1.0, 3.0);
    for (i, scheme) in [
        MisScheme::GeneralizedBalance,
        MisScheme::DefensivePairwise,
        MisScheme::ConfidenceWeightedPairwise,
    ]
    .into_iter()
    .enumerate()
    {
        let stats = run_driver(scheme, 300 + i as u64, canonical, &neighbors);
        stats.assert_unbiased(TOY_INTEGRAL, &format!("{scheme:?} with other confidences"));
    }
}

// ------------------------------------------------------------------------------------------
// The same GRIS step written by hand with the low-level API (as a renderer would), so the
// standalone `mis` functions, `GrisResampler` and `PairwiseResampler` are checked in an
// estimator independently of `resample`.
// ------------------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug)]
enum Manual {
    OneOverZ,
    Contribution,
    Balance,
    Pairwise,
    Defensive,
    ConfidenceWeighted,
    StreamingDefensive,
}

fn manual_step(
    scheme: Manual,
    domains: &[ToyDomain],
    reservoirs: &[Reservoir<f64>],
    rng: &mut Rng,
) -> Reservoir<f64> {
    // Technique 0 is the canonical.
    let map = PowerShift;
    let c = &domains[0];
    let k = domains.len() - 1;
    let confidences: Vec<f32> = reservoirs.iter().map(|r| r.confidence).collect();
    // Each technique's sample in the canonical domain, with its Jacobian.
    let shifted: Vec<Option<(f64, f32, f32)>> = reservoirs
        .iter()
        .zip(domains)
        .enumerate()
        .map(|(i, (r, d))| {
            let x = r.sample?;
            if i == 0 {
                return Some((x, 1.0, r.own_target));
            }
            map.shift(d, c, &x)
                .map(|s| (s.sample, s.jacobian, s.destination_target))
        })
        .collect();
    // Pulled-back targets of every technique at a canonical point y.
    let pulled = |y: f64| -> Vec<f32> {
        domains
            .iter()
            .enumerate()
            .map(|(j, d)| {
                if j == 0 {
                    c.target_pdf(y) as f32
                } else {
                    map.pulled_back_target_pdf(c, d, &y)
                }
            })
            .collect()
    };

    if let Manual::StreamingDefensive = scheme {
        let mut step = PairwiseResampler::new(PairwiseVariant::Defensive, k, reservoirs[0]);
        for i in 1..domains.len() {
            let neighbor = PairwiseNeighbor::new(
                &reservoirs[i],
                reservoirs[i]
                    .sample
                    .and_then(|x| map.shift(&domains[i], c, &x)),
                reservoirs[0]
                    .sample
                    .map_or(0.0, |xc| map.pulled_back_target_pdf(c, &domains[i], &xc)),
            );
            step.add_neighbor(neighbor, rng.next_f32());
        }
        return step.finalize(rng.next_f32());
    }

    let mut step = GrisResampler::new();
    let c_sum: f32 = confidences.iter().sum();
    for (i, s) in shifted.iter().enumerate() {
        let Some((y, jacobian, receiver_target)) = *s else {
            step.add_failed(confidences[i]);
            continue;
        };
        let p = pulled(y);
        let (cc, pc) = (confidences[0], p[0]);
        let nc = &confidences[1..];
        let np = &p[1..];
        let pair = |i: usize| mis::PairTerms {
            neighbor_confidence: nc[i - 1],
            neighbor_target_pdf: np[i - 1],
            canonical_confidence: cc,
            canonical_target_pdf: pc,
        };
        let m = match scheme {
            Manual::OneOverZ | Manual::Contribution => confidences[i],
            Manual::Balance => mis::generalized_balance(i, &confidences, &p),
            Manual::Pairwise if i == 0 => mis::pairwise_canonical(cc, pc, nc, np),
            Manual::Pairwise => mis::pairwise_neighbor(pair(i), k),
            Manual::Defensive if i == 0 => mis::defensive_pairwise_canonical(cc, pc, nc, np),
            Manual::Defensive => mis::defensive_pairwise_neighbor(pair(i), k),
            Manual::ConfidenceWeighted if i == 0 => {
                mis::confidence_weighted_pairwise_canonical(cc, pc, nc, np)
            }
            Manual::ConfidenceWeighted => {
                mis::confidence_weighted_pairwise_neighbor(pair(i), nc.iter().sum())
            }
            Manual::StreamingDefensive => unreachable!(),
        };
        let input = GrisInput {
            sample: y,
            receiver_target,
            ucw: reservoirs[i].ucw,
            jacobian,
            confidence: confidences[i],
        };
        step.add(input, m, rng.next_f32());
    }
    match scheme {
        Manual::OneOverZ | Manual::Contribution => {
            let Some(s) = step.selected_input() else {
                return step.finalize_scaled(0.0);
            };
            let y = *step.selected().unwrap();
            let p = pulled(y);
            let scale = if let Manual::OneOverZ = scheme {
                mis::one_over_z(&confidences, &p)
            } else {
                mis::contribution_scale(s, &confidences, &p)
            };
            let _ = c_sum;
            step.finalize_scaled(scale)
        }
        _ => step.finalize(),
    }
}

#[test]
fn gris_low_level_api_is_unbiased_for_every_unbiased_scheme() {
    let (canonical, neighbors) = toy_domains();
    let domains: Vec<ToyDomain> = std::iter::once(canonical).chain(neighbors).collect();
    for (i, scheme) in [
        Manual::OneOverZ,
        Manual::Contribution,
        Manual::Balance,
        Manual::Pairwise,
        Manual::Defensive,
        Manual::ConfidenceWeighted,
        Manual::StreamingDefensive,
    ]
    .into_iter()
    .enumerate()
    {
        let mut rng = Rng::new(400 + i as u64);
        let mut stats = Stats::default();
        for _ in 0..trials(120_000) {
            let reservoirs: Vec<Reservoir<f64>> =
                domains.iter().map(|d| d.sample(&mut rng)).collect();
            let out = manual_step(scheme, &domains, &reservoirs, &mut rng);
            stats.push(
                out.sample
                    .map_or(0.0, |y| toy_integrand(y) * f64::from(out.ucw)),
            );
        }
        stats.assert_unbiased(TOY_INTEGRAL, &format!("low-level {scheme:?}"));
    }
}
