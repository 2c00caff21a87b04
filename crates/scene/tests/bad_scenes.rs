//! The bad-scene suite: every `.xml` and `.ron` file in `tests/bad_scenes/` is a malformed (or
//! merely unusual) scene whose first line states what loading it must report.
//!
//! - `expect: A | B | …` (in an XML comment `<!-- … -->` or a RON comment `// …`): loading and
//!   building must fail, and the error's `Display` must contain every `|`-separated substring
//!   (normally `name.xml:LINE:` and the problem).
//! - `warn: A | B | …`: the scene must load and build, with a warning containing every substring.
//!
//! A file without either line fails the suite, so a case cannot pass silently. Each case runs on
//! its own thread with a time limit, so a hang or a panic fails that case with its name instead
//! of stopping the suite. Mesh files the cases refer to live in `tests/bad_scenes/meshes/`.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

/// Longest a case may take (a hang fails; the slowest case takes milliseconds).
const TIME_LIMIT: Duration = Duration::from_secs(30);

#[derive(Debug)]
enum Expectation {
    Error(Vec<String>),
    Warning(Vec<String>),
}

fn suite_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_scenes")
}

/// The expectation on the first line of `text`.
fn expectation(text: &str) -> Option<Expectation> {
    let first = text.lines().next()?.trim();
    let body = first
        .strip_prefix("<!--")
        .and_then(|s| s.strip_suffix("-->"))
        .or_else(|| first.strip_prefix("//"))?
        .trim();
    let split = |s: &str| -> Vec<String> {
        s.split(" | ")
            .map(|t| t.trim().to_string())
            .filter(|t| !t.is_empty())
            .collect()
    };
    if let Some(rest) = body.strip_prefix("expect:") {
        let v = split(rest);
        (!v.is_empty()).then_some(Expectation::Error(v))
    } else if let Some(rest) = body.strip_prefix("warn:") {
        let v = split(rest);
        (!v.is_empty()).then_some(Expectation::Warning(v))
    } else {
        None
    }
}

/// Loads and builds `path` on a thread with a time limit: `Ok(warnings)` or `Err(error)`, or a
/// description of a panic or a hang.
fn load(path: &Path) -> Result<Result<Vec<String>, String>, String> {
    let (tx, rx) = mpsc::channel();
    let p = path.to_path_buf();
    let handle = std::thread::spawn(move || {
        let r = restir_scene::load_scene(&p, &restir_scene::LoadOptions::default())
            .map(|l| l.warnings.iter().map(ToString::to_string).collect())
            .map_err(|e| e.to_string());
        let _ = tx.send(r);
    });
    match rx.recv_timeout(TIME_LIMIT) {
        Ok(r) => {
            let _ = handle.join();
            Ok(r)
        }
        Err(mpsc::RecvTimeoutError::Disconnected) => Err(match handle.join() {
            Err(p) => format!(
                "panicked: {}",
                p.downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default()
            ),
            Ok(()) => "the loader thread ended without an answer".into(),
        }),
        Err(mpsc::RecvTimeoutError::Timeout) => {
            Err(format!("did not finish within {TIME_LIMIT:?} (a hang?)"))
        }
    }
}

fn cases() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(suite_dir())
        .expect("tests/bad_scenes exists")
        .map(|e| e.expect("readable directory entry").path())
        .filter(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("xml") | Some("ron")
            )
        })
        // An XML case's sidecar animation (`name.anim.ron`) is read with its scene.
        .filter(|p| !p.to_string_lossy().ends_with(".anim.ron"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_bad_scene_reports_its_problem() {
    let files = cases();
    assert!(
        files.len() >= 30,
        "the suite has only {} cases; it should cover at least 30",
        files.len()
    );
    let mut failures = Vec::new();
    let (mut errors, mut warnings) = (0, 0);
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(path).unwrap();
        let Some(expect) = expectation(&text) else {
            failures.push(format!(
                "{name}: the first line states no expectation ('expect: …' or 'warn: …')"
            ));
            continue;
        };
        let outcome = match load(path) {
            Ok(o) => o,
            Err(e) => {
                failures.push(format!("{name}: {e}"));
                continue;
            }
        };
        match (&expect, outcome) {
            (Expectation::Error(want), Err(got)) => {
                errors += 1;
                println!("{name}: {got}");
                let missing: Vec<&String> = want.iter().filter(|w| !got.contains(*w)).collect();
                if !missing.is_empty() {
                    failures.push(format!("{name}: error \"{got}\" lacks {missing:?}"));
                } else if got.contains('\n') {
                    failures.push(format!("{name}: error \"{got}\" spans several lines"));
                }
            }
            (Expectation::Error(want), Ok(w)) => failures.push(format!(
                "{name}: loaded without error (expected {want:?}); warnings: {w:?}"
            )),
            (Expectation::Warning(want), Ok(got)) => {
                warnings += 1;
                println!("{name}: loads with {got:?}");
                let all = got.join("\n");
                let missing: Vec<&String> = want.iter().filter(|w| !all.contains(*w)).collect();
                if !missing.is_empty() {
                    failures.push(format!("{name}: warnings {got:?} lack {missing:?}"));
                }
            }
            (Expectation::Warning(want), Err(e)) => failures.push(format!(
                "{name}: expected to load with warning {want:?}, failed: {e}"
            )),
        }
    }
    println!(
        "{} cases: {errors} errors and {warnings} warnings as expected",
        files.len()
    );
    assert!(
        failures.is_empty(),
        "{} of {} bad-scene cases failed:\n{}",
        failures.len(),
        files.len(),
        failures.join("\n")
    );
}

/// The driver itself: a case without an expectation is caught, expectations parse, and a wrong
/// expectation would fail (the suite's negative control).
#[test]
fn driver_rejects_cases_without_expectations() {
    assert!(expectation("<scene>\n</scene>").is_none());
    assert!(expectation("<!-- a comment -->\n<scene/>").is_none());
    assert!(expectation("<!-- expect: -->\n<scene/>").is_none());
    match expectation("<!-- expect: a.xml:3: | radius -->") {
        Some(Expectation::Error(v)) => assert_eq!(v, ["a.xml:3:", "radius"]),
        e => panic!("{e:?}"),
    }
    match expectation("// warn: ignores property") {
        Some(Expectation::Warning(v)) => assert_eq!(v, ["ignores property"]),
        e => panic!("{e:?}"),
    }
    // Negative control: the message of a real case does not contain a wrong line number.
    let path = suite_dir().join("sphere_negative_radius.xml");
    let got = load(&path).unwrap().unwrap_err();
    assert!(got.contains("sphere_negative_radius.xml:"), "{got}");
    assert!(!got.contains("sphere_negative_radius.xml:1:"), "{got}");
}
