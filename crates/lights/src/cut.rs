//! Light cuts: the light hierarchy cut once for a region of receivers (a screen tile's primary
//! hits), so that a candidate costs a table lookup instead of a descent.
//!
//! A cut is a set of nodes of the hierarchy (`bvh.rs`) that holds every leaf exactly once. It
//! is grown from the root by splitting, again and again, the node whose importance for the
//! region times its angular size seen from the region is largest (where a node's emitters are
//! far and small, its importance varies little across them and it stays whole; near nodes are
//! split down to single emitters), up to a fixed number of nodes — the refinement of Walter et
//! al., "Lightcuts" (SIGGRAPH 2005), with the importance of Conty Estevez and Kulla (2018) in
//! place of their error bound. Each node of the cut gets its importance for the whole region
//! (the node's box grown by the region's radius, so the bound holds for every receiver in it);
//! a selection draws a node from an alias table over those importances and an emitter of the
//! node by power. Because a cut partitions the leaves, an entry's probability is its node's
//! probability times its power share in the node, found by one binary search over the cut's
//! leaf spans, exactly, for any entry. An entry's probability is zero only where its node's
//! importance is, that is where no emitter of the node can light any receiver of the region:
//! the support of every receiver's integrand is kept.
//!
//! Directional lights stay beside the tree with their power share, and the environment with
//! its share of all selections, as for the descent ([`LightSet::sample_hierarchy`]).

use std::collections::BinaryHeap;

use glam::{Vec2, Vec3};
use restir_sampling::AliasTable;

use crate::bvh::LightBvh;
use crate::own::OwnLight;
use crate::{LearnedDraw, LearnedSampler, LightSample, LightSet};

/// The hierarchy cut for one region of receivers ([`LightSet::light_cut`]).
#[derive(Clone, Debug)]
pub struct LightCut {
    /// Per node of the cut, ordered by its first leaf, its leaves `(first, count)` in the
    /// hierarchy's depth-first order.
    spans: Vec<(u32, u32)>,
    /// Over the nodes, by their importance for the region.
    table: AliasTable,
}

impl LightCut {
    /// Bytes a cut keeps per node: its leaf span and its alias table's bin.
    pub const BYTES_PER_NODE: usize = std::mem::size_of::<(u32, u32)>() + AliasTable::BYTES_PER_BIN;

    /// Number of nodes in the cut.
    pub fn len(&self) -> usize {
        self.spans.len()
    }

    /// Always false: a cut without a node with importance is not built.
    pub fn is_empty(&self) -> bool {
        self.spans.is_empty()
    }
}

/// A node waiting to be split, ordered by its priority.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Open {
    priority: f32,
    node: u32,
    importance: f32,
}

impl Eq for Open {}

impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Open {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.priority
            .total_cmp(&other.priority)
            .then(other.node.cmp(&self.node))
    }
}

impl LightBvh {
    /// The cut of at most `max_nodes` nodes for receivers within `spread` of `p` with normal
    /// `n` (zero: normals differ); `None` if no node can light the region.
    ///
    /// With `own`, every receiver lies on that light: its own nodes are not split, and together
    /// they keep `own.share` of the selections (in proportion to their importance), the other
    /// nodes the rest; where no other node can light the region they keep all of it.
    fn cut(
        &self,
        p: Vec3,
        n: Vec3,
        spread: f32,
        max_nodes: usize,
        own: Option<OwnLight>,
    ) -> Option<LightCut> {
        if !self.has_nodes() {
            return None;
        }
        let own_light = own.map(|o| o.light);
        let is_own = |node: usize| own_light.is_some() && self.node_light(node) == own_light;
        let open = |node: usize| {
            let importance = self.region_importance(node, p, n, spread);
            let priority = match self.children(node) {
                Some(_) if is_own(node) => 0.0,
                Some(_) => importance * self.angular_size(node, p),
                None => -1.0,
            };
            Open {
                priority,
                node: node as u32,
                importance,
            }
        };
        let mut heap = BinaryHeap::with_capacity(max_nodes + 1);
        heap.push(open(0));
        while heap.len() < max_nodes {
            let Some(top) = heap.peek().copied() else {
                break;
            };
            // Leaves and nodes that light nothing here are not split.
            let Some((a, b)) = self
                .children(top.node as usize)
                .filter(|_| top.priority > 0.0)
            else {
                break;
            };
            heap.pop();
            heap.push(open(a));
            heap.push(open(b));
        }
        let mut cut: Vec<((u32, u32), f32, bool)> = heap
            .into_iter()
            .map(|o| {
                let node = o.node as usize;
                (self.span(node), o.importance, is_own(node))
            })
            .collect();
        if let Some(own) = own {
            let (mut w_own, mut w_other) = (0.0f64, 0.0f64);
            for &(_, w, mine) in &cut {
                if mine {
                    w_own += f64::from(w);
                } else {
                    w_other += f64::from(w);
                }
            }
            if w_own > 0.0 && w_other > 0.0 {
                let share = f64::from(own.share.clamp(0.0, 0.5));
                let scale = (share / (1.0 - share) * w_other / w_own) as f32;
                for (_, w, mine) in &mut cut {
                    if *mine {
                        *w *= scale;
                    }
                }
            }
        }
        let mut cut: Vec<((u32, u32), f32)> =
            cut.into_iter().map(|(span, w, _)| (span, w)).collect();
        cut.sort_unstable_by_key(|&((first, _), _)| first);
        let weights: Vec<f32> = cut.iter().map(|&(_, w)| w).collect();
        let table = AliasTable::new(&weights)?;
        Some(LightCut {
            spans: cut.into_iter().map(|(span, _)| span).collect(),
            table,
        })
    }

