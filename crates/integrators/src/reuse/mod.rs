//! What the screen-space ReSTIR estimators (ReSTIR DI and ReSTIR PT) share, one floor below
//! them: the per-pixel primary hits ([`gbuffer`]), neighbour selection ([`neighbors`]) and
//! the reuse settings ([`settings`]) and the reuse
//! passes themselves ([`passes`]: temporal reuse, the spatial rounds and the history, generic
//! over the estimator's sample and shift map, as pbrt-v4's `ImageTileIntegrator` is over its
//! `RayIntegrator`; [`reciprocal`]: spatial rounds over reciprocal neighbour pairs, which share
//! their shifts; [`duplication`]: the history's confidence cap for duplicated samples).

pub mod duplication;
pub mod gbuffer;
pub mod neighbors;
pub mod passes;
pub mod reciprocal;
pub mod settings;

pub use settings::{MIS_NAMES, ReuseSettings, mis_name};
