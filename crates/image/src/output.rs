//! Writing output files so that no reader ever sees half of one, and so that pointing an output
//! anywhere does what a shell redirection would. What a path names decides how it is written
//! ([`destination`]):
//!
//! - a regular file, or nothing yet: the file goes to a temporary file beside it ([`temp_path`]),
//!   is flushed and synced, and is renamed onto the target in one step. A failure anywhere
//!   (creating, writing, flushing, syncing, renaming: a full disk, a file-size limit, a vanished
//!   directory) is an error naming the target; the temporary file is removed and an existing
//!   target is left as it was;
//! - a symbolic link: followed, and its final target written as above (the link stays a link);
//! - `-`, `/dev/stdout`, `/dev/stderr`: the process's own stream, written directly;
//! - a character device or a FIFO (`/dev/null`, a named pipe): opened and written directly, never
//!   replaced;
//! - anything else (a directory, a block device, a socket, a path ending in `/`): an error.
//!
//! [`check_writable`] tries the same steps before a long render starts, and
//! [`same_destination`] tells two outputs (or an output and an input) that are one file.

use std::fs::File;
use std::io::{BufWriter, Cursor, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use crate::ImageError;

/// Where an output path's bytes go ([`destination`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Destination {
    /// A regular file (or none yet) at this path, symbolic links resolved: replaced through a
    /// temporary file beside it.
    Replace(PathBuf),
    /// The process's standard output (`-`, `/dev/stdout`).
    Stdout,
    /// The process's standard error (`/dev/stderr`).
    Stderr,
    /// A character device or FIFO: opened for writing and written in place.
    Direct(PathBuf),
}

/// Symbolic links followed before giving up (Linux's limit).
const MAX_LINKS: usize = 40;

fn io_error(path: &Path, what: &'static str, source: std::io::Error) -> ImageError {
    ImageError::Io {
        path: path.to_path_buf(),
        what,
        source,
    }
}

fn refused(path: &Path, why: &str) -> ImageError {
    io_error(
        path,
        "cannot write",
        std::io::Error::new(std::io::ErrorKind::InvalidInput, why.to_string()),
    )
}

/// Whether the path, as written, ends in a separator (`out.exr/`): it names a directory.
fn ends_in_separator(path: &Path) -> bool {
    let s = path.as_os_str().as_encoded_bytes();
    s.len() > 1 && (s.ends_with(b"/") || s.ends_with(b"/.") || s.ends_with(b"/.."))
}

/// Follows symbolic links from `path` by hand while their targets do not exist (a dangling link
/// names the file to create); the path of the last link's target.
fn follow_dangling(path: &Path) -> std::io::Result<PathBuf> {
    let mut at = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match std::fs::symlink_metadata(&at) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = std::fs::read_link(&at)?;
                at = match at.parent() {
                    Some(dir) if to.is_relative() => dir.join(to),
                    _ => to,
                };
            }
            _ => return Ok(at),
        }
    }
    Err(std::io::Error::other("too many levels of symbolic links"))
}

/// Where writing `path` sends the bytes, or why it cannot be written (a directory, a block
/// device, a socket, a path ending in `/`, a loop of links). Nothing is created or opened.
pub fn destination(path: &Path) -> Result<Destination, ImageError> {
    match path.as_os_str().to_str() {
        Some("-") | Some("/dev/stdout") => return Ok(Destination::Stdout),
        Some("/dev/stderr") => return Ok(Destination::Stderr),
        _ => {}
    }
    if ends_in_separator(path) {
        return Err(refused(path, "the name ends in '/': it names a directory"));
    }
    // `metadata` follows links as the kernel does (magic links under /proc included).
    let meta = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            let target = follow_dangling(path).map_err(|e| io_error(path, "cannot write", e))?;
            return Ok(Destination::Replace(target));
        }
        Err(e) => return Err(io_error(path, "cannot write", e)),
    };
    let ft = meta.file_type();
    if ft.is_file() {
        let is_link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
        let target = if is_link {
            std::fs::canonicalize(path).map_err(|e| io_error(path, "cannot follow the link", e))?
        } else {
            path.to_path_buf()
        };
        return Ok(Destination::Replace(target));
    }
    if ft.is_dir() {
        return Err(refused(path, "it is a directory"));
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if ft.is_char_device() || ft.is_fifo() {
            return Ok(Destination::Direct(path.to_path_buf()));
        }
        if ft.is_block_device() {
            return Err(refused(
                path,
                "it is a block device (a disk): only regular files, character devices and FIFOs are written",
            ));
        }
    }
    Err(refused(
        path,
        "it is not a regular file, character device or FIFO (a socket?)",
    ))
}

