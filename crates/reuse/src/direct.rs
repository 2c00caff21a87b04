//! ReSTIR DI for a host renderer that brings its own lights (Bitterli et al. 2020, with the
//! unbiased reuse of Lin et al. 2022): implement [`DirectLighting`] (draw a light sample for a
//! pixel's surface, evaluate the target and the contribution, test visibility) and
//! [`Surfaces`] for the G-buffer, and [`RestirDi::pass`] runs initial resampling, the temporal
//! and spatial rounds of [`crate::passes`] and shading, returning each pixel's direct light.
//!
//! The shift between pixels is the identity: a light sample (a point on a light, or a
//! direction for a distant light) names where the light comes from without its receiver, so it
//! means the same at every pixel and the Jacobian is 1; only the target changes
//! (the map of the private `DirectShift`). Hosts whose samples need a real shift (paths, or light samples stored in
//! a receiver's solid angle) implement [`ReuseShift`] themselves and run
//! [`ScreenReuse`] directly, as this project's renderer does.
//!
//! # Contract
//!
//! * [`DirectLighting::sample_light`] returns a sample with its density in the **same measure**
//!   as the target (area on the light, for instance, with the target holding the geometry term
//!   `|cos θ_l| / d²`; or solid angle with the target without it). A density that does not match
//!   the sampler makes every estimate wrong; nothing here can notice.
//! * Wherever the contribution is not zero, the target is positive, and the sampler can draw the
//!   sample: the estimator is unbiased over that support only.
//! * The target is a function of the surface and the sample alone (deterministic, no random
//!   numbers), the same whichever pixel asks (the reuse evaluates a pixel's target at its
//!   neighbours' samples).
//! * Every method may be called from several threads at once.

use std::cell::Cell;
use std::sync::Arc;

use restir_gris::{Reservoir, ShiftMap, Shifted, StreamingReservoir};
use restir_sampling::Pcg32;

use crate::bands::Bands;
use crate::driver::{ReuseReport, ScreenReuse, Stages};
use crate::settings::ReuseSettings;
use crate::shift::ReuseShift;
use crate::surfaces::{Streams, Surfaces};

/// A host renderer's direct lighting, as ReSTIR DI asks for it. Every method gets the pass's
/// surfaces and a pixel index: the pixel's surface in this pass, or, in temporal reuse, in the
/// previous pass (its surfaces kept by the history).
pub trait DirectLighting: Sync {
    /// A light sample as a reservoir holds it, without its receiver (a point on a light).
    type Sample: Copy + Send + Sync + PartialEq;
    /// The host's G-buffer.
    type Surfaces: Surfaces;

    /// Draws a light sample for the surface of pixel `index` from `rng`, with its density in the
    /// target's measure; `None` when nothing was drawn (the candidate counts, with weight 0).
    fn sample_light(
        &self,
        surfaces: &Self::Surfaces,
        index: usize,
        rng: &mut Pcg32,
    ) -> Option<(Self::Sample, f32)>;

    /// The target `p̂ ≥ 0` at the surface of pixel `index` for `sample`, without visibility: a
    /// scalar of the contribution (its luminance, say).
    fn target(&self, surfaces: &Self::Surfaces, index: usize, sample: &Self::Sample) -> f32;

    /// What `sample` brings to the surface of pixel `index` (RGB, the target's measure), without
    /// visibility.
    fn contribution(
        &self,
        surfaces: &Self::Surfaces,
        index: usize,
        sample: &Self::Sample,
    ) -> [f32; 3];

    /// Whether `sample` is visible from the surface of pixel `index` (a shadow ray).
    fn visible(&self, surfaces: &Self::Surfaces, index: usize, sample: &Self::Sample) -> bool;

    /// [`target`](Self::target) and [`contribution`](Self::contribution) together, which the
    /// shifts need when shading takes every input of the last round
    /// ([`ReuseSettings::shade_expected`] with [`Visibility::Target`]). Override it when the
    /// two share work (a target that is the contribution's luminance, say).
    fn target_and_contribution(
        &self,
        surfaces: &Self::Surfaces,
        index: usize,
        sample: &Self::Sample,
    ) -> (f32, [f32; 3]) {
        (
            self.target(surfaces, index, sample),
            self.contribution(surfaces, index, sample),
        )
    }
}

/// A host's light sample as the reservoirs hold it: with its contribution over its target at
/// the pixel whose reservoir holds it (or into which it was shifted), when shading takes every
/// input of the last round.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Carried<S> {
    sample: S,
    ratio: Option<[f32; 3]>,
}

/// `contribution / target`, zero where the target is.
fn ratio(target: f32, contribution: [f32; 3]) -> [f32; 3] {
    if target > 0.0 && target.is_finite() {
        contribution.map(|c| c / target)
    } else {
        [0.0; 3]
    }
}

