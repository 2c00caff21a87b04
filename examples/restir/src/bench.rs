//! `restir bench`: the equal-time evaluation. Argument parsing and the progress bar; the suite
//! runner, references, plots and report live in `restir-evaluation`.

use std::io::IsTerminal;
use std::path::PathBuf;

use crate::say::say;
use restir_evaluation::{
    Clock, Progress, RunOptions, Suite, check_doc, run_suite, suite, update_doc, write_outputs,
};

/// Options of `restir bench`.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// Suite file (RON): scenes × integrator configurations × budgets × seeds.
    #[arg(default_value = "scenes/bench/default.ron")]
    suite: PathBuf,
    /// Output directory: results.csv, relmse-<scene>.svg, strip-<scene>.png, report.md, and the
    /// reference cache in references/.
    #[arg(long, default_value = "bench-out")]
    out: PathBuf,
    /// Time budgets in seconds, comma-separated; override the suite's.
    #[arg(long, value_delimiter = ',', value_name = "SECONDS,...")]
    budgets: Option<Vec<f64>>,
    /// The clock the budgets count, wall (elapsed seconds) or cpu (the process's CPU seconds:
    /// equal CPU time on a shared machine); overrides the suite's `clock`.
    #[arg(long, value_enum)]
    clock: Option<ClockArg>,
    /// Seeds per budget; overrides the suite's.
    #[arg(long)]
    seeds: Option<u32>,
    /// Reference passes; overrides the suite's (and every scene's) reference_spp.
    #[arg(long)]
    reference_spp: Option<u32>,
    /// Worker threads, 1 to 256 (0 or absent: one per core).
    #[arg(long)]
    threads: Option<usize>,
    /// Also rewrite the marked results section of this Markdown file (e.g. docs/BENCH_RESULTS.md).
    #[arg(long, value_name = "FILE.md")]
    update_doc: Option<PathBuf>,
    /// The most memory a scene's renders may need, in GiB (estimated from its size, the
    /// estimators' buffers and the images kept for the report, before rendering).
    #[arg(long, value_name = "GIB")]
    max_memory: Option<f64>,
    /// No progress bar and no summary line.
    #[arg(long)]
    quiet: bool,
}

/// `--clock`.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum ClockArg {
    Wall,
    Cpu,
}

/// Runs `restir bench`.
pub fn run(args: BenchArgs) -> Result<(), String> {
    let (mut suite, lines) = Suite::load_located(&args.suite).map_err(|e| e.to_string())?;
    let max_memory_gib = crate::strict::max_memory(args.max_memory)?;
    // Generated families are written beside the references, once.
    suite
        .expand_families(&args.out.join("families"))
        .map_err(|e| format!("{}: {e}", args.suite.display()))?;
    if let Some(b) = &args.budgets {
        suite::check_budgets(b).map_err(|e| format!("--budgets: {e}"))?;
        suite.budgets = b.clone();
        suite.strip_budget = None;
    }
    if let Some(clock) = args.clock {
        suite.clock = match clock {
            ClockArg::Wall => Clock::Wall,
            ClockArg::Cpu => Clock::Cpu,
        };
    }
    if let Some(s) = args.seeds {
        suite.seeds = s;
    }
    if let Some(spp) = args.reference_spp {
        suite.reference_spp = spp;
        for s in &mut suite.scenes {
            s.reference_spp = None;
        }
    }
    suite
        .validate()
        .map_err(|e| format!("{}: {e}", args.suite.display()))?;
    if let Some(doc) = &args.update_doc {
        check_doc(doc).map_err(|e| e.to_string())?;
    }
    let pool = crate::strict::thread_pool(args.threads)?;
    let opts = RunOptions {
        suite_dir: args.suite.parent().map(PathBuf::from).unwrap_or_default(),
        out: args.out.clone(),
        command_line: std::iter::once("restir".to_string())
            .chain(std::env::args().skip(1))
            .collect::<Vec<_>>()
            .join(" "),
        max_memory_gib,
        lines,
    };
    let bar = (!args.quiet && std::io::stderr().is_terminal()).then(|| {
        let b = indicatif::ProgressBar::new(0);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} renders, {elapsed_precise} elapsed, ETA {eta_precise} {msg}",
            )
            .expect("valid template"),
        );
        b
    });
    let results = pool.install(|| {
        run_suite(&suite, &opts, &mut |p: &Progress| {
            if let Some(b) = &bar {
                b.set_length(p.total);
                b.set_position(p.done);
                b.set_message(p.message.clone());
            }
        })
    });
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let results = results.map_err(|e| e.to_string())?;
    write_outputs(&results, &args.out).map_err(|e| e.to_string())?;
    if let Some(doc) = &args.update_doc {
        update_doc(&results, &args.out, doc).map_err(|e| e.to_string())?;
    }
    if !args.quiet {
        say!(
            "{} renders in {:.1} min -> {}",
            results.records.len(),
            results.wall_seconds / 60.0,
            args.out.join("report.md").display()
        );
    }
    Ok(())
}
