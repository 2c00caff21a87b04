//! Animated family members (ReSTIR under motion): a generated scene plus an animation
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
//! so [`Generated::desc`] builds at any time with [`restir_scene::animation::build_at`] and its RON text
//! (with `id`s and the `animation` section) renders with `restir render X.ron --frames 0..23`.

use glam::{Mat4, Vec3};
use restir_sampling::Pcg32;

use super::util::{emitter, hue_colour, round, round3, uniform};
use super::{AssetContents, GenerateError, Generated, Kind};
use restir_scene::desc::{
    AnimationDesc, CameraKey, CameraTrack, EmissionKey, Interpolation, Keys, MotionKey, ShapeTrack,
};
use restir_scene::{GeometryDesc, MaterialRef, SceneDesc, ShapeDesc, TransformOp, V3};

/// Frames per second of the generated animations.
pub const FPS: f32 = 12.0;
/// Length of the generated animations in seconds: keys span `0..=DURATION`, frames `0..=23`.
pub const DURATION: f32 = 2.0;

/// A shape's world-space bounding box (its centre and half extents), from its geometry and
/// `to_world`; meshes from files are read from the generated assets.
pub(super) fn bounds(shape: &ShapeDesc, generated: &Generated) -> Option<(Vec3, Vec3)> {
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
    let m = restir_scene::transform_matrix(&shape.to_world).ok()?;
    let points: Vec<Vec3> = points.iter().map(|p| m.transform_point3(*p)).collect();
    let lo = points.iter().copied().reduce(Vec3::min)?;
    let hi = points.iter().copied().reduce(Vec3::max)?;
    Some(((lo + hi) / 2.0, (hi - lo) / 2.0))
}

/// The luminance of a radiance.
pub(super) fn luminance(c: V3) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// `count` distinct entries of `from` in random order (fewer if `from` is shorter).
pub(super) fn choose(rng: &mut Pcg32, from: &[usize], count: usize) -> Vec<usize> {
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
pub(super) fn sign(rng: &mut Pcg32) -> f32 {
    if rng.next_bounded(2) == 0 { -1.0 } else { 1.0 }
}

/// The camera track: an orbit of `angle` degrees about the vertical through the target, the
/// distance scaled to `dolly` and the eye raised by `lift` by the end, at constant speed.
pub(super) fn camera_track(
    eye: Vec3,
    target: Vec3,
    angle: f32,
    dolly: f32,
    lift: f32,
) -> CameraTrack {
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
pub(super) fn rigid(rng: &mut Pcg32, end: Vec3, turn: V3) -> Keys<MotionKey> {
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
pub(super) fn horizontal(rng: &mut Pcg32, lo: f32, hi: f32) -> Vec3 {
    let length = uniform(rng, lo, hi);
    let phi = uniform(rng, 0.0, core::f32::consts::TAU);
    Vec3::new(phi.cos(), 0.0, phi.sin()) * length
}

pub(super) fn scaled(radiance: V3, s: f32) -> V3 {
    radiance.map(|c| round(c * s, 4))
}

/// Emission keys that go dark and come back: full until 0.5–0.8 s, down to zero in 0.15 s, dark
/// for 0.3–0.45 s (at least three frames), back up in 0.15 s. Returns the keys and the dark span.
pub(super) fn blink(rng: &mut Pcg32, radiance: V3) -> (Keys<EmissionKey>, (f32, f32)) {
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
pub(super) fn swell(rng: &mut Pcg32, radiance: V3) -> Keys<EmissionKey> {
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
pub(super) fn track(
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
pub(super) fn mover(
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
pub(super) fn alternate(n: usize) -> Interpolation {
    if n.is_multiple_of(2) {
        Interpolation::CatmullRom
    } else {
        Interpolation::Linear
    }
}

/// The camera's look-at (eye, target), or an error when the camera is not one look-at.
pub(super) fn look_at(desc: &SceneDesc) -> Result<(Vec3, Vec3), GenerateError> {
    match desc.camera.to_world.as_slice() {
        [TransformOp::LookAt { origin, target, .. }] => {
            Ok((Vec3::from(*origin), Vec3::from(*target)))
        }
        _ => Err(GenerateError::Animation(
            "the camera's to_world is not one LookAt".into(),
        )),
    }
}

pub(super) fn material_is(shape: &ShapeDesc, pred: impl Fn(&str) -> bool) -> bool {
    matches!(&shape.material, Some(MaterialRef::Ref(name)) if pred(name))
}

/// What a generated animation does, for the header.
pub(super) struct Summary(pub(super) Vec<String>);

mod many;
mod room;

use many::many_lights;
use room::room;

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
        Kind::Hall => {
            return Err(GenerateError::Animation(
                "the hall is not animated (the moving families are rects, spheres, meshes and \
                 rooms)"
                    .into(),
            ));
        }
    };
    restir_scene::animation::attach(&mut generated.desc, anim, "", 0)
        .map_err(|e| GenerateError::Animation(e.message))?;
    generated.header.push_str(&format!(
        "\nAnimated: {FPS} fps over {DURATION} s, render with --frames 0..23:\n{}.",
        summary.0.join(";\n")
    ));
    Ok(())
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use restir_geometry::Shape;

    use super::{DURATION, FPS};
    use crate::{Family, Split, members};
    use restir_scene::animation::{build_at, frame_time};

    /// A point that moves with the shape: a sphere's centre, the mean of a mesh's vertices.
    fn centroid(s: &Shape) -> Vec3 {
        match s {
            Shape::Sphere(s) => s.center,
            Shape::Mesh(m) => m.positions().iter().sum::<Vec3>() / m.positions().len() as f32,
            other => {
                let (lo, hi) = other.bounds();
                0.5 * (lo + hi)
            }
        }
    }

    #[test]
    fn every_moving_member_generates_parses_builds_and_moves_the_shapes_it_names() {
        let tmp = restir_testkit::TempDir::new("motion", "members");
        let dir = tmp.join("motion");
        for family in [Family::DiMotion, Family::PtMotion] {
            for split in [Split::Train, Split::Test] {
                for member in members(family, split) {
                    let name = member.name();
                    let generated = member.generate().unwrap();
                    let text = generated.ron().unwrap();
                    assert_eq!(text, member.generate().unwrap().ron().unwrap(), "{name}");
                    let path = generated.write(&dir, &name).unwrap();
                    let desc = restir_scene::parse_ron(&text, &path).unwrap();
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
    }

    #[test]
    fn the_moving_families_share_the_seeds_and_differ_by_seed() {
        for family in [Family::DiMotion, Family::PtMotion] {
            let train = members(family, Split::Train);
            let test = members(family, Split::Test);
            assert_eq!(train.len(), 6);
            assert_eq!(train.len(), test.len());
            assert_eq!(train[0].seed, 1);
            assert_eq!(test[0].seed, 101);
            assert!(
                train[0]
                    .name()
                    .starts_with(&format!("{}-train-00-", family.name()))
            );
            let (a, b) = (train[0].generate().unwrap(), test[0].generate().unwrap());
            assert_ne!(a.desc.animation, b.desc.animation);
        }
    }
}
