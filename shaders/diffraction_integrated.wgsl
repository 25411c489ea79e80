// nacre · shaders/diffraction_integrated.wgsl
// import: diffraction_common
//
// Technique `diffraction`, layout "integrated" (the fast path of issue 7): Stam's
// diffraction BRDF (Stam 1999) with the Taylor expansion of Dhillon et al. 2014, summed over
// wavelengths at bake time into colour tables Iₚ(u, v), p = 0 … 2N. The GPU twin of
// `nacre_optics::diffraction::integrated::IntegratedTable::colour` (derivation, axes and
// point symmetry in crates/optics/src/diffraction/integrated.rs; what every texel holds in
// crates/bake/src/kinds/diffraction_integrated.rs). Needs diffraction_common.wgsl before it
// (`nacre_runtime::diffraction_integrated::WGSL` is the two together); declares bind group
// 1 only, and every name it defines starts with `diffraction_integrated`.
//
// Symbols
//
//   symbol        code                          meaning
//   ω_i, ω_r      wi, wr                        towards the light and the viewer, grating frame
//                                               (x across the lines, z the normal)
//   (u, v, w)     uvw = −ω_i − ω_r              (Stam 1999); w < 0 above the surface
//   Iₚ(u, v)      diffraction_integrated_table  layer p = (Iₚ ch 0, ch 1, ch 2, 0) in the
//                                               table's output space (linear RGB or XYZ)
//   n, n/2        size.y, size.x                rows (v) and columns (u ≥ 0) of a layer
//   u_max         max_uv                        2 sin θ_max, the largest |u|, |v| served
//   γ             1 / inv_gamma                 warp exponent of both axes
//   F²(θ_h)       diffraction_fresnel_of          1, or unpolarised Fresnel of ñ = n + iκ
//
// Stam's k² (issue 37): the BRDF is f = ρ (σ_s k)²/π and the caller's light gain takes k at
// λ_ref (`nacre_runtime::diffraction::lobe_gain`), so a table baked with the manifest's
// `k_squared_reference_nm` holds Σ_λ (λ_ref/λ)² u(λ) … in its layers: the colour below is
// that of Σ_λ (λ_ref/λ)² ρ u, as the terms technique weights it, and every prefiltered level
// with it (a blur is linear). The zeroth order's efficiency has no k² (the lobe's integral
// π/(σ_s k)² cancels it): the specular colour reads the unweighted Jₚ of binding 2. A table
// without the field (an older bake) holds Σ_λ ρ u (tilted red by (λ/λ_ref)²) and renders as
// it did.
//
// Reconstruction (the manifest's `reconstruction`):
//
//   (u, v, w) = −ω_i − ω_r;  u < 0: (u, v, w) → (−u, −v, −w)   (Iₚ(−u, −v) = (−1)ᵖ Iₚ(u, v))
//   x = clamp((u/u_max)^{1/γ} · n/2 − ½, 0, n/2 − 1)                        column coordinate
//   y = clamp((sign(v)(|v|/u_max)^{1/γ} + 1) · n/2 − ½, 0, n − 1)           row coordinate
//   S = (…(I_{2N} w + I_{2N−1}) w + …) w + I₀,  each Iₚ bilinear in (x, y) from four
//       textureLoads (Rgba32Float is not filterable everywhere)
//   colour = F²(θ_h) · (1 + ω_i·ω_r)² / (cos θ_i cos θ_r (cos θ_i + cos θ_r)²) · S
//
// Texel centres: column c holds u = u_max ((2c + 1)/n)^γ, row r holds v = u_max sign(t)|t|^γ,
// t = (2r + 1)/n − 1; the centre of texel i is at coordinate i.
//
// Directions beyond the table's θ_max: as on the CPU (`WarpedAxis::coordinate`), |u|, |v|
// above u_max read the edge texels (clamp to edge) and the colour keeps its G/w² and F²;
// only directions at or below the horizon give 0. The tables are baked with u_max = 2 sin θ_max,
// so every pair of directions within θ_max of the normal is inside.
//
// Filtered over a spread σ in (u, v) (issue 37: a pixel's footprint, item 3, and a rough
// grating's facets, item 4; `diffraction_integrated_colour_filtered`): the texture holds L
// levels of the 2N + 1 layers (layer ℓ (2N + 1) + p), level 0 the table, level ℓ ≥ 1 the
// table blurred by a Gaussian of σ_ℓ = σ₁ 2^{ℓ−1} per axis in u and v (not in texel
// coordinates; `nacre_optics::diffraction::integrated::IntegratedLevels`, made when the
// table is loaded), σ₁ = u_max / 2^{L−2}. With
//
//   σ² = σ_uv² + w² σ_m²            the footprint's spread and the facets' (slope s moves
//                                   (u, v) by w s; σ_m² = α²/2, GGX α matched to Beckmann)
//   σ_ℓ² ≤ σ² ≤ σ_{ℓ+1}²,  t = (σ² − σ_ℓ²)/(σ_{ℓ+1}² − σ_ℓ²)  (σ₀ = 0; t ≤ 1 past the top)
//   S_σ = S_ℓ + t (S_{ℓ+1} − S_ℓ)   the two levels' Horner sums at the same texel coordinates
//
// interpolated in σ²: the kernel keeps the energy and has the variance σ² exactly.
//
// Cost per call: 4 (2N + 1) texel loads (92 for the CD table, N = 11) and 3 (2N + 1)
// multiply-adds of the Horner sum; no loop over wavelengths. Filtered: twice that when σ² > 0
// (two levels), the same at σ² = 0.
//
// Robustness: non-finite or zero directions and directions at or below the horizon give 0;
// huge components are rescaled before normalising; the layer loop is bounded by the texture's
// own layer count; the result is always finite.

