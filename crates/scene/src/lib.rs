//! Scenes for the `restir` renderer.
//!
//! A scene is first a *description* ([`SceneDesc`]): plain data that the project's RON format
//! deserialises into (strictly: unknown fields are errors) and that the Mitsuba-style XML importer
//! ([`xml`]) produces. [`Scene::build`] turns a description into the runtime [`Scene`] once:
//! meshes loaded and transformed to world space, one BVH, light tables, and a [`SceneFeatures`]
//! summary from which integrators choose cheaper code paths.
//!
//! ```
//! let ron = r#"(
//!     camera: (fov: 40, to_world: [LookAt(origin: (0, 0, 4), target: (0, 0, 0), up: (0, 1, 0))]),
//!     film: (width: 32, height: 32, filter: Box),
//!     shapes: [
//!         (geometry: Rectangle, material: Some(Inline(Diffuse(reflectance: (0.5, 0.5, 0.5))))),
//!         (geometry: Sphere(center: (0, 0, 2), radius: 0.1), emission: Some((10, 10, 10)), flip_normals: true),
//!     ],
//! )"#;
//! let desc = restir_scene::parse_ron(ron, "inline.ron".as_ref()).unwrap();
//! let scene = restir_scene::Scene::build(&desc, ".".as_ref(), "inline.ron".as_ref()).unwrap();
//! assert_eq!(scene.lights.len(), 1);
//! assert_eq!(scene.camera.resolution(), (32, 32));
//! ```

#![deny(missing_docs)]

pub mod animation;
mod build;
pub mod desc;
mod edit;
mod error;
mod light_share;
mod load;
mod material;
mod meshio;
pub mod principled;
pub mod spectrum;
mod spot;
pub mod texture;
mod volfile;
pub mod xml;

pub use desc::*;
pub use edit::EditError;
pub use error::{SceneError, SceneWarning};
pub use light_share::EnvironmentShare;
pub use load::{LoadOptions, LoadedScene, load_desc, load_scene, parse_ron, sidecar_path};

use glam::{Vec2, Vec3};
use restir_geometry::{Accel, Camera, Hit, Ray, Shape, SurfaceInteraction};
use restir_lights::LightSet;
use restir_materials::{Bsdf, ReflectanceParams};
use texture::Texture;
pub use texture::TexturePoint;

/// What a scene contains, decided once at build time so that integrators can pick cheaper code
/// paths instead of testing inside their loops.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SceneFeatures {
    /// Some material has a delta lobe (mirror, smooth glass).
    pub has_delta_lobes: bool,
    /// Some material has a glossy (microfacet) lobe.
    pub has_glossy_lobes: bool,
    /// Some material parameter is a texture.
    pub has_textures: bool,
    /// There is an environment light (rays that escape gather radiance).
    pub has_environment: bool,
    /// There is a point or directional light.
    pub has_delta_lights: bool,
    /// Number of lights.
    pub light_count: usize,
    /// Entries of the emitter table (one per emissive triangle, one per other light with
    /// power; the environment aside): what a light selection chooses among.
    pub emitter_count: usize,
    /// The entries the typical local light holds ([`restir_lights::LightSet::median_emitters_per_light`]:
    /// the lower median over the lights; 0 without local lights).
    pub median_light_emitters: usize,
    /// The largest probability with which a light selection picks one light (a mesh light with
    /// all its triangles; the environment with its share), after the environment share is
    /// decided; 0 without lights.
    pub largest_light_share: f32,
    /// The environment's share of light samples, when there is an environment beside local
    /// lights (decided from a pilot at the camera's primary hits).
    pub environment_share: Option<EnvironmentShare>,
}

