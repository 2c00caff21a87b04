//! The emitter table: what one light selection picks, in O(1).
//!
//! Every emissive triangle is an entry of its own, with its corners inline and a weight equal to
//! its power `π·A·lum(L)`; every other light with power (a sphere, a point or a directional light)
//! is one entry weighted by its power. One alias table over all entries picks an entry in one
//! lookup, whatever the grouping of triangles into meshes: no per-mesh cdf search and no index
//! chain from light to shape to triangle (as pbrt-v4 flattens its emitters into one light list,
//! Pharr et al., *Physically Based Rendering*, 4th ed., §12.6).
//!
//! Picking a triangle by its power and a point on it uniformly gives every point of a mesh light
//! the same area density as picking the mesh by power and a point uniformly by area, so the
//! density of a light point is `pmf(light) / area(light)`, as before the table existed.
//!
//! The environment (constant or image) is kept apart with its own share `s` of the selections:
//! the local entries share `1 − s` by power. Power is no measure of how much an environment
//! contributes next to local lights (its "power" through the scene's bounding sphere counts light
//! that walls and ceilings block), so the share is decided from what receivers actually see
//! ([`crate::LightSet::set_environment_share`]); the default is the power share.

use glam::{Vec2, Vec3};
use restir_geometry::{PositionSample, Shape};
use restir_sampling::{AliasTable, warp};

/// One entry of the table.
///
/// A triangle entry keeps what sampling a point on it reads (its corners and geometric normal
/// inline, its shading normal by [`Shading`]) and nothing else: 64 bytes, and 12 more for its bin
/// of the alias table. Its selection weight is not kept: [`EmitterTable::weights`] recomputes it
/// (the same bits) for the light hierarchy, the one reader.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Emitter {
    /// An emissive triangle of a mesh area light, corners inline.
    Triangle {
        /// The area light the triangle belongs to.
        light: u32,
        /// The triangle's index in its mesh.
        prim: u32,
        /// Corners, in the mesh's order.
        p: [Vec3; 3],
        /// Unit geometric normal, oriented as the mesh orients it.
        ng: Vec3,
        /// Where the shading normal comes from.
        shading: Shading,
    },
    /// A light sampled as a whole (sphere, point and directional lights).
    Whole {
        /// The light.
        light: u32,
    },
}

/// The shading normal of a triangle entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Shading {
    /// The geometric normal: the mesh has no vertex normals, or three equal ones that give the
    /// geometric normal to the bit.
    Flat,
    /// The same over the whole triangle (three equal vertex normals, a rectangle's), other than
    /// the geometric normal: the table's constant normal of this index.
    Constant(u32),
    /// Varying over the triangle: interpolated from the mesh's vertex normals.
    Smooth,
}

impl Emitter {
    /// The light the entry belongs to.
    #[inline]
    pub fn light(&self) -> u32 {
        match *self {
            Emitter::Triangle { light, .. } | Emitter::Whole { light } => light,
        }
    }
}

/// The area of a triangle entry with corners `p` (a uniform point on it has density one over
/// it).
#[inline]
pub(crate) fn triangle_area(p: &[Vec3; 3]) -> f32 {
    0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
}

/// Triangle `t`'s shading normal: `Some(n)` where it is the same everywhere on it, as
/// [`restir_geometry::TriangleMesh::point_at`] orients it (`ng` without vertex normals), `None`
/// where it varies.
fn constant_shading_normal(m: &restir_geometry::TriangleMesh, t: usize, ng: Vec3) -> Option<Vec3> {
    let Some(normals) = m.normals() else {
        return Some(ng);
    };
    let [a, b, c] = m.indices()[t].map(|i| normals[i as usize]);
    if a != b || a != c {
        return None;
    }
    let n = a.normalize_or_zero();
    Some(if n == Vec3::ZERO {
        ng
    } else if m.flip_normals() {
        -n
    } else {
        n
    })
}

/// Whether two vectors have the same bits (`==` takes `-0.0` for `0.0`).
fn same_bits(a: Vec3, b: Vec3) -> bool {
    a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits)
}

