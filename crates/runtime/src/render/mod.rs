//! The headless scene renderer behind `nacre render`: analytic scenes (a film-coated sphere,
//! a soap bubble, an oil film on a plane) ray-cast in a fragment shader, shaded by the
//! thin-film microfacet material of `shaders/material.wgsl` with any technique, lit by a
//! directional light and an equirectangular HDR environment, tone-mapped and read back as
//! sRGB-encoded RGBA8 pixels.
//!
//! Bind groups (`shaders/README.md`): 0 = the view ([`ViewUniform`], the environment, its
//! GGX-prefiltered layers, the E₁ table and the `rough-film-lut` of the split-sum paths:
//! [`FilmEval`], [`crate::ibl`]), 1 = the technique's tables ([`TechniqueBinding`]), 2 = the material
//! ([`MaterialUniform`], the thickness map and its sampler). The pipeline's source is
//! `shaders::film_pipeline(technique.module(), &["material", "scene"])` (= `shaders::compose(technique,
//! &[MATERIAL, SCENE])`).
//!
//! CPU-side inputs:
//!
//! * the environment ([`EnvironmentMap`], `environment.rs`): an OpenEXR equirectangular image (row 0 = the
//!   zenith, u = 0.5 looks down −z), or the default `tables/env/studio.exr`, which is
//!   [`procedural_environment`]`(256, 128)` written once in half floats (project-made, CC0;
//!   `tables/env/README.md`). Uploaded as `Rgba16Float` with a full mip chain of 2×2 box
//!   filters built here;
//! * the thickness map ([`ThicknessMap`], `thickness_map.rs`): an 8- or 16-bit greyscale PNG, or
//!   [`procedural_thickness_map`]. Uploaded as `Rgba16Float` holding (g, g², g_G, g_B) with a
//!   full mip chain, so that the shader can recover the thickness variance that filtering
//!   removed; g_G and g_B (a colour map's, or the built-in map's, channels G and B) move the
//!   lower films of `film_stack` that follow them.
//!
//! ```no_run
//! use nacre_runtime::render::{SceneKind, SceneOptions, render_scene};
//! use nacre_runtime::{GpuContext, TableSet, Technique};
//! # fn main() -> nacre_runtime::Result<()> {
//! let ctx = GpuContext::new_headless()?;
//! let mut tables = TableSet::load(&ctx, "tables/baked/film-dielectric.json".as_ref())?;
//! tables.add(&ctx, "tables/baked/fourier-srgb.json".as_ref())?;
//! let mut options = SceneOptions::new(SceneKind::Sphere);
//! options.fit_to_tables(&tables)?;
//! let image = render_scene(&ctx, &tables, Technique::Fourier, &options)?;
//! image.write_png("sphere.png".as_ref())?;
//! # Ok(()) }
//! ```
//!
//! Files: `options.rs` (the scene, the camera, the light, the material: [`SceneOptions`]),
//! `view.rs` (group 0: [`ViewUniform`], the environment's textures, the target formats),
//! this file (the [`Renderer`]); the wgpu helpers are in [`crate::gpu`], the CPU images in
//! [`crate::environment`], [`crate::thickness_map`] and [`crate::image_io`].

use crate::bindings::{TechniqueBinding, TechniqueOptions};
use crate::context::GpuContext;
use crate::error::{Error, Result, TableMismatch};
use crate::gpu::check_limit;
use crate::gpu::{
    begin_pass, cleared_attachment, fullscreen_pipeline, group_layout, read_texture, render_target,
    uniform_texture_group, upload_mips,
};
use crate::shaders::{self, Technique};
use crate::tables::TableSet;
use std::path::Path;

mod options;
mod view;

pub use crate::environment::{
    DEFAULT_ENVIRONMENT_SIZE, EnvironmentMap, SUN_DIRECTION, default_environment_path,
    procedural_environment, procedural_environment_with,
};
use crate::image_io::check_image_size;
pub use crate::image_io::{Level, MAX_DIMENSION, RenderedImage};
pub use crate::thickness_map::{
    DEFAULT_THICKNESS_MAP_SIZE, ThicknessMap, procedural_thickness_map,
};
pub use options::{
    BaseKind, Camera, FilmEval, Light, MAX_PUNCTUAL_LIGHTS, MaterialOptions, MaterialUniform,
    PunctualKind, PunctualLight, SceneKind, SceneOptions, ThicknessMapping,
};
pub(crate) use view::EnvironmentTextures;
pub use view::{
    LINEAR_TARGET_FORMAT, LightUniform, RenderOutput, RoughLutUniform, TARGET_FORMAT, ViewUniform,
    view_group_layout,
};

