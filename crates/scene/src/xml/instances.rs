//! `shapegroup` and `instance` (Mitsuba 3's `shape-shapegroup` and `shape-instance` plugin
//! pages): a named group of shapes, invisible by itself, placed in the scene by instances, each
//! with its own `to_world`.
//!
//! Instances are flattened when the scene is read: every instance adds a copy of each shape of
//! its group, whose transform is the shape's own followed by the instance's. The renderer then
//! sees ordinary world-space shapes, so every estimator, the light tables and the writer
//! (`restir convert`, which writes the copies as plain shapes) need nothing new. The price is
//! memory: an instanced mesh is loaded and built once per instance, and each copy counts
//! against `--max-memory` like any mesh; the number of copies is limited by
//! [`limits::MAX_INSTANCED_SHAPES`](crate::desc::limits::MAX_INSTANCED_SHAPES), checked before
//! any copy is made.
//!
//! As in Mitsuba, a group holds shapes only (no emitters, no nested group or instance), an
//! instance names exactly one group with `<ref>`, and a group must be declared before the
//! instances that use it.

use roxmltree::Node;

use super::props::PROPERTY_TAGS;
use super::{Importer, Result, elements};
use crate::desc::*;

/// A group's shapes, as read (each with its own `to_world`).
pub(super) struct ShapeGroup {
    shapes: Vec<ShapeDesc>,
}

