//! Temporal reuse across the frames of a moving sequence is unbiased: frame 1 of a sequence in
//! which the camera moves, a box moves (disocclusions), a sphere light moves, a one-sided light
//! turns over (facing away from the floor in frame 0, towards it in frame 1) and a light turns
//! on (it does not exist in frame 0's light list, so light indices differ between the frames),
//! rendered with the history of frame 0, averages to frame 1's path-traced reference block by
//! block within the standard error across seeds.
//!
//! * ReSTIR DI, with the power (default) and the balance heuristic as temporal MIS. The negative
//!   control evaluates the previous frame's targets with the current frame's scene
//!   (`temporal_current_scene`): the turned-over light then looks reachable from the previous
//!   frame's receivers, which never sampled it, and its light is underestimated.
//! * ReSTIR PT (`max_depth 3`; and `max_depth 4` with the hybrid shift through a near-specular
//!   box), on the sequence with a diffuse ball over the turning light, so the light paths bring
//!   back from beyond their reconnection vertex changes between the frames. Negative controls:
//!   shifting as if only the camera had moved (`temporal_ignore_motion`), keeping the suffix
//!   cached in the other frame (`temporal_stale_suffix`), the previous domain's target in the
//!   current scene (`temporal_current_scene`). The shift between the frames' domains is also
//!   checked on real paths: inverse, `J·J⁻¹ = 1`, round trip.

use std::sync::Arc;

use restir_gris::ShiftMap;
use restir_integrators::FrameMotion;
use restir_integrators::film::Filter;
use restir_integrators::path::PathSettings;
use restir_integrators::reuse::ReuseSettings;
use restir_integrators::reuse::gbuffer::GBuffer;
use restir_integrators::{
    Image, IntegratorOptions, Param, ParamSource, PassContext, RestirPtIntegrator,
    RestirPtSettings, make_integrator,
};
use restir_sampling::Pcg32;
use restir_scene::animation::build_at;
use restir_scene::{Scene, SceneDesc, parse_ron};

mod common;
use common::{block_statistics, max_z, render_image, render_with};

const SIZE: u32 = 32;
const BLOCK: u32 = 8;
/// 16 blocks, three comparisons that must pass: about 4 standard errors.
const Z_MAX: f64 = 4.0;

const T0: f32 = 0.0;
const T1: f32 = 1.0;

fn desc() -> SceneDesc {
    desc_with("Diffuse(reflectance: (0.3, 0.6, 0.3))", "")
}

/// The test sequence with the box's material `box_material` and the shapes `extra` added after
/// the others.
fn desc_with(box_material: &str, extra: &str) -> SceneDesc {
    let ron = format!(
        r#"(
        camera: (fov: 50, to_world: [LookAt(origin: (0, 5, 0.01), target: (0, 0, 0), up: (0, 0, -1))]),
        film: (width: {SIZE}, height: {SIZE}, filter: Box),
        integrator: (max_depth: 2),
        shapes: [
            (geometry: Rectangle, to_world: [Scale((3, 3, 1)), Rotate(axis: (1, 0, 0), angle: -90)],
             material: Some(Inline(Diffuse(reflectance: (0.6, 0.5, 0.4))))),
            (id: Some("box"), geometry: Cube, to_world: [Scale((0.4, 0.4, 0.4)), Translate((-0.6, 0.4, 0.2))],
             material: Some(Inline({box_material}))),
            (id: Some("flip"), geometry: Rectangle, to_world: [Scale((0.6, 0.6, 1)), Rotate(axis: (1, 0, 0), angle: -90),
             Translate((1.0, 1.2, -0.8))], emission: Some((4, 4, 4))),
            (id: Some("ball"), geometry: Sphere(center: (-1.2, 1.0, -1.0), radius: 0.1), emission: Some((60, 40, 30))),
            (id: Some("late"), geometry: Sphere(center: (0.8, 0.8, 1.2), radius: 0.12), emission: Some((0, 0, 0))),
            {extra}
        ],
        lights: [Constant(radiance: (0.05, 0.05, 0.08))],
        animation: Some((
            fps: 1,
            camera: Some((keys: [
                (time: 0, position: (0.3, 5, 0.3), target: (0.1, 0, 0.1), up: (0, 0, -1)),
                (time: 1, position: (0, 5, 0.01), target: (0, 0, 0), up: (0, 0, -1)),
            ])),
            shapes: [
                (id: "box", motion: Some([(time: 0, translate: (0.5, 0, 0.3)), (time: 1)])),
                (id: "flip", pivot: (1.0, 1.2, -0.8), motion: Some([(time: 0, rotate: (180, 0, 0)), (time: 1)])),
                (id: "ball", motion: Some([(time: 0, translate: (1.0, 0, 0.5)), (time: 1)])),
                (id: "late", emission: Some([(time: 0, radiance: (0, 0, 0)), (time: 1, radiance: (30, 30, 40))])),
            ],
        )),
    )"#
    );
    parse_ron(&ron, "motion-test.ron".as_ref()).unwrap()
}

