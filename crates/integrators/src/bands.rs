//! The parallel work items of a per-pixel pass (every estimator's loops over the image): bands of [`BAND_ROWS`] image rows, and the
//! arithmetic from a band and a position in it to the pixel index.

/// Image rows per parallel work item: small enough to balance the threads, large enough to
/// amortise the per-item setup.
pub(crate) const BAND_ROWS: usize = 2;

/// The bands of an image `width` pixels wide.
#[derive(Clone, Copy, Debug)]
pub struct Bands {
    len: usize,
}

impl Bands {
    /// The bands of an image `width` pixels wide.
    #[inline]
    pub fn new(width: usize) -> Self {
        Self {
            len: width * BAND_ROWS,
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
}
