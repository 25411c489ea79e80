//! Diffraction by surface nanostructure: Stam's diffraction BRDF evaluated from the
//! discrete Fourier transforms of the powers of a height field (Stam 1999; Dhillon et al.
//! 2014; Single 2014).
//!
//! # Symbols
//!
//! | symbol | code | meaning |
//! |---|---|---|
//! | h(x, y) | [`HeightField`] | surface height, µm, mean removed |
//! | Δ | `pitch_um` | sample spacing of the height field, µm (square samples) |
//! | M = Mₓ·M_y | `nx * ny` | samples of the patch; Lₓ = MₓΔ, L_y = M_yΔ its size, µm |
//! | ω_i, ω_r | `omega_i`, `omega_r` | unit vectors towards the light and towards the viewer |
//! | (u, v, w) | `u, v, w` | −ω_i − ω_r (Single 2014, Eq. 1.5); w = −(cos θ_i + cos θ_r) < 0 |
//! | k = 2π/λ | `k_per_um` | vacuum wavenumber, rad/µm (λ in nm in the API) |
//! | Tₙ\[j\] | [`TaylorTerms`] | DFT{(i h)ⁿ}\[j\] / M, DC centred |
//! | σ_s | `sigma_s_um` | standard deviation of the Gaussian coherence window, µm (4σ_s = coherence diameter) |
//! | κ_j = 2π j / L | | angular spatial frequency of DFT bin j, rad/µm |
//!
//! # The model
//!
//! A plane wave from ω_i, scattered by the surface r = (x, y, h(x, y)) towards ω_r, carries
//! in the far field (Kirchhoff approximation, scalar waves, time dependence e^{−iωt}) the
//! amplitude of every surface point with the phase e^{ik(u, v, w)·r}. Stam (1999, "Diffraction
//! Shaders", SIGGRAPH) writes the resulting BRDF as (restated in Single 2014, Eq. 1.8–1.9)
//!
//! ```text
//! BRDF_λ(ω_i, ω_r) = k² F² G / (4π² A w²) · ⟨|P(ku, kv)|²⟩,
//! P(ku, kv) = ∬ e^{ikw h(x,y)} e^{ik(ux + vy)} dx dy,
//! G = (1 + ω_i·ω_r)² / (cos θ_i cos θ_r)
//! ```
//!
//! with A the illuminated (coherent) area, F the Fresnel coefficient and G Stam's geometry
//! term (the change of variables from the surface to its projection; no shadowing or
//! masking: the model assumes shallow structures, |∇h| ≪ 1). The sign of the exponent is
//! this module's convention: it follows from the physics above (`sign_convention` in
//! table manifests repeats it) and decides which side of a blazed grating is bright.
//!
//! **Taylor expansion** (Dhillon et al. 2014, "Interactive Diffraction from Biological
//! Nanostructures"): e^{ikwh} =
//! Σₙ (kw)ⁿ/n! (ih)ⁿ, so P = Σₙ (kw)ⁿ/n! · FT{(ih)ⁿ}: the transforms of the powers of h
//! do not depend on λ or on the directions and are computed once. Truncated after n = N,
//! the phase factor errs by at most |kwh|^{N+1}/(N+1)! at every point (the Lagrange
//! remainder of e^{ix}, |x| = |kwh|); [`taylor_remainder_bound`] and [`taylor_order_for`]
//! choose N for the shortest wavelength, |w| ≤ 2 and the largest |h|.
//!
//! **Discretisation.** On M samples the transform of the periodic extension of the patch
//! has Fourier-series coefficients Tₙ\[j\] = (1/M) Σ_m (ih_m)ⁿ e^{+iκ_j·x_m}, a DFT with a
//! positive exponent (an "inverse" FFT, unnormalised, divided by M here),
//! stored with DC at index ⌊Mₓ/2⌋, ⌊M_y/2⌋. Tₙ\[0\] is the mean of (ih)ⁿ; T₀ = δ_j0.
//!
//! **Coherence window** (Dhillon et al. 2014): only light within a spatial coherence
//! area interferes. Weighting the periodic surface by a Gaussian g(x) = e^{−|x|²/(2σ_s²)}
//! turns each DFT bin into a Gaussian lobe in frequency; normalised so that a flat mirror
//! gives P̃(0, 0) = 1,
//!
//! ```text
//! P̃(qₓ, q_y) = Σ_j P_j · exp(−σ_s² |q − κ_j|² / 2),   P_j = Σₙ (kw)ⁿ/n! · Tₙ[j]
//! ```
//!
//! summed over the bins within reach of the window (weights below 10⁻¹⁰ are dropped).
//! The thesis' default coherence diameter 4σ_s = 65 µm (filtered sunlight) is
//! [`DEFAULT_COHERENCE_DIAMETER_UM`]. A patch smaller than the window would impose its own
//! period on the result, so [`DiffractionSurface::check_sampling`] requires L ≥ 4σ_s
//! along every axis the surface varies along, and κ within the Nyquist limit π/Δ for the
//! directions and wavelengths asked for.
//!
//! **Relative reflectance.** Dividing the BRDF by that of a flat, perfectly reflecting
//! mirror in its specular direction (where G/w² = 1 and |P̃| = 1) removes k² and A:
//!
//! ```text
//! ρ(ω_i, ω_r, λ) = F²(θ_h) · G / w² · |P̃(ku, kv)|²
//! ```
//!
//! so a flat mirror gives exactly 1 in the specular direction. F² is 1 ([`FresnelTerm::Unity`],
//! a perfect reflector) or the unpolarised Fresnel reflectance of a bulk material at the
//! angle θ_h between ω_i and the half vector (Stam's choice, [`FresnelTerm::Index`]).
//!
//! The mean height is removed from every height field: it only multiplies P by the
//! global phase e^{ikw h̄}, which |P|² does not see, and it would inflate |h| in the
//! Taylor bound.
//!
//! # In-plane directions
//!
//! [`in_plane_directions`]: x runs across the grating lines, z along the normal, and the
//! plane of incidence is x–z. The incidence angle θ_i > 0 puts the light on the −x side,
//! ω_i = (−sin θ_i, 0, cos θ_i); the view angle θ_r > 0 puts the viewer on the +x side,
//! ω_r = (sin θ_r, 0, cos θ_r). The specular direction is θ_r = θ_i, and the orders of a
//! grating of period d lie at sin θ_m = sin θ_i + mλ/d (m ∈ ℤ).

