//! Primary hits for a whole image (a G-buffer), the first stage of the screen-space ReSTIR
//! estimators. Camera rays are jittered by the film's filter with the pixel's pass stream, the
//! same numbers the path tracer draws first, so both see the same pixel footprint.

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use restir_geometry::{Frame, SurfaceInteraction};
use restir_materials::Bsdf;
use restir_scene::{Scene, TexturePoint};

use crate::bands::Bands;
use crate::motion::FrameMotion;
use crate::pass::PassContext;
use restir_reuse::{Similarity, SimilarityKey, Surfaces};

/// What a reuse pass needs to know about a pixel's primary hit: the shading point, its frame,
/// its material and where its textures are looked up, the direction to the camera and what the
/// neighbour-similarity tests compare. Cache-line aligned (spatial reuse reads it at random
/// neighbours): two lines since it holds the texture lookup point of mesh attributes (the
/// triangle and barycentrics) beside the texture coordinates, and a bump map's normal at the
/// hit; the second tangent of the shading frame is recomputed as `n × s`.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct Receiver {
    /// Hit position.
    pub p: Vec3,
    /// Shading normal.
    pub n: Vec3,
    /// First shading tangent.
    pub s: Vec3,
    /// Direction towards the camera in the shading frame [`Receiver::frame`].
    pub wo: Vec3,
    /// Index of the BSDF in `Scene::bsdfs`, or [`Receiver::NO_HIT`].
    pub bsdf: u32,
    /// Distance from the camera.
    pub depth: f32,
    /// Where [`Scene::bsdf_at`] looks up the material's textures (texture coordinates; the
    /// shape, triangle and barycentrics for mesh attributes).
    pub at: TexturePoint,
    /// A bump map's perturbed normal as a normal-map texel ([`Scene::bump_at`]), computed at
    /// the hit from the surface's derivatives, which `at` does not keep; `None` when the
    /// material has no bump map.
    pub bump: Option<Vec3>,
}

impl Receiver {
    /// `bsdf` of a pixel without a primary hit.
    pub const NO_HIT: u32 = u32::MAX;

    const EMPTY: Self = Self {
        p: Vec3::ZERO,
        n: Vec3::Z,
        s: Vec3::X,
        wo: Vec3::Z,
        bsdf: Self::NO_HIT,
        depth: 0.0,
        at: TexturePoint {
            uv: Vec2::ZERO,
            shape: 0,
            prim: 0,
            bary: Vec2::ZERO,
        },
        bump: None,
    };

    /// The receiver at surface hit `si` of `scene`, seen from direction `to_camera` (world
    /// space, unit) at distance `depth`: its shading frame, material, texture lookup point and
    /// bump-map normal, so that [`Receiver::resolve_bsdf`] gives `scene.bsdf(si)`.
    #[inline]
    pub fn at_hit(scene: &Scene, si: &SurfaceInteraction, to_camera: Vec3, depth: f32) -> Self {
        let frame = &si.shading;
        let mut r = Self {
            p: si.p,
            n: frame.n,
            s: frame.s,
            wo: Vec3::Z,
            bsdf: scene.shape_bsdf()[si.shape as usize],
            depth,
            at: TexturePoint::of(si),
            bump: scene.bump_at(si),
        };
        r.wo = r.frame().to_local(to_camera);
        r
    }

    /// The BSDF at this point, textures resolved and a bump map applied: the BSDF
    /// [`Scene::bsdf`] gives at the hit ([`Scene::bsdf_bumped`]).
    #[inline]
    pub fn resolve_bsdf(&self, scene: &Scene) -> Bsdf {
        scene.bsdf_bumped(self.bsdf, &self.at, self.bump)
    }

    /// The shading frame.
    #[inline]
    pub fn frame(&self) -> Frame {
        Frame {
            s: self.s,
            t: self.n.cross(self.s),
            n: self.n,
        }
    }

    /// What the similarity tests compare.
    #[inline]
    pub fn key(&self) -> SimilarityKey {
        SimilarityKey {
            n: self.n,
            depth: if self.bsdf == Self::NO_HIT {
                SimilarityKey::NO_HIT
            } else {
                self.depth
            },
        }
    }
}

/// One pass's primary hits, one entry per pixel (row-major) in each array.
#[derive(Clone, Debug, Default)]
pub struct GBuffer {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The shading data of each primary hit ([`Receiver::NO_HIT`] where the camera ray left the
    /// scene or the path ends there).
    pub receivers: Vec<Receiver>,
    /// Geometric normals (for ray offsets at shading).
    pub ng: Vec<Vec3>,
    /// The shape each primary hit lies on (index into `Scene::shapes`; motion vectors move the
    /// hit with its shape and reject a previous hit on another shape).
    pub shape: Vec<u32>,
    /// Each receiver's [`SimilarityKey`], what neighbour selection tests.
    pub keys: Vec<SimilarityKey>,
}

impl GBuffer {
    /// Bytes per pixel of one G-buffer (receiver, geometric normal, shape).
    pub const BYTES_PER_PIXEL: usize = std::mem::size_of::<Receiver>()
        + std::mem::size_of::<Vec3>()
        + std::mem::size_of::<u32>()
        + std::mem::size_of::<SimilarityKey>();

