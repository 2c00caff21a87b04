//! The interactive report in a real browser: headless Chromium loads the `report.html` that
//! `write_outputs` writes for a small synthetic bench result, and the `compare` page; the page
//! writes its own state into `#status` (images decoded, viewer and plot canvases non-blank, errors
//! caught by `window.onerror`), read back with `--dump-dom`, and a screenshot must not be blank.
//! A page with corrupted image data must report the error (the check is not vacuous).
//!
//! Needs Chromium (`apt-get install chromium`, or `RESTIR_CHROMIUM=/path/to/chrome`): the tests
//! are ignored by a plain `cargo test`; `.ci/run` installs Chromium and runs them with
//! `--ignored`, where a missing browser is a failure with a clear message.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use glam::Vec3;
use restir_evaluation::suite::{Clock, IntegratorConfig, Suite, SuiteScene};
use restir_evaluation::{
    BenchResults, Machine, ReferenceInfo, RunRecord, SceneImages, Strip, html, metrics,
    write_outputs,
};
use restir_image::{Image, IntegerEncoding};
use restir_testkit::TempDir;

const IGNORE_REASON: &str = "needs headless Chromium: run with --ignored (.ci/run installs it)";

/// The browser: `RESTIR_CHROMIUM`, else the first of the usual names on `PATH`.
fn chromium() -> PathBuf {
    if let Some(p) = std::env::var_os("RESTIR_CHROMIUM") {
        return PathBuf::from(p);
    }
    let path = std::env::var_os("PATH").unwrap_or_default();
    for name in ["chromium", "chromium-browser", "google-chrome", "chrome"] {
        for dir in std::env::split_paths(&path) {
            let p = dir.join(name);
            if p.is_file() {
                return p;
            }
        }
    }
    panic!(
        "no Chromium found on PATH (tried chromium, chromium-browser, google-chrome, chrome): \
         install it (`apt-get install chromium`) or set RESTIR_CHROMIUM ({IGNORE_REASON})"
    );
}
fn temp_dir(tag: &str) -> TempDir {
    TempDir::new("html", tag)
}

/// Runs headless Chromium on `page` with `extra` arguments (a fresh profile each time), killing
/// it after two minutes; returns its stdout (through a file: the DOM outgrows a pipe's buffer).
fn run_chromium(page: &Path, profile: &Path, extra: &[String]) -> String {
    run_chromium_at(page, "", profile, extra)
}

/// [`run_chromium`] on `page` with a `#fragment` (a view given in the address).
fn run_chromium_at(page: &Path, fragment: &str, profile: &Path, extra: &[String]) -> String {
    let url = format!(
        "file://{}{fragment}",
        page.canonicalize().unwrap().display()
    );
    let stdout_path = profile.with_extension("stdout");
    let stdout = std::fs::File::create(&stdout_path).unwrap();
    let mut child = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--virtual-time-budget=20000",
            &format!("--user-data-dir={}", profile.display()),
        ])
        .args(extra)
        .arg(&url)
        .stdout(stdout)
        .stderr(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start Chromium: {e} ({IGNORE_REASON})"));
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("Chromium did not finish within 120 s on {url}");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    String::from_utf8_lossy(&std::fs::read(&stdout_path).unwrap()).into_owned()
}

/// The page's `#status`: its `data-state` and the JSON it holds; and the DOM.
fn page_status(page: &Path, profile: &Path) -> (String, serde_json::Value, String) {
    page_status_at(page, "", profile)
}

/// [`page_status`] with a `#fragment`.
fn page_status_at(
    page: &Path,
    fragment: &str,
    profile: &Path,
) -> (String, serde_json::Value, String) {
    let dom = run_chromium_at(page, fragment, profile, &["--dump-dom".into()]);
    let start = dom.find("<pre id=\"status\"").unwrap_or_else(|| {
        panic!(
            "no #status in the page's DOM:\n{}",
            &dom[..dom.len().min(2000)]
        )
    });
    let rest = &dom[start..];
    let state = rest
        .split("data-state=\"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .unwrap()
        .to_string();
    let text = &rest[rest.find('>').unwrap() + 1..rest.find("</pre>").unwrap()];
    let text = text
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&");
    let json =
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("#status is not JSON ({e}): {text}"));
    (state, json, dom)
}

