//! `nacre`: bake thin-film interference tables and spectra, and render them on the GPU.
//!
//! This file is the entry and the dispatch: the clap schema's top level and one line per
//! command; each command's flags and body live in its module, the flags several commands
//! share in `args.rs`.

// `!(x > 0.0)` is how this crate rejects NaN together with out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use clap::{Parser, Subcommand};
use nacre_format::Param;
use std::path::PathBuf;
use std::process::ExitCode;

mod args;
mod bake;
mod bench_gpu;
mod choices;
mod color;
mod compare;
mod conformance;
mod diffraction;
mod error;
mod export;
mod fit;
mod gpu;
mod info;
mod materials;
mod plot;
mod render;
mod spectrum;

use error::Result;

#[derive(Parser)]
#[command(
    name = "nacre",
    version,
    about = "Bake lookup tables and spectra for real-time structural colour (thin-film interference).",
    after_help = gpu::HELP
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// A local copy of the refractiveindex.info database (the repository or its database/
    /// folder): material specs SHELF/BOOK/PAGE, e.g. main/Au/Johnson, are read from it
    /// [default: the NACRE_MATERIAL_DB environment variable].
    #[arg(long, global = true, value_name = "DIR")]
    material_db: Option<PathBuf>,
}

#[derive(Subcommand)]
enum Command {
    /// Exact reflectance/transmittance of a multilayer stack over angle × wavelength, as CSV.
    #[command(after_help = spectrum::EXAMPLES)]
    Spectrum(spectrum::SpectrumArgs),
    /// Colour of a stack's reflectance or transmittance by a chosen method, as CSV.
    #[command(after_help = color::EXAMPLES)]
    Color(color::ColorArgs),
    /// Bake lookup tables from recipes (default: every recipe in tables/recipes/ into tables/baked/).
    #[command(after_help = bake::EXAMPLES)]
    Bake(bake::BakeArgs),
    /// Compare the real-time methods with the exact colour over angle × thickness (CSV + PNG).
    #[command(after_help = compare::EXAMPLES)]
    Compare(compare::CompareArgs),
    /// Diffraction by surface nanostructure (Stam 1999; Dhillon et al. 2014): relative
    /// reflectance or colour over view angles for a height field or a baked table, as CSV.
    #[command(after_help = diffraction::EXAMPLES)]
    Diffraction(diffraction::DiffractionArgs),
    /// Pictures (PNG or SVG): spectra, the chromaticity diagram with film trajectories,
    /// swatch charts of film colours, slices of baked tables.
    Plot(plot::PlotArgs),
    /// Reference data for glTF KHR_materials_iridescence renderers: exact colours over the
    /// extension's parameter space (CSV), the glTF approximation's error, swatch charts.
    #[command(after_help = conformance::EXAMPLES)]
    Conformance(conformance::ConformanceArgs),
    /// Write one quantity of a film-lut or rough-film-lut table as a raw 3-D texture for a
    /// game engine (RGBA half floats, little-endian, x fastest, then y, then z) with a JSON
    /// sidecar (dimensions, format, axes, mappings, shader parameters), or a multilayer
    /// stack (--layer …) as the JSON the engine libraries' film_stack reads; docs/engines/.
    #[command(after_help = export::EXAMPLES)]
    Export(export::ExportArgs),
    /// Fit parameters to a target: `nacre fit gltf`, the closest glTF
    /// KHR_materials_iridescence material to a stack.
    Fit(fit::FitArgs),
    /// Print a baked table's manifest as JSON.
    Info(info::InfoArgs),
    /// List the bundled materials.
    Materials,
    /// Render a film-coated sphere, a soap bubble or an oil film on a plane to a PNG (GPU;
    /// any Vulkan/Metal/DX12/GL adapter, including Mesa's software lavapipe).
    #[command(after_help = render::EXAMPLES)]
    Render(render::RenderArgs),
    /// Time full-screen passes of each technique against a plain GGX + Schlick material on
    /// the same adapter (GPU timestamps where supported) and report the ratios.
    #[command(name = "bench-gpu", after_help = bench_gpu::EXAMPLES)]
    BenchGpu(bench_gpu::BenchGpuArgs),
}

/// Sets the material database from --material-db, else from NACRE_MATERIAL_DB.
fn set_material_db(flag: Option<&std::path::Path>) {
    use nacre_format::materials::{MaterialDb, set_database};
    let db = match flag {
        Some(dir) => Some(MaterialDb::new(dir, Param::MaterialDb)),
        None => std::env::var_os("NACRE_MATERIAL_DB")
            .filter(|v| !v.is_empty())
            .map(|dir| MaterialDb::new(PathBuf::from(dir), "NACRE_MATERIAL_DB")),
    };
    set_database(db);
}
fn run(cli: Cli) -> Result<()> {
    set_material_db(cli.material_db.as_deref());
    match cli.command {
        Command::Spectrum(args) => spectrum::run(&args),
        Command::Bake(args) => bake::run(&args),
        Command::Color(args) => color::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Diffraction(args) => Ok(diffraction::run(&args)?),
        Command::Plot(args) => Ok(plot::run(&args)?),
        Command::Conformance(args) => conformance::run(&args),
        Command::Render(args) => render::run(&args),
        Command::BenchGpu(args) => bench_gpu::run(&args),
        Command::Export(args) => export::run(&args),
        Command::Fit(args) => fit::run(&args),
        Command::Info(args) => info::run(&args),
        Command::Materials => materials::run(),
    }
}

/// Mesa's Vulkan device-select layer (`VK_LAYER_MESA_device_select`, an implicit layer that
/// Mesa installs) asks libwayland for the session's display to rank the GPUs; without a
/// Wayland session (`XDG_RUNTIME_DIR` unset or not a folder) libwayland prints `error:
/// XDG_RUNTIME_DIR is invalid or not set in the environment.` to stderr, once per Vulkan
/// instance, although nothing failed. nacre picks its adapter itself (`WGPU_ADAPTER_NAME`,
/// else wgpu's choice), so there the layer is switched off with its own switch,
/// `NODEVICE_SELECT=1` — unless the user set `NODEVICE_SELECT` or asks the layer for a
/// device (`MESA_VK_DEVICE_SELECT`).
fn quiet_vulkan_device_select() {
    let has = |var: &str| std::env::var_os(var).is_some_and(|v| !v.is_empty());
    let session = std::env::var_os("XDG_RUNTIME_DIR")
        .map(PathBuf::from)
        .is_some_and(|dir| dir.is_absolute() && dir.is_dir());
    if !session && !has("NODEVICE_SELECT") && !has("MESA_VK_DEVICE_SELECT") {
        // SAFETY: called first thing in `main`, before any other thread exists.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}

fn main() -> ExitCode {
    quiet_vulkan_device_select();
    gpu::list_float_targets_on_mesa_gl();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => e.exit(), // usage errors exit with status 2, --help/--version with 0
    };
    let result = run(cli);
    // What the material readers repaired or set aside (the materials are usable).
    error::warn(&nacre_format::materials::take_warnings());
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // `nacre spectrum | head`: the reader closed the pipe; end quietly.
        Err(e) if e.is_broken_pipe() => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("nacre: error: {e}");
            ExitCode::from(e.exit_status())
        }
    }
}
