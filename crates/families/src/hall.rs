//! A hall lit by tens of emissive garlands (thousands of small triangles) beside a dim sky seen
//! through windows and a far doorway, with heavy occlusion: the many-light case where most lights
//! are blocked from most points.
//!
//! - **The hall**: 10–14 m wide, 18–26 m long, 5–7 m high; a checkerboard floor (squares of
//!   0.5–1 m), pale walls and ceiling. Two colonnades of 5–8 square pillars (half width
//!   0.22–0.35 m, floor to ceiling) run along it, 2–3 m from the side walls.
//! - **Occluders** (with `occluders`): the pillars; two or three transverse partitions at inner
//!   pillar rows (not the two nearest the camera, so that its bay and the next are open), wall to
//!   wall, each with a doorway in the nave (1.6–2.6 m wide, 2.2–2.8 m high), one in three full
//!   height and the rest 0.45–0.7 of it (the garlands of the next bay shine over
//!   them onto the vault, not the floor); open shelf units (two uprights, four boards) against
//!   the side walls, about one per bay and side. Without occluders they are left out and the
//!   garlands keep their places.
//! - **Sky** (with `envmap`): clerestory windows, one per bay on each side wall (0.55–0.85 of the
//!   height), and a doorway in the far wall (2.5–4 m wide) open to a dim sky whose sun (20°–40°
//!   high) stands to one side, so that a few sun patches fall in through the windows.
//!   Without the sky the walls are closed.
//! - **Garlands** (`garlands.rs`): the `lights` triangles in 24–48 OBJ meshes (at most one per 24
//!   triangles), strung between pillars along each colonnade, across the nave and diagonally,
//!   3–5.5 m up and sagging 0.2–1 m; bulbs, rope or strip. Each garland has one radiance; the
//!   levels are `ratio^(t^2.5)` for `t` even in `[0, 1]` (shuffled), so a few garlands are bright
//!   among many dim ones; tints warm white to coloured. Total emitted power [`HALL_POWER`].
//! - **Objects** in the nave (receivers): a statue (a sphere on a pedestal, rough gold unless the
//!   receivers are diffuse or textured), spheres and crates of the receivers' materials.
//!
//! Emitters are visible to the camera (Mitsuba's default): in a hall the garlands are what one
//! looks at, and their pixels cost every estimator alike. Direct light only (max depth 2).
//!
//! Streams: the layout (hall, pillars, partitions, windows, objects, strands) depends on the seed
//! only, the materials on the seed and the receivers, the garlands' triangles on the seed and the
//! light count, so the OBJ names `hall-s<seed>-n<lights>-<i>-<style>.obj` say what they hold.

use restir_sampling::Pcg32;

use super::stage::receiver_material;
use super::util::{
    hue_colour, named, rect_transform, rough_conductor, round, round3, shape, uniform,
};
use super::{DiOptions, Generated, Receivers, envmap};
use restir_scene::{
    CameraDesc, FilmDesc, FilterDesc, GeometryDesc, IntegratorDesc, MaterialDesc, MicrofacetDesc,
    NamedMaterial, SceneDesc, ShapeDesc, TransformOp,
};

mod garland_lights;
#[cfg(test)]
mod tests;

use garland_lights::{lights, strands};

/// Total emitted power of the garlands (W), whatever their number.
pub(super) const HALL_POWER: f32 = 600.0;
/// Garlands per hall are drawn in this range (fewer when there are few triangles).
const GARLANDS: (u32, u32) = (24, 48);
/// The lowest point of a strand (m): above the tallest object, so no bulb touches one.
const LOWEST: f32 = 2.9;

/// The hall's layout (all from the seed).
struct Layout {
    /// Half width, half length, height.
    hw: f32,
    hl: f32,
    h: f32,
    /// The colonnades' distance from the axis and the pillars' half width.
    xc: f32,
    half: f32,
    /// The pillar rows' z, from the far end (−z) to the near end (+z, the camera's).
    rows: Vec<f32>,
}

