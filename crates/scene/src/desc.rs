//! Scene description types: what the RON format deserialises into and what the XML importer
//! produces. Both go through [`crate::Scene::build`]. Every struct denies unknown fields, so a typo
//! in a RON file is an error, not a silently ignored setting.

use serde::{Deserialize, Serialize};
use std::path::PathBuf;

pub use crate::texture::{TextureDesc, UvTransform};

/// Where a description item came from, for error messages (`file:line`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Location {
    /// The scene file.
    pub file: PathBuf,
    /// 1-based line, 0 if unknown.
    pub line: u32,
}

impl core::fmt::Display for Location {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        if self.line > 0 {
            write!(f, "{}:{}", self.file.display(), self.line)
        } else {
            write!(f, "{}", self.file.display())
        }
    }
}

/// A whole scene.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    /// The camera.
    pub camera: CameraDesc,
    /// Image size, reconstruction filter and output name.
    #[serde(default)]
    pub film: FilmDesc,
    /// Samples per pixel (passes) when the command line does not say.
    #[serde(default = "default_spp")]
    pub spp: u32,
    /// The integrator and its parameters.
    #[serde(default)]
    pub integrator: IntegratorDesc,
    /// Named materials that shapes refer to with `Ref("name")`.
    #[serde(default)]
    pub materials: Vec<NamedMaterial>,
    /// The geometry.
    #[serde(default)]
    pub shapes: Vec<ShapeDesc>,
    /// Lights that are not attached to a shape.
    #[serde(default)]
    pub lights: Vec<LightDesc>,
}

fn default_spp() -> u32 {
    16
}

/// A 3-vector `(x, y, z)` or colour `(r, g, b)`.
pub type V3 = [f32; 3];

/// One step of a transform; steps apply in order (the first is applied to the object first),
/// as in Mitsuba's `<transform>`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum TransformOp {
    /// Translation.
    Translate(V3),
    /// Per-axis scale.
    Scale(V3),
    /// Rotation by `angle` degrees about `axis` (counter-clockwise looking down the axis).
    Rotate {
        /// Rotation axis (need not be unit length).
        axis: V3,
        /// Angle in degrees.
        angle: f32,
    },
    /// Camera-style look-at: `+z` towards `target`, `+y` towards `up`, `+x = up × z`.
    LookAt {
        /// Eye position.
        origin: V3,
        /// Point looked at.
        target: V3,
        /// Up vector.
        up: V3,
    },
    /// A row-major 4×4 matrix.
    Matrix([f32; 16]),
}

/// Which axis the field of view spans.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FovAxis {
    /// Horizontal.
    #[default]
    X,
    /// Vertical.
    Y,
    /// Diagonal.
    Diagonal,
    /// The smaller image side.
    Smaller,
    /// The larger image side.
    Larger,
}

/// A perspective or thin-lens camera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Field of view in degrees.
    pub fov: f32,
    /// The axis `fov` spans.
    #[serde(default)]
    pub fov_axis: FovAxis,
    /// Camera-to-world transform.
    #[serde(default)]
    pub to_world: Vec<TransformOp>,
    /// Lens radius; 0 is a pinhole.
    #[serde(default)]
    pub aperture_radius: f32,
    /// Distance of the plane in focus (thin lens only).
    #[serde(default = "one")]
    pub focus_distance: f32,
}

fn one() -> f32 {
    1.0
}

impl Default for CameraDesc {
    fn default() -> Self {
        Self {
            fov: 45.0,
            fov_axis: FovAxis::X,
            to_world: Vec::new(),
            aperture_radius: 0.0,
            focus_distance: 1.0,
        }
    }
}

/// A reconstruction filter; the renderer importance-samples it to place camera rays.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum FilterDesc {
    /// One pixel wide: every sample lands in the pixel that made it.
    Box,
    /// `max(0, 1 − |x|/radius)` per axis.
    Tent {
        /// Radius in pixels (default 1).
        radius: f32,
    },
    /// `max(0, exp(−x²/2σ²) − exp(−8))` per axis, truncated at 4σ (Mitsuba's default filter).
    Gaussian {
        /// Standard deviation in pixels (default 0.5).
        stddev: f32,
    },
}

impl Default for FilterDesc {
    fn default() -> Self {
        FilterDesc::Gaussian { stddev: 0.5 }
    }
}

/// The image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilmDesc {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Reconstruction filter.
    #[serde(default)]
    pub filter: FilterDesc,
    /// Default output file name.
    #[serde(default)]
    pub filename: Option<String>,
}

