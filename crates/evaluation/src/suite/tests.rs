//! The suite file's parsing and rules.

use super::*;

const GOOD: &str = r#"(
    scenes: [(path: "a.xml", width: 32, height: Some(16))],
    integrators: [(label: "path", integrator: "path"),
                  (label: "di", integrator: "restir-di", params: [("candidates", "8")])],
    budgets: [0.5, 1.0],
)"#;

#[test]
fn parses_with_defaults() {
    let s = Suite::parse(GOOD, Path::new("s.ron")).unwrap();
    assert_eq!(s.seeds, 1);
    assert_eq!(s.reference_spp, 4096);
    assert_eq!(s.scenes[0].width, Some(32));
    assert_eq!(s.scenes[0].height, Some(16));
    assert_eq!(s.scenes[0].display_name(), "a");
    assert_eq!(s.integrators[1].params_string(), "candidates=8");
}

/// A family is checked when the suite is parsed, written into the output directory once and
/// expanded into one scene per chosen member, with the family's settings.
#[test]
fn families_expand_into_scenes() {
    let text = r#"(
        families: [(kind: "di", split: "test", members: [0], width: 40, height: 30,
                    integrators: ["path"])],
        integrators: [(label: "path", integrator: "path")],
        budgets: [0.5],
    )"#;
    let mut s = Suite::parse(text, Path::new("f.ron")).unwrap();
    let tmp = restir_testkit::TempDir::new("suite", "families");
    let dir = tmp.join("families");
    s.expand_families(&dir).unwrap();
    assert!(s.families.is_empty());
    assert_eq!(s.scenes.len(), 1);
    let scene = &s.scenes[0];
    let name = "di-test-00-rects-n1000-diffuse-occ-s101";
    assert_eq!(scene.display_name(), name);
    assert_eq!((scene.width, scene.height), (Some(40), Some(30)));
    assert_eq!(scene.path, dir.join("di-test").join(format!("{name}.ron")));
    let written = std::fs::metadata(&scene.path).unwrap().modified().unwrap();
    // A second expansion finds the member written and leaves it.
    let mut again = Suite::parse(text, Path::new("f.ron")).unwrap();
    again.expand_families(&dir).unwrap();
    let kept = std::fs::metadata(&again.scenes[0].path)
        .unwrap()
        .modified()
        .unwrap();
    assert_eq!(written, kept);
    drop(tmp);

    for (bad, says) in [
        (r#"kind: "dj""#, "family kind 'dj': expected di or pt"),
        (r#"kind: "di-motion""#, "family kind 'di-motion'"),
        (
            r#"split: "validation""#,
            "family split 'validation': expected train or test",
        ),
        (
            "members: [0, 12]",
            "the di test family has members 0 to 11, not 12",
        ),
    ] {
        let key = bad.split(':').next().unwrap();
        let original = match key {
            "kind" => r#"kind: "di""#,
            "split" => r#"split: "test""#,
            _ => "members: [0]",
        };
        let e = Suite::parse(&text.replace(original, bad), Path::new("f.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(says), "{bad}: {e}");
    }
}

#[test]
fn errors_name_file_and_line() {
    let bad = GOOD.replace("budgets", "\n budgetz");
    let e = Suite::parse(&bad, Path::new("s.ron"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("s.ron:6:2:"), "{e}");
    let e = Suite::parse(&GOOD.replace("0.5", "-1.0"), Path::new("s.ron"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("time budget -1"), "{e}");
    let e = Suite::parse(&GOOD.replace("\"di\"", "\"path\""), Path::new("s.ron"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("used twice"), "{e}");
    let only = GOOD.replace("height: Some(16)", "height: 16, integrators: [\"di\"]");
    let s = Suite::parse(&only, Path::new("s.ron")).unwrap();
    assert!(s.scenes[0].runs("di") && !s.scenes[0].runs("path"));
    let e = Suite::parse(&only.replace("[\"di\"]", "[\"dj\"]"), Path::new("s.ron"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("'dj'"), "{e}");
}

#[test]
fn sequences() {
    let seq = GOOD.replace("height: Some(16)", "height: 16, frames: (2, 5), fps: 12");
    let s = Suite::parse(&seq, Path::new("s.ron")).unwrap();
    assert_eq!(
        (s.scenes[0].frames, s.scenes[0].fps),
        (Some((2, 5)), Some(12.0))
    );
    for (bad, needle) in [
        ("frames: (5, 2)", "frames (5, 2)"),
        ("frames: (0, 20000)", "at most 10000"),
        ("frames: (0, 1), fps: 0", "fps 0"),
        ("fps: 12", "`fps` without `frames`"),
    ] {
        let text = GOOD.replace("height: Some(16)", &format!("height: 16, {bad}"));
        let e = Suite::parse(&text, Path::new("s.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("s.ron: a.xml: ") && e.contains(needle), "{e}");
    }
}
