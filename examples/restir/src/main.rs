//! `restir`: the command-line front end. Parsing arguments, a progress bar and writing files;
//! everything else lives in the library crates. This file dispatches the commands; each lives
//! in its own module (`render`, with its flags in `args` and its report in `stats`; `compare`,
//! `generate`, `convert`, `bench`, `merge`).

// The argument structs' doc comments are clap's `--help` text, where `<scene>` is a placeholder
// for the user, not an HTML tag.
#![allow(rustdoc::invalid_html_tags)]

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod args;
mod bench;
mod cluster;
mod compare;
mod convert;
mod frames;
mod generate;
mod interrupt;
mod merge;
mod preview;
mod progress;
mod render;
mod say;
mod stats;
mod strict;

use render::Rendered;
use say::say_err;

#[derive(Parser, Debug)]
#[command(
    name = "restir",
    version,
    about = "Path tracing, ReSTIR DI and ReSTIR PT on the CPU"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene (.xml in Mitsuba format, or .ron) to an image.
    Render(Box<args::RenderArgs>),
    /// Compare a rendered EXR with a reference EXR: relMSE, MSE, mean ratio, non-finite pixels,
    /// MAPE and FLIP.
    Compare {
        /// The image to judge.
        test: PathBuf,
        /// The reference.
        reference: PathBuf,
        /// Also write an interactive comparison page (split view, zoom, pixel values, exposure,
        /// error maps): one self-contained HTML file.
        #[arg(long, value_name = "OUT.html")]
        html: Option<PathBuf>,
    },
    /// Write a procedurally generated scene (RON).
    #[command(subcommand)]
    Generate(generate::Generate),
    /// Write a scene (.ron or .xml) as Mitsuba 3 XML, which Mitsuba 3 and restir read to the
    /// same scene.
    ///
    /// The film size, sample count and max depth become <default> variables resx, resy, spp and
    /// max_depth (restir render -D resx=128; in Mitsuba, mi.load_file(path, resx=128)). What
    /// Mitsuba 3 cannot express is an error naming it: an animation, a ReSTIR integrator or its
    /// parameters, an inline triangle mesh. See docs/SCENES.md, "Writing Mitsuba 3 XML".
    Convert(convert::ConvertArgs),
    /// Equal-time evaluation: render a suite of scenes × integrators × time budgets × seeds,
    /// compare with references, write a CSV, relMSE-versus-time plots, crops and a report.
    Bench(Box<bench::BenchArgs>),
    /// Merge the parts of a split render (--chain/--crop) into one image (docs/CLUSTER.md).
    Merge(merge::MergeArgs),
}

/// A file-size limit (`ulimit -f`) is a write error naming the file, not a silent death by
/// SIGXFSZ: the signal is blocked here, before any thread starts (threads inherit the mask), so
/// the write that crosses the limit returns EFBIG, is reported, and the temporary file is
/// removed. Blocked rather than ignored because blocking is safe code (`sigprocmask`), and a
/// blocked SIGXFSZ has the same effect on `write`.
#[cfg(unix)]
fn report_file_size_limit() {
    use nix::sys::signal::{SigSet, Signal};
    let mut set = SigSet::empty();
    set.add(Signal::SIGXFSZ);
    let _ = set.thread_block();
}

fn main() -> ExitCode {
    #[cfg(unix)]
    report_file_size_limit();
    // Rough-plastic tables are kept between runs (`RESTIR_CACHE_DIR=` turns this off).
    restir_materials::table_cache::set_cache_dir(restir_materials::table_cache::default_cache_dir());
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                let _ = e.print();
                return if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                    ExitCode::FAILURE
                } else {
                    ExitCode::SUCCESS
                };
            }
            // clap's whole message: the error, its hints ("a similar argument exists") and the
            // usage line.
            let _ = e.print();
            return ExitCode::FAILURE;
        }
    };
    let result = match cli.command {
        Command::Render(args) => render::run(*args),
        Command::Compare {
            test,
            reference,
            html,
        } => compare::run(&test, &reference, html.as_deref()).map(|()| Rendered::Complete),
        Command::Generate(what) => generate::run(what).map(|()| Rendered::Complete),
        Command::Convert(args) => convert::run(args).map(|()| Rendered::Complete),
        Command::Bench(args) => bench::run(*args).map(|()| Rendered::Complete),
        Command::Merge(args) => merge::run(args).map(|()| Rendered::Complete),
    };
    match result {
        Ok(Rendered::Complete) => ExitCode::SUCCESS,
        Ok(Rendered::Interrupted) => ExitCode::from(interrupt::EXIT_INTERRUPTED),
        Err(e) => {
            say_err!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
