//! Mitsuba's `blendbsdf` against its definition: a blend of a BSDF with itself is that BSDF;
//! weights 0 and 1 are the first and second component (sample for sample); any weight is the
//! linear mix of the components' `eval` and `pdf_sa`; and the sampled delta lobes keep their
//! component's throughput. The sampling distribution is tested by chi-square in `chi2.rs`.

use glam::{Vec2, Vec3};
use restir_materials::{Bsdf, BsdfKind, Distribution, LobeFlags, Microfacet, NormalMap, ior};
use restir_sampling::Pcg32;

/// Models of every family, delta ones included, and the wrappers.
fn models() -> Vec<Bsdf> {
    let (mirror_eta, mirror_k) = ior::conductor("none").unwrap();
    let (au_eta, au_k) = ior::conductor("Au").unwrap();
    let mf = Microfacet::new(Distribution::Ggx, 0.3);
    let c = Vec3::new(0.8, 0.5, 0.2);
    vec![
        Bsdf::diffuse(c),
        Bsdf::diffuse(c).two_sided(),
        Bsdf::conductor(mirror_eta, mirror_k, Vec3::ONE),
        Bsdf::rough_conductor(au_eta, au_k, Vec3::ONE, mf),
        Bsdf::dielectric(1.5, Vec3::ONE, Vec3::ONE),
        Bsdf::rough_dielectric(1.33, Vec3::ONE, Vec3::splat(0.7), mf),
        Bsdf::plastic(1.49, c, Vec3::ONE, false),
        Bsdf::rough_plastic(1.49, c, Vec3::ONE, true, Distribution::Beckmann, 0.2),
        Bsdf::null(),
        Bsdf::black(),
        Bsdf::diffuse(c).masked(0.4),
        Bsdf::diffuse(c).normal_mapped(NormalMap::new(Vec3::new(0.7, 0.4, 0.85), true, true)),
        Bsdf::blend(
            0.3,
            Bsdf::diffuse(c),
            Bsdf::rough_conductor(au_eta, au_k, Vec3::ONE, mf),
        ),
    ]
}

/// Random unit directions on both sides.
fn directions(rng: &mut Pcg32, n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|_| {
            let z = 2.0 * rng.next_f32() - 1.0;
            let phi = std::f32::consts::TAU * rng.next_f32();
            let s = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(s * phi.cos(), s * phi.sin(), z)
        })
        .collect()
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() <= 1e-5 * (1.0 + a.abs().max_element().max(b.abs().max_element()))
}

fn close1(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-5 * (1.0 + a.abs().max(b.abs()))
}

/// `eval` and `pdf_sa` of a blend are the weighted sums of its components', for every pair of
/// models and several weights.
#[test]
fn eval_and_pdf_are_the_linear_mix() {
    let mut rng = Pcg32::new(7, 1);
    let dirs = directions(&mut rng, 24);
    let ms = models();
    for a in &ms {
        for b in &ms {
            for w in [0.0, 0.25, 0.5, 0.9, 1.0] {
                let blend = Bsdf::blend(w, *a, *b);
                for &wo in &dirs {
                    for &wi in &dirs {
                        let want = (1.0 - w) * a.eval(wo, wi) + w * b.eval(wo, wi);
                        assert!(close(blend.eval(wo, wi), want), "{a:?} {b:?} {w}");
                        let want = (1.0 - w) * a.pdf_sa(wo, wi) + w * b.pdf_sa(wo, wi);
                        assert!(close1(blend.pdf_sa(wo, wi), want), "{a:?} {b:?} {w}");
                    }
                }
            }
        }
    }
}

