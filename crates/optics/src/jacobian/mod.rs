//! Exact derivatives of a stack's powers R_s, R_p, T_s, T_p with respect to every film's
//! thickness and to the real and imaginary parts of every film's index, by a reverse
//! (adjoint) sweep of the substrate-up recurrence: all L films' derivatives together cost
//! O(L), about one more pass over the stack.
//!
//! Entry points (the API the fit commands call):
//!
//! * [`sweep_jacobian`]: over (angle, wavelength) pairs, angle-major like
//!   [`crate::Stack::sweep`]: the powers and, per element, their derivatives per nm of
//!   thickness ([`SweepJacobian::d_thickness`]) and, with [`Wrt::ThicknessAndIndex`], per
//!   unit of Re ñ and Im ñ of each film ([`SweepJacobian::d_index_re`],
//!   [`SweepJacobian::d_index_im`]);
//! * [`point_jacobian`]: one (angle, wavelength) and one set of media indices (the scalar
//!   reference the sweep runs element by element);
//! * [`colour_jacobian`] and [`lab_jacobian`], [`delta_e_2000_gradient`]: the chain rule
//!   on to XYZ (or the colorimeter's output space), CIELAB and ΔE2000 (in
//!   [`crate::colour`]'s spectral sums).
//!
//! A derivative is carried in a [`Power`] whose fields are ∂R_s/∂x, ∂R_p/∂x, ∂T_s/∂x,
//! ∂T_p/∂x ([`Power::R`], [`Power::T`] are then the unpolarised derivatives).
//!
//! # Method
//!
//! The recurrence of [`crate::stack`] (Heavens 1955 §4; Born & Wolf §1.6.5), for media
//! j = 0 … N+1 (ambient, films 1 … N top first, substrate), interface j from medium j into
//! j + 1 with Fresnel coefficients r_j, t_j ([`crate::fresnel`]), film phases
//! δ_j = k₀ q_j d_j, E_j = e^{2iδ_j}:
//!
//! ```text
//! Γ_N = r_N,   g_j = Γ_{j+1} E_{j+1},   D_j = 1 + r_j g_j,   Γ_j = (r_j + g_j) / D_j
//! ln τ₀ = ln t_N + Σ_{j<N} (ln t_j + iδ_{j+1} − ln D_j)
//! R = |Γ₀|²,   T = |τ₀|² · F      (F: the ambient/substrate power factor, no film enters)
//! ```
//!
//! Γ₀ and ln τ₀ are holomorphic functions of every complex intermediate (r_j, t_j, q_j,
//! ñ_j², E_j: no conjugate appears before the final modulus; q_j = √(ñ_j² − β²) on the
//! forward branch is holomorphic in ñ_j away from q_j = 0, the branch point where a film
//! is at its critical angle), and of a film's thickness d_j and index ñ_j. So for a real
//! parameter x entering holomorphically,
//!
//! ```text
//! ∂R/∂x = 2 Re(conj(Γ₀) ∂Γ₀/∂x),        ∂T/∂x = 2 T Re(∂ ln τ₀/∂x),
//! ∂/∂(Re ñ_j) = ∂/∂ñ_j,                 ∂/∂(Im ñ_j) = i ∂/∂ñ_j,
//! ```
//!
//! and ∂Γ₀/∂x, ∂ ln τ₀/∂x follow from one reverse sweep each of complex adjoints
//! ā_v = ∂(output)/∂v, from the top (j = 0) down, with the partial derivatives
//!
//! ```text
//! ∂Γ_j/∂g_j = (1 − r_j²)/D_j²,   ∂Γ_j/∂r_j = (1 − g_j²)/D_j²,   ∂ ln D_j/∂g_j = r_j/D_j,
//! ∂ ln D_j/∂r_j = g_j/D_j,   ∂g_j/∂Γ_{j+1} = E_{j+1},   ∂g_j/∂E_{j+1} = Γ_{j+1},
//! ∂E_j/∂δ_j = 2i E_j,   ∂δ_j/∂d_j = k₀ q_j,   ∂δ_j/∂q_j = k₀ d_j:
//!
//! ā_g_j = ā_Γ_j (1 − r_j²)/D_j² − [τ] r_j/D_j,    ā_r_j = ā_Γ_j (1 − g_j²)/D_j² − [τ] g_j/D_j,
//! ā_Γ_{j+1} = ā_g_j E_{j+1},    ā_δ_{j+1} = 2i E_{j+1} Γ_{j+1} ā_g_j + [τ] i,    ā_r_N = ā_Γ_N,
//! ∂(output)/∂d_j = ā_δ_j k₀ q_j
//! ```
//!
//! starting from ā_Γ₀ = 1 for Γ₀ and ā_Γ₀ = 0 for ln τ₀; the terms marked [τ] (and
//! ā_{ln t_j} = 1) belong to ln τ₀ only. This is reverse mode: the adjoint ā_Γ_j is the
//! prefix product ∂Γ₀/∂Γ_j = Π_{i<j} (1 − r_i²) E_{i+1}/D_i², so the thickness Jacobian
//! ∂Γ₀/∂d_j = ā_Γ_j Γ_j 2i k₀ q_j costs one complex product chain for all films.
//!
//! Index derivatives continue the sweep through the interfaces (the admittance form of
//! [`crate::fresnel`]: r = (α − β)/(α + β), σ = α + β; s: α = q_i, β = q_j,
//! ln t = ln 2 + ln α − ln σ; p: α = ñ_j² q_i, β = ñ_i² q_j,
//! ln t = ln 2 + ln α + ½ ln ñ_i² − ½ ln ñ_j² − ln σ) and Snell's law:
//!
//! ```text
//! ∂r/∂α = 2β/σ²,  ∂r/∂β = −2α/σ²,  ∂ ln t/∂α = β/(α σ),  ∂ ln t/∂β = −1/σ,
//! ∂q_j/∂(ñ_j²) = 1/(2 q_j),  ∂(ñ_j²)/∂ñ_j = 2ñ_j,
//! ```
//!
//! the film's phase adding ā_δ_j k₀ d_j to ā_q_j. The ambient's index fixes β = n₀ sin θ₀
//! and is not a parameter, so neither it nor the substrate is differentiated.
//!
//! The powers returned are those of the same scalar recurrence as [`crate::Prepared`]
//! (the same operations in the same order: the same bits). Checked against central finite
//! differences and forward-mode dual numbers over random stacks (`tests/derivatives.rs`).
//!
//! # The vectorised sweep
//!
//! [`sweep_jacobian`] by thickness alone ([`Wrt::Thickness`], what `nacre spectrum
//! --jacobian`, the fits and the colour chain ask for) runs, wherever [`Stack::sweep`] takes
//! the vectorised multilayer kernel, its Jacobian form (`multilayer/jacobian.rs`):
//! wavelengths as SIMD lanes over the same arrays, a forward pass that is the value
//! kernel's recurrence on fractions Γ = N/D (so the powers are [`Stack::sweep`]'s, bit for
//! bit) keeping what the adjoint needs, then the reverse sweep written on the fractions —
//! no division per film. Its derivatives agree with this module's scalar sweep to ~10⁻¹⁴
//! (at worst ~10⁻¹¹ through several evanescent films; `tests/derivatives.rs`). Index
//! derivatives, and stacks outside the kernel's ranges, take the scalar sweep.

