//! The writer: a [`SceneDesc`] as a Mitsuba 3 scene file (`<scene version="3.0.0">`) that Mitsuba
//! 3 and this module's importer both read to the same scene. It is the one place that knows how
//! each camera, film, integrator, shape, material, texture and emitter of a description is
//! spelled in Mitsuba 3, function by function in the importer's order (sensor, integrator, bsdfs,
//! textures, shapes, emitters).
//!
//! What Mitsuba 3 cannot express faithfully is an [`XmlWriteError`] naming the item and why,
//! never an approximation: an animation, an estimator other than the path tracer (or estimator
//! parameters), a triangle mesh given inline, textures bound twice. What is written differently
//! but renders the same: a sphere's `to_world` is folded into its centre and radius (this renderer
//! computes a sphere's uv about world axes, Mitsuba about its object frame, which folding makes
//! the world's); a material of an area light that has none is left out (both renderers make it
//! black); `Black` is a diffuse bsdf of reflectance 0; `face_normals` is written for mesh files
//! only (built-in shapes are flat-faced or analytic: it changes nothing there, and Mitsuba
//! rejects it); a pinhole camera's focus distance is left out, and clip planes at Mitsuba's
//! defaults too; the film's output file name is a
//! comment (Mitsuba's `hdrfilm` refuses one); a material whose name is also a shape's id (one
//! namespace in Mitsuba, two here) gets the id `<name>-bsdf`.
//!
//! The film size, sample count and maximum depth are `<default>` variables (`resx`, `resy`,
//! `spp`, `max_depth`), as in the scenes Mitsuba's own tools export: `-D resx=128` here, and
//! `mi.load_file(path, resx=128)` in Mitsuba, change them without editing the file.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::desc::*;
use crate::texture::{FilterType, TextureDesc, UvTransform, WrapMode};

/// Options of [`to_mitsuba_xml`].
#[derive(Clone, Debug, Default)]
pub struct XmlWriteOptions {
    /// Prefix joined to every relative file name (meshes, textures, environment maps), for XML
    /// written in another directory than the scene it describes: the path from the XML's
    /// directory to the scene's. `None` keeps file names as they are.
    pub file_prefix: Option<PathBuf>,
    /// Lines of a leading comment (how the file was made).
    pub header: Option<String>,
}

/// Something of a description that Mitsuba 3's XML cannot say faithfully.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct XmlWriteError {
    /// What (`shape 3`, `material 'floor'`, `the integrator`).
    pub item: String,
    /// Why not.
    pub reason: String,
}

impl core::fmt::Display for XmlWriteError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "cannot write as Mitsuba 3 XML: {}: {}",
            self.item, self.reason
        )
    }
}

impl std::error::Error for XmlWriteError {}

type Result<T> = core::result::Result<T, XmlWriteError>;

fn refuse<T>(item: impl Into<String>, reason: impl Into<String>) -> Result<T> {
    Err(XmlWriteError {
        item: item.into(),
        reason: reason.into(),
    })
}

/// The description as Mitsuba 3 XML.
pub fn to_mitsuba_xml(desc: &SceneDesc, options: &XmlWriteOptions) -> Result<String> {
    if desc.animation.is_some() {
        return refuse(
            "the scene",
            "it is animated; Mitsuba 3 XML describes one instant (render its frames here, or convert a copy without the animation section)",
        );
    }
    let mut w = Writer {
        out: String::new(),
        depth: 0,
        options,
    };
    w.line(r#"<?xml version="1.0" encoding="utf-8"?>"#);
    if let Some(h) = &options.header {
        // `--` may not appear inside an XML comment.
        w.line(&format!("<!-- {} -->", h.replace("--", "- -")));
    }
    w.open(r#"<scene version="3.0.0">"#);
    w.line(&format!(
        r#"<default name="spp" value="{}"/>"#,
        desc.spp.max(1)
    ));
    w.line(&format!(
        r#"<default name="resx" value="{}"/>"#,
        desc.film.width
    ));
    w.line(&format!(
        r#"<default name="resy" value="{}"/>"#,
        desc.film.height
    ));
    w.line(&format!(
        r#"<default name="max_depth" value="{}"/>"#,
        desc.integrator.max_depth
    ));
    w.blank();
    w.integrator(&desc.integrator)?;
    w.blank();
    w.sensor(desc)?;

    // Materials: Mitsuba has one id namespace, this format two (materials, shapes).
    let shape_ids: HashSet<&str> = desc.shapes.iter().filter_map(|s| s.id.as_deref()).collect();
    let material_id = |name: &str| {
        if shape_ids.contains(name) {
            format!("{name}-bsdf")
        } else {
            name.to_string()
        }
    };
    let names: HashSet<&str> = desc.materials.iter().map(|m| m.name.as_str()).collect();
    for m in &desc.materials {
        if names.contains(format!("{}-bsdf", m.name).as_str()) && shape_ids.contains(&*m.name) {
            return refuse(
                format!("material '{}'", m.name),
                format!(
                    "its name is also a shape's id and '{}-bsdf' is taken by another material",
                    m.name
                ),
            );
        }
        w.blank();
        let item = format!("material '{}'", m.name);
        literal(&item, "name", &m.name)?;
        w.bsdf(&m.material, Some(&material_id(&m.name)), None, &item)?;
    }
    for (i, s) in desc.shapes.iter().enumerate() {
        if i == 0 {
            w.blank();
        }
        w.shape(s, i, &names, &material_id)?;
    }
    for (i, l) in desc.lights.iter().enumerate() {
        if i == 0 {
            w.blank();
        }
        w.emitter(l)?;
    }
    w.close("</scene>");
    Ok(w.out)
}

/// The text being written, with its indentation.
struct Writer<'a> {
    out: String,
    depth: usize,
    options: &'a XmlWriteOptions,
}

/// A number as the shortest decimal that reads back as the same `f32`.
fn num(x: f32) -> String {
    format!("{x}")
}

fn nums(v: &[f32]) -> String {
    v.iter().map(|&x| num(x)).collect::<Vec<_>>().join(", ")
}

/// `s` escaped for an attribute value in double quotes.
fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            '\n' => o.push_str("&#10;"),
            '\t' => o.push_str("&#9;"),
            '\r' => o.push_str("&#13;"),
            c => o.push(c),
        }
    }
    o
}

