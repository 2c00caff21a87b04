//! Mitsuba 3's `sdfgrid` (plugin page "SDF Grid (sdfgrid)"): a signed distance function sampled
//! on an `n³` grid of corner values spanning the unit cube `[0, 1]³` of object space, placed by
//! `to_world`. The surface is the zero set of the trilinear interpolant, intersected voxel by
//! voxel (Hansson-Söderlund, Evans and Akenine-Möller, "Ray Tracing of Signed Distance Function
//! Grids", JCGT 11(3), 2022): along a ray the interpolant in one voxel is a cubic, whose first
//! root in the voxel is isolated between the roots of its derivative and then refined.
//!
//! Only voxels whose corners do not all share one strict sign hold surface; each is one
//! primitive of the BVH. The geometric normal is the gradient of the voxel's interpolant. The
//! shading normal is the gradient (`analytic`) or, Mitsuba's default `smooth`, the blend the
//! paper proposes: the normalised gradients of the eight voxels around the nearest grid corner,
//! each evaluated at the point, weighted trilinearly by the point's position between the
//! voxels' centres (voxels outside the grid left out), which is continuous across voxels.
//!
//! As in Mitsuba, the shape has no texture coordinates (uv is zero) and cannot emit.
//!
//! A point is named by its voxel (the primitive) and its position in the voxel, three 16-bit
//! fractions packed into the two exactly representable integers of the parameters (see
//! [`SdfGrid::param_of`]): a resolution of 1/65 535 of a voxel.

use std::sync::Arc;

use glam::{Affine3A, Mat3A, Vec2, Vec3, Vec3A};

/// How shading normals are computed (Mitsuba's `normals`: `smooth` by default).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SdfNormals {
    /// The gradient of the voxel's trilinear interpolant (the geometric normal).
    Analytic,
    /// The paper's blend of the neighbouring voxels' gradients, continuous across voxels.
    Smooth,
}

/// A signed distance grid (see the module documentation).
#[derive(Clone, Debug)]
pub struct SdfGrid {
    /// Corner values per axis.
    n: u32,
    /// `n³` values, `x` fastest then `y` then `z`.
    values: Arc<[f32]>,
    /// The voxels holding surface, by linear voxel index `x + (n−1)(y + (n−1) z)`.
    voxels: Arc<[u32]>,
    to_world: Affine3A,
    to_object: Affine3A,
    /// Object-to-world for normals (the inverse transpose).
    normal_to_world: Mat3A,
    normals: SdfNormals,
}

impl SdfGrid {
    /// The grid of `n³` values (`x` fastest), placed by `to_world`. Refused (with the reason)
    /// when `n < 2`, the count is not `n³`, a value is not finite, or no voxel holds surface.
    pub fn new(
        n: u32,
        values: Vec<f32>,
        to_world: Affine3A,
        normals: SdfNormals,
    ) -> Result<Self, String> {
        if n < 2 {
            return Err(format!(
                "an sdfgrid needs at least 2 values per axis, not {n}"
            ));
        }
        let count = (n as u64).pow(3);
        if values.len() as u64 != count {
            return Err(format!(
                "an sdfgrid of {n}³ needs {count} values, not {}",
                values.len()
            ));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(format!("sdfgrid value {i} is not finite ({})", values[i]));
        }
        let det = to_world.matrix3.determinant();
        if !(det.is_finite() && det != 0.0) {
            return Err("sdfgrid transform is degenerate (zero scale)".into());
        }
        let mut grid = Self {
            n,
            values: values.into(),
            voxels: Arc::new([]),
            to_world,
            to_object: to_world.inverse(),
            normal_to_world: to_world.matrix3.inverse().transpose(),
            normals,
        };
        let m = n - 1;
        let mut voxels = Vec::new();
        for z in 0..m {
            for y in 0..m {
                for x in 0..m {
                    let c = grid.corners([x, y, z]);
                    let all_pos = c.iter().all(|&v| v > 0.0);
                    let all_neg = c.iter().all(|&v| v < 0.0);
                    if !(all_pos || all_neg) {
                        voxels.push(x + m * (y + m * z));
                    }
                }
            }
        }
        if voxels.is_empty() {
            return Err("the sdfgrid holds no surface (its values never change sign)".to_string());
        }
        grid.voxels = voxels.into();
        Ok(grid)
    }

    /// Values per axis.
    pub fn resolution(&self) -> u32 {
        self.n
    }

    /// The number of voxels holding surface (the shape's primitives).
    pub fn voxel_count(&self) -> usize {
        self.voxels.len()
    }