impl Default for FilmDesc {
    fn default() -> Self {
        Self {
            width: 768,
            height: 576,
            filter: FilterDesc::default(),
            filename: None,
        }
    }
}

/// The integrator chosen by the scene (the command line may override it).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorDesc {
    /// Name: `path` (default) or another estimator the renderer knows.
    #[serde(default = "default_integrator")]
    pub kind: String,
    /// Longest path in segments from the camera; -1 is unbounded.
    #[serde(default = "minus_one")]
    pub max_depth: i32,
    /// Depth from which Russian roulette runs.
    #[serde(default = "five")]
    pub rr_depth: u32,
    /// Whether directly visible emitters are hidden.
    #[serde(default)]
    pub hide_emitters: bool,
    /// Estimator-specific parameters as `name = value` strings (e.g. ReSTIR settings).
    #[serde(default)]
    pub params: Vec<(String, String)>,
    /// Where the integrator was declared (for errors in `params`); set by the loaders.
    #[serde(skip)]
    pub location: Location,
}

fn default_integrator() -> String {
    "path".into()
}
fn minus_one() -> i32 {
    -1
}
fn five() -> u32 {
    5
}

impl Default for IntegratorDesc {
    fn default() -> Self {
        Self {
            kind: default_integrator(),
            max_depth: -1,
            rr_depth: 5,
            hide_emitters: false,
            params: Vec::new(),
            location: Location::default(),
        }
    }
}

/// A material with a name.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NamedMaterial {
    /// The name shapes use.
    pub name: String,
    /// The material.
    pub material: MaterialDesc,
}

/// A microfacet normal distribution (Mitsuba's `distribution`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MicrofacetDesc {
    /// Beckmann (Mitsuba's default).
    #[default]
    Beckmann,
    /// GGX / Trowbridge–Reitz.
    Ggx,
}

/// Mitsuba's default roughness.
fn alpha_default() -> f32 {
    0.1
}
fn ones() -> V3 {
    [1.0; 3]
}
fn halves() -> V3 {
    [0.5; 3]
}
/// `air` in Mitsuba's IOR table.
pub const AIR_IOR: f32 = 1.000_277;
/// `bk7` in Mitsuba's IOR table (the dielectrics' default `int_ior`).
pub const BK7_IOR: f32 = 1.5046;
/// `polypropylene` in Mitsuba's IOR table (the plastics' default `int_ior`).
pub const POLYPROPYLENE_IOR: f32 = 1.49;
fn air() -> f32 {
    AIR_IOR
}
fn bk7() -> f32 {
    BK7_IOR
}
fn polypropylene() -> f32 {
    POLYPROPYLENE_IOR
}

/// A conductor's complex IOR: Mitsuba's `material` preset or explicit `eta`/`k`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConductorIorDesc {
    /// A named metal (`Au`, `Ag`, `Cu`, `Al`, `Cr`, …, `none` = perfect mirror); an error when
    /// combined with `eta` or `k`. Default: `none` unless `eta`/`k` are given.
    #[serde(default)]
    pub material: Option<String>,
    /// Real part of the IOR per channel (default 0).
    #[serde(default)]
    pub eta: Option<V3>,
    /// Imaginary part per channel (default 1).
    #[serde(default)]
    pub k: Option<V3>,
}

/// Microfacet roughness: isotropic `alpha`, or `alpha_u` and `alpha_v` together.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoughnessDesc {
    /// Normal distribution (default Beckmann).
    #[serde(default)]
    pub distribution: MicrofacetDesc,
    /// Isotropic roughness (Mitsuba `alpha`, default 0.1; clamped to at least 1e-4).
    #[serde(default = "alpha_default")]
    pub alpha: f32,
    /// Anisotropic roughness along the tangent; needs `alpha_v` and replaces `alpha`.
    #[serde(default)]
    pub alpha_u: Option<f32>,
    /// Anisotropic roughness along the bitangent; needs `alpha_u`.
    #[serde(default)]
    pub alpha_v: Option<f32>,
}

impl Default for RoughnessDesc {
    fn default() -> Self {
        Self {
            distribution: MicrofacetDesc::Beckmann,
            alpha: alpha_default(),
            alpha_u: None,
            alpha_v: None,
        }
    }
}

