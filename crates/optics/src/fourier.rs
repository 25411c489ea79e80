//! Analytic spectral integration of thin-film colour in the Fourier domain
//! (Belcour & Barla 2017, "A Practical Extension to Microfacet Theory for the Modeling of
//! Varying Iridescence", §4, Eq. 5–10), and the Gaussian-fit shortcut used by glTF's
//! `KHR_materials_iridescence`.
//!
//! # Symbols
//!
//! | symbol | code | meaning |
//! |---|---|---|
//! | s_j(λ) | [`Colorimeter::sensitivity_at`] | output-space sensitivity of channel j (may be negative for RGB) |
//! | ‖s_j‖ = ∫ s_j dλ | `norm` | the channel's white (1 for RGB) |
//! | D = 2 d q₂ | `opd_nm` | optical path difference of the film, q₂ = √(n₂² − n₁² sin²θ₁) |
//! | Φ(λ) = 2π D / λ | | round-trip phase, without the reflection phases |
//! | Ŝ_j(μ) | [`SensitivitySpectrum::transform`] | Ŝ_j(μ) = ∫ s_j(λ) e^{−2πiμ/λ} dλ / ‖s_j‖ |
//! | r₁₂, Γ | `r12`, `gamma` | film-top Fresnel amplitude, and base reflection seen from inside the film |
//!
//! # Sign convention of the transform
//!
//! With ν = 1/λ and S_j(ν) = s_j(1/ν) / (‖s_j‖ ν²) (so that S_j(ν) dν = s_j(λ) dλ / ‖s_j‖,
//! Belcour & Barla Eq. 8), Ŝ_j(μ) = ∫ S_j(ν) e^{−2πiμν} dν: the forward transform with a
//! negative exponent, Ŝ_j(0) = 1. A spectral term cos(mΦ + φ) integrates to
//! Re(e^{iφ} conj Ŝ_j(mD)) (tested in `cosine_integrates_through_the_transform`).
//!
//! # The Airy series (Belcour & Barla Eq. 5–6, written in closed form)
//!
//! The film's amplitude is r = r₁₂ + Σ_{k≥1} β ρ^{k−1} e^{ikΦ} with β = (1 − r₁₂²) Γ and
//! ρ = −r₁₂ Γ (the recurrence of [`crate::stack`] unrolled; for non-dispersive media r₁₂ and
//! Γ do not depend on λ). Hence R = |r|² = c₀ + 2 Σ_{m≥1} Re(c_m e^{imΦ}) with
//!
//! ```text
//! c₀ = |r₁₂|² + |β|² / (1 − |ρ|²)
//! c_m = ρ^{m−1} K,   K = β r₁₂* + |β|² ρ / (1 − |ρ|²)
//! ```
//!
//! and the colour of channel j is (Eq. 10)
//! `C_j = ‖s_j‖ [c₀ + 2 Σ_{m=1}^{M} Re(c_m conj Ŝ_j(m D))]`, averaged over s and p.
//! Reflection phases are carried by the complex c_m: Fresnel amplitudes are exact for
//! dielectric and conductor bases (not Schlick), and total internal reflection at the base
//! (|Γ| = 1) needs nothing special.
//!
//! # How many harmonics: [`Harmonics::Auto`], the default
//!
//! The terms decay like |ρ|^m (the Airy series) times |Ŝ_j(m D)| (the sensitivities'
//! transforms fall from 1 at μ = 0 to ≈ 10⁻² at 10 µm and ≈ 10⁻⁴ at 100 µm: thick films need
//! few harmonics even where |ρ| is large). Auto sums harmonics m = 1, 2, … and stops after
//! the first m at which, for every channel j and polarisation,
//!
//! ```text
//! 2 |K| |ρ|^m / (1 − |ρ|) · max_j |Ŝ_j(m D)|  ≤  ε · max(c̄₀,j, Y_floor)^(2/3)
//! ```
//!
//! (at most [`MAX_AUTO_HARMONICS`]): the tail bound of the remaining terms with |Ŝ| at the
//! last harmonic standing in for its decay, against a tolerance ε = [`AUTO_TOLERANCE`] scaled
//! to the channel's mean level c̄₀,j (the s/p average of c₀; floor Y_floor =
//! [`AUTO_LEVEL_FLOOR`]). The 2/3 power holds ΔE roughly constant: L* ∝ Y^(1/3), so
//! dL* = (116/3) Y^(−2/3) dY, and the same ΔE allows an error ∝ Y^(2/3) — dark films (a
//! free low-index film reflects a few per cent) get a tighter bound than bright metals.
//! ε was tuned to the ΔE2000 targets (p95 ≤ 0.1, max ≤ 0.5 on dielectric bases including
//! free films, p95 ≤ 0.3, max ≤ 1.0 on conductors; `BENCHMARKS.md`, test
//! `fourier_default` of nacre-tests): a fixed M = 3 reaches ΔE2000 0.7 on a free film of
//! index 2.26 near Brewster's angle (|ρ| = r₁₂² ≈ 0.45 for s) and several units on free
//! films at grazing angles, while Auto uses 1–3 harmonics for most films.
//!
//! # Prefiltering (Belcour & Barla §5)
//!
//! If the thickness within a pixel is Gaussian with standard deviation σ_d, D is Gaussian
//! with standard deviation τ σ_d, τ = 2 q₂, and the m-th harmonic averages Ŝ_j over a Gaussian
//! of standard deviation m τ σ_d in μ. In the spectral domain that is the damping
//! exp(−(2π σ_μ / λ)² / 2) of each wavelength, which [`SensitivitySpectrum::transform`]
//! applies exactly.