use crate::colour::{Colorimeter, delta_e_2000, xyz_to_lab};
use crate::elementary;
use crate::error::Result;
use crate::fresnel::{normal_component, power_factor_p, power_factor_s};
use crate::multilayer::Media;
use crate::multilayer::jacobian::row_jacobian;
use crate::power::{Power, wavenumber};
use crate::spectrum_sweep::SpectrumSweep;
use crate::stack::Stack;
use num_complex::Complex64 as C64;
use rayon::prelude::*;

/// Which derivatives to compute.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrt {
    /// Film thicknesses only.
    Thickness,
    /// Film thicknesses, and the real and imaginary parts of every film's index.
    ThicknessAndIndex,
}

/// A stack's powers at one (angle, wavelength) and their derivatives; each derivative is a
/// [`Power`] of ∂R_s/∂x, ∂R_p/∂x, ∂T_s/∂x, ∂T_p/∂x.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointJacobian {
    /// The powers.
    pub power: Power,
    /// Per film (top first): derivatives per nm of its thickness.
    pub d_thickness: Vec<Power>,
    /// Per film: derivatives per unit of Re ñ (empty for [`Wrt::Thickness`]).
    pub d_index_re: Vec<Power>,
    /// Per film: derivatives per unit of Im ñ (empty for [`Wrt::Thickness`]).
    pub d_index_im: Vec<Power>,
}

