//! `film_fourier`: Belcour & Barla 2017 Eq. 10 with a baked `fourier` table
//! (`shaders/film_fourier.wgsl`).
//!
//! Group 1: 0 `texture_2d_array<f32>` (unfilterable), 1 `uniform FourierParams` (the table's
//! axes and the harmonics, [`nacre_format::gpu_params::FourierParams`]).

use super::entry::{BindInputs, Slot, TechniqueEntry};
use crate::context::BufferInitExt;
use crate::error::Result;
use nacre_format::gpu_params::FourierParams;

/// The technique's entry.
pub const ENTRY: TechniqueEntry = TechniqueEntry {
    name: "fourier",
    module: "film_fourier",
    source: include_str!("../../../../shaders/film_fourier.wgsl"),
    bench_label: "film_fourier",
    cpu_twin: "fourier",
    layout: &[
        Slot::Texture(wgpu::TextureViewDimension::D2Array, false),
        Slot::Uniform,
    ],
    bind,
};

fn bind(inputs: &BindInputs<'_>) -> Result<wgpu::BindGroup> {
    let f = inputs
        .tables
        .fourier
        .as_ref()
        .ok_or_else(|| inputs.missing("fourier"))?;
    let uniform = inputs
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("FourierParams"),
            contents: bytemuck::bytes_of(&FourierParams::new(&f.axes, inputs.options.harmonics)),
            usage: wgpu::BufferUsages::UNIFORM,
        });
    let view = f.texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    Ok(inputs.bind_group(
        "fourier tables",
        &[
            wgpu::BindingResource::TextureView(&view),
            uniform.as_entire_binding(),
        ],
    ))
}
