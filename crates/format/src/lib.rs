//! # nacre-format
//!
//! The nacre table format, and nothing else: the typed JSON manifest every table ships with
//! ([`manifest::Manifest`], with a [`kind::TableKind`] and the kind's axes as
//! [`manifest::KindRecord`]), each kind's forward/inverse axis mappings and CPU lookups
//! ([`film_lut`], [`fourier`], [`rough_film_lut`], [`diffraction`]), the readers and writers
//! of table files (OpenEXR atlases and 16-bit PNG in [`table_io`], KTX 2.0 in [`ktx2`]),
//! atomic writes ([`atomic`]) and staged table commits ([`stage`]), the loaders that read a
//! table through its manifest ([`load`]), and the material references that
//! manifests and recipes name ([`materials`]: numbers, bundled materials, data files,
//! refractiveindex.info pages), the uniforms that mirror each kind's axes on the GPU
//! ([`gpu_params`]) and the import header of the WGSL modules that read them
//! ([`wgsl_header`]).
//!
//! No GPU, no TOML, no plotting: the runtime and engine integrations read tables through
//! this crate alone; `nacre-bake` writes them through it.

// `!(x > 0.0)` is how this crate rejects NaN together with out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod atomic;
pub mod checksum;
pub mod decode;
pub mod diffraction;
pub mod error;
pub mod export;
pub mod film_lut;
pub mod fourier;
pub mod gpu_params;
pub mod kind;
pub mod ktx2;
pub mod load;
pub mod manifest;
pub mod materials;
pub mod param;
pub mod rough_film_lut;
pub mod set;
pub mod stage;
pub mod table_io;
pub mod wgsl_header;

pub use error::{Error, Result};
pub use kind::TableKind;
pub use manifest::{AxisRecord, Encoding, FileFormat, FileRecord, KindRecord, Manifest};
pub use param::{Msg, Naming, Origin, Param, Render};
