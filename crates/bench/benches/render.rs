//! Estimator throughput on the shipped scenes: passes per second and Mrays/s (camera,
//! continuation and shadow rays) of one pass of the `path` and `restir-di` integrators (ReSTIR DI
//! with its defaults and with the configuration of the equal-time comparison in
//! docs/studies/2026-11-22-restir-di-many-lights.md).
//!
//! Run with `cargo bench -p restir-bench --bench render`. A small harness rather than divan,
//! because the two numbers wanted are rates of whole passes: each scene is loaded at 128×128,
//! warmed up with one pass, then timed pass by pass for about `RESTIR_BENCH_SECONDS` seconds
//! (default 3) in the default rayon pool (all cores) and in a one-thread pool. Reported: the
//! median pass time, passes/s = 1 / median, and Mrays/s = rays of the pass / median (rays per
//! pass vary little between passes; their mean is used).

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DVec3;
use restir_integrators::film::Filter;
use restir_integrators::{Integrator, IntegratorOptions, PassContext, make_integrator};
use restir_scene::{IntegratorDesc, Scene, load_desc};

const SIZE: u32 = 128;

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name)
}

/// The scene `name` at `SIZE`², with its file's integrator settings.
fn load(name: &str) -> (Scene, IntegratorDesc) {
    let path = scene_path(name);
    let (mut desc, _) = load_desc(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
    desc.film.width = SIZE;
    desc.film.height = SIZE;
    let scene =
        Scene::build(&desc, path.parent().unwrap(), &path).unwrap_or_else(|e| panic!("{e}"));
    (scene, desc.integrator)
}

struct Measurement {
    median_seconds: f64,
    mean_rays: f64,
    passes: usize,
}

fn measure(scene: &Scene, integrator: &dyn Integrator, budget: f64) -> Measurement {
    let filter = Filter::new(scene.filter);
    let (w, h) = scene.camera.resolution();
    let mut accum = vec![DVec3::ZERO; (w * h) as usize];
    let mut pass = 0u32;
    let mut run = |accum: &mut [DVec3]| {
        let ctx = PassContext {
            shared_offset: None,
            samples: None,
            seed: 0,
            pass,
            filter: &filter,
            crop: None,
        };
        pass += 1;
        let start = Instant::now();
        let rays = integrator.render_pass(scene, &ctx, accum);
        (start.elapsed().as_secs_f64(), rays)
    };
    run(&mut accum); // warm-up
    let start = Instant::now();
    let mut times = Vec::new();
    let mut rays = 0u64;
    while times.len() < 5 || (start.elapsed().as_secs_f64() < budget && times.len() < 10_000) {
        let (t, r) = run(&mut accum);
        times.push(t);
        rays += r;
    }
    std::hint::black_box(&accum);
    times.sort_by(f64::total_cmp);
    Measurement {
        median_seconds: times[times.len() / 2],
        mean_rays: rays as f64 / times.len() as f64,
        passes: times.len(),
    }
}

fn main() {
    let budget: f64 = std::env::var("RESTIR_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3.0);
    let all = rayon::current_num_threads();
    println!("one pass at {SIZE}×{SIZE}, ~{budget} s per row (RESTIR_BENCH_SECONDS)");
    println!(
        "{:<18} {:<22} {:>7} {:>9} {:>10} {:>10} {:>10} {:>8}",
        "scene", "integrator", "threads", "max_depth", "ms/pass", "passes/s", "Mrays/s", "passes"
    );
    let configs: [Config; 3] = [
        ("path", "path", &[]),
        ("restir-di", "restir-di", &[]),
        (
            "restir-di (tuned)",
            "restir-di",
            &[
                ("candidates", "8"),
                ("neighbors", "5"),
                ("spatial_rounds", "2"),
                ("radius", "10"),
            ],
        ),
    ];
    for name in ["cornell-box.xml", "many-lights.ron"] {
        let (scene, scene_integrator) = load(name);
        for (label, kind, params) in configs {
            let options = IntegratorOptions {
                name: Some(kind.into()),
                max_depth: None,
                params: params.into(),
                sampler: None,
            };
            let integrator = make_integrator(&scene, &scene_integrator, &options)
                .unwrap()
                .integrator;
            let depth = scene_integrator.max_depth;
            bench_rows(&scene, name, label, integrator.as_ref(), depth, budget, all);
        }
    }
}

/// A row label, an integrator name and its parameters.
type Config = (
    &'static str,
    &'static str,
    &'static [(&'static str, &'static str)],
);

fn bench_rows(
    scene: &Scene,
    name: &str,
    label: &str,
    integrator: &dyn Integrator,
    max_depth: i32,
    budget: f64,
    all: usize,
) {
    {
        for threads in [all, 1] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let m = pool.install(|| measure(scene, integrator, budget));
            println!(
                "{:<18} {:<22} {:>7} {:>9} {:>10.2} {:>10.2} {:>10.2} {:>8}",
                name,
                label,
                threads,
                max_depth,
                m.median_seconds * 1e3,
                1.0 / m.median_seconds,
                m.mean_rays / m.median_seconds / 1e6,
                m.passes
            );
            if all == 1 {
                break;
            }
        }
    }
}
