//! Elementary functions with the same bits on every machine, for everything whose result
//! ends up in baked table bytes or in `nacre color` / `nacre spectrum` exact outputs.
//!
//! # Why
//!
//! `f64::sin`, `exp`, `ln`, `powf`, `acos`, `atan2`, `hypot`, … call the platform's C
//! library (glibc, macOS libSystem, musl, the Windows CRT), and these are not correctly
//! rounded: the same input can give results one ulp apart on two machines. Baked tables
//! promise the same bytes for the same recipe whatever the machine, so every transcendental
//! on a table path goes through this module instead (a source scan keeps it so:
//! `crates/cli/tests/deterministic_math.rs`). IEEE 754 basic operations (+, −, ×, ÷, √) are
//! correctly rounded everywhere and need no wrapper; Rust never fuses a × b + c into an FMA
//! on its own.
//!
//! # How
//!
//! The functions are those of the [`libm`] crate (the Rust project's port of musl's libm,
//! itself Sun's fdlibm): pure Rust built from IEEE basic operations and exact bit
//! manipulation, compiled into nacre, so the code and therefore the bits are the same on
//! every target (x86-64 and arm64; Linux, macOS, Windows). Its only hardware shortcuts
//! (the `arch` feature: nacre leaves it off, but num-traits turns it on in the same build)
//! are correctly rounded operations — √, fused multiply–add inside `cbrt`, rounding to an
//! integer — that give the bits of the software path. Accuracy, as measured against the
//! platform libm by the tests below over dense ranges (both sides are within about 1 ulp of
//! the true value, so the difference bounds the error to about twice that):
//!
//! | function | method (fdlibm) | max difference from glibc (test) |
//! |---|---|---|
//! | [`sin_cos`], [`sin`], [`cos`] | Payne–Hanek / Cody–Waite reduction, `__kernel_sin`/`__kernel_cos` | 1 ulp |
//! | [`exp`] | reduction by ln 2 in two parts, rational approximation | 1 ulp |
//! | [`ln`], [`log2`], [`log10`] | reduction to [√2/2, √2], series in s = f/(2+f) | 1 ulp |
//! | [`powf`] | `e_pow.c`: log₂ x in extra precision, then 2^(y log₂ x) | 1 ulp |
//! | [`acos`] | rational approximation of asin on \|x\| ≤ 1/2, half-angle beyond | 1 ulp |
//! | [`atan2`] | `s_atan.c` on the reduced ratio, quadrant fix-up | 1 ulp |
//! | [`cbrt`] | bit-level first guess, Newton steps with exact FMA residuals | 1 ulp |
//! | [`hypot`] | exact squares split in two parts (musl), then √ | 1 ulp |
//! | [`erfc`] | `s_erf.c`: rational approximations on four ranges, exp(−x²) split in two parts | (std has none: checked against tabulated values) |
//!
//! On top of them: [`from_polar`], [`norm`] and [`csqrt`] for complex numbers (num-complex's
//! `Complex::sqrt`, `norm` and `from_polar` call the platform's `atan2`, `hypot`, `sin` and
//! `cos`).

use num_complex::Complex64 as C64;

/// sin x (x in radians).
#[inline]
pub fn sin(x: f64) -> f64 {
    libm::sin(x)
}

/// cos x (x in radians).
#[inline]
pub fn cos(x: f64) -> f64 {
    libm::cos(x)
}

/// (sin x, cos x), x in radians: the same bits as ([`sin`], [`cos`]).
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    libm::sincos(x)
}

/// e^x.
#[inline]
pub fn exp(x: f64) -> f64 {
    libm::exp(x)
}

/// The natural logarithm ln x.
#[inline]
pub fn ln(x: f64) -> f64 {
    libm::log(x)
}

/// log₂ x.
#[inline]
pub fn log2(x: f64) -> f64 {
    libm::log2(x)
}

/// log₁₀ x.
#[inline]
pub fn log10(x: f64) -> f64 {
    libm::log10(x)
}

/// The real cube root ∛x.
#[inline]
pub fn cbrt(x: f64) -> f64 {
    libm::cbrt(x)
}

/// x^y (C's `pow`: every special case of IEEE 754 §9.2.1).
#[inline]
pub fn powf(x: f64, y: f64) -> f64 {
    libm::pow(x, y)
}

