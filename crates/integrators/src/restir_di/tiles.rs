//! Screen-tile light selection for ReSTIR DI's initial candidates (`--light-sampler tiles`).
//!
//! The power-based light sampler ignores distance, so in a scene of many small lights most
//! candidates land on lights far from the pixel. Here, once per pass, every 16×16-pixel tile gets
//! an alias table over the lights weighted by an estimate of their contribution to the tile
//! (power × a cosine term / squared distance from the tile's mean primary hit). A candidate's
//! light is drawn from the mixture `α·tile + (1 − α)·power` (α = 1/2): the power part keeps every
//! light with power sampleable, so initial resampling stays unbiased whatever the estimate gets
//! wrong; the candidate's source density is the mixture's, exactly. This is a light-sampling
//! change only — targets, reuse and the light/BSDF split are untouched. The tables cost
//! `lights × tiles` work per pass, so they are used up to [`MAX_LIGHTS`] lights.

use glam::Vec3;
use rayon::prelude::*;
use restir_sampling::AliasTable;
use restir_scene::Scene;

use crate::reuse::gbuffer::GBuffer;

/// Tile side in pixels.
pub const TILE: usize = 16;
/// Share of the per-tile distribution in the mixture.
pub const TILE_SHARE: f32 = 0.5;
/// Above this many lights the per-tile tables cost too much; the power sampler is used.
pub const MAX_LIGHTS: usize = 4096;

/// Per-tile light tables for one pass.
#[derive(Debug)]
pub struct LightTiles {
    tiles_x: usize,
    tables: Vec<Option<AliasTable>>,
}

impl LightTiles {
    /// Builds the tables for the primary hits of `gbuf`, or `None` if the scene has too many
    /// lights (or none).
    pub fn build(scene: &Scene, gbuf: &GBuffer) -> Option<Self> {
        let lights = &scene.lights;
        let n = lights.len();
        if n == 0 || n > MAX_LIGHTS {
            return None;
        }
        let tiles_x = gbuf.width.div_ceil(TILE);
        let tiles_y = gbuf.height.div_ceil(TILE);
        let far2 = lights.scene_radius() * lights.scene_radius();
        let tables = (0..tiles_x * tiles_y)
            .into_par_iter()
            .map(|t| {
                let (tx, ty) = (t % tiles_x, t / tiles_x);
                // Mean position and normal of the tile's hits, and how far they spread.
                let (mut sum_p, mut sum_n, mut count) = (Vec3::ZERO, Vec3::ZERO, 0u32);
                let rows = ty * TILE..((ty + 1) * TILE).min(gbuf.height);
                let cols = tx * TILE..((tx + 1) * TILE).min(gbuf.width);
                for y in rows.clone() {
                    for x in cols.clone() {
                        if let Some(r) = gbuf.receiver(y * gbuf.width + x) {
                            sum_p += r.p;
                            sum_n += r.n;
                            count += 1;
                        }
                    }
                }
                if count == 0 {
                    return None;
                }
                let p = sum_p / count as f32;
                let nrm = sum_n.normalize_or_zero();
                let mut spread2 = 0.0f32;
                for y in rows {
                    for x in cols.clone() {
                        if let Some(r) = gbuf.receiver(y * gbuf.width + x) {
                            spread2 = spread2.max((r.p - p).length_squared());
                        }
                    }
                }
                let weights: Vec<f32> = (0..n as u32)
                    .map(|l| {
                        let power = lights.power(l);
                        match lights.bounding_sphere(l) {
                            Some((c, radius)) => {
                                let to = c - p;
                                let d2 = to.length_squared();
                                let cos = if d2 > 0.0 {
                                    nrm.dot(to) / d2.sqrt()
                                } else {
                                    1.0
                                };
                                power * (cos.max(0.0) + 0.1) / d2.max(radius * radius + spread2)
                            }
                            None => power / far2,
                        }
                    })
                    .collect();
                AliasTable::new(&weights)
            })
            .collect();
        Some(Self { tiles_x, tables })
    }

    /// The table of the tile holding pixel `(x, y)`, if it has one.
    #[inline]
    pub fn table(&self, x: usize, y: usize) -> Option<&AliasTable> {
        self.tables[(y / TILE) * self.tiles_x + x / TILE].as_ref()
    }
}
