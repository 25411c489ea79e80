//! The mesh renderer behind `nacre render --gltf`: rasterises a [`GltfScene`] with a depth
//! buffer and shades it with `shaders/material.wgsl` through `shaders/mesh.wgsl`, one
//! material uniform per primitive, the camera fitted to the scene's bounds.
//!
//! Techniques per primitive: `fourier` and `spectral` take any base (the material's index goes
//! to the shader). A `film-lut` table bakes its base, ambient and index range, so with the
//! `lut` technique a primitive is drawn with the table only when its material matches it —
//! a dielectric of the table's base index (film-dielectric: 1.5), or a gold-coloured metal
//! ([`is_gold_like`]) with a gold table (film-gold, whose baked base replaces the
//! Gulbrandsen 2014 index) — and its film index and thickness lie in the table; every other
//! primitive falls back to `fourier` (which needs the `fourier` table), and
//! [`MeshRender::notes`] says so.
//!
//! Bind groups: 0 view, 1 technique, 2 material (as the analytic scenes), 3 the mesh pass
//! (`MeshUniform`: view-projection).

use crate::bindings::TechniqueBinding;
use crate::context::BufferInitExt;
use crate::context::GpuContext;
use crate::environment::EnvironmentMap;
use crate::error::{Error, Result};
use crate::gltf_scene::{GltfScene, is_gold_like};
use crate::gpu::read_texture;
use crate::gpu::{group_layout, uniform_texture_group, upload_mips};
use crate::image_io::RenderedImage;
use crate::render::{
    BaseKind, MaterialOptions, MaterialUniform, SceneOptions, TARGET_FORMAT, ViewUniform,
    check_film_lut,
};
use crate::shaders::{self, Technique};
use crate::tables::TableSet;
use crate::thickness_map::ThicknessMap;
use bytemuck::{Pod, Zeroable};
use nacre_format::msg;
use nacre_format::param::{Msg, Piece};
use std::sync::Arc;

/// Depth buffer format.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Mirror of `MeshParams` (`shaders/mesh.wgsl`): 64 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MeshUniform {
    /// World → clip, column-major.
    pub view_proj: [[f32; 4]; 4],
}

/// A camera fitted to an axis-aligned box: eye, target, view-projection (world → clip,
/// column-major, depth in [0, 1]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FittedCamera {
    /// Eye position.
    pub eye: [f32; 3],
    /// The box centre.
    pub target: [f32; 3],
    /// World → clip.
    pub view_proj: [[f32; 4]; 4],
}

/// Largest vertical field of view of the fitted camera, degrees.
pub const FIT_FOV_Y_DEG: f64 = 30.0;

/// Largest horizontal field of view of the fitted camera, degrees.
pub const FIT_FOV_X_DEG: f64 = 40.0;

