//! Group 0 of the scene pipelines (`shaders/material.wgsl`), shared by the analytic scenes
//! and the glTF meshes: the view uniform ([`ViewUniform`]), the environment's textures (its
//! box mip chain, the GGX-prefiltered levels and E₁ table of [`crate::ibl`], the
//! `rough-film-lut` of [`FilmEval::Exact`]) and the render targets' formats.

use super::options::{
    FilmEval, MAX_PUNCTUAL_LIGHTS, PunctualKind, PunctualLight, SceneOptions, normalize,
};
use crate::context::{BufferInitExt, GpuContext};
use crate::environment::EnvironmentMap;
use crate::error::{Error, Result};
use crate::gpu::{
    linear_sampler, sampler_entry, texture_entry, uniform_entry, upload_layers, upload_mips,
};
use crate::tables::RoughFilmLutTextures;
use bytemuck::{Pod, Zeroable};

/// The render target format: 8-bit RGBA holding sRGB-encoded values written by the shader
/// (`material_display`), not an `…Srgb` format: the bytes read back are the bytes of the PNG.
pub const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// What a [`Renderer`](super::Renderer) writes: display pixels or linear radiance.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RenderOutput {
    /// Exposed, tone-mapped (PBR Neutral), sRGB-encoded RGBA8 ([`TARGET_FORMAT`]).
    #[default]
    Display,
    /// Linear scene radiance before exposure and tone mapping, `Rgba32Float`
    /// ([`LINEAR_TARGET_FORMAT`]; `scene_fs_linear`).
    Linear,
}

/// The render target format of [`RenderOutput::Linear`].
pub const LINEAR_TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// Mirror of `ViewLight` (`shaders/view.wgsl`): one [`PunctualLight`], 64 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LightUniform {
    /// World position (point and spot lights).
    pub position: [f32; 3],
    /// 0 directional, 1 point, 2 spot (`VIEW_LIGHT_*`).
    pub kind: u32,
    /// Unit direction the light shines along.
    pub direction: [f32; 3],
    /// 1 / range⁴ (0: unlimited), for the window clamp(1 − r⁴ / range⁴, 0, 1)².
    pub inv_range4: f32,
    /// Colour × intensity, linear RGB.
    pub radiant: [f32; 3],
    /// The spot's t = clamp(cos θ · scale + offset, 0, 1): scale = 1 / (cos θ_inner −
    /// cos θ_outer) (0 for other kinds).
    pub cone_scale: f32,
    /// offset = −cos θ_outer · scale (1 for other kinds: t = 1).
    pub cone_offset: f32,
    /// Padding to 64 bytes.
    pub _pad: [f32; 3],
}

impl LightUniform {
    /// The uniform of `light` (checked by [`SceneOptions::validate`]).
    pub fn new(light: &PunctualLight) -> LightUniform {
        let direction = normalize(light.direction.map(f64::from))
            .map_or([0.0, -1.0, 0.0], |d| d.map(|x| x as f32));
        let (kind, cone_scale, cone_offset) = match light.kind {
            PunctualKind::Directional => (0, 0.0, 1.0),
            PunctualKind::Point => (1, 0.0, 1.0),
            PunctualKind::Spot {
                inner_cone_rad,
                outer_cone_rad,
            } => {
                // KHR_lights_punctual's reference: scale = 1 / max(0.001, cos θ_i − cos θ_o).
                let (cos_inner, cos_outer) = (inner_cone_rad.cos(), outer_cone_rad.cos());
                let scale = 1.0 / (cos_inner - cos_outer).max(1e-3);
                (2, scale, -cos_outer * scale)
            }
        };
        LightUniform {
            position: light.position,
            kind,
            direction,
            inv_range4: light.range.map_or(0.0, |r| r.powi(-4)),
            radiant: light.colour.map(|c| c * light.intensity),
            cone_scale,
            cone_offset,
            _pad: [0.0; 3],
        }
    }
}

