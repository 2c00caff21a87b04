//! Building the runtime scene from a description, once: meshes loaded and transformed, the BVH
//! built, light tables made, and the scene's feature summary decided. And the edits a built
//! scene takes (its materials), each of which keeps the summary true.

use std::path::Path;

use glam::{Affine3A, Mat4, Vec2, Vec3};
use restir_geometry::{
    Accel, Camera, Cylinder, FovAxis as GeoFovAxis, SdfNormals, Shape, Sphere, TriangleMesh,
};
use restir_lights::{EnvMap, Light, LightSet};
use restir_materials::Bsdf;

use crate::desc::*;
use crate::material::v3;
use crate::texture::Texture;
use crate::transform_matrix;
use crate::{Scene, SceneError, SceneFeatures, SceneWarning, TexturedParams};

mod budget;
mod mesh_file;

use budget::Budget;

fn affine(m: Mat4) -> Result<Affine3A, String> {
    let row3 = m.row(3);
    if (row3 - glam::Vec4::new(0.0, 0.0, 0.0, 1.0))
        .abs()
        .max_element()
        > 1e-6
    {
        return Err("projective transforms are not supported on shapes".into());
    }
    let a = Affine3A::from_mat4(m);
    // Degenerate when an axis collapses, measured against the scale of the transform itself
    // (the determinant over the product of the column lengths, 1 for any rotation and uniform
    // or axis scale), so that a scene in millimetres or kilometres is no more degenerate than in
    // metres; and refused when the determinant leaves the normal range of `f32` (a uniform
    // scale below about 2·10⁻¹³ or above 7·10¹², whose cube does).
    let m3 = a.matrix3;
    let det = m3.determinant();
    let lengths = m3.x_axis.length() * m3.y_axis.length() * m3.z_axis.length();
    if !det.is_finite() || !det.is_normal() || det.abs() <= 1e-6 * lengths {
        return Err(format!(
            "transform is degenerate (zero scale): determinant {det:e}, axis lengths {:e}, {:e}, {:e}",
            m3.x_axis.length(),
            m3.y_axis.length(),
            m3.z_axis.length()
        ));
    }
    Ok(a)
}

/// Decoded textures, each distinct description loaded once, and the memory budget (which counted
/// every image before the first was decoded).
#[derive(Default)]
struct TextureCache {
    descs: Vec<TextureDesc>,
    textures: Vec<Texture>,
    budget: Budget,
}

impl TextureCache {
    fn get(&mut self, d: &TextureDesc, base_dir: &Path) -> Result<u32, String> {
        if let Some(i) = self.descs.iter().position(|e| e == d) {
            return Ok(i as u32);
        }
        let t = Texture::load(d, base_dir).map_err(|e| e.to_string())?;
        self.descs.push(d.clone());
        self.textures.push(t);
        Ok(self.textures.len() as u32 - 1)
    }
}

/// A material's BSDF and, if some of its parameters are textures, their slots.
fn material(
    m: &MaterialDesc,
    cache: &mut TextureCache,
    base_dir: &Path,
) -> Result<(Bsdf, Option<TexturedParams>), String> {
    let bsdf = crate::material::bsdf(m).map_err(|e| e.to_string())?;
    let (base, bindings) = crate::material::colors(m);
    if crate::material::bump_scale(m).is_some()
        && !bindings.iter().any(|b| b.param == ColorParam::BumpMap)
    {
        return Err("bumpmap needs its height texture (a bitmap)".into());
    }
    if bindings.is_empty() {
        return Ok((bsdf, None));
    }
    let mut t = TexturedParams {
        base,
        diffuse: None,
        specular: None,
        transmittance: None,
        opacity: None,
        normal: None,
        alpha_u: None,
        alpha_v: None,
        principled: Default::default(),
        bump: None,
        weight: None,
    };
    for b in bindings {
        let id = Some(cache.get(&b.texture, base_dir)?);
        if let (Some(p), Some(id)) = (b.param.principled(), id) {
            t.principled.set(p, id);
            continue;
        }
        match b.param {
            ColorParam::Reflectance | ColorParam::DiffuseReflectance => t.diffuse = id,
            ColorParam::SpecularReflectance => t.specular = id,
            ColorParam::SpecularTransmittance => t.transmittance = id,
            ColorParam::Opacity => t.opacity = id,
            ColorParam::NormalMap => t.normal = id,
            ColorParam::BumpMap => {
                if !matches!(b.texture, TextureDesc::Bitmap { .. }) {
                    return Err(
                        "bumpmap: the height must be a bitmap (Mitsuba defines no gradient for other textures)"
                            .into(),
                    );
                }
                let scale = crate::material::bump_scale(m).unwrap_or(defaults::BUMP_SCALE);
                t.bump = id.map(|i| (i, scale));
            }
            ColorParam::Alpha => {
                t.alpha_u = id;
                t.alpha_v = id;
            }
            ColorParam::AlphaU => t.alpha_u = id,
            ColorParam::AlphaV => t.alpha_v = id,
            ColorParam::Weight => t.weight = id,
            _ => unreachable!("the principled parameters are bound above"),
        }
    }
    Ok((bsdf, Some(t)))
}

