//! Split-sum image-based lighting for the rough iridescent GGX lobe (issue 6): the
//! GGX-prefiltered environment and the directional albedo of GGX with F ≡ 1, both computed
//! here on the CPU when a scene is rendered, deterministically (no random numbers).
//!
//! # Symbols
//!
//! | symbol | code | meaning |
//! |---|---|---|
//! | n, v, l, h | | normal, view, light, half vector (unit) |
//! | α | `alpha` | GGX roughness |
//! | L | [`PREFILTER_LEVELS`] | mip levels of the prefiltered environment |
//! | α_k | [`prefilter_alpha`] | roughness of mip level k: α_k = (k/(L − 1))² |
//! | k(α) | [`prefilter_level`] | fractional level a shader samples: k = √α (L − 1) |
//! | L_env(ω) | | environment radiance towards ω (equirectangular, [`EnvironmentMap`]) |
//! | L̃(r, α) | [`PrefilteredEnvironment`] | the GGX-prefiltered radiance around r |
//! | E₁(μ_o, α) | [`ggx_albedo_table`] | directional albedo of GGX with F = 1 |
//! | E_f(μ_o, α) | `rough-film-lut` | directional albedo of the iridescent GGX lobe (nacre-bake) |
//!
//! # The split sum
//!
//! The radiance a GGX surface reflects from an environment,
//!
//! ```text
//! L_o(v) = ∫ L_env(l) f_r(v, l) (n·l) dl
//! ```
//!
//! is approximated by the product of two separately pre-integrated factors (Karis 2013,
//! "Real Shading in Unreal Engine 4", SIGGRAPH course notes, Eq. 4):
//!
//! ```text
//! L_o(v) ≈ L̃(r, α) · E(v),      E(v) = ∫ f_r(v, l) (n·l) dl
//! L̃(r, α) = Σ_i L_env(l_i) (n·l_i) / Σ_i (n·l_i),   h_i ~ D(h)(n·h),  l_i = 2(v·h_i)h_i − v
//!           with the lobe's view direction taken equal to its normal and to its
//!           reflection direction: n = v = r (Karis 2013, "split-sum assumption")
//! ```
//!
//! E is where the film enters: `FilmEval::Exact` takes E from the `rough-film-lut` table
//! (E_f, the film's spectral reflectance integrated over the GGX lobe for the actual view
//! angle) and replaces L̃(r, α) by a film-weighted mean of L̃ over 32 visible normals of the
//! lobe, each sample l_i read from the level whose GGX lobe matches its solid angle
//! 1/(N p(l_i)) (filtered importance sampling, Křivánek & Colbert 2008; the levels then
//! serve as a blur of adjustable width around any direction, not only as L̃(r, α) of the
//! split sum; `shaders/material.wgsl` has the equations and why); `FilmEval::NormalView`, the
//! engines' common shortcut, uses L̃(r, α) · R_f(n·v) · E₁(n·v, α) (the film evaluated once,
//! at n·v, times the F = 1 albedo of [`ggx_albedo_table`]).
//!
//! # The prefilter
//!
//! Level k of [`PrefilteredEnvironment`] holds L̃ for α_k = (k/(L − 1))² — the mapping of
//! Karis 2013 (roughness r = k/(L − 1) linear in the level, α = r²), so that k(α) = √α (L − 1).
//! Unlike a mip chain, every level has the same size (the environment box-filtered down to at
//! most [`PREFILTER_MAX_WIDTH`] texels wide) and the levels are the layers of a 2-D array
//! texture: a mip chain halves the resolution per level, 2–4 times coarser than a GGX lobe of
//! α_k needs (its width ≈ α_k radians wants texels ≤ α_k/4), and the bilinear blur of the
//! coarse levels showed as colour error against the Monte Carlo reference. Level 0 (α = 0, a
//! mirror) is the box-filtered environment itself. Each texel of level k ≥ 1 is the GGX-importance-sampled convolution above at its direction r, with
//! [`PREFILTER_SAMPLES`] half vectors from the Hammersley point set (φ = 2π ξ₁,
//! cos θ_h = √((1 − ξ₂)/(1 + (α² − 1) ξ₂)), Karis 2013 `ImportanceSampleGGX`), each looked
//! up in the source's 2×2 box mip chain at the level whose texel matches the sample's solid
//! angle (filtered importance sampling, Křivánek & Colbert 2008, "Real-time Shading with
//! Filtered Importance Sampling", Eq. 13):
//!
//! ```text
//! pdf(l) = D(h)(n·h) / (4 v·h) = D(h)/4        (n = v)
//! Ω_s = 1 / (N pdf(l)),   Ω_p = (2π/W)(π/H) sin θ_l,   lod = max(½ log₂(Ω_s/Ω_p) + 1, 0)
//! ```
//!
//! The shader samples layers ⌊k(α)⌋ and ⌊k(α)⌋ + 1 bilinearly and mixes them linearly, so
//! roughnesses between two levels blend the two neighbouring convolutions. The result is
//! cached per environment (the last one prefiltered), so that renders of one environment
//! pay for it once.

