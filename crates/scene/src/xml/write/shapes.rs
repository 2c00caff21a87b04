//! Shapes and emitters as Mitsuba 3 spells them.

use super::*;

impl Writer<'_> {
    pub(super) fn shape(
        &mut self,
        s: &ShapeDesc,
        index: usize,
        materials: &HashSet<&str>,
        material_id: &dyn Fn(&str) -> String,
    ) -> Result<()> {
        let item = match &s.id {
            Some(id) => format!("shape {index} ('{id}')"),
            None => format!("shape {index}"),
        };
        if let Some(id) = &s.id {
            literal(&item, "id", id)?;
        }
        let id_attr =
            s.id.as_ref()
                .map_or(String::new(), |i| format!(r#" id="{}""#, esc(i)));
        let mut mesh_file = false;
        // A sphere's transform is folded into its centre and radius unless it turns the sphere
        // (which turns its texture): then centre, radius and transform are written as given.
        let mut fold_sphere = true;
        match &s.geometry {
            GeometryDesc::Rectangle => self.open(&format!(r#"<shape type="rectangle"{id_attr}>"#)),
            GeometryDesc::Cube => self.open(&format!(r#"<shape type="cube"{id_attr}>"#)),
            GeometryDesc::Disk => self.open(&format!(r#"<shape type="disk"{id_attr}>"#)),
            GeometryDesc::Sphere { center, radius } => {
                let (c, r, turned) =
                    world_sphere(*center, *radius, &s.to_world).or_else(|e| refuse(&item, e))?;
                let (c, r) = if turned {
                    fold_sphere = false;
                    (*center, *radius)
                } else {
                    (c, r)
                };
                self.open(&format!(r#"<shape type="sphere"{id_attr}>"#));
                self.line(&format!(
                    r#"<point name="center" x="{}" y="{}" z="{}"/>"#,
                    num(c[0]),
                    num(c[1]),
                    num(c[2])
                ));
                self.float("radius", r);
            }
            GeometryDesc::Cylinder { p0, p1, radius } => {
                self.open(&format!(r#"<shape type="cylinder"{id_attr}>"#));
                for (name, p) in [("p0", p0), ("p1", p1)] {
                    finite(&item, name, p)?;
                    self.line(&format!(
                        r#"<point name="{name}" x="{}" y="{}" z="{}"/>"#,
                        num(p[0]),
                        num(p[1]),
                        num(p[2])
                    ));
                }
                self.float("radius", *radius);
            }
            GeometryDesc::SdfGrid { filename, normals } => {
                if s.emission.is_some() {
                    return refuse(item, "an sdfgrid cannot be an area emitter");
                }
                if s.flip_normals {
                    return refuse(item, "an sdfgrid takes no flip_normals");
                }
                self.open(&format!(r#"<shape type="sdfgrid"{id_attr}>"#));
                let f = self.file(filename, &item)?;
                self.string("filename", &f);
                self.string("normals", normals.name());
            }
            GeometryDesc::Obj { filename } | GeometryDesc::Ply { filename } => {
                let ty = if matches!(s.geometry, GeometryDesc::Obj { .. }) {
                    "obj"
                } else {
                    "ply"
                };
                self.open(&format!(r#"<shape type="{ty}"{id_attr}>"#));
                let f = self.file(filename, &item)?;
                self.string("filename", &f);
                mesh_file = true;
            }
            GeometryDesc::Serialized {
                filename,
                shape_index,
            } => {
                self.open(&format!(r#"<shape type="serialized"{id_attr}>"#));
                let f = self.file(filename, &item)?;
                self.string("filename", &f);
                self.line(&format!(
                    r#"<integer name="shape_index" value="{shape_index}"/>"#
                ));
                mesh_file = true;
            }
            GeometryDesc::Mesh { .. } => {
                return refuse(
                    item,
                    "an inline triangle mesh: Mitsuba 3 XML has none (write the triangles to a PLY or OBJ file and name it)",
                );
            }
        }
        if !matches!(s.geometry, GeometryDesc::Sphere { .. }) || !fold_sphere {
            self.transform("to_world", &s.to_world, &item)?;
        }
        if s.flip_normals {
            self.boolean("flip_normals", true);
        }
        if s.face_normals && mesh_file {
            self.boolean("face_normals", true);
        }
        match &s.material {
            Some(MaterialRef::Ref(name)) => {
                if !materials.contains(name.as_str()) {
                    return refuse(item, format!("it refers to an undefined material '{name}'"));
                }
                self.line(&format!(r#"<ref id="{}"/>"#, esc(&material_id(name))));
            }
            Some(MaterialRef::Inline(m)) => self.bsdf(m, None, None, &item)?,
            // Mitsuba's rule is this renderer's: a shape without a bsdf is diffuse 0.5, an
            // area light without one is black.
            None => {}
        }
        if let Some(e) = &s.emission {
            finite(&item, "emission", e)?;
            self.open(r#"<emitter type="area">"#);
            match &s.emission_texture {
                None => self.rgb("radiance", e),
                // Mitsuba's area emitter takes a colour or a texture, not their product.
                Some(_) if *e != [1.0; 3] => {
                    return refuse(
                        &item,
                        format!(
                            "its emission texture has the factor {e:?}, which Mitsuba's area \
                             emitter cannot hold beside a texture (only (1, 1, 1))"
                        ),
                    );
                }
                Some(t) => self.texture(t, "radiance", &item)?,
            }
            self.close("</emitter>");
        }
        self.close("</shape>");
        Ok(())
    }

    pub(super) fn emitter(&mut self, l: &LightDesc) -> Result<()> {
        match l {
            LightDesc::Point {
                position,
                intensity,
            } => {
                finite("a point light", "intensity", intensity)?;
                self.open(r#"<emitter type="point">"#);
                self.line(&format!(
                    r#"<point name="position" x="{}" y="{}" z="{}"/>"#,
                    num(position[0]),
                    num(position[1]),
                    num(position[2])
                ));
                self.rgb("intensity", intensity);
            }
            LightDesc::Spot {
                intensity,
                cutoff_angle,
                beam_width,
                to_world,
                texture,
                ..
            } => {
                finite("a spot light", "intensity", intensity)?;
                finite("a spot light", "cutoff_angle", &[*cutoff_angle])?;
                self.open(r#"<emitter type="spot">"#);
                self.rgb("intensity", intensity);
                if *cutoff_angle != defaults::SPOT_CUTOFF_ANGLE {
                    self.float("cutoff_angle", *cutoff_angle);
                }
                if let Some(b) = beam_width {
                    finite("a spot light", "beam_width", &[*b])?;
                    self.float("beam_width", *b);
                }
                self.transform("to_world", to_world, "a spot light")?;
                if let Some(t) = texture {
                    self.texture(t, "texture", "a spot light")?;
                }
            }
            LightDesc::Projector {
                irradiance,
                scale,
                fov,
                fov_axis,
                to_world,
                texture,
                ..
            } => {
                let item = "a projector";
                finite(item, "irradiance", irradiance)?;
                finite(item, "scale", &[*scale])?;
                self.open(r#"<emitter type="projector">"#);
                match texture {
                    None => self.rgb("irradiance", irradiance),
                    Some(_) if *irradiance != defaults::EMISSION => {
                        return refuse(
                            item,
                            "Mitsuba's irradiance is a colour or a texture, not the product \
                             of both",
                        );
                    }
                    Some(t) => self.texture(t, "irradiance", item)?,
                }
                if *scale != defaults::PROJECTOR_SCALE {
                    self.float("scale", *scale);
                }
                if let Some(f) = fov {
                    finite(item, "fov", &[*f])?;
                    self.float("fov", *f);
                    self.string("fov_axis", fov_axis_name(*fov_axis));
                }
                self.transform("to_world", to_world, item)?;
            }
            LightDesc::Directional {
                direction,
                irradiance,
            } => {
                finite("a directional light", "irradiance", irradiance)?;
                finite("a directional light", "direction", direction)?;
                self.open(r#"<emitter type="directional">"#);
                self.line(&format!(
                    r#"<vector name="direction" x="{}" y="{}" z="{}"/>"#,
                    num(direction[0]),
                    num(direction[1]),
                    num(direction[2])
                ));
                self.rgb("irradiance", irradiance);
            }
            LightDesc::Constant { radiance } => {
                finite("the constant environment", "radiance", radiance)?;
                self.open(r#"<emitter type="constant">"#);
                self.rgb("radiance", radiance);
            }
            LightDesc::Envmap {
                filename,
                scale,
                to_world,
                ..
            } => {
                finite("the environment map", "scale", &[*scale])?;
                self.open(r#"<emitter type="envmap">"#);
                let f = self.file(filename, "the environment map")?;
                self.string("filename", &f);
                if *scale != defaults::ENVMAP_SCALE {
                    self.float("scale", *scale);
                }
                self.transform("to_world", to_world, "the environment map")?;
            }
        }
        self.close("</emitter>");
        Ok(())
    }
}

/// A sphere's world-space centre and radius, exactly as the builder computes them (so that the
/// sphere written without a transform builds to the same bits).
fn world_sphere(
    center: V3,
    radius: f32,
    to_world: &[TransformOp],
) -> core::result::Result<(V3, f32, bool), String> {
    if to_world.is_empty() {
        return Ok((center, radius, false));
    }
    let m = transform_matrix(to_world).map_err(|e| format!("to_world: {e}"))?;
    let a = glam::Affine3A::from_mat4(m);
    let c = a.transform_point3(Vec3::from(center));
    let scale = a.matrix3.x_axis.length();
    let (sy, sz) = (a.matrix3.y_axis.length(), a.matrix3.z_axis.length());
    if (sy - scale).abs() > 1e-4 * scale || (sz - scale).abs() > 1e-4 * scale {
        return Err("spheres take only uniform scales".into());
    }
    let turned = (glam::Mat3::from(a.matrix3) / scale - glam::Mat3::IDENTITY)
        .to_cols_array()
        .iter()
        .any(|v| v.abs() > 1e-6);
    Ok((c.to_array(), radius * scale, turned))
}
