//! `nacre fit`: from a look or a measurement back to parameters. `nacre fit gltf`: the
//! closest glTF `KHR_materials_iridescence` material to a stack; `nacre fit spectrum`: a
//! template's free thicknesses and indices (ranges in the stack flags) fitted to measured
//! spectra.

use crate::args::ColourArgs;
use crate::error::Result;
use clap::{Args, Subcommand};
use nacre_bake::commands::color_request::colorimeter;
use nacre_bake::commands::fit_gltf;
use nacre_bake::commands::fit_spectrum::{
    Request, fit_all, fit_plot, map_csv, parse_baseline, parse_loss, parse_window, read_spectra,
    recipe_toml, residuals_csv, warnings,
};
use nacre_bake::commands::fit_template::FitTemplate;
use nacre_bake::commands::plot::{ImageFormat, render};
use nacre_bake::commands::stack_spec::TemplateSpec;
use nacre_bake::commands::{fit_color, plot};
use nacre_format::Param;
use nacre_format::atomic::write_atomic;
use nacre_optics::fit::{ColourSettings, Quantity, Settings};
use std::path::PathBuf;

pub const GLTF_EXAMPLES: &str = "\
The material's glTF reference evaluation (nacre color --method gaussian: Belcour & Barla's
Gaussian-fit closed form, Schlick Fresnel, mixed with the base's Fresnel by
iridescenceFactor) is compared in CIEDE2000 with the stack's exact colour (linear sRGB, D65)
at 0-85 degrees every 5, over the top film's thickness range when it spans one
(`--layer oil@200:800`: the range a thickness texture maps; `--thicknesses 200:800` is the
same). The error of the fitted material and of the naive
mapping (top film's index and thickness, substrate's index or colour) go to stderr.

Examples:
  # the closest glTF film to a 3-layer stack on glass, as a material object
  nacre fit gltf --layer tio2@120 --layer sio2@180 --layer tio2@90 --substrate bk7 -o material.json
  # an oil slick whose thickness varies 200-800 nm over a thickness texture
  nacre fit gltf --layer oil@200:800 --substrate water -o oil.json
  # anodised titanium: an oxide film on a metal gives a metallic base
  nacre fit gltf --layer tio2@60 --substrate 2.5+3.4i";

pub const COLOR_EXAMPLES: &str = "\
Targets CSV: angle_deg and the colour as R,G,B (linear, in --space, as nacre color writes
them), X,Y,Z or L,a,b (CIELAB under --illuminant), optionally weight. The stack flags take
ranges as in nacre fit spectrum (--layer tio2@20:300: thickness free in 20-300 nm). The
objective is the weighted sum of squared CIEDE2000 over the rows, searched over the whole
box; the achieved colour and ΔE2000 per row go to stderr and --report, and a look out of
reach says how far its closest stack stays.

Examples:
  # two films on glass, designed for the colours of four angles
  nacre fit color look.csv --layer tio2@20:300 --layer sio2@20:300 --substrate bk7 -o fit.toml
  # three distinct stacks (fit.toml, fit-2.toml, fit-3.toml) and a picture of them
  nacre fit color look.csv --layer tio2@20:300 --layer sio2@20:300 --substrate bk7 \\
      --solutions 3 -o fit.toml --plot design.png
  # the designed stack's colour, back through nacre color
  nacre color --recipe fit.toml --angles 0:60:20";

pub const SPECTRUM_EXAMPLES: &str = "\
A range marks a free parameter: --layer sio2@50:400 (thickness free in 50–400 nm),
--layer 1.3:1.7@100:600 (constant index free in 1.3–1.7, thickness in 100–600 nm); in a
recipe, thickness_nm = [50, 400] and material = \"1.3:1.7\".

