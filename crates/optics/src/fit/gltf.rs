//! The closest `KHR_materials_iridescence` film to a colour target: glTF's reference
//! evaluation of a material with iridescence ([`GltfFilm::reflectance_rec709`]) and a fit of
//! its few parameters to target colours over angle (and over a thickness texture's range).
//!
//! The model, from the glTF extensions' specifications (`KHR_materials_iridescence`,
//! `KHR_materials_ior`, glTF 2.0 Appendix B): the base's normal-incidence reflectance is
//!
//! ```text
//! F0 = ((ior − 1)/(ior + 1))²  (white)      dielectric base, KHR_materials_ior
//! F0 = baseColorFactor.rgb                  metallic = 1
//! ```
//!
//! the thickness is `mix(iridescenceThicknessMinimum, iridescenceThicknessMaximum, t)` with
//! `t` the thickness texture's value (no texture: t = 1), the film term `I(θ)` is Belcour &
//! Barla 2017's Gaussian-fit closed form ([`crate::fourier::gltf_iridescence`], outside
//! index 1), and the specular reflectance is
//!
//! ```text
//! F(θ) = mix(F_Schlick(F0, cos θ), I(θ), iridescenceFactor)
//! F_Schlick(F0, cos θ) = F0 + (1 − F0)(1 − cos θ)⁵
//! ```
//!
//! The fit minimises the mean CIEDE2000 difference ([`crate::colour::delta_e_2000`])
//! between `F` and the targets: a grid over (iridescenceIor, thickness minimum, thickness
//! maximum) with the start's base, then the bounded Nelder–Mead simplex
//! ([`super::nelder_mead`]) over every free parameter from the best grid points and from the
//! start. Deterministic: the grid and the starts are fixed, each start's polish is serial.

use super::nelder_mead::{self, Options};
use crate::colour::{Colorimeter, OutputSpace, RgbSpace, delta_e_2000, xyz_to_lab};
use crate::elementary;
use crate::fourier::gltf_iridescence;
use rayon::prelude::*;

/// The base under the film.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GltfBase {
    /// A dielectric of index `ior` (`KHR_materials_ior`), metallic 0.
    Dielectric {
        /// `KHR_materials_ior.ior`.
        ior: f64,
    },
    /// A metal (metallic 1) whose normal-incidence reflectance is `base_colour` (linear
    /// Rec.709, `baseColorFactor`).
    Metal {
        /// `baseColorFactor.rgb`.
        base_colour: [f64; 3],
    },
}

/// The parameters of a glTF material with `KHR_materials_iridescence`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltfFilm {
    /// `iridescenceIor`.
    pub iridescence_ior: f64,
    /// `iridescenceThicknessMinimum`, nm (the thickness where the texture reads 0).
    pub thickness_min_nm: f64,
    /// `iridescenceThicknessMaximum`, nm (the thickness where the texture reads 1, and
    /// everywhere without a texture).
    pub thickness_max_nm: f64,
    /// `iridescenceFactor`.
    pub factor: f64,
    /// The base.
    pub base: GltfBase,
}

impl GltfFilm {
    /// The base's normal-incidence reflectance F0 (linear Rec.709).
    pub fn base_f0(&self) -> [f64; 3] {
        match self.base {
            GltfBase::Dielectric { ior } => {
                let r = (ior - 1.0) / (ior + 1.0);
                [r * r; 3]
            }
            GltfBase::Metal { base_colour } => base_colour,
        }
    }

    /// The film thickness at texture value `t` ∈ [0, 1]: `mix(minimum, maximum, t)`, nm.
    pub fn thickness_nm(&self, t: f64) -> f64 {
        self.thickness_min_nm + (self.thickness_max_nm - self.thickness_min_nm) * t
    }

    /// The specular reflectance `F(θ)` (linear Rec.709) at `cos_theta` and texture value `t`.
    pub fn reflectance_rec709(&self, cos_theta: f64, t: f64) -> [f64; 3] {
        let f0 = self.base_f0();
        let film = gltf_iridescence(
            1.0,
            self.iridescence_ior,
            cos_theta,
            self.thickness_nm(t),
            f0,
        );
        let m = (1.0 - cos_theta).clamp(0.0, 1.0);
        let m5 = m * m * m * m * m;
        std::array::from_fn(|i| {
            let schlick = f0[i] + (1.0 - f0[i]) * m5;
            schlick + (film[i] - schlick) * self.factor
        })
    }
}

