//! Rendering one part of a render for a cluster (`docs/CLUSTER.md`): `--chain I --chains N`
//! renders the chain's share of the passes, `--crop x0,y0,x1,y1` a window of the film (rendered
//! with the estimator's spatial-reuse halo). A part is written as an EXR whose data window sits in
//! the film's display window, with text attributes saying which render it belongs to and which
//! passes it holds; `restir merge` ([`crate::merge`]) puts the parts back together.

use std::ops::Range;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use restir_image::{ExrPart, Image};
use restir_integrators::{
    Integrator, PixelWindow, RenderJob, RenderOutput, RenderPart, part_halo, render_part,
};
use restir_scene::{Scene, SceneDesc};

/// Attribute names of a part's EXR file.
pub mod attr {
    /// The scene file as given on the command line (for messages).
    pub const SCENE: &str = "restir:scene";
    /// FNV-1a hash of the scene description after overrides, hex.
    pub const SCENE_HASH: &str = "restir:scene_hash";
    /// The estimator's settings line.
    pub const INTEGRATOR: &str = "restir:integrator";
    /// The seed.
    pub const SEED: &str = "restir:seed";
    /// Passes of the whole render.
    pub const SPP: &str = "restir:spp";
    /// The passes this part holds, `a..b`.
    pub const PASSES: &str = "restir:passes";
    /// The film window this part holds, `x0,y0,x1,y1`.
    pub const WINDOW: &str = "restir:window";
    /// The film size, `WxH`.
    pub const FILM: &str = "restir:film";
}

/// The `render` options that make a process render one part of a render.
#[derive(clap::Args, Debug)]
#[command(next_help_heading = "Cluster (docs/CLUSTER.md)")]
pub struct ClusterArgs {
    /// Render only chain I (0-based) of --chains N: its share of the --spp passes, the same
    /// passes one process would render. Temporal reuse restarts at the chain's first pass.
    #[arg(long, value_name = "I", requires = "chains")]
    pub chain: Option<u32>,
    /// Number of chains the passes are split into (with --chain).
    #[arg(long, value_name = "N", requires = "chain")]
    pub chains: Option<u32>,
    /// Render only the film window x0,y0,x1,y1 (pixels, x1 and y1 exclusive), with a halo for
    /// spatial reuse; the image written is the window.
    #[arg(long, value_name = "X0,Y0,X1,Y1")]
    pub crop: Option<String>,
}

/// What a part-rendering process renders.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Passes of the whole render.
    pub spp: u32,
    /// The passes of this part.
    pub passes: Range<u32>,
    /// `(chain, chains)` when split into chains.
    pub chain: Option<(u32, u32)>,
    /// The window when cropped.
    pub window: Option<PixelWindow>,
    /// The film size.
    pub film: (u32, u32),
}

/// The passes of chain `i` of `n` over `spp` passes: `⌊i·spp/n⌋..⌊(i+1)·spp/n⌋`.
pub fn chain_passes(i: u32, n: u32, spp: u32) -> Range<u32> {
    let at = |k: u32| (u64::from(k) * u64::from(spp) / u64::from(n)) as u32;
    at(i)..at(i + 1)
}

