//! Which light: the power sampler (one alias table over the emitter table's entries, every
//! emissive triangle and every other light, the environment with its own share) and the light
//! hierarchy over the same entries (`bvh.rs`, receiver-aware, with the exact probability of any
//! entry). Where on the chosen light is [`LightSet::sample_light`]'s, or for a triangle of the
//! table a uniform point on it.

use glam::{Vec2, Vec3};
use restir_geometry::area_to_solid_angle;

use crate::bvh::LightBvh;
use crate::light::area_light_sample;
use crate::table::{Emitter, triangle_area};
use crate::{EmitterGroups, LightSample, LightSet};

impl LightSet {
    /// Picks a light: `(index, probability)`, the probability being [`LightSet::pmf`].
    #[inline]
    pub fn select(&self, u: f32) -> Option<(u32, f32)> {
        let light = match self.table.pick(u)? {
            Ok(e) => e.light(),
            Err(env) => env,
        };
        Some((light, self.table.pmf(light)))
    }

    /// Picks a light by power (`u_select`) and a point on it (`u`) as seen from `ref_p`.
    #[inline]
    pub fn sample(&self, ref_p: Vec3, u_select: f32, u: Vec2) -> Option<LightSample> {
        let light = match self.table.pick(u_select)? {
            Ok(e @ Emitter::Triangle { .. }) => return self.sample_triangle(e, ref_p, u),
            Ok(&Emitter::Whole { light }) => light,
            Err(env) => env,
        };
        let mut s = self.sample_light(light, ref_p, u)?;
        s.pdf_sa *= self.table.pmf(light);
        Some(s)
    }

    /// A uniform point on an emissive triangle the table picked, with the selection in its
    /// density.
    #[inline]
    fn sample_triangle(&self, e: &Emitter, ref_p: Vec3, u: Vec2) -> Option<LightSample> {
        let (light, ps, radiance) = self.triangle_entry_point(e, u)?;
        let pdf_sa = area_to_solid_angle(self.area_pdf[light as usize], ref_p, ps.p, ps.ng)?;
        area_light_sample(light, radiance, ref_p, ps, pdf_sa)
    }

    /// The light hierarchy over the table's entries (built on the first call).
    pub(crate) fn hierarchy(&self) -> &LightBvh {
        self.hierarchy.get_or_init(|| {
            let weights = self.table.weights(&self.lights, &self.shapes, &self.powers);
            LightBvh::new(&self.lights, &self.shapes, &self.table, &weights)
        })
    }

    /// Builds the light hierarchy now (else the first [`LightSet::sample_hierarchy`] does);
    /// returns its node count.
    pub fn build_hierarchy(&self) -> usize {
        self.hierarchy().node_count()
    }

    /// Picks a light for a receiver at `ref_p` with normal `ref_n` (zero if unknown) by the
    /// light hierarchy (`u_select ∈ [0, 1)`, the environment keeping its share), and a point on
    /// it (`u`). Returns the sample, whose `pdf_sa` includes the hierarchy's selection
    /// probability, and the density [`LightSet::sample`] (power selection) would give the same
    /// point. `None` if nothing can light the receiver or the point is on a back face.
    #[inline]
    pub fn sample_hierarchy(
        &self,
        ref_p: Vec3,
        ref_n: Vec3,
        u_select: f64,
        u: Vec2,
    ) -> Option<(LightSample, f32)> {
        let share = self.table.env_share() as f64;
        if let Some(env) = self.environment
            && u_select < share
        {
            let s = self.sample_light(env, ref_p, u)?;
            let pdf = s.pdf_sa * self.table.pmf(env);
            return Some((LightSample { pdf_sa: pdf, ..s }, pdf));
        }
        let v = if share > 0.0 {
            ((u_select - share) / (1.0 - share)).clamp(0.0, 1.0 - f64::EPSILON)
        } else {
            u_select
        };
        let (entry, pmf) = self.hierarchy().sample(ref_p, ref_n, v)?;
        self.sample_entry(
            entry as usize,
            pmf * (1.0 - self.table.env_share()),
            ref_p,
            u,
        )
    }

