//! Statistical tests of every BSDF: chi-square of `sample()` against `pdf_sa`, the mass of
//! `pdf_sa`, agreement of `sample` with `eval`/`pdf_sa`, and a white furnace.
//!
//! Every check runs over the table [`cases`] × the directions [`wos`]; a new BSDF is tested by
//! adding one [`Case`] to the table.
//!
//! - **Chi-square** (`restir_testkit`, after Mitsuba 3): sampled `wi` are binned on a
//!   10 × 20 `(cos θ, φ)` grid over the whole sphere, `pdf_sa(wo, ·)` is integrated over the same
//!   cells; failed and delta-lobe samples are tested as one more cell whose expected count is
//!   `N · (1 − ∫ pdf_sa)`. A test fails when `p < sidak_level(0.01, m)` with `m` the number of
//!   chi-square tests run here, or at once when a sample lands where `pdf_sa` is zero.
//! - **Mass**: `∫ pdf_sa dω ≤ 1`, `= 1` for a BSDF that never fails to sample from the lit side
//!   (quadrature error below 1e-4).
//! - **Consistency**: for every sample, `eval(wo, wi) / pdf_sa(wo, wi) = f / pdf_sa` of the
//!   sample (relative 1e-4).
//! - **White furnace**: the albedo `∫ eval(wo, wi) dωi` estimated by uniform sphere sampling
//!   (independent of `sample`) and by `sample` itself equals the known albedo within 4 standard
//!   errors where known (1 for a white diffuse surface), and is ≤ 1 + 4 standard errors always.
//!   Transmitted radiance is scaled by `1/η²` (see the crate docs), so the furnace measures
//!   *energy*: transmitted values are multiplied back by `η'²`, the relative IOR seen from `wo`.
//!   The uniform estimate misses delta lobes and is compared with the known albedo only for
//!   models without them.
//!
//! A negative control (diffuse samples against the uniform-hemisphere pdf) must be rejected with
//! p < 1e-6.

use glam::Vec3;
use restir_materials::{Bsdf, Distribution, LobeFlags, Microfacet, NormalMap, ior};
use restir_sampling::{Pcg32, warp};
use restir_testkit::{Chi2Error, Chi2Outcome, Histogram, Quadrature, SphereGrid, sidak_level};

/// How much of `pdf_sa`'s mass a BSDF has from the side `wo` is on.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mass {
    /// `∫ pdf_sa = 1`: every sample succeeds and no lobe is a delta.
    One,
    /// `∫ pdf_sa ≤ 1`: samples may fail or come from delta lobes.
    AtMostOne,
    /// Nothing is scattered.
    Zero,
}

/// One BSDF under test.
#[derive(Clone, Debug)]
struct Case {
    name: &'static str,
    bsdf: Bsdf,
    /// `pdf_sa`'s mass when `wo` is on a side the BSDF scatters from (the front, or either side
    /// when two-sided). From the other side the mass is always zero.
    mass: Mass,
    /// The albedo `∫ eval dωi` (with delta lobes, and in energy: see the file docs) per channel
    /// when `wo` is on a scattering side, if known exactly; otherwise only `≤ 1` is checked.
    albedo: Option<Vec3>,
    /// Relative IOR of a transmitting model (1 otherwise), to turn radiance into energy.
    eta: f32,
}

