//! A point on a light named independently of any receiver ([`LightPoint`]: a reservoir's light
//! sample in ReSTIR DI, the light vertex of ReSTIR PT's direct paths), resolved in world space
//! through the set ([`Resolved`]) and seen from a receiver ([`Contact`]).
//!
//! # Sample space and measure
//!
//! A sample is a point on an area light (area measure), a point, spot or projector light (counting measure), a
//! directional light (counting measure) or a direction towards the environment (solid-angle
//! measure on the sphere at infinity). None of these depend on the receiver, so the shift
//! between pixels is the identity with Jacobian 1 (GRIS, Lin et al. 2022, §6: a shift that keeps the sample has Jacobian 1); each pixel's target and
//! source densities are expressed in these measures.
//!

use glam::{Vec2, Vec3};
use restir_geometry::SurfaceInteraction;

use crate::contact::{Contact, nonzero, point_contact};
use crate::{Light, LightSample, LightSet, NeeSelection, Projector, Spot};

/// A ReSTIR DI sample: 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightPoint {
    /// Index of the light.
    pub light: u32,
    /// Primitive on an area light's shape (0 otherwise).
    pub prim: u32,
    /// Barycentrics or sphere parameters on an area light; the environment's coordinates of the
    /// direction towards it (`LightSet::environment_param`: an environment map's `(u, v)`, so
    /// that resolving the sample needs no inverse trigonometry); unused for point and
    /// directional lights.
    pub param: Vec2,
}

impl LightPoint {
    /// The sample a light-sampling record names.
    #[inline]
    pub fn from_light_sample(ls: &LightSample) -> Self {
        if !ls.delta && !ls.dist.is_finite() {
            return Self::environment(ls.light, ls.param);
        }
        Self {
            light: ls.light,
            prim: ls.prim,
            param: ls.param,
        }
    }

    /// The environment sample at the environment's coordinates `param`
    /// (`LightSet::environment_param` of a direction).
    #[inline]
    pub fn environment(light: u32, param: Vec2) -> Self {
        Self {
            light,
            prim: 0,
            param,
        }
    }
}

/// A sample resolved in world space, independent of any receiver: resolving once and
/// evaluating at several receivers (as spatial reuse does) saves the surface lookup.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Resolved {
    /// A point on an area light.
    Surface {
        /// Position.
        p: Vec3,
        /// Shading normal (one-sided emission is judged against it).
        n: Vec3,
        /// Geometric normal (for the area-measure factor and the light pdf).
        ng: Vec3,
        /// Emitted radiance.
        le: Vec3,
        /// The power sampler's density per unit area (mesh lights; `None` on a sphere, whose
        /// density depends on the receiver).
        pdf_area: Option<f32>,
    },
    /// A point light.
    Point {
        /// Position.
        p: Vec3,
        /// Radiant intensity.
        intensity: Vec3,
    },
    /// A point emitter whose intensity depends on the direction to the receiver, a spot light
    /// or a projector (the set's light `light` says how).
    Spot {
        /// Position.
        p: Vec3,
        /// Index of the light.
        light: u32,
    },
    /// A light at infinity seen in direction `wi` (towards the light).
    Direction {
        /// Unit direction towards the light.
        wi: Vec3,
        /// Radiance (environment) or irradiance (directional light).
        le: Vec3,
        /// Whether the light is a delta light (directional).
        delta: bool,
        /// The power sampler's density per unit solid angle (the environment; unused for a
        /// directional light).
        pdf: f32,
    },
}

impl LightSet {
    /// Resolves `sample` in world space.
    #[inline]
    pub fn resolve(&self, sample: &LightPoint) -> Resolved {
        match self.lights()[sample.light as usize] {
            Light::Area {
                shape,
                radiance,
                texture,
            } => {
                let ps = self.area_point(
                    &self.shapes[shape as usize],
                    sample.light,
                    sample.prim,
                    sample.param,
                );
                Resolved::Surface {
                    p: ps.p,
                    n: ps.n,
                    ng: ps.ng,
                    le: self.area_le(shape, radiance, texture, sample.prim, sample.param),
                    pdf_area: self.mesh_area_density(sample.light),
                }
            }
            Light::Point {
                position,
                intensity,
            } => Resolved::Point {
                p: position,
                intensity,
            },
            Light::Spot(Spot { position, .. }) | Light::Projector(Projector { position, .. }) => {
                Resolved::Spot {
                    p: position,
                    light: sample.light,
                }
            }
            Light::Directional {
                direction,
                irradiance,
            } => Resolved::Direction {
                wi: -direction,
                le: irradiance,
                delta: true,
                pdf: 0.0,
            },
            Light::Constant { .. } | Light::Envmap => {
                let (wi, le, pdf) =
                    self.environment_at(sample.param)
                        .unwrap_or((Vec3::Z, Vec3::ZERO, 0.0));
                Resolved::Direction {
                    wi,
                    le,
                    delta: false,
                    pdf,
                }
            }
        }
    }

