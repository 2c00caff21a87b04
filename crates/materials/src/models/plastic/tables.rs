//! The tables of Mitsuba 3's `roughplastic`: the transmittance of the rough dielectric coating
//! into the base, `T(cos θ)`, and the hemispherical reflectance of its inside, `R_int`, both
//! integrated numerically when the material is made (Mitsuba's `parameters_changed` with
//! `eval_transmittance`/`eval_reflectance` in `src/bsdfs/roughplastic.cpp`; Weidlich and Wilkie,
//! "Arbitrarily layered micro-facet surfaces", 2007, for the layered model).
//!
//! Both are `Σ_ij w_i w_j/4 · g(m_ij)` over Gauss–Legendre nodes `u_ij` mapped to normals
//! `m_ij` by the visible-normal sampler, for 64 views (64 × 32² nodes for `T`, 64 × 128² for
//! `R_int`). What of the sampler does not depend on the view is computed once per node, not once
//! per node and view: Beckmann's sampler is separable (its slope `y` is Gaussian in `u_y`, its
//! slope `x` depends on `u_x` and the view only), so a view costs 128 one-dimensional inversions
//! instead of 128²; GGX's concentric-disk point depends on `u` only. What remains per node is
//! arithmetic (normalise, Fresnel, reflect or refract, `G1`), written as straight-line code over
//! a row of nodes that the compiler vectorises (8 lanes with AVX2, detected at run time). Every
//! `m_ij` is bit for bit `Microfacet::sample(v, u_ij)` and the sum runs in the same order, so the
//! tables are those of the direct quadrature, bit for bit, for about a twentieth (Beckmann) or a
//! fifth (GGX) of its CPU time: about 15 ms of one core a table.
//!
//! The tables depend on (distribution, α, η) only. They are built once per distinct triple and
//! kept for the life of the process in a small registry, so that [`crate::Bsdf`] stays `Copy`
//! and holds a `&'static` reference; a program may also keep them on disk between runs
//! ([`super::cache`]).

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

use glam::{Vec2, Vec3};

use crate::fresnel::{fresnel_dielectric, reflect, refract};
use restir_sampling::warp;

use crate::microfacet::{
    Distribution, Microfacet, StretchedView, beckmann_slope_x, beckmann_slope_y, ggx_disk_chord,
    ggx_slopes_from_disk,
};

/// Number of `cos θ` nodes of the transmittance table (Mitsuba's `MI_ROUGH_TRANSMITTANCE_RES`).
pub const TABLE_RES: usize = 64;

/// The precomputed coating terms of a rough plastic.
#[derive(Debug, PartialEq)]
pub struct RoughPlasticTable {
    /// `T(μ_k)` at `μ_k = max(1e-6, k/63)`: albedo of the rough interface's transmission lobe.
    pub transmittance: [f32; TABLE_RES],
    /// Hemispherical-cosine average of the interface's reflectance from inside (`2∫R(μ)μ dμ`).
    pub internal_reflectance: f32,
}

impl RoughPlasticTable {
    /// Integrates the table for (distribution, α, η) now, on every core the process may run on,
    /// without the process's registry or the disk cache: what [`rough_plastic_table`] does when
    /// neither has it (for benchmarks and checks; materials should share tables through
    /// [`rough_plastic_table`]).
    pub fn compute(distribution: Distribution, alpha: f32, eta: f32) -> Self {
        build(distribution, alpha, eta)
    }

    /// `T(cos θ)` by linear interpolation in the table (Mitsuba's `lerp_gather`).
    #[inline]
    pub fn transmittance_at(&self, cos_theta: f32) -> f32 {
        let x = cos_theta.clamp(0.0, 1.0) * (TABLE_RES - 1) as f32;
        let i = (x as usize).min(TABLE_RES - 2);
        let t = &self.transmittance;
        t[i] + (x - i as f32) * (t[i + 1] - t[i])
    }
}

