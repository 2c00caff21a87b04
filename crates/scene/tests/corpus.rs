//! Loads every scene of the shared corpus (`../shared/corpus` beside the workspace): the ones the
//! importer supports must load, the others must fail with a clear `file:line` message. When the
//! corpus was absent at build time the tests are ignored (`restir_testkit::corpus_test!`); under
//! CI (`CI` set) they run and fail without it.

use std::path::{Path, PathBuf};

use restir_scene::texture::{FilterType, Texture, TextureDesc, UvTransform, WrapMode};
use restir_scene::{LoadOptions, LoadedScene, load_scene};

fn load(dir: &Path, rel: &str) -> LoadedScene {
    let path = dir.join(rel);
    load_scene(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{rel} should load: {e}"))
}

restir_testkit::corpus_test! {
fn supported_corpus_scenes_load() {
    let dir = restir_testkit::corpus_dir();

    // Cornell box: OBJ meshes, measured reflectance spectra, a spectral area light.
    let cbox = load(&dir, "lajolla/cbox/cbox.xml");
    assert_eq!(cbox.scene.lights.len(), 1);
    let light = cbox
        .desc
        .shapes
        .iter()
        .find_map(|s| s.emission)
        .expect("cbox has an area light");
    // "400:0, 500:8, 600:15.6, 700:18.4" without D65: warm, all channels positive.
    assert!(
        light[0] > light[1] && light[1] > light[2] && light[2] > 0.0,
        "{light:?}"
    );

    // Veach's MIS plates: sphere lights, rough plastic.
    let mi = load(&dir, "lajolla/veach_mi/mi.xml");
    assert!(mi.scene.lights.len() >= 4);

    // Material preview: a `.serialized` mesh, an envmap and a checkerboard-textured floor.
    let mp = load(&dir, "lajolla/matpreview/matpreview.xml");
    assert!(mp.scene.features.has_environment && mp.scene.lights.envmap().is_some());
    assert!(mp.scene.features.has_textures);

    // ReSTIR test scene: PLY meshes, spectra, 100+ emissive spheres, unknown parameters.
    let t = load(&dir, "restir_test_scene/test.xml");
    assert!(t.scene.lights.len() >= 100, "{}", t.scene.lights.len());
    assert!(t.desc.shapes.iter().any(|s| matches!(
        &s.geometry,
        restir_scene::GeometryDesc::Ply { filename } if filename.contains("bunny")
    )));
}
}

restir_testkit::corpus_test! {
/// The textured scenes load, and their materials vary over the surface as their textures do.
fn textured_corpus_scenes_load() {
    let dir = restir_testkit::corpus_dir();
    let centre_hit = |scene: &restir_scene::Scene| {
        let (w, h) = scene.camera.resolution();
        let film = glam::Vec2::new(w as f32 / 2.0, h as f32 * 0.9);
        let ray = scene.camera.generate_ray(film, glam::Vec2::splat(0.5));
        scene.intersect(&ray).expect("the camera sees the floor")
    };
    let reflectance = |b: restir_materials::Bsdf| match b.kind {
        restir_materials::BsdfKind::Diffuse { reflectance } => reflectance,
        k => panic!("expected a diffuse floor, got {k:?}"),
    };

    // Checkerboard reflectance (1000 × 1000 checks of 1 and 0) on an OBJ floor.
    let pft = load(&dir, "lajolla/pixel_filter_test/pixel_filter_test.xml").scene;
    assert!(pft.features.has_textures);
    assert_eq!(pft.textures().len(), 1);
    let mut si = centre_hit(&pft);
    let mut seen = [false; 2];
    for k in 0..64 {
        si.uv = glam::Vec2::new(0.37 + k as f32 * 0.0005, 0.61);
        let r = reflectance(pft.bsdf(&si));
        assert!(r == glam::Vec3::ONE || r == glam::Vec3::ZERO, "{r}");
        seen[(r.x > 0.5) as usize] = true;
    }
    assert_eq!(seen, [true, true], "both checker colours along a row");

    // Sponza: JPEG textures on `.serialized` meshes with texture coordinates.
    let sponza = load(&dir, "lajolla/sponza/sponza.xml").scene;
    assert!(sponza.features.has_textures);
    assert_eq!(
        sponza.textures().len(),
        10,
        "each distinct bitmap decoded once"
    );
    let mut si = centre_hit(&sponza);
    let r0 = reflectance(sponza.bsdf(&si));
    si.uv += glam::Vec2::new(0.25, 0.25);
    let r1 = reflectance(sponza.bsdf(&si));
    assert!(r0 != r1 && r0.max_element() <= 1.0, "{r0} {r1}");
}
}

/// A scene around one shape, written into the test's temporary directory `dir`.
fn shape_scene(dir: &Path, name: &str, shape: &str) -> PathBuf {
    let path = dir.join(name);
    let xml = format!(
        r#"<scene version="0.6.0">
    <sensor type="perspective"><float name="fov" value="40"/>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film>
    </sensor>
{shape}
</scene>
"#
    );
    std::fs::write(&path, xml).unwrap();
    path
}

restir_testkit::corpus_test! {
fn serialized_meshes_of_the_corpus() {
    let dir = restir_testkit::corpus_dir();
    let mp = dir.join("lajolla/matpreview/matpreview.serialized");
    let sp = dir.join("lajolla/sponza/sponza.serialized");
    let tmp = restir_testkit::TempDir::new("corpus", "serialized");
    let mut shapes = String::new();
    for i in 0..3 {
        shapes += &format!(
            "<shape type=\"serialized\"><string name=\"filename\" value=\"{}\"/><integer name=\"shapeIndex\" value=\"{i}\"/><boolean name=\"faceNormals\" value=\"true\"/></shape>\n",
            mp.display()
        );
    }
    shapes += &format!(
        "<shape type=\"serialized\"><string name=\"filename\" value=\"{}\"/><integer name=\"shape_index\" value=\"5\"/><boolean name=\"flip_normals\" value=\"true\"/></shape>\n",
        sp.display()
    );
    let path = shape_scene(&tmp, "serialized.xml", &shapes);
    let s = load_scene(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.scene.shapes.len(), 4);

    // An index past the file's shapes: an error at the shape's line.
    let bad = format!(
        "<shape type=\"serialized\">\n<string name=\"filename\" value=\"{}\"/><integer name=\"shape_index\" value=\"99\"/></shape>",
        mp.display()
    );
    let e = load_scene(&shape_scene(&tmp, "bad-index.xml", &bad), &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("bad-index.xml:5:") && e.contains("shape_index 99 is out of range"),
        "{e}"
    );
    // A missing file.
    let e = load_scene(
        &shape_scene(
            &tmp,
            "missing.xml",
            "<shape type=\"ply\"><string name=\"filename\" value=\"nope.ply\"/></shape>",
        ),
        &LoadOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("missing.xml:5:") && e.contains("nope.ply"),
        "{e}"
    );
}
}

restir_testkit::corpus_test! {
fn corpus_exr_and_jpeg_decode() {
    let dir = restir_testkit::corpus_dir();
    let desc = TextureDesc::Bitmap {
        filename: "envmap.exr".into(),
        raw: false,
        uv: UvTransform::default(),
        wrap: WrapMode::default(),
        filter: FilterType::default(),
    };
    let t = Texture::load(&desc, &dir.join("lajolla/matpreview")).unwrap();
    let m = t.mean();
    assert!(m.is_finite() && m.min_element() > 0.0, "{m:?}");

    let jpeg = TextureDesc::Bitmap {
        filename: "textures/KAMEN.JPG".into(),
        raw: false,
        uv: UvTransform::default(),
        wrap: WrapMode::default(),
        filter: FilterType::default(),
    };
    let t = Texture::load(&jpeg, &dir.join("lajolla/sponza")).unwrap();
    let m = t.mean();
    assert!(m.max_element() <= 1.0 && m.min_element() > 0.0, "{m:?}");
}
}
