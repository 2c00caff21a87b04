//! obvhs's CWBVH build, step by step, so that what it no longer needs is freed before the next
//! step: the steps and parameters of `obvhs::cwbvh::builder::build_cwbvh` with
//! `BvhBuildParams::medium_build()` (the same tree), but the input boxes are dropped once the
//! binary tree is built, the PLOC builder's scratch is sized for the sort precision used, and
//! the binary tree's parent links (needed only by the reinsertion pass) are dropped before it
//! is converted. With the crate's 32-byte binary nodes (the `small_bvh2_node` feature) the build
//! peaks at the conversion, 264 bytes per primitive (obvhs's conversion keeps 7 cost
//! decisions of 8 bytes per binary node, 112 bytes per primitive, and reserves a wide node of 80
//! bytes per primitive).

use obvhs::{
    BvhBuildParams,
    aabb::Aabb,
    bvh2::{Bvh2, reinsertion::ReinsertionOptimizer},
    cwbvh::{CwBvh, bvh2_to_cwbvh::bvh2_to_cwbvh},
    ploc::PlocBuilder,
};

/// The CWBVH over `aabbs` (one primitive each, leaves of at most three), consuming the boxes.
pub(super) fn cwbvh(aabbs: Vec<Aabb>) -> CwBvh {
    let params = BvhBuildParams::medium_build();
    let mut bvh2 = Bvh2::default();
    let indices = (0..aabbs.len() as u32).collect();
    // `PlocBuilder::new`, not `with_capacity`: the latter reserves 32 bytes of sort keys per
    // primitive where the 64-bit sort uses 16.
    PlocBuilder::new().build_with_bvh(
        &mut bvh2,
        params.ploc_search_distance,
        &aabbs,
        indices,
        params.sort_precision,
        params.search_depth_threshold,
    );
    drop(aabbs);
    ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
    bvh2.parents = Vec::new();
    bvh2_to_cwbvh(&bvh2, params.max_prims_per_leaf.clamp(1, 3), true, false)
}