impl<'a> Importer<'a> {
    /// Reads `<shape type="shapegroup" id=…>` into the importer's groups.
    pub(super) fn shapegroup<'i>(&mut self, node: Node<'a, 'i>) -> Result<()> {
        let id = self.attr(node, "id")?.ok_or_else(|| {
            self.err(
                node,
                "a shapegroup needs an 'id' (instances refer to it with <ref id=\"…\"/>)",
            )
        })?;
        if let Some((_, line)) = self.groups.get(&id) {
            return Err(self.err(
                node,
                format!("shapegroup id '{id}' is already declared at line {line}"),
            ));
        }
        let mut shapes = Vec::new();
        for c in elements(node) {
            match c.tag_name().name() {
                "shape" => {
                    let ty = self.plugin_type(c)?;
                    if ty == "shapegroup" || ty == "instance" {
                        return Err(self.err(
                            c,
                            format!(
                                "a shapegroup cannot hold a shape of type '{ty}': nested \
                                 instancing is not supported (as in Mitsuba 3)"
                            ),
                        ));
                    }
                    if let Some(e) = elements(c).find(|e| e.tag_name().name() == "emitter") {
                        return Err(self.err(
                            e,
                            "a shape inside a shapegroup cannot be an emitter: instancing of \
                             emitters is not supported (as in Mitsuba 3)",
                        ));
                    }
                    shapes.push(self.shape(c)?);
                }
                t if PROPERTY_TAGS.contains(&t) => {
                    return Err(self.err(
                        c,
                        format!(
                            "a shapegroup takes no properties (found <{t}>): place it with an \
                             instance's to_world"
                        ),
                    ));
                }
                t => {
                    return Err(self.err(
                        c,
                        format!("unexpected <{t}> inside a shapegroup (it holds <shape>s only)"),
                    ));
                }
            }
        }
        if shapes.is_empty() {
            self.warn(node, format!("shapegroup '{id}' holds no shapes"));
        }
        let line = self.loc(node).line;
        self.groups.insert(id, (ShapeGroup { shapes }, line));
        Ok(())
    }

    /// The shapes `<shape type="instance">` places: its group's shapes, each followed by the
    /// instance's `to_world`.
    pub(super) fn instance<'i>(&self, node: Node<'a, 'i>, placed: usize) -> Result<Vec<ShapeDesc>> {
        let props = self.props(node, "shape 'instance'".into())?;
        let to_world = props.transform("to_world")?;
        let mut group = None;
        for c in elements(node) {
            match c.tag_name().name() {
                "ref" => {
                    let id = self.req_attr(c, "id")?;
                    if group.is_some() {
                        return Err(self.err(c, "an instance names one shapegroup"));
                    }
                    match self.groups.get(&id) {
                        Some((g, _)) => group = Some(g),
                        None => {
                            let what = if self.bsdf_ids.contains_key(&id) {
                                format!("'{id}' is a bsdf, not a shapegroup")
                            } else {
                                format!("reference to undefined shapegroup id '{id}'")
                            };
                            return Err(self.err(
                                c,
                                format!(
                                    "{what} (an instance refers to a shapegroup declared before it)"
                                ),
                            ));
                        }
                    }
                }
                t if PROPERTY_TAGS.contains(&t) => {}
                t => {
                    return Err(self.err(
                        c,
                        format!(
                            "unexpected <{t}> inside an instance (it takes a <ref> to a \
                             shapegroup and a to_world)"
                        ),
                    ));
                }
            }
        }
        props.finish();
        let group = group.ok_or_else(|| {
            self.err(
                node,
                "an instance needs a <ref id=\"…\"/> naming a shapegroup",
            )
        })?;
        let total = placed.saturating_add(group.shapes.len());
        if total as u64 > limits::MAX_INSTANCED_SHAPES {
            return Err(self.err(
                node,
                format!(
                    "instances would place {total} shapes, more than the limit of {} (instances \
                     are copied into the scene when it is read)",
                    limits::MAX_INSTANCED_SHAPES
                ),
            ));
        }
        // Each copy is located at the instance: what can go wrong with a copy that did not with
        // the group's shape is its transform, and a mesh file's error names the file.
        let location = self.loc(node);
        Ok(group
            .shapes
            .iter()
            .map(|s| {
                let mut s = s.clone();
                s.id = None;
                s.to_world.extend(to_world.iter().cloned());
                s.location = location.clone();
                s
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use crate::desc::{GeometryDesc, TransformOp, limits};
    use crate::xml::parse_xml;

    const SENSOR: &str = r#"<sensor type="perspective"/>"#;

    /// Each instance places a copy of every shape of its group, the shape's transform first and
    /// the instance's after it; the group alone places nothing.
    #[test]
    fn instances_copy_the_group_with_their_transform() {
        let xml = format!(
            r#"<scene>{SENSOR}
            <shape type="shapegroup" id="g">
                <shape type="sphere"><float name="radius" value="0.5"/></shape>
                <shape type="rectangle" id="r">
                    <transform name="to_world"><scale value="2"/></transform>
                </shape>
            </shape>
            <shape type="instance"><ref id="g"/></shape>
            <shape type="instance"><ref id="g"/>
                <transform name="to_world"><translate x="3"/></transform>
            </shape>
            </scene>"#
        );
        let (desc, warnings) = parse_xml(&xml, Path::new("i.xml"), &[]).unwrap();
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(desc.shapes.len(), 4);
        assert!(matches!(
            desc.shapes[0].geometry,
            GeometryDesc::Sphere { .. }
        ));
        assert!(desc.shapes[0].to_world.is_empty());
        assert_eq!(
            desc.shapes[3].to_world,
            vec![
                TransformOp::Scale([2.0; 3]),
                TransformOp::Translate([3.0, 0.0, 0.0])
            ]
        );
        // Copies carry no id (an animation could not tell them apart) and are located at their
        // instance.
        assert!(desc.shapes.iter().all(|s| s.id.is_none()));
        assert_eq!(desc.shapes[2].location.line, 9);
    }

    /// Many instances of a large group are refused before they are copied.
    #[test]
    fn too_many_copies_are_refused() {
        let group = 1000;
        let instances = limits::MAX_INSTANCED_SHAPES as usize / group + 1;
        let mut xml = format!("<scene>{SENSOR}\n<shape type=\"shapegroup\" id=\"g\">\n");
        xml.push_str(&"<shape type=\"sphere\"/>\n".repeat(group));
        xml.push_str("</shape>\n");
        xml.push_str(&"<shape type=\"instance\"><ref id=\"g\"/></shape>\n".repeat(instances));
        xml.push_str("</scene>\n");
        let e = parse_xml(&xml, Path::new("many.xml"), &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("many.xml:{}:", group + 3 + instances))
                && e.contains("more than the limit of 262144"),
            "{e}"
        );
    }
}