/// Gauss–Legendre nodes and weights of order `n` on `[−1, 1]` (Newton's method on the Legendre
/// recurrence, started from Tricomi's estimate of the roots).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (core::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0f64, x);
            for k in 2..=n {
                let k = k as f64;
                let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 0 { 1.0 } else { p1 };
            let pn1 = if n == 0 { 0.0 } else { p0 };
            dp = n as f64 * (x * pn - pn1) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() < 1e-15 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out.push((x, w));
    }
    out
}

/// Gauss–Legendre nodes mapped to `[0, 1]` and prepared for the visible-normal sampler: the part
/// of `Microfacet::sample(v, u_ij)` at `u_ij = ((x_i + 1)/2, (x_j + 1)/2)` that does not depend
/// on the view `v`, computed once for all 64 views of a table.
struct Nodes {
    /// `(x_i, w_i)` on `[−1, 1]`.
    gl: Vec<(f64, f64)>,
    grid: NodeGrid,
}

enum NodeGrid {
    /// Beckmann's sampler is separable: slope `x` from `u_x` and the view, slope `y` from `u_y`
    /// alone. Holds `u_x` per node and slope `y` per node.
    Beckmann { ux: Vec<f32>, sy: Vec<f32> },
    /// GGX's starts from the concentric-disk point `p` of `u`: `p.x`, `p.y` and the half chord
    /// `√(1 − p.x²)` per node pair, row-major.
    Ggx {
        x: Vec<f32>,
        y: Vec<f32>,
        chord: Vec<f32>,
    },
}

impl Nodes {
    fn new(distribution: Distribution, order: usize) -> Self {
        let gl = gauss_legendre(order);
        let u: Vec<f32> = gl.iter().map(|&(x, _)| (0.5 * (x + 1.0)) as f32).collect();
        let grid = match distribution {
            Distribution::Beckmann => NodeGrid::Beckmann {
                sy: u.iter().map(|&y| beckmann_slope_y(y)).collect(),
                ux: u,
            },
            Distribution::Ggx => {
                let disk: Vec<Vec2> = u
                    .iter()
                    .flat_map(|&x| {
                        u.iter()
                            .map(move |&y| warp::sample_concentric_disk(Vec2::new(x, y)))
                    })
                    .collect();
                NodeGrid::Ggx {
                    x: disk.iter().map(|p| p.x).collect(),
                    y: disk.iter().map(|p| p.y).collect(),
                    chord: disk.iter().map(|p| ggx_disk_chord(p.x)).collect(),
                }
            }
        };
        Self { gl, grid }
    }

    /// The nodes for an interface of relative IOR `eta` as seen from the view: Mitsuba's order
    /// 32 if `eta > 1`, else 128 (total internal reflection makes the integrand rougher). Made
    /// once per process: they depend on neither α nor η beyond that choice.
    fn for_eta(distribution: Distribution, eta: f32) -> &'static Nodes {
        static NODES: [[OnceLock<Nodes>; 2]; 2] = [
            [OnceLock::new(), OnceLock::new()],
            [OnceLock::new(), OnceLock::new()],
        ];
        let d = match distribution {
            Distribution::Beckmann => 0,
            Distribution::Ggx => 1,
        };
        let (o, order) = if eta > 1.0 { (0, 32) } else { (1, 128) };
        NODES[d][o].get_or_init(|| Nodes::new(distribution, order))
    }
}

/// What is integrated along the visible normals of a view `v`.
#[derive(Clone, Copy, Debug)]
enum Lobe {
    /// `G1(wt, m)·(1 − F(v·m, η))` for the refracted `wt` (0 unless it goes down).
    Transmit,
    /// `G1(wr, m)·F(v·m, η)` for the reflected `wr` (0 unless it goes up).
    Reflect,
}

/// The integrand at the normal `m` (`eta` is the relative IOR seen from `v`'s side).
#[inline(always)]
fn integrand(lobe: Lobe, mf: &Microfacet, v: Vec3, eta: f32, m: Vec3) -> f32 {
    let f = fresnel_dielectric(v.dot(m), eta);
    match lobe {
        Lobe::Transmit => {
            let wt = refract(v, m, f.cos_theta_t, f.eta_ti);
            if wt.z < 0.0 {
                mf.g1(wt, m) * (1.0 - f.r)
            } else {
                0.0
            }
        }
        Lobe::Reflect => {
            let wr = reflect(v, m);
            if wr.z > 0.0 { mf.g1(wr, m) * f.r } else { 0.0 }
        }
    }
}