use crate::colour::Colorimeter;
use crate::elementary;
use crate::error::{Error, Result};
use crate::fresnel::{Interface, normal_component};
use crate::microfacet::SplitMix64;
use ndarray::{Array2, Array3, ArrayView2, Axis, s};
use num_complex::Complex64 as C64;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The coherence diameter 4σ_s of filtered sunlight used by Dhillon et al. 2014, µm.
pub const DEFAULT_COHERENCE_DIAMETER_UM: f64 = 65.0;
/// Track pitch of a compact disc (Red Book), µm.
pub const CD_TRACK_PITCH_UM: f64 = 1.6;
/// Width of a CD pit across the track, µm.
pub const CD_PIT_WIDTH_UM: f64 = 0.5;
/// Depth of the CD-like pits, µm (about a quarter wave in polycarbonate).
pub const CD_PIT_DEPTH_UM: f64 = 0.1;
/// Channel bit length T of a CD at 1.2 m/s, µm: pits and lands are 3T to 11T long.
pub const CD_CHANNEL_BIT_UM: f64 = 0.2777;
/// Highest Taylor order N accepted: beyond it the series cancels catastrophically in f64
/// (terms reach e^{|kwh|}).
pub const MAX_TAYLOR_ORDER: usize = 80;
/// Most samples of a height field (2²⁴: 4096²).
pub const MAX_SAMPLES: usize = 1 << 24;
/// Window weights below this are dropped from the reconstruction of P̃.
const WINDOW_CUTOFF: f64 = 1e-10;

/// A height field on a square grid: `nx * ny` heights (x fastest, row y = 0 first), µm,
/// spaced `pitch_um` apart, mean removed. An axis with one sample is an axis the surface
/// does not vary along (a 1-D grating has `ny = 1`).
#[derive(Clone, Debug, PartialEq)]
pub struct HeightField {
    nx: usize,
    ny: usize,
    pitch_um: f64,
    heights_um: Vec<f64>,
    mean_removed_um: f64,
}

impl HeightField {
    /// A height field from `nx * ny` heights in µm (x fastest) spaced `pitch_um` µm apart.
    /// The mean height is subtracted (see the module docs) and kept in
    /// [`HeightField::mean_removed_um`].
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a non-positive or non-finite pitch, an empty or too large
    /// grid, or a grid whose size does not match the data; [`Error::NonFiniteHeight`] for a
    /// NaN or infinite height.
    pub fn new(nx: usize, ny: usize, pitch_um: f64, mut heights_um: Vec<f64>) -> Result<Self> {
        if !(pitch_um > 0.0 && pitch_um.is_finite()) {
            return Err(Error::OutOfRange {
                what: "height-field pitch (µm)",
                value: pitch_um,
                expected: "a finite positive length",
            });
        }
        let count = nx.saturating_mul(ny);
        if count == 0 || count > MAX_SAMPLES || count != heights_um.len() {
            return Err(Error::OutOfRange {
                what: "height-field samples",
                value: heights_um.len() as f64,
                expected: "nx × ny samples, 1 to 2²⁴",
            });
        }
        if let Some(i) = heights_um.iter().position(|h| !h.is_finite()) {
            return Err(Error::NonFiniteHeight {
                x: i % nx,
                y: i / nx,
            });
        }
        // Neumaier-compensated sum: the mean of a constant field is that constant exactly.
        let (mut sum, mut carry) = (0.0f64, 0.0f64);
        for &h in &heights_um {
            let t = sum + h;
            carry += if sum.abs() >= h.abs() {
                (sum - t) + h
            } else {
                (h - t) + sum
            };
            sum = t;
        }
        let mean = (sum + carry) / count as f64;
        for h in &mut heights_um {
            *h -= mean;
        }
        Ok(HeightField {
            nx,
            ny,
            pitch_um,
            heights_um,
            mean_removed_um: mean,
        })
    }

    /// Samples along x (across the grating lines).
    pub fn nx(&self) -> usize {
        self.nx
    }

    /// Samples along y.
    pub fn ny(&self) -> usize {
        self.ny
    }

    /// Sample spacing Δ, µm.
    pub fn pitch_um(&self) -> f64 {
        self.pitch_um
    }

    /// Heights, µm, mean removed, x fastest.
    pub fn heights_um(&self) -> &[f64] {
        &self.heights_um
    }

