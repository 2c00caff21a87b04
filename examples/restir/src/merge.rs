//! `restir merge OUT IN...`: puts the parts of a split render (`--chain`, `--crop`, see
//! [`crate::cluster`]) back together. Parts must come from one render (same scene, estimator
//! settings, seed, pass count and film); parts with the same window are chains, combined
//! pass-weighted (`Σ nᵢ·meanᵢ / Σ nᵢ` in f64), and their passes must be `0..spp` exactly once;
//! the windows must cover the film exactly once. The result is written as a plain render.
//!
//! Parts are read as every input is: regular files only, their sizes checked from the header
//! (and the film against `--max-memory`) before pixels are allocated. Everything is checked from
//! the headers first; then the pixels of one part at a time are added into the film, so memory
//! is the film's and one part's, whatever the number of parts.

use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::DVec3;
use restir_image::Image;
use restir_integrators::PixelWindow;

use crate::cluster::attr;
use crate::say::{say_err, tell};

/// `restir merge` arguments.
#[derive(clap::Args, Debug)]
pub struct MergeArgs {
    /// The merged image (.exr or .png).
    pub output: PathBuf,
    /// The parts: EXR files written by `restir render --chain/--crop`.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Refuse a merge whose estimated memory (the film's sums and image, the largest part)
    /// exceeds this many GiB, before allocating anything [default: 8].
    #[arg(long, value_name = "GIB")]
    pub max_memory: Option<f64>,
}

/// One part as described by its header (its pixels are read when merged).
#[derive(Clone, Debug)]
pub struct Part {
    /// Its file (for messages).
    pub path: PathBuf,
    /// The passes it holds.
    pub passes: Range<u32>,
    /// The window it holds.
    pub window: PixelWindow,
    /// What must agree between parts of one render: `(attribute, value)`.
    pub identity: Vec<(&'static str, String)>,
}

const IDENTITY: [(&str, &str); 5] = [
    (attr::SCENE_HASH, "scene"),
    (attr::INTEGRATOR, "integrator settings"),
    (attr::SEED, "seed"),
    (attr::SPP, "pass count"),
    (attr::FILM, "film size"),
];

fn parse_range(text: &str) -> Option<Range<u32>> {
    let (a, b) = text.split_once("..")?;
    let (a, b) = (a.parse().ok()?, b.parse().ok()?);
    (a < b).then_some(a..b)
}

fn parse_window(text: &str) -> Option<PixelWindow> {
    let v: Vec<u32> = text
        .split(',')
        .map(|s| s.parse().ok())
        .collect::<Option<_>>()?;
    let [x0, y0, x1, y1] = v[..] else {
        return None;
    };
    (x0 < x1 && y0 < y1).then_some(PixelWindow {
        x0,
        y0,
        width: x1 - x0,
        height: y1 - y0,
    })
}

impl Part {
    /// Reads a part file's header and checks that its attributes agree with its windows.
    pub fn read(path: &Path) -> Result<Self, String> {
        let (size, exr) = Image::read_exr_part_header(path).map_err(|e| e.to_string())?;
        Self::from_header(path, size, &exr)
    }

    fn from_header(
        path: &Path,
        size: (u32, u32),
        exr: &restir_image::ExrPart,
    ) -> Result<Self, String> {
        let get = |name: &str| {
            exr.attribute(name).ok_or_else(|| {
                format!(
                    "{}: not a part of a split render (no {name} attribute): render parts with --chain/--crop",
                    path.display()
                )
            })
        };
        let bad = |name: &str, v: &str| format!("{}: bad {name} attribute '{v}'", path.display());
        let passes = get(attr::PASSES)?;
        let passes = parse_range(passes).ok_or_else(|| bad(attr::PASSES, passes))?;
        let window = get(attr::WINDOW)?;
        let window = parse_window(window).ok_or_else(|| bad(attr::WINDOW, window))?;
        if (window.x0, window.y0) != exr.offset
            || (window.width, window.height) != size
            || !window.fits(exr.film)
        {
            return Err(format!(
                "{}: its {} attribute does not match its data window",
                path.display(),
                attr::WINDOW
            ));
        }
        let film = get(attr::FILM)?;
        if film != format!("{}x{}", exr.film.0, exr.film.1) {
            return Err(format!(
                "{}: its {} attribute '{film}' does not match its display window ({}x{})",
                path.display(),
                attr::FILM,
                exr.film.0,
                exr.film.1
            ));
        }
        let spp = get(attr::SPP)?;
        if !spp.parse::<u32>().is_ok_and(|n| n >= passes.end) {
            return Err(bad(attr::SPP, spp));
        }
        let identity = IDENTITY
            .iter()
            .map(|(name, _)| Ok((*name, get(name)?.to_string())))
            .collect::<Result<_, String>>()?;
        Ok(Self {
            path: path.to_path_buf(),
            passes,
            window,
            identity,
        })
    }

