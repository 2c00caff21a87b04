//! Indexed triangle meshes in world space: vertices, optional normals and texture coordinates,
//! per-triangle areas for uniform area sampling, and the errors that make a mesh unusable.

use glam::{Affine3A, Vec2, Vec3};
use restir_sampling::Distribution1D;

use crate::attribute::{AttributeError, AttributeRate, MeshAttribute};

/// Why a mesh is unusable.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshError {
    /// A face refers to a vertex that does not exist.
    IndexOutOfRange {
        /// The face.
        face: usize,
        /// The index it holds.
        index: u32,
        /// How many vertices there are.
        vertex_count: usize,
    },
    /// A position, normal or uv is NaN or infinite.
    NonFinite {
        /// Which attribute.
        attribute: &'static str,
        /// Its index.
        index: usize,
    },
    /// Normals or uvs are given but not one per vertex.
    AttributeCount {
        /// Which attribute.
        attribute: &'static str,
        /// How many there are.
        count: usize,
        /// How many vertices there are.
        vertex_count: usize,
    },
    /// The mesh has no triangles.
    Empty,
    /// Every triangle of the mesh has zero area (see [`TriangleMesh::drop_degenerate`]).
    AllDegenerate {
        /// How many triangles there were.
        count: usize,
    },
}

impl core::fmt::Display for MeshError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            MeshError::IndexOutOfRange {
                face,
                index,
                vertex_count,
            } => write!(
                f,
                "face {face} refers to vertex {index}, but the mesh has {vertex_count} vertices"
            ),
            MeshError::NonFinite { attribute, index } => {
                write!(f, "{attribute} {index} is not a finite number")
            }
            MeshError::AttributeCount {
                attribute,
                count,
                vertex_count,
            } => write!(
                f,
                "the mesh has {count} {attribute} for {vertex_count} vertices"
            ),
            MeshError::Empty => write!(f, "the mesh has no triangles"),
            MeshError::AllDegenerate { count } => write!(
                f,
                "all {count} triangles of the mesh have zero area (collinear or coincident corners)"
            ),
        }
    }
}

impl std::error::Error for MeshError {}

/// An indexed triangle mesh in world space, with an area table for uniform point sampling.
#[derive(Clone, Debug)]
pub struct TriangleMesh {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
    indices: Vec<[u32; 3]>,
    flip_normals: bool,
    area: f32,
    area_distribution: Option<Distribution1D>,
    /// Per triangle, what a surface lookup needs that depends on the triangle alone.
    faces: Vec<Face>,
    /// Named per-vertex and per-face values (Mitsuba's mesh attributes), usually none.
    attributes: Vec<MeshAttribute>,
}

/// The per-triangle part of a surface lookup, computed once when the mesh is built, transformed
/// or trimmed (the same operations a lookup did, so the same bits): the unit geometric normal
/// (flipped with the mesh; zero for a degenerate triangle) and `dp/du` (from the texture
/// coordinates, or the first edge without them).
#[derive(Clone, Copy, Debug)]
struct Face {
    ng: Vec3,
    dpdu: Vec3,
}

