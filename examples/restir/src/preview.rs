//! The `--preview` of a frame sequence, written as the frames come so that its memory does not
//! grow with the number of frames: an animated PNG spools each frame as 8-bit sRGB to a
//! temporary file beside the preview and is encoded from it one frame at a time at the end; a
//! video streams each frame to `ffmpeg`'s standard input as it is rendered, while a thread
//! drains ffmpeg's standard error (kept up to [`STDERR_KEEP`] bytes) so that a chatty ffmpeg
//! cannot block on a full pipe. The frames are written by a thread of their own, so an ffmpeg
//! that stops reading its input (or does not exit once it has ended) cannot hang the render: a
//! frame not taken within [`stall_timeout`] (by the time the next one is ready, or at the end),
//! or an exit that does not come within it, stops ffmpeg and is an error naming it.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use restir_image::Image;

use crate::frames::Preview;

/// The most of ffmpeg's standard error kept for the message when it fails (the first bytes).
pub const STDERR_KEEP: usize = 16 << 10;

/// How long ffmpeg may take to read a frame (counted from when the next one is ready) or to exit
/// after its input ends: `RESTIR_FFMPEG_TIMEOUT` seconds, 120 unless set.
pub fn stall_timeout() -> Duration {
    std::env::var("RESTIR_FFMPEG_TIMEOUT")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0)
        .map_or(Duration::from_secs(120), Duration::from_secs_f64)
}

/// The frames as 8-bit sRGB bytes, row by row (what APNG and ffmpeg's `rgb24` take).
pub fn srgb_bytes(img: &Image) -> Vec<u8> {
    img.pixels
        .iter()
        .flat_map(|p| p.to_array().map(restir_image::srgb::encode_u8))
        .collect()
}

/// A running ffmpeg fed frame by frame.
struct Encoder {
    child: Child,
    /// Frames to the writing thread (which owns ffmpeg's standard input); `None` once closed.
    frames: Option<SyncSender<Vec<u8>>>,
    /// The writing thread's answer for each frame.
    written: Receiver<std::io::Result<()>>,
    /// A frame was handed over and not yet answered.
    pending: bool,
    writer: Option<JoinHandle<()>>,
    stderr: Option<JoinHandle<Vec<u8>>>,
    /// ffmpeg's output, renamed onto the preview once it succeeds.
    tmp: PathBuf,
    /// Why feeding it failed (it exited early), reported at the end with its message.
    failed: Option<std::io::Error>,
}

enum Sink {
    Apng {
        spool: PathBuf,
        file: Option<BufWriter<File>>,
    },
    Video {
        ffmpeg: PathBuf,
        format: &'static str,
        encoder: Option<Encoder>,
    },
}

/// The preview being written ([`PreviewWriter::push`] each frame, then
/// [`PreviewWriter::finish`]); dropped unfinished, it removes its temporary files and stops
/// ffmpeg.
pub struct PreviewWriter {
    path: PathBuf,
    fps: f32,
    size: Option<(u32, u32)>,
    frames: u32,
    sink: Sink,
}

impl std::fmt::Debug for PreviewWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "PreviewWriter({}, {} frames)",
            self.path.display(),
            self.frames
        )
    }
}

impl PreviewWriter {
    /// A writer of the preview `path` in the way `preview` says, at `fps`.
    pub fn new(path: &Path, preview: &Preview, fps: f32) -> Self {
        let sink = match preview {
            Preview::Apng => {
                let mut spool = restir_image::temp_path(path).into_os_string();
                spool.push(".frames");
                Sink::Apng {
                    spool: spool.into(),
                    file: None,
                }
            }
            Preview::Video { ffmpeg, format } => Sink::Video {
                ffmpeg: ffmpeg.clone(),
                format,
                encoder: None,
            },
        };
        Self {
            path: path.to_path_buf(),
            fps,
            size: None,
            frames: 0,
            sink,
        }
    }

    /// Adds a frame (every frame must have the first one's size).
    pub fn push(&mut self, img: &Image) -> Result<(), String> {
        let size = *self.size.get_or_insert((img.width, img.height));
        if size != (img.width, img.height) {
            return Err(format!(
                "{}: frame {} is {}×{}, the first was {}×{}: a preview needs one size",
                self.path.display(),
                self.frames,
                img.width,
                img.height,
                size.0,
                size.1
            ));
        }
        let bytes = srgb_bytes(img);
        let path = &self.path;
        match &mut self.sink {
            Sink::Apng { spool, file } => {
                let f = match file {
                    Some(f) => f,
                    None => file.insert(BufWriter::new(File::create(&*spool).map_err(|e| {
                        format!("{}: cannot create a file beside it: {e}", path.display())
                    })?)),
                };
                f.write_all(&bytes)
                    .map_err(|e| format!("{}: cannot write its frames: {e}", path.display()))?;
            }
            Sink::Video {
                ffmpeg,
                format,
                encoder,
            } => {
                let enc = match encoder {
                    Some(e) => e,
                    None => encoder.insert(start_ffmpeg(ffmpeg, format, path, size, self.fps)?),
                };
                enc.settle();
                if enc.failed.is_none()
                    && let Some(frames) = &enc.frames
                {
                    // The thread is idle (the last frame was answered): this does not block.
                    if frames.send(bytes).is_ok() {
                        enc.pending = true;
                    }
                }
            }
        }
        self.frames += 1;
        Ok(())
    }

