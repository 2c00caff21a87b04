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
//!   the surface, as in Mitsuba; [`Bsdf::two_sided`] wraps them.
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

mod bsdf;
pub mod fresnel;
pub mod ior;
mod lobe;
pub mod microfacet;
pub mod plastic;

pub use bsdf::{Bsdf, BsdfKind, BsdfSample, Plastic, RoughPlastic};
pub use lobe::LobeFlags;
pub use microfacet::{Distribution, Microfacet};
