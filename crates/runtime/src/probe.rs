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

/// Invocations per workgroup (x) that a [`run_spirv_probe`] entry point declares.
pub const SPIRV_PROBE_WORKGROUP: u32 = 64;

/// The SPIR-V magic number (SPIR-V specification §3.1), first word of every module.
const SPIRV_MAGIC: u32 = 0x0723_0203;

/// A compute probe compiled outside nacre — SPIR-V from `glslangValidator -V` for a GLSL or
/// HLSL consumer of the engine libraries (`shaders/glsl/nacre.glsl`,
/// `shaders/hlsl/nacre.hlsl`) — run through naga's SPIR-V front end on the same device as
/// the WGSL techniques.
pub struct SpirvProbe<'a> {
    /// The module's bytes (little-endian words, as glslang writes them).
    pub spirv: &'a [u8],
    /// Its compute entry point, `local_size_x` = [`SPIRV_PROBE_WORKGROUP`].
    pub entry_point: &'a str,
    /// Group 1: the tables as the probe declares them (layout and bind group).
    pub tables: (&'a wgpu::BindGroupLayout, &'a wgpu::BindGroup),
}

/// Runs `probe` over `count` inputs of `input_bytes.len() / count` bytes each and returns two
/// `vec4<f32>` per input. The bindings (group 0 is empty):
///
/// | group | binding | type | holds |
/// |---|---|---|---|
/// | 1 | any | the probe's own | [`SpirvProbe::tables`] |
/// | 2 | 0 | `storage, read` | the inputs (`input_bytes`) |
/// | 2 | 1 | `uniform` (16 bytes) | `u32` count, then padding |
/// | 2 | 2 | `storage, read_write` | `array<vec4<f32>>`: index 2i and 2i + 1 for input i |
///
/// Errors: bytes that are not a SPIR-V module ([`Error::Invalid`]), a module naga or the
/// device rejects, or a layout it does not fit ([`Error::Gpu`]).
pub fn run_spirv_probe(
    ctx: &GpuContext,
    probe: &SpirvProbe<'_>,
    input_bytes: &[u8],
    count: u32,
) -> Result<Vec<[[f32; 4]; 2]>> {
    let invalid = |message: String| Error::Invalid {
        context: "SPIR-V probe".into(),
        message,
    };
    if probe.spirv.len() < 20 || !probe.spirv.len().is_multiple_of(4) {
        return Err(invalid(format!(
            "{} bytes: not a SPIR-V module (a whole number of words, header of 5)",
            probe.spirv.len()
        )));
    }
    let words: Vec<u32> = probe
        .spirv
        .chunks_exact(4)
        .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
        .collect();
    if words[0] != SPIRV_MAGIC {
        return Err(invalid(format!(
            "first word {:#010x} is not the SPIR-V magic number {SPIRV_MAGIC:#010x}",
            words[0]
        )));
    }
    if count == 0 {
        return Ok(Vec::new());
    }
    // naga's SPIR-V front end panics on some valid modules (e.g. naga 30 on an
    // `OpImageFetch` of a 2-D array image when no 2-component integer vector type was
    // declared): a panic there is reported as an error, not passed on.
    let module = ctx.checked("compiling the SPIR-V probe", || {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            ctx.device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some("SPIR-V probe"),
                    source: wgpu::ShaderSource::SpirV(words.as_slice().into()),
                })
        }))
        .map_err(|panic| {
            let message = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic without a message".into());
            Error::Gpu {
                context: "SPIR-V probe: naga's SPIR-V front end".into(),
                message,
            }
        })
    })??;
    let floats = dispatch_compute(
        ctx,
        &ComputeProbe {
            label: "SPIR-V probe",
            module: &module,
            entry_point: probe.entry_point,
            tables: probe.tables,
            io_group: 2,
            inputs: input_bytes,
            uniform: Some(bytemuck::bytes_of(&[count, 0, 0, 0])),
            cases: count as usize,
        },
    )?;
    Ok(floats.chunks_exact(2).map(|p| [p[0], p[1]]).collect())
}