impl TriangleMesh {
    /// Validates and builds a mesh. Degenerate (zero-area) triangles are kept for intersection but
    /// never sampled. With `flip_normals`, geometric and shading normals point the other way.
    pub fn new(
        positions: Vec<Vec3>,
        normals: Option<Vec<Vec3>>,
        uvs: Option<Vec<Vec2>>,
        indices: Vec<[u32; 3]>,
        flip_normals: bool,
    ) -> Result<Self, MeshError> {
        if indices.is_empty() {
            return Err(MeshError::Empty);
        }
        let n = positions.len();
        for (i, p) in positions.iter().enumerate() {
            if !p.is_finite() {
                return Err(MeshError::NonFinite {
                    attribute: "position",
                    index: i,
                });
            }
        }
        if let Some(ns) = &normals {
            if ns.len() != n {
                return Err(MeshError::AttributeCount {
                    attribute: "normals",
                    count: ns.len(),
                    vertex_count: n,
                });
            }
            if let Some(i) = ns.iter().position(|v| !v.is_finite()) {
                return Err(MeshError::NonFinite {
                    attribute: "normal",
                    index: i,
                });
            }
        }
        if let Some(uv) = &uvs {
            if uv.len() != n {
                return Err(MeshError::AttributeCount {
                    attribute: "uvs",
                    count: uv.len(),
                    vertex_count: n,
                });
            }
            if let Some(i) = uv.iter().position(|v| !v.is_finite()) {
                return Err(MeshError::NonFinite {
                    attribute: "uv",
                    index: i,
                });
            }
        }
        for (f, tri) in indices.iter().enumerate() {
            for &index in tri {
                if index as usize >= n {
                    return Err(MeshError::IndexOutOfRange {
                        face: f,
                        index,
                        vertex_count: n,
                    });
                }
            }
        }
        // Normalise vertex normals; a zero normal falls back to the face normal at lookup time.
        let normals = normals.map(|ns| ns.into_iter().map(|v| v.normalize_or_zero()).collect());
        let mut mesh = Self {
            positions,
            normals,
            uvs,
            indices,
            flip_normals,
            area: 0.0,
            area_distribution: None,
            faces: Vec::new(),
            attributes: Vec::new(),
        };
        mesh.update_tables();
        Ok(mesh)
    }

    /// The area table and the per-triangle faces, after the triangles changed.
    fn update_tables(&mut self) {
        self.faces = (0..self.indices.len()).map(|i| self.face(i)).collect();
        let areas: Vec<f32> = (0..self.indices.len())
            .map(|i| self.triangle_area(i))
            .map(|a| if a.is_finite() { a } else { 0.0 })
            .collect();
        self.area = areas.iter().map(|&a| a as f64).sum::<f64>() as f32;
        self.area_distribution = Distribution1D::new(&areas);
    }

    /// Applies an affine transform to positions (and the inverse transpose to normals).
    pub fn transform(&mut self, m: &Affine3A) {
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        if let Some(ns) = &mut self.normals {
            let nm = glam::Mat3::from(m.matrix3).inverse().transpose();
            for n in ns {
                *n = (nm * *n).normalize_or_zero();
            }
        }
        // A mirroring transform turns the winding inside out; keep normals pointing the way the
        // transformed shape's outside points, as Mitsuba does.
        if m.matrix3.determinant() < 0.0 {
            for tri in &mut self.indices {
                tri.swap(1, 2);
            }
        }
        self.update_tables();
    }

    /// Gives a mesh read without normals smooth ones, as Mitsuba 3 and Lajolla do for a mesh
    /// file that has none (unless it asks for face normals): [`angle_weighted_normals`] of the
    /// positions as they are now, so called on world-space meshes, after
    /// [`TriangleMesh::transform`]. A vertex that no triangle with an area meets gets a zero
    /// normal, which a lookup replaces by the face normal.
    pub fn compute_vertex_normals(&mut self) {
        self.normals = Some(angle_weighted_normals(&self.positions, &self.indices));
    }

    /// Removes the triangles of zero area (collinear or coincident corners: they can never be
    /// sampled and are hit only through rounding), returning how many there were. Called on
    /// world-space meshes, after [`TriangleMesh::transform`]; a mesh with nothing else is an error.
    /// Nothing changes, not even the area table, when every triangle has an area.
    pub fn drop_degenerate(&mut self) -> Result<usize, MeshError> {
        let keep: Vec<bool> = (0..self.indices.len())
            .map(|i| self.triangle_area(i) > 0.0)
            .collect();
        let dropped = keep.iter().filter(|&&k| !k).count();
        if dropped == 0 {
            return Ok(0);
        }
        if dropped == self.indices.len() {
            return Err(MeshError::AllDegenerate { count: dropped });
        }
        let mut k = keep.iter();
        self.indices.retain(|_| *k.next().unwrap_or(&true));
        for a in &mut self.attributes {
            a.retain_faces(&keep);
        }
        self.update_tables();
        Ok(dropped)
    }

