//! Emitters and light selection for the `restir` renderer.
//!
//! - [`Light`]: diffuse area lights on shapes (one-sided, as in Mitsuba: they emit on the side their
//!   shading normal points to), point lights, directional lights, a constant environment and
//!   an image environment ([`EnvMap`], Mitsuba's `envmap`; its image lives in the [`LightSet`]).
//! - [`LightSet`]: every light of a scene and an alias table that picks lights proportionally to
//!   their power. [`LightSet::sample`] returns a [`LightSample`] whose `pdf_sa` already includes
//!   the selection probability; [`LightSet::pdf_sa`] returns exactly that density for a point
//!   reached another way (by BSDF sampling), and [`LightSet::pmf`] the selection probability.
//!
//! - [`LightSet::sample_hierarchy`]: the same lights picked for one receiver by a light hierarchy
//!   (`bvh.rs`, built on first use) with receiver-aware importance; its exact probabilities
//!   are [`LightSet::hierarchy_pmf`].
//!
//! Measures: `pdf_sa` is per unit solid angle at the receiving point; for delta lights (point,
//! directional) it is the discrete selection probability and `delta` is set.

mod bvh;
mod envmap;
mod table;

pub use envmap::{EnvMap, EnvMapError};

use bvh::LightBvh;
use core::f32::consts::PI;
use glam::{Vec2, Vec3};
use restir_geometry::area_to_solid_angle;
use restir_geometry::{PositionSample, Shape};
use restir_sampling::{luminance, warp};
use std::sync::{Arc, OnceLock};
use table::{Emitter, EmitterTable};

/// An emitter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Uniform radiance leaving the front side of a shape.
    Area {
        /// Index of the shape in the scene's shape list.
        shape: u32,
        /// Emitted radiance (linear RGB).
        radiance: Vec3,
    },
    /// An isotropic point light of intensity `intensity` (W/sr).
    Point {
        /// Position.
        position: Vec3,
        /// Radiant intensity.
        intensity: Vec3,
    },
    /// A directional light.
    Directional {
        /// Unit direction in which the light travels.
        direction: Vec3,
        /// Irradiance on a surface facing the light.
        irradiance: Vec3,
    },
    /// Constant radiance from every direction at infinity.
    Constant {
        /// Radiance.
        radiance: Vec3,
    },
    /// Radiance at infinity from a latitude-longitude image: the [`EnvMap`] given to
    /// [`LightSet::with_envmap`] (at most one per set).
    Envmap,
}

/// A point (or direction) on a light chosen for next-event estimation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Index of the light.
    pub light: u32,
    /// The point on the light (for lights at infinity, a far point along `wi`).
    pub p: Vec3,
    /// The light's shading normal at `p` (zero for point lights, `-wi` for lights at infinity);
    /// one-sided emission is judged against it.
    pub n: Vec3,
    /// The light's geometric normal at `p` (the one [`LightSet::pdf_sa`] takes).
    pub ng: Vec3,
    /// Unit direction from the receiver to the light.
    pub wi: Vec3,
    /// Distance to `p`; infinite for lights at infinity.
    pub dist: f32,
    /// Radiance (or, for point lights, intensity / distance²) arriving along `-wi`.
    pub le: Vec3,
    /// Density per unit solid angle at the receiver including the light-selection probability;
    /// for delta lights the selection probability alone.
    pub pdf_sa: f32,
    /// Whether the light is a delta light (no BSDF sampling can reach it).
    pub delta: bool,
    /// The primitive on the light's shape (area lights).
    pub prim: u32,
    /// Barycentrics or sphere parameters of `p` on the primitive (area lights); the
    /// environment's coordinates of the direction ([`LightSet::environment_param`]).
    pub param: Vec2,
}

/// A light sample drawn without a receiver ([`LightSet::presample`]): what a pool of presampled
/// candidates holds (RTXDI's presampled light tiles, Wyman and Panteleev 2021). Its density is
/// the power sampler's ([`LightSet::sample`]) expressed in the sample's own measure, so it does
/// not depend on where the sample will be seen from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Presampled {
    /// A point on an emissive triangle.
    Surface {
        /// Index of the light.
        light: u32,
        /// The triangle in the light's mesh.
        prim: u32,
        /// Barycentrics of the point.
        param: Vec2,
        /// Position.
        p: Vec3,
        /// Shading normal (one-sided emission is judged against it).
        n: Vec3,
        /// Geometric normal.
        ng: Vec3,
        /// Emitted radiance.
        le: Vec3,
        /// Density per unit area, the selection included.
        pdf_area: f32,
    },
    /// A point light.
    Point {
        /// Index of the light.
        light: u32,
        /// Position.
        p: Vec3,
        /// Radiant intensity.
        intensity: Vec3,
        /// Selection probability.
        pmf: f32,
    },
    /// A direction towards a light at infinity (the environment, or a directional light).
    Direction {
        /// Index of the light.
        light: u32,
        /// The environment's coordinates of the direction ([`LightSet::environment_param`];
        /// unused for a directional light).
        param: Vec2,
        /// Unit direction towards the light.
        wi: Vec3,
        /// Radiance (environment) or irradiance (directional light).
        le: Vec3,
        /// Density per unit solid angle, the selection included (the selection probability for a
        /// directional light).
        pdf: f32,
        /// Whether the light is a delta light (directional).
        delta: bool,
    },
    /// A light whose points are drawn per receiver ([`LightSet::sample_light`]: a sphere's by the
    /// cone it subtends), with its selection probability.
    Light {
        /// Index of the light.
        light: u32,
        /// Selection probability.
        pmf: f32,
    },
}