// Byte layout (48 bytes; `nacre_runtime::diffraction_integrated::DiffractionIntegratedUniform`
// mirrors it):
//
//   offset size field
//        0    8 size: vec2<u32>          (columns n/2, rows n) of a layer
//        8    4 layers: u32              2N + 1
//       12    4 fresnel_kind: u32        the host's F² for diffraction_integrated_technique.wgsl:
//                                        0: F² = 1; 1: Fresnel of fresnel_ior
//       16    4 max_uv: f32              u_max = 2 sin θ_max
//       20    4 inv_gamma: f32           1/γ
//       24    8 fresnel_ior: vec2<f32>   (n, κ) of the bulk material (fresnel_kind 1)
//       32    4 levels: u32              L, prefiltered levels in the texture (1: the table only)
//       36    4 footprint_filter: u32    the host's footprint filter for the adapter: 0 point
//                                        samples, 1 filters (diffraction_colour_footprint)
//       40    4 sigma_base_sq: f32       σ₁² of level 1
//       44    4 slope_variance: f32      σ_m² = α²/2 of the grating's facets, for the adapter
struct DiffractionIntegratedParams {
    size: vec2<u32>,
    layers: u32,
    fresnel_kind: u32,
    max_uv: f32,
    inv_gamma: f32,
    fresnel_ior: vec2<f32>,
    levels: u32,
    footprint_filter: u32,
    sigma_base_sq: f32,
    slope_variance: f32,
}

@group(1) @binding(0) var<uniform> diffraction_integrated: DiffractionIntegratedParams;
// Rgba32Float 2-D array, (n/2) × n × L (2N + 1), unfilterable: read with textureLoad only.
@group(1) @binding(1) var diffraction_integrated_table: texture_2d_array<f32>;
// Jₚ, p = 0 … 2N: the table's layers at u = v = 0 without Stam's k² weight, (ch 0, ch 1,
// ch 2, 0) (the manifest's `zeroth_order_layers`; a table without k² gives its own layers
// there). The mirror image's colour reads these, not the layers (header: Stam's k²).
@group(1) @binding(2) var<storage, read> diffraction_integrated_zeroth: array<vec4<f32>>;

// The warped coordinate t = (a/u_max)^{1/γ} ∈ [0, 1] of a ≥ 0 (a above u_max clamps to 1;
// a floor of 10⁻³⁰ keeps pow's argument positive: pow(0, y) is undefined in WGSL).
fn diffraction_integrated_warp(a: f32) -> f32 {
    let x = clamp(a / diffraction_integrated.max_uv, 1e-30, 1.0);
    return pow(x, diffraction_integrated.inv_gamma);
}

