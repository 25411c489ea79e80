//! `film_lut`: trilinear lookup in a baked `film-lut` table (`shaders/film_lut.wgsl`).
//!
//! Group 1: 0 reflectance `texture_3d<f32>`, 1 transmittance `texture_3d<f32>`, 2 filtering
//! sampler, 3 `uniform FilmLutParams` (the table's axes,
//! [`nacre_format::gpu_params::FilmLutParams`]).

use super::entry::{BindInputs, Slot, TechniqueEntry};
use crate::context::BufferInitExt;
use crate::error::Result;
use nacre_format::gpu_params::FilmLutParams;
use wgpu::TextureViewDimension::D3;

/// The technique's entry.
pub const ENTRY: TechniqueEntry = TechniqueEntry {
    name: "lut",
    module: "film_lut",
    source: include_str!("../../../../shaders/film_lut.wgsl"),
    bench_label: "film_lut",
    cpu_twin: "lut:PATH",
    layout: &[
        Slot::Texture(D3, true),
        Slot::Texture(D3, true),
        Slot::Sampler,
        Slot::Uniform,
    ],
    bind,
};

fn bind(inputs: &BindInputs<'_>) -> Result<wgpu::BindGroup> {
    let device = inputs.device;
    let lut = inputs
        .tables
        .film_lut
        .as_ref()
        .ok_or_else(|| inputs.missing("film-lut"))?;
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("FilmLutParams"),
        contents: bytemuck::bytes_of(&FilmLutParams::new(&lut.axes, lut.has_transmittance)),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("film-lut trilinear"),
        address_mode_u: wgpu::AddressMode::ClampToEdge,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        address_mode_w: wgpu::AddressMode::ClampToEdge,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    });
    let r = lut.reflectance.create_view(&Default::default());
    let t = lut.transmittance.create_view(&Default::default());
    Ok(inputs.bind_group(
        "film-lut tables",
        &[
            wgpu::BindingResource::TextureView(&r),
            wgpu::BindingResource::TextureView(&t),
            wgpu::BindingResource::Sampler(&sampler),
            uniform.as_entire_binding(),
        ],
    ))
}