    /// Reads the part's pixels, checking that the file still says what its header said.
    pub fn pixels(&self) -> Result<Image, String> {
        let (image, exr) = Image::read_exr_part(&self.path).map_err(|e| e.to_string())?;
        let again = Self::from_header(&self.path, (image.width, image.height), &exr)?;
        if (again.passes, again.window, again.identity)
            != (self.passes.clone(), self.window, self.identity.clone())
        {
            return Err(format!(
                "{}: changed while being merged",
                self.path.display()
            ));
        }
        Ok(image)
    }
}

fn overlap(a: &PixelWindow, b: &PixelWindow) -> bool {
    let (ax1, ay1) = a.end();
    let (bx1, by1) = b.end();
    a.x0 < bx1 && b.x0 < ax1 && a.y0 < by1 && b.y0 < ay1
}

fn show(w: &PixelWindow) -> String {
    let (x1, y1) = w.end();
    format!("{},{},{x1},{y1}", w.x0, w.y0)
}

/// What the parts of one render make: the pass count and the film.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Passes of the whole render.
    pub spp: u32,
    /// The whole film.
    pub film: PixelWindow,
}

/// Checks that the parts belong to one render, that each window's passes are `0..spp` exactly
/// once and that the windows tile the film.
pub fn check(parts: &[Part]) -> Result<Layout, String> {
    let first = parts.first().ok_or("nothing to merge")?;
    for p in &parts[1..] {
        for ((name, what), ((_, a), (_, b))) in
            IDENTITY.iter().zip(first.identity.iter().zip(&p.identity))
        {
            if a != b {
                return Err(format!(
                    "{} and {}: parts of different renders ({what} differs: {name} '{a}' vs '{b}')",
                    first.path.display(),
                    p.path.display()
                ));
            }
        }
    }
    let spp: u32 = first.identity[3].1.parse().map_err(|_| {
        format!(
            "{}: bad {} attribute '{}'",
            first.path.display(),
            attr::SPP,
            first.identity[3].1
        )
    })?;
    let film = parse_window(&format!("0,0,{}", first.identity[4].1.replace('x', ",")))
        .ok_or_else(|| format!("{}: bad {} attribute", first.path.display(), attr::FILM))?;

    // Group the parts by window: chains of one tile.
    let mut tiles: Vec<(PixelWindow, Vec<&Part>)> = Vec::new();
    for p in parts {
        match tiles.iter_mut().find(|(w, _)| *w == p.window) {
            Some((_, v)) => v.push(p),
            None => tiles.push((p.window, vec![p])),
        }
    }
    for (i, (a, pa)) in tiles.iter().enumerate() {
        for (b, pb) in &tiles[i + 1..] {
            if overlap(a, b) {
                return Err(format!(
                    "{} (window {}) and {} (window {}): windows overlap",
                    pa[0].path.display(),
                    show(a),
                    pb[0].path.display(),
                    show(b)
                ));
            }
        }
    }
    let covered: u64 = tiles.iter().map(|(w, _)| w.pixels() as u64).sum();
    if covered != film.pixels() as u64 {
        return Err(format!(
            "the windows cover {covered} of the film's {}×{} = {} pixels: a tile is missing",
            film.width,
            film.height,
            film.pixels()
        ));
    }
    for (window, chains) in &mut tiles {
        chains.sort_by_key(|p| p.passes.start);
        let mut next = 0u32;
        let mut prev: Option<&Part> = None;
        for p in chains.iter() {
            if p.passes.start < next {
                let prev = prev.expect("a pass below `next` has a previous part");
                return Err(format!(
                    "{} (passes {}..{}) and {} (passes {}..{}): passes overlap",
                    prev.path.display(),
                    prev.passes.start,
                    prev.passes.end,
                    p.path.display(),
                    p.passes.start,
                    p.passes.end
                ));
            }
            if p.passes.start > next {
                return Err(format!(
                    "window {}: passes {next}..{} of {spp} are missing (before {})",
                    show(window),
                    p.passes.start,
                    p.path.display()
                ));
            }
            next = p.passes.end;
            prev = Some(p);
        }
        if next != spp {
            return Err(format!(
                "window {}: passes {next}..{spp} of {spp} are missing",
                show(window)
            ));
        }
    }
    Ok(Layout { spp, film })
}

