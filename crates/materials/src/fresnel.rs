//! Fresnel equations as Mitsuba 3 evaluates them (`include/mitsuba/render/fresnel.h`): the exact
//! unpolarised dielectric and conductor reflectances, refraction about a normal, and the fitted
//! hemispherical (diffuse) Fresnel reflectance.

use glam::Vec3;

/// Result of [`fresnel_dielectric`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DielectricFresnel {
    /// Unpolarised reflectance (1 under total internal reflection).
    pub r: f32,
    /// Cosine of the refracted direction, with the sign opposite to `cos θi` (0 under TIR).
    pub cos_theta_t: f32,
    /// Relative IOR `η_t/η_i` seen from the incident side.
    pub eta_it: f32,
    /// Its reciprocal `η_i/η_t`.
    pub eta_ti: f32,
}

/// Exact unpolarised Fresnel reflectance of a dielectric interface with relative IOR `eta`
/// (inside over outside) for an incident direction with cosine `cos_theta_i` to the normal;
/// `cos_theta_i < 0` means incidence from the inside (the IORs swap).
#[inline]
pub fn fresnel_dielectric(cos_theta_i: f32, eta: f32) -> DielectricFresnel {
    let (eta_it, eta_ti) = if cos_theta_i >= 0.0 {
        (eta, 1.0 / eta)
    } else {
        (1.0 / eta, eta)
    };
    let cos_t2 = 1.0 - (1.0 - cos_theta_i * cos_theta_i) * eta_ti * eta_ti;
    let ci = cos_theta_i.abs();
    let ct = cos_t2.max(0.0).sqrt();
    let r = if eta == 1.0 {
        0.0
    } else if ci == 0.0 {
        1.0
    } else {
        let a_s = (ci - eta_it * ct) / (ci + eta_it * ct);
        let a_p = (ct - eta_it * ci) / (ct + eta_it * ci);
        0.5 * (a_s * a_s + a_p * a_p)
    };
    DielectricFresnel {
        r,
        cos_theta_t: if cos_theta_i >= 0.0 { -ct } else { ct },
        eta_it,
        eta_ti,
    }
}

/// Exact unpolarised Fresnel reflectance of a conductor with complex relative IOR `eta + i·k`
/// (per channel) at `cos_theta_i ≥ 0`. `eta = 0, k = 1` is a perfect mirror (`F ≡ 1`).
#[inline]
pub fn fresnel_conductor(cos_theta_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
    let c = cos_theta_i.clamp(0.0, 1.0);
    let c2 = c * c;
    let s2 = 1.0 - c2;
    let s4 = s2 * s2;
    let channel = |n: f32, k: f32| {
        let a_ = n * n - k * k - s2;
        let b = (a_ * a_ + 4.0 * n * n * k * k).sqrt();
        let a = (0.5 * (b + a_)).max(0.0).sqrt();
        let rs = (b + c2 - 2.0 * a * c) / (b + c2 + 2.0 * a * c);
        let rp = rs * (b * c2 + s4 - 2.0 * a * c * s2) / (b * c2 + s4 + 2.0 * a * c * s2);
        let f = 0.5 * (rs + rp);
        if f.is_finite() {
            f.clamp(0.0, 1.0)
        } else {
            1.0
        }
    };
    Vec3::new(
        channel(eta.x, k.x),
        channel(eta.y, k.y),
        channel(eta.z, k.z),
    )
}

/// Mirror reflection of `v` about the normal `m`.
#[inline]
pub fn reflect(v: Vec3, m: Vec3) -> Vec3 {
    2.0 * v.dot(m) * m - v
}

/// Refraction of `v` about `m` given [`fresnel_dielectric`]'s `cos_theta_t` and `eta_ti` for
/// `cos θ = v·m` (Mitsuba: `m·((v·m)·η_ti + cos θt) − η_ti·v`).
#[inline]
pub fn refract(v: Vec3, m: Vec3, cos_theta_t: f32, eta_ti: f32) -> Vec3 {
    m * (v.dot(m) * eta_ti + cos_theta_t) - v * eta_ti
}

