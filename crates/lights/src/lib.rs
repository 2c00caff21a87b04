//! Emitters and light sampling for the `restir` renderer, in one place: which light, where on
//! it, and with what density.
//!
//! | file | what it holds |
//! |---|---|
//! | `light.rs` | [`Light`] (diffuse area lights on shapes, one-sided as in Mitsuba, their radiance uniform or a [`LightTexture`] over the shape's uv; point, spot ([`Spot`]), projector ([`Projector`]), directional, constant and image environment lights, [`EnvMap`] being Mitsuba's `envmap`), [`LightSample`] (a point on one light drawn for a receiver, [`LightSet::sample_light`]) and the densities of points reached another way ([`LightSet::pdf_sa`]) |
//! | `set.rs` | [`LightSet`]: every light of a scene with the shapes area lights lie on (emitters know their shapes, as in Mitsuba 3's scene, so no caller hands the shape list around), each light's power, the environment's share of selections |
//! | `select.rs` | which light: the power sampler ([`LightSet::sample`], [`LightSet::select`], [`LightSet::pmf`]) over one flat emitter table (`table.rs`: every emissive triangle, every other light), and the light hierarchy over the same entries (`bvh.rs`: [`LightSet::sample_hierarchy`], [`LightSet::hierarchy_pmf`]) |
//! | `nee.rs` | next-event estimation's light selection ([`NeeSelection`]: by power or by the hierarchy; [`LightSet::sample_nee`], [`LightSet::pdf_nee`]), for the path tracer and ReSTIR PT's walks |
//! | `cut.rs` | the hierarchy cut once for a region of receivers ([`LightCut`], [`LightSet::light_cut`]): a node by an alias table over the cut, an emitter of it by power, with the exact probability of any entry ([`LightSet::cut_pmf`]) |
//! | `clear.rs` | where a shadow ray toward a light may end: at the clear box of a convex part of an emissive mesh that nothing else comes near ([`LightSet::shadow_end`]) |
//! | `corners.rs` | the distinct corners of some triangles and whether they all lie behind a plane: the convexity tests of `own.rs` and `clear.rs` |
//! | `point.rs` | a light sample named without its receiver ([`LightPoint`], what a reservoir holds), resolved in world space ([`LightSet::resolve`], [`Resolved`]) and seen from a receiver ([`Contact`]) |
//! | `learned.rs` | a selection learned across passes: per cell of a world-space grid, what each emitter (a triangle, another light, the environment) delivered after its shadow ray ([`LightRecords`]), sampled in a mixture with the power sampler with its exact probability ([`LearnedSampler`]) |
//! | `spot.rs` | [`Spot`], Mitsuba's `spot` emitter (a point light with an angular falloff and an optional projected [`LightTexture`]) |
//! | `projector.rs` | [`Projector`], Mitsuba's `projector` emitter (a pinhole throwing an irradiance image, a [`LightTexture`] or a constant, through a perspective frustum) |
//! | `presample.rs` | samples drawn without a receiver ([`LightSet::presample`], [`Presampled`]), for pools of presampled candidates |
//! | `sampler.rs` | one interface over all of these for a receiver's candidates ([`LightSampler`]: power, hierarchy, presampled pool, a cut of the hierarchy for a screen tile, the learned cell), each candidate with the density that drew it and the power sampler's ([`LightCandidate`]) |
//!
//! [`LightSet::sample`] returns a [`LightSample`] whose `pdf_sa` already includes the selection
//! probability; [`LightSet::pdf_sa`] returns exactly that density for a point reached another
//! way (by BSDF sampling), and [`LightSet::pmf`] the selection probability.
//!
//! Measures: `pdf_sa` is per unit solid angle at the receiving point; for delta lights (point,
//! directional) it is the discrete selection probability and `delta` is set.
//!
//! # The set of lights is closed
//!
//! A program using this crate cannot add a kind of light of its own: [`Light`] is an enum of
//! the kinds above (area, point, spot, projector, directional, constant and image environment), and sampling,
//! densities, power and the emitter table dispatch with one `match` over it. This is
//! deliberate: light sampling runs for every candidate of every pixel, and an enum keeps those
//! calls monomorphised and inlinable, keeps a [`LightPoint`] a 16-byte value a reservoir can
//! hold, and lets the emitter table and the light hierarchy know every light's power and
//! bounds when they are built. pbrt-v4 closes its set of lights the same way (a tagged union
//! over a fixed list of light types, dispatched by a `switch`).
//!
//! What a user does instead:
//! - **Use the nearest light through its parameters**: any emissive shape (a mesh of any
//!   shape with a radiance), a point, spot, projector or directional light, a constant or image environment
//!   (an HDR image with a rotation and a scale).
//! - **Fork** and add a variant to [`Light`]: the compiler then lists every `match` that must
//!   learn it (sampling, density, power, bounds for the hierarchy).
//! - **Bring your own renderer**: the `restir-reuse` crate runs the reuse passes generically
//!   over host traits (the host's own light samples, densities and target function), and
//!   `restir-gris` holds the maths; neither needs this crate.

