//! `nacre diffraction`: relative reflectance and colour of a diffracting surface over view
//! angles in the plane of incidence (Stam 1999; Dhillon et al. 2014), from a height field
//! (file or synthetic spec) or a baked `diffraction` table. The physics is
//! [`nacre_optics::diffraction`], the sources and CSV writers [`nacre_bake::kinds::diffraction`].

use clap::Args;
use nacre_bake::commands::grid::parse_range;
use nacre_bake::error::{Error, Result};
use nacre_bake::kinds::diffraction::{HeightSource, ViewSweep, par_map_pairs, write_colour_csv};
use nacre_bake::kinds::diffraction_integrated::DEFAULT_INTEGRATED_SAMPLES;
use nacre_format::atomic::write_atomic;
use nacre_format::{Manifest, set};
use nacre_optics::C64;
use nacre_optics::colour::Colorimeter;
use nacre_optics::diffraction::integrated::{IntegratedTable, WarpedAxis};
use nacre_optics::diffraction::{
    DEFAULT_COHERENCE_DIAMETER_UM, DiffractionSurface, FresnelTerm, SpectralGrid, TaylorTerms,
    max_phase, taylor_order_for,
};
use std::path::PathBuf;

/// Tolerance on the Taylor remainder bound for fields evaluated directly (f64 terms).
pub const TAYLOR_TOLERANCE: f64 = 1e-6;

pub const EXAMPLES: &str = "\
Geometry: x runs across the grating lines and the plane of incidence is x-z. --incidence
θ_i > 0 puts the light on the -x side; a view angle θ_r > 0 puts the viewer on the +x side,
so the specular direction is θ_r = θ_i and a grating of period d sends order m to
sin θ_m = sin θ_i + m λ / d. Output: `view_deg,wavelength_nm,reflectance` (relative
reflectance: Stam's BRDF over that of a flat perfect mirror in its specular direction, so a
mirror gives 1 there), or with --color `view_deg,X,Y,Z,R,G,B` (XYZ under the illuminant,
perfect reflector Y = 1; R, G, B linear in --space) summed over the --wavelengths grid.

Layouts: a baked table (--table) is evaluated in its own layout. `terms` tables (and height
fields, by default) sum the Taylor terms per wavelength; `integrated` tables (the fast
path: wavelength-integrated colour tables I_p(u, v), colour = C * sum_p w^p I_p, bilinear
in warped (u, v) as a shader samples them) give colours only (--color), on the grid and
in the colour space they were baked for. `--layout integrated` builds such a table in
memory from a height field (--integrated-samples texels along v, gamma = 3, covering the
directions asked for) and evaluates from it.

Height fields: sine:PERIOD_UM:AMPLITUDE_UM, blazed:PERIOD_UM:HEIGHT_UM (one row, whole
periods over the coherence diameter), cd[:SEED] (tracks 1.6 µm apart, pits 0.1 µm deep),
bumps:RADIUS_UM:HEIGHT_UM:FILL[:SEED] (Stam's random bumps), or a greyscale PNG (8/16 bit,
full scale = --height-scale), OpenEXR (channel Y, Z or R) or CSV file (× --height-scale)
with --pitch.

Examples:
  # first and second orders of a 1.6 µm sinusoidal grating lit at 30 degrees
  nacre diffraction sine:1.6:0.05 --incidence 30 --views -80:80:0.1 -o sine.csv
  # the colours of a CD-like surface seen across the tracks
  nacre diffraction cd --incidence 20 --views -60:60:0.5 --color -o cd.csv
  # a measured height map, 0.1 µm per pixel, white = 0.15 µm
  nacre diffraction snake.png --pitch 0.1 --height-scale 0.15 --color
  # from the baked default table
  nacre diffraction --table cd-tracks --incidence 20 --views -40:40:0.5 --color
  # from the baked integrated (fast path) table, as a shader would
  nacre diffraction --table cd-tracks-fast --incidence 20 --views -40:40:0.5 --color
  # a height field through an integrated table built in memory
  nacre diffraction sine:1.6:0.05 --coherence 16 --layout integrated --color --views -40:40:1";

