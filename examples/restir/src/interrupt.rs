//! Ctrl-C (and SIGTERM, SIGHUP) during a render: the first asks the render to stop after the
//! current pass, so the image rendered so far is written (the command then exits with
//! [`EXIT_INTERRUPTED`]); a second one aborts at once, removing the output's temporary file if a
//! write was under way (outputs are written beside the target and renamed, so the target is
//! never half-written).

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

use crate::say::say_err;

/// The exit code after an interrupt (128 + SIGINT, the shell's convention).
pub const EXIT_INTERRUPTED: u8 = 130;

/// The output whose temporary file a second interrupt removes.
static OUTPUT: Mutex<Option<PathBuf>> = Mutex::new(None);

/// Installs the handler; the returned flag becomes true at the first interrupt. `quiet`
/// silences the first interrupt's message.
pub fn install(output: PathBuf, quiet: bool) -> Arc<AtomicBool> {
    let cancel = Arc::new(AtomicBool::new(false));
    *OUTPUT.lock().unwrap_or_else(|e| e.into_inner()) = Some(output);
    let flag = cancel.clone();
    let count = AtomicU32::new(0);
    // Without a handler (one was already set) Ctrl-C keeps its default: the process ends.
    let _ = ctrlc::set_handler(move || {
        if count.fetch_add(1, Ordering::SeqCst) == 0 {
            flag.store(true, Ordering::SeqCst);
            if !quiet {
                say_err!(
                    "interrupted: finishing the current pass, then writing the image (interrupt again to abort)"
                );
            }
        } else {
            if let Some(out) = OUTPUT.lock().unwrap_or_else(|e| e.into_inner()).as_ref() {
                let _ = std::fs::remove_file(restir_image::temp_path(out));
            }
            say_err!("aborted");
            std::process::exit(EXIT_INTERRUPTED as i32);
        }
    });
    cancel
}
