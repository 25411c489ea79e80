//! Film colours of a single non-dispersive film from the Fourier series of its Airy
//! spectrum: the same numbers as the wavelength sum of a [`SpectralRule`], at a cost that
//! does not grow with the number of wavelengths (issue 16 §3, the `rough-film-lut` bake).
//!
//! # The series
//!
//! A film of real index n_f between a non-absorbing ambient n₀ and a base ñ₂, none of them
//! dispersive, seen at cos θ₀ = c, has per polarisation the Airy reflectance and
//! transmittance (Born & Wolf, *Principles of Optics*, §7.6.1)
//!
//! ```text
//! R(Φ) = |r₀₁ + β e^{iΦ} / (1 − ρ e^{iΦ})|²,   T(Φ) = A / |1 − ρ e^{iΦ}|²,
//! Φ = 2π D / λ,   D = 2 d q₁,   q₁ = √(n_f² − n₀²(1 − c²)),
//! ```
//!
//! with r₀₁, Γ the film's top and bottom Fresnel amplitudes, β = (1 − r₀₁²) Γ, ρ = −r₀₁ Γ
//! and A = |t₀₁ t₁₂|² × the power factor of [`crate::fresnel`]. Both are Fourier series in
//! Φ whose coefficients are powers of ρ (Belcour & Barla 2017, "A Practical Extension to
//! Microfacet Theory for the Modeling of Varying Iridescence", §4 Eq. 5–6 and appendix;
//! written in closed form in [`crate::fourier::AirySeries`]):
//!
//! ```text
//! R = c₀ + 2 Σ_{m≥1} Re(c_m e^{imΦ}),   c_m = ρ^{m−1} K,   c₀, K as in AirySeries
//! T = a₀ [1 + 2 Σ_{m≥1} Re(ρ^m e^{imΦ})],  a₀ = A / (1 − |ρ|²)
//! ```
//!
//! Since none of r₀₁, Γ, A depends on λ, the colour of a rule with nodes λₖ and weights
//! Wₖ ([`SpectralRule`]) is, channel by channel and averaged over s and p,
//!
//! ```text
//! C_j = Σₖ Wₖⱼ R(λₖ) = ½ (c₀,s + c₀,p) Σₖ Wₖⱼ + Σ_{pol} Σ_{m≥1} Re(c_m,pol F_j(m D)),
//! F_j(μ) = Σₖ Wₖⱼ e^{2πiμ/λₖ}                                         (the rule's transform)
//! ```
//!
//! — the wavelength sum itself, rearranged; no approximation of the spectrum is involved
//! (F_j is the discrete transform of the rule's own weights, so fringes the rule aliases
//! alias identically).
//!
//! # Truncation
//!
//! |F_j(μ)| ≤ Σₖ |Wₖⱼ|, so the terms after harmonic M are bounded by
//! Σ_pol |K_pol| |ρ_pol|^M / (1 − |ρ_pol|) · Σₖ |Wₖⱼ|. [`SingleFilm::harmonics`] takes the
//! smallest M for which Σ_pol |K_pol| |ρ_pol|^M / (1 − |ρ_pol|) ≤ [`SERIES_TOLERANCE`]
//! (for R and T), at most [`MAX_SERIES_HARMONICS`] (a film whose fringes are that sharp is
//! left to the wavelength sum). A film index-matched to the ambient (r₀₁ = 0) or to the base
//! (Γ = 0) has K = 0: M = 0 and the colour is the bare interface's, exactly.
//!
//! # The transform between grid points: [`RuleTransform`]
//!
//! F_j is tabulated once per rule on a uniform grid μ_p = p h, h = [`TRANSFORM_STEP_NM`],
//! and read with 8-point Lagrange interpolation (the nodes p₀ − 3 … p₀ + 4 around μ). F_j is
//! a sum of exponentials e^{2πiμν} with ν = 1/λ ≤ ν_max = 1/360 nm⁻¹; interpolating
//! e^{iωμ} with n nodes errs by at most max|Π(x − x_i)| (ωh)ⁿ / n! (Davis, *Interpolation
//! and Approximation*, 1963, Thm. 3.1.1), for n = 8 and the central cell
//! 43.1 · (2π h ν_max)⁸ / 8! = 6·10⁻¹³ relative to Σₖ |Wₖⱼ| at h = 4 nm. The grid is
//! filled by the recurrence e^{2πi(p+1)h/λ} = e^{2πiph/λ} e^{2πih/λ} restarted from the
//! deterministic sin/cos of the `simd` module every [`TRANSFORM_BLOCK`] points (rounding
//! ≲ 10⁻¹⁴), so the table, like everything else here, is the same bits on every machine:
//! only IEEE basic operations in a fixed order.
//!
//! Measured against [`crate::Stack::colours_over_thickness`] with the same rule: ≤ 1.2·10⁻¹¹
//! over film indices 1.0–2.5 (1.0 and the base's 1.5 included), 0–1800 nm, cos θ 10⁻³–1
//! (test `series_matches_the_wavelength_sum`); the largest differences are at grazing
//! incidence, where the series takes q₀ = n₀ cos θ exactly and the wavelength sum takes it
//! through the angle in degrees (q₀² = 1 − sin²θ loses ≈ 10⁻⁴ of itself at cos θ = 10⁻⁶).

