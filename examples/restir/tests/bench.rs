//! `restir bench` end to end on the smoke suite (tiny images, 0.2 s budgets, 64-pass references
//! rendered into a temporary directory), and its errors on bad input.

mod common;
use common::{fails, restir, s};

use restir_testkit::TempDir;
use std::path::PathBuf;
use std::process::Command;

fn repo(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

fn temp_dir(tag: &str) -> TempDir {
    TempDir::new("bench", tag)
}

/// Splits a CSV line without quoted commas (the smoke suite's labels and settings have none).
fn fields(line: &str) -> Vec<&str> {
    line.split(',').collect()
}

#[test]
fn smoke_suite_end_to_end() {
    let dir = temp_dir("smoke");
    let out_dir = dir.join("out");
    let doc = dir.join("DOC.md");
    std::fs::write(
        &doc,
        "# Hand-written\n\nKeep me.\n\n<!-- restir bench results begin -->\nold\n\
         <!-- restir bench results end -->\n\n## After\n\nKeep me too.\n",
    )
    .unwrap();
    let suite = repo("scenes/bench/smoke.ron");
    let args = [
        "bench",
        s(&suite),
        "--out",
        s(&out_dir),
        "--update-doc",
        s(&doc),
    ];
    let out = restir(&args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "stderr:\n{stderr}");

    // CSV: header, one row per scene × configuration × budget × seed, numbers that parse.
    let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    let mut lines = csv.lines();
    let header = fields(lines.next().unwrap());
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = lines.map(fields).collect();
    // Each scene renders only the configurations its `integrators` list names.
    assert_eq!(rows.len(), 3 + 3 + 2, "{csv}");
    let scenes: Vec<&str> = rows.iter().map(|r| r[col("scene")]).collect();
    assert!(scenes.contains(&"cornell-box") && scenes.contains(&"many-lights"));
    let room: Vec<&str> = rows
        .iter()
        .filter(|r| r[col("scene")] == "indirect-room")
        .map(|r| r[col("label")])
        .collect();
    assert_eq!(room, ["path", "restir-pt"], "{csv}");
    for r in &rows {
        assert_eq!(r.len(), header.len(), "{r:?}");
        let num = |name: &str| r[col(name)].parse::<f64>().unwrap();
        assert!(num("relmse") > 0.0 && num("relmse").is_finite(), "{r:?}");
        assert!(num("seconds") >= 0.2, "{r:?}");
        assert!(num("passes") >= 1.0 && num("rays") > 0.0, "{r:?}");
        assert!((num("mean_ratio") - 1.0).abs() < 0.5, "{r:?}");
        assert!(num("reference_noise_relmse") > 0.0, "{r:?}");
        assert!(num("mape") > 0.0 && num("mape").is_finite(), "{r:?}");
        assert!(num("flip") > 0.0 && num("flip") < 1.0, "{r:?}");
        assert_eq!(num("nonfinite_pixels"), 0.0);
        assert_eq!(num("budget_s"), 0.2);
    }

    for scene in ["cornell-box", "many-lights"] {
        let svg = std::fs::read_to_string(out_dir.join(format!("relmse-{scene}.svg"))).unwrap();
        assert!(svg.contains("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(
            svg.contains("restir-di tuned"),
            "legend lacks a configuration"
        );
        let png = std::fs::read(out_dir.join(format!("strip-{scene}.png"))).unwrap();
        assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"));
    }
    let svg = std::fs::read_to_string(out_dir.join("relmse-indirect-room.svg")).unwrap();
    assert!(svg.contains("restir-pt") && !svg.contains("restir-di"));

    let report = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    for needle in [
        "restir bench /",
        "smoke.ron --out",
        "## cornell-box (24×24)",
        "relmse-many-lights.svg",
        "strip-cornell-box.png",
        "| restir-di tuned |",
        "Crops, left to right: reference, path, restir-pt.",
        "equal-time ratio",
        "own relMSE",
        "| MSE | MAPE | FLIP |",
        "(report.html)",
    ] {
        assert!(
            report.contains(needle),
            "report lacks {needle:?}:\n{report}"
        );
    }

    // The interactive page: one self-contained file with every scene's reference and seed-0
    // render (the browser test in crates/evaluation/tests/html_browser.rs draws such a page).
    let html = std::fs::read_to_string(out_dir.join("report.html")).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>") && html.trim_end().ends_with("</html>"));
    assert_eq!(
        html.matches("\"hdr_f16\"").count(),
        (1 + 3) + (1 + 3) + (1 + 2)
    );
    for scene in ["cornell-box", "many-lights", "indirect-room"] {
        assert!(html.contains(&format!("\"name\":\"{scene}\"")), "{scene}");
    }
    assert!(!html.contains("src=\"http") && !html.contains("href=\"http"));

    // The document keeps its hand-written parts and links into the output directory.
    let text = std::fs::read_to_string(&doc).unwrap();
    assert!(text.starts_with("# Hand-written\n\nKeep me.\n"));
    assert!(text.trim_end().ends_with("## After\n\nKeep me too."));
    assert!(!text.contains("\nold\n"));
    assert!(text.contains("](out/relmse-cornell-box.svg)"), "{text}");

    // A second run reuses the cached references.
    let out = restir(&["bench", s(&suite), "--out", s(&out_dir), "--quiet"]);
    assert!(out.status.success());
    let report = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    assert!(report.contains("64 passes (cached)"), "{report}");
}

/// The animation kind on its smoke suite: three frames of the glossy still life rendered by
/// spatial-only and spatiotemporal ReSTIR PT and the path tracer at one budget per frame; the
/// CSV has one row per frame, each frame its own reference, flicker from the second frame on,
/// and the report the per-frame plot and the sequence table.
#[test]
fn animation_suite_end_to_end() {
    let dir = temp_dir("anim");
    let out_dir = dir.join("out");
    let suite = repo("scenes/bench/animation-smoke.ron");
    let out = restir(&["bench", s(&suite), "--out", s(&out_dir), "--quiet"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "stderr:\n{stderr}");

    let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // 3 configurations × 3 frames × 1 budget × 1 seed.
    assert_eq!(rows.len(), 9, "{csv}");
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r.len(), header.len(), "{r:?}");
        let num = |name: &str| r[col(name)].parse::<f64>().unwrap();
        assert_eq!(num("frame"), (i % 3) as f64, "{r:?}");
        assert!(num("relmse") > 0.0 && num("relmse").is_finite(), "{r:?}");
        assert!(num("seconds") >= 0.05 && num("passes") >= 1.0, "{r:?}");
        assert!(num("cpu_seconds") > 0.0, "{r:?}");
        assert_eq!(num("nonfinite_pixels"), 0.0);
        if i % 3 == 0 {
            assert_eq!(r[col("flicker")], "", "{r:?}");
        } else {
            assert!(num("flicker") > 0.0 && num("flicker").is_finite(), "{r:?}");
        }
    }
    let labels: Vec<&str> = rows.iter().step_by(3).map(|r| r[col("label")]).collect();
    assert_eq!(
        labels,
        ["restir-pt spatial", "restir-pt spatiotemporal", "path"]
    );
    assert!(rows[4][col("integrator_settings")].contains("temporal=true"));
    // One cached reference per frame.
    let refs = std::fs::read_dir(out_dir.join("references"))
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "exr")
        })
        .count();
    assert_eq!(refs, 3);

    let svg = std::fs::read_to_string(out_dir.join("frames-glossy-still-life.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("restir-pt spatiotemporal") && svg.contains("frame"));
    let report = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    for needle in [
        "## glossy-still-life (32×24, frames 0 to 2)",
        "16 passes per frame",
        "frames-glossy-still-life.svg",
        "relmse-glossy-still-life.svg",
        "**Sequences.**",
        "| efficiency × restir-pt spatial | flicker | flicker × restir-pt spatial |",
        "| restir-pt spatial | 0.05 | ",
    ] {
        assert!(
            report.contains(needle),
            "report lacks {needle:?}:\n{report}"
        );
    }
    let html = std::fs::read_to_string(out_dir.join("report.html")).unwrap();
    assert!(html.contains("frames 0 to 2"));
    assert_eq!(html.matches("\"hdr_f16\"").count(), 1 + 3);

    // A second run reuses every frame's reference.
    let out = restir(&["bench", s(&suite), "--out", s(&out_dir), "--quiet"]);
    assert!(out.status.success());
    let report = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    assert!(report.contains("16 passes per frame (cached)"), "{report}");

    // A scene without animation given `frames` fails before anything renders.
    let text = std::fs::read_to_string(&suite).unwrap().replace(
        "\"../glossy-still-life.xml\"",
        &format!("\"{}\"", s(&repo("scenes/cornell-box.xml"))),
    );
    let bad = dir.join("still.ron");
    std::fs::write(&bad, text).unwrap();
    fails(
        &["bench", s(&bad), "--out", s(&dir.join("o"))],
        &["cornell-box.xml", "no animation"],
    );
    assert!(!dir.join("o").exists());
}

#[test]
fn bad_suites_fail_with_one_line() {
    let dir = temp_dir("bad");
    let bad = dir.join("bad.ron");
    std::fs::write(
        &bad,
        "(\n    scenes: [],\n    integratorz: [],\n    budgets: [1.0],\n)\n",
    )
    .unwrap();
    fails(
        &["bench", s(&bad), "--out", s(&dir)],
        &["bad.ron:3:", "integratorz"],
    );

    let empty = dir.join("empty.ron");
    std::fs::write(&empty, "(scenes: [], integrators: [], budgets: [1.0])").unwrap();
    fails(
        &["bench", s(&empty), "--out", s(&dir)],
        &["empty.ron", "no scenes"],
    );

    let suite = repo("scenes/bench/smoke.ron");
    fails(
        &["bench", s(&suite), "--out", s(&dir), "--budgets", "0.1,-2"],
        &["--budgets", "-2"],
    );
    fails(
        &["bench", s(&dir.join("none.ron")), "--out", s(&dir)],
        &["none.ron", "cannot read"],
    );

    // A misspelt parameter fails before anything renders.
    let typo = dir.join("typo.ron");
    let text = std::fs::read_to_string(&suite)
        .unwrap()
        .replace("\"../", &format!("\"{}/", s(&repo("scenes"))))
        .replace("(\"neighbors\"", "(\"neighbours_x\"");
    std::fs::write(&typo, text).unwrap();
    fails(
        &["bench", s(&typo), "--out", s(&dir.join("typo-out"))],
        &["typo.ron:15: ", "restir-di tuned", "neighbours_x"],
    );
    assert!(!dir.join("typo-out").exists());

    // --update-doc without markers is an error before anything renders, naming the file.
    let doc = dir.join("NOMARK.md");
    std::fs::write(&doc, "# Nothing to replace\n").unwrap();
    fails(
        &[
            "bench",
            s(&suite),
            "--out",
            s(&dir.join("o")),
            "--update-doc",
            s(&doc),
        ],
        &["NOMARK.md", "marker"],
    );
    assert!(!dir.join("o").exists());
}

#[test]
fn suite_files_are_bounded_and_errors_name_the_line() {
    let dir = temp_dir("bounded");
    // Not a regular file: a device is refused, not read until memory runs out, and a FIFO is
    // refused, not waited on.
    fails(
        &["bench", "/dev/zero", "--out", s(&dir.join("o"))],
        &["/dev/zero", "not a regular file"],
    );
    let fifo = dir.join("suite.fifo");
    let made = Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|st| st.success()) {
        fails(
            &["bench", s(&fifo), "--out", s(&dir.join("o"))],
            &["suite.fifo", "not a regular file"],
        );
    }
    // Too large: refused before it is read.
    let big = dir.join("big.ron");
    let file = std::fs::File::create(&big).unwrap();
    file.set_len((16 << 20) + 1).unwrap();
    fails(
        &["bench", s(&big), "--out", s(&dir.join("o"))],
        &["big.ron", "more than the limit"],
    );
    assert!(!dir.join("o").exists());

    // A scene whose renders would need more than --max-memory fails before anything renders,
    // at the scene's line; 16384² fails under the default limit.
    let suite = repo("scenes/bench/smoke.ron");
    let text = std::fs::read_to_string(&suite)
        .unwrap()
        .replace("\"../", &format!("\"{}/", s(&repo("scenes"))));
    let local = dir.join("smoke.ron");
    std::fs::write(&local, &text).unwrap();
    fails(
        &[
            "bench",
            s(&local),
            "--out",
            s(&dir.join("o")),
            "--max-memory",
            "0.00001",
        ],
        &["smoke.ron:5: ", "cornell-box", "--max-memory"],
    );
    let huge = dir.join("huge.ron");
    std::fs::write(
        &huge,
        text.replacen("width: 24, height: 24", "width: 16384, height: 16384", 2),
    )
    .unwrap();
    fails(
        &["bench", s(&huge), "--out", s(&dir.join("o"))],
        &["huge.ron:5: ", "16384×16384", "limit of 8 GiB"],
    );
    fails(
        &[
            "bench",
            s(&huge),
            "--out",
            s(&dir.join("o")),
            "--max-memory",
            "0",
        ],
        &["--max-memory 0", "positive"],
    );
    assert!(!dir.join("o").exists());
}