/// A surface material. Every model and default is Mitsuba 3's plugin of the same name (see
/// `docs/SCENES.md`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MaterialDesc {
    /// Lambertian reflection, black from the back.
    Diffuse {
        /// Albedo in `[0, 1]`.
        reflectance: V3,
    },
    /// Smooth conductor (a delta mirror with the conductor Fresnel term), black from the back.
    Conductor {
        /// Complex IOR (default: `none`, a perfect mirror).
        #[serde(default)]
        ior: ConductorIorDesc,
        /// Multiplier in `[0, 1]` (default 1).
        #[serde(default = "ones")]
        specular_reflectance: V3,
    },
    /// Rough conductor (microfacet), black from the back.
    RoughConductor {
        /// Complex IOR (default: `none`, a perfect mirror).
        #[serde(default)]
        ior: ConductorIorDesc,
        /// Multiplier in `[0, 1]` (default 1).
        #[serde(default = "ones")]
        specular_reflectance: V3,
        /// Distribution and roughness.
        #[serde(default)]
        roughness: RoughnessDesc,
    },
    /// Smooth dielectric interface (glass): delta reflection and refraction, from both sides.
    Dielectric {
        /// IOR inside (default 1.5046, `bk7`).
        #[serde(default = "bk7")]
        int_ior: f32,
        /// IOR outside (default 1.000277, `air`).
        #[serde(default = "air")]
        ext_ior: f32,
        /// Reflection multiplier in `[0, 1]` (default 1).
        #[serde(default = "ones")]
        specular_reflectance: V3,
        /// Transmission multiplier in `[0, 1]` (default 1).
        #[serde(default = "ones")]
        specular_transmittance: V3,
    },
    /// Rough dielectric interface (microfacet), from both sides.
    RoughDielectric {
        /// IOR inside (default 1.5046, `bk7`).
        #[serde(default = "bk7")]
        int_ior: f32,
        /// IOR outside (default 1.000277, `air`).
        #[serde(default = "air")]
        ext_ior: f32,
        /// Reflection multiplier in `[0, 1]` (default 1).
        #[serde(default = "ones")]
        specular_reflectance: V3,
        /// Transmission multiplier in `[0, 1]` (default 1).
        #[serde(default = "ones")]
        specular_transmittance: V3,
        /// Distribution and roughness.
        #[serde(default)]
        roughness: RoughnessDesc,
    },
    /// Diffuse base under a smooth dielectric coating, black from the back.
    Plastic {
        /// IOR of the coating (default 1.49, `polypropylene`).
        #[serde(default = "polypropylene")]
        int_ior: f32,
        /// IOR outside (default 1.000277, `air`).
        #[serde(default = "air")]
        ext_ior: f32,
        /// Base albedo in `[0, 1]` (default 0.5).
        #[serde(default = "halves")]
        diffuse_reflectance: V3,
        /// Specular multiplier in `[0, 1]` (default 1).
        #[serde(default = "ones")]
        specular_reflectance: V3,
        /// Mitsuba's `nonlinear` internal-scattering model (default false).
        #[serde(default)]
        nonlinear: bool,
    },
    /// Diffuse base under a rough dielectric coating, black from the back. Isotropic only.
    RoughPlastic {
        /// IOR of the coating (default 1.49, `polypropylene`); must differ from `ext_ior`.
        #[serde(default = "polypropylene")]
        int_ior: f32,
        /// IOR outside (default 1.000277, `air`).
        #[serde(default = "air")]
        ext_ior: f32,
        /// Base albedo in `[0, 1]` (default 0.5).
        #[serde(default = "halves")]
        diffuse_reflectance: V3,
        /// Specular multiplier in `[0, 1]` (default 1).
        #[serde(default = "ones")]
        specular_reflectance: V3,
        /// Mitsuba's `nonlinear` internal-scattering model (default false).
        #[serde(default)]
        nonlinear: bool,
        /// Distribution and roughness (`alpha_u`/`alpha_v` are an error).
        #[serde(default)]
        roughness: RoughnessDesc,
    },
    /// A surface light passes through unchanged (Mitsuba `null`).
    Null,
    /// The wrapped material on both sides (an error around transmitting materials, as in
    /// Mitsuba).
    TwoSided(Box<MaterialDesc>),
    /// Absorbs all light.
    Black,
    /// `material` with some of its colour parameters given by textures, looked up at each
    /// shading point's texture coordinates; the constant values in `material` are unused for
    /// those parameters. In RON: `Textured(material: Diffuse(reflectance: (0.5, 0.5, 0.5)),
    /// textures: [(param: Reflectance, texture: Bitmap(filename: "wood.png"))])`.
    Textured {
        /// The material (any model with the parameters named in `textures`).
        material: Box<MaterialDesc>,
        /// Which parameter each texture replaces.
        textures: Vec<TextureBinding>,
    },
}