    /// The mean height that was subtracted, µm.
    pub fn mean_removed_um(&self) -> f64 {
        self.mean_removed_um
    }

    /// Patch size (Lₓ, L_y) = (MₓΔ, M_yΔ), µm.
    pub fn patch_um(&self) -> (f64, f64) {
        (
            self.nx as f64 * self.pitch_um,
            self.ny as f64 * self.pitch_um,
        )
    }

    /// The largest |h| (mean removed), µm.
    pub fn max_abs_height_um(&self) -> f64 {
        self.heights_um.iter().fold(0.0, |m, h| m.max(h.abs()))
    }

    /// A sinusoidal grating h(x) = a sin(2πx/d) sampled at xᵢ = iΔ, `nx` samples, one row
    /// (invariant along y). The orders are exact when `nx · pitch_um` is a multiple of d.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a non-positive period or pitch, a negative amplitude, or
    /// a bad size.
    pub fn sine_grating(
        period_um: f64,
        amplitude_um: f64,
        pitch_um: f64,
        nx: usize,
    ) -> Result<Self> {
        check_length("grating period (µm)", period_um)?;
        check_height("grating amplitude (µm)", amplitude_um)?;
        let h = (0..nx)
            .map(|i| amplitude_um * elementary::sin(2.0 * PI * i as f64 * pitch_um / period_um))
            .collect();
        Self::new(nx, 1, pitch_um, h)
    }

    /// A blazed (sawtooth) grating rising linearly from 0 to `height_um` over each period
    /// d and dropping back, sampled at pixel centres xᵢ = (i + ½)Δ, one row.
    ///
    /// # Errors
    /// As [`HeightField::sine_grating`].
    pub fn blazed_grating(
        period_um: f64,
        height_um: f64,
        pitch_um: f64,
        nx: usize,
    ) -> Result<Self> {
        check_length("grating period (µm)", period_um)?;
        check_height("blaze height (µm)", height_um)?;
        let h = (0..nx)
            .map(|i| {
                let t = (i as f64 + 0.5) * pitch_um / period_um;
                height_um * (t - t.floor())
            })
            .collect();
        Self::new(nx, 1, pitch_um, h)
    }

    /// A CD-like surface: tracks along y, [`CD_TRACK_PITCH_UM`] apart across x (the pitch
    /// is stretched to L/round(L/1.6) so that the patch tiles; exactly 1.6 µm when Lₓ is a
    /// multiple of it), each a seeded random sequence of pits and lands 3T–11T long
    /// ([`CD_CHANNEL_BIT_UM`], rescaled by at most a few per cent so that every track
    /// tiles along y), pits [`CD_PIT_WIDTH_UM`] wide and `depth_um` deep, rasterised with
    /// exact box-filter coverage. Deterministic for a given seed.
    ///
    /// # Errors
    /// As [`HeightField::new`]; [`Error::OutOfRange`] when the patch is narrower than one
    /// track or shorter than one pit and land, or the pitch exceeds half a pit's width.
    pub fn cd_tracks(
        nx: usize,
        ny: usize,
        pitch_um: f64,
        depth_um: f64,
        seed: u64,
    ) -> Result<Self> {
        check_length("height-field pitch (µm)", pitch_um)?;
        check_height("pit depth (µm)", depth_um)?;
        // Two samples across a pit at least: coarser samples cannot show the pits (and a
        // patch of millimetres would hold billions of them to rasterise).
        if pitch_um > 0.5 * CD_PIT_WIDTH_UM {
            return Err(Error::OutOfRange {
                what: "CD height-field pitch (µm)",
                value: pitch_um,
                expected: "at most 0.25 µm: two samples across a 0.5 µm pit",
            });
        }
        let (lx, ly) = (nx as f64 * pitch_um, ny as f64 * pitch_um);
        if lx < CD_TRACK_PITCH_UM || ly < 22.0 * CD_CHANNEL_BIT_UM {
            return Err(Error::OutOfRange {
                what: "CD patch size (µm)",
                value: lx.min(ly),
                expected: "at least one track pitch (1.6 µm) across and 6.1 µm along the tracks",
            });
        }
        let tracks = (lx / CD_TRACK_PITCH_UM).round().max(1.0) as usize;
        let track_pitch = lx / tracks as f64;
        let mut h = vec![0.0; nx * ny];
        // Overlap of [a, b) with pixel i's interval [iΔ, (i+1)Δ), in pixel units.
        let cover = |a: f64, b: f64, out: &mut [f64], wrap: f64| {
            for shift in [-wrap, 0.0, wrap] {
                let (a, b) = ((a + shift) / pitch_um, (b + shift) / pitch_um);
                let lo = a.floor().max(0.0) as usize;
                let hi = (b.ceil().max(0.0) as usize).min(out.len());
                for (i, o) in out.iter_mut().enumerate().take(hi).skip(lo) {
                    let (p0, p1) = (i as f64, i as f64 + 1.0);
                    *o += (b.min(p1) - a.max(p0)).max(0.0);
                }
            }
        };
        for t in 0..tracks {
            let mut rng = SplitMix64::stream(seed, t as u64);
            let centre = (t as f64 + 0.5) * track_pitch;
            let mut cov_x = vec![0.0; nx];
            cover(
                centre - 0.5 * CD_PIT_WIDTH_UM,
                centre + 0.5 * CD_PIT_WIDTH_UM,
                &mut cov_x,
                lx,
            );
            // Alternating pit, land, pit, … lengths; an even count so that the track tiles.
            let mut lengths = Vec::new();
            let mut total = 0.0;
            while total < ly || lengths.len() % 2 == 1 {
                let run = 3 + (rng.next_u64() % 9) as usize; // 3T … 11T
                let l = run as f64 * CD_CHANNEL_BIT_UM;
                lengths.push(l);
                total += l;
            }
            let scale = ly / total;
            let mut y = rng.next_f64() * ly;
            let mut cov_y = vec![0.0; ny];
            for (s, l) in lengths.iter().enumerate() {
                let l = l * scale;
                if s % 2 == 0 {
                    let a = y.rem_euclid(ly);
                    cover(a, a + l, &mut cov_y, ly);
                }
                y += l;
            }
            // The few columns the track's pits cover.
            let columns: Vec<(usize, f64)> = cov_x
                .iter()
                .enumerate()
                .filter(|(_, c)| **c != 0.0)
                .map(|(i, c)| (i, *c))
                .collect();
            for (iy, cy) in cov_y.iter().enumerate() {
                if *cy == 0.0 {
                    continue;
                }
                for &(ix, cx) in &columns {
                    h[iy * nx + ix] -= depth_um * cx * cy;
                }
            }
        }
        Self::new(nx, ny, pitch_um, h)
    }

