//! The GPU side of a glTF frame, pass by pass ([`draw`]):
//!
//! 1. **plan** (CPU): the technique of each used material and the notes ([`plan`]);
//! 2. **pipelines**: one pass per technique (and base, for `spectral`), a pipeline per
//!    fixed-function state ([`Passes`]);
//! 3. **upload**: the environment, the view uniform, per material its uniform and thickness
//!    map, the glTF textures ([`Resources`]), then inside the frame's error scope the bind
//!    groups and the vertex and index buffers ([`Bound`]);
//! 4. **targets**: the display image, the depth buffer and the picture of the opaque scene
//!    behind transmissive surfaces ([`Targets`]);
//! 5. **opaque pass** (only when a material transmits): every non-transmissive primitive in
//!    linear radiance into that picture, then its mip chain (rough surfaces refract a blurred
//!    picture);
//! 6. **main pass**: every primitive into the display image, opaque and masked ones by
//!    pipeline, blended ones back to front, transmissive ones reading the picture;
//! 7. **readback**: submit, wait, read the image back (alpha set to 255).

use super::camera::view_depth;
use super::inputs::RenderInputs;
use super::materials;
use super::pipeline::{Passes, PipelineState, Raster, transmits};
use super::textures::{GltfTextures, MipDown, Samplers, mesh_group_layout};
use super::{
    BEHIND_FORMAT, DEPTH_FORMAT, FLAG_BEHIND, FLAG_GLASS, FLAG_LINEAR_OUTPUT, MeshRender,
    MeshUniform, vertex_data,
};
use crate::context::{BufferInitExt, GpuContext};
use crate::error::Result;
use crate::gltf_scene::GltfScene;
use crate::gpu::check_limit;
use crate::gpu::{group_layout, read_texture, uniform_texture_group, upload_mips};
use crate::image_io::RenderedImage;
use crate::render::{
    EnvironmentTextures, MaterialOptions, MaterialUniform, TARGET_FORMAT, ViewUniform,
};
use crate::shaders::Technique;
use crate::tables::TableSet;
use crate::thickness_map::ThicknessMap;
use nacre_format::param::Msg;

/// The display image's background (the environment itself is not drawn: a clear colour keeps
/// the silhouettes readable).
const BACKGROUND: wgpu::Color = wgpu::Color {
    r: 0.18,
    g: 0.18,
    b: 0.2,
    a: 1.0,
};

/// Renders `inputs` with `technique` from `tables` (see the module documentation).
pub(super) fn draw(
    ctx: &GpuContext,
    tables: &TableSet,
    technique: Technique,
    inputs: &RenderInputs,
    cache: &mut MeshCache,
) -> Result<MeshRender> {
    let (scene, options) = (inputs.scene, &inputs.options);
    let (width, height) = (options.width, options.height);
    check_limit(
        ctx,
        "render target",
        u64::from(width.max(height)),
        ctx.device.limits().max_texture_dimension_2d,
    )?;
    let plan = plan(tables, technique, inputs)?;

    let device = &ctx.device;
    let technique_options = options.technique_options();
    let key = passes_key(tables, technique, &technique_options, scene, &plan);
    let kept = match cache.passes.take() {
        Some(kept) if kept.key == key => kept,
        _ => {
            let layouts = [
                crate::render::view_group_layout(device, "mesh view"),
                group_layout(device, "mesh material"),
                mesh_group_layout(device),
            ];
            let passes = Passes::new(
                ctx,
                tables,
                &technique_options,
                &plan.colorimeter,
                scene,
                &plan.drawn,
                &plan.glass,
                &plan.used,
                [&layouts[0], &layouts[1], &layouts[2]],
            )?;
            cache.builds += 1;
            KeptPasses {
                key,
                layouts,
                passes,
            }
        }
    };
    let KeptPasses {
        layouts, passes, ..
    } = cache.passes.insert(kept);
    crate::render::check_film_eval(tables, options)?;
    let resources = Resources::upload(ctx, tables, inputs, &plan, passes.behind_needed)?;

    let (target, submitted) = ctx.checked("rendering the glTF scene", || {
        let bound = Bound::new(device, inputs, &plan, &resources, layouts);
        let targets = Targets::new(device, (width, height), passes.behind_needed);
        let frame = Frame {
            device,
            inputs,
            resources: &resources,
            mesh_layout: &layouts[2],
            passes,
            bound: &bound,
            order: draw_order(&bound.geometry, scene, passes),
            depth: &targets.depth_view,
        };
        let mut encoder = device.create_command_encoder(&Default::default());
        let groups = frame.opaque_pass(&mut encoder, &targets);
        // The main pass.
        frame.pass(&mut encoder, &targets.view, BACKGROUND, &groups, false);
        // Let the uploads finish first, so that the time measured is the passes' (a lost
        // device or a hung queue is an error, as in every other wait).
        ctx.wait("waiting for the glTF scene's uploads")?;
        let submitted = std::time::Instant::now();
        ctx.queue.submit([encoder.finish()]);
        Result::Ok((targets.target, submitted))
    })??;

    // Readback.
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
        notes: plan.notes,
    })
}