/// Mirror of `ViewParams` (`shaders/view.wgsl`): 656 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ViewUniform {
    /// Clip → world, column-major.
    pub inv_view_proj: [[f32; 4]; 4],
    /// Eye position.
    pub eye_position: [f32; 3],
    /// Linear exposure factor 2^EV.
    pub exposure: f32,
    /// Unit direction towards the light.
    pub light_direction: [f32; 3],
    /// Light intensity.
    pub light_intensity: f32,
    /// Light colour, linear RGB.
    pub light_colour: [f32; 3],
    /// Environment intensity.
    pub env_intensity: f32,
    /// Target size, pixels.
    pub resolution: [f32; 2],
    /// Scene id (0 sphere, 1 bubble, 2 plane).
    pub scene: u32,
    /// Last mip level of the environment texture.
    pub env_lod_max: f32,
    /// How many of `lights` are drawn (≤ [`MAX_PUNCTUAL_LIGHTS`]).
    pub light_count: u32,
    /// Padding to the array's 16-byte alignment.
    pub _pad: [u32; 3],
    /// The punctual lights drawn besides the directional one.
    pub lights: [LightUniform; MAX_PUNCTUAL_LIGHTS],
}

impl ViewUniform {
    /// The view uniform of `options` for an environment of `env_levels` mip levels.
    pub fn new(options: &SceneOptions, env_levels: usize) -> Result<ViewUniform> {
        let aspect = f64::from(options.width) / f64::from(options.height);
        let light =
            normalize(options.light.direction.map(f64::from)).ok_or_else(|| Error::Light {
                index: None,
                problem: "zero direction".into(),
            })?;
        Ok(ViewUniform {
            inv_view_proj: options.camera.inverse_view_projection(aspect)?,
            eye_position: options.camera.eye,
            exposure: 2f32.powf(options.exposure_ev),
            light_direction: light.map(|x| x as f32),
            light_intensity: options.light.intensity,
            light_colour: options.light.colour,
            env_intensity: options.env_intensity,
            resolution: [options.width as f32, options.height as f32],
            scene: options.scene.id(),
            env_lod_max: env_levels.saturating_sub(1) as f32,
            light_count: options.punctual_lights.len().min(MAX_PUNCTUAL_LIGHTS) as u32,
            _pad: [0; 3],
            lights: std::array::from_fn(|k| {
                options
                    .punctual_lights
                    .get(k)
                    .map_or_else(LightUniform::default, LightUniform::new)
            }),
        })
    }
}

/// Group 0, the view and the environment (`shaders/material.wgsl`): 0 the view uniform,
/// 1 the environment's box mip chain, 2 its sampler (u repeats, v clamps), 3 the
/// GGX-prefiltered environment, 4 the F = 1 GGX albedo table E₁, 5 a clamp-to-edge sampler,
/// 6 the `rough-film-lut` reflectance (3-D), 7 its [`RoughLutUniform`].
pub fn view_group_layout(device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
    let mut prefiltered = texture_entry(3);
    prefiltered.ty = wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable: true },
        view_dimension: wgpu::TextureViewDimension::D2Array,
        multisampled: false,
    };
    let mut rough_lut = texture_entry(6);
    rough_lut.ty = wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable: true },
        view_dimension: wgpu::TextureViewDimension::D3,
        multisampled: false,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[
            uniform_entry(0),
            texture_entry(1),
            sampler_entry(2),
            prefiltered,
            texture_entry(4),
            sampler_entry(5),
            rough_lut,
            uniform_entry(7),
        ],
    })
}

/// Mirror of `RoughLutParams` (`shaders/rough_lut_mapping.wgsl`; the axes of
/// `nacre_format::rough_film_lut::RoughLutAxes`): 48 bytes, defined once in
/// [`nacre_format::gpu_params`].
pub use nacre_format::gpu_params::RoughLutParams as RoughLutUniform;

/// The textures of group 0 besides the view uniform: the environment's box mip chain, its
/// GGX-prefiltered levels ([`crate::ibl::PrefilteredEnvironment`]) and the E₁ table
/// ([`crate::ibl::ggx_albedo_table`]). The classic path reads neither of the last two: they
/// are 1 × 1 placeholders unless the path is a split-sum one, and the `rough-film-lut`
/// a 1 × 1 × 1 placeholder unless the path is [`FilmEval::Exact`].
pub(crate) struct EnvironmentTextures {
    /// Mip levels of the environment's box chain.
    pub env_levels: usize,
    env: wgpu::Texture,
    prefiltered: wgpu::Texture,
    ggx_albedo: wgpu::Texture,
    rough_lut: wgpu::TextureView,
    rough_lut_uniform: RoughLutUniform,
}

