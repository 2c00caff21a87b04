//! Mitsuba 3's `envmap` emitter: a latitude-longitude image of radiance at infinity.
//!
//! # Mapping (Mitsuba 3.9, `src/emitters/envmap.cpp` and the `envmap` plugin reference)
//!
//! A world direction `ω` (pointing from the scene towards the sky) is taken to the emitter's
//! local frame, `v = to_world⁻¹·ω`, and then
//!
//! ```text
//! u = atan2(v.x, −v.z) / 2π  (wrapped to [0, 1)),     vv = θ/π,  θ = angle between v and +Y
//! d(u, vv) = (sin 2πu · sin πvv,  cos πvv,  −cos 2πu · sin πvv)
//! ```
//!
//! so `u = 0 → −Z`, `u = ¼ → +X`, `u = ½ → +Z`, `u = ¾ → −X`, and `vv = 0 → +Y` (the image's top
//! row), `vv = 1 → −Y`.
//!
//! # Lookup
//!
//! Bilinear, periodic in `u` with texel-centred columns (column `x` at `u = (x+½)/W`) and rows at
//! the corners (row `y` at `vv = y/(H−1)`, clamped), as Mitsuba 3.9: the first and last rows
//! sit exactly at the poles. Images one row high are padded to two equal rows.
//!
//! # Importance sampling
//!
//! The bilinear patches form a `W × (H−1)` grid (patch `(x, y)` spans columns `x, x+1` and rows
//! `y, y+1`, i.e. it is shifted by half a texel in `u`). Each patch gets the mean luminance of
//! its four corners times `sin θ` at its centre, and a piecewise-*constant* 2-D distribution
//! (a marginal over rows and one conditional per row) samples `(u, vv)` from that grid. A patch whose four corners are black is
//! black everywhere, so the density is positive wherever the radiance is. The solid-angle
//! density is `pdf_uv / (2π² sin θ)`. The patch is picked in O(1) by alias tables (one over the
//! rows, one per row over its patches) instead of binary searches through cdfs: the tables
//! (and the texels) of a large map do not stay in cache, and each cdf search cost several misses.
//!
//! Mitsuba instead warps with a piecewise-*bilinear* `Hierarchical2D` over the texels; the
//! expected image is the same, only the noise differs.

use core::f32::consts::PI;
use glam::{Mat3, Vec2, Vec3};
use restir_sampling::{AliasTable, luminance};

/// Piecewise-constant density on `[0, 1)²` over a `width × rows` grid, sampled by alias tables.
#[derive(Clone, Debug)]
struct PatchSampler {
    width: usize,
    rows: usize,
    marginal: AliasTable,
    /// One per row; a row of zero mass (never picked) gets a uniform table.
    conditional: Vec<AliasTable>,
}

impl PatchSampler {
    fn new(grid: &[f32], width: usize, rows: usize) -> Option<Self> {
        let row_sums: Vec<f32> = grid
            .chunks_exact(width)
            .map(|r| r.iter().map(|&v| v as f64).sum::<f64>() as f32)
            .collect();
        let marginal = AliasTable::new(&row_sums)?;
        let uniform = AliasTable::new(&vec![1.0; width])?;
        let conditional = grid
            .chunks_exact(width)
            .map(|r| AliasTable::new(r).unwrap_or_else(|| uniform.clone()))
            .collect();
        Some(Self {
            width,
            rows,
            marginal,
            conditional,
        })
    }

    /// A point of `[0, 1)²` and its density.
    #[inline]
    fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (row, pmf_row, ry) = self.marginal.sample(u.y);
        let (col, pmf_col, rx) = self.conditional[row].sample(u.x);
        let p = Vec2::new(
            ((col as f32 + rx) / self.width as f32).min(restir_sampling::ONE_MINUS_EPSILON),
            ((row as f32 + ry) / self.rows as f32).min(restir_sampling::ONE_MINUS_EPSILON),
        );
        (p, pmf_row * pmf_col * (self.width * self.rows) as f32)
    }

    /// The density of [`PatchSampler::sample`] at `p ∈ [0, 1)²`.
    #[inline]
    fn pdf(&self, p: Vec2) -> f32 {
        let row = ((p.y * self.rows as f32) as usize).min(self.rows - 1);
        let col = ((p.x * self.width as f32) as usize).min(self.width - 1);
        self.marginal.pmf(row) * self.conditional[row].pmf(col) * (self.width * self.rows) as f32
    }
}