/// A rectangle spanning `[u0, u1] × [v0, v1]` in a wall: `rotate` turns the rectangle's +z normal
/// to the wall's, and `place(u, v)` is the wall point at local coordinates `(u, v)`.
fn piece(
    material: &str,
    (u0, u1): (f32, f32),
    (v0, v1): (f32, f32),
    rotate: ([f32; 3], f32),
    place: impl Fn(f32, f32) -> [f32; 3],
) -> ShapeDesc {
    let at = place(0.5 * (u0 + u1), 0.5 * (v0 + v1));
    shape(
        GeometryDesc::Rectangle,
        rect_transform(
            round(0.5 * (u1 - u0).abs(), 3),
            round(0.5 * (v1 - v0).abs(), 3),
            rotate.0,
            rotate.1,
            round3(at, 3),
        ),
        named(material),
    )
}

/// An axis-aligned box of half extents `s` centred at `at`.
fn block(material: &str, s: [f32; 3], at: [f32; 3]) -> ShapeDesc {
    shape(
        GeometryDesc::Cube,
        vec![
            TransformOp::Scale(round3(s, 3)),
            TransformOp::Translate(round3(at, 3)),
        ],
        named(material),
    )
}

/// Splits `[lo, hi]` into solid pieces around the open `holes` (sorted, inside, disjoint).
fn solid(lo: f32, hi: f32, holes: &[(f32, f32)]) -> Vec<(f32, f32)> {
    let mut pieces = Vec::new();
    let mut at = lo;
    for &(a, b) in holes {
        if a > at {
            pieces.push((at, a));
        }
        at = b;
    }
    if hi > at {
        pieces.push((at, hi));
    }
    pieces
}

/// A side wall at `x = side · hw` (normal towards the axis) with `windows` (z ranges) in the band
/// `[y0, y1]`.
fn side_wall(l: &Layout, side: f32, windows: &[(f32, f32)], band: (f32, f32)) -> Vec<ShapeDesc> {
    let rotate = ([0.0, 1.0, 0.0], -90.0 * side);
    let place = |z: f32, y: f32| [side * l.hw, y, z];
    let full = (-l.hl, l.hl);
    if windows.is_empty() {
        return vec![piece("wall", full, (0.0, l.h), rotate, place)];
    }
    let mut shapes = vec![
        piece("wall", full, (0.0, band.0), rotate, place),
        piece("wall", full, (band.1, l.h), rotate, place),
    ];
    for z in solid(-l.hl, l.hl, windows) {
        shapes.push(piece("wall", z, band, rotate, place));
    }
    shapes
}

