//! The rough conductor in SIMD lanes ([`RoughConductorLanes`]): Mitsuba's `roughconductor` of
//! [`crate::models`], each lane its own material, direction and numbers, for an integrator that
//! carries eight paths at once. Every function gives, lane by lane, the bits of the model's own
//! [`crate::Bsdf::eval`], [`crate::Bsdf::pdf_sa`] and [`crate::Bsdf::sample`] on oriented
//! directions (the lanes' caller mirrors a two-sided surface seen from behind, as
//! [`crate::Bsdf`] does): the same operations in the same order ([`restir_sampling::lanes`]),
//! the Beckmann distribution's exponentials, error functions and slope sampling computed one
//! lane at a time by the scalar functions themselves.

use core::f32::consts::PI;
use glam::Vec3;
use restir_sampling::lanes::{self, F8, LANES, M8, V3};

use crate::microfacet::{
    Distribution, Microfacet, beckmann_g1, beckmann_slope_x, beckmann_slope_y, ggx_disk_chord,
};

/// A rough conductor's parameters in lanes: lane `i` holds the material of lane `i`'s surface
/// ([`RoughConductorLanes::set`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct RoughConductorLanes {
    /// Real part of the IOR.
    eta: V3,
    /// Imaginary part.
    k: V3,
    /// `specular_reflectance`.
    specular: V3,
    /// Roughness along the local `x` axis.
    alpha_u: F8,
    /// Roughness along the local `y` axis.
    alpha_v: F8,
    /// Lanes of the Beckmann distribution (the others GGX's, as are lanes never set, which
    /// cost the GGX distribution's arithmetic alone).
    beckmann: M8,
}

impl RoughConductorLanes {
    /// Lane `i` becomes the rough conductor of complex IOR `eta + i·k`, `specular_reflectance`
    /// `specular` and distribution `mf`.
    #[inline(always)]
    pub fn set(&mut self, i: usize, eta: Vec3, k: Vec3, specular: Vec3, mf: &Microfacet) {
        self.eta.set(i, eta);
        self.k.set(i, k);
        self.specular.set(i, specular);
        self.alpha_u.0[i] = mf.alpha_u;
        self.alpha_v.0[i] = mf.alpha_v;
        self.beckmann
            .set(i, mf.distribution == Distribution::Beckmann);
    }

    /// `f(v, l)·cos θl` and the density of [`RoughConductorLanes::sample`] at `l`, in every lane
    /// ([`crate::Bsdf::eval`] and [`crate::Bsdf::pdf_sa`] of the oriented `v`, `l`; reflection
    /// about a visible normal): each zero unless both directions are above the surface, and
    /// where it is not finite.
    #[inline(always)]
    pub fn eval_pdf(&self, v: V3, l: V3) -> (V3, F8) {
        let zero = F8::splat(0.0);
        let h = normalize(v + l);
        let (vh, lh) = (v.dot(h), l.dot(h));
        let d = self.d(h);
        let above = !v.z.le(zero) & !l.z.le(zero) & !d.eq(zero);
        let g1v = self.g1(v, h);
        let f =
            fresnel_conductor(vh, self.eta, self.k).scale(d * (g1v * self.g1(l, h)) / (v.z * 4.0));
        let f = f * self.specular;
        // The distribution of visible normals, with the exact Beckmann masking.
        let visible = d * self.g1_exact(v, h, g1v) * vh.abs() / v.z;
        let p = visible / (lh * 4.0);
        let p_ok = above & !vh.le(zero) & !lh.le(zero) & p.is_finite();
        (
            (above & f.is_finite()).select3(f, V3::ZERO),
            p_ok.select(p, zero),
        )
    }

