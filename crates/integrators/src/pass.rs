//! One pass of an estimator: what it is told ([`PassContext`]: seed, pass index, pixel filter,
//! and the window of the film it renders when a render is split, [`PixelWindow`]) and what it
//! is ([`Integrator`]). The render loop (`render.rs`), the reuse passes (`reuse/`) and every
//! estimator stand on this file.

use std::sync::Arc;

use glam::{DVec3, Vec2};
use restir_reuse::{SeededStreams, Streams};
use restir_sampling::{OwenSobol, Pcg32, Sampler, mix64};
use restir_scene::Scene;

use crate::Image;
use crate::film::Filter;
use crate::motion::FrameMotion;

/// The pass stream of the film's shared offset ([`PassContext::shared_offset_of`]).
const STAGE_FILM: u64 = 0xF11E;

/// The pass stream of the scramble of the film's extra camera rays
/// ([`PassContext::film_ray_points`]).
const STAGE_FILM_RAYS: u64 = 0xF11F;

/// Separates the pixel sequences' scrambles from the random streams of the same seed.
const SEQUENCE_SALT: u64 = 0x50B0_1000_5EED;

/// What an integrator needs to know about the current pass.
#[derive(Debug)]
pub struct PassContext<'a> {
    /// The render's seed.
    pub seed: u64,
    /// Index of this pass (0-based).
    pub pass: u32,
    /// The pixel filter, for jittering camera rays.
    pub filter: &'a Filter,
    /// Where within its pixel every camera ray of the pass goes, when the film splats
    /// (`restir_integrators::film::Reconstruction`; drawn by [`crate::film::Film::shared_offset`]);
    /// `None`: each ray samples `filter`.
    pub shared_offset: Option<Vec2>,
    /// Where the pass may put estimates of camera rays through offsets of their own
    /// ([`crate::film::FilmSample`]), when the film splats; `None` if it may not (every ray then
    /// goes through `shared_offset`).
    pub samples: Option<&'a crate::film::FilmSamples>,
    /// The part of the film this pass renders, if not all of it: pixel indices and coordinates
    /// the integrator sees are then the region's, and the random streams and camera rays are
    /// those of the same pixels in the whole film.
    pub crop: Option<Crop>,
}

/// A rectangle of film pixels: columns `x0..x0 + width`, rows `y0..y0 + height`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PixelWindow {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
}

/// Rendered regions of a cropped render start and end on multiples of this many pixels (or at
/// the film's edge), so that ReSTIR DI's 16×16 light tiles are the whole film's tiles.
pub const CROP_ALIGN: u32 = 16;

impl PixelWindow {
    /// The whole of a `width × height` film.
    pub fn full((width, height): (u32, u32)) -> Self {
        Self {
            x0: 0,
            y0: 0,
            width,
            height,
        }
    }

    /// One past the last column and row.
    pub fn end(&self) -> (u32, u32) {
        (self.x0 + self.width, self.y0 + self.height)
    }

    /// Pixels in the window.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Whether the window is non-empty and lies inside a film of `(width, height)`.
    pub fn fits(&self, (width, height): (u32, u32)) -> bool {
        self.width > 0
            && self.height > 0
            && u64::from(self.x0) + u64::from(self.width) <= u64::from(width)
            && u64::from(self.y0) + u64::from(self.height) <= u64::from(height)
    }

    /// The region to render for this window: grown by `halo` pixels on every side, its edges
    /// then moved out to multiples of [`CROP_ALIGN`], all clipped to the `film`.
    pub fn with_halo(&self, halo: u32, film: (u32, u32)) -> Self {
        let (x1, y1) = self.end();
        let down = |v: u32| v.saturating_sub(halo) / CROP_ALIGN * CROP_ALIGN;
        let up = |v: u32, max: u32| {
            v.saturating_add(halo)
                .div_ceil(CROP_ALIGN)
                .saturating_mul(CROP_ALIGN)
                .min(max)
        };
        let (x0, y0) = (down(self.x0), down(self.y0));
        let (x1, y1) = (up(x1, film.0), up(y1, film.1));
        Self {
            x0,
            y0,
            width: x1 - x0,
            height: y1 - y0,
        }
    }

