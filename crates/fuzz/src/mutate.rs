//! The mutators: byte- and text-level mutations of any seed, and a structure-aware one for the
//! rough-plastic table cache, which changes a table's values and then writes a valid checksum
//! (a file crafted to pass the checksum, which byte mutations almost never reach).

/// SplitMix64: the mutator's random numbers (fixed seed, so a run is reproducible).
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    pub(crate) fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Numbers that stress a loader where a number is expected.
const NUMBERS: [&str; 14] = [
    "1e38",
    "3e38",
    "1e39",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "-0",
    "1e20",
    "1e-45",
    "4294967295",
    "-1",
    "99999999999999999999",
    "65536",
];

/// Integers that stress a binary header.
const INTEGERS: [u64; 10] = [
    0,
    1,
    0xFF,
    0xFFFF,
    0x7FFF_FFFF,
    0xFFFF_FFFF,
    0x8000_0000,
    1 << 32,
    u64::MAX,
    0x7FC0_0000, // f32 NaN
];

/// One mutation of `input` (`others` are the target's seeds, for splicing).
pub(crate) fn mutate(rng: &mut Rng, input: &[u8], others: &[Vec<u8>]) -> Vec<u8> {
    let mut v = input.to_vec();
    let rounds = 1 + rng.below(4);
    for _ in 0..rounds {
        let len = v.len().max(1);
        match rng.below(9) {
            0 if !v.is_empty() => {
                let i = rng.below(v.len());
                v[i] ^= 1 << rng.below(8);
            }
            1 if !v.is_empty() => {
                let i = rng.below(v.len());
                v[i] = rng.next() as u8;
            }
            2 => {
                // An interesting integer, little- or big-endian, 1 to 8 bytes wide.
                let x = INTEGERS[rng.below(INTEGERS.len())];
                let w = [1, 2, 4, 8][rng.below(4)];
                let bytes = if rng.below(2) == 0 {
                    x.to_le_bytes()
                } else {
                    x.to_be_bytes()
                };
                let at = rng.below(len);
                for k in 0..w {
                    if let Some(b) = v.get_mut(at + k) {
                        *b = bytes[if rng.below(2) == 0 { k } else { 8 - w + k }];
                    }
                }
            }
            3 => {
                // Replace a number in text by a stressful one.
                let starts: Vec<usize> = (0..v.len())
                    .filter(|&i| {
                        v[i].is_ascii_digit() && (i == 0 || !v[i - 1].is_ascii_alphanumeric())
                    })
                    .collect();
                if !starts.is_empty() {
                    let s = starts[rng.below(starts.len())];
                    let e = (s..v.len())
                        .find(|&i| !(v[i].is_ascii_digit() || b".eE-+".contains(&v[i])))
                        .unwrap_or(v.len());
                    let n = NUMBERS[rng.below(NUMBERS.len())].as_bytes();
                    v.splice(s..e, n.iter().copied());
                }
            }
            4 => {
                // Duplicate a chunk many times (amplification, huge element lists).
                let s = rng.below(len);
                let e = (s + 1 + rng.below(64)).min(v.len());
                if s < e {
                    let chunk = v[s..e].to_vec();
                    let times = 1 + rng.below(200);
                    for _ in 0..times {
                        v.splice(e..e, chunk.iter().copied());
                    }
                }
            }
            5 => {
                let s = rng.below(len);
                let e = (s + rng.below(32)).min(v.len());
                if s < e {
                    v.drain(s..e);
                }
            }
            6 => v.truncate(rng.below(len)),
            7 if !others.is_empty() => {
                let o = &others[rng.below(others.len())];
                let at = rng.below(len).min(v.len());
                let from = rng.below(o.len().max(1)).min(o.len());
                v.truncate(at);
                v.extend_from_slice(&o[from..]);
            }
            _ => {
                let at = rng.below(len).min(v.len());
                let b = [b'$', b'<', b'>', b'"', b'\0', b'\n', b'(', b')', b',', b'-'];
                v.insert(at, b[rng.below(b.len())]);
            }
        }
    }
    v
}

/// Values a crafted table entry may take: the ends of the valid range, just inside and outside
/// them, non-finite and signed zero, the smallest normal and subnormal numbers.
const TABLE_VALUES: [f32; 11] = [
    0.0,
    -0.0,
    0.5,
    1.0,
    1.0 - 3e-7,
    1.0 + 1.2e-7,
    -1e-7,
    f32::NAN,
    f32::INFINITY,
    f32::MIN_POSITIVE,
    1e-45,
];

/// One structure-aware mutation of a table cache file (`input`: the magic, the `f32` values in
/// little-endian order, then the FNV-1a checksum of everything before it): one to three values
/// changed (the last one, the internal reflectance, a third of the time) to a stressful value,
/// scaled, nudged, copied from another row, or all rows shifted by one; then the checksum is
/// written again, so that the file passes it and reaches the reader's value checks. Inputs of
/// another shape get [`mutate`].
pub(crate) fn mutate_table(rng: &mut Rng, input: &[u8], others: &[Vec<u8>]) -> Vec<u8> {
    let n = input.len().saturating_sub(16) / 4;
    if n < 2 || input.len() != 16 + 4 * n {
        return mutate(rng, input, others);
    }
    let body = input.len() - 8;
    let mut values: Vec<f32> = input[8..body]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    for _ in 0..1 + rng.below(3) {
        let i = if rng.below(3) == 0 {
            n - 1
        } else {
            rng.below(n - 1)
        };
        let v = values[i];
        values[i] = match rng.below(5) {
            0 => TABLE_VALUES[rng.below(TABLE_VALUES.len())],
            1 => v * [0.99, 1.01, 0.9, 1.1, 1e-3][rng.below(5)],
            2 => v + [1e-6, -1e-6, 2e-5, -2e-5, 1e-3, -1e-3][rng.below(6)],
            3 => values[rng.below(n - 1)],
            _ => {
                values[..n - 1].rotate_right(1);
                values[i]
            }
        };
    }
    let mut out = input[..8].to_vec();
    for v in &values {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let sum = restir_sampling::hash::fnv1a(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}
