//! The settings every screen-space reuse pass shares (ReSTIR DI and ReSTIR PT): neighbours,
//! radius, rounds, MIS, confidence cap, temporal reuse and the similarity thresholds, their
//! names on the command line.

use restir_gris::MisScheme;

use crate::neighbors::NeighborRule;
use crate::surfaces::Similarity;

/// How spatial and temporal reuse weight their inputs (`--mis`).
pub const MIS_NAMES: &[(&str, MisScheme)] = &[
    ("defensive-pairwise", MisScheme::DefensivePairwise),
    ("pairwise", MisScheme::Pairwise),
    ("confidence-pairwise", MisScheme::ConfidenceWeightedPairwise),
    ("balance", MisScheme::GeneralizedBalance),
    ("power", MisScheme::GeneralizedPower),
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

/// Spatial and temporal reuse settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReuseSettings {
    /// Spatial neighbours per round, `k` (default 4).
    pub neighbors: u32,
    /// Spatial radius in pixels (default 3).
    pub radius: f32,
    /// Spatial reuse rounds, `R` (default 1).
    pub spatial_rounds: u32,
    /// MIS for reuse (default defensive pairwise).
    pub mis: MisScheme,
    /// Absolute confidence cap after every reuse step (default 20).
    pub mcap: f32,
    /// Reuse the previous pass's reservoirs (default off).
    pub temporal: bool,
    /// The MIS of temporal reuse, when chosen (`temporal_mis`); else [`Self::temporal_mis`]
    /// decides.
    pub temporal_scheme: Option<MisScheme>,
    /// Largest angle between neighbour shading normals, as a cosine (default cos 25°).
    pub normal_cos: f32,
    /// Largest relative difference of camera distances (default 0.1).
    pub depth_tolerance: f32,
    /// Spatial neighbours in reciprocal pairs that share their shifts ([`crate::reciprocal`];
    /// pairwise MIS only, default on).
    pub reciprocal: bool,
    /// Negative control only: reciprocal pairs read the wrong one of a pair's two shifts
    /// (biased).
    pub reciprocal_mismatched: bool,
    /// Duplication-aware history confidence, strength from 0 (off, the default) to 1: temporal
    /// reuse caps the previous pixel's confidence lower the more of its neighbours hold the
    /// same sample ([`crate::duplication`]). Biased: the cap depends on the sample it weighs.
    pub duplication: f32,
    /// Negative control only: temporal reuse across frames evaluates the previous frame's
    /// domains in the current frame's scene (lights where they are now; biased).
    pub temporal_current_scene: bool,
    /// Whether shading takes the expectation over the last spatial round's selection, every
    /// input with its resampling weight ([`crate::ScreenReuse::reuse_expected`]; default on),
    /// rather than the selected sample alone: the same mean, no more variance, no more shifts.
    pub shade_expected: bool,
}

/// Spatial neighbours per round of ReSTIR DI's reuse ([`ReuseSettings::direct`]): four
/// reciprocal pairs. On the project's DI training family at 640×360 (equal CPU time, 8 passes)
/// eight are 1.13× four's efficiency at the median and gain on every member (1.07–1.26×); twelve
/// are 1.16× but as low as 1.01× (the project repository's `docs/RESTIR_DI.md`, "The defaults at
/// a user's size"). The renderer takes twelve on films of 1280×720 pixels and more, where they
/// pay on every member (its `docs/RESTIR_DI.md`, "Twelve neighbours on large films").
pub const DIRECT_NEIGHBORS: u32 = 8;

/// ReSTIR DI's spatial radius in pixels ([`ReuseSettings::direct`]): with eight neighbours in
/// reciprocal pairs, 2 pixels are 1.05× the efficiency of 3 at the median of the project's DI
/// training family at 640×360 (0.97–1.13×, equal CPU time, 8 passes; the same cost per pass),
/// and 1.03× on its test family, where every member gains (1.01–1.08×; the project
/// repository's `docs/RESTIR_DI.md`, "The defaults at a user's size").
pub const DIRECT_RADIUS: f32 = 2.0;

