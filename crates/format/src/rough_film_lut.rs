//! Table kind `rough-film-lut`: its axes, mappings, texture layout and the CPU lookup.
//!
//! How the table is baked is `nacre_bake::kinds::rough_film_lut`.
//!
//! # Axes and mappings (forward and inverse: [`RoughLutAxes`])
//!
//! | axis | count | t from the physical value | inverse |
//! |---|---|---|---|
//! | x: cos θ_o | `cos_theta_count` | t = √cos θ_o | cos θ_o = t² |
//! | y: Δ, nm | `opd_count` | t = Δ / Δ_max, Δ = 2 d q(n_f, c_ref(cos θ_o, α)), Δ_max = 2 d_max n_max | Δ = t Δ_max |
//! | film index | `film_ior_count` | t = √((n_f − n_min)/(n_max − n_min)) | n_f = n_min + t² (n_max − n_min) |
//! | roughness α | `alpha_count` | t = ln(α/α_min) / ln(α_max/α_min) | α = α_min (α_max/α_min)^t |
//!
//! q(n, cos θ) = √(n² − n₀² sin²θ) is the film's normal wave-vector component (as in
//! film-lut). Δ is the optical path difference at the kernel's mean microfacet cosine,
//! c_ref(cos θ_o, α) = cos θ_o + (2α − α²)(0.7 − 0.8 cos θ_o) ([`RoughLutAxes::reference_cos`],
//! a fit within ±0.05 of the kernel mean): the specular path (c_ref = cos θ_o) for smooth
//! films, where film-lut showed that at fixed Δ the colour varies slowly with index and
//! angle, moving to c ≈ 0.7–0.9 at α = 1 whatever the view. Referring Δ to the view cosine at
//! every α instead left errors of ΔE2000 1.7 at α ≈ 1 (neighbouring view-angle texels at the
//! same Δ then hold films of different thickness as the normal microfacets see them). Each α
//! block refers Δ to its own α, so a lookup computes t_y per block. Unlike film-lut's index axis,
//! this one does not depend on θ_o, so the film colours of step 2 are shared by every view
//! angle. The square root crowds texels near n_min, where a film nearly index-matched to the
//! ambient changes fastest; the logarithm in α spreads them over 0.02–0.3, where roughness
//! washes the fringes out (the spread of microfacet optical paths grows linearly with α).
//! Values outside the ranges clamp to them.
//!
//! # Texture layout and texel centres
//!
//! Per quantity one 3-D texture: width = count(cos θ_o), height = count(Δ), depth =
//! count(α) × count(n_f) in α-major blocks, slice z = i_α · count(n_f) + i_n. On every axis
//! texel i of `count` holds t = i / (count − 1), reached at texture coordinate
//! u = (t (count − 1) + 0.5) / count. Within one α block a linear sampler filters x, y and
//! the film index (the index coordinate w = (i_α count(n_f) + t_n (count(n_f) − 1) + 0.5) /
//! depth stays between the block's first and last texel centres, so filtering never mixes
//! blocks); the two α blocks around t_α are fetched separately and mixed:
//!
//! ```text
//! t  = forward(cos θ_o, α, d, n_f)                  // (t_x, t_y, t_n, t_α)
//! s  = t_α (count(α) − 1);  a₀ = min(⌊s⌋, count(α) − 2);  f = s − a₀
//! E  = mix(sample(a₀), sample(a₀ + 1), f)           // sample(a): trilinear within block a
//! environment specular = prefiltered_env(R, α) × E_r;  transmitted = … × E_t
//! ```
//!
//! `shaders/rough_lut_mapping.wgsl` mirrors this and [`RoughFilmLut::lookup`] does the same
//! on the CPU. The files: OpenEXR atlas (width = count(cos θ_o), height = count(Δ) × depth,
//! slice z at rows [z count(Δ), (z + 1) count(Δ)), [`crate::table_io`]) and KTX 2.0 3-D
//! `RGBA16F` textures with alpha 1 ([`crate::ktx2::film_lut_image`]).

use crate::error::{Error, Result};
use crate::film_lut::MIN_COS_THETA;
use crate::table_io::Table3;
use nacre_optics::elementary;
use serde::{Deserialize, Serialize};

