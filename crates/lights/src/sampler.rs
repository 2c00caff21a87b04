//! One interface over every way of choosing a receiver's light candidates: [`LightSampler`].
//!
//! A candidate is a light sample seen from a receiver ([`LightCandidate`]) with two densities:
//! the density of the sampler that drew it (which initial resampling divides by) and the power
//! sampler's density of the same point (which the light/BSDF split of a light-sampled estimate
//! weighs by, whatever drew the candidate). The samplers:
//!
//! | sampler | which light | where on it |
//! |---|---|---|
//! | [`PowerSampler`] | the emitter table by power ([`LightSet::sample`]) | a uniform point of the picked triangle, or the light's own sampling |
//! | [`HierarchySampler`] | the light hierarchy, receiver-aware ([`LightSet::sample_hierarchy`]) | the same |
//! | [`PoolSampler`] | the power sampler's draws made once for a block of pixels ([`LightSet::presample`]) | fixed with the draw (a sphere's point per receiver) |
//! | [`LearnedCellSampler`] over a tile's pool | a cut of the light hierarchy made for a screen tile's receivers ([`LightSet::light_cut`], [`LightSet::presample_cut`]) | a pool of the cut's draws per tile, made once per pass |
//! | [`LearnedCellSampler`] | the learned table of the receiver's cell over emitters (triangles, other lights, the environment) mixed with the power sampler ([`LearnedSampler`](crate::LearnedSampler)) | a pool of the mixture's draws per cell, made once per pass ([`LearnedSampler::presample`](crate::LearnedSampler::presample)) |
//!
//! Each is a small value made per receiver from tables built per pass, so the candidate loop is
//! monomorphised for each.

use glam::{Vec2, Vec3};
use restir_geometry::Sphere;
use restir_sampling::{ONE_MINUS_EPSILON, Pcg32};

use crate::light::area_light_sample;
use crate::{Contact, LearnedDraw, LightPoint, LightSample, LightSet, Presampled, Resolved};

/// A receiver as light selection sees it: its position and shading normal (zero if unknown).
#[derive(Clone, Copy, Debug)]
pub struct At {
    /// Position.
    pub p: Vec3,
    /// Shading normal, or zero.
    pub n: Vec3,
}

/// The numbers of candidate `i` of a receiver's `n`: the stratified selection number
/// `(i + u0) / n` and a point on the light.
#[derive(Clone, Copy, Debug)]
pub struct CandidateU {
    /// Index of the candidate.
    pub i: u32,
    /// Candidates of the receiver.
    pub n: u32,
    /// The receiver's stratum offset in `[0, 1)`.
    pub u0: f32,
    /// `(i + u0) / n`, below 1.
    pub select: f32,
    /// For the point on the light.
    pub point: Vec2,
}

impl CandidateU {
    /// Candidate `i` of `n` with stratum offset `u0` and point numbers `point`.
    #[inline]
    pub fn new(i: u32, n: u32, u0: f32, point: Vec2) -> Self {
        Self {
            i,
            n,
            u0,
            select: ((i as f32 + u0) / n as f32).min(ONE_MINUS_EPSILON),
            point,
        }
    }
}

/// A light sample seen from a receiver, with the densities initial resampling needs.
#[derive(Clone, Copy, Debug)]
pub struct LightCandidate {
    /// The sample's name (what a reservoir holds).
    pub point: LightPoint,
    /// The sample seen from the receiver.
    pub contact: Contact,
    /// The density that drew it, in the sample's own measure (area, counting or solid angle),
    /// the selection included.
    pub source_pdf: f32,
    /// The power sampler's solid-angle density of the same point.
    pub power_pdf_sa: f32,
}

impl LightCandidate {
    /// A light sample drawn with solid-angle density `source_pdf_sa`, whose power-sampler
    /// density is `power_pdf_sa`.
    #[inline]
    pub fn from_sample(ls: &LightSample, source_pdf_sa: f32, power_pdf_sa: f32) -> Option<Self> {
        let measure = if ls.delta || !ls.dist.is_finite() {
            1.0
        } else {
            ls.ng.dot(ls.wi).abs() / (ls.dist * ls.dist)
        };
        Some(Self {
            point: LightPoint::from_light_sample(ls),
            contact: Contact {
                wi: ls.wi,
                p: ls.p,
                dist: ls.dist,
                le: ls.le,
                measure,
                delta: ls.delta,
                ng: ls.ng,
                pdf_sa: Some(power_pdf_sa),
                light: (!ls.delta && ls.dist.is_finite()).then_some((ls.light, ls.prim)),
            },
            source_pdf: if ls.delta {
                source_pdf_sa
            } else {
                source_pdf_sa * measure
            },
            power_pdf_sa,
        })
    }

