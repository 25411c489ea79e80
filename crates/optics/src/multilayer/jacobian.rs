//! The thickness Jacobian in the vectorised kernel's form: the powers R_s, R_p, T_s, T_p and
//! their derivatives by every film's thickness, wavelengths as SIMD lanes over the same
//! [`Media`] as the value kernel ([`super`]); the fast path of
//! [`crate::jacobian::sweep_jacobian`].
//!
//! # Method
//!
//! A forward pass from the substrate up runs the value kernel's recurrence on fractions
//! Γ_j = N_j / D_j, operation for operation (the same media, interfaces, phases, rescalings
//! and powers: the powers are [`crate::Stack::sweep`]'s, bit for bit), and keeps per film
//! what the reverse pass needs. Level j (interface j from medium j into j + 1, film j + 1
//! below it, α, β the interface's admittances, ρ = α − β, σ = α + β, E = e^{2iδ_{j+1}},
//! δ = k₀ q d, s_j the power of two the level was rescaled by, 1 if none) is linear in
//! (N_{j+1}, D_{j+1}):
//!
//! ```text
//! N_j = s_j (σ E N_{j+1} + ρ D_{j+1}),     D_j = s_j (ρ E N_{j+1} + σ D_{j+1}),
//! ```
//!
//! starting from (N_N, D_N) = s_N (ρ_N, σ_N), which no thickness enters (Heavens 1955 §4;
//! [`super`]'s module docs). For a row vector of adjoints λ_j = ∂F/∂(N_j, D_j) of a
//! holomorphic F(N₀, D₀), reverse mode gives, with p = λN_j + λD_j and m = λN_j − λD_j
//! (σλN + ρλD = αp + βm, ρλN + σλD = αp − βm),
//!
//! ```text
//! λN_{j+1} = s_j E (α p + β m),   λD_{j+1} = s_j (α p − β m),   ∂F/∂δ_{j+1} = 2i λN_{j+1} N_{j+1}
//! ```
//!
//! (∂E/∂δ = 2iE), and ∂δ_{j+1}/∂d_{j+1} = k₀ q_{j+1}. Two adjoints per polarisation:
//!
//! * R = |N₀|²/|D₀|², ∂R = 2 Re(conj N₀ ∂N₀ − R conj D₀ ∂D₀)/|D₀|²: F = μ·(N₀, D₀) with
//!   μ₀ = (conj N₀, −R conj D₀)/|D₀|², so ∂R/∂d_{j+1} = −4 k₀ Im(μN_{j+1} N_{j+1} q_{j+1});
//! * T: τ₀ = Π_j (t_j σ_j s_j) Π_j e^{iδ_j} / D₀ (no thickness in the first product), so
//!   ∂ ln τ₀/∂δ_k = i − ∂ ln D₀/∂δ_k and, with λ₀ = (0, 1/D₀),
//!   ∂T/∂d_{j+1} = 2T Re(k₀ q ∂ ln τ₀/∂δ) = −2 T k₀ (Im q_{j+1} − 2 Im(λN_{j+1} N_{j+1} q_{j+1})).
//!
//! No division per film (one per element, shared with the powers), O(L) per element: the
//! chains are the prefix products of [`crate::jacobian`]'s module docs written on the
//! fractions. The rescalings s_j are exact powers of two, piecewise constant in the
//! thicknesses.
//!
//! # Determinism
//!
//! As the value kernel's: IEEE basic operations and written-out fused multiply–adds in a
//! fixed order, every lane a pure function of its (angle, wavelength), the same bits on every
//! vector width (tested against [`pulp::Scalar`]), so on every thread count.

use super::lanes::{Cx, Medium, add, interface, medium, mul, norm_sqr, sub};
use super::{BLOCK, Media, PAD, RESCALE_EVERY, power_of_two_scale};
use crate::power::Power;
use crate::simd::{ARCH, exp_neg_with, lane, lane_mut, madd, sin_cos_bounded_with};
use pulp::{Simd, WithSimd};

/// What the reverse pass keeps per film, in vectors of lanes: E (re, im), q (re, im), N per
/// polarisation (s re, im, p re, im), α_s, β_s, α_p, β_p (re, im each), s_j per polarisation.
const FIELDS: usize = 18;
const E: usize = 0;
const Q: usize = 2;
const NUM: usize = 4;
const ALPHA_BETA: usize = 8;
const SCALE: usize = 16;

