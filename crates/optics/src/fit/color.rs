//! Colour design: the free thicknesses and indices of a [`Template`] whose reflected (or
//! transmitted) colour matches target colours at given incidence angles, globally over the
//! bounds.
//!
//! # Objective
//!
//! Each target row i has an angle θᵢ, a CIELAB colour Lab*ᵢ (under the colorimeter's
//! illuminant and observer, CIE 015:2018 §8.2.1) and a weight wᵢ > 0. The stack at
//! parameters x has the colour
//!
//! ```text
//! XYZ(θ, x) = Σₖ q(θ, λₖ; x) Wₖ,        Lab(θ, x) = CIELAB(XYZ(θ, x), white)
//! ```
//!
//! with q = R or T unpolarised and (λₖ, Wₖ) the exact spectral rule
//! ([`SpectralRule::for_stack`]) of the stack at the upper bounds (the largest optical path
//! any x reaches, so one rule resolves every trial stack's fringes), its output-space
//! weights taken back to XYZ. The fit minimises
//!
//! ```text
//! F(x) = Σᵢ wᵢ ΔE₀₀(Lab*ᵢ, Lab(θᵢ, x))²
//! ```
//!
//! (CIEDE2000, Sharma, Wu & Dalal 2005) as a least-squares problem with residuals
//! rᵢ = √wᵢ ΔE₀₀ᵢ.
//!
//! # Search
//!
//! Thickness orders give similar colours, so F has many minima. The search samples the
//! box with a Halton sequence (`samples`, default 256·4^(dims−1) up to 16384, every point a
//! value-only sweep of the prepared kernel, [`SpectrumSweep`]), keeps the best `starts`
//! points that lie apart (more than 5 % of a range in some coordinate), and polishes each
//! with box-bounded Levenberg–Marquardt ([`super::lm`]) on the exact gradient: the
//! thickness and index derivatives of R/T from [`crate::jacobian::sweep_jacobian`], carried
//! through the spectral sum, CIELAB and ΔE2000 ([`crate::jacobian::colour_jacobian`],
//! [`crate::jacobian::lab_jacobian`], [`crate::jacobian::delta_e_2000_param_gradient`]).
//! The polished minima, sorted by F, give up to `solutions` distinct stacks: two are the
//! same when every free thickness differs by at most `distinct_nm` and every free index by
//! at most [`DISTINCT_INDEX`].
//!
//! Samples and polishes run in parallel in fixed chunks: the results do not depend on the
//! thread count.

use super::lm::{self, LmOptions, Residuals};
use super::spectrum::Quantity;
use super::template::{FreeKind, Template};
use super::{PRIMES, Steps, Watch, halton};
use crate::colour::{Colorimeter, delta_e_2000, xyz_to_lab};
use crate::error::{Error, Result};
use crate::jacobian::{Wrt, colour_jacobian, delta_e_2000_param_gradient, lab_jacobian};
use crate::power::Power;
use crate::spectral::SpectralRule;
use crate::spectrum_sweep::SpectrumSweep;
use crate::{C64, Stack};
use rayon::prelude::*;

/// Two solutions whose free indices all differ by at most this are the same (with their
/// thicknesses within the distinctness tolerance).
pub const DISTINCT_INDEX: f64 = 0.02;

/// A target is reached when every row's ΔE2000 is at most this.
pub const REACHED_DELTA_E: f64 = 1.0;

/// Halton samples evaluated per parallel task (a function of the problem only).
const SAMPLE_CHUNK: usize = 64;

/// One target row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColourTarget {
    /// Incidence angle in the ambient, degrees.
    pub angle_deg: f64,
    /// CIELAB under the colorimeter's illuminant.
    pub lab: [f64; 3],
    /// Weight (> 0).
    pub weight: f64,
}

/// Search settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColourSettings {
    /// Reflected or transmitted colour.
    pub quantity: Quantity,
    /// Halton samples of the box (0: 256·4^(dims−1), at most 16384).
    pub samples: usize,
    /// Local polishes from the best samples.
    pub starts: usize,
    /// Most distinct solutions returned.
    pub solutions: usize,
    /// Thickness tolerance of distinctness, nm.
    pub distinct_nm: f64,
}