/// The texts of the `<td>` cells of the page's metrics table.
fn metrics_cells(dom: &str) -> Vec<Vec<String>> {
    let start = dom.find("<table id=\"metrics\"").expect("metrics table");
    let table = &dom[start..start + dom[start..].find("</table>").unwrap()];
    table
        .split("<tr")
        .skip(1)
        .map(|row| {
            row.split("<td>")
                .skip(1)
                .map(|c| c.split("</td>").next().unwrap().to_string())
                .collect::<Vec<_>>()
        })
        .filter(|r| !r.is_empty())
        .collect()
}

/// A smooth test pattern with a bright spot.
fn pattern(w: u32, h: u32, phase: f32) -> Image {
    let mut img = Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            let (u, v) = (x as f32 / w as f32, y as f32 / h as f32);
            let spot = (-((u - 0.6).powi(2) + (v - 0.4).powi(2)) * 40.0).exp() * 4.0;
            img.pixels[(y * w + x) as usize] = Vec3::new(
                0.2 + 0.6 * u + spot,
                0.1 + 0.5 * (6.0 * v + phase).sin().abs(),
                0.3 * (1.0 - u) + 0.2 * v,
            );
        }
    }
    img
}

/// `img` with deterministic noise of relative amplitude `a`.
fn noisy(img: &Image, a: f32, seed: u32) -> Image {
    let mut s = seed.wrapping_mul(747_796_405).wrapping_add(1);
    let mut out = img.clone();
    for p in &mut out.pixels {
        for c in 0..3 {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let u = (s >> 8) as f32 / (1u32 << 24) as f32;
            p[c] *= 1.0 + a * (2.0 * u - 1.0) * 2.0;
        }
    }
    out
}

/// A bench result of two scenes × two configurations × two budgets × two seeds, made up from
/// synthetic images (no rendering).
fn synthetic_results() -> BenchResults {
    let (w, h) = (48, 32);
    let configs = ["path", "restir-di"];
    let budgets = [0.5, 1.0];
    let mut records = Vec::new();
    let mut references = Vec::new();
    let mut strips = Vec::new();
    let mut images = Vec::new();
    for (si, scene) in ["room", "lamps"].iter().enumerate() {
        let reference = pattern(w, h, si as f32);
        let mut renders = Vec::new();
        for (ci, label) in configs.iter().enumerate() {
            for (bi, &budget) in budgets.iter().enumerate() {
                for seed in 0..2u64 {
                    let amp = 0.4 / (1.0 + ci as f32) / (1.0 + bi as f32);
                    let img = noisy(
                        &reference,
                        amp,
                        (si * 100 + ci * 10 + bi * 2) as u32 + seed as u32,
                    );
                    let m = metrics::evaluate(&img, &reference).unwrap();
                    records.push(RunRecord {
                        scene: scene.to_string(),
                        label: label.to_string(),
                        describe: label.to_string(),
                        width: w,
                        height: h,
                        budget,
                        seed,
                        seconds: budget * 1.05,
                        cpu_seconds: budget * 1.05,
                        passes: 10 * (bi as u32 + 1),
                        rays: 1000,
                        relmse: m.relmse,
                        mse: m.mse,
                        mape: m.mape,
                        flip: m.flip,
                        mean_ratio: m.mean_ratio,
                        top1_share: m.top1_share,
                        nonfinite: m.nonfinite,
                        rss_before_mib: 10.0,
                        peak_rss_mib: 12.0,
                        frame: None,
                        flicker: f64::NAN,
                    });
                    if seed == 0 {
                        renders.push((label.to_string(), budget, img));
                    }
                }
            }
        }
        references.push(ReferenceInfo {
            scene: scene.to_string(),
            path: PathBuf::from(format!("{scene}.exr")),
            spp: Some(64),
            noise_relmse: Some(1e-4),
            reused: true,
            seconds: 0.0,
        });
        strips.push(Strip {
            scene: scene.to_string(),
            crop: (0, 0, 8, 8),
            budget: 0.5,
            crops: vec![Image::new(8, 8)],
            labels: vec!["reference".into()],
        });
        images.push(SceneImages {
            scene: scene.to_string(),
            reference,
            renders,
        });
    }
    let scene_entry = |path: &str| SuiteScene {
        path: path.into(),
        name: None,
        width: None,
        height: None,
        max_depth: None,
        reference: None,
        reference_spp: None,
        crop: None,
        integrators: None,
        frames: None,
        fps: None,
    };
    BenchResults {
        suite: Suite {
            scenes: vec![scene_entry("room.xml"), scene_entry("lamps.xml")],
            families: Vec::new(),
            integrators: configs
                .iter()
                .map(|l| IntegratorConfig {
                    label: l.to_string(),
                    integrator: l.to_string(),
                    params: Vec::new(),
                })
                .collect(),
            budgets: budgets.to_vec(),
            seeds: 2,
            reference_spp: 64,
            strip_budget: None,
            clock: Clock::Wall,
        },
        records,
        references,
        strips,
        images,
        machine: Machine {
            cpu: "test".into(),
            cores: 1,
            threads: 1,
            load_start: "0".into(),
            load_end: "0".into(),
            peak_reset: false,
        },
        command_line: "restir bench synthetic".into(),
        started_unix: 0,
        wall_seconds: 1.0,
    }
}

