//! A light hierarchy over the emitter table's entries: a binary tree of bounded emitters that
//! picks one by a stochastic descent with a receiver-aware importance, and gives the exact
//! probability of any entry for a receiver by a second descent.
//!
//! Every node bounds its emitters by a box, their total power and a cone of emission directions
//! (an axis, the half-angle `θo` holding every emitter's normal, and the spread `θe` beyond it
//! in which they still emit: `π/2` for one-sided surfaces), after the light BVH of Conty Estevez
//! and Kulla (2018) that pbrt-v4 ships as `BVHLightSampler`. At a receiver `p` with normal `n`
//! the importance of a node is its power over the squared distance to its box's centre, times
//! a conservative bound of the emitters' cosine towards `p` and of the receiver's cosine towards
//! the box. It is zero only where no emitter of the node can light `p` (behind every one-sided
//! emitter of the node); the receiver's cosine is taken in absolute value (transmission is
//! covered) and floored, so a receiver never loses a light that faces it.
//!
//! The descent chooses a child with probability proportional to its importance, so the
//! probability of a leaf is the product of those choices along its path; [`LightBvh::pmf`]
//! follows the leaf's recorded path from the root and multiplies the same factors, so the two
//! agree to the last bit. The uniform number is rescaled in `f64` at every level (a 53-bit
//! mantissa outlasts any depth the tree reaches).
//!
//! Lights at infinity other than the environment (directional lights) have no box; they are
//! kept beside the tree with their power share of the local selections.

use core::f32::consts::PI;
use glam::Vec3;
use restir_geometry::Shape;

use crate::Light;
use crate::table::{Emitter, EmitterTable};

/// A cone of directions: `axis`, `cos θo` (every normal within `θo` of it) and `cos θe` (the
/// emission spread beyond a normal).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cone {
    axis: Vec3,
    cos_o: f32,
    cos_e: f32,
}

impl Cone {
    /// Every direction (an emitter that radiates all around: spheres, point lights, or
    /// triangles with varying shading normals).
    const ALL: Cone = Cone {
        axis: Vec3::Z,
        cos_o: -1.0,
        cos_e: 0.0,
    };

    /// The smallest cone this construction finds holding both (Conty Estevez and Kulla's union).
    fn union(a: Cone, b: Cone) -> Cone {
        let cos_e = a.cos_e.min(b.cos_e);
        let (ta, tb) = (
            a.cos_o.clamp(-1.0, 1.0).acos(),
            b.cos_o.clamp(-1.0, 1.0).acos(),
        );
        let (a, b, ta, tb) = if tb > ta {
            (b, a, tb, ta)
        } else {
            (a, b, ta, tb)
        };
        let td = a.axis.dot(b.axis).clamp(-1.0, 1.0).acos();
        if (td + tb).min(PI) <= ta {
            return Cone { cos_e, ..a };
        }
        let to = 0.5 * (ta + td + tb);
        if to >= PI {
            return Cone { cos_e, ..Cone::ALL };
        }
        let rotate = to - ta;
        let w = a.axis.cross(b.axis);
        if w.length_squared() < 1e-12 {
            return Cone { cos_e, ..Cone::ALL };
        }
        let axis = glam::Quat::from_axis_angle(w.normalize(), rotate) * a.axis;
        Cone {
            axis: axis.normalize(),
            // A little slack so rounding never leaves a normal outside.
            cos_o: (to + 1e-3).min(PI).cos(),
            cos_e,
        }
    }
}

/// `cos(max(0, a − b))` from the sines and cosines of `a` and `b` in `[0, π]`.
#[inline(always)]
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

/// `sin(max(0, a − b))` from the sines and cosines of `a` and `b` in `[0, π]`.
#[inline(always)]
fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        0.0
    } else {
        sin_a * cos_b - cos_a * sin_b
    }
}

/// A tree node: bounds, power and cone of its emitters. Nodes are stored depth first, so a
/// node's first child follows it; `index` is its second child, or for a leaf its entry.
#[derive(Clone, Copy, Debug)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    cone: Cone,
    power: f32,
    index: u32,
    leaf: bool,
}

