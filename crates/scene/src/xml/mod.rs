//! Importer for the Mitsuba-style XML scene format used by Mitsuba 0.6/3 and Lajolla.
//!
//! Accepts both camelCase (Mitsuba 0.6, Lajolla: `toWorld`, `maxDepth`) and snake_case (Mitsuba 3)
//! names. `<default name= value=>` declares variables that `$name` in any attribute refers to;
//! `-D name=value` on the command line overrides them.
//!
//! Files, as Mitsuba 3 finds them (`resolve.rs`): `<path value="dir"/>` adds a search folder
//! (relative to the file that declares it); a relative file name (mesh, texture, environment map,
//! included file) is looked for in the search folders, newest first, then beside the file that
//! names it, then beside the scene file. `<include filename="part.xml"/>` reads another scene
//! file's elements in its place (its `<default>`s apply where the including files set none;
//! errors name the included file and line, and where it was included).
//!
//! Unknown *properties* are warnings with `file:line` (legacy files carry many that do not matter,
//! such as `nearClip`); unknown *plugin types* and malformed values are errors with `file:line`.
//!
//! The importer is split by plugin family: [`props`](self) reads a plugin's properties (typed
//! getters, located errors, unused-property warnings), and `bsdfs`, `textures`, `shapes`,
//! `emitters`, `sensor` (camera, film, sampler) and `integrator` turn them into descriptions.
//! This module walks the document: `<default>` variables, top-level ids and references.
//!
//! The other direction is [`to_mitsuba_xml`] (`write/`): a description as a Mitsuba 3 scene
//! file, which this importer reads back to the same scene.

mod blend;
mod bsdfs;
mod bumpmap;
mod emitters;
mod instances;
mod integrator;
mod normalmap;
mod principled;
mod props;
mod resolve;
mod sensor;
mod shapes;
mod source;
mod textures;
mod values;
mod write;

pub use write::{XmlWriteError, XmlWriteOptions, to_mitsuba_xml};

use std::collections::{HashMap, HashSet};
use std::path::Path;

use roxmltree::{Document, Node};

use crate::desc::*;
use crate::texture::TextureDesc;
use crate::{SceneError, SceneWarning};
use props::{PROPERTY_TAGS, Props};
use source::Source;

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

/// The document walk's state: the source it reads through and the ids declared so far.
struct Importer<'a> {
    src: &'a Source<'a>,
    /// Top-level bsdf ids, with the line that declares them and the material (which a
    /// `blendbsdf` may reference).
    bsdf_ids: HashMap<String, (u32, MaterialDesc)>,
    bsdf_anon: usize,
    /// Top-level textures by id, with the line that declares them.
    textures: HashMap<String, (TextureDesc, u32)>,
    /// The `<path>` search folders, newest first, and the scene file's folder.
    files: resolve::SearchPath,
    /// Every `<default>` name declared in the scene file or a file it includes.
    declared: HashSet<String>,
    /// Whether a sensor was read.
    saw_sensor: bool,
    /// How deep in `<include>`s this file is (0: the scene file).
    depth: u32,
    /// Shapegroups by id, with the line that declares them.
    groups: HashMap<String, (instances::ShapeGroup, u32)>,
    /// How many shapes instances have placed so far.
    instanced: usize,
}

/// The importer reads attributes and reports errors through its source.
impl<'a> core::ops::Deref for Importer<'a> {
    type Target = Source<'a>;
    fn deref(&self) -> &Source<'a> {
        self.src
    }
}

impl<'a> Importer<'a> {
    /// The properties of `plugin`, named `what` in messages.
    fn props<'i>(&self, plugin: Node<'a, 'i>, what: String) -> Result<Props<'a, 'i>> {
        Props::read(self.src, plugin, what)
    }
}

/// The element children of `node`.
fn elements<'a, 'i>(node: Node<'a, 'i>) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children().filter(Node::is_element)
}

/// `s` with control characters escaped (`\n`, `\t`, `\u{1b}`), so an error stays on one line.
fn escape_controls(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_debug().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// Parses a Mitsuba-style XML scene. `defines` override `<default>` values.
pub fn parse_xml(
    text: &str,
    file: &Path,
    defines: &[(String, String)],
) -> Result<(SceneDesc, Vec<SceneWarning>)> {
    let doc = parse_document(text, file)?;
    let root = doc.root_element();
    let mut src = Source::new(file, text);
    expect_scene_root(&src, root)?;
    // Defaults first (the command line wins), so that `$name` works anywhere.
    let declared = read_defaults(&src, root)?;
    for (name, value) in &declared {
        src.defaults.insert(name.clone(), value.clone());
    }
    for (k, v) in defines {
        src.defaults.insert(k.clone(), v.clone());
    }
    let mut imp = Importer {
        src: &src,
        bsdf_ids: HashMap::new(),
        bsdf_anon: 0,
        textures: HashMap::new(),
        files: resolve::SearchPath::new(file),
        declared: declared.into_iter().map(|(k, _)| k).collect(),
        saw_sensor: false,
        depth: 0,
        groups: HashMap::new(),
        instanced: 0,
    };

    let mut desc = SceneDesc {
        spp: defaults::SPP,
        ..SceneDesc::default()
    };
    imp.walk(root, &mut desc)?;
    if !imp.saw_sensor {
        return Err(imp.err(root, "the scene has no <sensor>"));
    }
    let mut warnings: Vec<SceneWarning> = defines
        .iter()
        .filter(|(k, _)| !imp.declared.contains(k))
        .map(|(k, _)| SceneWarning {
            location: Location {
                file: file.to_path_buf(),
                line: 0,
            },
            message: format!("-D {k}: the scene declares no <default name=\"{k}\">"),
        })
        .collect();
    drop(imp);
    warnings.extend(src.warnings.into_inner());
    Ok((desc, warnings))
}

/// Parses `text`, read from `file`, as an XML document.
fn parse_document<'t>(text: &'t str, file: &Path) -> Result<Document<'t>> {
    Document::parse(text).map_err(|e| {
        SceneError::new(
            Location {
                file: file.to_path_buf(),
                line: e.pos().row,
            },
            // One line whatever the parser quotes: a newline it did not expect is shown as `\n`.
            format!("malformed XML: {}", escape_controls(&e.to_string())),
        )
    })
}