    /// Stam's random bumps (after Stam 1999): `count` = round(fill · LₓL_y / (πr²)) bumps
    /// of radius r and height H at seeded uniform random positions, each a smooth cap
    /// H cos²(πρ/(2r)) for ρ < r, summed with periodic wrap-around so that the patch tiles.
    ///
    /// # Errors
    /// As [`HeightField::new`]; [`Error::OutOfRange`] for a non-positive radius or one
    /// below the pitch, a negative height, or a fill outside (0, 10].
    #[allow(clippy::too_many_arguments)]
    pub fn random_bumps(
        nx: usize,
        ny: usize,
        pitch_um: f64,
        radius_um: f64,
        height_um: f64,
        fill: f64,
        seed: u64,
    ) -> Result<Self> {
        check_length("height-field pitch (µm)", pitch_um)?;
        check_length("bump radius (µm)", radius_um)?;
        check_height("bump height (µm)", height_um)?;
        if !(fill > 0.0 && fill <= 10.0) {
            return Err(Error::OutOfRange {
                what: "bump fill factor",
                value: fill,
                expected: "a number in (0, 10]",
            });
        }
        // A bump spans two samples at least: smaller ones are not resolved (and their
        // count, fill · area / (π r²), would grow without bound).
        if radius_um < pitch_um {
            return Err(Error::OutOfRange {
                what: "bump radius (µm)",
                value: radius_um,
                expected: "at least the height-field pitch: a bump must span two samples",
            });
        }
        let (lx, ly) = (nx as f64 * pitch_um, ny as f64 * pitch_um);
        let count = (fill * lx * ly / (PI * radius_um * radius_um)).round() as usize;
        let mut rng = SplitMix64::stream(seed, 0);
        let mut h = vec![0.0; nx * ny];
        // Pixels visited per bump along each axis: the disc's span, or every pixel once.
        let span = |n: usize| (2 * (radius_um / pitch_um).ceil() as i64 + 1).min(n as i64);
        let (sx, sy) = (span(nx), span(ny));
        for _ in 0..count {
            let (cx, cy) = (rng.next_f64() * lx, rng.next_f64() * ly);
            let (px, py) = ((cx / pitch_um) as i64, (cy / pitch_um) as i64);
            for dy in -(sy / 2)..sy - sy / 2 {
                for dx in -(sx / 2)..sx - sx / 2 {
                    let ix = (px + dx).rem_euclid(nx as i64) as usize;
                    let iy = (py + dy).rem_euclid(ny as i64) as usize;
                    // Minimum-image distance from the pixel centre to the bump centre.
                    let wrap = |d: f64, l: f64| d - l * (d / l).round();
                    let ddx = wrap((ix as f64 + 0.5) * pitch_um - cx, lx);
                    let ddy = wrap((iy as f64 + 0.5) * pitch_um - cy, ly);
                    let rho = (ddx * ddx + ddy * ddy).sqrt();
                    if rho < radius_um {
                        let c = elementary::cos(0.5 * PI * rho / radius_um);
                        h[iy * nx + ix] += height_um * c * c;
                    }
                }
            }
        }
        Self::new(nx, ny, pitch_um, h)
    }
}

fn check_length(what: &'static str, v: f64) -> Result<()> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(Error::OutOfRange {
            what,
            value: v,
            expected: "a finite positive length",
        })
    }
}

fn check_height(what: &'static str, v: f64) -> Result<()> {
    if v >= 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(Error::OutOfRange {
            what,
            value: v,
            expected: "a finite non-negative height",
        })
    }
}

/// The Lagrange bound on the Taylor remainder of the phase factor:
/// |e^{ix} − Σ_{n=0}^{N} (ix)ⁿ/n!| ≤ |x|^{N+1}/(N+1)! for real x, with |x| ≤ `x_max`.
pub fn taylor_remainder_bound(x_max: f64, order: usize) -> f64 {
    let x = x_max.abs();
    (1..=order + 1).fold(1.0, |b, n| b * x / n as f64)
}

