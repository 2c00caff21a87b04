//! Glossy rooms lit mostly indirectly (the ReSTIR PT family, in the manner of the hand-written
//! `scenes/indirect-room.ron`): a closed box room of random size whose one area light is out of
//! the camera's view — on the floor behind a low partition shining at the ceiling, or an uplight
//! behind the camera — with Beckmann and GGX rough conductors and rough plastics of α 0.05–0.5,
//! checkerboard-textured diffuse walls or floor, optionally a smooth or rough glass object, and
//! optionally a window in the right wall with a sky (EXR beside the scene) outside.

use glam::Vec3;
use restir_sampling::Pcg32;

use super::lamps::{POWER_RATIO, Space, lamps};
use super::util::{
    METALS, checkerboard, distribution, emitter, hue_colour, named, rect_transform,
    rough_conductor, rough_plastic, round, round3, shape, uniform,
};
use super::{Generated, envmap};
use restir_scene::{
    CameraDesc, FilmDesc, FilterDesc, GeometryDesc, IntegratorDesc, MaterialDesc, MaterialRef,
    NamedMaterial, RoughnessDesc, SceneDesc, ShapeDesc, TransformOp,
};

/// The glass object of a room, if any.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Glass {
    /// No glass.
    #[default]
    None,
    /// A smooth dielectric object.
    Smooth,
    /// A rough dielectric object (α 0.05–0.3).
    Rough,
}

impl Glass {
    /// Every choice.
    pub const ALL: [Glass; 3] = [Glass::None, Glass::Smooth, Glass::Rough];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Glass::None => "none",
            Glass::Smooth => "smooth",
            Glass::Rough => "rough",
        }
    }
}

/// Options of a glossy room.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RoomOptions {
    /// A glass object.
    pub glass: Glass,
    /// A window in the right wall with a sky outside.
    pub window: bool,
    /// Small lamps lighting the room instead of its hidden area light (0: none): the seed
    /// report's kind, many small emissive meshes lighting a room directly and indirectly.
    pub lamps: u32,
}

impl RoomOptions {
    /// A short tag for file names and headers: `glass-smooth-window`.
    pub fn tag(&self) -> String {
        let mut tag = format!("glass-{}", self.glass.name());
        if self.window {
            tag.push_str("-window");
        }
        if self.lamps > 0 {
            tag.push_str(&format!("-lamps{}", self.lamps));
        }
        tag
    }
}

/// α log-uniform in `[0.05, 0.5]`.
fn alpha(rng: &mut Pcg32) -> f32 {
    round(0.05 * 10f32.powf(rng.next_f32()), 3)
}

/// A glossy material: a rough conductor or a rough plastic, Beckmann or GGX.
fn glossy(rng: &mut Pcg32) -> MaterialDesc {
    let d = distribution(rng);
    let a = alpha(rng);
    if rng.next_bounded(2) == 0 {
        rough_conductor(METALS[rng.next_bounded(METALS.len() as u32) as usize], d, a)
    } else {
        let colour = hue_colour(rng.next_f32(), uniform(rng, 0.3, 0.8)).map(|c| round(0.7 * c, 3));
        rough_plastic(colour, d, a)
    }
}

fn colour(rng: &mut Pcg32, saturation: (f32, f32), level: f32) -> [f32; 3] {
    hue_colour(rng.next_f32(), uniform(rng, saturation.0, saturation.1))
        .map(|c| round(level * c, 3))
}

fn wall(sx: f32, sy: f32, axis: [f32; 3], angle: f32, at: [f32; 3], material: &str) -> ShapeDesc {
    shape(
        GeometryDesc::Rectangle,
        rect_transform(round(sx, 3), round(sy, 3), axis, angle, round3(at, 3)),
        named(material),
    )
}