/// The powers and derivatives of a sweep, elements angle-major as in
/// [`crate::Stack::sweep`] (element e = a · wavelengths + w), derivatives element-major:
/// film j of element e at `e * films + j`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SweepJacobian {
    /// Number of films L.
    pub films: usize,
    /// The powers, one per element: [`crate::Stack::sweep`]'s, bit for bit, on the
    /// vectorised path; else those of the scalar recurrence, within ~10⁻¹⁴ of them.
    pub power: Vec<Power>,
    /// ∂/∂d_j per nm, `e * films + j`.
    pub d_thickness: Vec<Power>,
    /// ∂/∂Re ñ_j, `e * films + j` (empty for [`Wrt::Thickness`]).
    pub d_index_re: Vec<Power>,
    /// ∂/∂Im ñ_j, `e * films + j` (empty for [`Wrt::Thickness`]).
    pub d_index_im: Vec<Power>,
}

/// `exp(i z)` as in [`crate::stack`] (the same bits).
#[inline]
fn exp_i(z: C64) -> C64 {
    let (s, c) = elementary::sin_cos(z.re);
    if z.im == 0.0 {
        C64::new(c, s)
    } else {
        let m = elementary::exp(-z.im);
        C64::new(m * c, m * s)
    }
}

/// Per-thread working arrays of [`point_into`], so that a sweep allocates nothing per
/// element.
#[derive(Default)]
struct Scratch {
    q: Vec<C64>,
    n2: Vec<C64>,
    /// Per interface and polarisation: α, β, r, t.
    alpha: Vec<[C64; 2]>,
    beta: Vec<[C64; 2]>,
    r: Vec<[C64; 2]>,
    t: Vec<[C64; 2]>,
    /// Per film (index j − 1): e^{iδ_j}, E_j = e^{2iδ_j}.
    e: Vec<C64>,
    e2: Vec<C64>,
    /// Per medium: Γ_j per polarisation (j = 1 … N), and 1/D_j, g_j per interface j < N.
    gamma: Vec<[C64; 2]>,
    den_inv: Vec<[C64; 2]>,
    g: Vec<[C64; 2]>,
    /// Adjoints of q_j and ñ_j² (per medium) for index derivatives.
    a_q: Vec<C64>,
    a_n2: Vec<C64>,
    a_r: Vec<C64>,
    a_lnt: Vec<C64>,
    a_delta: Vec<C64>,
    /// The indices and sin θ₀ that q, ñ², α, β, r, t were computed for.
    prepared_for: Option<Vec<C64>>,
    sin_theta: f64,
}

