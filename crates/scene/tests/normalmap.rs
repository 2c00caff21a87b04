//! Mitsuba's `normalmap` bsdf in XML: a `rawconstant` or a raw bitmap map, its switches, the
//! nesting rules with `mask` and `twosided`, what the BSDF at a hit holds, the XML writer's
//! round trip, and errors with `file:line`.

use std::path::Path;

use glam::Vec3;
use restir_scene::{
    ColorParam, LoadOptions, MaterialDesc, load_scene, parse_ron,
    xml::{XmlWriteOptions, parse_xml, to_mitsuba_xml},
};
use restir_testkit::TempDir;

mod common;
use common::scene_text;

/// A fresh directory with a 2×1 raw PNG normal map: left texel tilted towards +x, right flat;
/// removed when dropped.
fn dir_with_map(tag: &str) -> TempDir {
    let dir = TempDir::new("normalmap", tag);
    image::RgbImage::from_raw(2, 1, vec![204, 128, 230, 128, 128, 255])
        .unwrap()
        .save(dir.join("n.png"))
        .unwrap();
    dir
}

fn parse(body: &str) -> Result<MaterialDesc, String> {
    parse_xml(&scene_text(body), Path::new("n.xml"), &[])
        .map(|(d, _)| d.materials[0].material.clone())
        .map_err(|e| e.to_string())
}

#[test]
fn rawconstant_map_with_defaults() {
    let m = parse(
        r#"<bsdf type="normalmap" id="m">
        <texture name="normalmap" type="rawconstant"><vector name="value" value="0.5, 0.5, 1.0"/></texture>
        <bsdf type="roughconductor"><string name="material" value="Al"/><float name="alpha_u" value="0.25"/><float name="alpha_v" value="0.05"/></bsdf>
    </bsdf>"#,
    )
    .unwrap();
    match m {
        MaterialDesc::NormalMap {
            normal,
            flip_invalid_normals,
            use_shadowing_function,
            material,
        } => {
            assert_eq!(normal, [0.5, 0.5, 1.0]);
            assert!(flip_invalid_normals && use_shadowing_function);
            assert!(matches!(*material, MaterialDesc::RoughConductor { .. }));
        }
        m => panic!("{m:?}"),
    }
    let m = parse(
        r#"<bsdf type="normalmap" id="m">
        <texture name="normalmap" type="rawconstant"><float name="value" value="0.75"/></texture>
        <boolean name="flip_invalid_normals" value="false"/>
        <boolean name="use_shadowing_function" value="false"/>
        <bsdf type="diffuse"/>
    </bsdf>"#,
    )
    .unwrap();
    assert!(matches!(
        m,
        MaterialDesc::NormalMap {
            normal: [0.75, 0.75, 0.75],
            flip_invalid_normals: false,
            use_shadowing_function: false,
            ..
        }
    ));
}

/// A bitmap map: the raw texel reaches the BSDF at the hit (its normal is `2t − 1`), inside a
/// mask whose opacity is constant, with the nested diffuse's texture beside it.
#[test]
fn bitmap_map_reaches_the_bsdf() {
    let dir = dir_with_map("bitmap");
    let path = dir.join("s.xml");
    std::fs::write(
        &path,
        scene_text(
            r#"    <bsdf type="mask" id="m">
        <float name="opacity" value="0.8"/>
        <bsdf type="normalmap">
            <texture name="normalmap" type="bitmap"><string name="filename" value="n.png"/><boolean name="raw" value="true"/><string name="filter_type" value="nearest"/></texture>
            <bsdf type="twosided"><bsdf type="diffuse"><texture name="reflectance" type="checkerboard"/></bsdf></bsdf>
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
            assert_eq!(params, [ColorParam::Reflectance, ColorParam::NormalMap]);
        }
        m => panic!("{m:?}"),
    }
    let scene = &loaded.scene;
    let at = |x: f32| common::bsdf_from_above(scene, x, 0.0);
    let (left, right) = (at(-0.5), at(0.5));
    assert_eq!(left.opacity, 0.8);
    assert!(left.two_sided);
    let want = (Vec3::new(204.0, 128.0, 230.0) / 255.0 * 2.0 - Vec3::ONE).normalize();
    let n = left.normal_map.expect("normal map").normal();
    assert!((n - want).length() < 1e-3, "{n} {want}");
    let flat = (Vec3::new(128.0, 128.0, 255.0) / 255.0 * 2.0 - Vec3::ONE).normalize();
    assert!((right.normal_map.unwrap().normal() - flat).length() < 1e-3);
}

/// What the XML writer makes of a normal map reads back the same.
#[test]
fn writer_round_trip() {
    let desc = parse_ron(
        r#"(
        camera: (fov: 40),
        film: (width: 4, height: 4),
        materials: [(name: "m", material: NormalMap(normal: (0.6, 0.4, 0.9), flip_invalid_normals: false,
            material: TwoSided(Diffuse(reflectance: (0.2, 0.3, 0.4)))))],
        shapes: [(geometry: Rectangle, material: Some(Ref("m")))],
    )"#,
        Path::new("t.ron"),
    )
    .unwrap();
    let xml = to_mitsuba_xml(&desc, &XmlWriteOptions::default()).unwrap();
    assert!(xml.contains(r#"type="normalmap""#), "{xml}");
    let (back, _) = parse_xml(&xml, Path::new("w.xml"), &[]).unwrap();
    assert_eq!(back.materials[0].material, desc.materials[0].material);
}

#[test]
fn errors_name_the_line() {
    let cases = [
        (
            r#"<bsdf type="normalmap" id="m">
        <bsdf type="diffuse"/>
    </bsdf>"#,
            "n.xml:3",
            "needs its 'normalmap' texture",
        ),
        (
            r#"<bsdf type="normalmap" id="m">
        <texture name="normalmap" type="rawconstant"/>
    </bsdf>"#,
            "n.xml:3",
            "needs one nested <bsdf>",
        ),
        (
            r#"<bsdf type="normalmap" id="m">
        <texture name="normalmap" type="rawconstant"/>
        <bsdf type="mask"><bsdf type="diffuse"/></bsdf>
    </bsdf>"#,
            "n.xml:5",
            "cannot wrap a mask",
        ),
        (
            r#"<bsdf type="twosided" id="m">
        <bsdf type="normalmap"><texture name="normalmap" type="rawconstant"/><bsdf type="diffuse"/></bsdf>
    </bsdf>"#,
            "n.xml:4",
            "cannot wrap a normalmap",
        ),
        (
            r#"<bsdf type="normalmap" id="m">
        <texture name="bumps" type="rawconstant"/>
        <bsdf type="diffuse"/>
    </bsdf>"#,
            "n.xml:4",
            "no texture parameter 'bumps'",
        ),
        (
            r#"<bsdf type="normalmap" id="m">
        <texture name="normalmap" type="rawconstant"/>
        <bsdf type="diffuse"/>
        <bsdf type="diffuse"/>
    </bsdf>"#,
            "n.xml:6",
            "one nested bsdf, not two",
        ),
        (
            r#"<bsdf type="normalmap" id="m">
        <texture name="normalmap" type="rawconstant"><string name="value" value="up"/></texture>
        <bsdf type="diffuse"/>
    </bsdf>"#,
            "n.xml:4",
            "a float or a vector",
        ),
    ];
    for (body, line, what) in cases {
        let e = parse(body).unwrap_err();
        assert!(e.contains(line) && e.contains(what), "{e}");
    }
}
