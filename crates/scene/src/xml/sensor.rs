//! `<sensor>` with its `<film>` (and `<rfilter>`) and `<sampler>`: the camera, the image and
//! the sample count.

use roxmltree::Node;

use super::props::{PROPERTY_TAGS, Props};
use super::{Importer, Result, elements};
use crate::desc::*;

impl<'a> Importer<'a> {
    pub(super) fn sensor<'i>(&self, node: Node<'a, 'i>, desc: &mut SceneDesc) -> Result<()> {
        let ty = self.plugin_type(node)?;
        const SENSORS: &[&str] = &["perspective", "thinlens", "orthographic"];
        if !SENSORS.contains(&ty.as_str()) {
            return Err(self.unknown_type(node, "sensor", &ty, SENSORS));
        }
        let props = self.props(node, format!("sensor '{ty}'"))?;
        let mut cam = if ty == "orthographic" {
            // No field of view: `to_world`'s scale sets the extent.
            CameraDesc {
                orthographic: true,
                ..CameraDesc::default()
            }
        } else {
            let (fov, fov_axis) = self.field_of_view(node, &props, &format!("sensor '{ty}'"))?;
            CameraDesc {
                fov,
                fov_axis,
                ..CameraDesc::default()
            }
        };
        cam.to_world = props.transform("to_world")?;
        if ty == "perspective" {
            // Mitsuba 3's principal point offset (a fraction of the film) is read so that its
            // default, 0, passes quietly; any other value would move the image: an error.
            for name in ["principal_point_offset_x", "principal_point_offset_y"] {
                if let Some(v) = props.float(name)?
                    && v != 0.0
                {
                    return Err(self.err(
                        props.node_or(name, node),
                        format!(
                            "sensor 'perspective': {name} {v} is not supported (only 0, its default)"
                        ),
                    ));
                }
            }
        }
        // Mitsuba 3's clip planes (every sensor here is one of its projective cameras), with
        // its defaults and its rule that 0 < near_clip < far_clip.
        let near = props.float("near_clip")?;
        let far = props.float("far_clip")?;
        let (n, f) = (
            near.unwrap_or(defaults::NEAR_CLIP),
            far.unwrap_or(defaults::FAR_CLIP),
        );
        if !(n > 0.0 && n < f && f.is_finite()) {
            let at = if near.is_some() {
                props.node_or("near_clip", node)
            } else {
                props.node_or("far_clip", node)
            };
            return Err(self.err(
                at,
                format!(
                    "sensor '{ty}': near_clip {n} and far_clip {f} must satisfy 0 < near_clip < far_clip (defaults {} and {})",
                    defaults::NEAR_CLIP,
                    defaults::FAR_CLIP
                ),
            ));
        }
        (cam.near_clip, cam.far_clip) = (n, f);
        if ty != "thinlens" {
            // Mitsuba 3's perspective and orthographic sensors read a focus distance, which
            // they do not use: read, so it passes quietly.
            props.float("focus_distance")?;
        }
        if ty == "thinlens" {
            cam.aperture_radius = props
                .float("aperture_radius")?
                .unwrap_or(defaults::APERTURE_RADIUS);
            cam.focus_distance = props
                .float("focus_distance")?
                .unwrap_or(defaults::FOCUS_DISTANCE);
        }
        for c in elements(node) {
            match c.tag_name().name() {
                "film" => self.film(c, &mut desc.film)?,
                "sampler" => {
                    let sty = self.plugin_type(c)?;
                    // Mitsuba's samplers (0.6 and 3): `independent` is honoured, the
                    // stratified and low-discrepancy ones are rendered with Owen-scrambled Sobol.
                    const SAMPLERS: &[&str] = &[
                        "independent",
                        "stratified",
                        "multijitter",
                        "orthogonal",
                        "ldsampler",
                        "halton",
                        "hammersley",
                        "sobol",
                    ];
                    if !SAMPLERS.contains(&sty.as_str()) {
                        return Err(self.unknown_type(c, "sampler", &sty, SAMPLERS));
                    }
                    let sp = self.props(c, format!("sampler '{sty}'"))?;
                    if let Some(n) = sp.int("sample_count")? {
                        if !(1..=1 << 24).contains(&n) {
                            return Err(self.err(c, format!("sample_count {n} is out of range")));
                        }
                        desc.spp = n as u32;
                    }
                    desc.integrator.sampler = if sty == "independent" {
                        crate::SamplerKind::Independent
                    } else {
                        crate::SamplerKind::Sobol
                    };
                    sp.finish();
                }
                t if PROPERTY_TAGS.contains(&t) => {}
                t => return Err(self.err(c, format!("unexpected <{t}> inside a sensor"))),
            }
        }
        // Everything the builder would reject about the camera, reported with the sensor's line.
        if let Err(e) = crate::desc::transform_matrix(&cam.to_world)
            .map_err(|e| e.to_string())
            .and_then(|m| {
                let axis = restir_geometry::FovAxis::X;
                let res = (desc.film.width, desc.film.height);
                restir_geometry::Camera::thin_lens(
                    m,
                    cam.fov,
                    axis,
                    res,
                    cam.aperture_radius,
                    cam.focus_distance,
                )
                .map(|_| ())
                .map_err(|e| e.to_string())
            })
        {
            let lens = if ty == "thinlens" {
                format!(
                    " (aperture_radius {}, focus_distance {})",
                    cam.aperture_radius, cam.focus_distance
                )
            } else {
                String::new()
            };
            return Err(self.err(node, format!("sensor '{ty}': camera: {e}{lens}")));
        }
        props.finish();
        desc.camera = cam;
        Ok(())
    }

    /// The field of view and the axis it spans, as Mitsuba 3's perspective sensors read them
    /// (<https://mitsuba.readthedocs.io/en/latest/src/generated/plugins_sensors.html#perspective-pinhole-camera-perspective>):
    /// `fov` along `fov_axis` (default `x`), or else `focal_length` (default `50mm`) on a
    /// 36 × 24 mm film, which fixes the diagonal field of view (`fov_axis` is then not read).
    /// Giving both is an error. `what` names the plugin in messages (`sensor 'perspective'`);
    /// Mitsuba's `projector` emitter reads its field of view the same way.
    pub(super) fn field_of_view(
        &self,
        node: Node,
        props: &Props,
        what: &str,
    ) -> Result<(f32, FovAxis)> {
        let fov_given = props.node_or("fov", node) != node;
        let focal_given = props.node_or("focal_length", node) != node;
        if fov_given && focal_given {
            return Err(self.err(
                props.node_or("focal_length", node),
                format!("{what}: give either 'fov' or 'focal_length', not both"),
            ));
        }
        // Checked even where it is unused (without `fov`, where a warning says so).
        let axis = match props.string("fov_axis")?.as_deref() {
            None | Some("x") => FovAxis::X,
            Some("y") => FovAxis::Y,
            Some("diagonal") => FovAxis::Diagonal,
            Some("smaller") => FovAxis::Smaller,
            Some("larger") => FovAxis::Larger,
            Some(other) => {
                return Err(self.err(
                    props.node_or("fov_axis", node),
                    format!(
                        "{what}: unknown fov_axis '{other}' (known: x, y, diagonal, smaller, larger)"
                    ),
                ));
            }
        };
        if !fov_given {
            if props.node_or("fov_axis", node) != node {
                self.warn(
                    props.node_or("fov_axis", node),
                    format!("{what}: fov_axis has no effect without 'fov' (the focal length fixes the diagonal field of view)"),
                );
            }
            let written = props
                .string("focal_length")?
                .unwrap_or_else(|| defaults::FOCAL_LENGTH.to_string());
            let number = written.strip_suffix("mm").unwrap_or(&written);
            let mm = number
                .trim()
                .parse::<f32>()
                .ok()
                .filter(|f| f.is_finite() && *f > 0.0)
                .ok_or_else(|| {
                    self.err(
                        props.node_or("focal_length", node),
                        format!(
                            "{what}: focal_length \"{written}\" must be a positive length in millimetres, such as \"50mm\""
                        ),
                    )
                })?;
            return Ok((defaults::fov_of_focal_length(mm), FovAxis::Diagonal));
        }
        let fov = props.float("fov")?.unwrap_or(defaults::FOV);
        if !(fov > 0.0 && fov < 180.0) {
            let at = props.node_or("fov", node);
            return Err(self.err(
                at,
                format!("{what}: fov {fov} must lie in (0, 180) degrees"),
            ));
        }
        Ok((fov, axis))
    }

    fn film<'i>(&self, node: Node<'a, 'i>, film: &mut FilmDesc) -> Result<()> {
        let ty = self.plugin_type(node)?;
        // Mitsuba 3's hdrfilm and specfilm, Mitsuba 0.6's ldrfilm and tiledhdrfilm: all give an
        // image; the output format comes from the output file name.
        const FILMS: &[&str] = &["hdrfilm", "ldrfilm", "tiledhdrfilm", "specfilm"];
        if !FILMS.contains(&ty.as_str()) {
            return Err(self.unknown_type(node, "film", &ty, FILMS));
        }
        let props = self.props(node, format!("film '{ty}'"))?;
        let dim = |what: &str, d: u32| -> Result<u32> {
            match props.int(what)? {
                None => Ok(d),
                Some(n) if (1..=32768).contains(&n) => Ok(n as u32),
                Some(n) => Err(self.err(
                    props.node_or(what, node),
                    format!("film {what} {n} is out of range (1..=32768)"),
                )),
            }
        };
        film.width = dim("width", defaults::FILM_WIDTH)?;
        film.height = dim("height", defaults::FILM_HEIGHT)?;
        if film.width as u64 * film.height as u64 > 1 << 28 {
            return Err(self.err(
                node,
                format!(
                    "film resolution {}×{} has too many pixels (at most 2^28)",
                    film.width, film.height
                ),
            ));
        }
        film.filename = props.string("filename")?;
        // The output's channels and their type come from the output file's name; what an EXR
        // holds here (R, G, B in 32-bit floats) passes quietly.
        for (name, quiet) in [
            ("pixel_format", &["rgb"][..]),
            ("component_format", &["float32", "float16"][..]),
        ] {
            if let Some(v) = props.string(name)?
                && !quiet.contains(&v.as_str())
            {
                self.warn(
                    props.node_or(name, node),
                    format!(
                        "film '{ty}': {name} '{v}' is not what is written (EXR files hold R, G, B as 32-bit floats)"
                    ),
                );
            }
        }
        film.filter = FilterDesc::default();
        for c in elements(node) {
            match c.tag_name().name() {
                "rfilter" => {
                    let fty = self.plugin_type(c)?;
                    let fp = self.props(c, format!("rfilter '{fty}'"))?;
                    film.filter = match fty.as_str() {
                        "box" => {
                            // Mitsuba 3's box is one pixel; Lajolla's `width` and Mitsuba 0.6's
                            // `radius` may say so, a wider box is not supported.
                            let named = fp.node_or("width", fp.node_or("radius", c));
                            if let Some(w) =
                                fp.float("width")?.or(fp.float("radius")?.map(|r| 2.0 * r))
                                && (w - 1.0).abs() > 1e-6
                            {
                                return Err(self.err(
                                    named,
                                    format!(
                                        "rfilter 'box': a width of {w} pixels is not supported (only 1, Mitsuba 3's box; a wider filter: 'tent' or 'gaussian')"
                                    ),
                                ));
                            }
                            FilterDesc::Box
                        }
                        "tent" => {
                            let r = fp
                                .float("radius")?
                                .or(fp.float("width")?.map(|w| 0.5 * w))
                                .unwrap_or(defaults::TENT_RADIUS);
                            if r <= 0.0 {
                                return Err(self.err(c, "tent radius must be positive"));
                            }
                            if let Some(p) = limits::filter_width_problem(r) {
                                return Err(self.err(c, format!("tent radius {p}")));
                            }
                            FilterDesc::Tent { radius: r }
                        }
                        "gaussian" => {
                            let s = fp.float("stddev")?.unwrap_or(defaults::GAUSSIAN_STDDEV);
                            if s <= 0.0 {
                                return Err(self.err(c, "gaussian stddev must be positive"));
                            }
                            if let Some(p) = limits::filter_width_problem(s) {
                                return Err(self.err(c, format!("gaussian stddev {p}")));
                            }
                            FilterDesc::Gaussian { stddev: s }
                        }
                        other => {
                            return Err(self.unknown_type(
                                c,
                                "rfilter",
                                other,
                                &["box", "tent", "gaussian"],
                            ));
                        }
                    };
                    fp.finish();
                }
                t if PROPERTY_TAGS.contains(&t) => {}
                t => return Err(self.err(c, format!("unexpected <{t}> inside a film"))),
            }
        }
        props.finish();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    /// Mitsuba 3's `principal_point_offset_x`/`_y` at their default, 0, load without a
    /// warning; any other value is an error naming the line.
    #[test]
    fn principal_point_offsets_other_than_zero_are_errors() {
        let load = |body: &str| {
            let xml = format!("<scene>\n<sensor type=\"perspective\">\n{body}\n</sensor></scene>");
            crate::xml::parse_xml(&xml, "t.xml".as_ref(), &[])
                .map(|(_, w)| w.len())
                .map_err(|e| e.to_string())
        };
        let zero = r#"<float name="principal_point_offset_x" value="0.000000"/><float name="principal_point_offset_y" value="-0.000000"/>"#;
        assert_eq!(load(zero), Ok(0));
        let e = load(r#"<float name="principal_point_offset_y" value="0.1"/>"#).unwrap_err();
        assert!(
            e.starts_with("t.xml:3") && e.contains("principal_point_offset_y 0.1"),
            "{e}"
        );
    }
}
