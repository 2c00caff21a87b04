//! The path tracer's passes run eight paths at a time in SIMD lanes; each lane must give the
//! estimate of the scalar walk (`trace_camera_path`) for its pixel, to the bit, and the same
//! ray count: on diffuse meshes (in lanes), on every other material, sphere lights and an
//! environment (the scalar walk's bounce there, then lanes again), with both samplers, hidden
//! emitters, short and unbounded depths, and films whose width is not a multiple of eight.

mod common;

use glam::{DVec3, Vec3};
use restir_integrators::film::Filter;
use restir_integrators::path::{NeeRule, PathIntegrator, PathSettings, trace_camera_path};
use restir_integrators::{Integrator, PassContext};
use restir_lights::NeeSelection;
use restir_scene::{SamplerKind, Scene};

/// The scalar walk's estimates for every pixel of one pass, and its ray count.
fn scalar_pass(scene: &Scene, settings: &PathSettings, ctx: &PassContext) -> (Vec<Vec3>, u64) {
    let (w, h) = ctx.resolution(scene);
    let settings = settings.resolved(&scene.features);
    let mut rays = 0;
    let image = (0..(w * h) as usize)
        .map(|index| {
            let (x, y) = ((index % w as usize) as u32, (index / w as usize) as u32);
            let (l, r) = match settings.sampler {
                SamplerKind::Independent => {
                    let mut rng = ctx.pixel_rng(index);
                    let film = ctx.pixel_film_position(index, (x, y), &mut rng);
                    trace_camera_path(scene, &settings, film, &mut rng)
                }
                SamplerKind::Sobol => {
                    let mut rng = ctx.pixel_sequence(index);
                    let film = ctx.film_position(x, y, &mut rng);
                    trace_camera_path(scene, &settings, film, &mut rng)
                }
            };
            rays += r;
            l
        })
        .collect();
    (image, rays)
}

/// Renders passes of `file` (in the repository's `scenes/`, at 37 × 21) with the lanes and with
/// the scalar walk and requires the same bits and ray counts; returns how many pixels were not
/// black.
fn check(file: &str, edit: impl Fn(&mut PathSettings)) -> usize {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(file);
    check_file(&path, edit)
}

fn check_file(path: &std::path::Path, edit: impl Fn(&mut PathSettings)) -> usize {
    let file = path.display();
    let (mut desc, _) = restir_scene::load_desc(path, &[]).unwrap();
    desc.film.width = 37;
    desc.film.height = 21;
    let scene = common::build(&desc, path.parent().unwrap(), path);
    let mut settings = PathSettings::from_desc(&scene.integrator);
    edit(&mut settings);
    let integrator = PathIntegrator { settings };
    let filter = Filter::new(scene.filter);
    let mut lit = 0;
    for pass in 0..3 {
        let ctx = PassContext {
            seed: 11,
            pass,
            filter: &filter,
            shared_offset: None,
            samples: None,
            crop: None,
        };
        let mut lanes = vec![DVec3::ZERO; 37 * 21];
        let lane_rays = integrator.render_pass(&scene, &ctx, &mut lanes);
        let (scalar, scalar_rays) = scalar_pass(&scene, &settings, &ctx);
        for (i, (a, b)) in lanes.iter().zip(&scalar).enumerate() {
            assert_eq!(
                a.as_vec3().to_array().map(f32::to_bits),
                b.to_array().map(f32::to_bits),
                "{file}, pass {pass}, pixel {i}: lanes {a} against the scalar walk's {b}"
            );
            lit += usize::from(*b != Vec3::ZERO);
        }
        assert_eq!(lane_rays, scalar_rays, "{file}, pass {pass}: rays traced");
    }
    lit
}

/// Diffuse meshes and a rectangle light: every path in lanes, both samplers, every depth
/// from emitters alone to unbounded, emitters hidden.
#[test]
fn lanes_give_the_scalar_walks_bits_on_diffuse_meshes() {
    for sampler in [SamplerKind::Independent, SamplerKind::Sobol] {
        for depth in [1, 2, 3, 6, -1] {
            let lit = check("cornell-box.xml", |s| {
                s.sampler = sampler;
                s.max_depth = depth;
            });
            // Depth 1 is the emitters alone, which this camera does not see.
            assert!(
                depth == 1 || lit > 37 * 21,
                "{sampler:?}, depth {depth}: {lit} lit"
            );
        }
    }
    check("cornell-box.xml", |s| s.hide_emitters = true);
    check("cornell-box.xml", |s| s.rr_depth = 1);
}

