//! `restir generate`: the subcommand's arguments and writing the file; the scenes themselves
//! come from [`restir_families`], the environment map (a procedural sky, the asset of
//! `scenes/envmap-spheres.xml`) from [`sky`].

use std::path::PathBuf;

use glam::Vec3;
use restir_families::many_lights_ron;
use restir_image::Image;

use crate::say::tell;

/// Scenes the generator can write.
#[derive(clap::Subcommand, Debug)]
pub enum Generate {
    /// A floor with boxes and pillars lit only by many small coloured sphere lights.
    ManyLights(ManyLightsArgs),
    /// Small one-sided emissive rectangles hanging over receivers (direct light only).
    Rects(DiArgs),
    /// Small emissive spheres hanging over receivers (direct light only).
    Spheres(DiArgs),
    /// A few emissive OBJ meshes of thousands of small triangles over receivers (direct light only).
    Meshes(DiArgs),
    /// A glossy room lit mostly indirectly by one hidden area light, or by many small lamps.
    Room(RoomArgs),
    /// Small lamps added to a scene somebody else wrote (a Mitsuba 3 XML file, included by the
    /// file written, not copied): N emissive spheres placed by a rule that needs only the scene's
    /// geometry and camera (docs/SCENES.md).
    Lamps(LampsArgs),
    /// Every scene of a training or test family with an index: di (ReSTIR DI), pt (ReSTIR PT),
    /// and the moving di-motion and pt-motion (animated, 12 fps; render them with
    /// `restir render DIR/NAME.ron --frames 0..23`).
    Family(FamilyArgs),
    /// A latitude-longitude environment map (EXR): a sky with a sun over a dark ground, the map
    /// of scenes/envmap-spheres.xml.
    Envmap(EnvmapArgs),
    /// A 6×8 uv test pattern (PNG, sRGB): every texel a different colour, so a flipped or
    /// shifted lookup shows. The bitmap of scenes/textured/textured-shapes.xml.
    UvPattern(UvPatternArgs),
}

/// Options of `restir generate uv-pattern`.
#[derive(clap::Args, Debug)]
pub struct UvPatternArgs {
    /// Output PNG file.
    #[arg(
        short = 'o',
        long = "output",
        default_value = "scenes/textured/tex.png"
    )]
    output: PathBuf,
}

/// Options of `restir generate envmap`.
#[derive(clap::Args, Debug)]
pub struct EnvmapArgs {
    /// Width in texels (the height is half of it).
    #[arg(long, default_value_t = 256)]
    width: u32,
    /// Output EXR file.
    #[arg(short = 'o', long = "output", default_value = "scenes/envmap/sky.exr")]
    output: PathBuf,
}

/// Options of `restir generate many-lights`.
#[derive(clap::Args, Debug)]
pub struct ManyLightsArgs {
    /// Number of sphere lights.
    #[arg(long, default_value_t = 400)]
    lights: u32,
    /// Seed of the layout (lights and occluders).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output RON file.
    #[arg(short = 'o', long = "output", default_value = "scenes/many-lights.ron")]
    output: PathBuf,
}

/// Runs a `generate` subcommand.
pub fn run(what: Generate) -> Result<(), String> {
    match what {
        Generate::ManyLights(args) => {
            if !(1..=1_000_000).contains(&args.lights) {
                return Err(format!(
                    "--lights {}: expected 1 to 1000000 lights",
                    args.lights
                ));
            }
            let text = many_lights_ron(args.lights, args.seed).map_err(|e| e.to_string())?;
            restir_image::write_file_atomically(&args.output, text.as_bytes())
                .map_err(|e| e.to_string())?;
            tell!(
                "many-lights: {} lights, seed {} -> {}",
                args.lights,
                args.seed,
                args.output.display()
            )?;
            Ok(())
        }
        Generate::Rects(args) => write_di(Kind::Rects, args),
        Generate::Spheres(args) => write_di(Kind::Spheres, args),
        Generate::Meshes(args) => write_di(Kind::Meshes, args),
        Generate::Room(args) => write_room(args),
        Generate::Lamps(args) => write_lamps(args),
        Generate::Family(args) => write_family(&args),
        Generate::Envmap(args) => {
            if !(4..=8192).contains(&args.width) || args.width % 2 != 0 {
                return Err(format!(
                    "--width {}: expected an even width from 4 to 8192 texels",
                    args.width
                ));
            }
            create_parent(&args.output)?;
            sky(args.width, args.width / 2)
                .write(&args.output)
                .map_err(|e| e.to_string())?;
            tell!(
                "envmap: sky {}×{} -> {}",
                args.width,
                args.width / 2,
                args.output.display()
            )?;
            Ok(())
        }
        Generate::UvPattern(args) => {
            create_parent(&args.output)?;
            uv_pattern()
                .write(&args.output)
                .map_err(|e| e.to_string())?;
            tell!("uv-pattern: 6×8 -> {}", args.output.display())?;
            Ok(())
        }
    }
}

