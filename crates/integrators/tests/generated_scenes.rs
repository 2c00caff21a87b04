//! The generated scene kinds of `restir_families` (the ReSTIR DI and PT families): every
//! kind builds, renders a tiny image with the path tracer and its ReSTIR estimator without a
//! non-finite pixel and not black, the same seed gives the same scene, the families' splits are
//! disjoint and cover every kind and light count (halls of other sizes in each split), and the 10⁵-light members build (the time is
//! printed: `cargo test --release -p restir-integrators --test generated_scenes -- --nocapture`).

mod common;

use std::time::Instant;

use restir_families::{
    AssetContents, DiOptions, Family, Generated, Glass, Kind, Params, Receivers, RoomOptions,
    Split, generate, members,
};
use restir_scene::{LoadOptions, load_scene};
use restir_testkit::TempDir;

/// A fresh directory for one test's files, removed when dropped.
fn temp_dir(name: &str) -> TempDir {
    TempDir::new("generated", name)
}

/// Writes `generated` into a fresh directory and loads it at `width`×`height`; the directory
/// goes when the returned guard is dropped.
fn load(generated: &Generated, name: &str, width: u32, height: u32) -> (common::Built, TempDir) {
    let dir = temp_dir(name);
    let path = generated.write(&dir, name).unwrap();
    let options = LoadOptions {
        width: Some(width),
        height: Some(height),
        ..LoadOptions::default()
    };
    let scene = common::Built::from(load_scene(&path, &options).unwrap());
    (scene, dir)
}

/// Emissive rectangles, spheres or triangles of a generated many-light scene: the emissive
/// shapes, or for meshes the faces of their OBJ files.
fn emissive_primitives(generated: &Generated) -> usize {
    let objs: usize = generated
        .assets
        .iter()
        .filter_map(|a| match &a.contents {
            AssetContents::Text(text) if a.filename.ends_with(".obj") => {
                Some(text.lines().filter(|l| l.starts_with("f ")).count())
            }
            _ => None,
        })
        .sum();
    if objs > 0 {
        objs
    } else {
        generated
            .desc
            .shapes
            .iter()
            .filter(|s| s.emission.is_some())
            .count()
    }
}

fn di(kind: Kind, lights: u32, receivers: Receivers, envmap: bool) -> Params {
    Params::Di(
        kind,
        DiOptions {
            lights,
            receivers,
            envmap,
            ..DiOptions::default()
        },
    )
}

fn room(glass: Glass, window: bool) -> Params {
    Params::Room(RoomOptions {
        glass,
        window,
        lamps: 0,
    })
}

fn lamp_room(glass: Glass, window: bool, lamps: u32) -> Params {
    Params::Room(RoomOptions {
        glass,
        window,
        lamps,
    })
}

#[test]
fn every_kind_builds_and_renders_finite_and_lit() {
    let cases = [
        (
            "rects",
            di(Kind::Rects, 300, Receivers::Mixed, true),
            "restir-di",
        ),
        (
            "spheres",
            di(Kind::Spheres, 300, Receivers::Glossy, false),
            "restir-di",
        ),
        (
            "meshes",
            di(Kind::Meshes, 2000, Receivers::Textured, true),
            "restir-di",
        ),
        (
            "hall",
            di(Kind::Hall, 1200, Receivers::Mixed, true),
            "restir-di",
        ),
        ("room", room(Glass::None, false), "restir-pt"),
        ("room-smooth-window", room(Glass::Smooth, true), "restir-pt"),
        ("room-rough", room(Glass::Rough, false), "restir-pt"),
        ("room-lamps", lamp_room(Glass::None, false, 40), "restir-pt"),
    ];
    for (name, params, restir) in cases {
        for seed in [1, 2] {
            let generated = generate(&params, seed).unwrap();
            let (scene, _dir) = load(&generated, &format!("{name}-{seed}"), 32, 24);
            if let Params::Di(_, options) = &params {
                assert_eq!(
                    emissive_primitives(&generated),
                    options.lights as usize,
                    "{name}"
                );
                // The light set has an entry per emissive shape, plus the environment.
                let shapes = generated
                    .desc
                    .shapes
                    .iter()
                    .filter(|s| s.emission.is_some())
                    .count();
                let expected = shapes + usize::from(options.envmap);
                assert_eq!(scene.features.light_count, expected, "{name} seed {seed}");
                assert_eq!(scene.integrator.max_depth, 2, "{name}: direct light only");
            } else {
                assert_eq!(scene.integrator.max_depth, 8, "{name}");
                if let Params::Room(o) = &params {
                    // The lamps replace the hidden light: one emitter per lamp, each a bulb.
                    let emitters = generated
                        .desc
                        .shapes
                        .iter()
                        .filter(|s| s.emission.is_some())
                        .count();
                    let expected = if o.lamps > 0 { o.lamps as usize } else { 1 };
                    assert_eq!(emitters, expected, "{name} seed {seed}");
                }
            }
            for estimator in ["path", restir] {
                let image = common::render_image(&scene, estimator, &[], 4, 7);
                let mean = image.mean();
                assert!(
                    mean.max_element() > 1e-3,
                    "{name} seed {seed} {estimator}: black image (mean {mean})"
                );
            }
        }
    }
}

