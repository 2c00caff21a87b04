//! Reading and writing image files: EXR (linear float32), PNG (8-bit sRGB) output; EXR, Radiance
//! HDR, PNG, JPEG and BMP input. The one EXR decoder of the workspace is [`read_exr_pixels`].

use std::path::Path;

use glam::Vec3;

use crate::{Image, ImageError, ReadFailure, input, srgb};

/// A named channel written beside an image's R, G and B ([`Image::write_with`]): one value per
/// pixel, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// The channel's name in the file (`m2_nested.X`, …).
    pub name: String,
    /// One value per pixel.
    pub values: Vec<f32>,
}

/// How [`Image::read`] interprets the integer (8- or 16-bit) channels of PNG, JPEG and BMP files.
/// Float formats (EXR, Radiance HDR) hold linear values and are never decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum IntegerEncoding {
    /// sRGB-encoded: decoded with [`srgb::decode`] (colour images).
    #[default]
    Srgb,
    /// Used as they are, divided by the largest code (data such as roughness maps: Mitsuba's
    /// `raw = true`).
    Raw,
}

/// The file name's extension, lower case.
fn extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

/// Decodes the first RGB(A) layer of an EXR file (alpha is ignored): `(width, height, pixels)`.
/// Only a regular file is opened, and every layer's size is checked against
/// [`input::MAX_IMAGE_PIXELS`] from the header before the pixels are allocated.
fn read_exr_pixels(path: &Path) -> Result<(usize, usize, Vec<Vec3>), exr::error::Error> {
    use exr::prelude::*;
    use std::io::Seek;
    let mut file = std::io::BufReader::new(input::open_regular(path)?);
    let meta = MetaData::read_from_buffered(&mut file, false)?;
    for header in meta.headers.iter() {
        let size = header.layer_size;
        if let Some(problem) = input::size_problem(size.width(), size.height()) {
            return Err(exr::error::Error::Invalid(problem.into()));
        }
    }
    file.rewind()?;
    decode_first_rgb_layer(file)
}