/// A technique's scene pipeline: group-1 tables, group-0/2 layouts, the render pipeline.
pub struct Renderer {
    technique: Technique,
    output: RenderOutput,
    binding: TechniqueBinding,
    view_layout: wgpu::BindGroupLayout,
    material_layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

impl Renderer {
    /// Compiles the scene pipeline of `technique` (`shaders::film_pipeline(technique.module(),
    /// &["material", "scene"])`) and builds its group-1 tables from `tables` with `options`.
    pub fn new(
        ctx: &GpuContext,
        tables: &TableSet,
        technique: Technique,
        options: &TechniqueOptions,
    ) -> Result<Renderer> {
        Renderer::new_with_output(ctx, tables, technique, options, RenderOutput::Display)
    }

    /// [`Renderer::new`] writing `output`: display pixels (`scene_fs`, [`TARGET_FORMAT`]) or
    /// linear radiance (`scene_fs_linear`, [`LINEAR_TARGET_FORMAT`]; read it with
    /// [`Renderer::render_linear_with`]).
    pub fn new_with_output(
        ctx: &GpuContext,
        tables: &TableSet,
        technique: Technique,
        options: &TechniqueOptions,
        output: RenderOutput,
    ) -> Result<Renderer> {
        let (entry_point, format) = match output {
            RenderOutput::Display => ("scene_fs", TARGET_FORMAT),
            RenderOutput::Linear => ("scene_fs_linear", LINEAR_TARGET_FORMAT),
        };
        let colorimeter = tables.colorimeter()?;
        let binding = TechniqueBinding::new(ctx, tables, technique, options, &colorimeter)?;
        let device = &ctx.device;
        let source = shaders::film_pipeline(technique.module(), &["material", "scene"])?;
        let module = shaders::create_module(ctx, "scene", &source)?;
        let (view_layout, material_layout, pipeline) =
            ctx.checked("creating the scene pipeline", || {
                let view_layout = view_group_layout(device, "scene view");
                let material_layout = group_layout(device, "scene material");
                let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("scene"),
                    bind_group_layouts: &[
                        Some(&view_layout),
                        Some(&binding.layout),
                        Some(&material_layout),
                    ],
                    immediate_size: 0,
                });
                let pipeline = fullscreen_pipeline(
                    device,
                    "scene",
                    &module,
                    &layout,
                    ("scene_vs", entry_point),
                    &[format],
                );
                (view_layout, material_layout, pipeline)
            })?;
        Ok(Renderer {
            technique,
            output,
            binding,
            view_layout,
            material_layout,
            pipeline,
        })
    }

    /// The technique.
    pub fn technique(&self) -> Technique {
        self.technique
    }

    /// Rebuilds the technique's group 1 (its tables' bind group and its buffers: the stack
    /// of `film_stack`, the base of `film_spectral`) for new `options`, keeping the compiled
    /// pipeline: the group's layout depends on the technique alone
    /// ([`crate::bindings::table_layout`]), so an edited stack costs an upload, not a shader
    /// compilation (the studio's sliders).
    pub fn rebind(
        &mut self,
        ctx: &GpuContext,
        tables: &TableSet,
        options: &TechniqueOptions,
    ) -> Result<()> {
        let colorimeter = tables.colorimeter()?;
        self.binding = TechniqueBinding::new(ctx, tables, self.technique, options, &colorimeter)?;
        Ok(())
    }

    /// Renders `options`, loading its environment and thickness map.
    pub fn render(
        &self,
        ctx: &GpuContext,
        tables: &TableSet,
        options: &SceneOptions,
    ) -> Result<RenderedImage> {
        options.validate()?;
        let environment = match &options.environment {
            Some(path) => EnvironmentMap::load(path)?,
            None => EnvironmentMap::default_map()?,
        };
        let thickness = match &options.thickness_map {
            Some(path) => ThicknessMap::load_for(path, self.technique)?,
            None => procedural_thickness_map(DEFAULT_THICKNESS_MAP_SIZE),
        };
        self.render_with(ctx, tables, options, &environment, &thickness)
    }

    /// Renders `options` with an environment and a thickness map already in memory
    /// (`options.environment` and `options.thickness_map` are not read). Needs a renderer
    /// made for [`RenderOutput::Display`].
    pub fn render_with(
        &self,
        ctx: &GpuContext,
        tables: &TableSet,
        options: &SceneOptions,
        environment: &EnvironmentMap,
        thickness: &ThicknessMap,
    ) -> Result<RenderedImage> {
        if self.output != RenderOutput::Display {
            return Err(Error::WrongOutput {
                writes: "linear radiance",
                call: "render_linear_with",
            });
        }
        let (target, gpu_seconds) = self.draw(ctx, tables, options, environment, thickness)?;
        let mut pixels = read_texture(ctx, &target, 4)?;
        for p in pixels.chunks_exact_mut(4) {
            p[3] = 255;
        }
        Ok(RenderedImage {
            width: options.width,
            height: options.height,
            pixels,
            gpu_seconds,
        })
    }

    /// Renders the linear scene radiance of `options` (before exposure and tone mapping)
    /// with an environment and a thickness map in memory. Needs a renderer made for
    /// [`RenderOutput::Linear`].
    pub fn render_linear_with(
        &self,
        ctx: &GpuContext,
        tables: &TableSet,
        options: &SceneOptions,
        environment: &EnvironmentMap,
        thickness: &ThicknessMap,
    ) -> Result<LinearImage> {
        if self.output != RenderOutput::Linear {
            return Err(Error::WrongOutput {
                writes: "display pixels",
                call: "render_with",
            });
        }
        let (target, gpu_seconds) = self.draw(ctx, tables, options, environment, thickness)?;
        let bytes = read_texture(ctx, &target, 16)?;
        let floats: &[f32] = bytemuck::cast_slice(&bytes);
        Ok(LinearImage {
            width: options.width,
            height: options.height,
            rgb: floats.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect(),
            gpu_seconds,
        })
    }

    /// Draws `options` into a new target of the renderer's output format; returns it and the
    /// seconds from submission to completion.
    fn draw(
        &self,
        ctx: &GpuContext,
        tables: &TableSet,
        options: &SceneOptions,
        environment: &EnvironmentMap,
        thickness: &ThicknessMap,
    ) -> Result<(wgpu::Texture, f64)> {
        options.validate()?;
        for (what, w, h, n) in [
            (
                "environment",
                environment.width,
                environment.height,
                environment.rgb.len(),
            ),
            (
                "thickness map",
                thickness.width,
                thickness.height,
                thickness.values.len(),
            ),
        ] {
            check_image_size(Path::new(what), what, w, h)?;
            if n != w * h {
                return Err(Error::TexelCount {
                    what,
                    texels: n,
                    width: w,
                    height: h,
                });
            }
        }
        if self.technique == Technique::Lut {
            check_film_lut(tables, &options.material)?;
        }
        check_film_eval(tables, options)?;
        let (width, height) = (options.width, options.height);
        check_limit(
            ctx,
            "render target",
            u64::from(width.max(height)),
            ctx.device.limits().max_texture_dimension_2d,
        )?;
        let env = EnvironmentTextures::new(
            ctx,
            environment,
            options.film_eval,
            tables.rough_film_lut.as_ref(),
        )?;
        let view_uniform = ViewUniform::new(options, env.env_levels)?;
        let mut material_uniform = MaterialUniform::new(&options.material, tables)?;
        material_uniform.film_eval = options.film_eval.id();
        let thickness_texture = upload_mips(
            ctx,
            "thickness map",
            wgpu::TextureFormat::Rgba16Float,
            &thickness.stack_mip_chain(),
        )?;
        let device = &ctx.device;
        let (target, submitted) = ctx.checked("rendering the scene", || {
            let group = |layout: &wgpu::BindGroupLayout,
                         label: &str,
                         contents: &[u8],
                         texture: &wgpu::Texture,
                         repeat_v: bool| {
                uniform_texture_group(device, layout, label, contents, texture, repeat_v)
            };
            let view_group = env.bind_group(
                device,
                &self.view_layout,
                "scene view",
                bytemuck::bytes_of(&view_uniform),
            );
            let material_group = group(
                &self.material_layout,
                "scene material",
                bytemuck::bytes_of(&material_uniform),
                &thickness_texture,
                true,
            );
            let format = match self.output {
                RenderOutput::Display => TARGET_FORMAT,
                RenderOutput::Linear => LINEAR_TARGET_FORMAT,
            };
            let target = render_target(device, "scene target", (width, height), format, true);
            let target_view = target.create_view(&Default::default());
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = begin_pass(
                    &mut encoder,
                    "scene",
                    &[cleared_attachment(&target_view, wgpu::Color::BLACK)],
                );
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &view_group, &[]);
                pass.set_bind_group(1, &self.binding.bind_group, &[]);
                pass.set_bind_group(2, &material_group, &[]);
                pass.draw(0..3, 0..1);
            }
            // Let the uploads finish first, so that the time measured is the pass's (a lost
            // device or a hung queue is an error, as in every other wait).
            ctx.wait("waiting for the scene's uploads")?;
            let submitted = std::time::Instant::now();
            ctx.queue.submit([encoder.finish()]);
            Result::Ok((target, submitted))
        })??;
        ctx.wait("rendering the scene")?;
        Ok((target, submitted.elapsed().as_secs_f64()))
    }
}

