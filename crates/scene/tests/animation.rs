//! Animated scenes: interpolation (linear and Catmull-Rom), the description at a time (camera,
//! rigid motion, emission) built into scenes, motion maps, XML sidecars, and that scenes without
//! an animation parse and serialise as before. Bad animation input is covered by
//! `tests/bad_scenes/anim_*`.

use glam::Vec3;
use restir_geometry::Shape;
use restir_lights::Light;
use restir_scene::animation::{build_at, frame_time, interpolate};
use restir_scene::{Interpolation, LoadOptions, load_scene, parse_ron};
use restir_testkit::TempDir;

const SCENE: &str = r#"(
    camera: (fov: 40, to_world: [LookAt(origin: (0, 0, 4), target: (0, 0, 0), up: (0, 1, 0))]),
    film: (width: 16, height: 16, filter: Box),
    shapes: [
        (id: Some("floor"), geometry: Rectangle),
        (id: Some("lamp"), geometry: Sphere(center: (0, 0, 2), radius: 0.1), emission: Some((10, 10, 10))),
    ],
    animation: Some((
        fps: 10,
        camera: Some((keys: [
            (time: 0, position: (0, 0, 4), target: (0, 0, 0)),
            (time: 1, position: (2, 0, 4), target: (0, 0, 0), fov: Some(60)),
        ])),
        shapes: [
            (id: "lamp", pivot: (0, 0, 0), interpolation: CatmullRom,
             motion: Some([(time: 0), (time: 1, translate: (1, 0, 0)), (time: 2, translate: (2, 0, 0), rotate: (0, 0, 90))]),
             emission: Some([(time: 0, radiance: (10, 10, 10)), (time: 2, radiance: (0, 20, 0))])),
        ],
    )),
)"#;

/// A fresh directory for one test's files, removed when the test ends.
fn temp_dir(name: &str) -> TempDir {
    TempDir::new("anim", name)
}

fn write_scene(dir: &std::path::Path) -> std::path::PathBuf {
    let path = dir.join("anim.ron");
    std::fs::write(&path, SCENE).unwrap();
    path
}

fn sphere_center(s: &Shape) -> Vec3 {
    match s {
        Shape::Sphere(s) => s.center,
        _ => panic!("not a sphere"),
    }
}

#[test]
fn linear_interpolation_holds_outside_and_blends_inside() {
    let keys = [(0.0, [0.0, 10.0]), (2.0, [4.0, 10.0]), (3.0, [4.0, 0.0])];
    let at = |t| interpolate(&keys, Interpolation::Linear, t);
    assert_eq!(at(-1.0), [0.0, 10.0]);
    assert_eq!(at(1.0), [2.0, 10.0]);
    assert_eq!(at(2.5), [4.0, 5.0]);
    assert_eq!(at(9.0), [4.0, 0.0]);
    assert_eq!(
        interpolate(&[(5.0, [7.0])], Interpolation::Linear, 0.0),
        [7.0]
    );
}

#[test]
fn catmull_rom_passes_through_keys_reproduces_lines_and_has_continuous_velocity() {
    let keys = [(0.0, [0.0]), (1.0, [3.0]), (3.0, [1.0]), (4.0, [5.0])];
    let at = |t: f32| interpolate(&keys, Interpolation::CatmullRom, t)[0];
    for (t, v) in keys {
        assert!((at(t) - v[0]).abs() < 1e-5, "{t}");
    }
    // Velocity on both sides of an inner key agrees (C1), and differs from linear's.
    let h = 1e-3;
    let left = (at(1.0) - at(1.0 - h)) / h;
    let right = (at(1.0 + h) - at(1.0)) / h;
    assert!((left - right).abs() < 0.05, "{left} {right}");
    let lin = |t: f32| interpolate(&keys, Interpolation::Linear, t)[0];
    assert!(((lin(1.0) - lin(1.0 - h)) / h - (lin(1.0 + h) - lin(1.0)) / h).abs() > 1.0);
    // Keys on a line, unevenly spaced: the spline is that line.
    let line = [(0.0, [1.0]), (0.5, [2.0]), (2.0, [5.0]), (2.25, [5.5])];
    for i in 0..=45 {
        let t = i as f32 * 0.05;
        let v = interpolate(&line, Interpolation::CatmullRom, t)[0];
        assert!((v - (1.0 + 2.0 * t)).abs() < 1e-4, "{t}: {v}");
    }
}

