//! The mesh pipelines and their group 3 (material textures and the scene behind).

use super::{BEHIND_FORMAT, DEPTH_FORMAT, VERTEX_FLOATS};
use crate::bindings::{TechniqueBinding, TechniqueOptions};
use crate::context::GpuContext;
use crate::error::Result;
use crate::gltf_scene::{AlphaMode, GltfMaterial, GltfPrimitive, GltfScene, Topology};
use crate::render::{MaterialOptions, TARGET_FORMAT};
use crate::shaders::{self, Technique};
use crate::tables::TableSet;
use crate::technique::StackSetup;
use nacre_optics::colour::Colorimeter;
use std::collections::BTreeMap;

/// How a primitive is rasterised: its topology, and whether it is drawn unlit.
///
/// Lines and points without normals are drawn unlit, in their base colour (× texture ×
/// `COLOR_0`), as `KHR_materials_unlit` draws: glTF 2.0 §3.7.2.1's "when normals are not
/// specified, client implementations MUST calculate flat normals" concerns triangles (a
/// line or a point has no face to take a normal from), and a line or point has no surface
/// to light, so renderers conventionally draw them unlit (three.js' `LineBasicMaterial` and
/// `PointsMaterial`, the glTF Sample Viewer's screenshot of MeshPrimitiveModes). Lines and
/// points with normals are lit as surfaces are, with those normals.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(super) struct Raster {
    /// Triangles, lines or points.
    pub topology: Topology,
    /// Drawn unlit (`shaders/mesh.wgsl`'s override `MESH_PRIMITIVE_UNLIT`).
    pub unlit: bool,
}

impl Raster {
    /// How `p` is rasterised.
    pub(super) fn of(p: &GltfPrimitive) -> Raster {
        Raster {
            topology: p.topology,
            unlit: p.topology != Topology::Triangles && p.normals.len() != p.positions.len(),
        }
    }

    /// wgpu's topology: a point, line or triangle list (points and lines are one pixel
    /// wide: wgpu, like WebGPU, has no point size or line width).
    fn wgpu_topology(self) -> wgpu::PrimitiveTopology {
        match self.topology {
            Topology::Triangles => wgpu::PrimitiveTopology::TriangleList,
            Topology::Lines => wgpu::PrimitiveTopology::LineList,
            Topology::Points => wgpu::PrimitiveTopology::PointList,
        }
    }
}

/// The fixed-function state of a mesh pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(super) struct PipelineState {
    /// Single-sided material drawing triangles: back faces culled.
    pub cull_back: bool,
    /// `alphaMode` BLEND: src-alpha blending, no depth writes.
    pub blend: bool,
    /// The picture of the opaque scene (linear radiance, [`BEHIND_FORMAT`]) rather than the
    /// display image.
    pub linear: bool,
    /// The primitive's topology and lighting.
    pub raster: Raster,
}

impl PipelineState {
    /// The state of a primitive rasterised as `raster` with glTF material `gm`, drawn into
    /// the display image.
    pub(super) fn of(gm: &GltfMaterial, raster: Raster) -> PipelineState {
        PipelineState {
            cull_back: !gm.double_sided && raster.topology == Topology::Triangles,
            blend: gm.alpha_mode == AlphaMode::Blend,
            linear: false,
            raster,
        }
    }
}

/// Whether `gm` transmits (`KHR_materials_transmission`): it sees the opaque scene, which a
/// first pass draws into a picture of linear radiance, as the glTF Sample Viewer does.
pub(super) fn transmits(gm: &GltfMaterial) -> bool {
    gm.transmission > 0.0 && gm.transmission.is_finite()
}

/// The passes of a glTF render: one per technique, except `film_spectral`, whose group-1
/// samples hold the base index per wavelength: one pass (binding and pipelines) per distinct
/// base, and `film_glass`, whose group 1 holds the material's own pane: one pass per material
/// drawn with it. Each pass has a pipeline per [`PipelineState`] its materials need.
pub(super) struct Passes {
    /// Per pass, its group 1.
    pub bindings: Vec<TechniqueBinding>,
    /// Per (pass, state), the pipeline.
    pub pipelines: BTreeMap<(usize, PipelineState), wgpu::RenderPipeline>,
    /// Per material of the file, the pass that draws it (0 for an unused one).
    pub pass_of: Vec<usize>,
    /// Whether a used material transmits, so that the opaque scene is drawn first.
    pub behind_needed: bool,
}

