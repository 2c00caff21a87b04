//! A splatting film's machinery: how its passes' offsets are drawn ([`SplatOffsets`]), the
//! estimates of rays through offsets of their own ([`FilmSample`], [`FilmSamples`]), and the
//! gathering of a pass's estimates into pixel values (`Splat`).

use std::sync::{Arc, Mutex};

use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;
use restir_sampling::Distribution1D;
use restir_scene::FilterDesc;

use super::{pixel_integrals, profile};

/// Rows of the film a task of [`Splat::scatter`] adds to.
const SCATTER_ROWS: usize = 16;

/// Bins per axis of the table [`SplatOffsets`] draws from.
const OFFSET_BINS: usize = 1024;

/// Sub-intervals per bin for the table's averages.
const OFFSET_QUADRATURE: usize = 16;

/// Where a splatting film's shared offsets fall within their pixels, and the density to divide
/// by. A pixel sums the estimates of the pixels within its reach with the filter's weights;
/// when every ray of a pass goes through offset `u` of its pixel those weights sum to
/// `W(u) = Wx(u.x)·Wy(u.y)` (the filter is separable), which varies with `u`: by ±3 % for the
/// Gaussian of σ = 0.5. Drawn uniformly, that variation is noise on every pixel of a pass, as
/// large on a flat bright region (an emitter seen directly, a sky) as on an edge, and a
/// renderer that makes few passes keeps more of it. Drawn with a density `q(u)` proportional
/// to `W(u)` (per axis, from a table of its averages over 1024 bins) and each
/// estimate divided by `q(u)`, a region of constant radiance gets its radiance in every pass
/// (to within `W`'s variation inside a bin: under 10⁻³), and every pixel's expected value is
/// unchanged, since `E_q[g(u)/q(u)] = ∫ g(u) du` for what the pixel gathers, `g`.
#[derive(Clone, Debug)]
pub struct SplatOffsets {
    axis: Distribution1D,
}

impl SplatOffsets {
    /// The offsets of a splatting film whose pixels reach `reach` pixels each way.
    fn new(filter: FilterDesc, reach: u32) -> Self {
        let r = reach as i32;
        let sum_at = |t: f64| -> f64 {
            (-r..=r)
                .map(|k| profile(filter, f64::from(k) + t - 0.5))
                .sum()
        };
        let h = 1.0 / (OFFSET_BINS * OFFSET_QUADRATURE) as f64;
        let bins: Vec<f32> = (0..OFFSET_BINS)
            .map(|b| {
                let first = b * OFFSET_QUADRATURE;
                let mean = (first..first + OFFSET_QUADRATURE)
                    .map(|i| sum_at((i as f64 + 0.5) * h))
                    .sum::<f64>()
                    / OFFSET_QUADRATURE as f64;
                mean as f32
            })
            .collect();
        let axis = Distribution1D::new(&bins).expect("a splatted filter's weights sum above zero");
        Self { axis }
    }

    /// The offset for the uniform point `v` of `[0, 1)²`: distributed with density `q`.
    pub fn warp(&self, v: Vec2) -> Vec2 {
        Vec2::new(
            self.axis.sample_continuous(v.x).0,
            self.axis.sample_continuous(v.y).0,
        )
    }

    /// `1 / q(u)`: what an estimate through offset `u` is multiplied by.
    pub fn inverse_density(&self, u: Vec2) -> f64 {
        1.0 / (f64::from(self.axis.pdf(u.x)) * f64::from(self.axis.pdf(u.y)))
    }
}

/// An estimate of a camera ray that did not go through the pass's shared offset: a splatting film
/// adds it with the filter's weights at its own position (`offset` within pixel `pixel` of the
/// pass's buffer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilmSample {
    /// The pixel (row-major index into the pass's buffer).
    pub pixel: u32,
    /// Where within the pixel its ray went, in `[0, 1)²`.
    pub offset: Vec2,
    /// The estimate.
    pub value: Vec3,
}

