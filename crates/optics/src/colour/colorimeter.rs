//! The colorimeter: spectral reflectance → XYZ → linear RGB for one observer, illuminant and
//! output space, as one weighted sum over the 1 nm grid.

use super::cie::{Illuminant, Observer, SPECTRAL_MIN_NM, lerp, locate, spectral_wavelength_nm};
use super::matrix::{Mat3, diag, mat_inv, mat_mul, mat_vec};
use super::space::{OutputSpace, bradford, normalised_primary_matrix};

/// Turns spectral reflectances into colours for one observer, illuminant and output
/// space, with everything that does not depend on the reflectance precomputed.
#[derive(Clone, Debug, PartialEq)]
pub struct Colorimeter {
    observer: Observer,
    illuminant: Illuminant,
    space: OutputSpace,
    white_xyz: [f64; 3],
    matrix: Mat3,
    inverse: Mat3,
    xyz_weights: Vec<[f64; 3]>,
    weights: Vec<[f64; 3]>,
}

#[cfg(test)]
impl Colorimeter {
    /// CIE 1931 2°, D65, linear sRGB: the colorimeter of the unit tests.
    pub(crate) fn srgb_d65() -> Colorimeter {
        Colorimeter::new(
            Observer::Cie1931_2Deg,
            Illuminant::D65,
            OutputSpace::Rgb(super::space::RgbSpace::Srgb),
        )
    }
}

impl Colorimeter {
    /// Precomputes the conversion for `observer`, `illuminant` and `space`.
    ///
    /// With S(λ) the illuminant, (x̄, ȳ, z̄) the observer and λᵢ = 360, 361, …, 830 nm:
    ///
    /// 1. **XYZ weights** u(λᵢ) = (x̄, ȳ, z̄)(λᵢ) S(λᵢ) / Σₖ ȳ(λₖ) S(λₖ), so that
    ///    XYZ = Σᵢ R(λᵢ) u(λᵢ) has Y = 1 for the perfect reflector, whose XYZ is the
    ///    illuminant white W_I = Σᵢ u(λᵢ) ([`Illuminant::white_xyz`]).
    /// 2. **Matrix M** from that XYZ to the output space:
    ///    * [`OutputSpace::Xyz`]: M = I. The perfect reflector gives W_I.
    ///    * [`OutputSpace::Rgb`]: the space's white W_S is computed the same way as W_I
    ///      ([`RgbSpace::white_xyz`]: D65 integrated against this observer, or the ACES
    ///      chromaticity at Y = 1). Then
    ///      M₀ = N(W_S)⁻¹ · A_Bradford(W_I → W_S), where N(W_S) is the
    ///      [`normalised_primary_matrix`] of the published primaries with white W_S.
    ///      This equals diag(1/c) · N⁻¹ · A with N the nominal matrix of
    ///      [`RgbSpace::rgb_to_xyz_matrix`] and c = N⁻¹ W_S. That is, the standard matrix
    ///      rescaled per channel so that the computed white is exactly neutral. For
    ///      the D65 spaces the rescaling is within 2.5 × 10⁻⁴ of 1 with the 1931
    ///      observer, and up to 1.7 × 10⁻² (blue) with the 1964 observer, whose D65
    ///      white (x, y) ≈ (0.3138, 0.3310) is far from the nominal 2° one: D65 stays
    ///      neutral whatever the observer.
    ///      Since A·W_I = W_S and N(W_S)·(1,1,1) = W_S, M₀·W_I = (1, 1, 1) in exact
    ///      arithmetic. Finally M = diag(1/σ) · M₀ with σ = Σᵢ M₀·u(λᵢ), the weight
    ///      sums as actually computed. σ differs from (1, 1, 1) only by rounding
    ///      (~10⁻¹⁵), and the rescaling makes [`Colorimeter::colour_of`] of R ≡ 1 equal
    ///      (1, 1, 1) to the last few bits.
    /// 3. **Output weights** w(λᵢ) = M · u(λᵢ), so that colour = Σᵢ R(λᵢ) w(λᵢ).
    pub fn new(observer: Observer, illuminant: Illuminant, space: OutputSpace) -> Self {
        let cmf = observer.cmf().xyz_bar();
        let power: Vec<f64> = (0..cmf.len())
            .map(|i| illuminant.power_at(spectral_wavelength_nm(i)))
            .collect();
        let norm: f64 = cmf.iter().zip(&power).map(|(c, s)| c[1] * s).sum();
        let xyz_weights: Vec<[f64; 3]> = cmf
            .iter()
            .zip(&power)
            .map(|(c, s)| c.map(|v| v * s / norm))
            .collect();
        let white_xyz = illuminant.white_xyz(observer);
        let matrix = match space {
            OutputSpace::Xyz => diag([1.0; 3]),
            OutputSpace::Rgb(rgb) => {
                let white_space = rgb.white_xyz(observer);
                let npm = normalised_primary_matrix(rgb.primaries_xy(), white_space);
                let m0 = mat_mul(&mat_inv(&npm), &bradford(white_xyz, white_space));
                let sigma = sum_weights(xyz_weights.iter().map(|u| mat_vec(&m0, *u)));
                mat_mul(&diag(sigma.map(|s| 1.0 / s)), &m0)
            }
        };
        let weights = xyz_weights.iter().map(|u| mat_vec(&matrix, *u)).collect();
        Colorimeter {
            observer,
            illuminant,
            space,
            white_xyz,
            matrix,
            inverse: mat_inv(&matrix),
            xyz_weights,
            weights,
        }
    }

