//! A disk cache for the rough-plastic tables, so that loading a scene does not integrate them
//! again (a table takes about 15 ms of one core; a scene has a few, a generated one may have
//! dozens).
//!
//! Off unless a program turns it on with [`set_cache_dir`] (a library does not write files
//! behind its user's back); the `restir` binary turns it on at [`default_cache_dir`]. One small
//! file per (distribution, α, η), named by their bits and by [`TABLE_VERSION`], written to a
//! temporary name and renamed into place (concurrent writers cannot leave a torn file), and read
//! back only if it is a regular file of a table's length (nothing longer is read) and its magic,
//! checksum and values check out; anything else is rebuilt. A checksum only tells damage from a
//! good file, so the values are also checked against the integrals themselves
//! (`tables::plausible`: every transmittance row integrated again, the internal reflectance with
//! a quarter of the nodes, about 30 % of a build), and a file crafted with a valid checksum
//! cannot change the material beyond about 2 % of its diffuse scale.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use super::tables::{RoughPlasticTable, TABLE_RES};
use crate::microfacet::Distribution;

/// Changes whenever the tables' numerics change, so stale files are never read.
pub const TABLE_VERSION: u32 = 1;

const MAGIC: &[u8; 8] = b"RSTRPLT\0";

static DIR: Mutex<Option<PathBuf>> = Mutex::new(None);

/// Turns the disk cache on (at `dir`, created when first written) or off (`None`).
pub fn set_cache_dir(dir: Option<PathBuf>) {
    *DIR.lock().unwrap_or_else(|e| e.into_inner()) = dir;
}

/// The cache directory in use, if any.
pub fn cache_dir() -> Option<PathBuf> {
    DIR.lock().unwrap_or_else(|e| e.into_inner()).clone()
}

/// Where a program should cache tables: `$RESTIR_CACHE_DIR`, else `$XDG_CACHE_HOME/restir`,
/// else `$HOME/.cache/restir`; `None` if `RESTIR_CACHE_DIR` is set to the empty string (caching
/// off) or no home is known.
pub fn default_cache_dir() -> Option<PathBuf> {
    let var = |k: &str| std::env::var_os(k);
    if let Some(d) = var("RESTIR_CACHE_DIR") {
        return (!d.is_empty()).then(|| PathBuf::from(d));
    }
    if let Some(d) = var("XDG_CACHE_HOME").filter(|d| !d.is_empty()) {
        return Some(PathBuf::from(d).join("restir"));
    }
    var("HOME")
        .filter(|d| !d.is_empty())
        .map(|h| PathBuf::from(h).join(".cache").join("restir"))
}

fn file_name(distribution: Distribution, alpha: f32, eta: f32) -> String {
    let d = match distribution {
        Distribution::Beckmann => "beckmann",
        Distribution::Ggx => "ggx",
    };
    format!(
        "roughplastic-v{TABLE_VERSION}-{d}-{:08x}-{:08x}.bin",
        alpha.to_bits(),
        eta.to_bits()
    )
}

/// FNV-1a, 64 bits: enough to tell a torn or damaged file from a good one.
fn checksum(bytes: &[u8]) -> u64 {
    restir_sampling::hash::fnv1a(bytes)
}

fn encode(t: &RoughPlasticTable) -> Vec<u8> {
    let mut out = Vec::with_capacity(8 + 4 * (TABLE_RES + 1) + 8);
    out.extend_from_slice(MAGIC);
    for v in t.transmittance.iter().chain([&t.internal_reflectance]) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let sum = checksum(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

fn decode(bytes: &[u8]) -> Option<RoughPlasticTable> {
    let body = table_bytes() - 8;
    if bytes.len() != body + 8 || &bytes[..8] != MAGIC {
        return None;
    }
    let sum = u64::from_le_bytes(bytes[body..].try_into().ok()?);
    if sum != checksum(&bytes[..body]) {
        return None;
    }
    let mut values = bytes[8..body]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]));
    let mut transmittance = [0.0f32; TABLE_RES];
    for t in &mut transmittance {
        *t = values.next()?;
    }
    let internal_reflectance = values.next()?;
    let ok = |v: f32| (0.0..=1.0).contains(&v);
    (transmittance.iter().all(|&v| ok(v)) && ok(internal_reflectance)).then_some(
        RoughPlasticTable {
            transmittance,
            internal_reflectance,
        },
    )
}

/// The cached table, if the cache is on and holds a good one.
pub(super) fn load(distribution: Distribution, alpha: f32, eta: f32) -> Option<RoughPlasticTable> {
    let dir = cache_dir()?;
    let path = dir.join(file_name(distribution, alpha, eta));
    // Only regular files, and only as many bytes as a table has: whatever else lies at the name
    // (a huge file, a file growing while read) is not read past one byte more than a table.
    let size = table_bytes();
    let meta = std::fs::metadata(&path).ok()?;
    if !meta.is_file() || meta.len() != size as u64 {
        return None;
    }
    let mut bytes = Vec::with_capacity(size + 1);
    std::fs::File::open(&path)
        .ok()?
        .take(size as u64 + 1)
        .read_to_end(&mut bytes)
        .ok()?;
    decode(&bytes)
}

