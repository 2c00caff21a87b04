//! A scene's strip of crops as one image: the crops side by side, enlarged, with white gaps.

use glam::Vec3;
use restir_image::Image;

use crate::records::Strip;

/// Pixels of gap between crops in a strip.
pub const STRIP_GAP: u32 = 4;

/// Each crop's pixels are drawn as `k × k` blocks, `k` making the crop about 128 pixels tall.
pub(crate) fn strip_scale(strip: &Strip) -> u32 {
    let (_, _, w, h) = strip.crop;
    (128 / w.max(h).max(1)).clamp(1, 8)
}

pub(crate) fn strip_image(strip: &Strip) -> Image {
    let k = strip_scale(strip);
    let (_, _, cw, ch) = strip.crop;
    let n = strip.crops.len() as u32;
    let width = n * cw * k + n.saturating_sub(1) * STRIP_GAP;
    let mut out = Image::new(width, ch * k);
    for p in &mut out.pixels {
        *p = Vec3::splat(1.0);
    }
    for (i, c) in strip.crops.iter().enumerate() {
        let x0 = i as u32 * (cw * k + STRIP_GAP);
        for y in 0..ch * k {
            for x in 0..cw * k {
                out.pixels[(y * width + x0 + x) as usize] = c.get(x / k, y / k);
            }
        }
    }
    out
}
