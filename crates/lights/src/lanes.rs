//! Next-event estimation's light samples for eight receivers at once
//! ([`LightSet::sample_nee_lanes`]): the power sampler's pick lane by lane, and for a pick that
//! is a triangle of uniform radiance and normal (every rectangle and most emissive meshes) or a
//! sphere of uniform radiance seen from outside, the point, direction and density in lanes,
//! with the arithmetic of [`LightSet::sample_nee`]; every other lane (another light, another
//! selection) is [`LightSet::sample_nee`]'s own.

use glam::{Vec2, Vec3};
use restir_geometry::Shape;
use restir_geometry::lanes::sphere_cone_samples;
use restir_sampling::lanes::{F8, LANES, M8, V3};

use crate::table::Emitter;
use crate::{Light, LightSample, LightSet, NeeSelection};

/// Eight receivers' light samples ([`LightSet::sample_nee_lanes`]).
#[derive(Clone, Copy, Debug)]
pub struct NeeLanes {
    /// The lanes holding a sample.
    pub valid: M8,
    /// Unit directions from the receivers to the lights.
    pub wi: V3,
    /// Radiance arriving along `-wi`.
    pub le: V3,
    /// Densities per unit solid angle, selection included.
    pub pdf_sa: F8,
    /// Lanes whose light is a delta light.
    pub delta: M8,
    /// The points on the lights.
    pub p: V3,
    /// The lights' shading normals there.
    n: V3,
    /// The lights' geometric normals there.
    ng: V3,
    dist: F8,
    light: [u32; LANES],
    prim: [u32; LANES],
    param: [Vec2; LANES],
}

impl NeeLanes {
    /// Lane `i`'s sample, as [`LightSet::sample_nee`] returns it (`None` where it has none).
    #[inline(always)]
    pub fn get(&self, i: usize) -> Option<LightSample> {
        self.valid.get(i).then(|| LightSample {
            light: self.light[i],
            p: self.p.get(i),
            n: self.n.get(i),
            ng: self.ng.get(i),
            wi: self.wi.get(i),
            dist: self.dist.0[i],
            le: self.le.get(i),
            pdf_sa: self.pdf_sa.0[i],
            delta: self.delta.get(i),
            prim: self.prim[i],
            param: self.param[i],
        })
    }

    #[inline(always)]
    fn set(&mut self, i: usize, s: Option<LightSample>) {
        let Some(s) = s else {
            self.valid.set(i, false);
            return;
        };
        self.valid.set(i, true);
        self.p.set(i, s.p);
        self.n.set(i, s.n);
        self.ng.set(i, s.ng);
        self.wi.set(i, s.wi);
        self.dist.0[i] = s.dist;
        self.le.set(i, s.le);
        self.pdf_sa.0[i] = s.pdf_sa;
        self.delta.set(i, s.delta);
        self.light[i] = s.light;
        self.prim[i] = s.prim;
        self.param[i] = s.param;
    }
}

/// What a lane picked for the lanes to sample.
#[derive(Clone, Copy, Default, PartialEq)]
enum Kind {
    /// Nothing (another light, or none): [`LightSet::sample_nee`]'s sample.
    #[default]
    Other,
    /// A triangle of uniform radiance and normal.
    Triangle,
    /// A sphere of uniform radiance, seen from outside.
    Sphere,
}

/// A lane's pick: a triangle (its corners, normals and the density by area of the selection
/// and the point) or a sphere (its centre, in `p[0]`, radius and orientation, and the
/// selection's probability), its radiance and the numbers for the point.
#[derive(Clone, Copy, Default)]
struct Picked {
    p: [Vec3; 3],
    n: Vec3,
    ng: Vec3,
    le: Vec3,
    weight: f32,
    radius: f32,
    u: Vec2,
    kind: Kind,
    flip: bool,
}