    /// How shading normals are computed.
    pub fn normals(&self) -> SdfNormals {
        self.normals
    }

    /// The object-to-world transform.
    pub fn to_world(&self) -> Affine3A {
        self.to_world
    }

    /// The bytes the grid keeps (values and voxel list).
    pub fn bytes(&self) -> usize {
        4 * (self.values.len() + self.voxels.len())
    }

    fn voxel_coords(&self, prim: u32) -> [u32; 3] {
        let m = self.n - 1;
        let i = self.voxels[prim as usize];
        [i % m, (i / m) % m, i / (m * m)]
    }

    #[inline]
    fn value(&self, x: u32, y: u32, z: u32) -> f32 {
        let n = self.n as usize;
        self.values[x as usize + n * (y as usize + n * z as usize)]
    }

    /// The eight corner values of voxel `v`, corner `i` at offset `(i & 1, i >> 1 & 1, i >> 2)`.
    fn corners(&self, v: [u32; 3]) -> [f32; 8] {
        core::array::from_fn(|i| {
            self.value(
                v[0] + (i as u32 & 1),
                v[1] + (i as u32 >> 1 & 1),
                v[2] + (i as u32 >> 2),
            )
        })
    }

    /// The trilinear interpolant at grid coordinates `g` (corner `i` at `g = i`), coordinates
    /// clamped to the grid as Mitsuba's clamped texture lookup does.
    fn sample(&self, g: Vec3) -> f32 {
        let top = (self.n - 1) as f32;
        let g = g.clamp(Vec3::ZERO, Vec3::splat(top));
        let base = g.floor().min(Vec3::splat(top - 1.0));
        let f = g - base;
        let v = [base.x as u32, base.y as u32, base.z as u32];
        trilinear(&self.corners(v), f)
    }

    /// The gradient (in grid units) of voxel `v`'s interpolant, as Mitsuba evaluates it at `g`:
    /// the differences of the clamped interpolant across the voxel's faces, the other two
    /// coordinates at `g`'s.
    fn voxel_gradient(&self, g: Vec3, v: [i32; 3]) -> Vec3 {
        let mut d = Vec3::ZERO;
        for axis in 0..3 {
            let (mut hi, mut lo) = (g, g);
            hi[axis] = (v[axis] + 1) as f32;
            lo[axis] = v[axis] as f32;
            d[axis] = self.sample(hi) - self.sample(lo);
        }
        d
    }