impl Node {
    /// The receiver-aware importance of the node at `p` with normal `n` (zero `n`: no receiver
    /// term).
    #[inline(always)]
    /// `d2_floor` bounds the squared distance below (see [`LightBvh::d2_floor`]).
    fn importance(&self, p: Vec3, n: Vec3, d2_floor: f32) -> f32 {
        self.importance_at(p, n, d2_floor, None)
    }

    /// [`Node::importance`], or with `nearest = Some(floor)` the squared distance taken from
    /// `p` to the nearest point of the box (at least `floor`) instead of to its centre: a lower
    /// bound of every emitter's distance, so no emitter's importance is underestimated by the
    /// distance (what a region of receivers needs, [`LightBvh::region_importance`]).
    #[inline(always)]
    fn importance_at(&self, p: Vec3, n: Vec3, d2_floor: f32, nearest: Option<f32>) -> f32 {
        if self.power <= 0.0 {
            return 0.0;
        }
        let c = 0.5 * (self.lo + self.hi);
        let r2 = 0.25 * (self.hi - self.lo).length_squared();
        let to = p - c;
        let dist2 = to.length_squared();
        let d2 = match nearest {
            None => dist2.max(r2),
            Some(floor) => (p.clamp(self.lo, self.hi) - p).length_squared().max(floor),
        }
        .max(d2_floor);
        let wi = if dist2 > 0.0 {
            to / dist2.sqrt()
        } else {
            Vec3::Z
        };
        // The half-angle of a cone from p holding the node's bounding sphere.
        let inside = p.cmpge(self.lo).all() && p.cmple(self.hi).all();
        let (sin_b, cos_b) = if inside || dist2 <= r2 {
            (0.0, -1.0)
        } else {
            let s2 = r2 / dist2;
            (s2.sqrt(), (1.0 - s2).max(0.0).sqrt())
        };
        // The emitters' cosine towards p, bounded below the angle θ' = max(0, θw − θo − θb).
        let cos_w = self.cone.axis.dot(wi).clamp(-1.0, 1.0);
        let sin_w = (1.0 - cos_w * cos_w).max(0.0).sqrt();
        let cos_o = self.cone.cos_o;
        let sin_o = (1.0 - cos_o * cos_o).max(0.0).sqrt();
        let cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, cos_o);
        let sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, cos_o);
        let cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
        if cos_p <= self.cone.cos_e {
            return 0.0;
        }
        let mut importance = self.power * cos_p / d2;
        if n != Vec3::ZERO {
            let cos_i = n.dot(wi).abs().min(1.0);
            let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
            // A floor keeps a receiver lit at grazing angles by a near node sampleable.
            importance *= cos_sub_clamped(sin_i, cos_i, sin_b, cos_b).max(1e-3);
        }
        importance.max(0.0)
    }
}

/// One emitter as the build sees it.
#[derive(Clone, Copy, Debug)]
struct Item {
    entry: u32,
    /// The light the entry belongs to.
    light: u32,
    lo: Vec3,
    hi: Vec3,
    cone: Cone,
    power: f32,
}

/// The light hierarchy over the bounded local entries of an emitter table.
#[derive(Clone, Debug, Default)]
pub(crate) struct LightBvh {
    nodes: Vec<Node>,
    /// Per entry of the table, its leaf's path from the root (bit `d` set: second child at
    /// depth `d`); `u64::MAX` for an entry outside the tree.
    trails: Vec<u64>,
    /// Per node, the leaves under it: `(first, count)` in depth-first leaf order.
    spans: Vec<(u32, u32)>,
    /// Per node, the light all its entries belong to, or `u32::MAX` where they belong to
    /// several.
    node_light: Vec<u32>,
    /// Per light, whether it cannot light a point of its own surface (`own.rs`).
    pub(crate) self_unlit: Vec<bool>,
    /// Per entry of the table, its leaf's position in depth-first order; `u32::MAX` outside.
    ordinals: Vec<u32>,
    /// The entries in depth-first leaf order.
    by_ordinal: Vec<u32>,
    /// Prefix sums of the leaves' power in depth-first order (one more than the leaves), so a
    /// node's entries are drawn by power in its span ([`LightBvh::sample_span`]).
    prefix: Vec<f64>,
    /// A guide into `prefix`: entry `k` is the leaf whose interval holds `k / len` of the total
    /// power, so a search by power starts next to its answer (the guide table of Chen and
    /// Asau, 1974).
    guide: Vec<u32>,
    /// Entries without bounds (directional lights), picked by power beside the tree.
    pub(crate) unbounded: Vec<(u32, f32)>,
    /// Share of local selections that go to `unbounded` (their power share).
    pub(crate) unbounded_share: f32,
    pub(crate) unbounded_power: f32,
    /// The least squared distance importance divides by: `(10⁻⁶ · extent)²` of the tree's box
    /// (10⁻¹² for a scene of unit extent), so that a receiver on a point-like node does not
    /// divide by zero, and the same scene in any unit weighs its nodes alike (an absolute floor
    /// would flatten the importance of every node in a scene of 10⁻⁶ units).
    d2_floor: f32,
}

