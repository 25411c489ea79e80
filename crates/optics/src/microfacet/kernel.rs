//! Deterministic GGX visible-normal kernels: the distribution of the microfacet cosine
//! c = cos θ_d = ω_o·h under the visible normals, weighted by G₂/G₁, on a uniform grid of
//! cosines. They turn the directional albedo of the iridescent lobe ([`super`], "Estimator")
//! into a one-dimensional integral over c, which the `rough-film-lut` baker of nacre-bake
//! evaluates as a matrix product (no Monte Carlo):
//!
//! ```text
//! E_r = ∫ D_ωo(h) F_R(ω_o·h) G₂(ω_o, ω_i)/G₁(ω_o) χ⁺(ω_i·n) dh = ∫₀¹ K_r(c; cos θ_o, α) F_R(c) dc
//! E_t = ∫ D_ωo(h) F_T(ω_o·h) G₂(ω_o, ω_t)/G₁(ω_o) χ⁻(ω_t·n) dh = ∫₀¹ K_t(c; cos θ_o, α, η) F_T(c) dc
//! ```
//!
//! with ω_i = 2(ω_o·h)h − ω_o, ω_t = [`refract`](ω_o, h, η) and the
//! height-correlated G₂ of [`super`]. The kernels do not depend on the film term F.
//!
//! # Quadrature (Heitz's disk spread onto cosine nodes)
//!
//! The visible-normal domain is Heitz's unit disk (Heitz, "Sampling the GGX Distribution of
//! Visible Normals", JCGT 7(4), 2018, Listing 1: the map (u₁, u₂) ∈ [0, 1]² → h of
//! [`sample_ggx_vndf`](super::sample_ggx_vndf) has constant density on the disk), so
//! E = ∫∫ F(ω_o·h(u₁, u₂)) g(u₁, u₂) du₁ du₂ with g = G₂/G₁ (0 below the horizon). The
//! integral is taken by a deterministic product rule: [`KERNEL_RADIAL_NODES`]-point
//! Gauss–Legendre ([`gauss_legendre_01`]) in v, u₁ = r² = 1 − (1 − v)² (nodes crowd the
//! rim, where GGX's tail lives), and the [`KERNEL_AZIMUTH_NODES`]-point midpoint rule in
//! u₂ = φ/2π (the trapezoid rule of a periodic function). Each node's weight is spread onto
//! a uniform grid of N_c cosines c_j = j/(N_c − 1) ([`kernel_cos`]; [`KERNEL_COS_NODES`] by
//! default) with the 4-point (cubic) Lagrange weights of its c ([`cubic_stencil`]), so that
//! Σ_j K_j F(c_j) = ∫ K F̃ with F̃ the cubic interpolant of F through the grid nodes.
//!
//! With F ≡ 1 the reflection kernel's mass is GGX's single-scattering albedo; it matches the
//! Monte Carlo reference [`directional_albedo_with`](super::directional_albedo_with) at 2²²
//! samples within its noise (test `furnace_kernel_matches_monte_carlo`). Every sum runs in a
//! fixed order, so the kernels are the same bits on every run and thread count.

use super::{VndfFrame, refract, smith_lambda};
use crate::elementary;
use crate::quadrature::{cubic_stencil, gauss_legendre_01};
use std::f64::consts::PI;

/// Nodes of the uniform grid of microfacet cosines c = ω_o·h on which the kernels are
/// tabulated (and a baker evaluates the film colours).
pub const KERNEL_COS_NODES: usize = 128;

/// Gauss–Legendre nodes in v, u₁ = 1 − (1 − v)² (u₁ the squared radius on Heitz's
/// visible-normal disk).
pub const KERNEL_RADIAL_NODES: usize = 128;

/// Midpoint nodes in u₂ (the azimuth on the disk).
pub const KERNEL_AZIMUTH_NODES: usize = 384;

/// Smallest view cosine cos θ_o the kernels use: smaller ones (and grazing views, where
/// Λ(ω_o) diverges) clamp to it.
pub const MIN_COS_THETA: f64 = 1e-6;

/// One kernel pair: K_r and K_t on a grid of cosine nodes ([`kernel_cos`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Kernel {
    /// Reflection kernel weights K_r(c_j).
    pub reflection: Vec<f64>,
    /// Transmission kernel weights K_t(c_j) (all 0 without a base index).
    pub transmission: Vec<f64>,
}

impl Kernel {
    /// First and one-past-last node with a nonzero weight in either kernel (`lo == hi`
    /// when both are zero everywhere).
    pub fn support(&self) -> (usize, usize) {
        let nz = |v: &f64| *v != 0.0;
        let lo = self
            .reflection
            .iter()
            .position(nz)
            .into_iter()
            .chain(self.transmission.iter().position(nz))
            .min()
            .unwrap_or(0);
        let hi = self
            .reflection
            .iter()
            .rposition(nz)
            .into_iter()
            .chain(self.transmission.iter().rposition(nz))
            .max()
            .map_or(0, |i| i + 1);
        (lo, hi.max(lo))
    }
}

/// The cosine of node j of an `n`-node c grid: j / (n − 1).
pub fn kernel_cos(j: usize, n: usize) -> f64 {
    j as f64 / (n - 1) as f64
}

/// The reflection and transmission kernels of view cosine `cos_theta_o` and roughness
/// `alpha` on an `n_c`-node c grid (see the module docs), with relative base index `eta`
/// for transmission. Deterministic: the nodes are summed in a fixed order.
pub fn kernels(cos_theta_o: f64, alpha: f64, eta: Option<f64>, n_c: usize) -> Kernel {
    kernels_with(
        cos_theta_o,
        alpha,
        eta,
        n_c,
        KERNEL_RADIAL_NODES,
        KERNEL_AZIMUTH_NODES,
    )
}

