//! Helpers every generator shares: rounding for short files, uniform and log-uniform draws, light
//! tints, shape and material constructors, and RON serialisation.

use glam::Vec3;
use restir_sampling::Pcg32;

use restir_scene::{
    GeometryDesc, MaterialDesc, MaterialRef, MicrofacetDesc, RoughnessDesc, SceneDesc, ShapeDesc,
    TransformOp, V3,
};

/// Rounds to `digits` decimals so that the file stays short and readable.
pub(super) fn round(x: f32, digits: i32) -> f32 {
    let s = 10f32.powi(digits);
    (x * s).round() / s
}

/// Rounds every component of a vector.
pub(super) fn round3(v: V3, digits: i32) -> V3 {
    v.map(|x| round(x, digits))
}

/// Uniform in `[lo, hi)`.
pub(super) fn uniform(rng: &mut Pcg32, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * rng.next_f32()
}

/// Log-uniform in `[1, ratio)`: the power spread of the many-light scenes.
pub(super) fn log_uniform(rng: &mut Pcg32, ratio: f32) -> f32 {
    ratio.powf(rng.next_f32())
}

/// A colour with maximum component 1 from a hue in `[0, 1)` and a saturation (0 is white).
pub(super) fn hue_colour(h: f32, s: f32) -> [f32; 3] {
    let channel = |offset: f32| {
        let x = (h + offset).fract() * 6.0;
        let v = (x - 3.0).abs() - 1.0; // a triangle wave: 1 at x = 0 and 6, 0 on [2, 4]
        v.clamp(0.0, 1.0)
    };
    let rgb = [channel(0.0), channel(2.0 / 3.0), channel(1.0 / 3.0)];
    rgb.map(|c| 1.0 - s + s * c)
}

/// A lamp's colour (maximum component 1): three in four warm white, the rest saturated.
pub(super) fn lamp_tint(rng: &mut Pcg32) -> [f32; 3] {
    if rng.next_bounded(4) == 0 {
        hue_colour(rng.next_f32(), uniform(rng, 0.4, 0.8))
    } else {
        hue_colour(uniform(rng, 0.02, 0.12), uniform(rng, 0.05, 0.3))
    }
}

/// A shape with a material and a transform, not emitting.
pub(super) fn shape(
    geometry: GeometryDesc,
    to_world: Vec<TransformOp>,
    material: MaterialRef,
) -> ShapeDesc {
    ShapeDesc {
        id: None,
        geometry,
        to_world,
        material: Some(material),
        emission: None,
        emission_texture: None,
        flip_normals: false,
        face_normals: false,
        location: Default::default(),
    }
}

/// An emitter without a material (black apart from its emission).
pub(super) fn emitter(
    geometry: GeometryDesc,
    to_world: Vec<TransformOp>,
    radiance: V3,
) -> ShapeDesc {
    ShapeDesc {
        id: None,
        geometry,
        to_world,
        material: None,
        emission: Some(radiance),
        emission_texture: None,
        flip_normals: false,
        face_normals: false,
        location: Default::default(),
    }
}

/// A reference to a named material.
pub(super) fn named(name: &str) -> MaterialRef {
    MaterialRef::Ref(name.into())
}

/// A rectangle `[-sx, sx] × [-sy, sy]` rotated about `axis` by `angle` degrees, then moved to `at`.
pub(super) fn rect_transform(sx: f32, sy: f32, axis: V3, angle: f32, at: V3) -> Vec<TransformOp> {
    vec![
        TransformOp::Scale([sx, sy, 1.0]),
        TransformOp::Rotate { axis, angle },
        TransformOp::Translate(at),
    ]
}

/// Roughness with one α.
pub(super) fn roughness(distribution: MicrofacetDesc, alpha: f32) -> RoughnessDesc {
    RoughnessDesc {
        distribution,
        alpha,
        alpha_u: None,
        alpha_v: None,
    }
}

/// Beckmann or GGX, one each with probability ½.
pub(super) fn distribution(rng: &mut Pcg32) -> MicrofacetDesc {
    if rng.next_bounded(2) == 0 {
        MicrofacetDesc::Beckmann
    } else {
        MicrofacetDesc::Ggx
    }
}

/// A rough conductor of a named metal.
pub(super) fn rough_conductor(
    metal: &str,
    distribution: MicrofacetDesc,
    alpha: f32,
) -> MaterialDesc {
    MaterialDesc::RoughConductor {
        ior: restir_scene::ConductorIorDesc {
            material: Some(metal.into()),
            eta: None,
            k: None,
        },
        specular_reflectance: [1.0; 3],
        roughness: roughness(distribution, alpha),
    }
}

