//! Vectorised, deterministic kernels for the single-film (Airy) thickness sweep.
//!
//! # Determinism
//!
//! Every kernel is written once, generic over [`pulp::Simd`], and run either on the widest
//! vectors the CPU offers (AVX2 on x86-64, NEON on arm64: [`pulp::Arch::dispatch`]) or on
//! [`pulp::Scalar`] (one lane) for the remainder of a slice and on any other CPU. Each
//! element is a pure function of its own inputs computed with IEEE 754 basic operations
//! only (+, −, ×, ÷, √, comparisons and exact bit manipulation) in a fixed order — no fused
//! multiply–add, no platform `libm` — so the result has the same bits whatever the vector
//! width, the CPU or the operating system (tested: `simd_and_scalar_paths_are_bit_identical`).
//!
//! The multilayer kernel ([`crate::multilayer`]) takes sin/cos and e^{−a} in a fused form
//! ([`sin_cos_bounded_with`] and [`exp_neg_with`] with `FUSED`): the same methods with each
//! a·b + c a fused multiply–add ([`madd`]), one correctly rounded operation on every target,
//! so the bits are again the same everywhere; fewer operations, and no larger error (tests
//! `sin_cos_matches_libm`, `exp_neg_matches_libm`).
//!
//! # Elementary functions
//!
//! * [`sin_cos`]: argument reduction x = m π/2 + y, |y| ≤ π/4, with π/2 split in three parts
//!   (Cody & Waite, *Software Manual for the Elementary Functions*, 1980, ch. 8; the 33-bit
//!   split of fdlibm's `__ieee754_rem_pio2`, so m·P₁ and m·P₂ are exact for |m| < 2²⁰,
//!   |x| < 1.6×10⁶ rad), then fdlibm's minimax polynomials `__kernel_sin` /
//!   `__kernel_cos` on |y| ≤ π/4 (Sun Microsystems 1993, as in musl `__sin.c`/`__cos.c`;
//!   polynomial error < 2⁻⁵⁸). Measured against the platform `sin_cos` over |x| ≤ 10⁵:
//!   absolute difference ≤ 2.3×10⁻¹⁶ (test `sin_cos_matches_libm`). Beyond 1.6×10⁶ rad the
//!   reduction is no longer exact and the absolute error grows as |x|·2⁻⁵³, the same order as
//!   the rounding of the phase x itself.
//! * [`exp_neg`]: e^{−a} = 2^{−k} e^{−r}, k = round(a/ln 2), r by a two-part ln 2 (Cody &
//!   Waite), then fdlibm's `__ieee754_exp` rational approximation on |r| ≤ ln 2/2 (error
//!   < 1 ulp). Decays beyond a = 708 (e^{−a} < 3.3×10⁻³⁰⁸) return 0.

// The coefficients below keep fdlibm's published decimal digits, so that they can be checked
// against the source; each rounds to the double fdlibm uses.
#![allow(clippy::excessive_precision)]

use crate::stack::Power;
use pulp::{Simd, WithSimd};
use std::sync::LazyLock;

/// The CPU's SIMD capabilities, detected once.
pub(crate) static ARCH: LazyLock<pulp::Arch> = LazyLock::new(pulp::Arch::new);

/// 1.5 × 2⁵²: adding and subtracting it rounds |v| < 2⁵¹ to the nearest integer.
const SHIFTER: f64 = 6_755_399_441_055_744.0;
/// 2/π.
const FRAC_2_PI: f64 = std::f64::consts::FRAC_2_PI;
/// π/2 = P₁ + P₂ + P₃ (fdlibm `pio2_1`, `pio2_2`, `pio2_2t`): P₁, P₂ have 33 significant bits.
const PIO2_1: f64 = 1.570_796_326_734_125_614_17e+00;
const PIO2_2: f64 = 6.077_100_506_303_965_976_60e-11;
const PIO2_2T: f64 = 2.022_266_248_795_950_631_54e-21;
/// fdlibm `__kernel_sin` coefficients.
const S1: f64 = -1.666_666_666_666_663_243_48e-01;
const S2: f64 = 8.333_333_333_322_489_461_24e-03;
const S3: f64 = -1.984_126_982_985_794_931_34e-04;
const S4: f64 = 2.755_731_370_707_006_767_89e-06;
const S5: f64 = -2.505_076_025_340_686_341_95e-08;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;
/// fdlibm `__kernel_cos` coefficients.
const C1: f64 = 4.166_666_666_666_660_190_37e-02;
const C2: f64 = -1.388_888_888_887_410_957_49e-03;
const C3: f64 = 2.480_158_728_947_672_941_78e-05;
const C4: f64 = -2.755_731_435_139_066_330_35e-07;
const C5: f64 = 2.087_572_321_298_174_827_90e-09;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;
/// fdlibm `__ieee754_exp`: ln 2 = LN2_HI + LN2_LO, 1/ln 2, and the rational coefficients.
const LN2_HI: f64 = 6.931_471_803_691_238_164_90e-01;
const LN2_LO: f64 = 1.908_214_929_270_587_700_02e-10;
const INV_LN2: f64 = std::f64::consts::LOG2_E;
const P1: f64 = 1.666_666_666_666_660_190_37e-01;
const P2: f64 = -2.777_777_777_701_559_338_42e-03;
const P3: f64 = 6.613_756_321_437_934_361_17e-05;
const P4: f64 = -1.653_390_220_546_525_153_90e-06;
const P5: f64 = 4.138_136_797_057_238_460_39e-08;
/// Largest decay exponent evaluated; beyond it e^{−a} is flushed to 0.
const MAX_DECAY: f64 = 708.0;

