//! Building the runtime scene from a description, once: meshes loaded and transformed, the BVH
//! built, light tables made, and the scene's feature summary decided.

use std::path::Path;

use glam::{Affine3A, Mat4, Vec2, Vec3};
use restir_geometry::{Accel, Camera, FovAxis as GeoFovAxis, Shape, Sphere, TriangleMesh};
use restir_lights::{EnvMap, Light, LightSet};
use restir_materials::{Bsdf, Distribution, LobeFlags, Microfacet, ReflectanceParams};

use crate::desc::*;
use crate::texture::Texture;
use crate::{Scene, SceneError, SceneFeatures, TexturedParams};

/// Composes transform steps (first step applied first) into one matrix.
pub fn transform_matrix(ops: &[TransformOp]) -> Result<Mat4, String> {
    let mut m = Mat4::IDENTITY;
    for op in ops {
        let step = match op {
            TransformOp::Translate(t) => Mat4::from_translation(Vec3::from(*t)),
            TransformOp::Scale(s) => Mat4::from_scale(Vec3::from(*s)),
            TransformOp::Rotate { axis, angle } => {
                let a = Vec3::from(*axis);
                if a.length_squared() == 0.0 || !a.is_finite() {
                    return Err("rotation axis is zero".into());
                }
                Mat4::from_axis_angle(a.normalize(), angle.to_radians())
            }
            TransformOp::LookAt { origin, target, up } => {
                let (o, t, u) = (Vec3::from(*origin), Vec3::from(*target), Vec3::from(*up));
                let dir = (t - o).normalize_or_zero();
                let left = u.cross(dir).normalize_or_zero();
                if dir == Vec3::ZERO || left == Vec3::ZERO {
                    return Err(
                        "lookat is degenerate: origin equals target or up is parallel to the view direction"
                            .into(),
                    );
                }
                let new_up = dir.cross(left);
                Mat4::from_cols(
                    left.extend(0.0),
                    new_up.extend(0.0),
                    dir.extend(0.0),
                    o.extend(1.0),
                )
            }
            TransformOp::Matrix(v) => Mat4::from_cols_array(v).transpose(),
        };
        m = step * m;
    }
    if !m.is_finite() {
        return Err("transform has non-finite entries".into());
    }
    Ok(m)
}

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
    let det = a.matrix3.determinant();
    if det.abs() < 1e-12 || !det.is_finite() {
        return Err("transform is degenerate (zero scale)".into());
    }
    Ok(a)
}

fn unit_color(what: &str, c: &V3) -> Result<Vec3, String> {
    let v = Vec3::from(*c);
    if !v.is_finite() || v.min_element() < 0.0 || v.max_element() > 1.0 {
        return Err(format!("{what} {c:?} must lie in [0, 1]"));
    }
    Ok(v)
}

fn relative_ior(int_ior: f32, ext_ior: f32) -> Result<f32, String> {
    for (name, v) in [("int_ior", int_ior), ("ext_ior", ext_ior)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(format!("{name} {v} must be a positive number"));
        }
    }
    Ok(int_ior / ext_ior)
}

fn conductor_ior(d: &ConductorIorDesc) -> Result<(Vec3, Vec3), String> {
    if let Some(name) = &d.material {
        if name != "none" && (d.eta.is_some() || d.k.is_some()) {
            return Err(format!(
                "conductor material '{name}' cannot be combined with explicit eta or k"
            ));
        }
        if d.eta.is_none() && d.k.is_none() {
            return restir_materials::ior::conductor(name).ok_or_else(|| {
                format!(
                    "unknown conductor material '{name}' (known: {})",
                    restir_materials::ior::conductor_names()
                )
            });
        }
    }
    let eta = Vec3::from(d.eta.unwrap_or([0.0; 3]));
    let k = Vec3::from(d.k.unwrap_or([1.0; 3]));
    for (name, v) in [("eta", eta), ("k", k)] {
        if !v.is_finite() || v.min_element() < 0.0 {
            return Err(format!(
                "conductor {name} {v} must be finite and non-negative"
            ));
        }
    }
    Ok((eta, k))
}

