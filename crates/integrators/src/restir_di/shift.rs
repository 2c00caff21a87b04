//! ReSTIR DI's shift map: the identity between receivers (the light point stays where it is,
//! `J = 1`; only the target changes), also across the frames of a moving sequence, and with
//! the visibility of the sample in every target when the settings ask for it.

use glam::Vec3;
use restir_gris::{ShiftMap, Shifted};
use restir_lights::{Contact, LightPoint, Resolved};
use restir_materials::Bsdf;
use restir_scene::Scene;

use super::DiReservoir;
use super::target::{StrategyCounts, evaluate};
use crate::motion::FrameMotion;
use crate::reuse::gbuffer::{GBuffer, Receiver};
use crate::reuse::shift::ReuseShift;
use crate::shadow::{self, ShadowTarget};

/// A reservoir's sample: a point on a light, and its contribution over its target at the
/// receiver whose reservoir holds it (or into which it was shifted): `F·m_L / p̂`, RGB of
/// luminance 1, the light's colour as that receiver sees it. Shading every input of the last
/// spatial round ([`ReuseShift::ratio`]) needs it for samples whose targets only the shifts
/// evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiSample {
    /// The point on the light.
    pub point: LightPoint,
    /// `F·m_L / p̂` at the receiver (zero where the target is).
    pub ratio: Vec3,
}

impl DiSample {
    /// `point` with the ratio of its evaluation `e` at a receiver.
    #[inline]
    pub fn new(point: LightPoint, e: &super::target::Evaluated) -> Self {
        let ratio = if e.target > 0.0 {
            e.contribution / e.target
        } else {
            Vec3::ZERO
        };
        Self { point, ratio }
    }
}

/// A receiver where ReSTIR DI's shift map works: a pixel's primary hit in this pass, or in the
/// previous pass, which across frames lies in the previous frame's scene.
#[derive(Clone, Copy)]
pub(super) struct DiDomain<'a> {
    r: &'a Receiver,
    /// The receiver's geometric normal (shadow rays leave along it).
    ng: Vec3,
    /// The scene the receiver's target is evaluated in.
    scene: &'a Scene,
    /// Whether the receiver is the previous frame's (its light indices are that frame's).
    earlier: bool,
    /// The receiver's initial sample resolved in this pass's scene, if it has one.
    resolved: Option<&'a (LightPoint, Resolved)>,
    /// The receiver's BSDF, if this pass looked it up already.
    bsdf: Option<&'a Bsdf>,
}

/// The identity shift between pixels: the sample stays on the light, `J = 1`; only the target
/// changes. Across frames the sample moves with its light, which the previous frame may name
/// by another index ([`FrameMotion`]); a rigid motion keeps area, so `J = 1` still. A sample is
/// resolved in world space once: each pixel's initial sample after initial resampling
/// ([`DiReuse::resolved`]), the receiving pixel's own sample when a shift first needs it
/// (pairwise MIS evaluates it at every neighbour). With [`Visibility::Target`] a target includes the visibility of the sample
/// from the receiver it is evaluated at: one shadow ray per shift whose unshadowed target is
/// positive, in the scene of the destination domain.
pub(super) struct DiShift<'a> {
    scene: &'a Scene,
    counts: StrategyCounts,
    motion: Option<&'a FrameMotion>,
    /// The canonical sample, resolved when a shift first needs it.
    canonical: Option<LightPoint>,
    canonical_resolved: std::cell::OnceCell<Resolved>,
    visibility: bool,
    rays: std::cell::Cell<u64>,
}

impl<'a> DiShift<'a> {
    fn new(
        scene: &'a Scene,
        counts: StrategyCounts,
        motion: Option<&'a FrameMotion>,
        canonical: &DiReservoir,
        visibility: bool,
    ) -> Self {
        Self {
            scene,
            counts,
            motion,
            canonical: canonical.sample.map(|s| s.point),
            canonical_resolved: std::cell::OnceCell::new(),
            visibility,
            rays: std::cell::Cell::new(0),
        }
    }

    /// `x` resolved in this pass's scene: the canonical sample's or the source receiver's
    /// initial sample's when it is one of them (resolving is a function of the sample, so
    /// either is exactly what resolving again would give).
    #[inline(always)]
    fn resolved(&self, from: &DiDomain<'a>, x: &LightPoint) -> Resolved {
        match from.resolved {
            Some((y, r)) if y == x => *r,
            _ if self.canonical.as_ref() == Some(x) => *self
                .canonical_resolved
                .get_or_init(|| self.scene.lights.resolve(x)),
            _ => self.scene.lights.resolve(x),
        }
    }
}

impl<'a> ShiftMap<DiSample> for DiShift<'a> {
    type Domain = DiDomain<'a>;