    /// A presampled draw seen from `x` (a sphere light gets its point here, with `u`).
    #[inline]
    pub fn presampled(lights: &LightSet, e: &Presampled, x: Vec3, u: Vec2) -> Option<Self> {
        let (point, resolved, pdf) = match *e {
            Presampled::Fixed {
                point,
                resolved,
                pdf,
            } => (point, resolved, pdf),
            Presampled::Light { light, pmf } => {
                let ls = lights.sample_light(light, x, u)?;
                return Self::from_sample(&ls, ls.pdf_sa * pmf, ls.pdf_sa * pmf);
            }
            Presampled::Sphere {
                light,
                pmf,
                center,
                radius,
                radiance,
                flip_normals,
            } => {
                // What `sample_light` does for the sphere, from the entry's copy of it.
                let sphere = Sphere::new(center, radius, flip_normals);
                let (ps, pdf_sa) = sphere.sample_from(x, u)?;
                let ls = area_light_sample(light, radiance, x, ps, pdf_sa)?;
                return Self::from_sample(&ls, ls.pdf_sa * pmf, ls.pdf_sa * pmf);
            }
        };
        let contact = resolved.contact(lights, &point, x)?;
        // Area lights: the area density over the measure factor is the solid-angle density.
        if contact.measure <= 0.0 {
            return None;
        }
        Some(Self {
            point,
            contact,
            source_pdf: pdf,
            power_pdf_sa: pdf / contact.measure,
        })
    }
}

/// A way of drawing a receiver's light candidates.
pub trait LightSampler {
    /// Called once per receiver before its `n` candidates, after the stratum offset is drawn
    /// from `rng`: draws what the sampler decides per receiver.
    #[inline]
    fn begin(&mut self, _rng: &mut Pcg32, _n: u32) {}

    /// Candidate `u.i` for a receiver `at`, or `None` where nothing was drawn (no light, a back
    /// face). `rng` gives any further numbers the sampler needs.
    fn candidate(
        &self,
        lights: &LightSet,
        at: At,
        u: &CandidateU,
        rng: &mut Pcg32,
    ) -> Option<LightCandidate>;
}

/// The power sampler, drawn per receiver ([`LightSet::sample`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct PowerSampler;

impl LightSampler for PowerSampler {
    #[inline]
    fn candidate(
        &self,
        lights: &LightSet,
        at: At,
        u: &CandidateU,
        _rng: &mut Pcg32,
    ) -> Option<LightCandidate> {
        let ls = lights.sample(at.p, u.select, u.point)?;
        LightCandidate::from_sample(&ls, ls.pdf_sa, ls.pdf_sa)
    }
}

/// The light hierarchy ([`LightSet::sample_hierarchy`]): 48 bits for the descent, the
/// stratified number and 24 more from the generator.
#[derive(Clone, Copy, Debug, Default)]
pub struct HierarchySampler {
    /// Claim the power sampler's density instead of the hierarchy's (a negative control of the
    /// tests: biased).
    #[doc(hidden)]
    pub claim_power_density: bool,
}

impl LightSampler for HierarchySampler {
    #[inline]
    fn candidate(
        &self,
        lights: &LightSet,
        at: At,
        u: &CandidateU,
        rng: &mut Pcg32,
    ) -> Option<LightCandidate> {
        let v = (u.i as f64 + u.u0 as f64 + rng.next_f32() as f64 / 16_777_216.0) / u.n as f64;
        let (ls, power_pdf_sa) =
            lights.sample_hierarchy(at.p, at.n, v.min(1.0 - f64::EPSILON), u.point)?;
        let source = if self.claim_power_density {
            power_pdf_sa
        } else {
            ls.pdf_sa
        };
        LightCandidate::from_sample(&ls, source, power_pdf_sa)
    }
}

/// A tile of presampled power-sampler draws shared by a block of pixels: a receiver takes the
/// entries `start + i·S/n` (mod `S`) for a uniform `start`, one from each of `n` strata of the
/// tile's selection numbers.
#[derive(Clone, Copy, Debug)]
pub struct PoolSampler<'a> {
    tile: &'a [Option<Presampled>],
    start: usize,
    stride: usize,
    drop_selection: bool,
}