/// The BSDFs under test. To test a new model, add a case, e.g.
/// `Case { name: "rough conductor α=0.3", bsdf: .., mass: Mass::AtMostOne, albedo: None }`
/// (microfacet models without multiple scattering lose energy, so only `≤ 1` is checked).
/// Delta lobes (smooth dielectric, mirror) use `Mass::AtMostOne`: their samples are counted in
/// the chi-square's remainder cell, and a BSDF with only delta lobes (`pdf_sa` zero everywhere)
/// has no directions to test, only the checks that every sample is a delta sample.
fn cases() -> Vec<Case> {
    let mut v = vec![
        Case {
            name: "diffuse white",
            bsdf: Bsdf::diffuse(Vec3::ONE),
            mass: Mass::One,
            albedo: Some(Vec3::ONE),
            eta: 1.0,
        },
        Case {
            name: "diffuse coloured",
            bsdf: Bsdf::diffuse(Vec3::new(0.8, 0.5, 0.2)),
            mass: Mass::One,
            albedo: Some(Vec3::new(0.8, 0.5, 0.2)),
            eta: 1.0,
        },
        Case {
            name: "diffuse white two-sided",
            bsdf: Bsdf::diffuse(Vec3::ONE).two_sided(),
            mass: Mass::One,
            albedo: Some(Vec3::ONE),
            eta: 1.0,
        },
        Case {
            name: "diffuse coloured two-sided",
            bsdf: Bsdf::diffuse(Vec3::new(0.1, 0.9, 0.4)).two_sided(),
            mass: Mass::One,
            albedo: Some(Vec3::new(0.1, 0.9, 0.4)),
            eta: 1.0,
        },
        Case {
            name: "black",
            bsdf: Bsdf::black(),
            mass: Mass::Zero,
            albedo: Some(Vec3::ZERO),
            eta: 1.0,
        },
    ];
    let mirror = ior::conductor("none").unwrap();
    let gold = ior::conductor("Au").unwrap();
    let glass = 1.5046 / 1.000_277;
    let pp = 1.49 / 1.000_277;
    // Smooth (delta) models: every sample is a delta sample.
    v.push(Case {
        name: "conductor mirror",
        bsdf: Bsdf::conductor(mirror.0, mirror.1, Vec3::ONE),
        mass: Mass::AtMostOne,
        albedo: Some(Vec3::ONE),
        eta: 1.0,
    });
    v.push(Case {
        name: "dielectric bk7",
        bsdf: Bsdf::dielectric(glass, Vec3::ONE, Vec3::ONE),
        mass: Mass::AtMostOne,
        albedo: Some(Vec3::ONE),
        eta: glass,
    });
    v.push(Case {
        name: "null",
        bsdf: Bsdf::null(),
        mass: Mass::AtMostOne,
        albedo: Some(Vec3::ONE),
        eta: 1.0,
    });
    // Masks: the model with probability `opacity`, a pass-through (delta) otherwise.
    v.push(Case {
        name: "mask 0.3 of two-sided diffuse",
        bsdf: Bsdf::diffuse(Vec3::new(0.8, 0.5, 0.2))
            .two_sided()
            .masked(0.3),
        mass: Mass::AtMostOne,
        albedo: Some(Vec3::new(0.8, 0.5, 0.2) * 0.3 + Vec3::splat(0.7)),
        eta: 1.0,
    });
    v.push(Case {
        // (Not around a transmitting model: the furnace's energy factor assumes every
        // transmission refracts.)
        name: "mask 0.6 of two-sided rough conductor",
        bsdf: Bsdf::rough_conductor(
            gold.0,
            gold.1,
            Vec3::ONE,
            Microfacet::new(Distribution::Ggx, 0.3),
        )
        .two_sided()
        .masked(0.6),
        mass: Mass::AtMostOne,
        albedo: None,
        eta: 1.0,
    });
    // Normal maps: the model in a perturbed frame; samples that cross between the frames fail,
    // and the shadowing term lowers the albedo.
    let tilted = NormalMap::new(Vec3::new(0.75, 0.4, 0.85), true, true);
    v.push(Case {
        name: "normal-mapped two-sided diffuse",
        bsdf: Bsdf::diffuse(Vec3::new(0.8, 0.5, 0.2))
            .two_sided()
            .normal_mapped(tilted),
        mass: Mass::AtMostOne,
        albedo: None,
        eta: 1.0,
    });
    v.push(Case {
        name: "normal-mapped two-sided anisotropic rough conductor, no flip, no shadowing",
        bsdf: Bsdf::rough_conductor(
            gold.0,
            gold.1,
            Vec3::ONE,
            Microfacet::anisotropic(Distribution::Ggx, 0.25, 0.05),
        )
        .two_sided()
        .normal_mapped(NormalMap::new(Vec3::new(0.3, 0.6, 0.8), false, false)),
        mass: Mass::AtMostOne,
        albedo: None,
        eta: 1.0,
    });
    v.push(Case {
        name: "mask 0.5 of a normal-mapped two-sided rough plastic",
        bsdf: Bsdf::rough_plastic(
            pp,
            Vec3::new(0.2, 0.5, 0.8),
            Vec3::ONE,
            false,
            Distribution::Beckmann,
            0.2,
        )
        .two_sided()
        .normal_mapped(tilted)
        .masked(0.5),
        mass: Mass::AtMostOne,
        albedo: None,
        eta: 1.0,
    });
    v.push(Case {
        name: "plastic",
        bsdf: Bsdf::plastic(pp, Vec3::new(0.2, 0.5, 0.8), Vec3::ONE, false),
        mass: Mass::AtMostOne,
        albedo: None,
        eta: 1.0,
    });
    v.push(Case {
        name: "plastic nonlinear two-sided",
        bsdf: Bsdf::plastic(pp, Vec3::new(0.9, 0.1, 0.5), Vec3::splat(0.7), true).two_sided(),
        mass: Mass::AtMostOne,
        albedo: None,
        eta: 1.0,
    });
    // Blends: a component picked by weight; smooth samples carry the whole mix's eval and pdf.
    let coloured = Vec3::new(0.8, 0.5, 0.2);
    v.push(Case {
        name: "blend 0.3 of coloured and white diffuse",
        bsdf: Bsdf::blend(0.3, Bsdf::diffuse(coloured), Bsdf::diffuse(Vec3::ONE)),
        mass: Mass::One,
        albedo: Some(coloured * 0.7 + Vec3::splat(0.3)),
        eta: 1.0,
    });
    v.push(Case {
        name: "blend 0.5 of diffuse and a mirror (delta)",
        bsdf: Bsdf::blend(
            0.5,
            Bsdf::diffuse(coloured),
            Bsdf::conductor(mirror.0, mirror.1, Vec3::ONE),
        ),
        mass: Mass::AtMostOne,
        albedo: Some(coloured * 0.5 + Vec3::splat(0.5)),
        eta: 1.0,
    });
    v.push(Case {
        name: "blend 0.6 of rough plastic and rough gold",
        bsdf: Bsdf::blend(
            0.6,
            Bsdf::rough_plastic(pp, coloured, Vec3::ONE, false, Distribution::Beckmann, 0.2),
            Bsdf::rough_conductor(
                gold.0,
                gold.1,
                Vec3::ONE,
                Microfacet::new(Distribution::Ggx, 0.3),
            ),
        ),
        mass: Mass::AtMostOne,
        albedo: None,
        eta: 1.0,
    });
    v.push(Case {
        name: "blend 0.4 of two-sided diffuse and smooth glass",
        bsdf: Bsdf::blend(
            0.4,
            Bsdf::diffuse(coloured).two_sided(),
            Bsdf::dielectric(glass, Vec3::ONE, Vec3::ONE),
        ),
        mass: Mass::AtMostOne,
        albedo: None,
        eta: glass,
    });
    v.push(Case {
        name: "two-sided blend 0.5 of a blend (diffuse, rough conductor) and a normal-mapped mask",
        bsdf: Bsdf::blend(
            0.5,
            Bsdf::blend(
                0.25,
                Bsdf::diffuse(coloured),
                Bsdf::rough_conductor(
                    mirror.0,
                    mirror.1,
                    Vec3::ONE,
                    Microfacet::new(Distribution::Beckmann, 0.2),
                ),
            ),
            Bsdf::diffuse(Vec3::ONE).normal_mapped(tilted).masked(0.7),
        )
        .two_sided(),
        mass: Mass::AtMostOne,
        albedo: None,
        eta: 1.0,
    });
    for (dist, dname) in [
        (Distribution::Beckmann, "beckmann"),
        (Distribution::Ggx, "ggx"),
    ] {
        for alpha in [0.05f32, 0.2, 0.6] {
            let mf = Microfacet::new(dist, alpha);
            let name = |what: &str| -> &'static str {
                Box::leak(format!("{what} {dname} α={alpha}").into_boxed_str())
            };
            v.push(Case {
                name: name("rough conductor mirror"),
                bsdf: Bsdf::rough_conductor(mirror.0, mirror.1, Vec3::ONE, mf),
                mass: Mass::AtMostOne,
                albedo: None,
                eta: 1.0,
            });
            v.push(Case {
                name: name("rough dielectric bk7"),
                bsdf: Bsdf::rough_dielectric(glass, Vec3::ONE, Vec3::ONE, mf),
                mass: Mass::AtMostOne,
                albedo: None,
                eta: glass,
            });
            v.push(Case {
                name: name("rough plastic"),
                bsdf: Bsdf::rough_plastic(
                    pp,
                    Vec3::new(0.2, 0.5, 0.8),
                    Vec3::ONE,
                    false,
                    dist,
                    alpha,
                ),
                mass: Mass::AtMostOne,
                albedo: None,
                eta: 1.0,
            });
        }
        let aniso = Microfacet::anisotropic(dist, 0.05, 0.4);
        v.push(Case {
            name: Box::leak(
                format!("rough conductor gold two-sided {dname} α=(0.05, 0.4)").into_boxed_str(),
            ),
            bsdf: Bsdf::rough_conductor(gold.0, gold.1, Vec3::ONE, aniso).two_sided(),
            mass: Mass::AtMostOne,
            albedo: None,
            eta: 1.0,
        });
        v.push(Case {
            name: Box::leak(
                format!("rough dielectric water {dname} α=(0.05, 0.4)").into_boxed_str(),
            ),
            bsdf: Bsdf::rough_dielectric(1.333, Vec3::ONE, Vec3::splat(0.5), aniso),
            mass: Mass::AtMostOne,
            albedo: None,
            eta: 1.333,
        });
    }
    // Appended last, so the cases above keep their random streams.
    v.push(Case {
        name: "thin dielectric bk7",
        bsdf: Bsdf::thin_dielectric(glass, Vec3::ONE, Vec3::ONE),
        mass: Mass::AtMostOne,
        albedo: Some(Vec3::ONE),
        eta: 1.0,
    });
    v
}