    /// Picks a local entry from `cut` with `u_node` (the node) and `u_leaf` (the entry within
    /// it), both in `[0, 1)`: `(entry, probability)`.
    #[inline]
    fn sample_cut(&self, cut: &LightCut, u_node: f32, u_leaf: f64) -> Option<(u32, f32)> {
        let mut u_node = u_node;
        let mut scale = 1.0f32;
        if !self.unbounded.is_empty() {
            let s = self.unbounded_share;
            if u_node < s {
                let (entry, pmf) = self.sample_unbounded(u_leaf)?;
                return Some((entry, s * pmf));
            }
            u_node = ((u_node - s) / (1.0 - s)).min(restir_sampling::ONE_MINUS_EPSILON);
            scale = 1.0 - s;
        }
        let (k, node_pmf, _) = cut.table.sample(u_node);
        if node_pmf <= 0.0 {
            return None;
        }
        let (entry, leaf_pmf) = self.sample_span(cut.spans[k], u_leaf);
        Some((entry, scale * node_pmf * leaf_pmf))
    }

    /// The probability that [`LightBvh::sample_cut`] picks `entry` from `cut`.
    fn cut_pmf(&self, cut: &LightCut, entry: u32) -> f32 {
        if let Some(&(_, w)) = self.unbounded.iter().find(|(e, _)| *e == entry) {
            return self.unbounded_share * (w / self.unbounded_power);
        }
        let Some(ordinal) = self.ordinal(entry) else {
            return 0.0;
        };
        let k = cut.spans.partition_point(|&(first, _)| first <= ordinal);
        let Some(k) = k.checked_sub(1) else {
            return 0.0;
        };
        let Some(leaf_pmf) = self.span_pmf(cut.spans[k], entry) else {
            return 0.0;
        };
        let scale = if self.unbounded.is_empty() {
            1.0
        } else {
            1.0 - self.unbounded_share
        };
        scale * cut.table.pmf(k) * leaf_pmf
    }
}

impl LightSet {
    /// The light hierarchy cut into at most `max_nodes` nodes for receivers within `spread` of
    /// `p` whose shading normal is `n` (zero if they differ), built once for a region and
    /// sampled by [`LightSet::sample_cut`]. `None` if no local light can light the region.
    ///
    /// `own`: every receiver of the region lies on that light, whose emitters then keep
    /// `own.share` of the selections (the rest goes to the lights that can reach the
    /// receivers); meant for lights that cannot light their own surface
    /// ([`LightSet::self_unlit`]), unbiased for any light as long as the share is positive.
    pub fn light_cut(
        &self,
        p: Vec3,
        n: Vec3,
        spread: f32,
        max_nodes: usize,
        own: Option<OwnLight>,
    ) -> Option<LightCut> {
        // Rounding must not leave a receiver of the region outside its grown boxes.
        let spread = spread * (1.0 + 1e-4) + 1e-6 * p.abs().max_element();
        self.hierarchy().cut(p, n, spread, max_nodes.max(1), own)
    }

    /// Whether light `light` cannot light a point of its own surface: an outward sphere, or a
    /// mesh of at most 4096 emitting triangles with every corner behind every triangle's plane
    /// (a lamp's bulb, a flat panel). Decided once, when the hierarchy is built.
    pub fn self_unlit(&self, light: u32) -> bool {
        self.hierarchy()
            .self_unlit
            .get(light as usize)
            .copied()
            .unwrap_or(false)
    }

    /// How many lights cannot light their own surface ([`LightSet::self_unlit`]).
    pub fn self_unlit_count(&self) -> usize {
        self.hierarchy().self_unlit.iter().filter(|&&b| b).count()
    }

    /// Picks a light for a receiver at `ref_p` from a cut of its region (`u_select ∈ [0, 1)`
    /// for the environment's share and the cut's node, `u_leaf` for the emitter within the
    /// node), and a point on it (`u`). Returns the sample, whose `pdf_sa` includes the
    /// selection probability, and the density [`LightSet::sample`] (power selection) gives the
    /// same point.
    #[inline]
    pub fn sample_cut(
        &self,
        cut: &LightCut,
        ref_p: Vec3,
        u_select: f32,
        u_leaf: f64,
        u: Vec2,
    ) -> Option<(LightSample, f32)> {
        let (e, pmf) = self.pick_from_cut(cut, u_select, u_leaf)?;
        self.sample_entry(e, pmf, ref_p, u)
    }

