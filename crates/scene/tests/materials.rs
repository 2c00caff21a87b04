//! The Mitsuba material plugins in the XML importer and the RON format: defaults as Mitsuba 3,
//! the built BSDF, and errors with `file:line` for bad values.

use restir_materials::{BsdfKind, Distribution};
use restir_scene::xml::parse_xml;
use restir_scene::{MaterialDesc, MicrofacetDesc, Scene, SceneDesc};

fn scene_with(bsdf: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
    {bsdf}
    <shape type="sphere"><ref id="m"/></shape>
</scene>"#
    )
}

fn load(bsdf: &str) -> Result<(SceneDesc, Vec<String>), String> {
    let text = scene_with(bsdf);
    let (desc, warnings) = parse_xml(&text, "t.xml".as_ref(), &[]).map_err(|e| e.to_string())?;
    Ok((desc, warnings.iter().map(|w| w.to_string()).collect()))
}

fn material(bsdf: &str) -> MaterialDesc {
    let (desc, _) = load(bsdf).unwrap_or_else(|e| panic!("{bsdf}: {e}"));
    desc.materials[0].material.clone()
}

fn built(bsdf: &str) -> BsdfKind {
    let (desc, _) = load(bsdf).unwrap();
    let scene = Scene::build(&desc, ".".as_ref(), "t.xml".as_ref()).unwrap();
    let i = scene.shape_bsdf()[0] as usize;
    scene.bsdfs()[i].kind
}

fn error(bsdf: &str) -> String {
    match load(bsdf) {
        Ok(_) => panic!("{bsdf}: accepted"),
        Err(e) => e,
    }
}