    /// A direction `l` reflected about a normal visible from `v`, drawn with `(ux, uy)`, in
    /// every lane ([`crate::Bsdf::sample`]): `(l, f(v, l)·cos θl, density, the lanes with a
    /// sample)`. Where there is none (`v` below the surface, a degenerate normal, `l` below the
    /// surface or a density that is not positive and finite) the lane's values are meaningless.
    #[inline(always)]
    pub fn sample(&self, v: V3, ux: F8, uy: F8) -> (V3, V3, F8, M8) {
        let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
        let (au, av) = (self.alpha_u, self.alpha_v);
        // Where the scalar model samples at all.
        let seen = !v.z.le(zero) & v.is_finite();
        // `Microfacet::stretched_view`.
        let vs = normalize(V3 {
            x: au * v.x,
            y: av * v.y,
            z: v.z,
        });
        let sin2 = vs.x * vs.x + vs.y * vs.y;
        let inv = one / sin2.sqrt();
        let tilted = sin2.gt(zero);
        let sin_phi = tilted.select(clamp_unit(vs.y * inv), zero);
        let cos_phi = tilted.select(clamp_unit(vs.x * inv), one);
        let cos_theta = vs.z;
        // Unit-roughness slopes: GGX's from the concentric disk, Beckmann's one lane at a time.
        let (px, py) = lanes::sample_concentric_disk(ux, uy);
        let chord = F8::from_fn(|i| ggx_disk_chord(px.0[i]));
        let s = F8::splat(0.5) * (one + cos_theta);
        let y = (one - s) * chord + s * py;
        let z = (one - px * px - y * y).max(zero).sqrt();
        let sin_theta = (one - cos_theta * cos_theta).max(zero).sqrt();
        let nz = sin_theta * y + cos_theta * z;
        let mut sx = (cos_theta * y - sin_theta * z) / nz;
        let mut sy = -px / nz;
        let beckmann = seen & self.beckmann;
        if beckmann.any() {
            for i in 0..LANES {
                if beckmann.get(i) {
                    sx.0[i] = beckmann_slope_x(cos_theta.0[i], ux.0[i]);
                    sy.0[i] = beckmann_slope_y(uy.0[i]);
                }
            }
        }
        // `StretchedView::normal`.
        let m = normalize(V3 {
            x: -((cos_phi * sx - sin_phi * sy) * au),
            y: -((sin_phi * sx + cos_phi * sy) * av),
            z: one,
        });
        let l = m.scale(F8::splat(2.0) * v.dot(m)) - v;
        let (f, pdf) = self.eval_pdf(v, l);
        let ok =
            seen & m.is_finite() & !l.z.le(zero) & pdf.gt(zero) & pdf.is_finite() & l.is_finite();
        (l, f, pdf, ok)
    }

    /// [`Microfacet::d`] in every lane.
    #[inline(always)]
    fn d(&self, m: V3) -> F8 {
        let (au, av) = (self.alpha_u, self.alpha_v);
        let cos2 = m.z * m.z;
        let (qx, qy) = (m.x / au, m.y / av);
        let norm = F8::splat(PI) * au * av;
        let t = qx * qx + qy * qy + cos2;
        let ggx = one_over(norm * t * t);
        let r = if self.beckmann.any() {
            let e = (qx * qx + qy * qy) / cos2;
            let mut exp = F8::splat(0.0);
            for i in 0..LANES {
                if self.beckmann.get(i) {
                    exp.0[i] = (-e.0[i]).exp();
                }
            }
            self.beckmann.select(exp / (norm * cos2 * cos2), ggx)
        } else {
            ggx
        };
        (r * m.z).gt(F8::splat(1e-20)).select(r, F8::splat(0.0))
    }

    /// [`Microfacet::g1`] in every lane (Walter et al.'s rational fit for Beckmann).
    #[inline(always)]
    fn g1(&self, v: V3, m: V3) -> F8 {
        let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
        let (ax, ay) = (self.alpha_u * v.x, self.alpha_v * v.y);
        let xy = ax * ax + ay * ay;
        let tan2 = xy / (v.z * v.z);
        let ggx = F8::splat(2.0) / (one + (one + tan2).sqrt());
        let a = one / tan2.sqrt();
        let fit = (a * 3.535 + a * 2.181 * a) / (one + a * 2.276 + a * 2.577 * a);
        let beckmann = a.ge(F8::splat(1.6)).select(one, fit);
        let g = self.beckmann.select(beckmann, ggx);
        let g = xy.eq(zero).select(one, g);
        (v.dot(m) * v.z).le(zero).select(zero, g)
    }

