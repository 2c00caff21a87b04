//! `<bsdf type="principled">` and `<bsdf type="principledthin">` (Mitsuba 3 plugin reference,
//! "The Principled BSDF" and "The Thin Principled BSDF"): every parameter a float or a texture
//! (`base_color` a colour or a texture), with Mitsuba's defaults; `principled`'s `eta` and
//! `specular` are floats, and only one of them may be given. A property the plugin does not have
//! is an error. The sampling rates only tune Mitsuba's choice among lobes, which does not change
//! the expected image: they are read and, when not 1, named in a warning.

use roxmltree::Node;

use super::props::{ColorUse, Props};
use super::{Importer, Result};
use crate::desc::*;

/// `principled`'s parameters (the sampling rates last).
const PRINCIPLED: &[&str] = &[
    "base_color",
    "roughness",
    "anisotropic",
    "metallic",
    "spec_trans",
    "eta",
    "specular",
    "spec_tint",
    "sheen",
    "sheen_tint",
    "flatness",
    "clearcoat",
    "clearcoat_gloss",
    "diffuse_reflectance_sampling_rate",
    "main_specular_sampling_rate",
    "clearcoat_sampling_rate",
];

/// `principledthin`'s parameters (the sampling rates last).
const PRINCIPLED_THIN: &[&str] = &[
    "base_color",
    "roughness",
    "anisotropic",
    "spec_trans",
    "spec_tint",
    "sheen",
    "sheen_tint",
    "flatness",
    "diff_trans",
    "eta",
    "specular_reflectance_sampling_rate",
    "specular_transmittance_sampling_rate",
    "diffuse_transmittance_sampling_rate",
    "diffuse_reflectance_sampling_rate",
];

impl<'a> Importer<'a> {
    /// A `principled` or `principledthin` bsdf's constant parameters (textured ones get their
    /// defaults here, replaced by the texture at every shading point).
    pub(super) fn principled(&self, node: Node, ty: &str, props: &Props) -> Result<MaterialDesc> {
        let thin = ty == "principledthin";
        let known = if thin { PRINCIPLED_THIN } else { PRINCIPLED };
        if let Some(p) = props
            .items
            .iter()
            .find(|p| !known.contains(&p.name.as_str()))
        {
            return Err(self.err(
                p.node,
                format!(
                    "bsdf '{ty}' has no parameter '{}' (its parameters: {})",
                    p.name,
                    known.join(", ")
                ),
            ));
        }
        for name in known.iter().filter(|n| n.ends_with("_sampling_rate")) {
            if let Some(rate) = props.float(name)? {
                let at = props.node_or(name, node);
                if !(rate.is_finite() && rate >= 0.0) {
                    return Err(self.err(
                        at,
                        format!("bsdf '{ty}': {name} {rate} must be a non-negative number"),
                    ));
                }
                if rate != 1.0 {
                    self.warn(
                        at,
                        format!(
                            "bsdf '{ty}': {name} {rate} is ignored: lobes are chosen with Mitsuba's default rates (the same expected image, different noise)"
                        ),
                    );
                }
            }
        }
        let float =
            |name: &str, default: f32| -> Result<f32> { Ok(props.float(name)?.unwrap_or(default)) };
        let base_color = props
            .color("base_color", ColorUse::Reflectance)?
            .unwrap_or(defaults::DIFFUSE_REFLECTANCE);
        let roughness = float("roughness", defaults::PRINCIPLED_ROUGHNESS)?;
        Ok(if thin {
            MaterialDesc::PrincipledThin {
                base_color,
                roughness,
                anisotropic: float("anisotropic", 0.0)?,
                spec_trans: float("spec_trans", 0.0)?,
                spec_tint: float("spec_tint", 0.0)?,
                sheen: float("sheen", 0.0)?,
                sheen_tint: float("sheen_tint", 0.0)?,
                flatness: float("flatness", 0.0)?,
                diff_trans: float("diff_trans", 0.0)?,
                eta: float("eta", defaults::PRINCIPLED_THIN_ETA)?,
            }
        } else {
            MaterialDesc::Principled {
                base_color,
                roughness,
                anisotropic: float("anisotropic", 0.0)?,
                metallic: float("metallic", 0.0)?,
                spec_trans: float("spec_trans", 0.0)?,
                spec_tint: float("spec_tint", 0.0)?,
                sheen: float("sheen", 0.0)?,
                sheen_tint: float("sheen_tint", 0.0)?,
                flatness: float("flatness", 0.0)?,
                clearcoat: float("clearcoat", 0.0)?,
                clearcoat_gloss: float("clearcoat_gloss", 0.0)?,
                eta: props.float("eta")?,
                specular: props.float("specular")?,
            }
        })
    }
}
