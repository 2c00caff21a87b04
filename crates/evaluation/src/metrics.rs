//! Error metrics beyond `restir-image`'s relMSE that rendering papers report: MAPE on linear
//! values and FLIP on tone-mapped images, gathered with relMSE, MSE and the mean ratio in
//! [`Metrics`] by [`evaluate`] (the one function `restir bench` and `restir compare` call).
//!
//! - **MAPE**: mean over finite pixels and RGB channels of `|x − r| / (|r| + 0.01)`, the mean
//!   absolute percentage error with the same small offset as relMSE's `r² + 0.01` keeps for black
//!   reference pixels (here `0.01` on the magnitude, so dark pixels weigh less than in relMSE).
//! - **FLIP** (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating Images"):
//!   LDR-FLIP through the `nv-flip` crate, which compiles NVIDIA's reference C++ implementation.
//!   Both images are tone-mapped as `restir render -o x.png` writes them — clamped to [0, 1] and
//!   sRGB-encoded to 8 bits (NaN and infinities become 0) — and compared at FLIP's default
//!   67.02 pixels per degree (a 0.7 m wide 4K monitor seen from 0.7 m). [`Metrics::flip`] is the
//!   mean of the per-pixel FLIP map, in [0, 1]; [`flip_map`] returns the map itself.
//! - **Top-1 % share**: the share of the squared error (the sum over pixels of MSE's per-pixel
//!   terms) held by the 1 % of pixels with the largest squared error ([`top_share`]). Noise
//!   spread evenly gives a few percent; an image whose error sits in blotches or fireflies gives
//!   most of it. MSE counts those pixels fully, relMSE divides them by their reference.

use restir_image::{Image, compare, srgb};

/// Every metric of a test image against a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// Mean of `(x − r)² / (r² + 0.01)` (see `restir_image::ErrorMetrics`).
    pub relmse: f64,
    /// Mean of `(x − r)²`.
    pub mse: f64,
    /// Mean of `|x − r| / (|r| + 0.01)` (see the module documentation).
    pub mape: f64,
    /// Mean LDR-FLIP error of the tone-mapped images, in [0, 1].
    pub flip: f64,
    /// Mean of the test image over mean of the reference.
    pub mean_ratio: f64,
    /// Share of the squared error in the 1 % of pixels with the most ([`top_share`]).
    pub top1_share: f64,
    /// Pixels of the test image with a NaN or infinite channel (left out of relMSE, MSE, MAPE).
    pub nonfinite: usize,
    /// Pixels of the reference with a NaN or infinite channel (left out likewise).
    pub reference_nonfinite: usize,
}

/// Offset of MAPE's denominator.
pub const MAPE_EPSILON: f64 = 0.01;

/// MAPE of `test` against `reference` over the pixels whose channels are all finite in both
/// images (NaN when there are none); `None` if the sizes differ.
pub fn mape(test: &Image, reference: &Image) -> Option<f64> {
    if (test.width, test.height) != (reference.width, reference.height) {
        return None;
    }
    let (mut sum, mut n) = (0.0f64, 0usize);
    for (x, r) in test.pixels.iter().zip(&reference.pixels) {
        if !(x.is_finite() && r.is_finite()) {
            continue;
        }
        for c in 0..3 {
            let (xv, rv) = (x[c] as f64, r[c] as f64);
            sum += (xv - rv).abs() / (rv.abs() + MAPE_EPSILON);
        }
        n += 3;
    }
    Some(sum / n as f64)
}

/// The image as 8-bit sRGB RGB triples, row by row: clamped to [0, 1], NaN and infinities as 0
/// (what `Image::write` puts into a PNG).
pub fn tonemap_srgb8(image: &Image) -> Vec<u8> {
    image
        .pixels
        .iter()
        .flat_map(|p| {
            [
                srgb::encode_u8(p.x),
                srgb::encode_u8(p.y),
                srgb::encode_u8(p.z),
            ]
        })
        .collect()
}