/// The integrand at the nodes `(i, j)` of row `i`, `j = 0..n`, into `out` (0 where the sampler
/// fails, which the sum then skips). Straight-line code over `j`, so that the compiler
/// vectorises it; every lane computes what the scalar code does, bit for bit.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn row_terms(
    lobe: Lobe,
    mf: &Microfacet,
    view: &StretchedView,
    v: Vec3,
    eta: f32,
    nodes: &Nodes,
    i: usize,
    out: &mut [f32],
) {
    #[inline(always)]
    fn value(lobe: Lobe, mf: &Microfacet, v: Vec3, eta: f32, m: Vec3) -> f32 {
        let ok = m.x.is_finite() & m.y.is_finite() & m.z.is_finite();
        if ok {
            integrand(lobe, mf, v, eta, m)
        } else {
            0.0
        }
    }
    match &nodes.grid {
        NodeGrid::Beckmann { ux, sy } => {
            let sx = beckmann_slope_x(view.cos_theta, ux[i]);
            for (o, &sy) in out.iter_mut().zip(sy) {
                *o = value(lobe, mf, v, eta, view.normal_unchecked(Vec2::new(sx, sy)));
            }
        }
        NodeGrid::Ggx { x, y, chord } => {
            let row = i * out.len()..(i + 1) * out.len();
            let (x, y, chord) = (&x[row.clone()], &y[row.clone()], &chord[row]);
            for (j, o) in out.iter_mut().enumerate() {
                let p = Vec2::new(x[j], y[j]);
                let m = view.normal_unchecked(ggx_slopes_from_disk(view.cos_theta, p, chord[j]));
                *o = value(lobe, mf, v, eta, m);
            }
        }
    }
}

/// [`row_terms`] compiled for AVX2 (8 lanes; the same bits, since only IEEE-exact operations
/// are vectorised and nothing is fused).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
fn row_terms_avx2(
    lobe: Lobe,
    mf: &Microfacet,
    view: &StretchedView,
    v: Vec3,
    eta: f32,
    nodes: &Nodes,
    i: usize,
    out: &mut [f32],
) {
    row_terms(lobe, mf, view, v, eta, nodes, i, out);
}

/// `(Σ_ij w_i w_j / 4 · g(m_ij))` over visible normals `m_ij` sampled from `v` at the mapped
/// Gauss–Legendre nodes: the integral over the unit square of the [`integrand`] along the VNDF
/// sampler. Each `m_ij` is bit for bit `mf.sample(v, u_ij)`, from the view-independent parts in
/// `nodes`, and the sum runs in the order `i`, then `j`, in `f64`.
fn integrate_vndf(
    lobe: Lobe,
    mf: &Microfacet,
    v: Vec3,
    eta: f32,
    nodes: &Nodes,
    avx2: bool,
) -> f64 {
    let Some(view) = mf.stretched_view(v) else {
        return 0.0;
    };
    let mut terms = vec![0.0f32; nodes.gl.len()];
    let mut sum = 0.0;
    for (i, &(_, wi)) in nodes.gl.iter().enumerate() {
        #[cfg(target_arch = "x86_64")]
        if avx2 {
            #[allow(unsafe_code)]
            // SAFETY: `avx2` is true only if the CPU has AVX2 (`is_x86_feature_detected!`).
            unsafe {
                row_terms_avx2(lobe, mf, &view, v, eta, nodes, i, &mut terms)
            };
        } else {
            row_terms(lobe, mf, &view, v, eta, nodes, i, &mut terms);
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = avx2;
            row_terms(lobe, mf, &view, v, eta, nodes, i, &mut terms);
        }
        for (&(_, wj), &g) in nodes.gl.iter().zip(&terms) {
            sum += 0.25 * wi * wj * g as f64;
        }
    }
    sum
}