/// The runtime scene.
///
/// The materials are read with [`Scene::bsdfs`], [`Scene::shape_bsdf`], [`Scene::bsdf_textures`]
/// and [`Scene::textures`], and changed only through [`Scene::set_material`],
/// [`Scene::add_material`] and [`Scene::set_shape_material`], which keep the feature summary
/// ([`Scene::features`]) true to them. Shapes, lights, the BVH and the camera are built together
/// from the description (the BVH over the shapes, area lights on them, the environment's share
/// from the camera's view): to change them, change the [`SceneDesc`] and build again. Make the
/// integrator after editing: it decides its code paths from the summary when it is made.
#[derive(Debug)]
pub struct Scene {
    /// World-space shapes.
    pub shapes: std::sync::Arc<[Shape]>,
    /// For each shape, the index of its BSDF in `bsdfs`.
    shape_bsdf: Vec<u32>,
    /// The materials (with their constant parameters; see [`Scene::bsdf_at`]).
    bsdfs: Vec<Bsdf>,
    /// For each entry of `bsdfs`, the textures of its parameters, if it has any.
    bsdf_textures: Vec<Option<TexturedParams>>,
    /// The decoded textures that `bsdf_textures` refer to.
    textures: Vec<Texture>,
    /// The BVH over `shapes`.
    pub accel: Accel,
    /// Lights and light selection.
    pub lights: LightSet,
    /// The camera (its resolution is the film's).
    pub camera: Camera,
    /// Reconstruction filter (how camera rays are jittered within a pixel).
    pub filter: FilterDesc,
    /// What the scene contains, decided when it was built and kept up to date by the material
    /// edits. Written directly only to measure or test a code path the summary selects.
    pub features: SceneFeatures,
}

impl Scene {
    /// The closest surface hit by `ray` before its `t_max`.
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction> {
        let hit: Hit = self.accel.intersect(ray, ray.t_max)?;
        Some(self.accel.surface_interaction(&self.shapes, &hit, ray))
    }

    /// The surface a camera ray `ray` sees: the closest hit, or with `hide_emitters` the closest
    /// that is not an area light ([`Scene::intersect_past_emitters`]). Returns the hit and the
    /// number of rays traced.
    #[inline]
    pub fn camera_intersect(
        &self,
        ray: &Ray,
        hide_emitters: bool,
    ) -> (Option<SurfaceInteraction>, u64) {
        if hide_emitters {
            self.intersect_past_emitters(ray)
        } else {
            (self.intersect(ray), 1)
        }
    }

    /// The closest surface along camera ray `ray` that is not an area light, as a camera with
    /// `hide_emitters` sees it (Mitsuba 3's rule: its camera rays pass through area emitters);
    /// `si.t` is the distance along `ray`. Returns the hit and the number of rays traced.
    pub fn intersect_past_emitters(&self, ray: &Ray) -> (Option<SurfaceInteraction>, u64) {
        // Enough for any real scene; a ray still inside emitters after this many stops there.
        const MAX_SKIPS: u64 = 256;
        let mut next = *ray;
        for rays in 1..=MAX_SKIPS {
            let Some(mut si) = self.intersect(&next) else {
                return (None, rays);
            };
            if rays == MAX_SKIPS || self.lights.light_on_shape(si.shape).is_none() {
                si.t = (si.p - ray.o).length() / ray.d.length();
                return (Some(si), rays);
            }
            let o = restir_geometry::offset_ray_origin(si.p, si.ng, ray.d);
            // What is left of a camera ray that ends at the far clip plane.
            let t_max = ray.t_max - (o - ray.o).dot(ray.d) / ray.d.length_squared();
            next = Ray { o, d: ray.d, t_max };
        }
        unreachable!("the loop returns at MAX_SKIPS")
    }