/// x^n for an integer n, as [`powf`] (unlike `f64::powi`, whose result the standard leaves
/// to the implementation).
#[inline]
pub fn powi(x: f64, n: i32) -> f64 {
    libm::pow(x, f64::from(n))
}

/// The complementary error function erfc x = 1 − erf x = (2/√π) ∫ₓ^∞ e^{−t²} dt, accurate in
/// the upper tail (the normal distribution's Φ(z) = ½ erfc(−z/√2)).
#[inline]
pub fn erfc(x: f64) -> f64 {
    libm::erfc(x)
}

/// arccos x in [0, π] (NaN outside [−1, 1]).
#[inline]
pub fn acos(x: f64) -> f64 {
    libm::acos(x)
}

/// The angle of (x, y) in (−π, π] (C's `atan2(y, x)`).
#[inline]
pub fn atan2(y: f64, x: f64) -> f64 {
    libm::atan2(y, x)
}

/// √(x² + y²) without undue overflow or underflow.
#[inline]
pub fn hypot(x: f64, y: f64) -> f64 {
    libm::hypot(x, y)
}

/// r e^{iθ} = (r cos θ, r sin θ).
#[inline]
pub fn from_polar(r: f64, theta: f64) -> C64 {
    let (s, c) = sin_cos(theta);
    C64::new(r * c, r * s)
}

/// |z| = [`hypot`](Re z, Im z).
#[inline]
pub fn norm(z: C64) -> f64 {
    hypot(z.re, z.im)
}

/// The principal square root of z (Re ≥ 0; on the negative real axis the sign of Im z's
/// zero picks ±i√|z|, as C's `csqrt` and num-complex), from basic operations and
/// [`hypot`] (Kahan, "Branch cuts for complex elementary functions", 1987):
///
/// ```text
/// t = √((|a| + |z|) / 2);   a ≥ 0: √z = t + i b/(2t);   a < 0: √z = |b|/(2t) + i sign(b) t
/// ```
///
/// for z = a + ib, exact in both parts to a few ulps (no cancellation: |a| + |z| adds two
/// non-negative numbers). For real z (b = ±0) it gives num-complex's bits: √a + i b for
/// a ≥ 0, and ±i√−a for a < 0.
#[inline]
pub fn csqrt(z: C64) -> C64 {
    let (a, b) = (z.re, z.im);
    if b == 0.0 {
        return if a.is_sign_positive() {
            C64::new(a.sqrt(), b)
        } else {
            C64::new(0.0, (-a).sqrt().copysign(b))
        };
    }
    if a == 0.0 {
        let x = (0.5 * b.abs()).sqrt();
        return C64::new(x, x.copysign(b));
    }
    if !(a.is_finite() && b.is_finite()) {
        // Infinities and NaN: the general formula's conventions are not needed on any
        // physical path; keep num-complex's answer shape without its libm calls.
        return C64::new(f64::NAN, f64::NAN);
    }
    // Scale by a power of 4 so that |a| + |z| neither overflows nor loses subnormal bits.
    let big = a.abs().max(b.abs());
    let (scale, unscale) = if big > 1e300 {
        (0.25, 2.0)
    } else if big < 1e-300 {
        (power_of_two(100), power_of_two(-50))
    } else {
        (1.0, 1.0)
    };
    let (a, b) = (a * scale, b * scale);
    let t = (0.5 * (a.abs() + hypot(a, b))).sqrt();
    let (re, im) = if a >= 0.0 {
        (t, b / (2.0 * t))
    } else {
        (b.abs() / (2.0 * t), t.copysign(b))
    };
    C64::new(re * unscale, im * unscale)
}

