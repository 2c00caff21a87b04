//! What a terminal shows while the command works: a spinner with the elapsed time while a
//! scene loads (building a scene with several rough plastics takes seconds), then a bar of the
//! passes. Nothing is drawn with `--quiet` or when stderr is not a terminal.

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

/// A bar of the passes on stderr (of the time limit when only `--time-limit` bounds the render,
/// `spp == u32::MAX`), or `None` when `quiet` or stderr is no terminal.
pub fn pass_bar(
    quiet: bool,
    time_limit: Option<Duration>,
    spp: u32,
) -> Option<indicatif::ProgressBar> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = match time_limit {
        Some(t) if spp == u32::MAX => {
            let b = indicatif::ProgressBar::new(t.as_millis() as u64);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{bar:40} {elapsed_precise} / time limit, {msg}",
                )
                .expect("valid template"),
            );
            b
        }
        _ => {
            let b = indicatif::ProgressBar::new(spp as u64);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{bar:40} {pos}/{len} passes, {elapsed_precise} elapsed, ETA {eta_precise}",
                )
                .expect("valid template"),
            );
            b
        }
    };
    Some(bar)
}
