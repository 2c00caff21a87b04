//! Our traversal of obvhs's CWBVH: the node and leaf layout we build once from the `CwBvh`, the
//! closest-hit and any-hit loops (generic over the kernel that tests a node's eight children and
//! eight triangles at once), and the scalar kernel.
//!
//! The node test runs on each child's bounds in `f32`, computed at build from what the child
//! holds. (obvhs's quantized boxes exceed them by up to one cell of their 255-step grid per
//! axis, so a ray leaving a surface or ending at one entered that surface's leaf and tested its
//! triangles in vain.) It is conservative: with the direction's exact reciprocal and the exit
//! distances scaled by [`EXIT_SCALE`], rounding cannot cull a box the ray passes through, flat
//! boxes and axis-parallel rays included (tests
//! `the_node_test_enters_every_box_the_ray_passes_through` and
//! `rays_into_the_edge_of_two_walls_are_not_culled`). Against the traversal on obvhs's
//! quantized boxes, decoded at each test, on the rays of `scripts/mitsuba_rays.py`: corpus Sponza
//! 1.17–1.25× the rays per second, the indirect room's shadow rays 1.47×; a path-traced pass
//! 1.11× on corpus Sponza, 1.06× on 400 emissive rectangles, 1.03× on the Cornell box, the
//! images the same bits. A node takes 256 bytes (128 quantized).
//!
//! A node's leaf primitives are tested right after the node (testing them in distance order
//! with its inner children was 0.74–0.95× on closest-hit rays), the closest one kept with ties
//! going to the highest primitive offset, as obvhs's sequential highest-bit-first loop does. The
//! any-hit walk visits children in obvhs's order (the CWBVH's octant order: child slot `s` has
//! priority `s ^ octant`, so the slots laid out towards the ray come first), so occlusion
//! answers are those of obvhs's `ray_traverse_miss` except where its box test culls by
//! rounding. The closest-hit walk visits the inner children nearest box first and drops waiting
//! ones that lie behind the hit found meanwhile (on the corpus Sponza 15 % less time per
//! path-traced pass than the octant order); it finds the distance obvhs's `ray_traverse` finds,
//! bit for bit, except that among primitives hit at exactly the same distance it may name
//! another one, and except where the order decides in both traversals (hits nearer than
//! obvhs's node epsilon of 10⁻⁴, which ours does not have, rounding-noise hits of rays in a
//! triangle's plane) or obvhs's box test culls by rounding. The triangles of a node sit inline
//! in 8-wide SoA blocks (`v0`, `e1`, `e2` precomputed) in the node's own order, so a leaf test
//! does no index indirection and one block test covers up to eight triangles.

use glam::Vec3A;
use obvhs::cwbvh::CwBvh;

use super::prims::{intersect_triangle, triangle_hit};

/// The lower bound on a child box's entry distance: 0, boxes behind the ray's origin are culled.
/// (obvhs's own traversal clamps it at an absolute 10⁻⁴, which skips every box a ray leaves
/// within 10⁻⁴ scene units: whole scenes in small units. Self-intersection is the primitive
/// tests' concern, relative to their operands: `prims::REL_T_MIN`.)
pub(super) const NODE_EPSILON: f32 = 0.0;

/// The factor on a child box's computed exit distances that makes the slab test conservative
/// (Ize, "Robust BVH Ray Traversal", JCGT 2013): an entry `(b − o)·(1/d)` is three roundings
/// from its exact value and a scaled exit four, so an entry and an exit that meet exactly (a
/// ray through a box's edge or a flat box, as at the corner of two walls) could come out in the
/// wrong order; `1 + 2⁻²⁰` covers the seven. The boxes are exact `f32` values. The factor is
/// folded into each ray's far-plane reciprocal ([`TRay::inv_far`]) and into the walks' distance
/// limit once per change, not applied per node: a multiply on the node test's dependency chain
/// cost about 7 % of a path-traced pass on the Cornell box.
pub(super) const EXIT_SCALE: f32 = 1.0 + 1.0 / (1u32 << 20) as f32;

/// The deepest tree the fixed traversal stack holds; deeper trees use a heap stack.
pub(super) const STACK: usize = 24;

/// Runs a traversal `f` with a stack for a tree `depth` levels deep: on the call stack up to
/// [`STACK`] levels, on the heap beyond.
#[inline(always)]
pub(super) fn with_stack<T>(depth: usize, f: impl FnOnce(&mut [(u32, u32)]) -> T) -> T {
    if depth <= STACK {
        f(&mut [(0, 0); STACK])
    } else {
        f(&mut vec![(0, 0); depth])
    }
}