use crate::colour::Colorimeter;
use crate::elementary;
use crate::fresnel::{Interface, normal_component, power_factor_p, power_factor_s};
use crate::spectral::SpectralRule;
use num_complex::Complex64 as C64;
use std::f64::consts::PI;

/// Filon cells per nanometre in [`SensitivitySpectrum`].
pub const SUBCELLS: usize = 8;

/// Thickness below which fixed-harmonic evaluation blends the film index towards the
/// ambient's (Belcour & Barla 2017 §4), nm.
pub const THIN_FILM_BLEND_NM: f64 = 30.0;

/// Largest number of harmonics [`Harmonics::Auto`] will use (the GPU's
/// `FOURIER_MAX_HARMONICS`).
pub const MAX_AUTO_HARMONICS: usize = 128;

/// Tolerance ε of [`Harmonics::Auto`]'s stopping rule, in reflectance (or transmittance)
/// units at a mean level of 1; scaled by the level to the power 2/3 (module docs).
pub const AUTO_TOLERANCE: f64 = 1e-3;

/// Lowest mean level the tolerance of [`Harmonics::Auto`] is scaled to (Y = 0.01, L* ≈ 9).
pub const AUTO_LEVEL_FLOOR: f64 = 0.01;

/// How many harmonics of the Airy series to sum.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Harmonics {
    /// m = 1 … M.
    Fixed(usize),
    /// As many as the stopping rule of the module docs requires (at most
    /// [`MAX_AUTO_HARMONICS`]): the default of `nacre color --method fourier` and of the GPU
    /// technique.
    #[default]
    Auto,
}

/// The tolerance of [`Harmonics::Auto`] for a channel whose mean level (s/p average of c₀)
/// is `level`: ε · max(level, floor)^(2/3).
pub fn auto_tolerance(level: f64) -> f64 {
    AUTO_TOLERANCE * elementary::powf(level.max(AUTO_LEVEL_FLOOR), 2.0 / 3.0)
}

/// The sensitivities of a colorimeter in the frequency domain ν = 1/λ, ready for Fourier
/// transforms at any μ.
///
/// Ŝ_j(μ) = ∫ S_j(ν) e^{−2πiμν} dν is evaluated by Filon's method (L. N. G. Filon, Proc. R.
/// Soc. Edinburgh 49, 38–47, 1928; Davis & Rabinowitz §2.10): S_j(ν) = s_j(1/ν)/ν² (s_j the
/// linearly interpolated 1 nm sensitivities) is interpolated linearly in ν between nodes
/// 1/[`SUBCELLS`] nm apart over 360–830 nm, and each cell is integrated against the
/// exponential exactly, so the cost does not grow with μ and there is no aliasing however
/// large μ is. Ŝ_j(0) = 1 by normalisation. Against Gauss–Legendre quadrature aligned with
/// the 1 nm knots of the tables (the λ-linear interpolant, no kinks inside a cell) it agrees
/// to better than 10⁻⁶ for μ up to 160 µm (test `filon_is_within_1e6_of_a_knot_aligned_reference`);
/// a plain adaptive rule whose cells straddle the knots differs by ≈ 4·10⁻⁶, its own error
/// (`filon_matches_direct_quadrature`).
#[derive(Clone, Debug, PartialEq)]
pub struct SensitivitySpectrum {
    /// νᵢ in 1/nm, increasing.
    nu: Vec<f64>,
    /// S_j(νᵢ) = s_j(λᵢ) λᵢ², unnormalised.
    values: Vec<[f64; 3]>,
    /// Σ of the μ = 0 integrals, per channel.
    norm: [f64; 3],
}

impl SensitivitySpectrum {
    /// Prepares `colorimeter`'s output sensitivities.
    pub fn new(colorimeter: &Colorimeter) -> Self {
        let w = colorimeter.weights_1nm();
        let cells = (w.len() - 1) * SUBCELLS;
        let mut nu = Vec::with_capacity(cells + 1);
        let mut values = Vec::with_capacity(cells + 1);
        for k in (0..=cells).rev() {
            let wl = crate::colour::SPECTRAL_MIN_NM + k as f64 / SUBCELLS as f64;
            nu.push(1.0 / wl);
            values.push(colorimeter.sensitivity_at(wl).map(|v| v * wl * wl));
        }
        let mut this = SensitivitySpectrum {
            nu,
            values,
            norm: [1.0; 3],
        };
        let raw = this.transform(0.0, 0.0);
        this.norm = raw.map(|v| v.re);
        this
    }

