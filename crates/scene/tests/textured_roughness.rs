//! Microfacet roughness as a texture (`alpha`, `alpha_u`, `alpha_v` of `roughconductor` and
//! `roughdielectric`), read as Mitsuba's scalar lookup (`eval_1`), and the errors around it.

use std::path::Path;

use glam::Vec3;
use restir_geometry::Ray;
use restir_materials::BsdfKind;
use restir_scene::{
    ColorParam, LoadOptions, MaterialDesc, load_scene,
    xml::{XmlWriteOptions, parse_xml, to_mitsuba_xml},
};
use restir_testkit::TempDir;

mod common;
use common::scene_text;

const CHECKER_U: &str = r#"<texture name="alpha_u" type="checkerboard">
                <float name="color0" value="0.05"/><float name="color1" value="0.3"/></texture>"#;

/// `alpha_u` a checkerboard, `alpha_v` a value: the rough conductor at a hit has the texture's
/// roughness along `u` with Mitsuba's scalar checkerboard (`color0` where exactly one of the
/// fractional parts of `u`, `v` exceeds ½) and the constant along `v`.
#[test]
fn checkerboard_alpha_u_reaches_the_bsdf() {
    let dir = TempDir::new("alpha", "checkerboard");
    let path = dir.join("s.xml");
    std::fs::write(
        &path,
        scene_text(&format!(
            r#"    <bsdf type="roughconductor" id="m">
        {CHECKER_U}
        <float name="alpha_v" value="0.2"/>
    </bsdf>
    <shape type="rectangle"><ref id="m"/></shape>"#
        )),
    )
    .unwrap();
    let loaded = load_scene(&path, &LoadOptions::default()).unwrap();
    let scene = &loaded.scene;
    let alphas = |x: f32, y: f32| {
        let si = scene
            .intersect(&Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z))
            .expect("hit");
        match scene.bsdf(&si).kind {
            BsdfKind::RoughConductor { microfacet, .. } => {
                ((microfacet.alpha_u, microfacet.alpha_v), si.uv)
            }
            k => panic!("{k:?}"),
        }
    };
    for (x, y) in [(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)] {
        let ((au, av), uv) = alphas(x, y);
        let one_above = (uv.x.fract() > 0.5) != (uv.y.fract() > 0.5);
        assert_eq!(au, if one_above { 0.05 } else { 0.3 }, "uv {uv}");
        assert_eq!(av, 0.2);
    }
}

#[test]
fn isotropic_alpha_texture_and_round_trip() {
    let body = r#"<bsdf type="roughdielectric" id="m">
        <texture name="alpha" type="checkerboard"><float name="color0" value="0.1"/><float name="color1" value="0.4"/></texture>
    </bsdf>"#;
    let (desc, _) = parse_xml(&scene_text(body), Path::new("a.xml"), &[]).unwrap();
    match &desc.materials[0].material {
        MaterialDesc::Textured { material, textures } => {
            assert!(matches!(**material, MaterialDesc::RoughDielectric { .. }));
            assert_eq!(textures[0].param, ColorParam::Alpha);
        }
        m => panic!("{m:?}"),
    }
    let xml = to_mitsuba_xml(&desc, &XmlWriteOptions::default()).unwrap();
    assert!(xml.contains(r#"type="checkerboard" name="alpha""#), "{xml}");
    let (back, _) = parse_xml(&xml, Path::new("w.xml"), &[]).unwrap();
    assert_eq!(back.materials[0].material, desc.materials[0].material);
}

#[test]
fn errors_name_the_line() {
    let cases = [
        (
            format!(r#"<bsdf type="roughconductor" id="m">{CHECKER_U}</bsdf>"#),
            "a.xml:3",
            "alpha_u and alpha_v must be given together",
        ),
        (
            r#"<bsdf type="roughplastic" id="m">
        <texture name="alpha" type="checkerboard"/>
    </bsdf>"#
                .to_string(),
            "a.xml:4",
            "has no parameter 'alpha'",
        ),
        (
            r#"<bsdf type="conductor" id="m">
        <texture name="alpha" type="checkerboard"/>
    </bsdf>"#
                .to_string(),
            "a.xml:4",
            "has no parameter 'alpha'",
        ),
        (
            format!(
                r#"<bsdf type="roughconductor" id="m">{CHECKER_U}<float name="alpha_v" value="0.1"/><float name="alpha" value="0.1"/></bsdf>"#
            ),
            "a.xml:3",
            "either alpha or alpha_u/alpha_v",
        ),
        (
            r#"<bsdf type="roughconductor" id="m">
        <texture name="eta" type="checkerboard"/>
    </bsdf>"#
                .to_string(),
            "a.xml:4",
            "'eta' cannot be a texture",
        ),
    ];
    for (body, line, what) in cases {
        let e = parse_xml(&scene_text(&body), Path::new("a.xml"), &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains(line) && e.contains(what), "{e}");
    }
}
