//! `<bsdf>`: the material models (diffuse, conductors, dielectrics, plastics, twosided, mask,
//! null; `blendbsdf` in `blend.rs`),
//! their roughness and IOR properties, and textures bound to their colour parameters.

use roxmltree::Node;

use super::props::{ColorUse, PROPERTY_TAGS, Props, Value};
use super::{Importer, Result, elements, snake_case};
use crate::desc::*;

/// The smallest roughness Lajolla's rough materials use (its `roughness`, clamped).
const LAJOLLA_MIN_ROUGHNESS: f32 = 0.01;

/// The `<bsdf>` types the importer reads.
const BSDF_TYPES: &[&str] = &[
    "diffuse",
    "twosided",
    "conductor",
    "roughconductor",
    "dielectric",
    "roughdielectric",
    "thindielectric",
    "plastic",
    "roughplastic",
    "null",
    "mask",
    "normalmap",
    "principled",
    "principledthin",
    "bumpmap",
    "blendbsdf",
];

impl<'a> Importer<'a> {
    /// A `<bsdf>` element (top-level, nested in a shape or wrapped by `twosided`).
    pub(super) fn bsdf<'i>(&self, node: Node<'a, 'i>) -> Result<MaterialDesc> {
        let ty = self.plugin_type(node)?;
        let props = self.props(node, format!("bsdf '{ty}'"))?;
        if ty == "normalmap" {
            return self.normalmap(node, props);
        }
        if ty == "bumpmap" {
            return self.bumpmap(node, props);
        }
        if ty == "blendbsdf" {
            return self.blendbsdf(node, props);
        }
        // An unknown plugin is named before its parameters are looked at.
        if !BSDF_TYPES.contains(&ty.as_str()) {
            return Err(self.unknown_type(node, "bsdf", &ty, BSDF_TYPES));
        }
        let textured = self.texture_bindings(node, &ty, &props)?;
        let m = match ty.as_str() {
            "diffuse" => MaterialDesc::Diffuse {
                reflectance: props
                    .color("reflectance", ColorUse::Reflectance)?
                    .unwrap_or(defaults::DIFFUSE_REFLECTANCE),
            },
            "twosided" => self.twosided(node)?,
            "conductor" | "roughconductor" => self.conductor(node, &ty, &props)?,
            "dielectric" | "roughdielectric" | "thindielectric" => {
                self.dielectric(node, &ty, &props)?
            }
            "plastic" | "roughplastic" => self.plastic(node, &ty, &props)?,
            "null" => MaterialDesc::Null,
            "principled" | "principledthin" => self.principled(node, &ty, &props)?,
            "mask" => return self.mask(node, props, textured),
            other => return Err(self.unknown_type(node, "bsdf", other, BSDF_TYPES)),
        };
        let m = self.bind_textures(&ty, m, textured)?;
        // Everything the builder would reject, reported here with this bsdf's line.
        crate::material::check(&m).map_err(|e| self.err(node, format!("bsdf '{ty}': {e}")))?;
        self.check_bsdf_children(node, &ty)?;
        props.finish();
        Ok(m)
    }

    /// Parameters given as textures, nested or by reference; wrapped around the material by
    /// [`Self::bind_textures`] (the constant value of such a parameter is unused).
    fn texture_bindings<'i>(
        &self,
        node: Node<'a, 'i>,
        ty: &str,
        props: &Props,
    ) -> Result<Vec<(Node<'a, 'i>, TextureBinding)>> {
        let mut textured: Vec<(Node, TextureBinding)> = Vec::new();
        for c in elements(node) {
            let tag = c.tag_name().name();
            let (name, texture) = if tag == "texture" {
                (self.req_attr(c, "name")?, self.texture(c)?)
            } else if tag == "ref"
                && let Some(name) = self.attr(c, "name")?
            {
                let id = self.req_attr(c, "id")?;
                let (t, _) = self.textures.get(&id).ok_or_else(|| {
                    self.err(
                        c,
                        format!("bsdf '{ty}': reference to undefined texture '{id}'"),
                    )
                })?;
                (name, t.clone())
            } else {
                continue;
            };
            let name = snake_case(&name);
            // `eta` is a texture for principledthin only (elsewhere a value, never a texture).
            let param = ColorParam::from_name(&name)
                .filter(|p| *p != ColorParam::Eta || ty == "principledthin");
            let param = param.ok_or_else(|| {
                self.err(
                    c,
                    format!(
                        "bsdf '{ty}': '{name}' cannot be a texture (only these can: reflectance, diffuse_reflectance, specular_reflectance, specular_transmittance, a mask's opacity, a normalmap's normalmap, the rough conductor's and rough dielectric's alpha, alpha_u, alpha_v, and the principled models' parameters but principled's eta and specular)"
                    ),
                )
            })?;
            if props.get(&name).is_some() {
                return Err(self.err(
                    c,
                    format!("bsdf '{ty}': '{name}' is given twice (as a value and as a texture)"),
                ));
            }
            if textured.iter().any(|(_, b)| b.param == param) {
                return Err(self.err(c, format!("bsdf '{ty}': two textures for '{name}'")));
            }
            textured.push((c, TextureBinding { param, texture }));
        }
        Ok(textured)
    }

    /// `m` with the textures of `textured`, each of which must name a colour parameter of `m`.
    fn bind_textures(
        &self,
        ty: &str,
        m: MaterialDesc,
        textured: Vec<(Node, TextureBinding)>,
    ) -> Result<MaterialDesc> {
        if textured.is_empty() {
            return Ok(m);
        }
        let allowed = crate::material::color_params(&m);
        if let Some((c, b)) = textured.iter().find(|(_, b)| !allowed.contains(&b.param)) {
            return Err(self.err(
                *c,
                format!("bsdf '{ty}' has no parameter '{}'", b.param.name()),
            ));
        }
        Ok(MaterialDesc::Textured {
            material: Box::new(m),
            textures: textured.into_iter().map(|(_, b)| b).collect(),
        })
    }

    /// Only properties, textures and references inside a bsdf, and a nested bsdf only in
    /// `twosided`.
    fn check_bsdf_children(&self, node: Node, ty: &str) -> Result<()> {
        for c in elements(node) {
            let tag = c.tag_name().name();
            if !PROPERTY_TAGS.contains(&tag) && !["bsdf", "texture", "ref"].contains(&tag) {
                return Err(self.err(c, format!("unexpected <{tag}> inside a bsdf")));
            }
            if tag == "bsdf" && ty != "twosided" && ty != "mask" {
                return Err(self.err(
                    c,
                    format!("bsdf '{ty}' takes no nested bsdf (only twosided and mask wrap one)"),
                ));
            }
        }
        Ok(())
    }

    /// `twosided`: the first nested bsdf on both sides; not around transmitting ones.
    fn twosided<'i>(&self, node: Node<'a, 'i>) -> Result<MaterialDesc> {
        let nested: Vec<Node> = elements(node)
            .filter(|c| c.tag_name().name() == "bsdf")
            .collect();
        let inner = match nested.first() {
            // Checked before recursing, so nesting depth is bounded (a file with
            // thousands of nested twosided elements would overflow the stack).
            Some(n) if n.attribute("type").map(snake_case).as_deref() == Some("twosided") => {
                return Err(self.err(*n, "bsdf 'twosided' wraps another twosided"));
            }
            Some(n) if n.attribute("type").map(snake_case).as_deref() == Some("normalmap") => {
                return Err(self.err(
                    *n,
                    "bsdf 'twosided' cannot wrap a normalmap (the normalmap may wrap the twosided instead)",
                ));
            }
            Some(n) => self.bsdf(*n)?,
            None => {
                self.warn(
                    node,
                    "empty twosided bsdf wraps a default diffuse (reflectance 0.5)",
                );
                MaterialDesc::Diffuse {
                    reflectance: defaults::DIFFUSE_REFLECTANCE,
                }
            }
        };
        if nested.len() > 1 {
            self.warn(nested[1], "twosided with two different bsdfs is not supported; the back side uses the front bsdf");
        }
        if matches!(
            inner,
            MaterialDesc::Dielectric { .. }
                | MaterialDesc::RoughDielectric { .. }
                | MaterialDesc::ThinDielectric { .. }
                | MaterialDesc::Null
        ) {
            return Err(self.err(
                node,
                "twosided cannot wrap a transmitting bsdf (dielectric, roughdielectric, thindielectric, null), as in Mitsuba",
            ));
        }
        Ok(MaterialDesc::TwoSided(Box::new(inner)))
    }

    /// `mask`: one nested bsdf, and an `opacity` (a float or a texture, default 0.5). A texture
    /// of the nested bsdf is moved outside the mask, beside the opacity's, so the one texture
    /// slot per material holds both.
    fn mask<'i>(
        &self,
        node: Node<'a, 'i>,
        props: Props<'a, 'i>,
        textured: Vec<(Node<'a, 'i>, TextureBinding)>,
    ) -> Result<MaterialDesc> {
        let nested: Vec<Node> = elements(node)
            .filter(|c| c.tag_name().name() == "bsdf")
            .collect();
        let inner = match nested.as_slice() {
            // Checked before recursing, so nesting depth stays bounded (twosided and mask
            // alternating could otherwise nest as deep as the file).
            [n] if n.attribute("type").map(snake_case).as_deref() == Some("mask") => {
                return Err(self.err(*n, "bsdf 'mask' wraps another mask"));
            }
            [n] if elements(*n)
                .filter(|c| c.tag_name().name() == "bsdf")
                .any(|c| c.attribute("type").map(snake_case).as_deref() == Some("mask")) =>
            {
                return Err(self.err(*n, "bsdf 'mask' wraps another mask (inside a twosided)"));
            }
            [n] => self.bsdf(*n)?,
            [] => {
                return Err(self.err(
                    node,
                    "bsdf 'mask' needs one nested <bsdf> (the material where the surface is there)",
                ));
            }
            [_, second, ..] => {
                return Err(self.err(*second, "bsdf 'mask' takes one nested bsdf, not two"));
            }
        };
        if let Some((c, b)) = textured
            .iter()
            .find(|(_, b)| b.param != ColorParam::Opacity)
        {
            return Err(self.err(
                *c,
                format!(
                    "bsdf 'mask' has no parameter '{}' (its parameters: opacity and one nested bsdf)",
                    b.param.name()
                ),
            ));
        }
        let opacity = props.float("opacity")?.unwrap_or(defaults::MASK_OPACITY);
        if !(0.0..=1.0).contains(&opacity) {
            return Err(self.err(
                props.node_or("opacity", node),
                format!("bsdf 'mask': opacity {opacity} must lie in [0, 1]"),
            ));
        }
        // A textured nested bsdf: its textures join the opacity's outside the mask.
        let (inner, mut textures) = inner.split_textures();
        textures.extend(textured.into_iter().map(|(_, b)| b));
        let mask = MaterialDesc::Mask {
            opacity,
            material: Box::new(inner),
        };
        let m = mask.with_textures(textures);
        crate::material::check(&m).map_err(|e| self.err(node, format!("bsdf 'mask': {e}")))?;
        self.check_bsdf_children(node, "mask")?;
        props.finish();
        Ok(m)
    }

    /// `conductor` and `roughconductor`.
    fn conductor(&self, node: Node, ty: &str, props: &Props) -> Result<MaterialDesc> {
        let ior = self.conductor_ior(props)?;
        let specular_reflectance = props
            .color("specular_reflectance", ColorUse::Reflectance)?
            .unwrap_or(defaults::SPECULAR);
        Ok(if ty == "conductor" {
            MaterialDesc::Conductor {
                ior,
                specular_reflectance,
            }
        } else {
            MaterialDesc::RoughConductor {
                ior,
                specular_reflectance,
                roughness: self.roughness(node, props, true, false)?,
            }
        })
    }

    /// `dielectric`, `roughdielectric` and `thindielectric`.
    fn dielectric(&self, node: Node, ty: &str, props: &Props) -> Result<MaterialDesc> {
        let int_ior = props.ior("int_ior", defaults::BK7_IOR)?;
        let ext_ior = props.ior("ext_ior", defaults::AIR_IOR)?;
        let specular_reflectance = props
            .color("specular_reflectance", ColorUse::Reflectance)?
            .unwrap_or(defaults::SPECULAR);
        let specular_transmittance = props
            .color("specular_transmittance", ColorUse::Reflectance)?
            .unwrap_or(defaults::SPECULAR);
        Ok(if ty == "dielectric" {
            MaterialDesc::Dielectric {
                int_ior,
                ext_ior,
                specular_reflectance,
                specular_transmittance,
            }
        } else if ty == "thindielectric" {
            MaterialDesc::ThinDielectric {
                int_ior,
                ext_ior,
                specular_reflectance,
                specular_transmittance,
            }
        } else {
            MaterialDesc::RoughDielectric {
                int_ior,
                ext_ior,
                specular_reflectance,
                specular_transmittance,
                roughness: self.roughness(node, props, true, true)?,
            }
        })
    }

    /// `plastic` and `roughplastic`.
    fn plastic(&self, node: Node, ty: &str, props: &Props) -> Result<MaterialDesc> {
        let int_ior = props.ior("int_ior", defaults::POLYPROPYLENE_IOR)?;
        let ext_ior = props.ior("ext_ior", defaults::AIR_IOR)?;
        let diffuse_reflectance = props
            .color("diffuse_reflectance", ColorUse::Reflectance)?
            .unwrap_or(defaults::DIFFUSE_REFLECTANCE);
        let specular_reflectance = props
            .color("specular_reflectance", ColorUse::Reflectance)?
            .unwrap_or(defaults::SPECULAR);
        let nonlinear = props.bool("nonlinear")?.unwrap_or(false);
        if ty == "plastic" {
            return Ok(MaterialDesc::Plastic {
                int_ior,
                ext_ior,
                diffuse_reflectance,
                specular_reflectance,
                nonlinear,
            });
        }
        if int_ior == ext_ior {
            return Err(self.err(
                node,
                format!(
                    "bsdf 'roughplastic': int_ior and ext_ior are both {int_ior}; they must differ"
                ),
            ));
        }
        Ok(MaterialDesc::RoughPlastic {
            int_ior,
            ext_ior,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            roughness: self.roughness(node, props, false, true)?,
        })
    }

    /// Conductor `material` / `eta` / `k` (Mitsuba: `eta` with a named material is an error).
    fn conductor_ior(&self, props: &Props) -> Result<ConductorIorDesc> {
        let material_node = props.get("material").map(|p| p.node);
        let material = props.string("material")?;
        let eta = props.color("eta", ColorUse::Unbounded)?;
        let k = props.color("k", ColorUse::Unbounded)?;
        if let (Some(name), Some(n)) = (&material, material_node) {
            if restir_materials::ior::conductor(name).is_none() {
                return Err(self.err(
                    n,
                    format!(
                        "{}: unknown conductor material '{name}' (known: {})",
                        props.what,
                        restir_materials::ior::conductor_names()
                    ),
                ));
            }
            if name != "none" && (eta.is_some() || k.is_some()) {
                return Err(self.err(
                    n,
                    format!(
                        "{}: give either material '{name}' or eta/k, not both",
                        props.what
                    ),
                ));
            }
        }
        Ok(ConductorIorDesc { material, eta, k })
    }

    /// `distribution`, `alpha` or `alpha_u`/`alpha_v`, and `sample_visible`; with `lajolla`
    /// (`roughplastic`, `roughdielectric`), Lajolla's `roughness` in place of `alpha`.
    fn roughness(
        &self,
        node: Node,
        props: &Props,
        anisotropic: bool,
        lajolla: bool,
    ) -> Result<RoughnessDesc> {
        let mut r = RoughnessDesc::default();
        if let Some(p) = props.get("distribution") {
            let Value::Str(d) = &p.value else {
                return Err(props.type_err(p, "a string"));
            };
            r.distribution = match d.as_str() {
                "beckmann" => MicrofacetDesc::Beckmann,
                "ggx" => MicrofacetDesc::Ggx,
                other => {
                    return Err(self.err(
                        p.node,
                        format!(
                            "{}: unknown distribution '{other}' (beckmann, ggx)",
                            props.what
                        ),
                    ));
                }
            };
        }
        let alpha = |name: &str| -> Result<Option<f32>> {
            match props.float(name)? {
                Some(a) if a.is_nan() || a < 0.0 => Err(self.err(
                    props.node_or(name, node),
                    format!(
                        "{}: {name} {a} must be a non-negative roughness",
                        props.what
                    ),
                )),
                a => Ok(a),
            }
        };
        // A roughness given as a texture counts as given (its value here is a placeholder the
        // texture replaces at every shading point).
        let textured = |name: &str| {
            elements(node).any(|c| {
                ["texture", "ref"].contains(&c.tag_name().name())
                    && c.attribute("name").map(snake_case).as_deref() == Some(name)
            })
        };
        let given = |name: &str| -> Result<Option<f32>> {
            if textured(name) {
                Ok(Some(defaults::ALPHA))
            } else {
                alpha(name)
            }
        };
        let a = given("alpha")?;
        let au = given("alpha_u")?;
        let av = given("alpha_v")?;
        if lajolla && (props.get("roughness").is_some() || textured("roughness")) {
            // Lajolla's files give `roughness` r where Mitsuba's give alpha: Lajolla's rough
            // plastic and rough dielectric use GGX with α = r², r clamped to [0.01, 1].
            let at = props.node_or("roughness", node);
            if textured("roughness") {
                return Err(self.err(
                    at,
                    format!(
                        "{}: a textured roughness (Lajolla's α = roughness²) is not supported; give alpha as a texture",
                        props.what
                    ),
                ));
            }
            if a.is_some() || au.is_some() || av.is_some() {
                return Err(self.err(
                    at,
                    format!(
                        "{}: give either alpha (Mitsuba) or roughness (Lajolla, α = roughness²), not both",
                        props.what
                    ),
                ));
            }
            let rough = alpha("roughness")?.unwrap_or(0.0);
            r.alpha = rough.clamp(LAJOLLA_MIN_ROUGHNESS, 1.0).powi(2);
            if props.get("distribution").is_none() {
                r.distribution = MicrofacetDesc::Ggx;
            }
            return self.sample_visible(node, props, r);
        }
        match (au, av) {
            (None, None) => r.alpha = a.unwrap_or(defaults::ALPHA),
            (Some(u), Some(v)) => {
                if !anisotropic {
                    return Err(self.err(
                        node,
                        format!(
                            "{}: anisotropic roughness is not supported; give 'alpha'",
                            props.what
                        ),
                    ));
                }
                if a.is_some() {
                    return Err(self.err(
                        node,
                        format!(
                            "{}: give either alpha or alpha_u/alpha_v, not both",
                            props.what
                        ),
                    ));
                }
                r.alpha_u = Some(u);
                r.alpha_v = Some(v);
            }
            _ => {
                return Err(self.err(
                    node,
                    format!("{}: alpha_u and alpha_v must be given together", props.what),
                ));
            }
        }
        self.sample_visible(node, props, r)
    }

    /// `sample_visible`, read for `r`.
    fn sample_visible(&self, node: Node, props: &Props, r: RoughnessDesc) -> Result<RoughnessDesc> {
        if props.bool("sample_visible")? == Some(false) {
            self.warn(
                node,
                format!(
                    "{}: sample_visible=false is ignored; visible normals are always sampled (the same expected image, different noise)",
                    props.what
                ),
            );
        }
        Ok(r)
    }
}
