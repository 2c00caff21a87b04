//! What a triangle costs in memory at each stage of loading a mesh, measured with a counting
//! global allocator (this test binary's own; the library allocates normally): the mesh file read
//! and parsed, the runtime mesh with its area tables, the BVH (its build peak, obvhs's temporary
//! memory included, and what it keeps), the light tables of an emissive mesh, and a whole scene
//! load. Run with `--nocapture` to see the table; the whole load must stay under
//! the estimate `--max-memory` checks meshes with
//! (`restir_scene::desc::limits::MESH_BYTES_PER_TRIANGLE` and the vertex data).

use std::io::Write;
use std::sync::Mutex;

use glam::Vec3;
use restir_geometry::{Accel, Shape, TriangleMesh};
use restir_lights::{Light, LightSet};
use restir_scene::{LoadOptions, load_scene};
use restir_testkit::{CountingAllocator, measure};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// The tests of this file measure one at a time (the counters are global).
static SERIAL: Mutex<()> = Mutex::new(());

/// A height field of `n × n` quads (`2n²` triangles) with every vertex at a different height,
/// so no two triangles share bounds.
fn grid(n: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
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
    (positions, indices)
}

fn write_ply(path: &std::path::Path, positions: &[Vec3], indices: &[[u32; 3]]) {
    let mut out = Vec::new();
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\n\
         property float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        positions.len(),
        indices.len()
    )
    .unwrap();
    for p in positions {
        for c in p.to_array() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in indices {
        out.push(3);
        for v in t {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(path, out).unwrap();
}

/// 707² quads: 999 698 triangles.
const N: usize = 707;

#[test]
fn bytes_per_triangle_at_each_stage() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tris = (2 * N * N) as f64;
    let per = |b: usize| b as f64 / tris;
    let mut rows = Vec::new();

    let ((positions, indices), data, _) = measure(|| grid(N));
    rows.push(("mesh data (positions, indices)", data, data));
    let (mesh, kept, peak) =
        measure(|| TriangleMesh::new(positions, None, None, indices, false).unwrap());
    // The vectors moved into the mesh were counted in the data row already.
    rows.push(("runtime mesh: tables added", kept, peak));
    // Shared as the scene shares them, so the light set holds no copy.
    let shapes: std::sync::Arc<[Shape]> = vec![Shape::Mesh(mesh)].into();
    let (accel, bvh_kept, bvh_peak) = measure(|| Accel::build(&shapes));
    rows.push(("BVH build", bvh_kept, bvh_peak));
    let bounds = accel.bounds();
    let (lights, light_kept, light_peak) = measure(|| {
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
    rows.push(("light tables (emissive mesh)", light_kept, light_peak));
    drop((lights, accel, shapes));

    // The whole pipeline from a binary PLY file.
    let dir = std::env::temp_dir().join(format!("restir-mesh-memory-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (positions, indices) = grid(N);
    write_ply(&dir.join("grid.ply"), &positions, &indices);
    drop((positions, indices));
    let scene = dir.join("scene.ron");
    std::fs::write(
        &scene,
        "(camera: (fov: 40, to_world: [LookAt(origin: (350, 350, 900), target: (350, 350, 0), \
         up: (0, 1, 0))]), film: (width: 8, height: 8, filter: Box), spp: 1, \
         integrator: (kind: \"path\", max_depth: 2), materials: [], \
         shapes: [(geometry: Ply(filename: \"grid.ply\"), emission: Some((1, 1, 1)))], lights: [])",
    )
    .unwrap();
    let (loaded, scene_kept, scene_peak) =
        measure(|| load_scene(&scene, &LoadOptions::default()).unwrap());
    rows.push(("whole load (PLY, emissive)", scene_kept, scene_peak));
    drop(loaded);
    std::fs::remove_dir_all(&dir).ok();

    println!("{:<34} {:>12} {:>12}", "stage", "kept B/tri", "peak B/tri");
    for (name, kept, peak) in &rows {
        println!("{name:<34} {:>12.1} {:>12.1}", per(*kept), per(*peak));
    }
    // The estimate: per triangle, and the positions (12 bytes per vertex).
    let vertices = ((N + 1) * (N + 1)) as f64;
    let estimate =
        restir_scene::desc::limits::MESH_BYTES_PER_TRIANGLE as f64 + 12.0 * vertices / tris;
    assert!(
        per(scene_peak) <= estimate,
        "a scene load peaks at {:.1} bytes per triangle, above the estimate of {estimate:.1}",
        per(scene_peak)
    );
}
