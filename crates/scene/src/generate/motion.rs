//! Animated family members (issue 19, ReSTIR under motion): a generated scene plus an animation
//! drawn from the member's seed ([`animate`]), so that camera, objects and lights all move. Every
//! animation runs 2 s at 12 fps (frames `0..23`; [`FPS`], [`DURATION`]); keys start at the scene
//! as generated, so frame 0 is the still scene (apart from the room's two added lamps).
//!
//! - **Camera**: an orbit about its own look-at target (the generated cameras' `to_world` is one
//!   `LookAt`) through 8–20° on the many-light stage and 4–10° in a room, with a dolly of up to
//!   12 % closer (and on the stage a lift of −0.6 to +0.4), on a Catmull-Rom spline through five
//!   keys.
//! - **Objects** (non-emitting, ids `object0..`): on the stage three receivers (spheres or boxes)
//!   move by 0.4–0.8 of their size along a curve and turn 15–45° about their vertical axis, and
//!   two floating slats (`slat0`, `slat1`) move 0.3–0.8 and turn 20–60° (moving shadows); in a room
//!   two of the three floor objects (glass included, when drawn) move 0.2–0.4 m towards the camera
//!   or sideways and turn. Both uncover what was behind them (disocclusions).
//! - **Lights**: on the rectangle and sphere stages eight lights of the brightest 5 % (`light0..7`)
//!   move 0.6–1.5 m (rectangles also turn), and three of the brightest 1 % change radiance:
//!   `pulse0` goes dark for 0.3–0.45 s (it leaves the light list for those frames) and comes back,
//!   `pulse1` and `pulse2` swell to 2–3× or fade to 0.2–0.4× at 1 s and end at 0.6–1.5×. On the meshes stage the
//!   brightest mesh and two others move whole (`light0..2`, 0.5–1.2 m, turning 30–90° and tilting
//!   up to 10°), the second brightest is `pulse0` (dark and back) and the third `pulse1` (swells or fades).
//!   A room has one hidden area light: it slides (`light0`, behind its partition or behind the
//!   camera) and dims to 40–70 % and back; two small lamps are added (`lamp0`, `lamp1`, emissive
//!   spheres of 2–4 W, about a tenth of the main light, floating in view in the back half of the room),
//!   which move 0.6–1.2 m, and `lamp0` goes dark and back (dark, it is a small black sphere).
//!
//! Linear and Catmull-Rom tracks are both used. The animation is attached (shape ids resolved),
//! so [`Generated::desc`] builds at any time with [`crate::animation::build_at`] and its RON text
//! (with `id`s and the `animation` section) renders with `restir render X.ron --frames 0..23`.

use glam::{Mat4, Vec3};
use restir_sampling::Pcg32;

use super::stage::LIGHT_HEIGHT;
use super::util::{emitter, hue_colour, round, round3, uniform};
use super::{AssetContents, GenerateError, Generated, Kind};
use crate::desc::{
    AnimationDesc, CameraKey, CameraTrack, EmissionKey, Interpolation, Keys, MotionKey, ShapeTrack,
};
use crate::{GeometryDesc, MaterialRef, SceneDesc, ShapeDesc, TransformOp, V3};

/// Frames per second of the generated animations.
pub const FPS: f32 = 12.0;
/// Length of the generated animations in seconds: keys span `0..=DURATION`, frames `0..=23`.
pub const DURATION: f32 = 2.0;

