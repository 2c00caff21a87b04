//! Linear RGB images for the `restir` renderer, in one place:
//!
//! - [`Image`]: a linear RGB image, row-major from the top-left pixel.
//! - Files: [`Image::write`] writes `.exr` (linear float32 RGB) or `.png` (8-bit sRGB), through a
//!   temporary file renamed onto the target ([`write_atomically`]: never a half-written file,
//!   every error reported, flush included; [`Image::check_output`] checks a path before a render);
//!   [`Image::read_exr`] reads a rendered EXR back; [`Image::write_exr_part`] /
//!   [`Image::read_exr_part`] an EXR of one part of a render ([`ExrPart`]: its place in the film
//!   and text attributes); [`Image::read`] reads what a scene refers to
//!   (PNG/JPEG/BMP, sRGB-decoded unless told otherwise, EXR and Radiance HDR as linear values) for
//!   textures and environment maps. Failures are an [`ImageError`] naming the file.
//! - [`srgb`]: the sRGB transfer function both ways.
//! - [`compare`]: the error metrics of a test image against a reference ([`ErrorMetrics`]:
//!   relMSE, MSE, mean ratio, non-finite pixels).
//!
//! ```
//! use restir_image::{Image, compare};
//! use glam::Vec3;
//!
//! let reference = Image::new(2, 1);
//! let mut test = Image::new(2, 1);
//! test.pixels[0] = Vec3::splat(0.1);
//! let m = compare(&test, &reference).unwrap();
//! assert!((m.mse - 0.01 / 2.0).abs() < 1e-9);
//! assert_eq!(m.nonfinite, 0);
//! ```

#![deny(missing_docs)]

mod error;
pub mod input;
mod io;
mod metrics;
mod output;
mod part;
pub mod srgb;

pub use error::{ImageError, ReadFailure};
pub use io::{Channel, IntegerEncoding};
pub use metrics::{ErrorMetrics, compare};
pub use output::{
    Destination, OutputWriter, check_writable, destination, same_destination, temp_path,
    write_atomically, write_file_atomically,
};
pub use part::ExrPart;

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
}