/// Rough conductors and rough plastics on meshes, in lanes: the Cornell box with its white
/// surfaces made GGX gold, GGX plastic or nonlinear Beckmann plastic (two sided), its red wall
/// anisotropic Beckmann copper (one sided) and its green wall near-mirror GGX aluminium (two
/// sided), the back wall turned away from the camera (its back seen, mirrored to the front),
/// both samplers.
#[test]
fn lanes_give_the_scalar_walks_bits_on_rough_conductors_and_plastics() {
    let conductor = |material: &str, distribution: &str, alphas: &str| {
        format!(r#"<bsdf type="roughconductor"><string name="material" value="{material}"/>"#)
            + &format!(r#"<string name="distribution" value="{distribution}"/>{alphas}</bsdf>"#)
    };
    let plastic = |distribution: &str, alpha: f32, nonlinear: bool| {
        format!(r#"<bsdf type="roughplastic"><string name="distribution" value="{distribution}"/>"#)
            + &format!(
                r#"<float name="alpha" value="{alpha}"/><boolean name="nonlinear" value="{nonlinear}"/>"#
            )
            + r#"<rgb name="diffuse_reflectance" value="0.6, 0.5, 0.3"/></bsdf>"#
    };
    let original = std::fs::read_to_string(
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml"),
    )
    .unwrap();
    let dir = restir_testkit::TempDir::new("path-lanes", "glossy");
    for (n, white) in [
        conductor("Au", "ggx", r#"<float name="alpha" value="0.3"/>"#),
        plastic("ggx", 0.1, false),
        plastic("beckmann", 0.2, true),
    ]
    .into_iter()
    .enumerate()
    {
        let mut xml = original.clone();
        for (id, old, new) in [
            (
                "white",
                r#"<rgb name="reflectance" value="0.725, 0.71, 0.68"/>"#,
                format!(r#"<bsdf type="twosided" id="white">{white}</bsdf>"#),
            ),
            (
                "red",
                r#"<rgb name="reflectance" value="0.63, 0.065, 0.05"/>"#,
                conductor(
                    "Cu",
                    "beckmann",
                    r#"<float name="alpha_u" value="0.05"/><float name="alpha_v" value="0.4"/>"#,
                )
                .replacen("<bsdf ", r#"<bsdf id="red" "#, 1),
            ),
            (
                "green",
                r#"<rgb name="reflectance" value="0.14, 0.45, 0.091"/>"#,
                format!(
                    r#"<bsdf type="twosided" id="green">{}</bsdf>"#,
                    conductor("Al", "ggx", r#"<float name="alpha" value="0.01"/>"#)
                ),
            ),
        ] {
            let diffuse =
                format!("<bsdf type=\"diffuse\" id=\"{id}\">\n        {old}\n    </bsdf>");
            assert!(xml.contains(&diffuse), "{id}");
            xml = xml.replace(&diffuse, &new);
        }
        let back = r#"<translate x="0" y="1" z="-1"/>
        </transform>"#;
        assert!(xml.contains(back));
        xml = xml.replace(
            back,
            &format!(r#"{back}<boolean name="flip_normals" value="true"/>"#),
        );
        let path = dir.join(format!("glossy-{n}.xml"));
        std::fs::write(&path, xml).unwrap();
        for sampler in [SamplerKind::Independent, SamplerKind::Sobol] {
            let lit = check_file(&path, |s| s.sampler = sampler);
            assert!(lit > 37 * 21 / 2, "{n}, {sampler:?}: {lit} lit");
        }
    }
}

/// Sphere lights picked by power: sampled in lanes.
#[test]
fn lanes_give_the_scalar_walks_bits_under_sphere_lights_picked_by_power() {
    for sampler in [SamplerKind::Independent, SamplerKind::Sobol] {
        let lit = check("many-lights.ron", |s| {
            s.sampler = sampler;
            s.nee = NeeSelection::Power;
            s.nee_rule = NeeRule::Named;
        });
        assert!(lit > 37 * 21, "{sampler:?}: {lit} lit");
    }
}

/// Surfaces the lanes do not bounce on: conductors, dielectrics, plastics, masks and spheres
/// (the scalar walk's bounce there, and the path back in lanes after it), textures, sphere
/// lights under the light hierarchy's selection, an environment map, a thin pane.
#[test]
fn lanes_give_the_scalar_walks_bits_where_paths_bounce_one_lane_at_a_time() {
    for file in [
        "cornell-materials.xml",
        "envmap-spheres.xml",
        "many-lights.ron",
        "thin-pane.xml",
        "textured/textured-shapes.xml",
        "glossy-still-life.xml",
    ] {
        let lit = check(file, |_| {});
        assert!(lit > 0, "{file}: black");
        check(file, |s| {
            s.sampler = SamplerKind::Sobol;
            s.hide_emitters = !s.hide_emitters;
        });
    }
}

restir_testkit::corpus_test! {
    /// Corpus Sponza: textured diffuse meshes (in lanes, each texture looked up at its hit) and
    /// a sphere light (its samples in lanes, the scalar walk's bounce where a path meets it).
    fn lanes_give_the_scalar_walks_bits_on_corpus_sponza() {
        let path = restir_testkit::corpus::corpus_dir().join("lajolla/sponza/sponza.xml");
        assert!(check_file(&path, |_| {}) > 37 * 21);
    }
}
