//! Writing output files so that no reader ever sees half of one: every file goes to a temporary
//! file beside its target ([`temp_path`]), is flushed and synced, and is then renamed onto the
//! target in one step. A failure anywhere (creating, writing, flushing, syncing, renaming: a full
//! disk, a file-size limit, a vanished directory) is an error naming the target, the temporary
//! file is removed and an existing target is left as it was. [`check_writable`] tries the same
//! steps before a long render starts.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::ImageError;

/// The temporary file [`write_atomically`] writes before renaming it onto `path`: a hidden name
/// beside it, unique per process (`dir/.name.PID.tmp`), so it is on the same file system and
/// the rename is atomic.
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

fn io_error(path: &Path, what: &'static str, source: std::io::Error) -> ImageError {
    ImageError::Io {
        path: path.to_path_buf(),
        what,
        source,
    }
}

/// Checks, before anything is rendered, that `path` can be written: it is not a directory, its
/// directory exists, and a temporary file can be created there (the file is removed again).
/// The format (extension) is [`Image::check_output`](crate::Image::check_output)'s business.
pub fn check_writable(path: &Path) -> Result<(), ImageError> {
    if path.is_dir() {
        return Err(io_error(
            path,
            "cannot write",
            std::io::Error::new(std::io::ErrorKind::IsADirectory, "it is a directory"),
        ));
    }
    let temp = temp_path(path);
    File::create(&temp).map_err(|e| io_error(path, "cannot create a file beside it", e))?;
    std::fs::remove_file(&temp)
        .map_err(|e| io_error(path, "cannot remove a test file beside it", e))
}

/// Writes `path` through a temporary file: `write` fills a buffered writer on the temporary
/// file; the buffer is flushed, the file synced and renamed onto `path`. On any error the
/// temporary file is removed and `path` is untouched.
pub fn write_atomically<E>(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), E>,
    encoder_error: impl FnOnce(E) -> ImageError,
) -> Result<(), ImageError> {
    let temp = temp_path(path);
    let result = (|| {
        let file =
            File::create(&temp).map_err(|e| io_error(path, "cannot create a file beside it", e))?;
        let mut w = BufWriter::new(file);
        write(&mut w).map_err(encoder_error)?;
        let file = w
            .into_inner()
            .map_err(|e| io_error(path, "cannot write", e.into_error()))?;
        file.sync_all()
            .map_err(|e| io_error(path, "cannot write", e))?;
        drop(file);
        std::fs::rename(&temp, path).map_err(|e| io_error(path, "cannot replace it", e))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
    result
}

/// Writes `bytes` to `path` through a temporary file, as [`write_atomically`] (for text outputs
/// beside the images: statistics, reports).
pub fn write_file_atomically(path: &Path, bytes: &[u8]) -> Result<(), ImageError> {
    write_atomically(
        path,
        |w| w.write_all(bytes),
        |e| io_error(path, "cannot write", e),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(tag: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("restir-image-out-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// A failing write leaves the old file and no temporary file; a good one replaces it.
    #[test]
    fn a_failed_write_keeps_the_old_file() {
        let dir = temp_dir("keep");
        let path = dir.join("a.txt");
        write_file_atomically(&path, b"old").unwrap();
        let e = write_atomically(
            &path,
            |w| {
                w.write_all(b"half")?;
                Err(std::io::Error::other("disk on fire"))
            },
            |e| io_error(&path, "cannot write", e),
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("{}: cannot write: disk on fire", path.display())
        );
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert!(!temp_path(&path).exists());
        write_file_atomically(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).ok();
    }

    /// /dev/full accepts the file but fails every write: the error surfaces at the flush that
    /// `BufWriter` would otherwise drop.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_full_device_is_an_error_at_flush() {
        let path = Path::new("/dev/full");
        let mut w = BufWriter::new(std::fs::OpenOptions::new().write(true).open(path).unwrap());
        w.write_all(b"small enough to stay in the buffer").unwrap();
        assert!(w.into_inner().is_err(), "the flush error must surface");
    }

    #[test]
    fn writability_is_checked_before_rendering() {
        let dir = temp_dir("check");
        check_writable(&dir.join("ok.exr")).unwrap();
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            0,
            "the probe is removed"
        );
        let e = check_writable(&dir).unwrap_err().to_string();
        assert!(e.ends_with("cannot write: it is a directory"), "{e}");
        let e = check_writable(&dir.join("missing/ok.exr"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("missing/ok.exr: cannot create a file beside it: "),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