    /// World-space bounds of primitive (voxel) `prim`.
    pub fn voxel_bounds(&self, prim: u32) -> (Vec3, Vec3) {
        let v = self.voxel_coords(prim);
        let h = 1.0 / (self.n - 1) as f32;
        let lo = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32) * h;
        let (mut a, mut b) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for i in 0..8 {
            let c = lo + Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2) as f32) * h;
            let p = self.to_world.transform_point3(c);
            a = a.min(p);
            b = b.max(p);
        }
        (a, b)
    }

    /// World-space bounds of the whole grid.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let (mut a, mut b) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for i in 0..8 {
            let c = Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2) as f32);
            let p = self.to_world.transform_point3(c);
            a = a.min(p);
            b = b.max(p);
        }
        (a, b)
    }

    /// The distance along `o + t·d` (world space) of the first surface crossing inside voxel
    /// `prim` with `t_min < t < t_max` (`t_min` the rounding bound of the origin); infinity
    /// when none.
    pub fn intersect(&self, prim: u32, o: Vec3A, d: Vec3A, t_max: f32) -> f32 {
        let v = self.voxel_coords(prim);
        let scale = (self.n - 1) as f32;
        // The ray in this voxel's coordinates (the voxel is [0, 1]³); t is unchanged.
        let lo = self.to_object.transform_point3a(o);
        let ld = self.to_object.matrix3 * d;
        let go = lo * scale - Vec3A::new(v[0] as f32, v[1] as f32, v[2] as f32);
        let gd = ld * scale;
        let t_min = crate::accel::REL_T_MIN * (lo.abs().max_element() + 1.0) / ld.length();
        // Slabs.
        let (mut t0, mut t1) = (t_min, t_max);
        for a in 0..3 {
            let inv = 1.0 / gd[a];
            let (mut near, mut far) = (-go[a] * inv, (1.0 - go[a]) * inv);
            if near > far {
                core::mem::swap(&mut near, &mut far);
            }
            if near.is_nan() || far.is_nan() {
                // Parallel to the slab and on its boundary plane: inside when within it.
                if !(0.0..=1.0).contains(&go[a]) {
                    return f32::INFINITY;
                }
                continue;
            }
            t0 = t0.max(near);
            t1 = t1.min(far);
        }
        if t0 >= t1 {
            return f32::INFINITY;
        }
        let start = go + t0 * gd;
        let poly = cubic_along(&self.corners(v), start.into(), gd.into());
        match first_root(poly, t1 - t0) {
            Some(s) if t0 + s < t_max => t0 + s,
            _ => f32::INFINITY,
        }
    }

    /// The parameters naming world point `p` in voxel `prim`: its position in the voxel, each
    /// coordinate clamped to the voxel and quantised to 16 bits, `x` and the high byte of `z` in
    /// the first, `y` and the low byte of `z` in the second (integers below 2²⁴, exact in `f32`).
    pub fn param_of(&self, prim: u32, p: Vec3) -> Vec2 {
        let v = self.voxel_coords(prim);
        let g = self.to_object.transform_point3(p) * (self.n - 1) as f32
            - Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
        let q = (g.clamp(Vec3::ZERO, Vec3::ONE) * 65_535.0).round();
        let (x, y, z) = (q.x as u32, q.y as u32, q.z as u32);
        Vec2::new(((x << 8) | (z >> 8)) as f32, ((y << 8) | (z & 255)) as f32)
    }

    /// The surface point named by `(prim, param)`: its position, geometric normal and shading
    /// normal (both unit, world space).
    pub fn point_at(&self, prim: u32, param: Vec2) -> (Vec3, Vec3, Vec3) {
        let v = self.voxel_coords(prim);
        let (a, b) = (param.x as u32, param.y as u32);
        let q = Vec3::new(
            (a >> 8) as f32,
            (b >> 8) as f32,
            (((a & 255) << 8) | (b & 255)) as f32,
        ) / 65_535.0;
        let g = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32) + q;
        let p = self.to_world.transform_point3(g / (self.n - 1) as f32);
        let vi = [v[0] as i32, v[1] as i32, v[2] as i32];
        let ng = self.world_normal(self.voxel_gradient(g, vi));
        let ns = match self.normals {
            SdfNormals::Analytic => ng,
            SdfNormals::Smooth => {
                let s = self.world_normal(self.smooth_gradient(g));
                if s == Vec3::ZERO { ng } else { s }
            }
        };
        (p, ng, ns)
    }

    /// An object-space gradient in grid units as a unit world-space normal (zero if it is zero).
    fn world_normal(&self, grad: Vec3) -> Vec3 {
        // Grid units to object units scale every axis alike, so the direction is unchanged.
        Vec3::from(self.normal_to_world * Vec3A::from(grad)).normalize_or_zero()
    }

    /// The smooth shading normal's direction (object space) at grid coordinates `g`.
    fn smooth_gradient(&self, g: Vec3) -> Vec3 {
        let base = g.round() - Vec3::ONE;
        let b = [base.x as i32, base.y as i32, base.z as i32];
        let mut normals = [Vec3::ZERO; 8];
        let mut valid = [false; 8];
        for (i, (n, ok)) in normals.iter_mut().zip(&mut valid).enumerate() {
            let v = [
                b[0] + (i as i32 & 1),
                b[1] + (i as i32 >> 1 & 1),
                b[2] + (i as i32 >> 2),
            ];
            *ok = v.iter().all(|&c| c >= 0);
            if *ok {
                *n = self.voxel_gradient(g, v).normalize_or_zero();
            }
        }
        // The weights: the position between the centres of the two voxels on each axis, fixed to
        // the valid side where one side lies outside the grid.
        let mut w = g - base - Vec3::splat(0.5);
        for axis in 0..3 {
            let bit = 1 << axis;
            let side_invalid = |side: usize| {
                (0..8)
                    .filter(|i| (i & bit != 0) as usize == side)
                    .all(|i| !valid[i])
            };
            if side_invalid(0) {
                w[axis] = 1.0;
            }
            if side_invalid(1) {
                w[axis] = 0.0;
            }
        }
        trilinear_vec(&normals, w)
    }
}

/// The trilinear blend of the eight corner values at `f ∈ [0, 1]³`.
fn trilinear(c: &[f32; 8], f: Vec3) -> f32 {
    let x00 = c[0] + (c[1] - c[0]) * f.x;
    let x10 = c[2] + (c[3] - c[2]) * f.x;
    let x01 = c[4] + (c[5] - c[4]) * f.x;
    let x11 = c[6] + (c[7] - c[6]) * f.x;
    let y0 = x00 + (x10 - x00) * f.y;
    let y1 = x01 + (x11 - x01) * f.y;
    y0 + (y1 - y0) * f.z
}

