//! Micro-benchmarks of the renderer's inner loops, one thread: BVH traversal, BSDF sampling and
//! evaluation, light sampling.
//!
//! Run with `cargo bench -p restir-bench --bench micro` (add `-- bvh` to run one module). Every
//! benchmark processes a batch of inputs per iteration and declares it to divan as items, so the
//! `itemsps` column is the throughput: rays per second for `bvh` (Mrays/s = Mitem/s), samples or
//! evaluations per second for `bsdf` and `lights`.
//!
//! - `bvh`: closest-hit (`Accel::intersect`) and shadow (`Accel::occluded`) rays on the Cornell
//!   box, on the indirect room and, when the scene corpus is next to the repository, on two
//!   bigger scenes (`../shared/corpus/restir_test_scene/test.xml`: PLY bunnies and 100+ sphere
//!   lights; `../shared/corpus/lajolla/sponza/sponza.xml`: 66 000 triangles of architecture). *Coherent* rays are the camera rays of a 64×64 image in raster order;
//!   *incoherent* rays start at those rays' primary hits and go in uniformly random directions;
//!   *shadow* rays join random pairs of primary hits (finite `t_max`, any hit ends the
//!   traversal).
//! - `bsdf`: `Bsdf::sample` and `Bsdf::eval` for each model, with random outgoing directions in
//!   the upper hemisphere.
//! - `lights`: `LightSet::sample` (power-based alias table, then the light's own sampling) and
//!   `LightSet::pdf_sa` with 1, 400 and 100 000 sphere lights, from random points on the floor of
//!   the many-lights scene; and the ReSTIR DI tile sampler: building the per-tile tables for one
//!   128×128 pass and drawing a light from them (it is used up to 4096 lights).
//! - `tables`: a rough plastic's coating tables integrated from scratch
//!   (`RoughPlasticTable::compute`: what a first scene load pays per distinct (distribution, α,
//!   η)), Beckmann α = 0.1 and GGX α = 0.3 at η = 1.49. The integration spreads its 64 rows over
//!   every core the process may run on: `taskset -c 0` for one thread.

use std::path::{Path, PathBuf};

use divan::counter::ItemsCount;
use divan::{Bencher, black_box};
use glam::{Vec2, Vec3};
use restir_geometry::{Ray, shadow_ray_between};
use restir_integrators::PassContext;
use restir_integrators::film::Filter;
use restir_integrators::restir_di::tiles;
use restir_integrators::reuse::gbuffer::GBuffer;
use restir_materials::{Bsdf, Distribution};
use restir_sampling::Pcg32;
use restir_scene::{GeometryDesc, Scene, SceneDesc, ShapeDesc, load_desc};

fn main() {
    divan::main();
}

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

fn build(desc: &SceneDesc, path: &Path) -> Scene {
    Scene::build(desc, path.parent().unwrap(), path).unwrap_or_else(|e| panic!("{e}"))
}

/// Loads a scene at `size`×`size`; `None` when the file is absent (the corpus is optional).
fn load(path: &Path, size: u32) -> Option<Scene> {
    if !path.exists() {
        return None;
    }
    let (mut desc, _) = load_desc(path, &[]).unwrap_or_else(|e| panic!("{e}"));
    desc.film.width = size;
    desc.film.height = size;
    Some(build(&desc, path))
}

fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let phi = std::f32::consts::TAU * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u.x).max(0.0).sqrt())
}

mod bvh {
    use super::*;

    /// Image side of the coherent ray batch (64×64 = 4096 rays).
    const SIDE: u32 = 64;

    /// Camera rays, random rays from their hits, and shadow rays between pairs of hits.
    struct Rays {
        scene: Scene,
        camera: Vec<Ray>,
        random: Vec<Ray>,
        shadow: Vec<(Ray, f32)>,
    }

    fn rays(scene: Scene) -> Rays {
        let mut rng = Pcg32::new(7, 0);
        let mut camera = Vec::new();
        for y in 0..SIDE {
            for x in 0..SIDE {
                let film = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                camera.push(scene.camera.generate_ray(film, Vec2::splat(0.5)));
            }
        }
        let hits: Vec<(Vec3, Vec3)> = camera
            .iter()
            .filter_map(|r| scene.intersect(r).map(|si| (si.p, si.ng)))
            .collect();
        assert!(!hits.is_empty(), "no camera ray hits the scene");
        let mut random = Vec::new();
        let mut shadow = Vec::new();
        for i in 0..camera.len() {
            let (p, ng) = hits[i % hits.len()];
            let d = uniform_sphere(rng.next_2d());
            let o = restir_geometry::offset_ray_origin(p, ng, d);
            random.push(Ray::new(o, d));
            let (q, _) = hits[(rng.next_u32() as usize) % hits.len()];
            if (q - p).length() > 1e-3 {
                shadow.push(shadow_ray_between(p, ng, q));
            }
        }
        Rays {
            scene,
            camera,
            random,
            shadow,
        }
    }

