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
//! # Evaluation and derivatives
//!
//! The model runs through one prepared [`SpectrumSweep`] per incidence angle (indices
//! resolved once; per evaluation only the new thicknesses or free indices), and
//! Levenberg–Marquardt takes the exact derivatives of [`crate::jacobian`] (reverse mode:
//! all L thickness derivatives in one sweep; index derivatives with
//! [`Wrt::ThicknessAndIndex`]), projected off the linear scale/offset columns as in
//! Kaufman's variable projection.
//!
//! # Global search
//!
//! Thickness fits have a local minimum per fringe order. The search starts from the points
//! of a Halton sequence over the bounds; from each it scans along every free parameter in
//! turn over the whole range (thickness steps of a sixth of the shortest fringe period in
//! thickness, λ_min/(2 n_max), so no fringe order is skipped; 16 steps of an index), and
//! along every interface between two free films (d_j + t, d_{j+1} − t n_j/n_{j+1}: the
//! pair's optical thickness kept, so thickness moves between neighbours without crossing
//! the stack's fringe orders), until a round gains nothing (at most four rounds), on a
//! subsample of the points; then polishes by Levenberg–Marquardt ([`super::lm`]) on all
//! points. It stops when a fit reaches the noise of the data (mean squared residual ≤ 1.5
//! × the noise variance estimated from second differences,
//! σ̂² = Σ (y_{i−1} − 2y_i + y_{i+1})² / 6(n − 2)) with white residuals (the Durbin–Watson
//! ratio within 3 standard deviations of 2), or the starts run out, keeping the best.
//!
//! # Uncertainty
//!
//! Cov(x) = s² (JᵀJ)⁻¹ at the optimum, s² = χ²/(n − p) (the reduced χ²), or s² = 1 when
//! every point has a σ (Press et al., *Numerical Recipes* 3rd ed., §15.5).

use super::lm::{self, LmOptions, Residuals};
use super::template::{FreeKind, Template};
use super::{PRIMES, Steps, Watch, halton};
use crate::error::{Error, Result};
use crate::jacobian::{Wrt, point_jacobian};
use crate::power::Power;
use crate::spectrum_sweep::SpectrumSweep;
use crate::stack::sin_of_angle;
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

/// What every point's exact derivatives need: the media's indices and sin θ₀.
struct Points {
    angle_deg: Vec<f64>,
    wavelength_nm: Vec<f64>,
    sin_theta: Vec<f64>,
    /// Per point: ambient, films top first, substrate.
    indices: Vec<Vec<C64>>,
}

impl Points {
    fn new(template: &Template, points: &[Measurement]) -> Result<Self> {
        let stack = template.stack();
        stack.require_coherent("a fit")?;
        let mut sin_theta = Vec::with_capacity(points.len());
        let mut indices = Vec::with_capacity(points.len());
        for p in points {
            indices.push(stack.indices_at(p.wavelength_nm)?);
            sin_theta.push(sin_of_angle(p.angle_deg)?);
        }
        Ok(Points {
            angle_deg: points.iter().map(|p| p.angle_deg).collect(),
            wavelength_nm: points.iter().map(|p| p.wavelength_nm).collect(),
            sin_theta,
            indices,
        })
    }
}

/// The stack's R or T on a subset of the points for parameter vectors: one prepared
/// [`SpectrumSweep`] per incidence angle (indices resolved once; per evaluation only the
/// new thicknesses and free indices), and the exact derivatives of [`crate::jacobian`]
/// (reverse mode: every film's thickness derivative in one sweep, index derivatives with
/// [`Wrt::ThicknessAndIndex`]).
struct Model<'a> {
    template: &'a Template,
    quantity: Quantity,
    points: &'a Points,
    subset: Vec<usize>,
    /// Per angle: its sweep and the positions in `subset` of its points, in its order.
    groups: Vec<(SpectrumSweep, Vec<usize>)>,
    /// The free indices the sweeps hold now (per free parameter; NaN for a thickness).
    held_index: Vec<f64>,
    thickness_nm: Vec<f64>,
    powers: Vec<Power>,
}

