//! A bounded Nelder–Mead simplex minimiser for a few parameters.
//!
//! The method of J. A. Nelder and R. Mead, "A simplex method for function minimization",
//! *Comput. J.* **7**, 308–313 (1965), with the standard coefficients reflection α = 1,
//! expansion γ = 2, contraction ρ = ½ and shrink σ = ½ (Lagarias et al., *SIAM J. Optim.*
//! **9**, 112–147 (1998), §2). Each step orders the n + 1 vertices by value, takes the
//! centroid x̄ of the best n and tries
//!
//! ```text
//! x_r = x̄ + α (x̄ − x_worst)           reflection
//! x_e = x̄ + γ (x_r − x̄)              expansion, if x_r beats the best
//! x_c = x̄ + ρ (x_r − x̄) or x̄ − ρ (x̄ − x_worst)   outside / inside contraction
//! x_i ← x_best + σ (x_i − x_best)     shrink, if the contraction fails
//! ```
//!
//! Bounds: the search runs in coordinates scaled to the unit box, u = (x − lo)/(hi − lo),
//! and every trial point is projected onto the box (clamped) before it is evaluated, so the
//! objective is never called outside its bounds. Deterministic: no randomness, a fixed
//! order of operations.

/// When to stop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Most objective evaluations.
    pub max_evaluations: usize,
    /// Stop when the values at the simplex's vertices differ by at most this much…
    pub f_tolerance: f64,
    /// …and its vertices lie within this distance of the best one (unit-box coordinates).
    pub x_tolerance: f64,
    /// Edge of the first simplex, unit-box coordinates.
    pub initial_step: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            max_evaluations: 2000,
            f_tolerance: 1e-9,
            x_tolerance: 1e-7,
            initial_step: 0.05,
        }
    }
}

/// The best point found.
#[derive(Clone, Debug, PartialEq)]
pub struct Minimum {
    /// The parameters (inside the bounds).
    pub x: Vec<f64>,
    /// The objective there.
    pub value: f64,
    /// Objective evaluations spent.
    pub evaluations: usize,
}

