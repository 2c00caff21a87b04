//! FNV-1a, 64 bits (Fowler, Noll and Vo): a stable hash of bytes for cache keys, scene hashes and
//! file checksums, whose values must not change between Rust versions or machines (unlike
//! `std::hash`). Not for adversarial input.

const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const PRIME: u64 = 0x0000_0100_0000_01b3;

/// FNV-1a of `bytes`.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h = Fnv1a::new();
    h.write(bytes);
    h.finish()
}

/// FNV-1a over bytes that arrive in pieces (a file read in blocks): the same value as
/// [`fnv1a`] of the pieces concatenated.
#[derive(Clone, Copy, Debug)]
pub struct Fnv1a(u64);

impl Fnv1a {
    /// The hash of nothing yet.
    pub fn new() -> Self {
        Self(OFFSET)
    }

    /// Hashes `bytes` after what came before.
    pub fn write(&mut self, bytes: &[u8]) {
        self.0 = bytes
            .iter()
            .fold(self.0, |h, &b| (h ^ u64::from(b)).wrapping_mul(PRIME));
    }

    /// The hash so far.
    pub fn finish(&self) -> u64 {
        self.0
    }
}

impl Default for Fnv1a {
    fn default() -> Self {
        Self::new()
    }
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
        let mut h = Fnv1a::new();
        h.write(b"foo");
        h.write(b"bar");
        assert_eq!(h.finish(), fnv1a(b"foobar"));
    }
}