/// Whether [`row_terms_avx2`] may run on this CPU.
fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `μ_k` and the view of table row `k`.
fn view(k: usize) -> (f32, Vec3) {
    let mu = (k as f32 / (TABLE_RES - 1) as f32).max(1e-6);
    (mu, Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu))
}

/// Whether `t`, read from outside the process (the disk cache), can be the table of
/// (distribution, α, η), checked against the integrals themselves so that a file crafted with a
/// valid checksum can change neither lobe:
///
/// - every value in [0, 1];
/// - every transmittance row integrated again, with the build's nodes, and equal within 10⁻⁵
///   (for η > 1 the cheaper integral: 32² nodes a row, about 6 % of a build);
/// - `R_int` integrated again, with the build's nodes where they are 32² a row (η < 1), else
///   with 64² instead of 128² (a quarter of its cost), and within `0.02 · (1 − R_int)` of that:
///   the diffuse scale `1/(1 − ρ·R_int)` is then within about 2 % of the built table's. The
///   coarser quadrature's own error is below 0.3 % of `1 − R_int` up to η = 3 and 1.2 % at
///   η = 4 (both distributions, α from 0.001 to 1); beyond that it may refuse an honest table,
///   which costs a rebuild, never a wrong table.
///
/// The cost is about 30 % of a build for η > 1 (the check of `T` at η < 1 is most of one),
/// spread over the cores as a build is.
/// `R_int ≤ 1 − T̄/η²` (energy conservation with reciprocity, `T̄ = 2∫T(μ)μ dμ`) is checked
/// first, as the cheap refusal of an `R_int` near 1, which would scale the diffuse base by
/// `1/(1 − R_int)` as much as it likes.
pub(super) fn plausible(
    distribution: Distribution,
    alpha: f32,
    eta: f32,
    t: &RoughPlasticTable,
) -> bool {
    let unit = |v: f32| (0.0..=1.0).contains(&v);
    if !(t.transmittance.iter().all(|&v| unit(v)) && unit(t.internal_reflectance)) {
        return false;
    }
    // The cosine average by the trapezoid rule over the rows (μ_k = k/63); its error at 64
    // nodes is far inside the margin.
    let h = 1.0 / (TABLE_RES - 1) as f64;
    let tmu = |k: usize| t.transmittance[k] as f64 * k as f64 * h;
    let mean = 2.0 * h * ((1..TABLE_RES - 1).map(tmu).sum::<f64>() + 0.5 * tmu(TABLE_RES - 1));
    let eta2 = (eta as f64) * (eta as f64);
    if t.internal_reflectance as f64 > 1.0 - mean / eta2 + 0.02 {
        return false;
    }
    let mf = Microfacet::new(distribution, alpha);
    let avx2 = has_avx2();
    let nodes_t = Nodes::for_eta(distribution, eta);
    let rows_ok = in_parallel(|k| {
        let v = integrate_vndf(Lobe::Transmit, &mf, view(k).1, eta, nodes_t, avx2) as f32;
        (v - t.transmittance[k]).abs() <= 1e-5
    });
    if !rows_ok.into_iter().all(|ok| ok) {
        return false;
    }
    let built = Nodes::for_eta(distribution, 1.0 / eta);
    let exact = built.gl.len() <= 32;
    let coarse = (!exact).then(|| Nodes::new(distribution, 64));
    let nodes_r = coarse.as_ref().unwrap_or(built);
    let r_sum: f64 = in_parallel(|k| {
        let (mu, v) = view(k);
        integrate_vndf(Lobe::Reflect, &mf, v, 1.0 / eta, nodes_r, avx2) * mu as f64
    })
    .into_iter()
    .sum();
    let r_int = 2.0 * r_sum / TABLE_RES as f64;
    let tolerance = if exact { 1e-5 } else { 0.02 * (1.0 - r_int) };
    (t.internal_reflectance as f64 - r_int).abs() <= tolerance
}

