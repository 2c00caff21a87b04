//! Mitsuba 3's `moment` integrator: `restir render` writes each pixel's mean and second moment
//! beside the image as Mitsuba names them (`NAME.X`…, `m2_NAME.X`…, CIE XYZ) in an EXR; where
//! they cannot be written (a PNG) a warning says so before rendering and the image is written;
//! `restir convert` writes the wrapper back.

mod common;
use common::restir;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use restir_testkit::TempDir;

/// A diffuse sphere under a constant sky, 12×12 with a box filter; the sky fills the corners.
const SCENE: &str = r#"<scene version="3.0.0">
    <integrator type="moment">
        <integrator type="path" name="nested">
            <integer name="max_depth" value="3"/>
        </integrator>
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0,0,-5" target="0,0,0" up="0,1,0"/></transform>
        <film type="hdrfilm">
            <integer name="width" value="12"/>
            <integer name="height" value="12"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="0.5, 1, 2"/></emitter>
    <shape type="sphere"><bsdf type="diffuse"/></shape>
</scene>
"#;

fn scene(dir: &Path) -> PathBuf {
    let path = dir.join("moment.xml");
    std::fs::write(&path, SCENE).unwrap();
    path
}

fn render(scene: &Path, out: &Path) -> String {
    let o = restir(&[
        "render",
        scene.to_str().unwrap(),
        "--spp",
        "16",
        "-o",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{err}");
    err
}

/// Every channel of the EXR by name.
fn channels(path: &Path) -> BTreeMap<String, Vec<f32>> {
    use exr::prelude::*;
    let image = read_all_flat_layers_from_file(path).unwrap();
    let layer = &image.layer_data[0];
    layer
        .channel_data
        .list
        .iter()
        .map(|c| {
            let values = (0..c.sample_data.len())
                .map(|i| c.sample_data.value_by_flat_index(i).to_f32())
                .collect();
            (c.name.to_string(), values)
        })
        .collect()
}

#[test]
fn the_exr_holds_mitsubas_moment_channels() {
    let dir = TempDir::new("moment", "exr");
    let sc = scene(&dir.0);
    let out = dir.0.join("m.exr");
    render(&sc, &out);
    let ch = channels(&out);
    let names: Vec<&str> = ch.keys().map(String::as_str).collect();
    assert_eq!(
        names,
        [
            "B",
            "G",
            "R",
            "m2_nested.X",
            "m2_nested.Y",
            "m2_nested.Z",
            "nested.X",
            "nested.Y",
            "nested.Z"
        ]
    );
    let (mut sky, mut sphere) = (0, 0);
    for axis in ["X", "Y", "Z"] {
        let (mean, m2) = (
            &ch[&format!("nested.{axis}")],
            &ch[&format!("m2_nested.{axis}")],
        );
        for (m, s) in mean.iter().zip(m2) {
            assert!(
                *s >= m * m * (1.0 - 1e-5),
                "second moment {s} below mean² {}",
                m * m
            );
            // The sky seen directly is the same every pass: no variance.
            if (s - m * m).abs() <= 1e-5 * s {
                sky += 1;
            } else {
                sphere += 1;
            }
        }
    }
    assert!(sky > 0 && sphere > 0, "sky {sky}, sphere {sphere}");
    // The mean is the image in XYZ: Y of the sky's (0.5, 1, 2) is 0.96584.
    let y = ch["nested.Y"][0];
    assert!((y - 0.965_84).abs() < 1e-4, "sky Y {y}");
    // The image reads back as RGB.
    assert_eq!(restir_image::Image::read_exr(&out).unwrap().width, 12);
}

#[test]
fn a_png_gets_the_image_and_a_warning() {
    let dir = TempDir::new("moment", "png");
    let sc = scene(&dir.0);
    let out = dir.0.join("m.png");
    let err = render(&sc, &out);
    assert!(
        err.contains("moment.xml:3: the moment integrator's second-moment channels are not written (a PNG holds RGB only)"),
        "{err}"
    );
    assert!(out.is_file());
}

#[test]
fn convert_writes_the_moment_back() {
    let dir = TempDir::new("moment", "convert");
    let sc = scene(&dir.0);
    let again = dir.0.join("again.xml");
    let o = restir(&[
        "convert",
        sc.to_str().unwrap(),
        "-o",
        again.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&again).unwrap();
    assert!(text.contains(r#"<integrator type="moment">"#), "{text}");
    let out = dir.0.join("again.exr");
    render(&again, &out);
    assert!(channels(&out).contains_key("m2_nested.Y"));
}

/// The second moment's buffers count against `--max-memory`: a film that fits without them
/// (a PNG keeps none) is refused before rendering when an EXR would keep them.
#[test]
fn the_second_moment_counts_against_the_memory_limit() {
    let dir = TempDir::new("moment", "memory");
    let sc = scene(&dir.0);
    let run = |name: &str| {
        let out = dir.0.join(name);
        let o = restir(&[
            "render",
            sc.to_str().unwrap(),
            "--width",
            "100",
            "--height",
            "100",
            "--spp",
            "1",
            "--max-memory",
            "0.0007",
            "--quiet",
            "-o",
            out.to_str().unwrap(),
        ]);
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
            out,
        )
    };
    let (code, err, out) = run("m.png");
    assert_eq!(code, Some(0), "{err}");
    assert!(out.is_file());
    let (code, err, out) = run("m.exr");
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("96 bytes per pixel") && err.contains("raise --max-memory"),
        "{err}"
    );
    assert!(!out.exists());
}
