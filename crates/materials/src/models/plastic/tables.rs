//! The tables of Mitsuba 3's `roughplastic`: the transmittance of the rough dielectric coating
//! into the base, `T(cos θ)`, and the hemispherical reflectance of its inside, `R_int`, both
//! integrated numerically when the material is made (Mitsuba's `parameters_changed` with
//! `eval_transmittance`/`eval_reflectance`, see `shared/MATERIALS.md` §4.3).
//!
//! The tables depend on (distribution, α, η) only. They are built once per distinct triple and
//! kept for the life of the process in a small registry, so that [`crate::Bsdf`] stays `Copy`
//! and holds a `&'static` reference; a program may also keep them on disk between runs
//! ([`super::cache`]).

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

use glam::{Vec2, Vec3};

use crate::fresnel::{fresnel_dielectric, reflect, refract};
use crate::microfacet::{Distribution, Microfacet};

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

/// `(Σ_ij w_i w_j / 4 · g(m_ij))` over visible normals `m_ij` sampled from `v` at the mapped
/// Gauss–Legendre nodes: the integral over the unit square of `g` along the VNDF sampler.
fn integrate_vndf(mf: &Microfacet, v: Vec3, nodes: &[(f64, f64)], g: impl Fn(Vec3) -> f64) -> f64 {
    let mut sum = 0.0;
    for &(xi, wi) in nodes {
        for &(xj, wj) in nodes {
            let u = Vec2::new((0.5 * (xi + 1.0)) as f32, (0.5 * (xj + 1.0)) as f32);
            if let Some(m) = mf.sample(v, u) {
                sum += 0.25 * wi * wj * g(m);
            }
        }
    }
    sum
}

fn build(distribution: Distribution, alpha: f32, eta: f32) -> RoughPlasticTable {
    let mf = Microfacet::new(distribution, alpha);
    let order = |e: f32| if e > 1.0 { 32 } else { 128 };
    let nodes_t = gauss_legendre(order(eta));
    let nodes_r = gauss_legendre(order(1.0 / eta));
    // Row k: (T(μ_k), R(μ_k)·μ_k).
    let row = |k: usize| -> (f32, f64) {
        let mu = (k as f32 / (TABLE_RES - 1) as f32).max(1e-6);
        let v = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
        // Transmission through the interface from outside (relative IOR η).
        let t = integrate_vndf(&mf, v, &nodes_t, |m| {
            let f = fresnel_dielectric(v.dot(m), eta);
            let wt = refract(v, m, f.cos_theta_t, f.eta_ti);
            if wt.z < 0.0 {
                (mf.g1(wt, m) * (1.0 - f.r)) as f64
            } else {
                0.0
            }
        }) as f32;
        // Reflection at the interface from inside (relative IOR 1/η).
        let r = integrate_vndf(&mf, v, &nodes_r, |m| {
            let f = fresnel_dielectric(v.dot(m), 1.0 / eta);
            let wr = reflect(v, m);
            if wr.z > 0.0 {
                (mf.g1(wr, m) * f.r) as f64
            } else {
                0.0
            }
        });
        (t, r * mu as f64)
    };
    // The rows are independent: spread them over the cores (loading a scene waits for this).
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(TABLE_RES);
    let mut rows = vec![(0.0f32, 0.0f64); TABLE_RES];
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
    let table = super::cache::load(distribution, alpha, eta).unwrap_or_else(|| {
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

    /// MATERIALS.md §4.3 checkpoints (Mitsuba 3.9.1 values; η = 1.49/1.000277). Our quadrature
    /// nodes go through our own concentric-disk and Beckmann samplers, so we match to ~1e-4, not
    /// to Mitsuba's 1e-6.
    #[test]
    fn tables_match_mitsuba_checkpoints() {
        let eta = 1.49f32 / 1.000_277;
        let b = rough_plastic_table(Distribution::Beckmann, 0.1, eta);
        let g = rough_plastic_table(Distribution::Ggx, 0.3, eta);
        let close =
            |a: f32, b: f32, what: &str| assert!((a - b).abs() < 5e-4, "{what}: {a} vs {b}");
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