    /// Whether the segment `ray` up to `t_max` is blocked.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.accel.occluded(ray, t_max)
    }

    /// The BSDF of a surface point (its material with textures looked up there, and a bump
    /// map's normal from the height's gradient and the surface's derivatives there).
    #[inline]
    pub fn bsdf(&self, si: &SurfaceInteraction) -> Bsdf {
        let bsdf = self.shape_bsdf[si.shape as usize];
        self.bsdf_bumped(bsdf, &TexturePoint::of(si), self.bump_at(si))
    }

    /// The BSDF of every point of shape `shape` when it is the same everywhere (its material
    /// reads no texture and has no bump map): [`Scene::bsdf`] of any hit on it, without the
    /// hit. `None` when it varies over the shape.
    #[inline]
    pub fn uniform_bsdf(&self, shape: u32) -> Option<Bsdf> {
        let bsdf = self.shape_bsdf[shape as usize] as usize;
        if self.features.has_textures && self.bsdf_textures[bsdf].is_some() {
            return None;
        }
        Some(self.bsdfs[bsdf])
    }

    /// The diffuse reflectance of material `bsdf` at the point `at` names, its textures looked
    /// up ([`TexturedParams::diffuse_at`]): for a diffuse model whose other textures change
    /// nothing it holds (no mask, normal or bump map), [`Scene::bsdf_at`]'s `reflectance` there,
    /// without building the rest of the BSDF. `None` when the material's textures are not looked
    /// up (it has none, or the scene has none: [`SceneFeatures::has_textures`]).
    #[inline]
    pub fn textured_diffuse_at(&self, bsdf: u32, at: &TexturePoint) -> Option<Vec3> {
        if !self.features.has_textures {
            return None;
        }
        let t = self.bsdf_textures[bsdf as usize].as_ref()?;
        Some(t.diffuse_at(&self.textures, &self.shapes, at))
    }

    /// The normal-map texel a bump map gives at `si` (from the height's gradient, the
    /// surface's derivatives and its shading frame there: [`restir_materials::bump_normal`]),
    /// or `None` when the material of `si`'s shape has no bump map. With the hit's
    /// [`TexturePoint`] it is all [`Scene::bsdf_bumped`] needs to give [`Scene::bsdf`]'s BSDF
    /// later, without the hit.
    #[inline]
    pub fn bump_at(&self, si: &SurfaceInteraction) -> Option<Vec3> {
        if !self.features.has_textures {
            return None;
        }
        let bsdf = self.shape_bsdf[si.shape as usize];
        let (texture, scale) = self.bsdf_textures[bsdf as usize].as_ref()?.bump?;
        Some(self.bump_texel(texture, scale, si))
    }

    /// The normal-map texel of a bump map (height `texture` times `scale`) at `si`: Mitsuba's
    /// perturbed normal in the shading frame ([`restir_materials::bump_normal`]).
    fn bump_texel(&self, texture: u32, scale: f32, si: &SurfaceInteraction) -> Vec3 {
        let grad = self.textures[texture as usize]
            .eval_1_grad(si.uv)
            .unwrap_or(Vec2::ZERO);
        let (dp_du, dp_dv) = self.shapes[si.shape as usize].uv_derivatives(si.prim, si.param);
        let f = &si.shading;
        restir_materials::normal_texel(restir_materials::bump_normal(
            scale * grad,
            dp_du,
            dp_dv,
            [f.s, f.t, f.n],
            si.ng,
        ))
    }

    /// Material `bsdf` (an index into `bsdfs`) at lookup point `at` (texture coordinates, and
    /// the triangle and barycentrics a mesh attribute reads): the one place where textures are
    /// resolved. A scene without textures (decided at build time,
    /// [`SceneFeatures::has_textures`]) returns the stored BSDF without looking at `at`. A bump
    /// map's normal needs the surface's derivatives and shading frame, which `at` does not
    /// give: here it stays flat; [`Scene::bsdf`] (with the hit) and [`Scene::bsdf_bumped`]
    /// (with the texel [`Scene::bump_at`] gave at the hit) apply it.
    #[inline]
    pub fn bsdf_at(&self, bsdf: u32, at: &TexturePoint) -> Bsdf {
        self.bsdf_bumped(bsdf, at, None)
    }

    /// [`Scene::bsdf_at`] with a bump map's normal-map texel `bump` ([`Scene::bump_at`] of the
    /// hit `at` was taken from): the same BSDF as [`Scene::bsdf`] of that hit. `None` leaves a
    /// bump map flat; a material without a bump map ignores `bump`.
    #[inline]
    pub fn bsdf_bumped(&self, bsdf: u32, at: &TexturePoint, bump: Option<Vec3>) -> Bsdf {
        let base = self.bsdfs[bsdf as usize];
        if !self.features.has_textures {
            return base;
        }
        match &self.bsdf_textures[bsdf as usize] {
            None => base,
            Some(t) => self.textured(bsdf, t, at, bump.filter(|_| t.bump.is_some())),
        }
    }

    /// Material `bsdf` with its textures `t` looked up at `at`, and its normal map's texel
    /// replaced by `normal` (a bump map's, from the hit).
    #[inline]
    fn textured(
        &self,
        bsdf: u32,
        t: &TexturedParams,
        at: &TexturePoint,
        normal: Option<Vec3>,
    ) -> Bsdf {
        let mut p = t.eval(&self.textures, &self.shapes, at);
        if let Some(n) = normal {
            p.normal = n;
        }
        let mut b = self.bsdfs[bsdf as usize].with_params(&p);
        if let Some(w) = t.weight {
            b = b.with_blend_weight(self.textures[w as usize].eval_1_at(&self.shapes, at));
        }
        if t.principled.any() {
            t.principled.apply(b, &self.textures, &self.shapes, at)
        } else {
            b
        }
    }
}

