//! `restir render SCENE --frames A..B`: one image per frame through the atomic writer, the
//! animated PNG preview and the statistics, and every bad flag refused before rendering with
//! exit code 1 and exactly the message checked here.

mod common;
use common::{RESTIR, fails_with, restir, s};

use restir_testkit::TempDir;
use std::path::PathBuf;
use std::process::Command;

fn temp_dir(tag: &str) -> TempDir {
    TempDir::new("frames", tag)
}

const ANIMATED: &str = r#"(
    camera: (fov: 40, to_world: [LookAt(origin: (0, 0, 4), target: (0, 0, 0), up: (0, 1, 0))]),
    film: (width: 8, height: 8, filter: Box),
    shapes: [
        (geometry: Rectangle),
        (id: Some("lamp"), geometry: Sphere(center: (0, 0, 1), radius: 0.2), emission: Some((5, 5, 5))),
    ],
    animation: Some((
        fps: 2,
        camera: Some((keys: [
            (time: 0, position: (0, 0, 4), target: (0, 0, 0)),
            (time: 1, position: (1, 0, 4), target: (0, 0, 0)),
        ])),
        shapes: [(id: "lamp", motion: Some([(time: 0), (time: 1, translate: (0.5, 0, 0))]))],
    )),
)"#;

fn animated(dir: &TempDir) -> PathBuf {
    let p = dir.0.join("anim.ron");
    std::fs::write(&p, ANIMATED).unwrap();
    p
}

fn static_scene(dir: &TempDir) -> PathBuf {
    let p = dir.0.join("still.ron");
    let text = ANIMATED.split("    animation:").next().unwrap().to_string() + ")";
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn frames_are_written_one_file_each_with_a_preview_and_stats() {
    let dir = temp_dir("ok");
    let scene = animated(&dir);
    let out = dir.0.join("out/seq.exr");
    let preview = dir.0.join("seq.png");
    let stats = dir.0.join("stats.json");
    let run = restir(&[
        "render",
        s(&scene),
        "--frames",
        "0..2",
        "--spp",
        "2",
        "--integrator",
        "restir-di",
        "-o",
        s(&out),
        "--preview",
        s(&preview),
        "--stats",
        s(&stats),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let mut frames = Vec::new();
    for f in 0..3 {
        let p = dir.0.join(format!("out/seq_{f:04}.exr"));
        frames.push(restir_image::Image::read_exr(&p).unwrap());
    }
    assert!(!dir.0.join("out/seq.exr").exists());
    // The camera and the lamp move: consecutive frames differ.
    assert_ne!(frames[0].pixels, frames[1].pixels);
    // An animated PNG: its acTL chunk says 3 frames, looping.
    let bytes = std::fs::read(&preview).unwrap();
    let at = bytes
        .windows(4)
        .position(|w| w == b"acTL")
        .expect("an acTL chunk");
    assert_eq!(&bytes[at + 4..at + 8], &3u32.to_be_bytes());
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    let fr = json["frames"].as_array().unwrap();
    assert_eq!(fr.len(), 3);
    assert_eq!(fr[1]["frame"], 1);
    assert_eq!(fr[1]["time"], 0.5);
    assert_eq!(fr[2]["passes"], 2);
    assert!(json["rebuilt"].as_str().unwrap().contains("BVH"));
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(stdout.contains("3 frames (0 to 2) at 2 fps"), "{stdout}");
}

/// `--preview NAME.mp4` hands the frames to the `ffmpeg` on `PATH` as raw 8-bit RGB at the
/// frame rate. A stand-in `ffmpeg` (a shell script) writes its arguments and the number of
/// bytes it read into the file it is told to write, so this checks our side of the pipe; and
/// without an `ffmpeg` on `PATH` a video preview is refused before anything renders.
#[cfg(unix)]
#[test]
fn video_previews_go_through_ffmpeg_on_path() {
    use std::os::unix::fs::PermissionsExt;
    let dir = temp_dir("video");
    let scene = animated(&dir);
    let bin = dir.0.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let fake = bin.join("ffmpeg");
    std::fs::write(
        &fake,
        "#!/bin/sh\nfor a in \"$@\"; do out=\"$a\"; done\nprintf '%s\\n' \"$@\" > \"$out\"\nwc -c | tr -d ' ' >> \"$out\"\n",
    )
    .unwrap();
    std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    let out = dir.0.join("seq.exr");
    let video = dir.0.join("seq.mp4");
    let args = [
        "render",
        s(&scene),
        "--frames",
        "0..1",
        "--spp",
        "1",
        "-o",
        s(&out),
        "--preview",
        s(&video),
    ];
    // The stand-in first, then the system's tools (its `wc`).
    let path = std::env::join_paths(std::iter::once(bin.clone()).chain(std::env::split_paths(
        &std::env::var_os("PATH").unwrap_or_default(),
    )))
    .unwrap();
    let run = Command::new(RESTIR)
        .args(args)
        .env("PATH", &path)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let said = std::fs::read_to_string(&video).unwrap();
    let lines: Vec<&str> = said.lines().collect();
    let after = |flag: &str| lines[lines.iter().position(|l| *l == flag).unwrap() + 1];
    assert_eq!(after("-pix_fmt"), "rgb24");
    assert_eq!(after("-s"), "8x8");
    assert_eq!(after("-framerate"), "2");
    assert_eq!(lines.iter().filter(|l| **l == "-f").count(), 2);
    assert_eq!(*lines.iter().rev().nth(2).unwrap(), "mp4", "{said}");
    // Two 8x8 frames of 3 bytes a pixel.
    assert_eq!(*lines.last().unwrap(), (2 * 8 * 8 * 3).to_string());
    let left: Vec<_> = std::fs::read_dir(&dir.0)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp-"))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");

    // No ffmpeg: refused before rendering.
    let empty = dir.0.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let gif = dir.0.join("none.gif");
    let mut args = args;
    args[9] = s(&gif);
    let run = Command::new(RESTIR)
        .args(args)
        .env("PATH", &empty)
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&run.stderr),
        format!(
            "error: {}: a video preview needs ffmpeg on PATH, and there is none (install it, or write an animated PNG with --preview NAME.png)\n",
            s(&gif)
        )
    );
    assert!(!gif.exists());
}

