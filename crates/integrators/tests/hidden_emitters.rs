//! `hide_emitters`: camera rays pass through area lights (Mitsuba 3's rule), for every estimator.
//!
//! Scene A: a diffuse floor lit by a small sphere light just above it, and between the camera
//! and both a one-sided emissive rectangle facing the camera (it sends no light to the floor and
//! cannot shadow the sphere's light, which lies below it). Scene B is A without the rectangle.
//! With `hide_emitters` the camera sees through the rectangle and the sphere, so A and B have the
//! same expected image, block by block, for the path tracer, ReSTIR DI and ReSTIR PT. The
//! control: A with its emitters shown differs from B by far (the test sees the rectangle).

use restir_scene::parse_ron;

mod common;
use common::{block_statistics, max_z, render_image};

const SIZE: u32 = 32;
const BLOCK: u32 = 8;
const Z_MAX: f64 = 4.5;

fn scene(rectangle: bool, hide: bool) -> common::Built {
    let lamp = if rectangle {
        // Faces +z (the camera); one-sided, so its back, towards the floor, is dark.
        "(geometry: Rectangle, to_world: [Scale((0.8, 0.8, 1)), Translate((0, 0, 1))], \
         emission: Some((4, 4, 4))),"
    } else {
        ""
    };
    let ron = format!(
        r#"(
        camera: (fov: 40, to_world: [LookAt(origin: (0, 0, 4), target: (0, 0, 0), up: (0, 1, 0))]),
        film: (width: {SIZE}, height: {SIZE}, filter: Box),
        integrator: (max_depth: 3, hide_emitters: {hide}),
        shapes: [
            (geometry: Rectangle, to_world: [Scale((3, 3, 1)), Translate((0, 0, -1))],
             material: Some(Inline(Diffuse(reflectance: (0.7, 0.6, 0.5))))),
            (geometry: Sphere(center: (0.3, 0.2, -0.6), radius: 0.15), emission: Some((20, 18, 15))),
            {lamp}
        ],
    )"#
    );
    let desc = parse_ron(&ron, "hidden.ron".as_ref()).unwrap();
    common::build(&desc, ".".as_ref(), "hidden.ron".as_ref())
}

fn stats(
    scene: &common::Built,
    name: &str,
    params: &[(&str, &str)],
    seeds: u64,
) -> Vec<(f64, f64)> {
    block_statistics(
        |seed| render_image(scene, name, params, 2, seed),
        seeds,
        0x41de,
        BLOCK,
    )
}

#[test]
fn the_camera_sees_through_hidden_area_lights() {
    let with = scene(true, true);
    let without = scene(false, true);
    // The centre pixel looks through the rectangle at the lit floor (it was black before the
    // rule: the rectangle's unlit back material).
    let img = render_image(&with, "path", &[], 16, 1);
    let centre = img.pixels[(SIZE / 2 * SIZE + SIZE / 2) as usize];
    assert!(centre.max_element() > 0.01, "centre {centre:?}");

    let reference = stats(&without, "path", &[], 64);
    for (name, params) in [
        ("path", &[][..]),
        ("restir-di", &[][..]),
        ("restir-pt", &[][..]),
    ] {
        let z = max_z(&stats(&with, name, params, 64), &reference);
        eprintln!("{name}, hidden rectangle against none: max |z| = {z:.2}");
        assert!(z < Z_MAX, "{name}: max |z| = {z:.2}");
    }

    // Control: shown, the rectangle is in the image.
    let shown = scene(true, false);
    let z = max_z(&stats(&shown, "path", &[], 16), &reference);
    eprintln!("rectangle shown against none: max |z| = {z:.2}");
    assert!(
        z > 4.0 * Z_MAX,
        "the shown rectangle should be seen: max |z| = {z:.2}"
    );
}
