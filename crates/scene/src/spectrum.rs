//! Spectra given as `wavelength:value` lists, converted to linear sRGB once at load time the way
//! Mitsuba 3's RGB variants do it (its `include/mitsuba/core/spectrum.h`, and the "Spectra"
//! section of its plugin reference).
//!
//! The spectrum is linearly interpolated (zero outside its wavelength range), integrated against
//! the CIE 1931 2° colour-matching functions by a 1000-point Riemann sum over 360–830 nm,
//! weighted by the D65 illuminant for reflectances (not for emitters), and mapped XYZ → linear
//! sRGB with Mitsuba's matrix.
//!
//! The tables are the CIE's published data: the CIE 1931 2° standard observer and the D65
//! relative spectral power distribution, 360–830 nm at 5 nm (95 samples).

/// First wavelength of the tables (nm).
const LAMBDA_MIN: f64 = 360.0;
/// Last wavelength of the tables (nm).
const LAMBDA_MAX: f64 = 830.0;
/// Number of table entries (5 nm steps).
const SAMPLES: usize = 95;
/// Quadrature points of the conversion.
const QUAD: usize = 1000;
/// Mitsuba's normalisation of the CIE ȳ integral.
const CIE_Y_INTEGRAL: f64 = 106.750_259_399_414_06;
/// D65 table scale (so that D65-weighted white maps close to 1).
const D65_NORM: f64 = 1.0 / 98.997_417_518_762_55;

#[rustfmt::skip]
const CIE_X: [f64; SAMPLES] = [
    0.0001299, 0.0002321, 0.0004149, 0.0007416, 0.001368, 0.002236, 0.004243, 0.00765,
    0.01431, 0.02319, 0.04351, 0.07763, 0.13438, 0.21477, 0.2839, 0.3285, 0.34828, 0.34806,
    0.3362, 0.3187, 0.2908, 0.2511, 0.19536, 0.1421, 0.09564, 0.05795001, 0.03201, 0.0147,
    0.0049, 0.0024, 0.0093, 0.0291, 0.06327, 0.1096, 0.1655, 0.2257499, 0.2904, 0.3597,
    0.4334499, 0.5120501, 0.5945, 0.6784, 0.7621, 0.8425, 0.9163, 0.9786, 1.0263, 1.0567,
    1.0622, 1.0456, 1.0026, 0.9384, 0.8544499, 0.7514, 0.6424, 0.5419, 0.4479, 0.3608,
    0.2835, 0.2187, 0.1649, 0.1212, 0.0874, 0.0636, 0.04677, 0.0329, 0.0227, 0.01584,
    0.01135916, 0.008110916, 0.005790346, 0.004109457, 0.002899327, 0.00204919, 0.001439971,
    0.0009999493, 0.0006900786, 0.0004760213, 0.0003323011, 0.0002348261, 0.0001661505,
    0.000117413, 8.307527e-05, 5.870652e-05, 4.150994e-05, 2.935326e-05, 2.067383e-05,
    1.455977e-05, 1.025398e-05, 7.221456e-06, 5.085868e-06, 3.581652e-06, 2.522525e-06,
    1.776509e-06, 1.251141e-06,
];

#[rustfmt::skip]
const CIE_Y: [f64; SAMPLES] = [
    3.917e-06, 6.965e-06, 1.239e-05, 2.202e-05, 3.9e-05, 6.4e-05, 0.00012, 0.000217,
    0.000396, 0.00064, 0.00121, 0.00218, 0.004, 0.0073, 0.0116, 0.01684, 0.023, 0.0298,
    0.038, 0.048, 0.06, 0.0739, 0.09098, 0.1126, 0.13902, 0.1693, 0.20802, 0.2586, 0.323,
    0.4073, 0.503, 0.6082, 0.71, 0.7932, 0.862, 0.9148501, 0.954, 0.9803, 0.9949501, 1.0,
    0.995, 0.9786, 0.952, 0.9154, 0.87, 0.8163, 0.757, 0.6949, 0.631, 0.5668, 0.503,
    0.4412, 0.381, 0.321, 0.265, 0.217, 0.175, 0.1382, 0.107, 0.0816, 0.061, 0.04458,
    0.032, 0.0232, 0.017, 0.01192, 0.00821, 0.005723, 0.004102, 0.002929, 0.002091,
    0.001484, 0.001047, 0.00074, 0.00052, 0.0003611, 0.0002492, 0.0001719, 0.00012,
    8.48e-05, 6e-05, 4.24e-05, 3e-05, 2.12e-05, 1.499e-05, 1.06e-05, 7.4657e-06,
    5.2578e-06, 3.7029e-06, 2.6078e-06, 1.8366e-06, 1.2934e-06, 9.1093e-07, 6.4153e-07,
    4.5181e-07,
];

