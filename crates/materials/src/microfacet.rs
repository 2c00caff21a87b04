//! Microfacet distributions as Mitsuba 3 defines them (`include/mitsuba/render/microfacet.h`):
//! GGX and Beckmann normal distributions with anisotropic roughness, the *separable* Smith
//! masking term (exact for GGX, Walter et al.'s rational fit for Beckmann), and visible-normal
//! sampling (Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4), for GGX;
//! numerical inversion of the visible-slope CDF after Jakob 2014, "An Improved Visible Normal
//! Sampling Routine for the Beckmann Distribution", for Beckmann).
//!
//! Directions are in the local shading frame (`z` = normal). `v` is the direction the normals are
//! seen from; sampling requires `v.z > 0`.

use core::f32::consts::PI;
use glam::{Vec2, Vec3};
use restir_sampling::warp;

/// The normal distribution function.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
pub enum Distribution {
    /// Beckmann–Spizzichino (Mitsuba's default).
    #[default]
    Beckmann,
    /// Trowbridge–Reitz / GGX.
    Ggx,
}

/// Smallest roughness, as Mitsuba clamps it.
pub const MIN_ALPHA: f32 = 1e-4;

/// A microfacet distribution: its type and roughness along the tangent (`alpha_u`) and bitangent
/// (`alpha_v`). Sampling always uses visible normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    /// Normal distribution.
    pub distribution: Distribution,
    /// Roughness along the local `x` axis (clamped to at least [`MIN_ALPHA`]).
    pub alpha_u: f32,
    /// Roughness along the local `y` axis (clamped to at least [`MIN_ALPHA`]).
    pub alpha_v: f32,
}

impl Microfacet {
    /// An isotropic distribution; `alpha` is clamped to at least [`MIN_ALPHA`] (NaN becomes it).
    pub fn new(distribution: Distribution, alpha: f32) -> Self {
        Self::anisotropic(distribution, alpha, alpha)
    }

    /// An anisotropic distribution; each alpha is clamped to at least [`MIN_ALPHA`].
    pub fn anisotropic(distribution: Distribution, alpha_u: f32, alpha_v: f32) -> Self {
        Self {
            distribution,
            alpha_u: alpha_u.max(MIN_ALPHA),
            alpha_v: alpha_v.max(MIN_ALPHA),
        }
    }

    /// One roughness number for the whole lobe: `√(αu·αv)` (equal to `alpha` when isotropic).
    pub fn alpha(&self) -> f32 {
        (self.alpha_u * self.alpha_v).sqrt()
    }

    /// The normal distribution `D(m)` (per unit solid angle of `m`, projected: `∫ D cos θm = 1`).
    /// Zero for `m` below the surface.
    #[inline]
    pub fn d(&self, m: Vec3) -> f32 {
        let (au, av) = (self.alpha_u, self.alpha_v);
        let cos2 = m.z * m.z;
        let r = match self.distribution {
            Distribution::Beckmann => {
                let e = ((m.x / au).powi(2) + (m.y / av).powi(2)) / cos2;
                (-e).exp() / (PI * au * av * cos2 * cos2)
            }
            Distribution::Ggx => {
                let t = (m.x / au).powi(2) + (m.y / av).powi(2) + cos2;
                1.0 / (PI * au * av * t * t)
            }
        };
        // Mitsuba: D = 0 unless D·cos θm > 1e-20 (also rejects back-facing m and NaN).
        if r * m.z > 1e-20 { r } else { 0.0 }
    }

