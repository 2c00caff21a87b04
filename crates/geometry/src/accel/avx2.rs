//! The AVX2 kernel: a node's eight child boxes and a block's eight triangles tested in one
//! 256-bit pass each, with exactly the scalar kernel's float operations (no FMA; the same
//! operand order, min/max included), so both give the same bits. Used only when the CPU
//! reports AVX2 (and the bit-counting POPCNT, BMI1 and LZCNT that come with it), checked once
//! when the [`super::Accel`] is built.
//!
//! The entry points are `#[target_feature(enable = "avx2,popcnt,bmi1,lzcnt")]` functions around
//! the generic traversal, so the whole loop is compiled for them and the kernel's intrinsics
//! inline into it.
#![allow(unsafe_code)]

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

use super::prims::REL_T_MIN;
use super::wide::{
    Entries, Found, Kernel, NODE_EPSILON, Node, TRay, TriBlock, TriHit, Wide, any, closest,
};

/// The AVX2 kernel (x86-64 only).
#[derive(Debug)]
pub(super) struct Avx2;

#[inline(always)]
fn splat(x: f32) -> __m256 {
    // SAFETY: AVX is implied by AVX2, which the callers' `target_feature` guarantees.
    unsafe { _mm256_set1_ps(x) }
}

#[inline(always)]
fn load(x: &[f32; 8]) -> __m256 {
    // SAFETY: the rows of a `TriBlock` (32-byte aligned) and of a `Node`'s boxes (at the start of
    // a 64-byte aligned node, 32 bytes each) are 32-byte aligned arrays of eight floats.
    unsafe { _mm256_load_ps(x.as_ptr()) }
}

/// The triangle distances and barycentrics `(u, v)` of a block (Möller–Trumbore, the scalar
/// test's operations lane by lane) and the mask of the `lanes` hit with `0 < t < t_max`; `None`
/// when none is. Once the first barycentric has been tested, a block whose asked-for lanes have
/// all failed returns at once (most leaf tests on a ray's way miss every triangle): the second
/// half of the test is skipped, the answer is the same.
#[inline(always)]
fn block_t(
    b: &TriBlock,
    r: &TRay,
    t_max: f32,
    lanes: u32,
) -> Option<(__m256, __m256, __m256, u32)> {
    // SAFETY: arithmetic intrinsics only; AVX2 is guaranteed by the callers.
    unsafe {
        let (ox, oy, oz) = (splat(r.o.x), splat(r.o.y), splat(r.o.z));
        let (dx, dy, dz) = (splat(r.d.x), splat(r.d.y), splat(r.d.z));
        let v = &b.v;
        let (v0x, v0y, v0z) = (load(&v[0]), load(&v[1]), load(&v[2]));
        let (e1x, e1y, e1z) = (load(&v[3]), load(&v[4]), load(&v[5]));
        let (e2x, e2y, e2z) = (load(&v[6]), load(&v[7]), load(&v[8]));
        // (Plain `_mm256_*` calls or `#[inline(always)]` functions: a closure would be compiled
        // without AVX2 and every intrinsic in it would become a call.)
        use {_mm256_add_ps as add, _mm256_mul_ps as mul, _mm256_sub_ps as sub};
        // glam's `a.cross(b)`: (a.y·b.z − b.y·a.z, a.z·b.x − b.z·a.x, a.x·b.y − b.x·a.y);
        // `a.dot(b)`: (a.x·b.x + a.y·b.y) + a.z·b.z.
        let px = sub(mul(dy, e2z), mul(e2y, dz));
        let py = sub(mul(dz, e2x), mul(e2z, dx));
        let pz = sub(mul(dx, e2y), mul(e2x, dy));
        let det = add(add(mul(e1x, px), mul(e1y, py)), mul(e1z, pz));
        let abs = _mm256_andnot_ps(splat(-0.0), det);
        let mut ok = _mm256_cmp_ps::<_CMP_NLT_UQ>(abs, splat(f32::MIN_POSITIVE));
        let inv_det = _mm256_div_ps(splat(1.0), det);
        let (tx, ty, tz) = (sub(ox, v0x), sub(oy, v0y), sub(oz, v0z));
        let u = mul(add(add(mul(tx, px), mul(ty, py)), mul(tz, pz)), inv_det);
        ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_GE_OQ>(u, splat(0.0)));
        ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_LE_OQ>(u, splat(1.0)));
        if _mm256_movemask_ps(ok) as u32 & lanes == 0 {
            return None;
        }
        let qx = sub(mul(ty, e1z), mul(e1y, tz));
        let qy = sub(mul(tz, e1x), mul(e1z, tx));
        let qz = sub(mul(tx, e1y), mul(e1x, ty));
        let vv = mul(add(add(mul(dx, qx), mul(dy, qy)), mul(dz, qz)), inv_det);
        let out = _mm256_or_ps(
            _mm256_cmp_ps::<_CMP_LT_OQ>(vv, splat(0.0)),
            _mm256_cmp_ps::<_CMP_GT_OQ>(add(u, vv), splat(1.0)),
        );
        ok = _mm256_andnot_ps(out, ok);
        let t = mul(add(add(mul(e2x, qx), mul(e2y, qy)), mul(e2z, qz)), inv_det);
        // t > REL_T_MIN · max|o − v0| (glam's `max_element`: max(max(x, y), z)).
        let sign = splat(-0.0);
        let (ax, ay, az) = (
            _mm256_andnot_ps(sign, tx),
            _mm256_andnot_ps(sign, ty),
            _mm256_andnot_ps(sign, tz),
        );
        let t_min = mul(_mm256_max_ps(_mm256_max_ps(ax, ay), az), splat(REL_T_MIN));
        ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_GT_OQ>(t, t_min));
        ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_LT_OQ>(t, splat(t_max)));
        let hit = _mm256_movemask_ps(ok) as u32 & lanes;
        (hit != 0).then_some((t, u, vv, hit))
    }
}