/// With `--temporal`, ReSTIR DI's first pass of a frame reuses the previous frame (the frame
/// differs from the one rendered without it, same seed; the first frame, with no history,
/// does not); ReSTIR PT starts every frame afresh and renders too.
#[test]
fn temporal_reuse_crosses_frames() {
    let dir = temp_dir("temporal");
    let scene = animated(&dir);
    let render = |tag: &str, extra: &[&str]| -> Vec<restir_image::Image> {
        let out = dir.0.join(format!("{tag}/f.exr"));
        let stats = dir.0.join(format!("{tag}.json"));
        let mut args = vec![
            "render",
            s(&scene),
            "--frames",
            "0..2",
            "--spp",
            "1",
            "-o",
            s(&out),
            "--stats",
            s(&stats),
        ];
        args.extend_from_slice(extra);
        let run = restir(&args);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
        let settings = json["integrator_settings"].as_str().unwrap();
        assert_eq!(
            settings.contains("temporal=true"),
            extra.contains(&"--temporal") && !extra.contains(&"false"),
            "{settings}"
        );
        (0..3)
            .map(|f| {
                let p = dir.0.join(format!("{tag}/f_{f:04}.exr"));
                restir_image::Image::read_exr(&p).unwrap()
            })
            .collect()
    };
    let di = ["--integrator", "restir-di"];
    let spatial = render("di", &di);
    let temporal = render("di-t", &[&di[..], &["--temporal"]].concat());
    assert_eq!(spatial[0].pixels, temporal[0].pixels);
    assert_ne!(spatial[1].pixels, temporal[1].pixels);
    assert_ne!(spatial[2].pixels, temporal[2].pixels);
    // `--temporal false` is spatial-only.
    let off = render("di-f", &[&di[..], &["--temporal", "false"]].concat());
    assert_eq!(spatial[2].pixels, off[2].pixels);
    for img in render("pt-t", &["--integrator", "restir-pt", "--temporal"]) {
        assert!(img.pixels.iter().all(|p| p.is_finite()));
    }
}