impl<'a> PoolSampler<'a> {
    /// The sampler over `tile` (not empty).
    pub fn new(tile: &'a [Option<Presampled>]) -> Self {
        Self {
            tile,
            start: 0,
            stride: 1,
            drop_selection: false,
        }
    }

    /// The pool that forgets a whole light's selection probability in its density (a negative
    /// control of the tests: biased).
    #[doc(hidden)]
    pub fn without_selection(tile: &'a [Option<Presampled>]) -> Self {
        Self {
            drop_selection: true,
            ..Self::new(tile)
        }
    }

    /// The entry candidate `i` takes.
    #[inline]
    fn entry(&self, i: u32) -> Option<Presampled> {
        self.tile[(self.start + i as usize * self.stride) % self.tile.len()]
    }
}

impl LightSampler for PoolSampler<'_> {
    #[inline]
    fn begin(&mut self, rng: &mut Pcg32, n: u32) {
        self.start = rng.next_u32() as usize % self.tile.len();
        self.stride = (self.tile.len() / n as usize).max(1);
    }

    #[inline]
    fn candidate(
        &self,
        lights: &LightSet,
        at: At,
        u: &CandidateU,
        _rng: &mut Pcg32,
    ) -> Option<LightCandidate> {
        let mut e = self.entry(u.i)?;
        if self.drop_selection {
            e = without_selection(lights, e);
        }
        LightCandidate::presampled(lights, &e, at.p, u.point)
    }
}

/// `e` with the selection probability of a whole light (sphere, point light, environment or
/// directional light) left out of its density, as a pool that forgot it would weigh it.
fn without_selection(lights: &LightSet, e: Presampled) -> Presampled {
    match e {
        Presampled::Light { light, .. } => Presampled::Light { light, pmf: 1.0 },
        Presampled::Sphere {
            light,
            center,
            radius,
            radiance,
            flip_normals,
            ..
        } => Presampled::Sphere {
            light,
            pmf: 1.0,
            center,
            radius,
            radiance,
            flip_normals,
        },
        Presampled::Fixed {
            point,
            resolved: resolved @ Resolved::Point { .. },
            ..
        } => Presampled::Fixed {
            point,
            resolved,
            pdf: 1.0,
        },
        Presampled::Fixed {
            point,
            resolved: Resolved::Direction { wi, le, delta, pdf },
            ..
        } => {
            let pdf = pdf / lights.pmf(point.light).max(f32::MIN_POSITIVE);
            Presampled::Fixed {
                point,
                resolved: Resolved::Direction { wi, le, delta, pdf },
                pdf,
            }
        }
        surface @ Presampled::Fixed { .. } => surface,
    }
}

/// The learned selection at a receiver's cell ([`LearnedSampler`](crate::LearnedSampler)),
/// from the cell's pool of presampled draws of the mixture
/// ([`LearnedSampler::presample`](crate::LearnedSampler::presample)), taken as [`PoolSampler`]
/// takes a tile's: from a uniform start, one entry from each of `n` strata of the pool. Each
/// entry is an independent draw of the mixture whose density is the power sampler's times the
/// entry's probability ratio, so whichever entries a receiver takes, each candidate is
/// distributed as the mixture with exactly the density it carries. A screen tile's pool of
/// draws from its cut of the light hierarchy ([`LightSet::presample_cut`]) is taken the same
/// way.
#[derive(Clone, Copy, Debug)]
pub struct LearnedCellSampler<'a> {
    pool: &'a [Option<LearnedDraw>],
    start: usize,
    stride: usize,
}

impl<'a> LearnedCellSampler<'a> {
    /// The sampler over a cell's `pool` (not empty).
    pub fn new(pool: &'a [Option<LearnedDraw>]) -> Self {
        Self {
            pool,
            start: 0,
            stride: 1,
        }
    }
}

impl LightSampler for LearnedCellSampler<'_> {
    #[inline]
    fn begin(&mut self, rng: &mut Pcg32, n: u32) {
        self.start = rng.next_u32() as usize % self.pool.len();
        self.stride = (self.pool.len() / n as usize).max(1);
    }

    #[inline]
    fn candidate(
        &self,
        lights: &LightSet,
        at: At,
        u: &CandidateU,
        _rng: &mut Pcg32,
    ) -> Option<LightCandidate> {
        let (e, ratio) = self.pool[(self.start + u.i as usize * self.stride) % self.pool.len()]?;
        let mut c = LightCandidate::presampled(lights, &e, at.p, u.point)?;
        c.source_pdf *= ratio;
        Some(c)
    }
}
