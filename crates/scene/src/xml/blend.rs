//! `<bsdf type="blendbsdf">`
//! (<https://mitsuba.readthedocs.io/en/latest/src/generated/plugins_bsdfs.html#blended-material-blendbsdf>):
//! two nested bsdfs, inline or by `<ref>`, in the order written, and a `weight` (a float or a
//! texture, required as in Mitsuba): `(1 − weight)·first + weight·second`. A weight texture is
//! bound outside the blend (`Textured` with the parameter `Weight`); the nested bsdfs' own
//! parameters must be constant.

use roxmltree::Node;

use super::props::{PROPERTY_TAGS, Props};
use super::{Importer, Result, elements, snake_case};
use crate::desc::*;
use crate::material::MAX_BLEND_DEPTH;

/// Whether `n` is a `<bsdf type="blendbsdf">`.
fn is_blend(n: Node) -> bool {
    n.tag_name().name() == "bsdf"
        && n.attribute("type").map(snake_case).as_deref() == Some("blendbsdf")
}

impl<'a> Importer<'a> {
    /// A `blendbsdf` (its `props` read, not yet finished).
    pub(super) fn blendbsdf<'i>(
        &self,
        node: Node<'a, 'i>,
        props: Props<'a, 'i>,
    ) -> Result<MaterialDesc> {
        const WHAT: &str = "bsdf 'blendbsdf'";
        let mut parts: Vec<(Node, MaterialDesc)> = Vec::new();
        let mut weight_texture: Option<(Node, TextureDesc)> = None;
        for c in elements(node) {
            let tag = c.tag_name().name();
            match tag {
                "bsdf" => {
                    // Checked before recursing, so nesting depth stays bounded.
                    if is_blend(c)
                        && c.ancestors().filter(|a| is_blend(*a)).count() >= MAX_BLEND_DEPTH
                    {
                        return Err(self.err(
                            c,
                            format!("{WHAT}: blendbsdfs nest at most {MAX_BLEND_DEPTH} deep"),
                        ));
                    }
                    parts.push((c, self.bsdf(c)?));
                }
                "ref" => {
                    let id = self.req_attr(c, "id")?;
                    let name = self.attr(c, "name")?.map(|n| snake_case(&n));
                    if let Some((_, m)) = self.bsdf_ids.get(&id) {
                        parts.push((c, m.clone()));
                    } else if name.as_deref() == Some("weight") {
                        let (t, _) = self.textures.get(&id).ok_or_else(|| {
                            self.err(c, format!("{WHAT}: reference to undefined texture '{id}'"))
                        })?;
                        weight_texture = Some((c, t.clone()));
                    } else {
                        return Err(
                            self.err(c, format!("{WHAT}: reference to undefined bsdf '{id}'"))
                        );
                    }
                }
                "texture" => {
                    let name = snake_case(&self.req_attr(c, "name")?);
                    if name != "weight" {
                        return Err(self.err(
                            c,
                            format!(
                                "{WHAT} has no texture parameter '{name}' (its parameters: weight and two nested bsdfs)"
                            ),
                        ));
                    }
                    if weight_texture.is_some() {
                        return Err(self.err(c, format!("{WHAT}: two textures for 'weight'")));
                    }
                    weight_texture = Some((c, self.texture(c)?));
                }
                t if PROPERTY_TAGS.contains(&t) => {}
                other => return Err(self.err(c, format!("unexpected <{other}> inside a bsdf"))),
            }
        }
        let (first, second) = match <[_; 2]>::try_from(parts) {
            Ok([a, b]) => (a, b),
            Err(parts) => {
                let at = parts.get(2).map_or(node, |(n, _)| *n);
                return Err(self.err(
                    at,
                    format!(
                        "{WHAT} takes exactly two nested bsdfs (inline or by <ref>), not {}",
                        parts.len()
                    ),
                ));
            }
        };
        for (n, m) in [&first, &second] {
            if crate::material::contains_textured(m) || crate::material::bump_scale(m).is_some() {
                return Err(self.err(
                    *n,
                    format!(
                        "{WHAT}: this nested bsdf has textured parameters; only the blend's weight may be a texture here (give the nested bsdfs constant parameters)"
                    ),
                ));
            }
        }
        let value = props.float("weight")?;
        let weight = match (value, &weight_texture) {
            (Some(_), Some((c, _))) => {
                return Err(self.err(
                    *c,
                    format!("{WHAT}: 'weight' is given twice (as a value and as a texture)"),
                ));
            }
            (None, None) => {
                return Err(self.err(
                    node,
                    format!(
                        "{WHAT} needs a 'weight' (a float in [0, 1] or a texture), as in Mitsuba"
                    ),
                ));
            }
            (Some(w), None) => {
                if !(0.0..=1.0).contains(&w) {
                    return Err(self.err(
                        props.node_or("weight", node),
                        format!("{WHAT}: weight {w} must lie in [0, 1]"),
                    ));
                }
                w
            }
            // The texture gives the weight at every shading point; this one is never read.
            (None, Some(_)) => 0.5,
        };
        let blend = MaterialDesc::Blend {
            weight,
            bsdfs: Box::new((first.1, second.1)),
        };
        let m = match weight_texture {
            Some((_, texture)) => MaterialDesc::Textured {
                material: Box::new(blend),
                textures: vec![TextureBinding {
                    param: ColorParam::Weight,
                    texture,
                }],
            },
            None => blend,
        };
        crate::material::check(&m).map_err(|e| self.err(node, format!("{WHAT}: {e}")))?;
        props.finish();
        Ok(m)
    }
}