fn microfacet(r: &RoughnessDesc, anisotropy_allowed: bool) -> Result<Microfacet, String> {
    let dist = match r.distribution {
        MicrofacetDesc::Beckmann => Distribution::Beckmann,
        MicrofacetDesc::Ggx => Distribution::Ggx,
    };
    let check = |name: &str, a: f32| {
        if a.is_finite() && a >= 0.0 {
            Ok(a)
        } else {
            Err(format!(
                "{name} {a} must be a finite non-negative roughness"
            ))
        }
    };
    match (r.alpha_u, r.alpha_v) {
        (None, None) => Ok(Microfacet::new(dist, check("alpha", r.alpha)?)),
        (Some(u), Some(v)) => {
            if !anisotropy_allowed {
                return Err("this material is isotropic: give alpha, not alpha_u/alpha_v".into());
            }
            Ok(Microfacet::anisotropic(
                dist,
                check("alpha_u", u)?,
                check("alpha_v", v)?,
            ))
        }
        _ => Err("alpha_u and alpha_v must be given together".into()),
    }
}

/// Checks a material the way [`Scene::build`] would, without keeping the result.
pub(crate) fn check_material(m: &MaterialDesc) -> Result<(), String> {
    material_bsdf(m).map(|_| ())
}

fn material_bsdf(m: &MaterialDesc) -> Result<Bsdf, String> {
    Ok(match m {
        MaterialDesc::Diffuse { reflectance } => {
            Bsdf::diffuse(unit_color("diffuse reflectance", reflectance)?)
        }
        MaterialDesc::Conductor {
            ior,
            specular_reflectance,
        } => {
            let (eta, k) = conductor_ior(ior)?;
            Bsdf::conductor(
                eta,
                k,
                unit_color("specular_reflectance", specular_reflectance)?,
            )
        }
        MaterialDesc::RoughConductor {
            ior,
            specular_reflectance,
            roughness,
        } => {
            let (eta, k) = conductor_ior(ior)?;
            Bsdf::rough_conductor(
                eta,
                k,
                unit_color("specular_reflectance", specular_reflectance)?,
                microfacet(roughness, true)?,
            )
        }
        MaterialDesc::Dielectric {
            int_ior,
            ext_ior,
            specular_reflectance,
            specular_transmittance,
        } => Bsdf::dielectric(
            relative_ior(*int_ior, *ext_ior)?,
            unit_color("specular_reflectance", specular_reflectance)?,
            unit_color("specular_transmittance", specular_transmittance)?,
        ),
        MaterialDesc::RoughDielectric {
            int_ior,
            ext_ior,
            specular_reflectance,
            specular_transmittance,
            roughness,
        } => Bsdf::rough_dielectric(
            relative_ior(*int_ior, *ext_ior)?,
            unit_color("specular_reflectance", specular_reflectance)?,
            unit_color("specular_transmittance", specular_transmittance)?,
            microfacet(roughness, true)?,
        ),
        MaterialDesc::Plastic {
            int_ior,
            ext_ior,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
        } => Bsdf::plastic(
            relative_ior(*int_ior, *ext_ior)?,
            unit_color("diffuse_reflectance", diffuse_reflectance)?,
            unit_color("specular_reflectance", specular_reflectance)?,
            *nonlinear,
        ),
        MaterialDesc::RoughPlastic {
            int_ior,
            ext_ior,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            roughness,
        } => {
            let eta = relative_ior(*int_ior, *ext_ior)?;
            if eta == 1.0 {
                return Err("roughplastic: int_ior must differ from ext_ior".into());
            }
            let mf = microfacet(roughness, false)?;
            Bsdf::rough_plastic(
                eta,
                unit_color("diffuse_reflectance", diffuse_reflectance)?,
                unit_color("specular_reflectance", specular_reflectance)?,
                *nonlinear,
                mf.distribution,
                mf.alpha_u,
            )
        }
        MaterialDesc::Null => Bsdf::null(),
        MaterialDesc::TwoSided(inner) => {
            let b = material_bsdf(inner)?;
            if b.kind.transmits() {
                return Err(
                    "twosided cannot wrap a transmitting material (dielectric, roughdielectric, null), as in Mitsuba"
                        .into(),
                );
            }
            b.two_sided()
        }
        MaterialDesc::Black => Bsdf::black(),
        MaterialDesc::Textured { material, textures } => {
            let b = material_bsdf(material)?;
            let allowed = color_params(material);
            if matches!(**material, MaterialDesc::Textured { .. }) {
                return Err("a textured material cannot wrap another textured material".into());
            }
            for (i, t) in textures.iter().enumerate() {
                if !allowed.contains(&t.param) {
                    let names: Vec<&str> = allowed.iter().map(|p| p.name()).collect();
                    return Err(format!(
                        "texture for '{}': this material has no such parameter (its colour parameters: {})",
                        t.param.name(),
                        if names.is_empty() {
                            "none".to_string()
                        } else {
                            names.join(", ")
                        }
                    ));
                }
                if textures[..i].iter().any(|u| u.param == t.param) {
                    return Err(format!("two textures for '{}'", t.param.name()));
                }
            }
            b
        }
    })
}