/// Largest |x| that [`sin_cos`] reduces (2⁴⁰ rad); larger arguments count as 0.
const HUGE_PHASE: f64 = 1_099_511_627_776.0;

/// (sin x, cos x) lane by lane; see the module docs for the method and its error.
#[inline(always)]
pub(crate) fn sin_cos<S: Simd>(s: S, x: S::f64s) -> (S::f64s, S::f64s) {
    // Phases beyond HUGE_PHASE rad (fringes no spectrum resolves; past 2⁵² π/2 the reduction
    // below would overflow) are taken as 0, so that the result stays finite; NaN stays NaN.
    let big = s.greater_than_f64s(s.abs_f64s(x), s.splat_f64s(HUGE_PHASE));
    sin_cos_bounded(s, s.select_f64s(big, s.splat_f64s(0.0), x))
}

/// [`sin_cos`] for |x| ≤ 2⁴⁰ rad (or NaN), where it gives the same bits without its range
/// check.
#[inline(always)]
pub(crate) fn sin_cos_bounded<S: Simd>(s: S, x: S::f64s) -> (S::f64s, S::f64s) {
    sin_cos_bounded_with::<S, false>(s, x)
}

/// [`sin_cos_bounded`], its products and sums fused where `FUSED` ([`madd`]).
#[inline(always)]
pub(crate) fn sin_cos_bounded_with<S: Simd, const FUSED: bool>(
    s: S,
    x: S::f64s,
) -> (S::f64s, S::f64s) {
    let shifter = s.splat_f64s(SHIFTER);
    // m = round(x · 2/π); y = x − m π/2 in three parts. x · 2/π + 1.5 × 2⁵² has unit last
    // place, so its low mantissa bits hold m's (two's complement, |m| < 2⁵¹): quadrant
    // m mod 4 is its bits 0–1.
    let m_shifted = madd::<S, FUSED>(s, x, s.splat_f64s(FRAC_2_PI), shifter);
    let m = s.sub_f64s(m_shifted, shifter);
    let y = nmadd::<S, FUSED>(s, m, s.splat_f64s(PIO2_1), x);
    let y = nmadd::<S, FUSED>(s, m, s.splat_f64s(PIO2_2), y);
    let y = nmadd::<S, FUSED>(s, m, s.splat_f64s(PIO2_2T), y);
    let quadrant = s.transmute_u64s_f64s(m_shifted);
    // __kernel_sin(y, 0, 0) and __kernel_cos(y, 0).
    let z = s.mul_f64s(y, y);
    let w = s.mul_f64s(z, z);
    let r = madd::<S, FUSED>(
        s,
        s.mul_f64s(z, w),
        madd::<S, FUSED>(s, z, s.splat_f64s(S6), s.splat_f64s(S5)),
        madd::<S, FUSED>(
            s,
            z,
            madd::<S, FUSED>(s, z, s.splat_f64s(S4), s.splat_f64s(S3)),
            s.splat_f64s(S2),
        ),
    );
    let v = s.mul_f64s(z, y);
    let sin_y = madd::<S, FUSED>(s, v, madd::<S, FUSED>(s, z, r, s.splat_f64s(S1)), y);
    let rc = madd::<S, FUSED>(
        s,
        s.mul_f64s(w, w),
        madd::<S, FUSED>(
            s,
            z,
            madd::<S, FUSED>(s, z, s.splat_f64s(C6), s.splat_f64s(C5)),
            s.splat_f64s(C4),
        ),
        s.mul_f64s(
            z,
            madd::<S, FUSED>(
                s,
                z,
                madd::<S, FUSED>(s, z, s.splat_f64s(C3), s.splat_f64s(C2)),
                s.splat_f64s(C1),
            ),
        ),
    );
    let one = s.splat_f64s(1.0);
    let hz = s.mul_f64s(s.splat_f64s(0.5), z);
    let wc = s.sub_f64s(one, hz);
    let cos_y = s.add_f64s(
        wc,
        madd::<S, FUSED>(s, z, rc, s.sub_f64s(s.sub_f64s(one, wc), hz)),
    );
    // Quadrant q = 0: (s, c); 1: (c, −s); 2: (−s, −c); 3: (−c, s): the pair swapped where
    // bit 0 of q is set, sin negated where bit 1 of q is, cos where bit 1 of q + 1 is.
    let (one, two) = (s.splat_u64s(1), s.splat_u64s(2));
    let swap = s.equal_u64s(s.and_u64s(quadrant, one), one);
    let neg_sin = s.equal_u64s(s.and_u64s(quadrant, two), two);
    let neg_cos = s.equal_u64s(s.and_u64s(s.add_u64s(quadrant, one), two), two);
    let sin_x = s.select_f64s(swap, cos_y, sin_y);
    let cos_x = s.select_f64s(swap, sin_y, cos_y);
    (
        s.select_f64s(neg_sin, s.neg_f64s(sin_x), sin_x),
        s.select_f64s(neg_cos, s.neg_f64s(cos_x), cos_x),
    )
}

