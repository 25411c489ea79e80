//! Few wavelengths, chosen well: the spectral rule of the real-time multilayer technique
//! (`film_stack` on the GPU, `nacre color --method stack` on the CPU).
//!
//! # Why uniform samples fail
//!
//! A stack's reflectance, as a function of vacuum wavenumber σ = 1/λ, is a sum of fringes
//! cos(2π Δ σ + φ) whose optical path differences Δ are the round trips through the films
//! and their combinations (Sussenbach 2013 §3.1; Belcour & Barla 2017 §3), times the smooth
//! dispersion of the materials. Its colour is C = ∫ R(λ) s(λ) dλ, s the output-space
//! sensitivity ([`Colorimeter::sensitivity_at`]). A fixed handful of samples
//! (the thesis's 5 uniform wavelengths, [`crate::spectral::sample_weights`]) integrates the
//! white exactly but gives every fringe the weight of whatever sample it happens to hit:
//! over the population of the issue's test (2–6 films, ≤ 2 µm optical thickness, dielectric
//! and metal films and bases, 0–85°) 5 samples are off by ΔE2000 21 at the 95th percentile,
//! 16 samples by 0.87 (max 7.6), 32 by 0.12 (max 2.2). No fixed count is right: thin stacks
//! waste samples and thick ones alias.
//!
//! # The rule
//!
//! **Nodes**: N wavelengths uniform in wavenumber over 400–700 nm (the midpoints of N equal
//! cells of σ; outside that band the sensitivities hold 0.3 % of the white), so that the
//! fringes of every OPD are sampled at the same phase step.
//!
//! **Weights**, per output channel c, fitted to the colour-matching functions: the rule
//! should integrate *every fringe* of OPD Δ ≤ Δ_fit as well as N weights can, in the
//! least-squares sense,
//!
//! ```text
//! minimise  Σ_k | Σ_j W_jc e^{2πi Δ_k σ_j} − F_c(Δ_k) |²  + ε Σ_j W_jc²
//! F_c(Δ) = ∫ s_c(λ) e^{2πi Δ/λ} dλ                 (the sensitivity's Fourier transform)
//! ```
//!
//! over Δ_k = k Δ_fit / K, k = 0 … K = max(64, 8N), with the white row (Δ = 0) weighted 10³
//! (R ≡ 1 gives the colorimeter's white to 10⁻⁶ relative) and a ridge ε = 10⁻⁹ × the mean
//! diagonal. F_c is integrated with [`SpectralRule`] (resolved for Δ_fit). This is Belcour
//! & Barla's observation (§4: a fringe's colour is the Fourier transform of the sensitivity
//! at its OPD) turned into a quadrature. N uniform nodes cannot tell Δ from Δ + 1/δσ (δσ the
//! node spacing, (N − 1) δσ ≈ B = 1/400 − 1/700 nm⁻¹), so the fit stops at
//! Δ_fit = 0.6 (N − 1)/B ([`FIT_FRACTION`]); fringes above it are small because F_c decays
//! with Δ.
//!
//! **Count**, from the stack: thicker stacks fringe faster. With Δ_stack = Σ_j 2 d_j |ñ_j| the
//! stack's largest round-trip OPD ([`crate::Stack::max_opd_nm`]),
//!
//! ```text
//! N = ⌈12 + 0.0108 Δ_stack / nm⌉, rounded up to the ladder 12, 14, 16, 20, 24, 28, 32, 40, 48, 56, 64
//! ```
//!
//! ([`count_for_opd`], [`RuleLadder`]). The constant 12 covers the metals' own spectral
//! features (gold's absorption edge is a fringe of Δ ≈ 6 µm), the slope about 8 samples per
//! unit of Δ·(1/380 − 1/780 nm⁻¹), both found by a sweep (test
//! `error_against_sample_count`, ignored; its figures are in BENCHMARKS.md).
//!
//! # Error
//!
//! Over 2000 random stacks of the issue's population against the exact integration
//! ([`SpectralRule`]), test `stack_rule_meets_the_targets`: see the figures it prints and
//! BENCHMARKS.md; the targets are ΔE2000 p95 ≤ 0.3 and max ≤ 1.0.

