//! Eight `f32` lanes: the types estimators write lane-parallel mathematics in.
//!
//! [`F8`] is eight numbers in an aligned array, [`M8`] eight conditions, [`V3`] a vector of
//! lanes. Every operation is written lane by lane, as a loop the compiler vectorises: inside a
//! function compiled with AVX2 and FMA (`#[target_feature(enable = "avx2,fma")]`) into 256-bit
//! instructions, elsewhere into SSE2 ones. Neither contracts `a·b + c`
//! into a fused multiply-add, so both give the bits of the same arithmetic on `f32`, lane by
//! lane: lane `i` of any expression equals the scalar expression on lane `i`'s inputs.

use core::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};
use glam::Vec3;

/// Lanes in [`F8`] and [`M8`].
pub const LANES: usize = 8;

/// Eight `f32` lanes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
pub struct F8(pub [f32; LANES]);

/// Eight conditions, one a lane (each all ones or all zeros, as the vector instructions that
/// select by them want it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct M8([i32; LANES]);

macro_rules! lanewise {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: F8) -> F8 {
                let mut r = [0.0; LANES];
                for (i, v) in r.iter_mut().enumerate() {
                    *v = self.0[i] $op o.0[i];
                }
                F8(r)
            }
        }
        impl $tr<f32> for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: f32) -> F8 {
                self $op F8::splat(o)
            }
        }
    };
}
lanewise!(Add, add, +);
lanewise!(Sub, sub, -);
lanewise!(Mul, mul, *);
lanewise!(Div, div, /);

impl Neg for F8 {
    type Output = F8;
    #[inline(always)]
    fn neg(self) -> F8 {
        lanes1(self, |x| -x)
    }
}

/// `f` of every lane, written as a loop (which the compiler vectorises inside the caller; a
/// closure handed to `array::map` may be compiled without the caller's target features).
#[inline(always)]
fn lanes1(a: F8, f: impl Fn(f32) -> f32) -> F8 {
    let mut r = [0.0; LANES];
    for (i, v) in r.iter_mut().enumerate() {
        *v = f(a.0[i]);
    }
    F8(r)
}

/// The lanes where `f` holds.
#[inline(always)]
fn test1(a: F8, f: impl Fn(f32) -> bool) -> M8 {
    let mut r = [0; LANES];
    for (i, v) in r.iter_mut().enumerate() {
        *v = -i32::from(f(a.0[i]));
    }
    M8(r)
}

macro_rules! compare {
    ($name:ident, $op:tt, $doc:literal) => {
        #[doc = $doc]
        #[inline(always)]
        pub fn $name(self, o: F8) -> M8 {
            let mut r = [0; LANES];
            for (i, v) in r.iter_mut().enumerate() {
                *v = -i32::from(self.0[i] $op o.0[i]);
            }
            M8(r)
        }
    };
}

impl F8 {
    /// `x` in every lane.
    #[inline(always)]
    pub fn splat(x: f32) -> Self {
        F8([x; LANES])
    }

    /// Lane `i` is `f(i)`.
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> f32) -> Self {
        let mut r = [0.0; LANES];
        for (i, v) in r.iter_mut().enumerate() {
            *v = f(i);
        }
        F8(r)
    }

    /// The square root of every lane.
    #[inline(always)]
    pub fn sqrt(self) -> Self {
        lanes1(self, f32::sqrt)
    }

    /// The absolute value of every lane.
    #[inline(always)]
    pub fn abs(self) -> Self {
        lanes1(self, f32::abs)
    }

    /// `f32::clamp` of every lane to `[lo, hi]` (NaN stays NaN).
    #[inline(always)]
    pub fn clamp(self, lo: f32, hi: f32) -> Self {
        lanes1(self, |x| x.clamp(lo, hi))
    }

    /// The larger of the two in every lane; `o`'s lane where either is NaN (`x > o ? x : o`).
    #[inline(always)]
    pub fn max(self, o: F8) -> Self {
        M8::select(self.gt(o), self, o)
    }

    /// The smaller of the two in every lane; `o`'s lane where either is NaN (`x < o ? x : o`).
    #[inline(always)]
    pub fn min(self, o: F8) -> Self {
        M8::select(self.lt(o), self, o)
    }

    compare!(lt, <, "Lanes where `self < o`.");
    compare!(le, <=, "Lanes where `self <= o`.");
    compare!(gt, >, "Lanes where `self > o`.");
    compare!(ge, >=, "Lanes where `self >= o`.");
    compare!(eq, ==, "Lanes where `self == o`.");

    /// `self`'s magnitudes with `sign`'s signs (`f32::copysign` in every lane).
    #[inline(always)]
    pub fn copysign(self, sign: F8) -> Self {
        let mut r = [0.0; LANES];
        for (i, v) in r.iter_mut().enumerate() {
            *v = self.0[i].copysign(sign.0[i]);
        }
        F8(r)
    }

    /// Lanes holding a finite number.
    #[inline(always)]
    pub fn is_finite(self) -> M8 {
        test1(self, f32::is_finite)
    }

    /// Lanes holding an infinity.
    #[inline(always)]
    pub fn is_infinite(self) -> M8 {
        test1(self, f32::is_infinite)
    }
}

