//! Importer for the Mitsuba-style XML scene format used by Mitsuba 0.6/3 and Lajolla.
//!
//! Accepts both camelCase (Mitsuba 0.6, Lajolla: `toWorld`, `maxDepth`) and snake_case (Mitsuba 3)
//! names. `<default name= value=>` declares variables that `$name` in any attribute refers to;
//! `-D name=value` on the command line overrides them. Relative paths are relative to the XML file.
//!
//! Unknown *properties* are warnings with `file:line` (legacy files carry many that do not matter,
//! such as `nearClip`); unknown *plugin types* and malformed values are errors with `file:line`.

use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::path::Path;

use roxmltree::{Document, Node};

use crate::desc::*;
use crate::spectrum::{self, SpectrumUse};
use crate::texture::{TextureDesc, UvTransform};
use crate::{SceneError, SceneWarning};

type Result<T> = core::result::Result<T, SceneError>;

/// Converts a camelCase name to snake_case (`toWorld` → `to_world`, `intIOR` → `int_ior`).
pub fn snake_case(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    let chars: Vec<char> = name.chars().collect();
    for (i, &c) in chars.iter().enumerate() {
        if c.is_ascii_uppercase() {
            if i > 0 && chars[i - 1].is_ascii_lowercase() {
                out.push('_');
            }
            out.push(c.to_ascii_lowercase());
        } else {
            out.push(c);
        }
    }
    out
}

#[derive(Clone, Debug)]
enum Value {
    Float(f64),
    Int(i64),
    Bool(bool),
    Str(String),
    Rgb([f32; 3]),
    /// `<spectrum value="v"/>`: a constant spectrum.
    SpectrumConst(f32),
    /// `<spectrum value="λ1:v1, λ2:v2, …"/>`: a sampled spectrum (nm, value).
    Spectrum(Vec<(f64, f64)>),
    Point([f32; 3]),
    Transform(Vec<TransformOp>),
}

impl Value {
    fn kind(&self) -> &'static str {
        match self {
            Value::Float(_) => "float",
            Value::Int(_) => "integer",
            Value::Bool(_) => "boolean",
            Value::Str(_) => "string",
            Value::Rgb(_) => "rgb",
            Value::SpectrumConst(_) | Value::Spectrum(_) => "spectrum",
            Value::Point(_) => "point",
            Value::Transform(_) => "transform",
        }
    }
}

struct Prop<'a, 'i> {
    name: String,
    value: Value,
    node: Node<'a, 'i>,
    used: Cell<bool>,
}

/// How a colour is used: reflectances are bounded to [0, 1], emission converts constant spectra
/// through Mitsuba's emitter path.
#[derive(Clone, Copy, PartialEq, Eq)]
enum ColorUse {
    Reflectance,
    Emission,
    /// Unbounded non-negative parameters (conductor `eta`/`k`): taken as given.
    Unbounded,
}

/// XYZ → linear sRGB of an equal-energy (constant 1) emission spectrum, as Mitsuba 3's RGB mode
/// computes it (`xyz_to_srgb(1, 1, 1)`).
const EQUAL_ENERGY_RGB: [f32; 3] = [1.204_79, 0.948_291, 0.908_916];

struct Props<'a, 'i> {
    what: String,
    items: Vec<Prop<'a, 'i>>,
}

struct Importer<'a, 'i> {
    file: &'a Path,
    doc: &'a Document<'i>,
    defaults: HashMap<String, String>,
    warnings: RefCell<Vec<SceneWarning>>,
    /// Top-level bsdf ids, with the line that declares them.
    bsdf_ids: HashMap<String, u32>,
    bsdf_anon: usize,
    /// Top-level textures by id, with the line that declares them.
    textures: HashMap<String, (TextureDesc, u32)>,
}

fn parse_numbers(s: &str) -> Option<Vec<f64>> {
    s.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| t.parse::<f64>().ok())
        .collect()
}

impl<'a, 'i> Importer<'a, 'i> {
    fn loc(&self, node: Node) -> Location {
        Location {
            file: self.file.to_path_buf(),
            line: self.doc.text_pos_at(node.range().start).row,
        }
    }

    fn err(&self, node: Node, msg: impl Into<String>) -> SceneError {
        SceneError::new(self.loc(node), msg)
    }

    fn warn(&self, node: Node, msg: impl Into<String>) {
        let location = self.loc(node);
        self.warnings.borrow_mut().push(SceneWarning {
            location,
            message: msg.into(),
        });
    }

    /// Replaces `$name` references with `<default>` values.
    fn subst(&self, node: Node, s: &str) -> Result<String> {
        if !s.contains('$') {
            return Ok(s.to_string());
        }
        let mut out = String::new();
        let mut rest = s;
        while let Some(pos) = rest.find('$') {
            out.push_str(&rest[..pos]);
            let after = &rest[pos + 1..];
            let len = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            let name = &after[..len];
            if name.is_empty() {
                return Err(self.err(node, format!("'$' without a variable name in \"{s}\"")));
            }
            let value = self.defaults.get(name).ok_or_else(|| {
                self.err(
                    node,
                    format!("undefined variable ${name} (declare it with <default name=\"{name}\" value=\"…\"/> or -D {name}=…)"),
                )
            })?;
            out.push_str(value);
            rest = &after[len..];
        }
        out.push_str(rest);
        Ok(out)
    }

    fn attr(&self, node: Node, name: &str) -> Result<Option<String>> {
        match node.attribute(name) {
            Some(v) => Ok(Some(self.subst(node, v)?)),
            None => Ok(None),
        }
    }

    fn req_attr(&self, node: Node, name: &str) -> Result<String> {
        self.attr(node, name)?.ok_or_else(|| {
            self.err(
                node,
                format!("<{}> needs a '{name}' attribute", node.tag_name().name()),
            )
        })
    }

