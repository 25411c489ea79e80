//! Complex numbers as SIMD lanes, and the per-lane media and interface fractions of the
//! multilayer kernel ([`super`]).

use super::{FORWARD, LOSSLESS, SIGN};
use crate::fresnel::BRANCH_TOLERANCE;
use crate::simd::{madd, nmadd};
use pulp::Simd;

/// A complex number per lane.
#[derive(Clone, Copy)]
pub(super) struct Cx<S: Simd> {
    pub(super) re: S::f64s,
    pub(super) im: S::f64s,
}

#[inline(always)]
pub(super) fn add<S: Simd>(s: S, a: Cx<S>, b: Cx<S>) -> Cx<S> {
    Cx {
        re: s.add_f64s(a.re, b.re),
        im: s.add_f64s(a.im, b.im),
    }
}

#[inline(always)]
pub(super) fn sub<S: Simd>(s: S, a: Cx<S>, b: Cx<S>) -> Cx<S> {
    Cx {
        re: s.sub_f64s(a.re, b.re),
        im: s.sub_f64s(a.im, b.im),
    }
}

/// a b = (a.re b.re − a.im b.im, a.re b.im + a.im b.re).
#[inline(always)]
pub(super) fn mul<S: Simd>(s: S, a: Cx<S>, b: Cx<S>) -> Cx<S> {
    Cx {
        re: nmadd::<S, true>(s, a.im, b.im, s.mul_f64s(a.re, b.re)),
        im: madd::<S, true>(s, a.im, b.re, s.mul_f64s(a.re, b.im)),
    }
}

/// |a|².
#[inline(always)]
pub(super) fn norm_sqr<S: Simd>(s: S, a: Cx<S>) -> S::f64s {
    madd::<S, true>(s, a.im, a.im, s.mul_f64s(a.re, a.re))
}

/// One medium per lane: |ñ|², ñ², q = ñ cos θ on the forward branch.
#[derive(Clone, Copy)]
pub(super) struct Medium<S: Simd> {
    pub(super) n_abs2: S::f64s,
    pub(super) n2: Cx<S>,
    pub(super) q: Cx<S>,
}

/// The medium of index ñ (given as |ñ|² and ñ²) for β² = `beta2`: q = √(ñ² − β²) on the
/// forward branch (module docs).
///
/// Flags `F` (uniform over the block; the same bits as the general formula):
/// * [`LOSSLESS`] (Im ñ² = ±0 in every lane): the root takes |w| = |x| and y/2t = +0, since
///   √(x·x) = |x| exactly in binary floating point (no under- or overflow here) and
///   0/2t = +0 (t = 0 is replaced by the w = 0 case anyway);
/// * [`FORWARD`] (no Im ñ² with its sign bit set): copysign(·, y) changes nothing and
///   Im q ≥ +0, so the backward-branch correction never applies;
/// * both: t = √|x| ((|x| + |x|)/2 = |x| exactly) and q = (t, +0) or (+0, t), which is
///   also the w = 0 case (t = +0).
#[inline(always)]
pub(super) fn medium<S: Simd, const F: u8>(
    s: S,
    n_abs2: S::f64s,
    n2: Cx<S>,
    beta2: S::f64s,
) -> Medium<S> {
    let (lossless, forward) = (F & LOSSLESS != 0, F & FORWARD != 0);
    let x = s.sub_f64s(n2.re, beta2);
    let y = n2.im;
    let zero = s.splat_f64s(0.0);
    let ax = s.abs_f64s(x);
    let right = s.greater_than_or_equal_f64s(x, zero);
    if lossless && forward {
        let t = s.sqrt_f64s(ax);
        let q = Cx {
            re: s.select_f64s(right, t, zero),
            im: s.select_f64s(right, zero, t),
        };
        return Medium { n_abs2, n2, q };
    }
    let modulus = if lossless {
        ax
    } else {
        s.sqrt_f64s(madd::<S, true>(s, y, y, s.mul_f64s(x, x)))
    };
    let t = s.sqrt_f64s(s.mul_f64s(s.add_f64s(modulus, ax), s.splat_f64s(0.5)));
    let u = if lossless {
        zero
    } else if forward {
        s.div_f64s(y, s.add_f64s(t, t))
    } else {
        s.div_f64s(s.abs_f64s(y), s.add_f64s(t, t))
    };
    let re = s.select_f64s(right, t, u);
    let im_abs = s.select_f64s(right, u, t);
    let im = if forward {
        im_abs
    } else {
        // copysign(im_abs, y)
        let sign = s.and_u64s(s.transmute_u64s_f64s(y), s.splat_u64s(SIGN));
        s.transmute_f64s_u64s(s.or_u64s(s.transmute_u64s_f64s(im_abs), sign))
    };
    let origin = s.equal_f64s(t, zero);
    let re = s.select_f64s(origin, zero, re);
    let im = s.select_f64s(origin, zero, im);
    if forward {
        return Medium {
            n_abs2,
            n2,
            q: Cx { re, im },
        };
    }
    // Forward branch: re ≥ 0 here, so max(|re|, |im|) < |im| / tol reduces to |im| > tol re.
    let backward = s.and_m64s(
        s.less_than_f64s(im, zero),
        s.greater_than_f64s(
            s.abs_f64s(im),
            s.mul_f64s(s.splat_f64s(BRANCH_TOLERANCE), re),
        ),
    );
    let q = Cx {
        re: s.select_f64s(backward, s.neg_f64s(re), re),
        im: s.select_f64s(backward, s.neg_f64s(im), im),
    };
    Medium { n_abs2, n2, q }
}

