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
//! [`Technique`] variant, its place in [`Technique::ALL`] and its arm in
//! [`Technique::entry`] (this file), and its CPU twin (a
//! `Method` of `nacre_bake::commands::color`).

mod entry;
mod fourier;
mod glass;
mod lut;
mod options;
mod spectral;
mod stack;

pub use entry::{BindInputs, Slot, TechniqueEntry};
pub use glass::{GlassParams, glass_gpu};
pub use options::{SpectralSetup, StackSetup, TechniqueOptions};
pub use spectral::{SpectralParams, SpectralSample, spectral_samples};
pub use stack::{StackGpu, StackNode, StackParams, stack_buffers, stack_gpu};

/// How the film colour is computed: one variant per technique file, its entry in
/// [`Technique::entry`].
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
    /// `film_glass.wgsl`.
    Glass,
}

/// Every technique's entry, in [`Technique::ALL`] order (the command line's choices).
pub const REGISTRY: &[TechniqueEntry] = &{
    let mut all = [lut::ENTRY; Technique::ALL.len()];
    let mut i = 0;
    while i < all.len() {
        all[i] = *Technique::ALL[i].entry();
        i += 1;
    }
    all
};

impl Technique {
    /// Every technique, in the order of the command line's choices.
    pub const ALL: [Technique; 5] = [
        Technique::Lut,
        Technique::Fourier,
        Technique::Spectral,
        Technique::Stack,
        Technique::Glass,
    ];

    /// Its entry (in its file of `technique/`).
    pub const fn entry(self) -> &'static TechniqueEntry {
        match self {
            Technique::Lut => &lut::ENTRY,
            Technique::Fourier => &fourier::ENTRY,
            Technique::Spectral => &spectral::ENTRY,
            Technique::Stack => &stack::ENTRY,
            Technique::Glass => &glass::ENTRY,
        }
    }

    /// The technique called `name` on the command line.
    pub fn from_name(name: &str) -> Option<Technique> {
        Technique::ALL.into_iter().find(|t| t.entry().name == name)
    }

    /// The technique module's WGSL source.
    pub fn source(self) -> &'static str {
        self.entry().source
    }

    /// The technique module's name in [`crate::shaders::MODULES`] (`film_lut`, …).
    pub fn module(self) -> &'static str {
        self.entry().module
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
    fn every_technique_has_an_entry_and_a_module() {
        for (i, t) in Technique::ALL.into_iter().enumerate() {
            let e = t.entry();
            assert_eq!(REGISTRY[i].name, e.name);
            assert_eq!(
                Technique::ALL
                    .iter()
                    .filter(|u| u.entry().name == e.name)
                    .count(),
                1
            );
            assert_eq!(Technique::from_name(e.name), Some(t));
            assert_eq!(
                crate::shaders::module(e.module).map(|m| m.source),
                Some(e.source)
            );
            assert!(crate::shaders::TECHNIQUE_MODULES.contains(&e.module));
            assert!(!e.layout.is_empty());
        }
        assert_eq!(Technique::from_name("nope"), None);
    }
}
