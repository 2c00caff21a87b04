//! The hall's tests: its contents per option, and its determinism.

use super::*;
use crate::{Asset, AssetContents, GenerateError, Kind, Params, generate};

fn options(lights: u32, occluders: bool, envmap: bool) -> DiOptions {
    DiOptions {
        lights,
        receivers: Receivers::Mixed,
        occluders,
        envmap,
        ..DiOptions::default()
    }
}

/// Faces in the OBJ assets, and how many OBJ files.
fn triangles(generated: &Generated) -> (usize, usize) {
    let objs: Vec<&str> = generated
        .assets
        .iter()
        .filter_map(|a| match &a.contents {
            AssetContents::Text(t) if a.filename.ends_with(".obj") => Some(t.as_str()),
            _ => None,
        })
        .collect();
    let faces = objs
        .iter()
        .map(|t| t.lines().filter(|l| l.starts_with("f ")).count())
        .sum();
    (faces, objs.len())
}

#[test]
fn a_hall_has_its_triangles_in_tens_of_garlands_and_builds() {
    for (seed, lights) in [(11, 4_000), (111, 8_000), (3, 100)] {
        let params = Params::Di(Kind::Hall, options(lights, true, true));
        let a = generate(&params, seed).unwrap();
        assert_eq!(a, generate(&params, seed).unwrap(), "deterministic");
        let (faces, meshes) = triangles(&a);
        assert_eq!(faces, lights as usize, "seed {seed}");
        if lights >= 24 * GARLANDS.1 {
            assert!((GARLANDS.0 as usize..=GARLANDS.1 as usize).contains(&meshes));
        } else {
            assert!(meshes >= 1 && meshes as u32 <= lights / 24);
        }
        let emitters = a.desc.shapes.iter().filter(|s| s.emission.is_some());
        assert_eq!(emitters.count(), meshes);
        assert_eq!(a.desc.lights.len(), 1, "the sky");
        assert!(!a.desc.integrator.hide_emitters);
        assert_eq!(a.desc.integrator.max_depth, 2);
        // The RON text reads back and builds (OBJ meshes and sky written beside it).
        let tmp = restir_testkit::TempDir::new("hall", &seed.to_string());
        let dir = tmp.join("hall");
        let path = a.write(&dir, "hall").unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let desc = restir_scene::parse_ron(&text, &path).unwrap();
        assert_eq!(desc, a.desc);
        let scene = restir_scene::Scene::build(&desc, &dir, &path).unwrap();
        assert_eq!(scene.features.light_count, meshes + 1);
    }
    let other = generate(&Params::Di(Kind::Hall, options(4_000, true, true)), 12).unwrap();
    let first = generate(&Params::Di(Kind::Hall, options(4_000, true, true)), 11).unwrap();
    assert_ne!(other.desc, first.desc, "another seed, another hall");
}

#[test]
fn the_options_change_what_they_name_and_nothing_else() {
    let with = generate(&Params::Di(Kind::Hall, options(2_000, true, true)), 5).unwrap();
    let closed = generate(&Params::Di(Kind::Hall, options(2_000, true, false)), 5).unwrap();
    let open = generate(&Params::Di(Kind::Hall, options(2_000, false, true)), 5).unwrap();
    // The garlands are the same meshes whatever the occluders and the sky.
    let objs = |g: &Generated| -> Vec<Asset> {
        g.assets
            .iter()
            .filter(|a| a.filename.ends_with(".obj"))
            .cloned()
            .collect()
    };
    assert_eq!(objs(&with), objs(&closed));
    assert_eq!(objs(&with), objs(&open));
    assert!(closed.desc.lights.is_empty());
    assert!(closed.assets.iter().all(|a| !a.filename.ends_with(".exr")));
    // Windows and the far doorway cut the walls into more pieces.
    let walls = |g: &Generated| {
        g.desc
            .shapes
            .iter()
            .filter(
                |s| matches!(&s.material, Some(restir_scene::MaterialRef::Ref(n)) if n == "wall"),
            )
            .count()
    };
    assert!(walls(&with) > walls(&closed));
    let occluders = |g: &Generated| {
        g.desc
            .shapes
            .iter()
            .filter(|s| {
                matches!(&s.material, Some(restir_scene::MaterialRef::Ref(n))
                    if n == "partition" || n == "shelf")
            })
            .count()
    };
    assert!(occluders(&with) >= 2 && occluders(&open) == 0);
}

#[test]
fn a_hall_is_not_animated() {
    let mut hall = generate(&Params::Di(Kind::Hall, options(500, true, false)), 1).unwrap();
    let err = crate::animate(&mut hall, Kind::Hall, 1).unwrap_err();
    assert!(matches!(err, GenerateError::Animation(_)), "{err}");
}

#[test]
fn solid_pieces_leave_the_holes_open() {
    assert_eq!(
        solid(-5.0, 5.0, &[(-1.0, 1.0), (2.0, 3.0)]),
        vec![(-5.0, -1.0), (1.0, 2.0), (3.0, 5.0)]
    );
    assert_eq!(solid(0.0, 1.0, &[]), vec![(0.0, 1.0)]);
}
