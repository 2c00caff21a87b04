//! The film: the pixel filter and the accumulation of passes into an image.
//!
//! Pixel filters are importance-sampled: each camera ray is offset from the pixel centre by a
//! sample of the filter, and the pixel value is the plain average of its samples. The expected
//! value is the filter-weighted average of radiance over the footprint, the same as Mitsuba's
//! splatting film away from the image border, and every integrator sees the same footprint.
//! Because the filter is in the sampling, the [`Film`] keeps one sum per pixel (in `f64`, so that
//! thousands of passes lose nothing) and its image is the sum divided by the number of passes.
//! Asked to ([`Film::with_second_moment`], Mitsuba's `moment` integrator), it also keeps the sum
//! of each pass's estimate squared, in CIE XYZ as Mitsuba does: with `N` passes of mean `m` and
//! second moment `m₂`, `(m₂ − m²)/(N − 1)` estimates the variance of the pixel's value.

use glam::{DVec3, Vec2};
use restir_image::srgb;
use restir_sampling::{Distribution1D, warp};
use restir_scene::FilterDesc;

use crate::Image;

/// Table resolution for filters without an analytic inverse.
const TABLE_SIZE: usize = 1024;

/// A separable pixel filter ready for sampling.
#[derive(Clone, Debug)]
pub enum Filter {
    /// Uniform over the pixel.
    Box,
    /// Tent of the given radius.
    Tent {
        /// Radius in pixels.
        radius: f32,
    },
    /// A tabulated 1-D profile on `[-radius, radius]`.
    Tabulated {
        /// Support radius in pixels.
        radius: f32,
        /// The profile as a piecewise-constant distribution over `[0, 1)`.
        table: Distribution1D,
    },
}

impl Filter {
    /// Prepares the filter a scene asks for.
    pub fn new(desc: FilterDesc) -> Self {
        match desc {
            FilterDesc::Box => Filter::Box,
            FilterDesc::Tent { radius } => Filter::Tent { radius },
            FilterDesc::Gaussian { stddev } => {
                // Mitsuba: exp(−x²/2σ²) − exp(−8) clamped at zero, radius 4σ.
                let radius = 4.0 * stddev;
                let floor = (-8.0f32).exp();
                let vals: Vec<f32> = (0..TABLE_SIZE)
                    .map(|i| {
                        let x = ((i as f32 + 0.5) / TABLE_SIZE as f32 * 2.0 - 1.0) * radius;
                        ((-x * x / (2.0 * stddev * stddev)).exp() - floor).max(0.0)
                    })
                    .collect();
                let table = Distribution1D::new(&vals).expect("gaussian profile is positive");
                Filter::Tabulated { radius, table }
            }
        }
    }

    /// An offset from the pixel centre, in pixels, distributed like the filter.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Vec2 {
        match self {
            Filter::Box => u - Vec2::splat(0.5),
            Filter::Tent { radius } => Vec2::new(
                warp::sample_tent(u.x, *radius),
                warp::sample_tent(u.y, *radius),
            ),
            Filter::Tabulated { radius, table } => {
                let x = table.sample_continuous(u.x).0;
                let y = table.sample_continuous(u.y).0;
                (Vec2::new(x, y) * 2.0 - Vec2::ONE) * *radius
            }
        }
    }
}

/// The film of one render: the pixel filter, and per pixel the sum of one estimate per pass.
#[derive(Clone, Debug)]
pub struct Film {
    width: u32,
    height: u32,
    filter: Filter,
    sums: Vec<DVec3>,
    passes: u32,
    /// With a second moment: per pixel the sum of the passes' estimates squared (XYZ), and the
    /// buffer one pass writes its estimates into.
    moment: Option<SecondMoment>,
}

#[derive(Clone, Debug)]
struct SecondMoment {
    squares: Vec<DVec3>,
    pass: Vec<DVec3>,
}

/// A film's per-pixel mean and second moment over its passes, in CIE XYZ
/// ([`Film::moments`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Moments {
    /// The mean of the passes (the image in XYZ).
    pub mean: Vec<DVec3>,
    /// The mean of the passes' estimates squared, per XYZ channel.
    pub second: Vec<DVec3>,
}

impl Film {
    /// An empty film of `width × height` pixels with the filter `filter`.
    pub fn new(width: u32, height: u32, filter: FilterDesc) -> Self {
        Self {
            width,
            height,
            filter: Filter::new(filter),
            sums: vec![DVec3::ZERO; width as usize * height as usize],
            passes: 0,
            moment: None,
        }
    }

    /// The film also keeping each pixel's second moment ([`Film::moments`]): two more buffers of
    /// the film's size, and a pass's estimates are added after it ends.
    pub fn with_second_moment(mut self) -> Self {
        let n = self.sums.len();
        self.moment = Some(SecondMoment {
            squares: vec![DVec3::ZERO; n],
            pass: vec![DVec3::ZERO; n],
        });
        self
    }