/// With `--clock cpu` the budgets count the process's CPU seconds: every render spends at least
/// its budget of CPU time, and the report says which clock the budgets counted.
#[test]
fn cpu_clock_budgets_count_cpu_seconds() {
    let dir = temp_dir("cpu-clock");
    let suite = dir.join("cpu.ron");
    let cornell = repo("scenes/cornell-box.xml");
    std::fs::write(
        &suite,
        format!(
            "(scenes: [(path: {:?}, width: 16, height: 16, max_depth: 3)],\n \
             integrators: [(label: \"path\", integrator: \"path\")],\n \
             budgets: [0.3], seeds: 2, reference_spp: 16)\n",
            s(&cornell)
        ),
    )
    .unwrap();
    let out_dir = dir.join("out");
    let args = [
        "bench",
        s(&suite),
        "--out",
        s(&out_dir),
        "--clock",
        "cpu",
        "--threads",
        "2",
        "--quiet",
    ];
    let out = restir(&args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "stderr:\n{stderr}");
    let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    let mut lines = csv.lines();
    let header = fields(lines.next().unwrap());
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = lines.map(fields).collect();
    assert_eq!(rows.len(), 2, "{csv}");
    for r in &rows {
        let cpu: f64 = r[col("cpu_seconds")].parse().unwrap();
        assert!(cpu >= 0.3, "{r:?}");
    }
    let report = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    assert!(report.contains("in CPU seconds of the process"), "{report}");
    // A clock that is not one: refused before anything renders, naming the choices.
    let bad = restir(&["bench", s(&suite), "--out", s(&out_dir), "--clock", "sun"]);
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(!bad.status.success());
    assert!(
        stderr.contains("'sun'") && stderr.contains("wall, cpu"),
        "{stderr}"
    );
}