/// Creates the directory `path` goes in.
fn create_parent(path: &std::path::Path) -> Result<(), String> {
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create directory: {e}", dir.display())),
        None => Ok(()),
    }
}

/// A 6-wide, 8-high test pattern: red grows with the column, green with the row, blue marks a
/// checkerboard and the top-left texel is white, so every texel differs and the orientation
/// shows.
pub fn uv_pattern() -> Image {
    let (w, h) = (6u32, 8u32);
    let mut img = Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            let c = if (x, y) == (0, 0) {
                Vec3::ONE
            } else {
                Vec3::new(
                    0.1 + 0.8 * x as f32 / (w - 1) as f32,
                    0.1 + 0.8 * y as f32 / (h - 1) as f32,
                    if (x + y) % 2 == 0 { 0.8 } else { 0.1 },
                )
            };
            img.pixels[(y * w + x) as usize] = c;
        }
    }
    img
}

/// Direction of the sun in the map's frame (+Y up): 35° above the horizon.
fn sun_direction() -> Vec3 {
    let (elevation, azimuth) = (35f32.to_radians(), 0.3 * std::f32::consts::TAU);
    Vec3::new(
        azimuth.sin() * elevation.cos(),
        elevation.sin(),
        -azimuth.cos() * elevation.cos(),
    )
}

/// `0` below `a`, `1` above `b`, a smooth cubic between.
fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A procedural sky as a latitude-longitude map in Mitsuba's `envmap` layout (column `x` at
/// `u = (x + ½)/W`, row `y` at `θ = π·y/(H − 1)`, `+Y` up; see `restir_lights::envmap`): a blue
/// zenith fading to a pale horizon, a dark ground below it, and a sun of 2.5° radius with a glow.
/// Made here so the shipped scene needs nothing from outside the repository.
pub fn sky(width: u32, height: u32) -> Image {
    use std::f32::consts::{PI, TAU};
    let sun = sun_direction();
    let zenith = Vec3::new(0.06, 0.13, 0.35);
    let horizon = Vec3::new(0.4, 0.42, 0.45);
    let ground = Vec3::new(0.12, 0.1, 0.08);
    let sun_radius = 2.5f32.to_radians();
    let mut img = Image::new(width, height);
    for y in 0..height {
        let theta = PI * y as f32 / (height - 1) as f32;
        for x in 0..width {
            let phi = TAU * (x as f32 + 0.5) / width as f32;
            let d = Vec3::new(
                phi.sin() * theta.sin(),
                theta.cos(),
                -phi.cos() * theta.sin(),
            );
            let up = d.y.max(0.0);
            let sky = horizon.lerp(zenith, up.sqrt());
            let mut c = ground.lerp(sky, smoothstep(-0.04, 0.02, d.y));
            let angle = d.dot(sun).clamp(-1.0, 1.0).acos();
            c += Vec3::new(1.0, 0.92, 0.8)
                * (200.0 * (1.0 - smoothstep(0.8 * sun_radius, 1.2 * sun_radius, angle))
                    + 1.5 * (-angle / 0.12).exp());
            img.pixels[(y * width + x) as usize] = c;
        }
    }
    img
}

// ---- the generated kinds and the scene families (restir-families) ----

