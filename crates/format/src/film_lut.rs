//! Table kind `film-lut`: pre-integrated thin-film colour over incidence angle × film
//! thickness × film index, for a fixed ambient, base and optional fixed layers under the film.
//!
//! # What every channel holds
//!
//! Texel (x, y, z) holds the colour, in the recipe's output space (linear RGB or XYZ,
//! illuminant- and observer-specific, a perfect reflector = (1, 1, 1) in RGB), of the
//! unpolarised spectral reflectance R(λ) — and, in a second table, transmittance T(λ) into
//! the base — of the stack `ambient | film(n, d) | under… | base`, integrated exactly over
//! 360–830 nm ([`nacre_optics::SpectralRule`]), at
//!
//! * x: cos θ = tₓ² (θ the incidence angle in the ambient; the square mapping puts texels
//!   where Fresnel terms change fastest, near grazing incidence);
//! * y: the film's optical path difference Δ = 2 d √(n² − n₀² sin²θ) = t_y · Δ_max, with
//!   Δ_max = 2 d_max n_max. Interference depends on thickness only through Δ, so at fixed
//!   Δ the colour varies slowly with θ and n and trilinear interpolation stays accurate
//!   where a plain thickness axis would alias along the index axis;
//! * z: the film's real index through its normal wave-vector component
//!   q = √(n² − n₀² sin²θ) = n cos θ_film, as t_z = √((q − q_min) / (q_max − q_min)) with
//!   q_min/max(θ) = √(n_min/max² − n₀² sin²θ). The Fresnel coefficients are smooth functions
//!   of q; the square root crowds texels near q_min, where a film nearly index-matched to the
//!   ambient changes its reflection fastest (most of all near grazing incidence, where
//!   q_min → 0). Measured on the default tables, this mapping cuts the worst ΔE2000 of a
//!   linear index axis with the same texel count by a factor of about 3.
//!
//! # Over a slab
//!
//! When a fixed layer is an incoherent slab (the manifest's `under_incoherent`: a lens or
//! a window pane, its back face coated or bare, the base what lies behind the pane) the
//! same channels hold the *whole pane's* colour: R(λ) is the front's reflectance plus every
//! return from the slab's back face, summed in intensity (Byrnes, arXiv:1603.02720, §4;
//! `nacre_optics::incoherent`), and T(λ) what leaves through the back. Axes and lookup are
//! unchanged; a renderer draws the pane as one thin-walled surface, its back face already
//! in the table.
//!
//! # Texel-centre convention (the same in `shaders/`)
//!
//! For an axis with `count` texels, texel i holds the value at t = i / (count − 1), so both
//! ends of every range are sampled exactly. A sampler reaches t at texture coordinate
//! u = (t (count − 1) + 0.5) / count, and linear filtering between texel centres then
//! reproduces [`FilmLut::lookup`]. Coordinates outside [0, 1] clamp to the edge.
//!
//! # How a shader rebuilds the colour
//!
//! ```text
//! cos_t = dot(n, v);                    d = film thickness (nm); n_f = film index
//! opd   = 2 d sqrt(n_f² − n0² (1 − cos_t²))
//! q(n)  = sqrt(n² − n0² (1 − cos_t²))
//! uvw   = texel_coord(sqrt(cos_t), opd / opd_max, sqrt((q(n_f) − q(n_min)) / (q(n_max) − q(n_min))))
//! reflectance_rgb = textureSample(reflectance, trilinear, uvw).rgb
//! ```
//!
//! # Atlas layout
//!
//! Files store the 3-D table as a 2-D atlas: width = count(cos θ), height = count(Δ) ×
//! count(n); slice z (one film index) occupies rows [z·count(Δ), (z+1)·count(Δ)), row y of
//! the slice holding Δ index y, top row first ([`crate::table_io`]).

use crate::error::{Error, Result};
use crate::table_io::Table3;
use serde::{Deserialize, Serialize};

/// Cosines below this are evaluated at this value (θ → 90°, where every stack reflects
/// totally and the angle itself is excluded by the solver).
pub const MIN_COS_THETA: f64 = 1e-6;

