//! Top-level `<emitter>`s: point, directional, constant and envmap (area emitters belong to
//! shapes).

use roxmltree::Node;

use super::props::ColorUse;
use super::{Importer, Result};
use crate::desc::*;

impl<'a> Importer<'a> {
    pub(super) fn emitter<'i>(&self, node: Node<'a, 'i>) -> Result<LightDesc> {
        let ty = self.plugin_type(node)?;
        let props = self.props(node, format!("emitter '{ty}'"))?;
        let light = match ty.as_str() {
            "point" => {
                let intensity = props
                    .color("intensity", ColorUse::Emission)?
                    .unwrap_or(defaults::EMISSION);
                let position = match props.position("position")? {
                    Some(p) => p,
                    None => {
                        let m = crate::desc::transform_matrix(&props.transform("to_world")?)
                            .map_err(|e| self.err(node, e.to_string()))?;
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
                    .color("irradiance", ColorUse::Emission)?
                    .unwrap_or(defaults::EMISSION);
                let direction = match props.point("direction")? {
                    Some(d) => d,
                    None => {
                        let m = crate::desc::transform_matrix(&props.transform("to_world")?)
                            .map_err(|e| self.err(node, e.to_string()))?;
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
                    .color("radiance", ColorUse::Emission)?
                    .unwrap_or(defaults::EMISSION);
                LightDesc::Constant { radiance }
            }
            "envmap" => {
                let filename = props.string("filename")?.ok_or_else(|| {
                    self.err(
                        node,
                        "envmap emitter needs a 'filename' (EXR, HDR, PNG or JPEG)",
                    )
                })?;
                let filename = self.file_name(props.node_or("filename", node), filename)?;
                let scale = props.float("scale")?.unwrap_or(defaults::ENVMAP_SCALE);
                if !(scale.is_finite() && scale >= 0.0) {
                    return Err(self.err(
                        node,
                        format!("envmap scale {scale} must be finite and non-negative"),
                    ));
                }
                LightDesc::Envmap {
                    filename,
                    scale,
                    to_world: props.transform("to_world")?,
                    location: self.loc(node),
                }
            }
            "area" => return Err(self.err(node, "an area emitter must be inside a <shape>")),
            other => {
                return Err(self.unknown_type(
                    node,
                    "emitter",
                    other,
                    &[
                        "point",
                        "directional",
                        "constant",
                        "envmap",
                        "area (inside a shape)",
                    ],
                ));
            }
        };
        props.finish();
        Ok(light)
    }
}
