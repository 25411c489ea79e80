//! The single-film (Airy) thickness sweep, vectorised: per (angle, wavelength) row
//! ([`AiryRow`]) the powers at many thicknesses ([`airy_powers`]) or their colour sums
//! ([`airy_accumulate`]), on the kernels of [`crate::simd`] with the same bits on every CPU
//! (tested: `simd_and_scalar_paths_are_bit_identical`).
//!
//! Over the top film the recurrence of [`crate::stack`] is the Airy closed form
//! r = (r₀₁ + Γ₁ e^{2iδ₁}) / (1 + r₀₁Γ₁ e^{2iδ₁}) (Born & Wolf §1.6.5; Belcour & Barla 2017,
//! Eq. 2), in which e^{2iδ₁} = e^{i z d} is the only term that changes with the thickness d;
//! on a uniform thickness grid it is stepped by complex multiplication between exact anchors.

use crate::power::{Power, PowerSlot};
use crate::simd::{ARCH, exp_neg, lane, lane_mut, sin_cos};
use pulp::{Simd, WithSimd};
/// The constants of one (angle, wavelength) row of the top-film Airy sweep (see
/// `stack::ThicknessSweep`): per polarisation (s, p) r₀₁, Γ₁, r₀₁Γ₁ as (re, im) and
/// |t₀₁τ₁|² × power factor; and z = 2 k₀ q₁, so that e^{2iδ₁} = e^{i z d}.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AiryRow {
    pub r01: [[f64; 2]; 2],
    pub gamma: [[f64; 2]; 2],
    pub r01_gamma: [[f64; 2]; 2],
    pub t_norm: [f64; 2],
    pub z_re: f64,
    pub z_im: f64,
}

impl AiryRow {
    /// Whether r₀₁ and Γ₁ (both polarisations) are real.
    fn is_real(&self) -> bool {
        self.r01.iter().chain(&self.gamma).all(|c| c[1] == 0.0)
    }
}

/// [`AiryRow`] splatted into lanes.
#[derive(Clone, Copy)]
struct Lanes<S: Simd> {
    r01: [[S::f64s; 2]; 2],
    gamma: [[S::f64s; 2]; 2],
    r01_gamma: [[S::f64s; 2]; 2],
    t_norm: [S::f64s; 2],
    z_re: S::f64s,
    z_im: S::f64s,
}

impl<S: Simd> Lanes<S> {
    #[inline(always)]
    fn new(s: S, row: &AiryRow) -> Self {
        #[inline(always)]
        fn c<S: Simd>(s: S, v: [f64; 2]) -> [S::f64s; 2] {
            [s.splat_f64s(v[0]), s.splat_f64s(v[1])]
        }
        Lanes {
            r01: [c(s, row.r01[0]), c(s, row.r01[1])],
            gamma: [c(s, row.gamma[0]), c(s, row.gamma[1])],
            r01_gamma: [c(s, row.r01_gamma[0]), c(s, row.r01_gamma[1])],
            t_norm: [s.splat_f64s(row.t_norm[0]), s.splat_f64s(row.t_norm[1])],
            z_re: s.splat_f64s(row.z_re),
            z_im: s.splat_f64s(row.z_im),
        }
    }

    /// e^{2iδ} = e^{i z d} = e^{−Im z·d} (cos(Re z·d), sin(Re z·d)) at film thicknesses `d`
    /// (nm), as (re, im, modulus). `ABSORBING = false` skips e^{−Im z·d} when Im z = 0 (the
    /// factor is then exactly 1 and multiplying by it changes no bit, so both variants agree).
    #[inline(always)]
    fn phasor<const ABSORBING: bool>(&self, s: S, d: S::f64s) -> [S::f64s; 3] {
        let (sin_x, cos_x) = sin_cos(s, s.mul_f64s(self.z_re, d));
        if ABSORBING {
            let m = exp_neg(s, s.mul_f64s(self.z_im, d));
            [s.mul_f64s(m, cos_x), s.mul_f64s(m, sin_x), m]
        } else {
            [cos_x, sin_x, s.splat_f64s(1.0)]
        }
    }