/// A latitude-longitude environment map with its sampling distribution.
#[derive(Clone, Debug)]
pub struct EnvMap {
    width: usize,
    height: usize,
    /// `width × height` radiances (scale applied), the first row at the top (`vv = 0`, +Y).
    texels: Vec<Vec3>,
    to_world: Mat3,
    to_local: Mat3,
    /// Over the `width × (height − 1)` bilinear patches; `None` for a black map.
    dist: Option<PatchSampler>,
    /// `∫ lum(L(ω)) dω` over the sphere (of the sampling grid).
    luminance_integral: f32,
}

/// Why [`EnvMap::new`] refused its input.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvMapError {
    /// The texel count is not `width × height` (or the image is empty).
    TexelCount {
        /// Width in texels.
        width: usize,
        /// Height in texels.
        height: usize,
        /// Texels given.
        texels: usize,
    },
    /// The radiance scale is negative or not finite.
    Scale(f32),
    /// A texel is negative or not finite.
    Texels,
    /// `to_world` scales, shears or projects.
    NotRotation,
}

impl std::fmt::Display for EnvMapError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EnvMapError::TexelCount {
                width,
                height,
                texels,
            } => write!(f, "envmap image of {width}×{height} has {texels} texels"),
            EnvMapError::Scale(scale) => {
                write!(f, "envmap scale {scale} must be finite and non-negative")
            }
            EnvMapError::Texels => f.write_str("envmap image has negative or non-finite texels"),
            EnvMapError::NotRotation => {
                f.write_str("envmap to_world must be a rotation (no scale, shear or projection)")
            }
        }
    }
}

impl std::error::Error for EnvMapError {}

impl EnvMap {
    /// Builds from `width × height` linear RGB texels (first row at the top), a radiance `scale`
    /// and the rotation `to_world` (an orthogonal matrix: the map's local frame in world space).
    pub fn new(
        width: usize,
        height: usize,
        texels: Vec<Vec3>,
        scale: f32,
        to_world: Mat3,
    ) -> Result<Self, EnvMapError> {
        if width == 0 || height == 0 || texels.len() != width * height {
            return Err(EnvMapError::TexelCount {
                width,
                height,
                texels: texels.len(),
            });
        }
        if !(scale.is_finite() && scale >= 0.0) {
            return Err(EnvMapError::Scale(scale));
        }
        if texels
            .iter()
            .any(|t| !t.is_finite() || t.min_element() < 0.0)
        {
            return Err(EnvMapError::Texels);
        }
        // Only rotations (and reflections) keep directions unit length and the density's
        // Jacobian 1; reject scale and shear.
        let gram = to_world.transpose() * to_world;
        if !to_world.is_finite() || !gram.abs_diff_eq(Mat3::IDENTITY, 1e-3) {
            return Err(EnvMapError::NotRotation);
        }
        let mut texels: Vec<Vec3> = texels.into_iter().map(|t| t * scale).collect();
        let height = if height == 1 {
            texels.extend_from_within(..);
            2
        } else {
            height
        };
        let rows = height - 1;
        let mut grid = vec![0.0f32; width * rows];
        let mut sum = 0.0f64;
        for y in 0..rows {
            let sin_theta = (PI * (y as f32 + 0.5) / rows as f32).sin();
            for x in 0..width {
                let x1 = (x + 1) % width;
                let l = luminance(texels[y * width + x])
                    + luminance(texels[y * width + x1])
                    + luminance(texels[(y + 1) * width + x])
                    + luminance(texels[(y + 1) * width + x1]);
                let v = 0.25 * l * sin_theta;
                grid[y * width + x] = v;
                sum += v as f64;
            }
        }
        let dist = PatchSampler::new(&grid, width, rows);
        // ∫ f(u, vv)·2π² du dvv over the unit square, f = lum·sin θ.
        let luminance_integral = (2.0 * PI as f64 * PI as f64 * sum / (width * rows) as f64) as f32;
        Ok(Self {
            width,
            height,
            texels,
            to_world,
            to_local: to_world.inverse(),
            dist,
            luminance_integral,
        })
    }