impl<'a> Model<'a> {
    fn new(
        template: &'a Template,
        quantity: Quantity,
        points: &'a Points,
        subset: Vec<usize>,
    ) -> Result<Self> {
        let mut angles: Vec<(f64, Vec<usize>)> = Vec::new();
        for (pos, &i) in subset.iter().enumerate() {
            let a = points.angle_deg[i];
            match angles.iter_mut().find(|(b, _)| b.to_bits() == a.to_bits()) {
                Some((_, members)) => members.push(pos),
                None => angles.push((a, vec![pos])),
            }
        }
        let mut groups = Vec::with_capacity(angles.len());
        for (a, members) in angles {
            let wavelengths: Vec<f64> = members
                .iter()
                .map(|&pos| points.wavelength_nm[subset[pos]])
                .collect();
            groups.push((
                SpectrumSweep::new(template.stack(), &[a], &wavelengths)?,
                members,
            ));
        }
        Ok(Model {
            template,
            quantity,
            points,
            subset,
            groups,
            held_index: vec![f64::NAN; template.dims()],
            thickness_nm: template.stack().thicknesses_nm(),
            powers: Vec::new(),
        })
    }

    fn value(quantity: Quantity, p: &Power) -> f64 {
        match quantity {
            Quantity::Reflectance => 0.5 * (p.R_s + p.R_p),
            Quantity::Transmittance => 0.5 * (p.T_s + p.T_p),
        }
    }

    /// Sets the free parameters `x` into the thicknesses and the sweeps.
    fn set(&mut self, x: &[f64]) -> Result<()> {
        for (k, (f, &v)) in self.template.free().iter().zip(x).enumerate() {
            match f.kind {
                FreeKind::ThicknessNm => self.thickness_nm[f.layer - 1] = v,
                FreeKind::Index => {
                    if self.held_index[k].to_bits() != v.to_bits() {
                        for (sweep, _) in &mut self.groups {
                            sweep.set_film_index(f.layer, C64::new(v, 0.0))?;
                        }
                        self.held_index[k] = v;
                    }
                }
            }
        }
        Ok(())
    }

    /// M at the subset's points for `x`, into `out`.
    fn eval(&mut self, x: &[f64], out: &mut [f64]) -> Result<()> {
        self.set(x)?;
        let mut powers = std::mem::take(&mut self.powers);
        for (sweep, members) in &mut self.groups {
            sweep.set_thicknesses_nm(&self.thickness_nm)?;
            powers.resize(members.len(), Power::default());
            sweep.powers_into(&mut powers)?;
            for (p, &pos) in powers.iter().zip(members.iter()) {
                out[pos] = Self::value(self.quantity, p);
            }
        }
        self.powers = powers;
        Ok(())
    }

    /// ∂M_i/∂x_k at the subset's points into `dm[i * dims + k]`, exact.
    fn derivatives(&mut self, x: &[f64], dm: &mut [f64]) -> Result<()> {
        self.set(x)?;
        let free = self.template.free();
        let dims = free.len();
        let wrt = if free.iter().any(|f| f.kind == FreeKind::Index) {
            Wrt::ThicknessAndIndex
        } else {
            Wrt::Thickness
        };
        let mut n = Vec::new();
        for (row, &i) in dm.chunks_exact_mut(dims.max(1)).zip(&self.subset) {
            n.clone_from(&self.points.indices[i]);
            for (f, &v) in free.iter().zip(x) {
                if f.kind == FreeKind::Index {
                    n[f.layer] = C64::new(v, 0.0);
                }
            }
            let j = point_jacobian(
                &n,
                &self.thickness_nm,
                self.points.sin_theta[i],
                self.points.wavelength_nm[i],
                wrt,
            );
            for (d, f) in row.iter_mut().zip(free) {
                *d = Self::value(
                    self.quantity,
                    match f.kind {
                        FreeKind::ThicknessNm => &j.d_thickness[f.layer - 1],
                        FreeKind::Index => &j.d_index_re[f.layer - 1],
                    },
                );
            }
        }
        Ok(())
    }
}