    /// The light point a ray from `p` (shading normal `n`) in unit direction `d` reaches: the
    /// emitter of `hit`, or the environment when it is `None` (a miss). Returns the point, its
    /// radiance towards `p` and the density with which next-event estimation by `how` at `p`
    /// samples it ([`LightSet::pdf_nee`]: solid angle, the selection included);
    /// `None` when no light is there (a surface that is no light, the back of a one-sided
    /// emitter, a miss in a scene without an environment). An environment's radiance may be
    /// zero in direction `d`.
    #[inline]
    pub fn reached(
        &self,
        how: NeeSelection,
        (p, n): (Vec3, Vec3),
        d: Vec3,
        hit: Option<&SurfaceInteraction>,
    ) -> Option<(LightPoint, Vec3, f32)> {
        match hit {
            None => self.environment().map(|env| {
                let le = self.environment_radiance(d);
                let pdf = self.pdf_nee(how, (env, 0), p, n, p + d, -d);
                (
                    LightPoint::environment(env, self.environment_param(d)),
                    le,
                    pdf,
                )
            }),
            Some(si) => self.light_on_shape(si.shape).and_then(|light| {
                let le = self.area_radiance(light, si, -d);
                (le != Vec3::ZERO).then(|| {
                    let pdf = self.pdf_nee(how, (light, si.prim), p, n, si.p, si.ng);
                    let y = LightPoint {
                        light,
                        prim: si.prim,
                        param: si.param,
                    };
                    (y, le, pdf)
                })
            }),
        }
    }

    /// Where `sample` lies as seen from `x` ([`LightSet::resolve`] then [`Resolved::contact`]).
    #[inline]
    pub fn contact(&self, sample: &LightPoint, x: Vec3) -> Option<Contact> {
        self.resolve(sample).contact(self, sample, x)
    }
}

impl Resolved {
    /// The sample as seen from `x`, or `None` if it cannot contribute there (behind a one-sided
    /// emitter, outside a spot light's cone or a projector's frustum, at zero distance). `lights` is the set that resolved
    /// it (a spot light's profile and texture are read there), `point` the name it was resolved
    /// from (the light and primitive a shadow ray toward it ends on).
    #[inline]
    pub fn contact(&self, lights: &LightSet, point: &LightPoint, x: Vec3) -> Option<Contact> {
        match *self {
            Resolved::Surface {
                p,
                n,
                ng,
                le,
                pdf_area,
            } => {
                let to = p - x;
                let d2 = to.length_squared();
                if d2.is_nan() || d2 <= 0.0 {
                    return None;
                }
                let dist = d2.sqrt();
                let wi = to / dist;
                if n.dot(wi) >= 0.0 {
                    return None; // the back of a one-sided emitter
                }
                let measure = ng.dot(wi).abs() / d2;
                Some(Contact {
                    wi,
                    p,
                    dist,
                    le,
                    measure,
                    delta: false,
                    ng,
                    pdf_sa: pdf_area.filter(|_| measure > 0.0).map(|a| a / measure),
                    light: Some((point.light, point.prim)),
                })
            }
            Resolved::Point { p, intensity } => point_contact(p, x, |_| Some(intensity)),
            Resolved::Spot { p, light } => match lights.lights().get(light as usize) {
                Some(Light::Spot(spot)) => {
                    point_contact(p, x, |out| nonzero(lights.spot_intensity(spot, out)))
                }
                Some(Light::Projector(projector)) => point_contact(p, x, |out| {
                    nonzero(lights.projector_intensity(projector, out))
                }),
                _ => None,
            },
            Resolved::Direction { wi, le, delta, pdf } => Some(Contact {
                wi,
                p: x + wi,
                dist: f32::INFINITY,
                le,
                measure: 1.0,
                delta,
                ng: -wi,
                pdf_sa: (!delta).then_some(pdf),
                light: None,
            }),
        }
    }
}