impl LightBvh {
    /// Builds the tree over the entries of `table` with their selection weights `weights`
    /// (power).
    pub fn new(lights: &[Light], shapes: &[Shape], table: &EmitterTable, weights: &[f32]) -> Self {
        let entries = table.entries();
        let mut items = Vec::with_capacity(entries.len());
        let mut unbounded = Vec::new();
        let (mut bounded_power, mut unbounded_power) = (0.0f64, 0.0f64);
        for (i, (e, &w)) in entries.iter().zip(weights).enumerate() {
            if w.is_nan() || w <= 0.0 {
                continue;
            }
            let entry = i as u32;
            let item = match *e {
                Emitter::Triangle {
                    ref p, ng, shading, ..
                } => Some(Item {
                    entry,
                    light: e.light(),
                    lo: p[0].min(p[1]).min(p[2]),
                    hi: p[0].max(p[1]).max(p[2]),
                    cone: match table.constant_normal(ng, shading) {
                        None => Cone::ALL,
                        Some(n) => Cone {
                            axis: n,
                            cos_o: 1.0,
                            cos_e: 0.0,
                        },
                    },
                    power: w,
                }),
                Emitter::Whole { light } => match lights[light as usize] {
                    Light::Area { shape, .. } => {
                        let (lo, hi) = match &shapes[shape as usize] {
                            Shape::Sphere(s) => (
                                s.center - Vec3::splat(s.radius),
                                s.center + Vec3::splat(s.radius),
                            ),
                            Shape::Mesh(m) => mesh_bounds(m),
                            s => s.bounds(),
                        };
                        Some(Item {
                            entry,
                            light,
                            lo,
                            hi,
                            cone: Cone::ALL,
                            power: w,
                        })
                    }
                    Light::Point { position, .. }
                    | Light::Spot(crate::Spot { position, .. })
                    | Light::Projector(crate::Projector { position, .. }) => Some(Item {
                        entry,
                        light,
                        lo: position,
                        hi: position,
                        cone: Cone::ALL,
                        power: w,
                    }),
                    _ => None,
                },
            };
            match item {
                Some(item) => {
                    bounded_power += w as f64;
                    items.push(item);
                }
                None => {
                    unbounded_power += w as f64;
                    unbounded.push((entry, w));
                }
            }
        }
        let mut bvh = LightBvh {
            nodes: Vec::with_capacity(2 * items.len()),
            trails: vec![u64::MAX; entries.len()],
            spans: Vec::with_capacity(2 * items.len()),
            node_light: Vec::with_capacity(2 * items.len()),
            self_unlit: crate::own::self_unlit(lights, shapes, table),
            ordinals: vec![u32::MAX; entries.len()],
            by_ordinal: Vec::with_capacity(items.len()),
            prefix: vec![0.0],
            guide: Vec::new(),
            unbounded,
            unbounded_share: (unbounded_power / (unbounded_power + bounded_power).max(1e-300))
                as f32,
            unbounded_power: unbounded_power as f32,
            d2_floor: 1e-12,
        };
        if items.is_empty() {
            bvh.unbounded_share = if bvh.unbounded.is_empty() { 0.0 } else { 1.0 };
        } else {
            bvh.build(&mut items, 0, 0);
            bvh.d2_floor = Self::d2_floor(bvh.nodes[0].lo, bvh.nodes[0].hi);
            bvh.guide = guide(&bvh.prefix);
        }
        bvh
    }

