//! The environment's diffraction: Stam's BRDF integrated against the whole environment, lobe
//! by lobe (`shaders/diffraction_scene.wgsl`, `scene_env_diffracted`), for tables of the
//! layout "terms".
//!
//! # The integral
//!
//! With (u, v, w) = −ω_i − ω_r in the grating frame and k = 2π/λ, the radiance the
//! environment L_e sends towards ω_r through a grating of relative reflectance
//! ρ = F² G/w² |P̃(ku, kv)|² (Stam 1999; `nacre_optics::diffraction`) is, per wavelength,
//!
//! ```text
//!   L(ω_r, λ) = ∫ L_e(ω_i) f(ω_i, ω_r, λ) cos θ_i dω_i = ∫ L_e(ω_i(u, v)) ρ (σ_s k)²/π du dv
//! ```
//!
//! since du dv = cos θ_i dω_i at fixed ω_r and the BRDF whose flat mirror reflects all the
//! light is f = ρ (σ_s k)²/π (the Mitsuba reference's `nacre_grating`, Stam's k² at every λ).
//! The windowed transform P̃(q) = Σ_j P_j(kw) exp(−σ_s²|q − κ_j|²/2) is a sum of Gaussian
//! lobes around the DFT bins κ_j; dropping the cross terms between bins (exact for a
//! periodic grating whose bins lie ≥ 2/σ_s apart; for a random structure such as the CD's
//! pits their phases average out),
//!
//! ```text
//!   |P̃(q)|² ≈ Σ_j |P_j(kw)|² exp(−σ_s² |q − κ_j|²),   ∫ (σ_s k)²/π exp(−σ_s²|k(u,v) − κ_j|²) du dv = 1
//! ```
//!
//! so each bin contributes F² G/w² |P_j(kw)|² times the environment averaged over a
//! normalised Gaussian of per-axis variance 1/(2σ_s²) in q = k(u, v), centred where the
//! grating equation puts its order: the tangential part of ω_i is −ω_r,t − κ_j/k. The sum
//! over wavelengths then integrates the whole environment, each texel diffracted into every
//! order that reaches it, with Stam's k² and the wavelength dependence of the lobes exact.
//!
//! # Lobes
//!
//! A table has up to 65 536 bins (the CD's 256 × 256); summing them all per pixel and
//! wavelength is out of reach. The sum is compressed into at most [`MAX_LOBES`] lobes, chosen
//! once per table on the CPU at the reference s₀ = k w at 555 nm and normal incidence (w = −2):
//!
//! * the [`MAX_SHARP_LOBES`] strongest bins other than DC, each a lobe of its own
//!   (variance 1/(2σ_s²)): a periodic grating's orders (the 1200 lines/mm grating's
//!   m = ±1 … ±5, the CD's track orders (±20, 0), (±40, 0));
//! * every other bin joins the nearest (in κ) of DC and those bins; each group is a
//!   "halo" lobe at its power-weighted centroid whose variance adds the group's spread
//!   to the window's (the CD's pits scatter ~60 % of the non-specular power into a broad
//!   halo around the mirror and around each track order, coloured as the orders are).
//!
//! Each lobe's efficiency η(kw) = Σ_{j ∈ lobe} |P_j(kw)|² is tabulated at
//! [`LOBE_KW_SAMPLES`] points of kw ∈ [−2k_max, 0] (k_max at the table's shortest
//! wavelength) and interpolated linearly in the shader (|P_j|² is a polynomial of degree 2N
//! in kw, smooth on that grid: the phase kw·h moves by under 0.1 rad between samples for the
//! bundled tables). DC itself stays the specular order of the scene
//! (`diffraction_specular_order_colour`, the environment's mirror image).
//!
//! # The environment lookup
//!
//! A lobe of variance σ_q² per axis in q spans σ_q/k in (u, v), about σ_q/(k cos θ_i) in
//! angle; a band of the wavelength grid (step Δλ) sweeps the order by |κ| Δλ/(2π) in (u, v),
//! a uniform spread of variance (|κ| Δλ/2π)²/12. The shader reads the environment's box
//! mip chain (prefiltered once for every scene) at the level whose texels match the sum of
//! the two (level ℓ = log₂(2.5 σ/texel₀)), i.e. the environment is prefiltered by lobe
//! size; the bundled tables' sharp lobes (σ_s = 8 µm: 0.45° at 555 nm) read level 0.
//!
//! Why not Toisoul & Ghosh's low-rank factorisation (CVMP 2017)? It fits the BRDF as a sum
//! of products of functions of ω_i and ω_r and prefilters the environment once per factor:
//! exact for the factors kept, but the fit is per table and view range, offline, and its
//! rank grows with the sharpness of the lobes (a 0.45° lobe needs many). The lobe sum here
//! needs no fit, is exact for periodic gratings up to the lobe's Gaussian average, and costs
//! wavelengths × lobes environment reads per pixel (41 × ≤ 49 at the scenes' 10 nm step).

