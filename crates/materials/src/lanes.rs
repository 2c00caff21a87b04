//! The microfacet models in SIMD lanes ([`GlossyLanes`]): Mitsuba's `roughconductor` and
//! `roughplastic` as [`crate::Bsdf`] holds them, each lane its own material, direction and
//! numbers, for an integrator that carries eight paths at once. Every function gives, lane by
//! lane, the bits of the model's own [`crate::Bsdf::eval`], [`crate::Bsdf::pdf_sa`] and
//! [`crate::Bsdf::sample`] on oriented directions (the lanes' caller mirrors a two-sided surface
//! seen from behind, as [`crate::Bsdf`] does): the same operations in the same order
//! ([`restir_sampling::lanes`]), the Beckmann distribution's exponentials, error functions and
//! slope sampling and the plastic's coating tables computed one lane at a time by the scalar
//! functions themselves.

use core::f32::consts::{FRAC_1_PI, PI};
use glam::Vec3;
use restir_sampling::lanes::{self, F8, LANES, M8, V3};

use crate::microfacet::{
    Distribution, Microfacet, beckmann_g1, beckmann_slope_x, beckmann_slope_y, ggx_disk_chord,
};
use crate::models::plastic::RoughPlastic;
use crate::models::plastic::tables::RoughPlasticTable;

/// The microfacet models' parameters in lanes: lane `i` holds the material of lane `i`'s
/// surface, a rough conductor ([`GlossyLanes::set_rough_conductor`]) or a rough plastic
/// ([`GlossyLanes::set_rough_plastic`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct GlossyLanes {
    /// Lanes of a rough plastic (the others a rough conductor's).
    plastic: M8,
    /// The conductor's real part of the IOR.
    eta: V3,
    /// The conductor's imaginary part.
    k: V3,
    /// `specular_reflectance`, of either model.
    specular: V3,
    /// The plastic coating's relative IOR.
    coating: F8,
    /// The plastic's `ρ'/η²`.
    diffuse_scaled: V3,
    /// The plastic's specular sampling weight.
    specular_weight: F8,
    /// The plastic's coating tables.
    tables: [Option<&'static RoughPlasticTable>; LANES],
    /// Roughness along the local `x` axis.
    alpha_u: F8,
    /// Roughness along the local `y` axis.
    alpha_v: F8,
    /// Lanes of the Beckmann distribution (the others GGX's, as are lanes never set, which
    /// cost the GGX distribution's arithmetic alone).
    beckmann: M8,
}

impl GlossyLanes {
    /// Lane `i` becomes the rough conductor of complex IOR `eta + i·k`, `specular_reflectance`
    /// `specular` and distribution `mf` (Mitsuba's `roughconductor`).
    #[inline(always)]
    pub fn set_rough_conductor(
        &mut self,
        i: usize,
        eta: Vec3,
        k: Vec3,
        specular: Vec3,
        mf: &Microfacet,
    ) {
        self.plastic.set(i, false);
        self.eta.set(i, eta);
        self.k.set(i, k);
        self.specular.set(i, specular);
        self.set_microfacet(i, mf);
    }

    /// Lane `i` becomes the rough plastic `p` (Mitsuba's `roughplastic`).
    #[inline(always)]
    pub fn set_rough_plastic(&mut self, i: usize, p: &RoughPlastic) {
        self.plastic.set(i, true);
        self.coating.0[i] = p.eta;
        self.diffuse_scaled.set(i, p.diffuse_scaled);
        self.specular.set(i, p.specular_reflectance);
        self.specular_weight.0[i] = p.specular_weight;
        self.tables[i] = Some(p.table);
        self.set_microfacet(i, &p.microfacet);
    }

    #[inline(always)]
    fn set_microfacet(&mut self, i: usize, mf: &Microfacet) {
        self.alpha_u.0[i] = mf.alpha_u;
        self.alpha_v.0[i] = mf.alpha_v;
        self.beckmann
            .set(i, mf.distribution == Distribution::Beckmann);
    }

    /// The plastic's coating transmittance `T(cos θ)` in its lanes (one lane at a time: a table
    /// lookup), zero in the others.
    #[inline(always)]
    fn transmittance(&self, cos_theta: F8) -> F8 {
        F8::from_fn(|i| self.tables[i].map_or(0.0, |t| t.transmittance_at(cos_theta.0[i])))
    }

