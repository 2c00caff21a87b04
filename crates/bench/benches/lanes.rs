//! What SIMD lanes gain on a bounce's work besides its rays, one thread.
//!
//! Run with `cargo bench -p restir-bench --bench lanes`. At the Cornell box's camera-ray hits
//! (`scenes/cornell-box.xml`, 64×64, all diffuse, one rectangle light), each benchmark does what
//! the path tracer does at a bounce between its rays: next-event estimation (a light picked by
//! power, a uniform point on it, the diffuse BSDF there, the power heuristic against the BSDF's
//! density) and a cosine-weighted continuation turned into world space.
//!
//! - `general`: the renderer's own calls (`Scene::bsdf`, `LightSet::sample_nee`, `Bsdf::eval`,
//!   `Bsdf::pdf_sa`, `Bsdf::sample`, the shading frame), one receiver at a time.
//! - `scalar`: the same mathematics written for this scene alone (two emissive triangles, a
//!   diffuse albedo per receiver), one receiver at a time: what the general code's dispatch and
//!   data layout cost.
//! - `lanes`: that code again over eight receivers at once (`restir_sampling::lanes::F8`, eight
//!   `f32` lanes that the compiler maps to AVX2 registers; only where the CPU has AVX2 and FMA):
//!   what lanes gain.
//!
//! Both specialised versions are one generic function ([`bounce`]) instantiated for `f32` and
//! for `F8`; its sine and cosine are one polynomial for both. Items are receivers.

#![allow(unsafe_code)] // the AVX2 entry point and its call

use std::ops::{Add, Div, Mul, Sub};
use std::path::Path;

use divan::counter::ItemsCount;
use divan::{Bencher, black_box};
use glam::{Vec2, Vec3};
use restir_lights::NeeSelection;
use restir_sampling::Pcg32;
use restir_sampling::lanes::F8;
use restir_sampling::warp::power_heuristic;
use restir_scene::{Scene, load_desc};

fn main() {
    divan::main();
}

const SIDE: u32 = 64;

/// One receiver: position, normal, albedo, and the bounce's five numbers.
#[derive(Clone, Copy)]
struct Receiver {
    p: Vec3,
    n: Vec3,
    albedo: Vec3,
    si: restir_geometry::SurfaceInteraction,
    wo: Vec3,
    u: [f32; 5],
}

/// The Cornell box's camera-ray hits (each used once per pass over the batch) and its light's
/// two triangles `(v0, e1, e2)` with their normal.
struct Setup {
    scene: Scene,
    receivers: Vec<Receiver>,
    light: [[Vec3; 4]; 2],
    area: f32,
}

fn setup() -> Setup {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml");
    let (mut desc, _) = load_desc(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
    desc.film.width = SIDE;
    desc.film.height = SIDE;
    let scene =
        Scene::build(&desc, path.parent().unwrap(), &path).unwrap_or_else(|e| panic!("{e}"));
    let mut rng = Pcg32::new(3, 0);
    let mut receivers = Vec::new();
    for y in 0..SIDE {
        for x in 0..SIDE {
            let film = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let ray = scene.camera.generate_ray(film, Vec2::splat(0.5));
            let Some(si) = scene.intersect(&ray) else {
                continue;
            };
            if scene.lights.light_on_shape(si.shape).is_some() {
                continue;
            }
            let bsdf = scene.bsdf(&si);
            let albedo = bsdf.eval(Vec3::Z, Vec3::Z) * std::f32::consts::PI;
            receivers.push(Receiver {
                p: si.p,
                n: si.shading.n,
                albedo,
                si,
                wo: -ray.d,
                u: [
                    rng.next_f32(),
                    rng.next_f32(),
                    rng.next_f32(),
                    rng.next_f32(),
                    rng.next_f32(),
                ],
            });
        }
    }
    receivers.truncate(receivers.len() / 8 * 8);
    let mut light = Vec::new();
    let mut area = 0.0;
    for (i, shape) in scene.shapes.iter().enumerate() {
        if scene.lights.light_on_shape(i as u32).is_none() {
            continue;
        }
        let restir_geometry::Shape::Mesh(m) = shape else {
            panic!("the Cornell box's light is a mesh");
        };
        for t in 0..m.triangle_count() {
            let [a, b, c] = m.triangle(t);
            let n = (b - a).cross(c - a);
            area += 0.5 * n.length();
            light.push([a, b - a, c - a, n.normalize()]);
        }
    }
    assert_eq!(light.len(), 2, "the Cornell box's light is one rectangle");
    Setup {
        scene,
        receivers,
        light: [light[0], light[1]],
        area,
    }
}

/// Lane arithmetic: `f32` (one receiver) and `F8` (eight).
trait Lane:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    fn splat(x: f32) -> Self;
    fn sqrt(self) -> Self;
    fn max(self, o: Self) -> Self;
    /// `if a < b { x } else { y }`, per lane.
    fn lt_select(a: Self, b: Self, x: Self, y: Self) -> Self;
}

