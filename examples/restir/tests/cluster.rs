//! `restir render --chain/--chains/--crop` and `restir merge` from the command line: parts merge
//! into the single-process image (tiles to the same bytes), the parts' `--stats` say which passes
//! and window they hold, and bad splits or mismatched parts are one-line errors.

use restir_testkit::TempDir;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const RESTIR: &str = env!("CARGO_BIN_EXE_restir");

fn cornell() -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/cornell-box.xml")
        .display()
        .to_string()
}

fn temp_dir(tag: &str) -> TempDir {
    TempDir::new("cluster", tag)
}

fn restir(args: &[&str]) -> Output {
    Command::new(RESTIR).args(args).output().unwrap()
}

fn ok(args: &[&str]) {
    let out = restir(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Expects exit code 1 and one stderr line equal to `want`.
fn fails(args: &[&str], want: &str) {
    let out = restir(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert_eq!(stderr.trim_end(), want, "{args:?}");
}

fn p(dir: &Path, name: &str) -> String {
    dir.join(name).display().to_string()
}

const SMALL: [&str; 7] = [
    "--width",
    "48",
    "--height",
    "32",
    "--quiet",
    "--threads",
    "2",
];

fn render(scene: &str, extra: &[&str], out: &str) {
    let mut args = vec!["render", scene, "-o", out];
    args.extend(SMALL);
    args.extend(extra);
    ok(&args);
}

#[test]
fn chains_and_tiles_merge_into_the_single_render() {
    let dir = temp_dir("merge");
    let d = &dir.0;
    let scene = cornell();
    // Without learning: a part learns only from its own passes, so with it (the default) a split
    // render is another estimator of the image, not the single render's bits.
    let di = [
        "--integrator",
        "restir-di",
        "--radius",
        "3",
        "--spp",
        "3",
        "--learn",
        "off",
    ];
    render(&scene, &di, &p(d, "full.exr"));
    // Tiles of rows, plus chains inside the last tile.
    render(
        &scene,
        &[&di[..], &["--crop", "0,0,48,20"]].concat(),
        &p(d, "t0.exr"),
    );
    for (i, name) in ["c0.exr", "c1.exr", "c2.exr"].iter().enumerate() {
        let i = i.to_string();
        let args = [
            &di[..],
            &["--crop", "0,20,48,32", "--chain", &i, "--chains", "3"],
        ]
        .concat();
        render(&scene, &args, &p(d, name));
    }
    let stats = p(d, "c1.json");
    let args = [
        &di[..],
        &["--crop", "0,20,48,32", "--chain", "1", "--chains", "3"],
    ]
    .concat();
    render(
        &scene,
        &[&args[..], &["--stats", &stats]].concat(),
        &p(d, "c1.exr"),
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    let part = &json["part"];
    assert_eq!(part["passes"], serde_json::json!([1, 2]));
    assert_eq!(part["spp_total"], 3);
    assert_eq!(part["chain"], serde_json::json!([1, 3]));
    assert_eq!(part["window"], serde_json::json!([0, 20, 48, 32]));
    assert_eq!(part["region"], serde_json::json!([0, 16, 48, 32]));
    assert_eq!(part["halo"], 3);
    assert_eq!(part["temporal_restarts"], false);
    assert_eq!(part["learning_restarts"], false);
    assert_eq!(json["spp"], 1);
    let merged = p(d, "merged.exr");
    let parts = ["t0.exr", "c0.exr", "c1.exr", "c2.exr"].map(|n| p(d, n));
    let mut args = vec!["merge", &merged];
    args.extend(parts.iter().map(String::as_str));
    ok(&args);
    // One-pass chains: the merge is exact, so the file has the same bytes.
    assert!(
        std::fs::read(&merged).unwrap() == std::fs::read(p(d, "full.exr")).unwrap(),
        "merged chains and tiles differ from the single render"
    );
    // With temporal reuse each chain's history starts afresh, and the stats say so.
    let temporal = p(d, "temporal.json");
    let args = [
        &di[..],
        &[
            "--temporal",
            "--chain",
            "2",
            "--chains",
            "3",
            "--stats",
            &temporal,
        ],
    ]
    .concat();
    render(&scene, &args, &p(d, "temporal.exr"));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&temporal).unwrap()).unwrap();
    assert_eq!(json["part"]["temporal_restarts"], true);
    // With learning (the default) each part learns from its own passes, and the stats say so.
    let learning = p(d, "learning.json");
    let args = [
        &di[..di.len() - 2],
        &["--chain", "2", "--chains", "3", "--stats", &learning],
    ]
    .concat();
    render(&scene, &args, &p(d, "learning.exr"));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&learning).unwrap()).unwrap();
    assert_eq!(json["part"]["learning_restarts"], true);
    assert!(
        json["learned"]
            .as_str()
            .is_some_and(|l| l.contains(" records from 1 pass in ")),
        "{json}"
    );
    // A plain render has no stats part.
    let plain = p(d, "plain.json");
    render(
        &scene,
        &["--spp", "1", "--stats", &plain],
        &p(d, "plain.exr"),
    );
    assert!(
        !std::fs::read_to_string(&plain)
            .unwrap()
            .contains("\"part\"")
    );
}