/// Reads an environment map's image (counted against the budget already) and sets up its lookup
/// and sampling.
fn build_envmap(
    filename: &str,
    scale: f32,
    to_world: &[TransformOp],
    base_dir: &Path,
) -> Result<EnvMap, String> {
    let m = transform_matrix(to_world).map_err(|e| e.to_string())?;
    let (w, h, texels) =
        crate::texture::read_image(&base_dir.join(filename), false).map_err(|e| e.to_string())?;
    EnvMap::new(w, h, texels, scale, glam::Mat3::from_mat4(m)).map_err(|e| e.to_string())
}

/// Where the scene declares light `l`, if the description records it.
fn light_location(l: &LightDesc) -> Option<&Location> {
    match l {
        LightDesc::Spot { location, .. }
        | LightDesc::Projector { location, .. }
        | LightDesc::Envmap { location, .. } => Some(location),
        _ => None,
    }
}

/// ` (mesh 'file')` for a shape read from a file, else nothing.
fn mesh_file(sd: &ShapeDesc) -> String {
    match &sd.geometry {
        GeometryDesc::Obj { filename }
        | GeometryDesc::Ply { filename }
        | GeometryDesc::Serialized { filename, .. } => format!(" (mesh '{filename}')"),
        _ => String::new(),
    }
}

/// Why a world-space shape lies beyond [`limits::MAX_COORDINATE`], or `None`.
fn extent_problem(shape: &Shape) -> Option<String> {
    let (what, v) = match shape {
        Shape::Mesh(m) => (
            "a vertex",
            m.positions()
                .iter()
                .map(|p| p.abs().max_element())
                .fold(0.0, f32::max),
        ),
        Shape::Sphere(s) => ("the sphere", s.center.abs().max_element() + s.radius),
        s => {
            let (lo, hi) = s.bounds();
            ("the shape", lo.abs().max(hi.abs()).max_element())
        }
    };
    (v.is_nan() || v > limits::MAX_COORDINATE).then(|| {
        format!(
            "{what} reaches {v:e} in world space, beyond the coordinate limit ±{:e}",
            limits::MAX_COORDINATE
        )
    })
}