/// The surface both `nacre diffraction` and `nacre plot diffraction` evaluate: a height
/// field (file or synthetic spec, and how to read and window it) or a baked table.
#[derive(Args)]
pub struct SurfaceArgs {
    /// Height field: a .png/.exr/.csv file or a synthetic spec (see below).
    #[arg(
        value_name = "FILE|SPEC",
        required_unless_present = "table",
        conflicts_with = "table"
    )]
    surface: Option<String>,
    /// Evaluate a baked `diffraction` table (default-set name or manifest path) instead.
    #[arg(long, value_name = "NAME|PATH")]
    table: Option<String>,
    /// Layout to evaluate a height field through: terms or integrated (colours only)
    /// [default: terms; a --table uses its own].
    #[arg(long, value_name = "terms|integrated")]
    layout: Option<String>,
    /// Texels along v of an in-memory integrated table (even, 4-4096; u gets half).
    #[arg(long, value_name = "N")]
    integrated_samples: Option<usize>,
    /// Sample pitch of the height field, µm (required for files; synthetic: automatic).
    #[arg(long, value_name = "UM")]
    pitch: Option<String>,
    /// Samples per axis of a synthetic field (along x for gratings) [default: automatic].
    #[arg(long, value_name = "N")]
    samples: Option<usize>,
    /// Height of a file's full scale (PNG) or multiplier (EXR, CSV), µm.
    #[arg(
        long,
        value_name = "UM",
        default_value = "1",
        allow_hyphen_values = true
    )]
    height_scale: String,
    /// Coherence diameter 4σ_s of the light, µm [default: 65].
    #[arg(long, value_name = "UM")]
    coherence: Option<String>,
}

#[derive(Args)]
pub struct DiffractionArgs {
    #[command(flatten)]
    source: SurfaceArgs,
    /// Incidence angle θ_i, degrees, in (-90, 90).
    #[arg(
        long,
        value_name = "DEG",
        default_value = "0",
        allow_hyphen_values = true
    )]
    incidence: String,
    /// View angles θ_r, degrees, signed (see below).
    #[arg(
        long,
        value_name = "START:END:STEP",
        default_value = "-80:80:0.25",
        allow_hyphen_values = true
    )]
    views: String,
    /// Vacuum wavelengths, nm (the colour grid with --color; within 360-830) [default:
    /// 380:780:5, or an integrated table's grid].
    #[arg(long, value_name = "START:END:STEP", allow_hyphen_values = true)]
    wavelengths: Option<String>,
    /// Write colours (view_deg,X,Y,Z,R,G,B) instead of spectra.
    #[arg(long)]
    color: bool,
    /// Fresnel factor: the refractive index (n or n+κi) of the bulk material, evaluated at
    /// the half-vector angle [default: F = 1, a perfect reflector].
    #[arg(long, value_name = "INDEX")]
    fresnel: Option<String>,
    /// CIE observer: 1931 or 1964 [default: 1931, or the table's].
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

fn flag(flag: &str, value: &str, message: impl Into<String>) -> Error {
    Error::Flag {
        flag: flag.into(),
        value: value.into(),
        message: message.into(),
    }
}

fn positive(name: &str, text: &str) -> Result<f64> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| {
            flag(
                name,
                text,
                "expected a finite positive number of micrometres",
            )
        })
}

fn angles(name: &str, text: &str) -> Result<Vec<f64>> {
    let v = parse_range(name, text)?;
    if let Some(a) = v.iter().find(|a| !(a.abs() < 90.0)) {
        return Err(flag(
            name,
            text,
            format!("angle {a} must lie strictly between -90 and 90 degrees"),
        ));
    }
    Ok(v)
}

/// How the colour (and, for terms, the spectrum) is evaluated.
pub enum Evaluator {
    /// The Taylor terms, per wavelength.
    Terms(DiffractionSurface),
    /// An integrated table (colours only).
    Integrated(IntegratedTable),
}