    /// The mesh with `attributes` attached (replacing any it had): each has one row per vertex
    /// or per triangle, as its name says, and names are distinct.
    pub fn with_attributes(
        mut self,
        attributes: Vec<MeshAttribute>,
    ) -> Result<Self, AttributeError> {
        for (i, a) in attributes.iter().enumerate() {
            let rows = match a.rate() {
                AttributeRate::Vertex => self.positions.len(),
                AttributeRate::Face => self.indices.len(),
            };
            if a.values().len() != rows * a.channels() {
                return Err(AttributeError::Rows {
                    name: a.name().into(),
                    values: a.values().len(),
                    channels: a.channels(),
                    rows,
                });
            }
            if attributes[..i].iter().any(|b| b.name() == a.name()) {
                return Err(AttributeError::Duplicate(a.name().into()));
            }
        }
        self.attributes = attributes;
        Ok(self)
    }

    /// The mesh's named attributes.
    pub fn attributes(&self) -> &[MeshAttribute] {
        &self.attributes
    }

    /// Attribute `k` of [`TriangleMesh::attributes`] on triangle `prim` at barycentrics `b`
    /// ([`MeshAttribute::eval`]).
    #[inline]
    pub fn eval_attribute(&self, k: usize, prim: u32, b: Vec2) -> Vec3 {
        self.attributes[k].eval(self.indices[prim as usize], prim, b)
    }