/// Outgoing directions: normal, oblique, grazing, and the same below the surface.
fn wos() -> Vec<Vec3> {
    let dir = |cos_theta: f32, phi: f32| {
        let s = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), cos_theta)
    };
    vec![
        Vec3::Z,
        dir(0.7, 0.3),
        dir(0.17, 2.0),
        dir(0.01, -1.2),
        dir(1e-3, 4.0),
        dir(-0.6, 1.0),
        dir(-0.01, 0.5),
        -Vec3::Z,
    ]
}

impl Case {
    /// Whether `wo` sees a scattering side.
    fn lit(&self, wo: Vec3) -> bool {
        wo.z > 0.0 || ((self.bsdf.two_sided || self.bsdf.kind.transmits()) && wo.z < 0.0)
    }

    /// Factor turning a transmitted radiance weight into energy: `η'²`, the relative IOR seen
    /// from `wo`, when `wi` is on the other side.
    fn energy(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z * wi.z < 0.0 {
            let eta = if wo.z > 0.0 { self.eta } else { 1.0 / self.eta };
            eta * eta
        } else {
            1.0
        }
    }

    fn mass(&self, wo: Vec3) -> Mass {
        if self.lit(wo) { self.mass } else { Mass::Zero }
    }

    fn albedo(&self, wo: Vec3) -> Option<Vec3> {
        if self.lit(wo) {
            self.albedo
        } else {
            Some(Vec3::ZERO)
        }
    }
}

