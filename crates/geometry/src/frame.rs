//! Orthonormal shading frames: the change of basis between world space and the local frame in
//! which the normal is `+z`.

use glam::Vec3;

/// An orthonormal frame `(s, t, n)`; local coordinates have `n` as `+z`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent.
    pub s: Vec3,
    /// Second tangent, `n × s`.
    pub t: Vec3,
    /// Normal.
    pub n: Vec3,
}

impl Frame {
    /// A frame around unit `n` with a tangent chosen continuously almost everywhere (Duff et al.
    /// 2017, "Building an Orthonormal Basis, Revisited").
    #[inline]
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { s, t, n }
    }

    /// A frame with normal `n` whose first tangent is `tangent` made orthogonal to `n`; falls back to
    /// [`Frame::from_normal`] when `tangent` is (nearly) parallel to `n`.
    #[inline]
    pub fn from_normal_tangent(n: Vec3, tangent: Vec3) -> Self {
        let s = tangent - n * n.dot(tangent);
        let len2 = s.length_squared();
        if len2 < 1e-12 || !len2.is_finite() {
            return Self::from_normal(n);
        }
        let s = s / len2.sqrt();
        Self {
            s,
            t: n.cross(s),
            n,
        }
    }

    /// World to local.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Local to world.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn orthonormal(x in -1.0f32..1.0, y in -1.0f32..1.0, z in -1.0f32..1.0) {
            let v = Vec3::new(x, y, z);
            prop_assume!(v.length() > 1e-3);
            let n = v.normalize();
            let f = Frame::from_normal(n);
            prop_assert!((f.s.length() - 1.0).abs() < 1e-4);
            prop_assert!((f.t.length() - 1.0).abs() < 1e-4);
            prop_assert!(f.s.dot(f.t).abs() < 1e-4 && f.s.dot(n).abs() < 1e-4 && f.t.dot(n).abs() < 1e-4);
            prop_assert!((f.s.cross(f.t) - n).length() < 1e-3, "right-handed");
            let w = Vec3::new(0.3, -0.2, 0.5);
            prop_assert!((f.to_local(f.to_world(w)) - w).length() < 1e-5);
        }
    }
}