/// Why a light set could not be built.
#[derive(Clone, Debug, PartialEq)]
pub enum LightError {
    /// A light refers to a shape that does not exist.
    MissingShape(u32),
    /// A light has a negative or non-finite parameter.
    BadParameter(usize, &'static str),
    /// A second environment light (constant or envmap); a scene has at most one, as in Mitsuba.
    SecondEnvironment(usize),
    /// An `Envmap` light without an [`EnvMap`], or an [`EnvMap`] without an `Envmap` light.
    EnvmapMismatch,
}

impl core::fmt::Display for LightError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            LightError::MissingShape(s) => write!(f, "area light on missing shape {s}"),
            LightError::BadParameter(i, what) => {
                write!(f, "light {i}: {what} must be finite and non-negative")
            }
            LightError::SecondEnvironment(i) => write!(
                f,
                "light {i}: only one environment emitter (constant or envmap) is allowed per scene"
            ),
            LightError::EnvmapMismatch => {
                write!(f, "an envmap light needs exactly one environment image")
            }
        }
    }
}

impl std::error::Error for LightError {}

/// All lights of a scene with power-proportional selection.
#[derive(Clone, Debug)]
pub struct LightSet {
    lights: Vec<Light>,
    /// What a selection picks: every emissive triangle and every other light, and the
    /// environment with its share.
    table: EmitterTable,
    /// Per light: for area lights on meshes the area density of a selected point,
    /// `pmf / area`; zero otherwise.
    area_pdf: Vec<f32>,
    /// Each light's power (the selection weights).
    powers: Vec<f32>,
    /// Each light's bounding sphere; `None` for lights at infinity.
    spheres: Vec<Option<(Vec3, f32)>>,
    /// For each shape, the area light on it.
    shape_light: Vec<Option<u32>>,
    /// Per light, the area of its mesh (area lights on meshes; zero otherwise).
    mesh_areas: Vec<f32>,
    environment: Option<u32>,
    /// The image of the `Envmap` light, if there is one.
    envmap: Option<Arc<EnvMap>>,
    scene_radius: f32,
    /// The light hierarchy over the table's entries, built on first use.
    hierarchy: OnceLock<LightBvh>,
}

fn valid(v: Vec3) -> bool {
    v.is_finite() && v.min_element() >= 0.0
}

impl LightSet {
    /// Builds the set. `scene_bounds` sizes lights at infinity (directional power, shadow-ray
    /// length).
    pub fn new(
        lights: Vec<Light>,
        shapes: &[Shape],
        scene_bounds: (Vec3, Vec3),
    ) -> Result<Self, LightError> {
        Self::with_envmap(lights, None, shapes, scene_bounds)
    }

    /// Builds the set with the image of its [`Light::Envmap`] (which `lights` must then hold
    /// exactly once).
    pub fn with_envmap(
        lights: Vec<Light>,
        envmap: Option<EnvMap>,
        shapes: &[Shape],
        scene_bounds: (Vec3, Vec3),
    ) -> Result<Self, LightError> {
        let envmap_lights = lights.iter().filter(|l| **l == Light::Envmap).count();
        if envmap_lights != envmap.is_some() as usize {
            return Err(LightError::EnvmapMismatch);
        }
        let extent = scene_bounds.1 - scene_bounds.0;
        let scene_radius = if extent.is_finite() {
            (0.5 * extent.length()).max(1e-3)
        } else {
            1.0
        };
        let mut shape_light = vec![None; shapes.len()];
        let mut environment = None;
        let mut powers = Vec::with_capacity(lights.len());
        let mut spheres = Vec::with_capacity(lights.len());
        let mut mesh_areas = vec![0.0; lights.len()];
        for (i, l) in lights.iter().enumerate() {
            spheres.push(match *l {
                Light::Area { shape, .. } => shapes.get(shape as usize).map(bounding_sphere),
                Light::Point { position, .. } => Some((position, 0.0)),
                Light::Directional { .. } | Light::Constant { .. } | Light::Envmap => None,
            });
            let power = match *l {
                Light::Area { shape, radiance } => {
                    let s = shapes
                        .get(shape as usize)
                        .ok_or(LightError::MissingShape(shape))?;
                    if !valid(radiance) {
                        return Err(LightError::BadParameter(i, "radiance"));
                    }
                    shape_light[shape as usize] = Some(i as u32);
                    if let Shape::Mesh(m) = s {
                        mesh_areas[i] = m.area();
                    }
                    PI * s.area() * luminance(radiance)
                }
                Light::Point {
                    position,
                    intensity,
                } => {
                    if !valid(intensity) || !position.is_finite() {
                        return Err(LightError::BadParameter(i, "intensity"));
                    }
                    4.0 * PI * luminance(intensity)
                }
                Light::Directional {
                    direction,
                    irradiance,
                } => {
                    if !valid(irradiance) || !direction.is_finite() || direction == Vec3::ZERO {
                        return Err(LightError::BadParameter(i, "irradiance"));
                    }
                    PI * scene_radius * scene_radius * luminance(irradiance)
                }
                Light::Constant { radiance } => {
                    if !valid(radiance) {
                        return Err(LightError::BadParameter(i, "radiance"));
                    }
                    if environment.replace(i as u32).is_some() {
                        return Err(LightError::SecondEnvironment(i));
                    }
                    // π R² · ∫ lum(L) dω with ∫ = 4π·lum(L).
                    4.0 * PI * PI * scene_radius * scene_radius * luminance(radiance)
                }
                Light::Envmap => {
                    if environment.replace(i as u32).is_some() {
                        return Err(LightError::SecondEnvironment(i));
                    }
                    let map = envmap.as_ref().ok_or(LightError::EnvmapMismatch)?;
                    PI * scene_radius * scene_radius * map.luminance_integral()
                }
            };
            powers.push(if power.is_finite() { power } else { 0.0 });
        }
        let lights: Vec<Light> = lights
            .into_iter()
            .map(|l| match l {
                Light::Directional {
                    direction,
                    irradiance,
                } => Light::Directional {
                    direction: direction.normalize(),
                    irradiance,
                },
                l => l,
            })
            .collect();
        let table = EmitterTable::new(&lights, shapes, &powers, environment);
        let mut set = Self {
            area_pdf: vec![0.0; lights.len()],
            lights,
            table,
            powers,
            spheres,
            shape_light,
            environment,
            envmap: envmap.map(Arc::new),
            scene_radius,
            mesh_areas,
            hierarchy: OnceLock::new(),
        };
        set.update_area_pdfs();
        Ok(set)
    }

