//! A harness for counting the instructions of light sampling over many emissive triangles
//! (`valgrind --tool=callgrind`, whose counts are deterministic where wall times are not).
//!
//! ```text
//! light_sampling_cost MODE NORMALS TRIANGLES SAMPLES
//!   MODE     power (LightSet::sample) | hierarchy (LightSet::sample_hierarchy)
//!            | point (LightSet::area_point, a point named by triangle and barycentrics)
//!   NORMALS  none | constant (three equal vertex normals per triangle) | smooth
//! ```
//!
//! The triangles are a soup over a bumpy grid. Run it twice with different `SAMPLES` and divide
//! the difference of the two instruction counts by the difference of `SAMPLES`: what is left is
//! the cost of one sample, without the setup.

use glam::{Vec2, Vec3};
use restir_geometry::{Shape, TriangleMesh};
use restir_lights::{Light, LightSet};

/// A uniform number in [0, 1) from a counter (a 32-bit integer hash).
fn hash01(mut x: u32) -> f32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

fn soup(triangles: usize, normals: &str) -> TriangleMesh {
    let side = (triangles as f64 / 2.0).sqrt().ceil() as usize;
    let height = |x: f32, y: f32| 0.3 * (0.37 * x).sin() * (0.23 * y).cos();
    let mut positions = Vec::with_capacity(3 * triangles);
    let mut ns = Vec::with_capacity(3 * triangles);
    for t in 0..triangles {
        let q = t / 2;
        let (x, y) = ((q % side) as f32, (q / side) as f32);
        let corners = if t % 2 == 0 {
            [(x, y), (x + 1.0, y), (x + 1.0, y + 1.0)]
        } else {
            [(x, y), (x + 1.0, y + 1.0), (x, y + 1.0)]
        };
        for (k, (cx, cy)) in corners.into_iter().enumerate() {
            positions.push(Vec3::new(cx, cy, height(cx, cy)));
            ns.push(match normals {
                "constant" => Vec3::new(0.1, 0.2, 1.0),
                _ => Vec3::new(0.1 * k as f32, 0.05 * (t % 7) as f32, 1.0),
            });
        }
    }
    let indices = (0..triangles as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    let ns = (normals != "none").then_some(ns);
    TriangleMesh::new(positions, ns, None, indices, true).expect("a valid mesh")
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [mode, normals, triangles, samples] = args.as_slice() else {
        eprintln!(
            "usage: light_sampling_cost power|hierarchy|point none|constant|smooth TRIANGLES SAMPLES"
        );
        std::process::exit(1);
    };
    let triangles: usize = triangles.parse().expect("TRIANGLES: a count");
    let samples: u32 = samples.parse().expect("SAMPLES: a count");
    let mesh = soup(triangles, normals);
    let (lo, hi) = mesh
        .positions()
        .iter()
        .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let shapes: std::sync::Arc<[Shape]> = vec![Shape::Mesh(mesh)].into();
    let lights = vec![Light::Area {
        shape: 0,
        radiance: Vec3::ONE,
        texture: None,
    }];
    let set = LightSet::new(lights, shapes.clone(), (lo, hi)).expect("a light set");
    if mode == "hierarchy" {
        set.build_hierarchy();
    }
    let centre = 0.5 * (lo + hi);
    let mut acc = 0.0f64;
    for i in 0..samples {
        let us = hash01(3 * i);
        let u = Vec2::new(hash01(3 * i + 1), hash01(3 * i + 2));
        let ref_p = centre + Vec3::new(8.0 * (us - 0.5), 5.0 * (u.x - 0.5), -4.0);
        match mode.as_str() {
            "power" => {
                if let Some(s) = set.sample(ref_p, us, u) {
                    acc += s.pdf_sa as f64;
                }
            }
            "hierarchy" => {
                if let Some((s, p)) = set.sample_hierarchy(ref_p, Vec3::Z, us as f64, u) {
                    acc += (s.pdf_sa + p) as f64;
                }
            }
            "point" => {
                let prim = ((us * triangles as f32) as u32).min(triangles as u32 - 1);
                let b = if u.x + u.y > 1.0 { Vec2::ONE - u } else { u };
                acc += set.area_point(&shapes[0], 0, prim, b).p.x as f64;
            }
            _ => {
                eprintln!("MODE: power, hierarchy or point");
                std::process::exit(1);
            }
        }
    }
    println!("{acc}");
}