    fn finite(&self, node: Node, v: f64, what: &str) -> Result<f64> {
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

    fn parse_float(&self, node: Node, s: &str) -> Result<f64> {
        let v = s
            .trim()
            .parse::<f64>()
            .map_err(|_| self.err(node, format!("cannot parse \"{s}\" as a number")))?;
        self.finite(node, v, &format!("\"{s}\""))
    }

    fn parse_vec3(&self, node: Node, s: &str) -> Result<[f32; 3]> {
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
    fn xyz(&self, node: Node, default: f32) -> Result<[f32; 3]> {
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

    fn parse_transform(&self, node: Node) -> Result<Vec<TransformOp>> {
        let mut ops = Vec::new();
        for c in node.children().filter(Node::is_element) {
            let tag = snake_case(c.tag_name().name()).replace('_', "");
            let op = match tag.as_str() {
                "translate" => TransformOp::Translate(self.xyz(c, 0.0)?),
                "scale" => TransformOp::Scale(self.xyz(c, 1.0)?),
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
                    let target = self.parse_vec3(c, &self.req_attr(c, "target")?)?;
                    let up = match self.attr(c, "up")? {
                        Some(u) => self.parse_vec3(c, &u)?,
                        None => [0.0, 1.0, 0.0],
                    };
                    let op = TransformOp::LookAt { origin, target, up };
                    crate::transform_matrix(std::slice::from_ref(&op))
                        .map_err(|e| self.err(c, e))?;
                    op
                }
                "matrix" => {
                    let s = self.req_attr(c, "value")?;
                    let v = parse_numbers(&s)
                        .ok_or_else(|| self.err(c, format!("cannot parse matrix \"{s}\"")))?;
                    for x in &v {
                        self.finite(c, *x, "matrix entry")?;
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

    fn srgb_hex(&self, node: Node, s: &str) -> Result<[f32; 3]> {
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

    /// Reads the property children of a plugin element; nested plugins are left to the caller.
    fn props(&self, plugin: Node<'a, 'i>, what: String) -> Result<Props<'a, 'i>> {
        let mut items = Vec::new();
        for c in plugin.children().filter(Node::is_element) {
            let tag = c.tag_name().name();
            if !PROPERTY_TAGS.contains(&tag) {
                continue;
            }
            let name = self.req_attr(c, "name")?;
            // Value errors name the property: `<float name="alpha">: "abc" is not a number`.
            let named = |mut e: SceneError| {
                e.message = format!("<{tag} name=\"{name}\">: {}", e.message);
                e
            };
            let value = (|| -> Result<Value> {
                Ok(match tag {
                    "float" => Value::Float(self.parse_float(c, &self.req_attr(c, "value")?)?),
                    "integer" => {
                        let s = self.req_attr(c, "value")?;
                        let v = s.trim().parse::<i64>().map_err(|_| {
                            self.err(c, format!("cannot parse \"{s}\" as an integer"))
                        })?;
                        Value::Int(v)
                    }
                    "boolean" => {
                        let s = self.req_attr(c, "value")?;
                        match s.trim().to_ascii_lowercase().as_str() {
                            "true" | "1" => Value::Bool(true),
                            "false" | "0" => Value::Bool(false),
                            _ => {
                                return Err(
                                    self.err(c, format!("cannot parse \"{s}\" as a boolean"))
                                );
                            }
                        }
                    }
                    "string" => Value::Str(self.req_attr(c, "value")?),
                    "rgb" | "color" => Value::Rgb(self.parse_vec3(c, &self.req_attr(c, "value")?)?),
                    "srgb" => Value::Rgb(self.srgb_hex(c, &self.req_attr(c, "value")?)?),
                    "spectrum" => {
                        let s = self.req_attr(c, "value")?;
                        if s.contains(':') {
                            Value::Spectrum(
                                crate::spectrum::parse_pairs(&s).map_err(|e| self.err(c, e))?,
                            )
                        } else {
                            Value::SpectrumConst(self.parse_float(c, &s)? as f32)
                        }
                    }
                    "point" | "vector" => Value::Point(self.xyz(c, 0.0)?),
                    "transform" => Value::Transform(self.parse_transform(c)?),
                    other => return Err(self.err(c, format!("<{other}> is not a property"))),
                })
            })()
            .map_err(named)?;
            items.push(Prop {
                name: snake_case(&name),
                value,
                node: c,
                used: Cell::new(false),
            });
        }
        Ok(Props { what, items })
    }

    /// Warns about properties nobody read.
    fn finish(&mut self, props: Props) {
        for p in props.items.iter().filter(|p| !p.used.get()) {
            self.warn(
                p.node,
                format!("{} ignores property '{}'", props.what, p.name),
            );
        }
    }
}

impl Props<'_, '_> {
    fn get(&self, name: &str) -> Option<&Prop<'_, '_>> {
        let p = self.items.iter().rev().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    fn type_err(&self, imp: &Importer, p: &Prop, want: &str) -> SceneError {
        imp.err(
            p.node,
            format!(
                "{}: property '{}' must be {want}, not {}",
                self.what,
                p.name,
                p.value.kind()
            ),
        )
    }

    fn float(&self, imp: &Importer, name: &str) -> Result<Option<f32>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Float(v) => Ok(Some(v as f32)),
                Value::Int(v) => Ok(Some(v as f32)),
                _ => Err(self.type_err(imp, p, "a float")),
            },
        }
    }

    fn int(&self, imp: &Importer, name: &str) -> Result<Option<i64>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Int(v) => Ok(Some(v)),
                Value::Float(v) if v.fract() == 0.0 => Ok(Some(v as i64)),
                _ => Err(self.type_err(imp, p, "an integer")),
            },
        }
    }

    fn bool(&self, imp: &Importer, name: &str) -> Result<Option<bool>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Bool(v) => Ok(Some(v)),
                _ => Err(self.type_err(imp, p, "a boolean")),
            },
        }
    }

