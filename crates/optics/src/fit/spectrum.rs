//! Fitting a template's free parameters to a measured reflectance or transmittance
//! spectrum, globally over the bounds.
//!
//! # Model
//!
//! For points i (incidence angle θ_i, vacuum wavelength λ_i, measured value y_i, standard
//! deviation σ_i, 1 when unknown) the model is `y_i ≈ a(ν_i) M_i(x) + b(ν_i)`, M the
//! stack's unpolarised R or T at the free parameters x, a and b the scale and offset:
//! fixed numbers, or polynomials of degree N in the normalised wavenumber
//! u = 2 (ν − ν_min)/(ν_max − ν_min) − 1, ν = 1/λ. The polynomial coefficients enter
//! linearly and are solved exactly for every x (variable projection: Golub & Pereyra 1973,
//! *SIAM J. Numer. Anal.* 10, 413), so the search runs over x alone. The residuals are
//! r_i = w_i (y_i − a M_i − b)/σ_i, w_i = 1, or with the robust loss the Cauchy weights of
//! iteratively reweighted least squares, w_i² = 1/(1 + (r_i/c)²), c = 2.385 × 1.4826 ×
//! median |r| (Holland & Welsch 1977, *Commun. Stat.* 6, 813).
//!
//! # Global search
//!
//! Thickness fits have a local minimum per fringe order. The search starts from the points
//! of a Halton sequence over the bounds; from each it scans every free parameter in turn
//! over a grid spanning its whole range (thickness steps of a sixth of the shortest fringe
//! period in thickness, λ_min/(2 n_max), so no fringe order is skipped; 17 values of an
//! index), twice round, on a subsample of the points, then polishes by Levenberg–Marquardt
//! ([`super::lm`]) on all points. It stops when a fit reaches the noise of the data
//! (mean squared residual ≤ 1.5 × the noise variance estimated from second differences,
//! σ̂² = Σ (y_{i−1} − 2y_i + y_{i+1})² / 6(n − 2)) or the starts run out, keeping the best.
//!
//! # Uncertainty
//!
//! Cov(x) = s² (JᵀJ)⁻¹ at the optimum, s² = χ²/(n − p) (the reduced χ²), or s² = 1 when
//! every point has a σ (Press et al., *Numerical Recipes* 3rd ed., §15.5).

use super::lm::{self, LmOptions, Residuals};
use super::template::{FreeKind, Template};
use crate::error::{Error, Result};
use crate::stack::{Prepared, sin_of_angle};
use num_complex::Complex64 as C64;

/// Which power the data hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// Unpolarised reflectance.
    Reflectance,
    /// Unpolarised transmittance.
    Transmittance,
}

/// A scale or offset: a fixed number or a free polynomial of degree N in wavenumber
/// (`Poly(0)`: a free constant).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Baseline {
    /// A fixed value.
    Fixed(f64),
    /// A free polynomial of this degree.
    Poly(usize),
}

impl Baseline {
    fn terms(self) -> usize {
        match self {
            Baseline::Fixed(_) => 0,
            Baseline::Poly(n) => n + 1,
        }
    }
}

/// The loss.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Loss {
    /// Least squares.
    Linear,
    /// Cauchy (robust to outliers), by reweighting.
    Cauchy,
}

/// One measured point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measurement {
    /// Incidence angle in the ambient, degrees.
    pub angle_deg: f64,
    /// Vacuum wavelength, nm.
    pub wavelength_nm: f64,
    /// The measured R or T.
    pub value: f64,
    /// Its standard deviation, if known.
    pub sigma: Option<f64>,
}

/// How to fit.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// R or T.
    pub quantity: Quantity,
    /// The scale a(ν).
    pub scale: Baseline,
    /// The offset b(ν).
    pub offset: Baseline,
    /// The loss.
    pub loss: Loss,
    /// Most starts of the global search.
    pub starts: usize,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            quantity: Quantity::Reflectance,
            scale: Baseline::Fixed(1.0),
            offset: Baseline::Fixed(0.0),
            loss: Loss::Cauchy,
            starts: 64,
        }
    }
}