/// The glossy room for `seed`.
pub fn room(seed: u64, options: &RoomOptions) -> Generated {
    let mut rng = Pcg32::new(seed, 0x726f_6f6d); // "room"
    let w = round(uniform(&mut rng, 3.6, 4.6), 2);
    let d = round(uniform(&mut rng, 4.0, 5.0), 2);
    let h = round(uniform(&mut rng, 2.2, 2.8), 2);
    let (hw, hd) = (w / 2.0, d / 2.0);
    let y_axis = [0.0, 1.0, 0.0];
    let x_axis = [1.0, 0.0, 0.0];

    // Materials: the floor and back wall are textured or glossy, the left wall glossy, the
    // ceiling white, the right and front walls coloured diffuse.
    let floor = if rng.next_bounded(2) == 0 {
        checkerboard(
            colour(&mut rng, (0.0, 0.3), 0.7),
            [0.15, 0.15, 0.15],
            round(uniform(&mut rng, 3.0, 8.0), 1),
        )
    } else {
        glossy(&mut rng)
    };
    let back = if rng.next_bounded(2) == 0 {
        checkerboard(
            colour(&mut rng, (0.2, 0.6), 0.7),
            [0.3, 0.3, 0.3],
            round(uniform(&mut rng, 3.0, 8.0), 1),
        )
    } else {
        let c = colour(&mut rng, (0.3, 0.8), 0.6);
        rough_plastic(c, distribution(&mut rng), alpha(&mut rng))
    };
    let mut materials = vec![
        ("floor", floor),
        ("back", back),
        ("left", glossy(&mut rng)),
        (
            "ceiling",
            MaterialDesc::Diffuse {
                reflectance: [0.8, 0.8, 0.8],
            },
        ),
        (
            "right",
            MaterialDesc::Diffuse {
                reflectance: colour(&mut rng, (0.2, 0.6), 0.7),
            },
        ),
        (
            "front",
            MaterialDesc::Diffuse {
                reflectance: colour(&mut rng, (0.0, 0.3), 0.6),
            },
        ),
        (
            "partition",
            MaterialDesc::TwoSided(Box::new(MaterialDesc::Diffuse {
                reflectance: [0.6, 0.6, 0.55],
            })),
        ),
    ];
    for i in 0..3 {
        materials.push((["object0", "object1", "object2"][i], glossy(&mut rng)));
    }

    let mut shapes = vec![
        wall(hw, hd, x_axis, -90.0, [0.0, 0.0, 0.0], "floor"),
        wall(hw, hd, x_axis, 90.0, [0.0, h, 0.0], "ceiling"),
        wall(hw, h / 2.0, y_axis, 0.0, [0.0, h / 2.0, -hd], "back"),
        wall(hw, h / 2.0, y_axis, 180.0, [0.0, h / 2.0, hd], "front"),
        wall(hd, h / 2.0, y_axis, 90.0, [-hw, h / 2.0, 0.0], "left"),
    ];
    // The right wall (normal −x; its local x runs along +z), with a window when asked.
    let mut lights = Vec::new();
    let mut assets = Vec::new();
    if options.window {
        let (wz, half_wz) = (
            uniform(&mut rng, -hd / 2.0, hd / 4.0),
            uniform(&mut rng, 0.4, 0.7),
        );
        let (y0, y1) = (
            uniform(&mut rng, 0.8, 1.0),
            (h - uniform(&mut rng, 0.3, 0.5)),
        );
        let (z0, z1) = (round(wz - half_wz, 3), round(wz + half_wz, 3));
        let (y0, y1) = (round(y0, 3), round(y1, 3));
        let piece = |za: f32, zb: f32, ya: f32, yb: f32| {
            wall(
                (zb - za) / 2.0,
                (yb - ya) / 2.0,
                y_axis,
                -90.0,
                [hw, (ya + yb) / 2.0, (za + zb) / 2.0],
                "right",
            )
        };
        shapes.push(piece(-hd, hd, 0.0, y0));
        shapes.push(piece(-hd, hd, y1, h));
        shapes.push(piece(-hd, z0, y0, y1));
        shapes.push(piece(z1, hd, y0, y1));
        // The sun outside the window (+x side), 20°–40° high, so a patch of sunlight falls in.
        let sun = envmap::direction_at(
            uniform(&mut rng, 20.0, 40.0),
            uniform(&mut rng, 60.0, 120.0),
        );
        let (asset, light) =
            envmap::sky_light(format!("window-sky-s{seed}.exr"), seed, sun, 60.0, 1.0);
        assets.push(asset);
        lights.push(light);
    } else {
        shapes.push(wall(
            hd,
            h / 2.0,
            y_axis,
            -90.0,
            [hw, h / 2.0, 0.0],
            "right",
        ));
    }

    // The camera near the front wall, looking at the back wall.
    let eye = [
        round(uniform(&mut rng, -0.4, 0.4), 3),
        round(uniform(&mut rng, 1.0, 1.4), 3),
        round(hd - 0.25, 3),
    ];
    let target = [
        round(uniform(&mut rng, -0.3, 0.3), 3),
        round(uniform(&mut rng, 0.6, 0.9), 3),
        -hd,
    ];

    // The light, out of the camera's view (drawn with lamps too, so that the rest of the room is
    // the same room).
    let power = uniform(&mut rng, 25.0, 35.0);
    let mut partition = None;
    let (light_shape, placement) = if rng.next_bounded(2) == 0 {
        // On the floor near the back wall behind a partition across the room, shining up.
        let (lx, lz) = (uniform(&mut rng, 0.4, 0.6), uniform(&mut rng, 0.25, 0.4));
        let centre_z = -hd + 0.2 + lz;
        let partition_z = centre_z + lz + 0.3;
        // The partition's top is above the line from the eye to the light's near edge.
        let near = centre_z + lz;
        let t = (eye[2] - partition_z) / (eye[2] - near);
        let partition_h = round(eye[1] + (0.02 - eye[1]) * t + 0.15, 3);
        shapes.push(wall(
            hw,
            partition_h / 2.0,
            y_axis,
            0.0,
            [0.0, partition_h / 2.0, partition_z],
            "partition",
        ));
        partition = Some((partition_z, partition_h));
        let x = uniform(&mut rng, -hw + lx + 0.1, hw - lx - 0.1);
        let area = 4.0 * lx * lz;
        (
            emitter(
                GeometryDesc::Rectangle,
                rect_transform(
                    round(lx, 3),
                    round(lz, 3),
                    x_axis,
                    -90.0,
                    round3([x, 0.02, centre_z], 3),
                ),
                [round(power / (core::f32::consts::PI * area), 3); 3],
            ),
            "on the floor behind a partition, shining at the ceiling",
        )
    } else {
        // An uplight behind the camera, below the ceiling, shining at it.
        // Low enough (0.9–1.3 m under the ceiling) to light a wide patch of it.
        let (lx, lz) = (uniform(&mut rng, 0.6, 0.9), 0.1);
        let y = h - uniform(&mut rng, 0.9, 1.3);
        let area = 4.0 * lx * lz;
        (
            emitter(
                GeometryDesc::Rectangle,
                rect_transform(
                    round(lx, 3),
                    lz,
                    x_axis,
                    -90.0,
                    round3([eye[0], y, hd - 0.12], 3),
                ),
                [round(power / (core::f32::consts::PI * area), 3); 3],
            ),
            "an uplight behind the camera, shining at the ceiling",
        )
    };
    if options.lamps == 0 {
        shapes.push(light_shape);
    }

    // Objects on the floor between the camera and the back: boxes and spheres.
    let glass_index = if options.glass == Glass::None {
        usize::MAX
    } else {
        rng.next_bounded(3) as usize
    };
    let mut objects = Vec::new();
    for i in 0..3 {
        let x = -hw + (i as f32 + uniform(&mut rng, 0.35, 0.65)) * w / 3.0;
        let z = uniform(&mut rng, -hd + 1.4, hd - 1.8);
        let material = if i == glass_index {
            MaterialRef::Inline(match options.glass {
                Glass::Smooth => MaterialDesc::Dielectric {
                    int_ior: restir_scene::BK7_IOR,
                    ext_ior: restir_scene::AIR_IOR,
                    specular_reflectance: [1.0; 3],
                    specular_transmittance: [1.0; 3],
                },
                _ => MaterialDesc::RoughDielectric {
                    int_ior: restir_scene::BK7_IOR,
                    ext_ior: restir_scene::AIR_IOR,
                    specular_reflectance: [1.0; 3],
                    specular_transmittance: [1.0; 3],
                    roughness: RoughnessDesc {
                        alpha: round(0.05 * 6f32.powf(rng.next_f32()), 3),
                        distribution: distribution(&mut rng),
                        ..RoughnessDesc::default()
                    },
                },
            })
        } else {
            named(["object0", "object1", "object2"][i])
        };
        if rng.next_bounded(2) == 0 {
            let r = round(uniform(&mut rng, 0.25, 0.45), 3);
            objects.push((Vec3::new(x, r, z), r));
            shapes.push(shape(
                GeometryDesc::Sphere {
                    center: round3([x, r, z], 3),
                    radius: r,
                },
                Vec::new(),
                material,
            ));
        } else {
            let s = round3(
                [
                    uniform(&mut rng, 0.2, 0.4),
                    uniform(&mut rng, 0.2, 0.5),
                    uniform(&mut rng, 0.2, 0.4),
                ],
                3,
            );
            let angle = round(uniform(&mut rng, 0.0, 90.0), 1);
            objects.push((Vec3::new(x, s[1], z), Vec3::from(s).length()));
            shapes.push(shape(
                GeometryDesc::Cube,
                vec![
                    TransformOp::Scale(s),
                    TransformOp::Rotate {
                        axis: y_axis,
                        angle,
                    },
                    TransformOp::Translate(round3([x, s[1], z], 3)),
                ],
                material,
            ));
        }
    }

    // The lamps, from their own stream (the room above is the same with and without them).
    let mut lit_by = format!("mostly indirectly by one area light {placement}");
    if options.lamps > 0 {
        let mut lamp_rng = Pcg32::new(seed, 0x6c61_6d70); // "lamp"
        let space = Space {
            hw,
            hd,
            h,
            eye: Vec3::from(eye),
            objects,
            partition,
        };
        let (lamps, asset, triangles) = lamps(&mut lamp_rng, options.lamps, power, &space);
        lit_by = format!(
            "by {} small lamps ({triangles} emissive triangles; powers over {POWER_RATIO}×)",
            lamps.len()
        );
        shapes.extend(lamps);
        assets.push(asset);
    }

    let desc = SceneDesc {
        camera: CameraDesc {
            fov: 60.0,
            to_world: vec![TransformOp::LookAt {
                origin: eye,
                target,
                up: y_axis,
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
            max_depth: 8,
            ..IntegratorDesc::default()
        },
        materials: materials
            .into_iter()
            .map(|(name, material)| NamedMaterial {
                name: name.into(),
                material,
            })
            .collect(),
        shapes,
        lights,
        animation: None,
    };
    Generated {
        desc,
        header: format!(
            "Generated by `restir generate room --seed {seed}` ({tag}).\n\
             A closed {w}×{h}×{d} m room lit {lit_by};\n\
             rough conductors and plastics (Beckmann and GGX, α 0.05–0.5), textured walls{window}.\n\
             Max depth 8. Regenerate rather than edit.",
            tag = options.tag(),
            window = if options.window {
                ", a window with a sky outside"
            } else {
                ""
            },
        ),
        assets,
    }
}
