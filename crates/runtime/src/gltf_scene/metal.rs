//! A glTF metal's complex index from its colour (the module documentation of
//! [`crate::gltf_scene`] derives it): one index per channel by Gulbrandsen 2014
//! ([`metal_index_gulbrandsen2014`]), and for per-wavelength techniques a piecewise-constant
//! dispersion over three bands split where the colorimeter's channel sensitivities cross
//! ([`MetalBands`], [`rgb_metal_for`]), so that each channel's F0 is reproduced where that
//! channel's sensitivity lies.

use crate::error::{Error, Result};
use nacre_optics::colour::Colorimeter;
use nacre_optics::{C64, Material};

/// Linear base colour of gold at normal incidence (the glTF specification's reference metal
/// table, "gold": 1.000, 0.766, 0.336).
pub const GOLD_F0: [f32; 3] = [1.0, 0.766, 0.336];

/// The complex index n + iκ whose normal-incidence reflectance from air is `f0`, with edge
/// tint `edge_tint` (both in [0, 1]; f0 clamped to [0, 0.99]): Gulbrandsen 2014, Eq. (1)–(2)
/// (see the module documentation).
pub fn metal_index_gulbrandsen2014(f0: f64, edge_tint: f64) -> C64 {
    let r = if f0.is_finite() {
        f0.clamp(0.0, 0.99)
    } else {
        0.5
    };
    let g = if edge_tint.is_finite() {
        edge_tint.clamp(0.0, 1.0)
    } else {
        0.5
    };
    let sr = r.sqrt();
    let n = g * (1.0 - r) / (1.0 + r) + (1.0 - g) * (1.0 + sr) / (1.0 - sr);
    let k2 = (r * (n + 1.0).powi(2) - (n - 1.0).powi(2)) / (1.0 - r);
    C64::new(n.max(1e-3), k2.max(0.0).sqrt())
}

/// Whether a linear base colour is within 0.1 per channel of [`GOLD_F0`].
pub fn is_gold_like(base_colour: [f32; 3]) -> bool {
    base_colour
        .iter()
        .zip(GOLD_F0)
        .all(|(c, g)| (c - g).abs() <= 0.1)
}

/// Three wavelength bands (blue, green, red) over which a glTF metal's index is constant for
/// `film_spectral`, and how much of each channel's sensitivity lies in each band.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetalBands {
    /// The blue/green and green/red boundaries, nm: where the colorimeter's green weight
    /// first exceeds the blue one, and its red weight the green one (sRGB under D65 and the
    /// CIE 1931 observer: about 492 and 571 nm).
    pub boundaries_nm: [f64; 2],
    /// M\[j\]\[k\]: the share of channel j's weights (Σ_λ w_j(λ) = 1 for white) that falls in
    /// band k, so that a reflectance ρ_k per band has the colour C_j = Σ_k M\[j\]\[k\] ρ_k.
    pub share: [[f64; 3]; 3],
}

impl MetalBands {
    /// The bands of `colorimeter`'s 1-nm weights.
    pub fn new(colorimeter: &Colorimeter) -> MetalBands {
        let w = colorimeter.weights_1nm();
        let lambda = nacre_optics::colour::spectral_wavelength_nm;
        let crossing = |from: f64, to: f64, a: usize, b: usize, fallback: f64| {
            (0..w.len())
                .map(|i| (lambda(i), w[i]))
                .filter(|(l, _)| (from..=to).contains(l))
                .find(|(_, wi)| wi[b] >= wi[a])
                .map_or(fallback, |(l, _)| l - 0.5)
        };
        let b1 = crossing(440.0, 540.0, 2, 1, 492.0);
        let b2 = crossing(b1 + 10.0, 650.0, 1, 0, 571.0);
        let mut share = [[0.0; 3]; 3];
        for (i, wi) in w.iter().enumerate() {
            let l = lambda(i);
            let k = if l < b1 {
                2
            } else if l < b2 {
                1
            } else {
                0
            };
            for j in 0..3 {
                share[j][k] += wi[j];
            }
        }
        for row in &mut share {
            let sum: f64 = row.iter().sum();
            if sum.abs() > 1e-12 {
                row.iter_mut().for_each(|x| *x /= sum);
            }
        }
        MetalBands {
            boundaries_nm: [b1, b2],
            share,
        }
    }

