//! Mesh file readers besides OBJ: PLY (ASCII and binary) and Mitsuba's `.serialized` format.
//!
//! Both return positions, optional normals, optional uvs and triangles in object space; the
//! builder applies `to_world`, `flip_normals` and `face_normals`. Every malformed input is an
//! error message (the builder prefixes the scene file and line), never a panic; sizes read from a
//! file are checked against the bytes actually present before anything is allocated.

use std::io::Read;

use glam::{Vec2, Vec3};

/// Positions, optional normals, optional uvs and triangles of a mesh file.
pub(crate) type MeshData = (
    Vec<Vec3>,
    Option<Vec<Vec3>>,
    Option<Vec<Vec2>>,
    Vec<[u32; 3]>,
);

// ---------------------------------------------------------------------------------------------
// PLY

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for a list property.
    list: Option<Scalar>,
    ty: Scalar,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Format {
    Ascii,
    Little,
    Big,
}

/// Reads values one at a time from a PLY body.
struct Body<'a> {
    format: Format,
    bytes: &'a [u8],
    pos: usize,
    tokens: std::str::SplitAsciiWhitespace<'a>,
}

impl Body<'_> {
    fn read(&mut self, ty: Scalar) -> Result<f64, String> {
        if self.format == Format::Ascii {
            let t = self
                .tokens
                .next()
                .ok_or("the file ends before all elements are read (truncated?)")?;
            return t
                .parse::<f64>()
                .map_err(|_| format!("cannot parse \"{t}\" as a number"));
        }
        let n = ty.size();
        let b = self
            .bytes
            .get(self.pos..self.pos + n)
            .ok_or("the file ends before all elements are read (truncated?)")?;
        self.pos += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.format == Format::Big {
            a[..n].reverse();
        }
        Ok(match ty {
            Scalar::I8 => a[0] as i8 as f64,
            Scalar::U8 => a[0] as f64,
            Scalar::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(a),
        })
    }
}