fn frames() -> (SceneDesc, Arc<Scene>, common::Built) {
    frames_of(desc())
}

/// The same sequence with only the camera moving, and no environment (whose share of light
/// samples the scene build decides from what the camera sees, so it changes with the camera).
fn camera_only() -> (SceneDesc, Arc<Scene>, common::Built) {
    let mut d = desc();
    d.animation.as_mut().unwrap().shapes.clear();
    d.lights.clear();
    frames_of(d)
}

/// A diffuse ball hanging over the turning light: lit from below in frame 0, where the light
/// faces up, and by its back in frame 1, so the light that paths bring back from it (their
/// suffix beyond the ball) differs between the frames. [`pt_desc`] makes that light brighter.
const CAP: &str = r#"(geometry: Sphere(center: (1.0, 2.3, -0.8), radius: 0.5),
             material: Some(Inline(Diffuse(reflectance: (0.8, 0.8, 0.8))))),"#;

/// The moving sequence with [`CAP`] and the turning light ten times as bright, for ReSTIR PT.
fn pt_desc(box_material: &str) -> SceneDesc {
    let mut d = desc_with(box_material, CAP);
    let flip = d
        .shapes
        .iter_mut()
        .find(|s| s.id.as_deref() == Some("flip"))
        .unwrap();
    flip.emission = flip.emission.map(|e| e.map(|c| c * 10.0));
    d
}

fn pt_frames() -> (SceneDesc, Arc<Scene>, common::Built) {
    frames_of(pt_desc("Diffuse(reflectance: (0.3, 0.6, 0.3))"))
}

/// [`pt_frames`] with a near-specular box (a rough conductor with alpha 0.01, which paths
/// cannot reconnect at: the hybrid shift replays through it).
fn pt_glossy_frames() -> (SceneDesc, Arc<Scene>, common::Built) {
    frames_of(pt_desc("RoughConductor(roughness: (alpha: 0.01))"))
}

fn frames_of(desc: SceneDesc) -> (SceneDesc, Arc<Scene>, common::Built) {
    let path = std::path::Path::new("motion-test.ron");
    let s0 = Arc::new(build_at(&desc, path, T0).unwrap());
    let s1 = common::Built {
        scene: build_at(&desc, path, T1).unwrap(),
        integrator: desc.integrator.clone(),
    };
    (desc, s0, s1)
}

fn options(name: &str, max_depth: Option<i32>, params: &[(&str, &str)]) -> IntegratorOptions {
    IntegratorOptions {
        name: Some(name.into()),
        max_depth,
        params: params
            .iter()
            .map(|(k, v)| Param::new(*k, *v, ParamSource::Caller))
            .collect(),
        sampler: None,
    }
}

/// Frame 1 rendered with one pass after two passes of frame 0 (seed `seed`), the estimator
/// told of the motion in between.
fn frame_one(
    (desc, s0, s1): &(SceneDesc, Arc<Scene>, common::Built),
    (name, max_depth): (&str, Option<i32>),
    params: &[(&str, &str)],
    seed: u64,
) -> Image {
    let made = make_integrator(s0, &desc.integrator, &options(name, max_depth, params)).unwrap();
    assert!(made.unused_params.is_empty());
    let di = made.integrator;
    render_with(s0, di.as_ref(), 2, seed);
    let anim = desc.animation.as_ref().unwrap();
    di.next_frame(Arc::new(FrameMotion::new(s0.clone(), s1, anim, T0, T1)));
    render_with(s1, di.as_ref(), 1, seed ^ 0x5555)
}

fn statistics(
    frames: &(SceneDesc, Arc<Scene>, common::Built),
    params: &[(&str, &str)],
) -> Vec<(f64, f64)> {
    block_statistics(|s| frame_one(frames, DI, params, s), 200, 3000, BLOCK)
}