// S = Σₚ wᵖ Iₚ(u, v) of level `level` (header): the fold, the warped coordinates, bilinear
// from four loads per layer, Horner from p = 2N down. 0 for non-finite input, an empty table
// or a level past the texture.
fn diffraction_integrated_sum_level(uvw_in: vec3<f32>, level: u32) -> vec3<f32> {
    if !diffraction_finite3(uvw_in) {
        return vec3<f32>(0.0);
    }
    let uvw = select(uvw_in, -uvw_in, uvw_in.x < 0.0);
    let dims = textureDimensions(diffraction_integrated_table);
    let cols = i32(min(diffraction_integrated.size.x, dims.x));
    let rows = i32(min(diffraction_integrated.size.y, dims.y));
    let layers = min(diffraction_integrated.layers, textureNumLayers(diffraction_integrated_table));
    if cols < 2 || rows < 2 || layers == 0u || (level + 1u) * layers > textureNumLayers(diffraction_integrated_table) {
        return vec3<f32>(0.0);
    }
    let half_n = 0.5 * f32(rows);
    let tx = diffraction_integrated_warp(uvw.x);
    let ty = sign(uvw.y) * diffraction_integrated_warp(abs(uvw.y));
    let x = clamp(tx * half_n - 0.5, 0.0, f32(cols - 1));
    let y = clamp((ty + 1.0) * half_n - 0.5, 0.0, f32(rows - 1));
    let x0 = min(i32(floor(x)), cols - 2);
    let y0 = min(i32(floor(y)), rows - 2);
    let fx = x - f32(x0);
    let fy = y - f32(y0);
    let w = uvw.z;
    let base = i32(level * layers);
    var s = vec3<f32>(0.0);
    for (var k = 0u; k < layers; k++) {
        let p = base + i32(layers - 1u - k);
        let a = textureLoad(diffraction_integrated_table, vec2<i32>(x0, y0), p, 0).xyz;
        let b = textureLoad(diffraction_integrated_table, vec2<i32>(x0 + 1, y0), p, 0).xyz;
        let c = textureLoad(diffraction_integrated_table, vec2<i32>(x0, y0 + 1), p, 0).xyz;
        let d = textureLoad(diffraction_integrated_table, vec2<i32>(x0 + 1, y0 + 1), p, 0).xyz;
        let lo = a + fx * (b - a);
        let hi = c + fx * (d - c);
        s = s * w + (lo + fy * (hi - lo));
    }
    return s;
}

// S = Σₚ wᵖ Iₚ(u, v) of the table itself (level 0).
fn diffraction_integrated_sum(uvw_in: vec3<f32>) -> vec3<f32> {
    return diffraction_integrated_sum_level(uvw_in, 0u);
}

// S_σ = S_ℓ + t (S_{ℓ+1} − S_ℓ) of levels ℓ = `level` and ℓ + 1 (header); S_ℓ alone when
// t = 0 (no second loop: the unfiltered cost).
fn diffraction_integrated_sum_levels(uvw: vec3<f32>, level: u32, t: f32) -> vec3<f32> {
    let s = diffraction_integrated_sum_level(uvw, level);
    if !(t > 0.0) {
        return s;
    }
    return s + t * (diffraction_integrated_sum_level(uvw, level + 1u) - s);
}

// The level pair (ℓ, t) of the variance σ² (header): σ_ℓ² = σ₁² 4^{ℓ−1} by exact products in
// f32, t = (σ² − σ_ℓ²)/(σ_{ℓ+1}² − σ_ℓ²) ≤ 1; (0, 0) for σ² ≤ 0, NaN or a single level
// (`IntegratedLevels::level_weights` on the CPU).
fn diffraction_integrated_level(sigma2: f32) -> vec2<f32> {
    let count = diffraction_integrated.levels;
    if !(sigma2 > 0.0) || count < 2u {
        return vec2<f32>(0.0);
    }
    var l = 0u;
    var lo = 0.0;
    var hi = diffraction_integrated.sigma_base_sq;
    while l + 2u < count && sigma2 > hi {
        l += 1u;
        lo = hi;
        hi *= 4.0;
    }
    return vec2<f32>(f32(l), min((sigma2 - lo) / (hi - lo), 1.0));
}