use crate::environment::EnvironmentMap;
use crate::image_io::Level;
use nacre_optics::microfacet::{sample_ggx_vndf, smith_g1, smith_g2};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex, OnceLock};

/// Levels L of the prefiltered environment (level k at α_k = (k/(L − 1))²).
pub const PREFILTER_LEVELS: usize = 8;

/// Width of every prefiltered level, texels (height: half of it); narrower environments
/// keep their own size.
pub const PREFILTER_MAX_WIDTH: usize = 128;

/// GGX half vectors per prefiltered texel (Hammersley set).
pub const PREFILTER_SAMPLES: usize = 256;

/// Texels per side of the F = 1 GGX albedo table E₁(μ_o, α).
pub const GGX_ALBEDO_SIZE: usize = 32;

/// Stratified visible-normal samples per side of each E₁ entry (midpoints of a 64 × 64 grid).
pub const GGX_ALBEDO_STRATA: usize = 64;

/// Roughness α_k of prefiltered level `level`: (k/(L − 1))².
pub fn prefilter_alpha(level: usize) -> f64 {
    let r = level as f64 / (PREFILTER_LEVELS - 1) as f64;
    r * r
}

/// The fractional prefiltered level for roughness `alpha` (inverse of [`prefilter_alpha`]):
/// √α (L − 1), α clamped to [0, 1].
pub fn prefilter_level(alpha: f64) -> f64 {
    alpha.clamp(0.0, 1.0).sqrt() * (PREFILTER_LEVELS - 1) as f64
}

/// The nine real spherical harmonics Y_lm (l ≤ 2) of a unit direction d = (x, y, z), in the
/// order (0,0), (1,−1), (1,0), (1,1), (2,−2), (2,−1), (2,0), (2,1), (2,2) with
/// Y₁₋₁ ∝ y, Y₁₀ ∝ z, Y₁₁ ∝ x (Ramamoorthi & Hanrahan 2001, Eq. 3; `scene_irradiance` in
/// `shaders/diffraction_scene.wgsl` evaluates the same functions).
pub fn sh9_basis(d: [f64; 3]) -> [f64; 9] {
    let [x, y, z] = d;
    [
        0.282_095,
        0.488_603 * y,
        0.488_603 * z,
        0.488_603 * x,
        1.092_548 * x * y,
        1.092_548 * y * z,
        0.315_392 * (3.0 * z * z - 1.0),
        1.092_548 * x * z,
        0.546_274 * (x * x - y * y),
    ]
}

