//! `nacre bench-gpu`: the cost of each technique's film term in a full-screen GGX pass,
//! against the same pass with Schlick's Fresnel and no film (`shaders/plain.wgsl`,
//! `shaders/bench.wgsl`), and the cost of the `diffraction` technique at the same
//! resolution ([`BenchPass::Diffraction`]: every pixel evaluates Σ_λ ρ(λ) u(λ) for one
//! directional light over a swirling grating direction, scene 2 of
//! `shaders/diffraction_scene.wgsl`; with a layout "integrated" table, the same pass reads
//! the baked wavelength sum instead, `shaders/diffraction_integrated.wgsl`).
//!
//! Each pass draws one full-screen triangle into an `Rgba8Unorm` target. With
//! `TIMESTAMP_QUERY` the GPU time of every pass comes from timestamps written at the
//! beginning and end of the render pass (converted with the queue's timestamp period);
//! otherwise from the wall-clock time of submit + wait, per frame. The median over the
//! measured frames is reported, after warm-up frames that are discarded.

use crate::bindings::{StackSetup, TechniqueBinding, TechniqueOptions};
use crate::context::BufferInitExt;
use crate::context::GpuContext;
use crate::diffraction::{DiffractionOptions, DiffractionTables, ScenePass};
use crate::error::{Error, Result};
use crate::gpu;
use crate::render::Light;
use crate::shaders::{self, Technique};
use crate::tables::TableSet;
use std::time::Instant;

/// What one bench pass shades.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BenchPass {
    /// GGX + Schlick, no film.
    Plain,
    /// GGX with the technique's film term in place of Fresnel.
    Film(Technique),
    /// `film_fourier` with a fixed number of harmonics M (whatever
    /// [`BenchOptions::technique`] says), to time the default (automatic) against M.
    FourierFixed(u32),
    /// The `diffraction` technique (the table's layout, "terms" or "integrated") for one
    /// directional light per pixel.
    Diffraction,
    /// `film_stack` with a dielectric stack of this many films
    /// ([`StackSetup::alternating`]), the rule ladder.
    Stack(usize),
    /// `film_glass` with a coated pane ([`StackSetup::coated_pane`]: two films on each face
    /// of a 2 mm slab), the rule ladder.
    Glass,
}

impl BenchPass {
    /// Name for reports.
    pub fn name(self) -> &'static str {
        match self {
            BenchPass::Plain => "plain GGX + Schlick",
            BenchPass::Film(t) => t.entry().bench_label,
            BenchPass::FourierFixed(3) => "film_fourier, M = 3",
            BenchPass::FourierFixed(_) => "film_fourier, fixed M",
            BenchPass::Diffraction => "diffraction",
            BenchPass::Stack(2) => "film_stack, 2 films",
            BenchPass::Stack(4) => "film_stack, 4 films",
            BenchPass::Stack(8) => "film_stack, 8 films",
            BenchPass::Stack(_) => "film_stack, N films",
            BenchPass::Glass => "film_glass, 2+slab+2",
        }
    }
}

/// Settings of a bench run.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// Target width in pixels.
    pub width: u32,
    /// Target height in pixels.
    pub height: u32,
    /// Frames measured per pass.
    pub frames: u32,
    /// Frames drawn first and discarded.
    pub warmup: u32,
    /// Technique settings (harmonics, spectral wavelengths and base).
    pub technique: TechniqueOptions,
    /// Film index of every pixel (default 1.45).
    pub film_ior: f32,
    /// Base index of every pixel, real (default 1.5; 1.0 for a free film).
    pub base_ior: f32,
}

impl Default for BenchOptions {
    fn default() -> Self {
        BenchOptions {
            width: 1920,
            height: 1080,
            frames: 30,
            warmup: 3,
            technique: TechniqueOptions::default(),
            film_ior: 1.45,
            base_ior: 1.5,
        }
    }
}

