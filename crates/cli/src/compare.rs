//! `nacre compare`: the real-time methods against the exact colour over angle × thickness.

use crate::error::Result;
use clap::Args;
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Cases: fig7 (Belcour & Barla 2017 Fig. 7: film 1.5 on base 1.09), dielectric (film 1.5 on
1.5), gold (film 1.5 on gold), soap (film 1.33 in air).

Examples:
  nacre compare -o compare-fig7
  nacre compare --case gold --thicknesses 0:2000:20 -o compare-gold";

#[derive(Args)]
pub struct CompareArgs {
    /// Named case: fig7, dielectric, gold or soap.
    #[arg(long, default_value = "fig7")]
    case: String,
    /// Incidence angles, degrees.
    #[arg(
        long,
        value_name = "START:END:STEP",
        default_value = "0:85:2.5",
        allow_hyphen_values = true
    )]
    angles: String,
    /// Film thicknesses, nm.
    #[arg(
        long,
        value_name = "START:END:STEP",
        default_value = "0:1000:10",
        allow_hyphen_values = true
    )]
    thicknesses: String,
    /// Output folder: compare.csv and compare.png.
    #[arg(short = 'o', long = "output", value_name = "DIR")]
    output: PathBuf,
}

pub fn run(args: &CompareArgs) -> Result<()> {
    use nacre_bake::commands::compare;
    let case = compare::case_named(&args.case)?;
    let (angles, thicknesses) = compare::grid(&args.angles, &args.thicknesses)?;
    let results = compare::compare(case, &angles, &thicknesses)?;
    compare::write(&args.output, case, &angles, &thicknesses, &results)?;
    println!("{}", case.description);
    println!("| method | mean ΔE2000 | p95 | max |");
    println!("|---|---|---|---|");
    for r in &results {
        let (mean, p95, max) = r.summary();
        println!("| `{}` | {mean:.3} | {p95:.3} | {max:.3} |", r.label);
    }
    Ok(())
}