/// The irradiance of `env` (its linear radiance, the whole sphere) in nine spherical
/// harmonics (Ramamoorthi & Hanrahan, "An efficient representation for irradiance environment
/// maps", SIGGRAPH 2001): E(n) = ∫ L(ω) max(n·ω, 0) dω ≈ Σ_lm Â_l L_lm Y_lm(n), with
/// L_lm = Σ_texels L Y_lm dΩ (dΩ = (2π/W)(π/H) sin θ at the texel's centre) and the clamped
/// cosine's coefficients Â₀ = π, Â₁ = 2π/3, Â₂ = π/4. Returns Â_l L_lm per coefficient (RGB),
/// to be evaluated with [`sh9_irradiance`]. The nine terms keep the irradiance of any
/// environment to a few per cent (the clamped cosine's energy past l = 2 is under 1 %).
/// A sequential sum: deterministic.
pub fn irradiance_sh9(env: &EnvironmentMap) -> [[f64; 3]; 9] {
    const A: [f64; 9] = [
        PI,
        2.0 * PI / 3.0,
        2.0 * PI / 3.0,
        2.0 * PI / 3.0,
        PI / 4.0,
        PI / 4.0,
        PI / 4.0,
        PI / 4.0,
        PI / 4.0,
    ];
    let (w, h) = (env.width.max(1), env.height.max(1));
    let cell = (2.0 * PI / w as f64) * (PI / h as f64);
    let mut c = [[0.0f64; 3]; 9];
    for (j, row) in env.rgb.chunks(w).enumerate().take(h) {
        let v = (j as f64 + 0.5) / h as f64;
        for (i, texel) in row.iter().enumerate() {
            let d = env_uv_to_direction((i as f64 + 0.5) / w as f64, v);
            let d_omega = cell * (1.0 - d[1] * d[1]).max(0.0).sqrt();
            for (k, y) in sh9_basis(d).iter().enumerate() {
                for (ch, l) in texel.iter().enumerate() {
                    c[k][ch] += f64::from(*l) * y * d_omega;
                }
            }
        }
    }
    for (k, a) in A.iter().enumerate() {
        c[k] = c[k].map(|x| x * a);
    }
    c
}

/// E(n) = Σ c_k Y_k(n) of [`irradiance_sh9`]'s coefficients at the unit normal `n`, clamped
/// at 0 (the CPU twin of `scene_irradiance`).
pub fn sh9_irradiance(c: &[[f64; 3]; 9], n: [f64; 3]) -> [f64; 3] {
    let y = sh9_basis(n);
    std::array::from_fn(|ch| (0..9).map(|k| c[k][ch] * y[k]).sum::<f64>().max(0.0))
}

/// Unit direction of equirectangular coordinates (u, v) ([`EnvironmentMap`]'s convention):
/// φ = 2π(u − 0.5) from −z towards +x, θ = π v from +y.
pub fn env_uv_to_direction(u: f64, v: f64) -> [f64; 3] {
    let phi = 2.0 * PI * (u - 0.5);
    let theta = PI * v;
    [
        theta.sin() * phi.sin(),
        theta.cos(),
        -theta.sin() * phi.cos(),
    ]
}

/// Equirectangular (u, v) of a unit direction: u = 0.5 + atan2(x, −z)/2π, v = acos(y)/π
/// (`env_direction_to_uv` in `shaders/material.wgsl`).
pub fn env_direction_to_uv(d: [f64; 3]) -> (f64, f64) {
    let u = 0.5 + d[0].atan2(-d[2]) / (2.0 * PI);
    let v = d[1].clamp(-1.0, 1.0).acos() / PI;
    (u, v)
}

/// Bilinear lookup of one level at (u, v), as the GPU's sampler does it: texel centres at
/// (i + 0.5)/w, u repeats, v clamps to the edge.
pub fn sample_level_bilinear(level: &Level<4>, u: f64, v: f64) -> [f64; 3] {
    let (w, h, texels) = (level.0, level.1, &level.2);
    let x = u * w as f64 - 0.5;
    let y = (v * h as f64 - 0.5).clamp(0.0, (h - 1) as f64);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let wrap = |i: i64| i.rem_euclid(w as i64) as usize;
    let (i0, i1) = (wrap(x0 as i64), wrap(x0 as i64 + 1));
    let j0 = y0 as usize;
    let j1 = (j0 + 1).min(h - 1);
    let t = |i: usize, j: usize| texels[j * w + i];
    std::array::from_fn(|c| {
        let a = f64::from(t(i0, j0)[c]) * (1.0 - fx) + f64::from(t(i1, j0)[c]) * fx;
        let b = f64::from(t(i0, j1)[c]) * (1.0 - fx) + f64::from(t(i1, j1)[c]) * fx;
        a * (1.0 - fy) + b * fy
    })
}

