//! Fitting stacks to data: a stack with free parameters and their bounds
//! ([`template::Template`]), small bounded optimisers and the fits built on them.
//!
//! * [`template`] — a stack with free parameters and their bounds;
//! * [`nelder_mead`] — the bounded Nelder–Mead simplex for a few parameters;
//! * [`lm`] — a small box-bounded Levenberg–Marquardt;
//! * [`gltf`] — the closest `KHR_materials_iridescence` film to target colours;
//! * [`spectrum`] — the global fit of a measured spectrum;
//! * [`color`] — the design of a stack for target colours over angles.
//!
//! No I/O: the commands read the data and the template, this module fits.

pub mod color;
pub mod gltf;
pub mod lm;
pub mod nelder_mead;
pub mod spectrum;
pub mod template;

pub use color::{ColourFit, ColourSettings, ColourSolution, ColourTarget, fit_colour};
pub use spectrum::{Baseline, Loss, Measurement, Quantity, Settings, SpectrumFit, fit_spectrum};
pub use template::{Free, FreeKind, Template};