/// The textured colour parameters of one material: texture indices into [`Scene::textures`]
/// per parameter, and the constant values of the others.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexturedParams {
    /// The constant parameters (used where no texture is given).
    pub base: ReflectanceParams,
    /// Texture of the diffuse reflectance (`reflectance`, `diffuse_reflectance`).
    pub diffuse: Option<u32>,
    /// Texture of `specular_reflectance`.
    pub specular: Option<u32>,
    /// Texture of `specular_transmittance`.
    pub transmittance: Option<u32>,
    /// Texture of a `mask`'s `opacity` (its luminance, as Mitsuba's scalar lookup).
    pub opacity: Option<u32>,
    /// Texture of a `normalmap`'s normal (raw values, not clamped).
    pub normal: Option<u32>,
    /// Texture of a microfacet roughness `alpha_u` (its luminance, as Mitsuba's scalar lookup).
    pub alpha_u: Option<u32>,
    /// Texture of `alpha_v`.
    pub alpha_v: Option<u32>,
    /// Textures of a principled material's parameters (its other slots are unused).
    pub principled: principled::PrincipledTextures,
    /// A `bumpmap`'s height texture and scale: its gradient perturbs the normal at each hit
    /// ([`Scene::bsdf`]; [`TexturedParams::eval`] leaves the normal flat).
    pub bump: Option<(u32, f32)>,
    /// Texture of a `blendbsdf`'s `weight` (its luminance, as Mitsuba's scalar lookup; clamped
    /// to `[0, 1]`).
    pub weight: Option<u32>,
}

impl TexturedParams {
    /// The parameters at `at` on `shapes` (the scene's, which mesh attributes read); texture
    /// values are clamped to `[0, 1]` (reflectances), but for the normal map's.
    #[inline]
    pub fn eval(
        &self,
        textures: &[Texture],
        shapes: &[Shape],
        at: &TexturePoint,
    ) -> ReflectanceParams {
        let look =
            |slot: Option<u32>, constant: Vec3| colour_at(textures, shapes, at, slot, constant);
        ReflectanceParams {
            diffuse: self.diffuse_at(textures, shapes, at),
            specular: look(self.specular, self.base.specular),
            transmittance: look(self.transmittance, self.base.transmittance),
            nonlinear: self.base.nonlinear,
            opacity: match self.opacity {
                Some(i) => textures[i as usize].eval_1_at(shapes, at),
                None => self.base.opacity,
            },
            normal: match self.normal {
                Some(i) => textures[i as usize].eval_at(shapes, at),
                None => self.base.normal,
            },
            alpha: match (self.alpha_u, self.alpha_v, self.base.alpha) {
                (None, None, a) => a,
                (u, v, a) => {
                    let (au, av) = a.unwrap_or((0.1, 0.1));
                    let scalar = |slot: Option<u32>, constant: f32| match slot {
                        Some(i) => textures[i as usize].eval_1_at(shapes, at),
                        None => constant,
                    };
                    Some((scalar(u, au), scalar(v, av)))
                }
            },
        }
    }

    /// The diffuse reflectance at `at`: [`TexturedParams::eval`]'s `diffuse` alone.
    #[inline]
    pub fn diffuse_at(&self, textures: &[Texture], shapes: &[Shape], at: &TexturePoint) -> Vec3 {
        colour_at(textures, shapes, at, self.diffuse, self.base.diffuse)
    }
}

/// A colour parameter at `at`: texture `slot`'s value clamped to `[0, 1]`, or `constant` where
/// the parameter has no texture.
#[inline]
fn colour_at(
    textures: &[Texture],
    shapes: &[Shape],
    at: &TexturePoint,
    slot: Option<u32>,
    constant: Vec3,
) -> Vec3 {
    match slot {
        Some(i) => textures[i as usize]
            .eval_at(shapes, at)
            .clamp(Vec3::ZERO, Vec3::ONE),
        None => constant,
    }
}