    /// Smith's masking `G1(v, m)` for the direction `v` and microfacet normal `m`; zero when `m`
    /// is seen from its back (`(v·m)·v.z ≤ 0`).
    #[inline]
    pub fn g1(&self, v: Vec3, m: Vec3) -> f32 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        let xy = (self.alpha_u * v.x).powi(2) + (self.alpha_v * v.y).powi(2);
        if xy == 0.0 {
            return 1.0;
        }
        let tan2 = xy / (v.z * v.z);
        match self.distribution {
            Distribution::Ggx => 2.0 / (1.0 + (1.0 + tan2).sqrt()),
            Distribution::Beckmann => {
                let a = 1.0 / tan2.sqrt();
                if a >= 1.6 {
                    1.0
                } else {
                    (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)
                }
            }
        }
    }

    /// Separable Smith shadowing-masking `G1(a, m)·G1(b, m)` (Mitsuba's `G`; not the
    /// height-correlated form).
    #[inline]
    pub fn g(&self, a: Vec3, b: Vec3, m: Vec3) -> f32 {
        self.g1(a, m) * self.g1(b, m)
    }

    /// Smith's masking with the *exact* Beckmann Λ, `G1 = 1 / (1 + Λ(a))` with
    /// `Λ(a) = (e^(−a²) / (a√π) − erfc(a)) / 2` (Walter et al. 2007, eq. 27); equal to
    /// [`Microfacet::g1`] for GGX. It normalises the distribution of visible normals that
    /// [`Microfacet::sample`] draws from exactly, so [`Microfacet::pdf`] uses it: Mitsuba's
    /// rational fit (in [`Microfacet::g1`], used by `eval`, < 0.35 % off) would make the pdf
    /// disagree with the sampler by up to that much.
    #[inline]
    pub fn g1_exact(&self, v: Vec3, m: Vec3) -> f32 {
        match self.distribution {
            Distribution::Ggx => self.g1(v, m),
            Distribution::Beckmann => {
                if v.dot(m) * v.z <= 0.0 {
                    return 0.0;
                }
                let xy = (self.alpha_u * v.x).powi(2) + (self.alpha_v * v.y).powi(2);
                if xy == 0.0 {
                    return 1.0;
                }
                beckmann_g1(v.z.abs() / xy.sqrt())
            }
        }
    }

    /// Density of [`Microfacet::sample`] over `m` per unit solid angle:
    /// `D(m)·G1(v, m)·|v·m| / cos θv` (the distribution of visible normals, with
    /// [`Microfacet::g1_exact`]). `v.z > 0`.
    #[inline]
    pub fn pdf(&self, v: Vec3, m: Vec3) -> f32 {
        if v.z <= 0.0 {
            return 0.0;
        }
        let d = self.d(m);
        if d == 0.0 {
            return 0.0;
        }
        d * self.g1_exact(v, m) * v.dot(m).abs() / v.z
    }

    /// Samples a normal visible from `v` (`v.z > 0`): stretch `v` to the unit-roughness
    /// configuration, sample slopes there, rotate back and unstretch. Returns `m` (upper
    /// hemisphere, `v·m ≥ 0`) or `None` when `v` is not above the surface or the result is
    /// degenerate.
    pub fn sample(&self, v: Vec3, u: Vec2) -> Option<Vec3> {
        let view = self.stretched_view(v)?;
        let s = match self.distribution {
            Distribution::Ggx => sample_slopes_ggx(view.cos_theta, u),
            Distribution::Beckmann => sample_slopes_beckmann(view.cos_theta, u),
        };
        view.normal(s)
    }

    /// The part of [`Microfacet::sample`] that depends on `v` only: `v` stretched to unit
    /// roughness, as its polar cosine and azimuth. `None` when `v` is not above the surface.
    #[inline]
    pub(crate) fn stretched_view(&self, v: Vec3) -> Option<StretchedView> {
        if v.z <= 0.0 || !v.is_finite() {
            return None;
        }
        let vs = Vec3::new(self.alpha_u * v.x, self.alpha_v * v.y, v.z).normalize();
        let sin2 = vs.x * vs.x + vs.y * vs.y;
        let (sin_phi, cos_phi) = if sin2 > 0.0 {
            let inv = 1.0 / sin2.sqrt();
            ((vs.y * inv).clamp(-1.0, 1.0), (vs.x * inv).clamp(-1.0, 1.0))
        } else {
            (0.0, 1.0)
        };
        Some(StretchedView {
            cos_theta: vs.z,
            sin_phi,
            cos_phi,
            alpha_u: self.alpha_u,
            alpha_v: self.alpha_v,
        })
    }
}

