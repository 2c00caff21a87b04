//! Times this renderer's BVH on rays read from a file, one thread: the other half of
//! `scripts/mitsuba_rays.py`, which writes the rays, times Mitsuba 3 (Embree) on the same ones
//! and runs this program between its own timings.
//!
//! ```text
//! cargo run --release -p restir-bench --example ray_file -- SCENE RAYS REPEATS
//! ```
//!
//! `RAYS` holds three ray sets, each a little-endian `u32` count and then per ray seven `f32`
//! (origin, direction, `t_max`): closest-hit rays from the camera, closest-hit rays in random
//! directions, shadow rays. Prints one line per set: its name, the rays hit (or occluded), and
//! the median wall-clock nanoseconds per ray over `REPEATS` passes through the set.

use std::path::Path;
use std::time::Instant;

use glam::Vec3;
use restir_geometry::Ray;
use restir_scene::{Scene, load_desc};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, scene, rays, repeats] = &args[..] else {
        eprintln!("usage: ray_file SCENE RAYS REPEATS");
        std::process::exit(2);
    };
    let repeats: usize = repeats
        .parse()
        .unwrap_or_else(|e| fail(&format!("REPEATS: {e}")));
    let path = Path::new(scene);
    let (desc, _) = load_desc(path, &[]).unwrap_or_else(|e| fail(&e.to_string()));
    let dir = path.parent().unwrap_or(Path::new("."));
    let scene = Scene::build(&desc, dir, path).unwrap_or_else(|e| fail(&e.to_string()));
    let bytes = std::fs::read(rays).unwrap_or_else(|e| fail(&format!("{rays}: {e}")));
    let mut at = 0;
    for name in ["camera", "incoherent", "shadow"] {
        let set = read_set(&bytes, &mut at).unwrap_or_else(|| fail(&format!("{rays}: truncated")));
        let shadow = name == "shadow";
        let trace = |(ray, t): &(Ray, f32)| {
            if shadow {
                scene.accel.occluded(ray, *t)
            } else {
                scene.accel.intersect(ray, *t).is_some()
            }
        };
        let hits = set.iter().filter(|r| trace(r)).count();
        let mut times: Vec<f64> = (0..repeats.max(1))
            .map(|_| {
                let start = Instant::now();
                let n = set.iter().filter(|r| trace(r)).count();
                std::hint::black_box(n);
                start.elapsed().as_secs_f64() * 1e9 / set.len().max(1) as f64
            })
            .collect();
        times.sort_by(f64::total_cmp);
        println!("{name} {hits}/{} {:.2}", set.len(), times[times.len() / 2]);
    }
}

fn read_set(bytes: &[u8], at: &mut usize) -> Option<Vec<(Ray, f32)>> {
    let mut word = || {
        let w = bytes.get(*at..*at + 4)?;
        *at += 4;
        Some([w[0], w[1], w[2], w[3]])
    };
    let n = u32::from_le_bytes(word()?) as usize;
    let mut set = Vec::with_capacity(n);
    for _ in 0..n {
        let mut f = [0.0f32; 7];
        for x in &mut f {
            *x = f32::from_le_bytes(word()?);
        }
        let ray = Ray::new(Vec3::new(f[0], f[1], f[2]), Vec3::new(f[3], f[4], f[5]));
        set.push((ray, f[6]));
    }
    Some(set)
}

fn fail(msg: &str) -> ! {
    eprintln!("error: {msg}");
    std::process::exit(1);
}
