//! The acceleration structure: one `obvhs` CWBVH (8-wide, compressed nodes) over every triangle,
//! sphere, cylinder and signed-distance-grid voxel of the scene. All but triangles are tested one
//! at a time in the traversal closure; cylinders and grid voxels through the structure's own copy
//! of their shape.
//!
//! obvhs's PLOC builder pairs clusters only when both prefer each other; among many primitives
//! with bit-identical bounds every choice ties, almost nothing pairs per sweep, and the build turns
//! quadratic (20 000 coincident triangles: 22 s). When more than [`MAX_SHARED_BOUNDS`] primitives
//! share their bounds, those primitives become one BVH entry (a *group*, tested in a loop, exact
//! duplicates once); scenes without such pile-ups get the plain one-primitive-per-entry BVH.

use glam::{Vec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;

use crate::{Frame, Ray, Shape};

#[cfg(target_arch = "x86_64")]
mod avx2;
mod build;
mod prims;
mod wide;

pub(crate) use prims::REL_T_MIN;
use prims::{Prim, group_entries};
use wide::{Entries, Scalar, TRay, Wide};

/// A closest hit: distance, which primitive, and where on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// The shape that was hit (index into the slice given to [`Accel::build`]).
    pub shape: u32,
    /// The triangle within the shape (0 for spheres).
    pub prim: u32,
    /// A triangle's barycentrics `(b1, b2)` of the hit point (the weights of its second and
    /// third corner), as the ray-triangle test computed them; zero for spheres.
    pub bary: Vec2,
}

impl Hit {
    /// A triangle's barycentrics kept inside the triangle despite the test's rounding: the
    /// point [`Accel::surface_interaction`] names on it ([`SurfaceInteraction::param`]).
    #[inline(always)]
    pub fn triangle_param(&self) -> Vec2 {
        let u = self.bary.x.clamp(0.0, 1.0);
        Vec2::new(u, self.bary.y.clamp(0.0, 1.0 - u))
    }
}

/// Everything about a surface point that shading needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceInteraction {
    /// Position.
    pub p: Vec3,
    /// Geometric normal (unit; follows winding and `flip_normals`).
    pub ng: Vec3,
    /// Shading frame; `shading.n` is the interpolated shading normal.
    pub shading: Frame,
    /// Texture coordinates.
    pub uv: Vec2,
    /// Shape index.
    pub shape: u32,
    /// Primitive within the shape.
    pub prim: u32,
    /// Barycentrics (meshes) or [`crate::Sphere::param_of`] parameters (spheres) of the point on its primitive;
    /// with `shape` and `prim` this names the point without storing it.
    pub param: Vec2,
    /// Distance from the ray origin.
    pub t: f32,
}

/// The most primitives that may share bit-identical bounds before they are grouped into one BVH
/// entry (a quad's two triangles share theirs; only degenerate input piles up more).
pub const MAX_SHARED_BOUNDS: usize = 8;

/// A BVH over a list of shapes.
#[derive(Debug)]
pub struct Accel {
    /// The decoded CWBVH with the triangles inline; `None` for an empty scene.
    wide: Option<Wide>,
    /// The primitives tested one at a time (spheres, members of groups); single triangles live
    /// only inline in `wide`.
    scalar: ScalarPrims,
    /// (shape, primitive within shape) of each BVH-ordered primitive.
    ids: Vec<(u32, u32)>,
    /// The cylinders and signed distance grids, which [`Prim::Analytic`] names by slot.
    analytic: Vec<Shape>,
    /// With groups, BVH entry `e` holds primitives `groups[e]..groups[e + 1]`; without, entry
    /// `e` is primitive `e`.
    groups: Option<Vec<u32>>,
    bounds: (Vec3, Vec3),
    /// Whether the AVX2 kernel is used (the CPU was checked once, at build).
    avx2: bool,
    /// Every primitive in BVH order, kept by the tests for brute-force checks.
    #[cfg(test)]
    prims: Vec<Prim>,
    /// obvhs's tree, kept by the tests to run obvhs's own traversal as the reference.
    #[cfg(test)]
    reference: Option<obvhs::cwbvh::CwBvh>,
}