/// The projected residuals on a subset of the points.
struct Projected<'a> {
    model: Model<'a>,
    /// y_i, 1/σ_i × robust weight, u_i at the subset.
    y: Vec<f64>,
    w: Vec<f64>,
    u: Vec<f64>,
    scale: Baseline,
    offset: Baseline,
    m: Vec<f64>,
    dm: Vec<f64>,
}

impl<'a> Projected<'a> {
    fn new(model: Model<'a>, data: &Data, settings: &Settings) -> Self {
        let pick = |v: &[f64]| model.subset.iter().map(|&i| v[i]).collect::<Vec<_>>();
        Projected {
            y: pick(&data.y),
            w: pick(&data.w),
            u: pick(&data.u),
            m: vec![0.0; model.subset.len()],
            dm: Vec::new(),
            scale: settings.scale,
            offset: settings.offset,
            model,
        }
    }

    /// Column j of the linear model at point i: M u^j for the scale's terms, then u^j for
    /// the offset's.
    fn column(&self, j: usize, i: usize) -> f64 {
        let ns = self.scale.terms();
        if j < ns {
            self.m[i] * pow(self.u[i], j)
        } else {
            pow(self.u[i], j - ns)
        }
    }

    /// The fixed part of the fit at point i (a fixed scale times M plus a fixed offset).
    fn fixed(&self, i: usize) -> f64 {
        let a = match self.scale {
            Baseline::Fixed(a) => a * self.m[i],
            Baseline::Poly(_) => 0.0,
        };
        let b = match self.offset {
            Baseline::Fixed(b) => b,
            Baseline::Poly(_) => 0.0,
        };
        a + b
    }