/// Everything `nacre diffraction` and `nacre plot diffraction` share: the evaluator, its
/// colorimeter and the wavelength grid.
pub struct Loaded {
    pub evaluator: Evaluator,
    pub colorimeter: Colorimeter,
    pub wavelengths: Vec<f64>,
    pub fresnel: FresnelTerm,
    /// What the evaluator came from (`--table NAME`, `--layout integrated`), for messages.
    pub context: String,
}

impl Loaded {
    /// (XYZ, output-space colour) for each light/view pair.
    pub fn colours(
        &self,
        directions: &[([f64; 3], [f64; 3])],
    ) -> Result<Vec<([f64; 3], [f64; 3])>> {
        let c = &self.colorimeter;
        match &self.evaluator {
            Evaluator::Terms(surface) => {
                let grid =
                    SpectralGrid::new(c, &self.wavelengths).map_err(|source| Error::OpticsIn {
                        context: "--wavelengths".into(),
                        source,
                    })?;
                Ok(par_map_pairs(directions, &|wi, wr| {
                    let rho: Vec<f64> = self
                        .wavelengths
                        .iter()
                        .map(|&l| surface.relative_reflectance(wi, wr, l, self.fresnel))
                        .collect();
                    let xyz = grid.xyz(&rho);
                    (xyz, c.output_from_xyz(xyz))
                }))
            }
            Evaluator::Integrated(table) => Ok(par_map_pairs(directions, &|wi, wr| {
                let out = table.colour(wi, wr, self.fresnel);
                (c.xyz_from_output(out), out)
            })),
        }
    }
}

/// The sources and options `load` reads.
pub struct Source<'a> {
    /// The height field or table and how to read it.
    pub surface: &'a SurfaceArgs,
    /// `--wavelengths` as given.
    pub wavelengths: Option<&'a str>,
    /// The grid when `--wavelengths` is not given (terms layout).
    pub default_wavelengths: &'a str,
    pub fresnel: Option<&'a str>,
    /// --observer, --illuminant, --space.
    pub colour: [Option<&'a str>; 3],
}

fn parse_wavelengths(text: &str) -> Result<Vec<f64>> {
    let wavelengths = parse_range("--wavelengths", text)?;
    if let Some(l) = wavelengths.iter().find(|l| !(**l >= 360.0 && **l <= 830.0)) {
        return Err(flag(
            "--wavelengths",
            text,
            format!("wavelength {l} nm is outside 360-830 nm"),
        ));
    }
    Ok(wavelengths)
}