    /// (R_s, R_p, T_s, T_p) from e^{2iδ} = (e_re, e_im) of modulus `e_norm`:
    ///   R = |r₀₁ + Γ₁ e^{2iδ}|² / |1 + r₀₁Γ₁ e^{2iδ}|²,
    ///   T = |t₀₁τ₁|² × factor × |e^{2iδ}| / |1 + r₀₁Γ₁ e^{2iδ}|²
    /// (Belcour & Barla 2017, Eq. 2; the recurrence of `stack` without complex division).
    /// One division serves both polarisations: 1/D_s = D_p / (D_s D_p), 1/D_p = D_s / (D_s D_p)
    /// (D ≥ (1 − |r₀₁Γ₁|)², far from under- or overflow).
    ///
    /// The variants drop operations whose result they know: `REAL` when r₀₁, Γ₁ (hence
    /// r₀₁Γ₁) are real (products with a zero imaginary part are ±0, and adding ±0 changes no
    /// bit of a square), `ABSORBING = false` when |e^{2iδ}| = 1 exactly; each variant gives
    /// the same bits as the general formula.
    #[inline(always)]
    fn airy<const ABSORBING: bool, const REAL: bool>(
        &self,
        s: S,
        [e_re, e_im, e_norm]: [S::f64s; 3],
    ) -> [S::f64s; 4] {
        let one = s.splat_f64s(1.0);
        let mut num2 = [one; 2];
        let mut den2 = [one; 2];
        for pol in 0..2 {
            let [g_re, g_im] = self.gamma[pol];
            let [r_re, r_im] = self.r01[pol];
            let [rg_re, rg_im] = self.r01_gamma[pol];
            let (num_re, num_im, den_re, den_im) = if REAL {
                (
                    s.add_f64s(r_re, s.mul_f64s(g_re, e_re)),
                    s.mul_f64s(g_re, e_im),
                    s.add_f64s(one, s.mul_f64s(rg_re, e_re)),
                    s.mul_f64s(rg_re, e_im),
                )
            } else {
                (
                    s.add_f64s(
                        r_re,
                        s.sub_f64s(s.mul_f64s(g_re, e_re), s.mul_f64s(g_im, e_im)),
                    ),
                    s.add_f64s(
                        r_im,
                        s.add_f64s(s.mul_f64s(g_re, e_im), s.mul_f64s(g_im, e_re)),
                    ),
                    s.add_f64s(
                        one,
                        s.sub_f64s(s.mul_f64s(rg_re, e_re), s.mul_f64s(rg_im, e_im)),
                    ),
                    s.add_f64s(s.mul_f64s(rg_re, e_im), s.mul_f64s(rg_im, e_re)),
                )
            };
            num2[pol] = s.add_f64s(s.mul_f64s(num_re, num_re), s.mul_f64s(num_im, num_im));
            den2[pol] = s.add_f64s(s.mul_f64s(den_re, den_re), s.mul_f64s(den_im, den_im));
        }
        let inv_both = s.div_f64s(one, s.mul_f64s(den2[0], den2[1]));
        let inv = [s.mul_f64s(den2[1], inv_both), s.mul_f64s(den2[0], inv_both)];
        let t = if ABSORBING {
            [
                s.mul_f64s(self.t_norm[0], e_norm),
                s.mul_f64s(self.t_norm[1], e_norm),
            ]
        } else {
            self.t_norm
        };
        [
            s.mul_f64s(num2[0], inv[0]),
            s.mul_f64s(num2[1], inv[1]),
            s.mul_f64s(t[0], inv[0]),
            s.mul_f64s(t[1], inv[1]),
        ]
    }
}

/// Elements between exact phasors on a uniform thickness grid (a divisor of [`BLOCK`], and a
/// multiple of every vector width).
const ANCHOR: usize = 8;

/// The phasors e^{i z d_k} of one block of at most [`BLOCK`] thicknesses, (re, im, modulus).
struct Phasors {
    re: [f64; BLOCK],
    im: [f64; BLOCK],
    norm: [f64; BLOCK],
}

