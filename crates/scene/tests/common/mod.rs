//! What the scene crate's material tests share: a minimal XML scene around a body, and the BSDF
//! a ray straight down the z axis finds.

#![allow(dead_code)] // each test file uses what it needs

use glam::Vec3;
use restir_geometry::Ray;
use restir_materials::Bsdf;
use restir_scene::Scene;

/// A Mitsuba 3 scene of a 4×4 perspective sensor and `body`.
pub fn scene_text(body: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
{body}
</scene>"#
    )
}

/// The BSDF (textures looked up) where a ray from `(x, y, 5)` down the z axis hits `scene`.
pub fn bsdf_from_above(scene: &Scene, x: f32, y: f32) -> Bsdf {
    let si = scene
        .intersect(&Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z))
        .expect("hit");
    scene.bsdf(&si)
}