/// The primitives of the BVH entries tested one at a time, by BVH-ordered primitive index.
#[derive(Debug, Default)]
struct ScalarPrims {
    /// Where primitive `id` is in `prims`; `None` when `prims` holds every primitive in order
    /// (or none is tested one at a time).
    slot: Option<Vec<u32>>,
    prims: Vec<Prim>,
}

impl ScalarPrims {
    #[inline(always)]
    fn get(&self, id: usize) -> &Prim {
        match &self.slot {
            Some(slot) => &self.prims[slot[id] as usize],
            None => &self.prims[id],
        }
    }
}

/// Primitive `ti` of shape `si` as the traversal stores it; `slots[si]` is the shape's slot
/// among the analytic shapes (cylinders, grids).
fn prim_of(shapes: &[Shape], slots: &[u32], (si, ti): (u32, u32)) -> Prim {
    match &shapes[si as usize] {
        Shape::Mesh(m) => {
            let [a, b, c] = m.triangle(ti as usize);
            Prim::Triangle {
                v0: a.into(),
                e1: (b - a).into(),
                e2: (c - a).into(),
            }
        }
        Shape::Sphere(s) => Prim::Sphere {
            center: s.center.into(),
            radius: s.radius,
        },
        Shape::Cylinder(_) | Shape::SdfGrid(_) => Prim::Analytic {
            slot: slots[si as usize],
            prim: ti,
        },
    }
}

/// (shape, primitive within shape) of every primitive of `shapes`, in input order (`count` of
/// them).
fn prim_ids(shapes: &[Shape], count: usize) -> Vec<(u32, u32)> {
    let mut ids = Vec::with_capacity(count);
    for (si, shape) in shapes.iter().enumerate() {
        ids.extend((0..shape.primitive_count() as u32).map(|ti| (si as u32, ti)));
    }
    ids
}

/// Whether this CPU runs the AVX2 kernel.
fn detect_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        // The bit-counting instructions come with AVX2 on every CPU that has it (Haswell,
        // Excavator and later), but are separate features; the kernel uses them for the child
        // index and the lane loops.
        std::is_x86_feature_detected!("avx2")
            && std::is_x86_feature_detected!("popcnt")
            && std::is_x86_feature_detected!("bmi1")
            && std::is_x86_feature_detected!("lzcnt")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

impl Entries for Accel {
    #[inline(always)]
    fn entry(&self, e: usize, r: &TRay, t_max: f32) -> (f32, u32) {
        self.intersect_entry(e, r, t_max)
    }
}