// The colour (the table's output space) of Stam's BRDF for ω_i, ω_r in the grating frame
// (need not be unit; any values) with F² of `fresnel_kind`, `fresnel_ior`
// (diffraction_fresnel_of). Always finite; 0 at or below the horizon. A channel may
// be negative for a colour outside the gamut of a linear RGB output space, as on the CPU.
fn diffraction_integrated_colour(wi_in: vec3<f32>, wr_in: vec3<f32>, fresnel_kind: u32, fresnel_ior: vec2<f32>) -> vec3<f32> {
    let wi = diffraction_unit(wi_in);
    let wr = diffraction_unit(wr_in);
    let g = diffraction_geometry_over_w2(wi, wr);
    if !(g > 0.0) {
        return vec3<f32>(0.0);
    }
    let uvw = -wi - wr;
    // |uvw| ≥ −w = cos θ_i + cos θ_r > 0.
    let cos_h = -dot(wi, uvw) * inverseSqrt(dot(uvw, uvw));
    let f = diffraction_fresnel_of(cos_h, fresnel_kind, fresnel_ior);
    let colour = (f * g) * diffraction_integrated_sum(uvw);
    return select(vec3<f32>(0.0), colour, diffraction_finite3(colour));
}

// diffraction_integrated_colour filtered over the spread σ² = σ_uv² + w² σ_m² in (u, v)
// (header): `sigma_uv` the footprint's standard deviation, `slope_variance` σ_m² of the
// facets. σ² = 0 is diffraction_integrated_colour exactly (level 0 alone). Always finite.
fn diffraction_integrated_colour_filtered(wi_in: vec3<f32>, wr_in: vec3<f32>, sigma_uv: f32, slope_variance: f32, fresnel_kind: u32, fresnel_ior: vec2<f32>) -> vec3<f32> {
    let wi = diffraction_unit(wi_in);
    let wr = diffraction_unit(wr_in);
    let g = diffraction_geometry_over_w2(wi, wr);
    if !(g > 0.0) {
        return vec3<f32>(0.0);
    }
    let uvw = -wi - wr;
    let cos_h = -dot(wi, uvw) * inverseSqrt(dot(uvw, uvw));
    let f = diffraction_fresnel_of(cos_h, fresnel_kind, fresnel_ior);
    let sigma2 = sigma_uv * sigma_uv + uvw.z * uvw.z * slope_variance;
    let lt = diffraction_integrated_level(sigma2);
    let colour = (f * g) * diffraction_integrated_sum_levels(uvw, u32(lt.x), lt.y);
    return select(vec3<f32>(0.0), colour, diffraction_finite3(colour));
}

// The colour at the centre of the mirror lobe for a view at cos θ from the normal:
// F²(θ) · Σₚ (−2 cos θ)ᵖ Jₚ (G/w² = 1 there; Jₚ = Iₚ(0, 0) without the k² weight, binding 2,
// Horner from p = 2N): the colour of |P̃(0, 0)|², the zeroth order's efficiency as the
// coherence window sees it. It equals the terms layout's
// `diffraction_specular_order_colour` (F² |P_DC|²) when no other DFT bin lies within the
// window of DC (a 1-D grating whose period divides the patch); otherwise it also holds the
// window-weighted neighbouring bins (for the CD table 1.4 · 10⁻⁴ of the white, measured by
// crates/runtime/tests/diffraction_integrated.rs). Always finite; 0 for cos θ ≤ 0.
fn diffraction_integrated_specular_colour(cos_theta_in: f32, fresnel_kind: u32, fresnel_ior: vec2<f32>) -> vec3<f32> {
    let cos_theta = select(0.0, min(cos_theta_in, 1.0), diffraction_finite(cos_theta_in));
    if !(cos_theta > 0.0) {
        return vec3<f32>(0.0);
    }
    let f = diffraction_fresnel_of(cos_theta, fresnel_kind, fresnel_ior);
    let w = -2.0 * cos_theta;
    let layers = min(diffraction_integrated.layers, arrayLength(&diffraction_integrated_zeroth));
    var s = vec3<f32>(0.0);
    for (var k = 0u; k < layers; k++) {
        s = s * w + diffraction_integrated_zeroth[layers - 1u - k].xyz;
    }
    let colour = f * s;
    return select(vec3<f32>(0.0), colour, diffraction_finite3(colour));
}
