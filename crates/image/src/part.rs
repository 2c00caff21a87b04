//! EXR files of one part of a render (a chain of passes, a tile, or both): the image plus where
//! it sits in the whole film (the EXR data window inside the display window) and named text
//! attributes (which passes it holds, what was rendered), written by [`Image::write_exr_part`]
//! and read back by [`Image::read_exr_part`]. `restir merge` builds on these.

use std::path::Path;

use exr::prelude::{
    AttributeValue, Encoding, IntegerBounds, Layer, LayerAttributes, SpecificChannels, Text,
    WritableImage,
};
use glam::Vec3;

use crate::{Image, ImageError};

/// Where a part sits in the whole film and what it says about itself.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ExrPart {
    /// The whole film's `(width, height)` (the EXR display window).
    pub film: (u32, u32),
    /// The part's top-left pixel in the film (the EXR data window's origin).
    pub offset: (u32, u32),
    /// Text attributes, `(name, value)`, in the order written; read back sorted by name.
    pub attributes: Vec<(String, String)>,
}

impl ExrPart {
    /// The value of attribute `name`, if present.
    pub fn attribute(&self, name: &str) -> Option<&str> {
        self.attributes
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
}

impl Image {
    /// Writes the image as linear float32 RGB EXR whose data window is this image placed at
    /// `part.offset` in a display window of `part.film`, with `part.attributes` as text
    /// attributes of the layer (never half-written: through a temporary file renamed onto
    /// `path`).
    pub fn write_exr_part(&self, path: &Path, part: &ExrPart) -> Result<(), ImageError> {
        let err = |source| ImageError::WriteExr {
            path: path.to_path_buf(),
            source,
        };
        let mut attributes = LayerAttributes {
            layer_position: exr::math::Vec2(part.offset.0 as i32, part.offset.1 as i32),
            ..LayerAttributes::default()
        };
        for (k, v) in &part.attributes {
            let (Some(k), Some(v)) = (Text::new_or_none(k), Text::new_or_none(v)) else {
                return Err(err(exr::error::Error::Invalid(
                    "attribute is not ASCII/Latin-1 text".into(),
                )));
            };
            attributes.other.insert(k, AttributeValue::Text(v));
        }
        let w = self.width as usize;
        let channels = SpecificChannels::rgb(|exr::math::Vec2(x, y): exr::math::Vec2<usize>| {
            let p: Vec3 = self.pixels[y * w + x];
            (p.x, p.y, p.z)
        });
        let layer = Layer::new(
            (w, self.height as usize),
            attributes,
            Encoding::default(),
            channels,
        );
        let mut image = exr::image::Image::from_layer(layer);
        image.attributes.display_window =
            IntegerBounds::new((0, 0), (part.film.0 as usize, part.film.1 as usize));
        // Through a temporary file, as every output ([`crate::write_atomically`]).
        crate::write_atomically(path, |out| image.write().to_buffered(out), err)
    }

    /// Reads the header of an EXR written by [`Image::write_exr_part`]: the data window's size
    /// `(width, height)` and where it sits, with the text attributes, without decoding pixels.
    /// Only a regular file is opened ([`crate::input::open_regular`]), and the data and display
    /// windows are checked against [`crate::input::MAX_IMAGE_PIXELS`] / side limits; a data
    /// window outside the display window is an error.
    pub fn read_exr_part_header(path: &Path) -> Result<((u32, u32), ExrPart), ImageError> {
        let err = |source| ImageError::ReadExr {
            path: path.to_path_buf(),
            source,
        };
        let file = crate::input::open_regular(path).map_err(|e| err(e.into()))?;
        let mut file = std::io::BufReader::new(file);
        let meta = exr::meta::MetaData::read_from_buffered(&mut file, false).map_err(err)?;
        part_of_header(&meta).map_err(err)
    }