/// Decodes the first RGB(A) layer of an EXR file read from its start, whose header sizes were
/// checked already: `(width, height, pixels)`.
pub(crate) fn decode_first_rgb_layer(
    file: std::io::BufReader<std::fs::File>,
) -> Result<(usize, usize, Vec<Vec3>), exr::error::Error> {
    use exr::prelude::*;
    let img = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |res, _| (res.width(), vec![Vec3::ZERO; res.width() * res.height()]),
            |(w, px): &mut (usize, Vec<Vec3>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                if let Some(t) = px.get_mut(pos.y() * *w + pos.x()) {
                    *t = Vec3::new(r, g, b);
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(file)?;
    let size = img.layer_data.size;
    Ok((
        size.width(),
        size.height(),
        img.layer_data.channel_data.pixels.1,
    ))
}

impl Image {
    /// Checks before rendering that [`Image::write`] can write `path`: a known extension, and
    /// [`check_writable`](crate::check_writable) (not a directory, a file can be created beside
    /// it).
    pub fn check_output(path: &Path) -> Result<(), ImageError> {
        match extension(path).as_deref() {
            Some("exr") | Some("png") => crate::check_writable(path),
            _ => Err(ImageError::UnknownFormat {
                path: path.to_path_buf(),
            }),
        }
    }

    /// Writes the image; the format follows the extension: `.exr` is linear float32 RGB, `.png`
    /// 8-bit sRGB (clamped to [0, 1]). The file is written beside the target and renamed onto it
    /// ([`write_atomically`](crate::write_atomically)): a failed write (a full disk included)
    /// is an error and leaves an existing file as it was.
    pub fn write(&self, path: &Path) -> Result<(), ImageError> {
        self.write_with(path, &[])
    }

    /// [`Image::write`] with more channels beside R, G and B (an EXR file; with channels, a PNG
    /// file name is an error). Each channel holds one value per pixel, row-major; EXR stores the
    /// channels sorted by name.
    pub fn write_with(&self, path: &Path, extra: &[Channel]) -> Result<(), ImageError> {
        let format = extension(path);
        if !extra.is_empty() && format.as_deref() != Some("exr") {
            return Err(ImageError::ChannelsNeedExr {
                path: path.to_path_buf(),
            });
        }
        match format.as_deref() {
            Some("exr") => self.write_exr_channels(path, extra),
            Some("png") => {
                let bytes: Vec<u8> = self
                    .pixels
                    .iter()
                    .flat_map(|p| {
                        [
                            srgb::encode_u8(p.x),
                            srgb::encode_u8(p.y),
                            srgb::encode_u8(p.z),
                        ]
                    })
                    .collect();
                use image::ImageEncoder;
                crate::write_atomically(
                    path,
                    |out| {
                        image::codecs::png::PngEncoder::new(out).write_image(
                            &bytes,
                            self.width,
                            self.height,
                            image::ExtendedColorType::Rgb8,
                        )
                    },
                    |source| ImageError::WritePng {
                        path: path.to_path_buf(),
                        source,
                    },
                )
            }
            _ => Err(ImageError::UnknownFormat {
                path: path.to_path_buf(),
            }),
        }
    }

    /// An EXR of R, G, B and `extra`, all float32.
    fn write_exr_channels(&self, path: &Path, extra: &[Channel]) -> Result<(), ImageError> {
        use exr::prelude::{AnyChannel, AnyChannels, FlatSamples, SmallVec, WritableImage};
        let n = self.pixels.len();
        let rgb = |i: usize, name: &str| {
            AnyChannel::new(
                name,
                FlatSamples::F32(self.pixels.iter().map(|p| p[i]).collect()),
            )
        };
        let mut channels = vec![rgb(0, "R"), rgb(1, "G"), rgb(2, "B")];
        for c in extra {
            assert_eq!(c.values.len(), n, "channel {} has the image's size", c.name);
            channels.push(AnyChannel::new(
                c.name.as_str(),
                FlatSamples::F32(c.values.clone()),
            ));
        }
        let channels = AnyChannels::sort(SmallVec::from_vec(channels));
        let image = exr::prelude::Image::from_channels(
            (self.width as usize, self.height as usize),
            channels,
        );
        crate::write_atomically(
            path,
            |out| image.write().to_buffered(out),
            |source| ImageError::WriteExr {
                path: path.to_path_buf(),
                source,
            },
        )
    }

    /// Reads the first RGB(A) layer of an EXR file (alpha is ignored), as written by
    /// [`Image::write`].
    pub fn read_exr(path: &Path) -> Result<Self, ImageError> {
        let (w, h, pixels) = read_exr_pixels(path).map_err(|source| ImageError::ReadExr {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(Self {
            width: w as u32,
            height: h as u32,
            pixels,
        })
    }

    /// The size in pixels of an image [`Image::read`] would read, from its header alone (EXR:
    /// the largest layer), so that callers can account for the memory before decoding.
    pub fn read_dimensions(path: &Path) -> Result<(usize, usize), ImageError> {
        let fail = |reason| ImageError::Read {
            path: path.to_path_buf(),
            reason,
        };
        if extension(path).as_deref() == Some("exr") {
            let file = input::open_regular(path)
                .map_err(|e| fail(ReadFailure::Exr(exr::error::Error::from(e))))?;
            let meta =
                exr::meta::MetaData::read_from_buffered(std::io::BufReader::new(file), false)
                    .map_err(|e| fail(ReadFailure::Exr(e)))?;
            Ok(meta.headers.iter().fold((0, 0), |(w, h), header| {
                let size = header.layer_size;
                if size.area() > w * h {
                    (size.width(), size.height())
                } else {
                    (w, h)
                }
            }))
        } else {
            let file = input::open_regular(path).map_err(|e| fail(ReadFailure::Io(e)))?;
            let mut reader = image::ImageReader::new(std::io::BufReader::new(file));
            if let Ok(format) = image::ImageFormat::from_path(path) {
                reader.set_format(format);
            }
            let (w, h) = reader
                .with_guessed_format()
                .map_err(|e| fail(ReadFailure::Io(e)))?
                .into_dimensions()
                .map_err(|e| fail(ReadFailure::Decode(e)))?;
            Ok((w as usize, h as usize))
        }
    }

    /// Reads an image a scene refers to as linear RGB, the first row at the top: EXR (by
    /// extension) and Radiance HDR hold linear values; PNG/JPEG/BMP (8- or 16-bit, format guessed from
    /// the contents) are decoded as `encoding` says. Empty images and non-finite values are errors.
    /// Used for bitmap textures and environment maps.
    pub fn read(path: &Path, encoding: IntegerEncoding) -> Result<Self, ImageError> {
        let fail = |reason| ImageError::Read {
            path: path.to_path_buf(),
            reason,
        };
        let (w, h, texels) = if extension(path).as_deref() == Some("exr") {
            read_exr_pixels(path).map_err(|e| fail(ReadFailure::Exr(e)))?
        } else {
            let file = input::open_regular(path).map_err(|e| fail(ReadFailure::Io(e)))?;
            let mut limits = image::Limits::default();
            limits.max_image_width = Some(input::MAX_IMAGE_SIDE as u32);
            limits.max_image_height = Some(input::MAX_IMAGE_SIDE as u32);
            // As `ImageReader::open`: the format from the extension unless the contents say.
            let mut reader = image::ImageReader::new(std::io::BufReader::new(file));
            if let Ok(format) = image::ImageFormat::from_path(path) {
                reader.set_format(format);
            }
            let mut reader = reader
                .with_guessed_format()
                .map_err(|e| fail(ReadFailure::Io(e)))?;
            reader.limits(limits);
            let img = reader.decode().map_err(|e| fail(ReadFailure::Decode(e)))?;
            let (w, h) = (img.width() as usize, img.height() as usize);
            // Float formats (Radiance HDR) hold linear values already.
            let linear = encoding == IntegerEncoding::Raw
                || matches!(
                    img,
                    image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
                );
            let rgb = img.to_rgb32f();
            let decode = |c: f32| if linear { c } else { srgb::decode(c) };
            let texels = rgb
                .pixels()
                .map(|p| Vec3::new(decode(p.0[0]), decode(p.0[1]), decode(p.0[2])))
                .collect();
            (w, h, texels)
        };
        if w == 0 || h == 0 || texels.len() != w * h {
            return Err(fail(ReadFailure::Empty));
        }
        if texels.iter().any(|t| !t.is_finite()) {
            return Err(fail(ReadFailure::NonFinite));
        }
        Ok(Self {
            width: w as u32,
            height: h as u32,
            pixels: texels,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(tag: &str) -> restir_testkit::TempDir {
        restir_testkit::TempDir::new("image", tag)
    }

    #[test]
    fn exr_roundtrip() {
        let mut img = Image::new(3, 2);
        for (i, p) in img.pixels.iter_mut().enumerate() {
            *p = Vec3::new(i as f32, 0.5 * i as f32, 1e-3);
        }
        let dir = temp_dir("exr");
        let path = dir.join("t.exr");
        img.write(&path).unwrap();
        let back = Image::read_exr(&path).unwrap();
        assert_eq!(back, img);
        assert_eq!(Image::read(&path, IntegerEncoding::Srgb).unwrap(), img);
        img.write(&dir.join("t.png")).unwrap();
        assert!(img.write(&dir.join("t.bmp")).is_err());
        // More channels: the RGB reads back the same; a PNG cannot hold them.
        let extra = [Channel {
            name: "m2_x.Y".into(),
            values: vec![2.0; 6],
        }];
        img.write_with(&path, &extra).unwrap();
        assert_eq!(Image::read_exr(&path).unwrap(), img);
        let png = dir.join("m.png");
        assert!(matches!(
            img.write_with(&png, &extra),
            Err(ImageError::ChannelsNeedExr { .. })
        ));
        assert!(!png.exists());
    }

    /// PNG output is 8-bit sRGB; reading it back decodes it (or not, when raw).
    #[test]
    fn png_roundtrip_through_srgb() {
        let mut img = Image::new(2, 1);
        img.pixels = vec![Vec3::new(0.0, 0.5, 1.0), Vec3::new(2.0, f32::NAN, 0.25)];
        let dir = temp_dir("png");
        let path = dir.join("t.png");
        img.write(&path).unwrap();
        let raw = Image::read(&path, IntegerEncoding::Raw).unwrap();
        assert_eq!(raw.pixels[0], Vec3::new(0.0, 188.0 / 255.0, 1.0));
        assert_eq!(raw.pixels[1].y, 0.0);
        let back = Image::read(&path, IntegerEncoding::Srgb).unwrap();
        assert!(back.pixels[0].abs_diff_eq(Vec3::new(0.0, 0.5, 1.0), 0.01));
        assert!(back.pixels[1].abs_diff_eq(Vec3::new(1.0, 0.0, 0.25), 0.01));
    }

    /// BMP textures (Mitsuba reads them; its test scenes use one) are 8-bit sRGB like PNG, and
    /// their size is read from the header.
    #[test]
    fn bmp_is_read_as_srgb() {
        let dir = temp_dir("bmp");
        let path = dir.join("t.bmp");
        image::RgbImage::from_raw(2, 1, vec![0, 188, 255, 255, 0, 64])
            .unwrap()
            .save(&path)
            .unwrap();
        assert_eq!(Image::read_dimensions(&path).unwrap(), (2, 1));
        let raw = Image::read(&path, IntegerEncoding::Raw).unwrap();
        assert_eq!(raw.pixels[0], Vec3::new(0.0, 188.0 / 255.0, 1.0));
        assert_eq!(raw.pixels[1], Vec3::new(1.0, 0.0, 64.0 / 255.0));
        let back = Image::read(&path, IntegerEncoding::Srgb).unwrap();
        assert!(back.pixels[0].abs_diff_eq(Vec3::new(0.0, 0.5, 1.0), 0.01));
    }

    /// An EXR whose header claims 65536×65536 pixels (a few hundred bytes on disk) is refused
    /// from the header, by both readers, instead of allocating 51 GB.
    #[test]
    fn a_lying_exr_header_is_refused_before_allocating() {
        let dir = temp_dir("huge");
        let path = dir.join("huge.exr");
        Image::new(1, 1).write(&path).unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        let tag = b"dataWindow\0box2i\0";
        let at = bytes.windows(tag.len()).position(|w| w == tag).unwrap() + tag.len() + 4;
        for (i, v) in [0i32, 0, 65535, 65535].into_iter().enumerate() {
            bytes[at + 4 * i..at + 4 * i + 4].copy_from_slice(&v.to_le_bytes());
        }
        std::fs::write(&path, &bytes).unwrap();
        let want = "the image is 65536×65536 pixels, beyond the limit";
        let e = Image::read_exr(&path).unwrap_err().to_string();
        assert!(e.contains(want), "{e}");
        let e = Image::read(&path, IntegerEncoding::Srgb)
            .unwrap_err()
            .to_string();
        assert!(e.contains(want), "{e}");
    }

    /// The messages name the file, as the scene loader and the command line report them.
    #[test]
    fn error_messages() {
        let dir = temp_dir("err");
        let missing = dir.join("nope.exr");
        let e = Image::read_exr(&missing).unwrap_err();
        assert!(
            e.to_string()
                .starts_with(&format!("{}: cannot read EXR: ", missing.display())),
            "{e}"
        );
        assert_eq!(e.path(), missing);
        let e = Image::read(&dir.join("nope.png"), IntegerEncoding::Srgb).unwrap_err();
        assert!(
            e.to_string().starts_with(&format!(
                "cannot read image '{}': ",
                dir.join("nope.png").display()
            )),
            "{e}"
        );
        let bmp = dir.join("t.bmp");
        assert_eq!(
            Image::new(1, 1).write(&bmp).unwrap_err().to_string(),
            format!(
                "{}: unknown image format: use a .exr or .png file name",
                bmp.display()
            )
        );
        std::fs::write(dir.join("bad.png"), b"not a png").unwrap();
        assert!(Image::read(&dir.join("bad.png"), IntegerEncoding::Srgb).is_err());
    }
}
