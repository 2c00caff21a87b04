//! Materials and textures as Mitsuba 3 spells them.

use super::*;

impl Writer<'_> {
    /// A `<bsdf>`: with an `id` at the top level, with a `name`... never (bsdfs are nested
    /// unnamed); `textures` are the bindings of an enclosing `Textured`, written inside the
    /// model that owns the parameters.
    pub(super) fn bsdf(
        &mut self,
        m: &MaterialDesc,
        id: Option<&str>,
        textures: Option<&[TextureBinding]>,
        item: &str,
    ) -> Result<()> {
        if textures.is_none()
            && let Err(e) = crate::material::check(m)
        {
            return refuse(item, e.to_string());
        }
        let id_attr = id.map_or(String::new(), |i| format!(r#" id="{}""#, esc(i)));
        let bound = |p: ColorParam| textures.and_then(|t| t.iter().find(|b| b.param == p));
        match m {
            MaterialDesc::Textured {
                material,
                textures: t,
            } => {
                if textures.is_some() {
                    return refuse(
                        item,
                        "textures are bound twice (a Textured inside a Textured)",
                    );
                }
                return self.bsdf(material, id, Some(t), item);
            }
            MaterialDesc::TwoSided(inner) => {
                self.open(&format!(r#"<bsdf type="twosided"{id_attr}>"#));
                self.bsdf(inner, None, textures, item)?;
                self.close("</bsdf>");
                return Ok(());
            }
            MaterialDesc::Mask { opacity, material } => {
                self.open(&format!(r#"<bsdf type="mask"{id_attr}>"#));
                match bound(ColorParam::Opacity) {
                    Some(b) => self.texture(&b.texture, "opacity", item)?,
                    None => self.float("opacity", *opacity),
                }
                let rest: Option<Vec<TextureBinding>> = textures.map(|t| {
                    t.iter()
                        .filter(|b| b.param != ColorParam::Opacity)
                        .cloned()
                        .collect()
                });
                self.bsdf(material, None, rest.as_deref(), item)?;
                self.close("</bsdf>");
                return Ok(());
            }
            MaterialDesc::NormalMap {
                normal,
                flip_invalid_normals,
                use_shadowing_function,
                material,
            } => {
                self.open(&format!(r#"<bsdf type="normalmap"{id_attr}>"#));
                match bound(ColorParam::NormalMap) {
                    Some(b) => self.texture(&b.texture, "normalmap", item)?,
                    None => {
                        self.open(r#"<texture name="normalmap" type="rawconstant">"#);
                        self.line(&format!(
                            r#"<vector name="value" value="{}"/>"#,
                            nums(normal)
                        ));
                        self.close("</texture>");
                    }
                }
                self.boolean("flip_invalid_normals", *flip_invalid_normals);
                self.boolean("use_shadowing_function", *use_shadowing_function);
                let rest: Option<Vec<TextureBinding>> = textures.map(|t| {
                    t.iter()
                        .filter(|b| b.param != ColorParam::NormalMap)
                        .cloned()
                        .collect()
                });
                self.bsdf(material, None, rest.as_deref(), item)?;
                self.close("</bsdf>");
                return Ok(());
            }
            MaterialDesc::BumpMap {
                scale,
                flip_invalid_normals,
                use_shadowing_function,
                material,
            } => {
                self.open(&format!(r#"<bsdf type="bumpmap"{id_attr}>"#));
                match bound(ColorParam::BumpMap) {
                    Some(b) => self.texture(&b.texture, "bumpmap", item)?,
                    None => return refuse(item, "a bumpmap without its height texture"),
                }
                finite(item, "scale", &[*scale])?;
                self.float("scale", *scale);
                self.boolean("flip_invalid_normals", *flip_invalid_normals);
                self.boolean("use_shadowing_function", *use_shadowing_function);
                let rest: Option<Vec<TextureBinding>> = textures.map(|t| {
                    t.iter()
                        .filter(|b| b.param != ColorParam::BumpMap)
                        .cloned()
                        .collect()
                });
                self.bsdf(material, None, rest.as_deref(), item)?;
                self.close("</bsdf>");
                return Ok(());
            }
            MaterialDesc::Blend { weight, bsdfs } => {
                if let Some(b) =
                    textures.and_then(|t| t.iter().find(|b| b.param != ColorParam::Weight))
                {
                    return refuse(
                        item,
                        format!("the blendbsdf has no parameter '{}'", b.param.name()),
                    );
                }
                self.open(&format!(r#"<bsdf type="blendbsdf"{id_attr}>"#));
                match bound(ColorParam::Weight) {
                    Some(b) => self.texture(&b.texture, "weight", item)?,
                    None => self.float("weight", *weight),
                }
                self.bsdf(&bsdfs.0, None, None, item)?;
                self.bsdf(&bsdfs.1, None, None, item)?;
                self.close("</bsdf>");
                return Ok(());
            }
            _ => {}
        }
        // The colour parameters, constant or textured.
        let colour = |w: &mut Self, p: ColorParam, v: &V3| -> Result<()> {
            match bound(p) {
                Some(b) => w.texture(&b.texture, p.name(), item),
                None => {
                    w.rgb(p.name(), v);
                    Ok(())
                }
            }
        };
        if let Some(t) = textures {
            let allowed = crate::material::color_params(m);
            if let Some(b) = t.iter().find(|b| !allowed.contains(&b.param)) {
                return refuse(
                    item,
                    format!("the material has no parameter '{}'", b.param.name()),
                );
            }
        }
        match m {
            MaterialDesc::Diffuse { reflectance } => {
                self.open(&format!(r#"<bsdf type="diffuse"{id_attr}>"#));
                colour(self, ColorParam::Reflectance, reflectance)?;
            }
            MaterialDesc::Black => {
                self.open(&format!(r#"<bsdf type="diffuse"{id_attr}>"#));
                self.rgb("reflectance", &[0.0; 3]);
            }
            MaterialDesc::Null => {
                self.open(&format!(r#"<bsdf type="null"{id_attr}>"#));
            }
            MaterialDesc::Conductor {
                ior,
                specular_reflectance,
            }
            | MaterialDesc::RoughConductor {
                ior,
                specular_reflectance,
                ..
            } => {
                let rough = match m {
                    MaterialDesc::RoughConductor { roughness, .. } => Some(roughness),
                    _ => None,
                };
                let ty = if rough.is_some() {
                    "roughconductor"
                } else {
                    "conductor"
                };
                self.open(&format!(r#"<bsdf type="{ty}"{id_attr}>"#));
                if let Some(name) = &ior.material {
                    self.string("material", name);
                }
                if let Some(eta) = &ior.eta {
                    self.rgb("eta", eta);
                }
                if let Some(k) = &ior.k {
                    self.rgb("k", k);
                }
                colour(self, ColorParam::SpecularReflectance, specular_reflectance)?;
                if let Some(r) = rough {
                    self.roughness_textured(r, textures.unwrap_or(&[]), item)?;
                }
            }
            MaterialDesc::Dielectric {
                int_ior,
                ext_ior,
                specular_reflectance,
                specular_transmittance,
            }
            | MaterialDesc::ThinDielectric {
                int_ior,
                ext_ior,
                specular_reflectance,
                specular_transmittance,
            }
            | MaterialDesc::RoughDielectric {
                int_ior,
                ext_ior,
                specular_reflectance,
                specular_transmittance,
                ..
            } => {
                let rough = match m {
                    MaterialDesc::RoughDielectric { roughness, .. } => Some(roughness),
                    _ => None,
                };
                let ty = match m {
                    MaterialDesc::RoughDielectric { .. } => "roughdielectric",
                    MaterialDesc::ThinDielectric { .. } => "thindielectric",
                    _ => "dielectric",
                };
                self.open(&format!(r#"<bsdf type="{ty}"{id_attr}>"#));
                self.float("int_ior", *int_ior);
                self.float("ext_ior", *ext_ior);
                colour(self, ColorParam::SpecularReflectance, specular_reflectance)?;
                colour(
                    self,
                    ColorParam::SpecularTransmittance,
                    specular_transmittance,
                )?;
                if let Some(r) = rough {
                    self.roughness_textured(r, textures.unwrap_or(&[]), item)?;
                }
            }
            MaterialDesc::Plastic {
                int_ior,
                ext_ior,
                diffuse_reflectance,
                specular_reflectance,
                nonlinear,
            }
            | MaterialDesc::RoughPlastic {
                int_ior,
                ext_ior,
                diffuse_reflectance,
                specular_reflectance,
                nonlinear,
                ..
            } => {
                let rough = match m {
                    MaterialDesc::RoughPlastic { roughness, .. } => Some(roughness),
                    _ => None,
                };
                let ty = if rough.is_some() {
                    "roughplastic"
                } else {
                    "plastic"
                };
                self.open(&format!(r#"<bsdf type="{ty}"{id_attr}>"#));
                self.float("int_ior", *int_ior);
                self.float("ext_ior", *ext_ior);
                colour(self, ColorParam::DiffuseReflectance, diffuse_reflectance)?;
                colour(self, ColorParam::SpecularReflectance, specular_reflectance)?;
                self.boolean("nonlinear", *nonlinear);
                if let Some(r) = rough {
                    self.roughness(r);
                }
            }
            MaterialDesc::Principled { .. } | MaterialDesc::PrincipledThin { .. } => {
                let ty = if matches!(m, MaterialDesc::Principled { .. }) {
                    "principled"
                } else {
                    "principledthin"
                };
                self.open(&format!(r#"<bsdf type="{ty}"{id_attr}>"#));
                self.principled_params(m, textures.unwrap_or(&[]), item)?;
            }
            MaterialDesc::Textured { .. }
            | MaterialDesc::TwoSided(_)
            | MaterialDesc::Mask { .. }
            | MaterialDesc::NormalMap { .. }
            | MaterialDesc::BumpMap { .. }
            | MaterialDesc::Blend { .. } => {
                unreachable!()
            }
        }
        self.close("</bsdf>");
        Ok(())
    }

    /// [`Self::roughness`] where some of `alpha`, `alpha_u`, `alpha_v` may be textures.
    fn roughness_textured(
        &mut self,
        r: &RoughnessDesc,
        textures: &[TextureBinding],
        item: &str,
    ) -> Result<()> {
        let bound = |p: ColorParam| textures.iter().find(|b| b.param == p);
        let alpha_params = [ColorParam::Alpha, ColorParam::AlphaU, ColorParam::AlphaV];
        if alpha_params.iter().all(|p| bound(*p).is_none()) {
            self.roughness(r);
            return Ok(());
        }
        self.string(
            "distribution",
            match r.distribution {
                MicrofacetDesc::Beckmann => "beckmann",
                MicrofacetDesc::Ggx => "ggx",
            },
        );
        if let Some(b) = bound(ColorParam::Alpha) {
            return self.texture(&b.texture, "alpha", item);
        }
        for (p, v) in [
            (ColorParam::AlphaU, r.alpha_u.unwrap_or(r.alpha)),
            (ColorParam::AlphaV, r.alpha_v.unwrap_or(r.alpha)),
        ] {
            match bound(p) {
                Some(b) => self.texture(&b.texture, p.name(), item)?,
                None => self.float(p.name(), v),
            }
        }
        Ok(())
    }

    pub(super) fn roughness(&mut self, r: &RoughnessDesc) {
        self.string(
            "distribution",
            match r.distribution {
                MicrofacetDesc::Beckmann => "beckmann",
                MicrofacetDesc::Ggx => "ggx",
            },
        );
        match (r.alpha_u, r.alpha_v) {
            (Some(u), Some(v)) => {
                self.float("alpha_u", u);
                self.float("alpha_v", v);
            }
            _ => self.float("alpha", r.alpha),
        }
    }

    /// A `<texture name=...>` nested in a bsdf.
    pub(super) fn texture(&mut self, t: &TextureDesc, name: &str, item: &str) -> Result<()> {
        let uv = match t {
            TextureDesc::Bitmap { uv, .. } | TextureDesc::Checkerboard { uv, .. } => uv,
            TextureDesc::MeshAttribute {
                name: attribute,
                scale,
            } => {
                finite(item, "mesh_attribute scale", &[*scale])?;
                literal(item, "mesh attribute name", attribute)?;
                self.open(&format!(r#"<texture type="mesh_attribute" name="{name}">"#));
                self.string("name", attribute);
                if *scale != 1.0 {
                    self.float("scale", *scale);
                }
                self.close("</texture>");
                return Ok(());
            }
        };
        finite(
            item,
            "texture uv transform",
            &[uv.scale.x, uv.scale.y, uv.offset.x, uv.offset.y],
        )?;
        match t {
            TextureDesc::Bitmap {
                filename,
                raw,
                wrap,
                filter,
                ..
            } => {
                self.open(&format!(r#"<texture type="bitmap" name="{name}">"#));
                let f = self.file(filename, item)?;
                self.string("filename", &f);
                if *raw {
                    self.boolean("raw", true);
                }
                if *wrap != WrapMode::default() {
                    self.string("wrap_mode", wrap.name());
                }
                if *filter != FilterType::default() {
                    self.string("filter_type", filter.name());
                }
            }
            TextureDesc::Checkerboard { color0, color1, .. } => {
                self.open(&format!(r#"<texture type="checkerboard" name="{name}">"#));
                self.rgb("color0", color0);
                self.rgb("color1", color1);
            }
            // Written above, without a uv transform.
            TextureDesc::MeshAttribute { .. } => return Ok(()),
        }
        if *uv != UvTransform::default() {
            self.open(r#"<transform name="to_uv">"#);
            self.line(&format!(
                r#"<scale x="{}" y="{}" z="1"/>"#,
                num(uv.scale.x),
                num(uv.scale.y)
            ));
            if uv.offset != glam::Vec2::ZERO {
                self.line(&format!(
                    r#"<translate x="{}" y="{}" z="0"/>"#,
                    num(uv.offset.x),
                    num(uv.offset.y)
                ));
            }
            self.close("</transform>");
        }
        self.close("</texture>");
        Ok(())
    }
}
