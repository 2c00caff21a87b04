//! The screen-space reuse of ReSTIR DI and ReSTIR PT: the passes themselves are the
//! `restir-reuse` crate (re-exported here), which this renderer hosts like any other: its
//! G-buffer ([`gbuffer`]) is the crate's [`Surfaces`](restir_reuse::Surfaces), its
//! [`PassContext`](crate::PassContext) the crate's [`Streams`](restir_reuse::Streams), and
//! [`params`] reads the reuse settings from scene files and the command line.

pub mod chain;
pub mod gbuffer;
pub mod params;
pub mod seen;

pub use restir_reuse::{
    MIS_NAMES, ReuseSettings, duplication, mis_name, neighbors, passes, reciprocal, settings, shift,
};