    /// The observer.
    pub fn observer(&self) -> Observer {
        self.observer
    }

    /// The illuminant.
    pub fn illuminant(&self) -> Illuminant {
        self.illuminant
    }

    /// The output space.
    pub fn space(&self) -> OutputSpace {
        self.space
    }

    /// The illuminant's white W_I (XYZ, Y = 1) for this observer: the XYZ of the perfect
    /// reflector.
    pub fn white_xyz(&self) -> [f64; 3] {
        self.white_xyz
    }

    /// The matrix M: XYZ (under the illuminant, perfect reflector Y = 1) → output space,
    /// chromatic adaptation included (see [`Colorimeter::new`]).
    pub fn matrix(&self) -> Mat3 {
        self.matrix
    }

    /// Output weights w(λᵢ) = M · (x̄, ȳ, z̄)(λᵢ) S(λᵢ) / Σₖ ȳ(λₖ) S(λₖ) at
    /// λᵢ = 360 + i nm, i = 0 … 470 ([`spectral_wavelength_nm`]). The colour of a
    /// reflectance R is Σᵢ R(λᵢ) w(λᵢ): the CIE 015 rectangle rule at Δλ = 1 nm.
    /// Each weight is per sample (Δλ = 1 nm folded in). Σᵢ w(λᵢ) = (1, 1, 1) for RGB
    /// output and W_I for XYZ output.
    pub fn weights_1nm(&self) -> &[[f64; 3]] {
        &self.weights
    }

    /// The unadapted XYZ weights u(λᵢ) = (x̄, ȳ, z̄)(λᵢ) S(λᵢ) / Σₖ ȳ(λₖ) S(λₖ) on the
    /// same grid as [`Colorimeter::weights_1nm`].
    pub fn xyz_weights_1nm(&self) -> &[[f64; 3]] {
        &self.xyz_weights
    }

    /// The colour, in the output space, of a surface whose reflectance (or
    /// transmittance) at vacuum wavelength λ nm is `reflectance(λ)`:
    /// Σᵢ R(λᵢ) w(λᵢ), with `reflectance` called once at each λᵢ = 360, 361, …, 830 nm
    /// in increasing order.
    pub fn colour_of(&self, reflectance: impl FnMut(f64) -> f64) -> [f64; 3] {
        weighted_sum(&self.weights, reflectance)
    }

    /// The CIE XYZ (perfect reflector Y = 1, no chromatic adaptation) of a reflectance:
    /// Σᵢ R(λᵢ) u(λᵢ) with u the [`Colorimeter::xyz_weights_1nm`]. This is CIE 015's
    /// tristimulus sum divided by 100.
    pub fn xyz_of(&self, reflectance: impl FnMut(f64) -> f64) -> [f64; 3] {
        weighted_sum(&self.xyz_weights, reflectance)
    }

    /// The output weight as a continuous function of wavelength, per nm, for adaptive
    /// integration: colour ≈ ∫ R(λ) s(λ) dλ over 360–830 nm.
    ///
    /// s(λ) linearly interpolates the 1 nm weights ([`Colorimeter::weights_1nm`]) and
    /// is 0 outside 360–830 nm, so s(λᵢ) = w(λᵢ) at every whole nm. For a constant R,
    /// ∫ s dλ (the trapezoid rule on the same nodes) differs from the rectangle sum
    /// Σᵢ w(λᵢ) by −(w(360) + w(830))/2. That is at most 3.3 × 10⁻⁶ relative (the z̄/blue
    /// channel with the 1931 observer and illuminant E; 1.4 × 10⁻⁶ for sRGB under D65),
    /// because the CMFs nearly vanish at both ends.
    pub fn sensitivity_at(&self, wavelength_nm: f64) -> [f64; 3] {
        match locate(SPECTRAL_MIN_NM, self.weights.len(), wavelength_nm) {
            Some((i, t)) => {
                let (a, b) = (self.weights[i], self.weights[i + 1]);
                [
                    lerp(a[0], b[0], t),
                    lerp(a[1], b[1], t),
                    lerp(a[2], b[2], t),
                ]
            }
            None => [0.0; 3],
        }
    }

    /// Converts XYZ (under the illuminant, perfect reflector Y = 1) to the output space:
    /// M · xyz.
    pub fn output_from_xyz(&self, xyz: [f64; 3]) -> [f64; 3] {
        mat_vec(&self.matrix, xyz)
    }

    /// Converts an output-space colour back to XYZ under the illuminant: M⁻¹ · colour.
    pub fn xyz_from_output(&self, colour: [f64; 3]) -> [f64; 3] {
        mat_vec(&self.inverse, colour)
    }
}

/// Σᵢ vᵢ, component-wise.
fn sum_weights(values: impl Iterator<Item = [f64; 3]>) -> [f64; 3] {
    values.fold([0.0; 3], |acc, v| {
        [acc[0] + v[0], acc[1] + v[1], acc[2] + v[2]]
    })
}

/// Σᵢ R(λᵢ) wᵢ with λᵢ = 360 + i nm.
fn weighted_sum(weights: &[[f64; 3]], mut reflectance: impl FnMut(f64) -> f64) -> [f64; 3] {
    sum_weights(weights.iter().enumerate().map(|(i, w)| {
        let r = reflectance(spectral_wavelength_nm(i));
        w.map(|v| r * v)
    }))
}