impl M8 {
    /// `b` in every lane.
    #[inline(always)]
    pub fn splat(b: bool) -> Self {
        M8([-i32::from(b); LANES])
    }

    /// Lane `i` is `f(i)`.
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> bool) -> Self {
        let mut r = [0; LANES];
        for (i, v) in r.iter_mut().enumerate() {
            *v = -i32::from(f(i));
        }
        M8(r)
    }

    /// Whether lane `i` holds.
    #[inline(always)]
    pub fn get(self, i: usize) -> bool {
        self.0[i] != 0
    }

    /// Sets lane `i`.
    #[inline(always)]
    pub fn set(&mut self, i: usize, b: bool) {
        self.0[i] = -i32::from(b);
    }

    /// Per lane, `a` where the condition holds and `b` elsewhere.
    #[inline(always)]
    pub fn select(self, a: F8, b: F8) -> F8 {
        let mut r = [0.0; LANES];
        for (i, v) in r.iter_mut().enumerate() {
            // Bitwise, not a branch: a branch would let the compiler compute the chosen
            // lane's operand alone, one lane at a time.
            let m = self.0[i] as u32;
            *v = f32::from_bits((a.0[i].to_bits() & m) | (b.0[i].to_bits() & !m));
        }
        F8(r)
    }

    /// [`M8::select`] of each component.
    #[inline(always)]
    pub fn select3(self, a: V3, b: V3) -> V3 {
        V3 {
            x: self.select(a.x, b.x),
            y: self.select(a.y, b.y),
            z: self.select(a.z, b.z),
        }
    }

    /// Whether any lane holds.
    #[inline(always)]
    pub fn any(self) -> bool {
        self.0.iter().fold(0, |a, &b| a | b) != 0
    }
}

impl BitAnd for M8 {
    type Output = M8;
    #[inline(always)]
    fn bitand(self, o: M8) -> M8 {
        let mut r = self.0;
        for (i, v) in r.iter_mut().enumerate() {
            *v &= o.0[i];
        }
        M8(r)
    }
}

impl BitOr for M8 {
    type Output = M8;
    #[inline(always)]
    fn bitor(self, o: M8) -> M8 {
        let mut r = self.0;
        for (i, v) in r.iter_mut().enumerate() {
            *v |= o.0[i];
        }
        M8(r)
    }
}

impl Not for M8 {
    type Output = M8;
    #[inline(always)]
    fn not(self) -> M8 {
        let mut r = self.0;
        for v in &mut r {
            *v = !*v;
        }
        M8(r)
    }
}

/// A 3-vector of lanes: lane `i` of `x`, `y`, `z` is one vector.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct V3 {
    /// First components.
    pub x: F8,
    /// Second components.
    pub y: F8,
    /// Third components.
    pub z: F8,
}

impl V3 {
    /// Zero in every lane.
    pub const ZERO: V3 = V3 {
        x: F8([0.0; LANES]),
        y: F8([0.0; LANES]),
        z: F8([0.0; LANES]),
    };