/// Fits a camera to the box (lo, hi) for an image of aspect `aspect` (width / height): it
/// looks at the box centre along −z, from slightly above (the direction (0, 0.2, 1)), with
/// the field of view of [`FIT_FOV_Y_DEG`] × [`FIT_FOV_X_DEG`] at most, at the
/// smallest distance at which every corner lies inside the frame (5 % margin); near and far
/// planes enclose the box.
pub fn fit_camera(lo: [f32; 3], hi: [f32; 3], aspect: f64) -> Result<FittedCamera> {
    let bad = |message: String| Error::Invalid {
        context: "camera".into(),
        message,
    };
    if !lo.iter().chain(&hi).all(|x| x.is_finite()) || (0..3).any(|k| lo[k] > hi[k]) {
        return Err(bad(format!("scene bounds {lo:?} – {hi:?}")));
    }
    if !(aspect > 0.0 && aspect.is_finite()) {
        return Err(bad(format!("aspect ratio {aspect}")));
    }
    let c: [f64; 3] = std::array::from_fn(|k| 0.5 * (f64::from(lo[k]) + f64::from(hi[k])));
    let extent: f64 = (0..3)
        .map(|k| f64::from(hi[k]) - f64::from(lo[k]))
        .fold(0.0, f64::max)
        .max(1e-6);
    let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let b = {
        let v = [0.0, 0.2, 1.0];
        let l = len(v);
        v.map(|x| x / l)
    };
    // Basis: back b (towards the eye), right = up × b, true up = b × right.
    let right = {
        let v = [b[2], 0.0, -b[0]];
        let l = len(v);
        v.map(|x| x / l)
    };
    let up = [
        b[1] * right[2] - b[2] * right[1],
        b[2] * right[0] - b[0] * right[2],
        b[0] * right[1] - b[1] * right[0],
    ];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    // At most FIT_FOV_Y_DEG vertically and FIT_FOV_X_DEG horizontally (a wide image gets a
    // longer lens rather than the stretched edges of a wide angle).
    let ty = (0.5 * FIT_FOV_Y_DEG.to_radians())
        .tan()
        .min((0.5 * FIT_FOV_X_DEG.to_radians()).tan() / aspect);
    let tx = ty * aspect;
    let mut distance: f64 = 0.0;
    let mut depth: f64 = 0.0;
    for corner in 0..8 {
        let p: [f64; 3] = std::array::from_fn(|k| {
            let v = if corner >> k & 1 == 1 { hi[k] } else { lo[k] };
            f64::from(v) - c[k]
        });
        let (x, y, z) = (dot(p, right), dot(p, up), dot(p, b));
        distance = distance.max(z + (x.abs() / tx).max(y.abs() / ty));
        depth = depth.max(len(p));
    }
    let distance = (distance * 1.05).max(extent * 1e-3);
    let eye: [f64; 3] = std::array::from_fn(|k| c[k] + distance * b[k]);
    let near = (distance - depth * 1.1).max(distance * 1e-3);
    let far = distance + depth * 1.1 + extent * 1e-3;
    let f = 1.0 / ty;
    let (pa, pb) = (far / (near - far), near * far / (near - far));
    // View: rows right, up, b; translation −(row · eye).
    let view = [
        [right[0], right[1], right[2], -dot(right, eye)],
        [up[0], up[1], up[2], -dot(up, eye)],
        [b[0], b[1], b[2], -dot(b, eye)],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let proj = [
        [f / aspect, 0.0, 0.0, 0.0],
        [0.0, f, 0.0, 0.0],
        [0.0, 0.0, pa, pb],
        [0.0, 0.0, -1.0, 0.0],
    ];
    let m: [[f64; 4]; 4] = std::array::from_fn(|r| {
        std::array::from_fn(|col| (0..4).map(|k| proj[r][k] * view[k][col]).sum())
    });
    Ok(FittedCamera {
        eye: eye.map(|x| x as f32),
        target: c.map(|x| x as f32),
        view_proj: std::array::from_fn(|col| std::array::from_fn(|r| m[r][col] as f32)),
    })
}

/// A rendered glTF scene and what the renderer had to approximate.
pub struct MeshRender {
    /// The image.
    pub image: RenderedImage,
    /// Notes (ignored textures, technique fallbacks), one line each; they may quote an
    /// error that names parameters (render them with a [`nacre_format::param::Naming`]).
    pub notes: Vec<Msg>,
}

fn mesh_pipeline(
    ctx: &GpuContext,
    technique: Technique,
    binding: &TechniqueBinding,
    view_layout: &wgpu::BindGroupLayout,
    material_layout: &wgpu::BindGroupLayout,
    mesh_layout: &wgpu::BindGroupLayout,
) -> Result<wgpu::RenderPipeline> {
    let device = &ctx.device;
    let source = shaders::film_pipeline(technique.module(), &["material", "mesh"])?;
    let module = shaders::create_module(ctx, "mesh", &source)?;
    ctx.checked("creating the mesh pipeline", || {
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mesh"),
            bind_group_layouts: &[
                Some(view_layout),
                Some(&binding.layout),
                Some(material_layout),
                Some(mesh_layout),
            ],
            immediate_size: 0,
        });
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("mesh"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("mesh_vs"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 32,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2],
                })],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("mesh_fs"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: TARGET_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    })
}