    fn string(&self, imp: &Importer, name: &str) -> Result<Option<String>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Str(v) => Ok(Some(v.clone())),
                _ => Err(self.type_err(imp, p, "a string")),
            },
        }
    }

    fn point(&self, imp: &Importer, name: &str) -> Result<Option<[f32; 3]>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Point(v) | Value::Rgb(v) => Ok(Some(v)),
                _ => Err(self.type_err(imp, p, "a point or vector")),
            },
        }
    }

    fn transform(&self, imp: &Importer, name: &str) -> Result<Vec<TransformOp>> {
        match self.get(name) {
            None => Ok(Vec::new()),
            Some(p) => match &p.value {
                Value::Transform(v) => Ok(v.clone()),
                _ => Err(self.type_err(imp, p, "a transform")),
            },
        }
    }

    fn color(&self, imp: &Importer, name: &str, usage: ColorUse) -> Result<Option<[f32; 3]>> {
        let Some(p) = self.get(name) else {
            return Ok(None);
        };
        let c = match &p.value {
            Value::Rgb(v) => *v,
            Value::Float(v) => [*v as f32; 3],
            Value::Int(v) => [*v as f32; 3],
            Value::SpectrumConst(v) => match usage {
                ColorUse::Reflectance | ColorUse::Unbounded => [*v; 3],
                ColorUse::Emission => EQUAL_ENERGY_RGB.map(|c| c * v),
            },
            Value::Spectrum(pairs) => {
                // MATERIALS.md §7: BSDF parameters are D65-weighted, emitters are not; bounded
                // parameters are clipped to [0, 1] with a warning, others clamped at 0.
                let su = match usage {
                    ColorUse::Emission => SpectrumUse::Emission,
                    ColorUse::Reflectance | ColorUse::Unbounded => SpectrumUse::Reflectance,
                };
                let rgb = spectrum::to_rgb(pairs, su).map(|x| x as f32);
                let hi = if usage == ColorUse::Reflectance {
                    1.0
                } else {
                    f32::INFINITY
                };
                let clipped = rgb.map(|x| x.clamp(0.0, hi));
                if clipped.iter().zip(&rgb).any(|(a, b)| (a - b).abs() > 1e-6) {
                    imp.warn(
                        p.node,
                        format!(
                            "{}: spectrum '{}' converts to RGB {rgb:?}, clipped to {clipped:?}",
                            self.what, p.name
                        ),
                    );
                }
                clipped
            }
            _ => return Err(self.type_err(imp, p, "a colour (rgb, spectrum or float)")),
        };
        if c.iter().any(|x| !x.is_finite()) {
            return Err(imp.err(p.node, format!("{}: '{}' is not finite", self.what, p.name)));
        }
        if usage == ColorUse::Reflectance && c.iter().any(|&x| !(0.0..=1.0).contains(&x)) {
            return Err(imp.err(
                p.node,
                format!(
                    "{}: reflectance '{}' = {c:?} must lie in [0, 1]",
                    self.what, p.name
                ),
            ));
        }
        if usage != ColorUse::Reflectance && c.iter().any(|&x| x < 0.0) {
            return Err(imp.err(
                p.node,
                format!("{}: '{}' = {c:?} must not be negative", self.what, p.name),
            ));
        }
        Ok(Some(c))
    }
}

fn elements<'a, 'i>(node: Node<'a, 'i>) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children().filter(Node::is_element)
}

const PROPERTY_TAGS: &[&str] = &[
    "float",
    "integer",
    "boolean",
    "string",
    "rgb",
    "color",
    "srgb",
    "spectrum",
    "point",
    "vector",
    "transform",
];

impl<'a, 'i> Importer<'a, 'i> {
    fn plugin_type(&self, node: Node) -> Result<String> {
        Ok(snake_case(&self.req_attr(node, "type")?))
    }

