//! ReSTIR PT settings and their parsing from named parameters (XML scenes and the command line
//! use the same names; the reuse settings are [`ReuseSettings`], shared with ReSTIR DI). One
//! default is a rule of the scene, decided once when the integrator is made
//! ([`RestirPtSettings::resolve`]): the path tracer in place of ReSTIR PT where the camera's
//! paths reconnect at too few glossy surfaces ([`GLOSSY_VIEW_MIN`]) and too little of the light
//! there is indirect ([`INDIRECT_VIEW_MIN`]).

use restir_scene::Scene;

pub use crate::fallback::Fallback;
use crate::params::{Param, ParamError, ParamProblem, ParamSet};
use crate::path::PathSettings;
use crate::reuse::settings::ReuseSettings;

use super::fallback::{GLOSSY_VIEW_MIN, INDIRECT_VIEW_MIN, view_pilot};
use super::sample::{Reconnection, ShiftKind};

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
    /// (default 8; 1: the G-buffer's only).
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
    /// Whether a scene without glossy or indirectly lit surfaces in view goes to the path tracer
    /// (default auto).
    pub fallback: Fallback,
    /// Whether some ReSTIR PT parameter was given ([`RestirPtSettings::apply`]): then
    /// `fallback = auto` keeps ReSTIR PT (the user asked for a configured ReSTIR PT).
    pub configured: bool,
}

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
            edge_rays: 8,
            edge_mask_from_pass: false,
            unit_jacobian: false,
            one_sided_jacobian: false,
            temporal_ignore_motion: false,
            temporal_stale_suffix: false,
            shift: ShiftKind::Hybrid,
            skip_invertibility: false,
            fallback: Fallback::Auto,
            configured: false,
        }
    }

    /// Returns why the path tracer should render `scene` instead of ReSTIR PT: when `fallback`
    /// is auto, no other ReSTIR PT parameter was given (ReSTIR PT at its defaults) and the
    /// camera's paths reach too few glossy surfaces ([`GLOSSY_VIEW_MIN`]) and the light there is
    /// too little indirect ([`INDIRECT_VIEW_MIN`]), as a pilot of 1024 camera paths sees them
    /// ([`super::fallback`]; not run otherwise).
    pub fn resolve(&self, scene: &Scene) -> Option<String> {
        if self.fallback != Fallback::Auto || self.configured {
            return None;
        }
        let view = view_pilot(scene);
        // No commas: the bench CSV's settings column is split on them.
        (!view.keeps_restir_pt()).then(|| {
            format!(
                "of {} camera paths {:.1}% first reconnect at a glossy surface (< {:.0}%) and \
                 {:.0}% of their light is indirect (< {:.0}%): the path tracer renders it \
                 (fallback = off keeps ReSTIR PT)",
                view.reached,
                100.0 * view.glossy_share(),
                100.0 * GLOSSY_VIEW_MIN,
                100.0 * view.indirect_share(),
                100.0 * INDIRECT_VIEW_MIN
            )
        })
    }

    /// Whether the estimator is unbiased with these settings.
    pub fn is_unbiased(&self) -> bool {
        self.reuse.is_unbiased()
            && !self.unit_jacobian
            && (!self.edge_mask_from_pass || self.edge_rays <= 1)
            && (!self.one_sided_jacobian || self.max_jacobian <= 0.0)
            && !self.skip_invertibility
            && (!self.reuse.temporal
                || !(self.temporal_ignore_motion || self.temporal_stale_suffix))
    }

    /// Applies `params` in order (later ones win). Names are case-insensitive, `-` and `_` are
    /// the same. Returns the parameters it did not know, for the caller to warn about.
    pub fn apply(&mut self, params: &ParamSet) -> Result<Vec<Param>, ParamError> {
        params.apply(|key, p| {
            let used = self.apply_one(key, p)?;
            // A ReSTIR PT parameter given (other than `fallback`): the user configured ReSTIR
            // PT, keep it.
            self.configured |= used && key != "fallback";
            Ok(used)
        })
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
            "fallback" => self.fallback = p.choice(Fallback::NAMES, "auto or off")?,
            _ => return self.reuse.apply(key, p),
        }
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use restir_gris::MisScheme;

    use super::*;

    #[test]
    fn names_and_errors() {
        let mut s = RestirPtSettings::new(PathSettings {
            max_depth: 4,
            rr_depth: 5,
            hide_emitters: false,
        });
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

    /// `fallback` takes auto or off and is the one parameter that does not count as
    /// configuring ReSTIR PT; every other one does, including the shared reuse parameters.
    #[test]
    fn fallback_and_configured() {
        let new = || {
            RestirPtSettings::new(PathSettings {
                max_depth: 4,
                rr_depth: 5,
                hide_emitters: false,
            })
        };
        let p = |a: &str, b: &str| ParamSet::from(&[(a, b)][..]);
        let mut s = new();
        assert_eq!((s.fallback, s.configured), (Fallback::Auto, false));
        s.apply(&p("fallback", "OFF")).unwrap();
        assert_eq!((s.fallback, s.configured), (Fallback::Off, false));
        assert_eq!(
            s.apply(&p("fallback", "never")).unwrap_err().to_string(),
            "fallback = 'never': expected auto or off"
        );
        for (name, value) in [("candidates", "2"), ("radius", "3"), ("shift", "hybrid")] {
            let mut s = new();
            s.apply(&p(name, value)).unwrap();
            assert!(s.configured, "{name}");
        }
        let mut s = new();
        let unknown = s.apply(&p("foo", "1")).unwrap();
        assert_eq!(unknown.len(), 1);
        assert!(!s.configured);
    }
}
