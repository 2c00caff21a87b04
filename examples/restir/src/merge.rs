//! `restir merge OUT IN...`: puts the parts of a split render (`--chain`, `--crop`, see
//! [`crate::cluster`]) back together. Parts must come from one render (same scene, estimator
//! settings, seed, pass count and film); parts with the same window are chains, combined
//! pass-weighted (`Σ nᵢ·meanᵢ / Σ nᵢ` in f64), and their passes must be `0..spp` exactly once;
//! the windows must cover the film exactly once. The result is written as a plain render.

use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::DVec3;
use restir_image::Image;
use restir_integrators::PixelWindow;

use crate::cluster::attr;

/// `restir merge` arguments.
#[derive(clap::Args, Debug)]
pub struct MergeArgs {
    /// The merged image (.exr or .png).
    pub output: PathBuf,
    /// The parts: EXR files written by `restir render --chain/--crop`.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
}

/// One part as read back.
#[derive(Clone, Debug)]
pub struct Part {
    /// Its file (for messages).
    pub path: PathBuf,
    /// The window's pixels.
    pub image: Image,
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
    /// Reads a part file.
    pub fn read(path: &Path) -> Result<Self, String> {
        let (image, exr) = Image::read_exr_part(path).map_err(|e| e.to_string())?;
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
            || (window.width, window.height) != (image.width, image.height)
            || !window.fits(exr.film)
        {
            return Err(format!(
                "{}: its {} attribute does not match its data window",
                path.display(),
                attr::WINDOW
            ));
        }
        let identity = IDENTITY
            .iter()
            .map(|(name, _)| Ok((*name, get(name)?.to_string())))
            .collect::<Result<_, String>>()?;
        Ok(Self {
            path: path.to_path_buf(),
            image,
            passes,
            window,
            identity,
        })
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

/// Merges parts of one render into the whole image. Checks that they belong to one render, that
/// each window's passes are `0..spp` exactly once and that the windows tile the film.
pub fn merge(parts: &[Part]) -> Result<Image, String> {
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

    let mut out = Image::new(film.width, film.height);
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
        let combined = combine(chains);
        let w = window.width as usize;
        for (i, px) in combined.into_iter().enumerate() {
            let (x, y) = (i % w + window.x0 as usize, i / w + window.y0 as usize);
            out.pixels[y * film.width as usize + x] = px;
        }
    }
    Ok(out)
}

/// The pass-weighted mean of chains of one window: `Σ nᵢ·meanᵢ / Σ nᵢ` per pixel, in f64.
pub fn combine(chains: &[&Part]) -> Vec<glam::Vec3> {
    let total: f64 = chains.iter().map(|p| p.passes.len() as f64).sum();
    let n = chains[0].image.pixels.len();
    (0..n)
        .map(|i| {
            let sum: DVec3 = chains
                .iter()
                .map(|p| p.image.pixels[i].as_dvec3() * p.passes.len() as f64)
                .sum();
            (sum / total).as_vec3()
        })
        .collect()
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
    let parts = args
        .inputs
        .iter()
        .map(|p| Part::read(p))
        .collect::<Result<Vec<_>, _>>()?;
    let image = merge(&parts)?;
    image.write(&args.output).map_err(|e| e.to_string())?;
    println!(
        "merged {} parts: {}×{}, {} passes -> {}",
        parts.len(),
        image.width,
        image.height,
        parts[0].identity[3].1,
        args.output.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn part(name: &str, passes: Range<u32>, window: PixelWindow, value: f32) -> Part {
        let mut image = Image::new(window.width, window.height);
        for (i, p) in image.pixels.iter_mut().enumerate() {
            *p = Vec3::new(value, value * i as f32, 1.0);
        }
        Part {
            path: PathBuf::from(name),
            image,
            passes,
            window,
            identity: vec![
                (attr::SCENE_HASH, "h".into()),
                (attr::INTEGRATOR, "path".into()),
                (attr::SEED, "0".into()),
                (attr::SPP, "10".into()),
                (attr::FILM, "4x2".into()),
            ],
        }
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
        let m = merge(&parts).unwrap();
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
        let m = merge(&parts).unwrap();
        assert_eq!(m.pixels[0], Vec3::new(5.0, 0.0, 1.0));
        assert_eq!(m.pixels[4], Vec3::new(5.0, 5.0, 1.0));
        assert_eq!(m.pixels[1], Vec3::new(2.0, 0.0, 1.0));
        assert_eq!(m.pixels[7], Vec3::new(2.0, 10.0, 1.0));
        // One part holding everything is copied exactly.
        let one = part("x", 0..10, full, 0.1);
        assert_eq!(merge(std::slice::from_ref(&one)).unwrap(), one.image);
    }

    /// Overlapping or missing passes and tiles, and parts of different renders, are errors
    /// naming the files.
    #[test]
    fn merge_errors() {
        let full = win(0, 0, 4, 2);
        let err = |parts: &[Part]| merge(parts).unwrap_err();
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
        other.identity[1].1 = "restir-di".into();
        assert_eq!(
            err(&[part("a", 0..5, full, 1.0), other]),
            "a and b: parts of different renders (integrator settings differs: \
             restir:integrator 'path' vs 'restir-di')"
        );
        let mut other = part("b", 5..10, full, 1.0);
        other.identity[4].1 = "8x2".into();
        assert!(err(&[part("a", 0..5, full, 1.0), other]).contains("film size differs"));
    }
}
