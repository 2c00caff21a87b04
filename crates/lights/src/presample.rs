//! Light samples drawn without a receiver: what a pool of presampled candidates holds (RTXDI's
//! presampled light tiles; Wyman and Panteleev 2021, "Rearchitecting Spatiotemporal Resampling
//! for Production").

use glam::{Vec2, Vec3};

use crate::table::Emitter;
use restir_geometry::Shape;

use crate::{Light, LightPoint, LightSet, Resolved};

/// A light sample drawn without a receiver ([`LightSet::presample`]). Its density is the power
/// sampler's ([`LightSet::sample`]) expressed in the sample's own measure (area on an emissive
/// triangle, counting for a point or directional light, solid angle for the environment), so it
/// does not depend on where the sample will be seen from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Presampled {
    /// A point (or direction) fixed without the receiver: named, resolved in world space, and
    /// its density in its own measure, the selection included.
    Fixed {
        /// The sample's name.
        point: LightPoint,
        /// The sample in world space.
        resolved: Resolved,
        /// Density per unit area (triangles), selection probability (point and directional
        /// lights) or density per unit solid angle (the environment), the selection included.
        pdf: f32,
    },
    /// A sphere light, whose points are drawn per receiver by the cone it subtends, with its
    /// selection probability and what drawing needs of it inline: a pool's entry is read from
    /// cache, where the light's and its shape's records may be far apart in memory (10⁵
    /// spheres: two cache misses per candidate, half the cost of sampling).
    Sphere {
        /// Index of the light.
        light: u32,
        /// Selection probability.
        pmf: f32,
        /// The sphere's centre.
        center: Vec3,
        /// Its radius.
        radius: f32,
        /// Its emitted radiance.
        radiance: Vec3,
        /// Whether its normals point inwards.
        flip_normals: bool,
    },
    /// A light whose points are drawn per receiver ([`LightSet::sample_light`]), with its
    /// selection probability.
    Light {
        /// Index of the light.
        light: u32,
        /// Selection probability.
        pmf: f32,
    },
}

impl LightSet {
    /// What [`LightSet::sample`] draws with the same numbers, as far as it does not depend on
    /// the receiver ([`Presampled`]): the point of a triangle, a point light, the direction of a
    /// light at infinity; a sphere light only picked. `None` where nothing can be sampled.
    pub fn presample(&self, u_select: f32, u: Vec2) -> Option<Presampled> {
        let picked = match self.table.pick_index(u_select)? {
            Ok(e) => e,
            Err(_) => self.table.len(),
        };
        self.presample_emitter(picked, u)
    }

    /// [`LightSet::presample`] of a given emitter `e` (an entry of the emitter table, or the
    /// table's length for the environment; [`LightSet::emitter_of`]'s numbering), its density
    /// still the power sampler's. `None` for an emitter that does not exist or cannot be sampled.
    pub fn presample_emitter(&self, e: usize, u: Vec2) -> Option<Presampled> {
        let picked = match self.table.entries().get(e) {
            Some(entry) => Ok(entry),
            None if e == self.table.len() => Err(self.environment?),
            None => return None,
        };
        let light = match picked {
            Ok(e @ &Emitter::Triangle { prim, .. }) => {
                let (light, ps, radiance) = self.triangle_entry_point(e, u)?;
                let pdf_area = self.area_pdf[light as usize];
                return Some(Presampled::Fixed {
                    point: LightPoint {
                        light,
                        prim,
                        param: ps.param,
                    },
                    resolved: Resolved::Surface {
                        p: ps.p,
                        n: ps.n,
                        ng: ps.ng,
                        le: radiance,
                        pdf_area: Some(pdf_area),
                    },
                    pdf: pdf_area,
                });
            }
            Ok(&Emitter::Whole { light }) => light,
            Err(env) => env,
        };
        let pmf = self.table.pmf(light);
        match self.lights[light as usize] {
            Light::Area {
                shape,
                radiance,
                texture: None,
            } => match &self.shapes[shape as usize] {
                Shape::Sphere(s) => Some(Presampled::Sphere {
                    light,
                    pmf,
                    center: s.center,
                    radius: s.radius,
                    radiance,
                    flip_normals: s.flip_normals,
                }),
                _ => Some(Presampled::Light { light, pmf }),
            },
            // A textured area light's points are drawn, and their radiance looked up, when
            // they are resolved.
            Light::Area { .. } | Light::Spot(_) | Light::Projector(_) => {
                Some(Presampled::Light { light, pmf })
            }
            Light::Point {
                position,
                intensity,
            } => Some(Presampled::Fixed {
                point: LightPoint {
                    light,
                    prim: 0,
                    param: Vec2::ZERO,
                },
                resolved: Resolved::Point {
                    p: position,
                    intensity,
                },
                pdf: pmf,
            }),
            Light::Directional { .. } | Light::Constant { .. } | Light::Envmap => {
                let s = self.sample_light(light, Vec3::ZERO, u)?;
                let pdf = s.pdf_sa * pmf;
                Some(Presampled::Fixed {
                    point: if s.delta {
                        LightPoint {
                            light,
                            prim: 0,
                            param: Vec2::ZERO,
                        }
                    } else {
                        LightPoint::environment(light, s.param)
                    },
                    resolved: Resolved::Direction {
                        wi: s.wi,
                        le: s.le,
                        delta: s.delta,
                        pdf,
                    },
                    pdf,
                })
            }
        }
    }
}