/// One target colour: CIELAB (under `colorimeter`'s illuminant) at an angle and a texture
/// value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// Incidence angle, degrees.
    pub angle_deg: f64,
    /// Thickness texture value in [0, 1] (1 for a film of one thickness).
    pub t: f64,
    /// The colour to reach, CIELAB.
    pub lab: [f64; 3],
}

/// CIELAB of a colour `c` in `colorimeter`'s output space.
pub fn lab_of_output(colorimeter: &Colorimeter, c: [f64; 3]) -> [f64; 3] {
    xyz_to_lab(colorimeter.xyz_from_output(c), colorimeter.white_xyz())
}

/// CIELAB of a linear Rec.709 colour (glTF's working space), as `nacre color --method
/// gaussian` converts it: taken as the output colour when the output space is sRGB, else
/// through sRGB's primary matrix.
pub fn lab_of_rec709(colorimeter: &Colorimeter, rec709: [f64; 3]) -> [f64; 3] {
    let xyz = match colorimeter.space() {
        OutputSpace::Rgb(RgbSpace::Srgb) => colorimeter.xyz_from_output(rec709),
        _ => {
            let m = RgbSpace::Srgb.rgb_to_xyz_matrix();
            std::array::from_fn(|r| (0..3).map(|c| m[r][c] * rec709[c]).sum())
        }
    };
    xyz_to_lab(xyz, colorimeter.white_xyz())
}

/// ΔE2000 between a film and targets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    /// Mean over the targets.
    pub mean: f64,
    /// Largest.
    pub max: f64,
}

/// Each target's ΔE2000 against `film`.
pub fn delta_e_per_target(
    film: &GltfFilm,
    targets: &[Target],
    colorimeter: &Colorimeter,
) -> Vec<f64> {
    targets
        .iter()
        .map(|target| {
            let cos_theta = elementary::cos(target.angle_deg.to_radians());
            let c = film.reflectance_rec709(cos_theta, target.t);
            delta_e_2000(lab_of_rec709(colorimeter, c), target.lab)
        })
        .collect()
}

/// The mean and largest ΔE2000 of `film` against `targets` (zeros for no targets).
pub fn errors(film: &GltfFilm, targets: &[Target], colorimeter: &Colorimeter) -> Errors {
    let d = delta_e_per_target(film, targets, colorimeter);
    let n = d.len().max(1) as f64;
    Errors {
        mean: d.iter().sum::<f64>() / n,
        max: d.iter().copied().fold(0.0, f64::max),
    }
}

/// What the fit may change and within which bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setup {
    /// The first guess (the naive mapping); its base kind is kept.
    pub start: GltfFilm,
    /// Whether the thickness varies (minimum and maximum fitted apart); else one thickness,
    /// written to both.
    pub varies: bool,
    /// Whether `iridescenceFactor` is fitted (else kept at the start's).
    pub fit_factor: bool,
    /// Whether the base is fitted (else kept at the start's).
    pub fit_base: bool,
    /// `iridescenceIor` bounds.
    pub ior_bounds: (f64, f64),
    /// Thickness bounds, nm.
    pub thickness_bounds_nm: (f64, f64),
    /// A dielectric base's ior bounds.
    pub base_ior_bounds: (f64, f64),
}

impl Setup {
    /// Bounds that cover what glTF viewers accept and films show: `iridescenceIor`
    /// 1.0–3.0, thickness 0 to `max_thickness_nm`, base ior 1.0–4.0, base colour 0–1,
    /// factor 0–1; every parameter free.
    pub fn new(start: GltfFilm, varies: bool, max_thickness_nm: f64) -> Self {
        Setup {
            start,
            varies,
            fit_factor: true,
            fit_base: true,
            ior_bounds: (1.0, 3.0),
            thickness_bounds_nm: (0.0, max_thickness_nm),
            base_ior_bounds: (1.0, 4.0),
        }
    }

    /// Parameter vector: [ior, d_min, d_max, factor, b0, b1, b2].
    fn encode(&self, film: &GltfFilm) -> Vec<f64> {
        let b = match film.base {
            GltfBase::Dielectric { ior } => [ior, 0.0, 0.0],
            GltfBase::Metal { base_colour } => base_colour,
        };
        vec![
            film.iridescence_ior,
            film.thickness_min_nm,
            film.thickness_max_nm,
            film.factor,
            b[0],
            b[1],
            b[2],
        ]
    }

