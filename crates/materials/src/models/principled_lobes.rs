//! What Mitsuba 3's `principled` and `principledthin` share: Schlick's Fresnel weight and its
//! tinted form, the roughness mapping of the main specular lobe, the GTR1 distribution of the
//! clearcoat lobe with its Smith term, and the diffuse–retro-reflection–fake-subsurface and sheen
//! lobes. The formulas are Burley's ("Physically Based Shading at Disney", SIGGRAPH 2012 course
//! notes; "Extending the Disney BRDF to a BSDF with Integrated Subsurface Scattering", SIGGRAPH
//! 2015 course notes) as Mitsuba 3's plugin reference documents and evaluates them, constant for
//! constant, so that `eval` gives Mitsuba's values.

use core::f32::consts::{FRAC_1_PI, PI};
use glam::Vec3;

use crate::microfacet::{Distribution, Microfacet};

/// Schlick's weight `(1 − cos)⁵`, with `1 − cos` clamped to `[0, 1]`.
#[inline]
pub(crate) fn schlick_weight(cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// `a·(1 − t) + b·t`.
#[inline]
pub(crate) fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a * (1.0 - t) + b * t
}

/// Normal-incidence reflectance of an interface of relative IOR `eta`: `((η − 1)/(η + 1))²`.
#[inline]
pub(crate) fn r0_of_eta(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// Schlick's approximation `R0 + (1 − R0)·w` for a (micro)surface of relative IOR `eta` seen at
/// `cos_i` (negative from inside). Entering the denser side the weight is taken at `|cos_i|`,
/// otherwise at the refracted direction's cosine (1 under total internal reflection), as
/// Mitsuba's principled models do. Per channel of `r0`.
#[inline]
pub(crate) fn schlick(r0: Vec3, cos_i: f32, eta: f32) -> Vec3 {
    let w = schlick_cos_weight(cos_i, eta);
    r0 + (Vec3::ONE - r0) * w
}

/// [`schlick`] for a scalar `r0`.
#[inline]
pub(crate) fn schlick_1(r0: f32, cos_i: f32, eta: f32) -> f32 {
    let w = schlick_cos_weight(cos_i, eta);
    w * (1.0 - r0) + r0
}

/// The Schlick weight [`schlick`] uses: at `|cos_i|` when the relative IOR seen from the incident
/// side exceeds 1, else at the refracted cosine.
#[inline]
fn schlick_cos_weight(cos_i: f32, eta: f32) -> f32 {
    let outside = cos_i >= 0.0;
    let (eta_it, eta_ti) = if outside {
        (eta, 1.0 / eta)
    } else {
        (1.0 / eta, eta)
    };
    if eta_it > 1.0 {
        schlick_weight(cos_i.abs())
    } else {
        let cos_t2 = 1.0 - (1.0 - cos_i * cos_i) * (eta_ti * eta_ti);
        schlick_weight(cos_t2.max(0.0).sqrt())
    }
}

/// Luminance of a linear sRGB colour (Mitsuba's RGB-mode `luminance`).
#[inline]
pub(crate) fn luminance(c: Vec3) -> f32 {
    restir_sampling::luminance(c)
}

/// `base_color / luminance`, the hue the tints lean towards (1 for a black base colour).
#[inline]
pub(crate) fn tint_color(base_color: Vec3) -> Vec3 {
    let lum = luminance(base_color);
    if lum > 0.0 {
        base_color / lum
    } else {
        Vec3::ONE
    }
}

/// The GGX distribution of the main specular lobe (Burley 2012, §B.2): `α = roughness²`,
/// stretched by `aspect = √(1 − 0.9·anisotropic)` (`αu = α/aspect`, `αv = α·aspect`), each at
/// least 0.001.
#[inline]
pub(crate) fn specular_distribution(roughness: f32, anisotropic: f32) -> Microfacet {
    let r2 = roughness * roughness;
    let aspect = (1.0 - 0.9 * anisotropic).sqrt();
    Microfacet::anisotropic(
        Distribution::Ggx,
        (r2 / aspect).max(0.001),
        (r2 * aspect).max(0.001),
    )
}

/// The clearcoat's GTR1 ("Berry") distribution of roughness `alpha` (Burley 2012, eq. 4):
/// `D(m) = (α² − 1) / (π ln α² (1 + (α² − 1) cos²θm))`, zero where `D cos θm ≤ 1e-20`.
#[inline]
pub(crate) fn gtr1_d(alpha: f32, m: Vec3) -> f32 {
    let a2 = alpha * alpha;
    let c2 = m.z * m.z;
    let d = (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * c2));
    if d * m.z > 1e-20 { d } else { 0.0 }
}

