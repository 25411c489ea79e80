//! The ray-cast diffraction scenes of `nacre render --scene cd-disc | dvd-disc | snake-skin |
//! grating-plane`
//! (`shaders/diffraction_scene.wgsl`) and the scene pass the GPU bench reuses ([`ScenePass`]),
//! with a table of either layout. Which scenes there are, and their cameras and lights, is
//! the catalogue [`DiffractionScene`] (`scenes.rs`).

use super::integrated;
use super::lobes::{EnvironmentLobes, LOBE_KW_SAMPLES};
use super::scenes::DiffractionScene;
use super::tables::DiffractionTables;
use super::terms::{
    DiffractionBinding, DiffractionOptions, DiffractionTable, LLVMPIPE_LOOP_LIMIT, composition,
    filter_radius, filtered_iterations, spectrum_weights, wavelength_grid,
};
use crate::context::{BufferInitExt, GpuContext};
use crate::environment::EnvironmentMap;
use crate::error::{Error, Result};
use crate::gpu;
use crate::gpu::read_texture;
use crate::image_io::{Level, MAX_DIMENSION, RenderedImage};
use crate::render::{Camera, EnvironmentTextures, FilmEval, Light, ViewUniform, view_group_layout};
use crate::shaders;
use bytemuck::{Pod, Zeroable};
use nacre_format::diffraction::DiffractionRecord;
use nacre_format::msg;
use nacre_format::param::Param;
use nacre_optics::diffraction::SpectralGrid;
use std::path::PathBuf;

/// Its consumers (`shaders/diffraction_scene.wgsl`): the scenes, the bench pass and the probe.
pub const DIFFRACTION_SCENE: &str = include_str!("../../../../shaders/diffraction_scene.wgsl");

/// Most environment samples of a scene (`DiffractionLights.samples`).
pub const MAX_ENV_SAMPLES: usize = 8;

/// Environment samples of a scene with an "integrated" table when none are asked for (the
/// "terms" layout integrates the whole environment instead: [`super::lobes`]).
pub const DEFAULT_ENV_SAMPLES: usize = 4;

/// Settings of a diffraction scene.
#[derive(Clone, Debug)]
pub struct DiffractionSceneOptions {
    /// The scene.
    pub scene: DiffractionScene,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// The camera.
    pub camera: Camera,
    /// Equirectangular environment (OpenEXR); `None`: the default studio without its sun
    /// (the directional light is the sun) — [`crate::render::procedural_environment_with`].
    pub environment: Option<PathBuf>,
    /// Environment multiplier (default 0.5: a dim room, so that the rainbows stand out).
    pub env_intensity: f32,
    /// How the environment diffracts. `None` (the default): a "terms" table integrates the
    /// whole environment through its lobes ([`super::lobes`]), an "integrated" table (which
    /// keeps no bins) diffracts its [`DEFAULT_ENV_SAMPLES`] brightest texels like the light.
    /// `Some(K)`: the K brightest texels (0 to [`MAX_ENV_SAMPLES`], [`environment_samples`])
    /// with either layout, and no lobes (0: only the environment's mirror image remains).
    pub env_samples: Option<usize>,
    /// The directional light; `intensity` is its irradiance E₀ at normal incidence (the
    /// grating reflects f E₀ cos θ_i, f = ρ (σ_s k)²/π Stam's BRDF: [`lobe_gain`]).
    pub light: Light,
    /// Exposure, EV stops.
    pub exposure_ev: f32,
    /// The technique's settings (default here: a 10 nm wavelength step, which an
    /// integrated table leaves unused: [`DiffractionOptions`]).
    pub technique: DiffractionOptions,
    /// GGX roughness α of the grating's microfacets (0 to [`MAX_ROUGHNESS`]; default 0, a
    /// smooth grating): the two-scale model of `shaders/diffraction_scene.wgsl`, which blurs
    /// every order by the facets' slopes — a "terms" table's environment lobes
    /// (`scene_rough_light`; so without `env_samples`), an "integrated" table's prefiltered
    /// levels (σ² = σ_uv² + w² σ_m², `diffraction_integrated_colour_filtered`; with its
    /// environment samples).
    pub roughness: f64,
}

/// Largest GGX roughness α of a diffraction scene's grating.
pub const MAX_ROUGHNESS: f64 = 1.0;