/// Axes of a rough-film LUT, with the forward (physical → t ∈ [0, 1]) and inverse mappings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RoughLutAxes {
    /// Texels along cos θ_o (x, the texture width).
    pub cos_theta_count: usize,
    /// Texels along the optical path difference Δ at the reference cosine (y, the height).
    pub opd_count: usize,
    /// Texels along the film index within one α block.
    pub ior_count: usize,
    /// α blocks (the texture depth is `alpha_count * ior_count`).
    pub alpha_count: usize,
    /// Smallest film thickness, nm (the table covers Δ from 0).
    pub thickness_min_nm: f64,
    /// Largest film thickness d_max, nm.
    pub thickness_max_nm: f64,
    /// Smallest film index.
    pub ior_min: f64,
    /// Largest film index.
    pub ior_max: f64,
    /// Smallest GGX roughness α.
    pub alpha_min: f64,
    /// Largest GGX roughness α.
    pub alpha_max: f64,
    /// The (real, constant) ambient index n₀.
    pub ambient_index: f64,
    /// Relative index η = n_base / n₀ at 560 nm used to refract into the base, when the
    /// transmittance table is baked.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_eta: Option<f64>,
}

impl RoughLutAxes {
    /// Δ_max = 2 d_max n_max, nm.
    pub fn opd_max_nm(&self) -> f64 {
        2.0 * self.thickness_max_nm * self.ior_max
    }

    /// Normal component q = √(n² − n₀² sin²θ) of a film of index `film_ior` seen at
    /// `cos_theta`.
    pub fn film_q(&self, cos_theta: f64, film_ior: f64) -> f64 {
        let sin2 = (1.0 - cos_theta * cos_theta).max(0.0);
        (film_ior * film_ior - self.ambient_index * self.ambient_index * sin2)
            .max(0.0)
            .sqrt()
    }

    /// The microfacet cosine the Δ axis of an α block refers to:
    /// c_ref(cos θ_o, α) = cos θ_o + (2α − α²)(0.7 − 0.8 cos θ_o), a fit (within ±0.05)
    /// of the mean of c = ω_o·h under the reflection kernel (c_ref → cos θ_o as α → 0, the
    /// specular direction; 0.7–0.9 at α = 1 whatever the view). Clamped to [0, 1].
    pub fn reference_cos(cos_theta_o: f64, alpha: f64) -> f64 {
        let c = cos_theta_o.clamp(0.0, 1.0);
        let s = alpha.clamp(0.0, 1.0) * (2.0 - alpha.clamp(0.0, 1.0));
        (c + s * (0.7 - 0.8 * c)).clamp(0.0, 1.0)
    }

    /// Optical path difference of the Δ axis, Δ = 2 d q(n, c_ref(cos θ_o, α)), nm: the film's
    /// path at the kernel's mean microfacet, so that at fixed Δ the albedo varies slowly
    /// with view angle and index at every roughness.
    pub fn opd_nm(&self, cos_theta: f64, alpha: f64, thickness_nm: f64, film_ior: f64) -> f64 {
        2.0 * thickness_nm * self.film_q(Self::reference_cos(cos_theta, alpha), film_ior)
    }

    /// t of roughness α: ln(α/α_min) / ln(α_max/α_min) (0 when the range is one value).
    pub fn alpha_t(&self, alpha: f64) -> f64 {
        let span = elementary::ln(self.alpha_max / self.alpha_min);
        if span > 0.0 {
            elementary::ln(alpha / self.alpha_min) / span
        } else {
            0.0
        }
    }

    /// Forward mapping: physical (cos θ_o, α, d nm, n_f) → (t_x, t_y, t_n, t_α), each clamped
    /// to [0, 1]; non-finite values become 0.
    pub fn forward(
        &self,
        cos_theta: f64,
        alpha: f64,
        thickness_nm: f64,
        film_ior: f64,
    ) -> [f64; 4] {
        let c = cos_theta.clamp(0.0, 1.0);
        let tx = c.sqrt();
        let ty =
            self.opd_nm(c, alpha.max(self.alpha_min), thickness_nm, film_ior) / self.opd_max_nm();
        let span = self.ior_max - self.ior_min;
        let tn = if span > 0.0 {
            ((film_ior - self.ior_min) / span).max(0.0).sqrt()
        } else {
            0.0
        };
        let ta = self.alpha_t(alpha.max(self.alpha_min));
        [tx, ty, tn, ta].map(|t| {
            if t.is_finite() {
                t.clamp(0.0, 1.0)
            } else {
                0.0
            }
        })
    }