/// The selection weight of triangle `t` of a mesh light of radiance `radiance`: its power
/// `π·A·lum(L)`.
fn triangle_weight(radiance: Vec3, m: &restir_geometry::TriangleMesh, t: usize) -> f32 {
    core::f32::consts::PI * restir_sampling::luminance(radiance) * m.triangle_area(t)
}

/// How an entry is picked, decided once when the table is built: one entry skips the alias
/// table, and no entry means nothing to pick.
#[derive(Clone, Debug)]
enum Selection {
    Empty,
    Single,
    Alias(AliasTable),
}

/// The local emitters, the environment and the split between them.
#[derive(Clone, Debug)]
pub(crate) struct EmitterTable {
    entries: Vec<Emitter>,
    /// The shading normals of [`Shading::Constant`] entries.
    normals: Vec<Vec3>,
    selection: Selection,
    /// Per light, the probability that a local selection picks one of its entries.
    local_pmf: Vec<f32>,
    /// The environment light, if it has power.
    environment: Option<u32>,
    /// Share of selections that go to the environment.
    env_share: f32,
    /// The power share of the environment, the default of `env_share`.
    env_power_share: f32,
    /// Per light, the entry of its triangle 0 when every triangle of its mesh has an entry, in
    /// order (so triangle `t` is entry `first + t`); [`EmitterTable::NO_ENTRIES`] otherwise.
    first_triangle_entry: Vec<u32>,
    /// Per light, its first entry ([`EmitterTable::NO_ENTRIES`] for a light without entries):
    /// a light's entries are consecutive, so naming a sample's emitter needs no search over the
    /// table ([`crate::LightSet::emitter_of`]).
    first_entry: Vec<u32>,
}

impl EmitterTable {
    /// Builds the table from the lights' shapes and powers; `environment` is the environment
    /// light (its power in `powers`). Lights without power get no entry.
    pub fn new(
        lights: &[crate::Light],
        shapes: &[Shape],
        powers: &[f32],
        environment: Option<u32>,
    ) -> Self {
        // Sized once: a growing table would hold two copies at its peak.
        let capacity: usize = lights
            .iter()
            .zip(powers)
            .map(|(l, &power)| match (*l, power > 0.0) {
                (crate::Light::Area { shape, .. }, true) => match shapes.get(shape as usize) {
                    Some(Shape::Mesh(m)) => m.triangle_count(),
                    _ => 1,
                },
                (_, true) => 1,
                (_, false) => 0,
            })
            .sum();
        let mut entries = Vec::with_capacity(capacity);
        let mut weights = Vec::with_capacity(capacity);
        let mut normals = Vec::new();
        let mut first_triangle_entry = vec![Self::NO_ENTRIES; lights.len()];
        let mut first_entry = vec![Self::NO_ENTRIES; lights.len()];
        for (i, (l, &power)) in lights.iter().zip(powers).enumerate() {
            let light = i as u32;
            if power <= 0.0 || Some(light) == environment {
                continue;
            }
            let mesh = match *l {
                crate::Light::Area {
                    shape, radiance, ..
                } => match shapes.get(shape as usize) {
                    Some(Shape::Mesh(m)) => Some((m, radiance)),
                    _ => None,
                },
                _ => None,
            };
            match mesh {
                Some((m, radiance)) => {
                    let first = entries.len();
                    for t in 0..m.triangle_count() {
                        let w = triangle_weight(radiance, m, t);
                        if !(w > 0.0 && w.is_finite()) {
                            continue;
                        }
                        let ng = m.face_normal(t);
                        let shading = match constant_shading_normal(m, t, ng) {
                            None => Shading::Smooth,
                            Some(n) if same_bits(n, ng) => Shading::Flat,
                            Some(n) => {
                                normals.push(n);
                                Shading::Constant(normals.len() as u32 - 1)
                            }
                        };
                        entries.push(Emitter::Triangle {
                            light,
                            prim: t as u32,
                            p: m.triangle(t),
                            ng,
                            shading,
                        });
                        weights.push(w);
                    }
                    if entries.len() - first == m.triangle_count() {
                        first_triangle_entry[i] = first as u32;
                    }
                    if entries.len() > first {
                        first_entry[i] = first as u32;
                    }
                }
                None => {
                    first_entry[i] = entries.len() as u32;
                    entries.push(Emitter::Whole { light });
                    weights.push(power);
                }
            }
        }
        entries.shrink_to_fit();
        let selection = match entries.len() {
            0 => Selection::Empty,
            1 => Selection::Single,
            _ => AliasTable::new(&weights).map_or(Selection::Empty, Selection::Alias),
        };
        let mut local_pmf = vec![0.0f32; lights.len()];
        let total: f64 = weights.iter().map(|&w| w as f64).sum();
        if total > 0.0 {
            let mut sums = vec![0.0f64; lights.len()];
            for (e, &w) in entries.iter().zip(&weights) {
                sums[e.light() as usize] += w as f64;
            }
            for (p, s) in local_pmf.iter_mut().zip(sums) {
                *p = (s / total) as f32;
            }
        }
        let environment = environment.filter(|&e| powers[e as usize] > 0.0);
        let env_power_share = match environment {
            None => 0.0,
            Some(e) => {
                let pe = powers[e as usize] as f64;
                (pe / (pe + total)) as f32
            }
        };
        drop(weights);
        let mut table = Self {
            entries,
            normals,
            selection,
            local_pmf,
            environment,
            env_share: 0.0,
            env_power_share,
            first_triangle_entry,
            first_entry,
        };
        table.set_env_share(env_power_share);
        table
    }

