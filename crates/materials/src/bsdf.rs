use core::f32::consts::FRAC_1_PI;
use glam::{Vec2, Vec3};
use restir_sampling::warp;

use crate::LobeFlags;
use crate::fresnel::{
    fresnel_conductor, fresnel_dielectric, fresnel_diffuse_reflectance, reflect, refract,
};
use crate::microfacet::{Distribution, Microfacet};
use crate::plastic::{RoughPlasticTable, rough_plastic_table};

/// A sampled scattering direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// The sampled direction towards the light, local frame.
    pub wi: Vec3,
    /// `f(wo, wi) · |cos θi|` (for delta lobes: weight × `pdf_sa`, see the crate docs).
    pub f: Vec3,
    /// Solid-angle density of `wi` (for delta lobes: the lobe's selection probability).
    pub pdf_sa: f32,
    /// The lobe that produced the sample.
    pub lobe: LobeFlags,
    /// That lobe's roughness as Mitsuba's `alpha` (1 for diffuse, 0 for delta lobes).
    pub roughness: f32,
    /// Relative index of refraction along the sampled direction (1 for reflection).
    pub eta: f32,
}

/// Parameters of Mitsuba's smooth `plastic`, with the quantities it precomputes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    /// Relative IOR of the coating, `int_ior / ext_ior`.
    pub eta: f32,
    /// `ρ' / η²`: the base's reflectance after the internal-reflection series, times the
    /// radiance scale `1/η²` of refracting out of the coating.
    pub diffuse_scaled: Vec3,
    /// Multiplier of the specular lobe (Mitsuba `specular_reflectance`, default 1).
    pub specular_reflectance: Vec3,
    /// Probability weight of the specular lobe, `mean(ks) / (mean(ρd) + mean(ks))`.
    pub specular_weight: f32,
}

/// Parameters of Mitsuba's `roughplastic`, with its precomputed coating tables.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughPlastic {
    /// Relative IOR of the coating, `int_ior / ext_ior`.
    pub eta: f32,
    /// `ρ' / η²` with `ρ' = ρd / (1 − R_int)` (or `ρd / (1 − ρd R_int)` if nonlinear).
    pub diffuse_scaled: Vec3,
    /// Multiplier of the specular lobe.
    pub specular_reflectance: Vec3,
    /// Probability weight of the specular lobe, as for [`Plastic`].
    pub specular_weight: f32,
    /// The coating's (isotropic) microfacet distribution.
    pub microfacet: Microfacet,
    /// `T(cos θ)` and `R_int`, shared between materials with the same (distribution, α, η).
    pub table: &'static RoughPlasticTable,
}

/// The scattering models (Mitsuba 3's plugins of the same names). Construct them with the
/// functions on [`Bsdf`], which apply Mitsuba's clamping and precomputation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BsdfKind {
    /// Lambertian reflection (Mitsuba `diffuse`): `f = ρ/π` above the surface.
    Diffuse {
        /// Albedo, each channel in `[0, 1]`.
        reflectance: Vec3,
    },
    /// Smooth conductor (Mitsuba `conductor`): a delta mirror weighted by the conductor Fresnel
    /// reflectance of the complex IOR `eta + i·k` (`eta = 0, k = 1`: a perfect mirror).
    Conductor {
        /// Real part of the IOR, per channel.
        eta: Vec3,
        /// Imaginary part (absorption), per channel.
        k: Vec3,
        /// Multiplier (default 1).
        specular_reflectance: Vec3,
    },
    /// Rough conductor (Mitsuba `roughconductor`): `F(wo·h) D(h) G / (4 cos θo)`.
    RoughConductor {
        /// Real part of the IOR, per channel.
        eta: Vec3,
        /// Imaginary part, per channel.
        k: Vec3,
        /// Multiplier (default 1).
        specular_reflectance: Vec3,
        /// Microfacet distribution.
        microfacet: Microfacet,
    },
    /// Smooth dielectric interface (Mitsuba `dielectric`): delta reflection and refraction, two
    /// sided by nature (seen from inside, the relative IOR is `1/eta`).
    Dielectric {
        /// Relative IOR `int_ior / ext_ior`.
        eta: f32,
        /// Multiplier of reflection (default 1).
        specular_reflectance: Vec3,
        /// Multiplier of transmission (default 1).
        specular_transmittance: Vec3,
    },
    /// Rough dielectric interface (Mitsuba `roughdielectric`, Walter et al. 2007).
    RoughDielectric {
        /// Relative IOR `int_ior / ext_ior`.
        eta: f32,
        /// Multiplier of reflection (default 1).
        specular_reflectance: Vec3,
        /// Multiplier of transmission (default 1).
        specular_transmittance: Vec3,
        /// Microfacet distribution.
        microfacet: Microfacet,
    },
    /// Diffuse base under a smooth dielectric coating (Mitsuba `plastic`).
    Plastic(Plastic),
    /// Diffuse base under a rough dielectric coating (Mitsuba `roughplastic`).
    RoughPlastic(RoughPlastic),
    /// A pass-through surface (Mitsuba `null`): light continues unchanged, as a delta
    /// transmission with weight 1.
    Null,
    /// Absorbs everything (a black surface; also emitters without a material).
    Black,
}

