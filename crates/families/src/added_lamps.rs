//! Small lamps added to a scene somebody else wrote (a corpus scene), by a rule that needs only
//! the scene's geometry and camera, so that a real scene becomes a many-light scene without
//! anyone placing lights by hand. The written file includes the scene (Mitsuba's `<include>`)
//! and adds one emissive sphere per lamp after it.
//!
//! The rule, for each lamp, from the seed's stream:
//!
//! 1. a direction uniform on the sphere from the camera's position; the ray's first hit is the
//!    lamp's anchor (a miss, or a hit closer than 5 % of the scene's bounding-box diagonal `D`,
//!    draws again);
//! 2. the lamp hangs above the anchor along the surface normal turned towards the camera's side,
//!    at a height uniform in `[0.5 %, 2 %]·D` but at most half the hit distance, with a radius
//!    uniform in `[0.05 %, 0.15 %]·D` and at most a third of the height;
//! 3. a ray from the anchor along that normal must travel the height plus twice the radius
//!    without a hit (the lamp is in free space), or the lamp draws again (at most 100 tries);
//! 4. powers log-uniform over [`POWER_RATIO`], three in four warm white and the rest coloured,
//!    scaled so that all the lamps together emit `0.2·A` watts, `A` the area of the scene's
//!    bounding box (in the scene's units).
//!
//! Lamps therefore sit where the camera's position sees surfaces, in every direction (behind the
//! camera too), mostly just above floors, walls and ledges; many are in view.

use glam::{Vec2, Vec3};
use restir_geometry::{Ray, offset_ray_origin};
use restir_sampling::Pcg32;
use restir_sampling::warp::sample_uniform_sphere;
use restir_scene::Scene;

use super::util::{lamp_tint, uniform};

/// The brightest lamp's power over the dimmest's, at most.
pub const POWER_RATIO: f32 = 100.0;

/// One added lamp: an emissive sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AddedLamp {
    /// Centre.
    pub centre: Vec3,
    /// Radius.
    pub radius: f32,
    /// Emitted radiance.
    pub radiance: Vec3,
}

/// `count` lamps for `scene` by the rule of the module documentation, from `seed`. Fewer when the
/// rule cannot place them (a scene the camera's rays mostly leave).
pub fn added_lamps(scene: &Scene, count: u32, seed: u64) -> Vec<AddedLamp> {
    let mut rng = Pcg32::new(seed, 0x6164_6465); // "adde"
    let (lo, hi) = scene.accel.bounds();
    let extent = (hi - lo).max(Vec3::splat(1e-6));
    let diag = extent.length();
    let eye = scene
        .camera
        .generate_ray(Vec2::splat(0.5), Vec2::splat(0.5))
        .o;
    let mut drawn = Vec::new();
    for _ in 0..count {
        let spot = (0..100).find_map(|_| {
            let d = sample_uniform_sphere(rng.next_2d());
            let height = uniform(&mut rng, 0.005, 0.02) * diag;
            let radius = uniform(&mut rng, 0.0005, 0.0015) * diag;
            let hit = scene.intersect(&Ray::new(eye, d))?;
            let t = hit.p.distance(eye);
            if t < 0.05 * diag {
                return None;
            }
            let n = if hit.ng.dot(d) > 0.0 { -hit.ng } else { hit.ng };
            let height = height.min(0.5 * t);
            let radius = radius.min(height / 3.0);
            let up = Ray::new(offset_ray_origin(hit.p, n, n), n);
            let free = scene
                .intersect(&up)
                .is_none_or(|h| h.p.distance(hit.p) > height + 2.0 * radius);
            free.then_some((hit.p + n * height, radius))
        });
        let Some((centre, radius)) = spot else {
            continue;
        };
        let level = POWER_RATIO.powf(rng.next_f32());
        let tint = lamp_tint(&mut rng);
        drawn.push((centre, radius, level, Vec3::from(tint)));
    }
    // Flux of a Lambertian sphere: π · L · 4πr².
    let area = 2.0 * (extent.x * extent.y + extent.y * extent.z + extent.z * extent.x);
    let unit: f32 = drawn
        .iter()
        .map(|&(_, r, level, tint)| {
            level * tint.element_sum() / 3.0 * 4.0 * core::f32::consts::PI * r * r
        })
        .sum();
    let scale = 0.2 * area / (core::f32::consts::PI * unit.max(1e-30));
    drawn
        .into_iter()
        .map(|(centre, radius, level, tint)| AddedLamp {
            centre,
            radius,
            radiance: tint * level * scale,
        })
        .collect()
}

/// The Mitsuba 3 XML of `included` (a path written as given) with `lamps` added after it, each
/// line of `header` a comment at the top.
pub fn added_lamps_xml(included: &str, lamps: &[AddedLamp], header: &str) -> String {
    use core::fmt::Write;
    let mut text = String::from("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n");
    for line in header.lines() {
        let _ = writeln!(text, "<!-- {} -->", line.replace("--", "- -"));
    }
    let _ = writeln!(text, "<scene version=\"3.0.0\">");
    let _ = writeln!(text, "    <include filename=\"{included}\"/>");
    for l in lamps {
        let _ = writeln!(
            text,
            "    <shape type=\"sphere\"><point name=\"center\" x=\"{}\" y=\"{}\" z=\"{}\"/>\
             <float name=\"radius\" value=\"{}\"/><emitter type=\"area\">\
             <rgb name=\"radiance\" value=\"{}, {}, {}\"/></emitter></shape>",
            l.centre.x, l.centre.y, l.centre.z, l.radius, l.radiance.x, l.radiance.y, l.radiance.z
        );
    }
    text.push_str("</scene>\n");
    text
}
