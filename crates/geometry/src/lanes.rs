//! Surface data of eight mesh hits at once: a hit's corners, vertex normals, face normal and
//! `dp/du` gathered lane by lane ([`MeshHits::set`]), then the point and shading frame computed
//! in lanes ([`MeshHits::surface`]) with the arithmetic of [`TriangleMesh::surface_at`] and
//! [`Frame::from_normal_tangent`] (whose square roots and divisions, latency for one hit at a
//! time, are one instruction for eight). Also in lanes: Duff et al.'s frame around a normal,
//! the octahedral encoding of unit vectors, and points drawn on spheres in the cones they
//! subtend ([`sphere_cone_samples`]).

use glam::{Vec2, Vec3};
use restir_sampling::lanes::{F8, M8, V3};

use crate::{Frame, Ray, TriangleMesh};

/// Eight mesh hits, gathered.
#[derive(Clone, Copy, Debug, Default)]
pub struct MeshHits {
    corners: [V3; 3],
    normals: [V3; 3],
    smooth: M8,
    flip: M8,
    ng: V3,
    dpdu: V3,
    b1: F8,
    b2: F8,
}

/// A point and shading frame per lane.
#[derive(Clone, Copy, Debug, Default)]
pub struct SurfaceLanes {
    /// Position.
    pub p: V3,
    /// Geometric normal.
    pub ng: V3,
    /// The shading frame's first tangent.
    pub s: V3,
    /// Its second tangent, `n × s`.
    pub t: V3,
    /// The shading normal.
    pub n: V3,
}

impl SurfaceLanes {
    /// Lane `i`'s frame.
    #[inline(always)]
    pub fn frame(&self, i: usize) -> Frame {
        Frame {
            s: self.s.get(i),
            t: self.t.get(i),
            n: self.n.get(i),
        }
    }

    /// Sets lane `i` to a point and frame computed elsewhere.
    #[inline(always)]
    pub fn set(&mut self, i: usize, p: Vec3, ng: Vec3, f: &Frame) {
        self.p.set(i, p);
        self.ng.set(i, ng);
        self.s.set(i, f.s);
        self.t.set(i, f.t);
        self.n.set(i, f.n);
    }

    /// `v` in every lane's frame ([`Frame::to_local`]).
    #[inline(always)]
    pub fn to_local(&self, v: V3) -> V3 {
        V3 {
            x: v.dot(self.s),
            y: v.dot(self.t),
            z: v.dot(self.n),
        }
    }

    /// Every lane's local `v` in world space ([`Frame::to_world`]).
    #[inline(always)]
    pub fn to_world(&self, v: V3) -> V3 {
        self.s.scale(v.x) + self.t.scale(v.y) + self.n.scale(v.z)
    }
}

impl MeshHits {
    /// Gathers lane `i`: triangle `prim` of `mesh` at barycentrics `bary` (the traversal's).
    #[inline(always)]
    pub fn set(&mut self, i: usize, mesh: &TriangleMesh, prim: usize, bary: Vec2) {
        let [ia, ib, ic] = mesh.indices()[prim];
        let ps = mesh.positions();
        for (c, k) in self.corners.iter_mut().zip([ia, ib, ic]) {
            c.set(i, ps[k as usize]);
        }
        let smooth = match mesh.normals() {
            Some(ns) => {
                for (c, k) in self.normals.iter_mut().zip([ia, ib, ic]) {
                    c.set(i, ns[k as usize]);
                }
                true
            }
            None => false,
        };
        self.smooth.set(i, smooth);
        self.flip.set(i, mesh.flip_normals());
        self.ng.set(i, mesh.face_normal(prim));
        self.dpdu.set(i, mesh.face_dpdu(prim));
        self.b1.0[i] = bary.x;
        self.b2.0[i] = bary.y;
    }

    /// The points and shading frames of the gathered hits: [`crate::surface_at`]'s for a mesh,
    /// lane by lane (the barycentrics clamped into the triangle as
    /// [`crate::Accel::surface_interaction`] does).
    #[inline(always)]
    pub fn surface(&self) -> SurfaceLanes {
        let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
        let u = self.b1.max(zero).min(one);
        let v = self.b2.max(zero).min(one - u);
        let b0 = one - u - v;
        let [p0, p1, p2] = self.corners;
        let p = p0.scale(b0) + p1.scale(u) + p2.scale(v);
        let [n0, n1, n2] = self.normals;
        let ni = n0.scale(b0) + n1.scale(u) + n2.scale(v);
        // glam's `normalize_or_zero`: the reciprocal length where it is finite and positive.
        let rcp = one / ni.dot(ni).sqrt();
        let unit = rcp.is_finite() & rcp.gt(zero);
        let ni = ni.scale(rcp);
        let ns = (self.smooth & unit).select3(self.flip.select3(-ni, ni), self.ng);
        let (s, t) = tangents(ns, self.dpdu);
        SurfaceLanes {
            p,
            ng: self.ng,
            s,
            t,
            n: ns,
        }
    }
}

