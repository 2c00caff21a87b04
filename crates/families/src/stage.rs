//! The stage the many-light kinds share: a floor, receivers (spheres and boxes) of diffuse,
//! checkerboard or glossy materials, occluders between the lights and the receivers (floating
//! slats and a few tall pillars), the camera, and optionally a dim sky beside the lights. The
//! kinds (`rects.rs`, `spheres.rs`, `meshes.rs`) add the lights in the layer [`LIGHT_HEIGHT`]
//! above the slats.
//!
//! Emitters are hidden from the camera (`hide_emitters`), as in `many_lights`: most are smaller
//! than a pixel, and their silhouettes' noise comes from the camera ray, not light sampling.

use restir_sampling::Pcg32;

use super::util::{
    METALS, checkerboard, distribution, hue_colour, named, rect_transform, rough_conductor,
    rough_plastic, round, round3, shape, uniform,
};
use super::{Asset, envmap};
use restir_scene::{
    CameraDesc, FilmDesc, FilterDesc, GeometryDesc, IntegratorDesc, MaterialDesc, NamedMaterial,
    SceneDesc, ShapeDesc, TransformOp,
};

/// Half the side of the square the receivers and lights cover.
pub(super) const EXTENT: f32 = 5.0;
/// Lights lie between these heights (above the slats, below nothing).
pub(super) const LIGHT_HEIGHT: (f32, f32) = (2.3, 3.3);
/// Total emitted power of a scene's lights (W), whatever their number, so exposure stays put.
pub(super) const LIGHT_POWER: f32 = 160.0;

/// What the receivers are made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Receivers {
    /// Diffuse colours.
    Diffuse,
    /// Checkerboard-textured diffuse (the floor too).
    Textured,
    /// Rough conductors (Beckmann or GGX) and rough plastics, α 0.05–0.4.
    Glossy,
    /// A mix of the three.
    Mixed,
}

impl Receivers {
    /// Every choice.
    pub const ALL: [Receivers; 4] = [
        Receivers::Diffuse,
        Receivers::Textured,
        Receivers::Glossy,
        Receivers::Mixed,
    ];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Receivers::Diffuse => "diffuse",
            Receivers::Textured => "textured",
            Receivers::Glossy => "glossy",
            Receivers::Mixed => "mixed",
        }
    }
}

/// Options of the many-light kinds.
#[derive(Clone, Debug, PartialEq)]
pub struct DiOptions {
    /// Number of lights: rectangles, spheres or emissive triangles.
    pub lights: u32,
    /// Brightest over dimmest light radiance (log-uniform in between); 1000 in the families.
    pub power_ratio: f32,
    /// What the receivers are made of.
    pub receivers: Receivers,
    /// Floating slats and pillars between the lights and the receivers.
    pub occluders: bool,
    /// A dim sky (EXR beside the scene) besides the lights.
    pub envmap: bool,
}

impl Default for DiOptions {
    fn default() -> Self {
        Self {
            lights: 1000,
            power_ratio: 1000.0,
            receivers: Receivers::Mixed,
            occluders: true,
            envmap: false,
        }
    }
}

impl DiOptions {
    /// A short tag for file names and headers: `n1000-mixed-occ-env`.
    pub fn tag(&self) -> String {
        let mut tag = format!("n{}-{}", self.lights, self.receivers.name());
        if self.power_ratio != 1000.0 {
            tag.push_str(&format!("-p{}", self.power_ratio));
        }
        if self.occluders {
            tag.push_str("-occ");
        }
        if self.envmap {
            tag.push_str("-env");
        }
        tag
    }
}

/// A pillar's footprint, which lights keep out of.
struct Pillar {
    x: f32,
    z: f32,
    half: f32,
}

/// The stage before the lights: the scene without emitters and what the kinds need to place them.
pub(super) struct Stage {
    pub desc: SceneDesc,
    pub assets: Vec<Asset>,
    pillars: Vec<Pillar>,
}

