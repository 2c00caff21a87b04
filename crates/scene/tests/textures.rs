//! Textured material parameters in both scene formats: XML nested `<texture>` and `<ref>`, RON
//! `Textured(..)`, what [`Scene::bsdf_at`] returns at a hit, texture coordinates of the shapes
//! (Mitsuba's conventions), and errors with `file:line`.

use std::path::{Path, PathBuf};

use glam::Vec3;
use restir_geometry::Ray;
use restir_materials::BsdfKind;
use restir_scene::{
    ColorParam, LoadOptions, MaterialDesc, Scene, TextureDesc, load_scene, parse_ron,
    xml::parse_xml,
};
use restir_testkit::TempDir;

/// A fresh directory with a 2×2 raw PNG: row 0 (top) red, green; row 1 blue, white; removed
/// when dropped.
fn dir_with_png(tag: &str) -> TempDir {
    let dir = TempDir::new("textures", tag);
    image::RgbImage::from_raw(2, 2, vec![255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255])
        .unwrap()
        .save(dir.join("quad.png"))
        .unwrap();
    dir
}

fn write_scene(dir: &Path, name: &str, body: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!(
            r#"<scene version="3.0.0">
    <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
{body}
</scene>"#
        ),
    )
    .unwrap();
    path
}

fn diffuse_reflectance(kind: BsdfKind) -> Vec3 {
    match kind {
        BsdfKind::Diffuse { reflectance } => reflectance,
        k => panic!("expected diffuse, got {k:?}"),
    }
}

/// The material seen straight down `-z` at `(x, y)` (shapes in the `z ≤ 0` half-space).
fn seen_at(scene: &Scene, x: f32, y: f32) -> BsdfKind {
    let ray = Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z);
    let si = scene.intersect(&ray).expect("hit");
    scene.bsdf(&si).kind
}

#[test]
fn xml_nested_and_referenced_textures() {
    let dir = dir_with_png("xml");
    let path = write_scene(
        &dir,
        "s.xml",
        r#"    <texture type="bitmap" id="quad"><string name="filename" value="quad.png"/><boolean name="raw" value="true"/></texture>
    <bsdf type="diffuse" id="by_ref"><ref name="reflectance" id="quad"/></bsdf>
    <bsdf type="twosided" id="nested"><bsdf type="roughplastic">
        <texture type="checkerboard" name="diffuseReflectance"><rgb name="color0" value="1"/><rgb name="color1" value="0"/></texture>
        <rgb name="specular_reflectance" value="0.5"/>
    </bsdf></bsdf>
    <shape type="rectangle"><ref id="by_ref"/></shape>
    <shape type="rectangle"><transform name="to_world"><translate x="3"/></transform><ref id="nested"/></shape>"#,
    );
    let loaded = load_scene(&path, &LoadOptions::default()).unwrap();
    let scene = &loaded.scene;
    assert!(scene.features.has_textures);
    assert_eq!(scene.textures().len(), 2);
    // Mitsuba's rectangle: uv = ((x + 1)/2, (y + 1)/2); uv (0.25, 0.25) is the top-left texel.
    assert_eq!(diffuse_reflectance(seen_at(scene, -0.5, -0.5)), Vec3::X);
    assert_eq!(diffuse_reflectance(seen_at(scene, 0.5, -0.5)), Vec3::Y);
    assert_eq!(diffuse_reflectance(seen_at(scene, -0.5, 0.5)), Vec3::Z);
    // The rough plastic's diffuse base follows the checkerboard; its specular stays 0.5.
    let plastic = |x, y| match seen_at(scene, x, y) {
        BsdfKind::RoughPlastic(p) => p,
        k => panic!("{k:?}"),
    };
    let (white, black) = (plastic(3.0 - 0.5, -0.5), plastic(3.0 + 0.5, -0.5));
    assert!(white.diffuse_scaled.x > 0.1 && black.diffuse_scaled == Vec3::ZERO);
    assert_eq!(white.specular_reflectance, Vec3::splat(0.5));
    assert!(white.specular_weight < black.specular_weight);
    assert!(
        std::ptr::eq(white.table, black.table),
        "one coating table, not one per hit"
    );
    match &loaded.desc.materials[1].material {
        MaterialDesc::TwoSided(inner) => match &**inner {
            MaterialDesc::Textured { textures, .. } => {
                assert_eq!(textures[0].param, ColorParam::DiffuseReflectance);
                assert!(matches!(
                    textures[0].texture,
                    TextureDesc::Checkerboard { .. }
                ));
            }
            m => panic!("{m:?}"),
        },
        m => panic!("{m:?}"),
    }
}