/// [`Frame::from_normal_tangent`]'s tangents in every lane: `tangent` made orthogonal to `n`,
/// or [`Frame::from_normal`]'s where it is (nearly) parallel to `n`.
#[inline(always)]
pub fn tangents(n: V3, tangent: V3) -> (V3, V3) {
    let s = tangent - n.scale(n.dot(tangent));
    let len2 = s.dot(s);
    let fallback = len2.lt(F8::splat(1e-12)) | !len2.is_finite();
    let s = s / len2.sqrt();
    let t = n.cross(s);
    let (ds, dt) = normal_tangents(n);
    (fallback.select3(ds, s), fallback.select3(dt, t))
}

/// [`Frame::from_normal`]'s tangents in every lane (Duff et al.'s basis around unit `n`).
#[inline(always)]
pub fn normal_tangents(n: V3) -> (V3, V3) {
    let one = F8::splat(1.0);
    let sign = one.copysign(n.z);
    let a = -one / (sign + n.z);
    let b = n.x * n.y * a;
    let s = V3 {
        x: one + sign * n.x * n.x * a,
        y: sign * b,
        z: -sign * n.x,
    };
    let t = V3 {
        x: b,
        y: sign + n.y * n.y * a,
        z: -n.y,
    };
    (s, t)
}

/// The octahedral encoding of unit vectors ([`crate::Sphere::param_of`]) in every lane.
#[inline(always)]
pub fn octahedral_encode(n: V3) -> (F8, F8) {
    let (zero, one, half) = (F8::splat(0.0), F8::splat(1.0), F8::splat(0.5));
    let l1 = n.x.abs() + n.y.abs() + n.z.abs();
    let (x, y) = (n.x / l1, n.y / l1);
    let sign = |v: F8| v.ge(zero).select(one, -one);
    let lower = n.z.lt(zero);
    let fx = lower.select((one - y.abs()) * sign(x), x);
    let fy = lower.select((one - x.abs()) * sign(y), y);
    (half * fx + half, half * fy + half)
}

/// The unit vectors [`octahedral_encode`] maps to `(ex, ey)`, as [`crate::Sphere::point_at`]
/// decodes them, in every lane.
#[inline(always)]
pub fn octahedral_decode(ex: F8, ey: F8) -> V3 {
    let (zero, one, two) = (F8::splat(0.0), F8::splat(1.0), F8::splat(2.0));
    let (x, y) = (two * ex - one, two * ey - one);
    let z = one - x.abs() - y.abs();
    let t = (-z).max(zero);
    let x = x + x.ge(zero).select(-t, t);
    let y = y + y.ge(zero).select(-t, t);
    V3 { x, y, z }.normalize()
}

/// Points on spheres (centres `center`, radii `radius`) drawn uniformly in the cones of
/// directions they subtend from receivers `ref_p` outside them, with the arithmetic of
/// [`crate::Sphere::sample_from`] (its cone branch) on the numbers `(ux, uy)`: the points,
/// their outward normals, their parameters ([`crate::Sphere::param_of`]) and the solid-angle
/// densities, zero where [`crate::Sphere::sample_from`] has no sample.
#[inline(always)]
pub fn sphere_cone_samples(
    center: V3,
    radius: F8,
    ref_p: V3,
    (ux, uy): (F8, F8),
) -> (V3, V3, (F8, F8), F8) {
    let (zero, one, two) = (F8::splat(0.0), F8::splat(1.0), F8::splat(2.0));
    let to_c = center - ref_p;
    let d2 = to_c.dot(to_c);
    let r2 = radius * radius;
    let dist = d2.sqrt();
    // `one_minus_cos_max` and `uniform_cone_pdf_of`.
    let sin2_max = r2 / d2;
    let omc_max = sin2_max / (one + (one - sin2_max).max(zero).sqrt());
    let solid_angle = F8::splat(2.0 * core::f32::consts::PI) * omc_max;
    let pdf = one / solid_angle;
    let pdf = (solid_angle.gt(zero) & pdf.is_finite()).select(pdf, zero);
    let omc = ux * omc_max;
    let cos_theta = one - omc;
    let sin2_theta = omc * (two - omc);
    let inv_sin_max = dist / radius;
    let cos_alpha = sin2_theta * inv_sin_max
        + cos_theta * (one - (sin2_theta * inv_sin_max * inv_sin_max).min(one)).sqrt();
    let sin_alpha = (one - cos_alpha * cos_alpha).max(zero).sqrt();
    let (sin_phi, cos_phi) = restir_sampling::lanes::sincos_turns(uy);
    let back = to_c.scale(-one / dist);
    let (bs, bt) = normal_tangents(back);
    let n = bs.scale(sin_alpha * cos_phi) + bt.scale(sin_alpha * sin_phi) + back.scale(cos_alpha);
    let param = octahedral_encode(n);
    let n = octahedral_decode(param.0, param.1);
    (center + n.scale(radius), n, param, pdf)
}