#[test]
fn bad_splits_are_errors() {
    let dir = temp_dir("bad");
    let out = p(&dir.0, "x.exr");
    let scene = cornell();
    let base = [
        "render", &scene, "-o", &out, "--width", "48", "--height", "32",
    ];
    let run = |extra: &[&str], want: &str| fails(&[&base[..], extra].concat(), want);
    run(
        &["--spp", "4", "--chain", "4", "--chains", "4"],
        "error: --chain 4: expected 0 to 3 (--chains 4)",
    );
    run(
        &["--spp", "4", "--chain", "0", "--chains", "5"],
        "error: --chains 5: expected 1 to 4 (the render's passes)",
    );
    run(
        &["--crop", "0,0,49,32"],
        "error: --crop 0,0,49,32: outside the 48×32 film",
    );
    run(
        &["--crop", "5,0,5,32"],
        "error: --crop 5,0,5,32: expected x0,y0,x1,y1 (pixels, x0 < x1 <= width, y0 < y1 <= height)",
    );
    run(
        &["--time-limit", "1", "--crop", "0,0,8,8"],
        "error: --time-limit cannot be combined with --chain or --crop: a part's passes must be fixed for merge",
    );
    let png = p(&dir.0, "x.png");
    fails(
        &["render", &scene, "-o", &png, "--crop", "0,0,8,8"],
        &format!("error: {png}: a part of a render (--chain, --crop) must be written as .exr"),
    );
    let out = restir(&[&base[..], &["--chain", "1"]].concat());
    assert_eq!(out.status.code(), Some(1));
    // clap's message; the front end prints its first line.
    assert!(String::from_utf8_lossy(&out.stderr).contains("required arguments were not provided"));
}

#[test]
fn parts_of_different_renders_do_not_merge() {
    let dir = temp_dir("mismatch");
    let d = &dir.0;
    let scene = cornell();
    let chain = |i: &str, extra: &[&str], name: &str| {
        let args = [&["--spp", "2", "--chain", i, "--chains", "2"][..], extra].concat();
        render(&scene, &args, &p(d, name));
    };
    chain("0", &[], "a.exr");
    chain("1", &["--seed", "9"], "seed.exr");
    chain("1", &["--max-depth", "2"], "depth.exr");
    let merged = p(d, "m.exr");
    let (a, seed, depth) = (p(d, "a.exr"), p(d, "seed.exr"), p(d, "depth.exr"));
    fails(
        &["merge", &merged, &a, &seed],
        &format!(
            "error: {a} and {seed}: parts of different renders (seed differs: restir:seed '0' vs '9')"
        ),
    );
    let out = restir(&["merge", &merged, &a, &depth]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains("integrator settings differs"), "{stderr}");
    // Another film size is another scene description.
    let other = p(d, "size.exr");
    ok(&[
        "render", &scene, "-o", &other, "--width", "40", "--height", "32", "--quiet", "--spp", "2",
        "--chain", "1", "--chains", "2",
    ]);
    let out = restir(&["merge", &merged, &a, &other]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("(scene differs"));
    fails(
        &["merge", &merged, &a],
        "error: window 0,0,48,32: passes 1..2 of 2 are missing",
    );
    fails(
        &["merge", &merged, &a, &a],
        &format!("error: {a} (passes 0..1) and {a} (passes 0..1): passes overlap"),
    );
    let plain = p(d, "plain.exr");
    render(&scene, &["--spp", "1"], &plain);
    fails(
        &["merge", &merged, &plain],
        &format!(
            "error: {plain}: not a part of a split render (no restir:passes attribute): render parts with --chain/--crop"
        ),
    );
}