impl BsdfKind {
    /// Whether the model transmits (and so is two-sided by nature).
    pub fn transmits(&self) -> bool {
        matches!(
            self,
            BsdfKind::Dielectric { .. } | BsdfKind::RoughDielectric { .. } | BsdfKind::Null
        )
    }
}

/// A BSDF: a model and whether it is mirrored onto the back side (Mitsuba `twosided`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    /// The model.
    pub kind: BsdfKind,
    /// When set, a `wo` below the surface sees the model mirrored to the back side. Has no
    /// effect on transmitting models, which are two-sided by nature.
    pub two_sided: bool,
}

fn mean(v: Vec3) -> f32 {
    (v.x + v.y + v.z) / 3.0
}

fn one_sided(kind: BsdfKind) -> Bsdf {
    Bsdf {
        kind,
        two_sided: false,
    }
}

/// The colour parameters of a model as the scene gives them (before any precomputation), for
/// replacing them per shading point with texture values: [`Bsdf::with_params`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReflectanceParams {
    /// `diffuse`'s `reflectance`, the plastics' `diffuse_reflectance`.
    pub diffuse: Vec3,
    /// `specular_reflectance` (conductors, dielectrics, plastics).
    pub specular: Vec3,
    /// The dielectrics' `specular_transmittance`.
    pub transmittance: Vec3,
    /// The plastics' `nonlinear` flag (it decides how `diffuse` is precomputed).
    pub nonlinear: bool,
}

/// Mitsuba's specular sampling weight `mean(ks) / (mean(ρd) + mean(ks))` (1 when both are 0).
fn specular_weight(diffuse: Vec3, specular: Vec3) -> f32 {
    let (d, s) = (mean(diffuse), mean(specular));
    if d + s > 0.0 { s / (d + s) } else { 1.0 }
}

/// A plastic's `ρ' / η²`: the base reflectance `ρd` after the internal-reflection series
/// (`ρd / (1 − R_int)`, or `ρd / (1 − ρd R_int)` if `nonlinear`) times the radiance scale `1/η²`.
#[inline]
fn plastic_diffuse_scaled(eta: f32, diffuse: Vec3, r_int: f32, nonlinear: bool) -> Vec3 {
    let rho = if nonlinear {
        diffuse / (Vec3::ONE - diffuse * r_int)
    } else {
        diffuse / (1.0 - r_int)
    };
    rho / (eta * eta)
}

const REFLECT_DIFFUSE: LobeFlags = LobeFlags::DIFFUSE.union(LobeFlags::REFLECTION);
const REFLECT_GLOSSY: LobeFlags = LobeFlags::GLOSSY.union(LobeFlags::REFLECTION);
const REFLECT_DELTA: LobeFlags = LobeFlags::DELTA.union(LobeFlags::REFLECTION);
const TRANSMIT_GLOSSY: LobeFlags = LobeFlags::GLOSSY.union(LobeFlags::TRANSMISSION);
const TRANSMIT_DELTA: LobeFlags = LobeFlags::DELTA.union(LobeFlags::TRANSMISSION);

#[inline]
fn mirror(v: Vec3) -> Vec3 {
    Vec3::new(-v.x, -v.y, v.z)
}

impl Bsdf {
    /// A one-sided Lambertian BSDF.
    pub fn diffuse(reflectance: Vec3) -> Self {
        one_sided(BsdfKind::Diffuse { reflectance })
    }

    /// A BSDF that absorbs everything.
    pub fn black() -> Self {
        one_sided(BsdfKind::Black)
    }

    /// A pass-through surface (Mitsuba `null`).
    pub fn null() -> Self {
        one_sided(BsdfKind::Null)
    }

    /// A smooth one-sided conductor with complex IOR `eta + i·k` (see [`crate::ior::conductor`]
    /// for named metals; `Vec3::ZERO, Vec3::ONE` is Mitsuba's default perfect mirror).
    pub fn conductor(eta: Vec3, k: Vec3, specular_reflectance: Vec3) -> Self {
        one_sided(BsdfKind::Conductor {
            eta,
            k,
            specular_reflectance,
        })
    }

    /// A rough one-sided conductor.
    pub fn rough_conductor(
        eta: Vec3,
        k: Vec3,
        specular_reflectance: Vec3,
        microfacet: Microfacet,
    ) -> Self {
        one_sided(BsdfKind::RoughConductor {
            eta,
            k,
            specular_reflectance,
            microfacet,
        })
    }

    /// A smooth dielectric interface with relative IOR `eta = int_ior / ext_ior`.
    pub fn dielectric(eta: f32, specular_reflectance: Vec3, specular_transmittance: Vec3) -> Self {
        one_sided(BsdfKind::Dielectric {
            eta,
            specular_reflectance,
            specular_transmittance,
        })
    }

