//! Runs the library example: it renders the Cornell box through `Renderer`, and reports a bad
//! scene path as an error with exit status 1.

use std::path::PathBuf;
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn renders_the_cornell_box_through_the_library() {
    let dir = restir_testkit::TempDir::new("library-render", "cbox");
    let output = dir.join("cbox.exr");
    let run = Command::new(env!("CARGO_BIN_EXE_library-render"))
        .arg(repo().join("scenes/cornell-box.xml"))
        .arg("2")
        .arg(&output)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        stdout.starts_with("64x64 pixels, 2 passes, mean radiance ("),
        "{stdout}"
    );
    // A lit Cornell box is not black.
    let mean: Vec<f32> = stdout
        .split('(')
        .nth(1)
        .and_then(|s| s.split(')').next())
        .unwrap()
        .split(", ")
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(mean.iter().all(|&m| m > 0.01 && m.is_finite()), "{mean:?}");
    assert!(std::fs::metadata(&output).unwrap().len() > 0);
}

#[test]
fn a_missing_scene_is_an_error() {
    let run = Command::new(env!("CARGO_BIN_EXE_library-render"))
        .arg("no/such/scene.xml")
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.starts_with("library-render: "), "{stderr}");
    assert!(stderr.contains("no/such/scene.xml"), "{stderr}");
}