    /// A point on emitter `entry` ([`LightSet::pick_emitter`]'s numbering: a local entry, or the
    /// environment after them) picked with probability `pmf`, as seen from `ref_p`: the sample,
    /// whose `pdf_sa` is `pmf` times the density of the point on the entry (uniform on a
    /// triangle, [`LightSet::sample_light`]'s otherwise), and the density [`LightSet::sample`]
    /// (power selection) gives the same point.
    #[inline]
    pub fn sample_entry(
        &self,
        entry: usize,
        pmf: f32,
        ref_p: Vec3,
        u: Vec2,
    ) -> Option<(LightSample, f32)> {
        let Some(e) = self.table.entries().get(entry) else {
            // The environment.
            let env = self.environment.filter(|_| entry == self.table.len())?;
            let s = self.sample_light(env, ref_p, u)?;
            let power_pdf = s.pdf_sa * self.table.pmf(env);
            return Some((
                LightSample {
                    pdf_sa: s.pdf_sa * pmf,
                    ..s
                },
                power_pdf,
            ));
        };
        match *e {
            Emitter::Triangle { ref p, .. } => {
                let (light, ps, radiance) = self.triangle_entry_point(e, u)?;
                let pdf_sa = area_to_solid_angle(pmf / triangle_area(p), ref_p, ps.p, ps.ng)?;
                let power_pdf =
                    area_to_solid_angle(self.area_pdf[light as usize], ref_p, ps.p, ps.ng)?;
                Some((
                    area_light_sample(light, radiance, ref_p, ps, pdf_sa)?,
                    power_pdf,
                ))
            }
            Emitter::Whole { light } => {
                let s = self.sample_light(light, ref_p, u)?;
                let power_pdf = s.pdf_sa * self.table.pmf(light);
                Some((
                    LightSample {
                        pdf_sa: s.pdf_sa * pmf,
                        ..s
                    },
                    power_pdf,
                ))
            }
        }
    }

    /// Emitters [`LightSet::pick_emitter`] numbers: the [`LightSet::emitter_count`] local
    /// entries of the emitter table (every emissive triangle of a mesh and every other light but
    /// the environment, ordered by light, then by triangle), then the environment if there is
    /// one.
    pub fn emitters_with_environment(&self) -> usize {
        self.table.len() + usize::from(self.environment.is_some())
    }

    /// Picks an emitter by power with uniform `u`: `(emitter, probability)`, the probability
    /// being [`LightSet::emitter_pmf`]'s.
    #[inline]
    pub fn pick_emitter(&self, u: f32) -> Option<(usize, f32)> {
        let e = match self.table.pick_index(u)? {
            Ok(e) => e,
            Err(_) => self.table.len(),
        };
        Some((e, self.emitter_pmf(e)))
    }

    /// The probability that [`LightSet::pick_emitter`] (and the power sampler) picks emitter
    /// `e`.
    #[inline]
    pub fn emitter_pmf(&self, e: usize) -> f32 {
        let s = self.table.env_share();
        if e < self.table.len() {
            (1.0 - s) * self.table.entry_pmf(e)
        } else if e == self.table.len() && self.environment.is_some() {
            s
        } else {
            0.0
        }
    }

