//! The principled materials in scene files: Mitsuba 3's defaults from XML and RON alike, the
//! errors (an unknown parameter, `eta` with `specular`, a value out of range, a checkerboard
//! colour out of its parameter's range) with file and line, textures on the scalar parameters
//! looked up as Mitsuba's `eval_1` does, and the XML writer's round trip.

use glam::{Vec2, Vec3};
use restir_materials::{BsdfKind, Principled, PrincipledThin, eta_of_specular};
use restir_scene::xml::{XmlWriteOptions, parse_xml, to_mitsuba_xml};
use restir_scene::{Scene, SceneDesc};

/// The scene with `body` after a sensor, parsed from `t.xml`.
fn xml(body: &str) -> Result<SceneDesc, String> {
    let text =
        format!("<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n{body}\n</scene>");
    parse_xml(&text, "t.xml".as_ref(), &[])
        .map(|(d, _)| d)
        .map_err(|e| e.to_string())
}

fn built(d: &SceneDesc) -> Scene {
    Scene::build(d, ".".as_ref(), "t.xml".as_ref()).unwrap()
}

/// The index in the built scene's materials of the description's `k`-th named material (they
/// come last, after the built-in ones).
fn named(s: &Scene, d: &SceneDesc, k: usize) -> usize {
    s.bsdfs().len() - d.materials.len() + k
}