/// Axes of a film LUT: counts and ranges, with the forward (physical → t ∈ [0, 1]) and
/// inverse (t → physical) mappings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FilmLutAxes {
    /// Texels along cos θ (x).
    pub cos_theta_count: usize,
    /// Texels along the optical path difference (y).
    pub opd_count: usize,
    /// Texels along the film index (z).
    pub ior_count: usize,
    /// Thickness range covered, nm (the table holds Δ up to 2 d_max n_max).
    pub thickness_min_nm: f64,
    /// Largest film thickness, nm.
    pub thickness_max_nm: f64,
    /// Smallest film index.
    pub ior_min: f64,
    /// Largest film index.
    pub ior_max: f64,
    /// The (real, constant) ambient index n₀.
    pub ambient_index: f64,
}

impl FilmLutAxes {
    /// Δ_max = 2 d_max n_max, nm.
    pub fn opd_max_nm(&self) -> f64 {
        2.0 * self.thickness_max_nm * self.ior_max
    }

    /// Optical path difference Δ = 2 d √(n² − n₀² sin²θ), nm.
    pub fn opd_nm(&self, cos_theta: f64, thickness_nm: f64, film_ior: f64) -> f64 {
        let sin2 = (1.0 - cos_theta * cos_theta).max(0.0);
        let a = self.ambient_index;
        2.0 * thickness_nm * (film_ior * film_ior - a * a * sin2).max(0.0).sqrt()
    }

    /// Normal component q = √(n² − n₀² sin²θ) of a film of index `film_ior`.
    pub fn film_q(&self, cos_theta: f64, film_ior: f64) -> f64 {
        let sin2 = (1.0 - cos_theta * cos_theta).max(0.0);
        (film_ior * film_ior - self.ambient_index * self.ambient_index * sin2)
            .max(0.0)
            .sqrt()
    }

    /// Forward mapping: physical (cos θ, d, n) → normalised t ∈ [0, 1]³ (clamped).
    pub fn forward(&self, cos_theta: f64, thickness_nm: f64, film_ior: f64) -> [f64; 3] {
        let c = cos_theta.clamp(0.0, 1.0);
        let tx = c.sqrt();
        let ty = self.opd_nm(c, thickness_nm, film_ior) / self.opd_max_nm();
        let (q_min, q_max) = (self.film_q(c, self.ior_min), self.film_q(c, self.ior_max));
        let tz = if q_max > q_min {
            ((self.film_q(c, film_ior) - q_min) / (q_max - q_min))
                .max(0.0)
                .sqrt()
        } else {
            0.0
        };
        [tx, ty, tz].map(|t| {
            if t.is_finite() {
                t.clamp(0.0, 1.0)
            } else {
                0.0
            }
        })
    }

    /// Inverse mapping: t → (cos θ, Δ in nm, n).
    pub fn inverse(&self, t: [f64; 3]) -> (f64, f64, f64) {
        let c = t[0] * t[0];
        let (q_min, q_max) = (self.film_q(c, self.ior_min), self.film_q(c, self.ior_max));
        let q = q_min + t[2] * t[2] * (q_max - q_min);
        let sin2 = 1.0 - c * c;
        let n = (q * q + self.ambient_index * self.ambient_index * sin2).sqrt();
        (c, t[1] * self.opd_max_nm(), n)
    }

    /// t of texel `i` of an axis with `count` texels: i / (count − 1) (0 when count = 1).
    pub fn texel_t(i: usize, count: usize) -> f64 {
        if count <= 1 {
            0.0
        } else {
            i as f64 / (count - 1) as f64
        }
    }

    /// Texture coordinate that samples t on an axis of `count` texels:
    /// u = (t (count − 1) + 0.5) / count.
    pub fn texture_coordinate(t: f64, count: usize) -> f64 {
        (t * (count.max(1) - 1) as f64 + 0.5) / count.max(1) as f64
    }

    /// Physical parameters of texel (x, y, z): (cos θ, thickness nm, n).
    pub fn texel_parameters(&self, x: usize, y: usize, z: usize) -> (f64, f64, f64) {
        let t = [
            Self::texel_t(x, self.cos_theta_count),
            Self::texel_t(y, self.opd_count),
            Self::texel_t(z, self.ior_count),
        ];
        let t = [t[0].max(MIN_COS_THETA.sqrt()), t[1], t[2]];
        let (cos_theta, opd, n) = self.inverse(t);
        let q = self.film_q(cos_theta, n);
        (cos_theta, if opd > 0.0 { opd / (2.0 * q) } else { 0.0 }, n)
    }
}

