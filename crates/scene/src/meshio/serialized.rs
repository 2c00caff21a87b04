//! Mitsuba's `.serialized` meshes: a file of zlib-compressed shapes (format versions 3 and 4),
//! one of which a scene picks with `shape_index`.

use std::io::Read;

use glam::{Vec2, Vec3};

use super::{MeshData, finish};

const SERIALIZED_ID: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_UVS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const FACE_NORMALS: u32 = 0x0010;
const SINGLE: u32 = 0x1000;
const DOUBLE: u32 = 0x2000;

/// Reads shape `index` of a Mitsuba `.serialized` file: per shape a little-endian header (u16
/// 0x041C, u16 version 3 or 4) and a zlib stream (u32 flags, [v4: NUL-terminated name], u64
/// vertex and triangle counts, positions, optional normals, uvs and colours, indices); the file
/// ends with the shapes' offsets (u64 in v4, u32 in v3) and a u32 shape count.
pub(crate) fn read_serialized(bytes: &[u8], index: usize) -> Result<MeshData, String> {
    let u16_at = |o: usize| {
        bytes
            .get(o..o + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
    };
    let (Some(id), Some(version)) = (u16_at(0), u16_at(2)) else {
        return Err("not a Mitsuba .serialized file (too short)".into());
    };
    if id != SERIALIZED_ID {
        return Err(format!(
            "not a Mitsuba .serialized file (header 0x{id:04x}, expected 0x041c)"
        ));
    }
    if version != 3 && version != 4 {
        return Err(format!(
            ".serialized version {version} is not supported (3 or 4)"
        ));
    }
    // Offset dictionary at the end of the file.
    let len = bytes.len();
    let count = bytes
        .get(len.saturating_sub(4)..)
        .filter(|b| b.len() == 4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
        .ok_or("truncated .serialized file")?;
    let width = if version == 4 { 8 } else { 4 };
    let table = count
        .checked_mul(width)
        .and_then(|t| len.checked_sub(4 + t))
        .filter(|&t| t >= 4 && count > 0)
        .ok_or("the .serialized file's shape table is damaged (truncated file?)")?;
    if index >= count {
        return Err(format!(
            "shape_index {index} is out of range: the file holds {count} shape{}",
            if count == 1 { "" } else { "s" }
        ));
    }
    let at = table + index * width;
    let offset = if width == 8 {
        let b: [u8; 8] = bytes[at..at + 8].try_into().map_err(|_| "bad offset")?;
        u64::from_le_bytes(b)
    } else {
        let b: [u8; 4] = bytes[at..at + 4].try_into().map_err(|_| "bad offset")?;
        u32::from_le_bytes(b) as u64
    };
    let offset = usize::try_from(offset)
        .ok()
        .filter(|&o| o + 4 <= table)
        .ok_or_else(|| format!("shape {index}: offset {offset} lies outside the file"))?;
    if u16_at(offset) != Some(SERIALIZED_ID) {
        return Err(format!("shape {index}: no shape header at offset {offset}"));
    }
    let shape_version = u16_at(offset + 2).unwrap_or(0);
    let compressed = &bytes[offset + 4..table];
    let mut z = Inflate {
        inner: flate2::read::ZlibDecoder::new(compressed),
        // zlib expands at most about 1032:1; more claimed data than that is a damaged file.
        budget: (compressed.len() as u64)
            .saturating_mul(1100)
            .saturating_add(1 << 16),
        index,
    };
    let flags = z.u32()?;
    if shape_version == 4 {
        // Shape name, NUL-terminated.
        let mut n = 0;
        while z.bytes(1)?[0] != 0 {
            n += 1;
            if n > 1 << 16 {
                return Err(format!("shape {index}: unterminated name"));
            }
        }
    }
    let nv = z.u64()?;
    let nt = z.u64()?;
    let cap = crate::desc::limits::MAX_MESH_ELEMENTS;
    let real = if flags & DOUBLE != 0 { 8 } else { 4 };
    z.check(nv.saturating_mul(3 * real))?;
    if nv > cap || nt > cap {
        // Checked before inflating: a small file can claim (and hold) gigabytes.
        return Err(format!(
            "shape {index}: {nv} vertices and {nt} triangles exceed the limit of {cap} each"
        ));
    }
    let double = flags & DOUBLE != 0;
    if double == (flags & SINGLE != 0) {
        return Err(format!(
            "shape {index}: flags 0x{flags:x} give no single/double precision"
        ));
    }
    let real = if double { 8 } else { 4 };
    let mut reals = |count: u64, per: u64| -> Result<Vec<f32>, String> {
        let n = count
            .checked_mul(per)
            .ok_or_else(|| format!("shape {index}: absurd vertex count {count}"))?;
        let raw = z.bytes(n.saturating_mul(real))?;
        Ok(if double {
            raw.chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])) as f32)
                .collect()
        } else {
            raw.chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap_or([0; 4])))
                .collect()
        })
    };
    let p = reals(nv, 3)?;
    let n = if flags & HAS_NORMALS != 0 {
        reals(nv, 3)?
    } else {
        Vec::new()
    };
    let t = if flags & HAS_UVS != 0 {
        reals(nv, 2)?
    } else {
        Vec::new()
    };
    if flags & HAS_COLORS != 0 {
        reals(nv, 3)?;
    }
    let wide = nv > u32::MAX as u64;
    let ni = nt
        .checked_mul(3)
        .ok_or_else(|| format!("shape {index}: absurd triangle count {nt}"))?;
    let raw = z.bytes(ni.saturating_mul(if wide { 8 } else { 4 }))?;
    let mut idx = Vec::with_capacity(nt as usize);
    let mut flat = Vec::with_capacity(ni as usize);
    if wide {
        for c in raw.chunks_exact(8) {
            let v = u64::from_le_bytes(c.try_into().unwrap_or([0; 8]));
            flat.push(u32::try_from(v).map_err(|_| format!("shape {index}: index {v} too large"))?);
        }
    } else {
        flat.extend(
            raw.chunks_exact(4)
                .map(|c| u32::from_le_bytes(c.try_into().unwrap_or([0; 4]))),
        );
    }
    idx.extend(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
    let positions = p
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect();
    let normals = if flags & FACE_NORMALS != 0 {
        Vec::new()
    } else {
        n.chunks_exact(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect()
    };
    let uvs = t.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect();
    finish(positions, normals, uvs, idx).map_err(|e| format!("shape {index}: {e}"))
}

/// A zlib stream read in exact sizes, with a bound on the total.
struct Inflate<'a> {
    inner: flate2::read::ZlibDecoder<&'a [u8]>,
    budget: u64,
    index: usize,
}