/// The compiled passes of the last frame, kept for the next ([`super::render_cached`]):
/// compiling a scene's pipelines is most of a frame (1.1–1.3 s of 1.8 s for Khronos'
/// IridescenceSuzanne on lavapipe), while a frame that moves the camera or changes a film's
/// thickness or index (uniforms) needs none.
#[derive(Default)]
pub struct MeshCache {
    passes: Option<KeptPasses>,
    builds: u64,
}

impl MeshCache {
    /// How many times the passes were compiled (a frame that reused them adds nothing).
    pub fn builds(&self) -> u64 {
        self.builds
    }
}

/// Passes and the layouts their pipelines were made with, under the key of what decides them.
struct KeptPasses {
    key: String,
    layouts: [wgpu::BindGroupLayout; 3],
    passes: Passes,
}

/// What decides [`Passes::new`]'s pipelines and group-1 bindings, as text: the tables, the
/// technique and its options (harmonics, wavelengths, the stack), per used material the
/// technique that draws it, its base and its pane, and per primitive its material, its
/// fixed-function state and whether it transmits. Films' thicknesses and indices, the
/// camera, lights and environment are uniforms and textures: not part of it.
fn passes_key(
    tables: &TableSet,
    technique: Technique,
    technique_options: &crate::technique::TechniqueOptions,
    scene: &GltfScene,
    plan: &Plan,
) -> String {
    let table = |path: Option<&std::path::Path>| path.map(|p| p.display().to_string());
    let drawn: Vec<_> = plan
        .used
        .iter()
        .map(|&i| {
            let (m, t) = &plan.drawn[i];
            (
                i,
                t.name(),
                format!("{:?}", m.base),
                format!("{:?}", plan.glass.get(i)),
            )
        })
        .collect();
    let states: Vec<_> = scene
        .primitives
        .iter()
        .filter(|p| !p.indices.is_empty() && plan.used.contains(&p.material))
        .map(|p| {
            let gm = &scene.materials[p.material];
            (
                p.material,
                PipelineState::of(gm, Raster::of(p)),
                transmits(gm),
            )
        })
        .collect();
    format!(
        "{:?}",
        (
            table(tables.film_lut.as_ref().map(|t| t.manifest_path.as_path())),
            table(tables.fourier.as_ref().map(|t| t.manifest_path.as_path())),
            table(
                tables
                    .rough_film_lut
                    .as_ref()
                    .map(|t| t.manifest_path.as_path())
            ),
            technique.name(),
            technique_options,
            drawn,
            states,
        )
    )
}

/// What the frame draws, decided on the CPU.
struct Plan {
    /// The materials a primitive refers to, sorted.
    used: Vec<usize>,
    /// Per material of the file: nacre's options and the technique that draws it.
    drawn: Vec<(MaterialOptions, Technique)>,
    /// Per material of the file: the pane of those drawn with `glass`.
    glass: Vec<Option<crate::technique::StackSetup>>,
    /// The colorimeter of the tables.
    colorimeter: nacre_optics::colour::Colorimeter,
    /// The notes of [`MeshRender::notes`].
    notes: Vec<Msg>,
}

/// The used materials, the technique of each ([`materials::choose`]) and the notes: the
/// scene's own about a used material (or about no material), the materials', the lights',
/// then the technique fallbacks'.
fn plan(tables: &TableSet, technique: Technique, inputs: &RenderInputs) -> Result<Plan> {
    let scene = inputs.scene;
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
    if let Some(note) = &inputs.light_note {
        notes.push(Msg::from(note.as_str()));
    }
    if let Some(note) = choice.fallback_note {
        notes.push(note);
    }
    Ok(Plan {
        used,
        drawn: choice.drawn,
        glass: choice.glass,
        colorimeter,
        notes,
    })
}