use crate::colour::Colorimeter;
use crate::elementary;
use crate::spectral::SpectralRule;
use std::f64::consts::PI;

/// Shortest wavelength of the nodes' band, nm.
pub const BAND_MIN_NM: f64 = 400.0;
/// Longest wavelength of the nodes' band, nm.
pub const BAND_MAX_NM: f64 = 700.0;
/// Δ_fit = FIT_FRACTION · (N − 1)/B: how far towards the aliasing limit the weights are fitted.
pub const FIT_FRACTION: f64 = 0.6;
/// The sample counts a [`RuleLadder`] holds.
pub const LADDER: [usize; 13] = [12, 14, 16, 20, 24, 28, 32, 40, 48, 56, 64, 80, 96];
/// Samples for the metals' own spectral features (N at Δ_stack = 0).
pub const BASE_COUNT: f64 = 12.0;
/// Samples per nm of Δ_stack.
pub const COUNT_PER_OPD_NM: f64 = 0.0108;

/// Width of the nodes' band in wavenumber B, nm⁻¹.
pub fn band_wavenumber() -> f64 {
    1.0 / BAND_MIN_NM - 1.0 / BAND_MAX_NM
}

/// N nodes uniform in wavenumber over [`BAND_MIN_NM`]–[`BAND_MAX_NM`] (cell midpoints),
/// wavelengths increasing.
pub fn uniform_wavenumber_nodes(count: usize) -> Vec<f64> {
    let (hi, b) = (1.0 / BAND_MIN_NM, band_wavenumber());
    let mut nodes: Vec<f64> = (0..count)
        .map(|j| 1.0 / (hi - (j as f64 + 0.5) * b / count as f64))
        .collect();
    nodes.sort_by(f64::total_cmp);
    nodes
}

/// The sample count for a stack whose largest round-trip OPD is `opd_nm`:
/// ⌈[`BASE_COUNT`] + [`COUNT_PER_OPD_NM`] Δ⌉ rounded up to the [`LADDER`] (its last entry
/// beyond). NaN and negative OPDs count as 0.
pub fn count_for_opd(opd_nm: f64) -> usize {
    let opd_nm = if opd_nm > 0.0 { opd_nm } else { 0.0 };
    let needed = (BASE_COUNT + COUNT_PER_OPD_NM * opd_nm).ceil();
    LADDER
        .iter()
        .copied()
        .find(|&n| n as f64 >= needed)
        .unwrap_or(LADDER[LADDER.len() - 1])
}

/// Most round trips a cavity's fringes are counted with ([`finesse_factor`]).
pub const MAX_ROUND_TRIPS: f64 = 3.0;

/// The factor h by which a stack's round-trip OPD is multiplied before [`count_for_opd`]:
/// a cavity between two interfaces of reflection amplitudes |r_a|, |r_b| adds harmonics of
/// its fringe decaying as ρᵏ, ρ = |r_a| |r_b| (the Airy series, Born & Wolf §7.6.1), so its
/// spectrum reaches about 1/(1 − ρ) times its OPD: h = min(1/(1 − ρ), [`MAX_ROUND_TRIPS`]),
/// ρ the product of the two largest interface amplitudes at normal incidence and 550 nm
/// (`indices`: ambient, films, substrate at 550 nm). A metal–dielectric–metal filter has
/// ρ ≈ 0.95 and the largest h; a dielectric stack h ≈ 1.
pub fn finesse_factor(indices: &[crate::C64]) -> f64 {
    let mut r: Vec<f64> = indices
        .windows(2)
        .map(|p| elementary::norm((p[0] - p[1]) / (p[0] + p[1])))
        .filter(|x| x.is_finite())
        .collect();
    r.sort_by(|a, b| b.total_cmp(a));
    let rho = match r.as_slice() {
        [a, b, ..] => (a * b).min(1.0),
        _ => 0.0,
    };
    if rho >= 1.0 - 1.0 / MAX_ROUND_TRIPS {
        MAX_ROUND_TRIPS
    } else {
        1.0 / (1.0 - rho)
    }
}

