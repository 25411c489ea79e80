//! # nacre-optics
//!
//! Pure physics and colorimetry for nacre, in f64: complex refractive indices and
//! dispersive materials ([`material`]), Snell's law and Fresnel coefficients for absorbing
//! media ([`fresnel`]), multilayer thin-film stacks ([`stack`]), and diffraction by surface
//! nanostructure from height fields ([`diffraction`]: Stam 1999, Dhillon et al. 2014).
//!
//! This crate does no file or GPU I/O: parsers take the text they are handed.
//!
//! ```
//! use nacre_optics::{Layer, Material, Stack};
//! // A 400 nm soap film (n = 1.33) in air, at normal incidence and 550 nm.
//! let air = Material::parse_index("1.0")?;
//! let water = Material::parse_index("1.33")?;
//! let stack = Stack::new(air.clone(), vec![Layer { material: water, thickness_nm: 400.0 }], air)?;
//! let r = stack.evaluate(0.0, 550.0)?.power;
//! assert!((r.R() + r.T() - 1.0).abs() < 1e-12); // lossless
//! # Ok::<(), nacre_optics::Error>(())
//! ```

// `!(x > 0.0)` is how this crate rejects NaN together with out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub(crate) mod airy;
pub mod colour;
pub mod csv_rows;
pub mod diffraction;
pub mod elementary;
pub mod error;
pub mod few_wavelengths;
pub mod film_series;
pub mod fit;
pub mod fourier;
pub mod fresnel;
pub mod incoherent;
pub mod jacobian;
pub mod material;
pub mod microfacet;
pub(crate) mod multilayer;
pub(crate) mod power;
pub mod quadrature;
pub(crate) mod simd;
pub mod spectral;
pub mod spectrum_sweep;
pub mod stack;

pub use colour::{Colorimeter, Illuminant, Observer, OutputSpace, RgbSpace};
pub use error::{Error, Result};
pub use material::{Material, MaterialWarning, WarningKind, WavelengthSpan};
pub use num_complex::Complex64 as C64;
pub use spectral::{FilmColours, SpectralRule};
pub use spectrum_sweep::SpectrumSweep;
pub use stack::{Amplitudes, Layer, Power, Prepared, Response, Stack, Undersampled};
