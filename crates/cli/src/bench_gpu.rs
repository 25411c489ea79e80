//! `nacre bench-gpu`: full-screen passes of each technique timed against a plain GGX +
//! Schlick material on the same adapter.

use crate::args::{DEFAULT_WAVELENGTH_STEP_NM, refuse_step_for_integrated};
use crate::error::Result;
use clap::Args;
use nacre_format::{Manifest, Param, set};

pub const EXAMPLES: &str = "\
Every pass shades each pixel of a WIDTHxHEIGHT target with the same GGX microfacet material
(shaders/bench.wgsl); only the Fresnel term differs: Schlick (plain), film_lut, film_fourier
(--harmonics M, by default automatic, then M = 3) or film_spectral (N wavelengths), then
film_stack with 2, 4 and 8 films and film_glass with a coated pane (those 2 films on each
face of a 2 mm slab). A last pass times the diffraction technique
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
pub struct BenchGpuArgs {
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

pub fn run(args: &BenchGpuArgs) -> Result<()> {
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
    let ctx = crate::gpu::context()?;
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
        BenchPass::Glass,
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