/// Reads a PLY file: vertex `x, y, z` with optional `nx, ny, nz` and `u, v` (or `s, t`,
/// `texture_u, texture_v`), and faces as `vertex_indices` (or `vertex_index`) lists, polygons
/// triangulated as fans. Other elements and properties are skipped.
pub(crate) fn read_ply(bytes: &[u8]) -> Result<MeshData, String> {
    // Header: ASCII lines up to `end_header`.
    let end = find(bytes, b"end_header").ok_or("not a PLY file (no end_header)")?;
    let mut body_start = end + b"end_header".len();
    // The body begins after the line break that ends the header line.
    if bytes.get(body_start) == Some(&b'\r') {
        body_start += 1;
    }
    if bytes.get(body_start) == Some(&b'\n') {
        body_start += 1;
    }
    let header = std::str::from_utf8(&bytes[..end]).map_err(|_| "PLY header is not text")?;
    let mut lines = header.lines().map(str::trim);
    if lines.next() != Some("ply") {
        return Err("not a PLY file (it does not start with 'ply')".into());
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    for line in lines {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            [] | ["comment", ..] | ["obj_info", ..] => {}
            ["format", f, _version] => {
                format = Some(match *f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Little,
                    "binary_big_endian" => Format::Big,
                    other => return Err(format!("unknown PLY format '{other}'")),
                })
            }
            ["element", name, count] => elements.push(Element {
                name: name.to_string(),
                count: count
                    .parse()
                    .map_err(|_| format!("bad PLY element count \"{count}\""))?,
                props: Vec::new(),
            }),
            ["property", "list", ct, it, name] => {
                let e = elements
                    .last_mut()
                    .ok_or("PLY property before any element")?;
                let list = Scalar::parse(ct).ok_or(format!("unknown PLY type '{ct}'"))?;
                let ty = Scalar::parse(it).ok_or(format!("unknown PLY type '{it}'"))?;
                e.props.push(Property {
                    name: name.to_string(),
                    list: Some(list),
                    ty,
                });
            }
            ["property", ty, name] => {
                let e = elements
                    .last_mut()
                    .ok_or("PLY property before any element")?;
                let ty = Scalar::parse(ty).ok_or(format!("unknown PLY type '{ty}'"))?;
                e.props.push(Property {
                    name: name.to_string(),
                    list: None,
                    ty,
                });
            }
            _ => return Err(format!("cannot parse PLY header line \"{line}\"")),
        }
    }
    let format = format.ok_or("PLY header has no 'format' line")?;
    let data = &bytes[body_start.min(bytes.len())..];
    let text = if format == Format::Ascii {
        std::str::from_utf8(data).map_err(|_| "ASCII PLY body is not text")?
    } else {
        ""
    };
    let mut body = Body {
        format,
        bytes: data,
        pos: 0,
        tokens: text.split_ascii_whitespace(),
    };
    // Every value takes at least one byte, which bounds the counts before allocating.
    let cap = |n: usize| n.min(data.len());

    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut indices: Vec<[u32; 3]> = Vec::new();
    let mut saw_vertex = false;
    for e in &elements {
        if e.name == "vertex" {
            if saw_vertex {
                return Err("PLY file has two vertex elements".into());
            }
            saw_vertex = true;
            let idx = |names: &[&str]| {
                names.iter().find_map(|n| {
                    e.props
                        .iter()
                        .position(|p| p.name == *n && p.list.is_none())
                })
            };
            let (Some(x), Some(y), Some(z)) = (idx(&["x"]), idx(&["y"]), idx(&["z"])) else {
                return Err("PLY vertices need x, y and z".into());
            };
            let n = match (idx(&["nx"]), idx(&["ny"]), idx(&["nz"])) {
                (Some(a), Some(b), Some(c)) => Some([a, b, c]),
                _ => None,
            };
            let t = match (
                idx(&["u", "s", "texture_u", "texture_s"]),
                idx(&["v", "t", "texture_v", "texture_t"]),
            ) {
                (Some(a), Some(b)) => Some([a, b]),
                _ => None,
            };
            positions.reserve(cap(e.count));
            let mut vals = vec![0.0f64; e.props.len()];
            for _ in 0..e.count {
                for (k, p) in e.props.iter().enumerate() {
                    vals[k] = match p.list {
                        None => body.read(p.ty)?,
                        Some(ct) => {
                            let len = body.read(ct)?;
                            for _ in 0..list_len(len)? {
                                body.read(p.ty)?;
                            }
                            0.0
                        }
                    };
                }
                positions.push(Vec3::new(vals[x] as f32, vals[y] as f32, vals[z] as f32));
                if let Some([a, b, c]) = n {
                    normals.push(Vec3::new(vals[a] as f32, vals[b] as f32, vals[c] as f32));
                }
                if let Some([a, b]) = t {
                    uvs.push(Vec2::new(vals[a] as f32, vals[b] as f32));
                }
            }
        } else if e.name == "face" {
            let list = e
                .props
                .iter()
                .position(|p| {
                    p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index")
                })
                .ok_or("PLY faces need a vertex_indices list")?;
            indices.reserve(cap(e.count));
            let mut poly: Vec<u32> = Vec::new();
            for f in 0..e.count {
                for (k, p) in e.props.iter().enumerate() {
                    match p.list {
                        None => {
                            body.read(p.ty)?;
                        }
                        Some(ct) => {
                            let len = list_len(body.read(ct)?)?;
                            poly.clear();
                            for _ in 0..len {
                                let v = body.read(p.ty)?;
                                if k == list {
                                    if !(v >= 0.0 && v < u32::MAX as f64 && v.fract() == 0.0) {
                                        return Err(format!("face {f}: bad vertex index {v}"));
                                    }
                                    poly.push(v as u32);
                                }
                            }
                            if k == list {
                                if poly.len() < 3 {
                                    return Err(format!(
                                        "face {f} has {} vertices (at least 3 needed)",
                                        poly.len()
                                    ));
                                }
                                for i in 1..poly.len() - 1 {
                                    indices.push([poly[0], poly[i], poly[i + 1]]);
                                }
                            }
                        }
                    }
                }
            }
        } else if !e.props.is_empty() {
            // (An element without properties occupies no bytes, whatever its count: skipping it
            // must not take `count` steps.)
            for _ in 0..e.count {
                for p in &e.props {
                    match p.list {
                        None => {
                            body.read(p.ty)?;
                        }
                        Some(ct) => {
                            for _ in 0..list_len(body.read(ct)?)? {
                                body.read(p.ty)?;
                            }
                        }
                    }
                }
            }
        }
    }
    finish(positions, normals, uvs, indices)
}

