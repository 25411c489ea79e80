//! Table kind `fourier`: the Fourier transforms Ŝ_j(μ) of the output-space sensitivities
//! (Belcour & Barla 2017, Eq. 8–10), prefiltered and mip-mapped (§5), for evaluating thin-film
//! colour per pixel with [`nacre_optics::fourier`]'s Eq. 10.
//!
//! # What every texel holds
//!
//! Level k is a row of N_k = N / 2^k texels over optical path differences μ ∈ [0, D_max];
//! texel i holds, for each channel j (R, G, B of the output space, or X, Y, Z),
//!
//! ```text
//! A_j,k(μᵢ) = Ŝ_j,σk(μᵢ) · e^{+2πi μᵢ ν̄_j},   μᵢ = (i + 0.5) D_max / N_k
//! ```
//!
//! where Ŝ_j,σ is Ŝ_j convolved with a Gaussian of standard deviation σ in μ (exactly: the
//! spectral damping exp(−(2πσ/λ)²/2)), σ₀ = 0 and σ_k = D_max / N_k for k ≥ 1 (the level's
//! texel spacing: doubling per level), and ν̄_j is the channel's centroid frequency
//! ([`nacre_optics::fourier::SensitivitySpectrum::centroid_nu`], in the manifest). Removing
//! the carrier e^{−2πiμν̄_j} leaves a slowly varying envelope that linear filtering
//! reproduces accurately; the real and imaginary parts are stored in two rows (row 0: Re,
//! row 1: Im) of one OpenEXR file per level, full float.
//!
//! # How a shader rebuilds Ŝ
//!
//! ```text
//! u     = μ / D_max                         (texel centres at (i + 0.5)/N_k: the usual mip convention)
//! lod   = σ_μ < σ₁ ? σ_μ / σ₁ : 1 + log2(σ_μ / σ₁)     (clamped to the last level)
//! A     = trilinear sample of (Re, Im) at (u, lod), clamp to edge
//! Ŝ_j   = A_j · e^{−2πi μ ν̄_j}
//! ```
//!
//! and the colour of a single film follows Eq. 10:
//! `C_j = ‖s_j‖ [c₀ + 2 Σ_{m=1}^{M} Re(c_m conj Ŝ_j(m D, m τ σ_d))]` (see
//! [`nacre_optics::fourier`] for c₀, c_m, D and τ).

use crate::error::{Error, Result};
use crate::table_io::{self, Precision, Table3};
use nacre_optics::C64;
use nacre_optics::colour::Colorimeter;
use nacre_optics::elementary;
use nacre_optics::fourier::SensitivitySpectrum;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::path::Path;

/// Axes and constants of a `fourier` table, as recorded in its manifest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FourierAxes {
    /// Texels of level 0.
    pub samples: usize,
    /// D_max, nm: u = μ / D_max.
    pub max_opd_nm: f64,
    /// Texels per level.
    pub level_samples: Vec<usize>,
    /// Prefilter standard deviation of each level in μ, nm (0 for level 0).
    pub level_sigma_nm: Vec<f64>,
    /// Carrier (centroid) frequency ν̄_j of each channel, 1/nm.
    pub carrier_nu_per_nm: [f64; 3],
    /// ‖s_j‖: the colour of a perfect reflector in the output space.
    pub white: [f64; 3],
}

impl FourierAxes {
    /// Axes for `samples` texels over [0, `max_opd_nm`] and `levels` mip levels.
    pub fn new(colorimeter: &Colorimeter, samples: usize, max_opd_nm: f64, levels: usize) -> Self {
        let spectrum = SensitivitySpectrum::new(colorimeter);
        let level_samples: Vec<usize> = (0..levels).map(|k| (samples >> k).max(1)).collect();
        let level_sigma_nm = level_samples
            .iter()
            .enumerate()
            .map(|(k, &n)| if k == 0 { 0.0 } else { max_opd_nm / n as f64 })
            .collect();
        let white = colorimeter
            .weights_1nm()
            .iter()
            .fold([0.0; 3], |a, w| [a[0] + w[0], a[1] + w[1], a[2] + w[2]]);
        FourierAxes {
            samples,
            max_opd_nm,
            level_samples,
            level_sigma_nm,
            carrier_nu_per_nm: spectrum.centroid_nu(),
            white,
        }
    }

