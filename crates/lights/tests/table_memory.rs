//! What the light tables cost per emissive triangle, measured with a counting global allocator
//! (this test binary's own; the library allocates normally): the emitter table with its alias
//! table (what every estimator keeps), and the light hierarchy (built when a light sampler
//! asks for it). Run with `--nocapture` to see the numbers.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::Vec3;
use restir_geometry::{Shape, TriangleMesh};
use restir_lights::{Light, LightSet};

struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is forwarded to the system allocator unchanged; only counters are updated.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(l) };
        if !p.is_null() {
            let now = LIVE.fetch_add(l.size(), Ordering::Relaxed) + l.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) };
        LIVE.fetch_sub(l.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        let q = unsafe { System.realloc(p, l, new) };
        if !q.is_null() {
            if new >= l.size() {
                let now = LIVE.fetch_add(new - l.size(), Ordering::Relaxed) + new - l.size();
                PEAK.fetch_max(now, Ordering::Relaxed);
            } else {
                LIVE.fetch_sub(l.size() - new, Ordering::Relaxed);
            }
        }
        q
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Runs `f`, returning its result, the bytes still allocated after it beyond those before, and
/// the peak above the start while it ran.
fn measure<T>(f: impl FnOnce() -> T) -> (T, usize, usize) {
    let start = LIVE.load(Ordering::Relaxed);
    PEAK.store(start, Ordering::Relaxed);
    let out = f();
    let kept = LIVE.load(Ordering::Relaxed).saturating_sub(start);
    let peak = PEAK.load(Ordering::Relaxed) - start;
    (out, kept, peak)
}

/// A bumpy height field of `n × n` quads (`2n²` triangles).
fn grid(n: usize) -> TriangleMesh {
    let s = n + 1;
    let positions = (0..s * s)
        .map(|i| {
            let (x, y) = ((i % s) as f32, (i / s) as f32);
            Vec3::new(x, y, (0.37 * x).sin() * (0.23 * y).cos())
        })
        .collect();
    let mut indices = Vec::with_capacity(2 * n * n);
    for y in 0..n {
        for x in 0..n {
            let a = (y * s + x) as u32;
            let (b, c, d) = (a + 1, a + s as u32, a + s as u32 + 1);
            indices.push([a, b, d]);
            indices.push([a, d, c]);
        }
    }
    TriangleMesh::new(positions, None, None, indices, false).unwrap()
}

/// 300² quads: 180 000 emissive triangles.
const N: usize = 300;

/// The most the emitter table (entries and alias table) may keep per emissive triangle.
const TABLE_BYTES_PER_TRIANGLE: f64 = 78.0;

#[test]
fn bytes_per_emissive_triangle() {
    let shapes: std::sync::Arc<[Shape]> = vec![Shape::Mesh(grid(N))].into();
    let tris = (2 * N * N) as f64;
    let bounds = (Vec3::ZERO, Vec3::new(N as f32, N as f32, 1.0));
    let (set, kept, peak) = measure(|| {
        LightSet::new(
            vec![Light::Area {
                shape: 0,
                radiance: Vec3::ONE,
            }],
            shapes.clone(),
            bounds,
        )
        .unwrap()
    });
    let ((), h_kept, h_peak) = measure(|| {
        set.build_hierarchy();
    });
    println!(
        "{:<28} {:>12} {:>12}",
        "per emissive triangle", "kept B", "peak B"
    );
    println!(
        "{:<28} {:>12.1} {:>12.1}",
        "emitter table",
        kept as f64 / tris,
        peak as f64 / tris
    );
    println!(
        "{:<28} {:>12.1} {:>12.1}",
        "light hierarchy",
        h_kept as f64 / tris,
        h_peak as f64 / tris
    );
    let per = kept as f64 / tris;
    assert!(
        per <= TABLE_BYTES_PER_TRIANGLE,
        "the emitter table keeps {per:.1} bytes per emissive triangle, more than {TABLE_BYTES_PER_TRIANGLE}"
    );
    // Negative control: the measurement sees the table (it is not zero for want of counting).
    assert!(
        per >= 24.0,
        "{per:.1} bytes per triangle is too few to be the table"
    );
}