#[test]
fn untextured_scenes_take_the_constant_path() {
    let dir = dir_with_png("plain");
    // A texture declared but used by no shape does not make the scene textured.
    let path = write_scene(
        &dir,
        "s.xml",
        r#"    <texture type="bitmap" id="quad"><string name="filename" value="quad.png"/></texture>
    <bsdf type="diffuse" id="unused"><ref name="reflectance" id="quad"/></bsdf>
    <shape type="rectangle"><bsdf type="diffuse"><rgb name="reflectance" value="0.25"/></bsdf></shape>"#,
    );
    let scene = load_scene(&path, &LoadOptions::default()).unwrap().scene;
    assert!(!scene.features.has_textures);
    assert_eq!(
        diffuse_reflectance(seen_at(&scene, 0.3, 0.2)),
        Vec3::splat(0.25)
    );
}

#[test]
fn obj_texture_coordinates_count_v_from_the_bottom() {
    let dir = dir_with_png("obj");
    std::fs::write(
        dir.join("q.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    let path = write_scene(
        &dir,
        "s.xml",
        r#"    <shape type="obj"><string name="filename" value="q.obj"/>
        <bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="quad.png"/><boolean name="raw" value="true"/></texture></bsdf>
    </shape>"#,
    );
    let scene = load_scene(&path, &LoadOptions::default()).unwrap().scene;
    // Mitsuba 3 reads this OBJ's (vt 0 0) corner as uv (0, 1): the image's bottom-left texel.
    assert_eq!(diffuse_reflectance(seen_at(&scene, -0.5, -0.5)), Vec3::Z);
    assert_eq!(diffuse_reflectance(seen_at(&scene, -0.5, 0.5)), Vec3::X);
}

#[test]
fn ron_textured_materials() {
    let dir = dir_with_png("ron");
    let ron = r#"(
        camera: (fov: 40),
        film: (width: 4, height: 4),
        materials: [
            (name: "floor", material: Textured(
                material: Diffuse(reflectance: (0.5, 0.5, 0.5)),
                textures: [(param: Reflectance, texture: Bitmap(filename: "quad.png", raw: true))])),
        ],
        shapes: [
            (geometry: Rectangle, material: Some(Ref("floor"))),
            (geometry: Rectangle, to_world: [Translate((3, 0, 0))], material: Some(Inline(Textured(
                material: Conductor(),
                textures: [(param: SpecularReflectance, texture: Checkerboard(uv: (scale: (2, 2))))])))),
        ],
    )"#;
    let desc = parse_ron(ron, "t.ron".as_ref()).unwrap();
    let scene = Scene::build(&desc, &dir, "t.ron".as_ref()).unwrap();
    assert!(scene.features.has_textures && scene.features.has_delta_lobes);
    assert_eq!(diffuse_reflectance(seen_at(&scene, 0.5, -0.5)), Vec3::Y);
    match seen_at(&scene, 3.0 - 0.9, -0.9) {
        BsdfKind::Conductor {
            specular_reflectance,
            ..
        } => assert_eq!(specular_reflectance, Vec3::splat(0.4), "Mitsuba's color0"),
        k => panic!("{k:?}"),
    }
    // Swapping the textured materials for constant ones drops their textures and the flag
    // with them (the summary follows the edit; a constant material then reads no texture).
    let mut scene = scene;
    for shape in 0..2 {
        let m = scene.shape_bsdf()[shape];
        let constant = scene.bsdfs()[m as usize];
        scene.set_material(m, constant).unwrap();
        assert_eq!(scene.features.has_textures, shape == 0, "shape {shape}");
    }
    assert!(scene.features.has_delta_lobes);
    assert_eq!(
        diffuse_reflectance(seen_at(&scene, 0.5, -0.5)),
        Vec3::splat(0.5)
    );
    // Strict: unknown fields, and parameters the material does not have, are errors.
    let typo = ron.replace("raw: true", "raw: true, filter: 1");
    assert!(parse_ron(&typo, "t.ron".as_ref()).is_err());
    let wrong = ron.replace("param: SpecularReflectance", "param: Reflectance");
    let desc = parse_ron(&wrong, "t.ron".as_ref()).unwrap();
    let e = Scene::build(&desc, &dir, "t.ron".as_ref())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("texture for 'reflectance': this material has no such parameter"),
        "{e}"
    );
    let missing = ron.replace("quad.png", "nope.png");
    let desc = parse_ron(&missing, "t.ron".as_ref()).unwrap();
    let e = Scene::build(&desc, &dir, "t.ron".as_ref())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("material 'floor'") && e.contains("nope.png"),
        "{e}"
    );
}

