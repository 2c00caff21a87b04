//! Small lamps for a room (the kind of the seed report's scene: many small emissive meshes lighting
//! a room directly and through its walls): `count` bulbs, each a tessellated sphere of a few
//! hundred emissive triangles (one OBJ file, placed by each lamp's transform), hung through the
//! room's volume clear of the objects, the walls and the camera. A few are bright among many dim
//! ones (powers log-uniform over [`POWER_RATIO`]), most warm white, some coloured.

use glam::Vec3;
use restir_sampling::Pcg32;

use super::util::{emitter, grid, lamp_tint, obj, round, round3, uniform};
use super::{Asset, AssetContents};
use restir_scene::{GeometryDesc, ShapeDesc, TransformOp};

/// The brightest lamp's power over the dimmest's, at most.
pub(super) const POWER_RATIO: f32 = 30.0;
/// The bulb's tessellation: quads around the axis and from pole to pole.
const AROUND: u32 = 16;
const POLE_TO_POLE: u32 = 8;

/// The room a lamp must stay inside and the things it must keep clear of.
pub(super) struct Space {
    /// Half width (x) and half depth (z) of the room, and its height.
    pub hw: f32,
    pub hd: f32,
    pub h: f32,
    /// The camera's position.
    pub eye: Vec3,
    /// Bounding spheres (centre, radius) of the objects.
    pub objects: Vec<(Vec3, f32)>,
    /// A partition across the room at this z, up to this height.
    pub partition: Option<(f32, f32)>,
}

impl Space {
    /// Whether a lamp of radius `r` at `c` is clear of everything, `placed` included.
    fn clear(&self, c: Vec3, r: f32, placed: &[(Vec3, f32)]) -> bool {
        let gap = 0.05;
        let away = |(o, radius): &(Vec3, f32)| c.distance(*o) > radius + r + gap;
        c.distance(self.eye) > 0.6
            && self.objects.iter().all(away)
            && placed.iter().all(away)
            && self
                .partition
                .is_none_or(|(z, top)| (c.z - z).abs() > r + gap || c.y - r > top + gap)
    }
}

/// The unit bulb: a sphere of radius 1 at the origin, normals outward, without the degenerate
/// triangles at its poles. Returns the OBJ text, the triangle count and the area (the
/// triangles', a little under 4π).
fn bulb() -> (String, usize, f32) {
    let (p, t) = grid(AROUND, POLE_TO_POLE, |u, v| {
        let (phi, theta) = (u * core::f32::consts::TAU, v * core::f32::consts::PI);
        Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        )
    });
    let t: Vec<[u32; 3]> = t
        .into_iter()
        .filter(|[a, b, c]| {
            let [a, b, c] = [a, b, c].map(|&i| p[i as usize]);
            (b - a).cross(c - a).length() > 1e-6
        })
        .collect();
    let area = t
        .iter()
        .map(|[a, b, c]| {
            let [a, b, c] = [a, b, c].map(|&i| p[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    (obj("bulb", "room lamps", &p, &t), t.len(), area)
}

/// `count` lamps of total power `power` (watts, the emitted flux) in `space`, drawn from `rng`;
/// returns the emitters, the bulb's OBJ file and the number of emissive triangles. Fewer lamps
/// than asked are placed only if the room has no room left for them (a lamp is tried at 200
/// positions).
pub(super) fn lamps(
    rng: &mut Pcg32,
    count: u32,
    power: f32,
    space: &Space,
) -> (Vec<ShapeDesc>, Asset, usize) {
    let filename = format!("room-lamp-bulb-{AROUND}x{POLE_TO_POLE}.obj");
    let (text, triangles, unit_area) = bulb();
    let mut placed: Vec<(Vec3, f32)> = Vec::new();
    let mut drawn = Vec::new();
    for _ in 0..count {
        let r = uniform(rng, 0.02, 0.045);
        // Most hang in the upper half of the room; a third anywhere from the floor up.
        let low = if rng.next_bounded(3) == 0 {
            0.1
        } else {
            space.h * 0.5
        };
        let margin = r + 0.08;
        let spot = (0..200).find_map(|_| {
            let c = Vec3::new(
                uniform(rng, -space.hw + margin, space.hw - margin),
                uniform(rng, low + margin, space.h - margin),
                uniform(rng, -space.hd + margin, space.hd - margin),
            );
            space.clear(c, r, &placed).then_some(c)
        });
        let Some(c) = spot else { continue };
        placed.push((c, r));
        let level = POWER_RATIO.powf(rng.next_f32());
        let tint = lamp_tint(rng);
        drawn.push((c, r, level, tint));
    }
    // Radiance from power: flux = π · L · area for a Lambertian emitter.
    let total: f32 = drawn
        .iter()
        .map(|&(_, r, level, _)| level * unit_area * r * r)
        .sum();
    let scale = power / (core::f32::consts::PI * total.max(1e-12));
    let shapes = drawn
        .into_iter()
        .map(|(c, r, level, tint)| {
            let r = round(r, 3);
            emitter(
                GeometryDesc::Obj {
                    filename: filename.clone(),
                },
                vec![
                    TransformOp::Scale([r; 3]),
                    TransformOp::Translate(round3(c.to_array(), 3)),
                ],
                tint.map(|t| round(t * level * scale, 3)),
            )
        })
        .collect::<Vec<_>>();
    let lamps = shapes.len();
    (
        shapes,
        Asset {
            filename,
            contents: AssetContents::Text(text),
        },
        lamps * triangles,
    )
}
