//! The film: the pixel filter and the accumulation of passes into an image.
//!
//! Every pass makes one camera ray per pixel, and the film turns the pass's per-pixel estimates
//! into pixel values in one of two ways, decided once per render from the filter
//! ([`Reconstruction`]):
//!
//! - **Sampled** (the box filter, and filters about as narrow): each camera ray is offset from
//!   the pixel centre by a sample of the filter, and the pixel's value in the pass is its own
//!   estimate.
//! - **Splatted** (filters wider than a pixel: Mitsuba's default Gaussian, a tent of radius 1):
//!   every pixel's ray goes through the same uniformly drawn position `u` within its own pixel
//!   (one `u` per pass), and a pixel's value is the filter-weighted sum of the estimates of the
//!   pixels its filter reaches, divided by the filter's expected weight over the film. Each
//!   pixel then averages several rays per pass instead of one, and the estimate stays unbiased:
//!   the expected value is `∫ f(x − c)·L(x) dx / ∫ f(x − c) dx` over the film, Mitsuba's
//!   splatting film's limit, at the border too. Because `u` is shared, the weights a pixel
//!   sums vary little from pass to pass (for a tent of radius 1 they sum to one exactly; for
//!   the Gaussian of σ = 0.5 by ±3 %); the offset is drawn in proportion to that sum and each
//!   pass divided by its density ([`SplatOffsets`]), so a region of constant radiance gets its
//!   radiance in every pass, as it does when sampling. Within the filter's reach of the film's
//!   edge a pixel misses the estimates beyond it, so there the sum varies more (by up to a third
//!   on an edge) and a flat region shows some noise that sampling would not.
//!
//! The expected image is the same either way away from the border. The [`Film`] keeps one sum
//! per pixel (in `f64`, so that thousands of passes lose nothing) and its image is the sum
//! divided by the number of passes.
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
                // Mitsuba's profile ([`profile`]) over its radius 4σ.
                let radius = 4.0 * stddev;
                let vals: Vec<f32> = (0..TABLE_SIZE)
                    .map(|i| {
                        let x = ((i as f32 + 0.5) / TABLE_SIZE as f32 * 2.0 - 1.0) * radius;
                        profile(desc, f64::from(x)) as f32
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

/// Splatting reaches at most this many pixels beyond a pixel's own; wider filters are sampled
/// (a pass's gathering costs `2·reach + 1` additions per pixel and axis).
pub const MAX_SPLAT_REACH: u32 = 8;

/// Splatting is chosen when, for estimates with independent noise, it leaves at most this
/// fraction of the sampled film's variance (`(∫f² / (∫f)²)²`, [`Reconstruction::decide`]).
const SPLAT_VARIANCE_FACTOR: f64 = 0.9;

/// Sub-intervals per pixel for the filter's integrals over pixels.
const QUADRATURE: usize = 4096;

/// How the film makes pixel values from a pass's one estimate per pixel (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub enum Reconstruction {
    /// Camera rays sample the filter; a pixel's value is its own estimate.
    Sampled,
    /// Camera rays share one uniform position within their pixels per pass; a pixel's value is
    /// the filter-weighted sum of the estimates within `reach` pixels.
    Splatted {
        /// How many pixels beyond its own a pixel's filter reaches.
        reach: u32,
        /// The variance of a splatted pixel relative to a sampled one when the estimates'
        /// noise is independent between pixels: `(∫f² / (∫f)²)²`.
        variance_factor: f64,
    },
}

impl Reconstruction {
    /// The reconstruction for `filter`: splatted when that leaves at most
    /// `SPLAT_VARIANCE_FACTOR` (0.9) of the sampled variance for independent noise and the
    /// filter reaches at most [`MAX_SPLAT_REACH`] pixels; sampled otherwise (the box filter,
    /// whose factor is 1, narrow filters, whose factor exceeds 1, and very wide ones).
    pub fn decide(filter: FilterDesc) -> Self {
        let Some(radius) = profile_radius(filter) else {
            return Self::Sampled;
        };
        let reach = (radius + 0.5).ceil() - 1.0;
        if reach > MAX_SPLAT_REACH as f32 {
            return Self::Sampled;
        }
        let reach = reach.max(0.0) as u32;
        let (integral, squares) = (-(reach as i32)..=reach as i32).fold((0.0, 0.0), |acc, k| {
            let (a, b) = pixel_integrals(filter, k);
            (acc.0 + a, acc.1 + b)
        });
        let variance_factor = (squares / (integral * integral)).powi(2);
        if variance_factor <= SPLAT_VARIANCE_FACTOR {
            Self::Splatted {
                reach,
                variance_factor,
            }
        } else {
            Self::Sampled
        }
    }

    /// How many pixels beyond its own a pixel's value reaches for estimates: the halo a
    /// cropped render needs for its film (0 when sampled).
    pub fn reach(&self) -> u32 {
        match self {
            Self::Sampled => 0,
            Self::Splatted { reach, .. } => *reach,
        }
    }

    /// Bytes per pixel the film keeps for this reconstruction beside its sums: when splatting,
    /// a pass's estimates and their rows gathered (3 × f64 each).
    pub fn buffer_bytes_per_pixel(&self) -> usize {
        match self {
            Self::Sampled => 0,
            Self::Splatted { .. } => 2 * std::mem::size_of::<DVec3>(),
        }
    }

    /// One line for `--stats`: what was decided and why.
    pub fn describe(&self, filter: FilterDesc) -> String {
        let name = match filter {
            FilterDesc::Box => "box".to_string(),
            FilterDesc::Tent { radius } => format!("tent radius {radius}"),
            FilterDesc::Gaussian { stddev } => format!("gaussian stddev {stddev}"),
        };
        match self {
            Self::Sampled => format!("{name}: sampled (camera rays sample the filter)"),
            Self::Splatted {
                reach,
                variance_factor,
            } => format!(
                "{name}: splatted over {reach} pixels each way (for independent noise, \
                 {variance_factor:.2} of the sampled variance), each pass's offset drawn in \
                 proportion to the filter weights it gathers"
            ),
        }
    }
}

/// The filter's 1-D profile at `x` pixels from the centre (Mitsuba's definitions).
fn profile(filter: FilterDesc, x: f64) -> f64 {
    match filter {
        FilterDesc::Box => f64::from(u8::from(x.abs() < 0.5)),
        FilterDesc::Tent { radius } => (1.0 - x.abs() / f64::from(radius)).max(0.0),
        FilterDesc::Gaussian { stddev } => {
            let s = f64::from(stddev);
            if x.abs() >= 4.0 * s {
                return 0.0;
            }
            ((-x * x / (2.0 * s * s)).exp() - (-8.0f64).exp()).max(0.0)
        }
    }
}

/// The radius of a filter that may be splatted (`None` for the box).
fn profile_radius(filter: FilterDesc) -> Option<f32> {
    match filter {
        FilterDesc::Box => None,
        FilterDesc::Tent { radius } => Some(radius),
        FilterDesc::Gaussian { stddev } => Some(4.0 * stddev),
    }
}

/// `(∫ f, ∫ f²)` over the pixel `k` pixels from the centre's: the expected weight, and its
/// expected square, of the estimate of a pixel `k` away when its ray is uniform in its pixel.
fn pixel_integrals(filter: FilterDesc, k: i32) -> (f64, f64) {
    let h = 1.0 / QUADRATURE as f64;
    (0..QUADRATURE).fold((0.0, 0.0), |acc, i| {
        let f = profile(filter, f64::from(k) - 0.5 + (i as f64 + 0.5) * h);
        (acc.0 + f * h, acc.1 + f * f * h)
    })
}

mod splat;

use splat::Splat;
pub use splat::{FilmSample, FilmSamples, SplatOffsets};

/// The film of one render (or of the region of a film one part renders): the pixel filter, how
/// pixel values are made from it, and per pixel the sum of one value per pass.
#[derive(Clone, Debug)]
pub struct Film {
    width: u32,
    height: u32,
    filter: Filter,
    reconstruction: Reconstruction,
    splat: Option<Splat>,
    sums: Vec<DVec3>,
    passes: u32,
    /// With a second moment: per pixel the sum of the passes' estimates squared (XYZ), and the
    /// buffer one pass's values are made in.
    moment: Option<SecondMoment>,
}

#[derive(Clone, Debug)]
struct SecondMoment {
    squares: Vec<DVec3>,
    pass: Vec<DVec3>,
}

impl SecondMoment {
    /// Adds the pass's values to `sums` and their squares (in XYZ) to the second moment's.
    fn add_to(&mut self, sums: &mut [DVec3]) {
        for ((sum, square), v) in sums.iter_mut().zip(&mut self.squares).zip(&self.pass) {
            *sum += *v;
            let xyz = srgb::to_xyz(*v);
            *square += xyz * xyz;
        }
    }
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
    /// An empty film of `width × height` pixels with the filter `filter`. A cropped render's
    /// film is its region's: when splatting, its pixels within the filter's reach
    /// ([`Reconstruction::reach`]) of a region edge inside the whole film miss estimates, and
    /// the halo keeps them out of the window.
    pub fn new(width: u32, height: u32, filter: FilterDesc) -> Self {
        let reconstruction = Reconstruction::decide(filter);
        let splat = match reconstruction {
            Reconstruction::Sampled => None,
            Reconstruction::Splatted { reach, .. } => {
                Some(Splat::new(filter, reach, (width, height)))
            }
        };
        Self {
            width,
            height,
            filter: match splat {
                None => Filter::new(filter),
                Some(_) => Filter::Box,
            },
            reconstruction,
            splat,
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

    /// The filter camera rays sample: the scene's when sampling, the box when splatting (each
    /// pass then also gets one shared position, [`Film::add_pass`]).
    pub fn filter(&self) -> &Filter {
        &self.filter
    }

    /// Where within its pixel every camera ray of a pass goes when the film splats, for the
    /// uniform point `v` of `[0, 1)²` the pass draws: drawn in proportion to the filter weights
    /// the pixels then gather ([`SplatOffsets`]); `v` itself when the film samples.
    pub fn shared_offset(&self, v: Vec2) -> Vec2 {
        match &self.splat {
            Some(s) => s.offsets.warp(v),
            None => v,
        }
    }

    /// How pixel values are made.
    pub fn reconstruction(&self) -> &Reconstruction {
        &self.reconstruction
    }

    /// Passes added so far.
    pub fn passes(&self) -> u32 {
        self.passes
    }

    /// Adds one pass: `pass` gets the filter (for jittering camera rays), where to put estimates
    /// of rays that went elsewhere than `offset` (when splatting; [`FilmSample`]) and a
    /// row-major buffer to which it adds one estimate per pixel; its result is returned. When
    /// splatting, `offset` is where within its pixel every ray of the pass went (in `[0, 1)²`;
    /// ignored when sampling), as [`Film::shared_offset`] draws it.
    pub fn add_pass<R>(
        &mut self,
        offset: Vec2,
        pass: impl FnOnce(&Filter, Option<&FilmSamples>, &mut [DVec3]) -> R,
    ) -> R {
        let r = match (&mut self.splat, &mut self.moment) {
            (None, None) => pass(&self.filter, None, &mut self.sums),
            (None, Some(m)) => {
                m.pass.fill(DVec3::ZERO);
                let r = pass(&self.filter, None, &mut m.pass);
                m.add_to(&mut self.sums);
                r
            }
            (Some(s), moment) => {
                s.pass.fill(DVec3::ZERO);
                let samples = s.samples();
                let r = pass(&self.filter, Some(&samples), &mut s.pass);
                let samples = samples.take();
                match moment {
                    None => {
                        s.gather(offset, &mut self.sums);
                        s.scatter(&samples, &mut self.sums);
                    }
                    Some(m) => {
                        m.pass.fill(DVec3::ZERO);
                        s.gather(offset, &mut m.pass);
                        s.scatter(&samples, &mut m.pass);
                        m.add_to(&mut self.sums);
                    }
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
    use crate::pass::PixelWindow;
    use glam::Vec3;

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
            plain.add_pass(Vec2::ZERO, |_, _, sums| sums[0] += v);
            film.add_pass(Vec2::ZERO, |_, _, sums| sums[0] += v);
        }
        assert_eq!(film.image(), plain.image());
        let m = film.moments().unwrap();
        let xyz = passes.map(srgb::to_xyz);
        let second = (xyz[0] * xyz[0] + xyz[1] * xyz[1]) / 2.0;
        assert!((m.second[0] - second).abs().max_element() < 1e-12);
        assert!((m.mean[0] - (xyz[0] + xyz[1]) / 2.0).abs().max_element() < 1e-12);
    }

    /// The box is sampled; filters wider than a pixel are splatted when that lowers the
    /// variance of independent estimates, narrow and very wide ones are sampled.
    #[test]
    fn reconstruction_is_decided_by_the_filter() {
        assert_eq!(
            Reconstruction::decide(FilterDesc::Box),
            Reconstruction::Sampled
        );
        let splatted = |f| match Reconstruction::decide(f) {
            Reconstruction::Splatted {
                reach,
                variance_factor,
            } => Some((reach, variance_factor)),
            Reconstruction::Sampled => None,
        };
        // ∫f² / (∫f)² = 1 / (2σ√π) per axis for a Gaussian; 2/3 for a tent of radius 1.
        let (reach, factor) = splatted(FilterDesc::Gaussian { stddev: 0.5 }).unwrap();
        assert_eq!(reach, 2);
        assert!(
            (factor - 1.0 / std::f64::consts::PI).abs() < 2e-3,
            "{factor}"
        );
        let (reach, factor) = splatted(FilterDesc::Tent { radius: 1.0 }).unwrap();
        assert_eq!(reach, 1);
        assert!((factor - 4.0 / 9.0).abs() < 1e-6, "{factor}");
        assert_eq!(splatted(FilterDesc::Tent { radius: 0.6 }), None);
        assert_eq!(splatted(FilterDesc::Gaussian { stddev: 0.2 }), None);
        assert_eq!(
            splatted(FilterDesc::Gaussian { stddev: 3.0 }),
            None,
            "reach 12"
        );
    }

    /// Radiance along one axis, with a step: separable test images are products of two.
    fn line(x: f64) -> f64 {
        1.0 + 0.5 * (0.7 * x).sin() + if x > 5.3 { 2.0 } else { 0.0 }
    }

    /// `∫ f(x − c)·L(x) dx / ∫ f(x − c) dx` over `[0, size)` for the pixel centred at `c`.
    fn expected_line(filter: FilterDesc, c: f64, size: u32) -> f64 {
        let n = size as usize * 8192;
        let h = f64::from(size) / n as f64;
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..n {
            let x = (i as f64 + 0.5) * h;
            let f = profile(filter, x - c);
            num += f * line(x);
            den += f;
        }
        num / den
    }

    /// Renders `passes` passes of the separable image `line(x)·line(y)` on a film, each pass's
    /// estimates exact at the rays' positions; returns the film and each pixel's per-pass
    /// values' sample variance. With `own`, every third pixel's estimate is the mean of three
    /// rays, one through the shared offset and two through offsets of their own
    /// ([`FilmSample`]s).
    fn splat_passes(
        filter: FilterDesc,
        (w, h): (u32, u32),
        passes: u32,
        own: bool,
    ) -> (Film, Vec<f64>) {
        let mut film = Film::new(w, h, filter).with_second_moment();
        let mut rng = restir_sampling::Pcg32::new(7, 3);
        let at = |i: usize, u: Vec2| {
            let (x, y) = ((i % w as usize) as f64, (i / w as usize) as f64);
            line(x + f64::from(u.x)) * line(y + f64::from(u.y))
        };
        for _ in 0..passes {
            let u = film.shared_offset(rng.next_2d());
            let extra: Vec<[Vec2; 2]> = (0..w * h)
                .map(|_| [rng.next_2d(), rng.next_2d()].map(|v| film.shared_offset(v)))
                .collect();
            film.add_pass(u, |_, samples, sums| {
                for (i, v) in sums.iter_mut().enumerate() {
                    if !(own && i % 3 == 0) {
                        *v += DVec3::splat(at(i, u));
                        continue;
                    }
                    *v += DVec3::splat(at(i, u) / 3.0);
                    samples.unwrap().add(extra[i].map(|offset| FilmSample {
                        pixel: i as u32,
                        offset,
                        value: Vec3::splat((at(i, offset) / 3.0) as f32),
                    }));
                }
            });
        }
        let m = film.moments().unwrap();
        // The second moment is kept in XYZ; Y of a grey pixel is its value.
        let var = (m.mean.iter().zip(&m.second))
            .map(|(mean, second)| (second.y - mean.y * mean.y).max(0.0))
            .collect();
        (film, var)
    }

    /// A splatting film's pixels converge to the filter-weighted radiance over the film, at the
    /// border too, within 4.5 standard errors, also where some estimates come from rays through
    /// offsets of their own; normalising by the filter's whole integral
    /// instead (ignoring the border) is caught.
    #[test]
    fn splatting_is_unbiased() {
        let (w, h) = (12, 9);
        let passes = 20_000;
        for (filter, own) in [
            (FilterDesc::Gaussian { stddev: 0.5 }, false),
            (FilterDesc::Tent { radius: 1.5 }, false),
            (FilterDesc::Gaussian { stddev: 0.5 }, true),
        ] {
            let (film, var) = splat_passes(filter, (w, h), passes, own);
            let image = film.image();
            let ex: Vec<f64> = (0..w)
                .map(|x| expected_line(filter, f64::from(x) + 0.5, w))
                .collect();
            let ey: Vec<f64> = (0..h)
                .map(|y| expected_line(filter, f64::from(y) + 0.5, h))
                .collect();
            let whole = pixel_integrals(filter, 0).0
                + (1..=2)
                    .map(|k| 2.0 * pixel_integrals(filter, k).0)
                    .sum::<f64>();
            let (mut worst, mut worst_control) = (0.0f64, 0.0f64);
            for (i, px) in image.pixels.iter().enumerate() {
                let (x, y) = (i % w as usize, i / w as usize);
                let se = (var[i] / f64::from(passes)).sqrt().max(1e-12);
                let z = (f64::from(px.x) - ex[x] * ey[y]).abs() / se;
                worst = worst.max(z);
                // The control: what the pixel would be with the film's inner normalisation.
                let inner = |p: usize, size: u32| {
                    let r = 2i64;
                    (-r..=r)
                        .filter(|k| (0..i64::from(size)).contains(&(p as i64 + k)))
                        .map(|k| pixel_integrals(filter, k as i32).0)
                        .sum::<f64>()
                };
                let control = f64::from(px.x) * inner(x, w) * inner(y, h) / (whole * whole);
                worst_control = worst_control.max((control - ex[x] * ey[y]).abs() / se);
            }
            assert!(worst < 4.5, "{filter:?}: max |z| {worst}");
            assert!(
                worst_control > 10.0,
                "{filter:?}: control max |z| {worst_control}"
            );
        }
    }

    /// Under constant radiance every pass gives the radiance, to 10⁻³, away from the border
    /// (where a pixel misses the estimates outside the film), for the Gaussian and for tents
    /// whose weights sum to a constant (radius 1) or not (radius 1.5); also where every pixel's
    /// estimate is the mean of four rays through offsets of their own that all pixels share
    /// ([`FilmSamples::offset`]; pixels with one ray and pixels with several sum to it only
    /// together). The control: offsets drawn uniformly, as before they were
    /// drawn by the weights they gather, leave more than 1 % for the Gaussian.
    #[test]
    fn constant_radiance_stays_noiseless() {
        let (w, h) = (13, 11);
        let mut rng = restir_sampling::Pcg32::new(1, 1);
        for filter in [
            FilterDesc::Tent { radius: 1.0 },
            FilterDesc::Tent { radius: 1.5 },
            FilterDesc::Gaussian { stddev: 0.5 },
        ] {
            let (mut worst, mut worst_control) = (0.0f32, 0.0f32);
            for pass in 0..64 {
                let own = pass % 2 == 1;
                let mut film = Film::new(w, h, filter);
                let v = rng.next_2d();
                let points: Vec<Vec2> = (0..4).map(|_| rng.next_2d()).collect();
                film.add_pass(film.shared_offset(v), |_, samples, sums| {
                    for (i, s) in sums.iter_mut().enumerate() {
                        if !own {
                            *s += DVec3::ONE;
                            continue;
                        }
                        // Four rays through the pass's offsets of their own.
                        let samples = samples.unwrap();
                        samples.add(points.iter().map(|&v| FilmSample {
                            pixel: i as u32,
                            offset: samples.offset(v),
                            value: Vec3::splat(0.25),
                        }));
                    }
                });
                let mut control = Film::new(w, h, filter);
                let u = v;
                let inverse = control.splat.as_ref().unwrap().offsets.inverse_density(u);
                control.add_pass(u, |_, _, sums| sums.fill(DVec3::splat(1.0 / inverse)));
                let reach = film.reconstruction().reach() as usize;
                let inner = |i: usize| {
                    let (x, y) = (i % w as usize, i / w as usize);
                    (reach..w as usize - reach).contains(&x)
                        && (reach..h as usize - reach).contains(&y)
                };
                for (i, (p, c)) in film
                    .image()
                    .pixels
                    .iter()
                    .zip(control.image().pixels)
                    .enumerate()
                {
                    if inner(i) {
                        worst = worst.max((p.x - 1.0).abs());
                        worst_control = worst_control.max((c.x - 1.0).abs());
                    }
                }
            }
            assert!(worst < 1e-3, "{filter:?}: {worst}");
            if matches!(filter, FilterDesc::Gaussian { .. }) {
                assert!(worst_control > 0.01, "control: {worst_control}");
            }
        }
    }

    /// A region's film gives the whole film's pixel values, bit for bit, on the pixels at
    /// least the filter's reach inside the region's edges (or at the film's).
    #[test]
    fn a_region_gives_the_whole_films_values() {
        let film = (40, 30);
        let filter = FilterDesc::Gaussian { stddev: 0.5 };
        let region = PixelWindow {
            x0: 16,
            y0: 0,
            width: 24,
            height: 16,
        };
        let value = |x: u32, y: u32| DVec3::new(f64::from(x * 31 + y * 7 % 13), 1.0, f64::from(y));
        let mut whole = Film::new(film.0, film.1, filter);
        let mut part = Film::new(region.width, region.height, filter);
        for u in [Vec2::new(0.1, 0.7), Vec2::new(0.9, 0.3)] {
            whole.add_pass(u, |_, _, sums| {
                for (i, v) in sums.iter_mut().enumerate() {
                    *v += value(i as u32 % film.0, i as u32 / film.0);
                }
            });
            part.add_pass(u, |_, _, sums| {
                for (i, v) in sums.iter_mut().enumerate() {
                    let (x, y) = (i as u32 % region.width, i as u32 / region.width);
                    *v += value(x + region.x0, y + region.y0);
                }
            });
        }
        let inner = PixelWindow {
            x0: 18,
            y0: 0,
            width: 22,
            height: 14,
        };
        let full = PixelWindow::full(film);
        assert_eq!(
            region.extract(&part.image(), &inner),
            full.extract(&whole.image(), &inner)
        );
    }

    /// The image is the per-pixel mean of the passes.
    #[test]
    fn film_averages_passes() {
        let mut film = Film::new(2, 1, FilterDesc::Box);
        assert_eq!(film.image().pixels, vec![glam::Vec3::ZERO; 2]);
        for v in [1.0, 2.0, 6.0] {
            film.add_pass(Vec2::ZERO, |_, _, sums| {
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