/// A colour parameter of a material that a texture can provide.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ColorParam {
    /// `Diffuse`'s `reflectance`.
    Reflectance,
    /// The plastics' `diffuse_reflectance`.
    DiffuseReflectance,
    /// `specular_reflectance` (conductors, dielectrics, plastics).
    SpecularReflectance,
    /// The dielectrics' `specular_transmittance`.
    SpecularTransmittance,
}

impl ColorParam {
    /// The parameter's name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            ColorParam::Reflectance => "reflectance",
            ColorParam::DiffuseReflectance => "diffuse_reflectance",
            ColorParam::SpecularReflectance => "specular_reflectance",
            ColorParam::SpecularTransmittance => "specular_transmittance",
        }
    }

    /// The parameter named `name` (snake_case), if it is one.
    pub fn from_name(name: &str) -> Option<Self> {
        [
            ColorParam::Reflectance,
            ColorParam::DiffuseReflectance,
            ColorParam::SpecularReflectance,
            ColorParam::SpecularTransmittance,
        ]
        .into_iter()
        .find(|p| p.name() == name)
    }
}

/// A texture bound to a material parameter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureBinding {
    /// The parameter.
    pub param: ColorParam,
    /// The texture.
    pub texture: TextureDesc,
}

/// A shape's material: by name or inline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum MaterialRef {
    /// A material from [`SceneDesc::materials`].
    Ref(String),
    /// An inline material.
    Inline(MaterialDesc),
}

/// Geometry of a shape, before its transform.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum GeometryDesc {
    /// `[-1, 1]²` in the `z = 0` plane, normal `+z`.
    Rectangle,
    /// `[-1, 1]³`.
    Cube,
    /// Unit disk in the `z = 0` plane, normal `+z`.
    Disk,
    /// A sphere (its transform may translate, rotate and scale uniformly).
    Sphere {
        /// Centre.
        center: V3,
        /// Radius.
        radius: f32,
    },
    /// A Wavefront OBJ file, relative to the scene file.
    Obj {
        /// Path.
        filename: String,
    },
    /// A PLY file (ASCII or binary), relative to the scene file.
    Ply {
        /// Path.
        filename: String,
    },
    /// One shape of a Mitsuba `.serialized` file, relative to the scene file.
    Serialized {
        /// Path.
        filename: String,
        /// Which shape of the file (default 0).
        #[serde(default)]
        shape_index: u32,
    },
    /// Triangles given inline.
    Mesh {
        /// Vertex positions.
        positions: Vec<V3>,
        /// Triangles as index triples.
        indices: Vec<[u32; 3]>,
        /// Optional per-vertex normals.
        #[serde(default)]
        normals: Option<Vec<V3>>,
    },
}

/// A shape with its transform, material and optional area emitter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeDesc {
    /// What it is.
    pub geometry: GeometryDesc,
    /// Object-to-world transform.
    #[serde(default)]
    pub to_world: Vec<TransformOp>,
    /// Material; a default diffuse (ρ = 0.5) when absent, black for an emitter without one.
    #[serde(default)]
    pub material: Option<MaterialRef>,
    /// Radiance when the shape is an area light.
    #[serde(default)]
    pub emission: Option<V3>,
    /// Turn normals inside out.
    #[serde(default)]
    pub flip_normals: bool,
    /// Ignore vertex normals (flat shading).
    #[serde(default)]
    pub face_normals: bool,
    /// Where the shape was declared (set by importers, not part of the RON format).
    #[serde(skip)]
    pub location: Location,
}

/// A light that is not a shape.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum LightDesc {
    /// Isotropic point light.
    Point {
        /// Position.
        position: V3,
        /// Intensity (W/sr).
        intensity: V3,
    },
    /// Light arriving from one direction.
    Directional {
        /// Direction the light travels in.
        direction: V3,
        /// Irradiance.
        irradiance: V3,
    },
    /// Uniform environment.
    Constant {
        /// Radiance.
        radiance: V3,
    },
    /// Environment from a latitude-longitude image (Mitsuba's `envmap`): EXR or Radiance `.hdr`
    /// (linear), or PNG/JPEG (sRGB-decoded).
    Envmap {
        /// Image path, relative to the scene file.
        filename: String,
        /// Radiance multiplier.
        #[serde(default = "default_scale")]
        scale: f32,
        /// Rotation of the map (Mitsuba's orientation: `+Y` up, `u = 0` towards `−Z`).
        #[serde(default)]
        to_world: Vec<TransformOp>,
        /// Where the emitter was declared (set by importers, not part of the RON format).
        #[serde(skip)]
        location: Location,
    },
}

fn default_scale() -> f32 {
    1.0
}
