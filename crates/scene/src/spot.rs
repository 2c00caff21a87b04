//! Mitsuba's `spot` and `projector` emitters from their descriptions ([`LightDesc::Spot`],
//! [`LightDesc::Projector`]): the light set's [`Spot`] and [`Projector`]; their projected
//! textures and area emitters' radiance textures as [`LightTexture`]s (the scene's own bitmap
//! and checkerboard lookups, so wrap modes, filters and `to_uv` are the materials' ones).

use std::path::Path;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use restir_lights::{Light, LightTexture, Projector, Spot};

use crate::desc::{LightDesc, TextureDesc, defaults, transform_matrix};
use crate::texture::Texture;

impl LightTexture for Texture {
    fn eval(&self, uv: Vec2) -> Vec3 {
        Texture::eval(self, uv)
    }

    fn mean(&self) -> Vec3 {
        Texture::mean(self)
    }
}

/// The light of a spot or projector description (a [`LightDesc::Spot`] or
/// [`LightDesc::Projector`]); its texture, if any, is loaded (a bitmap was counted against the
/// memory limit with the scene's other images) and appended to `textures`, which the light names by index. Errors
/// are the message without the location.
pub(crate) fn spot_light(
    desc: &LightDesc,
    base_dir: &Path,
    textures: &mut Vec<Arc<dyn LightTexture>>,
) -> Result<Light, String> {
    match desc {
        LightDesc::Spot {
            intensity,
            cutoff_angle,
            beam_width,
            to_world,
            texture,
            ..
        } => {
            let m =
                transform_matrix(to_world).map_err(|e| format!("spot emitter: to_world: {e}"))?;
            let index = match texture {
                Some(t) => Some(load(t, "spot", base_dir, textures)?.0),
                None => None,
            };
            let beam = beam_width.unwrap_or(cutoff_angle * defaults::SPOT_BEAM_FRACTION);
            let spot = Spot::new(m, Vec3::from(*intensity), *cutoff_angle, beam, index)
                .map_err(|e| format!("spot emitter: {e}"))?;
            Ok(Light::Spot(spot))
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
            let m = transform_matrix(to_world)
                .map_err(|e| format!("projector emitter: to_world: {e}"))?;
            // The image's aspect ratio is the texture's; a constant is 1×1, as in Mitsuba.
            let (index, resolution) = match texture {
                Some(t) => {
                    let (i, r) = load(t, "projector", base_dir, textures)?;
                    (Some(i), r)
                }
                None => (None, (1, 1)),
            };
            let (fov, axis) = match fov {
                Some(f) => (*f, (*fov_axis).into()),
                None => (
                    defaults::fov_of_focal_length(defaults::FOCAL_LENGTH_MM),
                    restir_geometry::FovAxis::Diagonal,
                ),
            };
            let projector = Projector::new(
                m,
                Vec3::from(*irradiance),
                *scale,
                fov,
                axis,
                resolution,
                index,
            )
            .map_err(|e| format!("projector emitter: {e}"))?;
            Ok(Light::Projector(projector))
        }
        _ => Err("neither a spot light nor a projector".into()),
    }
}

/// The radiance textures of area emitters loaded so far, by description: shapes that name the
/// same texture share one copy of its image (and of its mean and brightest texel).
#[derive(Debug, Default)]
pub(crate) struct EmissionTextures {
    /// Each description loaded: the unscaled texture's index, its mean and its largest value per
    /// channel.
    loaded: Vec<(TextureDesc, u32, Vec3, Vec3)>,
}

/// The radiance texture `t` of an area emitter, times `factor` (its `emission`), loaded into
/// `textures` unless `shared` holds it already: its index there and its mean (what the light's
/// selection weights count). Errors are the message without the location.
pub(crate) fn emission_texture(
    t: &TextureDesc,
    factor: Vec3,
    base_dir: &Path,
    textures: &mut Vec<Arc<dyn LightTexture>>,
    shared: &mut EmissionTextures,
) -> Result<(u32, Vec3), String> {
    let (index, mean, max) = match shared.loaded.iter().find(|(d, ..)| d == t) {
        Some(&(_, index, mean, max)) => (index, mean, max),
        None => {
            let texture = read(t, "area", base_dir)?;
            let (mean, max) = (texture.mean(), texture.max());
            textures.push(Arc::new(texture));
            let index = textures.len() as u32 - 1;
            shared.loaded.push((t.clone(), index, mean, max));
            (index, mean, max)
        }
    };
    let (mean, max) = (mean * factor, max * factor);
    if !mean.is_finite() || mean.min_element() < 0.0 {
        return Err(format!(
            "area emitter texture: its mean radiance {mean} must be finite and non-negative"
        ));
    }
    if max.max_element() > restir_lights::MAX_EMISSION {
        return Err(format!(
            "area emitter texture: its brightest texel, {:e} (times the emission), exceeds the \
             largest emission this renderer computes with, {:e} (products with geometry terms \
             and sample weights would overflow)",
            max.max_element(),
            restir_lights::MAX_EMISSION
        ));
    }
    if factor == Vec3::ONE {
        return Ok((index, mean));
    }
    let texture = textures[index as usize].clone();
    textures.push(Arc::new(Scaled { texture, factor }));
    Ok((textures.len() as u32 - 1, mean))
}

/// A light's texture times a constant factor.
#[derive(Debug)]
struct Scaled {
    texture: Arc<dyn LightTexture>,
    factor: Vec3,
}

impl LightTexture for Scaled {
    fn eval(&self, uv: Vec2) -> Vec3 {
        self.texture.eval(uv) * self.factor
    }

    fn mean(&self) -> Vec3 {
        self.texture.mean() * self.factor
    }
}

/// Loads texture `t` of a `plugin` emitter into `textures`: its index there and its resolution
/// (`(1, 1)` for a checkerboard, as Mitsuba's textures other than bitmaps).
fn load(
    t: &TextureDesc,
    plugin: &str,
    base_dir: &Path,
    textures: &mut Vec<Arc<dyn LightTexture>>,
) -> Result<(u32, (u32, u32)), String> {
    let t = read(t, plugin, base_dir)?;
    let resolution = match &t {
        Texture::Bitmap { width, height, .. } => (*width as u32, *height as u32),
        Texture::Checkerboard { .. } | Texture::MeshAttribute(_) => (1, 1),
    };
    textures.push(Arc::new(t));
    Ok((textures.len() as u32 - 1, resolution))
}

/// Reads texture `t` of a `plugin` emitter: a bitmap or a checkerboard (a mesh attribute is
/// refused: a light cannot project it).
fn read(t: &TextureDesc, plugin: &str, base_dir: &Path) -> Result<Texture, String> {
    if let TextureDesc::MeshAttribute { name, .. } = t {
        return Err(format!(
            "{plugin} emitter texture: a 'mesh_attribute' texture (\"{name}\") reads the mesh a \
             ray hits and cannot be projected by a light; use a bitmap or checkerboard"
        ));
    }
    Texture::load(t, base_dir).map_err(|e| format!("{plugin} emitter texture: {e}"))
}
