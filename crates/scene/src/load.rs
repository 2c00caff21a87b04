//! Loading a scene file: reading and parsing it (RON or Mitsuba-style XML), applying the
//! caller's overrides ([`LoadOptions`]: `-D` defines, film size), building the runtime
//! [`Scene`] and collecting what the loader noticed. [`load_scene`] is the one way the command
//! line, the evaluation and the tests turn a path into a scene.

use std::path::{Path, PathBuf};

use crate::{Location, Scene, SceneDesc, SceneError, SceneWarning, animation, xml};

/// What a caller may change about a scene file while loading it. The film size is here and not
/// in a render job because the camera's projection is built for it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// XML `<default>` values, `(name, value)` (`-D name=value` on the command line); an error
    /// for RON files, which have none.
    pub defines: Vec<(String, String)>,
    /// Film width in pixels, overriding the scene's.
    pub width: Option<u32>,
    /// Film height in pixels, overriding the scene's.
    pub height: Option<u32>,
    /// Whether a scene without light sources adds a warning (default: yes).
    pub warn_no_lights: bool,
    /// The most memory, in bytes, the scene's images, meshes and light tables may need
    /// (`--max-memory`), checked before each is decoded, built or made; `None` (the default):
    /// unbounded.
    pub max_memory: Option<u64>,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            defines: Vec::new(),
            width: None,
            height: None,
            warn_no_lights: true,
            max_memory: None,
        }
    }
}

/// A loaded scene and what the loader noticed.
#[derive(Debug)]
pub struct LoadedScene {
    /// The built scene.
    pub scene: Scene,
    /// Warnings (ignored properties, fallbacks), each with `file:line`.
    pub warnings: Vec<SceneWarning>,
    /// The description it was built from (with the overrides applied).
    pub desc: SceneDesc,
}

/// Parses the project's RON scene format, an `animation` section included (its tracks'
/// shape ids resolved to shape indices; an unknown id is an error).
pub fn parse_ron(text: &str, file: &Path) -> Result<SceneDesc, SceneError> {
    let mut desc = ron::Options::default()
        .from_str::<SceneDesc>(text)
        .map_err(|e| {
            SceneError::new(
                Location {
                    file: file.to_path_buf(),
                    line: e.span.start.line as u32,
                },
                e.code.to_string(),
            )
        })?;
    if let Some(mut anim) = desc.animation.take() {
        anim.location.file = file.to_path_buf();
        let from = animation::section_start(text);
        animation::attach(&mut desc, anim, text, from)?;
    }
    Ok(desc)
}

/// Where an XML scene's animation is looked for: `<name>.anim.ron` beside `<name>.xml`.
pub fn sidecar_path(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scene");
    scene.with_file_name(format!("{stem}.anim.ron"))
}

/// Reads a scene description from a `.ron` or `.xml` file (with its animation: a RON scene's
/// `animation` section, or an XML scene's sidecar, [`sidecar_path`]). `defines` set XML `<default>` values
/// (`-D name=value` on the command line); they are an error for RON files, which have none.
pub fn load_desc(
    path: &Path,
    defines: &[(String, String)],
) -> Result<(SceneDesc, Vec<SceneWarning>), SceneError> {
    let whole = |msg: String| {
        SceneError::new(
            Location {
                file: path.to_path_buf(),
                line: 0,
            },
            msg,
        )
    };
    let bytes = restir_image::input::read_regular(path)
        .map_err(|e| whole(format!("cannot read scene: {e}")))?;
    let text = String::from_utf8(bytes)
        .map_err(|_| whole("cannot read scene: stream did not contain valid UTF-8".into()))?;
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("ron") => {
            if let Some((name, _)) = defines.first() {
                return Err(whole(format!(
                    "-D {name}=…: RON scenes have no <default> variables to set"
                )));
            }
            Ok((parse_ron(&text, path)?, Vec::new()))
        }
        Some("xml") => {
            let (mut desc, warnings) = xml::parse_xml(&text, path, defines)?;
            let sidecar = sidecar_path(path);
            if sidecar.is_file() {
                animation::load_animation(&mut desc, &sidecar)?;
            }
            Ok((desc, warnings))
        }
        _ => Err(whole(
            "unknown scene format: expected a .ron or .xml file".into(),
        )),
    }
}

/// Loads a scene file with `options` applied and builds it. Relative paths inside the scene
/// (meshes, textures) are resolved against the file's directory; errors name the file.
pub fn load_scene(path: &Path, options: &LoadOptions) -> Result<LoadedScene, SceneError> {
    let (mut desc, mut warnings) = load_desc(path, &options.defines)?;
    if let Some(w) = options.width {
        desc.film.width = w;
    }
    if let Some(h) = options.height {
        desc.film.height = h;
    }
    if desc.integrator.location.file.as_os_str().is_empty() {
        // RON scenes carry no line numbers; errors in their parameters still name the file.
        desc.integrator.location.file = path.to_path_buf();
    }
    let base: PathBuf = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let (scene, noted) = Scene::build_within(&desc, &base, path, options.max_memory)?;
    warnings.extend(noted);
    if options.warn_no_lights && scene.lights.is_empty() {
        warnings.push(SceneWarning {
            location: Location {
                file: path.to_path_buf(),
                line: 0,
            },
            message: "the scene has no light sources (no emitter with positive radiance): the image will be black".into(),
        });
    }
    Ok(LoadedScene {
        scene,
        warnings,
        desc,
    })
}