/// The result of one pass.
#[derive(Clone, Debug)]
pub struct BenchResult {
    /// The pass.
    pub pass: BenchPass,
    /// Median time per frame, ms.
    pub median_ms: f64,
    /// Fastest frame, ms.
    pub min_ms: f64,
    /// Whether the times are GPU timestamps (else wall clock).
    pub timestamps: bool,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct BenchParams {
    resolution: [f32; 2],
    roughness: f32,
    film_ior: f32,
    base_ior: [f32; 3],
    ambient_ior: f32,
    base_kappa: [f32; 3],
    pad: f32,
}

/// Times `passes` on `ctx` with the tables of `tables` (a `film-lut` table for
/// [`Technique::Lut`], a `fourier` table for the others' colorimeter).
pub fn run_bench(
    ctx: &GpuContext,
    tables: &TableSet,
    passes: &[BenchPass],
    options: &BenchOptions,
) -> Result<Vec<BenchResult>> {
    run_bench_with_diffraction(ctx, tables, None, passes, options)
}

/// [`run_bench`] with a `diffraction` table and its settings for [`BenchPass::Diffraction`]
/// (an [`Error::Invalid`] when that pass is asked for without one).
pub fn run_bench_with_diffraction(
    ctx: &GpuContext,
    tables: &TableSet,
    diffraction: Option<(&DiffractionTables, &DiffractionOptions)>,
    passes: &[BenchPass],
    options: &BenchOptions,
) -> Result<Vec<BenchResult>> {
    let limit = ctx.device.limits().max_texture_dimension_2d;
    if options.width == 0 || options.height == 0 || options.width > limit || options.height > limit
    {
        return Err(Error::TargetSize {
            what: "bench-gpu",
            width: options.width,
            height: options.height,
            max: limit,
        });
    }
    if options.frames == 0 {
        return Err(Error::OutOfRange {
            what: "bench-gpu: frames".into(),
            value: 0.0,
            unit: "",
            expected: "at least 1".into(),
        });
    }
    let colorimeter = tables.colorimeter()?;
    let timestamps = ctx
        .device
        .features()
        .contains(wgpu::Features::TIMESTAMP_QUERY);
    let device = &ctx.device;
    let target = crate::gpu::render_target(
        device,
        "bench target",
        (options.width, options.height),
        wgpu::TextureFormat::Rgba8Unorm,
        false,
    );
    let view = target.create_view(&Default::default());
    let params = BenchParams {
        resolution: [options.width as f32, options.height as f32],
        roughness: 0.3,
        film_ior: options.film_ior,
        base_ior: [options.base_ior; 3],
        ambient_ior: 1.0,
        base_kappa: [0.0; 3],
        pad: 0.0,
    };
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("BenchParams"),
        contents: bytemuck::bytes_of(&params),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let view_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("bench view"),
        entries: &[gpu::uniform_entry(0)],
    });
    let view_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("bench view"),
        layout: &view_layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: uniform.as_entire_binding(),
        }],
    });
    let empty_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("no tables"),
        entries: &[],
    });
    let empty_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("no tables"),
        layout: &empty_layout,
        entries: &[],
    });

    let mut results = Vec::new();
    for &pass in passes {
        if pass == BenchPass::Diffraction {
            let (table, technique) = diffraction.ok_or_else(|| Error::MissingTable {
                needed_by: "bench-gpu: the diffraction pass".into(),
                kind: "diffraction",
                example: Some("cd-tracks"),
            })?;
            let scene = ScenePass::bench(
                ctx,
                table,
                technique,
                options.width,
                options.height,
                &Light {
                    direction: [0.4, 0.6, 0.7],
                    colour: [1.0; 3],
                    intensity: 3.0,
                },
            )?;
            results.push(time_pass(ctx, pass, &view, options, timestamps, |rp| {
                scene.draw(rp)
            })?);
            continue;
        }
        let binding = match pass {
            BenchPass::Plain | BenchPass::Diffraction => None,
            BenchPass::Film(t) => Some(TechniqueBinding::new(
                ctx,
                tables,
                t,
                &options.technique,
                &colorimeter,
            )?),
            BenchPass::FourierFixed(harmonics) => {
                let technique = TechniqueOptions {
                    harmonics,
                    ..options.technique.clone()
                };
                Some(TechniqueBinding::new(
                    ctx,
                    tables,
                    Technique::Fourier,
                    &technique,
                    &colorimeter,
                )?)
            }
            BenchPass::Stack(films) => {
                let technique = TechniqueOptions {
                    stack: StackSetup::alternating(films)?,
                    ..options.technique.clone()
                };
                Some(TechniqueBinding::new(
                    ctx,
                    tables,
                    Technique::Stack,
                    &technique,
                    &colorimeter,
                )?)
            }
            BenchPass::Glass => {
                let technique = TechniqueOptions {
                    stack: StackSetup::coated_pane()?,
                    ..options.technique.clone()
                };
                Some(TechniqueBinding::new(
                    ctx,
                    tables,
                    Technique::Glass,
                    &technique,
                    &colorimeter,
                )?)
            }
        };
        let (source, table_layout, table_group) = match (&binding, pass) {
            (Some(b), BenchPass::Film(t)) => (
                shaders::film_pipeline(t.module(), &["bench"])?,
                &b.layout,
                &b.bind_group,
            ),
            (Some(b), BenchPass::FourierFixed(_)) => (
                shaders::film_pipeline(Technique::Fourier.module(), &["bench"])?,
                &b.layout,
                &b.bind_group,
            ),
            (Some(b), BenchPass::Stack(_)) => (
                shaders::film_pipeline(Technique::Stack.module(), &["bench"])?,
                &b.layout,
                &b.bind_group,
            ),
            (Some(b), BenchPass::Glass) => (
                shaders::film_pipeline(Technique::Glass.module(), &["bench"])?,
                &b.layout,
                &b.bind_group,
            ),
            _ => (
                shaders::film_pipeline("plain", &["bench"])?,
                &empty_layout,
                &empty_group,
            ),
        };
        let module = shaders::create_module(ctx, pass.name(), &source)?;
        let pipeline = ctx.checked("building a bench pipeline", || {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(pass.name()),
                bind_group_layouts: &[Some(&view_layout), Some(table_layout)],
                immediate_size: 0,
            });
            gpu::fullscreen_pipeline(
                device,
                pass.name(),
                &module,
                &layout,
                ("bench_vs", "bench_fs"),
                &[wgpu::TextureFormat::Rgba8Unorm],
            )
        })?;
        results.push(time_pass(ctx, pass, &view, options, timestamps, |rp| {
            rp.set_pipeline(&pipeline);
            rp.set_bind_group(0, &view_group, &[]);
            rp.set_bind_group(1, table_group, &[]);
            rp.draw(0..3, 0..1);
        })?);
    }
    Ok(results)
}