use restir_families::{
    DiOptions, Family, FamilyMember, Generated, Glass, Kind, Params, Receivers, RoomOptions, Split,
    members,
};

/// Options of `restir generate rects|spheres|meshes`.
#[derive(clap::Args, Debug)]
pub struct DiArgs {
    /// Seed of the layout, materials and lights.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Number of lights (rectangles, spheres or emissive triangles).
    #[arg(long, default_value_t = 1000)]
    lights: u32,
    /// Receiver materials.
    #[arg(long, default_value = "mixed", value_parser = ["diffuse", "textured", "glossy", "mixed"])]
    receivers: String,
    /// Brightest over dimmest light radiance.
    #[arg(long, default_value_t = 1000.0)]
    power_ratio: f32,
    /// Leave out the slats and pillars between lights and receivers.
    #[arg(long)]
    no_occluders: bool,
    /// A dim sky (EXR written beside the scene) besides the lights.
    #[arg(long)]
    envmap: bool,
    /// Output RON file; assets go beside it. Default: <kind>-<options>-s<seed>.ron.
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
}

/// Options of `restir generate room`.
#[derive(clap::Args, Debug)]
pub struct RoomArgs {
    /// Seed of the layout, materials and light.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// A glass object.
    #[arg(long, default_value = "none", value_parser = ["none", "smooth", "rough"])]
    glass: String,
    /// A window in the right wall with a sky (EXR written beside the scene) outside.
    #[arg(long)]
    window: bool,
    /// Light the room with this many small lamps (tessellated bulbs, an OBJ file written beside
    /// the scene) instead of its hidden area light: the seed report's kind of scene.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=2000))]
    lamps: u32,
    /// Output RON file; assets go beside it. Default: room-<options>-s<seed>.ron.
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
}

/// Options of `restir generate lamps`.
#[derive(clap::Args, Debug)]
pub struct LampsArgs {
    /// The scene to add lamps to (Mitsuba 3 XML; RON scenes cannot be included).
    #[arg(long)]
    scene: PathBuf,
    /// How many lamps.
    #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    lamps: u32,
    /// Seed of the placement, powers and colours.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output XML file (it includes the scene by its absolute path).
    #[arg(short = 'o', long = "output")]
    output: PathBuf,
}

/// Options of `restir generate family`.
#[derive(clap::Args, Debug)]
pub struct FamilyArgs {
    /// Which study: di (ReSTIR DI, many lights, direct light), pt (ReSTIR PT, glossy rooms), or
    /// the same under motion, di-motion and pt-motion (camera, objects and lights move over 2 s
    /// at 12 fps, frames 0..23).
    #[arg(long, value_parser = ["di", "pt", "di-motion", "pt-motion"])]
    kind: String,
    /// train (seeds 1..) or test (seeds 101..).
    #[arg(long, value_parser = ["train", "test"])]
    split: String,
    /// Directory for the scenes, their assets and the index family.txt.
    #[arg(long)]
    out: PathBuf,
    /// Write only the member with this index (0-based; its scene and assets, no family.txt).
    #[arg(long)]
    index: Option<usize>,
    /// Also write each scene as Mitsuba 3 XML, NAME.xml beside NAME.ron (as `restir convert`
    /// does; animated families cannot be).
    #[arg(long)]
    xml: bool,
}

fn di_params(kind: Kind, args: &DiArgs) -> Result<Params, String> {
    if !(1..=1_000_000).contains(&args.lights) {
        return Err(format!(
            "--lights {}: expected 1 to 1000000 lights",
            args.lights
        ));
    }
    if !(args.power_ratio.is_finite() && args.power_ratio >= 1.0) {
        return Err(format!(
            "--power-ratio {}: expected a ratio of at least 1",
            args.power_ratio
        ));
    }
    let receivers = Receivers::ALL
        .into_iter()
        .find(|r| r.name() == args.receivers)
        .ok_or_else(|| {
            format!(
                "--receivers {}: expected diffuse, textured, glossy or mixed",
                args.receivers
            )
        })?;
    Ok(Params::Di(
        kind,
        DiOptions {
            lights: args.lights,
            power_ratio: args.power_ratio,
            receivers,
            occluders: !args.no_occluders,
            envmap: args.envmap,
        },
    ))
}

