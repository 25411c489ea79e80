//! The commands behind the `nacre` tool that evaluate rather than bake: `color` (its methods,
//! and [`color_request`]: a method prepared from the command line's values), `compare`,
//! `conformance`, `diffraction`, `spectrum`, `plot`, the stack JSON of `export`
//! ([`export_stack`]), with their inputs (stack flags and
//! recipes, angle/wavelength grids).

pub mod color;
pub mod color_request;
pub mod compare;
pub mod conformance;
pub mod diffraction;
pub mod export_stack;
pub mod fit_color;
pub mod fit_gltf;
pub mod fit_spectrum;
pub mod fit_template;
pub mod grid;
pub mod plot;
pub mod spectrum;
pub mod stack_spec;