/// The OPD a stack's rule is chosen for: Δ_stack × [`finesse_factor`], Δ_stack =
/// [`crate::Stack::max_opd_nm`] (indices at 550 nm; a material without data there counts
/// as n = 1).
pub fn stack_rule_opd_nm(stack: &crate::Stack) -> f64 {
    let indices: Vec<crate::C64> = std::iter::once(stack.ambient())
        .chain(stack.layers().iter().map(|l| &l.material))
        .chain(std::iter::once(stack.substrate()))
        .map(|m| m.index_at(550.0).unwrap_or(crate::C64::new(1.0, 0.0)))
        .collect();
    stack.max_opd_nm(None) * finesse_factor(&indices)
}

/// A rule of a few wavelengths: colour = Σ_j f(λ_j) W_j.
#[derive(Clone, Debug, PartialEq)]
pub struct FewWavelengthRule {
    wavelengths_nm: Vec<f64>,
    weights: Vec<[f64; 3]>,
    fit_opd_nm: f64,
}

impl FewWavelengthRule {
    /// The rule of `count` nodes (≥ 1; module docs): uniform in wavenumber, weights fitted
    /// up to Δ_fit = [`FIT_FRACTION`] (N − 1)/B.
    pub fn new(colorimeter: &Colorimeter, count: usize) -> Self {
        let count = count.max(1);
        let fit_opd_nm = FIT_FRACTION * (count as f64 - 1.0) / band_wavenumber();
        Self::fit_nodes(colorimeter, uniform_wavenumber_nodes(count), fit_opd_nm)
    }

    /// The least-squares weights of `nodes` (wavelengths, nm) for fringes up to
    /// `fit_opd_nm` (module docs).
    pub fn fit_nodes(colorimeter: &Colorimeter, nodes: Vec<f64>, fit_opd_nm: f64) -> Self {
        let count = nodes.len();
        let fit_opd_nm = fit_opd_nm.max(0.0);
        let reference = SpectralRule::new(colorimeter, fit_opd_nm);
        let rows = (8 * count).max(64);
        // Rows: (weight, Δ) for Δ_k = k Δ_fit / K; the white row weighted 10³.
        let opds: Vec<(f64, f64)> = (0..=rows)
            .map(|k| {
                let w = if k == 0 { 1e3 } else { 1.0 };
                (w, fit_opd_nm * k as f64 / rows as f64)
            })
            .collect();
        // Normal equations per channel: (AᵀA + εI) W = Aᵀ b, A's rows the real and
        // imaginary parts of e^{2πiΔσ_j} (one row for Δ = 0).
        let mut ata = vec![0.0; count * count];
        let mut atb = vec![[0.0; 3]; count];
        for &(w, opd) in &opds {
            let parts: &[fn(f64) -> f64] = if opd == 0.0 {
                &[elementary::cos]
            } else {
                &[elementary::cos, elementary::sin]
            };
            for part in parts {
                let a: Vec<f64> = nodes
                    .iter()
                    .map(|&l| w * part(2.0 * PI * opd / l))
                    .collect();
                let mut b = [0.0; 3];
                for (&l, s) in reference.wavelengths_nm().iter().zip(reference.weights()) {
                    let v = part(2.0 * PI * opd / l);
                    for c in 0..3 {
                        b[c] += v * s[c];
                    }
                }
                for (i, &ai) in a.iter().enumerate() {
                    for (j, &aj) in a.iter().enumerate() {
                        ata[i * count + j] += ai * aj;
                    }
                    for c in 0..3 {
                        atb[i][c] += ai * w * b[c];
                    }
                }
            }
        }
        let mean_diag = (0..count).map(|i| ata[i * count + i]).sum::<f64>() / count as f64;
        for i in 0..count {
            ata[i * count + i] += 1e-9 * mean_diag;
        }
        let weights = solve_spd(&ata, &atb, count);
        FewWavelengthRule {
            wavelengths_nm: nodes,
            weights,
            fit_opd_nm,
        }
    }

