//! Top-level `<emitter>`s: point, spot, projector, directional, constant and envmap (area
//! emitters belong to shapes).

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
            "projector" => self.projector(node, &props)?,
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
                        "projector",
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
        for (c, name, t) in self.emitter_textures(node, "spot")? {
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

    /// Mitsuba's `projector` (plugin page "Projection light source"): `irradiance` (a colour or
    /// a nested or referenced texture, default 1), `scale` (1), the perspective sensor's field of
    /// view (`fov` along `fov_axis`, or `focal_length`, default a 50 mm lens), `to_world`.
    fn projector<'i>(&self, node: Node<'a, 'i>, props: &Props) -> Result<LightDesc> {
        let color = props.color("irradiance", ColorUse::Emission)?;
        let scale = props.float("scale")?.unwrap_or(defaults::PROJECTOR_SCALE);
        if !(scale.is_finite() && scale >= 0.0) {
            return Err(self.err(
                props.node_or("scale", node),
                format!("projector emitter: scale {scale} must be finite and non-negative"),
            ));
        }
        let mut texture = None;
        for (c, name, t) in self.emitter_textures(node, "projector")? {
            match name.as_str() {
                "irradiance" if texture.is_some() => {
                    return Err(self.err(c, "projector emitter: a second 'irradiance'"));
                }
                "irradiance" if color.is_some() => {
                    return Err(self.err(
                        c,
                        "projector emitter: 'irradiance' is given both as a colour and as a texture (give one)",
                    ));
                }
                "irradiance" => texture = Some(t),
                other => {
                    return Err(self.err(
                        c,
                        format!(
                            "projector emitter: '{other}' cannot be a texture (only 'irradiance' can)"
                        ),
                    ));
                }
            }
        }
        let (fov, fov_axis) = self.field_of_view(node, props, "emitter 'projector'")?;
        Ok(LightDesc::Projector {
            irradiance: color.unwrap_or(defaults::EMISSION),
            scale,
            fov: Some(fov),
            fov_axis,
            to_world: props.transform("to_world")?,
            texture,
            location: self.loc(node),
        })
    }

    /// The nested (`<texture name=…>`) and referenced (`<ref name=… id=…>`) textures of emitter
    /// `node` (a `plugin` emitter, for messages): each element with its name and texture.
    pub(super) fn emitter_textures<'i>(
        &self,
        node: Node<'a, 'i>,
        plugin: &str,
    ) -> Result<Vec<(Node<'a, 'i>, String, TextureDesc)>> {
        let mut found = Vec::new();
        for c in elements(node) {
            match c.tag_name().name() {
                "texture" => found.push((c, self.req_attr(c, "name")?, self.texture(c)?)),
                "ref" => {
                    let id = self.req_attr(c, "id")?;
                    let (t, _) = self.textures.get(&id).ok_or_else(|| {
                        self.err(
                            c,
                            format!("{plugin} emitter: reference to undefined texture '{id}'"),
                        )
                    })?;
                    found.push((c, self.attr(c, "name")?.unwrap_or_default(), t.clone()));
                }
                _ => {}
            }
        }
        Ok(found)
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use crate::desc::{FovAxis, LightDesc, TextureDesc, defaults};

    fn projector(body: &str) -> LightDesc {
        let xml = format!(
            r#"<scene version="3.0.0"><sensor type="perspective"/><emitter type="projector">{body}</emitter></scene>"#
        );
        let (desc, warnings) = crate::xml::parse_xml(&xml, Path::new("p.xml"), &[]).unwrap();
        assert!(warnings.is_empty(), "{warnings:?}");
        desc.lights.into_iter().next().unwrap()
    }

    /// Mitsuba's defaults: irradiance 1, scale 1, a 50 mm lens on the diagonal; `fov` along
    /// `fov_axis`; the irradiance as a nested texture.
    #[test]
    fn projector_defaults_fov_and_texture() {
        let LightDesc::Projector {
            irradiance,
            scale,
            fov,
            fov_axis,
            texture,
            ..
        } = projector("")
        else {
            panic!("not a projector")
        };
        assert_eq!((irradiance, scale), (defaults::EMISSION, 1.0));
        assert_eq!(
            (fov, fov_axis),
            (
                Some(defaults::fov_of_focal_length(defaults::FOCAL_LENGTH_MM)),
                FovAxis::Diagonal
            )
        );
        assert!(texture.is_none());
        let LightDesc::Projector {
            scale,
            fov,
            fov_axis,
            texture,
            ..
        } = projector(
            r#"<float name="scale" value="15"/><float name="fov" value="30"/>
               <string name="fov_axis" value="smaller"/>
               <texture type="checkerboard" name="irradiance"/>"#,
        )
        else {
            panic!("not a projector")
        };
        assert_eq!((scale, fov, fov_axis), (15.0, Some(30.0), FovAxis::Smaller));
        assert!(matches!(texture, Some(TextureDesc::Checkerboard { .. })));
    }
}