/// Whether the loaded `film-lut` table can draw `material` (see the module documentation);
/// a gold-like metal gets the table's base. `Err` holds the reason it cannot.
fn lut_material(
    tables: &TableSet,
    material: &MaterialOptions,
    base_colour: [f32; 3],
) -> std::result::Result<MaterialOptions, Msg> {
    let Some(lut) = &tables.film_lut else {
        return Err("no film-lut table is loaded".into());
    };
    // Errors are kept whole, so that a front end names their parameters its own way.
    let quoted = |e: Error| Msg::from_pieces(vec![Piece::Nested(Arc::new(e))]);
    let context = format!("{} (base)", lut.manifest_path.display());
    let table_base =
        nacre_format::materials::resolve(&lut.manifest.base, &context, lut.manifest_path.parent())
            .map_err(|e| quoted(e.into()))?;
    let table_kind = BaseKind::of(&table_base);
    let mut m = material.clone();
    match (material.base_kind, table_kind) {
        (BaseKind::Dielectric, BaseKind::Dielectric) => {
            let a = material
                .base
                .index_at(550.0)
                .map_err(|e| quoted(e.into()))?;
            let b = table_base.index_at(550.0).map_err(|e| quoted(e.into()))?;
            if (a - b).norm() > 1e-3 {
                return Err(format!(
                    "base index {} differs from the table `{}`'s {}",
                    a.re, lut.name, b.re
                )
                .into());
            }
        }
        (BaseKind::Metal, BaseKind::Metal) if is_gold_like(base_colour) => {
            m.base = table_base;
        }
        (BaseKind::Metal, _) => {
            return Err(format!(
                "a metal base needs a table baked on that metal (film-gold for a gold-coloured base), not `{}`",
                lut.name
            )
            .into());
        }
        _ => return Err(format!("the base differs from the table `{}`'s", lut.name).into()),
    }
    check_film_lut(tables, &m).map_err(quoted)?;
    Ok(m)
}

