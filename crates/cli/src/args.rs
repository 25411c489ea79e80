//! Arguments and checks that several commands share: the stack flags (`spectrum`, `color`,
//! `render --technique stack`, `plot`), the colour flags (`color`, `diffraction`) and the
//! diffraction wavelength step (`render`, `bench-gpu`).

use crate::error::Result;
use clap::Args;
use nacre_bake::commands::color_request::ColourSettings;
use nacre_bake::commands::stack_spec::{StackRecipe, StackSpec};
use nacre_format::{Manifest, Param};
use std::path::PathBuf;

/// `--observer`, `--illuminant`, `--space`: shared by `color` and `diffraction`.
#[derive(Args)]
pub struct ColourArgs {
    /// CIE observer: 1931 (2°) or 1964 (10°) [default: 1931, or the table's].
    #[arg(long)]
    observer: Option<String>,
    /// Illuminant: d65, d50, a or e [default: d65, or the table's].
    #[arg(long)]
    illuminant: Option<String>,
    /// Output space: xyz, srgb, rec2020, p3 or acescg (linear) [default: srgb, or the table's].
    #[arg(long)]
    space: Option<String>,
}

impl ColourArgs {
    /// The settings as given (`None`: the table's, else 1931, d65, srgb).
    pub fn settings(&self) -> ColourSettings<'_> {
        ColourSettings {
            observer: self.observer.as_deref(),
            illuminant: self.illuminant.as_deref(),
            space: self.space.as_deref(),
        }
    }
}

#[derive(Args)]
pub struct StackArgs {
    /// Ambient (incidence) medium; must be non-absorbing [default: 1.0, vacuum, at every
    /// wavelength; with a lut:/rough-lut: method and no stack flags, the table's own stack].
    #[arg(long, value_name = "M")]
    pub ambient: Option<String>,
    /// A film, top first; repeat for more films (default with no stack flags: 1.33@400, a
    /// soap film).
    #[arg(long = "layer", value_name = "M@THICKNESS")]
    pub layers: Vec<String>,
    /// Substrate (any index, absorbing allowed) [default: 1.0, vacuum].
    #[arg(long, value_name = "M")]
    pub substrate: Option<String>,
    /// Read the stack (and optional angles/wavelengths) from a TOML recipe instead.
    #[arg(long, value_name = "FILE.toml", conflicts_with_all = ["ambient", "layers", "substrate"])]
    pub recipe: Option<PathBuf>,
}

/// The stack and any ranges a recipe supplied.
pub fn load_stack(
    args: &StackArgs,
) -> nacre_bake::Result<(StackSpec, Option<String>, Option<String>)> {
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

/// Default wavelength step of the terms technique's colour sum, nm (`nacre render
/// --wavelength-step`, `nacre bench-gpu --diffraction-step`).
pub const DEFAULT_WAVELENGTH_STEP_NM: f64 = 10.0;

/// An integrated `diffraction` table's wavelength sum was done at bake time: refuses `flag`
/// when it was given for one.
pub fn refuse_step_for_integrated(
    flag: Param,
    step_nm: Option<f64>,
    manifest: &Manifest,
) -> Result<()> {
    match step_nm {
        None => Ok(()),
        Some(step_nm) => Err(nacre_bake::error::Error::invalid(flag, format!(
                "{step_nm} nm: table `{}` has the layout \"integrated\", whose wavelength sum was done at bake time (the manifest's grid); the step applies to layout \"terms\" tables only",
                manifest.name
            ))
        .into()),
    }
}