/// Loads the surface or table of `src` for the light/view pairs `directions`, checking
/// the sampling and the table's range.
pub fn load(src: &Source, directions: &[([f64; 3], [f64; 3])]) -> Result<Loaded> {
    let a = src.surface;
    let (surface, table, layout) = (
        a.surface.as_deref(),
        a.table.as_deref(),
        a.layout.as_deref(),
    );
    let (pitch, coherence) = (a.pitch.as_deref(), a.coherence.as_deref());
    let (samples, integrated_samples, height_scale) =
        (a.samples, a.integrated_samples, a.height_scale.as_str());
    let integrated_wanted = match layout.map(str::trim) {
        None | Some("terms") => false,
        Some("integrated") => true,
        Some(other) => {
            return Err(flag("--layout", other, "expected `terms` or `integrated`"));
        }
    };
    if integrated_samples.is_some() && !integrated_wanted {
        return Err(flag(
            "--integrated-samples",
            &integrated_samples.unwrap_or(0).to_string(),
            "applies to --layout integrated only",
        ));
    }
    let fresnel = match src.fresnel {
        None => FresnelTerm::Unity,
        Some(text) => {
            let m = nacre_optics::Material::parse_index(text)
                .map_err(|e| flag("--fresnel", text, e.to_string()))?;
            let n: C64 = m
                .index_at(550.0)
                .map_err(|e| flag("--fresnel", text, e.to_string()))?;
            FresnelTerm::Index(n)
        }
    };
    // |u|, |v| and |w| reached by the directions asked for.
    let max_uv = directions
        .iter()
        .map(|(i, r)| (i[0] + r[0]).abs().max((i[1] + r[1]).abs()))
        .fold(0.0, f64::max);
    let w_max = directions
        .iter()
        .map(|(i, r)| i[2] + r[2])
        .fold(0.0, f64::max);
    let pick = |given: Option<&str>, table: &Option<String>, default: &str| {
        given
            .map(str::to_string)
            .or_else(|| table.clone())
            .unwrap_or_else(|| default.to_string())
    };
    let colorimeter_of = |table_colour: [Option<String>; 3]| -> Result<Colorimeter> {
        let o = pick(src.colour[0], &table_colour[0], "1931");
        let i = pick(src.colour[1], &table_colour[1], "d65");
        let s = pick(src.colour[2], &table_colour[2], "srgb");
        Ok(Colorimeter::new(
            o.parse()
                .map_err(|e: nacre_optics::Error| flag("--observer", &o, e.to_string()))?,
            i.parse()
                .map_err(|e: nacre_optics::Error| flag("--illuminant", &i, e.to_string()))?,
            s.parse()
                .map_err(|e: nacre_optics::Error| flag("--space", &s, e.to_string()))?,
        ))
    };
    let (terms, sigma_s, table_colour, context, wavelengths) = match (surface, table) {
        (_, Some(name)) => {
            let path = set::resolve_table(name);
            let manifest = Manifest::read(&path)?;
            let record = manifest
                .diffraction()
                .cloned()
                .ok_or_else(|| Error::Invalid {
                    context: path.display().to_string(),
                    message: format!(
                        "table `{}` is a `{}` table, not a diffraction table",
                        manifest.name, manifest.kind
                    ),
                })?;
            if let Some(l) = layout {
                return Err(flag(
                    "--layout",
                    l,
                    format!(
                        "applies to height fields; table `{name}` has the layout \"{}\"",
                        record.layout
                    ),
                ));
            }
            let integrated = record.layout == "integrated";
            let table_grid = format!(
                "{}:{}:{}",
                record.wavelength_min_nm, record.wavelength_max_nm, record.wavelength_step_nm
            );
            let wavelengths = match (src.wavelengths, integrated) {
                (Some(text), true) => {
                    let w = parse_wavelengths(text)?;
                    if w != parse_range("--wavelengths", &table_grid)? {
                        return Err(flag(
                            "--wavelengths",
                            text,
                            format!(
                                "table `{name}` has the integrated layout: its colours are summed over {table_grid} nm (leave --wavelengths out)"
                            ),
                        ));
                    }
                    w
                }
                (None, true) => parse_range("--wavelengths", &table_grid)?,
                (text, false) => parse_wavelengths(text.unwrap_or(src.default_wavelengths))?,
            };
            let wl_min = wavelengths.iter().copied().fold(f64::INFINITY, f64::min);
            let wl_max = wavelengths.iter().copied().fold(0.0, f64::max);
            if wl_min < record.wavelength_min_nm - 1e-9 || wl_max > record.wavelength_max_nm + 1e-9
            {
                return Err(flag(
                    "--wavelengths",
                    src.wavelengths.unwrap_or(src.default_wavelengths),
                    format!(
                        "table `{name}` serves {}-{} nm",
                        record.wavelength_min_nm, record.wavelength_max_nm
                    ),
                ));
            }
            let max_polar_deg = directions
                .iter()
                .map(|(i, r)| i[2].min(r[2]).clamp(-1.0, 1.0).acos().to_degrees())
                .fold(0.0, f64::max);
            if max_polar_deg > record.max_angle_deg + 1e-9 || max_uv > record.max_uv * (1.0 + 1e-9)
            {
                return Err(Error::Invalid {
                    context: "--incidence/--views".into(),
                    message: format!(
                        "light or view reaches {max_polar_deg:.2}° from the normal; table `{name}` serves light and view within {}° (|u|, |v| ≤ {:.4})",
                        record.max_angle_deg, record.max_uv
                    ),
                });
            }
            if coherence.is_some() || pitch.is_some() || samples.is_some() {
                return Err(flag(
                    "--table",
                    name,
                    "--coherence, --pitch and --samples come from the table",
                ));
            }
            let c = [
                Some(manifest.observer.clone()),
                Some(manifest.illuminant.clone()),
                Some(manifest.space.clone()),
            ];
            if integrated {
                let colorimeter = colorimeter_of(c.clone())?;
                let baked = manifest.colorimeter(&path)?;
                for (given, flag_name, same) in [
                    (
                        src.colour[0],
                        "--observer",
                        colorimeter.observer() == baked.observer(),
                    ),
                    (
                        src.colour[1],
                        "--illuminant",
                        colorimeter.illuminant() == baked.illuminant(),
                    ),
                    (
                        src.colour[2],
                        "--space",
                        colorimeter.space() == baked.space(),
                    ),
                ] {
                    if let (Some(v), false) = (given, same) {
                        return Err(flag(
                            flag_name,
                            v,
                            format!(
                                "table `{name}` has the integrated layout, baked for observer {}, illuminant {} and space {}",
                                baked.observer(),
                                baked.illuminant(),
                                baked.space()
                            ),
                        ));
                    }
                }
                let (_, table) = manifest.load_diffraction_integrated(&path)?;
                return Ok(Loaded {
                    evaluator: Evaluator::Integrated(table),
                    colorimeter,
                    wavelengths,
                    fresnel,
                    context: format!("--table {name}"),
                });
            }
            let (record, terms) = manifest.load_diffraction(&path)?;
            (
                terms,
                record.sigma_s_um,
                c,
                format!("--table {name}"),
                wavelengths,
            )
        }
        (Some(text), None) => {
            let wavelengths =
                parse_wavelengths(src.wavelengths.unwrap_or(src.default_wavelengths))?;
            let wl_min = wavelengths.iter().copied().fold(f64::INFINITY, f64::min);
            let coherence_um = match coherence {
                Some(t) => positive("--coherence", t)?,
                None => DEFAULT_COHERENCE_DIAMETER_UM,
            };
            let pitch_um = pitch.map(|t| positive("--pitch", t)).transpose()?;
            let scale = height_scale
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| {
                    flag(
                        "--height-scale",
                        height_scale,
                        "expected a finite non-negative number of micrometres",
                    )
                })?;
            if samples == Some(0) {
                return Err(flag("--samples", "0", "expected at least 1"));
            }
            let source = HeightSource::parse("FILE|SPEC", text)?;
            let field = source.load(text, "--pitch", coherence_um, pitch_um, samples, scale)?;
            let x = max_phase(&field, wl_min, w_max);
            let (order, bound) =
                taylor_order_for(x, TAYLOR_TOLERANCE).map_err(|source| Error::OpticsIn {
                    context: text.to_string(),
                    source,
                })?;
            eprintln!(
                "nacre: {}x{} samples at {} µm, Taylor order N = {order} (remainder bound {bound:.1e} at max |k w h| = {x:.3}), 4σ_s = {coherence_um} µm",
                field.nx(),
                field.ny(),
                field.pitch_um()
            );
            (
                TaylorTerms::compute(&field, order),
                coherence_um / 4.0,
                [None, None, None],
                text.to_string(),
                wavelengths,
            )
        }
        (None, None) => unreachable!("clap requires FILE|SPEC or --table"),
    };
    let wl_min = wavelengths.iter().copied().fold(f64::INFINITY, f64::min);
    let surface = DiffractionSurface::new(terms, sigma_s).map_err(|source| Error::OpticsIn {
        context: context.clone(),
        source,
    })?;
    surface
        .check_sampling(wl_min, max_uv)
        .map_err(|source| Error::OpticsIn {
            context: format!("{context} with --views/--incidence and --wavelengths"),
            source,
        })?;
    let colorimeter = colorimeter_of(table_colour)?;
    let evaluator = if integrated_wanted {
        let n = integrated_samples.unwrap_or(DEFAULT_INTEGRATED_SAMPLES);
        let axis =
            WarpedAxis::new(max_uv.clamp(1e-3, 2.0), 3.0, n).map_err(|source| Error::OpticsIn {
                context: "--integrated-samples".into(),
                source,
            })?;
        let grid =
            SpectralGrid::new(&colorimeter, &wavelengths).map_err(|source| Error::OpticsIn {
                context: "--wavelengths".into(),
                source,
            })?;
        eprintln!(
            "nacre: integrated table of {} x {n} texels x {} layers over |u|, |v| <= {:.4}",
            n / 2,
            2 * surface.terms().order() + 1,
            axis.max_uv
        );
        Evaluator::Integrated(IntegratedTable::compute(
            &surface,
            &grid,
            &colorimeter,
            axis,
        ))
    } else {
        Evaluator::Terms(surface)
    };
    Ok(Loaded {
        evaluator,
        colorimeter,
        wavelengths,
        fresnel,
        context: if integrated_wanted {
            "--layout integrated".into()
        } else {
            context
        },
    })
}

