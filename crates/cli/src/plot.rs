//! `nacre plot spectrum|chromaticity|chart|table`: pictures, as PNG or SVG by the output's
//! extension. The figures and their colour conventions live in [`nacre_bake::commands::plot`]; this
//! module parses the flags, computes the data and hands it over.

use crate::args::{StackArgs, load_stack};
use clap::{Args, Subcommand};
use nacre_bake::commands::color::{self, LoadedLut, Method, Point, Quantity};
use nacre_bake::commands::grid::{parse_range, parse_thickness_nm};
use nacre_bake::commands::plot::{self, ChartColumns, ImageFormat, SpectrumQuantity};
use nacre_bake::commands::stack_spec::StackSpec;
use nacre_bake::error::{Error, Origin, Param, Result};
use nacre_format::msg;
use nacre_optics::Stack;
use nacre_optics::colour::{Colorimeter, Illuminant, Observer, OutputSpace, RgbSpace};
use std::path::PathBuf;

#[derive(Args)]
pub struct PlotArgs {
    #[command(subcommand)]
    kind: PlotKind,
}

#[derive(Subcommand)]
enum PlotKind {
    /// Reflectance/transmittance spectra against wavelength at a few angles, from a stack or a
    /// `nacre spectrum` CSV.
    #[command(after_help = SPECTRUM_EXAMPLES)]
    Spectrum(SpectrumPlotArgs),
    /// The CIE 1931 xy diagram (locus, gamuts, white) with a film's colour trajectory over
    /// thickness or angle, by several methods.
    #[command(after_help = CHROMATICITY_EXAMPLES)]
    Chromaticity(ChromaticityArgs),
    /// A swatch chart of film colours: thickness rows × angle (or film index) columns.
    #[command(after_help = CHART_EXAMPLES)]
    Chart(ChartArgs),
    /// A baked table as pictures: film-lut slices (cos θ × optical path) or fourier envelopes.
    #[command(after_help = TABLE_EXAMPLES)]
    Table(TableArgs),
    /// A diffraction map: the colour of a diffracting surface over view directions for a
    /// fixed light (Stam 1999; see `nacre diffraction`).
    #[command(after_help = crate::diffraction::MAP_EXAMPLES)]
    Diffraction(crate::diffraction::MapArgs),
}

const SPECTRUM_EXAMPLES: &str = "\
The image format follows the -o extension: .png (bitmap) or .svg (vector).
Colour tells the angle; solid lines are unpolarised, dashed s, dotted p.

Examples:
  # the 400 nm soap film at 0, 30 and 60 degrees -> spectrum.png
  nacre plot spectrum
  # an anti-reflection coating with its s and p parts, as SVG
  nacre plot spectrum --layer mgf2@99.75nm --substrate bk7 --angles 0:60:30 --quantities R,R_s,R_p -o ar.svg
  # curves from a `nacre spectrum` CSV
  nacre spectrum --layer au@30 --substrate 1.52 -o gold.csv
  nacre plot spectrum --csv gold.csv --angles 0,45,70 --quantities R,T,A -o gold.png";