/// Where a pass of a splatting film puts its [`FilmSample`]s ([`crate::PassContext::samples`]),
/// and how it draws their offsets.
#[derive(Debug)]
pub struct FilmSamples {
    samples: Mutex<Vec<FilmSample>>,
    offsets: Arc<SplatOffsets>,
}

impl FilmSamples {
    /// The offset within its pixel of a camera ray for the uniform point `v` of `[0, 1)²`,
    /// drawn as the film draws its shared offsets ([`SplatOffsets`]). A ray whose estimate is
    /// added here must go through such an offset, and every pixel that takes rays through
    /// offsets of their own must take the same ones: then the filter weights a pixel gathers
    /// from its neighbours' rays still sum to a constant, as they do at the shared offset.
    pub fn offset(&self, v: Vec2) -> Vec2 {
        self.offsets.warp(v)
    }

    /// Adds `samples`.
    pub fn add(&self, samples: impl IntoIterator<Item = FilmSample>) {
        if let Ok(mut v) = self.samples.lock() {
            v.extend(samples);
        }
    }

    /// The samples added, by pixel (in the order each pixel's came).
    pub(super) fn take(&self) -> Vec<FilmSample> {
        let mut v = self
            .samples
            .lock()
            .map(|mut v| std::mem::take(&mut *v))
            .unwrap_or_default();
        v.sort_by_key(|s| s.pixel);
        v
    }
}

/// What a splatting film keeps: the filter, how its offsets are drawn, and per column and row
/// the inverse of the filter's expected weight over the film.
#[derive(Clone, Debug)]
pub(super) struct Splat {
    filter: FilterDesc,
    reach: usize,
    pub(super) offsets: Arc<SplatOffsets>,
    inv_norm_x: Vec<f64>,
    inv_norm_y: Vec<f64>,
    /// The pass's estimates, and their rows summed with the horizontal weights.
    pub(super) pass: Vec<DVec3>,
    rows: Vec<DVec3>,
}

impl Splat {
    pub(super) fn new(filter: FilterDesc, reach: u32, (width, height): (u32, u32)) -> Self {
        let r = reach as i32;
        let expected: Vec<f64> = (-r..=r).map(|k| pixel_integrals(filter, k).0).collect();
        // Pixel `p` of the film sums the pixels `p + k` that are in the film.
        let inv_norm = |size: u32| -> Vec<f64> {
            (0..size)
                .map(|p| {
                    let sum: f64 = (-r..=r)
                        .filter(|k| (0..size as i64).contains(&(i64::from(p) + i64::from(*k))))
                        .map(|k| expected[(k + r) as usize])
                        .sum();
                    1.0 / sum
                })
                .collect()
        };
        let n = width as usize * height as usize;
        Self {
            filter,
            reach: reach as usize,
            offsets: Arc::new(SplatOffsets::new(filter, reach)),
            inv_norm_x: inv_norm(width),
            inv_norm_y: inv_norm(height),
            pass: vec![DVec3::ZERO; n],
            rows: vec![DVec3::ZERO; n],
        }
    }

    /// An empty sink for a pass's estimates of rays through offsets of their own.
    pub(super) fn samples(&self) -> FilmSamples {
        FilmSamples {
            samples: Mutex::default(),
            offsets: self.offsets.clone(),
        }
    }

