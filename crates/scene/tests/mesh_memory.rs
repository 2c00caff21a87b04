//! What a triangle costs in memory at each stage of loading a mesh, measured with a counting
//! global allocator (this test binary's own; the library allocates normally): the mesh file read
//! and parsed, the runtime mesh with its area tables, the BVH (its build peak, obvhs's temporary
//! memory included, and what it keeps), the light tables of an emissive mesh, and whole scene
//! loads, plain and emissive with the light hierarchy built. Run with `--nocapture` to see the
//! table; the loads must stay under the estimates `--max-memory` checks meshes and emitters with
//! (`restir_scene::desc::limits::MESH_BYTES_PER_TRIANGLE` and the vertex data,
//! `EMITTER_BYTES_PER_ENTRY`), and the BVH build under what obvhs's conversion alone needs and
//! a little more (none of our own copies alive then).

use std::io::Write;
use std::sync::Mutex;

use glam::Vec3;
use restir_geometry::{Accel, Shape, TriangleMesh};
use restir_lights::{Light, LightSet};
use restir_scene::{LoadOptions, load_scene};
use restir_testkit::{CountingAllocator, TempDir, measure};

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
    // obvhs's conversion to the wide tree holds the binary tree (68 bytes per triangle), its
    // cost decisions (112) and the wide nodes it reserves (84): 264.
    assert!(
        per(bvh_peak) <= 270.0,
        "the BVH build peaks at {:.1} bytes per triangle, more than obvhs's conversion needs",
        per(bvh_peak)
    );
    let bounds = accel.bounds();
    let (lights, light_kept, light_peak) = measure(|| {
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
    rows.push(("light tables (emissive mesh)", light_kept, light_peak));
    drop((lights, accel, shapes));

    // The whole pipeline from a binary PLY file.
    let dir = TempDir::new("mesh-memory", "ply");
    let (positions, indices) = grid(N);
    write_ply(&dir.join("grid.ply"), &positions, &indices);
    drop((positions, indices));
    let scene = |emissive: bool| {
        let path = dir.join(format!("scene-{emissive}.ron"));
        let (emission, lights) = if emissive {
            (", emission: Some((1, 1, 1))", "")
        } else {
            ("", "Point(position: (350, 350, 100), intensity: (1, 1, 1))")
        };
        std::fs::write(
            &path,
            format!(
                "(camera: (fov: 40, to_world: [LookAt(origin: (350, 350, 900), target: (350, \
                 350, 0), up: (0, 1, 0))]), film: (width: 8, height: 8, filter: Box), spp: 1, \
                 integrator: (kind: \"path\", max_depth: 2), materials: [], \
                 shapes: [(geometry: Ply(filename: \"grid.ply\"){emission})], lights: [{lights}])"
            ),
        )
        .unwrap();
        path
    };
    let (loaded, plain_kept, plain_peak) =
        measure(|| load_scene(&scene(false), &LoadOptions::default()).unwrap());
    rows.push(("whole load (PLY)", plain_kept, plain_peak));
    drop(loaded);
    // The emissive mesh with the light hierarchy a light sampler builds over its triangles.
    let (loaded, emissive_kept, emissive_peak) = measure(|| {
        let loaded = load_scene(&scene(true), &LoadOptions::default()).unwrap();
        loaded.scene.lights.build_hierarchy();
        loaded
    });
    rows.push((
        "whole load, emissive, hierarchy",
        emissive_kept,
        emissive_peak,
    ));
    drop(loaded);
    drop(dir);

    println!("{:<34} {:>12} {:>12}", "stage", "kept B/tri", "peak B/tri");
    for (name, kept, peak) in &rows {
        println!("{name:<34} {:>12.1} {:>12.1}", per(*kept), per(*peak));
    }
    // The estimates: per triangle, and the positions (12 bytes per vertex); an emissive
    // triangle's light tables on top.
    let vertices = ((N + 1) * (N + 1)) as f64;
    let estimate =
        restir_scene::desc::limits::MESH_BYTES_PER_TRIANGLE as f64 + 12.0 * vertices / tris;
    assert!(
        per(plain_peak) <= estimate,
        "a scene load peaks at {:.1} bytes per triangle, above the estimate of {estimate:.1}",
        per(plain_peak)
    );
    let emissive_estimate = estimate + restir_scene::desc::limits::EMITTER_BYTES_PER_ENTRY as f64;
    assert!(
        per(emissive_peak) <= emissive_estimate,
        "an emissive load with its light hierarchy peaks at {:.1} bytes per triangle, above \
         the estimate of {emissive_estimate:.1}",
        per(emissive_peak)
    );
}