const CHROMATICITY_EXAMPLES: &str = "\
The image format follows the -o extension: .png (bitmap) or .svg (vector).
Cases: fig7 (default: Belcour & Barla 2017 Fig. 7, film 1.5 on base 1.09), dielectric (film
1.5 on 1.5), gold (film 1.5 on gold), soap (film 1.33 in air); or a stack by --layer etc.
(the first film's thickness varies). Colours: CIE 1931 2°, D65, linear sRGB.

Examples:
  # Fig. 7: thickness 0-1000 nm at normal incidence, five methods -> chromaticity.png
  nacre plot chromaticity
  # a soap film over angle at 500 nm, with the P3 and Rec.2020 gamuts
  nacre plot chromaticity --case soap --angles 0:85:1 --thickness 500 --gamut srgb,p3,rec2020
  # the baked table against the reference: a film of index 1.8 on the glTF default base
  nacre plot chromaticity --ambient 1.0 --layer 1.8@0 --substrate 1.5 --methods spectral,lut:film-dielectric,gaussian";

const CHART_EXAMPLES: &str = "\
The image format follows the -o extension: .png (bitmap) or .svg (vector).
Swatches are the linear sRGB colour (D65, a perfect reflector = white) times --exposure,
clipped per channel to [0, 1] and sRGB-encoded.

Examples:
  # the soap-film chart: 0-1500 nm by 50 nm, at 0/30/60/80 degrees -> chart.png
  nacre plot chart
  # film index columns on the glTF default base, brighter
  nacre plot chart --case dielectric --film-iors 1.2,1.5,1.8,2.1,2.4 --exposure 4
  # an oil slick on water, from a stack
  nacre plot chart --ambient air --layer oil@0 --substrate water --thicknesses 0:1200:25";

const TABLE_EXAMPLES: &str = "\
The image format follows the -o extension: .png (bitmap) or .svg (vector).
film-lut tables: the colour the GPU would sample over cos θ × optical path difference at a
few film indices, as sRGB (clipped, × --exposure). fourier tables: Re and Im of each
channel's stored envelope against μ, one line per mip level.

Examples:
  nacre plot table                                  # film-dielectric -> table.png
  nacre plot table soap-film --quantity t --film-iors 1.33 -o soap-t.png
  nacre plot table fourier-srgb --max-opd 20000 -o fourier.svg";

#[derive(Args)]
struct SpectrumPlotArgs {
    #[command(flatten)]
    stack: StackArgs,
    /// Read the curves from a `nacre spectrum` CSV instead of computing them.
    #[arg(long, value_name = "FILE.csv", conflicts_with_all = ["ambient", "layers", "substrate", "recipe", "wavelengths"])]
    csv: Option<PathBuf>,
    /// Incidence angles, degrees: a list and/or START:END:STEP ranges (at most 10)
    /// [default: 0,30,60; with --csv every angle of the file, or 6 of them when it has more
    /// than 10].
    #[arg(long, value_name = "LIST", allow_hyphen_values = true)]
    angles: Option<String>,
    /// Vacuum wavelengths in nm: START:END:STEP [default: 380:780:1, or the recipe's].
    #[arg(long, value_name = "START:END:STEP")]
    wavelengths: Option<String>,
    /// Curves to draw, any of R, T, A, R_s, R_p, T_s, T_p (one panel per family).
    #[arg(long, value_name = "LIST", default_value = "R,T")]
    quantities: String,
    /// Output image (.png or .svg).
    #[arg(
        short = 'o',
        long = "output",
        value_name = "FILE",
        default_value = "spectrum.png"
    )]
    output: PathBuf,
}

#[derive(Args)]
struct ChromaticityArgs {
    #[command(flatten)]
    stack: StackArgs,
    /// Named case when no stack flag is given: fig7, dielectric, gold or soap [default: fig7].
    #[arg(long, conflicts_with_all = ["ambient", "layers", "substrate", "recipe"])]
    case: Option<String>,
    /// Methods to overlay, comma-separated (as `nacre color --method`).
    #[arg(
        long,
        value_name = "LIST",
        default_value = "spectral,gaussian,fourier:3,rgb3,samples:5"
    )]
    methods: String,
    /// The trajectory over film thickness, nm [default: 0:1000:2].
    #[arg(long, value_name = "START:END:STEP", conflicts_with = "angles")]
    thicknesses: Option<String>,
    /// Incidence angle of a trajectory over thickness, degrees.
    #[arg(
        long,
        default_value = "0",
        allow_hyphen_values = true,
        conflicts_with = "angles"
    )]
    angle: f64,
    /// A trajectory over incidence angle instead, degrees (START:END:STEP), at --thickness.
    #[arg(long, value_name = "START:END:STEP", allow_hyphen_values = true)]
    angles: Option<String>,
    /// Film thickness of a trajectory over angle [default: the film's; 400 nm for a case].
    #[arg(long, value_name = "THICKNESS", requires = "angles")]
    thickness: Option<String>,
    /// Gamut triangles, any of srgb, p3, rec2020, acescg.
    #[arg(long, value_name = "LIST", default_value = "srgb")]
    gamut: String,
    /// Leave the inside of the spectral locus white.
    #[arg(long)]
    no_fill: bool,
    /// The fourier table for fourier:… methods: a default-set name or a manifest path.
    #[arg(long, value_name = "NAME|PATH")]
    fourier_table: Option<String>,
    /// Output image (.png or .svg).
    #[arg(
        short = 'o',
        long = "output",
        value_name = "FILE",
        default_value = "chromaticity.png"
    )]
    output: PathBuf,
}

