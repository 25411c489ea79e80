//! The powers a stack reflects and transmits ([`Power`]), the vacuum wavenumber, and the
//! slot a kernel writes one power into: the leaf that the scalar recurrence
//! ([`crate::stack`]) and the vectorised kernels ([`crate::multilayer`], [`crate::airy`])
//! share.

use std::f64::consts::PI;

/// Power reflectance and transmittance of a stack, per polarisation.
///
/// `#[repr(C)]`: four `f64` in field order (R_s, R_p, T_s, T_p), so that a slice of powers
/// is an (n, 4) array of `f64` for bindings (the Python package hands a sweep to numpy
/// without copying it).
#[allow(non_snake_case)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Power {
    /// Reflectance, s polarisation.
    pub R_s: f64,
    /// Reflectance, p polarisation.
    pub R_p: f64,
    /// Transmittance into the substrate, s polarisation.
    pub T_s: f64,
    /// Transmittance into the substrate, p polarisation.
    pub T_p: f64,
}

#[allow(non_snake_case)]
impl Power {
    /// Unpolarised reflectance (R_s + R_p) / 2.
    pub fn R(&self) -> f64 {
        0.5 * (self.R_s + self.R_p)
    }
    /// Unpolarised transmittance (T_s + T_p) / 2.
    pub fn T(&self) -> f64 {
        0.5 * (self.T_s + self.T_p)
    }
    /// Unpolarised absorptance A = 1 − R − T, never below 0: for a lossless stack R + T is 1
    /// up to rounding, and the difference can come out as −10⁻¹⁶.
    pub fn A(&self) -> f64 {
        (1.0 - self.R() - self.T()).max(0.0)
    }
}

/// Vacuum wavenumber k₀ = 2π/λ, in rad/nm.
#[inline]
pub fn wavenumber(wavelength_nm: f64) -> f64 {
    2.0 * PI / wavelength_nm
}

/// A place for one [`Power`]: initialised, or not yet (the sweeps' fresh output).
pub(crate) trait PowerSlot {
    fn put(&mut self, power: Power);
}

impl PowerSlot for Power {
    #[inline(always)]
    fn put(&mut self, power: Power) {
        *self = power;
    }
}

impl PowerSlot for std::mem::MaybeUninit<Power> {
    #[inline(always)]
    fn put(&mut self, power: Power) {
        self.write(power);
    }
}
