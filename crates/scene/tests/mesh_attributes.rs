//! Mitsuba's `mesh_attribute` texture on PLY meshes: face attributes constant per triangle,
//! vertex attributes interpolated, `scale`, both scene formats and `restir convert`'s XML, and
//! the errors (an attribute the mesh lacks, a shape that is no mesh, a channel count the
//! parameter cannot read) with the file, the line and what the mesh has.

use std::path::{Path, PathBuf};

use glam::Vec3;
use restir_geometry::Ray;
use restir_materials::BsdfKind;
use restir_scene::xml::{XmlWriteOptions, to_mitsuba_xml};
use restir_scene::{LoadOptions, Scene, TextureDesc, load_desc, load_scene};
use restir_testkit::TempDir;

/// Two triangles in the `z = 0` plane: the left one `x < 0`, the right one `x > 0`, both facing
/// `+z`. Vertex colours (8-bit, sRGB-coded) red at the bottom-left corner, green at the top,
/// blue at the bottom-right, white at the top-left; face colours (floats) and a face weight.
const PLY: &str = "ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
property uchar red
property uchar green
property uchar blue
element face 2
property list uchar int vertex_indices
property float color_0
property float color_1
property float color_2
property float weight_0
end_header
-1 -1 0 255 0 0
0 1 0 0 255 0
1 -1 0 0 0 255
-1 1 0 255 255 255
3 0 1 3 0.1 0.2 0.3 0.25
3 0 2 1 0.6 0.5 0.4 0.75
";

fn dir(tag: &str) -> TempDir {
    let dir = TempDir::new("meshattr", tag);
    std::fs::write(dir.join("m.ply"), PLY).unwrap();
    dir
}

/// A scene file whose line 3 onwards is `body`.
fn write_scene(dir: &Path, body: &str) -> PathBuf {
    let path = dir.join("s.xml");
    std::fs::write(
        &path,
        format!(
            "<scene version=\"3.0.0\">\n    <sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"4\"/><integer name=\"height\" value=\"4\"/></film></sensor>\n{body}\n</scene>"
        ),
    )
    .unwrap();
    path
}

fn reflectance(scene: &Scene, x: f32, y: f32) -> Vec3 {
    let si = scene
        .intersect(&Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z))
        .expect("hit");
    match scene.bsdf(&si).kind {
        BsdfKind::Diffuse { reflectance } => reflectance,
        k => panic!("expected diffuse, got {k:?}"),
    }
}