/// Runs a closest-hit traversal `f` with a stack for a tree `depth` levels deep (each level
/// leaves at most seven children waiting): on the call stack for trees up to 13 levels deep (a
/// short one for small trees, as the stack is zeroed for every ray), on the heap beyond.
#[inline(always)]
pub(super) fn with_nearest_stack<T>(depth: usize, f: impl FnOnce(&mut [(u32, f32)]) -> T) -> T {
    let len = 7 * depth + 1;
    if len <= 22 {
        f(&mut [(0, 0.0); 22])
    } else if len <= 92 {
        f(&mut [(0, 0.0); 92])
    } else {
        f(&mut vec![(0, 0.0); len])
    }
}

/// One CWBVH node, decoded for traversal.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
pub(super) struct Node {
    /// Child box bounds: min x, max x, min y, max y, min z, max z, per child slot (the bounds of
    /// what the child holds; empty slots inverted, never hit).
    pub b: [[f32; 8]; 6],
    /// Per child slot: the slot's leaf entries as a mask of offsets from `first` (0 for inner
    /// and empty slots).
    pub leaf: [u32; 8],
    /// Index of the first child node.
    pub child_base: u32,
    /// BVH entry at offset 0.
    pub first: u32,
    /// First of this node's triangle blocks (offset `o` is lane `o % 8` of block `block + o / 8`).
    pub block: u32,
    /// Offsets of the entries tested one at a time (spheres, groups of coincident primitives).
    pub scalar: u32,
    /// Which child slots are inner nodes (obvhs's `imask`).
    pub imask: u8,
}

/// Eight triangles in SoA: `v[0..3]` the first vertex, `v[3..6]` edge 1, `v[6..9]` edge 2, each an
/// axis across the eight lanes. Unused lanes are zero (a zero edge never hits).
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
pub(super) struct TriBlock {
    pub v: [[f32; 8]; 9],
}

impl TriBlock {
    #[inline(always)]
    pub fn lane(&self, j: usize) -> (Vec3A, Vec3A, Vec3A) {
        let v = &self.v;
        (
            Vec3A::new(v[0][j], v[1][j], v[2][j]),
            Vec3A::new(v[3][j], v[4][j], v[5][j]),
            Vec3A::new(v[6][j], v[7][j], v[8][j]),
        )
    }
}

/// A ray prepared for traversal: no negative zeros in the direction, and its reciprocal
/// `1/d` (infinite along an axis the ray does not move on: a slab that holds the origin is then
/// crossed over `(−∞, +∞)`, and one whose face the origin lies on gives NaN, which the node
/// test's min and max pass over, as the box is closed).
#[derive(Clone, Copy, Debug)]
pub(super) struct TRay {
    pub o: Vec3A,
    pub d: Vec3A,
    pub inv_d: Vec3A,
    /// `inv_d · EXIT_SCALE`: the reciprocal the exit distances are computed with.
    pub inv_far: Vec3A,
    /// Per axis: whether the direction is negative (the near plane is the box's max).
    pub neg: [bool; 3],
    /// Octant code (`4·[d.x ≥ 0] + 2·[d.y ≥ 0] + [d.z ≥ 0]`), the child-order key.
    pub oct: u32,
}

impl TRay {
    #[inline(always)]
    pub fn new(o: Vec3A, d: Vec3A) -> Self {
        let d = d + Vec3A::ZERO;
        let neg = [d.x < 0.0, d.y < 0.0, d.z < 0.0];
        let oct = (!neg[0] as u32) << 2 | (!neg[1] as u32) << 1 | !neg[2] as u32;
        let inv_d = Vec3A::ONE / d;
        TRay {
            o,
            d,
            inv_d,
            inv_far: inv_d * EXIT_SCALE,
            neg,
            oct,
        }
    }
}