    /// Inverse mapping: t → (cos θ_o, Δ nm, n_f, α).
    pub fn inverse(&self, t: [f64; 4]) -> (f64, f64, f64, f64) {
        (
            t[0] * t[0],
            t[1] * self.opd_max_nm(),
            self.ior_min + t[2] * t[2] * (self.ior_max - self.ior_min),
            self.alpha_min * elementary::powf(self.alpha_max / self.alpha_min, t[3]),
        )
    }

    /// t of texel `i` on an axis of `count` texels: i / (count − 1) (0 when count = 1).
    pub fn texel_t(i: usize, count: usize) -> f64 {
        crate::film_lut::FilmLutAxes::texel_t(i, count)
    }

    /// Texture depth: `alpha_count * ior_count`.
    pub fn depth(&self) -> usize {
        self.alpha_count * self.ior_count
    }

    /// cos θ_o of texel column `x` (at least [`MIN_COS_THETA`]).
    pub fn texel_cos_theta(&self, x: usize) -> f64 {
        let t = Self::texel_t(x, self.cos_theta_count);
        (t * t).max(MIN_COS_THETA)
    }

    /// Film index of index texel `k`.
    pub fn texel_ior(&self, k: usize) -> f64 {
        self.inverse([0.0, 0.0, Self::texel_t(k, self.ior_count), 0.0])
            .2
    }

    /// Roughness of α block `a`.
    pub fn texel_alpha(&self, a: usize) -> f64 {
        self.inverse([0.0, 0.0, 0.0, Self::texel_t(a, self.alpha_count)])
            .3
    }

    /// Film thickness (nm) of texel (x, y, k) of α block `a`:
    /// d = Δ_y / (2 q(n_k, c_ref(cos θ_x, α_a))) (0 at Δ = 0).
    pub fn texel_thickness_nm(&self, x: usize, y: usize, k: usize, a: usize) -> f64 {
        let opd = Self::texel_t(y, self.opd_count) * self.opd_max_nm();
        let c_ref = Self::reference_cos(self.texel_cos_theta(x), self.texel_alpha(a));
        let q = self.film_q(c_ref, self.texel_ior(k));
        if opd > 0.0 { opd / (2.0 * q) } else { 0.0 }
    }
}

/// A rough-film LUT in memory.
#[derive(Clone, Debug, PartialEq)]
pub struct RoughFilmLut {
    /// The axes.
    pub axes: RoughLutAxes,
    /// Reflected albedo E_r per texel (width × height × depth, see the module docs).
    pub reflectance: Table3,
    /// Transmitted albedo E_t per texel, when the base transmits.
    pub transmittance: Option<Table3>,
}

impl RoughFilmLut {
    /// The albedo colour at physical (cos θ_o, α, d nm, n_f) from `table` (one quantity),
    /// exactly as the shader samples it: trilinear within the two α blocks around α, mixed
    /// linearly (module docs).
    pub fn lookup(
        axes: &RoughLutAxes,
        table: &Table3,
        cos_theta: f64,
        alpha: f64,
        thickness_nm: f64,
        film_ior: f64,
    ) -> [f64; 3] {
        let t = axes.forward(cos_theta, alpha, thickness_nm, film_ior);
        let (a0, f) = lerp_index(t[3], axes.alpha_count);
        // Each block's Δ axis refers to its own α (texel_alpha), as it was baked.
        let block = |a: usize| {
            let t_block = axes.forward(cos_theta, axes.texel_alpha(a), thickness_nm, film_ior);
            trilinear(
                table,
                [t[0], t_block[1], t[2]],
                a * axes.ior_count,
                axes.ior_count,
            )
        };
        let lo = block(a0);
        if f == 0.0 {
            return lo;
        }
        let hi = block(a0 + 1);
        std::array::from_fn(|c| lo[c] + f * (hi[c] - lo[c]))
    }
}

/// Lower texel and fraction of linear interpolation at t on `count` texels.
fn lerp_index(t: f64, count: usize) -> (usize, f64) {
    if count <= 1 {
        return (0, 0.0);
    }
    let pos = t.clamp(0.0, 1.0) * (count - 1) as f64;
    let i = (pos.floor() as usize).min(count - 2);
    (i, pos - i as f64)
}