Examples:
  # one oxide film on silicon, thickness anywhere in 10–2000 nm
  nacre fit spectrum measured.csv --layer sio2@10:2000 --substrate si -o fit.toml
  # a relative measurement: free scale, a linear baseline, 450–750 nm only
  nacre fit spectrum counts.csv --layer sio2@10:2000 --substrate si --scale free \\
      --offset poly:1 --range 450:750 -o fit.toml --residuals res.csv
  # a folder of spectra (or a wide CSV): a thickness map
  nacre fit spectrum wafer/ --layer sio2@10:2000 --substrate si -o map.csv
  # the fitted stack, back into the forward commands
  nacre spectrum --recipe fit.toml";

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
    /// Fit a stack's free thicknesses and indices to measured reflectance or transmittance
    /// spectra (CSV: wavelength_nm, R or T, optional angle_deg and sigma), globally over the
    /// bounds.
    #[command(after_help = SPECTRUM_EXAMPLES)]
    Spectrum(FitSpectrumArgs),
    /// Design a stack for a look: the free thicknesses and indices whose colour matches
    /// target colours at given angles (CSV: angle_deg and R,G,B, X,Y,Z or L,a,b), globally
    /// over the bounds.
    #[command(after_help = COLOR_EXAMPLES)]
    Color(FitColorArgs),
}

/// The stack flags of the fit commands, where a range marks what varies: shared by `fit
/// spectrum`, `fit color` and `fit gltf`.
#[derive(Args)]
pub struct TemplateArgs {
    /// Ambient (incidence) medium [default: 1.0].
    #[arg(long, value_name = "M")]
    ambient: Option<String>,
    /// A film, top first; a range marks a free value: `sio2@50:400` (thickness free in
    /// 50–400 nm), `1.3:1.7@100:600` (constant index free too).
    #[arg(long = "layer", value_name = "M@THICKNESS")]
    layers: Vec<String>,
    /// Substrate [default: 1.0].
    #[arg(long, value_name = "M")]
    substrate: Option<String>,
    /// Read the stack from a TOML recipe (ranges: thickness_nm = [LO, HI], material =
    /// "NLO:NHI").
    #[arg(long, value_name = "FILE.toml", conflicts_with_all = ["ambient", "layers", "substrate"])]
    recipe: Option<PathBuf>,
}

impl TemplateArgs {
    /// The template as given (ranges kept).
    fn spec(&self) -> nacre_bake::Result<TemplateSpec> {
        match &self.recipe {
            Some(path) => TemplateSpec::read(path),
            None => TemplateSpec::from_flags(
                self.ambient.as_deref(),
                &self.layers,
                self.substrate.as_deref(),
            ),
        }
    }
}

/// `--quantity r|t` of the fit commands.
fn parse_quantity(text: &str) -> Result<Quantity> {
    match text {
        "r" | "R" => Ok(Quantity::Reflectance),
        "t" | "T" => Ok(Quantity::Transmittance),
        other => Err(nacre_bake::Error::value(Param::Quantity, other, "expected r or t").into()),
    }
}

#[derive(Args)]
pub struct GltfArgs {
    #[command(flatten)]
    stack: TemplateArgs,
    /// The top film's thickness varies over START:END nm (as a thickness texture maps it
    /// from 0 to 1), the same as a range on the top film (`--layer oil@200:800`)
    /// [default: the film's own thickness].
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

#[derive(Args)]
pub struct FitSpectrumArgs {
    /// The measured spectrum: a CSV file (one R or T column, or several: a wide file) or a
    /// folder of CSV files.
    #[arg(value_name = "MEASURED")]
    measured: PathBuf,
    #[command(flatten)]
    template: TemplateArgs,
    /// The measured quantity of a wide file's columns: r or t [default: the column's name].
    #[arg(long, value_name = "r|t")]
    quantity: Option<String>,
    /// Scale a(λ) of R_measured ≈ a·R + b: a number, `free` or `poly:N` (degree N in
    /// wavenumber).
    #[arg(long, default_value = "1", value_name = "1|free|poly:N")]
    scale: String,
    /// Offset b(λ): a number, `free` or `poly:N`.
    #[arg(long, default_value = "0", value_name = "0|free|poly:N")]
    offset: String,
    /// Fit only wavelengths in START:END, nm.
    #[arg(long = "range", value_name = "START:END")]
    window: Option<String>,
    /// Loss: cauchy (robust to outliers) or linear (least squares).
    #[arg(long, default_value = "cauchy")]
    loss: String,
    /// Most starts of the global search.
    #[arg(long, default_value_t = 64)]
    starts: usize,
    /// Output: the fitted recipe (TOML; a CSV thickness map for several spectra), or `-`.
    #[arg(
        short = 'o',
        long = "output",
        value_name = "FIT.toml",
        default_value = "-"
    )]
    output: PathBuf,
    /// Write measured, fitted and residual values per point to this CSV.
    #[arg(long, value_name = "FILE.csv")]
    residuals: Option<PathBuf>,
    /// Draw the measured spectrum against the fitted one, residuals below (PNG or SVG, by
    /// the extension; one spectrum).
    #[arg(long, value_name = "FILE.png|svg")]
    plot: Option<PathBuf>,
}