/// An error unless `root` is a `<scene>`.
fn expect_scene_root(src: &Source, root: Node) -> Result<()> {
    if root.tag_name().name() != "scene" {
        return Err(src.err(
            root,
            format!(
                "expected a <scene> root element, found <{}>",
                root.tag_name().name()
            ),
        ));
    }
    Ok(())
}

/// The `<default name= value=>` children of `root`, in file order.
fn read_defaults(src: &Source, root: Node) -> Result<Vec<(String, String)>> {
    let mut out = Vec::new();
    for c in elements(root).filter(|c| c.tag_name().name() == "default") {
        let name = c
            .attribute("name")
            .ok_or_else(|| src.err(c, "<default> needs a 'name'"))?;
        let value = c
            .attribute("value")
            .ok_or_else(|| src.err(c, "<default> needs a 'value'"))?;
        out.push((name.to_string(), value.to_string()));
    }
    Ok(out)
}

impl<'a> Importer<'a> {
    /// Reads the elements of the `<scene>` `root` into `desc`.
    fn walk<'i>(&mut self, root: Node<'a, 'i>, desc: &mut SceneDesc) -> Result<()> {
        for c in elements(root) {
            match c.tag_name().name() {
                "default" => {}
                "path" => self.path(c)?,
                "include" => self.include(c, desc)?,
                "integrator" => self.integrator(c, desc)?,
                "sensor" => {
                    if self.saw_sensor {
                        self.warn(c, "only the first sensor is used");
                        continue;
                    }
                    self.saw_sensor = true;
                    self.sensor(c, desc)?;
                }
                "bsdf" => {
                    let material = self.bsdf(c)?;
                    let name = match self.attr(c, "id")? {
                        Some(id) => {
                            if let Some((line, _)) = self.bsdf_ids.get(&id) {
                                return Err(self.err(
                                    c,
                                    format!("bsdf id '{id}' is already declared at line {line}"),
                                ));
                            }
                            id
                        }
                        None => {
                            self.bsdf_anon += 1;
                            format!("__anonymous_{}", self.bsdf_anon)
                        }
                    };
                    let line = self.loc(c).line;
                    self.bsdf_ids.insert(name.clone(), (line, material.clone()));
                    desc.materials.push(NamedMaterial { name, material });
                }
                "texture" => {
                    let id = self.req_attr(c, "id")?;
                    let t = self.texture(c)?;
                    let line = self.loc(c).line;
                    self.textures.insert(id, (t, line));
                }
                "shape" => match self.plugin_type(c)?.as_str() {
                    "shapegroup" => self.shapegroup(c)?,
                    "instance" => {
                        let placed = self.instance(c, self.instanced)?;
                        self.instanced += placed.len();
                        desc.shapes.extend(placed);
                    }
                    _ => {
                        let s = self.shape(c)?;
                        desc.shapes.push(s);
                    }
                },
                "emitter" => {
                    let l = self.emitter(c)?;
                    // Mitsuba allows one environment emitter per scene.
                    let is_env = |l: &LightDesc| {
                        matches!(l, LightDesc::Constant { .. } | LightDesc::Envmap { .. })
                    };
                    if is_env(&l) && desc.lights.iter().any(is_env) {
                        return Err(self.err(
                            c,
                            "a second environment emitter (constant or envmap); only one is allowed per scene",
                        ));
                    }
                    desc.lights.push(l);
                }
                t if PROPERTY_TAGS.contains(&t) => {
                    self.warn(c, format!("ignored <{t}> directly inside <scene>"))
                }
                t => {
                    return Err(self.err(
                        c,
                        format!(
                            "unsupported element <{t}> (known: integrator, sensor, bsdf, texture, shape, emitter, default, path, include, and properties)"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shape_of_a_large_file_knows_its_line() {
        // One shape per line after the sensor: line numbers come from the line index, so this
        // takes milliseconds, not a scan of the file per shape.
        let n = 20_000;
        let mut xml = String::from("<scene>\n<sensor type=\"perspective\"/>\n");
        for i in 0..n {
            xml.push_str(&format!(
                "<shape type=\"sphere\"><float name=\"radius\" value=\"{}\"/></shape>\n",
                1 + i
            ));
        }
        xml.push_str("</scene>\n");
        let (desc, warnings) = parse_xml(&xml, Path::new("big.xml"), &[]).unwrap();
        assert!(warnings.is_empty());
        assert_eq!(desc.shapes.len(), n);
        for (i, s) in desc.shapes.iter().enumerate() {
            assert_eq!(s.location.line, i as u32 + 3);
        }
    }
}