/// Per-row steps of a uniform grid d_k = d₀ + k h: P_j = e^{i z j h}, j < [`ANCHOR`].
struct Steps {
    re: [f64; ANCHOR],
    im: [f64; ANCHOR],
    norm: [f64; ANCHOR],
}

/// e^{i z d_k} for every element of `d`, exactly, into (re, im, norm).
#[inline(always)]
fn exact<S: Simd, const ABSORBING: bool>(
    s: S,
    lanes: &Lanes<S>,
    one: &Lanes<pulp::Scalar>,
    d: &[f64],
    re: &mut [f64],
    im: &mut [f64],
    norm: &mut [f64],
) {
    let scalar = pulp::Scalar::new();
    let (dv, dt) = S::as_simd_f64s(d);
    let (rv, rt) = S::as_mut_simd_f64s(re);
    let (iv, it) = S::as_mut_simd_f64s(im);
    let (nv, nt) = S::as_mut_simd_f64s(norm);
    for (i, &dk) in dv.iter().enumerate() {
        [rv[i], iv[i], nv[i]] = lanes.phasor::<ABSORBING>(s, dk);
    }
    for (i, &dk) in dt.iter().enumerate() {
        [rt[i], it[i], nt[i]] = one.phasor::<ABSORBING>(scalar, dk);
    }
}

/// The phasors of one block `d` (its first element at a multiple of [`ANCHOR`] in the row):
/// exact (e^{i z d_k} by [`sin_cos`] and [`exp_neg`]) for every element, or, on a uniform
/// grid (`steps`), exact at every [`ANCHOR`]-th element A_m = e^{i z d_{8m}} and
/// A_m P_j = e^{i z (d_{8m} + j h)} between — one complex product per element. Either way
/// element k depends only on the thicknesses and k, not on the vector width.
#[inline(always)]
fn phasors<S: Simd, const ABSORBING: bool>(
    s: S,
    lanes: &Lanes<S>,
    one: &Lanes<pulp::Scalar>,
    d: &[f64],
    steps: Option<&Steps>,
    out: &mut Phasors,
) {
    let n = d.len();
    let Some(steps) = steps else {
        exact::<S, ABSORBING>(
            s,
            lanes,
            one,
            d,
            &mut out.re[..n],
            &mut out.im[..n],
            &mut out.norm[..n],
        );
        return;
    };
    const ANCHORS: usize = BLOCK / ANCHOR;
    let mut anchor_d = [0.0; ANCHORS];
    for (m, a) in anchor_d.iter_mut().enumerate() {
        *a = d.get(m * ANCHOR).copied().unwrap_or(0.0);
    }
    let (mut a_re, mut a_im, mut a_norm) = ([0.0; ANCHORS], [0.0; ANCHORS], [0.0; ANCHORS]);
    exact::<S, ABSORBING>(s, lanes, one, &anchor_d, &mut a_re, &mut a_im, &mut a_norm);
    let head = n - n % S::F64_LANES;
    for start in (0..head).step_by(S::F64_LANES) {
        let (m, j) = (start / ANCHOR, start % ANCHOR);
        let (p_re, p_im) = (lane::<S>(&steps.re, j), lane::<S>(&steps.im, j));
        let (ar, ai) = (s.splat_f64s(a_re[m]), s.splat_f64s(a_im[m]));
        let re = s.sub_f64s(s.mul_f64s(ar, p_re), s.mul_f64s(ai, p_im));
        let im = s.add_f64s(s.mul_f64s(ar, p_im), s.mul_f64s(ai, p_re));
        let norm = s.mul_f64s(s.splat_f64s(a_norm[m]), lane::<S>(&steps.norm, j));
        *lane_mut::<S>(&mut out.re, start) = re;
        *lane_mut::<S>(&mut out.im, start) = im;
        *lane_mut::<S>(&mut out.norm, start) = norm;
    }
    for k in head..n {
        let (m, j) = (k / ANCHOR, k % ANCHOR);
        out.re[k] = a_re[m] * steps.re[j] - a_im[m] * steps.im[j];
        out.im[k] = a_re[m] * steps.im[j] + a_im[m] * steps.re[j];
        out.norm[k] = a_norm[m] * steps.norm[j];
    }
}