/// `_mm_max_ps` / `_mm_min_ps` semantics (the second operand when either is NaN).
#[inline(always)]
fn max_ps(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}
#[inline(always)]
fn min_ps(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// What a traversal needs from the hardware: a node's child hit mask and a triangle block's
/// closest / any hit. Implementations must agree bit for bit.
pub(super) trait Kernel {
    /// Bit `s` set when child slot `s`'s box is entered before `t_lim` (a distance limit already
    /// scaled by [`EXIT_SCALE`]), and each slot's entry
    /// distance (meaningful for the slots hit).
    fn node_hits(node: &Node, ray: &TRay, t_lim: f32) -> (u32, [f32; 8]);
    /// The closest hit among `lanes` (a mask) with `t < t_max`, ties to the highest lane.
    fn block_closest(block: &TriBlock, ray: &TRay, t_max: f32, lanes: u32) -> Option<TriHit>;
    /// Whether any of `lanes` is hit with `t < t_max`.
    fn block_any(block: &TriBlock, ray: &TRay, t_max: f32, lanes: u32) -> bool;
}

/// A triangle hit in a block: distance, lane and the barycentrics `(u, v)` (the weights of the
/// second and third vertex), as Möller–Trumbore computed them for the test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct TriHit {
    pub t: f32,
    pub lane: u32,
    pub u: f32,
    pub v: f32,
}

/// The scalar kernel (every target; the reference the SIMD kernels match).
#[derive(Debug)]
pub(super) struct Scalar;

impl Kernel for Scalar {
    #[inline(always)]
    fn node_hits(n: &Node, r: &TRay, t_lim: f32) -> (u32, [f32; 8]) {
        let (o, inv, inv_far) = (r.o.to_array(), r.inv_d.to_array(), r.inv_far.to_array());
        let mut mask = 0;
        let mut entry = [0.0; 8];
        for (s, e) in entry.iter_mut().enumerate() {
            let mut t0 = [0.0; 3];
            let mut t1 = [0.0; 3];
            for a in 0..3 {
                let (lo, hi) = (n.b[2 * a][s], n.b[2 * a + 1][s]);
                let (near, far) = if r.neg[a] { (hi, lo) } else { (lo, hi) };
                t0[a] = (near - o[a]) * inv[a];
                t1[a] = (far - o[a]) * inv_far[a];
            }
            // Each distance is the first operand of its max or min, so a NaN (the origin on the
            // face of a slab the ray does not move across) is passed over.
            let tmin = max_ps(t0[0], max_ps(t0[1], max_ps(t0[2], NODE_EPSILON)));
            let tmax = min_ps(t1[0], min_ps(t1[1], min_ps(t1[2], t_lim)));
            if tmin <= tmax {
                mask |= 1 << s;
            }
            *e = tmin;
        }
        (mask, entry)
    }

    #[inline(always)]
    fn block_closest(b: &TriBlock, r: &TRay, t_max: f32, mut lanes: u32) -> Option<TriHit> {
        let mut best: Option<TriHit> = None;
        let mut t_max = t_max;
        while lanes != 0 {
            let j = 31 - lanes.leading_zeros();
            lanes &= !(1 << j);
            let (v0, e1, e2) = b.lane(j as usize);
            if let Some((t, u, v)) = triangle_hit(v0, e1, e2, r.o, r.d, t_max) {
                t_max = t;
                best = Some(TriHit { t, lane: j, u, v });
            }
        }
        best
    }

    #[inline(always)]
    fn block_any(b: &TriBlock, r: &TRay, t_max: f32, mut lanes: u32) -> bool {
        while lanes != 0 {
            let j = lanes.trailing_zeros();
            lanes &= lanes - 1;
            let (v0, e1, e2) = b.lane(j as usize);
            if intersect_triangle(v0, e1, e2, r.o, r.d, t_max) < t_max {
                return true;
            }
        }
        false
    }
}

/// `PERM[oct][m]`: child hit mask `m` (bit = slot) re-indexed by priority (bit `s ^ oct`).
static PERM: [[u8; 256]; 8] = {
    let mut t = [[0u8; 256]; 8];
    let mut oct = 0;
    while oct < 8 {
        let mut m = 0;
        while m < 256 {
            let mut s = 0;
            let mut out = 0u8;
            while s < 8 {
                if m & (1 << s) != 0 {
                    out |= 1 << (s ^ oct);
                }
                s += 1;
            }
            t[oct][m] = out;
            m += 1;
        }
        oct += 1;
    }
    t
};

/// The decoded tree and its inline triangles.
#[derive(Debug, Default)]
pub(super) struct Wide {
    pub nodes: Vec<Node>,
    pub blocks: Vec<TriBlock>,
    /// Tree depth (nodes on the longest root-to-leaf path).
    pub depth: usize,
}

