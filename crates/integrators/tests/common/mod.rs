//! Helpers shared by the integrators' statistical tests: render a scene with an estimator, and
//! the test kit's block statistics (per-block means of independent renders and their standard
//! errors) applied to [`Image`]s.
#![allow(dead_code)] // each test file uses a different subset

use std::sync::atomic::AtomicBool;

use restir_integrators::{
    Image, Integrator, IntegratorOptions, Param, ParamSource, RenderJob, make_integrator, render,
};
use restir_scene::{IntegratorDesc, LoadedScene, Scene, SceneDesc};

/// A built scene with the integrator settings of the description it was built from (what a
/// [`LoadedScene`] holds, for scenes the tests describe themselves). Dereferences to the scene.
pub struct Built {
    /// The scene.
    pub scene: Scene,
    /// Its description's integrator settings.
    pub integrator: IntegratorDesc,
}

impl std::ops::Deref for Built {
    type Target = Scene;
    fn deref(&self) -> &Scene {
        &self.scene
    }
}

impl std::ops::DerefMut for Built {
    fn deref_mut(&mut self) -> &mut Scene {
        &mut self.scene
    }
}

impl From<LoadedScene> for Built {
    fn from(loaded: LoadedScene) -> Self {
        Built {
            scene: loaded.scene,
            integrator: loaded.desc.integrator,
        }
    }
}

/// Builds `desc` (relative paths from `base`, errors naming `file`).
pub fn try_build(
    desc: &SceneDesc,
    base: &std::path::Path,
    file: &std::path::Path,
) -> Result<Built, restir_scene::SceneError> {
    Ok(Built {
        scene: Scene::build(desc, base, file)?,
        integrator: desc.integrator.clone(),
    })
}

/// [`try_build`], panicking on an error.
pub fn build(desc: &SceneDesc, base: &std::path::Path, file: &std::path::Path) -> Built {
    try_build(desc, base, file).unwrap_or_else(|e| panic!("{e}"))
}

/// The repository's Cornell box at `w × h`.
pub fn cornell(w: u32, h: u32) -> Built {
    let path =
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml");
    let (mut desc, _) = restir_scene::load_desc(&path, &[]).unwrap();
    desc.film.width = w;
    desc.film.height = h;
    build(&desc, path.parent().unwrap(), &path)
}

/// Renders `scene` with estimator `name`. `params` are the estimator's parameters, except
/// `max_depth`, which is taken as the command line's `--max-depth`. Every parameter must be used
/// and every pixel finite.
pub fn render_image(
    scene: &Built,
    name: &str,
    params: &[(&str, &str)],
    spp: u32,
    seed: u64,
) -> Image {
    render_with(scene, make(scene, name, params).as_ref(), spp, seed)
}

/// Estimator `name` for `scene` with `params` (`max_depth` as the command line's
/// `--max-depth`); every parameter must be used.
pub fn make(scene: &Built, name: &str, params: &[(&str, &str)]) -> Box<dyn Integrator> {
    let max_depth = params
        .iter()
        .find(|(k, _)| *k == "max_depth")
        .map(|(_, v)| v.parse().unwrap());
    let params: Vec<_> = params.iter().filter(|(k, _)| *k != "max_depth").collect();
    let options = IntegratorOptions {
        name: Some(name.into()),
        max_depth,
        params: params
            .iter()
            .map(|(k, v)| Param::new(*k, *v, ParamSource::Caller))
            .collect(),
        sampler: None,
    };
    let made = make_integrator(scene, &scene.integrator, &options).unwrap();
    assert!(made.unused_params.is_empty());
    made.integrator
}

/// Renders `spp` passes of `scene` with `integrator` (which keeps whatever history it has
/// between calls) and seed `seed`. Every pixel must be finite.
pub fn render_with(scene: &Scene, integrator: &dyn Integrator, spp: u32, seed: u64) -> Image {
    let settings = RenderJob {
        spp,
        seed,
        ..RenderJob::default()
    };
    let out = render(
        scene,
        integrator,
        &settings,
        &AtomicBool::new(false),
        &mut |_, _| {},
    );
    assert_eq!(
        out.nonfinite_pixels,
        0,
        "{}: non-finite pixels",
        integrator.describe()
    );
    out.image
}

/// Mean RGB-average of each `block`×`block` block of the image (row-major blocks).
pub fn block_means(img: &Image, block: u32) -> Vec<f64> {
    restir_testkit::block_means(img.width, img.height, &img.pixels, block)
}

/// Per block: mean and standard error of the mean over `seeds` independent renders with seeds
/// `seed_base`, `seed_base + 1`, … (the test kit's block statistics of [`block_means`]).
pub fn block_statistics(
    render_one: impl Fn(u64) -> Image,
    seeds: u64,
    seed_base: u64,
    block: u32,
) -> Vec<(f64, f64)> {
    restir_testkit::block_statistics(|s| block_means(&render_one(s), block), seeds, seed_base)
}

/// The per-pixel relative variance (of each channel, over `mean² + 0.01`), summed over the
/// image and its channels, across `seeds` renders with seeds `seed_base`, `seed_base + 1`, …:
/// a pixel's own noise, which block means average away, without the bright pixels outweighing
/// the rest.
pub fn pixel_relative_variance(
    render_one: impl Fn(u64) -> Image,
    seeds: u64,
    seed_base: u64,
) -> f64 {
    let renders: Vec<Image> = (0..seeds).map(|s| render_one(seed_base + s)).collect();
    let n = renders.len() as f64;
    let mut total = 0.0;
    for i in 0..renders[0].pixels.len() {
        for c in 0..3 {
            let v: Vec<f64> = renders.iter().map(|r| f64::from(r.pixels[i][c])).collect();
            let mean = v.iter().sum::<f64>() / n;
            let variance = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
            total += variance / (mean * mean + 0.01);
        }
    }
    total
}

/// The largest |z| over blocks between two sets of block statistics (the test kit's).
pub fn max_z(a: &[(f64, f64)], b: &[(f64, f64)]) -> f64 {
    restir_testkit::max_z(a, b)
}
