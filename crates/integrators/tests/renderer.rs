//! The one-line library API: `Renderer` gives the same image as the full `render` driver, and
//! its errors are typed.

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
    let short = Renderer::new(scene).spp(3).seed(5).render().unwrap();
    let integrator = make_integrator(scene, &IntegratorOptions::default())
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
    let out = Renderer::for_loaded(&loaded)
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
    let unknown = Renderer::new(&loaded.scene)
        .integrator("restirdii")
        .render();
    assert!(matches!(
        unknown,
        Err(RenderError::Integrator(IntegratorError::Unknown(ref name))) if name == "restirdii"
    ));
    let e = unknown.unwrap_err();
    assert_eq!(
        e.to_string(),
        "unknown integrator 'restirdii' (available: path, restir-di, restir-pt)"
    );
    assert!(std::error::Error::source(&e).is_some());

    let unused = Renderer::new(&loaded.scene)
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

    let bad = Renderer::new(&loaded.scene).max_depth(-2).render();
    assert!(matches!(
        bad,
        Err(RenderError::Integrator(IntegratorError::MaxDepth(-2)))
    ));
}
