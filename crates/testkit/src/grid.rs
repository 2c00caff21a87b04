//! Grids that bin samples into histogram cells ([`Grid2D`] over a rectangle, [`SphereGrid`] over
//! directions) and the adaptive quadrature ([`Quadrature`]) that integrates a density over their
//! cells into the probabilities a chi-square test expects.

use core::f64::consts::PI;
use glam::Vec3;

// ------------------------------------------------------------------------------------------
// Grids and quadrature
// ------------------------------------------------------------------------------------------

/// How [`Grid2D::integrate`] integrates a density over each cell: a tensor-product Simpson rule,
/// made adaptive so that densities with discontinuities (the edge of a cone, a light's
/// silhouette) are still integrated accurately.
///
/// Each cell is split into `subdivisions × subdivisions` sub-cells. On each, the 3×3-point Simpson
/// rule is compared with the composite rule on its four quarters (5×5 points); if they differ by
/// more than `15 · tol` the quarters are refined recursively (each with half the parent's `tol`),
/// down to `max_depth` levels, else the Richardson-extrapolated fine value is kept. `tolerance` is
/// the target absolute error per cell in units of the density's integral (a probability): with
/// `N` samples the expected counts are off by about `N · tolerance`. Smooth densities meet it
/// with few evaluations; across a discontinuity the refinement stops at `max_depth`, where the
/// error is about `jump · cell area · 2^−(max_depth + 2) / subdivisions`.
///
/// Points on a cell's boundary are evaluated `1e-7` of the cell's width inside it, so that a
/// discontinuity exactly on a cell boundary (the horizon of a hemisphere, a step of a
/// piecewise-constant density) costs nothing and is attributed to the correct cell.
///
/// Features narrower than a sub-cell can fall between the sample points and be missed; the
/// chi-square test then fails (samples in cells with zero expected count) rather than passing
/// silently. Raise `subdivisions` for small features.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadrature {
    /// Sub-cells per axis in every cell before any refinement (at least 1).
    pub subdivisions: usize,
    /// Target absolute error per cell.
    pub tolerance: f64,
    /// Maximum number of adaptive refinements of a sub-cell.
    pub max_depth: u32,
}

impl Default for Quadrature {
    /// 4 × 4 sub-cells, tolerance 1e-8, depth 10: smooth densities are exact to ~1e-8, and a cell
    /// cut by a discontinuity is within ~1e-4 of its mass for the default grids.
    fn default() -> Self {
        Self {
            subdivisions: 4,
            tolerance: 1e-8,
            max_depth: 10,
        }
    }
}

/// Weights of the 1-D Simpson rule on three points, times 6.
const SIMPSON: [f64; 3] = [1.0, 4.0, 1.0];

/// Simpson's rule on a `w × h` rectangle from its 3 × 3 values `v[ix][iy]`.
#[inline]
fn simpson_3x3(v: &[[f64; 3]; 3], w: f64, h: f64) -> f64 {
    let mut s = 0.0;
    for (ix, row) in v.iter().enumerate() {
        for (iy, value) in row.iter().enumerate() {
            s += SIMPSON[ix] * SIMPSON[iy] * value;
        }
    }
    s * w * h / 36.0
}

/// Adaptive Simpson on `[x0, x0 + w] × [y0, y0 + h]` given the values at its 3 × 3 points.
#[allow(clippy::too_many_arguments)]
fn adaptive_simpson<F: Fn(f64, f64) -> f64>(
    f: &F,
    x0: f64,
    y0: f64,
    w: f64,
    h: f64,
    v: &[[f64; 3]; 3],
    tol: f64,
    depth: u32,
    max_depth: u32,
) -> f64 {
    let mut g = [[0.0f64; 5]; 5];
    for (ix, row) in g.iter_mut().enumerate() {
        for (iy, value) in row.iter_mut().enumerate() {
            *value = if ix % 2 == 0 && iy % 2 == 0 {
                v[ix / 2][iy / 2]
            } else {
                f(x0 + 0.25 * w * ix as f64, y0 + 0.25 * h * iy as f64)
            };
        }
    }
    let quarter = |qx: usize, qy: usize| {
        let mut q = [[0.0f64; 3]; 3];
        for (ix, row) in q.iter_mut().enumerate() {
            for (iy, value) in row.iter_mut().enumerate() {
                *value = g[2 * qx + ix][2 * qy + iy];
            }
        }
        q
    };
    let quarters = [quarter(0, 0), quarter(1, 0), quarter(0, 1), quarter(1, 1)];
    let (hw, hh) = (0.5 * w, 0.5 * h);
    let coarse = simpson_3x3(v, w, h);
    let fine: f64 = quarters.iter().map(|q| simpson_3x3(q, hw, hh)).sum();
    let diff = fine - coarse;
    if !diff.is_finite() || depth >= max_depth || diff.abs() <= 15.0 * tol {
        return fine + diff / 15.0;
    }
    let origins = [(x0, y0), (x0 + hw, y0), (x0, y0 + hh), (x0 + hw, y0 + hh)];
    quarters
        .iter()
        .zip(origins)
        .map(|(q, (qx, qy))| {
            adaptive_simpson(f, qx, qy, hw, hh, q, 0.5 * tol, depth + 1, max_depth)
        })
        .sum()
}