/// Whether outputs (or an output and an input) `a` and `b` are the same file: the same path once
/// links are followed, or the same existing file (device and inode), or the same stream.
pub fn same_destination(a: &Path, b: &Path) -> bool {
    let (Ok(da), Ok(db)) = (destination(a), destination(b)) else {
        return false;
    };
    match (&da, &db) {
        (Destination::Stdout, Destination::Stdout) | (Destination::Stderr, Destination::Stderr) => {
            return true;
        }
        (Destination::Replace(x), Destination::Replace(y)) if x == y => return true,
        _ => {}
    }
    let file = |d: &Destination, p: &Path| match d {
        Destination::Replace(t) => Some(t.clone()),
        Destination::Direct(_) => Some(p.to_path_buf()),
        _ => None,
    };
    let (Some(x), Some(y)) = (file(&da, a), file(&db, b)) else {
        return false;
    };
    // Different spellings of one existing file; a file not yet there is the same as another
    // only if the directories and names agree.
    #[cfg(unix)]
    if let (Ok(mx), Ok(my)) = (std::fs::metadata(&x), std::fs::metadata(&y)) {
        use std::os::unix::fs::MetadataExt;
        return (mx.dev(), mx.ino()) == (my.dev(), my.ino());
    }
    let canon = |p: &Path| -> Option<PathBuf> {
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Some(std::fs::canonicalize(dir).ok()?.join(p.file_name()?))
    };
    matches!((canon(&x), canon(&y)), (Some(x), Some(y)) if x == y)
}

/// The longest file name part kept in a temporary name; longer names are cut and a hash of the
/// whole name added, so that a name of up to 255 bytes (the usual limit) still has a temporary.
const TEMP_NAME_KEEP: usize = 180;

/// The temporary file [`write_atomically`] writes before renaming it onto `path` (links
/// followed): a hidden name beside it, unique per process (`dir/.name.PID.tmp`, the name cut to
/// fit a 255-byte limit), so it is on the same file system and the rename is atomic.
pub fn temp_path(path: &Path) -> PathBuf {
    let target = match destination(path) {
        Ok(Destination::Replace(t)) => t,
        _ => path.to_path_buf(),
    };
    let name = target
        .file_name()
        .map(|n| n.as_encoded_bytes().to_vec())
        .unwrap_or_default();
    let short = if name.len() > TEMP_NAME_KEEP {
        let hash = name.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
        });
        // Cut at a character boundary so the name stays valid where names must be UTF-8.
        let text = String::from_utf8_lossy(&name);
        let mut cut = TEMP_NAME_KEEP;
        while !text.is_char_boundary(cut) {
            cut -= 1;
        }
        format!("{}~{:08x}", &text[..cut], hash as u32)
    } else {
        String::from_utf8_lossy(&name).into_owned()
    };
    target.with_file_name(format!(".{short}.{}.tmp", std::process::id()))
}

/// What [`write_atomically`]'s writer fills: the temporary file (buffered), or bytes in memory
/// for a stream, device or FIFO (written in one go afterwards). It can seek, as EXR encoders
/// need.
#[derive(Debug)]
pub struct OutputWriter(Sink);

#[derive(Debug)]
enum Sink {
    File(BufWriter<File>),
    Memory(Cursor<Vec<u8>>),
}

impl Write for OutputWriter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match &mut self.0 {
            Sink::File(f) => f.write(buf),
            Sink::Memory(m) => m.write(buf),
        }
    }
    fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.0 {
            Sink::File(f) => f.flush(),
            Sink::Memory(m) => m.flush(),
        }
    }
}

impl Seek for OutputWriter {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        match &mut self.0 {
            Sink::File(f) => f.seek(pos),
            Sink::Memory(m) => m.seek(pos),
        }
    }
}

