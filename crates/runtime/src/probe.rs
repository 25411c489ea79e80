//! The probe pass: evaluates a technique's `film_colour` for a list of [`FilmInput`]s on the
//! GPU, one per pixel of a float render target, and reads the colours back — the GPU side
//! of the GPU = CPU tests (`shaders/probe.wgsl`).

use crate::bindings::TechniqueBinding;
use crate::context::BufferInitExt;
use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::gpu;
use crate::gpu::read_texture;
use crate::params::{FilmInput, FilmOutput};
use crate::shaders;

/// Pixels per row of the probe target (64 × 16 bytes: rows already 256-byte aligned).
const WIDTH: u32 = 64;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ProbeParams {
    width: u32,
    count: u32,
    pad: [u32; 2],
}

/// Evaluates `film_colour` of `binding`'s technique at every input.
pub fn run_probe(
    ctx: &GpuContext,
    binding: &TechniqueBinding,
    inputs: &[FilmInput],
) -> Result<Vec<FilmOutput>> {
    if inputs.is_empty() {
        return Ok(Vec::new());
    }
    let count = u32::try_from(inputs.len()).map_err(|_| Error::Invalid {
        context: "probe".into(),
        message: format!("{} inputs (at most {})", inputs.len(), u32::MAX),
    })?;
    let height = count.div_ceil(WIDTH);
    let device = &ctx.device;
    let source = shaders::film_pipeline(binding.technique.module(), &["probe"])?;
    let module = shaders::create_module(ctx, "probe", &source)?;
    let (reflectance, transmittance) = ctx.checked("running the probe pass", || {
        let view_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("probe view (empty)"),
            entries: &[],
        });
        let stage = wgpu::ShaderStages::FRAGMENT;
        let probe_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("probe inputs"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: stage,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: stage,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("probe"),
            bind_group_layouts: &[
                Some(&view_layout),
                Some(&binding.layout),
                Some(&probe_layout),
            ],
            immediate_size: 0,
        });
        let pipeline = gpu::fullscreen_pipeline(
            device,
            "probe",
            &module,
            &layout,
            ("probe_vs", "probe_fs"),
            &[wgpu::TextureFormat::Rgba32Float; 2],
        );
        let storage = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("probe inputs"),
            contents: bytemuck::cast_slice(inputs),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("ProbeParams"),
            contents: bytemuck::bytes_of(&ProbeParams {
                width: WIDTH,
                count,
                pad: [0; 2],
            }),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let view_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("probe view"),
            layout: &view_layout,
            entries: &[],
        });
        let probe_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("probe inputs"),
            layout: &probe_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: storage.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: uniform.as_entire_binding(),
                },
            ],
        });
        let make_target = |label| {
            crate::gpu::render_target(
                device,
                label,
                (WIDTH, height),
                wgpu::TextureFormat::Rgba32Float,
                true,
            )
        };
        let (r, t) = (
            make_target("probe reflectance"),
            make_target("probe transmittance"),
        );
        let (rv, tv) = (
            r.create_view(&Default::default()),
            t.create_view(&Default::default()),
        );
        let clear = wgpu::Color::TRANSPARENT;
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = crate::gpu::begin_pass(
                &mut encoder,
                "probe",
                &[
                    crate::gpu::cleared_attachment(&rv, clear),
                    crate::gpu::cleared_attachment(&tv, clear),
                ],
            );
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &view_group, &[]);
            pass.set_bind_group(1, &binding.bind_group, &[]);
            pass.set_bind_group(2, &probe_group, &[]);
            pass.draw(0..3, 0..1);
        }
        ctx.queue.submit([encoder.finish()]);
        (r, t)
    })?;
    let to_floats = |bytes: Vec<u8>| -> Vec<[f32; 4]> { bytemuck::pod_collect_to_vec(&bytes) };
    let r = to_floats(read_texture(ctx, &reflectance, 16)?);
    let t = to_floats(read_texture(ctx, &transmittance, 16)?);
    Ok((0..inputs.len())
        .map(|i| FilmOutput {
            reflectance: [r[i][0], r[i][1], r[i][2]],
            transmittance: [t[i][0], t[i][1], t[i][2]],
        })
        .collect())
}