/// Refuses a value that Mitsuba 3's XML reader (and this crate's) would not read back as written:
/// both substitute `$name` in every attribute from the `<default>` variables (this writer declares
/// `spp`, `resx`, `resy` and `max_depth`), and neither has an escape for a literal `$`, so a file
/// name `a$spp.ply` would load `a16.ply`.
fn literal(item: &str, what: &str, s: &str) -> Result<()> {
    if s.contains('$') {
        refuse(
            item,
            format!(
                "{what} \"{s}\" holds a '$', which Mitsuba 3 XML reads as a variable and cannot escape (rename it)"
            ),
        )
    } else {
        Ok(())
    }
}

/// Mitsuba's name of a field-of-view axis.
fn fov_axis_name(axis: FovAxis) -> &'static str {
    match axis {
        FovAxis::X => "x",
        FovAxis::Y => "y",
        FovAxis::Diagonal => "diagonal",
        FovAxis::Smaller => "smaller",
        FovAxis::Larger => "larger",
    }
}

fn finite(item: &str, what: &str, v: &[f32]) -> Result<()> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        refuse(item, format!("{what} {v:?} is not finite"))
    }
}

impl Writer<'_> {
    fn line(&mut self, s: &str) {
        for _ in 0..self.depth {
            self.out.push_str("    ");
        }
        self.out.push_str(s);
        self.out.push('\n');
    }

    fn blank(&mut self) {
        self.out.push('\n');
    }

    fn open(&mut self, s: &str) {
        self.line(s);
        self.depth += 1;
    }

    fn close(&mut self, s: &str) {
        self.depth -= 1;
        self.line(s);
    }

    fn float(&mut self, name: &str, v: f32) {
        self.line(&format!(r#"<float name="{name}" value="{}"/>"#, num(v)));
    }

    fn rgb(&mut self, name: &str, v: &V3) {
        self.line(&format!(r#"<rgb name="{name}" value="{}"/>"#, nums(v)));
    }

    fn string(&mut self, name: &str, v: &str) {
        self.line(&format!(r#"<string name="{name}" value="{}"/>"#, esc(v)));
    }

    fn boolean(&mut self, name: &str, v: bool) {
        self.line(&format!(r#"<boolean name="{name}" value="{v}"/>"#));
    }

    /// A file name as the XML must give it (see [`XmlWriteOptions::file_prefix`]), refused when
    /// it holds a `$` (see [`literal`]).
    fn file(&self, name: &str, item: &str) -> Result<String> {
        let f = match &self.options.file_prefix {
            Some(p) if Path::new(name).is_relative() && !p.as_os_str().is_empty() => {
                p.join(name).to_string_lossy().into_owned()
            }
            _ => name.to_string(),
        };
        literal(item, "file name", &f)?;
        Ok(f)
    }

    /// `<transform name=...>` with the steps in order (nothing when there are none).
    fn transform(&mut self, name: &str, ops: &[TransformOp], item: &str) -> Result<()> {
        if ops.is_empty() {
            return Ok(());
        }
        if let Err(e) = transform_matrix(ops) {
            return refuse(item, format!("{name}: {e}"));
        }
        self.open(&format!(r#"<transform name="{name}">"#));
        for op in ops {
            let xyz = |v: &V3| format!(r#"x="{}" y="{}" z="{}""#, num(v[0]), num(v[1]), num(v[2]));
            let s = match op {
                TransformOp::Translate(t) => format!("<translate {}/>", xyz(t)),
                TransformOp::Scale(s) => format!("<scale {}/>", xyz(s)),
                TransformOp::Rotate { axis, angle } => {
                    format!(r#"<rotate {} angle="{}"/>"#, xyz(axis), num(*angle))
                }
                TransformOp::LookAt { origin, target, up } => format!(
                    r#"<lookat origin="{}" target="{}" up="{}"/>"#,
                    nums(origin),
                    nums(target),
                    nums(up)
                ),
                TransformOp::Matrix(m) => format!(r#"<matrix value="{}"/>"#, nums(m)),
            };
            self.line(&s);
        }
        self.close("</transform>");
        Ok(())
    }

    fn integrator(&mut self, integ: &IntegratorDesc) -> Result<()> {
        // Mitsuba 3's own estimators: its path tracer and its particle tracer.
        let mitsuba_type = integ.kind.as_str();
        if !matches!(mitsuba_type, "path" | "ptracer") {
            return refuse(
                "the integrator",
                format!(
                    "'{}' is this renderer's own estimator; Mitsuba 3 has only its path tracer to \
                     stand for it (convert a copy whose integrator kind is \"path\"; every \
                     estimator here converges to the same image)",
                    integ.kind
                ),
            );
        }
        if let Some((name, _)) = integ.params.first() {
            return refuse(
                "the integrator",
                format!("the parameter '{name}' has no counterpart in Mitsuba 3's path tracer"),
            );
        }
        if let Some(name) = &integ.moment {
            literal("the integrator", "the moment channels' name", name)?;
            self.open(r#"<integrator type="moment">"#);
            self.open(&format!(
                r#"<integrator type="{mitsuba_type}" name="{}">"#,
                esc(name)
            ));
        } else {
            self.open(&format!(r#"<integrator type="{mitsuba_type}">"#));
        }
        self.line(r#"<integer name="max_depth" value="$max_depth"/>"#);
        self.line(&format!(
            r#"<integer name="rr_depth" value="{}"/>"#,
            integ.rr_depth
        ));
        if integ.hide_emitters {
            self.boolean("hide_emitters", true);
        }
        self.close("</integrator>");
        if integ.moment.is_some() {
            self.close("</integrator>");
        }
        Ok(())
    }

    fn sensor(&mut self, desc: &SceneDesc) -> Result<()> {
        let cam = &desc.camera;
        let item = "the camera";
        finite(item, "fov", &[cam.fov])?;
        finite(item, "lens", &[cam.aperture_radius, cam.focus_distance])?;
        let thin = cam.aperture_radius != 0.0 && !cam.orthographic;
        if cam.orthographic {
            self.open(r#"<sensor type="orthographic">"#);
            self.transform("to_world", &cam.to_world, item)?;
        } else {
            self.perspective_sensor(cam, thin, item)?;
        }
        // Clip planes other than Mitsuba's defaults.
        let clips = [
            ("near_clip", cam.near_clip, defaults::NEAR_CLIP),
            ("far_clip", cam.far_clip, defaults::FAR_CLIP),
        ];
        for (name, value, default) in clips {
            if value != default {
                finite(item, name, &[value])?;
                if value <= 0.0 {
                    return refuse(item, format!("{name} {value}: Mitsuba needs it positive"));
                }
                self.float(name, value);
            }
        }
        self.sensor_rest(desc)
    }

    /// A perspective or thin-lens `<sensor>`'s own properties.
    fn perspective_sensor(&mut self, cam: &CameraDesc, thin: bool, item: &str) -> Result<()> {
        self.open(&format!(
            r#"<sensor type="{}">"#,
            if thin { "thinlens" } else { "perspective" }
        ));
        self.float("fov", cam.fov);
        self.string("fov_axis", fov_axis_name(cam.fov_axis));
        if thin {
            self.float("aperture_radius", cam.aperture_radius);
            self.float("focus_distance", cam.focus_distance);
        }
        self.transform("to_world", &cam.to_world, item)
    }

    /// A `<sensor>`'s sampler and film.
    fn sensor_rest(&mut self, desc: &SceneDesc) -> Result<()> {
        self.open(match desc.integrator.sampler {
            SamplerKind::Independent => r#"<sampler type="independent">"#,
            SamplerKind::Sobol => r#"<sampler type="ldsampler">"#,
        });
        self.line(r#"<integer name="sample_count" value="$spp"/>"#);
        self.close("</sampler>");
        self.open(r#"<film type="hdrfilm">"#);
        self.line(r#"<integer name="width" value="$resx"/>"#);
        self.line(r#"<integer name="height" value="$resy"/>"#);
        if let Some(f) = &desc.film.filename {
            // Mitsuba 3's hdrfilm has no file name (it refuses one): this renderer's default
            // output name is kept for the reader, not part of the image.
            self.line(&format!("<!-- output file: {} -->", f.replace("--", "- -")));
        }
        match desc.film.filter {
            FilterDesc::Box => self.line(r#"<rfilter type="box"/>"#),
            FilterDesc::Tent { radius } => {
                finite("the film", "tent radius", &[radius])?;
                self.open(r#"<rfilter type="tent">"#);
                self.float("radius", radius);
                self.close("</rfilter>");
            }
            FilterDesc::Gaussian { stddev } => {
                finite("the film", "gaussian stddev", &[stddev])?;
                self.open(r#"<rfilter type="gaussian">"#);
                self.float("stddev", stddev);
                self.close("</rfilter>");
            }
        }
        self.close("</film>");
        self.close("</sensor>");
        Ok(())
    }
}

mod materials;
mod principled;
mod shapes;