    /// `first_triangle_entry` of a light whose triangles are not all entries.
    const NO_ENTRIES: u32 = u32::MAX;

    /// The entry of triangle `prim` of area light `light`, when the table holds every triangle
    /// of the light's mesh.
    #[inline]
    pub fn triangle_entry(&self, light: u32, prim: u32) -> Option<&Emitter> {
        let first = *self.first_triangle_entry.get(light as usize)?;
        if first == Self::NO_ENTRIES {
            return None;
        }
        self.entries.get(first as usize + prim as usize)
    }

    /// The first entry of `light`, if it has entries (its entries follow it).
    #[inline]
    pub fn first_entry(&self, light: u32) -> Option<usize> {
        let first = *self.first_entry.get(light as usize)?;
        (first != Self::NO_ENTRIES).then_some(first as usize)
    }

    /// Sets the environment's share of selections (clamped to what the table holds: 0 without
    /// an environment, 1 without local emitters).
    pub fn set_env_share(&mut self, share: f32) {
        self.env_share = match (self.environment, self.has_local()) {
            (None, _) => 0.0,
            (Some(_), false) => 1.0,
            (Some(_), true) => share.clamp(0.0, 1.0),
        };
    }

    /// The environment's share of selections.
    pub fn env_share(&self) -> f32 {
        self.env_share
    }

    /// The environment's power share (the default share).
    pub fn env_power_share(&self) -> f32 {
        self.env_power_share
    }

    fn has_local(&self) -> bool {
        !matches!(self.selection, Selection::Empty)
    }

    /// Whether nothing can be picked.
    pub fn is_empty(&self) -> bool {
        !self.has_local() && self.environment.is_none()
    }

    /// Number of local entries.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// The local entries.
    pub fn entries(&self) -> &[Emitter] {
        &self.entries
    }

    /// Each local entry's selection weight (its power), recomputed from the lights, their
    /// shapes and `powers` as [`EmitterTable::new`] computed it (the same bits).
    pub fn weights(&self, lights: &[crate::Light], shapes: &[Shape], powers: &[f32]) -> Vec<f32> {
        self.entries
            .iter()
            .map(|e| match *e {
                Emitter::Triangle { light, prim, .. } => match lights[light as usize] {
                    crate::Light::Area {
                        shape, radiance, ..
                    } => match &shapes[shape as usize] {
                        Shape::Mesh(m) => triangle_weight(radiance, m, prim as usize),
                        _ => 0.0,
                    },
                    _ => 0.0,
                },
                Emitter::Whole { light } => powers[light as usize],
            })
            .collect()
    }

