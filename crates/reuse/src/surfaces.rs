//! What the reuse passes ask of the host renderer about its image: the surface each pixel sees
//! ([`Surfaces`]: whether there is one, whether two are similar enough to share samples, which
//! pixel of the previous pass saw the same point) and its random streams ([`Streams`]).

use glam::Vec3;
use restir_sampling::Pcg32;

/// The thresholds of the similarity test that picks reuse neighbours: the shading normals within
/// an angle, the camera distances within a relative tolerance. These tests only choose which
/// pixels take part; the estimators stay unbiased whatever they decide.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Similarity {
    /// Cosine of the largest angle between shading normals.
    pub normal_cos: f32,
    /// Largest relative difference of camera distances.
    pub depth_tolerance: f32,
}

/// One pass's primary surfaces, one per pixel, row-major, as the host renderer keeps them (its
/// G-buffer). The passes read it from several threads at once.
///
/// Contract: [`Surfaces::similar`] is symmetric (reciprocal spatial pairs rely on it) and, like
/// [`Surfaces::previous_pixel`], depends only on the surfaces, never on reservoirs: neighbour
/// choices that look at samples bias the reuse.
pub trait Surfaces: Sync {
    /// How the scene moved between the previous pass and this one, when they are frames of a
    /// sequence (`()` for a host without motion).
    type Motion: Send + Sync;

    /// Width in pixels.
    fn width(&self) -> usize;
    /// Height in pixels.
    fn height(&self) -> usize;
    /// Whether pixel `index` sees a surface that receives light (no reservoir without one).
    fn has_surface(&self, index: usize) -> bool;
    /// Whether pixels `a` and `b` both have a surface and are similar enough to be reuse
    /// neighbours under `rule` (symmetric).
    fn similar(&self, a: usize, b: usize, rule: &Similarity) -> bool;
    /// The pixel of `previous` (the previous pass's surfaces) that saw the point pixel `index`
    /// sees, if that one is similar under `rule`: the same pixel when nothing moved (`motion`
    /// `None`), else where the motion vectors say.
    fn previous_pixel(
        &self,
        index: usize,
        previous: &Self,
        motion: Option<&Self::Motion>,
        rule: &Similarity,
    ) -> Option<usize>;
}

/// What the common similarity test compares of a primary hit, in 16 bytes: spatial reuse tries
/// pixels at random within its radius, and testing this instead of a full surface record touches
/// less memory. A host may keep one per pixel and implement [`Surfaces::similar`] with
/// [`SimilarityKey::is_similar`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
pub struct SimilarityKey {
    /// Shading normal.
    pub n: Vec3,
    /// Distance from the camera; [`SimilarityKey::NO_HIT`] without a primary hit.
    pub depth: f32,
}

impl SimilarityKey {
    /// `depth` of a pixel without a primary hit.
    pub const NO_HIT: f32 = -1.0;

    /// Whether the pixel has a primary hit.
    #[inline]
    pub fn hit(&self) -> bool {
        self.depth >= 0.0
    }

    /// Whether `other` is similar enough to be a reuse neighbour: shading normals within
    /// `rule.normal_cos` and camera distances within a relative `rule.depth_tolerance` (Bitterli
    /// et al. 2020, §6). Both keys must have a hit.
    #[inline]
    pub fn is_similar(&self, other: &SimilarityKey, rule: &Similarity) -> bool {
        self.n.dot(other.n) >= rule.normal_cos
            && (self.depth - other.depth).abs()
                <= rule.depth_tolerance * self.depth.max(other.depth)
    }
}

/// The host's random streams of one pass: the passes draw every random number of pixel `index`
/// from [`Streams::pixel`] with their own stage number (so the numbers do not depend on the
/// order threads run in), and choices made once per pass from [`Streams::pass`].
///
/// Contract: streams of distinct `(index, stage)` pairs are independent, and the same pair gives
/// the same stream within a pass; a new pass gives new streams.
pub trait Streams: Sync {
    /// The stream of pixel `index` for stage `stage`.
    fn pixel(&self, index: usize, stage: u64) -> Pcg32;
    /// The stream of the whole pass for stage `stage`.
    fn pass(&self, stage: u64) -> Pcg32;
}

/// Streams from a seed and a pass number, for a host without streams of its own (and the
/// renderer's own, which maps a cropped render's pixels to the film's first): the stream of pixel
/// `index` at stage `s` is PCG32 on sequence `index` at the pass's offset, seeded by the seed
/// mixed with `s` (stage 0 by the seed itself, the stream a host draws its camera ray from).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SeededStreams {
    /// The render's seed.
    pub seed: u64,
    /// The pass number.
    pub pass: u32,
}

impl SeededStreams {
    /// Stream `stream` of the whole pass for stage `stage`, one of many (one per tile of a pool
    /// drawn once per pass, say); [`Streams::pass`] is stream `u64::MAX`.
    #[inline]
    pub fn pass_stream(&self, stage: u64, stream: u64) -> Pcg32 {
        let seed = restir_sampling::mix64(self.seed ^ stage.wrapping_mul(0xe703_7ed1_a0b4_28db));
        Pcg32::for_pixel_sample(seed, stream, u64::from(self.pass))
    }
}

impl Streams for SeededStreams {
    #[inline]
    fn pixel(&self, index: usize, stage: u64) -> Pcg32 {
        let seed = if stage == 0 {
            self.seed
        } else {
            restir_sampling::mix64(self.seed ^ stage.wrapping_mul(0xa076_1d64_78bd_642f))
        };
        Pcg32::for_pixel_sample(seed, index as u64, u64::from(self.pass))
    }

    #[inline]
    fn pass(&self, stage: u64) -> Pcg32 {
        self.pass_stream(stage, u64::MAX)
    }
}