/// A shape's world-space bounding box (its centre and half extents), from its geometry and
/// `to_world`; meshes from files are read from the generated assets.
fn bounds(shape: &ShapeDesc, generated: &Generated) -> Option<(Vec3, Vec3)> {
    let square = || {
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(x, y)| Vec3::new(x, y, 0.0))
            .to_vec()
    };
    let points: Vec<Vec3> = match &shape.geometry {
        GeometryDesc::Rectangle | GeometryDesc::Disk => square(),
        GeometryDesc::Cube => (0..8)
            .map(|i| {
                Vec3::new(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                )
            })
            .collect(),
        GeometryDesc::Sphere { center, radius } => {
            let c = Vec3::from(*center);
            [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z]
                .map(|d| c + *radius * d)
                .to_vec()
        }
        GeometryDesc::Obj { filename } => {
            let asset = generated.assets.iter().find(|a| &a.filename == filename)?;
            let AssetContents::Text(text) = &asset.contents else {
                return None;
            };
            text.lines()
                .filter_map(|l| l.strip_prefix("v "))
                .filter_map(|l| {
                    let v: Vec<f32> = l
                        .split_whitespace()
                        .filter_map(|x| x.parse().ok())
                        .collect();
                    (v.len() == 3).then(|| Vec3::new(v[0], v[1], v[2]))
                })
                .collect()
        }
        GeometryDesc::Mesh { positions, .. } => positions.iter().map(|p| Vec3::from(*p)).collect(),
        _ => return None,
    };
    let m = crate::transform_matrix(&shape.to_world).ok()?;
    let points: Vec<Vec3> = points.iter().map(|p| m.transform_point3(*p)).collect();
    let lo = points.iter().copied().reduce(Vec3::min)?;
    let hi = points.iter().copied().reduce(Vec3::max)?;
    Some(((lo + hi) / 2.0, (hi - lo) / 2.0))
}

/// The luminance of a radiance.
fn luminance(c: V3) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// `count` distinct entries of `from` in random order (fewer if `from` is shorter).
fn choose(rng: &mut Pcg32, from: &[usize], count: usize) -> Vec<usize> {
    let mut v = from.to_vec();
    let count = count.min(v.len());
    for i in 0..count {
        let j = i + rng.next_bounded((v.len() - i) as u32) as usize;
        v.swap(i, j);
    }
    v.truncate(count);
    v
}

/// A random sign.
fn sign(rng: &mut Pcg32) -> f32 {
    if rng.next_bounded(2) == 0 { -1.0 } else { 1.0 }
}

/// The camera track: an orbit of `angle` degrees about the vertical through the target, the
/// distance scaled to `dolly` and the eye raised by `lift` by the end, at constant speed.
fn camera_track(eye: Vec3, target: Vec3, angle: f32, dolly: f32, lift: f32) -> CameraTrack {
    let keys = (0..=4)
        .map(|k| {
            let f = k as f32 / 4.0;
            let turn = Mat4::from_rotation_y((angle * f).to_radians());
            let d = turn.transform_vector3(eye - target) * (1.0 + (dolly - 1.0) * f);
            let p = target + d + Vec3::new(0.0, lift * f, 0.0);
            CameraKey {
                time: DURATION * f,
                position: round3(p.to_array(), 3),
                target: target.to_array(),
                up: [0.0, 1.0, 0.0],
                fov: None,
            }
        })
        .collect();
    CameraTrack {
        interpolation: Interpolation::CatmullRom,
        keys: Keys(keys),
    }
}

/// Rigid motion keys at 0, 1 and 2 s: from rest to `end` through a point part-way there and off
/// the straight line, turning to `turn` (degrees about x, y, z).
fn rigid(rng: &mut Pcg32, end: Vec3, turn: V3) -> Keys<MotionKey> {
    let side = Vec3::new(-end.z, 0.0, end.x) * uniform(rng, -0.3, 0.3);
    let mid = end * uniform(rng, 0.35, 0.65) + side;
    let half = uniform(rng, 0.35, 0.65);
    Keys(vec![
        MotionKey {
            time: 0.0,
            translate: [0.0; 3],
            rotate: [0.0; 3],
        },
        MotionKey {
            time: 1.0,
            translate: round3(mid.to_array(), 3),
            rotate: round3(turn.map(|a| a * half), 1),
        },
        MotionKey {
            time: DURATION,
            translate: round3(end.to_array(), 3),
            rotate: round3(turn, 1),
        },
    ])
}

/// A horizontal vector of a length in `[lo, hi)` in a random direction.
fn horizontal(rng: &mut Pcg32, lo: f32, hi: f32) -> Vec3 {
    let length = uniform(rng, lo, hi);
    let phi = uniform(rng, 0.0, core::f32::consts::TAU);
    Vec3::new(phi.cos(), 0.0, phi.sin()) * length
}

