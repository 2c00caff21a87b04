//! `<emitter type="envmap">` import: EXR, Radiance HDR and PNG images, `scale`, `to_world`, the
//! Mitsuba orientation seen through the built scene, and bad input as `file:line` errors.

use std::path::{Path, PathBuf};

use glam::Vec3;
use restir_scene::{LoadOptions, load_scene};
use restir_testkit::TempDir;

/// A fresh directory per test (tests run in parallel), removed when the test ends.
fn temp_dir(test: &str) -> TempDir {
    TempDir::new("envmap", test)
}

/// Writes a scene whose only emitter is `emitter` (starting on line 5).
fn scene(dir: &Path, name: &str, emitter: &str) -> PathBuf {
    let path = dir.join(name);
    let xml = format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective"><float name="fov" value="40"/>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
    </sensor>
{emitter}
    <shape type="sphere"><float name="radius" value="0.5"/></shape>
</scene>
"#
    );
    std::fs::write(&path, xml).unwrap();
    path
}

/// A 4×3 image: column x, row y holds (x + 1, y + 1, 1) (top row first).
fn pattern(x: usize, y: usize) -> [f32; 3] {
    [(x + 1) as f32, (y + 1) as f32, 1.0]
}

fn write_exr(path: &Path) {
    exr::prelude::write_rgb_file(path, 4, 3, |x, y| {
        let p = pattern(x, y);
        (p[0], p[1], p[2])
    })
    .unwrap();
}

#[test]
fn envmap_formats_orientation_and_scale() {
    let dir = temp_dir("formats");
    write_exr(&dir.join("map.exr"));
    let mut hdr = Vec::new();
    let pixels: Vec<image::Rgb<f32>> = (0..3)
        .flat_map(|y| (0..4).map(move |x| image::Rgb(pattern(x, y))))
        .collect();
    image::codecs::hdr::HdrEncoder::new(&mut hdr)
        .encode(&pixels, 4, 3)
        .unwrap();
    std::fs::write(dir.join("map.hdr"), hdr).unwrap();

    for file in ["map.exr", "map.hdr"] {
        let path = scene(
            &dir,
            "s.xml",
            &format!(
                r#"    <emitter type="envmap"><string name="filename" value="{file}"/><float name="scale" value="2"/></emitter>"#
            ),
        );
        let s =
            load_scene(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(s.scene.features.has_environment);
        let lights = &s.scene.lights;
        // +Y is the top row (row 0 → g = 1); −Y the bottom row (g = 3). Column x sits at
        // u = (x + ½)/4 and u = ¼ is +X: between columns 0 and 1 (r = 1.5).
        let at = |d: Vec3| lights.environment_radiance(d.normalize()) / 2.0;
        let tol = 0.02; // HDR stores 8-bit mantissas
        assert!((at(Vec3::Y).y - 1.0).abs() < tol, "{file}: {}", at(Vec3::Y));
        assert!((at(-Vec3::Y).y - 3.0).abs() < 3.0 * tol, "{file}");
        let eq = at(Vec3::X);
        assert!(
            (eq - Vec3::new(1.5, 2.0, 1.0)).abs().max_element() < 3.0 * tol,
            "{file}: {eq}"
        );
        // u = 0 (−Z) lies halfway between the last and the first column.
        assert!((at(-Vec3::Z).x - 2.5).abs() < 3.0 * tol, "{file}");
    }

    // to_world rotates the map: turned 90° about +Y, what was at −Z is seen at −X... (R·(−Z)).
    let path = scene(
        &dir,
        "r.xml",
        r#"    <emitter type="envmap"><string name="filename" value="map.exr"/>
        <transform name="to_world"><rotate y="1" angle="90"/></transform></emitter>"#,
    );
    let s = load_scene(&path, &LoadOptions::default()).unwrap();
    let r = glam::Mat3::from_rotation_y(90f32.to_radians());
    let got = s.scene.lights.environment_radiance(r * -Vec3::Z);
    assert!((got.x - 2.5).abs() < 1e-3, "{got}");

    // PNG: 8-bit sRGB is linearised.
    image::RgbImage::from_raw(2, 2, vec![188; 12])
        .unwrap()
        .save(dir.join("map.png"))
        .unwrap();
    let path = scene(
        &dir,
        "p.xml",
        r#"    <emitter type="envmap"><string name="filename" value="map.png"/></emitter>"#,
    );
    let s = load_scene(&path, &LoadOptions::default()).unwrap();
    let l = s.scene.lights.environment_radiance(Vec3::Z);
    assert!((l.x - 0.5029).abs() < 1e-3, "{l}");
}

#[test]
fn envmap_bad_input_names_file_and_line() {
    let dir = temp_dir("bad");
    write_exr(&dir.join("ok.exr"));
    let bytes = std::fs::read(dir.join("ok.exr")).unwrap();
    std::fs::write(dir.join("truncated.exr"), &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(dir.join("garbage.hdr"), b"#?RADIANCE\nnonsense").unwrap();
    let cases = [
        (
            "missing.xml",
            r#"    <emitter type="envmap"><string name="filename" value="nope.exr"/></emitter>"#,
            "missing.xml:5: envmap: cannot read image",
        ),
        (
            "truncated.xml",
            r#"    <emitter type="envmap"><string name="filename" value="truncated.exr"/></emitter>"#,
            "truncated.xml:5: envmap: cannot read image",
        ),
        (
            "garbage.xml",
            r#"    <emitter type="envmap"><string name="filename" value="garbage.hdr"/></emitter>"#,
            "garbage.xml:5: envmap: cannot read image",
        ),
        (
            "nofile.xml",
            r#"    <emitter type="envmap"><float name="scale" value="2"/></emitter>"#,
            "nofile.xml:5: envmap emitter needs a 'filename'",
        ),
        (
            "scale.xml",
            r#"    <emitter type="envmap"><string name="filename" value="ok.exr"/><float name="scale" value="-1"/></emitter>"#,
            "scale.xml:5: envmap scale -1 must be finite and non-negative",
        ),
        (
            "shear.xml",
            r#"    <emitter type="envmap"><string name="filename" value="ok.exr"/>
        <transform name="to_world"><scale x="2"/></transform></emitter>"#,
            "shear.xml:5: envmap: envmap to_world must be a rotation",
        ),
        (
            "two.xml",
            r#"    <emitter type="constant"/>
    <emitter type="envmap"><string name="filename" value="ok.exr"/></emitter>"#,
            "two.xml:6: a second environment emitter",
        ),
    ];
    for (name, emitter, want) in cases {
        let path = scene(&dir, name, emitter);
        let e = match load_scene(&path, &LoadOptions::default()) {
            Ok(_) => panic!("{name} loads"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains(want), "{name}: got \"{e}\", want \"{want}\"");
    }
}