    fn bsdf(&mut self, node: Node<'a, 'i>) -> Result<MaterialDesc> {
        let ty = self.plugin_type(node)?;
        let props = self.props(node, format!("bsdf '{ty}'"))?;
        let nested: Vec<Node> = elements(node)
            .filter(|c| c.tag_name().name() == "bsdf")
            .collect();
        // Parameters given as textures, nested or by reference; wrapped around the material
        // below (the constant value of such a parameter is unused).
        let mut textured: Vec<(Node, TextureBinding)> = Vec::new();
        for c in elements(node) {
            let tag = c.tag_name().name();
            let (name, texture) = if tag == "texture" {
                (self.req_attr(c, "name")?, self.texture(c)?)
            } else if tag == "ref"
                && let Some(name) = self.attr(c, "name")?
            {
                let id = self.req_attr(c, "id")?;
                let (t, _) = self.textures.get(&id).ok_or_else(|| {
                    self.err(
                        c,
                        format!("bsdf '{ty}': reference to undefined texture '{id}'"),
                    )
                })?;
                (name, t.clone())
            } else {
                continue;
            };
            let name = snake_case(&name);
            let param = ColorParam::from_name(&name).ok_or_else(|| {
                self.err(
                    c,
                    format!(
                        "bsdf '{ty}': '{name}' cannot be a texture (only reflectances can: reflectance, diffuse_reflectance, specular_reflectance, specular_transmittance)"
                    ),
                )
            })?;
            if props.get(&name).is_some() {
                return Err(self.err(
                    c,
                    format!("bsdf '{ty}': '{name}' is given twice (as a value and as a texture)"),
                ));
            }
            if textured.iter().any(|(_, b)| b.param == param) {
                return Err(self.err(c, format!("bsdf '{ty}': two textures for '{name}'")));
            }
            textured.push((c, TextureBinding { param, texture }));
        }
        let m = match ty.as_str() {
            "diffuse" => {
                let r = props
                    .color(self, "reflectance", ColorUse::Reflectance)?
                    .unwrap_or([0.5; 3]);
                MaterialDesc::Diffuse { reflectance: r }
            }
            "twosided" => {
                let inner = match nested.first() {
                    // Checked before recursing, so nesting depth is bounded (a file with
                    // thousands of nested twosided elements would overflow the stack).
                    Some(n)
                        if n.attribute("type").map(snake_case).as_deref() == Some("twosided") =>
                    {
                        return Err(self.err(*n, "bsdf 'twosided' wraps another twosided"));
                    }
                    Some(n) => self.bsdf(*n)?,
                    None => {
                        self.warn(
                            node,
                            "empty twosided bsdf wraps a default diffuse (reflectance 0.5)",
                        );
                        MaterialDesc::Diffuse {
                            reflectance: [0.5; 3],
                        }
                    }
                };
                if nested.len() > 1 {
                    self.warn(nested[1], "twosided with two different bsdfs is not supported; the back side uses the front bsdf");
                }
                MaterialDesc::TwoSided(Box::new(inner))
            }
            "conductor" | "roughconductor" => {
                let ior = self.conductor_ior(&props)?;
                let specular_reflectance = props
                    .color(self, "specular_reflectance", ColorUse::Reflectance)?
                    .unwrap_or([1.0; 3]);
                if ty == "conductor" {
                    MaterialDesc::Conductor {
                        ior,
                        specular_reflectance,
                    }
                } else {
                    MaterialDesc::RoughConductor {
                        ior,
                        specular_reflectance,
                        roughness: self.roughness(node, &props, true)?,
                    }
                }
            }
            "dielectric" | "roughdielectric" => {
                let int_ior = self.ior(&props, "int_ior", BK7_IOR)?;
                let ext_ior = self.ior(&props, "ext_ior", AIR_IOR)?;
                let specular_reflectance = props
                    .color(self, "specular_reflectance", ColorUse::Reflectance)?
                    .unwrap_or([1.0; 3]);
                let specular_transmittance = props
                    .color(self, "specular_transmittance", ColorUse::Reflectance)?
                    .unwrap_or([1.0; 3]);
                if ty == "dielectric" {
                    MaterialDesc::Dielectric {
                        int_ior,
                        ext_ior,
                        specular_reflectance,
                        specular_transmittance,
                    }
                } else {
                    MaterialDesc::RoughDielectric {
                        int_ior,
                        ext_ior,
                        specular_reflectance,
                        specular_transmittance,
                        roughness: self.roughness(node, &props, true)?,
                    }
                }
            }
            "plastic" | "roughplastic" => {
                let int_ior = self.ior(&props, "int_ior", POLYPROPYLENE_IOR)?;
                let ext_ior = self.ior(&props, "ext_ior", AIR_IOR)?;
                let diffuse_reflectance = props
                    .color(self, "diffuse_reflectance", ColorUse::Reflectance)?
                    .unwrap_or([0.5; 3]);
                let specular_reflectance = props
                    .color(self, "specular_reflectance", ColorUse::Reflectance)?
                    .unwrap_or([1.0; 3]);
                let nonlinear = props.bool(self, "nonlinear")?.unwrap_or(false);
                if ty == "plastic" {
                    MaterialDesc::Plastic {
                        int_ior,
                        ext_ior,
                        diffuse_reflectance,
                        specular_reflectance,
                        nonlinear,
                    }
                } else {
                    if int_ior == ext_ior {
                        return Err(self.err(
                            node,
                            format!("bsdf 'roughplastic': int_ior and ext_ior are both {int_ior}; they must differ"),
                        ));
                    }
                    MaterialDesc::RoughPlastic {
                        int_ior,
                        ext_ior,
                        diffuse_reflectance,
                        specular_reflectance,
                        nonlinear,
                        roughness: self.roughness(node, &props, false)?,
                    }
                }
            }
            "null" => MaterialDesc::Null,
            "thindielectric" => {
                return Err(self.err(
                    node,
                    "bsdf 'thindielectric' is not supported yet (use 'dielectric' on a closed shape)",
                ));
            }
            other => return Err(self.err(node, format!("unknown bsdf type '{other}'"))),
        };
        if let MaterialDesc::TwoSided(inner) = &m
            && matches!(
                **inner,
                MaterialDesc::Dielectric { .. }
                    | MaterialDesc::RoughDielectric { .. }
                    | MaterialDesc::Null
            )
        {
            return Err(self.err(
                node,
                "twosided cannot wrap a transmitting bsdf (dielectric, roughdielectric, null), as in Mitsuba",
            ));
        }
        let m = if textured.is_empty() {
            m
        } else {
            let allowed = crate::build::color_params(&m);
            if let Some((c, b)) = textured.iter().find(|(_, b)| !allowed.contains(&b.param)) {
                return Err(self.err(
                    *c,
                    format!("bsdf '{ty}' has no parameter '{}'", b.param.name()),
                ));
            }
            MaterialDesc::Textured {
                material: Box::new(m),
                textures: textured.into_iter().map(|(_, b)| b).collect(),
            }
        };
        // Everything the builder would reject, reported here with this bsdf's line.
        crate::build::check_material(&m)
            .map_err(|e| self.err(node, format!("bsdf '{ty}': {e}")))?;
        for c in elements(node) {
            let tag = c.tag_name().name();
            if !PROPERTY_TAGS.contains(&tag) && !["bsdf", "texture", "ref"].contains(&tag) {
                return Err(self.err(c, format!("unexpected <{tag}> inside a bsdf")));
            }
            if tag == "bsdf" && ty != "twosided" {
                return Err(self.err(
                    c,
                    format!("bsdf '{ty}' takes no nested bsdf (only twosided wraps one)"),
                ));
            }
        }
        self.finish(props);
        Ok(m)
    }

    /// A `<texture>`: `bitmap` or `checkerboard`, with Mitsuba 0.6 `uscale`/`vscale`/
    /// `uoffset`/`voffset` or Mitsuba 3 `to_uv` (scale and translation only).
    fn texture(&mut self, node: Node<'a, 'i>) -> Result<TextureDesc> {
        let ty = self.plugin_type(node)?;
        let props = self.props(node, format!("texture '{ty}'"))?;
        let mut uv = UvTransform::default();
        let to_uv = props.transform(self, "to_uv")?;
        if !to_uv.is_empty() {
            let m = crate::transform_matrix(&to_uv).map_err(|e| self.err(node, e))?;
            if m.x_axis.y.abs() > 1e-6 || m.y_axis.x.abs() > 1e-6 {
                return Err(self.err(
                    node,
                    format!("texture '{ty}': to_uv may only scale and translate"),
                ));
            }
            uv.scale = glam::Vec2::new(m.x_axis.x, m.y_axis.y);
            uv.offset = glam::Vec2::new(m.w_axis.x, m.w_axis.y);
        }
        let (us, vs) = (props.float(self, "uscale")?, props.float(self, "vscale")?);
        let (uo, vo) = (props.float(self, "uoffset")?, props.float(self, "voffset")?);
        uv.scale *= glam::Vec2::new(us.unwrap_or(1.0), vs.unwrap_or(1.0));
        uv.offset += glam::Vec2::new(uo.unwrap_or(0.0), vo.unwrap_or(0.0));
        let t = match ty.as_str() {
            "bitmap" => {
                let filename = props
                    .string(self, "filename")?
                    .ok_or_else(|| self.err(node, "bitmap texture needs a 'filename'"))?;
                let path = self.file.parent().unwrap_or(Path::new("")).join(&filename);
                if !path.is_file() {
                    return Err(self.err(
                        node,
                        format!("bitmap texture: file '{}' not found", path.display()),
                    ));
                }
                let raw = props.bool(self, "raw")?.unwrap_or(false);
                if let Some(f) = props.string(self, "filter_type")?
                    && f != "bilinear"
                {
                    self.warn(
                        node,
                        format!("texture 'bitmap': filter_type '{f}' is replaced by bilinear"),
                    );
                }
                if let Some(w) = props.string(self, "wrap_mode")?
                    && w != "repeat"
                {
                    self.warn(
                        node,
                        format!("texture 'bitmap': wrap_mode '{w}' is replaced by repeat"),
                    );
                }
                TextureDesc::Bitmap { filename, raw, uv }
            }
            "checkerboard" => TextureDesc::Checkerboard {
                color0: props
                    .color(self, "color0", ColorUse::Reflectance)?
                    .unwrap_or([0.4; 3]),
                color1: props
                    .color(self, "color1", ColorUse::Reflectance)?
                    .unwrap_or([0.2; 3]),
                uv,
            },
            other => return Err(self.err(node, format!("unknown texture type '{other}'"))),
        };
        for c in elements(node) {
            let tag = c.tag_name().name();
            if !PROPERTY_TAGS.contains(&tag) {
                return Err(self.err(c, format!("unexpected <{tag}> inside a texture")));
            }
        }
        self.finish(props);
        Ok(t)
    }