/// The smallest order N whose [`taylor_remainder_bound`] at `x_max` = max |k w h| is at
/// most `tolerance`, and that bound.
///
/// # Errors
/// [`Error::TaylorOrder`] when N would exceed [`MAX_TAYLOR_ORDER`] (the structure is too
/// tall for the expansion at this wavelength), [`Error::OutOfRange`] for a tolerance
/// outside (0, 1) or a non-finite `x_max`.
pub fn taylor_order_for(x_max: f64, tolerance: f64) -> Result<(usize, f64)> {
    if !(tolerance > 0.0 && tolerance < 1.0) {
        return Err(Error::OutOfRange {
            what: "Taylor tolerance",
            value: tolerance,
            expected: "a number in (0, 1)",
        });
    }
    if !x_max.is_finite() {
        return Err(Error::OutOfRange {
            what: "max |k w h|",
            value: x_max,
            expected: "a finite number",
        });
    }
    (0..=MAX_TAYLOR_ORDER)
        .map(|n| (n, taylor_remainder_bound(x_max, n)))
        .find(|&(_, b)| b <= tolerance)
        .ok_or(Error::TaylorOrder {
            x_max,
            tolerance,
            max_order: MAX_TAYLOR_ORDER,
        })
}

/// max |k w h| for the shortest wavelength `wavelength_min_nm`, |w| ≤ `w_max` (2 at
/// most: normal incidence and view) and the field's largest |h|.
pub fn max_phase(field: &HeightField, wavelength_min_nm: f64, w_max: f64) -> f64 {
    k_per_um(wavelength_min_nm) * w_max * field.max_abs_height_um()
}

/// The vacuum wavenumber k = 2π/λ in rad/µm for λ in nm.
pub fn k_per_um(wavelength_nm: f64) -> f64 {
    2.0 * PI / (wavelength_nm * 1e-3)
}

/// The DFTs of the powers of a height field: Tₙ\[j\] = (1/M) Σ_m (i h_m)ⁿ e^{+iκ_j·x_m}
/// for n = 0 … N, DC centred (module docs). Computed in f64 by `dft` (the same bits on
/// every machine).
#[derive(Clone, Debug, PartialEq)]
pub struct TaylorTerms {
    nx: usize,
    ny: usize,
    pitch_um: f64,
    order: usize,
    /// Bin-major: `data[[sy, sx, n]]`, shape (ny, nx, order + 1).
    data: Array3<C64>,
}

impl TaylorTerms {
    /// Computes T₀ … T_N of `field` (terms in parallel; each term is an independent
    /// sequence of FFTs, so the result does not depend on the thread count).
    pub fn compute(field: &HeightField, order: usize) -> Self {
        let (nx, ny) = (field.nx, field.ny);
        let m = (nx * ny) as f64;
        let fx = dft::Dft::new(nx);
        let fy = dft::Dft::new(ny);
        let heights =
            ArrayView2::from_shape((ny, nx), &field.heights_um[..]).expect("nx × ny heights");
        let terms: Vec<Vec<C64>> = (0..=order)
            .into_par_iter()
            .map(|n| {
                if n == 0 {
                    // (ih)⁰ = 1: T₀ = δ_j0 exactly (a transform would add rounding noise).
                    let mut out = vec![C64::new(0.0, 0.0); nx * ny];
                    out[(ny / 2) * nx + nx / 2] = C64::new(1.0, 0.0);
                    return out;
                }
                // iⁿ hⁿ
                let phase = [
                    C64::new(1.0, 0.0),
                    C64::new(0.0, 1.0),
                    C64::new(-1.0, 0.0),
                    C64::new(0.0, -1.0),
                ][n % 4];
                // Rows y of x samples: FFT along x, one contiguous row at a time.
                let mut rows = heights.mapv(|h| phase * elementary::powi(h, n as i32));
                fx.process(rows.as_slice_mut().expect("standard layout"));
                // Columns x of y samples (the transpose, contiguous): FFT along y.
                let mut columns = rows.t().as_standard_layout().into_owned();
                fy.process(columns.as_slice_mut().expect("standard layout"));
                // Back to x fastest, DC centred, divided by M.
                let mut out = Array2::from_elem((ny, nx), C64::new(0.0, 0.0));
                for ((x, y), v) in columns.indexed_iter() {
                    out[[(y + ny / 2) % ny, (x + nx / 2) % nx]] = v / m;
                }
                out.into_raw_vec_and_offset().0
            })
            .collect();
        Self::from_terms(nx, ny, field.pitch_um, &terms).expect("consistent terms")
    }

    /// Terms from their layers (`terms[n][sy * nx + sx]`, DC centred), e.g. read back from
    /// a baked table.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for no terms, a layer of the wrong size, or a bad pitch.
    pub fn from_terms(nx: usize, ny: usize, pitch_um: f64, terms: &[Vec<C64>]) -> Result<Self> {
        check_length("height-field pitch (µm)", pitch_um)?;
        let count = nx * ny;
        if terms.is_empty() || count == 0 || terms.iter().any(|t| t.len() != count) {
            return Err(Error::OutOfRange {
                what: "Taylor-term layers",
                value: terms.len() as f64,
                expected: "at least one layer of nx × ny bins",
            });
        }
        let order = terms.len() - 1;
        let data = Array3::from_shape_fn((ny, nx, order + 1), |(sy, sx, n)| terms[n][sy * nx + sx]);
        Ok(TaylorTerms {
            nx,
            ny,
            pitch_um,
            order,
            data,
        })
    }

