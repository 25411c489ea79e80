//! `nacre`: bake thin-film interference tables and spectra.

// `!(x > 0.0)` is how this crate rejects NaN together with out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use clap::{Args, Parser, Subcommand};
use nacre_bake::error::Result;
use nacre_bake::grid::parse_range;
use nacre_bake::output::write_atomic;
use nacre_bake::stack_spec::{StackRecipe, StackSpec};
use nacre_bake::{bake, materials, spectrum};
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
    /// Colour of a stack's reflectance or transmittance by a chosen method, as CSV.
    #[command(after_help = COLOR_EXAMPLES)]
    Color(ColorArgs),
    /// Bake lookup tables from recipes (default: every recipe in tables/recipes/ into tables/baked/).
    #[command(after_help = BAKE_EXAMPLES)]
    Bake(BakeArgs),
    /// Compare the real-time methods with the exact colour over angle × thickness (CSV + PNG).
    #[command(after_help = COMPARE_EXAMPLES)]
    Compare(CompareArgs),
    /// Print a baked table's manifest as JSON.
    Info {
        /// A default-set table name (e.g. film-dielectric) or a manifest path.
        #[arg(value_name = "NAME|PATH")]
        table: String,
    },
    /// List the bundled materials.
    Materials,
}

const BAKE_EXAMPLES: &str = "\
Examples:
  # the default set: every recipe in tables/recipes/ into tables/baked/
  nacre bake
  # one recipe into another folder
  nacre bake tables/recipes/film-gold.toml --out /tmp/tables
The recipe format is documented in the README (\"Table recipes\").";

const COLOR_EXAMPLES: &str = "\
Methods: spectral (exact reference), lut:NAME|PATH (a baked film-lut, default-set name or
manifest path), rgb3 (650/510/475 nm), samples:N (N wavelengths over 400-700 nm),
fourier:M | fourier:auto [:SIGMA_NM] (Belcour & Barla 2017 Eq. 10 with exact Fresnel, the
baked fourier table sampled as a GPU would, optional prefiltering for a thickness standard
deviation), fourier-exact:… (the same with exact transforms), gaussian (the glTF
KHR_materials_iridescence Gaussian-fit approximation).

Examples:
  # colour of a 400 nm soap film over angle, exact
  nacre color --layer 1.33@400 --angles 0:85:5
  # the same from the baked default table
  nacre color --ambient 1.0 --layer 1.33@400 --substrate 1.0 --angles 0:85:5 --method lut:soap-film
  # points (angle_deg,thickness_nm,film_ior) on the glTF default base, in Rec.2020
  nacre color --ambient 1.0 --layer 1.5@0 --substrate 1.5 --points points.csv --space rec2020
  # transmittance colour, CIE 1964 observer under illuminant A
  nacre color --layer water@600 --quantity t --observer 1964 --illuminant a";

#[derive(Args)]
struct ColorArgs {
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
    /// spectral | lut:NAME|PATH | rgb3 | samples:N.
    #[arg(long, default_value = "spectral")]
    method: String,
    /// The fourier table for fourier:… methods: a default-set name or a manifest path
    /// [default: the default-set table matching --space, --illuminant and --observer].
    #[arg(long, value_name = "NAME|PATH")]
    fourier_table: Option<String>,
    /// r (reflectance) or t (transmittance into the base).
    #[arg(long, default_value = "r", value_parser = ["r", "t"])]
    quantity: String,
    /// CIE observer: 1931 (2°) or 1964 (10°) [default: 1931, or the table's].
    #[arg(long)]
    observer: Option<String>,
    /// Illuminant: d65, d50, a or e [default: d65, or the table's].
    #[arg(long)]
    illuminant: Option<String>,
    /// Output space: xyz, srgb, rec2020, p3 or acescg (linear) [default: srgb, or the table's].
    #[arg(long)]
    space: Option<String>,
    /// Output CSV file, or `-` for standard output.
    #[arg(
        short = 'o',
        long = "output",
        value_name = "FILE.csv",
        default_value = "-"
    )]
    output: PathBuf,
}

const COMPARE_EXAMPLES: &str = "\
Cases: fig7 (Belcour & Barla 2017 Fig. 7: film 1.5 on base 1.09), dielectric (film 1.5 on
1.5), gold (film 1.5 on gold), soap (film 1.33 in air).

Examples:
  nacre compare -o compare-fig7
  nacre compare --case gold --thicknesses 0:2000:20 -o compare-gold";

#[derive(Args)]
struct CompareArgs {
    /// Named case: fig7, dielectric, gold or soap.
    #[arg(long, default_value = "fig7")]
    case: String,
    /// Incidence angles, degrees.
    #[arg(long, value_name = "START:END:STEP", default_value = "0:85:2.5")]
    angles: String,
    /// Film thicknesses, nm.
    #[arg(long, value_name = "START:END:STEP", default_value = "0:1000:10")]
    thicknesses: String,
    /// Output folder: compare.csv and compare.png.
    #[arg(short = 'o', long = "output", value_name = "DIR")]
    output: PathBuf,
}