    /// The band of wavelength λ (0 red, 1 green, 2 blue, as the channels).
    pub fn band_of(&self, wavelength_nm: f64) -> usize {
        if wavelength_nm < self.boundaries_nm[0] {
            2
        } else if wavelength_nm < self.boundaries_nm[1] {
            1
        } else {
            0
        }
    }

    /// The band reflectances ρ ∈ \[0, 0.99\]³ whose colour Σ_k M\[j\]\[k\] ρ_k is closest to
    /// `f0` (RGB): the 3 × 3 solution when it lies in the box, else a projected
    /// Gauss–Seidel least-squares fit (a few hundred sweeps; deterministic).
    pub fn band_reflectance(&self, f0: [f64; 3]) -> [f64; 3] {
        let m = self.share;
        let target = f0.map(|c| {
            if c.is_finite() {
                c.clamp(0.0, 0.99)
            } else {
                0.5
            }
        });
        // Normal equations (MᵀM) ρ = Mᵀ f0, solved coordinate-wise with the box constraint.
        let mut ata = [[0.0; 3]; 3];
        let mut atb = [0.0; 3];
        for k in 0..3 {
            for l in 0..3 {
                ata[k][l] = (0..3).map(|j| m[j][k] * m[j][l]).sum();
            }
            atb[k] = (0..3).map(|j| m[j][k] * target[j]).sum();
        }
        let mut rho = target;
        for _ in 0..500 {
            for k in 0..3 {
                if ata[k][k].abs() < 1e-12 {
                    continue;
                }
                let r: f64 = atb[k]
                    - (0..3)
                        .filter(|&l| l != k)
                        .map(|l| ata[k][l] * rho[l])
                        .sum::<f64>();
                rho[k] = (r / ata[k][k]).clamp(0.0, 0.99);
            }
        }
        rho
    }

    /// The colour Σ_k M\[j\]\[k\] ρ_k of band reflectances ρ.
    pub fn colour(&self, rho: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|j| (0..3).map(|k| self.share[j][k] * rho[k]).sum())
    }
}

/// A metal base for a glTF base colour `f0` (linear RGB, the metal's reflectance at normal
/// incidence): per band of `bands` the index n_k + iκ_k of
/// [`metal_index_gulbrandsen2014`]`(ρ_k, ρ_k)`, with ρ = [`MetalBands::band_reflectance`]
/// (f0) — so that the bare metal's colour integrated over the spectrum is f0 wherever the
/// box [0, 0.99]³ allows it (a saturated red (0.8, 0, 0) would need a negative green band:
/// its closest fit is (0.794, 0.067, 0.002) with sRGB D65, see the tests). Defined from 200 to 3000 nm, the
/// index changing over 0.2 nm at each boundary.
pub fn rgb_metal_for(name: &str, f0: [f64; 3], bands: &MetalBands) -> Result<Material> {
    banded_metal(name, bands.band_reflectance(f0), bands)
}