#[rustfmt::skip]
const CIE_Z: [f64; SAMPLES] = [
    0.0006061, 0.001086, 0.001946, 0.003486, 0.006450001, 0.01054999, 0.02005001, 0.03621,
    0.06785001, 0.1102, 0.2074, 0.3713, 0.6456, 1.0390501, 1.3856, 1.62296, 1.74706,
    1.7826, 1.77211, 1.7441, 1.6692, 1.5281, 1.28764, 1.0419, 0.8129501, 0.6162, 0.46518,
    0.3533, 0.272, 0.2123, 0.1582, 0.1117, 0.07824999, 0.05725001, 0.04216, 0.02984,
    0.0203, 0.0134, 0.008749999, 0.005749999, 0.0039, 0.002749999, 0.0021, 0.0018,
    0.001650001, 0.0014, 0.0011, 0.001, 0.0008, 0.0006, 0.00034, 0.00024, 0.00019, 0.0001,
    4.999999e-05, 3e-05, 2e-05, 1e-05, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
];

/// D65 relative spectral power (100 at 560 nm), before [`D65_NORM`].
#[rustfmt::skip]
const D65: [f64; SAMPLES] = [
    46.6383, 49.3637, 52.0891, 51.0323, 49.9755, 52.3118, 54.6482, 68.7015, 82.7549,
    87.1204, 91.486, 92.4589, 93.4318, 90.057, 86.6823, 95.7736, 104.865, 110.936, 117.008,
    117.41, 117.812, 116.336, 114.861, 115.392, 115.923, 112.367, 108.811, 109.082, 109.354,
    108.578, 107.802, 106.296, 104.79, 106.239, 107.689, 106.047, 104.405, 104.225, 104.046,
    102.023, 100.0, 98.1671, 96.3342, 96.0611, 95.788, 92.2368, 88.6856, 89.3459, 90.0062,
    89.8026, 89.5991, 88.6489, 87.6987, 85.4936, 83.2886, 83.4939, 83.6992, 81.863, 80.0268,
    80.1207, 80.2146, 81.2462, 82.2778, 80.281, 78.2842, 74.0027, 69.7213, 70.6652, 71.6091,
    72.979, 74.349, 67.9765, 61.604, 65.7448, 69.8856, 72.4863, 75.087, 69.3398, 63.5927,
    55.0054, 46.4182, 56.6118, 66.8054, 65.0941, 63.3828, 63.8434, 64.304, 61.8779, 59.4519,
    55.7054, 51.959, 54.6998, 57.4406, 58.8765, 60.3125,
];

/// Mitsuba's XYZ → linear sRGB matrix.
const XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.240479, -1.537150, -0.498535],
    [-0.969256, 1.875991, 0.041556],
    [0.055648, -0.204043, 1.057311],
];

/// How a spectrum is used: reflectance-like parameters are D65-weighted, emitters are not.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectrumUse {
    /// BSDF parameters (D65-weighted, "illuminant normalisation").
    Reflectance,
    /// Emitter radiance/intensity/irradiance (unweighted).
    Emission,
}

