//! What the light tables cost per emissive triangle, measured with a counting global allocator
//! (this test binary's own; the library allocates normally): the emitter table with its alias
//! table (what every estimator keeps), and the light hierarchy (built when a light sampler
//! asks for it). Run with `--nocapture` to see the numbers.

use glam::Vec3;
use restir_geometry::{Shape, TriangleMesh};
use restir_lights::{Light, LightSet};
use restir_testkit::{CountingAllocator, measure};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

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
                texture: None,
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