use crate::elementary;
use crate::error::{Error, Result};
use crate::fourier::AirySeries;
use crate::fresnel::{Interface, power_factor_p, power_factor_s};
use crate::spectral::{FilmColours, SpectralRule};
use crate::{Layer, Material};
use num_complex::Complex64 as C64;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Bound on the truncated tail of the series relative to Σₖ |Wₖⱼ| (module docs).
pub const SERIES_TOLERANCE: f64 = 1e-13;

/// Most harmonics [`SingleFilm::harmonics`] allows before leaving a film to the wavelength
/// sum (|ρ| ≳ 0.993).
pub const MAX_SERIES_HARMONICS: usize = 4096;

/// Cost of one Airy evaluation of the wavelength sum (per node and thickness) in units of
/// one grid point of [`RuleTransform`] per node, as measured on x86-64 (≈ 4): the trade-off
/// of [`series_extent`].
pub const AIRY_COST_PER_POINT: f64 = 4.0;

/// The extent μ* to tabulate [`RuleTransform`] for, given each film's need (the μ = M D its
/// series reaches, [`SingleFilm::plan`]) and the length of its thickness sweep: the μ*
/// among the needs (or 0) that minimises the work μ*/h + Σ_{need > μ*} length ×
/// [`AIRY_COST_PER_POINT`] — films whose series reaches further than μ* (sharp fringes of
/// thick films near grazing incidence) keep the wavelength sum. A pure function of its
/// input, so the choice (and the bytes baked) do not depend on the machine.
pub fn series_extent(needs: &[(f64, usize)]) -> f64 {
    let mut sorted: Vec<(f64, usize)> = needs.to_vec();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut rest: f64 = sorted.iter().map(|&(_, n)| n as f64).sum::<f64>() * AIRY_COST_PER_POINT;
    let (mut best, mut best_cost) = (0.0, rest);
    for &(mu, n) in &sorted {
        rest -= n as f64 * AIRY_COST_PER_POINT;
        let cost = mu / TRANSFORM_STEP_NM + rest;
        if cost < best_cost {
            (best, best_cost) = (mu, cost);
        }
    }
    best
}

/// Grid step of [`RuleTransform`], nm of μ.
pub const TRANSFORM_STEP_NM: f64 = 4.0;

/// Points of [`RuleTransform`]'s grid filled by one recurrence from a sin/cos anchor.
pub const TRANSFORM_BLOCK: usize = 64;

/// Most grid points of a [`RuleTransform`] (2²², 192 MiB; μ up to 1.6·10⁷ nm).
pub const MAX_TRANSFORM_POINTS: usize = 1 << 22;

