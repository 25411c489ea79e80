//! One real quantity (n or κ) of a material as a function of wavelength: a constant, a
//! linearly interpolated table, or a refractiveindex.info dispersion formula (the formulas'
//! table is in the parent module's documentation).

use crate::elementary::powf;

/// One real quantity (n or κ) as a function of vacuum wavelength.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Dispersion {
    /// Independent of wavelength.
    Constant(f64),
    /// Samples at strictly increasing wavelengths (nm), linearly interpolated; outside
    /// them 0 when `zero_outside` (κ beyond its own table), else never asked for (n: the
    /// material's range is the table's).
    Tabulated {
        wavelength_nm: Vec<f64>,
        value: Vec<f64>,
        zero_outside: bool,
    },
    /// A refractiveindex.info dispersion formula evaluated with λ in µm; gives n.
    Formula { kind: u8, coefficients: Vec<f64> },
}

impl Dispersion {
    pub(super) fn eval(&self, wavelength_nm: f64) -> f64 {
        self.eval_from(wavelength_nm, &mut Cursor::default())
    }

    /// [`Dispersion::eval`] (the same bits), a tabulated value found from `cursor` (the
    /// segment of the previous wavelength asked for) when the wavelengths ascend, so that a
    /// sweep walks the table once instead of searching it per wavelength.
    pub(super) fn eval_from(&self, wavelength_nm: f64, cursor: &mut Cursor) -> f64 {
        match self {
            Dispersion::Constant(v) => *v,
            Dispersion::Tabulated {
                wavelength_nm: w,
                value,
                zero_outside,
            } => {
                if *zero_outside && !(wavelength_nm >= w[0] && wavelength_nm <= w[w.len() - 1]) {
                    0.0
                } else {
                    cursor.interpolate(w, value, wavelength_nm)
                }
            }
            Dispersion::Formula { kind, coefficients } => {
                eval_formula(*kind, coefficients, wavelength_nm * 1e-3)
            }
        }
    }
}

/// Where the previous interpolation in a table was: the first sample strictly greater than
/// the previous wavelength `at` (+∞ before any, so that the first is searched for).
#[derive(Clone, Copy, Debug)]
pub(super) struct Cursor {
    first_above: usize,
    at: f64,
}

impl Default for Cursor {
    fn default() -> Self {
        Cursor {
            first_above: 0,
            at: f64::INFINITY,
        }
    }
}

impl Cursor {
    /// Linear interpolation in `x` (strictly increasing, `x[0] <= at <= x[last]`).
    fn interpolate(&mut self, x: &[f64], y: &[f64], at: f64) -> f64 {
        if x.len() == 1 {
            return y[0];
        }
        // First sample strictly greater than `at`: a few steps on from the previous one while
        // the wavelengths ascend, else searched for (the same index either way).
        let mut first_above = 0;
        if at >= self.at {
            first_above = self.first_above;
            for _ in 0..4 {
                if first_above < x.len() && x[first_above] <= at {
                    first_above += 1;
                }
            }
        }
        if first_above < x.len() && x[first_above] <= at {
            first_above += x[first_above..].partition_point(|&v| v <= at);
        }
        *self = Cursor { first_above, at };
        // Clamped so that [i-1, i] is a segment.
        let i = first_above.clamp(1, x.len() - 1);
        let (x0, x1, y0, y1) = (x[i - 1], x[i], y[i - 1], y[i]);
        let t = (at - x0) / (x1 - x0);
        y0 + t * (y1 - y0)
    }
}

/// Evaluates refractiveindex.info formula `kind` at `lambda_um`; returns n (NaN when the
/// formula yields n² < 0 there).
fn eval_formula(kind: u8, c: &[f64], lambda_um: f64) -> f64 {
    let l = lambda_um;
    let l2 = l * l;
    let coef = |i: usize| c.get(i).copied().unwrap_or(0.0);
    // Pairs (C_i, C_{i+1}) for i = start, start+2, … (0-based indices).
    let pairs = |start: usize| {
        (start..c.len())
            .step_by(2)
            .map(move |i| (coef(i), coef(i + 1)))
    };
    match kind {
        1 => (1.0 + coef(0) + pairs(1).map(|(a, b)| a * l2 / (l2 - b * b)).sum::<f64>()).sqrt(),
        2 => (1.0 + coef(0) + pairs(1).map(|(a, b)| a * l2 / (l2 - b)).sum::<f64>()).sqrt(),
        3 => (coef(0) + pairs(1).map(|(a, b)| a * powf(l, b)).sum::<f64>()).sqrt(),
        4 => {
            let mut n2 = coef(0)
                + coef(1) * powf(l, coef(2)) / (l2 - powf(coef(3), coef(4)))
                + coef(5) * powf(l, coef(6)) / (l2 - powf(coef(7), coef(8)));
            n2 += pairs(9).map(|(a, b)| a * powf(l, b)).sum::<f64>();
            n2.sqrt()
        }
        5 => coef(0) + pairs(1).map(|(a, b)| a * powf(l, b)).sum::<f64>(),
        6 => 1.0 + coef(0) + pairs(1).map(|(a, b)| a / (b - 1.0 / l2)).sum::<f64>(),
        7 => {
            let u = 1.0 / (l2 - 0.028);
            coef(0)
                + coef(1) * u
                + coef(2) * u * u
                + coef(3) * l2
                + coef(4) * l2 * l2
                + coef(5) * l2 * l2 * l2
        }
        8 => {
            let a = coef(0) + coef(1) * l2 / (l2 - coef(2)) + coef(3) * l2;
            // (n² − 1)/(n² + 2) = a  ⇒  n² = (1 + 2a)/(1 − a)
            ((1.0 + 2.0 * a) / (1.0 - a)).sqrt()
        }
        9 => {
            let d = l - coef(4);
            (coef(0) + coef(1) / (l2 - coef(2)) + coef(3) * d / (d * d + coef(5))).sqrt()
        }
        _ => f64::NAN,
    }
}
