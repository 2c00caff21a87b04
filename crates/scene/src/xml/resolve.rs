//! Finding files as Mitsuba 3 does: `<path value="dir"/>` adds a search folder, `<include
//! filename="part.xml"/>` reads another file's elements in its place, and relative file names
//! (meshes, textures, environment maps, included files) are looked up through the search folders
//! (<https://mitsuba.readthedocs.io/en/latest/src/getting_started/file_format.html>).
//!
//! The order: the `<path>` folders, the one declared last first (Mitsuba prepends each to its
//! file resolver), then the folder of the file that names the file, then the scene file's folder.
//! A name found in none of them is left as written, relative to the scene file, so the error that
//! follows (a missing mesh or texture) names it as the scene wrote it.

use std::path::{Path, PathBuf};

use roxmltree::Node;

use super::source::Source;
use super::{Importer, Result, expect_scene_root, parse_document, read_defaults};
use crate::SceneError;
use crate::desc::SceneDesc;

/// How deep `<include>`s may nest (Mitsuba 3's limit): a file including itself stops here.
const MAX_INCLUDE_DEPTH: u32 = 15;

/// The folders relative file names are looked for in.
pub(super) struct SearchPath {
    /// `<path>` folders, the newest first.
    folders: Vec<PathBuf>,
    /// The scene file's folder (what the scene builder resolves relative names against).
    scene_dir: PathBuf,
}

impl SearchPath {
    /// The search path of the scene file `file`: its own folder only.
    pub(super) fn new(file: &Path) -> Self {
        Self {
            folders: Vec::new(),
            scene_dir: file.parent().map(Path::to_path_buf).unwrap_or_default(),
        }
    }

    /// Where `name` (named in `file`) is: the first folder holding it, or `None`.
    fn find(&self, name: &Path, file: &Path) -> Option<PathBuf> {
        let here = file.parent().unwrap_or(Path::new(""));
        self.folders
            .iter()
            .map(PathBuf::as_path)
            .chain([here, self.scene_dir.as_path()])
            .map(|dir| dir.join(name))
            .find(|p| p.exists())
    }
}

impl<'a> Importer<'a> {
    /// A file name written at `node`, resolved through the search path: unchanged when it is
    /// absolute or lies beside the scene file (or nowhere), otherwise the path where it was
    /// found, absolute, so that the scene builder (which resolves against the scene file's
    /// folder) reads the same file.
    pub(super) fn file_name(&self, node: Node, name: String) -> Result<String> {
        let p = Path::new(&name);
        if p.is_absolute() {
            return Ok(name);
        }
        match self.files.find(p, self.file) {
            Some(found) if found != self.files.scene_dir.join(p) => {
                let abs = std::path::absolute(&found).map_err(|e| {
                    self.err(node, format!("cannot resolve '{}': {e}", found.display()))
                })?;
                abs.into_os_string().into_string().map_err(|abs| {
                    self.err(
                        node,
                        format!("file name '{}' is not valid UTF-8", abs.display()),
                    )
                })
            }
            _ => Ok(name),
        }
    }

    /// Where the scene builder will look for a name [`Self::file_name`] returned.
    pub(super) fn scene_path(&self, name: &str) -> PathBuf {
        self.files.scene_dir.join(name)
    }

    /// `<path value="dir"/>`: a search folder, relative to the file that declares it.
    pub(super) fn path(&mut self, node: Node) -> Result<()> {
        for a in node.attributes() {
            if a.name() != "value" {
                return Err(self.err(
                    node,
                    format!("<path>: unknown attribute '{}' (only 'value')", a.name()),
                ));
            }
        }
        let value = self.req_attr(node, "value")?;
        let here = self.file.parent().unwrap_or(Path::new(""));
        let dir = here.join(&value);
        if !dir.is_dir() {
            return Err(self.err(
                node,
                format!(
                    "<path>: folder '{value}' not found (looked for {})",
                    dir.display()
                ),
            ));
        }
        self.files.folders.insert(0, dir);
        Ok(())
    }

    /// `<include filename="part.xml"/>`: the elements of another scene file, read in place with
    /// this file's ids, variables and search folders. Its `<default>`s apply where no including
    /// file or `-D` set the variable. Errors inside it name its file and line, and this line.
    pub(super) fn include(&mut self, node: Node, desc: &mut SceneDesc) -> Result<()> {
        for a in node.attributes() {
            if a.name() != "filename" {
                return Err(self.err(
                    node,
                    format!(
                        "<include>: unknown attribute '{}' (only 'filename')",
                        a.name()
                    ),
                ));
            }
        }
        let name = self.req_attr(node, "filename")?;
        if self.depth + 1 > MAX_INCLUDE_DEPTH {
            return Err(self.err(
                node,
                format!(
                    "<include filename=\"{name}\">: includes nest deeper than {MAX_INCLUDE_DEPTH} files (does a file include itself?)"
                ),
            ));
        }
        let path = Path::new(&name);
        let path = if path.is_absolute() {
            path.to_path_buf()
        } else {
            self.files.find(path, self.file).ok_or_else(|| {
                self.err(
                    node,
                    format!(
                        "<include>: file '{name}' not found (looked in the <path> folders, beside {} and beside the scene file)",
                        self.file.display()
                    ),
                )
            })?
        };
        let bytes = restir_image::input::read_regular(&path).map_err(|e| {
            self.err(
                node,
                format!("<include>: cannot read '{}': {e}", path.display()),
            )
        })?;
        let text = String::from_utf8(bytes).map_err(|_| {
            self.err(
                node,
                format!("<include>: '{}' is not valid UTF-8", path.display()),
            )
        })?;
        let at = self.loc(node);
        let context = |mut e: SceneError| {
            let note = format!(
                " (in the file included at {}:{})",
                at.file.display(),
                at.line
            );
            // A file that includes itself would repeat the same note at every level.
            if !e.message.ends_with(&note) {
                e.message.push_str(&note);
            }
            e
        };
        let doc = parse_document(&text, &path).map_err(context)?;
        let root = doc.root_element();
        let mut src = Source::new(&path, &text);
        expect_scene_root(&src, root).map_err(context)?;
        src.defaults = self.defaults.clone();
        for (k, v) in read_defaults(&src, root).map_err(context)? {
            src.defaults.entry(k.clone()).or_insert(v);
            self.declared.insert(k);
        }
        let mut nested = Importer {
            src: &src,
            bsdf_ids: std::mem::take(&mut self.bsdf_ids),
            bsdf_anon: self.bsdf_anon,
            textures: std::mem::take(&mut self.textures),
            files: std::mem::replace(&mut self.files, SearchPath::new(Path::new(""))),
            declared: std::mem::take(&mut self.declared),
            saw_sensor: self.saw_sensor,
            depth: self.depth + 1,
            groups: std::mem::take(&mut self.groups),
            instanced: self.instanced,
        };
        let result = nested.walk(root, desc);
        self.bsdf_ids = nested.bsdf_ids;
        self.bsdf_anon = nested.bsdf_anon;
        self.textures = nested.textures;
        self.files = nested.files;
        self.declared = nested.declared;
        self.saw_sensor = nested.saw_sensor;
        self.groups = nested.groups;
        self.instanced = nested.instanced;
        self.warnings.borrow_mut().extend(src.warnings.into_inner());
        result.map_err(context)
    }
}
