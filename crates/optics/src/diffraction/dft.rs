//! Discrete Fourier transforms with the same bits on every machine, for the height-field
//! Taylor terms: X_j = Σ_k x_k e^{+2πi jk/n} (positive exponent, unnormalised).
//!
//! A general FFT library computes its twiddle factors with the platform's `cos`/`sin`, whose
//! last bits differ between C libraries; here they come from [`crate::elementary`] and every
//! other step is an IEEE basic operation in a fixed order, so the output is the same bits
//! everywhere (the guarantee of the baked tables, docs/hardening.md).
//!
//! * n a power of two: iterative radix-2 decimation in time (Cooley & Tukey 1965) after a
//!   bit-reversal permutation, twiddles w_k = e^{2πik/n} tabulated once.
//! * any other n: Bluestein's chirp z-transform (Bluestein 1970): with jk = (j² + k² −
//!   (j − k)²)/2, X_j = c_j Σ_k (x_k c_k) c̄_{j−k}, c_k = e^{iπk²/n} (k² taken mod 2n, exact
//!   in integers), a cyclic convolution of length m = the power of two ≥ 2n − 1 done with
//!   two radix-2 transforms (the kernel's transform tabulated once).
//!
//! Accuracy: against `rustfft` (test `matches_rustfft`), the largest difference is below
//! 2·10⁻¹⁵ of the largest |X_j| for every size tested up to 1000.

use crate::C64;
use crate::elementary;
use std::f64::consts::PI;

/// A radix-2 transform of a power-of-two length.
#[derive(Clone, Debug)]
struct Radix2 {
    n: usize,
    /// w_k = e^{2πik/n}, k < n/2.
    twiddles: Vec<C64>,
}

impl Radix2 {
    fn new(n: usize) -> Self {
        debug_assert!(n.is_power_of_two());
        let twiddles = (0..n / 2)
            .map(|k| elementary::from_polar(1.0, 2.0 * PI * k as f64 / n as f64))
            .collect();
        Radix2 { n, twiddles }
    }

    /// The positive-exponent transform of `a` (length n), in place.
    fn process(&self, a: &mut [C64]) {
        let n = self.n;
        if n <= 1 {
            return;
        }
        let bits = n.trailing_zeros();
        for i in 0..n {
            let j = i.reverse_bits() >> (usize::BITS - bits);
            if i < j {
                a.swap(i, j);
            }
        }
        let mut len = 2;
        while len <= n {
            let half = len / 2;
            let stride = n / len;
            for block in a.chunks_exact_mut(len) {
                let (lo, hi) = block.split_at_mut(half);
                for k in 0..half {
                    let v = hi[k] * self.twiddles[k * stride];
                    let u = lo[k];
                    lo[k] = u + v;
                    hi[k] = u - v;
                }
            }
            len *= 2;
        }
    }
}

/// Bluestein's algorithm for a length that is not a power of two.
#[derive(Clone, Debug)]
struct Bluestein {
    n: usize,
    inner: Radix2,
    /// c_k = e^{iπk²/n}, k < n.
    chirp: Vec<C64>,
    /// The radix-2 transform of the kernel b_k = c̄_{|k|} (k mod m), divided by m.
    kernel: Vec<C64>,
}

impl Bluestein {
    fn new(n: usize) -> Self {
        let m = (2 * n - 1).next_power_of_two();
        let inner = Radix2::new(m);
        let two_n = 2 * n as u128;
        let chirp: Vec<C64> = (0..n)
            .map(|k| {
                let k2 = (k as u128 * k as u128) % two_n;
                elementary::from_polar(1.0, PI * k2 as f64 / n as f64)
            })
            .collect();
        let mut kernel = vec![C64::new(0.0, 0.0); m];
        kernel[0] = chirp[0].conj();
        for k in 1..n {
            kernel[k] = chirp[k].conj();
            kernel[m - k] = chirp[k].conj();
        }
        inner.process(&mut kernel);
        let scale = 1.0 / m as f64;
        for v in &mut kernel {
            *v *= scale;
        }
        Bluestein {
            n,
            inner,
            chirp,
            kernel,
        }
    }

