//! Bitmap and checkerboard lookups.

use super::*;
use restir_image::srgb::decode as srgb_to_linear;

/// 8-bit texels are kept as codes with exactly the values the reader decoded; other values
/// stay floats.
#[test]
fn texels_in_bytes_hold_the_same_values() {
    for raw in [false, true] {
        let level = |k: u8| {
            let c = k as f32 / 255.0;
            if raw {
                c
            } else {
                restir_image::srgb::decode(c)
            }
        };
        let values: Vec<Vec3> = (0..=255u8)
            .map(|k| Vec3::new(level(k), level(255 - k), level(k / 2)))
            .collect();
        let t = Texels::new(values.clone(), raw);
        assert!(matches!(t, Texels::Levels { .. }), "raw {raw}");
        assert_eq!(t.len(), values.len());
        for (i, v) in values.iter().enumerate() {
            assert_eq!(
                t.get(i).to_array().map(f32::to_bits),
                v.to_array().map(f32::to_bits)
            );
        }
        // One value that is no 8-bit level (a 16-bit or float image): floats.
        let mut other = values.clone();
        other[7].y = 0.123_456_7;
        let t = Texels::new(other.clone(), raw);
        assert!(matches!(t, Texels::Float(_)), "raw {raw}");
        assert_eq!(t.get(7), other[7]);
    }
}

#[test]
fn checkerboard_pattern_and_scale() {
    let t = Texture::Checkerboard {
        color0: Vec3::ONE,
        color1: Vec3::ZERO,
        uv: UvTransform {
            scale: Vec2::splat(2.0),
            offset: Vec2::ZERO,
        },
    };
    assert_eq!(t.eval(Vec2::new(0.1, 0.1)), Vec3::ONE);
    assert_eq!(t.eval(Vec2::new(0.3, 0.1)), Vec3::ZERO);
    assert_eq!(t.eval(Vec2::new(0.3, 0.3)), Vec3::ONE);
    assert_eq!(t.eval(Vec2::new(-0.1, 0.1)), Vec3::ZERO);
    assert_eq!(t.mean(), Vec3::splat(0.5));
}

fn temp_dir(tag: &str) -> restir_testkit::TempDir {
    restir_testkit::TempDir::new("tex", tag)
}

/// Checkerboard values agree with Mitsuba 3's at points read off its `checkerboard` (also for
/// negative coordinates and on the ½ lines), with a uv offset.
#[test]
fn checkerboard_matches_mitsuba_and_offsets() {
    let t = Texture::Checkerboard {
        color0: Vec3::X,
        color1: Vec3::Z,
        uv: UvTransform::default(),
    };
    for (u, v, want) in [
        (0.25, 0.25, Vec3::X),
        (0.75, 0.25, Vec3::Z),
        (0.25, 0.75, Vec3::Z),
        (0.75, 0.75, Vec3::X),
        (-0.25, 0.25, Vec3::Z),
        (-0.75, -0.25, Vec3::Z),
        (1.25, 0.25, Vec3::X),
        (0.5, 0.25, Vec3::X),
        (0.25, 0.5, Vec3::X),
    ] {
        assert_eq!(t.eval(Vec2::new(u, v)), want, "({u}, {v})");
    }
    let shifted = Texture::Checkerboard {
        color0: Vec3::X,
        color1: Vec3::Z,
        uv: UvTransform {
            scale: Vec2::ONE,
            offset: Vec2::new(0.5, 0.0),
        },
    };
    assert_eq!(shifted.eval(Vec2::new(0.25, 0.25)), Vec3::Z);
}

