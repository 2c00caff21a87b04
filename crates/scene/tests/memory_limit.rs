//! `--max-memory` (`LoadOptions::max_memory`) covers a scene's images, meshes and light tables
//! together: every image is counted from its header before the first is decoded, each mesh
//! before it is built, each emitter's tables before they are made, and the one that crosses the
//! limit is named where the scene declares it.

use std::path::Path;

use restir_scene::desc::limits;
use restir_scene::{LoadOptions, load_scene};
use restir_testkit::TempDir;

fn temp_dir(tag: &str) -> TempDir {
    TempDir::new("memlimit", tag)
}

fn load(scene: &Path, max_memory: Option<u64>) -> Result<(), String> {
    let options = LoadOptions {
        max_memory,
        ..LoadOptions::default()
    };
    load_scene(scene, &options)
        .map(|_| ())
        .map_err(|e| e.to_string())
}

const HEAD: &str = "(camera: (fov: 40, to_world: [LookAt(origin: (0, 0, 5), target: (0, 0, 0), \
                    up: (0, 1, 0))]), film: (width: 8, height: 8, filter: Box), spp: 1, \
                    integrator: (kind: \"path\", max_depth: 2), ";

/// Three 512² textures: each alone is far below the limit, the three together are not, and the
/// third one named in the error is the one that crosses it.
#[test]
fn textures_are_bounded_together() {
    let dir = temp_dir("tex");
    let mut materials = String::new();
    let mut shapes = String::new();
    for k in 0..3 {
        let img = image::RgbImage::from_fn(512, 512, |x, y| {
            image::Rgb([(x % 256) as u8, (y % 256) as u8, 40 * k as u8])
        });
        img.save(dir.join(format!("tex{k}.png"))).unwrap();
        materials += &format!(
            "(name: \"m{k}\", material: Textured(material: Diffuse(reflectance: (0.5, 0.5, 0.5)), textures: [(param: \
             Reflectance, texture: Bitmap(filename: \"tex{k}.png\"))])), "
        );
        shapes += &format!(
            "(geometry: Rectangle, to_world: [Translate(({k}, 0, 0))], material: \
             Some(Ref(\"m{k}\"))), "
        );
    }
    let scene = dir.join("scene.ron");
    std::fs::write(
        &scene,
        format!(
            "{HEAD}materials: [{materials}], shapes: [{shapes}], \
             lights: [Point(position: (0, 0, 3), intensity: (1, 1, 1))])"
        ),
    )
    .unwrap();
    // 512² texels: 3 MiB kept and 7 MiB more while decoding each. The third needs 6 + 3 + 7 MiB.
    let limit = 15 << 20;
    let err = load(&scene, Some(limit)).unwrap_err();
    assert!(err.contains("tex2.png"), "{err}");
    assert!(err.contains("512×512 texels"), "{err}");
    assert!(err.contains("raise --max-memory"), "{err}");
    assert!(err.contains("material 'm2'"), "{err}");
    // Negative controls: a limit each image fits in alone was enough before; the three fit
    // under a limit a little higher, and without one.
    load(&scene, Some(20 << 20)).unwrap();
    load(&scene, None).unwrap();
}

/// A 40 × 40 quad grid (3200 triangles, 1681 vertices) as an OBJ file in `dir`.
fn write_grid(dir: &Path) {
    let mut obj = String::new();
    let n = 40;
    for y in 0..=n {
        for x in 0..=n {
            obj += &format!("v {x} {y} {}\n", ((x * y) % 7) as f32 * 0.1);
        }
    }
    for y in 0..n {
        for x in 0..n {
            let a = y * (n + 1) + x + 1;
            obj += &format!(
                "f {a} {} {}\nf {a} {} {}\n",
                a + 1,
                a + n + 2,
                a + n + 2,
                a + n + 1
            );
        }
    }
    std::fs::write(dir.join("grid.obj"), obj).unwrap();
}