#[test]
fn bad_frame_flags_are_refused_before_rendering() {
    let dir = temp_dir("bad");
    let scene = animated(&dir);
    let still = static_scene(&dir);
    let out = dir.0.join("o.exr");
    let o = s(&out);
    let range = "error: --frames 5..2: expected A..B, the first and last frame numbers with A <= B (e.g. 1..48)";
    fails_with(&["render", s(&scene), "-o", o, "--frames", "5..2"], range);
    fails_with(
        &["render", s(&scene), "-o", o, "--frames", "three"],
        "error: --frames three: expected A..B, the first and last frame numbers with A <= B (e.g. 1..48)",
    );
    fails_with(
        &["render", s(&scene), "-o", o, "--frames", "1..-4"],
        "error: --frames 1..-4: expected A..B, the first and last frame numbers with A <= B (e.g. 1..48)",
    );
    fails_with(
        &["render", s(&still), "-o", o, "--frames", "1..3"],
        &format!(
            "error: {}: --frames: the scene has no animation (give it an `animation` section, a sidecar {}, or --animation FILE)",
            s(&still),
            s(&dir.0.join("still.anim.ron"))
        ),
    );
    fails_with(
        &[
            "render",
            s(&scene),
            "-o",
            o,
            "--frames",
            "1..3",
            "--fps",
            "0",
        ],
        "error: --fps 0: expected a positive number of frames per second (at most 1e6)",
    );
    fails_with(
        &["render", s(&scene), "-o", o, "--fps", "24"],
        "error: --fps 24: needs --frames A..B",
    );
    fails_with(
        &["render", s(&scene), "-o", o, "--preview", "p.png"],
        "error: --preview p.png: needs --frames A..B",
    );
    fails_with(
        &[
            "render",
            s(&scene),
            "-o",
            o,
            "--frames",
            "1..3",
            "--preview",
            "p.jpg",
        ],
        "error: p.jpg: --preview must end in one of .png, .gif, .mp4, .webm, .mkv, .mov (.png: an animated PNG; the others: a video through ffmpeg)",
    );
    fails_with(
        &[
            "render",
            s(&scene),
            "-o",
            o,
            "--frames",
            "1..3",
            "--crop",
            "0,0,4,4",
        ],
        "error: --frames cannot be combined with --chain or --crop",
    );
    let missing = dir.0.join("missing.anim.ron");
    let out = restir(&[
        "render",
        s(&still),
        "-o",
        o,
        "--frames",
        "1..3",
        "--animation",
        s(&missing),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr.starts_with(&format!("error: {}: cannot read animation: ", s(&missing))),
        "{stderr}"
    );
    fails_with(
        &["render", s(&still), "-o", o, "--animation", s(&missing)],
        &format!("error: --animation {}: needs --frames A..B", s(&missing)),
    );
    // A second animation beside the scene's own.
    let side = dir.0.join("side.anim.ron");
    std::fs::write(&side, "(fps: 3)").unwrap();
    fails_with(
        &[
            "render",
            s(&scene),
            "-o",
            o,
            "--frames",
            "0..1",
            "--animation",
            s(&side),
        ],
        &format!(
            "error: {}: the scene already has an animation (from {}): give one animation",
            s(&side),
            s(&scene)
        ),
    );
    assert!(!out_exists(&dir), "nothing was rendered");
}

fn out_exists(dir: &TempDir) -> bool {
    std::fs::read_dir(&dir.0)
        .unwrap()
        .any(|e| e.unwrap().file_name().to_string_lossy().starts_with("o"))
}

/// A stand-in `ffmpeg` in a fresh `bin` directory with `body`, executable or not, and a `PATH`
/// that finds it first (then the system's tools).
#[cfg(unix)]
fn fake_ffmpeg(dir: &TempDir, body: &str, mode: u32) -> std::ffi::OsString {
    use std::os::unix::fs::PermissionsExt;
    let bin = dir.0.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let fake = bin.join("ffmpeg");
    std::fs::write(&fake, format!("#!/bin/sh\n{body}\n")).unwrap();
    std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(mode)).unwrap();
    std::env::join_paths(std::iter::once(bin).chain(std::env::split_paths(
        &std::env::var_os("PATH").unwrap_or_default(),
    )))
    .unwrap()
}