/// What the frame uploads before its error scope: the environment and view uniform (group
/// 0), per material its uniform and thickness map (group 2), the glTF textures (group 3).
struct Resources {
    env: EnvironmentTextures,
    view_uniform: ViewUniform,
    /// A 1 × 1 map of g = 1 (d = d_max), for the materials without a thickness texture.
    flat_thickness: wgpu::Texture,
    /// Per material, its thickness texture (used materials only).
    thickness: Vec<Option<wgpu::Texture>>,
    material_uniforms: Vec<MaterialUniform>,
    textures: GltfTextures,
    /// The picture's mip-chain pass, when a material transmits.
    mip_down: Option<MipDown>,
}

impl Resources {
    fn upload(
        ctx: &GpuContext,
        tables: &TableSet,
        inputs: &RenderInputs,
        plan: &Plan,
        behind_needed: bool,
    ) -> Result<Resources> {
        let (scene, options) = (inputs.scene, &inputs.options);
        let env = EnvironmentTextures::new(
            ctx,
            &inputs.environment,
            options.film_eval,
            tables.rough_film_lut.as_ref(),
        )?;
        let view_uniform = ViewUniform::new(&inputs.view_options, env.env_levels)?;
        let thickness_map = |map: &ThicknessMap| {
            upload_mips(
                ctx,
                "thickness map",
                wgpu::TextureFormat::Rg16Float,
                &map.mip_chain(),
            )
        };
        let flat_thickness = thickness_map(&ThicknessMap {
            width: 1,
            height: 1,
            values: vec![1.0],
            green_blue: None,
        })?;
        let mut thickness = Vec::with_capacity(plan.drawn.len());
        for i in 0..plan.drawn.len() {
            thickness.push(match scene.thickness_maps.get(i).and_then(Option::as_ref) {
                Some(map) if plan.used.contains(&i) => Some(thickness_map(map)?),
                _ => None,
            });
        }
        let mut material_uniforms = Vec::with_capacity(plan.drawn.len());
        for (m, _) in &plan.drawn {
            let mut u = MaterialUniform::new(m, tables)?;
            u.film_eval = options.film_eval.id();
            material_uniforms.push(u);
        }
        let textures = GltfTextures::upload(ctx, scene, &plan.used)?;
        let mip_down = if behind_needed {
            Some(MipDown::new(ctx)?)
        } else {
            None
        };
        Ok(Resources {
            env,
            view_uniform,
            flat_thickness,
            thickness,
            material_uniforms,
            textures,
            mip_down,
        })
    }
}

/// One drawable primitive on the GPU.
struct Geometry {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    material: usize,
    /// Its topology and lighting.
    raster: Raster,
    /// The distance of its bounding box's centre along the view axis.
    depth: f64,
}

/// The bind groups and buffers of the frame, made inside its error scope.
struct Bound<'r> {
    /// Group 0.
    view_group: wgpu::BindGroup,
    /// Group 2 per material.
    material_groups: Vec<wgpu::BindGroup>,
    /// Every sampler the used materials read.
    samplers: Samplers,
    /// The primitives with something to draw (triangles, lines or points).
    geometry: Vec<Geometry>,
    /// The used materials.
    used: &'r [usize],
    /// Per material of the file: drawn by `film_glass` as a pane ([`FLAG_GLASS`]).
    glass: Vec<bool>,
}