/// A mesh beyond the limit is an error naming the shape and the file before its BVH is built.
#[test]
fn meshes_are_bounded_before_the_build() {
    let dir = temp_dir("mesh");
    write_grid(&dir);
    let scene = dir.join("scene.ron");
    std::fs::write(
        &scene,
        format!(
            "{HEAD}materials: [], shapes: [(geometry: Rectangle), (geometry: Obj(filename: \
             \"grid.obj\"))], lights: [Point(position: (0, 0, 3), intensity: (1, 1, 1))])"
        ),
    )
    .unwrap();
    // 3200 triangles at the estimate per triangle and 1681 vertices at 12 bytes.
    let mesh = 3200 * limits::MESH_BYTES_PER_TRIANGLE + 12 * 1681;
    let err = load(&scene, Some(mesh - 50_000)).unwrap_err();
    assert!(err.contains("shape 1: mesh '"), "{err}");
    assert!(err.contains("grid.obj' (3200 triangles)"), "{err}");
    load(&scene, Some(mesh + 50_000)).unwrap();
}

/// An emissive mesh's light tables (one entry per triangle, and the light hierarchy over them)
/// are counted too: the mesh that fits as a plain shape does not fit as an area emitter, and the
/// error names the emitter.
#[test]
fn emitters_are_counted() {
    let dir = temp_dir("emitter");
    write_grid(&dir);
    let scene = |emissive: bool| {
        let path = dir.join(format!("scene-{emissive}.ron"));
        let emission = if emissive {
            ", emission: Some((1, 1, 1))"
        } else {
            ""
        };
        std::fs::write(
            &path,
            format!(
                "{HEAD}materials: [], shapes: [(geometry: Obj(filename: \"grid.obj\"){emission})], \
                 lights: [Point(position: (0, 0, 3), intensity: (1, 1, 1))])"
            ),
        )
        .unwrap();
        path
    };
    // The mesh and 200 kB: less than the tables of 3200 emissive triangles.
    let limit = 3200 * limits::MESH_BYTES_PER_TRIANGLE + 12 * 1681 + 200_000;
    load(&scene(false), Some(limit)).unwrap();
    let err = load(&scene(true), Some(limit)).unwrap_err();
    assert!(
        err.contains("shape 0: the area emitter (3200 light table entries)"),
        "{err}"
    );
    assert!(err.contains("raise --max-memory"), "{err}");
    load(&scene(true), Some(limit + 3200 * 300)).unwrap();
}

/// A PNG whose header says 64 × 64 but whose pixel data is cut off: its size is known, its
/// decoding fails.
fn write_truncated_png(path: &Path) {
    let img = image::RgbImage::from_fn(64, 64, |x, y| image::Rgb([x as u8, y as u8, 7]));
    img.save(path).unwrap();
    let bytes = std::fs::read(path).unwrap();
    std::fs::write(path, &bytes[..60]).unwrap();
}

