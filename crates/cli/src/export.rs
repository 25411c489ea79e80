//! `nacre export`: one quantity of a film-lut or rough-film-lut table as a raw 3-D texture
//! for a game engine, with its JSON sidecar.

use crate::error::Result;
use clap::Args;
use nacre_format::set;
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Examples:
  nacre export --table soap-film --quantity reflectance --out soap-film.reflectance.raw
  nacre export --table rough-film-dielectric --quantity transmittance --out rough.t.raw
Loading the raw file in Unity, Unreal and three.js: docs/engines/.";

#[derive(Args)]
pub struct ExportArgs {
    /// A default-set table name (e.g. soap-film) or a manifest path.
    #[arg(long, value_name = "NAME|PATH")]
    table: String,
    /// reflectance or transmittance.
    #[arg(long, default_value = "reflectance")]
    quantity: String,
    /// The raw file to write (e.g. soap-film.reflectance.raw); the sidecar is the same
    /// path with extension .json. Both are written atomically.
    #[arg(long, value_name = "PATH")]
    out: PathBuf,
}

pub fn run(args: &ExportArgs) -> Result<()> {
    let path = set::resolve_table(&args.table);
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
