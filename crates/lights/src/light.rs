//! A light, a sample of one seen from a receiver, and the densities: what one light emits
//! ([`Light`]), a point on it drawn for a receiver ([`LightSample`], [`LightSet::sample_light`]),
//! the density of a point reached another way ([`LightSet::pdf_sa`]), and the environment's
//! radiance and coordinates.

use glam::{Vec2, Vec3};
use restir_geometry::{PositionSample, Shape, SurfaceInteraction, area_to_solid_angle, surface_at};
use restir_sampling::warp;

use crate::contact::{Contact, nonzero, point_contact};
use crate::table::Emitter;
use crate::{EnvMap, LightSet, Projector, Spot};

/// A texture a light emits or projects: an area light's radiance over its surface's uv
/// ([`Light::Area`]), a spot light's or projector's image ([`crate::Spot`],
/// [`crate::Projector`]); the renderer's textures (the scene crate's bitmaps and checkerboards)
/// evaluated at `uv`, linear RGB.
pub trait LightTexture: Send + Sync + core::fmt::Debug {
    /// The texture's value at `uv`.
    fn eval(&self, uv: Vec2) -> Vec3;

    /// The texture's mean over the unit square (a projector's or a textured area light's power,
    /// for its selection weight).
    fn mean(&self) -> Vec3;
}

/// An emitter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Radiance leaving the front side of a shape: uniform, or a texture over the shape's uv.
    Area {
        /// Index of the shape in the scene's shape list.
        shape: u32,
        /// Emitted radiance (linear RGB); with a texture, the texture's mean (what the
        /// selection weights and bounds count).
        radiance: Vec3,
        /// The radiance as a texture over the shape's uv (index into the set's textures, as
        /// [`crate::Spot::texture`]); `None`: uniform `radiance`.
        texture: Option<u32>,
    },
    /// An isotropic point light of intensity `intensity` (W/sr).
    Point {
        /// Position.
        position: Vec3,
        /// Radiant intensity.
        intensity: Vec3,
    },
    /// Mitsuba's `spot`: a point light whose intensity falls off with the angle from its axis,
    /// optionally projecting a texture ([`Spot`]).
    Spot(Spot),
    /// Mitsuba's `projector`: a point light throwing an irradiance image (or a constant) through
    /// a perspective frustum ([`Projector`]).
    Projector(Projector),
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

impl LightSet {
    /// Radiance leaving area light `light` at surface point `si` (a hit on its shape) towards
    /// unit `w` (pointing away from the light). One-sided: zero behind the shading normal.
    #[inline]
    pub fn area_radiance(&self, light: u32, si: &SurfaceInteraction, w: Vec3) -> Vec3 {
        match self.lights[light as usize] {
            Light::Area {
                radiance, texture, ..
            } if si.shading.n.dot(w) > 0.0 => match texture {
                None => radiance,
                Some(t) => self.light_textures[t as usize].eval(si.uv),
            },
            _ => Vec3::ZERO,
        }
    }

    /// A point `u` drawn uniformly on the triangle entry `e` of an area light: its light, the
    /// point, and the radiance the light emits there; `None` for another entry.
    #[inline]
    pub(crate) fn triangle_entry_point(
        &self,
        e: &Emitter,
        u: Vec2,
    ) -> Option<(u32, PositionSample, Vec3)> {
        let Emitter::Triangle {
            light,
            prim,
            ref p,
            ng,
            shading,
        } = *e
        else {
            return None;
        };
        let Light::Area {
            shape,
            radiance,
            texture,
        } = self.lights[light as usize]
        else {
            return None;
        };
        let ps = self
            .table
            .triangle_point(p, ng, shading, &self.shapes[shape as usize], prim, u);
        let le = self.area_le(shape, radiance, texture, prim, ps.param);
        Some((light, ps, le))
    }