/// Density of [`gtr1_sample`] over microfacet normals: `D(m)·cos θm` (zero below the surface).
#[inline]
pub(crate) fn gtr1_pdf(alpha: f32, m: Vec3) -> f32 {
    if m.z < 0.0 {
        0.0
    } else {
        m.z * gtr1_d(alpha, m)
    }
}

/// A GTR1 normal from `u` by inverting its cosine-weighted CDF:
/// `cos²θ = (1 − α^(2(1 − u_y))) / (1 − α²)`, `φ = 2π u_x`.
#[inline]
pub(crate) fn gtr1_sample(alpha: f32, u: glam::Vec2) -> Vec3 {
    let a2 = alpha * alpha;
    let (sin_phi, cos_phi) = (2.0 * PI * u.x).sin_cos();
    let cos2 = (1.0 - a2.powf(1.0 - u.y)) / (1.0 - a2);
    let sin_theta = (1.0 - cos2).max(0.0).sqrt();
    let cos_theta = cos2.max(0.0).sqrt();
    Vec3::new(cos_phi * sin_theta, sin_phi * sin_theta, cos_theta)
}

/// The clearcoat lobe's roughness: `0.1` at `clearcoat_gloss` 0 to `0.001` at 1.
#[inline]
pub(crate) fn clearcoat_alpha(gloss: f32) -> f32 {
    lerp(0.1, 0.001, gloss)
}

