//! The motion of a many-light scene (rectangles, spheres or emissive meshes over receivers).

use super::*;
use crate::stage::LIGHT_HEIGHT;

/// The many-light stages' animation (rectangles, spheres or meshes).
pub(super) fn many_lights(
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
