//! Copying a 2-D texture back to the host (rows padded to 256 bytes on the GPU side).

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
    let (sender, receiver) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = sender.send(r);
    });
    ctx.wait("reading a texture back")?;
    receiver
        .recv()
        .map_err(|e| e.to_string())
        .and_then(|r| r.map_err(|e| e.to_string()))
        .map_err(|message| Error::Gpu {
            context: "mapping the readback buffer".into(),
            message,
        })?;
    let view = buffer.get_mapped_range(..).map_err(|e| Error::Gpu {
        context: "mapping the readback buffer".into(),
        message: e.to_string(),
    })?;
    let mut out = Vec::with_capacity((row * height) as usize);
    for y in 0..height as usize {
        let start = y * padded as usize;
        out.extend_from_slice(&view[start..start + row as usize]);
    }
    drop(view);
    buffer.unmap();
    Ok(out)
}
