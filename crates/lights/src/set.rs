//! The light set: every light of a scene with the shapes area lights lie on, the power of each,
//! and the emitter table a selection picks from (`table.rs`). Construction, the environment's
//! share of selections, and what the set knows of each light.

use core::f32::consts::PI;
use std::sync::{Arc, OnceLock};

use glam::Vec3;
use restir_geometry::Shape;
use restir_sampling::luminance;

use crate::bvh::LightBvh;
use crate::light::bounding_sphere;
use crate::table::EmitterTable;
use crate::{EnvMap, Light, LightTexture};

/// Why a light set could not be built.
#[derive(Clone, Debug, PartialEq)]
pub enum LightError {
    /// A light refers to a shape that does not exist.
    MissingShape(u32),
    /// A light has a negative or non-finite parameter.
    BadParameter(usize, &'static str),
    /// A second environment light (constant or envmap); a scene has at most one, as in Mitsuba.
    SecondEnvironment(usize),
    /// A light whose emission or power exceeds [`crate::MAX_EMISSION`] (what, and the value).
    TooBright(usize, &'static str, f32),
    /// An `Envmap` light without an [`EnvMap`], or an [`EnvMap`] without an `Envmap` light.
    EnvmapMismatch,
    /// An area light, a spot light or a projector names a texture the set was not given
    /// (light, texture index).
    MissingLightTexture(usize, u32),
}

impl core::fmt::Display for LightError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            LightError::MissingShape(s) => write!(f, "area light on missing shape {s}"),
            LightError::BadParameter(i, what) => {
                write!(f, "light {i}: {what} must be finite and non-negative")
            }
            LightError::TooBright(i, what, v) => write!(
                f,
                "light {i}: {what} {v:e} exceeds the largest emission this renderer computes with, {:e} (products with geometry terms and sample weights would overflow)",
                crate::MAX_EMISSION
            ),
            LightError::SecondEnvironment(i) => write!(
                f,
                "light {i}: only one environment emitter (constant or envmap) is allowed per scene"
            ),
            LightError::EnvmapMismatch => {
                write!(f, "an envmap light needs exactly one environment image")
            }
            LightError::MissingLightTexture(i, t) => {
                write!(f, "light {i}: texture {t} was not given to the light set")
            }
        }
    }
}

impl std::error::Error for LightError {}

/// All lights of a scene with power-proportional selection.
#[derive(Clone, Debug)]
pub struct LightSet {
    /// The scene's shapes (area lights name theirs by index).
    pub(crate) shapes: Arc<[Shape]>,
    pub(crate) lights: Vec<Light>,
    /// What a selection picks: every emissive triangle and every other light, and the
    /// environment with its share.
    pub(crate) table: EmitterTable,
    /// Per light: for area lights on meshes the area density of a selected point,
    /// `pmf / area`; zero otherwise.
    pub(crate) area_pdf: Vec<f32>,
    /// Each light's power (the selection weights).
    pub(crate) powers: Vec<f32>,
    /// Each light's bounding sphere; `None` for lights at infinity.
    pub(crate) spheres: Vec<Option<(Vec3, f32)>>,
    /// For each shape, the area light on it.
    pub(crate) shape_light: Vec<Option<u32>>,
    /// Per light, the area of its mesh (area lights on meshes; zero otherwise).
    pub(crate) mesh_areas: Vec<f32>,
    pub(crate) environment: Option<u32>,
    /// The image of the `Envmap` light, if there is one.
    pub(crate) envmap: Option<Arc<EnvMap>>,
    /// The textures area lights emit and spot lights and projectors project (their `texture`
    /// indexes them).
    pub(crate) light_textures: Vec<Arc<dyn LightTexture>>,
    pub(crate) scene_radius: f32,
    /// The light hierarchy over the table's entries, built on first use.
    pub(crate) hierarchy: OnceLock<LightBvh>,
    /// Per light, where shadow rays toward it may end ([`LightSet::shadow_end`]).
    pub(crate) clear: Vec<Option<crate::clear::LightClear>>,
}

fn valid(v: Vec3) -> bool {
    v.is_finite() && v.min_element() >= 0.0
}

impl LightSet {
    /// Builds the set. `shapes` are all of the scene's shapes, occluders included (area lights
    /// name theirs by index, and [`LightSet::shadow_end`] is exact only when nothing else can
    /// block a ray). `scene_bounds` sizes lights at infinity (directional power, shadow-ray
    /// length).
    pub fn new(
        lights: Vec<Light>,
        shapes: impl Into<Arc<[Shape]>>,
        scene_bounds: (Vec3, Vec3),
    ) -> Result<Self, LightError> {
        Self::with_envmap(lights, None, shapes, scene_bounds)
    }

    /// Builds the set with the image of its [`Light::Envmap`] (which `lights` must then hold
    /// exactly once).
    pub fn with_envmap(
        lights: Vec<Light>,
        envmap: Option<EnvMap>,
        shapes: impl Into<Arc<[Shape]>>,
        scene_bounds: (Vec3, Vec3),
    ) -> Result<Self, LightError> {
        Self::with_textures(lights, envmap, Vec::new(), shapes, scene_bounds)
    }

