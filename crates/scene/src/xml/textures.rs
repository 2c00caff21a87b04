//! `<texture>`: `bitmap` and `checkerboard`, with their uv transform, and `mesh_attribute`.

use roxmltree::Node;

use super::props::{ColorUse, PROPERTY_TAGS};
use super::{Importer, Result, elements};
use crate::desc::defaults;
use crate::texture::{FilterType, TextureDesc, UvTransform, WrapMode};

impl<'a> Importer<'a> {
    /// A `<texture>`: `bitmap` or `checkerboard`, with Mitsuba 0.6 `uscale`/`vscale`/
    /// `uoffset`/`voffset` or Mitsuba 3 `to_uv` (scale and translation only), or
    /// `mesh_attribute` (`name`, `scale`).
    pub(super) fn texture<'i>(&self, node: Node<'a, 'i>) -> Result<TextureDesc> {
        let ty = self.plugin_type(node)?;
        let props = self.props(node, format!("texture '{ty}'"))?;
        if ty == "mesh_attribute" {
            // Mitsuba 3's plugin page "Mesh attribute texture": `name` (required), `scale` (1).
            let name = props.string("name")?.ok_or_else(|| {
                self.err(
                    node,
                    "texture 'mesh_attribute' needs a 'name' (an attribute of the mesh, \
                     such as vertex_color or face_color)",
                )
            })?;
            if restir_geometry::AttributeRate::of_name(&name).is_none() {
                return Err(self.err(
                    props.node_or("name", node),
                    format!(
                        "texture 'mesh_attribute': the name '{name}' must start with \
                         'vertex_' or 'face_'"
                    ),
                ));
            }
            let scale = props.float("scale")?.unwrap_or(1.0);
            if !scale.is_finite() {
                return Err(self.err(
                    props.node_or("scale", node),
                    format!("texture 'mesh_attribute': scale {scale} is not finite"),
                ));
            }
            self.only_properties(node)?;
            props.finish();
            return Ok(TextureDesc::MeshAttribute { name, scale });
        }
        let mut uv = UvTransform::default();
        let to_uv = props.transform("to_uv")?;
        if !to_uv.is_empty() {
            let m =
                crate::desc::transform_matrix(&to_uv).map_err(|e| self.err(node, e.to_string()))?;
            if m.x_axis.y.abs() > 1e-6 || m.y_axis.x.abs() > 1e-6 {
                return Err(self.err(
                    node,
                    format!("texture '{ty}': to_uv may only scale and translate"),
                ));
            }
            uv.scale = glam::Vec2::new(m.x_axis.x, m.y_axis.y);
            uv.offset = glam::Vec2::new(m.w_axis.x, m.w_axis.y);
        }
        let (us, vs) = (props.float("uscale")?, props.float("vscale")?);
        let (uo, vo) = (props.float("uoffset")?, props.float("voffset")?);
        uv.scale *= glam::Vec2::new(us.unwrap_or(1.0), vs.unwrap_or(1.0));
        uv.offset += glam::Vec2::new(uo.unwrap_or(0.0), vo.unwrap_or(0.0));
        let t = match ty.as_str() {
            "bitmap" => {
                let filename = props
                    .string("filename")?
                    .ok_or_else(|| self.err(node, "bitmap texture needs a 'filename'"))?;
                let filename = self.file_name(props.node_or("filename", node), filename)?;
                let path = self.scene_path(&filename);
                if path.exists() && !path.is_file() {
                    return Err(self.err(
                        node,
                        format!("bitmap texture: '{}' is not a regular file", path.display()),
                    ));
                }
                if !path.is_file() {
                    return Err(self.err(
                        node,
                        format!("bitmap texture: file '{}' not found", path.display()),
                    ));
                }
                let raw = props.bool("raw")?.unwrap_or(false);
                // Mitsuba 3's storage format: `variant` (floats, its default) is how textures
                // are kept here; `fixed` (8- or 16-bit integers) would round a float image's
                // texels.
                match props.string("format")?.as_deref() {
                    None | Some("variant") => {}
                    Some(f) => {
                        return Err(self.err(
                            props.node_or("format", node),
                            format!(
                                "texture 'bitmap': format '{f}' is not supported (textures are kept as floats, Mitsuba's 'variant')"
                            ),
                        ));
                    }
                }
                let filter = match props.string("filter_type")? {
                    None => FilterType::default(),
                    Some(f) => FilterType::from_name(&f).ok_or_else(|| {
                        self.err(
                            props.node_or("filter_type", node),
                            format!(
                                "texture 'bitmap': unknown filter_type '{f}' (known: {})",
                                FilterType::NAMES.join(", ")
                            ),
                        )
                    })?,
                };
                let wrap = match props.string("wrap_mode")? {
                    None => WrapMode::default(),
                    Some(w) => WrapMode::from_name(&w).ok_or_else(|| {
                        self.err(
                            props.node_or("wrap_mode", node),
                            format!(
                                "texture 'bitmap': unknown wrap_mode '{w}' (known: {})",
                                WrapMode::NAMES.join(", ")
                            ),
                        )
                    })?,
                };
                TextureDesc::Bitmap {
                    filename,
                    raw,
                    uv,
                    wrap,
                    filter,
                }
            }
            // Any non-negative colours: the parameter a checkerboard is bound to decides the
            // range (a reflectance [0, 1], `principledthin`'s `diff_trans` [0, 2]).
            "checkerboard" => TextureDesc::Checkerboard {
                color0: props
                    .color("color0", ColorUse::Unbounded)?
                    .unwrap_or(defaults::CHECKER_COLOR0),
                color1: props
                    .color("color1", ColorUse::Unbounded)?
                    .unwrap_or(defaults::CHECKER_COLOR1),
                uv,
            },
            other => {
                return Err(self.unknown_type(
                    node,
                    "texture",
                    other,
                    &["bitmap", "checkerboard", "mesh_attribute"],
                ));
            }
        };
        self.only_properties(node)?;
        props.finish();
        Ok(t)
    }

    /// Refuses a texture element that holds anything but properties.
    fn only_properties(&self, node: Node<'a, '_>) -> Result<()> {
        for c in elements(node) {
            let tag = c.tag_name().name();
            if !PROPERTY_TAGS.contains(&tag) {
                return Err(self.err(c, format!("unexpected <{tag}> inside a texture")));
            }
        }
        Ok(())
    }
}