impl Scratch {
    fn resize(&mut self, media: usize) {
        let zero = C64::new(0.0, 0.0);
        self.q.resize(media, zero);
        self.n2.resize(media, zero);
        for v in [
            &mut self.alpha,
            &mut self.beta,
            &mut self.r,
            &mut self.t,
            &mut self.gamma,
            &mut self.den_inv,
            &mut self.g,
        ] {
            v.resize(media, [zero; 2]);
        }
        for v in [
            &mut self.e,
            &mut self.e2,
            &mut self.a_q,
            &mut self.a_n2,
            &mut self.a_r,
            &mut self.a_lnt,
            &mut self.a_delta,
        ] {
            v.resize(media, zero);
        }
    }
}

/// The powers and their derivatives for media `indices` (ambient, films top first,
/// substrate; the ambient's index real), films `thickness_nm` (top first), incidence
/// sin θ₀ = `sin_theta` and vacuum wavelength `wavelength_nm`; see the module docs.
pub fn point_jacobian(
    indices: &[C64],
    thickness_nm: &[f64],
    sin_theta: f64,
    wavelength_nm: f64,
    wrt: Wrt,
) -> PointJacobian {
    let films = thickness_nm.len();
    assert_eq!(indices.len(), films + 2, "ambient, films and substrate");
    let mut out = PointJacobian {
        d_thickness: vec![Power::default(); films],
        ..Default::default()
    };
    if wrt == Wrt::ThicknessAndIndex {
        out.d_index_re = vec![Power::default(); films];
        out.d_index_im = vec![Power::default(); films];
    }
    let mut scratch = Scratch::default();
    out.power = point_into(
        &mut scratch,
        indices,
        thickness_nm,
        sin_theta,
        wavelength_nm,
        &mut out.d_thickness,
        (wrt == Wrt::ThicknessAndIndex).then_some((&mut out.d_index_re, &mut out.d_index_im)),
    );
    out
}

