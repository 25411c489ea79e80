//! `nacre fit`: from a look or a measurement back to parameters. `nacre fit gltf`: the
//! closest glTF `KHR_materials_iridescence` material to a stack.

use crate::args::{StackArgs, load_stack};
use crate::error::Result;
use clap::{Args, Subcommand};
use nacre_bake::commands::fit_gltf;
use nacre_format::atomic::write_atomic;
use std::path::PathBuf;

pub const GLTF_EXAMPLES: &str = "\
The material's glTF reference evaluation (nacre color --method gaussian: Belcour & Barla's
Gaussian-fit closed form, Schlick Fresnel, mixed with the base's Fresnel by
iridescenceFactor) is compared in CIEDE2000 with the stack's exact colour (linear sRGB, D65)
at 0-85 degrees every 5, over the top film's thickness range when --thicknesses is given
(the range a thickness texture maps). The error of the fitted material and of the naive
mapping (top film's index and thickness, substrate's index or colour) go to stderr.

Examples:
  # the closest glTF film to a 3-layer stack on glass, as a material object
  nacre fit gltf --layer tio2@120 --layer sio2@180 --layer tio2@90 --substrate bk7 -o material.json
  # an oil slick whose thickness varies 200-800 nm over a thickness texture
  nacre fit gltf --layer oil@500 --substrate water --thicknesses 200:800 -o oil.json
  # anodised titanium: an oxide film on a metal gives a metallic base
  nacre fit gltf --layer tio2@60 --substrate 2.5+3.4i";

#[derive(Args)]
pub struct FitArgs {
    #[command(subcommand)]
    command: FitCommand,
}

#[derive(Subcommand)]
enum FitCommand {
    /// The glTF KHR_materials_iridescence material (iridescenceIor, thickness minimum and
    /// maximum, factor, KHR_materials_ior or a metallic base colour) closest in CIEDE2000
    /// to a stack's exact colour over 0-85 degrees, as glTF JSON.
    #[command(after_help = GLTF_EXAMPLES)]
    Gltf(GltfArgs),
}

#[derive(Args)]
pub struct GltfArgs {
    #[command(flatten)]
    stack: StackArgs,
    /// The top film's thickness varies over START:END nm (as a thickness texture maps it
    /// from 0 to 1) [default: the film's own thickness].
    #[arg(long, value_name = "START:END")]
    thicknesses: Option<String>,
    /// Output JSON file (the material object), or `-` for standard output.
    #[arg(
        short = 'o',
        long = "output",
        value_name = "FILE.json",
        default_value = "-"
    )]
    output: PathBuf,
}

pub fn run(args: &FitArgs) -> Result<()> {
    match &args.command {
        FitCommand::Gltf(args) => gltf(args),
    }
}

fn gltf(args: &GltfArgs) -> Result<()> {
    let range = args
        .thicknesses
        .as_deref()
        .map(fit_gltf::parse_thickness_range)
        .transpose()?;
    let (spec, _, _) = load_stack(&args.stack)?;
    let stack = spec.build()?;
    let report = fit_gltf::fit_gltf(&stack, range).map_err(|e| spec.attribute(&stack, e))?;
    let json = fit_gltf::material_json(&report.fit.film, "nacre fit gltf");
    write_atomic(&args.output, |w| {
        serde_json::to_writer_pretty(&mut *w, &json).map_err(std::io::Error::other)?;
        writeln!(w)
    })?;
    let (f, n) = (report.fit.errors, report.naive_errors);
    eprintln!(
        "fitted: ΔE2000 mean {:.2}, max {:.2} ({})",
        f.mean,
        f.max,
        fit_gltf::describe(&report.fit.film)
    );
    eprintln!(
        "naive:  ΔE2000 mean {:.2}, max {:.2} ({})",
        n.mean,
        n.max,
        fit_gltf::describe(&report.naive)
    );
    Ok(())
}
