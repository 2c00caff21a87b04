//! Scene description types: what the RON format deserialises into and what the XML importer
//! produces. Both go through [`crate::Scene::build`]. Every struct denies unknown fields, so a typo
//! in a RON file is an error, not a silently ignored setting.
//!
//! The scene, camera, film, integrator, shapes and lights are here; materials are in
//! [`materials`](self) (re-exported), and every default value is in [`defaults`].

mod animation;
pub mod defaults;
pub mod limits;
mod materials;
mod transform;

pub use animation::*;
pub use defaults::{AIR_IOR, BK7_IOR, POLYPROPYLENE_IOR};
pub use materials::*;
pub use transform::{TransformError, TransformOp, transform_matrix};

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
    #[serde(default = "defaults::spp")]
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
    /// What moves over time, if anything (docs/ANIMATION.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub animation: Option<AnimationDesc>,
}

/// A 3-vector `(x, y, z)` or colour `(r, g, b)`.
pub type V3 = [f32; 3];

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

impl From<FovAxis> for restir_geometry::FovAxis {
    fn from(axis: FovAxis) -> Self {
        match axis {
            FovAxis::X => Self::X,
            FovAxis::Y => Self::Y,
            FovAxis::Diagonal => Self::Diagonal,
            FovAxis::Smaller => Self::Smaller,
            FovAxis::Larger => Self::Larger,
        }
    }
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
    #[serde(default, deserialize_with = "limits::coordinate")]
    pub aperture_radius: f32,
    /// Distance of the plane in focus (thin lens only).
    #[serde(
        default = "defaults::focus_distance",
        deserialize_with = "limits::coordinate"
    )]
    pub focus_distance: f32,
    /// Mitsuba's `orthographic` sensor: parallel rays, the film spanning `[−1, 1]` across
    /// (and `1/aspect` up and down) in camera space before `to_world` (`fov` and the lens are
    /// unused). Written only when set, so perspective scenes read as before.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub orthographic: bool,
    /// Mitsuba's `near_clip`: the camera-space depth of the plane before which the camera sees
    /// nothing ([`defaults::NEAR_CLIP`], Mitsuba's, in both formats).
    #[serde(
        default = "defaults::near_clip",
        skip_serializing_if = "defaults::is_near_clip"
    )]
    pub near_clip: f32,
    /// Mitsuba's `far_clip`: the camera-space depth of the plane past which the camera sees
    /// nothing, so that what lies beyond is seen as a miss ([`defaults::FAR_CLIP`]).
    #[serde(
        default = "defaults::far_clip",
        skip_serializing_if = "defaults::is_far_clip"
    )]
    pub far_clip: f32,
}