    /// A rough dielectric interface with relative IOR `eta = int_ior / ext_ior`.
    pub fn rough_dielectric(
        eta: f32,
        specular_reflectance: Vec3,
        specular_transmittance: Vec3,
        microfacet: Microfacet,
    ) -> Self {
        one_sided(BsdfKind::RoughDielectric {
            eta,
            specular_reflectance,
            specular_transmittance,
            microfacet,
        })
    }

    /// Mitsuba's smooth `plastic`: diffuse base `diffuse_reflectance` under a smooth coating of
    /// relative IOR `eta`; `nonlinear` selects `ρd / (1 − ρd·Fdr)` over `ρd / (1 − Fdr)`.
    pub fn plastic(
        eta: f32,
        diffuse_reflectance: Vec3,
        specular_reflectance: Vec3,
        nonlinear: bool,
    ) -> Self {
        let fdr_int = fresnel_diffuse_reflectance(1.0 / eta);
        one_sided(BsdfKind::Plastic(Plastic {
            eta,
            diffuse_scaled: plastic_diffuse_scaled(eta, diffuse_reflectance, fdr_int, nonlinear),
            specular_reflectance,
            specular_weight: specular_weight(diffuse_reflectance, specular_reflectance),
        }))
    }

    /// Mitsuba's `roughplastic` with an isotropic coating roughness `alpha`. Builds (or reuses)
    /// the coating tables, which takes a moment the first time for each (distribution, α, η).
    pub fn rough_plastic(
        eta: f32,
        diffuse_reflectance: Vec3,
        specular_reflectance: Vec3,
        nonlinear: bool,
        distribution: Distribution,
        alpha: f32,
    ) -> Self {
        let microfacet = Microfacet::new(distribution, alpha);
        let table = rough_plastic_table(distribution, microfacet.alpha_u, eta);
        one_sided(BsdfKind::RoughPlastic(RoughPlastic {
            eta,
            diffuse_scaled: plastic_diffuse_scaled(
                eta,
                diffuse_reflectance,
                table.internal_reflectance,
                nonlinear,
            ),
            specular_reflectance,
            specular_weight: specular_weight(diffuse_reflectance, specular_reflectance),
            microfacet,
            table,
        }))
    }

    /// The same model with its colour parameters replaced by `p` (each model takes the ones it
    /// has; the others are ignored). Cheap: the rough plastic's coating tables depend on the
    /// IOR and roughness only and are kept, so only the reflectance-derived terms
    /// (`diffuse_scaled`, `specular_weight`) are recomputed. Equal to building the model with
    /// these parameters in the first place.
    #[inline]
    pub fn with_params(&self, p: &ReflectanceParams) -> Self {
        let kind = match self.kind {
            BsdfKind::Diffuse { .. } => BsdfKind::Diffuse {
                reflectance: p.diffuse,
            },
            BsdfKind::Conductor { eta, k, .. } => BsdfKind::Conductor {
                eta,
                k,
                specular_reflectance: p.specular,
            },
            BsdfKind::RoughConductor {
                eta, k, microfacet, ..
            } => BsdfKind::RoughConductor {
                eta,
                k,
                specular_reflectance: p.specular,
                microfacet,
            },
            BsdfKind::Dielectric { eta, .. } => BsdfKind::Dielectric {
                eta,
                specular_reflectance: p.specular,
                specular_transmittance: p.transmittance,
            },
            BsdfKind::RoughDielectric {
                eta, microfacet, ..
            } => BsdfKind::RoughDielectric {
                eta,
                specular_reflectance: p.specular,
                specular_transmittance: p.transmittance,
                microfacet,
            },
            BsdfKind::Plastic(q) => {
                let fdr_int = fresnel_diffuse_reflectance(1.0 / q.eta);
                BsdfKind::Plastic(Plastic {
                    diffuse_scaled: plastic_diffuse_scaled(q.eta, p.diffuse, fdr_int, p.nonlinear),
                    specular_reflectance: p.specular,
                    specular_weight: specular_weight(p.diffuse, p.specular),
                    ..q
                })
            }
            BsdfKind::RoughPlastic(q) => BsdfKind::RoughPlastic(RoughPlastic {
                diffuse_scaled: plastic_diffuse_scaled(
                    q.eta,
                    p.diffuse,
                    q.table.internal_reflectance,
                    p.nonlinear,
                ),
                specular_reflectance: p.specular,
                specular_weight: specular_weight(p.diffuse, p.specular),
                ..q
            }),
            k @ (BsdfKind::Null | BsdfKind::Black) => k,
        };
        Self { kind, ..*self }
    }

    /// The same model, visible from both sides (no effect on transmitting models).
    pub fn two_sided(self) -> Self {
        Self {
            two_sided: true,
            ..self
        }
    }

    /// Every lobe the BSDF has.
    pub fn flags(&self) -> LobeFlags {
        match self.kind {
            BsdfKind::Diffuse { .. } => REFLECT_DIFFUSE,
            BsdfKind::Conductor { .. } => REFLECT_DELTA,
            BsdfKind::RoughConductor { .. } => REFLECT_GLOSSY,
            BsdfKind::Dielectric { .. } => REFLECT_DELTA | LobeFlags::TRANSMISSION,
            BsdfKind::RoughDielectric { .. } => REFLECT_GLOSSY | LobeFlags::TRANSMISSION,
            BsdfKind::Plastic(_) => REFLECT_DELTA | LobeFlags::DIFFUSE,
            BsdfKind::RoughPlastic(_) => REFLECT_GLOSSY | LobeFlags::DIFFUSE,
            BsdfKind::Null => TRANSMIT_DELTA,
            BsdfKind::Black => LobeFlags::NONE,
        }
    }

