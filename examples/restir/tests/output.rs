//! Outputs that are never half-written and a command that never panics on its streams
//! (and Ctrl-C): a write that fails (here a file-size limit, as a
//! full disk would) is exit code 1 with the file named and the old file kept; a closed stdout
//! or stderr is no panic; an interrupt writes what was rendered and exits 130, a second one
//! aborts at once without writing.

mod common;
use common::{RESTIR, cornell, s};

use restir_testkit::TempDir;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn temp_dir(tag: &str) -> TempDir {
    TempDir::new("output", tag)
}

/// The names of the files in `dir`.
fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A write that fails part-way (the file-size limit `ulimit -f` with SIGXFSZ ignored, so the
/// write returns EFBIG as on a full disk) is exit code 1 naming the file; the previous image
/// stays whole and no temporary file is left. Both formats.
#[test]
fn a_failed_write_is_an_error_and_keeps_the_old_image() {
    let dir = temp_dir("efbig");
    for ext in ["exr", "png"] {
        let out = dir.0.join(format!("o.{ext}"));
        let small = ["--width", "64", "--height", "48", "--spp", "1", "--quiet"];
        let good = Command::new(RESTIR)
            .args(["render", s(&cornell()), "-o", s(&out)])
            .args(small)
            .output()
            .unwrap();
        assert!(good.status.success());
        let before = std::fs::read(&out).unwrap();
        // 8 blocks (4 or 8 KiB depending on the shell) is smaller than either image.
        let o = Command::new("sh")
            .arg("-c")
            .arg("trap '' XFSZ; ulimit -f 8; exec \"$0\" \"$@\"")
            .arg(RESTIR)
            .args(["render", s(&cornell()), "-o", s(&out), "--seed", "3"])
            .args(["--width", "64", "--height", "48", "--spp", "1"])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{ext}: {stderr}");
        assert!(
            stderr.starts_with(&format!("error: {}: cannot write", s(&out))),
            "{ext}: {stderr}"
        );
        assert!(stderr.contains("too large"), "{ext}: {stderr}");
        assert!(
            o.stdout.is_empty(),
            "{ext}: no summary after a failed write"
        );
        assert_eq!(
            std::fs::read(&out).unwrap(),
            before,
            "{ext}: old image kept"
        );
        assert_eq!(entries(&dir.0).len(), if ext == "exr" { 1 } else { 2 });
    }
}

/// `restir render … | head -0`: the summary goes to a closed pipe; no panic, exit code 0.
#[test]
fn a_closed_stdout_is_no_panic() {
    let dir = temp_dir("stdout");
    let out = dir.0.join("o.exr");
    let mut child = Command::new(RESTIR)
        .args(["render", s(&cornell()), "-o", s(&out)])
        .args(["--width", "16", "--height", "16", "--spp", "1"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert!(out.is_file());
    // compare's one line, too.
    let mut child = Command::new(RESTIR)
        .args(["compare", s(&out), s(&out)])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(0));
    assert!(o.stderr.is_empty());
}

/// Warnings and errors to a closed stderr: no panic, the exit code unchanged.
#[test]
fn a_closed_stderr_is_no_panic() {
    let dir = temp_dir("stderr");
    let scene = dir.0.join("warns.xml");
    let text = std::fs::read_to_string(cornell()).unwrap().replace(
        "<float name=\"fov\"",
        "<float name=\"near_clip\" value=\"1\"/><float name=\"fov\"",
    );
    std::fs::write(&scene, text).unwrap();
    let out = dir.0.join("o.exr");
    for (args, code) in [
        (
            vec![
                "render",
                s(&scene),
                "-o",
                s(&out),
                "--spp",
                "1",
                "--width",
                "8",
            ],
            0,
        ),
        (vec!["render", s(&scene), "-o", s(&out), "--spp", "0"], 1),
    ] {
        let mut child = Command::new(RESTIR)
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stderr.take());
        let o = child.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(code), "{args:?}");
    }
}

