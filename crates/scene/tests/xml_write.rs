//! The Mitsuba 3 XML writer against this crate's importer: a description written as XML and read
//! back builds the same runtime scene (every shape, material, texture, light, the camera and the
//! BVH: their `Debug` text is compared whole), for the generated families and the shipped
//! scenes; and what Mitsuba 3 cannot express is an error naming it. (Against Mitsuba itself:
//! docs/VALIDATION.md, "Scenes written as Mitsuba 3 XML".)

use std::path::{Path, PathBuf};

use restir_families::{Family, Params, Split, members};
use restir_scene::xml::{XmlWriteOptions, to_mitsuba_xml};
use restir_scene::{ColorParam, MaterialDesc, MaterialRef, Scene, SceneDesc, defaults, load_desc};
use restir_testkit::TempDir;

/// A fresh directory per test (tests run in parallel), removed when the test ends.
fn temp_dir(test: &str) -> TempDir {
    TempDir::new("xmlwrite", test)
}

/// The built scene and its integrator settings as text, without where the integrator was
/// declared (file and line differ between the two files by construction).
fn built(desc: &SceneDesc, file: &Path) -> String {
    let scene = Scene::build(desc, file.parent().unwrap(), file)
        .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let mut integrator = desc.integrator.clone();
    integrator.location = Default::default();
    format!("{scene:?}\n{integrator:?}")
}

/// `desc` with what the XML says differently but renders the same: `Black` is a diffuse bsdf of
/// reflectance 0, and a textured parameter's unused constant is the default (Mitsuba takes a
/// parameter as a value or as a texture, not both).
fn as_written(desc: &SceneDesc) -> SceneDesc {
    fn material(m: &mut MaterialDesc) {
        match m {
            MaterialDesc::Black => {
                *m = MaterialDesc::Diffuse {
                    reflectance: [0.0; 3],
                }
            }
            MaterialDesc::TwoSided(inner) => material(inner),
            MaterialDesc::Textured {
                material: inner,
                textures,
            } => {
                material(inner);
                let mut m = &mut **inner;
                while let MaterialDesc::TwoSided(i) = m {
                    m = &mut **i;
                }
                for b in textures.iter() {
                    let default = match b.param {
                        ColorParam::Reflectance | ColorParam::DiffuseReflectance => {
                            defaults::DIFFUSE_REFLECTANCE
                        }
                        _ => defaults::SPECULAR,
                    };
                    match (m as &mut MaterialDesc, b.param) {
                        (MaterialDesc::Diffuse { reflectance }, ColorParam::Reflectance) => {
                            *reflectance = default
                        }
                        (
                            MaterialDesc::Plastic {
                                diffuse_reflectance,
                                ..
                            }
                            | MaterialDesc::RoughPlastic {
                                diffuse_reflectance,
                                ..
                            },
                            ColorParam::DiffuseReflectance,
                        ) => *diffuse_reflectance = default,
                        (
                            MaterialDesc::Conductor {
                                specular_reflectance,
                                ..
                            }
                            | MaterialDesc::RoughConductor {
                                specular_reflectance,
                                ..
                            }
                            | MaterialDesc::Dielectric {
                                specular_reflectance,
                                ..
                            }
                            | MaterialDesc::ThinDielectric {
                                specular_reflectance,
                                ..
                            }
                            | MaterialDesc::RoughDielectric {
                                specular_reflectance,
                                ..
                            }
                            | MaterialDesc::Plastic {
                                specular_reflectance,
                                ..
                            }
                            | MaterialDesc::RoughPlastic {
                                specular_reflectance,
                                ..
                            },
                            ColorParam::SpecularReflectance,
                        ) => *specular_reflectance = default,
                        (
                            MaterialDesc::Dielectric {
                                specular_transmittance,
                                ..
                            }
                            | MaterialDesc::ThinDielectric {
                                specular_transmittance,
                                ..
                            }
                            | MaterialDesc::RoughDielectric {
                                specular_transmittance,
                                ..
                            },
                            ColorParam::SpecularTransmittance,
                        ) => *specular_transmittance = default,
                        (other, p) => panic!("{p:?} on {other:?}"),
                    }
                }
            }
            _ => {}
        }
    }
    let mut d = desc.clone();
    for m in &mut d.materials {
        material(&mut m.material);
    }
    for s in &mut d.shapes {
        if let Some(MaterialRef::Inline(m)) = &mut s.material {
            material(m);
        }
    }
    d
}