#[derive(Args)]
struct ChartArgs {
    #[command(flatten)]
    stack: StackArgs,
    /// Named case when no stack flag is given: soap, fig7, dielectric or gold [default: soap].
    #[arg(long, conflicts_with_all = ["ambient", "layers", "substrate", "recipe"])]
    case: Option<String>,
    /// Rows: film thicknesses, nm.
    #[arg(long, value_name = "START:END:STEP", default_value = "0:1500:50")]
    thicknesses: String,
    /// Columns: incidence angles, degrees, a list and/or ranges [default: 0,30,60,80].
    #[arg(
        long,
        value_name = "LIST",
        allow_hyphen_values = true,
        conflicts_with = "film_iors"
    )]
    angles: Option<String>,
    /// Columns by film index instead (a list and/or ranges), at --angle.
    #[arg(long, value_name = "LIST")]
    film_iors: Option<String>,
    /// Incidence angle of --film-iors columns, degrees.
    #[arg(
        long,
        default_value = "0",
        allow_hyphen_values = true,
        requires = "film_iors"
    )]
    angle: f64,
    /// Colour method (as `nacre color --method`).
    #[arg(long, default_value = "spectral")]
    method: String,
    /// r (reflectance) or t (transmittance into the base).
    #[arg(long, value_enum, default_value = "r")]
    quantity: crate::choices::QuantityArg,
    /// Factor on the linear colour before clipping.
    #[arg(long, default_value = "1")]
    exposure: f64,
    /// The fourier table for fourier:… methods: a default-set name or a manifest path.
    #[arg(long, value_name = "NAME|PATH")]
    fourier_table: Option<String>,
    /// Output image (.png or .svg).
    #[arg(
        short = 'o',
        long = "output",
        value_name = "FILE",
        default_value = "chart.png"
    )]
    output: PathBuf,
}

#[derive(Args)]
struct TableArgs {
    /// A default-set table name or a manifest path.
    #[arg(value_name = "NAME|PATH", default_value = "film-dielectric")]
    table: String,
    /// film-lut: r (reflectance) or t (transmittance).
    #[arg(long, value_enum, default_value = "r")]
    quantity: crate::choices::QuantityArg,
    /// film-lut: film indices of the slices (a list and/or ranges) [default:
    /// n_min + (n_max − n_min)·k/4 for k = 1…4].
    #[arg(long, value_name = "LIST")]
    film_iors: Option<String>,
    /// film-lut: factor on the linear colour before clipping.
    #[arg(long, default_value = "1")]
    exposure: f64,
    /// fourier: the largest optical path difference drawn, nm [default: where the envelopes
    /// fade below 3 % of their peak, plus half].
    #[arg(long, value_name = "NM")]
    max_opd: Option<f64>,
    /// Output image (.png or .svg).
    #[arg(
        short = 'o',
        long = "output",
        value_name = "FILE",
        default_value = "table.png"
    )]
    output: PathBuf,
}

/// Runs `nacre plot …`.
pub fn run(args: &PlotArgs) -> Result<()> {
    match &args.kind {
        PlotKind::Spectrum(a) => run_spectrum(a),
        PlotKind::Chromaticity(a) => run_chromaticity(a),
        PlotKind::Chart(a) => run_chart(a),
        PlotKind::Table(a) => run_table(a),
        PlotKind::Diffraction(a) => crate::diffraction::run_map(a),
    }
}

/// `air | water 400 nm | air`, or with `vary_first` `air | film water | air` (the first
/// film's thickness is what the plot varies).
fn describe(spec: &StackSpec, vary_first: bool) -> String {
    let mut parts = vec![spec.ambient.spec.clone()];
    parts.extend(spec.layers.iter().enumerate().map(|(k, (m, d))| {
        if k == 0 && vary_first {
            format!("film {}", m.spec)
        } else {
            format!("{} {d} nm", m.spec)
        }
    }));
    parts.push(spec.substrate.spec.clone());
    parts.join(" | ")
}