    #[inline(always)]
    fn shift(
        &self,
        from: &DiDomain<'a>,
        to: &DiDomain<'a>,
        x: &DiSample,
    ) -> Option<Shifted<DiSample>> {
        let x = &x.point;
        let mut y = *x;
        if from.earlier != to.earlier
            && let Some(m) = self.motion
        {
            y.light = if to.earlier {
                m.light_to_prev(x.light)?
            } else {
                m.light_from_prev(x.light)?
            };
        }
        let resolved = if std::ptr::eq(to.scene, self.scene) {
            self.resolved(from, &y)
        } else {
            to.scene.lights.resolve(&y)
        };
        let Some(c) = resolved.contact(&to.scene.lights, &y, to.r.p) else {
            return Some(Shifted::identity(
                DiSample {
                    point: y,
                    ratio: Vec3::ZERO,
                },
                0.0,
            ));
        };
        let looked_up;
        let bsdf = match to.bsdf {
            Some(b) => b,
            None => {
                looked_up = to.r.resolve_bsdf(to.scene);
                &looked_up
            }
        };
        let e = evaluate(to.scene, to.r, bsdf, &y, &c, None, self.counts);
        let mut p = e.target;
        if self.visibility && p > 0.0 {
            self.rays.set(self.rays.get() + 1);
            if !shadow::visible(to.scene, to.r.p, to.ng, shadow_target(&c)) {
                p = 0.0;
            }
        }
        Some(Shifted::identity(DiSample::new(y, &e), p))
    }
}

/// ReSTIR DI's part in the reuse passes: the identity shift between receivers; a domain is a
/// pixel's receiver in this pass or the previous one (across frames, with the previous
/// frame's scene, or with this frame's for the negative control `temporal_current_scene`).
pub(super) struct DiReuse<'p> {
    pub(super) scene: &'p Scene,
    pub(super) counts: StrategyCounts,
    pub(super) gbuf: &'p GBuffer,
    pub(super) prev: Option<&'p GBuffer>,
    /// The previous pass's scene and the motion since, when it was the previous frame's.
    pub(super) motion: Option<&'p FrameMotion>,
    pub(super) prev_scene: &'p Scene,
    /// Whether targets include visibility ([`Visibility::Target`]).
    pub(super) visibility: bool,
    /// Each pixel's initial sample resolved in `scene`.
    pub(super) resolved: &'p [Option<(LightPoint, Resolved)>],
    /// Each pixel's BSDF in `scene`.
    pub(super) bsdfs: &'p [Option<Bsdf>],
}

impl<'p> ReuseShift for DiReuse<'p> {
    type Sample = DiSample;
    type Domain = DiDomain<'p>;
    type DomainRef<'d>
        = DiDomain<'p>
    where
        Self: 'd;
    type Map<'m>
        = DiShift<'p>
    where
        Self: 'm;

    #[inline]
    fn map(&self, canonical: &DiReservoir) -> DiShift<'p> {
        DiShift::new(
            self.scene,
            self.counts,
            self.motion,
            canonical,
            self.visibility,
        )
    }

    fn rays(map: &DiShift<'p>) -> u64 {
        map.rays.get()
    }

    #[inline]
    fn domain(&self, index: usize, previous: bool) -> DiDomain<'p> {
        if previous {
            let prev = self.prev.expect("temporal reuse has a previous pass");
            DiDomain {
                r: &prev.receivers[index],
                ng: prev.ng[index],
                scene: self.prev_scene,
                earlier: self.motion.is_some(),
                resolved: None,
                bsdf: None,
            }
        } else {
            DiDomain {
                r: &self.gbuf.receivers[index],
                ng: self.gbuf.ng[index],
                scene: self.scene,
                earlier: false,
                resolved: self.resolved[index].as_ref(),
                bsdf: self.bsdfs[index].as_ref(),
            }
        }
    }

    /// The identity shift keeps the light point.
    #[inline]
    fn same_sample(a: &DiSample, b: &DiSample) -> bool {
        a.point == b.point
    }

    #[inline]
    fn ratio(sample: &DiSample) -> Option<[f32; 3]> {
        Some(sample.ratio.to_array())
    }
}

/// Whether the light point `c` is visible from receiver `r` (one shadow ray).
#[inline]
pub(super) fn visible(scene: &Scene, r: &Receiver, ng: Vec3, c: &Contact) -> bool {
    shadow::visible(scene, r.p, ng, shadow_target(c))
}

/// The shadow ray's end at light point `c`.
#[inline]
pub(super) fn shadow_target(c: &Contact) -> ShadowTarget {
    ShadowTarget::of_contact(c)
}