/// Grid points before μ = 0 (the stencil's left half at μ < 3h).
const LEAD: usize = 3;

/// 1 / Πₗ≠ᵢ (i − l) for the nodes l = 0 … 7: (−1)^{7−i} / (i! (7 − i)!).
const INV_DEN: [f64; 8] = [
    -1.0 / 5040.0,
    1.0 / 720.0,
    -1.0 / 240.0,
    1.0 / 144.0,
    -1.0 / 144.0,
    1.0 / 240.0,
    -1.0 / 720.0,
    1.0 / 5040.0,
];

/// The transform F_j(μ) = Σₖ Wₖⱼ e^{2πiμ/λₖ} of a [`SpectralRule`], tabulated for
/// interpolation (module docs).
#[derive(Clone, Debug)]
pub struct RuleTransform {
    step_nm: f64,
    /// F(p h) for p = −3, −2, …
    values: Vec<[C64; 3]>,
    /// Σₖ Wₖⱼ.
    white: [f64; 3],
    /// Σₖ |Wₖⱼ|.
    bound: [f64; 3],
}

impl RuleTransform {
    /// Tabulates `rule`'s transform for 0 ≤ μ ≤ `max_mu_nm`.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] when the grid would exceed [`MAX_TRANSFORM_POINTS`].
    pub fn new(rule: &SpectralRule, max_mu_nm: f64) -> Result<Self> {
        let h = TRANSFORM_STEP_NM;
        let span = (max_mu_nm.max(0.0) / h).ceil();
        if !(span < (MAX_TRANSFORM_POINTS - 2 * LEAD - 2) as f64) {
            return Err(Error::OutOfRange {
                what: "largest optical path of the film series, nm",
                value: max_mu_nm,
                expected: "at most 1.6e7 nm",
            });
        }
        let points = span as usize + 2 * LEAD + 2;
        let wl = rule.wavelengths_nm();
        let w = rule.weights();
        // Per node: the angular step 2π h / λₖ of the recurrence.
        let rate: Vec<f64> = wl.iter().map(|&l| 2.0 * PI * h / l).collect();
        let (mut step_sin, mut step_cos) = (vec![0.0; wl.len()], vec![0.0; wl.len()]);
        crate::simd::sin_cos_slice(&rate, &mut step_sin, &mut step_cos);
        let mut values = vec![[C64::new(0.0, 0.0); 3]; points];
        values
            .par_chunks_mut(TRANSFORM_BLOCK)
            .enumerate()
            .for_each(|(b, block)| {
                let p0 = (b * TRANSFORM_BLOCK) as f64 - LEAD as f64;
                let arg: Vec<f64> = rate.iter().map(|&r| r * p0).collect();
                let (mut s, mut c) = (vec![0.0; wl.len()], vec![0.0; wl.len()]);
                crate::simd::sin_cos_slice(&arg, &mut s, &mut c);
                for k in 0..wl.len() {
                    let step = C64::new(step_cos[k], step_sin[k]);
                    let mut e = C64::new(c[k], s[k]);
                    for v in block.iter_mut() {
                        for j in 0..3 {
                            v[j] += e * w[k][j];
                        }
                        e *= step;
                    }
                }
            });
        let white = std::array::from_fn(|j| w.iter().map(|v| v[j]).sum());
        let bound = std::array::from_fn(|j| w.iter().map(|v| v[j].abs()).sum());
        Ok(RuleTransform {
            step_nm: h,
            values,
            white,
            bound,
        })
    }

    /// The largest μ the table covers, nm.
    pub fn max_mu_nm(&self) -> f64 {
        (self.values.len() - 2 * LEAD - 2) as f64 * self.step_nm
    }

    /// Σₖ Wₖⱼ: the colour of R ≡ 1.
    pub fn white(&self) -> [f64; 3] {
        self.white
    }

    /// Σₖ |Wₖⱼ|, the bound on |F_j|.
    pub fn bound(&self) -> [f64; 3] {
        self.bound
    }