/// A fit's result.
#[derive(Clone, Debug)]
pub struct SpectrumFit {
    /// The fitted parameters (the template's order).
    pub x: Vec<f64>,
    /// Their 1σ uncertainties (NaN where the Jacobian leaves a parameter undetermined).
    pub sigma: Vec<f64>,
    /// Root-mean-square of y − fit (unweighted).
    pub rms: f64,
    /// χ² = Σ ((y − fit)/σ)² (σ = 1 where unknown; without the robust weights).
    pub chi2: f64,
    /// Points fitted.
    pub points: usize,
    /// Scale polynomial coefficients (lowest degree first; the fixed value when fixed).
    pub scale: Vec<f64>,
    /// Offset polynomial coefficients (lowest degree first; the fixed value when fixed).
    pub offset: Vec<f64>,
    /// Levenberg–Marquardt iterations, all starts together.
    pub iterations: usize,
    /// Starts of the global search used.
    pub starts: usize,
    /// Per parameter: at (within 10⁻⁶ of the range of) a bound.
    pub on_bound: Vec<bool>,
    /// Per parameter: interference fringes its film spans over the data's wavenumbers,
    /// 2 n d (1/λ_min − 1/λ_max) (NaN for an index).
    pub fringes: Vec<f64>,
    /// Another minimum, differing by more than max(1 nm, 0.5 %) in a thickness, whose χ² is
    /// within 4 s² of the best: the data do not decide between them.
    pub ambiguous: Option<Vec<f64>>,
    /// The fitted values a M + b at every point.
    pub fitted: Vec<f64>,
}

/// The stack's R or T at every point, for parameter vectors.
struct Model<'a> {
    template: &'a Template,
    quantity: Quantity,
    wavelength_nm: Vec<f64>,
    beta: Vec<f64>,
    indices: Vec<Vec<C64>>,
    /// Prepared per point when no index is free.
    prepared: Option<Vec<Prepared>>,
    base_thickness: Vec<f64>,
}

impl<'a> Model<'a> {
    fn new(template: &'a Template, quantity: Quantity, points: &[Measurement]) -> Result<Self> {
        let stack = template.stack();
        stack.require_coherent("a fit")?;
        let mut beta = Vec::with_capacity(points.len());
        let mut indices = Vec::with_capacity(points.len());
        for p in points {
            let n = stack.indices_at(p.wavelength_nm)?;
            beta.push(n[0].re * sin_of_angle(p.angle_deg)?);
            indices.push(n);
        }
        let free_index = template.free().iter().any(|f| f.kind == FreeKind::Index);
        let prepared = (!free_index).then(|| {
            indices
                .iter()
                .zip(&beta)
                .map(|(n, &b)| Prepared::new(n, b))
                .collect()
        });
        Ok(Model {
            template,
            quantity,
            wavelength_nm: points.iter().map(|p| p.wavelength_nm).collect(),
            beta,
            indices,
            prepared,
            base_thickness: stack.thicknesses_nm(),
        })
    }

    /// M at points `subset` for `x`.
    fn eval(&self, x: &[f64], subset: &[usize], out: &mut [f64]) {
        let mut d = self.base_thickness.clone();
        let mut index_of = Vec::new();
        for (f, &v) in self.template.free().iter().zip(x) {
            match f.kind {
                FreeKind::ThicknessNm => d[f.layer - 1] = v,
                FreeKind::Index => index_of.push((f.layer, v)),
            }
        }
        let mut n = Vec::new();
        for (o, &i) in out.iter_mut().zip(subset) {
            let own;
            let p = match &self.prepared {
                Some(p) => &p[i],
                None => {
                    n.clone_from(&self.indices[i]);
                    for &(layer, v) in &index_of {
                        n[layer] = C64::new(v, 0.0);
                    }
                    own = Prepared::new(&n, self.beta[i]);
                    &own
                }
            };
            let power = p.power(&p.amplitudes(self.wavelength_nm[i], &d));
            *o = match self.quantity {
                Quantity::Reflectance => 0.5 * (power.R_s + power.R_p),
                Quantity::Transmittance => 0.5 * (power.T_s + power.T_p),
            };
        }
    }
}

/// The projected residuals on a subset of the points.
struct Projected<'m, 'a> {
    model: &'m Model<'a>,
    subset: Vec<usize>,
    /// y_i, 1/σ_i × robust weight, u_i at the subset.
    y: Vec<f64>,
    w: Vec<f64>,
    u: Vec<f64>,
    scale: Baseline,
    offset: Baseline,
    m: Vec<f64>,
}