/// Writes the powers and ∂/∂d_j per nm (film j of element w at `d_thickness[w * films + j]`)
/// at wavelengths `start .. start + powers.len()` of `media` (`start` a multiple of the arrays'
/// padding) and incidence sin θ₀ = `sin_theta`, on the CPU's widest vectors (`vector`) or
/// one lane at a time: the same bits either way.
pub(crate) fn row_jacobian(
    media: &Media,
    sin_theta: f64,
    start: usize,
    powers: &mut [Power],
    d_thickness: &mut [Power],
    vector: bool,
) {
    let films = media.thickness_nm.len();
    assert!(start.is_multiple_of(PAD), "rows start on the padding");
    assert!(start + powers.len() <= media.wavelengths);
    assert_eq!(d_thickness.len(), powers.len() * films);
    let op = JacobianOp {
        media,
        sin_theta,
        start,
        powers,
        d_thickness,
    };
    if vector {
        ARCH.dispatch(op)
    } else {
        op.with_simd(pulp::Scalar::new())
    }
}

struct JacobianOp<'a> {
    media: &'a Media,
    sin_theta: f64,
    start: usize,
    powers: &'a mut [Power],
    d_thickness: &'a mut [Power],
}

/// (N, D, U) scaled as [`super::Block::put`] does (by the power of two that brings
/// |Re D| + |Im D| into [1, 2), U by its square) when `rescale`, and the scale (1 if not).
#[inline(always)]
fn rescaled<S: Simd>(
    s: S,
    n: Cx<S>,
    d: Cx<S>,
    u: S::f64s,
    rescale: bool,
) -> (Cx<S>, Cx<S>, S::f64s, S::f64s) {
    if !rescale {
        return (n, d, u, s.splat_f64s(1.0));
    }
    let scale = power_of_two_scale(s, s.add_f64s(s.abs_f64s(d.re), s.abs_f64s(d.im)));
    let scale2 = s.mul_f64s(scale, scale);
    (
        scale_cx(s, n, scale),
        scale_cx(s, d, scale),
        s.mul_f64s(u, scale2),
        scale,
    )
}

#[inline(always)]
fn scale_cx<S: Simd>(s: S, a: Cx<S>, k: S::f64s) -> Cx<S> {
    Cx {
        re: s.mul_f64s(a.re, k),
        im: s.mul_f64s(a.im, k),
    }
}

/// Im(a b), rounded as the imaginary part of [`mul`].
#[inline(always)]
fn im_mul<S: Simd>(s: S, a: Cx<S>, b: Cx<S>) -> S::f64s {
    madd::<S, true>(s, a.im, b.re, s.mul_f64s(a.re, b.im))
}