/// `uv = (0, 0)` is the image's top-left corner (Mitsuba 3: its bitmap at uv (0.25, 0.25)
/// of a 2×2 image is the first texel of the first row); scale and offset apply before the
/// lookup; lookups repeat.
#[test]
fn bitmap_orientation_scale_offset_and_wrap() {
    let dir = temp_dir("orient");
    // Row 0 (top): red, green; row 1: blue, white. Raw, so values are exact.
    let img = image::RgbImage::from_raw(2, 2, vec![255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255])
        .unwrap();
    img.save(dir.join("q.png")).unwrap();
    let load = |scale: Vec2, offset: Vec2| {
        let desc = TextureDesc::Bitmap {
            filename: "q.png".into(),
            raw: true,
            uv: UvTransform { scale, offset },
            wrap: WrapMode::Repeat,
            filter: FilterType::Bilinear,
        };
        Texture::load(&desc, &dir).unwrap()
    };
    let t = load(Vec2::ONE, Vec2::ZERO);
    let (red, green, blue) = (Vec3::X, Vec3::Y, Vec3::Z);
    assert_eq!(t.eval(Vec2::new(0.25, 0.25)), red);
    assert_eq!(t.eval(Vec2::new(0.75, 0.25)), green);
    assert_eq!(t.eval(Vec2::new(0.25, 0.75)), blue);
    assert_eq!(t.eval(Vec2::new(0.75, 0.75)), Vec3::ONE);
    // Repeat: one period further in each direction (and negative) is the same.
    assert_eq!(t.eval(Vec2::new(1.25, -0.75)), red);
    assert_eq!(t.eval(Vec2::new(-1.25, 2.25)), green);
    // Bilinear: the centre of the image is the mean of the four texels.
    let centre = t.eval(Vec2::splat(0.5));
    assert!((centre - Vec3::new(0.5, 0.5, 0.5)).abs().max_element() < 1e-6);
    // Halfway between the two texel centres of the top row.
    let top = t.eval(Vec2::new(0.5, 0.25));
    assert!((top - Vec3::new(0.5, 0.5, 0.0)).abs().max_element() < 1e-6);
    // uv' = uv · scale + offset.
    let scaled = load(Vec2::splat(2.0), Vec2::ZERO);
    assert_eq!(scaled.eval(Vec2::new(0.375, 0.125)), green);
    assert_eq!(scaled.eval(Vec2::new(0.625, 0.125)), red);
    let offset = load(Vec2::ONE, Vec2::new(0.5, 0.5));
    assert_eq!(offset.eval(Vec2::new(0.25, 0.25)), Vec3::ONE);
    assert_eq!(offset.eval(Vec2::new(0.75, 0.75)), red);
}

/// `wrap_mode` mirror and clamp, and `filter_type` nearest, on the same 2×2 image.
#[test]
fn bitmap_mirror_clamp_and_nearest() {
    let dir = temp_dir("modes");
    let img = image::RgbImage::from_raw(2, 2, vec![255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255])
        .unwrap();
    img.save(dir.join("q.png")).unwrap();
    let load = |wrap: WrapMode, filter: FilterType| {
        let desc = TextureDesc::Bitmap {
            filename: "q.png".into(),
            raw: true,
            uv: UvTransform::default(),
            wrap,
            filter,
        };
        Texture::load(&desc, &dir).unwrap()
    };
    let (red, green, blue) = (Vec3::X, Vec3::Y, Vec3::Z);
    // Mirror: just right of the image is its right column again, then the left one.
    let m = load(WrapMode::Mirror, FilterType::Bilinear);
    assert_eq!(m.eval(Vec2::new(1.25, 0.25)), green);
    assert_eq!(m.eval(Vec2::new(1.75, 0.25)), red);
    assert_eq!(m.eval(Vec2::new(-0.25, 0.75)), blue);
    // Bilinear across the mirrored edge: both texels are the edge texel.
    assert_eq!(m.eval(Vec2::new(1.0, 0.25)), green);
    // Clamp: the edge texels extend outwards.
    let c = load(WrapMode::Clamp, FilterType::Bilinear);
    assert_eq!(c.eval(Vec2::new(7.0, -3.0)), green);
    assert_eq!(c.eval(Vec2::new(-7.0, 9.0)), blue);
    // Nearest: no blending, whichever texel the point is in.
    let n = load(WrapMode::Repeat, FilterType::Nearest);
    assert_eq!(n.eval(Vec2::new(0.49, 0.49)), red);
    assert_eq!(n.eval(Vec2::new(0.51, 0.49)), green);
    assert_eq!(n.eval(Vec2::new(1.51, -0.49)), Vec3::ONE);
    let r = load(WrapMode::Repeat, FilterType::Bilinear);
    assert_ne!(r.eval(Vec2::new(1.0, 0.25)), green);
}