/// Linear interpolation of a 5 nm table at `lambda` (clamped to the table's range).
fn table(t: &[f64; SAMPLES], lambda: f64) -> f64 {
    let x = (lambda - LAMBDA_MIN) / 5.0;
    let i = (x.floor().max(0.0) as usize).min(SAMPLES - 2);
    let w = x - i as f64;
    (1.0 - w) * t[i] + w * t[i + 1]
}

/// Why a sampled spectrum (`"λ1:v1, λ2:v2, …"`) cannot be read.
#[derive(Clone, Debug, PartialEq)]
pub enum SpectrumError {
    /// An entry without a `:`.
    NotAPair {
        /// The entry.
        item: String,
    },
    /// A wavelength or value that is not a number.
    NotANumber {
        /// The text that is not a number.
        text: String,
        /// The entry holding it.
        item: String,
    },
    /// A wavelength or value that is not finite.
    NotFinite {
        /// The entry.
        item: String,
    },
    /// A wavelength not above the one before it.
    NotIncreasing {
        /// The wavelength (nm).
        lambda: f64,
        /// The one before it (nm).
        previous: f64,
    },
    /// No entries.
    Empty,
}

impl core::fmt::Display for SpectrumError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SpectrumError::NotAPair { item } => {
                write!(f, "spectrum entry \"{item}\" is not wavelength:value")
            }
            SpectrumError::NotANumber { text, item } => {
                write!(f, "cannot parse \"{text}\" in spectrum entry \"{item}\"")
            }
            SpectrumError::NotFinite { item } => {
                write!(f, "spectrum entry \"{item}\" is not finite")
            }
            SpectrumError::NotIncreasing { lambda, previous } => write!(
                f,
                "spectrum wavelengths must increase ({lambda} nm follows {previous} nm)"
            ),
            SpectrumError::Empty => f.write_str("empty spectrum"),
        }
    }
}

impl std::error::Error for SpectrumError {}

/// Parses `"λ1:v1, λ2:v2, …"`. Wavelengths must be finite and strictly increasing, values finite.
pub fn parse_pairs(s: &str) -> Result<Vec<(f64, f64)>, SpectrumError> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    for item in s.split(',').map(str::trim).filter(|t| !t.is_empty()) {
        let (l, v) = item
            .split_once(':')
            .ok_or_else(|| SpectrumError::NotAPair { item: item.into() })?;
        let parse = |t: &str| -> Result<f64, SpectrumError> {
            let x = t
                .trim()
                .parse::<f64>()
                .map_err(|_| SpectrumError::NotANumber {
                    text: t.into(),
                    item: item.into(),
                })?;
            if x.is_finite() {
                Ok(x)
            } else {
                Err(SpectrumError::NotFinite { item: item.into() })
            }
        };
        let (l, v) = (parse(l)?, parse(v)?);
        if let Some(&(prev, _)) = out.last()
            && l <= prev
        {
            return Err(SpectrumError::NotIncreasing {
                lambda: l,
                previous: prev,
            });
        }
        out.push((l, v));
    }
    if out.is_empty() {
        return Err(SpectrumError::Empty);
    }
    Ok(out)
}

/// The spectrum's value at `lambda`: linear interpolation, zero outside its range.
fn eval(pairs: &[(f64, f64)], lambda: f64) -> f64 {
    let (first, last) = (pairs[0].0, pairs[pairs.len() - 1].0);
    if lambda < first || lambda > last {
        return 0.0;
    }
    if pairs.len() == 1 {
        return pairs[0].1;
    }
    let i = pairs
        .partition_point(|&(l, _)| l <= lambda)
        .clamp(1, pairs.len() - 1);
    let (l0, v0) = pairs[i - 1];
    let (l1, v1) = pairs[i];
    let w = (lambda - l0) / (l1 - l0);
    (1.0 - w) * v0 + w * v1
}

