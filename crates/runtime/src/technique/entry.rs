//! What a technique's file declares: its [`TechniqueEntry`], the [`Slot`]s of its group 1 and
//! the [`BindInputs`] its bind function reads (a leaf of `technique/`: the files of the
//! techniques import it, never `technique/mod.rs`).

use crate::error::{Error, Result};
use crate::tables::TableSet;
use crate::technique::options::TechniqueOptions;
use nacre_optics::colour::Colorimeter;

/// One binding of a technique's group 1, in binding order (0, 1, …).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// A float texture of this dimension, filterable or not.
    Texture(wgpu::TextureViewDimension, bool),
    /// A filtering sampler.
    Sampler,
    /// A uniform buffer.
    Uniform,
    /// A read-only storage buffer.
    Storage,
}

/// What a technique's bind function reads.
pub struct BindInputs<'a> {
    /// The device.
    pub device: &'a wgpu::Device,
    /// The group-1 layout made from the entry's [`TechniqueEntry::layout`].
    pub layout: &'a wgpu::BindGroupLayout,
    /// The tables on the GPU.
    pub tables: &'a TableSet,
    /// The techniques' options.
    pub options: &'a TechniqueOptions,
    /// The colorimeter (of the tables, or the caller's).
    pub colorimeter: &'a Colorimeter,
    /// The technique's name (errors name it).
    pub name: &'static str,
}

impl BindInputs<'_> {
    /// The error for a table of `kind` the table set lacks.
    pub fn missing(&self, kind: &'static str) -> Error {
        Error::MissingTable {
            needed_by: format!("technique `{}`", self.name),
            kind,
            example: None,
        }
    }

    /// The bind group of `label` over `resources`, bindings 0, 1, … in order.
    pub fn bind_group(
        &self,
        label: &str,
        resources: &[wgpu::BindingResource<'_>],
    ) -> wgpu::BindGroup {
        let entries: Vec<wgpu::BindGroupEntry<'_>> = resources
            .iter()
            .enumerate()
            .map(|(i, resource)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: resource.clone(),
            })
            .collect();
        self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout: self.layout,
            entries: &entries,
        })
    }
}

/// Everything the runtime knows about one technique.
#[derive(Clone, Copy, Debug)]
pub struct TechniqueEntry {
    /// Its name on the command line (`nacre render --technique`) and in file names.
    pub name: &'static str,
    /// Its WGSL module's name (`shaders/NAME.wgsl` without `.wgsl`), which
    /// [`crate::shaders::MODULES`] lists.
    pub module: &'static str,
    /// The module's text (`include_str!` of the file).
    pub source: &'static str,
    /// Its pass's name in `nacre bench-gpu` reports.
    pub bench_label: &'static str,
    /// The `nacre color --method` of its CPU twin, which the GPU = CPU tests compare with
    /// (`N` and `PATH` stand for a count and a table manifest).
    pub cpu_twin: &'static str,
    /// Group 1, binding by binding.
    pub layout: &'static [Slot],
    /// Fills group 1 (inside a [`crate::GpuContext::checked`] scope).
    pub bind: fn(&BindInputs<'_>) -> Result<wgpu::BindGroup>,
}
