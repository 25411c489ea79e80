//! `nacre`: bake thin-film interference tables and spectra, and render them on the GPU.

// `!(x > 0.0)` is how this crate rejects NaN together with out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use clap::{Args, Parser, Subcommand};
use nacre_bake::commands::color_request::ColourSettings;
use nacre_bake::commands::grid::parse_range;
use nacre_bake::commands::spectrum;
use nacre_bake::commands::stack_spec::{StackRecipe, StackSpec};
use nacre_bake::kinds;
use nacre_format::atomic::write_atomic;
use nacre_format::msg;
use nacre_format::{Manifest, Origin, Param, Render, materials, set};
use std::path::PathBuf;
use std::process::ExitCode;

mod choices;
mod diffraction;
mod error;
mod gpu;
mod plot;

use choices::{FilmEvalArg, QuantityArg, SceneArg, TechniqueArg};
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
    /// Diffraction by surface nanostructure (Stam 1999; Dhillon et al. 2014): relative
    /// reflectance or colour over view angles for a height field or a baked table, as CSV.
    #[command(after_help = diffraction::EXAMPLES)]
    Diffraction(diffraction::DiffractionArgs),
    /// Pictures (PNG or SVG): spectra, the chromaticity diagram with film trajectories,
    /// swatch charts of film colours, slices of baked tables.
    Plot(plot::PlotArgs),
    /// Reference data for glTF KHR_materials_iridescence renderers: exact colours over the
    /// extension's parameter space (CSV), the glTF approximation's error, swatch charts.
    #[command(after_help = CONFORMANCE_EXAMPLES)]
    Conformance(ConformanceArgs),
    /// Write one quantity of a film-lut or rough-film-lut table as a raw 3-D texture for a
    /// game engine (RGBA half floats, little-endian, x fastest, then y, then z) with a JSON
    /// sidecar (dimensions, format, axes, mappings, shader parameters); docs/engines/.
    #[command(after_help = EXPORT_EXAMPLES)]
    Export {
        /// A default-set table name (e.g. soap-film) or a manifest path.
        #[arg(long, value_name = "NAME|PATH")]
        table: String,
        /// reflectance or transmittance.
        #[arg(long, default_value = "reflectance")]
        quantity: String,
        /// The raw file to write (e.g. soap-film.reflectance.raw); the sidecar is the same
        /// path with extension .json. Both are written atomically.
        #[arg(long, value_name = "PATH")]
        out: std::path::PathBuf,
    },
    /// Print a baked table's manifest as JSON.
    Info {
        /// A default-set table name (e.g. film-dielectric) or a manifest path.
        #[arg(value_name = "NAME|PATH")]
        table: String,
    },
    /// List the bundled materials.
    Materials,
    /// Render a film-coated sphere, a soap bubble or an oil film on a plane to a PNG (GPU;
    /// any Vulkan/Metal/DX12/GL adapter, including Mesa's software lavapipe).
    #[command(after_help = RENDER_EXAMPLES)]
    Render(RenderArgs),
    /// Time full-screen passes of each technique against a plain GGX + Schlick material on
    /// the same adapter (GPU timestamps where supported) and report the ratios.
    #[command(name = "bench-gpu", after_help = BENCH_GPU_EXAMPLES)]
    BenchGpu(BenchGpuArgs),
}

const BENCH_GPU_EXAMPLES: &str = "\
Every pass shades each pixel of a WIDTHxHEIGHT target with the same GGX microfacet material
(shaders/bench.wgsl); only the Fresnel term differs: Schlick (plain), film_lut, film_fourier
(--harmonics M, by default automatic, then M = 3) or film_spectral (N wavelengths). A last pass times the diffraction technique
at the same resolution (one directional light per pixel, the --diffraction table: layout
\"terms\" sums over the --diffraction-step grid, layout \"integrated\" reads the sum baked into
the table). Times are GPU timestamps of the render pass where the adapter supports them,
else wall clock per frame; the median is reported.

Examples:
  # 1920x1080, 30 frames per pass, default tables (film-dielectric + fourier-srgb)
  nacre bench-gpu
  # a quick look on a software rasteriser
  nacre bench-gpu --width 640 --height 360 --frames 5
  # film_fourier's hardest case: a free film of index 2.26 (automatic harmonics vs M = 3)
  nacre bench-gpu --width 640 --height 360 --frames 5 --film-ior 2.26 --base-ior 1.0
  # the diffraction pass on the fast (integrated) table of the same CD surface
  nacre bench-gpu --width 320 --height 180 --frames 5 --diffraction cd-tracks-fast";