    /// Whether light sampling can help: the BSDF has a lobe that `eval` can evaluate.
    pub fn has_smooth_lobe(&self) -> bool {
        self.flags()
            .intersects(LobeFlags::DIFFUSE | LobeFlags::GLOSSY)
    }

    /// Whether `wo` is mirrored to the front (two-sided, reflection-only model seen from behind).
    #[inline]
    fn flips(&self, wo: Vec3) -> bool {
        self.two_sided && wo.z < 0.0 && !self.kind.transmits()
    }

    /// Mirrors `(wo, wi)` to the front side for a two-sided BSDF seen from the back.
    #[inline]
    fn orient(&self, wo: Vec3, wi: Vec3) -> (Vec3, Vec3) {
        if self.flips(wo) {
            (Vec3::new(wo.x, wo.y, -wo.z), Vec3::new(wi.x, wi.y, -wi.z))
        } else {
            (wo, wi)
        }
    }

    /// `f(wo, wi) · |cos θi|`; zero for delta lobes and for directions the model does not reach.
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let (v, l) = self.orient(wo, wi);
        let r = match &self.kind {
            BsdfKind::Diffuse { reflectance } => {
                if v.z > 0.0 && l.z > 0.0 {
                    *reflectance * (FRAC_1_PI * l.z)
                } else {
                    Vec3::ZERO
                }
            }
            BsdfKind::RoughConductor {
                eta,
                k,
                specular_reflectance,
                microfacet,
            } => rough_conductor_eval(microfacet, *eta, *k, v, l) * *specular_reflectance,
            BsdfKind::RoughDielectric {
                eta,
                specular_reflectance,
                specular_transmittance,
                microfacet,
            } => rough_dielectric_eval(
                microfacet,
                *eta,
                *specular_reflectance,
                *specular_transmittance,
                v,
                l,
            ),
            BsdfKind::Plastic(p) => {
                if v.z > 0.0 && l.z > 0.0 {
                    let fi = fresnel_dielectric(v.z, p.eta).r;
                    let fo = fresnel_dielectric(l.z, p.eta).r;
                    p.diffuse_scaled * ((1.0 - fi) * (1.0 - fo) * FRAC_1_PI * l.z)
                } else {
                    Vec3::ZERO
                }
            }
            BsdfKind::RoughPlastic(p) => rough_plastic_eval(p, v, l),
            BsdfKind::Conductor { .. }
            | BsdfKind::Dielectric { .. }
            | BsdfKind::Null
            | BsdfKind::Black => Vec3::ZERO,
        };
        if r.is_finite() { r } else { Vec3::ZERO }
    }

    /// Solid-angle density with which [`Bsdf::sample`] returns `wi`; zero for delta lobes.
    #[inline]
    pub fn pdf_sa(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (v, l) = self.orient(wo, wi);
        let p = match &self.kind {
            BsdfKind::Diffuse { .. } => {
                if v.z > 0.0 {
                    warp::cosine_hemisphere_pdf(l.z)
                } else {
                    0.0
                }
            }
            BsdfKind::RoughConductor { microfacet, .. } => rough_reflection_pdf(microfacet, v, l),
            BsdfKind::RoughDielectric {
                eta, microfacet, ..
            } => rough_dielectric_pdf(microfacet, *eta, v, l),
            BsdfKind::Plastic(p) => {
                if v.z > 0.0 && l.z > 0.0 {
                    let fi = fresnel_dielectric(v.z, p.eta).r;
                    let (_, pd) = lobe_probabilities(
                        fi * p.specular_weight,
                        (1.0 - fi) * (1.0 - p.specular_weight),
                    );
                    pd * warp::cosine_hemisphere_pdf(l.z)
                } else {
                    0.0
                }
            }
            BsdfKind::RoughPlastic(p) => rough_plastic_pdf(p, v, l),
            BsdfKind::Conductor { .. }
            | BsdfKind::Dielectric { .. }
            | BsdfKind::Null
            | BsdfKind::Black => 0.0,
        };
        if p.is_finite() { p } else { 0.0 }
    }

    /// Samples `wi` given `wo`: `u_lobe` chooses a lobe, `u` the direction within it. `None` when
    /// nothing is scattered (below a one-sided surface, an absorber, or a zero-pdf direction).
    #[inline]
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let flip = self.flips(wo);
        let v = if flip {
            Vec3::new(wo.x, wo.y, -wo.z)
        } else {
            wo
        };
        let mut s = self.sample_front(v, u_lobe, u)?;
        if !(s.pdf_sa > 0.0 && s.pdf_sa.is_finite() && s.f.is_finite() && s.wi.is_finite()) {
            return None;
        }
        if flip {
            s.wi.z = -s.wi.z;
        }
        Some(s)
    }

    /// [`Bsdf::sample`] after the two-sided mirroring (`v` is the oriented `wo`).
    #[inline]
    fn sample_front(&self, v: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let delta = |wi: Vec3, f: Vec3, pdf_sa: f32, lobe: LobeFlags, eta: f32| BsdfSample {
            wi,
            f,
            pdf_sa,
            lobe,
            roughness: 0.0,
            eta,
        };
        match &self.kind {
            BsdfKind::Diffuse { reflectance } => {
                if v.z <= 0.0 {
                    return None;
                }
                let wi = warp::sample_cosine_hemisphere(u);
                Some(BsdfSample {
                    wi,
                    f: *reflectance * (FRAC_1_PI * wi.z),
                    pdf_sa: warp::cosine_hemisphere_pdf(wi.z),
                    lobe: REFLECT_DIFFUSE,
                    roughness: 1.0,
                    eta: 1.0,
                })
            }
            BsdfKind::Conductor {
                eta,
                k,
                specular_reflectance,
            } => {
                if v.z <= 0.0 {
                    return None;
                }
                let f = fresnel_conductor(v.z, *eta, *k) * *specular_reflectance;
                Some(delta(mirror(v), f, 1.0, REFLECT_DELTA, 1.0))
            }
            BsdfKind::RoughConductor { microfacet, .. } => {
                if v.z <= 0.0 {
                    return None;
                }
                let m = microfacet.sample(v, u)?;
                let l = reflect(v, m);
                if l.z <= 0.0 {
                    return None;
                }
                Some(self.smooth_sample(v, l, REFLECT_GLOSSY, microfacet.alpha(), 1.0))
            }
            BsdfKind::Dielectric {
                eta,
                specular_reflectance,
                specular_transmittance,
            } => {
                if v.z == 0.0 {
                    return None;
                }
                let fr = fresnel_dielectric(v.z, *eta);
                if u_lobe < fr.r {
                    Some(delta(
                        mirror(v),
                        *specular_reflectance * fr.r,
                        fr.r,
                        REFLECT_DELTA,
                        1.0,
                    ))
                } else {
                    let wi = Vec3::new(-fr.eta_ti * v.x, -fr.eta_ti * v.y, fr.cos_theta_t);
                    // Radiance scales by 1/η² across the interface (η_ti = 1/η_it).
                    let t = 1.0 - fr.r;
                    let f = *specular_transmittance * (fr.eta_ti * fr.eta_ti * t);
                    Some(delta(wi, f, t, TRANSMIT_DELTA, fr.eta_it))
                }
            }
            BsdfKind::RoughDielectric {
                eta, microfacet, ..
            } => {
                if v.z == 0.0 {
                    return None;
                }
                let side = v.z.signum();
                let m = microfacet.sample(v * side, u)?;
                let fr = fresnel_dielectric(v.dot(m), *eta);
                let (l, lobe, eta_s) = if u_lobe < fr.r {
                    (reflect(v, m), REFLECT_GLOSSY, 1.0)
                } else {
                    (
                        refract(v, m, fr.cos_theta_t, fr.eta_ti),
                        TRANSMIT_GLOSSY,
                        fr.eta_it,
                    )
                };
                let reflected = l.z * v.z > 0.0;
                if reflected != (lobe == REFLECT_GLOSSY) || l.z == 0.0 {
                    return None;
                }
                Some(self.smooth_sample(v, l, lobe, microfacet.alpha(), eta_s))
            }
            BsdfKind::Plastic(p) => {
                if v.z <= 0.0 {
                    return None;
                }
                let fi = fresnel_dielectric(v.z, p.eta).r;
                let (ps, pd) = lobe_probabilities(
                    fi * p.specular_weight,
                    (1.0 - fi) * (1.0 - p.specular_weight),
                );
                if u_lobe < ps {
                    Some(delta(
                        mirror(v),
                        p.specular_reflectance * fi,
                        ps,
                        REFLECT_DELTA,
                        1.0,
                    ))
                } else if pd > 0.0 {
                    let l = warp::sample_cosine_hemisphere(u);
                    Some(self.smooth_sample(v, l, REFLECT_DIFFUSE, 1.0, 1.0))
                } else {
                    None
                }
            }
            BsdfKind::RoughPlastic(p) => {
                if v.z <= 0.0 {
                    return None;
                }
                let (ps, _) = rough_plastic_lobes(p, v.z);
                let (l, lobe, roughness) = if u_lobe < ps {
                    let m = p.microfacet.sample(v, u)?;
                    (reflect(v, m), REFLECT_GLOSSY, p.microfacet.alpha())
                } else {
                    (warp::sample_cosine_hemisphere(u), REFLECT_DIFFUSE, 1.0)
                };
                if l.z <= 0.0 {
                    return None;
                }
                Some(self.smooth_sample(v, l, lobe, roughness, 1.0))
            }
            BsdfKind::Null => Some(delta(-v, Vec3::ONE, 1.0, TRANSMIT_DELTA, 1.0)),
            BsdfKind::Black => None,
        }
    }

    /// A sample of a non-delta lobe whose `f` and `pdf_sa` are `eval` and `pdf_sa` themselves
    /// (for mixtures, the pdf of the whole mixture: one-sample MIS over the lobes, as Mitsuba).
    #[inline]
    fn smooth_sample(
        &self,
        v: Vec3,
        l: Vec3,
        lobe: LobeFlags,
        roughness: f32,
        eta: f32,
    ) -> BsdfSample {
        // `v` is already oriented; evaluate without mirroring again.
        let front = Bsdf {
            two_sided: false,
            ..*self
        };
        BsdfSample {
            wi: l,
            f: front.eval(v, l),
            pdf_sa: front.pdf_sa(v, l),
            lobe,
            roughness,
            eta,
        }
    }
}

