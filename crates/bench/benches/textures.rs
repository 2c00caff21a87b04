//! What textures cost, and what deciding "no textures" once at build time saves.
//!
//! Run with `cargo bench -p restir-bench --bench textures`. A small harness like `render`:
//! configurations are timed in interleaved passes (A, B, A, B, …) in a one-thread rayon pool, so
//! that the shared machine's load drifts over both alike; reported are median times and their
//! ratio. `RESTIR_BENCH_SECONDS` (default 6) is the budget per comparison.
//!
//! 1. `Scene::bsdf_at` per call: an untextured scene as built (`has_textures = false`: returns
//!    the stored BSDF), the same with the flag forced on (looks at the material's texture slots,
//!    finds none), a checkerboard and a 256×256 bitmap reflectance.
//! 2. The path tracer on `scenes/cornell-box.xml` (128×128): as built against the flag forced
//!    on — the whole-render saving of the build-time decision.
//! 3. The path tracer on the corpus Sponza (128×96, if `../shared/corpus` exists): textured as
//!    loaded against each textured material replaced by a constant at its texture's mean (so
//!    paths keep about the same length), in Mrays/s.

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::{DVec3, Vec2, Vec3};
use restir_integrators::film::Filter;
use restir_integrators::{IntegratorOptions, PassContext, make_integrator};
use restir_materials::Bsdf;
use restir_scene::{IntegratorDesc, Scene, TexturePoint, load_desc, parse_ron};

fn budget() -> f64 {
    std::env::var("RESTIR_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(6.0)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The scene at `path` at `size`, with its file's integrator settings.
fn load(path: &Path, size: (u32, u32)) -> (Scene, IntegratorDesc) {
    let (mut desc, _) = load_desc(path, &[]).unwrap_or_else(|e| panic!("{e}"));
    desc.film.width = size.0;
    desc.film.height = size.1;
    let scene = Scene::build(&desc, path.parent().unwrap(), path).unwrap_or_else(|e| panic!("{e}"));
    (scene, desc.integrator)
}

/// Times `run(config)` for configs 0 and 1 alternately until `budget` seconds have passed (at
/// least 5 rounds); returns the per-config times and the value each run returned (summed).
fn interleaved(budget: f64, mut run: impl FnMut(usize) -> u64) -> [(f64, u64, usize); 2] {
    let mut times = [Vec::new(), Vec::new()];
    let mut counts = [0u64; 2];
    run(0);
    run(1); // warm-up
    let start = Instant::now();
    while times[0].len() < 5 || start.elapsed().as_secs_f64() < budget {
        for c in 0..2 {
            let t = Instant::now();
            counts[c] += run(c);
            times[c].push(t.elapsed().as_secs_f64());
        }
    }
    let n = times[0].len();
    let [a, b] = times;
    [(median(a), counts[0], n), (median(b), counts[1], n)]
}

fn bsdf_at_costs(budget: f64) {
    let dir = restir_testkit::TempDir::new("bench-tex", "bsdf-at");
    let img = image::RgbImage::from_fn(256, 256, |x, y| {
        image::Rgb([(x ^ y) as u8, (x * 7) as u8, (y * 3) as u8])
    });
    img.save(dir.join("b.png")).unwrap();
    let ron = r#"(
        camera: (fov: 40), film: (width: 8, height: 8),
        shapes: [
            (geometry: Rectangle, material: Some(Inline(Diffuse(reflectance: (0.5, 0.5, 0.5))))),
            (geometry: Rectangle, material: Some(Inline(Textured(material: Diffuse(reflectance: (0.5, 0.5, 0.5)),
                textures: [(param: Reflectance, texture: Checkerboard(uv: (scale: (8, 8))))])))),
            (geometry: Rectangle, material: Some(Inline(Textured(material: Diffuse(reflectance: (0.5, 0.5, 0.5)),
                textures: [(param: Reflectance, texture: Bitmap(filename: "b.png"))])))),
        ],
    )"#;
    let desc = parse_ron(ron, "b.ron".as_ref()).unwrap();
    let mut scene = Scene::build(&desc, &dir, "b.ron".as_ref()).unwrap();
    drop(dir);
    let uvs: Vec<TexturePoint> = (0..4096)
        .map(|i| {
            TexturePoint::at_uv(Vec2::new(
                (i as f32 * 0.618_034).fract(),
                (i as f32 * 0.414_214).fract(),
            ))
        })
        .collect();
    const REPS: usize = 64;
    let calls = |scene: &Scene, bsdf: u32| -> u64 {
        let mut acc = Vec3::ZERO;
        for _ in 0..REPS {
            for uv in &uvs {
                let b: Bsdf = scene.bsdf_at(std::hint::black_box(bsdf), uv);
                acc += b.eval(Vec3::Z, Vec3::Z);
            }
        }
        std::hint::black_box(acc);
        (REPS * uvs.len()) as u64
    };
    let per_call = |t: f64| t / (REPS * uvs.len()) as f64 * 1e9;
    println!("Scene::bsdf_at + one diffuse eval, ns per call (median of interleaved batches):");
    let untextured = scene.shape_bsdf()[0];
    // The constant material with the flag as built (false: the scene has textures, so force it).
    let [flag_off, flag_on] = interleaved(budget / 3.0, |c| {
        scene.features.has_textures = c == 1;
        calls(&scene, untextured)
    });
    println!(
        "  constant material, has_textures = false: {:7.2} ns\n  constant material, has_textures = true:  {:7.2} ns  (×{:.3})",
        per_call(flag_off.0),
        per_call(flag_on.0),
        flag_on.0 / flag_off.0
    );
    scene.features.has_textures = true;
    let [checker, bitmap] = interleaved(budget / 3.0, |c| calls(&scene, scene.shape_bsdf()[1 + c]));
    println!(
        "  checkerboard reflectance:                {:7.2} ns\n  256×256 bitmap reflectance (bilinear):   {:7.2} ns",
        per_call(checker.0),
        per_call(bitmap.0)
    );
}

fn cornell_flag(budget: f64) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml");
    let (mut scene, scene_integrator) = load(&path, (128, 128));
    assert!(!scene.features.has_textures);
    let options = IntegratorOptions {
        name: Some("path".into()),
        ..Default::default()
    };
    let integrator = make_integrator(&scene, &scene_integrator, &options)
        .unwrap()
        .integrator;
    let filter = Filter::new(scene.filter);
    let mut pass = 0u32;
    let mut accum = vec![DVec3::ZERO; 128 * 128];
    let [off, on] = interleaved(budget, |c| {
        scene.features.has_textures = c == 1;
        let ctx = PassContext {
            shared_offset: None,
            samples: None,
            seed: 0,
            pass: pass / 2,
            filter: &filter,
            crop: None,
        };
        pass += 1;
        integrator.render_pass(&scene, &ctx, &mut accum)
    });
    println!(
        "cornell-box.xml 128×128, path, 1 thread, {} passes each: has_textures = false {:.2} ms/pass, forced true {:.2} ms/pass (×{:.4})",
        off.2,
        off.0 * 1e3,
        on.0 * 1e3,
        on.0 / off.0
    );
}