    /// Picks an emitter from `cut` with `u_select` and `u_leaf` as [`LightSet::sample_cut`]
    /// does: `(emitter, probability)`, numbered as [`LightSet::pick_emitter`] numbers them (the
    /// environment after the local entries).
    #[inline]
    pub fn pick_from_cut(
        &self,
        cut: &LightCut,
        u_select: f32,
        u_leaf: f64,
    ) -> Option<(usize, f32)> {
        let share = self.table.env_share();
        if self.environment.is_some() && u_select < share {
            return Some((self.table.len(), share));
        }
        let v = if share > 0.0 {
            ((u_select - share) / (1.0 - share)).clamp(0.0, restir_sampling::ONE_MINUS_EPSILON)
        } else {
            u_select
        };
        let (entry, pmf) = self.hierarchy().sample_cut(cut, v, u_leaf)?;
        Some((entry as usize, pmf * (1.0 - share)))
    }

    /// Fills `out` with independent draws made without a receiver from `cut`, or, with
    /// `learned = Some((sampler, cell))`, from the mixture of the cell's learned table (its
    /// share, [`LearnedSampler::table_share`]) and the cut (the rest) — the cut as the learned
    /// table's defensive part in place of the power sampler. The selections are stratified
    /// over `out`; each draw is a [`Presampled`](crate::Presampled) point (its density the
    /// power sampler's) with the ratio of the mixture's probability to the power sampler's, as
    /// [`LearnedSampler::presample`] fills a cell's pool. The tests' negative controls:
    /// `claim` [`Claim::Power`] weighs the draws as the power sampler's, [`Claim::TableAlone`]
    /// as the learned table's alone where it has the emitter.
    pub fn presample_cut(
        &self,
        cut: &LightCut,
        learned: Option<(&LearnedSampler, u32)>,
        rng: &mut restir_sampling::Pcg32,
        claim: Claim,
        out: &mut [Option<LearnedDraw>],
    ) {
        let n = out.len() as f32;
        let u0 = rng.next_f32();
        let share = learned.map_or(0.0, |(l, c)| l.table_share(Some(c)));
        for (j, slot) in out.iter_mut().enumerate() {
            let u_select = ((j as f32 + u0) / n).min(restir_sampling::ONE_MINUS_EPSILON);
            let u_leaf = rng.next_f64();
            let u = rng.next_2d();
            // The emitter and, without a learned table, its probability (the cut's, known at
            // the pick); with one, the mixture's is looked up below.
            let picked = match learned {
                Some((l, c)) if u_select < share => l
                    .sample_table(
                        c,
                        (u_select / share).min(restir_sampling::ONE_MINUS_EPSILON),
                    )
                    .map(|e| (e, None)),
                _ => {
                    let v = ((u_select - share) / (1.0 - share))
                        .clamp(0.0, restir_sampling::ONE_MINUS_EPSILON);
                    self.pick_from_cut(cut, v, u_leaf)
                        .map(|(e, pmf)| (e, learned.is_none().then_some(pmf)))
                }
            };
            *slot = picked.and_then(|(e, known)| {
                let power = self.emitter_pmf(e);
                let table = learned.map_or(0.0, |(l, c)| l.table_probability(self, c, e));
                let mixture =
                    known.unwrap_or_else(|| share * table + (1.0 - share) * self.cut_pmf(cut, e));
                let claimed = match claim {
                    Claim::Exact => mixture,
                    Claim::Power => power,
                    Claim::TableAlone if table > 0.0 => table,
                    Claim::TableAlone => mixture,
                };
                (power > 0.0)
                    .then(|| self.presample_emitter(e, u))
                    .flatten()
                    .map(|d| (d, claimed / power))
            });
        }
    }

    /// The probability that [`LightSet::sample_cut`] picks emitter `e` (numbered as
    /// [`LightSet::pick_emitter`] numbers them: the environment after the local entries) from
    /// `cut`.
    pub fn cut_pmf(&self, cut: &LightCut, e: usize) -> f32 {
        let share = self.table.env_share();
        if e == self.table.len() && self.environment.is_some() {
            return share;
        }
        (1.0 - share) * self.hierarchy().cut_pmf(cut, e as u32)
    }
}

/// What a pool's draws claim as their probability ([`LightSet::presample_cut`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Claim {
    /// The mixture's, exactly.
    Exact,
    /// The power sampler's (a negative control of the tests: biased).
    #[doc(hidden)]
    Power,
    /// The learned table's alone where it has the emitter, forgetting the defensive part (a
    /// negative control of the tests: biased).
    #[doc(hidden)]
    TableAlone,
}