    /// Builds the set with the image of its [`Light::Envmap`] and the textures its area lights
    /// emit and its spot lights and projectors project (their `texture` indexes
    /// `light_textures`; an error if one names a texture beyond them).
    pub fn with_textures(
        lights: Vec<Light>,
        envmap: Option<EnvMap>,
        light_textures: Vec<Arc<dyn LightTexture>>,
        shapes: impl Into<Arc<[Shape]>>,
        scene_bounds: (Vec3, Vec3),
    ) -> Result<Self, LightError> {
        let shapes: Arc<[Shape]> = shapes.into();
        let envmap_lights = lights.iter().filter(|l| **l == Light::Envmap).count();
        if envmap_lights != envmap.is_some() as usize {
            return Err(LightError::EnvmapMismatch);
        }
        let extent = scene_bounds.1 - scene_bounds.0;
        // Relative to the scene's own size (no absolute floor, which would outweigh every other
        // light in a scene in small units); 1 when the scene has no extent.
        let radius = 0.5 * extent.length();
        let scene_radius = if radius.is_finite() && radius.is_normal() {
            radius
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
                Light::Spot(s) => Some((s.position, 0.0)),
                Light::Projector(p) => Some((p.position, 0.0)),
                Light::Directional { .. } | Light::Constant { .. } | Light::Envmap => None,
            });
            let power = match *l {
                Light::Area {
                    shape,
                    radiance,
                    texture,
                } => {
                    let s = shapes
                        .get(shape as usize)
                        .ok_or(LightError::MissingShape(shape))?;
                    if !valid(radiance) {
                        return Err(LightError::BadParameter(i, "radiance"));
                    }
                    if let Some(t) = texture
                        && t as usize >= light_textures.len()
                    {
                        return Err(LightError::MissingLightTexture(i, t));
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
                Light::Spot(s) => {
                    if !valid(s.intensity) || !s.position.is_finite() {
                        return Err(LightError::BadParameter(i, "intensity"));
                    }
                    if let Some(t) = s.texture
                        && t as usize >= light_textures.len()
                    {
                        return Err(LightError::MissingLightTexture(i, t));
                    }
                    // The untextured power: a texture's mean is not counted (a selection
                    // weight only).
                    s.solid_angle() * luminance(s.intensity)
                }
                Light::Projector(p) => {
                    if !valid(p.intensity) || !p.position.is_finite() {
                        return Err(LightError::BadParameter(i, "irradiance"));
                    }
                    let mean = match p.texture {
                        Some(t) => light_textures
                            .get(t as usize)
                            .ok_or(LightError::MissingLightTexture(i, t))?
                            .mean(),
                        None => Vec3::ONE,
                    };
                    p.power(mean)
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
            let emission = match *l {
                Light::Area { radiance: v, .. }
                | Light::Point { intensity: v, .. }
                | Light::Spot(crate::Spot { intensity: v, .. })
                | Light::Projector(crate::Projector { intensity: v, .. })
                | Light::Directional { irradiance: v, .. }
                | Light::Constant { radiance: v } => v.max_element(),
                Light::Envmap => 0.0,
            };
            if emission > crate::MAX_EMISSION {
                return Err(LightError::TooBright(i, "emission", emission));
            }
            if power.is_nan() || power > crate::MAX_EMISSION {
                return Err(LightError::TooBright(i, "power", power));
            }
            powers.push(power);
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
        let table = EmitterTable::new(&lights, &shapes, &powers, environment);
        let clear = crate::clear::clear_boxes(&lights, &shapes);
        let mut set = Self {
            shapes,
            area_pdf: vec![0.0; lights.len()],
            lights,
            table,
            powers,
            spheres,
            shape_light,
            environment,
            envmap: envmap.map(Arc::new),
            light_textures,
            scene_radius,
            mesh_areas,
            hierarchy: OnceLock::new(),
            clear,
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

    /// The number of entries the typical local light holds: the lower median, over the lights
    /// with entries, of each light's count (a mesh light's emissive triangles, 1 for any other
    /// light); 0 without local lights. At most `n` means at least half of the lights hold at
    /// most `n` entries.
    pub fn median_emitters_per_light(&self) -> usize {
        let mut counts = vec![0usize; self.lights.len()];
        for e in self.table.entries() {
            let light = match *e {
                crate::table::Emitter::Triangle { light, .. }
                | crate::table::Emitter::Whole { light } => light,
            };
            counts[light as usize] += 1;
        }
        counts.retain(|&c| c > 0);
        counts.sort_unstable();
        counts
            .get(counts.len().saturating_sub(1) / 2)
            .copied()
            .unwrap_or(0)
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
    pub fn mesh_area_density(&self, light: u32) -> Option<f32> {
        match self.lights.get(light as usize)? {
            Light::Area { shape, .. } if matches!(self.shapes[*shape as usize], Shape::Mesh(_)) => {
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
}