fn scaled(radiance: V3, s: f32) -> V3 {
    radiance.map(|c| round(c * s, 4))
}

/// Emission keys that go dark and come back: full until 0.5–0.8 s, down to zero in 0.15 s, dark
/// for 0.3–0.45 s (at least three frames), back up in 0.15 s. Returns the keys and the dark span.
fn blink(rng: &mut Pcg32, radiance: V3) -> (Keys<EmissionKey>, (f32, f32)) {
    let off = round(uniform(rng, 0.5, 0.8), 3);
    let dark = round(uniform(rng, 0.3, 0.45), 3);
    let ramp = 0.15;
    let times = [
        0.0,
        off,
        off + ramp,
        off + ramp + dark,
        off + 2.0 * ramp + dark,
        DURATION,
    ];
    let levels = [1.0, 1.0, 0.0, 0.0, 1.0, 1.0];
    let keys = times
        .iter()
        .zip(levels)
        .map(|(&t, l)| EmissionKey {
            time: round(t, 3),
            radiance: scaled(radiance, l),
        })
        .collect();
    (
        Keys(keys),
        (round(off + ramp, 3), round(off + ramp + dark, 3)),
    )
}

/// Emission keys at 0, 1 and 2 s: the radiance as generated, then 2–3× (a swell) or 0.2–0.4× (a
/// fade) of it, then 0.6–1.5× of it.
fn swell(rng: &mut Pcg32, radiance: V3) -> Keys<EmissionKey> {
    let middle = if rng.next_bounded(2) == 0 {
        uniform(rng, 2.0, 3.0)
    } else {
        uniform(rng, 0.2, 0.4)
    };
    let end = uniform(rng, 0.6, 1.5);
    Keys(
        [(0.0, 1.0), (1.0, middle), (DURATION, end)]
            .into_iter()
            .map(|(time, s)| EmissionKey {
                time,
                radiance: if s == 1.0 {
                    radiance
                } else {
                    scaled(radiance, s)
                },
            })
            .collect(),
    )
}

/// A track for `shape` under the name `id` (the shape gets the id).
fn track(
    shapes: &mut [ShapeDesc],
    shape: usize,
    id: String,
    interpolation: Interpolation,
    pivot: Vec3,
) -> ShapeTrack {
    shapes[shape].id = Some(id.clone());
    ShapeTrack {
        id,
        interpolation,
        pivot: round3(pivot.to_array(), 3),
        motion: None,
        emission: None,
        shape,
    }
}

/// A track that moves shape `shape` rigidly by `motion` ([`track`] with its motion keys).
fn mover(
    shapes: &mut [ShapeDesc],
    shape: usize,
    id: String,
    interpolation: Interpolation,
    pivot: Vec3,
    motion: Keys<MotionKey>,
) -> ShapeTrack {
    ShapeTrack {
        motion: Some(motion),
        ..track(shapes, shape, id, interpolation, pivot)
    }
}

/// Catmull-Rom for the even-numbered of a group of moving shapes, linear for the others.
fn alternate(n: usize) -> Interpolation {
    if n.is_multiple_of(2) {
        Interpolation::CatmullRom
    } else {
        Interpolation::Linear
    }
}

/// The camera's look-at (eye, target), or an error when the camera is not one look-at.
fn look_at(desc: &SceneDesc) -> Result<(Vec3, Vec3), GenerateError> {
    match desc.camera.to_world.as_slice() {
        [TransformOp::LookAt { origin, target, .. }] => {
            Ok((Vec3::from(*origin), Vec3::from(*target)))
        }
        _ => Err(GenerateError::Animation(
            "the camera's to_world is not one LookAt".into(),
        )),
    }
}

fn material_is(shape: &ShapeDesc, pred: impl Fn(&str) -> bool) -> bool {
    matches!(&shape.material, Some(MaterialRef::Ref(name)) if pred(name))
}