/// [`crate::offset_ray_origin`] in every lane: `p` moved off its surface along `ng`, to the
/// side `d` leaves towards.
#[inline(always)]
pub fn offset_ray_origins(p: V3, ng: V3, d: V3) -> V3 {
    let one = F8::splat(1.0);
    let side = ng.dot(d).ge(F8::splat(0.0)).select(one, -one);
    let a = V3 {
        x: p.x.abs(),
        y: p.y.abs(),
        z: p.z.abs(),
    };
    p + ng.scale(side * (a.max_element() * crate::RAY_EPSILON))
}

/// Eight rays: origins, directions and ends in lanes.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayLanes {
    /// Origins.
    pub o: V3,
    /// Directions.
    pub d: V3,
    /// Ends ([`Ray::t_max`]).
    pub t_max: F8,
}

impl RayLanes {
    /// Lane `i` is `f(i)`.
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> Ray) -> Self {
        let mut r = RayLanes::default();
        for i in 0..restir_sampling::lanes::LANES {
            r.set(i, f(i));
        }
        r
    }

    /// Lane `i`.
    #[inline(always)]
    pub fn get(&self, i: usize) -> Ray {
        Ray {
            o: self.o.get(i),
            d: self.d.get(i),
            t_max: self.t_max.0[i],
        }
    }

    /// Sets lane `i`.
    #[inline(always)]
    pub fn set(&mut self, i: usize, r: Ray) {
        self.o.set(i, r.o);
        self.d.set(i, r.d);
        self.t_max.0[i] = r.t_max;
    }

    /// Where `m` holds, the unbounded ray from `o` along `d` ([`Ray::new`]).
    #[inline(always)]
    pub fn set_where(&mut self, m: M8, o: V3, d: V3) {
        self.o = m.select3(o, self.o);
        self.d = m.select3(d, self.d);
        self.t_max = m.select(F8::splat(f32::INFINITY), self.t_max);
    }
}

/// [`crate::shadow_ray_between`] in every lane: the shadow rays' origins, unit directions and
/// the distances to test.
#[inline(always)]
pub fn shadow_rays_between(p: V3, ng: V3, target: V3) -> (V3, V3, F8) {
    let o = offset_ray_origins(p, ng, target - p);
    let to = target - o;
    let dist = to.dot(to).sqrt();
    (o, to / dist, dist * (1.0 - crate::SHADOW_EPSILON))
}

#[cfg(test)]
mod tests {
    use super::*;
    use restir_sampling::Pcg32;
    use restir_sampling::lanes::LANES;