    /// Vertex positions.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }
    /// Per-vertex shading normals, if any.
    pub fn normals(&self) -> Option<&[Vec3]> {
        self.normals.as_deref()
    }
    /// Per-vertex texture coordinates, if any.
    pub fn uvs(&self) -> Option<&[Vec2]> {
        self.uvs.as_deref()
    }
    /// Triangles as vertex index triples.
    pub fn indices(&self) -> &[[u32; 3]] {
        &self.indices
    }
    /// Whether normals are flipped.
    pub fn flip_normals(&self) -> bool {
        self.flip_normals
    }
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }
    /// Total surface area.
    pub fn area(&self) -> f32 {
        self.area
    }

    /// The three corners of triangle `i`.
    #[inline]
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        let [a, b, c] = self.indices[i];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// Area of triangle `i`.
    pub fn triangle_area(&self, i: usize) -> f32 {
        let [p0, p1, p2] = self.triangle(i);
        0.5 * (p1 - p0).cross(p2 - p0).length()
    }

    /// The unit geometric normal of triangle `i` (zero for a degenerate triangle).
    #[inline]
    pub fn face_normal(&self, i: usize) -> Vec3 {
        self.faces[i].ng
    }

    /// The `dp/du` of triangle `i` that shading frames take their first tangent from
    /// ([`TriangleMesh::surface_at`]).
    #[inline]
    pub fn face_dpdu(&self, i: usize) -> Vec3 {
        self.faces[i].dpdu
    }

    /// Triangle `i`'s geometric normal and `dp/du`, computed from its corners.
    fn face(&self, i: usize) -> Face {
        let [ia, ib, ic] = self.indices[i];
        let [p0, p1, p2] = self.triangle(i);
        let n = (p1 - p0).cross(p2 - p0).normalize_or_zero();
        let ng = if self.flip_normals { -n } else { n };
        let dpdu = match &self.uvs {
            Some(uvs) => {
                let (t0, t1, t2) = (uvs[ia as usize], uvs[ib as usize], uvs[ic as usize]);
                let (d1, d2) = (t1 - t0, t2 - t0);
                let det = d1.x * d2.y - d1.y * d2.x;
                if det.abs() > 1e-12 {
                    ((p1 - p0) * d2.y - (p2 - p0) * d1.y) / det
                } else {
                    p1 - p0
                }
            }
            None => p1 - p0,
        };
        Face { ng, dpdu }
    }

    /// Triangle `i`'s partial derivatives `(dp/du, dp/dv)` in its texture coordinates, as
    /// Mitsuba 3's mesh computes them: the edges `p1 − p0`, `p2 − p0` taken to the `uv` basis
    /// (both zero when the `uv` triangle is degenerate), or the edges themselves without texture
    /// coordinates (the parametrisation is then barycentric).
    pub fn uv_derivatives(&self, i: usize) -> (Vec3, Vec3) {
        let [p0, p1, p2] = self.triangle(i);
        let (e1, e2) = (p1 - p0, p2 - p0);
        let Some(uvs) = &self.uvs else {
            return (e1, e2);
        };
        let [ia, ib, ic] = self.indices[i];
        let t0 = uvs[ia as usize];
        let (d1, d2) = (uvs[ib as usize] - t0, uvs[ic as usize] - t0);
        let det = d1.x * d2.y - d1.y * d2.x;
        let inv = if det != 0.0 { 1.0 / det } else { 0.0 };
        ((e1 * d2.y - e2 * d1.y) * inv, (e2 * d1.x - e1 * d2.x) * inv)
    }

    /// Point, geometric normal and shading normal at barycentrics `b = (b1, b2)` of triangle `i`
    /// (the cheaper part of [`TriangleMesh::surface_at`], for light sampling).
    #[inline(always)]
    pub fn point_at(&self, i: usize, b: Vec2) -> (Vec3, Vec3, Vec3) {
        let [ia, ib, ic] = self.indices[i];
        let (p0, p1, p2) = (
            self.positions[ia as usize],
            self.positions[ib as usize],
            self.positions[ic as usize],
        );
        let b0 = 1.0 - b.x - b.y;
        let p = b0 * p0 + b.x * p1 + b.y * p2;
        let ng = self.faces[i].ng;
        let ns = match &self.normals {
            Some(ns) => {
                let n = (b0 * ns[ia as usize] + b.x * ns[ib as usize] + b.y * ns[ic as usize])
                    .normalize_or_zero();
                if n == Vec3::ZERO {
                    ng
                } else if self.flip_normals {
                    -n
                } else {
                    n
                }
            }
            None => ng,
        };
        (p, ng, ns)
    }

    /// Point, geometric normal, shading normal, uv and `dp/du` at barycentrics `b = (b1, b2)` of
    /// triangle `i`.
    #[inline(always)]
    pub fn surface_at(&self, i: usize, b: Vec2) -> (Vec3, Vec3, Vec3, Vec2, Vec3) {
        let (p, ng, ns) = self.point_at(i, b);
        (p, ng, ns, self.uv_at(i, b), self.faces[i].dpdu)
    }

    /// The texture coordinates at barycentrics `b` of triangle `i` (the barycentrics themselves
    /// for a mesh without texture coordinates).
    #[inline(always)]
    pub fn uv_at(&self, i: usize, b: Vec2) -> Vec2 {
        match &self.uvs {
            Some(uvs) => {
                let [ia, ib, ic] = self.indices[i];
                let (t0, t1, t2) = (uvs[ia as usize], uvs[ib as usize], uvs[ic as usize]);
                let b0 = 1.0 - b.x - b.y;
                b0 * t0 + b.x * t1 + b.y * t2
            }
            None => b,
        }
    }

    /// Picks a triangle proportionally to area and a uniform point on it. Returns the triangle,
    /// its barycentrics and the area pdf `1 / total area`. `None` if the mesh has no area.
    #[inline]
    pub fn sample_point(&self, u: Vec2) -> Option<(usize, Vec2, f32)> {
        let dist = self.area_distribution.as_ref()?;
        let (tri, _pmf, ux) = dist.sample_discrete(u.x);
        let b = restir_sampling::warp::sample_uniform_triangle(Vec2::new(ux, u.y));
        Some((tri, b, 1.0 / self.area))
    }
}

