//! [`ImageError`]: why an image file could not be read or written, naming the file.

use std::path::PathBuf;

/// Why an image file could not be read or written. The message names the file.
#[derive(Debug)]
#[non_exhaustive]
pub enum ImageError {
    /// [`Image::read_exr`](crate::Image::read_exr) failed.
    ReadExr {
        /// The file.
        path: PathBuf,
        /// The EXR decoder's error.
        source: exr::error::Error,
    },
    /// [`Image::read`](crate::Image::read) failed.
    Read {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        reason: ReadFailure,
    },
    /// Writing an EXR file failed.
    WriteExr {
        /// The file.
        path: PathBuf,
        /// The EXR encoder's error.
        source: exr::error::Error,
    },
    /// Writing a PNG file failed.
    WritePng {
        /// The file.
        path: PathBuf,
        /// The PNG encoder's error.
        source: image::ImageError,
    },
    /// The file name's extension is neither `.exr` nor `.png`.
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// Channels beside RGB ([`crate::Channel`]) were to be written to a format without them
    /// (PNG holds 8-bit RGB only).
    ChannelsNeedExr {
        /// The file.
        path: PathBuf,
    },
    /// Creating, writing, flushing, syncing or renaming an output file failed.
    Io {
        /// The target file.
        path: PathBuf,
        /// What could not be done ("cannot write", "cannot create a file beside it", …).
        what: &'static str,
        /// The system's error.
        source: std::io::Error,
    },
}

/// What went wrong in [`Image::read`](crate::Image::read).
#[derive(Debug)]
#[non_exhaustive]
pub enum ReadFailure {
    /// The file could not be opened or its format guessed.
    Io(std::io::Error),
    /// The EXR decoder failed.
    Exr(exr::error::Error),
    /// The PNG/JPEG/BMP/HDR decoder failed.
    Decode(image::ImageError),
    /// The image has no pixels, or fewer than its size says.
    Empty,
    /// A pixel has a NaN or infinite channel.
    NonFinite,
}

impl core::fmt::Display for ReadFailure {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ReadFailure::Io(e) => write!(f, "{e}"),
            ReadFailure::Exr(e) => write!(f, "{e}"),
            ReadFailure::Decode(e) => write!(f, "{e}"),
            ReadFailure::Empty => f.write_str("empty or inconsistent image"),
            ReadFailure::NonFinite => f.write_str("non-finite texel values"),
        }
    }
}

impl std::error::Error for ReadFailure {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ReadFailure::Io(e) => Some(e),
            ReadFailure::Exr(e) => Some(e),
            ReadFailure::Decode(e) => Some(e),
            ReadFailure::Empty | ReadFailure::NonFinite => None,
        }
    }
}

impl ImageError {
    /// The file the error is about.
    pub fn path(&self) -> &std::path::Path {
        match self {
            ImageError::ReadExr { path, .. }
            | ImageError::Read { path, .. }
            | ImageError::WriteExr { path, .. }
            | ImageError::WritePng { path, .. }
            | ImageError::UnknownFormat { path }
            | ImageError::ChannelsNeedExr { path }
            | ImageError::Io { path, .. } => path,
        }
    }
}

impl core::fmt::Display for ImageError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ImageError::ReadExr { path, source } => {
                write!(f, "{}: cannot read EXR: {source}", path.display())
            }
            ImageError::Read { path, reason } => {
                write!(f, "cannot read image '{}': {reason}", path.display())
            }
            ImageError::WriteExr { path, source } => {
                write!(f, "{}: cannot write EXR: {source}", path.display())
            }
            ImageError::WritePng { path, source } => {
                write!(f, "{}: cannot write PNG: {source}", path.display())
            }
            ImageError::UnknownFormat { path } => write!(
                f,
                "{}: unknown image format: use a .exr or .png file name",
                path.display()
            ),
            ImageError::ChannelsNeedExr { path } => write!(
                f,
                "{}: channels beside RGB need an EXR file (a .exr file name)",
                path.display()
            ),
            ImageError::Io { path, what, source } => {
                write!(f, "{}: {what}: {source}", path.display())
            }
        }
    }
}

impl std::error::Error for ImageError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ImageError::ReadExr { source, .. } | ImageError::WriteExr { source, .. } => {
                Some(source)
            }
            ImageError::Read { reason, .. } => Some(reason),
            ImageError::WritePng { source, .. } => Some(source),
            ImageError::Io { source, .. } => Some(source),
            ImageError::UnknownFormat { .. } | ImageError::ChannelsNeedExr { .. } => None,
        }
    }
}
