//! The `nacre` binary's error: the libraries' errors side by side, displayed as
//! `nacre: error: …` by `main`, with exit status 2, or 3 where no usable GPU was found
//! ([`CliError::exit_status`]).
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
        Param::Relative => "--relative",
        Param::LayerChannel => "--layer-channel",
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
        Param::Camera => "--camera",
        Param::Yaw => "--yaw",
        Param::Distance => "--distance",
        Param::Jacobian => "--jacobian",
        Param::BenchFilmIor => "--film-ior",
        Param::BenchBaseIor => "--base-ior",
        Param::Measured => "MEASURED",
        Param::Scale => "--scale",
        Param::Offset => "--offset",
        Param::FitRange => "--range",
        Param::Loss => "--loss",
        Param::Residuals => "--residuals",
        Param::Targets => "TARGETS",
        Param::Solutions => "--solutions",
        Param::Distinct => "--distinct",
        Param::FitPlot => "--plot",
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

/// The exit status when no usable GPU was found (documented in the top-level help).
pub const NO_GPU_STATUS: u8 = 3;

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

impl CliError {
    /// The exit status for this error: [`NO_GPU_STATUS`] where no usable GPU was found (no
    /// adapter, or it refused a device), 2 for everything else (bad input, a refused or
    /// failed command, a wgpu error or a lost device).
    pub fn exit_status(&self) -> u8 {
        match self {
            CliError::Runtime(e) if e.is_no_gpu() => NO_GPU_STATUS,
            _ => 2,
        }
    }

    /// True when the error is a write into a closed pipe (`nacre spectrum | head`): the
    /// reader has what it wanted, and Unix tools end quietly then.
    pub fn is_broken_pipe(&self) -> bool {
        let mut next: Option<&(dyn std::error::Error + 'static)> = Some(match self {
            CliError::Bake(e) => e,
            CliError::Format(e) => e,
            CliError::Runtime(e) => e,
        });
        let broken = |io: &std::io::Error| io.kind() == std::io::ErrorKind::BrokenPipe;
        while let Some(e) = next {
            if let Some(io) = e.downcast_ref::<std::io::Error>() {
                if broken(io) {
                    return true;
                }
                // An error wrapped into an I/O error (the CSV writer's): look inside it.
                next = io
                    .get_ref()
                    .map(|inner| inner as &(dyn std::error::Error + 'static));
            } else if let Some(c) = e.downcast_ref::<csv::Error>() {
                // The CSV writer keeps the I/O error in its kind, not as a source.
                return matches!(c.kind(), csv::ErrorKind::Io(io) if broken(io));
            } else {
                next = e.source();
            }
        }
        false
    }
}

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

#[cfg(test)]
mod pipe_tests {
    use super::*;

    #[test]
    fn broken_pipes_are_found_through_wrappers() {
        let io = || std::io::Error::from(std::io::ErrorKind::BrokenPipe);
        let direct = CliError::Format(nacre_format::Error::Io {
            path: "-".into(),
            source: io(),
        });
        let mut chain = String::new();
        let mut next: Option<&(dyn std::error::Error + 'static)> = match &direct {
            CliError::Format(e) => Some(e),
            _ => None,
        };
        while let Some(e) = next {
            chain.push_str(&format!("[{e:?}] "));
            next = e.source();
        }
        assert!(direct.is_broken_pipe(), "{chain}");
        // The CSV writer's error inside an I/O error of kind Other.
        let csv_error = {
            let mut w = csv::Writer::from_writer(Failing);
            w.write_record(["a"])
                .and_then(|()| w.flush().map_err(csv::Error::from))
        }
        .unwrap_err();
        let wrapped = CliError::Format(nacre_format::Error::Io {
            path: "-".into(),
            source: std::io::Error::other(csv_error),
        });
        assert!(wrapped.is_broken_pipe(), "{wrapped:?}");
        let other = CliError::Format(nacre_format::Error::Io {
            path: "-".into(),
            source: std::io::Error::from(std::io::ErrorKind::PermissionDenied),
        });
        assert!(!other.is_broken_pipe());
    }

    /// A writer whose reader has gone.
    struct Failing;
    impl std::io::Write for Failing {
        fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
            Err(std::io::ErrorKind::BrokenPipe.into())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Err(std::io::ErrorKind::BrokenPipe.into())
        }
    }
}

/// Prints a library's warnings (`nacre: warning: …`, one line each) on stderr: the
/// libraries return them, the binary shows them.
pub fn warn<W: fmt::Display>(warnings: &[W]) {
    for w in warnings {
        eprintln!("nacre: warning: {w}");
    }
}
