//! Copying a 2-D texture (rows padded to 256 bytes on the GPU side) or a buffer back to the
//! host.

use crate::context::GpuContext;
use crate::error::{Error, Result};

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