/// The slope variance per axis σ_m² of microfacets of GGX roughness α, as the scenes blur a
/// rough grating's orders with it: GGX's slope distribution
/// P₂₂(s) = 1/(π α² (1 + |s|²/α²)²) has no finite variance (tails ∝ |s|⁻⁴), so it is matched
/// to the Beckmann distribution of the same α (Walter et al., EGSR 2007: the same parameter,
/// the same peak), whose slopes have variance α²/2 per axis.
pub fn rough_slope_variance(alpha: f64) -> f64 {
    0.5 * alpha * alpha
}

impl DiffractionSceneOptions {
    /// The defaults of `scene`: 800 × 600, the environment integrated (or, for an integrated
    /// table, [`DEFAULT_ENV_SAMPLES`] samples), 10 nm wavelength step,
    /// the scene's [`DiffractionScene::fresnel`].
    pub fn new(scene: DiffractionScene) -> DiffractionSceneOptions {
        DiffractionSceneOptions {
            scene,
            width: 800,
            height: 600,
            camera: scene.camera(),
            environment: None,
            env_intensity: 0.5,
            env_samples: None,
            light: scene.light(),
            exposure_ev: 0.0,
            technique: DiffractionOptions {
                wavelength_step_nm: Some(10.0),
                fresnel: scene.fresnel(),
                ..DiffractionOptions::default()
            },
            roughness: 0.0,
        }
    }

    /// Checks the settings.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] or [`Error::Light`] naming the setting.
    pub fn validate(&self) -> Result<()> {
        let bad = |what: &str, value: f64, unit: &'static str, expected: String| {
            Err(Error::OutOfRange {
                what: what.into(),
                value,
                unit,
                expected,
            })
        };
        for (what, n) in [("width", self.width), ("height", self.height)] {
            if n == 0 || n > MAX_DIMENSION {
                return bad(
                    what,
                    f64::from(n),
                    " pixels",
                    format!("1 to {MAX_DIMENSION}"),
                );
            }
        }
        if !self.exposure_ev.is_finite() || self.exposure_ev.abs() > 64.0 {
            return bad(
                "exposure",
                f64::from(self.exposure_ev),
                " EV",
                "−64 to 64".into(),
            );
        }
        if !(self.env_intensity.is_finite() && self.env_intensity >= 0.0) {
            return bad(
                "environment intensity",
                f64::from(self.env_intensity),
                "",
                "≥ 0".into(),
            );
        }
        if !(self.roughness.is_finite() && (0.0..=MAX_ROUGHNESS).contains(&self.roughness)) {
            return bad(
                "roughness (GGX α)",
                self.roughness,
                "",
                format!("0 to {MAX_ROUGHNESS}"),
            );
        }
        if let Some(k) = self.env_samples.filter(|k| *k > MAX_ENV_SAMPLES) {
            return bad(
                "environment samples",
                k as f64,
                "",
                format!("0 to {MAX_ENV_SAMPLES}"),
            );
        }
        let l = &self.light;
        if !(l.direction.iter().chain(&l.colour).all(|x| x.is_finite())
            && l.intensity.is_finite()
            && l.intensity >= 0.0
            && l.direction.iter().any(|x| *x != 0.0))
        {
            return Err(Error::Light {
                index: None,
                problem: format!("{l:?} (finite, non-zero direction)"),
            });
        }
        self.camera
            .inverse_view_projection(f64::from(self.width) / f64::from(self.height))?;
        Ok(())
    }
}

/// Mirror of `DiffractionLights` (shaders/diffraction_scene.wgsl, group 2 binding 0, 448
/// bytes): the light, the environment samples and the environment lobes' settings as the
/// gratings see them (the lobes, their efficiencies and the spectrum are bindings 1–3,
/// [`LobeData`]). The camera, the exposure, the
/// light's direction, colour and irradiance E₀ and the environment are every scene's group 0
/// ([`ViewUniform`], `shaders/view.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct DiffractionLightsUniform {
    /// I₀ = E₀ (σ_s k₀)²/π, the radiance of the light's mirror image ([`lobe_gain`]).
    pub light_radiance: f32,
    /// Environment samples used.
    pub sample_count: u32,
    /// Environment lobes (0: none; [`super::lobes`]).
    pub lobe_count: u32,
    /// Wavelengths of the lobes' spectrum.
    pub lobe_wavelength_count: u32,
    /// Sample directions (xyz unit, w 0).
    pub samples: [[f32; 4]; MAX_ENV_SAMPLES],
    /// Sample radiance I_k (rgb, × env_intensity; w 0).
    pub sample_radiance: [[f32; 4]; MAX_ENV_SAMPLES],
    /// (kw_min, (S − 1)/(−kw_min), Δλ µm, 0): the efficiency samples' first kw and their
    /// density (S = [`LOBE_KW_SAMPLES`]), and the step of the lobes' wavelength grid.
    pub lobe_kw: [f32; 4],
    /// (σ_m², α, π/σ_s², 0): the grating's microfacets, GGX roughness α and the slope
    /// variance per axis σ_m² = α²/2 of the Beckmann distribution it is matched to
    /// ([`rough_slope_variance`]; 0 for a smooth grating), and the lobes' normalisation
    /// π/σ_s² (`scene_rough_light`).
    pub roughness: [f32; 4],
    /// The environment's irradiance in nine spherical harmonics, × env_intensity (rgb, w 0;
    /// [`crate::ibl::irradiance_sh9`]): the snake's Lambertian skin (`scene_irradiance`).
    pub irradiance: [[f32; 4]; 9],
}

