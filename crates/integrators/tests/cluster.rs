//! Splitting a render for a cluster ([`render_part`], `docs/CLUSTER.md`): a range of passes
//! renders exactly the passes one process would, so chains merged pass-weighted equal the single
//! render (bit-identical for one-pass chains, within float rounding otherwise), and a window
//! rendered with the estimator's halo equals the same window of the whole film: exactly for the
//! path tracer and for ReSTIR DI (without learning) and PT without temporal reuse, and in distribution (block
//! statistics over independent seeds). Negative control: a tile rendered without its halo
//! differs near the tile's edges, and only there.

mod common;

use std::sync::atomic::AtomicBool;

use glam::{DVec3, Vec3};
use restir_integrators::{
    Image, Integrator, PassContext, PixelWindow, RenderJob, RenderPart, render_part,
};
use restir_scene::Scene;
use restir_testkit::{block_means, block_statistics, max_z};

use common::cornell;

fn integrator(scene: &common::Built, name: &str, params: &[(&str, &str)]) -> Box<dyn Integrator> {
    common::make(scene, name, &[&[("max_depth", "3")], params].concat())
}

/// Small spatial reuse: two rounds within 4 pixels, a halo of 8.
const REUSE: &[(&str, &str)] = &[("radius", "4"), ("spatial_rounds", "2")];

/// ReSTIR DI without learning across passes: a part learns only from its own passes
/// (docs/CLUSTER.md), so with learning a split render is another estimator, not the same bits.
const DI: &[(&str, &str)] = &[("radius", "4"), ("spatial_rounds", "2"), ("learn", "off")];

/// The same with candidates from the 16×16 tiles' cuts of the light hierarchy, whose pools
/// come from streams named by the tiles' places on the film.
const DI_TILES: &[(&str, &str)] = &[
    ("radius", "4"),
    ("spatial_rounds", "2"),
    ("learn", "off"),
    ("light_sampler", "tiles"),
];

/// The path tracer (with independent numbers and with Sobol sequences), ReSTIR DI (with the
/// power sampler's pool and with the tiles' light cuts) and PT.
fn estimators(scene: &common::Built) -> Vec<Box<dyn Integrator>> {
    let sobol = make_with_sampler(scene, restir_scene::SamplerKind::Sobol);
    vec![
        integrator(scene, "path", &[]),
        sobol,
        integrator(scene, "restir-di", DI),
        integrator(scene, "restir-di", DI_TILES),
        integrator(scene, "restir-pt", REUSE),
    ]
}

/// The path tracer of `scene` drawing from `sampler`.
fn make_with_sampler(
    scene: &common::Built,
    sampler: restir_scene::SamplerKind,
) -> Box<dyn Integrator> {
    let options = restir_integrators::IntegratorOptions {
        name: Some("path".into()),
        max_depth: Some(3),
        sampler: Some(sampler),
        ..Default::default()
    };
    restir_integrators::make_integrator(scene, &scene.integrator, &options)
        .unwrap()
        .integrator
}

fn part(
    scene: &Scene,
    integrator: &dyn Integrator,
    seed: u64,
    passes: std::ops::Range<u32>,
    window: Option<PixelWindow>,
) -> Image {
    let job = RenderJob {
        spp: passes.len() as u32,
        seed,
        ..RenderJob::default()
    };
    let part = RenderPart {
        first_pass: passes.start,
        window,
    };
    let out = render_part(
        scene,
        integrator,
        &job,
        &part,
        &AtomicBool::new(false),
        &mut |_, _| {},
    );
    assert_eq!(out.passes, passes.len() as u32);
    out.image
}

fn whole(scene: &Scene, integrator: &dyn Integrator, seed: u64, spp: u32) -> Image {
    common::render_with(scene, integrator, spp, seed)
}

/// `Σ nᵢ·imageᵢ / Σ nᵢ` in f64, what `restir merge` computes for chains.
fn merge(chains: &[(Image, u32)]) -> Vec<Vec3> {
    let total: f64 = chains.iter().map(|(_, n)| f64::from(*n)).sum();
    (0..chains[0].0.pixels.len())
        .map(|i| {
            let s: DVec3 = chains
                .iter()
                .map(|(img, n)| img.pixels[i].as_dvec3() * f64::from(*n))
                .sum();
            (s / total).as_vec3()
        })
        .collect()
}

/// Chains hold exactly the passes of one process: one-pass chains merge to the same bits, and
/// uneven multi-pass chains to within two float roundings per channel.
#[test]
fn chains_merge_to_the_single_render() {
    let scene = cornell(40, 32);
    for integrator in estimators(&scene) {
        let name = integrator.name();
        let full = whole(&scene, integrator.as_ref(), 7, 7);
        let singles: Vec<(Image, u32)> = (0..7)
            .map(|p| (part(&scene, integrator.as_ref(), 7, p..p + 1, None), 1))
            .collect();
        assert!(merge(&singles) == full.pixels, "{name}: one-pass chains");
        let uneven: Vec<(Image, u32)> = [0..1, 1..4, 4..7]
            .into_iter()
            .map(|r| {
                let n = r.len() as u32;
                (part(&scene, integrator.as_ref(), 7, r, None), n)
            })
            .collect();
        let merged = merge(&uneven);
        let mut worst = 0.0f32;
        for (m, f) in merged.iter().zip(&full.pixels) {
            for (a, b) in m.to_array().into_iter().zip(f.to_array()) {
                let tol = 2.0 * f32::EPSILON * a.abs().max(b.abs());
                assert!((a - b).abs() <= tol, "{name}: {a} vs {b}");
                worst = worst.max((a - b).abs() / b.abs().max(f32::MIN_POSITIVE));
            }
        }
        eprintln!("{name}: chains 1+3+3 vs one process: worst relative difference {worst:e}");
        // A different pass range is different passes.
        assert!(part(&scene, integrator.as_ref(), 7, 1..2, None) != singles[0].0);
    }
}

