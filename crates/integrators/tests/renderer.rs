//! The one-line library API: `Renderer` gives the same image as the full `render` driver, and
//! its errors are typed. What is asked for is what runs: a named estimator renders as named,
//! `auto` chooses one from the scene, and the output says which ran and why.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use restir_integrators::{
    IntegratorError, IntegratorOptions, RenderError, RenderJob, Renderer, make_integrator, render,
};
use restir_scene::{LoadOptions, LoadedScene, load_scene};

fn cornell(size: u32) -> LoadedScene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml");
    let options = LoadOptions {
        width: Some(size),
        height: Some(size),
        ..LoadOptions::default()
    };
    load_scene(&path, &options).unwrap()
}

fn bits(pixels: &[restir_integrators::glam::Vec3]) -> Vec<[u32; 3]> {
    pixels
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect()
}

#[test]
fn one_line_render_matches_the_full_driver() {
    let loaded = cornell(16);
    let scene = &loaded.scene;
    let short = Renderer::new(&loaded).spp(3).seed(5).render().unwrap();
    let integrator = make_integrator(
        scene,
        &loaded.desc.integrator,
        &IntegratorOptions::default(),
    )
    .unwrap()
    .integrator;
    let job = RenderJob {
        spp: 3,
        seed: 5,
        ..RenderJob::default()
    };
    let full = render(
        scene,
        integrator.as_ref(),
        &job,
        &AtomicBool::new(false),
        &mut |_, _| {},
    );
    assert_eq!(short.passes, 3);
    assert_eq!((short.image.width, short.image.height), (16, 16));
    assert_eq!(bits(&short.image.pixels), bits(&full.image.pixels));
    assert!(short.image.mean().x > 0.0);
}

#[test]
fn named_integrator_and_parameters() {
    let loaded = cornell(8);
    let out = Renderer::new(&loaded)
        .spp(1)
        .integrator("restir-di")
        .param("spatial-rounds", 1u32)
        .render()
        .unwrap();
    assert_eq!(out.passes, 1);
    assert_eq!(out.nonfinite_pixels, 0);
}

#[test]
fn errors_are_typed() {
    let loaded = cornell(8);
    let unknown = Renderer::new(&loaded).integrator("restirdii").render();
    assert!(matches!(
        unknown,
        Err(RenderError::Integrator(IntegratorError::Unknown(ref name))) if name == "restirdii"
    ));
    let e = unknown.unwrap_err();
    assert_eq!(
        e.to_string(),
        "unknown integrator 'restirdii' (available: path, restir-di, restir-pt, auto)"
    );
    assert!(std::error::Error::source(&e).is_some());

    let unused = Renderer::new(&loaded)
        .integrator("path")
        .param("spatial-rounds", 2u32)
        .render()
        .unwrap_err();
    assert_eq!(
        unused,
        RenderError::UnusedParam {
            name: "spatial-rounds".into(),
            integrator: "path".into()
        }
    );
    assert_eq!(
        unused.to_string(),
        "parameter 'spatial-rounds' is not used by integrator path"
    );

    let bad = Renderer::new(&loaded).max_depth(-2).render();
    assert!(matches!(
        bad,
        Err(RenderError::Integrator(IntegratorError::MaxDepth(-2)))
    ));
}

fn many_lights(size: u32) -> LoadedScene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/many-lights.ron");
    let options = LoadOptions {
        width: Some(size),
        height: Some(size),
        ..LoadOptions::default()
    };
    load_scene(&path, &options).unwrap()
}