#[test]
fn xml_and_ron_defaults_are_mitsubas() {
    let d = xml(r#"<bsdf type="principled" id="p"/><bsdf type="principledthin" id="t"/>"#).unwrap();
    let ron: SceneDesc = restir_scene::parse_ron(
        r#"(camera: (fov: 45), materials: [(name: "p", material: Principled()), (name: "t", material: PrincipledThin())])"#,
        "t.ron".as_ref(),
    )
    .unwrap();
    assert_eq!(d.materials, ron.materials);
    let s = built(&d);
    let (i, j) = (named(&s, &d, 0), named(&s, &d, 1));
    let BsdfKind::Principled(p) = s.bsdfs()[i].kind else {
        panic!("{:?}", s.bsdfs()[i])
    };
    assert_eq!(p, Principled::default());
    assert!((p.eta - eta_of_specular(0.5)).abs() < 1e-7);
    assert!(!s.bsdfs()[i].kind.transmits());
    let BsdfKind::PrincipledThin(t) = s.bsdfs()[j].kind else {
        panic!("{:?}", s.bsdfs()[j])
    };
    assert_eq!(t, PrincipledThin::default());
}

#[test]
fn mitsubas_adjustments_of_eta_for_transmission() {
    let eta = |body: &str| {
        let d = xml(body).unwrap();
        let s = built(&d);
        match s.bsdfs()[named(&s, &d, 0)].kind {
            BsdfKind::Principled(p) => p.eta,
            k => panic!("{k:?}"),
        }
    };
    let p = |params: &str| format!(r#"<bsdf type="principled" id="p">{params}</bsdf>"#);
    assert_eq!(eta(&p(r#"<float name="eta" value="1"/>"#)), 1.0);
    assert_eq!(
        eta(&p(
            r#"<float name="eta" value="1"/><float name="spec_trans" value="0.5"/>"#
        )),
        1.001
    );
    assert_eq!(eta(&p(r#"<float name="specular" value="0"/>"#)), 1.0);
    assert_eq!(
        eta(&p(
            r#"<float name="specular" value="0"/><texture name="spec_trans" type="checkerboard"/>"#
        )),
        eta_of_specular(1e-3)
    );
}

#[test]
fn bad_principled_materials_are_errors_at_their_line() {
    let cases = [
        (
            r#"<bsdf type="principled"><float name="roughnes" value="0.1"/></bsdf>"#,
            "t.xml:3: bsdf 'principled' has no parameter 'roughnes' (its parameters: base_color,",
        ),
        (
            r#"<bsdf type="principledthin"><float name="metallic" value="0.1"/></bsdf>"#,
            "t.xml:3: bsdf 'principledthin' has no parameter 'metallic'",
        ),
        (
            r#"<bsdf type="principled"><float name="eta" value="1.3"/><float name="specular" value="0.3"/></bsdf>"#,
            "t.xml:3: bsdf 'principled': give either eta or specular, not both",
        ),
        (
            r#"<bsdf type="principled"><float name="metallic" value="1.5"/></bsdf>"#,
            "t.xml:3: bsdf 'principled': metallic 1.5 must lie in [0, 1]",
        ),
        (
            r#"<bsdf type="principledthin"><float name="diff_trans" value="2.5"/></bsdf>"#,
            "t.xml:3: bsdf 'principledthin': diff_trans 2.5 must lie in [0, 2]",
        ),
        (
            r#"<bsdf type="principled"><texture name="sheen" type="checkerboard"><float name="color1" value="1.4"/></texture></bsdf>"#,
            "t.xml:3: bsdf 'principled': texture for 'sheen': colour [1.4, 1.4, 1.4] must lie in [0, 1]",
        ),
        (
            r#"<bsdf type="principled"><texture name="eta" type="checkerboard"/></bsdf>"#,
            "t.xml:3: bsdf 'principled': 'eta' cannot be a texture",
        ),
        (
            r#"<bsdf type="twosided"><bsdf type="principledthin"/></bsdf>"#,
            "t.xml:3: bsdf 'twosided': twosided cannot wrap a transmitting material",
        ),
        (
            r#"<bsdf type="twosided"><bsdf type="principled"><texture name="spec_trans" type="checkerboard"/></bsdf></bsdf>"#,
            "t.xml:3: bsdf 'twosided': twosided cannot wrap a transmitting material",
        ),
        (
            r#"<bsdf type="principled"><float name="main_specular_sampling_rate" value="-1"/></bsdf>"#,
            "t.xml:3: bsdf 'principled': main_specular_sampling_rate -1 must be a non-negative number",
        ),
    ];
    for (body, want) in cases {
        let e = xml(body).expect_err(body);
        assert!(e.contains(want), "{body}:\n got  {e}\n want {want}");
    }
    // A twosided principled without transmission is allowed (and mirrored), as in Mitsuba.
    let d = xml(r#"<bsdf type="twosided" id="m"><bsdf type="principled"/></bsdf>"#).unwrap();
    let s = built(&d);
    assert!(s.bsdfs()[named(&s, &d, 0)].two_sided);
    // diff_trans up to 2 from a checkerboard (Mitsuba's test scene gives 1.4).
    xml(r#"<bsdf type="principledthin" id="m"><texture name="diff_trans" type="checkerboard"><float name="color1" value="1.4"/></texture></bsdf>"#)
        .unwrap();
}

/// A checkerboard on a scalar parameter is read as Mitsuba's `eval_1` reads it (its colours
/// the other way round from its `eval`), on the base colour as its `eval`.
#[test]
fn textured_parameters_are_looked_up_per_point() {
    let d = xml(
        r#"<bsdf type="principledthin" id="m">
            <texture name="base_color" type="checkerboard"><rgb name="color0" value="0.1,0.2,0.3"/><rgb name="color1" value="0.9,0.8,0.7"/></texture>
            <texture name="diff_trans" type="checkerboard"><float name="color0" value="0.4"/><float name="color1" value="1.4"/></texture>
            <texture name="sheen" type="checkerboard"><float name="color0" value="0.1"/><float name="color1" value="0.8"/></texture>
        </bsdf>
        <shape type="rectangle"><ref id="m"/></shape>"#,
    )
    .unwrap();
    let s = built(&d);
    let m = named(&s, &d, 0) as u32;
    // u, v both in the lower half: eval gives color0, eval_1 gives color1.
    let at = |uv| restir_scene::TexturePoint {
        uv,
        ..Default::default()
    };
    let thin = |uv: Vec2| match s.bsdf_at(m, &at(uv)).kind {
        BsdfKind::PrincipledThin(t) => t,
        k => panic!("{k:?}"),
    };
    let t = thin(Vec2::new(0.25, 0.25));
    assert_eq!(t.base_color, Vec3::new(0.1, 0.2, 0.3));
    assert!((t.diff_trans - 1.4).abs() < 1e-6, "{}", t.diff_trans);
    assert!((t.sheen - 0.8).abs() < 1e-6);
    let t = thin(Vec2::new(0.75, 0.25));
    assert_eq!(t.base_color, Vec3::new(0.9, 0.8, 0.7));
    assert!((t.diff_trans - 0.4).abs() < 1e-6);
    assert!((t.sheen - 0.1).abs() < 1e-6);
    // The constants stay.
    assert_eq!(t.eta, 1.5);
    assert_eq!(t.roughness, 0.5);
}

/// RON → Mitsuba XML → description: the same materials, constant or textured (textures listed
/// in the order the writer writes the parameters).
#[test]
fn xml_writer_round_trips() {
    let ron = r#"(
        camera: (fov: 45),
        materials: [
            (name: "a", material: Principled(base_color: (0.2, 0.8, 0.1), roughness: 0.15, metallic: 0.3,
                clearcoat: 0.4, clearcoat_gloss: 0.2, sheen: 0.5, sheen_tint: 0.1, spec_tint: 0.2,
                flatness: 0.3, anisotropic: 0.6, specular: Some(0.7))),
            (name: "b", material: Principled(spec_trans: 0.4, eta: Some(1.33))),
            (name: "c", material: PrincipledThin(base_color: (0.7, 0.1, 0.1), eta: 1.33, diff_trans: 1.2)),
            (name: "d", material: Textured(material: PrincipledThin(eta: 1.33), textures: [
                (param: SpecTrans, texture: Checkerboard(color0: (0.2, 0.2, 0.2), color1: (0.8, 0.8, 0.8))),
                (param: DiffTrans, texture: Checkerboard(color0: (0.4, 0.4, 0.4), color1: (1.4, 1.4, 1.4))),
            ])),
            (name: "e", material: Textured(material: Principled(), textures: [
                (param: BaseColor, texture: Checkerboard(color0: (0.7, 0.2, 0.7), color1: (0.1, 0.3, 0.1))),
                (param: Metallic, texture: Checkerboard(color0: (0.7, 0.7, 0.7), color1: (0.1, 0.1, 0.1))),
            ])),
        ],
    )"#;
    let desc = restir_scene::parse_ron(ron, "t.ron".as_ref()).unwrap();
    let text = to_mitsuba_xml(&desc, &XmlWriteOptions::default()).unwrap();
    assert!(
        text.contains(r#"<bsdf type="principledthin" id="c">"#),
        "{text}"
    );
    let (back, warnings) = parse_xml(&text, "t.xml".as_ref(), &[]).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(desc.materials, back.materials, "{text}");
}
