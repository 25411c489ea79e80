//! `nacre conformance`: reference data for glTF KHR_materials_iridescence renderers.

use crate::error::Result;
use clap::Args;
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Writes DIR/conformance.csv (base_ior,angle_deg,thickness_nm,film_ior,X,Y,Z,R,G,B: exact
unpolarised reflectance colour of air | film | base, CIE 1931 2 deg, D65, Y = 1 for a perfect
reflector, linear sRGB), DIR/gltf-reference-error.csv (the glTF reference approximation and
its CIEDE2000), DIR/swatches-<base>.png and DIR/README.md (conventions, glTF mapping, how to
compare a renderer). Bases (base_ior) 1, 1.25, 1.5, 1.75, 2, 2.5, au, ag, cu, al; film index
1.0-2.333; thickness 0-1200 nm; angles 0-89 deg. Every file is written to a temporary file
first and renamed only when all are complete.

Examples:
  # the default grid (48 510 rows, 5 MB of CSV; the copy in docs/conformance/)
  nacre conformance -o docs/conformance
  # a denser grid (202 730 rows, about 21 MB)
  nacre conformance --fine -o conformance-fine
  # a coarse grid for quick checks (2 080 rows)
  nacre conformance --quick -o /tmp/conformance";

#[derive(Args)]
pub struct ConformanceArgs {
    /// A coarse grid for tests: angles 0, 30, 60, 85; thickness step 100 nm; film index 1.0,
    /// 1.3, 1.5, 2.333.
    #[arg(long, conflicts_with = "fine")]
    quick: bool,
    /// A denser grid: angles 0-85 step 5 and 89; thickness step 12.5 nm; film index 1.0-1.8
    /// step 0.1, 2.0, 2.333.
    #[arg(long)]
    fine: bool,
    /// Output folder (created if needed; files of the same names are replaced).
    #[arg(short = 'o', long = "output", value_name = "DIR")]
    output: PathBuf,
}

pub fn run(args: &ConformanceArgs) -> Result<()> {
    use nacre_bake::commands::conformance::{self, GridSize};
    let size = if args.quick {
        GridSize::Quick
    } else if args.fine {
        GridSize::Fine
    } else {
        GridSize::Default
    };
    let start = std::time::Instant::now();
    let set = conformance::write(&args.output, size)?;
    eprintln!(
        "wrote conformance.csv ({} rows), gltf-reference-error.csv, {} swatch charts and README.md in {:.1} s -> {}",
        set.bases.len() * set.grid.points_per_base(),
        set.bases.len(),
        start.elapsed().as_secs_f64(),
        args.output.display()
    );
    Ok(())
}