    /// The centroid frequency ν̄_j = ∫ ν |S_j(ν)| dν / ∫ |S_j(ν)| dν of each channel, 1/nm:
    /// the carrier that [`SensitivitySpectrum::transform`] oscillates at. Multiplying Ŝ_j(μ)
    /// by e^{+2πiμν̄_j} leaves a slowly varying envelope that interpolates well.
    pub fn centroid_nu(&self) -> [f64; 3] {
        std::array::from_fn(|j| {
            let (mut num, mut den) = (0.0, 0.0);
            for i in 0..self.nu.len() - 1 {
                let h = self.nu[i + 1] - self.nu[i];
                let (a, b) = (self.values[i][j].abs(), self.values[i + 1][j].abs());
                num += 0.5 * h * (a * self.nu[i] + b * self.nu[i + 1]);
                den += 0.5 * h * (a + b);
            }
            num / den
        })
    }

    /// Ŝ_j(μ), prefiltered by a Gaussian of standard deviation `sigma_mu_nm` in μ
    /// (multiplying S_j(ν) by exp(−(2π σ_μ ν)²/2); 0 for none).
    pub fn transform(&self, mu_nm: f64, sigma_mu_nm: f64) -> [C64; 3] {
        self.transform_damped(mu_nm, &self.damped(sigma_mu_nm))
    }

    /// The node values S_j(νᵢ) exp(−(2π σ_μ νᵢ)²/2) of the prefilter `sigma_mu_nm` (0 for
    /// none), for [`SensitivitySpectrum::transform_damped`]: many μ at one σ_μ (a mip level
    /// of the `fourier` table) share them.
    pub fn damped(&self, sigma_mu_nm: f64) -> Vec<[f64; 3]> {
        let damp = |nu: f64| {
            if sigma_mu_nm > 0.0 {
                let x = 2.0 * PI * sigma_mu_nm * nu;
                elementary::exp(-0.5 * (x * x))
            } else {
                1.0
            }
        };
        self.nu
            .iter()
            .zip(&self.values)
            .map(|(&nu, v)| {
                let d = damp(nu);
                v.map(|v| v * d)
            })
            .collect()
    }

    /// Ŝ_j(μ) with the node values `damped` of [`SensitivitySpectrum::damped`] (the same
    /// bits as [`SensitivitySpectrum::transform`] at that σ_μ).
    pub fn transform_damped(&self, mu_nm: f64, damped: &[[f64; 3]]) -> [C64; 3] {
        let omega = 2.0 * PI * mu_nm;
        let cells = self.nu.len() - 1;
        // The phases e^{−iωνᵢ} and the cells' e^{−iωhᵢ}, by the vectorised deterministic
        // sin/cos of `crate::simd` (the same bits on every CPU).
        let mut arg = Vec::with_capacity(2 * cells);
        arg.extend(self.nu[..cells].iter().map(|&a| -omega * a));
        arg.extend(self.nu.windows(2).map(|p| -(omega * (p[1] - p[0]))));
        let (mut sin, mut cos) = (vec![0.0; 2 * cells], vec![0.0; 2 * cells]);
        crate::simd::sin_cos_slice(&arg, &mut sin, &mut cos);
        let mut sum = [C64::new(0.0, 0.0); 3];
        for i in 0..cells {
            let (a, b) = (self.nu[i], self.nu[i + 1]);
            let h = b - a;
            let (fa, fb) = (damped[i], damped[i + 1]);
            let e = C64::new(cos[cells + i], sin[cells + i]);
            let (wa, wb) = filon_weights(omega, h, e);
            let phase = C64::new(cos[i], sin[i]);
            for j in 0..3 {
                // ∫ (f_a + (f_b − f_a) t / h) e^{−iω(a + t)} dt = e^{−iωa} (f_a A + (f_b − f_a) B / h)
                sum[j] += phase * (wa * fa[j] + wb * ((fb[j] - fa[j]) / h));
            }
        }
        std::array::from_fn(|j| sum[j] / self.norm[j])
    }
}

/// A = ∫₀ʰ e^{−iωt} dt and B = ∫₀ʰ t e^{−iωt} dt, with Taylor series for small ωh;
/// `e` = e^{−iωh}.
fn filon_weights(omega: f64, h: f64, e: C64) -> (C64, C64) {
    let theta = omega * h;
    let i = C64::new(0.0, 1.0);
    if theta.abs() < 1e-2 {
        // A = h Σ (−iθ)^k/(k+1)!, B = h² Σ (−iθ)^k k!… written out to θ⁴.
        let t = C64::new(0.0, -theta);
        let a = h * (1.0 + t / 2.0 + t * t / 6.0 + t * t * t / 24.0 + t * t * t * t / 120.0);
        let b = h * h * (0.5 + t / 3.0 + t * t / 8.0 + t * t * t / 30.0 + t * t * t * t / 144.0);
        (a, b)
    } else {
        let a = (1.0 - e) / (i * omega);
        let b = i * h * e / omega - (1.0 - e) / (omega * omega);
        (a, b)
    }
}