/// Smith's GGX masking of the clearcoat for direction `v` with fixed roughness `alpha`:
/// `2 / (1 + √(1 + α² tan²θ))`, 1 at normal incidence, 0 where `m` is seen from its back.
#[inline]
pub(crate) fn smith_ggx1(v: Vec3, m: Vec3, alpha: f32) -> f32 {
    if v.dot(m) * v.z <= 0.0 {
        return 0.0;
    }
    if v.z == 1.0 {
        return 1.0;
    }
    let c2 = v.z * v.z;
    let tan2 = (1.0 - c2) / c2;
    2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

/// Whether the microfacet `m` (upper hemisphere) is seen from its front by `v` and by `l`
/// (`reflect`) or by `v` and from its back by `l` (a transmission), with `m` turned to `v`'s
/// side of the surface first (`cos_v` is `v`'s cosine to the macro normal).
#[inline]
pub(crate) fn facet_compatible(m: Vec3, v: Vec3, l: Vec3, cos_v: f32, reflect: bool) -> bool {
    let m = if cos_v < 0.0 { -m } else { m };
    if reflect {
        v.dot(m) > 0.0 && l.dot(m) > 0.0
    } else {
        v.dot(m) > 0.0 && l.dot(m) < 0.0
    }
}

/// The diffuse reflection of the principled models without the `base_color / π` and
/// `|cos θl|` factors: Burley's diffuse with retro-reflection, blended by `flatness` with the
/// Hanrahan–Krueger-style fake subsurface term (Burley 2015, §5.3). `cos_v`, `cos_l` are the
/// (absolute) cosines, `cos_d` the cosine between the half vector and `l`.
#[inline]
pub(crate) fn diffuse_shape(
    roughness: f32,
    flatness: f32,
    cos_v: f32,
    cos_l: f32,
    cos_d: f32,
) -> f32 {
    let fo = schlick_weight(cos_l);
    let fi = schlick_weight(cos_v);
    let f_diff = (1.0 - 0.5 * fi) * (1.0 - 0.5 * fo);
    let rr = 2.0 * roughness * cos_d * cos_d;
    let f_retro = rr * (fo + fi + fo * fi * (rr - 1.0));
    if flatness == 0.0 {
        return f_diff + f_retro;
    }
    let fss90 = rr / 2.0;
    let fss = lerp(1.0, fss90, fo) * lerp(1.0, fss90, fi);
    let f_ss = 1.25 * (fss * (1.0 / (cos_l + cos_v) - 0.5) + 0.5);
    lerp(f_diff + f_retro, f_ss, flatness)
}

/// `base_color · |cos θl| / π ·` [`diffuse_shape`].
#[inline]
pub(crate) fn diffuse_lobe(
    base_color: Vec3,
    roughness: f32,
    flatness: f32,
    cos_v: f32,
    cos_l: f32,
    cos_d: f32,
) -> Vec3 {
    base_color * (cos_l * FRAC_1_PI * diffuse_shape(roughness, flatness, cos_v, cos_l, cos_d))
}

/// The sheen lobe without its weight: `(1 − cos_d)⁵ · lerp(1, tint, sheen_tint) · |cos θl|`
/// (Burley 2012, §5.5).
#[inline]
pub(crate) fn sheen_lobe(base_color: Vec3, sheen_tint: f32, cos_l: f32, cos_d: f32) -> Vec3 {
    let fd = schlick_weight(cos_d.abs());
    let c = if sheen_tint == 0.0 {
        Vec3::ONE
    } else {
        Vec3::ONE * (1.0 - sheen_tint) + tint_color(base_color) * sheen_tint
    };
    c * (fd * cos_l)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    /// The GTR1 sampler's cosine-weighted density integrates to 1 over the hemisphere, and
    /// histogramming its samples against `gtr1_pdf` agrees (a quick check; the chi-square tests
    /// cover the whole model).
    #[test]
    fn gtr1_is_normalised() {
        for alpha in [0.001f32, 0.05, 0.1] {
            let n = 200_000;
            let mut sum = 0.0f64;
            let mut rng = restir_sampling::Pcg32::new(7, 3);
            for _ in 0..n {
                // Uniform hemisphere sampling: pdf 1/(2π).
                let u = rng.next_2d();
                let z = u.x;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let m = Vec3::new(r * (2.0 * PI * u.y).cos(), r * (2.0 * PI * u.y).sin(), z);
                sum += f64::from(gtr1_pdf(alpha, m)) * 2.0 * std::f64::consts::PI;
            }
            let mean = sum / n as f64;
            // Very sharp lobes are poorly integrated by uniform sampling: loose for 0.001.
            let tol = if alpha < 0.01 { 0.5 } else { 0.05 };
            assert!((mean - 1.0).abs() < tol, "α {alpha}: ∫ = {mean}");
            let m = gtr1_sample(alpha, Vec2::new(0.3, 0.7));
            assert!((m.length() - 1.0).abs() < 1e-5 && m.z > 0.0);
        }
    }

    #[test]
    fn schlick_limits() {
        assert_eq!(schlick_weight(1.0), 0.0);
        assert_eq!(schlick_weight(0.0), 1.0);
        // At normal incidence Schlick gives R0; at grazing 1.
        assert!((schlick_1(0.04, 1.0, 1.5) - 0.04).abs() < 1e-7);
        assert!((schlick_1(0.04, 0.0, 1.5) - 1.0).abs() < 1e-7);
        // From inside beyond the critical angle: total internal reflection.
        assert!((schlick_1(0.04, -0.3, 1.5) - 1.0).abs() < 1e-7);
    }
}
