//! `nacre`: bake thin-film interference tables and spectra.

// `!(x > 0.0)` is how this crate rejects NaN together with out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use clap::{Args, Parser, Subcommand};
use nacre_bake::error::Result;
use nacre_bake::grid::parse_range;
use nacre_bake::output::write_atomic;
use nacre_bake::stack_spec::{StackRecipe, StackSpec};
use nacre_bake::{materials, spectrum};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "nacre",
    version,
    about = "Bake lookup tables and spectra for real-time structural colour (thin-film interference)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Exact reflectance/transmittance of a multilayer stack over angle × wavelength, as CSV.
    #[command(after_help = SPECTRUM_EXAMPLES)]
    Spectrum(SpectrumArgs),
    /// List the bundled materials.
    Materials,
}

const SPECTRUM_EXAMPLES: &str = "\
Materials (M): a real index `1.33`, a complex index `0.27+2.9i`, a bundled name
(`nacre materials` lists them), or a path to a refractiveindex.info .yml or a
wavelength_nm,n,k .csv file. Thickness: nanometres, `635` or `635nm` (or `1.2um`).

Examples:
  # the default: a 400 nm soap film in air, 0:89:1 degrees × 380:780:5 nm, to stdout
  nacre spectrum
  # quarter-wave MgF2 anti-reflection coating on BK7 glass, to a file
  nacre spectrum --layer mgf2@99.75nm --substrate bk7 -o ar-coating.csv
  # 30 nm gold on glass at 45 degrees, every nanometre
  nacre spectrum --layer au@30 --substrate 1.52 --angles 45 --wavelengths 380:780:1
  # oil slick: oil film on water, seen from air
  nacre spectrum --ambient air --layer oil@450 --substrate water -o oil.csv
  # the same stack from a recipe file (see README)
  nacre spectrum --recipe tables/examples/ar-coating.toml -o ar.csv";

#[derive(Args)]
struct StackArgs {
    /// Ambient (incidence) medium; must be non-absorbing [default: air].
    #[arg(long, value_name = "M")]
    ambient: Option<String>,
    /// A film, top first; repeat for more films [default with no stack flags: water@400].
    #[arg(long = "layer", value_name = "M@THICKNESS")]
    layers: Vec<String>,
    /// Substrate (any index, absorbing allowed) [default: air].
    #[arg(long, value_name = "M")]
    substrate: Option<String>,
    /// Read the stack (and optional angles/wavelengths) from a TOML recipe instead.
    #[arg(long, value_name = "FILE.toml", conflicts_with_all = ["ambient", "layers", "substrate"])]
    recipe: Option<PathBuf>,
}

#[derive(Args)]
struct SpectrumArgs {
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
}

/// The stack and any ranges a recipe supplied.
fn load_stack(args: &StackArgs) -> Result<(StackSpec, Option<String>, Option<String>)> {
    match &args.recipe {
        Some(path) => {
            let r = StackRecipe::read(path)?;
            Ok((r.stack, r.angles, r.wavelengths))
        }
        None => Ok((
            StackSpec::from_flags(
                args.ambient.as_deref(),
                &args.layers,
                args.substrate.as_deref(),
            )?,
            None,
            None,
        )),
    }
}

fn run_spectrum(args: &SpectrumArgs) -> Result<()> {
    let (spec, recipe_angles, recipe_wavelengths) = load_stack(&args.stack)?;
    let range = |flag: &str, given: &Option<String>, recipe: Option<String>, default: &str| {
        let (context, text) = match (given, recipe) {
            (Some(t), _) => (flag.to_string(), t.clone()),
            (None, Some(t)) => (format!("{flag} (from the recipe)"), t),
            (None, None) => (flag.to_string(), default.to_string()),
        };
        parse_range(&context, &text)
    };
    let angles = range("--angles", &args.angles, recipe_angles, "0:89:1")?;
    let wavelengths = range(
        "--wavelengths",
        &args.wavelengths,
        recipe_wavelengths,
        "380:780:5",
    )?;
    let stack = spec.build()?;
    let powers = spectrum::compute(&stack, &angles, &wavelengths)?;
    write_atomic(&args.output, |w| {
        spectrum::write_csv(w, &angles, &wavelengths, &powers)
    })
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Spectrum(args) => run_spectrum(&args),
        Command::Materials => {
            for b in materials::BUNDLED {
                let m = materials::load_bundled(b)?;
                let (lo, hi) = m.range_nm();
                println!(
                    "{:<13} {:>7.1}–{:<8.1} nm  {}",
                    b.name, lo, hi, b.description
                );
            }
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => e.exit(), // usage errors exit with status 2, --help/--version with 0
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("nacre: error: {e}");
            ExitCode::from(2)
        }
    }
}
