//! Bind-group layouts (one per technique, for group 1 — the tables) and the bind groups
//! that fill them, from each technique's [`TechniqueEntry`](crate::technique::TechniqueEntry)
//! in [`crate::technique::REGISTRY`]. Groups are ordered by how often they change: 0 view,
//! 1 tables, 2 material (`shaders/README.md`).

use crate::context::GpuContext;
use crate::error::Result;
use crate::tables::TableSet;
use crate::technique::{BindInputs, Slot, Technique};
use nacre_optics::colour::Colorimeter;

pub use crate::technique::{
    GlassParams, SpectralSetup, StackSetup, TechniqueOptions, glass_gpu, spectral_samples,
    stack_buffers, stack_gpu,
};

const STAGES: wgpu::ShaderStages = wgpu::ShaderStages::FRAGMENT.union(wgpu::ShaderStages::COMPUTE);

/// The layout entry of `slot` at `binding`.
fn layout_entry(binding: u32, slot: Slot) -> wgpu::BindGroupLayoutEntry {
    let ty = match slot {
        Slot::Texture(view_dimension, filterable) => wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable },
            view_dimension,
            multisampled: false,
        },
        Slot::Sampler => wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        Slot::Uniform | Slot::Storage => wgpu::BindingType::Buffer {
            ty: match slot {
                Slot::Uniform => wgpu::BufferBindingType::Uniform,
                _ => wgpu::BufferBindingType::Storage { read_only: true },
            },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
    };
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: STAGES,
        ty,
        count: None,
    }
}

/// The group-1 layout of `technique`: its entry's [`Slot`]s as bindings 0, 1, …, visible to
/// fragment and compute stages (each technique's file in `technique/` lists them).
pub fn table_layout(device: &wgpu::Device, technique: Technique) -> wgpu::BindGroupLayout {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = technique
        .entry()
        .layout
        .iter()
        .enumerate()
        .map(|(i, &slot)| layout_entry(i as u32, slot))
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(technique.name()),
        entries: &entries,
    })
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
    /// Builds group 1 of `technique` from `tables` (and, for `Spectral` and `Stack`, the
    /// colorimeter of the tables or `colorimeter`) with its entry's `bind`.
    pub fn new(
        ctx: &GpuContext,
        tables: &TableSet,
        technique: Technique,
        options: &TechniqueOptions,
        colorimeter: &Colorimeter,
    ) -> Result<Self> {
        let layout = table_layout(&ctx.device, technique);
        let inputs = BindInputs {
            device: &ctx.device,
            layout: &layout,
            tables,
            options,
            colorimeter,
            name: technique.name(),
        };
        let bind_group = ctx.checked("creating a table bind group", || {
            (technique.entry().bind)(&inputs)
        })??;
        Ok(TechniqueBinding {
            technique,
            layout,
            bind_group,
        })
    }
}
