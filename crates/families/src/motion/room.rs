//! The motion of a glossy room (camera, two objects, the hidden light and two added lamps).

use super::*;

/// A glossy room's animation (and its two added lamps).
pub(super) fn room(
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