    /// The pixels of `inner` (a window inside this one, both in film coordinates) out of
    /// `image`, this window's pixels, row-major.
    pub fn extract(&self, image: &Image, inner: &PixelWindow) -> Image {
        Image {
            width: inner.width,
            height: inner.height,
            pixels: self.extract_values(&image.pixels, inner),
        }
    }

    /// [`PixelWindow::extract`] of any per-pixel values, row-major over this window.
    pub fn extract_values<T: Copy>(&self, values: &[T], inner: &PixelWindow) -> Vec<T> {
        let (dx, dy) = ((inner.x0 - self.x0) as usize, (inner.y0 - self.y0) as usize);
        let w = self.width as usize;
        (0..inner.height as usize)
            .flat_map(|y| {
                let row = (dy + y) * w + dx;
                values[row..row + inner.width as usize].iter().copied()
            })
            .collect()
    }
}

/// Where a cropped pass sits in the film.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    /// The region rendered.
    pub region: PixelWindow,
    /// The whole film's width.
    pub film_width: u32,
}

impl PassContext<'_> {
    /// The `(width, height)` of the pixels this pass renders: the film's, or the crop region's.
    #[inline]
    pub fn resolution(&self, scene: &Scene) -> (u32, u32) {
        match &self.crop {
            None => scene.camera.resolution(),
            Some(c) => (c.region.width, c.region.height),
        }
    }

    /// The film's index of pixel `index` of this pass.
    #[inline]
    fn film_index(&self, index: usize) -> u64 {
        match &self.crop {
            None => index as u64,
            Some(c) => {
                let w = c.region.width as usize;
                let (x, y) = (
                    index % w + c.region.x0 as usize,
                    index / w + c.region.y0 as usize,
                );
                (y * c.film_width as usize + x) as u64
            }
        }
    }

    /// The seed and pass as the reuse passes' streams see them.
    #[inline]
    fn streams(&self) -> SeededStreams {
        SeededStreams {
            seed: self.seed,
            pass: self.pass,
        }
    }

    /// The random stream of pixel `index` in this pass, the same whatever thread renders it.
    #[inline]
    pub fn pixel_rng(&self, index: usize) -> Pcg32 {
        self.stage_rng(index, 0)
    }

    /// Pixel `index`'s sample of this pass from its own Owen-scrambled Sobol sequence (the
    /// pass is the sample's index): the alternative to [`PassContext::pixel_rng`] when a scene
    /// asks for stratified samples. The scrambles depend on the seed and the film pixel only.
    #[inline]
    pub fn pixel_sequence(&self, index: usize) -> OwenSobol {
        let seed = mix64(mix64(self.seed ^ SEQUENCE_SALT) ^ self.film_index(index));
        OwenSobol::new(seed, self.pass)
    }

    /// A second, independent stream of pixel `index` in this pass, for estimator stage `stage`
    /// (stage 0 is [`PassContext::pixel_rng`]'s stream).
    #[inline]
    pub fn stage_rng(&self, index: usize, stage: u64) -> Pcg32 {
        self.streams().pixel(self.film_index(index) as usize, stage)
    }

    /// A stream of the whole pass for estimator stage `stage`: the same for every pixel, and for
    /// every crop of the film (choices made once per pass, like shared neighbour offsets).
    #[inline]
    pub fn pass_rng(&self, stage: u64) -> Pcg32 {
        self.streams().pass(stage)
    }

    /// Stream `stream` of the whole pass for estimator stage `stage`, one of many (one per tile
    /// of a pool drawn once per pass, say): like [`PassContext::pass_rng`], the same for every
    /// pixel and every crop.
    #[inline]
    pub fn pass_stream(&self, stage: u64, stream: u64) -> Pcg32 {
        self.streams().pass_stream(stage, stream)
    }

    /// The film coordinates of pixel `index` of this pass's buffers, which are `width` pixels
    /// wide (the film's, or the crop region's).
    #[inline]
    pub fn film_xy(&self, index: usize, width: usize) -> (u32, u32) {
        let (x, y) = ((index % width) as u32, (index / width) as u32);
        match &self.crop {
            None => (x, y),
            Some(c) => (x + c.region.x0, y + c.region.y0),
        }
    }

    /// The film position (pixel units) of the camera ray through pixel `(x, y)` of this pass:
    /// jittered by the filter, or at the pass's shared offset. Draws two numbers from `rng`
    /// either way.
    #[inline]
    pub fn film_position<S: Sampler>(&self, x: u32, y: u32, rng: &mut S) -> Vec2 {
        let (x, y) = match &self.crop {
            None => (x, y),
            Some(c) => (x + c.region.x0, y + c.region.y0),
        };
        let u = rng.next_2d();
        match self.shared_offset {
            None => Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + self.filter.sample(u),
            Some(offset) => Vec2::new(x as f32, y as f32) + offset,
        }
    }

    /// The film position of pixel `index`'s own camera ray in this pass (pixel `(x, y)` of the
    /// pass's buffers): [`PassContext::film_position`] with the numbers of the pixel's
    /// Owen-scrambled Sobol sequence at this pass (its first two dimensions), so that over the
    /// passes a pixel's camera rays are stratified over its filter, whatever sampler draws the
    /// estimator's other numbers. Still draws two numbers from `rng` (the budget of the
    /// pixel's stream is unchanged); with a pixel sequence as `rng` the position is the same.
    #[inline]
    pub fn pixel_film_position<S: Sampler>(
        &self,
        index: usize,
        (x, y): (u32, u32),
        rng: &mut S,
    ) -> Vec2 {
        let _ = rng.next_2d();
        self.film_position(x, y, &mut self.pixel_sequence(index))
    }

    /// The uniform point from which a splatting film draws the position within their pixels
    /// that every camera ray of pass `pass` of a render with seed `seed` goes through
    /// ([`crate::film::Film::shared_offset`]): point `pass` of a (0, 2)-sequence Owen-scrambled
    /// by the seed, so each pass's point is uniform in `[0, 1)²` and those of the first `2^k`
    /// passes are stratified over the pixel (the film's map keeps that, axis by axis); the same
    /// in every part of a split render.
    pub fn shared_offset_of(seed: u64, pass: u32) -> Vec2 {
        OwenSobol::new(Self::film_scramble(seed, STAGE_FILM), pass).next_2d()
    }

    /// The scramble of a film sequence of the render with seed `seed`, one per `stage`: the
    /// same for every pass and in every part of a split render.
    fn film_scramble(seed: u64, stage: u64) -> u64 {
        let mut rng = SeededStreams { seed, pass: 0 }.pass(stage);
        u64::from(rng.next_u32()) << 32 | u64::from(rng.next_u32())
    }

    /// The uniform points from which a splatting film draws the offsets of `n` more camera
    /// rays per pixel in this pass, each shared by every pixel that takes them
    /// ([`crate::film::FilmSamples::offset`]): points `n·pass` to `n·pass + n − 1` of a
    /// (0, 2)-sequence Owen-scrambled by the seed (not the shared offsets' sequence). Each is
    /// uniform, those of one pass cover the pixel evenly, and those of the first passes together
    /// are the sequence's first points: stratified over the pixel as one sequence of `n` times
    /// the passes (when `n` and the pass count are powers of two, a (0, m, 2)-net); the same in
    /// every part of a split render.
    pub fn film_ray_points(&self, n: u32) -> Vec<Vec2> {
        let scramble = Self::film_scramble(self.seed, STAGE_FILM_RAYS);
        let first = self.pass.wrapping_mul(n);
        (0..n)
            .map(|j| OwenSobol::new(scramble, first.wrapping_add(j)).next_2d())
            .collect()
    }
}