impl Default for ReuseSettings {
    /// One round of four neighbours in two reciprocal pairs within 3 pixels, defensive pairwise
    /// MIS, `M` capped at 20, no temporal reuse, 25° and 10 % similarity, shading every input
    /// of the last round: ReSTIR PT's, which runs three such rounds, chosen on its training family
    /// (the project repository's `docs/studies/2026-12-02-restir-pt-defaults.md`). ReSTIR DI
    /// takes [`ReuseSettings::direct`].
    fn default() -> Self {
        Self {
            neighbors: 4,
            radius: 3.0,
            spatial_rounds: 1,
            mis: MisScheme::DefensivePairwise,
            mcap: 20.0,
            temporal: false,
            temporal_scheme: None,
            normal_cos: 25f32.to_radians().cos(),
            depth_tolerance: 0.1,
            reciprocal: true,
            reciprocal_mismatched: false,
            duplication: 0.0,
            temporal_current_scene: false,
            shade_expected: true,
        }
    }
}

impl ReuseSettings {
    /// ReSTIR DI's reuse: the [default](ReuseSettings::default) with [`DIRECT_NEIGHBORS`]
    /// neighbours within [`DIRECT_RADIUS`] pixels (the rest chosen on the DI training family
    /// too: the project repository's
    /// `docs/studies/2026-12-02-restir-di-light-pool-and-defaults.md`).
    pub fn direct() -> Self {
        Self {
            neighbors: DIRECT_NEIGHBORS,
            radius: DIRECT_RADIUS,
            ..Self::default()
        }
    }

    /// Whether reuse is unbiased with these settings.
    pub fn is_unbiased(&self) -> bool {
        self.mis.is_unbiased()
            && (!self.temporal || self.temporal_mis().is_unbiased())
            && !(self.reciprocal && self.reciprocal_mismatched)
            && !(self.temporal && self.temporal_current_scene)
            && !(self.temporal && self.duplication > 0.0)
    }

    /// How many pixels from a pixel the spatial rounds of one pass reach: `rounds × ⌈radius⌉`
    /// (neighbours lie in a disk of `radius`, rounded to the nearest pixel), 0 without spatial
    /// reuse. A cropped render renders this halo around its window.
    pub fn halo(&self) -> u32 {
        if self.neighbors == 0 {
            return 0;
        }
        self.spatial_rounds
            .saturating_mul(self.radius.ceil().min(u32::MAX as f32) as u32)
    }

    /// Whether the spatial rounds run in reciprocal pairs ([`crate::reciprocal`]): asked for,
    /// with a pairwise MIS, neighbours and rounds.
    pub fn runs_reciprocal(&self) -> bool {
        self.reciprocal
            && crate::reciprocal::shares_pair_shifts(self.mis)
            && self.neighbors > 0
            && self.spatial_rounds > 0
    }

    /// Reciprocal rounds take neighbours in pairs (`p ± o_j`), so an odd count asks for one
    /// more than a round can take alone: raises it to the even count the rounds use and returns
    /// a note saying so (the settings line then names the count used), or `None` when nothing
    /// changed.
    pub fn pair_neighbors(&mut self) -> Option<String> {
        if !self.runs_reciprocal() || self.neighbors.is_multiple_of(2) {
            return None;
        }
        let asked = self.neighbors;
        self.neighbors = asked.saturating_add(1);
        Some(format!(
            "neighbors = {asked}: reciprocal reuse takes neighbours in pairs, so {} are used \
             (reciprocal = false takes {asked})",
            self.neighbors
        ))
    }

    /// The neighbour rule of the spatial rounds.
    pub fn neighbor_rule(&self) -> NeighborRule {
        NeighborRule {
            count: self.neighbors as usize,
            radius: self.radius,
            similarity: self.similarity(),
        }
    }

    /// The similarity test's thresholds.
    pub fn similarity(&self) -> Similarity {
        Similarity {
            normal_cos: self.normal_cos,
            depth_tolerance: self.depth_tolerance,
        }
    }

