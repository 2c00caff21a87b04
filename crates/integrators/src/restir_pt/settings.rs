//! ReSTIR PT settings and their parsing from named parameters (XML scenes and the command line
//! use the same names; the reuse settings are [`ReuseSettings`], shared with ReSTIR DI).

use crate::params::{Param, ParamError, ParamProblem, ParamSet};
use crate::path::PathSettings;
use crate::reuse::params::{LARGE_FILM_PIXELS, RADIUS_NAMES, ReuseParams, large_film_label};
use crate::reuse::settings::ReuseSettings;

use super::sample::{Reconnection, ShiftKind};
use restir_scene::SceneFeatures;

/// The shifts `--shift` accepts.
pub const SHIFT_NAMES: &[&str] = &["reconnection", "replay", "hybrid"];

/// Every name `--shift` accepts, with the shift it names.
const SHIFT_CHOICES: &[(&str, ShiftKind)] = &[
    ("reconnection", ShiftKind::Reconnection),
    ("reconnect", ShiftKind::Reconnection),
    ("replay", ShiftKind::Replay),
    ("random-replay", ShiftKind::Replay),
    ("hybrid", ShiftKind::Hybrid),
];

/// Every name `--reconnection` accepts.
const RECONNECTION_CHOICES: &[(&str, Reconnection)] = &[
    ("fixed", Reconnection::Fixed),
    ("footprint", Reconnection::Footprint),
];

/// Where the direct light at the primary hit comes from (`--direct`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectLight {
    /// Carried in the reservoirs like every other path (default).
    Reservoir,
    /// Path-traced per pixel (light sampling and BSDF sampling with the power heuristic)
    /// instead of carried in the reservoirs.
    Path,
    /// A ReSTIR DI pass with the same reuse settings takes the direct light at the primary hit
    /// (and the emitters the camera sees); the reservoirs carry the paths of three or more
    /// segments.
    RestirDi,
}

impl DirectLight {
    /// Every name `--direct` accepts.
    const CHOICES: &[(&str, DirectLight)] = &[
        ("reservoir", DirectLight::Reservoir),
        ("reservoirs", DirectLight::Reservoir),
        ("path", DirectLight::Path),
        ("restir-di", DirectLight::RestirDi),
        ("restirdi", DirectLight::RestirDi),
        ("di", DirectLight::RestirDi),
    ];

    /// The name `--direct` takes.
    pub fn name(self) -> &'static str {
        match self {
            DirectLight::Reservoir => "reservoir",
            DirectLight::Path => "path",
            DirectLight::RestirDi => "restir-di",
        }
    }
}

/// Everything ReSTIR PT can be told.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestirPtSettings {
    /// Path settings: depth semantics, Russian roulette, hidden emitters.
    pub path: PathSettings,
    /// Spatial and temporal reuse.
    pub reuse: ReuseSettings,
    /// Candidate paths per pixel in initial sampling (default 2).
    pub candidates: u32,
    /// Shortest reconnection segment, as a fraction of the scene's bounding-sphere radius
    /// (default 0.01).
    pub near_distance: f32,
    /// The rule for the reconnection segment (default fixed thresholds).
    pub reconnection: Reconnection,
    /// The footprint rule's `T`: the lobe's footprint at `x_k` must be at least `T` times the
    /// squared ray-cone width at `x_{k−1}` (default 30).
    pub footprint: f32,
    /// Reject shifts whose Jacobian `J` has `max(J, 1/J)` above this (symmetric, so unbiased);
    /// 0 (default) rejects none.
    pub max_jacobian: f32,
    /// Where the direct light at the primary hit comes from (default the reservoirs).
    pub direct: DirectLight,
    /// Camera rays for the emission seen on emitter silhouettes, the G-buffer's included
    /// (default 32: docs/RESTIR_PT.md, "Silhouettes"; 1 traces no more).
    pub edge_rays: u32,
    /// Negative control only: choose the pixels that get `edge_rays` by what the pass's own
    /// camera ray saw (an emitter) instead of a mask made without the pass's samples (biased).
    pub edge_mask_from_pass: bool,
    /// Negative control only: use Jacobian 1 in every shift (biased).
    pub unit_jacobian: bool,
    /// Negative control only: with `max_jacobian`, reject only `J > τ`, not `1/J > τ` (a
    /// rejection that is not symmetric; biased).
    pub one_sided_jacobian: bool,
    /// Negative control only: across frames in which shapes or lights moved, shift paths as if
    /// only the camera had moved (vertices, light indices and cached suffixes of the previous
    /// frame taken for the current one's; biased).
    pub temporal_ignore_motion: bool,
    /// Negative control only: across frames in which shapes or lights moved, keep the suffix a
    /// path cached in its own frame (the radiance beyond its reconnection vertex, its
    /// direction and light density) instead of evaluating it in the other frame (biased).
    pub temporal_stale_suffix: bool,
    /// The shift between pixels (default hybrid; plain reconnection in scenes without
    /// near-specular materials).
    pub shift: ShiftKind,
    /// Negative control only: skip the hybrid shift's invertibility checks (biased).
    pub skip_invertibility: bool,
    /// Negative control only: the walks keep the emission seen through delta lobes that the
    /// silhouette stage adds too (counted twice; biased).
    pub delta_emission_twice: bool,
    /// The radius was named (`radius`, `max_radius`, `spatial_radius`), so
    /// [`RestirPtSettings::resolve`] keeps it.
    pub radius_named: bool,
    /// [`RestirPtSettings::resolve`] widened the radius to [`LARGE_FILM_RADIUS`] for a large
    /// film (the settings line says why).
    pub radius_widened: bool,
}