    /// Bins along x and y.
    pub fn size(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// Sample spacing Δ of the height field, µm.
    pub fn pitch_um(&self) -> f64 {
        self.pitch_um
    }

    /// The Taylor order N (terms T₀ … T_N).
    pub fn order(&self) -> usize {
        self.order
    }

    /// Term n as a layer, DC centred, x fastest.
    pub fn layer(&self, n: usize) -> Vec<C64> {
        self.data.slice(s![.., .., n]).iter().copied().collect()
    }

    /// Tₙ at frequency (jₓ, j_y), jₓ ∈ [−⌊Mₓ/2⌋, ⌈Mₓ/2⌉ − 1]; `None` outside.
    pub fn bin(&self, n: usize, jx: i64, jy: i64) -> Option<C64> {
        let (sy, sx) = self.index(jx, jy)?;
        (n <= self.order).then(|| self.data[[sy, sx, n]])
    }

    /// The (row, column) = (sy, sx) of frequency (jₓ, j_y) in the DC-centred arrays.
    fn index(&self, jx: i64, jy: i64) -> Option<(usize, usize)> {
        let sx = jx + (self.nx / 2) as i64;
        let sy = jy + (self.ny / 2) as i64;
        (sx >= 0 && sy >= 0 && (sx as usize) < self.nx && (sy as usize) < self.ny)
            .then_some((sy as usize, sx as usize))
    }

    /// The Taylor sum P_j = Σₙ (kw)ⁿ/n! Tₙ\[j\] at every bin (DC centred, x fastest): the
    /// DFT coefficients of e^{ikwh} up to the truncation.
    pub fn series(&self, kw: f64) -> Vec<C64> {
        let c = taylor_coefficients(kw, self.order);
        self.data
            .lanes(Axis(2))
            .into_iter()
            .map(|t| t.iter().zip(&c).map(|(t, c)| t * c).sum())
            .collect()
    }

    #[inline]
    fn sum_at(&self, (sy, sx): (usize, usize), c: &[f64]) -> C64 {
        self.bin_terms(sy, sx)
            .iter()
            .zip(c)
            .map(|(t, c)| t * c)
            .sum()
    }

    /// T₀ … T_N of bin (sy, sx): a plain slice of the standard-layout array (an ndarray
    /// `slice` per bin costs more than the sums over it in the hot loops).
    #[inline]
    fn bin_terms(&self, sy: usize, sx: usize) -> &[C64] {
        let n = self.order + 1;
        let start = (sy * self.nx + sx) * n;
        let data = self
            .data
            .as_slice()
            .expect("built by Array3::from_shape_fn: standard layout");
        &data[start..start + n]
    }
}

/// (kw)ⁿ/n! for n = 0 … order.
fn taylor_coefficients(kw: f64, order: usize) -> Vec<f64> {
    let mut c = Vec::with_capacity(order + 1);
    let mut v = 1.0;
    for n in 0..=order {
        if n > 0 {
            v *= kw / n as f64;
        }
        c.push(v);
    }
    c
}

/// The Fresnel factor F² of Stam's BRDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FresnelTerm {
    /// F = 1: a perfect reflector (the default; relative reflectance of the structure alone).
    Unity,
    /// The unpolarised Fresnel reflectance (|r_s|² + |r_p|²)/2 from air into a bulk
    /// material of this complex index, at the angle θ_h between ω_i and the half vector.
    Index(C64),
}

impl FresnelTerm {
    /// F² at cos θ_h.
    pub fn reflectance(&self, cos_theta_h: f64) -> f64 {
        match *self {
            FresnelTerm::Unity => 1.0,
            FresnelTerm::Index(n) => {
                let cos = cos_theta_h.clamp(0.0, 1.0);
                let beta = (1.0 - cos * cos).sqrt();
                let one = C64::new(1.0, 0.0);
                let i = Interface::new(one, C64::new(cos, 0.0), n, normal_component(n, beta));
                0.5 * (i.r_s.norm_sqr() + i.r_p.norm_sqr())
            }
        }
    }
}

/// Light and view directions in the plane of incidence (module docs): θ_i > 0 puts the
/// light on the −x side, θ_r > 0 the viewer on the +x side; degrees.
pub fn in_plane_directions(incidence_deg: f64, view_deg: f64) -> ([f64; 3], [f64; 3]) {
    let (si, ci) = elementary::sin_cos(incidence_deg.to_radians());
    let (sr, cr) = elementary::sin_cos(view_deg.to_radians());
    ([-si, 0.0, ci], [sr, 0.0, cr])
}

/// Stam's G / w² = (1 + ω_i·ω_r)² / (cos θ_i cos θ_r (cos θ_i + cos θ_r)²): 1 in the
/// specular direction; 0 when either direction is at or below the horizon.
pub fn geometry_over_w2(omega_i: [f64; 3], omega_r: [f64; 3]) -> f64 {
    let (ci, cr) = (omega_i[2], omega_r[2]);
    if !(ci > 0.0 && cr > 0.0) {
        return 0.0;
    }
    let d = omega_i[0] * omega_r[0] + omega_i[1] * omega_r[1] + omega_i[2] * omega_r[2];
    let w = ci + cr;
    (1.0 + d) * (1.0 + d) / (ci * cr * w * w)
}

