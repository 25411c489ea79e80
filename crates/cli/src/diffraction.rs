//! `nacre diffraction`: relative reflectance and colour of a diffracting surface over view
//! angles in the plane of incidence (Stam 1999; Dhillon et al. 2014), from a height field
//! (file or synthetic spec) or a baked `diffraction` table. The evaluation is
//! [`nacre_bake::commands::diffraction`]; this module holds the flags.

use crate::args::ColourArgs;
use clap::Args;
use nacre_bake::commands::diffraction::{
    self as lib, MapRequest, Source, SurfaceSpec, ViewsRequest,
};
use nacre_bake::error::Result;
use nacre_format::atomic::write_atomic;
use std::path::PathBuf;

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

impl SurfaceArgs {
    /// The surface as the library takes it.
    fn spec(&self) -> SurfaceSpec {
        SurfaceSpec {
            surface: self.surface.clone(),
            table: self.table.clone(),
            layout: self.layout.clone(),
            integrated_samples: self.integrated_samples,
            pitch: self.pitch.clone(),
            samples: self.samples,
            height_scale: self.height_scale.clone(),
            coherence: self.coherence.clone(),
        }
    }
}

pub fn run(args: &DiffractionArgs) -> Result<()> {
    let surface = args.source.spec();
    let output = lib::evaluate_views(&ViewsRequest {
        source: Source {
            surface: &surface,
            wavelengths: args.wavelengths.as_deref(),
            default_wavelengths: "380:780:5",
            fresnel: args.fresnel.as_deref(),
            colour: args.colour.settings(),
        },
        incidence: &args.incidence,
        views: &args.views,
        color: args.color,
    })?;
    Ok(write_atomic(&args.output, |w| output.write_csv(w))?)
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
    let map = lib::map(&MapRequest {
        surface: &args.source.spec(),
        incidence: &args.incidence,
        max_view: &args.max_view,
        cells: args.cells,
        wavelengths: args.wavelengths.as_deref(),
        exposure: &args.exposure,
    })?;
    nacre_bake::commands::plot::write_figure(&args.output, &map)
}
