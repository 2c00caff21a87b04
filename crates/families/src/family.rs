//! The scene families of the equal-time studies: for each family a fixed list of kinds and
//! parameters, and for each split its own seeds (training `1..`, test `101..`), so a family is a
//! list of seeds and the two splits never share a scene. Defaults are chosen on the training
//! family and gains reported on the test family.
//!
//! - [`Family::Di`] (ReSTIR DI, direct light only): rectangles, spheres and emissive meshes at
//!   10³, 10⁴ and 10⁵ lights, radiances spread over 1000×, occluders between lights and receivers,
//!   diffuse, checkerboard, glossy and mixed receivers, four members with a sky beside the lights;
//!   and two halls (garlands of emissive triangles among pillars and partitions, a dim sky through
//!   windows, a checkerboard floor, a rough gold statue), whose light counts differ between the
//!   splits (training 4000 and 12000 triangles, test 8000 and 20000), so that a default chosen on
//!   training halls is checked on halls of other sizes as well as other layouts.
//! - [`Family::Pt`] (ReSTIR PT): glossy rooms without glass, with smooth and with rough glass,
//!   each with and without a window to a sky, and two rooms lit by a hundred or so small lamps
//!   (tessellated bulbs) instead of one hidden light, the kind of the seed report's scene.
//! - [`Family::DiMotion`] (ReSTIR DI under motion): rectangles, spheres and emissive
//!   meshes at 10³ lights, two of each, with diffuse, glossy, mixed and textured receivers,
//!   occluders everywhere and a sky in three, each animated by [`super::animate`] (camera,
//!   receivers, slats and lights move, lights change radiance and one goes dark and back).
//! - [`Family::PtMotion`] (ReSTIR PT under motion): the six glossy rooms (each glass choice with
//!   and without a window), animated likewise (camera, two objects, the hidden light, and two
//!   added lamps move; one lamp goes dark and back).
//!
//! The moving families share the static families' seeds (training `1..`, test `101..`), so a
//! moving member with the parameters of a static one is that scene in motion.

use super::{DiOptions, GenerateError, Generated, Glass, Kind, Params, Receivers, RoomOptions};

/// A family of generated scenes: which study it serves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Family {
    /// ReSTIR DI against the path tracer at max depth 2.
    Di,
    /// ReSTIR PT against the path tracer in glossy rooms.
    Pt,
    /// ReSTIR DI under motion: animated many-light scenes at 10³ lights.
    DiMotion,
    /// ReSTIR PT under motion: animated glossy rooms.
    PtMotion,
}

impl Family {
    /// Every study.
    pub const ALL: [Family; 4] = [Family::Di, Family::Pt, Family::DiMotion, Family::PtMotion];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Family::Di => "di",
            Family::Pt => "pt",
            Family::DiMotion => "di-motion",
            Family::PtMotion => "pt-motion",
        }
    }

    /// Whether the family's scenes are animated (render them with `--frames 0..23`).
    pub fn animated(self) -> bool {
        matches!(self, Family::DiMotion | Family::PtMotion)
    }
}

/// Training (to choose defaults) or test (to report on).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Split {
    /// Seeds `1..`.
    Train,
    /// Seeds `101..`.
    Test,
}

impl Split {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Test => "test",
        }
    }

    /// The first seed; member `i` has seed `first_seed + i`.
    pub fn first_seed(self) -> u64 {
        match self {
            Split::Train => 1,
            Split::Test => 101,
        }
    }
}

/// One scene of a family.
#[derive(Clone, Debug, PartialEq)]
pub struct FamilyMember {
    /// The family.
    pub family: Family,
    /// The split.
    pub split: Split,
    /// Position in the family (the same kind and options in both splits, apart from the halls'
    /// light counts).
    pub index: usize,
    /// Kind and options.
    pub params: Params,
    /// The seed.
    pub seed: u64,
}

impl FamilyMember {
    /// The file stem: `di-test-03-spheres-n1000-glossy-occ-env-s104`.
    pub fn name(&self) -> String {
        let tag = match &self.params {
            Params::Di(_, options) => options.tag(),
            Params::Room(options) => options.tag(),
        };
        format!(
            "{}-{}-{:02}-{}-{tag}-s{}",
            self.family.name(),
            self.split.name(),
            self.index,
            self.params.kind().name(),
            self.seed
        )
    }

