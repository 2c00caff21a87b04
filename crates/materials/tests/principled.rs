//! Statistical tests of the principled models (`principled`, `principledthin`), in the manner of
//! `chi2.rs`: chi-square of `sample()` against `pdf_sa`, the mass of `pdf_sa`, agreement of
//! `sample` with `eval`/`pdf_sa`, and a furnace that compares the BSDF's own estimate of
//! `∫ eval dωi` (`f/pdf` of its samples) with an estimate independent of its sampling (uniform
//! directions). Burley's models are not energy conserving (retro-reflection, sheen and clearcoat
//! add energy), so the furnace checks agreement of the two estimates, not an albedo below one.
//!
//! The negative control bins the samples of a clearcoated principled against the density of the
//! same model without its clearcoat lobe, which must be rejected with p < 1e-6.

use glam::Vec3;
use restir_materials::{Bsdf, LobeFlags, Principled, PrincipledThin, eta_of_specular};
use restir_sampling::{Pcg32, warp};
use restir_testkit::{Histogram, Quadrature, SphereGrid, sidak_level};

/// One BSDF under test, with the relative IOR its transmission sees (1 for the thin sheet).
struct Case {
    name: &'static str,
    bsdf: Bsdf,
    eta: f32,
}

fn cases() -> Vec<Case> {
    let base = Principled {
        base_color: Vec3::new(0.2, 0.8, 0.1),
        roughness: 0.4,
        ..Principled::default()
    };
    let thin = PrincipledThin {
        base_color: Vec3::new(0.7, 0.1, 0.1),
        eta: 1.33,
        ..PrincipledThin::default()
    };
    let mut v = vec![
        Case {
            name: "principled defaults",
            bsdf: Bsdf::principled(Principled::default()),
            eta: 1.0,
        },
        Case {
            name: "principled metallic anisotropic clearcoat sheen",
            bsdf: Bsdf::principled(Principled {
                metallic: 0.7,
                anisotropic: 0.8,
                clearcoat: 0.9,
                clearcoat_gloss: 0.3,
                sheen: 0.9,
                sheen_tint: 0.5,
                spec_tint: 0.4,
                eta: eta_of_specular(0.7),
                ..base
            }),
            eta: 1.0,
        },
        Case {
            name: "principled two-sided flatness",
            bsdf: Bsdf::principled(Principled {
                flatness: 0.6,
                roughness: 0.8,
                clearcoat: 0.5,
                ..base
            })
            .two_sided(),
            eta: 1.0,
        },
    ];
    for (name, eta) in [
        ("principled spec_trans η=1.5", 1.5f32),
        ("principled spec_trans η=0.7", 0.7),
    ] {
        v.push(Case {
            name,
            bsdf: Bsdf::principled(Principled {
                spec_trans: 0.7,
                metallic: 0.1,
                anisotropic: 0.4,
                clearcoat: 0.6,
                sheen: 0.2,
                roughness: 0.3,
                eta,
                ..base
            }),
            eta,
        });
    }
    v.push(Case {
        name: "principledthin defaults",
        bsdf: Bsdf::principled_thin(PrincipledThin::default()),
        eta: 1.0,
    });
    v.push(Case {
        name: "principledthin spec_trans diff_trans sheen",
        bsdf: Bsdf::principled_thin(PrincipledThin {
            anisotropic: 0.6,
            spec_trans: 0.5,
            diff_trans: 1.4,
            sheen: 0.8,
            sheen_tint: 0.3,
            spec_tint: 0.5,
            flatness: 0.3,
            roughness: 0.35,
            ..thin
        }),
        eta: 1.0,
    });
    v.push(Case {
        name: "principledthin all specular",
        bsdf: Bsdf::principled_thin(PrincipledThin {
            spec_trans: 1.0,
            roughness: 0.6,
            ..thin
        }),
        eta: 1.0,
    });
    v
}

/// Viewer directions on both sides (grazing ones are left to `chi2.rs`'s reasoning: the
/// quadrature cannot resolve a microfacet lobe seen at `cos θ < 5e-3`).
fn wos() -> Vec<Vec3> {
    let dir = |cos_theta: f32, phi: f32| {
        let s = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), cos_theta)
    };
    vec![
        Vec3::Z,
        dir(0.7, 0.3),
        dir(0.17, 2.0),
        dir(0.02, -1.2),
        dir(-0.6, 1.0),
        dir(-0.1, 0.5),
        -Vec3::Z,
    ]
}

