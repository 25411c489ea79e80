//! The mesh renderer behind `nacre render --gltf`: rasterises a [`GltfScene`] with a depth
//! buffer and shades it with `shaders/material.wgsl` through `shaders/mesh.wgsl`, one
//! material uniform per primitive, the camera fitted to the scene's bounds.
//!
//! Techniques per primitive: `fourier` and `spectral` take any base (the material's index goes
//! to the shader). A `film-lut` table bakes its base, ambient and index range, so with the
//! `lut` technique a primitive is drawn with the table only when its material matches it —
//! a dielectric of the table's base index (film-dielectric: 1.5), or a gold-coloured metal
//! ([`crate::gltf_scene::is_gold_like`]) with a gold table (film-gold, whose baked base replaces the
//! Gulbrandsen 2014 index) — and its film index and thickness lie in the table; every other
//! primitive falls back to `fourier` (which needs the `fourier` table), and
//! [`MeshRender::notes`] says so.
//!
//! Bind groups: 0 view, 1 technique, 2 material (as the analytic scenes), 3 the mesh pass
//! (`MeshUniform`: view-projection).
//!
//! Files: `camera.rs` (orbit and file cameras), `lights.rs` (`KHR_lights_punctual`),
//! `materials.rs` (the technique of each material), `pipeline.rs` (the passes and their
//! pipelines), `textures.rs` (glTF textures, samplers and group 3); this file holds the
//! uniform and the frame ([`render_gltf_from`]).

mod camera;
mod lights;
mod materials;
mod pipeline;
mod textures;

pub use camera::{
    DEFAULT_PITCH_DEG, FIT_FOV_X_DEG, FIT_FOV_Y_DEG, FittedCamera, Orbit, ViewPoint, file_camera,
    fit_camera, orbit_camera, view_camera,
};
pub use lights::scene_lights;
pub use textures::rgba8_mip_chain;

use crate::context::BufferInitExt;
use crate::context::GpuContext;
use crate::environment::EnvironmentMap;
use crate::error::Result;
use crate::gltf_scene::{
    AlphaMode, GltfMaterial, GltfPrimitive, GltfScene, IDENTITY_TRANSFORM, TextureRef,
};
use crate::gpu::read_texture;
use crate::gpu::{group_layout, uniform_texture_group, upload_mips};
use crate::image_io::RenderedImage;
use crate::render::{MaterialUniform, SceneOptions, TARGET_FORMAT, ViewUniform};
use crate::shaders::Technique;
use crate::tables::{TableSet, check_limit};
use crate::thickness_map::ThicknessMap;
use bytemuck::{Pod, Zeroable};
use camera::view_depth;
use nacre_format::param::Msg;
use pipeline::{Passes, PipelineState, transmits};
use textures::{GltfTextures, MipDown, mesh_group_layout};

/// Depth buffer format.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Mirror of `MeshParams` (`shaders/mesh.wgsl`): 464 bytes, one per drawn material.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MeshUniform {
    /// World → clip, column-major.
    pub view_proj: [[f32; 4]; 4],
    /// `baseColorFactor`, linear RGBA.
    pub base_colour: [f32; 4],
    /// `emissiveFactor` × `emissiveStrength`.
    pub emissive: [f32; 3],
    /// `metallicFactor`.
    pub metallic: f32,
    /// `specularColorFactor`.
    pub specular_colour: [f32; 3],
    /// `roughnessFactor`.
    pub roughness: f32,
    /// `specularFactor`.
    pub specular: f32,
    /// `normalTexture.scale`.
    pub normal_scale: f32,
    /// `occlusionTexture.strength`.
    pub occlusion_strength: f32,
    /// `alphaCutoff`.
    pub alpha_cutoff: f32,
    /// `ior`.
    pub dielectric_ior: f32,
    /// `iridescenceFactor`.
    pub iridescence: f32,
    /// 0 OPAQUE, 1 MASK, 2 BLEND.
    pub alpha_mode: u32,
    /// Bit 0: a normal texture is bound; [`FLAG_LINEAR_OUTPUT`], [`FLAG_BEHIND`].
    pub flags: u32,
    /// `transmissionFactor`.
    pub transmission: f32,
    /// The lobes every fragment evaluates: 0 dielectric, 1 metal, 2 both.
    pub lobes: u32,
    /// `KHR_materials_volume` `thicknessFactor` (0: thin-walled).
    pub volume_thickness: f32,
    /// `attenuationDistance` (0: no attenuation).
    pub attenuation_distance: f32,
    /// `attenuationColor` (rgb; w unused).
    pub attenuation_colour: [f32; 4],
    /// Per texture slot ([`TEXTURE_SLOTS`] and the thickness texture): rows (a, b, c, set),
    /// (d, e, f, 0) of its `KHR_texture_transform`.
    pub transforms: [[[f32; 4]; 2]; 9],
}

