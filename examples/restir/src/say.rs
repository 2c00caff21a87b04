//! Printing that never panics: `say!` (stdout) and `say_err!` (stderr) are `println!` and
//! `eprintln!` that drop write errors, so `restir render … | head` or a closed stderr end the
//! messages, not the program (Rust's `println!` panics on a closed pipe). `tell!` is the checked
//! kind, for a command's final report.

/// `println!` that ignores a closed or failing stdout.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

/// `eprintln!` that ignores a closed or failing stderr.
macro_rules! say_err {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// `println!` whose failure is an error (`Err(String)`, for `?`): for the report of a command
/// whose files are written (`merge`, `generate`), so that a full disk behind stdout
/// (`> /dev/full`) or a closed pipe (`| head -c0`) ends it with a message and a non-zero exit
/// status instead of a success whose report was lost.
macro_rules! tell {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let mut out = std::io::stdout().lock();
        writeln!(out, $($arg)*)
            .and_then(|()| out.flush())
            .map_err(|e| format!("cannot write to standard output: {e}"))
    }};
}

pub(crate) use {say, say_err, tell};