    /// The node wavelengths, nm, increasing.
    pub fn wavelengths_nm(&self) -> &[f64] {
        &self.wavelengths_nm
    }

    /// The weights W_j (output space, per node).
    pub fn weights(&self) -> &[[f64; 3]] {
        &self.weights
    }

    /// The largest OPD the rule was fitted for, nm.
    pub fn fit_opd_nm(&self) -> f64 {
        self.fit_opd_nm
    }

    /// Σ_j values\[j\] W_j.
    pub fn colour(&self, values: impl IntoIterator<Item = f64>) -> [f64; 3] {
        let mut c = [0.0; 3];
        for (v, w) in values.into_iter().zip(&self.weights) {
            for (ci, wi) in c.iter_mut().zip(w) {
                *ci += v * wi;
            }
        }
        c
    }
}

/// The rules of every count of the [`LADDER`], fitted once for one colorimeter: what the GPU
/// technique uploads and its CPU twin evaluates.
#[derive(Clone, Debug, PartialEq)]
pub struct RuleLadder {
    rules: Vec<FewWavelengthRule>,
}

impl RuleLadder {
    /// Fits the rule of every count of the [`LADDER`] for `colorimeter`.
    pub fn new(colorimeter: &Colorimeter) -> Self {
        RuleLadder {
            rules: LADDER
                .iter()
                .map(|&n| FewWavelengthRule::new(colorimeter, n))
                .collect(),
        }
    }

    /// The rules, by increasing count.
    pub fn rules(&self) -> &[FewWavelengthRule] {
        &self.rules
    }

    /// The rule of [`count_for_opd`]`(opd_nm)`.
    pub fn for_opd(&self, opd_nm: f64) -> &FewWavelengthRule {
        let n = count_for_opd(opd_nm);
        self.rules
            .iter()
            .find(|r| r.wavelengths_nm.len() == n)
            .unwrap_or(&self.rules[self.rules.len() - 1])
    }
}

/// Most films of a real-time stack (`shaders/film_stack.wgsl`).
pub const MAX_STACK_FILMS: usize = 8;

/// The real-time multilayer evaluation shared by the GPU technique `film_stack` and its CPU
/// twin (`nacre color --method stack`): a stack whose top film takes the pixel's thickness
/// and whose other films vary together, d_j = d_j⁰ + r_j s (Sussenbach 2013 §4.2, Eq. 4.3:
/// the spatially varying thickness d_avg + d_rel Δ(x), with s = 2g − 1 ∈ [−1, 1] from a
/// greyscale map g), integrated with the rule of [`count_for_opd`] for the pixel's films
/// (or one fixed rule).
///
/// The rule's OPD is h Σ_j k_j d_j, k_j = 2 max_λ |ñ_j| over 380, 480, …, 780 nm (as
/// [`crate::Stack::max_opd_nm`]) and h = [`finesse_factor`] of the stack at 550 nm; both are
/// constants of the stack, so the GPU computes the OPD per pixel from the films' thicknesses.
/// Every medium's index is resolved on the CPU at every node of every rule (a dispersive
/// material costs nothing per pixel); when no material is dispersive the interfaces'
/// Fresnel coefficients are wavelength-invariant and the GPU computes them once per pixel
/// (the thesis's precalculation, §4.3).
///
/// One film may be an incoherent slab ([`crate::Stack::with_incoherent`]): thin-walled coated
/// glass, evaluated at each node by [`slab`]'s intensity recurrence (the GPU technique
/// `film_glass`). It may be any film; it keeps its own thickness (neither the pixel's, even
/// as the top film, nor the map's) and adds nothing to the rule's OPD (its fringes are
/// averaged, not sampled). `film_stack`, which sums amplitudes only, refuses it.
#[derive(Clone, Debug, PartialEq)]
pub struct StackEvaluation {
    rules: Vec<FewWavelengthRule>,
    fixed: bool,
    /// Per node of every rule (rules concatenated), every medium's index.
    indices: Vec<Vec<crate::C64>>,
    thickness_nm: Vec<f64>,
    relative_nm: Vec<f64>,
    channels: Vec<usize>,
    opd_factors: Vec<f64>,
    finesse: f64,
    dispersive: bool,
    /// The incoherent slab: its 1-based medium index ([`slab`]).
    slab: Option<usize>,
}