    /// The primary hit of pixel `index`, if there is one.
    #[inline]
    pub fn receiver(&self, index: usize) -> Option<&Receiver> {
        let r = &self.receivers[index];
        (r.bsdf != Receiver::NO_HIT).then_some(r)
    }

    /// Traces the camera rays of pass `ctx`; with `hide_emitters` they pass through area lights
    /// (as in Mitsuba 3) and see no environment. With `add_seen`, adds what the camera sees
    /// directly (emitters and the environment, unless hidden) to `radiance`, which must have one
    /// entry per pixel. With `keep_hits = false` (`max_depth ≤ 1`) no hits are stored. Returns
    /// the buffer and the number of rays traced.
    pub fn trace(
        scene: &Scene,
        ctx: &PassContext,
        hide_emitters: bool,
        add_seen: bool,
        keep_hits: bool,
        radiance: &mut [Vec3],
    ) -> (Self, u64) {
        Self::trace_into(
            scene,
            ctx,
            hide_emitters,
            add_seen,
            keep_hits,
            radiance,
            None,
        )
    }

    /// [`GBuffer::trace`] into the memory of `recycled`, a buffer an earlier pass no longer
    /// needs (a fresh buffer of an image's size is faulted in page by page, a few per cent of
    /// a pass).
    pub fn trace_into(
        scene: &Scene,
        ctx: &PassContext,
        hide_emitters: bool,
        add_seen: bool,
        keep_hits: bool,
        radiance: &mut [Vec3],
        recycled: Option<GBuffer>,
    ) -> (Self, u64) {
        /// `v` as `n` copies of `value`, its memory reused.
        fn refill<T: Clone>(mut v: Vec<T>, value: T, n: usize) -> Vec<T> {
            v.clear();
            v.resize(n, value);
            v
        }
        let add_seen = add_seen && !hide_emitters;
        let (w, h) = ctx.resolution(scene);
        let (w, h) = (w as usize, h as usize);
        let old = recycled.unwrap_or_default();
        let mut receivers = refill(old.receivers, Receiver::EMPTY, w * h);
        let mut ng = refill(old.ng, Vec3::ZERO, w * h);
        let mut shape = refill(old.shape, u32::MAX, w * h);
        let mut keys = old.keys;
        let lights = &scene.lights;
        let bands = Bands::new(w);
        let buffers = (
            ((&mut receivers[..], &mut ng[..]), &mut shape[..]),
            radiance,
        );
        let rays = bands.run(buffers, |first, (((recv, ngs), shapes), rad)| {
            let mut rays = 0;
            for (i, l) in rad.iter_mut().enumerate() {
                let index = first + i;
                let (x, y) = ((index % w) as u32, (index / w) as u32);
                let mut rng = ctx.pixel_rng(index);
                let film = ctx.pixel_film_position(index, (x, y), &mut rng);
                let ray = scene.camera.generate_ray(film, rng.next_2d());
                let (hit, n) = scene.camera_intersect(&ray, hide_emitters);
                rays += n;
                let Some(si) = hit else {
                    if add_seen {
                        *l += lights.environment_radiance(ray.d);
                    }
                    continue;
                };
                if add_seen && let Some(light) = lights.light_on_shape(si.shape) {
                    *l += lights.area_radiance(light, &si, -ray.d);
                }
                if keep_hits {
                    recv[i] = Receiver::at_hit(scene, &si, -ray.d, si.t);
                    ngs[i] = si.ng;
                    shapes[i] = si.shape;
                }
            }
            rays
        });
        keys.clear();
        keys.par_extend(receivers.par_iter().map(Receiver::key));
        (
            Self {
                width: w,
                height: h,
                receivers,
                ng,
                shape,
                keys,
            },
            rays,
        )
    }