#[derive(Args)]
struct BenchGpuArgs {
    /// Target width, pixels.
    #[arg(long, default_value_t = 1920)]
    width: u32,
    /// Target height, pixels.
    #[arg(long, default_value_t = 1080)]
    height: u32,
    /// Frames measured per pass (after 3 discarded warm-up frames).
    #[arg(long, default_value_t = 30)]
    frames: u32,
    /// Harmonics M of film_fourier (0 = automatic, the runtime's default); a pass with
    /// M = 3 follows it.
    #[arg(long, default_value_t = 0)]
    harmonics: u32,
    /// Film index of every pixel.
    #[arg(long, value_name = "N", default_value_t = 1.45)]
    film_ior: f32,
    /// Base index of every pixel (real; 1.0 for a free film).
    #[arg(long, value_name = "N", default_value_t = 1.5)]
    base_ior: f32,
    /// Wavelengths N of film_spectral.
    #[arg(long, default_value_t = 30)]
    wavelengths: usize,
    /// Tables to load (repeatable) [default: film-dielectric + fourier-srgb].
    #[arg(long = "tables", value_name = "NAME|PATH")]
    tables: Vec<String>,
    /// The diffraction table of the `diffraction` pass (default-set name or manifest path;
    /// layout "terms" or "integrated", e.g. cd-tracks-fast).
    #[arg(long, value_name = "NAME|PATH", default_value = "cd-tracks")]
    diffraction: String,
    /// Wavelength step of the `diffraction` pass's colour sum, nm (as `nacre render`; layout
    /// "terms" only) [default: 10].
    #[arg(long, value_name = "NM")]
    diffraction_step: Option<f64>,
}

const BAKE_EXAMPLES: &str = "\
Examples:
  # the default set: every recipe in tables/recipes/ into tables/baked/
  nacre bake
  # one recipe into another folder
  nacre bake tables/recipes/film-gold.toml --out /tmp/tables
The recipe format is documented in the user guide (docs/guide/src/bake.md, \"Table recipes\").";

const COLOR_EXAMPLES: &str = "\
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
stack's optical thickness, or N of them).

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

/// `--observer`, `--illuminant`, `--space`: shared by `color` and `diffraction`.
#[derive(Args)]
struct ColourArgs {
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
    fn settings(&self) -> ColourSettings<'_> {
        ColourSettings {
            observer: self.observer.as_deref(),
            illuminant: self.illuminant.as_deref(),
            space: self.space.as_deref(),
        }
    }
}

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
    #[arg(
        long,
        value_name = "START:END:STEP",
        default_value = "0:85:2.5",
        allow_hyphen_values = true
    )]
    angles: String,
    /// Film thicknesses, nm.
    #[arg(
        long,
        value_name = "START:END:STEP",
        default_value = "0:1000:10",
        allow_hyphen_values = true
    )]
    thicknesses: String,
    /// Output folder: compare.csv and compare.png.
    #[arg(short = 'o', long = "output", value_name = "DIR")]
    output: PathBuf,
}

const EXPORT_EXAMPLES: &str = "\
Examples:
  nacre export --table soap-film --quantity reflectance --out soap-film.reflectance.raw
  nacre export --table rough-film-dielectric --quantity transmittance --out rough.t.raw
Loading the raw file in Unity, Unreal and three.js: docs/engines/.";

const RENDER_EXAMPLES: &str = "\
Scenes: sphere (a film of index 1.9 on a black glazed dielectric; on gold with --tables
film-gold), bubble (a draining soap film in air, reflection and transmission), plane (an oil
film on water to the horizon, the thickness map minified towards it). Techniques: lut
(trilinear lookup in the film-lut table), fourier (Belcour & Barla 2017 Eq. 10 with the
fourier table, prefiltered by the thickness's pixel footprint), spectral (N wavelengths, brute
force). The base, ambient and film index range come from the film-lut table. The environment
is an equirectangular OpenEXR, Radiance HDR, or sRGB PNG/JPEG (default tables/env/studio.exr);
the thickness map an 8/16-bit greyscale PNG or JPEG (default: built-in swirls). Output: 8-bit sRGB PNG (Khronos PBR Neutral tone
mapping).

Examples:
  # the film-coated sphere with the default tables
  nacre render -o sphere.png
  # a soap bubble, brute-force spectral with 40 wavelengths
  nacre render --scene bubble --technique spectral --wavelengths 40 -o bubble.png
  # the oil slick, Fourier with a fixed 3 harmonics (the default: automatic), half a stop darker
  nacre render --scene plane --technique fourier --harmonics 3 --exposure -0.5 -o plane.png
  # a film on gold, your own environment and thickness map
  nacre render --tables film-gold --tables fourier-srgb --env sky.exr --thickness-map swirl.png -o gold.png
  # a rough film lit the engines' way (film at n·v) and exactly (film per light, rough-film-lut)
  nacre render --film-eval nv -o shortcut.png && nacre render --film-eval exact -o exact.png
  # rough spheres α 0.05 … 0.8: shortcut, exact path and Monte Carlo reference, three rows
  nacre render --scene rough-row --reference-samples 1024 -o rough-row.png
  # a glTF 2.0 / GLB scene with KHR_materials_iridescence (meshes rasterised, camera fitted)
  nacre render --gltf tests/golden/gltf/sweep-thickness.glb --width 1000 --height 260 -o sweep.png
  # the same from above and to the left, or from the file's first camera
  nacre render --gltf scene.glb --yaw -35 --pitch 30 -o orbit.png
  nacre render --gltf scene.glb --camera 0 -o camera.png
  # diffraction (technique `diffraction`, tables cd-tracks / snake-ridges): a CD and snake scales
  nacre render --scene cd-disc -o cd.png && nacre render --scene snake-skin -o snake.png
  # the CD from the fast table (layout \"integrated\": the wavelength sum baked in)
  nacre render --scene cd-disc --tables cd-tracks-fast -o cd-fast.png

