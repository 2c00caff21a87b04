//! Checks of the command line made before anything is rendered: flags the chosen estimator
//! does not use, the thread count, and the memory a film needs.

use restir_integrators::film::Reconstruction;
use restir_integrators::{
    Integrator, IntegratorOptions, MadeIntegrator, ParamSet, ParamSource, make_integrator,
};
use restir_scene::{IntegratorDesc, Scene};

/// The estimators that take parameters (`auto`, the fourth name `--integrator` accepts, takes
/// none).
pub const INTEGRATORS: [&str; 3] = ["path", "restir-di", "restir-pt"];

/// A command-line flag the chosen estimator does not use is an error naming the estimators that
/// do (a scene file's unused parameters stay warnings with their line).
pub fn check_flags_used(
    scene: &Scene,
    integrator: &IntegratorDesc,
    made: &MadeIntegrator,
) -> Result<(), String> {
    let Some(p) = made
        .unused_params
        .iter()
        .find(|p| p.source == ParamSource::Flag)
    else {
        return Ok(());
    };
    // Which estimators read it: those that leave it unused are not among them.
    let users: Vec<&str> = INTEGRATORS
        .into_iter()
        .filter(|name| {
            let mut params = ParamSet::new();
            params.push(p.clone());
            let options = IntegratorOptions {
                name: Some(name.to_string()),
                max_depth: None,
                params,
                sampler: None,
            };
            match make_integrator(scene, integrator, &options) {
                Ok(m) => m.unused_params.is_empty(),
                // It read the value (and disliked it): it uses the flag.
                Err(_) => true,
            }
        })
        .collect();
    Err(format!(
        "--{} is not an option of the integrator '{}' (used by: {})",
        p.name.replace('_', "-"),
        made.integrator.name(),
        users.join(", ")
    ))
}

/// The most worker threads `--threads` accepts: more is a typo on any machine this renders on.
pub const MAX_THREADS: usize = 256;

/// The render pool: `threads` workers (0 or absent: one per core), at most [`MAX_THREADS`].
pub fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, String> {
    let threads = threads.unwrap_or(0);
    if threads > MAX_THREADS {
        return Err(format!(
            "--threads {threads}: expected 1 to {MAX_THREADS} (0 or no flag = one per core)"
        ));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| format!("cannot start {threads} threads: {e}"))
}

/// Bytes per pixel every render needs beside the estimator's own buffers: the film's sums
/// (3 × f64), one pass's image and the output image (3 × f32 each).
pub const FILM_BYTES_PER_PIXEL: u64 = 24 + 12 + 12;

/// Bytes per pixel the film adds for a `moment` integrator's second moment: the sums of the
/// squares and one pass's estimates (3 × f64 each).
pub const MOMENT_BYTES_PER_PIXEL: u64 = 24 + 24;

/// The default of `--max-memory`, in GiB.
pub const DEFAULT_MAX_MEMORY_GIB: f64 = 8.0;

/// Refuses, before anything is allocated, a film whose estimated memory (film, pass and output
/// images, the splatting film's buffers, the estimator's buffers on `threads` threads) exceeds
/// `max_gib` GiB.
pub fn check_memory(
    (width, height): (u32, u32),
    threads: usize,
    integrator: &dyn Integrator,
    reconstruction: &Reconstruction,
    moment: bool,
    max_gib: f64,
) -> Result<(), String> {
    let pixels = width as u64 * height as u64;
    let film = FILM_BYTES_PER_PIXEL
        + reconstruction.buffer_bytes_per_pixel() as u64
        + if moment { MOMENT_BYTES_PER_PIXEL } else { 0 };
    let need = pixels
        .saturating_mul(film)
        .saturating_add(integrator.buffer_bytes(width, height, threads));
    let per_pixel = need.div_ceil(pixels.max(1));
    let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
    if gib(need) > max_gib {
        return Err(format!(
            "a {width}×{height} film with {} needs about {:.1} GiB ({per_pixel} bytes per pixel), \
             more than the limit of {max_gib} GiB: render smaller or raise --max-memory",
            integrator.name(),
            gib(need)
        ));
    }
    Ok(())
}

/// `--max-memory`: a positive, finite number of GiB.
pub fn max_memory(gib: Option<f64>) -> Result<f64, String> {
    match gib {
        None => Ok(DEFAULT_MAX_MEMORY_GIB),
        Some(g) if g.is_finite() && g > 0.0 => Ok(g),
        Some(g) => Err(format!(
            "--max-memory {g}: expected a positive number of GiB"
        )),
    }
}