/// On the Cornell box (one light, two emitter-table entries, no glossy surface) `auto` renders
/// with the path tracer, bit for bit its image, and says so; `restir-di` asked for by name runs
/// ReSTIR DI (another image) and says that it was asked for.
#[test]
fn auto_picks_the_path_tracer_on_the_cornell_box_and_restir_di_runs_as_named() {
    let loaded = cornell(16);
    let run = |name: &str| {
        Renderer::new(&loaded)
            .spp(2)
            .seed(3)
            .integrator(name)
            .render()
            .unwrap()
    };
    let (auto, path, di) = (run("auto"), run("path"), run("restir-di"));

    assert_eq!(
        (auto.estimator.asked.as_str(), auto.estimator.ran.as_str()),
        ("auto", "path")
    );
    assert!(
        auto.estimator.settings.starts_with("path "),
        "{:?}",
        auto.estimator
    );
    assert!(
        auto.estimator.why.starts_with("chosen by auto: ")
            && auto
                .estimator
                .why
                .contains("one light takes 100% of the light selections"),
        "{:?}",
        auto.estimator
    );
    assert!(
        auto.estimator
            .to_string()
            .starts_with("ran path (chosen by auto: ")
    );
    assert_eq!(bits(&auto.image.pixels), bits(&path.image.pixels));

    assert_eq!(
        (
            di.estimator.asked.as_str(),
            di.estimator.ran.as_str(),
            di.estimator.why.as_str()
        ),
        ("restir-di", "restir-di", "asked for by name")
    );
    assert!(
        di.estimator.settings.starts_with("restir-di "),
        "{:?}",
        di.estimator
    );
    assert_ne!(bits(&di.image.pixels), bits(&path.image.pixels));
    assert_eq!(path.estimator.why, "asked for by name");

    // Emitters only: nothing for reservoirs to choose among.
    let emitters = Renderer::new(&loaded)
        .integrator("auto")
        .max_depth(1)
        .render()
        .unwrap();
    assert_eq!(emitters.estimator.ran, "path");
    assert!(
        emitters
            .estimator
            .why
            .contains("max_depth 1: no reflected light"),
        "{:?}",
        emitters.estimator
    );
}

