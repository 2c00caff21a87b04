//! What a terminal shows while the command works: a spinner with the elapsed time while a
//! scene loads (building a scene with several rough plastics takes seconds). Nothing is drawn
//! with `--quiet` or when stderr is not a terminal.

use std::io::IsTerminal;
use std::path::Path;
use std::time::Duration;

/// A spinner "loading SCENE" on stderr, or `None` when `quiet` or stderr is no terminal.
/// Clear it with `finish_and_clear` before printing anything else.
pub fn load_spinner(scene: &Path, quiet: bool) -> Option<indicatif::ProgressBar> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let s = indicatif::ProgressBar::new_spinner();
    s.set_style(
        indicatif::ProgressStyle::with_template("{spinner} loading {msg} ({elapsed})")
            .expect("valid template"),
    );
    s.set_message(scene.display().to_string());
    s.enable_steady_tick(Duration::from_millis(100));
    Some(s)
}