/// Bindings 1–3 of the scenes' group 2: the environment lobes of a "terms" table
/// ([`EnvironmentLobes`]) as the shader reads them, and the spectrum they are summed over.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LobeData {
    /// Per lobe (κ_x, κ_y rad/µm, variance per axis (rad/µm)², 0).
    pub lobes: Vec<[f32; 4]>,
    /// η(kw) of lobe l at `l · S + s` (S = [`LOBE_KW_SAMPLES`]).
    pub efficiency: Vec<f32>,
    /// (λ nm, u_R, u_G, u_B) per wavelength (the technique's grid and CIE weights).
    pub spectrum: Vec<[f32; 4]>,
    /// `DiffractionLights.lobe_kw`.
    pub kw: [f32; 4],
}

impl LobeData {
    /// The lobes of `lobes` summed over the wavelength grid of `record` at `step_nm` (the
    /// scene technique's: [`wavelength_grid`]) with the CIE weights of `colorimeter`.
    ///
    /// # Errors
    /// The grid's errors ([`wavelength_grid`], [`SpectralGrid::new`]).
    pub fn new(
        lobes: &EnvironmentLobes,
        record: &DiffractionRecord,
        colorimeter: &nacre_optics::colour::Colorimeter,
        step_nm: Option<f64>,
    ) -> Result<LobeData> {
        let wavelengths = wavelength_grid(record, step_nm)?;
        let step_um = (wavelengths[1] - wavelengths[0]) * 1e-3;
        let grid = SpectralGrid::new(colorimeter, &wavelengths)?;
        Ok(LobeData {
            lobes: lobes
                .lobes
                .iter()
                .map(|l| {
                    [
                        l.centre_per_um[0] as f32,
                        l.centre_per_um[1] as f32,
                        l.variance_per_um2 as f32,
                        0.0,
                    ]
                })
                .collect(),
            efficiency: lobes
                .lobes
                .iter()
                .flat_map(|l| l.efficiency.iter().map(|&e| e as f32))
                .collect(),
            spectrum: spectrum_weights(&grid, colorimeter),
            kw: [
                lobes.kw_min as f32,
                ((LOBE_KW_SAMPLES - 1) as f64 / -lobes.kw_min) as f32,
                step_um as f32,
                0.0,
            ],
        })
    }

    /// Per-pixel loop iterations of the lobe sum (lobes × wavelengths).
    pub fn iterations(&self) -> u64 {
        (self.lobes.len() * self.spectrum.len()) as u64
    }

    /// Appends the specular order of `lobes` as one more lobe (centre 0, the window's
    /// variance, efficiency |P_DC(kw)|²) past the environment's, for a rough grating's light
    /// (`scene_rough_light`, which sums every order; the environment's lobe sum stops at
    /// `DiffractionLights.lobe_count` and keeps its mirror image apart).
    pub fn push_specular(&mut self, lobes: &EnvironmentLobes) {
        self.lobes
            .push([0.0, 0.0, lobes.window_per_um2 as f32, 0.0]);
        self.efficiency
            .extend(lobes.specular.iter().map(|&e| e as f32));
    }
}

