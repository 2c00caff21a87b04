//! Low-discrepancy sequences.

/// The first primes, the bases of the Halton dimensions.
pub const PRIMES: [u32; 16] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53];

/// The radical inverse of `index` in `base`: its digits mirrored about the radix point.
pub fn radical_inverse(base: u32, mut index: u64) -> f32 {
    let inv_base = 1.0 / base as f64;
    let mut inv_base_n = 1.0f64;
    let mut reversed = 0u64;
    let b = base as u64;
    while index > 0 {
        let next = index / b;
        let digit = index - next * b;
        reversed = reversed * b + digit;
        inv_base_n *= inv_base;
        index = next;
    }
    ((reversed as f64 * inv_base_n) as f32).min(crate::ONE_MINUS_EPSILON)
}

/// Component `dimension` (< 16) of the `index`-th Halton point.
pub fn halton(index: u64, dimension: usize) -> f32 {
    radical_inverse(PRIMES[dimension % PRIMES.len()], index)
}

/// The plastic constant's R2 sequence (Roberts 2018, "The unreasonable effectiveness of
/// quasirandom sequences"): point `index` shifted by `offset` (a Cranley–Patterson rotation),
/// in `[0, 1)²`.
pub fn r2(index: u64, offset: [f32; 2]) -> [f32; 2] {
    // g is the plastic number, the real root of x³ = x + 1.
    const G: f64 = 1.324_717_957_244_746;
    const A1: f64 = 1.0 / G;
    const A2: f64 = 1.0 / (G * G);
    let x = (offset[0] as f64 + A1 * index as f64).fract();
    let y = (offset[1] as f64 + A2 * index as f64).fract();
    [
        (x as f32).min(crate::ONE_MINUS_EPSILON),
        (y as f32).min(crate::ONE_MINUS_EPSILON),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radical_inverse_base2() {
        assert_eq!(radical_inverse(2, 0), 0.0);
        assert_eq!(radical_inverse(2, 1), 0.5);
        assert_eq!(radical_inverse(2, 2), 0.25);
        assert_eq!(radical_inverse(2, 3), 0.75);
        assert!((radical_inverse(3, 1) - 1.0 / 3.0).abs() < 1e-7);
        assert!((radical_inverse(3, 5) - (2.0 / 3.0 + 1.0 / 9.0)).abs() < 1e-6);
    }

    /// Every one of the first n² points of a 2-D sequence falls in a distinct cell of an n×n grid
    /// only for (0,2)-sequences; for Halton and R2 we check the weaker, still falsifiable property
    /// that each cell of a 16×16 grid gets between half and twice its share of 4096 points.
    #[test]
    fn stratification() {
        for seq in 0..2 {
            let mut counts = [0u32; 256];
            for i in 0..4096u64 {
                let p = if seq == 0 {
                    [halton(i, 0), halton(i, 1)]
                } else {
                    r2(i, [0.3, 0.7])
                };
                let cx = (p[0] * 16.0) as usize;
                let cy = (p[1] * 16.0) as usize;
                counts[cy * 16 + cx] += 1;
            }
            for c in counts {
                assert!((8..=32).contains(&c), "sequence {seq}: cell count {c}");
            }
        }
    }
}