/// Writes a crafted part: a `w`×`h` image of `value` at `offset` in a `film` display window,
/// with attributes claiming `film_attr`.
fn crafted_part(
    path: &str,
    (w, h): (u32, u32),
    value: f32,
    offset: (u32, u32),
    film: (u32, u32),
    film_attr: &str,
) {
    let mut image = restir_image::Image::new(w, h);
    image.pixels.fill(glam::Vec3::splat(value));
    let (x1, y1) = (offset.0 + w, offset.1 + h);
    let attributes = [
        ("restir:scene", "s.xml".to_string()),
        ("restir:scene_hash", "0".into()),
        ("restir:integrator", "path".into()),
        ("restir:seed", "0".into()),
        ("restir:spp", "1".into()),
        ("restir:passes", "0..1".into()),
        (
            "restir:window",
            format!("{},{},{x1},{y1}", offset.0, offset.1),
        ),
        ("restir:film", film_attr.into()),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    let part = restir_image::ExrPart {
        film,
        offset,
        attributes,
    };
    image.write_exr_part(Path::new(path), &part).unwrap();
}

/// Expects exit code 1, no panic, and stderr containing `want`.
fn fails_with(args: &[&str], want: &str) {
    let out = restir(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert!(stderr.contains(want), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
}

/// A part claiming a 65536² film, a `restir:film` attribute that disagrees with the display
/// window, the output naming an input, a memory limit: errors before anything is allocated
/// or overwritten, never an abort or a panic. NaN pixels merge with a warning.
#[test]
fn merge_checks_parts_as_every_reader() {
    let dir = temp_dir("merge-checks");
    let d = &dir.0;
    let (huge, out) = (p(d, "huge.exr"), p(d, "out.exr"));
    crafted_part(&huge, (2, 2), 1.0, (0, 0), (65536, 65536), "65536x65536");
    fails_with(&["merge", &out, &huge], "beyond the limit");
    // The film attribute says 4×4 while the display window is 2×2.
    let liar = p(d, "liar.exr");
    crafted_part(&liar, (2, 2), 1.0, (0, 0), (2, 2), "4x4");
    fails_with(
        &["merge", &out, &liar],
        "its restir:film attribute '4x4' does not match its display window (2x2)",
    );
    let good = p(d, "good.exr");
    crafted_part(&good, (2, 2), 0.5, (0, 0), (2, 2), "2x2");
    let before = std::fs::read(&good).unwrap();
    fails_with(
        &["merge", &good, &good],
        "merging would overwrite one of its inputs",
    );
    assert_eq!(std::fs::read(&good).unwrap(), before);
    fails_with(
        &["merge", &out, &good, "--max-memory", "1e-9"],
        "bytes (0.0 GiB), more than the limit of 0.000000001 GiB",
    );
    ok(&["merge", &out, &good]);
    let nan = p(d, "nan.exr");
    crafted_part(&nan, (2, 2), f32::NAN, (0, 0), (2, 2), "2x2");
    let o = restir(&["merge", &out, &nan]);
    assert!(o.status.success());
    assert_eq!(
        String::from_utf8_lossy(&o.stderr),
        "warning: 4 pixels are NaN or infinite\n"
    );
}

/// A FIFO among the parts is refused at once (opening it would wait for a writer forever).
#[cfg(unix)]
#[test]
fn merge_refuses_a_fifo() {
    let dir = temp_dir("merge-fifo");
    let fifo = p(&dir.0, "part.exr");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let mut child = Command::new(RESTIR)
        .args(["merge", &p(&dir.0, "out.exr"), &fifo])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > std::time::Duration::from_secs(20) {
            child.kill().unwrap();
            panic!("merge hangs on a FIFO");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("not a regular file"));
}

/// Parts rendered before and after a mesh file changed are parts of different renders; with
/// the mesh unchanged they merge.
#[test]
fn the_scene_hash_covers_mesh_contents() {
    let dir = temp_dir("merge-assets");
    let d = &dir.0;
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/textured");
    for f in ["textured-shapes.xml", "quad.obj", "quad.ply", "tex.png"] {
        std::fs::copy(src.join(f), d.join(f)).unwrap();
    }
    let scene = p(d, "textured-shapes.xml");
    let chain =
        |i: &str, out: &str| render(&scene, &["--spp", "2", "--chains", "2", "--chain", i], out);
    let (a, b, m) = (p(d, "a.exr"), p(d, "b.exr"), p(d, "m.exr"));
    chain("0", &a);
    chain("1", &b);
    ok(&["merge", &m, &a, &b]);
    let mut obj = std::fs::read(d.join("quad.obj")).unwrap();
    obj.extend_from_slice(b"\n# edited\n");
    std::fs::write(d.join("quad.obj"), obj).unwrap();
    chain("1", &b);
    fails_with(&["merge", &m, &a, &b], "scene differs");
}

/// An interrupted chain's part holds the passes it rendered and says so: its `restir:passes`
/// ends where the render stopped, so the merge reports the missing passes.
#[cfg(unix)]
#[test]
fn an_interrupted_part_records_its_passes() {
    let dir = temp_dir("merge-interrupted");
    let out = p(&dir.0, "part.exr");
    let child = Command::new(RESTIR)
        .args(["render", &cornell(), "-o", &out, "--spp", "100000"])
        .args(["--chain", "0", "--chains", "2", "--quiet"])
        .args(["--width", "16", "--height", "16"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    assert!(
        Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status()
            .unwrap()
            .success()
    );
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130));
    let (_, part) = restir_image::Image::read_exr_part(Path::new(&out)).unwrap();
    let passes = part.attribute("restir:passes").unwrap();
    let end: u32 = passes.strip_prefix("0..").unwrap().parse().unwrap();
    assert!(end > 0 && end < 50000, "{passes}");
    fails_with(
        &["merge", &p(&dir.0, "m.exr"), &out],
        &format!("passes {end}..100000 of 100000 are missing"),
    );
}

/// `merge` and `generate` report what they wrote on stdout: a full stdout (`> /dev/full`) or a
/// closed one (`| head -c0`) is an error with a message and exit status 1, not a panic and not
/// a success whose report was lost. (The files are written before the report.)
#[cfg(unix)]
#[test]
fn a_full_or_closed_stdout_is_an_error() {
    use std::process::Stdio;
    let dir = temp_dir("stdout");
    let d = dir.0.as_path();
    let scene = cornell();
    for i in 0..2 {
        let chain = i.to_string();
        render(
            &scene,
            &["--spp", "2", "--chain", &chain, "--chains", "2"],
            &p(d, &format!("c{i}.exr")),
        );
    }
    let (c0, c1) = (p(d, "c0.exr"), p(d, "c1.exr"));
    let merged = p(d, "m.exr");
    let generated = p(d, "g.ron");
    let commands: [&[&str]; 2] = [
        &["merge", &merged, &c0, &c1],
        &["generate", "rects", "--lights", "4", "-o", &generated],
    ];
    for args in commands {
        // Full: every write fails with ENOSPC.
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let out = Command::new(RESTIR)
            .args(args)
            .stdout(Stdio::from(full))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?} > /dev/full: {stderr}");
        assert!(
            stderr.contains("cannot write to standard output") && !stderr.contains("panicked"),
            "{args:?} > /dev/full: {stderr}"
        );
        // Closed: the reading end is gone before the command starts.
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let out = Command::new(RESTIR)
            .args(args)
            .stdout(writer)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?} | head -c0: {stderr}");
        assert!(
            stderr.contains("cannot write to standard output") && !stderr.contains("panicked"),
            "{args:?} | head -c0: {stderr}"
        );
    }
}