fn load(path: &Path) -> Scene {
    load_scene(path, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .scene
}

fn load_err(path: &Path) -> String {
    match load_scene(path, &LoadOptions::default()) {
        Ok(_) => panic!("{} loads", path.display()),
        Err(e) => e.to_string(),
    }
}

fn shape_with(texture: &str) -> String {
    format!(
        "    <shape type=\"ply\"><string name=\"filename\" value=\"m.ply\"/>\n        <bsdf type=\"diffuse\">{texture}</bsdf>\n    </shape>"
    )
}

#[test]
fn face_attributes_are_constant_per_triangle() {
    let d = dir("face");
    let path = write_scene(
        &d,
        &shape_with(
            r#"<texture type="mesh_attribute" name="reflectance"><string name="name" value="face_color"/></texture>"#,
        ),
    );
    let scene = load(&path);
    assert!(scene.features.has_textures);
    for (x, y) in [(-0.9, 0.5), (-0.9, -0.5)] {
        assert_eq!(reflectance(&scene, x, y), Vec3::new(0.1, 0.2, 0.3));
    }
    for (x, y) in [(0.1, -0.9), (0.5, -0.5)] {
        assert_eq!(reflectance(&scene, x, y), Vec3::new(0.6, 0.5, 0.4));
    }
    // A one-channel attribute fills the three channels; `scale` multiplies.
    let path = write_scene(
        &d,
        &shape_with(
            r#"<texture type="mesh_attribute" name="reflectance"><string name="name" value="face_weight"/><float name="scale" value="0.5"/></texture>"#,
        ),
    );
    let scene = load(&path);
    assert_eq!(reflectance(&scene, -0.9, 0.5), Vec3::splat(0.125));
    assert_eq!(reflectance(&scene, 0.5, -0.5), Vec3::splat(0.375));
}

#[test]
fn vertex_attributes_are_interpolated() {
    let d = dir("vertex");
    let path = write_scene(
        &d,
        &shape_with(
            r#"<texture type="mesh_attribute" name="reflectance"><string name="name" value="vertex_color"/></texture>"#,
        ),
    );
    let scene = load(&path);
    // On the right triangle (corners red (-1,-1), blue (1,-1), green (0,1)): at (0, -1/3) the
    // barycentrics are 1/3 each.
    let c = reflectance(&scene, 0.0, -1.0 / 3.0);
    assert!(
        (c - Vec3::splat(1.0 / 3.0)).abs().max_element() < 1e-5,
        "{c}"
    );
    // Near a corner, that corner's colour.
    let c = reflectance(&scene, 0.98, -0.99);
    assert!(c.z > 0.97 && c.x < 0.02, "{c}");
    let c = reflectance(&scene, -0.99, 0.98);
    assert!(c.min_element() > 0.97, "{c}");
}

#[test]
fn a_missing_attribute_is_an_error_with_what_the_mesh_has() {
    let d = dir("missing");
    let path = write_scene(
        &d,
        &shape_with(
            r#"<texture type="mesh_attribute" name="reflectance"><string name="name" value="vertex_albedo"/></texture>"#,
        ),
    );
    let e = load_err(&path);
    for part in [
        "s.xml:3:",
        "m.ply",
        "vertex_albedo",
        "its attributes: vertex_color, face_color, face_weight",
    ] {
        assert!(e.contains(part), "{part:?} not in: {e}");
    }
    // A shape that is not a mesh.
    let path = write_scene(
        &d,
        r#"    <shape type="sphere">
        <bsdf type="diffuse"><texture type="mesh_attribute" name="reflectance"><string name="name" value="face_color"/></texture></bsdf>
    </shape>"#,
    );
    let e = load_err(&path);
    assert!(e.contains("s.xml:3:") && e.contains("not a mesh"), "{e}");
    // A name that is neither a vertex nor a face attribute, at its line.
    let path = write_scene(
        &d,
        &shape_with(
            r#"<texture type="mesh_attribute" name="reflectance"><string name="name" value="color"/></texture>"#,
        ),
    );
    let e = load_err(&path);
    assert!(
        e.contains("s.xml:4:") && e.contains("'vertex_' or 'face_'"),
        "{e}"
    );
    // A three-channel attribute where one channel is read (a mask's opacity).
    let path = write_scene(
        &d,
        r#"    <shape type="ply"><string name="filename" value="m.ply"/>
        <bsdf type="mask"><texture type="mesh_attribute" name="opacity"><string name="name" value="face_color"/></texture><bsdf type="diffuse"/></bsdf>
    </shape>"#,
    );
    let e = load_err(&path);
    assert!(
        e.contains("s.xml:3:") && e.contains("3 channels") && e.contains("opacity"),
        "{e}"
    );
}

/// A RON scene uses the texture as `MeshAttribute(name: …)`; `restir convert` writes it as
/// Mitsuba's `mesh_attribute`, which reads back to the same description and scene.
#[test]
fn ron_and_the_xml_writer() {
    let d = dir("ron");
    let ron = r#"(
    camera: (fov: 40, to_world: [LookAt(origin: (0, 0, 4), target: (0, 0, 0), up: (0, 1, 0))]),
    film: (width: 8, height: 8, filter: Box),
    shapes: [(geometry: Ply(filename: "m.ply"), material: Some(Inline(Textured(
        material: Diffuse(reflectance: (0.5, 0.5, 0.5)),
        textures: [(param: Reflectance, texture: MeshAttribute(name: "face_color", scale: 2))],
    ))))],
)"#;
    let path = d.join("s.ron");
    std::fs::write(&path, ron).unwrap();
    let (desc, _) = load_desc(&path, &[]).unwrap();
    let scene = Scene::build(&desc, &d, &path).unwrap();
    assert_eq!(reflectance(&scene, -0.9, 0.5), Vec3::new(0.2, 0.4, 0.6));
    // Clamped to [0, 1] as every textured reflectance.
    assert_eq!(reflectance(&scene, 0.5, -0.5), Vec3::new(1.0, 1.0, 0.8));
    let xml = to_mitsuba_xml(&desc, &XmlWriteOptions::default()).unwrap();
    assert!(
        xml.contains(r#"<texture type="mesh_attribute" name="reflectance">"#),
        "{xml}"
    );
    let back_path = d.join("back.xml");
    std::fs::write(&back_path, &xml).unwrap();
    let (back, warnings) = load_desc(&back_path, &[]).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let texture = |desc: &restir_scene::SceneDesc| format!("{:?}", desc.shapes[0].material);
    assert!(
        texture(&back).contains("MeshAttribute"),
        "{}",
        texture(&back)
    );
    let scene = Scene::build(&back, &d, &back_path).unwrap();
    assert_eq!(reflectance(&scene, -0.9, 0.5), Vec3::new(0.2, 0.4, 0.6));
    // A name Mitsuba's XML would substitute is refused by the writer.
    let mut bad = desc.clone();
    if let Some(restir_scene::MaterialRef::Inline(restir_scene::MaterialDesc::Textured {
        textures,
        ..
    })) = &mut bad.shapes[0].material
    {
        textures[0].texture = TextureDesc::MeshAttribute {
            name: "face_$x".into(),
            scale: 1.0,
        };
    }
    let e = to_mitsuba_xml(&bad, &XmlWriteOptions::default()).unwrap_err();
    assert!(e.to_string().contains("face_$x"), "{e}");
}

/// Giving a shape a material whose mesh attribute it lacks is refused; giving it to a mesh that
/// has the attribute binds it there.
#[test]
fn editing_a_shape_material_checks_its_attributes() {
    let d = dir("edit");
    let path = write_scene(
        &d,
        &format!(
            "{}\n    <shape type=\"rectangle\"><transform name=\"to_world\"><translate x=\"5\"/></transform></shape>\n    <shape type=\"ply\"><string name=\"filename\" value=\"m.ply\"/><transform name=\"to_world\"><translate x=\"-5\"/></transform></shape>",
            shape_with(
                r#"<texture type="mesh_attribute" name="reflectance"><string name="name" value="face_color"/></texture>"#
            )
        ),
    );
    let mut scene = load(&path);
    let m = scene.shape_bsdf()[0];
    let e = scene.set_shape_material(1, m).unwrap_err();
    assert!(e.to_string().contains("shape 1") && e.to_string().contains("face_color"));
    scene.set_shape_material(2, m).unwrap();
    assert_eq!(reflectance(&scene, -5.9, 0.5), Vec3::new(0.1, 0.2, 0.3));
}

/// Attributes count against `--max-memory` with their mesh: the limit that holds the mesh's
/// triangles, positions and attributes loads it, one byte less does not.
#[test]
fn attributes_count_against_the_memory_limit() {
    let d = dir("memory");
    let path = write_scene(&d, &shape_with(""));
    // 2 triangles, 4 positions (48 bytes), 4 normals computed at load (the file has none: 48
    // bytes), vertex_color 4 × 3, face_color 2 × 3 and face_weight 2 floats (80 bytes).
    let need = 2 * restir_scene::limits::MESH_BYTES_PER_TRIANGLE + 48 + 48 + 80;
    let with_limit = |max_memory| {
        load_scene(
            &path,
            &LoadOptions {
                max_memory: Some(max_memory),
                ..LoadOptions::default()
            },
        )
    };
    assert!(with_limit(need).is_ok());
    match with_limit(need - 1) {
        Ok(_) => panic!("loads within {} bytes", need - 1),
        Err(e) => assert!(e.to_string().contains("m.ply"), "{e}"),
    }
}