/// A height field's Taylor terms with a Gaussian coherence window: evaluates P̃ and the
/// relative reflectance (module docs).
#[derive(Clone, Debug)]
pub struct DiffractionSurface {
    terms: TaylorTerms,
    sigma_s_um: f64,
    /// Bins within reach of the window along x and y.
    reach: (i64, i64),
}

impl DiffractionSurface {
    /// The surface of `terms` seen through a Gaussian coherence window of standard
    /// deviation `sigma_s_um` µm (4σ_s = coherence diameter).
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a non-positive or non-finite σ_s.
    pub fn new(terms: TaylorTerms, sigma_s_um: f64) -> Result<Self> {
        check_length("coherence window σ_s (µm)", sigma_s_um)?;
        // σ|q − κ| beyond which w < cutoff
        let cut = (2.0 * elementary::ln(1.0 / WINDOW_CUTOFF)).sqrt();
        let reach = |n: usize| {
            let l = n as f64 * terms.pitch_um;
            let dk = 2.0 * PI / l;
            ((cut / (sigma_s_um * dk)).ceil() as i64).min(n as i64)
        };
        let reach = (reach(terms.nx), reach(terms.ny));
        Ok(DiffractionSurface {
            terms,
            sigma_s_um,
            reach,
        })
    }

    /// The Taylor terms.
    pub fn terms(&self) -> &TaylorTerms {
        &self.terms
    }

    /// σ_s, µm.
    pub fn sigma_s_um(&self) -> f64 {
        self.sigma_s_um
    }

    /// Checks the sampling against the coherence window and the Nyquist limit: the patch
    /// must span at least 4σ_s along every axis with more than one sample, and the
    /// largest spatial frequency k·max(|u|, |v|) reached at `wavelength_min_nm` with
    /// |u|, |v| ≤ `max_uv` must lie within the Nyquist limit π/Δ, i.e. Δ ≤ λ_min/(2·max_uv).
    ///
    /// # Errors
    /// [`Error::PatchTooSmall`] or [`Error::NyquistExceeded`].
    pub fn check_sampling(&self, wavelength_min_nm: f64, max_uv: f64) -> Result<()> {
        let (nx, ny) = self.terms.size();
        let d = 4.0 * self.sigma_s_um;
        for (axis, n) in [("x", nx), ("y", ny)] {
            let l = n as f64 * self.terms.pitch_um;
            if n > 1 && l < d * (1.0 - 1e-9) {
                return Err(Error::PatchTooSmall {
                    axis,
                    patch_um: l,
                    coherence_diameter_um: d,
                });
            }
        }
        let max_pitch_um = wavelength_min_nm * 1e-3 / (2.0 * max_uv);
        if self.terms.pitch_um > max_pitch_um * (1.0 + 1e-9) {
            return Err(Error::NyquistExceeded {
                pitch_um: self.terms.pitch_um,
                max_pitch_um,
                wavelength_nm: wavelength_min_nm,
                max_uv,
            });
        }
        Ok(())
    }

    /// P̃(ku, kv) for the Taylor sum at kw (module docs), normalised so that a flat mirror
    /// gives 1 at (0, 0). Bins beyond the height field's Nyquist limit are absent (0).
    pub fn transform(&self, wavelength_nm: f64, u: f64, v: f64, w: f64) -> C64 {
        let k = k_per_um(wavelength_nm);
        let c = taylor_coefficients(k * w, self.terms.order);
        self.transform_with(k * u, k * v, &|i| self.terms.sum_at(i, &c))
    }

    /// The windowed transforms of the terms alone, P̃ₙ(ku, kv) = Σ_j Tₙ\[j\]
    /// exp(−σ_s²|(ku, kv) − κ_j|²/2) for n = 0 … N, so that P̃ = Σₙ (kw)ⁿ/n! P̃ₙ (the
    /// building blocks of the integrated layout, [`integrated`]).
    pub fn transform_terms(&self, wavelength_nm: f64, u: f64, v: f64) -> Vec<C64> {
        let k = k_per_um(wavelength_nm);
        let order = self.terms.order;
        let mut out = vec![C64::new(0.0, 0.0); order + 1];
        let xs = self.axis_weights(k * u, true);
        let ys = self.axis_weights(k * v, false);
        for &(jy, wy) in &ys {
            for &(jx, wx) in &xs {
                if let Some((sy, sx)) = self.terms.index(jx, jy) {
                    let t = self.terms.bin_terms(sy, sx);
                    for (o, t) in out.iter_mut().zip(t) {
                        *o += t * (wx * wy);
                    }
                }
            }
        }
        out
    }

    /// The bins j within reach of spatial frequency `q` (rad/µm) along x (`along_x`) or
    /// y, with their window weights exp(−σ_s²(q − κ_j)²/2) ≥ 10⁻¹⁰, in increasing j.
    fn axis_weights(&self, q: f64, along_x: bool) -> Vec<(i64, f64)> {
        let t = &self.terms;
        let (n, reach) = if along_x {
            (t.nx, self.reach.0)
        } else {
            (t.ny, self.reach.1)
        };
        let s2 = self.sigma_s_um * self.sigma_s_um;
        let dk = 2.0 * PI / (n as f64 * t.pitch_um);
        let lo = -((n / 2) as i64);
        let hi = lo + n as i64 - 1;
        let j0 = (q / dk).round() as i64;
        let (a, b) = ((j0 - reach).max(lo), (j0 + reach).min(hi));
        (a..=b)
            .filter_map(move |j| {
                let d = q - j as f64 * dk;
                let wgt = elementary::exp(-0.5 * s2 * d * d);
                (wgt >= WINDOW_CUTOFF).then_some((j, wgt))
            })
            .collect()
    }