impl Default for ColourSettings {
    fn default() -> Self {
        ColourSettings {
            quantity: Quantity::Reflectance,
            samples: 0,
            starts: 16,
            solutions: 1,
            distinct_nm: 10.0,
        }
    }
}

/// A designed stack.
#[derive(Clone, Debug, PartialEq)]
pub struct ColourSolution {
    /// The free parameters (the template's order).
    pub x: Vec<f64>,
    /// Achieved CIELAB per target row (by the fit's rule).
    pub lab: Vec<[f64; 3]>,
    /// ΔE2000 per target row.
    pub delta_e: Vec<f64>,
    /// F(x) = Σ wᵢ ΔE₀₀ᵢ².
    pub cost: f64,
    /// Levenberg–Marquardt iterations of its polish.
    pub iterations: usize,
}

impl ColourSolution {
    /// The largest ΔE2000 over the rows.
    pub fn max_delta_e(&self) -> f64 {
        self.delta_e.iter().copied().fold(0.0, f64::max)
    }
}

/// What a design found.
#[derive(Clone, Debug, PartialEq)]
pub struct ColourFit {
    /// Distinct solutions, best (lowest F) first; at least one.
    pub solutions: Vec<ColourSolution>,
    /// Halton samples evaluated.
    pub samples: usize,
    /// Local polishes run.
    pub starts: usize,
}

/// The prepared evaluation: angles, rule, XYZ weights.
struct Model<'a> {
    template: &'a Template,
    targets: &'a [ColourTarget],
    quantity: Quantity,
    colorimeter: &'a Colorimeter,
    angles_deg: Vec<f64>,
    /// Per row: its angle's index in `angles_deg`.
    row_angle: Vec<usize>,
    wavelengths_nm: Vec<f64>,
    xyz_weights: Vec<[f64; 3]>,
}

impl<'a> Model<'a> {
    fn new(
        template: &'a Template,
        targets: &'a [ColourTarget],
        colorimeter: &'a Colorimeter,
        quantity: Quantity,
    ) -> Result<Self> {
        let mut angles_deg: Vec<f64> = targets.iter().map(|t| t.angle_deg).collect();
        angles_deg.sort_by(f64::total_cmp);
        angles_deg.dedup();
        let row_angle = targets
            .iter()
            .map(|t| {
                angles_deg
                    .iter()
                    .position(|&a| a == t.angle_deg)
                    .unwrap_or(0)
            })
            .collect();
        let hi: Vec<f64> = template.free().iter().map(|f| f.hi).collect();
        let widest = template.stack_at(&hi)?;
        let rule =
            SpectralRule::for_stack(colorimeter, &widest, &angles_deg, widest.max_opd_nm(None))?;
        let xyz_weights = rule
            .weights()
            .iter()
            .map(|&w| colorimeter.xyz_from_output(w))
            .collect();
        Ok(Model {
            template,
            targets,
            quantity,
            colorimeter,
            angles_deg,
            row_angle,
            wavelengths_nm: rule.wavelengths_nm().to_vec(),
            xyz_weights,
        })
    }

    fn value(&self, p: &Power) -> f64 {
        match self.quantity {
            Quantity::Reflectance => p.R(),
            Quantity::Transmittance => p.T(),
        }
    }

    fn sweep(&self) -> Result<SpectrumSweep> {
        SpectrumSweep::new(
            self.template.stack(),
            &self.angles_deg,
            &self.wavelengths_nm,
        )
    }

    /// CIELAB per angle at `x`, through the prepared `sweep`.
    fn labs(
        &self,
        sweep: &mut SpectrumSweep,
        x: &[f64],
        powers: &mut Vec<Power>,
    ) -> Result<Vec<[f64; 3]>> {
        let mut d = self.template.stack().thicknesses_nm();
        for (f, &v) in self.template.free().iter().zip(x) {
            match f.kind {
                FreeKind::ThicknessNm => d[f.layer - 1] = v,
                FreeKind::Index => sweep.set_film_index(f.layer, C64::new(v, 0.0))?,
            }
        }
        sweep.set_thicknesses_nm(&d)?;
        powers.resize(sweep.len(), Power::default());
        sweep.powers_into(powers)?;
        let nw = self.wavelengths_nm.len();
        let white = self.colorimeter.white_xyz();
        Ok((0..self.angles_deg.len())
            .map(|a| {
                let mut xyz = [0.0; 3];
                for (p, w) in powers[a * nw..(a + 1) * nw].iter().zip(&self.xyz_weights) {
                    let v = self.value(p);
                    for c in 0..3 {
                        xyz[c] += v * w[c];
                    }
                }
                xyz_to_lab(xyz, white)
            })
            .collect())
    }

