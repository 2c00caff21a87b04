//! A few emissive triangle meshes over the shared stage, written as OBJ files beside the scene:
//! rings (tori), wavy ceiling panels and bulbs (spheres), each a fine tessellation of which a
//! random ~40 % of the triangles is kept, so that every mesh is a cloud of small emissive
//! triangles. The `n` lights are the triangles, split evenly over [`MESHES`] meshes; each mesh
//! has one radiance, spaced log-evenly over the power ratio (the brightest mesh is `ratio`× the
//! dimmest), so the power differs both between meshes and with triangle size.

use glam::Vec3;
use restir_sampling::Pcg32;

use super::stage::{EXTENT, LIGHT_HEIGHT, radiance_scale, stage};
use super::util::{emitter, grid, hue_colour, obj, round, uniform};
use super::{Asset, AssetContents, DiOptions, Generated};
use restir_scene::GeometryDesc;

/// Meshes per scene.
pub(super) const MESHES: u32 = 8;
/// Fraction of a tessellation's triangles kept.
const KEEP: f32 = 0.4;

/// One mesh of about `faces` triangles (before thinning) at `centre`, of a shape drawn from `rng`.
fn surface(rng: &mut Pcg32, faces: u32, centre: Vec3) -> (&'static str, Vec<Vec3>, Vec<[u32; 3]>) {
    let quads = (faces / 2).max(8);
    match rng.next_bounded(3) {
        0 => {
            // A horizontal ring: u around the tube (ψ), v around the axis (φ), normals outward.
            let major = uniform(rng, 0.6, 1.4);
            let minor = uniform(rng, 0.08, 0.2);
            let nv = ((quads as f32 * major / minor).sqrt() as u32).max(4);
            let nu = quads.div_ceil(nv).max(3);
            let (p, t) = grid(nu, nv, |u, v| {
                let (psi, phi) = (u * core::f32::consts::TAU, v * core::f32::consts::TAU);
                let rho = major + minor * psi.cos();
                centre + Vec3::new(rho * phi.cos(), minor * psi.sin(), rho * phi.sin())
            });
            ("ring", p, t)
        }
        1 => {
            // A wavy panel facing down (normal −y).
            let (w, d) = (uniform(rng, 1.0, 2.2), uniform(rng, 1.0, 2.2));
            let (k1, k2) = (uniform(rng, 2.0, 6.0), uniform(rng, 2.0, 6.0));
            let n = ((quads as f32).sqrt().ceil() as u32).max(3);
            let (p, t) = grid(n, n, |u, v| {
                let wave = 0.12 * (k1 * u).sin() * (k2 * v).cos();
                centre + Vec3::new((u - 0.5) * w, wave, (v - 0.5) * d)
            });
            ("panel", p, t)
        }
        _ => {
            // A bulb: u around the axis (φ), v from the top (θ), normals outward.
            let r = uniform(rng, 0.25, 0.6);
            let nv = ((quads as f32 / 2.0).sqrt() as u32).max(3);
            let nu = quads.div_ceil(nv).max(6);
            let (p, t) = grid(nu, nv, |u, v| {
                let (phi, theta) = (u * core::f32::consts::TAU, v * core::f32::consts::PI);
                centre
                    + r * Vec3::new(
                        theta.sin() * phi.cos(),
                        theta.cos(),
                        theta.sin() * phi.sin(),
                    )
            });
            ("bulb", p, t)
        }
    }
}

/// Keeps `count` of the triangles (a uniform random subset, in their original order) and only the
/// vertices they use; returns positions, triangles and the total area.
fn thin(
    rng: &mut Pcg32,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    count: usize,
) -> (Vec<Vec3>, Vec<[u32; 3]>, f32) {
    let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
    let count = count.min(order.len());
    for i in 0..count {
        let j = i + rng.next_bounded((order.len() - i) as u32) as usize;
        order.swap(i, j);
    }
    let mut chosen = order[..count].to_vec();
    chosen.sort_unstable();
    let mut remap = vec![u32::MAX; positions.len()];
    let mut kept_positions = Vec::new();
    let mut kept = Vec::with_capacity(count);
    let mut area = 0.0;
    for &t in &chosen {
        let tri = triangles[t as usize].map(|v| {
            if remap[v as usize] == u32::MAX {
                remap[v as usize] = kept_positions.len() as u32;
                kept_positions.push(positions[v as usize]);
            }
            remap[v as usize]
        });
        let [a, b, c] = tri.map(|v| kept_positions[v as usize]);
        area += 0.5 * (b - a).cross(c - a).length();
        kept.push(tri);
    }
    (kept_positions, kept, area)
}

/// The emissive meshes scene for `seed`.
pub(super) fn meshes(seed: u64, options: &DiOptions) -> Generated {
    let stage = stage(seed, options);
    // The meshes' own stream: they depend on the seed and the light count only, as their names say.
    let mut rng = Pcg32::new(seed, 0x6d65_7368); // "mesh"
    let meshes = MESHES.min(options.lights);
    let mut levels: Vec<f32> = (0..meshes)
        .map(|i| {
            options
                .power_ratio
                .powf(i as f32 / (meshes - 1).max(1) as f32)
        })
        .collect();
    for i in (1..levels.len()).rev() {
        levels.swap(i, rng.next_bounded(i as u32 + 1) as usize);
    }
    let mut assets = stage.assets.clone();
    let mut parts = Vec::new();
    for i in 0..meshes {
        let count = options.lights / meshes + u32::from(i < options.lights % meshes);
        let centre = Vec3::new(
            uniform(&mut rng, -EXTENT + 1.0, EXTENT - 1.0),
            uniform(&mut rng, LIGHT_HEIGHT.0 + 0.2, LIGHT_HEIGHT.1 - 0.2),
            uniform(&mut rng, -EXTENT + 1.0, EXTENT - 1.0),
        );
        let (shape, p, t) = surface(&mut rng, (count as f32 / KEEP) as u32 + 2, centre);
        let (p, t, area) = thin(&mut rng, &p, &t, count as usize);
        let tint = hue_colour(rng.next_f32(), uniform(&mut rng, 0.0, 0.35));
        let filename = format!("meshes-s{seed}-n{}-{i}-{shape}.obj", options.lights);
        assets.push(Asset {
            filename: filename.clone(),
            contents: AssetContents::Text(obj(shape, "meshes", &p, &t)),
        });
        parts.push((filename, levels[i as usize], tint, area, t.len()));
    }
    let scale = radiance_scale(parts.iter().map(|p| (p.1, p.3)));
    let triangles: usize = parts.iter().map(|p| p.4).sum();
    let lights = parts
        .into_iter()
        .map(|(filename, level, tint, _, _)| {
            let radiance = tint.map(|c| round(c * level * scale, 4));
            emitter(GeometryDesc::Obj { filename }, Vec::new(), radiance)
        })
        .collect();
    let (desc, _) = stage.finish(lights);
    Generated {
        desc,
        header: format!(
            "Generated by `restir generate meshes --seed {seed}` ({tag}).\n\
             {triangles} small emissive triangles in {meshes} OBJ meshes (rings, panels, bulbs) over\n\
             spheres and boxes; mesh radiances spaced over {ratio}x. Direct light only (max depth 2).\n\
             Regenerate rather than edit.",
            tag = options.tag(),
            ratio = options.power_ratio,
        ),
        assets,
    }
}