    /// [`MeshHits::surface`] gives [`crate::surface_at`]'s point and frame to the bit: meshes
    /// with and without vertex normals, texture coordinates and flipped normals, a shading
    /// normal along dp/du (Duff et al.'s frame instead), barycentrics outside the triangle
    /// (clamped).
    #[test]
    fn lanes_give_surface_ats_bits() {
        let mut rng = Pcg32::new(3, 8);
        let mut r = |s: f32| (rng.next_f32() * 2.0 - 1.0) * s;
        let positions: Vec<Vec3> = (0..30).map(|_| Vec3::new(r(3.0), r(3.0), r(3.0))).collect();
        let normals: Vec<Vec3> = (0..30)
            .map(|k| match k {
                // Along the first triangle's dp/du: the tangent has nothing left.
                0..3 => Vec3::X,
                _ => Vec3::new(r(1.0), r(1.0), r(1.0)).normalize(),
            })
            .collect();
        let uvs: Vec<Vec2> = (0..30).map(|_| Vec2::new(r(1.0), r(1.0))).collect();
        let indices: Vec<[u32; 3]> = (0..10).map(|k| [3 * k, 3 * k + 1, 3 * k + 2]).collect();
        let mut meshes = Vec::new();
        for (n, uv, flip) in [
            (true, true, false),
            (true, false, true),
            (false, true, false),
            (false, false, true),
        ] {
            let mut p = positions.clone();
            // A triangle in the plane z = 0: without uvs its dp/du is along x.
            p[0..3].copy_from_slice(&[Vec3::ZERO, Vec3::X, Vec3::Y]);
            meshes.push(
                TriangleMesh::new(
                    p,
                    n.then(|| normals.clone()),
                    uv.then(|| uvs.clone()),
                    indices.clone(),
                    flip,
                )
                .unwrap(),
            );
        }
        let shapes: Vec<crate::Shape> = meshes.into_iter().map(crate::Shape::Mesh).collect();
        let mut checked = 0;
        for _ in 0..500 {
            let mut hits = MeshHits::default();
            let picks: [(u32, usize, Vec2); restir_sampling::lanes::LANES] =
                core::array::from_fn(|_| {
                    let shape = (rng.next_f32() * 4.0) as u32 % 4;
                    let prim = (rng.next_f32() * 10.0) as usize % 10;
                    let b = Vec2::new(rng.next_f32() * 1.2 - 0.1, rng.next_f32() * 1.2 - 0.1);
                    (shape, prim, b)
                });
            for (i, &(shape, prim, b)) in picks.iter().enumerate() {
                let crate::Shape::Mesh(m) = &shapes[shape as usize] else {
                    unreachable!()
                };
                hits.set(i, m, prim, b);
            }
            let got = hits.surface();
            for (i, &(shape, prim, b)) in picks.iter().enumerate() {
                let u = b.x.clamp(0.0, 1.0);
                let b = Vec2::new(u, b.y.clamp(0.0, 1.0 - u));
                let want = crate::surface_at(&shapes, shape, prim as u32, b);
                let f = got.frame(i);
                let bits = |v: [Vec3; 5]| v.map(|v| v.to_array().map(f32::to_bits));
                assert_eq!(
                    bits([got.p.get(i), got.ng.get(i), f.s, f.t, f.n]),
                    bits([
                        want.p,
                        want.ng,
                        want.shading.s,
                        want.shading.t,
                        want.shading.n
                    ]),
                    "shape {shape}, triangle {prim}, barycentrics {b}"
                );
                checked += 1;
            }
        }
        assert_eq!(checked, 500 * restir_sampling::lanes::LANES);
    }

    /// [`offset_ray_origins`] and [`shadow_rays_between`] give the scalar functions' bits, on
    /// either side of the surface and at points far from the origin.
    /// The octahedral encoding and decoding in lanes give the scalar bits: the axes, the
    /// equator, both hemispheres, random directions.
    #[test]
    fn lanes_give_the_octahedral_maps_bits() {
        let mut rng = Pcg32::new(21, 2);
        let mut dirs = vec![
            Vec3::X,
            -Vec3::X,
            Vec3::Y,
            -Vec3::Y,
            Vec3::Z,
            -Vec3::Z,
            Vec3::new(1.0, 1.0, 0.0).normalize(),
            Vec3::new(-1.0, 0.5, 0.0).normalize(),
        ];
        dirs.extend((0..4000).map(|_| {
            let mut c = || rng.next_f32() * 2.0 - 1.0;
            Vec3::new(c(), c(), c()).normalize()
        }));
        for chunk in dirs.chunks_exact(LANES) {
            let n = V3::from_fn(|i| chunk[i]);
            let (ex, ey) = octahedral_encode(n);
            let back = octahedral_decode(ex, ey);
            for (i, &d) in chunk.iter().enumerate() {
                let e = crate::shape::octahedral_encode(d);
                assert_eq!(
                    [ex.0[i], ey.0[i]].map(f32::to_bits),
                    e.to_array().map(f32::to_bits),
                    "{d}"
                );
                assert_eq!(
                    back.get(i).to_array().map(f32::to_bits),
                    crate::shape::octahedral_decode(e)
                        .to_array()
                        .map(f32::to_bits),
                    "{d}"
                );
            }
        }
    }

    #[test]
    fn lanes_give_the_ray_offsets_bits() {
        let mut rng = Pcg32::new(6, 2);
        for k in 0..2000 {
            let scale = if k % 2 == 0 { 1.0 } else { 1e4 };
            let mut r = || (rng.next_f32() * 2.0 - 1.0) * scale;
            let p = V3::from_fn(|_| Vec3::new(r(), r(), r()));
            let q = V3::from_fn(|_| Vec3::new(r(), r(), r()));
            let ng = V3::from_fn(|_| Vec3::new(r(), r(), r()).normalize());
            let o = offset_ray_origins(p, ng, q - p);
            let (so, sd, st) = shadow_rays_between(p, ng, q);
            for i in 0..restir_sampling::lanes::LANES {
                let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                let want = crate::offset_ray_origin(p.get(i), ng.get(i), q.get(i) - p.get(i));
                assert_eq!(bits(o.get(i)), bits(want));
                let (ray, t) = crate::shadow_ray_between(p.get(i), ng.get(i), q.get(i));
                assert_eq!(
                    (bits(so.get(i)), bits(sd.get(i)), st.0[i].to_bits()),
                    (bits(ray.o), bits(ray.d), t.to_bits())
                );
            }
        }
    }
}