/// [`point_jacobian`] into caller-owned slices; returns the powers.
// The sweeps index several per-medium arrays by the same j, as the equations do.
#[allow(clippy::needless_range_loop)]
fn point_into(
    w: &mut Scratch,
    indices: &[C64],
    thickness_nm: &[f64],
    sin_theta: f64,
    wavelength_nm: f64,
    d_thickness: &mut [Power],
    mut d_index: Option<(&mut [Power], &mut [Power])>,
) -> Power {
    let n = thickness_nm.len();
    let media = n + 2;
    let k0 = wavenumber(wavelength_nm);
    // The media and interfaces depend on the indices and the angle only: kept from the last
    // element when those are the same (constant materials along a row).
    let same = w.prepared_for.as_deref() == Some(indices) && w.sin_theta == sin_theta;
    if !same {
        w.resize(media);
        let beta_t = indices[0].re * sin_theta;
        for (j, &nj) in indices.iter().enumerate() {
            w.q[j] = normal_component(nj, beta_t);
            w.n2[j] = nj * nj;
        }
        // Interfaces j = 0 … N: as `fresnel::Interface::new` (the same operations).
        for j in 0..=n {
            let (qi, qj) = (w.q[j], w.q[j + 1]);
            let sum_s = qi + qj;
            let a = w.n2[j + 1] * qi;
            let b = w.n2[j] * qj;
            let sum_p = a + b;
            w.alpha[j] = [qi, a];
            w.beta[j] = [qj, b];
            w.r[j] = [(qi - qj) / sum_s, (a - b) / sum_p];
            w.t[j] = [
                2.0 * qi / sum_s,
                2.0 * indices[j] * indices[j + 1] * qi / sum_p,
            ];
        }
        w.prepared_for = Some(indices.to_vec());
        w.sin_theta = sin_theta;
    }
    for j in 1..=n {
        let e = exp_i(w.q[j] * (k0 * thickness_nm[j - 1]));
        w.e[j - 1] = e;
        w.e2[j - 1] = e * e;
    }
    // Forward: Γ and τ as `Prepared::step` (the same operations).
    let mut gamma = w.r[n];
    let mut tau = w.t[n];
    w.gamma[n] = gamma;
    for j in (0..n).rev() {
        let (e, e2) = (w.e[j], w.e2[j]);
        for pol in 0..2 {
            let r = w.r[j][pol];
            let ge2 = gamma[pol] * e2;
            let den_inv = (1.0 + r * ge2).inv();
            w.g[j][pol] = ge2;
            w.den_inv[j][pol] = den_inv;
            gamma[pol] = (r + ge2) * den_inv;
            tau[pol] = w.t[j][pol] * tau[pol] * e * den_inv;
        }
        w.gamma[j] = gamma;
    }
    let last = media - 1;
    let factor = [
        power_factor_s(w.q[0], w.q[last]),
        power_factor_p(indices[0], w.q[0], indices[last], w.q[last]),
    ];
    let power = Power {
        R_s: gamma[0].norm_sqr(),
        R_p: gamma[1].norm_sqr(),
        T_s: tau[0].norm_sqr() * factor[0],
        T_p: tau[1].norm_sqr() * factor[1],
    };
    let powers = [[power.R_s, power.R_p], [power.T_s, power.T_p]];
    let i = C64::new(0.0, 1.0);
    let zero = C64::new(0.0, 0.0);
    for slot in d_thickness.iter_mut() {
        *slot = Power::default();
    }
    if let Some((re, im)) = d_index.as_mut() {
        re.fill(Power::default());
        im.fill(Power::default());
    }
    for pol in 0..2 {
        // Output 0: Γ₀ (R = |Γ₀|²); output 1: ln τ₀ (T = |τ₀|² F).
        for output in 0..2 {
            let tau_out = output == 1;
            // ∂R/∂x = 2 Re(conj Γ₀ ∂Γ₀/∂x); ∂T/∂x = 2 T Re(∂ ln τ₀/∂x).
            let project = if tau_out {
                C64::new(2.0 * powers[1][pol], 0.0)
            } else {
                2.0 * gamma[pol].conj()
            };
            let mut a_gamma = if tau_out { zero } else { C64::new(1.0, 0.0) };
            for j in 0..n {
                let r = w.r[j][pol];
                let g = w.g[j][pol];
                let di = w.den_inv[j][pol];
                let di2 = di * di;
                let mut a_g = a_gamma * (1.0 - r * r) * di2;
                let mut a_r = a_gamma * (1.0 - g * g) * di2;
                if tau_out {
                    a_g -= r * di;
                    a_r -= g * di;
                }
                w.a_r[j] = a_r;
                // g_j = Γ_{j+1} E_{j+1}; E = e^{2iδ}.
                let mut a_delta = a_g * w.gamma[j + 1][pol] * 2.0 * i * w.e2[j];
                if tau_out {
                    a_delta += i;
                }
                w.a_delta[j] = a_delta;
                a_gamma = a_g * w.e2[j];
                let slot = &mut d_thickness[j];
                let v = (project * a_delta * k0 * w.q[j + 1]).re;
                set(slot, output, pol, v);
            }
            w.a_r[n] = a_gamma;
            let Some((d_re, d_im)) = d_index.as_mut() else {
                continue;
            };
            let lnt = if tau_out { C64::new(1.0, 0.0) } else { zero };
            w.a_q.fill(zero);
            w.a_n2.fill(zero);
            for j in 0..n {
                w.a_q[j + 1] += w.a_delta[j] * k0 * thickness_nm[j];
            }
            for j in 0..=n {
                let (alpha, beta) = (w.alpha[j][pol], w.beta[j][pol]);
                let sigma = alpha + beta;
                let sigma_inv = sigma.inv();
                let s2 = sigma_inv * sigma_inv;
                let a_r = w.a_r[j];
                let a_alpha = a_r * 2.0 * beta * s2 + lnt * beta / alpha * sigma_inv;
                let a_beta = -(a_r * 2.0 * alpha * s2) - lnt * sigma_inv;
                if pol == 0 {
                    w.a_q[j] += a_alpha;
                    w.a_q[j + 1] += a_beta;
                } else {
                    // α = ñ_{j+1}² q_j, β = ñ_j² q_{j+1}; ln t_p += ½ ln ñ_j² − ½ ln ñ_{j+1}².
                    w.a_n2[j + 1] += a_alpha * w.q[j] - 0.5 * lnt / w.n2[j + 1];
                    w.a_q[j] += a_alpha * w.n2[j + 1];
                    w.a_n2[j] += a_beta * w.q[j + 1] + 0.5 * lnt / w.n2[j];
                    w.a_q[j + 1] += a_beta * w.n2[j];
                }
            }
            for j in 1..=n {
                // q = √(ñ² − β²): ∂q/∂ñ² = 1/(2q); ∂ñ²/∂ñ = 2ñ.
                let a_n2 = w.a_n2[j] + w.a_q[j] / (2.0 * w.q[j]);
                let a_n = a_n2 * 2.0 * indices[j];
                set(&mut d_re[j - 1], output, pol, (project * a_n).re);
                set(&mut d_im[j - 1], output, pol, (project * a_n * i).re);
            }
        }
    }
    power
}

