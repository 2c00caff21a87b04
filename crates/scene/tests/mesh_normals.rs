//! A mesh file without normals gets smooth vertex normals at load, as Mitsuba 3 (and Lajolla)
//! give it: the faces' normals weighted by their angles at each vertex, in world space, after
//! `to_world`; `face_normals` keeps it flat, and a file's own normals are kept.

use std::path::{Path, PathBuf};

use glam::Vec3;
use restir_geometry::{Ray, Shape, TriangleMesh, angle_weighted_normals};
use restir_scene::{LoadOptions, load_scene};
use restir_testkit::TempDir;

/// A square pyramid without its base: apex (0, 0, 1) over the corners (±1, ±1, 0), four faces
/// wound outwards, as OBJ (1-based) and as ASCII PLY; neither has normals.
const OBJ: &str =
    "v 0 0 1\nv 1 1 0\nv -1 1 0\nv -1 -1 0\nv 1 -1 0\nf 1 2 3\nf 1 3 4\nf 1 4 5\nf 1 5 2\n";
const PLY: &str = "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 1\n1 1 0\n-1 1 0\n-1 -1 0\n1 -1 0\n3 0 1 2\n3 0 2 3\n3 0 3 4\n3 0 4 1\n";

fn dir(tag: &str) -> TempDir {
    let dir = TempDir::new("mesh-normals", tag);
    std::fs::write(dir.join("p.obj"), OBJ).unwrap();
    std::fs::write(dir.join("p.ply"), PLY).unwrap();
    // The same pyramid with a normal of its own per vertex (all +z).
    let with_vn = OBJ.replace("f 1 2 3\nf 1 3 4\nf 1 4 5\nf 1 5 2\n", "")
        + "vn 0 0 1\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\nf 1//1 4//1 5//1\nf 1//1 5//1 2//1\n";
    std::fs::write(dir.join("vn.obj"), with_vn).unwrap();
    dir
}

/// A scene with one shape of `kind` from `file`, with the extra properties `props`.
fn scene_file(dir: &Path, kind: &str, file: &str, props: &str) -> PathBuf {
    let path = dir.join(format!("{kind}-{}.xml", props.len()));
    std::fs::write(
        &path,
        format!(
            r#"<scene version="3.0.0">
    <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
    <shape type="{kind}"><string name="filename" value="{file}"/>{props}</shape>
</scene>"#
        ),
    )
    .unwrap();
    path
}

fn mesh(path: &Path) -> TriangleMesh {
    let loaded = load_scene(path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    match &loaded.scene.shapes[0] {
        Shape::Mesh(m) => m.clone(),
        s => panic!("expected a mesh, got {s:?}"),
    }
}

#[test]
fn files_without_normals_get_the_faces_normals_weighted_by_angle() {
    let d = dir("smooth");
    for (kind, file) in [("obj", "p.obj"), ("ply", "p.ply")] {
        let m = mesh(&scene_file(&d, kind, file, ""));
        let n = m
            .normals()
            .unwrap_or_else(|| panic!("{kind}: no vertex normals"));
        assert_eq!(n, angle_weighted_normals(m.positions(), m.indices()));
        // The apex's normal is +z (the four faces alike); a base corner's leans outwards
        // between its two faces.
        let apex = m.positions().iter().position(|p| p.z == 1.0).unwrap();
        assert!(
            (n[apex] - Vec3::Z).length() < 1e-6,
            "{kind}: apex {}",
            n[apex]
        );
        for (p, n) in m.positions().iter().zip(n) {
            if p.z == 0.0 {
                let outwards = Vec3::new(p.x, p.y, 0.0).normalize();
                assert!(
                    n.dot(outwards) > 0.5 && n.z > 0.3,
                    "{kind}: corner {p}: {n}"
                );
            }
        }
    }
}

#[test]
fn normals_are_computed_in_world_space() {
    let d = dir("world");
    // Stretched along x: the angles, and so the weights, are the world-space triangles'.
    let stretch = r#"<transform name="to_world"><scale x="4" y="1" z="1"/></transform>"#;
    let m = mesh(&scene_file(&d, "obj", "p.obj", stretch));
    assert!(m.positions().iter().any(|p| p.x == 4.0));
    assert_eq!(
        m.normals().unwrap(),
        angle_weighted_normals(m.positions(), m.indices())
    );
}

#[test]
fn face_normals_and_a_files_own_normals_are_kept() {
    let d = dir("kept");
    let flat = r#"<boolean name="face_normals" value="true"/>"#;
    for (kind, file) in [("obj", "p.obj"), ("ply", "p.ply")] {
        assert!(mesh(&scene_file(&d, kind, file, flat)).normals().is_none());
    }
    let m = mesh(&scene_file(&d, "obj", "vn.obj", ""));
    assert!(m.normals().unwrap().iter().all(|n| *n == Vec3::Z));
}

/// The computed normals are stored as the winding gives them and turned at lookup with the
/// shape, as a file's own normals are: under `flip_normals` a hit near the apex shades with
/// the interpolated normal reversed.
#[test]
fn flip_normals_turns_computed_normals() {
    let d = dir("flip");
    let shading = |props: &str| {
        let path = scene_file(&d, "obj", "p.obj", props);
        let scene = load_scene(&path, &LoadOptions::default())
            .unwrap_or_else(|e| panic!("{e}"))
            .scene;
        let si = scene
            .intersect(&Ray::new(Vec3::new(0.1, 0.05, 5.0), -Vec3::Z))
            .expect("hit");
        (si.shading.n, si.ng)
    };
    let (n, ng) = shading("");
    let (flipped, flipped_ng) = shading(r#"<boolean name="flip_normals" value="true"/>"#);
    // Smooth: near the apex the shading normal leans towards +z, away from the face's.
    assert!(n.z > ng.z + 0.1, "{n} against the face's {ng}");
    assert!((flipped + n).length() < 1e-6, "{flipped} against {n}");
    assert!(
        (flipped_ng + ng).length() < 1e-6,
        "{flipped_ng} against {ng}"
    );
}