/// e^{−a} lane by lane for a ≤ 708 (a < −708 is clamped there); 0 beyond; see the module docs.
#[inline(always)]
pub(crate) fn exp_neg<S: Simd>(s: S, a: S::f64s) -> S::f64s {
    exp_neg_with::<S, false>(s, a)
}

/// [`exp_neg`], its products and sums fused where `FUSED` ([`madd`]).
#[inline(always)]
pub(crate) fn exp_neg_with<S: Simd, const FUSED: bool>(s: S, a: S::f64s) -> S::f64s {
    let limit = s.splat_f64s(MAX_DECAY);
    let neg_limit = s.splat_f64s(-MAX_DECAY);
    let beyond = s.greater_than_f64s(a, limit);
    let a = s.select_f64s(beyond, limit, a);
    let a = s.select_f64s(s.less_than_f64s(a, neg_limit), neg_limit, a);
    let x = s.neg_f64s(a);
    let shifter = s.splat_f64s(SHIFTER);
    // k = round(x / ln 2), |k| ≤ 1022.
    let k = s.sub_f64s(
        madd::<S, FUSED>(s, x, s.splat_f64s(INV_LN2), shifter),
        shifter,
    );
    let hi = nmadd::<S, FUSED>(s, k, s.splat_f64s(LN2_HI), x);
    let lo = s.mul_f64s(k, s.splat_f64s(LN2_LO));
    let r = s.sub_f64s(hi, lo);
    let y = exp_fdlibm::<S, FUSED>(s, r, hi, lo);
    // 2^k from its bits: (k + 1023) · 2⁵², k + 1023 read off (k + 1023 + 2⁵²)'s mantissa.
    let two52 = s.splat_f64s(4_503_599_627_370_496.0);
    let biased = s.transmute_u64s_f64s(s.add_f64s(k, s.add_f64s(s.splat_f64s(1023.0), two52)));
    let biased = s.sub_u64s(biased, s.transmute_u64s_f64s(two52));
    let scale = s.transmute_f64s_u64s(s.mul_u64s(biased, s.splat_u64s(1u64 << 52)));
    s.select_f64s(beyond, s.splat_f64s(0.0), s.mul_f64s(y, scale))
}

/// e^r for r = hi − lo, |r| ≤ ln 2/2: fdlibm's `__ieee754_exp` rational form (module docs).
#[inline(always)]
fn exp_fdlibm<S: Simd, const FUSED: bool>(s: S, r: S::f64s, hi: S::f64s, lo: S::f64s) -> S::f64s {
    let t = s.mul_f64s(r, r);
    let poly = madd::<S, FUSED>(
        s,
        t,
        madd::<S, FUSED>(
            s,
            t,
            madd::<S, FUSED>(
                s,
                t,
                madd::<S, FUSED>(s, t, s.splat_f64s(P5), s.splat_f64s(P4)),
                s.splat_f64s(P3),
            ),
            s.splat_f64s(P2),
        ),
        s.splat_f64s(P1),
    );
    let c = nmadd::<S, FUSED>(s, t, poly, r);
    let one = s.splat_f64s(1.0);
    // y = 1 − ((lo − r c / (2 − c)) − hi) = e^r.
    s.sub_f64s(
        one,
        s.sub_f64s(
            s.sub_f64s(
                lo,
                s.div_f64s(s.mul_f64s(r, c), s.sub_f64s(s.splat_f64s(2.0), c)),
            ),
            hi,
        ),
    )
}