/// On the many-lights scene (400 small lamps, none dominating, direct light only) `auto`
/// renders with ReSTIR DI, bit for bit its image, and says why.
#[test]
fn auto_picks_restir_di_on_many_lights() {
    let loaded = many_lights(16);
    let scene = &loaded.scene;
    let run = |name: &str| {
        Renderer::new(&loaded)
            .spp(1)
            .integrator(name)
            .render()
            .unwrap()
    };
    let (auto, di) = (run("auto"), run("restir-di"));
    assert_eq!(
        (auto.estimator.asked.as_str(), auto.estimator.ran.as_str()),
        ("auto", "restir-di")
    );
    assert!(
        auto.estimator
            .why
            .contains("no light dominates the selections"),
        "{:?}",
        auto.estimator
    );
    assert_eq!(auto.estimator.settings, di.estimator.settings);
    assert_eq!(bits(&auto.image.pixels), bits(&di.image.pixels));
    let made = make_integrator(
        scene,
        &loaded.desc.integrator,
        &IntegratorOptions {
            name: Some("auto".into()),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(made.integrator.name(), "restir-di");
    assert!(
        made.notes[0].starts_with("auto: restir-di renders it: "),
        "{:?}",
        made.notes
    );
}

/// The same scene with indirect light asked for (`max_depth` −1): no light dominates and the
/// paths are longer than two segments, so `auto` renders with ReSTIR PT, bit for bit its image,
/// and says why; with `max_depth` 2 it stays with ReSTIR DI (above).
#[test]
fn auto_picks_restir_pt_for_many_lights_with_indirect_light() {
    let loaded = many_lights(16);
    let run = |name: &str| {
        Renderer::new(&loaded)
            .spp(1)
            .max_depth(-1)
            .integrator(name)
            .render()
            .unwrap()
    };
    let (auto, pt) = (run("auto"), run("restir-pt"));
    assert_eq!(
        (auto.estimator.asked.as_str(), auto.estimator.ran.as_str()),
        ("auto", "restir-pt")
    );
    assert!(
        auto.estimator
            .why
            .contains("no light dominates the selections")
            && auto
                .estimator
                .why
                .contains("indirect light asked for (max_depth above 2)"),
        "{:?}",
        auto.estimator
    );
    assert_eq!(auto.estimator.settings, pt.estimator.settings);
    assert_eq!(bits(&auto.image.pixels), bits(&pt.image.pixels));
}

/// `fallback`, the parameter that let ReSTIR DI and PT hand a scene to the path tracer, is an
/// error naming what replaced it, from the caller and from a scene file (with its line); `auto`
/// takes no estimator parameters.
#[test]
fn the_removed_fallback_parameter_and_parameters_of_auto_are_errors() {
    let loaded = cornell(8);
    for name in ["restir-di", "restir-pt", "path"] {
        let e = Renderer::new(&loaded)
            .integrator(name)
            .param("fallback", "off")
            .render()
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "fallback = 'off': no such parameter any more: a named integrator runs as named; the \
             integrator auto chooses the path tracer where ReSTIR does not pay (integrators: \
             path, restir-di, restir-pt, auto)"
        );
    }
    let xml = r#"<scene version="3.0.0">
        <integrator type="restir">
            <string name="fallback" value="auto"/>
        </integrator>
        <sensor type="perspective"><float name="fov" value="40"/>
            <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
        </sensor>
        <shape type="rectangle"><bsdf type="diffuse"/></shape>
    </scene>"#;
    let (desc, _) = restir_scene::xml::parse_xml(xml, "old.xml".as_ref(), &[]).unwrap();
    let scene = restir_scene::Scene::build(&desc, ".".as_ref(), "old.xml".as_ref()).unwrap();
    let e = make_integrator(&scene, &desc.integrator, &IntegratorOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("old.xml:2: integrator: fallback = 'auto': no such parameter any more"),
        "{e}"
    );
    let e = Renderer::new(&loaded)
        .integrator("auto")
        .param("temporal", true)
        .render()
        .unwrap_err();
    assert!(
        e.to_string()
            .contains("the integrator auto takes no estimator parameters"),
        "{e}"
    );
}

/// A scene that asks for Mitsuba 3's particle tracer loads (its depth kept), but making its
/// integrator is an error naming the file, the line and the estimators that render the same
/// image; any of them asked for by name renders it with the scene's depth.
#[test]
fn mitsuba_particle_tracer_scenes_load_and_name_the_estimators_to_choose() {
    let xml = r#"<scene version="3.0.0">
        <integrator type="ptracer">
            <integer name="max_depth" value="4"/>
            <integer name="samples_per_pass" value="8"/>
        </integrator>
        <sensor type="perspective"><float name="fov" value="40"/>
            <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
        </sensor>
        <shape type="rectangle"><bsdf type="diffuse"/></shape>
    </scene>"#;
    let (desc, warnings) = restir_scene::xml::parse_xml(xml, "pt.xml".as_ref(), &[]).unwrap();
    assert_eq!(desc.integrator.kind, "ptracer");
    assert_eq!(desc.integrator.max_depth, 4);
    // What no estimator here reads is said, with its line.
    assert!(
        warnings
            .iter()
            .any(|w| w.to_string().contains("samples_per_pass")),
        "{warnings:?}"
    );
    let scene = restir_scene::Scene::build(&desc, ".".as_ref(), "pt.xml".as_ref()).unwrap();
    let e = make_integrator(&scene, &desc.integrator, &IntegratorOptions::default()).unwrap_err();
    assert!(matches!(e, IntegratorError::Unavailable { .. }), "{e:?}");
    assert_eq!(
        e.to_string(),
        "pt.xml:2: the scene's integrator 'ptracer' is Mitsuba 3's particle tracer, which this \
         renderer does not have; every estimator here renders the same image: choose one with \
         --integrator (path, restir-di, restir-pt, auto)"
    );
    for name in ["path", "restir-di", "restir-pt"] {
        let options = IntegratorOptions {
            name: Some(name.into()),
            ..Default::default()
        };
        let made = make_integrator(&scene, &desc.integrator, &options).unwrap();
        assert!(
            made.integrator.describe().contains("max_depth=4"),
            "{}",
            made.integrator.describe()
        );
    }
}