impl Wide {
    /// Decodes `bvh`; `tri(e)` is BVH entry `e`'s triangle `(v0, e1, e2)` when the entry is a
    /// single triangle, `None` for entries tested one at a time; `bounds(e)` is the entry's box
    /// `[min, max]`.
    pub fn build(
        bvh: &CwBvh,
        tri: impl Fn(usize) -> Option<[Vec3A; 3]>,
        bounds: impl Fn(usize) -> [Vec3A; 2],
    ) -> Self {
        let mut nodes = Vec::with_capacity(bvh.nodes.len());
        let mut blocks = Vec::new();
        for n in &bvh.nodes {
            let mut node = Node {
                // Filled by `tighten`; empty slots keep an inverted box that no ray enters.
                b: [
                    [f32::INFINITY; 8],
                    [f32::NEG_INFINITY; 8],
                    [f32::INFINITY; 8],
                    [f32::NEG_INFINITY; 8],
                    [f32::INFINITY; 8],
                    [f32::NEG_INFINITY; 8],
                ],
                child_base: n.child_base_idx,
                first: n.primitive_base_idx,
                block: blocks.len() as u32,
                imask: n.imask,
                ..Node::default()
            };
            let mut span = 0;
            for s in 0..8 {
                let meta = n.child_meta[s] as u32;
                let inner = meta & (meta << 1) & 0b1_0000 != 0;
                if !inner {
                    let (off, bits) = (meta & 0b1_1111, (meta >> 5) & 0b111);
                    node.leaf[s] = bits << off;
                    if bits != 0 {
                        span = span.max(off + 32 - bits.leading_zeros());
                    }
                }
            }
            let first = blocks.len();
            blocks.resize(first + span.div_ceil(8) as usize, TriBlock::default());
            for off in 0..span as usize {
                let e = n.primitive_base_idx as usize + off;
                match tri(e) {
                    Some(v) => {
                        let b = &mut blocks[first + off / 8];
                        for (axis, x) in v.iter().flat_map(|v| v.to_array()).enumerate() {
                            b.v[axis][off % 8] = x;
                        }
                    }
                    None => node.scalar |= 1 << off,
                }
            }
            nodes.push(node);
        }
        tighten(&mut nodes, 0, &bounds);
        let depth = depth_of(&nodes, 0);
        Wide {
            nodes,
            blocks,
            depth,
        }
    }
}

/// Replaces node `n`'s child boxes, and those below it, by the bounds of what they hold, and
/// returns the node's own box. The entries' boxes are widened by one `f32` step: a sphere's
/// `centre ± radius` and the analytic shapes' bounds are computed in `f32` and may round inward
/// (a triangle's vertices bound it exactly; the step costs it nothing).
fn tighten(nodes: &mut [Node], n: usize, bounds: &impl Fn(usize) -> [Vec3A; 2]) -> [Vec3A; 2] {
    let node = nodes[n];
    let mut all = [Vec3A::INFINITY, Vec3A::NEG_INFINITY];
    for s in 0..8 {
        let inner = node.imask & (1 << s) != 0;
        let [lo, hi] = if inner {
            tighten(nodes, child(node.child_base, node.imask as u32, s), bounds)
        } else if node.leaf[s as usize] != 0 {
            let mut entries = node.leaf[s as usize];
            let mut b = [Vec3A::INFINITY, Vec3A::NEG_INFINITY];
            while entries != 0 {
                let off = entries.trailing_zeros();
                entries &= entries - 1;
                let [lo, hi] = bounds((node.first + off) as usize);
                b = [
                    b[0].min(lo.to_array().map(f32::next_down).into()),
                    b[1].max(hi.to_array().map(f32::next_up).into()),
                ];
            }
            b
        } else {
            continue;
        };
        for axis in 0..3 {
            nodes[n].b[2 * axis][s as usize] = lo[axis];
            nodes[n].b[2 * axis + 1][s as usize] = hi[axis];
        }
        all = [all[0].min(lo), all[1].max(hi)];
    }
    all
}

/// Nodes on the longest path down from `n`.
fn depth_of(nodes: &[Node], n: usize) -> usize {
    let node = &nodes[n];
    let inner = node.imask.count_ones() as usize;
    (0..inner)
        .map(|k| depth_of(nodes, node.child_base as usize + k))
        .max()
        .unwrap_or(0)
        + 1
}

/// The child node in slot `slot` of a node with these `child_base` and `imask`.
#[inline(always)]
fn child(child_base: u32, imask: u32, slot: u32) -> usize {
    (child_base + (imask & !(u32::MAX << slot)).count_ones()) as usize
}