    fn delta_es(&self, labs: &[[f64; 3]]) -> Vec<f64> {
        self.targets
            .iter()
            .zip(&self.row_angle)
            .map(|(t, &a)| delta_e_2000(t.lab, labs[a]))
            .collect()
    }

    fn cost(&self, delta_e: &[f64]) -> f64 {
        self.targets
            .iter()
            .zip(delta_e)
            .map(|(t, e)| t.weight * e * e)
            .sum()
    }
}

/// The least-squares problem of one polish.
struct Problem<'m, 'a> {
    model: &'m Model<'a>,
    sweep: SpectrumSweep,
    powers: Vec<Power>,
    wrt: Wrt,
}

impl Residuals for Problem<'_, '_> {
    fn len(&self) -> usize {
        self.model.targets.len()
    }

    fn residuals(&mut self, x: &[f64], out: &mut [f64]) -> Result<()> {
        let labs = self.model.labs(&mut self.sweep, x, &mut self.powers)?;
        for ((o, t), &a) in out
            .iter_mut()
            .zip(self.model.targets)
            .zip(&self.model.row_angle)
        {
            *o = t.weight.sqrt() * delta_e_2000(t.lab, labs[a]);
        }
        Ok(())
    }

    fn jacobian(&mut self, x: &[f64], _lo: &[f64], _hi: &[f64], jac: &mut [f64]) -> Result<()> {
        let m = self.model;
        let stack: Stack = m.template.stack_at(x)?;
        let sj =
            crate::jacobian::sweep_jacobian(&stack, &m.angles_deg, &m.wavelengths_nm, self.wrt)?;
        let dims = x.len();
        let (nw, films) = (m.wavelengths_nm.len(), sj.films);
        let mut values = vec![0.0; nw];
        let mut derivatives = vec![0.0; nw * dims];
        for a in 0..m.angles_deg.len() {
            for k in 0..nw {
                let e = a * nw + k;
                values[k] = m.value(&sj.power[e]);
                for (p, f) in m.template.free().iter().enumerate() {
                    let slot = e * films + f.layer - 1;
                    let d = match f.kind {
                        FreeKind::ThicknessNm => &sj.d_thickness[slot],
                        FreeKind::Index => &sj.d_index_re[slot],
                    };
                    derivatives[k * dims + p] = m.value(d);
                }
            }
            let xyz = colour_jacobian(&m.xyz_weights, &values, &derivatives, dims);
            let lab = lab_jacobian(&xyz, m.colorimeter.white_xyz());
            for (i, t) in m.targets.iter().enumerate() {
                if m.row_angle[i] != a {
                    continue;
                }
                let (_, g) = delta_e_2000_param_gradient(t.lab, &lab);
                let s = t.weight.sqrt();
                for (p, gp) in g.iter().enumerate() {
                    jac[i * dims + p] = s * gp;
                }
            }
        }
        Ok(())
    }
}

/// Designs `template`'s free parameters so that its colour matches `targets` (see the
/// module docs). Errors: no target, a target angle outside (−90°, 90°), a weight that is
/// not positive and finite, a Lab value that is not finite, and what the stack refuses
/// (a material without data in 360–830 nm).
pub fn fit_colour(
    template: &Template,
    targets: &[ColourTarget],
    colorimeter: &Colorimeter,
    settings: &ColourSettings,
) -> Result<ColourFit> {
    fit_colour_watched(template, targets, colorimeter, settings, Watch::none())
}

