//! `<shape>`: built-in shapes and mesh files, with their bsdf (nested or by reference) and area
//! emitter. Mitsuba 3's plugin pages: `rectangle`, `cube`, `disk`, `sphere`, `cylinder` (p0, p1,
//! radius; an open tube), `sdfgrid` (a signed distance grid from a `.vol` file, `normals`
//! smooth or analytic; no uv and no emitter), `obj`, `ply`, `serialized`.

use roxmltree::Node;

use super::props::{ColorUse, PROPERTY_TAGS};
use super::{Importer, Result, elements, snake_case};
use crate::desc::*;

impl<'a> Importer<'a> {
    pub(super) fn shape<'i>(&self, node: Node<'a, 'i>) -> Result<ShapeDesc> {
        let ty = self.plugin_type(node)?;
        let props = self.props(node, format!("shape '{ty}'"))?;
        let geometry = match ty.as_str() {
            "rectangle" => GeometryDesc::Rectangle,
            "cube" => GeometryDesc::Cube,
            "disk" => GeometryDesc::Disk,
            "sphere" => {
                let center = props.position("center")?.unwrap_or(defaults::SPHERE_CENTER);
                let radius = props.length("radius")?.unwrap_or(defaults::SPHERE_RADIUS);
                if radius <= 0.0 {
                    return Err(self.err(node, format!("sphere radius {radius} must be positive")));
                }
                GeometryDesc::Sphere { center, radius }
            }
            "cylinder" => {
                let p0 = props.position("p0")?.unwrap_or(defaults::CYLINDER_P0);
                let p1 = props.position("p1")?.unwrap_or(defaults::CYLINDER_P1);
                let radius = props.length("radius")?.unwrap_or(defaults::CYLINDER_RADIUS);
                if radius <= 0.0 {
                    return Err(self.err(
                        props.node_or("radius", node),
                        format!("cylinder radius {radius} must be positive"),
                    ));
                }
                if p0 == p1 {
                    return Err(self.err(
                        props.node_or("p1", node),
                        format!(
                            "cylinder p0 and p1 are the same point {p0:?}: the axis needs a length"
                        ),
                    ));
                }
                GeometryDesc::Cylinder { p0, p1, radius }
            }
            "sdfgrid" => {
                let f = props.string("filename")?.ok_or_else(|| {
                    self.err(
                        node,
                        "sdfgrid shape needs a 'filename' (a grid volume .vol file; Mitsuba's \
                         'grid' tensor cannot be given in XML)",
                    )
                })?;
                let f = self.file_name(props.node_or("filename", node), f)?;
                let normals = match props.string("normals")?.as_deref() {
                    None | Some("smooth") => SdfNormalsDesc::Smooth,
                    Some("analytic") => SdfNormalsDesc::Analytic,
                    Some(other) => {
                        return Err(self.err(
                            props.node_or("normals", node),
                            format!("sdfgrid normals '{other}' is not one of: smooth, analytic"),
                        ));
                    }
                };
                if props.bool("flip_normals")?.is_some() {
                    return Err(self.err(
                        props.node_or("flip_normals", node),
                        "sdfgrid takes no 'flip_normals' (its normals follow the distance \
                         gradient, as in Mitsuba 3)",
                    ));
                }
                if let Some(e) = elements(node).find(|e| e.tag_name().name() == "emitter") {
                    return Err(self.err(
                        e,
                        "an sdfgrid cannot be an area emitter (as in Mitsuba 3: it has no \
                         area to sample)",
                    ));
                }
                GeometryDesc::SdfGrid {
                    filename: f,
                    normals,
                }
            }
            "obj" => {
                let f = props
                    .string("filename")?
                    .ok_or_else(|| self.err(node, "obj shape needs a 'filename'"))?;
                let f = self.file_name(props.node_or("filename", node), f)?;
                GeometryDesc::Obj { filename: f }
            }
            "ply" => {
                let f = props
                    .string("filename")?
                    .ok_or_else(|| self.err(node, "ply shape needs a 'filename'"))?;
                let f = self.file_name(props.node_or("filename", node), f)?;
                GeometryDesc::Ply { filename: f }
            }
            "serialized" => {
                let f = props
                    .string("filename")?
                    .ok_or_else(|| self.err(node, "serialized shape needs a 'filename'"))?;
                let f = self.file_name(props.node_or("filename", node), f)?;
                let i = props.int("shape_index")?.unwrap_or(0);
                let shape_index = u32::try_from(i).map_err(|_| {
                    self.err(
                        node,
                        format!("shape_index {i} must be a non-negative integer"),
                    )
                })?;
                GeometryDesc::Serialized {
                    filename: f,
                    shape_index,
                }
            }
            other => {
                return Err(self.unknown_type(
                    node,
                    "shape",
                    other,
                    &[
                        "rectangle",
                        "cube",
                        "disk",
                        "sphere",
                        "cylinder",
                        "sdfgrid",
                        "obj",
                        "ply",
                        "serialized",
                        "shapegroup",
                        "instance",
                    ],
                ));
            }
        };
        let to_world = props.transform("to_world")?;
        let flip_normals = props.bool("flip_normals")?.unwrap_or(false);
        let face_normals = props.bool("face_normals")?.unwrap_or(false);
        let mut material = None;
        let mut emission = None;
        let mut emission_texture = None;
        for c in elements(node) {
            match c.tag_name().name() {
                "bsdf" => {
                    if material.is_some() {
                        return Err(self.err(c, "a shape takes one bsdf"));
                    }
                    material = Some(MaterialRef::Inline(self.bsdf(c)?));
                }
                "ref" => {
                    let id = self.req_attr(c, "id")?;
                    if !self.bsdf_ids.contains_key(&id) {
                        return Err(self.err(c, format!("reference to undefined id '{id}'")));
                    }
                    if material.is_some() {
                        return Err(self.err(c, "a shape takes one bsdf"));
                    }
                    material = Some(MaterialRef::Ref(id));
                }
                "emitter" => {
                    let ety = self.plugin_type(c)?;
                    if ety != "area" {
                        return Err(
                            self.err(c, format!("shapes carry only 'area' emitters, not '{ety}'"))
                        );
                    }
                    if emission.is_some() {
                        return Err(self.err(c, "a shape takes one emitter"));
                    }
                    // `radiance` is a colour or a texture over the shape's uv.
                    let mut texture = None;
                    for (t, name, desc) in self.emitter_textures(c, "area")? {
                        if snake_case(&name) != "radiance" {
                            return Err(self.err(
                                t,
                                format!(
                                    "emitter 'area': '{name}' cannot be a texture (only 'radiance' can)"
                                ),
                            ));
                        }
                        if texture.is_some() {
                            return Err(self.err(t, "emitter 'area': a second 'radiance'"));
                        }
                        if let TextureDesc::MeshAttribute { name, .. } = &desc {
                            return Err(self.err(
                                t,
                                format!(
                                    "emitter 'area': a 'mesh_attribute' radiance (\"{name}\") is not supported (give a bitmap, a checkerboard or a colour)"
                                ),
                            ));
                        }
                        texture = Some(desc);
                    }
                    let ep = self.props(c, "emitter 'area'".into())?;
                    let colour = ep.color("radiance", ColorUse::Emission)?;
                    if let (Some(_), Some(_)) = (&colour, &texture) {
                        return Err(self.err(
                            ep.node_or("radiance", c),
                            "emitter 'area': 'radiance' is given both as a colour and as a texture (give one)",
                        ));
                    }
                    ep.finish();
                    emission = Some(match texture {
                        Some(_) => [1.0; 3],
                        None => colour.unwrap_or(defaults::EMISSION),
                    });
                    emission_texture = texture;
                }
                t if PROPERTY_TAGS.contains(&t) => {}
                t => return Err(self.err(c, format!("unexpected <{t}> inside a shape"))),
            }
        }
        props.finish();
        Ok(ShapeDesc {
            id: self.attr(node, "id")?,
            geometry,
            to_world,
            material,
            emission,
            emission_texture,
            flip_normals,
            face_normals,
            location: self.loc(node),
        })
    }
}