/// One compute dispatch of a GPU = CPU probe: the one dispatcher of [`run_spirv_probe`] and
/// the diffraction probes (`crate::diffraction`).
pub(crate) struct ComputeProbe<'a> {
    /// What errors and wgpu labels call it.
    pub label: &'a str,
    /// The compiled module.
    pub module: &'a wgpu::ShaderModule,
    /// Its compute entry point, [`SPIRV_PROBE_WORKGROUP`] invocations per workgroup, one per
    /// case.
    pub entry_point: &'a str,
    /// Group 1: the technique's tables (layout and bind group).
    pub tables: (&'a wgpu::BindGroupLayout, &'a wgpu::BindGroup),
    /// The group of the inputs and outputs; the groups other than 1 below it are empty.
    pub io_group: u32,
    /// Binding 0 of the io group, `storage, read`.
    pub inputs: &'a [u8],
    /// Binding 1 of the io group when present, `uniform`.
    pub uniform: Option<&'a [u8]>,
    /// Cases: the outputs, the io group's last binding (`storage, read_write`), hold two
    /// `vec4<f32>` per case.
    pub cases: usize,
}

/// Runs `probe` and returns its outputs: two `vec4<f32>` per case, in order.
///
/// # Errors
/// [`Error::Limit`] for more cases than one dispatch takes; [`Error::Gpu`] or
/// [`Error::DeviceLost`] from the device.
pub(crate) fn dispatch_compute(
    ctx: &GpuContext,
    probe: &ComputeProbe<'_>,
) -> Result<Vec<[f32; 4]>> {
    if probe.cases == 0 {
        return Ok(Vec::new());
    }
    let label = probe.label;
    let limit = ctx.device.limits().max_compute_workgroups_per_dimension;
    let needed = probe.cases.div_ceil(SPIRV_PROBE_WORKGROUP as usize);
    let groups = u32::try_from(needed)
        .ok()
        .filter(|g| *g <= limit)
        .ok_or_else(|| Error::Limit {
            what: format!(
                "{label} of {} cases ({SPIRV_PROBE_WORKGROUP} a workgroup)",
                probe.cases
            ),
            needed: needed as u64,
            limit: u64::from(limit),
            adapter: ctx.info.name.clone(),
        })?;
    let out_bytes = probe.cases as u64 * 32;
    let device = &ctx.device;
    let readback = ctx.checked(&format!("running the {label}"), || {
        let buffer_entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let mut io_entries = vec![buffer_entry(
            0,
            wgpu::BufferBindingType::Storage { read_only: true },
        )];
        if probe.uniform.is_some() {
            io_entries.push(buffer_entry(1, wgpu::BufferBindingType::Uniform));
        }
        io_entries.push(buffer_entry(
            io_entries.len() as u32,
            wgpu::BufferBindingType::Storage { read_only: false },
        ));
        let io_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries: &io_entries,
        });
        let empty = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries: &[],
        });
        let layouts: Vec<Option<&wgpu::BindGroupLayout>> = (0..=probe.io_group)
            .map(|g| match g {
                1 => Some(probe.tables.0),
                g if g == probe.io_group => Some(&io_layout),
                _ => Some(&empty),
            })
            .collect();
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(probe.entry_point),
            layout: Some(&layout),
            module: probe.module,
            entry_point: Some(probe.entry_point),
            compilation_options: Default::default(),
            cache: None,
        });
        let inputs = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: probe.inputs,
            usage: wgpu::BufferUsages::STORAGE,
        });
        let uniform = probe.uniform.map(|contents| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::UNIFORM,
            })
        });
        let outputs = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: out_bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: out_bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let empty_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout: &empty,
            entries: &[],
        });
        let mut resources = vec![inputs.as_entire_binding()];
        resources.extend(uniform.as_ref().map(|u| u.as_entire_binding()));
        resources.push(outputs.as_entire_binding());
        let io_entries: Vec<wgpu::BindGroupEntry<'_>> = resources
            .into_iter()
            .enumerate()
            .map(|(i, resource)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource,
            })
            .collect();
        let io_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout: &io_layout,
            entries: &io_entries,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            for g in 0..=probe.io_group {
                let group = match g {
                    1 => probe.tables.1,
                    g if g == probe.io_group => &io_group,
                    _ => &empty_group,
                };
                pass.set_bind_group(g, group, &[]);
            }
            pass.dispatch_workgroups(groups, 1, 1);
        }
        encoder.copy_buffer_to_buffer(&outputs, 0, &readback, 0, out_bytes);
        ctx.queue.submit([encoder.finish()]);
        readback
    })?;
    let bytes = gpu::read_buffer(ctx, &readback, &format!("reading the {label}'s outputs"))?;
    Ok(bytemuck::pod_collect_to_vec(&bytes))
}