    /// The scene (animated by [`super::animate`] in the moving families).
    pub fn generate(&self) -> Result<Generated, GenerateError> {
        let mut generated = super::generate(&self.params, self.seed)?;
        if self.family.animated() {
            super::animate(&mut generated, self.params.kind(), self.seed)?;
        }
        Ok(generated)
    }
}

/// The DI family's parameters: every stage kind at every light count, every receiver choice, sky
/// in four; two halls with a sky, whose triangle counts depend on the split.
fn di_params(split: Split) -> Vec<Params> {
    let di = |kind, lights, receivers, envmap| {
        Params::Di(
            kind,
            DiOptions {
                lights,
                power_ratio: 1000.0,
                receivers,
                occluders: true,
                envmap,
            },
        )
    };
    use Kind::{Hall, Meshes, Rects, Spheres};
    use Receivers::{Diffuse, Glossy, Mixed, Textured};
    let halls = match split {
        Split::Train => [4_000, 12_000],
        Split::Test => [8_000, 20_000],
    };
    vec![
        di(Rects, 1_000, Diffuse, false),
        di(Rects, 10_000, Textured, false),
        di(Rects, 100_000, Glossy, false),
        di(Spheres, 1_000, Glossy, true),
        di(Spheres, 10_000, Mixed, false),
        di(Spheres, 100_000, Textured, false),
        di(Meshes, 1_000, Textured, true),
        di(Meshes, 10_000, Glossy, true),
        di(Meshes, 100_000, Mixed, false),
        di(Rects, 1_000, Mixed, true),
        di(Hall, halls[0], Mixed, true),
        di(Hall, halls[1], Glossy, true),
    ]
}

/// The PT family's parameters: each glass choice with and without a window, two more plain ones,
/// and two rooms lit by small lamps (the seed report's kind), one plain and closed, one with
/// smooth glass and a window.
fn pt_params() -> Vec<Params> {
    let room = |glass, window| {
        Params::Room(RoomOptions {
            glass,
            window,
            lamps: 0,
        })
    };
    let lit = |glass, window, lamps| {
        Params::Room(RoomOptions {
            glass,
            window,
            lamps,
        })
    };
    vec![
        room(Glass::None, false),
        room(Glass::None, true),
        room(Glass::Smooth, false),
        room(Glass::Smooth, true),
        room(Glass::Rough, false),
        room(Glass::Rough, true),
        room(Glass::None, false),
        room(Glass::Rough, true),
        lit(Glass::None, false, 120),
        lit(Glass::Smooth, true, 60),
    ]
}

/// The moving DI family's parameters: each kind twice at 10³ lights, every receiver choice.
fn di_motion_params() -> Vec<Params> {
    let di = |kind, receivers, envmap| {
        Params::Di(
            kind,
            DiOptions {
                lights: 1_000,
                power_ratio: 1000.0,
                receivers,
                occluders: true,
                envmap,
            },
        )
    };
    use Kind::{Meshes, Rects, Spheres};
    use Receivers::{Diffuse, Glossy, Mixed, Textured};
    vec![
        di(Rects, Diffuse, false),
        di(Rects, Glossy, true),
        di(Spheres, Mixed, false),
        di(Spheres, Textured, true),
        di(Meshes, Textured, false),
        di(Meshes, Mixed, true),
    ]
}

/// The moving PT family's parameters: each glass choice with and without a window.
fn pt_motion_params() -> Vec<Params> {
    Glass::ALL
        .into_iter()
        .flat_map(|glass| {
            [false, true].map(|window| {
                Params::Room(RoomOptions {
                    glass,
                    window,
                    lamps: 0,
                })
            })
        })
        .collect()
}

/// The members of `family` for `split`.
pub fn members(family: Family, split: Split) -> Vec<FamilyMember> {
    let params = match family {
        Family::Di => di_params(split),
        Family::Pt => pt_params(),
        Family::DiMotion => di_motion_params(),
        Family::PtMotion => pt_motion_params(),
    };
    params
        .into_iter()
        .enumerate()
        .map(|(index, params)| FamilyMember {
            family,
            split,
            index,
            params,
            seed: split.first_seed() + index as u64,
        })
        .collect()
}
