//! Benchmarks of the `restir-gris` core: nanoseconds per streaming `add`, per stream `merge`, and
//! per k-neighbour GRIS resampling step (k = 3, 5).
//!
//! Run with `cargo bench -p restir-bench --bench gris`. The `add` and `merge` benchmarks process
//! `BATCH` items per iteration (divan prints the time per iteration and the item throughput);
//! divide the time by `BATCH` for nanoseconds per operation. The resampling benchmarks time one
//! complete step per iteration with a cheap analytic shift map, so they measure the resampling
//! and MIS bookkeeping rather than a renderer's shift.

use divan::counter::ItemsCount;
use divan::{Bencher, black_box};
use restir_gris::{
    GrisInput, GrisResampler, MisScheme, Reservoir, ShiftMap, Shifted, StreamingReservoir, mis,
    resample,
};
// SplitMix64 from the test kit, for reproducible inputs.
use restir_testkit::SplitMix64 as Rng;

fn main() {
    divan::main();
}

const BATCH: usize = 1024;

/// A light-sample-sized payload (`light` is carried, as in a renderer, but not read here).
#[derive(Clone, Copy, Debug)]
#[allow(dead_code)]
struct LightSample {
    position: [f32; 3],
    light: u32,
}

fn candidates(seed: u64) -> Vec<(LightSample, f32, f32)> {
    let mut rng = Rng::new(seed);
    (0..BATCH)
        .map(|i| {
            let s = LightSample {
                position: [rng.next_f32(), rng.next_f32(), rng.next_f32()],
                light: i as u32,
            };
            (s, rng.next_f32() * 2.0, rng.next_f32())
        })
        .collect()
}

#[divan::bench(name = "add (per 1024 candidates)")]
fn add(bencher: Bencher) {
    let input = candidates(1);
    bencher.counter(ItemsCount::new(BATCH)).bench_local(|| {
        let mut s = StreamingReservoir::new();
        for &(sample, w, u) in black_box(&input) {
            s.add(sample, w, u);
        }
        black_box(s.finalize(1.0))
    });
}

#[divan::bench(name = "merge (per 1024 streams)")]
fn merge(bencher: Bencher) {
    let mut rng = Rng::new(2);
    let streams: Vec<StreamingReservoir<LightSample>> = candidates(3)
        .chunks(4)
        .cycle()
        .take(BATCH)
        .map(|chunk| {
            let mut s = StreamingReservoir::new();
            for &(sample, w, u) in chunk {
                s.add(sample, w, u);
            }
            s
        })
        .collect();
    let us: Vec<f32> = (0..BATCH).map(|_| rng.next_f32()).collect();
    bencher.counter(ItemsCount::new(BATCH)).bench_local(|| {
        let mut total = StreamingReservoir::new();
        for (s, &u) in black_box(&streams).iter().zip(&us) {
            total.merge(*s, u);
        }
        black_box(total)
    });
}

/// A pixel-like domain with a cheap analytic target.
#[derive(Debug)]
struct Pixel {
    normal: [f32; 3],
    offset: [f32; 3],
}

impl Pixel {
    fn target_pdf(&self, s: &LightSample) -> f32 {
        let d = [
            s.position[0] - self.offset[0],
            s.position[1] - self.offset[1],
            s.position[2] - self.offset[2],
        ];
        let cos = d[0] * self.normal[0] + d[1] * self.normal[1] + d[2] * self.normal[2];
        let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 1e-3;
        cos.max(0.0) / d2
    }
}

/// Light samples are shared between pixels (identity shift in area measure, J = 1).
struct AreaIdentity;

impl ShiftMap<LightSample> for AreaIdentity {
    type Domain = Pixel;
    fn shift(&self, _from: &Pixel, to: &Pixel, s: &LightSample) -> Option<Shifted<LightSample>> {
        Some(Shifted::identity(*s, to.target_pdf(s)))
    }
}