/// A rough plastic (polypropylene coat) over a diffuse base.
pub(super) fn rough_plastic(diffuse: V3, distribution: MicrofacetDesc, alpha: f32) -> MaterialDesc {
    MaterialDesc::RoughPlastic {
        int_ior: restir_scene::POLYPROPYLENE_IOR,
        ext_ior: restir_scene::AIR_IOR,
        diffuse_reflectance: diffuse,
        specular_reflectance: [1.0; 3],
        nonlinear: false,
        roughness: roughness(distribution, alpha),
    }
}

/// A diffuse material with a checkerboard bound to its reflectance, `tiles` squares per unit uv.
pub(super) fn checkerboard(color0: V3, color1: V3, tiles: f32) -> MaterialDesc {
    MaterialDesc::Textured {
        material: Box::new(MaterialDesc::Diffuse {
            reflectance: color0,
        }),
        textures: vec![restir_scene::TextureBinding {
            param: restir_scene::ColorParam::Reflectance,
            texture: restir_scene::TextureDesc::Checkerboard {
                color0,
                color1,
                uv: restir_scene::UvTransform {
                    scale: glam::Vec2::splat(tiles),
                    offset: glam::Vec2::ZERO,
                },
            },
        }],
    }
}

/// The metals the glossy materials draw from (named IORs of `restir_materials::ior`).
pub(super) const METALS: [&str; 4] = ["Au", "Cu", "Al", "Ag"];

/// A scene description as pretty RON (one shape per line) after a header of `//` comments.
pub(super) fn to_ron(desc: &SceneDesc, header: &str) -> Result<String, ron::Error> {
    let config = ron::ser::PrettyConfig::new()
        .depth_limit(2)
        .struct_names(false);
    let mut body = match &desc.animation {
        None => ron::ser::to_string_pretty(desc, config.clone())?,
        Some(_) => {
            let still = SceneDesc {
                animation: None,
                ..desc.clone()
            };
            ron::ser::to_string_pretty(&still, config.clone())?
        }
    };
    if let Some(anim) = &desc.animation {
        // The animation one level deeper than the scene, so that every track and camera key
        // gets its own line.
        let anim = ron::ser::to_string_pretty(anim, config)?;
        let close = body.rfind(')').unwrap_or(body.len());
        body.truncate(close);
        body.push_str("    animation: Some(");
        for (i, line) in anim.lines().enumerate() {
            if i > 0 {
                body.push_str("\n    ");
            }
            body.push_str(line);
        }
        body.push_str("),\n)");
    }
    let mut text = String::new();
    for line in header.lines() {
        text.push_str("// ");
        text.push_str(line);
        text.push('\n');
    }
    text.push_str(&body);
    text.push('\n');
    Ok(text)
}

/// A tessellated parametric surface: triangles `(a, b, c)` with normal along `∂u × ∂v`.
pub(super) fn grid(nu: u32, nv: u32, f: impl Fn(f32, f32) -> Vec3) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::with_capacity(((nu + 1) * (nv + 1)) as usize);
    for j in 0..=nv {
        for i in 0..=nu {
            positions.push(f(i as f32 / nu as f32, j as f32 / nv as f32));
        }
    }
    let index = |i: u32, j: u32| j * (nu + 1) + i;
    let mut triangles = Vec::with_capacity((2 * nu * nv) as usize);
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (
                index(i, j),
                index(i + 1, j),
                index(i + 1, j + 1),
                index(i, j + 1),
            );
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    (positions, triangles)
}

/// The mesh as OBJ text, its header naming the generator `kind` (positions to 4 decimals, 1-based faces).
pub(super) fn obj(name: &str, kind: &str, positions: &[Vec3], triangles: &[[u32; 3]]) -> String {
    use core::fmt::Write;
    let mut text = format!(
        "# {name}: {} emissive triangles, generated by restir_families ({kind})\no {name}\n",
        triangles.len()
    );
    for p in positions {
        let _ = writeln!(
            text,
            "v {} {} {}",
            round(p.x, 4),
            round(p.y, 4),
            round(p.z, 4)
        );
    }
    for [a, b, c] in triangles {
        let _ = writeln!(text, "f {} {} {}", a + 1, b + 1, c + 1);
    }
    text
}