    /// F_j(μ) for 0 ≤ μ ≤ [`RuleTransform::max_mu_nm`], by 8-point Lagrange interpolation.
    ///
    /// # Panics
    /// If μ is outside the table.
    #[inline]
    pub fn at(&self, mu_nm: f64) -> [C64; 3] {
        let x = mu_nm / self.step_nm;
        // x ≥ 0: truncation is the floor.
        let p = x as usize;
        let t = x - p as f64;
        // (t − l) for the nodes l = −3 … 4 relative to p, numbered 0 … 7.
        let d: [f64; 8] = std::array::from_fn(|i| t - (i as f64 - 3.0));
        let mut left = [1.0; 8];
        for i in 1..8 {
            left[i] = left[i - 1] * d[i - 1];
        }
        let mut right = 1.0;
        let mut wts = [0.0; 8];
        for i in (0..8).rev() {
            wts[i] = left[i] * right * INV_DEN[i];
            right *= d[i];
        }
        let nodes = &self.values[p..p + 8];
        let mut out = [C64::new(0.0, 0.0); 3];
        for (v, &wt) in nodes.iter().zip(&wts) {
            for j in 0..3 {
                out[j] += v[j] * wt;
            }
        }
        out
    }
}

/// The ambient's (real) and the base's index of a film between `ambient` and `base` with
/// `under` below it, when its colours are a Fourier series ([`SingleFilm`]): no layers under
/// the film, neither medium dispersive, the ambient non-absorbing.
pub fn non_dispersive_surround(
    ambient: &Material,
    under: &[Layer],
    base: &Material,
) -> Option<(f64, C64)> {
    if !under.is_empty() || !ambient.is_constant() || !base.is_constant() {
        return None;
    }
    let n_ambient = ambient.index_at(560.0).ok()?;
    let n_base = base.index_at(560.0).ok()?;
    (n_ambient.im == 0.0).then_some((n_ambient.re, n_base))
}

/// One non-dispersive single film: the Airy series of its reflectance (and transmittance)
/// for s and p (module docs).
#[derive(Clone, Copy, Debug)]
pub struct SingleFilm {
    /// q₁ = √(n_f² − n₀² (1 − c²)).
    q_film: f64,
    reflect: [AirySeries; 2],
    transmit: Option<[AirySeries; 2]>,
}

impl SingleFilm {
    /// The film of real index `n_film` between the ambient `n_ambient` (real) and `base`,
    /// at incidence cosine `cos_theta` in (0, 1]; with `transmittance`, the series of the
    /// transmittance into the base too. None where the series does not apply: a film that
    /// is evanescent (n_f < n₀ sin θ) or has no partial reflection (|ρ| ≥ 1).
    pub fn new(
        n_ambient: f64,
        n_film: f64,
        base: C64,
        cos_theta: f64,
        transmittance: bool,
    ) -> Option<Self> {
        if !(cos_theta > 0.0 && cos_theta <= 1.0) {
            return None;
        }
        // q² = n² − n₀² sin²θ written as (n² − n₀²) + n₀² c², exact for n = n₀.
        let n0 = n_ambient;
        let c2 = cos_theta * cos_theta;
        let q_of = |n: C64| {
            let q2 = (n * n - n0 * n0) + n0 * n0 * c2;
            crate::fresnel::forward_branch(elementary::csqrt(q2))
        };
        let q0 = C64::new(n0 * cos_theta, 0.0);
        let q1_sq = (n_film * n_film - n0 * n0) + n0 * n0 * c2;
        if !(q1_sq > 0.0) {
            return None;
        }
        let q1 = C64::new(q1_sq.sqrt(), 0.0);
        let q2 = q_of(base);
        let (a, f) = (C64::new(n0, 0.0), C64::new(n_film, 0.0));
        let top = Interface::new(a, q0, f, q1);
        let bottom = Interface::new(f, q1, base, q2);
        let reflect = [
            AirySeries::new(top.r_s, bottom.r_s),
            AirySeries::new(top.r_p, bottom.r_p),
        ];
        if reflect.iter().any(|s| !(elementary::norm(s.rho) < 1.0)) {
            return None;
        }
        let transmit = transmittance.then(|| {
            let factor = [power_factor_s(q0, q2), power_factor_p(a, q0, base, q2)];
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
        });
        Some(SingleFilm {
            q_film: q1.re,
            reflect,
            transmit,
        })
    }