/// The entry and exit distances of the eight child slabs along `axis`.
#[inline(always)]
fn slab(n: &Node, r: &TRay, axis: usize, o: f32, inv: f32, inv_far: f32) -> (__m256, __m256) {
    let (lo, hi) = (load(&n.b[2 * axis]), load(&n.b[2 * axis + 1]));
    let (near, far) = if r.neg[axis] { (hi, lo) } else { (lo, hi) };
    let (o, inv, inv_far) = (splat(o), splat(inv), splat(inv_far));
    // SAFETY: arithmetic intrinsics only; AVX2 is guaranteed by the callers.
    unsafe {
        (
            _mm256_mul_ps(_mm256_sub_ps(near, o), inv),
            _mm256_mul_ps(_mm256_sub_ps(far, o), inv_far),
        )
    }
}

impl Kernel for Avx2 {
    #[inline(always)]
    fn node_hits(n: &Node, r: &TRay, t_lim: f32) -> (u32, [f32; 8]) {
        let (o, inv, far) = (r.o.to_array(), r.inv_d.to_array(), r.inv_far.to_array());
        let (x0, x1) = slab(n, r, 0, o[0], inv[0], far[0]);
        let (y0, y1) = slab(n, r, 1, o[1], inv[1], far[1]);
        let (z0, z1) = slab(n, r, 2, o[2], inv[2], far[2]);
        // SAFETY: arithmetic intrinsics only; AVX2 is guaranteed by the callers.
        unsafe {
            // The scalar kernel's order: a NaN distance is always a first operand, passed over.
            let tmin = _mm256_max_ps(
                x0,
                _mm256_max_ps(y0, _mm256_max_ps(z0, splat(NODE_EPSILON))),
            );
            let tmax = _mm256_min_ps(x1, _mm256_min_ps(y1, _mm256_min_ps(z1, splat(t_lim))));
            let mut entry = [0.0f32; 8];
            _mm256_storeu_ps(entry.as_mut_ptr(), tmin);
            (
                _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(tmin, tmax)) as u32,
                entry,
            )
        }
    }

    #[inline(always)]
    fn block_closest(b: &TriBlock, r: &TRay, t_max: f32, lanes: u32) -> Option<TriHit> {
        let (t, u, v, hit) = block_t(b, r, t_max, lanes)?;
        let mut ts = [0.0f32; 8];
        // SAFETY: stores eight floats into an eight-float array.
        unsafe { _mm256_storeu_ps(ts.as_mut_ptr(), t) };
        // Highest lane first, strict `<`: ties go to the highest lane.
        let mut rest = hit;
        let mut best = (f32::INFINITY, 0);
        while rest != 0 {
            let j = 31 - rest.leading_zeros();
            rest &= !(1 << j);
            if ts[j as usize] < best.0 {
                best = (ts[j as usize], j);
            }
        }
        let (mut us, mut vs) = ([0.0f32; 8], [0.0f32; 8]);
        // SAFETY: stores eight floats into eight-float arrays.
        unsafe {
            _mm256_storeu_ps(us.as_mut_ptr(), u);
            _mm256_storeu_ps(vs.as_mut_ptr(), v);
        }
        let j = best.1 as usize;
        Some(TriHit {
            t: best.0,
            lane: best.1,
            u: us[j],
            v: vs[j],
        })
    }

    #[inline(always)]
    fn block_any(b: &TriBlock, r: &TRay, t_max: f32, lanes: u32) -> bool {
        block_t(b, r, t_max, lanes).is_some()
    }
}

/// [`closest`] with the AVX2 kernel.
///
/// # Safety
/// The CPU must support AVX2, POPCNT, BMI1 and LZCNT.
#[target_feature(enable = "avx2,popcnt,bmi1,lzcnt")]
pub(super) unsafe fn closest_avx2(
    w: &Wide,
    r: &TRay,
    t_max: f32,
    stack: &mut [(u32, f32)],
    entries: &impl Entries,
) -> Option<Found> {
    closest::<Avx2>(w, r, t_max, stack, entries)
}

/// [`any`] with the AVX2 kernel.
///
/// # Safety
/// The CPU must support AVX2, POPCNT, BMI1 and LZCNT.
#[target_feature(enable = "avx2,popcnt,bmi1,lzcnt")]
pub(super) unsafe fn any_avx2(
    w: &Wide,
    r: &TRay,
    t_max: f32,
    stack: &mut [(u32, u32)],
    entries: &impl Entries,
) -> bool {
    any::<Avx2>(w, r, t_max, stack, entries)
}

/// The AVX2 node test alone, for the tests that hold it to the scalar one.
///
/// # Safety
/// The CPU must support AVX2, POPCNT, BMI1 and LZCNT.
#[cfg(test)]
#[target_feature(enable = "avx2,popcnt,bmi1,lzcnt")]
pub(super) unsafe fn node_hits_avx2(n: &Node, r: &TRay, t_lim: f32) -> (u32, [f32; 8]) {
    Avx2::node_hits(n, r, t_lim)
}