    /// `int_ior`/`ext_ior`: a number or a name from Mitsuba's IOR table.
    fn ior(&self, props: &Props, name: &str, default: f32) -> Result<f32> {
        let Some(p) = props.get(name) else {
            return Ok(default);
        };
        let v = match &p.value {
            Value::Float(v) => *v as f32,
            Value::Int(v) => *v as f32,
            Value::Str(s) => restir_materials::ior::ior(s).ok_or_else(|| {
                self.err(
                    p.node,
                    format!(
                        "{}: unknown {name} material '{s}' (known: {})",
                        props.what,
                        restir_materials::ior::ior_names()
                    ),
                )
            })?,
            _ => return Err(props.type_err(self, p, "a number or an IOR name")),
        };
        if !(v.is_finite() && v > 0.0) {
            return Err(self.err(
                p.node,
                format!("{}: {name} {v} must be positive", props.what),
            ));
        }
        Ok(v)
    }

    /// Conductor `material` / `eta` / `k` (Mitsuba: `eta` with a named material is an error).
    fn conductor_ior(&self, props: &Props) -> Result<ConductorIorDesc> {
        let material_node = props.get("material").map(|p| p.node);
        let material = props.string(self, "material")?;
        let eta = props.color(self, "eta", ColorUse::Unbounded)?;
        let k = props.color(self, "k", ColorUse::Unbounded)?;
        if let (Some(name), Some(n)) = (&material, material_node) {
            if restir_materials::ior::conductor(name).is_none() {
                return Err(self.err(
                    n,
                    format!(
                        "{}: unknown conductor material '{name}' (known: {})",
                        props.what,
                        restir_materials::ior::conductor_names()
                    ),
                ));
            }
            if name != "none" && (eta.is_some() || k.is_some()) {
                return Err(self.err(
                    n,
                    format!(
                        "{}: give either material '{name}' or eta/k, not both",
                        props.what
                    ),
                ));
            }
        }
        Ok(ConductorIorDesc { material, eta, k })
    }

    /// `distribution`, `alpha` or `alpha_u`/`alpha_v`, and `sample_visible`.
    fn roughness(&mut self, node: Node, props: &Props, anisotropic: bool) -> Result<RoughnessDesc> {
        let mut r = RoughnessDesc::default();
        if let Some(p) = props.get("distribution") {
            let Value::Str(d) = &p.value else {
                return Err(props.type_err(self, p, "a string"));
            };
            r.distribution = match d.as_str() {
                "beckmann" => MicrofacetDesc::Beckmann,
                "ggx" => MicrofacetDesc::Ggx,
                other => {
                    return Err(self.err(
                        p.node,
                        format!(
                            "{}: unknown distribution '{other}' (beckmann, ggx)",
                            props.what
                        ),
                    ));
                }
            };
        }
        let alpha = |name: &str| -> Result<Option<f32>> {
            let node_of = props
                .items
                .iter()
                .rev()
                .find(|p| p.name == name)
                .map(|p| p.node);
            match props.float(self, name)? {
                Some(a) if a.is_nan() || a < 0.0 => Err(self.err(
                    node_of.unwrap_or(node),
                    format!(
                        "{}: {name} {a} must be a non-negative roughness",
                        props.what
                    ),
                )),
                a => Ok(a),
            }
        };
        let a = alpha("alpha")?;
        let au = alpha("alpha_u")?;
        let av = alpha("alpha_v")?;
        match (au, av) {
            (None, None) => r.alpha = a.unwrap_or(0.1),
            (Some(u), Some(v)) => {
                if !anisotropic {
                    return Err(self.err(
                        node,
                        format!(
                            "{}: anisotropic roughness is not supported; give 'alpha'",
                            props.what
                        ),
                    ));
                }
                if a.is_some() {
                    return Err(self.err(
                        node,
                        format!(
                            "{}: give either alpha or alpha_u/alpha_v, not both",
                            props.what
                        ),
                    ));
                }
                r.alpha_u = Some(u);
                r.alpha_v = Some(v);
            }
            _ => {
                return Err(self.err(
                    node,
                    format!("{}: alpha_u and alpha_v must be given together", props.what),
                ));
            }
        }
        if props.bool(self, "sample_visible")? == Some(false) {
            self.warn(
                node,
                format!(
                    "{}: sample_visible=false is ignored; visible normals are always sampled (the same expected image, different noise)",
                    props.what
                ),
            );
        }
        Ok(r)
    }