/// The colour parameters of a material that textures may replace.
pub(crate) fn color_params(m: &MaterialDesc) -> &'static [ColorParam] {
    use ColorParam::*;
    match m {
        MaterialDesc::Diffuse { .. } => &[Reflectance],
        MaterialDesc::Conductor { .. } | MaterialDesc::RoughConductor { .. } => {
            &[SpecularReflectance]
        }
        MaterialDesc::Dielectric { .. } | MaterialDesc::RoughDielectric { .. } => {
            &[SpecularReflectance, SpecularTransmittance]
        }
        MaterialDesc::Plastic { .. } | MaterialDesc::RoughPlastic { .. } => {
            &[DiffuseReflectance, SpecularReflectance]
        }
        MaterialDesc::TwoSided(inner) => color_params(inner),
        MaterialDesc::Textured { material, .. } => color_params(material),
        MaterialDesc::Null | MaterialDesc::Black => &[],
    }
}

/// The constant colour parameters of a material as written (defaults where a model has none)
/// and the textures that replace some of them.
fn material_colors(m: &MaterialDesc) -> (ReflectanceParams, &[TextureBinding]) {
    let mut p = ReflectanceParams {
        diffuse: Vec3::splat(0.5),
        specular: Vec3::ONE,
        transmittance: Vec3::ONE,
        nonlinear: false,
    };
    let mut bindings: &[TextureBinding] = &[];
    let mut m = m;
    loop {
        match m {
            MaterialDesc::TwoSided(inner) => m = inner,
            MaterialDesc::Textured { material, textures } => {
                bindings = textures;
                m = material;
            }
            _ => break,
        }
    }
    match m {
        MaterialDesc::Diffuse { reflectance } => p.diffuse = v3(reflectance),
        MaterialDesc::Conductor {
            specular_reflectance,
            ..
        }
        | MaterialDesc::RoughConductor {
            specular_reflectance,
            ..
        } => p.specular = v3(specular_reflectance),
        MaterialDesc::Dielectric {
            specular_reflectance,
            specular_transmittance,
            ..
        }
        | MaterialDesc::RoughDielectric {
            specular_reflectance,
            specular_transmittance,
            ..
        } => {
            p.specular = v3(specular_reflectance);
            p.transmittance = v3(specular_transmittance);
        }
        MaterialDesc::Plastic {
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            ..
        }
        | MaterialDesc::RoughPlastic {
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            ..
        } => {
            p.diffuse = v3(diffuse_reflectance);
            p.specular = v3(specular_reflectance);
            p.nonlinear = *nonlinear;
        }
        _ => {}
    }
    (p, bindings)
}

/// Decoded textures, each distinct description loaded once.
#[derive(Default)]
struct TextureCache {
    descs: Vec<TextureDesc>,
    textures: Vec<Texture>,
}

