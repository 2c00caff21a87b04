//! Screen-space ReSTIR reuse over a host renderer's own surfaces, samples and shift map.
//!
//! [`restir_gris`] is the mathematics of one resampling step (reservoirs, GRIS, MIS weights,
//! Jacobians). This crate runs those steps over an image the way ReSTIR DI (Bitterli et al.
//! 2020) and ReSTIR PT (Lin et al. 2022) do: temporal reuse with the previous pass's reservoirs,
//! spatial rounds over similar neighbours (ping-ponging two buffers, so results do not depend on
//! thread scheduling), reciprocal neighbour pairs that share their shifts, confidence caps, the
//! history across passes and across the frames of a moving sequence. It knows nothing of the
//! scene: the host renderer brings
//!
//! * its G-buffer, through [`Surfaces`] (which pixels see a surface, which are similar, which
//!   pixel of the previous pass saw the same point);
//! * its random streams, through [`Streams`] (or [`SeededStreams`]);
//! * either its direct lighting through [`direct::DirectLighting`] (a light sample, its density,
//!   the target, the contribution, a visibility test), and gets ReSTIR DI from
//!   [`direct::RestirDi`];
//! * or its own sample type and shift map through [`ReuseShift`] and runs the passes with
//!   [`ScreenReuse`] (what this project's renderer does for ReSTIR DI, whose light samples follow
//!   moving lights, and for ReSTIR PT, whose paths shift by reconnection and replay).
//!
//! Every loop is generic over the host's types: nothing is dispatched through a trait object
//! per sample. The [`guide`] walks through a complete host renderer in about a hundred lines.
//!
//! | module | what it holds |
//! |---|---|
//! | [`surfaces`] | the host's image: [`Surfaces`], [`Streams`], the common similarity test |
//! | [`settings`] | [`ReuseSettings`]: neighbours, radius, rounds, MIS, confidence cap, temporal reuse |
//! | [`shift`] | [`ReuseShift`]: how an estimator plugs in (its sample, domain and shift map) |
//! | [`passes`] | temporal reuse, the spatial rounds, the history |
//! | [`reciprocal`], [`neighbors`], [`duplication`] | reciprocal pairs; the neighbour pattern; the duplication-aware history cap |
//! | [`driver`] | [`ScreenReuse`]: one pass's reuse in order, and the state kept between passes |
//! | [`direct`] | ReSTIR DI over a host's lights |
//! | [`bands`] | the parallel loop over the image (bands of rows, on rayon) |

#![deny(missing_docs)]

pub mod bands;
pub mod direct;
pub mod driver;
pub mod duplication;
pub mod neighbors;
pub mod passes;
pub mod reciprocal;
pub mod settings;
pub mod shift;
pub mod surfaces;

pub mod guide {
    #![doc = include_str!("../GUIDE.md")]
}

pub use driver::{ReuseReport, ScreenReuse, Stages};
pub use passes::{History, HistorySlot};
pub use settings::{MIS_NAMES, ReuseSettings, mis_name};
pub use shift::ReuseShift;
pub use surfaces::{SeededStreams, Similarity, SimilarityKey, Streams, Surfaces};

/// The reservoir type and the MIS schemes, re-exported from `restir-gris`.
pub use restir_gris::{MisScheme, Reservoir};
/// The random number generator of the streams (PCG32), re-exported so that a host needs no
/// other crate of this project.
pub use restir_sampling::Pcg32;