    /// Image size `(width, height)` (after padding).
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// `∫ lum(L(ω)) dω` over the sphere, from the sampling grid (patch means × `sin θ` at the
    /// patch centres). The light's power is `π R²` times this ([`crate::LightSet::power`]).
    pub fn luminance_integral(&self) -> f32 {
        self.luminance_integral
    }

    /// Whether the map is black everywhere (nothing to sample).
    pub fn is_black(&self) -> bool {
        self.dist.is_none()
    }

    /// Map coordinates `(u, vv)` of a local (map-frame) unit direction.
    #[inline]
    pub fn local_to_uv(v: Vec3) -> Vec2 {
        let mut u = v.x.atan2(-v.z) * (0.5 / PI);
        if u < 0.0 {
            u += 1.0;
        }
        if u >= 1.0 {
            u = 0.0;
        }
        let vv = (v.x.hypot(v.z).atan2(v.y) / PI).clamp(0.0, 1.0);
        Vec2::new(u, vv)
    }

    /// The local (map-frame) unit direction of map coordinates `(u, vv)`.
    #[inline]
    pub fn uv_to_local(uv: Vec2) -> Vec3 {
        let (sp, cp) = (2.0 * PI * uv.x).sin_cos();
        let (st, ct) = (PI * uv.y).sin_cos();
        Vec3::new(sp * st, ct, -cp * st)
    }

    /// Radiance at map coordinates `(u, vv)` (bilinear, Mitsuba 3.9's texel placement).
    #[inline]
    pub fn eval_uv(&self, uv: Vec2) -> Vec3 {
        let (w, h) = (self.width, self.height);
        let fx = uv.x * w as f32 - 0.5;
        let x0f = fx.floor();
        let tx = fx - x0f;
        let x0 = (x0f as i64).rem_euclid(w as i64) as usize;
        let x1 = (x0 + 1) % w;
        let fy = (uv.y.clamp(0.0, 1.0) * (h - 1) as f32).max(0.0);
        let y0 = (fy as usize).min(h - 2);
        let ty = (fy - y0 as f32).clamp(0.0, 1.0);
        let row = |y: usize| self.texels[y * w + x0] * (1.0 - tx) + self.texels[y * w + x1] * tx;
        row(y0) * (1.0 - ty) + row(y0 + 1) * ty
    }

    /// Radiance arriving from world direction `d` (unit, pointing away from the scene).
    #[inline]
    pub fn eval(&self, d: Vec3) -> Vec3 {
        let v = (self.to_local * d).normalize_or_zero();
        self.eval_uv(Self::local_to_uv(v))
    }