#[test]
fn xml_texture_errors_name_file_and_line() {
    let dir = dir_with_png("err");
    let cases = [
        (
            r#"<bsdf type="diffuse" id="m">
<texture type="bitmap" name="reflectance"><string name="filename" value="missing.png"/></texture></bsdf>"#,
            "s.xml:4: bitmap texture: file",
        ),
        (
            r#"<bsdf type="roughconductor" id="m">
<texture type="checkerboard" name="eta"/></bsdf>"#,
            "s.xml:4: bsdf 'roughconductor': 'eta' cannot be a texture",
        ),
        (
            r#"<bsdf type="diffuse" id="m">
<texture type="checkerboard" name="specular_reflectance"/></bsdf>"#,
            "s.xml:4: bsdf 'diffuse' has no parameter 'specular_reflectance'",
        ),
        (
            r#"<bsdf type="diffuse" id="m"><rgb name="reflectance" value="0.5"/>
<texture type="checkerboard" name="reflectance"/></bsdf>"#,
            "s.xml:4: bsdf 'diffuse': 'reflectance' is given twice",
        ),
        (
            r#"<bsdf type="diffuse" id="m">
<ref name="reflectance" id="nowhere"/></bsdf>"#,
            "s.xml:4: bsdf 'diffuse': reference to undefined texture 'nowhere'",
        ),
        (
            r#"<bsdf type="diffuse" id="m">
<texture type="checkerboard" name="reflectance"><rgb name="color0" value="2"/></texture></bsdf>"#,
            "s.xml:3: bsdf 'diffuse': texture for 'reflectance': colour [2.0, 2.0, 2.0] must lie in [0, 1]",
        ),
    ];
    for (body, want) in cases {
        let path = write_scene(&dir, "s.xml", body);
        let text = std::fs::read_to_string(&path).unwrap();
        let e = match parse_xml(&text, &path, &[]) {
            Ok(_) => panic!("{body}: accepted"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains(want), "got \"{e}\", want \"{want}\"");
    }
}

/// Texture coordinates reach the material on every built-in shape: a sphere's are Mitsuba's
/// `(φ/2π, θ/π)`.
#[test]
fn sphere_texture_coordinates() {
    let ron = r#"(
        camera: (fov: 40),
        film: (width: 4, height: 4),
        shapes: [(geometry: Sphere(center: (0, 0, 0), radius: 1), material: Some(Inline(Textured(
            material: Diffuse(reflectance: (0.5, 0.5, 0.5)),
            textures: [(param: Reflectance, texture: Checkerboard(color0: (1, 1, 1), color1: (0, 0, 0)))]))))],
    )"#;
    let desc = parse_ron(ron, "t.ron".as_ref()).unwrap();
    let scene = Scene::build(&desc, ".".as_ref(), "t.ron".as_ref()).unwrap();
    // Seen from +x at height z = 0.4 (θ/π ≈ 0.37 < ½): φ/2π just above 0 → color0; from −y,
    // φ/2π = ¾ → color1.
    let at = |o: Vec3| {
        let si = scene.intersect(&Ray::new(o, -o.normalize())).unwrap();
        assert!(
            (si.uv - restir_geometry::Sphere::uv_of(si.p))
                .abs()
                .max_element()
                < 1e-4
        );
        diffuse_reflectance(scene.bsdf(&si).kind)
    };
    assert_eq!(at(Vec3::new(3.0, 0.3, 1.2)), Vec3::ONE);
    assert_eq!(at(Vec3::new(0.3, -3.0, 1.2)), Vec3::ZERO);
}

