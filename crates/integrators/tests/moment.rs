//! Each pixel's second moment (Mitsuba 3's `moment` integrator, [`RenderJob::moment`]): the mean
//! over the passes of each pass's estimate squared, in CIE XYZ. Checked exactly against the
//! passes rendered one at a time ([`render_part`] renders the same `(seed, pixel, pass)`
//! streams), for the path tracer and for ReSTIR DI and PT (spatial reuse, no history between
//! passes); asking for it leaves the image as it was. Negative control: the square of the mean
//! (what a film that squared the average instead of each pass would give) differs.

mod common;

use std::sync::atomic::AtomicBool;

use glam::DVec3;
use restir_image::srgb;
use restir_integrators::{Integrator, RenderJob, RenderOutput, RenderPart, render_part};
use restir_scene::Scene;

use common::cornell;

fn integrator(scene: &common::Built, name: &str) -> Box<dyn Integrator> {
    // ReSTIR DI without learning across passes: with it a pass depends on the passes before,
    // and the passes rendered one at a time below would each start with nothing learned.
    let reuse: &[(&str, &str)] = match name {
        "path" => &[],
        "restir-di" => &[("radius", "4"), ("spatial_rounds", "2"), ("learn", "off")],
        _ => &[("radius", "4"), ("spatial_rounds", "2")],
    };
    common::make(scene, name, &[&[("max_depth", "3")], reuse].concat())
}

fn run(
    scene: &Scene,
    integrator: &dyn Integrator,
    passes: std::ops::Range<u32>,
    moment: bool,
) -> RenderOutput {
    let job = RenderJob {
        spp: passes.len() as u32,
        seed: 7,
        moment: moment.then(|| "nested".to_string()),
        ..RenderJob::default()
    };
    let part = RenderPart {
        first_pass: passes.start,
        window: None,
    };
    render_part(
        scene,
        integrator,
        &job,
        &part,
        &AtomicBool::new(false),
        &mut |_, _| {},
    )
}

#[test]
fn the_second_moment_is_the_mean_of_each_pass_squared() {
    let scene = cornell(24, 18);
    const N: u32 = 6;
    for name in ["path", "restir-di", "restir-pt"] {
        let est = integrator(&scene, name);
        let with = run(&scene, est.as_ref(), 0..N, true);
        let without = run(&scene, est.as_ref(), 0..N, false);
        assert_eq!(with.image, without.image, "{name}: the image changed");
        assert!(without.moment.is_none());
        let m = with.moment.expect("moments were asked for");
        assert_eq!(m.name, "nested");

        // The passes one at a time: Σ xyz(pass)² / N and Σ xyz(pass) / N.
        let n = with.image.pixels.len();
        let (mut sum, mut squares) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        for k in 0..N {
            let one = run(&scene, est.as_ref(), k..k + 1, false);
            for (i, p) in one.image.pixels.iter().enumerate() {
                let xyz = srgb::to_xyz(p.as_dvec3());
                sum[i] += xyz;
                squares[i] += xyz * xyz;
            }
        }
        let mut worst = 0.0f64;
        let mut control = 0.0f64;
        for i in 0..n {
            let (mean, second) = (sum[i] / N as f64, squares[i] / N as f64);
            let scale = second.max_element().max(1e-6);
            worst = worst.max((m.second[i] - second).abs().max_element() / scale);
            worst = worst.max((m.mean[i] - mean).abs().max_element() / scale.sqrt());
            control = control.max((m.second[i] - mean * mean).abs().max_element() / scale);
        }
        // Single passes are stored in f32, the film sums in f64.
        assert!(worst < 1e-5, "{name}: relative difference {worst}");
        assert!(
            control > 1e-2,
            "{name}: the control does not differ ({control})"
        );

        // Mitsuba's channel names and order of values.
        let channels = m.channels();
        let names: Vec<_> = channels.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "nested.X",
                "nested.Y",
                "nested.Z",
                "m2_nested.X",
                "m2_nested.Y",
                "m2_nested.Z"
            ]
        );
        assert_eq!(channels[4].values[5], m.second[5].y as f32);
    }
}