/// Checks, before anything is rendered, that `path` can be written: [`destination`] accepts it;
/// for a file, its directory exists and a temporary file can be created there (and is removed
/// again); a device is opened for writing (a FIFO is not opened: that would wait for a reader).
/// The format (extension) is [`Image::check_output`](crate::Image::check_output)'s business.
pub fn check_writable(path: &Path) -> Result<(), ImageError> {
    match destination(path)? {
        Destination::Replace(_) => {
            let temp = temp_path(path);
            File::create(&temp).map_err(|e| io_error(path, "cannot create a file beside it", e))?;
            std::fs::remove_file(&temp)
                .map_err(|e| io_error(path, "cannot remove a test file beside it", e))
        }
        Destination::Direct(p) => {
            #[cfg(unix)]
            {
                use std::os::unix::fs::FileTypeExt;
                if std::fs::metadata(&p).is_ok_and(|m| m.file_type().is_fifo()) {
                    return Ok(());
                }
            }
            std::fs::OpenOptions::new()
                .write(true)
                .open(&p)
                .map(drop)
                .map_err(|e| io_error(path, "cannot open it for writing", e))
        }
        Destination::Stdout | Destination::Stderr => Ok(()),
    }
}

/// Writes `path` as [`destination`] says: for a file, `write` fills a buffered writer on a
/// temporary file, which is flushed, synced and renamed onto the target; on any error the
/// temporary file is removed and the target is untouched. For a stream, device or FIFO, `write`
/// fills memory and the bytes are then written directly (flush errors included).
pub fn write_atomically<E>(
    path: &Path,
    write: impl FnOnce(&mut OutputWriter) -> Result<(), E>,
    encoder_error: impl FnOnce(E) -> ImageError,
) -> Result<(), ImageError> {
    let target = match destination(path)? {
        Destination::Replace(t) => t,
        direct => {
            let mut w = OutputWriter(Sink::Memory(Cursor::new(Vec::new())));
            write(&mut w).map_err(encoder_error)?;
            let Sink::Memory(bytes) = w.0 else {
                unreachable!("a memory sink stays one")
            };
            let bytes = bytes.into_inner();
            let written = match direct {
                Destination::Stdout => {
                    let mut out = std::io::stdout().lock();
                    out.write_all(&bytes).and_then(|()| out.flush())
                }
                Destination::Stderr => {
                    let mut out = std::io::stderr().lock();
                    out.write_all(&bytes).and_then(|()| out.flush())
                }
                Destination::Direct(p) => std::fs::OpenOptions::new()
                    .write(true)
                    .open(&p)
                    .and_then(|mut f| f.write_all(&bytes).and_then(|()| f.flush())),
                Destination::Replace(_) => unreachable!("handled above"),
            };
            return written.map_err(|e| io_error(path, "cannot write", e));
        }
    };
    let temp = temp_path(&target);
    let result = (|| {
        let file =
            File::create(&temp).map_err(|e| io_error(path, "cannot create a file beside it", e))?;
        let mut w = OutputWriter(Sink::File(BufWriter::new(file)));
        write(&mut w).map_err(encoder_error)?;
        let Sink::File(w) = w.0 else {
            unreachable!("a file sink stays one")
        };
        let file = w
            .into_inner()
            .map_err(|e| io_error(path, "cannot write", e.into_error()))?;
        file.sync_all()
            .map_err(|e| io_error(path, "cannot write", e))?;
        drop(file);
        std::fs::rename(&temp, &target).map_err(|e| io_error(path, "cannot replace it", e))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
    result
}

/// Writes `bytes` to `path` as [`write_atomically`] (for text outputs beside the images:
/// statistics, reports).
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

    fn temp_dir(tag: &str) -> restir_testkit::TempDir {
        restir_testkit::TempDir::new("image-out", tag)
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
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
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
        // Written directly, the device's error is the output's error.
        let e = write_file_atomically(path, b"x").unwrap_err().to_string();
        assert!(e.starts_with("/dev/full: cannot write: "), "{e}");
    }

    #[test]
    fn writability_is_checked_before_rendering() {
        let dir = temp_dir("check");
        check_writable(&dir.join("ok.exr")).unwrap();
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
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
        // A trailing separator names a directory: refused before anything is written.
        let slash = PathBuf::from(format!("{}/out.exr/", dir.display()));
        let e = check_writable(&slash).unwrap_err().to_string();
        assert!(e.ends_with("ends in '/': it names a directory"), "{e}");
    }

    /// A device is written in place, never replaced by a regular file (as root the rename
    /// would succeed and replace the system's /dev/null).
    #[cfg(unix)]
    #[test]
    fn a_device_is_written_in_place() {
        use std::os::unix::fs::FileTypeExt;
        // As root a private null device (a faulty writer could replace the system's).
        let dir = temp_dir("device");
        let private = dir.join("null");
        let made = std::process::Command::new("mknod")
            .arg(&private)
            .args(["c", "1", "3"])
            .stderr(std::process::Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        let null = if made {
            private.as_path()
        } else {
            Path::new("/dev/null")
        };
        assert_eq!(destination(null).unwrap(), Destination::Direct(null.into()));
        check_writable(null).unwrap();
        write_file_atomically(null, b"{}\n").unwrap();
        assert!(
            std::fs::metadata(null)
                .unwrap()
                .file_type()
                .is_char_device()
        );
        for stdout in ["-", "/dev/stdout"] {
            assert_eq!(destination(Path::new(stdout)).unwrap(), Destination::Stdout);
        }
    }

    /// A FIFO is opened and written (a reader gets the bytes) and stays a FIFO; the check
    /// before rendering does not open it (which would wait for a reader).
    #[cfg(unix)]
    #[test]
    fn a_fifo_is_written_in_place() {
        use std::io::Read;
        use std::os::unix::fs::FileTypeExt;
        let dir = temp_dir("fifo");
        let fifo = dir.join("pipe.json");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if !made.is_ok_and(|s| s.success()) {
            eprintln!("mkfifo unavailable: skipped");
            return;
        }
        check_writable(&fifo).unwrap();
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || {
                let mut s = String::new();
                File::open(&fifo).unwrap().read_to_string(&mut s).unwrap();
                s
            })
        };
        write_file_atomically(&fifo, b"through the pipe").unwrap();
        assert_eq!(reader.join().unwrap(), "through the pipe");
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "no temporary left"
        );
    }

    /// A link is followed: its target is replaced and the link stays a link; a dangling link
    /// creates its target.
    #[cfg(unix)]
    #[test]
    fn a_link_is_followed() {
        let dir = temp_dir("link");
        std::fs::create_dir_all(dir.join("real")).unwrap();
        let target = dir.join("real/image.exr");
        std::fs::write(&target, b"old").unwrap();
        let link = dir.join("link.exr");
        std::os::unix::fs::symlink("real/image.exr", &link).unwrap();
        check_writable(&link).unwrap();
        write_file_atomically(&link, b"new").unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        assert!(same_destination(&link, &target));
        let dangling = dir.join("dangling.exr");
        std::os::unix::fs::symlink("real/later.exr", &dangling).unwrap();
        write_file_atomically(&dangling, b"created").unwrap();
        assert_eq!(
            std::fs::read(dir.join("real/later.exr")).unwrap(),
            b"created"
        );
        assert!(
            std::fs::symlink_metadata(&dangling)
                .unwrap()
                .file_type()
                .is_symlink()
        );
    }

    /// A socket (or anything that is neither a file, a character device nor a FIFO) is an
    /// error before anything is written.
    #[cfg(unix)]
    #[test]
    fn a_socket_is_refused() {
        let dir = temp_dir("socket");
        let sock = dir.join("s.exr");
        let _listener = std::os::unix::net::UnixListener::bind(&sock).unwrap();
        let e = check_writable(&sock).unwrap_err().to_string();
        assert!(
            e.contains("not a regular file, character device or FIFO"),
            "{e}"
        );
        assert!(write_file_atomically(&sock, b"x").is_err());
    }

    /// A valid name of 250 bytes has a temporary name within the 255-byte limit.
    #[test]
    fn a_long_name_can_be_written() {
        let dir = temp_dir("long");
        let name = format!("{}.json", "n".repeat(245));
        assert_eq!(name.len(), 250);
        let path = dir.join(&name);
        check_writable(&path).unwrap();
        write_file_atomically(&path, b"long").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"long");
        let temp = temp_path(&path);
        assert!(temp.file_name().unwrap().len() <= 255);
    }

    /// Two spellings of one file are one destination; different files are not.
    #[test]
    fn one_file_two_spellings() {
        let dir = temp_dir("same");
        let a = dir.join("a.exr");
        assert!(
            same_destination(&a, &dir.join("./a.exr")),
            "before it exists"
        );
        std::fs::write(&a, b"x").unwrap();
        assert!(same_destination(&a, &dir.join(".").join("a.exr")));
        assert!(!same_destination(&a, &dir.join("b.exr")));
        assert!(same_destination(Path::new("-"), Path::new("/dev/stdout")));
    }
}