fn stack_given(s: &StackArgs) -> bool {
    s.ambient.is_some() || !s.layers.is_empty() || s.substrate.is_some() || s.recipe.is_some()
}

/// The stack from the flags, or a named case's film (at 400 nm) on its base in air, with a
/// description for the title.
fn case_or_stack(
    stack: &StackArgs,
    case: Option<&str>,
    default_case: &str,
) -> Result<(Stack, String)> {
    if stack_given(stack) {
        let (spec, _, _) = load_stack(stack)?;
        let built = spec.build()?;
        if built.layers().is_empty() {
            return Err(Error::value(
                Param::Layer,
                String::new(),
                msg!["this plot varies a film: give at least one ", Param::Layer],
            ));
        }
        return Ok((built, describe(&spec, true)));
    }
    let name = case.unwrap_or(default_case);
    let case = nacre_bake::commands::compare::case_named(name)?;
    let spec = StackSpec::from_flags(
        Some("1.0"),
        &[format!("{}@400", case.film_ior)],
        Some(case.base),
    )?;
    Ok((spec.build()?, case.description.to_string()))
}

/// A method ready to evaluate: `lut:` tables loaded and checked against the stack,
/// `fourier:` with the baked table (as `nacre color`).
fn prepare_method(
    flag: Param,
    text: &str,
    stack: &Stack,
    colorimeter: &Colorimeter,
    fourier_table: Option<&str>,
) -> Result<(Method, Option<LoadedLut>)> {
    nacre_bake::commands::color_request::prepare_method(text, stack, colorimeter, fourier_table)
        .map_err(|e| match e {
            Error::Value { value, message, .. } => Error::value(flag, value, message),
            other => other,
        })
}

fn reference_colorimeter() -> Colorimeter {
    Colorimeter::new(
        Observer::Cie1931_2Deg,
        Illuminant::D65,
        OutputSpace::Rgb(RgbSpace::Srgb),
    )
}

fn run_spectrum(args: &SpectrumPlotArgs) -> Result<()> {
    ImageFormat::from_path(&args.output)?;
    let quantities = SpectrumQuantity::parse_list(&args.quantities)?;
    let angles = match &args.angles {
        Some(text) => {
            let a = plot::parse_list(Param::Angles, text)?;
            plot::check_angles(Param::Angles, text, &a)?;
            Some((text.as_str(), a))
        }
        None => None,
    };
    let (title, curves) = match &args.csv {
        Some(path) => {
            let text = std::fs::read_to_string(path).map_err(|source| nacre_format::Error::Io {
                path: path.clone(),
                source,
            })?;
            let all = plot::read_spectrum_csv(path, &text)?;
            let count = all.len();
            let curves =
                plot::select_curves(all, angles.as_ref().map(|(t, a)| (*t, a.as_slice())), path)?;
            if angles.is_none() && curves.len() < count {
                eprintln!(
                    "nacre: note: {} has {count} angles; plotting {} of them (choose with --angles)",
                    path.display(),
                    curves.len()
                );
            }
            (format!("Spectra from {}", path.display()), curves)
        }
        None => {
            let (spec, _, recipe_wavelengths) = load_stack(&args.stack)?;
            let angles = angles.map_or_else(|| vec![0.0, 30.0, 60.0], |(_, a)| a);
            if angles.len() > plot::MAX_CURVES {
                return Err(Error::value(
                    Param::Angles,
                    args.angles.clone().unwrap_or_default(),
                    format!(
                        "{} angles: a spectrum plot shows at most {}",
                        angles.len(),
                        plot::MAX_CURVES
                    ),
                ));
            }
            let (flag, text) = match (&args.wavelengths, recipe_wavelengths) {
                (Some(t), _) => (Origin::from(Param::Wavelengths), t.clone()),
                (None, Some(t)) => (msg![Param::Wavelengths, " (from the recipe)"].into(), t),
                (None, None) => (Origin::from(Param::Wavelengths), "380:780:1".to_string()),
            };
            let wavelengths = parse_range(flag, &text)?;
            let stack = spec.build()?;
            let curves = plot::spectrum_curves(&stack, &angles, &wavelengths)?;
            crate::error::warn(&stack.undersampled_films(&wavelengths));
            (format!("Spectra of {}", describe(&spec, false)), curves)
        }
    };
    let figure = plot::SpectrumPlot::new(title, curves, quantities)?;
    plot::write_figure(&args.output, &figure)
}

