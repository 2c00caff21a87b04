//! `<bsdf type="normalmap">` (<https://mitsuba.readthedocs.io/en/latest/src/generated/plugin_reference.html#normal-map-bsdf-normalmap>):
//! one nested bsdf, the map as a `normalmap` texture (a raw `bitmap`, or a `rawconstant`), and
//! Mitsuba 3.9's switches `flip_invalid_normals` and `use_shadowing_function` (both default
//! true). A textured nested bsdf's textures move outside, beside the map's, as for `mask`.

use roxmltree::Node;

use super::props::{PROPERTY_TAGS, Props, Value};
use super::{Importer, Result, elements, snake_case};
use crate::desc::*;

/// Whether `n` is a `<bsdf>` of type `ty`.
fn is_bsdf(n: Node, ty: &str) -> bool {
    n.tag_name().name() == "bsdf" && n.attribute("type").map(snake_case).as_deref() == Some(ty)
}

impl<'a> Importer<'a> {
    /// A `normalmap` bsdf (its `props` read, not yet finished).
    pub(super) fn normalmap<'i>(
        &self,
        node: Node<'a, 'i>,
        props: Props<'a, 'i>,
    ) -> Result<MaterialDesc> {
        let nested: Vec<Node> = elements(node)
            .filter(|c| c.tag_name().name() == "bsdf")
            .collect();
        let inner = match nested.as_slice() {
            // Checked before recursing, so nesting depth stays bounded.
            [n] if is_bsdf(*n, "mask") || is_bsdf(*n, "normalmap") => {
                return Err(self.err(
                    *n,
                    "bsdf 'normalmap' cannot wrap a mask or a normalmap (a mask may wrap the normalmap instead)",
                ));
            }
            [n] if is_bsdf(*n, "twosided")
                && elements(*n).any(|c| is_bsdf(c, "mask") || is_bsdf(c, "normalmap")) =>
            {
                return Err(self.err(
                    *n,
                    "bsdf 'normalmap' cannot wrap a mask or a normalmap (inside a twosided)",
                ));
            }
            [n] => self.bsdf(*n)?,
            [] => {
                return Err(self.err(node, "bsdf 'normalmap' needs one nested <bsdf>"));
            }
            [_, second, ..] => {
                return Err(self.err(*second, "bsdf 'normalmap' takes one nested bsdf, not two"));
            }
        };
        let mut normal = defaults::FLAT_NORMAL;
        let mut bound = None;
        let mut seen = false;
        for c in elements(node) {
            let tag = c.tag_name().name();
            if tag == "bsdf" {
                continue;
            }
            if !PROPERTY_TAGS.contains(&tag) && !["texture", "ref"].contains(&tag) {
                return Err(self.err(c, format!("unexpected <{tag}> inside a bsdf")));
            }
            if tag == "texture" || (tag == "ref" && self.attr(c, "name")?.is_some()) {
                let name = snake_case(&self.req_attr(c, "name")?);
                if name != "normalmap" {
                    return Err(self.err(
                        c,
                        format!(
                            "bsdf 'normalmap' has no texture parameter '{name}' (its parameters: normalmap, flip_invalid_normals, use_shadowing_function and one nested bsdf)"
                        ),
                    ));
                }
                if seen {
                    return Err(self.err(c, "bsdf 'normalmap': two textures for 'normalmap'"));
                }
                seen = true;
                if tag == "texture" && self.plugin_type(c)? == "rawconstant" {
                    normal = self.rawconstant(c)?;
                } else if tag == "texture" {
                    bound = Some(self.texture(c)?);
                } else {
                    let id = self.req_attr(c, "id")?;
                    let (t, _) = self.textures.get(&id).ok_or_else(|| {
                        self.err(
                            c,
                            format!("bsdf 'normalmap': reference to undefined texture '{id}'"),
                        )
                    })?;
                    bound = Some(t.clone());
                }
            }
        }
        if !seen {
            return Err(self.err(
                node,
                "bsdf 'normalmap' needs its 'normalmap' texture (a raw bitmap or a rawconstant)",
            ));
        }
        let flip_invalid_normals = props.bool("flip_invalid_normals")?.unwrap_or(true);
        let use_shadowing_function = props.bool("use_shadowing_function")?.unwrap_or(true);
        // A textured nested bsdf: its textures join the map's outside the normal map.
        let (inner, mut textures) = inner.split_textures();
        if let Some(texture) = bound {
            textures.push(TextureBinding {
                param: ColorParam::NormalMap,
                texture,
            });
        }
        let map = MaterialDesc::NormalMap {
            normal,
            flip_invalid_normals,
            use_shadowing_function,
            material: Box::new(inner),
        };
        let m = map.with_textures(textures);
        crate::material::check(&m).map_err(|e| self.err(node, format!("bsdf 'normalmap': {e}")))?;
        props.finish();
        Ok(m)
    }

    /// A `rawconstant` texture's `value` (a float or a vector; Mitsuba's default 1).
    fn rawconstant(&self, node: Node) -> Result<V3> {
        let props = self.props(node, "texture 'rawconstant'".into())?;
        let v = match props.get("value") {
            None => [1.0; 3],
            Some(p) => match &p.value {
                Value::Float(f) => [*f as f32; 3],
                Value::Point(v) | Value::Rgb(v) => *v,
                _ => return Err(props.type_err(p, "a float or a vector")),
            },
        };
        if !v.iter().all(|x| x.is_finite()) {
            return Err(self.err(node, "texture 'rawconstant': value must be finite"));
        }
        for c in elements(node) {
            let tag = c.tag_name().name();
            if !PROPERTY_TAGS.contains(&tag) {
                return Err(self.err(c, format!("unexpected <{tag}> inside a texture")));
            }
        }
        props.finish();
        Ok(v)
    }
}