    /// The plastic's probability of sampling its specular lobe seen at `cos θv`, given
    /// `T(cos θv)` `t` (`rough_plastic_lobes`' first).
    #[inline(always)]
    fn specular_probability(&self, t: F8) -> (F8, F8) {
        let one = F8::splat(1.0);
        let (a, b) = (
            (one - t) * self.specular_weight,
            t * (one - self.specular_weight),
        );
        let s = a + b;
        let some = s.gt(F8::splat(0.0));
        (some.select(a / s, one), some.select(b / s, F8::splat(0.0)))
    }

    /// `f(v, l)·cos θl` and the density of [`GlossyLanes::sample`] at `l`, in every lane
    /// ([`crate::Bsdf::eval`] and [`crate::Bsdf::pdf_sa`] of the oriented `v`, `l`): each zero
    /// unless both directions are above the surface, and where it is not finite.
    #[inline(always)]
    pub fn eval_pdf(&self, v: V3, l: V3) -> (V3, F8) {
        let zero = F8::splat(0.0);
        let h = (v + l).normalize();
        let (vh, lh) = (v.dot(h), l.dot(h));
        let d = self.d(h);
        let above = !v.z.le(zero) & !l.z.le(zero);
        let g1v = self.g1(v, h);
        let g = g1v * self.g1(l, h);
        // Reflection about a visible normal: the distribution of visible normals, with the
        // exact Beckmann masking.
        let visible = d * self.g1_exact(v, h, g1v) * vh.abs() / v.z;
        let p = visible / (lh * 4.0);
        let reflection_pdf = (!vh.le(zero) & !lh.le(zero) & !d.eq(zero)).select(p, zero);
        // The conductor.
        let conductor = (!d.eq(zero)).select3(
            fresnel_conductor(vh, self.eta, self.k).scale(d * g / (v.z * 4.0)) * self.specular,
            V3::ZERO,
        );
        let (mut f, mut pdf) = (conductor, reflection_pdf);
        if self.plastic.any() {
            // The plastic: its coating's reflection and the diffuse base beneath.
            let fresnel = fresnel_dielectric(vh, self.coating);
            let spec = self.specular.scale(fresnel * d * g / (v.z * 4.0));
            let spec = d.gt(zero).select3(spec, V3::ZERO);
            let (ti, to) = (self.transmittance(v.z), self.transmittance(l.z));
            let plastic = spec
                + self
                    .diffuse_scaled
                    .scale(ti * to * F8::splat(FRAC_1_PI) * l.z);
            let (ps, pd) = self.specular_probability(ti);
            let cosine = l.z.gt(zero).select(l.z * FRAC_1_PI, zero);
            f = self.plastic.select3(plastic, f);
            pdf = self.plastic.select(ps * reflection_pdf + pd * cosine, pdf);
        }
        (
            (above & f.is_finite()).select3(f, V3::ZERO),
            (above & pdf.is_finite()).select(pdf, zero),
        )
    }