use crate::error::{Error, Result};
use nacre_format::diffraction::DiffractionRecord;
use nacre_optics::C64;
use nacre_optics::diffraction::{TaylorTerms, k_per_um};
use rayon::prelude::*;

/// Bins that get a sharp lobe of their own (module docs).
pub const MAX_SHARP_LOBES: usize = 24;

/// Most lobes of a table: the sharp ones and a halo for DC and for each of them.
pub const MAX_LOBES: usize = 2 * MAX_SHARP_LOBES + 1;

/// Samples of each lobe's efficiency η(kw) over kw ∈ [−2k_max, 0].
pub const LOBE_KW_SAMPLES: usize = 64;

/// Reference wavelength of the lobes' choice, nm (s₀ = −2 k at normal incidence).
pub const LOBE_CHOICE_NM: f64 = 555.0;

/// Lobes whose efficiency stays below this at every kw are dropped (a bin of the CD's halo
/// carries ~10⁻⁶).
pub const MIN_LOBE_EFFICIENCY: f64 = 1e-5;

/// One lobe: where it sits in q, how wide it is, and its efficiency over kw.
#[derive(Clone, Debug, PartialEq)]
pub struct Lobe {
    /// Centre κ in the grating frame (x across the lines), rad/µm.
    pub centre_per_um: [f64; 2],
    /// Variance of the lobe per axis in q, (rad/µm)²: 1/(2σ_s²) plus a halo's spread.
    pub variance_per_um2: f64,
    /// η(kw) at [`LOBE_KW_SAMPLES`] points from `kw_min` to 0.
    pub efficiency: Vec<f64>,
    /// True for one bin of its own, false for a halo.
    pub sharp: bool,
}

/// A table's lobes (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentLobes {
    /// The lobes, sharp ones first (strongest first), then the halos.
    pub lobes: Vec<Lobe>,
    /// The first kw of the efficiency samples (−2 k_max), rad.
    pub kw_min: f64,
    /// The non-specular power Σ_{j ≠ 0} |P_j(s₀)|² of the table at the reference.
    pub scattered: f64,
    /// The part of `scattered` the kept lobes carry at the reference.
    pub captured: f64,
    /// The specular order's efficiency |P_DC(kw)|² at the lobes' [`LOBE_KW_SAMPLES`] points
    /// (the rough light of the scenes sums it as one more lobe: `scene_rough_light`).
    pub specular: Vec<f64>,
    /// The window's variance per axis in q, 1/(2σ_s²), (rad/µm)²: the specular order's and
    /// every sharp lobe's.
    pub window_per_um2: f64,
}

