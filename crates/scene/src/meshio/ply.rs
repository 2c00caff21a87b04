//! PLY meshes, ASCII and binary (little- and big-endian): vertex positions, optional normals and
//! uvs, polygon faces fanned into triangles, and the other vertex and face properties as mesh
//! attributes ([`super::ply_attributes`]). Sizes read from the header are checked against the
//! bytes present before anything is allocated.

use glam::{Vec2, Vec3};
use restir_geometry::MeshAttribute;

use super::ply_attributes::{Group, groups};
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
    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
    /// The largest value of an integer type.
    fn max(self) -> f64 {
        match self {
            Scalar::I8 => i8::MAX as f64,
            Scalar::U8 => u8::MAX as f64,
            Scalar::I16 => i16::MAX as f64,
            Scalar::U16 => u16::MAX as f64,
            Scalar::I32 => i32::MAX as f64,
            Scalar::U32 | Scalar::F32 | Scalar::F64 => u32::MAX as f64,
        }
    }
    /// A property value as a mesh attribute holds it. Mitsuba 3 reads every integer PLY
    /// property as a normalised sRGB-encoded value: divided by the type's largest value, then
    /// decoded to linear (so 8-bit colours mean what they mean in an 8-bit image); floats are
    /// used as they are.
    fn attribute_value(self, raw: f64) -> f32 {
        if self.is_integer() {
            restir_image::srgb::decode((raw / self.max()) as f32)
        } else {
            raw as f32
        }
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

/// The attributes of one element being read: the groups and each one's values so far.
struct Attributes {
    groups: Vec<Group>,
    values: Vec<Vec<f32>>,
}

impl Attributes {
    fn of(kind: &str, e: &Element) -> Self {
        let props: Vec<(&str, bool)> = e
            .props
            .iter()
            .map(|p| (p.name.as_str(), p.list.is_some()))
            .collect();
        let groups = groups(kind, &props);
        let values = groups.iter().map(|_| Vec::new()).collect();
        Self { groups, values }
    }

    /// Appends one row per group from an element's values `vals`, `times` times.
    fn push(&mut self, e: &Element, vals: &[f64], times: usize) {
        for (g, out) in self.groups.iter().zip(&mut self.values) {
            for _ in 0..times {
                out.extend(
                    g.fields
                        .iter()
                        .map(|&k| e.props[k].ty.attribute_value(vals[k])),
                );
            }
        }
    }

    fn finish(self, out: &mut Vec<MeshAttribute>) -> Result<(), String> {
        for (g, values) in self.groups.into_iter().zip(self.values) {
            out.push(
                MeshAttribute::new(&g.name, g.fields.len(), values).map_err(|e| e.to_string())?,
            );
        }
        Ok(())
    }
}

/// Reads a PLY file: vertex `x, y, z` with optional `nx, ny, nz` and `u, v` (or `s, t`,
/// `texture_u, texture_v`), and faces as `vertex_indices` (or `vertex_index`) lists, polygons
/// triangulated as fans (each triangle of a polygon gets the polygon's face attributes). The
/// other vertex and face properties become mesh attributes as Mitsuba 3 groups them; other
/// elements are skipped.
pub(crate) fn read_ply(bytes: &[u8]) -> Result<(MeshData, Vec<MeshAttribute>), String> {
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
    let mut attributes = Vec::new();
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
            let mut attrs = Attributes::of("vertex_", e);
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
                attrs.push(e, &vals, 1);
            }
            attrs.finish(&mut attributes)?;
        } else if e.name == "face" {
            let list = e
                .props
                .iter()
                .position(|p| {
                    p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index")
                })
                .ok_or("PLY faces need a vertex_indices list")?;
            indices.reserve(cap(e.count));
            let mut attrs = Attributes::of("face_", e);
            let mut vals = vec![0.0f64; e.props.len()];
            let mut poly: Vec<u32> = Vec::new();
            for f in 0..e.count {
                for (k, p) in e.props.iter().enumerate() {
                    match p.list {
                        None => {
                            vals[k] = body.read(p.ty)?;
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
                attrs.push(e, &vals, poly.len().saturating_sub(2));
            }
            attrs.finish(&mut attributes)?;
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
    Ok((finish(positions, normals, uvs, indices)?, attributes))
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
        let ((p, n, uv, idx), attrs) = read_ply(ASCII_QUAD.as_bytes()).unwrap();
        assert!(attrs.is_empty());
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
        let ((p, n, _, idx), _) = read_ply(&b).unwrap();
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

    /// Vertex and face properties become attributes: 8-bit values normalised and sRGB-decoded
    /// (Mitsuba's reading of integer properties), floats as they are; a polygon's face row is
    /// repeated for each triangle of its fan.
    #[test]
    fn vertex_and_face_attributes_ascii() {
        let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nproperty float temp_0\nelement face 2\nproperty list uchar int vertex_indices\nproperty float weight_0\nproperty float n_x\nproperty float n_y\nproperty float n_z\nend_header\n0 0 0 255 0 128 0.5\n1 0 0 0 255 0 1.5\n1 1 0 0 0 255 2.5\n0 1 0 10 20 30 3.5\n4 0 1 2 3 0.25 1 2 3\n3 0 2 3 0.75 4 5 6\n";
        let ((_, _, _, idx), attrs) = read_ply(ply.as_bytes()).unwrap();
        assert_eq!(idx.len(), 3);
        let names: Vec<&str> = attrs.iter().map(|a| a.name()).collect();
        assert_eq!(
            names,
            ["vertex_color", "vertex_temp", "face_weight", "face_n"]
        );
        let srgb = |c: f32| restir_image::srgb::decode(c / 255.0);
        let color = attrs[0].values();
        assert_eq!(attrs[0].channels(), 3);
        assert_eq!(&color[..3], &[1.0, 0.0, srgb(128.0)]);
        assert_eq!(&color[9..], &[srgb(10.0), srgb(20.0), srgb(30.0)]);
        assert!((srgb(128.0) - 0.2158605).abs() < 1e-6);
        assert_eq!(attrs[1].values(), &[0.5, 1.5, 2.5, 3.5]);
        // The quad is two triangles, each with the quad's row.
        assert_eq!(attrs[2].values(), &[0.25, 0.25, 0.75]);
        assert_eq!(attrs[3].channels(), 3);
        assert_eq!(attrs[3].values()[6..], [4.0, 5.0, 6.0]);
    }

    /// The same in a binary file, with 16-bit and float values.
    #[test]
    fn vertex_and_face_attributes_binary() {
        let mut b = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty ushort k_0\nelement face 1\nproperty list uchar uint vertex_indices\nproperty uchar r\nproperty uchar g\nproperty uchar b\nend_header\n".to_vec();
        for (v, k) in [
            ([0.0f32, 0.0, 0.0], 0u16),
            ([1.0, 0.0, 0.0], 65535),
            ([0.0, 1.0, 0.0], 1000),
        ] {
            for x in v {
                b.extend(x.to_be_bytes());
            }
            b.extend(k.to_be_bytes());
        }
        b.push(3);
        for i in [0u32, 1, 2] {
            b.extend(i.to_be_bytes());
        }
        b.extend([255, 0, 64]);
        let ((_, _, _, idx), attrs) = read_ply(&b).unwrap();
        assert_eq!(idx, vec![[0, 1, 2]]);
        assert_eq!(attrs[0].name(), "vertex_k");
        let k = attrs[0].values();
        assert_eq!(k[..2], [0.0, 1.0]);
        assert_eq!(k[2], restir_image::srgb::decode((1000.0 / 65535.0) as f32));
        assert_eq!(attrs[1].name(), "face_color");
        assert_eq!(
            attrs[1].values(),
            &[1.0, 0.0, restir_image::srgb::decode(64.0 / 255.0)]
        );
        // Truncated inside the face attributes: an error.
        assert!(
            read_ply(&b[..b.len() - 1])
                .unwrap_err()
                .contains("truncated")
        );
    }
}