/// The `count` brightest texels (by luminance 0.2126 R + 0.7152 G + 0.0722 B) of the 32 × 16
/// (or the first narrower) level of `env`'s mip chain, above the horizon (y > 0.05) and at
/// least 25° apart, as (unit direction, irradiance L·Ω at normal incidence, Ω the texel's
/// solid angle (2π/w)(π/h) sin θ); brightest first, ties by texel index.
pub fn environment_samples(env: &EnvironmentMap, count: usize) -> Vec<([f32; 3], [f32; 3])> {
    let levels = env.mip_chain();
    let (w, h, texels): &Level<4> = levels
        .iter()
        .find(|(w, _, _)| *w <= 32)
        .unwrap_or_else(|| levels.last().expect("a mip chain has a level"));
    let mut order: Vec<(f32, usize)> = texels
        .iter()
        .enumerate()
        .map(|(i, t)| (0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2], i))
        .collect();
    order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let min_cos = 25f64.to_radians().cos();
    let mut chosen: Vec<([f32; 3], [f32; 3])> = Vec::new();
    for (lum, i) in order {
        if chosen.len() == count || lum.is_nan() || lum <= 0.0 {
            break;
        }
        let (u, v) = (
            ((i % w) as f64 + 0.5) / *w as f64,
            ((i / w) as f64 + 0.5) / *h as f64,
        );
        let d = crate::ibl::env_uv_to_direction(u, v);
        if d[1] <= 0.05 {
            continue;
        }
        let far = chosen.iter().all(|(c, _)| {
            f64::from(c[0]) * d[0] + f64::from(c[1]) * d[1] + f64::from(c[2]) * d[2] < min_cos
        });
        if far {
            let t = texels[i];
            let theta = std::f64::consts::PI * v;
            let omega = (std::f64::consts::TAU / *w as f64)
                * (std::f64::consts::PI / *h as f64)
                * theta.sin();
            chosen.push((
                d.map(|x| x as f32),
                [t[0], t[1], t[2]].map(|x| (f64::from(x) * omega) as f32),
            ));
        }
    }
    chosen
}

/// Groups 0 and 2 of the scene and bench passes: every scene's view and environment
/// ([`view_group_layout`], the environment's box chain; the split-sum textures are
/// placeholders) and the diffraction lights.
struct SceneGroups {
    view_layout: wgpu::BindGroupLayout,
    view: wgpu::BindGroup,
    lights_layout: wgpu::BindGroupLayout,
    lights: wgpu::BindGroup,
}

fn scene_groups(
    ctx: &GpuContext,
    view: &ViewUniform,
    lights: &DiffractionLightsUniform,
    lobes: &LobeData,
    env: &EnvironmentMap,
) -> Result<SceneGroups> {
    let textures = EnvironmentTextures::new(ctx, env, FilmEval::Classic, None)?;
    let device = &ctx.device;
    ctx.checked("binding the diffraction view", || {
        let view_layout = view_group_layout(device, "diffraction view");
        let view = textures.bind_group(
            device,
            &view_layout,
            "diffraction view",
            bytemuck::bytes_of(view),
        );
        let storage = |binding: u32| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let lights_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("diffraction lights"),
            entries: &[
                crate::gpu::uniform_entry(0),
                storage(1),
                storage(2),
                storage(3),
            ],
        });
        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("DiffractionLights"),
            contents: bytemuck::bytes_of(lights),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        // A storage binding may not be empty: one zero element stands for none (the
        // uniform's counts say how many are read).
        let store = |label: &str, bytes: &[u8]| {
            let zero = [0u8; 16];
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: if bytes.is_empty() { &zero } else { bytes },
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let lobe_buffer = store("diffraction lobes", bytemuck::cast_slice(&lobes.lobes));
        let efficiency = store(
            "diffraction lobe efficiency",
            bytemuck::cast_slice(&lobes.efficiency),
        );
        let spectrum = store(
            "diffraction lobe spectrum",
            bytemuck::cast_slice(&lobes.spectrum),
        );
        let lights = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("diffraction lights"),
            layout: &lights_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: lobe_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: efficiency.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: spectrum.as_entire_binding(),
                },
            ],
        });
        SceneGroups {
            view_layout,
            view,
            lights_layout,
            lights,
        }
    })
}

/// Group 1 of a scene pass: the technique of the table's layout.
enum SceneTechnique {
    /// Layout "terms": the table, its uniform and the spectral weights.
    Terms(DiffractionBinding),
    /// Layout "integrated": the table's own bind group
    /// ([`DiffractionIntegrated::bind_group`]).
    Integrated {
        layout: wgpu::BindGroupLayout,
        bind_group: wgpu::BindGroup,
    },
}

/// The scene (or bench) pipeline with its groups 0 (view), 1 (technique) and 2 (lights),
/// ready to draw.
pub struct ScenePass {
    pipeline: wgpu::RenderPipeline,
    groups: SceneGroups,
    technique: SceneTechnique,
}