    fn decode(&self, x: &[f64]) -> GltfFilm {
        let base = match self.start.base {
            GltfBase::Dielectric { .. } => GltfBase::Dielectric { ior: x[4] },
            GltfBase::Metal { .. } => GltfBase::Metal {
                base_colour: [x[4], x[5], x[6]],
            },
        };
        GltfFilm {
            iridescence_ior: x[0],
            thickness_min_nm: if self.varies { x[1] } else { x[2] },
            thickness_max_nm: x[2],
            factor: x[3],
            base,
        }
    }

    /// Lower and upper bounds of the parameter vector (equal where fixed).
    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let s = self.encode(&self.start);
        let (t0, t1) = self.thickness_bounds_nm;
        let mut lo = vec![self.ior_bounds.0, t0, t0, 0.0, 0.0, 0.0, 0.0];
        let mut hi = vec![self.ior_bounds.1, t1, t1, 1.0, 1.0, 1.0, 1.0];
        let fix = |i: usize, lo: &mut Vec<f64>, hi: &mut Vec<f64>| {
            lo[i] = s[i];
            hi[i] = s[i];
        };
        if !self.varies {
            fix(1, &mut lo, &mut hi);
        }
        if !self.fit_factor {
            fix(3, &mut lo, &mut hi);
        }
        match self.start.base {
            GltfBase::Dielectric { .. } => {
                lo[4] = self.base_ior_bounds.0;
                hi[4] = self.base_ior_bounds.1;
                fix(5, &mut lo, &mut hi);
                fix(6, &mut lo, &mut hi);
            }
            GltfBase::Metal { .. } => {}
        }
        if !self.fit_base {
            for i in 4..7 {
                fix(i, &mut lo, &mut hi);
            }
        }
        (lo, hi)
    }
}

/// A fitted film.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// The film.
    pub film: GltfFilm,
    /// Its ΔE2000 against the targets.
    pub errors: Errors,
    /// Model evaluations spent (grid and polish; each evaluates every target).
    pub evaluations: usize,
}

/// Grid steps: iridescenceIor every 0.05 (one thickness) or 0.15 (a thickness range), the
/// thickness in 200 (one thickness) or 20 (each end of a range) steps over its bounds.
const GRID_IOR_STEP: [f64; 2] = [0.05, 0.15];
const GRID_THICKNESS_STEPS: [usize; 2] = [200, 20];
/// Starts polished from the grid's best points (plus the given start).
const POLISHED_STARTS: usize = 4;