    /// The optical path difference D = 2 d q₁ at thickness `thickness_nm`.
    pub fn opd_nm(&self, thickness_nm: f64) -> f64 {
        2.0 * thickness_nm * self.q_film
    }

    /// The number of harmonics M that brings the truncated tail below
    /// [`SERIES_TOLERANCE`] (module docs), or None beyond [`MAX_SERIES_HARMONICS`].
    pub fn harmonics(&self) -> Option<usize> {
        let mut most = 0;
        for series in std::iter::once(&self.reflect).chain(self.transmit.as_ref()) {
            let tail = |m: i32| {
                series
                    .iter()
                    .map(|s| {
                        let r = elementary::norm(s.rho);
                        elementary::norm(s.k) * elementary::powi(r, m) / (1.0 - r)
                    })
                    .sum::<f64>()
            };
            let mut m = 0;
            while tail(m as i32) > SERIES_TOLERANCE {
                m += 1;
                if m > MAX_SERIES_HARMONICS {
                    return None;
                }
            }
            most = most.max(m);
        }
        Some(most)
    }

    /// The harmonics M ([`SingleFilm::harmonics`]) and the extent μ = M D the series
    /// reaches for films up to `max_thickness_nm` (None beyond [`MAX_SERIES_HARMONICS`]):
    /// a baker's input to [`series_extent`].
    pub fn plan(&self, max_thickness_nm: f64) -> Option<(usize, f64)> {
        let m = self.harmonics()?;
        Some((m, m as f64 * self.opd_nm(max_thickness_nm)))
    }