/// [`fit_colour`] reporting its steps to `watch` and stopping with
/// [`Error::FitCancelled`] once its cancel flag is set: the steps are the chunks of
/// [`SAMPLE_CHUNK`] samples, then the polishes. The result is [`fit_colour`]'s.
pub fn fit_colour_watched(
    template: &Template,
    targets: &[ColourTarget],
    colorimeter: &Colorimeter,
    settings: &ColourSettings,
    watch: Watch<'_>,
) -> Result<ColourFit> {
    if targets.is_empty() {
        return Err(Error::FitData {
            message: "no target colour to fit".into(),
        });
    }
    for (i, t) in targets.iter().enumerate() {
        if !(t.weight > 0.0 && t.weight.is_finite()) {
            return Err(Error::FitData {
                message: format!("target {}: weight {} must be positive", i + 1, t.weight),
            });
        }
        if !t.lab.iter().all(|v| v.is_finite()) || !t.angle_deg.is_finite() {
            return Err(Error::FitData {
                message: format!("target {}: values must be finite numbers", i + 1),
            });
        }
    }
    template.stack().require_coherent("a colour design")?;
    let model = Model::new(template, targets, colorimeter, settings.quantity)?;
    let dims = template.dims();
    let lo: Vec<f64> = template.free().iter().map(|f| f.lo).collect();
    let hi: Vec<f64> = template.free().iter().map(|f| f.hi).collect();
    let wrt = if template.free().iter().any(|f| f.kind == FreeKind::Index) {
        Wrt::ThicknessAndIndex
    } else {
        Wrt::Thickness
    };
    let polish = |x0: &[f64]| -> Result<ColourSolution> {
        let mut problem = Problem {
            model: &model,
            sweep: model.sweep()?,
            powers: Vec::new(),
            wrt,
        };
        let r = lm::minimize(&mut problem, x0, &lo, &hi, LmOptions::default())?;
        let labs = model.labs(&mut problem.sweep, &r.x, &mut problem.powers)?;
        let delta_e = model.delta_es(&labs);
        Ok(ColourSolution {
            cost: model.cost(&delta_e),
            lab: model.row_angle.iter().map(|&a| labs[a]).collect(),
            delta_e,
            x: r.x,
            iterations: r.iterations,
        })
    };
    if dims == 0 {
        let steps = Steps::new(watch, 1);
        steps.check()?;
        let solution = polish(&[])?;
        steps.step();
        return Ok(ColourFit {
            solutions: vec![solution],
            samples: 0,
            starts: 1,
        });
    }
    let samples = if settings.samples > 0 {
        settings.samples
    } else {
        (256usize << (2 * (dims - 1).min(6))).min(16384)
    };
    let point = |i: usize| -> Vec<f64> {
        (0..dims)
            .map(|k| lo[k] + (hi[k] - lo[k]) * halton(i + 1, PRIMES[k % PRIMES.len()]))
            .collect()
    };
    let want = settings.starts.max(settings.solutions).max(1);
    let chunks = samples.div_ceil(SAMPLE_CHUNK);
    let steps = Steps::new(watch, chunks + want);
    // Value-only costs of the samples, in fixed chunks.
    let costs: Vec<f64> = (0..chunks)
        .into_par_iter()
        .map(|c| -> Result<Vec<f64>> {
            steps.check()?;
            let mut sweep = model.sweep()?;
            let mut powers = Vec::new();
            let chunk = (c * SAMPLE_CHUNK..((c + 1) * SAMPLE_CHUNK).min(samples))
                .map(|i| {
                    let labs = model.labs(&mut sweep, &point(i), &mut powers)?;
                    Ok(model.cost(&model.delta_es(&labs)))
                })
                .collect();
            steps.step();
            chunk
        })
        .collect::<Result<Vec<Vec<f64>>>>()?
        .into_iter()
        .flatten()
        .collect();
    let mut order: Vec<usize> = (0..samples).collect();
    order.sort_by(|&a, &b| costs[a].total_cmp(&costs[b]).then(a.cmp(&b)));
    // The best samples that lie apart.
    let mut starts: Vec<Vec<f64>> = Vec::with_capacity(want);
    for &i in &order {
        if starts.len() == want {
            break;
        }
        let x = point(i);
        let apart = starts
            .iter()
            .all(|s| (0..dims).any(|k| (s[k] - x[k]).abs() > 0.05 * (hi[k] - lo[k])));
        if apart {
            starts.push(x);
        }
    }
    steps.set_total(chunks + starts.len());
    let mut polished = starts
        .par_iter()
        .map(|x0| {
            steps.check()?;
            let solution = polish(x0)?;
            steps.step();
            Ok(solution)
        })
        .collect::<Result<Vec<_>>>()?;
    polished.sort_by(|a, b| a.cost.total_cmp(&b.cost));
    let same = |a: &ColourSolution, b: &ColourSolution| {
        template.free().iter().enumerate().all(|(k, f)| {
            let tol = match f.kind {
                FreeKind::ThicknessNm => settings.distinct_nm,
                FreeKind::Index => DISTINCT_INDEX,
            };
            (a.x[k] - b.x[k]).abs() <= tol
        })
    };
    let n_starts = polished.len();
    let mut solutions: Vec<ColourSolution> = Vec::new();
    for s in polished {
        if solutions.len() >= settings.solutions.max(1) {
            break;
        }
        if let Some(best) = solutions.first() {
            // An alternative must reach the look as well as the best does.
            let bar = REACHED_DELTA_E.max(best.max_delta_e());
            if s.max_delta_e() > bar || solutions.iter().any(|o| same(o, &s)) {
                continue;
            }
        }
        solutions.push(s);
    }
    Ok(ColourFit {
        solutions,
        samples,
        starts: n_starts,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::{Illuminant, Observer, OutputSpace, RgbSpace};
    use crate::fit::template::Free;
    use crate::{Layer, Material};

    fn template(free: Vec<Free>) -> Template {
        let m = |n: f64| Material::constant(format!("{n}"), C64::new(n, 0.0)).unwrap();
        let stack = Stack::new(
            m(1.0),
            vec![
                Layer {
                    material: m(2.3),
                    thickness_nm: 100.0,
                },
                Layer {
                    material: m(1.46),
                    thickness_nm: 100.0,
                },
            ],
            m(1.52),
        )
        .unwrap();
        Template::new(stack, free).unwrap()
    }

    fn thickness(layer: usize, lo: f64, hi: f64) -> Free {
        Free {
            layer,
            kind: FreeKind::ThicknessNm,
            lo,
            hi,
        }
    }

    fn colorimeter() -> Colorimeter {
        Colorimeter::new(
            Observer::Cie1931_2Deg,
            Illuminant::D65,
            OutputSpace::Rgb(RgbSpace::Srgb),
        )
    }

    /// The targets of the template at `x` (by the model's own rule).
    fn targets_of(t: &Template, x: &[f64], angles: &[f64]) -> Vec<ColourTarget> {
        let c = colorimeter();
        let stack = t.stack_at(x).unwrap();
        angles
            .iter()
            .map(|&a| {
                let rule = SpectralRule::for_stack(&c, &stack, &[a], 4.0 * stack.max_opd_nm(None))
                    .unwrap();
                let p = stack.sweep(&[a], rule.wavelengths_nm()).unwrap();
                let rgb = rule.colour(p.iter().map(|p| p.R()));
                ColourTarget {
                    angle_deg: a,
                    lab: xyz_to_lab(c.xyz_from_output(rgb), c.white_xyz()),
                    weight: 1.0,
                }
            })
            .collect()
    }

    #[test]
    fn a_reachable_two_film_look_is_found() {
        let t = template(vec![thickness(1, 20.0, 300.0), thickness(2, 20.0, 300.0)]);
        let truth = [137.0, 211.0];
        let targets = targets_of(&t, &truth, &[0.0, 30.0, 60.0]);
        let fit = fit_colour(&t, &targets, &colorimeter(), &ColourSettings::default()).unwrap();
        let best = &fit.solutions[0];
        assert!(best.max_delta_e() < 0.5, "{best:?}");
        assert!(
            best.x
                .iter()
                .zip(&lo_hi(&t))
                .all(|(x, (l, h))| x >= l && x <= h)
        );
    }

    fn lo_hi(t: &Template) -> Vec<(f64, f64)> {
        t.free().iter().map(|f| (f.lo, f.hi)).collect()
    }

    #[test]
    fn the_gradient_matches_finite_differences() {
        let t = template(vec![
            Free {
                layer: 1,
                kind: FreeKind::Index,
                lo: 1.8,
                hi: 2.5,
            },
            thickness(1, 20.0, 300.0),
            thickness(2, 20.0, 300.0),
        ]);
        let targets = targets_of(&t, &[2.2, 150.0, 90.0], &[0.0, 45.0]);
        let c = colorimeter();
        let model = Model::new(&t, &targets, &c, Quantity::Reflectance).unwrap();
        let mut p = Problem {
            model: &model,
            sweep: model.sweep().unwrap(),
            powers: Vec::new(),
            wrt: Wrt::ThicknessAndIndex,
        };
        let x = [2.0, 120.0, 200.0];
        let mut jac = vec![0.0; 2 * 3];
        p.jacobian(&x, &[], &[], &mut jac).unwrap();
        for k in 0..3 {
            let h = if k == 0 { 1e-6 } else { 1e-4 };
            let (mut up, mut down) = (x, x);
            up[k] += h;
            down[k] -= h;
            let (mut ru, mut rd) = ([0.0; 2], [0.0; 2]);
            p.residuals(&up, &mut ru).unwrap();
            p.residuals(&down, &mut rd).unwrap();
            for i in 0..2 {
                let fd = (ru[i] - rd[i]) / (2.0 * h);
                let exact = jac[i * 3 + k];
                assert!(
                    (fd - exact).abs() <= 1e-5 * exact.abs().max(1.0),
                    "row {i} param {k}: {exact} vs {fd}"
                );
            }
        }
    }

    #[test]
    fn distinct_solutions_differ_and_an_unreachable_look_says_how_far() {
        let t = template(vec![thickness(1, 20.0, 600.0)]);
        let targets = targets_of(&t, &[300.0], &[0.0, 40.0]);
        let settings = ColourSettings {
            solutions: 3,
            ..ColourSettings::default()
        };
        let fit = fit_colour(&t, &targets, &colorimeter(), &settings).unwrap();
        assert!(
            (fit.solutions[0].x[0] - 300.0).abs() < 2.0,
            "{:?}",
            fit.solutions[0]
        );
        for (i, a) in fit.solutions.iter().enumerate() {
            for b in &fit.solutions[i + 1..] {
                assert!((a.x[0] - b.x[0]).abs() > settings.distinct_nm);
            }
        }
        // Saturated green at normal incidence is beyond a weak single film.
        let far = [ColourTarget {
            angle_deg: 0.0,
            lab: [60.0, -80.0, 60.0],
            weight: 1.0,
        }];
        let fit = fit_colour(&t, &far, &colorimeter(), &ColourSettings::default()).unwrap();
        assert!(fit.solutions[0].max_delta_e() > 10.0);
        assert!(fit_colour(&t, &[], &colorimeter(), &settings).is_err());
    }

    /// A watched design reports every sample chunk and polish and gives the plain
    /// design's result; a set cancel flag stops it.
    #[test]
    fn a_watched_design_reports_and_cancels() {
        use std::sync::Mutex;
        use std::sync::atomic::{AtomicBool, Ordering};
        let t = template(vec![thickness(1, 20.0, 600.0)]);
        let targets = targets_of(&t, &[300.0], &[0.0, 40.0]);
        let settings = ColourSettings::default();
        let plain = fit_colour(&t, &targets, &colorimeter(), &settings).unwrap();
        let seen = Mutex::new(Vec::new());
        let progress = |done: usize, total: usize| seen.lock().unwrap().push((done, total));
        let cancel = AtomicBool::new(false);
        let watch = Watch {
            progress: &progress,
            cancel: &cancel,
        };
        let watched = fit_colour_watched(&t, &targets, &colorimeter(), &settings, watch).unwrap();
        assert_eq!(watched, plain);
        let seen = seen.lock().unwrap().clone();
        // 256 samples in chunks of 64, then the polishes.
        let total = 256 / SAMPLE_CHUNK + plain.starts;
        assert_eq!(seen.len(), total, "{seen:?}");
        assert!(
            seen.iter().any(|&(d, t)| (d, t) == (total, total)),
            "{seen:?}"
        );
        cancel.store(true, Ordering::Relaxed);
        let e = fit_colour_watched(&t, &targets, &colorimeter(), &settings, watch).unwrap_err();
        assert!(matches!(e, Error::FitCancelled { done: 0, .. }), "{e}");
    }
}