impl Default for CameraDesc {
    fn default() -> Self {
        Self {
            fov: defaults::FOV,
            fov_axis: FovAxis::X,
            to_world: Vec::new(),
            aperture_radius: defaults::APERTURE_RADIUS,
            focus_distance: defaults::FOCUS_DISTANCE,
            orthographic: false,
            near_clip: defaults::NEAR_CLIP,
            far_clip: defaults::FAR_CLIP,
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
        #[serde(deserialize_with = "limits::filter_width")]
        radius: f32,
    },
    /// `max(0, exp(−x²/2σ²) − exp(−8))` per axis, truncated at 4σ (Mitsuba's default filter).
    Gaussian {
        /// Standard deviation in pixels (default 0.5).
        #[serde(deserialize_with = "limits::filter_width")]
        stddev: f32,
    },
}

impl Default for FilterDesc {
    fn default() -> Self {
        FilterDesc::Gaussian {
            stddev: defaults::GAUSSIAN_STDDEV,
        }
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
            width: defaults::FILM_WIDTH,
            height: defaults::FILM_HEIGHT,
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
    #[serde(default = "defaults::integrator")]
    pub kind: String,
    /// Longest path in segments from the camera; -1 is unbounded.
    #[serde(default = "defaults::max_depth")]
    pub max_depth: i32,
    /// Depth from which Russian roulette runs.
    #[serde(default = "defaults::rr_depth")]
    pub rr_depth: u32,
    /// Whether directly visible emitters are hidden.
    #[serde(default)]
    pub hide_emitters: bool,
    /// Estimator-specific parameters as `name = value` strings (e.g. ReSTIR settings).
    #[serde(default)]
    pub params: Vec<(String, String)>,
    /// Where the path tracer's uniform numbers come from (a Mitsuba scene's `<sampler>`).
    #[serde(default, skip_serializing_if = "SamplerKind::is_independent")]
    pub sampler: SamplerKind,
    /// Mitsuba's `moment` integrator around this one: the name under which an EXR output
    /// also holds each pixel's mean and second moment over the passes (CIE XYZ channels
    /// `NAME.X`… and `m2_NAME.X`…, as Mitsuba 3 writes them). `None`: the image only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moment: Option<String>,
    /// Where the integrator was declared (for errors in `params`); set by the loaders.
    #[serde(skip)]
    pub location: Location,
}

impl Default for IntegratorDesc {
    fn default() -> Self {
        Self {
            kind: defaults::integrator(),
            max_depth: defaults::MAX_DEPTH,
            rr_depth: defaults::RR_DEPTH,
            hide_emitters: false,
            params: Vec::new(),
            sampler: SamplerKind::Independent,
            moment: None,
            location: Location::default(),
        }
    }
}

/// Where an estimator's uniform numbers come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum SamplerKind {
    /// Independent pseudo-random numbers (PCG32), Mitsuba's `independent`: the default.
    #[default]
    Independent,
    /// Owen-scrambled Sobol points, padded per dimension (Burley 2020): stratified across the
    /// passes of each pixel, unbiased like independent numbers. Mitsuba's `ldsampler`,
    /// `stratified`, `multijitter` and `orthogonal` are rendered with it.
    Sobol,
}

impl SamplerKind {
    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Independent => "independent",
            SamplerKind::Sobol => "sobol",
        }
    }

    /// Whether this is the default, [`SamplerKind::Independent`].
    pub fn is_independent(&self) -> bool {
        *self == SamplerKind::Independent
    }
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
        #[serde(deserialize_with = "limits::coordinates")]
        center: V3,
        /// Radius.
        #[serde(deserialize_with = "limits::coordinate")]
        radius: f32,
    },
    /// Mitsuba's `cylinder`: the open tube (no caps) of radius `radius` around the segment from
    /// `p0` to `p1`; its transform may not shear, mirror or scale its cross-section unevenly.
    Cylinder {
        /// Start of the axis (default the origin).
        #[serde(
            default = "defaults::cylinder_p0",
            deserialize_with = "limits::coordinates"
        )]
        p0: V3,
        /// End of the axis (default `(0, 0, 1)`).
        #[serde(
            default = "defaults::cylinder_p1",
            deserialize_with = "limits::coordinates"
        )]
        p1: V3,
        /// Radius (default 1).
        #[serde(
            default = "defaults::cylinder_radius",
            deserialize_with = "limits::coordinate"
        )]
        radius: f32,
    },
    /// Mitsuba's `sdfgrid`: a signed distance grid over the unit cube, read from a Mitsuba
    /// grid-volume (`.vol`) file relative to the scene file. It cannot emit.
    SdfGrid {
        /// Path.
        filename: String,
        /// How shading normals are computed (default `smooth`).
        #[serde(default)]
        normals: SdfNormalsDesc,
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
        #[serde(deserialize_with = "limits::point_list")]
        positions: Vec<V3>,
        /// Triangles as index triples.
        indices: Vec<[u32; 3]>,
        /// Optional per-vertex normals.
        #[serde(default)]
        normals: Option<Vec<V3>>,
    },
}

/// How an `sdfgrid`'s shading normals are computed (Mitsuba's `normals`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SdfNormalsDesc {
    /// Blended across neighbouring voxels, continuous (Mitsuba's default).
    #[default]
    Smooth,
    /// The gradient of the voxel's interpolant.
    Analytic,
}