    /// `(10⁻⁶ · e)²` for the box `lo..hi` of largest side `e`; where the box is a point, its
    /// largest coordinate magnitude stands for `e`, and 1 where that is zero too.
    fn d2_floor(lo: Vec3, hi: Vec3) -> f32 {
        let extent = (hi - lo).max_element();
        let magnitude = lo.abs().max(hi.abs()).max_element();
        let e = [extent, magnitude, 1.0]
            .into_iter()
            .find(|e| e.is_finite() && *e > 0.0)
            .unwrap_or(1.0);
        let floor = (1e-6 * e) * (1e-6 * e);
        if floor.is_normal() {
            floor
        } else {
            f32::MIN_POSITIVE
        }
    }

    /// Builds the subtree over `items` (non-empty) at `depth` whose path is `trail`; returns its
    /// node index.
    fn build(&mut self, items: &mut [Item], depth: u32, trail: u64) -> u32 {
        let index = self.nodes.len() as u32;
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        let (mut clo, mut chi) = (lo, hi);
        let mut power = 0.0f32;
        let mut cone: Option<Cone> = None;
        for it in items.iter() {
            lo = lo.min(it.lo);
            hi = hi.max(it.hi);
            let c = 0.5 * (it.lo + it.hi);
            clo = clo.min(c);
            chi = chi.max(c);
            power += it.power;
            cone = Some(cone.map_or(it.cone, |k| Cone::union(k, it.cone)));
        }
        let cone = cone.unwrap_or(Cone::ALL);
        if items.len() == 1 {
            // One entry per leaf; a median split keeps the depth at ⌈log2 n⌉ (< 64).
            let entry = items[0].entry;
            self.nodes.push(Node {
                lo,
                hi,
                cone,
                power,
                index: entry,
                leaf: true,
            });
            self.node_light.push(items[0].light);
            self.trails[entry as usize] = trail;
            let ordinal = self.by_ordinal.len() as u32;
            self.spans.push((ordinal, 1));
            self.ordinals[entry as usize] = ordinal;
            self.by_ordinal.push(entry);
            let last = *self.prefix.last().unwrap_or(&0.0);
            self.prefix.push(last + power as f64);
            return index;
        }
        self.nodes.push(Node {
            lo,
            hi,
            cone,
            power,
            index: 0,
            leaf: false,
        });
        let first = self.by_ordinal.len() as u32;
        self.spans.push((first, items.len() as u32));
        let light = items[0].light;
        let one_light = items.iter().all(|it| it.light == light);
        self.node_light
            .push(if one_light { light } else { u32::MAX });
        // Median split of the centroids along their widest axis.
        let extent = chi - clo;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let mid = items.len() / 2;
        items.select_nth_unstable_by(mid, |a, b| {
            let ca = (a.lo + a.hi)[axis];
            let cb = (b.lo + b.hi)[axis];
            ca.total_cmp(&cb)
        });
        let (left, right) = items.split_at_mut(mid);
        self.build(left, depth + 1, trail);
        let second = self.build(right, depth + 1, trail | (1u64 << depth));
        self.nodes[index as usize].index = second;
        index
    }

    /// Picks a local entry for a receiver at `p` with normal `n` (zero if unknown) with uniform
    /// `u ∈ [0, 1)`: `(entry, probability)`. `None` when no entry can light `p`.
    #[inline]
    pub fn sample(&self, p: Vec3, n: Vec3, u: f64) -> Option<(u32, f32)> {
        let mut u = u;
        let mut pmf = 1.0f32;
        let s = self.unbounded_share as f64;
        if !self.unbounded.is_empty() {
            if u < s {
                let (entry, pmf) = self.sample_unbounded(u / s)?;
                return Some((entry, self.unbounded_share * pmf));
            }
            u = ((u - s) / (1.0 - s)).min(1.0 - f64::EPSILON);
            pmf = 1.0 - self.unbounded_share;
        }
        let mut node = 0usize;
        let mut current = self.nodes.get(node)?;
        if current.importance(p, n, self.d2_floor) <= 0.0 {
            return None;
        }
        while !current.leaf {
            let (a, b) = (node + 1, current.index as usize);
            let ia = self.nodes[a].importance(p, n, self.d2_floor) as f64;
            let ib = self.nodes[b].importance(p, n, self.d2_floor) as f64;
            let total = ia + ib;
            if total <= 0.0 {
                return None;
            }
            let pa = ia / total;
            if u < pa {
                u = (u / pa).min(1.0 - f64::EPSILON);
                pmf *= pa as f32;
                node = a;
            } else {
                u = ((u - pa) / (1.0 - pa)).min(1.0 - f64::EPSILON);
                pmf *= (ib / total) as f32;
                node = b;
            }
            current = &self.nodes[node];
        }
        Some((current.index, pmf))
    }