#[derive(Args)]
struct BakeArgs {
    /// Recipe files (TOML) [default: every tables/recipes/*.toml].
    #[arg(value_name = "RECIPE.toml")]
    recipes: Vec<PathBuf>,
    /// Output folder [default: tables/baked].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
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
    /// A film, top first; repeat for more films (default with no stack flags: water@400).
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

fn run_color(args: &ColorArgs) -> Result<()> {
    use nacre_bake::color::{self, LoadedLut, Method, Point, Quantity};
    use nacre_bake::error::Error;
    use nacre_optics::colour::Colorimeter;
    let (spec, recipe_angles, _) = load_stack(&args.stack)?;
    let mut method = Method::parse(&args.method)?;
    let quantity = if args.quantity == "t" {
        Quantity::Transmittance
    } else {
        Quantity::Reflectance
    };
    let points: Vec<Point> = match &args.points {
        Some(path) => {
            let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
                path: path.clone(),
                source,
            })?;
            color::parse_points(path, &text)?
        }
        None => {
            let text = args
                .angles
                .clone()
                .or(recipe_angles)
                .unwrap_or_else(|| "0:89:1".into());
            let angles = parse_range("--angles", &text)?;
            if let Some(a) = angles.iter().find(|a| !(a.abs() < 90.0)) {
                return Err(Error::Flag {
                    flag: "--angles".into(),
                    value: text,
                    message: format!("angle {a} must lie strictly between -90 and 90 degrees"),
                });
            }
            angles
                .into_iter()
                .map(|angle_deg| Point {
                    angle_deg,
                    thickness_nm: None,
                    film_ior: None,
                })
                .collect()
        }
    };
    let stack = spec.build()?;
    let (lut, colorimeter) = match &method {
        Method::Lut(path) => {
            let lut = LoadedLut::load(path)?;
            lut.check_stack(path, &stack)?;
            let m = &lut.manifest;
            for (flag, given, table) in [
                ("--observer", &args.observer, &m.observer),
                ("--illuminant", &args.illuminant, &m.illuminant),
                ("--space", &args.space, &m.space),
            ] {
                if let Some(g) = given
                    && !g.eq_ignore_ascii_case(table)
                {
                    return Err(Error::Flag {
                        flag: flag.into(),
                        value: g.clone(),
                        message: format!("table `{}` was baked for `{table}`", m.name),
                    });
                }
            }
            let c = lut.colorimeter.clone();
            (Some(lut), c)
        }
        _ => {
            fn flag_err(flag: &'static str, v: &str) -> impl FnOnce(nacre_optics::Error) -> Error {
                let v = v.to_string();
                move |e| Error::Flag {
                    flag: flag.into(),
                    value: v,
                    message: e.to_string(),
                }
            }
            let o = args.observer.clone().unwrap_or_else(|| "1931".into());
            let i = args.illuminant.clone().unwrap_or_else(|| "d65".into());
            let s = args.space.clone().unwrap_or_else(|| "srgb".into());
            let c = Colorimeter::new(
                o.parse().map_err(flag_err("--observer", &o))?,
                i.parse().map_err(flag_err("--illuminant", &i))?,
                s.parse().map_err(flag_err("--space", &s))?,
            );
            if method == Method::Rgb3 && s == "xyz" {
                return Err(Error::Flag {
                    flag: "--method".into(),
                    value: "rgb3".into(),
                    message: "rgb3 gives RGB directly: choose an RGB --space".into(),
                });
            }
            if let Method::Fourier(h, sigma, None) = &method
                && args.method.trim().starts_with("fourier:")
            {
                let table = load_fourier_table(args.fourier_table.as_deref(), &c)?;
                method = Method::Fourier(*h, *sigma, Some(std::sync::Arc::new(table)));
            }
            (None, c)
        }
    };
    let colours = color::evaluate(
        &stack,
        &points,
        &method,
        &colorimeter,
        quantity,
        lut.as_ref(),
    )?;
    write_atomic(&args.output, |w| {
        color::write_csv(w, &stack, &points, &colours, &colorimeter)
    })
}

