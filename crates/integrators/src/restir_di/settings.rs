//! ReSTIR DI settings and their parsing from named parameters (XML scenes and the command line
//! use the same names; the names Lajolla ReSTIR ports use are accepted too). The reuse settings
//! are [`ReuseSettings`].

use crate::params::{Param, ParamError, ParamSet};
use crate::path::PathSettings;
use crate::reuse::settings::ReuseSettings;

/// Where initial candidates' lights come from (`--light-sampler`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightSampler {
    /// The power-based light sampler (the paper's choice; default).
    Power,
    /// Per 16×16-pixel tile, a mixture of a distance-aware table and the power sampler
    /// (see [`super::tiles`]).
    Tiles,
}

impl LightSampler {
    /// The names `--light-sampler` takes.
    pub const NAMES: &[(&str, LightSampler)] = &[
        ("power", LightSampler::Power),
        ("tiles", LightSampler::Tiles),
    ];

    /// The name `--light-sampler` takes.
    pub fn name(self) -> &'static str {
        match self {
            LightSampler::Power => "power",
            LightSampler::Tiles => "tiles",
        }
    }
}

/// Everything ReSTIR DI can be told.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestirDiSettings {
    /// Path settings: depth semantics, Russian roulette, hidden emitters.
    pub path: PathSettings,
    /// Spatial and temporal reuse.
    pub reuse: ReuseSettings,
    /// Light candidates per pixel in initial resampling, `N_L` (default 8, chosen by an
    /// equal-CPU-time sweep on a training family of generated scenes; `docs/BENCHMARKS.md`).
    pub candidates: u32,
    /// Where candidates' lights come from (default the power sampler).
    pub light_sampler: LightSampler,
    /// BSDF samples per pixel, `N_B` (default 1), combined with the reservoirs' light strategy
    /// by the balance heuristic.
    pub bsdf_candidates: u32,
    /// Zero an occluded initial candidate, keeping its confidence. Biased at shadow edges.
    pub visibility_reuse: bool,
}

impl RestirDiSettings {
    /// The defaults (Bitterli et al. 2020's unbiased configuration with 8 candidates instead of
    /// the paper's 32, which cost more than they gain on a CPU; `docs/RESTIR_DI.md`).
    pub fn new(path: PathSettings) -> Self {
        Self {
            path,
            reuse: ReuseSettings::default(),
            candidates: 8,
            light_sampler: LightSampler::Power,
            bsdf_candidates: 1,
            visibility_reuse: false,
        }
    }

    /// Whether the estimator is unbiased with these settings.
    pub fn is_unbiased(&self) -> bool {
        self.reuse.is_unbiased() && !self.visibility_reuse
    }

    /// Applies `params` in order (later ones win). Names are case-insensitive, `-` and `_` are
    /// the same. Returns the parameters it did not know, for the caller to warn about.
    pub fn apply(&mut self, params: &ParamSet) -> Result<Vec<Param>, ParamError> {
        params.apply(|key, p| {
            match key {
                "candidates" | "light_candidates" | "initial_candidates" | "num_candidates"
                | "reservoir_size" | "reservior_size" => self.candidates = p.count(1)?,
                "light_sampler" => {
                    self.light_sampler = p.choice(LightSampler::NAMES, "power or tiles")?;
                }
                "bsdf_candidates" | "brdf_candidates" => self.bsdf_candidates = p.count(0)?,
                "visibility_reuse" => self.visibility_reuse = p.boolean()?,
                _ => return self.reuse.apply(key, p),
            }
            Ok(true)
        })
    }
}

#[cfg(test)]
mod tests {
    use restir_gris::MisScheme;

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
        let p = |a: &str, b: &str| ParamSet::from(&[(a, b)][..]);
        let unknown = s
            .apply(&ParamSet::from(
                &[
                    ("neighbour_select", "5"),
                    ("spatial_iteration", "2"),
                    ("reservior_size", "16"),
                    ("m-capping", "8"),
                    ("mis", "one_over_z"),
                    ("nearClip", "1"),
                ][..],
            ))
            .unwrap();
        let names: Vec<&str> = unknown.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["nearClip"]);
        assert_eq!(
            (s.reuse.neighbors, s.reuse.spatial_rounds, s.candidates),
            (5, 2, 16)
        );
        assert_eq!((s.reuse.mcap, s.reuse.mis), (8.0, MisScheme::OneOverZ));
        assert!(s.apply(&p("candidates", "0")).is_err());
        assert!(s.apply(&p("radius", "NaN")).is_err());
        assert!(
            s.apply(&p("mis", "magic"))
                .unwrap_err()
                .to_string()
                .contains("defensive-pairwise")
        );
        assert!(s.apply(&p("temporal", "maybe")).is_err());
        assert_eq!(
            s.apply(&p("light_sampler", "near"))
                .unwrap_err()
                .to_string(),
            "light_sampler = 'near': expected power or tiles"
        );
    }
}
