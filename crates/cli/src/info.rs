//! `nacre info`: a baked table's manifest as JSON.

use crate::error::Result;
use clap::Args;
use nacre_format::{Manifest, set};

#[derive(Args)]
pub struct InfoArgs {
    /// A default-set table name (e.g. film-dielectric) or a manifest path.
    #[arg(value_name = "NAME|PATH")]
    table: String,
}

pub fn run(args: &InfoArgs) -> Result<()> {
    let path = set::resolve_table(&args.table);
    let manifest = Manifest::read(&path)?;
    println!(
        "{}",
        serde_json::to_string_pretty(&manifest).expect("manifest serialises")
    );
    Ok(())
}
