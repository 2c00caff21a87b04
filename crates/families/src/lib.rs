//! Procedural scenes: [`SceneDesc`] values computed from a seed, for tests, benchmarks and the
//! scene families of the equal-time studies (`restir generate` writes them as RON files).
//!
//! | kind | file | what it is |
//! |---|---|---|
//! | [`many_lights`] | `many_lights.rs` | the shipped `scenes/many-lights.ron` (sphere lights over boxes) |
//! | [`Kind::Rects`] | `rects.rs` | small one-sided emissive rectangles (two-triangle meshes) hanging over receivers |
//! | [`Kind::Spheres`] | `spheres.rs` | small emissive spheres over receivers |
//! | [`Kind::Meshes`] | `meshes.rs` | a few emissive OBJ meshes of thousands of small triangles over receivers |
//! | [`Kind::Room`] | `room.rs` | a glossy room lit mostly indirectly by one hidden area light |
//! | [`Kind::Hall`] | `hall.rs`, `garlands.rs` | a hall of tens of emissive garlands (thousands of triangles) among pillars, partitions and shelves, a dim sky through its windows |
//! | [`added_lamps`] | `added_lamps.rs` | small lamps added to a scene somebody else wrote, by a rule that needs only its geometry and camera |
//!
//! The rectangles, spheres and meshes share their stage (`stage.rs`: a floor, receivers,
//! occluders between lights and receivers, an optional environment map); the hall builds its
//! own. All four many-light kinds are direct-light scenes (max depth 2). `envmap.rs` makes the
//! environment images, `family.rs` the training and test families (lists of kinds, seeds and
//! parameters), `motion.rs` the animations of the moving families ([`animate`]: camera, objects
//! and lights in motion, from the seed), `util.rs` the shared helpers.
//!
//! A generated scene is a [`Generated`]: the description plus the files it names (OBJ meshes,
//! EXR environment maps), which [`Generated::write`] puts beside the RON file. Asset names are a
//! function of exactly the parameters that determine their contents, so scenes of one family can
//! share a directory.

mod added_lamps;
pub mod envmap;
mod family;
mod garlands;
mod hall;
mod lamps;
mod many_lights;
mod meshes;
mod motion;
mod rects;
mod room;
mod spheres;
mod stage;
mod util;

use std::path::{Path, PathBuf};

use restir_image::{Image, ImageError};

use restir_scene::SceneDesc;

pub use added_lamps::{
    AddedLamp, POWER_RATIO as ADDED_LAMPS_POWER_RATIO, added_lamps, added_lamps_xml,
};
pub use family::{Family, FamilyMember, Split, members};
pub use many_lights::{many_lights, many_lights_ron};
pub use motion::{DURATION, FPS, animate};
pub use room::{Glass, RoomOptions, room};
pub use stage::{DiOptions, Receivers};

/// The generated kinds (besides the shipped [`many_lights`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kind {
    /// Small one-sided emissive rectangles.
    Rects,
    /// Small emissive spheres.
    Spheres,
    /// A few emissive triangle meshes (OBJ files).
    Meshes,
    /// A glossy room lit mostly indirectly.
    Room,
    /// A hall of emissive garlands (OBJ meshes), pillars, partitions and a sky through openings.
    Hall,
}

impl Kind {
    /// Every kind.
    pub const ALL: [Kind; 5] = [
        Kind::Rects,
        Kind::Spheres,
        Kind::Meshes,
        Kind::Room,
        Kind::Hall,
    ];

    /// The name on the command line and in file names.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Rects => "rects",
            Kind::Spheres => "spheres",
            Kind::Meshes => "meshes",
            Kind::Room => "room",
            Kind::Hall => "hall",
        }
    }
}

/// The parameters of one generated scene: the kind's options.
#[derive(Clone, Debug, PartialEq)]
pub enum Params {
    /// A many-light direct-lighting scene of kind `Rects`, `Spheres`, `Meshes` or `Hall`.
    Di(Kind, DiOptions),
    /// A glossy room.
    Room(RoomOptions),
}

impl Params {
    /// The kind.
    pub fn kind(&self) -> Kind {
        match self {
            Params::Di(kind, _) => *kind,
            Params::Room(_) => Kind::Room,
        }
    }
}

/// Why a scene could not be generated or written.
#[derive(Debug)]
pub enum GenerateError {
    /// A light count outside `1..=1_000_000`.
    LightCount(u32),
    /// A many-light option given to a kind that is not one (`Room` in [`Params::Di`]).
    NotManyLights(Kind),
    /// Serialising the description failed.
    Ron(ron::Error),
    /// Writing a file failed.
    Io {
        /// The file.
        path: PathBuf,
        /// The reason.
        source: std::io::Error,
    },
    /// Writing an image failed.
    Image(ImageError),
    /// A scene that [`animate`] cannot animate (not one of the generated kinds).
    Animation(String),
}

