//! PLY meshes, ASCII and binary (little- and big-endian): vertex positions, optional normals and
//! uvs, and polygon faces fanned into triangles. Sizes read from the header are checked against
//! the bytes present before anything is allocated.

use glam::{Vec2, Vec3};

use super::{MeshData, finish};

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