/// Where visibility enters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visibility {
    /// Only at shading: targets are unshadowed, one shadow ray per pixel.
    Shading,
    /// In every target: the initial sample is dropped when occluded, every shift traces a shadow
    /// ray, shading needs none (lower noise near shadows, more rays).
    Target,
}

/// ReSTIR DI's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectSettings {
    /// Light candidates per pixel in initial resampling, `M` (default 8).
    pub candidates: u32,
    /// The temporal and spatial reuse (default [`ReuseSettings::direct`]).
    pub reuse: ReuseSettings,
    /// Where visibility enters (default [`Visibility::Target`]).
    pub visibility: Visibility,
}

impl Default for DirectSettings {
    fn default() -> Self {
        Self {
            candidates: 8,
            reuse: ReuseSettings::direct(),
            visibility: Visibility::Target,
        }
    }
}

/// The random-stream stages a pass draws from ([`Streams::pixel`]).
const STAGE_INITIAL: u64 = 1;
const STAGES: Stages = Stages {
    temporal: 2,
    spatial: 16,
};

/// A pixel's surface in this pass or in the previous one: where the identity shift works.
#[derive(Debug)]
pub struct Pixel<'a, G> {
    /// The pass's surfaces.
    pub surfaces: &'a G,
    /// The pixel.
    pub index: usize,
}

impl<G> Clone for Pixel<'_, G> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<G> Copy for Pixel<'_, G> {}

/// The identity shift of light samples between pixels: `J = 1`, the destination's target (with
/// visibility, when the settings put it in the target).
struct DirectShift<'a, H> {
    host: &'a H,
    visibility: bool,
    /// Whether shifted samples carry their ratio at the destination.
    carry: bool,
    rays: Cell<u64>,
}

impl<'a, H: DirectLighting> ShiftMap<Carried<H::Sample>> for DirectShift<'a, H> {
    type Domain = Pixel<'a, H::Surfaces>;

    #[inline]
    fn shift(
        &self,
        _from: &Self::Domain,
        to: &Self::Domain,
        x: &Carried<H::Sample>,
    ) -> Option<Shifted<Carried<H::Sample>>> {
        let x = &x.sample;
        let (mut p, ratio) = if self.carry {
            let (p, f) = self.host.target_and_contribution(to.surfaces, to.index, x);
            (p, Some(ratio(p, f)))
        } else {
            (self.host.target(to.surfaces, to.index, x), None)
        };
        if self.visibility && p > 0.0 {
            self.rays.set(self.rays.get() + 1);
            if !self.host.visible(to.surfaces, to.index, x) {
                p = 0.0;
            }
        }
        let sample = Carried { sample: *x, ratio };
        Some(Shifted::identity(sample, p))
    }
}

/// ReSTIR DI's part in the reuse passes over a host's direct lighting.
struct DirectReuse<'a, H: DirectLighting> {
    host: &'a H,
    current: &'a H::Surfaces,
    previous: Option<&'a H::Surfaces>,
    visibility: bool,
    carry: bool,
}

impl<'a, H: DirectLighting> ReuseShift for DirectReuse<'a, H> {
    type Sample = Carried<H::Sample>;
    type Domain = Pixel<'a, H::Surfaces>;
    type DomainRef<'d>
        = Pixel<'a, H::Surfaces>
    where
        Self: 'd;
    type Map<'m>
        = DirectShift<'a, H>
    where
        Self: 'm;

    #[inline]
    fn map(&self, _canonical: &Reservoir<Carried<H::Sample>>) -> DirectShift<'a, H> {
        DirectShift {
            host: self.host,
            visibility: self.visibility,
            carry: self.carry,
            rays: Cell::new(0),
        }
    }

    fn rays(map: &DirectShift<'a, H>) -> u64 {
        map.rays.get()
    }

    #[inline]
    fn domain(&self, index: usize, previous: bool) -> Pixel<'a, H::Surfaces> {
        let surfaces = match (previous, self.previous) {
            (true, Some(p)) => p,
            _ => self.current,
        };
        Pixel { surfaces, index }
    }

    #[inline]
    fn same_sample(a: &Carried<H::Sample>, b: &Carried<H::Sample>) -> bool {
        a.sample == b.sample
    }

    #[inline]
    fn ratio(sample: &Carried<H::Sample>) -> Option<[f32; 3]> {
        sample.ratio
    }
}

/// One pass's result.
#[derive(Clone, Debug, PartialEq)]
pub struct DirectPass {
    /// Each pixel's direct light (RGB; zero where there is no surface).
    pub radiance: Vec<[f32; 3]>,
    /// Shadow rays traced.
    pub rays: u64,
    /// What the reuse did.
    pub reuse: ReuseReport,
}

/// ReSTIR DI over a host's [`DirectLighting`]: the state it keeps between passes (the history
/// for temporal reuse) and the pass itself.
pub struct RestirDi<H: DirectLighting> {
    settings: DirectSettings,
    reuse: ScreenReuse<Carried<H::Sample>, H::Surfaces>,
}

