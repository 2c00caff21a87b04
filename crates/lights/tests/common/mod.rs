//! What the spot and projector tests share: a texture that shows where it is read, and the check
//! that the path ReSTIR takes for a delta light (`LightPoint` → `Resolved` → `Contact`) agrees
//! with `sample`.
#![allow(dead_code)] // each test file uses a different subset

use glam::{Mat4, Vec2, Vec3};
use restir_lights::{LightPoint, LightSet, LightTexture, Presampled};
use restir_sampling::{Pcg32, warp};

/// Mitsuba's look-at frame from `position` towards a tilted axis (`z` along the axis,
/// `x = up × z`, `y = z × x`, up `+y`): the spot's and the projector's `to_world`.
pub fn tilted_frame(position: Vec3) -> Mat4 {
    let axis = Vec3::new(0.3, -0.5, 0.8).normalize();
    let x = Vec3::Y.cross(axis).normalize();
    let y = axis.cross(x);
    Mat4::from_cols(
        x.extend(0.0),
        y.extend(0.0),
        axis.extend(0.0),
        position.extend(1.0),
    )
}

/// A texture that returns its coordinates: `(u, v, 1)`.
#[derive(Debug)]
pub struct UvRamp;

impl LightTexture for UvRamp {
    fn eval(&self, uv: Vec2) -> Vec3 {
        uv.extend(1.0)
    }
    fn mean(&self) -> Vec3 {
        Vec3::new(0.5, 0.5, 1.0)
    }
}

/// For receivers around `center`, the sample a reservoir holds, resolved once and seen from the
/// receiver, is what `sample` returned (a delta light: no solid-angle pdf); where `sample` finds
/// nothing the contact is none too, and a presampled pool of the one light draws it with
/// probability 1. Both cases must occur.
pub fn reservoir_path_agrees_with_sample(set: &LightSet, center: Vec3) {
    let mut rng = Pcg32::new(9, 0);
    let (mut inside, mut outside) = (0, 0);
    for _ in 0..20_000 {
        let x = center + 3.0 * warp::sample_uniform_sphere(rng.next_2d());
        match set.sample(x, rng.next_f32(), rng.next_2d()) {
            Some(s) => {
                inside += 1;
                let c = set
                    .contact(&LightPoint::from_light_sample(&s), x)
                    .expect("a sampled light is seen from its receiver");
                assert!(c.delta && c.measure == 1.0 && c.pdf_sa.is_none());
                assert!((c.le - s.le).abs().max_element() <= 1e-6 * s.le.max_element());
                assert!((c.wi - s.wi).length() < 1e-6 && (c.dist - s.dist).abs() < 1e-5);
                assert_eq!(set.pdf_sa(0, x, s.p, s.ng), 0.0);
            }
            None => {
                outside += 1;
                let lp = LightPoint {
                    light: 0,
                    prim: 0,
                    param: Vec2::ZERO,
                };
                assert!(set.contact(&lp, x).is_none());
            }
        }
    }
    assert!(
        inside > 0 && outside > 0,
        "inside {inside}, outside {outside}"
    );
    assert!(matches!(
        set.presample(0.5, Vec2::splat(0.5)),
        Some(Presampled::Light { light: 0, pmf }) if pmf == 1.0
    ));
}
