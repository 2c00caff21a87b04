//! BSDFs for the `restir` renderer, after Mitsuba 3's models.
//!
//! Conventions (stated once, used everywhere):
//! - Everything is in the local shading frame: `z` is the shading normal.
//! - `wo` points towards the viewer (the previous path vertex), `wi` towards the light (the next
//!   vertex); both point away from the surface. Light flows from `wi` to `wo`.
//! - [`Bsdf::eval`] returns `f(wo, wi) · |cos θi|`: the BSDF *including* the foreshortening cosine.
//! - [`Bsdf::pdf_sa`] is the density of [`Bsdf::sample`] per unit solid angle of `wi`.
//! - Delta lobes (mirror, smooth glass) are returned only by [`Bsdf::sample`]; `eval` and `pdf_sa`
//!   return zero for them. A delta sample's `pdf_sa` holds the discrete probability of choosing
//!   that lobe and its `f` is the lobe's weight times that probability, so `f / pdf_sa` is the
//!   throughput weight in every case.
//! - One-sided models (diffuse, conductors, plastics) are black unless both `wo` and `wi` are above
//!   the surface, as in Mitsuba; [`Bsdf::two_sided`] wraps them. Transmitting models (dielectric,
//!   rough dielectric, null) are two-sided by nature: seen from below (`wo.z < 0`) the relative
//!   IOR is `1/eta`.
//! - **Radiance across refraction** (Mitsuba 3's radiance mode): transmitted radiance is scaled by
//!   `1/η'²`, with `η'` the relative IOR `η_t/η_i` seen from `wo`'s side. The smooth dielectric's
//!   transmission weight is `kt·(η_i/η_t)²`; in the rough dielectric's `eval` the `η'²` of Walter
//!   et al.'s BTDF and the scale `1/η'²` cancel. The radiance BTDF is therefore not symmetric:
//!   `f(wo, wi)/η_o² = f(wi, wo)/η_i²` (Veach 1997, §5.2). A transmission sample's `eta` is
//!   `η'`, so a path's product of `eta²` undoes the scaling where energy is wanted (Russian
//!   roulette, as Mitsuba: `q = min(max(β)·η², 0.95)`). Reflection samples have `eta = 1`.
//! - Sample records: `lobe` is the lobe that produced the sample (`DELTA`/`GLOSSY`/`DIFFUSE` with
//!   `REFLECTION`/`TRANSMISSION`); `roughness` is Mitsuba's α (`√(αu·αv)` when anisotropic), 1
//!   for diffuse and 0 for delta lobes. For non-delta samples of a model with several lobes
//!   (rough plastic, rough dielectric), `f` and `pdf_sa` are the whole model's `eval` and `pdf_sa`
//!   (one-sample MIS over the lobes, as Mitsuba), so `f/pdf_sa` is what `eval/pdf_sa` gives.
//!
//! # Models
//!
//! [`BsdfKind`] holds Mitsuba 3's `diffuse`, `conductor`, `roughconductor`, `dielectric`,
//! `roughdielectric`, `plastic`, `roughplastic` and `null`, and `blendbsdf` (two of them mixed by
//! a weight: [`Blend`], `src/models/blend.rs`), with Mitsuba's parameters, defaults and
//! formulas (the specification is Mitsuba 3's plugin reference, "BSDFs", and its
//! `src/bsdfs/*.cpp`; each model's documentation names the paper it follows). Each family's
//! maths sits in one file of `src/models/` (`diffuse`, `conductor`, `dielectric`, `plastic`: its
//! parameters, `eval`, `pdf` and `sample` and their tests); `src/bsdf.rs` holds [`Bsdf`] and the
//! dispatch, one `match` per method. Beneath them: [`microfacet`] (GGX and Beckmann,
//! anisotropic, separable Smith, visible-normal sampling), [`fresnel`] (exact dielectric and
//! conductor Fresnel, the diffuse Fresnel fit), [`ior`] (named IORs and metals) and [`plastic`]
//! (the rough plastic's precomputed coating tables, in `src/models/plastic/tables.rs`).
//! Deliberate differences from Mitsuba, none of which changes an expected value:
//! - visible normals are always sampled (Mitsuba's `sample_visible = false` samples `D` instead);
//! - the VNDF pdf uses the exact Beckmann Smith term (Mitsuba's rational G1 fit stays in `eval`),
//!   so that the pdf is the density the sampler draws from; Mitsuba's sample weight assumes the
//!   fit normalises it, which it does to 0.35 %;
//! - the Beckmann visible-slope sampler takes a fixed two Newton steps in `f32` from Jakob's
//!   starting point (CDF residual below 1e-5), so the rough plastic tables (integrated through
//!   it) agree with Mitsuba's to ~1e-4, not 1e-6.
//!
//! # The set of models is closed
//!
//! A program using this crate cannot add a BSDF model of its own: [`Bsdf`] holds a
//! [`BsdfKind`], an enum of the models above, and every method dispatches with one `match` over
//! it. This is deliberate. The estimators evaluate and sample BSDFs in their innermost loops
//! (every candidate, every shift, every bounce); an enum keeps those calls monomorphised, lets
//! the compiler inline each model's code into the `match`, and keeps a material a small `Copy`
//! value with no allocation, where a trait object would add an indirect call per evaluation
//! and hide the model from the optimiser. pbrt-v4 makes the same choice (its BxDF type is a
//! tagged union over a fixed list of models, dispatched by a `switch` on the tag, for the same
//! reason, and adding a model there also means editing that list).
//!
//! What a user does instead:
//! - **Use the nearest model through its parameters**: the eight models with Mitsuba 3's
//!   parameters cover diffuse, metals (any IOR, anisotropic roughness, GGX or Beckmann),
//!   glass (smooth or rough), coated diffuse (plastic, smooth or rough), and textures reach the
//!   colour parameters (see `restir-scene`).
//! - **Fork** and add a variant to [`BsdfKind`] with a file in `src/models/`: the compiler then
//!   lists every `match` that must learn the new model.
//! - **Bring your own renderer**: the reuse passes are offered generically over host traits by
//!   the `restir-reuse` crate, and the GRIS maths by `restir-gris`; a renderer with its own
//!   materials implements their target function and gets ReSTIR without this crate.
//!
//! ```
//! use restir_materials::{Bsdf, LobeFlags};
//! use glam::{Vec2, Vec3};
//! let bsdf = Bsdf::diffuse(Vec3::splat(0.5));
//! let wo = Vec3::new(0.0, 0.6, 0.8);
//! let s = bsdf.sample(wo, 0.3, Vec2::new(0.2, 0.7)).unwrap();
//! assert!(s.lobe.contains(LobeFlags::DIFFUSE));
//! // For diffuse, f/pdf is exactly the reflectance.
//! assert!(((s.f / s.pdf_sa) - Vec3::splat(0.5)).abs().max_element() < 1e-5);
//! assert!((bsdf.pdf_sa(wo, s.wi) - s.pdf_sa).abs() < 1e-5);
//! ```

#![deny(missing_docs)]

mod bsdf;
pub mod fresnel;
pub mod ior;
pub mod lanes;
mod lobe;
pub mod microfacet;
mod models;

pub use bsdf::{Bsdf, BsdfKind, ReflectanceParams};
pub use lobe::LobeFlags;
pub use microfacet::{Distribution, Microfacet};
pub use models::BsdfSample;
pub use models::blend::Blend;
pub use models::bumpmap::{bump_normal, normal_texel};
pub use models::normalmap::NormalMap;
pub use models::plastic::cache as table_cache;
pub use models::plastic::tables as plastic;
pub use models::plastic::{Plastic, RoughPlastic};
pub use models::principled::{Principled, eta_of_specular};
pub use models::principled_params::PrincipledParam;
pub use models::principled_thin::PrincipledThin;
