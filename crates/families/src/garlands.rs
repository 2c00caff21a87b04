//! The hall's emissive garlands (`hall.rs`): strands of small emissive triangles hung between
//! two anchors with a sag, each one OBJ mesh. Three styles:
//!
//! - **bulbs**: small octahedra (8 triangles, radius 3–6 cm) spaced along the strand, each
//!   hanging a little below it;
//! - **rope**: a thin triangular tube (radius 1.5–3 cm, 6 triangles per segment) along the strand;
//! - **strip**: a flat ribbon (width 4–10 cm, 2 triangles per segment) facing down.
//!
//! A garland has exactly the number of triangles asked for (the last bulb or segment may be
//! incomplete); every triangle faces outward (bulbs, rope) or down (strip), since emitters emit
//! on their front side only.

use glam::Vec3;
use restir_sampling::Pcg32;

use super::util::{round, uniform};

/// The style of a garland.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Style {
    Bulbs,
    Rope,
    Strip,
}

impl Style {
    pub(super) fn name(self) -> &'static str {
        match self {
            Style::Bulbs => "bulbs",
            Style::Rope => "rope",
            Style::Strip => "strip",
        }
    }
}

/// A strand from `a` to `b` sagging by `sag` at its middle (a parabola, close to a catenary at
/// these sags).
#[derive(Clone, Copy, Debug)]
pub(super) struct Strand {
    pub a: Vec3,
    pub b: Vec3,
    pub sag: f32,
}

impl Strand {
    fn at(&self, t: f32) -> Vec3 {
        self.a.lerp(self.b, t) - Vec3::Y * (4.0 * self.sag * t * (1.0 - t))
    }

    fn tangent(&self, t: f32) -> Vec3 {
        ((self.b - self.a) - Vec3::Y * (4.0 * self.sag * (1.0 - 2.0 * t))).normalize()
    }
}

/// Triangles being built: positions and index triples.
#[derive(Default)]
struct Builder {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
}

impl Builder {
    fn vertex(&mut self, p: Vec3) -> u32 {
        self.positions.push(p);
        self.positions.len() as u32 - 1
    }

    /// Adds the triangle, wound so that its normal points along `outward`.
    fn triangle(&mut self, [a, b, c]: [u32; 3], outward: Vec3) {
        let [pa, pb, pc] = [a, b, c].map(|i| self.positions[i as usize]);
        if (pb - pa).cross(pc - pa).dot(outward) >= 0.0 {
            self.triangles.push([a, b, c]);
        } else {
            self.triangles.push([a, c, b]);
        }
    }
}

/// A garland of exactly `count` triangles along `strand`; returns positions, triangles and the
/// total area (of the positions as written, rounded to 4 decimals).
pub(super) fn garland(
    rng: &mut Pcg32,
    style: Style,
    strand: &Strand,
    count: usize,
) -> (Vec<Vec3>, Vec<[u32; 3]>, f32) {
    let mut b = Builder::default();
    match style {
        Style::Bulbs => {
            let r = uniform(rng, 0.03, 0.06);
            let bulbs = count.div_ceil(8).max(1);
            for j in 0..bulbs {
                let t = (j as f32 + 0.5) / bulbs as f32;
                let centre = strand.at(t) - Vec3::Y * uniform(rng, r, 3.0 * r);
                let yaw = uniform(rng, 0.0, core::f32::consts::FRAC_PI_2);
                let (s, c) = yaw.sin_cos();
                let axes = [Vec3::new(c, 0.0, s), Vec3::Y, Vec3::new(-s, 0.0, c)];
                let mut v = [[0u32; 2]; 3];
                for (k, axis) in axes.iter().enumerate() {
                    v[k] = [b.vertex(centre + r * *axis), b.vertex(centre - r * *axis)];
                }
                for face in 0..8 {
                    let pick = |k: usize| (face >> k) & 1;
                    let tri = [v[0][pick(0)], v[1][pick(1)], v[2][pick(2)]];
                    let outward = [0, 1, 2]
                        .map(|k| if pick(k) == 0 { axes[k] } else { -axes[k] })
                        .into_iter()
                        .sum::<Vec3>();
                    b.triangle(tri, outward);
                }
            }
        }
        Style::Rope => {
            let r = uniform(rng, 0.015, 0.03);
            let segments = count.div_ceil(6).max(1);
            let ring = |t: f32| {
                let p = strand.at(t);
                let tangent = strand.tangent(t);
                let n = tangent.cross(Vec3::Y).normalize_or(Vec3::X);
                let m = n.cross(tangent);
                (
                    p,
                    [0, 1, 2].map(|k| {
                        let a = k as f32 * core::f32::consts::TAU / 3.0;
                        p + r * (a.cos() * n + a.sin() * m)
                    }),
                )
            };
            let mut previous = ring(0.0);
            let mut prev_ids = previous.1.map(|p| b.vertex(p));
            for j in 1..=segments {
                let next = ring(j as f32 / segments as f32);
                let ids = next.1.map(|p| b.vertex(p));
                let axis = 0.5 * (previous.0 + next.0);
                for k in 0..3 {
                    let k1 = (k + 1) % 3;
                    let side =
                        0.25 * (previous.1[k] + previous.1[k1] + next.1[k] + next.1[k1]) - axis;
                    b.triangle([prev_ids[k], prev_ids[k1], ids[k1]], side);
                    b.triangle([prev_ids[k], ids[k1], ids[k]], side);
                }
                previous = next;
                prev_ids = ids;
            }
        }
        Style::Strip => {
            let w = uniform(rng, 0.02, 0.05);
            let segments = count.div_ceil(2).max(1);
            let edge = |t: f32| {
                let p = strand.at(t);
                let side = strand.tangent(t).cross(Vec3::Y).normalize_or(Vec3::X);
                [p - w * side, p + w * side]
            };
            let mut prev = edge(0.0).map(|p| b.vertex(p));
            for j in 1..=segments {
                let next = edge(j as f32 / segments as f32).map(|p| b.vertex(p));
                b.triangle([prev[0], prev[1], next[1]], -Vec3::Y);
                b.triangle([prev[0], next[1], next[0]], -Vec3::Y);
                prev = next;
            }
        }
    }
    b.triangles.truncate(count);
    compact(&b.positions, &b.triangles)
}

