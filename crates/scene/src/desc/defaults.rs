//! Every default of the scene description, in one place: the values Mitsuba 3's plugins take
//! when a property is absent. The RON format's serde defaults (the functions below) and the XML
//! importer's absent properties both read them here, so the two formats cannot drift apart.

use super::V3;

/// Samples per pixel when the scene does not say (a sampler's `sample_count`).
pub const SPP: u32 = 16;

/// Field of view in degrees of a RON camera and of the scenes this crate generates. (A Mitsuba
/// perspective sensor without `fov` has [`FOCAL_LENGTH`] instead.)
pub const FOV: f32 = 45.0;
/// The focal length of a Mitsuba 3 `perspective` or `thinlens` sensor that gives neither `fov`
/// nor `focal_length`.
pub const FOCAL_LENGTH: &str = "50mm";
/// [`FOCAL_LENGTH`] in millimetres (a `projector` without `fov` has this lens too).
pub const FOCAL_LENGTH_MM: f32 = 50.0;

/// The diagonal field of view in degrees of a lens of focal length `mm` millimetres on a
/// 36 × 24 mm film (Mitsuba 3's `focal_length`): `2·atan(√(36² + 24²) / (2·mm))`. For 50 mm
/// it is 46.79°, which on a square image is 34.02° across.
pub fn fov_of_focal_length(mm: f32) -> f32 {
    let diagonal = (36.0f64 * 36.0 + 24.0 * 24.0).sqrt();
    (2.0 * (diagonal / (2.0 * f64::from(mm))).atan()).to_degrees() as f32
}
/// Lens radius of a thin lens (0 is a pinhole).
pub const APERTURE_RADIUS: f32 = 0.0;
/// Distance of the plane in focus (`thinlens`).
pub const FOCUS_DISTANCE: f32 = 1.0;
/// Mitsuba 3's `near_clip` when a sensor does not name one (camera-space depth).
pub const NEAR_CLIP: f32 = 1e-2;
/// Mitsuba 3's `far_clip` when a sensor does not name one (camera-space depth).
pub const FAR_CLIP: f32 = 1e4;

/// Film width in pixels (`hdrfilm`).
pub const FILM_WIDTH: u32 = 768;
/// Film height in pixels (`hdrfilm`).
pub const FILM_HEIGHT: u32 = 576;
/// Standard deviation of the Gaussian filter in pixels (Mitsuba's default filter).
pub const GAUSSIAN_STDDEV: f32 = 0.5;
/// Radius of the tent filter in pixels.
pub const TENT_RADIUS: f32 = 1.0;

/// The integrator when the scene names none.
pub const INTEGRATOR: &str = "path";
/// Longest path in segments; -1 is unbounded.
pub const MAX_DEPTH: i32 = -1;
/// Depth from which Russian roulette runs.
pub const RR_DEPTH: u32 = 5;

/// A diffuse reflectance (`diffuse`'s `reflectance`, the plastics' `diffuse_reflectance`, the
/// material of a shape without one).
pub const DIFFUSE_REFLECTANCE: V3 = [0.5; 3];
/// `specular_reflectance` and `specular_transmittance` multipliers.
pub const SPECULAR: V3 = [1.0; 3];
/// A `normalmap` value that leaves the shading frame as it is.
pub const FLAT_NORMAL: V3 = [0.5, 0.5, 1.0];

/// `mask`'s `opacity`.
pub const MASK_OPACITY: f32 = 0.5;
/// Isotropic microfacet roughness `alpha`.
pub const ALPHA: f32 = 0.1;
/// `air` in Mitsuba's IOR table (every `ext_ior`).
pub const AIR_IOR: f32 = 1.000_277;
/// `bk7` in Mitsuba's IOR table (the dielectrics' default `int_ior`).
pub const BK7_IOR: f32 = 1.5046;
/// `polypropylene` in Mitsuba's IOR table (the plastics' default `int_ior`).
pub const POLYPROPYLENE_IOR: f32 = 1.49;
/// A conductor's real IOR part when only `k` is given.
pub const CONDUCTOR_ETA: V3 = [0.0; 3];
/// A conductor's imaginary IOR part when only `eta` is given.
pub const CONDUCTOR_K: V3 = [1.0; 3];

