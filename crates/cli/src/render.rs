//! `nacre render`: a film scene, a diffraction scene, the rough row or a glTF file to a PNG
//! on the GPU.

use crate::args::{DEFAULT_WAVELENGTH_STEP_NM, StackArgs, load_stack, refuse_step_for_integrated};
use crate::choices::{ChannelArg, FilmEvalArg, LightingArg, OnOffArg, SceneArg, TechniqueArg};
use crate::error::{self, Result};
use clap::Args;
use nacre_bake::commands::stack_spec::StackSpec;
use nacre_format::atomic::write_atomic;
use nacre_format::{Manifest, Param, Render, set};
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
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
  # diffraction (technique `diffraction`, tables cd-tracks / dvd-tracks / snake-ridges /
  # grating-1200): a CD, a DVD, snake scales and a flat 1200 lines/mm grating under an
  # overhead light
  nacre render --scene cd-disc -o cd.png && nacre render --scene snake-skin -o snake.png
  nacre render --scene dvd-disc -o dvd.png && nacre render --scene grating-plane -o grating.png
  # the CD from the fast table (layout \"integrated\": the wavelength sum baked in)
  nacre render --scene cd-disc --tables cd-tracks-fast -o cd-fast.png

With --gltf, each material maps onto nacre's: iridescenceIor → film index, d = mix(thickness
minimum, maximum, g) with g the thickness texture's green channel (PNG; g = 1 without one),
iridescenceFactor → film weight, ior → dielectric base,
metallicFactor ≥ 0.5 → a metal whose index reproduces the base colour at normal incidence
(Gulbrandsen 2014). With --technique lut a material whose base, film index or thickness the
film-lut table cannot represent is drawn with fourier instead (a note on stderr says so).
With --technique glass a transmissive dielectric material (KHR_materials_transmission,
metallic 0) is drawn as a coated pane: air | its iridescence film | an incoherent slab of
its ior, KHR_materials_volume's thickness (0: thin-walled) | air; every other material with
fourier.";

#[derive(Args)]
pub struct RenderArgs {
    /// Scene: sphere, bubble, plane, rough-row (spheres of GGX α 0.05 … 0.8 by the
    /// film-at-n·v shortcut, the exact path and the Monte Carlo reference, three rows), or a
    /// diffraction scene: cd-disc (a CD-like disc with circular tracks; table cd-tracks),
    /// dvd-disc (the same disc with a DVD's 0.74 µm track pitch, lit from the left; table
    /// dvd-tracks), snake-skin (a curved patch of scales with fanned ridges; table snake-ridges) or
    /// grating-plane (a flat 1200 lines/mm grating; table grating-1200).
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
    /// cd-disc, dvd-disc, snake-skin and grating-plane take one diffraction table, either
    /// layout: cd-tracks, dvd-tracks, snake-ridges, grating-1200; cd-tracks-fast is the
    /// integrated table of the CD].
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
    layer_channels: Vec<ChannelArg>,
    /// Diffraction scenes: wavelength step of the colour sum, nm, over the table's range (the
    /// table's own step, 5 nm for the default set, is the CPU's grid); layout "terms" only
    /// (an integrated table's sum is fixed at bake time) [default: 10].
    #[arg(long, value_name = "NM")]
    wavelength_step: Option<f64>,
    /// Diffraction scenes: diffract the environment's K brightest directions like the light
    /// (0 to 8; 0: only its mirror image) instead of the default, the whole environment
    /// integrated through a "terms" table's lobes (an "integrated" table, which has none,
    /// diffracts 4 directions by default).
    #[arg(long, value_name = "K")]
    env_samples: Option<usize>,
    /// Diffraction scenes: GGX roughness α of the grating's microfacets, 0 to 1 (a brushed
    /// or scratched grating, a CD's worn coat): the two-scale model, every order blurred by
    /// the facets' slopes (docs/architecture.md, "Rough gratings"); a "terms" table blurs its
    /// environment lobes (not with --env-samples), an "integrated" table its prefiltered
    /// levels [default: 0, a smooth grating].
    #[arg(long, value_name = "ALPHA", allow_hyphen_values = true)]
    roughness: Option<f64>,
    /// Diffraction scenes: average the grating's BRDF over each pixel's footprint (ray
    /// differentials; a "terms" table sums its bins' Gaussians, an "integrated" table reads
    /// prefiltered levels) or point-sample it once per pixel, as before issue 37 (aliasing:
    /// a distant disc shows speckle). A rough grating's blur keeps the footprint either way
    /// [default: on].
    #[arg(long, value_enum, value_name = "ON|OFF")]
    footprint_filter: Option<OnOffArg>,
    /// Analytic scenes (not --gltf or rough-row): which sources light the scene: both (the
    /// directional light and the environment), light (the directional light alone: the
    /// environment is black) or environment (the environment alone, with the film scenes'
    /// sun in it). `python -m nacre.reference --lighting` takes the same choice, so that each
    /// source's picture can be measured against its reference [default: both].
    #[arg(long, value_enum, value_name = "SOURCES")]
    lighting: Option<LightingArg>,
    /// Output PNG file.
    #[arg(short = 'o', long = "output", value_name = "FILE.png")]
    output: PathBuf,
}

