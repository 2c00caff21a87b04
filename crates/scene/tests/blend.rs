//! Mitsuba's `blendbsdf` in XML and RON: nested bsdfs inline and by `<ref>`, a constant or
//! textured weight (looked up at each hit), its nesting inside `mask` and `twosided`, the XML
//! writer's round trip, and errors with `file:line`.

use std::path::Path;

use glam::Vec3;
use restir_materials::{Bsdf, BsdfKind};
use restir_scene::{
    ColorParam, LoadOptions, MaterialDesc, load_scene, parse_ron,
    xml::{XmlWriteOptions, parse_xml, to_mitsuba_xml},
};
use restir_testkit::TempDir;

mod common;
use common::scene_text;

fn parse(body: &str) -> Result<Vec<MaterialDesc>, String> {
    parse_xml(&scene_text(body), Path::new("b.xml"), &[])
        .map(|(d, _)| d.materials.into_iter().map(|m| m.material).collect())
        .map_err(|e| e.to_string())
}

#[test]
fn inline_and_referenced_bsdfs_in_order() {
    let ms = parse(
        r#"<bsdf type="conductor" id="metal"/>
    <bsdf type="blendbsdf" id="b">
        <float name="weight" value="0.3"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.1, 0.2, 0.3"/></bsdf>
        <ref id="metal"/>
    </bsdf>"#,
    )
    .unwrap();
    let MaterialDesc::Blend { weight, bsdfs } = &ms[1] else {
        panic!("{:?}", ms[1]);
    };
    assert_eq!(*weight, 0.3);
    assert!(
        matches!(bsdfs.0, MaterialDesc::Diffuse { reflectance } if reflectance == [0.1, 0.2, 0.3])
    );
    assert_eq!(bsdfs.1, ms[0]);
}

/// A checkerboard weight of 0 and 1 picks one component on each square, at every hit.
#[test]
fn textured_weight_reaches_the_bsdf() {
    let dir = TempDir::new("blend", "weight");
    let path = dir.join("s.xml");
    std::fs::write(
        &path,
        scene_text(
            r#"    <texture type="checkerboard" id="w">
        <rgb name="color0" value="0"/><rgb name="color1" value="1"/>
    </texture>
    <bsdf type="mask" id="m">
        <float name="opacity" value="0.9"/>
        <bsdf type="blendbsdf">
            <ref name="weight" id="w"/>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.2"/></bsdf>
            <bsdf type="roughconductor"/>
        </bsdf>
    </bsdf>
    <shape type="rectangle"><ref id="m"/></shape>"#,
        ),
    )
    .unwrap();
    let loaded = load_scene(&path, &LoadOptions::default()).unwrap();
    match &loaded.desc.materials[0].material {
        MaterialDesc::Textured { material, textures } => {
            assert!(matches!(**material, MaterialDesc::Mask { .. }));
            let params: Vec<ColorParam> = textures.iter().map(|t| t.param).collect();
            assert_eq!(params, [ColorParam::Weight]);
        }
        m => panic!("{m:?}"),
    }
    let scene = &loaded.scene;
    let at = |x: f32| -> Bsdf { common::bsdf_from_above(scene, x, 0.5) };
    let weight = |b: Bsdf| match b.kind {
        BsdfKind::Blend(b) => b.weight,
        k => panic!("{k:?}"),
    };
    let (left, right) = (at(-0.5), at(0.5));
    assert_eq!(left.opacity, 0.9);
    let (wl, wr) = (weight(left), weight(right));
    assert!(
        (wl == 0.0 && wr == 1.0) || (wl == 1.0 && wr == 0.0),
        "{wl} {wr}"
    );
    let BsdfKind::Blend(b) = left.kind else {
        unreachable!()
    };
    assert_eq!(b.parts()[0], Bsdf::diffuse(Vec3::splat(0.2)));
}