/// The window of a film 96 wide and 96 tall used by the tile tests: rows 32..64, all columns.
const WINDOW: PixelWindow = PixelWindow {
    x0: 0,
    y0: 32,
    width: 96,
    height: 32,
};

fn window_of(image: &Image) -> Image {
    PixelWindow::full((image.width, image.height)).extract(image, &WINDOW)
}

/// The estimator with its halo hidden: the negative control's tile has no halo.
#[derive(Debug)]
struct NoHalo<'a>(&'a dyn Integrator);

impl Integrator for NoHalo<'_> {
    fn name(&self) -> &'static str {
        self.0.name()
    }
    fn render_pass(&self, scene: &Scene, ctx: &PassContext, accum: &mut [DVec3]) -> u64 {
        self.0.render_pass(scene, ctx, accum)
    }
}

/// With its halo, a tile is the film's window exactly. Without it (negative control) ReSTIR's
/// tile differs from the film's window, and only within the halo's reach of the tile's edges.
#[test]
fn tiles_equal_the_untiled_window() {
    let scene = cornell(96, 96);
    for integrator in estimators(&scene) {
        let name = integrator.name();
        let halo = integrator.halo();
        assert_eq!(halo, if name == "path" { 0 } else { 8 }, "{name}");
        let full = window_of(&whole(&scene, integrator.as_ref(), 3, 2));
        let tile = part(&scene, integrator.as_ref(), 3, 0..2, Some(WINDOW));
        assert!(
            tile == full,
            "{name}: the tile differs from the untiled window"
        );
        if halo == 0 {
            continue;
        }
        let bare = NoHalo(integrator.as_ref());
        let region = RenderPart {
            first_pass: 0,
            window: Some(WINDOW),
        }
        .region(&bare, &scene);
        assert_eq!(region, WINDOW, "the control's region is the bare window");
        let tile = part(&scene, &bare, 3, 0..2, Some(WINDOW));
        let (mut edge_rows, mut inner) = (0, 0);
        for (i, (a, b)) in tile.pixels.iter().zip(&full.pixels).enumerate() {
            if a != b {
                let y = i as u32 / WINDOW.width;
                let from_edge = y.min(WINDOW.height - 1 - y);
                if from_edge < halo {
                    edge_rows += 1;
                } else {
                    inner += 1;
                }
            }
        }
        eprintln!("{name} without halo: {edge_rows} pixels near the edges differ");
        assert_eq!(inner, 0, "{name}: pixels beyond the halo's reach differ");
        assert!(
            edge_rows >= (WINDOW.width * halo / 4) as usize,
            "{name}: only {edge_rows} pixels near the tile's edges differ without a halo"
        );
    }
}

/// With a splatting film (Mitsuba's Gaussian filter) a pixel's value gathers the estimates of
/// pixels within the filter's reach: the region grows by that reach, and the tile is still the
/// film's window exactly.
#[test]
fn splatted_tiles_equal_the_untiled_window() {
    let mut scene = cornell(96, 96);
    scene.filter = restir_scene::FilterDesc::Gaussian { stddev: 0.5 };
    for integrator in estimators(&scene) {
        let name = integrator.name();
        let halo = restir_integrators::part_halo(integrator.as_ref(), &scene);
        assert_eq!(
            halo,
            integrator.halo() + 2,
            "{name}: the Gaussian reaches 2 pixels"
        );
        let full = window_of(&whole(&scene, integrator.as_ref(), 3, 2));
        let tile = part(&scene, integrator.as_ref(), 3, 0..2, Some(WINDOW));
        assert!(
            tile == full,
            "{name}: the splatted tile differs from the untiled window"
        );
    }
}

/// In distribution: block means of the tile over 32 seeds agree with those of the untiled
/// window over 32 other seeds, within 5 standard errors of the difference (192 blocks; the
/// family-wise false-alarm rate at 5 σ is below 1e-4 for normal means). The same test on a
/// deliberately wrong "tile" — the window one row lower — must fail (negative control).
#[test]
fn tiles_match_in_distribution() {
    let scene = cornell(96, 96);
    let (seeds, block) = (32, 4);
    for integrator in estimators(&scene).into_iter().skip(1) {
        let name = integrator.name();
        let means = |img: &Image| block_means(img.width, img.height, &img.pixels, block);
        let tiled = block_statistics(
            |s| means(&part(&scene, integrator.as_ref(), s, 0..1, Some(WINDOW))),
            seeds,
            0,
        );
        let fulls: Vec<Image> = (0..seeds)
            .map(|s| whole(&scene, integrator.as_ref(), 1000 + s, 1))
            .collect();
        let untiled = block_statistics(|s| means(&window_of(&fulls[s as usize])), seeds, 0);
        let z = max_z(&tiled, &untiled);
        eprintln!(
            "{name}: tile vs untiled, max |z| over {} blocks = {z:.2}",
            tiled.len()
        );
        assert!(
            z < 5.0,
            "{name}: tile and untiled differ in distribution (max z {z})"
        );
        // Negative control: the film's rows 40..72 instead of 32..64.
        let shifted = PixelWindow { y0: 40, ..WINDOW };
        let wrong = block_statistics(
            |s| {
                let f = &fulls[s as usize];
                means(&PixelWindow::full((f.width, f.height)).extract(f, &shifted))
            },
            seeds,
            0,
        );
        let z = max_z(&tiled, &wrong);
        assert!(
            z > 5.0,
            "{name}: the test cannot tell a shifted window (max z {z})"
        );
    }
}