/// [`kernels`] with explicit quadrature orders (radial Gauss–Legendre nodes, azimuthal
/// midpoint nodes).
pub fn kernels_with(
    cos_theta_o: f64,
    alpha: f64,
    eta: Option<f64>,
    n_c: usize,
    radial: usize,
    azimuth: usize,
) -> Kernel {
    let c_o = cos_theta_o.clamp(MIN_COS_THETA, 1.0);
    let wo = [(1.0 - c_o * c_o).max(0.0).sqrt(), 0.0, c_o];
    let lambda_o = smith_lambda(wo, alpha);
    let g1_o = 1.0 / (1.0 + lambda_o);
    // Gauss–Legendre in v with u₁ = 1 − (1 − v)² (du₁ = 2(1 − v) dv): nodes crowd the disk's
    // rim, where GGX's long tail lives (a mass ≈ α² beyond 45° at normal view) and where
    // N_z = √(1 − r²) has its square-root edge, which the substitution makes linear in v.
    let (vs, wvs) = gauss_legendre_01(radial);
    let (u1s, w1s): (Vec<f64>, Vec<f64>) = vs
        .iter()
        .zip(&wvs)
        .map(|(&v, &w)| (1.0 - (1.0 - v) * (1.0 - v), 2.0 * (1.0 - v) * w))
        .unzip();
    let mut k = Kernel {
        reflection: vec![0.0; n_c],
        transmission: vec![0.0; n_c],
    };
    let scale = (n_c - 1) as f64;
    // sample_ggx_vndf(wo, α, u₁, u₂) with its view-only part and the azimuths' sin/cos
    // computed once (the same operations, the same bits).
    let frame = VndfFrame::new(wo, alpha);
    let phis: Vec<(f64, f64)> = (0..azimuth)
        .map(|i| elementary::sin_cos(2.0 * PI * ((i as f64 + 0.5) / azimuth as f64)))
        .collect();
    for (&u1, &w1) in u1s.iter().zip(&w1s) {
        let w = w1 / azimuth as f64;
        let r = u1.sqrt();
        for &(sin_phi, cos_phi) in &phis {
            let h = frame.sample(r, sin_phi, cos_phi);
            let cos_d = wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2];
            if cos_d <= 0.0 {
                continue;
            }
            let (start, lw) = cubic_stencil(cos_d * scale, n_c);
            let wi = std::array::from_fn(|c| 2.0 * cos_d * h[c] - wo[c]);
            if wi[2] > 0.0 {
                let g = w / (1.0 + lambda_o + smith_lambda(wi, alpha)) / g1_o;
                for (slot, w) in k.reflection[start..start + 4].iter_mut().zip(lw) {
                    *slot += g * w;
                }
            }
            if let Some(eta) = eta
                && let Some(wt) = refract(wo, h, cos_d, eta)
                && wt[2] < 0.0
            {
                let g = w / (1.0 + lambda_o + smith_lambda(wt, alpha)) / g1_o;
                for (slot, w) in k.transmission[start..start + 4].iter_mut().zip(lw) {
                    *slot += g * w;
                }
            }
        }
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::{Colorimeter, Illuminant, Observer, OutputSpace, RgbSpace};
    use crate::microfacet::{FilmTerm, directional_albedo_with};

    #[test]
    fn kernel_of_a_smooth_surface_is_a_spike_at_the_view_cosine() {
        // α → 0: every visible normal is n, c = cos θ_o, G₂/G₁ → 1.
        let k = kernels_with(0.6, 1e-4, None, 256, 16, 16);
        let mass: f64 = k.reflection.iter().sum();
        assert!((mass - 1.0).abs() < 1e-6, "{mass}");
        let mean: f64 = k
            .reflection
            .iter()
            .enumerate()
            .map(|(j, w)| w * kernel_cos(j, 256))
            .sum();
        assert!((mean - 0.6).abs() < 1e-4, "{mean}");
        let (lo, hi) = k.support();
        assert!(lo < hi && kernel_cos(lo, 256) < 0.6 && kernel_cos(hi - 1, 256) > 0.6);
        assert!(k.transmission.iter().all(|&w| w == 0.0));
    }

    /// With F ≡ 1 the reflection kernel's mass is GGX's single-scattering albedo: the
    /// deterministic quadrature against the Monte Carlo reference at 2²² samples.
    #[test]
    fn furnace_kernel_matches_monte_carlo() {
        let srgb = Colorimeter::new(
            Observer::Cie1931_2Deg,
            Illuminant::D65,
            OutputSpace::Rgb(RgbSpace::Srgb),
        );
        let mirror = FilmTerm::perfect_mirror(&srgb);
        for &(cos_o, alpha) in &[(1.0, 0.02), (0.9, 0.5), (0.3, 0.5), (0.9, 1.0), (0.1, 1.0)] {
            let mass: f64 = kernels(cos_o, alpha, None, KERNEL_COS_NODES)
                .reflection
                .iter()
                .sum();
            let mc = directional_albedo_with(&mirror, alpha, cos_o, 1 << 22, 11).unwrap();
            let (e, se) = (mc.reflection.colour[1], mc.reflection.standard_error[1]);
            eprintln!(
                "cos θ_o {cos_o} α {alpha}: quadrature {mass:.6}, Monte Carlo {e:.6} ± {se:.1e}"
            );
            assert!(
                (mass - e).abs() <= 4.0 * se + 1e-4,
                "{cos_o} {alpha}: {mass} vs {e} ± {se}"
            );
            assert!(mass <= 1.0 + 1e-9);
        }
    }
}