impl core::fmt::Display for GenerateError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            GenerateError::LightCount(n) => {
                write!(f, "{n} lights: expected 1 to 1000000 lights")
            }
            GenerateError::NotManyLights(kind) => write!(
                f,
                "{} is not a many-light kind (expected rects, spheres, meshes or hall)",
                kind.name()
            ),
            GenerateError::Ron(e) => write!(f, "serialising the scene: {e}"),
            GenerateError::Io { path, source } => write!(f, "{}: {source}", path.display()),
            GenerateError::Image(e) => write!(f, "{e}"),
            GenerateError::Animation(why) => write!(f, "cannot animate the scene: {why}"),
        }
    }
}

impl std::error::Error for GenerateError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            GenerateError::Ron(e) => Some(e),
            GenerateError::Io { source, .. } => Some(source),
            GenerateError::Image(e) => Some(e),
            _ => None,
        }
    }
}

/// The contents of a file a generated scene names.
#[derive(Clone, Debug, PartialEq)]
pub enum AssetContents {
    /// A text file (OBJ).
    Text(String),
    /// An image, written as EXR.
    Image(Image),
}

/// A file a generated scene names, relative to the scene file.
#[derive(Clone, Debug, PartialEq)]
pub struct Asset {
    /// File name (no directories).
    pub filename: String,
    /// What goes in it.
    pub contents: AssetContents,
}

/// A generated scene: its description, a header saying how it was made, and the files it names.
#[derive(Clone, Debug, PartialEq)]
pub struct Generated {
    /// The scene.
    pub desc: SceneDesc,
    /// Lines for the RON file's leading comment (without `//`).
    pub header: String,
    /// Files the description names, to be written beside it.
    pub assets: Vec<Asset>,
}

impl Generated {
    /// The description as RON text with the header as a comment.
    pub fn ron(&self) -> Result<String, GenerateError> {
        util::to_ron(&self.desc, &self.header).map_err(GenerateError::Ron)
    }

    /// Writes the RON file as `dir/<stem>.ron` and every asset beside it; returns the RON path.
    pub fn write(&self, dir: &Path, stem: &str) -> Result<PathBuf, GenerateError> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| GenerateError::Io { path, source }
        };
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        for asset in &self.assets {
            let path = dir.join(&asset.filename);
            match &asset.contents {
                AssetContents::Text(text) => std::fs::write(&path, text).map_err(io(&path))?,
                AssetContents::Image(image) => image.write(&path).map_err(GenerateError::Image)?,
            }
        }
        let path = dir.join(format!("{stem}.ron"));
        std::fs::write(&path, self.ron()?).map_err(io(&path))?;
        Ok(path)
    }
}

/// Generates a scene of the kind and options in `params` from `seed`.
pub fn generate(params: &Params, seed: u64) -> Result<Generated, GenerateError> {
    match params {
        Params::Di(kind, options) => {
            if !(1..=1_000_000).contains(&options.lights) {
                return Err(GenerateError::LightCount(options.lights));
            }
            match kind {
                Kind::Rects => Ok(rects::rects(seed, options)),
                Kind::Spheres => Ok(spheres::spheres(seed, options)),
                Kind::Meshes => Ok(meshes::meshes(seed, options)),
                Kind::Hall => Ok(hall::hall(seed, options)),
                Kind::Room => Err(GenerateError::NotManyLights(Kind::Room)),
            }
        }
        Params::Room(options) => Ok(room(seed, options)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_many_lights_scene_is_what_the_generator_writes() {
        let shipped = include_str!("../../../scenes/many-lights.ron");
        assert_eq!(many_lights_ron(400, 1).unwrap(), shipped);
    }

    #[test]
    fn bad_light_counts_and_kinds_are_errors() {
        let bad = Params::Di(
            Kind::Rects,
            DiOptions {
                lights: 0,
                ..DiOptions::default()
            },
        );
        assert_eq!(
            generate(&bad, 1).unwrap_err().to_string(),
            "0 lights: expected 1 to 1000000 lights"
        );
        let room = Params::Di(Kind::Room, DiOptions::default());
        assert_eq!(
            generate(&room, 1).unwrap_err().to_string(),
            "room is not a many-light kind (expected rects, spheres, meshes or hall)"
        );
    }
}