/// An estimator that renders whole passes.
pub trait Integrator: Sync + Send + std::fmt::Debug {
    /// The command-line name of the estimator that renders (for `auto`, the one it chose).
    fn name(&self) -> &'static str;
    /// Renders one pass, adding one estimate per pixel to `accum` (row-major). Returns the number
    /// of rays traced.
    fn render_pass(&self, scene: &Scene, ctx: &PassContext, accum: &mut [DVec3]) -> u64;
    /// The estimator's settings in one line, for logs and statistics.
    fn describe(&self) -> String {
        self.name().to_string()
    }
    /// Bytes of the per-pass buffers the estimator keeps besides the image (reservoirs, primary
    /// hits, tables of shifts) for a film of `width × height` pixels rendered on `threads`
    /// threads, at most.
    fn buffer_bytes(&self, width: u32, height: u32, threads: usize) -> u64 {
        let _ = (width, height, threads);
        0
    }
    /// How far, in pixels, a pixel's estimate in one pass reaches for other pixels' samples
    /// (spatial reuse: rounds × radius): the halo a cropped render needs around its window.
    fn halo(&self) -> u32 {
        0
    }
    /// Wall seconds spent in each stage of the passes so far, in the order the stages run
    /// (empty for an estimator without stages, like the path tracer).
    fn stage_seconds(&self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
    /// The passes that follow render the next frame of a sequence, which moved from the frame
    /// of the passes before as `motion` says. An estimator that keeps samples between passes
    /// (temporal reuse) shifts them across the frames with it, or forgets them; the default
    /// keeps nothing, so it does nothing.
    fn next_frame(&self, motion: Arc<FrameMotion>) {
        let _ = motion;
    }
    /// What the estimator learned across the passes so far and decided from it, one line
    /// (`None`, the default, for an estimator that learns nothing).
    fn learned(&self) -> Option<String> {
        None
    }
    /// What the estimator decided about the emitter silhouettes in view (pixels that get more
    /// camera rays for the emission they see, and how many), one line; `None` (the default)
    /// when it decides nothing of the kind.
    fn silhouettes(&self) -> Option<String> {
        None
    }
    /// How the estimator cut the light hierarchy for screen tiles in its last pass (ReSTIR DI
    /// with `light_sampler = tiles`), one line; `None` (the default) when it does not.
    fn light_cuts(&self) -> Option<String> {
        None
    }
    /// What the estimator runs in SIMD lanes for `scene` (the path tracer: how many paths at a
    /// time, with which instructions, on which of the scene's shapes), one line; `None` (the
    /// default) when it runs nothing in lanes.
    fn lanes(&self, scene: &Scene) -> Option<String> {
        let _ = scene;
        None
    }
    /// Why this estimator renders when the `auto` estimator chose it (what its rules measured
    /// of the scene, one line); `None` (the default) when it was asked for by name.
    fn auto_choice(&self) -> Option<&str> {
        None
    }
}

/// The reuse passes draw from the pass's streams, pixel indices of a cropped render mapped to the
/// film's.
impl Streams for PassContext<'_> {
    #[inline]
    fn pixel(&self, index: usize, stage: u64) -> Pcg32 {
        self.stage_rng(index, stage)
    }

