//! Fitting stacks to data: a stack with free parameters and their bounds
//! ([`template::Template`]), small bounded optimisers and the fits built on them.
//!
//! * [`template`] — a stack with free parameters and their bounds;
//! * [`nelder_mead`] — the bounded Nelder–Mead simplex for a few parameters;
//! * [`gltf`] — the closest `KHR_materials_iridescence` film to target colours.
//!
//! No I/O: the commands read the data and the template, this module fits.

pub mod gltf;
pub mod nelder_mead;
pub mod template;

pub use template::{Free, FreeKind, Template};
