//! How the XML importer finds files, as Mitsuba 3 does: `<path>` search folders, `<include>`d
//! scene files with their `<default>`s, and relative names resolved through both. (The errors
//! are cases of `tests/bad_scenes/`.)

use std::path::Path;

use restir_scene::{GeometryDesc, LightDesc, LoadOptions, load_desc, load_scene};
use restir_testkit::TempDir;

/// A fresh directory tree: `scene/`, `scene/parts/`, `common/meshes/`, `common/textures/`,
/// removed when dropped.
fn tree(tag: &str) -> TempDir {
    let root = TempDir::new("xml-files", tag);
    for d in ["scene/parts", "common/meshes", "common/textures"] {
        std::fs::create_dir_all(root.join(d)).unwrap();
    }
    std::fs::write(
        root.join("common/meshes/tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    image::RgbImage::from_raw(1, 1, vec![10, 20, 30])
        .unwrap()
        .save(root.join("common/textures/t.png"))
        .unwrap();
    root
}

fn write(path: &Path, text: &str) {
    std::fs::write(path, text).unwrap();
}

/// `<path>` is relative to the scene file; meshes, textures and included files are found through
/// it; the included file's `<default>`s apply where nothing else set the variable, and `-D`
/// overrides them.
#[test]
fn path_and_include_resolve_like_mitsuba() {
    let root = tree("resolve");
    write(
        &root.join("scene/parts/camera.xml"),
        r#"<scene version="3.0.0">
    <default name="spp" value="128"/>
    <default name="width" value="24"/>
    <sensor type="perspective">
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="$width"/><integer name="height" value="16"/>
        </film>
    </sensor>
    <shape type="obj">
        <string name="filename" value="meshes/tri.obj"/>
        <bsdf type="diffuse">
            <texture type="bitmap" name="reflectance">
                <string name="filename" value="textures/t.png"/>
                <string name="wrap_mode" value="mirror"/>
                <string name="filter_type" value="nearest"/>
            </texture>
        </bsdf>
    </shape>
</scene>"#,
    );
    let scene = root.join("scene/main.xml");
    write(
        &scene,
        r#"<scene version="3.0.0">
    <path value="../common"/>
    <default name="width" value="32"/>
    <emitter type="constant"/>
    <include filename="parts/camera.xml"/>
</scene>"#,
    );
    let (desc, warnings) = load_desc(&scene, &[("spp".into(), "7".into())]).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    // `-D spp` beats the included default; the including file's `width` beats the included one.
    assert_eq!(desc.spp, 7);
    assert_eq!((desc.film.width, desc.film.height), (32, 16));
    assert!(matches!(desc.lights[0], LightDesc::Constant { .. }));
    let GeometryDesc::Obj { filename } = &desc.shapes[0].geometry else {
        panic!("{:?}", desc.shapes[0].geometry)
    };
    assert!(Path::new(filename).is_absolute(), "{filename}");
    assert!(filename.ends_with("common/meshes/tri.obj"), "{filename}");
    // The shape's line is in the included file.
    assert!(desc.shapes[0].location.file.ends_with("parts/camera.xml"));
    assert_eq!(desc.shapes[0].location.line, 10);
    // And the whole scene builds from another working directory's point of view.
    let loaded = load_scene(&scene, &LoadOptions::default()).unwrap();
    assert_eq!(loaded.scene.camera.resolution(), (32, 16));
}

/// A name beside the scene file stays as written (so written scenes keep relative names); the
/// newest `<path>` folder wins over an older one.
#[test]
fn names_beside_the_scene_stay_relative_and_newer_paths_win() {
    let root = tree("order");
    std::fs::create_dir_all(root.join("other/meshes")).unwrap();
    std::fs::copy(
        root.join("common/meshes/tri.obj"),
        root.join("other/meshes/tri.obj"),
    )
    .unwrap();
    std::fs::create_dir_all(root.join("scene/meshes")).unwrap();
    std::fs::copy(
        root.join("common/meshes/tri.obj"),
        root.join("scene/meshes/own.obj"),
    )
    .unwrap();
    let scene = root.join("scene/main.xml");
    write(
        &scene,
        r#"<scene version="3.0.0">
    <path value="../common"/>
    <path value="../other"/>
    <sensor type="perspective"/>
    <shape type="obj"><string name="filename" value="meshes/tri.obj"/></shape>
    <shape type="obj"><string name="filename" value="meshes/own.obj"/></shape>
</scene>"#,
    );
    let (desc, _) = load_desc(&scene, &[]).unwrap();
    let names: Vec<&str> = desc
        .shapes
        .iter()
        .map(|s| match &s.geometry {
            GeometryDesc::Obj { filename } => filename.as_str(),
            g => panic!("{g:?}"),
        })
        .collect();
    assert!(names[0].ends_with("other/meshes/tri.obj"), "{names:?}");
    assert_eq!(names[1], "meshes/own.obj");
}

/// A sensor's `<sampler>` decides where the path tracer's numbers come from: `independent` (and
/// no sampler, Mitsuba's default) is independent, the stratified and low-discrepancy samplers are
/// Owen-scrambled Sobol, whether the `<integrator>` comes before or after the sensor; the XML
/// writer says it back.
#[test]
fn samplers_choose_the_path_tracers_numbers() {
    use restir_scene::SamplerKind;
    use restir_scene::xml::{XmlWriteOptions, to_mitsuba_xml};
    let root = tree("samplers");
    let cases = [
        (Some("independent"), SamplerKind::Independent),
        (None, SamplerKind::Independent),
        (Some("ldsampler"), SamplerKind::Sobol),
        (Some("stratified"), SamplerKind::Sobol),
        (Some("multijitter"), SamplerKind::Sobol),
        (Some("orthogonal"), SamplerKind::Sobol),
    ];
    for (sampler, kind) in cases {
        for integrator_first in [false, true] {
            let sampler_xml = sampler.map_or(String::new(), |s| {
                format!(r#"<sampler type="{s}"><integer name="sample_count" value="4"/></sampler>"#)
            });
            let integrator =
                r#"<integrator type="path"><integer name="max_depth" value="3"/></integrator>"#;
            let sensor = format!(r#"<sensor type="perspective">{sampler_xml}</sensor>"#);
            let body = if integrator_first {
                format!("{integrator}{sensor}")
            } else {
                format!("{sensor}{integrator}")
            };
            let scene = root.join("s.xml");
            write(&scene, &format!(r#"<scene version="3.0.0">{body}</scene>"#));
            let (desc, warnings) = load_desc(&scene, &[]).unwrap();
            assert!(warnings.is_empty(), "{sampler:?}: {warnings:?}");
            assert_eq!(desc.integrator.sampler, kind, "{sampler:?}");
            assert_eq!(desc.integrator.max_depth, 3);
            let written = to_mitsuba_xml(&desc, &XmlWriteOptions::default()).unwrap();
            write(&scene, &written);
            let (back, _) = load_desc(&scene, &[]).unwrap();
            assert_eq!(back.integrator.sampler, kind, "written back: {sampler:?}");
        }
    }
}