impl EnvironmentTextures {
    /// Uploads `environment` (and, for the split-sum paths, prefilters it and builds E₁);
    /// `rough_lut` is bound for [`FilmEval::Exact`]. The diffraction scenes pass
    /// [`FilmEval::Classic`] and no table: they read the environment's box chain only.
    pub(crate) fn new(
        ctx: &GpuContext,
        environment: &EnvironmentMap,
        film_eval: FilmEval,
        rough_lut: Option<&RoughFilmLutTextures>,
    ) -> Result<EnvironmentTextures> {
        let split_sum = film_eval.split_sum();
        let (rough_lut, rough_lut_uniform) = match (rough_lut, film_eval) {
            (Some(lut), FilmEval::Exact) => (
                lut.reflectance.create_view(&Default::default()),
                RoughLutUniform::new(&lut.axes, lut.has_transmittance),
            ),
            _ => {
                let placeholder = ctx.checked("a rough-film-lut placeholder", || {
                    ctx.device.create_texture(&wgpu::TextureDescriptor {
                        label: Some("rough-film-lut (unused)"),
                        size: wgpu::Extent3d {
                            width: 1,
                            height: 1,
                            depth_or_array_layers: 1,
                        },
                        mip_level_count: 1,
                        sample_count: 1,
                        dimension: wgpu::TextureDimension::D3,
                        format: wgpu::TextureFormat::Rgba16Float,
                        usage: wgpu::TextureUsages::TEXTURE_BINDING,
                        view_formats: &[],
                    })
                })?;
                (
                    placeholder.create_view(&Default::default()),
                    RoughLutUniform::default(),
                )
            }
        };
        let env_mips = environment.mip_chain();
        let env = upload_mips(
            ctx,
            "environment",
            wgpu::TextureFormat::Rgba16Float,
            &env_mips,
        )?;
        let (prefiltered, ggx_albedo) = if split_sum {
            let p = crate::ibl::PrefilteredEnvironment::cached(environment);
            (
                upload_layers(ctx, "prefiltered environment", &p.levels)?,
                upload_mips(
                    ctx,
                    "GGX albedo",
                    wgpu::TextureFormat::Rg16Float,
                    std::slice::from_ref(crate::ibl::ggx_albedo_table()),
                )?,
            )
        } else {
            (
                upload_layers(
                    ctx,
                    "prefiltered environment (unused)",
                    &[(1, 1, vec![[0.0f32; 4]])],
                )?,
                upload_mips(
                    ctx,
                    "GGX albedo (unused)",
                    wgpu::TextureFormat::Rg16Float,
                    &[(1, 1, vec![[0.0f32; 2]])],
                )?,
            )
        };
        Ok(EnvironmentTextures {
            env,
            env_levels: env_mips.len(),
            prefiltered,
            ggx_albedo,
            rough_lut,
            rough_lut_uniform,
        })
    }

    /// The group-0 bind group for `layout` ([`view_group_layout`]) with the view uniform
    /// `uniform` (its bytes).
    pub(crate) fn bind_group(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        label: &str,
        uniform: &[u8],
    ) -> wgpu::BindGroup {
        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: uniform,
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let env_view = self.env.create_view(&Default::default());
        let prefiltered_view = self.prefiltered.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let albedo_view = self.ggx_albedo.create_view(&Default::default());
        let rough_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("rough-film-lut axes"),
            contents: bytemuck::bytes_of(&self.rough_lut_uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let env_sampler = linear_sampler(device, label, false);
        let clamp_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("lut clamp"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&env_view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&env_sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&prefiltered_view),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(&albedo_view),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::Sampler(&clamp_sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: wgpu::BindingResource::TextureView(&self.rough_lut),
                },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: rough_buffer.as_entire_binding(),
                },
            ],
        })
    }
}