/// Canonical pixel, its reservoir, and the neighbours' pixels and reservoirs.
type Scene = (
    Pixel,
    Reservoir<LightSample>,
    Vec<(Pixel, Reservoir<LightSample>)>,
);

fn scene(k: usize) -> Scene {
    let mut rng = Rng::new(10 + k as u64);
    let pixel = |rng: &mut Rng| Pixel {
        normal: [0.0, 0.0, 1.0],
        offset: [rng.next_f32() * 0.1, rng.next_f32() * 0.1, -1.0],
    };
    let reservoir = |rng: &mut Rng, p: &Pixel| {
        let sample = LightSample {
            position: [rng.next_f32(), rng.next_f32(), rng.next_f32()],
            light: 0,
        };
        Reservoir {
            sample: Some(sample),
            ucw: 0.5 + rng.next_f32(),
            confidence: 1.0 + rng.next_f32() * 10.0,
            own_target: p.target_pdf(&sample),
        }
    };
    let c = pixel(&mut rng);
    let rc = reservoir(&mut rng, &c);
    let neighbors = (0..k)
        .map(|_| {
            let p = pixel(&mut rng);
            let r = reservoir(&mut rng, &p);
            (p, r)
        })
        .collect();
    (c, rc, neighbors)
}

fn bench_scheme(bencher: Bencher, k: usize, scheme: MisScheme) {
    let (c, rc, neighbors) = scene(k);
    let list: Vec<(&Pixel, &Reservoir<LightSample>)> =
        neighbors.iter().map(|(p, r)| (p, r)).collect();
    let mut rng = Rng::new(99);
    bencher.bench_local(|| {
        black_box(resample(
            &AreaIdentity,
            scheme,
            black_box(&c),
            black_box(&rc),
            black_box(&list),
            || rng.next_f32(),
        ))
    });
}

#[divan::bench(args = [3, 5])]
fn resample_defensive_pairwise(bencher: Bencher, k: usize) {
    bench_scheme(bencher, k, MisScheme::DefensivePairwise);
}

#[divan::bench(args = [3, 5])]
fn resample_pairwise(bencher: Bencher, k: usize) {
    bench_scheme(bencher, k, MisScheme::Pairwise);
}

#[divan::bench(args = [3, 5])]
fn resample_generalized_balance(bencher: Bencher, k: usize) {
    bench_scheme(bencher, k, MisScheme::GeneralizedBalance);
}

#[divan::bench(args = [3, 5])]
fn resample_contribution(bencher: Bencher, k: usize) {
    bench_scheme(bencher, k, MisScheme::Contribution);
}

#[divan::bench(args = [3, 5])]
fn resample_constant_biased(bencher: Bencher, k: usize) {
    bench_scheme(bencher, k, MisScheme::ConstantBiased);
}

/// The bare resampling arithmetic: k + 1 pre-shifted inputs with caller-computed balance weights.
#[divan::bench(args = [3, 5])]
fn gris_resampler_step(bencher: Bencher, k: usize) {
    let mut rng = Rng::new(7);
    let inputs: Vec<GrisInput<LightSample>> = (0..=k)
        .map(|i| GrisInput {
            sample: LightSample {
                position: [rng.next_f32(), rng.next_f32(), rng.next_f32()],
                light: i as u32,
            },
            receiver_target: rng.next_f32(),
            ucw: rng.next_f32() + 0.5,
            jacobian: 1.0,
            confidence: 1.0 + rng.next_f32(),
        })
        .collect();
    let confidences: Vec<f32> = inputs.iter().map(|i| i.confidence).collect();
    let targets: Vec<f32> = inputs.iter().map(|i| i.receiver_target).collect();
    bencher.bench_local(|| {
        let mut step = GrisResampler::new();
        for (i, input) in black_box(&inputs).iter().enumerate() {
            let m = mis::generalized_balance(i, &confidences, &targets);
            step.add(*input, m, rng.next_f32());
        }
        black_box(step.finalize())
    });
}