#[test]
fn defaults_are_mitsubas() {
    match material(r#"<bsdf type="roughconductor" id="m"/>"#) {
        MaterialDesc::RoughConductor {
            ior,
            specular_reflectance,
            roughness,
        } => {
            assert_eq!(ior.material, None);
            assert_eq!(specular_reflectance, [1.0; 3]);
            assert_eq!(roughness.distribution, MicrofacetDesc::Beckmann);
            assert_eq!(roughness.alpha, 0.1);
        }
        m => panic!("{m:?}"),
    }
    match built(r#"<bsdf type="conductor" id="m"/>"#) {
        BsdfKind::Conductor { eta, k, .. } => {
            assert_eq!((eta.x, k.x), (0.0, 1.0), "default is the perfect mirror");
        }
        k => panic!("{k:?}"),
    }
    match built(r#"<bsdf type="dielectric" id="m"/>"#) {
        BsdfKind::Dielectric { eta, .. } => assert!((eta - 1.5046 / 1.000_277).abs() < 1e-6),
        k => panic!("{k:?}"),
    }
    match built(
        r#"<bsdf type="thindielectric" id="m"><string name="int_ior" value="water"/>
           <rgb name="specular_transmittance" value="0.5, 0.6, 0.7"/></bsdf>"#,
    ) {
        BsdfKind::ThinDielectric {
            eta,
            specular_reflectance,
            specular_transmittance,
        } => {
            assert!((eta - 1.333 / 1.000_277).abs() < 1e-6);
            assert_eq!(specular_reflectance, glam::Vec3::ONE);
            assert_eq!(specular_transmittance, glam::Vec3::new(0.5, 0.6, 0.7));
        }
        k => panic!("{k:?}"),
    }
    match built(r#"<bsdf type="roughplastic" id="m"/>"#) {
        BsdfKind::RoughPlastic(p) => {
            assert!((p.eta - 1.49 / 1.000_277).abs() < 1e-6);
            assert_eq!(p.microfacet.distribution, Distribution::Beckmann);
            assert!((p.microfacet.alpha_u - 0.1).abs() < 1e-7);
            // ρd = 0.5 and ks = 1: w_s = 1/1.5.
            assert!((p.specular_weight - 2.0 / 3.0).abs() < 1e-6);
        }
        k => panic!("{k:?}"),
    }
    assert!(matches!(
        built(r#"<bsdf type="plastic" id="m"/>"#),
        BsdfKind::Plastic(_)
    ));
    assert!(matches!(
        built(r#"<bsdf type="null" id="m"/>"#),
        BsdfKind::Null
    ));
}

#[test]
fn parameters_and_names() {
    match built(
        r#"<bsdf type="roughconductor" id="m"><string name="material" value="Au"/>
           <string name="distribution" value="ggx"/><float name="alphaU" value="0.05"/>
           <float name="alpha_v" value="0.3"/></bsdf>"#,
    ) {
        BsdfKind::RoughConductor {
            eta, microfacet, ..
        } => {
            assert!((eta.x - 0.143_036).abs() < 1e-6);
            assert_eq!(microfacet.distribution, Distribution::Ggx);
            assert!((microfacet.alpha_u - 0.05).abs() < 1e-7);
            assert!((microfacet.alpha_v - 0.3).abs() < 1e-7);
        }
        k => panic!("{k:?}"),
    }
    match built(
        r#"<bsdf type="roughdielectric" id="m"><string name="int_ior" value="water"/>
           <float name="extIOR" value="1.0"/><float name="alpha" value="0.3"/></bsdf>"#,
    ) {
        BsdfKind::RoughDielectric { eta, .. } => assert!((eta - 1.333).abs() < 1e-6),
        k => panic!("{k:?}"),
    }
    match built(
        r#"<bsdf type="conductor" id="m"><rgb name="eta" value="0.2, 0.9, 1.1"/>
           <rgb name="k" value="3.9, 2.4, 2.1"/><rgb name="specular_reflectance" value="0.5"/></bsdf>"#,
    ) {
        BsdfKind::Conductor {
            eta,
            k,
            specular_reflectance,
        } => {
            assert_eq!((eta.y, k.z, specular_reflectance.x), (0.9, 2.1, 0.5));
        }
        k => panic!("{k:?}"),
    }
    match material(
        r#"<bsdf type="plastic" id="m"><rgb name="diffuse_reflectance" value="0.1, 0.2, 0.3"/>
           <boolean name="nonlinear" value="true"/><string name="int_ior" value="diamond"/></bsdf>"#,
    ) {
        MaterialDesc::Plastic {
            int_ior,
            diffuse_reflectance,
            nonlinear,
            ..
        } => {
            assert_eq!(
                (int_ior, diffuse_reflectance, nonlinear),
                (2.419, [0.1, 0.2, 0.3], true)
            );
        }
        m => panic!("{m:?}"),
    }
    // sample_visible=false: accepted with a warning.
    let (_, w) = load(r#"<bsdf type="roughconductor" id="m"><boolean name="sample_visible" value="false"/></bsdf>"#).unwrap();
    assert!(w.iter().any(|w| w.contains("sample_visible")), "{w:?}");
    // Unknown properties stay warnings.
    let (_, w) =
        load(r#"<bsdf type="dielectric" id="m"><float name="bogus" value="1"/></bsdf>"#).unwrap();
    assert!(
        w.iter()
            .any(|w| w.contains("bogus") && w.contains("t.xml:3")),
        "{w:?}"
    );
}

#[test]
fn bad_values_are_errors_with_file_and_line() {
    let cases = [
        (
            r#"<bsdf type="roughconductor" id="m">
            <float name="alpha" value="-0.1"/></bsdf>"#,
            "t.xml:4",
            "alpha",
        ),
        (
            r#"<bsdf type="roughconductor" id="m">
            <string name="material" value="Pt"/></bsdf>"#,
            "t.xml:4",
            "unknown conductor material 'Pt'",
        ),
        (
            r#"<bsdf type="conductor" id="m"><string name="material" value="Au"/>
            <rgb name="eta" value="1"/></bsdf>"#,
            "t.xml:3",
            "not both",
        ),
        (
            r#"<bsdf type="roughdielectric" id="m">
            <float name="alpha" value="nan"/></bsdf>"#,
            "t.xml:4",
            "finite",
        ),
        (
            r#"<bsdf type="dielectric" id="m">
            <string name="int_ior" value="unobtainium"/></bsdf>"#,
            "t.xml:4",
            "unknown int_ior",
        ),
        (
            r#"<bsdf type="dielectric" id="m">
            <float name="int_ior" value="-1.5"/></bsdf>"#,
            "t.xml:4",
            "positive",
        ),
        (
            r#"<bsdf type="roughconductor" id="m"><float name="alpha_u" value="0.1"/></bsdf>"#,
            "t.xml:3",
            "together",
        ),
        (
            r#"<bsdf type="roughplastic" id="m"><float name="alpha_u" value="0.1"/><float name="alpha_v" value="0.1"/></bsdf>"#,
            "t.xml:3",
            "anisotropic",
        ),
        (
            r#"<bsdf type="roughplastic" id="m"><float name="int_ior" value="1.5"/><float name="ext_ior" value="1.5"/></bsdf>"#,
            "t.xml:3",
            "differ",
        ),
        (
            r#"<bsdf type="roughconductor" id="m"><string name="distribution" value="phong"/></bsdf>"#,
            "t.xml:3",
            "distribution",
        ),
        (
            r#"<bsdf type="twosided" id="m"><bsdf type="thindielectric"/></bsdf>"#,
            "t.xml:3",
            "twosided",
        ),
        (
            r#"<bsdf type="thindielectric" id="m"><rgb name="specular_transmittance" value="1.5"/></bsdf>"#,
            "t.xml:3",
            "[0, 1]",
        ),
        (
            r#"<bsdf type="twosided" id="m"><bsdf type="dielectric"/></bsdf>"#,
            "t.xml:3",
            "twosided",
        ),
        (
            r#"<bsdf type="plastic" id="m"><rgb name="diffuse_reflectance" value="1.5"/></bsdf>"#,
            "t.xml:3",
            "[0, 1]",
        ),
        (
            r#"<bsdf type="conductor" id="m"><rgb name="k" value="-1"/></bsdf>"#,
            "t.xml:3",
            "negative",
        ),
    ];
    for (bsdf, at, what) in cases {
        let e = error(bsdf);
        assert!(
            e.starts_with(at) && e.contains(what),
            "{bsdf}: got '{e}', want {at} … {what}"
        );
    }
}

#[test]
fn ron_materials() {
    let ron = r#"(
        camera: (fov: 40),
        film: (width: 4, height: 4),
        materials: [
            (name: "gold", material: RoughConductor(ior: (material: Some("Au")), roughness: (distribution: ggx, alpha: 0.2))),
            (name: "glass", material: Dielectric()),
            (name: "pp", material: RoughPlastic(diffuse_reflectance: (0.2, 0.5, 0.8))),
            (name: "mirror", material: TwoSided(Conductor())),
        ],
        shapes: [(geometry: Sphere(center: (0, 0, 0), radius: 1), material: Some(Ref("gold")))],
    )"#;
    let desc = restir_scene::parse_ron(ron, "t.ron".as_ref()).unwrap();
    let scene = Scene::build(&desc, ".".as_ref(), "t.ron".as_ref()).unwrap();
    assert!(scene.features.has_glossy_lobes && !scene.features.has_delta_lobes);
    let bad = ron.replace("alpha: 0.2", "alpha: 0.2, roughnes: 1");
    assert!(
        restir_scene::parse_ron(&bad, "t.ron".as_ref()).is_err(),
        "unknown fields are errors"
    );
    let bad = ron.replace("Some(\"Au\")", "Some(\"Fe\")");
    let desc = restir_scene::parse_ron(&bad, "t.ron".as_ref()).unwrap();
    let e = Scene::build(&desc, ".".as_ref(), "t.ron".as_ref())
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown conductor material 'Fe'"), "{e}");
}

/// Editing a built scene's materials keeps its feature summary true: swapping a material for
/// glass or a rough conductor sets the lobe flags, giving a shape a new material or swapping a
/// textured one for a constant one updates them, and a bad index is an error naming the range.
#[test]
fn material_edits_keep_the_feature_summary() {
    use glam::Vec3;
    use restir_materials::Bsdf;
    let ron = r#"(
        camera: (fov: 40, to_world: [LookAt(origin: (0, 0, 4), target: (0, 0, 0), up: (0, 1, 0))]),
        film: (width: 8, height: 8, filter: Box),
        shapes: [
            (geometry: Rectangle, material: Some(Inline(Diffuse(reflectance: (0.5, 0.5, 0.5))))),
            (geometry: Sphere(center: (0, 0, 2), radius: 0.1), emission: Some((10, 10, 10))),
        ],
    )"#;
    let desc = restir_scene::parse_ron(ron, "edit.ron".as_ref()).unwrap();
    let mut scene = Scene::build(&desc, ".".as_ref(), "edit.ron".as_ref()).unwrap();
    let f = scene.features;
    assert!(!f.has_delta_lobes && !f.has_glossy_lobes && !f.has_textures);
    let wall = scene.shape_bsdf()[0];

    scene
        .set_material(wall, Bsdf::dielectric(1.5, Vec3::ONE, Vec3::ONE))
        .unwrap();
    assert!(scene.features.has_delta_lobes && !scene.features.has_glossy_lobes);
    let gold = scene.add_material(Bsdf::rough_conductor(
        Vec3::splat(0.2),
        Vec3::splat(3.0),
        Vec3::ONE,
        restir_materials::Microfacet::new(Distribution::Ggx, 0.3),
    ));
    assert!(!scene.features.has_glossy_lobes, "no shape uses it yet");
    scene.set_shape_material(0, gold).unwrap();
    assert!(scene.features.has_glossy_lobes && !scene.features.has_delta_lobes);
    scene.set_shape_material(0, wall).unwrap();
    assert!(scene.features.has_delta_lobes && !scene.features.has_glossy_lobes);

    // The summary after the edits is the one a build of the edited scene would decide.
    let diffuse = scene.add_material(Bsdf::diffuse(Vec3::splat(0.5)));
    scene.set_shape_material(0, diffuse).unwrap();
    let rebuilt = Scene::build(&desc, ".".as_ref(), "edit.ron".as_ref()).unwrap();
    assert_eq!(scene.features, rebuilt.features);

    let n = scene.bsdfs().len();
    assert_eq!(
        scene
            .set_material(n as u32, Bsdf::diffuse(Vec3::ONE))
            .unwrap_err()
            .to_string(),
        format!(
            "no material {n}: the scene has {n} (indices 0 to {})",
            n - 1
        )
    );
    assert_eq!(
        scene.set_shape_material(2, 0).unwrap_err().to_string(),
        "no shape 2: the scene has 2 (indices 0 to 1)"
    );
    assert!(scene.set_shape_material(0, n as u32 + 5).is_err());
}

#[test]
fn lajollas_roughness_is_its_ggx_alpha_squared() {
    // Lajolla's files give rough plastics and dielectrics a `roughness` r: GGX with α = r²
    // (r clamped to [0.01, 1]), where Mitsuba's give `alpha`.
    let rough = |bsdf: &str| match load(bsdf) {
        Ok((desc, warnings)) => {
            assert!(warnings.is_empty(), "{bsdf}: {warnings:?}");
            match &desc.materials[0].material {
                MaterialDesc::RoughPlastic { roughness, .. }
                | MaterialDesc::RoughDielectric { roughness, .. } => roughness.clone(),
                m => panic!("{m:?}"),
            }
        }
        Err(e) => panic!("{bsdf}: {e}"),
    };
    let r = rough(
        r#"<bsdf type="roughplastic" id="m"><rgb name="diffuseReflectance" value="0.8 0.6 0.2"/><float name="roughness" value="0.3"/></bsdf>"#,
    );
    assert_eq!(r.distribution, MicrofacetDesc::Ggx);
    assert!((r.alpha - 0.09).abs() < 1e-7, "{}", r.alpha);
    let r = rough(
        r#"<bsdf type="roughdielectric" id="m"><float name="roughness" value="0.001"/></bsdf>"#,
    );
    assert!(
        (r.alpha - 1e-4).abs() < 1e-9,
        "clamped to 0.01: {}",
        r.alpha
    );
    let r = rough(
        r#"<bsdf type="roughplastic" id="m"><string name="distribution" value="beckmann"/><float name="roughness" value="0.5"/></bsdf>"#,
    );
    assert_eq!(
        r.distribution,
        MicrofacetDesc::Beckmann,
        "a named distribution stays"
    );
    assert!((r.alpha - 0.25).abs() < 1e-7);
    // Without it, Mitsuba's `alpha` and Beckmann, as before.
    let r = rough(r#"<bsdf type="roughplastic" id="m"><float name="alpha" value="0.3"/></bsdf>"#);
    assert_eq!((r.distribution, r.alpha), (MicrofacetDesc::Beckmann, 0.3));
    // A conductor has no Lajolla roughness: the property stays unknown (a warning).
    let (_, warnings) =
        load(r#"<bsdf type="roughconductor" id="m"><float name="roughness" value="0.3"/></bsdf>"#)
            .unwrap();
    assert!(
        warnings.iter().any(|w| w.contains("roughness")),
        "{warnings:?}"
    );
    for (bsdf, what) in [
        (
            r#"<bsdf type="roughplastic" id="m"><float name="alpha" value="0.1"/><float name="roughness" value="0.3"/></bsdf>"#,
            "not both",
        ),
        (
            r#"<bsdf type="roughplastic" id="m"><float name="roughness" value="-0.3"/></bsdf>"#,
            "non-negative",
        ),
        (
            r#"<bsdf type="roughdielectric" id="m"><texture type="checkerboard" name="roughness"/></bsdf>"#,
            "textured roughness",
        ),
    ] {
        let e = error(bsdf);
        assert!(
            e.starts_with("t.xml:3") && e.contains(what),
            "{bsdf}: got '{e}', want t.xml:3 … {what}"
        );
    }
}