With --gltf, each material maps onto nacre's: iridescenceIor → film index, d = mix(thickness
minimum, maximum, g) with g the thickness texture's green channel (PNG; g = 1 without one),
iridescenceFactor → film weight, ior → dielectric base,
metallicFactor ≥ 0.5 → a metal whose index reproduces the base colour at normal incidence
(Gulbrandsen 2014). With --technique lut a material whose base, film index or thickness the
film-lut table cannot represent is drawn with fourier instead (a note on stderr says so).";

#[derive(Args)]
struct RenderArgs {
    /// Scene: sphere, bubble, plane, rough-row (spheres of GGX α 0.05 … 0.8 by the
    /// film-at-n·v shortcut, the exact path and the Monte Carlo reference, three rows), or a
    /// diffraction scene: cd-disc (a CD-like disc with circular tracks; table cd-tracks) or
    /// snake-skin (a curved patch of scales with fanned ridges; table snake-ridges).
    #[arg(long, value_enum, default_value = "sphere")]
    scene: SceneArg,
    /// How the film enters the lighting: classic (the film at v·h for the light, at n·v for
    /// a box-filtered environment), nv (the engines' shortcut: the film once at n·v for
    /// every light and the split-sum environment) or exact (the film at each light's half
    /// vector; the split-sum environment with the rough-film-lut table's directional
    /// albedo). nv and exact prefilter the environment with GGX at load.
    #[arg(long, value_enum, default_value = "classic")]
    film_eval: FilmEvalArg,
    /// Monte Carlo samples per pixel of the rough-row reference (16 to 1048576).
    #[arg(long, value_name = "N", default_value_t = 1024)]
    reference_samples: usize,
    /// Render a glTF 2.0 (.gltf / .glb) scene instead of --scene: its triangle meshes and
    /// materials (KHR_materials_iridescence, _ior, _transmission) [default tables:
    /// film-dielectric + fourier-srgb].
    #[arg(long, value_name = "FILE.glb", conflicts_with_all = ["scene", "thickness_map"])]
    gltf: Option<PathBuf>,
    /// A table to load (repeatable): default-set name or manifest path [default: the scene's
    /// film-lut (sphere film-dielectric, bubble soap-film, plane oil-slick) + fourier-srgb;
    /// cd-disc and snake-skin take one diffraction table, either layout: cd-tracks,
    /// snake-ridges; cd-tracks-fast is the integrated table of the CD].
    #[arg(long = "tables", value_name = "NAME|PATH")]
    tables: Vec<String>,
    /// Technique: lut, fourier, spectral, or stack (a multilayer stack per pixel from
    /// --ambient/--layer/--substrate or --recipe: the top film follows the scene's thickness
    /// map around its own thickness, the others move by their --relative thickness).
    #[arg(long, value_enum, default_value = "lut")]
    technique: TechniqueArg,
    /// Image width, pixels (1 to 8192).
    #[arg(long, default_value_t = 800)]
    width: u32,
    /// Image height, pixels (1 to 8192).
    #[arg(long, default_value_t = 600)]
    height: u32,
    /// Equirectangular environment (OpenEXR or Radiance HDR, linear; PNG or JPEG, sRGB;
    /// row 0 = zenith) [default: tables/env/studio.exr].
    #[arg(long, value_name = "FILE")]
    env: Option<PathBuf>,
    /// Thickness map, 8- or 16-bit PNG or JPEG: greyscale, or with --technique stack RGB,
    /// one channel per film (--layer-channel) [default: built-in swirls, channels R, G, B
    /// three phases of one pattern].
    #[arg(long, value_name = "FILE.png")]
    thickness_map: Option<PathBuf>,
    /// Exposure in EV stops (radiance × 2^EV before tone mapping).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
    /// With --gltf: render from the file's camera N (0-based, in node order) instead of the
    /// orbit camera.
    #[arg(long, value_name = "N", requires = "gltf", conflicts_with_all = ["yaw", "pitch", "distance"])]
    camera: Option<usize>,
    /// With --gltf: the orbit camera's rotation about the vertical axis, degrees (0: looking
    /// along −z; 90: from the +x side) [default: 0].
    #[arg(
        long,
        value_name = "DEG",
        requires = "gltf",
        allow_hyphen_values = true
    )]
    yaw: Option<f64>,
    /// With --gltf: the orbit camera's elevation, degrees (−89 to 89) [default: 11.3, the
    /// direction (0, 0.2, 1)].
    #[arg(
        long,
        value_name = "DEG",
        requires = "gltf",
        allow_hyphen_values = true
    )]
    pitch: Option<f64>,
    /// With --gltf: the orbit camera's distance from the scene's centre, in the file's units
    /// (metres) [default: the nearest that frames the whole scene].
    #[arg(long, value_name = "D", requires = "gltf")]
    distance: Option<f64>,
    /// Harmonics M of the fourier technique (0 = automatic: per pixel, as many as the
    /// series needs, as `nacre color --method fourier`) [default: 0].
    #[arg(long, value_name = "M")]
    harmonics: Option<u32>,
    /// Wavelengths N of the spectral technique (1 to 4096) [default: 30]; with --technique
    /// stack a fixed rule of N (1 to 256) [default: chosen per pixel].
    #[arg(long, value_name = "N")]
    wavelengths: Option<usize>,
    /// The stack of --technique stack.
    #[command(flatten)]
    stack: StackArgs,
    /// --technique stack: each film's relative thickness r, nm (repeat once per film, top
    /// first): film j spans d_j ± r_j over the thickness map (the top film's own r too)
    /// [default: 0 for every film].
    #[arg(long = "relative", value_name = "NM")]
    relative: Vec<f64>,
    /// --technique stack: the thickness-map channel each film follows (repeat once per film,
    /// top first; the top film's is r): one map for every film, or one channel per film
    /// (the thesis's SVT per layer) [default: r for every film].
    #[arg(long = "layer-channel", value_name = "C", value_enum)]
    layer_channels: Vec<choices::ChannelArg>,
    /// Diffraction scenes: wavelength step of the colour sum, nm, over the table's range (the
    /// table's own step, 5 nm for the default set, is the CPU's grid); layout "terms" only
    /// (an integrated table's sum is fixed at bake time) [default: 10].
    #[arg(long, value_name = "NM")]
    wavelength_step: Option<f64>,
    /// Diffraction scenes: brightest environment directions diffracted like the light (0 to 8).
    #[arg(long, value_name = "K", default_value_t = 4)]
    env_samples: usize,
    /// Output PNG file.
    #[arg(short = 'o', long = "output", value_name = "FILE.png")]
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
(`nacre materials` lists them), a path to a refractiveindex.info .yml or a
wavelength_nm,n,k .csv file, or a refractiveindex.info page SHELF/BOOK/PAGE
(`main/Au/Johnson`) with --material-db DIR. Thickness: nanometres, `635` or `635nm` (or `1.2um`).