#![deny(missing_docs)]

mod bvh;
mod clear;
mod contact;
mod corners;
mod cut;
mod envmap;
mod lanes;
mod learned;
mod light;
mod nee;
mod own;
mod point;
mod presample;
mod projector;
mod sampler;
mod select;
mod set;
mod spot;
mod table;

pub use clear::MAX_CLEAR_TRIANGLES;
pub use contact::Contact;
pub use cut::{Claim, LightCut};
pub use envmap::{EnvMap, EnvMapError};
pub use lanes::NeeLanes;
pub use learned::{CellKey, EmitterGroups, LearnGrid, LearnedDraw, LearnedSampler, LightRecords};
pub use light::{Light, LightSample, LightTexture};
pub use nee::NeeSelection;
pub use own::{OWN_LIGHT_SHARE, OwnLight};
pub use point::{LightPoint, Resolved};
pub use presample::Presampled;
pub use projector::{Projector, ProjectorError};
pub use sampler::{
    At, CandidateU, HierarchySampler, LearnedCellSampler, LightCandidate, LightSampler,
    PoolSampler, PowerSampler,
};
pub use set::{LightError, LightSet};
pub use spot::{Spot, SpotError};

/// The largest emission any light may have, in each channel of its radiance, intensity or
/// irradiance and in its power: 10²⁶. The estimators multiply emission by BSDF values,
/// geometry terms, inverse densities, Jacobians and reservoir weights, and add up candidates,
/// all in `f32` (largest 3.4·10³⁸); this leaves twelve orders of magnitude for those factors, so
/// a pixel is never infinite because a light is. Brighter is refused when the scene is built,
/// never clamped or silently dropped.
pub const MAX_EMISSION: f32 = 1e26;

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use restir_geometry::{Shape, Sphere};
    use restir_sampling::Pcg32;
    use std::f32::consts::PI;

    fn setup() -> (Vec<Shape>, LightSet) {
        let mut quad = Shape::rectangle();
        quad.transform(&glam::Affine3A::from_rotation_translation(
            glam::Quat::from_rotation_x(PI),
            Vec3::new(0.0, 0.0, 2.0),
        ));
        let shapes = vec![
            Shape::Mesh(quad),
            Shape::Sphere(Sphere::new(Vec3::new(2.0, 0.0, 1.0), 0.3, false)),
        ];
        let lights = vec![
            Light::Area {
                shape: 0,
                radiance: Vec3::splat(1.0),
                texture: None,
            },
            Light::Area {
                shape: 1,
                radiance: Vec3::new(5.0, 1.0, 1.0),
                texture: None,
            },
            Light::Point {
                position: Vec3::new(0.0, 1.0, 1.0),
                intensity: Vec3::splat(3.0),
            },
        ];
        let set = LightSet::new(
            lights,
            shapes.clone(),
            (Vec3::splat(-3.0), Vec3::splat(3.0)),
        )
        .unwrap();
        (shapes, set)
    }

    /// A set whose only light with power is one of several skips the alias table: that light is
    /// always picked with probability 1, the others never, and `sample` agrees with `pdf_sa`.
    #[test]
    fn single_light_selection() {
        let (shapes, _) = setup();
        let lights = vec![
            Light::Area {
                shape: 0,
                radiance: Vec3::ZERO,
                texture: None,
            },
            Light::Area {
                shape: 1,
                radiance: Vec3::new(5.0, 1.0, 1.0),
                texture: None,
            },
        ];
        let set = LightSet::new(
            lights,
            shapes.clone(),
            (Vec3::splat(-3.0), Vec3::splat(3.0)),
        )
        .unwrap();
        assert_eq!(set.emitter_count(), 1);
        assert_eq!((set.pmf(0), set.pmf(1)), (0.0, 1.0));
        let mut rng = Pcg32::new(5, 0);
        for _ in 0..1000 {
            let u = rng.next_f32();
            assert_eq!(set.select(u), Some((1, 1.0)));
            if let Some(s) = set.sample(Vec3::ZERO, u, rng.next_2d()) {
                let pdf = set.pdf_sa(1, Vec3::ZERO, s.p, s.ng);
                assert!(
                    (pdf - s.pdf_sa).abs() <= 1e-3 * pdf,
                    "{pdf} vs {}",
                    s.pdf_sa
                );
            }
        }
        let empty = LightSet::new(
            vec![],
            shapes.clone(),
            (Vec3::splat(-3.0), Vec3::splat(3.0)),
        )
        .unwrap();
        assert!(empty.is_empty() && empty.select(0.5).is_none());
    }

    /// The pdf a sample reports equals what `pdf_sa` recomputes, and the empirical selection
    /// frequencies match `pmf` within 4 standard errors.
    #[test]
    fn sample_pdf_pmf_agree() {
        let (_, set) = setup();
        let mut rng = Pcg32::new(11, 0);
        let n = 200_000;
        let mut counts = [0u32; 3];
        for _ in 0..n {
            let (us, u) = (rng.next_f32(), rng.next_2d());
            let Some((index, _)) = set.select(us) else {
                panic!()
            };
            let index = index as usize;
            counts[index] += 1;
            if let Some(s) = set.sample(Vec3::ZERO, us, u) {
                assert_eq!(s.light as usize, index);
                if s.delta {
                    assert!((s.pdf_sa - set.pmf(s.light)).abs() < 1e-6);
                } else {
                    let pdf = set.pdf_sa(s.light, Vec3::ZERO, s.p, s.ng);
                    assert!(
                        (pdf - s.pdf_sa).abs() <= 1e-3 * pdf,
                        "{pdf} vs {}",
                        s.pdf_sa
                    );
                }
            }
        }
        for (i, c) in counts.iter().enumerate() {
            let p = set.pmf(i as u32) as f64;
            let se = (p * (1.0 - p) / n as f64).sqrt();
            assert!((*c as f64 / n as f64 - p).abs() < 4.0 * se, "light {i}");
        }
        let total: f32 = (0..3).map(|i| set.pmf(i)).sum();
        assert!((total - 1.0).abs() < 1e-5);
    }

    /// With an environment beside local lights, the environment takes exactly its share of
    /// selections and the local lights split the rest by power; `pmf`, `select`, `sample` and
    /// `pdf_sa` agree whatever the share, and a triangle of a mesh light is picked with the
    /// mesh's pmf times its area fraction.
    #[test]
    fn environment_share_splits_selection() {
        let (shapes, _) = setup();
        let lights = vec![
            Light::Area {
                shape: 0,
                radiance: Vec3::splat(1.0),
                texture: None,
            },
            Light::Constant {
                radiance: Vec3::splat(0.2),
            },
            Light::Area {
                shape: 1,
                radiance: Vec3::new(5.0, 1.0, 1.0),
                texture: None,
            },
        ];
        let mut set = LightSet::new(
            lights,
            shapes.clone(),
            (Vec3::splat(-3.0), Vec3::splat(3.0)),
        )
        .unwrap();
        let power_share = set.environment_power_share();
        assert!((set.pmf(1) - power_share).abs() < 1e-6);
        assert_eq!(set.emitter_count(), 3, "two triangles and a sphere");
        for share in [0.3f32, 0.01, 0.99] {
            set.set_environment_share(share);
            assert_eq!(set.environment_share(), share);
            assert!((set.pmf(1) - share).abs() < 1e-7);
            let local = set.pmf(0) + set.pmf(2);
            assert!((local - (1.0 - share)).abs() < 1e-6, "{local}");
            let ratio = set.pmf(0) / set.pmf(2);
            let want = set.power(0) / set.power(2);
            assert!((ratio - want).abs() < 1e-4 * want, "{ratio} vs {want}");
            let mut rng = Pcg32::new(31, 0);
            let n = 100_000;
            let mut counts = [0u32; 3];
            for _ in 0..n {
                let (us, u) = (rng.next_f32(), rng.next_2d());
                let (light, pmf) = set.select(us).unwrap();
                assert_eq!(pmf, set.pmf(light));
                counts[light as usize] += 1;
                if let Some(s) = set.sample(Vec3::ZERO, us, u) {
                    assert_eq!(s.light, light);
                    let pdf = set.pdf_sa(s.light, Vec3::ZERO, s.p, s.ng);
                    assert!(
                        (pdf - s.pdf_sa).abs() <= 1e-3 * pdf,
                        "{pdf} vs {}",
                        s.pdf_sa
                    );
                }
            }
            for (i, c) in counts.iter().enumerate() {
                let p = set.pmf(i as u32) as f64;
                let se = (p * (1.0 - p) / n as f64).sqrt().max(1e-9);
                assert!(
                    (*c as f64 / n as f64 - p).abs() < 4.0 * se,
                    "light {i} at share {share}"
                );
            }
        }
    }

    /// ∫ over the light of Le·cos/pdf estimates the irradiance of a unit-radiance quad seen head-on,
    /// checked against the closed-form form factor of a square.
    #[test]
    fn area_sampling_estimates_irradiance() {
        let (_, set) = setup();
        let mut rng = Pcg32::new(12, 0);
        let n = 100_000;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let v = set
                .sample_light(0, Vec3::ZERO, rng.next_2d())
                .map_or(0.0, |s| (s.le.x * s.wi.z / s.pdf_sa) as f64);
            sum += v;
            sum2 += v * v;
        }
        let mean = sum / n as f64;
        let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
        // Irradiance at distance h below the centre of a 2a×2a square of unit radiance:
        // four corner rectangles, each contributing (1/2)·[x/√(x²+h²)·atan(y/√(x²+h²)) + (x↔y)].
        let (a, h) = (1.0f64, 2.0f64);
        let fa = |x: f64, y: f64| {
            x / (x * x + h * h).sqrt() * (y / (x * x + h * h).sqrt()).atan()
                + y / (y * y + h * h).sqrt() * (x / (y * y + h * h).sqrt()).atan()
        };
        let exact = 2.0 * fa(a, a);
        assert!(
            (mean - exact).abs() < 4.0 * se,
            "{mean} vs {exact} (se {se})"
        );
    }

    /// A texture whose value is its lookup point: `(u, v, 1)`.
    #[derive(Debug)]
    struct UvTexture;

    impl LightTexture for UvTexture {
        fn eval(&self, uv: glam::Vec2) -> Vec3 {
            uv.extend(1.0)
        }

        fn mean(&self) -> Vec3 {
            Vec3::new(0.5, 0.5, 1.0)
        }
    }

    /// A textured area light emits its texture at the point's uv wherever the point is met: a
    /// light sample, the same point resolved again, and a BSDF ray's hit; a set without the
    /// texture it names is an error.
    #[test]
    fn textured_area_light_reads_its_texture_where_it_is_met() {
        let (shapes, _) = setup();
        let lights = vec![Light::Area {
            shape: 0,
            radiance: Vec3::new(0.5, 0.5, 1.0),
            texture: Some(0),
        }];
        let bounds = (Vec3::splat(-3.0), Vec3::splat(3.0));
        assert_eq!(
            LightSet::new(lights.clone(), shapes.clone(), bounds).err(),
            Some(LightError::MissingLightTexture(0, 0))
        );
        let textures: Vec<std::sync::Arc<dyn LightTexture>> = vec![std::sync::Arc::new(UvTexture)];
        let set = LightSet::with_textures(lights, None, textures, shapes.clone(), bounds).unwrap();
        let accel = restir_geometry::Accel::build(&shapes);
        let mut rng = Pcg32::new(9, 0);
        let receiver = Vec3::new(0.1, -0.2, 0.0);
        let mut distinct = Vec::new();
        for _ in 0..64 {
            let s = set
                .sample(receiver, rng.next_f32(), rng.next_2d())
                .expect("the quad faces the receiver");
            let uv = restir_geometry::surface_at(&shapes, 0, s.prim, s.param).uv;
            assert!((s.le - uv.extend(1.0)).length() < 1e-5, "{} at {uv}", s.le);
            distinct.push(s.le.x);
            let point = LightPoint {
                light: s.light,
                prim: s.prim,
                param: s.param,
            };
            match set.resolve(&point) {
                Resolved::Surface { le, .. } => assert_eq!(le, s.le),
                other => panic!("{other:?}"),
            }
            let ray = restir_geometry::Ray::new(receiver, s.wi);
            let hit = accel
                .intersect(&ray, f32::INFINITY)
                .expect("the sample is on the quad");
            let si = accel.surface_interaction(&shapes, &hit, &ray);
            let le = set.area_radiance(0, &si, -s.wi);
            assert!((le - s.le).length() < 1e-3, "{le} vs {}", s.le);
        }
        // The texture varies over the light (not its mean everywhere).
        distinct.sort_by(f32::total_cmp);
        assert!(distinct[63] - distinct[0] > 0.5, "{distinct:?}");
    }
}
