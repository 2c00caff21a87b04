//! What the screen-space ReSTIR estimators (ReSTIR DI and ReSTIR PT) share, one floor below
//! them: the per-pixel primary hits ([`gbuffer`]), neighbour selection ([`neighbors`]) and
//! the light-point sample ([`light_point`]) and the reuse settings ([`settings`]).

pub mod gbuffer;
pub mod light_point;
pub mod neighbors;
pub mod settings;

pub use settings::{MIS_NAMES, ReuseSettings, mis_name};