impl ScenePass {
    /// Group 1 and the source for `table`: the terms technique ([`compose`]) with a
    /// [`DiffractionBinding`], or the integrated module with the adapter
    /// ([`integrated::compose_scene`]) and the table's own bind group.
    fn new(
        ctx: &GpuContext,
        table: &DiffractionTables,
        technique: &DiffractionOptions,
        view: &ViewUniform,
        lights: &DiffractionLightsUniform,
        lobes: &LobeData,
        env: &EnvironmentMap,
    ) -> Result<ScenePass> {
        let (technique, source) = match table {
            DiffractionTables::Terms(t) => (
                SceneTechnique::Terms(DiffractionBinding::new(ctx, t, technique)?),
                composition(),
            ),
            DiffractionTables::Integrated(t) => {
                let wanted = integrated::fresnel_parameters(technique.fresnel)?;
                if wanted != (t.uniform.fresnel_kind, t.uniform.fresnel_ior) {
                    return Err(Error::FresnelMismatch {
                        table: t.name.clone(),
                        fresnel: format!("{:?}", technique.fresnel),
                    });
                }
                // The footprint filter (off: point samples, as before issue 37) and a rough
                // grating's facets, which blur with or without it.
                let slope_variance = lights.roughness[0];
                let uniform = integrated::DiffractionIntegratedUniform {
                    footprint_filter: u32::from(
                        technique.filter_radius.is_some() || slope_variance > 0.0,
                    ),
                    slope_variance,
                    ..t.uniform
                };
                (
                    SceneTechnique::Integrated {
                        layout: t.bind_group_layout().clone(),
                        bind_group: t.bind_group_with(ctx, &uniform)?,
                    },
                    integrated::scene_composition(),
                )
            }
        };
        let technique_layout = match &technique {
            SceneTechnique::Terms(b) => &b.layout,
            SceneTechnique::Integrated { layout, .. } => layout,
        };
        let groups = scene_groups(ctx, view, lights, lobes, env)?;
        let device = &ctx.device;
        let module = shaders::create_module(ctx, "diffraction scene", &source)?;
        let pipeline = ctx.checked("building the diffraction pipeline", || {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("diffraction scene"),
                bind_group_layouts: &[
                    Some(&groups.view_layout),
                    Some(technique_layout),
                    Some(&groups.lights_layout),
                ],
                immediate_size: 0,
            });
            gpu::fullscreen_pipeline(
                device,
                "diffraction scene",
                &module,
                &layout,
                ("diffraction_vs", "diffraction_scene_fs"),
                &[crate::render::TARGET_FORMAT],
            )
        })?;
        Ok(ScenePass {
            pipeline,
            groups,
            technique,
        })
    }

    /// The bench pass of `nacre bench-gpu`: every pixel of a `width × height` target shaded
    /// with the technique of `table`'s layout (scene 2 of `shaders/diffraction_scene.wgsl`),
    /// lit by `light`.
    pub fn bench(
        ctx: &GpuContext,
        table: &DiffractionTables,
        technique: &DiffractionOptions,
        width: u32,
        height: u32,
        light: &Light,
    ) -> Result<ScenePass> {
        let view = ViewUniform {
            exposure: 1.0,
            light_direction: unit(light.direction),
            light_colour: light.colour,
            light_intensity: light.intensity,
            resolution: [width as f32, height as f32],
            scene: 2,
            ..ViewUniform::zeroed()
        };
        let lights = DiffractionLightsUniform {
            light_radiance: light.intensity * lobe_gain(table.record()),
            ..DiffractionLightsUniform::zeroed()
        };
        let env = EnvironmentMap {
            width: 1,
            height: 1,
            rgb: vec![[0.0; 3]],
        };
        let pass = ScenePass::new(
            ctx,
            table,
            technique,
            &view,
            &lights,
            &LobeData::default(),
            &env,
        )?;
        pass.check_loop_cap(ctx, 1, false, 0, "bench")?;
        Ok(pass)
    }

    /// On llvmpipe, refuses a terms-layout pass whose per-pixel loops — `diffracted` calls of
    /// `diffraction_colour` (`diffraction_colour_footprint` when `filtered`: the scenes), the
    /// specular order and `lobe_iterations` of the environment's lobe sum
    /// ([`LobeData::iterations`]) — could run past
    /// [`LLVMPIPE_LOOP_LIMIT`], which would silently cut them short. The estimate counts
    /// the sums' own loops; llvmpipe's count runs ~20 % higher (cd-disc went wrong from 56
    /// wavelengths on, an estimate of 54,824), so the pass is refused above three quarters of
    /// the cap. Other adapters and integrated tables (a few dozen iterations) always pass.
    ///
    /// # Errors
    /// [`Error::Refused`] naming the way out (a coarser step, fewer samples, the fast layout).
    pub fn check_loop_cap(
        &self,
        ctx: &GpuContext,
        diffracted: u64,
        filtered: bool,
        lobe_iterations: u64,
        what: &str,
    ) -> Result<()> {
        let Some(binding) = self.technique() else {
            return Ok(());
        };
        let u = &binding.uniform;
        let specular = u64::from(u.wavelength_count) * (u64::from(u.order) + 3);
        let per_colour = if filtered {
            binding.loop_iterations_per_filtered_colour()
        } else {
            binding.loop_iterations_per_colour()
        };
        let needed = diffracted * per_colour + specular + lobe_iterations;
        if ctx.info.name.contains("llvmpipe") && needed > LLVMPIPE_LOOP_LIMIT * 3 / 4 {
            return Err(Error::Refused {
                context: format!("the diffraction {what} pass on {}", ctx.info.name),
                message: msg![
                    format!(
                        "needs about {needed} shader loop iterations per pixel ({diffracted} diffracted lights × {} wavelengths), more than llvmpipe allows with margin (it stops every shader invocation after {LLVMPIPE_LOOP_LIMIT} and would draw a wrong picture): use a coarser ",
                        u.wavelength_count
                    ),
                    Param::WavelengthStep,
                    " (",
                    Param::DiffractionStep,
                    " in bench-gpu), fewer ",
                    Param::EnvSamples,
                    ", or a table in the layout \"integrated\" (e.g. ",
                    Param::Tables.given("cd-tracks-fast"),
                    ")"
                ],
            });
        }
        Ok(())
    }

    /// Records the draw into `pass` (a render pass on a [`crate::render::TARGET_FORMAT`] target).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.groups.view, &[]);
        let technique = match &self.technique {
            SceneTechnique::Terms(b) => &b.bind_group,
            SceneTechnique::Integrated { bind_group, .. } => bind_group,
        };
        pass.set_bind_group(1, technique, &[]);
        pass.set_bind_group(2, &self.groups.lights, &[]);
        pass.draw(0..3, 0..1);
    }

    /// The terms technique's bind group (uniform, spectrum) as built; `None` for an
    /// integrated table (its group 1 is the table's own).
    pub fn technique(&self) -> Option<&DiffractionBinding> {
        match &self.technique {
            SceneTechnique::Terms(b) => Some(b),
            SceneTechnique::Integrated { .. } => None,
        }
    }
}