/// 8-bit values go through the exact sRGB curve (both branches), unless `raw`.
#[test]
fn srgb_decoding_of_8_bit_values() {
    let dir = temp_dir("srgb");
    let codes = [0u8, 5, 10, 11, 64, 128, 200, 255];
    let img = image::GrayImage::from_raw(codes.len() as u32, 1, codes.to_vec()).unwrap();
    img.save(dir.join("g.png")).unwrap();
    let desc = TextureDesc::Bitmap {
        filename: "g.png".into(),
        raw: false,
        uv: UvTransform::default(),
        wrap: WrapMode::default(),
        filter: FilterType::default(),
    };
    let t = Texture::load(&desc, &dir).unwrap();
    let n = codes.len() as f32;
    for (i, &c) in codes.iter().enumerate() {
        let x = c as f32 / 255.0;
        let want = if x <= 0.04045 {
            x / 12.92
        } else {
            ((x + 0.055) / 1.055).powf(2.4)
        };
        // At the texel centre, bilinear filtering returns the texel itself.
        let got = t.eval(Vec2::new((i as f32 + 0.5) / n, 0.5));
        assert!(
            (got - Vec3::splat(want)).abs().max_element() < 1e-6,
            "code {c}: {got} vs {want}"
        );
    }
    assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
}

#[test]
fn bad_texture_parameters_are_errors() {
    // Negative (above 1 is for the parameter it is bound to to judge).
    let bad = TextureDesc::Checkerboard {
        color0: [-0.5, 0.0, 0.0],
        color1: [0.0; 3],
        uv: UvTransform::default(),
    };
    assert!(
        Texture::load(&bad, Path::new("."))
            .unwrap_err()
            .to_string()
            .contains("color0")
    );
    let bad = TextureDesc::Checkerboard {
        color0: [0.5; 3],
        color1: [0.0; 3],
        uv: UvTransform {
            scale: Vec2::new(f32::NAN, 1.0),
            offset: Vec2::ZERO,
        },
    };
    assert!(
        Texture::load(&bad, Path::new("."))
            .unwrap_err()
            .to_string()
            .contains("not finite")
    );
}

#[test]
fn png_is_srgb_decoded_and_bilinear() {
    let dir = temp_dir("png");
    // 2×1 image: black | sRGB 188 (≈ linear 0.5).
    let img = image::RgbImage::from_raw(2, 1, vec![0, 0, 0, 188, 188, 188]).unwrap();
    img.save(dir.join("t.png")).unwrap();
    let desc = TextureDesc::Bitmap {
        filename: "t.png".into(),
        raw: false,
        uv: UvTransform::default(),
        wrap: WrapMode::default(),
        filter: FilterType::default(),
    };
    let t = Texture::load(&desc, &dir).unwrap();
    let lin = srgb_to_linear(188.0 / 255.0);
    assert!((lin - 0.5).abs() < 0.01);
    // Texel centres at u = 0.25 and 0.75; halfway between is the average.
    assert!((t.eval(Vec2::new(0.75, 0.5)).x - lin).abs() < 1e-5);
    assert!(t.eval(Vec2::new(0.25, 0.5)).x.abs() < 1e-6);
    assert!((t.eval(Vec2::new(0.5, 0.5)).x - 0.5 * lin).abs() < 1e-5);
    // Wrapping: u = 0 is halfway between the last and the first texel.
    assert!((t.eval(Vec2::new(0.0, 0.5)).x - 0.5 * lin).abs() < 1e-5);
    let raw = TextureDesc::Bitmap {
        filename: "t.png".into(),
        raw: true,
        uv: UvTransform::default(),
        wrap: WrapMode::default(),
        filter: FilterType::default(),
    };
    let t = Texture::load(&raw, &dir).unwrap();
    assert!((t.eval(Vec2::new(0.75, 0.5)).x - 188.0 / 255.0).abs() < 1e-5);
    // Missing and malformed files are errors.
    let missing = TextureDesc::Bitmap {
        filename: "nope.png".into(),
        raw: false,
        uv: UvTransform::default(),
        wrap: WrapMode::default(),
        filter: FilterType::default(),
    };
    assert!(
        Texture::load(&missing, &dir)
            .unwrap_err()
            .to_string()
            .contains("nope.png")
    );
    std::fs::write(dir.join("bad.png"), b"not a png").unwrap();
    let bad = TextureDesc::Bitmap {
        filename: "bad.png".into(),
        raw: false,
        uv: UvTransform::default(),
        wrap: WrapMode::default(),
        filter: FilterType::default(),
    };
    assert!(Texture::load(&bad, &dir).is_err());
}