/// A regular grid of `nx × ny` cells over the rectangle `[x0, x1) × [y0, y1)`. Cell `(ix, iy)`
/// has index `iy · nx + ix`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid2D {
    x: (f64, f64),
    y: (f64, f64),
    nx: usize,
    ny: usize,
}

impl Grid2D {
    /// A grid over `[x.0, x.1) × [y.0, y.1)`. `None` if a count is zero or a range is empty or
    /// not finite.
    pub fn new(x: (f64, f64), nx: usize, y: (f64, f64), ny: usize) -> Option<Self> {
        let ok = |r: (f64, f64)| r.0.is_finite() && r.1.is_finite() && r.0 < r.1;
        (nx > 0 && ny > 0 && ok(x) && ok(y)).then_some(Self { x, y, nx, ny })
    }

    /// The unit square `[0, 1)²` with `nx × ny` cells (`None` if a count is zero).
    pub fn unit_square(nx: usize, ny: usize) -> Option<Self> {
        Self::new((0.0, 1.0), nx, (0.0, 1.0), ny)
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// Always false: a grid has at least one cell.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Cells per axis `(nx, ny)`.
    pub fn size(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// The cell containing `(x, y)`, or `None` if the point is outside `[x0, x1) × [y0, y1)` or
    /// not finite.
    #[inline]
    pub fn bin(&self, x: f64, y: f64) -> Option<usize> {
        let ix = Self::axis_bin(x, self.x, self.nx)?;
        let iy = Self::axis_bin(y, self.y, self.ny)?;
        Some(iy * self.nx + ix)
    }

    #[inline]
    fn axis_bin(v: f64, range: (f64, f64), n: usize) -> Option<usize> {
        if !(range.0..range.1).contains(&v) {
            return None;
        }
        let t = (v - range.0) / (range.1 - range.0) * n as f64;
        Some((t as usize).min(n - 1))
    }

    /// The bounds `((x_lo, x_hi), (y_lo, y_hi))` of cell `cell` (`None` if out of range).
    pub fn cell_bounds(&self, cell: usize) -> Option<((f64, f64), (f64, f64))> {
        if cell >= self.len() {
            return None;
        }
        let (ix, iy) = (cell % self.nx, cell / self.nx);
        let edge = |r: (f64, f64), n: usize, i: usize| r.0 + (r.1 - r.0) * i as f64 / n as f64;
        Some((
            (edge(self.x, self.nx, ix), edge(self.x, self.nx, ix + 1)),
            (edge(self.y, self.ny, iy), edge(self.y, self.ny, iy + 1)),
        ))
    }

    /// `∫ density` over every cell (see [`Quadrature`] for the rule and its accuracy). For a
    /// probability density these are the cell probabilities; multiplied by the sample count they
    /// are the expected counts.
    pub fn integrate<F: Fn(f64, f64) -> f64>(&self, density: F, quad: &Quadrature) -> Vec<f64> {
        (0..self.len())
            .map(|cell| {
                let ((x0, x1), (y0, y1)) = self.cell_bounds(cell).expect("cell index in range");
                integrate_rect(&density, (x0, x1), (y0, y1), quad)
            })
            .collect()
    }
}

/// How far inside a cell, relative to its width, the quadrature evaluates points on its boundary.
const EDGE_NUDGE: f64 = 1e-7;

/// Adaptive Simpson over one rectangle split into `quad.subdivisions²` sub-cells.
fn integrate_rect<F: Fn(f64, f64) -> f64>(
    f: &F,
    x: (f64, f64),
    y: (f64, f64),
    quad: &Quadrature,
) -> f64 {
    // Points on the cell's boundary are evaluated a hair inside it, so that a discontinuity lying
    // exactly on a cell boundary (the horizon of a hemisphere) is attributed to the right cell.
    let (ex, ey) = (EDGE_NUDGE * (x.1 - x.0), EDGE_NUDGE * (y.1 - y.0));
    let f = &|px: f64, py: f64| f(px.clamp(x.0 + ex, x.1 - ex), py.clamp(y.0 + ey, y.1 - ey));
    let s = quad.subdivisions.max(1);
    let (w, h) = ((x.1 - x.0) / s as f64, (y.1 - y.0) / s as f64);
    // Values on the (2s + 1)² lattice shared by neighbouring sub-cells.
    let m = 2 * s + 1;
    let mut lattice = vec![0.0f64; m * m];
    for ix in 0..m {
        for iy in 0..m {
            let px = if ix == m - 1 {
                x.1
            } else {
                x.0 + 0.5 * w * ix as f64
            };
            let py = if iy == m - 1 {
                y.1
            } else {
                y.0 + 0.5 * h * iy as f64
            };
            lattice[ix * m + iy] = f(px, py);
        }
    }
    let tol = quad.tolerance / (s * s) as f64;
    let mut total = 0.0;
    for sx in 0..s {
        for sy in 0..s {
            let mut v = [[0.0f64; 3]; 3];
            for (ix, row) in v.iter_mut().enumerate() {
                for (iy, value) in row.iter_mut().enumerate() {
                    *value = lattice[(2 * sx + ix) * m + 2 * sy + iy];
                }
            }
            let (x0, y0) = (x.0 + w * sx as f64, y.0 + h * sy as f64);
            total += adaptive_simpson(f, x0, y0, w, h, &v, tol, 0, quad.max_depth);
        }
    }
    total
}

/// A grid over the unit sphere of directions in `(cos θ, φ)`: `cos θ = z ∈ [−1, 1]` in equal
/// steps and `φ = atan2(y, x) ∈ [0, 2π)` in equal steps. Since `dω = d(cos θ) dφ`, every cell
/// has the same solid angle `4π / len()`, and a density per unit solid angle is also the density
/// over `(cos θ, φ)`, so cells are integrated without a Jacobian.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereGrid {
    grid: Grid2D,
}

impl Default for SphereGrid {
    /// 10 `cos θ` bins × 20 `φ` bins over the whole sphere.
    fn default() -> Self {
        Self::new(10, 20).expect("non-zero bin counts")
    }
}

impl SphereGrid {
    /// Directions whose length differs from 1 by more than this are rejected by
    /// [`SphereGrid::bin`]: a sampler of directions must return unit vectors.
    pub const UNIT_TOLERANCE: f32 = 1e-3;