    fn scenes() -> Vec<(&'static str, PathBuf)> {
        vec![
            ("cornell-box", repo("scenes/cornell-box.xml")),
            ("indirect-room", repo("scenes/indirect-room.ron")),
            (
                "restir_test_scene",
                repo("../shared/corpus/restir_test_scene/test.xml"),
            ),
            ("sponza", repo("../shared/corpus/lajolla/sponza/sponza.xml")),
        ]
    }

    const SCENES: [&str; 4] = [
        "cornell-box",
        "indirect-room",
        "restir_test_scene",
        "sponza",
    ];

    fn setup(name: &str) -> Option<Rays> {
        let (_, path) = scenes().into_iter().find(|(n, _)| *n == name)?;
        let scene = load(&path, SIDE)?;
        eprintln!(
            "{name}: {} primitives in the BVH, {} lights",
            scene.accel.primitive_count(),
            scene.lights.len()
        );
        Some(rays(scene))
    }

    #[divan::bench(args = SCENES)]
    fn closest_coherent(bencher: Bencher, name: &str) {
        let Some(r) = setup(name) else { return };
        bencher
            .counter(ItemsCount::new(r.camera.len()))
            .bench_local(|| {
                let mut n = 0u32;
                for ray in &r.camera {
                    n += r.scene.accel.intersect(ray, f32::INFINITY).is_some() as u32;
                }
                black_box(n)
            });
    }

    #[divan::bench(args = SCENES)]
    fn closest_incoherent(bencher: Bencher, name: &str) {
        let Some(r) = setup(name) else { return };
        bencher
            .counter(ItemsCount::new(r.random.len()))
            .bench_local(|| {
                let mut n = 0u32;
                for ray in &r.random {
                    n += r.scene.accel.intersect(ray, f32::INFINITY).is_some() as u32;
                }
                black_box(n)
            });
    }

    /// Any-hit rays along the coherent camera rays, stopped at half their hit distance
    /// (unoccluded) — the cost of a shadow ray that succeeds.
    #[divan::bench(args = SCENES)]
    fn shadow_coherent(bencher: Bencher, name: &str) {
        let Some(r) = setup(name) else { return };
        let segs: Vec<(Ray, f32)> = r
            .camera
            .iter()
            .filter_map(|ray| {
                r.scene
                    .accel
                    .intersect(ray, f32::INFINITY)
                    .map(|h| (*ray, 0.5 * h.t))
            })
            .collect();
        bencher
            .counter(ItemsCount::new(segs.len()))
            .bench_local(|| {
                let mut n = 0u32;
                for (ray, t) in &segs {
                    n += r.scene.accel.occluded(ray, *t) as u32;
                }
                black_box(n)
            });
    }

    /// Shadow rays between random pairs of primary hits (a mix of occluded and visible).
    #[divan::bench(args = SCENES)]
    fn shadow_incoherent(bencher: Bencher, name: &str) {
        let Some(r) = setup(name) else { return };
        let occluded = r
            .shadow
            .iter()
            .filter(|(ray, t)| r.scene.accel.occluded(ray, *t))
            .count();
        eprintln!(
            "{name}: {occluded} of {} incoherent shadow rays occluded",
            r.shadow.len()
        );
        bencher
            .counter(ItemsCount::new(r.shadow.len()))
            .bench_local(|| {
                let mut n = 0u32;
                for (ray, t) in &r.shadow {
                    n += r.scene.accel.occluded(ray, *t) as u32;
                }
                black_box(n)
            });
    }
}

mod bsdf {
    use super::*;

    const BATCH: usize = 1024;

    const MODELS: [&str; 7] = [
        "diffuse",
        "roughplastic GGX 0.1",
        "roughconductor GGX 0.2",
        "roughconductor Beckmann 0.2",
        "roughdielectric GGX 0.2",
        "plastic (smooth)",
        "dielectric (smooth)",
    ];