/// [`MeshUniform::flags`]: the draw writes linear radiance (the scene behind transmissive
/// surfaces) instead of display colour (`shaders/mesh.wgsl` MESH_FLAG_LINEAR_OUTPUT).
pub const FLAG_LINEAR_OUTPUT: u32 = 2;

/// [`MeshUniform::flags`]: binding 17 holds the opaque scene's linear radiance
/// (`shaders/mesh.wgsl` MESH_FLAG_BEHIND).
pub const FLAG_BEHIND: u32 = 4;

/// Format of the picture of the opaque scene that transmissive surfaces refract.
pub const BEHIND_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The texture slots of group 3 (`shaders/mesh.wgsl` MESH_TEX_*), in binding order.
pub const TEXTURE_SLOTS: [&str; 8] = [
    "baseColorTexture",
    "metallicRoughnessTexture",
    "normalTexture",
    "occlusionTexture",
    "emissiveTexture",
    "iridescenceTexture",
    "specularTexture",
    "specularColorTexture",
];

impl MeshUniform {
    /// The uniform of glTF material `m` seen through `view_proj`.
    pub fn new(view_proj: [[f32; 4]; 4], m: &GltfMaterial) -> MeshUniform {
        let t = &m.textures;
        let in_order = textures::slots_of(m);
        let slots: [Option<TextureRef>; 9] =
            std::array::from_fn(|k| in_order.get(k).copied().unwrap_or(t.thickness));
        let transforms = slots.map(|slot| {
            let r = slot.unwrap_or(TextureRef {
                texture: 0,
                tex_coord: 0,
                transform: IDENTITY_TRANSFORM,
            });
            let [a, b] = r.transform;
            [
                [a[0], a[1], a[2], r.tex_coord as f32],
                [b[0], b[1], b[2], 0.0],
            ]
        });
        let (alpha_mode, alpha_cutoff) = match m.alpha_mode {
            AlphaMode::Opaque => (0, 0.5),
            AlphaMode::Mask(c) => (1, c),
            AlphaMode::Blend => (2, 0.5),
        };
        MeshUniform {
            view_proj,
            base_colour: m.base_colour,
            emissive: m.emissive,
            metallic: m.metallic,
            specular_colour: m.specular_colour,
            roughness: m.roughness,
            specular: m.specular,
            normal_scale: m.normal_scale,
            occlusion_strength: m.occlusion_strength,
            alpha_cutoff,
            dielectric_ior: m.dielectric_ior(),
            iridescence: m.iridescence.map_or(0.0, |i| i.factor),
            alpha_mode,
            flags: u32::from(t.normal.is_some()),
            transmission: m.transmission,
            lobes: match m.metallic_range() {
                (_, hi) if hi <= 0.0 => 0,
                (lo, _) if lo >= 1.0 => 1,
                _ => 2,
            },
            volume_thickness: m.volume.map_or(0.0, |v| v.thickness),
            attenuation_distance: m.volume.map_or(0.0, |v| {
                if v.attenuation_distance.is_finite() {
                    v.attenuation_distance
                } else {
                    0.0
                }
            }),
            attenuation_colour: m.volume.map_or([1.0; 4], |v| {
                let [r, g, b] = v.attenuation_colour;
                [r, g, b, 1.0]
            }),
            transforms,
        }
    }
}

/// A rendered glTF scene and what the renderer had to approximate.
pub struct MeshRender {
    /// The image.
    pub image: RenderedImage,
    /// Notes (ignored textures, technique fallbacks), one line each; they may quote an
    /// error that names parameters (render them with a [`nacre_format::param::Naming`]).
    pub notes: Vec<Msg>,
}

/// Floats per vertex: position 3, normal 3, tangent 4, TEXCOORD_0 2, TEXCOORD_1 2, COLOR_0 4.
pub const VERTEX_FLOATS: usize = 18;

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
    render_gltf_from(ctx, tables, technique, scene, options, ViewPoint::default())
}