    #[inline]
    fn pass(&self, stage: u64) -> Pcg32 {
        self.pass_rng(stage)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn win(x0: u32, y0: u32, x1: u32, y1: u32) -> PixelWindow {
        PixelWindow {
            x0,
            y0,
            width: x1 - x0,
            height: y1 - y0,
        }
    }

    /// Cell of `p` (in `[0, 1)²`) on an `nx × ny` grid.
    fn cell(p: Vec2, nx: usize, ny: usize) -> usize {
        ((p.x * nx as f32) as usize).min(nx - 1) + nx * ((p.y * ny as f32) as usize).min(ny - 1)
    }

    /// The splatting film's shared offsets: the first 4 and 16 passes of every seed fill every
    /// elementary interval of their count once (a (0, 2)-sequence), and a fixed pass's offset is
    /// uniform over seeds (chi-square on 8×8 cells). The control: offsets drawn twice as dense
    /// towards one corner are rejected by the same chi-square.
    #[test]
    fn shared_offsets_are_uniform_and_stratified_over_passes() {
        for seed in 0..200u64 {
            for k in [2u32, 4] {
                let n = 1usize << k;
                let points: Vec<Vec2> = (0..n as u32)
                    .map(|pass| PassContext::shared_offset_of(seed, pass))
                    .collect();
                for a in 0..=k {
                    let (nx, ny) = (1usize << a, 1usize << (k - a));
                    let mut seen = vec![false; n];
                    for &p in &points {
                        assert!(!std::mem::replace(&mut seen[cell(p, nx, ny)], true));
                    }
                }
            }
        }
        let histogram = |warp: fn(Vec2) -> Vec2| {
            let mut h = restir_testkit::Histogram::new(64);
            for seed in 0..20_000u64 {
                h.record(Some(cell(
                    warp(PassContext::shared_offset_of(seed, 3)),
                    8,
                    8,
                )));
            }
            h.chi2(&[1.0 / 64.0; 64]).unwrap()
        };
        let uniform = histogram(|p| p);
        assert!(uniform.accepts(1e-3), "{uniform}");
        let skewed = histogram(|p| p * p);
        assert!(!skewed.accepts(1e-3), "the control passed: {skewed}");
    }

    /// The film's extra rays: with 4 rays per pass, each pass's 4 points fill every elementary
    /// interval of 4 cells once, and those of 4 passes every interval of 16 cells, for 200
    /// seeds; the control, the first ray of each of the 4 passes, does not for most seeds.
    #[test]
    fn film_ray_points_are_stratified_over_passes() {
        let filter = Filter::Box;
        let points = |seed: u64, pass: u32| {
            PassContext {
                seed,
                pass,
                filter: &filter,
                shared_offset: None,
                samples: None,
                crop: None,
            }
            .film_ray_points(4)
        };
        let fills = |points: &[Vec2], k: usize| {
            (0..=k).all(|a| {
                let (nx, ny) = (1usize << a, 1usize << (k - a));
                let mut seen = vec![false; 1 << k];
                points
                    .iter()
                    .all(|&p| !std::mem::replace(&mut seen[cell(p, nx, ny)], true))
            })
        };
        let mut control_fails = 0;
        for seed in 0..200u64 {
            let all: Vec<Vec<Vec2>> = (0..4).map(|pass| points(seed, pass)).collect();
            for pass in &all {
                assert!(fills(pass, 2), "seed {seed}: {pass:?}");
            }
            assert!(fills(&all.concat(), 4), "seed {seed}");
            let swapped: Vec<Vec2> = (0..4).map(|j| all[j][0]).collect();
            control_fails += usize::from(!fills(&swapped, 2));
        }
        assert!(
            control_fails > 100,
            "the control filled the cells: {control_fails}"
        );
    }

    /// A pixel's own camera rays over the passes are stratified over its box filter (one in each
    /// quadrant in the first 4 passes) whatever stream draws the pass's other numbers, and the
    /// stream's budget is unchanged (it is where it would be after `film_position`).
    #[test]
    fn pixel_film_positions_are_stratified_over_passes() {
        let filter = Filter::Box;
        for index in [0usize, 7, 1234] {
            let (x, y) = (index as u32 % 100, index as u32 / 100);
            let mut seen = [false; 4];
            for pass in 0..4 {
                let ctx = PassContext {
                    seed: 5,
                    pass,
                    filter: &filter,
                    shared_offset: None,
                    samples: None,
                    crop: None,
                };
                let mut rng = ctx.pixel_rng(index);
                let p = ctx.pixel_film_position(index, (x, y), &mut rng);
                let within = p - Vec2::new(x as f32, y as f32);
                assert!(!std::mem::replace(&mut seen[cell(within, 2, 2)], true));
                let mut other = ctx.pixel_rng(index);
                let _ = ctx.film_position(x, y, &mut other);
                assert_eq!(rng.next_u32(), other.next_u32());
            }
        }
    }

    /// The region grows by the halo, moves out to multiples of 16 and stops at the film.
    #[test]
    fn region_with_halo() {
        let film = (100, 70);
        assert_eq!(win(20, 40, 50, 50).with_halo(0, film), win(16, 32, 64, 64));
        assert_eq!(win(20, 40, 50, 50).with_halo(5, film), win(0, 32, 64, 64));
        assert_eq!(win(32, 32, 48, 48).with_halo(0, film), win(32, 32, 48, 48));
        assert_eq!(win(32, 32, 48, 48).with_halo(1, film), win(16, 16, 64, 64));
        assert_eq!(
            win(90, 60, 100, 70).with_halo(8, film),
            win(80, 48, 100, 70)
        );
        assert_eq!(win(0, 0, 100, 70).with_halo(30, film), win(0, 0, 100, 70));
        assert!(win(0, 0, 100, 70).fits(film) && !win(1, 0, 101, 70).fits(film));
    }

    /// `extract` cuts an inner window out of a region's pixels.
    #[test]
    fn extract_window() {
        let region = win(2, 3, 6, 6);
        let image = Image {
            width: 4,
            height: 3,
            pixels: (0..12).map(|i| glam::Vec3::splat(i as f32)).collect(),
        };
        let inner = region.extract(&image, &win(3, 4, 5, 6));
        assert_eq!((inner.width, inner.height), (2, 2));
        let v: Vec<f32> = inner.pixels.iter().map(|p| p.x).collect();
        assert_eq!(v, [5.0, 6.0, 9.0, 10.0]);
    }
}