/// Ŝ_j(μ) for each channel of `colorimeter`, prefiltered by a Gaussian of standard
/// deviation `sigma_mu_nm` in μ (0 for none). Convenience wrapper of
/// [`SensitivitySpectrum`]; prepare one when evaluating many μ.
pub fn sensitivity_transform(colorimeter: &Colorimeter, mu_nm: f64, sigma_mu_nm: f64) -> [C64; 3] {
    SensitivitySpectrum::new(colorimeter).transform(mu_nm, sigma_mu_nm)
}

/// Ŝ_j(μ) by direct adaptive quadrature in λ with `rule` (which must resolve |μ|): the
/// independent check of [`SensitivitySpectrum`].
pub fn transform_with_rule(rule: &SpectralRule, mu_nm: f64, sigma_mu_nm: f64) -> [C64; 3] {
    let mut sum = [C64::new(0.0, 0.0); 3];
    let mut norm = [0.0; 3];
    for (&wl, w) in rule.wavelengths_nm().iter().zip(rule.weights()) {
        let phase = -2.0 * PI * mu_nm / wl;
        let damping = if sigma_mu_nm > 0.0 {
            let x = 2.0 * PI * sigma_mu_nm / wl;
            elementary::exp(-0.5 * (x * x))
        } else {
            1.0
        };
        let e = elementary::from_polar(damping, phase);
        for j in 0..3 {
            sum[j] += e * w[j];
            norm[j] += w[j];
        }
    }
    std::array::from_fn(|j| sum[j] / norm[j])
}

/// Closed-form Airy Fourier coefficients of one polarisation: R = c₀ + 2 Σ Re(c_m e^{imΦ}),
/// c_m = ρ^{m−1} K.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AirySeries {
    /// The DC term c₀.
    pub c0: f64,
    /// K = c₁.
    pub k: C64,
    /// The ratio ρ = −r₁₂ Γ.
    pub rho: C64,
}

impl AirySeries {
    /// The series of the reflectance of a film with top amplitude `r12` and base reflection
    /// `gamma` seen from inside the film (module docs).
    pub fn new(r12: C64, gamma: C64) -> Self {
        let beta = (1.0 - r12 * r12) * gamma;
        let rho = -r12 * gamma;
        let inv = 1.0 / (1.0 - rho.norm_sqr());
        AirySeries {
            c0: r12.norm_sqr() + beta.norm_sqr() * inv,
            k: beta * r12.conj() + beta.norm_sqr() * rho * inv,
            rho,
        }
    }

    /// The bound 2|c_{m+1}| / (1 − |ρ|) of the terms after harmonic m, from |c_m| (the
    /// module docs' stopping rule, before the |Ŝ| factor).
    fn tail_after(&self, cm_norm: f64) -> f64 {
        let r = elementary::norm(self.rho);
        2.0 * cm_norm * r / (1.0 - r).max(1e-12)
    }
}

/// A single film (real index `n_film`) between a non-absorbing ambient `n_ambient` and a
/// base of complex index `base` (per output channel), seen at `cos_theta`.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmOnBase {
    /// Ambient index n₁ (real).
    pub n_ambient: f64,
    /// Film index n₂ (real).
    pub n_film: f64,
    /// Base index per output channel (the base's index at the channel's centroid
    /// wavelength; the same value thrice for a non-dispersive base).
    pub base: [C64; 3],
}

/// The result of [`FilmOnBase::fourier_colour`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FourierColour {
    /// Output-space colour.
    pub colour: [f64; 3],
    /// Harmonics summed (for [`Harmonics::Auto`], until every channel and polarisation met
    /// the stopping rule).
    pub harmonics: usize,
}

impl FilmOnBase {
    /// The film's normal component q₂ = √(n₂² − n₁² sin²θ₁), or None when the film is
    /// evanescent (n₂ < n₁ sin θ₁), where the spectrum is not a Fourier series in 1/λ.
    pub fn film_q(&self, cos_theta: f64) -> Option<f64> {
        let sin2 = 1.0 - cos_theta * cos_theta;
        let q2 = self.n_film * self.n_film - self.n_ambient * self.n_ambient * sin2;
        (q2 > 0.0).then(|| q2.sqrt())
    }