/// 2^k for |k| ≤ 1022, from its bits.
const fn power_of_two(k: i32) -> f64 {
    f64::from_bits(((1023 + k) as u64) << 52)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// erfc against values tabulated to 17 digits (Abramowitz & Stegun 7.1; mpmath), and
    /// erfc(x) + erfc(−x) = 2.
    #[test]
    fn erfc_matches_tabulated_values() {
        for (x, want) in [
            (0.0, 1.0),
            (0.5, 0.479_500_122_186_953_5),
            (1.0, 0.157_299_207_050_285_13),
            (2.0, 0.004_677_734_981_047_266),
            (5.0, 1.537_459_794_428_034_8e-12),
            (-1.0, 1.842_700_792_949_715),
        ] {
            let got = erfc(x);
            assert!(
                (got - want).abs() <= 4.0 * f64::EPSILON * want,
                "erfc({x}) = {got}, want {want}"
            );
        }
        for x in spread(-6.0, 6.0, 1000) {
            assert!(
                (erfc(x) + erfc(-x) - 2.0).abs() <= 4.0 * f64::EPSILON,
                "{x}"
            );
        }
    }

    /// Distance in units in the last place between two finite doubles of the same sign.
    fn ulps(a: f64, b: f64) -> u64 {
        if a == b {
            return 0;
        }
        assert_eq!(a.is_sign_negative(), b.is_sign_negative(), "{a} vs {b}");
        a.to_bits().abs_diff(b.to_bits())
    }

    /// `n` points spread over [lo, hi] by the golden ratio (deterministic, no clustering).
    fn spread(lo: f64, hi: f64, n: usize) -> impl Iterator<Item = f64> {
        (0..n).map(move |i| lo + (hi - lo) * (i as f64 * 0.618_033_988_749_895).fract())
    }

    /// Largest ulp difference of `ours` from `std` over `xs`, skipping results whose
    /// magnitude is below `floor` (relative ulps of values near a zero crossing are not the
    /// error measure there; the absolute error is checked instead).
    fn worst(
        xs: impl Iterator<Item = f64>,
        ours: impl Fn(f64) -> f64,
        std: impl Fn(f64) -> f64,
        floor: f64,
    ) -> u64 {
        let mut worst = 0;
        for x in xs {
            let (a, b) = (ours(x), std(x));
            if b.abs() < floor {
                assert!((a - b).abs() <= f64::EPSILON * floor, "{x}: {a} vs {b}");
                continue;
            }
            worst = worst.max(ulps(a, b));
        }
        worst
    }

    #[test]
    fn sin_cos_within_1_ulp_of_libm() {
        let xs = || spread(-1e5, 1e5, 200_000).chain(spread(-7.0, 7.0, 200_000));
        let s = worst(xs(), sin, f64::sin, 1e-3);
        let c = worst(xs(), cos, f64::cos, 1e-3);
        println!("sin: {s} ulp, cos: {c} ulp from libm");
        assert!(s <= 1 && c <= 1, "sin {s} ulp, cos {c} ulp");
        for x in spread(-1e3, 1e3, 10_000) {
            assert_eq!(sin_cos(x), (sin(x), cos(x)));
        }
    }

    #[test]
    fn exp_and_ln_within_1_ulp_of_libm() {
        let e = worst(spread(-745.0, 709.7, 400_000), exp, f64::exp, 1e-300);
        let l = worst(
            spread(1e-6, 1e6, 200_000).chain(spread(0.5, 2.0, 200_000)),
            ln,
            f64::ln,
            1e-3,
        );
        let l2 = worst(spread(1e-6, 1e6, 200_000), log2, f64::log2, 1e-3);
        let l10 = worst(spread(1e-6, 1e6, 200_000), log10, f64::log10, 1e-3);
        println!("exp: {e} ulp, ln: {l} ulp, log2: {l2} ulp, log10: {l10} ulp from libm");
        assert!(e <= 1 && l <= 1, "exp {e} ulp, ln {l} ulp");
        assert!(l2 <= 1 && l10 <= 1, "log2 {l2} ulp, log10 {l10} ulp");
        for k in -20..=20 {
            assert_eq!(log10(powi(10.0, k)), f64::from(k));
        }
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(ln(1.0), 0.0);
        assert_eq!(exp(-800.0), 0.0);
        assert_eq!(exp(710.0), f64::INFINITY);
    }

    #[test]
    fn powf_and_powi_within_1_ulp_of_libm() {
        let mut worst_ulps = 0;
        for (x, y) in spread(1e-3, 30.0, 100_000).zip(spread(-12.0, 12.0, 100_000).skip(7)) {
            worst_ulps = worst_ulps.max(ulps(powf(x, y), x.powf(y)));
        }
        for n in -8..=8 {
            for x in spread(0.01, 10.0, 2_000) {
                worst_ulps = worst_ulps.max(ulps(powi(x, n), x.powf(f64::from(n))));
            }
        }
        let c = worst(spread(-1e6, 1e6, 200_000), cbrt, f64::cbrt, 1e-3);
        assert!(c <= 1, "cbrt {c} ulp");
        println!("powf: {worst_ulps} ulp, cbrt: {c} ulp from libm");
        assert!(worst_ulps <= 1, "powf {worst_ulps} ulp");
        assert_eq!(powf(0.0, 3.0), 0.0);
        assert_eq!(powf(2.0, 0.0), 1.0);
        assert_eq!(powi(3.0, 2), 9.0);
    }

    #[test]
    fn acos_and_atan2_within_1_ulp_of_libm() {
        let a = worst(
            spread(-1.0, 1.0, 400_000).chain([-1.0, 1.0, 0.0, 0.5, -0.5, 1e-20]),
            acos,
            f64::acos,
            1e-300,
        );
        let mut t = 0;
        for (y, x) in spread(-3.0, 3.0, 200_000).zip(spread(-3.0, 3.0, 200_000).skip(11)) {
            let (ours, std) = (atan2(y, x), y.atan2(x));
            if std.abs() < 1e-3 {
                assert!((ours - std).abs() <= 1e-18, "atan2({y}, {x})");
            } else {
                t = t.max(ulps(ours, std));
            }
        }
        println!("acos: {a} ulp, atan2: {t} ulp from libm");
        assert!(a <= 1 && t <= 1, "acos {a} ulp, atan2 {t} ulp");
        assert!(acos(1.5).is_nan());
        assert_eq!(acos(1.0), 0.0);
    }

    #[test]
    fn hypot_norm_and_from_polar_match_libm() {
        let mut h = 0;
        for (x, y) in spread(-1e3, 1e3, 200_000).zip(spread(-1e-2, 1e-2, 200_000).skip(3)) {
            h = h.max(ulps(hypot(x, y), x.hypot(y)));
            assert_eq!(norm(C64::new(x, y)), hypot(x, y));
        }
        println!("hypot: {h} ulp from libm");
        assert!(h <= 1, "hypot {h} ulp");
        assert_eq!(hypot(1e300, 1e300), 1e300 * 2f64.sqrt());
        for theta in spread(-10.0, 10.0, 10_000) {
            let (ours, std) = (from_polar(2.5, theta), C64::from_polar(2.5, theta));
            assert!((ours - std).norm() <= 1e-15, "{theta}");
        }
    }

    /// csqrt squares back to z to rounding, is on the principal branch, agrees with
    /// num-complex to a few ulps, and gives num-complex's bits on the real axis.
    #[test]
    fn csqrt_is_the_principal_root() {
        let mut worst_rel: f64 = 0.0;
        for (a, b) in spread(-10.0, 10.0, 100_000).zip(spread(-10.0, 10.0, 100_000).skip(5)) {
            for z in [
                C64::new(a, b),
                C64::new(a * 1e-200, b * 1e-200),
                C64::new(a * 1e300, b * 1e300),
                C64::new(a, b * 1e-12),
            ] {
                let (ours, std) = (csqrt(z), z.sqrt());
                assert!(ours.re >= 0.0, "{z}");
                let rel = (ours - std).norm() / std.norm();
                worst_rel = worst_rel.max(rel);
                let back = ours * ours;
                assert!(
                    (back - z).norm() <= 4.0 * f64::EPSILON * z.norm(),
                    "{z}: {back}"
                );
            }
        }
        println!("csqrt: worst relative difference from num-complex {worst_rel:.2e}");
        assert!(worst_rel <= 4.0 * f64::EPSILON, "{worst_rel:e}");
        for a in [2.25, 0.0, -0.0, -4.0, 1e-300, -7.5] {
            for b in [0.0, -0.0] {
                let z = C64::new(a, b);
                let (ours, std) = (csqrt(z), z.sqrt());
                assert_eq!(
                    (ours.re.to_bits(), ours.im.to_bits()),
                    (std.re.to_bits(), std.im.to_bits()),
                    "{z}"
                );
            }
        }
        assert_eq!(csqrt(C64::new(0.0, 8.0)), C64::new(2.0, 2.0));
        assert_eq!(csqrt(C64::new(0.0, -8.0)), C64::new(2.0, -2.0));
    }
}