    fn shape(&mut self, node: Node<'a, 'i>) -> Result<ShapeDesc> {
        let ty = self.plugin_type(node)?;
        let props = self.props(node, format!("shape '{ty}'"))?;
        let geometry = match ty.as_str() {
            "rectangle" => GeometryDesc::Rectangle,
            "cube" => GeometryDesc::Cube,
            "disk" => GeometryDesc::Disk,
            "sphere" => {
                let center = props.point(self, "center")?.unwrap_or([0.0; 3]);
                let radius = props.float(self, "radius")?.unwrap_or(1.0);
                if radius <= 0.0 {
                    return Err(self.err(node, format!("sphere radius {radius} must be positive")));
                }
                GeometryDesc::Sphere { center, radius }
            }
            "obj" => {
                let f = props
                    .string(self, "filename")?
                    .ok_or_else(|| self.err(node, "obj shape needs a 'filename'"))?;
                GeometryDesc::Obj { filename: f }
            }
            "ply" => {
                let f = props
                    .string(self, "filename")?
                    .ok_or_else(|| self.err(node, "ply shape needs a 'filename'"))?;
                GeometryDesc::Ply { filename: f }
            }
            "serialized" => {
                let f = props
                    .string(self, "filename")?
                    .ok_or_else(|| self.err(node, "serialized shape needs a 'filename'"))?;
                let i = props.int(self, "shape_index")?.unwrap_or(0);
                let shape_index = u32::try_from(i).map_err(|_| {
                    self.err(
                        node,
                        format!("shape_index {i} must be a non-negative integer"),
                    )
                })?;
                GeometryDesc::Serialized {
                    filename: f,
                    shape_index,
                }
            }
            other => return Err(self.err(node, format!("unknown shape type '{other}'"))),
        };
        let to_world = props.transform(self, "to_world")?;
        let flip_normals = props.bool(self, "flip_normals")?.unwrap_or(false);
        let face_normals = props.bool(self, "face_normals")?.unwrap_or(false);
        let mut material = None;
        let mut emission = None;
        for c in elements(node) {
            match c.tag_name().name() {
                "bsdf" => {
                    if material.is_some() {
                        return Err(self.err(c, "a shape takes one bsdf"));
                    }
                    material = Some(MaterialRef::Inline(self.bsdf(c)?));
                }
                "ref" => {
                    let id = self.req_attr(c, "id")?;
                    if !self.bsdf_ids.contains_key(&id) {
                        return Err(self.err(c, format!("reference to undefined id '{id}'")));
                    }
                    if material.is_some() {
                        return Err(self.err(c, "a shape takes one bsdf"));
                    }
                    material = Some(MaterialRef::Ref(id));
                }
                "emitter" => {
                    let ety = self.plugin_type(c)?;
                    if ety != "area" {
                        return Err(
                            self.err(c, format!("shapes carry only 'area' emitters, not '{ety}'"))
                        );
                    }
                    if emission.is_some() {
                        return Err(self.err(c, "a shape takes one emitter"));
                    }
                    let ep = self.props(c, "emitter 'area'".into())?;
                    let r = ep
                        .color(self, "radiance", ColorUse::Emission)?
                        .unwrap_or([1.0; 3]);
                    self.finish(ep);
                    emission = Some(r);
                }
                t if PROPERTY_TAGS.contains(&t) => {}
                t => return Err(self.err(c, format!("unexpected <{t}> inside a shape"))),
            }
        }
        self.finish(props);
        Ok(ShapeDesc {
            geometry,
            to_world,
            material,
            emission,
            flip_normals,
            face_normals,
            location: self.loc(node),
        })
    }

    fn sensor(&mut self, node: Node<'a, 'i>, desc: &mut SceneDesc) -> Result<()> {
        let ty = self.plugin_type(node)?;
        if ty != "perspective" && ty != "thinlens" {
            return Err(self.err(node, format!("unknown sensor type '{ty}'")));
        }
        let props = self.props(node, format!("sensor '{ty}'"))?;
        let fov = props.float(self, "fov")?.unwrap_or(45.0);
        if !(fov > 0.0 && fov < 180.0) {
            let at = props.get("fov").map_or(node, |p| p.node);
            return Err(self.err(
                at,
                format!("sensor '{ty}': fov {fov} must lie in (0, 180) degrees"),
            ));
        }
        let mut cam = CameraDesc {
            fov,
            to_world: props.transform(self, "to_world")?,
            ..CameraDesc::default()
        };
        if let Some(axis) = props.string(self, "fov_axis")? {
            cam.fov_axis = match axis.as_str() {
                "x" => FovAxis::X,
                "y" => FovAxis::Y,
                "diagonal" => FovAxis::Diagonal,
                "smaller" => FovAxis::Smaller,
                "larger" => FovAxis::Larger,
                other => {
                    return Err(self.err(
                        node,
                        format!("unknown fov_axis '{other}' (x, y, diagonal, smaller, larger)"),
                    ));
                }
            };
        }
        if ty == "thinlens" {
            cam.aperture_radius = props.float(self, "aperture_radius")?.unwrap_or(0.0);
            cam.focus_distance = props.float(self, "focus_distance")?.unwrap_or(1.0);
        }
        for c in elements(node) {
            match c.tag_name().name() {
                "film" => self.film(c, &mut desc.film)?,
                "sampler" => {
                    let sty = self.plugin_type(c)?;
                    let sp = self.props(c, format!("sampler '{sty}'"))?;
                    if let Some(n) = sp.int(self, "sample_count")? {
                        if !(1..=1 << 24).contains(&n) {
                            return Err(self.err(c, format!("sample_count {n} is out of range")));
                        }
                        desc.spp = n as u32;
                    }
                    if sty != "independent" {
                        self.warn(
                            c,
                            format!("sampler '{sty}' is replaced by this renderer's own sampler"),
                        );
                    }
                    self.finish(sp);
                }
                t if PROPERTY_TAGS.contains(&t) => {}
                t => return Err(self.err(c, format!("unexpected <{t}> inside a sensor"))),
            }
        }
        // Everything the builder would reject about the camera, reported with the sensor's line.
        if let Err(e) = crate::transform_matrix(&cam.to_world).and_then(|m| {
            let axis = restir_geometry::FovAxis::X;
            let res = (desc.film.width, desc.film.height);
            restir_geometry::Camera::thin_lens(
                m,
                cam.fov,
                axis,
                res,
                cam.aperture_radius,
                cam.focus_distance,
            )
            .map(|_| ())
            .map_err(|e| e.to_string())
        }) {
            let lens = if ty == "thinlens" {
                format!(
                    " (aperture_radius {}, focus_distance {})",
                    cam.aperture_radius, cam.focus_distance
                )
            } else {
                String::new()
            };
            return Err(self.err(node, format!("sensor '{ty}': camera: {e}{lens}")));
        }
        self.finish(props);
        desc.camera = cam;
        Ok(())
    }