/// A blend of a BSDF with itself is that BSDF (whatever the weight), and its lobes are the
/// BSDF's.
#[test]
fn blend_of_a_bsdf_with_itself_is_the_bsdf() {
    let mut rng = Pcg32::new(8, 1);
    let dirs = directions(&mut rng, 32);
    for m in models() {
        for w in [0.2, 0.5, 0.77] {
            let blend = Bsdf::blend(w, m, m);
            assert_eq!(blend.flags(), m.flags());
            assert_eq!(blend.kind.transmits(), m.kind.transmits());
            for &wo in &dirs {
                for &wi in &dirs {
                    assert!(close(blend.eval(wo, wi), m.eval(wo, wi)), "{m:?}");
                    assert!(close1(blend.pdf_sa(wo, wi), m.pdf_sa(wo, wi)), "{m:?}");
                }
                // Every sample is one the model itself gives, with the model's weight.
                for _ in 0..16 {
                    let (ul, u) = (rng.next_f32(), Vec2::new(rng.next_f32(), rng.next_f32()));
                    let Some(s) = blend.sample(wo, ul, u) else {
                        continue;
                    };
                    if s.lobe.is_delta() {
                        continue;
                    }
                    assert!(close(s.f, m.eval(wo, s.wi)), "{m:?}");
                    assert!(close1(s.pdf_sa, m.pdf_sa(wo, s.wi)), "{m:?}");
                }
            }
        }
    }
}

/// Weight 0 samples exactly the first component and weight 1 exactly the second: the same
/// direction, lobe and weight for the same random numbers.
#[test]
fn weights_zero_and_one_are_the_components() {
    let mut rng = Pcg32::new(9, 1);
    let dirs = directions(&mut rng, 16);
    let ms = models();
    for a in &ms {
        for b in &ms {
            for (w, m) in [(0.0, a), (1.0, b)] {
                let blend = Bsdf::blend(w, *a, *b);
                assert!(blend.flags().contains(a.flags()) && blend.flags().contains(b.flags()));
                for &wo in &dirs {
                    for _ in 0..8 {
                        let (ul, u) = (rng.next_f32(), Vec2::new(rng.next_f32(), rng.next_f32()));
                        let (s, t) = (blend.sample(wo, ul, u), m.sample(wo, ul, u));
                        match (s, t) {
                            (None, None) => {}
                            (Some(s), Some(t)) => {
                                assert_eq!(s.wi, t.wi, "{m:?}");
                                assert_eq!(s.lobe, t.lobe, "{m:?}");
                                assert!(close(s.f, t.f) && close1(s.pdf_sa, t.pdf_sa), "{m:?}");
                            }
                            (s, t) => panic!("{m:?} w={w}: {s:?} vs {t:?}"),
                        }
                    }
                }
            }
        }
    }
}

/// A delta sample keeps its component's throughput `f / pdf_sa`, and its `pdf_sa` is the
/// component's lobe probability times the component's weight.
#[test]
fn delta_samples_keep_their_component_weight() {
    let (eta, k) = ior::conductor("none").unwrap();
    let mirror = Bsdf::conductor(eta, k, Vec3::splat(0.6));
    let blend = Bsdf::blend(0.25, Bsdf::diffuse(Vec3::ONE), mirror);
    let wo = Vec3::new(0.3, -0.2, 0.9).normalize();
    let s = blend.sample(wo, 0.1, Vec2::splat(0.5)).unwrap();
    assert!(s.lobe.contains(LobeFlags::DELTA | LobeFlags::REFLECTION));
    assert!((s.pdf_sa - 0.25).abs() < 1e-6);
    assert!(close(s.f / s.pdf_sa, Vec3::splat(0.6)));
    assert!(blend.flags().is_delta() && blend.has_smooth_lobe());
    // The diffuse component's samples carry the mix: (1 − w)·ρ/π·cos over (1 − w)·cos/π.
    let s = blend.sample(wo, 0.6, Vec2::splat(0.5)).unwrap();
    assert!(!s.lobe.is_delta());
    assert!(close(s.f / s.pdf_sa, Vec3::ONE));
}

/// A weight texture replaces the weight; textures of colour parameters leave a blend alone.
#[test]
fn weight_is_replaced_per_shading_point() {
    let (a, b) = (Bsdf::diffuse(Vec3::splat(0.2)), Bsdf::diffuse(Vec3::ONE));
    let blend = Bsdf::blend(0.5, a, b).masked(0.5);
    let w = blend.with_blend_weight(0.8);
    let BsdfKind::Blend(inner) = w.kind else {
        panic!("not a blend");
    };
    assert_eq!(inner.weight, 0.8);
    assert_eq!(inner.parts(), &[a, b]);
    assert_eq!(w.opacity, 0.5);
    assert_eq!(a.with_blend_weight(0.8), a);
    let BsdfKind::Blend(inner) = blend.with_blend_weight(7.0).kind else {
        panic!("not a blend");
    };
    assert_eq!(inner.weight, 1.0);
}