/// [`render_gltf`] seen from `view`: an orbit camera around the scene's bounds or one of the
/// file's cameras (an index past the last is an error naming how many the file has).
pub fn render_gltf_from(
    ctx: &GpuContext,
    tables: &TableSet,
    technique: Technique,
    scene: &GltfScene,
    options: &SceneOptions,
    view: ViewPoint,
) -> Result<MeshRender> {
    options.validate()?;
    let environment = match &options.environment {
        Some(path) => EnvironmentMap::load(path)?,
        None => EnvironmentMap::default_map()?,
    };
    let (width, height) = (options.width, options.height);
    check_limit(
        ctx,
        "render target",
        u64::from(width.max(height)),
        ctx.device.limits().max_texture_dimension_2d,
    )?;
    let camera = view_camera(scene, view, f64::from(width) / f64::from(height))?;
    let mut view_options = options.clone();
    view_options.camera.eye = camera.eye;
    view_options.camera.target = camera.target;
    view_options.camera.up = camera.up;
    view_options.camera.fov_y_deg = camera.fov_y_deg;
    let (light, punctual_lights, light_note) = scene_lights(scene);
    view_options.light = light;
    view_options.punctual_lights = punctual_lights;

    // Materials: nacre's options and the technique that draws each.
    let colorimeter = tables.colorimeter()?;
    let used: Vec<usize> = {
        let mut v: Vec<usize> = scene.primitives.iter().map(|p| p.material).collect();
        v.sort_unstable();
        v.dedup();
        v
    };
    let used_name = |n: &str| {
        // A note about a material names it first (`name: …`); other notes are kept.
        let about = |i: usize| n.starts_with(&format!("{}:", scene.materials[i].name));
        !(0..scene.materials.len()).any(about) || used.iter().any(|&i| about(i))
    };
    let mut notes: Vec<Msg> = scene
        .notes
        .iter()
        .filter(|n| used_name(n))
        .map(|n| Msg::from(n.as_str()))
        .collect();
    let choice = materials::choose(scene, tables, technique, &colorimeter, &used)?;
    notes.extend(choice.notes);
    let drawn = choice.drawn;
    if let Some(note) = light_note {
        notes.push(Msg::from(note));
    }
    if let Some(note) = choice.fallback_note {
        notes.push(note);
    }

    let device = &ctx.device;
    let view_layout = crate::render::view_group_layout(device, "mesh view");
    let material_layout = group_layout(device, "mesh material");
    let mesh_layout = mesh_group_layout(device);
    let passes = Passes::new(
        ctx,
        tables,
        &options.technique_options(),
        &colorimeter,
        scene,
        &drawn,
        &used,
        [&view_layout, &material_layout, &mesh_layout],
    )?;
    let behind_needed = passes.behind_needed;
    let state_of = |i: usize| PipelineState::of(&scene.materials[i]);
    let transmissive = |i: usize| transmits(&scene.materials[i]);
    let pass_of = |i: usize| passes.pass_of[i];

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
    let textures = GltfTextures::upload(ctx, scene, &used)?;

    let mip_down = if behind_needed {
        Some(MipDown::new(ctx)?)
    } else {
        None
    };
    let (target, submitted) = ctx.checked("rendering the glTF scene", || {
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
                uniform_texture_group(
                    device,
                    &material_layout,
                    "mesh material",
                    bytemuck::bytes_of(u),
                    t.as_ref().unwrap_or(&flat_texture),
                    true,
                )
            })
            .collect();
        // Group 3 per used material: its MeshUniform (with `extra_flags`), textures and
        // samplers, and the picture of the scene behind.
        let samplers = textures.samplers(device, scene, &used);
        let mesh_groups_with = |extra_flags: u32, behind: &wgpu::TextureView| {
            let mut mesh_groups: Vec<Option<wgpu::BindGroup>> = Vec::new();
            for (i, gm) in scene.materials.iter().enumerate() {
                if !used.contains(&i) {
                    mesh_groups.push(None);
                    continue;
                }
                let mut uniform = MeshUniform::new(camera.view_proj, gm);
                uniform.flags |= extra_flags;
                let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("mesh material (glTF)"),
                    contents: bytemuck::bytes_of(&uniform),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
                mesh_groups.push(Some(textures.mesh_group(
                    device,
                    &mesh_layout,
                    scene,
                    gm,
                    &samplers,
                    &buffer,
                    behind,
                )));
            }
            mesh_groups
        };
        let geometry: Vec<(wgpu::Buffer, wgpu::Buffer, u32, usize, f64)> = scene
            .primitives
            .iter()
            .filter(|p| !p.indices.is_empty())
            .map(|p| {
                let vertices = vertex_data(p);
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
                (
                    vb,
                    ib,
                    p.indices.len() as u32,
                    p.material,
                    view_depth(&camera, p),
                )
            })
            .collect();
        // Draw order: opaque and masked primitives by pass, then blended ones back to front.
        let mut order: Vec<usize> = (0..geometry.len()).collect();
        order.sort_by(|&a, &b| {
            let (ma, mb) = (geometry[a].3, geometry[b].3);
            let (ba, bb) = (state_of(ma).blend, state_of(mb).blend);
            ba.cmp(&bb).then_with(|| {
                if ba {
                    geometry[b].4.total_cmp(&geometry[a].4)
                } else {
                    (pass_of(ma), state_of(ma)).cmp(&(pass_of(mb), state_of(mb)))
                }
            })
        });
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
        // The picture of the opaque scene (cleared to alpha 0: nothing drawn there), or a
        // 1 × 1 stand-in when no material transmits.
        let linear_texture = |label: &str, size: wgpu::Extent3d| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                // The full chain (mip_down.wgsl): rough surfaces refract a blurred picture.
                mip_level_count: size.max_mips(wgpu::TextureDimension::D2),
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: BEHIND_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
        };
        let one = wgpu::Extent3d {
            width: 1,
            height: 1,
            depth_or_array_layers: 1,
        };
        let behind = linear_texture("mesh scene behind", if behind_needed { size } else { one });
        let behind_view = behind.create_view(&Default::default());
        // Level k of the picture, alone: a render attachment holds one level.
        let behind_level = |k: u32| {
            behind.create_view(&wgpu::TextureViewDescriptor {
                base_mip_level: k,
                mip_level_count: Some(1),
                ..Default::default()
            })
        };
        let no_behind = linear_texture("mesh no scene behind", one);
        let no_behind_view = no_behind.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        // The stand-in is cleared once (alpha 0) so that it reads as "nothing behind".
        drop(crate::gpu::begin_pass(
            &mut encoder,
            "mesh no scene behind",
            &[crate::gpu::cleared_attachment(
                &no_behind_view,
                wgpu::Color::TRANSPARENT,
            )],
        ));
        // Draws `order`'s primitives into `colour` (cleared to `clear`; depth cleared), with
        // group-3 bind groups `groups`; `linear`: the picture of the opaque scene (transmissive
        // primitives skipped).
        let draw = |encoder: &mut wgpu::CommandEncoder,
                    colour: &wgpu::TextureView,
                    clear: wgpu::Color,
                    groups: &[Option<wgpu::BindGroup>],
                    linear: bool| {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("mesh"),
                color_attachments: &[crate::gpu::cleared_attachment(colour, clear)],
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
            let mut current: Option<(usize, PipelineState)> = None;
            for &g in &order {
                let (vb, ib, count, material, _) = &geometry[g];
                if linear && transmissive(*material) {
                    continue;
                }
                let (Some(mesh_group), k) = (&groups[*material], pass_of(*material)) else {
                    continue;
                };
                let key = (
                    k,
                    PipelineState {
                        linear,
                        ..state_of(*material)
                    },
                );
                let Some(pipeline) = passes.pipelines.get(&key) else {
                    continue;
                };
                if current != Some(key) {
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(1, &passes.bindings[k].bind_group, &[]);
                    current = Some(key);
                }
                pass.set_bind_group(2, &material_groups[*material], &[]);
                pass.set_bind_group(3, mesh_group, &[]);
                pass.set_vertex_buffer(0, vb.slice(..));
                pass.set_index_buffer(ib.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..*count, 0, 0..1);
            }
        };
        if behind_needed {
            let groups = mesh_groups_with(FLAG_LINEAR_OUTPUT, &no_behind_view);
            draw(
                &mut encoder,
                &behind_level(0),
                wgpu::Color::TRANSPARENT,
                &groups,
                true,
            );
            if let Some(mip_down) = &mip_down {
                mip_down.fill(
                    device,
                    &mut encoder,
                    &behind_level,
                    behind.mip_level_count(),
                );
            }
        }
        // The background: the environment seen by the camera is not drawn (a clear colour
        // keeps the spheres' silhouettes readable).
        let groups = if behind_needed {
            mesh_groups_with(FLAG_BEHIND, &behind_view)
        } else {
            mesh_groups_with(0, &no_behind_view)
        };
        draw(
            &mut encoder,
            &target_view,
            wgpu::Color {
                r: 0.18,
                g: 0.18,
                b: 0.2,
                a: 1.0,
            },
            &groups,
            false,
        );
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

/// The interleaved vertices of a primitive ([`VERTEX_FLOATS`] floats each).
fn vertex_data(p: &GltfPrimitive) -> Vec<f32> {
    let mut out = Vec::with_capacity(p.positions.len() * VERTEX_FLOATS);
    for k in 0..p.positions.len() {
        let x = p.positions[k];
        let n = p.normals.get(k).copied().unwrap_or([0.0, 1.0, 0.0]);
        let t = p.tangents.get(k).copied().unwrap_or([1.0, 0.0, 0.0, 1.0]);
        let uv = p.uvs.get(k).copied().unwrap_or([0.0; 2]);
        let uv1 = p.uvs1.get(k).copied().unwrap_or(uv);
        let c = p.colours.get(k).copied().unwrap_or([1.0; 4]);
        out.extend_from_slice(&x);
        out.extend_from_slice(&n);
        out.extend_from_slice(&t);
        out.extend_from_slice(&uv);
        out.extend_from_slice(&uv1);
        out.extend_from_slice(&c);
    }
    out
}