    /// Writes the preview (nothing without frames) and removes the temporary files.
    pub fn finish(mut self) -> Result<(), String> {
        let (path, fps, frames) = (self.path.clone(), self.fps, self.frames);
        match &mut self.sink {
            Sink::Apng { spool, file } => {
                let Some(f) = file.take() else {
                    return Ok(());
                };
                f.into_inner().map_err(|e| {
                    format!("{}: cannot write its frames: {}", path.display(), e.error())
                })?;
                let (w, h) = self.size.unwrap_or_default();
                write_apng(&path, spool, (w, h), frames, fps)
            }
            Sink::Video {
                ffmpeg, encoder, ..
            } => {
                let Some(mut enc) = encoder.take() else {
                    return Ok(());
                };
                enc.settle();
                let status = enc.finish_input();
                let said = enc
                    .stderr
                    .take()
                    .and_then(|t| join_within(t, Instant::now() + Duration::from_secs(5)))
                    .unwrap_or_default();
                let fail = |what: String| {
                    format!("{}: ffmpeg ({}) {what}", path.display(), ffmpeg.display())
                };
                let status = status.map_err(|e| {
                    let _ = std::fs::remove_file(&enc.tmp);
                    fail(e.to_string())
                })?;
                if !status.success() || enc.failed.is_some() {
                    let _ = std::fs::remove_file(&enc.tmp);
                    let said = String::from_utf8_lossy(&said);
                    return Err(match &enc.failed {
                        Some(e) if e.kind() == std::io::ErrorKind::TimedOut => fail(e.to_string()),
                        _ => fail(format!("failed ({status}): {}", said.trim())),
                    });
                }
                std::fs::rename(&enc.tmp, &path).map_err(|e| {
                    let _ = std::fs::remove_file(&enc.tmp);
                    format!("{}: cannot write the preview: {e}", path.display())
                })
            }
        }
    }
}

impl Drop for PreviewWriter {
    fn drop(&mut self) {
        match &mut self.sink {
            Sink::Apng { spool, file } => {
                drop(file.take());
                let _ = std::fs::remove_file(&*spool);
            }
            Sink::Video { encoder, .. } => {
                if let Some(mut enc) = encoder.take() {
                    // Killed first: a writer blocked on a full pipe then fails and ends.
                    let _ = enc.child.kill();
                    drop(enc.frames.take());
                    let _ = enc.child.wait();
                    let _ = std::fs::remove_file(&enc.tmp);
                }
            }
        }
    }
}

