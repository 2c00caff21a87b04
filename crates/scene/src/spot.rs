//! Mitsuba's `spot` emitter from its description ([`LightDesc::Spot`]): the light set's
//! [`Spot`], and its projected texture as a [`SpotTexture`] (the scene's own bitmap and
//! checkerboard lookups, so wrap modes, filters and `to_uv` are the materials' ones).

use std::path::Path;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use restir_lights::{Light, Spot, SpotTexture};

use crate::desc::{LightDesc, TextureDesc, defaults, transform_matrix};
use crate::texture::Texture;

impl SpotTexture for Texture {
    fn eval(&self, uv: Vec2) -> Vec3 {
        Texture::eval(self, uv)
    }
}

/// The light of spot description `desc` (a [`LightDesc::Spot`]); its texture, if any, is loaded
/// (after `take_image` counts a bitmap against the memory limit) and appended to `textures`,
/// which the light names by index. Errors are the message without the location.
pub(crate) fn spot_light(
    desc: &LightDesc,
    base_dir: &Path,
    take_image: &mut dyn FnMut(&Path) -> Result<(), String>,
    textures: &mut Vec<Arc<dyn SpotTexture>>,
) -> Result<Light, String> {
    let LightDesc::Spot {
        intensity,
        cutoff_angle,
        beam_width,
        to_world,
        texture,
        ..
    } = desc
    else {
        return Err("not a spot light".into());
    };
    let m = transform_matrix(to_world).map_err(|e| format!("spot emitter: to_world: {e}"))?;
    let index = match texture {
        Some(TextureDesc::MeshAttribute { name, .. }) => {
            return Err(format!(
                "spot emitter texture: a 'mesh_attribute' texture (\"{name}\") reads the mesh a \
                 ray hits and cannot be projected by a light; use a bitmap or checkerboard"
            ));
        }
        Some(t) => {
            if let TextureDesc::Bitmap { filename, .. } = t {
                take_image(&base_dir.join(filename))?;
            }
            let t = Texture::load(t, base_dir).map_err(|e| format!("spot emitter texture: {e}"))?;
            textures.push(Arc::new(t));
            Some(textures.len() as u32 - 1)
        }
        None => None,
    };
    let beam = beam_width.unwrap_or(cutoff_angle * defaults::SPOT_BEAM_FRACTION);
    let spot = Spot::new(m, Vec3::from(*intensity), *cutoff_angle, beam, index)
        .map_err(|e| format!("spot emitter: {e}"))?;
    Ok(Light::Spot(spot))
}
