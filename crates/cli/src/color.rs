//! `nacre color`: the colour of a stack's reflectance or transmittance by a chosen method, as CSV.

use crate::args::{ColourArgs, StackArgs, load_stack};
use crate::choices::QuantityArg;
use crate::error::Result;
use clap::Args;
use nacre_bake::commands::stack_spec::StackSpec;
use nacre_format::Manifest;
use nacre_format::atomic::write_atomic;
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Methods: spectral (exact reference), lut:NAME|PATH (a baked film-lut, default-set name or
manifest path), rgb3 (650/510/475 nm), samples:N (N wavelengths over 400-700 nm),
fourier | fourier:M | fourier:auto [:SIGMA_NM] (Belcour & Barla 2017 Eq. 10 with exact
Fresnel, the baked fourier table sampled as a GPU would, optional prefiltering for a
thickness standard deviation; fourier alone is fourier:auto, the GPU's default: per point
as many harmonics as ΔE2000 p95 <= 0.1 needs), fourier-exact… (the same with exact
transforms), gaussian (the glTF
KHR_materials_iridescence Gaussian-fit approximation), rough-lut:NAME|PATH with --roughness
ALPHA (the directional albedo of the rough GGX film lobe from a baked rough-film-lut table),
rough-mc[:N] with --roughness ALPHA (its Monte Carlo reference, N samples per point,
default 2^20; the largest standard error is printed on stderr), stack | stack:N (the GPU
technique film_stack for any stack of 1 to 8 films: a few wavelengths uniform in
wavenumber with weights fitted to the colour-matching functions, the count chosen from the
stack's optical thickness, or N of them; a stack with one incoherent slab is the GPU
technique film_glass: the films above and below the slab exact, the slab in intensity).

Examples:
  # colour of a 400 nm soap film over angle, exact
  nacre color --layer 1.33@400 --angles 0:85:5
  # the same from the baked default table
  nacre color --ambient 1.0 --layer 1.33@400 --substrate 1.0 --angles 0:85:5 --method lut:soap-film
  # points (angle_deg,thickness_nm,film_ior) on the glTF default base, in Rec.2020
  nacre color --ambient 1.0 --layer 1.5@0 --substrate 1.5 --points points.csv --space rec2020
  # transmittance colour, CIE 1964 observer under illuminant A
  nacre color --layer water@600 --quantity t --observer 1964 --illuminant a
  # directional albedo of a rough film (GGX alpha 0.3) from the table, and its Monte Carlo reference
  nacre color --ambient 1.0 --layer 1.33@400 --substrate 1.5 --angles 0:80:10 --method rough-lut:rough-film-dielectric --roughness 0.3
  nacre color --ambient 1.0 --layer 1.33@400 --substrate 1.5 --angles 0:80:10 --method rough-mc --roughness 0.3";

#[derive(Args)]
pub struct ColorArgs {
    #[command(flatten)]
    stack: StackArgs,
    /// Incidence angles in the ambient, degrees [default: 0:89:1]; the film keeps its own
    /// thickness and index.
    #[arg(
        long,
        value_name = "START:END:STEP",
        allow_hyphen_values = true,
        conflicts_with = "points"
    )]
    angles: Option<String>,
    /// Points CSV with columns angle_deg,thickness_nm,film_ior; each row overrides the first
    /// film's thickness and real index.
    #[arg(long, value_name = "FILE.csv")]
    points: Option<PathBuf>,
    /// spectral | lut:NAME|PATH | rgb3 | samples:N | fourier:… | stack | stack:N | … (below).
    #[arg(long, default_value = "spectral")]
    method: String,
    /// The fourier table for fourier:… methods: a default-set name or a manifest path
    /// [default: the default-set table matching --space, --illuminant and --observer].
    #[arg(long, value_name = "NAME|PATH")]
    fourier_table: Option<String>,
    /// r (reflectance) or t (transmittance into the base).
    #[arg(long, value_enum, default_value = "r")]
    quantity: QuantityArg,
    /// GGX roughness α (0 < α ≤ 1) of the rough-lut: and rough-mc methods.
    #[arg(long, value_name = "ALPHA")]
    roughness: Option<f64>,
    #[command(flatten)]
    colour: ColourArgs,
    /// Output CSV file, or `-` for standard output.
    #[arg(
        short = 'o',
        long = "output",
        value_name = "FILE.csv",
        default_value = "-"
    )]
    output: PathBuf,
}

pub fn run(args: &ColorArgs) -> Result<()> {
    use nacre_bake::commands::color::{self, Method, Quantity};
    use nacre_bake::commands::color_request::{self as request, ColorRequest};
    let method = Method::parse(&args.method)?;
    let (mut spec, recipe_angles, _) = load_stack(&args.stack)?;
    // A table method and no stack flags: the stack the table was baked for.
    let s = &args.stack;
    if s.ambient.is_none()
        && s.layers.is_empty()
        && s.substrate.is_none()
        && s.recipe.is_none()
        && let Method::Lut(path) | Method::RoughLut { path, .. } = &method
        && let Some(own) = StackSpec::for_table(&Manifest::read(path)?, path)
    {
        spec = own;
    }
    let quantity = Quantity::from(args.quantity);
    let points = match &args.points {
        Some(path) => request::read_points(path)?,
        None => request::angle_points(args.angles.clone().or(recipe_angles))?,
    };
    let stack = spec.build()?;
    // A material without data (or without a physical index) at a wavelength the method
    // needs: named by the input that gave it.
    let named = |e| spec.attribute(&stack, e);
    let prepared = request::prepare(
        &stack,
        method,
        &ColorRequest {
            method: &args.method,
            roughness: args.roughness,
            colour: args.colour.settings(),
            fourier_table: args.fourier_table.as_deref(),
        },
    )
    .map_err(named)?;
    let out = request::compute(&stack, &points, &prepared, quantity).map_err(named)?;
    crate::error::warn(&out.undersampled);
    if let Some((samples, worst)) = out.monte_carlo {
        eprintln!(
            "rough-mc: {samples} samples per point (seed = point index); largest standard error per channel {worst:.2e}"
        );
    }
    Ok(write_atomic(&args.output, |w| {
        color::write_csv(w, &stack, &points, &out.colours, &prepared.colorimeter)
    })?)
}