    fn film(&mut self, node: Node<'a, 'i>, film: &mut FilmDesc) -> Result<()> {
        let ty = self.plugin_type(node)?;
        // Mitsuba 3's hdrfilm and specfilm, Mitsuba 0.6's ldrfilm and tiledhdrfilm: all give an
        // image; the output format comes from the output file name.
        if !matches!(
            ty.as_str(),
            "hdrfilm" | "ldrfilm" | "tiledhdrfilm" | "specfilm"
        ) {
            return Err(self.err(node, format!("unknown film type '{ty}'")));
        }
        let props = self.props(node, format!("film '{ty}'"))?;
        let dim = |what: &str, d: u32| -> Result<u32> {
            match props.int(self, what)? {
                None => Ok(d),
                Some(n) if (1..=32768).contains(&n) => Ok(n as u32),
                Some(n) => Err(self.err(
                    props.get(what).map_or(node, |p| p.node),
                    format!("film {what} {n} is out of range (1..=32768)"),
                )),
            }
        };
        film.width = dim("width", 768)?;
        film.height = dim("height", 576)?;
        if film.width as u64 * film.height as u64 > 1 << 28 {
            return Err(self.err(
                node,
                format!(
                    "film resolution {}×{} has too many pixels (at most 2^28)",
                    film.width, film.height
                ),
            ));
        }
        film.filename = props.string(self, "filename")?;
        film.filter = FilterDesc::Gaussian { stddev: 0.5 };
        for c in elements(node) {
            match c.tag_name().name() {
                "rfilter" => {
                    let fty = self.plugin_type(c)?;
                    let fp = self.props(c, format!("rfilter '{fty}'"))?;
                    film.filter = match fty.as_str() {
                        "box" => {
                            // Lajolla's box filter `width`; Mitsuba's box is one pixel.
                            if let Some(w) = fp
                                .float(self, "width")?
                                .or(fp.float(self, "radius")?.map(|r| 2.0 * r))
                                && (w - 1.0).abs() > 1e-6
                            {
                                self.warn(c, format!("box filter width {w} is treated as 1 pixel"));
                            }
                            FilterDesc::Box
                        }
                        "tent" => {
                            let r = fp
                                .float(self, "radius")?
                                .or(fp.float(self, "width")?.map(|w| 0.5 * w))
                                .unwrap_or(1.0);
                            if r <= 0.0 {
                                return Err(self.err(c, "tent radius must be positive"));
                            }
                            FilterDesc::Tent { radius: r }
                        }
                        "gaussian" => {
                            let s = fp.float(self, "stddev")?.unwrap_or(0.5);
                            if s <= 0.0 {
                                return Err(self.err(c, "gaussian stddev must be positive"));
                            }
                            FilterDesc::Gaussian { stddev: s }
                        }
                        other => return Err(self.err(c, format!("unknown rfilter type '{other}'"))),
                    };
                    self.finish(fp);
                }
                t if PROPERTY_TAGS.contains(&t) => {}
                t => return Err(self.err(c, format!("unexpected <{t}> inside a film"))),
            }
        }
        self.finish(props);
        Ok(())
    }

    fn integrator(&mut self, node: Node<'a, 'i>, desc: &mut SceneDesc) -> Result<()> {
        let ty = self.plugin_type(node)?;
        let props = self.props(node, format!("integrator '{ty}'"))?;
        let mut integ = IntegratorDesc::default();
        let mut keep_params = false;
        match ty.as_str() {
            "path" | "volpath" => integ.kind = "path".into(),
            "direct" => {
                integ.kind = "path".into();
                integ.max_depth = 2;
            }
            "restir" | "restir_di" | "restir-di" => {
                integ.kind = "restir-di".into();
                keep_params = true;
            }
            "restir_pt" | "restir-pt" | "restirpt" => {
                integ.kind = "restir-pt".into();
                keep_params = true;
            }
            other => {
                self.warn(
                    node,
                    format!("unknown integrator type '{other}': using the path tracer"),
                );
                integ.kind = "path".into();
            }
        }
        if keep_params {
            // Keep every parameter but the common ones for estimators that understand them.
            for p in &props.items {
                if matches!(p.name.as_str(), "max_depth" | "rr_depth" | "hide_emitters") {
                    continue;
                }
                let v = match &p.value {
                    Value::Float(v) => v.to_string(),
                    Value::Int(v) => v.to_string(),
                    Value::Bool(v) => v.to_string(),
                    Value::Str(v) => v.clone(),
                    _ => continue,
                };
                p.used.set(true);
                integ.params.push((p.name.clone(), v));
            }
        }
        if let Some(d) = props.int(self, "max_depth")? {
            if d < -1 {
                return Err(self.err(
                    node,
                    format!("max_depth {d} must be -1 (unbounded) or non-negative"),
                ));
            }
            integ.max_depth = d.min(i32::MAX as i64) as i32;
        }
        if let Some(d) = props.int(self, "rr_depth")? {
            if d <= 0 {
                return Err(self.err(node, format!("rr_depth {d} must be positive")));
            }
            integ.rr_depth = d.min(u32::MAX as i64) as u32;
        }
        if let Some(h) = props.bool(self, "hide_emitters")? {
            integ.hide_emitters = h;
        }
        self.finish(props);
        integ.location = self.loc(node);
        desc.integrator = integ;
        Ok(())
    }

