//! How an estimator plugs into the reuse passes ([`crate::passes`], [`crate::reciprocal`]): its
//! sample, its shift map's domain and the map itself.

use std::borrow::Borrow;

use restir_gris::{Reservoir, ShiftMap};

/// What an estimator's reuse needs for one pass: its shift map between the pixels of this pass
/// and the previous one.
pub trait ReuseShift: Sync {
    /// The reservoirs' sample.
    type Sample: Copy + Send + Sync;
    /// What the shift map calls a domain.
    type Domain: Sync + ?Sized;
    /// The shift map resampling a pixel uses.
    type Map<'m>: ShiftMap<Self::Sample, Domain = Self::Domain>
    where
        Self: 'm;

    /// The shift map for resampling into a pixel whose reservoir is `canonical`.
    fn map(&self, canonical: &Reservoir<Self::Sample>) -> Self::Map<'_>;

    /// Rays `map`'s shifts traced.
    fn rays(map: &Self::Map<'_>) -> u64 {
        let _ = map;
        0
    }

    /// How [`Self::domain`] hands a domain out: a reference into the estimator's buffers, or a
    /// small value (a pixel index) that needs no buffer to lend it.
    type DomainRef<'d>: Borrow<Self::Domain> + Copy
    where
        Self: 'd;

    /// The domain of pixel `index` (which has a primary hit) in this pass, or in the previous
    /// pass with `previous`.
    fn domain(&self, index: usize, previous: bool) -> Self::DomainRef<'_>;

    /// The integrand over the target, `f(y)/p̂(y)` (RGB), of `sample` at the receiver it is
    /// expressed in (its pixel's reservoir, or the shift's destination), when the sample
    /// carries it. With it, the last spatial round also gives each pixel the expectation of
    /// its shading over the round's selection ([`ScreenReuse::reuse_expected`](crate::ScreenReuse::reuse_expected)):
    /// every input shaded with its resampling weight, at no extra shift. `None` (the default):
    /// the host shades the selected sample.
    fn ratio(sample: &Self::Sample) -> Option<[f32; 3]> {
        let _ = sample;
        None
    }

    /// Whether two pixels hold the same sample (one of them shifted from the other, or both
    /// from a common one), for the duplication-aware history cap ([`crate::duplication`]).
    fn same_sample(a: &Self::Sample, b: &Self::Sample) -> bool;
}