    /// `v` in every lane.
    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        V3 {
            x: F8::splat(v.x),
            y: F8::splat(v.y),
            z: F8::splat(v.z),
        }
    }

    /// Lane `i` is `f(i)`.
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> Vec3) -> Self {
        let mut v = V3::ZERO;
        for i in 0..LANES {
            v.set(i, f(i));
        }
        v
    }

    /// Lane `i`.
    #[inline(always)]
    pub fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.x.0[i], self.y.0[i], self.z.0[i])
    }

    /// Sets lane `i` to `v`.
    #[inline(always)]
    pub fn set(&mut self, i: usize, v: Vec3) {
        self.x.0[i] = v.x;
        self.y.0[i] = v.y;
        self.z.0[i] = v.z;
    }

    /// Every component times `s`'s lane.
    #[inline(always)]
    pub fn scale(self, s: F8) -> Self {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// The dot product in every lane (`x·x + y·y + z·z`, in that order, as glam's).
    #[inline(always)]
    pub fn dot(self, o: V3) -> F8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// The unit vector in every lane, as glam's `normalize` (times the reciprocal of the
    /// length).
    #[inline(always)]
    pub fn normalize(self) -> V3 {
        self.scale(F8::splat(1.0) / self.dot(self).sqrt())
    }

    /// The cross product in every lane (glam's order of operations).
    #[inline(always)]
    pub fn cross(self, o: V3) -> V3 {
        V3 {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    /// The largest component in every lane (as glam's `max_element`).
    #[inline(always)]
    pub fn max_element(self) -> F8 {
        self.x.max(self.y.max(self.z))
    }

    /// Lanes whose three components are finite.
    #[inline(always)]
    pub fn is_finite(self) -> M8 {
        self.x.is_finite() & self.y.is_finite() & self.z.is_finite()
    }
}

impl Add for V3 {
    type Output = V3;
    #[inline(always)]
    fn add(self, o: V3) -> V3 {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for V3 {
    type Output = V3;
    #[inline(always)]
    fn sub(self, o: V3) -> V3 {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl Mul for V3 {
    type Output = V3;
    #[inline(always)]
    fn mul(self, o: V3) -> V3 {
        V3 {
            x: self.x * o.x,
            y: self.y * o.y,
            z: self.z * o.z,
        }
    }
}

impl Div<F8> for V3 {
    type Output = V3;
    /// Every component divided by the lane's `s` (as glam's `Vec3 / f32`).
    #[inline(always)]
    fn div(self, s: F8) -> V3 {
        V3 {
            x: self.x / s,
            y: self.y / s,
            z: self.z / s,
        }
    }
}

impl Neg for V3 {
    type Output = V3;
    #[inline(always)]
    fn neg(self) -> V3 {
        V3 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

/// [`crate::warp::sincos_quarter`] in every lane: the same polynomials, the same bits.
#[inline(always)]
pub fn sincos_quarter(x: F8) -> (F8, F8) {
    let x2 = x * x;
    let mut s = F8::splat(0.0);
    for c in crate::warp::SIN_TAYLOR {
        s = s * x2 + c;
    }
    let mut k = F8::splat(0.0);
    for c in crate::warp::COS_TAYLOR {
        k = k * x2 + c;
    }
    (x + x * (s * x2), k * x2 + 1.0)
}

/// [`crate::warp::sincos_turns`] in every lane: `(sin 2πt, cos 2πt)` for `t ∈ [0, 1]`, reduced
/// to the nearest quarter turn, the same bits.
#[inline(always)]
pub fn sincos_turns(t: F8) -> (F8, F8) {
    // The nearest quarter `k` (truncation is the floor of `t·4 + ½ ≥ ½`) and its bits.
    let mut k = [0.0; LANES];
    let mut odd = M8::default();
    let mut half = M8::default();
    for (i, k) in k.iter_mut().enumerate() {
        let q = (t.0[i] * 4.0 + 0.5) as u32;
        *k = q as f32;
        odd.0[i] = -((q & 1) as i32);
        half.0[i] = -((q >> 1 & 1) as i32);
    }
    let (s, c) = sincos_quarter((t - F8(k) * 0.25) * (2.0 * core::f32::consts::PI));
    // Quarters 0 and 1 give (s, c) and (c, −s); 2 and 3 their negatives.
    let (a, b) = (odd.select(c, s), odd.select(-s, c));
    (half.select(-a, a), half.select(-b, b))
}

/// [`crate::warp::power_heuristic`] in every lane: the weight of `pdf_a` against `pdf_b`, 1
/// where `pdf_a` is infinite, 0 where the ratio is not finite.
#[inline(always)]
pub fn power_heuristic(pdf_a: F8, pdf_b: F8) -> F8 {
    let (a2, b2) = (pdf_a * pdf_a, pdf_b * pdf_b);
    let w = a2 / (a2 + b2);
    let w = w.is_finite().select(w, F8::splat(0.0));
    pdf_a.is_infinite().select(F8::splat(1.0), w)
}

/// [`crate::warp::sample_cosine_hemisphere`] in every lane (Malley's method over Shirley and
/// Chiu's concentric map): the same direction to within rounding, the angle's sine and cosine
/// from [`sincos_quarter`] (either branch of the map needs them only on `[−π/4, π/4]`).
#[inline(always)]
pub fn sample_cosine_hemisphere(ux: F8, uy: F8) -> V3 {
    let (x, y) = sample_concentric_disk(ux, uy);
    let z = (F8::splat(1.0) - (x * x + y * y))
        .max(F8::splat(0.0))
        .sqrt();
    V3 { x, y, z }
}

/// [`crate::warp::sample_concentric_disk`] in every lane (Shirley and Chiu's map), the angle's
/// sine and cosine from [`sincos_quarter`]: the same bits.
#[inline(always)]
pub fn sample_concentric_disk(ux: F8, uy: F8) -> (F8, F8) {
    let (ox, oy) = (ux * 2.0 - 1.0, uy * 2.0 - 1.0);
    let wide = ox.abs().gt(oy.abs());
    let q = wide.select(oy / ox, ox / oy);
    let (s, c) = sincos_quarter(q * core::f32::consts::FRAC_PI_4);
    let r = wide.select(ox, oy);
    let centre = ox.eq(F8::splat(0.0)) & oy.eq(F8::splat(0.0));
    let zero = F8::splat(0.0);
    let x = centre.select(zero, r * wide.select(c, s));
    let y = centre.select(zero, r * wide.select(s, c));
    (x, y)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lanes' sine and cosine are the scalar polynomials' bits (whose accuracy
    /// `warp`'s tests check).
    #[test]
    fn sincos_quarter_gives_the_scalar_bits() {
        let n = 100_003;
        for k in (0..n).step_by(LANES) {
            let x = F8::from_fn(|i| {
                core::f32::consts::FRAC_PI_4 * (2.0 * (k + i) as f32 / n as f32 - 1.0)
            });
            let (s, c) = sincos_quarter(x);
            for i in 0..LANES {
                let (ws, wc) = crate::warp::sincos_quarter(x.0[i]);
                assert_eq!(
                    (s.0[i].to_bits(), c.0[i].to_bits()),
                    (ws.to_bits(), wc.to_bits())
                );
            }
        }
    }

    /// The lanes' sine and cosine of turns are the warp's bits, in all four quarters and on
    /// their boundaries.
    #[test]
    fn sincos_turns_gives_the_warps_bits() {
        let n = 40_000;
        for k in (0..=n).step_by(LANES) {
            let t = F8::from_fn(|i| ((k + i).min(n) as f32 / n as f32).min(1.0));
            let (s, c) = sincos_turns(t);
            for i in 0..LANES {
                let (ws, wc) = crate::warp::sincos_turns(t.0[i]);
                assert_eq!(
                    (s.0[i].to_bits(), c.0[i].to_bits()),
                    (ws.to_bits(), wc.to_bits()),
                    "t = {}",
                    t.0[i]
                );
            }
        }
    }

    /// Lane `i` of an expression is the scalar expression on lane `i`'s inputs, bit for bit.
    #[test]
    fn lanes_compute_the_scalar_bits() {
        let a = F8::from_fn(|i| 0.1 + i as f32 * 1.37);
        let b = F8::from_fn(|i| 2.5 - i as f32 * 0.61);
        let r = (a * b + a / b - b).sqrt().max(F8::splat(0.3));
        for i in 0..LANES {
            let (x, y) = (a.0[i], b.0[i]);
            let want = (x * y + x / y - y).sqrt();
            let want = if want > 0.3 { want } else { 0.3 };
            assert_eq!(r.0[i].to_bits(), want.to_bits(), "lane {i}");
        }
    }

    /// The lanes' cosine-weighted directions are the warp's bits (the square grid's corners,
    /// edges and centre included).
    #[test]
    fn cosine_hemisphere_gives_the_warps_bits() {
        let mut rng = crate::Pcg32::new(5, 1);
        for k in 0..4_000 {
            let u: [(f32, f32); LANES] = core::array::from_fn(|i| {
                let j = k * LANES + i;
                if j < 9 {
                    ((j % 3) as f32 * 0.5, (j / 3) as f32 * 0.5)
                } else {
                    (rng.next_f32(), rng.next_f32())
                }
            });
            let d = sample_cosine_hemisphere(F8::from_fn(|i| u[i].0), F8::from_fn(|i| u[i].1));
            for (i, &(x, y)) in u.iter().enumerate() {
                let want = crate::warp::sample_cosine_hemisphere(glam::Vec2::new(x, y));
                assert_eq!(
                    d.get(i).to_array().map(f32::to_bits),
                    want.to_array().map(f32::to_bits)
                );
            }
        }
    }

    /// The lanes' power heuristic is the scalar one's bits, infinite, zero and huge densities
    /// included.
    #[test]
    fn power_heuristic_gives_the_scalar_bits() {
        let values = [0.0, 1e-30, 0.3, 1.0, 7.5, 1e20, 3e38, f32::INFINITY];
        for &a in &values {
            let w = power_heuristic(F8::splat(a), F8::from_fn(|i| values[i]));
            for (i, &b) in values.iter().enumerate() {
                let want = crate::warp::power_heuristic(a, b);
                assert_eq!(w.0[i].to_bits(), want.to_bits(), "{a} against {b}");
            }
        }
    }
}