/// Elements per block of the kernels' staging buffers.
const BLOCK: usize = 64;

/// The steps P_j of a uniform grid of spacing `uniform_step_nm` ([`uniform_step`]), or `None`.
#[inline(always)]
fn steps_of<S: Simd, const ABSORBING: bool>(
    s: S,
    lanes: &Lanes<S>,
    one: &Lanes<pulp::Scalar>,
    uniform_step_nm: Option<f64>,
) -> Option<Steps> {
    let h = uniform_step_nm?;
    let d: [f64; ANCHOR] = std::array::from_fn(|j| j as f64 * h);
    let mut p = Phasors {
        re: [0.0; BLOCK],
        im: [0.0; BLOCK],
        norm: [0.0; BLOCK],
    };
    phasors::<S, ABSORBING>(s, lanes, one, &d, None, &mut p);
    Some(Steps {
        re: std::array::from_fn(|j| p.re[j]),
        im: std::array::from_fn(|j| p.im[j]),
        norm: std::array::from_fn(|j| p.norm[j]),
    })
}

/// The common spacing h of `values` when every value lies within a few ulps of
/// `values[0] + k h` (so that stepping a phasor is as exact as evaluating it).
pub(crate) fn uniform_step(values: &[f64]) -> Option<f64> {
    let n = values.len();
    if n < 3 {
        return None;
    }
    let step = (values[n - 1] - values[0]) / (n - 1) as f64;
    let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let tolerance = 8.0 * f64::EPSILON * scale;
    let uniform = step > 0.0
        && values
            .iter()
            .enumerate()
            .all(|(k, &v)| (v - (values[0] + k as f64 * step)).abs() <= tolerance);
    uniform.then_some(step)
}

/// Writes into `out[k]` the powers of `row` at thickness `thickness_nm[k]`, on the CPU's
/// widest vectors (`vector = true`) or one lane at a time; both give the same bits.
/// `uniform_step_nm` is [`uniform_step`] of `thickness_nm`.
pub(crate) fn airy_powers<T: PowerSlot>(
    row: &AiryRow,
    thickness_nm: &[f64],
    uniform_step_nm: Option<f64>,
    out: &mut [T],
    vector: bool,
) {
    let op = PowersOp {
        row,
        thickness_nm,
        uniform_step_nm,
        out,
    };
    if vector {
        ARCH.dispatch(op)
    } else {
        op.with_simd(pulp::Scalar::new())
    }
}

struct PowersOp<'a, T> {
    row: &'a AiryRow,
    thickness_nm: &'a [f64],
    uniform_step_nm: Option<f64>,
    out: &'a mut [T],
}

impl<T: PowerSlot> WithSimd for PowersOp<'_, T> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, s: S) {
        match (self.row.z_im == 0.0, self.row.is_real()) {
            (true, true) => self.run::<S, false, true>(s),
            (true, false) => self.run::<S, false, false>(s),
            (false, true) => self.run::<S, true, true>(s),
            (false, false) => self.run::<S, true, false>(s),
        }
    }
}