impl Passes {
    /// The passes that draw the materials `used` of `scene` as `drawn` says (per material:
    /// options and technique; `glass`, the pane of those drawn with `glass`); `layouts` are
    /// groups 0, 2 and 3.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(
        ctx: &GpuContext,
        tables: &TableSet,
        technique_options: &TechniqueOptions,
        colorimeter: &Colorimeter,
        scene: &GltfScene,
        drawn: &[(MaterialOptions, Technique)],
        glass: &[Option<StackSetup>],
        used: &[usize],
        layouts: [&wgpu::BindGroupLayout; 3],
    ) -> Result<Passes> {
        let key_of = |i: usize| {
            let (m, t) = &drawn[i];
            if *t == Technique::Spectral {
                (*t, m.base.name().to_string())
            } else if *t == Technique::Glass {
                (*t, format!("material {i}"))
            } else {
                (*t, String::new())
            }
        };
        let behind_needed = used.iter().any(|&i| transmits(&scene.materials[i]));
        let mut keys: Vec<(Technique, String)> = used.iter().map(|&i| key_of(i)).collect();
        keys.sort_by(|a, b| (a.0.name(), &a.1).cmp(&(b.0.name(), &b.1)));
        keys.dedup();
        let mut bindings = Vec::new();
        let mut pipelines = BTreeMap::new();
        for (k, key) in keys.iter().enumerate() {
            let mut options = technique_options.clone();
            if let Some(&i) = used.iter().find(|&&i| key_of(i) == *key) {
                options.spectral.base = drawn[i].0.base.clone();
                if let Some(Some(pane)) = glass.get(i) {
                    options.stack = pane.clone();
                }
            }
            let binding = TechniqueBinding::new(ctx, tables, key.0, &options, colorimeter)?;
            let mut states: Vec<PipelineState> = Vec::new();
            for p in scene.primitives.iter().filter(|p| {
                !p.indices.is_empty() && used.contains(&p.material) && key_of(p.material) == *key
            }) {
                let gm = &scene.materials[p.material];
                let state = PipelineState::of(gm, Raster::of(p));
                states.push(state);
                if behind_needed && !transmits(gm) {
                    states.push(PipelineState {
                        linear: true,
                        ..state
                    });
                }
            }
            states.sort_unstable();
            states.dedup();
            for state in states {
                let [view, material, mesh] = layouts;
                let pipeline = mesh_pipeline(ctx, key.0, &binding, view, material, mesh, state)?;
                pipelines.insert((k, state), pipeline);
            }
            bindings.push(binding);
        }
        let pass_of = (0..drawn.len())
            .map(|i| keys.iter().position(|k| *k == key_of(i)).unwrap_or(0))
            .collect();
        Ok(Passes {
            bindings,
            pipelines,
            pass_of,
            behind_needed,
        })
    }
}

/// The render pipeline of one pass and state: `mesh.wgsl` over the technique's module.
fn mesh_pipeline(
    ctx: &GpuContext,
    technique: Technique,
    binding: &TechniqueBinding,
    view_layout: &wgpu::BindGroupLayout,
    material_layout: &wgpu::BindGroupLayout,
    mesh_layout: &wgpu::BindGroupLayout,
    state: PipelineState,
) -> Result<wgpu::RenderPipeline> {
    let device = &ctx.device;
    let source = shaders::film_pipeline(technique.module(), &["material", "mesh"])?;
    let module = shaders::create_module(ctx, "mesh", &source)?;
    let unlit: &[(&str, f64)] = if state.raster.unlit {
        &[("MESH_PRIMITIVE_UNLIT", 1.0)]
    } else {
        &[]
    };
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
                    array_stride: (VERTEX_FLOATS * 4) as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![
                        0 => Float32x3, 1 => Float32x3, 2 => Float32x4,
                        3 => Float32x2, 4 => Float32x2, 5 => Float32x4
                    ],
                })],
            },
            primitive: wgpu::PrimitiveState {
                topology: state.raster.wgpu_topology(),
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: state.cull_back.then_some(wgpu::Face::Back),
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                // Blended primitives test depth but do not write it.
                depth_write_enabled: Some(!state.blend),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("mesh_fs"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: unlit,
                    ..Default::default()
                },
                targets: &[Some(wgpu::ColorTargetState {
                    format: if state.linear {
                        BEHIND_FORMAT
                    } else {
                        TARGET_FORMAT
                    },
                    blend: state.blend.then_some(wgpu::BlendState::ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    })
}