/// A view direction stretched to unit roughness ([`Microfacet::stretched_view`]): what turns
/// unit-roughness slopes sampled for it into a microfacet normal. Kept apart so that sampling at
/// many points `u` for one view (the rough plastic's quadrature) computes it once.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StretchedView {
    /// Cosine of the stretched view's polar angle.
    pub cos_theta: f32,
    sin_phi: f32,
    cos_phi: f32,
    alpha_u: f32,
    alpha_v: f32,
}

impl StretchedView {
    /// The normal of unit-roughness slopes `s` (sampled for this view in its own azimuth): rotated
    /// back, unstretched and normalised; `None` if not finite.
    #[inline]
    pub(crate) fn normal(&self, s: Vec2) -> Option<Vec3> {
        let m = self.normal_unchecked(s);
        m.is_finite().then_some(m)
    }

    /// [`StretchedView::normal`] without the check: possibly not finite.
    #[inline(always)]
    pub(crate) fn normal_unchecked(&self, s: Vec2) -> Vec3 {
        let (sin_phi, cos_phi) = (self.sin_phi, self.cos_phi);
        let slope = Vec2::new(
            (cos_phi * s.x - sin_phi * s.y) * self.alpha_u,
            (sin_phi * s.x + cos_phi * s.y) * self.alpha_v,
        );
        Vec3::new(-slope.x, -slope.y, 1.0).normalize()
    }
}

/// GGX visible slopes at unit roughness for a view direction `(sin θ, 0, cos θ)`: a point on the
/// concentric disk, squeezed towards the visible half (Heitz 2018, with the uniform-disk form of
/// "A Simpler and Exact Sampling Routine for the GGX Distribution of Visible Normals", 2017),
/// lifted to the hemisphere, projected onto the plane normal to the view, and returned as slopes.
fn sample_slopes_ggx(cos_theta: f32, u: Vec2) -> Vec2 {
    let p = warp::sample_concentric_disk(u);
    ggx_slopes_from_disk(cos_theta, p, ggx_disk_chord(p.x))
}

/// `√(1 − x²)`: the half chord of the unit disk at `x`, which [`ggx_slopes_from_disk`] needs.
#[inline(always)]
pub(crate) fn ggx_disk_chord(x: f32) -> f32 {
    (1.0 - x * x).max(0.0).sqrt()
}

/// [`sample_slopes_ggx`] from the point `p = warp::sample_concentric_disk(u)` and its
/// [`ggx_disk_chord`], which do not depend on the view (so a quadrature over `u` for many views
/// computes them once per node).
#[inline(always)]
pub(crate) fn ggx_slopes_from_disk(cos_theta: f32, p: Vec2, chord: f32) -> Vec2 {
    let s = 0.5 * (1.0 + cos_theta);
    let x = p.x;
    let y = (1.0 - s) * chord + s * p.y;
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    // The hemisphere point in the frame (T1, T2, v) with T1 = (0, 1, 0) and
    // T2 = (−cos θ, 0, sin θ) is n = (−y cos θ + z sin θ, x, y sin θ + z cos θ); slopes
    // are −n.xy / n.z.
    let nz = sin_theta * y + cos_theta * z;
    Vec2::new(cos_theta * y - sin_theta * z, -x) / nz
}

/// `1/√π`.
const INV_SQRT_PI: f64 = 0.564_189_583_547_756_3;

/// The largest `f32` below 1: erf-domain values are kept in `[−B_MAX, B_MAX]`, where
/// [`erfinv_f32`] is finite (`|x| ≤ 3.8`; the Gaussian mass beyond is 1e-7).
const B_MAX: f32 = 1.0 - f32::EPSILON / 2.0;