/// a·b + c lane by lane: fused where `FUSED` (IEEE 754 fusedMultiplyAdd, one rounding:
/// `vfmadd` on x86-64 v3/v4, `fmla` on NEON, `f64::mul_add` on one lane — the same bits on
/// every target), else the product rounded, then the sum.
#[inline(always)]
pub(crate) fn madd<S: Simd, const FUSED: bool>(
    s: S,
    a: S::f64s,
    b: S::f64s,
    c: S::f64s,
) -> S::f64s {
    if FUSED {
        s.mul_add_f64s(a, b, c)
    } else {
        s.add_f64s(s.mul_f64s(a, b), c)
    }
}

/// c − a·b lane by lane, fused where `FUSED` ([`madd`]).
#[inline(always)]
pub(crate) fn nmadd<S: Simd, const FUSED: bool>(
    s: S,
    a: S::f64s,
    b: S::f64s,
    c: S::f64s,
) -> S::f64s {
    if FUSED {
        s.mul_add_f64s(s.neg_f64s(a), b, c)
    } else {
        s.sub_f64s(c, s.mul_f64s(a, b))
    }
}

/// `sin[k]`, `cos[k]` = sin, cos of `x[k]` ([`sin_cos`]) on the CPU's widest vectors, the
/// remainder one lane at a time (the same bits).
pub(crate) fn sin_cos_slice(x: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    struct Op<'a>(&'a [f64], &'a mut [f64], &'a mut [f64]);
    impl WithSimd for Op<'_> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: Simd>(self, s: S) {
            let (xv, xt) = S::as_simd_f64s(self.0);
            let (sv, st) = S::as_mut_simd_f64s(self.1);
            let (cv, ct) = S::as_mut_simd_f64s(self.2);
            for (i, &x) in xv.iter().enumerate() {
                (sv[i], cv[i]) = sin_cos(s, x);
            }
            let scalar = pulp::Scalar::new();
            for (i, &x) in xt.iter().enumerate() {
                (st[i], ct[i]) = sin_cos(scalar, x);
            }
        }
    }
    ARCH.dispatch(Op(x, sin, cos))
}

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

/// The vector of `v` starting at element `start`.
#[inline(always)]
pub(crate) fn lane<S: Simd>(v: &[f64], start: usize) -> S::f64s {
    S::as_simd_f64s(&v[start..start + S::F64_LANES]).0[0]
}