/// The per-pixel LDR-FLIP error of `test` against `reference` (row-major, each in [0, 1]),
/// both tone-mapped by [`tonemap_srgb8`]; `None` if the sizes differ or the images are empty.
pub fn flip_map(test: &Image, reference: &Image) -> Option<Vec<f32>> {
    let (w, h) = (test.width, test.height);
    if (w, h) != (reference.width, reference.height) || w == 0 || h == 0 {
        return None;
    }
    let r = nv_flip::FlipImageRgb8::with_data(w, h, &tonemap_srgb8(reference));
    let t = nv_flip::FlipImageRgb8::with_data(w, h, &tonemap_srgb8(test));
    Some(nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE).to_vec())
}

/// Mean of a FLIP map.
pub fn mean(map: &[f32]) -> f64 {
    map.iter().map(|&v| v as f64).sum::<f64>() / map.len().max(1) as f64
}

/// Per-pixel squared error, the mean over RGB of `(x − r)²` (MSE's terms), NaN where a channel
/// of either image is not finite; `None` if the sizes differ.
pub fn squared_errors(test: &Image, reference: &Image) -> Option<Vec<f64>> {
    if (test.width, test.height) != (reference.width, reference.height) {
        return None;
    }
    Some(
        test.pixels
            .iter()
            .zip(&reference.pixels)
            .map(|(x, r)| {
                if !(x.is_finite() && r.is_finite()) {
                    return f64::NAN;
                }
                (0..3)
                    .map(|c| (f64::from(x[c]) - f64::from(r[c])).powi(2))
                    .sum::<f64>()
                    / 3.0
            })
            .collect(),
    )
}

/// The share of the total of `errors` (NaN entries left out) held by its `fraction` largest
/// entries (at least one): 1 for an error in one pixel, `fraction` for an error spread evenly.
/// NaN when nothing is finite or the total is 0.
pub fn top_share(errors: &[f64], fraction: f64) -> f64 {
    let mut e: Vec<f64> = errors.iter().copied().filter(|v| v.is_finite()).collect();
    let total: f64 = e.iter().sum();
    if e.is_empty() || total <= 0.0 {
        return f64::NAN;
    }
    let n = ((e.len() as f64 * fraction).ceil() as usize).clamp(1, e.len());
    e.select_nth_unstable_by(n - 1, |a, b| b.total_cmp(a));
    e[..n].iter().sum::<f64>() / total
}