impl WithSimd for JacobianOp<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, s: S) {
        let lanes = S::F64_LANES;
        let m = self.media;
        let films = m.thickness_nm.len();
        let count = films + 2;
        let n = self.powers.len();
        let mut keep = vec![0.0; films * FIELDS * lanes];
        let mut out = [[0.0; 8]; 4];
        let mut d_out = vec![[0.0; 8]; 4 * films];
        for v in (0..n).step_by(lanes) {
            let w = self.start + v;
            // A constant medium's arrays are one block of copies.
            let at = |constant: bool| if constant { w % BLOCK } else { w };
            let k0 = lane::<S>(&m.k0_per_nm, w);
            let beta = s.mul_f64s(
                lane::<S>(&m.re[0], at(m.beta_constant)),
                s.splat_f64s(self.sin_theta),
            );
            let beta2 = s.mul_f64s(beta, beta);
            let field = |j: usize, f: usize| (j * FIELDS + f) * lanes;
            // Forward: the value kernel's stages (`SUBSTRATE`, `FIRST`, `MEDIUM_PHASE`, `STEP`).
            let substrate = medium_of(s, m, count - 1, at(m.constant[count - 1]), beta2);
            let sub_re_n2_conj_q = madd::<S, true>(
                s,
                substrate.n2.im,
                substrate.q.im,
                s.mul_f64s(substrate.n2.re, substrate.q.re),
            );
            let mut below = substrate;
            let mut above = medium_of(s, m, count - 2, at(m.constant[count - 2]), beta2);
            let f = interface(s, &above, &below);
            let zero = Cx::<S> {
                re: s.splat_f64s(0.0),
                im: s.splat_f64s(0.0),
            };
            let mut num = [zero; 2];
            let mut den = [zero; 2];
            let mut u = [s.splat_f64s(0.0); 2];
            for pol in 0..2 {
                let (alpha, beta) = (f.alpha[pol], f.beta[pol]);
                let (rho, sigma) = (sub(s, alpha, beta), add(s, alpha, beta));
                (num[pol], den[pol], u[pol], _) = rescaled(s, rho, sigma, f.t_sigma2[pol], true);
            }
            for j in (0..count - 2).rev() {
                below = above;
                above = medium_of(s, m, j, at(m.constant[j]), beta2);
                // Film j + 1: E = e^{2iδ} = e^{−2 Im δ} (cos, sin)(2 Re δ), δ = k₀ q d.
                let kd2 = s.mul_f64s(k0, s.splat_f64s(2.0 * m.thickness_nm[j]));
                let (sin_x, cos_x) =
                    sin_cos_bounded_with::<S, true>(s, s.mul_f64s(below.q.re, kd2));
                let decay = exp_neg_with::<S, true>(s, s.mul_f64s(below.q.im, kd2));
                let e2 = Cx::<S> {
                    re: s.mul_f64s(decay, cos_x),
                    im: s.mul_f64s(decay, sin_x),
                };
                let f = interface(s, &above, &below);
                let base = field(j, 0);
                let k = |f: usize| base + f * lanes;
                put(s, &mut keep, k(E), e2.re);
                put(s, &mut keep, k(E + 1), e2.im);
                put(s, &mut keep, k(Q), below.q.re);
                put(s, &mut keep, k(Q + 1), below.q.im);
                let rescale = j.is_multiple_of(RESCALE_EVERY);
                for pol in 0..2 {
                    let (alpha, beta) = (f.alpha[pol], f.beta[pol]);
                    put(s, &mut keep, k(NUM + 2 * pol), num[pol].re);
                    put(s, &mut keep, k(NUM + 2 * pol + 1), num[pol].im);
                    put(s, &mut keep, k(ALPHA_BETA + 4 * pol), alpha.re);
                    put(s, &mut keep, k(ALPHA_BETA + 4 * pol + 1), alpha.im);
                    put(s, &mut keep, k(ALPHA_BETA + 4 * pol + 2), beta.re);
                    put(s, &mut keep, k(ALPHA_BETA + 4 * pol + 3), beta.im);
                    // N' = α(D + M) − β(D − M), D' = α(D + M) + β(D − M), M = N E.
                    let mm = mul(s, num[pol], e2);
                    let a = mul(s, alpha, add(s, den[pol], mm));
                    let b = mul(s, beta, sub(s, den[pol], mm));
                    let uu = s.mul_f64s(s.mul_f64s(f.t_sigma2[pol], u[pol]), decay);
                    let scale;
                    (num[pol], den[pol], u[pol], scale) =
                        rescaled(s, sub(s, a, b), add(s, a, b), uu, rescale);
                    put(s, &mut keep, k(SCALE + pol), scale);
                }
            }
            // Powers: the value kernel's `POWERS` (`above` is the ambient).
            let amb = above;
            let re_n2_conj_q =
                madd::<S, true>(s, amb.n2.im, amb.q.im, s.mul_f64s(amb.n2.re, amb.q.re));
            let x = amb.q.re;
            let y = s.mul_f64s(substrate.n_abs2, re_n2_conj_q);
            let d2 = [norm_sqr(s, den[0]), norm_sqr(s, den[1])];
            let xy = s.mul_f64s(x, y);
            let dd = s.mul_f64s(d2[0], d2[1]);
            let inv_all = s.div_f64s(s.splat_f64s(1.0), s.mul_f64s(xy, dd));
            let inv_dd = s.mul_f64s(xy, inv_all);
            let inv_xy = s.mul_f64s(dd, inv_all);
            let inv = [s.mul_f64s(d2[1], inv_dd), s.mul_f64s(d2[0], inv_dd)];
            let factor_s = s.mul_f64s(substrate.q.re, s.mul_f64s(y, inv_xy));
            let factor_p = s.mul_f64s(
                s.mul_f64s(sub_re_n2_conj_q, amb.n_abs2),
                s.mul_f64s(x, inv_xy),
            );
            let p = [
                s.mul_f64s(norm_sqr(s, num[0]), inv[0]),
                s.mul_f64s(norm_sqr(s, num[1]), inv[1]),
                s.mul_f64s(s.mul_f64s(u[0], inv[0]), factor_s),
                s.mul_f64s(s.mul_f64s(u[1], inv[1]), factor_p),
            ];
            for (k, &value) in p.iter().enumerate() {
                *lane_mut::<S>(&mut out[k], 0) = value;
            }
            // Reverse: μ (for R) and λ (for T) per polarisation, from the top down.
            let four_k0 = s.mul_f64s(s.splat_f64s(-4.0), k0);
            for pol in 0..2 {
                let (n0, d0, inv) = (num[pol], den[pol], inv[pol]);
                let r_inv = s.mul_f64s(p[pol], inv);
                let mut mu = [
                    Cx::<S> {
                        re: s.mul_f64s(n0.re, inv),
                        im: s.neg_f64s(s.mul_f64s(n0.im, inv)),
                    },
                    Cx::<S> {
                        re: s.neg_f64s(s.mul_f64s(d0.re, r_inv)),
                        im: s.mul_f64s(d0.im, r_inv),
                    },
                ];
                let mut lambda = [
                    zero,
                    Cx::<S> {
                        re: s.mul_f64s(d0.re, inv),
                        im: s.neg_f64s(s.mul_f64s(d0.im, inv)),
                    },
                ];
                // −2 T k₀.
                let two_t_k0 = s.mul_f64s(s.mul_f64s(s.splat_f64s(-2.0), p[2 + pol]), k0);
                for j in 0..films {
                    let k = |f: usize| field(j, f);
                    let e2 = get_cx::<S>(&keep, k(E), lanes);
                    let q = get_cx::<S>(&keep, k(Q), lanes);
                    let alpha = get_cx::<S>(&keep, k(ALPHA_BETA + 4 * pol), lanes);
                    let beta = get_cx::<S>(&keep, k(ALPHA_BETA + 4 * pol + 2), lanes);
                    let scale = lane::<S>(&keep, k(SCALE + pol));
                    mu = adjoint_step(s, alpha, beta, e2, scale, mu);
                    lambda = adjoint_step(s, alpha, beta, e2, scale, lambda);
                    let z = mul(s, q, get_cx::<S>(&keep, k(NUM + 2 * pol), lanes));
                    let d_r = s.mul_f64s(four_k0, im_mul(s, mu[0], z));
                    let d_t = s.mul_f64s(two_t_k0, nmadd2(s, im_mul(s, lambda[0], z), q.im));
                    *lane_mut::<S>(&mut d_out[4 * j + pol], 0) = d_r;
                    *lane_mut::<S>(&mut d_out[4 * j + 2 + pol], 0) = d_t;
                }
            }
            for k in 0..lanes.min(n - v) {
                let e = v + k;
                self.powers[e] = Power {
                    R_s: out[0][k],
                    R_p: out[1][k],
                    T_s: out[2][k],
                    T_p: out[3][k],
                };
                for (j, d) in self.d_thickness[e * films..(e + 1) * films]
                    .iter_mut()
                    .enumerate()
                {
                    *d = Power {
                        R_s: d_out[4 * j][k],
                        R_p: d_out[4 * j + 1][k],
                        T_s: d_out[4 * j + 2][k],
                        T_p: d_out[4 * j + 3][k],
                    };
                }
            }
        }
    }
}