    /// [`Microfacet::g1_exact`] in every lane, given [`RoughConductorLanes::g1`]'s `g1` for the
    /// same directions: GGX's is that, Beckmann's exact masking is computed one lane at a time.
    #[inline(always)]
    fn g1_exact(&self, v: V3, m: V3, g1: F8) -> F8 {
        let mut g = g1;
        if self.beckmann.any() {
            let (ax, ay) = (self.alpha_u * v.x, self.alpha_v * v.y);
            let xy = ax * ax + ay * ay;
            let a = v.z.abs() / xy.sqrt();
            let zero = F8::splat(0.0);
            let exact = self.beckmann & !(v.dot(m) * v.z).le(zero) & !xy.eq(zero);
            for i in 0..LANES {
                if exact.get(i) {
                    g.0[i] = beckmann_g1(a.0[i]);
                }
            }
        }
        g
    }
}

/// `v / |v|` in every lane, as glam's `normalize` (times the reciprocal of the length).
#[inline(always)]
fn normalize(v: V3) -> V3 {
    v.scale(one_over(v.dot(v).sqrt()))
}

/// `1 / x` in every lane.
#[inline(always)]
fn one_over(x: F8) -> F8 {
    F8::splat(1.0) / x
}

/// `x.clamp(−1, 1)` in every lane (NaN stays NaN).
#[inline(always)]
fn clamp_unit(x: F8) -> F8 {
    F8::from_fn(|i| x.0[i].clamp(-1.0, 1.0))
}