    /// The probability that a local selection picks entry `entry` (among the local entries).
    pub fn entry_pmf(&self, entry: usize) -> f32 {
        match &self.selection {
            Selection::Empty => 0.0,
            Selection::Single => (entry == 0) as u32 as f32,
            Selection::Alias(t) => t.pmf(entry),
        }
    }

    /// The shading normal of a triangle entry where it is the same over the whole triangle;
    /// `None` where it varies.
    #[inline]
    pub fn constant_normal(&self, ng: Vec3, shading: Shading) -> Option<Vec3> {
        match shading {
            Shading::Flat => Some(ng),
            Shading::Constant(i) => self.normals.get(i as usize).copied(),
            Shading::Smooth => None,
        }
    }

    /// A uniform point on a triangle entry, computed exactly as
    /// [`restir_geometry::TriangleMesh::point_at`] computes it (so a point named by its
    /// barycentrics resolves to the same bits later, through the table); `shape` is read only
    /// for smooth meshes.
    #[inline]
    pub fn triangle_point(
        &self,
        p: &[Vec3; 3],
        ng: Vec3,
        shading: Shading,
        shape: &Shape,
        prim: u32,
        u: Vec2,
    ) -> PositionSample {
        self.point_at(
            p,
            ng,
            shading,
            shape,
            prim,
            warp::sample_uniform_triangle(u),
        )
    }

    /// The point of a triangle entry at barycentrics `b`, the same bits as
    /// [`restir_geometry::TriangleMesh::point_at`] except a [`Shading::Constant`] normal, which
    /// is the vertex normal itself (the mesh interpolates three copies of it, which may differ in
    /// the last bit); `shape` is read only for smooth meshes.
    #[inline]
    pub fn point_at(
        &self,
        p: &[Vec3; 3],
        ng: Vec3,
        shading: Shading,
        shape: &Shape,
        prim: u32,
        b: Vec2,
    ) -> PositionSample {
        let b0 = 1.0 - b.x - b.y;
        let point = b0 * p[0] + b.x * p[1] + b.y * p[2];
        let n = match (self.constant_normal(ng, shading), shape) {
            (Some(n), _) => n,
            (None, Shape::Mesh(m)) => m.point_at(prim as usize, b).2,
            (None, _) => ng,
        };
        PositionSample {
            p: point,
            n,
            ng,
            prim,
            param: b,
        }
    }

    /// Probability that a selection picks light `light` (any of its entries).
    #[inline]
    pub fn pmf(&self, light: u32) -> f32 {
        if Some(light) == self.environment {
            self.env_share
        } else {
            (1.0 - self.env_share) * self.local_pmf.get(light as usize).copied().unwrap_or(0.0)
        }
    }

    /// Picks the environment or an entry with uniform `u`: `Err(environment light)` or
    /// `Ok(entry)`.
    #[inline]
    pub fn pick(&self, u: f32) -> Option<Result<&Emitter, u32>> {
        Some(self.pick_index(u)?.map(|e| &self.entries[e]))
    }