/// Renders `scene` with `technique` from `tables`. `options` gives the image size, the
/// environment, light, exposure and technique settings (its scene, camera, thickness map and
/// material are not used: the camera is fitted, the materials come from the file).
pub fn render_gltf(
    ctx: &GpuContext,
    tables: &TableSet,
    technique: Technique,
    scene: &GltfScene,
    options: &SceneOptions,
) -> Result<MeshRender> {
    options.validate()?;
    let environment = match &options.environment {
        Some(path) => EnvironmentMap::load(path)?,
        None => EnvironmentMap::default_map()?,
    };
    let (width, height) = (options.width, options.height);
    let limit = ctx.device.limits().max_texture_dimension_2d;
    if width.max(height) > limit {
        return Err(Error::Limit {
            what: "render target".into(),
            needed: u64::from(width.max(height)),
            limit: u64::from(limit),
            adapter: ctx.info.name.clone(),
        });
    }
    let (lo, hi) = scene.bounds();
    let camera = fit_camera(lo, hi, f64::from(width) / f64::from(height))?;
    let mut view_options = options.clone();
    view_options.camera.eye = camera.eye;
    view_options.camera.target = camera.target;
    view_options.camera.up = [0.0, 1.0, 0.0];

    // Materials: nacre's options and the technique that draws each.
    let mut notes: Vec<Msg> = scene.notes.iter().map(|n| Msg::from(n.as_str())).collect();
    let mut drawn = Vec::with_capacity(scene.materials.len());
    for gm in &scene.materials {
        let (mut m, material_notes) = gm.material_options()?;
        notes.extend(material_notes.into_iter().map(Msg::from));
        let mut t = technique;
        if technique == Technique::Lut {
            let colour = [gm.base_colour[0], gm.base_colour[1], gm.base_colour[2]];
            match lut_material(tables, &m, colour) {
                Ok(lm) => m = lm,
                Err(why) => {
                    notes.push(msg![
                        format!("{}: drawn with fourier instead of lut: ", gm.name),
                        why
                    ]);
                    t = Technique::Fourier;
                }
            }
        }
        if t == Technique::Lut {
            // The table's ambient (checked above) must be the material's.
            m.ambient_ior = tables
                .film_lut
                .as_ref()
                .map_or(1.0, |l| l.axes.ambient_index as f32);
        }
        drawn.push((m, t));
    }
    let used: Vec<usize> = {
        let mut v: Vec<usize> = scene.primitives.iter().map(|p| p.material).collect();
        v.sort_unstable();
        v.dedup();
        v
    };
    notes.retain(|n| {
        let n = n.to_string();
        used.iter()
            .any(|&i| n.starts_with(&format!("{}:", scene.materials[i].name)))
    });

    // The passes: one per technique, except film_spectral, whose group-1 samples hold the
    // base index per wavelength: one pass (binding + pipeline) per distinct base.
    let mut pass_keys: Vec<(Technique, String)> = used
        .iter()
        .map(|&i| {
            let (m, t) = &drawn[i];
            let base = if *t == Technique::Spectral {
                m.base.name().to_string()
            } else {
                String::new()
            };
            (*t, base)
        })
        .collect();
    pass_keys.sort_by(|a, b| (a.0.name(), &a.1).cmp(&(b.0.name(), &b.1)));
    pass_keys.dedup();
    let key_of = |i: usize| {
        let (m, t) = &drawn[i];
        if *t == Technique::Spectral {
            (*t, m.base.name().to_string())
        } else {
            (*t, String::new())
        }
    };
    let colorimeter = tables.colorimeter()?;
    let device = &ctx.device;
    let view_layout = crate::render::view_group_layout(device, "mesh view");
    let material_layout = group_layout(device, "mesh material");
    let mesh_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("mesh pass"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        }],
    });
    let mut pipelines = Vec::new();
    for key in &pass_keys {
        let t = key.0;
        let mut technique_options = options.technique_options();
        if let Some(&i) = used.iter().find(|&&i| key_of(i) == *key) {
            technique_options.spectral.base = drawn[i].0.base.clone();
        }
        let binding = TechniqueBinding::new(ctx, tables, t, &technique_options, &colorimeter)?;
        let pipeline = mesh_pipeline(
            ctx,
            t,
            &binding,
            &view_layout,
            &material_layout,
            &mesh_layout,
        )?;
        pipelines.push((key.clone(), binding, pipeline));
    }

    crate::render::check_film_eval(tables, options)?;
    let env = crate::render::EnvironmentTextures::new(
        ctx,
        &environment,
        options.film_eval,
        tables.rough_film_lut.as_ref(),
    )?;
    let view_uniform = ViewUniform::new(&view_options, env.env_levels)?;
    // Per material its thickness texture, or a 1×1 map of g = 1 (d = d_max) without one.
    let flat = ThicknessMap {
        width: 1,
        height: 1,
        values: vec![1.0],
        green_blue: None,
    };
    let flat_texture = upload_mips(
        ctx,
        "thickness map",
        wgpu::TextureFormat::Rg16Float,
        &flat.mip_chain(),
    )?;
    let mut thickness_textures = Vec::with_capacity(drawn.len());
    for i in 0..drawn.len() {
        thickness_textures.push(match scene.thickness_maps.get(i).and_then(Option::as_ref) {
            Some(map) if used.contains(&i) => Some(upload_mips(
                ctx,
                "thickness map",
                wgpu::TextureFormat::Rg16Float,
                &map.mip_chain(),
            )?),
            _ => None,
        });
    }
    let mut material_uniforms = Vec::with_capacity(drawn.len());
    for (m, _) in &drawn {
        let mut u = MaterialUniform::new(m, tables)?;
        u.film_eval = options.film_eval.id();
        material_uniforms.push(u);
    }
    let mesh_uniform = MeshUniform {
        view_proj: camera.view_proj,
    };

    let (target, submitted) = ctx.checked("rendering the glTF scene", || {
        let group = |layout: &wgpu::BindGroupLayout,
                     label: &str,
                     contents: &[u8],
                     texture: &wgpu::Texture,
                     repeat_v: bool| {
            uniform_texture_group(device, layout, label, contents, texture, repeat_v)
        };
        let view_group = env.bind_group(
            device,
            &view_layout,
            "mesh view",
            bytemuck::bytes_of(&view_uniform),
        );
        let material_groups: Vec<wgpu::BindGroup> = material_uniforms
            .iter()
            .zip(&thickness_textures)
            .map(|(u, t)| {
                group(
                    &material_layout,
                    "mesh material",
                    bytemuck::bytes_of(u),
                    t.as_ref().unwrap_or(&flat_texture),
                    true,
                )
            })
            .collect();
        let mesh_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mesh pass"),
            contents: bytemuck::bytes_of(&mesh_uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let mesh_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mesh pass"),
            layout: &mesh_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: mesh_buffer.as_entire_binding(),
            }],
        });
        let geometry: Vec<(wgpu::Buffer, wgpu::Buffer, u32, usize)> = scene
            .primitives
            .iter()
            .filter(|p| !p.indices.is_empty())
            .map(|p| {
                let vertices: Vec<f32> = p
                    .positions
                    .iter()
                    .zip(&p.normals)
                    .zip(&p.uvs)
                    .flat_map(|((x, n), t)| [x[0], x[1], x[2], n[0], n[1], n[2], t[0], t[1]])
                    .collect();
                let vb = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("mesh vertices"),
                    contents: bytemuck::cast_slice(&vertices),
                    usage: wgpu::BufferUsages::VERTEX,
                });
                let ib = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("mesh indices"),
                    contents: bytemuck::cast_slice(&p.indices),
                    usage: wgpu::BufferUsages::INDEX,
                });
                (vb, ib, p.indices.len() as u32, p.material)
            })
            .collect();
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let extent = (size.width, size.height);
        let target = crate::gpu::render_target(device, "mesh target", extent, TARGET_FORMAT, true);
        let depth = crate::gpu::render_target(device, "mesh depth", extent, DEPTH_FORMAT, false);
        let target_view = target.create_view(&Default::default());
        let depth_view = depth.create_view(&Default::default());
        // The background: the environment seen by the fitted camera is not drawn (a clear
        // colour keeps the spheres' silhouettes readable); black.
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("mesh"),
                color_attachments: &[crate::gpu::cleared_attachment(
                    &target_view,
                    wgpu::Color {
                        r: 0.18,
                        g: 0.18,
                        b: 0.2,
                        a: 1.0,
                    },
                )],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &view_group, &[]);
            pass.set_bind_group(3, &mesh_group, &[]);
            for (key, binding, pipeline) in &pipelines {
                pass.set_pipeline(pipeline);
                pass.set_bind_group(1, &binding.bind_group, &[]);
                for (vb, ib, count, material) in &geometry {
                    if key_of(*material) != *key {
                        continue;
                    }
                    pass.set_bind_group(2, &material_groups[*material], &[]);
                    pass.set_vertex_buffer(0, vb.slice(..));
                    pass.set_index_buffer(ib.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..*count, 0, 0..1);
                }
            }
        }
        let _ = device.poll(wgpu::PollType::wait_indefinitely());
        let submitted = std::time::Instant::now();
        ctx.queue.submit([encoder.finish()]);
        (target, submitted)
    })?;
    ctx.wait("rendering the glTF scene")?;
    let gpu_seconds = submitted.elapsed().as_secs_f64();
    let mut pixels = read_texture(ctx, &target, 4)?;
    for p in pixels.chunks_exact_mut(4) {
        p[3] = 255;
    }
    Ok(MeshRender {
        image: RenderedImage {
            width,
            height,
            pixels,
            gpu_seconds,
        },
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitted_camera_frames_every_corner() {
        let (lo, hi) = ([-5.0, -1.0, -1.0], [5.0, 1.0, 1.0]);
        let cam = fit_camera(lo, hi, 4.0).unwrap();
        let m = cam.view_proj;
        for corner in 0..8 {
            let p: [f32; 3] =
                std::array::from_fn(|k| if corner >> k & 1 == 1 { hi[k] } else { lo[k] });
            let clip: [f32; 4] =
                std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r]);
            let ndc = [clip[0] / clip[3], clip[1] / clip[3], clip[2] / clip[3]];
            assert!(ndc[0].abs() <= 1.0 && ndc[1].abs() <= 1.0, "{ndc:?}");
            assert!((0.0..=1.0).contains(&ndc[2]), "{ndc:?}");
        }
        assert!(fit_camera([0.0; 3], [f32::NAN; 3], 1.0).is_err());
    }
}