    /// Samples a world direction ∝ luminance × sin θ: `(direction, radiance, pdf per unit solid
    /// angle)`. `None` for a black map or a sample exactly at a pole.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, Vec3, f32)> {
        self.sample_uv(u).map(|(_, d, le, pdf)| (d, le, pdf))
    }

    /// [`EnvMap::sample`] with the map coordinates of the direction: `(uv, direction, radiance,
    /// pdf per unit solid angle)`.
    #[inline]
    pub fn sample_uv(&self, u: Vec2) -> Option<(Vec2, Vec3, Vec3, f32)> {
        let dist = self.dist.as_ref()?;
        let (st, pdf_uv) = dist.sample(u);
        let mut uu = st.x + 0.5 / self.width as f32;
        if uu >= 1.0 {
            uu -= 1.0;
        }
        let uv = Vec2::new(uu, st.y);
        let sin_theta = (PI * uv.y).sin();
        if !(sin_theta > 0.0 && pdf_uv > 0.0) {
            return None;
        }
        let d = self.world_direction(uv);
        let pdf = pdf_uv / (2.0 * PI * PI * sin_theta);
        Some((uv, d, self.eval_uv(uv), pdf))
    }

    /// The world direction of map coordinates `uv`.
    #[inline]
    pub fn world_direction(&self, uv: Vec2) -> Vec3 {
        (self.to_world * Self::uv_to_local(uv)).normalize()
    }

    /// Map coordinates of world direction `d` (unit).
    #[inline]
    pub fn uv_of(&self, d: Vec3) -> Vec2 {
        Self::local_to_uv((self.to_local * d).normalize_or_zero())
    }

    /// The solid-angle density of [`EnvMap::sample`] at map coordinates `uv` (the density of
    /// [`EnvMap::pdf`] without finding the coordinates of a direction).
    #[inline]
    pub fn pdf_uv(&self, uv: Vec2) -> f32 {
        self.pdf_at(uv, (PI * uv.y).sin())
    }

    /// The solid-angle density of [`EnvMap::sample`] at world direction `d`.
    #[inline]
    pub fn pdf(&self, d: Vec3) -> f32 {
        let v = (self.to_local * d).normalize_or_zero();
        self.pdf_at(Self::local_to_uv(v), v.x.hypot(v.z))
    }

    /// The solid-angle density at map coordinates `uv` whose polar angle has sine `sin_theta`:
    /// the map distribution's density (texel centres at half a column) over the Jacobian
    /// `2π² sin θ` of the (u, v) → direction map.
    #[inline]
    fn pdf_at(&self, uv: Vec2, sin_theta: f32) -> f32 {
        let Some(dist) = self.dist.as_ref() else {
            return 0.0;
        };
        if sin_theta.is_nan() || sin_theta <= 0.0 {
            return 0.0;
        }
        let mut s = uv.x - 0.5 / self.width as f32;
        if s < 0.0 {
            s += 1.0;
        }
        let p = Vec2::new(
            s.min(restir_sampling::ONE_MINUS_EPSILON),
            uv.y.min(restir_sampling::ONE_MINUS_EPSILON),
        );
        dist.pdf(p) / (2.0 * PI * PI * sin_theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 8×5 map whose texels encode their own column and row, so lookups can be checked.
    fn indexed() -> EnvMap {
        let (w, h) = (8, 5);
        let texels = (0..h)
            .flat_map(|y| (0..w).map(move |x| Vec3::new(x as f32, y as f32, 1.0)))
            .collect();
        EnvMap::new(w, h, texels, 1.0, Mat3::IDENTITY).unwrap()
    }

    /// Mitsuba 3.9's documented orientation: u = 0 → −Z, ¼ → +X, ½ → +Z, ¾ → −X; vv = 0 → +Y.
    #[test]
    fn orientation_matches_mitsuba() {
        let cases = [
            (-Vec3::Z, Vec2::new(0.0, 0.5)),
            (Vec3::X, Vec2::new(0.25, 0.5)),
            (Vec3::Z, Vec2::new(0.5, 0.5)),
            (-Vec3::X, Vec2::new(0.75, 0.5)),
        ];
        for (d, uv) in cases {
            let got = EnvMap::local_to_uv(d);
            assert!((got - uv).abs().max_element() < 1e-6, "{d} → {got}");
            assert!((EnvMap::uv_to_local(uv) - d).length() < 1e-6, "{uv}");
        }
        assert!(EnvMap::local_to_uv(Vec3::Y).y.abs() < 1e-6);
        assert!((EnvMap::local_to_uv(-Vec3::Y).y - 1.0).abs() < 1e-6);
        // Column x sits at u = (x + ½)/W; row y at vv = y/(H − 1).
        let m = indexed();
        for x in 0..8 {
            for y in 0..5 {
                let uv = Vec2::new((x as f32 + 0.5) / 8.0, y as f32 / 4.0);
                let l = m.eval_uv(uv);
                assert!(
                    (l - Vec3::new(x as f32, y as f32, 1.0)).length() < 1e-4,
                    "{uv}: {l}"
                );
            }
        }
        // +Y is the top row; −Z (u = 0) is halfway between the last and the first column.
        assert!((m.eval(Vec3::Y).y).abs() < 1e-5);
        assert!((m.eval(-Vec3::Y).y - 4.0).abs() < 1e-5);
        assert!(
            (m.eval(-Vec3::Z).x - 3.5).abs() < 1e-4,
            "{}",
            m.eval(-Vec3::Z)
        );
        assert!((m.eval(Vec3::X).x - 1.5).abs() < 1e-4);
        // to_world rotates the map: a map turned 90° about +Y shows at +X what was at −Z...
        let r = Mat3::from_rotation_y(core::f32::consts::FRAC_PI_2);
        let t: Vec<Vec3> = (0..5)
            .flat_map(|y| (0..8).map(move |x| Vec3::new(x as f32, y as f32, 1.0)))
            .collect();
        let rm = EnvMap::new(8, 5, t, 2.0, r).unwrap();
        for d in [Vec3::X, -Vec3::Z, Vec3::new(0.3, 0.4, -0.5).normalize()] {
            assert!((rm.eval(r * d) - 2.0 * m.eval(d)).length() < 1e-4);
        }
    }

    /// Sampled directions report the density `pdf` recomputes, and a constant map is sampled with
    /// a density that integrates to one.
    #[test]
    fn sample_and_pdf_agree() {
        let (w, h) = (16, 9);
        let texels = (0..w * h)
            .map(|i| Vec3::splat(((i * 7919) % 13) as f32 * 0.3 + (i % 5 == 0) as u8 as f32 * 5.0))
            .collect();
        let r = Mat3::from_rotation_x(0.4) * Mat3::from_rotation_z(1.1);
        let m = EnvMap::new(w, h, texels, 1.5, r).unwrap();
        let mut rng = restir_sampling::Pcg32::new(5, 0);
        let (mut n, mut off) = (0, 0);
        for _ in 0..100_000 {
            let Some((d, l, pdf)) = m.sample(rng.next_2d()) else {
                continue;
            };
            n += 1;
            assert!((d.length() - 1.0).abs() < 1e-5);
            assert!((l - m.eval(d)).length() <= 1e-3 * l.length().max(1.0));
            let p = m.pdf(d);
            // Directions within rounding of a patch boundary may be assigned to the neighbour.
            if (p - pdf).abs() > 1e-3 * pdf {
                off += 1;
            }
        }
        assert!(n > 99_000);
        assert!(off * 1000 < n, "{off} of {n} pdfs disagree");
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(EnvMap::new(2, 2, vec![Vec3::ONE; 3], 1.0, Mat3::IDENTITY).is_err());
        assert!(EnvMap::new(2, 2, vec![Vec3::ONE; 4], -1.0, Mat3::IDENTITY).is_err());
        assert!(EnvMap::new(2, 2, vec![Vec3::NAN; 4], 1.0, Mat3::IDENTITY).is_err());
        let s = Mat3::from_diagonal(Vec3::new(1.0, 2.0, 1.0));
        assert!(EnvMap::new(2, 2, vec![Vec3::ONE; 4], 1.0, s).is_err());
        let one_row = EnvMap::new(3, 1, vec![Vec3::ONE; 3], 1.0, Mat3::IDENTITY).unwrap();
        assert_eq!(one_row.size(), (3, 2));
        let black = EnvMap::new(2, 2, vec![Vec3::ZERO; 4], 1.0, Mat3::IDENTITY).unwrap();
        assert!(black.is_black() && black.sample(Vec2::splat(0.5)).is_none());
    }
}
