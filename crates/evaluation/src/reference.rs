//! The reference of a scene or of a sequence's frame: given, cached, or path-traced as two halves
//! whose difference estimates the reference's own noise (see the crate documentation).

use std::borrow::Cow;
use std::path::PathBuf;
use std::time::Instant;

use restir_image::{Image, compare};
use restir_integrators::RenderJob;
use restir_scene::Scene;

use crate::error::BenchError;
use crate::load::{LoadedSuiteScene, build_integrator, render_once};
use crate::records::{ReferenceInfo, RunOptions};
use crate::suite::{IntegratorConfig, Suite, SuiteScene};

/// Seeds of the two reference halves; benchmark runs use seeds `0..seeds`.
pub const REFERENCE_SEEDS: [u64; 2] = [0x5eed_0000_0000_0001, 0x5eed_0000_0000_0002];

/// Stable 64-bit FNV-1a hash of byte strings, each followed by a separator (for cache keys that
/// must not change between Rust versions).
pub use restir_sampling::hash::fnv1a_chunks as fnv1a;

/// The references of a scene's views, in order: a still scene's image kept in memory, a
/// sequence's frames read back from their cached EXR files one at a time (the files are written
/// as 32-bit floats, so they read back exactly), so that memory does not grow with the frames.
pub(crate) struct References {
    /// A still scene's reference.
    pub(crate) still: Option<Image>,
    /// A sequence's reference files, one per frame.
    pub(crate) frames: Vec<PathBuf>,
}

impl References {
    /// The reference of view `i`.
    pub(crate) fn get(&self, i: usize) -> Result<Cow<'_, Image>, BenchError> {
        match &self.still {
            Some(image) => Ok(Cow::Borrowed(image)),
            None => Ok(Cow::Owned(Image::read_exr(&self.frames[i])?)),
        }
    }
}

/// Loads, or renders and caches, the reference of one scene (`frame = None`) or of one frame of
/// a sequence (`scene` the frame's).
pub(crate) fn reference_for(
    entry: &SuiteScene,
    loaded: &LoadedSuiteScene,
    (frame, scene): (Option<u32>, &Scene),
    suite: &Suite,
    opts: &RunOptions,
) -> Result<(Image, ReferenceInfo), BenchError> {
    let (w, h) = scene.camera.resolution();
    if let Some(given) = &entry.reference {
        let path = opts.suite_dir.join(given);
        let image = Image::read_exr(&path)?;
        if (image.width, image.height) != (w, h) {
            return Err(BenchError::ReferenceSize {
                path,
                reference: (image.width, image.height),
                scene: (w, h),
            });
        }
        return Ok((
            image,
            ReferenceInfo {
                scene: loaded.name.clone(),
                path,
                spp: None,
                noise_relmse: None,
                reused: true,
                seconds: 0.0,
            },
        ));
    }
    let spp = entry.reference_spp.unwrap_or(suite.reference_spp);
    let depth = entry
        .max_depth
        .map_or("scene".to_string(), |d| d.to_string());
    // A frame's key adds its number and the frame rate (which decide its time); a still
    // scene's is what it always was, so cached references stay valid.
    let frame_key = frame.map_or(String::new(), |f| format!(" frame={f} fps={}", loaded.fps));
    let key = fnv1a(&[
        &loaded.file_bytes,
        format!("{w}x{h} max_depth={depth} spp={spp} path-halves-v1{frame_key}").as_bytes(),
    ]);
    let dir = opts.out.join("references");
    let stem = match frame {
        Some(f) => format!("{}-{f:04}-{key:016x}", loaded.name),
        None => format!("{}-{key:016x}", loaded.name),
    };
    let exr = dir.join(format!("{stem}.exr"));
    let noise_file = dir.join(format!("{stem}.noise"));
    // A cached reference needs its EXR (of the right size) and its noise estimate.
    let cached = || -> Option<(Image, f64)> {
        let noise = std::fs::read_to_string(&noise_file)
            .ok()?
            .trim()
            .parse::<f64>()
            .ok()?;
        let image = Image::read_exr(&exr).ok()?;
        ((image.width, image.height) == (w, h)).then_some((image, noise))
    };
    if let Some((image, noise)) = cached() {
        return Ok((
            image,
            ReferenceInfo {
                scene: loaded.name.clone(),
                path: exr,
                spp: Some(spp),
                noise_relmse: Some(noise),
                reused: true,
                seconds: 0.0,
            },
        ));
    }
    std::fs::create_dir_all(&dir).map_err(BenchError::io(&dir, "cannot create directory: "))?;
    let path_config = IntegratorConfig {
        label: "reference".into(),
        integrator: "path".into(),
        params: Vec::new(),
    };
    let integrator = build_integrator(loaded, &path_config, entry)?;
    let start = Instant::now();
    let halves: Vec<Image> = REFERENCE_SEEDS
        .iter()
        .map(|&seed| {
            let job = RenderJob {
                spp: spp / 2,
                seed,
                ..RenderJob::default()
            };
            render_once(scene, integrator.as_ref(), &job).image
        })
        .collect();
    let seconds = start.elapsed().as_secs_f64();
    let mut image = Image::new(w, h);
    for (i, p) in image.pixels.iter_mut().enumerate() {
        *p = 0.5 * (halves[0].pixels[i] + halves[1].pixels[i]);
    }
    let noise = compare(&halves[0], &halves[1]).map_or(f64::NAN, |m| m.relmse / 4.0);
    image.write(&exr)?;
    std::fs::write(&noise_file, format!("{noise:e}\n")).map_err(BenchError::io(&noise_file, ""))?;
    Ok((
        image,
        ReferenceInfo {
            scene: loaded.name.clone(),
            path: exr,
            spp: Some(spp),
            noise_relmse: Some(noise),
            reused: false,
            seconds,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv_is_stable_and_chunked() {
        assert_eq!(fnv1a(&[]), 0xcbf2_9ce4_8422_2325);
        assert_ne!(fnv1a(&[b"ab", b"c"]), fnv1a(&[b"a", b"bc"]));
        assert_eq!(fnv1a(&[b"scene"]), fnv1a(&[b"scene"]));
    }
}