/// Interface from medium `i` into medium `j` per polarisation (s, p): r = ρ/σ with
/// ρ = α − β, σ = α + β (the admittances y_s = q, y_p = q/ñ² of [`crate::fresnel`],
/// multiplied through by ñ_i² ñ_j²), and |t σ|²: α_s = q_i, β_s = q_j, |t_s σ_s|² = 4|q_i|²;
/// α_p = ñ_j² q_i, β_p = ñ_i² q_j, |t_p σ_p|² = 4|ñ_i ñ_j q_i|².
pub(super) struct Fractions<S: Simd> {
    pub(super) alpha: [Cx<S>; 2],
    pub(super) beta: [Cx<S>; 2],
    pub(super) t_sigma2: [S::f64s; 2],
}

#[inline(always)]
pub(super) fn interface<S: Simd>(s: S, i: &Medium<S>, j: &Medium<S>) -> Fractions<S> {
    let a = mul(s, j.n2, i.q);
    let b = mul(s, i.n2, j.q);
    let four_qi2 = s.mul_f64s(s.splat_f64s(4.0), norm_sqr(s, i.q));
    let ninj2 = s.mul_f64s(i.n_abs2, j.n_abs2);
    Fractions {
        alpha: [i.q, a],
        beta: [j.q, b],
        t_sigma2: [four_qi2, s.mul_f64s(four_qi2, ninj2)],
    }
}

/// |t′σ|² of the same interface crossed the other way, from medium `j` into medium `i`
/// (α and β exchanged, σ unchanged): 4|q_j|² (s), 4|ñ_i ñ_j q_j|² (p).
#[inline(always)]
pub(super) fn reverse_t_sigma2<S: Simd>(s: S, i: &Medium<S>, j: &Medium<S>) -> [S::f64s; 2] {
    let four_qj2 = s.mul_f64s(s.splat_f64s(4.0), norm_sqr(s, j.q));
    let ninj2 = s.mul_f64s(i.n_abs2, j.n_abs2);
    [four_qj2, s.mul_f64s(four_qj2, ninj2)]
}

/// Whether any lane of `v` is non-zero (NaN counts as zero).
#[inline(always)]
pub(super) fn any_nonzero<S: Simd>(s: S, v: S::f64s) -> bool {
    let mask = s.greater_than_f64s(s.abs_f64s(v), s.splat_f64s(0.0));
    s.first_true_m64s(mask) < S::F64_LANES
}
