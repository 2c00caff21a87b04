//! The ReSTIR DI sample: a point on a light named independently of any receiver, and the target
//! function each pixel evaluates for it.
//!
//! # Sample space and measure
//!
//! A sample is a point on an area light (area measure), a point light (counting measure), a
//! directional light (counting measure) or a direction towards the environment (solid-angle
//! measure on the sphere at infinity). None of these depend on the receiver, so the shift
//! between pixels is the identity with Jacobian 1 (`docs/GRIS.md` §6.7); each pixel's target and
//! source densities are expressed in these measures.
//!
//! # Integrand and target
//!
//! The direct light at receiver `x` is split exactly between the two strategies that cover it,
//! light sampling (the reservoirs) and BSDF sampling (traced at shading), by balance-heuristic
//! weights that depend only on `x` and `y`:
//!
//! ```text
//! m_L(y) = N_L·p_L(y) / (N_L·p_L(y) + N_B·p_B(y)),   m_B = 1 − m_L      (solid angle at x)
//! ```
//!
//! The reservoirs estimate `∫ F(y)·m_L(y)·V(x, y) dy` with `F = f_s·|cos θ_x|·L_e·G` (the
//! unshadowed contribution) and target `p̂(y) = lum(F(y)·m_L(y))`; visibility is tested once, at
//! shading. Because `m_L` needs no visibility, every pixel's target is a fixed function and
//! reservoirs stay valid at their neighbours; BSDF samples could not be resampled into the
//! reservoirs without that (their density on a light is zero wherever the light is occluded).

use glam::{Vec2, Vec3};
use restir_geometry::Sphere;
use restir_lights::{Light, LightSample};
use restir_sampling::luminance;
use restir_scene::Scene;

use crate::gbuffer::Receiver;

/// A ReSTIR DI sample: 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightPoint {
    /// Index of the light.
    pub light: u32,
    /// Primitive on an area light's shape (0 otherwise).
    pub prim: u32,
    /// Barycentrics or sphere parameters on an area light; the octahedral encoding of the
    /// direction towards the environment; unused for point and directional lights.
    pub param: Vec2,
}

impl LightPoint {
    /// The sample a light-sampling record names.
    #[inline]
    pub fn from_light_sample(ls: &LightSample) -> Self {
        if !ls.delta && !ls.dist.is_finite() {
            return Self::environment(ls.light, ls.wi);
        }
        Self {
            light: ls.light,
            prim: ls.prim,
            param: ls.param,
        }
    }

    /// The environment sample in direction `d` (unit, pointing away from the scene).
    #[inline]
    pub fn environment(light: u32, d: Vec3) -> Self {
        Self {
            light,
            prim: 0,
            param: Sphere::param_of(d),
        }
    }
}

/// A light sample seen from a receiver.
#[derive(Clone, Copy, Debug)]
pub struct Contact {
    /// Unit direction from the receiver towards the light (world space).
    pub wi: Vec3,
    /// The point on the light (shadow-ray end), for lights at a finite distance.
    pub p: Vec3,
    /// Distance to `p`; infinite for lights at infinity.
    pub dist: f32,
    /// Radiance arriving along `-wi` (for point lights intensity/distance²).
    pub le: Vec3,
    /// Converts a solid-angle density at the receiver into the sample's measure:
    /// `|cos θ_y|/d²` on area lights, 1 otherwise.
    pub measure: f32,
    /// Whether the light is a delta light (BSDF sampling cannot reach it).
    pub delta: bool,
    /// The light's geometric normal at `p` (area lights), for the light pdf.
    pub ng: Vec3,
}

/// A sample resolved in world space, independent of any receiver: resolving once and
/// evaluating at several receivers (as spatial reuse does) saves the surface lookup.
#[derive(Clone, Copy, Debug)]
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
    },
    /// A point light.
    Point {
        /// Position.
        p: Vec3,
        /// Radiant intensity.
        intensity: Vec3,
    },
    /// A light at infinity seen in direction `wi` (towards the light).
    Direction {
        /// Unit direction towards the light.
        wi: Vec3,
        /// Radiance (environment) or irradiance (directional light).
        le: Vec3,
        /// Whether the light is a delta light (directional).
        delta: bool,
    },
}

