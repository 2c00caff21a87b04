//! `--max-memory` (`LoadOptions::max_memory`) covers a scene's meshes and images together: each is
//! counted before it is built or decoded, and the one that crosses the limit is named.

use std::path::{Path, PathBuf};

use restir_scene::{LoadOptions, load_scene};

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("restir-memlimit-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
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
    std::fs::remove_dir_all(&dir).ok();
}

/// A mesh beyond the limit is an error naming the shape and the file before its BVH is built.
#[test]
fn meshes_are_bounded_before_the_build() {
    let dir = temp_dir("mesh");
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
    let scene = dir.join("scene.ron");
    std::fs::write(
        &scene,
        format!(
            "{HEAD}materials: [], shapes: [(geometry: Rectangle), (geometry: Obj(filename: \
             \"grid.obj\"))], lights: [Point(position: (0, 0, 3), intensity: (1, 1, 1))])"
        ),
    )
    .unwrap();
    // 3200 triangles at 390 bytes and 1681 vertices at 12: 1.27 MB.
    let err = load(&scene, Some(1 << 20)).unwrap_err();
    assert!(err.contains("shape 1: mesh '"), "{err}");
    assert!(err.contains("grid.obj' (3200 triangles)"), "{err}");
    load(&scene, Some(2 << 20)).unwrap();
    std::fs::remove_dir_all(&dir).ok();
}
