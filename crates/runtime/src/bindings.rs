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
/// * `Spectral`: 0 `storage, read array<SpectralSample>`, 1 `uniform SpectralParams`;
/// * `Stack`: 0 `storage, read array<StackNode>`, 1 `storage, read array<vec2<f32>>` (every
///   medium's index at every node), 2 `uniform StackParams`.
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
        Technique::Stack => vec![
            buffer_entry(0, Storage { read_only: true }),
            buffer_entry(1, Storage { read_only: true }),
            buffer_entry(2, Uniform),
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

/// What `film_stack` evaluates: a stack of 1 to 8 films whose top film takes the pixel's
/// thickness and whose other films vary as d_j + r_j s_c, s_c from their channel c of the
/// thickness map ([`nacre_optics::few_wavelengths::StackEvaluation`]).
#[derive(Clone, Debug)]
pub struct StackSetup {
    /// Ambient, films (their own thicknesses d_j⁰) and base.
    pub stack: nacre_optics::Stack,
    /// Relative thickness r_j of each film, nm (the top film's is unused).
    pub relative_nm: Vec<f64>,
    /// Each film's thickness-map channel (0 R or grey, 1 G, 2 B; the top film's is unused:
    /// it follows the material's thickness mapping of channel R); empty: every film follows
    /// channel R.
    pub channels: Vec<usize>,
    /// `None`: the rule ladder (counts from the pixel's OPD); `Some(N)`: N nodes everywhere.
    pub samples: Option<usize>,
}

impl Default for StackSetup {
    /// A two-film dielectric stack in air on glass (n 1.5): 100 nm of n 1.38 over 60 nm of
    /// n 2.3, the lower film varying by ±30 nm.
    fn default() -> Self {
        let constant = |n: f64| {
            nacre_optics::Material::constant(format!("{n}"), nacre_optics::C64::new(n, 0.0))
                .expect("a real index above zero is a valid material")
        };
        let layers = vec![
            nacre_optics::Layer {
                material: constant(1.38),
                thickness_nm: 100.0,
            },
            nacre_optics::Layer {
                material: constant(2.3),
                thickness_nm: 60.0,
            },
        ];
        StackSetup {
            stack: nacre_optics::Stack::new(constant(1.0), layers, constant(1.5))
                .expect("finite thicknesses and a clear ambient"),
            relative_nm: vec![0.0, 30.0],
            channels: Vec::new(),
            samples: None,
        }
    }
}

impl StackSetup {
    /// A dielectric stack of `films` (1 to 8) films in air on glass (n 1.5), alternating
    /// n 1.38 (100 nm) and n 2.3 (60 nm), every film below the top varying by ±20 nm: the
    /// stacks `nacre bench-gpu` times.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a film count outside 1 to 8.
    pub fn alternating(films: usize) -> Result<StackSetup> {
        if !(1..=nacre_optics::few_wavelengths::MAX_STACK_FILMS).contains(&films) {
            return Err(Error::OutOfRange {
                what: "film_stack: films".into(),
                value: films as f64,
                unit: "",
                expected: format!("1 to {}", nacre_optics::few_wavelengths::MAX_STACK_FILMS),
            });
        }
        let constant = |n: f64| {
            nacre_optics::Material::constant(format!("{n}"), nacre_optics::C64::new(n, 0.0))
                .expect("a real index above zero is a valid material")
        };
        let layers = (0..films)
            .map(|j| nacre_optics::Layer {
                material: constant(if j % 2 == 0 { 1.38 } else { 2.3 }),
                thickness_nm: if j % 2 == 0 { 100.0 } else { 60.0 },
            })
            .collect();
        Ok(StackSetup {
            stack: nacre_optics::Stack::new(constant(1.0), layers, constant(1.5))?,
            relative_nm: (0..films)
                .map(|j| if j == 0 { 0.0 } else { 20.0 })
                .collect(),
            channels: Vec::new(),
            samples: None,
        })
    }
}

/// Group 1 of `film_stack` for `setup`: the nodes of every rule, every medium's index at
/// every node and the uniform ([`StackEvaluation`](nacre_optics::few_wavelengths::StackEvaluation)
/// holds the same numbers in f64 for the CPU twin).
pub fn stack_buffers(
    colorimeter: &Colorimeter,
    setup: &StackSetup,
) -> Result<(Vec<params::StackNode>, Vec<[f32; 2]>, params::StackParams)> {
    use nacre_optics::few_wavelengths::{BASE_COUNT, COUNT_PER_OPD_NM, StackEvaluation};
    let mut eval =
        StackEvaluation::new(colorimeter, &setup.stack, &setup.relative_nm, setup.samples)?;
    if !setup.channels.is_empty() {
        eval = eval.with_channels(&setup.channels)?;
    }
    let mut nodes = Vec::new();
    let mut u = params::StackParams {
        films: eval.thickness_nm().len() as u32,
        dispersive: u32::from(eval.dispersive()),
        rule_count: eval.rules().len() as u32,
        fixed: u32::from(eval.fixed()),
        base_count: BASE_COUNT as f32,
        count_per_opd_nm: COUNT_PER_OPD_NM as f32,
        finesse: eval.finesse() as f32,
        ..params::StackParams::default()
    };
    for (i, rule) in eval.rules().iter().enumerate() {
        u.rule_offset[i] = nodes.len() as u32;
        u.rule_size[i] = rule.wavelengths_nm().len() as u32;
        for (&l, w) in rule.wavelengths_nm().iter().zip(rule.weights()) {
            nodes.push(params::StackNode {
                wavelength_nm: l as f32,
                _pad: [0.0; 3],
                weight: [w[0] as f32, w[1] as f32, w[2] as f32, 0.0],
            });
        }
    }
    for (j, (((d, r), k), c)) in eval
        .thickness_nm()
        .iter()
        .zip(eval.relative_nm())
        .zip(eval.opd_factors())
        .zip(eval.channels())
        .enumerate()
    {
        u.layers[j] = [*d as f32, *r as f32, *k as f32, *c as f32];
    }
    let indices = eval
        .indices()
        .iter()
        .flatten()
        .map(|n| [n.re as f32, n.im as f32])
        .collect();
    Ok((nodes, indices, u))
}

/// Options of a technique's group-1 bind group.
#[derive(Clone, Debug)]
pub struct TechniqueOptions {
    /// Harmonics M of `film_fourier`: 0 (the default) = automatic, as `nacre color --method
    /// fourier` (`fourier:auto`): per pixel, as many as the series' decay and the
    /// sensitivities' need for ΔE2000 p95 ≤ 0.1 (`nacre_optics::fourier` module docs, "How
    /// many harmonics"); a fixed M otherwise.
    pub harmonics: u32,
    /// Setup of `film_spectral`.
    pub spectral: SpectralSetup,
    /// Setup of `film_stack`.
    pub stack: StackSetup,
}

impl Default for TechniqueOptions {
    fn default() -> Self {
        TechniqueOptions {
            harmonics: 0,
            spectral: SpectralSetup {
                samples: 30,
                base: Material::constant("1.5", nacre_optics::C64::new(1.5, 0.0))
                    .expect("a real index above zero is a valid material"),
            },
            stack: StackSetup::default(),
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
        let missing = |kind: &'static str| Error::MissingTable {
            needed_by: format!("technique `{}`", technique.name()),
            kind,
            example: None,
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
                    Technique::Stack => {
                        let (nodes, indices, uniform) = stack_buffers(colorimeter, &options.stack)?;
                        let nodes = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                            label: Some("StackNode[]"),
                            contents: bytemuck::cast_slice(&nodes),
                            usage: wgpu::BufferUsages::STORAGE,
                        });
                        let indices =
                            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                                label: Some("stack indices"),
                                contents: bytemuck::cast_slice(&indices),
                                usage: wgpu::BufferUsages::STORAGE,
                            });
                        let uniform =
                            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                                label: Some("StackParams"),
                                contents: bytemuck::bytes_of(&uniform),
                                usage: wgpu::BufferUsages::UNIFORM,
                            });
                        device.create_bind_group(&wgpu::BindGroupDescriptor {
                            label: Some("stack tables"),
                            layout: &layout,
                            entries: &[
                                wgpu::BindGroupEntry {
                                    binding: 0,
                                    resource: nodes.as_entire_binding(),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 1,
                                    resource: indices.as_entire_binding(),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 2,
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
