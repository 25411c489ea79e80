//! `nacre export`: one quantity of a film-lut or rough-film-lut table as a raw 3-D texture
//! for a game engine, with its JSON sidecar; or a multilayer stack prepared for the engine
//! libraries' `film_stack` as one JSON.

use crate::args::{ColourArgs, StackArgs, load_stack};
use crate::choices::ChannelArg;
use crate::error::Result;
use clap::{ArgGroup, Args};
use nacre_format::set;
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Examples:
  nacre export --table soap-film --quantity reflectance --out soap-film.reflectance.raw
  nacre export --table rough-film-dielectric --quantity transmittance --out rough.t.raw
  nacre export --layer mgf2@100 --layer tio2@60 --substrate ag --relative 0 --relative 20 \\
      --out stack.json
Loading the raw file or the stack JSON in Unity, Unreal, three.js and Bevy: docs/engines/.";

#[derive(Args)]
#[command(group(ArgGroup::new("what").required(true).args(["table", "layers", "recipe"])))]
pub struct ExportArgs {
    /// A default-set table name (e.g. soap-film) or a manifest path.
    #[arg(long, value_name = "NAME|PATH", conflicts_with_all = [
        "layers", "recipe", "ambient", "substrate", "relative", "layer_channels",
        "wavelengths", "observer", "illuminant", "space",
    ])]
    table: Option<String>,
    /// reflectance or transmittance (with --table).
    #[arg(long, default_value = "reflectance", conflicts_with_all = ["layers", "recipe"])]
    quantity: String,
    /// Instead of --table: the stack (1 to 8 films) to prepare for film_stack.
    #[command(flatten)]
    stack: StackArgs,
    /// With a stack: each film's relative thickness r, nm (repeat once per film, top first;
    /// film j spans d_j ± r_j over the thickness map) [default: 0 for every film].
    #[arg(long = "relative", value_name = "NM", allow_hyphen_values = true)]
    relative: Vec<f64>,
    /// With a stack: the thickness-map channel each film follows (repeat once per film, top
    /// first; the top film's is r) [default: r for every film].
    #[arg(long = "layer-channel", value_name = "C", value_enum)]
    layer_channels: Vec<ChannelArg>,
    /// With a stack: a fixed rule of N wavelengths (1 to 256) [default: the rule ladder,
    /// chosen per pixel].
    #[arg(long, value_name = "N")]
    wavelengths: Option<usize>,
    /// With a stack: the colour settings of its node weights.
    #[command(flatten)]
    colour: ColourArgs,
    /// The file to write: with --table the raw file (e.g. soap-film.reflectance.raw; the
    /// sidecar is the same path with extension .json), with a stack the JSON (e.g.
    /// stack.json). Written atomically.
    #[arg(long, value_name = "PATH")]
    out: PathBuf,
}

pub fn run(args: &ExportArgs) -> Result<()> {
    let Some(table) = &args.table else {
        return run_stack(args);
    };
    let path = set::resolve_table(table);
    let texture = nacre_format::export::export_raw(&path, &args.quantity)?;
    let sidecar = nacre_format::export::write_raw(&args.out, &texture)?;
    eprintln!(
        "nacre export: {} ({} × {} × {} RGBA16F) and {}",
        args.out.display(),
        texture.width,
        texture.height,
        texture.depth,
        sidecar.display()
    );
    Ok(())
}

/// A stack: its JSON for the engine libraries.
fn run_stack(args: &ExportArgs) -> Result<()> {
    use nacre_bake::commands::export_stack::{StackExport, stack_export};
    let (spec, _, _) = load_stack(&args.stack)?;
    let channels: Vec<usize> = args.layer_channels.iter().map(|c| c.index()).collect();
    let json = stack_export(&StackExport {
        spec: &spec,
        relative_nm: &args.relative,
        channels: &channels,
        samples: args.wavelengths,
        colour: args.colour.settings(),
    })?;
    nacre_format::export::write_json(&args.out, &json)?;
    eprintln!(
        "nacre export: {} (film_stack: {} films, {} nodes, stack table {} × {} RGBA32F)",
        args.out.display(),
        json["shader_params"]["films"],
        json["node_count"],
        json["texture"]["width"],
        json["texture"]["height"],
    );
    Ok(())
}