/// Writes `desc` (read from `source`) as XML to `xml`, reads it back and checks that both build
/// the same scene (up to [`as_written`]); returns the XML text.
fn round_trip(desc: &SceneDesc, source: &Path, xml: &Path, prefix: Option<&str>) -> String {
    let options = XmlWriteOptions {
        file_prefix: prefix.map(PathBuf::from),
        header: Some(format!("converted from {}", source.display())),
    };
    let text =
        to_mitsuba_xml(desc, &options).unwrap_or_else(|e| panic!("{}: {e}", source.display()));
    std::fs::write(xml, &text).unwrap();
    let (back, warnings) =
        load_desc(xml, &[]).unwrap_or_else(|e| panic!("{}: {e}\n{text}", source.display()));
    assert!(warnings.is_empty(), "{}: {warnings:?}", source.display());
    let (a, b) = (built(&as_written(desc), source), built(&back, xml));
    if a != b {
        let at = a
            .bytes()
            .zip(b.bytes())
            .position(|(x, y)| x != y)
            .unwrap_or(0);
        let from = at.saturating_sub(300);
        panic!(
            "{}: the XML builds another scene; first difference at byte {at}:\n  ron: {}\n  xml: {}",
            source.display(),
            &a[from..(at + 300).min(a.len())],
            &b[from..(at + 300).min(b.len())]
        );
    }
    text
}

#[test]
fn the_static_families_round_trip() {
    let dir = temp_dir("families");
    for (family, split) in [
        (Family::Pt, Split::Train),
        (Family::Pt, Split::Test),
        (Family::Di, Split::Test),
    ] {
        for member in members(family, split) {
            // The many-light members at 10³ lights stand for the rest (10⁵ lights build slowly).
            if matches!(&member.params, Params::Di(_, o) if o.lights > 1000) {
                continue;
            }
            let generated = member.generate().unwrap();
            let ron = generated.write(&dir, &member.name()).unwrap();
            let (desc, _) = load_desc(&ron, &[]).unwrap();
            let xml = ron.with_extension("xml");
            let text = round_trip(&desc, &ron, &xml, None);
            assert!(text.starts_with("<?xml"), "{text}");
        }
    }
}

#[test]
fn the_shipped_scenes_round_trip() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let dir = temp_dir("shipped");
    for name in [
        "cornell-box.xml",
        "cornell-materials.xml",
        "glossy-still-life.xml",
        "envmap-spheres.xml",
        "thin-pane.xml",
        "textured/textured-shapes.xml",
        "many-lights.ron",
        "indirect-room-glass.ron",
    ] {
        let source = scenes.join(name);
        let (mut desc, _) = load_desc(&source, &[]).unwrap();
        // The still life's sidecar animation is refused (below); its still scene is written.
        desc.animation = None;
        // Written to another directory: file names go through the prefix back to `scenes/`.
        let stem = name.replace('/', "-");
        let xml = dir.join(Path::new(&stem).with_extension("xml"));
        let prefix = source.parent().unwrap().to_str().unwrap().to_string();
        round_trip(&desc, &source, &xml, Some(&prefix));
    }
}