    /// The probability that [`LightBvh::sample`] picks `entry` for a receiver at `p` with
    /// normal `n`.
    #[inline]
    pub fn pmf(&self, p: Vec3, n: Vec3, entry: u32) -> f32 {
        if let Some(&(_, w)) = self.unbounded.iter().find(|(e, _)| *e == entry) {
            return self.unbounded_share * (w / self.unbounded_power);
        }
        let Some(&trail) = self.trails.get(entry as usize) else {
            return 0.0;
        };
        if trail == u64::MAX || self.nodes.is_empty() {
            return 0.0;
        }
        let mut pmf = if self.unbounded.is_empty() {
            1.0f32
        } else {
            1.0 - self.unbounded_share
        };
        let mut node = 0usize;
        if self.nodes[0].importance(p, n, self.d2_floor) <= 0.0 {
            return 0.0;
        }
        let mut depth = 0;
        while !self.nodes[node].leaf {
            let (a, b) = (node + 1, self.nodes[node].index as usize);
            let ia = self.nodes[a].importance(p, n, self.d2_floor) as f64;
            let ib = self.nodes[b].importance(p, n, self.d2_floor) as f64;
            let total = ia + ib;
            if total <= 0.0 {
                return 0.0;
            }
            if trail & (1u64 << depth) == 0 {
                pmf *= (ia / total) as f32;
                node = a;
            } else {
                pmf *= (ib / total) as f32;
                node = b;
            }
            depth += 1;
        }
        if self.nodes[node].index == entry {
            pmf
        } else {
            0.0
        }
    }

    /// Number of nodes (for statistics).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The importance of node `i` for every receiver within `spread` of `p` whose normal is `n`
    /// (zero: any normal): the node's box grown by `spread`, so that each such receiver sees
    /// the node's emitters within the directions `p` sees the grown box in, and the distance
    /// from `p` to the grown box's nearest point, a lower bound of every receiver's distance to
    /// every emitter of the node (floored at the region's radius and the node's own half
    /// diagonal: what is nearer is one of the region's or the node's own). So the bound stays
    /// conservative: zero only where no emitter of the node can light any receiver, and no
    /// emitter near one receiver of the region has its probability set by the region's mean
    /// (the distance to a box's centre would make it arbitrarily small there).
    #[inline]
    pub(crate) fn region_importance(&self, i: usize, p: Vec3, n: Vec3, spread: f32) -> f32 {
        let mut node = self.nodes[i];
        let r2 = 0.25 * (node.hi - node.lo).length_squared();
        let grow = Vec3::splat(spread);
        node.lo -= grow;
        node.hi += grow;
        node.importance_at(p, n, self.d2_floor, Some(r2.max(spread * spread)))
    }

    /// The children of node `i`, or `None` for a leaf.
    #[inline]
    pub(crate) fn children(&self, i: usize) -> Option<(usize, usize)> {
        let node = &self.nodes[i];
        (!node.leaf).then_some((i + 1, node.index as usize))
    }

    /// How far node `i`'s emitters spread as seen from `p`: the radius of its bounding sphere
    /// over the distance to its centre, at most 1.
    #[inline]
    pub(crate) fn angular_size(&self, i: usize, p: Vec3) -> f32 {
        let node = &self.nodes[i];
        let r = 0.5 * (node.hi - node.lo).length();
        let d = (0.5 * (node.lo + node.hi) - p).length();
        if d <= r { 1.0 } else { r / d }
    }

    /// The light all of node `i`'s entries belong to, if one.
    #[inline]
    pub(crate) fn node_light(&self, i: usize) -> Option<u32> {
        Some(self.node_light[i]).filter(|&l| l != u32::MAX)
    }