/// Trilinear lookup in a mip chain at fractional level `lod` (clamped to the chain).
fn sample_trilinear(chain: &[Level<4>], u: f64, v: f64, lod: f64) -> [f64; 3] {
    let lod = lod.clamp(0.0, (chain.len() - 1) as f64);
    let k0 = lod.floor() as usize;
    let k1 = (k0 + 1).min(chain.len() - 1);
    let f = lod - k0 as f64;
    let a = sample_level_bilinear(&chain[k0], u, v);
    if f == 0.0 || k0 == k1 {
        return a;
    }
    let b = sample_level_bilinear(&chain[k1], u, v);
    std::array::from_fn(|c| a[c] * (1.0 - f) + b[c] * f)
}

/// The i-th of n points of the Hammersley set: (i/n, radical inverse of i in base 2).
fn hammersley(i: usize, n: usize) -> (f64, f64) {
    let bits = (i as u32).reverse_bits();
    (
        i as f64 / n as f64,
        f64::from(bits) * (1.0 / 4_294_967_296.0),
    )
}

/// An orthonormal basis (t, b) completing the unit vector n (Duff et al. 2017,
/// "Building an Orthonormal Basis, Revisited", JCGT 6(1)).
pub fn tangent_frame(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let sign = 1f64.copysign(n[2]);
    let a = -1.0 / (sign + n[2]);
    let b = n[0] * n[1] * a;
    (
        [1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]],
        [b, sign + n[1] * n[1] * a, -n[1]],
    )
}

/// The GGX-prefiltered environment: [`PREFILTER_LEVELS`] levels of one size, level k at
/// α_k (see the module doc), RGBA (alpha 1), uploaded as the layers of a 2-D array texture.
#[derive(Clone, Debug)]
pub struct PrefilteredEnvironment {
    /// Level 0 (α = 0) first; every level of the same size.
    pub levels: Vec<Level<4>>,
}

impl PrefilteredEnvironment {
    /// [`PrefilteredEnvironment::new`], cached: the last environment prefiltered (compared
    /// texel for texel) is returned without recomputing it.
    pub fn cached(env: &EnvironmentMap) -> Arc<PrefilteredEnvironment> {
        static CACHE: Mutex<Option<(EnvironmentMap, Arc<PrefilteredEnvironment>)>> =
            Mutex::new(None);
        let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((key, value)) = cache.as_ref()
            && key == env
        {
            return value.clone();
        }
        let value = Arc::new(PrefilteredEnvironment::new(env));
        *cache = Some((env.clone(), value.clone()));
        value
    }

    /// Prefilters `env` (see the module doc). Deterministic; parallel over texels.
    pub fn new(env: &EnvironmentMap) -> PrefilteredEnvironment {
        let chain = env.mip_chain();
        // Level 0: the first box level at most PREFILTER_MAX_WIDTH wide.
        let first = chain
            .iter()
            .position(|l| l.0 <= PREFILTER_MAX_WIDTH)
            .unwrap_or(chain.len() - 1);
        let source = &chain[first..];
        let (w, h) = (source[0].0, source[0].1);
        let mut levels = vec![source[0].clone()];
        for k in 1..PREFILTER_LEVELS {
            let alpha = prefilter_alpha(k);
            let texels: Vec<[f32; 4]> = (0..w * h)
                .into_par_iter()
                .map(|t| {
                    let (i, j) = (t % w, t / w);
                    let r = env_uv_to_direction(
                        (i as f64 + 0.5) / w as f64,
                        (j as f64 + 0.5) / h as f64,
                    );
                    let c = prefilter_direction(source, r, alpha);
                    [c[0] as f32, c[1] as f32, c[2] as f32, 1.0]
                })
                .collect();
            levels.push((w, h, texels));
        }
        PrefilteredEnvironment { levels }
    }
}

