//! What the `restir` command's tests share: running it, and expecting a one-line error.
#![allow(dead_code)] // each test file uses a different subset

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary under test.
pub const RESTIR: &str = env!("CARGO_BIN_EXE_restir");

/// Runs `restir args` to the end.
pub fn restir(args: &[&str]) -> Output {
    Command::new(RESTIR).args(args).output().unwrap()
}

/// The path as a `&str` (test paths are UTF-8).
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The shipped Cornell box.
pub fn cornell() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml")
}

/// Runs `restir args`, expects exit code 1 and a single stderr line (no panic) that contains
/// every string in `needles`; returns that line.
pub fn fails(args: &[&str], needles: &[&str]) -> String {
    let out = restir(args);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(
        !stderr.contains("panicked"),
        "{args:?}: panicked:\n{stderr}"
    );
    assert_eq!(out.status.code(), Some(1), "{args:?}: stderr:\n{stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(
        lines.len(),
        1,
        "{args:?}: expected one line, got:\n{stderr}"
    );
    for n in needles {
        assert!(lines[0].contains(n), "{args:?}: {:?} lacks {n:?}", lines[0]);
    }
    lines[0].to_string()
}

/// Runs `restir args`: exit code 1, nothing on stdout (nothing rendered), stderr exactly
/// `expected` plus a newline.
pub fn fails_with(args: &[&str], expected: &str) {
    let out = restir(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert_eq!(stderr, format!("{expected}\n"), "{args:?}");
    assert!(out.stdout.is_empty(), "{args:?} printed a summary");
}