/// The hall for `seed`.
pub(super) fn hall(seed: u64, options: &DiOptions) -> Generated {
    let mut rng = Pcg32::new(seed, 0x6861_6c6c); // "hall"
    let hw = round(uniform(&mut rng, 5.0, 7.0), 2);
    let hl = round(uniform(&mut rng, 9.0, 13.0), 2);
    let h = round(uniform(&mut rng, 5.0, 7.0), 2);
    let xc = round(hw - uniform(&mut rng, 2.0, 3.0), 2);
    let half = round(uniform(&mut rng, 0.22, 0.35), 3);
    let n_rows = 5 + rng.next_bounded(4) as usize;
    let spacing = 2.0 * hl / (n_rows + 1) as f32;
    let rows: Vec<f32> = (1..=n_rows)
        .map(|i| round(-hl + i as f32 * spacing, 3))
        .collect();
    let l = Layout {
        hw,
        hl,
        h,
        xc,
        half,
        rows,
    };

    // The shell: floor, ceiling, near wall; side walls with windows and a far wall with a doorway
    // when there is a sky.
    let band = (round(0.55 * h, 3), round(0.85 * h, 3));
    let mut windows = Vec::new();
    let bounds: Vec<f32> = core::iter::once(-hl)
        .chain(l.rows.iter().copied())
        .chain(core::iter::once(hl))
        .collect();
    for pair in bounds.windows(2) {
        let (mid, w) = (0.5 * (pair[0] + pair[1]), 0.5 * (pair[1] - pair[0]));
        let half_window = w * uniform(&mut rng, 0.35, 0.6);
        windows.push((round(mid - half_window, 3), round(mid + half_window, 3)));
    }
    let door_half = round(uniform(&mut rng, 1.25, 2.0), 3);
    let door_h = round(uniform(&mut rng, 3.0, 4.0).min(0.8 * h), 3);
    let sun = envmap::direction_at(
        uniform(&mut rng, 20.0, 40.0),
        if rng.next_bounded(2) == 0 {
            90.0
        } else {
            270.0
        } + uniform(&mut rng, -35.0, 35.0),
    );
    let x_axis = [1.0, 0.0, 0.0];
    let y_axis = [0.0, 1.0, 0.0];
    let mut shapes = vec![
        piece("floor", (-hw, hw), (-hl, hl), (x_axis, -90.0), |x, z| {
            [x, 0.0, z]
        }),
        piece("ceiling", (-hw, hw), (-hl, hl), (x_axis, 90.0), |x, z| {
            [x, h, z]
        }),
        piece("wall", (-hw, hw), (0.0, h), (y_axis, 180.0), |x, y| {
            [x, y, hl]
        }),
    ];
    let far = |x: f32, y: f32| [x, y, -hl];
    if options.envmap {
        for side in [-1.0, 1.0] {
            shapes.extend(side_wall(&l, side, &windows, band));
        }
        for x in solid(-hw, hw, &[(-door_half, door_half)]) {
            shapes.push(piece("wall", x, (0.0, h), (y_axis, 0.0), far));
        }
        shapes.push(piece(
            "wall",
            (-door_half, door_half),
            (door_h, h),
            (y_axis, 0.0),
            far,
        ));
    } else {
        for side in [-1.0, 1.0] {
            shapes.extend(side_wall(&l, side, &[], band));
        }
        shapes.push(piece("wall", (-hw, hw), (0.0, h), (y_axis, 0.0), far));
    }

    // Occluders: pillars, partitions at two or three inner rows, shelves against the side walls.
    let mut occluders = Vec::new();
    for &z in &l.rows {
        for side in [-1.0, 1.0] {
            occluders.push(block(
                "pillar",
                [half, 0.5 * h, half],
                [side * xc, 0.5 * h, z],
            ));
        }
    }
    // Not the row nearest the camera's bay, so that the first garlands are in view.
    let mut inner: Vec<usize> = (1..n_rows - 2).collect();
    for i in (1..inner.len()).rev() {
        inner.swap(i, rng.next_bounded(i as u32 + 1) as usize);
    }
    let take = (2 + rng.next_bounded(2) as usize).min(inner.len());
    let mut partitioned: Vec<usize> = inner[..take].to_vec();
    partitioned.sort_unstable();
    for &row in &partitioned {
        let z = l.rows[row];
        let height = if rng.next_bounded(3) == 0 {
            h
        } else {
            round(uniform(&mut rng, 0.45, 0.7) * h, 3)
        };
        let door_w = uniform(&mut rng, 0.8, 1.3);
        let door_x = uniform(&mut rng, -xc + 0.6 + door_w, xc - 0.6 - door_w);
        let (d0, d1) = (round(door_x - door_w, 3), round(door_x + door_w, 3));
        let door_top = round(uniform(&mut rng, 2.2, 2.8), 3);
        let at = |x: f32, y: f32| [x, y, z];
        for x in solid(-hw, hw, &[(d0, d1)]) {
            occluders.push(piece("partition", x, (0.0, height), (y_axis, 0.0), at));
        }
        if height > door_top {
            occluders.push(piece(
                "partition",
                (d0, d1),
                (door_top, height),
                (y_axis, 0.0),
                at,
            ));
        }
    }
    for pair in bounds.windows(2) {
        for side in [-1.0f32, 1.0] {
            if rng.next_bounded(5) == 0 {
                continue;
            }
            let half_bay = 0.5 * (pair[1] - pair[0]);
            let depth = uniform(&mut rng, 0.2, 0.3);
            let length = uniform(&mut rng, 0.5, 1.0).min(half_bay - 0.35);
            let tall = uniform(&mut rng, 1.6, 2.4);
            let room = half_bay - length - 0.3;
            let z = 0.5 * (pair[0] + pair[1]) + uniform(&mut rng, -1.0, 1.0) * room.max(0.0);
            let x = side * (hw - depth - 0.05);
            for end in [-1.0, 1.0] {
                occluders.push(block(
                    "shelf",
                    [depth, 0.5 * tall, 0.03],
                    [x, 0.5 * tall, z + end * (length - 0.03)],
                ));
            }
            for k in 0..4 {
                let y = 0.15 + k as f32 * (tall - 0.2) / 3.0;
                occluders.push(block("shelf", [depth, 0.02, length], [x, y, z]));
            }
        }
    }
    if options.occluders {
        shapes.extend(occluders);
    }

    // Objects in the nave, the statue first.
    let mut placed: Vec<(f32, f32, f32)> = Vec::new();
    let count = 6 + rng.next_bounded(5);
    let mut tries = 0;
    while placed.len() < count as usize && tries < 1000 {
        tries += 1;
        let r = uniform(&mut rng, 0.3, 0.7);
        let x = uniform(&mut rng, -xc + half + r + 0.2, xc - half - r - 0.2);
        let z = uniform(&mut rng, -hl + 1.5, hl - 3.0);
        // Clear of the rows (partitions, garlands across the nave) and of each other.
        let clear = l.rows.iter().all(|&p| (z - p).abs() > r + l.half + 0.5)
            && placed
                .iter()
                .all(|&(px, pz, pr)| (x - px).hypot(z - pz) > r + pr + 0.3);
        if !clear {
            continue;
        }
        let kind = if placed.is_empty() {
            0
        } else {
            1 + rng.next_bounded(2)
        };
        let material = if placed.is_empty() {
            "statue".to_string()
        } else {
            format!("object{}", rng.next_bounded(4))
        };
        match kind {
            0 => {
                let top = uniform(&mut rng, 0.8, 1.1);
                shapes.push(block(
                    "pillar",
                    [0.6 * r, 0.5 * top, 0.6 * r],
                    [x, 0.5 * top, z],
                ));
                shapes.push(shape(
                    GeometryDesc::Sphere {
                        center: round3([x, top + r, z], 3),
                        radius: round(r, 3),
                    },
                    Vec::new(),
                    named(&material),
                ));
            }
            1 => shapes.push(shape(
                GeometryDesc::Sphere {
                    center: round3([x, r, z], 3),
                    radius: round(r, 3),
                },
                Vec::new(),
                named(&material),
            )),
            _ => {
                let s = [r * 0.8, r * uniform(&mut rng, 0.5, 1.0), r * 0.8];
                let angle = round(uniform(&mut rng, 0.0, 90.0), 1);
                shapes.push(shape(
                    GeometryDesc::Cube,
                    vec![
                        TransformOp::Scale(round3(s, 3)),
                        TransformOp::Rotate {
                            axis: y_axis,
                            angle,
                        },
                        TransformOp::Translate(round3([x, s[1], z], 3)),
                    ],
                    named(&material),
                ));
            }
        }
        placed.push((x, z, r));
    }

    // The strands: along each colonnade, across the nave and diagonally, between pillars.
    let strands = strands(&mut rng, &l);

    // The camera at the near end, above head height, looking down the hall.
    let eye = round3(
        [
            uniform(&mut rng, -1.0, 1.0),
            uniform(&mut rng, 0.4, 0.5) * h,
            hl - 0.4,
        ],
        3,
    );
    let target = round3(
        [
            uniform(&mut rng, -0.8, 0.8),
            uniform(&mut rng, 1.8, 2.6),
            uniform(&mut rng, -0.5, 0.3) * hl,
        ],
        3,
    );

    let materials = materials(seed, options.receivers, &l);
    let (lights_shapes, assets_meshes, garlands) = lights(seed, options, &strands);
    shapes.extend(lights_shapes);
    let mut assets = assets_meshes;
    let mut lights = Vec::new();
    if options.envmap {
        let (asset, light) =
            envmap::sky_light(format!("hall-sky-s{seed}.exr"), seed, sun, 40.0, 0.5);
        assets.push(asset);
        lights.push(light);
    }
    let desc = SceneDesc {
        camera: CameraDesc {
            fov: 60.0,
            to_world: vec![TransformOp::LookAt {
                origin: eye,
                target,
                up: [0.0, 1.0, 0.0],
            }],
            ..CameraDesc::default()
        },
        film: FilmDesc {
            width: 320,
            height: 240,
            filter: FilterDesc::Box,
            filename: None,
        },
        spp: 64,
        integrator: IntegratorDesc {
            max_depth: 2,
            hide_emitters: false,
            ..IntegratorDesc::default()
        },
        materials,
        shapes,
        lights,
        animation: None,
    };
    Generated {
        desc,
        header: format!(
            "Generated by `restir generate family --kind di` (hall, seed {seed}, {tag}).\n\
             A {w} x {len} x {h} m hall: {n} emissive triangles in {garlands} garlands (OBJ) strung\n\
             between {pillars} pillars{occ}{sky}; checkerboard floor, objects in the nave.\n\
             Garland radiances spread over {ratio}x. Direct light only (max depth 2). Regenerate\n\
             rather than edit.",
            tag = options.tag(),
            w = round(2.0 * hw, 1),
            len = round(2.0 * hl, 1),
            n = options.lights,
            pillars = 2 * n_rows,
            occ = if options.occluders {
                format!(
                    ", {} partitions with doorways and shelves",
                    partitioned.len()
                )
            } else {
                " (pillars, partitions and shelves left out)".into()
            },
            sky = if options.envmap {
                ", a dim sky through clerestory windows and a far doorway"
            } else {
                ", closed walls"
            },
            ratio = options.power_ratio,
        ),
        assets,
    }
}