fn trilinear_vec(c: &[Vec3; 8], f: Vec3) -> Vec3 {
    let l = |a: Vec3, b: Vec3, t: f32| (1.0 - t) * a + t * b;
    let y0 = l(l(c[0], c[1], f.x), l(c[2], c[3], f.x), f.y);
    let y1 = l(l(c[4], c[5], f.x), l(c[6], c[7], f.x), f.y);
    l(y0, y1, f.z)
}

/// The coefficients `[c0, c1, c2, c3]` of the voxel's interpolant along `o + s·d` (voxel
/// coordinates) as a cubic in `s`: each corner's weight is a product of three linear factors.
fn cubic_along(c: &[f32; 8], o: Vec3, d: Vec3) -> [f32; 4] {
    let mut out = [0.0f32; 4];
    for (i, &value) in c.iter().enumerate() {
        let factor = |bit: bool, o: f32, d: f32| if bit { (o, d) } else { (1.0 - o, -d) };
        let (a0, a1) = factor(i & 1 != 0, o.x, d.x);
        let (b0, b1) = factor(i & 2 != 0, o.y, d.y);
        let (e0, e1) = factor(i & 4 != 0, o.z, d.z);
        out[0] += value * a0 * b0 * e0;
        out[1] += value * (a1 * b0 * e0 + a0 * b1 * e0 + a0 * b0 * e1);
        out[2] += value * (a1 * b1 * e0 + a1 * b0 * e1 + a0 * b1 * e1);
        out[3] += value * a1 * b1 * e1;
    }
    out
}

fn eval_cubic(c: [f32; 4], s: f32) -> f32 {
    ((c[3] * s + c[2]) * s + c[1]) * s + c[0]
}

/// The first root of cubic `c` in `[0, end]` where it changes sign: the interval is split at the
/// roots of the derivative (so each piece is monotonic), the first piece whose ends differ in
/// sign is refined by the Illinois variant of regula falsi.
fn first_root(c: [f32; 4], end: f32) -> Option<f32> {
    let mut cuts = [0.0f32, end, end, end];
    let mut k = 1;
    if let Some((r0, r1)) = real_roots(3.0 * c[3], 2.0 * c[2], c[1]) {
        for r in [r0, r1] {
            if r > cuts[k - 1] && r < end {
                cuts[k] = r;
                k += 1;
            }
        }
    }
    cuts[k] = end;
    for w in cuts[..=k].windows(2) {
        let (mut a, mut b) = (w[0], w[1]);
        let (mut fa, mut fb) = (eval_cubic(c, a), eval_cubic(c, b));
        if fa == 0.0 {
            return Some(a);
        }
        if fa * fb > 0.0 {
            continue;
        }
        // Illinois: regula falsi, halving the value kept at an end that stays twice in a row.
        let mut last = 0i8;
        let mut s = b;
        for _ in 0..64 {
            s = (a * fb - b * fa) / (fb - fa);
            if !(s >= a && s <= b) {
                s = 0.5 * (a + b);
            }
            let fs = eval_cubic(c, s);
            if fs == 0.0 {
                break;
            }
            if (fs > 0.0) == (fa > 0.0) {
                (a, fa) = (s, fs);
                if last == -1 {
                    fb *= 0.5;
                }
                last = -1;
            } else {
                (b, fb) = (s, fs);
                if last == 1 {
                    fa *= 0.5;
                }
                last = 1;
            }
            if b - a <= 1e-7 * b.abs().max(1e-6) {
                break;
            }
        }
        return Some(s);
    }
    None
}

/// The real roots of `a x² + b x + c` in increasing order (the linear case when `a = 0`).
fn real_roots(a: f32, b: f32, c: f32) -> Option<(f32, f32)> {
    if a == 0.0 {
        return (b != 0.0).then(|| (-c / b, -c / b));
    }
    let disc = b as f64 * b as f64 - 4.0 * a as f64 * c as f64;
    if disc < 0.0 {
        return None;
    }
    let q = -0.5 * (b as f64 + (b as f64).signum() * disc.sqrt());
    let (r0, r1) = if q == 0.0 {
        (0.0, 0.0)
    } else {
        ((q / a as f64) as f32, (c as f64 / q) as f32)
    };
    Some((r0.min(r1), r0.max(r1)))
}

#[cfg(test)]
mod tests;