/// Every image is counted from its header before the first is decoded: with a first texture
/// that cannot be decoded and a second beyond the limit, the error is the limit's, naming the
/// second, the scene's image count and their total; without a limit the first texture's decoding
/// fails (the negative control: it is decoded first).
#[test]
fn images_are_counted_before_any_is_decoded() {
    let dir = temp_dir("before");
    write_truncated_png(&dir.join("broken.png"));
    image::RgbImage::from_pixel(1024, 1024, image::Rgb([100, 150, 200]))
        .save(dir.join("big.png"))
        .unwrap();
    let scene = dir.join("scene.ron");
    let material = |k: usize, file: &str| {
        format!(
            "(name: \"m{k}\", material: Textured(material: Diffuse(reflectance: (0.5, 0.5, 0.5)), \
             textures: [(param: Reflectance, texture: Bitmap(filename: \"{file}\"))])), "
        )
    };
    std::fs::write(
        &scene,
        format!(
            "{HEAD}materials: [{}{}], shapes: [(geometry: Rectangle, material: Some(Ref(\"m0\"))), \
             (geometry: Rectangle, material: Some(Ref(\"m1\")))], \
             lights: [Point(position: (0, 0, 3), intensity: (1, 1, 1))])",
            material(0, "broken.png"),
            material(1, "big.png"),
        ),
    )
    .unwrap();
    // 1024² texels: 12 MiB kept and 28 MiB more while decoding.
    let err = load(&scene, Some(20 << 20)).unwrap_err();
    assert!(err.contains("shape 1: material 'm1': image '"), "{err}");
    assert!(err.contains("big.png' (1024×1024 texels)"), "{err}");
    assert!(err.contains("the scene's 2 images need about"), "{err}");
    assert!(err.contains("before any is decoded"), "{err}");
    let err = load(&scene, None).unwrap_err();
    assert!(err.contains("broken.png"), "{err}");
    assert!(!err.contains("--max-memory"), "{err}");
}

/// In an XML scene the error is at the line of the shape that uses the named material whose
/// texture crosses the limit (the material itself is declared at the top level).
#[test]
fn an_image_beyond_the_limit_is_located() {
    let dir = temp_dir("xml");
    image::RgbImage::from_pixel(1024, 1024, image::Rgb([100, 150, 200]))
        .save(dir.join("big.png"))
        .unwrap();
    let scene = dir.join("scene.xml");
    std::fs::write(
        &scene,
        r#"<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="40"/><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
  <bsdf type="diffuse" id="wall">
    <texture type="bitmap" name="reflectance"><string name="filename" value="big.png"/></texture>
  </bsdf>
  <shape type="rectangle"/>
  <shape type="rectangle">
    <ref id="wall"/>
  </shape>
  <emitter type="point"><point name="position" x="0" y="0" z="3"/></emitter>
</scene>
"#,
    )
    .unwrap();
    let err = load(&scene, Some(20 << 20)).unwrap_err();
    assert!(err.contains("scene.xml:7"), "{err}");
    assert!(err.contains("material 'wall'"), "{err}");
    assert!(err.contains("big.png' (1024×1024 texels)"), "{err}");
    load(&scene, Some(60 << 20)).unwrap();
}

/// Area emitters that name the same radiance texture share one copy of its image, and the
/// limit counts it once: three rectangles lit by one 512² image load under a limit that one
/// copy fits in (3 MiB kept, 7 MiB more while decoding) and three do not (6 + 3 + 7 MiB), which
/// three different images of that size exceed (the negative control).
#[test]
fn emitters_sharing_a_radiance_texture_count_it_once() {
    let dir = temp_dir("shared-radiance");
    for k in 0..3 {
        let img = image::RgbImage::from_fn(512, 512, |x, y| {
            image::Rgb([(x % 256) as u8, (y % 256) as u8, 40 * k as u8])
        });
        img.save(dir.join(format!("tex{k}.png"))).unwrap();
    }
    let scene = |files: [&str; 3]| {
        let shapes: String = files
            .iter()
            .enumerate()
            .map(|(k, f)| {
                format!(
                    "(geometry: Rectangle, to_world: [Translate(({k}, 0, 0))], emission: \
                     Some((1, 1, 1)), emission_texture: Some(Bitmap(filename: \"{f}\"))), "
                )
            })
            .collect();
        let path = dir.join(format!("{}.ron", files.join("-")));
        std::fs::write(&path, format!("{HEAD}shapes: [{shapes}])")).unwrap();
        path
    };
    let limit = 15 << 20;
    load(&scene(["tex0.png"; 3]), Some(limit)).unwrap();
    let err = load(&scene(["tex0.png", "tex1.png", "tex2.png"]), Some(limit)).unwrap_err();
    assert!(err.contains("tex2.png"), "{err}");
    assert!(err.contains("emitter radiance texture"), "{err}");
}