/// All metrics of `test` against `reference`; `None` if their sizes differ.
pub fn evaluate(test: &Image, reference: &Image) -> Option<Metrics> {
    let m = compare(test, reference)?;
    // No pixel finite in both images: nothing was compared, so no FLIP either (the tone mapping
    // would turn NaN into black and score black against black as a match).
    let flip = if m.mse.is_nan() {
        f64::NAN
    } else {
        flip_map(test, reference).map_or(f64::NAN, |map| mean(&map))
    };
    Some(Metrics {
        relmse: m.relmse,
        mse: m.mse,
        mape: mape(test, reference)?,
        flip,
        mean_ratio: m.mean_ratio,
        top1_share: top_share(&squared_errors(test, reference)?, 0.01),
        nonfinite: m.nonfinite,
        reference_nonfinite: m.reference_nonfinite,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn top_share_of_spread_and_concentrated_error() {
        let even = vec![1.0; 1000];
        assert!((top_share(&even, 0.01) - 0.01).abs() < 1e-12);
        let mut one = vec![0.0; 1000];
        one[17] = 5.0;
        assert_eq!(top_share(&one, 0.01), 1.0);
        // 10 of 1000 entries: the 10 largest of 1..=1000 over their sum.
        let rising: Vec<f64> = (1..=1000).map(f64::from).chain([f64::NAN]).collect();
        let expected = (991..=1000).sum::<i32>() as f64 / 500_500.0;
        assert!((top_share(&rising, 0.01) - expected).abs() < 1e-12);
        assert!(top_share(&[0.0, 0.0], 0.01).is_nan());
        let (r, mut t) = (ramp(8, 8), ramp(8, 8));
        t.pixels[3] += Vec3::splat(1.0);
        let m = evaluate(&t, &r).unwrap();
        assert_eq!(m.top1_share, 1.0);
    }

    fn ramp(w: u32, h: u32) -> Image {
        let mut img = Image::new(w, h);
        for y in 0..h {
            for x in 0..w {
                img.pixels[(y * w + x) as usize] = Vec3::new(
                    x as f32 / w as f32,
                    y as f32 / h as f32,
                    0.5 * (x + y) as f32 / (w + h) as f32,
                );
            }
        }
        img
    }

    /// Deterministic noise of amplitude `a` (a small LCG, fixed seed).
    fn noisy(img: &Image, a: f32) -> Image {
        let mut s = 0x2545_f491u32;
        let mut out = img.clone();
        for p in &mut out.pixels {
            for c in 0..3 {
                s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                let u = (s >> 8) as f32 / (1u32 << 24) as f32 - 0.5;
                p[c] = (p[c] + a * u).max(0.0);
            }
        }
        out
    }

    #[test]
    fn mape_known_values() {
        let mut a = Image::new(2, 1);
        let mut b = Image::new(2, 1);
        a.pixels = vec![Vec3::splat(1.0), Vec3::splat(0.0)];
        b.pixels = vec![Vec3::splat(0.5), Vec3::splat(0.0)];
        // (0.5 / 0.51 · 3 + 0) / 6.
        assert!((mape(&a, &b).unwrap() - 0.5 / 0.51 / 2.0).abs() < 1e-12);
        a.pixels[1] = Vec3::new(f32::NAN, 0.0, 0.0);
        assert!((mape(&a, &b).unwrap() - 0.5 / 0.51).abs() < 1e-12);
        assert!(mape(&Image::new(1, 1), &b).is_none());
        // NaN in the reference is left out the same way; nothing left is NaN, not 0.
        assert!((mape(&b, &a).unwrap() - 0.5 / 1.01).abs() < 1e-12);
        let nan = Image {
            pixels: vec![Vec3::NAN; 2],
            ..Image::new(2, 1)
        };
        assert!(mape(&nan, &b).unwrap().is_nan());
        let m = evaluate(&nan, &Image::new(2, 1)).unwrap();
        assert!(
            m.relmse.is_nan() && m.mape.is_nan() && m.flip.is_nan(),
            "{m:?}"
        );
        assert_eq!((m.nonfinite, m.reference_nonfinite), (2, 0));
        assert_eq!(evaluate(&b, &nan).unwrap().reference_nonfinite, 2);
    }

    #[test]
    fn tonemap_is_the_png_encoding() {
        let mut img = Image::new(2, 1);
        img.pixels = vec![Vec3::new(0.0, 0.5, 1.0), Vec3::new(2.0, f32::NAN, -1.0)];
        assert_eq!(tonemap_srgb8(&img), [0, 188, 255, 255, 0, 0]);
    }

    /// FLIP is 0 for identical images, grows with the noise, stays in [0, 1], and is large for
    /// black against white; a different size is `None`.
    #[test]
    fn flip_orders_noise_levels() {
        let r = ramp(48, 32);
        let same = evaluate(&r, &r).unwrap();
        assert_eq!(same.flip, 0.0);
        assert_eq!(same.mape, 0.0);
        let levels: Vec<f64> = [0.02, 0.1, 0.4]
            .iter()
            .map(|&a| evaluate(&noisy(&r, a), &r).unwrap().flip)
            .collect();
        assert!(
            levels[0] > 0.0 && levels[0] < levels[1] && levels[1] < levels[2] && levels[2] < 1.0,
            "{levels:?}"
        );
        let black = Image::new(48, 32);
        let mut white = Image::new(48, 32);
        white.pixels.iter_mut().for_each(|p| *p = Vec3::ONE);
        let map = flip_map(&black, &white).unwrap();
        assert_eq!(map.len(), 48 * 32);
        assert!(map.iter().all(|&v| (0.0..=1.0).contains(&v)));
        assert!(mean(&map) > 0.5, "{}", mean(&map));
        assert!(flip_map(&Image::new(4, 4), &white).is_none());
    }
}