/// Bytes a merge needs: the film's f64 sums and its f32 image, and the largest part's pixels
/// twice (the decoder's buffer and the image).
pub fn memory_bytes(layout: &Layout, parts: &[Part]) -> u64 {
    let largest = parts
        .iter()
        .map(|p| p.window.pixels() as u64)
        .max()
        .unwrap_or(0);
    (layout.film.pixels() as u64) * (24 + 12) + largest * 24
}

/// Merges parts of one render into the whole image ([`check`] first): the pixels of each part,
/// read by `load` one part at a time, are added pass-weighted into the film's f64 sums, which
/// are divided by the pass count at the end (every window's passes add up to it).
pub fn merge(
    parts: &[Part],
    mut load: impl FnMut(&Part) -> Result<Image, String>,
) -> Result<Image, String> {
    let layout = check(parts)?;
    let film = layout.film;
    let width = film.width as usize;
    let mut sums = vec![DVec3::ZERO; film.pixels()];
    for p in parts {
        let image = load(p)?;
        if (image.width, image.height) != (p.window.width, p.window.height) {
            return Err(format!("{}: changed while being merged", p.path.display()));
        }
        let n = p.passes.len() as f64;
        let w = p.window.width as usize;
        for (i, px) in image.pixels.iter().enumerate() {
            let (x, y) = (i % w + p.window.x0 as usize, i / w + p.window.y0 as usize);
            sums[y * width + x] += px.as_dvec3() * n;
        }
    }
    let total = f64::from(layout.spp);
    let mut out = Image::new(film.width, film.height);
    for (o, s) in out.pixels.iter_mut().zip(&sums) {
        *o = (*s / total).as_vec3();
    }
    Ok(out)
}

