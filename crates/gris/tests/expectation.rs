//! [`resample_observed`]'s expectation over the selection: for fixed inputs, the mean of
//! `f(Y)·W_Y` over many selections (fresh uniforms, the same reservoirs and shifts) must equal
//! `s · Σ_i w_i · f(Y_i) / p̂_c(Y_i)` computed from the observed inputs, for every MIS scheme
//! that reports a scale, within five standard errors of the mean. The integrand is a colour
//! (three channels) whose ratio to the target differs between samples, as a light's colour
//! does. Negative control: the same sum without the scale (`s = 1`) must be rejected.

use restir_gris::{MisScheme, Reservoir, ShiftMap, Shifted, resample_observed};
use restir_testkit::SplitMix64 as Rng;

/// A domain: a receiver whose target at sample `x` is `1 + slope·x` times a bump.
struct Domain {
    slope: f32,
    offset: f32,
}

impl Domain {
    fn target(&self, x: f32) -> f32 {
        (1.0 + self.slope * x) * (1.2 + (3.0 * (x + self.offset)).sin())
    }
}

/// A shift that moves samples by the difference of the domains' offsets (Jacobian 1) and fails
/// beyond the unit interval.
struct Offset;

impl ShiftMap<f32> for Offset {
    type Domain = Domain;
    fn shift(&self, from: &Domain, to: &Domain, x: &f32) -> Option<Shifted<f32>> {
        let y = x + (from.offset - to.offset) * 0.5;
        (0.0..1.0)
            .contains(&y)
            .then(|| Shifted::identity(y, to.target(y)))
    }
}

/// The integrand at the canonical receiver: the target times a colour that depends on the
/// sample, so `f/p̂` varies between inputs.
fn ratio(y: f32) -> [f64; 3] {
    [
        0.5 + f64::from(y),
        1.5 - f64::from(y),
        0.2 + 2.0 * f64::from(y * y),
    ]
}

fn reservoir(domain: &Domain, x: f32, ucw: f32, confidence: f32) -> Reservoir<f32> {
    Reservoir {
        sample: Some(x),
        ucw,
        confidence,
        own_target: domain.target(x),
    }
}

/// For one scheme: (mean of f(Y)·W_Y over `trials` selections, its standard error, the
/// observed expectation, the observed sum without the scale), per channel.
fn compare(scheme: MisScheme, trials: usize) -> ([f64; 3], [f64; 3], [f64; 3], [f64; 3]) {
    let canonical_domain = Domain {
        slope: 1.0,
        offset: 0.0,
    };
    let domains: Vec<Domain> = (0..5)
        .map(|i| Domain {
            slope: 0.3 * i as f32,
            offset: 0.1 * i as f32 - 0.2,
        })
        .collect();
    let canonical = reservoir(&canonical_domain, 0.35, 1.7, 1.0);
    let inputs: Vec<Reservoir<f32>> = domains
        .iter()
        .enumerate()
        .map(|(i, d)| {
            reservoir(
                d,
                0.1 + 0.17 * i as f32,
                0.8 + 0.3 * i as f32,
                1.0 + i as f32,
            )
        })
        .collect();
    let neighbors: Vec<(&Domain, &Reservoir<f32>)> = domains.iter().zip(&inputs).collect();

    let mut rng = Rng::new(0x0b5e_77ed);
    let mut sum = [0.0f64; 3];
    let mut observed = [0.0f64; 3];
    let mut scale = None;
    let mut moments = [[0.0f64; 2]; 3];
    for t in 0..trials {
        let mut acc = [0.0f64; 3];
        let (out, s) = resample_observed(
            &Offset,
            scheme,
            &canonical_domain,
            &canonical,
            &neighbors,
            || rng.next_f32(),
            &mut |y: &f32, w: f64| {
                for (a, r) in acc.iter_mut().zip(ratio(*y)) {
                    *a += w * r;
                }
            },
        );
        if t == 0 {
            observed = acc;
            scale = s;
        }
        // The observed inputs do not depend on the uniforms.
        assert_eq!(acc, observed, "{scheme:?}");
        if let Some(y) = out.sample {
            let f = ratio(y).map(|r| r * f64::from(out.own_target) * f64::from(out.ucw));
            for c in 0..3 {
                sum[c] += f[c];
                moments[c][0] += f[c];
                moments[c][1] += f[c] * f[c];
            }
        }
    }
    let n = trials as f64;
    let mean = sum.map(|s| s / n);
    let se = [0, 1, 2].map(|c| {
        let m = moments[c][0] / n;
        ((moments[c][1] / n - m * m).max(0.0) / n).sqrt()
    });
    let s = f64::from(scale.expect("the scheme reports a scale"));
    (mean, se, observed.map(|o| o * s), observed)
}

const SCHEMES: [MisScheme; 5] = [
    MisScheme::DefensivePairwise,
    MisScheme::Pairwise,
    MisScheme::ConfidenceWeightedPairwise,
    MisScheme::GeneralizedBalance,
    MisScheme::ConstantBiased,
];

#[test]
fn the_observed_inputs_give_the_selections_expectation() {
    for scheme in SCHEMES {
        let (mean, se, expected, _) = compare(scheme, 200_000);
        for c in 0..3 {
            let z = (mean[c] - expected[c]) / se[c].max(1e-12);
            assert!(
                z.abs() < 5.0,
                "{scheme:?} channel {c}: mean {} expected {} (z = {z:.2})",
                mean[c],
                expected[c]
            );
        }
    }
}

/// Negative control: without the scale the sum is off by the MIS normalisation (`n + 1` for
/// defensive pairwise with five neighbours), far outside the tolerance.
#[test]
fn the_sum_without_its_scale_is_rejected() {
    let (mean, se, _, unscaled) = compare(MisScheme::DefensivePairwise, 200_000);
    let z = (mean[0] - unscaled[0]) / se[0].max(1e-12);
    assert!(z.abs() > 5.0, "z = {z:.2}");
}

/// Schemes whose normalisation depends on the selected sample report no scale.
#[test]
fn selection_dependent_normalisations_report_no_scale() {
    let d = Domain {
        slope: 1.0,
        offset: 0.0,
    };
    let r = reservoir(&d, 0.4, 1.0, 1.0);
    let none: &[(&Domain, &Reservoir<f32>)] = &[];
    for scheme in [MisScheme::OneOverZ, MisScheme::Contribution] {
        let (_, s) = resample_observed(&Offset, scheme, &d, &r, none, || 0.5f32, &mut |_, _| {});
        assert_eq!(s, None, "{scheme:?}");
    }
}