fn assert_ready(page: &Path, profile: &Path, images: u64, plot: bool) {
    let (state, status, _) = page_status(page, profile);
    assert_eq!(state, "ready", "{status}");
    assert_eq!(status["errors"], serde_json::json!([]), "{status}");
    assert_eq!(status["images"], images, "{status}");
    assert_eq!(status["decoded"], images, "{status}");
    assert_eq!(status["thumbs"], images, "{status}");
    assert_eq!(status["viewerNonblank"], true, "{status}");
    assert_eq!(status["inspectorLines"], 3, "{status}");
    let want_plot = if plot {
        serde_json::json!(true)
    } else {
        serde_json::Value::Null
    };
    assert_eq!(status["plotNonblank"], want_plot, "{status}");
}

/// Distinct colours of a screenshot.
fn distinct_colours(png: &Path) -> usize {
    let img = Image::read(png, IntegerEncoding::Raw).unwrap();
    let mut seen: Vec<[u8; 3]> = img
        .pixels
        .iter()
        .map(|p| {
            [
                (p.x * 255.0) as u8,
                (p.y * 255.0) as u8,
                (p.z * 255.0) as u8,
            ]
        })
        .collect();
    seen.sort_unstable();
    seen.dedup();
    seen.len()
}

#[test]
#[ignore = "needs headless Chromium: run with --ignored (.ci/run installs it)"]
fn bench_report_draws_in_chromium() {
    let dir = temp_dir("bench");
    let out = dir.0.join("out");
    let results = synthetic_results();
    write_outputs(&results, &out).unwrap();
    let page = out.join("report.html");
    if let Some(keep) = std::env::var_os("RESTIR_KEEP_PAGE") {
        std::fs::copy(&page, keep).unwrap();
    }
    let size = std::fs::metadata(&page).unwrap().len();
    assert!(size < 2_000_000, "report.html is {size} bytes");
    // Two scenes: the page reports the images of every scene (reference + 4 renders each) as
    // decoded, and the thumbnails of the scene shown.
    let (state, status, dom) = page_status(&page, &dir.0.join("profile-dom"));
    assert_eq!(state, "ready", "{status}");
    assert_eq!(status["errors"], serde_json::json!([]), "{status}");
    assert_eq!(status["images"], 10, "{status}");
    assert_eq!(status["decoded"], 10, "{status}");
    assert_eq!(status["thumbs"], 5, "{status}");
    assert_eq!(status["viewerNonblank"], true, "{status}");
    assert_eq!(status["plotNonblank"], true, "{status}");
    assert_eq!(status["inspectorLines"], 3, "{status}");
    // One row per render of the first scene; budget, time, passes and the metrics are numbers.
    let rows = metrics_cells(&dom);
    assert_eq!(rows.len(), 4, "{rows:?}");
    let first = results.records.iter().find(|r| r.scene == "room").unwrap();
    for row in &rows {
        assert_eq!(row.len(), 8, "{row:?}");
        for cell in &row[1..] {
            assert!(cell.parse::<f64>().is_ok(), "{row:?}");
        }
    }
    assert_eq!(rows[0][0], first.label);
    let flip: f64 = rows[0][6].parse().unwrap();
    assert!(
        (flip / first.flip - 1.0).abs() < 1e-3,
        "{} {}",
        rows[0][6],
        first.flip
    );

    let shot = dir.0.join("shot.png");
    run_chromium(
        &page,
        &dir.0.join("profile-shot"),
        &[
            format!("--screenshot={}", shot.display()),
            "--window-size=1200,2200".into(),
        ],
    );
    let colours = distinct_colours(&shot);
    assert!(colours > 500, "screenshot has only {colours} colours");
    if let Some(keep) = std::env::var_os("RESTIR_KEEP_SCREENSHOT") {
        std::fs::copy(&shot, keep).unwrap();
    }
}

