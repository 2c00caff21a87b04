//! Mitsuba 3's `bumpmap` (plugin page "Bump map BSDF adapter (`bumpmap`)", mitsuba3
//! `src/bsdfs/bumpmap.cpp`): the wrapped model evaluated in a shading frame perturbed by the
//! gradient of a scalar height texture. The height field's gradient `g = scale · ∇h(u, v)` (the
//! texture's `eval_1_grad`: the derivative of its bilinear lookup in `u` and `v`) moves the
//! surface's partial derivatives along the shading normal `n`:
//!
//! `dp/du' = dp/du + n·(g_u − n·dp/du)`, `dp/dv' = dp/dv + n·(g_v − n·dp/dv)`,
//!
//! and the perturbed normal is `normalize(dp/du' × dp/dv')`, turned to the side of the geometric
//! normal. From there on a bump map is a normal map ([`crate::NormalMap`]): the same
//! `flip_invalid_normals`, perturbed tangent, same-side test and shadowing term of Estévez et al.
//! 2019, which Mitsuba's two adapters share. Only variations of the height matter (a constant
//! offset has no gradient).

use glam::{Vec2, Vec3};

/// The perturbed shading normal of a bump map, in the coordinates of the unperturbed shading
/// frame `(s, t, n)` (world vectors): `grad` is the scaled height gradient `(g_u, g_v)`,
/// `dp_du` and `dp_dv` the surface's partial derivatives and `ng` its geometric normal (all in
/// the world). A degenerate perturbation (parallel derivatives, non-finite values) leaves the
/// normal unperturbed, `(0, 0, 1)`.
pub fn bump_normal(grad: Vec2, dp_du: Vec3, dp_dv: Vec3, frame: [Vec3; 3], ng: Vec3) -> Vec3 {
    let [s, t, n] = frame;
    let du = dp_du + n * (grad.x - n.dot(dp_du));
    let dv = dp_dv + n * (grad.y - n.dot(dp_dv));
    let Some(mut m) = du.cross(dv).try_normalize() else {
        return Vec3::Z;
    };
    if ng.dot(m) < 0.0 {
        m = -m;
    }
    let local = Vec3::new(m.dot(s), m.dot(t), m.dot(n));
    if local.is_finite() { local } else { Vec3::Z }
}

/// The texel a [`crate::NormalMap`] takes for the normal `local` (`t = (n + 1) / 2`).
pub fn normal_texel(local: Vec3) -> Vec3 {
    (local + Vec3::ONE) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    const FRAME: [Vec3; 3] = [Vec3::X, Vec3::Y, Vec3::Z];

    /// A flat height field changes nothing, whatever the parametrisation's scale.
    #[test]
    fn no_gradient_no_perturbation() {
        let n = bump_normal(
            Vec2::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.3, 0.5, 0.0),
            FRAME,
            Vec3::Z,
        );
        assert!((n - Vec3::Z).length() < 1e-6, "{n}");
    }

    /// On the plane `p = (u, v, 0)` with height `h = a·u + b·v` the displaced surface
    /// `(u, v, h)` has the normal `(−a, −b, 1)/|…|`.
    #[test]
    fn a_linear_height_tilts_the_normal_against_its_slope() {
        let (a, b) = (0.4, -0.7);
        let n = bump_normal(Vec2::new(a, b), Vec3::X, Vec3::Y, FRAME, Vec3::Z);
        let want = Vec3::new(-a, -b, 1.0).normalize();
        assert!((n - want).length() < 1e-6, "{n} vs {want}");
        // A parametrisation twice as fast in u halves the slope in space.
        let n = bump_normal(Vec2::new(a, b), 2.0 * Vec3::X, Vec3::Y, FRAME, Vec3::Z);
        let want = Vec3::new(-a / 2.0, -b, 1.0).normalize();
        assert!((n - want).length() < 1e-6, "{n} vs {want}");
        // A mirrored parametrisation (dp/du × dp/dv against the normal) is turned to the
        // geometric normal's side.
        let n = bump_normal(Vec2::new(a, b), Vec3::Y, Vec3::X, FRAME, Vec3::Z);
        assert!(n.z > 0.0, "{n}");
    }

    #[test]
    fn degenerate_derivatives_leave_the_normal() {
        assert_eq!(
            bump_normal(Vec2::ONE, Vec3::X, Vec3::X, FRAME, Vec3::Z),
            Vec3::Z
        );
        assert_eq!(normal_texel(Vec3::Z), Vec3::new(0.5, 0.5, 1.0));
    }
}