/// The mask of leaf entries (offsets from `node.first`) in the slots of `leaves`.
#[inline(always)]
fn leaf_entries(node: &Node, mut leaves: u32) -> u32 {
    let mut pm = 0;
    while leaves != 0 {
        pm |= node.leaf[leaves.trailing_zeros() as usize];
        leaves &= leaves - 1;
    }
    pm
}

/// Tests the BVH entries that are not inline triangles (spheres, groups): entry `e`'s closest
/// distance below `t_max` (infinity if none) and the primitive it names.
pub(super) trait Entries {
    fn entry(&self, e: usize, r: &TRay, t_max: f32) -> (f32, u32);
}

/// What a traversal does at a node's hit leaf entries: `Some(new t_max)` to go on, `None` to stop.
/// (A trait with `#[inline(always)]` methods rather than a closure: a closure would be compiled
/// without the kernel's target features, and every intrinsic in it would become a call.)
trait Visit {
    fn visit(&mut self, node: &Node, entries: u32, t_max: f32) -> Option<f32>;
}

/// Visits the tree depth first in obvhs's order, calling `v` at each node with hit leaves.
#[inline(always)]
fn walk<K: Kernel>(
    w: &Wide,
    r: &TRay,
    mut t_max: f32,
    stack: &mut [(u32, u32)],
    v: &mut impl Visit,
) {
    let perm = &PERM[r.oct as usize];
    let mut sp = 0;
    let mut n = 0;
    let t_lim = t_max * EXIT_SCALE;
    loop {
        let node = &w.nodes[n];
        let (m, _) = K::node_hits(node, r, t_lim);
        let imask = node.imask as u32;
        let leaves = m & !imask;
        if leaves != 0 {
            match v.visit(node, leaf_entries(node, leaves), t_max) {
                Some(t) => t_max = t,
                None => return,
            }
        }
        let inner = perm[(m & imask) as usize] as u32;
        if inner != 0 {
            stack[sp] = (node.child_base, imask << 8 | inner);
            sp += 1;
        }
        if sp == 0 {
            return;
        }
        let (base, packed) = stack[sp - 1];
        let order = packed & 0xff;
        let k = 31 - order.leading_zeros();
        let rest = order & !(1 << k);
        if rest == 0 {
            sp -= 1;
        } else {
            stack[sp - 1].1 = (packed & !0xff) | rest;
        }
        n = child(base, packed >> 8, k ^ r.oct);
    }
}

/// The closest-hit walk: depth first, nearest child first. At each node the hit leaves are
/// tested first (which may shorten `t_max`), then the inner children entered before `t_max` are
/// visited in order of their boxes' entry distance; a child waiting on the stack is dropped when
/// it is popped if the hit found meanwhile is nearer than its box. `stack` holds
/// `7·depth + 1` entries.
#[inline(always)]
fn walk_nearest<K: Kernel>(
    w: &Wide,
    r: &TRay,
    mut t_max: f32,
    stack: &mut [(u32, f32)],
    v: &mut impl Visit,
) {
    let mut sp = 0;
    let mut n = 0;
    let mut t_lim = t_max * EXIT_SCALE;
    loop {
        let node = &w.nodes[n];
        let (m, entry) = K::node_hits(node, r, t_lim);
        let imask = node.imask as u32;
        let leaves = m & !imask;
        if leaves != 0 {
            match v.visit(node, leaf_entries(node, leaves), t_max) {
                Some(t) if t != t_max => {
                    t_max = t;
                    t_lim = t * EXIT_SCALE;
                }
                Some(_) => {}
                None => return,
            }
        }
        // The inner children still in front of the nearest hit, nearest first.
        let mut inner = m & imask;
        let mut near: Option<(u32, f32)> = None;
        let base = sp;
        while inner != 0 {
            let s = inner.trailing_zeros();
            inner &= inner - 1;
            let t = entry[s as usize];
            // With the node test's allowance: a box's entry and a hit on its boundary are
            // computed apart and may round either way.
            if t > t_lim {
                continue;
            }
            let c = child(node.child_base, imask, s) as u32;
            match near {
                None => near = Some((c, t)),
                Some((nc, nt)) => {
                    // Keep the nearer one to visit now; the farther one goes on the stack,
                    // which is kept sorted farthest-first within this node's entries.
                    let (keep, push) = if t < nt {
                        ((c, t), (nc, nt))
                    } else {
                        ((nc, nt), (c, t))
                    };
                    near = Some(keep);
                    let mut i = sp;
                    while i > base && stack[i - 1].1 < push.1 {
                        stack[i] = stack[i - 1];
                        i -= 1;
                    }
                    stack[i] = push;
                    sp += 1;
                }
            }
        }
        if let Some((c, _)) = near {
            n = c as usize;
            continue;
        }
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            let (c, t) = stack[sp];
            if t <= t_lim {
                n = c as usize;
                break;
            }
        }
    }
}