/// A film LUT in memory: axes plus reflectance (and transmittance) tables.
#[derive(Clone, Debug)]
pub struct FilmLut {
    /// The axes.
    pub axes: FilmLutAxes,
    /// Reflectance colour per texel.
    pub reflectance: Table3,
    /// Transmittance colour per texel, when the base transmits.
    pub transmittance: Option<Table3>,
}

impl FilmLut {
    /// Trilinear lookup in `table` at physical (cos θ, d, n), exactly as a GPU sampler with
    /// linear filtering and clamp-to-edge addressing at the texture coordinates of the
    /// module docs (without the GPU's reduced-precision filter weights).
    pub fn lookup(
        axes: &FilmLutAxes,
        table: &Table3,
        cos_theta: f64,
        thickness_nm: f64,
        film_ior: f64,
    ) -> [f64; 3] {
        let t = axes.forward(cos_theta, thickness_nm, film_ior);
        let counts = [table.nx, table.ny, table.nz];
        let mut i0 = [0usize; 3];
        let mut f = [0.0f64; 3];
        for a in 0..3 {
            let pos = t[a] * (counts[a].max(1) - 1) as f64;
            let i = (pos.floor() as usize).min(counts[a].saturating_sub(2));
            i0[a] = if counts[a] > 1 { i } else { 0 };
            f[a] = if counts[a] > 1 {
                pos - i0[a] as f64
            } else {
                0.0
            };
        }
        let mut out = [0.0f64; 3];
        for corner in 0..8 {
            let mut w = 1.0;
            let mut idx = [0usize; 3];
            for a in 0..3 {
                let up = (corner >> a) & 1 == 1;
                if up && counts[a] <= 1 {
                    w = 0.0;
                }
                idx[a] = i0[a] + usize::from(up && counts[a] > 1);
                w *= if up { f[a] } else { 1.0 - f[a] };
            }
            if w == 0.0 {
                continue;
            }
            let v = table.texel(idx[0], idx[1], idx[2]);
            for c in 0..3 {
                out[c] += w * f64::from(v[c]);
            }
        }
        out
    }
}

/// Checks the axes of a recipe; `context` names the recipe.
pub fn validate_axes(axes: &FilmLutAxes, context: &str, max_texels: u64) -> Result<()> {
    let err = |message: String| Error::Invalid {
        context: context.to_string().into(),
        message: message.into(),
    };
    for (name, count) in [
        ("cos_theta_count", axes.cos_theta_count),
        ("opd_count", axes.opd_count),
        ("film_ior_count", axes.ior_count),
    ] {
        if count == 0 || (count < 2 && name != "film_ior_count") {
            return Err(err(format!("{name} = {count}: needs at least 2 texels")));
        }
    }
    if !(axes.thickness_max_nm > 0.0 && axes.thickness_max_nm.is_finite()) {
        return Err(err(format!(
            "thickness_nm maximum {} must be positive",
            axes.thickness_max_nm
        )));
    }
    if !(axes.thickness_min_nm >= 0.0 && axes.thickness_min_nm < axes.thickness_max_nm) {
        return Err(err(format!(
            "thickness_nm range [{}, {}] must satisfy 0 ≤ min < max",
            axes.thickness_min_nm, axes.thickness_max_nm
        )));
    }
    if !(axes.ior_min > 0.0 && axes.ior_max >= axes.ior_min && axes.ior_max.is_finite()) {
        return Err(err(format!(
            "film_ior range [{}, {}] must satisfy 0 < min ≤ max",
            axes.ior_min, axes.ior_max
        )));
    }
    if axes.ior_min < axes.ambient_index {
        return Err(err(format!(
            "film_ior minimum {} is below the ambient index {}: the film would be evanescent at grazing angles, which a film-lut cannot parameterise",
            axes.ior_min, axes.ambient_index
        )));
    }
    // Saturating: absurd counts (up to usize::MAX each) must give this error, not overflow.
    let texels = (axes.cos_theta_count as u64)
        .saturating_mul(axes.opd_count as u64)
        .saturating_mul(axes.ior_count as u64);
    if texels > max_texels {
        return Err(Error::TooLarge {
            what: format!("{context}: texels (cos_theta × opd × film_ior)").into(),
            count: texels,
            limit: max_texels,
        });
    }
    Ok(())
}