impl Inflate<'_> {
    /// An error unless `n` more bytes fit the budget.
    fn check(&self, n: u64) -> Result<(), String> {
        if n > self.budget {
            return Err(format!(
                "shape {}: the file claims more data than it holds (truncated or damaged)",
                self.index
            ));
        }
        Ok(())
    }
    fn bytes(&mut self, n: u64) -> Result<Vec<u8>, String> {
        self.check(n)?;
        self.budget -= n;
        // Grows with the data actually decompressed, so a lying count cannot allocate much.
        let mut v = Vec::new();
        let read = (&mut self.inner)
            .take(n)
            .read_to_end(&mut v)
            .map_err(|e| format!("shape {}: compressed data is damaged ({e})", self.index))?;
        if read as u64 != n {
            return Err(format!(
                "shape {}: compressed data ends early (truncated file?)",
                self.index
            ));
        }
        Ok(v)
    }
    fn u32(&mut self) -> Result<u32, String> {
        let b = self.bytes(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    fn u64(&mut self) -> Result<u64, String> {
        let b = self.bytes(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(&b);
        Ok(u64::from_le_bytes(a))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    /// Writes one shape in the `.serialized` layout.
    fn shape(version: u16, p: &[[f32; 3]], tris: &[[u32; 3]], normals: bool) -> Vec<u8> {
        let mut raw = Vec::new();
        let flags = SINGLE | if normals { HAS_NORMALS } else { 0 };
        raw.extend(flags.to_le_bytes());
        if version == 4 {
            raw.extend(b"tri\0");
        }
        raw.extend((p.len() as u64).to_le_bytes());
        raw.extend((tris.len() as u64).to_le_bytes());
        for v in p {
            for x in v {
                raw.extend(x.to_le_bytes());
            }
        }
        if normals {
            for _ in p {
                for x in [0.0f32, 0.0, 1.0] {
                    raw.extend(x.to_le_bytes());
                }
            }
        }
        for t in tris {
            for i in t {
                raw.extend(i.to_le_bytes());
            }
        }
        let mut out = SERIALIZED_ID.to_le_bytes().to_vec();
        out.extend(version.to_le_bytes());
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
        z.write_all(&raw).unwrap();
        out.extend(z.finish().unwrap());
        out
    }

    fn file(version: u16, shapes: &[Vec<u8>]) -> Vec<u8> {
        let mut out = Vec::new();
        let mut offsets = Vec::new();
        for s in shapes {
            offsets.push(out.len() as u64);
            out.extend(s);
        }
        for o in offsets {
            if version == 4 {
                out.extend(o.to_le_bytes());
            } else {
                out.extend((o as u32).to_le_bytes());
            }
        }
        out.extend((shapes.len() as u32).to_le_bytes());
        out
    }

    #[test]
    fn serialized_shapes_by_index() {
        for version in [3u16, 4] {
            let a = shape(
                version,
                &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                &[[0, 1, 2]],
                true,
            );
            let b = shape(
                version,
                &[[0.0; 3], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0]],
                &[[0, 1, 2], [0, 2, 3]],
                false,
            );
            let f = file(version, &[a, b]);
            let (p, n, _, idx) = read_serialized(&f, 0).unwrap();
            assert_eq!((p.len(), idx.len()), (3, 1));
            assert!(n.is_some());
            let (p, n, _, idx) = read_serialized(&f, 1).unwrap();
            assert_eq!((p.len(), idx.len()), (4, 2));
            assert_eq!(p[2], Vec3::new(2.0, 2.0, 0.0));
            assert!(n.is_none());
            let e = read_serialized(&f, 2).unwrap_err();
            assert!(e.contains("out of range"), "{e}");
        }
    }

    /// A small file that really inflates to more vertices than the limit (1.5 MB inflating to
    /// 100 M vertices took 3.5 GB before the limit): refused from its counts, before inflating.
    #[test]
    fn a_decompression_bomb_is_refused_from_its_counts() {
        let nv = crate::desc::limits::MAX_MESH_ELEMENTS + 1;
        let mut raw = Vec::new();
        raw.extend(SINGLE.to_le_bytes());
        raw.extend(nv.to_le_bytes());
        raw.extend(1u64.to_le_bytes());
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
        z.write_all(&raw).unwrap();
        let zeros = vec![0u8; 1 << 20];
        for _ in 0..(nv * 12 + 12) >> 20 {
            z.write_all(&zeros).unwrap();
        }
        let mut shape = SERIALIZED_ID.to_le_bytes().to_vec();
        shape.extend(3u16.to_le_bytes());
        shape.extend(z.finish().unwrap());
        let f = file(3, &[shape]);
        assert!(f.len() < 1 << 20, "{} bytes", f.len());
        let e = read_serialized(&f, 0).unwrap_err();
        assert_eq!(
            e,
            "shape 0: 33554433 vertices and 1 triangles exceed the limit of 33554432 each"
        );
    }

    #[test]
    fn damaged_serialized_is_an_error() {
        let s = shape(
            4,
            &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[[0, 1, 5]],
            false,
        );
        let f = file(4, std::slice::from_ref(&s));
        assert!(read_serialized(&f, 0).unwrap_err().contains("vertex 5"));
        let good = shape(
            4,
            &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[[0, 1, 2]],
            false,
        );
        let f = file(4, &[good]);
        for cut in [1, 5, 13, f.len() / 2, f.len() - 1] {
            assert!(read_serialized(&f[..cut], 0).is_err());
        }
        let mut bad = f.clone();
        bad[0] = 0;
        assert!(read_serialized(&bad, 0).is_err());
        // A corrupted compressed stream.
        let mut bad = f.clone();
        for b in &mut bad[6..12] {
            *b ^= 0x5a;
        }
        assert!(read_serialized(&bad, 0).is_err());
    }
}