#[derive(Args)]
pub struct FitColorArgs {
    /// The target colours: a CSV file (angle_deg and R,G,B, X,Y,Z or L,a,b; optional
    /// weight).
    #[arg(value_name = "TARGETS")]
    targets: PathBuf,
    #[command(flatten)]
    template: TemplateArgs,
    #[command(flatten)]
    colour: ColourArgs,
    /// The colour of: r (reflectance) or t (transmittance).
    #[arg(long, default_value = "r", value_name = "r|t")]
    quantity: String,
    /// Up to K distinct stacks that reach the look (the 2nd written beside -o as
    /// NAME-2.toml, …).
    #[arg(long, default_value_t = 1, value_name = "K")]
    solutions: usize,
    /// Two stacks are distinct when a free thickness differs by more than this, nm.
    #[arg(long, default_value_t = 10.0, value_name = "NM")]
    distinct: f64,
    /// Local polishes of the global search.
    #[arg(long, default_value_t = 16)]
    starts: usize,
    /// Output: the designed recipe (TOML), or `-`.
    #[arg(
        short = 'o',
        long = "output",
        value_name = "FIT.toml",
        default_value = "-"
    )]
    output: PathBuf,
    /// Write the target and achieved colour and ΔE2000 per row (and solution) to this CSV.
    #[arg(long, value_name = "FILE.csv")]
    report: Option<PathBuf>,
    /// Draw the target swatches over the designed ones, per angle (PNG or SVG).
    #[arg(long, value_name = "FILE.png|svg")]
    plot: Option<PathBuf>,
}

pub fn run(args: &FitArgs) -> Result<()> {
    match &args.command {
        FitCommand::Gltf(args) => gltf(args),
        FitCommand::Spectrum(args) => spectrum(args),
        FitCommand::Color(args) => color(args),
    }
}

/// NAME-k.EXT beside `path` for solution k ≥ 2.
fn sibling(path: &std::path::Path, k: usize) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name = match path.extension() {
        Some(e) => format!("{stem}-{k}.{}", e.to_string_lossy()),
        None => format!("{stem}-{k}"),
    };
    path.with_file_name(name)
}