/// What a generated animation does, for the header.
struct Summary(Vec<String>);

/// The many-light stages' animation (rectangles, spheres or meshes).
fn many_lights(
    generated: &mut Generated,
    kind: Kind,
    rng: &mut Pcg32,
    summary: &mut Summary,
) -> Result<AnimationDesc, GenerateError> {
    let (eye, target) = look_at(&generated.desc)?;
    let angle = sign(rng) * round(uniform(rng, 8.0, 20.0), 1);
    let dolly = uniform(rng, 0.88, 1.0);
    let lift = uniform(rng, -0.6, 0.4);
    let camera = camera_track(eye, target, angle, dolly, lift);
    summary.0.push(format!(
        "the camera orbits {angle}° about its target and moves {:.0} % closer",
        100.0 * (1.0 - dolly)
    ));

    let info: Vec<Option<(Vec3, Vec3)>> = generated
        .desc
        .shapes
        .iter()
        .map(|s| bounds(s, generated))
        .collect();
    let box_of = |i: usize| {
        info[i].ok_or_else(|| GenerateError::Animation(format!("shape {i} has no bounds")))
    };
    let shapes = &generated.desc.shapes;
    let receivers: Vec<usize> = (0..shapes.len())
        .filter(|&i| {
            shapes[i].emission.is_none() && material_is(&shapes[i], |m| m.starts_with("receiver"))
        })
        .collect();
    let slats: Vec<usize> = (0..shapes.len())
        .filter(|&i| {
            shapes[i].geometry == GeometryDesc::Rectangle
                && material_is(&shapes[i], |m| m == "occluder")
        })
        .collect();
    let mut lights: Vec<usize> = (0..shapes.len())
        .filter(|&i| shapes[i].emission.is_some())
        .collect();
    // Brightest first: radiance times area (a box's largest face stands for the area).
    let power = |i: usize| {
        let h = info[i].map_or(Vec3::ZERO, |b| b.1);
        let area = (h.x * h.y).max(h.y * h.z).max(h.x * h.z);
        luminance(shapes[i].emission.unwrap_or_default()) * area
    };
    lights.sort_by(|&a, &b| power(b).total_cmp(&power(a)).then(a.cmp(&b)));
    let radiances: Vec<V3> = shapes
        .iter()
        .map(|s| s.emission.unwrap_or_default())
        .collect();
    let radiance = |i: usize| radiances[i];

    let mut tracks = Vec::new();
    for (n, &i) in choose(rng, &receivers, 3).iter().enumerate() {
        let (c, h) = box_of(i)?;
        let size = 2.0 * h.x.max(h.z);
        let end = horizontal(rng, 0.4 * size, 0.8 * size);
        let turn = [0.0, sign(rng) * uniform(rng, 15.0, 45.0), 0.0];
        tracks.push(mover(
            &mut generated.desc.shapes,
            i,
            format!("object{n}"),
            Interpolation::CatmullRom,
            c,
            rigid(rng, end, turn),
        ));
    }
    summary.0.push("three receivers move and turn".into());
    for (n, &i) in choose(rng, &slats, 2).iter().enumerate() {
        let (c, _) = box_of(i)?;
        let end = horizontal(rng, 0.3, 0.8);
        let turn = [0.0, sign(rng) * uniform(rng, 20.0, 60.0), 0.0];
        tracks.push(mover(
            &mut generated.desc.shapes,
            i,
            format!("slat{n}"),
            Interpolation::Linear,
            c,
            rigid(rng, end, turn),
        ));
    }
    if !slats.is_empty() {
        summary.0.push("two slats move and turn".into());
    }

    if kind == Kind::Meshes {
        // lights[0] is the brightest mesh: it moves, as two others; the next two change.
        let (pulse0, pulse1) = (lights.get(1).copied(), lights.get(2).copied());
        let mut moving = vec![lights[0]];
        moving.extend(choose(rng, lights.get(3..).unwrap_or_default(), 2));
        for (n, &i) in moving.iter().enumerate() {
            let (c, _) = box_of(i)?;
            let end = horizontal(rng, 0.5, 1.2);
            let turn = [
                sign(rng) * uniform(rng, 0.0, 10.0),
                sign(rng) * uniform(rng, 30.0, 90.0),
                0.0,
            ];
            tracks.push(mover(
                &mut generated.desc.shapes,
                i,
                format!("light{n}"),
                alternate(n),
                c,
                rigid(rng, end, turn),
            ));
        }
        summary.0.push(format!(
            "{} emissive meshes move whole (the brightest among them)",
            moving.len()
        ));
        if let Some(i) = pulse0 {
            let (keys, (a, b)) = blink(rng, radiance(i));
            let mut t = track(
                &mut generated.desc.shapes,
                i,
                "pulse0".into(),
                Interpolation::Linear,
                Vec3::ZERO,
            );
            t.emission = Some(keys);
            tracks.push(t);
            summary.0.push(format!(
                "the second brightest mesh is dark from {a} to {b} s"
            ));
        }
        if let Some(i) = pulse1 {
            let mut t = track(
                &mut generated.desc.shapes,
                i,
                "pulse1".into(),
                Interpolation::CatmullRom,
                Vec3::ZERO,
            );
            t.emission = Some(swell(rng, radiance(i)));
            tracks.push(t);
            summary
                .0
                .push("the third brightest mesh swells or fades".into());
        }
    } else {
        let top =
            |fraction: f32| &lights[..((lights.len() as f32 * fraction).ceil() as usize).max(1)];
        let pulses = choose(rng, top(0.01).to_vec().as_slice(), 3);
        let movers: Vec<usize> = top(0.05)
            .iter()
            .copied()
            .filter(|i| !pulses.contains(i))
            .collect();
        let movers = choose(rng, &movers, 8);
        for (n, &i) in movers.iter().enumerate() {
            let (c, _) = box_of(i)?;
            let mut end = horizontal(rng, 0.6, 1.5);
            end.y = (c.y + uniform(rng, -0.15, 0.15)).clamp(LIGHT_HEIGHT.0, LIGHT_HEIGHT.1) - c.y;
            let turn = if kind == Kind::Rects {
                [0.0, sign(rng) * uniform(rng, 30.0, 90.0), 0.0]
            } else {
                [0.0; 3]
            };
            tracks.push(mover(
                &mut generated.desc.shapes,
                i,
                format!("light{n}"),
                alternate(n),
                c,
                rigid(rng, end, turn),
            ));
        }
        summary
            .0
            .push(format!("{} lights of the brightest 5 % move", movers.len()));
        for (n, &i) in pulses.iter().enumerate() {
            let mut t = track(
                &mut generated.desc.shapes,
                i,
                format!("pulse{n}"),
                Interpolation::Linear,
                Vec3::ZERO,
            );
            if n == 0 {
                let (keys, (a, b)) = blink(rng, radiance(i));
                t.emission = Some(keys);
                summary.0.push(format!(
                    "pulse0 (of the brightest 1 %) is dark from {a} to {b} s"
                ));
            } else {
                t.emission = Some(swell(rng, radiance(i)));
            }
            tracks.push(t);
        }
        if pulses.len() > 1 {
            summary
                .0
                .push(format!("{} more swell or fade", pulses.len() - 1));
        }
    }
    Ok(AnimationDesc {
        fps: FPS,
        camera: Some(camera),
        shapes: tracks,
        location: Default::default(),
    })
}

