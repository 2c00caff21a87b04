//! `restir generate`: the subcommand's arguments and writing the file; the scenes themselves
//! come from [`restir_scene::generate`].

use std::path::PathBuf;

use restir_scene::generate::many_lights_ron;

/// Scenes the generator can write.
#[derive(clap::Subcommand, Debug)]
pub enum Generate {
    /// A floor with boxes and pillars lit only by many small coloured sphere lights.
    ManyLights(ManyLightsArgs),
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
            std::fs::write(&args.output, text)
                .map_err(|e| format!("{}: {e}", args.output.display()))?;
            println!(
                "many-lights: {} lights, seed {} -> {}",
                args.lights,
                args.seed,
                args.output.display()
            );
            Ok(())
        }
    }
}
