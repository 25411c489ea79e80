//! The `nacre` binary's error: the libraries' errors side by side, displayed as
//! `nacre: error: …` with exit status 2 by `main`.
//!
//! The libraries name the inputs that went wrong with [`Param`] values; [`Flags`] spells
//! each as the flag (or argument) that supplies it, from the one table [`flag`].

use nacre_format::param::{Naming, Param, Render};
use std::fmt;

/// The flag (or positional argument) that supplies `param` on nacre's command line.
pub fn flag(param: Param) -> &'static str {
    match param {
        Param::Angles => "--angles",
        Param::Angle => "--angle",
        Param::Thickness => "--thickness",
        Param::Thicknesses => "--thicknesses",
        Param::Wavelengths => "--wavelengths",
        Param::Method => "--method",
        Param::Methods => "--methods",
        Param::Observer => "--observer",
        Param::Illuminant => "--illuminant",
        Param::Space => "--space",
        Param::Roughness => "--roughness",
        Param::FourierTable => "--fourier-table",
        Param::Ambient => "--ambient",
        Param::Layer => "--layer",
        Param::Substrate => "--substrate",
        Param::MaterialDb => "--material-db",
        Param::Points => "--points",
        Param::Quantity => "--quantity",
        Param::Quantities => "--quantities",
        Param::Color => "--color",
        Param::Case => "--case",
        Param::FilmIors => "--film-iors",
        Param::MaxOpd => "--max-opd",
        Param::Gamut => "--gamut",
        Param::Output => "-o/--output",
        Param::Surface => "FILE|SPEC",
        Param::Table => "--table",
        Param::Tables => "--tables",
        Param::Out => "--out",
        Param::Layout => "--layout",
        Param::IntegratedSamples => "--integrated-samples",
        Param::Pitch => "--pitch",
        Param::Samples => "--samples",
        Param::HeightScale => "--height-scale",
        Param::Coherence => "--coherence",
        Param::Fresnel => "--fresnel",
        Param::Incidence => "--incidence",
        Param::Views => "--views",
        Param::MaxView => "--max-view",
        Param::Cells => "--cells",
        Param::Exposure => "--exposure",
        Param::WavelengthStep => "--wavelength-step",
        Param::DiffractionStep => "--diffraction-step",
        Param::EnvSamples => "--env-samples",
        Param::ReferenceSamples => "--reference-samples",
    }
}

/// The placeholder a flag's help shows for its value, where a message asks for the flag
/// with one (`--roughness ALPHA`).
fn placeholder(param: Param) -> Option<&'static str> {
    match param {
        Param::Roughness => Some("ALPHA"),
        Param::MaterialDb => Some("DIR"),
        _ => None,
    }
}

/// The command line's [`Naming`]: parameters as flags.
pub struct Flags;

impl Naming for Flags {
    fn name(&self, param: Param) -> &'static str {
        flag(param)
    }

    fn arg(&self, param: Param) -> String {
        match placeholder(param) {
            Some(p) => format!("{} {p}", flag(param)),
            None => flag(param).to_string(),
        }
    }
}

/// Everything a command can fail with.
#[derive(Debug)]
pub enum CliError {
    /// Recipes, commands, materials, tables through nacre-bake.
    Bake(nacre_bake::Error),
    /// Reading or writing tables and files directly.
    Format(nacre_format::Error),
    /// The GPU runtime (`render`, `bench-gpu`).
    Runtime(nacre_runtime::Error),
}

/// Shorthand for the commands' results.
pub type Result<T, E = CliError> = std::result::Result<T, E>;

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Bake(e) => e.render(f, &Flags),
            CliError::Format(e) => e.render(f, &Flags),
            // Table, physics and file errors name their file or value themselves; the
            // runtime's own errors are said to come from the render.
            CliError::Runtime(
                e @ (nacre_runtime::Error::Table(_)
                | nacre_runtime::Error::Optics(_)
                | nacre_runtime::Error::Io { .. }),
            ) => e.render(f, &Flags),
            CliError::Runtime(e) => write!(f, "render: {}", e.named(&Flags)),
        }
    }
}

impl std::error::Error for CliError {}

impl From<nacre_bake::Error> for CliError {
    fn from(e: nacre_bake::Error) -> Self {
        CliError::Bake(e)
    }
}

impl From<nacre_format::Error> for CliError {
    fn from(e: nacre_format::Error) -> Self {
        CliError::Format(e)
    }
}

impl From<nacre_runtime::Error> for CliError {
    fn from(e: nacre_runtime::Error) -> Self {
        CliError::Runtime(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_parameter_has_a_distinct_flag() {
        let mut seen = std::collections::HashSet::new();
        for &p in Param::ALL {
            assert!(seen.insert(flag(p)), "{p:?}: {} twice", flag(p));
        }
    }
}