fn run_chromaticity(args: &ChromaticityArgs) -> Result<()> {
    ImageFormat::from_path(&args.output)?;
    let gamuts = plot::parse_gamuts(&args.gamut)?;
    let (stack, what) = case_or_stack(&args.stack, args.case.as_deref(), "fig7")?;
    let c = reference_colorimeter();
    let (points, parameter, unit, sweep) = match &args.angles {
        Some(text) => {
            let angles = parse_range(Param::Angles, text)?;
            plot::check_angles(Param::Angles, text, &angles)?;
            let d = args
                .thickness
                .as_deref()
                .map(|t| parse_thickness_nm(Param::Thickness, t))
                .transpose()?;
            let d_shown = d.unwrap_or(stack.layers()[0].thickness_nm);
            let points: Vec<Point> = angles
                .iter()
                .map(|&angle_deg| Point {
                    angle_deg,
                    thickness_nm: d,
                    film_ior: None,
                })
                .collect();
            (
                points,
                angles,
                "°",
                format!("over angle of incidence at thickness {d_shown} nm"),
            )
        }
        None => {
            let text = args.thicknesses.as_deref().unwrap_or("0:1000:2");
            let d = parse_range(Param::Thicknesses, text)?;
            if let Some(v) = d.iter().find(|v| !(**v >= 0.0)) {
                return Err(Error::value(
                    Param::Thicknesses,
                    text,
                    format!("thickness {v} must be non-negative"),
                ));
            }
            plot::check_angles(Param::Angle, &args.angle.to_string(), &[args.angle])?;
            let points: Vec<Point> = d
                .iter()
                .map(|&t| Point {
                    angle_deg: args.angle,
                    thickness_nm: Some(t),
                    film_ior: None,
                })
                .collect();
            (
                points,
                d,
                " nm",
                format!("over film thickness at {}° incidence", args.angle),
            )
        }
    };
    if points.len() > plot::MAX_TRAJECTORY_POINTS {
        return Err(nacre_format::Error::TooLarge {
            what: "trajectory points".into(),
            count: points.len() as u64,
            limit: plot::MAX_TRAJECTORY_POINTS as u64,
        }
        .into());
    }
    let mut trajectories = Vec::new();
    for text in args.methods.split(',') {
        let (method, lut) = prepare_method(
            Param::Methods,
            text,
            &stack,
            &c,
            args.fourier_table.as_deref(),
        )?;
        let cm = lut.as_ref().map_or(&c, |l| &l.colorimeter);
        let colours = color::evaluate(
            &stack,
            &points,
            &method,
            cm,
            Quantity::Reflectance,
            lut.as_ref(),
        )?;
        crate::error::warn(&color::undersampled(&stack, &points, &method, cm));
        trajectories.push(plot::Trajectory {
            label: text.trim().to_string(),
            xy: colours
                .iter()
                .map(|col| plot::chromaticity(*col, cm))
                .collect(),
        });
    }
    let observer = Observer::Cie1931_2Deg;
    let figure = plot::ChromaticityPlot {
        title: format!("Reflected colour of {what}, {sweep}"),
        observer,
        white: (Illuminant::D65.white_xy(observer), "D65 white".to_string()),
        gamuts,
        marker_step: plot::ChromaticityPlot::default_marker_step(&parameter),
        parameter,
        parameter_unit: unit.into(),
        trajectories,
        fill: !args.no_fill,
    };
    plot::write_figure(&args.output, &figure)
}