impl<T: PowerSlot> PowersOp<'_, T> {
    #[inline(always)]
    fn run<S: Simd, const ABSORBING: bool, const REAL: bool>(self, s: S) {
        let lanes = Lanes::<S>::new(s, self.row);
        let scalar = pulp::Scalar::new();
        let one = Lanes::<pulp::Scalar>::new(scalar, self.row);
        let steps = steps_of::<S, ABSORBING>(s, &lanes, &one, self.uniform_step_nm);
        let mut e = Phasors {
            re: [0.0; BLOCK],
            im: [0.0; BLOCK],
            norm: [0.0; BLOCK],
        };
        for (d, out) in self
            .thickness_nm
            .chunks(BLOCK)
            .zip(self.out.chunks_mut(BLOCK))
        {
            let n = d.len();
            phasors::<S, ABSORBING>(s, &lanes, &one, d, steps.as_ref(), &mut e);
            let (re, re_t) = S::as_simd_f64s(&e.re[..n]);
            let (im, im_t) = S::as_simd_f64s(&e.im[..n]);
            let (norm, norm_t) = S::as_simd_f64s(&e.norm[..n]);
            let head = re.len() * S::F64_LANES;
            let (out_v, out_t) = out.split_at_mut(head);
            for (i, chunk) in out_v.chunks_exact_mut(S::F64_LANES).enumerate() {
                let p = lanes.airy::<ABSORBING, REAL>(s, [re[i], im[i], norm[i]]);
                let p: [&[f64]; 4] = [
                    bytemuck::cast_slice(std::slice::from_ref(&p[0])),
                    bytemuck::cast_slice(std::slice::from_ref(&p[1])),
                    bytemuck::cast_slice(std::slice::from_ref(&p[2])),
                    bytemuck::cast_slice(std::slice::from_ref(&p[3])),
                ];
                for (l, slot) in chunk.iter_mut().enumerate() {
                    slot.put(Power {
                        R_s: p[0][l],
                        R_p: p[1][l],
                        T_s: p[2][l],
                        T_p: p[3][l],
                    });
                }
            }
            for (i, slot) in out_t.iter_mut().enumerate() {
                let [rs, rp, ts, tp] =
                    one.airy::<ABSORBING, REAL>(scalar, [re_t[i], im_t[i], norm_t[i]]);
                slot.put(Power {
                    R_s: rs,
                    R_p: rp,
                    T_s: ts,
                    T_p: tp,
                });
            }
        }
    }
}

/// Running colour sums of a thickness sweep, channel-major: `reflectance[c][k]`,
/// `transmittance[c][k]` for thickness k.
pub(crate) struct ColourSums {
    pub reflectance: [Vec<f64>; 3],
    pub transmittance: [Vec<f64>; 3],
}

impl ColourSums {
    pub(crate) fn new(n: usize) -> Self {
        let z = || [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        ColourSums {
            reflectance: z(),
            transmittance: z(),
        }
    }
}

/// Adds, for every thickness k, R(d_k) w and T(d_k) w to `sums` (R = (R_s + R_p)/2,
/// T = (T_s + T_p)/2, w the node's weights per channel), on the CPU's widest vectors
/// (`vector = true`) or one lane at a time; both give the same bits. `uniform_step_nm` is
/// [`uniform_step`] of `thickness_nm`.
pub(crate) fn airy_accumulate(
    row: &AiryRow,
    thickness_nm: &[f64],
    uniform_step_nm: Option<f64>,
    weights: [f64; 3],
    sums: &mut ColourSums,
    vector: bool,
) {
    let op = AccumulateOp {
        row,
        thickness_nm,
        uniform_step_nm,
        weights,
        sums,
    };
    if vector {
        ARCH.dispatch(op)
    } else {
        op.with_simd(pulp::Scalar::new())
    }
}

struct AccumulateOp<'a> {
    row: &'a AiryRow,
    thickness_nm: &'a [f64],
    uniform_step_nm: Option<f64>,
    weights: [f64; 3],
    sums: &'a mut ColourSums,
}

impl WithSimd for AccumulateOp<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, s: S) {
        match (self.row.z_im == 0.0, self.row.is_real()) {
            (true, true) => self.run::<S, false, true>(s),
            (true, false) => self.run::<S, false, false>(s),
            (false, true) => self.run::<S, true, true>(s),
            (false, false) => self.run::<S, true, false>(s),
        }
    }
}

/// One element's (or lane's) contribution: R w and T w added to the six sums.
#[inline(always)]
fn accumulate_one<S: Simd, const ABSORBING: bool, const REAL: bool>(
    s: S,
    lanes: &Lanes<S>,
    w: &[S::f64s; 3],
    e: [S::f64s; 3],
    r: [&mut S::f64s; 3],
    t: [&mut S::f64s; 3],
) {
    let [rs, rp, ts, tp] = lanes.airy::<ABSORBING, REAL>(s, e);
    let half = s.splat_f64s(0.5);
    let rv = s.mul_f64s(half, s.add_f64s(rs, rp));
    let tv = s.mul_f64s(half, s.add_f64s(ts, tp));
    for (c, (r, t)) in r.into_iter().zip(t).enumerate() {
        *r = s.add_f64s(*r, s.mul_f64s(rv, w[c]));
        *t = s.add_f64s(*t, s.mul_f64s(tv, w[c]));
    }
}