/// [`crate::fresnel::fresnel_conductor`] in every lane, for `cos θi` `cos_theta_i`.
#[inline(always)]
fn fresnel_conductor(cos_theta_i: F8, eta: V3, k: V3) -> V3 {
    let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
    let c = F8::from_fn(|i| cos_theta_i.0[i].clamp(0.0, 1.0));
    let c2 = c * c;
    let s2 = one - c2;
    let s4 = s2 * s2;
    let channel = |n: F8, k: F8| {
        let a_ = n * n - k * k - s2;
        let b = (a_ * a_ + n * 4.0 * n * k * k).sqrt();
        let a = ((b + a_) * 0.5).max(zero).sqrt();
        let rs = (b + c2 - a * 2.0 * c) / (b + c2 + a * 2.0 * c);
        let rp = rs * (b * c2 + s4 - a * 2.0 * c * s2) / (b * c2 + s4 + a * 2.0 * c * s2);
        let f = (rs + rp) * 0.5;
        let clamped = F8::from_fn(|i| f.0[i].clamp(0.0, 1.0));
        f.is_finite().select(clamped, one)
    };
    V3 {
        x: channel(eta.x, k.x),
        y: channel(eta.y, k.y),
        z: channel(eta.z, k.z),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Bsdf, ior};
    use glam::Vec2;
    use restir_sampling::Pcg32;

    /// A direction from two numbers, over the whole sphere (some below the surface), with
    /// grazing and exactly normal ones mixed in.
    fn direction(rng: &mut Pcg32, k: usize) -> Vec3 {
        match k % 11 {
            0 => Vec3::Z,
            1 => Vec3::new(1.0, 0.0, 1e-7).normalize(),
            _ => {
                let u = rng.next_2d();
                let z = 1.0 - 2.0 * u.x;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * PI * u.y;
                Vec3::new(r * phi.cos(), r * phi.sin(), z)
            }
        }
    }

    /// Lane by lane, the bits of the scalar model's `eval`, `pdf_sa` and `sample` (its
    /// direction, value and density, and whether there is a sample): both distributions,
    /// isotropic and anisotropic, smooth to very rough, three metals and a perfect mirror, each
    /// lane its own material; directions above, below and along the surface.
    #[test]
    fn lanes_give_the_rough_conductors_bits() {
        let mut rng = Pcg32::new(7, 3);
        // Three metals and Mitsuba's default, a perfect mirror (`eta = 0, k = 1`).
        let mut metals = [(Vec3::ZERO, Vec3::ONE); 4];
        for (m, name) in metals.iter_mut().zip(["Cu", "Au", "Al"]) {
            *m = ior::conductor(name).unwrap();
        }
        let alphas = [1e-4, 0.05, 0.2, 0.6, 1.5];
        let (mut sampled, mut beckmann, mut reached) = (0, 0, 0);
        for round in 0..4000 {
            let mut lanes = RoughConductorLanes::default();
            let mut bsdfs = [Bsdf::black(); LANES];
            let (mut v, mut l) = (V3::ZERO, V3::ZERO);
            let (mut ux, mut uy) = (F8::splat(0.0), F8::splat(0.0));
            for (i, bsdf) in bsdfs.iter_mut().enumerate() {
                let k = round * LANES + i;
                let dist = if k.is_multiple_of(3) {
                    Distribution::Beckmann
                } else {
                    Distribution::Ggx
                };
                let au = alphas[k % 5];
                let av = if k.is_multiple_of(4) {
                    alphas[(k / 5) % 5]
                } else {
                    au
                };
                let mf = Microfacet::anisotropic(dist, au, av);
                let (eta, kk) = metals[k % 4];
                let spec = Vec3::new(1.0, 0.9, 0.5 + 0.5 * (k % 2) as f32);
                *bsdf = Bsdf::rough_conductor(eta, kk, spec, mf);
                lanes.set(i, eta, kk, spec, &mf);
                v.set(i, direction(&mut rng, k));
                l.set(i, direction(&mut rng, k / 11));
                let u = rng.next_2d();
                (ux.0[i], uy.0[i]) = (u.x, u.y);
            }
            let (f, pdf) = lanes.eval_pdf(v, l);
            let (sl, sf, spdf, ok) = lanes.sample(v, ux, uy);
            for (i, bsdf) in bsdfs.iter().enumerate() {
                let (vi, li) = (v.get(i), l.get(i));
                let want = bsdf.eval(vi, li);
                assert_eq!(
                    f.get(i).to_array().map(f32::to_bits),
                    want.to_array().map(f32::to_bits),
                    "eval {vi} {li} {bsdf:?}"
                );
                assert_eq!(
                    pdf.0[i].to_bits(),
                    bsdf.pdf_sa(vi, li).to_bits(),
                    "pdf {vi} {li} {bsdf:?}"
                );
                reached += usize::from(want != Vec3::ZERO);
                let s = bsdf.sample(vi, 0.5, Vec2::new(ux.0[i], uy.0[i]));
                assert_eq!(ok.get(i), s.is_some(), "sample {vi} {bsdf:?}");
                if let Some(s) = s {
                    sampled += 1;
                    beckmann += usize::from((round * LANES + i).is_multiple_of(3));
                    assert_eq!(
                        sl.get(i).to_array().map(f32::to_bits),
                        s.wi.to_array().map(f32::to_bits),
                        "{vi} {bsdf:?}"
                    );
                    assert_eq!(
                        sf.get(i).to_array().map(f32::to_bits),
                        s.f.to_array().map(f32::to_bits),
                        "{vi} {bsdf:?}"
                    );
                    assert_eq!(spdf.0[i].to_bits(), s.pdf_sa.to_bits(), "{vi} {bsdf:?}");
                }
            }
        }
        // Enough of each case to mean something.
        assert!(
            sampled > 8000 && beckmann > 2000 && reached > 4000,
            "{sampled} {beckmann} {reached}"
        );
    }
}