/// The hall's materials: a checkerboard floor, pale walls and ceiling, stone pillars, coloured
/// partitions, wooden shelves, the statue and four object materials of the receivers' kind.
fn materials(seed: u64, receivers: Receivers, l: &Layout) -> Vec<NamedMaterial> {
    let mut rng = Pcg32::new(seed, 0x686d_6174); // "hmat"
    let square = uniform(&mut rng, 0.5, 1.0);
    let light = hue_colour(uniform(&mut rng, 0.05, 0.15), uniform(&mut rng, 0.0, 0.25))
        .map(|c| round(0.7 * c, 3));
    let dark = hue_colour(rng.next_f32(), uniform(&mut rng, 0.0, 0.5)).map(|c| round(0.15 * c, 3));
    let floor = MaterialDesc::Textured {
        material: Box::new(MaterialDesc::Diffuse { reflectance: light }),
        textures: vec![restir_scene::TextureBinding {
            param: restir_scene::ColorParam::Reflectance,
            texture: restir_scene::TextureDesc::Checkerboard {
                color0: light,
                color1: dark,
                uv: restir_scene::UvTransform {
                    scale: glam::Vec2::new(round(l.hw / square, 2), round(l.hl / square, 2)),
                    offset: glam::Vec2::ZERO,
                },
            },
        }],
    };
    let diffuse = |c: [f32; 3]| MaterialDesc::Diffuse { reflectance: c };
    let two_sided = |c: [f32; 3]| MaterialDesc::TwoSided(Box::new(diffuse(c)));
    let wall = hue_colour(uniform(&mut rng, 0.05, 0.15), uniform(&mut rng, 0.05, 0.2))
        .map(|c| round(0.7 * c, 3));
    let partition =
        hue_colour(rng.next_f32(), uniform(&mut rng, 0.2, 0.5)).map(|c| round(0.55 * c, 3));
    let statue = match receivers {
        Receivers::Diffuse | Receivers::Textured => receiver_material(&mut rng, receivers),
        Receivers::Glossy | Receivers::Mixed => {
            let alpha = round(uniform(&mut rng, 0.15, 0.35), 3);
            rough_conductor("Au", MicrofacetDesc::Ggx, alpha)
        }
    };
    let mut materials = vec![
        ("floor".to_string(), floor),
        ("wall".into(), two_sided(wall)),
        ("ceiling".into(), two_sided([0.6, 0.6, 0.58])),
        ("pillar".into(), diffuse([0.55, 0.53, 0.5])),
        ("partition".into(), two_sided(partition)),
        ("shelf".into(), diffuse([0.45, 0.3, 0.18])),
        ("statue".into(), statue),
    ];
    for i in 0..4 {
        materials.push((format!("object{i}"), receiver_material(&mut rng, receivers)));
    }
    materials
        .into_iter()
        .map(|(name, material)| NamedMaterial { name, material })
        .collect()
}