impl<'m, 'a> Projected<'m, 'a> {
    fn new(model: &'m Model<'a>, data: &Data, subset: Vec<usize>, settings: &Settings) -> Self {
        let pick = |v: &[f64]| subset.iter().map(|&i| v[i]).collect::<Vec<_>>();
        Projected {
            model,
            y: pick(&data.y),
            w: pick(&data.w),
            u: pick(&data.u),
            m: vec![0.0; subset.len()],
            subset,
            scale: settings.scale,
            offset: settings.offset,
        }
    }

    /// The linear coefficients (scale's, then offset's) for model values `self.m`, and the
    /// fitted values into `fit`.
    fn solve_linear(&self, fit: &mut [f64]) -> (Vec<f64>, Vec<f64>) {
        let (ns, no) = (self.scale.terms(), self.offset.terms());
        let k = ns + no;
        let column = |j: usize, i: usize| -> f64 {
            if j < ns {
                self.m[i] * pow(self.u[i], j)
            } else {
                pow(self.u[i], j - ns)
            }
        };
        let fixed = |i: usize| -> f64 {
            let a = match self.scale {
                Baseline::Fixed(a) => a * self.m[i],
                Baseline::Poly(_) => 0.0,
            };
            let b = match self.offset {
                Baseline::Fixed(b) => b,
                Baseline::Poly(_) => 0.0,
            };
            a + b
        };
        let mut c = vec![0.0; k];
        if k > 0 {
            let mut a = vec![0.0; k * k];
            for i in 0..self.m.len() {
                let w2 = self.w[i] * self.w[i];
                let target = self.y[i] - fixed(i);
                for p in 0..k {
                    let cp = column(p, i);
                    c[p] += w2 * cp * target;
                    for q in 0..=p {
                        a[p * k + q] += w2 * cp * column(q, i);
                    }
                }
            }
            let trace: f64 = (0..k).map(|p| a[p * k + p]).sum();
            for p in 0..k {
                for q in 0..p {
                    a[q * k + p] = a[p * k + q];
                }
                a[p * k + p] += 1e-12 * trace + f64::MIN_POSITIVE;
            }
            if !lm::cholesky_solve(&mut a, k, &mut c) {
                c.fill(0.0);
            }
        }
        for (i, f) in fit.iter_mut().enumerate() {
            *f = fixed(i) + (0..k).map(|j| c[j] * column(j, i)).sum::<f64>();
        }
        let scale = match self.scale {
            Baseline::Fixed(a) => vec![a],
            Baseline::Poly(_) => c[..ns].to_vec(),
        };
        let offset = match self.offset {
            Baseline::Fixed(b) => vec![b],
            Baseline::Poly(_) => c[ns..].to_vec(),
        };
        (scale, offset)
    }
}

impl Residuals for Projected<'_, '_> {
    fn len(&self) -> usize {
        self.subset.len()
    }

    fn residuals(&mut self, x: &[f64], out: &mut [f64]) -> Result<()> {
        let mut m = std::mem::take(&mut self.m);
        self.model.eval(x, &self.subset, &mut m);
        self.m = m;
        self.solve_linear(out);
        for ((o, w), y) in out.iter_mut().zip(&self.w).zip(&self.y) {
            *o = w * (y - *o);
        }
        Ok(())
    }
}

/// The data in the form the residuals use.
struct Data {
    y: Vec<f64>,
    /// 1/σ.
    w: Vec<f64>,
    /// Normalised wavenumber.
    u: Vec<f64>,
}

/// u^k by repeated multiplication (IEEE basic operations: the same bits everywhere).
fn pow(u: f64, k: usize) -> f64 {
    (0..k).fold(1.0, |a, _| a * u)
}

fn sq(v: f64) -> f64 {
    v * v
}

/// The Halton sequence's `i`-th value in base `b` (i ≥ 1), in (0, 1).
fn halton(mut i: usize, b: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= b as f64;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

const PRIMES: [usize; 16] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53];

