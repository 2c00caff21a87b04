//! Spatial reuse with the streaming pairwise resampler, the form a ReSTIR renderer's spatial
//! pass uses: a row of "pixels" each resamples its own reservoir (RIS), then every pixel reuses
//! its two neighbours' reservoirs with defensive pairwise MIS. Prints each pixel's estimate
//! against the exact integral.
//!
//! Run with `cargo run -p restir-gris --example pairwise` (add `--release` for more trials).
//!
//! The toy: pixel `i` integrates `f_i(x) = 1 + s_i·x` over `x ∈ [0, 1)` (exact `1 + s_i/2`),
//! with its target `p̂_i = f_i`. The samples are shared between pixels the way light samples are
//! (the shift is the identity, `J = 1`), so only the targets differ.

use restir_gris::{
    PairwiseNeighbor, PairwiseResampler, PairwiseVariant, Reservoir, ShiftMap, Shifted,
    StreamingReservoir,
};

/// A pixel: the slope of its integrand.
struct Pixel {
    slope: f32,
}

impl Pixel {
    fn target(&self, x: f32) -> f32 {
        1.0 + self.slope * x
    }
}

/// The identity shift between pixels: the sample stays, the destination evaluates its target.
struct SharedSamples;

impl ShiftMap<f32> for SharedSamples {
    type Domain = Pixel;
    fn shift(&self, _from: &Pixel, to: &Pixel, x: &f32) -> Option<Shifted<f32>> {
        Some(Shifted::identity(*x, to.target(*x)))
    }
}

/// A small deterministic generator (bring your own in a renderer).
struct Rng(u64);

impl Rng {
    fn next_f32(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Initial sampling: `N` uniform candidates, resampling weight `p̂(x) / (N · pdf(x))`.
fn initial(pixel: &Pixel, rng: &mut Rng) -> Reservoir<f32> {
    const N: usize = 4;
    let mut stream = StreamingReservoir::new();
    for _ in 0..N {
        let x = rng.next_f32();
        let t = pixel.target(x);
        stream.add_candidate(x, t, t / N as f32, 0.0, rng.next_f32());
    }
    let mut r = stream.finalize_recorded();
    r.confidence = 1.0; // one initial-sampling technique
    r
}

/// Spatial reuse at pixel `c` from the pixels in `neighbors` (defensive pairwise MIS).
fn spatial_reuse(
    pixels: &[Pixel],
    reservoirs: &[Reservoir<f32>],
    c: usize,
    neighbors: &[usize],
    rng: &mut Rng,
) -> Reservoir<f32> {
    let map = SharedSamples;
    let canonical = reservoirs[c];
    let mut step = PairwiseResampler::new(PairwiseVariant::Defensive, neighbors.len(), canonical);
    for &i in neighbors {
        let neighbor = &reservoirs[i];
        // Forward: the neighbour's sample into this pixel (None if empty or the shift fails).
        let shifted = neighbor
            .sample
            .and_then(|x| map.shift(&pixels[i], &pixels[c], &x));
        // Inverse: this pixel's sample into the neighbour, pulled back (0 if it fails).
        let pulled_back = canonical.sample.map_or(0.0, |x| {
            map.pulled_back_target_pdf(&pixels[c], &pixels[i], &x)
        });
        // Empty neighbours and failed shifts are added too: they keep their canonical share.
        step.add_neighbor(
            PairwiseNeighbor::new(neighbor, shifted, pulled_back),
            rng.next_f32(),
        );
    }
    step.finalize(rng.next_f32()).with_confidence_cap(20.0)
}

fn main() {
    let pixels: Vec<Pixel> = [0.0f32, 2.0, 6.0, 1.0, 4.0]
        .iter()
        .map(|&slope| Pixel { slope })
        .collect();
    let trials = if cfg!(debug_assertions) {
        20_000
    } else {
        400_000
    };
    let mut rng = Rng(0x5eed);
    let mut sums = vec![(0.0f64, 0.0f64); pixels.len()];
    for _ in 0..trials {
        let reservoirs: Vec<_> = pixels.iter().map(|p| initial(p, &mut rng)).collect();
        for c in 0..pixels.len() {
            let neighbors: Vec<usize> = [c.wrapping_sub(1), c + 1]
                .into_iter()
                .filter(|&i| i < pixels.len())
                .collect();
            let out = spatial_reuse(&pixels, &reservoirs, c, &neighbors, &mut rng);
            let estimate = out
                .sample
                .map_or(0.0, |y| f64::from(pixels[c].target(y) * out.ucw));
            sums[c].0 += estimate;
            sums[c].1 += estimate * estimate;
        }
    }
    println!("pixel  slope   exact   estimate ± 3 SE");
    let mut all_within = true;
    for (c, p) in pixels.iter().enumerate() {
        let n = trials as f64;
        let mean = sums[c].0 / n;
        let se = ((sums[c].1 / n - mean * mean) / (n - 1.0)).sqrt();
        let exact = 1.0 + f64::from(p.slope) / 2.0;
        let within = (mean - exact).abs() < 4.0 * se;
        all_within &= within;
        println!(
            "{c:>5}  {:>5.1}  {exact:>6.3}   {mean:>6.3} ± {:.3}{}",
            p.slope,
            3.0 * se,
            if within { "" } else { "   <- off" }
        );
    }
    assert!(
        all_within,
        "an estimate is more than 4 SE from its integral"
    );
    println!("every pixel's estimate matches its integral (within 4 standard errors)");
}
