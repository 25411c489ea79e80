//! Levenberg–Marquardt for small box-bounded least squares: minimise ½ Σ r_i(x)² with
//! lo ≤ x ≤ hi.
//!
//! Each step solves the damped normal equations (Marquardt 1963, *J. SIAM* 11, 431;
//! Nocedal & Wright, *Numerical Optimization*, 2nd ed., §10.3)
//!
//! ```text
//! (JᵀJ + μ diag(JᵀJ)) δ = −Jᵀr
//! ```
//!
//! by Cholesky factorisation, projects x + δ onto the box, and accepts the step when the
//! cost falls (μ ÷ 3), else raises μ (× 4) and tries again. The Jacobian comes from the
//! problem ([`Residuals::jacobian`]); the default is central differences
//! (∂r/∂x_k ≈ (r(x + h e_k) − r(x − h e_k)) / 2h, one-sided at a bound), which a problem
//! with exact derivatives overrides.
//!
//! A small dense solver written here rather than a crate's: the problems have at most a
//! few dozen parameters, the box projection and the accept rule are a dozen lines, and the
//! crates that offer LM (`levenberg-marquardt`, `argmin`) bring `nalgebra` or a framework
//! into a crate that has neither.

use crate::error::Result;

/// A least-squares problem: residuals r(x) and, optionally, their Jacobian.
pub trait Residuals {
    /// Number of residuals.
    fn len(&self) -> usize;

    /// Whether there are no residuals.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Writes r(x) into `out` (`len()` values).
    fn residuals(&mut self, x: &[f64], out: &mut [f64]) -> Result<()>;

    /// Writes ∂r_i/∂x_k into `jac[i * x.len() + k]`; central differences by default with
    /// steps `h_k` ([`step_sizes`]), staying inside `lo`/`hi`.
    fn jacobian(&mut self, x: &[f64], lo: &[f64], hi: &[f64], jac: &mut [f64]) -> Result<()> {
        central_differences(self, x, lo, hi, jac)
    }
}

/// Finite-difference steps: 10⁻⁶ of each parameter's range (at least 10⁻⁹).
pub fn step_sizes(lo: &[f64], hi: &[f64]) -> Vec<f64> {
    lo.iter()
        .zip(hi)
        .map(|(l, h)| ((h - l) * 1e-6).max(1e-9))
        .collect()
}

/// The Jacobian of `p` at `x` by central differences (one-sided at a bound).
pub fn central_differences<P: Residuals + ?Sized>(
    p: &mut P,
    x: &[f64],
    lo: &[f64],
    hi: &[f64],
    jac: &mut [f64],
) -> Result<()> {
    let n = p.len();
    let dims = x.len();
    let h = step_sizes(lo, hi);
    let mut plus = vec![0.0; n];
    let mut minus = vec![0.0; n];
    let mut xs = x.to_vec();
    for k in 0..dims {
        let up = (x[k] + h[k]).min(hi[k].max(x[k]));
        let down = (x[k] - h[k]).max(lo[k].min(x[k]));
        xs[k] = up;
        p.residuals(&xs, &mut plus)?;
        xs[k] = down;
        p.residuals(&xs, &mut minus)?;
        xs[k] = x[k];
        let span = up - down;
        for i in 0..n {
            jac[i * dims + k] = if span > 0.0 {
                (plus[i] - minus[i]) / span
            } else {
                0.0
            };
        }
    }
    Ok(())
}

/// Limits of a run.
#[derive(Clone, Copy, Debug)]
pub struct LmOptions {
    /// Most iterations (accepted or refused steps).
    pub max_iterations: usize,
    /// Stop when a step lowers the cost by less than this fraction.
    pub relative_tolerance: f64,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            max_iterations: 100,
            relative_tolerance: 1e-10,
        }
    }
}

/// Where a run ended.
#[derive(Clone, Debug)]
pub struct LmResult {
    /// The parameters.
    pub x: Vec<f64>,
    /// Σ r_i² there.
    pub cost: f64,
    /// The residuals there.
    pub residuals: Vec<f64>,
    /// JᵀJ there (row-major, dims × dims), for the covariance.
    pub jtj: Vec<f64>,
    /// Iterations run.
    pub iterations: usize,
}

