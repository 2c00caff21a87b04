//! Opening input files defensively: only regular files (a FIFO would block forever, `/dev/zero`
//! would be read until memory runs out, a directory is no file), no bigger than
//! [`MAX_INPUT_BYTES`], and images no larger than [`MAX_IMAGE_SIDE`] / [`MAX_IMAGE_PIXELS`],
//! checked from the header before anything is allocated. The scene loader opens its scene, mesh
//! and image files through here too.

use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

/// The largest input file read: 2 GiB.
pub const MAX_INPUT_BYTES: u64 = 2 << 30;

/// The longest image side read, in pixels (the film's limit too).
pub const MAX_IMAGE_SIDE: usize = 32768;

/// The most pixels an image read may have: 2^28 (the film's limit too).
pub const MAX_IMAGE_PIXELS: usize = 1 << 28;

/// Opens `path` for reading if it is a regular file of at most [`MAX_INPUT_BYTES`]; otherwise an
/// `InvalidInput` error saying what it is. The type is checked before opening, since opening a
/// FIFO blocks until someone writes to it.
pub fn open_regular(path: &Path) -> io::Result<File> {
    let check = |meta: std::fs::Metadata| -> io::Result<()> {
        let ft = meta.file_type();
        if !ft.is_file() {
            let what = if ft.is_dir() {
                "a directory"
            } else {
                "not a regular file (a FIFO, socket or device)"
            };
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("it is {what}"),
            ));
        }
        if meta.len() > MAX_INPUT_BYTES {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "the file has {} bytes, more than the limit of {MAX_INPUT_BYTES}",
                    meta.len()
                ),
            ));
        }
        Ok(())
    };
    check(std::fs::metadata(path)?)?;
    let file = File::open(path)?;
    // The path may have been replaced between the two calls.
    check(file.metadata()?)?;
    Ok(file)
}

/// Reads the whole of a regular file ([`open_regular`]), never more than [`MAX_INPUT_BYTES`].
pub fn read_regular(path: &Path) -> io::Result<Vec<u8>> {
    let file = open_regular(path)?;
    let mut bytes = Vec::new();
    file.take(MAX_INPUT_BYTES).read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// Why an image of `width` × `height` pixels is too large to read, or `None`.
pub fn size_problem(width: usize, height: usize) -> Option<String> {
    (width > MAX_IMAGE_SIDE
        || height > MAX_IMAGE_SIDE
        || width.saturating_mul(height) > MAX_IMAGE_PIXELS)
        .then(|| {
            format!(
                "the image is {width}×{height} pixels, beyond the limit (each side at most \
                 {MAX_IMAGE_SIDE}, at most 2^28 pixels)"
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn special_files_are_refused() {
        let e = open_regular(Path::new("/dev/zero")).unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        let e = read_regular(Path::new("/")).unwrap_err();
        assert_eq!(e.to_string(), "it is a directory");
        assert!(open_regular(Path::new("/nonexistent/x")).is_err());
        let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
        assert!(read_regular(&manifest).unwrap().starts_with(b"[package]"));
    }

    #[test]
    fn sizes_beyond_the_limit_are_named() {
        assert!(size_problem(32768, 8192).is_none());
        assert!(size_problem(16384, 16384).is_none());
        assert_eq!(
            size_problem(65536, 65536).unwrap(),
            "the image is 65536×65536 pixels, beyond the limit (each side at most 32768, at most 2^28 pixels)"
        );
        assert!(size_problem(32768, 32768).is_some());
    }
}