fn list_len(v: f64) -> Result<usize, String> {
    if v >= 0.0 && v.fract() == 0.0 && v < 1e6 {
        Ok(v as usize)
    } else {
        Err(format!("bad PLY list length {v}"))
    }
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// Checks indices and attribute counts and assembles the result.
fn finish(
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    indices: Vec<[u32; 3]>,
) -> Result<MeshData, String> {
    if indices.is_empty() {
        return Err("the mesh has no triangles".into());
    }
    let n = positions.len();
    if let Some((i, t)) = indices
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&v| v as usize >= n))
    {
        return Err(format!(
            "triangle {i} refers to vertex {} but there are only {n} vertices",
            t.iter().max().copied().unwrap_or(0)
        ));
    }
    if positions.iter().any(|p| !p.is_finite()) {
        return Err("the mesh has non-finite vertex positions".into());
    }
    let normals = (normals.len() == n && normals.iter().all(|v| v.is_finite())).then_some(normals);
    let uvs = (uvs.len() == n && uvs.iter().all(|v| v.is_finite())).then_some(uvs);
    Ok((positions, normals, uvs, indices))
}

// ---------------------------------------------------------------------------------------------
// Mitsuba .serialized

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
    fn bytes(&mut self, n: u64) -> Result<Vec<u8>, String> {
        if n > self.budget {
            return Err(format!(
                "shape {}: the file claims more data than it holds (truncated or damaged)",
                self.index
            ));
        }
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

    const ASCII_QUAD: &str = "ply\nformat ascii 1.0\ncomment hi\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float s\nproperty float t\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n";

    #[test]
    fn ascii_quad_is_two_triangles() {
        let (p, n, uv, idx) = read_ply(ASCII_QUAD.as_bytes()).unwrap();
        assert_eq!(p.len(), 4);
        assert!(n.is_none());
        assert_eq!(uv.unwrap()[2], Vec2::new(1.0, 1.0));
        assert_eq!(idx, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn binary_ply_with_normals() {
        let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n".to_vec();
        for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            for x in v.iter().chain(&[0.0, 0.0, 1.0]) {
                b.extend(x.to_le_bytes());
            }
        }
        b.push(3);
        for i in [0u32, 1, 2] {
            b.extend(i.to_le_bytes());
        }
        let (p, n, _, idx) = read_ply(&b).unwrap();
        assert_eq!(p[1], Vec3::X);
        assert_eq!(n.unwrap()[0], Vec3::Z);
        assert_eq!(idx, vec![[0, 1, 2]]);
        // Truncated: an error, not a panic.
        let e = read_ply(&b[..b.len() - 3]).unwrap_err();
        assert!(e.contains("truncated"), "{e}");
    }

    #[test]
    fn bad_ply_is_an_error() {
        let bad = ASCII_QUAD.replace("4 0 1 2 3", "3 0 1 7");
        assert!(read_ply(bad.as_bytes()).unwrap_err().contains("vertex 7"));
        assert!(read_ply(b"ply\nformat ascii 1.0\nelement vertex 99999999999\n").is_err());
        assert!(read_ply(b"hello").is_err());
        let huge = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
        assert!(read_ply(huge.as_bytes()).is_err());
    }

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