    /// The weighted normal matrix BᵀB of the linear columns (k × k, regularised by 10⁻¹²
    /// of its trace).
    fn normal_matrix(&self) -> Vec<f64> {
        let k = self.scale.terms() + self.offset.terms();
        let mut a = vec![0.0; k * k];
        for i in 0..self.m.len() {
            let w2 = self.w[i] * self.w[i];
            for p in 0..k {
                let cp = self.column(p, i);
                for q in 0..=p {
                    a[p * k + q] += w2 * cp * self.column(q, i);
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
        a
    }

    /// The linear coefficients (scale's, then offset's) for model values `self.m`, and the
    /// fitted values into `fit`.
    fn solve_linear(&self, fit: &mut [f64]) -> (Vec<f64>, Vec<f64>) {
        let ns = self.scale.terms();
        let k = ns + self.offset.terms();
        let mut c = vec![0.0; k];
        if k > 0 {
            for i in 0..self.m.len() {
                let w2 = self.w[i] * self.w[i];
                let target = self.y[i] - self.fixed(i);
                for (p, cp) in c.iter_mut().enumerate() {
                    *cp += w2 * self.column(p, i) * target;
                }
            }
            let mut a = self.normal_matrix();
            if !lm::cholesky_solve(&mut a, k, &mut c) {
                c.fill(0.0);
            }
        }
        for (i, f) in fit.iter_mut().enumerate() {
            *f = self.fixed(i) + (0..k).map(|j| c[j] * self.column(j, i)).sum::<f64>();
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

impl Residuals for Projected<'_> {
    fn len(&self) -> usize {
        self.model.subset.len()
    }

    fn residuals(&mut self, x: &[f64], out: &mut [f64]) -> Result<()> {
        self.model.eval(x, &mut self.m)?;
        self.solve_linear(out);
        for ((o, w), y) in out.iter_mut().zip(&self.w).zip(&self.y) {
            *o = w * (y - *o);
        }
        Ok(())
    }

    /// The variable-projection Jacobian in Kaufman's form (Kaufman 1975, *BIT* 15, 49):
    /// J = −P⊥ W diag(a) ∂M/∂x, a(ν) the scale at the optimal linear coefficients, P⊥ the
    /// projector off the weighted linear columns B, P⊥ v = v − B (BᵀB)⁻¹ Bᵀ v; exact when
    /// scale and offset are fixed.
    fn jacobian(&mut self, x: &[f64], _lo: &[f64], _hi: &[f64], jac: &mut [f64]) -> Result<()> {
        let n = self.len();
        let dims = x.len();
        self.model.eval(x, &mut self.m)?;
        let mut fit = vec![0.0; n];
        let (scale, _) = self.solve_linear(&mut fit);
        let mut dm = std::mem::take(&mut self.dm);
        dm.resize(n * dims, 0.0);
        self.model.derivatives(x, &mut dm)?;
        for i in 0..n {
            let a = match self.scale {
                Baseline::Fixed(a) => a,
                Baseline::Poly(_) => scale
                    .iter()
                    .enumerate()
                    .map(|(j, c)| c * pow(self.u[i], j))
                    .sum(),
            };
            for k in 0..dims {
                jac[i * dims + k] = -self.w[i] * a * dm[i * dims + k];
            }
        }
        self.dm = dm;
        let terms = self.scale.terms() + self.offset.terms();
        if terms > 0 {
            let a = self.normal_matrix();
            let b = |i: usize, j: usize| self.w[i] * self.column(j, i);
            for k in 0..dims {
                let mut s: Vec<f64> = (0..terms)
                    .map(|j| (0..n).map(|i| b(i, j) * jac[i * dims + k]).sum())
                    .collect();
                let mut f = a.clone();
                if !lm::cholesky_solve(&mut f, terms, &mut s) {
                    continue;
                }
                for i in 0..n {
                    jac[i * dims + k] -= (0..terms).map(|j| b(i, j) * s[j]).sum::<f64>();
                }
            }
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

/// Scans `x` along `dir` (pairs parameter, coefficient) over the whole range the bounds
/// allow, in steps no longer than any of its parameters' `steps`, and moves it to the
/// lowest cost found (x itself included); returns that cost.
fn line_scan(
    scan: &mut Projected,
    r: &mut [f64],
    x: &mut [f64],
    dir: &[(usize, f64)],
    steps: &[f64],
    lo: &[f64],
    hi: &[f64],
) -> Result<f64> {
    let (mut t_lo, mut t_hi, mut step) = (f64::NEG_INFINITY, f64::INFINITY, f64::INFINITY);
    for &(k, c) in dir {
        let (a, b) = ((lo[k] - x[k]) / c, (hi[k] - x[k]) / c);
        t_lo = t_lo.max(a.min(b));
        t_hi = t_hi.min(a.max(b));
        step = step.min(steps[k] / c.abs());
    }
    scan.residuals(x, r)?;
    let mut best = (lm::sum_sq(r), 0.0);
    if t_hi > t_lo {
        let count = (((t_hi - t_lo) / step).ceil() as usize + 1).clamp(2, 100_000);
        let mut xt = x.to_vec();
        for i in 0..count {
            let t = t_lo + (t_hi - t_lo) * i as f64 / (count - 1) as f64;
            for &(k, c) in dir {
                xt[k] = (x[k] + c * t).clamp(lo[k], hi[k]);
            }
            scan.residuals(&xt, r)?;
            let cost = lm::sum_sq(r);
            if cost < best.0 {
                best = (cost, t);
            }
        }
    }
    for &(k, c) in dir {
        x[k] = (x[k] + c * best.1).clamp(lo[k], hi[k]);
    }
    Ok(best.0)
}

/// Fits `template`'s free parameters to `points` (at least one more point than free
/// parameters and linear coefficients together).
pub fn fit_spectrum(
    template: &Template,
    points: &[Measurement],
    settings: &Settings,
) -> Result<SpectrumFit> {
    fit_spectrum_watched(template, points, settings, Watch::none())
}

/// [`fit_spectrum`] reporting its steps to `watch` (one per start of the global search; a
/// search that stops early at the noise jumps to the end) and stopping with
/// [`Error::FitCancelled`] once its cancel flag is set (read before every start and every
/// round of scans). The result is [`fit_spectrum`]'s.
pub fn fit_spectrum_watched(
    template: &Template,
    points: &[Measurement],
    settings: &Settings,
    watch: Watch<'_>,
) -> Result<SpectrumFit> {
    let progress = Steps::new(watch, settings.starts.max(1));
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
    let pts = Points::new(template, points)?;
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
            FreeKind::ThicknessNm => pts
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
            let n = pts.indices.iter().map(|n| n[j + 1].re).fold(0.0, f64::max);
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
    // The scans' steps: a sixth of the shortest fringe period in thickness, λ_min/(2 n_max);
    // a sixteenth of an index's range.
    let steps: Vec<f64> = template
        .free()
        .iter()
        .zip(&n_max)
        .map(|(f, &nm)| match f.kind {
            FreeKind::ThicknessNm => lambda_min / (2.0 * nm.max(1.0)) / 6.0,
            FreeKind::Index => (f.hi - f.lo) / 16.0,
        })
        .map(|s| s.max(f64::MIN_POSITIVE))
        .collect();
    // The scans' directions: every parameter alone, then every interface between two films
    // whose thicknesses are free moved alone (d_j + t, d_{j+1} − t n_j/n_{j+1}: the optical
    // thickness of the pair kept), which swaps thickness between neighbours without
    // crossing the fringe orders of the whole stack.
    let mut directions: Vec<Vec<(usize, f64)>> = (0..dims).map(|k| vec![(k, 1.0)]).collect();
    for k in 0..dims {
        let f = template.free()[k];
        if f.kind != FreeKind::ThicknessNm {
            continue;
        }
        if let Some(m) = (k + 1..dims).find(|&m| {
            template.free()[m].kind == FreeKind::ThicknessNm
                && template.free()[m].layer == f.layer + 1
        }) {
            directions.push(vec![(k, 1.0), (m, -n_max[k] / n_max[m].max(1.0))]);
        }
    }
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
    let mut scan = Projected::new(
        Model::new(template, settings.quantity, &pts, subset)?,
        &data,
        settings,
    );
    let mut full = Projected::new(
        Model::new(template, settings.quantity, &pts, all)?,
        &data,
        settings,
    );
    let mut r_scan = vec![0.0; scan.len()];
    let mut best: Option<lm::LmResult> = None;
    let mut minima: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut iterations = 0;
    let mut starts = 0;
    // A fit is good enough to stop at when its residuals are as small as the noise and as
    // white: the Durbin–Watson ratio Σ (r_i − r_{i−1})² / Σ r_i² over neighbours of one
    // angle's run is 2 for white noise (standard deviation ≈ 2/√n) and falls towards 0
    // when a smooth misfit remains (Durbin & Watson 1950, *Biometrika* 37, 409). The noise
    // estimate from second differences grows with the curvature of a fast-fringing signal,
    // so the size test alone accepts a neighbouring minimum whose misfit is as large as
    // the noise.
    let neighbours: Vec<usize> = (1..n)
        .filter(|&i| points[i - 1].angle_deg == points[i].angle_deg)
        .collect();
    let white = |r: &[f64]| {
        let num: f64 = neighbours.iter().map(|&i| sq(r[i] - r[i - 1])).sum();
        let den: f64 = neighbours
            .iter()
            .map(|&i| sq(r[i]) + sq(r[i - 1]))
            .sum::<f64>()
            / 2.0;
        let m = neighbours.len() as f64;
        m < 8.0 || num / den.max(f64::MIN_POSITIVE) >= 2.0 - 6.0 / m.sqrt()
    };
    let good_enough =
        |r: &lm::LmResult| r.cost / n as f64 <= 1.5 * noise_var && white(&r.residuals);
    for s in 1..=settings.starts.max(1) {
        progress.check()?;
        starts = s;
        let mut x: Vec<f64> = (0..dims)
            .map(|k| lo[k] + (hi[k] - lo[k]) * halton(s, PRIMES[k % PRIMES.len()]))
            .collect();
        let mut cost = f64::INFINITY;
        for _round in 0..4 {
            progress.check()?;
            let before = cost;
            for dir in &directions {
                cost = line_scan(&mut scan, &mut r_scan, &mut x, dir, &steps, &lo, &hi)?;
            }
            if cost >= before * (1.0 - 1e-9) {
                break;
            }
        }
        let r = lm::minimize(&mut full, &x, &lo, &hi, options)?;
        iterations += r.iterations;
        minima.push((r.cost, r.x.clone()));
        let done = good_enough(&r);
        if best.as_ref().is_none_or(|b| r.cost < b.cost) {
            best = Some(r);
        }
        progress.step();
        if done || dims == 0 {
            break;
        }
    }
    progress.finish();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::template::Free;
    use crate::material::Material;
    use crate::stack::{Layer, Stack};

    /// Two films on glass, film 1's index and both thicknesses free.
    fn template() -> Template {
        let m = |n: f64| Material::constant(format!("{n}"), C64::new(n, 0.0)).unwrap();
        let stack = Stack::new(
            m(1.0),
            vec![
                Layer {
                    material: m(2.1),
                    thickness_nm: 180.0,
                },
                Layer {
                    material: m(1.46),
                    thickness_nm: 420.0,
                },
            ],
            m(1.52),
        )
        .unwrap();
        let free = |layer, kind, lo, hi| Free {
            layer,
            kind,
            lo,
            hi,
        };
        Template::new(
            stack,
            vec![
                free(1, FreeKind::Index, 1.8, 2.4),
                free(1, FreeKind::ThicknessNm, 10.0, 2000.0),
                free(2, FreeKind::ThicknessNm, 10.0, 2000.0),
            ],
        )
        .unwrap()
    }

    /// The exact Jacobian of the projected residuals against central differences: at any
    /// point with a fixed scale and offset, and with a free linear scale and offset at the
    /// truth of noiseless data (zero residuals, where Kaufman's form is exact).
    #[test]
    fn exact_jacobian_matches_central_differences() {
        let t = template();
        let truth = [2.1, 180.0, 420.0];
        let stack = t.stack_at(&truth).unwrap();
        let mut measured = Vec::new();
        for angle_deg in [0.0, 40.0] {
            for w in (400..=800).step_by(5) {
                let wl = w as f64;
                let p = stack.evaluate(angle_deg, wl).unwrap().power;
                let value = (0.8 + 30.0 / wl) * 0.5 * (p.R_s + p.R_p) + 0.02;
                measured.push(Measurement {
                    angle_deg,
                    wavelength_nm: wl,
                    value,
                    sigma: None,
                });
            }
        }
        let points = Points::new(&t, &measured).unwrap();
        let n = measured.len();
        let data = Data {
            y: measured.iter().map(|p| p.value).collect(),
            w: vec![1.0; n],
            u: measured
                .iter()
                .map(|p| {
                    2.0 * (1.0 / p.wavelength_nm - 1.0 / 800.0) / (1.0 / 400.0 - 1.0 / 800.0) - 1.0
                })
                .collect(),
        };
        let lo: Vec<f64> = t.free().iter().map(|f| f.lo).collect();
        let hi: Vec<f64> = t.free().iter().map(|f| f.hi).collect();
        for (scale, offset, x) in [
            (
                Baseline::Fixed(0.9),
                Baseline::Fixed(0.01),
                [2.05, 190.0, 400.0],
            ),
            (Baseline::Poly(1), Baseline::Poly(0), truth),
        ] {
            let settings = Settings {
                scale,
                offset,
                ..Settings::default()
            };
            let model = Model::new(&t, Quantity::Reflectance, &points, (0..n).collect()).unwrap();
            let mut p = Projected::new(model, &data, &settings);
            let mut exact = vec![0.0; n * 3];
            let mut numeric = vec![0.0; n * 3];
            p.jacobian(&x, &lo, &hi, &mut exact).unwrap();
            // Smaller steps than the search's, for a tighter check.
            let h = [1e-6, 1e-5, 1e-5];
            for k in 0..3 {
                let (mut up, mut down) = (x, x);
                up[k] += h[k];
                down[k] -= h[k];
                let (mut ru, mut rd) = (vec![0.0; n], vec![0.0; n]);
                p.residuals(&up, &mut ru).unwrap();
                p.residuals(&down, &mut rd).unwrap();
                for i in 0..n {
                    numeric[i * 3 + k] = (ru[i] - rd[i]) / (2.0 * h[k]);
                }
            }
            let scale_of = |k: usize| (0..n).map(|i| numeric[i * 3 + k].abs()).fold(0.0, f64::max);
            for i in 0..n {
                for k in 0..3 {
                    let (e, d) = (exact[i * 3 + k], numeric[i * 3 + k]);
                    assert!(
                        (e - d).abs() <= 1e-5 * scale_of(k),
                        "{scale:?}/{offset:?}: point {i}, parameter {k}: exact {e}, numeric {d}"
                    );
                }
            }
        }
    }

    /// A watched fit reports its starts and gives the plain fit's result; a set cancel
    /// flag stops it before its first start.
    #[test]
    fn a_watched_fit_reports_and_cancels() {
        use std::sync::Mutex;
        use std::sync::atomic::AtomicBool;
        let m = |n: f64| Material::constant(format!("{n}"), C64::new(n, 0.0)).unwrap();
        let stack = Stack::new(
            m(1.0),
            vec![Layer {
                material: m(1.46),
                thickness_nm: 300.0,
            }],
            m(3.9),
        )
        .unwrap();
        let t = Template::new(
            stack.clone(),
            vec![Free {
                layer: 1,
                kind: FreeKind::ThicknessNm,
                lo: 10.0,
                hi: 1000.0,
            }],
        )
        .unwrap();
        let measured: Vec<Measurement> = (400..=800)
            .step_by(4)
            .map(|w| {
                let wl = w as f64;
                let p = stack.evaluate(0.0, wl).unwrap().power;
                Measurement {
                    angle_deg: 0.0,
                    wavelength_nm: wl,
                    value: 0.5 * (p.R_s + p.R_p),
                    sigma: None,
                }
            })
            .collect();
        let settings = Settings::default();
        let plain = fit_spectrum(&t, &measured, &settings).unwrap();
        let seen = Mutex::new(Vec::new());
        let progress = |done: usize, total: usize| seen.lock().unwrap().push((done, total));
        let cancel = AtomicBool::new(false);
        let watch = Watch {
            progress: &progress,
            cancel: &cancel,
        };
        let watched = fit_spectrum_watched(&t, &measured, &settings, watch).unwrap();
        assert_eq!(watched.x, plain.x);
        assert_eq!(watched.rms, plain.rms);
        let seen = seen.lock().unwrap().clone();
        assert!(!seen.is_empty());
        assert_eq!(seen.last(), Some(&(settings.starts, settings.starts)));
        cancel.store(true, std::sync::atomic::Ordering::Relaxed);
        let e = fit_spectrum_watched(&t, &measured, &settings, watch).unwrap_err();
        assert!(
            matches!(e, Error::FitCancelled { done: 0, total } if total == settings.starts),
            "{e}"
        );
    }
}
