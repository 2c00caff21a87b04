//! How a bitmap is read between and beyond its texels: Mitsuba 3's `bitmap` texture's
//! `filter_type` (`bilinear`, the default, or `nearest`) and `wrap_mode` (`repeat`, the default,
//! `mirror` or `clamp`), <https://mitsuba.readthedocs.io/en/latest/src/generated/plugins_textures.html#bitmap-texture-bitmap>.
//!
//! Texel `i` of an axis of `n` texels covers `[i, i + 1) / n`. Bilinear lookups blend the four
//! texels whose centres `(i + ½)/n` surround the point; nearest lookups take the texel that
//! covers it. Indices outside `0..n` are wrapped: `repeat` takes them modulo `n`, `mirror` reflects
//! the image at each of its edges (period `2n`: `n` maps to `n − 1`, `−1` to `0`), `clamp` takes
//! the nearest edge texel.

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

use super::Texels;

/// What a bitmap lookup outside `[0, 1)` reads (Mitsuba's `wrap_mode`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum WrapMode {
    /// The image repeats.
    #[default]
    Repeat,
    /// The image repeats mirrored at every edge.
    Mirror,
    /// The edge texels extend outwards.
    Clamp,
}

impl WrapMode {
    /// The names Mitsuba's `wrap_mode` takes, in the order of the variants.
    pub const NAMES: [&'static str; 3] = ["repeat", "mirror", "clamp"];

    /// The mode named `name` (Mitsuba's spelling), if any.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "repeat" => Some(Self::Repeat),
            "mirror" => Some(Self::Mirror),
            "clamp" => Some(Self::Clamp),
            _ => None,
        }
    }

    /// Mitsuba's name of the mode.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The texel index of whole-number coordinate `i` (a float) on an axis of `n` texels
    /// (non-finite coordinates read texel 0).
    #[inline]
    fn index(self, i: f32, n: usize) -> usize {
        let i = if i.is_finite() { i as i64 } else { 0 };
        let n = n as i64;
        let k = match self {
            WrapMode::Repeat => i.rem_euclid(n),
            WrapMode::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m >= n { 2 * n - 1 - m } else { m }
            }
            WrapMode::Clamp => i.clamp(0, n - 1),
        };
        k as usize
    }

    /// The texel indices of `i` and `i + 1`.
    #[inline]
    fn pair(self, i: f32, n: usize) -> (usize, usize) {
        match self {
            WrapMode::Repeat => wrap_pair(i, n),
            _ => (self.index(i, n), self.index(i + 1.0, n)),
        }
    }
}

/// How a bitmap is interpolated between texel centres (Mitsuba's `filter_type`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum FilterType {
    /// Bilinear interpolation of the four nearest texels.
    #[default]
    Bilinear,
    /// The texel the point falls in.
    Nearest,
}

impl FilterType {
    /// The names Mitsuba's `filter_type` takes, in the order of the variants.
    pub const NAMES: [&'static str; 2] = ["bilinear", "nearest"];

    /// The filter named `name` (Mitsuba's spelling), if any.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "bilinear" => Some(Self::Bilinear),
            "nearest" => Some(Self::Nearest),
            _ => None,
        }
    }

    /// Mitsuba's name of the filter.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

/// The value of a `width × height` bitmap at (already transformed) texture coordinates `p`.
#[inline]
pub(super) fn lookup(
    texels: &Texels,
    (width, height): (usize, usize),
    p: Vec2,
    wrap: WrapMode,
    filter: FilterType,
) -> Vec3 {
    match filter {
        FilterType::Bilinear => {
            // Texel centres at (i + ½)/size.
            let x = p.x * width as f32 - 0.5;
            let y = p.y * height as f32 - 0.5;
            let (x0, y0) = (x.floor(), y.floor());
            let (fx, fy) = (x - x0, y - y0);
            let (xa, xb) = wrap.pair(x0, width);
            let (ya, yb) = wrap.pair(y0, height);
            let (ra, rb) = (ya * width, yb * width);
            let at = |i: usize| texels.get(i);
            let top = at(ra + xa) * (1.0 - fx) + at(ra + xb) * fx;
            let bottom = at(rb + xa) * (1.0 - fx) + at(rb + xb) * fx;
            top * (1.0 - fy) + bottom * fy
        }
        FilterType::Nearest => {
            let x = wrap.index((p.x * width as f32).floor(), width);
            let y = wrap.index((p.y * height as f32).floor(), height);
            texels.get(y * width + x)
        }
    }
}

