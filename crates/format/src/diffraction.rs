//! Table kind `diffraction`: what its manifest records (both layouts) and the readers of
//! its files. How the tables are baked is `nacre_bake::kinds::diffraction`.

use serde::{Deserialize, Serialize};

/// The sign convention recorded in manifests and printed by the CLI.
pub const SIGN_CONVENTION: &str = "P(ku, kv) = ∬ exp(+i k (u x + v y + w h(x, y))) dx dy with (u, v, w) = −ω_i − ω_r (ω_i towards the light, ω_r towards the viewer; time dependence exp(−iωt)); T_n[j] = (1/M) Σ_m (i h_m)^n exp(+i κ_j·x_m), κ_j = 2π j / L; P_j = Σ_n (k w)^n / n! T_n[j]; x runs across the grating lines";

/// Everything a `diffraction` manifest records about the table (beside the common fields).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DiffractionRecord {
    /// `terms` or `integrated`.
    pub layout: String,
    /// The height field: a synthetic spec or the file name as written in the recipe.
    pub source: String,
    /// Samples (bins) along x.
    pub nx: usize,
    /// Samples (bins) along y.
    pub ny: usize,
    /// Sample spacing Δ, µm.
    pub pitch_um: f64,
    /// Patch size (Lₓ, L_y), µm.
    pub patch_um: [f64; 2],
    /// The mean height removed (a global phase), µm.
    pub mean_removed_um: f64,
    /// Largest |h| after removing the mean, µm.
    pub max_abs_height_um: f64,
    /// Coherence diameter 4σ_s, µm.
    pub coherence_diameter_um: f64,
    /// σ_s, µm.
    pub sigma_s_um: f64,
    /// Shortest wavelength served, nm.
    pub wavelength_min_nm: f64,
    /// Longest wavelength served, nm.
    pub wavelength_max_nm: f64,
    /// Wavelength step of the colour sums, nm.
    pub wavelength_step_nm: f64,
    /// Largest polar angle of light and view served, degrees.
    pub max_angle_deg: f64,
    /// 2 sin(max_angle): the largest |u|, |v|.
    pub max_uv: f64,
    /// Taylor order N (terms T₀ … T_N).
    pub taylor_order: usize,
    /// Tolerance asked for on the remainder bound.
    pub taylor_tolerance: f64,
    /// max |k w h| at the shortest wavelength with |w| ≤ 2.
    pub max_phase: f64,
    /// The remainder bound |kwh|^{N+1}/(N+1)! at max_phase.
    pub taylor_bound: f64,
    /// Bound on the error of the Taylor sum from storing Tₙ as f32: 2⁻²⁴ e^{max_phase}.
    pub f32_rounding_bound: f64,
    /// Texel of the DC bin, (⌊Mₓ/2⌋, ⌊M_y/2⌋).
    pub dc_texel: [usize; 2],
    /// [`SIGN_CONVENTION`].
    pub sign_convention: String,
    /// Layout "integrated" only: its axes, settings and measured reconstruction error
    /// (`nacre_bake::kinds::diffraction_integrated`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub integrated: Option<IntegratedRecord>,
}

/// The error metric recorded in manifests.
pub const ERROR_METRIC: &str = "max over light/view pairs and output channels c of |colour_integrated,c - colour_terms,c| / white_c, white = the colour of rho = 1 (a flat perfect mirror in its specular direction) with the table's k^2 weight (lambda_ref/lambda)^2, i.e. sum_lambda (k_squared_reference_nm/lambda)^2 u(lambda); colour_integrated as a shader rebuilds it (f32 texels, bilinear in the warped coordinates, f32 Horner sum), colour_terms from the f64 Taylor terms at the same N and wavelength grid with the same (k_squared_reference_nm/lambda)^2 weight per wavelength, F = 1";

/// Largest integrated table accepted: (2N + 1)·n·n/2 RGBA32F texels, 1 GiB (the KTX2
/// file; the EXR file is ¾ of it).
pub const MAX_INTEGRATED_BYTES: u64 = 1 << 30;

/// What a manifest records about an integrated table (inside [`DiffractionRecord`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IntegratedRecord {
    /// Columns n/2 (u ≥ 0).
    pub samples_u: usize,
    /// Rows n (v over [−u_max, u_max]).
    pub samples_v: usize,
    /// Warp exponent γ.
    pub gamma: f64,
    /// u_max = 2 sin θ_max.
    pub max_uv: f64,
    /// Layers 2N + 1 (p = 0 … 2N).
    pub layers: usize,
    /// What the three channels hold.
    pub channels: String,
    /// Column coordinate of u ≥ 0.
    pub u_forward: String,
    /// u at the centre of column c.
    pub u_inverse: String,
    /// Row coordinate of v.
    pub v_forward: String,
    /// v at the centre of row r.
    pub v_inverse: String,
    /// How u < 0 is read.
    pub fold: String,
    /// [`ERROR_METRIC`].
    pub error_metric: String,
    /// The tolerance the bake was held to.
    pub tolerance: f64,
    /// The measured error ([`ERROR_METRIC`]).
    pub reconstruction_error: f64,
    /// Its mean over the pairs.
    pub mean_error: f64,
    /// Light direction of the largest error: (θ, φ), degrees (φ from +x towards +y).
    pub worst_light_deg: [f64; 2],
    /// View direction of the largest error: (θ, φ), degrees.
    pub worst_view_deg: [f64; 2],
    /// Output channel of the largest error.
    pub worst_channel: String,
    /// Light/view pairs measured.
    pub pairs: usize,
    /// Error of f32 storage and the f32 sum alone, at texel centres (no interpolation),
    /// same units: the catastrophic cancellation of tall structures.
    pub storage_error: f64,
    /// λ_ref, nm, of Stam's k² weight (λ_ref/λ)² = (k/k_ref)² the layers were summed with
    /// (issue 37): Stam's BRDF is f = ρ (σ_s k)²/π and a renderer's light gain
    /// (σ_s k_ref)²/π takes k at λ_ref (`nacre_runtime::diffraction::lobe_gain`), so the
    /// layers hold Σ_λ (λ_ref/λ)² u(λ) kᵖ … and colour = C · Σₚ wᵖ Iₚ is the colour of
    /// Σ_λ (λ_ref/λ)² ρ(λ) u(λ), as the terms technique weights it. `None` (absent: a table
    /// baked by a nacre before the weight) means the layers hold Σ_λ ρ u without it — a
    /// picture drawn from them is tilted towards red by (λ/λ_ref)²; such a table still
    /// loads and renders as it did.
    #[serde(default)]
    pub k_squared_reference_nm: Option<f64>,
    /// Jₚ, p = 0 … 2N, in the output space (f32 values, written as f64): the layers at u = v = 0 without the
    /// k² weight, so that F²(θ) Σₚ (−2 cos θ)ᵖ Jₚ is the colour of the zeroth order's
    /// efficiency |P̃(0, 0)|² (the mirror image has no k²: the lobe's integral
    /// π/(σ_s k)² cancels it). Empty (absent) for a table without
    /// `k_squared_reference_nm`, whose own layers at (0, 0) serve.
    #[serde(default)]
    pub zeroth_order_layers: Vec<[f64; 3]>,
}