/// The principled models' `roughness`.
pub const PRINCIPLED_ROUGHNESS: f32 = 0.5;
/// `principled`'s `specular` (its IOR when neither `eta` nor `specular` is given).
pub const PRINCIPLED_SPECULAR: f32 = 0.5;
/// `principledthin`'s `eta`.
pub const PRINCIPLED_THIN_ETA: f32 = 1.5;

/// Radiance, intensity or irradiance of an emitter that does not give one.
pub const EMISSION: V3 = [1.0; 3];
/// An envmap's radiance multiplier.
pub const ENVMAP_SCALE: f32 = 1.0;
/// A spot light's `cutoff_angle`, in degrees.
pub const SPOT_CUTOFF_ANGLE: f32 = 20.0;
/// A spot light's `beam_width` as a fraction of its `cutoff_angle`.
pub const SPOT_BEAM_FRACTION: f32 = 0.75;
/// A bump map's gradient multiplier (`scale`).
pub const BUMP_SCALE: f32 = 1.0;
/// A projector's irradiance multiplier (`scale`).
pub const PROJECTOR_SCALE: f32 = 1.0;

/// A sphere's centre.
pub const SPHERE_CENTER: V3 = [0.0; 3];
/// A sphere's radius.
pub const SPHERE_RADIUS: f32 = 1.0;
/// A cylinder's `p0`, the start of its axis.
pub const CYLINDER_P0: V3 = [0.0; 3];
/// A cylinder's `p1`, the end of its axis.
pub const CYLINDER_P1: V3 = [0.0, 0.0, 1.0];
/// A cylinder's radius.
pub const CYLINDER_RADIUS: f32 = 1.0;

/// A checkerboard's `color0`.
pub const CHECKER_COLOR0: V3 = [0.4; 3];
/// A checkerboard's `color1`.
pub const CHECKER_COLOR1: V3 = [0.2; 3];

// Serde default functions for the RON format (serde takes a path to a function).

pub(crate) fn cylinder_p0() -> V3 {
    CYLINDER_P0
}

pub(crate) fn cylinder_p1() -> V3 {
    CYLINDER_P1
}

pub(crate) fn cylinder_radius() -> f32 {
    CYLINDER_RADIUS
}

pub(crate) fn spp() -> u32 {
    SPP
}
pub(crate) fn focus_distance() -> f32 {
    FOCUS_DISTANCE
}
pub(crate) fn integrator() -> String {
    INTEGRATOR.into()
}
pub(crate) fn max_depth() -> i32 {
    MAX_DEPTH
}
pub(crate) fn rr_depth() -> u32 {
    RR_DEPTH
}
pub(crate) fn alpha() -> f32 {
    ALPHA
}
pub(crate) fn flat_normal() -> V3 {
    FLAT_NORMAL
}

pub(crate) fn yes() -> bool {
    true
}

pub(crate) fn mask_opacity() -> f32 {
    MASK_OPACITY
}
pub(crate) fn specular() -> V3 {
    SPECULAR
}
pub(crate) fn diffuse_reflectance() -> V3 {
    DIFFUSE_REFLECTANCE
}
pub(crate) fn air_ior() -> f32 {
    AIR_IOR
}
pub(crate) fn bk7_ior() -> f32 {
    BK7_IOR
}
pub(crate) fn polypropylene_ior() -> f32 {
    POLYPROPYLENE_IOR
}
pub(crate) fn principled_roughness() -> f32 {
    PRINCIPLED_ROUGHNESS
}
pub(crate) fn principled_thin_eta() -> f32 {
    PRINCIPLED_THIN_ETA
}
pub(crate) fn envmap_scale() -> f32 {
    ENVMAP_SCALE
}
pub(crate) fn spot_cutoff_angle() -> f32 {
    SPOT_CUTOFF_ANGLE
}
pub(crate) fn near_clip() -> f32 {
    NEAR_CLIP
}
pub(crate) fn far_clip() -> f32 {
    FAR_CLIP
}
pub(crate) fn is_near_clip(v: &f32) -> bool {
    *v == NEAR_CLIP
}
pub(crate) fn is_far_clip(v: &f32) -> bool {
    *v == FAR_CLIP
}
pub(crate) fn emission() -> V3 {
    EMISSION
}
pub(crate) fn bump_scale() -> f32 {
    BUMP_SCALE
}
pub(crate) fn projector_scale() -> f32 {
    PROJECTOR_SCALE
}

