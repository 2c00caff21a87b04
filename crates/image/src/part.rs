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

    /// Reads an EXR written by [`Image::write_exr_part`]: the data window's pixels, and where they
    /// sit with the text attributes. Files without attributes read as parts with none.
    pub fn read_exr_part(path: &Path) -> Result<(Self, ExrPart), ImageError> {
        let img = exr::prelude::read_first_rgba_layer_from_file(
            path,
            |res, _| (res.width(), vec![Vec3::ZERO; res.width() * res.height()]),
            |(w, px): &mut (usize, Vec<Vec3>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                if let Some(t) = px.get_mut(pos.y() * *w + pos.x()) {
                    *t = Vec3::new(r, g, b);
                }
            },
        )
        .map_err(|source| ImageError::ReadExr {
            path: path.to_path_buf(),
            source,
        })?;
        let layer = &img.layer_data;
        let mut attributes: Vec<(String, String)> = layer
            .attributes
            .other
            .iter()
            .chain(img.attributes.other.iter())
            .filter_map(|(k, v)| match v {
                AttributeValue::Text(t) => Some((k.to_string(), t.to_string())),
                _ => None,
            })
            .collect();
        attributes.sort();
        let display = img.attributes.display_window;
        let pos = layer.attributes.layer_position;
        let offset = (
            (pos.0 - display.position.0).max(0) as u32,
            (pos.1 - display.position.1).max(0) as u32,
        );
        let image = Self {
            width: layer.size.width() as u32,
            height: layer.size.height() as u32,
            pixels: layer.channel_data.pixels.1.clone(),
        };
        let part = ExrPart {
            film: (display.size.0 as u32, display.size.1 as u32),
            offset,
            attributes,
        };
        Ok((image, part))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pixels, offset, film size and attributes survive a round trip.
    #[test]
    fn part_roundtrip() {
        let dir = std::env::temp_dir().join(format!("restir-image-part-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
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
        std::fs::remove_dir_all(&dir).ok();
    }
}