impl Lane for f32 {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        f32::max(self, o)
    }
    #[inline(always)]
    fn lt_select(a: Self, b: Self, x: Self, y: Self) -> Self {
        if a < b { x } else { y }
    }
}

impl Lane for F8 {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        F8::splat(x)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        F8::sqrt(self)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        F8::max(self, o)
    }
    #[inline(always)]
    fn lt_select(a: Self, b: Self, x: Self, y: Self) -> Self {
        a.lt(b).select(x, y)
    }
}

#[derive(Clone, Copy)]
struct V3<L> {
    x: L,
    y: L,
    z: L,
}

impl<L: Lane> V3<L> {
    #[inline(always)]
    fn splat(v: Vec3) -> Self {
        V3 {
            x: L::splat(v.x),
            y: L::splat(v.y),
            z: L::splat(v.z),
        }
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
    #[inline(always)]
    fn scale(self, s: L) -> Self {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        V3 {
            x: self.x * o.x,
            y: self.y * o.y,
            z: self.z * o.z,
        }
    }
    #[inline(always)]
    fn dot(self, o: Self) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    #[inline(always)]
    fn select(a: L, b: L, x: Self, y: Self) -> Self {
        V3 {
            x: L::lt_select(a, b, x.x, y.x),
            y: L::lt_select(a, b, x.y, y.y),
            z: L::lt_select(a, b, x.z, y.z),
        }
    }
}

/// `sin` and `cos` of `phi ∈ [0, 2π)`: odd and even Taylor polynomials about π (degree 13
/// and 14; error below 3·10⁻⁵, enough for a cost measurement).
#[inline(always)]
fn sincos<L: Lane>(phi: L) -> (L, L) {
    let x = phi - L::splat(std::f32::consts::PI);
    let x2 = x * x;
    let mut s = L::splat(-1.0 / 6_227_020_800.0);
    let mut c = L::splat(1.0 / 87_178_291_200.0);
    for (ks, kc) in [
        (1.0 / 39_916_800.0, -1.0 / 479_001_600.0),
        (-1.0 / 362_880.0, 1.0 / 3_628_800.0),
        (1.0 / 5040.0, -1.0 / 40_320.0),
        (-1.0 / 120.0, 1.0 / 720.0),
        (1.0 / 6.0, -1.0 / 24.0),
        (-1.0, 0.5),
    ] {
        s = s * x2 + L::splat(ks);
        c = c * x2 + L::splat(kc);
    }
    // sin(π + x) = −sin x, cos(π + x) = −cos x.
    (s * x, c * x2 - L::splat(1.0))
}

/// One bounce's work besides its rays at a receiver (or eight): the next-event estimate
/// (visibility left out) and the continuation's world direction and throughput factor.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn bounce<L: Lane>(
    p: V3<L>,
    n: V3<L>,
    albedo: V3<L>,
    u: [L; 5],
    light: &[[Vec3; 4]; 2],
    area: f32,
    le: Vec3,
) -> (V3<L>, V3<L>, V3<L>) {
    let (zero, one, inv_pi) = (
        L::splat(0.0),
        L::splat(1.0),
        L::splat(std::f32::consts::FRAC_1_PI),
    );
    // The light: a triangle by area (they are equal), a uniform point on it.
    let half = L::splat(0.5);
    // (No closure here: one would be compiled without the caller's target features.)
    let v0 = V3::select(u[0], half, V3::splat(light[0][0]), V3::splat(light[1][0]));
    let e1 = V3::select(u[0], half, V3::splat(light[0][1]), V3::splat(light[1][1]));
    let e2 = V3::select(u[0], half, V3::splat(light[0][2]), V3::splat(light[1][2]));
    let nl = V3::select(u[0], half, V3::splat(light[0][3]), V3::splat(light[1][3]));
    let su = u[1].sqrt();
    let (b1, b2) = (one - su, u[2] * su);
    let q = v0.add(e1.scale(b1)).add(e2.scale(b2));
    let d = q.sub(p);
    let d2 = d.dot(d);
    let wi = d.scale(one / d2.sqrt());
    let cos_l = zero - wi.dot(nl);
    let cos_r = wi.dot(n);
    let pdf = d2 / (cos_l.max(L::splat(1e-12)) * L::splat(area));
    let bpdf = cos_r.max(zero) * inv_pi;
    let w = pdf * pdf / (pdf * pdf + bpdf * bpdf);
    let ok = L::lt_select(zero, cos_l, L::lt_select(zero, cos_r, one, zero), zero);
    let direct = albedo.mul(V3::splat(le)).scale(bpdf * w / pdf * ok);
    // The continuation: cosine-weighted about `n` (Duff et al.'s frame), throughput `albedo`.
    let r = u[3].sqrt();
    let (s, c) = sincos(u[4] * L::splat(std::f32::consts::TAU));
    let local = V3 {
        x: r * c,
        y: r * s,
        z: (one - u[3]).max(zero).sqrt(),
    };
    let sign = L::lt_select(n.z, zero, L::splat(-1.0), one);
    let a = zero - one / (sign + n.z);
    let b = n.x * n.y * a;
    let t = V3 {
        x: one + sign * n.x * n.x * a,
        y: sign * b,
        z: zero - sign * n.x,
    };
    let bt = V3 {
        x: b,
        y: sign + n.y * n.y * a,
        z: zero - n.y,
    };
    let dir = t
        .scale(local.x)
        .add(bt.scale(local.y))
        .add(n.scale(local.z));
    (direct, dir, albedo)
}

