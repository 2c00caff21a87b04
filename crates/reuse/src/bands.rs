//! The parallel work items of a per-pixel pass (every estimator's loops over the image): bands
//! of [`BAND_ROWS`] image rows, run in parallel over one or several per-pixel buffers at once
//! ([`Bands::run`]), each band told the index of its first pixel.

use rayon::iter::{Either, Map, RepeatN, Zip, repeat_n};
use rayon::prelude::*;
use rayon::slice::ChunksMut;

/// Image rows per parallel work item: small enough to balance the threads, large enough to
/// amortise the per-item setup.
pub const BAND_ROWS: usize = 2;

/// The bands of an image `width` pixels wide.
#[derive(Clone, Copy, Debug)]
pub struct Bands {
    len: usize,
}

/// Per-pixel buffers cut into bands together: a mutable slice, or a pair of them (nest pairs
/// for more: `((a, b), c)`). A band of a pair is the pair of the bands.
pub trait BandBuffers: Send + Sized {
    /// One band's part of the buffers.
    type Band: Send;
    /// The bands in order.
    type Iter: IndexedParallelIterator<Item = Self::Band>;
    /// Cuts the buffers into pieces of `len` items.
    fn split(self, len: usize) -> Self::Iter;
}

impl<'a, T: Send> BandBuffers for &'a mut [T] {
    type Band = &'a mut [T];
    type Iter = ChunksMut<'a, T>;
    fn split(self, len: usize) -> Self::Iter {
        self.par_chunks_mut(len)
    }
}

/// The bands of a buffer that may be absent.
type OptionalBands<'a, T> = Either<
    Map<ChunksMut<'a, T>, fn(&'a mut [T]) -> Option<&'a mut [T]>>,
    Map<RepeatN<()>, fn(()) -> Option<&'a mut [T]>>,
>;

/// A buffer that may be absent: its bands, or `None` for every band (beside another buffer,
/// which decides how many bands there are).
impl<'a, T: Send> BandBuffers for Option<&'a mut [T]> {
    type Band = Option<&'a mut [T]>;
    type Iter = OptionalBands<'a, T>;
    fn split(self, len: usize) -> Self::Iter {
        match self {
            Some(buffer) => Either::Left(buffer.par_chunks_mut(len).map(Some as fn(_) -> _)),
            None => Either::Right(repeat_n((), usize::MAX).map((|()| None) as fn(_) -> _)),
        }
    }
}

impl<A: BandBuffers, B: BandBuffers> BandBuffers for (A, B) {
    type Band = (A::Band, B::Band);
    type Iter = Zip<A::Iter, B::Iter>;
    fn split(self, len: usize) -> Self::Iter {
        self.0.split(len).zip(self.1.split(len))
    }
}

impl Bands {
    /// The bands of an image `width` pixels wide.
    #[inline]
    pub fn new(width: usize) -> Self {
        Self {
            len: width * BAND_ROWS,
        }
    }

    /// The bands of `rows` image rows (at least one) of an image `width` pixels wide: for a loop
    /// whose pixels share data by blocks of rows (a screen tile's pool of light samples).
    pub fn of_rows(width: usize, rows: usize) -> Self {
        Self {
            len: width * rows.max(1),
        }
    }

    /// Pixels per band (the chunk length of `par_chunks_mut`).
    #[inline]
    pub fn pixels(self) -> usize {
        self.len
    }

    /// The index of the first pixel of band `band`.
    #[inline]
    pub fn first(self, band: usize) -> usize {
        band * self.len
    }

    /// Runs `f(first pixel, band)` on every band of `buffers` (one item per pixel) in parallel
    /// and sums what it returns (rays traced).
    pub fn run<B: BandBuffers>(
        self,
        buffers: B,
        f: impl Fn(usize, B::Band) -> u64 + Sync + Send,
    ) -> u64 {
        self.run_strided(buffers, 1, f)
    }

    /// [`Bands::run`] over buffers with `per_pixel` items per pixel.
    pub fn run_strided<B: BandBuffers>(
        self,
        buffers: B,
        per_pixel: usize,
        f: impl Fn(usize, B::Band) -> u64 + Sync + Send,
    ) -> u64 {
        let len = self.len;
        buffers
            .split(len * per_pixel)
            .enumerate()
            .map(|(band, b)| f(band * len, b))
            .sum()
    }
}