/// Hemispherical average of the dielectric Fresnel reflectance for relative IOR `eta`
/// (Mitsuba's `fresnel_diffuse_reflectance`): Egan & Hilgeman's fit for `eta < 1`, d'Eon &
/// Irving's polynomial in `1/eta` otherwise.
pub fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    if eta < 1.0 {
        -1.4399 * eta * eta + 0.7099 * eta + 0.6681 + 0.0636 / eta
    } else {
        let x = 1.0 / eta;
        0.919_317 - 3.4793 * x + 6.753_35 * x * x - 7.809_89 * x.powi(3) + 4.985_54 * x.powi(4)
            - 1.368_81 * x.powi(5)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_dielectric() {
        for eta in [1.333f32, 1.5, 2.4, 0.7] {
            let want = ((eta - 1.0) / (eta + 1.0)).powi(2);
            let f = fresnel_dielectric(1.0, eta);
            assert!((f.r - want).abs() < 1e-6, "{eta}: {} vs {want}", f.r);
            assert!((f.cos_theta_t + 1.0).abs() < 1e-6);
            // From the inside, the same at normal incidence.
            assert!((fresnel_dielectric(-1.0, eta).r - want).abs() < 1e-6);
        }
    }

    #[test]
    fn snell_and_tir() {
        let eta = 1.5f32;
        let ci = 0.6f32;
        let f = fresnel_dielectric(ci, eta);
        let si = (1.0 - ci * ci).sqrt();
        let st = (1.0 - f.cos_theta_t * f.cos_theta_t).sqrt();
        assert!((si - eta * st).abs() < 1e-6);
        // Inside, beyond the critical angle (sin θ > 1/1.5): total internal reflection.
        let f = fresnel_dielectric(-0.3, eta);
        assert_eq!(f.r, 1.0);
        assert_eq!(f.cos_theta_t, 0.0);
        // Index matched: no reflection.
        assert_eq!(fresnel_dielectric(0.4, 1.0).r, 0.0);
    }

    /// Conductor Fresnel at normal incidence is `((n−1)² + k²) / ((n+1)² + k²)`.
    #[test]
    fn conductor_normal_incidence() {
        let (eta, k) = crate::ior::conductor("Au").unwrap();
        let f = fresnel_conductor(1.0, eta, k);
        for c in 0..3 {
            let (n, k) = (eta[c], k[c]);
            let want = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
            assert!((f[c] - want).abs() < 1e-5, "{c}: {} vs {want}", f[c]);
        }
        // Gold, computed independently (Python, from the table's η and k):
        // (0.966679, 0.802010, 0.324121).
        let want = Vec3::new(0.966_679, 0.802_010, 0.324_121);
        assert!((f - want).abs().max_element() < 1e-5, "{f}");
        // The "none" preset is a perfect mirror at every angle.
        for c in [0.0f32, 0.1, 0.5, 1.0] {
            let f = fresnel_conductor(c, Vec3::ZERO, Vec3::ONE);
            assert!((f - Vec3::ONE).abs().max_element() < 1e-6, "{c}: {f}");
        }
        // A real-valued "conductor" (k = 0) is a dielectric.
        let f = fresnel_conductor(0.6, Vec3::splat(1.5), Vec3::ZERO);
        assert!((f.x - fresnel_dielectric(0.6, 1.5).r).abs() < 1e-5);
    }

    #[test]
    fn diffuse_fresnel_matches_mitsuba() {
        // MATERIALS.md §4.2: Fdr_int = fdr(1/η) = 0.590479 for η = 1.49/1.000277.
        let eta = 1.49f32 / 1.000_277;
        assert!((fresnel_diffuse_reflectance(1.0 / eta) - 0.590_479).abs() < 2e-5);
    }
}