impl Accel {
    /// Builds the BVH over all shapes.
    ///
    /// Memory: the input-order boxes live only until obvhs has built its binary tree and the
    /// ids are not held while it builds (without groups they are made again after; see
    /// `build.rs` for the build's own peak), the triangles are read from the shapes where they
    /// are needed (the groups' keys, the inline blocks), and a triangle that is its own BVH
    /// entry is kept only inline, so the structure keeps the tree, the inline blocks and 8 bytes
    /// of ids per primitive.
    pub fn build(shapes: &[Shape]) -> Self {
        let count: usize = shapes.iter().map(Shape::primitive_count).sum();
        let mut analytic = Vec::new();
        let slots: Vec<u32> = shapes
            .iter()
            .map(|s| match s {
                Shape::Cylinder(_) | Shape::SdfGrid(_) => {
                    analytic.push(s.clone());
                    analytic.len() as u32 - 1
                }
                _ => u32::MAX,
            })
            .collect();
        let ids = prim_ids(shapes, count);
        let mut aabbs = Vec::with_capacity(count);
        for shape in shapes {
            match shape {
                Shape::Mesh(m) => {
                    for ti in 0..m.triangle_count() {
                        let [a, b, c] = m.triangle(ti);
                        aabbs.push(Aabb::from_points(&[a.into(), b.into(), c.into()]));
                    }
                }
                Shape::Sphere(s) => {
                    let r = Vec3A::splat(s.radius);
                    aabbs.push(Aabb::new(
                        Vec3A::from(s.center) - r,
                        Vec3A::from(s.center) + r,
                    ));
                }
                _ => {
                    for ti in 0..shape.primitive_count() as u32 {
                        let (lo, hi) = shape.primitive_bounds(ti);
                        aabbs.push(Aabb::new(lo.into(), hi.into()));
                    }
                }
            }
        }
        let mut bounds = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for b in &aabbs {
            bounds.0 = bounds.0.min(b.min.into());
            bounds.1 = bounds.1.max(b.max.into());
        }
        let avx2 = detect_avx2();
        if ids.is_empty() {
            return Self {
                wide: None,
                scalar: ScalarPrims::default(),
                analytic,
                ids,
                groups: None,
                bounds: (Vec3::ZERO, Vec3::ZERO),
                avx2,
                #[cfg(test)]
                prims: Vec::new(),
                #[cfg(test)]
                reference: None,
            };
        }
        let grouped = group_entries(&aabbs, |i| prim_of(shapes, &slots, ids[i]));
        let (bvh, ids, groups) = match grouped {
            Some((entries, boxes)) => {
                drop(aabbs);
                let bvh = build::cwbvh(boxes);
                let mut starts = Vec::with_capacity(entries.len() + 1);
                starts.push(0);
                let mut out_ids = Vec::with_capacity(ids.len());
                for &e in &bvh.primitive_indices {
                    for &i in &entries[e as usize] {
                        out_ids.push(ids[i]);
                    }
                    starts.push(out_ids.len() as u32);
                }
                (bvh, out_ids, Some(starts))
            }
            None => {
                // The ids are made again once the tree is built, so that they do not take
                // memory while obvhs builds it.
                drop(ids);
                let bvh = build::cwbvh(aabbs);
                let ids = prim_ids(shapes, count);
                // Lay primitives out in BVH order so the traversal indexes them directly.
                let d = bvh
                    .primitive_indices
                    .iter()
                    .map(|&i| ids[i as usize])
                    .collect();
                (bvh, d, None)
            }
        };
        let members = |e: usize| match &groups {
            Some(s) => s[e] as usize..s[e + 1] as usize,
            None => e..e + 1,
        };
        let is_mesh = |id: usize| matches!(shapes[ids[id].0 as usize], Shape::Mesh(_));
        let wide = Wide::build(
            &bvh,
            |e| {
                let m = members(e);
                match prim_of(shapes, &slots, ids[m.start]) {
                    Prim::Triangle { v0, e1, e2 } if m.len() == 1 => Some([v0, e1, e2]),
                    _ => None,
                }
            },
            |e| {
                members(e).fold([Vec3A::INFINITY, Vec3A::NEG_INFINITY], |[lo, hi], id| {
                    let (shape, prim) = ids[id];
                    let (a, b) = shapes[shape as usize].primitive_bounds(prim);
                    [lo.min(a.into()), hi.max(b.into())]
                })
            },
        );
        // The primitives tested one at a time: spheres and members of groups.
        let entry_count = groups.as_ref().map_or(ids.len(), |s| s.len() - 1);
        let scalar_ids: Vec<usize> = (0..entry_count)
            .map(members)
            .filter(|m| m.len() > 1 || !is_mesh(m.start))
            .flatten()
            .collect();
        let scalar = if scalar_ids.len() == ids.len() {
            ScalarPrims {
                slot: None,
                prims: ids.iter().map(|&id| prim_of(shapes, &slots, id)).collect(),
            }
        } else if scalar_ids.is_empty() {
            ScalarPrims::default()
        } else {
            let mut slot = vec![u32::MAX; ids.len()];
            for (k, &id) in scalar_ids.iter().enumerate() {
                slot[id] = k as u32;
            }
            ScalarPrims {
                slot: Some(slot),
                prims: scalar_ids
                    .iter()
                    .map(|&id| prim_of(shapes, &slots, ids[id]))
                    .collect(),
            }
        };
        Self {
            wide: Some(wide),
            scalar,
            analytic,
            #[cfg(test)]
            prims: ids.iter().map(|&id| prim_of(shapes, &slots, id)).collect(),
            ids,
            groups,
            bounds,
            avx2,
            #[cfg(test)]
            reference: Some(bvh),
        }
    }

    /// The scene's axis-aligned bounds `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    /// Number of primitives (triangles, spheres, cylinders and grid voxels).
    pub fn primitive_count(&self) -> usize {
        self.ids.len()
    }