/// `row(k)` for every row `k` of a table, in order. The rows are independent: they are spread
/// over the cores (loading a scene waits for this).
fn in_parallel<R: Copy + Default + Send>(row: impl Fn(usize) -> R + Sync) -> Vec<R> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(TABLE_RES);
    let mut rows = vec![R::default(); TABLE_RES];
    std::thread::scope(|s| {
        let chunk = TABLE_RES.div_ceil(threads);
        for (c, out) in rows.chunks_mut(chunk).enumerate() {
            let row = &row;
            s.spawn(move || {
                for (i, slot) in out.iter_mut().enumerate() {
                    *slot = row(c * chunk + i);
                }
            });
        }
    });
    rows
}

fn build(distribution: Distribution, alpha: f32, eta: f32) -> RoughPlasticTable {
    build_with(distribution, alpha, eta, has_avx2())
}

fn build_with(distribution: Distribution, alpha: f32, eta: f32, avx2: bool) -> RoughPlasticTable {
    let mf = Microfacet::new(distribution, alpha);
    let nodes_t = Nodes::for_eta(distribution, eta);
    let nodes_r = Nodes::for_eta(distribution, 1.0 / eta);
    // Row k: (T(μ_k), R(μ_k)·μ_k).
    let row = |k: usize| -> (f32, f64) {
        let (mu, v) = view(k);
        // Transmission through the interface from outside (relative IOR η).
        let t = integrate_vndf(Lobe::Transmit, &mf, v, eta, nodes_t, avx2) as f32;
        // Reflection at the interface from inside (relative IOR 1/η).
        let r = integrate_vndf(Lobe::Reflect, &mf, v, 1.0 / eta, nodes_r, avx2);
        (t, r * mu as f64)
    };
    let rows = in_parallel(row);
    let mut transmittance = [0.0f32; TABLE_RES];
    for (t, r) in transmittance.iter_mut().zip(&rows) {
        *t = r.0;
    }
    let r_sum: f64 = rows.iter().map(|r| r.1).sum();
    RoughPlasticTable {
        transmittance,
        internal_reflectance: (2.0 * r_sum / TABLE_RES as f64) as f32,
    }
}

type Key = (Distribution, u32, u32);