/// Normalised lobe probabilities `(a, b) / (a + b)` (`(1, 0)` when both vanish).
#[inline]
fn lobe_probabilities(a: f32, b: f32) -> (f32, f32) {
    let s = a + b;
    if s > 0.0 { (a / s, b / s) } else { (1.0, 0.0) }
}

/// Mitsuba's `roughconductor` eval without `specular_reflectance`: `v` towards the viewer, `l`
/// towards the light; `F(v·h) D(h) G1(v,h) G1(l,h) / (4 cos θv)`.
#[inline]
fn rough_conductor_eval(mf: &Microfacet, eta: Vec3, k: Vec3, v: Vec3, l: Vec3) -> Vec3 {
    if v.z <= 0.0 || l.z <= 0.0 {
        return Vec3::ZERO;
    }
    let h = (v + l).normalize();
    let d = mf.d(h);
    if d == 0.0 {
        return Vec3::ZERO;
    }
    let g = mf.g(v, l, h);
    fresnel_conductor(v.dot(h), eta, k) * (d * g / (4.0 * v.z))
}

/// Density of reflecting about a visible normal: `D(h) G1(v,h) / (4 cos θv)`.
#[inline]
fn rough_reflection_pdf(mf: &Microfacet, v: Vec3, l: Vec3) -> f32 {
    if v.z <= 0.0 || l.z <= 0.0 {
        return 0.0;
    }
    let h = (v + l).normalize();
    let lh = l.dot(h);
    if v.dot(h) <= 0.0 || lh <= 0.0 {
        return 0.0;
    }
    mf.pdf(v, h) / (4.0 * lh)
}