/// Minimises `f` over the box `lower ≤ x ≤ upper` from `start` (clamped into the box).
/// A bound pair with `lower == upper` holds that parameter fixed. NaN values count as +∞.
///
/// # Panics
/// If the slices differ in length (a programming error, not an input error).
pub fn minimize(
    mut f: impl FnMut(&[f64]) -> f64,
    start: &[f64],
    lower: &[f64],
    upper: &[f64],
    options: &Options,
) -> Minimum {
    let n = start.len();
    assert!(
        lower.len() == n && upper.len() == n,
        "start, lower and upper must have the same length"
    );
    let span: Vec<f64> = lower.iter().zip(upper).map(|(l, u)| u - l).collect();
    let to_x = |u: &[f64]| -> Vec<f64> {
        u.iter()
            .zip(lower)
            .zip(&span)
            .map(|((u, l), s)| l + s * u.clamp(0.0, 1.0))
            .collect()
    };
    let mut evaluations = 0;
    let mut eval = |u: &[f64], evaluations: &mut usize| -> f64 {
        *evaluations += 1;
        let v = f(&to_x(u));
        if v.is_nan() { f64::INFINITY } else { v }
    };
    let u0: Vec<f64> = start
        .iter()
        .zip(lower)
        .zip(&span)
        .map(|((x, l), s)| {
            if *s > 0.0 {
                ((x - l) / s).clamp(0.0, 1.0)
            } else {
                0.0
            }
        })
        .collect();
    // The free coordinates; a fixed one keeps its value.
    let free: Vec<usize> = (0..n).filter(|&i| span[i] > 0.0).collect();
    let mut simplex: Vec<(Vec<f64>, f64)> = Vec::with_capacity(free.len() + 1);
    let v0 = eval(&u0, &mut evaluations);
    simplex.push((u0.clone(), v0));
    for &i in &free {
        let mut u = u0.clone();
        // Step inwards when the start sits on the upper bound.
        u[i] = if u[i] + options.initial_step <= 1.0 {
            u[i] + options.initial_step
        } else {
            u[i] - options.initial_step
        };
        let v = eval(&u, &mut evaluations);
        simplex.push((u, v));
    }
    if free.is_empty() {
        return Minimum {
            x: to_x(&u0),
            value: v0,
            evaluations,
        };
    }
    let m = free.len();
    let clamp = |u: Vec<f64>| -> Vec<f64> { u.into_iter().map(|v| v.clamp(0.0, 1.0)).collect() };
    while evaluations < options.max_evaluations {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let best = simplex[0].1;
        let worst = simplex[m].1;
        let size = simplex[1..]
            .iter()
            .map(|(u, _)| {
                u.iter()
                    .zip(&simplex[0].0)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max);
        if (worst - best).abs() <= options.f_tolerance && size <= options.x_tolerance {
            break;
        }
        let mut centroid = vec![0.0; n];
        for (u, _) in &simplex[..m] {
            for (c, v) in centroid.iter_mut().zip(u) {
                *c += v / m as f64;
            }
        }
        let along = |t: f64, from: &[f64]| -> Vec<f64> {
            clamp(
                centroid
                    .iter()
                    .zip(from)
                    .map(|(c, w)| c + t * (c - w))
                    .collect(),
            )
        };
        let worst_u = simplex[m].0.clone();
        let reflected = along(1.0, &worst_u);
        let fr = eval(&reflected, &mut evaluations);
        if fr < best {
            let expanded = along(2.0, &worst_u);
            let fe = eval(&expanded, &mut evaluations);
            simplex[m] = if fe < fr {
                (expanded, fe)
            } else {
                (reflected, fr)
            };
            continue;
        }
        if fr < simplex[m - 1].1 {
            simplex[m] = (reflected, fr);
            continue;
        }
        let (contracted, fc) = if fr < worst {
            let c = along(0.5, &worst_u);
            let fc = eval(&c, &mut evaluations);
            (c, fc)
        } else {
            let c = along(-0.5, &worst_u);
            let fc = eval(&c, &mut evaluations);
            (c, fc)
        };
        if fc < worst.min(fr) {
            simplex[m] = (contracted, fc);
            continue;
        }
        // Shrink towards the best vertex.
        let best_u = simplex[0].0.clone();
        for vertex in simplex.iter_mut().skip(1) {
            let u: Vec<f64> = best_u
                .iter()
                .zip(&vertex.0)
                .map(|(b, v)| b + 0.5 * (v - b))
                .collect();
            let v = eval(&u, &mut evaluations);
            *vertex = (u, v);
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (u, value) = simplex.swap_remove(0);
    Minimum {
        x: to_x(&u),
        value,
        evaluations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_rosenbrock_minimum() {
        let rosen = |x: &[f64]| {
            let (a, b) = (x[0], x[1]);
            (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2)
        };
        let m = minimize(
            rosen,
            &[-1.2, 1.0],
            &[-2.0, -2.0],
            &[2.0, 2.0],
            &Options {
                max_evaluations: 5000,
                f_tolerance: 1e-14,
                x_tolerance: 1e-10,
                initial_step: 0.1,
            },
        );
        assert!(
            (m.x[0] - 1.0).abs() < 1e-4 && (m.x[1] - 1.0).abs() < 1e-4,
            "{m:?}"
        );
        assert!(m.evaluations <= 5000);
    }

    #[test]
    fn stays_inside_the_bounds_and_finds_a_minimum_on_one() {
        // Unconstrained minimum at (3, −1): the box's corner (2, 0) is the answer.
        let mut outside = false;
        let m = minimize(
            |x| {
                outside |= !(0.0..=2.0).contains(&x[0]) || !(0.0..=5.0).contains(&x[1]);
                (x[0] - 3.0).powi(2) + (x[1] + 1.0).powi(2)
            },
            &[1.0, 1.0],
            &[0.0, 0.0],
            &[2.0, 5.0],
            &Options::default(),
        );
        assert!(!outside);
        assert!((m.x[0] - 2.0).abs() < 1e-6 && m.x[1].abs() < 1e-6, "{m:?}");
    }

    #[test]
    fn a_fixed_parameter_keeps_its_value() {
        let m = minimize(
            |x| (x[0] - 0.3).powi(2) + (x[1] - 9.0).powi(2),
            &[0.9, 4.0],
            &[0.0, 4.0],
            &[1.0, 4.0],
            &Options::default(),
        );
        assert_eq!(m.x[1], 4.0);
        assert!((m.x[0] - 0.3).abs() < 1e-5, "{m:?}");
    }
}