    /// The MIS of temporal reuse: `temporal_mis` when given; else, for an unbiased `mis`, the
    /// generalized power heuristic over the two techniques (the pixel and its previous pixel,
    /// which carries up to `mcap` passes of history): like the balance heuristic it lets the
    /// history weigh by its confidence where the two targets agree (defensive pairwise would keep
    /// half the weight on the fresh sample), and it bounds what a history sample brings where
    /// the receiver's target has grown (motion; the repository's `docs/GRIS.md` §4.4′). Chosen over the balance
    /// heuristic on the moving training family (the repository's `docs/studies/2026-12-02-temporal-reuse.md`). Biased schemes stay as chosen.
    pub fn temporal_mis(&self) -> MisScheme {
        if let Some(scheme) = self.temporal_scheme {
            scheme
        } else if self.mis.is_unbiased() {
            MisScheme::GeneralizedPower
        } else {
            self.mis
        }
    }

    /// Whether shading takes the expectation over the last spatial round's selection: asked
    /// for ([`Self::shade_expected`]), with spatial rounds, and with an MIS whose normalisation
    /// all inputs share (not 1/Z or contribution MIS). An estimator may need more (ReSTIR DI:
    /// visibility in the target).
    pub fn shades_expected(&self) -> bool {
        self.shade_expected
            && self.spatial_rounds > 0
            && self.neighbors > 0
            && !matches!(self.mis, MisScheme::OneOverZ | MisScheme::Contribution)
    }

    /// `shade=…` in an estimator's one-line description: `expected` when
    /// [`Self::shades_expected`] and the estimator's own condition `also` hold, else `selected`
    /// (with why, when the expectation was asked for).
    pub fn describe_shading(&self, also: bool) -> String {
        if self.shades_expected() && also {
            "shade=expected".into()
        } else if self.shade_expected {
            "shade=selected (the expectation needs spatial rounds, a pairwise or balance MIS and \
             visibility in the target)"
                .into()
        } else {
            "shade=selected".into()
        }
    }

    /// `temporal=…` in an estimator's one-line description: `false`, or `true` with the
    /// temporal MIS (and the duplication strength when it is on).
    pub fn describe_temporal(&self) -> String {
        if self.temporal {
            let duplication = if self.duplication > 0.0 {
                format!(" duplication={}", self.duplication)
            } else {
                String::new()
            };
            format!(
                "temporal=true temporal_mis={}{duplication}",
                mis_name(self.temporal_mis())
            )
        } else {
            "temporal=false".into()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The halo is `rounds × ⌈radius⌉`, none without neighbours.
    #[test]
    fn reuse_halo() {
        let mut s = ReuseSettings {
            radius: 30.0,
            ..ReuseSettings::default()
        };
        assert_eq!(s.halo(), 30);
        s.radius = 2.5;
        s.spatial_rounds = 3;
        assert_eq!(s.halo(), 9);
        s.neighbors = 0;
        assert_eq!(s.halo(), 0);
    }

    /// An odd neighbour count becomes the even count reciprocal rounds use, with a note; even
    /// counts and rounds that are not reciprocal keep theirs, silently.
    #[test]
    fn odd_neighbors_are_paired_aloud() {
        let mut s = ReuseSettings {
            neighbors: 5,
            ..ReuseSettings::default()
        };
        let note = s.pair_neighbors().expect("a note");
        assert_eq!(s.neighbors, 6);
        assert!(note.contains("so 6 are used"), "{note}");
        assert_eq!(s.pair_neighbors(), None);
        let mut plain = ReuseSettings {
            neighbors: 5,
            reciprocal: false,
            ..ReuseSettings::default()
        };
        assert_eq!(plain.pair_neighbors(), None);
        assert_eq!(plain.neighbors, 5);
        let mut balance = ReuseSettings {
            neighbors: 3,
            mis: MisScheme::GeneralizedBalance,
            ..ReuseSettings::default()
        };
        assert_eq!(balance.pair_neighbors(), None);
        assert_eq!(ReuseSettings::direct().neighbors, DIRECT_NEIGHBORS);
    }
}