/// The thread's result if it ends before `deadline`; otherwise it is left to end on its own.
fn join_within<T>(thread: JoinHandle<T>, deadline: Instant) -> Option<T> {
    while !thread.is_finished() {
        if Instant::now() > deadline {
            return None;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    thread.join().ok()
}

impl Encoder {
    /// Waits for the answer to the frame handed over last, up to [`stall_timeout`]; a failed
    /// write (ffmpeg exited) or no answer in time (ffmpeg stopped reading: then it is killed,
    /// which ends the blocked write) marks the encoder failed, reported by `finish`.
    fn settle(&mut self) {
        if !self.pending {
            return;
        }
        let timeout = stall_timeout();
        let failure = match self.written.recv_timeout(timeout) {
            Ok(Ok(())) => None,
            Ok(Err(e)) => Some(e),
            Err(RecvTimeoutError::Timeout) => {
                let _ = self.child.kill();
                Some(std::io::Error::new(
                    std::io::ErrorKind::TimedOut,
                    format!(
                        "stopped reading its input for {} s and was stopped (RESTIR_FFMPEG_TIMEOUT sets how long to wait)",
                        timeout.as_secs_f64()
                    ),
                ))
            }
            Err(RecvTimeoutError::Disconnected) => {
                Some(std::io::Error::other("the thread feeding it ended early"))
            }
        };
        self.pending = false;
        if let Some(e) = failure {
            self.failed.get_or_insert(e);
            self.frames = None;
        }
    }

    /// Ends ffmpeg's input and waits for it to exit, up to [`stall_timeout`] (then it is killed
    /// and the wait is an error).
    fn finish_input(&mut self) -> std::io::Result<std::process::ExitStatus> {
        drop(self.frames.take());
        let timeout = stall_timeout();
        let start = Instant::now();
        if let Some(w) = self.writer.take() {
            // Idle, or in a write that a killed ffmpeg ended; a process ffmpeg left behind may
            // still hold the pipe, so not waited for past the timeout.
            let _ = join_within(w, start + timeout);
        }
        loop {
            if let Some(status) = self.child.try_wait()? {
                return Ok(status);
            }
            if start.elapsed() > timeout {
                let _ = self.child.kill();
                let _ = self.child.wait();
                return Err(std::io::Error::new(
                    std::io::ErrorKind::TimedOut,
                    format!(
                        "did not exit within {} s of the end of its input and was stopped (RESTIR_FFMPEG_TIMEOUT sets how long to wait)",
                        timeout.as_secs_f64()
                    ),
                ));
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

/// Starts ffmpeg reading raw `rgb24` frames of `size` at `fps` from its standard input and
/// writing container `format` to a temporary file beside `path`; odd sizes are padded by a
/// pixel (H.264's 4:2:0 needs even ones).
fn start_ffmpeg(
    ffmpeg: &Path,
    format: &str,
    path: &Path,
    (w, h): (u32, u32),
    fps: f32,
) -> Result<Encoder, String> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(format!(".tmp-{}", std::process::id()));
    let tmp = PathBuf::from(tmp);
    let mut cmd = Command::new(ffmpeg);
    cmd.args(["-hide_banner", "-loglevel", "error", "-y"])
        .args(["-f", "rawvideo", "-pix_fmt", "rgb24"])
        .args(["-s", &format!("{w}x{h}")])
        .args(["-framerate", &fps.to_string(), "-i", "pipe:0"]);
    if format != "gif" {
        cmd.args([
            "-vf",
            "pad=ceil(iw/2)*2:ceil(ih/2)*2",
            "-pix_fmt",
            "yuv420p",
        ]);
    }
    cmd.args(["-f", format])
        .arg(&tmp)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    let mut child = cmd.spawn().map_err(|e| {
        format!(
            "{}: ffmpeg ({}) could not start: {e}",
            path.display(),
            ffmpeg.display()
        )
    })?;
    let (frames, feed) = std::sync::mpsc::sync_channel::<Vec<u8>>(1);
    let (answer, written) = std::sync::mpsc::channel();
    let writer = child.stdin.take().map(|mut stdin| {
        std::thread::spawn(move || {
            // Ends when the frames' sender is dropped, closing ffmpeg's input.
            for frame in feed {
                if answer.send(stdin.write_all(&frame)).is_err() {
                    break;
                }
            }
        })
    });
    let stderr = child.stderr.take().map(|mut err| {
        std::thread::spawn(move || {
            let mut kept = Vec::new();
            let mut buf = [0u8; 8192];
            while let Ok(n) = err.read(&mut buf) {
                if n == 0 {
                    break;
                }
                let room = STDERR_KEEP.saturating_sub(kept.len());
                kept.extend_from_slice(&buf[..n.min(room)]);
            }
            kept
        })
    });
    Ok(Encoder {
        child,
        frames: Some(frames),
        written,
        pending: false,
        writer,
        stderr,
        tmp,
        failed: None,
    })
}

/// Encodes the `frames` spooled `size` frames of `spool` as an animated PNG (8-bit sRGB,
/// looping) at `fps`, one frame in memory at a time, written atomically to `path`.
fn write_apng(
    path: &Path,
    spool: &Path,
    (w, h): (u32, u32),
    frames: u32,
    fps: f32,
) -> Result<(), String> {
    let fail =
        |e: png::EncodingError| format!("{}: cannot encode the preview: {e}", path.display());
    let frame_bytes = w as usize * h as usize * 3;
    let mut input = BufReader::new(
        File::open(spool)
            .map_err(|e| format!("{}: cannot read its frames: {e}", path.display()))?,
    );
    let mut error: Option<String> = None;
    let result = restir_image::write_atomically(
        path,
        |out| -> Result<(), ()> {
            let go = || -> Result<(), String> {
                let mut enc = png::Encoder::new(out, w, h);
                enc.set_color(png::ColorType::Rgb);
                enc.set_depth(png::BitDepth::Eight);
                enc.set_animated(frames, 0).map_err(fail)?;
                // The delay in seconds as a fraction: 100 / (100 fps).
                let den = (fps * 100.0).round().clamp(1.0, 65535.0) as u16;
                enc.set_frame_delay(100, den).map_err(fail)?;
                let mut writer = enc.write_header().map_err(fail)?;
                let mut frame = vec![0u8; frame_bytes];
                for _ in 0..frames {
                    input
                        .read_exact(&mut frame)
                        .map_err(|e| format!("{}: cannot read its frames: {e}", path.display()))?;
                    writer.write_image_data(&frame).map_err(fail)?;
                }
                writer.finish().map_err(fail)
            };
            go().map_err(|e| error = Some(e))
        },
        |()| restir_image::ImageError::Io {
            path: path.to_path_buf(),
            what: "cannot write",
            source: std::io::Error::other("encoding failed"),
        },
    );
    match (result, error) {
        (_, Some(e)) => Err(e),
        (Err(e), None) => Err(e.to_string()),
        (Ok(()), None) => Ok(()),
    }
}