/// `restir merge`.
pub fn run(args: MergeArgs) -> Result<(), String> {
    match args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("exr") | Some("png") => {}
        _ => {
            return Err(format!(
                "{}: output must end in .exr or .png",
                args.output.display()
            ));
        }
    }
    let max_gib = crate::strict::max_memory(args.max_memory)?;
    if let Some(input) = args
        .inputs
        .iter()
        .find(|i| restir_image::same_destination(&args.output, i))
    {
        return Err(format!(
            "{}: the same file as the part {}: merging would overwrite one of its inputs",
            args.output.display(),
            input.display()
        ));
    }
    Image::check_output(&args.output).map_err(|e| e.to_string())?;
    let parts = args
        .inputs
        .iter()
        .map(|p| Part::read(p))
        .collect::<Result<Vec<_>, _>>()?;
    let layout = check(&parts)?;
    let need = memory_bytes(&layout, &parts);
    let gib = need as f64 / (1u64 << 30) as f64;
    if gib > max_gib {
        return Err(format!(
            "merging a {}×{} film needs about {need} bytes ({gib:.1} GiB), more than the limit \
             of {max_gib} GiB: raise --max-memory",
            layout.film.width, layout.film.height
        ));
    }
    let image = merge(&parts, Part::pixels)?;
    let nonfinite = image.nonfinite_count();
    image.write(&args.output).map_err(|e| e.to_string())?;
    if nonfinite > 0 {
        say_err!("warning: {nonfinite} pixels are NaN or infinite");
    }
    tell!(
        "merged {} parts: {}×{}, {} passes -> {}",
        parts.len(),
        image.width,
        image.height,
        layout.spp,
        args.output.display()
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn part(name: &str, passes: Range<u32>, window: PixelWindow, value: f32) -> (Part, Image) {
        let mut image = Image::new(window.width, window.height);
        for (i, p) in image.pixels.iter_mut().enumerate() {
            *p = Vec3::new(value, value * i as f32, 1.0);
        }
        let part = Part {
            path: PathBuf::from(name),
            passes,
            window,
            identity: vec![
                (attr::SCENE_HASH, "h".into()),
                (attr::INTEGRATOR, "path".into()),
                (attr::SEED, "0".into()),
                (attr::SPP, "10".into()),
                (attr::FILM, "4x2".into()),
            ],
        };
        (part, image)
    }

    /// [`merge`] with the images held in memory.
    fn merged(parts: &[(Part, Image)]) -> Result<Image, String> {
        let headers: Vec<Part> = parts.iter().map(|(p, _)| p.clone()).collect();
        merge(&headers, |p| {
            Ok(parts
                .iter()
                .find(|(q, _)| q.path == p.path)
                .expect("a part")
                .1
                .clone())
        })
    }

    fn win(x0: u32, y0: u32, x1: u32, y1: u32) -> PixelWindow {
        PixelWindow {
            x0,
            y0,
            width: x1 - x0,
            height: y1 - y0,
        }
    }

    /// Chains are weighted by their pass counts; tiles land at their offsets.
    #[test]
    fn merge_arithmetic() {
        let full = win(0, 0, 4, 2);
        let parts = [part("a", 0..3, full, 1.0), part("b", 3..10, full, 2.0)];
        let m = merged(&parts).unwrap();
        let want = (3.0 * 1.0 + 7.0 * 2.0) / 10.0;
        assert_eq!(m.pixels[0], Vec3::new(want, 0.0, 1.0));
        assert_eq!(
            m.pixels[5],
            Vec3::new(want, (3.0 * 5.0 + 7.0 * 10.0) / 10.0, 1.0)
        );
        // Two tiles, the right one in two chains.
        let parts = [
            part("l", 0..10, win(0, 0, 1, 2), 5.0),
            part("r0", 0..5, win(1, 0, 4, 2), 1.0),
            part("r1", 5..10, win(1, 0, 4, 2), 3.0),
        ];
        let m = merged(&parts).unwrap();
        assert_eq!(m.pixels[0], Vec3::new(5.0, 0.0, 1.0));
        assert_eq!(m.pixels[4], Vec3::new(5.0, 5.0, 1.0));
        assert_eq!(m.pixels[1], Vec3::new(2.0, 0.0, 1.0));
        assert_eq!(m.pixels[7], Vec3::new(2.0, 10.0, 1.0));
        // One part holding everything is copied exactly.
        let one = part("x", 0..10, full, 0.1);
        assert_eq!(merged(std::slice::from_ref(&one)).unwrap(), one.1);
    }

    /// Overlapping or missing passes and tiles, and parts of different renders, are errors
    /// naming the files.
    #[test]
    fn merge_errors() {
        let full = win(0, 0, 4, 2);
        let err = |parts: &[(Part, Image)]| merged(parts).unwrap_err();
        assert_eq!(
            err(&[part("a", 0..6, full, 1.0), part("b", 5..10, full, 1.0)]),
            "a (passes 0..6) and b (passes 5..10): passes overlap"
        );
        assert_eq!(
            err(&[part("a", 0..4, full, 1.0), part("b", 5..10, full, 1.0)]),
            "window 0,0,4,2: passes 4..5 of 10 are missing (before b)"
        );
        assert_eq!(
            err(&[part("a", 0..4, full, 1.0)]),
            "window 0,0,4,2: passes 4..10 of 10 are missing"
        );
        assert_eq!(
            err(&[part("a", 0..10, win(0, 0, 2, 2), 1.0)]),
            "the windows cover 4 of the film's 4×2 = 8 pixels: a tile is missing"
        );
        assert_eq!(
            err(&[
                part("a", 0..10, win(0, 0, 3, 2), 1.0),
                part("b", 0..10, win(2, 0, 4, 2), 1.0)
            ]),
            "a (window 0,0,3,2) and b (window 2,0,4,2): windows overlap"
        );
        let mut other = part("b", 5..10, full, 1.0);
        other.0.identity[1].1 = "restir-di".into();
        assert_eq!(
            err(&[part("a", 0..5, full, 1.0), other]),
            "a and b: parts of different renders (integrator settings differs: \
             restir:integrator 'path' vs 'restir-di')"
        );
        let mut other = part("b", 5..10, full, 1.0);
        other.0.identity[4].1 = "8x2".into();
        assert!(err(&[part("a", 0..5, full, 1.0), other]).contains("film size differs"));
    }
}