impl TextureCache {
    fn get(&mut self, d: &TextureDesc, base_dir: &Path) -> Result<u32, String> {
        if let Some(i) = self.descs.iter().position(|e| e == d) {
            return Ok(i as u32);
        }
        let t = Texture::load(d, base_dir)?;
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
    let bsdf = material_bsdf(m)?;
    let (base, bindings) = material_colors(m);
    if bindings.is_empty() {
        return Ok((bsdf, None));
    }
    let mut t = TexturedParams {
        base,
        diffuse: None,
        specular: None,
        transmittance: None,
    };
    for b in bindings {
        let id = Some(cache.get(&b.texture, base_dir)?);
        match b.param {
            ColorParam::Reflectance | ColorParam::DiffuseReflectance => t.diffuse = id,
            ColorParam::SpecularReflectance => t.specular = id,
            ColorParam::SpecularTransmittance => t.transmittance = id,
        }
    }
    Ok((bsdf, Some(t)))
}

use crate::meshio::MeshData;

/// Reads a whole mesh file.
fn read_mesh_file(path: &Path) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| format!("cannot read mesh '{}': {e}", path.display()))
}

fn load_obj(path: &Path) -> Result<MeshData, String> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // tobj reports a missing file as "open file failed"; say why.
    std::fs::File::open(path).map_err(|e| format!("cannot read mesh '{}': {e}", path.display()))?;
    let (models, _) = tobj::load_obj(path, &opts)
        .map_err(|e| format!("cannot read mesh '{}': {e}", path.display()))?;
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut indices = Vec::new();
    let all_normals = models
        .iter()
        .all(|m| m.mesh.normals.len() == m.mesh.positions.len());
    let all_uvs = models
        .iter()
        .all(|m| m.mesh.texcoords.len() / 2 == m.mesh.positions.len() / 3);
    for m in &models {
        let base = positions.len() as u32;
        let mesh = &m.mesh;
        if mesh.positions.len() % 3 != 0 || mesh.indices.len() % 3 != 0 {
            return Err(format!("mesh '{}' is truncated", path.display()));
        }
        positions.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2])),
        );
        if all_normals {
            normals.extend(
                mesh.normals
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2])),
            );
        }
        if all_uvs {
            uvs.extend(
                mesh.texcoords
                    .chunks_exact(2)
                    // OBJ counts v from the bottom of the image; Mitsuba flips it on load.
                    .map(|c| Vec2::new(c[0], 1.0 - c[1])),
            );
        }
        for t in mesh.indices.chunks_exact(3) {
            indices.push([base + t[0], base + t[1], base + t[2]]);
        }
    }
    if indices.is_empty() {
        return Err(format!("mesh '{}' has no triangles", path.display()));
    }
    Ok((
        positions,
        (all_normals && !normals.is_empty()).then_some(normals),
        (all_uvs && !uvs.is_empty()).then_some(uvs),
        indices,
    ))
}

/// Reads an environment map's image and sets up its lookup and sampling.
fn build_envmap(
    filename: &str,
    scale: f32,
    to_world: &[TransformOp],
    base_dir: &Path,
) -> Result<EnvMap, String> {
    let m = transform_matrix(to_world)?;
    let (w, h, texels) = crate::texture::read_image(&base_dir.join(filename), false)?;
    EnvMap::new(w, h, texels, scale, glam::Mat3::from_mat4(m))
}

fn build_shape(desc: &ShapeDesc, base_dir: &Path) -> Result<Shape, String> {
    let m = transform_matrix(&desc.to_world)?;
    let mesh = |mut mesh: TriangleMesh| -> Result<Shape, String> {
        mesh.transform(&affine(m)?);
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
            Shape::Sphere(Sphere::new(c, radius * scale, desc.flip_normals))
        }
        GeometryDesc::Obj { filename } => {
            let path = base_dir.join(filename);
            let (p, n, uv, idx) = load_obj(&path)?;
            let n = if desc.face_normals { None } else { n };
            mesh(
                TriangleMesh::new(p, n, uv, idx, desc.flip_normals)
                    .map_err(|e| format!("mesh '{}': {e}", path.display()))?,
            )?
        }
        GeometryDesc::Ply { filename } => {
            let path = base_dir.join(filename);
            let (p, n, uv, idx) = crate::meshio::read_ply(&read_mesh_file(&path)?)
                .map_err(|e| format!("mesh '{}': {e}", path.display()))?;
            let n = if desc.face_normals { None } else { n };
            mesh(
                TriangleMesh::new(p, n, uv, idx, desc.flip_normals)
                    .map_err(|e| format!("mesh '{}': {e}", path.display()))?,
            )?
        }
        GeometryDesc::Serialized {
            filename,
            shape_index,
        } => {
            let path = base_dir.join(filename);
            let (p, n, uv, idx) =
                crate::meshio::read_serialized(&read_mesh_file(&path)?, *shape_index as usize)
                    .map_err(|e| format!("mesh '{}': {e}", path.display()))?;
            let n = if desc.face_normals { None } else { n };
            mesh(
                TriangleMesh::new(p, n, uv, idx, desc.flip_normals)
                    .map_err(|e| format!("mesh '{}': {e}", path.display()))?,
            )?
        }
        GeometryDesc::Mesh {
            positions,
            indices,
            normals,
        } => {
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
        .map_err(|e| e.to_string())?;
    }
    Ok(shape)
}