/// Medium j at lanes `i ..` of its arrays (the general formula of [`medium`]).
#[inline(always)]
fn medium_of<S: Simd>(s: S, m: &Media, j: usize, i: usize, beta2: S::f64s) -> Medium<S> {
    let n2 = Cx::<S> {
        re: lane::<S>(&m.n2_re[j], i),
        im: lane::<S>(&m.n2_im[j], i),
    };
    medium::<S, 0>(s, lane::<S>(&m.n_abs2[j], i), n2, beta2)
}

/// Keeps `x` at lanes `at ..` of `keep`.
#[inline(always)]
fn put<S: Simd>(_: S, keep: &mut [f64], at: usize, x: S::f64s) {
    *lane_mut::<S>(keep, at) = x;
}

/// The complex number kept at `at` (real part) and `at + lanes` (imaginary part).
#[inline(always)]
fn get_cx<S: Simd>(keep: &[f64], at: usize, lanes: usize) -> Cx<S> {
    Cx {
        re: lane::<S>(keep, at),
        im: lane::<S>(keep, at + lanes),
    }
}

/// One level of the reverse sweep: (λN_{j+1}, λD_{j+1}) from (λN_j, λD_j) = `c` (module
/// docs): p = λN + λD, m = λN − λD, λN' = s E (αp + βm), λD' = s (αp − βm).
#[inline(always)]
fn adjoint_step<S: Simd>(
    s: S,
    alpha: Cx<S>,
    beta: Cx<S>,
    e2: Cx<S>,
    scale: S::f64s,
    c: [Cx<S>; 2],
) -> [Cx<S>; 2] {
    let a = mul(s, alpha, add(s, c[0], c[1]));
    let b = mul(s, beta, sub(s, c[0], c[1]));
    [
        scale_cx(s, mul(s, e2, add(s, a, b)), scale),
        scale_cx(s, sub(s, a, b), scale),
    ]
}