    /// The positive-exponent transform of `x` (length n), in place; `work` has length m.
    fn process(&self, x: &mut [C64], work: &mut [C64]) {
        let n = self.n;
        work.fill(C64::new(0.0, 0.0));
        for k in 0..n {
            work[k] = x[k] * self.chirp[k];
        }
        self.inner.process(work);
        // Convolution theorem with the positive-exponent transform F: the cyclic
        // convolution is F⁻¹(F a · F b) = conj(F(conj(F a · F b))) / m (1/m in the kernel).
        for (w, k) in work.iter_mut().zip(&self.kernel) {
            *w = (*w * k).conj();
        }
        self.inner.process(work);
        for j in 0..n {
            x[j] = work[j].conj() * self.chirp[j];
        }
    }
}

/// A positive-exponent, unnormalised DFT of one length, planned once.
#[derive(Clone, Debug)]
pub(crate) struct Dft(Plan);

#[derive(Clone, Debug)]
enum Plan {
    Radix2(Radix2),
    Bluestein(Bluestein),
}

impl Dft {
    /// Plans the transform of length `n` (≥ 1).
    pub(crate) fn new(n: usize) -> Self {
        assert!(n >= 1, "a DFT of length 0");
        Dft(if n.is_power_of_two() {
            Plan::Radix2(Radix2::new(n))
        } else {
            Plan::Bluestein(Bluestein::new(n))
        })
    }

    /// Transforms each consecutive chunk of n elements of `data` (whose length is a multiple
    /// of n) in place.
    pub(crate) fn process(&self, data: &mut [C64]) {
        match &self.0 {
            Plan::Radix2(r) => data.chunks_exact_mut(r.n).for_each(|c| r.process(c)),
            Plan::Bluestein(b) => {
                let mut work = vec![C64::new(0.0, 0.0); b.inner.n];
                data.chunks_exact_mut(b.n)
                    .for_each(|c| b.process(c, &mut work));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signal(n: usize) -> Vec<C64> {
        (0..n)
            .map(|k| {
                let u = (k as f64 * 0.618_033_988_749_895).fract();
                C64::new(u - 0.5, (3.0 * u).fract() - 0.3)
            })
            .collect()
    }

    #[test]
    fn matches_rustfft() {
        let mut planner = rustfft::FftPlanner::<f64>::new();
        for n in [
            1, 2, 3, 4, 5, 7, 8, 12, 16, 100, 128, 256, 250, 800, 1000, 1024,
        ] {
            let x = signal(3 * n);
            let mut ours = x.clone();
            Dft::new(n).process(&mut ours);
            let mut theirs = x.clone();
            planner.plan_fft_inverse(n).process(&mut theirs);
            let peak = theirs
                .iter()
                .map(|v| v.norm_sqr())
                .fold(0.0, f64::max)
                .sqrt();
            let worst = ours
                .iter()
                .zip(&theirs)
                .map(|(a, b)| (a - b).norm_sqr())
                .fold(0.0, f64::max)
                .sqrt();
            assert!(worst <= 2e-15 * peak, "n = {n}: {worst:e} of {peak:e}");
        }
    }

    /// A unit impulse at k₀ transforms to e^{2πi j k₀/n}; a constant to n δ_j.
    #[test]
    fn impulses_and_constants() {
        for n in [6, 8, 9, 64, 100] {
            let dft = Dft::new(n);
            let mut x = vec![C64::new(0.0, 0.0); n];
            x[1] = C64::new(1.0, 0.0);
            dft.process(&mut x);
            for (j, v) in x.iter().enumerate() {
                let want = C64::from_polar(1.0, 2.0 * PI * j as f64 / n as f64);
                assert!((v - want).norm() < 1e-14, "n = {n}, j = {j}: {v}");
            }
            let mut c = vec![C64::new(1.0, 0.0); n];
            dft.process(&mut c);
            assert!((c[0] - C64::new(n as f64, 0.0)).norm() < 1e-12);
            assert!(c[1..].iter().all(|v| v.norm() < 1e-12), "n = {n}");
        }
    }
}