    /// `(width, height)` in pixels.
    pub fn resolution(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The pixel filter.
    pub fn filter(&self) -> &Filter {
        &self.filter
    }

    /// Passes added so far.
    pub fn passes(&self) -> u32 {
        self.passes
    }

    /// Adds one pass: `pass` gets the filter (for jittering camera rays) and the row-major
    /// per-pixel sums, to which it adds one estimate per pixel; its result is returned.
    pub fn add_pass<R>(&mut self, pass: impl FnOnce(&Filter, &mut [DVec3]) -> R) -> R {
        let r = match &mut self.moment {
            None => pass(&self.filter, &mut self.sums),
            Some(m) => {
                m.pass.fill(DVec3::ZERO);
                let r = pass(&self.filter, &mut m.pass);
                for ((sum, square), v) in self.sums.iter_mut().zip(&mut m.squares).zip(&m.pass) {
                    *sum += *v;
                    let xyz = srgb::to_xyz(*v);
                    *square += xyz * xyz;
                }
                r
            }
        };
        self.passes += 1;
        r
    }

    /// The per-pixel mean and second moment of the passes in XYZ, if the film keeps them
    /// ([`Film::with_second_moment`]); zero before the first pass.
    pub fn moments(&self) -> Option<Moments> {
        let m = self.moment.as_ref()?;
        let inv = 1.0 / self.passes.max(1) as f64;
        Some(Moments {
            mean: self.sums.iter().map(|s| srgb::to_xyz(*s * inv)).collect(),
            second: m.squares.iter().map(|s| *s * inv).collect(),
        })
    }

    /// The average of the passes (black before the first).
    pub fn image(&self) -> Image {
        let inv = 1.0 / self.passes.max(1) as f64;
        Image {
            width: self.width,
            height: self.height,
            pixels: self.sums.iter().map(|s| (*s * inv).as_vec3()).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sample offsets have mean zero and the variance of the filter profile.
    #[test]
    fn filter_moments() {
        let n = 200_000;
        let cases = [
            (FilterDesc::Box, 1.0 / 12.0),
            (FilterDesc::Tent { radius: 1.0 }, 1.0 / 6.0),
            // Truncated at 4σ the variance is within 0.1% of σ².
            (FilterDesc::Gaussian { stddev: 0.5 }, 0.25),
        ];
        for (desc, var) in cases {
            let f = Filter::new(desc);
            let mut rng = restir_sampling::Pcg32::new(1, 2);
            let (mut s, mut s2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let o = f.sample(rng.next_2d());
                s += o.x as f64;
                s2 += (o.x as f64).powi(2);
            }
            let mean = s / n as f64;
            let v = s2 / n as f64 - mean * mean;
            let se_mean = (var / n as f64).sqrt();
            assert!(mean.abs() < 4.0 * se_mean, "{desc:?}: mean {mean}");
            // Fourth moment ≤ 3σ⁴ for these profiles: SE of the variance ≤ sqrt(2/n)·σ².
            assert!(
                (v - var).abs() < 4.0 * (2.0 / n as f64).sqrt() * var + 1e-3 * var,
                "{desc:?}: var {v} vs {var}"
            );
        }
    }

    /// The second moment is the mean of the passes' estimates squared in XYZ, the mean the
    /// image's in XYZ; the image is the same as without it.
    #[test]
    fn film_keeps_the_second_moment() {
        let passes = [DVec3::new(1.0, 0.0, 0.0), DVec3::new(3.0, 2.0, 1.0)];
        let mut plain = Film::new(1, 1, FilterDesc::Box);
        let mut film = Film::new(1, 1, FilterDesc::Box).with_second_moment();
        assert!(plain.moments().is_none());
        for v in passes {
            plain.add_pass(|_, sums| sums[0] += v);
            film.add_pass(|_, sums| sums[0] += v);
        }
        assert_eq!(film.image(), plain.image());
        let m = film.moments().unwrap();
        let xyz = passes.map(srgb::to_xyz);
        let second = (xyz[0] * xyz[0] + xyz[1] * xyz[1]) / 2.0;
        assert!((m.second[0] - second).abs().max_element() < 1e-12);
        assert!((m.mean[0] - (xyz[0] + xyz[1]) / 2.0).abs().max_element() < 1e-12);
    }

    /// The image is the per-pixel mean of the passes.
    #[test]
    fn film_averages_passes() {
        let mut film = Film::new(2, 1, FilterDesc::Box);
        assert_eq!(film.image().pixels, vec![glam::Vec3::ZERO; 2]);
        for v in [1.0, 2.0, 6.0] {
            film.add_pass(|_, sums| {
                sums[0] += DVec3::splat(v);
                sums[1] += DVec3::new(v, 0.0, -v);
            });
        }
        assert_eq!(film.passes(), 3);
        let image = film.image();
        assert_eq!((image.width, image.height), (2, 1));
        assert_eq!(image.pixels[0], glam::Vec3::splat(3.0));
        assert_eq!(image.pixels[1], glam::Vec3::new(3.0, 0.0, -3.0));
    }
}