/// A `mask` with a textured opacity around a twosided textured diffuse: both textures reach the
/// BSDF at a hit (the opacity is the texel's luminance), and a constant opacity stays put.
#[test]
fn textured_mask_opacity() {
    let dir = dir_with_png("mask");
    let path = write_scene(
        &dir,
        "s.xml",
        r#"    <texture type="bitmap" id="quad"><string name="filename" value="quad.png"/><boolean name="raw" value="true"/></texture>
    <bsdf type="mask" id="leaf">
        <ref name="opacity" id="quad"/>
        <bsdf type="twosided"><bsdf type="diffuse"><ref name="reflectance" id="quad"/></bsdf></bsdf>
    </bsdf>
    <bsdf type="mask" id="half"><bsdf type="diffuse"/></bsdf>
    <shape type="rectangle"><ref id="leaf"/></shape>
    <shape type="rectangle"><transform name="to_world"><translate x="3"/></transform><ref id="half"/></shape>"#,
    );
    let loaded = load_scene(&path, &LoadOptions::default()).unwrap();
    let scene = &loaded.scene;
    let at = |x: f32, y: f32| {
        let si = scene
            .intersect(&Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z))
            .expect("hit");
        scene.bsdf(&si)
    };
    // Top-left texel red, top-right green, bottom-right white.
    let red = at(-0.5, -0.5);
    assert_eq!(diffuse_reflectance(red.kind), Vec3::X);
    assert!(red.two_sided);
    assert!((red.opacity - 0.212_671).abs() < 1e-4, "{}", red.opacity);
    assert!((at(0.5, -0.5).opacity - 0.715_160).abs() < 1e-4);
    assert_eq!(at(0.5, 0.5).opacity, 1.0);
    assert_eq!(at(3.0, 0.0).opacity, 0.5);
    match &loaded.desc.materials[0].material {
        MaterialDesc::Textured { material, textures } => {
            assert!(matches!(**material, MaterialDesc::Mask { .. }));
            let params: Vec<ColorParam> = textures.iter().map(|t| t.param).collect();
            assert_eq!(params, [ColorParam::Reflectance, ColorParam::Opacity]);
        }
        m => panic!("{m:?}"),
    }
}

/// Area emitters that name the same radiance texture share one loaded copy: the lights name
/// one texture, and one with another factor wraps that copy (a texture of its own, the image
/// not read again). Each light's radiance is the texture's mean times its factor.
#[test]
fn area_emitters_share_their_radiance_texture() {
    let dir = dir_with_png("shared-radiance");
    let shape = |x: i32, factor: f32| {
        format!(
            "(geometry: Rectangle, to_world: [Translate(({x}, 0, 0))], emission: Some(({factor}, \
             {factor}, {factor})), emission_texture: Some(Bitmap(filename: \"quad.png\", raw: \
             true))), "
        )
    };
    let path = dir.join("shared.ron");
    std::fs::write(
        &path,
        format!(
            "(camera: (fov: 45), film: (width: 4, height: 4), shapes: [{}{}{}])",
            shape(0, 1.0),
            shape(3, 1.0),
            shape(6, 2.0)
        ),
    )
    .unwrap();
    let scene = load_scene(&path, &LoadOptions::default()).unwrap().scene;
    let lights: Vec<(Vec3, Option<u32>)> = scene
        .lights
        .lights()
        .iter()
        .filter_map(|l| match *l {
            restir_lights::Light::Area {
                radiance, texture, ..
            } => Some((radiance, texture)),
            _ => None,
        })
        .collect();
    // Red, green, blue and white: the mean is 0.5 in each channel.
    let mean = Vec3::splat(0.5);
    assert_eq!(
        lights,
        [(mean, Some(0)), (mean, Some(0)), (2.0 * mean, Some(1))]
    );
}
