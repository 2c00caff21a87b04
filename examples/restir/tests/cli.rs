//! The `restir` command on bad input (exit code 1, a one-line error naming the problem, never a
//! panic) and on a tiny happy path (images, `--stats` JSON, `compare`).

mod common;
use common::{cornell, fails, restir, s};

use restir_testkit::TempDir;
use std::path::{Path, PathBuf};

fn temp_dir(tag: &str) -> TempDir {
    TempDir::new("cli", tag)
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn missing_scene_file() {
    let dir = temp_dir("missing");
    let scene = dir.join("no-such-scene.xml");
    let out = dir.join("o.png");
    fails(
        &["render", s(&scene), "-o", s(&out)],
        &[s(&scene), "cannot read"],
    );
}

#[test]
fn malformed_xml_names_file_and_line() {
    let dir = temp_dir("xml");
    let scene = write(
        &dir,
        "bad.xml",
        "<scene version=\"3.0.0\">\n    <shape type=\"rectangle\">\n        <float name=\"x\" value=\"1\"\n    </shape>\n</scene>\n",
    );
    let out = dir.join("o.png");
    let line = fails(&["render", s(&scene), "-o", s(&out)], &["malformed XML"]);
    // `file:line:` with a line in the malformed region.
    let prefix = format!("{}:", s(&scene));
    let rest = line
        .split_once(&prefix)
        .unwrap_or_else(|| panic!("{line:?} does not name the file"))
        .1;
    let n: u32 = rest.split(':').next().unwrap().parse().unwrap();
    assert!((3..=4).contains(&n), "line {n} in {line:?}");
}

#[test]
fn malformed_ron_names_file_and_line() {
    let dir = temp_dir("ron");
    let scene = write(
        &dir,
        "bad.ron",
        "(\n    camera: (fov: 40),\n    film: (width: 16 height: 16),\n)\n",
    );
    let out = dir.join("o.png");
    fails(
        &["render", s(&scene), "-o", s(&out)],
        &[&format!("{}:3:", s(&scene))],
    );
}

#[test]
fn unknown_field_in_ron() {
    let dir = temp_dir("ronfield");
    let scene = write(&dir, "typo.ron", "(\n    camera: (fov: 40, fvo: 3),\n)\n");
    let out = dir.join("o.png");
    fails(
        &["render", s(&scene), "-o", s(&out)],
        &[&format!("{}:2:", s(&scene)), "fvo"],
    );
}

#[test]
fn unknown_plugin_type() {
    let dir = temp_dir("plugin");
    let scene = write(
        &dir,
        "teapot.xml",
        "<scene version=\"3.0.0\">\n    <shape type=\"teapot\"/>\n</scene>\n",
    );
    let out = dir.join("o.png");
    fails(
        &["render", s(&scene), "-o", s(&out)],
        &[&format!("{}:2:", s(&scene)), "teapot"],
    );
}

/// A bad ReSTIR parameter in the scene's `<integrator>` names the scene file and the line of
/// the integrator; the same value on the command line is reported as a flag.
#[test]
fn bad_integrator_parameter_in_scene() {
    let dir = temp_dir("integrator-param");
    let scene = write(
        &dir,
        "restir.xml",
        "<scene version=\"3.0.0\">\n    <integrator type=\"restir\">\n        \
         <integer name=\"reservior_size\" value=\"0\"/>\n    </integrator>\n    \
         <sensor type=\"perspective\"/>\n    <shape type=\"rectangle\"/>\n</scene>\n",
    );
    let out = dir.join("o.png");
    fails(
        &[
            "render",
            s(&scene),
            "-o",
            s(&out),
            "--width",
            "8",
            "--height",
            "8",
        ],
        &[&format!("{}:2:", s(&scene)), "reservior_size"],
    );
    let line = fails(
        &[
            "render",
            s(&cornell()),
            "-o",
            s(&out),
            "--integrator",
            "restir-di",
            "--mis",
            "magic",
        ],
        &["mis", "defensive-pairwise"],
    );
    assert!(!line.contains(".xml"), "{line}");
}

#[test]
fn nan_in_a_parameter() {
    let dir = temp_dir("nan");
    let text = std::fs::read_to_string(cornell()).unwrap();
    let needle = "<float name=\"fov\" value=\"40\"/>";
    assert!(text.contains(needle));
    let line = text.lines().position(|l| l.contains(needle)).unwrap() + 1;
    let scene = write(
        &dir,
        "nan.xml",
        &text.replace(needle, "<float name=\"fov\" value=\"nan\"/>"),
    );
    let out = dir.join("o.png");
    fails(
        &["render", s(&scene), "-o", s(&out)],
        &[&format!("{}:{line}:", s(&scene)), "nan", "finite"],
    );
    // And a NaN in a RON scene, caught while deserialising, at its line.
    let scene = write(
        &dir,
        "nan.ron",
        "(camera: (fov: 40), shapes: [(geometry: Sphere(center: (0, 0, 0), radius: NaN))])",
    );
    fails(
        &["render", s(&scene), "-o", s(&out)],
        &[&format!("{}:1:", s(&scene)), "NaN is not a finite number"],
    );
}

/// clap's whole message (error, hints, usage) on stderr, exit code 1.
#[test]
fn unknown_flag() {
    for (args, needle) in [
        (
            &["render", s(&cornell()), "--frobnicate"][..],
            "--frobnicate",
        ),
        (&["frobnicate"][..], "frobnicate"),
    ] {
        let out = restir(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(
            stderr.starts_with("error: ") && stderr.contains(needle),
            "{stderr}"
        );
        assert!(stderr.contains("Usage: restir"), "{stderr}");
    }
}

#[test]
fn unknown_integrator() {
    let dir = temp_dir("integrator");
    let out = dir.join("o.png");
    fails(
        &[
            "render",
            s(&cornell()),
            "--integrator",
            "nosuch",
            "-o",
            s(&out),
        ],
        &["unknown integrator", "nosuch", "path"],
    );
}

#[test]
fn bad_define_syntax() {
    let dir = temp_dir("define");
    let out = dir.join("o.png");
    for bad in ["resx", "=3"] {
        fails(
            &["render", s(&cornell()), "-D", bad, "-o", s(&out)],
            &["-D", bad, "NAME=VALUE"],
        );
    }
    // A well-formed define with a value the scene cannot use: file and line.
    fails(
        &["render", s(&cornell()), "-D", "resx=abc", "-o", s(&out)],
        &["cornell-box.xml:", "\"abc\"", "integer"],
    );
}

#[test]
fn unwritable_output_path() {
    let dir = temp_dir("unwritable");
    // A regular file where a directory should be: fails even for root, before rendering.
    let file = write(&dir, "a-file", "");
    let out = file.join("o.png");
    fails(
        &["render", s(&cornell()), "--spp", "1", "-o", s(&out)],
        &[s(&file), "cannot create output directory"],
    );
    // The output is an existing directory.
    let out = dir.join("dir.png");
    std::fs::create_dir_all(&out).unwrap();
    fails(
        &["render", s(&cornell()), "--spp", "1", "-o", s(&out)],
        &[s(&out), "directory"],
    );
    // An unsupported extension.
    let out = dir.join("o.txt");
    fails(
        &["render", s(&cornell()), "--spp", "1", "-o", s(&out)],
        &[s(&out), ".exr or .png"],
    );
    // The stats file cannot be written (after a render of 8×8 pixels).
    let out = dir.join("o.exr");
    let stats = file.join("stats.json");
    let common = ["--width", "8", "--height", "8", "--spp", "1", "--quiet"];
    let c = cornell();
    let mut args = vec!["render", s(&c), "-o", s(&out), "--stats", s(&stats)];
    args.extend(common);
    fails(&args, &[s(&stats)]);
}

#[test]
fn bad_numbers_on_the_command_line() {
    let dir = temp_dir("numbers");
    let out = dir.join("o.png");
    let c = cornell();
    // Each of these fails before rendering.
    let base = ["render", s(&c), "-o", s(&out)];
    let cases: [(&[&str], &[&str]); 6] = [
        (&["--time-limit", "nan"], &["--time-limit"]),
        (&["--time-limit", "1e300"], &["--time-limit", "too large"]),
        (&["--threads", "100000"], &["--threads", "100000"]),
        (&["--spp", "0"], &["--spp"]),
        (&["--max-depth", "-5"], &["max depth -5"]),
        (&["--width", "0"], &["0×256", "resolution"]),
    ];
    for (extra, needles) in cases {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        fails(&args, needles);
    }
}

/// Files of the scene crate's bad-scene suite through the command: a truncated binary PLY (an
/// error found while building), 3000 nested bsdfs (once a stack overflow) and a 10⁶×10⁶ film
/// (rejected before anything is allocated) exit with code 1 and the suite's message.
#[test]
fn bad_scene_suite_files() {
    let dir = temp_dir("badsuite");
    let out = dir.join("o.png");
    let suite =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../crates/scene/tests/bad_scenes");
    for (file, needles) in [
        (
            "ply_truncated_binary.xml",
            &["ply_truncated_binary.xml:9:", "truncated"][..],
        ),
        (
            "xml_deep_nesting.xml",
            &["xml_deep_nesting.xml:10:", "wraps another twosided"][..],
        ),
        (
            "film_million_squared.xml",
            &[
                "film_million_squared.xml:5:",
                "film width 1000000 is out of range",
            ][..],
        ),
    ] {
        let scene = suite.join(file);
        fails(&["render", s(&scene), "-o", s(&out)], needles);
    }
    assert!(!out.exists(), "no image is written for a bad scene");
}

#[test]
fn compare_bad_inputs() {
    let dir = temp_dir("compare");
    let not_exr = write(&dir, "not.exr", "hello");
    let missing = dir.join("missing.exr");
    fails(&["compare", s(&not_exr), s(&not_exr)], &[s(&not_exr)]);
    fails(&["compare", s(&missing), s(&not_exr)], &[s(&missing)]);
}

/// NaN is never a perfect match: an all-NaN image is an error, NaN in the reference is counted
/// and warned about.
/// Images of different sizes are refused from their headers, before either is decoded: a
/// truncated file that claims a 1024² image is not read beyond its header.
#[test]
fn compare_refuses_different_sizes_before_decoding() {
    let dir = temp_dir("compare-size");
    let small = dir.join("small.exr");
    restir_image::Image::new(8, 8).write(&small).unwrap();
    let big = dir.join("big.exr");
    restir_image::Image::new(1024, 1024).write(&big).unwrap();
    let f = std::fs::OpenOptions::new().write(true).open(&big).unwrap();
    f.set_len(2000).unwrap();
    fails(
        &["compare", s(&small), s(&big)],
        &[s(&small), "size 8×8 differs from the reference's 1024×1024"],
    );
}

#[test]
fn compare_counts_nan_on_both_sides() {
    let dir = temp_dir("compare-nan");
    let image = |name: &str, v: [f32; 2]| {
        let mut img = restir_image::Image::new(2, 1);
        img.pixels = v.iter().map(|&x| glam::Vec3::splat(x)).collect();
        let p = dir.join(name);
        img.write(&p).unwrap();
        p
    };
    let nan = image("nan.exr", [f32::NAN; 2]);
    let black = image("black.exr", [0.0; 2]);
    let half = image("half.exr", [f32::NAN, 0.0]);
    fails(
        &["compare", s(&nan), s(&black)],
        &[
            "no pixel is finite in both",
            "2 NaN or infinite in the image",
        ],
    );
    fails(
        &["compare", s(&black), s(&nan)],
        &["no pixel is finite in both", "2 in the reference"],
    );
    let o = restir(&["compare", s(&black), s(&half)]);
    assert!(o.status.success());
    let stdout = String::from_utf8(o.stdout).unwrap();
    assert!(
        stdout.contains(" nonfinite=0 reference_nonfinite=1 "),
        "{stdout}"
    );
    assert!(stdout.contains("relmse=0.0"), "{stdout}");
    let stderr = String::from_utf8(o.stderr).unwrap();
    assert!(stderr.contains("half.exr: 1 pixels are NaN"), "{stderr}");
}

#[test]
fn tiny_render_writes_images_stats_and_compares() {
    let dir = temp_dir("happy");
    let exr = dir.join("a.exr");
    let exr2 = dir.join("b.exr");
    let png = dir.join("a.png");
    let stats = dir.join("stats.json");
    let c = cornell();
    let tiny = ["--width", "16", "--height", "16", "--spp", "2", "--quiet"];
    for (out, seed) in [(&exr, "1"), (&exr2, "2"), (&png, "1")] {
        let mut args = vec!["render", s(&c), "-o", s(out), "--seed", seed];
        args.extend(tiny);
        if out == &exr {
            args.extend(["--stats", s(&stats)]);
        }
        let o = restir(&args);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{args:?}: {stderr}");
        assert!(stderr.is_empty(), "--quiet printed: {stderr}");
    }
    let exr_bytes = std::fs::read(&exr).unwrap();
    assert_eq!(&exr_bytes[..4], &[0x76, 0x2f, 0x31, 0x01], "EXR magic");
    let png_bytes = std::fs::read(&png).unwrap();
    assert_eq!(&png_bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG magic");

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    for key in [
        "seconds",
        "load_seconds",
        "spp",
        "width",
        "height",
        "integrator",
        "rays",
        "nonfinite_pixels",
    ] {
        assert!(json.get(key).is_some(), "stats lack {key}: {json}");
    }
    assert_eq!(json["spp"], 2);
    assert_eq!(json["width"], 16);
    assert_eq!(json["height"], 16);
    assert_eq!(json["integrator"], "path");
    assert_eq!(json["nonfinite_pixels"], 0);
    let bvh = json["bvh"].as_str().unwrap();
    assert!(bvh.contains("nodes") && bvh.contains("kernel"), "{bvh}");
    // The Cornell box's one light is picked by power: its samples are drawn in lanes.
    let lanes = json["lanes"].as_str().unwrap();
    assert!(
        lanes.contains("paths at a time") && lanes.contains("light samples in lanes"),
        "{lanes}"
    );
    // At least a camera ray per pixel and pass.
    assert!(json["rays"].as_u64().unwrap() >= 16 * 16 * 2);
    assert!(json["seconds"].as_f64().unwrap() >= 0.0);

    // compare: one line `relmse=… mse=… mean_ratio=… nonfinite=… reference_nonfinite=… mape=…
    // flip=… top1_share=…`.
    let o = restir(&["compare", s(&exr), s(&exr2)]);
    assert!(o.status.success());
    let stdout = String::from_utf8(o.stdout).unwrap();
    let fields: Vec<(&str, &str)> = stdout
        .trim()
        .split(' ')
        .map(|f| f.split_once('=').unwrap())
        .collect();
    let names: Vec<&str> = fields.iter().map(|f| f.0).collect();
    assert_eq!(
        names,
        [
            "relmse",
            "mse",
            "mean_ratio",
            "nonfinite",
            "reference_nonfinite",
            "mape",
            "flip",
            "top1_share"
        ]
    );
    let relmse: f64 = fields[0].1.parse().unwrap();
    let ratio: f64 = fields[2].1.parse().unwrap();
    assert!(relmse > 0.0 && relmse.is_finite(), "{stdout}");
    assert!(ratio > 0.5 && ratio < 2.0, "{stdout}");
    assert_eq!(fields[3].1, "0");
    assert_eq!(fields[4].1, "0");
    let mape: f64 = fields[5].1.parse().unwrap();
    let flip: f64 = fields[6].1.parse().unwrap();
    assert!(mape > 0.0 && mape.is_finite(), "{stdout}");
    assert!(flip > 0.0 && flip < 1.0, "{stdout}");
    // An image against itself, with the comparison page.
    let page = dir.join("cmp.html");
    let o = restir(&["compare", s(&exr), s(&exr), "--html", s(&page)]);
    let stdout = String::from_utf8(o.stdout).unwrap();
    assert_eq!(
        stdout,
        "relmse=0.000000e0 mse=0.000000e0 mean_ratio=1.000000 nonfinite=0 reference_nonfinite=0 mape=0.000000e0 \
         flip=0.000000 top1_share=NaN\n"
    );
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>") && html.contains("\"hdr_f16\""));
    fails(
        &["compare", s(&exr), s(&exr), "--html", "/proc/nope/x.html"],
        &["/proc/nope/x.html"],
    );
    // Different sizes are an error, not a panic.
    let small = dir.join("small.exr");
    let mut args = vec!["render", s(&c), "-o", s(&small), "--width", "8"];
    args.extend(&tiny[2..]);
    assert!(restir(&args).status.success());
    fails(&["compare", s(&small), s(&exr)], &[s(&small), "differs"]);
}

/// What is asked for is what runs: `--integrator auto` says on the summary line and in
/// `--stats` which estimator it chose and why; a named one says it was asked for by name; the
/// removed `--fallback` is an error naming what replaced it.
#[test]
fn auto_says_what_ran_and_why() {
    let dir = temp_dir("auto");
    let out = dir.join("o.exr");
    let stats = dir.join("s.json");
    for (name, ran, why) in [
        ("auto", "path", "chosen by auto: "),
        ("restir-di", "restir-di", "asked for by name"),
    ] {
        let o = restir(&[
            "render",
            s(&cornell()),
            "--integrator",
            name,
            "--spp",
            "1",
            "--width",
            "16",
            "--height",
            "16",
            "-o",
            s(&out),
            "--stats",
            s(&stats),
        ]);
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(
            stdout.starts_with(&format!("{ran} ")) && stdout.contains(&format!(" [{why}")),
            "{stdout}"
        );
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
        assert_eq!(json["integrator"], ran);
        assert_eq!(json["estimator"]["asked"], name);
        assert_eq!(json["estimator"]["ran"], ran);
        assert!(
            json["estimator"]["why"].as_str().unwrap().starts_with(why),
            "{json}"
        );
    }
    fails(
        &[
            "render",
            s(&cornell()),
            "--integrator",
            "restir-di",
            "--fallback",
            "off",
            "-o",
            s(&out),
        ],
        &["fallback = 'off': no such parameter any more", "auto"],
    );
}
