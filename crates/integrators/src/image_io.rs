//! Linear RGB images: EXR (float32) and PNG (8-bit sRGB) output, EXR input.

use std::path::Path;

use glam::Vec3;

/// A linear RGB image, row-major from the top-left pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` pixels.
    pub pixels: Vec<Vec3>,
}

/// Why an image could not be read or written.
#[derive(Debug)]
pub struct ImageError {
    /// The file.
    pub path: std::path::PathBuf,
    /// What went wrong.
    pub message: String,
}

impl core::fmt::Display for ImageError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.message)
    }
}

impl std::error::Error for ImageError {}

fn srgb_encode(c: f32) -> u8 {
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

impl Image {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![Vec3::ZERO; width as usize * height as usize],
        }
    }

    /// The pixel at `(x, y)`.
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Number of pixels with a NaN or infinite channel.
    pub fn nonfinite_count(&self) -> usize {
        self.pixels.iter().filter(|p| !p.is_finite()).count()
    }

    /// Mean over pixels of each channel.
    pub fn mean(&self) -> Vec3 {
        let s = self
            .pixels
            .iter()
            .fold(glam::DVec3::ZERO, |a, p| a + p.as_dvec3());
        (s / self.pixels.len().max(1) as f64).as_vec3()
    }

    /// Writes the image; the format follows the extension: `.exr` is linear float32 RGB, `.png`
    /// 8-bit sRGB (clamped to [0, 1]).
    pub fn write(&self, path: &Path) -> Result<(), ImageError> {
        let err = |m: String| ImageError {
            path: path.to_path_buf(),
            message: m,
        };
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("exr") => {
                let w = self.width as usize;
                exr::prelude::write_rgb_file(path, w, self.height as usize, |x, y| {
                    let p = self.pixels[y * w + x];
                    (p.x, p.y, p.z)
                })
                .map_err(|e| err(format!("cannot write EXR: {e}")))
            }
            Some("png") => {
                let bytes: Vec<u8> = self
                    .pixels
                    .iter()
                    .flat_map(|p| [srgb_encode(p.x), srgb_encode(p.y), srgb_encode(p.z)])
                    .collect();
                image::save_buffer(
                    path,
                    &bytes,
                    self.width,
                    self.height,
                    image::ExtendedColorType::Rgb8,
                )
                .map_err(|e| err(format!("cannot write PNG: {e}")))
            }
            _ => Err(err(
                "unknown image format: use a .exr or .png file name".into()
            )),
        }
    }

    /// Reads the first RGB(A) layer of an EXR file (alpha is ignored).
    pub fn read_exr(path: &Path) -> Result<Self, ImageError> {
        let img = exr::prelude::read_first_rgba_layer_from_file(
            path,
            |res, _| (res.width(), vec![Vec3::ZERO; res.width() * res.height()]),
            |(w, px): &mut (usize, Vec<Vec3>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * *w + pos.x()] = Vec3::new(r, g, b);
            },
        )
        .map_err(|e| ImageError {
            path: path.to_path_buf(),
            message: format!("cannot read EXR: {e}"),
        })?;
        let size = img.layer_data.size;
        Ok(Self {
            width: size.width() as u32,
            height: size.height() as u32,
            pixels: img.layer_data.channel_data.pixels.1,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_roundtrip() {
        let mut img = Image::new(3, 2);
        for (i, p) in img.pixels.iter_mut().enumerate() {
            *p = Vec3::new(i as f32, 0.5 * i as f32, 1e-3);
        }
        let dir = std::env::temp_dir().join(format!("restir-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.exr");
        img.write(&path).unwrap();
        let back = Image::read_exr(&path).unwrap();
        assert_eq!(back, img);
        img.write(&dir.join("t.png")).unwrap();
        assert!(img.write(&dir.join("t.bmp")).is_err());
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn srgb_endpoints() {
        assert_eq!(srgb_encode(0.0), 0);
        assert_eq!(srgb_encode(1.0), 255);
        assert_eq!(srgb_encode(f32::NAN), 0);
        assert_eq!(srgb_encode(0.5), 188);
    }
}
