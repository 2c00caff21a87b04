//! The errors of a benchmark run ([`BenchError`]): a bad suite, a scene that does not load, an
//! integrator configuration that does not build, a file that cannot be read or written. Each
//! names the file or the configuration it is about.

use std::path::PathBuf;

use restir_integrators::ImageError;
use restir_scene::SceneError;

use crate::suite::SuiteError;

/// Why a benchmark run, or writing its outputs, failed.
#[derive(Debug)]
pub enum BenchError {
    /// The suite breaks a rule.
    Suite(SuiteError),
    /// A scene of the suite does not load.
    Scene(SceneError),
    /// An integrator configuration does not build for a scene.
    Integrator {
        /// The configuration's label.
        label: String,
        /// What is wrong.
        message: String,
    },
    /// A file or directory cannot be read, written or created.
    Io {
        /// The file or directory.
        path: PathBuf,
        /// What was being done, as a message prefix (`"cannot read scene: "`), possibly empty.
        doing: &'static str,
        /// The system's error.
        source: std::io::Error,
    },
    /// An image cannot be read or written.
    Image(ImageError),
    /// A plot cannot be drawn.
    Plot {
        /// The SVG file.
        path: PathBuf,
        /// The plotting library's message.
        message: String,
    },
    /// A scene's crop rectangle does not fit in its image.
    Crop {
        /// The scene file, as given in the suite.
        scene: PathBuf,
        /// The rectangle `(x, y, width, height)`.
        rect: (u32, u32, u32, u32),
        /// The image size.
        size: (u32, u32),
    },
    /// A given reference image is not the size the scene renders.
    ReferenceSize {
        /// The reference file.
        path: PathBuf,
        /// Its size.
        reference: (u32, u32),
        /// The scene's.
        scene: (u32, u32),
    },
    /// A render and the reference differ in size.
    ReferenceMismatch,
    /// The HTML page cannot be made.
    Page(crate::report::html::PageError),
    /// A scene given `frames` in the suite has no animation (no `animation` section, no XML
    /// sidecar).
    NoAnimation(PathBuf),
    /// A scene's renders would need more memory than the limit (`--max-memory`).
    Memory {
        /// The scene's name.
        scene: String,
        /// Its image size.
        size: (u32, u32),
        /// The estimate per pixel, in bytes.
        bytes_per_pixel: u64,
        /// The limit, in GiB.
        max_gib: f64,
    },
    /// An error about one entry of the suite file, at its line.
    At {
        /// The suite file.
        file: PathBuf,
        /// The 1-based line of the entry.
        line: usize,
        /// The error.
        source: Box<BenchError>,
    },
    /// A Markdown document lacks a results marker.
    Marker {
        /// The document.
        doc: PathBuf,
        /// Which marker is missing: `true` for the begin marker.
        begin: bool,
        /// The missing marker's text.
        marker: &'static str,
    },
}

impl BenchError {
    /// The same error, at `line` of the suite file when both are known.
    pub(crate) fn at(self, file: Option<&PathBuf>, line: Option<usize>) -> Self {
        match (file, line) {
            (Some(file), Some(line)) => Self::At {
                file: file.clone(),
                line,
                source: Box::new(self),
            },
            _ => self,
        }
    }

    /// An I/O error on `path` while `doing` (a message prefix such as `"cannot read: "`).
    pub(crate) fn io(
        path: impl Into<PathBuf>,
        doing: &'static str,
    ) -> impl FnOnce(std::io::Error) -> Self {
        let path = path.into();
        move |source| Self::Io {
            path,
            doing,
            source,
        }
    }
}

impl std::fmt::Display for BenchError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Suite(e) => e.fmt(f),
            Self::Scene(e) => e.fmt(f),
            Self::Integrator { label, message } => write!(f, "integrator '{label}': {message}"),
            Self::Io {
                path,
                doing,
                source,
            } => write!(f, "{}: {doing}{source}", path.display()),
            Self::Image(e) => e.fmt(f),
            Self::Plot { path, message } => {
                write!(f, "{}: cannot draw plot: {message}", path.display())
            }
            Self::Crop {
                scene,
                rect: (x, y, w, h),
                size: (width, height),
            } => write!(
                f,
                "{}: crop ({x}, {y}, {w}, {h}) does not fit in {width}×{height}",
                scene.display()
            ),
            Self::ReferenceSize {
                path,
                reference: (rw, rh),
                scene: (w, h),
            } => write!(
                f,
                "{}: reference is {rw}×{rh} but the scene renders {w}×{h}",
                path.display()
            ),
            Self::ReferenceMismatch => f.write_str("reference size mismatch"),
            Self::NoAnimation(path) => write!(
                f,
                "{}: the suite gives `frames` but the scene has no animation (an `animation` \
                 section, or NAME.anim.ron beside NAME.xml)",
                path.display()
            ),
            Self::Page(e) => e.fmt(f),
            Self::Memory {
                scene,
                size: (w, h),
                bytes_per_pixel,
                max_gib,
            } => {
                let gib = (*w as u64 * *h as u64).saturating_mul(*bytes_per_pixel) as f64
                    / (1u64 << 30) as f64;
                write!(
                    f,
                    "scene '{scene}': its {w}×{h} renders need about {gib:.1} GiB \
                     ({bytes_per_pixel} bytes per pixel: film, estimator buffers, reference and \
                     kept images), more than the limit of {max_gib} GiB: render smaller or raise \
                     --max-memory"
                )
            }
            Self::At { file, line, source } => write!(f, "{}:{line}: {source}", file.display()),
            Self::Marker {
                doc,
                begin: true,
                marker,
            } => write!(
                f,
                "{}: no '{marker}' marker: add the markers where the results belong",
                doc.display()
            ),
            Self::Marker {
                doc,
                begin: false,
                marker,
            } => write!(f, "{}: no '{marker}' after the begin marker", doc.display()),
        }
    }
}

impl std::error::Error for BenchError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Suite(e) => Some(e),
            Self::Scene(e) => Some(e),
            Self::Io { source, .. } => Some(source),
            Self::Image(e) => Some(e),
            Self::Page(e) => Some(e),
            Self::At { source, .. } => Some(source.as_ref()),
            _ => None,
        }
    }
}

impl From<SuiteError> for BenchError {
    fn from(e: SuiteError) -> Self {
        Self::Suite(e)
    }
}

impl From<SceneError> for BenchError {
    fn from(e: SceneError) -> Self {
        Self::Scene(e)
    }
}

impl From<crate::report::html::PageError> for BenchError {
    fn from(e: crate::report::html::PageError) -> Self {
        Self::Page(e)
    }
}

impl From<ImageError> for BenchError {
    fn from(e: ImageError) -> Self {
        Self::Image(e)
    }
}
