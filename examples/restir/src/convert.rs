//! `restir convert`: a scene (RON or XML) written as a Mitsuba 3 XML scene file, by
//! [`restir_scene::xml::to_mitsuba_xml`]; and the file-name plumbing that lets the XML live in
//! another directory than the scene (and its meshes, textures and environment maps).

use std::path::{Component, Path, PathBuf};

use restir_scene::SceneDesc;
use restir_scene::xml::{XmlWriteOptions, to_mitsuba_xml};

use crate::say::say;

/// Options of `restir convert`.
#[derive(clap::Args, Debug)]
pub struct ConvertArgs {
    /// Scene file (.ron or .xml).
    scene: PathBuf,
    /// Output XML file. File names inside (meshes, textures, environment maps) are rewritten
    /// relative to its directory.
    #[arg(short = 'o', long = "output")]
    output: PathBuf,
    /// Set a scene <default> variable (XML scenes).
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    defines: Vec<String>,
}

/// Runs `restir convert`.
pub fn run(args: ConvertArgs) -> Result<(), String> {
    let defines = crate::args::parse_defines(&args.defines)?;
    if args.output.extension().and_then(|e| e.to_str()) != Some("xml") {
        return Err(format!(
            "{}: the output must end in .xml",
            args.output.display()
        ));
    }
    if same_file(&args.scene, &args.output) {
        return Err(format!(
            "{}: the output would overwrite the scene",
            args.output.display()
        ));
    }
    // Everything the renderer would say about the scene is said here too: a scene that does
    // not load is not converted.
    let loaded = restir_scene::load_scene(
        &args.scene,
        &restir_scene::LoadOptions {
            defines,
            warn_no_lights: false,
            ..Default::default()
        },
    )
    .map_err(|e| e.to_string())?;
    for w in &loaded.warnings {
        crate::say::say_err!("{w}");
    }
    let header = format!(
        "Written by `restir convert {}` from the scene description; Mitsuba 3 and restir read it \
         to the same scene. -D resx=, resy=, spp=, max_depth= (Mitsuba: load_file(path, resx=...)) \
         change the film and the path depth.",
        args.scene.display()
    );
    write_xml(&loaded.desc, &args.scene, &args.output, header)?;
    say!("{} -> {}", args.scene.display(), args.output.display());
    Ok(())
}

/// Writes `desc`, read from `scene`, as Mitsuba 3 XML to `output` (creating its directory), with
/// file names rewritten for the output's directory.
pub fn write_xml(
    desc: &SceneDesc,
    scene: &Path,
    output: &Path,
    header: String,
) -> Result<(), String> {
    let out_dir = parent(output);
    std::fs::create_dir_all(&out_dir)
        .map_err(|e| format!("{}: cannot create directory: {e}", out_dir.display()))?;
    let options = XmlWriteOptions {
        file_prefix: file_prefix(&parent(scene), &out_dir),
        header: Some(header),
    };
    let text = to_mitsuba_xml(desc, &options).map_err(|e| format!("{}: {e}", scene.display()))?;
    restir_image::write_file_atomically(output, text.as_bytes()).map_err(|e| e.to_string())
}

/// The directory a file is in (`.` for a bare name).
fn parent(p: &Path) -> PathBuf {
    match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

fn same_file(a: &Path, b: &Path) -> bool {
    matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
}

/// How a file name relative to `scene_dir` is written in a file in `out_dir`: nothing when they
/// are one directory, else the relative path from `out_dir` to `scene_dir` (or `scene_dir`
/// absolute when they share nothing below the root).
fn file_prefix(scene_dir: &Path, out_dir: &Path) -> Option<PathBuf> {
    let (Ok(from), Ok(to)) = (out_dir.canonicalize(), scene_dir.canonicalize()) else {
        return Some(std::path::absolute(scene_dir).unwrap_or(scene_dir.to_path_buf()));
    };
    if from == to {
        return None;
    }
    let (f, t): (Vec<Component>, Vec<Component>) =
        (from.components().collect(), to.components().collect());
    let common = f.iter().zip(&t).take_while(|(a, b)| a == b).count();
    // Nothing in common but the root: the absolute path says more than a climb to the root.
    if common <= 1 {
        return Some(to);
    }
    let mut rel = PathBuf::new();
    for _ in common..f.len() {
        rel.push("..");
    }
    for c in &t[common..] {
        rel.push(c);
    }
    Some(rel)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prefixes_lead_from_the_output_to_the_scene() {
        let tmp = restir_testkit::TempDir::new("convert", "prefixes");
        let (a, b, c) = (tmp.join("a"), tmp.join("a/b"), tmp.join("c/d"));
        let root = std::path::Path::new("/");
        for d in [&a, &b, &c] {
            std::fs::create_dir_all(d).unwrap();
        }
        assert_eq!(file_prefix(&a, &a), None);
        assert_eq!(file_prefix(&a, &b), Some(PathBuf::from("..")));
        assert_eq!(file_prefix(&b, &a), Some(PathBuf::from("b")));
        assert_eq!(file_prefix(&c, &b), Some(PathBuf::from("../../c/d")));
        if cfg!(unix) {
            assert_eq!(file_prefix(&a, root), Some(a.canonicalize().unwrap()));
        }
    }
}
