//! Bind-group layouts (one per technique, for group 1 — the tables) and the bind groups
//! that fill them. Groups are ordered by how often they change: 0 view, 1 tables,
//! 2 material (`shaders/README.md`).

use crate::context::BufferInitExt;
use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::params;
use crate::shaders::Technique;
use crate::tables::TableSet;
use nacre_optics::Material;
use nacre_optics::colour::Colorimeter;

const STAGES: wgpu::ShaderStages = wgpu::ShaderStages::FRAGMENT.union(wgpu::ShaderStages::COMPUTE);

fn texture_entry(
    binding: u32,
    dimension: wgpu::TextureViewDimension,
    filterable: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: STAGES,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable },
            view_dimension: dimension,
            multisampled: false,
        },
        count: None,
    }
}

fn buffer_entry(binding: u32, ty: wgpu::BufferBindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: STAGES,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// The group-1 layout of `technique`:
///
/// * `Lut`: 0 reflectance `texture_3d<f32>`, 1 transmittance `texture_3d<f32>`,
///   2 filtering sampler, 3 `uniform FilmLutParams`;
/// * `Fourier`: 0 `texture_2d_array<f32>` (unfilterable), 1 `uniform FourierParams`;
/// * `Spectral`: 0 `storage, read array<SpectralSample>`, 1 `uniform SpectralParams`.
pub fn table_layout(device: &wgpu::Device, technique: Technique) -> wgpu::BindGroupLayout {
    use wgpu::BufferBindingType::{Storage, Uniform};
    let entries: Vec<wgpu::BindGroupLayoutEntry> = match technique {
        Technique::Lut => vec![
            texture_entry(0, wgpu::TextureViewDimension::D3, true),
            texture_entry(1, wgpu::TextureViewDimension::D3, true),
            wgpu::BindGroupLayoutEntry {
                binding: 2,
                visibility: STAGES,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
            buffer_entry(3, Uniform),
        ],
        Technique::Fourier => vec![
            texture_entry(0, wgpu::TextureViewDimension::D2Array, false),
            buffer_entry(1, Uniform),
        ],
        Technique::Spectral => vec![
            buffer_entry(0, Storage { read_only: true }),
            buffer_entry(1, Uniform),
        ],
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(technique.name()),
        entries: &entries,
    })
}

/// What the spectral technique integrates over: N wavelengths with their weights and the
/// base's index at each (the `samples:N` method of `nacre color`).
#[derive(Clone, Debug)]
pub struct SpectralSetup {
    /// Wavelength count N.
    pub samples: usize,
    /// The base material (its index is sampled at each wavelength).
    pub base: Material,
}

/// The samples of `film_spectral` for `setup`: the wavelengths and weights of `nacre color
/// --method samples:N` ([`nacre_optics::spectral::sample_weights`]) and the base's index at each.
pub fn spectral_samples(
    colorimeter: &Colorimeter,
    setup: &SpectralSetup,
) -> Result<Vec<params::SpectralSample>> {
    if !(1..=4096).contains(&setup.samples) {
        return Err(Error::Invalid {
            context: "spectral technique".into(),
            message: format!("{} wavelengths (expected 1 to 4096)", setup.samples),
        });
    }
    let (wavelengths, weights) = nacre_optics::spectral::sample_weights(colorimeter, setup.samples);
    wavelengths
        .iter()
        .zip(&weights)
        .map(|(&wl, w)| {
            let n = setup.base.index_at(wl).map_err(Error::from)?;
            Ok(params::SpectralSample {
                wavelength_nm: wl as f32,
                base_ior: n.re as f32,
                base_kappa: n.im as f32,
                _pad: 0.0,
                weight: [w[0] as f32, w[1] as f32, w[2] as f32, 0.0],
            })
        })
        .collect()
}

/// Options of a technique's group-1 bind group.
#[derive(Clone, Debug)]
pub struct TechniqueOptions {
    /// Harmonics M of `film_fourier` (0 = automatic, as `fourier:auto`).
    pub harmonics: u32,
    /// Setup of `film_spectral`.
    pub spectral: SpectralSetup,
}

impl Default for TechniqueOptions {
    fn default() -> Self {
        TechniqueOptions {
            harmonics: 3,
            spectral: SpectralSetup {
                samples: 30,
                base: Material::constant("1.5", nacre_optics::C64::new(1.5, 0.0))
                    .expect("a real index above zero is a valid material"),
            },
        }
    }
}

/// A technique ready to bind as group 1: its layout, bind group and the buffers they own.
pub struct TechniqueBinding {
    /// The technique.
    pub technique: Technique,
    /// Group-1 layout.
    pub layout: wgpu::BindGroupLayout,
    /// Group-1 bind group.
    pub bind_group: wgpu::BindGroup,
}

impl TechniqueBinding {
    /// Builds group 1 of `technique` from `tables` (and, for `Spectral`, the colorimeter of
    /// the tables or `colorimeter`).
    pub fn new(
        ctx: &GpuContext,
        tables: &TableSet,
        technique: Technique,
        options: &TechniqueOptions,
        colorimeter: &Colorimeter,
    ) -> Result<Self> {
        let device = &ctx.device;
        let layout = table_layout(device, technique);
        let missing = |kind: &str| Error::Invalid {
            context: format!("technique `{}`", technique.name()),
            message: format!("needs a `{kind}` table in the table set"),
        };
        let bind_group = ctx.checked(
            "creating a table bind group",
            || -> Result<wgpu::BindGroup> {
                Ok(match technique {
                    Technique::Lut => {
                        let lut = tables
                            .film_lut
                            .as_ref()
                            .ok_or_else(|| missing("film-lut"))?;
                        let uniform =
                            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                                label: Some("FilmLutParams"),
                                contents: bytemuck::bytes_of(&params::FilmLutParams::new(
                                    &lut.axes,
                                    lut.has_transmittance,
                                )),
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
                        device.create_bind_group(&wgpu::BindGroupDescriptor {
                            label: Some("film-lut tables"),
                            layout: &layout,
                            entries: &[
                                wgpu::BindGroupEntry {
                                    binding: 0,
                                    resource: wgpu::BindingResource::TextureView(&r),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 1,
                                    resource: wgpu::BindingResource::TextureView(&t),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 2,
                                    resource: wgpu::BindingResource::Sampler(&sampler),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 3,
                                    resource: uniform.as_entire_binding(),
                                },
                            ],
                        })
                    }
                    Technique::Fourier => {
                        let f = tables.fourier.as_ref().ok_or_else(|| missing("fourier"))?;
                        let uniform =
                            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                                label: Some("FourierParams"),
                                contents: bytemuck::bytes_of(&params::FourierParams::new(
                                    &f.axes,
                                    options.harmonics,
                                )),
                                usage: wgpu::BufferUsages::UNIFORM,
                            });
                        let view = f.texture.create_view(&wgpu::TextureViewDescriptor {
                            dimension: Some(wgpu::TextureViewDimension::D2Array),
                            ..Default::default()
                        });
                        device.create_bind_group(&wgpu::BindGroupDescriptor {
                            label: Some("fourier tables"),
                            layout: &layout,
                            entries: &[
                                wgpu::BindGroupEntry {
                                    binding: 0,
                                    resource: wgpu::BindingResource::TextureView(&view),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 1,
                                    resource: uniform.as_entire_binding(),
                                },
                            ],
                        })
                    }
                    Technique::Spectral => {
                        let samples = spectral_samples(colorimeter, &options.spectral)?;
                        let storage =
                            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                                label: Some("SpectralSample[]"),
                                contents: bytemuck::cast_slice(&samples),
                                usage: wgpu::BufferUsages::STORAGE,
                            });
                        let uniform =
                            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                                label: Some("SpectralParams"),
                                contents: bytemuck::bytes_of(&params::SpectralParams::new(
                                    samples.len(),
                                )),
                                usage: wgpu::BufferUsages::UNIFORM,
                            });
                        device.create_bind_group(&wgpu::BindGroupDescriptor {
                            label: Some("spectral tables"),
                            layout: &layout,
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
                        })
                    }
                })
            },
        )??;
        Ok(TechniqueBinding {
            technique,
            layout,
            bind_group,
        })
    }
}