/// The largest difference, in sRGB-encoded units (IEC 61966-2-1, 0–1), between a channel of
/// a glTF metal's base colour and the reflectance the three-band fit gives that channel's
/// band, above which [`gltf_metal_for`] falls back to [`per_channel_metal`].
///
/// The per-channel techniques (`lut`, `fourier`) read the base index once per channel, at a
/// wavelength inside that channel's band, so the F0 they draw is the band's ρ_k, not the
/// integrated colour Σ_k M\[j\]\[k\] ρ_k that the fit matches. For most metals the two are
/// close (sRGB D65: gold 0.03, copper 0.04 at most), but a saturated colour needs bands far
/// from it to cancel the sensitivities' negative lobes: TextureEncodingTest's green (0, 0.246,
/// 0) takes ρ = (0.063, 0.261, 0.010), an olive (red 0.063 is 0.28 in sRGB), and the red
/// (0.8, 0, 0) takes a blue band of 0.025 (0.17 in sRGB).
pub const BAND_FIT_TOLERANCE_SRGB: f64 = 0.1;

/// sRGB encoding (IEC 61966-2-1) of a linear value in \[0, 1\].
fn srgb_encode(c: f64) -> f64 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * nacre_optics::elementary::powf(c, 1.0 / 2.4) - 0.055
    }
}

/// Whether the three-band fit ρ of `bands` misses the base colour `f0` per channel by more
/// than [`BAND_FIT_TOLERANCE_SRGB`] (see there), `f0` clamped to \[0, 0.99\] as the fit is.
pub fn band_fit_misses(f0: [f64; 3], bands: &MetalBands) -> bool {
    let rho = bands.band_reflectance(f0);
    (0..3).any(|j| {
        let want = if f0[j].is_finite() {
            f0[j].clamp(0.0, 0.99)
        } else {
            0.5
        };
        (srgb_encode(rho[j]) - srgb_encode(want)).abs() > BAND_FIT_TOLERANCE_SRGB
    })
}

/// A metal base whose band k has [`metal_index_gulbrandsen2014`]`(f0_k, f0_k)`: Gulbrandsen's
/// per-channel inversion, exact at normal incidence for every technique that reads the base
/// once per channel (the route of textured metals in `shaders/mesh.wgsl`); integrated over
/// the spectrum (`film_spectral`) its colour is Σ_k M\[j\]\[k\] f0_k. Bands as
/// [`rgb_metal_for`].
pub fn per_channel_metal(name: &str, f0: [f64; 3], bands: &MetalBands) -> Result<Material> {
    banded_metal(
        name,
        f0.map(|c| {
            if c.is_finite() {
                c.clamp(0.0, 0.99)
            } else {
                0.5
            }
        }),
        bands,
    )
}

/// The metal base of a glTF base colour `f0`: [`rgb_metal_for`] (the three-band fit, right for
/// the spectrum) unless the fit misses a channel ([`band_fit_misses`]), then
/// [`per_channel_metal`] (right per channel). The flag says which: `true` for the fallback.
pub fn gltf_metal_for(name: &str, f0: [f64; 3], bands: &MetalBands) -> Result<(Material, bool)> {
    if band_fit_misses(f0, bands) {
        Ok((
            per_channel_metal(
                &format!("{name} (Gulbrandsen 2014, per channel)"),
                f0,
                bands,
            )?,
            true,
        ))
    } else {
        Ok((
            rgb_metal_for(&format!("{name} (Gulbrandsen 2014, 3 bands)"), f0, bands)?,
            false,
        ))
    }
}

/// The metal whose band k (of `bands`) has [`metal_index_gulbrandsen2014`]`(ρ_k, ρ_k)`.
fn banded_metal(name: &str, rho: [f64; 3], bands: &MetalBands) -> Result<Material> {
    let index = rho.map(|r| metal_index_gulbrandsen2014(r, r));
    let [b1, b2] = bands.boundaries_nm;
    let [r, g, b] = index;
    let mut csv = String::from("wavelength_nm,n,k\n");
    for (w, n) in [
        (200.0, b),
        (b1 - 0.1, b),
        (b1 + 0.1, g),
        (b2 - 0.1, g),
        (b2 + 0.1, r),
        (3000.0, r),
    ] {
        csv.push_str(&format!("{w},{},{}\n", n.re, n.im));
    }
    Material::from_nk_csv(name, name, &csv).map_err(Error::from)
}
