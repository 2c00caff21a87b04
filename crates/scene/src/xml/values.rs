//! Parsing property values: numbers, 3-vectors, `x= y= z=` points, sRGB hex colours and
//! `<transform>` steps. Every failure is an error located at the element that holds the value.

use roxmltree::Node;

use super::source::Source;
use super::{Result, snake_case};
use crate::desc::{TransformOp, limits};

/// Numbers separated by commas and/or whitespace.
pub(super) fn parse_numbers(s: &str) -> Option<Vec<f64>> {
    s.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| t.parse::<f64>().ok())
        .collect()
}

impl Source<'_> {
    pub(super) fn finite(&self, node: Node, v: f64, what: &str) -> Result<f64> {
        if !v.is_finite() {
            Err(self.err(node, format!("{what} is not a finite number")))
        } else if !(v as f32).is_finite() {
            // Values are stored as f32: 1e39 would become infinite.
            Err(self.err(
                node,
                format!("{what} is out of range (beyond ±3.4e38, the largest 32-bit float)"),
            ))
        } else {
            Ok(v)
        }
    }

    /// `v` unless it lies beyond the coordinate limit ([`limits::MAX_COORDINATE`]).
    fn within_limit(&self, node: Node, v: [f32; 3], what: &str) -> Result<[f32; 3]> {
        match v.iter().find_map(|&x| limits::coordinate_problem(x)) {
            Some(problem) => Err(self.err(node, format!("{what}: {problem}"))),
            None => Ok(v),
        }
    }

    pub(super) fn parse_float(&self, node: Node, s: &str) -> Result<f64> {
        let v = s
            .trim()
            .parse::<f64>()
            .map_err(|_| self.err(node, format!("cannot parse \"{s}\" as a number")))?;
        self.finite(node, v, &format!("\"{s}\""))
    }

    pub(super) fn parse_vec3(&self, node: Node, s: &str) -> Result<[f32; 3]> {
        let v = parse_numbers(s)
            .ok_or_else(|| self.err(node, format!("cannot parse \"{s}\" as numbers")))?;
        for x in &v {
            self.finite(node, *x, &format!("\"{s}\""))?;
        }
        match v.len() {
            1 => Ok([v[0] as f32; 3]),
            3 => Ok([v[0] as f32, v[1] as f32, v[2] as f32]),
            n => Err(self.err(
                node,
                format!("expected 1 or 3 numbers, found {n} in \"{s}\""),
            )),
        }
    }

    /// A point/vector given as `x= y= z=` attributes or as `value="x, y, z"`.
    pub(super) fn xyz(&self, node: Node, default: f32) -> Result<[f32; 3]> {
        if let Some(v) = self.attr(node, "value")? {
            return self.parse_vec3(node, &v);
        }
        let mut out = [default; 3];
        for (i, k) in ["x", "y", "z"].iter().enumerate() {
            if let Some(v) = self.attr(node, k)? {
                out[i] = self.parse_float(node, &v)? as f32;
            }
        }
        Ok(out)
    }

    pub(super) fn parse_transform(&self, node: Node) -> Result<Vec<TransformOp>> {
        let mut ops = Vec::new();
        for c in node.children().filter(Node::is_element) {
            let tag = snake_case(c.tag_name().name()).replace('_', "");
            let op = match tag.as_str() {
                "translate" => {
                    TransformOp::Translate(self.within_limit(c, self.xyz(c, 0.0)?, "translate")?)
                }
                "scale" => TransformOp::Scale(self.within_limit(c, self.xyz(c, 1.0)?, "scale")?),
                "rotate" => {
                    let axis = match self.attr(c, "axis")? {
                        Some(a) => self.parse_vec3(c, &a)?,
                        None => self.xyz(c, 0.0)?,
                    };
                    let angle = self.parse_float(c, &self.req_attr(c, "angle")?)? as f32;
                    if axis == [0.0; 3] {
                        return Err(self.err(c, "rotation axis is zero"));
                    }
                    TransformOp::Rotate { axis, angle }
                }
                "lookat" => {
                    let origin = self.parse_vec3(c, &self.req_attr(c, "origin")?)?;
                    let origin = self.within_limit(c, origin, "lookat origin")?;
                    let target = self.parse_vec3(c, &self.req_attr(c, "target")?)?;
                    let target = self.within_limit(c, target, "lookat target")?;
                    let up = match self.attr(c, "up")? {
                        Some(u) => self.parse_vec3(c, &u)?,
                        None => [0.0, 1.0, 0.0],
                    };
                    let op = TransformOp::LookAt { origin, target, up };
                    crate::desc::transform_matrix(std::slice::from_ref(&op))
                        .map_err(|e| self.err(c, e.to_string()))?;
                    op
                }
                "matrix" => {
                    let s = self.req_attr(c, "value")?;
                    let v = parse_numbers(&s)
                        .ok_or_else(|| self.err(c, format!("cannot parse matrix \"{s}\"")))?;
                    for x in &v {
                        self.finite(c, *x, "matrix entry")?;
                        self.within_limit(c, [*x as f32; 3], "matrix entry")?;
                    }
                    let m: [f32; 16] = match v.len() {
                        16 => core::array::from_fn(|i| v[i] as f32),
                        9 => {
                            let mut m = [0.0; 16];
                            for r in 0..3 {
                                for col in 0..3 {
                                    m[r * 4 + col] = v[r * 3 + col] as f32;
                                }
                            }
                            m[15] = 1.0;
                            m
                        }
                        n => {
                            return Err(
                                self.err(c, format!("a matrix needs 16 (or 9) numbers, found {n}"))
                            );
                        }
                    };
                    TransformOp::Matrix(m)
                }
                other => {
                    return Err(self.err(c, format!("unknown transform step <{other}>")));
                }
            };
            ops.push(op);
        }
        Ok(ops)
    }

    pub(super) fn srgb_hex(&self, node: Node, s: &str) -> Result<[f32; 3]> {
        let h = s.trim().trim_start_matches('#');
        if h.len() != 6 || !h.chars().all(|c| c.is_ascii_hexdigit()) {
            return Err(self.err(
                node,
                format!("cannot parse sRGB colour \"{s}\" (expected #rrggbb)"),
            ));
        }
        let byte = |i: usize| u8::from_str_radix(&h[i..i + 2], 16).unwrap_or(0) as f32 / 255.0;
        let lin = |c: f32| {
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        };
        Ok([lin(byte(0)), lin(byte(2)), lin(byte(4))])
    }
}