impl EnvironmentLobes {
    /// The lobes of `terms` with coherence window σ_s = `record.sigma_s_um`, served down to
    /// `record.wavelength_min_nm`.
    ///
    /// # Errors
    /// [`Error::Invalid`] for a record whose σ_s, shortest wavelength or patch is not
    /// positive and finite, or whose sizes disagree with the terms.
    pub fn new(terms: &TaylorTerms, record: &DiffractionRecord) -> Result<EnvironmentLobes> {
        let (nx, ny) = terms.size();
        let sigma = record.sigma_s_um;
        let lambda_min = record.wavelength_min_nm;
        let [lx, ly] = [nx as f64 * terms.pitch_um(), ny as f64 * terms.pitch_um()];
        if !(sigma.is_finite() && sigma > 0.0 && lambda_min.is_finite() && lambda_min > 0.0)
            || !(lx.is_finite() && lx > 0.0 && ly.is_finite() && ly > 0.0)
            || (nx, ny) != (record.nx, record.ny)
        {
            return Err(Error::Invalid {
                context: "the environment lobes of a diffraction table".into(),
                message: format!(
                    "σ_s {sigma} µm, shortest wavelength {lambda_min} nm, patch {lx} × {ly} µm, terms {nx} × {ny} against the record's {} × {} (positive and finite, sizes equal)",
                    record.nx, record.ny
                ),
            });
        }
        let dk = [std::f64::consts::TAU / lx, std::f64::consts::TAU / ly];
        let kappa = |i: usize| -> [f64; 2] {
            let jx = (i % nx) as f64 - (nx / 2) as f64;
            let jy = (i / nx) as f64 - (ny / 2) as f64;
            [jx * dk[0], jy * dk[1]]
        };
        let dc = (ny / 2) * nx + nx / 2;
        let power0: Vec<f64> = terms
            .series(-2.0 * k_per_um(LOBE_CHOICE_NM))
            .iter()
            .map(C64::norm_sqr)
            .collect();
        let scattered: f64 = power0
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != dc)
            .map(|(_, p)| p)
            .sum();
        // The strongest bins (ties by index), then every other bin to its nearest anchor.
        let mut order: Vec<usize> = (0..power0.len()).filter(|&i| i != dc).collect();
        order.sort_by(|&a, &b| power0[b].total_cmp(&power0[a]).then(a.cmp(&b)));
        let sharp: Vec<usize> = order
            .iter()
            .copied()
            .take(MAX_SHARP_LOBES)
            .filter(|&i| power0[i] > 0.0)
            .collect();
        // Anchor 0 is DC, anchor a ≥ 1 the sharp bin a − 1.
        let anchors: Vec<[f64; 2]> = std::iter::once([0.0, 0.0])
            .chain(sharp.iter().map(|&i| kappa(i)))
            .collect();
        let mut group = vec![usize::MAX; power0.len()];
        for (i, slot) in group.iter_mut().enumerate() {
            if i == dc || sharp.contains(&i) {
                continue;
            }
            let q = kappa(i);
            let mut best = (f64::INFINITY, 0);
            for (a, c) in anchors.iter().enumerate() {
                let d = (q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2);
                if d < best.0 {
                    best = (d, a);
                }
            }
            *slot = best.1;
        }
        // Efficiencies: |P_j(kw)|² at every sample, summed per lobe (lobe index: sharp
        // bins 0 … S − 1, halos S … 2S).
        let kw_min = -2.0 * k_per_um(lambda_min);
        let lobe_of = |i: usize| -> Option<usize> {
            if i == dc {
                None
            } else if let Some(s) = sharp.iter().position(|&b| b == i) {
                Some(s)
            } else {
                Some(sharp.len() + group[i])
            }
        };
        let count = 2 * sharp.len() + 1;
        // Per sample: the lobes' efficiencies, then the specular order's |P_DC|² last.
        let samples: Vec<Vec<f64>> = (0..LOBE_KW_SAMPLES)
            .into_par_iter()
            .map(|s| {
                let kw = kw_min * (1.0 - s as f64 / (LOBE_KW_SAMPLES - 1) as f64);
                let mut eta = vec![0.0; count + 1];
                for (i, p) in terms.series(kw).iter().enumerate() {
                    match lobe_of(i) {
                        Some(l) => eta[l] += p.norm_sqr(),
                        None => eta[count] = p.norm_sqr(),
                    }
                }
                eta
            })
            .collect();
        let specular = samples.iter().map(|e| e[count]).collect();
        let window = 1.0 / (2.0 * sigma * sigma);
        // Lobe l as (l, lobe); a halo's group is empty when every bin went elsewhere.
        let mut lobes: Vec<(usize, Lobe)> = Vec::with_capacity(count);
        for (s, &i) in sharp.iter().enumerate() {
            lobes.push((
                s,
                Lobe {
                    centre_per_um: kappa(i),
                    variance_per_um2: window,
                    efficiency: samples.iter().map(|e| e[s]).collect(),
                    sharp: true,
                },
            ));
        }
        for a in 0..anchors.len() {
            // Power-weighted centroid and per-axis variance of the group at s₀.
            let members: Vec<usize> = (0..power0.len()).filter(|&i| group[i] == a).collect();
            let w: f64 = members.iter().map(|&i| power0[i]).sum();
            if w.is_nan() || w <= 0.0 {
                continue;
            }
            let mut c = [0.0, 0.0];
            for &i in &members {
                let q = kappa(i);
                c = [c[0] + power0[i] * q[0] / w, c[1] + power0[i] * q[1] / w];
            }
            let spread: f64 = members
                .iter()
                .map(|&i| {
                    let q = kappa(i);
                    power0[i] * ((q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2))
                })
                .sum::<f64>()
                / w;
            let l = sharp.len() + a;
            lobes.push((
                l,
                Lobe {
                    centre_per_um: c,
                    // Half the 2-D spread per axis.
                    variance_per_um2: window + 0.5 * spread,
                    efficiency: samples.iter().map(|e| e[l]).collect(),
                    sharp: false,
                },
            ));
        }
        lobes.retain(|(_, lobe)| lobe.efficiency.iter().any(|&e| e >= MIN_LOBE_EFFICIENCY));
        let mut kept = vec![false; count];
        for (l, _) in &lobes {
            kept[*l] = true;
        }
        let captured: f64 = (0..power0.len())
            .filter(|&i| lobe_of(i).is_some_and(|l| kept[l]))
            .map(|i| power0[i])
            .sum();
        let lobes = lobes.into_iter().map(|(_, lobe)| lobe).collect();
        Ok(EnvironmentLobes {
            lobes,
            kw_min,
            scattered,
            captured,
            specular,
            window_per_um2: window,
        })
    }
}