const DI: (&str, Option<i32>) = ("restir-di", None);
/// ReSTIR PT with paths of up to three segments (one bounce: reconnections).
const PT: (&str, Option<i32>) = ("restir-pt", Some(3));

fn pt_statistics(
    frames: &(SceneDesc, Arc<Scene>, common::Built),
    pt: (&str, Option<i32>),
    params: &[(&str, &str)],
) -> Vec<(f64, f64)> {
    block_statistics(|s| frame_one(frames, pt, params, s), 200, 5000, BLOCK)
}

/// Frame 1's path-traced reference: 48 renders of 256 passes.
fn pt_reference(
    frames: &(SceneDesc, Arc<Scene>, common::Built),
    max_depth: i32,
) -> Vec<(f64, f64)> {
    let depth = max_depth.to_string();
    block_statistics(
        |s| render_image(&frames.2, "path", &[("max_depth", &depth)], 256, s),
        48,
        1,
        BLOCK,
    )
}

/// ReSTIR PT across frames where only the camera moved: the previous frame's paths are reused
/// (the frame differs from one rendered without history) and the average matches the
/// reference.
#[test]
fn restir_pt_reuses_frames_where_only_the_camera_moved() {
    let still = camera_only();
    let motion = FrameMotion::new(
        still.1.clone(),
        &still.2,
        still.0.animation.as_ref().unwrap(),
        T0,
        T1,
    );
    assert!(motion.scene_is_still());
    let temporal = [("temporal", "true")];
    assert_ne!(
        frame_one(&still, PT, &temporal, 1).pixels,
        frame_one(&still, PT, &[("temporal", "false")], 1).pixels,
        "frame 1 should reuse frame 0"
    );
    let z = max_z(
        &pt_statistics(&still, PT, &temporal),
        &pt_reference(&still, 3),
    );
    eprintln!("restir-pt, camera moving: max |z| = {z:.2}");
    assert!(z < Z_MAX, "restir-pt, camera moving: max |z| = {z:.2}");
}

/// ReSTIR PT across frames in which shapes and lights moved: the previous frame's paths are
/// shifted into the current frame (`x_k` moved with its shape, a light vertex renamed through
/// the light correspondence, the suffix evaluated in the destination frame's scene, each
/// domain's target in its own frame), and the average matches the reference. Negative
/// controls: shifting as if only the camera had moved (`temporal_ignore_motion`), keeping the
/// suffix cached in the other frame (`temporal_stale_suffix`), and evaluating the previous
/// domain's target in the current scene (`temporal_current_scene`).
#[test]
fn restir_pt_temporal_reuse_across_moving_frames_is_unbiased() {
    let moving = pt_frames();
    let temporal = [("temporal", "true")];
    assert_ne!(
        frame_one(&moving, PT, &temporal, 1).pixels,
        frame_one(&moving, PT, &[("temporal", "false")], 1).pixels,
        "frame 1 should reuse frame 0"
    );
    let reference = pt_reference(&moving, 3);
    let z = max_z(&pt_statistics(&moving, PT, &temporal), &reference);
    eprintln!("restir-pt, scene moving: max |z| = {z:.2}");
    assert!(z < Z_MAX, "restir-pt, scene moving: max |z| = {z:.2}");
    for control in [
        "temporal_ignore_motion",
        "temporal_stale_suffix",
        "temporal_current_scene",
    ] {
        let params = [("temporal", "true"), (control, "true")];
        let z = max_z(&pt_statistics(&moving, PT, &params), &reference);
        eprintln!("restir-pt with {control}: max |z| = {z:.2}");
        assert!(
            z > 2.0 * Z_MAX,
            "{control} should be biased: max |z| = {z:.2}"
        );
    }
}

/// The same with longer paths (`max_depth 4`: suffixes of several segments replayed in the
/// destination frame) and a near-specular moving box (the hybrid shift's replayed prefixes,
/// walked in the previous frame's scene for the shifts into it).
#[test]
fn restir_pt_hybrid_across_moving_frames_is_unbiased() {
    let moving = pt_glossy_frames();
    let pt = ("restir-pt", Some(4));
    let reference = pt_reference(&moving, 4);
    let temporal = [("temporal", "true")];
    let z = max_z(&pt_statistics(&moving, pt, &temporal), &reference);
    eprintln!("restir-pt hybrid, max_depth 4, scene moving: max |z| = {z:.2}");
    assert!(
        z < Z_MAX,
        "restir-pt hybrid, scene moving: max |z| = {z:.2}"
    );
    let params = [("temporal", "true"), ("temporal_stale_suffix", "true")];
    let z = max_z(&pt_statistics(&moving, pt, &params), &reference);
    eprintln!("restir-pt hybrid with temporal_stale_suffix: max |z| = {z:.2}");
    assert!(
        z > 2.0 * Z_MAX,
        "stale suffixes should be biased: max |z| = {z:.2}"
    );
}