    /// Adds `samples` (by pixel), each with the filter's weights at its own position, to `out`,
    /// normalised as [`Splat::gather`] normalises and divided by the density of its offset
    /// ([`SplatOffsets`]): so a pixel's value is linear in every estimate of the pass, wherever
    /// its ray went.
    pub(super) fn scatter(&self, samples: &[FilmSample], out: &mut [DVec3]) {
        let (w, h) = (self.inv_norm_x.len(), self.inv_norm_y.len());
        let r = self.reach;
        // The samples of each row of the pass (they come by pixel).
        let mut starts = vec![0usize; h + 1];
        for s in samples {
            let y = (s.pixel as usize / w).min(h);
            if y < h {
                starts[y + 1] += 1;
            }
        }
        for y in 0..h {
            starts[y + 1] += starts[y];
        }
        // Pixel `p` weighs the ray `q − p + u − ½` from its centre.
        let weight = |q: usize, p: usize, u: f32| {
            profile(self.filter, q as f64 - p as f64 + f64::from(u) - 0.5)
        };
        // Bands of rows in parallel; within a band each sample's horizontal weights are found
        // once for all the band's rows within its reach. Each pixel adds the samples within
        // reach in their order, so the sums are the same for any thread count (and the same as
        // row by row).
        out.par_chunks_mut(w * SCATTER_ROWS)
            .enumerate()
            .for_each(|(band, chunk)| {
                let y0 = band * SCATTER_ROWS;
                let y1 = y0 + chunk.len() / w;
                let mut wx = vec![0.0f64; 2 * r + 1];
                let rows = y0.saturating_sub(r)..(y1 + r).min(h);
                for s in &samples[starts[rows.start]..starts[rows.end]] {
                    let (qx, qy) = (s.pixel as usize % w, s.pixel as usize / w);
                    let first = qx.saturating_sub(r);
                    let span = first..(qx + r + 1).min(w);
                    for (x, wx) in span.clone().zip(wx.iter_mut()) {
                        *wx = weight(qx, x, s.offset.x);
                    }
                    let inverse_density = self.offsets.inverse_density(s.offset);
                    for y in qy.saturating_sub(r).max(y0)..(qy + r + 1).min(y1) {
                        let wy = weight(qy, y, s.offset.y) * self.inv_norm_y[y];
                        if wy == 0.0 {
                            continue;
                        }
                        let value = s.value.as_dvec3() * (wy * inverse_density);
                        let row = &mut chunk[(y - y0) * w..(y - y0 + 1) * w];
                        for ((v, inv), wx) in row[span.clone()]
                            .iter_mut()
                            .zip(&self.inv_norm_x[span.clone()])
                            .zip(&wx)
                        {
                            *v += value * (wx * inv);
                        }
                    }
                }
            });
    }

    /// Adds the pass's pixel values, made from its estimates (in `self.pass`) whose rays went
    /// through `offset` within their pixels, to `out`, divided by the density of `offset`
    /// ([`SplatOffsets`]). Pixels nearer the film's edge than `reach` sum the estimates it has
    /// and are normalised by their expected weight.
    pub(super) fn gather(&mut self, offset: Vec2, out: &mut [DVec3]) {
        let Splat {
            filter,
            reach,
            offsets,
            inv_norm_x,
            inv_norm_y,
            pass,
            rows,
        } = self;
        let (filter, reach) = (*filter, *reach);
        let (w, h) = (inv_norm_x.len(), inv_norm_y.len());
        // The weight of the estimate of the pixel `k` away: its ray is `k + u − ½` from the
        // centre, at index `k + reach`; the offset's density is divided out along one axis.
        let weights = |u: f32, scale: f64| -> Vec<f64> {
            let r = reach as i64;
            (-r..=r)
                .map(|k| profile(filter, k as f64 + f64::from(u) - 0.5) * scale)
                .collect()
        };
        let (wx, wy) = (
            weights(offset.x, offsets.inverse_density(offset)),
            weights(offset.y, 1.0),
        );
        // The pixels within reach of `p` in a line of `size`.
        let span = move |p: usize, size: usize| p.saturating_sub(reach)..(p + reach + 1).min(size);
        rows.par_chunks_mut(w)
            .zip(pass.par_chunks(w))
            .for_each(|(row, src)| {
                for (x, v) in row.iter_mut().enumerate() {
                    let mut sum = DVec3::ZERO;
                    for q in span(x, w) {
                        sum += src[q] * wx[q + reach - x];
                    }
                    *v = sum * inv_norm_x[x];
                }
            });
        let rows = &*rows;
        out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, v) in row.iter_mut().enumerate() {
                let mut sum = DVec3::ZERO;
                for q in span(y, h) {
                    sum += rows[q * w + x] * wy[q + reach - y];
                }
                *v += sum * inv_norm_y[y];
            }
        });
    }
}