pub fn run(args: &DiffractionArgs) -> Result<()> {
    let incidence = args
        .incidence
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|a| a.abs() < 90.0)
        .ok_or_else(|| {
            flag(
                "--incidence",
                &args.incidence,
                "expected an angle in degrees strictly between -90 and 90",
            )
        })?;
    let views = angles("--views", &args.views)?;
    let directions: Vec<_> = views
        .iter()
        .map(|&v| nacre_optics::diffraction::in_plane_directions(incidence, v))
        .collect();
    if args.source.layout.as_deref().map(str::trim) == Some("integrated") && !args.color {
        return Err(flag(
            "--layout",
            "integrated",
            "the integrated layout holds colours summed over wavelengths: add --color, or use the terms layout for per-wavelength reflectance",
        ));
    }
    let loaded = load(
        &Source {
            surface: &args.source,
            wavelengths: args.wavelengths.as_deref(),
            default_wavelengths: "380:780:5",
            fresnel: args.fresnel.as_deref(),
            colour: [
                args.observer.as_deref(),
                args.illuminant.as_deref(),
                args.space.as_deref(),
            ],
        },
        &directions,
    )?;
    if args.color {
        let colours = loaded.colours(&directions)?;
        return Ok(write_atomic(&args.output, |w| {
            write_colour_csv(w, &views, &colours)
        })?);
    }
    let Evaluator::Terms(surface) = &loaded.evaluator else {
        return Err(Error::Invalid {
            context: loaded.context.clone(),
            message: "the integrated layout holds colours summed over wavelengths, not spectra: add --color, or use a terms table for per-wavelength reflectance".into(),
        });
    };
    let sweep = ViewSweep {
        surface,
        incidence_deg: incidence,
        views_deg: &views,
        wavelengths_nm: &loaded.wavelengths,
        fresnel: loaded.fresnel,
    };
    let rho = sweep.reflectance();
    Ok(write_atomic(&args.output, |w| {
        sweep.write_reflectance_csv(w, &rho)
    })?)
}