fn color(args: &FitColorArgs) -> Result<()> {
    let colorimeter = colorimeter(&args.colour.settings())?;
    let settings = ColourSettings {
        quantity: parse_quantity(&args.quantity)?,
        starts: args.starts.max(1),
        solutions: fit_color::parse_solutions(args.solutions)?,
        distinct_nm: fit_color::check_distinct(args.distinct)?,
        ..ColourSettings::default()
    };
    let plot_format = args
        .plot
        .as_deref()
        .map(|p| {
            plot::ImageFormat::from_path(p).map_err(|_| {
                nacre_bake::Error::value(
                    Param::FitPlot,
                    p.display().to_string(),
                    "expected a file name ending in .png or .svg",
                )
            })
        })
        .transpose()?;
    let template = FitTemplate::build(args.template.spec()?)?;
    let rows = fit_color::read_targets(&args.targets, &colorimeter)?;
    let design = fit_color::design(&template, &rows, &colorimeter, &settings)?;
    let name = args.targets.display().to_string();
    // Everything is computed before anything is written.
    let recipes = (0..design.solutions.len())
        .map(|k| fit_color::recipe_toml(&template, &design, k, &rows, &colorimeter, &name))
        .collect::<nacre_bake::Result<Vec<String>>>()?;
    let picture = match plot_format {
        Some(format) => {
            let figure = fit_color::design_plot(
                &design,
                &rows,
                &colorimeter,
                &format!("nacre fit color {name}"),
            );
            Some(plot::render(&figure, format)?)
        }
        None => None,
    };
    for line in fit_color::describe(&template, &design, &rows, &fit_color::file_line) {
        eprintln!("{line}");
    }
    let mut table = Vec::new();
    fit_color::report_csv(&design, &rows, &colorimeter, &mut table).map_err(|source| {
        nacre_format::Error::Io {
            path: args.report.clone().unwrap_or_default(),
            source,
        }
    })?;
    match &args.report {
        Some(path) => write_atomic(path, |w| w.write_all(&table))?,
        None => eprint!("{}", String::from_utf8_lossy(&table)),
    }
    if let (Some(path), Some(bytes)) = (&args.plot, &picture) {
        write_atomic(path, |w| w.write_all(bytes))?;
    }
    let to_stdout = args.output.as_os_str() == "-";
    for (k, recipe) in recipes.iter().enumerate().skip(1) {
        if !to_stdout {
            write_atomic(&sibling(&args.output, k + 1), |w| {
                w.write_all(recipe.as_bytes())
            })?;
        }
    }
    write_atomic(&args.output, |w| w.write_all(recipes[0].as_bytes()))?;
    Ok(())
}

fn gltf(args: &GltfArgs) -> Result<()> {
    let flag_range = args
        .thicknesses
        .as_deref()
        .map(fit_gltf::parse_thickness_range)
        .transpose()?;
    let template = FitTemplate::build(args.stack.spec()?)?;
    let range = fit_gltf::template_range(&template, flag_range)?;
    let spec = &template.spec.stack;
    let stack = template.template.stack().clone();
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

fn spectrum(args: &FitSpectrumArgs) -> Result<()> {
    let template = FitTemplate::build(args.template.spec()?)?;
    let quantity = args.quantity.as_deref().map(parse_quantity).transpose()?;
    let request = Request {
        settings: Settings {
            scale: parse_baseline(Param::Scale, &args.scale)?,
            offset: parse_baseline(Param::Offset, &args.offset)?,
            loss: parse_loss(&args.loss)?,
            starts: args.starts.max(1),
            ..Settings::default()
        },
        window: args.window.as_deref().map(parse_window).transpose()?,
    };
    let plot_format = args
        .plot
        .as_deref()
        .map(|path| ImageFormat::from_path_of(Param::FitPlot, path))
        .transpose()?;
    let spectra = read_spectra(&args.measured, quantity)?;
    if let (Some(path), true) = (&args.plot, spectra.len() != 1) {
        return Err(nacre_bake::Error::value(
            Param::FitPlot,
            path.display().to_string(),
            format!(
                "a fit plot draws one spectrum: {} holds {}",
                args.measured.display(),
                spectra.len()
            ),
        )
        .into());
    }
    let outcomes = fit_all(&template, &spectra, &request)?;
    for o in &outcomes {
        for w in warnings(&template, &o.fit) {
            eprintln!("warning: {}: {w}", o.name);
        }
    }
    // Everything is computed before anything is written.
    let output = if outcomes.len() == 1 {
        recipe_toml(&template, &outcomes[0])?.into_bytes()
    } else {
        let mut v = Vec::new();
        map_csv(&template, &outcomes, &mut v).map_err(|source| nacre_format::Error::Io {
            path: args.output.clone(),
            source,
        })?;
        v
    };
    let picture = match plot_format {
        Some(format) => Some(render(&fit_plot(&template, &outcomes[0])?, format)?),
        None => None,
    };
    if let Some(path) = &args.residuals {
        write_atomic(path, |w| residuals_csv(&outcomes, w))?;
    }
    if let (Some(path), Some(bytes)) = (&args.plot, &picture) {
        write_atomic(path, |w| w.write_all(bytes))?;
    }
    write_atomic(&args.output, |w| w.write_all(&output))?;
    Ok(())
}