/// The length of a table's file: magic, the values, the checksum.
fn table_bytes() -> usize {
    8 + 4 * (TABLE_RES + 1) + 8
}

/// Stores `table` if the cache is on; failures (read-only disk, no space) only cost the next
/// load its time, so they are ignored.
pub(super) fn store(distribution: Distribution, alpha: f32, eta: f32, table: &RoughPlasticTable) {
    if let Some(dir) = cache_dir() {
        let _ = write_atomically(&dir, &file_name(distribution, alpha, eta), &encode(table));
    }
}

fn write_atomically(dir: &Path, name: &str, bytes: &[u8]) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let tmp = dir.join(format!("{name}.{}.tmp", std::process::id()));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, dir.join(name))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> RoughPlasticTable {
        let mut transmittance = [0.0; TABLE_RES];
        for (i, t) in transmittance.iter_mut().enumerate() {
            *t = i as f32 / TABLE_RES as f32;
        }
        RoughPlasticTable {
            transmittance,
            internal_reflectance: 0.42,
        }
    }

    /// A table survives the round trip bit for bit; a truncated, damaged or foreign file is
    /// refused.
    #[test]
    fn round_trip_and_damage() {
        let t = table();
        let bytes = encode(&t);
        assert_eq!(decode(&bytes).as_ref(), Some(&t));
        assert!(decode(&bytes[..bytes.len() - 1]).is_none());
        let mut flipped = bytes.clone();
        flipped[20] ^= 1;
        assert!(decode(&flipped).is_none());
        let mut foreign = bytes.clone();
        foreign[0] = b'X';
        assert!(decode(&foreign).is_none());
        assert!(decode(&[]).is_none());
    }

    /// Through the directory: stored, found again, and a damaged file is ignored (rebuilt by the
    /// caller) rather than used.
    #[test]
    fn store_and_load_through_a_directory() {
        let tmp = restir_testkit::TempDir::new("plastic-cache", "store");
        let dir = tmp.join("cache");
        let previous = cache_dir();
        set_cache_dir(Some(dir.clone()));
        let (d, a, e) = (Distribution::Ggx, 0.123f32, 1.777f32);
        assert!(load(d, a, e).is_none());
        store(d, a, e, &table());
        assert_eq!(load(d, a, e), Some(table()));
        std::fs::write(dir.join(file_name(d, a, e)), b"torn").unwrap();
        assert!(load(d, a, e).is_none());
        // A file longer than a table is not read at all (a sparse 1 GiB file here).
        let big = std::fs::File::create(dir.join(file_name(d, a, e))).unwrap();
        big.set_len(1 << 30).unwrap();
        drop(big);
        assert!(load(d, a, e).is_none());
        set_cache_dir(previous);
    }

    /// A table with a valid checksum but values no integration gives is refused by the
    /// registry's check and rebuilt: an internal reflectance just below 1 (which would scale
    /// the diffuse base by about 3·10⁶) and transmittances that are not the integral.
    #[test]
    fn crafted_tables_with_valid_checksums_are_refused() {
        use super::super::tables::plausible;
        let (d, a, e) = (Distribution::Ggx, 0.3f32, 1.5f32);
        let honest = RoughPlasticTable::compute(d, a, e);
        assert!(plausible(d, a, e, &honest));
        let bright = RoughPlasticTable {
            internal_reflectance: 1.0 - 3e-7,
            ..honest
        };
        assert!(
            decode(&encode(&bright)).is_some(),
            "the checksum alone passes it"
        );
        assert!(!plausible(d, a, e, &bright));
        let mut shifted = RoughPlasticTable::compute(d, a, e);
        for t in &mut shifted.transmittance {
            *t *= 0.99;
        }
        assert!(!plausible(d, a, e, &shifted));
        // One row changed, wherever it is (two rows checked at random passed this 62 times in
        // 64), and the internal reflectance moved either way within the energy bound (which
        // bound it from above only: 0.415 here against 0.597, a diffuse base up to a third
        // brighter).
        for k in [0, 1, 31, 62, 63] {
            let mut one = RoughPlasticTable::compute(d, a, e);
            one.transmittance[k] = (one.transmittance[k] + 0.05).min(1.0);
            assert!(!plausible(d, a, e, &one), "row {k}");
        }
        for r in [0.0, 0.3, 0.45, 0.55, 0.6] {
            let crafted = RoughPlasticTable {
                internal_reflectance: r,
                ..RoughPlasticTable::compute(d, a, e)
            };
            assert!(!plausible(d, a, e, &crafted), "R_int {r}");
        }
        // Every table over a grid of roughness and IOR (both distributions) passes.
        for d in [Distribution::Ggx, Distribution::Beckmann] {
            for a in [0.002f32, 0.05, 0.3, 0.6, 1.0] {
                for e in [0.6f32, 0.9, 1.01, 1.2, 1.5, 2.0, 3.0] {
                    let t = RoughPlasticTable::compute(d, a, e);
                    assert!(plausible(d, a, e, &t), "{d:?} α {a} η {e}: {t:?}");
                }
            }
        }
    }
}
