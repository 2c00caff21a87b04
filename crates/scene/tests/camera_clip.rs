//! Mitsuba 3's clip planes (`near_clip`, `far_clip`): a camera sees only what lies between two
//! planes perpendicular to its axis, at camera-space depths, for the perspective, thin-lens and
//! orthographic sensors. The expectations below are what Mitsuba 3.9.1 (`scalar_rgb`) renders
//! for the same scene: a camera at the origin looking along +z, a rectangle at depth 0.5 that
//! fills the view and a larger one at depth 20. The corner pixel's ray meets the near rectangle
//! 0.64 units away and the far one 25 units away, so it tells planes from distances: a clip by
//! distance would see the near rectangle with `near_clip` 0.55 and miss the far one with
//! `far_clip` 21.

use glam::Vec2;
use restir_scene::{LoadOptions, load_scene};
use restir_testkit::TempDir;

/// What the camera sees through the film's centre and its top-left corner: the depth of the
/// surface hit, or `None` for a miss.
fn seen(sensor: &str, props: &str) -> [Option<f32>; 2] {
    let dir = TempDir::new("camera-clip", sensor);
    let path = dir.join(format!("{sensor}-{}.xml", props.len()));
    let fov = if sensor == "orthographic" {
        ""
    } else {
        r#"<float name="fov" value="60"/>"#
    };
    let rect = |z: f32, s: f32| {
        format!(
            r#"<shape type="rectangle"><transform name="to_world"><scale value="{s}"/>
            <rotate y="1" angle="180"/><translate z="{z}"/></transform>
            <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>"#
        )
    };
    let xml = format!(
        r#"<scene version="3.0.0">
        <sensor type="{sensor}">{fov}{props}
            <transform name="to_world"><lookat origin="0, 0, 0" target="0, 0, 1" up="0, 1, 0"/></transform>
            <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/>
            <rfilter type="box"/></film>
        </sensor>
        {}{}
        </scene>"#,
        rect(0.5, 1.0),
        rect(20.0, 100.0)
    );
    std::fs::write(&path, xml).unwrap();
    let loaded = load_scene(&path, &LoadOptions::default()).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let scene = loaded.scene;
    [Vec2::splat(16.0), Vec2::splat(0.5)].map(|film| {
        let ray = scene.camera.generate_ray(film, Vec2::splat(0.5));
        scene.camera_intersect(&ray, false).0.map(|si| si.p.z)
    })
}

fn near(z: Option<f32>) -> bool {
    z.is_some_and(|z| (z - 0.5).abs() < 1e-3)
}

fn far(z: Option<f32>) -> bool {
    z.is_some_and(|z| (z - 20.0).abs() < 1e-2)
}

#[test]
fn clip_planes_are_mitsubas() {
    let f = |name: &str, v: f32| format!(r#"<float name="{name}" value="{v}"/>"#);
    // Mitsuba's defaults (0.01 and 10⁴) clip nothing here.
    let [c, k] = seen("perspective", "");
    assert!(near(c) && near(k), "{c:?} {k:?}");
    // A near plane past the near rectangle: the far one shows, in the corner too.
    let [c, k] = seen("perspective", &f("near_clip", 0.55));
    assert!(far(c) && far(k), "near_clip 0.55: {c:?} {k:?}");
    let [c, k] = seen("perspective", &f("near_clip", 0.45));
    assert!(near(c) && near(k), "near_clip 0.45: {c:?} {k:?}");
    // A far plane past the far rectangle's depth keeps it, though the corner's ray meets it
    // farther away than 21; one before it leaves a miss.
    let both = |n: f32, fc: f32| format!("{}{}", f("near_clip", n), f("far_clip", fc));
    let [c, k] = seen("perspective", &both(0.6, 21.0));
    assert!(far(c) && far(k), "far_clip 21: {c:?} {k:?}");
    let [c, k] = seen("perspective", &both(0.6, 19.0));
    assert!(c.is_none() && k.is_none(), "far_clip 19: {c:?} {k:?}");
    // Mitsuba 0.6's spelling, the thin lens and the orthographic camera.
    let [c, _] = seen("perspective", r#"<float name="nearClip" value="0.6"/>"#);
    assert!(far(c), "nearClip: {c:?}");
    let lens =
        r#"<float name="aperture_radius" value="0.05"/><float name="focus_distance" value="5"/>"#;
    let [c, k] = seen("thinlens", &format!("{lens}{}", f("near_clip", 0.6)));
    assert!(far(c) && far(k), "thinlens: {c:?} {k:?}");
    let [c, k] = seen("orthographic", &f("near_clip", 0.6));
    assert!(far(c) && far(k), "orthographic near_clip: {c:?} {k:?}");
    let [c, _] = seen("orthographic", &both(0.6, 19.0));
    assert!(c.is_none(), "orthographic far_clip: {c:?}");
    // A perspective sensor's focus distance (which a pinhole does not use) passes quietly.
    let [c, _] = seen("perspective", &f("focus_distance", 3.0));
    assert!(near(c), "{c:?}");
}