/// L̃(r, α): the GGX-importance-sampled convolution of `chain` around `r` with n = v = r.
fn prefilter_direction(chain: &[Level<4>], r: [f64; 3], alpha: f64) -> [f64; 3] {
    let (t, b) = tangent_frame(r);
    let (w0, h0) = (chain[0].0 as f64, chain[0].1 as f64);
    let a2 = alpha * alpha;
    let n = PREFILTER_SAMPLES;
    let mut sum = [0.0f64; 3];
    let mut weight = 0.0;
    for i in 0..n {
        let (xi1, xi2) = hammersley(i, n);
        let phi = 2.0 * PI * xi1;
        let cos_h = ((1.0 - xi2) / (1.0 + (a2 - 1.0) * xi2)).max(0.0).sqrt();
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        let hl = [sin_h * phi.cos(), sin_h * phi.sin(), cos_h];
        // l = 2 (v·h) h − v with v = n = (0, 0, 1) locally.
        let ll = [
            2.0 * cos_h * hl[0],
            2.0 * cos_h * hl[1],
            2.0 * cos_h * cos_h - 1.0,
        ];
        let n_dot_l = ll[2];
        if n_dot_l <= 0.0 {
            continue;
        }
        let l: [f64; 3] = std::array::from_fn(|c| ll[0] * t[c] + ll[1] * b[c] + ll[2] * r[c]);
        let k = cos_h * cos_h * (a2 - 1.0) + 1.0;
        let d = a2 / (PI * k * k);
        let pdf = d / 4.0;
        let omega_s = 1.0 / (n as f64 * pdf.max(1e-30));
        let sin_theta = (1.0 - l[1] * l[1]).max(1e-6).sqrt();
        let omega_p = (2.0 * PI / w0) * (PI / h0) * sin_theta;
        let lod = (0.5 * (omega_s / omega_p).log2() + 1.0).max(0.0);
        let (u, v) = env_direction_to_uv(l);
        let c = sample_trilinear(chain, u, v, lod);
        for ch in 0..3 {
            sum[ch] += c[ch] * n_dot_l;
        }
        weight += n_dot_l;
    }
    if weight > 0.0 {
        sum.map(|s| s / weight)
    } else {
        sample_trilinear(
            chain,
            env_direction_to_uv(r).0,
            env_direction_to_uv(r).1,
            0.0,
        )
    }
}

/// μ_o of column `i` of the E₁ table: t = i/(n − 1), μ_o = max(t, 10⁻³). Texture
/// coordinate of μ: (t (n − 1) + 0.5)/n (texel centres), as the film-lut axes.
pub fn ggx_albedo_cos(i: usize) -> f64 {
    (i as f64 / (GGX_ALBEDO_SIZE - 1) as f64).max(1e-3)
}

/// α of row `j` of the E₁ table: α = max(j/(n − 1), 10⁻³).
pub fn ggx_albedo_alpha(j: usize) -> f64 {
    (j as f64 / (GGX_ALBEDO_SIZE - 1) as f64).max(1e-3)
}

/// E₁(μ_o, α) = ∫ D G₂ / (4 μ_o μ_i) μ_i dω_i, the directional albedo of the GGX lobe with
/// F ≡ 1 (height-correlated Smith; single scattering), by the visible-normal estimator of
/// `nacre_optics::microfacet` (weight G₂/G₁) on the midpoints of a
/// [`GGX_ALBEDO_STRATA`]² grid of (u₁, u₂): deterministic, stratified.
pub fn ggx_albedo(cos_theta_o: f64, alpha: f64) -> f64 {
    ggx_albedo_terms(cos_theta_o, alpha)[0]
}