/// Trilinear interpolation at normalised t (x, y, index) inside the block of `block_count`
/// slices starting at slice `z0`.
fn trilinear(table: &Table3, t: [f64; 3], z0: usize, block_count: usize) -> [f64; 3] {
    let (x0, fx) = lerp_index(t[0], table.nx);
    let (y0, fy) = lerp_index(t[1], table.ny);
    let (k0, fk) = lerp_index(t[2], block_count);
    let mut out = [0.0; 3];
    for corner in 0..8 {
        let (ux, uy, uk) = (corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        let w = [(1.0 - fx, fx), (1.0 - fy, fy), (1.0 - fk, fk)];
        let weight = [ux, uy, uk]
            .iter()
            .zip(w)
            .map(|(&u, (a, b))| if u == 1 { b } else { a })
            .product::<f64>();
        if weight == 0.0 {
            continue;
        }
        let v = table.texel(x0 + ux, y0 + uy, z0 + k0 + uk);
        for c in 0..3 {
            out[c] += weight * f64::from(v[c]);
        }
    }
    out
}

/// Checks the axes of a recipe; `context` names the recipe's `[axes]` table.
pub fn validate_axes(axes: &RoughLutAxes, context: &str, max_texels: u64) -> Result<()> {
    let err = |message: String| Error::Invalid {
        context: context.to_string().into(),
        message: message.into(),
    };
    for (name, count, least) in [
        ("cos_theta_count", axes.cos_theta_count, 2),
        ("opd_count", axes.opd_count, 2),
        ("film_ior_count", axes.ior_count, 1),
        ("alpha_count", axes.alpha_count, 1),
    ] {
        if count < least {
            return Err(err(format!(
                "{name} = {count}: needs at least {least} texel(s)"
            )));
        }
    }
    if !(axes.thickness_max_nm > 0.0 && axes.thickness_max_nm <= 1e5) {
        return Err(err(format!(
            "thickness_nm maximum {} must be positive and at most 100000 nm",
            axes.thickness_max_nm
        )));
    }
    if !(axes.thickness_min_nm >= 0.0 && axes.thickness_min_nm < axes.thickness_max_nm) {
        return Err(err(format!(
            "thickness_nm range [{}, {}] must satisfy 0 ≤ min < max",
            axes.thickness_min_nm, axes.thickness_max_nm
        )));
    }
    if !(axes.ior_min > 0.0 && axes.ior_max >= axes.ior_min && axes.ior_max <= 10.0) {
        return Err(err(format!(
            "film_ior range [{}, {}] must satisfy 0 < min ≤ max ≤ 10",
            axes.ior_min, axes.ior_max
        )));
    }
    if axes.ior_min < axes.ambient_index {
        return Err(err(format!(
            "film_ior minimum {} is below the ambient index {}: the film would be evanescent at grazing angles",
            axes.ior_min, axes.ambient_index
        )));
    }
    if (axes.ior_max > axes.ior_min) != (axes.ior_count > 1) {
        return Err(err(format!(
            "film_ior = [{}, {}] with film_ior_count = {}: a range needs at least 2 texels, a single index exactly 1",
            axes.ior_min, axes.ior_max, axes.ior_count
        )));
    }
    if !(axes.alpha_min >= 1e-3 && axes.alpha_max >= axes.alpha_min && axes.alpha_max <= 1.0) {
        return Err(err(format!(
            "alpha range [{}, {}] must satisfy 0.001 ≤ min ≤ max ≤ 1",
            axes.alpha_min, axes.alpha_max
        )));
    }
    if (axes.alpha_max > axes.alpha_min) != (axes.alpha_count > 1) {
        return Err(err(format!(
            "alpha = [{}, {}] with alpha_count = {}: a range needs at least 2 texels, a single roughness exactly 1",
            axes.alpha_min, axes.alpha_max, axes.alpha_count
        )));
    }
    let texels = axes.cos_theta_count as u64
        * axes.opd_count as u64
        * axes.ior_count as u64
        * axes.alpha_count as u64;
    if texels > max_texels {
        return Err(Error::TooLarge {
            what: format!("{context}: texels (cos_theta × opd × film_ior × alpha)").into(),
            count: texels,
            limit: max_texels,
        });
    }
    Ok(())
}
