//! The typed property reader: a plugin element's property children (`<float name= value=>`,
//! `<rgb>`, `<transform>`, …) read once into [`Props`], then asked for by name and type. Each
//! getter checks the type and value and produces the error located at the property's line; the
//! properties nobody asked for become "ignores property" warnings in [`Props::finish`].

use std::cell::Cell;

use roxmltree::Node;

use super::source::Source;
use super::{Result, snake_case};
use crate::SceneError;
use crate::desc::{TransformOp, limits};
use crate::spectrum::{self, SpectrumUse};

/// The element names that are properties (everything else inside a plugin is a nested plugin).
pub(super) const PROPERTY_TAGS: &[&str] = &[
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

/// A property's value as written.
#[derive(Clone, Debug)]
pub(super) enum Value {
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

/// One property of a plugin.
pub(super) struct Prop<'a, 'i> {
    /// Its name in snake_case.
    pub(super) name: String,
    /// Its value.
    pub(super) value: Value,
    /// The property element (for locating messages).
    pub(super) node: Node<'a, 'i>,
    /// Whether some getter read it.
    pub(super) used: Cell<bool>,
}

/// How a colour is used: reflectances are bounded to [0, 1], emission converts constant spectra
/// through Mitsuba's emitter path.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum ColorUse {
    Reflectance,
    Emission,
    /// Unbounded non-negative parameters (conductor `eta`/`k`): taken as given.
    Unbounded,
}

/// XYZ → linear sRGB of an equal-energy (constant 1) emission spectrum, as Mitsuba 3's RGB mode
/// computes it (`xyz_to_srgb(1, 1, 1)`).
const EQUAL_ENERGY_RGB: [f32; 3] = [1.204_79, 0.948_291, 0.908_916];

/// The properties of one plugin element.
pub(super) struct Props<'a, 'i> {
    src: &'a Source<'a>,
    /// What the plugin is (`bsdf 'diffuse'`), the prefix of messages.
    pub(super) what: String,
    /// The properties in file order (a later one of the same name wins).
    pub(super) items: Vec<Prop<'a, 'i>>,
}

impl<'a, 'i> Props<'a, 'i> {
    /// Reads the property children of `plugin`; nested plugins are left to the caller. `what`
    /// names the plugin in messages.
    pub(super) fn read(src: &'a Source<'a>, plugin: Node<'a, 'i>, what: String) -> Result<Self> {
        let mut items = Vec::new();
        for c in plugin.children().filter(Node::is_element) {
            let tag = c.tag_name().name();
            if !PROPERTY_TAGS.contains(&tag) {
                continue;
            }
            let name = src.req_attr(c, "name")?;
            // Value errors name the property: `<float name="alpha">: "abc" is not a number`.
            let named = |mut e: SceneError| {
                e.message = format!("<{tag} name=\"{name}\">: {}", e.message);
                e
            };
            let value = (|| -> Result<Value> {
                Ok(match tag {
                    "float" => Value::Float(src.parse_float(c, &src.req_attr(c, "value")?)?),
                    "integer" => {
                        let s = src.req_attr(c, "value")?;
                        let v = s.trim().parse::<i64>().map_err(|_| {
                            src.err(c, format!("cannot parse \"{s}\" as an integer"))
                        })?;
                        Value::Int(v)
                    }
                    "boolean" => {
                        let s = src.req_attr(c, "value")?;
                        match s.trim().to_ascii_lowercase().as_str() {
                            "true" | "1" => Value::Bool(true),
                            "false" | "0" => Value::Bool(false),
                            _ => {
                                return Err(
                                    src.err(c, format!("cannot parse \"{s}\" as a boolean"))
                                );
                            }
                        }
                    }
                    "string" => Value::Str(src.req_attr(c, "value")?),
                    "rgb" | "color" => Value::Rgb(src.parse_vec3(c, &src.req_attr(c, "value")?)?),
                    "srgb" => Value::Rgb(src.srgb_hex(c, &src.req_attr(c, "value")?)?),
                    "spectrum" => {
                        let s = src.req_attr(c, "value")?;
                        if s.contains(':') {
                            Value::Spectrum(
                                crate::spectrum::parse_pairs(&s)
                                    .map_err(|e| src.err(c, e.to_string()))?,
                            )
                        } else {
                            Value::SpectrumConst(src.parse_float(c, &s)? as f32)
                        }
                    }
                    "point" | "vector" => Value::Point(src.xyz(c, 0.0)?),
                    "transform" => Value::Transform(src.parse_transform(c)?),
                    other => return Err(src.err(c, format!("<{other}> is not a property"))),
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
        Ok(Props { src, what, items })
    }

    /// Warns about properties nobody read.
    pub(super) fn finish(self) {
        for p in self.items.iter().filter(|p| !p.used.get()) {
            self.src.warn(
                p.node,
                format!("{} ignores property '{}'", self.what, p.name),
            );
        }
    }

    /// The property `name` (the last one of that name), marked as used.
    pub(super) fn get(&self, name: &str) -> Option<&Prop<'a, 'i>> {
        let p = self.items.iter().rev().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    /// Where property `name` is written, or `fallback` when it is absent (does not mark it used).
    pub(super) fn node_or(&self, name: &str, fallback: Node<'a, 'i>) -> Node<'a, 'i> {
        self.items
            .iter()
            .rev()
            .find(|p| p.name == name)
            .map_or(fallback, |p| p.node)
    }

    /// An error at property `p`.
    pub(super) fn err(&self, p: &Prop, msg: impl Into<String>) -> SceneError {
        self.src.err(p.node, msg)
    }

    /// "`what`: property 'name' must be `want`, not `kind`", at `p`.
    pub(super) fn type_err(&self, p: &Prop, want: &str) -> SceneError {
        self.src.err(
            p.node,
            format!(
                "{}: property '{}' must be {want}, not {}",
                self.what,
                p.name,
                p.value.kind()
            ),
        )
    }

    pub(super) fn float(&self, name: &str) -> Result<Option<f32>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Float(v) => Ok(Some(v as f32)),
                Value::Int(v) => Ok(Some(v as f32)),
                _ => Err(self.type_err(p, "a float")),
            },
        }
    }

    pub(super) fn int(&self, name: &str) -> Result<Option<i64>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Int(v) => Ok(Some(v)),
                Value::Float(v) if v.fract() == 0.0 => Ok(Some(v as i64)),
                _ => Err(self.type_err(p, "an integer")),
            },
        }
    }

    pub(super) fn bool(&self, name: &str) -> Result<Option<bool>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Bool(v) => Ok(Some(v)),
                _ => Err(self.type_err(p, "a boolean")),
            },
        }
    }

    pub(super) fn string(&self, name: &str) -> Result<Option<String>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Str(v) => Ok(Some(v.clone())),
                _ => Err(self.type_err(p, "a string")),
            },
        }
    }

    pub(super) fn point(&self, name: &str) -> Result<Option<[f32; 3]>> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Point(v) | Value::Rgb(v) => Ok(Some(v)),
                _ => Err(self.type_err(p, "a point or vector")),
            },
        }
    }

    /// A point within the coordinate limit ([`crate::desc::limits::MAX_COORDINATE`]).
    pub(super) fn position(&self, name: &str) -> Result<Option<[f32; 3]>> {
        let v = self.point(name)?;
        if let (Some(p), Some(v)) = (self.get(name), v)
            && let Some(problem) = v.iter().find_map(|&x| limits::coordinate_problem(x))
        {
            return Err(self.err(p, format!("{}: '{}': {problem}", self.what, p.name)));
        }
        Ok(v)
    }

    /// A length (radius) within the coordinate limit.
    pub(super) fn length(&self, name: &str) -> Result<Option<f32>> {
        let v = self.float(name)?;
        if let (Some(p), Some(v)) = (self.get(name), v)
            && let Some(problem) = limits::coordinate_problem(v)
        {
            return Err(self.err(p, format!("{}: '{}': {problem}", self.what, p.name)));
        }
        Ok(v)
    }

    pub(super) fn transform(&self, name: &str) -> Result<Vec<TransformOp>> {
        match self.get(name) {
            None => Ok(Vec::new()),
            Some(p) => match &p.value {
                Value::Transform(v) => Ok(v.clone()),
                _ => Err(self.type_err(p, "a transform")),
            },
        }
    }

    pub(super) fn color(&self, name: &str, usage: ColorUse) -> Result<Option<[f32; 3]>> {
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
                    self.src.warn(
                        p.node,
                        format!(
                            "{}: spectrum '{}' converts to RGB {rgb:?}, clipped to {clipped:?}",
                            self.what, p.name
                        ),
                    );
                }
                clipped
            }
            _ => return Err(self.type_err(p, "a colour (rgb, spectrum or float)")),
        };
        if c.iter().any(|x| !x.is_finite()) {
            return Err(self
                .src
                .err(p.node, format!("{}: '{}' is not finite", self.what, p.name)));
        }
        if usage == ColorUse::Reflectance && c.iter().any(|&x| !(0.0..=1.0).contains(&x)) {
            return Err(self.src.err(
                p.node,
                format!(
                    "{}: reflectance '{}' = {c:?} must lie in [0, 1]",
                    self.what, p.name
                ),
            ));
        }
        if usage != ColorUse::Reflectance && c.iter().any(|&x| x < 0.0) {
            return Err(self.src.err(
                p.node,
                format!("{}: '{}' = {c:?} must not be negative", self.what, p.name),
            ));
        }
        Ok(Some(c))
    }

    /// `int_ior`/`ext_ior`: a number or a name from Mitsuba's IOR table; `default` when absent.
    pub(super) fn ior(&self, name: &str, default: f32) -> Result<f32> {
        let Some(p) = self.get(name) else {
            return Ok(default);
        };
        let v = match &p.value {
            Value::Float(v) => *v as f32,
            Value::Int(v) => *v as f32,
            Value::Str(s) => restir_materials::ior::ior(s).ok_or_else(|| {
                self.err(
                    p,
                    format!(
                        "{}: unknown {name} material '{s}' (known: {})",
                        self.what,
                        restir_materials::ior::ior_names()
                    ),
                )
            })?,
            _ => return Err(self.type_err(p, "a number or an IOR name")),
        };
        if !(v.is_finite() && v > 0.0) {
            return Err(self.err(p, format!("{}: {name} {v} must be positive", self.what)));
        }
        Ok(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roxmltree::Document;
    use std::path::Path;

    /// Reads the properties of the root element of `xml` (file `t.xml`) and hands them to `f`
    /// with the warnings `finish` produced afterwards.
    fn with_props<R>(xml: &str, f: impl FnOnce(&Props) -> R) -> (R, Vec<String>) {
        let doc = Document::parse(xml).unwrap();
        let mut src = Source::new(Path::new("t.xml"), xml);
        src.defaults.insert("a".into(), "0.25".into());
        let props = Props::read(&src, doc.root_element(), "bsdf 'test'".into()).unwrap();
        let r = f(&props);
        props.finish();
        let warnings = src.warnings.into_inner();
        (r, warnings.iter().map(ToString::to_string).collect())
    }

    fn read_err(xml: &str) -> String {
        let doc = Document::parse(xml).unwrap();
        let src = Source::new(Path::new("t.xml"), xml);
        match Props::read(&src, doc.root_element(), "bsdf 'test'".into()) {
            Ok(_) => panic!("{xml} should not read"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn typed_getters_read_their_types() {
        let xml = r#"<bsdf type="test">
            <float name="alpha" value="0.5"/>
            <integer name="maxDepth" value="7"/>
            <boolean name="nonlinear" value="true"/>
            <string name="distribution" value="ggx"/>
            <point name="center" x="1" z="3"/>
            <rgb name="reflectance" value="0.1, 0.2, 0.3"/>
            <transform name="toWorld"><translate x="2"/></transform>
        </bsdf>"#;
        let (r, warnings) = with_props(xml, |p| {
            (
                p.float("alpha").unwrap(),
                p.int("max_depth").unwrap(),
                p.bool("nonlinear").unwrap(),
                p.string("distribution").unwrap(),
                p.point("center").unwrap(),
                p.color("reflectance", ColorUse::Reflectance).unwrap(),
                p.transform("to_world").unwrap(),
                p.float("absent").unwrap(),
            )
        });
        assert_eq!(r.0, Some(0.5));
        assert_eq!(r.1, Some(7));
        assert_eq!(r.2, Some(true));
        assert_eq!(r.3.as_deref(), Some("ggx"));
        assert_eq!(r.4, Some([1.0, 0.0, 3.0]));
        assert_eq!(r.5, Some([0.1, 0.2, 0.3]));
        assert_eq!(r.6, vec![TransformOp::Translate([2.0, 0.0, 0.0])]);
        assert_eq!(r.7, None);
        assert!(warnings.is_empty(), "{warnings:?}");
    }

    #[test]
    fn integers_are_floats_and_whole_floats_are_integers() {
        let xml = r#"<bsdf type="test"><integer name="a" value="3"/><float name="b" value="4"/>
            <float name="c" value="4.5"/></bsdf>"#;
        let (r, _) = with_props(xml, |p| {
            (
                p.float("a").unwrap(),
                p.int("b").unwrap(),
                p.int("c").unwrap_err().to_string(),
            )
        });
        assert_eq!(r.0, Some(3.0));
        assert_eq!(r.1, Some(4));
        assert_eq!(
            r.2,
            "t.xml:2: bsdf 'test': property 'c' must be an integer, not float"
        );
    }

    #[test]
    fn a_wrong_type_is_an_error_at_the_property_line() {
        let xml = "<bsdf type=\"test\">\n\n<string name=\"alpha\" value=\"x\"/></bsdf>";
        let (e, _) = with_props(xml, |p| p.float("alpha").unwrap_err().to_string());
        assert_eq!(
            e,
            "t.xml:3: bsdf 'test': property 'alpha' must be a float, not string"
        );
    }

    #[test]
    fn the_last_of_two_properties_wins_and_names_become_snake_case() {
        let xml = r#"<bsdf type="test"><float name="intIOR" value="1.2"/>
            <float name="int_ior" value="1.3"/></bsdf>"#;
        let (v, warnings) = with_props(xml, |p| p.float("int_ior").unwrap());
        assert_eq!(v, Some(1.3));
        // The overridden one was never read.
        assert_eq!(
            warnings,
            ["t.xml:1: warning: bsdf 'test' ignores property 'int_ior'"]
        );
    }

    #[test]
    fn unread_properties_are_warnings() {
        let xml = "<bsdf type=\"test\">\n<float name=\"nearClip\" value=\"1\"/></bsdf>";
        let ((), warnings) = with_props(xml, |_| ());
        assert_eq!(
            warnings,
            ["t.xml:2: warning: bsdf 'test' ignores property 'near_clip'"]
        );
    }

    #[test]
    fn value_errors_name_the_property() {
        assert_eq!(
            read_err(r#"<bsdf type="t"><float name="alpha" value="abc"/></bsdf>"#),
            "t.xml:1: <float name=\"alpha\">: cannot parse \"abc\" as a number"
        );
        assert_eq!(
            read_err(r#"<bsdf type="t"><boolean name="b" value="yes"/></bsdf>"#),
            "t.xml:1: <boolean name=\"b\">: cannot parse \"yes\" as a boolean"
        );
        assert_eq!(
            read_err(r#"<bsdf type="t"><float value="1"/></bsdf>"#),
            "t.xml:1: <float> needs a 'name' attribute"
        );
    }

    #[test]
    fn variables_are_substituted() {
        let xml = r#"<bsdf type="test"><float name="alpha" value="$a"/></bsdf>"#;
        let (v, _) = with_props(xml, |p| p.float("alpha").unwrap());
        assert_eq!(v, Some(0.25));
    }

    #[test]
    fn colours_are_checked_by_use() {
        let xml = r#"<bsdf type="test"><rgb name="reflectance" value="1.5"/>
            <spectrum name="radiance" value="2"/><rgb name="eta" value="-1, 0, 0"/>
            <float name="grey" value="0.5"/></bsdf>"#;
        let (r, _) = with_props(xml, |p| {
            (
                p.color("reflectance", ColorUse::Reflectance)
                    .unwrap_err()
                    .to_string(),
                p.color("radiance", ColorUse::Emission).unwrap(),
                p.color("eta", ColorUse::Unbounded).unwrap_err().to_string(),
                p.color("grey", ColorUse::Reflectance).unwrap(),
            )
        });
        assert_eq!(
            r.0,
            "t.xml:1: bsdf 'test': reflectance 'reflectance' = [1.5, 1.5, 1.5] must lie in [0, 1]"
        );
        assert_eq!(r.1, Some(EQUAL_ENERGY_RGB.map(|c| 2.0 * c)));
        assert_eq!(
            r.2,
            "t.xml:2: bsdf 'test': 'eta' = [-1.0, 0.0, 0.0] must not be negative"
        );
        assert_eq!(r.3, Some([0.5; 3]));
    }

    #[test]
    fn iors_are_numbers_or_names_and_positive() {
        let xml = r#"<bsdf type="test"><string name="int_ior" value="bk7"/>
            <float name="ext_ior" value="-1"/></bsdf>"#;
        let (r, _) = with_props(xml, |p| {
            (
                p.ior("int_ior", 9.0).unwrap(),
                p.ior("ext_ior", 9.0).unwrap_err().to_string(),
                p.ior("absent", 9.0).unwrap(),
            )
        });
        assert_eq!(r.0, 1.5046);
        assert_eq!(r.1, "t.xml:2: bsdf 'test': ext_ior -1 must be positive");
        assert_eq!(r.2, 9.0);
    }

    #[test]
    fn node_or_finds_the_property_without_using_it() {
        let xml = "<bsdf type=\"test\">\n<float name=\"fov\" value=\"1\"/></bsdf>";
        let ((), warnings) = with_props(xml, |p| {
            let root = p.items[0].node.parent().unwrap();
            assert_eq!(p.node_or("fov", root), p.items[0].node);
            assert_eq!(p.node_or("absent", root), root);
        });
        assert_eq!(warnings.len(), 1);
    }
}