/// Every material model, texture, filter, camera and light kind the description has.
const EVERYTHING: &str = r#"(
    camera: (fov: 35, fov_axis: y, to_world: [LookAt(origin: (0, 1, 5), target: (0, 0.5, 0), up: (0, 1, 0))],
             aperture_radius: 0.05, focus_distance: 4.5),
    film: (width: 24, height: 16, filter: Gaussian(stddev: 0.4), filename: Some("out.exr")),
    spp: 3,
    integrator: (kind: "path", max_depth: 7, rr_depth: 3, hide_emitters: true),
    materials: [
        (name: "d", material: Diffuse(reflectance: (0.2, 0.3, 0.4))),
        (name: "c", material: Conductor(ior: (material: Some("Au")), specular_reflectance: (0.9, 0.8, 0.7))),
        (name: "rc", material: RoughConductor(ior: (eta: Some((0.2, 0.9, 1.1)), k: Some((3.9, 2.4, 2.1))),
                                            roughness: (distribution: ggx, alpha_u: Some(0.05), alpha_v: Some(0.3)))),
        (name: "g", material: Dielectric(int_ior: 1.33, ext_ior: 1.0, specular_transmittance: (0.9, 1, 1))),
        (name: "rg", material: RoughDielectric(roughness: (alpha: 0.2))),
        (name: "tg", material: ThinDielectric(int_ior: 1.33, specular_reflectance: (0.8, 0.9, 1))),
        (name: "p", material: Plastic(diffuse_reflectance: (0.1, 0.5, 0.2), nonlinear: true)),
        (name: "rp", material: RoughPlastic(int_ior: 1.6, roughness: (distribution: ggx, alpha: 0.3))),
        (name: "n", material: Null),
        (name: "b", material: Black),
        (name: "two", material: TwoSided(RoughConductor(ior: (material: Some("Cu"))))),
        (name: "tex", material: Textured(material: RoughPlastic(), textures: [
            (param: DiffuseReflectance, texture: Checkerboard(color0: (0.9, 0.9, 0.9), color1: (0.1, 0.1, 0.1),
                                                              uv: (scale: (8, 4), offset: (0.25, 0.5)))),
            (param: SpecularReflectance, texture: Bitmap(filename: "textured/tex.png", raw: true, wrap: Mirror, filter: Nearest)),
        ])),
        (name: "two-tex", material: TwoSided(Textured(material: Diffuse(reflectance: (0.5, 0.5, 0.5)),
            textures: [(param: Reflectance, texture: Bitmap(filename: "textured/tex.png", uv: (scale: (2, 2), offset: (0, 0)), wrap: Clamp))]))),
        (name: "sphere", material: Diffuse(reflectance: (0.5, 0.5, 0.5))),
    ],
    shapes: [
        (geometry: Rectangle, to_world: [Scale((3, 3, 1)), Rotate(axis: (1, 0, 0), angle: -90)], material: Some(Ref("tex"))),
        (geometry: Cube, to_world: [Scale((0.3, 0.3, 0.3)), Translate((-1, 0.3, 0))], material: Some(Ref("rc"))),
        (geometry: Disk, to_world: [Matrix((0.5, 0, 0, 1, 0, 0.5, 0, 1, 0, 0, 0.5, -1, 0, 0, 0, 1))], material: Some(Ref("two-tex")),
         flip_normals: true),
        (id: Some("sphere"), geometry: Sphere(center: (0.1, 0.2, 0.3), radius: 0.25),
         to_world: [Rotate(axis: (0, 1, 1), angle: 30), Scale((2, 2, 2)), Translate((1, 0.5, 0))], material: Some(Ref("sphere"))),
        (geometry: Sphere(center: (0, 0.4, 1), radius: 0.2), material: Some(Ref("g"))),
        (geometry: Sphere(center: (0.6, 0.4, 1), radius: 0.2), material: Some(Ref("rg"))),
        (geometry: Obj(filename: "textured/quad.obj"), to_world: [Translate((0, 1, -2))], material: Some(Ref("p")), face_normals: true),
        (geometry: Ply(filename: "textured/quad.ply"), to_world: [Translate((1, 1, -2))], material: Some(Ref("rp"))),
        (geometry: Rectangle, to_world: [Translate((0, 2, -2))], material: Some(Ref("n"))),
        (geometry: Rectangle, to_world: [Translate((0, -2, -2))], material: Some(Ref("tg"))),
        (geometry: Rectangle, to_world: [Translate((2, 2, -2))], material: Some(Ref("b"))),
        (geometry: Rectangle, to_world: [Translate((-2, 2, -2))], material: Some(Ref("two"))),
        (geometry: Rectangle, to_world: [Translate((-2, 0, -2))], material: Some(Ref("c"))),
        (geometry: Rectangle, to_world: [Translate((-2, -2, -2))], material: Some(Ref("d"))),
        (geometry: Rectangle, to_world: [Scale((0.3, 0.3, 1)), Rotate(axis: (1, 0, 0), angle: 90), Translate((0, 3, 0))],
         emission: Some((10, 9, 8))),
        (geometry: Rectangle, to_world: [Translate((0, 0, -3))],
         material: Some(Inline(Diffuse(reflectance: (0.7, 0.7, 0.7)))), emission: Some((0.5, 0.5, 0.5))),
        (geometry: Rectangle, to_world: [Translate((2, 0, -3))], emission: Some((1, 1, 1)),
         emission_texture: Some(Checkerboard(color0: (3, 2, 1)))),
    ],
    lights: [
        Point(position: (1, 2, 1), intensity: (3, 2, 1)),
        Spot(intensity: (4, 4, 4)),
        Spot(intensity: (5, 4, 3), cutoff_angle: 35, beam_width: Some(10),
             to_world: [LookAt(origin: (0, 3, 0), target: (0, 0, 0), up: (0, 0, 1))],
             texture: Some(Bitmap(filename: "textured/tex.png", wrap: Clamp))),
        Projector(irradiance: (2, 1, 0.5)),
        Projector(scale: 3, fov: Some(40), fov_axis: y,
             to_world: [LookAt(origin: (0, 3, 1), target: (0, 0, 0), up: (0, 0, 1))],
             texture: Some(Bitmap(filename: "textured/tex.png"))),
        Directional(direction: (0.2, -1, 0.1), irradiance: (0.5, 0.5, 0.5)),
        Envmap(filename: "envmap/sky.exr", scale: 0.7, to_world: [Rotate(axis: (0, 1, 0), angle: 40)]),
    ],
)"#;