/// Minimises Σ r_i² from `x0` inside the box `lo ≤ x ≤ hi`.
pub fn minimize<P: Residuals + ?Sized>(
    p: &mut P,
    x0: &[f64],
    lo: &[f64],
    hi: &[f64],
    options: LmOptions,
) -> Result<LmResult> {
    let dims = x0.len();
    let n = p.len();
    let clamp = |x: &mut [f64]| {
        for k in 0..dims {
            x[k] = x[k].clamp(lo[k], hi[k]);
        }
    };
    let mut x = x0.to_vec();
    clamp(&mut x);
    let mut r = vec![0.0; n];
    p.residuals(&x, &mut r)?;
    let mut cost = sum_sq(&r);
    let mut jac = vec![0.0; n * dims];
    let mut jtj = vec![0.0; dims * dims];
    let mut g = vec![0.0; dims];
    let mut mu = 1e-3;
    let mut trial = vec![0.0; dims];
    let mut r_trial = vec![0.0; n];
    let mut iterations = 0;
    let mut fresh = true;
    while iterations < options.max_iterations && dims > 0 {
        if fresh {
            p.jacobian(&x, lo, hi, &mut jac)?;
            normal_equations(&jac, &r, dims, &mut jtj, &mut g);
            fresh = false;
        }
        iterations += 1;
        let mut a = jtj.clone();
        for k in 0..dims {
            a[k * dims + k] += mu * jtj[k * dims + k].max(1e-30);
        }
        let mut delta: Vec<f64> = g.iter().map(|v| -v).collect();
        if !cholesky_solve(&mut a, dims, &mut delta) {
            mu *= 4.0;
            continue;
        }
        for k in 0..dims {
            trial[k] = x[k] + delta[k];
        }
        clamp(&mut trial);
        if trial == x {
            break;
        }
        p.residuals(&trial, &mut r_trial)?;
        let c = sum_sq(&r_trial);
        if c < cost {
            let gain = (cost - c) / cost.max(f64::MIN_POSITIVE);
            x.copy_from_slice(&trial);
            std::mem::swap(&mut r, &mut r_trial);
            cost = c;
            mu = (mu / 3.0).max(1e-12);
            fresh = true;
            if gain < options.relative_tolerance {
                break;
            }
        } else {
            mu *= 4.0;
            if mu > 1e12 {
                break;
            }
        }
    }
    if fresh && dims > 0 {
        p.jacobian(&x, lo, hi, &mut jac)?;
        normal_equations(&jac, &r, dims, &mut jtj, &mut g);
    }
    Ok(LmResult {
        x,
        cost,
        residuals: r,
        jtj,
        iterations,
    })
}

/// Σ v².
pub fn sum_sq(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum()
}

/// JᵀJ and Jᵀr.
fn normal_equations(jac: &[f64], r: &[f64], dims: usize, jtj: &mut [f64], g: &mut [f64]) {
    jtj.fill(0.0);
    g.fill(0.0);
    for (row, ri) in jac.chunks_exact(dims).zip(r) {
        for a in 0..dims {
            g[a] += row[a] * ri;
            for b in 0..=a {
                jtj[a * dims + b] += row[a] * row[b];
            }
        }
    }
    for a in 0..dims {
        for b in 0..a {
            jtj[b * dims + a] = jtj[a * dims + b];
        }
    }
}

/// Solves A x = b in place (A symmetric positive definite, row-major n × n, overwritten by
/// its Cholesky factor; b becomes x). False when A is not positive definite.
pub fn cholesky_solve(a: &mut [f64], n: usize, b: &mut [f64]) -> bool {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        if !(d > 0.0) || !d.is_finite() {
            return false;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= a[i * n + k] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= a[k * n + i] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
    true
}

/// The diagonal of A⁻¹ (A symmetric positive definite, n × n); None when A is singular.
pub fn inverse_diagonal(a: &[f64], n: usize) -> Option<Vec<f64>> {
    (0..n)
        .map(|k| {
            let mut m = a.to_vec();
            let mut e = vec![0.0; n];
            e[k] = 1.0;
            cholesky_solve(&mut m, n, &mut e).then(|| e[k])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rosenbrock as least squares: r = (10 (y − x²), 1 − x).
    struct Rosenbrock;

    impl Residuals for Rosenbrock {
        fn len(&self) -> usize {
            2
        }
        fn residuals(&mut self, x: &[f64], out: &mut [f64]) -> Result<()> {
            out[0] = 10.0 * (x[1] - x[0] * x[0]);
            out[1] = 1.0 - x[0];
            Ok(())
        }
    }

    #[test]
    fn finds_the_rosenbrock_minimum() {
        let r = minimize(
            &mut Rosenbrock,
            &[-1.2, 1.0],
            &[-5.0, -5.0],
            &[5.0, 5.0],
            LmOptions::default(),
        )
        .unwrap();
        assert!(
            (r.x[0] - 1.0).abs() < 1e-6 && (r.x[1] - 1.0).abs() < 1e-6,
            "{:?}",
            r.x
        );
        // A box that excludes the minimum: the solution sits on the bound.
        let r = minimize(
            &mut Rosenbrock,
            &[-1.2, 0.5],
            &[-5.0, -5.0],
            &[0.5, 5.0],
            LmOptions::default(),
        )
        .unwrap();
        assert!((r.x[0] - 0.5).abs() < 1e-9, "{:?}", r.x);
    }

    #[test]
    fn cholesky_and_inverse() {
        let a = [4.0, 2.0, 2.0, 3.0];
        let mut m = a;
        let mut b = [2.0, 1.0];
        assert!(cholesky_solve(&mut m, 2, &mut b));
        assert!((4.0 * b[0] + 2.0 * b[1] - 2.0).abs() < 1e-12);
        assert!((2.0 * b[0] + 3.0 * b[1] - 1.0).abs() < 1e-12);
        let d = inverse_diagonal(&a, 2).unwrap();
        assert!((d[0] - 3.0 / 8.0).abs() < 1e-12 && (d[1] - 0.5).abs() < 1e-12);
        assert!(inverse_diagonal(&[1.0, 1.0, 1.0, 1.0], 2).is_none());
    }
}