    /// `cos_theta_bins × phi_bins` cells (`None` if a count is zero).
    pub fn new(cos_theta_bins: usize, phi_bins: usize) -> Option<Self> {
        Grid2D::new((-1.0, 1.0), cos_theta_bins, (0.0, 2.0 * PI), phi_bins)
            .map(|grid| Self { grid })
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.grid.len()
    }

    /// Always false: a grid has at least one cell.
    pub fn is_empty(&self) -> bool {
        self.grid.is_empty()
    }

    /// The underlying grid over `(cos θ, φ)`: cell `iφ · cos_theta_bins + i_cosθ`.
    pub fn grid(&self) -> &Grid2D {
        &self.grid
    }

    /// The unit direction with `cos θ = z` and azimuth `phi`.
    #[inline]
    pub fn direction(z: f64, phi: f64) -> Vec3 {
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (s, c) = phi.sin_cos();
        Vec3::new((r * c) as f32, (r * s) as f32, z as f32)
    }

    /// The cell of unit direction `w`; `None` if `w` is not finite or its length differs from 1
    /// by more than [`SphereGrid::UNIT_TOLERANCE`].
    #[inline]
    pub fn bin(&self, w: Vec3) -> Option<usize> {
        let len = w.length();
        if !len.is_finite() || (len - 1.0).abs() > Self::UNIT_TOLERANCE {
            return None;
        }
        let (x, y, z) = (w.x as f64, w.y as f64, w.z as f64);
        let z = (z / len as f64).clamp(-1.0, 1.0);
        let mut phi = y.atan2(x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        // Keep z = 1 and φ = 2π (rounding) in the last cells.
        let z = z.min(1.0 - f64::EPSILON);
        let phi = phi.min(2.0 * PI * (1.0 - f64::EPSILON));
        self.grid.bin(z, phi)
    }

    /// `∫ pdf_sa dω` over every cell, for a density per unit solid angle (see [`Quadrature`]).
    /// The sum over all cells is the integral over the sphere.
    pub fn integrate<F: Fn(Vec3) -> f64>(&self, pdf_sa: F, quad: &Quadrature) -> Vec<f64> {
        self.grid
            .integrate(|z, phi| pdf_sa(Self::direction(z, phi)), quad)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_binning() {
        let g = Grid2D::new((-1.0, 3.0), 4, (0.0, 1.0), 2).unwrap();
        assert_eq!(g.bin(-1.0, 0.0), Some(0));
        assert_eq!(g.bin(2.999, 0.99), Some(7));
        assert_eq!(g.bin(0.5, 0.5), Some(5));
        assert_eq!(g.bin(3.0, 0.5), None);
        assert_eq!(g.bin(0.0, f64::NAN), None);
        assert_eq!(g.cell_bounds(5), Some(((0.0, 1.0), (0.5, 1.0))));
        assert!(Grid2D::new((0.0, 0.0), 1, (0.0, 1.0), 1).is_none());
        assert!(Grid2D::unit_square(0, 3).is_none());

        let s = SphereGrid::default();
        assert_eq!(s.len(), 200);
        assert_eq!(s.bin(Vec3::Z), Some(9));
        assert_eq!(s.bin(Vec3::new(0.0, 0.0, -1.0)), Some(0));
        assert_eq!(s.bin(Vec3::new(0.0, -1.0, 0.0)), Some(15 * 10 + 5));
        assert_eq!(
            s.bin(Vec3::new(1.0, -1e-7, 0.0).normalize()),
            Some(19 * 10 + 5)
        );
        assert_eq!(s.bin(Vec3::new(0.0, 0.0, 1.1)), None);
        assert_eq!(s.bin(Vec3::NAN), None);
        for cell in 0..s.len() {
            let ((z0, z1), (p0, p1)) = s.grid().cell_bounds(cell).unwrap();
            let w = SphereGrid::direction(0.5 * (z0 + z1), 0.5 * (p0 + p1));
            assert_eq!(s.bin(w), Some(cell));
        }
    }

    /// Smooth densities are integrated to rounding; each cell has solid angle 4π / 200.
    #[test]
    fn integrate_smooth_densities() {
        let s = SphereGrid::default();
        let q = Quadrature::default();
        let uniform = s.integrate(|_| 0.25 / PI, &q);
        for p in &uniform {
            assert!((p - 1.0 / 200.0).abs() < 1e-12);
        }
        // ∫ z² dω over a cell = Δφ (z1³ − z0³) / 3: cubic in z, exact for Simpson.
        let quad = s.integrate(|w| (w.z as f64).powi(2), &q);
        for (cell, got) in quad.iter().enumerate() {
            let ((z0, z1), (p0, p1)) = s.grid().cell_bounds(cell).unwrap();
            let want = (p1 - p0) * (z1.powi(3) - z0.powi(3)) / 3.0;
            assert!(
                (got - want).abs() < 1e-7 * want.max(1e-3),
                "cell {cell}: {got} vs {want}"
            );
        }
        // A smooth non-polynomial lobe: e^(κ (w·a) − κ) κ / (2π (1 − e^(−2κ))) integrates to 1.
        let a = Vec3::new(0.3, -0.5, 0.81).normalize();
        let kappa = 6.0f64;
        let norm = kappa / (2.0 * PI * (1.0 - (-2.0 * kappa).exp()));
        let vmf = s.integrate(|w| norm * (kappa * (w.dot(a) as f64 - 1.0)).exp(), &q);
        let total: f64 = vmf.iter().sum();
        assert!((total - 1.0).abs() < 1e-6, "{total}");
    }

    /// A density with a discontinuity: the indicator of a cone around +z, whose cell integrals
    /// are known exactly; cells cut by the edge are within 1e-4 of their mass.
    #[test]
    fn integrate_discontinuous_density() {
        let s = SphereGrid::default();
        for cos_max in [0.83f64, 0.3, -0.55] {
            let pdf = 1.0 / (2.0 * PI * (1.0 - cos_max));
            let got = s.integrate(
                |w| if w.z as f64 >= cos_max { pdf } else { 0.0 },
                &Quadrature::default(),
            );
            for (cell, p) in got.iter().enumerate() {
                let ((z0, z1), (p0, p1)) = s.grid().cell_bounds(cell).unwrap();
                let overlap = (z1.min(1.0) - z0.max(cos_max)).max(0.0);
                let want = pdf * overlap * (p1 - p0);
                assert!(
                    (p - want).abs() <= 1e-4 * want + 1e-9,
                    "cos_max {cos_max}, cell {cell}: {p} vs {want}"
                );
            }
        }
        // An off-axis cap: the total is its probability, 1.
        let axis = Vec3::new(0.6, 0.0, 0.8);
        let cos_max = 0.9f64;
        let pdf = 1.0 / (2.0 * PI * (1.0 - cos_max));
        let got = s.integrate(
            |w| {
                if w.dot(axis) as f64 >= cos_max {
                    pdf
                } else {
                    0.0
                }
            },
            &Quadrature::default(),
        );
        let total: f64 = got.iter().sum();
        assert!((total - 1.0).abs() < 1e-4, "{total}");
    }
}
