//! The principled materials as Mitsuba 3 spells them: every parameter as a `<float>` (the base
//! colour as an `<rgb>`), or as the texture bound to it.

use super::*;

impl Writer<'_> {
    /// A `principled` or `principledthin` bsdf's parameters (the element is open); `textures` are
    /// the bindings of an enclosing `Textured`.
    pub(super) fn principled_params(
        &mut self,
        m: &MaterialDesc,
        textures: &[TextureBinding],
        item: &str,
    ) -> Result<()> {
        let bound = |p: ColorParam| textures.iter().find(|b| b.param == p);
        let scalar = |w: &mut Self, p: ColorParam, v: f32| -> Result<()> {
            match bound(p) {
                Some(b) => w.texture(&b.texture, p.name(), item),
                None => {
                    w.float(p.name(), v);
                    Ok(())
                }
            }
        };
        match m {
            MaterialDesc::Principled {
                base_color,
                roughness,
                anisotropic,
                metallic,
                spec_trans,
                spec_tint,
                sheen,
                sheen_tint,
                flatness,
                clearcoat,
                clearcoat_gloss,
                eta,
                specular,
            } => {
                match bound(ColorParam::BaseColor) {
                    Some(b) => self.texture(&b.texture, "base_color", item)?,
                    None => self.rgb("base_color", base_color),
                }
                for (p, v) in [
                    (ColorParam::Roughness, roughness),
                    (ColorParam::Anisotropic, anisotropic),
                    (ColorParam::Metallic, metallic),
                    (ColorParam::SpecTrans, spec_trans),
                    (ColorParam::SpecTint, spec_tint),
                    (ColorParam::Sheen, sheen),
                    (ColorParam::SheenTint, sheen_tint),
                    (ColorParam::Flatness, flatness),
                    (ColorParam::Clearcoat, clearcoat),
                    (ColorParam::ClearcoatGloss, clearcoat_gloss),
                ] {
                    scalar(self, p, *v)?;
                }
                if let Some(e) = eta {
                    self.float("eta", *e);
                }
                if let Some(s) = specular {
                    self.float("specular", *s);
                }
            }
            MaterialDesc::PrincipledThin {
                base_color,
                roughness,
                anisotropic,
                spec_trans,
                spec_tint,
                sheen,
                sheen_tint,
                flatness,
                diff_trans,
                eta,
            } => {
                match bound(ColorParam::BaseColor) {
                    Some(b) => self.texture(&b.texture, "base_color", item)?,
                    None => self.rgb("base_color", base_color),
                }
                for (p, v) in [
                    (ColorParam::Roughness, roughness),
                    (ColorParam::Anisotropic, anisotropic),
                    (ColorParam::SpecTrans, spec_trans),
                    (ColorParam::SpecTint, spec_tint),
                    (ColorParam::Sheen, sheen),
                    (ColorParam::SheenTint, sheen_tint),
                    (ColorParam::Flatness, flatness),
                    (ColorParam::DiffTrans, diff_trans),
                    (ColorParam::Eta, eta),
                ] {
                    scalar(self, p, *v)?;
                }
            }
            _ => {}
        }
        Ok(())
    }
}
