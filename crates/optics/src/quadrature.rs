//! Quadrature and interpolation rules shared by the bakers: Gauss–Legendre nodes and weights
//! on [0, 1] ([`gauss_legendre_01`]) and the 4-point Lagrange (cubic) stencil on a uniform
//! grid ([`cubic_stencil`]).

/// Gauss–Legendre nodes and weights on [0, 1] (Newton iteration on P_n from the
/// Chebyshev-like initial guesses cos(π(i + 3/4)/(n + 1/2)); Abramowitz & Stegun 25.4.29).
///
/// On [−1, 1] the nodes xᵢ are the roots of the Legendre polynomial P_n and the weights
/// wᵢ = 2 / ((1 − xᵢ²) P_n′(xᵢ)²); mapped to [0, 1] by t = (1 − x)/2 (so the nodes come in
/// increasing order) with weights wᵢ/2, summing to 1. The rule integrates polynomials of
/// degree up to 2n − 1 exactly. P_n and P_n′ come from the three-term recurrence
/// k P_k = (2k − 1) x P_{k−1} − (k − 1) P_{k−2} and P_n′ = n (x P_n − P_{n−1}) / (x² − 1).
pub fn gauss_legendre_01(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n {
        let mut x =
            crate::elementary::cos(std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5));
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let p = if n == 0 { 1.0 } else { p1 };
            let pm1 = if n <= 1 { 1.0 } else { p0 };
            dp = n as f64 * (x * p - pm1) / (x * x - 1.0);
            let dx = p / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        nodes[i] = 0.5 * (1.0 - x);
        weights[i] = 1.0 / ((1.0 - x * x) * dp * dp);
    }
    (nodes, weights)
}

/// 4-point Lagrange (cubic) interpolation stencil at fractional position `pos` on a grid of
/// `n` ≥ 4 uniform nodes: the first node and the weights, exact for cubics; the stencil is
/// shifted inwards at the ends. `pos` is clamped to [0, n − 1].
///
/// With x = pos − start − 1 the position relative to the stencil's second node, the weights
/// are the Lagrange basis polynomials through the nodes −1, 0, 1, 2:
/// −x(x − 1)(x − 2)/6, (x + 1)(x − 1)(x − 2)/2, −(x + 1)x(x − 2)/2, (x + 1)x(x − 1)/6
/// (the four-point Lagrange interpolation formula, Abramowitz & Stegun §25.2).
#[inline]
pub fn cubic_stencil(pos: f64, n: usize) -> (usize, [f64; 4]) {
    let pos = pos.clamp(0.0, (n - 1) as f64);
    let start = ((pos.floor() as isize) - 1).clamp(0, n as isize - 4) as usize;
    let x = pos - start as f64 - 1.0;
    (
        start,
        [
            -x * (x - 1.0) * (x - 2.0) / 6.0,
            (x + 1.0) * (x - 1.0) * (x - 2.0) / 2.0,
            -(x + 1.0) * x * (x - 2.0) / 2.0,
            (x + 1.0) * x * (x - 1.0) / 6.0,
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        let (x, w) = gauss_legendre_01(12);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        for p in 0..24 {
            let got: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(p)).sum();
            assert!((got - 1.0 / (p as f64 + 1.0)).abs() < 1e-14, "x^{p}: {got}");
        }
    }

    #[test]
    fn cubic_stencil_reproduces_cubics() {
        let f = |x: f64| 2.0 - x + 0.3 * x * x - 0.05 * x * x * x;
        for &pos in &[0.0, 0.3, 1.0, 2.5, 7.9, 9.0] {
            let (s, w) = cubic_stencil(pos, 10);
            let v: f64 = (0..4).map(|m| w[m] * f((s + m) as f64)).sum();
            assert!((v - f(pos)).abs() < 1e-12, "{pos}: {v}");
        }
    }
}