const TEMPORAL: &[(&str, &str)] = &[("temporal", "true"), ("candidates", "2")];

#[test]
fn temporal_reuse_across_moving_frames_is_unbiased() {
    let frames = frames();
    // The light that turns on is not in frame 0's light list.
    assert_eq!(frames.1.lights.len() + 1, frames.2.lights.len());
    let reference = block_statistics(
        |s| render_image(&frames.2, "path", &[], 256, s),
        48,
        1,
        BLOCK,
    );
    let z = max_z(&statistics(&frames, TEMPORAL), &reference);
    eprintln!("temporal across frames (power heuristic): max |z| = {z:.2}");
    assert!(z < Z_MAX, "temporal across frames: max |z| = {z:.2}");
    let balance = [TEMPORAL, &[("temporal_mis", "balance")]].concat();
    let z = max_z(&statistics(&frames, &balance), &reference);
    eprintln!("temporal across frames, balance heuristic: max |z| = {z:.2}");
    assert!(
        z < Z_MAX,
        "temporal across frames, balance heuristic: max |z| = {z:.2}"
    );
    // Spatial-only ReSTIR DI on the same frames, for comparison (no history is used).
    let z = max_z(&statistics(&frames, &[("candidates", "2")]), &reference);
    eprintln!("spatial only: max |z| = {z:.2}");
    assert!(z < Z_MAX, "spatial only: max |z| = {z:.2}");
    // Negative control: the previous frame's targets taken in the current frame's scene.
    let control = [TEMPORAL, &[("temporal_current_scene", "true")]].concat();
    let z = max_z(&statistics(&frames, &control), &reference);
    eprintln!("previous targets from the current scene: max |z| = {z:.2}");
    assert!(
        z > 2.0 * Z_MAX,
        "the current frame's targets for the previous frame should be biased: max |z| = {z:.2}"
    );
}

fn gbuffer(scene: &Scene, pass: u32) -> GBuffer {
    let filter = Filter::new(scene.filter);
    let ctx = PassContext {
        shared_offset: None,
        samples: None,
        seed: 7,
        pass,
        filter: &filter,
        crop: None,
    };
    let mut radiance = vec![glam::Vec3::ZERO; (SIZE * SIZE) as usize];
    GBuffer::trace(scene, &ctx, false, true, true, &mut radiance).0
}

/// Motion vectors: in a still frame every pixel finds itself (up to hits on another shape at
/// the jittered edges); across the moving frames most pixels find a previous pixel whose hit is
/// where the motion took theirs, and the pixels the box uncovered find none.
#[test]
fn motion_vectors_find_the_previous_hit() {
    let (desc, s0, s1) = frames();
    let settings = ReuseSettings::default();
    let still = FrameMotion::with_shape_motion(
        Arc::new(build_at(&desc, "motion-test.ron".as_ref(), T1).unwrap()),
        &s1,
        vec![glam::Mat4::IDENTITY; s1.shapes.len()],
    );
    let (now, before) = (gbuffer(&s1, 1), gbuffer(&s1, 0));
    let hits: Vec<usize> = (0..now.receivers.len())
        .filter(|&i| now.receiver(i).is_some())
        .collect();
    let same = hits
        .iter()
        .filter(|&&i| {
            now.previous_pixel_moved(i, &still, &before, &settings.similarity()) == Some(i)
        })
        .count();
    // Two passes' camera rays lie in different strata of their pixels (about half a pixel
    // apart), so a pixel on an edge between two shapes hits another one in the other pass.
    assert!(
        same * 100 >= hits.len() * 92,
        "{same} of {} pixels found themselves",
        hits.len()
    );

    let motion = FrameMotion::new(s0.clone(), &s1, desc.animation.as_ref().unwrap(), T0, T1);
    let prev = gbuffer(&s0, 0);
    let mut found = 0;
    let mut box_missed = 0;
    for &i in &hits {
        let r = now.receiver(i).unwrap();
        match now.previous_pixel_moved(i, &motion, &prev, &settings.similarity()) {
            Some(q) => {
                found += 1;
                let moved = motion.point_to_prev(now.shape[i], r.p);
                let d = (prev.receivers[q].p - moved).length();
                assert!(d < 0.3, "pixel {i}: previous hit {d} from the moved point");
                assert_eq!(prev.shape[q], now.shape[i]);
            }
            None if now.shape[i] == 0 => box_missed += 1,
            None => {}
        }
    }
    assert!(
        found * 100 >= hits.len() * 60,
        "{found} of {} pixels found",
        hits.len()
    );
    assert!(
        box_missed > 0,
        "the floor the box uncovered should be disoccluded"
    );
}