/// Starts a render of `passes` passes of `size`² pixels into `out` and sends it `signals`
/// (`sh`'s `kill -SIG`), the first after `wait`, the others 50 ms apart.
fn interrupt(out: &Path, size: &str, signals: &[&str], wait: Duration) -> std::process::Output {
    let child = Command::new(RESTIR)
        .args(["render", s(&cornell()), "-o", s(out), "--spp", "100000"])
        .args(["--width", size, "--height", size, "--quiet"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(wait);
    for sig in signals {
        let kill = format!("kill -{sig} {}", child.id());
        assert!(
            Command::new("sh")
                .arg("-c")
                .arg(&kill)
                .status()
                .unwrap()
                .success()
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

/// One interrupt (SIGINT, as Ctrl-C, or SIGTERM): the passes done so far are written, stderr
/// says so, exit code 130.
#[test]
fn an_interrupt_writes_what_was_rendered_and_exits_130() {
    let dir = temp_dir("sigint");
    for sig in ["INT", "TERM"] {
        let out = dir.0.join(format!("{sig}.exr"));
        let o = interrupt(&out, "32", &[sig], Duration::from_millis(1500));
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(130), "{sig}: {stderr}");
        let line = stderr.lines().last().unwrap_or("");
        assert!(
            line.starts_with("interrupted after ")
                && line.ends_with(&format!("passes: wrote what was rendered -> {}", s(&out))),
            "{sig}: {stderr}"
        );
        let img = restir_image::Image::read_exr(&out).unwrap();
        assert_eq!((img.width, img.height), (32, 32));
        assert!(
            img.mean().max_element() > 0.0,
            "{sig}: the image has the passes"
        );
    }
}

/// A second interrupt aborts the current pass at once: exit 130 within a fraction of a pass,
/// nothing written.
#[test]
fn a_second_interrupt_aborts_at_once() {
    let dir = temp_dir("abort");
    let out = dir.0.join("o.exr");
    // 2048² pixels: one pass takes seconds, the abort must not wait for it.
    let start = Instant::now();
    let o = interrupt(&out, "2048", &["INT", "INT"], Duration::from_millis(1500));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{stderr}");
    assert!(stderr.ends_with("aborted\n"), "{stderr}");
    assert!(!out.exists(), "nothing written");
    assert!(entries(&dir.0).is_empty(), "no temporary file left");
    assert!(start.elapsed() < Duration::from_secs(30));
}

const TINY: [&str; 7] = ["--width", "8", "--height", "8", "--spp", "1", "--quiet"];

fn render(out: &Path, extra: &[&str]) -> std::process::Output {
    Command::new(RESTIR)
        .args(["render", s(&cornell()), "-o", s(out)])
        .args(TINY)
        .args(extra)
        .output()
        .unwrap()
}

/// Expects exit code 1 with stderr starting `error: ` and containing `want`.
fn assert_fails(o: &std::process::Output, want: &str) {
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.starts_with("error: ") && stderr.contains(want),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// Statistics to a device or to stdout are written there directly: `/dev/null` stays the
/// character device (the old writer renamed a regular file over it when it could), `-` and
/// `/dev/stdout` print the JSON.
#[cfg(unix)]
#[test]
fn stats_to_a_device_or_stdout_are_written_directly() {
    use std::os::unix::fs::FileTypeExt;
    let dir = temp_dir("devices");
    let out = dir.0.join("o.exr");
    let null = private_null(&dir.0);
    let o = render(&out, &["--stats", s(&null)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        std::fs::metadata(&null)
            .unwrap()
            .file_type()
            .is_char_device()
    );
    for stdout in ["-", "/dev/stdout"] {
        let o = render(&out, &["--stats", stdout]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(json["width"], 8, "{stdout}");
    }
    let mut want = vec!["o.exr".to_string()];
    if null.starts_with(&dir.0) {
        want.insert(0, "null".into());
    }
    assert_eq!(entries(&dir.0), want, "no temporary file left");
}

/// A null device to write to: as root (who could replace the system's /dev/null by mistake) a
/// private one made in `dir` with `mknod`; otherwise /dev/null, which a user cannot replace.
#[cfg(unix)]
fn private_null(dir: &Path) -> PathBuf {
    let node = dir.join("null");
    let made = Command::new("mknod")
        .arg(&node)
        .args(["c", "1", "3"])
        .stderr(Stdio::null())
        .status();
    if made.is_ok_and(|s| s.success()) {
        node
    } else {
        PathBuf::from("/dev/null")
    }
}

/// A FIFO output is opened and written (a reader receives the statistics) and stays a FIFO.
#[cfg(unix)]
#[test]
fn stats_to_a_fifo_reach_the_reader() {
    use std::io::Read;
    use std::os::unix::fs::FileTypeExt;
    let dir = temp_dir("fifo");
    let fifo = dir.0.join("stats.json");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            let mut s = String::new();
            std::fs::File::open(&fifo)
                .unwrap()
                .read_to_string(&mut s)
                .unwrap();
            s
        })
    };
    let o = render(&dir.0.join("o.exr"), &["--stats", s(&fifo)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(reader.join().unwrap().contains("\"width\": 8"));
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
}

/// A symlinked output is followed: the link's target gets the image, the link stays a link.
#[cfg(unix)]
#[test]
fn a_symlinked_output_replaces_its_target() {
    let dir = temp_dir("symlink");
    std::fs::create_dir(dir.0.join("real")).unwrap();
    let target = dir.0.join("real/image.exr");
    std::fs::write(&target, b"old").unwrap();
    let link = dir.0.join("link.exr");
    std::os::unix::fs::symlink("real/image.exr", &link).unwrap();
    let o = render(&link, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    let img = restir_image::Image::read_exr(&target).unwrap();
    assert_eq!((img.width, img.height), (8, 8));
    assert_eq!(entries(&dir.0.join("real")), ["image.exr"]);
}

/// A valid 250-byte file name is written (its temporary name fits the 255-byte limit).
#[test]
fn a_250_byte_name_is_written() {
    let dir = temp_dir("long");
    let name = format!("{}.exr", "x".repeat(246));
    assert_eq!(name.len(), 250);
    let out = dir.0.join(&name);
    let o = render(
        &out,
        &[
            "--stats",
            s(&dir.0.join(format!("{}.json", "s".repeat(245)))),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.is_file());
    assert_eq!(entries(&dir.0).len(), 2, "no temporary left");
}

/// `--stats` naming the image, `-o out.exr/`, a directory or a socket: errors before rendering,
/// nothing written.
#[test]
fn impossible_outputs_fail_before_rendering() {
    let dir = temp_dir("refused");
    let out = dir.0.join("o.exr");
    let o = render(&out, &["--stats", s(&out)]);
    assert_fails(&o, "the same file as the output image");
    let o = render(&out, &["--stats", &format!("{}/./o.exr", s(&dir.0))]);
    assert_fails(&o, "the same file as the output image");
    let slash = PathBuf::from(format!("{}/", s(&out)));
    let o = render(&slash, &[]);
    assert_fails(&o, "ends in '/': it names a directory");
    #[cfg(unix)]
    {
        let sock = dir.0.join("s.json");
        let _l = std::os::unix::net::UnixListener::bind(&sock).unwrap();
        let o = render(&out, &["--stats", s(&sock)]);
        assert_fails(&o, "not a regular file, character device or FIFO");
        std::fs::remove_file(&sock).unwrap();
    }
    assert!(entries(&dir.0).is_empty(), "{:?}", entries(&dir.0));
}

/// Under a file-size limit without any signal disposition set by the caller, the write that
/// crosses the limit is a reported error (not a silent death by SIGXFSZ), and the temporary
/// file is removed.
#[cfg(unix)]
#[test]
fn a_file_size_limit_is_reported_not_a_signal_death() {
    let dir = temp_dir("xfsz");
    let out = dir.0.join("o.exr");
    let o = Command::new("sh")
        .arg("-c")
        .arg("ulimit -f 8; exec \"$0\" \"$@\"")
        .arg(RESTIR)
        .args(["render", s(&cornell()), "-o", s(&out)])
        .args(["--width", "64", "--height", "48", "--spp", "1"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{:?} {stderr}", o.status);
    assert!(
        stderr.starts_with(&format!("error: {}: cannot write", s(&out))),
        "{stderr}"
    );
    assert!(entries(&dir.0).is_empty(), "{:?}", entries(&dir.0));
}

/// `compare --html` onto one of the images compared is refused; to a device it is written
/// directly.
#[test]
fn compare_html_is_checked() {
    let dir = temp_dir("html");
    let out = dir.0.join("o.exr");
    assert!(render(&out, &[]).status.success());
    let before = std::fs::read(&out).unwrap();
    let o = Command::new(RESTIR)
        .args(["compare", s(&out), s(&out), "--html", s(&out)])
        .output()
        .unwrap();
    assert_fails(&o, "the same file as the input");
    assert_eq!(std::fs::read(&out).unwrap(), before);
    #[cfg(unix)]
    {
        let o = Command::new(RESTIR)
            .args(["compare", s(&out), s(&out), "--html", "/dev/null"])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
}

/// `generate` and `merge` with their summary line going to a closed pipe: no panic, the files
/// written, and the lost report an error (exit 1) rather than a silent success.
#[test]
fn generate_and_merge_survive_a_closed_stdout() {
    let dir = temp_dir("closed-generate");
    let scene = dir.0.join("lights.ron");
    let part = dir.0.join("part.exr");
    let merged = dir.0.join("merged.exr");
    assert!(
        render(&part, &["--chain", "0", "--chains", "1"])
            .status
            .success()
    );
    for args in [
        vec!["generate", "many-lights", "--lights", "2", "-o", s(&scene)],
        vec!["merge", s(&merged), s(&part)],
    ] {
        // The reading end closed before the command starts (closing it after spawning races
        // with a quick command's write into the pipe's buffer).
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let o = Command::new(RESTIR)
            .args(&args)
            .stdout(writer)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert_eq!(o.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(
            stderr.contains("cannot write to standard output"),
            "{args:?}: {stderr}"
        );
    }
    assert!(scene.is_file() && merged.is_file());
}
