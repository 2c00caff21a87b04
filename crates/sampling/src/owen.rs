//! Owen-scrambled Sobol points, padded dimension by dimension: a randomised quasi-Monte Carlo
//! source of uniform numbers whose every dimension is exactly uniform (so every estimator stays
//! unbiased) and whose first `2^k` points in each pair of dimensions form a `(0, k, 2)`-net.
//!
//! The construction is Burley's ("Practical Hash-based Owen Scrambling", JCGT 9(4), 2020):
//!
//! - the points are the first two dimensions of the Sobol sequence (van der Corput in base 2 and
//!   the Pascal-matrix dimension), a `(0, 2)`-sequence in base 2;
//! - each request for one or two numbers is a new *dimension*; it shuffles the point index with a
//!   nested uniform scramble of its own (so dimensions are decorrelated, "padding"), then
//!   Owen-scrambles each coordinate with another seed;
//! - the nested uniform scramble is Laine and Karras's hash-based approximation ("Stratified
//!   sampling for stochastic transparency", 2011) applied to the bit-reversed value, with Burley's
//!   constants.
//!
//! Shuffling the index by a nested uniform scramble keeps the first `2^k` indices within one
//! aligned block of `2^k` Sobol indices, and every such block is itself a net: the stratification
//! holds for any prefix of power-of-two length, at every pixel, without knowing the sample count.

use crate::mix64;

/// Laine and Karras's hash-based nested uniform permutation of the *low-to-high* bits of `x`
/// (each bit flipped by a hash of the bits below it), with Burley's constants.
#[inline]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Owen scrambling of a 32-bit fixed-point number in `[0, 1)`: each bit flipped by a hash of the
/// more significant bits and the seed.
#[inline]
pub fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// The direction numbers of the second Sobol dimension: its generator matrix is the Pascal
/// matrix modulo 2, each column the previous one xor itself shifted right by one.
const fn pascal_directions() -> [u32; 32] {
    let mut v = [0u32; 32];
    let mut d = 1u32 << 31;
    let mut j = 0;
    while j < 32 {
        v[j] = d;
        d ^= d >> 1;
        j += 1;
    }
    v
}

/// The matrix-vector product over GF(2), one byte at a time: `BYTES[b][x]` is the xor of the
/// columns that byte `b` of the index selects when it is `x`.
const BYTES: [[u32; 256]; 4] = byte_tables(false);

/// The same product in bit-reversed form, `reverse(sobol(reverse(r)))` for an argument `r`:
/// the scrambles work on reversed bits, so the sampler never reverses in between.
const REVERSED_BYTES: [[u32; 256]; 4] = byte_tables(true);

const fn byte_tables(reversed: bool) -> [[u32; 256]; 4] {
    let v = pascal_directions();
    let mut t = [[0u32; 256]; 4];
    let mut b = 0;
    while b < 4 {
        let mut x = 0;
        while x < 256 {
            let mut r = 0u32;
            let mut bit = 0;
            while bit < 8 {
                if x & (1 << bit) != 0 {
                    let j = 8 * b + bit;
                    r ^= if reversed {
                        v[31 - j].reverse_bits()
                    } else {
                        v[j]
                    };
                }
                bit += 1;
            }
            t[b][x] = r;
            x += 1;
        }
        b += 1;
    }
    t
}

#[inline]
fn product(tables: &[[u32; 256]; 4], x: u32) -> u32 {
    let [b0, b1, b2, b3] = x.to_le_bytes();
    tables[0][b0 as usize]
        ^ tables[1][b1 as usize]
        ^ tables[2][b2 as usize]
        ^ tables[3][b3 as usize]
}

/// The second Sobol dimension of point `index` as 32-bit fixed point.
#[inline]
pub fn sobol_dimension_1(index: u32) -> u32 {
    product(&BYTES, index)
}

/// A fixed-point number as an `f32` in `[0, 1)` (its top 24 bits).
#[inline]
fn to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// The uniform numbers of one pixel sample: sample `index` of a sequence whose scrambles are
/// drawn from `seed`. Each call to [`OwenSobol::next_f32`] or [`OwenSobol::next_2d`] is a new
/// dimension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OwenSobol {
    seed: u64,
    /// The sample index, bit-reversed (every dimension starts from it).
    reversed_index: u32,
    dimension: u32,
}

impl OwenSobol {
    /// Sample `index` of the sequence scrambled by `seed` (a pixel's, say), at its first
    /// dimension.
    pub fn new(seed: u64, index: u32) -> Self {
        Self {
            seed,
            reversed_index: index.reverse_bits(),
            dimension: 0,
        }
    }