#[test]
fn same_seed_same_scene_other_seed_other_scene() {
    for params in [
        di(Kind::Rects, 50, Receivers::Mixed, true),
        di(Kind::Spheres, 50, Receivers::Diffuse, false),
        di(Kind::Meshes, 500, Receivers::Glossy, false),
        di(Kind::Hall, 500, Receivers::Mixed, true),
        room(Glass::Rough, true),
        lamp_room(Glass::Smooth, true, 30),
    ] {
        let a = generate(&params, 5).unwrap();
        assert_eq!(a, generate(&params, 5).unwrap(), "{params:?}");
        assert_eq!(
            a.ron().unwrap(),
            generate(&params, 5).unwrap().ron().unwrap()
        );
        assert_ne!(a.desc, generate(&params, 6).unwrap().desc, "{params:?}");
        // The RON text reads back as the same description.
        let back = restir_scene::parse_ron(&a.ron().unwrap(), "gen.ron".as_ref()).unwrap();
        assert_eq!(back, a.desc, "{params:?}");
    }
}

#[test]
fn families_are_disjoint_and_cover_every_kind_and_light_count() {
    for family in [Family::Di, Family::Pt] {
        let train = members(family, Split::Train);
        let test = members(family, Split::Test);
        assert!(
            (8..=12).contains(&train.len()),
            "{family:?}: {} members",
            train.len()
        );
        assert_eq!(train.len(), test.len());
        for t in &train {
            assert!(
                test.iter().all(|s| s.seed != t.seed),
                "{family:?}: seed {} shared",
                t.seed
            );
        }
        let mut names: Vec<String> = train.iter().chain(&test).map(|m| m.name()).collect();
        names.sort();
        names.dedup();
        assert_eq!(
            names.len(),
            2 * train.len(),
            "{family:?}: member names collide"
        );
    }
    let di = members(Family::Di, Split::Test);
    for kind in [Kind::Rects, Kind::Spheres, Kind::Meshes] {
        for lights in [1_000, 10_000, 100_000] {
            assert!(
                di.iter().any(
                    |m| matches!(&m.params, Params::Di(k, o) if *k == kind && o.lights == lights)
                ),
                "no {kind:?} member with {lights} lights"
            );
        }
    }
    // Halls in both splits, of other sizes in each (a default chosen on training halls is
    // checked on halls it was not chosen on).
    let halls = |split| -> Vec<u32> {
        members(Family::Di, split)
            .iter()
            .filter_map(|m| match &m.params {
                Params::Di(Kind::Hall, o) if o.envmap => Some(o.lights),
                _ => None,
            })
            .collect()
    };
    let (train_halls, test_halls) = (halls(Split::Train), halls(Split::Test));
    assert!(train_halls.len() >= 2 && test_halls.len() >= 2);
    assert!(
        train_halls.iter().all(|n| !test_halls.contains(n)),
        "{train_halls:?} {test_halls:?}"
    );
    for receivers in Receivers::ALL {
        assert!(
            di.iter()
                .any(|m| matches!(&m.params, Params::Di(_, o) if o.receivers == receivers))
        );
    }
    assert!(
        di.iter()
            .any(|m| matches!(&m.params, Params::Di(_, o) if o.envmap))
    );
    assert!(
        di.iter().all(
            |m| matches!(&m.params, Params::Di(_, o) if o.occluders && o.power_ratio == 1000.0)
        )
    );
    let pt = members(Family::Pt, Split::Test);
    for glass in Glass::ALL {
        for window in [false, true] {
            assert!(
                pt.iter().any(|m| m.params == room(glass, window)),
                "{glass:?} window {window}"
            );
        }
    }
    // The seed report's kind: rooms lit by many small lamps.
    assert!(
        pt.iter()
            .any(|m| matches!(&m.params, Params::Room(o) if o.lamps >= 100))
    );
}