    /// Groups of emitters that fit in a box of diagonal `size` ([`EmitterGroups`]).
    pub fn emitter_groups(&self, size: f32) -> EmitterGroups {
        let entries = self.table.entries();
        let n = self.emitters_with_environment();
        let mut start = Vec::with_capacity(n);
        let mut cumulative = Vec::with_capacity(n + 1);
        let mut acc = 0.0f64;
        cumulative.push(0.0);
        let (mut first, mut lo, mut hi) = (0usize, Vec3::ZERO, Vec3::ZERO);
        for e in 0..n {
            acc += f64::from(self.emitter_pmf(e));
            cumulative.push(acc);
            let grown = match (
                entries.get(e),
                e.checked_sub(1).and_then(|d| entries.get(d)),
            ) {
                (Some(Emitter::Triangle { light, p, .. }), Some(prev))
                    if prev.light() == *light && matches!(prev, Emitter::Triangle { .. }) =>
                {
                    let (l, h) = (
                        lo.min(p[0].min(p[1]).min(p[2])),
                        hi.max(p[0].max(p[1]).max(p[2])),
                    );
                    ((h - l).length() < size).then_some((l, h))
                }
                _ => None,
            };
            match grown {
                Some((l, h)) => (lo, hi) = (l, h),
                None => {
                    first = e;
                    (lo, hi) = match entries.get(e) {
                        Some(Emitter::Triangle { p, .. }) => {
                            (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
                        }
                        _ => (Vec3::ZERO, Vec3::ZERO),
                    };
                }
            }
            start.push(first as u32);
        }
        let mut end = vec![0u32; n];
        let mut next = n as u32;
        for e in (0..n).rev() {
            end[e] = next;
            if start[e] as usize == e {
                next = e as u32;
            }
        }
        EmitterGroups {
            count: start
                .iter()
                .enumerate()
                .filter(|&(e, &s)| s as usize == e)
                .count(),
            start,
            end,
            cumulative,
        }
    }

    /// The emitter holding the point `light`/`prim` of a light sample (`prim` is ignored for a
    /// light that is not a triangle mesh): `None` for a light without power.
    #[inline]
    pub fn emitter_of(&self, light: u32, prim: u32) -> Option<usize> {
        if Some(light) == self.environment {
            return Some(self.table.len());
        }
        let entries = self.table.entries();
        let first = self.table.first_entry(light)?;
        match entries.get(first)? {
            Emitter::Whole { light: l } => (*l == light).then_some(first),
            Emitter::Triangle { light: l, .. } if *l != light => None,
            Emitter::Triangle { .. } => {
                // Triangles of one mesh are in order; most meshes keep all of theirs.
                if let Some(Emitter::Triangle {
                    light: l, prim: q, ..
                }) = entries.get(first + prim as usize)
                    && *l == light
                    && *q == prim
                {
                    return Some(first + prim as usize);
                }
                let rest = &entries[first..];
                let n = rest.partition_point(|e| e.light() == light);
                rest[..n]
                    .binary_search_by_key(&prim, |e| match *e {
                        Emitter::Triangle { prim, .. } => prim,
                        Emitter::Whole { .. } => 0,
                    })
                    .ok()
                    .map(|i| first + i)
            }
        }
    }

    /// Picks a local entry (an emissive triangle or another light; the environment aside) for a
    /// receiver at `ref_p` with normal `ref_n` by the light hierarchy: `(entry, probability)`,
    /// the probability among local entries. The entries are numbered `0..emitter_count()`.
    pub fn hierarchy_select(&self, ref_p: Vec3, ref_n: Vec3, u: f64) -> Option<(usize, f32)> {
        let (e, pmf) = self.hierarchy().sample(ref_p, ref_n, u)?;
        Some((e as usize, pmf))
    }

    /// The probability that [`LightSet::hierarchy_select`] picks local entry `entry` for a
    /// receiver at `ref_p` with normal `ref_n` (a second descent of the hierarchy, exact: the
    /// same factors as the sampling descent multiplies).
    pub fn hierarchy_pmf(&self, ref_p: Vec3, ref_n: Vec3, entry: usize) -> f32 {
        self.hierarchy().pmf(ref_p, ref_n, entry as u32)
    }

    /// The probability that the power table picks local entry `entry` among the local entries.
    pub fn entry_power_pmf(&self, entry: usize) -> f32 {
        self.table.entry_pmf(entry)
    }

    /// The light local entry `entry` belongs to.
    pub fn entry_light(&self, entry: usize) -> u32 {
        self.table.entries()[entry].light()
    }
}
