//! `restir-fuzz`: deterministic mutation fuzzing of the scene loader, one target per input format
//! (`xml`, `ron`, `obj`, `ply`, `serialized`, `exr`, `hdr`, `png`), the reader of the parts
//! of a split render that `restir merge` reads (`part`: `restir_image::Image::read_exr_part`),
//! `restir bench` suite files (`suite`: `restir_evaluation::Suite::load_located`), animation
//! files (`anim`: an XML scene's `NAME.anim.ron` sidecar, loaded with the scene and built at a
//! few times) and the rough-plastic table cache (`cache`: a file at a table's name in the cache
//! directory, read when a scene with that material loads).
//!
//! Coverage-guided fuzzers need nightly Rust (cargo-fuzz) or an AFL++ toolchain; this workspace
//! builds on one stable toolchain, so the harness mutates the checked-in seeds in
//! `crates/fuzz/corpus/<target>/` with a fixed-seed generator (byte flips and overwrites,
//! interesting integers, numbers replaced by `1e38`, `NaN`, `-0`, huge counts, chunk
//! duplication, splices, truncation) and loads each input (`restir_scene::load_scene`, the
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

/// SplitMix64: the mutator's random numbers (fixed seed, so a run is reproducible).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Numbers that stress a loader where a number is expected.
const NUMBERS: [&str; 14] = [
    "1e38",
    "3e38",
    "1e39",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "-0",
    "1e20",
    "1e-45",
    "4294967295",
    "-1",
    "99999999999999999999",
    "65536",
];

/// Integers that stress a binary header.
const INTEGERS: [u64; 10] = [
    0,
    1,
    0xFF,
    0xFFFF,
    0x7FFF_FFFF,
    0xFFFF_FFFF,
    0x8000_0000,
    1 << 32,
    u64::MAX,
    0x7FC0_0000, // f32 NaN
];

/// One mutation of `input` (`others` are the target's seeds, for splicing).
fn mutate(rng: &mut Rng, input: &[u8], others: &[Vec<u8>]) -> Vec<u8> {
    let mut v = input.to_vec();
    let rounds = 1 + rng.below(4);
    for _ in 0..rounds {
        let len = v.len().max(1);
        match rng.below(9) {
            0 if !v.is_empty() => {
                let i = rng.below(v.len());
                v[i] ^= 1 << rng.below(8);
            }
            1 if !v.is_empty() => {
                let i = rng.below(v.len());
                v[i] = rng.next() as u8;
            }
            2 => {
                // An interesting integer, little- or big-endian, 1 to 8 bytes wide.
                let x = INTEGERS[rng.below(INTEGERS.len())];
                let w = [1, 2, 4, 8][rng.below(4)];
                let bytes = if rng.below(2) == 0 {
                    x.to_le_bytes()
                } else {
                    x.to_be_bytes()
                };
                let at = rng.below(len);
                for k in 0..w {
                    if let Some(b) = v.get_mut(at + k) {
                        *b = bytes[if rng.below(2) == 0 { k } else { 8 - w + k }];
                    }
                }
            }
            3 => {
                // Replace a number in text by a stressful one.
                let starts: Vec<usize> = (0..v.len())
                    .filter(|&i| {
                        v[i].is_ascii_digit() && (i == 0 || !v[i - 1].is_ascii_alphanumeric())
                    })
                    .collect();
                if !starts.is_empty() {
                    let s = starts[rng.below(starts.len())];
                    let e = (s..v.len())
                        .find(|&i| !(v[i].is_ascii_digit() || b".eE-+".contains(&v[i])))
                        .unwrap_or(v.len());
                    let n = NUMBERS[rng.below(NUMBERS.len())].as_bytes();
                    v.splice(s..e, n.iter().copied());
                }
            }
            4 => {
                // Duplicate a chunk many times (amplification, huge element lists).
                let s = rng.below(len);
                let e = (s + 1 + rng.below(64)).min(v.len());
                if s < e {
                    let chunk = v[s..e].to_vec();
                    let times = 1 + rng.below(200);
                    for _ in 0..times {
                        v.splice(e..e, chunk.iter().copied());
                    }
                }
            }
            5 => {
                let s = rng.below(len);
                let e = (s + rng.below(32)).min(v.len());
                if s < e {
                    v.drain(s..e);
                }
            }
            6 => v.truncate(rng.below(len)),
            7 if !others.is_empty() => {
                let o = &others[rng.below(others.len())];
                let at = rng.below(len).min(v.len());
                let from = rng.below(o.len().max(1)).min(o.len());
                v.truncate(at);
                v.extend_from_slice(&o[from..]);
            }
            _ => {
                let at = rng.below(len).min(v.len());
                let b = [b'$', b'<', b'>', b'"', b'\0', b'\n', b'(', b')', b',', b'-'];
                v.insert(at, b[rng.below(b.len())]);
            }
        }
    }
    v
}

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

/// An animation input: the sidecar of [`ANIM_SCENE`], the scene loaded with it and built at a
/// few times (inside, before, after and far beyond its keys).
fn load_animated(input: &Path) -> Result<(), String> {
    let dir = input.parent().unwrap_or(Path::new("."));
    let scene = dir.join("anim-scene.xml");
    std::fs::write(&scene, ANIM_SCENE).map_err(|e| e.to_string())?;
    std::fs::copy(input, restir_scene::sidecar_path(&scene)).map_err(|e| e.to_string())?;
    let loaded = restir_scene::load_scene(&scene, &restir_scene::LoadOptions::default())
        .map_err(|e| e.to_string())?;
    for t in [0.0, 1.3, -1.0, 1e6] {
        restir_scene::animation::build_at(&loaded.desc, &scene, t).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// A table cache input: `input` lies in a directory of its own under the name of the table the
/// seed holds; that directory is the cache while [`CACHE_SCENE`] loads. A seed must be read as
/// it is (the loader rebuilding and replacing it would mean its name or contents went stale, and
/// the target no longer reached the reader).
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
    Ok(())
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
            let bytes = if n < seeds.len() {
                seed.clone()
            } else {
                mutate(&mut rng, seed, &others)
            };
            let ext = Path::new(name)
                .extension()
                .and_then(|e| e.to_str())
                .unwrap_or(target);
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
