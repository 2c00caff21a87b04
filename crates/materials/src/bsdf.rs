//! [`Bsdf`]: a scattering model ([`BsdfKind`], Mitsuba 3's plugins with their parameters) and
//! whether it is two-sided, with the constructors that apply Mitsuba's clamping and
//! precomputation, and the dispatch of `eval`, `pdf_sa` and `sample` to the models in
//! [`crate::models`] (one `match` per method). The two-sided mirroring and the clean-up of
//! non-finite values happen here, once for every model.

use glam::{Vec2, Vec3};

use crate::LobeFlags;
use crate::lobe::{
    REFLECT_DELTA, REFLECT_DIFFUSE, REFLECT_GLOSSY, TRANSMIT_DELTA, TRANSMIT_GLOSSY,
};
use crate::microfacet::{Distribution, Microfacet};
use crate::models::blend::{self, Blend};
use crate::models::normalmap::{self, NormalMap};
use crate::models::plastic::{Plastic, RoughPlastic};
use crate::models::principled::Principled;
use crate::models::principled_thin::PrincipledThin;
use crate::models::{
    BsdfSample, conductor, delta, dielectric, diffuse, finite_or_zero, finite_pdf, plastic,
    principled, principled_thin,
};

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
    /// A sheet of glass too thin to offset what it transmits (Mitsuba `thindielectric`): delta
    /// reflection with the reflectance of both faces and the light bounced between them, and
    /// transmission straight through; the same from both sides.
    ThinDielectric {
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
    /// Burley's Disney BSDF (Mitsuba `principled`): two-sided by nature when it transmits
    /// (`spec_trans > 0`), one-sided otherwise.
    Principled(Principled),
    /// Burley's thin-sheet variant (Mitsuba `principledthin`), the same from both sides.
    PrincipledThin(PrincipledThin),
    /// A pass-through surface (Mitsuba `null`): light continues unchanged, as a delta
    /// transmission with weight 1.
    Null,
    /// Absorbs everything (a black surface; also emitters without a material).
    Black,
    /// Two BSDFs mixed by a weight (Mitsuba `blendbsdf`); see [`Bsdf::blend`].
    Blend(Blend),
}

impl BsdfKind {
    /// Whether the model transmits (and so is two-sided by nature).
    pub fn transmits(&self) -> bool {
        match self {
            BsdfKind::Dielectric { .. }
            | BsdfKind::ThinDielectric { .. }
            | BsdfKind::RoughDielectric { .. }
            | BsdfKind::Null
            | BsdfKind::PrincipledThin(_) => true,
            BsdfKind::Principled(p) => p.transmits(),
            BsdfKind::Blend(b) => b.transmits(),
            _ => false,
        }
    }
}

/// A BSDF: a model, whether it is mirrored onto the back side (Mitsuba `twosided`) and its
/// opacity (Mitsuba `mask`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    /// The model.
    pub kind: BsdfKind,
    /// When set, a `wo` below the surface sees the model mirrored to the back side. Has no
    /// effect on transmitting models, which are two-sided by nature.
    pub two_sided: bool,
    /// Mitsuba's `mask`: the model scatters with this probability, and light passes through
    /// unchanged otherwise (a delta transmission of weight `1 − opacity`, from both sides). 1 for
    /// an opaque surface; in `[0, 1]`. See [`Bsdf::masked`].
    pub opacity: f32,
    /// Mitsuba's `normalmap`: the model (two-sided mirroring included, inside the mask's
    /// pass-through) is evaluated in the frame this normal perturbs. See
    /// [`Bsdf::normal_mapped`].
    pub normal_map: Option<NormalMap>,
}