    fn model(name: &str) -> Bsdf {
        let gold_eta = Vec3::new(0.143, 0.374, 1.442);
        let gold_k = Vec3::new(3.983, 2.385, 1.603);
        let grey = Vec3::splat(0.5);
        match name {
            "diffuse" => Bsdf::diffuse(grey),
            "roughplastic GGX 0.1" => {
                Bsdf::rough_plastic(1.49, grey, Vec3::ONE, false, Distribution::Ggx, 0.1)
            }
            "roughconductor GGX 0.2" => Bsdf::rough_conductor(
                gold_eta,
                gold_k,
                Vec3::ONE,
                restir_materials::Microfacet::new(Distribution::Ggx, 0.2),
            ),
            "roughconductor Beckmann 0.2" => Bsdf::rough_conductor(
                gold_eta,
                gold_k,
                Vec3::ONE,
                restir_materials::Microfacet::new(Distribution::Beckmann, 0.2),
            ),
            "roughdielectric GGX 0.2" => Bsdf::rough_dielectric(
                1.5,
                Vec3::ONE,
                Vec3::ONE,
                restir_materials::Microfacet::new(Distribution::Ggx, 0.2),
            ),
            "plastic (smooth)" => Bsdf::plastic(1.49, grey, Vec3::ONE, false),
            "dielectric (smooth)" => Bsdf::dielectric(1.5, Vec3::ONE, Vec3::ONE),
            _ => unreachable!("{name}"),
        }
    }

    /// `(wo, u_lobe, u, wi)`: outgoing directions cosine-distributed in the upper hemisphere and
    /// incident directions on the whole sphere (so `eval` also meets transmission).
    fn inputs() -> Vec<(Vec3, f32, Vec2, Vec3)> {
        let mut rng = Pcg32::new(3, 0);
        (0..BATCH)
            .map(|_| {
                let wo = cosine_hemisphere(rng.next_2d());
                (
                    wo,
                    rng.next_f32(),
                    rng.next_2d(),
                    uniform_sphere(rng.next_2d()),
                )
            })
            .collect()
    }

    #[divan::bench(args = MODELS)]
    fn sample(bencher: Bencher, name: &str) {
        let bsdf = model(name);
        let input = inputs();
        bencher.counter(ItemsCount::new(BATCH)).bench_local(|| {
            let mut acc = 0.0f32;
            for &(wo, ul, u, _) in &input {
                if let Some(s) = black_box(&bsdf).sample(wo, ul, u) {
                    acc += s.pdf_sa;
                }
            }
            black_box(acc)
        });
    }

    #[divan::bench(args = MODELS)]
    fn eval(bencher: Bencher, name: &str) {
        let bsdf = model(name);
        let input = inputs();
        bencher.counter(ItemsCount::new(BATCH)).bench_local(|| {
            let mut acc = Vec3::ZERO;
            for &(wo, _, _, wi) in &input {
                acc += black_box(&bsdf).eval(wo, wi);
            }
            black_box(acc)
        });
    }

    #[divan::bench(args = MODELS)]
    fn pdf(bencher: Bencher, name: &str) {
        let bsdf = model(name);
        let input = inputs();
        bencher.counter(ItemsCount::new(BATCH)).bench_local(|| {
            let mut acc = 0.0f32;
            for &(wo, _, _, wi) in &input {
                acc += black_box(&bsdf).pdf_sa(wo, wi);
            }
            black_box(acc)
        });
    }
}

mod lights {
    use super::*;

    const BATCH: usize = 1024;
    const COUNTS: [usize; 3] = [1, 400, 100_000];