    /// Airy series of channel j for (s, p): of the reflectance, or of the transmittance
    /// into the base, T = A / |1 − ρ e^{iΦ}|² = A/(1 − |ρ|²) [1 + 2 Σ Re(ρ^m e^{imΦ})] with
    /// A = |t₁₂ t₂₃|² × the power factor of [`crate::fresnel`] (Belcour & Barla 2017,
    /// appendix, in closed form).
    fn series(
        &self,
        n_film: f64,
        cos_theta: f64,
        j: usize,
        transmittance: bool,
    ) -> [AirySeries; 2] {
        let n1 = C64::new(self.n_ambient, 0.0);
        let n2 = C64::new(n_film, 0.0);
        let beta = self.n_ambient * (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let (q1, q2, q3) = (
            normal_component(n1, beta),
            normal_component(n2, beta),
            normal_component(self.base[j], beta),
        );
        let top = Interface::new(n1, q1, n2, q2);
        let bottom = Interface::new(n2, q2, self.base[j], q3);
        let reflect = [
            AirySeries::new(top.r_s, bottom.r_s),
            AirySeries::new(top.r_p, bottom.r_p),
        ];
        if !transmittance {
            return reflect;
        }
        let factor = [
            power_factor_s(q1, q3),
            power_factor_p(n1, q1, self.base[j], q3),
        ];
        let t = [(top.t_s, bottom.t_s), (top.t_p, bottom.t_p)];
        std::array::from_fn(|pol| {
            let rho = reflect[pol].rho;
            let a = (t[pol].0 * t[pol].1).norm_sqr() * factor[pol] / (1.0 - rho.norm_sqr());
            AirySeries {
                c0: a,
                k: a * rho,
                rho,
            }
        })
    }

    /// Belcour & Barla Eq. 10 with exact Fresnel terms: the colour of the film's
    /// unpolarised reflectance (or, with `transmittance`, its transmittance into the base,
    /// for bases that transmit) at thickness `thickness_nm`, optionally prefiltered for a
    /// Gaussian thickness distribution of standard deviation `sigma_d_nm`.
    ///
    /// With a fixed number of harmonics the film index is blended towards the ambient's as
    /// the film vanishes, n₂' = n₁ + (n₂ − n₁) smoothstep(0, 30 nm, d) (Belcour & Barla §4:
    /// "we force η₂ → 1 when d → 0"): a truncated series cannot reproduce the bare base at
    /// d = 0, while with n₂' = n₁ the film term vanishes and the result is exact there.
    /// [`Harmonics::Auto`] sums until the remaining terms are below its tolerance (at d = 0
    /// too) and needs no blend.
    /// Returns None for an evanescent film (use the spectral reference there).
    pub fn fourier_colour(
        &self,
        colorimeter: &Colorimeter,
        cos_theta: f64,
        thickness_nm: f64,
        harmonics: Harmonics,
        sigma_d_nm: f64,
        transmittance: bool,
    ) -> Option<FourierColour> {
        let spectrum = SensitivitySpectrum::new(colorimeter);
        self.fourier_colour_with(
            colorimeter,
            cos_theta,
            thickness_nm,
            harmonics,
            sigma_d_nm,
            transmittance,
            |mu, sigma| spectrum.transform(mu, sigma),
        )
    }

    /// [`FilmOnBase::fourier_colour`] with Ŝ_j(μ, σ_μ) supplied by `transform` (e.g. a baked,
    /// mip-mapped table sampled as a GPU would).
    #[allow(clippy::too_many_arguments)]
    pub fn fourier_colour_with(
        &self,
        colorimeter: &Colorimeter,
        cos_theta: f64,
        thickness_nm: f64,
        harmonics: Harmonics,
        sigma_d_nm: f64,
        transmittance: bool,
        transform: impl Fn(f64, f64) -> [C64; 3],
    ) -> Option<FourierColour> {
        let n_film = match harmonics {
            Harmonics::Fixed(_) => {
                let t = (thickness_nm / THIN_FILM_BLEND_NM).clamp(0.0, 1.0);
                self.n_ambient + (self.n_film - self.n_ambient) * t * t * (3.0 - 2.0 * t)
            }
            Harmonics::Auto => self.n_film,
        };
        let blended = FilmOnBase {
            n_film,
            ..self.clone()
        };
        let q2 = blended.film_q(cos_theta)?;
        let opd = 2.0 * thickness_nm * q2;
        let tau = 2.0 * q2;
        let white = colorimeter
            .weights_1nm()
            .iter()
            .fold([0.0; 3], |a, w| [a[0] + w[0], a[1] + w[1], a[2] + w[2]]);
        let series: [[AirySeries; 2]; 3] =
            std::array::from_fn(|j| self.series(n_film, cos_theta, j, transmittance));
        let m_max = match harmonics {
            Harmonics::Fixed(m) => m,
            Harmonics::Auto => MAX_AUTO_HARMONICS,
        };
        let mut colour = [0.0; 3];
        for (j, c) in colour.iter_mut().enumerate() {
            *c = 0.5 * (series[j][0].c0 + series[j][1].c0);
        }
        // Auto's tolerance per channel, from its mean level.
        let tolerance: [f64; 3] = std::array::from_fn(|j| auto_tolerance(colour[j]));
        let mut cm = [[C64::new(0.0, 0.0); 2]; 3];
        let mut summed = 0;
        for m in 1..=m_max {
            let s_hat = transform(m as f64 * opd, m as f64 * tau * sigma_d_nm);
            for j in 0..3 {
                let mut sum = 0.0;
                for pol in 0..2 {
                    let s = &series[j][pol];
                    cm[j][pol] = if m == 1 { s.k } else { cm[j][pol] * s.rho };
                    sum += (cm[j][pol] * s_hat[j].conj()).re;
                }
                colour[j] += sum; // 2 Re(…) averaged over two polarisations
            }
            summed = m;
            if harmonics == Harmonics::Auto {
                let s_max = s_hat
                    .iter()
                    .map(|&v| elementary::norm(v))
                    .fold(0.0, f64::max);
                let converged = (0..3).all(|j| {
                    (0..2).all(|pol| {
                        series[j][pol].tail_after(elementary::norm(cm[j][pol])) * s_max
                            <= tolerance[j]
                    })
                });
                if converged {
                    break;
                }
            }
        }
        Some(FourierColour {
            colour: std::array::from_fn(|j| colour[j] * white[j]),
            harmonics: summed,
        })
    }
}

/// The Gaussian fit of the XYZ sensitivities' Fourier transforms published with Belcour &
/// Barla 2017 and used by glTF's `KHR_materials_iridescence` reference implementation: for
/// an OPD in nm and a phase shift, the linear Rec.709 (sRGB primaries) sensitivity term
/// `S(OPD, shift)`. Per XYZ channel, a Gaussian of amplitude `val`, centre `pos` (1/m) and
/// variance `var` (1/m²): `val √(2π var) cos(pos φ + shift) exp(−φ² var)` with
/// φ = 2π OPD·10⁻⁹, an extra Gaussian for the second lobe of x̄, normalised by 1.0685·10⁻⁷,
/// then XYZ → Rec.709.
pub fn gaussian_sensitivity_belcour2017(opd_nm: f64, shift: [f64; 3]) -> [f64; 3] {
    const VAL: [f64; 3] = [5.4856e-13, 4.4201e-13, 5.2481e-13];
    const POS: [f64; 3] = [1.6810e+06, 1.7953e+06, 2.2084e+06];
    const VAR: [f64; 3] = [4.3278e+09, 9.3046e+09, 6.6121e+09];
    const XYZ_TO_REC709: [[f64; 3]; 3] = [
        [3.2404542, -1.5371385, -0.4985314],
        [-0.9692660, 1.8760108, 0.0415560],
        [0.0556434, -0.2040259, 1.0572252],
    ];
    let phase = 2.0 * PI * opd_nm * 1e-9;
    let mut xyz: [f64; 3] = std::array::from_fn(|i| {
        VAL[i]
            * (2.0 * PI * VAR[i]).sqrt()
            * elementary::cos(POS[i] * phase + shift[i])
            * elementary::exp(-phase * phase * VAR[i])
    });
    xyz[0] += 9.7470e-14
        * (2.0 * PI * 4.5282e+09f64).sqrt()
        * elementary::cos(2.2399e+06 * phase + shift[0])
        * elementary::exp(-4.5282e+09 * phase * phase);
    let xyz = xyz.map(|v| v / 1.0685e-7);
    std::array::from_fn(|r| (0..3).map(|c| XYZ_TO_REC709[r][c] * xyz[c]).sum())
}

/// The `KHR_materials_iridescence` reference thin-film term (Belcour & Barla 2017's
/// real-time approximation: Schlick Fresnel from F0, π phase flips, unpolarised, m ≤ 2,
/// Gaussian-fit sensitivities), in linear Rec.709, for an outside index `n_outside`, film
/// index `n_film`, `cos_theta`, thickness in nm and the base's normal-incidence reflectance
/// `base_f0` (RGB). As in the glTF reference renderer, the film index is blended to the
/// outside index by smoothstep(0, 0.03, thickness_nm).
pub fn gltf_iridescence(
    n_outside: f64,
    n_film: f64,
    cos_theta: f64,
    thickness_nm: f64,
    base_f0: [f64; 3],
) -> [f64; 3] {
    let smooth = {
        let t = (thickness_nm / 0.03).clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    };
    let ior = n_outside + (n_film - n_outside) * smooth;
    let ratio = n_outside / ior;
    let sin2_t2 = ratio * ratio * (1.0 - cos_theta * cos_theta);
    let cos2_t2 = 1.0 - sin2_t2;
    if cos2_t2 < 0.0 {
        return [1.0; 3];
    }
    let cos_t2 = cos2_t2.sqrt();
    let schlick = |f0: f64, c: f64| {
        let m = (1.0 - c).clamp(0.0, 1.0);
        let m2 = m * m;
        f0 + (1.0 - f0) * (m * (m2 * m2))
    };
    let f0_of = |a: f64, b: f64| {
        let r = (a - b) / (a + b);
        r * r
    };
    let r12 = schlick(f0_of(ior, n_outside), cos_theta);
    let t121 = 1.0 - r12;
    let phi12 = if ior < n_outside { PI } else { 0.0 };
    let phi21 = PI - phi12;
    let opd = 2.0 * ior * thickness_nm * cos_t2;
    let mut out = [0.0; 3];
    let mut shifts = [0.0; 3];
    let mut r123 = [0.0; 3];
    let mut cm = [0.0; 3];
    for i in 0..3 {
        let f0 = base_f0[i].clamp(0.0, 0.9999);
        let base_ior = (1.0 + f0.sqrt()) / (1.0 - f0.sqrt());
        let r23 = schlick(f0_of(base_ior, ior), cos_t2);
        let phi23 = if base_ior < ior { PI } else { 0.0 };
        shifts[i] = phi21 + phi23;
        let r123_sq = (r12 * r23).clamp(1e-5, 0.9999);
        r123[i] = r123_sq.sqrt();
        let rs = t121 * t121 * r23 / (1.0 - r123_sq);
        out[i] = r12 + rs;
        cm[i] = rs - t121;
    }
    for m in 1..=2 {
        let mf = m as f64;
        let s = gaussian_sensitivity_belcour2017(mf * opd, shifts.map(|p| mf * p));
        for i in 0..3 {
            cm[i] *= r123[i];
            out[i] += cm[i] * 2.0 * s[i];
        }
    }
    out.map(|v| v.max(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::{Illuminant, Observer, OutputSpace};
    use crate::{Layer, Material, Stack};

    #[test]
    fn transform_is_one_at_zero_and_decays() {
        let c = Colorimeter::srgb_d65();
        let s0 = sensitivity_transform(&c, 0.0, 0.0);
        for v in s0 {
            assert!((v - C64::new(1.0, 0.0)).norm() < 1e-12, "{s0:?}");
        }
        let far = sensitivity_transform(&c, 50_000.0, 0.0);
        assert!(far.iter().all(|v| v.norm() < 1e-3), "{far:?}");
        // Prefiltering only damps.
        let direct = transform_with_rule(&SpectralRule::new(&c, 0.0), 0.0, 0.0);
        assert!(
            direct
                .iter()
                .all(|v| (v - C64::new(1.0, 0.0)).norm() < 1e-12)
        );
        let a = sensitivity_transform(&c, 800.0, 0.0);
        let b = sensitivity_transform(&c, 800.0, 100.0);
        assert!((0..3).all(|j| b[j].norm() < a[j].norm()));
    }

    #[test]
    fn filon_matches_direct_quadrature() {
        let c = Colorimeter::srgb_d65();
        let spectrum = SensitivitySpectrum::new(&c);
        let mut worst: f64 = 0.0;
        for &(mu, sigma) in &[
            (0.0, 0.0),
            (300.0, 0.0),
            (1234.5, 0.0),
            (5000.0, 40.0),
            (20_000.0, 0.0),
            (60_000.0, 0.0),
            (2500.0, 400.0),
        ] {
            let a = spectrum.transform(mu, sigma);
            // A rule 20× finer than needed for the phase (GL2 error ∝ step⁴) as the reference.
            let b = transform_with_rule(&SpectralRule::new(&c, 20.0 * mu.max(1000.0)), mu, sigma);
            for j in 0..3 {
                worst = worst.max((a[j] - b[j]).norm());
            }
        }
        // The residual (≈ 4e-6) is the reference's: its 2 nm Gauss–Legendre cells span the
        // kinks of the 1 nm sensitivity tables.
        assert!(worst < 1e-5, "{worst:e}");
    }

    /// Ŝ_j(μ) of the λ-linear interpolant of the 1 nm sensitivity tables by Gauss–Legendre
    /// quadrature aligned with the table's knots (16 sub-intervals per nm, 4 nodes each):
    /// an independent reference with no kinks inside its cells.
    fn knot_aligned_transform(c: &Colorimeter, mu_nm: f64) -> [C64; 3] {
        const X: [f64; 4] = [
            -0.861_136_311_594_052_6,
            -0.339_981_043_584_856_3,
            0.339_981_043_584_856_3,
            0.861_136_311_594_052_6,
        ];
        const W: [f64; 4] = [
            0.347_854_845_137_453_9,
            0.652_145_154_862_546_1,
            0.652_145_154_862_546_1,
            0.347_854_845_137_453_9,
        ];
        let sub = 16;
        let (mut sum, mut norm) = ([C64::new(0.0, 0.0); 3], [0.0; 3]);
        let nm = (crate::colour::SPECTRAL_MAX_NM - crate::colour::SPECTRAL_MIN_NM) as usize;
        for k in 0..nm * sub {
            let a = crate::colour::SPECTRAL_MIN_NM + k as f64 / sub as f64;
            let h = 1.0 / sub as f64;
            for (x, w) in X.iter().zip(W) {
                let wl = a + 0.5 * h * (1.0 + x);
                let s = c.sensitivity_at(wl);
                let e = C64::from_polar(0.5 * h * w, -2.0 * PI * mu_nm / wl);
                for j in 0..3 {
                    sum[j] += e * s[j];
                    norm[j] += 0.5 * h * w * s[j];
                }
            }
        }
        std::array::from_fn(|j| sum[j] / norm[j])
    }

    #[test]
    fn filon_is_within_1e6_of_a_knot_aligned_reference() {
        for c in [
            Colorimeter::srgb_d65(),
            Colorimeter::new(Observer::Cie1964_10Deg, Illuminant::A, OutputSpace::Xyz),
        ] {
            let spectrum = SensitivitySpectrum::new(&c);
            let mut worst: f64 = 0.0;
            for mu in [
                0.0, 150.0, 777.0, 2500.0, 9000.0, 30_000.0, 80_000.0, 160_000.0,
            ] {
                let (a, b) = (spectrum.transform(mu, 0.0), knot_aligned_transform(&c, mu));
                for j in 0..3 {
                    worst = worst.max((a[j] - b[j]).norm());
                }
            }
            assert!(worst < 1e-6, "{worst:e}");
        }
    }

    #[test]
    fn cosine_integrates_through_the_transform() {
        // ∫ cos(2π μ/λ + φ) s(λ) dλ / ‖s‖ = Re(e^{iφ} conj Ŝ(μ)), by direct quadrature.
        let c = Colorimeter::srgb_d65();
        let (mu, phi) = (1234.5, 0.7);
        let rule = SpectralRule::new(&c, 20.0 * mu);
        let direct = rule.colour(
            rule.wavelengths_nm()
                .iter()
                .map(|&wl| (2.0 * PI * mu / wl + phi).cos()),
        );
        let s = sensitivity_transform(&c, mu, 0.0);
        for j in 0..3 {
            let via = (C64::from_polar(1.0, phi) * s[j].conj()).re;
            assert!(
                (direct[j] - via).abs() < 1e-5,
                "{j}: {} vs {via}",
                direct[j]
            );
        }
    }

    #[test]
    fn transmittance_series_and_thin_film_limit() {
        let c = Colorimeter::srgb_d65();
        let film = FilmOnBase {
            n_ambient: 1.0,
            n_film: 1.8,
            base: [C64::new(1.5, 0.0); 3],
        };
        let m = |n: f64| Material::constant("m", C64::new(n, 0.0)).unwrap();
        for &(cos_t, d) in &[(1.0f64, 420.0), (0.5, 1234.0), (0.15, 777.0)] {
            let stack = Stack::new(
                m(1.0),
                vec![Layer {
                    material: m(1.8),
                    thickness_nm: d,
                }],
                m(1.5),
            )
            .unwrap();
            let rule = SpectralRule::new(&c, stack.max_opd_nm(None));
            let exact = stack
                .colours_over_thickness(1, cos_t.acos().to_degrees(), &rule, &[d])
                .unwrap();
            let r = film
                .fourier_colour(&c, cos_t, d, Harmonics::Auto, 0.0, false)
                .unwrap()
                .colour;
            let t = film
                .fourier_colour(&c, cos_t, d, Harmonics::Auto, 0.0, true)
                .unwrap()
                .colour;
            for j in 0..3 {
                assert!(
                    (r[j] - exact.reflectance[0][j]).abs() < 1e-4,
                    "{r:?} {:?}",
                    exact.reflectance[0]
                );
                assert!(
                    (t[j] - exact.transmittance[0][j]).abs() < 1e-4,
                    "{t:?} {:?}",
                    exact.transmittance[0]
                );
            }
        }
        // At zero thickness the blended fixed-harmonic result is the bare base exactly.
        let bare = Stack::new(m(1.0), vec![], m(1.5)).unwrap();
        let rule = SpectralRule::new(&c, 0.0);
        let p = bare.sweep(&[60.0], rule.wavelengths_nm()).unwrap();
        let want = rule.colour(p.iter().map(|p| p.R()));
        let got = film
            .fourier_colour(&c, 0.5, 0.0, Harmonics::Fixed(3), 0.0, false)
            .unwrap()
            .colour;
        for j in 0..3 {
            assert!((got[j] - want[j]).abs() < 1e-9, "{got:?} vs {want:?}");
        }
    }

    #[test]
    fn airy_series_sums_to_the_airy_reflectance() {
        // Sum the series at one wavelength (no spectral integration) and compare with the
        // stack solver.
        for &(n2, base, cos_t) in &[
            (1.5, C64::new(1.0, 0.0), 1.0),
            (2.2, C64::new(0.27, 2.9), 0.6),
            (1.33, C64::new(1.5, 0.0), 0.2),
            (1.8, C64::new(1.2, 0.0), 0.3), // TIR at the base
        ] {
            let film = FilmOnBase {
                n_ambient: 1.0,
                n_film: n2,
                base: [base; 3],
            };
            let series = film.series(n2, cos_t, 0, false);
            let (d, wl) = (321.0, 550.0);
            let q2 = film.film_q(cos_t).unwrap();
            let phi = 2.0 * PI * 2.0 * d * q2 / wl;
            let mut r = [0.0; 2];
            for pol in 0..2 {
                let s = &series[pol];
                r[pol] = s.c0;
                let mut cm = s.k;
                for m in 1..2000 {
                    r[pol] += 2.0 * (cm * C64::from_polar(1.0, m as f64 * phi)).re;
                    cm *= s.rho;
                }
            }
            let m = |n: C64| Material::constant("m", n).unwrap();
            let stack = Stack::new(
                m(C64::new(1.0, 0.0)),
                vec![Layer {
                    material: m(C64::new(n2, 0.0)),
                    thickness_nm: d,
                }],
                m(base),
            )
            .unwrap();
            let p = stack.evaluate(cos_t.acos().to_degrees(), wl).unwrap().power;
            assert!(
                (r[0] - p.R_s).abs() < 1e-9 && (r[1] - p.R_p).abs() < 1e-9,
                "{n2} {base}: {r:?} vs {p:?}"
            );
        }
    }
}