/// Parses `x0,y0,x1,y1` into a window of a `film`-sized film.
pub fn parse_crop(text: &str, film: (u32, u32)) -> Result<PixelWindow, String> {
    let bad = || {
        format!("--crop {text}: expected x0,y0,x1,y1 (pixels, x0 < x1 <= width, y0 < y1 <= height)")
    };
    let v: Vec<u32> = text
        .split(',')
        .map(|s| s.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    let [x0, y0, x1, y1] = v[..] else {
        return Err(bad());
    };
    if x0 >= x1 || y0 >= y1 {
        return Err(bad());
    }
    let window = PixelWindow {
        x0,
        y0,
        width: x1 - x0,
        height: y1 - y0,
    };
    if !window.fits(film) {
        return Err(format!(
            "--crop {text}: outside the {}×{} film",
            film.0, film.1
        ));
    }
    Ok(window)
}

impl ClusterArgs {
    /// The part to render, or `None` without cluster options. `spp` is the render's pass count,
    /// `time_limit` whether a time limit was given, `output` the output file.
    pub fn plan(
        &self,
        spp: u32,
        time_limit: bool,
        output: &Path,
        film: (u32, u32),
    ) -> Result<Option<Plan>, String> {
        if self.chain.is_none() && self.crop.is_none() {
            return Ok(None);
        }
        if time_limit {
            return Err(
                "--time-limit cannot be combined with --chain or --crop: a part's passes must be fixed for merge"
                    .into(),
            );
        }
        if !output
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
        {
            return Err(format!(
                "{}: a part of a render (--chain, --crop) must be written as .exr",
                output.display()
            ));
        }
        let chain = match (self.chain, self.chains) {
            (Some(i), Some(n)) => {
                if n == 0 || n > spp {
                    return Err(format!(
                        "--chains {n}: expected 1 to {spp} (the render's passes)"
                    ));
                }
                if i >= n {
                    return Err(format!(
                        "--chain {i}: expected 0 to {} (--chains {n})",
                        n - 1
                    ));
                }
                Some((i, n))
            }
            _ => None,
        };
        let passes = chain.map_or(0..spp, |(i, n)| chain_passes(i, n, spp));
        let window = self
            .crop
            .as_deref()
            .map(|c| parse_crop(c, film))
            .transpose()?;
        Ok(Some(Plan {
            spp,
            passes,
            chain,
            window,
            film,
        }))
    }
}

/// What a part says about itself in the `--stats` JSON (`"part"`).
#[derive(serde::Serialize, Debug)]
pub struct PartStats {
    /// The passes held, `[first, end)`.
    pub passes: [u32; 2],
    /// Passes of the whole render.
    pub spp_total: u32,
    /// `[chain, chains]`.
    pub chain: Option<[u32; 2]>,
    /// The window held, `[x0, y0, x1, y1]`.
    pub window: [u32; 4],
    /// The region rendered (window plus halo, aligned), `[x0, y0, x1, y1]`.
    pub region: [u32; 4],
    /// The halo in pixels: the estimator's spatial reuse beyond the film's splatting reach
    /// (`restir_integrators::part_halo`).
    pub halo: u32,
    /// Whether the estimator reuses temporally: its history then starts afresh at the part's
    /// first pass (each chain, each tile keeps its own), unlike one process rendering all passes.
    pub temporal_restarts: bool,
    /// Whether the estimator learns across passes (ReSTIR DI's `learn`): it then learns only
    /// from the part's own passes, starting with nothing learned at the part's first pass.
    pub learning_restarts: bool,
}

fn corners(w: &PixelWindow) -> [u32; 4] {
    let (x1, y1) = w.end();
    [w.x0, w.y0, x1, y1]
}

impl Plan {
    /// The library's part description.
    pub fn part(&self) -> RenderPart {
        RenderPart {
            first_pass: self.passes.start,
            window: self.window,
        }
    }

    /// The window held (the whole film without a crop).
    pub fn window(&self) -> PixelWindow {
        self.window.unwrap_or(PixelWindow::full(self.film))
    }

    /// The statistics of this part rendered with `integrator`.
    pub fn stats(&self, integrator: &dyn Integrator, scene: &Scene) -> PartStats {
        PartStats {
            passes: [self.passes.start, self.passes.end],
            spp_total: self.spp,
            chain: self.chain.map(|(i, n)| [i, n]),
            window: corners(&self.window()),
            region: corners(&self.part().region(integrator, scene)),
            halo: part_halo(integrator, scene),
            temporal_restarts: integrator.describe().contains("temporal=true"),
            learning_restarts: integrator.learned().is_some(),
        }
    }

    /// Writes the part's image with its attributes.
    pub fn write(
        &self,
        image: &Image,
        output: &Path,
        scene: &Path,
        desc: &SceneDesc,
        integrator: &dyn Integrator,
        seed: u64,
    ) -> Result<(), String> {
        let window = self.window();
        let [x0, y0, x1, y1] = corners(&window);
        let attributes = vec![
            (attr::SCENE.into(), scene.display().to_string()),
            (
                attr::SCENE_HASH.into(),
                format!(
                    "{:016x}",
                    scene_hash(desc, scene.parent().unwrap_or(Path::new(".")))
                ),
            ),
            (attr::INTEGRATOR.into(), integrator.describe()),
            (attr::SEED.into(), seed.to_string()),
            (attr::SPP.into(), self.spp.to_string()),
            (
                attr::PASSES.into(),
                format!("{}..{}", self.passes.start, self.passes.end),
            ),
            (attr::WINDOW.into(), format!("{x0},{y0},{x1},{y1}")),
            (
                attr::FILM.into(),
                format!("{}x{}", self.film.0, self.film.1),
            ),
        ];
        let part = ExrPart {
            film: self.film,
            offset: (window.x0, window.y0),
            attributes,
        };
        image
            .write_exr_part(output, &part)
            .map_err(|e| e.to_string())
    }
}

/// FNV-1a (64-bit) of the scene description's JSON and of the contents of every file it refers
/// to (meshes, textures, environment maps; `filename` values, relative to `base_dir`): the same
/// for the same scene, assets and overrides, whatever machine renders it, and different when an
/// asset changed between parts. A file that cannot be read hashes as missing.
pub fn scene_hash(desc: &SceneDesc, base_dir: &Path) -> u64 {
    use std::io::Read;
    let mut h = restir_sampling::hash::Fnv1a::new();
    let mut value = serde_json::to_value(desc).unwrap_or_default();
    // The film's file name is where the image goes, not an input.
    if let Some(film) = value.get_mut("film").and_then(|f| f.as_object_mut()) {
        film.remove("filename");
    }
    h.write(value.to_string().as_bytes());
    let mut files = Vec::new();
    referenced_files(&value, &mut files);
    for f in files {
        h.write(f.as_bytes());
        match restir_image::input::open_regular(&base_dir.join(f)) {
            Ok(file) => {
                let mut reader = std::io::BufReader::new(file);
                let mut buf = [0u8; 1 << 16];
                loop {
                    match reader.read(&mut buf) {
                        Ok(0) => break,
                        Ok(n) => h.write(&buf[..n]),
                        Err(_) => {
                            h.write(b"\0unreadable");
                            break;
                        }
                    }
                }
            }
            Err(_) => h.write(b"\0missing"),
        }
    }
    h.finish()
}

/// The `filename` strings of a scene description's JSON, in order.
fn referenced_files<'a>(value: &'a serde_json::Value, out: &mut Vec<&'a str>) {
    match value {
        serde_json::Value::Object(map) => {
            for (k, v) in map {
                match (k.as_str(), v) {
                    ("filename", serde_json::Value::String(f)) => out.push(f),
                    _ => referenced_files(v, out),
                }
            }
        }
        serde_json::Value::Array(items) => items.iter().for_each(|v| referenced_files(v, out)),
        _ => {}
    }
}