/// The name `--lighting` takes for `lighting`.
fn lighting_name(lighting: LightingArg) -> &'static str {
    match lighting {
        LightingArg::Both => "both",
        LightingArg::Light => "light",
        LightingArg::Environment => "environment",
    }
}

/// Refuses a stack with an incoherent layer (`--layer bk7@2mm:incoherent`, or
/// `incoherent = true` in `--recipe`) for every technique but `glass`: `film_stack` sums
/// coherent amplitudes at a few wavelengths and the other techniques draw their tables'
/// film, so rendering it with them would be silently wrong.
fn refuse_slabs(spec: &StackSpec, args: &StackArgs) -> Result<()> {
    refuse_slab(spec, args, 0, |j| {
        format!(
            "layer {j} is incoherent: only `--technique glass` draws an incoherent slab (the stack technique sums coherent amplitudes; the table techniques draw one film)"
        )
    })
}

/// Refuses a second incoherent layer for `--technique glass` (one pane: films, a slab, films).
fn refuse_second_slab(spec: &StackSpec, args: &StackArgs) -> Result<()> {
    refuse_slab(spec, args, 1, |j| {
        format!(
            "layer {j} is a second incoherent slab: the glass technique draws one slab (films, one slab, films); compute a stack of several with `nacre color --method spectral`"
        )
    })
}

/// The error naming the stack's `nth` incoherent layer (0: the first) as the user wrote it,
/// `why(layer number, 1-based)` its reason; none when the stack has no such layer.
fn refuse_slab(
    spec: &StackSpec,
    args: &StackArgs,
    nth: usize,
    why: impl Fn(usize) -> String,
) -> Result<()> {
    let Some(j) = spec
        .incoherent
        .iter()
        .enumerate()
        .filter(|(_, i)| **i)
        .nth(nth)
        .map(|(j, _)| j)
    else {
        return Ok(());
    };
    let (material, thickness_nm) = &spec.layers[j];
    let value = match args.layers.get(j) {
        Some(text) if args.recipe.is_none() => text.clone(),
        _ => format!("{}@{}nm:incoherent", material.spec, thickness_nm),
    };
    Err(nacre_bake::Error::value(material.context.clone(), value, why(j + 1)).into())
}