    /// The same sample's numbers from `dimension` on.
    pub fn at_dimension(self, dimension: u32) -> Self {
        Self { dimension, ..self }
    }

    /// The next dimension's seeds: one for the index shuffle, one per coordinate.
    #[inline]
    fn next_seeds(&mut self) -> u64 {
        let h =
            mix64(self.seed ^ (u64::from(self.dimension) + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15));
        self.dimension += 1;
        h
    }

    /// One uniform number in `[0, 1)`: a scrambled van der Corput point.
    ///
    /// The point of shuffled index `i` is `reverse(i)`, and its Owen scramble is
    /// `reverse(LK(reverse(reverse(i))))`: with the shuffle `i = reverse(LK(reverse(index)))`,
    /// the value is `reverse(LK(reverse(LK(reverse(index)))))`, three bit reversals.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        let h = self.next_seeds();
        let i = laine_karras(self.reversed_index, h as u32).reverse_bits();
        to_unit(laine_karras(i, (h >> 32) as u32).reverse_bits())
    }

    /// Two uniform numbers in `[0, 1)²`: a scrambled `(0, 2)`-sequence point (the same
    /// shuffle; the second coordinate's scramble takes the reversed Sobol value straight from
    /// a table of the reversed product).
    #[inline]
    pub fn next_2d(&mut self) -> glam::Vec2 {
        let h = self.next_seeds();
        let r = laine_karras(self.reversed_index, h as u32);
        let h2 = (h.wrapping_mul(0xd1b5_4a32_d192_ed03) >> 32) as u32;
        glam::Vec2::new(
            to_unit(laine_karras(r.reverse_bits(), (h >> 32) as u32).reverse_bits()),
            to_unit(laine_karras(product(&REVERSED_BYTES, r), h2).reverse_bits()),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tables give the bit-by-bit product.
    #[test]
    fn tables_match_the_matrix() {
        let v = pascal_directions();
        for index in [0u32, 1, 2, 3, 255, 256, 0xdead_beef, u32::MAX, 0x8000_0001] {
            let direct = (0..32)
                .filter(|j| index >> j & 1 == 1)
                .fold(0, |r, j| r ^ v[j]);
            assert_eq!(sobol_dimension_1(index), direct, "{index:#x}");
        }
        for r in [0u32, 1, 0x8000_0000, 0x1234_5678, u32::MAX] {
            let direct = sobol_dimension_1(r.reverse_bits()).reverse_bits();
            assert_eq!(product(&REVERSED_BYTES, r), direct, "{r:#x}");
        }
        // The first points: 1/2, 3/4 and 1/4 at indices 1, 2, 3.
        assert_eq!(sobol_dimension_1(1), 1 << 31);
        assert_eq!(sobol_dimension_1(2), 3 << 30);
        assert_eq!(sobol_dimension_1(3), 1 << 30);
    }

    /// The first 2^k points of every 2-D dimension fall one in each elementary interval of every
    /// shape `2^a × 2^(k-a)`: a (0, k, 2)-net, for several seeds and dimensions.
    #[test]
    fn prefixes_are_nets() {
        for seed in [1u64, 7, 12345] {
            for k in [4u32, 6, 8] {
                let n = 1usize << k;
                for dim in [0u32, 1, 5, 20] {
                    let points: Vec<glam::Vec2> = (0..n as u32)
                        .map(|i| OwenSobol::new(seed, i).at_dimension(dim).next_2d())
                        .collect();
                    for a in 0..=k {
                        let (nx, ny) = (1usize << a, 1usize << (k - a));
                        let mut seen = vec![false; n];
                        for p in &points {
                            let cell = (p.x * nx as f32) as usize + nx * (p.y * ny as f32) as usize;
                            assert!(!seen[cell], "seed {seed} k {k} dim {dim} shape {nx}x{ny}");
                            seen[cell] = true;
                        }
                    }
                }
            }
        }
    }

    /// One-dimensional prefixes of length 2^k are stratified: one point per interval of 2^-k.
    #[test]
    fn one_dimensional_prefixes_are_stratified() {
        for seed in [3u64, 99] {
            for dim in [0u32, 2, 9] {
                let n = 256usize;
                let mut seen = vec![false; n];
                for i in 0..n as u32 {
                    let x = OwenSobol::new(seed, i).at_dimension(dim).next_f32();
                    let cell = (x * n as f32) as usize;
                    assert!(!seen[cell]);
                    seen[cell] = true;
                }
            }
        }
    }
}