fn v3(v: &V3) -> Vec3 {
    Vec3::from(*v)
}

impl Scene {
    /// Builds the runtime scene. `base_dir` resolves relative mesh paths; `source` names the scene
    /// file in errors.
    pub fn build(desc: &SceneDesc, base_dir: &Path, source: &Path) -> Result<Scene, SceneError> {
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
        let fov_axis = match desc.camera.fov_axis {
            FovAxis::X => GeoFovAxis::X,
            FovAxis::Y => GeoFovAxis::Y,
            FovAxis::Diagonal => GeoFovAxis::Diagonal,
            FovAxis::Smaller => GeoFovAxis::Smaller,
            FovAxis::Larger => GeoFovAxis::Larger,
        };
        let camera = Camera::thin_lens(
            cam_m,
            desc.camera.fov,
            fov_axis,
            (w, h),
            desc.camera.aperture_radius,
            desc.camera.focus_distance,
        )
        .map_err(|e| whole(format!("camera: {e}")))?;
        match desc.film.filter {
            FilterDesc::Box => {}
            FilterDesc::Tent { radius } if radius.is_finite() && radius > 0.0 => {}
            FilterDesc::Gaussian { stddev } if stddev.is_finite() && stddev > 0.0 => {}
            f => return Err(whole(format!("filter {f:?} needs a positive width"))),
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
        let mut bsdfs = vec![Bsdf::diffuse(Vec3::splat(0.5)), Bsdf::black()];
        let mut bsdf_textures = vec![None, None];
        let mut cache = TextureCache::default();
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
        for (i, sd) in desc.shapes.iter().enumerate() {
            let shape = build_shape(sd, base_dir)
                .map_err(|e| at(&sd.location, format!("shape {i}: {e}")))?;
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
                if radiance.max_element() > 0.0 && shape.area() > 0.0 {
                    lights.push(Light::Area {
                        shape: shapes.len() as u32,
                        radiance,
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
            lights.push(light);
        }

        let accel = Accel::build(&shapes);
        let light_set = LightSet::with_envmap(lights, envmap, &shapes, accel.bounds())
            .map_err(|e| whole(e.to_string()))?;

        // Feature summary, decided once.
        let used: Vec<&Bsdf> = shape_bsdf.iter().map(|&b| &bsdfs[b as usize]).collect();
        let features = SceneFeatures {
            has_delta_lobes: used.iter().any(|b| b.flags().contains(LobeFlags::DELTA)),
            has_glossy_lobes: used.iter().any(|b| b.flags().contains(LobeFlags::GLOSSY)),
            has_textures: shape_bsdf
                .iter()
                .any(|&b| bsdf_textures[b as usize].is_some()),
            has_environment: light_set.environment().is_some(),
            has_delta_lights: light_set
                .lights()
                .iter()
                .any(|l| matches!(l, Light::Point { .. } | Light::Directional { .. })),
            light_count: light_set.len(),
        };

        Ok(Scene {
            shapes,
            shape_bsdf,
            bsdfs,
            bsdf_textures,
            textures: cache.textures,
            accel,
            lights: light_set,
            camera,
            filter: desc.film.filter,
            integrator: desc.integrator.clone(),
            features,
        })
    }
}