/// ReSTIR PT's spatial radius in pixels on a film of at least
/// [`LARGE_FILM_PIXELS`] pixels (1280×720), where the radius was not named
/// (else 3). Chosen on the PT training family at 1280×720 (4 passes, seeds 11 and 12, 1 thread,
/// `scripts/pair_variance.py`): **1.24×** radius 3's efficiency at the median (1.13–1.35, every
/// member gaining; MSE 1.19×, 1.03–1.24), where 8 neighbours in place of 4 were 1.18× (MSE
/// 1.08×, 0.89–1.25); reported on the test family at 1280×720: 1.19× (1.10–1.42, MSE 1.11×).
/// At 640×360, where the defaults were chosen, radius 5 gains little (`docs/RESTIR_PT.md`, "A
/// wider radius on large films").
pub const LARGE_FILM_RADIUS: f32 = 5.0;

impl RestirPtSettings {
    /// The defaults: two candidate paths, three spatial rounds of four neighbours within 3
    /// pixels in two reciprocal pairs, defensive pairwise MIS. Chosen on the training family
    /// of `restir generate family --kind pt` (`docs/studies/2026-12-02-restir-pt-defaults.md`).
    pub fn new(path: PathSettings) -> Self {
        Self {
            path,
            reuse: ReuseSettings {
                spatial_rounds: 3,
                ..ReuseSettings::default()
            },
            candidates: 2,
            near_distance: 0.01,
            reconnection: Reconnection::Fixed,
            footprint: 30.0,
            max_jacobian: 0.0,
            direct: DirectLight::Reservoir,
            edge_rays: 32,
            edge_mask_from_pass: false,
            unit_jacobian: false,
            one_sided_jacobian: false,
            temporal_ignore_motion: false,
            temporal_stale_suffix: false,
            shift: ShiftKind::Hybrid,
            skip_invertibility: false,
            delta_emission_twice: false,
            radius_named: false,
            radius_widened: false,
        }
    }

    /// Decides the scene-dependent defaults: next-event estimation's light selection
    /// ([`PathSettings::resolve_nee`]) and, on a film of `pixels` ≥
    /// [`LARGE_FILM_PIXELS`] (the camera's whole film, so that the parts of a
    /// split render agree), a radius that was not named becomes [`LARGE_FILM_RADIUS`].
    pub fn resolve(&mut self, features: &SceneFeatures, pixels: u64) {
        self.path.resolve_nee(features);
        if !self.radius_named && pixels >= LARGE_FILM_PIXELS {
            self.reuse.radius = LARGE_FILM_RADIUS;
            self.radius_widened = true;
        }
    }

    /// `radius=R`, with why when [`RestirPtSettings::resolve`] widened it, for the settings
    /// line.
    pub fn radius_label(&self) -> String {
        large_film_label("radius", self.reuse.radius, self.radius_widened)
    }

    /// Whether the estimator is unbiased with these settings.
    pub fn is_unbiased(&self) -> bool {
        self.reuse.is_unbiased()
            && !self.unit_jacobian
            && (!self.edge_mask_from_pass || self.edge_rays <= 1)
            && (!self.one_sided_jacobian || self.max_jacobian <= 0.0)
            && !self.skip_invertibility
            && !self.delta_emission_twice
            && (!self.reuse.temporal
                || !(self.temporal_ignore_motion || self.temporal_stale_suffix))
    }

    /// Applies `params` in order (later ones win). Names are case-insensitive, `-` and `_` are
    /// the same. Returns the parameters it did not know, for the caller to warn about.
    pub fn apply(&mut self, params: &ParamSet) -> Result<Vec<Param>, ParamError> {
        params.apply(|key, p| self.apply_one(key, p))
    }