/// An ffmpeg that writes a megabyte to its standard error before reading its input does not
/// deadlock the render (its stderr is drained while frames are written); one that is not
/// executable is refused before rendering.
#[cfg(unix)]
#[test]
fn ffmpeg_stderr_is_drained_and_a_non_executable_one_refused() {
    let dir = temp_dir("ffmpeg-flood");
    let scene = animated(&dir);
    let path = fake_ffmpeg(
        &dir,
        "for a in \"$@\"; do out=\"$a\"; done\nhead -c 1000000 /dev/zero >&2\ncat > /dev/null\necho ok > \"$out\"",
        0o755,
    );
    let video = dir.0.join("seq.mp4");
    let out = dir.0.join("seq.exr");
    // Two 128² frames (96 KiB) are more than a pipe holds.
    let mut child = Command::new(RESTIR)
        .args([
            "render",
            s(&scene),
            "--frames",
            "0..1",
            "--spp",
            "1",
            "--quiet",
        ])
        .args(["--width", "128", "--height", "128", "-o", s(&out)])
        .args(["--preview", s(&video)])
        .env("PATH", &path)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > std::time::Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("the render deadlocked on ffmpeg's stderr");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let o = child.wait_with_output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read_to_string(&video).unwrap(), "ok\n");

    let dir = temp_dir("ffmpeg-noexec");
    let scene = animated(&dir);
    let path = fake_ffmpeg(&dir, "exit 0", 0o644);
    let video = dir.0.join("seq.mp4");
    let o = Command::new(RESTIR)
        .args(["render", s(&scene), "--frames", "0..1", "--spp", "1"])
        .args(["-o", s(&dir.0.join("seq.exr")), "--preview", s(&video)])
        .env("PATH", &path)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("/bin/ffmpeg is not executable"), "{stderr}");
    assert!(
        !dir.0.join("seq_0000.exr").exists(),
        "refused before rendering"
    );
}

/// An ffmpeg that stops reading its input, or reads it all and never exits, does not hang the
/// render: after `RESTIR_FFMPEG_TIMEOUT` seconds it is stopped and the preview is an error
/// naming it (the frames themselves are written).
#[cfg(unix)]
#[test]
fn a_stalled_ffmpeg_is_stopped_and_reported() {
    for (tag, body, expected) in [
        (
            "ffmpeg-stall",
            "exec sleep 600",
            "stopped reading its input for 2 s",
        ),
        (
            "ffmpeg-no-exit",
            "cat > /dev/null\nexec sleep 600",
            "did not exit within 2 s of the end of its input",
        ),
    ] {
        let dir = temp_dir(tag);
        let scene = animated(&dir);
        let path = fake_ffmpeg(&dir, body, 0o755);
        let video = dir.0.join("seq.mp4");
        let out = dir.0.join("seq.exr");
        // Two 128² frames (96 KiB) are more than a pipe holds.
        let mut child = Command::new(RESTIR)
            .args(["render", s(&scene), "--frames", "0..1", "--spp", "1"])
            .args([
                "--quiet",
                "--width",
                "128",
                "--height",
                "128",
                "-o",
                s(&out),
            ])
            .args(["--preview", s(&video)])
            .env("PATH", &path)
            .env("RESTIR_FFMPEG_TIMEOUT", "2")
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let start = std::time::Instant::now();
        while child.try_wait().unwrap().is_none() {
            if start.elapsed() > std::time::Duration::from_secs(60) {
                child.kill().unwrap();
                panic!("{tag}: the render hung on ffmpeg");
            }
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
        let o = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{tag}: {stderr}");
        assert!(stderr.contains(expected), "{tag}: {stderr}");
        assert!(stderr.contains("/bin/ffmpeg"), "{tag}: {stderr}");
        assert!(!video.exists(), "{tag}: no preview");
        assert!(
            dir.0.join("seq_0001.exr").exists(),
            "{tag}: the frames are written"
        );
    }
}

/// `--frames 0..4294967295` (2^32 frames) is an error, not an overflow.
#[test]
fn a_frame_count_beyond_u32_is_an_error() {
    let dir = temp_dir("frames-overflow");
    let scene = animated(&dir);
    let o = dir.0.join("o.exr");
    fails_with(
        &[
            "render",
            s(&scene),
            "-o",
            s(&o),
            "--frames",
            "0..4294967295",
        ],
        "error: --frames 0..4294967295: 4294967296 frames, more than the most a sequence may have (4294967295)",
    );
}
