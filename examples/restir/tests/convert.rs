//! `restir convert` and `restir generate family --xml`: the Mitsuba 3 XML they write renders the
//! same image as the scene it came from (path tracer and ReSTIR PT, same seed and passes: bit
//! for bit), from the same directory or another one; and what cannot be written is a one-line
//! error.

use std::path::Path;
use std::process::{Command, Output};

use restir_image::Image;
use restir_testkit::TempDir;

const RESTIR: &str = env!("CARGO_BIN_EXE_restir");

fn temp_dir(tag: &str) -> TempDir {
    TempDir::new("convert", tag)
}

fn restir(args: &[&str]) -> Output {
    Command::new(RESTIR).args(args).output().unwrap()
}

fn ok(args: &[&str]) -> String {
    let out = restir(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The image `scene` renders with `flags` (32×24, 4 passes, seed 3).
fn render(scene: &Path, out: &Path, flags: &[&str]) -> Image {
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--spp",
        "4",
        "--seed",
        "3",
        "--width",
        "32",
        "--height",
        "24",
        "--quiet",
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(flags);
    ok(&args);
    Image::read_exr(out).unwrap()
}

fn same_images(a: &Path, b: &Path, work: &Path) {
    for flags in [
        &["--integrator", "path"][..],
        &["--integrator", "restir-pt"][..],
    ] {
        let x = render(a, &work.join("a.exr"), flags);
        let y = render(b, &work.join("b.exr"), flags);
        assert!(
            x.pixels.iter().any(|p| p.max_element() > 0.0),
            "{flags:?}: black image"
        );
        assert!(
            x.pixels == y.pixels,
            "{} and {} render different images with {flags:?}",
            a.display(),
            b.display()
        );
    }
}

#[test]
fn written_xml_renders_the_image_of_its_scene() {
    let dir = temp_dir("same");
    let d = dir.0.to_str().unwrap();
    // A room with a window (an environment map file) and a checkerboard, written with its XML.
    ok(&[
        "generate", "family", "--kind", "pt", "--split", "test", "--out", d, "--index", "1",
        "--xml",
    ]);
    let ron = dir.0.join("pt-test-01-room-glass-none-window-s102.ron");
    let beside = ron.with_extension("xml");
    assert!(beside.is_file());
    same_images(&ron, &beside, &dir.0);
    // Converted into another directory: the environment map's name leads back.
    let other = dir.0.join("elsewhere/room.xml");
    let said = ok(&[
        "convert",
        ron.to_str().unwrap(),
        "-o",
        other.to_str().unwrap(),
    ]);
    assert!(said.contains("room.xml"), "{said}");
    let text = std::fs::read_to_string(&other).unwrap();
    assert!(text.contains(r#"value="../window-sky-s102.exr""#), "{text}");
    same_images(&ron, &other, &dir.0);
    // An XML scene converts too (the shipped still life without its sidecar animation).
    let still = dir.0.join("still.xml");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/glossy-still-life.xml"),
        &still,
    )
    .unwrap();
    let again = dir.0.join("still-again.xml");
    ok(&[
        "convert",
        still.to_str().unwrap(),
        "-o",
        again.to_str().unwrap(),
    ]);
    same_images(&still, &again, &dir.0);
}

/// Runs `restir` with `args`, expects exit code 1 and one stderr line holding `needle`.
fn fails(args: &[&str], needle: &str) {
    let out = restir(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    assert!(err.contains(needle), "{args:?}: {err:?} lacks {needle:?}");
}

#[test]
fn what_cannot_be_written_is_an_error() {
    let dir = temp_dir("bad");
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let out = dir.0.join("x.xml");
    fails(
        &[
            "convert",
            scenes.join("many-lights-flythrough.ron").to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        "cannot write as Mitsuba 3 XML: the scene: it is animated",
    );
    assert!(!out.exists());
    let restir_pt = dir.0.join("pt.ron");
    std::fs::write(
        &restir_pt,
        r#"(camera: (fov: 45), integrator: (kind: "restir-pt"),
            shapes: [(geometry: Sphere(center: (0, 0, -3), radius: 1), emission: Some((1, 1, 1)))])"#,
    )
    .unwrap();
    fails(
        &[
            "convert",
            restir_pt.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        "the integrator: 'restir-pt' is this renderer's own estimator",
    );
    fails(
        &[
            "convert",
            restir_pt.to_str().unwrap(),
            "-o",
            dir.0.join("x.txt").to_str().unwrap(),
        ],
        "the output must end in .xml",
    );
    let xml = dir.0.join("same.xml");
    std::fs::copy(scenes.join("cornell-box.xml"), &xml).unwrap();
    fails(
        &[
            "convert",
            xml.to_str().unwrap(),
            "-o",
            xml.to_str().unwrap(),
        ],
        "the output would overwrite the scene",
    );
    fails(
        &[
            "generate",
            "family",
            "--kind",
            "pt-motion",
            "--split",
            "test",
            "--out",
            dir.0.to_str().unwrap(),
            "--index",
            "0",
            "--xml",
        ],
        "--xml: the pt-motion family is animated",
    );
    // Refused before anything was written.
    assert!(!dir.0.join("family.txt").exists());
    assert!(std::fs::read_dir(&dir.0).unwrap().all(|e| {
        let name = e.unwrap().file_name();
        !name.to_string_lossy().starts_with("pt-motion")
    }));
}