    /// The radiance area light `light` (shape `shape`, radiance `radiance` and `texture` as
    /// [`Light::Area`] holds them) emits at the point `(prim, param)` of its shape.
    #[inline]
    pub(crate) fn area_le(
        &self,
        shape: u32,
        radiance: Vec3,
        texture: Option<u32>,
        prim: u32,
        param: Vec2,
    ) -> Vec3 {
        match texture {
            None => radiance,
            Some(t) => {
                let uv = surface_at(&self.shapes, shape, prim, param).uv;
                self.light_textures[t as usize].eval(uv)
            }
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

    /// The point of area light `light`, whose shape is `shape`, named by primitive `prim` and
    /// parameters `param` (barycentrics on a triangle, sphere parameters): the same bits as
    /// [`Shape::position_at`]. A triangle of a light whose mesh is in the emitter table is read
    /// from its table entry (corners and normals inline: one lookup instead of the chain shape →
    /// indices → positions).
    #[inline]
    pub fn area_point(&self, shape: &Shape, light: u32, prim: u32, param: Vec2) -> PositionSample {
        match self.table.triangle_entry(light, prim) {
            Some(&Emitter::Triangle {
                ref p, ng, shading, ..
            }) => self.table.point_at(p, ng, shading, shape, prim, param),
            _ => shape.position_at(prim, param),
        }
    }

    /// Samples a point on light `light` as seen from `ref_p`, with `pdf_sa` *not* including the
    /// selection probability.
    #[inline]
    pub fn sample_light(&self, light: u32, ref_p: Vec3, u: Vec2) -> Option<LightSample> {
        match self.lights[light as usize] {
            Light::Area {
                shape,
                radiance,
                texture,
            } => {
                let (ps, pdf_sa) = self.shapes[shape as usize].sample_from(ref_p, u)?;
                let le = self.area_le(shape, radiance, texture, ps.prim, ps.param);
                area_light_sample(light, le, ref_p, ps, pdf_sa)
            }
            Light::Point {
                position,
                intensity,
            } => point_light_sample(light, point_contact(position, ref_p, |_| Some(intensity))?),
            Light::Spot(spot) => point_light_sample(
                light,
                point_contact(spot.position, ref_p, |out| {
                    nonzero(self.spot_intensity(&spot, out)) // outside the cone: none
                })?,
            ),
            Light::Projector(projector) => point_light_sample(
                light,
                point_contact(projector.position, ref_p, |out| {
                    nonzero(self.projector_intensity(&projector, out)) // outside the frustum
                })?,
            ),
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

    /// The solid-angle density, including the selection probability, with which
    /// [`LightSet::sample`] would return point `p` (geometric normal `n`) on light `light` from `ref_p`; for
    /// the environment `p` is ignored and `n` must be the direction back from the environment
    /// (`−wi`, as [`LightSample::ng`] is). Zero for delta lights.
    #[inline]
    pub fn pdf_sa(&self, light: u32, ref_p: Vec3, p: Vec3, n: Vec3) -> f32 {
        let pmf = self.pmf(light);
        if pmf == 0.0 {
            return 0.0;
        }
        match self.lights[light as usize] {
            Light::Area { shape, .. } if matches!(self.shapes[shape as usize], Shape::Mesh(_)) => {
                area_to_solid_angle(self.area_pdf[light as usize], ref_p, p, n).unwrap_or(0.0)
            }
            _ => pmf * self.pdf_on_light(light, ref_p, p, n),
        }
    }

    /// The solid-angle density with which [`LightSet::sample_light`] returns point `p`
    /// (geometric normal `n`; for the environment, the direction back from it) of light `light`
    /// from `ref_p`, without any selection of the light. Zero for delta lights.
    #[inline]
    pub(crate) fn pdf_on_light(&self, light: u32, ref_p: Vec3, p: Vec3, n: Vec3) -> f32 {
        match self.lights[light as usize] {
            Light::Area { shape, .. } => self.shapes[shape as usize].pdf_sa_from(ref_p, p, n),
            Light::Constant { .. } => warp::UNIFORM_SPHERE_PDF,
            Light::Envmap => self
                .envmap
                .as_ref()
                .map_or(0.0, |m| m.pdf(-n.normalize_or_zero())),
            Light::Point { .. }
            | Light::Spot(_)
            | Light::Projector(_)
            | Light::Directional { .. } => 0.0,
        }
    }

    /// The intensity spot light `spot` (one of this set's) sends in world direction `w` (from
    /// the light, any length), its texture included.
    #[inline]
    pub fn spot_intensity(&self, spot: &Spot, w: Vec3) -> Vec3 {
        spot.intensity_towards(
            w,
            spot.texture
                .and_then(|t| self.light_textures.get(t as usize)),
        )
    }

    /// The intensity projector `projector` (one of this set's) sends in world direction `w`
    /// (from the light, any length), its texture included.
    #[inline]
    pub fn projector_intensity(&self, projector: &Projector, w: Vec3) -> Vec3 {
        projector.intensity_towards(
            w,
            projector
                .texture
                .and_then(|t| self.light_textures.get(t as usize)),
        )
    }
}

/// The sample of area light `light` (radiance `radiance`) at point `ps` seen from `ref_p`, with
/// solid-angle density `pdf_sa`; `None` at the receiver itself or behind the one-sided emitter.
#[inline]
pub(crate) fn area_light_sample(
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

/// A sphere around a shape (for other shapes than spheres, around its bounding box).
pub(crate) fn bounding_sphere(shape: &Shape) -> (Vec3, f32) {
    match shape {
        Shape::Sphere(s) => (s.center, s.radius),
        Shape::Cylinder(_) | Shape::SdfGrid(_) => {
            let (lo, hi) = shape.bounds();
            (0.5 * (lo + hi), 0.5 * (hi - lo).length())
        }
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

/// The sample of a point emitter (a point or spot light) as seen from a receiver.
#[inline]
fn point_light_sample(light: u32, c: Contact) -> Option<LightSample> {
    Some(LightSample {
        light,
        p: c.p,
        n: Vec3::ZERO,
        ng: Vec3::ZERO,
        wi: c.wi,
        dist: c.dist,
        le: c.le,
        pdf_sa: 1.0,
        delta: true,
        prim: 0,
        param: Vec2::ZERO,
    })
}