/// The shift between the two frames' domains on real paths (the initial reservoirs of 16
/// passes of frame 0 and of frame 1, `max_depth 4`, the near-specular box): whenever a shift from one frame to
/// the other succeeds, the shift of its result back succeeds too, `J·J⁻¹ = 1` and the round
/// trip returns the original contribution, for every kind of path.
#[test]
fn restir_pt_shift_across_frames_is_invertible() {
    let (desc, s0, s1) = pt_glossy_frames();
    let pt = RestirPtIntegrator::new(RestirPtSettings::new(PathSettings {
        max_depth: 4,
        rr_depth: 5,
        hide_emitters: false,
        sampler: restir_scene::SamplerKind::Independent,
        nee: restir_lights::NeeSelection::Power,
        nee_rule: restir_integrators::path::NeeRule::Named,
    }));
    let motion = FrameMotion::new(s0.clone(), &s1, desc.animation.as_ref().unwrap(), T0, T1);
    assert!(!motion.scene_is_still());
    let filter = Filter::new(s1.filter);
    let ctx = |pass| PassContext {
        shared_offset: None,
        samples: None,
        seed: 3,
        pass,
        filter: &filter,
        crop: None,
    };
    let mut checked = [0usize; 6];
    let (mut tried, mut forward, mut exact) = (0, 0, 0);
    for pass in 0..16 {
        let (prev, prev_res, _, _) = pt.initial_reservoirs(&s0, &ctx(2 * pass));
        let (now, now_res, _, _) = pt.initial_reservoirs(&s1, &ctx(2 * pass + 1));
        let shift = pt.frame_shift_map(&s1, &now, &prev, &motion);
        let n = now_res.len();
        let mut rng = Pcg32::new(5, u64::from(pass));
        // Samples of either frame, each shifted to random pixels of the other frame.
        for (from, res) in prev_res
            .iter()
            .enumerate()
            .map(|(q, r)| (n + q, r))
            .chain(now_res.iter().enumerate())
        {
            let Some(x) = res.sample else { continue };
            for _ in 0..6 {
                let to = (rng.next_u32() as usize) % n + if from < n { n } else { 0 };
                tried += 1;
                let Some(f) = shift.shift(&from, &to, &x) else {
                    continue;
                };
                forward += 1;
                let b = shift.shift(&to, &from, &f.sample).unwrap_or_else(|| {
                    panic!("{from}->{to}: forward succeeded, inverse failed ({x:?})")
                });
                let prod = f64::from(f.jacobian) * f64::from(b.jacobian);
                assert!(
                    (prod - 1.0).abs() < 1e-3,
                    "{from}->{to}: J·J⁻¹ = {prod} ({x:?})"
                );
                if f.destination_target > 0.0 && b.destination_target > 0.0 {
                    let err =
                        (b.sample.value - x.value).abs().max_element() / x.value.max_element();
                    assert!(
                        err < 1e-3,
                        "{from}->{to}: round trip {:?} vs {:?} ({x:?})",
                        b.sample.value,
                        x.value
                    );
                    checked[x.kind as usize] += 1;
                    exact += usize::from(b.sample.value == x.value);
                }
            }
        }
    }
    eprintln!(
        "across frames: {tried} shifts tried, {forward} succeeded, round trips with light both \
         ways by kind (DirectNee, DirectHit, NeeAtX2, HitAtX3, Continue, Frozen) {checked:?}, \
         bit-exact {exact}"
    );
    for (kind, &count) in checked.iter().enumerate() {
        assert!(
            count >= 10,
            "too few round trips of kind {kind}: {checked:?}"
        );
    }
}