/// A shape in world space and how many zero-area triangles were dropped from it.
fn build_shape(
    desc: &ShapeDesc,
    base_dir: &Path,
    budget: &mut Budget,
) -> Result<(Shape, usize), String> {
    let m = transform_matrix(&desc.to_world).map_err(|e| e.to_string())?;
    let dropped = std::cell::Cell::new(0);
    let mesh = |mut mesh: TriangleMesh| -> Result<Shape, String> {
        mesh.transform(&affine(m)?);
        dropped.set(mesh.drop_degenerate().map_err(|e| e.to_string())?);
        Ok(Shape::Mesh(mesh))
    };
    let mut shape = match &desc.geometry {
        GeometryDesc::Rectangle => mesh(Shape::rectangle())?,
        GeometryDesc::Cube => mesh(Shape::cube())?,
        GeometryDesc::Disk => mesh(Shape::disk(256).map_err(|e| e.to_string())?)?,
        GeometryDesc::Sphere { center, radius } => {
            if !(radius.is_finite() && *radius > 0.0) {
                return Err(format!("sphere radius {radius} must be positive"));
            }
            let a = affine(m)?;
            let c = a.transform_point3(Vec3::from(*center));
            let scale = a.matrix3.x_axis.length();
            let (sy, sz) = (a.matrix3.y_axis.length(), a.matrix3.z_axis.length());
            if (sy - scale).abs() > 1e-4 * scale || (sz - scale).abs() > 1e-4 * scale {
                return Err("spheres take only uniform scales".into());
            }
            // The rotation (and a mirroring) orients the texture, as in Mitsuba.
            let rotation = glam::Mat3::from(a.matrix3) / scale;
            Shape::Sphere(Sphere::new(c, radius * scale, desc.flip_normals).with_rotation(rotation))
        }
        GeometryDesc::Cylinder { p0, p1, radius } => Shape::Cylinder(Cylinder::new(
            Vec3::from(*p0),
            Vec3::from(*p1),
            *radius,
            affine(m)?,
            desc.flip_normals,
        )?),
        GeometryDesc::SdfGrid { filename, normals } => {
            if desc.emission.is_some() {
                return Err("an sdfgrid cannot be an area emitter (as in Mitsuba 3)".into());
            }
            if desc.flip_normals {
                return Err("an sdfgrid takes no flip_normals (as in Mitsuba 3)".into());
            }
            let normals = match normals {
                SdfNormalsDesc::Smooth => SdfNormals::Smooth,
                SdfNormalsDesc::Analytic => SdfNormals::Analytic,
            };
            let mut take =
                |kept, transient, what: &dyn Fn() -> String| budget.take(kept, transient, what);
            let grid = crate::volfile::load_sdfgrid(
                &base_dir.join(filename),
                affine(m)?,
                normals,
                &mut take,
            )?;
            Shape::SdfGrid(grid)
        }
        GeometryDesc::Obj { .. } | GeometryDesc::Ply { .. } | GeometryDesc::Serialized { .. } => {
            let (m, computed_normals) = mesh_file::read(desc, base_dir, budget)?;
            let mut shape = mesh(m)?;
            // A file without normals gets smooth ones, in world space, as in Mitsuba 3.
            if let (Shape::Mesh(m), true) = (&mut shape, computed_normals) {
                m.compute_vertex_normals();
            }
            shape
        }
        GeometryDesc::Mesh {
            positions,
            indices,
            normals,
        } => {
            let vertices = positions.len() + normals.as_ref().map_or(0, Vec::len);
            budget.take_mesh(indices.len(), 12 * vertices, || "the inline mesh".into())?;
            let p = positions.iter().map(|v| Vec3::from(*v)).collect();
            let n = if desc.face_normals {
                None
            } else {
                normals
                    .as_ref()
                    .map(|ns| ns.iter().map(|v| Vec3::from(*v)).collect())
            };
            mesh(
                TriangleMesh::new(p, n, None, indices.clone(), desc.flip_normals)
                    .map_err(|e| format!("inline mesh: {e}"))?,
            )?
        }
    };
    if let (Shape::Mesh(m), true) = (&mut shape, desc.flip_normals) {
        // Built-in meshes are made unflipped; rebuild with the flag.
        if !m.flip_normals() {
            let rebuilt = TriangleMesh::new(
                m.positions().to_vec(),
                if desc.face_normals {
                    None
                } else {
                    m.normals().map(<[Vec3]>::to_vec)
                },
                m.uvs().map(<[Vec2]>::to_vec),
                m.indices().to_vec(),
                true,
            )
            .map_err(|e| e.to_string())?
            .with_attributes(m.attributes().to_vec())
            .map_err(|e| e.to_string())?;
            *m = rebuilt;
        }
    } else if let (Shape::Mesh(m), true) = (&mut shape, desc.face_normals)
        && m.normals().is_some()
    {
        *m = TriangleMesh::new(
            m.positions().to_vec(),
            None,
            m.uvs().map(<[Vec2]>::to_vec),
            m.indices().to_vec(),
            m.flip_normals(),
        )
        .map_err(|e| e.to_string())?
        .with_attributes(m.attributes().to_vec())
        .map_err(|e| e.to_string())?;
    }
    if let Some(problem) = extent_problem(&shape) {
        return Err(problem);
    }
    Ok((shape, dropped.get()))
}