/// The `fourier` table named by `--fourier-table`, or the default-set one baked for the same
/// observer, illuminant and space as `colorimeter`.
fn load_fourier_table(
    given: Option<&str>,
    colorimeter: &nacre_optics::colour::Colorimeter,
) -> Result<nacre_bake::fourier_table::FourierTable> {
    use nacre_bake::error::Error;
    let settings = (
        colorimeter.observer().to_string(),
        colorimeter.illuminant().to_string(),
        colorimeter.space().to_string(),
    );
    let path = match given {
        Some(name) => bake::resolve_table(name),
        None => {
            let dir = bake::default_baked_dir();
            let mut found = None;
            if let Ok(entries) = std::fs::read_dir(&dir) {
                let mut paths: Vec<PathBuf> = entries
                    .filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|p| p.extension().is_some_and(|x| x == "json"))
                    .collect();
                paths.sort();
                for p in paths {
                    if let Ok(m) = bake::Manifest::read(&p)
                        && m.kind == "fourier"
                        && (m.observer.clone(), m.illuminant.clone(), m.space.clone()) == settings
                    {
                        found = Some(p);
                        break;
                    }
                }
            }
            found.ok_or_else(|| Error::Invalid {
                context: "--method fourier".into(),
                message: format!(
                    "no fourier table for observer {}, illuminant {}, space {} in {}: bake one (kind = \"fourier\") and pass --fourier-table, or use fourier-exact:",
                    settings.0,
                    settings.1,
                    settings.2,
                    dir.display()
                ),
            })?
        }
    };
    let manifest = bake::Manifest::read(&path)?;
    if (
        manifest.observer.clone(),
        manifest.illuminant.clone(),
        manifest.space.clone(),
    ) != settings
    {
        return Err(Error::Invalid {
            context: format!("--fourier-table {}", path.display()),
            message: format!(
                "the table was baked for observer {}, illuminant {}, space {}; this run uses {}, {}, {}",
                manifest.observer,
                manifest.illuminant,
                manifest.space,
                settings.0,
                settings.1,
                settings.2
            ),
        });
    }
    manifest.load_fourier(&path)
}

fn run_compare(args: &CompareArgs) -> Result<()> {
    use nacre_bake::compare;
    use nacre_bake::error::Error;
    let case = compare::CASES
        .iter()
        .find(|c| c.name == args.case)
        .ok_or_else(|| Error::Flag {
            flag: "--case".into(),
            value: args.case.clone(),
            message: format!(
                "expected one of {}",
                compare::CASES
                    .iter()
                    .map(|c| c.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        })?;
    let angles = parse_range("--angles", &args.angles)?;
    if let Some(a) = angles.iter().find(|a| !(a.abs() < 90.0)) {
        return Err(Error::Flag {
            flag: "--angles".into(),
            value: args.angles.clone(),
            message: format!("angle {a} must lie strictly between -90 and 90 degrees"),
        });
    }
    let thicknesses = parse_range("--thicknesses", &args.thicknesses)?;
    if let Some(d) = thicknesses.iter().find(|d| !(**d >= 0.0)) {
        return Err(Error::Flag {
            flag: "--thicknesses".into(),
            value: args.thicknesses.clone(),
            message: format!("thickness {d} must be non-negative"),
        });
    }
    let points = angles.len() as u64 * thicknesses.len() as u64;
    if points > 200_000 {
        return Err(Error::TooLarge {
            what: "--angles × --thicknesses points".into(),
            count: points,
            limit: 200_000,
        });
    }
    let results = compare::compare(case, &angles, &thicknesses)?;
    std::fs::create_dir_all(&args.output).map_err(|source| Error::Io {
        path: args.output.clone(),
        source,
    })?;
    compare::write_csv(
        &args.output.join("compare.csv"),
        &angles,
        &thicknesses,
        &results,
    )?;
    compare::write_png(
        &args.output.join("compare.png"),
        case,
        &angles,
        &thicknesses,
        &results,
    )?;
    println!("{}", case.description);
    println!("| method | mean ΔE2000 | p95 | max |");
    println!("|---|---|---|---|");
    for r in &results {
        let (mean, p95, max) = r.summary();
        println!("| `{}` | {mean:.3} | {p95:.3} | {max:.3} |", r.label);
    }
    Ok(())
}

fn run_bake(args: &BakeArgs) -> Result<()> {
    use indicatif::{ProgressBar, ProgressStyle};
    let paths = if args.recipes.is_empty() {
        bake::default_recipes()?
    } else {
        args.recipes.clone()
    };
    let out = args.out.clone().unwrap_or_else(bake::default_baked_dir);
    // Parse and validate every recipe before baking any.
    let recipes = paths
        .iter()
        .map(|p| bake::AnyRecipe::read(p))
        .collect::<Result<Vec<_>>>()?;
    for recipe in &recipes {
        let bar = ProgressBar::new(recipe.work()).with_style(
            ProgressStyle::with_template("{prefix:>16} [{bar:30}] {pos}/{len} {elapsed}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar.set_prefix(recipe.name().to_string());
        let start = std::time::Instant::now();
        let manifest = recipe.bake(&out, &|| bar.inc(1))?;
        bar.finish_and_clear();
        eprintln!(
            "baked {} in {:.2} s -> {}",
            recipe.name(),
            start.elapsed().as_secs_f64(),
            manifest.display()
        );
    }
    Ok(())
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Spectrum(args) => run_spectrum(&args),
        Command::Bake(args) => run_bake(&args),
        Command::Color(args) => run_color(&args),
        Command::Compare(args) => run_compare(&args),
        Command::Info { table } => {
            let path = bake::resolve_table(&table);
            let manifest = bake::Manifest::read(&path)?;
            println!(
                "{}",
                serde_json::to_string_pretty(&manifest).expect("manifest serialises")
            );
            Ok(())
        }
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