/// Fits `template`'s free parameters to `points` (at least one more point than free
/// parameters and linear coefficients together).
pub fn fit_spectrum(
    template: &Template,
    points: &[Measurement],
    settings: &Settings,
) -> Result<SpectrumFit> {
    let dims = template.dims();
    let linear = settings.scale.terms() + settings.offset.terms();
    if points.len() <= dims + linear {
        return Err(Error::FitData {
            message: format!(
                "{} points cannot fix {dims} free parameters and {linear} scale/offset coefficients: at least {} are needed",
                points.len(),
                dims + linear + 1
            ),
        });
    }
    let model = Model::new(template, settings.quantity, points)?;
    let nu: Vec<f64> = points.iter().map(|p| 1.0 / p.wavelength_nm).collect();
    let (nu_min, nu_max) = nu
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let span = (nu_max - nu_min).max(f64::MIN_POSITIVE);
    let data = Data {
        y: points.iter().map(|p| p.value).collect(),
        w: points
            .iter()
            .map(|p| 1.0 / p.sigma.unwrap_or(1.0))
            .collect(),
        u: nu.iter().map(|v| 2.0 * (v - nu_min) / span - 1.0).collect(),
    };
    let n = points.len();
    let all: Vec<usize> = (0..n).collect();
    // The subsample for the scans: about 4 points per fringe of the thickest stack allowed.
    let lo: Vec<f64> = template.free().iter().map(|f| f.lo).collect();
    let hi: Vec<f64> = template.free().iter().map(|f| f.hi).collect();
    let n_max: Vec<f64> = template
        .free()
        .iter()
        .map(|f| match f.kind {
            FreeKind::Index => f.hi,
            FreeKind::ThicknessNm => model
                .indices
                .iter()
                .map(|n| n[f.layer].re)
                .fold(0.0, f64::max),
        })
        .collect();
    let max_opd: f64 = template
        .stack()
        .layers()
        .iter()
        .enumerate()
        .map(|(j, l)| {
            let n = model
                .indices
                .iter()
                .map(|n| n[j + 1].re)
                .fold(0.0, f64::max);
            let d = template
                .free()
                .iter()
                .filter(|f| f.layer == j + 1 && f.kind == FreeKind::ThicknessNm)
                .map(|f| f.hi)
                .fold(l.thickness_nm, f64::max);
            let n = template
                .free()
                .iter()
                .filter(|f| f.layer == j + 1 && f.kind == FreeKind::Index)
                .map(|f| f.hi)
                .fold(n, f64::max);
            2.0 * n * d
        })
        .sum();
    let wanted = ((max_opd * (nu_max - nu_min)) * 4.0).ceil() as usize + 4 * (dims + linear);
    let stride = (n / wanted.max(1)).max(1);
    let subset: Vec<usize> = (0..n).step_by(stride).collect();
    let lambda_min = 1.0 / nu_max;
    // The grids of the scans.
    let grids: Vec<Vec<f64>> = template
        .free()
        .iter()
        .zip(&n_max)
        .map(|(f, &nm)| {
            let count = match f.kind {
                FreeKind::ThicknessNm => {
                    let step = lambda_min / (2.0 * nm.max(1.0)) / 6.0;
                    ((f.hi - f.lo) / step).ceil() as usize + 1
                }
                FreeKind::Index => 17,
            }
            .clamp(2, 100_000);
            (0..count)
                .map(|i| f.lo + (f.hi - f.lo) * i as f64 / (count - 1) as f64)
                .collect()
        })
        .collect();
    // The noise the data show: second differences along each run of points.
    let noise_var = {
        let (mut s, mut c) = (0.0, 0usize);
        for i in 1..n.saturating_sub(1) {
            if points[i - 1].angle_deg == points[i].angle_deg
                && points[i + 1].angle_deg == points[i].angle_deg
            {
                let d2 = data.w[i] * (data.y[i - 1] - 2.0 * data.y[i] + data.y[i + 1]);
                s += d2 * d2;
                c += 1;
            }
        }
        if c > 0 { s / (6.0 * c as f64) } else { 0.0 }
    };
    let options = LmOptions::default();
    let mut scan = Projected::new(&model, &data, subset, settings);
    let mut full = Projected::new(&model, &data, all.clone(), settings);
    let mut r_scan = vec![0.0; scan.len()];
    let mut best: Option<lm::LmResult> = None;
    let mut minima: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut iterations = 0;
    let mut starts = 0;
    let good_enough = |cost: f64| cost / n as f64 <= 1.5 * noise_var;
    for s in 1..=settings.starts.max(1) {
        starts = s;
        let mut x: Vec<f64> = (0..dims)
            .map(|k| lo[k] + (hi[k] - lo[k]) * halton(s, PRIMES[k % PRIMES.len()]))
            .collect();
        for _round in 0..2 {
            for k in 0..dims {
                let mut best_v = (f64::INFINITY, x[k]);
                for &v in &grids[k] {
                    x[k] = v;
                    scan.residuals(&x, &mut r_scan)?;
                    let c = lm::sum_sq(&r_scan);
                    if c < best_v.0 {
                        best_v = (c, v);
                    }
                }
                x[k] = best_v.1;
            }
        }
        let r = lm::minimize(&mut full, &x, &lo, &hi, options)?;
        iterations += r.iterations;
        minima.push((r.cost, r.x.clone()));
        let done = good_enough(r.cost);
        if best.as_ref().is_none_or(|b| r.cost < b.cost) {
            best = Some(r);
        }
        if done || dims == 0 {
            break;
        }
    }
    let mut best = match best {
        Some(b) => b,
        None => lm::minimize(&mut full, &[], &lo, &hi, options)?,
    };
    // Robust polish: Cauchy weights by IRLS.
    if settings.loss == Loss::Cauchy && dims > 0 {
        for _ in 0..3 {
            let mut abs: Vec<f64> = best.residuals.iter().map(|r| r.abs()).collect();
            abs.sort_by(f64::total_cmp);
            let c = 2.385 * 1.4826 * abs[abs.len() / 2];
            if !(c > 0.0) {
                break;
            }
            for (i, r) in best.residuals.iter().enumerate() {
                let raw = r / full.w[i];
                let wi = data.w[i];
                let rr = raw * wi / c;
                full.w[i] = wi / (1.0 + rr * rr).sqrt();
            }
            let r = lm::minimize(&mut full, &best.x, &lo, &hi, options)?;
            iterations += r.iterations;
            best = r;
        }
    }
    // Values at the optimum, without robust weights.
    let mut fitted = vec![0.0; n];
    full.residuals(&best.x, &mut fitted)?;
    let (scale, offset) = full.solve_linear(&mut fitted);
    let chi2: f64 = (0..n)
        .map(|i| sq(data.w[i] * (data.y[i] - fitted[i])))
        .sum();
    let rms = ((0..n).map(|i| sq(data.y[i] - fitted[i])).sum::<f64>() / n as f64).sqrt();
    let dof = (n - dims - linear) as f64;
    let s2 = if points.iter().all(|p| p.sigma.is_some()) {
        1.0
    } else {
        chi2 / dof
    };
    let sigma = match lm::inverse_diagonal(&best.jtj, dims) {
        Some(d) => d.iter().map(|v| (v * s2).max(0.0).sqrt()).collect(),
        None => vec![f64::NAN; dims],
    };
    let on_bound = (0..dims)
        .map(|k| {
            let tol = 1e-6 * (hi[k] - lo[k]);
            best.x[k] <= lo[k] + tol || best.x[k] >= hi[k] - tol
        })
        .collect();
    let fringes = template
        .free()
        .iter()
        .enumerate()
        .map(|(k, f)| match f.kind {
            FreeKind::Index => f64::NAN,
            FreeKind::ThicknessNm => {
                let n = template
                    .free()
                    .iter()
                    .position(|g| g.layer == f.layer && g.kind == FreeKind::Index)
                    .map_or(n_max[k], |i| best.x[i]);
                2.0 * n * best.x[k] * (nu_max - nu_min)
            }
        })
        .collect();
    let distinct = |x: &[f64]| {
        template
            .free()
            .iter()
            .zip(x)
            .zip(&best.x)
            .any(|((f, a), b)| {
                f.kind == FreeKind::ThicknessNm && (a - b).abs() > (0.005 * b.abs()).max(1.0)
            })
    };
    let best_cost = minima.iter().map(|m| m.0).fold(f64::INFINITY, f64::min);
    let ambiguous = minima
        .iter()
        .filter(|(c, x)| distinct(x) && c - best_cost < 4.0 * s2)
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|m| m.1.clone());
    Ok(SpectrumFit {
        x: best.x,
        sigma,
        rms,
        chi2,
        points: n,
        scale,
        offset,
        iterations,
        starts,
        on_bound,
        fringes,
        ambiguous,
        fitted,
    })
}