/// [`bounce`] for one receiver with its numbers `u`.
#[inline(always)]
fn bounce_one(s: &Setup, r: &Receiver, u: [f32; 5]) -> [V3<f32>; 3] {
    let v = |v: Vec3| V3 {
        x: v.x,
        y: v.y,
        z: v.z,
    };
    let (d, dir, beta) = bounce(v(r.p), v(r.n), v(r.albedo), u, &s.light, s.area, Vec3::ONE);
    [d, dir, beta]
}

#[divan::bench]
fn general(bencher: Bencher) {
    let s = setup();
    let lights = &s.scene.lights;
    bencher
        .counter(ItemsCount::new(s.receivers.len()))
        .bench_local(|| {
            let mut acc = Vec3::ZERO;
            for r in &s.receivers {
                let si = &r.si;
                let bsdf = s.scene.bsdf(si);
                let wo = si.shading.to_local(r.wo);
                if bsdf.has_smooth_lobe()
                    && let Some(ls) = lights.sample_nee(
                        NeeSelection::Power,
                        si.p,
                        si.shading.n,
                        (r.u[0], 0.5),
                        Vec2::new(r.u[1], r.u[2]),
                    )
                {
                    let wi = si.shading.to_local(ls.wi);
                    let f = bsdf.eval(wo, wi);
                    if f != Vec3::ZERO {
                        let w = power_heuristic(ls.pdf_sa, bsdf.pdf_sa(wo, wi));
                        acc += f * ls.le * (w / ls.pdf_sa);
                    }
                }
                if let Some(bs) = bsdf.sample(wo, 0.5, Vec2::new(r.u[3], r.u[4])) {
                    acc += si.shading.to_world(bs.wi) + bs.f / bs.pdf_sa;
                }
            }
            black_box(acc)
        });
}

#[divan::bench]
fn scalar(bencher: Bencher) {
    let s = setup();
    bencher
        .counter(ItemsCount::new(s.receivers.len()))
        .bench_local(|| {
            let mut acc = Vec3::ZERO;
            for r in &s.receivers {
                for x in bounce_one(&s, r, r.u) {
                    acc += Vec3::new(x.x, x.y, x.z);
                }
            }
            black_box(acc)
        });
}

/// Eight receivers' inputs in lanes.
struct Group {
    p: V3<F8>,
    n: V3<F8>,
    albedo: V3<F8>,
    u: [F8; 5],
}

