//! `--max-memory` (`RunOptions::max_memory_gib`) bounds what a suite scene's meshes need while it
//! loads, as `restir render` bounds it: a scene over the limit is an error at its line of the
//! suite file, naming the mesh, before anything renders.

use std::path::Path;

use restir_evaluation::{RunOptions, Suite, run_suite};
use restir_testkit::TempDir;

/// A 50×50 grid of quads: 5000 triangles and 2601 vertices, about 1.6 MB by the mesh estimate.
fn write_grid(path: &Path) {
    let n = 50;
    let mut obj = String::new();
    for y in 0..=n {
        for x in 0..=n {
            obj += &format!("v {x} {y} {}\n", ((x * y) % 7) as f32 * 0.1);
        }
    }
    for y in 0..n {
        for x in 0..n {
            let a = y * (n + 1) + x + 1;
            obj += &format!(
                "f {a} {} {}\nf {a} {} {}\n",
                a + 1,
                a + n + 2,
                a + n + 2,
                a + n + 1
            );
        }
    }
    std::fs::write(path, obj).unwrap();
}

fn run(suite_file: &Path, max_memory_gib: f64) -> (Result<(), String>, u32) {
    let (suite, lines) = Suite::load_located(suite_file).unwrap();
    let opts = RunOptions {
        suite_dir: suite_file.parent().unwrap().to_path_buf(),
        out: suite_file.parent().unwrap().join("out"),
        command_line: "restir bench".into(),
        max_memory_gib,
        lines,
    };
    let mut steps = 0;
    let result = run_suite(&suite, &opts, &mut |_| steps += 1)
        .map(|_| ())
        .map_err(|e| e.to_string());
    (result, steps)
}

#[test]
fn a_scene_over_the_limit_fails_at_its_line_before_rendering() {
    let dir = TempDir::new("evaluation-memory", "mesh");
    write_grid(&dir.path().join("grid.obj"));
    std::fs::write(
        dir.path().join("scene.ron"),
        "(camera: (fov: 40, to_world: [LookAt(origin: (25, 25, 75), target: (25, 25, 0), \
         up: (0, 1, 0))]), film: (width: 8, height: 8, filter: Box), spp: 1, \
         integrator: (kind: \"path\", max_depth: 2), materials: [], \
         shapes: [(geometry: Obj(filename: \"grid.obj\"))], \
         lights: [Point(position: (25, 25, 30), intensity: (1, 1, 1))])",
    )
    .unwrap();
    let suite = dir.path().join("suite.ron");
    std::fs::write(
        &suite,
        "(\n    scenes: [\n        (path: \"scene.ron\", width: 8, height: 8),\n    ],\n    \
         integrators: [(label: \"path\", integrator: \"path\")],\n    budgets: [0.01],\n    \
         seeds: 1,\n    reference_spp: 2,\n)\n",
    )
    .unwrap();
    // 1 MiB: the mesh needs about 1.6 MB. The images of 8×8 pixels need far less.
    let (result, steps) = run(&suite, 1.0 / 1024.0);
    let err = result.unwrap_err();
    assert!(err.contains("suite.ron:3: "), "{err}");
    assert!(err.contains("grid.obj' (5000 triangles)"), "{err}");
    assert!(err.contains("raise --max-memory"), "{err}");
    assert_eq!(steps, 0, "progress was reported before the error: {err}");
    assert!(!dir.path().join("out/references").exists());
    // Negative control: under a limit the mesh fits in, the suite runs.
    let (result, steps) = run(&suite, 1.0);
    result.unwrap();
    assert!(steps > 0);
}