/// A glossy room's animation (and its two added lamps).
fn room(
    generated: &mut Generated,
    rng: &mut Pcg32,
    summary: &mut Summary,
) -> Result<AnimationDesc, GenerateError> {
    let (eye, target) = look_at(&generated.desc)?;
    let angle = sign(rng) * round(uniform(rng, 4.0, 10.0), 1);
    let dolly = uniform(rng, 0.9, 0.97);
    let camera = camera_track(eye, target, angle, dolly, 0.0);
    summary.0.push(format!(
        "the camera orbits {angle}° about its target and moves {:.0} % closer",
        100.0 * (1.0 - dolly)
    ));
    let missing = || GenerateError::Animation("not a generated room".into());
    // Shape 0 is the floor, shape 1 the ceiling.
    let shapes = &generated.desc.shapes;
    let (_, floor_h) = shapes
        .first()
        .and_then(|s| bounds(s, generated))
        .ok_or_else(missing)?;
    let (ceiling, _) = shapes
        .get(1)
        .and_then(|s| bounds(s, generated))
        .ok_or_else(missing)?;
    let (hw, hd, h) = (floor_h.x, floor_h.z, ceiling.y);
    let objects: Vec<usize> = (0..shapes.len())
        .filter(|&i| {
            shapes[i].emission.is_none()
                && matches!(
                    shapes[i].geometry,
                    GeometryDesc::Sphere { .. } | GeometryDesc::Cube
                )
        })
        .collect();
    let light = (0..shapes.len())
        .find(|&i| shapes[i].emission.is_some())
        .ok_or_else(missing)?;
    let mut tracks = Vec::new();

    for (n, &i) in choose(rng, &objects, 2).iter().enumerate() {
        let (c, _) = bounds(&generated.desc.shapes[i], generated).ok_or_else(missing)?;
        // Towards the camera or sideways (within 60° of +z), away from the partition and walls.
        let phi = uniform(rng, -60f32, 60.0).to_radians();
        let end = Vec3::new(phi.sin(), 0.0, phi.cos()) * uniform(rng, 0.2, 0.4);
        let turn = [0.0, sign(rng) * uniform(rng, 15.0, 45.0), 0.0];
        tracks.push(mover(
            &mut generated.desc.shapes,
            i,
            format!("object{n}"),
            Interpolation::CatmullRom,
            c,
            rigid(rng, end, turn),
        ));
    }
    summary.0.push("two floor objects move and turn".into());

    // The hidden light slides along x (staying behind its partition or the camera) and dims.
    let (c, _) = bounds(&generated.desc.shapes[light], generated).ok_or_else(missing)?;
    // Towards the middle of the room, where there is always space (0.15–0.4 m).
    let shift = -c.x.signum() * uniform(rng, 0.15, 0.4);
    let main = generated.desc.shapes[light].emission.unwrap_or_default();
    let mut t = track(
        &mut generated.desc.shapes,
        light,
        "light0".into(),
        Interpolation::Linear,
        c,
    );
    t.motion = Some(Keys(vec![
        MotionKey {
            time: 0.0,
            translate: [0.0; 3],
            rotate: [0.0; 3],
        },
        MotionKey {
            time: DURATION,
            translate: [round(shift, 3), 0.0, 0.0],
            rotate: [0.0; 3],
        },
    ]));
    let dim = round(uniform(rng, 0.4, 0.7), 2);
    t.emission = Some(Keys(vec![
        EmissionKey {
            time: 0.0,
            radiance: main,
        },
        EmissionKey {
            time: 1.0,
            radiance: scaled(main, dim),
        },
        EmissionKey {
            time: DURATION,
            radiance: main,
        },
    ]));
    tracks.push(t);
    summary.0.push(format!(
        "the hidden light slides {:.2} m and dims to {:.0} % at 1 s",
        shift.abs(),
        100.0 * dim
    ));

    // Two small lamps floating in the back half, moving mostly across the room.
    // Inside the room and in the camera's view (which looks a little down at the back wall:
    // within ±0.45 of the distance across and 0.2 of it above the eye), away from the walls.
    let inside = |p: Vec3| {
        let z = p.z.clamp(-hd + 0.6, -0.1);
        let dist = eye.z - z;
        Vec3::new(
            p.x.clamp(
                (-hw + 0.4).max(eye.x - 0.45 * dist),
                (hw - 0.4).min(eye.x + 0.45 * dist),
            ),
            p.y.clamp(1.1, (h - 0.35).min(eye.y + 0.2 * dist)),
            z,
        )
    };
    for n in 0..2 {
        let radius = round(uniform(rng, 0.05, 0.08), 3);
        let power = uniform(rng, 2.0, 4.0);
        // A sphere of radius r emits π · L · 4πr².
        let level = power / (4.0 * core::f32::consts::PI * core::f32::consts::PI * radius * radius);
        let tint = hue_colour(rng.next_f32(), uniform(rng, 0.1, 0.5));
        let radiance = tint.map(|c| round(c * level, 3));
        let start = inside(Vec3::new(
            uniform(rng, -hw + 0.5, hw - 0.5),
            uniform(rng, 1.1, h - 0.4),
            uniform(rng, -hd + 0.7, -0.2),
        ));
        let length = uniform(rng, 0.6, 1.2);
        let dir = Vec3::new(
            -start.x.signum() * uniform(rng, 0.7, 1.0),
            uniform(rng, -0.3, 0.3),
            uniform(rng, -0.4, 0.4),
        )
        .normalize();
        let end = inside(start + dir * length) - start;
        let center = round3(start.to_array(), 3);
        generated.desc.shapes.push(emitter(
            GeometryDesc::Sphere { center, radius },
            Vec::new(),
            radiance,
        ));
        let i = generated.desc.shapes.len() - 1;
        let mut t = track(
            &mut generated.desc.shapes,
            i,
            format!("lamp{n}"),
            if n == 0 {
                Interpolation::Linear
            } else {
                Interpolation::CatmullRom
            },
            Vec3::from(center),
        );
        // The middle key stays inside too (the path bends a little).
        let mut keys = rigid(rng, end, [0.0; 3]);
        let mid = &mut keys.0[1].translate;
        *mid = round3(
            (inside(Vec3::from(center) + Vec3::from(*mid)) - Vec3::from(center)).to_array(),
            3,
        );
        t.motion = Some(keys);
        if n == 0 {
            let (keys, (a, b)) = blink(rng, radiance);
            // One track, one interpolation: the blink's keys are piecewise linear.
            t.emission = Some(keys);
            summary.0.push(format!(
                "two small lamps are added and move; lamp0 is dark from {a} to {b} s"
            ));
        }
        tracks.push(t);
    }
    Ok(AnimationDesc {
        fps: FPS,
        camera: Some(camera),
        shapes: tracks,
        location: Default::default(),
    })
}

