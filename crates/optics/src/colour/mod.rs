//! Colorimetry: from a spectral reflectance R(λ) to CIE XYZ and to linear RGB.
//!
//! # Data
//!
//! The CIE standard observers and illuminants are bundled from `tables/cie/` (see its
//! README) and parsed once, on first use:
//!
//! * [`Observer`]: CIE 1931 2° and CIE 1964 10° colour-matching functions x̄, ȳ, z̄,
//!   360–830 nm every 1 nm (CIE 015:2018; ISO/CIE 11664-1:2019);
//! * [`Illuminant`]: relative spectral power S(λ) of D65, D50 and A, 300–830 nm every
//!   1 nm (CIE 015:2018; ISO/CIE 11664-2), and the equal-energy E, S ≡ 1.
//!
//! # Tristimulus values
//!
//! CIE 015:2018 defines the tristimulus values of an object colour by a sum over
//! wavelength, recommending Δλ = 1 nm over 360–830 nm:
//!
//! ```text
//! X = k Σᵢ R(λᵢ) S(λᵢ) x̄(λᵢ) Δλ,   Y = k Σᵢ R(λᵢ) S(λᵢ) ȳ(λᵢ) Δλ,   Z = k Σᵢ R(λᵢ) S(λᵢ) z̄(λᵢ) Δλ
//! k = 1 / Σᵢ S(λᵢ) ȳ(λᵢ) Δλ
//! ```
//!
//! with λᵢ = 360, 361, …, 830 nm. nacre takes k so that the perfect reflector (R ≡ 1)
//! has Y = 1, where CIE 015 uses Y = 100. The XYZ of the perfect reflector is the
//! illuminant's white point [`Illuminant::white_xyz`].
//!
//! # Output spaces
//!
//! A [`Colorimeter`] fixes an observer, an illuminant and an [`OutputSpace`] (XYZ, or
//! one of four linear RGB spaces), and precomputes the per-wavelength weights that make
//! a colour a single weighted sum over 471 samples. For an RGB space the conversion
//! includes a Bradford chromatic adaptation ([`bradford`]) from the illuminant's white
//! to the space's white, so that the perfect reflector always comes out as exactly
//! RGB (1, 1, 1): see [`Colorimeter::new`] for the precise construction.
//!
//! # Colour difference
//!
//! [`xyz_to_lab`] gives CIE 1976 L\*a\*b\* (CIE 015:2018) and [`delta_e_2000`] the
//! CIEDE2000 colour difference (Sharma, Wu & Dalal 2005).
//!
//! ```
//! use nacre_optics::colour::{Colorimeter, Illuminant, Observer, OutputSpace, RgbSpace};
//! let c = Colorimeter::new(Observer::Cie1931_2Deg, Illuminant::D65, OutputSpace::Rgb(RgbSpace::Srgb));
//! let white = c.colour_of(|_wavelength_nm| 1.0);
//! assert!(white.iter().all(|v| (v - 1.0).abs() < 1e-12));
//! ```

mod cie;
mod colorimeter;
mod difference;
mod matrix;
mod space;
#[cfg(test)]
mod tests;

pub use cie::{
    CmfTable, Illuminant, Observer, SPECTRAL_MAX_NM, SPECTRAL_MIN_NM, SPECTRAL_SAMPLES,
    SPECTRAL_STEP_NM, spectral_wavelength_nm, xy_to_xyz, xyz_to_xy,
};
pub use colorimeter::Colorimeter;
pub use difference::{delta_e_2000, xyz_to_lab};
pub use matrix::Mat3;
pub use space::{BRADFORD, OutputSpace, RgbSpace, bradford, normalised_primary_matrix};
