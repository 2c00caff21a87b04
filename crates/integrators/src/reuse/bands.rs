//! The parallel work items of a per-pixel pass: bands of [`BAND_ROWS`] image rows, and the
//! arithmetic from a band and a position in it to the pixel index.

use crate::render::BAND_ROWS;

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