impl<H: DirectLighting> std::fmt::Debug for RestirDi<H> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RestirDi")
            .field("settings", &self.settings)
            .field("reuse", &self.reuse)
            .finish()
    }
}

impl<H: DirectLighting> RestirDi<H> {
    /// ReSTIR DI with `settings`.
    pub fn new(settings: DirectSettings) -> Self {
        Self {
            settings,
            reuse: ScreenReuse::default(),
        }
    }

    /// The settings.
    pub fn settings(&self) -> &DirectSettings {
        &self.settings
    }

    /// One pass over `surfaces` (this pass's G-buffer, kept afterwards as the history when
    /// temporal reuse is on), with random numbers from `streams` (new streams each pass).
    pub fn pass(&self, host: &H, surfaces: H::Surfaces, streams: &impl Streams) -> DirectPass {
        let s = &self.settings;
        let n = surfaces.width() * surfaces.height();
        let bands = Bands::new(surfaces.width());
        let visibility = s.visibility == Visibility::Target;
        // Shading every input of the last round needs each one's contribution over its
        // target, with visibility in both.
        let carry = visibility && s.reuse.shade_expected;
        let mut current = vec![Reservoir::empty(); n];
        let mut rays = bands.run(&mut current[..], |first, out| {
            let mut rays = 0;
            for (i, res) in out.iter_mut().enumerate() {
                let index = first + i;
                if surfaces.has_surface(index) {
                    let mut rng = streams.pixel(index, STAGE_INITIAL);
                    let (r, nr) = initial(host, &surfaces, index, s, &mut rng);
                    *res = Reservoir {
                        sample: r.sample.map(|x| Carried {
                            sample: x,
                            ratio: carry.then(|| {
                                ratio(r.own_target, host.contribution(&surfaces, index, &x))
                            }),
                        }),
                        ucw: r.ucw,
                        confidence: r.confidence,
                        own_target: r.own_target,
                    };
                    rays += nr;
                }
            }
            rays
        });
        let history = self.reuse.take_history(&s.reuse, n);
        let shift = DirectReuse {
            host,
            current: &surfaces,
            previous: history.as_ref().map(|h| &h.surfaces),
            visibility,
            carry,
        };
        let mut expected = Vec::new();
        let report = self.reuse.reuse_expected(
            &shift,
            &s.reuse,
            streams,
            &surfaces,
            history.as_ref(),
            STAGES,
            &mut current,
            carry.then_some(&mut expected),
        );
        rays += report.rays();
        let mut radiance = vec![[0.0; 3]; n];
        rays += bands.run(&mut radiance[..], |first, out| {
            let mut rays = 0;
            for (i, l) in out.iter_mut().enumerate() {
                let index = first + i;
                if let Some(e) = expected.get(index).copied().flatten() {
                    *l = e;
                    continue;
                }
                let res = &current[index];
                let Some(Carried { sample: x, .. }) = &res.sample else {
                    continue;
                };
                if !visibility {
                    rays += 1;
                    if !host.visible(&surfaces, index, x) {
                        continue;
                    }
                }
                let f = host.contribution(&surfaces, index, x);
                *l = f.map(|c| c * res.ucw);
            }
            rays
        });
        self.reuse.keep(&s.reuse, surfaces, current);
        DirectPass {
            radiance,
            rays,
            reuse: report,
        }
    }

    /// The passes that follow render the next frame, which moved from this one as `motion`
    /// says (`None`: the history is dropped).
    pub fn next_frame(&self, motion: Option<Arc<<H::Surfaces as Surfaces>::Motion>>) {
        self.reuse.next_frame(motion);
    }
}

/// Initial resampling at pixel `index`: `M` candidates streamed with weights `p̂/(M·p)`, the
/// result of confidence 1; with visibility in the target, an occluded selection is dropped.
/// Returns the reservoir and the rays traced.
pub fn initial<H: DirectLighting>(
    host: &H,
    surfaces: &H::Surfaces,
    index: usize,
    settings: &DirectSettings,
    rng: &mut Pcg32,
) -> (Reservoir<H::Sample>, u64) {
    let m = settings.candidates.max(1);
    let mut stream = StreamingReservoir::new();
    for _ in 0..m {
        let drawn = host.sample_light(surfaces, index, rng);
        let u = rng.next_f32();
        let Some((x, pdf)) = drawn.filter(|(_, pdf)| *pdf > 0.0 && pdf.is_finite()) else {
            continue;
        };
        let target = host.target(surfaces, index, &x);
        stream.add_candidate(x, target, target / (m as f32 * pdf), 0.0, u);
    }
    let mut res = stream.finalize_recorded();
    res.confidence = 1.0;
    let mut rays = 0;
    if settings.visibility == Visibility::Target
        && let Some(x) = &res.sample
    {
        rays += 1;
        if !host.visible(surfaces, index, x) {
            res = Reservoir {
                confidence: 1.0,
                ..Reservoir::empty()
            };
        }
    }
    (res, rays)
}