impl Stage {
    /// Whether a light of radius `r` centred at `(x, z)` would be inside a pillar.
    pub fn blocked(&self, x: f32, z: f32, r: f32) -> bool {
        self.pillars
            .iter()
            .any(|p| (x - p.x).abs() < p.half + r && (z - p.z).abs() < p.half + r)
    }

    /// Adds the lights and returns the description.
    pub fn finish(mut self, lights: Vec<ShapeDesc>) -> (SceneDesc, Vec<Asset>) {
        self.desc.shapes.extend(lights);
        (self.desc, self.assets)
    }
}

/// A receiver material of the kind `receivers` asks for.
pub(super) fn receiver_material(rng: &mut Pcg32, receivers: Receivers) -> MaterialDesc {
    let receivers = if receivers == Receivers::Mixed {
        [Receivers::Diffuse, Receivers::Textured, Receivers::Glossy][rng.next_bounded(3) as usize]
    } else {
        receivers
    };
    let colour = hue_colour(rng.next_f32(), uniform(rng, 0.2, 0.7)).map(|c| round(0.75 * c, 3));
    match receivers {
        Receivers::Diffuse | Receivers::Mixed => MaterialDesc::Diffuse {
            reflectance: colour,
        },
        Receivers::Textured => {
            checkerboard(colour, [0.1, 0.1, 0.1], round(uniform(rng, 2.0, 6.0), 1))
        }
        Receivers::Glossy => {
            let alpha = round(0.05 * 8f32.powf(rng.next_f32()), 3); // 0.05–0.4
            let d = distribution(rng);
            if rng.next_bounded(2) == 0 {
                let metal = METALS[rng.next_bounded(METALS.len() as u32) as usize];
                rough_conductor(metal, d, alpha)
            } else {
                rough_plastic(colour, d, alpha)
            }
        }
    }
}

