//! Every shipped file in `scenes/` loads from the repository alone: the scenes are copied (the
//! whole `scenes/` tree, nothing else) into a fresh directory and loaded from there, so a file
//! reached through a path leaving the repository (such as the shared corpus beside the clone)
//! is missing; and every file a scene names is a relative path that stays inside `scenes/`. The
//! bench suites' scenes are in the copy too. The committed assets are the ones `restir generate`
//! writes (`envmap`, `uv-pattern`).

use std::path::{Component, Path, PathBuf};
use std::process::Command;

use restir_testkit::TempDir;

const RESTIR: &str = env!("CARGO_BIN_EXE_restir");

fn scenes_dir() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes"))
}

/// Every file under `dir`, recursively, sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(files(&p));
        } else {
            out.push(p);
        }
    }
    out.sort();
    out
}

/// Copies `from` into `to` (created), recursively.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let dest = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_tree(&p, &dest);
        } else {
            std::fs::copy(&p, &dest).unwrap();
        }
    }
}

/// Every string value of a field named `filename` in `v`.
fn filenames(v: &serde_json::Value, out: &mut Vec<String>) {
    match v {
        serde_json::Value::Object(m) => {
            for (k, x) in m {
                if k == "filename"
                    && let Some(s) = x.as_str()
                {
                    out.push(s.to_string());
                }
                filenames(x, out);
            }
        }
        serde_json::Value::Array(a) => a.iter().for_each(|x| filenames(x, out)),
        _ => {}
    }
}

/// `rel` (relative to `scene_dir`, itself relative to the scenes root) stays inside the root.
fn stays_inside(scene_dir: &Path, rel: &str) -> bool {
    let mut depth = 0i32;
    for c in scene_dir.join(rel).components() {
        match c {
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            Component::ParentDir => {
                depth -= 1;
                if depth < 0 {
                    return false;
                }
            }
            Component::RootDir | Component::Prefix(_) => return false,
        }
    }
    true
}

#[test]
fn every_shipped_scene_loads_from_the_repository_alone() {
    let root = scenes_dir();
    // Nothing beside the copy: a path leaving it finds no file.
    let sandbox = TempDir::new("scenes", "sandbox");
    let copy = sandbox.join("repo/scenes");
    copy_tree(&root, &copy);

    let mut scenes = 0;
    let mut suites = 0;
    let mut animated = 0;
    for file in files(&copy) {
        let rel = file.strip_prefix(&copy).unwrap().to_path_buf();
        let ext = file.extension().and_then(|e| e.to_str()).unwrap_or("");
        if rel.starts_with("bench") && ext == "ron" {
            // A bench suite: its scenes are relative to it and must be in the copy.
            let suite = restir_evaluation::Suite::load(&file)
                .unwrap_or_else(|e| panic!("{}: {e}", rel.display()));
            suite.validate().unwrap();
            for s in &suite.scenes {
                let p = file.parent().unwrap().join(&s.path);
                assert!(
                    p.is_file(),
                    "{}: scene {} missing",
                    rel.display(),
                    p.display()
                );
            }
            suites += 1;
            continue;
        }
        if ext != "xml" && ext != "ron" {
            continue;
        }
        if rel.to_string_lossy().ends_with(".anim.ron") {
            // An XML scene's animation: read with its scene, which must be beside it.
            let name = file
                .file_name()
                .unwrap()
                .to_string_lossy()
                .replace(".anim.ron", ".xml");
            assert!(
                file.with_file_name(&name).is_file(),
                "{}: no scene {name} beside it",
                rel.display()
            );
            continue;
        }
        let options = restir_scene::LoadOptions {
            width: Some(8),
            height: Some(8),
            ..Default::default()
        };
        let loaded = restir_scene::load_scene(&file, &options)
            .unwrap_or_else(|e| panic!("{} does not load from scenes/ alone: {e}", rel.display()));
        if restir_scene::sidecar_path(&file).is_file() {
            assert!(loaded.desc.animation.is_some(), "{}", rel.display());
        }
        // An animated scene builds at its first and a later time.
        if loaded.desc.animation.is_some() {
            for t in [0.0, 1.5] {
                restir_scene::animation::build_at(&loaded.desc, &file, t)
                    .unwrap_or_else(|e| panic!("{}: {e}", rel.display()));
            }
            animated += 1;
        }
        let json = serde_json::to_value(&loaded.desc).unwrap();
        let mut names = Vec::new();
        filenames(&json, &mut names);
        for n in &names {
            assert!(
                stays_inside(rel.parent().unwrap(), n),
                "{}: '{n}' leaves scenes/",
                rel.display()
            );
        }
        scenes += 1;
    }
    drop(sandbox);
    assert!(scenes >= 8, "only {scenes} scenes found");
    assert!(suites >= 2, "only {suites} suites found");
    assert!(animated >= 2, "only {animated} animated scenes found");
}

/// The path check itself: relative paths that stay inside pass, the corpus path of old fails.
#[test]
fn paths_leaving_the_scenes_directory_are_caught() {
    assert!(stays_inside(Path::new(""), "envmap/sky.exr"));
    assert!(stays_inside(Path::new("textured"), "../envmap/sky.exr"));
    assert!(!stays_inside(
        Path::new(""),
        "../../shared/corpus/lajolla/matpreview/envmap.exr"
    ));
    assert!(!stays_inside(
        Path::new(""),
        "/work/shared/corpus/envmap.exr"
    ));
}

/// `scenes/envmap/sky.exr` is what `restir generate envmap` writes (within rounding of the
/// platform's sin/cos), so the asset can be remade.
#[test]
fn the_committed_sky_is_the_generated_one() {
    let dir = TempDir::new("scenes", "sky");
    let out = dir.join("sky.exr");
    let o = Command::new(RESTIR)
        .args(["generate", "envmap", "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let made = restir_image::Image::read_exr(&out).unwrap();
    let committed = restir_image::Image::read_exr(&scenes_dir().join("envmap/sky.exr")).unwrap();
    assert_eq!(
        (made.width, made.height),
        (committed.width, committed.height)
    );
    for (a, b) in made.pixels.iter().zip(&committed.pixels) {
        assert!((*a - *b).abs().max_element() <= 1e-5 * b.max_element().max(1.0));
    }
}

/// `scenes/textured/tex.png` is what `restir generate uv-pattern` writes (8-bit, so exact).
#[test]
fn the_committed_uv_pattern_is_the_generated_one() {
    let dir = TempDir::new("scenes", "uv");
    let out = dir.join("tex.png");
    let o = Command::new(RESTIR)
        .args(["generate", "uv-pattern", "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let raw = restir_image::IntegerEncoding::Raw;
    let made = restir_image::Image::read(&out, raw).unwrap();
    let committed = restir_image::Image::read(&scenes_dir().join("textured/tex.png"), raw).unwrap();
    assert_eq!(made, committed);
}