    /// The pixel of the previous frame's `prev` G-buffer that saw pixel `index`'s primary hit
    /// of this one, after the scene moved as `motion` says: the hit moved back with its shape
    /// and projected by the previous camera. The hit found there must lie on the same shape,
    /// face the same way (shading normals within `rule.normal_cos`) and lie at the expected
    /// distance from the previous camera (within `rule.depth_tolerance`), or the pixel is
    /// disoccluded and has no history (`None`, as for a point outside the previous film). These
    /// tests only choose which domain takes part; the estimators stay unbiased whatever they
    /// decide (`docs/ANIMATION.md`, "Across frames").
    pub fn previous_pixel_moved(
        &self,
        index: usize,
        motion: &FrameMotion,
        prev: &GBuffer,
        rule: &Similarity,
    ) -> Option<usize> {
        let r = self.receiver(index)?;
        let shape = self.shape[index];
        let m = motion.shape_to_prev(shape)?;
        let p = m.transform_point3(r.p);
        let camera = &motion.prev_scene.camera;
        let film = camera.film_position_of(p)?;
        let (x, y) = (film.x.floor(), film.y.floor());
        if x < 0.0 || y < 0.0 || x >= prev.width as f32 || y >= prev.height as f32 {
            return None;
        }
        let q = y as usize * prev.width + x as usize;
        let pr = prev.receiver(q)?;
        if prev.shape[q] != shape {
            return None;
        }
        let n = m.transform_vector3(r.n).normalize_or_zero();
        let depth = (p - camera.origin()).length();
        let moved = SimilarityKey { n, depth };
        pr.key().is_similar(&moved, rule).then_some(q)
    }
}

/// The reuse passes see this renderer's primary hits through the crate's interface.
impl Surfaces for GBuffer {
    type Motion = FrameMotion;

    #[inline]
    fn width(&self) -> usize {
        self.width
    }

    #[inline]
    fn height(&self) -> usize {
        self.height
    }

    #[inline]
    fn has_surface(&self, index: usize) -> bool {
        self.keys[index].hit()
    }

    #[inline]
    fn similar(&self, a: usize, b: usize, rule: &Similarity) -> bool {
        let (ka, kb) = (&self.keys[a], &self.keys[b]);
        ka.hit() && kb.hit() && ka.is_similar(kb, rule)
    }

    /// The same pixel in the same frame; across frames [`GBuffer::previous_pixel_moved`].
    #[inline]
    fn previous_pixel(
        &self,
        index: usize,
        previous: &Self,
        motion: Option<&FrameMotion>,
        rule: &Similarity,
    ) -> Option<usize> {
        match motion {
            Some(m) => self.previous_pixel_moved(index, m, previous, rule),
            None => {
                let (a, b) = (&self.keys[index], &previous.keys[index]);
                (a.hit() && b.hit() && a.is_similar(b, rule)).then_some(index)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// A bump-mapped sphere and plane (the same height texture), seen by a 16 × 16 camera.
    fn bumped_scene() -> Scene {
        let bumped = |geometry: &str| {
            format!(
                r#"(geometry: {geometry}, material: Some(Inline(Textured(
                    material: BumpMap(scale: 3.0, material: Diffuse(reflectance: (0.5, 0.5, 0.5))),
                    textures: [(param: BumpMap, texture: Bitmap(filename: "tex.png"))]))))"#
            )
        };
        let ron = format!(
            r#"(
            camera: (fov: 40, to_world: [LookAt(origin: (0, 0, 5), target: (0, 0, 0), up: (0, 1, 0))]),
            film: (width: 16, height: 16, filter: Box),
            shapes: [{}, {}],
            lights: [Constant(radiance: (1, 1, 1))],
        )"#,
            bumped("Sphere(center: (0.6, 0, 0.5), radius: 0.6)"),
            bumped("Rectangle"),
        );
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/textured");
        let desc = restir_scene::parse_ron(&ron, "bumped.ron".as_ref()).unwrap();
        Scene::build(&desc, &dir, "bumped.ron".as_ref()).unwrap()
    }

    /// A receiver resolves the BSDF the path tracer gets at the same hit, bump map applied;
    /// the lookup by texture point alone (the negative control) leaves the bump flat and differs.
    #[test]
    fn receiver_resolves_the_bumped_bsdf_of_its_hit() {
        let scene = bumped_scene();
        let (mut hits, mut flat_differs) = (0, 0);
        for y in 0..16 {
            for x in 0..16 {
                let film = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let ray = scene.camera.generate_ray(film, Vec2::splat(0.5));
                let Some(si) = scene.intersect(&ray) else {
                    continue;
                };
                hits += 1;
                let r = Receiver::at_hit(&scene, &si, -ray.d, si.t);
                assert!(r.bump.is_some());
                assert_eq!(r.resolve_bsdf(&scene), scene.bsdf(&si), "pixel ({x}, {y})");
                flat_differs += usize::from(scene.bsdf_at(r.bsdf, &r.at) != scene.bsdf(&si));
            }
        }
        assert!(hits > 50, "{hits}");
        assert!(flat_differs > hits / 2, "{flat_differs} of {hits}");
    }

    /// The receiver stays within two cache lines with the bump map's normal.
    #[test]
    fn receiver_size() {
        assert_eq!(std::mem::size_of::<Receiver>(), 128);
    }
}