    /// The fractional mip level for a prefilter width σ_μ (nm).
    pub fn lod(&self, sigma_mu_nm: f64) -> f64 {
        let last = (self.level_samples.len() - 1) as f64;
        if self.level_samples.len() < 2 || !(sigma_mu_nm > 0.0) {
            return 0.0;
        }
        let s1 = self.level_sigma_nm[1];
        let lod = if sigma_mu_nm < s1 {
            sigma_mu_nm / s1
        } else {
            1.0 + elementary::log2(sigma_mu_nm / s1)
        };
        lod.min(last)
    }
}

/// A baked `fourier` table: the demodulated envelopes A_j,k per level.
#[derive(Clone, Debug, PartialEq)]
pub struct FourierTable {
    /// Axes.
    pub axes: FourierAxes,
    /// Level k: N_k texels of (A_R, A_G, A_B), as stored (f32 precision).
    pub levels: Vec<Vec<[C64; 3]>>,
}

impl FourierTable {
    /// Ŝ_j(μ) prefiltered at σ_μ, sampled exactly as a GPU sampler with linear filtering
    /// between texels and levels and clamp-to-edge addressing (module docs).
    pub fn sample(&self, mu_nm: f64, sigma_mu_nm: f64) -> [C64; 3] {
        let lod = self.axes.lod(sigma_mu_nm);
        let k0 = lod.floor() as usize;
        let f = lod - k0 as f64;
        let a0 = self.sample_level(k0, mu_nm);
        let a = if f > 0.0 && k0 + 1 < self.levels.len() {
            let a1 = self.sample_level(k0 + 1, mu_nm);
            std::array::from_fn(|j| a0[j] * (1.0 - f) + a1[j] * f)
        } else {
            a0
        };
        std::array::from_fn(|j| {
            a[j] * elementary::from_polar(1.0, -2.0 * PI * mu_nm * self.axes.carrier_nu_per_nm[j])
        })
    }

    fn sample_level(&self, k: usize, mu_nm: f64) -> [C64; 3] {
        let level = &self.levels[k];
        let n = level.len();
        let x = (mu_nm / self.axes.max_opd_nm * n as f64 - 0.5).clamp(0.0, (n - 1) as f64);
        let i0 = (x.floor() as usize).min(n - 1);
        let i1 = (i0 + 1).min(n - 1);
        let f = x - i0 as f64;
        std::array::from_fn(|j| level[i0][j] * (1.0 - f) + level[i1][j] * f)
    }

    /// Level `k` as a 2-row image: row 0 the real parts, row 1 the imaginary parts.
    pub fn level_image(&self, k: usize) -> Table3 {
        let level = &self.levels[k];
        let mut t = Table3::new(level.len(), 2, 1);
        for (i, a) in level.iter().enumerate() {
            t.set(i, 0, 0, a.map(|c| c.re as f32));
            t.set(i, 1, 0, a.map(|c| c.im as f32));
        }
        t
    }

    /// Writes level `k` as OpenEXR (full float).
    pub fn write_level(&self, k: usize, path: &Path) -> Result<()> {
        table_io::write_exr(path, &self.level_image(k), Precision::Float)
    }

    /// Reads a table from its level files (in order).
    pub fn read(axes: FourierAxes, paths: &[std::path::PathBuf]) -> Result<Self> {
        if paths.len() != axes.level_samples.len() {
            return Err(Error::Invalid {
                context: "fourier table".into(),
                message: format!(
                    "{} level files for {} levels",
                    paths.len(),
                    axes.level_samples.len()
                )
                .into(),
            });
        }
        let levels = paths
            .iter()
            .zip(&axes.level_samples)
            .map(|(p, &n)| {
                let (t, _) = table_io::read_exr_table(p, n, 2, 1)?;
                Ok((0..n)
                    .map(|i| {
                        let (re, im) = (t.texel(i, 0, 0), t.texel(i, 1, 0));
                        std::array::from_fn(|j| C64::new(f64::from(re[j]), f64::from(im[j])))
                    })
                    .collect())
            })
            .collect::<Result<_>>()?;
        Ok(FourierTable { axes, levels })
    }
}