pub fn run(args: &RenderArgs) -> Result<()> {
    use nacre_runtime::mesh::{RenderInputs, TableFile, load_environment};
    use nacre_runtime::render::{FilmEval, SceneOptions, render_scene};
    use nacre_runtime::{Scene, TableSet, Technique};
    let film_eval = FilmEval::from(args.film_eval);
    let all = Scene::from(args.scene);
    if let (Some(alpha), Scene::RoughRow | Scene::Film(_)) = (args.roughness, all) {
        return Err(nacre_bake::error::Error::invalid(
            Param::Roughness,
            format!(
                "{alpha}: the roughness of a grating, for the diffraction scenes (cd-disc, dvd-disc, snake-skin, grating-plane) only"
            ),
        )
        .into());
    }
    if let (Some(filter), Scene::RoughRow | Scene::Film(_)) = (args.footprint_filter, all) {
        return Err(nacre_bake::error::Error::invalid(
            "--footprint-filter",
            format!(
                "{}: the footprint filter of the diffraction scenes (cd-disc, dvd-disc, snake-skin, grating-plane) only",
                if filter == OnOffArg::On { "on" } else { "off" }
            ),
        )
        .into());
    }
    if let Some(lighting) = args.lighting
        && (args.gltf.is_some() || all == Scene::RoughRow)
    {
        let (what, lit_by) = if args.gltf.is_some() {
            ("a glTF file is", "its own lights and --env")
        } else {
            ("rough-row is", "its fixed light")
        };
        return Err(nacre_bake::error::Error::invalid(
            "--lighting",
            format!(
                "{}: the analytic scenes' light and environment (sphere, bubble, plane, cd-disc, dvd-disc, snake-skin, grating-plane) only; {what} lit by {lit_by}",
                lighting_name(lighting),
            ),
        )
        .into());
    }
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
    match args.lighting {
        Some(LightingArg::Light) => options.env_intensity = 0.0,
        Some(LightingArg::Environment) => options.light.intensity = 0.0,
        Some(LightingArg::Both) | None => {}
    }
    if let Some(m) = args.harmonics {
        options.harmonics = m;
    }
    if let Some(n) = args.wavelengths {
        options.spectral_samples = n;
    }
    let s = &args.stack;
    let stacked = matches!(technique, Technique::Stack | Technique::Glass);
    if !stacked && (!s.layers.is_empty() || s.recipe.is_some()) {
        // The other techniques leave the stack flags unused; a slab among them is refused
        // all the same, rather than rendered as something else.
        if let Ok((spec, _, _)) = load_stack(s) {
            refuse_slabs(&spec, s)?;
        }
    }
    if stacked {
        let (spec, _, _) = load_stack(s)?;
        if technique == Technique::Stack {
            refuse_slabs(&spec, s)?;
        } else {
            refuse_second_slab(&spec, s)?;
        }
        let stack = spec.build()?;
        let relative = if args.relative.is_empty() {
            vec![0.0; stack.layers().len()]
        } else {
            args.relative.clone()
        };
        if let (Some(top), Some(r)) = (stack.layers().first(), relative.first()) {
            // A top slab keeps its own thickness (the glass technique ignores the pixel's).
            let average_nm = if stack.is_incoherent(1) {
                0.0
            } else {
                top.thickness_nm as f32
            };
            options.material.thickness = nacre_runtime::render::ThicknessMapping::Svt {
                average_nm,
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
    // Check the settings and read every input before starting the GPU: bad input fails fast;
    // what the renderer needs is kept, so that nothing is read twice.
    options.validate()?;
    let mut table_files = Vec::with_capacity(names.len());
    for name in &names {
        let path = set::resolve_table(name);
        let manifest = Manifest::read(&path)?;
        table_files.push(TableFile { path, manifest });
    }
    // The glTF renderer's environment (the default one without --env); the film scenes read
    // theirs again in render_scene.
    let environment = match (&args.gltf, &options.environment) {
        (Some(_), _) => Some(load_environment(&options)?),
        (None, Some(path)) => {
            nacre_runtime::render::EnvironmentMap::load(path)?;
            None
        }
        (None, None) => None,
    };
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
            Some((scene, view))
        }
        None => None,
    };
    // The camera fitted, the lights and the settings of the frame: still before the GPU.
    let inputs = match (&gltf, environment) {
        (Some((scene, view)), Some(environment)) => Some(RenderInputs::with_environment(
            scene,
            &options,
            *view,
            environment,
        )?),
        _ => None,
    };
    let ctx = crate::gpu::context()?;
    eprintln!("adapter: {}", ctx.describe());
    let mut tables = TableSet::default();
    for file in &table_files {
        file.upload(&ctx, &mut tables)?;
    }
    if let Some(inputs) = &inputs {
        let scene = inputs.scene;
        let start = std::time::Instant::now();
        let out = nacre_runtime::mesh::render(&ctx, &tables, technique, inputs)?;
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

/// `nacre render --scene cd-disc | dvd-disc | snake-skin | grating-plane`: the `diffraction`
/// technique.
fn run_render_diffraction(
    args: &RenderArgs,
    scene: nacre_runtime::diffraction::DiffractionScene,
) -> Result<()> {
    use nacre_runtime::diffraction::{
        DiffractionLayout, DiffractionSceneOptions, DiffractionTables, MAX_ROUGHNESS,
        render_diffraction_scene, wavelength_grid,
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
    match args.lighting {
        Some(LightingArg::Light) => options.env_intensity = 0.0,
        Some(LightingArg::Environment) => options.light.intensity = 0.0,
        Some(LightingArg::Both) | None => {}
    }
    if args.footprint_filter == Some(OnOffArg::Off) {
        options.technique.filter_radius = None;
    }
    if let Some(alpha) = args.roughness {
        if !(alpha.is_finite() && (0.0..=MAX_ROUGHNESS).contains(&alpha)) {
            return Err(nacre_bake::error::Error::invalid(
                Param::Roughness,
                format!("{alpha} (expected 0 to {MAX_ROUGHNESS}: the GGX α of the grating's microfacets)"),
            )
            .into());
        }
        options.roughness = alpha;
    }
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
            if options.roughness > 0.0 && args.env_samples.is_some() {
                return Err(nacre_bake::error::Error::invalid(
                    Param::Roughness,
                    format!("{}: a rough grating on a \"terms\" table (`{}`) is drawn through the table's environment lobes, which --env-samples replaces: leave --env-samples out, or use an \"integrated\" table (e.g. cd-tracks-fast)", options.roughness, manifest.name),
                )
                .into());
            }
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
    let ctx = crate::gpu::context()?;
    eprintln!("adapter: {}", ctx.describe());
    let table = DiffractionTables::load(&ctx, &path, options.technique.fresnel)?;
    let start = std::time::Instant::now();
    let image = render_diffraction_scene(&ctx, &table, &options)?;
    let total = start.elapsed().as_secs_f64();
    let png = image.encode_png()?;
    write_atomic(&args.output, |w| w.write_all(&png))?;
    eprintln!(
        "rendered {} (diffraction, {}, {sum}{}) at {}x{} in {:.2} s (render pass {:.2} s) -> {}",
        scene.name(),
        table.name(),
        if options.roughness > 0.0 {
            format!(", roughness {}", options.roughness)
        } else {
            String::new()
        },
        image.width,
        image.height,
        total,
        image.gpu_seconds,
        args.output.display()
    );
    Ok(())
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
    let ctx = crate::gpu::context()?;
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
