//! Snell's law with complex cosines and the Fresnel amplitude coefficients of one
//! planar interface, valid for absorbing media and evanescent waves.
//!
//! # Symbols
//!
//! | symbol | code | meaning |
//! |---|---|---|
//! | ñ = n + iκ | `n_j: C64` | complex refractive index of medium j, κ ≥ 0 absorbs |
//! | θ₀ | `angle_deg` | incidence angle in the (non-absorbing) ambient medium |
//! | β = n₀ sin θ₀ | `beta` | tangential wave-vector component / k₀, conserved across every interface (Snell) |
//! | q_j = ñ_j cos θ_j | `q_j` | normal wave-vector component / k₀ in medium j |
//! | k₀ = 2π/λ | `k0` | vacuum wavenumber, λ in nm |
//! | r_s, r_p, t_s, t_p | fields of [`Interface`] | amplitude coefficients from medium i into medium j |
//!
//! # Conventions (those of Byrnes' `tmm` package, arXiv:1603.02720)
//!
//! * Time dependence `exp(−iωt)`; a wave travelling towards +z (into the stack) in medium j
//!   is `exp(i k₀ q_j z)`. Hence κ ≥ 0 means absorption and a forward wave must have
//!   Im q_j ≥ 0 so that it decays with depth.
//! * Snell's law in complex form: q_j = ±√(ñ_j² − β²). The branch is the *forward* one:
//!   Im q_j > 0 (the wave decays into the medium: absorbing media and evanescent waves
//!   beyond total internal reflection), or, when Im q_j vanishes (lossless, propagating),
//!   Re q_j > 0 (power flows into the medium). See [`normal_component`].
//! * s (TE) amplitudes are ratios of the electric field, p (TM) amplitudes ratios of the
//!   electric field with the p unit vectors chosen as in `tmm` and Born & Wolf, so that at
//!   normal incidence r_p = −r_s:
//!
//!   ```text
//!   r_s = (q_i − q_j) / (q_i + q_j)               t_s = 2 q_i / (q_i + q_j)
//!   r_p = (ñ_j² q_i − ñ_i² q_j) / (ñ_j² q_i + ñ_i² q_j)
//!   t_p = 2 ñ_i ñ_j q_i / (ñ_j² q_i + ñ_i² q_j)
//!   ```
//!
//!   which are the textbook `r_s = (n_i cos θ_i − n_j cos θ_j)/(n_i cos θ_i + n_j cos θ_j)`,
//!   `r_p = (n_j cos θ_i − n_i cos θ_j)/(n_j cos θ_i + n_i cos θ_j)`,
//!   `t_p = 2 n_i cos θ_i/(n_j cos θ_i + n_i cos θ_j)` (Born & Wolf §1.5; Byrnes Eq. 5–8)
//!   written with q = ñ cos θ so that no complex angle is ever formed. Both polarisations
//!   share the form `r = (y_i − y_j)/(y_i + y_j)` with the *admittances* `y_s = q`,
//!   `y_p = q / ñ²`.
//! * Power transmittance is the normal component of the Poynting vector that crosses into
//!   the exit medium, relative to the incident one (Byrnes Eq. 21–22):
//!   `T_s = |t_s|² Re(q_f) / Re(q_0)`, `T_p = |t_p|² Re(ñ_f conj(cos θ_f)) / Re(ñ_0 conj(cos θ_0))`.

use num_complex::Complex64 as C64;

/// Relative size below which the imaginary part of q is treated as zero when choosing the
/// forward branch (rounding noise of a lossless medium). Same role as `tmm`'s
/// `100 * EPSILON` test.
pub(crate) const BRANCH_TOLERANCE: f64 = 100.0 * f64::EPSILON;

/// The normal component `q = ñ cos θ` of the wave vector (in units of k₀) in a medium of
/// complex index `n`, for a tangential component `beta = n₀ sin θ₀` (Snell's law,
/// `q² = ñ² − β²`), on the forward branch described in the module docs.
#[inline]
pub fn normal_component(n: C64, beta: f64) -> C64 {
    let q = crate::elementary::csqrt(n * n - beta * beta);
    forward_branch(q)
}

/// Chooses the sign of `q` that describes a wave travelling or decaying towards +z:
/// Im q > 0, or Re q > 0 when Im q is rounding noise.
#[inline]
pub fn forward_branch(q: C64) -> C64 {
    let scale = q.re.abs().max(q.im.abs());
    let forward = if q.im.abs() > BRANCH_TOLERANCE * scale {
        q.im > 0.0
    } else {
        q.re >= 0.0
    };
    if forward { q } else { -q }
}