/// Stores `v` as the derivative of output (0: R, 1: T) for polarisation `pol` (0: s, 1: p).
#[inline]
fn set(slot: &mut Power, output: usize, pol: usize, v: f64) {
    match (output, pol) {
        (0, 0) => slot.R_s = v,
        (0, _) => slot.R_p = v,
        (_, 0) => slot.T_s = v,
        _ => slot.T_p = v,
    }
}

/// Elements per parallel task of [`sweep_jacobian`] (a function of the sweep only, so the
/// results do not depend on the thread count; every element is computed alone anyway).
const CHUNK: usize = 256;

/// The powers of `stack` over every (angle, wavelength) pair (angle-major, as
/// [`Stack::sweep`]) and their derivatives `wrt` each film's thickness (per nm) and index;
/// see the module docs (by thickness alone, the vectorised sweep of "The vectorised sweep").
/// Errors as [`Stack::sweep`]; a stack with an incoherent layer is refused
/// ([`crate::Error::IncoherentLayer`]). The bits do not depend on the thread count.
pub fn sweep_jacobian(
    stack: &Stack,
    angles_deg: &[f64],
    wavelengths_nm: &[f64],
    wrt: Wrt,
) -> Result<SweepJacobian> {
    stack.require_coherent("derivatives")?;
    if wrt == Wrt::Thickness {
        let sweep = SpectrumSweep::new(stack, angles_deg, wavelengths_nm)?;
        if let Some((media, sines)) = sweep.kernel() {
            return Ok(kernel_jacobian(media, sines, wavelengths_nm.len()));
        }
    }
    let (sines, indices) = stack.resolve(angles_deg, wavelengths_nm)?;
    let thickness = stack.thicknesses_nm();
    let films = thickness.len();
    let per_angle = wavelengths_nm.len();
    let total = sines.len() * per_angle;
    let with_index = wrt == Wrt::ThicknessAndIndex;
    let mut out = SweepJacobian {
        films,
        power: vec![Power::default(); total],
        d_thickness: vec![Power::default(); total * films],
        d_index_re: vec![Power::default(); if with_index { total * films } else { 0 }],
        d_index_im: vec![Power::default(); if with_index { total * films } else { 0 }],
    };
    if total == 0 {
        return Ok(out);
    }
    let step = films.max(1) * CHUNK;
    let mut d_re: Vec<&mut [Power]> = out.d_index_re.chunks_mut(step).collect();
    let mut d_im: Vec<&mut [Power]> = out.d_index_im.chunks_mut(step).collect();
    d_re.resize_with(total.div_ceil(CHUNK), Default::default);
    d_im.resize_with(total.div_ceil(CHUNK), Default::default);
    out.power
        .par_chunks_mut(CHUNK)
        .zip(out.d_thickness.par_chunks_mut(step))
        .zip(d_re.par_iter_mut().zip(d_im.par_iter_mut()))
        .enumerate()
        .for_each_init(Scratch::default, |w, (c, ((power, d_t), (d_re, d_im)))| {
            for (k, p) in power.iter_mut().enumerate() {
                let e = c * CHUNK + k;
                let (a, wl) = (e / per_angle, e % per_angle);
                let span = k * films..(k + 1) * films;
                let index = with_index.then(|| (&mut d_re[span.clone()], &mut d_im[span.clone()]));
                *p = point_into(
                    w,
                    &indices[wl],
                    &thickness,
                    sines[a],
                    wavelengths_nm[wl],
                    &mut d_t[span],
                    index,
                );
            }
        });
    Ok(out)
}