/// The footprint filter's radius cap for a scene pass of `table` on llvmpipe: the largest
/// cap, at most `technique.filter_radius`, whose per-pixel loops (`diffracted` filtered
/// colours, the specular order and `lobe_iterations` of the environment's lobes) stay within three quarters of [`LLVMPIPE_LOOP_LIMIT`]
/// (the margin of [`ScenePass::check_loop_cap`]); 0 (the table's own radius) when none does,
/// which that check then refuses; `None` when the filter is off. The filter keeps its weights at any cap; a smaller one
/// loses the detail of the widest footprints, not their energy (`shaders/diffraction.wgsl`).
///
/// # Errors
/// [`Error::Invalid`] for a bad window tolerance or wavelength step.
pub fn llvmpipe_filter_radius(
    table: &DiffractionTable,
    technique: &DiffractionOptions,
    diffracted: u64,
    lobe_iterations: u64,
) -> Result<Option<i32>> {
    let radius = table.radius(technique.window_tolerance)?;
    let wavelengths = wavelength_grid(&table.record, technique.wavelength_step_nm)?.len() as u32;
    let order = table.terms.order() as u32;
    let specular = u64::from(wavelengths) * (u64::from(order) + 3);
    let size = [table.record.nx, table.record.ny];
    let Some(wanted) = technique.filter_radius else {
        return Ok(None);
    };
    let top = wanted.clamp(0, super::terms::MAX_FILTER_RADIUS);
    Ok((0..=top)
        .rev()
        .find(|&cap| {
            let needed = diffracted
                * filtered_iterations(order, wavelengths, filter_radius(radius, size, cap))
                + specular
                + lobe_iterations;
            needed <= LLVMPIPE_LOOP_LIMIT * 3 / 4
        })
        .or(Some(0)))
}

/// Refuses a rough grating (`options.roughness` > 0) on a "terms" table without its
/// environment lobes (a scene whose environment is `env_samples`): its rough light is drawn
/// through them (`scene_rough_light`). An "integrated" table blurs its prefiltered levels
/// instead, samples and all.
///
/// # Errors
/// [`Error::Refused`] naming the roughness and the way out.
fn refuse_rough_without_lobes(
    table: &DiffractionTables,
    options: &DiffractionSceneOptions,
) -> Result<()> {
    if options.roughness <= 0.0 {
        return Ok(());
    }
    let why = match (table, options.env_samples) {
        (DiffractionTables::Integrated(_), _) => return Ok(()),
        (_, Some(_)) => {
            ": a rough grating is drawn through the table's environment lobes, which environment samples replace"
        }
        _ => return Ok(()),
    };
    Err(Error::Refused {
        context: format!("the {} scene", options.scene.name()),
        message: msg![Param::Roughness.given(options.roughness.to_string()), why],
    })
}