#[test]
fn scene_at_a_time_moves_the_camera_shapes_and_emission() {
    let dir = temp_dir("ron");
    let path = write_scene(&dir);
    let loaded = load_scene(&path, &LoadOptions::default()).unwrap();
    let anim = loaded.desc.animation.as_ref().unwrap();
    assert_eq!(anim.fps, 10.0);
    assert_eq!(anim.shapes[0].shape, 1);
    // Without frames the scene is the one written.
    assert_eq!(
        sphere_center(&loaded.scene.shapes[1]),
        Vec3::new(0.0, 0.0, 2.0)
    );

    assert_eq!(frame_time(5, anim.fps), 0.5);
    let s = build_at(&loaded.desc, &path, 0.5).unwrap();
    assert!((s.camera.origin() - Vec3::new(1.0, 0.0, 4.0)).length() < 1e-5);
    let s = build_at(&loaded.desc, &path, 1.0).unwrap();
    assert!((sphere_center(&s.shapes[1]) - Vec3::new(1.0, 0.0, 2.0)).length() < 1e-5);
    // At t = 2: rotated 90° about z at the origin, then moved by (2, 0, 0): (0, 0, 2) stays on the axis.
    let s = build_at(&loaded.desc, &path, 2.0).unwrap();
    assert!((sphere_center(&s.shapes[1]) - Vec3::new(2.0, 0.0, 2.0)).length() < 1e-5);
    match s.lights.lights()[0] {
        Light::Area { radiance, .. } => assert_eq!(radiance, Vec3::new(0.0, 20.0, 0.0)),
        ref l => panic!("{l:?}"),
    }
    // The floor does not move; the motion map of the lamp takes its t=1 point to its t=2 point.
    let m = anim.shape_motion(1, 1.0, 2.0);
    assert!(
        (m.transform_point3(Vec3::new(1.0, 0.0, 2.0)) - Vec3::new(2.0, 0.0, 2.0)).length() < 1e-5
    );
    let p = Vec3::new(1.1, 0.0, 2.0); // a point on the lamp's surface at t = 1
    let q = m.transform_point3(p);
    assert!((q - Vec3::new(2.0, 0.1, 2.0)).length() < 1e-5, "{q}");
    assert!(anim.shape_moves(1) && !anim.shape_moves(0));
    assert_eq!(anim.shape_motion(0, 0.0, 2.0), glam::Mat4::IDENTITY);
}

#[test]
fn xml_scene_reads_its_sidecar_by_shape_id() {
    let dir = temp_dir("xml");
    let xml = dir.join("s.xml");
    std::fs::write(
        &xml,
        r#"<scene version="3.0.0">
    <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
    <shape type="rectangle" id="floor"/>
    <shape type="sphere" id="ball"><point name="center" x="0" y="0" z="1"/><float name="radius" value="0.5"/>
        <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
</scene>"#,
    )
    .unwrap();
    std::fs::write(
        dir.join("s.anim.ron"),
        r#"(shapes: [(id: "ball", motion: Some([(time: 0), (time: 1, translate: (0, 2, 0))]))])"#,
    )
    .unwrap();
    let loaded = load_scene(&xml, &LoadOptions::default()).unwrap();
    let anim = loaded.desc.animation.as_ref().unwrap();
    assert_eq!(anim.shapes[0].shape, 1);
    assert!(anim.location.file.ends_with("s.anim.ron"));
    let s = build_at(&loaded.desc, &xml, 0.25).unwrap();
    assert!((sphere_center(&s.shapes[1]) - Vec3::new(0.0, 0.5, 1.0)).length() < 1e-5);
    // A second animation for the same scene is refused.
    let mut desc = loaded.desc.clone();
    let e = restir_scene::animation::load_animation(&mut desc, &dir.join("s.anim.ron"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("the scene already has an animation"), "{e}");
}

#[test]
fn scenes_without_animation_parse_and_serialise_as_before() {
    let text = r#"(
        camera: (fov: 40),
        film: (width: 8, height: 8),
        shapes: [(geometry: Rectangle)],
    )"#;
    let desc = parse_ron(text, "a.ron".as_ref()).unwrap();
    assert!(desc.animation.is_none() && desc.shapes[0].id.is_none());
    let out = ron::to_string(&desc).unwrap();
    assert!(!out.contains("animation") && !out.contains("id:"), "{out}");
    assert_eq!(desc.at_time(3.0), desc);
}