impl StackEvaluation {
    /// Prepares `stack` (1 to [`MAX_STACK_FILMS`] films) with per-film relative thicknesses
    /// `relative_nm` (r_j, ≥ 0; the top film's is unused: its thickness is the pixel's) for
    /// `colorimeter`, with the [`RuleLadder`] (`samples` = None) or the rule of `samples`
    /// nodes (1 to 256).
    ///
    /// # Errors
    /// [`crate::Error::OutOfRange`] for a film count, relative thickness or sample count out
    /// of range; a material's error where it has no data at a node.
    pub fn new(
        colorimeter: &Colorimeter,
        stack: &crate::Stack,
        relative_nm: &[f64],
        samples: Option<usize>,
    ) -> crate::Result<Self> {
        let films = stack.layers().len();
        let out_of_range =
            |what: &'static str, value: f64, expected: &'static str| crate::Error::OutOfRange {
                what,
                value,
                expected,
            };
        if !(1..=MAX_STACK_FILMS).contains(&films) {
            return Err(out_of_range(
                "films of a real-time stack",
                films as f64,
                "1 to 8",
            ));
        }
        if relative_nm.len() != films {
            return Err(out_of_range(
                "relative thicknesses given",
                relative_nm.len() as f64,
                "one per film",
            ));
        }
        let slabs = (1..=films).filter(|&j| stack.is_incoherent(j)).count();
        if slabs > 1 {
            return Err(out_of_range(
                "incoherent slabs of a real-time stack",
                slabs as f64,
                "at most 1 (a coated pane: films, one slab, films)",
            ));
        }
        let slab = (1..=films).find(|&j| stack.is_incoherent(j));
        if let Some(&r) = relative_nm.iter().find(|r| !(r.is_finite() && **r >= 0.0)) {
            return Err(out_of_range(
                "relative thickness (nm)",
                r,
                "a finite value ≥ 0",
            ));
        }
        let (rules, fixed) = match samples {
            None => (RuleLadder::new(colorimeter).rules, false),
            Some(n) if (1..=256).contains(&n) => {
                (vec![FewWavelengthRule::new(colorimeter, n)], true)
            }
            Some(n) => {
                return Err(out_of_range(
                    "wavelengths of the stack rule",
                    n as f64,
                    "1 to 256",
                ));
            }
        };
        let mut indices = Vec::new();
        for rule in &rules {
            for &l in rule.wavelengths_nm() {
                indices.push(stack.indices_at(l)?);
            }
        }
        let opd_factors = stack
            .layers()
            .iter()
            .enumerate()
            .map(|(j, l)| {
                if slab == Some(j + 1) {
                    return 0.0;
                }
                2.0 * [380.0, 480.0, 580.0, 680.0, 780.0]
                    .iter()
                    .filter_map(|&wl| l.material.index_at(wl).ok())
                    .map(elementary::norm)
                    .fold(0.0f64, f64::max)
            })
            .collect();
        let at_550: Vec<crate::C64> = std::iter::once(stack.ambient())
            .chain(stack.layers().iter().map(|l| &l.material))
            .chain(std::iter::once(stack.substrate()))
            .map(|m| m.index_at(550.0).unwrap_or(crate::C64::new(1.0, 0.0)))
            .collect();
        let dispersive = !(stack.ambient().is_constant()
            && stack.substrate().is_constant()
            && stack.layers().iter().all(|l| l.material.is_constant()));
        Ok(StackEvaluation {
            rules,
            fixed,
            indices,
            thickness_nm: stack.thicknesses_nm(),
            relative_nm: relative_nm.to_vec(),
            channels: vec![0; films],
            opd_factors,
            finesse: finesse_factor(&at_550),
            dispersive,
            slab,
        })
    }