/// Fits `setup`'s free parameters to `targets` (mean ΔE2000); see the module's notes.
pub fn fit(targets: &[Target], colorimeter: &Colorimeter, setup: &Setup) -> Fit {
    let (lo, hi) = setup.bounds();
    let objective = |x: &[f64]| errors(&setup.decode(x), targets, colorimeter).mean;
    let start = setup.encode(&setup.start);

    // The grid over (ior, d_min, d_max); the other parameters at the start's values.
    let v = usize::from(setup.varies);
    let ior_steps = ((hi[0] - lo[0]) / GRID_IOR_STEP[v]).round().max(0.0) as usize;
    let d_steps = GRID_THICKNESS_STEPS[v];
    let axis = |i: usize, steps: usize| -> Vec<f64> {
        if hi[i] > lo[i] && steps > 0 {
            (0..=steps)
                .map(|k| lo[i] + (hi[i] - lo[i]) * k as f64 / steps as f64)
                .collect()
        } else {
            vec![start[i]]
        }
    };
    let (iors, d_mins, d_maxs) = (axis(0, ior_steps), axis(1, d_steps), axis(2, d_steps));
    let mut grid: Vec<Vec<f64>> = Vec::with_capacity(iors.len() * d_mins.len() * d_maxs.len());
    for &n in &iors {
        for &d0 in &d_mins {
            for &d1 in &d_maxs {
                let mut x = start.clone();
                x[0] = n;
                x[1] = d0;
                x[2] = d1;
                grid.push(x);
            }
        }
    }
    let mut scored: Vec<(f64, usize)> = grid
        .par_iter()
        .enumerate()
        .map(|(i, x)| (objective(x), i))
        .collect();
    scored.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut starts = vec![start.clone()];
    starts.extend(
        scored
            .iter()
            .take(POLISHED_STARTS)
            .map(|&(_, i)| grid[i].clone()),
    );
    let options = Options {
        max_evaluations: 800,
        f_tolerance: 1e-7,
        x_tolerance: 1e-6,
        initial_step: 0.02,
    };
    let polished: Vec<nelder_mead::Minimum> = starts
        .par_iter()
        .map(|s| {
            // A restart from the first minimum leaves a collapsed simplex behind.
            let first = nelder_mead::minimize(objective, s, &lo, &hi, &options);
            let second = nelder_mead::minimize(objective, &first.x, &lo, &hi, &options);
            nelder_mead::Minimum {
                evaluations: first.evaluations + second.evaluations,
                ..if second.value <= first.value {
                    second
                } else {
                    first
                }
            }
        })
        .collect();
    let evaluations = grid.len() + polished.iter().map(|m| m.evaluations).sum::<usize>();
    let best = polished
        .into_iter()
        .min_by(|a, b| a.value.total_cmp(&b.value))
        .expect("at least the start");
    let film = setup.decode(&best.x);
    Fit {
        film,
        errors: errors(&film, targets, colorimeter),
        evaluations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn targets_of(film: &GltfFilm, ts: &[f64], colorimeter: &Colorimeter) -> Vec<Target> {
        let mut out = vec![];
        for &t in ts {
            for a in 0..18 {
                let angle_deg = 5.0 * a as f64;
                let c = film.reflectance_rec709(elementary::cos(angle_deg.to_radians()), t);
                out.push(Target {
                    angle_deg,
                    t,
                    lab: lab_of_rec709(colorimeter, c),
                });
            }
        }
        out
    }

    #[test]
    fn factor_zero_is_the_bare_base_and_one_the_film() {
        let film = GltfFilm {
            iridescence_ior: 1.3,
            thickness_min_nm: 100.0,
            thickness_max_nm: 400.0,
            factor: 0.0,
            base: GltfBase::Dielectric { ior: 1.5 },
        };
        for v in film.reflectance_rec709(1.0, 0.5) {
            assert!((v - 0.04).abs() < 1e-15, "{v}");
        }
        let one = GltfFilm {
            factor: 1.0,
            ..film
        };
        assert_eq!(
            one.reflectance_rec709(0.8, 0.5),
            gltf_iridescence(1.0, 1.3, 0.8, 250.0, [0.04; 3])
        );
    }

    #[test]
    fn a_gltf_film_fits_back_to_its_own_parameters() {
        let c = Colorimeter::srgb_d65();
        let truth = GltfFilm {
            iridescence_ior: 1.8,
            thickness_min_nm: 320.0,
            thickness_max_nm: 320.0,
            factor: 1.0,
            base: GltfBase::Dielectric { ior: 1.5 },
        };
        let targets = targets_of(&truth, &[1.0], &c);
        // Start from elsewhere: index 1.33, 500 nm, base 1.2.
        let start = GltfFilm {
            iridescence_ior: 1.33,
            thickness_min_nm: 500.0,
            thickness_max_nm: 500.0,
            base: GltfBase::Dielectric { ior: 1.2 },
            ..truth
        };
        let f = fit(&targets, &c, &Setup::new(start, false, 1000.0));
        assert!(f.errors.max < 0.05, "{f:?}");
        assert!((f.film.iridescence_ior - 1.8).abs() < 0.01, "{f:?}");
        assert!((f.film.thickness_max_nm - 320.0).abs() < 2.0, "{f:?}");
    }

    #[test]
    fn a_varying_gltf_film_on_metal_fits_back_to_its_own_parameters() {
        let c = Colorimeter::srgb_d65();
        let truth = GltfFilm {
            iridescence_ior: 2.2,
            thickness_min_nm: 150.0,
            thickness_max_nm: 450.0,
            factor: 1.0,
            base: GltfBase::Metal {
                base_colour: [0.55, 0.5, 0.45],
            },
        };
        let targets = targets_of(&truth, &[0.0, 0.25, 0.5, 0.75, 1.0], &c);
        let start = GltfFilm {
            iridescence_ior: 1.6,
            thickness_min_nm: 100.0,
            thickness_max_nm: 600.0,
            base: GltfBase::Metal {
                base_colour: [0.4; 3],
            },
            ..truth
        };
        let f = fit(&targets, &c, &Setup::new(start, true, 1000.0));
        assert!(f.errors.max < 0.1, "{f:?}");
        assert!((f.film.iridescence_ior - 2.2).abs() < 0.02, "{f:?}");
        assert!((f.film.thickness_min_nm - 150.0).abs() < 3.0, "{f:?}");
        assert!((f.film.thickness_max_nm - 450.0).abs() < 3.0, "{f:?}");
    }
}