/// Animates a generated scene of kind `kind` from `seed` (see the module documentation): shapes
/// that move get ids, a room gets two lamps, and the animation is attached to the description
/// (track shape indices set); the header says what moves.
pub fn animate(generated: &mut Generated, kind: Kind, seed: u64) -> Result<(), GenerateError> {
    if generated.desc.animation.is_some() {
        return Err(GenerateError::Animation(
            "the scene already has an animation".into(),
        ));
    }
    let mut rng = Pcg32::new(seed, 0x6d6f_7469); // "moti"
    let mut summary = Summary(Vec::new());
    let anim = match kind {
        Kind::Rects | Kind::Spheres | Kind::Meshes => {
            many_lights(generated, kind, &mut rng, &mut summary)?
        }
        Kind::Room => room(generated, &mut rng, &mut summary)?,
    };
    crate::animation::attach(&mut generated.desc, anim, "", 0)
        .map_err(|e| GenerateError::Animation(e.message))?;
    generated.header.push_str(&format!(
        "\nAnimated (issue 19): {FPS} fps over {DURATION} s, render with --frames 0..23:\n{}.",
        summary.0.join(";\n")
    ));
    Ok(())
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use restir_geometry::Shape;

    use super::super::{Issue, Split, family};
    use super::{DURATION, FPS};
    use crate::animation::{build_at, frame_time};

    /// A point that moves with the shape: a sphere's centre, the mean of a mesh's vertices.
    fn centroid(s: &Shape) -> Vec3 {
        match s {
            Shape::Sphere(s) => s.center,
            Shape::Mesh(m) => m.positions().iter().sum::<Vec3>() / m.positions().len() as f32,
        }
    }

    #[test]
    fn every_moving_member_generates_parses_builds_and_moves_the_shapes_it_names() {
        let dir = std::env::temp_dir().join(format!("restir-motion-{}", std::process::id()));
        for issue in [Issue::DiMotion, Issue::PtMotion] {
            for split in [Split::Train, Split::Test] {
                for member in family(issue, split) {
                    let name = member.name();
                    let generated = member.generate().unwrap();
                    let text = generated.ron().unwrap();
                    assert_eq!(text, member.generate().unwrap().ron().unwrap(), "{name}");
                    let path = generated.write(&dir, &name).unwrap();
                    let desc = crate::parse_ron(&text, &path).unwrap();
                    let anim = desc.animation.as_ref().expect("animated");
                    let made = generated.desc.animation.as_ref().unwrap();
                    // Attached in code as the parser attaches it: the same shapes.
                    assert_eq!(anim.shapes, made.shapes, "{name}");
                    assert_eq!(desc.shapes, generated.desc.shapes, "{name}");
                    assert_eq!(anim.fps, FPS);
                    for t in &anim.shapes {
                        assert_eq!(desc.shapes[t.shape].id.as_deref(), Some(t.id.as_str()));
                    }
                    let moving: Vec<usize> = (0..desc.shapes.len())
                        .filter(|&i| anim.shape_moves(i))
                        .collect();
                    let moving_lights = moving
                        .iter()
                        .filter(|&&i| desc.shapes[i].emission.is_some())
                        .count();
                    assert!(moving.len() - moving_lights >= 2, "{name}: objects");
                    assert!(moving_lights >= 3, "{name}: {moving_lights} moving lights");

                    let a = build_at(&desc, &path, 0.0).unwrap();
                    let b = build_at(&desc, &path, DURATION).unwrap();
                    assert_eq!(a.shapes.len(), desc.shapes.len(), "{name}");
                    assert!(
                        (a.camera.origin() - b.camera.origin()).length() > 0.1,
                        "{name}: the camera stays"
                    );
                    for i in 0..desc.shapes.len() {
                        let (p, q) = (centroid(&a.shapes[i]), centroid(&b.shapes[i]));
                        if anim.shape_moves(i) {
                            let expect = anim.shape_motion(i, 0.0, DURATION).transform_point3(p);
                            assert!((q - expect).length() < 2e-3, "{name}: shape {i}");
                            assert!((q - p).length() > 0.04, "{name}: shape {i} stays");
                        } else {
                            assert_eq!(p, q, "{name}: shape {i} moves");
                        }
                    }

                    // One light goes dark for a few frames and leaves the light list.
                    let dark: Vec<u32> = (0..24)
                        .filter(|&f| {
                            anim.shapes
                                .iter()
                                .any(|s| s.emission_at(frame_time(f, FPS)) == Some([0.0; 3]))
                        })
                        .collect();
                    assert!(dark.len() >= 3, "{name}: dark frames {dark:?}");
                    assert!(
                        !dark.contains(&0) && !dark.contains(&23),
                        "{name}: {dark:?}"
                    );
                    let c = build_at(&desc, &path, frame_time(dark[1], FPS)).unwrap();
                    assert!(
                        c.features.emitter_count < a.features.emitter_count,
                        "{name}: {} emitters when dark, {} before",
                        c.features.emitter_count,
                        a.features.emitter_count
                    );
                    assert_eq!(b.features.emitter_count, a.features.emitter_count);
                }
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_moving_families_share_the_seeds_and_differ_by_seed() {
        for issue in [Issue::DiMotion, Issue::PtMotion] {
            let train = family(issue, Split::Train);
            let test = family(issue, Split::Test);
            assert_eq!(train.len(), 6);
            assert_eq!(train.len(), test.len());
            assert_eq!(train[0].seed, 1);
            assert_eq!(test[0].seed, 101);
            assert!(
                train[0]
                    .name()
                    .starts_with(&format!("{}-train-00-", issue.name()))
            );
            let (a, b) = (train[0].generate().unwrap(), test[0].generate().unwrap());
            assert_ne!(a.desc.animation, b.desc.animation);
        }
    }
}