/// Reference wavelength of [`lobe_gain`], nm (the baker's
/// [`nacre_optics::diffraction::integrated::K_SQUARED_REFERENCE_NM`], which integrated tables
/// record as their k² reference).
pub const LOBE_REFERENCE_NM: f64 = nacre_optics::diffraction::integrated::K_SQUARED_REFERENCE_NM;

/// (σ_s k₀)²/π at k₀ = 2π/λ₀: the radiance, per unit irradiance at normal incidence, of a
/// light's mirror image spread over the coherence lobe. A flat mirror's
/// |P̃|² = exp(−σ_s² k² |Δ(u, v)|²) integrates to π/(σ_s k)² over (u, v), so Stam's BRDF is
/// f = ρ (σ_s k)²/π and a source of irradiance E at normal incidence, at θ_i from the normal
/// of a surface of relative reflectance ρ, gives the radiance
/// f · E cos θ_i = ρ · E · (σ_s k₀)²/π · (k/k₀)² · cos θ_i. The scenes pass E · this gain as
/// one number and the scene multiplies by cos θ_i (`scene_shade`,
/// `shaders/diffraction_scene.wgsl`); the (k/k₀)² = (λ₀/λ)² per wavelength comes from the
/// technique:
///
/// * layout "terms": λ₀ = [`LOBE_REFERENCE_NM`]; the shader weights each wavelength
///   (`diffraction_colour_footprint`'s `reference_nm`, `shaders/diffraction.wgsl`, and the
///   rough light's lobes, `scene_rough_light`);
/// * layout "integrated" baked with Stam's k² (the manifest's `k_squared_reference_nm`):
///   λ₀ = that wavelength, whose (λ₀/λ)² the table's layers already hold — for the light,
///   the environment's samples, a rough grating's blurred levels alike (they all read the
///   layers; a blur is linear);
/// * layout "integrated" without the field (a table baked before the weight): λ₀ =
///   [`LOBE_REFERENCE_NM`] and no (λ₀/λ)² at all — such a table renders as it did, tilted
///   towards red by (λ/555 nm)² against the terms technique.
pub fn lobe_gain(record: &DiffractionRecord) -> f32 {
    let reference_nm = record
        .integrated
        .as_ref()
        .and_then(|s| s.k_squared_reference_nm)
        .filter(|r| *r > 0.0 && r.is_finite())
        .unwrap_or(LOBE_REFERENCE_NM);
    let k0 = std::f64::consts::TAU / (reference_nm * 1e-3);
    ((record.sigma_s_um * k0).powi(2) / std::f64::consts::PI) as f32
}