#[test]
fn hundred_thousand_light_members_build() {
    for member in members(Family::Di, Split::Test)
        .into_iter()
        .filter(|m| matches!(&m.params, Params::Di(_, o) if o.lights == 100_000))
    {
        let start = Instant::now();
        let generated = member.generate().unwrap();
        let made = start.elapsed();
        let start = Instant::now();
        let (scene, _dir) = load(&generated, &member.name(), 32, 24);
        let loaded = start.elapsed();
        eprintln!(
            "{}: generated in {:.2} s, written, parsed and built in {:.2} s, {} light-set entries",
            member.name(),
            made.as_secs_f64(),
            loaded.as_secs_f64(),
            scene.features.light_count
        );
        assert_eq!(
            emissive_primitives(&generated),
            100_000,
            "{}",
            member.name()
        );
        assert!(scene.features.light_count >= 8, "{}", member.name());
    }
}

/// Lamps added to a scene somebody else wrote (`restir generate lamps`): placed in free space,
/// emitting the rule's total power, and the written XML loads as the scene plus the lamps and
/// renders.
#[test]
fn added_lamps_sit_in_free_space_and_the_written_scene_loads() {
    let host =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml");
    let host = std::fs::canonicalize(host).unwrap();
    let loaded = load_scene(&host, &LoadOptions::default()).unwrap();
    let lamps = restir_families::added_lamps(&loaded.scene, 60, 3);
    assert!(lamps.len() >= 50, "{} of 60 lamps placed", lamps.len());
    assert_eq!(lamps, restir_families::added_lamps(&loaded.scene, 60, 3));
    let (lo, hi) = loaded.scene.accel.bounds();
    let e = hi - lo;
    let area = 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
    let mut flux = 0.0;
    for l in &lamps {
        assert!(l.radius > 0.0 && l.radiance.is_finite() && l.radiance.min_element() > 0.0);
        // Clear of every surface: rays from the centre in the six axis directions travel
        // farther than the radius (or leave through the box's open side).
        for d in [
            glam::Vec3::X,
            -glam::Vec3::X,
            glam::Vec3::Y,
            -glam::Vec3::Y,
            glam::Vec3::Z,
            -glam::Vec3::Z,
        ] {
            if let Some(hit) = loaded
                .scene
                .intersect(&restir_geometry::Ray::new(l.centre, d))
            {
                assert!(hit.p.distance(l.centre) > l.radius, "{l:?} touches a wall");
            }
        }
        flux += std::f32::consts::PI * l.radiance.element_sum() / 3.0
            * 4.0
            * std::f32::consts::PI
            * l.radius
            * l.radius;
    }
    assert!((flux / (0.2 * area) - 1.0).abs() < 1e-3, "{flux} W");

    let dir = temp_dir("added-lamps");
    let path = dir.join("lamps.xml");
    let text = restir_families::added_lamps_xml(host.to_str().unwrap(), &lamps, "a test");
    std::fs::write(&path, text).unwrap();
    let options = LoadOptions {
        width: Some(32),
        height: Some(24),
        ..LoadOptions::default()
    };
    let with = common::Built::from(load_scene(&path, &options).unwrap());
    assert_eq!(
        with.scene.lights.len(),
        loaded.scene.lights.len() + lamps.len()
    );
    let image = common::render_image(&with, "restir-di", &[], 2, 7);
    assert!(image.mean().max_element() > 1e-3);
}