#[test]
fn every_model_filter_camera_and_light_round_trips() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let dir = temp_dir("everything");
    // Beside the shipped scenes' assets, as a user's scene would be.
    let source = scenes.join("everything-xml-write-test.ron");
    let desc = restir_scene::parse_ron(EVERYTHING, &source).unwrap();
    let xml = dir.join("everything.xml");
    let text = round_trip(&desc, &source, &xml, Some(scenes.to_str().unwrap()));
    for expected in [
        r#"<sensor type="thinlens">"#,
        r#"<rfilter type="gaussian">"#,
        r#"<bsdf type="roughconductor" id="rc">"#,
        r#"<float name="alpha_u" value="0.05"/>"#,
        r#"<string name="wrap_mode" value="mirror"/>"#,
        r#"<string name="filter_type" value="nearest"/>"#,
        r#"<string name="wrap_mode" value="clamp"/>"#,
        r#"<bsdf type="null" id="n">"#,
        r#"<texture type="checkerboard" name="diffuse_reflectance">"#,
        r#"<boolean name="raw" value="true"/>"#,
        // The material named like the sphere's id is renamed (one id namespace in Mitsuba).
        r#"<bsdf type="diffuse" id="sphere-bsdf">"#,
        r#"<ref id="sphere-bsdf"/>"#,
        r#"<emitter type="envmap">"#,
        r#"<emitter type="spot">"#,
        r#"<float name="cutoff_angle" value="35"/>"#,
        r#"<float name="beam_width" value="10"/>"#,
        r#"<texture type="bitmap" name="texture">"#,
        r#"<emitter type="projector">"#,
        r#"<texture type="bitmap" name="irradiance">"#,
        r#"<float name="scale" value="3"/>"#,
        r#"<texture type="checkerboard" name="radiance">"#,
        r#"<string name="fov_axis" value="y"/>"#,
        r#"<boolean name="hide_emitters" value="true"/>"#,
        "<!-- output file: out.exr -->",
    ] {
        assert!(text.contains(expected), "{expected} not in\n{text}");
    }
    // The sphere's transform turns it (and its texture), so it is written as given; an unturned
    // sphere's is folded into its centre and radius (the shipped scenes above).
    assert!(text.contains(r#"<rotate x="0" y="1" z="1""#), "{text}");
    // A shape with a file only takes face_normals (Mitsuba rejects it elsewhere).
    assert_eq!(text.matches("face_normals").count(), 1, "{text}");
}

/// Clip planes other than Mitsuba's defaults are written and read back; the defaults are left
/// out.
#[test]
fn clip_planes_round_trip() {
    let dir = temp_dir("clip");
    for camera in ["fov: 45", "fov: 45, orthographic: true"] {
        for clips in ["", ", near_clip: 0.5, far_clip: 40"] {
            let ron = format!("(camera: ({camera}{clips}), shapes: [(geometry: Rectangle)])");
            let source = dir.join("clip.ron");
            std::fs::write(&source, &ron).unwrap();
            let (desc, _) = load_desc(&source, &[]).unwrap();
            let text = round_trip(&desc, &source, &dir.join("clip.xml"), None);
            assert_eq!(text.contains("near_clip"), !clips.is_empty(), "{text}");
            assert_eq!(text.contains("far_clip"), !clips.is_empty(), "{text}");
        }
    }
}

#[test]
fn what_mitsuba_cannot_say_is_refused_by_name() {
    let base = restir_scene::parse_ron(
        "(camera: (fov: 45), shapes: [(geometry: Rectangle)])",
        "t.ron".as_ref(),
    )
    .unwrap();
    let write = |desc: &SceneDesc| {
        to_mitsuba_xml(desc, &XmlWriteOptions::default())
            .unwrap_err()
            .to_string()
    };

    let mut d = base.clone();
    d.integrator.kind = "restir-pt".into();
    let e = write(&d);
    assert!(e.contains("the integrator: 'restir-pt'"), "{e}");

    let mut d = base.clone();
    d.integrator.params.push(("candidates".into(), "4".into()));
    let e = write(&d);
    assert!(e.contains("the parameter 'candidates'"), "{e}");

    let mut d = base.clone();
    d.shapes[0].geometry = restir_scene::GeometryDesc::Mesh {
        positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        indices: vec![[0, 1, 2]],
        normals: None,
    };
    let e = write(&d);
    assert!(e.contains("shape 0: an inline triangle mesh"), "{e}");

    let mut d = base.clone();
    d.camera.near_clip = 0.0;
    let e = write(&d);
    assert!(e.contains("near_clip 0: Mitsuba needs it positive"), "{e}");

    let mut d = base.clone();
    d.shapes[0].material = Some(restir_scene::MaterialRef::Ref("nowhere".into()));
    let e = write(&d);
    assert!(e.contains("undefined material 'nowhere'"), "{e}");

    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let (d, _) = load_desc(&scenes.join("many-lights-flythrough.ron"), &[]).unwrap();
    let e = write(&d);
    assert!(e.contains("the scene: it is animated"), "{e}");

    let textured = restir_scene::parse_ron(
        r#"(camera: (fov: 45), materials: [(name: "t", material: Textured(material: Textured(material: Diffuse(reflectance: (0.5, 0.5, 0.5)), textures: []), textures: []))])"#,
        "t.ron".as_ref(),
    )
    .unwrap();
    let e = write(&textured);
    assert!(e.contains("material 't'"), "{e}");

    let tinted = restir_scene::parse_ron(
        r#"(camera: (fov: 45), lights: [Projector(irradiance: (1, 0.5, 0.5), texture: Some(Checkerboard()))])"#,
        "t.ron".as_ref(),
    )
    .unwrap();
    let e = write(&tinted);
    assert!(
        e.contains("a projector: Mitsuba's irradiance is a colour or a texture"),
        "{e}"
    );

    let mut d = base.clone();
    d.shapes[0].emission = Some([2.0, 1.0, 1.0]);
    d.shapes[0].emission_texture = Some(restir_scene::TextureDesc::Checkerboard {
        color0: [1.0; 3],
        color1: [0.0; 3],
        uv: Default::default(),
    });
    let e = write(&d);
    assert!(
        e.contains("shape 0: its emission texture has the factor [2.0, 1.0, 1.0]"),
        "{e}"
    );
}

/// Mitsuba 3 substitutes `$name` in every attribute and has no escape for a literal `$`: a file
/// name, shape id or material name holding one would read back as another (`m$spp.ply` loads
/// `m16.ply`), so the writer refuses it by name.
#[test]
fn a_dollar_in_a_name_is_refused_not_substituted() {
    let write = |ron: &str| {
        let d = restir_scene::parse_ron(ron, "t.ron".as_ref()).unwrap();
        to_mitsuba_xml(&d, &XmlWriteOptions::default()).map_err(|e| e.to_string())
    };
    let e = write(r#"(camera: (fov: 45), shapes: [(geometry: Ply(filename: "m$spp.ply"))])"#)
        .unwrap_err();
    assert!(
        e.contains("shape 0") && e.contains("m$spp.ply") && e.contains("'$'"),
        "{e}"
    );
    let e = write(r#"(camera: (fov: 45), shapes: [(id: Some("a$resx"), geometry: Rectangle)])"#)
        .unwrap_err();
    assert!(e.contains("id \"a$resx\""), "{e}");
    let e = write(
        r#"(camera: (fov: 45), materials: [(name: "m$spp", material: Diffuse(reflectance: (0.5, 0.5, 0.5)))])"#,
    )
    .unwrap_err();
    assert!(e.contains("material 'm$spp'"), "{e}");
    let e = write(r#"(camera: (fov: 45), lights: [Envmap(filename: "sky$x.exr")])"#).unwrap_err();
    assert!(
        e.contains("the environment map") && e.contains("sky$x.exr"),
        "{e}"
    );
    // Without a '$' the same descriptions are written.
    write(r#"(camera: (fov: 45), shapes: [(geometry: Ply(filename: "m.ply"))])"#).unwrap();
}

/// Cylinders (with and without their defaults, as an emitter) and signed distance grids round
/// trip.
#[test]
fn cylinders_and_sdfgrids_round_trip() {
    let dir = temp_dir("shapes");
    let n = 5u32;
    let mut vol = b"VOL\x03".to_vec();
    for v in [1i32, n as i32, n as i32, n as i32, 1] {
        vol.extend(v.to_le_bytes());
    }
    for v in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0] {
        vol.extend(v.to_le_bytes());
    }
    for i in 0..n * n * n {
        let p = [i % n, (i / n) % n, i / (n * n)].map(|c| c as f32 / (n - 1) as f32 - 0.5);
        let d = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 0.3;
        vol.extend(d.to_le_bytes());
    }
    std::fs::write(dir.join("ball.vol"), vol).unwrap();
    let source = dir.join("shapes.ron");
    let ron = r#"(
        camera: (fov: 40, to_world: [LookAt(origin: (0, -5, 1), target: (0, 0, 0), up: (0, 0, 1))]),
        shapes: [
            (geometry: Cylinder()),
            (geometry: Cylinder(p0: (1, 0, 0), p1: (1, 0, 2), radius: 0.25),
             to_world: [Rotate(axis: (1, 0, 0), angle: 20)], emission: Some((2, 2, 2)), flip_normals: true),
            (geometry: SdfGrid(filename: "ball.vol")),
            (geometry: SdfGrid(filename: "ball.vol", normals: analytic), to_world: [Translate((2, 0, 0))]),
        ],
    )"#;
    std::fs::write(&source, ron).unwrap();
    let desc = restir_scene::parse_ron(ron, &source).unwrap();
    let text = round_trip(&desc, &source, &dir.join("shapes.xml"), None);
    for expected in [
        r#"<shape type="cylinder">"#,
        r#"<point name="p1" x="1" y="0" z="2"/>"#,
        r#"<float name="radius" value="0.25"/>"#,
        r#"<shape type="sdfgrid">"#,
        r#"<string name="normals" value="analytic"/>"#,
    ] {
        assert!(text.contains(expected), "{expected} not in\n{text}");
    }
    // What Mitsuba's sdfgrid cannot be is refused by name.
    let mut bad = desc.clone();
    bad.shapes[2].emission = Some([1.0; 3]);
    let e = to_mitsuba_xml(&bad, &XmlWriteOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("sdfgrid cannot be an area emitter"), "{e}");
}