    /// Node `i`'s leaves, `(first, count)` in depth-first order.
    #[inline]
    pub(crate) fn span(&self, i: usize) -> (u32, u32) {
        self.spans[i]
    }

    /// Whether the tree holds any entry.
    pub(crate) fn has_nodes(&self) -> bool {
        !self.nodes.is_empty()
    }

    /// Picks an entry of the span `(first, count)` by power with `u ∈ [0, 1)`: `(entry,
    /// probability within the span)`.
    #[inline]
    pub(crate) fn sample_span(&self, (first, count): (u32, u32), u: f64) -> (u32, f32) {
        let (a, b) = (first as usize, (first + count) as usize);
        let (lo, hi) = (self.prefix[a], self.prefix[b]);
        let target = lo + u * (hi - lo);
        // The leaf whose interval [prefix[o], prefix[o + 1]) holds the target: from the guide's
        // leaf a few steps forward, else by bisection over the rest of the span.
        let total = self.prefix[self.prefix.len() - 1];
        let n = self.guide.len();
        let k = ((target / total * n as f64) as usize).min(n - 1);
        let mut o = (self.guide[k] as usize).clamp(a, b - 1);
        // Rounding of the bucket can put the guide one leaf past the target.
        while o > a && self.prefix[o] > target {
            o -= 1;
        }
        let mut steps = 0;
        while o + 1 < b && self.prefix[o + 1] <= target {
            o += 1;
            steps += 1;
            if steps == 8 {
                o += self.prefix[o + 1..b].partition_point(|&c| c <= target);
                break;
            }
        }
        let o = o.min(b - 1);
        let pmf = ((self.prefix[o + 1] - self.prefix[o]) / (hi - lo)) as f32;
        (self.by_ordinal[o], pmf)
    }

    /// The probability that [`LightBvh::sample_span`] picks `entry` from the span `(first,
    /// count)`; `None` if the entry is not in it.
    #[inline]
    pub(crate) fn span_pmf(&self, (first, count): (u32, u32), entry: u32) -> Option<f32> {
        let o = *self.ordinals.get(entry as usize)? as usize;
        let (a, b) = (first as usize, (first + count) as usize);
        if o < a || o >= b {
            return None;
        }
        Some(((self.prefix[o + 1] - self.prefix[o]) / (self.prefix[b] - self.prefix[a])) as f32)
    }

    /// The depth-first position of `entry`'s leaf, if the tree holds it.
    #[inline]
    pub(crate) fn ordinal(&self, entry: u32) -> Option<u32> {
        self.ordinals
            .get(entry as usize)
            .copied()
            .filter(|&o| o != u32::MAX)
    }

    /// Picks one of the entries without bounds by power with `u ∈ [0, 1)`: `(entry, probability
    /// among them)`.
    pub(crate) fn sample_unbounded(&self, u: f64) -> Option<(u32, f32)> {
        let v = u * self.unbounded_power as f64;
        let mut acc = 0.0f64;
        for &(entry, w) in &self.unbounded {
            acc += w as f64;
            if v < acc {
                return Some((entry, w / self.unbounded_power));
            }
        }
        let &(entry, w) = self.unbounded.last()?;
        Some((entry, w / self.unbounded_power))
    }
}

/// The guide table of the prefix sums `prefix` (one more than the leaves, non-decreasing,
/// starting at 0): per bucket `k` of as many as leaves, the last leaf `o` with
/// `prefix[o] ≤ k / n · total`, so the leaf holding any target in the bucket is at or after it.
fn guide(prefix: &[f64]) -> Vec<u32> {
    let n = prefix.len() - 1;
    let total = prefix[n];
    let mut out = Vec::with_capacity(n);
    let mut o = 0usize;
    for k in 0..n {
        let t = k as f64 / n as f64 * total;
        while o + 1 < n && prefix[o + 1] <= t {
            o += 1;
        }
        out.push(o as u32);
    }
    out
}

/// The bounding box of a mesh.
fn mesh_bounds(m: &restir_geometry::TriangleMesh) -> (Vec3, Vec3) {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for t in 0..m.triangle_count() {
        for p in m.triangle(t) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    (lo, hi)
}
