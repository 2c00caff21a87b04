//! Sampling building blocks for the `restir` renderer.
//!
//! - [`Pcg32`]: a small PCG random number generator whose whole state can be stored and restored
//!   (ReSTIR PT replays paths from stored states), with [`Pcg32::for_pixel_sample`] deriving
//!   independent streams from `(seed, pixel, sample index)`.
//! - [`sequences`]: low-discrepancy sequences (Halton, R2).
//! - [`warp`]: warps from the unit square with their pdfs, in triples (`sample_*`, `*_pdf`, and the
//!   inverse where it exists).
//! - [`lanes`]: eight `f32` lanes ([`lanes::F8`]) for lane-parallel estimators, with the warps
//!   they need.
//! - [`hash`]: FNV-1a, a stable hash for cache keys and checksums.
//! - [`Distribution1D`], [`Distribution2D`]: piecewise-constant distributions; [`AliasTable`]: O(1)
//!   discrete sampling.
//!
//! Conventions: random numbers are arguments (`u: f32`, `u: Vec2`) in `[0, 1)`; a pdf over
//! directions is per unit solid angle and its name says so (`*_pdf` functions in [`warp`] document
//! their measure); discrete probabilities are called `pmf`.
//!
//! ```
//! use restir_sampling::{Pcg32, warp};
//! use glam::Vec2;
//! let mut rng = Pcg32::for_pixel_sample(7, 1234, 0);
//! let u = Vec2::new(rng.next_f32(), rng.next_f32());
//! let wi = warp::sample_cosine_hemisphere(u);
//! let pdf_sa = warp::cosine_hemisphere_pdf(wi.z);
//! assert!(wi.z >= 0.0 && pdf_sa >= 0.0);
//! ```

#![deny(missing_docs)]

mod distribution;
pub mod hash;
pub mod lanes;
pub mod owen;
mod rng;
pub mod sequences;
pub mod warp;

pub use distribution::{AliasTable, Distribution1D, Distribution2D};
pub use owen::OwenSobol;
pub use rng::{Pcg32, mix64};

/// A pixel sample's source of uniform numbers in `[0, 1)`: a random generator ([`Pcg32`]) or a
/// randomised low-discrepancy sequence ([`OwenSobol`]). Estimators draw from it in a fixed order
/// (the same count per path vertex), so that a sequence's dimensions line up across samples.
pub trait Sampler {
    /// One number.
    fn next_1d(&mut self) -> f32;
    /// Two numbers (one point of a 2-D dimension, for a sequence).
    fn next_2d(&mut self) -> glam::Vec2;
}

impl Sampler for Pcg32 {
    #[inline]
    fn next_1d(&mut self) -> f32 {
        self.next_f32()
    }
    #[inline]
    fn next_2d(&mut self) -> glam::Vec2 {
        Pcg32::next_2d(self)
    }
}

impl Sampler for OwenSobol {
    #[inline]
    fn next_1d(&mut self) -> f32 {
        self.next_f32()
    }
    #[inline]
    fn next_2d(&mut self) -> glam::Vec2 {
        OwenSobol::next_2d(self)
    }
}

/// The largest `f32` strictly below one: random numbers are clamped to it so that `u < 1` holds.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Relative luminance of a linear RGB value with Mitsuba 3's coefficients (sRGB primaries, D65),
/// the one scalarisation used across the workspace: light powers, envmap importance, ReSTIR target
/// functions and Russian roulette all use it.
#[inline]
pub fn luminance(rgb: glam::Vec3) -> f32 {
    0.212_671 * rgb.x + 0.715_160 * rgb.y + 0.072_169 * rgb.z
}
