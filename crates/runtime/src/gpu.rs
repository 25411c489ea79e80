//! wgpu helpers shared by the runtime's passes: bind-group layout entries and groups,
//! samplers, texture uploads of mip chains and array layers, the full-screen-triangle
//! pipeline, and reading textures and buffers back to the host.

use crate::context::{BufferInitExt, GpuContext};
use crate::error::{Error, Result};
use crate::image_io::Level;
use half::f16;

/// An [`Error::Limit`] naming `what` when `needed` exceeds the adapter's `limit`.
pub(crate) fn check_limit(ctx: &GpuContext, what: &str, needed: u64, limit: u32) -> Result<()> {
    if needed > u64::from(limit) {
        return Err(Error::Limit {
            what: what.to_string(),
            needed,
            limit: u64::from(limit),
            adapter: ctx.info.name.clone(),
        });
    }
    Ok(())
}

/// A texture the shaders sample and the host fills (`TEXTURE_BINDING | COPY_DST`), one
/// sample per texel, no view formats.
pub(crate) fn sampled_texture(
    device: &wgpu::Device,
    label: &str,
    size: wgpu::Extent3d,
    dimension: wgpu::TextureDimension,
    format: wgpu::TextureFormat,
    mip_level_count: u32,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size,
        mip_level_count,
        sample_count: 1,
        dimension,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

/// Writes `texels` (texels of `texel_bytes` bytes, row after row, then image after image)
/// into the region `size` of mip `level` of `texture`, from layer (or depth) `first_layer`.
pub(crate) fn write_region(
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    level: u32,
    first_layer: u32,
    size: wgpu::Extent3d,
    texel_bytes: u32,
    texels: &[u8],
) {
    queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: level,
            origin: wgpu::Origin3d {
                x: 0,
                y: 0,
                z: first_layer,
            },
            aspect: wgpu::TextureAspect::All,
        },
        texels,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(size.width * texel_bytes),
            rows_per_image: Some(size.height),
        },
        size,
    );
}

pub(crate) fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

pub(crate) fn texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// A 2-D float texture read with `textureLoad` (so it need not be filterable).
pub(crate) fn loaded_texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

pub(crate) fn sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

/// Group 2 (and the old group 0) shape: 0 uniform, 1 filterable 2-D texture, 2 sampler.
pub(crate) fn group_layout(device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[uniform_entry(0), texture_entry(1), sampler_entry(2)],
    })
}

/// Uploads a mip chain as a 2-D half-float texture of `format` (C channels of 2 bytes).
pub(crate) fn upload_mips<const C: usize>(
    ctx: &GpuContext,
    label: &str,
    format: wgpu::TextureFormat,
    levels: &[Level<C>],
) -> Result<wgpu::Texture> {
    let bytes: Vec<(u32, u32, Vec<u8>)> = levels
        .iter()
        .map(|(w, h, texels)| {
            let halves: Vec<u8> = texels
                .iter()
                .flat_map(|t| t.map(|v| f16::from_f32(v).to_bits()))
                .flat_map(u16::to_ne_bytes)
                .collect();
            (*w as u32, *h as u32, halves)
        })
        .collect();
    upload_levels(ctx, label, format, (C * 2) as u32, &bytes)
}

/// Uploads a mip chain as a sampled 2-D texture of `format`: level k is (width, height,
/// texels packed row after row, `texel_bytes` each). A level 0 wider or taller than the
/// adapter allows is an [`Error::Limit`] naming `label`.
pub(crate) fn upload_levels(
    ctx: &GpuContext,
    label: &str,
    format: wgpu::TextureFormat,
    texel_bytes: u32,
    levels: &[(u32, u32, Vec<u8>)],
) -> Result<wgpu::Texture> {
    let (width, height) = levels.first().map_or((0, 0), |(w, h, _)| (*w, *h));
    check_limit(
        ctx,
        label,
        u64::from(width.max(height)),
        ctx.device.limits().max_texture_dimension_2d,
    )?;
    ctx.checked(&format!("uploading {label}"), || {
        let texture = sampled_texture(
            &ctx.device,
            label,
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            wgpu::TextureDimension::D2,
            format,
            levels.len() as u32,
        );
        for (k, (w, h, texels)) in levels.iter().enumerate() {
            let size = wgpu::Extent3d {
                width: *w,
                height: *h,
                depth_or_array_layers: 1,
            };
            write_region(&ctx.queue, &texture, k as u32, 0, size, texel_bytes, texels);
        }
        texture
    })
}