    /// A direction `l` drawn with `(u_lobe, ux, uy)` in every lane ([`crate::Bsdf::sample`]):
    /// the conductor's reflected about a normal visible from `v`, the plastic's so with its
    /// specular lobe's probability, else cosine-weighted. Returns `(l, f(v, l)·cos θl,
    /// density, the lanes with a sample)`; where there is none (`v` below the surface, a
    /// degenerate normal, `l` below the surface or a density that is not positive and finite)
    /// the lane's values are meaningless.
    #[inline(always)]
    pub fn sample(&self, v: V3, u_lobe: F8, ux: F8, uy: F8) -> (V3, V3, F8, M8) {
        let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
        let (au, av) = (self.alpha_u, self.alpha_v);
        // Which lanes reflect about a visible normal.
        let up = !v.z.le(zero);
        let mut specular = !self.plastic;
        if self.plastic.any() {
            let (ps, _) = self.specular_probability(self.transmittance(v.z));
            specular = specular | (self.plastic & u_lobe.lt(ps));
        }
        // Where the scalar model samples a visible normal (`Microfacet::stretched_view`).
        let seen = up & v.is_finite();
        let vs = V3 {
            x: au * v.x,
            y: av * v.y,
            z: v.z,
        }
        .normalize();
        let sin2 = vs.x * vs.x + vs.y * vs.y;
        let inv = one / sin2.sqrt();
        let tilted = sin2.gt(zero);
        let sin_phi = tilted.select((vs.y * inv).clamp(-1.0, 1.0), zero);
        let cos_phi = tilted.select((vs.x * inv).clamp(-1.0, 1.0), one);
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
        let beckmann = seen & specular & self.beckmann;
        if beckmann.any() {
            for i in 0..LANES {
                if beckmann.get(i) {
                    sx.0[i] = beckmann_slope_x(cos_theta.0[i], ux.0[i]);
                    sy.0[i] = beckmann_slope_y(uy.0[i]);
                }
            }
        }
        // `StretchedView::normal`, and the reflection about it.
        let m = V3 {
            x: -((cos_phi * sx - sin_phi * sy) * au),
            y: -((sin_phi * sx + cos_phi * sy) * av),
            z: one,
        }
        .normalize();
        let reflected = m.scale(F8::splat(2.0) * v.dot(m)) - v;
        // The plastic's diffuse lobe: the concentric disk lifted to the hemisphere.
        let lifted = V3 {
            x: px,
            y: py,
            z: (one - (px * px + py * py)).max(zero).sqrt(),
        };
        let l = specular.select3(reflected, lifted);
        let drawn = (specular & seen & m.is_finite()) | (!specular & up);
        let (f, pdf) = self.eval_pdf(v, l);
        let ok = drawn & !l.z.le(zero) & pdf.gt(zero) & pdf.is_finite() & l.is_finite();
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
        let ggx = F8::splat(1.0) / (norm * t * t);
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

    /// [`Microfacet::g1_exact`] in every lane, given [`GlossyLanes::g1`]'s `g1` for the
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

/// [`crate::fresnel::fresnel_dielectric`]'s reflectance in every lane, for `cos θi`
/// `cos_theta_i` and relative IOR `eta`.
#[inline(always)]
fn fresnel_dielectric(cos_theta_i: F8, eta: F8) -> F8 {
    let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
    let inside = !cos_theta_i.ge(zero);
    let (eta_it, eta_ti) = (inside.select(one / eta, eta), inside.select(eta, one / eta));
    let cos_t2 = one - (one - cos_theta_i * cos_theta_i) * eta_ti * eta_ti;
    let ci = cos_theta_i.abs();
    let ct = cos_t2.max(zero).sqrt();
    let a_s = (ci - eta_it * ct) / (ci + eta_it * ct);
    let a_p = (ct - eta_it * ci) / (ct + eta_it * ci);
    let r = (a_s * a_s + a_p * a_p) * 0.5;
    eta.eq(one).select(zero, ci.eq(zero).select(one, r))
}

/// [`crate::fresnel::fresnel_conductor`] in every lane, for `cos θi` `cos_theta_i`.
#[inline(always)]
fn fresnel_conductor(cos_theta_i: F8, eta: V3, k: V3) -> V3 {
    let c = cos_theta_i.clamp(0.0, 1.0);
    V3 {
        x: fresnel_conductor_channel(c, eta.x, k.x),
        y: fresnel_conductor_channel(c, eta.y, k.y),
        z: fresnel_conductor_channel(c, eta.z, k.z),
    }
}

/// One channel of [`fresnel_conductor`] for the clamped `cos θi` `c`. (A function, not a
/// closure: a closure is compiled apart from its caller's target features and called.)
#[inline(always)]
fn fresnel_conductor_channel(c: F8, n: F8, k: F8) -> F8 {
    let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
    let c2 = c * c;
    let s2 = one - c2;
    let s4 = s2 * s2;
    let a_ = n * n - k * k - s2;
    let b = (a_ * a_ + n * 4.0 * n * k * k).sqrt();
    let a = ((b + a_) * 0.5).max(zero).sqrt();
    let rs = (b + c2 - a * 2.0 * c) / (b + c2 + a * 2.0 * c);
    let rp = rs * (b * c2 + s4 - a * 2.0 * c * s2) / (b * c2 + s4 + a * 2.0 * c * s2);
    let f = (rs + rp) * 0.5;
    f.is_finite().select(f.clamp(0.0, 1.0), one)
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

    /// Lane by lane, the bits of the scalar models' `eval`, `pdf_sa` and `sample` (its
    /// direction, value and density, and whether there is a sample): rough conductors and rough
    /// plastics side by side, both distributions, isotropic and anisotropic (conductors),
    /// smooth to very rough, three metals and a perfect mirror, plastics linear and not, each
    /// lane its own material; directions above, below and along the surface.
    #[test]
    fn lanes_give_the_glossy_models_bits() {
        let mut rng = Pcg32::new(7, 3);
        // Three metals and Mitsuba's default, a perfect mirror (`eta = 0, k = 1`).
        let mut metals = [(Vec3::ZERO, Vec3::ONE); 4];
        for (m, name) in metals.iter_mut().zip(["Cu", "Au", "Al"]) {
            *m = ior::conductor(name).unwrap();
        }
        let alphas = [1e-4, 0.05, 0.2, 0.6, 1.5];
        let plastics: Vec<Bsdf> = [
            (1.49, Distribution::Ggx, 0.08, false),
            (1.49, Distribution::Beckmann, 0.133, false),
            (1.9, Distribution::Ggx, 0.4, true),
            (1.3, Distribution::Beckmann, 0.02, true),
            // A coating of the surrounding medium's index reflects nothing.
            (1.0, Distribution::Ggx, 0.3, false),
        ]
        .iter()
        .enumerate()
        .map(|(j, &(eta, dist, alpha, nonlinear))| {
            let diffuse = Vec3::new(0.7, 0.3 + 0.1 * j as f32, 0.05);
            let specular = Vec3::new(1.0, 0.8, 0.5);
            Bsdf::rough_plastic(eta, diffuse, specular, nonlinear, dist, alpha)
        })
        .collect();
        let (mut sampled, mut beckmann, mut reached, mut diffuse) = (0, 0, 0, 0);
        for round in 0..4000 {
            let mut lanes = GlossyLanes::default();
            let mut bsdfs = [Bsdf::black(); LANES];
            let (mut v, mut l) = (V3::ZERO, V3::ZERO);
            let (mut u_lobe, mut ux, mut uy) = (F8::splat(0.0), F8::splat(0.0), F8::splat(0.0));
            for (i, bsdf) in bsdfs.iter_mut().enumerate() {
                let k = round * LANES + i;
                if k % 5 < 2 {
                    *bsdf = plastics[(k / 5) % plastics.len()];
                    let crate::BsdfKind::RoughPlastic(p) = &bsdf.kind else {
                        unreachable!()
                    };
                    lanes.set_rough_plastic(i, p);
                } else {
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
                    lanes.set_rough_conductor(i, eta, kk, spec, &mf);
                }
                v.set(i, direction(&mut rng, k));
                l.set(i, direction(&mut rng, k / 11));
                let u = rng.next_2d();
                (ux.0[i], uy.0[i]) = (u.x, u.y);
                u_lobe.0[i] = rng.next_2d().x;
            }
            let (f, pdf) = lanes.eval_pdf(v, l);
            let (sl, sf, spdf, ok) = lanes.sample(v, u_lobe, ux, uy);
            for (i, bsdf) in bsdfs.iter().enumerate() {
                let (vi, li) = (v.get(i), l.get(i));
                let want = bsdf.eval(vi, li);
                let bits = |x: Vec3| x.to_array().map(f32::to_bits);
                assert_eq!(bits(f.get(i)), bits(want), "eval {vi} {li} {bsdf:?}");
                let want_pdf = bsdf.pdf_sa(vi, li);
                assert_eq!(
                    pdf.0[i].to_bits(),
                    want_pdf.to_bits(),
                    "pdf {vi} {li} {bsdf:?}"
                );
                reached += usize::from(want != Vec3::ZERO);
                let s = bsdf.sample(vi, u_lobe.0[i], Vec2::new(ux.0[i], uy.0[i]));
                assert_eq!(ok.get(i), s.is_some(), "sample {vi} {bsdf:?}");
                if let Some(s) = s {
                    sampled += 1;
                    let mf = match bsdf.kind {
                        crate::BsdfKind::RoughConductor { microfacet, .. } => microfacet,
                        crate::BsdfKind::RoughPlastic(p) => p.microfacet,
                        _ => unreachable!(),
                    };
                    beckmann += usize::from(
                        s.lobe.contains(crate::LobeFlags::GLOSSY)
                            && mf.distribution == Distribution::Beckmann,
                    );
                    diffuse += usize::from(s.lobe.contains(crate::LobeFlags::DIFFUSE));
                    assert_eq!(bits(sl.get(i)), bits(s.wi), "{vi} {bsdf:?}");
                    assert_eq!(bits(sf.get(i)), bits(s.f), "{vi} {bsdf:?}");
                    assert_eq!(spdf.0[i].to_bits(), s.pdf_sa.to_bits(), "{vi} {bsdf:?}");
                }
            }
        }
        assert!(diffuse > 2000, "{diffuse} diffuse samples");
        // Enough of each case to mean something.
        assert!(
            sampled > 8000 && beckmann > 2000 && reached > 4000,
            "{sampled} {beckmann} {reached}"
        );
    }
}