/// The vector of `v` starting at element `start`.
#[inline(always)]
pub(crate) fn lane_mut<S: Simd>(v: &mut [f64], start: usize) -> &mut S::f64s {
    &mut S::as_mut_simd_f64s(&mut v[start..start + S::F64_LANES]).0[0]
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

    /// Runs `f` on the dispatched vectors and on one lane, over `x`.
    fn both(x: &[f64], f: impl Fn(&[f64], &mut [f64], bool)) -> (Vec<f64>, Vec<f64>) {
        let mut v = vec![0.0; x.len()];
        let mut s = vec![0.0; x.len()];
        f(x, &mut v, true);
        f(x, &mut s, false);
        (v, s)
    }

    struct Map<'a, F> {
        x: &'a [f64],
        out: &'a mut [f64],
        f: F,
    }

    trait LaneFn {
        fn apply<S: Simd>(&self, s: S, x: S::f64s) -> S::f64s;
    }

    impl<F: LaneFn> WithSimd for Map<'_, F> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: Simd>(self, s: S) {
            let (xv, xt) = S::as_simd_f64s(self.x);
            let (ov, ot) = S::as_mut_simd_f64s(self.out);
            for (o, &x) in ov.iter_mut().zip(xv) {
                *o = self.f.apply(s, x);
            }
            for (o, &x) in ot.iter_mut().zip(xt) {
                *o = self.f.apply(pulp::Scalar::new(), x);
            }
        }
    }

    fn map<F: LaneFn>(f: F, x: &[f64], out: &mut [f64], vector: bool) {
        let op = Map { x, out, f };
        if vector {
            ARCH.dispatch(op)
        } else {
            op.with_simd(pulp::Scalar::new())
        }
    }

    /// sin, cos and e^{−a}: `sin_cos` and `exp_neg`, or their fused variants.
    fn sin_cos_of<S: Simd, const FUSED: bool>(s: S, x: S::f64s) -> (S::f64s, S::f64s) {
        if FUSED {
            sin_cos_bounded_with::<S, true>(s, x)
        } else {
            sin_cos(s, x)
        }
    }
    struct Sin<const FUSED: bool>;
    impl<const FUSED: bool> LaneFn for Sin<FUSED> {
        fn apply<S: Simd>(&self, s: S, x: S::f64s) -> S::f64s {
            sin_cos_of::<S, FUSED>(s, x).0
        }
    }
    struct Cos<const FUSED: bool>;
    impl<const FUSED: bool> LaneFn for Cos<FUSED> {
        fn apply<S: Simd>(&self, s: S, x: S::f64s) -> S::f64s {
            sin_cos_of::<S, FUSED>(s, x).1
        }
    }
    struct ExpNeg<const FUSED: bool>;
    impl<const FUSED: bool> LaneFn for ExpNeg<FUSED> {
        fn apply<S: Simd>(&self, s: S, x: S::f64s) -> S::f64s {
            exp_neg_with::<S, FUSED>(s, x)
        }
    }

    /// A deterministic spread of points: dense near 0, multiples of π/2 and their
    /// neighbours, and large phases.
    fn phases() -> Vec<f64> {
        let mut x: Vec<f64> = (0..20_011)
            .map(|i| {
                let u = (i as f64 * 0.618_033_988_749_895).fract();
                (u - 0.5) * 2e5 * u.powi(3)
            })
            .collect();
        for k in -2000..2000 {
            let c = k as f64 * std::f64::consts::FRAC_PI_2;
            x.extend([c, c.next_up(), c.next_down(), c + 1e-9, c - 3e-12]);
        }
        x
    }

    /// Vector and scalar paths give the same bits, within 2.3×10⁻¹⁶ of libm (fused or not).
    #[test]
    fn sin_cos_matches_libm() {
        let x = phases();
        let ((sv, ss), (cv, cs)) = (
            both(&x, |x, o, v| map(Sin::<false>, x, o, v)),
            both(&x, |x, o, v| map(Cos::<false>, x, o, v)),
        );
        let ((fsv, fss), (fcv, fcs)) = (
            both(&x, |x, o, v| map(Sin::<true>, x, o, v)),
            both(&x, |x, o, v| map(Cos::<true>, x, o, v)),
        );
        let (mut worst, mut worst_fused): (f64, f64) = (0.0, 0.0);
        for (k, &xi) in x.iter().enumerate() {
            assert_eq!(sv[k].to_bits(), ss[k].to_bits(), "sin({xi})");
            assert_eq!(cv[k].to_bits(), cs[k].to_bits(), "cos({xi})");
            assert_eq!(fsv[k].to_bits(), fss[k].to_bits(), "fused sin({xi})");
            assert_eq!(fcv[k].to_bits(), fcs[k].to_bits(), "fused cos({xi})");
            let (s, c) = xi.sin_cos();
            worst = worst.max((sv[k] - s).abs()).max((cv[k] - c).abs());
            worst_fused = worst_fused.max((fsv[k] - s).abs()).max((fcv[k] - c).abs());
        }
        println!(
            "sin_cos: worst absolute difference from libm {worst:.3e}, fused {worst_fused:.3e}"
        );
        assert!(worst <= 2.3e-16, "{worst:e}");
        assert!(worst_fused <= 2.3e-16, "{worst_fused:e}");
    }

    #[test]
    fn exp_neg_matches_libm() {
        let mut a: Vec<f64> = (0..30_001).map(|i| i as f64 * 0.0236).collect();
        a.extend([
            0.0, 1e-300, 1e-12, 707.9, 708.0, 708.5, 800.0, 1e300, -0.5, -1e-17,
        ]);
        for fused in [false, true] {
            let (v, s) = if fused {
                both(&a, |x, o, v| map(ExpNeg::<true>, x, o, v))
            } else {
                both(&a, |x, o, v| map(ExpNeg::<false>, x, o, v))
            };
            let mut worst: f64 = 0.0;
            for (k, &ai) in a.iter().enumerate() {
                assert_eq!(v[k].to_bits(), s[k].to_bits(), "exp(-{ai}), fused {fused}");
                let want = if ai > MAX_DECAY { 0.0 } else { (-ai).exp() };
                if want == 0.0 {
                    assert_eq!(v[k], 0.0, "exp(-{ai})");
                } else {
                    worst = worst.max(((v[k] - want) / want).abs());
                }
            }
            println!("exp_neg (fused {fused}): worst relative difference from libm {worst:.3e}");
            assert!(worst <= 2.5e-16, "{worst:e}");
        }
    }

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