fn sponza(budget: f64) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/corpus/lajolla/sponza/sponza.xml");
    if !path.is_file() {
        println!("sponza: skipped (no corpus at {})", path.display());
        return;
    }
    let (textured_scene, scene_integrator) = load(&path, (128, 96));
    assert!(textured_scene.features.has_textures);
    // The constant variant, a second copy: each textured material's BSDF at its textures' means.
    let (mut constant, _) = load(&path, (128, 96));
    for m in 0..constant.bsdfs().len() {
        if let Some(t) = constant.bsdf_textures()[m] {
            let mut p = t.base;
            if let Some(i) = t.diffuse {
                p.diffuse = constant.textures()[i as usize].mean();
            }
            let b = constant.bsdfs()[m].with_params(&p);
            constant.set_material(m as u32, b).unwrap();
        }
    }
    assert!(!constant.features.has_textures);
    let scene = &textured_scene;
    let options = IntegratorOptions {
        name: Some("path".into()),
        ..Default::default()
    };
    let integrator = make_integrator(scene, &scene_integrator, &options)
        .unwrap()
        .integrator;
    let filter = Filter::new(scene.filter);
    let mut pass = 0u32;
    let (w, h) = scene.camera.resolution();
    let mut accum = vec![DVec3::ZERO; (w * h) as usize];
    let [tex, con] = interleaved(budget, |c| {
        let scene = if c == 0 { &textured_scene } else { &constant };
        let ctx = PassContext {
            shared_offset: None,
            samples: None,
            seed: 0,
            pass: pass / 2,
            filter: &filter,
            crop: None,
        };
        pass += 1;
        integrator.render_pass(scene, &ctx, &mut accum)
    });
    let mrays = |m: (f64, u64, usize)| m.1 as f64 / m.2 as f64 / m.0 / 1e6;
    println!(
        "sponza 128×96, path, 1 thread, {} passes each: textured {:.1} ms/pass {:.3} Mrays/s, constant means {:.1} ms/pass {:.3} Mrays/s (Mrays/s ratio textured/constant {:.4})",
        tex.2,
        tex.0 * 1e3,
        mrays(tex),
        con.0 * 1e3,
        mrays(con),
        mrays(tex) / mrays(con)
    );
}

fn main() {
    let budget = budget();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    pool.install(|| {
        bsdf_at_costs(budget);
        cornell_flag(budget);
        sponza(budget);
    });
}