    /// Unpolarised reflectance (and transmittance, if requested at construction; zeros
    /// otherwise) colours at each thickness of `thicknesses_nm`, with `harmonics` terms
    /// ([`SingleFilm::harmonics`]) and the rule's `transform`, which must cover
    /// μ = harmonics · [`SingleFilm::opd_nm`] of the thickest film.
    pub fn colours_over_thickness(
        &self,
        transform: &RuleTransform,
        harmonics: usize,
        thicknesses_nm: &[f64],
    ) -> FilmColours {
        let white = transform.white();
        let r0 = 0.5 * (self.reflect[0].c0 + self.reflect[1].c0);
        let t0 = self.transmit.map_or(0.0, |t| 0.5 * (t[0].c0 + t[1].c0));
        let mut out = FilmColours {
            reflectance: Vec::with_capacity(thicknesses_nm.len()),
            transmittance: Vec::with_capacity(thicknesses_nm.len()),
        };
        let zero = C64::new(0.0, 0.0);
        let trans = self.transmit.unwrap_or(
            [AirySeries {
                c0: 0.0,
                k: zero,
                rho: zero,
            }; 2],
        );
        for &d in thicknesses_nm {
            let opd = self.opd_nm(d);
            let mut r: [f64; 3] = white.map(|w| r0 * w);
            let mut t: [f64; 3] = white.map(|w| t0 * w);
            // c_m per (R s, R p, T s, T p), c_1 = K.
            let mut cr = [self.reflect[0].k, self.reflect[1].k];
            let mut ct = [trans[0].k, trans[1].k];
            for m in 1..=harmonics {
                if m > 1 {
                    for pol in 0..2 {
                        cr[pol] *= self.reflect[pol].rho;
                        ct[pol] *= trans[pol].rho;
                    }
                }
                let f = transform.at(m as f64 * opd);
                let (ar, at) = (cr[0] + cr[1], ct[0] + ct[1]);
                for j in 0..3 {
                    r[j] += ar.re * f[j].re - ar.im * f[j].im;
                    t[j] += at.re * f[j].re - at.im * f[j].im;
                }
            }
            out.reflectance.push(r);
            out.transmittance.push(t);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Stack;
    use crate::colour::Colorimeter;

    /// Interpolated F against the direct sum over the rule's nodes.
    #[test]
    fn transform_interpolates_to_1e12() {
        let rule = SpectralRule::new(&Colorimeter::srgb_d65(), 9000.0);
        let table = RuleTransform::new(&rule, 50_000.0).unwrap();
        let bound = table.bound();
        let mut worst: f64 = 0.0;
        for i in 0..2000 {
            let mu = if i == 0 {
                0.0
            } else {
                50_000.0 * ((i as f64 * 0.618_034) % 1.0)
            };
            let got = table.at(mu);
            let mut want = [C64::new(0.0, 0.0); 3];
            for (&l, w) in rule.wavelengths_nm().iter().zip(rule.weights()) {
                let e = C64::from_polar(1.0, 2.0 * PI * mu / l);
                for j in 0..3 {
                    want[j] += e * w[j];
                }
            }
            for j in 0..3 {
                worst = worst.max((got[j] - want[j]).norm() / bound[j]);
            }
        }
        assert!(worst < 1e-12, "{worst}");
    }

    /// The series against the wavelength sum of [`Stack::colours_over_thickness`] with the
    /// same rule, over the rough-film table's range: index 1.0 (no film), the base's index
    /// 1.5, up to 2.5; cos θ from 10⁻³ (grazing) to 1; thickness 0–1800 nm.
    #[test]
    fn series_matches_the_wavelength_sum() {
        let colorimeter = Colorimeter::srgb_d65();
        let rule = SpectralRule::new(&colorimeter, 2.0 * 1800.0 * 2.5);
        let thicknesses: Vec<f64> = (0..=150).map(|i| 12.0 * i as f64).collect();
        let base = C64::new(1.5, 0.0);
        let mut films = Vec::new();
        for &n in &[1.0, 1.0026, 1.2, 1.5, 1.9, 2.5] {
            for &c in &[1e-3, 0.02, 0.3, 0.6, 1.0] {
                let film = SingleFilm::new(1.0, n, base, c, true).unwrap();
                films.push((n, c, film, film.harmonics().unwrap()));
            }
        }
        let top = films
            .iter()
            .map(|(_, _, f, m)| *m as f64 * f.opd_nm(1800.0))
            .fold(0.0, f64::max);
        let table = RuleTransform::new(&rule, top).unwrap();
        let mut worst: f64 = 0.0;
        for (n, c, film, m) in films {
            if n == 1.0 || n == 1.5 {
                assert_eq!(m, 0, "index-matched film {n}: no interference term");
            }
            let got = film.colours_over_thickness(&table, m, &thicknesses);
            let material = |v: f64| Material::constant(format!("{v}"), C64::new(v, 0.0)).unwrap();
            let stack = Stack::new(
                material(1.0),
                vec![Layer {
                    material: material(n),
                    thickness_nm: 0.0,
                }],
                material(1.5),
            )
            .unwrap();
            let want = stack
                .colours_over_thickness(1, c.acos().to_degrees(), &rule, &thicknesses)
                .unwrap();
            for (i, d) in thicknesses.iter().enumerate() {
                for j in 0..3 {
                    let e = (got.reflectance[i][j] - want.reflectance[i][j]).abs();
                    let f = (got.transmittance[i][j] - want.transmittance[i][j]).abs();
                    worst = worst.max(e.max(f));
                    assert!(
                        e.max(f) <= 1e-9,
                        "n {n} cos {c} d {d} channel {j}: R {} vs {}, T {} vs {}",
                        got.reflectance[i][j],
                        want.reflectance[i][j],
                        got.transmittance[i][j],
                        want.transmittance[i][j]
                    );
                }
            }
        }
        eprintln!("largest difference {worst:e}");
    }
}
