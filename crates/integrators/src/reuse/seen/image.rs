//! Where on the film the camera may see an area emitter: the silhouette mask's probes that
//! can change it (the rest are skipped).

use glam::{Vec2, Vec3};
use restir_scene::Scene;

use super::DeltaChains;

/// Where on the film the camera may see an area emitter, in tiles of [`EmitterImage::TILE`]
/// pixels, widened by two filter reaches and a pixel: the probes the silhouette mask needs.
pub(super) struct EmitterImage {
    /// Film position of the first tile's corner.
    origin: Vec2,
    /// Tiles per row and rows.
    size: (i32, i32),
    /// Per tile, whether it may matter.
    near: Vec<bool>,
}

impl EmitterImage {
    /// Tile side in pixels.
    const TILE: f32 = 8.0;

    /// The tiles over the probes' domain (its first probe at film position `(first, first)`,
    /// `probes` probes every half pixel along each axis; `reach` the filter's in whole pixels)
    /// near the image of some area emitter's primitive: the film box of the camera's view of
    /// the primitive's bounds, widened by `2·reach + 2` pixels. `None` (every probe traced)
    /// when the probes follow delta lobes (an emitter may show anywhere through them), for a
    /// camera with a lens (a point is then seen from several film positions) and when some
    /// emitter's bounds lie across the camera's plane (those wholly behind it are skipped).
    pub(super) fn of(
        scene: &Scene,
        chains: Option<&DeltaChains>,
        (first, reach): (f32, i32),
        probes: (i32, i32),
    ) -> Option<Self> {
        if chains.is_some() || !scene.camera.is_pinhole() {
            return None;
        }
        let origin = Vec2::splat(first);
        let extent = Vec2::new(probes.0 as f32, probes.1 as f32) * 0.5;
        let size = (
            (extent.x / Self::TILE).ceil() as i32 + 1,
            (extent.y / Self::TILE).ceil() as i32 + 1,
        );
        let mut near = vec![false; (size.0 * size.1) as usize];
        let margin = 2.0 * reach as f32 + 2.0;
        for (shape, geometry) in scene.shapes.iter().enumerate() {
            if scene.lights.light_on_shape(shape as u32).is_none() {
                continue;
            }
            for prim in 0..geometry.primitive_count() as u32 {
                let (a, b) = geometry.primitive_bounds(prim);
                let (mut lo, mut hi) = (Vec2::INFINITY, Vec2::NEG_INFINITY);
                let mut behind = 0;
                for corner in 0..8 {
                    let p = Vec3::new(
                        if corner & 1 == 0 { a.x } else { b.x },
                        if corner & 2 == 0 { a.y } else { b.y },
                        if corner & 4 == 0 { a.z } else { b.z },
                    );
                    match scene.camera.film_position_of(p) {
                        Some(f) => (lo, hi) = (lo.min(f), hi.max(f)),
                        None => behind += 1,
                    }
                }
                match behind {
                    0 => {}
                    // Wholly behind the camera: never seen.
                    8 => continue,
                    // Across the camera's plane: its image may be anywhere.
                    _ => return None,
                }
                let to_tile = |v: f32, n: i32| {
                    ((v - first) / Self::TILE).floor().clamp(-1.0, n as f32) as i32
                };
                let (x0, x1) = (
                    to_tile(lo.x - margin, size.0),
                    to_tile(hi.x + margin, size.0),
                );
                let (y0, y1) = (
                    to_tile(lo.y - margin, size.1),
                    to_tile(hi.y + margin, size.1),
                );
                for ty in y0.max(0)..=y1.min(size.1 - 1) {
                    for tx in x0.max(0)..=x1.min(size.0 - 1) {
                        near[(ty * size.0 + tx) as usize] = true;
                    }
                }
            }
        }
        Some(Self { origin, size, near })
    }

    /// Whether the probe at film position `film` may matter.
    pub(super) fn covers(&self, film: Vec2) -> bool {
        let t = ((film - self.origin) / Self::TILE).floor();
        let (tx, ty) = (t.x as i32, t.y as i32);
        !(0..self.size.0).contains(&tx)
            || !(0..self.size.1).contains(&ty)
            || self.near[(ty * self.size.0 + tx) as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::super::SeenEmission;
    use super::*;

    /// A room seen by a pinhole camera with a sphere lamp and a quad light in view, a lamp
    /// behind the camera and, with `across`, a long emitting bar through the camera's plane.
    fn room(across: bool, aperture: f32) -> Scene {
        let bar = if across {
            r#"(geometry: Cube, to_world: [Scale((0.05, 0.05, 4)), Translate((1.5, 1.8, 4))],
                emission: Some((5, 5, 5))),"#
        } else {
            ""
        };
        let ron = format!(
            r#"(
            camera: (fov: 50, aperture_radius: {aperture}, focus_distance: 4,
                     to_world: [LookAt(origin: (0, 1, 4), target: (0, 1, 0), up: (0, 1, 0))]),
            film: (width: 64, height: 48, filter: Gaussian(stddev: 0.5)),
            shapes: [
                (geometry: Rectangle, to_world: [Scale((3, 3, 1)), Rotate(axis: (1, 0, 0), angle: -90)],
                 material: Some(Inline(Diffuse(reflectance: (0.6, 0.5, 0.4))))),
                (geometry: Rectangle, to_world: [Scale((3, 2, 1)), Translate((0, 1, -1))],
                 material: Some(Inline(Diffuse(reflectance: (0.5, 0.5, 0.5))))),
                (geometry: Sphere(center: (0.8, 1.4, -0.5), radius: 0.06), emission: Some((300, 200, 100))),
                (geometry: Rectangle, to_world: [Scale((0.4, 0.1, 1)), Translate((-1, 0.5, -0.9))],
                 emission: Some((20, 20, 20))),
                (geometry: Sphere(center: (0, 1, 6), radius: 0.3), emission: Some((50, 50, 50))),
                {bar}
            ],
            lights: [Constant(radiance: (0.2, 0.2, 0.3))],
        )"#
        );
        let desc = restir_scene::parse_ron(&ron, "probes.ron".as_ref()).unwrap();
        Scene::build(&desc, ".".as_ref(), "probes.ron".as_ref()).unwrap()
    }

    /// Tracing only the probes near an emitter's image gives the mask every probe gives, on a
    /// splatting film (any emitter within reach) and a sampled one (the contrast), with fewer
    /// rays; a lamp behind the camera is skipped, a bar through the camera's plane and a lens
    /// make every probe count.
    #[test]
    fn probes_near_emitters_give_the_whole_films_mask() {
        let scene = room(false, 0.0);
        let size = scene.camera.resolution();
        for (reach, any) in [(3, true), (1, false), (2, false)] {
            let (near, near_rays) =
                SeenEmission::contrast_probing(&scene, reach, size, None, any, true);
            let (all, all_rays) =
                SeenEmission::contrast_probing(&scene, reach, size, None, any, false);
            assert_eq!(near, all, "reach {reach}, any {any}");
            assert!(near.iter().any(|&c| c > 0.0) && near.contains(&0.0));
            assert!(
                2 * near_rays < all_rays,
                "reach {reach}: {near_rays} of {all_rays} probes"
            );
        }
        let probes = (2 * 64 - 1 + 12, 2 * 48 - 1 + 12);
        assert!(EmitterImage::of(&scene, None, (-2.5, 3), probes).is_some());
        assert!(EmitterImage::of(&room(true, 0.0), None, (-2.5, 3), probes).is_none());
        assert!(EmitterImage::of(&room(false, 0.05), None, (-2.5, 3), probes).is_none());
    }
}