/// (E₁, E₅)(μ_o, α): E₁ as [`ggx_albedo`], and E₅ = ∫ (1 − v·h)⁵ D G₂ / (4 μ_o μ_i) μ_i dω_i,
/// its share weighted by Schlick's Fresnel term, by the same estimator: the albedo of a GGX
/// lobe with Schlick's F = F0 + (1 − F0)(1 − v·h)⁵ is F0 E₁ + (1 − F0) E₅ (Karis 2013, "Real
/// Shading in Unreal Engine 4", the split sum's scale and bias: A = E₁ − E₅, B = E₅).
pub fn ggx_albedo_terms(cos_theta_o: f64, alpha: f64) -> [f64; 2] {
    let mu = cos_theta_o.clamp(1e-4, 1.0);
    let wo = [(1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu];
    let g1 = smith_g1(wo, alpha);
    let m = GGX_ALBEDO_STRATA;
    let mut sum = [0.0; 2];
    for a in 0..m {
        for b in 0..m {
            let h = sample_ggx_vndf(
                wo,
                alpha,
                (a as f64 + 0.5) / m as f64,
                (b as f64 + 0.5) / m as f64,
            );
            let d = wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2];
            let wi = [
                2.0 * d * h[0] - wo[0],
                2.0 * d * h[1] - wo[1],
                2.0 * d * h[2] - wo[2],
            ];
            if wi[2] > 0.0 && d > 0.0 {
                let w = smith_g2(wo, wi, alpha) / g1;
                sum[0] += w;
                sum[1] += w * (1.0 - d).powi(5);
            }
        }
    }
    sum.map(|s| s / (m * m) as f64)
}