/// Newton steps of the Beckmann visible-slope inversion. From Jakob's starting point the
/// CDF residual is below 5e-2 before the first step, 2e-3 after one and 3e-6 after two (worst
/// case, at grazing incidence; `f32` rounding adds ~1e-7); `beckmann_slopes_solve_the_cdf`
/// checks it.
const BECKMANN_NEWTON_STEPS: usize = 2;

/// Beckmann visible slopes at unit roughness for a view direction `(sin θ, 0, cos θ)`, after
/// Jakob 2014 ("An Improved Visible Normal Sampling Routine for the Beckmann Distribution").
/// The slope `y` is Gaussian, `erf⁻¹(2u₂ − 1)`. The slope `x` has the marginal density
/// `∝ e^(−x²)(cos θ − x sin θ)` on `x < cot θ`, whose CDF in the variable `b = erf(x)` is
/// `(1 + b + tan θ/√π · e^(−x²)) / (1 + erf(cot θ) + tan θ/√π · e^(−cot²θ))`: increasing and
/// concave on `(−1, erf(cot θ)]`. It is inverted in `f32` by a fixed two Newton steps from the
/// paper's fitted starting point `b₀ = c − (1 + c)(1 − u₁)^p(θ)` (`c = erf(cot θ)`; exact at
/// normal incidence, where the CDF is linear in `b`), each step kept inside the bracket the
/// previous residuals give (bisection when Newton leaves it).
fn sample_slopes_beckmann(cos_theta: f32, u: Vec2) -> Vec2 {
    Vec2::new(beckmann_slope_x(cos_theta, u.x), beckmann_slope_y(u.y))
}

/// The slope `y` of [`sample_slopes_beckmann`]: Gaussian, independent of the view.
#[inline]
pub(crate) fn beckmann_slope_y(u: f32) -> f32 {
    erfinv_f32((2.0 * u - 1.0).clamp(-B_MAX, B_MAX))
}

/// Smith's masking `1 / (1 + Λ(a))` with the exact Beckmann `Λ(a) = (e^(−a²) / (a√π) −
/// erfc(a)) / 2`, in `f32`: where the two terms cancel (large `a`) Λ is below 10⁻⁵ beside the 1
/// it is added to, so the result is within 3·10⁻⁷ (relative) of the `f64` formula's
/// (`beckmann_g1_matches_f64`); beyond `a = 9` Λ is far below `f32`'s resolution of 1.
#[inline]
pub(crate) fn beckmann_g1(a: f32) -> f32 {
    if a > 9.0 {
        return 1.0;
    }
    let lambda = 0.5 * ((-a * a).exp() / (a * 1.772_453_8) - libm::erfcf(a));
    1.0 / (1.0 + lambda)
}

/// The slope `x` of [`sample_slopes_beckmann`]: it depends on `u.x` and the view only, so the
/// sampler is separable in `u` (the rough plastic's quadrature solves it once per node row).
pub(crate) fn beckmann_slope_x(cos_theta: f32, ux: f32) -> f32 {
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    if sin_theta < 1e-6 {
        // Normal incidence: the marginal is Gaussian too.
        return erfinv_f32((2.0 * ux - 1.0).clamp(-B_MAX, B_MAX));
    }
    let tan_theta = sin_theta / cos_theta;
    let cot_theta = cos_theta / sin_theta;
    let skew = INV_SQRT_PI as f32 * tan_theta;
    let c = libm::erff(cot_theta).min(B_MAX);
    let inv_norm = 1.0 / (1.0 + c + skew * (-cot_theta * cot_theta).exp());
    let theta = cos_theta.acos();
    let p = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
    let (mut lo, mut hi) = (-B_MAX, c);
    let mut b = (c - (1.0 + c) * (1.0 - ux).powf(p)).clamp(lo, hi);
    for _ in 0..BECKMANN_NEWTON_STEPS {
        let x = erfinv_f32(b);
        let residual = inv_norm * (1.0 + b + skew * (-x * x).exp()) - ux;
        if residual > 0.0 {
            hi = b;
        } else {
            lo = b;
        }
        // d/db of the CDF: (1 − x·tan θ)/norm (since dx/db = √π/2·e^(x²)).
        let next = b - residual / (inv_norm * (1.0 - x * tan_theta));
        b = if next >= lo && next <= hi {
            next
        } else {
            0.5 * (lo + hi)
        };
    }
    erfinv_f32(b)
}

