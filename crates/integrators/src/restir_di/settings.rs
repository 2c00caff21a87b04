//! ReSTIR DI settings and their parsing from `name = value` parameters (XML scenes and the
//! command line use the same names; the names Lajolla ReSTIR ports use are accepted too).

use restir_gris::MisScheme;

use crate::params::{parse_bool, parse_count, parse_mis, parse_positive};
use crate::path::PathSettings;

/// How spatial and temporal reuse weight their inputs (`--mis`).
pub const MIS_NAMES: &[(&str, MisScheme)] = &[
    ("defensive-pairwise", MisScheme::DefensivePairwise),
    ("pairwise", MisScheme::Pairwise),
    ("confidence-pairwise", MisScheme::ConfidenceWeightedPairwise),
    ("balance", MisScheme::GeneralizedBalance),
    ("contribution", MisScheme::Contribution),
    ("one-over-z", MisScheme::OneOverZ),
    ("uniform", MisScheme::ConstantBiased),
];

/// The command-line name of an MIS scheme.
pub fn mis_name(scheme: MisScheme) -> &'static str {
    MIS_NAMES
        .iter()
        .find(|(_, s)| *s == scheme)
        .map_or("?", |(n, _)| n)
}

/// Where initial candidates' lights come from (`--light-sampler`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightSampler {
    /// The power-based light sampler (the paper's choice; default).
    Power,
    /// Per 16×16-pixel tile, a mixture of a distance-aware table and the power sampler
    /// (see [`super::tiles`]).
    Tiles,
}

/// Everything ReSTIR DI can be told.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestirDiSettings {
    /// Path settings: depth semantics, Russian roulette, hidden emitters.
    pub path: PathSettings,
    /// Light candidates per pixel in initial resampling, `N_L` (default 32).
    pub candidates: u32,
    /// Where candidates' lights come from (default the power sampler).
    pub light_sampler: LightSampler,
    /// BSDF samples per pixel, `N_B` (default 1), combined with the reservoirs' light strategy
    /// by the balance heuristic.
    pub bsdf_candidates: u32,
    /// Spatial neighbours per round, `k` (default 3).
    pub neighbors: u32,
    /// Spatial radius in pixels (default 30).
    pub radius: f32,
    /// Spatial reuse rounds, `R` (default 1).
    pub spatial_rounds: u32,
    /// MIS for reuse (default defensive pairwise).
    pub mis: MisScheme,
    /// Absolute confidence cap after every reuse step (default 20).
    pub mcap: f32,
    /// Reuse the previous pass's reservoirs (default off).
    pub temporal: bool,
    /// Zero an occluded initial candidate, keeping its confidence. Biased at shadow edges.
    pub visibility_reuse: bool,
    /// Largest angle between neighbour shading normals, as a cosine (default cos 25°).
    pub normal_cos: f32,
    /// Largest relative difference of camera distances (default 0.1).
    pub depth_tolerance: f32,
}

impl RestirDiSettings {
    /// The defaults (Bitterli et al. 2020's unbiased configuration; `docs/RESTIR_DI.md`).
    pub fn new(path: PathSettings) -> Self {
        Self {
            path,
            candidates: 32,
            light_sampler: LightSampler::Power,
            bsdf_candidates: 1,
            neighbors: 3,
            radius: 30.0,
            spatial_rounds: 1,
            mis: MisScheme::DefensivePairwise,
            mcap: 20.0,
            temporal: false,
            visibility_reuse: false,
            normal_cos: 25f32.to_radians().cos(),
            depth_tolerance: 0.1,
        }
    }

    /// Whether the estimator is unbiased with these settings.
    pub fn is_unbiased(&self) -> bool {
        self.mis.is_unbiased() && !self.visibility_reuse
    }

    /// Applies `name = value` parameters in order (later ones win). Names are case-insensitive,
    /// `-` and `_` are the same. Returns the names it did not know, for the caller to warn about.
    pub fn apply(&mut self, params: &[(String, String)]) -> Result<Vec<String>, String> {
        let mut unknown = Vec::new();
        for (name, value) in params {
            let key = name.to_ascii_lowercase().replace('-', "_");
            let v = value.trim();
            match key.as_str() {
                "candidates" | "light_candidates" | "initial_candidates" | "num_candidates"
                | "reservoir_size" | "reservior_size" => {
                    self.candidates = parse_count(name, v, 1)?;
                }
                "light_sampler" => {
                    self.light_sampler = match v.to_ascii_lowercase().as_str() {
                        "power" => LightSampler::Power,
                        "tiles" => LightSampler::Tiles,
                        _ => return Err(format!("{name} = '{v}': expected power or tiles")),
                    };
                }
                "bsdf_candidates" | "brdf_candidates" => {
                    self.bsdf_candidates = parse_count(name, v, 0)?;
                }
                "neighbors"
                | "neighbours"
                | "neighbors_per_pixel"
                | "neighbours_per_pixel"
                | "neighbor_select"
                | "neighbour_select"
                | "num_neighbors"
                | "spatial_neighbors" => {
                    self.neighbors = parse_count(name, v, 0)?;
                }
                "radius" | "max_radius" | "spatial_radius" => {
                    self.radius = parse_positive(name, v)?;
                }
                "spatial_rounds" | "spatial_iteration" | "spatial_iterations"
                | "spatial_passes" => {
                    self.spatial_rounds = parse_count(name, v, 0)?;
                }
                "mis" | "bias_correction" => self.mis = parse_mis(name, v)?,
                "mcap" | "m_cap" | "m_capping" | "max_history" => {
                    self.mcap = parse_positive(name, v)?;
                }
                "temporal" | "temporal_reuse" => self.temporal = parse_bool(name, v)?,
                "visibility_reuse" => self.visibility_reuse = parse_bool(name, v)?,
                "normal_threshold" => {
                    let deg = parse_positive(name, v)?;
                    if deg > 180.0 {
                        return Err(format!(
                            "{name} = {v}: expected an angle in degrees up to 180"
                        ));
                    }
                    self.normal_cos = deg.to_radians().cos();
                }
                "depth_threshold" => self.depth_tolerance = parse_positive(name, v)?,
                _ => unknown.push(name.clone()),
            }
        }
        Ok(unknown)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings() -> RestirDiSettings {
        RestirDiSettings::new(PathSettings {
            max_depth: 2,
            rr_depth: 5,
            hide_emitters: false,
        })
    }

    #[test]
    fn lajolla_names_and_errors() {
        let mut s = settings();
        let p = |a: &str, b: &str| (a.to_string(), b.to_string());
        let unknown = s
            .apply(&[
                p("neighbour_select", "5"),
                p("spatial_iteration", "2"),
                p("reservior_size", "16"),
                p("m-capping", "8"),
                p("mis", "one_over_z"),
                p("nearClip", "1"),
            ])
            .unwrap();
        assert_eq!(unknown, vec!["nearClip".to_string()]);
        assert_eq!((s.neighbors, s.spatial_rounds, s.candidates), (5, 2, 16));
        assert_eq!((s.mcap, s.mis), (8.0, MisScheme::OneOverZ));
        assert!(s.apply(&[p("candidates", "0")]).is_err());
        assert!(s.apply(&[p("radius", "NaN")]).is_err());
        assert!(
            s.apply(&[p("mis", "magic")])
                .unwrap_err()
                .contains("defensive-pairwise")
        );
        assert!(s.apply(&[p("temporal", "maybe")]).is_err());
    }
}