    /// Whether traversal uses the AVX2 kernel (decided by the CPU at build).
    pub fn uses_avx2(&self) -> bool {
        self.avx2
    }

    /// What the build made, for `--stats`: the tree's nodes and inline triangle blocks, the
    /// bytes they take, and the kernel the CPU runs.
    pub fn describe(&self) -> String {
        let kernel = if self.avx2 { "AVX2" } else { "scalar" };
        let Some(w) = &self.wide else {
            return format!("empty (no primitives), {kernel} kernel");
        };
        let bytes =
            std::mem::size_of_val(w.nodes.as_slice()) + std::mem::size_of_val(w.blocks.as_slice());
        let size = if bytes < 1 << 20 {
            format!("{:.1} KiB", bytes as f64 / 1024.0)
        } else {
            format!("{:.1} MiB", bytes as f64 / (1024.0 * 1024.0))
        };
        format!(
            "{} nodes, {} blocks of 8 triangles, {} levels, {size}; {kernel} kernel",
            w.nodes.len(),
            w.blocks.len(),
            w.depth,
        )
    }

    /// The scalar kernel from now on, whatever the CPU (to compare kernels).
    #[doc(hidden)]
    pub fn force_scalar(&mut self) {
        self.avx2 = false;
    }

    /// Primitive `id`'s distance along `r` if below `t_max`, else infinity (a primitive of an
    /// entry tested one at a time).
    #[inline(always)]
    fn intersect_scalar(&self, id: usize, r: &TRay, t_max: f32) -> f32 {
        // The tests' reference traversal tests inline triangles through here too.
        #[cfg(test)]
        if self.scalar.slot.as_ref().is_some_and(|s| s[id] == u32::MAX)
            || (self.scalar.slot.is_none() && self.scalar.prims.is_empty())
        {
            return self.intersect_prim(id, r, t_max);
        }
        self.scalar
            .get(id)
            .intersect(&self.analytic, r.o, r.d, t_max)
    }

    /// Any primitive `id`'s distance along `r` if below `t_max`, else infinity (brute force for
    /// the tests).
    #[cfg(test)]
    fn intersect_prim(&self, id: usize, r: &TRay, t_max: f32) -> f32 {
        self.prims[id].intersect(&self.analytic, r.o, r.d, t_max)
    }

    /// BVH entry `e` tested member by member: the closest distance below `t_max` (infinity if
    /// none) and its primitive, the first of equals.
    #[inline(always)]
    fn intersect_entry(&self, e: usize, r: &TRay, t_max: f32) -> (f32, u32) {
        let Some(starts) = &self.groups else {
            return (self.intersect_scalar(e, r, t_max), e as u32);
        };
        let mut best = (f32::INFINITY, 0);
        for id in starts[e] as usize..starts[e + 1] as usize {
            let t = self.intersect_scalar(id, r, t_max);
            if t < best.0 && t < t_max {
                best = (t, id as u32);
            }
        }
        best
    }

