//! `restir-fuzz`: deterministic mutation fuzzing of the scene loader, one target per input format
//! (`xml`, `ron`, `obj`, `ply`, `serialized`, `exr`, `hdr`, `png`), the reader of the parts
//! of a split render that `restir merge` reads (`part`: `restir_image::Image::read_exr_part`),
//! `restir bench` suite files (`suite`: `restir_evaluation::Suite::load_located`), animation
//! files (`anim`: an XML scene's `NAME.anim.ron` sidecar, or a RON scene with its animation
//! inline, loaded and built at a few times and frames) and the rough-plastic table cache
//! (`cache`: a file at a table's name in the cache directory, read when a scene with that
//! material loads; half of its inputs are tables with changed values and a valid checksum, and a
//! table the reader uses must be the integral it stands for).
//!
//! Coverage-guided fuzzers need nightly Rust (cargo-fuzz) or an AFL++ toolchain; this workspace
//! builds on one stable toolchain, so the harness mutates the checked-in seeds in
//! `crates/fuzz/corpus/<target>/` with a fixed-seed generator (byte flips and overwrites,
//! interesting integers, numbers replaced by `1e38`, `NaN`, `-0`, huge counts, chunk
//! duplication, splices, truncation; for the cache, value changes under a valid checksum:
//! `mutate.rs`) and loads each input (`restir_scene::load_scene`, the
//! whole build) in a child process run under `ulimit -v` (a memory cap) and a time limit. Errors
//! are the expected outcome; a panic, an abort, a signal, a hang or a breach of the memory cap
//! fails the run, and the input is kept in the work directory for a regression case.
//!
//! ```text
//! restir-fuzz run [--seconds S] [--seed N] [--target T]... [--work DIR]   fuzz (default: all, 20 s each)
//! restir-fuzz one <target> <input file>                                   load one input (the child)
//! ```

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

mod mutate;
use mutate::{Rng, mutate, mutate_table};

/// The formats, with how an input of each is placed into a scene.
const TARGETS: [&str; 12] = [
    "part",
    "cache",
    "suite",
    "anim",
    "xml",
    "ron",
    "obj",
    "ply",
    "serialized",
    "exr",
    "hdr",
    "png",
];

/// Longest one input may take to load.
const TIME_LIMIT: Duration = Duration::from_secs(10);

/// The child's address-space limit in KiB (`ulimit -v`): 3 GiB.
const MEMORY_LIMIT_KIB: u64 = 3 << 20;