/// Linear scene radiance read back from a [`RenderOutput::Linear`] render.
#[derive(Clone, Debug)]
pub struct LinearImage {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Linear RGB radiance (the tables' output space), row-major, top row first.
    pub rgb: Vec<[f32; 3]>,
    /// As [`RenderedImage::gpu_seconds`].
    pub gpu_seconds: f64,
}

/// Checks that the tables can render `options.film_eval`: the exact path needs a
/// `rough-film-lut` whose ambient matches and whose ranges hold the material.
pub(crate) fn check_film_eval(tables: &TableSet, options: &SceneOptions) -> Result<()> {
    if options.film_eval != FilmEval::Exact {
        return Ok(());
    }
    let Some(lut) = &tables.rough_film_lut else {
        return Err(Error::MissingTable {
            needed_by: "film evaluation `exact`".into(),
            kind: "rough-film-lut",
            example: Some("rough-film-dielectric"),
        });
    };
    let a = &lut.axes;
    let context = format!("rough-film-lut `{}`", lut.name);
    check_material_in_table(
        &context,
        &options.material,
        a.ambient_index,
        [a.ior_min, a.ior_max],
        a.thickness_max_nm,
    )
}

/// Checks that a table baked for `ambient_index`, film indices `film_ior` = [min, max] and
/// thicknesses up to `thickness_max_nm` holds `material` (its ambient, film index and
/// thickest point), naming the table (`context`) and the value out of range.
fn check_material_in_table(
    context: &str,
    material: &MaterialOptions,
    ambient_index: f64,
    [ior_min, ior_max]: [f64; 2],
    thickness_max_nm: f64,
) -> Result<()> {
    let tol = 1e-4;
    let invalid = |mismatch: TableMismatch| {
        Err(Error::TableRange {
            table: context.to_string(),
            mismatch,
        })
    };
    if (f64::from(material.ambient_ior) - ambient_index).abs() > tol {
        return invalid(TableMismatch::Ambient {
            table: ambient_index,
            material: f64::from(material.ambient_ior),
        });
    }
    let n = f64::from(material.film_ior);
    if n < ior_min - tol || n > ior_max + tol {
        return invalid(TableMismatch::FilmIndex {
            index: n,
            range: [ior_min, ior_max],
        });
    }
    let d = f64::from(material.max_thickness_nm());
    if d > thickness_max_nm * (1.0 + tol) {
        return invalid(TableMismatch::Thickness {
            thickness_nm: d,
            max_nm: thickness_max_nm,
        });
    }
    Ok(())
}

/// Checks that a `film-lut` table can render `material`: the table exists, its ambient is
/// the material's, the film index and the thicknesses lie inside the table, and a
/// transmitting material has a table with a transmittance.
pub(crate) fn check_film_lut(tables: &TableSet, material: &MaterialOptions) -> Result<()> {
    let Some(lut) = &tables.film_lut else {
        return Err(Error::MissingTable {
            needed_by: "technique `lut`".into(),
            kind: "film-lut",
            example: None,
        });
    };
    let a = &lut.axes;
    let context = format!("film-lut `{}`", lut.name);
    check_material_in_table(
        &context,
        material,
        a.ambient_index,
        [a.ior_min, a.ior_max],
        a.thickness_max_nm,
    )?;
    if material.transmission && !lut.has_transmittance {
        return Err(Error::TableRange {
            table: context,
            mismatch: TableMismatch::NoTransmittance,
        });
    }
    Ok(())
}

/// Renders `options` with `technique` from `tables`: [`Renderer::new`] with
/// [`SceneOptions::technique_options`], then [`Renderer::render`].
pub fn render_scene(
    ctx: &GpuContext,
    tables: &TableSet,
    technique: Technique,
    options: &SceneOptions,
) -> Result<RenderedImage> {
    options.validate()?;
    let renderer = Renderer::new(ctx, tables, technique, &options.technique_options())?;
    renderer.render(ctx, tables, options)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_sizes_match_the_wgsl_layouts() {
        assert_eq!(std::mem::size_of::<ViewUniform>(), 656);
        assert_eq!(std::mem::size_of::<LightUniform>(), 64);
        assert_eq!(std::mem::offset_of!(ViewUniform, light_count), 128);
        assert_eq!(std::mem::offset_of!(ViewUniform, lights), 144);
        assert_eq!(std::mem::size_of::<MaterialUniform>(), 96);
        assert_eq!(std::mem::offset_of!(MaterialUniform, film_weight), 80);
        assert_eq!(std::mem::offset_of!(MaterialUniform, base_ior), 32);
        assert_eq!(std::mem::offset_of!(MaterialUniform, base_kappa), 48);
        assert_eq!(std::mem::offset_of!(MaterialUniform, base_colour), 64);
        assert_eq!(std::mem::offset_of!(ViewUniform, eye_position), 64);
        assert_eq!(std::mem::offset_of!(ViewUniform, resolution), 112);
    }

    #[test]
    fn procedural_images_are_finite_and_in_range() {
        let env = procedural_environment(64, 32);
        assert!(
            env.rgb
                .iter()
                .flatten()
                .all(|v| v.is_finite() && *v >= 0.0 && *v < 65504.0)
        );
        let map = procedural_thickness_map(64);
        assert!(map.values.iter().all(|v| (0.0..=1.0).contains(v)));
        // Tileable: the first and the last column differ as little as neighbours do.
        let step = |a: usize, b: usize| (map.values[a] - map.values[b]).abs();
        let wrap: f32 = (0..64)
            .map(|y| step(y * 64, y * 64 + 63))
            .fold(0.0, f32::max);
        let inner: f32 = (0..64)
            .map(|y| step(y * 64, y * 64 + 1))
            .fold(0.0, f32::max);
        assert!(wrap <= 2.0 * inner + 1e-3, "{wrap} vs {inner}");
    }

    #[test]
    fn film_eval_names_parse_and_uniform_layouts_hold() {
        for k in FilmEval::ALL {
            assert_eq!(k.name().parse::<FilmEval>().unwrap(), k);
        }
        assert!("fresnel".parse::<FilmEval>().is_err());
        assert!(!FilmEval::Classic.split_sum() && FilmEval::Exact.split_sum());
        assert_eq!(std::mem::offset_of!(MaterialUniform, film_eval), 84);
        assert_eq!(std::mem::size_of::<RoughLutUniform>(), 48);
        assert_eq!(std::mem::offset_of!(RoughLutUniform, has_transmittance), 40);
    }

    #[test]
    fn exact_path_needs_a_rough_table() {
        let mut o = SceneOptions::new(SceneKind::Sphere);
        o.film_eval = FilmEval::Exact;
        assert!(check_film_eval(&TableSet::default(), &o).is_err());
        o.film_eval = FilmEval::NormalView;
        assert!(check_film_eval(&TableSet::default(), &o).is_ok());
    }
}
