//! Next-event estimation's light selection: one light sample per path vertex, picked by power or
//! by the light hierarchy, and the density of that choice for a point reached by a BSDF ray (the
//! other side of the MIS pair). The path tracer and ReSTIR PT's walks draw their light samples
//! here; ReSTIR DI's candidates have their own samplers (`sampler.rs`).

use glam::{Vec2, Vec3};
use restir_geometry::area_to_solid_angle;

use crate::table::{Emitter, triangle_area};
use crate::{LightSample, LightSet};

/// How next-event estimation picks the light it samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
// The hidden variant is the tests' negative control, not a stand-in for future variants.
#[allow(clippy::manual_non_exhaustive)]
pub enum NeeSelection {
    /// The power sampler ([`LightSet::sample`]): every emitter in proportion to its power,
    /// wherever the vertex is.
    #[default]
    Power,
    /// The light hierarchy ([`LightSet::sample_hierarchy`]): a descent by power, distance and
    /// orientation from the vertex, the environment keeping its share.
    Hierarchy,
    /// A negative control for the tests, never a choice: samples drawn by the hierarchy, but
    /// the density a BSDF ray's emitter is weighed against is the power sampler's, so the two
    /// strategies' MIS weights no longer sum to one (biased).
    #[doc(hidden)]
    HierarchyWeighedByPower,
}

impl NeeSelection {
    /// Every name `--light-sampler` takes for it.
    pub const NAMES: &[(&str, NeeSelection)] = &[
        ("power", NeeSelection::Power),
        ("bvh", NeeSelection::Hierarchy),
        ("hierarchy", NeeSelection::Hierarchy),
    ];

    /// The name `--light-sampler` takes.
    pub fn name(self) -> &'static str {
        match self {
            NeeSelection::Power => "power",
            NeeSelection::Hierarchy => "bvh",
            NeeSelection::HierarchyWeighedByPower => "bvh-weighed-by-power",
        }
    }
}

/// The selection number of the hierarchy's descent: the bounce's selection number (24 bits) and
/// 24 more bits below them from another of its numbers, uniform on `[0, 1)` with 48 bits, so that
/// the descent's rescaling at every level (a hundred thousand emitters are 17 levels) still
/// reaches every entry whose probability it reports.
#[inline]
fn fine_selection(u_select: f32, u_fine: f32) -> f64 {
    (f64::from(u_select) + f64::from(u_fine) * (1.0 / 16_777_216.0)).min(1.0 - f64::EPSILON)
}

impl LightSet {
    /// A light sample for next-event estimation at `ref_p` (shading normal `ref_n`, or zero)
    /// picked by `how`, with `u_select` choosing the light (and `u_fine` its low bits for the
    /// hierarchy; the power sampler ignores it) and `u` the point. Its `pdf_sa` is
    /// [`LightSet::pdf_nee`]'s for the same point.
    #[inline]
    pub fn sample_nee(
        &self,
        how: NeeSelection,
        ref_p: Vec3,
        ref_n: Vec3,
        (u_select, u_fine): (f32, f32),
        u: Vec2,
    ) -> Option<LightSample> {
        match how {
            NeeSelection::Power => self.sample(ref_p, u_select, u),
            NeeSelection::Hierarchy | NeeSelection::HierarchyWeighedByPower => self
                .sample_hierarchy(ref_p, ref_n, fine_selection(u_select, u_fine), u)
                .map(|(s, _)| s),
        }
    }

    /// The solid-angle density with which [`LightSet::sample_nee`] at `ref_p` (normal `ref_n`)
    /// produces the point `p` (normal `n`) of primitive `prim` of light `light`, selection
    /// included (`prim` is ignored for a light that is not a triangle mesh). For the power
    /// sampler this is [`LightSet::pdf_sa`].
    #[inline]
    pub fn pdf_nee(
        &self,
        how: NeeSelection,
        (light, prim): (u32, u32),
        ref_p: Vec3,
        ref_n: Vec3,
        p: Vec3,
        n: Vec3,
    ) -> f32 {
        if how != NeeSelection::Hierarchy || Some(light) == self.environment {
            // The environment keeps its power share under the hierarchy too.
            return self.pdf_sa(light, ref_p, p, n);
        }
        let Some(entry) = self.emitter_of(light, prim) else {
            return 0.0;
        };
        let pmf = self.hierarchy_pmf(ref_p, ref_n, entry) * (1.0 - self.table.env_share());
        if pmf <= 0.0 {
            return 0.0;
        }
        match self.table.entries()[entry] {
            Emitter::Triangle { p: ref tri, .. } => {
                area_to_solid_angle(pmf / triangle_area(tri), ref_p, p, n).unwrap_or(0.0)
            }
            Emitter::Whole { light } => pmf * self.pdf_on_light(light, ref_p, p, n),
        }
    }
}