/// Keeps only the vertices the triangles use, rounded as the OBJ file writes them; returns the
/// positions, the renumbered triangles and their total area.
fn compact(positions: &[Vec3], triangles: &[[u32; 3]]) -> (Vec<Vec3>, Vec<[u32; 3]>, f32) {
    let mut remap = vec![u32::MAX; positions.len()];
    let mut kept = Vec::new();
    let mut out = Vec::with_capacity(triangles.len());
    let mut area = 0.0;
    for tri in triangles {
        let tri = tri.map(|v| {
            if remap[v as usize] == u32::MAX {
                remap[v as usize] = kept.len() as u32;
                kept.push(positions[v as usize].to_array().map(|x| round(x, 4)).into());
            }
            remap[v as usize]
        });
        let [a, b, c]: [Vec3; 3] = tri.map(|v| kept[v as usize]);
        area += 0.5 * (b - a).cross(c - a).length();
        out.push(tri);
    }
    (kept, out, area)
}

/// The garland as OBJ text (positions to 4 decimals, 1-based faces).
pub(super) fn obj(name: &str, positions: &[Vec3], triangles: &[[u32; 3]]) -> String {
    use core::fmt::Write;
    let mut text = format!(
        "# {name}: {} emissive triangles of a garland, generated by restir_families (hall)\no {name}\n",
        triangles.len()
    );
    for p in positions {
        let _ = writeln!(text, "v {} {} {}", p.x, p.y, p.z);
    }
    for [a, b, c] in triangles {
        let _ = writeln!(text, "f {} {} {}", a + 1, b + 1, c + 1);
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_style_has_the_count_asked_for_and_faces_outward_or_down() {
        let strand = Strand {
            a: Vec3::new(-2.0, 4.0, 0.0),
            b: Vec3::new(2.0, 4.2, 0.5),
            sag: 0.6,
        };
        for style in [Style::Bulbs, Style::Rope, Style::Strip] {
            for count in [1, 7, 8, 9, 250, 601] {
                let mut rng = Pcg32::new(3, 4);
                let (p, t, area) = garland(&mut rng, style, &strand, count);
                assert_eq!(t.len(), count, "{style:?}");
                assert!(area > 0.0);
                assert!(t.iter().flatten().all(|&v| (v as usize) < p.len()));
                let corners = |tri: &[u32; 3]| tri.map(|v| p[v as usize]);
                match style {
                    Style::Strip => {
                        for tri in &t {
                            let [a, b, c] = corners(tri);
                            assert!((b - a).cross(c - a).y < 0.0, "strip faces down");
                        }
                    }
                    // With few segments a segment's chord strays from the curve, so the
                    // curve's nearest point stands for the axis only when segments are short.
                    Style::Rope if count >= 60 => {
                        for tri in &t {
                            let [a, b, c] = corners(tri);
                            let centre = (a + b + c) / 3.0;
                            let axis = (0..=400)
                                .map(|i| strand.at(i as f32 / 400.0))
                                .min_by(|x, y| {
                                    (*x - centre).length().total_cmp(&(*y - centre).length())
                                })
                                .unwrap();
                            let n = (b - a).cross(c - a);
                            assert!(n.dot(centre - axis) > 0.0, "rope faces outward");
                        }
                    }
                    Style::Rope => {}
                    Style::Bulbs => {
                        // Each whole bulb is a closed octahedron: outward faces give it a
                        // positive signed volume (divergence theorem).
                        for bulb in t.chunks_exact(8) {
                            let volume: f32 = bulb
                                .iter()
                                .map(|tri| {
                                    let [a, b, c] = corners(tri);
                                    a.dot(b.cross(c)) / 6.0
                                })
                                .sum();
                            assert!(volume > 0.0, "bulb faces outward ({volume})");
                        }
                    }
                }
            }
        }
    }
}