/// The thickness Jacobian by the vectorised kernel ([`crate::multilayer`]'s `jacobian`
/// module) over `media`, one task per angle's row and [`CHUNK`] wavelengths (a multiple of the
/// kernel's padding): every element is computed alone, so the bits do not depend on the
/// thread count.
fn kernel_jacobian(media: &Media, sines: &[f64], per_angle: usize) -> SweepJacobian {
    let films = media.films();
    let total = sines.len() * per_angle;
    let mut out = SweepJacobian {
        films,
        power: vec![Power::default(); total],
        d_thickness: vec![Power::default(); total * films],
        d_index_re: Vec::new(),
        d_index_im: Vec::new(),
    };
    if total == 0 {
        return out;
    }
    // Per task: its powers and derivatives (none without films).
    let chunks = per_angle.div_ceil(CHUNK);
    let mut d_t: Vec<&mut [Power]> = out
        .d_thickness
        .chunks_mut(per_angle * films.max(1))
        .flat_map(|row| row.chunks_mut(CHUNK * films.max(1)))
        .collect();
    d_t.resize_with(sines.len() * chunks, Default::default);
    let mut power: Vec<&mut [Power]> = out
        .power
        .chunks_mut(per_angle)
        .flat_map(|row| row.chunks_mut(CHUNK))
        .collect();
    power
        .par_iter_mut()
        .zip(d_t.par_iter_mut())
        .enumerate()
        .for_each(|(task, (power, d_t))| {
            let (a, c) = (task / chunks, task % chunks);
            row_jacobian(media, sines[a], c * CHUNK, power, d_t, true);
        });
    out
}

/// A colour and its derivatives: `value` and, per parameter, `d[k]` = ∂value/∂p_k.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ColourJacobian {
    /// The colour (three components).
    pub value: [f64; 3],
    /// Per parameter: the derivative of each component.
    pub d: Vec<[f64; 3]>,
}

/// The chain rule through a spectral sum: for a colour c = Σ_k v_k W_k (the weights W_k of
/// [`crate::colour::Colorimeter::weights_1nm`] or [`crate::spectral::SpectralRule::weights`],
/// in XYZ or the output space), ∂c/∂p = Σ_k (∂v_k/∂p) W_k. `values[k]` is the spectral
/// quantity at node k (R or T) and `derivatives[k * params + p]` its derivative by
/// parameter p.
#[allow(clippy::needless_range_loop)]
pub fn colour_jacobian(
    weights: &[[f64; 3]],
    values: &[f64],
    derivatives: &[f64],
    params: usize,
) -> ColourJacobian {
    assert_eq!(weights.len(), values.len(), "one weight per node");
    assert_eq!(derivatives.len(), values.len() * params, "params per node");
    let mut out = ColourJacobian {
        value: [0.0; 3],
        d: vec![[0.0; 3]; params],
    };
    for (k, (w, &v)) in weights.iter().zip(values).enumerate() {
        for c in 0..3 {
            out.value[c] += v * w[c];
        }
        for (p, d) in out.d.iter_mut().enumerate() {
            let dv = derivatives[k * params + p];
            for c in 0..3 {
                d[c] += dv * w[c];
            }
        }
    }
    out
}