const SAMPLES: usize = 400_000;

/// Whether the chi-square test runs for `case` at `wo` (see [`MICROFACET_MIN_COS`]).
fn chi2_runs(case: &Case, wo: Vec3) -> bool {
    let glossy = case.bsdf.flags().contains(LobeFlags::GLOSSY);
    !(glossy && wo.z.abs() < MICROFACET_MIN_COS)
}

/// Every (case, wo) with something to sample is one chi-square test.
fn chi2_test_count() -> usize {
    let wos = wos();
    cases()
        .iter()
        .map(|c| {
            wos.iter()
                .filter(|&&wo| c.mass(wo) != Mass::Zero && chi2_runs(c, wo))
                .count()
        })
        .sum()
}

fn seed(case: usize, wo: usize) -> u64 {
    (case as u64) << 16 | wo as u64
}

/// Per-cell probabilities of `pdf_sa(wo, ·)` on `grid`.
fn pdf_cells(grid: &SphereGrid, bsdf: &Bsdf, wo: Vec3) -> Vec<f64> {
    grid.integrate(|wi| bsdf.pdf_sa(wo, wi) as f64, &Quadrature::default())
}

/// The chi-square test skips `|cos θo|` below this for microfacet models. Seen from
/// `cos θo = 10⁻³`, a microfacet reflection lobe is a sliver about 10⁻³ thick in `cos θ` at the
/// horizon, which the `(cos θ, φ)` quadrature cannot resolve: it loses ~1.6e-4 of the mass
/// (measured for Beckmann α = 0.05), and the test then fails on its own quadrature. The same
/// `pdf_sa` integrated in microfacet-normal space (where the lobe is smooth) gives the mass the
/// sampler produces (0.99991 vs 0.99990); mass, consistency and furnace checks still run there.
const MICROFACET_MIN_COS: f32 = 5e-3;

