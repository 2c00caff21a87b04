//! Error metrics between a test image and a reference.

use crate::Image;

/// Errors of an image against a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorMetrics {
    /// Mean over pixels and RGB channels of `(x − r)² / (r² + 0.01)`, the relative MSE of the
    /// ReSTIR papers' figures.
    pub relmse: f64,
    /// Mean over pixels and channels of `(x − r)²`.
    pub mse: f64,
    /// Mean of the test image over mean of the reference (all channels together).
    pub mean_ratio: f64,
    /// Pixels of the test image with a NaN or infinite channel (left out of the other metrics).
    pub nonfinite: usize,
    /// Pixels of the reference with a NaN or infinite channel (left out of the other metrics,
    /// whatever the test image holds there).
    pub reference_nonfinite: usize,
}

/// Compares `test` with `reference`; `None` if their sizes differ. A pixel non-finite in either
/// image is counted ([`ErrorMetrics::nonfinite`], [`ErrorMetrics::reference_nonfinite`]) and left
/// out; when no pixel is left, relMSE, MSE and the mean ratio are NaN, never the 0 of a perfect
/// match.
pub fn compare(test: &Image, reference: &Image) -> Option<ErrorMetrics> {
    if test.width != reference.width || test.height != reference.height {
        return None;
    }
    let (mut rel, mut mse, mut st, mut sr) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut n = 0usize;
    let (mut nonfinite, mut reference_nonfinite) = (0, 0);
    for (x, r) in test.pixels.iter().zip(&reference.pixels) {
        let (xf, rf) = (x.is_finite(), r.is_finite());
        nonfinite += usize::from(!xf);
        reference_nonfinite += usize::from(!rf);
        if !(xf && rf) {
            continue;
        }
        for c in 0..3 {
            let (xv, rv) = (x[c] as f64, r[c] as f64);
            let d = xv - rv;
            rel += d * d / (rv * rv + 0.01);
            mse += d * d;
            st += xv;
            sr += rv;
        }
        n += 3;
    }
    // 0 / 0 when nothing was compared: NaN.
    let n = n as f64;
    Some(ErrorMetrics {
        relmse: rel / n,
        mse: mse / n,
        mean_ratio: if sr != 0.0 { st / sr } else { f64::NAN },
        nonfinite,
        reference_nonfinite,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn known_values() {
        let mut a = Image::new(2, 1);
        let mut b = Image::new(2, 1);
        a.pixels = vec![Vec3::splat(1.0), Vec3::splat(0.0)];
        b.pixels = vec![Vec3::splat(0.5), Vec3::splat(0.0)];
        let m = compare(&a, &b).unwrap();
        assert!((m.mse - 0.25 / 2.0).abs() < 1e-12);
        assert!((m.relmse - 0.25 / 0.26 / 2.0).abs() < 1e-12);
        assert!((m.mean_ratio - 2.0).abs() < 1e-12);
        a.pixels[1] = Vec3::new(f32::NAN, 0.0, 0.0);
        assert_eq!(compare(&a, &b).unwrap().nonfinite, 1);
        assert!(compare(&Image::new(1, 1), &b).is_none());
    }

    /// An all-NaN test image is no perfect match, and NaN in the reference is counted.
    #[test]
    fn non_finite_pixels_are_counted_on_both_sides_and_never_score_zero() {
        let mut a = Image::new(2, 1);
        let b = Image::new(2, 1);
        a.pixels = vec![Vec3::splat(f32::NAN); 2];
        let m = compare(&a, &b).unwrap();
        assert_eq!((m.nonfinite, m.reference_nonfinite), (2, 0));
        assert!(m.relmse.is_nan() && m.mse.is_nan(), "{m:?}");
        let m = compare(&b, &a).unwrap();
        assert_eq!((m.nonfinite, m.reference_nonfinite), (0, 2));
        assert!(m.relmse.is_nan(), "{m:?}");
        // One finite pixel left: it alone is scored.
        a.pixels[0] = Vec3::splat(1.0);
        let m = compare(&a, &b).unwrap();
        assert_eq!(m.nonfinite, 1);
        assert!((m.mse - 1.0).abs() < 1e-12, "{m:?}");
        let m = compare(&b, &a).unwrap();
        assert_eq!(m.reference_nonfinite, 1);
        assert!((m.mse - 1.0).abs() < 1e-12, "{m:?}");
    }
}
