//! The commands behind the `nacre` tool that evaluate rather than bake: `color` (and its
//! methods), `compare`, `conformance`, `spectrum`, `plot`, with their inputs (stack flags and
//! recipes, angle/wavelength grids).

pub mod color;
pub mod compare;
pub mod conformance;
pub mod grid;
pub mod plot;
pub mod spectrum;
pub mod stack_spec;