const SAMPLES: usize = 400_000;

fn seed(case: usize, wo: usize) -> u64 {
    0x5EED_0000 | (case as u64) << 8 | wo as u64
}

fn pdf_cells(grid: &SphereGrid, bsdf: &Bsdf, wo: Vec3) -> Vec<f64> {
    grid.integrate(|wi| bsdf.pdf_sa(wo, wi) as f64, &Quadrature::default())
}

fn sample_histogram(grid: &SphereGrid, bsdf: &Bsdf, wo: Vec3, seed: u64, n: usize) -> Histogram {
    let mut rng = Pcg32::new(seed, 1);
    let mut hist = Histogram::new(grid.len());
    for _ in 0..n {
        let u_lobe = rng.next_f32();
        match bsdf.sample(wo, u_lobe, rng.next_2d()) {
            Some(s) if !s.lobe.is_delta() => hist.record(grid.bin(s.wi)),
            _ => hist.record_remainder(),
        }
    }
    hist
}

/// Runs `f` on every case, spread over the cores (fixed seeds per case, so the outcome does not
/// depend on the scheduling).
fn for_each_case(f: impl Fn(usize, &Case) + Sync) {
    let cases = cases();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(case) = cases.get(i) else { break };
                    f(i, case);
                }
            });
        }
    });
}

/// Whether anything is sampled at `wo` (a one-sided principled is black from behind).
fn scatters(case: &Case, wo: Vec3) -> bool {
    wo.z > 0.0 || case.bsdf.two_sided || case.bsdf.kind.transmits()
}

#[test]
fn chi2_sampled_directions() {
    let tests = cases()
        .iter()
        .map(|c| wos().iter().filter(|&&wo| scatters(c, wo)).count())
        .sum();
    let level = sidak_level(0.01, tests);
    let grid = SphereGrid::default();
    for_each_case(|ci, case| {
        for (wi_, wo) in wos().into_iter().enumerate() {
            let what = format!("{} at wo = {wo}", case.name);
            let p = pdf_cells(&grid, &case.bsdf, wo);
            let hist = sample_histogram(&grid, &case.bsdf, wo, seed(ci, wi_), SAMPLES);
            if !scatters(case, wo) {
                assert_eq!(hist.remainder(), SAMPLES as u64, "{what}: smooth samples");
                assert!(p.iter().all(|&x| x == 0.0), "{what}: pdf_sa must be zero");
                continue;
            }
            let mass: f64 = p.iter().sum();
            assert!(mass <= 1.0 + 1e-3, "{what}: ∫ pdf_sa = {mass}");
            match hist.chi2(&p) {
                Ok(o) => {
                    eprintln!("{what}: {o}");
                    assert!(o.accepts(level), "{what}: rejected at {level:.2e}: {o}");
                }
                Err(e) => panic!("{what}: {e}"),
            }
        }
    });
}

/// `sample` reports the model's own `eval` and `pdf_sa`, never a delta lobe, and well-formed
/// values.
#[test]
fn sample_agrees_with_eval_and_pdf() {
    for (ci, case) in cases().iter().enumerate() {
        assert!(
            !case.bsdf.flags().contains(LobeFlags::DELTA),
            "{}",
            case.name
        );
        for (wi_, wo) in wos().into_iter().enumerate() {
            let mut rng = Pcg32::new(seed(ci, wi_), 2);
            for _ in 0..20_000 {
                let u_lobe = rng.next_f32();
                let Some(s) = case.bsdf.sample(wo, u_lobe, rng.next_2d()) else {
                    continue;
                };
                let what = format!("{} at wo = {wo}, wi = {}", case.name, s.wi);
                assert!(scatters(case, wo), "{what}: sampled from a black side");
                assert!((s.wi.length() - 1.0).abs() < 1e-4, "{what}: not unit");
                assert!(
                    s.f.is_finite() && s.f.min_element() >= 0.0,
                    "{what}: {}",
                    s.f
                );
                let (eval, pdf) = (case.bsdf.eval(wo, s.wi), case.bsdf.pdf_sa(wo, s.wi));
                assert!(
                    (pdf - s.pdf_sa).abs() <= 1e-4 * s.pdf_sa,
                    "{what}: {pdf} vs {}",
                    s.pdf_sa
                );
                let (ratio, reported) = (eval / pdf, s.f / s.pdf_sa);
                assert!(
                    (ratio - reported).abs().max_element() <= 1e-4 * reported.max_element() + 1e-6,
                    "{what}: eval/pdf {ratio} vs f/pdf {reported}"
                );
            }
        }
    }
}