/// Uploads equal-sized RGBA levels as the layers of a 2-D array `Rgba16Float` texture (one
/// mip level).
pub(crate) fn upload_layers(
    ctx: &GpuContext,
    label: &str,
    layers: &[Level<4>],
) -> Result<wgpu::Texture> {
    let (width, height, _) = &layers[0];
    if layers
        .iter()
        .any(|l| (l.0, l.1) != (*width, *height) || l.2.len() != l.0 * l.1)
    {
        return Err(Error::LayerSizes {
            label: label.into(),
        });
    }
    let limit = ctx.device.limits();
    if (*width.max(height) as u64) > u64::from(limit.max_texture_dimension_2d)
        || layers.len() as u64 > u64::from(limit.max_texture_array_layers)
    {
        return Err(Error::Limit {
            what: label.to_string(),
            needed: (*width.max(height)).max(layers.len()) as u64,
            limit: u64::from(
                limit
                    .max_texture_dimension_2d
                    .min(limit.max_texture_array_layers),
            ),
            adapter: ctx.info.name.clone(),
        });
    }
    ctx.checked(&format!("uploading {label}"), || {
        let size = wgpu::Extent3d {
            width: *width as u32,
            height: *height as u32,
            depth_or_array_layers: layers.len() as u32,
        };
        let texture = sampled_texture(
            &ctx.device,
            label,
            size,
            wgpu::TextureDimension::D2,
            wgpu::TextureFormat::Rgba16Float,
            1,
        );
        let halves: Vec<u16> = layers
            .iter()
            .flat_map(|l| l.2.iter())
            .flat_map(|t| t.map(|v| f16::from_f32(v).to_bits()))
            .collect();
        write_region(
            &ctx.queue,
            &texture,
            0,
            0,
            size,
            8,
            bytemuck::cast_slice(&halves),
        );
        texture
    })
}

/// A bind group of the layout shared by the view and material groups: binding 0 a uniform
/// buffer holding `contents`, 1 `texture`'s default view, 2 a linear sampler
/// ([`linear_sampler`]; `repeat_v` repeats v instead of clamping).
pub(crate) fn uniform_texture_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    label: &str,
    contents: &[u8],
    texture: &wgpu::Texture,
    repeat_v: bool,
) -> wgpu::BindGroup {
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let view = texture.create_view(&Default::default());
    let sampler = linear_sampler(device, label, repeat_v);
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&view),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::Sampler(&sampler),
            },
        ],
    })
}

pub(crate) fn linear_sampler(device: &wgpu::Device, label: &str, repeat_v: bool) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some(label),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: if repeat_v {
            wgpu::AddressMode::Repeat
        } else {
            wgpu::AddressMode::ClampToEdge
        },
        address_mode_w: wgpu::AddressMode::ClampToEdge,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    })
}

/// The one pipeline shape the runtime's own passes use: a full-screen triangle (no vertex
/// buffers; the vertex entry point derives the corners from the vertex index) and a fragment
/// entry point writing to `targets` without blending.
pub fn fullscreen_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    entry_points: (&str, &str),
    targets: &[wgpu::TextureFormat],
) -> wgpu::RenderPipeline {
    let targets: Vec<Option<wgpu::ColorTargetState>> = targets
        .iter()
        .map(|&format| {
            Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })
        })
        .collect();
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(entry_points.0),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(entry_points.1),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

// ─── Render targets and passes ───────────────────────────────────────────────────────────

/// A `width × height` 2-D texture of `format` to render into (one mip, one sample), also a
/// copy source when `readback` (for [`read_texture`]).
pub fn render_target(
    device: &wgpu::Device,
    label: &str,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    readback: bool,
) -> wgpu::Texture {
    let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
    if readback {
        usage |= wgpu::TextureUsages::COPY_SRC;
    }
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// A colour attachment that clears `view` to `clear` and stores what the pass draws.
pub fn cleared_attachment(
    view: &wgpu::TextureView,
    clear: wgpu::Color,
) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load: wgpu::LoadOp::Clear(clear),
            store: wgpu::StoreOp::Store,
        },
    })
}

/// A render pass labelled `label` drawing into `colour` (no depth, no queries).
pub fn begin_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    colour: &[Option<wgpu::RenderPassColorAttachment<'_>>],
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: colour,
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

// ─── Readback ──────────────────────────────────────────────────────────────────────────────

/// Reads mip level 0 of a 2-D `texture` whose texels are `bytes_per_texel` bytes, returning
/// tightly packed rows, top row first.
pub fn read_texture(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    bytes_per_texel: u32,
) -> Result<Vec<u8>> {
    let (width, height) = (texture.width(), texture.height());
    let row = width * bytes_per_texel;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = ctx.checked("reading a texture back", || {
        let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: u64::from(padded) * u64::from(height),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(height),
                },
            },
            texture.size(),
        );
        ctx.queue.submit([encoder.finish()]);
        buffer
    })?;
    let bytes = read_buffer(ctx, &buffer, "reading a texture back")?;
    let mut out = Vec::with_capacity((row * height) as usize);
    for y in 0..height as usize {
        let start = y * padded as usize;
        out.extend_from_slice(&bytes[start..start + row as usize]);
    }
    Ok(out)
}

/// Maps a `MAP_READ` `buffer` whose copies have been submitted, waits for the queue and
/// returns its bytes; `what` names the operation in errors ([`Error::Gpu`], or
/// [`Error::DeviceLost`] from the wait).
pub fn read_buffer(ctx: &GpuContext, buffer: &wgpu::Buffer, what: &str) -> Result<Vec<u8>> {
    let (sender, receiver) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = sender.send(r);
    });
    ctx.wait(what)?;
    let gpu = |message: String| Error::Gpu {
        context: format!("{what}: mapping the buffer"),
        message,
    };
    receiver
        .recv()
        .map_err(|e| e.to_string())
        .and_then(|r| r.map_err(|e| e.to_string()))
        .map_err(gpu)?;
    let view = buffer
        .get_mapped_range(..)
        .map_err(|e| gpu(e.to_string()))?;
    let out = view.to_vec();
    drop(view);
    buffer.unmap();
    Ok(out)
}