pub const MAP_EXAMPLES: &str = "\
The map shows the colour of the relative reflectance over view directions for a fixed
light (as `nacre diffraction --color`), on the projected hemisphere: x = sin θ_r cos φ_r
across the grating lines, y = sin θ_r sin φ_r along them, the light at --incidence on the
-x side (the white cross marks the specular direction). Colours are linear sRGB × exposure,
clipped; by default the exposure puts the 98th percentile at 1.

Examples:
  nacre plot diffraction cd --incidence 20 -o cd-map.png
  nacre plot diffraction sine:1.6:0.05 --incidence 30 --max-view 80 -o sine-map.png
  nacre plot diffraction --table cd-tracks --incidence 10 --max-view 35 -o table-map.png";

#[derive(Args)]
pub struct MapArgs {
    #[command(flatten)]
    source: SurfaceArgs,
    /// Incidence angle θ_i, degrees, in (-90, 90); the light is on the -x side.
    #[arg(
        long,
        value_name = "DEG",
        default_value = "20",
        allow_hyphen_values = true
    )]
    incidence: String,
    /// Largest view angle drawn, degrees, in (0, 90).
    #[arg(long, value_name = "DEG", default_value = "60")]
    max_view: String,
    /// Cells per side of the map (16 to 1024).
    #[arg(long, default_value_t = 161)]
    cells: usize,
    /// Wavelength grid of the colour sums, nm [default: 380:780:10, or an integrated
    /// table's grid].
    #[arg(long, value_name = "START:END:STEP")]
    wavelengths: Option<String>,
    /// Exposure: a positive factor, or `auto`.
    #[arg(long, default_value = "auto")]
    exposure: String,
    /// Output image (.png or .svg).
    #[arg(
        short = 'o',
        long = "output",
        value_name = "FILE",
        default_value = "diffraction.png"
    )]
    output: PathBuf,
}