    /// The closest hit along `ray` with `t < t_max`.
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let w = self.wide.as_ref()?;
        let r = TRay::new(ray.o.into(), ray.d.into());
        let found = wide::with_nearest_stack(w.depth, |stack| {
            #[cfg(target_arch = "x86_64")]
            if self.avx2 {
                // SAFETY: `avx2` is set only when the CPU reported AVX2, POPCNT, BMI1 and LZCNT
                // (`detect_avx2`).
                #[allow(unsafe_code)]
                return unsafe { avx2::closest_avx2(w, &r, t_max, stack, self) };
            }
            wide::closest::<Scalar>(w, &r, t_max, stack, self)
        });
        let f = found?;
        let id = match (f.member, &self.groups) {
            (u32::MAX, Some(starts)) => starts[f.entry as usize],
            (u32::MAX, None) => f.entry,
            (m, _) => m,
        };
        let bary = match f.member {
            // An inline triangle: the block test's barycentrics.
            u32::MAX => f.bary,
            // A triangle tested one at a time (in a group): the same test again, for its
            // barycentrics.
            _ => match *self.scalar.get(id as usize) {
                Prim::Triangle { v0, e1, e2 } => {
                    prims::triangle_hit(v0, e1, e2, r.o, r.d, f32::INFINITY)
                        .map_or([0.0; 2], |(_, u, v)| [u, v])
                }
                Prim::Sphere { .. } | Prim::Analytic { .. } => [0.0; 2],
            },
        };
        let (shape, prim) = self.ids[id as usize];
        Some(Hit {
            t: f.t,
            shape,
            prim,
            bary: Vec2::from(bary),
        })
    }

    /// Whether anything blocks `ray` before `t_max`.
    #[inline(always)]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        let Some(w) = self.wide.as_ref() else {
            return false;
        };
        let r = TRay::new(ray.o.into(), ray.d.into());
        wide::with_stack(w.depth, |stack| {
            #[cfg(target_arch = "x86_64")]
            if self.avx2 {
                // SAFETY: `avx2` is set only when the CPU reported AVX2, POPCNT, BMI1 and LZCNT
                // (`detect_avx2`).
                #[allow(unsafe_code)]
                return unsafe { avx2::any_avx2(w, &r, t_max, stack, self) };
            }
            wide::any::<Scalar>(w, &r, t_max, stack, self)
        })
    }

    /// Surface details of a hit returned by [`Accel::intersect`] for the same `ray`.
    #[inline(always)]
    pub fn surface_interaction(
        &self,
        shapes: &[Shape],
        hit: &Hit,
        ray: &Ray,
    ) -> SurfaceInteraction {
        let shape = &shapes[hit.shape as usize];
        let param = match shape {
            Shape::Mesh(_) => hit.triangle_param(),
            Shape::Sphere(s) => {
                let n = (ray.at(hit.t) - s.center).normalize();
                crate::Sphere::param_of(n)
            }
            // Reprojected onto the tube, as Mitsuba does.
            Shape::Cylinder(c) => c.param_of(ray.at(hit.t)),
            Shape::SdfGrid(g) => g.param_of(hit.prim, ray.at(hit.t)),
        };
        let mut si = surface_at(shapes, hit.shape, hit.prim, param);
        si.t = hit.t;
        if let Shape::Sphere(s) = shape {
            // Reproject onto the sphere for accuracy.
            let n = (ray.at(hit.t) - s.center).normalize();
            si.p = s.center + s.radius * n;
        }
        si
    }
}

/// The surface interaction at a point named by `(shape, prim, param)` (see
/// [`SurfaceInteraction::param`]); `t` is left at 0.
#[inline(always)]
pub fn surface_at(shapes: &[Shape], shape: u32, prim: u32, param: Vec2) -> SurfaceInteraction {
    match &shapes[shape as usize] {
        Shape::Mesh(m) => {
            let (p, ng, ns, uv, dpdu) = m.surface_at(prim as usize, param);
            SurfaceInteraction {
                p,
                ng,
                shading: Frame::from_normal_tangent(ns, dpdu),
                uv,
                shape,
                prim,
                param,
                t: 0.0,
            }
        }
        Shape::Sphere(s) => {
            let (p, out) = s.point_at(param);
            let n = if s.flip_normals { -out } else { out };
            // Tangent along increasing φ (of object space).
            let dpdu = s.tangent(out);
            SurfaceInteraction {
                p,
                ng: n,
                shading: Frame::from_normal_tangent(n, dpdu),
                uv: s.local_uv(out),
                shape,
                prim,
                param,
                t: 0.0,
            }
        }
        Shape::Cylinder(c) => {
            let (p, n, dpdu) = c.point_at(param);
            SurfaceInteraction {
                p,
                ng: n,
                shading: Frame::from_normal_tangent(n, dpdu),
                uv: param,
                shape,
                prim,
                param,
                t: 0.0,
            }
        }
        Shape::SdfGrid(g) => {
            let (p, ng, ns) = g.point_at(prim, param);
            SurfaceInteraction {
                p,
                ng,
                // No tangents (Mitsuba's frame around the normal alone).
                shading: Frame::from_normal(ns),
                // As in Mitsuba, the grid has no texture coordinates.
                uv: Vec2::ZERO,
                shape,
                prim,
                param,
                t: 0.0,
            }
        }
    }
}

#[cfg(test)]
mod proptests;
#[cfg(test)]
mod tests;
