//! # nacre-bake
//!
//! The front end of nacre: material library and recipes, table generators and writers,
//! and the `nacre` command-line tool (`src/main.rs`). The physics lives in
//! [`nacre_optics`]; this crate parses, resolves, calls the core and writes files
//! atomically.

// `!(x > 0.0)` is how this crate rejects NaN together with out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bake;
pub mod color;
pub mod compare;
pub mod conformance;
pub mod diffraction;
pub mod diffraction_integrated;
pub mod error;
pub mod film_lut;
pub mod fourier_table;
pub mod grid;
pub mod ktx2;
pub mod materials;
pub mod output;
pub mod plot;
pub mod rough_lut;
pub mod spectrum;
pub mod stack_spec;
pub mod table_io;

pub use error::{Error, Result};