/// Bins `n` samples of `bsdf` at `wo`: smooth samples by direction, failed and delta samples in
/// the remainder.
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

/// Runs `f` on every case, spread over the available cores (the cases are independent and each
/// uses its own fixed seeds, so the outcome does not depend on the scheduling). A panic in any
/// case fails the test with that case's message.
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

#[test]
fn chi2_sampled_directions() {
    let level = sidak_level(0.01, chi2_test_count());
    let grid = SphereGrid::default();
    for_each_case(|ci, case| {
        for (wi_, wo) in wos().into_iter().enumerate() {
            if !chi2_runs(case, wo) {
                continue;
            }
            let what = format!("{} at wo = {wo}", case.name);
            let hist = sample_histogram(&grid, &case.bsdf, wo, seed(ci, wi_), SAMPLES);
            let p = pdf_cells(&grid, &case.bsdf, wo);
            if case.mass(wo) == Mass::Zero || p.iter().all(|&x| x == 0.0) {
                // Nothing to bin: every sample must have failed or come from a delta lobe.
                assert_eq!(hist.remainder(), SAMPLES as u64, "{what}: smooth samples");
                assert!(p.iter().all(|&x| x == 0.0), "{what}: pdf_sa must be zero");
                continue;
            }
            match hist.chi2(&p) {
                Ok(o) => {
                    eprintln!("{what}: {o}");
                    assert!(
                        o.accepts(level),
                        "{what}: rejected at level {level:.2e}: {o}"
                    );
                }
                Err(e) => panic!("{what}: {e}"),
            }
        }
    });
}

#[test]
fn pdf_mass_at_most_one() {
    let grid = SphereGrid::default();
    for case in cases() {
        for wo in wos() {
            let mass: f64 = pdf_cells(&grid, &case.bsdf, wo).iter().sum();
            let what = format!("{} at wo = {wo}: ∫ pdf_sa = {mass}", case.name);
            match case.mass(wo) {
                Mass::One => assert!((mass - 1.0).abs() < 1e-4, "{what}"),
                Mass::AtMostOne => assert!(mass <= 1.0 + 1e-4, "{what}"),
                Mass::Zero => assert_eq!(mass, 0.0, "{what}"),
            }
        }
    }
}