/// Converts a sampled spectrum to linear sRGB as Mitsuba 3's RGB mode does (no clamping; the
/// caller clamps as the parameter requires).
pub fn to_rgb(pairs: &[(f64, f64)], usage: SpectrumUse) -> [f64; 3] {
    let (first, last) = (pairs[0].0, pairs[pairs.len() - 1].0);
    let mut xyz = [0.0f64; 3];
    for i in 0..QUAD {
        let w = LAMBDA_MIN + i as f64 * ((LAMBDA_MAX - LAMBDA_MIN) / (QUAD - 1) as f64);
        if w < first || w > last {
            continue;
        }
        let mut v = eval(pairs, w);
        if usage == SpectrumUse::Reflectance {
            v *= table(&D65, w) * D65_NORM;
        }
        xyz[0] += table(&CIE_X, w) * v;
        xyz[1] += table(&CIE_Y, w) * v;
        xyz[2] += table(&CIE_Z, w) * v;
    }
    let scale = (LAMBDA_MAX - LAMBDA_MIN) / (QUAD as f64 * CIE_Y_INTEGRAL);
    let xyz = xyz.map(|c| c * scale);
    XYZ_TO_SRGB.map(|row| row[0] * xyz[0] + row[1] * xyz[1] + row[2] * xyz[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f64; 3], b: [f64; 3], tol: f64) {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() < tol, "{a:?} vs {b:?}");
        }
    }

    /// A flat spectrum over the whole visible range.
    fn flat(v: f64) -> Vec<(f64, f64)> {
        vec![(360.0, v), (830.0, v)]
    }

    #[test]
    fn constant_reflectance_is_grey() {
        // D65 is the sRGB white point: a flat reflectance maps to (nearly) the same grey.
        close(to_rgb(&flat(0.5), SpectrumUse::Reflectance), [0.5; 3], 2e-3);
        // The values MATERIALS.md §7 records for Mitsuba 3.
        close(
            to_rgb(&flat(1.0), SpectrumUse::Reflectance),
            [0.99898, 0.99887, 0.99880],
            2e-4,
        );
    }

    #[test]
    fn constant_emission_is_equal_energy_white() {
        // Without D65 a flat spectrum is illuminant E: xyz_to_srgb(1, 1, 1) up to quadrature.
        close(
            to_rgb(&flat(1.0), SpectrumUse::Emission),
            [1.20488, 0.948228, 0.909267],
            2e-4,
        );
        let e = XYZ_TO_SRGB.map(|r| r[0] + r[1] + r[2]);
        close(to_rgb(&flat(1.0), SpectrumUse::Emission), e, 2e-3);
    }

    #[test]
    fn partial_range_matches_mitsuba() {
        let p = parse_pairs("400:0.5, 700:0.5").unwrap();
        close(
            to_rgb(&p, SpectrumUse::Reflectance),
            [0.497671, 0.499878, 0.497455],
            2e-4,
        );
        close(
            to_rgb(&p, SpectrumUse::Emission),
            [0.599846, 0.474761, 0.451722],
            2e-4,
        );
    }

    #[test]
    fn linear_in_the_spectrum() {
        let a = to_rgb(
            &parse_pairs("400:0.1, 550:0.7, 700:0.3").unwrap(),
            SpectrumUse::Emission,
        );
        let b = to_rgb(
            &parse_pairs("400:0.2, 550:1.4, 700:0.6").unwrap(),
            SpectrumUse::Emission,
        );
        close(a.map(|c| 2.0 * c), b, 1e-9);
    }

    #[test]
    fn red_spectrum_is_red() {
        let p = parse_pairs("600:0, 610:1, 700:1").unwrap();
        let c = to_rgb(&p, SpectrumUse::Reflectance);
        assert!(
            c[0] > 0.1 && c[0] > 5.0 * c[1].abs() && c[0] > 5.0 * c[2].abs(),
            "{c:?}"
        );
    }

    #[test]
    fn bad_lists_are_errors() {
        assert!(parse_pairs("400:0.5, 300:0.5").is_err());
        assert!(parse_pairs("400-0.5").is_err());
        assert!(parse_pairs("400:x").is_err());
        assert!(parse_pairs("400:inf").is_err());
        assert!(parse_pairs(" , ").is_err());
    }
}