#[cfg(test)]
mod tests {
    use crate::desc::{MaterialDesc, SceneDesc};

    /// The materials of a RON scene whose materials give no parameters.
    fn ron_materials(models: &[&str]) -> Vec<MaterialDesc> {
        let list: Vec<String> = models
            .iter()
            .enumerate()
            .map(|(i, m)| format!("(name: \"m{i}\", material: {m})"))
            .collect();
        let ron = format!("(camera: (fov: 45), materials: [{}])", list.join(", "));
        let desc: SceneDesc = crate::parse_ron(&ron, "t.ron".as_ref()).unwrap();
        desc.materials.into_iter().map(|m| m.material).collect()
    }

    #[test]
    fn ron_and_xml_share_the_defaults() {
        let ron = ron_materials(&[
            "Dielectric()",
            "ThinDielectric()",
            "RoughDielectric()",
            "Plastic()",
            "RoughPlastic()",
            "Conductor()",
            "RoughConductor()",
        ]);
        let xml = r#"<scene><sensor type="perspective"/>
            <bsdf type="dielectric"/><bsdf type="thindielectric"/><bsdf type="roughdielectric"/><bsdf type="plastic"/>
            <bsdf type="roughplastic"/><bsdf type="conductor"/><bsdf type="roughconductor"/>
            </scene>"#;
        let (desc, _) = crate::xml::parse_xml(xml, "t.xml".as_ref(), &[]).unwrap();
        let imported: Vec<MaterialDesc> = desc.materials.into_iter().map(|m| m.material).collect();
        assert_eq!(ron, imported);

        let ron: SceneDesc = crate::parse_ron("(camera: (fov: 45))", "t.ron".as_ref()).unwrap();
        let xml =
            r#"<scene><sensor type="perspective"><float name="fov" value="45"/></sensor></scene>"#;
        let (imported, _) = crate::xml::parse_xml(xml, "t.xml".as_ref(), &[]).unwrap();
        assert_eq!(ron.camera, imported.camera);
        assert_eq!(ron.film, imported.film);
        assert_eq!(ron.spp, imported.spp);
        assert_eq!(ron.integrator, imported.integrator);
    }

    /// A perspective sensor without `fov` has Mitsuba's 50 mm lens: 46.79° diagonally, 34.02°
    /// across a square image; `focal_length` sets another lens; both at once is an error.
    #[test]
    fn the_default_lens_is_50mm() {
        let camera = |body: &str| {
            let xml = format!(r#"<scene><sensor type="perspective">{body}</sensor></scene>"#);
            crate::xml::parse_xml(&xml, "t.xml".as_ref(), &[]).map(|(d, _)| d.camera)
        };
        let c = camera("").unwrap();
        assert_eq!(c.fov_axis, super::super::FovAxis::Diagonal);
        assert!((c.fov - 46.7930).abs() < 1e-3, "{}", c.fov);
        let across = 2.0 * ((c.fov.to_radians() / 2.0).tan() / 2f32.sqrt()).atan();
        assert!((across.to_degrees() - 34.0221).abs() < 1e-3);
        let c = camera(r#"<string name="focal_length" value="35mm"/>"#).unwrap();
        assert!((c.fov - super::fov_of_focal_length(35.0)).abs() < 1e-6);
        let e =
            camera(r#"<float name="fov" value="30"/><string name="focal_length" value="35mm"/>"#)
                .unwrap_err()
                .to_string();
        assert!(e.contains("either 'fov' or 'focal_length'"), "{e}");
        let e = camera(r#"<string name="focal_length" value="wide"/>"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("focal_length \"wide\""), "{e}");
    }
}
