//! Next-event estimation's light samples for eight receivers at once
//! ([`LightSet::sample_nee_lanes`]): the power sampler's pick lane by lane, and for a pick that
//! is a triangle of uniform radiance and normal (every rectangle and most emissive meshes) the
//! point, direction and density in lanes, with the arithmetic of [`LightSet::sample_nee`];
//! every other lane (another light, another selection) is [`LightSet::sample_nee`]'s own.

use glam::{Vec2, Vec3};
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

/// A lane's triangle pick: the triangle, its normals and radiance, the density by area of the
/// selection and the point, and the numbers for the point.
#[derive(Clone, Copy, Default)]
struct Picked {
    p: [Vec3; 3],
    n: Vec3,
    ng: Vec3,
    le: Vec3,
    area_pdf: f32,
    u: Vec2,
    tri: bool,
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
        // The triangles picked, one lane at a time, each as a whole record; then gathered.
        let mut picked = [Picked::default(); LANES];
        for (i, &[u_select, u_fine, u0, u1]) in u.iter().enumerate() {
            if !lanes.get(i) {
                continue;
            }
            if how == NeeSelection::Power
                && let Some(Ok(&Emitter::Triangle {
                    light,
                    prim,
                    p,
                    ng,
                    shading,
                })) = self.table.pick(u_select)
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
                    area_pdf: self.area_pdf[light as usize],
                    u: Vec2::new(u0, u1),
                    tri: true,
                };
                out.light[i] = light;
                out.prim[i] = prim;
                continue;
            }
            let s = self.sample_nee(how, ref_p.get(i), ref_n.get(i), (u_select, u_fine), {
                Vec2::new(u0, u1)
            });
            out.set(i, s);
        }
        let tri = M8::from_fn(|i| picked[i].tri);
        if !tri.any() {
            return out;
        }
        let c0 = V3::from_fn(|i| picked[i].p[0]);
        let c1 = V3::from_fn(|i| picked[i].p[1]);
        let c2 = V3::from_fn(|i| picked[i].p[2]);
        let area_pdf = F8::from_fn(|i| picked[i].area_pdf);
        let ux = F8::from_fn(|i| picked[i].u.x);
        let uy = F8::from_fn(|i| picked[i].u.y);
        out.n = tri.select3(V3::from_fn(|i| picked[i].n), out.n);
        out.ng = tri.select3(V3::from_fn(|i| picked[i].ng), out.ng);
        out.le = tri.select3(V3::from_fn(|i| picked[i].le), out.le);
        // `warp::sample_uniform_triangle` and the point `TriangleMesh::point_at` computes.
        let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
        let su0 = ux.sqrt();
        let (b1, b2) = (one - su0, uy * su0);
        let b0 = one - b1 - b2;
        let q = c0.scale(b0) + c1.scale(b1) + c2.scale(b2);
        // `area_to_solid_angle`: `pdf_area · d² / |cos θ|`, finite and positive.
        let d = q - ref_p;
        let d2 = d.dot(d);
        let cos = (out.ng.dot(d) / d2.sqrt()).abs();
        let pdf = area_pdf * d2 / cos;
        // `area_light_sample`: a positive distance, the receiver in front of the emitter.
        let to = q - ref_p;
        let dist = to.dot(to).sqrt();
        let wi = to / dist;
        let ok =
            d2.gt(zero) & pdf.is_finite() & pdf.gt(zero) & dist.gt(zero) & out.n.dot(wi).lt(zero);
        out.p = tri.select3(q, out.p);
        out.wi = tri.select3(wi, out.wi);
        out.dist = tri.select(dist, out.dist);
        out.pdf_sa = tri.select(pdf, out.pdf_sa);
        out.valid = (tri & ok) | (!tri & out.valid);
        out.delta = !tri & out.delta;
        for i in 0..LANES {
            if tri.get(i) {
                out.param[i] = Vec2::new(b1.0[i], b2.0[i]);
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
    /// rectangle (in lanes), of a smooth mesh and a sphere (one at a time), receivers behind
    /// and in front of the rectangle, both selections, lanes left out.
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
        ];
        let lights = (0..3)
            .map(|shape| Light::Area {
                shape,
                radiance: Vec3::new(1.0 + shape as f32, 2.0, 0.5),
                texture: None,
            })
            .collect();
        let set = LightSet::new(lights, shapes, (Vec3::splat(-3.0), Vec3::splat(3.0))).unwrap();
        let mut rng = Pcg32::new(9, 4);
        let mut in_lanes = 0;
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
                    in_lanes += usize::from(
                        how == NeeSelection::Power && want.is_some_and(|s| s.light == 0),
                    );
                }
            }
        }
        assert!(in_lanes > 1000, "{in_lanes} rectangle samples");
    }
}