/// `sample` reports the same `f` and `pdf_sa` as `eval` and `pdf_sa`, so that
/// `eval / pdf_sa = f / pdf_sa` for every smooth sample, and samples are well-formed.
#[test]
fn sample_agrees_with_eval_and_pdf() {
    for (ci, case) in cases().iter().enumerate() {
        for (wi_, wo) in wos().into_iter().enumerate() {
            let mut rng = Pcg32::new(seed(ci, wi_), 2);
            for _ in 0..20_000 {
                let u_lobe = rng.next_f32();
                let Some(s) = case.bsdf.sample(wo, u_lobe, rng.next_2d()) else {
                    continue;
                };
                let what = format!("{} at wo = {wo}, wi = {}", case.name, s.wi);
                assert!(case.lit(wo), "{what}: sampled from a black side");
                assert!((s.wi.length() - 1.0).abs() < 1e-4, "{what}: not unit");
                assert!(
                    s.pdf_sa > 0.0 && s.pdf_sa.is_finite(),
                    "{what}: pdf {}",
                    s.pdf_sa
                );
                assert!(
                    s.f.is_finite() && s.f.min_element() >= 0.0,
                    "{what}: f {}",
                    s.f
                );
                if s.lobe.is_delta() {
                    continue;
                }
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

/// Running mean and standard error per channel.
#[derive(Default)]
struct MeanVec3 {
    n: f64,
    sum: [f64; 3],
    sum2: [f64; 3],
}

impl MeanVec3 {
    fn push(&mut self, v: Vec3) {
        assert!(v.is_finite(), "non-finite estimate {v}");
        self.n += 1.0;
        for k in 0..3 {
            self.sum[k] += v[k] as f64;
            self.sum2[k] += (v[k] as f64).powi(2);
        }
    }

    fn mean(&self, k: usize) -> f64 {
        self.sum[k] / self.n
    }

    fn std_error(&self, k: usize) -> f64 {
        let m = self.mean(k);
        ((self.sum2[k] / self.n - m * m).max(0.0) / (self.n - 1.0)).sqrt()
    }
}

/// `∫ eval(wo, wi) dωi` is the albedo: equal to the known value within 4 standard errors (plus
/// 1e-5 for rounding when the estimator has no variance), and never above one.
#[test]
fn white_furnace() {
    const N: usize = 400_000;
    for_each_case(|ci, case| {
        for (wi_, wo) in wos().into_iter().enumerate() {
            // Independent of `sample`: uniform directions over the sphere.
            let mut rng = Pcg32::new(seed(ci, wi_), 3);
            let mut uniform = MeanVec3::default();
            for _ in 0..N {
                let wi = warp::sample_uniform_sphere(rng.next_2d());
                uniform
                    .push(case.bsdf.eval(wo, wi) * case.energy(wo, wi) / warp::UNIFORM_SPHERE_PDF);
            }
            // With the BSDF's own sampling (f/pdf; zero when sampling fails).
            let mut sampled = MeanVec3::default();
            for _ in 0..N {
                let u_lobe = rng.next_f32();
                let v = case
                    .bsdf
                    .sample(wo, u_lobe, rng.next_2d())
                    .map_or(Vec3::ZERO, |s| s.f / s.pdf_sa * case.energy(wo, s.wi));
                sampled.push(v);
            }
            for (name, est) in [("uniform", &uniform), ("sampled", &sampled)] {
                for k in 0..3 {
                    let (m, se) = (est.mean(k), est.std_error(k));
                    let tol = 4.0 * se + 1e-5;
                    let what = format!(
                        "{} at wo = {wo}, {name} estimate, channel {k}: albedo {m} ± {se}",
                        case.name
                    );
                    assert!(m <= 1.0 + tol, "{what} exceeds one");
                    let has_delta = case.bsdf.flags().contains(LobeFlags::DELTA);
                    if let Some(albedo) = case.albedo(wo)
                        && !(name == "uniform" && has_delta && case.lit(wo))
                    {
                        let want = albedo[k] as f64;
                        assert!((m - want).abs() <= tol, "{what}, want {want}");
                    }
                }
            }
        }
    });
}

// ------------------------------------------------------------------------------------------
// Negative controls
// ------------------------------------------------------------------------------------------

fn rejected(what: &str, outcome: Result<Chi2Outcome, Chi2Error>) {
    let o = outcome.unwrap_or_else(|e| panic!("{what}: expected a p-value, got {e}"));
    eprintln!("{what}: {o}");
    assert!(o.p_value < 1e-6, "{what}: a wrong pdf passed: {o}");
}

/// A mask's samples against its model's pdf, as if `pdf_sa` had forgotten the opacity.
#[test]
fn control_mask_vs_unmasked_pdf() {
    let grid = SphereGrid::default();
    let inner = Bsdf::diffuse(Vec3::ONE).two_sided();
    let wo = Vec3::new(0.3, 0.2, 0.93).normalize();
    let hist = sample_histogram(&grid, &inner.masked(0.8), wo, 98, SAMPLES);
    rejected(
        "mask samples vs the unmasked pdf",
        hist.chi2(&pdf_cells(&grid, &inner, wo)),
    );
}

/// A normal-mapped diffuse's samples against the unperturbed model's pdf, as if `pdf_sa` had
/// forgotten the normal map.
#[test]
fn control_normal_map_vs_unperturbed_pdf() {
    let grid = SphereGrid::default();
    let inner = Bsdf::diffuse(Vec3::ONE);
    let mapped = inner.normal_mapped(NormalMap::new(Vec3::new(0.75, 0.4, 0.85), true, true));
    let wo = Vec3::new(0.3, 0.2, 0.93).normalize();
    let hist = sample_histogram(&grid, &mapped, wo, 97, SAMPLES);
    rejected(
        "normal-mapped samples vs the unperturbed pdf",
        hist.chi2(&pdf_cells(&grid, &inner, wo)),
    );
}

/// A blend's samples against the pdf of its first component alone, as if `pdf_sa` had
/// forgotten the mix.
#[test]
fn control_blend_vs_one_component_pdf() {
    let grid = SphereGrid::default();
    let first = Bsdf::diffuse(Vec3::ONE);
    let second = Bsdf::rough_conductor(
        Vec3::ZERO,
        Vec3::ONE,
        Vec3::ONE,
        Microfacet::new(Distribution::Ggx, 0.2),
    );
    let blend = Bsdf::blend(0.3, first, second);
    let wo = Vec3::new(0.3, 0.2, 0.93).normalize();
    let hist = sample_histogram(&grid, &blend, wo, 96, SAMPLES);
    rejected(
        "blend samples vs its first component's pdf",
        hist.chi2(&pdf_cells(&grid, &first, wo)),
    );
}

/// Diffuse samples against the uniform-hemisphere pdf, as if `pdf_sa` had forgotten the cosine.
#[test]
fn control_diffuse_vs_uniform_hemisphere_pdf() {
    let grid = SphereGrid::default();
    let bsdf = Bsdf::diffuse(Vec3::ONE);
    let wo = Vec3::new(0.3, 0.2, 0.93).normalize();
    let hist = sample_histogram(&grid, &bsdf, wo, 99, SAMPLES);
    let wrong = grid.integrate(
        |wi| {
            if wi.z > 0.0 {
                warp::UNIFORM_HEMISPHERE_PDF as f64
            } else {
                0.0
            }
        },
        &Quadrature::default(),
    );
    rejected(
        "diffuse samples vs uniform hemisphere pdf",
        hist.chi2(&wrong),
    );
}