fn run_chart(args: &ChartArgs) -> Result<()> {
    ImageFormat::from_path(&args.output)?;
    if !(args.exposure > 0.0 && args.exposure.is_finite()) {
        return Err(Error::value(
            Param::Exposure,
            args.exposure.to_string(),
            "must be a positive number",
        ));
    }
    let (stack, what) = case_or_stack(&args.stack, args.case.as_deref(), "soap")?;
    let rows = parse_range(Param::Thicknesses, &args.thicknesses)?;
    if let Some(v) = rows.iter().find(|v| !(**v >= 0.0)) {
        return Err(Error::value(
            Param::Thicknesses,
            args.thicknesses.clone(),
            format!("thickness {v} must be non-negative"),
        ));
    }
    let (columns, kind) = match &args.film_iors {
        Some(text) => {
            let n = plot::parse_list(Param::FilmIors, text)?;
            if let Some(v) = n.iter().find(|v| !(**v > 0.0)) {
                return Err(Error::value(
                    Param::FilmIors,
                    text.clone(),
                    format!("film index {v} must be positive"),
                ));
            }
            plot::check_angles(Param::Angle, &args.angle.to_string(), &[args.angle])?;
            (n, ChartColumns::FilmIor)
        }
        None => {
            let text = args.angles.as_deref().unwrap_or("0,30,60,80");
            let a = plot::parse_list(Param::Angles, text)?;
            plot::check_angles(Param::Angles, text, &a)?;
            (a, ChartColumns::Angle)
        }
    };
    let (max_rows, max_cols) = plot::MAX_CHART_CELLS;
    if rows.len() > max_rows || columns.len() > max_cols {
        return Err(nacre_format::Error::TooLarge {
            what: format!("chart rows × columns ({} × {})", rows.len(), columns.len()).into(),
            count: (rows.len() * columns.len()) as u64,
            limit: (max_rows * max_cols) as u64,
        }
        .into());
    }
    let points: Vec<Point> = rows
        .iter()
        .flat_map(|&d| {
            columns.iter().map(move |&v| match kind {
                ChartColumns::Angle => Point {
                    angle_deg: v,
                    thickness_nm: Some(d),
                    film_ior: None,
                },
                ChartColumns::FilmIor => Point {
                    angle_deg: args.angle,
                    thickness_nm: Some(d),
                    film_ior: Some(v),
                },
            })
        })
        .collect();
    let quantity = Quantity::from(args.quantity);
    let c = reference_colorimeter();
    let (method, lut) = prepare_method(
        Param::Method,
        &args.method,
        &stack,
        &c,
        args.fourier_table.as_deref(),
    )?;
    let cm = lut.as_ref().map_or(&c, |l| &l.colorimeter);
    let colours = color::evaluate(&stack, &points, &method, cm, quantity, lut.as_ref())?;
    crate::error::warn(&color::undersampled(&stack, &points, &method, cm));
    let display = plot::DisplayConverter::new(cm);
    let quantity_name = match quantity {
        Quantity::Reflectance => "Reflected",
        Quantity::Transmittance => "Transmitted",
    };
    let at = match kind {
        ChartColumns::Angle => String::new(),
        ChartColumns::FilmIor => format!(" at {}°", args.angle),
    };
    let exposure = if args.exposure == 1.0 {
        String::new()
    } else {
        format!(", exposure ×{}", args.exposure)
    };
    let figure = plot::ChartPlot {
        title: format!(
            "{quantity_name} colour of {what}{at} — {}, sRGB (clipped{exposure})",
            args.method.trim()
        ),
        thicknesses_nm: rows,
        columns,
        column_kind: kind,
        colours: colours
            .iter()
            .map(|col| display.linear_srgb(*col))
            .collect(),
        exposure: args.exposure,
    };
    plot::write_figure(&args.output, &figure)
}

fn run_table(args: &TableArgs) -> Result<()> {
    ImageFormat::from_path(&args.output)?;
    if !(args.exposure > 0.0 && args.exposure.is_finite()) {
        return Err(Error::value(
            Param::Exposure,
            args.exposure.to_string(),
            "must be a positive number",
        ));
    }
    let film_iors = args
        .film_iors
        .as_deref()
        .map(|t| plot::parse_list(Param::FilmIors, t))
        .transpose()?;
    let figure = plot::load_table_plot(
        &args.table,
        &plot::TableOptions {
            quantity: Quantity::from(args.quantity),
            film_iors,
            exposure: args.exposure,
            max_opd_nm: args.max_opd,
        },
    )?;
    plot::write_figure(&args.output, &figure)
}
