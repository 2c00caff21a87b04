//! The reuse settings' names in scene files and on the command line, and their parsing.

use restir_gris::MisScheme;
use restir_reuse::{MIS_NAMES, ReuseSettings};

use crate::params::{Param, ParamError, ParamProblem};

impl Param {
    /// An MIS scheme by one of [`MIS_NAMES`].
    pub fn mis(&self) -> Result<MisScheme, ParamError> {
        let names: Vec<&str> = MIS_NAMES.iter().map(|(n, _)| *n).collect();
        self.choice(MIS_NAMES, &format!("one of {}", names.join(", ")))
    }
}

/// The film size in pixels (1280×720) from which the reuse's defaults for large films apply
/// where the parameter was not named: ReSTIR DI's neighbours
/// ([`crate::restir_di::LARGE_FILM_NEIGHBORS`]) and ReSTIR PT's radius
/// ([`crate::restir_pt::LARGE_FILM_RADIUS`]). Smaller pixels see more alike surfaces within
/// the same radius in pixels.
pub const LARGE_FILM_PIXELS: u64 = 1280 * 720;

/// `name=value` for the settings line, with why when a film of at least [`LARGE_FILM_PIXELS`]
/// decided the value (`decided`).
pub fn large_film_label(name: &str, value: impl std::fmt::Display, decided: bool) -> String {
    if decided {
        format!("{name}={value} (auto: a film of at least 1280×720 pixels)")
    } else {
        format!("{name}={value}")
    }
}

/// The names of the spatial radius ([`ReuseSettings::radius`]).
pub const RADIUS_NAMES: &[&str] = &["radius", "max_radius", "spatial_radius"];

/// The names of the spatial neighbour count ([`ReuseSettings::neighbors`]).
pub const NEIGHBOR_NAMES: &[&str] = &[
    "neighbors",
    "neighbours",
    "neighbors_per_pixel",
    "neighbours_per_pixel",
    "neighbor_select",
    "neighbour_select",
    "num_neighbors",
    "spatial_neighbors",
];

/// Reading [`ReuseSettings`] from an estimator's parameters.
pub trait ReuseParams {
    /// Reads parameter `p` (normalized name `key`) if it is a reuse setting; returns whether
    /// it was. The names Lajolla ReSTIR ports use are accepted too.
    fn apply(&mut self, key: &str, p: &Param) -> Result<bool, ParamError>;
}

impl ReuseParams for ReuseSettings {
    fn apply(&mut self, key: &str, p: &Param) -> Result<bool, ParamError> {
        match key {
            k if NEIGHBOR_NAMES.contains(&k) => self.neighbors = p.count(0)?,
            k if RADIUS_NAMES.contains(&k) => self.radius = p.positive()?,
            "spatial_rounds" | "spatial_iteration" | "spatial_iterations" | "spatial_passes" => {
                self.spatial_rounds = p.count(0)?;
            }
            "mis" | "bias_correction" => self.mis = p.mis()?,
            "mcap" | "m_cap" | "m_capping" | "max_history" => self.mcap = p.positive()?,
            "temporal" | "temporal_reuse" => self.temporal = p.boolean()?,
            "temporal_mis" => self.temporal_scheme = Some(p.mis()?),
            "reciprocal" | "reciprocal_neighbors" => self.reciprocal = p.boolean()?,
            "reciprocal_mismatched" => self.reciprocal_mismatched = p.boolean()?,
            "temporal_current_scene" => self.temporal_current_scene = p.boolean()?,
            "duplication" | "duplication_map" | "duplication_strength" => {
                self.duplication = p.fraction()?;
            }
            "normal_threshold" => {
                let deg = p.positive()?;
                if deg > 180.0 {
                    return Err(p.error(ParamProblem::AngleTooLarge));
                }
                self.normal_cos = deg.to_radians().cos();
            }
            "depth_threshold" => self.depth_tolerance = p.positive()?,
            "shade" => {
                self.shade_expected = p.choice(
                    &[("expected", true), ("selected", false)],
                    "one of expected, selected",
                )?;
            }
            _ => return Ok(false),
        }
        Ok(true)
    }
}