/// The gradient in `(x, y)` (texture coordinates, already transformed) of the scalar (luminance)
/// lookup of a `width × height` bitmap at `p`, as Mitsuba's `eval_1_grad`: the derivative of the
/// bilinear interpolation of the four texels around `p`, zero for a nearest-neighbour lookup.
#[inline]
pub(super) fn lookup_grad(
    texels: &Texels,
    (width, height): (usize, usize),
    p: Vec2,
    wrap: WrapMode,
    filter: FilterType,
) -> Vec2 {
    if filter == FilterType::Nearest {
        return Vec2::ZERO;
    }
    let x = p.x * width as f32 - 0.5;
    let y = p.y * height as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (xa, xb) = wrap.pair(x0, width);
    let (ya, yb) = wrap.pair(y0, height);
    let (ra, rb) = (ya * width, yb * width);
    let at = |i: usize| restir_sampling::luminance(texels.get(i));
    let (f00, f10, f01, f11) = (at(ra + xa), at(ra + xb), at(rb + xa), at(rb + xb));
    let dx = (1.0 - fy) * (f10 - f00) + fy * (f11 - f01);
    let dy = (1.0 - fx) * (f01 - f00) + fx * (f11 - f10);
    Vec2::new(dx * width as f32, dy * height as f32)
}

/// The texel indices of whole-number coordinates `i` and `i + 1` (as floats) on an axis of `n`
/// texels, repeating (non-finite coordinates read texel 0). The integer remainder, a division,
/// only when `i` lies outside the image.
#[inline]
fn wrap_pair(i: f32, n: usize) -> (usize, usize) {
    let wrap = |i: f32| -> usize {
        let n = n as i64;
        let i = if i.is_finite() { i as i64 } else { 0 };
        if (0..n).contains(&i) {
            i as usize
        } else {
            i.rem_euclid(n) as usize
        }
    };
    let a = wrap(i);
    // `i + 1` is the next texel unless it rounds back to `i` (|i| ≥ 2²⁴) or is not finite.
    let b = if i.is_finite() && i + 1.0 != i {
        if a + 1 == n { 0 } else { a + 1 }
    } else {
        wrap(i + 1.0)
    };
    (a, b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `wrap_pair` gives the texels the lookup read before it (each coordinate wrapped by its
    /// own remainder), at the edges, outside the image, at huge and non-finite coordinates.
    #[test]
    fn wrap_pair_is_the_remainder_of_each_coordinate() {
        let wrap = |i: f32, n: usize| -> usize {
            let i = if i.is_finite() { i as i64 } else { 0 };
            i.rem_euclid(n as i64) as usize
        };
        let values = [
            0.0,
            -0.0,
            1.0,
            2.0,
            3.0,
            4.0,
            -1.0,
            -2.0,
            -5.0,
            17.0,
            -17.0,
            16_777_215.0,
            16_777_216.0,
            -16_777_216.0,
            3.0e9,
            -3.0e9,
            1.0e20,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        for n in [1, 2, 3, 4, 7] {
            for &i in &values {
                assert_eq!(
                    wrap_pair(i, n),
                    (wrap(i, n), wrap(i + 1.0, n)),
                    "{i} of {n}"
                );
            }
        }
    }

    /// Mirror reflects at each edge with period `2n`; clamp holds the edge texels.
    #[test]
    fn mirror_and_clamp_indices() {
        let n = 3;
        let mirror: Vec<usize> = (-7..8)
            .map(|i| WrapMode::Mirror.index(i as f32, n))
            .collect();
        assert_eq!(mirror, [0, 0, 1, 2, 2, 1, 0, 0, 1, 2, 2, 1, 0, 0, 1]);
        let clamp: Vec<usize> = (-2..5)
            .map(|i| WrapMode::Clamp.index(i as f32, n))
            .collect();
        assert_eq!(clamp, [0, 0, 0, 1, 2, 2, 2]);
        for mode in [WrapMode::Mirror, WrapMode::Clamp, WrapMode::Repeat] {
            for i in [f32::NAN, f32::INFINITY, f32::MAX, f32::MIN, -3.0e9] {
                assert!(mode.index(i, n) < n, "{mode:?} {i}");
            }
        }
    }

    /// Names read back to their variants.
    #[test]
    fn names_round_trip() {
        for m in [WrapMode::Repeat, WrapMode::Mirror, WrapMode::Clamp] {
            assert_eq!(WrapMode::from_name(m.name()), Some(m));
        }
        for f in [FilterType::Bilinear, FilterType::Nearest] {
            assert_eq!(FilterType::from_name(f.name()), Some(f));
        }
        assert_eq!(WrapMode::from_name("border"), None);
    }
}
