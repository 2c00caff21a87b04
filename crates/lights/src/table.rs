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
        /// The shading normal where it is the same over the whole triangle (no vertex normals,
        /// or three equal ones: a rectangle's).
        n: Vec3,
        /// Whether the shading normal varies over the triangle (then it is interpolated).
        smooth: bool,
    },
    /// A light sampled as a whole (sphere, point and directional lights).
    Whole {
        /// The light.
        light: u32,
    },
}

impl Emitter {
    /// The light the entry belongs to.
    #[inline]
    pub fn light(&self) -> u32 {
        match *self {
            Emitter::Triangle { light, .. } | Emitter::Whole { light } => light,
        }
    }

    /// A uniform point on a triangle entry, computed exactly as
    /// [`restir_geometry::TriangleMesh::point_at`] computes it (so a point named by its
    /// barycentrics resolves to the same bits later); `shapes` only for smooth meshes.
    #[inline]
    pub fn triangle_point(
        p: &[Vec3; 3],
        ng: Vec3,
        n: Vec3,
        smooth: bool,
        shape: &Shape,
        prim: u32,
        u: Vec2,
    ) -> PositionSample {
        Self::point_at(
            p,
            ng,
            n,
            smooth,
            shape,
            prim,
            warp::sample_uniform_triangle(u),
        )
    }

    /// The point of a triangle entry at barycentrics `b`, the same bits as
    /// [`restir_geometry::TriangleMesh::point_at`]; `shape` is read only for smooth meshes.
    #[inline]
    pub fn point_at(
        p: &[Vec3; 3],
        ng: Vec3,
        n: Vec3,
        smooth: bool,
        shape: &Shape,
        prim: u32,
        b: Vec2,
    ) -> PositionSample {
        let b0 = 1.0 - b.x - b.y;
        let point = b0 * p[0] + b.x * p[1] + b.y * p[2];
        let n = match (smooth, shape) {
            (true, Shape::Mesh(m)) => m.point_at(prim as usize, b).2,
            _ => n,
        };
        PositionSample {
            p: point,
            n,
            ng,
            prim,
            param: b,
        }
    }
}

/// Triangle `t`'s shading normal if it is the same everywhere on it (`(n, false)`), as
/// [`restir_geometry::TriangleMesh::point_at`] orients it, else `(ng, true)`.
fn constant_shading_normal(m: &restir_geometry::TriangleMesh, t: usize, ng: Vec3) -> (Vec3, bool) {
    let Some(normals) = m.normals() else {
        return (ng, false);
    };
    let [a, b, c] = m.indices()[t].map(|i| normals[i as usize]);
    if a != b || a != c {
        return (ng, true);
    }
    let n = a.normalize_or_zero();
    if n == Vec3::ZERO {
        (ng, false)
    } else if m.flip_normals() {
        (-n, false)
    } else {
        (n, false)
    }
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
    /// Each entry's selection weight (its power).
    weights: Vec<f32>,
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
        let mut entries = Vec::new();
        let mut weights = Vec::new();
        let mut first_triangle_entry = vec![Self::NO_ENTRIES; lights.len()];
        for (i, (l, &power)) in lights.iter().zip(powers).enumerate() {
            let light = i as u32;
            if power <= 0.0 || Some(light) == environment {
                continue;
            }
            let mesh = match *l {
                crate::Light::Area { shape, radiance } => match shapes.get(shape as usize) {
                    Some(Shape::Mesh(m)) => Some((m, radiance)),
                    _ => None,
                },
                _ => None,
            };
            match mesh {
                Some((m, radiance)) => {
                    let per_area = core::f32::consts::PI * restir_sampling::luminance(radiance);
                    let first = entries.len();
                    for t in 0..m.triangle_count() {
                        let p = m.triangle(t);
                        let w = per_area * m.triangle_area(t);
                        if !(w > 0.0 && w.is_finite()) {
                            continue;
                        }
                        let ng = m.face_normal(t);
                        let (n, smooth) = constant_shading_normal(m, t, ng);
                        entries.push(Emitter::Triangle {
                            light,
                            prim: t as u32,
                            p,
                            ng,
                            n,
                            smooth,
                        });
                        weights.push(w);
                    }
                    if entries.len() - first == m.triangle_count() {
                        first_triangle_entry[i] = first as u32;
                    }
                }
                None => {
                    entries.push(Emitter::Whole { light });
                    weights.push(power);
                }
            }
        }
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
        let mut table = Self {
            entries,
            weights,
            selection,
            local_pmf,
            environment,
            env_share: 0.0,
            env_power_share,
            first_triangle_entry,
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

    /// The probability that the local selection (the environment aside) picks entry `e`.
    #[inline]
    pub fn local_entry_pmf(&self, e: usize) -> f32 {
        match &self.selection {
            Selection::Empty => 0.0,
            Selection::Single => f32::from(e == 0),
            Selection::Alias(t) => t.pmf(e),
        }
    }

    /// Each local entry's selection weight (its power).
    pub fn weights(&self) -> &[f32] {
        &self.weights
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