/// The inverse error function in `f32` for `|x| < 1`: Giles' single-precision approximation
/// ("Approximating the erfinv function", GPU Computing Gems, 2011) without refinement (relative
/// error about 1e-6; `erfinv_f32_matches_erfinv` checks it).
// Giles' published coefficients; each rounds to the nearest `f32`.
#[allow(clippy::excessive_precision)]
#[inline]
fn erfinv_f32(x: f32) -> f32 {
    let w = -((1.0 - x) * (1.0 + x)).ln();
    let p = if w < 5.0 {
        let w = w - 2.5;
        let mut p = 2.810_226_36e-08;
        p = 3.432_739_39e-07 + p * w;
        p = -3.523_387_7e-06 + p * w;
        p = -4.391_506_54e-06 + p * w;
        p = 0.000_218_580_87 + p * w;
        p = -0.001_253_725_03 + p * w;
        p = -0.004_177_681_64 + p * w;
        p = 0.246_640_727 + p * w;
        1.501_409_41 + p * w
    } else {
        let w = w.sqrt() - 3.0;
        let mut p = -0.000_200_214_257;
        p = 0.000_100_950_558 + p * w;
        p = 0.001_349_343_22 + p * w;
        p = -0.003_673_428_44 + p * w;
        p = 0.005_739_507_73 + p * w;
        p = -0.007_622_461_3 + p * w;
        p = 0.009_438_870_47 + p * w;
        p = 1.001_674_06 + p * w;
        2.832_976_82 + p * w
    };
    p * x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference inverse error function on `(−1, 1)` (±∞ at ±1): [`erfinv_f32`]'s estimate
    /// refined by Newton steps on `libm::erf` to about 1e-14 away from the end points.
    fn erfinv(x: f64) -> f64 {
        if x <= -1.0 {
            return f64::NEG_INFINITY;
        }
        if x >= 1.0 {
            return f64::INFINITY;
        }
        let mut y = f64::from(erfinv_f32(x as f32));
        // Newton on erf(y) = x: y ← y − (erf(y) − x) / (2/√π · e^(−y²)).
        for _ in 0..3 {
            let d = 2.0 * INV_SQRT_PI * (-y * y).exp();
            if d <= 0.0 {
                break;
            }
            y -= (libm::erf(y) - x) / d;
        }
        y
    }

    /// The `f32` Beckmann masking against the formula in `f64`, from grazing (`a` near 0) to
    /// where Λ vanishes.
    #[test]
    fn beckmann_g1_matches_f64() {
        let mut worst = 0.0f64;
        for i in 1..=20_000 {
            let a = i as f32 * 5e-4;
            let a64 = a as f64;
            let lambda = 0.5 * ((-a64 * a64).exp() * INV_SQRT_PI / a64 - libm::erfc(a64));
            let want = 1.0 / (1.0 + lambda);
            worst = worst.max((beckmann_g1(a) as f64 - want).abs() / want);
        }
        assert!(worst < 1e-6, "relative error {worst}");
    }

    #[test]
    fn erfinv_inverts_erf() {
        for i in 1..2000 {
            let x = -1.0 + i as f64 / 1000.0;
            let y = erfinv(x);
            assert!((libm::erf(y) - x).abs() < 1e-13, "{x}: {y}");
        }
        assert_eq!(erfinv(0.0), 0.0);
    }

    #[test]
    fn erfinv_f32_matches_erfinv() {
        let mut worst = 0.0f64;
        for i in 0..=20_000 {
            let x = (-1.0 + i as f32 / 10_000.0).clamp(-B_MAX, B_MAX);
            let (got, want) = (erfinv_f32(x) as f64, erfinv(x as f64));
            worst = worst.max((got - want).abs() / want.abs().max(1.0));
        }
        assert!(worst < 2e-6, "relative error {worst}");
    }

    /// The Beckmann sampler's slope `x` solves `CDF(x) = u₁` (the exact CDF, in `f64`) to
    /// 1e-5 from normal to grazing incidence, so it draws from the visible normals that
    /// [`Microfacet::pdf`] describes.
    #[test]
    fn beckmann_slopes_solve_the_cdf() {
        let mut worst = (0.0f64, 0.0f32, 0.0f32);
        for i in 0..=400 {
            let cos_theta = if i == 0 { 1e-4 } else { i as f32 / 400.0 };
            let (c, s) = (
                cos_theta as f64,
                (1.0 - (cos_theta as f64).powi(2)).max(0.0).sqrt(),
            );
            for j in 0..=2000 {
                let u1 = (j as f32 / 2000.0).min(1.0 - f32::EPSILON / 2.0);
                let x = sample_slopes_beckmann(cos_theta, Vec2::new(u1, 0.5)).x as f64;
                assert!(x.is_finite(), "cos θ = {cos_theta}, u = {u1}: {x}");
                let cdf = if s < 1e-6 {
                    0.5 * (1.0 + libm::erf(x))
                } else {
                    let (tan, cot) = (s / c, c / s);
                    let skew = INV_SQRT_PI * tan;
                    let norm = 1.0 + libm::erf(cot) + skew * (-cot * cot).exp();
                    (1.0 + libm::erf(x) + skew * (-x * x).exp()) / norm
                };
                let r = (cdf - u1 as f64).abs();
                if r > worst.0 {
                    worst = (r, cos_theta, u1);
                }
            }
        }
        assert!(worst.0 < 1e-5, "CDF residual {worst:?}");
    }

    /// `∫ D(m) cos θm dω = 1` and `∫ pdf(v, m) dω = 1`, by midpoint quadrature in
    /// `(cos θ, φ)` (fine enough for α ≥ 0.2).
    #[test]
    fn d_and_vndf_normalised() {
        for dist in [Distribution::Beckmann, Distribution::Ggx] {
            for (au, av) in [(0.2, 0.2), (0.5, 0.3), (0.9, 0.9)] {
                let mf = Microfacet::anisotropic(dist, au, av);
                let v = Vec3::new(0.5, 0.3, 0.8).normalize();
                let (n_t, n_p) = (2000, 400);
                let (mut sd, mut sp) = (0.0f64, 0.0f64);
                for i in 0..n_t {
                    let z = (i as f32 + 0.5) / n_t as f32;
                    let s = (1.0 - z * z).sqrt();
                    for j in 0..n_p {
                        let phi = 2.0 * PI * (j as f32 + 0.5) / n_p as f32;
                        let m = Vec3::new(s * phi.cos(), s * phi.sin(), z);
                        let dw = (2.0 * PI / n_p as f32 / n_t as f32) as f64;
                        sd += (mf.d(m) * z) as f64 * dw;
                        sp += mf.pdf(v, m) as f64 * dw;
                    }
                }
                let tol = 2e-3;
                assert!((sd - 1.0).abs() < 2e-3, "{dist:?} {au} {av}: ∫D cos = {sd}");
                assert!((sp - 1.0).abs() < tol, "{dist:?} {au} {av}: ∫pdf = {sp}");
            }
        }
    }

    #[test]
    fn sampled_normals_are_visible() {
        let mut rng = restir_sampling::Pcg32::new(5, 0);
        for dist in [Distribution::Beckmann, Distribution::Ggx] {
            let mf = Microfacet::anisotropic(dist, 0.3, 0.05);
            for _ in 0..10_000 {
                let v = warp::sample_uniform_hemisphere(rng.next_2d());
                let Some(m) = mf.sample(v, rng.next_2d()) else {
                    continue;
                };
                assert!((m.length() - 1.0).abs() < 1e-4);
                assert!(m.z > 0.0 && v.dot(m) >= -1e-4, "{v} {m}");
            }
        }
    }
}
