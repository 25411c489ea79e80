//! `nacre spectrum`: exact reflectance/transmittance of a stack over angle × wavelength, as CSV.

use crate::args::{StackArgs, load_stack};
use crate::error::Result;
use clap::Args;
use nacre_bake::commands::grid::parse_range;
use nacre_bake::commands::spectrum;
use nacre_format::atomic::write_atomic;
use nacre_format::{Origin, Param, msg};
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Materials (M): a real index `1.33`, a complex index `0.27+2.9i`, a bundled name
(`nacre materials` lists them), a path to a refractiveindex.info .yml or a
wavelength_nm,n,k .csv file, or a refractiveindex.info page SHELF/BOOK/PAGE
(`main/Au/Johnson`) with --material-db DIR. Thickness: nanometres, `635` or `635nm` (or `1.2um`).

Examples:
  # the default: a 400 nm soap film (index 1.33) in vacuum (1.0), 0:89:1 degrees ×
  # 380:780:5 nm, to stdout
  nacre spectrum
  # quarter-wave MgF2 anti-reflection coating on BK7 glass, to a file
  nacre spectrum --layer mgf2@99.75nm --substrate bk7 -o ar-coating.csv
  # 30 nm gold on glass at 45 degrees, every nanometre
  nacre spectrum --layer au@30 --substrate 1.52 --angles 45 --wavelengths 380:780:1
  # oil slick: oil film on water, seen from air
  nacre spectrum --ambient air --layer oil@450 --substrate water -o oil.csv
  # the same stack from a recipe file (docs/guide/src/spectrum.md, \"Stack recipes\")
  nacre spectrum --recipe tables/examples/ar-coating.toml -o ar.csv
  # with dR/dd and dT/dd of both films, per nm, after the usual columns
  nacre spectrum --layer tio2@60 --layer mgf2@100 --substrate bk7 --angles 0 --jacobian";

#[derive(Args)]
pub struct SpectrumArgs {
    #[command(flatten)]
    stack: StackArgs,
    /// Incidence angles in the ambient, degrees: START:END:STEP or one value [default: 0:89:1].
    #[arg(long, value_name = "START:END:STEP", allow_hyphen_values = true)]
    angles: Option<String>,
    /// Vacuum wavelengths in nm: START:END:STEP or one value [default: 380:780:5].
    #[arg(long, value_name = "START:END:STEP", allow_hyphen_values = true)]
    wavelengths: Option<String>,
    /// Output CSV file, or `-` for standard output.
    #[arg(
        short = 'o',
        long = "output",
        value_name = "FILE.csv",
        default_value = "-"
    )]
    output: PathBuf,
    /// Append the derivatives of the unpolarised R and T columns by each film's thickness,
    /// per nm: `dR_dd1 … dR_ddL, dT_dd1 … dT_ddL` (films top first; exact, not finite
    /// differences). Coherent stacks only.
    #[arg(long)]
    jacobian: bool,
}

pub fn run(args: &SpectrumArgs) -> Result<()> {
    let (spec, recipe_angles, recipe_wavelengths) = load_stack(&args.stack)?;
    let range = |flag: Param, given: &Option<String>, recipe: Option<String>, default: &str| {
        let (context, text) = match (given, recipe) {
            (Some(t), _) => (Origin::from(flag), t.clone()),
            (None, Some(t)) => (msg![flag, " (from the recipe)"].into(), t),
            (None, None) => (Origin::from(flag), default.to_string()),
        };
        parse_range(context, &text)
    };
    let angles = range(Param::Angles, &args.angles, recipe_angles, "0:89:1")?;
    let wavelengths = range(
        Param::Wavelengths,
        &args.wavelengths,
        recipe_wavelengths,
        "380:780:5",
    )?;
    let stack = spec.build()?;
    if args.jacobian {
        let (powers, jacobian) = spectrum::compute_jacobian(&stack, &angles, &wavelengths)?;
        crate::error::warn(&stack.undersampled_films(&wavelengths));
        return Ok(write_atomic(&args.output, |w| {
            spectrum::write_csv_jacobian(w, &angles, &wavelengths, &powers, &jacobian)
        })?);
    }
    let powers = spectrum::compute(&stack, &angles, &wavelengths)?;
    crate::error::warn(&stack.undersampled_films(&wavelengths));
    Ok(write_atomic(&args.output, |w| {
        spectrum::write_csv(w, &angles, &wavelengths, &powers)
    })?)
}