    /// [`EmitterTable::pick`] by index: `Err(environment light)` or `Ok(entry index)`.
    #[inline]
    pub fn pick_index(&self, u: f32) -> Option<Result<usize, u32>> {
        let s = self.env_share;
        if let Some(env) = self.environment
            && u < s
        {
            return Some(Err(env));
        }
        let v = if s > 0.0 {
            ((u - s) / (1.0 - s)).clamp(0.0, restir_sampling::ONE_MINUS_EPSILON)
        } else {
            u
        };
        match &self.selection {
            Selection::Empty => None,
            Selection::Single => Some(Ok(0)),
            Selection::Alias(t) => Some(Ok(t.sample(v).0)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Light;
    use restir_geometry::TriangleMesh;

    /// Two triangles of a quad with the given vertex normals.
    fn quad(normals: Option<Vec<Vec3>>, flip: bool) -> Shape {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.1, 0.0),
            Vec3::new(1.0, 1.0, 0.2),
            Vec3::new(0.0, 1.0, 0.1),
        ];
        Shape::Mesh(TriangleMesh::new(p, normals, None, vec![[0, 1, 2], [0, 2, 3]], flip).unwrap())
    }

    fn table(shape: &Shape) -> EmitterTable {
        let lights = [Light::Area {
            shape: 0,
            radiance: Vec3::ONE,
            texture: None,
        }];
        EmitterTable::new(&lights, std::slice::from_ref(shape), &[1.0], None)
    }

    /// Every kind of shading normal resolves to the bits the mesh gives the same point, and is
    /// stored as the kind it is.
    #[test]
    fn entries_give_the_meshs_points() {
        // What the type documentation promises a triangle entry costs.
        assert_eq!(size_of::<Emitter>(), 64);
        let tilted = Vec3::new(0.1, -0.2, 1.0);
        let cases = [
            (None, Shading::Flat),
            (Some(vec![tilted; 4]), Shading::Constant(0)),
            (
                Some(vec![tilted, Vec3::Z, Vec3::X + Vec3::Z, Vec3::Y + Vec3::Z]),
                Shading::Smooth,
            ),
        ];
        for (normals, kind) in cases {
            for flip in [false, true] {
                let shape = quad(normals.clone(), flip);
                let Shape::Mesh(m) = &shape else {
                    unreachable!()
                };
                let t = table(&shape);
                assert_eq!(t.len(), 2);
                for (prim, e) in t.entries().iter().enumerate() {
                    let Emitter::Triangle {
                        ref p, ng, shading, ..
                    } = *e
                    else {
                        panic!("a triangle entry");
                    };
                    assert_eq!(
                        std::mem::discriminant(&shading),
                        std::mem::discriminant(&kind)
                    );
                    for b in [
                        Vec2::new(0.2, 0.3),
                        Vec2::new(0.0, 1.0),
                        Vec2::new(0.5, 0.5),
                    ] {
                        let got = t.point_at(p, ng, shading, &shape, prim as u32, b);
                        let (wp, wng, wn) = m.point_at(prim, b);
                        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                        assert_eq!(bits(got.p), bits(wp), "{kind:?} flip {flip}");
                        if kind == Shading::Constant(0) {
                            // The vertex normal itself, not the mesh's interpolation of three
                            // copies of it (which may round differently in the last bit).
                            let n = tilted.normalize();
                            let n = if flip { -n } else { n };
                            assert_eq!(bits(got.n), bits(n), "flip {flip}");
                            assert!((got.n - wn).length() < 1e-6, "flip {flip}");
                        } else {
                            assert_eq!(bits(got.n), bits(wn), "{kind:?} flip {flip}");
                        }
                        assert_eq!(bits(got.ng), bits(wng), "{kind:?} flip {flip}");
                    }
                }
                // Negative control: reading a constant normal as the geometric one moves it.
                if let Some(Emitter::Triangle { ng, .. }) = t.entries().first()
                    && kind == Shading::Constant(0)
                {
                    assert_ne!(
                        t.constant_normal(*ng, Shading::Flat),
                        Some(m.point_at(0, Vec2::ZERO).2)
                    );
                }
            }
        }
    }

    /// The weights recomputed for the light hierarchy are the ones the table was built with:
    /// the entry probabilities follow from them to the bit.
    #[test]
    fn recomputed_weights_match_the_selection() {
        let shape = quad(None, false);
        let lights = [Light::Area {
            shape: 0,
            radiance: Vec3::new(1.0, 2.0, 0.5),
            texture: None,
        }];
        let t = EmitterTable::new(&lights, std::slice::from_ref(&shape), &[1.0], None);
        let w = t.weights(&lights, std::slice::from_ref(&shape), &[1.0]);
        let total: f64 = w.iter().map(|&x| x as f64).sum();
        for (i, &x) in w.iter().enumerate() {
            assert_eq!(t.entry_pmf(i), (x as f64 / total) as f32);
        }
        assert_eq!(t.entry_pmf(2), 0.0);
    }
}