    /// One parameter; whether it is one of ReSTIR PT's.
    fn apply_one(&mut self, key: &str, p: &Param) -> Result<bool, ParamError> {
        match key {
            "candidates" | "path_candidates" | "initial_candidates" | "num_candidates" => {
                self.candidates = p.count(1)?;
            }
            "shift" | "shift_mapping" => {
                self.shift =
                    p.choice(SHIFT_CHOICES, &format!("one of {}", SHIFT_NAMES.join(", ")))?;
            }
            "near_distance" | "distance_threshold" => self.near_distance = p.positive()?,
            "reconnection" | "reconnection_rule" => {
                self.reconnection = p.choice(RECONNECTION_CHOICES, "fixed or footprint")?;
            }
            "footprint" | "footprint_threshold" => self.footprint = p.positive()?,
            "max_jacobian" | "jacobian_threshold" => {
                let j = p.positive()?;
                if j <= 1.0 {
                    return Err(p.error(ParamProblem::NotAboveOne));
                }
                self.max_jacobian = j;
            }
            "direct" => {
                self.direct = p.choice(DirectLight::CHOICES, "reservoir, path or restir-di")?;
            }
            "edge_rays" | "silhouette_rays" => self.edge_rays = p.count(1)?,
            "edge_mask_from_pass" => self.edge_mask_from_pass = p.boolean()?,
            "unit_jacobian" => self.unit_jacobian = p.boolean()?,
            "one_sided_jacobian" => self.one_sided_jacobian = p.boolean()?,
            "temporal_ignore_motion" => self.temporal_ignore_motion = p.boolean()?,
            "temporal_stale_suffix" => self.temporal_stale_suffix = p.boolean()?,
            "skip_invertibility" => self.skip_invertibility = p.boolean()?,
            "delta_emission_twice" => self.delta_emission_twice = p.boolean()?,
            _ if self.path.apply_one(key, p)? => {}
            k if RADIUS_NAMES.contains(&k) => {
                self.radius_named = true;
                return self.reuse.apply(key, p);
            }
            _ => return self.reuse.apply(key, p),
        }
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use restir_gris::MisScheme;

    use super::*;

    /// Paths of depth 4 with the power sampler, named.
    fn path() -> PathSettings {
        PathSettings {
            max_depth: 4,
            rr_depth: 5,
            hide_emitters: false,
            sampler: restir_scene::SamplerKind::Independent,
            nee: restir_lights::NeeSelection::Power,
            nee_rule: crate::path::NeeRule::Named,
        }
    }

    #[test]
    fn names_and_errors() {
        let mut s = RestirPtSettings::new(path());
        let p = |a: &str, b: &str| ParamSet::from(&[(a, b)][..]);
        let unknown = s
            .apply(&ParamSet::from(
                &[
                    ("neighbour_select", "5"),
                    ("spatial-rounds", "2"),
                    ("candidates", "4"),
                    ("mis", "balance"),
                    ("shift", "reconnection"),
                    ("foo", "1"),
                ][..],
            ))
            .unwrap();
        let names: Vec<&str> = unknown.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["foo"]);
        assert_eq!(
            (s.reuse.neighbors, s.reuse.spatial_rounds, s.candidates),
            (5, 2, 4)
        );
        assert_eq!(s.reuse.mis, MisScheme::GeneralizedBalance);
        s.apply(&p("shift", "replay")).unwrap();
        assert_eq!(s.shift, ShiftKind::Replay);
        s.apply(&p("shift", "Random_Replay")).unwrap();
        assert_eq!(s.shift, ShiftKind::Replay);
        assert!(
            s.apply(&p("shift", "manifold"))
                .unwrap_err()
                .to_string()
                .contains("reconnection, replay, hybrid")
        );
        assert!(s.apply(&p("candidates", "0")).is_err());
        s.apply(&p("direct", "restir_di")).unwrap();
        assert_eq!(s.direct, DirectLight::RestirDi);
        assert_eq!(s.reconnection, Reconnection::Fixed);
        s.apply(&p("reconnection", "Footprint")).unwrap();
        s.apply(&p("footprint", "3")).unwrap();
        assert_eq!(
            (s.reconnection, s.footprint),
            (Reconnection::Footprint, 3.0)
        );
        assert!(
            s.apply(&p("reconnection", "roughness"))
                .unwrap_err()
                .to_string()
                .contains("fixed or footprint")
        );
        assert!(s.apply(&p("footprint", "-1")).is_err());
        assert!(s.is_unbiased());
        s.apply(&p("one_sided_jacobian", "true")).unwrap();
        assert!(s.is_unbiased(), "no rejection: nothing one-sided");
        s.apply(&p("max_jacobian", "2")).unwrap();
        assert!(!s.is_unbiased());
    }

    /// A radius that was not named widens to [`LARGE_FILM_RADIUS`] on a film of at least
    /// 1280×720 pixels (the settings line says why), not one pixel below; a named one stays,
    /// under each of its names.
    #[test]
    fn auto_radius_follows_the_film_size() {
        let path = path();
        let features = SceneFeatures::default();
        let radius = |params: &[(&str, &str)], pixels: u64| {
            let mut s = RestirPtSettings::new(path);
            s.apply(&ParamSet::from(params)).unwrap();
            s.resolve(&features, pixels);
            (s.reuse.radius, s.radius_label())
        };
        let auto = "radius=5 (auto: a film of at least 1280×720 pixels)".to_string();
        assert_eq!(radius(&[], 1280 * 720), (LARGE_FILM_RADIUS, auto.clone()));
        assert_eq!(radius(&[], 1800 * 1080), (LARGE_FILM_RADIUS, auto));
        assert_eq!(radius(&[], 1280 * 720 - 1), (3.0, "radius=3".into()));
        assert_eq!(radius(&[], 640 * 360), (3.0, "radius=3".into()));
        for name in RADIUS_NAMES {
            assert_eq!(
                radius(&[(name, "3")], 1800 * 1080),
                (3.0, "radius=3".into())
            );
        }
    }
}
