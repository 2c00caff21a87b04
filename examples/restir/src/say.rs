//! Printing that never panics: `say!` (stdout) and `say_err!` (stderr) are `println!` and
//! `eprintln!` that drop write errors, so `restir render … | head` or a closed stderr end the
//! messages, not the program (Rust's `println!` panics on a closed pipe).

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

pub(crate) use {say, say_err};