    fn update_area_pdfs(&mut self) {
        for (i, pdf) in self.area_pdf.iter_mut().enumerate() {
            let area = self.mesh_areas[i];
            *pdf = if area > 0.0 {
                self.table.pmf(i as u32) / area
            } else {
                0.0
            };
        }
    }

    /// Sets the share of light selections that go to the environment (constant or image
    /// environment light), the rest going to the local emitters by power. The default is the
    /// environment's power share, which overrates an environment that walls block; a scene
    /// builder that can see what receivers get decides a better share once. Ignored without an
    /// environment or without local lights.
    pub fn set_environment_share(&mut self, share: f32) {
        self.table.set_env_share(share);
        self.update_area_pdfs();
    }

    /// The share of light selections that go to the environment.
    pub fn environment_share(&self) -> f32 {
        self.table.env_share()
    }

    /// The environment's share of the lights' power (the default environment share).
    pub fn environment_power_share(&self) -> f32 {
        self.table.env_power_share()
    }

    /// Number of entries a selection picks from besides the environment: one per emissive
    /// triangle and one per other light with power.
    pub fn emitter_count(&self) -> usize {
        self.table.len()
    }

    /// The lights.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.lights.len()
    }

    /// Whether there are no lights (or none with power).
    pub fn is_empty(&self) -> bool {
        self.table.is_empty()
    }

    /// The area light on shape `shape`, if any.
    #[inline]
    pub fn light_on_shape(&self, shape: u32) -> Option<u32> {
        self.shape_light.get(shape as usize).copied().flatten()
    }

    /// The environment light, if any (radiance for rays that leave the scene).
    pub fn environment(&self) -> Option<u32> {
        self.environment
    }

    /// The image of the [`Light::Envmap`] light, if there is one.
    pub fn envmap(&self) -> Option<&EnvMap> {
        self.envmap.as_deref()
    }

    /// Radius of the scene's bounding sphere.
    pub fn scene_radius(&self) -> f32 {
        self.scene_radius
    }

    /// Picks a light: `(index, probability)`, the probability being [`LightSet::pmf`].
    #[inline]
    pub fn select(&self, u: f32) -> Option<(u32, f32)> {
        let light = match self.table.pick(u)? {
            Ok(e) => e.light(),
            Err(env) => env,
        };
        Some((light, self.table.pmf(light)))
    }

    /// The power (selection weight) of light `light`: `π·A·lum(L)` for area lights, `4π·lum(I)`
    /// for point lights, and the power through the scene's bounding sphere for lights at
    /// infinity (`π·R²·lum(E)` for directional lights, `π·R²·∫lum(L)dω` for environments).
    pub fn power(&self, light: u32) -> f32 {
        self.powers[light as usize]
    }

    /// A sphere bounding light `light` (centre, radius); `None` for lights at infinity.
    pub fn bounding_sphere(&self, light: u32) -> Option<(Vec3, f32)> {
        self.spheres[light as usize]
    }

    /// [`LightSet::sample`]'s density per unit area on mesh light `light`, the selection
    /// included (the same everywhere on the mesh); `None` for other lights (a sphere's points are
    /// drawn from the receiver).
    #[inline]
    pub fn mesh_area_density(&self, shapes: &[Shape], light: u32) -> Option<f32> {
        match self.lights.get(light as usize)? {
            Light::Area { shape, .. } if matches!(shapes[*shape as usize], Shape::Mesh(_)) => {
                Some(self.area_pdf[light as usize])
            }
            _ => None,
        }
    }

    /// Probability that [`LightSet::sample`] picks light `light` (for a mesh, any of its
    /// triangles).
    #[inline]
    pub fn pmf(&self, light: u32) -> f32 {
        self.table.pmf(light)
    }

    /// Radiance leaving an area light's surface point with shading normal `n` towards unit `w`
    /// (pointing away from the light). One-sided: zero behind the surface.
    #[inline]
    pub fn area_radiance(&self, light: u32, n: Vec3, w: Vec3) -> Vec3 {
        match self.lights[light as usize] {
            Light::Area { radiance, .. } if n.dot(w) > 0.0 => radiance,
            _ => Vec3::ZERO,
        }
    }

    /// The coordinates by which the environment names direction `d` (unit, away from the
    /// scene): an environment map's `(u, v)`, a constant environment's the same lat-long
    /// coordinates in the world frame. [`LightSet::environment_at`] maps them back.
    #[inline]
    pub fn environment_param(&self, d: Vec3) -> Vec2 {
        match (
            self.environment.map(|i| self.lights[i as usize]),
            &self.envmap,
        ) {
            (Some(Light::Envmap), Some(m)) => m.uv_of(d),
            _ => EnvMap::local_to_uv(d),
        }
    }

    /// The environment at coordinates `param` ([`LightSet::environment_param`]): the direction
    /// towards it, its radiance there and [`LightSet::sample`]'s density of that direction per
    /// unit solid angle, the selection included. Cheaper than looking up a direction: no
    /// inverse trigonometry.
    #[inline]
    pub fn environment_at(&self, param: Vec2) -> Option<(Vec3, Vec3, f32)> {
        let env = self.environment?;
        let pmf = self.table.pmf(env);
        match (self.lights[env as usize], &self.envmap) {
            (Light::Constant { radiance }, _) => Some((
                EnvMap::uv_to_local(param),
                radiance,
                pmf * warp::UNIFORM_SPHERE_PDF,
            )),
            (Light::Envmap, Some(m)) => Some((
                m.world_direction(param),
                m.eval_uv(param),
                pmf * m.pdf_uv(param),
            )),
            _ => None,
        }
    }

    /// Radiance arriving from the environment along a ray that left the scene in direction `d`
    /// (unit, pointing away from the scene).
    #[inline]
    pub fn environment_radiance(&self, d: Vec3) -> Vec3 {
        match self.environment.map(|i| self.lights[i as usize]) {
            Some(Light::Constant { radiance }) => radiance,
            Some(Light::Envmap) => self.envmap.as_ref().map_or(Vec3::ZERO, |m| m.eval(d)),
            _ => Vec3::ZERO,
        }
    }

    /// Picks a light by power (`u_select`) and a point on it (`u`) as seen from `ref_p`.
    #[inline]
    pub fn sample(
        &self,
        shapes: &[Shape],
        ref_p: Vec3,
        u_select: f32,
        u: Vec2,
    ) -> Option<LightSample> {
        let light = match self.table.pick(u_select)? {
            Ok(e @ Emitter::Triangle { .. }) => return self.sample_triangle(shapes, e, ref_p, u),
            Ok(&Emitter::Whole { light }) => light,
            Err(env) => env,
        };
        let mut s = self.sample_light(shapes, light, ref_p, u)?;
        s.pdf_sa *= self.table.pmf(light);
        Some(s)
    }

    /// What [`LightSet::sample`] draws with the same numbers, as far as it does not depend on
    /// the receiver ([`Presampled`]): the point of a triangle, a point light, the direction of a
    /// light at infinity; a sphere light only picked. `None` where nothing can be sampled.
    pub fn presample(&self, shapes: &[Shape], u_select: f32, u: Vec2) -> Option<Presampled> {
        let light = match self.table.pick(u_select)? {
            Ok(&Emitter::Triangle {
                light,
                prim,
                ref p,
                ng,
                n,
                smooth,
            }) => {
                let Light::Area { shape, radiance } = self.lights[light as usize] else {
                    return None;
                };
                let ps =
                    Emitter::triangle_point(p, ng, n, smooth, &shapes[shape as usize], prim, u);
                return Some(Presampled::Surface {
                    light,
                    prim,
                    param: ps.param,
                    p: ps.p,
                    n: ps.n,
                    ng: ps.ng,
                    le: radiance,
                    pdf_area: self.area_pdf[light as usize],
                });
            }
            Ok(&Emitter::Whole { light }) => light,
            Err(env) => env,
        };
        let pmf = self.table.pmf(light);
        match self.lights[light as usize] {
            Light::Area { .. } => Some(Presampled::Light { light, pmf }),
            Light::Point {
                position,
                intensity,
            } => Some(Presampled::Point {
                light,
                p: position,
                intensity,
                pmf,
            }),
            Light::Directional { .. } | Light::Constant { .. } | Light::Envmap => {
                let s = self.sample_light(shapes, light, Vec3::ZERO, u)?;
                Some(Presampled::Direction {
                    light,
                    param: s.param,
                    wi: s.wi,
                    le: s.le,
                    pdf: s.pdf_sa * pmf,
                    delta: s.delta,
                })
            }
        }
    }

    /// A uniform point on an emissive triangle the table picked, with the selection in its
    /// density.
    #[inline]
    fn sample_triangle(
        &self,
        shapes: &[Shape],
        e: &Emitter,
        ref_p: Vec3,
        u: Vec2,
    ) -> Option<LightSample> {
        let Emitter::Triangle {
            light,
            prim,
            ref p,
            ng,
            n,
            smooth,
        } = *e
        else {
            return None;
        };
        let Light::Area { shape, radiance } = self.lights[light as usize] else {
            return None;
        };
        let ps = Emitter::triangle_point(p, ng, n, smooth, &shapes[shape as usize], prim, u);
        let pdf_sa = area_to_solid_angle(self.area_pdf[light as usize], ref_p, ps.p, ps.ng)?;
        area_light_sample(light, radiance, ref_p, ps, pdf_sa)
    }

    /// The point of area light `light`, whose shape is `shape`, named by primitive `prim` and
    /// parameters `param` (barycentrics on a triangle, sphere parameters): the same bits as
    /// [`Shape::position_at`]. A triangle of a light whose mesh is in the emitter table is read
    /// from its table entry (corners and normals inline: one lookup instead of the chain shape →
    /// indices → positions).
    #[inline]
    pub fn area_point(&self, shape: &Shape, light: u32, prim: u32, param: Vec2) -> PositionSample {
        match self.table.triangle_entry(light, prim) {
            Some(&Emitter::Triangle {
                ref p,
                ng,
                n,
                smooth,
                ..
            }) => Emitter::point_at(p, ng, n, smooth, shape, prim, param),
            _ => shape.position_at(prim, param),
        }
    }

    /// Samples a point on light `light` as seen from `ref_p`, with `pdf_sa` *not* including the
    /// selection probability.
    #[inline]
    pub fn sample_light(
        &self,
        shapes: &[Shape],
        light: u32,
        ref_p: Vec3,
        u: Vec2,
    ) -> Option<LightSample> {
        match self.lights[light as usize] {
            Light::Area { shape, radiance } => {
                let (ps, pdf_sa) = shapes[shape as usize].sample_from(ref_p, u)?;
                area_light_sample(light, radiance, ref_p, ps, pdf_sa)
            }
            Light::Point {
                position,
                intensity,
            } => {
                let to = position - ref_p;
                let d2 = to.length_squared();
                if d2 <= 0.0 {
                    return None;
                }
                let dist = d2.sqrt();
                Some(LightSample {
                    light,
                    p: position,
                    n: Vec3::ZERO,
                    ng: Vec3::ZERO,
                    wi: to / dist,
                    dist,
                    le: intensity / d2,
                    pdf_sa: 1.0,
                    delta: true,
                    prim: 0,
                    param: Vec2::ZERO,
                })
            }
            Light::Directional {
                direction,
                irradiance,
            } => Some(LightSample {
                light,
                p: ref_p - direction * (2.0 * self.scene_radius),
                n: direction,
                ng: direction,
                wi: -direction,
                dist: f32::INFINITY,
                le: irradiance,
                pdf_sa: 1.0,
                delta: true,
                prim: 0,
                param: Vec2::ZERO,
            }),
            Light::Constant { radiance } => {
                let wi = warp::sample_uniform_sphere(u);
                Some(LightSample {
                    light,
                    p: ref_p + wi * (2.0 * self.scene_radius),
                    n: -wi,
                    ng: -wi,
                    wi,
                    dist: f32::INFINITY,
                    le: radiance,
                    pdf_sa: warp::UNIFORM_SPHERE_PDF,
                    delta: false,
                    prim: 0,
                    param: EnvMap::local_to_uv(wi),
                })
            }
            Light::Envmap => {
                let (uv, wi, le, pdf_sa) = self.envmap.as_ref()?.sample_uv(u)?;
                Some(LightSample {
                    light,
                    p: ref_p + wi * (2.0 * self.scene_radius),
                    n: -wi,
                    ng: -wi,
                    wi,
                    dist: f32::INFINITY,
                    le,
                    pdf_sa,
                    delta: false,
                    prim: 0,
                    param: uv,
                })
            }
        }
    }

    /// The light hierarchy over the table's entries (built on the first call; `shapes` are the
    /// scene's, as for every other call).
    fn hierarchy(&self, shapes: &[Shape]) -> &LightBvh {
        self.hierarchy.get_or_init(|| {
            LightBvh::new(
                &self.lights,
                shapes,
                self.table.entries(),
                self.table.weights(),
            )
        })
    }

    /// Builds the light hierarchy now (else the first [`LightSet::sample_hierarchy`] does);
    /// returns its node count.
    pub fn build_hierarchy(&self, shapes: &[Shape]) -> usize {
        self.hierarchy(shapes).node_count()
    }

    /// Picks a light for a receiver at `ref_p` with normal `ref_n` (zero if unknown) by the
    /// light hierarchy (`u_select ∈ [0, 1)`, the environment keeping its share), and a point on
    /// it (`u`). Returns the sample, whose `pdf_sa` includes the hierarchy's selection
    /// probability, and the density [`LightSet::sample`] (power selection) would give the same
    /// point. `None` if nothing can light the receiver or the point is on a back face.
    #[inline]
    pub fn sample_hierarchy(
        &self,
        shapes: &[Shape],
        ref_p: Vec3,
        ref_n: Vec3,
        u_select: f64,
        u: Vec2,
    ) -> Option<(LightSample, f32)> {
        let share = self.table.env_share() as f64;
        if let Some(env) = self.environment
            && u_select < share
        {
            let s = self.sample_light(shapes, env, ref_p, u)?;
            let pdf = s.pdf_sa * self.table.pmf(env);
            return Some((LightSample { pdf_sa: pdf, ..s }, pdf));
        }
        let v = if share > 0.0 {
            ((u_select - share) / (1.0 - share)).clamp(0.0, 1.0 - f64::EPSILON)
        } else {
            u_select
        };
        let (entry, pmf) = self.hierarchy(shapes).sample(ref_p, ref_n, v)?;
        let pmf = pmf * (1.0 - self.table.env_share());
        match self.table.entries()[entry as usize] {
            Emitter::Triangle {
                light,
                prim,
                ref p,
                ng,
                n,
                smooth,
            } => {
                let Light::Area { shape, radiance } = self.lights[light as usize] else {
                    return None;
                };
                let ps =
                    Emitter::triangle_point(p, ng, n, smooth, &shapes[shape as usize], prim, u);
                let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
                let pdf_sa = area_to_solid_angle(pmf / area, ref_p, ps.p, ps.ng)?;
                let power_pdf =
                    area_to_solid_angle(self.area_pdf[light as usize], ref_p, ps.p, ps.ng)?;
                Some((
                    area_light_sample(light, radiance, ref_p, ps, pdf_sa)?,
                    power_pdf,
                ))
            }
            Emitter::Whole { light } => {
                let s = self.sample_light(shapes, light, ref_p, u)?;
                let power_pdf = s.pdf_sa * self.table.pmf(light);
                Some((
                    LightSample {
                        pdf_sa: s.pdf_sa * pmf,
                        ..s
                    },
                    power_pdf,
                ))
            }
        }
    }

    /// Picks a local entry (an emissive triangle or another light; the environment aside) for a
    /// receiver at `ref_p` with normal `ref_n` by the light hierarchy: `(entry, probability)`,
    /// the probability among local entries. The entries are numbered `0..emitter_count()`.
    pub fn hierarchy_select(
        &self,
        shapes: &[Shape],
        ref_p: Vec3,
        ref_n: Vec3,
        u: f64,
    ) -> Option<(usize, f32)> {
        let (e, pmf) = self.hierarchy(shapes).sample(ref_p, ref_n, u)?;
        Some((e as usize, pmf))
    }

    /// The probability that [`LightSet::hierarchy_select`] picks local entry `entry` for a
    /// receiver at `ref_p` with normal `ref_n` (a second descent of the hierarchy, exact: the
    /// same factors as the sampling descent multiplies).
    pub fn hierarchy_pmf(&self, shapes: &[Shape], ref_p: Vec3, ref_n: Vec3, entry: usize) -> f32 {
        self.hierarchy(shapes).pmf(ref_p, ref_n, entry as u32)
    }

    /// The probability that the power table picks local entry `entry` among the local entries.
    pub fn entry_power_pmf(&self, entry: usize) -> f32 {
        let w = self.table.weights();
        let total: f64 = w.iter().map(|&x| x as f64).sum();
        w.get(entry).map_or(0.0, |&x| (x as f64 / total) as f32)
    }

    /// The light local entry `entry` belongs to.
    pub fn entry_light(&self, entry: usize) -> u32 {
        self.table.entries()[entry].light()
    }

    /// The local entry of light `light`'s primitive `prim` (a triangle of a mesh light; `prim`
    /// is ignored for other lights): entries are ordered by light, then by triangle.
    pub fn entry_of(&self, light: u32, prim: u32) -> Option<usize> {
        let key = |e: &Emitter| match *e {
            Emitter::Triangle { light, prim, .. } => (light, prim),
            Emitter::Whole { light } => (light, 0),
        };
        let prim = match self.table.entries().iter().find(|e| e.light() == light)? {
            Emitter::Triangle { .. } => prim,
            Emitter::Whole { .. } => 0,
        };
        self.table
            .entries()
            .binary_search_by(|e| key(e).cmp(&(light, prim)))
            .ok()
    }

    /// The solid-angle density, including the selection probability, with which
    /// [`LightSet::sample`] would return point `p` (geometric normal `n`) on light `light` from `ref_p`; for
    /// the environment `p` is ignored and `n` must be the direction back from the environment
    /// (`−wi`, as [`LightSample::ng`] is). Zero for delta lights.
    #[inline]
    pub fn pdf_sa(&self, shapes: &[Shape], light: u32, ref_p: Vec3, p: Vec3, n: Vec3) -> f32 {
        let pmf = self.pmf(light);
        if pmf == 0.0 {
            return 0.0;
        }
        match self.lights[light as usize] {
            Light::Area { shape, .. } => match &shapes[shape as usize] {
                Shape::Mesh(_) => {
                    area_to_solid_angle(self.area_pdf[light as usize], ref_p, p, n).unwrap_or(0.0)
                }
                s => pmf * s.pdf_sa_from(ref_p, p, n),
            },
            Light::Constant { .. } => pmf * warp::UNIFORM_SPHERE_PDF,
            Light::Envmap => self
                .envmap
                .as_ref()
                .map_or(0.0, |m| pmf * m.pdf(-n.normalize_or_zero())),
            Light::Point { .. } | Light::Directional { .. } => 0.0,
        }
    }
}