/// The generalised half vector of a rough dielectric (Walter et al. 2007), in `+z`; `None` if
/// degenerate. Returns `(m, reflect, η')` with `η'` the relative IOR seen from `v`'s side.
#[inline]
fn dielectric_half(eta: f32, v: Vec3, l: Vec3) -> Option<(Vec3, bool, f32)> {
    if v.z == 0.0 || l.z == 0.0 {
        return None;
    }
    let reflect = v.z * l.z > 0.0;
    let eta_p = if v.z > 0.0 { eta } else { 1.0 / eta };
    let m = (v + l * if reflect { 1.0 } else { eta_p }).normalize();
    if !m.is_finite() {
        return None;
    }
    let m = if m.z < 0.0 { -m } else { m };
    Some((m, reflect, eta_p))
}

fn rough_dielectric_eval(mf: &Microfacet, eta: f32, ks: Vec3, kt: Vec3, v: Vec3, l: Vec3) -> Vec3 {
    let Some((m, reflect, eta_p)) = dielectric_half(eta, v, l) else {
        return Vec3::ZERO;
    };
    let d = mf.d(m);
    if d == 0.0 {
        return Vec3::ZERO;
    }
    let g = mf.g(v, l, m);
    if g == 0.0 {
        return Vec3::ZERO;
    }
    let (vm, lm) = (v.dot(m), l.dot(m));
    let f = fresnel_dielectric(vm, eta).r;
    if reflect {
        ks * (f * d * g / (4.0 * v.z.abs()))
    } else {
        // Walter et al.'s BTDF times |cos θl|, times η'² and by the radiance scale 1/η'²,
        // which cancel (Mitsuba's radiance mode).
        let denom = vm + eta_p * lm;
        kt * ((1.0 - f) * d * g * vm * lm / (v.z * denom * denom)).abs()
    }
}

fn rough_dielectric_pdf(mf: &Microfacet, eta: f32, v: Vec3, l: Vec3) -> f32 {
    let Some((m, reflect, eta_p)) = dielectric_half(eta, v, l) else {
        return 0.0;
    };
    let (vm, lm) = (v.dot(m), l.dot(m));
    if vm * v.z <= 0.0 || lm * l.z <= 0.0 {
        return 0.0;
    }
    let dwh_dwo = if reflect {
        1.0 / (4.0 * lm)
    } else {
        let denom = vm + eta_p * lm;
        eta_p * eta_p * lm / (denom * denom)
    };
    let side = v.z.signum();
    let f = fresnel_dielectric(vm, eta).r;
    let choose = if reflect { f } else { 1.0 - f };
    (mf.pdf(v * side, m) * choose * dwh_dwo).abs()
}