fn unit(v: [f32; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if l > 0.0 && l.is_finite() {
        v.map(|x| x / l)
    } else {
        [0.0, 1.0, 0.0]
    }
}

/// Renders a diffraction scene with `table` (either layout) and reads it back as
/// sRGB-encoded RGBA8: [`render_diffraction_scene_in`] under `options.environment` (or the
/// default studio without its sun).
///
/// # Errors
/// [`Error::Invalid`] for bad options (and an integrated table loaded with another F² than
/// `options.technique.fresnel`); environment and GPU errors as [`crate::render`].
pub fn render_diffraction_scene(
    ctx: &GpuContext,
    table: &DiffractionTables,
    options: &DiffractionSceneOptions,
) -> Result<RenderedImage> {
    options.validate()?;
    let env = match &options.environment {
        Some(path) => EnvironmentMap::load(path)?,
        None => {
            let (w, h) = crate::environment::DEFAULT_ENVIRONMENT_SIZE;
            crate::environment::procedural_environment_with(w, h, false)
        }
    };
    render_diffraction_scene_in(ctx, table, options, &env)
}

/// Renders a diffraction scene under `env` (`options.environment` unused): the light, the
/// environment's mirror image through the specular order, and the environment diffracted
/// through the table's lobes or as samples ([`DiffractionSceneOptions::env_samples`]).
///
/// # Errors
/// As [`render_diffraction_scene`].
pub fn render_diffraction_scene_in(
    ctx: &GpuContext,
    table: &DiffractionTables,
    options: &DiffractionSceneOptions,
    env: &EnvironmentMap,
) -> Result<RenderedImage> {
    options.validate()?;
    let (width, height) = (options.width, options.height);
    let gain = lobe_gain(table.record());
    let view = ViewUniform {
        inv_view_proj: options
            .camera
            .inverse_view_projection(f64::from(width) / f64::from(height))?,
        eye_position: options.camera.eye,
        exposure: 2f32.powf(options.exposure_ev),
        light_direction: unit(options.light.direction),
        light_intensity: options.light.intensity,
        light_colour: options.light.colour,
        env_intensity: options.env_intensity,
        resolution: [width as f32, height as f32],
        scene: options.scene.id(),
        env_lod_max: env.mip_chain().len().saturating_sub(1) as f32,
        ..ViewUniform::zeroed()
    };
    // The whole environment through the lobes (terms tables), or its brightest texels.
    refuse_rough_without_lobes(table, options)?;
    let mut env_lobe_count = 0;
    let lobes = match (table, options.env_samples) {
        (DiffractionTables::Terms(t), None) => {
            let lobes = EnvironmentLobes::new(&t.terms, &t.record)?;
            let mut data = LobeData::new(
                &lobes,
                &t.record,
                &t.colorimeter()?,
                options.technique.wavelength_step_nm,
            )?;
            env_lobe_count = data.lobes.len();
            if options.roughness > 0.0 {
                data.push_specular(&lobes);
            }
            data
        }
        _ => LobeData::default(),
    };
    let sample_count = match (table, options.env_samples) {
        (_, Some(k)) => k,
        (DiffractionTables::Terms(_), None) => 0,
        (DiffractionTables::Integrated(_), None) => DEFAULT_ENV_SAMPLES,
    };
    let samples = environment_samples(env, sample_count);
    let mut lights = DiffractionLightsUniform {
        light_radiance: options.light.intensity * gain,
        sample_count: samples.len() as u32,
        lobe_count: env_lobe_count as u32,
        lobe_wavelength_count: lobes.spectrum.len() as u32,
        lobe_kw: lobes.kw,
        roughness: [
            rough_slope_variance(options.roughness) as f32,
            options.roughness as f32,
            (std::f64::consts::PI / (table.record().sigma_s_um * table.record().sigma_s_um)) as f32,
            0.0,
        ],
        ..DiffractionLightsUniform::zeroed()
    };
    for (k, c) in crate::ibl::irradiance_sh9(env).iter().enumerate() {
        lights.irradiance[k] =
            [c[0], c[1], c[2], 0.0].map(|x| (x * f64::from(options.env_intensity)) as f32);
    }
    for (k, (d, l)) in samples.iter().enumerate() {
        lights.samples[k] = [d[0], d[1], d[2], 0.0];
        lights.sample_radiance[k] =
            [l[0], l[1], l[2], 0.0].map(|x| x * options.env_intensity * gain);
    }
    // The light and every environment sample are diffracted, filtered over the footprint;
    // the lobes add their sum.
    let diffracted = 1 + samples.len() as u64;
    let mut technique = options.technique;
    if let DiffractionTables::Terms(t) = table
        && ctx.info.name.contains("llvmpipe")
    {
        technique.filter_radius =
            llvmpipe_filter_radius(t, &technique, diffracted, lobes.iterations())?;
    }
    let pass = ScenePass::new(ctx, table, &technique, &view, &lights, &lobes, env)?;
    pass.check_loop_cap(
        ctx,
        diffracted,
        true,
        lobes.iterations(),
        options.scene.name(),
    )?;
    let device = &ctx.device;
    let target = ctx.checked("creating the diffraction target", || {
        gpu::render_target(
            device,
            "diffraction scene",
            (width, height),
            crate::render::TARGET_FORMAT,
            true,
        )
    })?;
    let target_view = target.create_view(&Default::default());
    let start = std::time::Instant::now();
    ctx.checked("drawing the diffraction scene", || {
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut rp = gpu::begin_pass(
                &mut encoder,
                "diffraction scene",
                &[gpu::cleared_attachment(&target_view, wgpu::Color::BLACK)],
            );
            pass.draw(&mut rp);
        }
        ctx.queue.submit([encoder.finish()]);
    })?;
    ctx.wait("rendering the diffraction scene")?;
    let gpu_seconds = start.elapsed().as_secs_f64();
    let pixels = read_texture(ctx, &target, 4)?;
    Ok(RenderedImage {
        width,
        height,
        pixels,
        gpu_seconds,
    })
}