/// Mean and standard error per channel.
#[derive(Default)]
struct Mean {
    n: f64,
    sum: [f64; 3],
    sum2: [f64; 3],
}

impl Mean {
    fn push(&mut self, v: Vec3) {
        assert!(v.is_finite(), "non-finite estimate {v}");
        self.n += 1.0;
        for k in 0..3 {
            self.sum[k] += f64::from(v[k]);
            self.sum2[k] += f64::from(v[k]).powi(2);
        }
    }
    fn mean(&self, k: usize) -> f64 {
        self.sum[k] / self.n
    }
    fn var_of_mean(&self, k: usize) -> f64 {
        let m = self.mean(k);
        (self.sum2[k] / self.n - m * m).max(0.0) / (self.n - 1.0)
    }
}

/// The BSDF's own estimate of `∫ eval·(transmitted energy) dωi` (`f/pdf` of its samples) agrees
/// with uniform sphere sampling of `eval` within 4.5 combined standard errors: the sampler's
/// weights are unbiased for its `eval`.
#[test]
fn furnace_sampled_equals_uniform() {
    const N: usize = 1_000_000;
    for_each_case(|ci, case| {
        for (wi_, wo) in wos().into_iter().enumerate() {
            let energy = |wi: Vec3| {
                if wo.z * wi.z < 0.0 {
                    let e = if wo.z > 0.0 { case.eta } else { 1.0 / case.eta };
                    e * e
                } else {
                    1.0
                }
            };
            let mut rng = Pcg32::new(seed(ci, wi_), 3);
            let (mut uniform, mut sampled) = (Mean::default(), Mean::default());
            for _ in 0..N {
                let wi = warp::sample_uniform_sphere(rng.next_2d());
                uniform.push(case.bsdf.eval(wo, wi) * energy(wi) / warp::UNIFORM_SPHERE_PDF);
                let u_lobe = rng.next_f32();
                sampled.push(
                    case.bsdf
                        .sample(wo, u_lobe, rng.next_2d())
                        .map_or(Vec3::ZERO, |s| s.f / s.pdf_sa * energy(s.wi)),
                );
            }
            for k in 0..3 {
                let (a, b) = (uniform.mean(k), sampled.mean(k));
                let se = (uniform.var_of_mean(k) + sampled.var_of_mean(k)).sqrt();
                assert!(
                    (a - b).abs() <= 4.5 * se + 1e-6,
                    "{} at wo = {wo}, channel {k}: uniform {a} vs sampled {b} (± {se})",
                    case.name
                );
            }
        }
    });
}

/// Negative control: a clearcoated principled's samples against the density of the same model
/// without the clearcoat (as if `pdf_sa` had forgotten that lobe's share) must be rejected.
#[test]
fn control_samples_vs_pdf_without_clearcoat() {
    let grid = SphereGrid::default();
    let p = Principled {
        clearcoat: 1.0,
        clearcoat_gloss: 0.2,
        roughness: 0.6,
        ..Principled::default()
    };
    let wo = Vec3::new(0.3, 0.2, 0.93).normalize();
    let hist = sample_histogram(&grid, &Bsdf::principled(p), wo, 96, SAMPLES);
    let wrong = Bsdf::principled(Principled {
        clearcoat: 0.0,
        ..p
    });
    let o = hist
        .chi2(&pdf_cells(&grid, &wrong, wo))
        .unwrap_or_else(|e| panic!("expected a p-value, got {e}"));
    eprintln!("principled samples vs the pdf without clearcoat: {o}");
    assert!(o.p_value < 1e-6, "a wrong pdf passed: {o}");
}
