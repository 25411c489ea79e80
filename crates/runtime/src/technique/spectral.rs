//! `film_spectral`: the brute-force loop over N wavelengths (`shaders/film_spectral.wgsl`),
//! the `samples:N` method of `nacre color` on the GPU.
//!
//! Group 1: 0 `storage, read array<SpectralSample>`, 1 `uniform SpectralParams`.

use super::entry::{BindInputs, Slot, TechniqueEntry};
use super::options::SpectralSetup;
use crate::context::BufferInitExt;
use crate::error::{Error, Result};
use bytemuck::{Pod, Zeroable};
use nacre_optics::colour::Colorimeter;

/// The technique's entry.
pub const ENTRY: TechniqueEntry = TechniqueEntry {
    name: "spectral",
    module: "film_spectral",
    source: include_str!("../../../../shaders/film_spectral.wgsl"),
    bench_label: "film_spectral",
    cpu_twin: "samples:N",
    layout: &[Slot::Storage, Slot::Uniform],
    bind,
};

fn bind(inputs: &BindInputs<'_>) -> Result<wgpu::BindGroup> {
    let device = inputs.device;
    let samples = spectral_samples(inputs.colorimeter, &inputs.options.spectral)?;
    let storage = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("SpectralSample[]"),
        contents: bytemuck::cast_slice(&samples),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("SpectralParams"),
        contents: bytemuck::bytes_of(&SpectralParams::new(samples.len())),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    Ok(inputs.bind_group(
        "spectral tables",
        &[storage.as_entire_binding(), uniform.as_entire_binding()],
    ))
}

/// The samples of `film_spectral` for `setup`: the wavelengths and weights of `nacre color
/// --method samples:N` ([`nacre_optics::spectral::sample_weights`]) and the base's index at each.
pub fn spectral_samples(
    colorimeter: &Colorimeter,
    setup: &SpectralSetup,
) -> Result<Vec<SpectralSample>> {
    if !(1..=4096).contains(&setup.samples) {
        return Err(Error::OutOfRange {
            what: "spectral technique: wavelengths".into(),
            value: setup.samples as f64,
            unit: "",
            expected: "1 to 4096".into(),
        });
    }
    let (wavelengths, weights) = nacre_optics::spectral::sample_weights(colorimeter, setup.samples);
    wavelengths
        .iter()
        .zip(&weights)
        .map(|(&wl, w)| {
            let n = setup.base.index_at(wl).map_err(Error::from)?;
            Ok(SpectralSample {
                wavelength_nm: wl as f32,
                base_ior: n.re as f32,
                base_kappa: n.im as f32,
                _pad: 0.0,
                weight: [w[0] as f32, w[1] as f32, w[2] as f32, 0.0],
            })
        })
        .collect()
}

/// Mirror of `SpectralSample` (`shaders/film_spectral.wgsl`): 32 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SpectralSample {
    /// λ, nm.
    pub wavelength_nm: f32,
    /// Base index at λ, real part.
    pub base_ior: f32,
    /// Base index at λ, imaginary part.
    pub base_kappa: f32,
    /// Padding.
    pub _pad: f32,
    /// Weight per channel (Σ over samples = white); w unused.
    pub weight: [f32; 4],
}

/// Mirror of `SpectralParams`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SpectralParams {
    /// Samples N.
    pub count: u32,
    /// Padding.
    pub _pad: [u32; 3],
}

impl SpectralParams {
    /// For `count` samples.
    pub fn new(count: usize) -> Self {
        SpectralParams {
            count: count as u32,
            _pad: [0; 3],
        }
    }
}
