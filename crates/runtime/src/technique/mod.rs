//! The GPU film techniques, one file each behind [`REGISTRY`], as `nacre-bake`'s `kinds/` is
//! for table kinds.
//!
//! A technique is a WGSL module of `shaders/` that defines
//! `fn film_colour(input: FilmInput) -> FilmOutput` and declares bind group 1 (the tables).
//! Its file here holds everything the runtime knows about it: the group-1 layout (a list of
//! [`Slot`]s), the function that fills the bind group from a [`TableSet`] and
//! [`TechniqueOptions`], its uniforms, and its [`TechniqueEntry`] (command-line name, WGSL
//! module, bench label, the `nacre color --method` of its CPU twin). [`shaders`](crate::shaders)
//! knows modules only; [`crate::bindings`], [`crate::bench`] and the command line's
//! `--technique` read [`REGISTRY`].
//!
//! Adding a technique: `shaders/film_NEW.wgsl`, `technique/NEW.rs` (its `ENTRY`), a
//! [`Technique`] variant and its line in [`REGISTRY`] (this file), and its CPU twin (a
//! `Method` of `nacre_bake::commands::color`).

mod fourier;
mod lut;
mod spectral;
mod stack;

pub use spectral::{SpectralParams, SpectralSample, SpectralSetup, spectral_samples};
pub use stack::{StackNode, StackParams, StackSetup, stack_buffers};

use crate::bindings::TechniqueOptions;
use crate::error::{Error, Result};
use crate::tables::TableSet;
use nacre_optics::colour::Colorimeter;

/// How the film colour is computed: one variant per entry of [`REGISTRY`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Technique {
    /// `film_lut.wgsl`.
    Lut,
    /// `film_fourier.wgsl`.
    Fourier,
    /// `film_spectral.wgsl`.
    Spectral,
    /// `film_stack.wgsl`.
    Stack,
}

/// Every technique, in the order of the command line's choices.
pub const REGISTRY: &[TechniqueEntry] =
    &[lut::ENTRY, fourier::ENTRY, spectral::ENTRY, stack::ENTRY];

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
    /// The technique.
    pub technique: Technique,
}

impl BindInputs<'_> {
    /// The error for a table of `kind` the table set lacks.
    pub fn missing(&self, kind: &'static str) -> Error {
        Error::MissingTable {
            needed_by: format!("technique `{}`", self.technique.name()),
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
    /// The technique.
    pub technique: Technique,
    /// Its name on the command line (`nacre render --technique`) and in file names.
    pub name: &'static str,
    /// Its WGSL module (`shaders/NAME.wgsl`), which [`crate::shaders::MODULES`] lists.
    pub module: crate::shaders::Module,
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

impl Technique {
    /// Every technique, in [`REGISTRY`] order.
    pub const ALL: [Technique; REGISTRY.len()] = {
        let mut all = [Technique::Lut; REGISTRY.len()];
        let mut i = 0;
        while i < REGISTRY.len() {
            all[i] = REGISTRY[i].technique;
            i += 1;
        }
        all
    };

    /// Its entry in [`REGISTRY`].
    ///
    /// # Panics
    /// Never: a test checks that every variant has exactly one entry.
    pub fn entry(self) -> &'static TechniqueEntry {
        REGISTRY
            .iter()
            .find(|e| e.technique == self)
            .expect("every technique has an entry in REGISTRY")
    }

    /// The technique called `name` on the command line.
    pub fn from_name(name: &str) -> Option<Technique> {
        REGISTRY
            .iter()
            .find(|e| e.name == name)
            .map(|e| e.technique)
    }

    /// The technique module's WGSL source.
    pub fn source(self) -> &'static str {
        self.entry().module.source
    }

    /// The technique module's name in [`crate::shaders::MODULES`] (`film_lut`, …).
    pub fn module(self) -> &'static str {
        self.entry().module.name
    }

    /// The name used on the command line and in file names.
    pub fn name(self) -> &'static str {
        self.entry().name
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_technique_has_one_entry_and_a_module() {
        for (i, e) in REGISTRY.iter().enumerate() {
            assert_eq!(
                REGISTRY
                    .iter()
                    .filter(|f| f.technique == e.technique)
                    .count(),
                1,
                "{:?}",
                e.technique
            );
            assert_eq!(Technique::ALL[i], e.technique);
            assert_eq!(Technique::from_name(e.name), Some(e.technique));
            assert_eq!(crate::shaders::module(e.module.name), Some(&e.module));
            assert!(crate::shaders::TECHNIQUE_MODULES.contains(&e.module.name));
            assert!(!e.layout.is_empty());
        }
        // A variant without an entry fails to compile here.
        for t in Technique::ALL {
            match t {
                Technique::Lut | Technique::Fourier | Technique::Spectral | Technique::Stack => {
                    assert_eq!(t.entry().technique, t)
                }
            }
        }
        assert_eq!(Technique::from_name("nope"), None);
    }
}