/// The scene (file name, text) that refers to an asset input of `target` named `asset`.
fn wrapper_scene(target: &str, asset: &str) -> String {
    let sensor = r#"<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>"#;
    let body = match target {
        "obj" | "ply" | "serialized" => format!(
            r#"<shape type="{target}"><string name="filename" value="{asset}"/><emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>"#
        ),
        "exr" | "hdr" => {
            format!(r#"<emitter type="envmap"><string name="filename" value="{asset}"/></emitter>"#)
        }
        _ => format!(
            r#"<texture type="bitmap" id="t"><string name="filename" value="{asset}"/></texture><bsdf type="diffuse" id="m"><ref name="reflectance" id="t"/></bsdf><shape type="rectangle"><ref id="m"/></shape>"#
        ),
    };
    format!("<scene version=\"3.0.0\">{sensor}{body}</scene>")
}

/// The scene an animation input (`anim`) is the sidecar of: shapes with the ids its seed names.
const ANIM_SCENE: &str = r#"<scene version="3.0.0"><sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor><shape type="sphere" id="copper"><point name="center" x="-1.1" y="0.38" z="-0.6"/><float name="radius" value="0.38"/></shape><shape type="rectangle" id="light_small"><emitter type="area"><rgb name="radiance" value="20"/></emitter></shape></scene>"#;

/// The scene a table cache input (`cache`) is read by: a rough plastic whose table is the one
/// the seed holds (GGX, α = 0.3, η = 1.5).
const CACHE_SCENE: &str = r#"<scene version="3.0.0"><sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor><bsdf type="roughplastic" id="m"><string name="distribution" value="ggx"/><float name="alpha" value="0.3"/><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/></bsdf><shape type="rectangle"><ref id="m"/></shape><emitter type="constant"/></scene>"#;

/// Reports a loader's answer as the child does: success, or an error that must be one line and
/// must not happen for a seed.
fn answer(result: Result<(), String>) -> ExitCode {
    match result {
        Ok(()) => println!("ok"),
        Err(msg) => {
            if std::env::var_os("RESTIR_FUZZ_SEED").is_some() {
                eprintln!("a seed must load: {msg}");
                return ExitCode::from(4);
            }
            if msg.contains('\n') {
                eprintln!("error message spans several lines: {msg}");
                return ExitCode::from(3);
            }
            println!("error: {msg}");
        }
    }
    ExitCode::SUCCESS
}

/// An animation input: the sidecar of [`ANIM_SCENE`] (or, for a seed named `*.scene.ron`, a RON
/// scene with its animation inline), the scene loaded with it and built at a few times: inside,
/// before, after and far beyond its keys, and the times of the first, a later and the last
/// frame `--frames` can name at the animation's own rate.
fn load_animated(input: &Path) -> Result<(), String> {
    let scene = if input.to_string_lossy().ends_with(".scene.ron") {
        input.to_path_buf()
    } else {
        let dir = input.parent().unwrap_or(Path::new("."));
        let scene = dir.join("anim-scene.xml");
        std::fs::write(&scene, ANIM_SCENE).map_err(|e| e.to_string())?;
        std::fs::copy(input, restir_scene::sidecar_path(&scene)).map_err(|e| e.to_string())?;
        scene
    };
    let loaded = restir_scene::load_scene(&scene, &restir_scene::LoadOptions::default())
        .map_err(|e| e.to_string())?;
    let fps = loaded.desc.animation.as_ref().map_or(24.0, |a| a.fps);
    let frames = [0, 47, u32::MAX].map(|f| restir_scene::animation::frame_time(f, fps));
    for t in [0.0, 1.3, -1.0, 1e6].into_iter().chain(frames) {
        restir_scene::animation::build_at(&loaded.desc, &scene, t).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// A table cache input: `input` lies in a directory of its own under the name of the table the
/// seed holds; that directory is the cache while [`CACHE_SCENE`] loads. A seed must be read as
/// it is (the loader rebuilding and replacing it would mean its name or contents went stale, and
/// the target no longer reached the reader). A mutated input that is read (not replaced by a
/// rebuilt table) must be the seed's table within what the reader's checks let through: a
/// transmittance row within 10⁻⁵, the internal reflectance within 2.5 % of `1 − R_int`;
/// anything else is a crafted table trusted, and the child exits with status 5.
fn load_cached(input: &Path) -> Result<(), String> {
    use std::os::unix::fs::MetadataExt as _;
    let cache = input.parent().ok_or("the input has no directory")?;
    let work = cache.parent().unwrap_or(Path::new("."));
    let scene = work.join("cache-scene.xml");
    std::fs::write(&scene, CACHE_SCENE).map_err(|e| e.to_string())?;
    let inode = std::fs::metadata(input).map_err(|e| e.to_string())?.ino();
    restir_materials::table_cache::set_cache_dir(Some(cache.to_path_buf()));
    restir_scene::load_scene(&scene, &restir_scene::LoadOptions::default())
        .map_err(|e| e.to_string())?;
    let replaced = std::fs::metadata(input).map_or(true, |m| m.ino() != inode);
    if replaced && std::env::var_os("RESTIR_FUZZ_SEED").is_some() {
        return Err(format!(
            "{}: the cache did not read the seed (stale name or table version?)",
            input.display()
        ));
    }
    if !replaced && let Some(why) = trusted_but_not_honest(input) {
        eprintln!(
            "{}: a table that is not the integral was used ({why})",
            input.display()
        );
        std::process::exit(5);
    }
    Ok(())
}

/// The values of a table cache file (between the 8-byte magic and the 8-byte checksum).
fn table_values(bytes: &[u8]) -> Vec<f32> {
    bytes
        .get(8..bytes.len().saturating_sub(8))
        .unwrap_or_default()
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// How the table cache file `input` differs from the seed of its name (the honest table) by
/// more than the reader's checks allow, if it does.
fn trusted_but_not_honest(input: &Path) -> Option<String> {
    let name = input.file_name()?;
    let seed = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("corpus/cache")
        .join(name);
    let honest = table_values(&std::fs::read(seed).ok()?);
    let read = table_values(&std::fs::read(input).unwrap_or_default());
    let (&r_honest, t_honest) = honest.split_last()?;
    let Some((&r_read, t_read)) = read.split_last() else {
        return Some("it has no values".into());
    };
    if t_read.len() != t_honest.len() {
        return Some(format!("{} values", read.len()));
    }
    // Written so that NaN counts as a difference.
    let close = |a: f32, b: f32, tolerance: f32| (a - b).abs() <= tolerance;
    for (k, (&a, &b)) in t_read.iter().zip(t_honest).enumerate() {
        if !close(a, b, 1e-5) {
            return Some(format!("transmittance row {k}: {a} for {b}"));
        }
    }
    if !close(r_read, r_honest, 0.025 * (1.0 - r_honest)) {
        return Some(format!("internal reflectance {r_read} for {r_honest}"));
    }
    None
}

/// The child: loads one input of `target` (`input` is the mutated file) and exits 0 whatever the
/// loader says, so that only panics, aborts, signals and hangs count as failures.
fn run_one(target: &str, input: &Path) -> ExitCode {
    if target == "part" {
        match restir_image::Image::read_exr_part(input) {
            Ok(_) => println!("ok"),
            Err(e) => {
                let msg = e.to_string();
                if std::env::var_os("RESTIR_FUZZ_SEED").is_some() {
                    eprintln!("a seed must load: {msg}");
                    return ExitCode::from(4);
                }
                println!("error: {msg}");
            }
        }
        return ExitCode::SUCCESS;
    }
    match target {
        "suite" => {
            return answer(
                restir_evaluation::Suite::load_located(input)
                    .map(|_| ())
                    .map_err(|e| e.to_string()),
            );
        }
        "anim" => return answer(load_animated(input)),
        "cache" => return answer(load_cached(input)),
        _ => {}
    }
    let scene = match target {
        "xml" | "ron" => input.to_path_buf(),
        _ => {
            let dir = input.parent().unwrap_or(Path::new("."));
            let name = input
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or("input");
            let scene = dir.join(format!("{name}.scene.xml"));
            if std::fs::write(&scene, wrapper_scene(target, name)).is_err() {
                return ExitCode::from(2);
            }
            scene
        }
    };
    answer(
        restir_scene::load_scene(&scene, &restir_scene::LoadOptions::default())
            .map(|_| ())
            .map_err(|e| e.to_string()),
    )
}

/// How one input went.
enum Outcome {
    Fine,
    Failed(String),
}

/// Runs the child on `input` under the memory cap and the time limit.
fn check(exe: &Path, target: &str, input: &Path, is_seed: bool) -> Outcome {
    let script = format!("ulimit -v {MEMORY_LIMIT_KIB} && exec \"$0\" one {target} \"$1\"",);
    let mut command = Command::new("sh");
    if is_seed {
        command.env("RESTIR_FUZZ_SEED", "1");
    }
    let child = command
        .arg("-c")
        .arg(script)
        .arg(exe)
        .arg(input)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn();
    let mut child = match child {
        Ok(c) => c,
        Err(e) => return Outcome::Failed(format!("cannot start the child: {e}")),
    };
    let start = Instant::now();
    loop {
        match child.try_wait() {
            Ok(Some(status)) if status.success() => return Outcome::Fine,
            Ok(Some(status)) => {
                let mut err = String::new();
                if let Some(mut s) = child.stderr.take() {
                    let _ = std::io::Read::read_to_string(&mut s, &mut err);
                }
                let last = err.lines().rev().take(3).collect::<Vec<_>>().join(" / ");
                return Outcome::Failed(format!("{status}: {last}"));
            }
            Ok(None) if start.elapsed() > TIME_LIMIT => {
                let _ = child.kill();
                let _ = child.wait();
                return Outcome::Failed(format!("no answer within {TIME_LIMIT:?} (a hang?)"));
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(2)),
            Err(e) => return Outcome::Failed(format!("cannot wait for the child: {e}")),
        }
    }
}

/// The seeds of `target`, by name.
fn seeds(corpus: &Path, target: &str) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(corpus.join(target))
        .map(|d| {
            d.filter_map(Result::ok)
                .filter_map(|e| {
                    let name = e.file_name().to_string_lossy().into_owned();
                    std::fs::read(e.path()).ok().map(|b| (name, b))
                })
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}

struct Options {
    seconds: f64,
    seed: u64,
    targets: Vec<String>,
    work: PathBuf,
}

fn parse(args: &[String]) -> Result<Options, String> {
    let mut o = Options {
        seconds: 20.0,
        seed: 1,
        targets: Vec::new(),
        work: std::env::temp_dir().join(format!("restir-fuzz-{}", std::process::id())),
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--seconds" => o.seconds = value()?.parse().map_err(|_| "bad --seconds")?,
            "--seed" => o.seed = value()?.parse().map_err(|_| "bad --seed")?,
            "--target" => {
                let t = value()?.clone();
                if !TARGETS.contains(&t.as_str()) {
                    return Err(format!("unknown target '{t}' (one of {TARGETS:?})"));
                }
                o.targets.push(t);
            }
            "--work" => o.work = PathBuf::from(value()?),
            other => return Err(format!("unknown option '{other}'")),
        }
    }
    if o.targets.is_empty() {
        o.targets = TARGETS.iter().map(|t| t.to_string()).collect();
    }
    Ok(o)
}

/// Fuzzes every chosen target for `seconds` each; the exit status says whether anything failed.
fn run(o: &Options) -> ExitCode {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus");
    let Ok(exe) = std::env::current_exe() else {
        eprintln!("cannot find the harness executable");
        return ExitCode::FAILURE;
    };
    let mut failures = 0usize;
    let mut total = 0usize;
    for target in &o.targets {
        let seeds = seeds(&corpus, target);
        if seeds.is_empty() {
            eprintln!("{target}: no seeds in {}", corpus.join(target).display());
            return ExitCode::FAILURE;
        }
        let dir = o.work.join(target);
        if std::fs::create_dir_all(&dir).is_err() {
            eprintln!("cannot create {}", dir.display());
            return ExitCode::FAILURE;
        }
        let others: Vec<Vec<u8>> = seeds.iter().map(|(_, b)| b.clone()).collect();
        let mut rng = Rng(o.seed ^ (target.len() as u64) << 32 ^ target.as_bytes()[0] as u64);
        let start = Instant::now();
        let (mut n, mut failed) = (0usize, 0usize);
        while start.elapsed().as_secs_f64() < o.seconds {
            let (name, seed) = &seeds[n % seeds.len()];
            // The seeds first, as they are (they must load), then mutations.
            // Half of the cache's inputs are crafted tables with a valid checksum.
            let bytes = if n < seeds.len() {
                seed.clone()
            } else if target == "cache" && n % 2 == 1 {
                mutate_table(&mut rng, seed, &others)
            } else {
                mutate(&mut rng, seed, &others)
            };
            // Everything after the name's first dot (`scene.ron` tells a RON scene with its
            // animation inline from a sidecar).
            let ext = name.split_once('.').map_or(target.as_str(), |(_, e)| e);
            // A cache input keeps its seed's name (the table's), in a directory of its own.
            let input = if target == "cache" {
                dir.join("cache").join(name)
            } else {
                dir.join(format!("input.{ext}"))
            };
            if let Some(parent) = input.parent()
                && std::fs::create_dir_all(parent).is_err()
            {
                eprintln!("cannot create {}", parent.display());
                return ExitCode::FAILURE;
            }
            if std::fs::File::create(&input)
                .and_then(|mut f| f.write_all(&bytes))
                .is_err()
            {
                eprintln!("cannot write {}", input.display());
                return ExitCode::FAILURE;
            }
            if let Outcome::Failed(why) = check(&exe, target, &input, n < seeds.len()) {
                failed += 1;
                let keep = dir.join(format!("failure-{n}.{ext}"));
                let _ = std::fs::copy(&input, &keep);
                println!("{target}: FAILED on {} ({why})", keep.display());
            }
            n += 1;
        }
        println!(
            "{target}: {n} inputs in {:.0} s, {failed} failures",
            start.elapsed().as_secs_f64()
        );
        total += n;
        failures += failed;
    }
    println!("{total} inputs, {failures} failures");
    if failures == 0 {
        let _ = std::fs::remove_dir_all(&o.work);
        ExitCode::SUCCESS
    } else {
        println!("failing inputs kept in {}", o.work.display());
        ExitCode::FAILURE
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("one") if args.len() == 3 => run_one(&args[1], Path::new(&args[2])),
        Some("run") => match parse(&args[1..]) {
            Ok(o) => run(&o),
            Err(e) => {
                eprintln!("restir-fuzz: {e}");
                ExitCode::from(2)
            }
        },
        _ => {
            eprintln!(
                "usage: restir-fuzz run [--seconds S] [--seed N] [--target T]... [--work DIR]\n       restir-fuzz one <target> <input>"
            );
            ExitCode::from(2)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A suite whose scene path and label hold a newline and a NUL (found by the `suite`
    /// target) gets a one-line error with them escaped.
    #[test]
    fn suite_errors_stay_on_one_line() {
        let seed = include_str!("../corpus/suite/smoke.ron");
        let text = seed
            .replacen("../cornell-box.xml", "../cornell-box.x\nml", 1)
            .replacen("\"restir-di tuned\"]", "\"resti\0r-di tuned\"]", 1);
        assert_ne!(text, seed);
        let e = restir_evaluation::Suite::parse(&text, Path::new("s.ron"))
            .unwrap_err()
            .to_string();
        assert!(!e.contains('\n') && !e.contains('\0'), "{e}");
        assert!(e.contains("x\\nml") && e.contains("resti\\u{0}r-di"), "{e}");
        // The seed itself loads.
        restir_evaluation::Suite::parse(seed, Path::new("s.ron")).unwrap();
    }

    /// The cache seed is named for the table version the cache reads, so that the target
    /// reaches the reader (a stale name would only be rebuilt; the seed run catches that too).
    #[test]
    fn the_cache_seed_has_a_current_name() {
        let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus");
        let prefix = format!(
            "roughplastic-v{}-",
            restir_materials::table_cache::TABLE_VERSION
        );
        let seeds = seeds(&corpus, "cache");
        assert!(!seeds.is_empty());
        for (name, _) in seeds {
            assert!(
                name.starts_with(&prefix),
                "{name} does not start with {prefix}"
            );
        }
    }

    /// A crafted table keeps the cache file's shape and carries a valid checksum, so that it
    /// reaches the reader's value checks; it differs from its seed.
    #[test]
    fn crafted_tables_pass_the_checksum() {
        let (_, seed) = &seeds(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus"),
            "cache",
        )[0];
        let mut rng = Rng(3);
        let mut changed = 0;
        for _ in 0..100 {
            let t = mutate_table(&mut rng, seed, &[]);
            assert_eq!(t.len(), seed.len());
            let body = t.len() - 8;
            let sum = u64::from_le_bytes(t[body..].try_into().unwrap());
            assert_eq!(sum, restir_sampling::hash::fnv1a(&t[..body]));
            changed += usize::from(t != *seed);
        }
        assert!(changed > 80, "{changed}");
    }

    /// The mutator is deterministic and does change its input.
    #[test]
    fn mutations_are_reproducible() {
        let seed = b"<float name=\"radius\" value=\"0.5\"/>".to_vec();
        let a: Vec<Vec<u8>> = {
            let mut r = Rng(7);
            (0..50).map(|_| mutate(&mut r, &seed, &[])).collect()
        };
        let b: Vec<Vec<u8>> = {
            let mut r = Rng(7);
            (0..50).map(|_| mutate(&mut r, &seed, &[])).collect()
        };
        assert_eq!(a, b);
        assert!(a.iter().filter(|m| **m != seed).count() > 40);
    }
}