/// CIELAB ([`xyz_to_lab`]) of `xyz` and its derivatives by the chain rule: with
/// f(t) = t^{1/3} above (24/116)³ (f′ = 1/(3 t^{2/3})) and 841/108 t + 16/116 below
/// (f′ = 841/108),
///
/// ```text
/// ∂L*/∂p = 116 f′_Y ∂Y/∂p / Yₙ,   ∂a*/∂p = 500 (f′_X ∂X/∂p / Xₙ − f′_Y ∂Y/∂p / Yₙ),
/// ∂b*/∂p = 200 (f′_Y ∂Y/∂p / Yₙ − f′_Z ∂Z/∂p / Zₙ).
/// ```
pub fn lab_jacobian(xyz: &ColourJacobian, white_xyz: [f64; 3]) -> ColourJacobian {
    const EPS: f64 = (24.0 / 116.0) * (24.0 / 116.0) * (24.0 / 116.0);
    let slope = |c: usize| {
        let t = xyz.value[c] / white_xyz[c];
        let fp = if t > EPS {
            let cb = elementary::cbrt(t);
            1.0 / (3.0 * cb * cb)
        } else {
            841.0 / 108.0
        };
        fp / white_xyz[c]
    };
    let s = [slope(0), slope(1), slope(2)];
    ColourJacobian {
        value: xyz_to_lab(xyz.value, white_xyz),
        d: xyz
            .d
            .iter()
            .map(|d| {
                let (fx, fy, fz) = (s[0] * d[0], s[1] * d[1], s[2] * d[2]);
                [116.0 * fy, 500.0 * (fx - fy), 200.0 * (fy - fz)]
            })
            .collect(),
    }
}

/// CIELAB and its derivatives of a reflectance (or transmittance) given at the
/// colorimeter's 1 nm nodes (360–830 nm, [`Colorimeter::xyz_weights_1nm`]): XYZ by
/// [`colour_jacobian`], then [`lab_jacobian`] against the illuminant's white.
pub fn lab_of_spectrum(
    colorimeter: &Colorimeter,
    values: &[f64],
    derivatives: &[f64],
    params: usize,
) -> ColourJacobian {
    let xyz = colour_jacobian(colorimeter.xyz_weights_1nm(), values, derivatives, params);
    lab_jacobian(&xyz, colorimeter.white_xyz())
}

/// ΔE2000(target, lab) ([`delta_e_2000`]) and its gradient with respect to `lab`, by
/// forward-mode dual numbers through the same formula (module [`dual`]): exact up to
/// rounding wherever the formula is differentiable (not at ΔE = 0, where its gradient is
/// undefined and (0, 0, 0) is returned, nor across its hue branches).
pub fn delta_e_2000_gradient(target: [f64; 3], lab: [f64; 3]) -> (f64, [f64; 3]) {
    let value = delta_e_2000(target, lab);
    if value == 0.0 {
        return (0.0, [0.0; 3]);
    }
    let g = dual::delta_e_2000(target, lab);
    (value, g.d)
}

/// The gradient of ΔE2000(target, Lab(params)) by the chain rule from [`lab_jacobian`]'s
/// output: ∂ΔE/∂p = Σ_c ∂ΔE/∂Lab_c ∂Lab_c/∂p.
pub fn delta_e_2000_param_gradient(target: [f64; 3], lab: &ColourJacobian) -> (f64, Vec<f64>) {
    let (value, g) = delta_e_2000_gradient(target, lab.value);
    let grad = lab
        .d
        .iter()
        .map(|d| g[0] * d[0] + g[1] * d[1] + g[2] * d[2])
        .collect();
    (value, grad)
}

pub mod dual;