    /// Σ_j P_j exp(−σ²|q − κ_j|²/2) for bin values given by `p(index)`.
    fn transform_with(&self, qx: f64, qy: f64, p: &dyn Fn((usize, usize)) -> C64) -> C64 {
        let t = &self.terms;
        let xs = self.axis_weights(qx, true);
        let ys = self.axis_weights(qy, false);
        let mut sum = C64::new(0.0, 0.0);
        for &(jy, wy) in &ys {
            for &(jx, wx) in &xs {
                if let Some(i) = t.index(jx, jy) {
                    sum += p(i) * (wx * wy);
                }
            }
        }
        sum
    }

    /// The relative reflectance ρ = F²(θ_h) · G/w² · |P̃(ku, kv)|² (module docs): Stam's
    /// BRDF divided by that of a flat perfect mirror in its specular direction. 0 when
    /// either direction is at or below the horizon.
    pub fn relative_reflectance(
        &self,
        omega_i: [f64; 3],
        omega_r: [f64; 3],
        wavelength_nm: f64,
        fresnel: FresnelTerm,
    ) -> f64 {
        let g = geometry_over_w2(omega_i, omega_r);
        if g == 0.0 {
            return 0.0;
        }
        let [u, v, w] = [
            -omega_i[0] - omega_r[0],
            -omega_i[1] - omega_r[1],
            -omega_i[2] - omega_r[2],
        ];
        // cos θ_h = ω_i · h with h = −(u, v, w)/|(u, v, w)|.
        let cos_h =
            -(omega_i[0] * u + omega_i[1] * v + omega_i[2] * w) / (u * u + v * v + w * w).sqrt();
        fresnel.reflectance(cos_h) * g * self.transform(wavelength_nm, u, v, w).norm_sqr()
    }
}

/// CIE weights on a regular wavelength grid for colours of diffraction spectra:
/// XYZ = Σᵢ ρ(λᵢ) uᵢ with uᵢ = the colorimeter's 1 nm XYZ weights interpolated at λᵢ,
/// times the step, rescaled per component so that ρ ≡ 1 gives the illuminant white W_I
/// (the part of the CMFs outside the grid, below 10⁻⁴ of the total for 380–780 nm, is
/// folded back in). The output colour is M·XYZ ([`Colorimeter::output_from_xyz`]), so
/// ρ ≡ 1 is white (1, 1, 1) in an RGB space.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectralGrid {
    wavelengths_nm: Vec<f64>,
    xyz_weights: Vec<[f64; 3]>,
}

impl SpectralGrid {
    /// The grid `wavelengths_nm` (within 360–830 nm, increasing, at least two, evenly
    /// spaced: the step is taken from the first two) for `colorimeter`.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for fewer than two wavelengths or any outside 360–830 nm.
    pub fn new(colorimeter: &Colorimeter, wavelengths_nm: &[f64]) -> Result<Self> {
        if wavelengths_nm.len() < 2
            || wavelengths_nm.iter().any(|l| {
                !(*l >= crate::colour::SPECTRAL_MIN_NM && *l <= crate::colour::SPECTRAL_MAX_NM)
            })
        {
            return Err(Error::OutOfRange {
                what: "colour wavelengths (nm)",
                value: wavelengths_nm.first().copied().unwrap_or(f64::NAN),
                expected: "two or more wavelengths within 360–830 nm",
            });
        }
        let step = wavelengths_nm[1] - wavelengths_nm[0];
        let table = colorimeter.xyz_weights_1nm();
        let mut xyz_weights: Vec<[f64; 3]> = wavelengths_nm
            .iter()
            .map(|&l| {
                let x = l - crate::colour::SPECTRAL_MIN_NM;
                let i = (x.floor() as usize).min(table.len() - 2);
                let t = x - i as f64;
                std::array::from_fn(|c| ((1.0 - t) * table[i][c] + t * table[i + 1][c]) * step)
            })
            .collect();
        let white = colorimeter.white_xyz();
        for c in 0..3 {
            let s: f64 = xyz_weights.iter().map(|w| w[c]).sum();
            for w in &mut xyz_weights {
                w[c] *= white[c] / s;
            }
        }
        Ok(SpectralGrid {
            wavelengths_nm: wavelengths_nm.to_vec(),
            xyz_weights,
        })
    }

    /// The wavelengths, nm.
    pub fn wavelengths_nm(&self) -> &[f64] {
        &self.wavelengths_nm
    }

    /// XYZ (perfect reflector Y = 1) of values ρ(λᵢ) given in grid order.
    pub fn xyz(&self, values: &[f64]) -> [f64; 3] {
        let mut xyz = [0.0; 3];
        for (v, w) in values.iter().zip(&self.xyz_weights) {
            for c in 0..3 {
                xyz[c] += v * w[c];
            }
        }
        xyz
    }
}

mod dft;
pub mod integrated;

#[cfg(test)]
mod tests;