    /// The rules (the ladder, or the one fixed rule), by increasing count.
    pub fn rules(&self) -> &[FewWavelengthRule] {
        &self.rules
    }

    /// True for one fixed rule (`stack:N`).
    pub fn fixed(&self) -> bool {
        self.fixed
    }

    /// Every medium's index at every node, rules concatenated (node-major).
    pub fn indices(&self) -> &[Vec<crate::C64>] {
        &self.indices
    }

    /// The films' own thicknesses d_j⁰, nm, top first.
    pub fn thickness_nm(&self) -> &[f64] {
        &self.thickness_nm
    }

    /// The films' relative thicknesses r_j, nm.
    pub fn relative_nm(&self) -> &[f64] {
        &self.relative_nm
    }

    /// The films' OPD factors k_j = 2 max |ñ_j|.
    pub fn opd_factors(&self) -> &[f64] {
        &self.opd_factors
    }

    /// The stack's [`finesse_factor`] h.
    pub fn finesse(&self) -> f64 {
        self.finesse
    }

    /// True when some medium's index varies with wavelength.
    pub fn dispersive(&self) -> bool {
        self.dispersive
    }

    /// The incoherent slab's 1-based medium index (film j is medium j), if the stack has one.
    pub fn slab(&self) -> Option<usize> {
        self.slab
    }

    /// The same stack with film j's thickness following channel `channels[j]` of the
    /// thickness map (0 = R or grey, 1 = G, 2 = B; one per film; the top film's must be 0:
    /// its thickness is the pixel's, from channel 0): the thesis's SVT with one map channel
    /// per layer (Sussenbach 2013 §4.2). Without it every film follows channel 0.
    ///
    /// # Errors
    /// [`crate::Error::OutOfRange`] for a count other than one per film, a channel above 2
    /// or a top film's channel other than 0.
    pub fn with_channels(mut self, channels: &[usize]) -> crate::Result<Self> {
        if channels.len() != self.thickness_nm.len() {
            return Err(crate::Error::OutOfRange {
                what: "map channels given",
                value: channels.len() as f64,
                expected: "one per film",
            });
        }
        if channels.first().is_some_and(|&c| c != 0) {
            return Err(crate::Error::OutOfRange {
                what: "top film's map channel",
                value: channels[0] as f64,
                expected: "0 (R): the top film's thickness is the pixel's",
            });
        }
        if let Some(&c) = channels.iter().find(|&&c| c > 2) {
            return Err(crate::Error::OutOfRange {
                what: "map channel",
                value: c as f64,
                expected: "0 (R), 1 (G) or 2 (B)",
            });
        }
        self.channels = channels.to_vec();
        Ok(self)
    }

    /// Film j's map channel (0 = R, 1 = G, 2 = B; [`StackEvaluation::with_channels`]).
    pub fn channels(&self) -> &[usize] {
        &self.channels
    }

    /// The films' thicknesses at a pixel: the top film `top_thickness_nm`, film j ≥ 2
    /// max(0, d_j⁰ + r_j s_c), s_c = `variation[c]` for film j's channel c, clamped to
    /// [−1, 1] (NaN → 0); thicknesses sanitised as the GPU's FilmInput (NaN or ≤ 0 → 0, at
    /// most 10⁶ nm).
    pub fn thicknesses_at(&self, top_thickness_nm: f64, variation: [f64; 3]) -> Vec<f64> {
        let clean = |d: f64| if d > 0.0 { d.min(1e6) } else { 0.0 };
        let s = variation.map(|v| if v.is_nan() { 0.0 } else { v.clamp(-1.0, 1.0) });
        (0..self.thickness_nm.len())
            .map(|j| {
                if self.slab == Some(j + 1) {
                    // The slab keeps its own thickness (millimetres: no 10⁶ nm clamp).
                    let d = self.thickness_nm[j];
                    if d > 0.0 && d.is_finite() { d } else { 0.0 }
                } else if j == 0 {
                    clean(top_thickness_nm)
                } else {
                    clean(self.thickness_nm[j] + self.relative_nm[j] * s[self.channels[j]])
                }
            })
            .collect()
    }

