//! ReSTIR PT settings and their parsing from `name = value` parameters (XML scenes and the
//! command line use the same names; the reuse parameters are ReSTIR DI's).

use restir_gris::MisScheme;

use crate::params::{parse_bool, parse_count, parse_mis, parse_positive};
use crate::path::PathSettings;

use super::sample::ShiftKind;

/// The shifts `--shift` accepts.
pub const SHIFT_NAMES: &[&str] = &["reconnection", "replay", "hybrid"];

/// Everything ReSTIR PT can be told.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestirPtSettings {
    /// Path settings: depth semantics, Russian roulette, hidden emitters.
    pub path: PathSettings,
    /// Candidate paths per pixel in initial sampling (default 1).
    pub candidates: u32,
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
    /// Largest angle between neighbour shading normals, as a cosine (default cos 25°).
    pub normal_cos: f32,
    /// Largest relative difference of camera distances (default 0.1).
    pub depth_tolerance: f32,
    /// Shortest reconnection segment, as a fraction of the scene's bounding-sphere radius
    /// (default 0.01).
    pub near_distance: f32,
    /// Reject shifts whose Jacobian `J` has `max(J, 1/J)` above this (symmetric, so unbiased);
    /// 0 (default) rejects none.
    pub max_jacobian: f32,
    /// Path-trace the direct light at the primary hit (light sampling and BSDF sampling with
    /// the power heuristic, per pixel) instead of carrying it in the reservoirs (`direct = path`;
    /// default `reservoir`).
    pub direct_path_traced: bool,
    /// Hand the direct light at the primary hit (and the emitters the camera sees) to a ReSTIR DI
    /// pass with the same reuse settings; the reservoirs carry the paths of three or more
    /// segments (`direct = restir-di`).
    pub direct_restir_di: bool,
    /// Negative control only: use Jacobian 1 in every shift (biased).
    pub unit_jacobian: bool,
    /// The shift between pixels (default hybrid; plain reconnection in scenes without
    /// near-specular materials).
    pub shift: ShiftKind,
    /// Negative control only: skip the hybrid shift's invertibility checks (biased).
    pub skip_invertibility: bool,
}

impl RestirPtSettings {
    /// The defaults (one candidate path, one round of three neighbours, defensive pairwise MIS).
    pub fn new(path: PathSettings) -> Self {
        Self {
            path,
            candidates: 1,
            neighbors: 3,
            radius: 30.0,
            spatial_rounds: 1,
            mis: MisScheme::DefensivePairwise,
            mcap: 20.0,
            temporal: false,
            normal_cos: 25f32.to_radians().cos(),
            depth_tolerance: 0.1,
            near_distance: 0.01,
            max_jacobian: 0.0,
            direct_path_traced: false,
            direct_restir_di: false,
            unit_jacobian: false,
            shift: ShiftKind::Hybrid,
            skip_invertibility: false,
        }
    }

    /// Whether the estimator is unbiased with these settings.
    pub fn is_unbiased(&self) -> bool {
        self.mis.is_unbiased() && !self.unit_jacobian && !self.skip_invertibility
    }

    /// Applies `name = value` parameters in order (later ones win). Names are case-insensitive,
    /// `-` and `_` are the same. Returns the names it did not know, for the caller to warn about.
    pub fn apply(&mut self, params: &[(String, String)]) -> Result<Vec<String>, String> {
        let mut unknown = Vec::new();
        for (name, value) in params {
            let key = name.to_ascii_lowercase().replace('-', "_");
            let v = value.trim();
            match key.as_str() {
                "candidates" | "path_candidates" | "initial_candidates" | "num_candidates" => {
                    self.candidates = parse_count(name, v, 1)?;
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
                "shift" | "shift_mapping" => {
                    self.shift = match v.to_ascii_lowercase().as_str() {
                        "reconnection" | "reconnect" => ShiftKind::Reconnection,
                        "replay" | "random_replay" | "random-replay" => ShiftKind::Replay,
                        "hybrid" => ShiftKind::Hybrid,
                        _ => {
                            return Err(format!(
                                "{name} = '{v}': expected one of {}",
                                SHIFT_NAMES.join(", ")
                            ));
                        }
                    };
                }
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
                "near_distance" | "distance_threshold" => {
                    self.near_distance = parse_positive(name, v)?;
                }
                "max_jacobian" | "jacobian_threshold" => {
                    let j = parse_positive(name, v)?;
                    if j <= 1.0 {
                        return Err(format!("{name} = {v}: expected a number above 1"));
                    }
                    self.max_jacobian = j;
                }
                "direct" => {
                    (self.direct_path_traced, self.direct_restir_di) =
                        match v.to_ascii_lowercase().replace('_', "-").as_str() {
                            "reservoir" | "reservoirs" => (false, false),
                            "path" => (true, false),
                            "restir-di" | "restirdi" | "di" => (false, true),
                            _ => {
                                return Err(format!(
                                    "{name} = '{v}': expected reservoir, path or restir-di"
                                ));
                            }
                        };
                }
                "unit_jacobian" => self.unit_jacobian = parse_bool(name, v)?,
                "skip_invertibility" => self.skip_invertibility = parse_bool(name, v)?,
                _ => unknown.push(name.clone()),
            }
        }
        Ok(unknown)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_errors() {
        let mut s = RestirPtSettings::new(PathSettings {
            max_depth: 4,
            rr_depth: 5,
            hide_emitters: false,
        });
        let p = |a: &str, b: &str| (a.to_string(), b.to_string());
        let unknown = s
            .apply(&[
                p("neighbour_select", "5"),
                p("spatial-rounds", "2"),
                p("candidates", "4"),
                p("mis", "balance"),
                p("shift", "reconnection"),
                p("foo", "1"),
            ])
            .unwrap();
        assert_eq!(unknown, vec!["foo".to_string()]);
        assert_eq!((s.neighbors, s.spatial_rounds, s.candidates), (5, 2, 4));
        assert_eq!(s.mis, MisScheme::GeneralizedBalance);
        s.apply(&[p("shift", "replay")]).unwrap();
        assert_eq!(s.shift, ShiftKind::Replay);
        assert!(
            s.apply(&[p("shift", "manifold")])
                .unwrap_err()
                .contains("reconnection, replay, hybrid")
        );
        assert!(s.apply(&[p("candidates", "0")]).is_err());
    }
}