    /// The many-lights scene's floor and occluders with `n` sphere lights of log-uniform
    /// radiance (1000× range) at 0.2–2 units over a 12×12 floor, at 128×128.
    fn scene(n: usize) -> Scene {
        let path = repo("scenes/many-lights.ron");
        let (mut desc, _) = load_desc(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
        desc.film.width = 128;
        desc.film.height = 128;
        desc.shapes.retain(|s| s.emission.is_none());
        let mut rng = Pcg32::new(11, 0);
        for _ in 0..n {
            let c = [
                -6.0 + 12.0 * rng.next_f32(),
                0.2 + 1.8 * rng.next_f32(),
                -6.0 + 12.0 * rng.next_f32(),
            ];
            let l = 0.1 * 1000f32.powf(rng.next_f32());
            desc.shapes.push(ShapeDesc {
                id: None,
                geometry: GeometryDesc::Sphere {
                    center: c,
                    radius: 0.03 + 0.03 * rng.next_f32(),
                },
                to_world: Vec::new(),
                material: None,
                emission: Some([l, l, l]),
                emission_texture: None,
                flip_normals: false,
                face_normals: false,
                location: Default::default(),
            });
        }
        let scene = build(&desc, &path);
        assert_eq!(scene.lights.len(), n);
        scene
    }

    fn receivers() -> Vec<(Vec3, f32, Vec2)> {
        let mut rng = Pcg32::new(5, 0);
        (0..BATCH)
            .map(|_| {
                let p = Vec3::new(
                    -6.0 + 12.0 * rng.next_f32(),
                    0.0,
                    -6.0 + 12.0 * rng.next_f32(),
                );
                (p, rng.next_f32(), rng.next_2d())
            })
            .collect()
    }

    /// `LightSet::sample`: pick a light by power, then a point on it (cone sampling).
    #[divan::bench(args = COUNTS)]
    fn sample(bencher: Bencher, n: usize) {
        let scene = scene(n);
        let input = receivers();
        bencher.counter(ItemsCount::new(BATCH)).bench_local(|| {
            let mut acc = 0.0f32;
            for &(p, us, u) in &input {
                if let Some(s) = scene.lights.sample(p, us, u) {
                    acc += s.pdf_sa;
                }
            }
            black_box(acc)
        });
    }

    /// `LightSet::pdf_sa` of the samples `sample` returns (as MIS of a BSDF sample needs).
    #[divan::bench(args = COUNTS)]
    fn pdf_sa(bencher: Bencher, n: usize) {
        let scene = scene(n);
        let samples: Vec<_> = receivers()
            .into_iter()
            .filter_map(|(p, us, u)| {
                let s = scene.lights.sample(p, us, u)?;
                Some((p, s.light, s.p, s.ng))
            })
            .collect();
        bencher
            .counter(ItemsCount::new(samples.len()))
            .bench_local(|| {
                let mut acc = 0.0f32;
                for &(p, l, q, ng) in &samples {
                    acc += scene.lights.pdf_sa(l, p, q, ng);
                }
                black_box(acc)
            });
    }

    fn context(filter: &Filter) -> PassContext<'_> {
        PassContext {
            shared_offset: None,
            samples: None,
            seed: 0,
            pass: 0,
            filter,
            crop: None,
        }
    }

    fn gbuffer(scene: &Scene) -> GBuffer {
        let filter = Filter::new(scene.filter);
        let ctx = context(&filter);
        let (w, h) = scene.camera.resolution();
        let mut radiance = vec![Vec3::ZERO; (w * h) as usize];
        GBuffer::trace(scene, &ctx, false, false, true, &mut radiance).0
    }

    /// Building the tiles' pools from their light cuts (found once beforehand) for one 128×128
    /// pass (64 tiles, 8 candidates per pixel; one thread).
    #[divan::bench(args = COUNTS)]
    fn tiles_build(bencher: Bencher, n: usize) {
        let scene = scene(n);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let gbuf = pool.install(|| gbuffer(&scene));
        let filter = Filter::new(scene.filter);
        let ctx = context(&filter);
        let (w, h) = (gbuf.width, gbuf.height);
        let cuts = pool
            .install(|| tiles::TileCuts::probe(&scene, &ctx, w, h, false, tiles::OwnLights::Apart))
            .expect("a local light");
        bencher.bench_local(|| {
            pool.install(|| {
                black_box(tiles::LightTiles::build(
                    &scene,
                    &ctx,
                    &gbuf,
                    &cuts,
                    8,
                    None,
                    restir_lights::Claim::Exact,
                    6,
                ))
            })
        });
    }

    /// Picking an emitter from a cut of 256 nodes of the light hierarchy (the node by its
    /// alias table, the emitter within it by power).
    #[divan::bench(args = COUNTS)]
    fn cut_pick(bencher: Bencher, n: usize) {
        let scene = scene(n);
        let cut = scene
            .lights
            .light_cut(
                Vec3::new(0.0, 0.5, 0.0),
                Vec3::ZERO,
                0.5,
                tiles::CUT_NODES,
                None,
            )
            .expect("a cut");
        let input = receivers();
        bencher.counter(ItemsCount::new(BATCH)).bench_local(|| {
            let mut acc = 0.0f32;
            for &(_, us, u) in &input {
                if let Some((_, pmf)) = scene.lights.pick_from_cut(&cut, us, u.x as f64) {
                    acc += pmf;
                }
            }
            black_box(acc)
        });
    }
}

mod tables {
    use restir_materials::Distribution;
    use restir_materials::plastic::RoughPlasticTable;

    const CASES: [&str; 2] = ["Beckmann 0.1", "GGX 0.3"];

    #[divan::bench(args = CASES, sample_count = 30, sample_size = 1)]
    fn rough_plastic(name: &str) -> RoughPlasticTable {
        let (distribution, alpha) = match name {
            "Beckmann 0.1" => (Distribution::Beckmann, 0.1),
            "GGX 0.3" => (Distribution::Ggx, 0.3),
            _ => unreachable!("{name}"),
        };
        RoughPlasticTable::compute(distribution, alpha, 1.49 / 1.000_277)
    }
}