impl Scene {
    /// Builds the runtime scene. `base_dir` resolves relative mesh paths; `source` names the scene
    /// file in errors.
    pub fn build(desc: &SceneDesc, base_dir: &Path, source: &Path) -> Result<Scene, SceneError> {
        Self::build_noting(desc, base_dir, source).map(|(scene, _)| scene)
    }

    /// [`Scene::build`], also returning what the builder noticed (zero-area triangles dropped).
    pub fn build_noting(
        desc: &SceneDesc,
        base_dir: &Path,
        source: &Path,
    ) -> Result<(Scene, Vec<SceneWarning>), SceneError> {
        Self::build_within(desc, base_dir, source, None)
    }

    /// [`Scene::build_noting`] within `max_bytes` of memory for images, meshes and light tables
    /// (`None`: unbounded): every image is counted from its header before the first is decoded
    /// ([`limits::TEXTURE_BYTES_PER_TEXEL`] kept, [`limits::DECODE_BYTES_PER_TEXEL`] while
    /// decoding, and an environment map's sampling tables), each mesh
    /// ([`limits::MESH_BYTES_PER_TRIANGLE`] and its vertex data) before it is built, and each
    /// emitter ([`limits::EMITTER_BYTES_PER_ENTRY`] per emissive triangle or light) before its
    /// tables are made; the one that would cross the limit is an error at its line.
    pub fn build_within(
        desc: &SceneDesc,
        base_dir: &Path,
        source: &Path,
        max_bytes: Option<u64>,
    ) -> Result<(Scene, Vec<SceneWarning>), SceneError> {
        let mut warnings = Vec::new();
        let at = |loc: &Location, msg: String| {
            let location = if loc.file.as_os_str().is_empty() {
                Location {
                    file: source.to_path_buf(),
                    line: 0,
                }
            } else {
                loc.clone()
            };
            SceneError::new(location, msg)
        };
        let whole = |msg: String| at(&Location::default(), msg);

        // Camera.
        let (w, h) = (desc.film.width, desc.film.height);
        if w == 0 || h == 0 || w > 32768 || h > 32768 || (w as u64 * h as u64) > (1 << 28) {
            return Err(whole(format!(
                "film resolution {w}×{h} is out of range (each side 1..=32768, at most 2^28 pixels)"
            )));
        }
        let cam_m =
            transform_matrix(&desc.camera.to_world).map_err(|e| whole(format!("camera: {e}")))?;
        let fov_axis: GeoFovAxis = desc.camera.fov_axis.into();
        let camera = if desc.camera.orthographic {
            Camera::orthographic(cam_m, (w, h))
        } else {
            Camera::thin_lens(
                cam_m,
                desc.camera.fov,
                fov_axis,
                (w, h),
                desc.camera.aperture_radius,
                desc.camera.focus_distance,
            )
        }
        .and_then(|c| c.with_clip(desc.camera.near_clip, desc.camera.far_clip))
        .map_err(|e| whole(format!("camera: {e}")))?;
        match desc.film.filter {
            FilterDesc::Box => {}
            FilterDesc::Tent { radius: w } | FilterDesc::Gaussian { stddev: w } => {
                if w.is_nan() || w <= 0.0 {
                    return Err(whole(format!(
                        "filter {:?} needs a positive width",
                        desc.film.filter
                    )));
                }
                if let Some(p) = limits::filter_width_problem(w) {
                    return Err(whole(format!("filter {:?}: width {p}", desc.film.filter)));
                }
            }
        }
        if desc.integrator.max_depth < -1 {
            return Err(whole(format!(
                "max_depth {} must be -1 (unbounded) or non-negative",
                desc.integrator.max_depth
            )));
        }
        if desc.integrator.rr_depth == 0 {
            return Err(whole("rr_depth must be positive".into()));
        }

        // Materials.
        let mut bsdfs = vec![
            Bsdf::diffuse(v3(&defaults::DIFFUSE_REFLECTANCE)),
            Bsdf::black(),
        ];
        let mut bsdf_textures = vec![None, None];
        let mut cache = TextureCache {
            budget: Budget {
                limit: max_bytes,
                used: 0,
            },
            ..TextureCache::default()
        };
        // Every image, counted from its header before the first is decoded.
        cache
            .budget
            .take_images(&budget::images(desc, base_dir))
            .map_err(|(location, e)| at(&location, e))?;
        let mut names = std::collections::HashMap::new();
        for nm in &desc.materials {
            let (b, t) = material(&nm.material, &mut cache, base_dir)
                .map_err(|e| whole(format!("material '{}': {e}", nm.name)))?;
            names.insert(nm.name.clone(), bsdfs.len() as u32);
            bsdfs.push(b);
            bsdf_textures.push(t);
        }

        // Shapes, their materials and area lights.
        let mut shapes = Vec::with_capacity(desc.shapes.len());
        let mut shape_bsdf = Vec::with_capacity(desc.shapes.len());
        let mut lights = Vec::new();
        // The textures lights emit (area lights) and project (spot lights, projectors).
        let mut light_textures = Vec::new();
        let mut emission_textures = crate::spot::EmissionTextures::default();
        for (i, sd) in desc.shapes.iter().enumerate() {
            let (shape, dropped) = build_shape(sd, base_dir, &mut cache.budget)
                .map_err(|e| at(&sd.location, format!("shape {i}: {e}")))?;
            if dropped > 0 {
                let location = at(&sd.location, String::new()).location;
                warnings.push(SceneWarning {
                    location,
                    message: format!(
                        "shape {i}: {dropped} zero-area triangle{} dropped",
                        if dropped == 1 { "" } else { "s" }
                    ),
                });
            }
            let bsdf = match &sd.material {
                Some(MaterialRef::Ref(name)) => *names.get(name).ok_or_else(|| {
                    at(
                        &sd.location,
                        format!("shape {i}: no material named '{name}'"),
                    )
                })?,
                Some(MaterialRef::Inline(m)) => {
                    let (b, t) = material(m, &mut cache, base_dir)
                        .map_err(|e| at(&sd.location, format!("shape {i}: {e}")))?;
                    bsdfs.push(b);
                    bsdf_textures.push(t);
                    bsdfs.len() as u32 - 1
                }
                None if sd.emission.is_some() => 1,
                None => 0,
            };
            if let Some(t) = &bsdf_textures[bsdf as usize] {
                crate::texture::bind(&mut cache.textures, t, i as u32, &shape)
                    .map_err(|e| at(&sd.location, format!("shape {i}{}: {e}", mesh_file(sd))))?;
            }
            if sd.emission_texture.is_some() && sd.emission.is_none() {
                return Err(at(
                    &sd.location,
                    format!(
                        "shape {i}: an emission_texture needs emission, its factor ((1, 1, 1) for the texture's values)"
                    ),
                ));
            }
            if let Some(e) = &sd.emission {
                let radiance = v3(e);
                if !radiance.is_finite() || radiance.min_element() < 0.0 {
                    return Err(at(
                        &sd.location,
                        format!(
                            "shape {i}: emitted radiance {e:?} must be finite and non-negative"
                        ),
                    ));
                }
                // Refused here, where the shape's line is known, rather than by the light set.
                let power =
                    std::f32::consts::PI * shape.area() * restir_sampling::luminance(radiance);
                if radiance.max_element() > restir_lights::MAX_EMISSION
                    || power.is_nan()
                    || power > restir_lights::MAX_EMISSION
                {
                    return Err(at(
                        &sd.location,
                        format!(
                            "shape {i}: emitted radiance {e:?} (power {power:e}) exceeds the largest emission this renderer computes with, {:e} (products with geometry terms and sample weights would overflow)",
                            restir_lights::MAX_EMISSION
                        ),
                    ));
                }
                // A textured radiance: the light's `radiance` is the texture's mean (times the
                // factor), what its selection weights count.
                let (radiance, texture) = match &sd.emission_texture {
                    Some(t) => {
                        let (index, mean) = crate::spot::emission_texture(
                            t,
                            radiance,
                            base_dir,
                            &mut light_textures,
                            &mut emission_textures,
                        )
                        .map_err(|e| at(&sd.location, format!("shape {i}: {e}")))?;
                        (mean, Some(index))
                    }
                    None => (radiance, None),
                };
                if radiance.max_element() > 0.0 && shape.area() > 0.0 {
                    let entries = match &shape {
                        Shape::Mesh(m) => m.triangle_count(),
                        _ => 1,
                    };
                    cache
                        .budget
                        .take_emitters(entries, || format!("shape {i}: the area emitter"))
                        .map_err(|e| at(&sd.location, e))?;
                    lights.push(Light::Area {
                        shape: shapes.len() as u32,
                        radiance,
                        texture,
                    });
                }
            }
            shapes.push(shape);
            shape_bsdf.push(bsdf);
        }
        let mut envmap = None;
        for l in &desc.lights {
            let light = match l {
                LightDesc::Point {
                    position,
                    intensity,
                } => Light::Point {
                    position: v3(position),
                    intensity: v3(intensity),
                },
                LightDesc::Directional {
                    direction,
                    irradiance,
                } => Light::Directional {
                    direction: v3(direction),
                    irradiance: v3(irradiance),
                },
                LightDesc::Constant { radiance } => Light::Constant {
                    radiance: v3(radiance),
                },
                LightDesc::Spot { location, .. } | LightDesc::Projector { location, .. } => {
                    crate::spot::spot_light(l, base_dir, &mut light_textures)
                        .map_err(|e| at(location, e))?
                }
                LightDesc::Envmap {
                    filename,
                    scale,
                    to_world,
                    location,
                } => {
                    if envmap.is_some() {
                        return Err(at(
                            location,
                            "a second envmap emitter; only one environment is allowed per scene"
                                .into(),
                        ));
                    }
                    let map = build_envmap(filename, *scale, to_world, base_dir)
                        .map_err(|e| at(location, format!("envmap: {e}")))?;
                    envmap = Some(map);
                    Light::Envmap
                }
            };
            cache
                .budget
                .take_emitters(1, || "an emitter".into())
                .map_err(|e| match light_location(l) {
                    Some(location) => at(location, e),
                    None => whole(e),
                })?;
            lights.push(light);
        }

        let accel = Accel::build(&shapes);
        let shapes: std::sync::Arc<[Shape]> = shapes.into();
        let light_set = LightSet::with_textures(
            lights,
            envmap,
            light_textures,
            shapes.clone(),
            accel.bounds(),
        )
        .map_err(|e| whole(e.to_string()))?;

        // Feature summary, decided once (the material flags by `update_material_features`).
        let features = SceneFeatures {
            has_delta_lobes: false,
            has_glossy_lobes: false,
            has_textures: false,
            has_environment: light_set.environment().is_some(),
            has_delta_lights: light_set.lights().iter().any(|l| {
                matches!(
                    l,
                    Light::Point { .. }
                        | Light::Spot(_)
                        | Light::Projector(_)
                        | Light::Directional { .. }
                )
            }),
            light_count: light_set.len(),
            emitter_count: light_set.emitter_count(),
            median_light_emitters: light_set.median_emitters_per_light(),
            largest_light_share: 0.0,
            environment_share: None,
        };

        let mut scene = Scene {
            shapes,
            shape_bsdf,
            bsdfs,
            bsdf_textures,
            textures: cache.textures,
            accel,
            lights: light_set,
            camera,
            filter: desc.film.filter,
            features,
        };
        scene.update_material_features();
        scene.features.environment_share =
            scene.decide_environment_share(desc.integrator.hide_emitters);
        scene.features.largest_light_share = (0..scene.lights.len() as u32)
            .map(|l| scene.lights.pmf(l))
            .fold(0.0, f32::max);
        Ok((scene, warnings))
    }
}