/// Builds the stage for `seed` (its own random stream, apart from the lights').
pub(super) fn stage(seed: u64, options: &DiOptions) -> Stage {
    let mut rng = Pcg32::new(seed, 0x7374_6167); // "stag"
    let floor = match options.receivers {
        Receivers::Textured | Receivers::Mixed => {
            checkerboard([0.6, 0.6, 0.58], [0.25, 0.25, 0.25], 10.0)
        }
        Receivers::Diffuse | Receivers::Glossy => MaterialDesc::Diffuse {
            reflectance: [0.6, 0.6, 0.6],
        },
    };
    let mut materials = vec![
        NamedMaterial {
            name: "floor".into(),
            material: floor,
        },
        NamedMaterial {
            name: "occluder".into(),
            material: MaterialDesc::TwoSided(Box::new(MaterialDesc::Diffuse {
                reflectance: [0.5, 0.5, 0.5],
            })),
        },
    ];
    for i in 0..6 {
        materials.push(NamedMaterial {
            name: format!("receiver{i}"),
            material: receiver_material(&mut rng, options.receivers),
        });
    }
    let side = EXTENT + 1.0;
    let mut shapes = vec![shape(
        GeometryDesc::Rectangle,
        rect_transform(side, side, [1.0, 0.0, 0.0], -90.0, [0.0, 0.0, 0.0]),
        named("floor"),
    )];

    // Receivers on a jittered 5×5 grid, one cell in four empty: spheres and boxes up to 1.2 high.
    let cells = 5;
    let cell = 2.0 * EXTENT / cells as f32;
    for gz in 0..cells {
        for gx in 0..cells {
            if rng.next_bounded(4) == 0 {
                continue;
            }
            let cx = round(
                -EXTENT + (gx as f32 + uniform(&mut rng, 0.3, 0.7)) * cell,
                3,
            );
            let cz = round(
                -EXTENT + (gz as f32 + uniform(&mut rng, 0.3, 0.7)) * cell,
                3,
            );
            let material = named(&format!("receiver{}", rng.next_bounded(6)));
            if rng.next_bounded(2) == 0 {
                let r = round(uniform(&mut rng, 0.25, 0.6), 3);
                shapes.push(shape(
                    GeometryDesc::Sphere {
                        center: [cx, r, cz],
                        radius: r,
                    },
                    Vec::new(),
                    material,
                ));
            } else {
                let s = round3(
                    [
                        uniform(&mut rng, 0.2, 0.5),
                        uniform(&mut rng, 0.15, 0.6),
                        uniform(&mut rng, 0.2, 0.5),
                    ],
                    3,
                );
                let angle = round(uniform(&mut rng, 0.0, 90.0), 1);
                shapes.push(shape(
                    GeometryDesc::Cube,
                    vec![
                        TransformOp::Scale(s),
                        TransformOp::Rotate {
                            axis: [0.0, 1.0, 0.0],
                            angle,
                        },
                        TransformOp::Translate([cx, s[1], cz]),
                    ],
                    material,
                ));
            }
        }
    }

    // Occluders: slats floating between the receivers and the lights, and a few pillars that
    // reach up through the light layer.
    let mut pillars = Vec::new();
    if options.occluders {
        for _ in 0..10 {
            let (sx, sz) = (uniform(&mut rng, 0.3, 1.2), uniform(&mut rng, 0.08, 0.25));
            let at = round3(
                [
                    uniform(&mut rng, -EXTENT, EXTENT),
                    uniform(&mut rng, 1.5, 2.1),
                    uniform(&mut rng, -EXTENT, EXTENT),
                ],
                3,
            );
            let yaw = round(uniform(&mut rng, 0.0, 180.0), 1);
            let mut to_world =
                rect_transform(round(sx, 3), round(sz, 3), [1.0, 0.0, 0.0], -90.0, [0.0; 3]);
            to_world.pop();
            to_world.push(TransformOp::Rotate {
                axis: [0.0, 1.0, 0.0],
                angle: yaw,
            });
            to_world.push(TransformOp::Translate(at));
            shapes.push(shape(GeometryDesc::Rectangle, to_world, named("occluder")));
        }
        for _ in 0..3 {
            let half = round(uniform(&mut rng, 0.12, 0.25), 3);
            let (x, z) = (
                round(uniform(&mut rng, -EXTENT, EXTENT), 3),
                round(uniform(&mut rng, -EXTENT, EXTENT), 3),
            );
            let height = LIGHT_HEIGHT.1 + 0.3;
            shapes.push(shape(
                GeometryDesc::Cube,
                vec![
                    TransformOp::Scale([half, height / 2.0, half]),
                    TransformOp::Translate([x, height / 2.0, z]),
                ],
                named("occluder"),
            ));
            pillars.push(Pillar {
                x,
                z,
                half: half * core::f32::consts::SQRT_2,
            });
        }
    }

    let mut lights = Vec::new();
    let mut assets = Vec::new();
    if options.envmap {
        let sun = envmap::sky_sun(seed);
        let (asset, light) = envmap::sky_light(format!("sky-s{seed}.exr"), seed, sun, 300.0, 0.3);
        assets.push(asset);
        lights.push(light);
    }

    let desc = SceneDesc {
        camera: CameraDesc {
            fov: 55.0,
            to_world: vec![TransformOp::LookAt {
                origin: [0.0, 6.5, 10.0],
                target: [0.0, 0.3, 0.3],
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
            hide_emitters: true,
            ..IntegratorDesc::default()
        },
        materials,
        shapes,
        lights,
        animation: None,
    };
    Stage {
        desc,
        assets,
        pillars,
    }
}

/// Scales relative radiances so that the lights' total power (π · radiance · area, one-sided)
/// is [`LIGHT_POWER`]; `lights` are (relative radiance, area) pairs.
pub(super) fn radiance_scale(lights: impl Iterator<Item = (f32, f32)>) -> f32 {
    let power: f64 = lights.map(|(l, a)| l as f64 * a as f64).sum();
    (LIGHT_POWER as f64 / (core::f64::consts::PI * power.max(1e-30))) as f32
}