impl<'r> Bound<'r> {
    fn new(
        device: &wgpu::Device,
        inputs: &RenderInputs,
        plan: &'r Plan,
        resources: &Resources,
        layouts: &[wgpu::BindGroupLayout; 3],
    ) -> Bound<'r> {
        let scene = inputs.scene;
        let used = &plan.used;
        let view_group = resources.env.bind_group(
            device,
            &layouts[0],
            "mesh view",
            bytemuck::bytes_of(&resources.view_uniform),
        );
        let material_groups = resources
            .material_uniforms
            .iter()
            .zip(&resources.thickness)
            .map(|(u, t)| {
                uniform_texture_group(
                    device,
                    &layouts[1],
                    "mesh material",
                    bytemuck::bytes_of(u),
                    t.as_ref().unwrap_or(&resources.flat_thickness),
                    true,
                )
            })
            .collect();
        let samplers = resources.textures.samplers(device, scene, used);
        let geometry: Vec<Geometry> = scene
            .primitives
            .iter()
            .filter(|p| !p.indices.is_empty())
            .map(|p| Geometry {
                vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("mesh vertices"),
                    contents: bytemuck::cast_slice(&vertex_data(p)),
                    usage: wgpu::BufferUsages::VERTEX,
                }),
                indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("mesh indices"),
                    contents: bytemuck::cast_slice(&p.indices),
                    usage: wgpu::BufferUsages::INDEX,
                }),
                index_count: p.indices.len() as u32,
                material: p.material,
                raster: Raster::of(p),
                depth: view_depth(&inputs.camera, p),
            })
            .collect();
        Bound {
            view_group,
            material_groups,
            samplers,
            geometry,
            used,
            glass: plan.glass.iter().map(Option::is_some).collect(),
        }
    }

    /// Group 3 per material of the file (`None` for an unused one): its [`MeshUniform`]
    /// (with `extra_flags`), textures and samplers, and the picture `behind`.
    fn mesh_groups(
        &self,
        device: &wgpu::Device,
        inputs: &RenderInputs,
        resources: &Resources,
        layout: &wgpu::BindGroupLayout,
        extra_flags: u32,
        behind: &wgpu::TextureView,
    ) -> Vec<Option<wgpu::BindGroup>> {
        let scene = inputs.scene;
        let mut groups = Vec::with_capacity(scene.materials.len());
        for (i, gm) in scene.materials.iter().enumerate() {
            if !self.used.contains(&i) {
                groups.push(None);
                continue;
            }
            let mut uniform = MeshUniform::new(inputs.camera.view_proj, gm);
            uniform.flags |= extra_flags;
            if self.glass.get(i) == Some(&true) {
                uniform.flags |= FLAG_GLASS;
            }
            let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("mesh material (glTF)"),
                contents: bytemuck::bytes_of(&uniform),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            groups.push(Some(resources.textures.mesh_group(
                device,
                layout,
                scene,
                gm,
                &self.samplers,
                &buffer,
                behind,
            )));
        }
        groups
    }
}

/// The draw order of `geometry`: opaque and masked primitives grouped by pass and pipeline
/// state, then blended ones back to front.
fn draw_order(geometry: &[Geometry], scene: &GltfScene, passes: &Passes) -> Vec<usize> {
    let state_of = |g: &Geometry| PipelineState::of(&scene.materials[g.material], g.raster);
    let mut order: Vec<usize> = (0..geometry.len()).collect();
    order.sort_by(|&a, &b| {
        let (ga, gb) = (&geometry[a], &geometry[b]);
        let (ba, bb) = (state_of(ga).blend, state_of(gb).blend);
        ba.cmp(&bb).then_with(|| {
            if ba {
                gb.depth.total_cmp(&ga.depth)
            } else {
                (passes.pass_of[ga.material], state_of(ga))
                    .cmp(&(passes.pass_of[gb.material], state_of(gb)))
            }
        })
    });
    order
}

/// The frame's attachments.
struct Targets {
    /// The display image ([`TARGET_FORMAT`], read back).
    target: wgpu::Texture,
    view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    /// The picture of the opaque scene in linear radiance ([`BEHIND_FORMAT`], cleared to
    /// alpha 0: nothing drawn there, with its full mip chain), or a 1 × 1 stand-in when no
    /// material transmits.
    behind: wgpu::Texture,
    behind_view: wgpu::TextureView,
    /// A 1 × 1 picture of nothing, bound while the opaque pass draws.
    no_behind_view: wgpu::TextureView,
}

impl Targets {
    fn new(device: &wgpu::Device, extent: (u32, u32), behind_needed: bool) -> Targets {
        let target = crate::gpu::render_target(device, "mesh target", extent, TARGET_FORMAT, true);
        let depth = crate::gpu::render_target(device, "mesh depth", extent, DEPTH_FORMAT, false);
        let linear_texture = |label: &str, (width, height): (u32, u32)| {
            let size = wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            };
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
        let behind = linear_texture(
            "mesh scene behind",
            if behind_needed { extent } else { (1, 1) },
        );
        let no_behind = linear_texture("mesh no scene behind", (1, 1));
        Targets {
            view: target.create_view(&Default::default()),
            target,
            depth_view: depth.create_view(&Default::default()),
            behind_view: behind.create_view(&Default::default()),
            behind,
            no_behind_view: no_behind.create_view(&Default::default()),
        }
    }