/// What the XML writer makes of blends (constant and textured weights, nested in a mask,
/// a blend in a blend) reads back the same.
#[test]
fn writer_round_trip() {
    let desc = parse_ron(
        r#"(
        camera: (fov: 40),
        film: (width: 4, height: 4),
        materials: [
            (name: "a", material: Blend(weight: 0.25, bsdfs: (
                Diffuse(reflectance: (0.2, 0.3, 0.4)),
                Blend(weight: 1.0, bsdfs: (Dielectric(), TwoSided(Mask(opacity: 0.3, material: Conductor())))),
            ))),
            (name: "b", material: Textured(
                material: Mask(opacity: 0.5, material: Blend(weight: 0.5, bsdfs: (Null, Plastic()))),
                textures: [
                    (param: Weight, texture: MeshAttribute(name: "face_w")),
                    (param: Opacity, texture: Checkerboard(color0: (0, 0, 0), color1: (1, 1, 1))),
                ],
            )),
        ],
        shapes: [(geometry: Rectangle, material: Some(Ref("a")))],
    )"#,
        Path::new("t.ron"),
    )
    .unwrap();
    let xml = to_mitsuba_xml(&desc, &XmlWriteOptions::default()).unwrap();
    assert!(xml.contains(r#"type="blendbsdf""#), "{xml}");
    let (back, _) = parse_xml(&xml, Path::new("w.xml"), &[]).unwrap();
    assert_eq!(
        back.materials[0].material, desc.materials[0].material,
        "{xml}"
    );
    let (m, mut t) = back.materials[1].material.clone().split_textures();
    let (want_m, mut want_t) = desc.materials[1].material.clone().split_textures();
    assert_eq!(m, want_m, "{xml}");
    t.sort_by_key(|b| b.param.name());
    want_t.sort_by_key(|b| b.param.name());
    assert_eq!(t, want_t, "{xml}");
}

#[test]
fn errors_name_the_line() {
    let err = |body: &str| parse(body).unwrap_err();
    let e = err(r#"<bsdf type="blendbsdf">
        <float name="weight" value="0.5"/>
        <bsdf type="diffuse"/>
        <bsdf type="diffuse"/>
        <bsdf type="diffuse"/>
    </bsdf>"#);
    assert!(
        e.contains("b.xml:7:") && e.contains("exactly two nested bsdfs"),
        "{e}"
    );
    let e = err(r#"<bsdf type="blendbsdf">
        <float name="weight" value="0.5"/>
        <texture name="reflectance" type="checkerboard"/>
        <bsdf type="diffuse"/>
        <bsdf type="diffuse"/>
    </bsdf>"#);
    assert!(
        e.contains("b.xml:5:") && e.contains("no texture parameter 'reflectance'"),
        "{e}"
    );
    // twosided cannot wrap a transmitting blend, as it cannot wrap a dielectric.
    let e = err(r#"<bsdf type="twosided"><bsdf type="blendbsdf">
        <float name="weight" value="0.5"/>
        <bsdf type="diffuse"/>
        <bsdf type="dielectric"/>
    </bsdf></bsdf>"#);
    assert!(e.contains("b.xml:3:") && e.contains("transmitting"), "{e}");
    // Blends nested too deep: refused before the parser recurses further.
    let mut body = String::new();
    for _ in 0..10 {
        body.push_str(
            r#"<bsdf type="blendbsdf"><float name="weight" value="0.5"/><bsdf type="diffuse"/>"#,
        );
    }
    body.push_str(r#"<bsdf type="diffuse"/>"#);
    for _ in 0..10 {
        body.push_str("</bsdf>");
    }
    let e = err(&body);
    assert!(e.contains("nest at most 8 deep"), "{e}");
    // The same in RON.
    let mut ron = String::from("Diffuse(reflectance: (0.5, 0.5, 0.5))");
    for _ in 0..10 {
        ron = format!("Blend(weight: 0.5, bsdfs: (Null, {ron}))");
    }
    let text = format!(
        "(camera: (fov: 40), film: (width: 4, height: 4), materials: [(name: \"m\", material: {ron})], shapes: [(geometry: Rectangle, material: Some(Ref(\"m\")))])"
    );
    let desc = parse_ron(&text, Path::new("t.ron")).unwrap();
    let e = match restir_scene::Scene::build(&desc, Path::new("."), Path::new("t.ron")) {
        Ok(_) => panic!("blends nested 10 deep were built"),
        Err(e) => e.to_string(),
    };
    assert!(e.contains("nest at most 8 deep"), "{e}");
}
