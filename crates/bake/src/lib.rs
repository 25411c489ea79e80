//! # nacre-bake
//!
//! The front end of nacre: table recipes and their bakers, and the commands behind the
//! `nacre` command-line tool. The physics lives in [`nacre_optics`]; the table format
//! (manifests, file readers and writers, atomic writes, material references) in
//! [`nacre_format`]. This crate parses recipes and flags, calls the core and writes tables
//! through the format.
//!
//! - [`kinds`]: one module per table kind behind [`kinds::TableRecipe`] and
//!   [`kinds::REGISTRY`];
//! - [`recipe`]: the recipe sections every kind shares (`[colour]`, `[stack]`, `[output]`);
//! - [`commands`]: `color`, `compare`, `conformance`, `spectrum`, `plot` and their inputs.

// `!(x > 0.0)` is how this crate rejects NaN together with out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod commands;
mod csv_text;
pub mod error;
pub mod kinds;
pub mod recipe;

pub use error::{Error, Result};
