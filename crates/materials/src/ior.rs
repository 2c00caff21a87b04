//! Named indices of refraction (Mitsuba 3's `include/mitsuba/render/ior.h`) and the RGB complex
//! IORs of Mitsuba 3's named metals (its `data/ior/*.spd` files integrated to linear sRGB without
//! D65 weighting, as read from Mitsuba 3.9.1 `scalar_rgb`; see `shared/MATERIALS.md` §3.5).

use glam::Vec3;

/// Mitsuba's table of named real IORs.
pub const IOR_TABLE: &[(&str, f32)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000_036),
    ("hydrogen", 1.000_132),
    ("air", 1.000_277),
    ("carbon dioxide", 1.000_45),
    ("water", 1.333),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.520_45),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.47),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.575),
    ("diamond", 2.419),
];

/// The IOR of a named material (exact name as in Mitsuba, e.g. `bk7`, `water ice`).
pub fn ior(name: &str) -> Option<f32> {
    IOR_TABLE.iter().find(|(n, _)| *n == name).map(|&(_, v)| v)
}

/// RGB `(η, k)` of Mitsuba's named conductors that this renderer knows. `none` is the perfect
/// mirror `η = 0, k = 1` (Mitsuba's default).
pub const CONDUCTOR_TABLE: &[(&str, [f32; 3], [f32; 3])] = &[
    ("none", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
    (
        "Au",
        [0.143_036, 0.375_307, 1.442_045],
        [3.982_997, 2.385_556, 1.603_359],
    ),
    (
        "Ag",
        [0.155_276, 0.116_728, 0.138_388],
        [4.828_354, 3.122_222, 2.146_901],
    ),
    (
        "Cu",
        [0.201_005, 0.923_75, 1.102_215],
        [3.913_262, 2.453_045, 2.142_09],
    ),
    (
        "Cu_palik",
        [0.213_229, 0.919_715, 1.102_411],
        [3.921_873, 2.457_332, 2.136_584],
    ),
    (
        "Al",
        [1.657_501, 0.880_405, 0.521_244],
        [9.223_811, 6.269_502, 4.837_004],
    ),
    (
        "Cr",
        [4.369_668, 2.916_505, 1.654_905],
        [5.206_547, 4.231_306, 3.754_699],
    ),
    (
        "W",
        [4.370_817, 3.300_246, 2.998_407],
        [3.500_641, 2.604_874, 2.273_233],
    ),
    (
        "Hg",
        [2.398_939, 1.440_028, 0.909_57],
        [6.327_587, 4.371_925, 3.421_764],
    ),
    (
        "Ni_palik",
        [2.367_305, 1.663_373, 1.467_078],
        [4.498_812, 3.050_153, 2.345_439],
    ),
    (
        "Ir",
        [3.086_3, 2.082_191, 1.617_915],
        [5.592_153, 4.067_088, 3.267_312],
    ),
    (
        "Rh",
        [2.585_793, 1.860_216, 1.554_263],
        [6.782_26, 4.702_987, 3.976_073],
    ),
    (
        "Mo",
        [4.483_974, 3.525_131, 2.776_31],
        [4.111_437, 3.420_827, 3.150_607],
    ),
    (
        "Ta",
        [2.062_721, 2.392_939, 2.627_929],
        [2.408_36, 1.741_486, 1.947_028],
    ),
    (
        "TiN",
        [1.648_45, 1.150_516, 1.379_823],
        [3.368_328, 1.943_498, 1.102_068],
    ),
];

/// `(η, k)` of a named conductor (case-sensitive, as in Mitsuba).
pub fn conductor(name: &str) -> Option<(Vec3, Vec3)> {
    CONDUCTOR_TABLE
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|&(_, e, k)| (Vec3::from(e), Vec3::from(k)))
}

/// The conductor names [`conductor`] knows, comma-separated (for error messages).
pub fn conductor_names() -> String {
    CONDUCTOR_TABLE
        .iter()
        .map(|(n, _, _)| *n)
        .collect::<Vec<_>>()
        .join(", ")
}

/// The IOR names [`ior`] knows, comma-separated (for error messages).
pub fn ior_names() -> String {
    IOR_TABLE
        .iter()
        .map(|(n, _)| *n)
        .collect::<Vec<_>>()
        .join(", ")
}