impl SdfNormalsDesc {
    /// Mitsuba's name.
    pub fn name(self) -> &'static str {
        match self {
            SdfNormalsDesc::Smooth => "smooth",
            SdfNormalsDesc::Analytic => "analytic",
        }
    }
}

/// A shape with its transform, material and optional area emitter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeDesc {
    /// A name an animation refers to the shape by (XML: the `id` attribute).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub id: Option<String>,
    /// What it is.
    pub geometry: GeometryDesc,
    /// Object-to-world transform.
    #[serde(default)]
    pub to_world: Vec<TransformOp>,
    /// Material; a default diffuse (ρ = 0.5) when absent, black for an emitter without one.
    #[serde(default)]
    pub material: Option<MaterialRef>,
    /// Radiance when the shape is an area light; with `emission_texture`, its factor.
    #[serde(default)]
    pub emission: Option<V3>,
    /// The radiance as a texture over the shape's uv (Mitsuba's area emitter with a
    /// `radiance` texture), times `emission`, which must be given (`(1, 1, 1)` for the
    /// texture's values).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission_texture: Option<TextureDesc>,
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
        #[serde(deserialize_with = "limits::coordinates")]
        position: V3,
        /// Intensity (W/sr).
        intensity: V3,
    },
    /// Mitsuba's `spot`: a point light at the origin of `to_world`, shining along its `+z`, full
    /// within `beam_width` of the axis, falling linearly in angle to zero at `cutoff_angle`,
    /// optionally projecting a texture (docs/SCENES.md).
    Spot {
        /// Intensity on the axis (W/sr).
        intensity: V3,
        /// Angle from the axis beyond which nothing is emitted, in degrees (default 20).
        #[serde(default = "defaults::spot_cutoff_angle")]
        cutoff_angle: f32,
        /// Angle of the full-intensity beam, in degrees (default ¾ of `cutoff_angle`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        beam_width: Option<f32>,
        /// Position and orientation (the light at the origin, shining along `+z`).
        #[serde(default)]
        to_world: Vec<TransformOp>,
        /// A texture projected along the axis (the cone's cutoff circle touches the edges of its
        /// unit square).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        texture: Option<TextureDesc>,
        /// Where the emitter was declared (set by importers, not part of the RON format).
        #[serde(skip)]
        location: Location,
    },
    /// Mitsuba's `projector`: a pinhole at the origin of `to_world` throwing an irradiance image
    /// through a perspective frustum along its `+z`, the reciprocal of a perspective camera
    /// (docs/SCENES.md).
    Projector {
        /// Irradiance on the image plane at distance 1 in front of the pinhole, a constant
        /// (default 1), multiplied by `texture` when there is one (Mitsuba's `irradiance` is the
        /// one or the other). What arrives there is `π·scale·irradiance`, as in Mitsuba.
        #[serde(default = "defaults::emission")]
        irradiance: V3,
        /// Multiplier of the irradiance (default 1).
        #[serde(default = "defaults::projector_scale")]
        scale: f32,
        /// Field of view in degrees along `fov_axis`; without it, Mitsuba's 50 mm lens on a
        /// 36 × 24 mm film, which fixes the diagonal field of view.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        fov: Option<f32>,
        /// The image axis `fov` spans (default `x`); the image's aspect ratio is the
        /// texture's (1 without one).
        #[serde(default)]
        fov_axis: FovAxis,
        /// Position and orientation (the pinhole at the origin, looking along `+z`, `+y` up).
        #[serde(default)]
        to_world: Vec<TransformOp>,
        /// The projected image (`uv = (0, 0)` its top-left corner, seen looking along `+z`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        texture: Option<TextureDesc>,
        /// Where the emitter was declared (set by importers, not part of the RON format).
        #[serde(skip)]
        location: Location,
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
        #[serde(default = "defaults::envmap_scale")]
        scale: f32,
        /// Rotation of the map (Mitsuba's orientation: `+Y` up, `u = 0` towards `−Z`).
        #[serde(default)]
        to_world: Vec<TransformOp>,
        /// Where the emitter was declared (set by importers, not part of the RON format).
        #[serde(skip)]
        location: Location,
    },
}