#[test]
#[ignore = "needs headless Chromium: run with --ignored (.ci/run installs it)"]
fn compare_page_draws_in_chromium() {
    let dir = temp_dir("compare");
    let reference = pattern(40, 40, 0.0);
    let mut test = noisy(&reference, 0.2, 7);
    test.pixels[5] = Vec3::new(f32::NAN, 0.0, 0.0);
    let html = html::compare_page("test.exr", &test, "ref.exr", &reference).unwrap();
    let page = dir.0.join("compare.html");
    std::fs::write(&page, &html).unwrap();
    assert_ready(&page, &dir.0.join("profile"), 2, false);
    // A view given in the address: the FLIP map, zoomed, the inspector pinned on a pixel.
    let (state, status, dom) = page_status_at(
        &page,
        "#mode=flip&a=1&b=0&zoom=8&px=12,20",
        &dir.0.join("profile-hash"),
    );
    assert_eq!(state, "ready", "{status}");
    assert_eq!(status["viewerNonblank"], true, "{status}");
    assert!(
        dom.contains("pixel (12, 20)"),
        "the inspector is not pinned"
    );
    assert!(
        dom.contains("FLIP 0."),
        "the inspector lacks the FLIP value"
    );
    assert_eq!(status["mode"], "flip", "{status}");
    assert_eq!(status["scale"], 8.0, "{status}");
}

/// Negative control: corrupted image data must show up as an error in the status, not "ready".
#[test]
#[ignore = "needs headless Chromium: run with --ignored (.ci/run installs it)"]
fn corrupted_page_reports_an_error() {
    let dir = temp_dir("corrupt");
    let reference = pattern(16, 16, 0.0);
    let html = html::compare_page("a.exr", &reference, "b.exr", &reference).unwrap();
    let at = html.find("\"hdr_f16\":\"").unwrap() + "\"hdr_f16\":\"".len();
    let broken = format!("{}AAAA{}", &html[..at], &html[at + 8..]);
    let page = dir.0.join("broken.html");
    std::fs::write(&page, broken).unwrap();
    let (state, status, dom) = page_status(&page, &dir.0.join("profile"));
    assert_eq!(state, "error", "{status}");
    assert_ne!(status["errors"], serde_json::json!([]), "{status}");
    // The reader is told too, not only the test.
    assert!(dom.contains("This page failed to draw"), "no visible error");
}
