//! Meshes the tests of several crates build: a UV sphere of triangles, as positions and index
//! triples (the crates wrap them in their own mesh types).

use glam::Vec3;

/// A sphere of `around × rows` quads (two triangles each, fans at the poles) of radius `r`
/// around `c`, wound so that `(p1 − p0) × (p2 − p0)` points outwards: its positions (the poles
/// first, then `rows − 1` rings of `around`) and triangles.
pub fn uv_sphere(c: Vec3, r: f32, around: u32, rows: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut p = vec![c + Vec3::Y * r, c - Vec3::Y * r];
    for i in 1..rows {
        let theta = std::f32::consts::PI * i as f32 / rows as f32;
        for j in 0..around {
            let phi = std::f32::consts::TAU * j as f32 / around as f32;
            let s = theta.sin();
            p.push(c + r * Vec3::new(s * phi.cos(), theta.cos(), s * phi.sin()));
        }
    }
    let ring = |i: u32, j: u32| 2 + (i - 1) * around + j % around;
    let mut t = Vec::new();
    for j in 0..around {
        t.push([0, ring(1, j + 1), ring(1, j)]);
        t.push([1, ring(rows - 1, j), ring(rows - 1, j + 1)]);
        for i in 1..rows - 1 {
            let (a, b, c2, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j + 1),
                ring(i + 1, j),
            );
            t.push([a, b, c2]);
            t.push([a, c2, d]);
        }
    }
    (p, t)
}