/// Renders the plan's part, or the whole render without a plan.
pub fn render(
    scene: &Scene,
    integrator: &dyn Integrator,
    job: &RenderJob,
    plan: Option<&Plan>,
    cancel: &AtomicBool,
    progress: &mut dyn FnMut(u32, Duration),
) -> RenderOutput {
    let part = plan.map(Plan::part).unwrap_or_default();
    render_part(scene, integrator, job, &part, cancel, progress)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Chains partition the passes in order, whatever the remainder.
    #[test]
    fn chains_partition_passes() {
        for spp in [1u32, 4, 7, 16, 1001] {
            for n in 1..=spp.min(9) {
                let mut next = 0;
                for i in 0..n {
                    let r = chain_passes(i, n, spp);
                    assert_eq!(r.start, next);
                    assert!(r.end > r.start, "chain {i}/{n} of {spp} is empty");
                    assert!(r.len() as u32 <= spp.div_ceil(n));
                    next = r.end;
                }
                assert_eq!(next, spp);
            }
        }
    }

    #[test]
    fn crop_parsing() {
        let w = parse_crop("2, 3,10,8", (16, 8)).unwrap();
        assert_eq!((w.x0, w.y0, w.width, w.height), (2, 3, 8, 5));
        for bad in ["1,2,3", "3,0,3,4", "a,0,1,1", "0,0,1,1,1", "-1,0,1,1"] {
            assert!(
                parse_crop(bad, (16, 8))
                    .unwrap_err()
                    .contains("expected x0,y0,x1,y1")
            );
        }
        assert_eq!(
            parse_crop("0,0,17,8", (16, 8)).unwrap_err(),
            "--crop 0,0,17,8: outside the 16×8 film"
        );
    }
}