/// The sample of area light `light` (radiance `radiance`) at point `ps` seen from `ref_p`, with
/// solid-angle density `pdf_sa`; `None` at the receiver itself or behind the one-sided emitter.
#[inline]
fn area_light_sample(
    light: u32,
    radiance: Vec3,
    ref_p: Vec3,
    ps: PositionSample,
    pdf_sa: f32,
) -> Option<LightSample> {
    let to = ps.p - ref_p;
    let dist = to.length();
    if dist <= 0.0 {
        return None;
    }
    let wi = to / dist;
    if ps.n.dot(wi) >= 0.0 {
        return None; // back of a one-sided emitter
    }
    Some(LightSample {
        light,
        p: ps.p,
        n: ps.n,
        ng: ps.ng,
        wi,
        dist,
        le: radiance,
        pdf_sa,
        delta: false,
        prim: ps.prim,
        param: ps.param,
    })
}

/// A sphere around a shape (for meshes, around its bounding box).
fn bounding_sphere(shape: &Shape) -> (Vec3, f32) {
    match shape {
        Shape::Sphere(s) => (s.center, s.radius),
        Shape::Mesh(m) => {
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for i in 0..m.triangle_count() {
                for p in m.triangle(i) {
                    lo = lo.min(p);
                    hi = hi.max(p);
                }
            }
            if lo.cmple(hi).all() {
                (0.5 * (lo + hi), 0.5 * (hi - lo).length())
            } else {
                (Vec3::ZERO, 0.0)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use restir_geometry::Sphere;
    use restir_sampling::Pcg32;

    fn setup() -> (Vec<Shape>, LightSet) {
        let mut quad = Shape::rectangle();
        quad.transform(&glam::Affine3A::from_rotation_translation(
            glam::Quat::from_rotation_x(PI),
            Vec3::new(0.0, 0.0, 2.0),
        ));
        let shapes = vec![
            Shape::Mesh(quad),
            Shape::Sphere(Sphere::new(Vec3::new(2.0, 0.0, 1.0), 0.3, false)),
        ];
        let lights = vec![
            Light::Area {
                shape: 0,
                radiance: Vec3::splat(1.0),
            },
            Light::Area {
                shape: 1,
                radiance: Vec3::new(5.0, 1.0, 1.0),
            },
            Light::Point {
                position: Vec3::new(0.0, 1.0, 1.0),
                intensity: Vec3::splat(3.0),
            },
        ];
        let set = LightSet::new(lights, &shapes, (Vec3::splat(-3.0), Vec3::splat(3.0))).unwrap();
        (shapes, set)
    }

    /// A set whose only light with power is one of several skips the alias table: that light is
    /// always picked with probability 1, the others never, and `sample` agrees with `pdf_sa`.
    #[test]
    fn single_light_selection() {
        let (shapes, _) = setup();
        let lights = vec![
            Light::Area {
                shape: 0,
                radiance: Vec3::ZERO,
            },
            Light::Area {
                shape: 1,
                radiance: Vec3::new(5.0, 1.0, 1.0),
            },
        ];
        let set = LightSet::new(lights, &shapes, (Vec3::splat(-3.0), Vec3::splat(3.0))).unwrap();
        assert_eq!(set.emitter_count(), 1);
        assert_eq!((set.pmf(0), set.pmf(1)), (0.0, 1.0));
        let mut rng = Pcg32::new(5, 0);
        for _ in 0..1000 {
            let u = rng.next_f32();
            assert_eq!(set.select(u), Some((1, 1.0)));
            if let Some(s) = set.sample(&shapes, Vec3::ZERO, u, rng.next_2d()) {
                let pdf = set.pdf_sa(&shapes, 1, Vec3::ZERO, s.p, s.ng);
                assert!(
                    (pdf - s.pdf_sa).abs() <= 1e-3 * pdf,
                    "{pdf} vs {}",
                    s.pdf_sa
                );
            }
        }
        let empty = LightSet::new(vec![], &shapes, (Vec3::splat(-3.0), Vec3::splat(3.0))).unwrap();
        assert!(empty.is_empty() && empty.select(0.5).is_none());
    }

    /// The pdf a sample reports equals what `pdf_sa` recomputes, and the empirical selection
    /// frequencies match `pmf` within 4 standard errors.
    #[test]
    fn sample_pdf_pmf_agree() {
        let (shapes, set) = setup();
        let mut rng = Pcg32::new(11, 0);
        let n = 200_000;
        let mut counts = [0u32; 3];
        for _ in 0..n {
            let (us, u) = (rng.next_f32(), rng.next_2d());
            let Some((index, _)) = set.select(us) else {
                panic!()
            };
            let index = index as usize;
            counts[index] += 1;
            if let Some(s) = set.sample(&shapes, Vec3::ZERO, us, u) {
                assert_eq!(s.light as usize, index);
                if s.delta {
                    assert!((s.pdf_sa - set.pmf(s.light)).abs() < 1e-6);
                } else {
                    let pdf = set.pdf_sa(&shapes, s.light, Vec3::ZERO, s.p, s.ng);
                    assert!(
                        (pdf - s.pdf_sa).abs() <= 1e-3 * pdf,
                        "{pdf} vs {}",
                        s.pdf_sa
                    );
                }
            }
        }
        for (i, c) in counts.iter().enumerate() {
            let p = set.pmf(i as u32) as f64;
            let se = (p * (1.0 - p) / n as f64).sqrt();
            assert!((*c as f64 / n as f64 - p).abs() < 4.0 * se, "light {i}");
        }
        let total: f32 = (0..3).map(|i| set.pmf(i)).sum();
        assert!((total - 1.0).abs() < 1e-5);
    }

    /// With an environment beside local lights, the environment takes exactly its share of
    /// selections and the local lights split the rest by power; `pmf`, `select`, `sample` and
    /// `pdf_sa` agree whatever the share, and a triangle of a mesh light is picked with the
    /// mesh's pmf times its area fraction.
    #[test]
    fn environment_share_splits_selection() {
        let (shapes, _) = setup();
        let lights = vec![
            Light::Area {
                shape: 0,
                radiance: Vec3::splat(1.0),
            },
            Light::Constant {
                radiance: Vec3::splat(0.2),
            },
            Light::Area {
                shape: 1,
                radiance: Vec3::new(5.0, 1.0, 1.0),
            },
        ];
        let mut set =
            LightSet::new(lights, &shapes, (Vec3::splat(-3.0), Vec3::splat(3.0))).unwrap();
        let power_share = set.environment_power_share();
        assert!((set.pmf(1) - power_share).abs() < 1e-6);
        assert_eq!(set.emitter_count(), 3, "two triangles and a sphere");
        for share in [0.3f32, 0.01, 0.99] {
            set.set_environment_share(share);
            assert_eq!(set.environment_share(), share);
            assert!((set.pmf(1) - share).abs() < 1e-7);
            let local = set.pmf(0) + set.pmf(2);
            assert!((local - (1.0 - share)).abs() < 1e-6, "{local}");
            let ratio = set.pmf(0) / set.pmf(2);
            let want = set.power(0) / set.power(2);
            assert!((ratio - want).abs() < 1e-4 * want, "{ratio} vs {want}");
            let mut rng = Pcg32::new(31, 0);
            let n = 100_000;
            let mut counts = [0u32; 3];
            for _ in 0..n {
                let (us, u) = (rng.next_f32(), rng.next_2d());
                let (light, pmf) = set.select(us).unwrap();
                assert_eq!(pmf, set.pmf(light));
                counts[light as usize] += 1;
                if let Some(s) = set.sample(&shapes, Vec3::ZERO, us, u) {
                    assert_eq!(s.light, light);
                    let pdf = set.pdf_sa(&shapes, s.light, Vec3::ZERO, s.p, s.ng);
                    assert!(
                        (pdf - s.pdf_sa).abs() <= 1e-3 * pdf,
                        "{pdf} vs {}",
                        s.pdf_sa
                    );
                }
            }
            for (i, c) in counts.iter().enumerate() {
                let p = set.pmf(i as u32) as f64;
                let se = (p * (1.0 - p) / n as f64).sqrt().max(1e-9);
                assert!(
                    (*c as f64 / n as f64 - p).abs() < 4.0 * se,
                    "light {i} at share {share}"
                );
            }
        }
    }

    /// ∫ over the light of Le·cos/pdf estimates the irradiance of a unit-radiance quad seen head-on,
    /// checked against the closed-form form factor of a square.
    #[test]
    fn area_sampling_estimates_irradiance() {
        let (shapes, set) = setup();
        let mut rng = Pcg32::new(12, 0);
        let n = 100_000;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let v = set
                .sample_light(&shapes, 0, Vec3::ZERO, rng.next_2d())
                .map_or(0.0, |s| (s.le.x * s.wi.z / s.pdf_sa) as f64);
            sum += v;
            sum2 += v * v;
        }
        let mean = sum / n as f64;
        let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
        // Irradiance at distance h below the centre of a 2a×2a square of unit radiance:
        // four corner rectangles, each contributing (1/2)·[x/√(x²+h²)·atan(y/√(x²+h²)) + (x↔y)].
        let (a, h) = (1.0f64, 2.0f64);
        let fa = |x: f64, y: f64| {
            x / (x * x + h * h).sqrt() * (y / (x * x + h * h).sqrt()).atan()
                + y / (y * y + h * h).sqrt() * (x / (y * y + h * h).sqrt()).atan()
        };
        let exact = 2.0 * fa(a, a);
        assert!(
            (mean - exact).abs() < 4.0 * se,
            "{mean} vs {exact} (se {se})"
        );
    }
}