/// A one-line description of a scene's parameters.
fn describe(params: &Params) -> String {
    match params {
        Params::Di(kind, o) => format!(
            "{}: {} lights, power ratio {}, {} receivers, {}occluders, {}",
            kind.name(),
            o.lights,
            o.power_ratio,
            o.receivers.name(),
            if o.occluders { "" } else { "no " },
            if o.envmap {
                "sky beside the lights"
            } else {
                "no environment"
            }
        ),
        Params::Room(o) => format!(
            "room: glass {}, {}, {}",
            o.glass.name(),
            if o.window {
                "window with a sky"
            } else {
                "closed"
            },
            if o.lamps > 0 {
                format!("{} small lamps", o.lamps)
            } else {
                "one hidden area light".to_string()
            }
        ),
    }
}

/// [`describe`], saying when the member is animated.
fn describe_member(member: &FamilyMember) -> String {
    if member.family.animated() {
        format!(
            "{}, animated ({} fps, frames 0..{})",
            describe(&member.params),
            restir_families::FPS,
            (restir_families::FPS * restir_families::DURATION) as u32 - 1
        )
    } else {
        describe(&member.params)
    }
}

fn tag(params: &Params) -> String {
    match params {
        Params::Di(_, o) => o.tag(),
        Params::Room(o) => o.tag(),
    }
}

/// Writes one generated scene to `output` (or its default name) and says so.
fn write_one(params: &Params, seed: u64, output: Option<PathBuf>) -> Result<(), String> {
    let generated: Generated =
        restir_families::generate(params, seed).map_err(|e| e.to_string())?;
    let output = output.unwrap_or_else(|| {
        PathBuf::from(format!(
            "{}-{}-s{seed}.ron",
            params.kind().name(),
            tag(params)
        ))
    });
    let dir = output
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(".".as_ref());
    let stem = output
        .file_stem()
        .and_then(|s| s.to_str())
        .ok_or_else(|| format!("{}: expected a file name ending in .ron", output.display()))?;
    if output.extension().and_then(|e| e.to_str()) != Some("ron") {
        return Err(format!(
            "{}: expected a file name ending in .ron",
            output.display()
        ));
    }
    let path = generated.write(dir, stem).map_err(|e| e.to_string())?;
    tell!(
        "{}, seed {seed} -> {} (+{} assets)",
        describe(params),
        path.display(),
        generated.assets.len()
    )?;
    Ok(())
}

/// Writes every member of a family and the index `family.txt`.
fn write_family(args: &FamilyArgs) -> Result<(), String> {
    let family = Family::ALL
        .into_iter()
        .find(|i| i.name() == args.kind)
        .ok_or_else(|| {
            format!(
                "--kind {}: expected di, pt, di-motion or pt-motion",
                args.kind
            )
        })?;
    let split = if args.split == "train" {
        Split::Train
    } else {
        Split::Test
    };
    if args.xml && family.animated() {
        return Err(format!(
            "--xml: the {} family is animated, and Mitsuba 3 XML describes one instant (the \
             static families pt and di convert)",
            family.name()
        ));
    }
    let members: Vec<FamilyMember> = members(family, split);
    if let Some(i) = args.index {
        let member = members.get(i).ok_or_else(|| {
            format!(
                "--index {i}: the {} family has members 0 to {}",
                family.name(),
                members.len() - 1
            )
        })?;
        let generated = member.generate().map_err(|e| e.to_string())?;
        let path = generated
            .write(&args.out, &member.name())
            .map_err(|e| e.to_string())?;
        if args.xml {
            write_xml(&generated, &path)?;
        }
        tell!(
            "{}, seed {} -> {} (+{} assets)",
            describe_member(member),
            member.seed,
            path.display(),
            generated.assets.len()
        )?;
        return Ok(());
    }
    let mut index = format!(
        "# The {} {} family: written by `restir generate family --kind {} --split {} --out DIR`.\n\
         # Regenerate rather than edit. One line per scene: file, seed, kind and parameters.\n\
         # Training seeds start at 1, test seeds at 101 (the splits never share a scene).\n",
        family.name(),
        split.name(),
        family.name(),
        split.name()
    );
    for member in &members {
        let generated = member.generate().map_err(|e| e.to_string())?;
        let path = generated
            .write(&args.out, &member.name())
            .map_err(|e| e.to_string())?;
        if args.xml {
            write_xml(&generated, &path)?;
        }
        let assets: Vec<&str> = generated
            .assets
            .iter()
            .map(|a| a.filename.as_str())
            .collect();
        index.push_str(&format!(
            "{}.ron\tseed {}\t{}{}\n",
            member.name(),
            member.seed,
            describe_member(member),
            if assets.is_empty() {
                String::new()
            } else {
                format!("\tassets: {}", assets.join(" "))
            }
        ));
        tell!("{}", path.display())?;
    }
    let path = args.out.join("family.txt");
    restir_image::write_file_atomically(&path, index.as_bytes()).map_err(|e| e.to_string())?;
    tell!("{} scenes, index {}", members.len(), path.display())?;
    Ok(())
}