pub fn run_map(args: &MapArgs) -> Result<()> {
    nacre_bake::commands::plot::ImageFormat::from_path(&args.output)?;
    let incidence = args
        .incidence
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|a| a.abs() < 90.0)
        .ok_or_else(|| {
            flag(
                "--incidence",
                &args.incidence,
                "expected an angle in degrees strictly between -90 and 90",
            )
        })?;
    let max_view = args
        .max_view
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|a| *a > 0.0 && *a < 90.0)
        .ok_or_else(|| {
            flag(
                "--max-view",
                &args.max_view,
                "expected an angle in degrees strictly between 0 and 90",
            )
        })?;
    if !(16..=1024).contains(&args.cells) {
        return Err(flag(
            "--cells",
            &args.cells.to_string(),
            "expected 16 to 1024",
        ));
    }
    let exposure = match args.exposure.trim() {
        "auto" => None,
        t => Some(
            t.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v > 0.0)
                .ok_or_else(|| flag("--exposure", t, "expected a positive number or `auto`"))?,
        ),
    };
    // The extreme view directions: the rim of the disc.
    let (wi, _) = nacre_optics::diffraction::in_plane_directions(incidence, 0.0);
    let s = max_view.to_radians().sin();
    let c = max_view.to_radians().cos();
    let directions: Vec<_> = [[s, 0.0, c], [-s, 0.0, c], [0.0, s, c], [0.0, -s, c]]
        .into_iter()
        .map(|r| (wi, r))
        .collect();
    let loaded = load(
        &Source {
            surface: &args.source,
            wavelengths: args.wavelengths.as_deref(),
            default_wavelengths: "380:780:10",
            fresnel: None,
            colour: [None, None, None],
        },
        &directions,
    )?;
    let name = args
        .source
        .surface
        .clone()
        .or_else(|| args.source.table.clone())
        .unwrap_or_default();
    let map = match &loaded.evaluator {
        Evaluator::Terms(surface) => {
            let grid =
                SpectralGrid::new(&loaded.colorimeter, &loaded.wavelengths).map_err(|source| {
                    Error::OpticsIn {
                        context: "--wavelengths".into(),
                        source,
                    }
                })?;
            nacre_bake::kinds::diffraction::DiffractionMap::compute(
                String::new(),
                surface,
                incidence,
                max_view,
                args.cells,
                &grid,
                &loaded.colorimeter,
                loaded.fresnel,
                exposure,
            )
        }
        Evaluator::Integrated(table) => {
            nacre_bake::kinds::diffraction::DiffractionMap::compute_with(
                String::new(),
                &|wi, wr| table.colour(wi, wr, loaded.fresnel),
                incidence,
                max_view,
                args.cells,
                &loaded.colorimeter,
                exposure,
            )
        }
    };
    let title = format!(
        "diffraction map of {name}: light at {incidence}°, views to {max_view}°, exposure {:.3}",
        map.exposure
    );
    let map = nacre_bake::kinds::diffraction::DiffractionMap { title, ..map };
    nacre_bake::commands::plot::write_figure(&args.output, &map)
}