impl LightSet {
    /// [`LightSet::sample_nee`] for the receivers at `ref_p` (shading normals `ref_n`) of the
    /// lanes in `lanes`, lane `i` with the numbers `u[i] = [u_select, u_fine, u.x, u.y]`: the
    /// same samples, to the bit.
    #[inline(always)]
    pub fn sample_nee_lanes(
        &self,
        how: NeeSelection,
        ref_p: V3,
        ref_n: V3,
        u: &[[f32; 4]; LANES],
        lanes: M8,
    ) -> NeeLanes {
        let mut out = NeeLanes {
            valid: M8::default(),
            wi: V3::ZERO,
            le: V3::ZERO,
            pdf_sa: F8::splat(1.0),
            delta: M8::default(),
            p: V3::ZERO,
            n: V3::ZERO,
            ng: V3::ZERO,
            dist: F8::splat(0.0),
            light: [0; LANES],
            prim: [0; LANES],
            param: [Vec2::ZERO; LANES],
        };
        // The triangles and spheres picked, one lane at a time, each as a whole record; then
        // gathered.
        let mut picked = [Picked::default(); LANES];
        for (i, &[u_select, u_fine, u0, u1]) in u.iter().enumerate() {
            if !lanes.get(i) {
                continue;
            }
            let pick = match how {
                NeeSelection::Power => self.table.pick(u_select),
                _ => None,
            };
            if let Some(Ok(&Emitter::Triangle {
                light,
                prim,
                p,
                ng,
                shading,
            })) = pick
                && let Light::Area {
                    radiance,
                    texture: None,
                    ..
                } = self.lights[light as usize]
                && let Some(n) = self.table.constant_normal(ng, shading)
            {
                picked[i] = Picked {
                    p,
                    n,
                    ng,
                    le: radiance,
                    weight: self.area_pdf[light as usize],
                    u: Vec2::new(u0, u1),
                    kind: Kind::Triangle,
                    ..Picked::default()
                };
                out.light[i] = light;
                out.prim[i] = prim;
                continue;
            }
            if let Some(Ok(&Emitter::Whole { light })) = pick
                && let Light::Area {
                    shape,
                    radiance,
                    texture: None,
                } = self.lights[light as usize]
                && let Shape::Sphere(sphere) = &self.shapes[shape as usize]
                // From inside, `Sphere::sample_from` samples by area.
                && (sphere.center - ref_p.get(i)).length_squared()
                    > sphere.radius * sphere.radius * (1.0 + 1e-4)
            {
                picked[i] = Picked {
                    p: [sphere.center; 3],
                    le: radiance,
                    weight: self.table.pmf(light),
                    radius: sphere.radius,
                    u: Vec2::new(u0, u1),
                    kind: Kind::Sphere,
                    flip: sphere.flip_normals,
                    ..Picked::default()
                };
                out.light[i] = light;
                out.prim[i] = 0;
                continue;
            }
            let s = self.sample_nee(how, ref_p.get(i), ref_n.get(i), (u_select, u_fine), {
                Vec2::new(u0, u1)
            });
            out.set(i, s);
        }
        let tri = M8::from_fn(|i| picked[i].kind == Kind::Triangle);
        let sph = M8::from_fn(|i| picked[i].kind == Kind::Sphere);
        let mine = tri | sph;
        if !mine.any() {
            return out;
        }
        let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
        let weight = F8::from_fn(|i| picked[i].weight);
        let ux = F8::from_fn(|i| picked[i].u.x);
        let uy = F8::from_fn(|i| picked[i].u.y);
        let c0 = V3::from_fn(|i| picked[i].p[0]);
        out.le = mine.select3(V3::from_fn(|i| picked[i].le), out.le);
        // Triangles: `warp::sample_uniform_triangle` and the point `TriangleMesh::point_at`
        // computes, then `area_to_solid_angle` (`pdf_area · d² / |cos θ|`).
        let (mut q, mut tri_n, mut tri_ng) = (V3::ZERO, V3::ZERO, V3::ZERO);
        let (mut b1, mut b2, mut d2, mut tri_pdf) = (zero, zero, zero, zero);
        if tri.any() {
            let c1 = V3::from_fn(|i| picked[i].p[1]);
            let c2 = V3::from_fn(|i| picked[i].p[2]);
            tri_n = V3::from_fn(|i| picked[i].n);
            tri_ng = V3::from_fn(|i| picked[i].ng);
            let su0 = ux.sqrt();
            (b1, b2) = (one - su0, uy * su0);
            let b0 = one - b1 - b2;
            q = c0.scale(b0) + c1.scale(b1) + c2.scale(b2);
            let d = q - ref_p;
            d2 = d.dot(d);
            let cos = (tri_ng.dot(d) / d2.sqrt()).abs();
            tri_pdf = weight * d2 / cos;
        }
        // Spheres: `Sphere::sample_from`'s cone, its density times the selection's.
        let (mut sp, mut sn, mut param, mut cone_pdf) = (V3::ZERO, V3::ZERO, (zero, zero), zero);
        if sph.any() {
            let radius = F8::from_fn(|i| picked[i].radius);
            (sp, sn, param, cone_pdf) = sphere_cone_samples(c0, radius, ref_p, (ux, uy));
            let flip = M8::from_fn(|i| picked[i].flip);
            sn = flip.select3(-sn, sn);
        }
        let p = sph.select3(sp, q);
        let n = sph.select3(sn, tri_n);
        // `area_light_sample`: a positive distance, the receiver in front of the emitter.
        let to = p - ref_p;
        let dist = to.dot(to).sqrt();
        let wi = to / dist;
        let facing = n.dot(wi);
        let tri_ok =
            d2.gt(zero) & tri_pdf.is_finite() & tri_pdf.gt(zero) & dist.gt(zero) & facing.lt(zero);
        // Written as `Sphere::sample_from`'s and `area_light_sample`'s rejections (a NaN passes
        // them there too).
        let sph_ok = !cone_pdf.eq(zero) & !dist.le(zero) & !facing.ge(zero);
        out.p = mine.select3(p, out.p);
        out.n = mine.select3(n, out.n);
        out.ng = mine.select3(sph.select3(sn, tri_ng), out.ng);
        out.wi = mine.select3(wi, out.wi);
        out.dist = mine.select(dist, out.dist);
        out.pdf_sa = mine.select(sph.select(cone_pdf * weight, tri_pdf), out.pdf_sa);
        out.valid = (tri & tri_ok) | (sph & sph_ok) | (!mine & out.valid);
        out.delta = !mine & out.delta;
        for i in 0..LANES {
            if tri.get(i) {
                out.param[i] = Vec2::new(b1.0[i], b2.0[i]);
            } else if sph.get(i) {
                out.param[i] = Vec2::new(param.0.0[i], param.1.0[i]);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Affine3A, Quat, Vec3};
    use restir_geometry::{Shape, Sphere, TriangleMesh};
    use restir_sampling::Pcg32;

    /// Lane by lane, the samples of [`LightSet::sample_nee`] to the bit: triangles of a
    /// rectangle and spheres seen from outside (in lanes), a smooth mesh's triangle and
    /// spheres seen from inside (one at a time), receivers behind and in front of the
    /// rectangle and of a sphere whose normals point inwards, a sphere a thousand times
    /// smaller than its distance, both selections, lanes left out.
    #[test]
    fn lanes_give_sample_nees_bits() {
        let mut quad = Shape::rectangle();
        quad.transform(&Affine3A::from_rotation_translation(
            Quat::from_rotation_x(std::f32::consts::PI),
            Vec3::new(0.0, 0.0, 2.0),
        ));
        let smooth = TriangleMesh::new(
            vec![
                Vec3::new(-1.0, 1.5, 0.0),
                Vec3::new(1.0, 1.5, 0.2),
                Vec3::new(0.0, 1.7, 1.0),
            ],
            Some(vec![
                Vec3::new(0.0, -1.0, 0.0),
                Vec3::new(0.3, -1.0, 0.0).normalize(),
                Vec3::new(0.0, -1.0, 0.3).normalize(),
            ]),
            None,
            vec![[0, 1, 2]],
            false,
        )
        .unwrap();
        let shapes = vec![
            Shape::Mesh(quad),
            Shape::Mesh(smooth),
            Shape::Sphere(Sphere::new(Vec3::new(2.0, 0.0, 1.0), 0.3, false)),
            Shape::Sphere(Sphere::new(Vec3::new(-1.5, 1.0, -1.0), 1.5, true)),
            Shape::Sphere(Sphere::new(Vec3::new(2.9, -2.9, 2.9), 0.002, false)),
        ];
        let lights = (0..5)
            .map(|shape| Light::Area {
                shape,
                // The tiny sphere bright enough to be picked.
                radiance: Vec3::new(1.0 + shape as f32, 2.0, 0.5)
                    * if shape == 4 { 2e4 } else { 1.0 },
                texture: None,
            })
            .collect();
        let set = LightSet::new(lights, shapes, (Vec3::splat(-3.0), Vec3::splat(3.0))).unwrap();
        let mut rng = Pcg32::new(9, 4);
        let (mut rectangle, mut spheres, mut inside) = (0, [0; 3], 0);
        for how in [NeeSelection::Power, NeeSelection::Hierarchy] {
            for _ in 0..2000 {
                let p = V3::from_fn(|_| {
                    Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 6.0 - 3.0
                });
                let n = V3::from_fn(|_| {
                    Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32() + 0.1).normalize()
                });
                let u = core::array::from_fn(|_| {
                    [
                        rng.next_f32(),
                        rng.next_f32(),
                        rng.next_f32(),
                        rng.next_f32(),
                    ]
                });
                let lanes = M8::from_fn(|_| rng.next_f32() < 0.9);
                let got = set.sample_nee_lanes(how, p, n, &u, lanes);
                for (i, [u0, u1, u2, u3]) in u.iter().copied().enumerate() {
                    if !lanes.get(i) {
                        assert!(got.get(i).is_none());
                        continue;
                    }
                    let want = set.sample_nee(how, p.get(i), n.get(i), (u0, u1), Vec2::new(u2, u3));
                    let bits = |s: Option<LightSample>| {
                        s.map(|s| {
                            let v = [s.p, s.n, s.ng, s.wi, s.le].map(|v| v.to_array());
                            let f = [s.dist, s.pdf_sa, s.param.x, s.param.y];
                            (v, f.map(f32::to_bits), s.light, s.prim, s.delta)
                        })
                    };
                    let v = |v: [[f32; 3]; 5]| v.map(|a| a.map(f32::to_bits));
                    let (g, w) = (bits(got.get(i)), bits(want));
                    assert_eq!(
                        g.map(|g| (v(g.0), g.1, g.2, g.3, g.4)),
                        w.map(|w| (v(w.0), w.1, w.2, w.3, w.4)),
                        "{how:?}, lane {i}"
                    );
                    if how == NeeSelection::Power
                        && let Some(s) = want
                    {
                        match s.light {
                            0 => rectangle += 1,
                            l @ 2..=4 => spheres[l as usize - 2] += 1,
                            _ => {}
                        }
                        let big = Vec3::new(-1.5, 1.0, -1.0);
                        inside += usize::from(s.light == 3 && p.get(i).distance(big) < 1.5);
                    }
                }
            }
        }
        assert!(rectangle > 1000, "{rectangle} rectangle samples");
        assert!(
            spheres.iter().all(|&n| n > 300),
            "{spheres:?} sphere samples"
        );
        assert!(inside > 100, "{inside} samples from inside a sphere");
    }
}