/// q − 2 z, as (−2) z + q in one fused multiply–add.
#[inline(always)]
fn nmadd2<S: Simd>(s: S, z: S::f64s, q: S::f64s) -> S::f64s {
    madd::<S, true>(s, s.splat_f64s(-2.0), z, q)
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64 as C64;

    /// The CPU's widest vectors and one lane at a time give the same bits, over rows whose
    /// last vector is partial, absorbing and evanescent media, and from an offset start.
    #[test]
    fn vectors_and_one_lane_give_the_same_bits() {
        let films = [
            (C64::new(2.3, 0.0), 120.0),
            (C64::new(1.46, 0.0), 250.0),
            (C64::new(1.9, 0.4), 35.0),
            (C64::new(1.0, 0.0), 400.0),
            (C64::new(2.3, 0.0), 120.0),
        ];
        for count in [1, 7, 19, 64, 77] {
            let wl: Vec<f64> = (0..count)
                .map(|i| 380.0 + 400.0 * i as f64 / count as f64)
                .collect();
            let indices: Vec<Vec<C64>> = wl
                .iter()
                .map(|&w| {
                    let mut idx = vec![C64::new(1.5, 0.0)];
                    idx.extend(films.iter().map(|f| f.0 + C64::new(w * 1e-4, 0.0)));
                    idx.push(C64::new(0.3, 3.0));
                    idx
                })
                .collect();
            let thickness: Vec<f64> = films.iter().map(|f| f.1).collect();
            let media = Media::new(&indices, &wl, &thickness).unwrap();
            for sin_theta in [0.0, 0.5, 0.8, 0.99] {
                let run = |start: usize, vector: bool| {
                    let n = count - start;
                    let mut p = vec![Power::default(); n];
                    let mut d = vec![Power::default(); n * thickness.len()];
                    row_jacobian(&media, sin_theta, start, &mut p, &mut d, vector);
                    (p, d)
                };
                let bits = |v: &[Power]| -> Vec<[u64; 4]> {
                    v.iter()
                        .map(|p| [p.R_s, p.R_p, p.T_s, p.T_p].map(f64::to_bits))
                        .collect()
                };
                let (pv, dv) = run(0, true);
                let (ps, ds) = run(0, false);
                assert_eq!(bits(&pv), bits(&ps));
                assert_eq!(bits(&dv), bits(&ds));
                // The powers are the value kernel's.
                let mut value = vec![Power::default(); count];
                super::super::stack_powers(&media, sin_theta, &mut value, true);
                assert_eq!(bits(&pv), bits(&value));
                if count > 8 {
                    let (po, d_o) = run(8, true);
                    assert_eq!(bits(&po), bits(&pv[8..]));
                    assert_eq!(bits(&d_o), bits(&dv[8 * thickness.len()..]));
                }
            }
        }
    }
}