/// `(p_spec, p_diffuse)` of a rough plastic at `cos θv`.
#[inline]
fn rough_plastic_lobes(p: &RoughPlastic, cos_v: f32) -> (f32, f32) {
    let t = p.table.transmittance_at(cos_v);
    lobe_probabilities((1.0 - t) * p.specular_weight, t * (1.0 - p.specular_weight))
}

fn rough_plastic_eval(p: &RoughPlastic, v: Vec3, l: Vec3) -> Vec3 {
    if v.z <= 0.0 || l.z <= 0.0 {
        return Vec3::ZERO;
    }
    let mf = &p.microfacet;
    let h = (v + l).normalize();
    let d = mf.d(h);
    let spec = if d > 0.0 {
        let f = fresnel_dielectric(v.dot(h), p.eta).r;
        p.specular_reflectance * (f * d * mf.g(v, l, h) / (4.0 * v.z))
    } else {
        Vec3::ZERO
    };
    let (ti, to) = (p.table.transmittance_at(v.z), p.table.transmittance_at(l.z));
    spec + p.diffuse_scaled * (ti * to * FRAC_1_PI * l.z)
}

fn rough_plastic_pdf(p: &RoughPlastic, v: Vec3, l: Vec3) -> f32 {
    if v.z <= 0.0 || l.z <= 0.0 {
        return 0.0;
    }
    let (ps, pd) = rough_plastic_lobes(p, v.z);
    ps * rough_reflection_pdf(&p.microfacet, v, l) + pd * warp::cosine_hemisphere_pdf(l.z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn dir(x: f32, y: f32) -> Vec3 {
        warp::sample_uniform_sphere(Vec2::new(x, y))
    }

    proptest! {
        /// `sample` agrees with `eval` and `pdf_sa`, and reciprocity holds.
        #[test]
        fn sample_eval_pdf_agree(a in 0.0f32..1.0, b in 0.0f32..1.0, c in 0.0f32..1.0,
                                 d in 0.0f32..1.0, two in proptest::bool::ANY) {
            let mut bsdf = Bsdf::diffuse(Vec3::new(0.8, 0.5, 0.2));
            if two { bsdf = bsdf.two_sided(); }
            let wo = dir(a, b);
            if let Some(s) = bsdf.sample(wo, 0.5, Vec2::new(c, d)) {
                prop_assert!((bsdf.eval(wo, s.wi) - s.f).abs().max_element() < 1e-5);
                prop_assert!((bsdf.pdf_sa(wo, s.wi) - s.pdf_sa).abs() < 1e-4 * s.pdf_sa.max(1.0));
                // Reciprocity of f = eval/|cos θi|.
                let f_ab = bsdf.eval(wo, s.wi) / s.wi.z.abs();
                let f_ba = bsdf.eval(s.wi, wo) / wo.z.abs();
                prop_assert!((f_ab - f_ba).abs().max_element() < 1e-4);
            } else {
                prop_assert!(!two && wo.z <= 0.0);
            }
        }
    }

    /// Replacing the colour parameters gives exactly the model built with them.
    #[test]
    fn with_params_equals_fresh_construction() {
        let (d0, s0, t0) = (Vec3::splat(0.5), Vec3::ONE, Vec3::ONE);
        let (d1, s1, t1) = (
            Vec3::new(0.1, 0.7, 0.3),
            Vec3::new(0.9, 0.4, 0.2),
            Vec3::new(0.3, 0.8, 0.6),
        );
        let mf = Microfacet::new(Distribution::Ggx, 0.3);
        let (eta, k) = (Vec3::new(0.2, 0.9, 1.1), Vec3::new(3.9, 2.4, 2.1));
        for nonlinear in [false, true] {
            let p = ReflectanceParams {
                diffuse: d1,
                specular: s1,
                transmittance: t1,
                nonlinear,
            };
            let pairs = [
                (Bsdf::diffuse(d0), Bsdf::diffuse(d1)),
                (Bsdf::conductor(eta, k, s0), Bsdf::conductor(eta, k, s1)),
                (
                    Bsdf::rough_conductor(eta, k, s0, mf),
                    Bsdf::rough_conductor(eta, k, s1, mf),
                ),
                (Bsdf::dielectric(1.5, s0, t0), Bsdf::dielectric(1.5, s1, t1)),
                (
                    Bsdf::rough_dielectric(1.5, s0, t0, mf),
                    Bsdf::rough_dielectric(1.5, s1, t1, mf),
                ),
                (
                    Bsdf::plastic(1.49, d0, s0, nonlinear),
                    Bsdf::plastic(1.49, d1, s1, nonlinear),
                ),
                (
                    Bsdf::rough_plastic(1.49, d0, s0, nonlinear, Distribution::Beckmann, 0.2),
                    Bsdf::rough_plastic(1.49, d1, s1, nonlinear, Distribution::Beckmann, 0.2),
                ),
                (Bsdf::null(), Bsdf::null()),
                (Bsdf::black(), Bsdf::black()),
            ];
            for (base, want) in pairs {
                assert_eq!(base.with_params(&p), want);
                assert_eq!(base.two_sided().with_params(&p), want.two_sided());
            }
        }
    }

    /// The enum stays small (it is copied into path vertices and reservoirs).
    #[test]
    fn bsdf_is_small() {
        assert!(
            core::mem::size_of::<Bsdf>() <= 64,
            "{}",
            core::mem::size_of::<Bsdf>()
        );
    }

    #[test]
    fn one_sided_is_black_from_behind() {
        let bsdf = Bsdf::diffuse(Vec3::ONE);
        let wo = Vec3::new(0.0, 0.0, -1.0);
        assert_eq!(bsdf.eval(wo, Vec3::Z), Vec3::ZERO);
        assert_eq!(bsdf.eval(wo, -Vec3::Z), Vec3::ZERO);
        assert!(bsdf.sample(wo, 0.5, Vec2::splat(0.5)).is_none());
        let two = bsdf.two_sided();
        assert!(two.eval(wo, -Vec3::Z).x > 0.0);
        assert_eq!(two.eval(wo, Vec3::Z), Vec3::ZERO);
    }

    fn sph(theta_deg: f32, phi_deg: f32) -> Vec3 {
        let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
        Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    }

    fn close(got: Vec3, want: Vec3, rel: f32, what: &str) {
        assert!(
            (got - want).abs().max_element() <= rel * want.max_element(),
            "{what}: {got} vs Mitsuba {want}"
        );
    }

    /// Mitsuba 3.9.1 `eval` values (MATERIALS.md §4.3), ρd = (0.2, 0.5, 0.8), η = 1.49/1.000277.
    /// Mitsuba's `wi` (viewer) is our `wo`.
    #[test]
    fn plastics_match_mitsuba_eval() {
        let eta = 1.49 / 1.000_277;
        let rho = Vec3::new(0.2, 0.5, 0.8);
        let b = Bsdf::rough_plastic(eta, rho, Vec3::ONE, false, Distribution::Beckmann, 0.1);
        close(
            b.eval(Vec3::Z, Vec3::Z),
            Vec3::new(0.370_087, 0.463_594, 0.557_101),
            1e-3,
            "beckmann 0/0",
        );
        close(
            b.eval(sph(60.0, 0.0), sph(20.0, 90.0)),
            Vec3::new(0.055_477, 0.138_693, 0.221_910),
            1e-3,
            "beckmann 60/20",
        );
        let g = Bsdf::rough_plastic(eta, rho, Vec3::ONE, false, Distribution::Ggx, 0.3);
        close(
            g.eval(Vec3::Z, Vec3::Z),
            Vec3::new(0.078_410, 0.144_733, 0.211_056),
            1e-3,
            "ggx 0/0",
        );
        close(
            g.eval(sph(75.0, 0.0), sph(70.0, 180.0)),
            Vec3::new(0.480_867, 0.497_536, 0.514_205),
            1e-3,
            "ggx 75/70",
        );
        let p = Bsdf::plastic(eta, rho, Vec3::ONE, false);
        close(
            p.eval(Vec3::Z, Vec3::Z),
            Vec3::new(0.064_746, 0.161_866, 0.258_985),
            1e-4,
            "plastic",
        );
    }

    /// Smooth dielectric: Mitsuba's transmission weight at 30° is 1/η² = 0.441976, reflection
    /// weight 1, and R + T = 1.
    #[test]
    fn dielectric_weights() {
        let eta = 1.5046 / 1.000_277;
        let bsdf = Bsdf::dielectric(eta, Vec3::ONE, Vec3::ONE);
        let wo = sph(30.0, 40.0);
        let r = bsdf.sample(wo, 0.0, Vec2::ZERO).unwrap();
        let t = bsdf.sample(wo, 0.999, Vec2::ZERO).unwrap();
        assert!(r.lobe.contains(LobeFlags::REFLECTION) && t.lobe.contains(LobeFlags::TRANSMISSION));
        assert!(((r.f / r.pdf_sa) - Vec3::ONE).abs().max_element() < 1e-6);
        assert!(
            ((t.f / t.pdf_sa) - Vec3::splat(0.441_976))
                .abs()
                .max_element()
                < 1e-5
        );
        assert!((r.pdf_sa + t.pdf_sa - 1.0).abs() < 1e-6);
        assert!((t.eta - eta).abs() < 1e-6 && r.eta == 1.0);
        // Snell's law and the refracted side.
        assert!(t.wi.z < 0.0);
        let (si, st) = ((1.0 - wo.z * wo.z).sqrt(), (1.0 - t.wi.z * t.wi.z).sqrt());
        assert!((si - eta * st).abs() < 1e-5);
        // From inside, the weight is η² and eta is 1/η.
        let t_in = bsdf.sample(-Vec3::Z, 0.999, Vec2::ZERO).unwrap();
        assert!(
            ((t_in.f / t_in.pdf_sa) - Vec3::splat(eta * eta))
                .abs()
                .max_element()
                < 1e-4
        );
        assert!((t_in.eta - 1.0 / eta).abs() < 1e-6);
    }
}