    /// Level `k` of the picture behind, alone (a render attachment holds one level).
    fn behind_level(&self, k: u32) -> wgpu::TextureView {
        self.behind.create_view(&wgpu::TextureViewDescriptor {
            base_mip_level: k,
            mip_level_count: Some(1),
            ..Default::default()
        })
    }
}

/// What the render passes of the frame draw with.
struct Frame<'f> {
    device: &'f wgpu::Device,
    inputs: &'f RenderInputs<'f>,
    resources: &'f Resources,
    /// Group 3's layout.
    mesh_layout: &'f wgpu::BindGroupLayout,
    passes: &'f Passes,
    bound: &'f Bound<'f>,
    /// Indices into the bound geometry ([`draw_order`]).
    order: Vec<usize>,
    /// The depth attachment (cleared by every pass).
    depth: &'f wgpu::TextureView,
}

impl Frame<'_> {
    /// Group 3 per material ([`Bound::mesh_groups`]) with `extra_flags` and the picture
    /// `behind`.
    fn mesh_groups(
        &self,
        extra_flags: u32,
        behind: &wgpu::TextureView,
    ) -> Vec<Option<wgpu::BindGroup>> {
        self.bound.mesh_groups(
            self.device,
            self.inputs,
            self.resources,
            self.mesh_layout,
            extra_flags,
            behind,
        )
    }

    /// Clears the 1 × 1 stand-in (alpha 0: "nothing behind") and, when a material transmits,
    /// draws the opaque pass — every non-transmissive primitive in linear radiance into the
    /// picture behind, then its mip chain. Returns the main pass's group 3, which reads the
    /// picture (or the stand-in).
    fn opaque_pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &Targets,
    ) -> Vec<Option<wgpu::BindGroup>> {
        drop(crate::gpu::begin_pass(
            encoder,
            "mesh no scene behind",
            &[crate::gpu::cleared_attachment(
                &targets.no_behind_view,
                wgpu::Color::TRANSPARENT,
            )],
        ));
        if !self.passes.behind_needed {
            return self.mesh_groups(0, &targets.no_behind_view);
        }
        let groups = self.mesh_groups(FLAG_LINEAR_OUTPUT, &targets.no_behind_view);
        self.pass(
            encoder,
            &targets.behind_level(0),
            wgpu::Color::TRANSPARENT,
            &groups,
            true,
        );
        if let Some(mip_down) = &self.resources.mip_down {
            mip_down.fill(
                self.device,
                encoder,
                &|k| targets.behind_level(k),
                targets.behind.mip_level_count(),
            );
        }
        self.mesh_groups(FLAG_BEHIND, &targets.behind_view)
    }

    /// Draws the primitives in `order` into `colour` (cleared to `clear`; depth
    /// cleared), with group-3 bind groups `groups`; `linear`: the picture of the opaque
    /// scene (transmissive primitives skipped).
    fn pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        colour: &wgpu::TextureView,
        clear: wgpu::Color,
        groups: &[Option<wgpu::BindGroup>],
        linear: bool,
    ) {
        let (scene, passes, bound) = (self.inputs.scene, self.passes, self.bound);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("mesh"),
            color_attachments: &[crate::gpu::cleared_attachment(colour, clear)],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: self.depth,
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
        pass.set_bind_group(0, &bound.view_group, &[]);
        let mut current: Option<(usize, PipelineState)> = None;
        for &g in &self.order {
            let geometry = &bound.geometry[g];
            let material = geometry.material;
            if linear && transmits(&scene.materials[material]) {
                continue;
            }
            let (Some(mesh_group), k) = (&groups[material], passes.pass_of[material]) else {
                continue;
            };
            let key = (
                k,
                PipelineState {
                    linear,
                    ..PipelineState::of(&scene.materials[material], geometry.raster)
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
            pass.set_bind_group(2, &bound.material_groups[material], &[]);
            pass.set_bind_group(3, mesh_group, &[]);
            pass.set_vertex_buffer(0, geometry.vertices.slice(..));
            pass.set_index_buffer(geometry.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..geometry.index_count, 0, 0..1);
        }
    }
}