/// Draws `options.warmup + options.frames` frames of one pass into `view` (recorded by
/// `draw`) and reports the median and fastest of the measured ones.
fn time_pass(
    ctx: &GpuContext,
    pass: BenchPass,
    view: &wgpu::TextureView,
    options: &BenchOptions,
    timestamps: bool,
    draw: impl Fn(&mut wgpu::RenderPass<'_>),
) -> Result<BenchResult> {
    let device = &ctx.device;
    let mut times_ms = Vec::new();
    for frame in 0..options.warmup + options.frames {
        let query = timestamps.then(|| {
            (
                device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("bench timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 2,
                }),
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("bench timestamps"),
                    size: 16,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("bench timestamps readback"),
                    size: 16,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
            )
        });
        let start = Instant::now();
        ctx.checked("drawing a bench frame", || {
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(pass.name()),
                    color_attachments: &[crate::gpu::cleared_attachment(view, wgpu::Color::BLACK)],
                    depth_stencil_attachment: None,
                    timestamp_writes: query.as_ref().map(|(q, _, _)| {
                        wgpu::RenderPassTimestampWrites {
                            query_set: q,
                            beginning_of_pass_write_index: Some(0),
                            end_of_pass_write_index: Some(1),
                        }
                    }),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                draw(&mut rp);
            }
            if let Some((q, resolve, readback)) = &query {
                encoder.resolve_query_set(q, 0..2, resolve, 0);
                encoder.copy_buffer_to_buffer(resolve, 0, readback, 0, 16);
            }
            ctx.queue.submit([encoder.finish()]);
        })?;
        let ms = match &query {
            Some((_, _, readback)) => {
                readback.map_async(wgpu::MapMode::Read, .., |_| {});
                ctx.wait("timing a bench frame")?;
                let view = readback.get_mapped_range(..).map_err(|e| Error::Gpu {
                    context: "reading timestamps".into(),
                    message: e.to_string(),
                })?;
                let t: [u64; 2] = bytemuck::pod_read_unaligned(&view[..16]);
                drop(view);
                readback.unmap();
                t[1].saturating_sub(t[0]) as f64
                    * f64::from(ctx.queue.get_timestamp_period())
                    * 1e-6
            }
            None => {
                ctx.wait("timing a bench frame")?;
                start.elapsed().as_secs_f64() * 1e3
            }
        };
        if frame >= options.warmup {
            times_ms.push(ms);
        }
    }
    times_ms.sort_by(f64::total_cmp);
    Ok(BenchResult {
        pass,
        median_ms: times_ms[times_ms.len() / 2],
        min_ms: times_ms[0],
        timestamps,
    })
}