pub(crate) fn one_sided(kind: BsdfKind) -> Bsdf {
    Bsdf {
        kind,
        two_sided: false,
        opacity: 1.0,
        normal_map: None,
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
    /// The opacity of a `mask` (1 for an opaque surface).
    pub opacity: f32,
    /// The raw texel of a `normalmap` (ignored by a BSDF without one).
    pub normal: Vec3,
    /// Roughness `(alpha_u, alpha_v)` replacing a rough conductor's or rough dielectric's
    /// (`None` keeps the model's; each clamped to at least [`crate::microfacet::MIN_ALPHA`]).
    pub alpha: Option<(f32, f32)>,
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

    /// A thin dielectric sheet with relative IOR `eta = int_ior / ext_ior` (Mitsuba
    /// `thindielectric`).
    pub fn thin_dielectric(
        eta: f32,
        specular_reflectance: Vec3,
        specular_transmittance: Vec3,
    ) -> Self {
        one_sided(BsdfKind::ThinDielectric {
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
        one_sided(BsdfKind::Plastic(Plastic::new(
            eta,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
        )))
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
        one_sided(BsdfKind::RoughPlastic(RoughPlastic::new(
            eta,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            distribution,
            alpha,
        )))
    }

    /// Mitsuba's `blendbsdf`: `(1 − weight)·first + weight·second` (weight clamped to
    /// `[0, 1]`), one-sided itself (each component keeps its own sides, mask and normal map).
    pub fn blend(weight: f32, first: Bsdf, second: Bsdf) -> Self {
        one_sided(BsdfKind::Blend(Blend::new(weight, first, second)))
    }

    /// The same BSDF with a blend's weight replaced by `weight` (a weight texture's value at a
    /// shading point; clamped to `[0, 1]`); other models are returned unchanged.
    #[inline]
    pub fn with_blend_weight(self, weight: f32) -> Self {
        match self.kind {
            BsdfKind::Blend(b) => Self {
                kind: BsdfKind::Blend(b.with_weight(weight)),
                ..self
            },
            _ => self,
        }
    }

    /// The same model with its colour parameters replaced by `p` (each model takes the ones it
    /// has; the others are ignored). Cheap: the rough plastic's coating tables depend on the
    /// IOR and roughness only and are kept, so only the reflectance-derived terms
    /// (`diffuse_scaled`, `specular_weight`) are recomputed. Equal to building the model with
    /// these parameters in the first place.
    #[inline]
    pub fn with_params(&self, p: &ReflectanceParams) -> Self {
        let rough = |m: Microfacet| match p.alpha {
            Some((u, v)) => Microfacet::anisotropic(m.distribution, u, v),
            None => m,
        };
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
                microfacet: rough(microfacet),
            },
            BsdfKind::Dielectric { eta, .. } => BsdfKind::Dielectric {
                eta,
                specular_reflectance: p.specular,
                specular_transmittance: p.transmittance,
            },
            BsdfKind::ThinDielectric { eta, .. } => BsdfKind::ThinDielectric {
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
                microfacet: rough(microfacet),
            },
            BsdfKind::Plastic(q) => {
                BsdfKind::Plastic(q.with_reflectance(p.diffuse, p.specular, p.nonlinear))
            }
            BsdfKind::RoughPlastic(q) => {
                BsdfKind::RoughPlastic(q.with_reflectance(p.diffuse, p.specular, p.nonlinear))
            }
            k @ (BsdfKind::Null
            | BsdfKind::Black
            | BsdfKind::Blend(_)
            | BsdfKind::Principled(_)
            | BsdfKind::PrincipledThin(_)) => k,
        };
        Self {
            kind,
            opacity: crate::models::mask::clamp_opacity(p.opacity),
            normal_map: self.normal_map.map(|m| m.with_texel(p.normal)),
            ..*self
        }
    }

    /// The same model behind Mitsuba's `normalmap` (`map` holds the perturbed normal and the
    /// switches; textured maps replace the normal per shading point through
    /// [`ReflectanceParams::normal`]).
    pub fn normal_mapped(self, map: NormalMap) -> Self {
        Self {
            normal_map: Some(map),
            ..self
        }
    }

    /// The same model behind Mitsuba's `mask` of opacity `opacity` (clamped to `[0, 1]`, as
    /// Mitsuba clamps it).
    pub fn masked(self, opacity: f32) -> Self {
        Self {
            opacity: crate::models::mask::clamp_opacity(opacity),
            ..self
        }
    }

    /// Whether the surface lets some light pass through unchanged (a `mask` below opacity 1).
    #[inline]
    pub fn is_masked(&self) -> bool {
        self.opacity < 1.0
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
        if self.is_masked() {
            return self.model_flags() | TRANSMIT_DELTA;
        }
        self.model_flags()
    }

    /// The lobes of the model (without the pass-through of a mask).
    fn model_flags(&self) -> LobeFlags {
        match self.kind {
            BsdfKind::Diffuse { .. } => REFLECT_DIFFUSE,
            BsdfKind::Conductor { .. } => REFLECT_DELTA,
            BsdfKind::RoughConductor { .. } => REFLECT_GLOSSY,
            BsdfKind::Dielectric { .. } | BsdfKind::ThinDielectric { .. } => {
                REFLECT_DELTA | LobeFlags::TRANSMISSION
            }
            BsdfKind::RoughDielectric { .. } => REFLECT_GLOSSY | LobeFlags::TRANSMISSION,
            BsdfKind::Plastic(_) => REFLECT_DELTA | LobeFlags::DIFFUSE,
            BsdfKind::RoughPlastic(_) => REFLECT_GLOSSY | LobeFlags::DIFFUSE,
            BsdfKind::Principled(p) if p.transmits() => {
                REFLECT_DIFFUSE | REFLECT_GLOSSY | TRANSMIT_GLOSSY
            }
            BsdfKind::Principled(_) => REFLECT_DIFFUSE | REFLECT_GLOSSY,
            BsdfKind::PrincipledThin(_) => {
                LobeFlags::DIFFUSE
                    | LobeFlags::GLOSSY
                    | LobeFlags::REFLECTION
                    | LobeFlags::TRANSMISSION
            }
            BsdfKind::Null => TRANSMIT_DELTA,
            BsdfKind::Black => LobeFlags::NONE,
            BsdfKind::Blend(b) => b.flags(),
        }
    }

    /// Whether light sampling can help: the BSDF has a lobe that `eval` can evaluate.
    pub fn has_smooth_lobe(&self) -> bool {
        self.model_flags()
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
        if self.is_masked() {
            return self.eval_model(wo, wi) * self.opacity;
        }
        self.eval_model(wo, wi)
    }

    /// [`Bsdf::eval`] of the model alone (in the normal map's frame, if there is one).
    #[inline]
    fn eval_model(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let Some(map) = &self.normal_map else {
            return self.eval_shaded(wo, wi);
        };
        let frame = map.frame(wo);
        let wi_p = frame.to_local(wi);
        if !normalmap::same_side(wi, wi_p) {
            return Vec3::ZERO;
        }
        finite_or_zero(self.eval_shaded(frame.to_local(wo), wi_p) * map.shadowing(frame.n, wi))
    }

    /// [`Bsdf::eval`] of the model in its own shading frame.
    #[inline]
    fn eval_shaded(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let (v, l) = self.orient(wo, wi);
        finite_or_zero(match &self.kind {
            BsdfKind::Diffuse { reflectance } => diffuse::eval(*reflectance, v, l),
            BsdfKind::RoughConductor {
                eta,
                k,
                specular_reflectance,
                microfacet,
            } => conductor::eval_rough(microfacet, *eta, *k, *specular_reflectance, v, l),
            BsdfKind::RoughDielectric {
                eta,
                specular_reflectance,
                specular_transmittance,
                microfacet,
            } => dielectric::eval_rough(
                microfacet,
                *eta,
                *specular_reflectance,
                *specular_transmittance,
                v,
                l,
            ),
            BsdfKind::Plastic(p) => plastic::eval_smooth(p, v, l),
            BsdfKind::RoughPlastic(p) => plastic::eval_rough(p, v, l),
            BsdfKind::Principled(p) => principled::eval(p, v, l),
            BsdfKind::PrincipledThin(p) => principled_thin::eval(p, v, l),
            BsdfKind::Blend(b) => blend::eval(b, v, l),
            BsdfKind::Conductor { .. }
            | BsdfKind::Dielectric { .. }
            | BsdfKind::ThinDielectric { .. }
            | BsdfKind::Null
            | BsdfKind::Black => Vec3::ZERO,
        })
    }

    /// Solid-angle density with which [`Bsdf::sample`] returns `wi`; zero for delta lobes.
    #[inline]
    pub fn pdf_sa(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.is_masked() {
            return self.pdf_model(wo, wi) * self.opacity;
        }
        self.pdf_model(wo, wi)
    }

    /// [`Bsdf::pdf_sa`] of the model alone (in the normal map's frame, if there is one).
    #[inline]
    fn pdf_model(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(map) = &self.normal_map else {
            return self.pdf_shaded(wo, wi);
        };
        let frame = map.frame(wo);
        let wi_p = frame.to_local(wi);
        if !normalmap::same_side(wi, wi_p) {
            return 0.0;
        }
        self.pdf_shaded(frame.to_local(wo), wi_p)
    }

    /// [`Bsdf::pdf_sa`] of the model in its own shading frame.
    #[inline]
    fn pdf_shaded(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (v, l) = self.orient(wo, wi);
        finite_pdf(match &self.kind {
            BsdfKind::Diffuse { .. } => diffuse::pdf(v, l),
            BsdfKind::RoughConductor { microfacet, .. } => conductor::pdf_rough(microfacet, v, l),
            BsdfKind::RoughDielectric {
                eta, microfacet, ..
            } => dielectric::pdf_rough(microfacet, *eta, v, l),
            BsdfKind::Plastic(p) => plastic::pdf_smooth(p, v, l),
            BsdfKind::RoughPlastic(p) => plastic::pdf_rough(p, v, l),
            BsdfKind::Principled(p) => principled::pdf(p, v, l),
            BsdfKind::PrincipledThin(p) => principled_thin::pdf(p, v, l),
            BsdfKind::Blend(b) => blend::pdf(b, v, l),
            BsdfKind::Conductor { .. }
            | BsdfKind::Dielectric { .. }
            | BsdfKind::ThinDielectric { .. }
            | BsdfKind::Null
            | BsdfKind::Black => 0.0,
        })
    }

    /// Samples `wi` given `wo`: `u_lobe` chooses a lobe, `u` the direction within it. `None` when
    /// nothing is scattered (below a one-sided surface, an absorber, or a zero-pdf direction).
    #[inline]
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if self.is_masked() {
            return crate::models::mask::sample(self.opacity, wo, u_lobe, |u_lobe| {
                self.sample_model(wo, u_lobe, u)
            });
        }
        self.sample_model(wo, u_lobe, u)
    }

    /// [`Bsdf::sample`] of the model alone (in the normal map's frame, if there is one).
    #[inline]
    fn sample_model(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let Some(map) = &self.normal_map else {
            return self.sample_shaded(wo, u_lobe, u);
        };
        let frame = map.frame(wo);
        let mut s = self.sample_shaded(frame.to_local(wo), u_lobe, u)?;
        let wi = frame.to_shading(s.wi);
        if !normalmap::same_side(wi, s.wi) {
            return None;
        }
        s.f = finite_or_zero(s.f * map.shadowing(frame.n, wi));
        s.wi = wi;
        Some(s)
    }

    /// [`Bsdf::sample`] of the model in its own shading frame.
    #[inline]
    fn sample_shaded(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
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
        match &self.kind {
            BsdfKind::Diffuse { reflectance } => diffuse::sample(*reflectance, v, u),
            BsdfKind::Conductor {
                eta,
                k,
                specular_reflectance,
            } => conductor::sample_smooth(*eta, *k, *specular_reflectance, v),
            BsdfKind::RoughConductor {
                eta,
                k,
                specular_reflectance,
                microfacet,
            } => conductor::sample_rough(microfacet, *eta, *k, *specular_reflectance, v, u),
            BsdfKind::Dielectric {
                eta,
                specular_reflectance,
                specular_transmittance,
            } => dielectric::sample_smooth(
                *eta,
                *specular_reflectance,
                *specular_transmittance,
                v,
                u_lobe,
            ),
            BsdfKind::ThinDielectric {
                eta,
                specular_reflectance,
                specular_transmittance,
            } => dielectric::sample_thin(
                *eta,
                *specular_reflectance,
                *specular_transmittance,
                v,
                u_lobe,
            ),
            BsdfKind::RoughDielectric {
                eta,
                specular_reflectance,
                specular_transmittance,
                microfacet,
            } => dielectric::sample_rough(
                microfacet,
                *eta,
                *specular_reflectance,
                *specular_transmittance,
                v,
                u_lobe,
                u,
            ),
            BsdfKind::Plastic(p) => plastic::sample_smooth(p, v, u_lobe, u),
            BsdfKind::RoughPlastic(p) => plastic::sample_rough(p, v, u_lobe, u),
            BsdfKind::Principled(p) => principled::sample(p, v, u_lobe, u),
            BsdfKind::PrincipledThin(p) => principled_thin::sample(p, v, u_lobe, u),
            BsdfKind::Blend(b) => blend::sample(b, v, u_lobe, u),
            BsdfKind::Null => Some(delta(-v, Vec3::ONE, 1.0, TRANSMIT_DELTA, 1.0)),
            BsdfKind::Black => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
                opacity: 1.0,
                normal: Vec3::new(0.5, 0.5, 1.0),
                alpha: None,
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
                    Bsdf::thin_dielectric(1.5, s0, t0),
                    Bsdf::thin_dielectric(1.5, s1, t1),
                ),
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

    /// The enum stays small (it is copied into path vertices): the largest model (the
    /// principled's twelve parameters), the two-sided flag, the opacity and a quantised normal
    /// map.
    #[test]
    fn bsdf_is_small() {
        assert!(
            core::mem::size_of::<Bsdf>() <= 80,
            "{}",
            core::mem::size_of::<Bsdf>()
        );
    }

    /// A blend (a weight and a reference to its interned components) is smaller than the
    /// largest model, so adding it made neither [`BsdfKind`] nor [`Bsdf`] larger (both were 64
    /// and 80 bytes before it, with the same alignment: the rough plastic's table reference
    /// already made the enum 8-byte aligned).
    #[test]
    fn blend_does_not_grow_the_enum() {
        use crate::models::principled::Principled;
        eprintln!(
            "size_of: Bsdf {}, BsdfKind {}, Blend {}, Principled {}",
            core::mem::size_of::<Bsdf>(),
            core::mem::size_of::<BsdfKind>(),
            core::mem::size_of::<Blend>(),
            core::mem::size_of::<Principled>()
        );
        assert!(core::mem::size_of::<Blend>() <= core::mem::size_of::<Principled>());
        assert_eq!(
            core::mem::align_of::<Blend>(),
            core::mem::align_of::<BsdfKind>()
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
}