/// Resolves `sample` in world space.
#[inline]
pub fn resolve(scene: &Scene, sample: &LightPoint) -> Resolved {
    match scene.lights.lights()[sample.light as usize] {
        Light::Area { shape, radiance } => {
            let ps = scene.shapes[shape as usize].position_at(sample.prim, sample.param);
            Resolved::Surface {
                p: ps.p,
                n: ps.n,
                ng: ps.ng,
                le: radiance,
            }
        }
        Light::Point {
            position,
            intensity,
        } => Resolved::Point {
            p: position,
            intensity,
        },
        Light::Directional {
            direction,
            irradiance,
        } => Resolved::Direction {
            wi: -direction,
            le: irradiance,
            delta: true,
        },
        Light::Constant { .. } | Light::Envmap => {
            let (_, wi) = Sphere::new(Vec3::ZERO, 1.0, false).point_at(sample.param);
            Resolved::Direction {
                wi,
                le: scene.lights.environment_radiance(wi),
                delta: false,
            }
        }
    }
}

impl Resolved {
    /// The sample as seen from `x`, or `None` if it cannot contribute there (behind a one-sided
    /// emitter, at zero distance).
    #[inline]
    pub fn contact(&self, x: Vec3) -> Option<Contact> {
        match *self {
            Resolved::Surface { p, n, ng, le } => {
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
                Some(Contact {
                    wi,
                    p,
                    dist,
                    le,
                    measure: ng.dot(wi).abs() / d2,
                    delta: false,
                    ng,
                })
            }
            Resolved::Point { p, intensity } => {
                let to = p - x;
                let d2 = to.length_squared();
                if d2.is_nan() || d2 <= 0.0 {
                    return None;
                }
                let dist = d2.sqrt();
                Some(Contact {
                    wi: to / dist,
                    p,
                    dist,
                    le: intensity / d2,
                    measure: 1.0,
                    delta: true,
                    ng: Vec3::ZERO,
                })
            }
            Resolved::Direction { wi, le, delta } => Some(Contact {
                wi,
                p: x + wi,
                dist: f32::INFINITY,
                le,
                measure: 1.0,
                delta,
                ng: -wi,
            }),
        }
    }
}

/// Where `sample` lies as seen from `x` ([`resolve`] then [`Resolved::contact`]).
#[inline]
pub fn contact(scene: &Scene, sample: &LightPoint, x: Vec3) -> Option<Contact> {
    resolve(scene, sample).contact(x)
}

/// The two strategy counts of the direct-light split.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrategyCounts {
    /// Light candidates per pixel, `N_L`.
    pub light: f32,
    /// BSDF samples per pixel, `N_B`.
    pub bsdf: f32,
}

/// A sample's value at a receiver: the reservoirs' integrand without visibility, and its target.
#[derive(Clone, Copy, Debug)]
pub struct Evaluated {
    /// `F(y)·m_L(y)` (RGB, in the sample's measure).
    pub contribution: Vec3,
    /// `p̂(y) = lum(contribution)`.
    pub target: f32,
}

impl Evaluated {
    const ZERO: Self = Self {
        contribution: Vec3::ZERO,
        target: 0.0,
    };
}

/// Evaluates `sample` at receiver `r` seen as `c` (from [`contact`]). `known_light_pdf_sa` is
/// the light-sampling density at `r` if the caller has it (selection included; the pmf for
/// delta lights); otherwise it is computed when the light/BSDF split needs it (`N_B > 0`).
#[inline]
pub fn evaluate(
    scene: &Scene,
    r: &Receiver,
    sample: &LightPoint,
    c: &Contact,
    known_light_pdf_sa: Option<f32>,
    counts: StrategyCounts,
) -> Evaluated {
    let bsdf = &r.resolve_bsdf(scene);
    let wi = r.frame().to_local(c.wi);
    let f = bsdf.eval(r.wo, wi);
    if f == Vec3::ZERO {
        return Evaluated::ZERO;
    }
    let m_light = if c.delta || counts.bsdf == 0.0 {
        1.0
    } else {
        let light_pdf_sa = known_light_pdf_sa.unwrap_or_else(|| {
            scene
                .lights
                .pdf_sa(&scene.shapes, sample.light, r.p, c.p, c.ng)
        });
        let nl = counts.light * light_pdf_sa;
        let nb = counts.bsdf * bsdf.pdf_sa(r.wo, wi);
        if nl > 0.0 { nl / (nl + nb) } else { 0.0 }
    };
    let contribution = f * c.le * (c.measure * m_light);
    let target = luminance(contribution);
    if !(target > 0.0 && target.is_finite()) {
        return Evaluated::ZERO;
    }
    Evaluated {
        contribution,
        target,
    }
}

/// The target `p̂` of receiver `r` at `sample`, resolved as `resolved` (0 where it cannot
/// contribute).
#[inline]
pub fn target(
    scene: &Scene,
    r: &Receiver,
    sample: &LightPoint,
    resolved: &Resolved,
    counts: StrategyCounts,
) -> f32 {
    resolved
        .contact(r.p)
        .map_or(0.0, |c| evaluate(scene, r, sample, &c, None, counts).target)
}
