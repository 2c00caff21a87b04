//! Top-level `<emitter>`s: point, spot, directional, constant and envmap (area emitters belong
//! to shapes).

use roxmltree::Node;

use super::props::{ColorUse, Props};
use super::{Importer, Result, elements};
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
            "spot" => self.spot(node, &props)?,
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
                        "spot",
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

    /// Mitsuba's `spot` (plugin page "Spot light source"): `intensity` (a colour, not a
    /// texture), `cutoff_angle` (20°), `beam_width` (¾ of the cutoff), `to_world`, and an
    /// optional `texture` (nested or by reference) projected along the axis.
    fn spot<'i>(&self, node: Node<'a, 'i>, props: &Props) -> Result<LightDesc> {
        let intensity = props
            .color("intensity", ColorUse::Emission)?
            .unwrap_or(defaults::EMISSION);
        let cutoff_angle = props
            .float("cutoff_angle")?
            .unwrap_or(defaults::SPOT_CUTOFF_ANGLE);
        let beam_width = props.float("beam_width")?;
        if let Some(p) = props.get("texture") {
            return Err(props.err(
                p,
                "spot emitter: 'texture' must be a spatially varying texture (a nested or \
                 referenced <texture>: bitmap or checkerboard), as in Mitsuba 3",
            ));
        }
        let mut texture = None;
        for c in elements(node) {
            let tag = c.tag_name().name();
            let found = match tag {
                "texture" => Some((self.req_attr(c, "name")?, self.texture(c)?)),
                "ref" => {
                    let id = self.req_attr(c, "id")?;
                    let (t, _) = self.textures.get(&id).ok_or_else(|| {
                        self.err(
                            c,
                            format!("spot emitter: reference to undefined texture '{id}'"),
                        )
                    })?;
                    Some((self.attr(c, "name")?.unwrap_or_default(), t.clone()))
                }
                _ => None,
            };
            let Some((name, t)) = found else { continue };
            match name.as_str() {
                "texture" if texture.is_none() => texture = Some(t),
                "texture" => return Err(self.err(c, "spot emitter: a second 'texture'")),
                "intensity" => {
                    return Err(self.err(
                        c,
                        "spot emitter: 'intensity' cannot be a texture (give a colour; a \
                         spatially varying pattern goes in 'texture'), as in Mitsuba 3",
                    ));
                }
                other => {
                    return Err(self.err(
                        c,
                        format!("spot emitter: '{other}' cannot be a texture (only 'texture' can)"),
                    ));
                }
            }
        }
        let max_cutoff = if texture.is_some() { 90.0 } else { 180.0 };
        if !(cutoff_angle > 0.0 && cutoff_angle < max_cutoff) {
            return Err(self.err(
                props.node_or("cutoff_angle", node),
                format!(
                    "spot emitter: cutoff_angle {cutoff_angle}° must be in (0°, {max_cutoff}°){}",
                    if texture.is_some() {
                        " with a texture (its projection needs tan(cutoff_angle) > 0)"
                    } else {
                        ""
                    }
                ),
            ));
        }
        let beam = beam_width.unwrap_or(cutoff_angle * defaults::SPOT_BEAM_FRACTION);
        if !(beam >= 0.0 && beam <= cutoff_angle) {
            return Err(self.err(
                props.node_or("beam_width", node),
                format!(
                    "spot emitter: beam_width {beam}° must be in [0°, cutoff_angle] = [0°, \
                     {cutoff_angle}°]"
                ),
            ));
        }
        Ok(LightDesc::Spot {
            intensity,
            cutoff_angle,
            beam_width,
            to_world: props.transform("to_world")?,
            texture,
            location: self.loc(node),
        })
    }
}
