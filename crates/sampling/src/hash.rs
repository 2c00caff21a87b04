//! FNV-1a, 64 bits (Fowler, Noll and Vo): a stable hash of bytes for cache keys, scene hashes and
//! file checksums, whose values must not change between Rust versions or machines (unlike
//! `std::hash`). Not for adversarial input.

const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const PRIME: u64 = 0x0000_0100_0000_01b3;

/// FNV-1a of `bytes`.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes
        .iter()
        .fold(OFFSET, |h, &b| (h ^ u64::from(b)).wrapping_mul(PRIME))
}

/// FNV-1a of several byte strings, with a separator byte (0xff) hashed after each, so that
/// `("ab", "c")` and `("a", "bc")` differ.
pub fn fnv1a_chunks(chunks: &[&[u8]]) -> u64 {
    let mut h = OFFSET;
    for chunk in chunks {
        for &b in *chunk {
            h = (h ^ u64::from(b)).wrapping_mul(PRIME);
        }
        h = (h ^ 0xff).wrapping_mul(PRIME);
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        // The published FNV-1a test vectors.
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(b"foobar"), 0x8594_4171_f739_67e8);
        assert_eq!(fnv1a_chunks(&[]), fnv1a(b""));
        assert_ne!(fnv1a_chunks(&[b"ab", b"c"]), fnv1a_chunks(&[b"a", b"bc"]));
        assert_ne!(fnv1a_chunks(&[b"abc"]), fnv1a(b"abc"));
    }
}
