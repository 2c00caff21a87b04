//! `<bsdf type="bumpmap">` (<https://mitsuba.readthedocs.io/en/latest/src/generated/plugin_reference.html#bump-map-bsdf-adapter-bumpmap>):
//! one nested bsdf, one height texture (a `bitmap`, nested under any name or referenced), and
//! Mitsuba 3's `scale` (default 1), `flip_invalid_normals` and `use_shadowing_function` (both
//! default true). A textured nested bsdf's textures move outside, beside the height, as for
//! `normalmap`.

use roxmltree::Node;

use super::props::{PROPERTY_TAGS, Props};
use super::{Importer, Result, elements};
use crate::desc::*;

impl<'a> Importer<'a> {
    /// A `bumpmap` bsdf (its `props` read, not yet finished).
    pub(super) fn bumpmap<'i>(
        &self,
        node: Node<'a, 'i>,
        props: Props<'a, 'i>,
    ) -> Result<MaterialDesc> {
        let nested: Vec<Node> = elements(node)
            .filter(|c| c.tag_name().name() == "bsdf")
            .collect();
        let inner = match nested.as_slice() {
            // Checked before recursing, so nesting depth stays bounded.
            [n] if ["mask", "normalmap", "bumpmap"].contains(&self.plugin_type(*n)?.as_str()) => {
                return Err(self.err(
                    *n,
                    "bsdf 'bumpmap' cannot wrap a mask, a normalmap or a bumpmap (a mask may wrap the bumpmap instead)",
                ));
            }
            [n] => self.bsdf(*n)?,
            [] => return Err(self.err(node, "bsdf 'bumpmap' needs one nested <bsdf>")),
            [_, second, ..] => {
                return Err(self.err(*second, "bsdf 'bumpmap' takes one nested bsdf, not two"));
            }
        };
        let mut height = None;
        for c in elements(node) {
            let tag = c.tag_name().name();
            if tag == "bsdf" || PROPERTY_TAGS.contains(&tag) {
                continue;
            }
            let t = match tag {
                "texture" => self.texture(c)?,
                "ref" => {
                    let id = self.req_attr(c, "id")?;
                    let (t, _) = self.textures.get(&id).ok_or_else(|| {
                        self.err(
                            c,
                            format!("bsdf 'bumpmap': reference to undefined texture '{id}'"),
                        )
                    })?;
                    t.clone()
                }
                _ => return Err(self.err(c, format!("unexpected <{tag}> inside a bsdf"))),
            };
            if !matches!(t, TextureDesc::Bitmap { .. }) {
                return Err(self.err(
                    c,
                    "bsdf 'bumpmap': the height must be a bitmap (Mitsuba defines no gradient for other textures)",
                ));
            }
            if height.replace(t).is_some() {
                return Err(self.err(c, "bsdf 'bumpmap' takes one texture, not two"));
            }
        }
        let Some(height) = height else {
            return Err(self.err(node, "bsdf 'bumpmap' needs its height texture (a bitmap)"));
        };
        let scale = props.float("scale")?.unwrap_or(defaults::BUMP_SCALE);
        if !scale.is_finite() {
            return Err(self.err(
                props.node_or("scale", node),
                format!("bsdf 'bumpmap': scale {scale} must be finite"),
            ));
        }
        let flip_invalid_normals = props.bool("flip_invalid_normals")?.unwrap_or(true);
        let use_shadowing_function = props.bool("use_shadowing_function")?.unwrap_or(true);
        let (inner, mut textures) = inner.split_textures();
        textures.push(TextureBinding {
            param: ColorParam::BumpMap,
            texture: height,
        });
        let m = MaterialDesc::BumpMap {
            scale,
            flip_invalid_normals,
            use_shadowing_function,
            material: Box::new(inner),
        }
        .with_textures(textures);
        crate::material::check(&m).map_err(|e| self.err(node, format!("bsdf 'bumpmap': {e}")))?;
        props.finish();
        Ok(m)
    }
}