/// The table for (distribution, α, η), built on first use and shared afterwards.
pub fn rough_plastic_table(
    distribution: Distribution,
    alpha: f32,
    eta: f32,
) -> &'static RoughPlasticTable {
    static TABLES: OnceLock<Mutex<HashMap<Key, &'static RoughPlasticTable>>> = OnceLock::new();
    let key = (distribution, alpha.to_bits(), eta.to_bits());
    let tables = TABLES.get_or_init(|| Mutex::new(HashMap::new()));
    if let Some(t) = tables.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return t;
    }
    // Built outside the lock (it takes a moment); a racing thread may build it twice.
    let table = super::cache::load(distribution, alpha, eta)
        .filter(|t| plausible(distribution, alpha, eta, t))
        .unwrap_or_else(|| {
            let t = build(distribution, alpha, eta);
            super::cache::store(distribution, alpha, eta, &t);
            t
        });
    let table: &'static RoughPlasticTable = Box::leak(Box::new(table));
    let mut guard = tables.lock().unwrap_or_else(|e| e.into_inner());
    let stored: &&'static RoughPlasticTable = guard.entry(key).or_insert(table);
    stored
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials() {
        for n in [1usize, 2, 5, 32, 128] {
            let nodes = gauss_legendre(n);
            let sum: f64 = nodes.iter().map(|p| p.1).sum();
            assert!((sum - 2.0).abs() < 1e-12, "{n}: {sum}");
            // Exact up to degree 2n − 1: ∫ x^(2n−2) = 2/(2n−1).
            let d = 2 * n as i32 - 2;
            let s: f64 = nodes.iter().map(|&(x, w)| w * x.powi(d)).sum();
            assert!((s - 2.0 / (d as f64 + 1.0)).abs() < 1e-10, "{n}: {s}");
        }
    }

    /// The integral as first written: every node through [`Microfacet::sample`], the integrand
    /// by the same functions, summed in the same order.
    fn integrate_naive(lobe: Lobe, mf: &Microfacet, v: Vec3, eta: f32, order: usize) -> f64 {
        let nodes = gauss_legendre(order);
        let mut sum = 0.0;
        for &(xi, wi) in &nodes {
            for &(xj, wj) in &nodes {
                let u = Vec2::new((0.5 * (xi + 1.0)) as f32, (0.5 * (xj + 1.0)) as f32);
                if let Some(m) = mf.sample(v, u) {
                    sum += 0.25 * wi * wj * integrand(lobe, mf, v, eta, m) as f64;
                }
            }
        }
        sum
    }

    /// The separable, vectorised quadrature is the sampler's, bit for bit: against the naive
    /// integral on a spread of rows (normal and grazing views included), for both distributions
    /// and both lobes, with the scalar kernel and with the one this CPU runs (AVX2 where it has
    /// it).
    #[test]
    fn fast_quadrature_is_the_naive_one_bit_for_bit() {
        let eta = 1.49f32 / 1.000_277;
        for (distribution, alpha) in [
            (Distribution::Beckmann, 0.1),
            (Distribution::Beckmann, 0.7),
            (Distribution::Ggx, 0.3),
            (Distribution::Ggx, 0.02),
        ] {
            let mf = Microfacet::new(distribution, alpha);
            for (lobe, eta, order) in [(Lobe::Transmit, eta, 32), (Lobe::Reflect, 1.0 / eta, 128)] {
                let nodes = Nodes::new(distribution, order);
                for k in [0usize, 1, 9, 31, 50, 62, 63] {
                    let mu = (k as f32 / 63.0).max(1e-6);
                    let v = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
                    let want = integrate_naive(lobe, &mf, v, eta, order);
                    for avx2 in [false, has_avx2()] {
                        let got = integrate_vndf(lobe, &mf, v, eta, &nodes, avx2);
                        assert_eq!(
                            got.to_bits(),
                            want.to_bits(),
                            "{distribution:?} α {alpha} {lobe:?} k {k} avx2 {avx2}: {got} vs {want}"
                        );
                    }
                }
            }
        }
    }

    /// Whole tables: the scalar kernel and this CPU's agree bit for bit.
    #[test]
    fn scalar_and_vector_tables_agree() {
        let eta = 1.5f32;
        for (d, a) in [(Distribution::Beckmann, 0.2), (Distribution::Ggx, 0.15)] {
            assert_eq!(
                build_with(d, a, eta, false),
                build_with(d, a, eta, has_avx2())
            );
        }
    }

    /// MATERIALS.md §4.3 checkpoints (Mitsuba 3.9.1 values, given to 6 decimals; η =
    /// 1.49/1.000277): every value agrees to 1e-6 (the largest difference is 6.6e-7, T(0) of
    /// the Beckmann table).
    #[test]
    fn tables_match_mitsuba_checkpoints() {
        let eta = 1.49f32 / 1.000_277;
        let b = rough_plastic_table(Distribution::Beckmann, 0.1, eta);
        let g = rough_plastic_table(Distribution::Ggx, 0.3, eta);
        let close =
            |a: f32, b: f32, what: &str| assert!((a - b).abs() < 1e-6, "{what}: {a} vs {b}");
        close(b.internal_reflectance, 0.574_663, "beckmann R_int");
        close(b.transmittance[0], 0.370_129, "beckmann T(0)");
        close(b.transmittance[63], 0.961_324, "beckmann T(1)");
        close(b.transmittance_at(0.5), 0.910_767, "beckmann t(0.5)");
        close(g.internal_reflectance, 0.408_760, "ggx R_int");
        close(g.transmittance[0], 0.636_037, "ggx T(0)");
        close(g.transmittance[63], 0.954_541, "ggx T(1)");
        close(g.transmittance_at(0.5), 0.887_868, "ggx t(0.5)");
        // Cached: the same table comes back.
        assert!(core::ptr::eq(
            b,
            rough_plastic_table(Distribution::Beckmann, 0.1, eta)
        ));
    }
}