/// Fresnel amplitude coefficients of one interface, from medium i into medium j.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interface {
    /// Reflection amplitude for s (TE) polarisation.
    pub r_s: C64,
    /// Reflection amplitude for p (TM) polarisation.
    pub r_p: C64,
    /// Transmission amplitude for s polarisation.
    pub t_s: C64,
    /// Transmission amplitude for p polarisation.
    pub t_p: C64,
}

impl Interface {
    /// The interface from medium `n_i` (normal component `q_i`) into medium `n_j`
    /// (normal component `q_j`); see the module docs for the formulas.
    #[inline]
    pub fn new(n_i: C64, q_i: C64, n_j: C64, q_j: C64) -> Self {
        let sum_s = q_i + q_j;
        let r_s = (q_i - q_j) / sum_s;
        let t_s = 2.0 * q_i / sum_s;
        let ni2 = n_i * n_i;
        let nj2 = n_j * n_j;
        let a = nj2 * q_i;
        let b = ni2 * q_j;
        let sum_p = a + b;
        let r_p = (a - b) / sum_p;
        let t_p = 2.0 * n_i * n_j * q_i / sum_p;
        Interface { r_s, r_p, t_s, t_p }
    }
}

/// Ratio that turns |t_s|² into the s power transmittance between an incidence medium
/// (normal component `q_0`) and an exit medium (`q_f`): `Re(q_f) / Re(q_0)`.
#[inline]
pub fn power_factor_s(q_0: C64, q_f: C64) -> f64 {
    q_f.re / q_0.re
}

/// Ratio that turns |t_p|² into the p power transmittance:
/// `Re(ñ_f conj(cos θ_f)) / Re(ñ_0 conj(cos θ_0))` with `cos θ = q / ñ`.
#[inline]
pub fn power_factor_p(n_0: C64, q_0: C64, n_f: C64, q_f: C64) -> f64 {
    (n_f * (q_f / n_f).conj()).re / (n_0 * (q_0 / n_0).conj()).re
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> C64 {
        C64::new(re, im)
    }

    #[test]
    fn normal_incidence_matches_textbook() {
        let n1 = c(1.0, 0.0);
        let n2 = c(1.5, 0.0);
        let i = Interface::new(n1, n1, n2, n2);
        assert!((i.r_s.re - (-0.2)).abs() < 1e-15);
        assert!((i.r_p.re - 0.2).abs() < 1e-15);
        assert!((i.t_s.re - 0.8).abs() < 1e-15);
        // R + T = 1 at a lossless interface.
        let t = i.t_s.norm_sqr() * power_factor_s(n1, n2);
        assert!((i.r_s.norm_sqr() + t - 1.0).abs() < 1e-15);
    }

    #[test]
    fn brewster_angle_zeroes_r_p() {
        let (n1, n2) = (1.0f64, 1.5f64);
        let theta = (n2 / n1).atan();
        let beta = n1 * theta.sin();
        let q1 = normal_component(c(n1, 0.0), beta);
        let q2 = normal_component(c(n2, 0.0), beta);
        let i = Interface::new(c(n1, 0.0), q1, c(n2, 0.0), q2);
        assert!(i.r_p.norm() < 1e-15, "r_p = {}", i.r_p);
    }

    #[test]
    fn total_internal_reflection_is_evanescent_and_total() {
        let beta = 1.5 * 60f64.to_radians().sin();
        let q1 = normal_component(c(1.5, 0.0), beta);
        let q2 = normal_component(c(1.0, 0.0), beta);
        assert!(q2.re.abs() < 1e-15 && q2.im > 0.0, "q2 = {q2}");
        let i = Interface::new(c(1.5, 0.0), q1, c(1.0, 0.0), q2);
        assert!((i.r_s.norm() - 1.0).abs() < 1e-14);
        assert!((i.r_p.norm() - 1.0).abs() < 1e-14);
        assert_eq!(power_factor_s(q1, q2), 0.0);
    }

    #[test]
    fn absorbing_medium_decays_forward() {
        for beta in [0.0, 0.5, 0.99] {
            let q = normal_component(c(0.27, 2.9), beta);
            assert!(q.im > 0.0);
        }
        // A negative-zero imaginary part of ñ² − β² (principal root −i…) must not pick
        // the growing wave.
        let q = normal_component(C64::new(1.0, -0.0), 1.5);
        assert!(q.im > 0.0 && q.re == 0.0, "q = {q}");
    }
}