/// Vertex normals from the faces: each triangle's unit normal (its winding's, `(p1 − p0) ×
/// (p2 − p0)`), weighted by the triangle's angle at the vertex, summed and normalised
/// (Thürmer and Wüthrich, "Computing vertex normals from polygonal facets", JGT 1998, the
/// weighting Mitsuba 3 uses). Triangles of zero area add nothing; a vertex that only they
/// meet gets a zero normal.
pub fn angle_weighted_normals(positions: &[Vec3], indices: &[[u32; 3]]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for tri in indices {
        let p = tri.map(|i| positions[i as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let len2 = n.length_squared();
        if !(len2 > 0.0 && len2.is_finite()) {
            continue;
        }
        let n = n / len2.sqrt();
        for k in 0..3 {
            let a = (p[(k + 1) % 3] - p[k]).normalize_or_zero();
            let b = (p[(k + 2) % 3] - p[k]).normalize_or_zero();
            normals[tri[k] as usize] += n * unit_angle(a, b);
        }
    }
    for n in &mut normals {
        *n = n.normalize_or_zero();
    }
    normals
}

/// The angle between unit vectors `a` and `b`, accurate near 0 and π (from the chord `|a ∓ b|`
/// rather than the cosine, whose `acos` loses digits there).
fn unit_angle(a: Vec3, b: Vec3) -> f32 {
    if a.dot(b) < 0.0 {
        std::f32::consts::PI - 2.0 * (0.5 * (a + b).length()).min(1.0).asin()
    } else {
        2.0 * (0.5 * (a - b).length()).min(1.0).asin()
    }
}

#[cfg(test)]
mod normal_tests {
    use super::*;

    /// A fan around the origin in the plane z = 0 and one face tilted out of it.
    fn fan() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let p = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(0.0, -1.0, 1.0),
        ];
        (p, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]])
    }

    #[test]
    fn planar_faces_keep_their_normal() {
        let (p, idx) = fan();
        let n = angle_weighted_normals(&p, &idx[..2]);
        for (i, n) in n[..4].iter().enumerate() {
            assert_eq!(*n, Vec3::Z, "vertex {i}");
        }
        // A vertex no triangle uses.
        assert_eq!(n[4], Vec3::ZERO);
    }

    #[test]
    fn faces_weigh_by_their_angle_at_the_vertex() {
        let (p, idx) = fan();
        let n = angle_weighted_normals(&p, &idx);
        // At the centre: two right angles of +z and the tilted face's angle (between −x and
        // (0, −1, 1)/√2: 90°) of its normal.
        let tilted = (p[3] - p[0]).cross(p[4] - p[0]).normalize();
        let expected =
            (Vec3::Z * std::f32::consts::PI + tilted * std::f32::consts::FRAC_PI_2).normalize();
        assert!((n[0] - expected).length() < 1e-6, "{} vs {expected}", n[0]);
        // The corner at (−1, 0, 0): the second face's 45° and the tilted face's acos(1/√3)
        // (between (1, 0, 0) and (1, −1, 1)).
        let w2 = std::f32::consts::FRAC_PI_4;
        let w3 = (1.0 / 3f32.sqrt()).acos();
        let expected = (Vec3::Z * w2 + tilted * w3).normalize();
        assert!((n[3] - expected).length() < 1e-6, "{} vs {expected}", n[3]);
    }

    #[test]
    fn zero_area_triangles_add_nothing() {
        let (mut p, mut idx) = fan();
        p.push(Vec3::new(2.0, 0.0, 0.0));
        idx.push([0, 1, 5]);
        let with = angle_weighted_normals(&p, &idx);
        let without = angle_weighted_normals(&p, &idx[..3]);
        assert_eq!(with[..5], without[..5]);
        assert_eq!(with[5], Vec3::ZERO);
    }

    #[test]
    fn unit_angle_is_accurate_at_both_ends() {
        let a = Vec3::X;
        let tiny = Vec3::new(1.0, 1e-4, 0.0).normalize();
        assert!((unit_angle(a, tiny) - 1e-4).abs() < 1e-9);
        let opposite = Vec3::new(-1.0, 1e-4, 0.0).normalize();
        assert!((unit_angle(a, opposite) - (std::f32::consts::PI - 1e-4)).abs() < 1e-6);
        assert!((unit_angle(a, Vec3::Y) - std::f32::consts::FRAC_PI_2).abs() < 4e-7);
    }

    #[test]
    fn a_sphere_gets_its_radial_normals() {
        // A UV sphere of 16 × 8 quads with shared vertices: each computed normal lies within
        // six degrees of the radial direction, the normal of the sphere the facets approximate.
        let (p, idx) = restir_testkit::meshes::uv_sphere(Vec3::ZERO, 1.0, 16, 8);
        let n = angle_weighted_normals(&p, &idx);
        for (i, (n, p)) in n.iter().zip(&p).enumerate() {
            assert!(n.dot(*p) > 0.995, "vertex {i}: {n} against {p}");
        }
    }
}