fn groups(receivers: &[Receiver]) -> Vec<Group> {
    receivers
        .chunks_exact(8)
        .map(|c| {
            let v = |f: &dyn Fn(&Receiver) -> Vec3| V3 {
                x: F8::from_fn(|i| f(&c[i]).x),
                y: F8::from_fn(|i| f(&c[i]).y),
                z: F8::from_fn(|i| f(&c[i]).z),
            };
            Group {
                p: v(&|r| r.p),
                n: v(&|r| r.n),
                albedo: v(&|r| r.albedo),
                u: std::array::from_fn(|k| F8::from_fn(|i| c[i].u[k])),
            }
        })
        .collect()
}

/// [`bounce`] over every group, compiled for AVX2 and FMA.
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn run_lanes(groups: &[Group], light: &[[Vec3; 4]; 2], area: f32) -> F8 {
    let mut acc = F8::default();
    for g in groups {
        let (d, dir, beta) = bounce(g.p, g.n, g.albedo, g.u, light, area, Vec3::ONE);
        for x in [d, dir, beta] {
            acc = acc + x.x + x.y + x.z;
        }
    }
    acc
}

#[divan::bench]
fn lanes(bencher: Bencher) {
    #[cfg(target_arch = "x86_64")]
    {
        if !(std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")) {
            eprintln!("lanes: this CPU has no AVX2 and FMA; skipped");
            return;
        }
        let s = setup();
        let g = groups(&s.receivers);
        check(&s, &g);
        bencher
            .counter(ItemsCount::new(s.receivers.len()))
            // SAFETY: AVX2 and FMA were detected above.
            .bench_local(|| black_box(unsafe { run_lanes(&g, &s.light, s.area) }));
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = bencher;
        eprintln!("lanes: x86-64 only; skipped");
    }
}

/// Before timing: the lanes give the scalar version's bits, and the specialised next-event
/// estimate has the general code's mean over the receivers (visibility aside, both estimate the
/// same direct light; within 4 standard errors of their difference).
#[cfg(target_arch = "x86_64")]
fn check(s: &Setup, g: &[Group]) {
    for (k, group) in g.iter().enumerate() {
        // SAFETY: the caller detected AVX2 and FMA.
        let lanes = unsafe { run_lanes(std::slice::from_ref(group), &s.light, s.area) };
        for i in 0..8 {
            let r = &s.receivers[8 * k + i];
            let sum = bounce_one(s, r, r.u)
                .iter()
                .fold(0.0f32, |a, x| a + x.x + x.y + x.z);
            assert_eq!(lanes.0[i].to_bits(), sum.to_bits(), "group {k} lane {i}");
        }
    }
    let mut rng = Pcg32::new(9, 0);
    let (mut diff, mut diff2, mut count) = (0.0f64, 0.0f64, 0.0f64);
    for r in &s.receivers {
        for _ in 0..16 {
            let u = [rng.next_f32(), rng.next_f32(), rng.next_f32(), 0.5, 0.5];
            let [d, _, _] = bounce_one(s, r, u);
            let si = &r.si;
            let bsdf = s.scene.bsdf(si);
            let wo = si.shading.to_local(r.wo);
            let mut general = 0.0;
            if let Some(ls) = s.scene.lights.sample_nee(
                NeeSelection::Power,
                si.p,
                si.shading.n,
                (u[0], 0.5),
                Vec2::new(u[1], u[2]),
            ) {
                let wi = si.shading.to_local(ls.wi);
                let f = bsdf.eval(wo, wi);
                if f != Vec3::ZERO {
                    let w = power_heuristic(ls.pdf_sa, bsdf.pdf_sa(wo, wi));
                    // The specialised estimate takes the light's radiance as 1.
                    general = (f * (w / ls.pdf_sa)).element_sum() as f64;
                }
            }
            let x = (d.x + d.y + d.z) as f64 - general;
            diff += x;
            diff2 += x * x;
            count += 1.0;
        }
    }
    let mean = diff / count;
    let se = ((diff2 / count - mean * mean) / count).sqrt();
    assert!(
        mean.abs() <= 4.0 * se + 1e-9,
        "the specialised estimate's mean differs from the general code's by {mean} (s.e. {se})"
    );
}