Examples:
  # the default: a 400 nm soap film (index 1.33) in vacuum (1.0), 0:89:1 degrees ×
  # 380:780:5 nm, to stdout
  nacre spectrum
  # quarter-wave MgF2 anti-reflection coating on BK7 glass, to a file
  nacre spectrum --layer mgf2@99.75nm --substrate bk7 -o ar-coating.csv
  # 30 nm gold on glass at 45 degrees, every nanometre
  nacre spectrum --layer au@30 --substrate 1.52 --angles 45 --wavelengths 380:780:1
  # oil slick: oil film on water, seen from air
  nacre spectrum --ambient air --layer oil@450 --substrate water -o oil.csv
  # the same stack from a recipe file (docs/guide/src/spectrum.md, \"Stack recipes\")
  nacre spectrum --recipe tables/examples/ar-coating.toml -o ar.csv";

#[derive(Args)]
struct StackArgs {
    /// Ambient (incidence) medium; must be non-absorbing [default: 1.0, vacuum, at every
    /// wavelength; with a lut:/rough-lut: method and no stack flags, the table's own stack].
    #[arg(long, value_name = "M")]
    ambient: Option<String>,
    /// A film, top first; repeat for more films (default with no stack flags: 1.33@400, a
    /// soap film).
    #[arg(long = "layer", value_name = "M@THICKNESS")]
    layers: Vec<String>,
    /// Substrate (any index, absorbing allowed) [default: 1.0, vacuum].
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
fn load_stack(args: &StackArgs) -> nacre_bake::Result<(StackSpec, Option<String>, Option<String>)> {
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
    let range = |flag: Param, given: &Option<String>, recipe: Option<String>, default: &str| {
        let (context, text) = match (given, recipe) {
            (Some(t), _) => (Origin::from(flag), t.clone()),
            (None, Some(t)) => (msg![flag, " (from the recipe)"].into(), t),
            (None, None) => (Origin::from(flag), default.to_string()),
        };
        parse_range(context, &text)
    };
    let angles = range(Param::Angles, &args.angles, recipe_angles, "0:89:1")?;
    let wavelengths = range(
        Param::Wavelengths,
        &args.wavelengths,
        recipe_wavelengths,
        "380:780:5",
    )?;
    let stack = spec.build()?;
    let powers = spectrum::compute(&stack, &angles, &wavelengths)?;
    Ok(write_atomic(&args.output, |w| {
        spectrum::write_csv(w, &angles, &wavelengths, &powers)
    })?)
}

fn run_color(args: &ColorArgs) -> Result<()> {
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
    if let Some((samples, worst)) = out.monte_carlo {
        eprintln!(
            "rough-mc: {samples} samples per point (seed = point index); largest standard error per channel {worst:.2e}"
        );
    }
    Ok(write_atomic(&args.output, |w| {
        color::write_csv(w, &stack, &points, &out.colours, &prepared.colorimeter)
    })?)
}

fn run_compare(args: &CompareArgs) -> Result<()> {
    use nacre_bake::commands::compare;
    let case = compare::case_named(&args.case)?;
    let (angles, thicknesses) = compare::grid(&args.angles, &args.thicknesses)?;
    let results = compare::compare(case, &angles, &thicknesses)?;
    compare::write(&args.output, case, &angles, &thicknesses, &results)?;
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
    use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
    use nacre_format::TableKind;
    let paths = if args.recipes.is_empty() {
        set::default_recipes()?
    } else {
        args.recipes.clone()
    };
    let out = args.out.clone().unwrap_or_else(set::default_baked_dir);
    // Parse and validate every recipe before baking any.
    let recipes = paths
        .iter()
        .map(|p| kinds::read_recipe(p))
        .collect::<nacre_bake::Result<Vec<_>>>()?;
    // The tables bake concurrently, the largest first, each with its own parallel loops
    // inside: rayon's work stealing keeps every core busy through one table's serial
    // stretches (set-up, compression, file writing) with the others' work. Each table
    // writes only its own files and sums in a fixed order, so the bytes do not depend on
    // the schedule.
    let mut order: Vec<usize> = (0..recipes.len()).collect();
    order.sort_by_key(|&i| match recipes[i].kind() {
        TableKind::RoughFilmLut => 0,
        TableKind::Diffraction => 1,
        TableKind::Fourier => 2,
        _ => 3,
    });
    let bars = MultiProgress::new();
    let failure = std::sync::Mutex::new(None);
    rayon::scope_fifo(|scope| {
        for &i in &order {
            let (recipe, bars, out, failure) = (&recipes[i], &bars, &out, &failure);
            scope.spawn_fifo(move |_| {
                let bar = bars.add(
                    ProgressBar::new(recipe.work()).with_style(
                        ProgressStyle::with_template(
                            "{prefix:>22} [{bar:30}] {pos}/{len} {elapsed}",
                        )
                        .expect("valid template")
                        .progress_chars("=> "),
                    ),
                );
                bar.set_prefix(recipe.name().to_string());
                let start = std::time::Instant::now();
                match recipe.bake(out, &|| bar.inc(1)) {
                    Ok(manifest) => {
                        bar.finish_and_clear();
                        bars.suspend(|| {
                            eprintln!(
                                "baked {} in {:.2} s -> {}",
                                recipe.name(),
                                start.elapsed().as_secs_f64(),
                                manifest.display()
                            )
                        });
                    }
                    Err(e) => {
                        bar.abandon();
                        failure.lock().expect("not poisoned").get_or_insert(e);
                    }
                }
            });
        }
    });
    match failure.into_inner().expect("not poisoned") {
        Some(e) => Err(e.into()),
        None => Ok(()),
    }
}

fn run_render(args: &RenderArgs) -> Result<()> {
    use nacre_runtime::render::{FilmEval, SceneOptions, render_scene};
    use nacre_runtime::{Scene, TableSet, Technique};
    let film_eval = FilmEval::from(args.film_eval);
    let all = Scene::from(args.scene);
    let scene = match all {
        Scene::RoughRow => return run_render_rough_row(args),
        Scene::Diffraction(scene) => return run_render_diffraction(args, scene),
        Scene::Film(scene) => scene,
    };
    let technique = Technique::from(args.technique);
    let names = table_names(args, all, film_eval);
    let mut options = SceneOptions::new(scene);
    options.width = args.width;
    options.height = args.height;
    options.environment = args.env.clone();
    options.thickness_map = args.thickness_map.clone();
    options.exposure_ev = args.exposure;
    options.film_eval = film_eval;
    if let Some(m) = args.harmonics {
        options.harmonics = m;
    }
    if let Some(n) = args.wavelengths {
        options.spectral_samples = n;
    }
    if technique == Technique::Stack {
        let (spec, _, _) = load_stack(&args.stack)?;
        let stack = spec.build()?;
        let relative = if args.relative.is_empty() {
            vec![0.0; stack.layers().len()]
        } else {
            args.relative.clone()
        };
        if let (Some(top), Some(r)) = (stack.layers().first(), relative.first()) {
            options.material.thickness = nacre_runtime::render::ThicknessMapping::Svt {
                average_nm: top.thickness_nm as f32,
                relative_nm: *r as f32,
            };
            options.material.drain_nm = 0.0;
        }
        options.stack = nacre_runtime::bindings::StackSetup {
            stack,
            relative_nm: relative,
            channels: args.layer_channels.iter().map(|c| c.index()).collect(),
            samples: args.wavelengths,
        };
    }
    // Check the settings and read every input before starting the GPU: bad input fails fast.
    options.validate()?;
    for name in &names {
        Manifest::read(&set::resolve_table(name))?;
    }
    if let Some(path) = &options.environment {
        nacre_runtime::render::EnvironmentMap::load(path)?;
    }
    if let Some(path) = &options.thickness_map {
        nacre_runtime::render::ThicknessMap::load_for(path, technique)?;
    }
    let gltf = match &args.gltf {
        Some(path) => {
            let scene = nacre_runtime::gltf_scene::GltfScene::load(path)?;
            let view = match args.camera {
                Some(k) => nacre_runtime::mesh::ViewPoint::File(k),
                None => {
                    let default = nacre_runtime::mesh::Orbit::default();
                    nacre_runtime::mesh::ViewPoint::Orbit(nacre_runtime::mesh::Orbit {
                        yaw_deg: args.yaw.unwrap_or(default.yaw_deg),
                        pitch_deg: args.pitch.unwrap_or(default.pitch_deg),
                        distance: args.distance,
                    })
                }
            };
            let aspect = f64::from(options.width) / f64::from(options.height);
            nacre_runtime::mesh::view_camera(&scene, view, aspect)?;
            Some((scene, view))
        }
        None => None,
    };
    let ctx = gpu::context()?;
    eprintln!("adapter: {}", ctx.describe());
    let mut tables = TableSet::default();
    for name in &names {
        tables.add(&ctx, &set::resolve_table(name))?;
    }
    if let Some((scene, view)) = &gltf {
        let start = std::time::Instant::now();
        let out = nacre_runtime::mesh::render_gltf_from(
            &ctx, &tables, technique, scene, &options, *view,
        )?;
        for note in &out.notes {
            eprintln!("note: {}", note.named(&error::Flags));
        }
        let png = out.image.encode_png()?;
        write_atomic(&args.output, |w| w.write_all(&png))?;
        eprintln!(
            "rendered {} ({}, {} primitives) at {}x{} in {:.2} s -> {}",
            scene.path.display(),
            technique.name(),
            scene.primitives.len(),
            out.image.width,
            out.image.height,
            start.elapsed().as_secs_f64(),
            args.output.display()
        );
        return Ok(());
    }
    options.fit_to_tables(&tables)?;
    let start = std::time::Instant::now();
    let image = render_scene(&ctx, &tables, technique, &options)?;
    let total = start.elapsed().as_secs_f64();
    let png = image.encode_png()?;
    write_atomic(&args.output, |w| w.write_all(&png))?;
    eprintln!(
        "rendered {} ({}) at {}x{} in {:.2} s (render pass {:.2} s) -> {}",
        scene.name(),
        technique.name(),
        image.width,
        image.height,
        total,
        image.gpu_seconds,
        args.output.display()
    );
    Ok(())
}

/// `--tables`, or the tables `scene` reads by default.
fn table_names(
    args: &RenderArgs,
    scene: nacre_runtime::Scene,
    film_eval: nacre_runtime::render::FilmEval,
) -> Vec<String> {
    if args.tables.is_empty() {
        scene
            .default_tables(film_eval, args.gltf.is_some())
            .into_iter()
            .map(String::from)
            .collect()
    } else {
        args.tables.clone()
    }
}

/// `nacre render --scene cd-disc | snake-skin`: the `diffraction` technique.
fn run_render_diffraction(
    args: &RenderArgs,
    scene: nacre_runtime::diffraction::DiffractionScene,
) -> Result<()> {
    use nacre_runtime::diffraction::{
        DiffractionLayout, DiffractionSceneOptions, DiffractionTables, render_diffraction_scene,
        wavelength_grid,
    };
    let name = match args.tables.as_slice() {
        [] => scene.default_table().to_string(),
        [one] => one.clone(),
        _ => {
            return Err(nacre_bake::error::Error::invalid(
                Param::Tables,
                format!("the {} scene takes one diffraction table", scene.name()),
            )
            .into());
        }
    };
    let mut options = DiffractionSceneOptions::new(scene);
    options.width = args.width;
    options.height = args.height;
    options.environment = args.env.clone();
    options.exposure_ev = args.exposure;
    options.env_samples = args.env_samples;
    // Check the settings and read every input before starting the GPU: bad input fails fast.
    options.validate()?;
    let path = set::resolve_table(&name);
    let manifest = Manifest::read(&path)?;
    let record = manifest.diffraction().cloned().ok_or_else(|| {
        nacre_bake::error::Error::invalid(
            path.display().to_string(),
            format!(
                "table `{}` is a `{}` table; the {} scene needs a diffraction table",
                manifest.name,
                manifest.kind,
                scene.name()
            ),
        )
    })?;
    let layout = DiffractionLayout::of(&record, &path)?;
    let sum = match layout {
        DiffractionLayout::Terms { .. } => {
            let step_nm = args.wavelength_step.unwrap_or(DEFAULT_WAVELENGTH_STEP_NM);
            wavelength_grid(&record, Some(step_nm)).map_err(|_| {
                nacre_bake::error::Error::invalid(
                    Param::WavelengthStep,
                    format!(
                        "{step_nm} nm over {}–{} nm (expected 2 to 4096 wavelengths)",
                        record.wavelength_min_nm, record.wavelength_max_nm
                    ),
                )
            })?;
            options.technique.wavelength_step_nm = Some(step_nm);
            format!("{step_nm} nm step")
        }
        DiffractionLayout::Integrated { .. } => {
            refuse_step_for_integrated(Param::WavelengthStep, args.wavelength_step, &manifest)?;
            "integrated".to_string()
        }
    };
    if let Some(path) = &options.environment {
        nacre_runtime::render::EnvironmentMap::load(path)?;
    }
    let ctx = gpu::context()?;
    eprintln!("adapter: {}", ctx.describe());
    let table = DiffractionTables::load(&ctx, &path, options.technique.fresnel)?;
    let start = std::time::Instant::now();
    let image = render_diffraction_scene(&ctx, &table, &options)?;
    let total = start.elapsed().as_secs_f64();
    let png = image.encode_png()?;
    write_atomic(&args.output, |w| w.write_all(&png))?;
    eprintln!(
        "rendered {} (diffraction, {}, {sum}) at {}x{} in {:.2} s (render pass {:.2} s) -> {}",
        scene.name(),
        table.name(),
        image.width,
        image.height,
        total,
        image.gpu_seconds,
        args.output.display()
    );
    Ok(())
}

/// Default wavelength step of the terms technique's colour sum, nm (`nacre render
/// --wavelength-step`, `nacre bench-gpu --diffraction-step`).
const DEFAULT_WAVELENGTH_STEP_NM: f64 = 10.0;

/// An integrated `diffraction` table's wavelength sum was done at bake time: refuses `flag`
/// when it was given for one.
fn refuse_step_for_integrated(
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

/// `nacre render --scene rough-row`: the shortcut, exact and Monte Carlo rows.
fn run_render_rough_row(args: &RenderArgs) -> Result<()> {
    use nacre_runtime::rough_reference::{RoughRowOptions, render_rough_row};
    use nacre_runtime::{TableSet, Technique};
    if !(16..=1 << 20).contains(&args.reference_samples) {
        return Err(nacre_bake::error::Error::invalid(
            Param::ReferenceSamples,
            format!("{} (expected 16 to 1048576)", args.reference_samples),
        )
        .into());
    }
    let technique = Technique::from(args.technique);
    let names = table_names(
        args,
        nacre_runtime::Scene::RoughRow,
        nacre_runtime::render::FilmEval::Exact,
    );
    for name in &names {
        Manifest::read(&set::resolve_table(name))?;
    }
    let options = RoughRowOptions {
        samples_per_pixel: args.reference_samples,
        exposure_ev: args.exposure,
        environment: args.env.clone(),
        ..RoughRowOptions::default()
    };
    let ctx = gpu::context()?;
    eprintln!("adapter: {}", ctx.describe());
    let mut tables = TableSet::default();
    for name in &names {
        tables.add(&ctx, &set::resolve_table(name))?;
    }
    let row = render_rough_row(&ctx, &tables, technique, &options)?;
    let png = row.image.encode_png()?;
    write_atomic(&args.output, |w| w.write_all(&png))?;
    eprintln!("alpha   mean dE2000 vs Monte Carlo: film at n.v   exact");
    for (alpha, nv, exact) in &row.delta_e {
        eprintln!("{alpha:5.2}   {nv:38.3}   {exact:5.3}");
    }
    eprintln!(
        "rendered rough-row ({}) at {}x{}: GPU {:.2} s, Monte Carlo reference ({} samples per pixel) {:.1} s -> {}",
        technique.name(),
        row.image.width,
        row.image.height,
        row.gpu_seconds,
        args.reference_samples,
        row.reference_seconds,
        args.output.display()
    );
    Ok(())
}

fn run_bench_gpu(args: &BenchGpuArgs) -> Result<()> {
    use nacre_runtime::bench::{BenchOptions, BenchPass, run_bench_with_diffraction};
    use nacre_runtime::bindings::TechniqueOptions;
    use nacre_runtime::diffraction::{DiffractionLayout, DiffractionOptions, DiffractionTables};
    use nacre_runtime::{TableSet, Technique};
    let names: Vec<String> = if args.tables.is_empty() {
        vec!["film-dielectric".into(), "fourier-srgb".into()]
    } else {
        args.tables.clone()
    };
    for name in &names {
        Manifest::read(&set::resolve_table(name))?;
    }
    let diffraction_path = set::resolve_table(&args.diffraction);
    let diffraction_manifest = Manifest::read(&diffraction_path)?;
    let mut diffraction_options = DiffractionOptions::default();
    // The sum the diffraction pass does, for the report.
    let diffraction_sum = match diffraction_manifest
        .diffraction()
        .map(|record| DiffractionLayout::of(record, &diffraction_path))
    {
        Some(Ok(DiffractionLayout::Integrated { .. })) => {
            refuse_step_for_integrated(
                Param::DiffractionStep,
                args.diffraction_step,
                &diffraction_manifest,
            )?;
            "(layout integrated)".to_string()
        }
        Some(Err(e)) => return Err(e.into()),
        // Another kind fails in the loader, with its message.
        Some(Ok(DiffractionLayout::Terms { .. })) | None => {
            let step_nm = args.diffraction_step.unwrap_or(DEFAULT_WAVELENGTH_STEP_NM);
            diffraction_options.wavelength_step_nm = Some(step_nm);
            format!("at a {step_nm} nm step")
        }
    };
    for (flag, value) in [
        (Param::BenchFilmIor, args.film_ior),
        (Param::BenchBaseIor, args.base_ior),
    ] {
        if !(value.is_finite() && (1.0..=4.0).contains(&value)) {
            return Err(nacre_bake::error::Error::invalid(
                flag,
                format!("{value} (expected an index from 1 to 4)"),
            )
            .into());
        }
    }
    let mut technique = TechniqueOptions {
        harmonics: args.harmonics,
        ..Default::default()
    };
    technique.spectral.samples = args.wavelengths;
    let options = BenchOptions {
        width: args.width,
        height: args.height,
        frames: args.frames,
        warmup: 3,
        technique,
        film_ior: args.film_ior,
        base_ior: args.base_ior,
    };
    let ctx = gpu::context()?;
    eprintln!("adapter: {}", ctx.describe());
    let mut tables = TableSet::default();
    for name in &names {
        tables.add(&ctx, &set::resolve_table(name))?;
    }
    let diffraction =
        DiffractionTables::load(&ctx, &diffraction_path, diffraction_options.fresnel)?;
    let passes = [
        BenchPass::Plain,
        BenchPass::Film(Technique::Lut),
        BenchPass::Film(Technique::Fourier),
        BenchPass::FourierFixed(3),
        BenchPass::Film(Technique::Spectral),
        BenchPass::Stack(2),
        BenchPass::Stack(4),
        BenchPass::Stack(8),
        BenchPass::Diffraction,
    ];
    let results = run_bench_with_diffraction(
        &ctx,
        &tables,
        Some((&diffraction, &diffraction_options)),
        &passes,
        &options,
    )?;
    let plain = results[0].median_ms;
    let lut = results[1].median_ms;
    println!(
        "{}x{}, {} frames per pass, {} (film {} on base {}, fourier M = {} (0: automatic), spectral N = {}, diffraction {} {})",
        args.width,
        args.height,
        args.frames,
        if results[0].timestamps {
            "GPU timestamps"
        } else {
            "wall clock (no timestamp queries)"
        },
        args.film_ior,
        args.base_ior,
        args.harmonics,
        args.wavelengths,
        diffraction.name(),
        diffraction_sum
    );
    println!(
        "{:<22} {:>11} {:>11} {:>10} {:>10}",
        "pass", "median ms", "min ms", "/ plain", "/ lut"
    );
    for r in &results {
        println!(
            "{:<22} {:>11.3} {:>11.3} {:>10.2} {:>10.2}",
            r.pass.name(),
            r.median_ms,
            r.min_ms,
            r.median_ms / plain,
            r.median_ms / lut
        );
    }
    Ok(())
}

const CONFORMANCE_EXAMPLES: &str = "\
Writes DIR/conformance.csv (base_ior,angle_deg,thickness_nm,film_ior,X,Y,Z,R,G,B: exact
unpolarised reflectance colour of air | film | base, CIE 1931 2 deg, D65, Y = 1 for a perfect
reflector, linear sRGB), DIR/gltf-reference-error.csv (the glTF reference approximation and
its CIEDE2000), DIR/swatches-<base>.png and DIR/README.md (conventions, glTF mapping, how to
compare a renderer). Bases (base_ior) 1, 1.25, 1.5, 1.75, 2, 2.5, au, ag, cu, al; film index
1.0-2.333; thickness 0-1200 nm; angles 0-89 deg. Every file is written to a temporary file
first and renamed only when all are complete.

Examples:
  # the default grid (48 510 rows, 5 MB of CSV; the copy in docs/conformance/)
  nacre conformance -o docs/conformance
  # a denser grid (202 730 rows, about 21 MB)
  nacre conformance --fine -o conformance-fine
  # a coarse grid for quick checks (2 080 rows)
  nacre conformance --quick -o /tmp/conformance";

#[derive(Args)]
struct ConformanceArgs {
    /// A coarse grid for tests: angles 0, 30, 60, 85; thickness step 100 nm; film index 1.0,
    /// 1.3, 1.5, 2.333.
    #[arg(long, conflicts_with = "fine")]
    quick: bool,
    /// A denser grid: angles 0-85 step 5 and 89; thickness step 12.5 nm; film index 1.0-1.8
    /// step 0.1, 2.0, 2.333.
    #[arg(long)]
    fine: bool,
    /// Output folder (created if needed; files of the same names are replaced).
    #[arg(short = 'o', long = "output", value_name = "DIR")]
    output: PathBuf,
}

fn run_conformance(args: &ConformanceArgs) -> Result<()> {
    use nacre_bake::commands::conformance::{self, GridSize};
    let size = if args.quick {
        GridSize::Quick
    } else if args.fine {
        GridSize::Fine
    } else {
        GridSize::Default
    };
    let start = std::time::Instant::now();
    let set = conformance::write(&args.output, size)?;
    eprintln!(
        "wrote conformance.csv ({} rows), gltf-reference-error.csv, {} swatch charts and README.md in {:.1} s -> {}",
        set.bases.len() * set.grid.points_per_base(),
        set.bases.len(),
        start.elapsed().as_secs_f64(),
        args.output.display()
    );
    Ok(())
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
        Command::Spectrum(args) => run_spectrum(&args),
        Command::Bake(args) => run_bake(&args),
        Command::Color(args) => run_color(&args),
        Command::Compare(args) => run_compare(&args),
        Command::Diffraction(args) => Ok(diffraction::run(&args)?),
        Command::Plot(args) => Ok(plot::run(&args)?),
        Command::Conformance(args) => run_conformance(&args),
        Command::Render(args) => run_render(&args),
        Command::BenchGpu(args) => run_bench_gpu(&args),
        Command::Export {
            table,
            quantity,
            out,
        } => {
            let path = set::resolve_table(&table);
            let texture = nacre_format::export::export_raw(&path, &quantity)?;
            let sidecar = nacre_format::export::write_raw(&out, &texture)?;
            eprintln!(
                "nacre export: {} ({} × {} × {} RGBA16F) and {}",
                out.display(),
                texture.width,
                texture.height,
                texture.depth,
                sidecar.display()
            );
            Ok(())
        }
        Command::Info { table } => {
            let path = set::resolve_table(&table);
            let manifest = Manifest::read(&path)?;
            println!(
                "{}",
                serde_json::to_string_pretty(&manifest).expect("manifest serialises")
            );
            Ok(())
        }
        Command::Materials => {
            // The ranges exactly as the data give them (not rounded: each bound printed is
            // accepted).
            for b in materials::BUNDLED {
                let m = materials::load_bundled(b)?;
                let (lo, hi) = m.range_nm();
                println!(
                    "{:<13} {:<26} {}",
                    b.name,
                    format!("{lo}–{hi} nm"),
                    b.description
                );
            }
            Ok(())
        }
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
    for w in materials::take_warnings() {
        eprintln!("nacre: warning: {w}");
    }
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