    /// Reads an EXR written by [`Image::write_exr_part`]: the data window's pixels, and where they
    /// sit with the text attributes. Files without attributes read as parts with none. The
    /// header is checked as [`Image::read_exr_part_header`] does before pixels are allocated.
    pub fn read_exr_part(path: &Path) -> Result<(Self, ExrPart), ImageError> {
        use std::io::Seek;
        let err = |source| ImageError::ReadExr {
            path: path.to_path_buf(),
            source,
        };
        let file = crate::input::open_regular(path).map_err(|e| err(e.into()))?;
        let mut file = std::io::BufReader::new(file);
        let meta = exr::meta::MetaData::read_from_buffered(&mut file, false).map_err(err)?;
        let (_, part) = part_of_header(&meta).map_err(err)?;
        file.rewind().map_err(|e| err(e.into()))?;
        let (width, height, pixels) = crate::io::decode_first_rgb_layer(file).map_err(err)?;
        let image = Self {
            width: width as u32,
            height: height as u32,
            pixels,
        };
        Ok((image, part))
    }
}

/// The part described by the first layer's header (the layer [`Image::read_exr_part`] decodes),
/// after the size checks; `((width, height), part)`.
fn part_of_header(meta: &exr::meta::MetaData) -> Result<((u32, u32), ExrPart), exr::error::Error> {
    let invalid = |m: String| exr::error::Error::Invalid(m.into());
    for header in meta.headers.iter() {
        let size = header.layer_size;
        if let Some(problem) = crate::input::size_problem(size.width(), size.height()) {
            return Err(invalid(problem));
        }
    }
    let header = meta
        .headers
        .first()
        .ok_or_else(|| invalid("no layer".into()))?;
    let display = header.shared_attributes.display_window;
    if let Some(problem) = crate::input::size_problem(display.size.0, display.size.1) {
        return Err(invalid(format!("display window: {problem}")));
    }
    let pos = header.own_attributes.layer_position;
    let size = header.layer_size;
    let (ox, oy) = (
        i64::from(pos.0) - i64::from(display.position.0),
        i64::from(pos.1) - i64::from(display.position.1),
    );
    if ox < 0
        || oy < 0
        || ox as u64 + size.0 as u64 > display.size.0 as u64
        || oy as u64 + size.1 as u64 > display.size.1 as u64
    {
        return Err(invalid(format!(
            "the data window ({}×{} at {ox},{oy}) is outside the display window ({}×{})",
            size.0, size.1, display.size.0, display.size.1
        )));
    }
    let mut attributes: Vec<(String, String)> = header
        .own_attributes
        .other
        .iter()
        .chain(header.shared_attributes.other.iter())
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(t) => Some((k.to_string(), t.to_string())),
            _ => None,
        })
        .collect();
    attributes.sort();
    Ok((
        (size.0 as u32, size.1 as u32),
        ExrPart {
            film: (display.size.0 as u32, display.size.1 as u32),
            offset: (ox as u32, oy as u32),
            attributes,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pixels, offset, film size and attributes survive a round trip.
    #[test]
    fn part_roundtrip() {
        let dir = restir_testkit::TempDir::new("image-part", "roundtrip");
        let path = dir.join("part.exr");
        let mut image = Image::new(3, 2);
        for (i, p) in image.pixels.iter_mut().enumerate() {
            *p = Vec3::new(i as f32, 0.25, -1.5 * i as f32);
        }
        let part = ExrPart {
            film: (10, 7),
            offset: (4, 5),
            attributes: vec![
                ("restir:passes".into(), "8..16".into()),
                ("restir:film".into(), "10x7".into()),
            ],
        };
        image.write_exr_part(&path, &part).unwrap();
        let (back, got) = Image::read_exr_part(&path).unwrap();
        assert_eq!(back, image);
        assert_eq!((got.film, got.offset), ((10, 7), (4, 5)));
        assert_eq!(got.attribute("restir:passes"), Some("8..16"));
        assert_eq!(got.attribute("restir:film"), Some("10x7"));
        // A plain render reads as a part covering its film, without attributes.
        image.write(&path).unwrap();
        let (_, plain) = Image::read_exr_part(&path).unwrap();
        assert_eq!((plain.film, plain.offset), ((3, 2), (0, 0)));
        assert!(plain.attribute("restir:passes").is_none());
    }

    /// A part whose display window claims more pixels than any image read may have, or whose
    /// data window lies outside it, is refused from its header; so is a FIFO (which would
    /// block).
    #[test]
    fn bad_part_headers_are_refused() {
        let dir = restir_testkit::TempDir::new("image-part", "bad");
        let path = dir.join("huge.exr");
        let image = Image::new(2, 2);
        let part = |film| ExrPart {
            film,
            offset: (0, 0),
            attributes: vec![],
        };
        image.write_exr_part(&path, &part((65536, 65536))).unwrap();
        let e = Image::read_exr_part(&path).unwrap_err().to_string();
        assert!(
            e.contains("display window: the image is 65536×65536 pixels"),
            "{e}"
        );
        assert!(Image::read_exr_part_header(&path).is_err());
        image.write_exr_part(&path, &part((1, 1))).unwrap();
        let e = Image::read_exr_part(&path).unwrap_err().to_string();
        assert!(e.contains("outside the display window"), "{e}");
        image.write_exr_part(&path, &part((2, 3))).unwrap();
        let (size, p) = Image::read_exr_part_header(&path).unwrap();
        assert_eq!((size, p.film), ((2, 2), (2, 3)));
        let fifo = dir.join("fifo.exr");
        if std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success())
        {
            let e = Image::read_exr_part(&fifo).unwrap_err().to_string();
            assert!(e.contains("not a regular file"), "{e}");
        }
    }
}
