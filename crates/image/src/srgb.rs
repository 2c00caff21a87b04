//! The sRGB transfer function (IEC 61966-2-1): [`decode`] turns an encoded value in `[0, 1]` into
//! a linear one, [`encode_u8`] turns a linear value into an 8-bit code for PNG output; and the
//! sRGB primaries' matrix to CIE XYZ ([`to_xyz`]).

use glam::DVec3;

/// Rows of the linear sRGB → CIE XYZ matrix (D65 white; IEC 61966-2-1), the matrix Mitsuba 3
/// converts with (`srgb_to_xyz`).
pub const TO_XYZ: [[f64; 3]; 3] = [
    [0.412453, 0.357580, 0.180423],
    [0.212671, 0.715160, 0.072169],
    [0.019334, 0.119193, 0.950227],
];

/// Linear sRGB → CIE XYZ ([`TO_XYZ`]).
#[inline]
pub fn to_xyz(c: DVec3) -> DVec3 {
    let row = |r: [f64; 3]| r[0] * c.x + r[1] * c.y + r[2] * c.z;
    DVec3::new(row(TO_XYZ[0]), row(TO_XYZ[1]), row(TO_XYZ[2]))
}

/// sRGB-encoded value in `[0, 1]` → linear.
#[inline]
pub fn decode(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear value → 8-bit sRGB code, rounded to nearest; clamped to `[0, 1]` first, with NaN and
/// infinities written as 0.
#[inline]
pub fn encode_u8(c: f32) -> u8 {
    let c = if c.is_finite() {
        c.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let v = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (v * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    /// sRGB white (1, 1, 1) is D65: Y = 1, x = 0.3127, y = 0.3290.
    #[test]
    fn white_is_d65() {
        let w = to_xyz(DVec3::ONE);
        assert!((w.y - 1.0).abs() < 1e-5, "{w}");
        let sum = w.x + w.y + w.z;
        assert!((w.x / sum - 0.3127).abs() < 1e-4 && (w.y / sum - 0.3290).abs() < 1e-4);
    }

    #[test]
    fn encode_endpoints() {
        assert_eq!(encode_u8(0.0), 0);
        assert_eq!(encode_u8(1.0), 255);
        assert_eq!(encode_u8(f32::NAN), 0);
        assert_eq!(encode_u8(0.5), 188);
    }

    #[test]
    fn decode_known_values() {
        assert!((decode(0.5) - 0.214_041).abs() < 1e-5);
        assert_eq!(decode(0.0), 0.0);
        assert!((decode(1.0) - 1.0).abs() < 1e-6);
    }

    /// Every 8-bit code survives decode → encode.
    #[test]
    fn codes_round_trip() {
        for c in 0..=255u8 {
            assert_eq!(encode_u8(decode(c as f32 / 255.0)), c);
        }
    }
}