    fn emitter(&mut self, node: Node<'a, 'i>) -> Result<LightDesc> {
        let ty = self.plugin_type(node)?;
        let props = self.props(node, format!("emitter '{ty}'"))?;
        let light = match ty.as_str() {
            "point" => {
                let intensity = props
                    .color(self, "intensity", ColorUse::Emission)?
                    .unwrap_or([1.0; 3]);
                let position = match props.point(self, "position")? {
                    Some(p) => p,
                    None => {
                        let m = crate::transform_matrix(&props.transform(self, "to_world")?)
                            .map_err(|e| self.err(node, e))?;
                        m.transform_point3(glam::Vec3::ZERO).to_array()
                    }
                };
                LightDesc::Point {
                    position,
                    intensity,
                }
            }
            "directional" => {
                let irradiance = props
                    .color(self, "irradiance", ColorUse::Emission)?
                    .unwrap_or([1.0; 3]);
                let direction = match props.point(self, "direction")? {
                    Some(d) => d,
                    None => {
                        let m = crate::transform_matrix(&props.transform(self, "to_world")?)
                            .map_err(|e| self.err(node, e))?;
                        m.transform_vector3(glam::Vec3::Z).to_array()
                    }
                };
                if direction == [0.0; 3] {
                    return Err(self.err(node, "directional emitter direction is zero"));
                }
                LightDesc::Directional {
                    direction,
                    irradiance,
                }
            }
            "constant" => {
                let radiance = props
                    .color(self, "radiance", ColorUse::Emission)?
                    .unwrap_or([1.0; 3]);
                LightDesc::Constant { radiance }
            }
            "envmap" => {
                let filename = props.string(self, "filename")?.ok_or_else(|| {
                    self.err(
                        node,
                        "envmap emitter needs a 'filename' (EXR, HDR, PNG or JPEG)",
                    )
                })?;
                let scale = props.float(self, "scale")?.unwrap_or(1.0);
                if !(scale.is_finite() && scale >= 0.0) {
                    return Err(self.err(
                        node,
                        format!("envmap scale {scale} must be finite and non-negative"),
                    ));
                }
                LightDesc::Envmap {
                    filename,
                    scale,
                    to_world: props.transform(self, "to_world")?,
                    location: self.loc(node),
                }
            }
            "area" => return Err(self.err(node, "an area emitter must be inside a <shape>")),
            other => return Err(self.err(node, format!("unknown emitter type '{other}'"))),
        };
        self.finish(props);
        Ok(light)
    }
}

/// Parses a Mitsuba-style XML scene. `defines` override `<default>` values.
pub fn parse_xml(
    text: &str,
    file: &Path,
    defines: &[(String, String)],
) -> Result<(SceneDesc, Vec<SceneWarning>)> {
    let doc = Document::parse(text).map_err(|e| {
        SceneError::new(
            Location {
                file: file.to_path_buf(),
                line: e.pos().row,
            },
            format!("malformed XML: {e}"),
        )
    })?;
    let root = doc.root_element();
    let mut imp = Importer {
        file,
        doc: &doc,
        defaults: HashMap::new(),
        warnings: RefCell::new(Vec::new()),
        bsdf_ids: HashMap::new(),
        bsdf_anon: 0,
        textures: HashMap::new(),
    };
    if root.tag_name().name() != "scene" {
        return Err(imp.err(
            root,
            format!(
                "expected a <scene> root element, found <{}>",
                root.tag_name().name()
            ),
        ));
    }
    // Defaults first (the command line wins), so that `$name` works anywhere.
    for c in elements(root).filter(|c| c.tag_name().name() == "default") {
        let name = c
            .attribute("name")
            .ok_or_else(|| imp.err(c, "<default> needs a 'name'"))?;
        let value = c
            .attribute("value")
            .ok_or_else(|| imp.err(c, "<default> needs a 'value'"))?;
        imp.defaults.insert(name.to_string(), value.to_string());
    }
    for (k, v) in defines {
        if !imp.defaults.contains_key(k) {
            imp.warnings.borrow_mut().push(SceneWarning {
                location: Location {
                    file: file.to_path_buf(),
                    line: 0,
                },
                message: format!("-D {k}: the scene declares no <default name=\"{k}\">"),
            });
        }
        imp.defaults.insert(k.clone(), v.clone());
    }

    let mut desc = SceneDesc {
        spp: 16,
        ..SceneDesc::default()
    };
    let mut saw_sensor = false;
    for c in elements(root) {
        match c.tag_name().name() {
            "default" => {}
            "integrator" => imp.integrator(c, &mut desc)?,
            "sensor" => {
                if saw_sensor {
                    imp.warn(c, "only the first sensor is used");
                    continue;
                }
                saw_sensor = true;
                imp.sensor(c, &mut desc)?;
            }
            "bsdf" => {
                let material = imp.bsdf(c)?;
                let name = match imp.attr(c, "id")? {
                    Some(id) => {
                        if let Some(line) = imp.bsdf_ids.get(&id) {
                            return Err(imp.err(
                                c,
                                format!("bsdf id '{id}' is already declared at line {line}"),
                            ));
                        }
                        id
                    }
                    None => {
                        imp.bsdf_anon += 1;
                        format!("__anonymous_{}", imp.bsdf_anon)
                    }
                };
                imp.bsdf_ids.insert(name.clone(), imp.loc(c).line);
                desc.materials.push(NamedMaterial { name, material });
            }
            "texture" => {
                let id = imp.req_attr(c, "id")?;
                let t = imp.texture(c)?;
                let line = imp.loc(c).line;
                imp.textures.insert(id, (t, line));
            }
            "shape" => {
                let s = imp.shape(c)?;
                desc.shapes.push(s);
            }
            "emitter" => {
                let l = imp.emitter(c)?;
                // Mitsuba allows one environment emitter per scene.
                let is_env = |l: &LightDesc| {
                    matches!(l, LightDesc::Constant { .. } | LightDesc::Envmap { .. })
                };
                if is_env(&l) && desc.lights.iter().any(is_env) {
                    return Err(imp.err(
                        c,
                        "a second environment emitter (constant or envmap); only one is allowed per scene",
                    ));
                }
                desc.lights.push(l);
            }
            t if PROPERTY_TAGS.contains(&t) => {
                imp.warn(c, format!("ignored <{t}> directly inside <scene>"))
            }
            t => return Err(imp.err(c, format!("unsupported element <{t}>"))),
        }
    }
    if !saw_sensor {
        return Err(imp.err(root, "the scene has no <sensor>"));
    }
    Ok((desc, imp.warnings.into_inner()))
}