/// The E₁ table: [`GGX_ALBEDO_SIZE`]² texels, x = μ_o ([`ggx_albedo_cos`]), y = α
/// ([`ggx_albedo_alpha`]), (E₁, E₅) per texel ([`ggx_albedo_terms`]; `Rg16Float` on the GPU). Computed once per
/// process (≈ 4 M visible-normal samples) and cached.
pub fn ggx_albedo_table() -> &'static Level<2> {
    static TABLE: OnceLock<Level<2>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let n = GGX_ALBEDO_SIZE;
        let texels = (0..n * n)
            .into_par_iter()
            .map(|t| {
                ggx_albedo_terms(ggx_albedo_cos(t % n), ggx_albedo_alpha(t / n)).map(|e| e as f32)
            })
            .collect();
        (n, n, texels)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// L(d) = 1 + 0.5 d_y has only l ≤ 1 terms, so its irradiance is exact in nine
    /// harmonics: E(n) = π + (π/3) n_y (∫ max(n·ω, 0) dω = π, ∫ ω max(n·ω, 0) dω = 2π/3 n).
    #[test]
    fn sh9_irradiance_of_a_linear_sky_is_exact() {
        let (width, height) = (256, 128);
        let mut rgb = Vec::with_capacity(width * height);
        for j in 0..height {
            for i in 0..width {
                let d = env_uv_to_direction(
                    (i as f64 + 0.5) / width as f64,
                    (j as f64 + 0.5) / height as f64,
                );
                rgb.push([(1.0 + 0.5 * d[1]) as f32, 1.0, (2.0 - d[0]) as f32]);
            }
        }
        let c = irradiance_sh9(&EnvironmentMap { width, height, rgb });
        for n in [
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.6, 0.0, 0.8],
            [-0.48, 0.6, -0.64],
        ] {
            let e = sh9_irradiance(&c, n);
            let expected = [PI + PI / 3.0 * n[1], PI, 2.0 * PI - 2.0 * PI / 3.0 * n[0]];
            for ch in 0..3 {
                assert!(
                    (e[ch] - expected[ch]).abs() <= 2e-3 * expected[ch],
                    "{n:?} channel {ch}: {} against {}",
                    e[ch],
                    expected[ch]
                );
            }
        }
    }

    /// The studio without its sun (the diffraction scenes' environment): nine harmonics
    /// against the brute-force ∫ L max(n·ω, 0) dω over its texels, within 5 % of the
    /// luminance at normals from up to sideways (measured: 2.1 % up, 1.3 % and 0.8 % at 60°
    /// from it, 3.7 % sideways towards −z).
    #[test]
    fn sh9_irradiance_of_the_studio_is_close() {
        let env = crate::environment::procedural_environment_with(256, 128, false);
        let c = irradiance_sh9(&env);
        let (w, h) = (env.width, env.height);
        let lum = |x: [f64; 3]| 0.2126 * x[0] + 0.7152 * x[1] + 0.0722 * x[2];
        for n in [
            [0.0, 1.0, 0.0],
            [0.0, 0.5, 0.866_025],
            [0.866_025, 0.5, 0.0],
            [0.0, 0.0, -1.0],
        ] {
            let mut brute = [0.0; 3];
            for j in 0..h {
                for i in 0..w {
                    let d = env_uv_to_direction(
                        (i as f64 + 0.5) / w as f64,
                        (j as f64 + 0.5) / h as f64,
                    );
                    let cos = (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]).max(0.0);
                    let d_omega =
                        (2.0 * PI / w as f64) * (PI / h as f64) * (1.0 - d[1] * d[1]).sqrt();
                    for (b, l) in brute.iter_mut().zip(env.rgb[j * w + i]) {
                        *b += f64::from(l) * cos * d_omega;
                    }
                }
            }
            let e = sh9_irradiance(&c, n);
            let err = (lum(e) - lum(brute)).abs() / lum(brute);
            eprintln!(
                "{n:?}: nine harmonics {:.4}, texels {:.4} ({err:.4})",
                lum(e),
                lum(brute)
            );
            assert!(
                err <= 0.05,
                "{n:?}: {} against {} ({err})",
                lum(e),
                lum(brute)
            );
        }
    }

    #[test]
    fn levels_and_alphas_are_inverse() {
        for k in 0..PREFILTER_LEVELS {
            assert!((prefilter_level(prefilter_alpha(k)) - k as f64).abs() < 1e-12);
        }
        assert_eq!(prefilter_alpha(PREFILTER_LEVELS - 1), 1.0);
    }

    #[test]
    fn uv_and_directions_round_trip() {
        for &(u, v) in &[(0.1, 0.2), (0.5, 0.5), (0.8, 0.9), (0.3, 0.05)] {
            let (u2, v2) = env_direction_to_uv(env_uv_to_direction(u, v));
            assert!((u - u2).abs() < 1e-12 && (v - v2).abs() < 1e-12);
        }
        let (t, b) = tangent_frame([0.0, 0.6, 0.8]);
        let dot = |a: [f64; 3], c: [f64; 3]| a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
        assert!(dot(t, b).abs() < 1e-12 && dot(t, [0.0, 0.6, 0.8]).abs() < 1e-12);
    }

    #[test]
    fn constant_environment_stays_constant() {
        // A uniform environment of radiance 2: every prefiltered texel is 2.
        let env = EnvironmentMap {
            width: 64,
            height: 32,
            rgb: vec![[2.0, 2.0, 2.0]; 64 * 32],
        };
        let p = PrefilteredEnvironment::new(&env);
        assert_eq!(p.levels.len(), PREFILTER_LEVELS);
        for (w, h, texels) in &p.levels {
            assert_eq!(texels.len(), w * h);
            for t in texels {
                assert!((t[0] - 2.0).abs() < 1e-4, "{t:?}");
            }
        }
    }

    #[test]
    fn ggx_albedo_is_one_for_a_mirror_and_falls_with_roughness() {
        assert!((ggx_albedo(0.9, 1e-3) - 1.0).abs() < 1e-3);
        let (a, b) = (ggx_albedo(0.7, 0.3), ggx_albedo(0.7, 0.9));
        assert!(a < 1.0 && b < a && b > 0.3, "{a} {b}");
        // Against the Monte Carlo estimator of nacre-optics with F ≡ 1.
        let white = nacre_optics::microfacet::FilmTerm::from_fn(1, None, |_| ([1.0; 3], [0.0; 3]));
        for &(mu, alpha) in &[(0.9, 0.1), (0.5, 0.5), (0.2, 0.8)] {
            let e =
                nacre_optics::microfacet::directional_albedo_with(&white, alpha, mu, 1 << 16, 7)
                    .unwrap();
            let got = ggx_albedo(mu, alpha);
            let want = e.reflection.colour[0];
            let tol = 4.0 * e.reflection.standard_error[0] + 2e-3;
            assert!(
                (got - want).abs() < tol,
                "μ {mu} α {alpha}: {got} vs {want} ± {tol}"
            );
        }
    }
}
