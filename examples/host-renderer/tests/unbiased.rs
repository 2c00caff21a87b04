//! ReSTIR DI from `restir-reuse`, run by a host renderer that shares no scene, geometry or light
//! code with the workspace, is unbiased: per 8×8 block, the mean over independent seeds agrees
//! with the host's own light-sampling estimator within the standard error, for the default
//! settings, with temporal reuse and visibility at shading, and with the balance heuristic over
//! non-reciprocal neighbours. Negative control: a host whose sampler reports the uniform light
//! selection's density while it selects by power (a wrong pdf) is caught.

use glam::Vec3;
use host_renderer::{Lights, Scene, render_reference, render_restir};
use restir_reuse::direct::{DirectSettings, Visibility};
use restir_reuse::{Pcg32, ReuseSettings};
use restir_testkit::blocks::{block_means, block_statistics, max_z};

const W: usize = 64;
const H: usize = 48;
const BLOCK: u32 = 8;
const SEEDS: u64 = 16;
/// 48 blocks compared with 16 seeds each (t with 15 degrees of freedom per block): about a 1 %
/// chance that an unbiased estimator exceeds this somewhere.
const Z_MAX: f64 = 4.5;

fn scene() -> Scene {
    Scene::demo(3, 6)
}

fn stats(render: impl Fn(u64) -> Vec<Vec3>) -> Vec<(f64, f64)> {
    block_statistics(
        |seed| block_means(W as u32, H as u32, &render(seed), BLOCK),
        SEEDS,
        1000,
    )
}

fn reference(scene: &Scene) -> Vec<(f64, f64)> {
    stats(|seed| render_reference(scene, W, H, 64, seed).pixels)
}

fn restir(scene: &Scene, wrong_pdf: bool, settings: DirectSettings) -> Vec<(f64, f64)> {
    let lights = Lights { scene, wrong_pdf };
    stats(|seed| render_restir(&lights, W, H, 4, seed ^ 0x5eed, settings).pixels)
}

#[test]
fn restir_di_through_the_host_traits_is_unbiased() {
    let scene = scene();
    let reference = reference(&scene);
    let configs = [
        ("defaults", DirectSettings::default()),
        (
            "temporal, visibility at shading",
            DirectSettings {
                visibility: Visibility::Shading,
                reuse: ReuseSettings {
                    temporal: true,
                    ..ReuseSettings::default()
                },
                ..DirectSettings::default()
            },
        ),
        (
            "the selected sample shaded",
            DirectSettings {
                reuse: ReuseSettings {
                    shade_expected: false,
                    ..ReuseSettings::default()
                },
                ..DirectSettings::default()
            },
        ),
        (
            "balance heuristic, two rounds, no reciprocal pairs",
            DirectSettings {
                reuse: ReuseSettings {
                    mis: restir_reuse::MisScheme::GeneralizedBalance,
                    reciprocal: false,
                    spatial_rounds: 2,
                    ..ReuseSettings::default()
                },
                ..DirectSettings::default()
            },
        ),
    ];
    for (name, settings) in configs {
        let z = max_z(&restir(&scene, false, settings), &reference);
        println!("{name}: max |z| = {z:.2}");
        assert!(z < Z_MAX, "{name}: max |z| = {z:.2} ≥ {Z_MAX}");
    }
}

#[test]
fn a_wrong_light_pdf_is_caught() {
    let scene = scene();
    let z = max_z(
        &restir(&scene, true, DirectSettings::default()),
        &reference(&scene),
    );
    println!("wrong pdf: max |z| = {z:.2}");
    assert!(z > Z_MAX, "the wrong pdf went unnoticed: max |z| = {z:.2}");
}

/// The sampler's density is the one it draws with: a histogram of light selections matches the
/// power-proportional probabilities (so the reference itself is right).
#[test]
fn light_selection_follows_its_pmf() {
    let scene = scene();
    let lights = Lights {
        scene: &scene,
        wrong_pdf: false,
    };
    let n = 200_000;
    let mut counts = vec![0u32; scene.lights.len()];
    let mut rng = Pcg32::new(7, 3);
    for _ in 0..n {
        counts[lights.sample(&mut rng).0.light as usize] += 1;
    }
    for (i, &c) in counts.iter().enumerate() {
        let p = f64::from(scene.light_pmf(i));
        let se = (p * (1.0 - p) / n as f64).sqrt();
        let z = (f64::from(c) / n as f64 - p).abs() / se;
        assert!(z < 5.0, "light {i}: {c} of {n}, pmf {p}, z {z:.1}");
    }
}