impl AccumulateOp<'_> {
    #[inline(always)]
    fn run<S: Simd, const ABSORBING: bool, const REAL: bool>(self, s: S) {
        let lanes = Lanes::<S>::new(s, self.row);
        let w = [
            s.splat_f64s(self.weights[0]),
            s.splat_f64s(self.weights[1]),
            s.splat_f64s(self.weights[2]),
        ];
        let scalar = pulp::Scalar::new();
        let one = Lanes::<pulp::Scalar>::new(scalar, self.row);
        let steps = steps_of::<S, ABSORBING>(s, &lanes, &one, self.uniform_step_nm);
        let mut e = Phasors {
            re: [0.0; BLOCK],
            im: [0.0; BLOCK],
            norm: [0.0; BLOCK],
        };
        let [r0, r1, r2] = &mut self.sums.reflectance;
        let [t0, t1, t2] = &mut self.sums.transmittance;
        let blocks = self.thickness_nm.chunks(BLOCK).zip(
            r0.chunks_mut(BLOCK)
                .zip(r1.chunks_mut(BLOCK))
                .zip(r2.chunks_mut(BLOCK))
                .zip(
                    t0.chunks_mut(BLOCK)
                        .zip(t1.chunks_mut(BLOCK))
                        .zip(t2.chunks_mut(BLOCK)),
                ),
        );
        for (d, (((r0, r1), r2), ((t0, t1), t2))) in blocks {
            let n = d.len();
            phasors::<S, ABSORBING>(s, &lanes, &one, d, steps.as_ref(), &mut e);
            let (re, re_t) = S::as_simd_f64s(&e.re[..n]);
            let (im, im_t) = S::as_simd_f64s(&e.im[..n]);
            let (norm, norm_t) = S::as_simd_f64s(&e.norm[..n]);
            let (r0v, r0t) = S::as_mut_simd_f64s(r0);
            let (r1v, r1t) = S::as_mut_simd_f64s(r1);
            let (r2v, r2t) = S::as_mut_simd_f64s(r2);
            let (t0v, t0t) = S::as_mut_simd_f64s(t0);
            let (t1v, t1t) = S::as_mut_simd_f64s(t1);
            let (t2v, t2t) = S::as_mut_simd_f64s(t2);
            for i in 0..re.len() {
                accumulate_one::<S, ABSORBING, REAL>(
                    s,
                    &lanes,
                    &w,
                    [re[i], im[i], norm[i]],
                    [&mut r0v[i], &mut r1v[i], &mut r2v[i]],
                    [&mut t0v[i], &mut t1v[i], &mut t2v[i]],
                );
            }
            for i in 0..re_t.len() {
                accumulate_one::<pulp::Scalar, ABSORBING, REAL>(
                    scalar,
                    &one,
                    &self.weights,
                    [re_t[i], im_t[i], norm_t[i]],
                    [&mut r0t[i], &mut r1t[i], &mut r2t[i]],
                    [&mut t0t[i], &mut t1t[i], &mut t2t[i]],
                );
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows() -> Vec<AiryRow> {
        let row = |n: f64, z_im: f64| AiryRow {
            r01: [[-0.2, 0.0], [0.17, 0.01]],
            gamma: [[-0.05 * n, 0.3], [0.6, -0.2]],
            r01_gamma: [[0.01, -0.06], [0.1, -0.03]],
            t_norm: [0.8, 0.9],
            z_re: 0.04 * n,
            z_im,
        };
        let mut real = row(1.33, 0.0);
        for c in real
            .r01
            .iter_mut()
            .chain(&mut real.gamma)
            .chain(&mut real.r01_gamma)
        {
            c[1] = 0.0;
        }
        vec![
            row(1.33, 0.0),
            row(2.4, 0.0),
            row(1.5, 3e-3),
            row(2.0, 0.2),
            real,
        ]
    }

    /// The real and lossless variants of the kernel give the bits of the general formula.
    #[test]
    fn special_variants_match_the_general_formula() {
        let row = AiryRow {
            r01: [[-0.2, 0.0], [0.17, 0.0]],
            gamma: [[0.3, 0.0], [-0.6, 0.0]],
            r01_gamma: [[-0.06, 0.0], [-0.102, 0.0]],
            t_norm: [0.8, 0.9],
            z_re: 0.05,
            z_im: 0.0,
        };
        assert!(row.is_real());
        for d in [
            (0..67).map(|k| 3.0 * k as f64).collect::<Vec<_>>(),
            (0..67).map(|k| (k * k) as f64).collect(),
        ] {
            let h = uniform_step(&d);
            let mut special = vec![Power::default(); d.len()];
            airy_powers(&row, &d, h, &mut special, true);
            let mut general = vec![Power::default(); d.len()];
            PowersOp {
                row: &row,
                thickness_nm: &d,
                uniform_step_nm: h,
                out: &mut general,
            }
            .run::<pulp::Scalar, true, false>(pulp::Scalar::new());
            let bits = |p: &[Power]| -> Vec<u64> {
                p.iter()
                    .flat_map(|p| [p.R_s, p.R_p, p.T_s, p.T_p])
                    .map(f64::to_bits)
                    .collect()
            };
            assert_eq!(bits(&special), bits(&general));
        }
    }

    #[test]
    fn simd_and_scalar_paths_are_bit_identical() {
        for row in rows() {
            for n in [0, 1, 2, 3, 5, 7, 9, 31, 63, 64, 65, 127, 129, 1001] {
                let d: Vec<f64> = (0..n).map(|k| 0.37 + 13.1 * k as f64).collect();
                let h = uniform_step(&d);
                assert_eq!(h.is_some(), n >= 3);
                let mut v = vec![Power::default(); n];
                let mut s = vec![Power::default(); n];
                airy_powers(&row, &d, h, &mut v, true);
                airy_powers(&row, &d, h, &mut s, false);
                // Exact phasors at every element (a non-uniform grid) agree to rounding.
                let mut e = vec![Power::default(); n];
                airy_powers(&row, &d, None, &mut e, true);
                for (a, b) in v.iter().zip(&e) {
                    for (x, y) in [
                        (a.R_s, b.R_s),
                        (a.R_p, b.R_p),
                        (a.T_s, b.T_s),
                        (a.T_p, b.T_p),
                    ] {
                        assert!((x - y).abs() <= 1e-13, "{row:?} n = {n}: {x} vs {y}");
                    }
                }
                let bits = |p: &[Power]| -> Vec<u64> {
                    p.iter()
                        .flat_map(|p| [p.R_s, p.R_p, p.T_s, p.T_p])
                        .map(f64::to_bits)
                        .collect()
                };
                assert_eq!(bits(&v), bits(&s), "{row:?} n = {n}");
                let mut cv = ColourSums::new(n);
                let mut cs = ColourSums::new(n);
                for (i, w) in [[0.1, 0.2, 0.3], [0.7, -0.1, 0.05]].into_iter().enumerate() {
                    let dd: Vec<f64> = d.iter().map(|x| x * (1.0 + 0.1 * i as f64)).collect();
                    let h = uniform_step(&dd);
                    airy_accumulate(&row, &dd, h, w, &mut cv, true);
                    airy_accumulate(&row, &dd, h, w, &mut cs, false);
                }
                for c in 0..3 {
                    for (a, b) in [
                        (&cv.reflectance[c], &cs.reflectance[c]),
                        (&cv.transmittance[c], &cs.transmittance[c]),
                    ] {
                        let a: Vec<u64> = a.iter().map(|x| x.to_bits()).collect();
                        let b: Vec<u64> = b.iter().map(|x| x.to_bits()).collect();
                        assert_eq!(a, b, "{row:?} n = {n} channel {c}");
                    }
                }
            }
        }
    }
}
