//! Fitting stacks to data: a stack with free parameters and their bounds
//! ([`template::Template`]).
//!
//! No I/O: the commands read the data and the template, this module fits.

pub mod template;

pub use template::{Free, FreeKind, Template};