/// Writes a generated scene, just written as `ron`, as Mitsuba 3 XML beside it.
fn write_xml(generated: &Generated, ron: &std::path::Path) -> Result<(), String> {
    let header = format!(
        "{}\nWritten as Mitsuba 3 XML by `restir generate family --xml` beside {}; regenerate \
         rather than edit.",
        generated.header.trim_end(),
        ron.file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("the RON file")
    );
    crate::convert::write_xml(&generated.desc, ron, &ron.with_extension("xml"), header)
}

/// Writes one many-light scene (`restir generate rects|spheres|meshes`).
fn write_di(kind: Kind, args: DiArgs) -> Result<(), String> {
    write_one(&di_params(kind, &args)?, args.seed, args.output)
}

/// Writes one glossy room (`restir generate room`).
fn write_room(args: RoomArgs) -> Result<(), String> {
    let glass = Glass::ALL
        .into_iter()
        .find(|g| g.name() == args.glass)
        .ok_or_else(|| format!("--glass {}: expected none, smooth or rough", args.glass))?;
    let params = Params::Room(RoomOptions {
        glass,
        window: args.window,
        lamps: args.lamps,
    });
    write_one(&params, args.seed, args.output)
}

/// Writes a scene with small lamps added (`restir generate lamps`).
fn write_lamps(args: LampsArgs) -> Result<(), String> {
    let ext = args.scene.extension().and_then(|e| e.to_str());
    if ext != Some("xml") {
        return Err(format!(
            "--scene {}: expected a Mitsuba 3 XML file (.xml): only XML scenes can be included",
            args.scene.display()
        ));
    }
    let loaded = restir_scene::load_scene(&args.scene, &restir_scene::LoadOptions::default())
        .map_err(|e| e.to_string())?;
    let lamps = restir_families::added_lamps(&loaded.scene, args.lamps, args.seed);
    if lamps.is_empty() {
        return Err(format!(
            "{}: no lamp could be placed (the rays from the camera's position hit nothing)",
            args.scene.display()
        ));
    }
    let included =
        std::fs::canonicalize(&args.scene).map_err(|e| format!("{}: {e}", args.scene.display()))?;
    let included = included
        .to_str()
        .ok_or_else(|| format!("{}: not a UTF-8 path", included.display()))?;
    let header = format!(
        "Written by `restir generate lamps --scene {} --lamps {} --seed {}`: the scene, included\n\
         (not copied), with {} small emissive spheres added by the rule of docs/SCENES.md\n\
         (powers over {}x). Regenerate rather than edit.",
        args.scene.display(),
        args.lamps,
        args.seed,
        lamps.len(),
        restir_families::ADDED_LAMPS_POWER_RATIO,
    );
    let text = restir_families::added_lamps_xml(included, &lamps, &header);
    restir_image::write_file_atomically(&args.output, text.as_bytes())
        .map_err(|e| e.to_string())?;
    tell!(
        "{} lamps added to {} -> {}",
        lamps.len(),
        args.scene.display(),
        args.output.display()
    )?;
    Ok(())
}