    /// The index of the rule used for films of `thickness_nm`: the fixed rule, or the
    /// ladder's rule for the OPD h Σ_j k_j d_j.
    pub fn rule_index(&self, thickness_nm: &[f64]) -> usize {
        if self.fixed {
            return 0;
        }
        let opd: f64 = thickness_nm
            .iter()
            .zip(&self.opd_factors)
            .map(|(d, k)| d * k)
            .sum::<f64>()
            * self.finesse;
        let n = count_for_opd(opd);
        self.rules
            .iter()
            .position(|r| r.wavelengths_nm().len() == n)
            .unwrap_or(self.rules.len() - 1)
    }

    /// Unpolarised (reflectance, transmittance) colours at incidence cosine `cos_theta_i`
    /// (in the ambient; clamped to [10⁻⁶, 1], NaN → 1) for the pixel's films
    /// ([`StackEvaluation::thicknesses_at`]): Σ_k W_k (R_s + R_p)/2 at the nodes of the
    /// pixel's rule, and likewise T.
    pub fn colour(
        &self,
        cos_theta_i: f64,
        top_thickness_nm: f64,
        variation: [f64; 3],
    ) -> ([f64; 3], [f64; 3]) {
        let c = if cos_theta_i.is_nan() {
            1.0
        } else {
            cos_theta_i.clamp(1e-6, 1.0)
        };
        let sin = (1.0 - c * c).max(0.0).sqrt();
        let d = self.thicknesses_at(top_thickness_nm, variation);
        let rule = self.rule_index(&d);
        let first: usize = self.rules[..rule]
            .iter()
            .map(|r| r.wavelengths_nm().len())
            .sum();
        let (mut r, mut t) = ([0.0; 3], [0.0; 3]);
        let chosen = &self.rules[rule];
        for (k, (&l, w)) in chosen
            .wavelengths_nm()
            .iter()
            .zip(chosen.weights())
            .enumerate()
        {
            let idx = &self.indices[first + k];
            let (rv, tv) = match self.slab {
                Some(s) => slab::slab_power(idx, idx[0].re * sin, l, &d, s),
                None => {
                    let prepared = crate::Prepared::new(idx, idx[0].re * sin);
                    let p = prepared.power(&prepared.amplitudes(l, &d));
                    (p.R(), p.T())
                }
            };
            for ch in 0..3 {
                r[ch] += rv * w[ch];
                t[ch] += tv * w[ch];
            }
        }
        (r, t)
    }
}

/// Solves A X = B for a symmetric positive definite n × n `a` (row-major) and three
/// right-hand sides, by Cholesky factorisation.
fn solve_spd(a: &[f64], b: &[[f64; 3]], n: usize) -> Vec<[f64; 3]> {
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= l[i * n + k] * l[j * n + k];
            }
            if i == j {
                l[i * n + i] = s.max(f64::MIN_POSITIVE).sqrt();
            } else {
                l[i * n + j] = s / l[j * n + j];
            }
        }
    }
    let mut y = vec![[0.0; 3]; n];
    for i in 0..n {
        for c in 0..3 {
            let mut s = b[i][c];
            for k in 0..i {
                s -= l[i * n + k] * y[k][c];
            }
            y[i][c] = s / l[i * n + i];
        }
    }
    let mut x = vec![[0.0; 3]; n];
    for i in (0..n).rev() {
        for c in 0..3 {
            let mut s = y[i][c];
            for k in i + 1..n {
                s -= l[k * n + i] * x[k][c];
            }
            x[i][c] = s / l[i * n + i];
        }
    }
    x
}

mod slab;

#[cfg(test)]
mod tests_support;

#[cfg(test)]
mod tests;
