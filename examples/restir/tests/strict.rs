//! Strict inputs on the command line: each bad input fails before rendering with
//! exit code 1 and exactly the message checked here, naming the file and line or the flag, and
//! the valid choices.

mod common;
use common::{cornell, fails_with, restir, s};

use restir_testkit::TempDir;
use std::path::PathBuf;

fn temp_dir(tag: &str) -> TempDir {
    TempDir::new("strict", tag)
}

/// A minimal scene with `body` after its sensor.
fn scene(dir: &TempDir, name: &str, body: &str) -> PathBuf {
    let text = format!(
        "<scene version=\"3.0.0\">\n{body}\n    <sensor type=\"perspective\">\n        \
         <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/>\
         <integer name=\"height\" value=\"8\"/></film>\n    </sensor>\n    \
         <shape type=\"sphere\"><emitter type=\"area\"/></shape>\n</scene>\n"
    );
    let path = dir.0.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn integrator_type_typo_is_an_error_listing_the_types() {
    let dir = temp_dir("integrator");
    let sc = scene(&dir, "typo.xml", "    <integrator type=\"restir-dl\"/>");
    let out = dir.0.join("o.exr");
    fails_with(
        &["render", s(&sc), "-o", s(&out)],
        &format!(
            "error: {}:2: unknown integrator type 'restir-dl' (known: path, moment, ptracer, volpath, \
             direct, restir-di, restir_di, restir, restirdi, restir-pt, restir_pt, restirpt)",
            s(&sc)
        ),
    );
    assert!(!out.exists());
}

#[test]
fn unknown_plugin_types_list_the_valid_ones() {
    let dir = temp_dir("types");
    let sc = scene(
        &dir,
        "bsdf.xml",
        "    <shape type=\"sphere\"><bsdf type=\"velvet\"/></shape>",
    );
    fails_with(
        &["render", s(&sc), "-o", s(&dir.0.join("o.exr"))],
        &format!(
            "error: {}:2: unknown bsdf type 'velvet' (known: diffuse, twosided, conductor, \
             roughconductor, dielectric, roughdielectric, thindielectric, plastic, roughplastic, \
             null, mask, normalmap, principled, principledthin, bumpmap, blendbsdf)",
            s(&sc)
        ),
    );
}

#[test]
fn conductor_ior_error_names_its_line() {
    let dir = temp_dir("conductor");
    let sc = scene(
        &dir,
        "eta.xml",
        "    <shape type=\"sphere\">\n        <bsdf type=\"conductor\">\n            \
         <rgb name=\"eta\" value=\"-1\"/>\n        </bsdf>\n    </shape>",
    );
    fails_with(
        &["render", s(&sc), "-o", s(&dir.0.join("o.exr"))],
        &format!(
            "error: {}:4: bsdf 'conductor': 'eta' = [-1.0, -1.0, -1.0] must not be negative",
            s(&sc)
        ),
    );
}

/// A ReSTIR flag with an estimator that does not use it is an error naming the estimators that
/// do, not a warning before rendering anyway.
#[test]
fn flags_the_estimator_does_not_use() {
    let dir = temp_dir("flags");
    let out = dir.0.join("o.exr");
    let c = cornell();
    fails_with(
        &["render", s(&c), "-o", s(&out), "--mis", "foo"],
        "error: --mis is not an option of the integrator 'path' (used by: restir-di, restir-pt)",
    );
    fails_with(
        &["render", s(&c), "-o", s(&out), "--temporal"],
        "error: --temporal is not an option of the integrator 'path' (used by: restir-di, restir-pt)",
    );
    fails_with(
        &[
            "render",
            s(&c),
            "-o",
            s(&out),
            "--integrator",
            "restir-di",
            "--shift",
            "replay",
        ],
        "error: --shift is not an option of the integrator 'restir-di' (used by: restir-pt)",
    );
    fails_with(
        &["render", s(&c), "-o", s(&out), "--learn", "on"],
        "error: --learn is not an option of the integrator 'path' (used by: restir-di)",
    );
    // The path tracer's next-event estimation takes three of ReSTIR DI's light samplers.
    fails_with(
        &["render", s(&c), "-o", s(&out), "--light-sampler", "tiles"],
        "error: light_sampler = 'tiles': expected power, bvh or auto",
    );
    assert!(!out.exists());
}

#[test]
fn thread_count_is_bounded() {
    let dir = temp_dir("threads");
    let out = dir.0.join("o.exr");
    for n in ["257", "1000"] {
        fails_with(
            &["render", s(&cornell()), "-o", s(&out), "--threads", n],
            &format!("error: --threads {n}: expected 1 to 256 (0 or no flag = one per core)"),
        );
    }
    // 0 means one thread per core.
    let o = restir(&[
        "render",
        s(&cornell()),
        "-o",
        s(&out),
        "--threads",
        "0",
        "--spp",
        "1",
        "--width",
        "8",
        "--height",
        "8",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// clap's message is kept whole: the missing argument, the "similar argument" tip, the usage.
#[test]
fn clap_messages_are_whole() {
    let out = restir(&["render"]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        "error: the following required arguments were not provided:\n  <SCENE>\n\n\
         Usage: restir render <SCENE>\n\nFor more information, try '--help'.\n"
    );
    let out = restir(&["render", s(&cornell()), "--thread", "2"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.starts_with("error: unexpected argument '--thread' found\n"),
        "{stderr}"
    );
    assert!(
        stderr.contains("tip: a similar argument exists: '--threads'"),
        "{stderr}"
    );
}

/// The output is checked before the first pass.
#[test]
fn output_path_is_checked_before_rendering() {
    fails_with(
        &["render", s(&cornell()), "-o", "/proc/nope.png"],
        "error: /proc/nope.png: cannot create a file beside it: No such file or directory (os error 2)",
    );
    let dir = temp_dir("output");
    let stats = dir.0.join("no-such-dir/stats.json");
    fails_with(
        &[
            "render",
            s(&cornell()),
            "-o",
            s(&dir.0.join("o.exr")),
            "--stats",
            s(&stats),
        ],
        &format!(
            "error: {}: cannot create a file beside it: No such file or directory (os error 2)",
            s(&stats)
        ),
    );
}

/// A film whose memory need exceeds the limit is refused before anything is allocated.
#[test]
fn huge_films_are_refused_before_allocating() {
    let dir = temp_dir("memory");
    let out = dir.0.join("o.exr");
    let c = cornell();
    let big = ["--width", "16384", "--height", "16384"];
    let mut args = vec!["render", s(&c), "-o", s(&out)];
    args.extend(big);
    fails_with(
        &args,
        "error: a 16384×16384 film with path needs about 12.0 GiB (48 bytes per pixel), more \
         than the limit of 8 GiB: render smaller or raise --max-memory",
    );
    let mut args = vec!["render", s(&c), "-o", s(&out), "--max-memory", "0.001"];
    args.extend(["--width", "256", "--height", "256"]);
    fails_with(
        &args,
        "error: a 256×256 film with path needs about 0.0 GiB (48 bytes per pixel), more than the \
         limit of 0.001 GiB: render smaller or raise --max-memory",
    );
    fails_with(
        &["render", s(&c), "-o", s(&out), "--max-memory", "0"],
        "error: --max-memory 0: expected a positive number of GiB",
    );
}

/// ReSTIR's table of shifts holds a window of rows, so a 4K film's estimate counts the window,
/// not the film: ReSTIR DI at 3840×2160 with twelve neighbours is estimated at well under 8 GiB
/// (with the whole film's table, 1121 bytes per pixel, 8.7 GiB, it was refused at the default
/// limit), and on more threads the window and the estimate grow.
#[test]
fn restir_tables_count_their_window_of_rows() {
    let dir = temp_dir("memory-window");
    let out = dir.0.join("o.exr");
    let c = cornell();
    let per_pixel = |threads: &str| -> u64 {
        let o = restir(&[
            "render",
            s(&c),
            "-o",
            s(&out),
            "--integrator",
            "restir-di",
            "--width",
            "3840",
            "--height",
            "2160",
            "--threads",
            threads,
            "--max-memory",
            "0.01",
        ]);
        assert!(!o.status.success());
        let err = String::from_utf8_lossy(&o.stderr);
        let n = err
            .split(" GiB (")
            .nth(1)
            .and_then(|t| t.split(' ').next())
            .and_then(|n| n.parse().ok());
        n.unwrap_or_else(|| panic!("no bytes per pixel in: {err}"))
    };
    let (two, many) = (per_pixel("2"), per_pixel("64"));
    assert!(two < 800, "{two} bytes per pixel at 3840×2160 on 2 threads");
    assert!(
        (two as f64 * 3840.0 * 2160.0) / ((1u64 << 30) as f64) < 6.0,
        "{two} bytes per pixel"
    );
    assert!(many > two, "64 threads: {many}, 2 threads: {two}");
}

/// A splatting film's two buffers (a pass's estimates and their rows gathered, 48 bytes per
/// pixel) count against `--max-memory`: the Cornell box with Mitsuba's default Gaussian filter
/// needs 96 bytes per pixel where the box filter needs 48.
#[test]
fn a_splatting_film_counts_against_the_memory_limit() {
    let dir = temp_dir("memory-splat");
    let text = std::fs::read_to_string(cornell()).unwrap();
    let gaussian = dir.0.join("cornell-gaussian.xml");
    // The shipped scene has no file references, so a copy elsewhere loads the same.
    assert!(text.contains(r#"<rfilter type="box"/>"#));
    let text = text.replace(r#"<rfilter type="box"/>"#, r#"<rfilter type="gaussian"/>"#);
    std::fs::write(&gaussian, text).unwrap();
    let out = dir.0.join("o.exr");
    let mut args = vec![
        "render",
        s(&gaussian),
        "-o",
        s(&out),
        "--max-memory",
        "0.001",
    ];
    args.extend(["--width", "256", "--height", "256"]);
    fails_with(
        &args,
        "error: a 256×256 film with path needs about 0.0 GiB (96 bytes per pixel), more than the \
         limit of 0.001 GiB: render smaller or raise --max-memory",
    );
}