struct Closest<'a, K, E> {
    w: &'a Wide,
    r: &'a TRay,
    entries: &'a E,
    best: Option<Found>,
    kernel: std::marker::PhantomData<K>,
}

/// The closest hit a traversal found: distance, BVH entry, the member [`Entries::entry`] named
/// for an entry tested one at a time (`u32::MAX` for an inline triangle), and an inline
/// triangle's barycentrics (zero otherwise).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Found {
    pub t: f32,
    pub entry: u32,
    pub member: u32,
    pub bary: [f32; 2],
}

impl<K: Kernel, E: Entries> Visit for Closest<'_, K, E> {
    #[inline(always)]
    fn visit(&mut self, node: &Node, entries: u32, t_max: f32) -> Option<f32> {
        let mut bt = t_max;
        let mut found: Option<(u32, u32, [f32; 2])> = None;
        let tris = entries & !node.scalar;
        for c in (0..3).rev() {
            let lanes = (tris >> (8 * c)) & 0xff;
            if lanes != 0 {
                let b = &self.w.blocks[(node.block + c) as usize];
                if let Some(h) = K::block_closest(b, self.r, bt, lanes) {
                    bt = h.t;
                    found = Some((8 * c + h.lane, u32::MAX, [h.u, h.v]));
                }
            }
        }
        let mut sc = entries & node.scalar;
        while sc != 0 {
            let off = 31 - sc.leading_zeros();
            sc &= !(1 << off);
            let (t, member) = self
                .entries
                .entry((node.first + off) as usize, self.r, t_max);
            // Sequentially (highest offset first, strict `<`), equal distances go to the
            // highest offset.
            if t < bt || (t == bt && found.is_some_and(|(o, _, _)| off > o)) {
                bt = t;
                found = Some((off, member, [0.0; 2]));
            }
        }
        if let Some((off, member, bary)) = found {
            self.best = Some(Found {
                t: bt,
                entry: node.first + off,
                member,
                bary,
            });
        }
        Some(bt)
    }
}

struct Any<'a, K, E> {
    w: &'a Wide,
    r: &'a TRay,
    entries: &'a E,
    hit: bool,
    kernel: std::marker::PhantomData<K>,
}

impl<K: Kernel, E: Entries> Visit for Any<'_, K, E> {
    #[inline(always)]
    fn visit(&mut self, node: &Node, entries: u32, t_max: f32) -> Option<f32> {
        let tris = entries & !node.scalar;
        for c in 0..3 {
            let lanes = (tris >> (8 * c)) & 0xff;
            if lanes != 0
                && K::block_any(
                    &self.w.blocks[(node.block + c) as usize],
                    self.r,
                    t_max,
                    lanes,
                )
            {
                self.hit = true;
                return None;
            }
        }
        let mut sc = entries & node.scalar;
        while sc != 0 {
            let off = sc.trailing_zeros();
            sc &= sc - 1;
            if self
                .entries
                .entry((node.first + off) as usize, self.r, t_max)
                .0
                < t_max
            {
                self.hit = true;
                return None;
            }
        }
        Some(t_max)
    }
}

/// The closest entry hit before `t_max`; `stack` holds `7·depth + 1` entries.
#[inline(always)]
pub(super) fn closest<K: Kernel>(
    w: &Wide,
    r: &TRay,
    t_max: f32,
    stack: &mut [(u32, f32)],
    entries: &impl Entries,
) -> Option<Found> {
    let mut v = Closest::<K, _> {
        w,
        r,
        entries,
        best: None,
        kernel: std::marker::PhantomData,
    };
    walk_nearest::<K>(w, r, t_max, stack, &mut v);
    v.best
}

/// Whether any entry is hit before `t_max`.
#[inline(always)]
pub(super) fn any<K: Kernel>(
    w: &Wide,
    r: &TRay,
    t_max: f32,
    stack: &mut [(u32, u32)],
    entries: &impl Entries,
) -> bool {
    let mut v = Any::<K, _> {
        w,
        r,
        entries,
        hit: false,
        kernel: std::marker::PhantomData,
    };
    walk::<K>(w, r, t_max, stack, &mut v);
    v.hit
}
