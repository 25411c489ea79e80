// nacre · shaders/material.wgsl — consumer: a thin-film microfacet material
// import: common, <technique>, rough_lut_mapping, view, output
//
// A GGX specular lobe whose Fresnel term is the technique's film colour, over a Lambertian
// (dielectric) or metallic base, lit by one directional light and by an equirectangular HDR
// environment, with optional transmission through a thin transparent shell (soap bubble),
// exposure, the Khronos PBR Neutral tone mapper and an sRGB encoding. Composed after
// common.wgsl, lut_mapping.wgsl, one technique module (which supplies `film_colour`),
// rough_lut_mapping.wgsl, view.wgsl (group 0) and output.wgsl (its import line above: `nacre_runtime::shaders`
// resolves them), and before
// scene.wgsl or mesh.wgsl, which ray-casts the geometry and calls `material_shade`
// (crates/runtime/src/render/mod.rs; shaders/README.md).
//
// Symbols
//
//   symbol        code                         meaning
//   n, v, l, h    normal, view, light, half    unit vectors at the shading point; v and l point
//                                              away from the surface, h = (v + l)/|v + l|
//   α             roughness_alpha              GGX roughness (α = perceptual roughness²)
//   D(h)          ggx_distribution             GGX / Trowbridge–Reitz normal distribution
//   Λ(ω)          (inside ggx_visibility)      Smith auxiliary function of GGX
//   G₂(v, l)      (inside ggx_visibility)      height-correlated masking-shadowing
//   V(v, l)       ggx_visibility               G₂ / (4 |n·v| |n·l|)
//   R_f(cos θ)    FilmOutput.reflectance       film reflectance colour (replaces Fresnel F)
//   T_f(cos θ)    FilmOutput.transmittance     film transmittance colour (thin shells)
//   E_GGX(α)      ggx_albedo_scale             directional albedo of the GGX lobe with F = 1
//                                              (classic path: Karis's fit, no view dependence)
//   E₁(μ_o, α)    ggx_albedo                   the same, tabulated exactly over n·v and α
//   E_f(μ_o, α)   material_rough_film_albedo   directional albedo of the iridescent GGX lobe
//                                              (rough-film-lut: film and GGX integrated)
//   L̃(r, α)       env_prefiltered_radiance     GGX-prefiltered environment (split sum)
//   L_env(ω, k)   env_radiance                 environment radiance towards ω at mip level k
//   E_l           light_colour × intensity     irradiance of the directional light at normal
//                                              incidence (linear RGB)
//   d             thickness_nm                 film thickness at the shading point, nm
//   g             thickness map value          greyscale value ∈ [0, 1]
//   σ_d           sigma_thickness_nm           std. dev. of d inside the pixel (film_fourier)
//
// Specular, one light (Walter et al. 2007, Eq. 33 for D; Heitz 2014, "Understanding the
// Masking-Shadowing Function in Microfacet-Based BRDFs", JCGT 3(2), Eq. 72 for Λ and Eq. 99
// for the height-correlated G₂):
//
//   f_s = D(h) G₂(v, l) R_f(v·h) / (4 n·v n·l)
//   D(h) = α² / (π ((n·h)² (α² − 1) + 1)²)
//   Λ(ω) = (−1 + √(1 + α² tan² θ_ω)) / 2,   G₂ = 1 / (1 + Λ(v) + Λ(l))
//   ⇒ V = G₂ / (4 n·v n·l) = 0.5 / (n·l √((n·v)²(1 − α²) + α²) + n·v √((n·l)²(1 − α²) + α²))
//
// The film term sits where Fresnel sits and is evaluated at the microfacet's incidence v·h;
// for a metal base the film lies on the metal, and R_f already contains the metal's
// reflectance (film_lut bakes the base; film_fourier and film_spectral get its complex index).
// Film weight w (MaterialParams.film_weight; glTF iridescenceFactor, OpenPBR thin_film_weight):
// a fraction w of the surface is coated, so every film term is blended with the bare base's
// unpolarised Fresnel reflectance F_base (ambient → base index n + iκ per channel, no film):
//
//   R = mix(F_base, R_f, w),   T = mix(1 − F_base, T_f, w)        (w = 1: the film alone, exactly)
//
// Diffuse, dielectric base only: a Lambertian base of albedo ρ under the film, weighted by
// what the film does not reflect: f_d = ρ/π (1 − R_f(v·h)) for the light, ρ (1 − R_f(n·v))
// for the environment. Metal bases and thin shells have no diffuse term.
//
// Classic image-based lighting (no split-sum table): the environment's mip chain (a 2×2 box filter
// built on the CPU, `render::EnvironmentMap::mip_chain`) stands in for the pre-convolved
// radiance, and the GGX lobe's directional albedo becomes one scale:
//
//   L_spec ≈ L_env(reflect(−v, n), k(α)) · R_f(n·v) · E_GGX(α)
//   E_GGX(α) = 1 − 0.55 √α
//   k(α) = log2(max(2 α H / π, 1))     (H: environment height in texels; the reflected lobe's
//                                       half-width ≈ 2α radians spans 2αH/π texels at level 0)
//   L_diff ≈ L_env(n, k_max − 2) · ρ (1 − R_f(n·v))   (a 4×8-texel-wide box ≈ the cosine lobe)
//
// E_GGX is the F = 1 limit (A + B) of B. Karis, "Physically Based Shading on Mobile" (Unreal
// Engine blog, 2014), EnvBRDFApprox, after D. Lazarov (2013): it ignores the view angle and
// the multiple scattering between microfacets, and the film is evaluated once, at n·v.
// That is the classic path (MaterialParams.film_eval = 0, the default; the golden images).
//
// Split-sum paths (film_eval = 1 or 2; Karis 2013, "Real Shading in Unreal Engine 4", Eq. 4;
// Belcour & Barla 2017 §6 and Fig. 16 for why the film matters here):
//
//   L_spec ≈ L̃(r, α) · E(μ_o),   μ_o = n·v,  r = reflect(−v, n)
//   L̃(r, α) = env_prefiltered at level √α (L − 1)   (the GGX convolution with n = v = r)
//
//   film_eval = 1, "film at n·v" — the engines' common shortcut: the film colour is evaluated
//   once per pixel, at n·v, and used for the environment and for every light:
//       E = R_f(n·v) E₁(n·v, α),   f_s = D G₂ R_f(n·v) / (4 n·v n·l)
//   film_eval = 2, "exact": the environment takes the film's directional albedo integrated
//   over the GGX lobe for this view angle (the rough-film-lut table), each light the film at
//   its own half vector:
//       E = E_f(n·v, α, d, n₂),               f_s = D G₂ R_f(v·h) / (4 n·v n·l)
//   and, because the film colour and the environment are correlated across the lobe (a
//   microfacet's incidence c = v·h fixes the angle 2 acos c between v and the direction it
//   reflects, so each interference colour sees its own part of the sky), the environment
//   factor is the film-weighted mean over N = MATERIAL_LOBE_SAMPLES visible normals m_i of
//   the lobe (Heitz 2018 visible-normal sampling at the points of a Fibonacci spiral,
//   u_i = ((i + ½)/N, frac(i g)), g = (3 − √5)/2), per channel:
//       L_spec ≈ E_f · Σ_i w_i R_f(v·m_i) L̃(l_i, α_i) / Σ_i w_i R_f(v·m_i),
//       l_i = reflect(−v, m_i),  w_i = G₂(v, l_i)/G₁(v)
//   (the rough-film-lut supplies the energy, the samples only how it is distributed over
//   the environment). Each sample reads the prefiltered environment blurred to its own
//   footprint — filtered importance sampling (Křivánek & Colbert 2008, "Real-time Shading
//   with Filtered Importance Sampling", EGSR 2008): the sample stands for the solid angle
//   Ω_i = 1/(N p(l_i)), with p(l) = D_v(m)/(4 v·m) = G₁(v) D(m)/(4 n·v) the density of l
//   under visible-normal sampling, and the prefiltered layer whose GGX lobe around l_i
//   spans about that much (the lobe of α_k has its peak density D(1)/4 = 1/(4π α_k²), so
//   Ω ≈ 4π α_k²):
//       α_i = k_FIS √(Ω_i/(4π)) = k_FIS √(n·v (1 + Λ(v)) / (π N D(m_i))),   k_FIS = 0.7
//   (k_FIS from a CPU sweep of 0.5–2 against the Monte Carlo references: wider footprints
//   wash out the correlation, narrower ones alias). With a film that does not vary over the
//   lobe this is the split sum for the lobe's true shape. Against the references of
//   tests/golden/rough/ the estimator's mean ΔE2000 falls with N: 1.19 / 1.94 / 1.48 at
//   α = 0.1 / 0.3 / 0.6 for 16 samples on a 4 × 4 grid (k_FIS = 1), 0.74 / 0.71 / 0.79 for 32
//   spiral samples, 0.51 / 0.45 / 0.48 for 64 (lobe_sample_count_sweep in
//   crates/runtime/tests/rough.rs, a CPU twin with the exact film term; on lavapipe the
//   shader's 32 give 0.74 / 0.71 / 0.80).
//
// Diffuse (dielectric base) in the split-sum paths: L_env(n, k_max − 2) ρ (1 − R̄) with the
// lobe's mean reflectance R̄ = R_f(n·v) for the shortcut and R̄ = E_f/E₁ for the exact path;
// the light's diffuse is as in the classic path with the film at n·v (shortcut) or v·h.
// A film weight w < 1 blends E_f with the bare base's F_base(n·v) E₁ (exact path).
//
// Thin transparent shells (MaterialParams.transmission = 1, the soap bubble): the surface
// reflects as above and passes T_f(n·v) of the light behind it straight through (no refraction
// offset: both faces of a thin shell are parallel); `material_shade` returns T_f and the
// scene multiplies what lies behind by it.
//
// Spatially varying thickness from a greyscale map (MaterialParams.thickness_mode):
//
//   0  SVT, Sussenbach 2013 §4.2 Eq. 4.3–4.4:   d = d_avg + d_rel (2g − 1)
//   1  glTF KHR_materials_iridescence:          d = mix(d_min, d_max, g)
//
// plus a drainage term d += drain (1 − h)/2 for a normalised object height h ∈ [−1, 1]
// (gravity pulls a soap film down: 0 at the top, `drain` nm at the bottom); d ≥ 0.
//
// Prefiltering (film_fourier; the other techniques ignore σ_d): σ_d comes from the
// screen-space derivatives of d and from the sub-pixel variance of the map
// (`material_thickness_sigma`, the formula of film_fourier.wgsl's
// fourier_sigma_from_derivatives, redefined here so that this module composes with every
// technique):
//
//   σ_d = √(max((∂d/∂x)², (∂d/∂y)²)/12 + σ_r²),   σ_r² = roughness² + (∂d/∂g)² Var(g)
//
// where Var(g) = E[g²] − E[g]² is read from the map's mip chain, which stores (g, g²) per
// texel: the mip level the sampler picks for the pixel's footprint averages both, so the
// variance of the thickness the filtering removed is not lost (mean-and-second-moment
// mipmapping as in variance shadow maps, Donnelly & Lauritzen 2006).
//
// Output: exposure (a factor 2^EV), tone mapping by Khronos PBR Neutral
// (KhronosGroup/ToneMapping, PBR_Neutral, 2024), then the sRGB transfer function
// (IEC 61966-2-1) applied here: the render target is Rgba8Unorm and holds sRGB-encoded bytes.
// The tone mapper and the encoding are output.wgsl's; the exposure and guards are here.
//
// NaN guards: every film evaluation is sanitised by the technique; vectors are normalised
// with a fallback; the final colour replaces non-finite channels by 0 before tone mapping.

// ─── Group 0: the view and the environment (changes per frame): view.wgsl ───────────────

// ─── Group 2: the material (changes per draw) ────────────────────────────────────────────
//
// 96 bytes, uniform (mirrored by `MaterialUniform` in crates/runtime/src/render/options.rs):
//
//   offset size field
//        0    4 film_ior: f32                 real film index n₂
//        4    4 ambient_ior: f32              ambient index n₁
//        8    4 thickness_a_nm: f32           SVT: d_avg; glTF: d_min (nm)
//       12    4 thickness_b_nm: f32           SVT: d_rel; glTF: d_max (nm)
//       16    4 thickness_mode: u32           0 SVT, 1 glTF
//       20    4 thickness_roughness_nm: f32   sub-pixel std. dev. of d, nm
//       24    4 thickness_drain_nm: f32       extra thickness at the bottom (h = −1), nm
//       28    4 roughness_alpha: f32          GGX α
//       32   12 base_ior: vec3<f32>           base index per output channel, real part
//       44    4 base_kind: u32                0 dielectric (Lambertian diffuse), 1 metal
//       48   12 base_kappa: vec3<f32>         base index per output channel, κ
//       60    4 transmission: u32             1: thin transparent shell
//       64   12 base_colour: vec3<f32>        diffuse albedo ρ (linear RGB, dielectric base)
//       76    4 thickness_map_scale: f32      s: a map tile spans 2/s units of the scene's map coordinate
//       80    4 film_weight: f32              w ∈ [0, 1]: F = mix(F_base, R_f, w) (glTF
//                                             iridescenceFactor, OpenPBR thin_film_weight); 1 = film
//       84    4 film_eval: u32                lighting path: 0 classic, 1 film at n·v (split sum),
//                                             2 exact (split sum + rough-film-lut, film at v·h)
//       88    8 _pad1.._pad2: f32             (96 bytes in all)
struct MaterialParams {
    film_ior: f32,
    ambient_ior: f32,
    thickness_a_nm: f32,
    thickness_b_nm: f32,
    thickness_mode: u32,
    thickness_roughness_nm: f32,
    thickness_drain_nm: f32,
    roughness_alpha: f32,
    base_ior: vec3<f32>,
    base_kind: u32,
    base_kappa: vec3<f32>,
    transmission: u32,
    base_colour: vec3<f32>,
    thickness_map_scale: f32,
    film_weight: f32,
    film_eval: u32,
    _pad1: f32,
    _pad2: f32,
}

@group(2) @binding(0) var<uniform> material_params: MaterialParams;
// Thickness map, Rg16Float with a full mip chain: r = g, g = g² (mean and second moment).
@group(2) @binding(1) var thickness_map: texture_2d<f32>;
// Linear min/mag/mip, repeat.
@group(2) @binding(2) var thickness_sampler: sampler;

const MATERIAL_THICKNESS_SVT: u32 = 0u;
const MATERIAL_THICKNESS_GLTF: u32 = 1u;
const MATERIAL_BASE_DIELECTRIC: u32 = 0u;
const MATERIAL_BASE_METAL: u32 = 1u;
// MaterialParams.film_eval: how the film enters the lighting (see the header).
const MATERIAL_FILM_EVAL_CLASSIC: u32 = 0u;
const MATERIAL_FILM_EVAL_NV: u32 = 1u;
const MATERIAL_FILM_EVAL_EXACT: u32 = 2u;
// Layers of env_prefiltered (crates/runtime/src/ibl.rs, PREFILTER_LEVELS): layer k holds
// the environment convolved with GGX of α_k = (k / (L − 1))².
const ENV_PREFILTER_LEVELS: f32 = 8.0;
// Texels per side of env_ggx_albedo (ibl.rs, GGX_ALBEDO_SIZE).
const GGX_ALBEDO_SIZE: f32 = 32.0;
// Smallest GGX α (a mirror-like α keeps D finite in f32).
const MATERIAL_ALPHA_MIN: f32 = 1e-3;
// Smallest |n·v| and |n·l| used in the BRDF (grazing guard).
const MATERIAL_COS_MIN: f32 = 1e-4;
// Variance of a unit-width box footprint (as FOURIER_BOX_VARIANCE).
const MATERIAL_BOX_VARIANCE: f32 = 0.0833333333333333;
// Largest radiance passed to the tone mapper (keeps f32 arithmetic finite).
const MATERIAL_RADIANCE_MAX: f32 = 65504.0;

// ─── Small helpers ───────────────────────────────────────────────────────────────────────

// v / |v|, or `fallback` when v is zero or not finite.
fn safe_normalize(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let len2 = dot(v, v);
    if !(len2 > 1e-30) || !f32_is_finite(len2) {
        return fallback;
    }
    return v * inverseSqrt(len2);
}

// Every non-finite or negative channel → 0, the rest clamped to MATERIAL_RADIANCE_MAX.
fn sanitize_radiance(c: vec3<f32>) -> vec3<f32> {
    let zero = vec3<f32>(0.0);
    return select(zero, clamp(c, zero, vec3<f32>(MATERIAL_RADIANCE_MAX)), vec3_is_finite(c));
}

// ─── Thickness ───────────────────────────────────────────────────────────────────────────

// Film thickness d (nm) for a map value g ∈ [0, 1] (NaN → 0.5, clamped) at normalised object
// height h ∈ [−1, 1] (h = 1 at the top; NaN → 1: no drainage).
fn material_thickness_nm(g_raw: f32, h_raw: f32) -> f32 {
    let p = material_params;
    let g = clamp(finite_or(g_raw, 0.5), 0.0, 1.0);
    let h = clamp(finite_or(h_raw, 1.0), -1.0, 1.0);
    var d: f32;
    if p.thickness_mode == MATERIAL_THICKNESS_GLTF {
        d = mix(p.thickness_a_nm, p.thickness_b_nm, g);
    } else {
        d = p.thickness_a_nm + p.thickness_b_nm * (2.0 * g - 1.0);
    }
    d += p.thickness_drain_nm * 0.5 * (1.0 - h);
    return clamp(finite_or(d, 0.0), 0.0, THICKNESS_MAX_NM);
}

// ∂d/∂g of the current thickness mode (nm per unit of g).
fn material_thickness_slope_nm() -> f32 {
    let p = material_params;
    if p.thickness_mode == MATERIAL_THICKNESS_GLTF {
        return finite_or(p.thickness_b_nm - p.thickness_a_nm, 0.0);
    }
    return finite_or(2.0 * p.thickness_b_nm, 0.0);
}

// σ_d (nm) from the screen-space derivatives of d (nm per pixel) and a sub-pixel thickness
// roughness (nm): √(max(∂d/∂x, ∂d/∂y)²/12 + roughness²) — the formula of
// fourier_sigma_from_derivatives (film_fourier.wgsl). Non-finite inputs count as 0; the
// result is at most THICKNESS_MAX_NM.
fn material_thickness_sigma(d_thickness_dx: f32, d_thickness_dy: f32, roughness_nm: f32) -> f32 {
    let gx = finite_or(d_thickness_dx, 0.0);
    let gy = finite_or(d_thickness_dy, 0.0);
    let r = finite_or(roughness_nm, 0.0);
    let g2 = max(gx * gx, gy * gy);
    return min(sqrt(g2 * MATERIAL_BOX_VARIANCE + r * r), THICKNESS_MAX_NM);
}

// The thickness map's texel (E[g], E[g²], E[g_G], E[g_B]) at `uv` for a footprint given by
// the uv derivatives (textureSampleGrad: no implicit derivatives, so it may be called in
// non-uniform control flow). g is channel R (or grey), g_G and g_B the map's other channels
// for a stack's films (a two-channel texture reads as (0, 1) there). Non-finite uv → the
// map's centre; a non-finite component → its flat-map value.
fn material_sample_thickness_texel(uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>) -> vec4<f32> {
    let ok = f32_is_finite(uv.x) && f32_is_finite(uv.y);
    let st = select(vec2<f32>(0.5), uv, ok);
    let gx = select(vec2<f32>(0.0), duv_dx, vec3_is_finite(vec3<f32>(duv_dx, 0.0)).xy);
    let gy = select(vec2<f32>(0.0), duv_dy, vec3_is_finite(vec3<f32>(duv_dy, 0.0)).xy);
    let m = textureSampleGrad(thickness_map, thickness_sampler, st, gx, gy);
    let finite = vec4<bool>(vec3_is_finite(m.xyz), f32_is_finite(m.w));
    return select(vec4<f32>(0.5, 0.25, 0.5, 0.5), m, finite);
}

// The thickness map's (E[g], E[g²]) at `uv` (material_sample_thickness_texel's first two).
fn material_sample_thickness_map(uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>) -> vec2<f32> {
    return material_sample_thickness_texel(uv, duv_dx, duv_dy).xy;
}

// The sub-pixel thickness std. dev. (nm) that the map's filtering removed, combined with the
// material's thickness roughness: √(roughness² + (∂d/∂g)² (E[g²] − E[g]²)).
fn material_thickness_roughness_nm(moments: vec2<f32>) -> f32 {
    let var_g = max(moments.y - moments.x * moments.x, 0.0);
    let slope = material_thickness_slope_nm();
    let r = finite_or(material_params.thickness_roughness_nm, 0.0);
    return sqrt(r * r + slope * slope * var_g);
}

// ─── Environment ─────────────────────────────────────────────────────────────────────────

// Equirectangular coordinates of a unit direction: u = 0.5 + atan2(x, −z)/(2π),
// v = acos(y)/π (v = 0 at the zenith).
fn env_direction_to_uv(dir: vec3<f32>) -> vec2<f32> {
    let d = safe_normalize(dir, vec3<f32>(0.0, 1.0, 0.0));
    let u = 0.5 + atan2(d.x, -d.z) / TWO_PI;
    let v = acos(clamp(d.y, -1.0, 1.0)) / PI;
    return vec2<f32>(u, v);
}

// The last mip level of the environment (from the uniform: GLSL ES has no textureQueryLevels).
fn env_lod_max() -> f32 {
    return max(finite_or(view.env_lod_max, 0.0), 0.0);
}

// Environment radiance towards `dir` at mip level `lod` (clamped), times env_intensity.
fn env_radiance(dir: vec3<f32>, lod: f32) -> vec3<f32> {
    let uv = env_direction_to_uv(dir);
    let k = clamp(finite_or(lod, 0.0), 0.0, env_lod_max());
    let c = textureSampleLevel(env_map, env_sampler, uv, k).rgb;
    return sanitize_radiance(c * max(finite_or(view.env_intensity, 0.0), 0.0));
}

// Mip level k(α) = log2(max(2αH/π, 1)) for the reflected lobe of a GGX surface.
fn env_specular_lod(alpha: f32) -> f32 {
    let h = f32(max(textureDimensions(env_map, 0u).y, 1u));
    return log2(max(2.0 * alpha * h / PI, 1.0));
}

// L̃(r, α): the GGX-prefiltered environment towards `dir` for roughness α (level
// k = √α (L − 1): layers ⌊k⌋ and ⌊k⌋ + 1 sampled bilinearly and mixed), times env_intensity.
fn env_prefiltered_radiance(dir: vec3<f32>, alpha: f32) -> vec3<f32> {
    let uv = env_direction_to_uv(dir);
    let k = clamp(sqrt(clamp(finite_or(alpha, 0.0), 0.0, 1.0)) * (ENV_PREFILTER_LEVELS - 1.0), 0.0, ENV_PREFILTER_LEVELS - 1.0);
    let k0 = min(u32(floor(k)), u32(ENV_PREFILTER_LEVELS) - 2u);
    let f = k - f32(k0);
    let c0 = textureSampleLevel(env_prefiltered, env_sampler, uv, k0, 0.0).rgb;
    let c1 = textureSampleLevel(env_prefiltered, env_sampler, uv, k0 + 1u, 0.0).rgb;
    return sanitize_radiance(mix(c0, c1, f) * max(finite_or(view.env_intensity, 0.0), 0.0));
}

// Visible GGX normals per pixel of the exact path's environment quadrature (header).
const MATERIAL_LOBE_SAMPLES: u32 = 32u;
// Golden-angle step of the lobe's Fibonacci spiral in u₂: (3 − √5)/2.
const MATERIAL_LOBE_SPIRAL: f32 = 0.3819660112501051;
// Footprint scale k_FIS of the lobe samples' filtered importance sampling (header).
const MATERIAL_LOBE_FIS_SCALE: f32 = 0.7;

// A GGX visible normal for view wo (local frame, n = +z) and u ∈ [0, 1)²: Heitz 2018,
// "Sampling the GGX Distribution of Visible Normals", JCGT 7(4), Listing 1 (the routine
// nacre_optics::microfacet::sample_ggx_vndf implements on the CPU).
fn ggx_sample_vndf(wo: vec3<f32>, alpha: f32, u: vec2<f32>) -> vec3<f32> {
    let vh = normalize(vec3<f32>(alpha * wo.x, alpha * wo.y, wo.z));
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1v = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(-vh.y, vh.x, 0.0) * inverseSqrt(max(lensq, 1e-30)), lensq > 0.0);
    let t2v = cross(vh, t1v);
    let r = sqrt(u.x);
    let phi = TWO_PI * u.y;
    let t1 = r * cos(phi);
    let s = 0.5 * (1.0 + vh.z);
    let t2 = (1.0 - s) * sqrt(max(1.0 - t1 * t1, 0.0)) + s * r * sin(phi);
    let nh = t1 * t1v + t2 * t2v + sqrt(max(1.0 - t1 * t1 - t2 * t2, 0.0)) * vh;
    return normalize(vec3<f32>(alpha * nh.x, alpha * nh.y, max(nh.z, 0.0)));
}

// Smith Λ of GGX for a direction of cosine c to the normal: (−1 + √(1 + α² tan²θ)) / 2.
fn ggx_lambda(c: f32, alpha: f32) -> f32 {
    let c2 = max(c * c, 1e-8);
    return 0.5 * (sqrt(1.0 + alpha * alpha * max(1.0 - c2, 0.0) / c2) - 1.0);
}

// Mip level used for the diffuse (cosine-weighted) lookup.
fn env_diffuse_lod() -> f32 {
    return max(env_lod_max() - 2.0, 0.0);
}

// ─── GGX ─────────────────────────────────────────────────────────────────────────────────

// D(h) = α² / (π ((n·h)² (α² − 1) + 1)²).
fn ggx_distribution(n_dot_h: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let c = clamp(n_dot_h, 0.0, 1.0);
    let k = c * c * (a2 - 1.0) + 1.0;
    return a2 / max(PI * k * k, 1e-30);
}

// V = G₂(v, l) / (4 n·v n·l), height-correlated Smith (Heitz 2014 Eq. 99 with Eq. 72).
fn ggx_visibility(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let v = max(n_dot_v, MATERIAL_COS_MIN);
    let l = max(n_dot_l, MATERIAL_COS_MIN);
    let lambda_v = l * sqrt(v * v * (1.0 - a2) + a2);
    let lambda_l = v * sqrt(l * l * (1.0 - a2) + a2);
    return 0.5 / max(lambda_v + lambda_l, 1e-30);
}

// E_GGX(α) = 1 − 0.55 √α (Karis 2014, EnvBRDFApprox with F = 1).
fn ggx_albedo_scale(alpha: f32) -> f32 {
    return clamp(1.0 - 0.55 * sqrt(alpha), 0.0, 1.0);
}

// E₁(μ_o, α): the directional albedo of GGX with F = 1 (height-correlated Smith), from
// env_ggx_albedo at its texel centres.
fn ggx_albedo(n_dot_v: f32, alpha: f32) -> f32 {
    let t = clamp(vec2<f32>(finite_or(n_dot_v, 1.0), finite_or(alpha, 0.0)), vec2<f32>(0.0), vec2<f32>(1.0));
    let uv = (t * (GGX_ALBEDO_SIZE - 1.0) + 0.5) / GGX_ALBEDO_SIZE;
    return clamp(textureSampleLevel(env_ggx_albedo, env_lut_sampler, uv, 0.0).r, 0.0, 1.0);
}

// ─── Film ────────────────────────────────────────────────────────────────────────────────

// The technique's input for incidence cos θ, the point's thickness statistics (and the
// thickness map's variation per channel, for film_stack) and a base of index n + iκ per
// channel (`base_ior`, `base_kappa`: one lobe of SurfaceMaterial).
fn material_film_input(cos_theta: f32, thickness_nm: f32, sigma_thickness_nm: f32, variation: vec3<f32>, base_ior: vec3<f32>, base_kappa: vec3<f32>) -> FilmInput {
    let p = material_params;
    var input: FilmInput;
    input.cos_theta_i = cos_theta;
    input.thickness_nm = thickness_nm;
    input.film_ior = p.film_ior;
    input.sigma_thickness_nm = sigma_thickness_nm;
    input.ambient_ior = p.ambient_ior;
    input.variation = variation.x;
    input.variation_g = variation.y;
    input.variation_b = variation.z;
    input.base_ior = base_ior;
    input.base_kappa = base_kappa;
    return input;
}

// The bare base's unpolarised Fresnel reflectance per channel at incidence cos θ, seen from
// the ambient n₁ (fresnel_interface, (|r_s|² + |r_p|²)/2): the film-free part of a partially
// coated surface (film_weight < 1). The base is the lobe's (`base_ior`, `base_kappa`: the
// dielectric's or the metal's), and for the metal lobe of a two-lobe point (`schlick`) the
// bare reflectance is glTF's F_schlick(F0, v·h) with F0 the metal index's normal-incidence
// reflectance (glTF 2.0 Appendix B, conductor_fresnel). With `pane` (SurfaceMaterial.bare_pane)
// the base is a clear pane of that index in the ambient, its two faces' reflections summed
// in intensity, per polarisation (the incoherent slab of film_glass.wgsl with P = 1 and
// R′ = R_B = R, T = 1 − R: Byrnes, arXiv:1603.02720 §4):
//
//   R_pane = R + (1 − R)² R / (1 − R²) = 2R / (1 + R)
fn material_base_reflectance(cos_theta: f32, schlick: bool, base_ior: vec3<f32>, base_kappa: vec3<f32>, pane: bool) -> vec3<f32> {
    let p = material_params;
    let c = clamp(finite_or(cos_theta, 1.0), 1e-6, 1.0);
    if schlick {
        let n = max(base_ior, vec3<f32>(1e-3));
        let k2 = base_kappa * base_kappa;
        let f0 = ((n - 1.0) * (n - 1.0) + k2) / ((n + 1.0) * (n + 1.0) + k2);
        return clamp(f0 + (1.0 - f0) * pow(1.0 - c, 5.0), vec3<f32>(0.0), vec3<f32>(1.0));
    }
    let n1 = select(1.0, p.ambient_ior, f32_is_finite(p.ambient_ior) && p.ambient_ior > 0.0);
    let q0 = c_real(n1 * c);
    var r = vec3<f32>(0.0);
    for (var j = 0; j < 3; j++) {
        let nk = sanitize_base_index(base_ior[j], base_kappa[j]);
        let f = fresnel_interface(c_real(n1), q0, nk, normal_component_cos(nk, n1, c));
        let r_s = clamp(c_abs2(f.r_s), 0.0, 1.0);
        let r_p = clamp(c_abs2(f.r_p), 0.0, 1.0);
        if pane {
            r[j] = 0.5 * (2.0 * r_s / (1.0 + r_s) + 2.0 * r_p / (1.0 + r_p));
        } else {
            r[j] = 0.5 * (r_s + r_p);
        }
    }
    return r;
}

// The film's output blended with the bare base (index n + iκ) for a film weight w < 1 (see
// the header); w ≥ 1 (or NaN) returns the film unchanged.
fn material_weight_film(film: FilmOutput, cos_theta: f32, weight: f32, schlick: bool, base_ior: vec3<f32>, base_kappa: vec3<f32>, pane: bool) -> FilmOutput {
    let w = clamp(finite_or(weight, 1.0), 0.0, 1.0);
    if w >= 1.0 {
        return film;
    }
    let f_base = material_base_reflectance(cos_theta, schlick, base_ior, base_kappa, pane);
    var out: FilmOutput;
    out.reflectance = mix(f_base, film.reflectance, w);
    out.transmittance = mix(vec3<f32>(1.0) - f_base, film.transmittance, w);
    return out;
}

// E_f(μ_o, α, d, n₂): the iridescent GGX lobe's directional albedo from the rough-film-lut
// (two trilinear fetches, rough_lut_sample), blended for a film weight w < 1 with the bare
// base's F_base(n·v) E₁(n·v, α) (base index n + iκ).
fn material_rough_film_albedo(n_dot_v: f32, alpha: f32, thickness_nm: f32, weight: f32, schlick: bool, base_ior: vec3<f32>, base_kappa: vec3<f32>, pane: bool) -> vec3<f32> {
    let p = material_params;
    let e = rough_lut_sample(env_rough_lut, env_lut_sampler, env_rough_lut_params, n_dot_v, alpha, thickness_nm, p.film_ior);
    let e_film = select(vec3<f32>(0.0), clamp(e, vec3<f32>(0.0), vec3<f32>(1.0)), vec3_is_finite(e));
    let w = clamp(finite_or(weight, 1.0), 0.0, 1.0);
    if w >= 1.0 {
        return e_film;
    }
    return mix(material_base_reflectance(n_dot_v, schlick, base_ior, base_kappa, pane) * ggx_albedo(n_dot_v, alpha), e_film, w);
}

// ─── Shading ─────────────────────────────────────────────────────────────────────────────

// One shading point, as scene.wgsl finds it.
struct SurfacePoint {
    // World position (where the punctual lights are seen from).
    position: vec3<f32>,
    // Unit normal on the viewer's side.
    normal: vec3<f32>,
    // Unit vector from the point towards the viewer.
    view_dir: vec3<f32>,
    // Film thickness d at the point, nm.
    thickness_nm: f32,
    // Std. dev. of d inside the pixel, nm.
    sigma_thickness_nm: f32,
    // The thickness map's spatial variation s_c = 2g_c − 1 ∈ [−1, 1] of channels R (or grey),
    // G, B (film_stack moves its lower films by their channel's: d_j + r_j s_c; 0 where no
    // map is sampled).
    variation: vec3<f32>,
}

// What the surface sends towards the viewer, and what it lets through.
struct ShadeResult {
    // Reflected radiance (specular + diffuse), linear RGB.
    radiance: vec3<f32>,
    // Colour transmitted straight through a thin shell (0 unless transmission = 1).
    transmittance: vec3<f32>,
}

// The material at one shading point: what glTF's textures vary per point (mesh.wgsl fills it
// from the textures of a glTF material), or the uniform's constants (`material_surface`, the
// analytic scenes). glTF 2.0 specification, Appendix B (BRDF implementation):
//
//   material = mix(dielectric_brdf, metal_brdf, metallic)
//   dielectric_brdf = fresnel_mix(ior, diffuse_brdf(ρ), specular_brdf(α))
//   metal_brdf = conductor_fresnel(baseColor, specular_brdf(α))
//
// with KHR_materials_iridescence's film on both lobes (the extension's "Iridescence" section:
// the dielectric lobe's Fresnel term becomes the film over the dielectric base, the metal
// lobe's the film over the metal; weight w = iridescenceFactor × its texture's R), each lobe
// evaluated here by the technique (`film_colour`) on its own base index. A point whose
// metallic m is 0 or 1 evaluates one lobe (the analytic scenes always do); 0 < m < 1 both.
// KHR_materials_specular scales the dielectric lobe's reflectance by specular × specularColor
// (exact at normal incidence while F0 specularColor ≤ 1; the extension's F90 = specular is
// approximated by the same scale at grazing angles).
struct SurfaceMaterial {
    // Lambertian albedo ρ of the dielectric lobe (linear RGB).
    diffuse_colour: vec3<f32>,
    // m ∈ [0, 1]: the metal lobe's share.
    metallic: f32,
    // Base index of the dielectric lobe per channel (real part; κ below).
    dielectric_ior: vec3<f32>,
    // GGX α.
    roughness_alpha: f32,
    dielectric_kappa: vec3<f32>,
    // Film weight w ∈ [0, 1].
    film_weight: f32,
    // Base index of the metal lobe per channel.
    metal_ior: vec3<f32>,
    // Share t ∈ [0, 1] of the dielectric lobe that is a thin transparent shell (no diffuse).
    transmission: f32,
    metal_kappa: vec3<f32>,
    // Factor on the environment's (indirect) light: glTF occlusion, 1 + strength (ao − 1).
    occlusion: f32,
    // Scale of the dielectric lobe's reflectance (KHR_materials_specular); 1 = none.
    specular_colour: vec3<f32>,
    // Which lobes are evaluated, the same for every point of a draw: 0 the dielectric only,
    // 1 the metal only, 2 both (their shares 1 − m and m). (A per-point choice made
    // lavapipe's LLVM back end of Mesa 22 crash.)
    lobes: u32,
    // 1: the film-free share (w < 1) of the dielectric lobe is an uncoated clear pane of the
    // dielectric's index in the ambient, both faces summed in intensity (the technique
    // `film_glass` drawing a glTF glass: crates/runtime/src/mesh/materials.rs glass_setup);
    // 0: one interface, the bare base.
    bare_pane: u32,
}

// The uniform's material at every point: one lobe, dielectric or metal (base_kind), the
// uniform's base index for it, a thin shell when `transmission` is set.
fn material_surface() -> SurfaceMaterial {
    let p = material_params;
    let metal = p.base_kind != MATERIAL_BASE_DIELECTRIC;
    let diffuse_on = !metal && p.transmission == 0u;
    var m: SurfaceMaterial;
    m.diffuse_colour = select(vec3<f32>(0.0), clamp(p.base_colour, vec3<f32>(0.0), vec3<f32>(1.0)), diffuse_on && all(vec3_is_finite(p.base_colour)));
    m.metallic = select(0.0, 1.0, metal);
    m.dielectric_ior = p.base_ior;
    m.dielectric_kappa = p.base_kappa;
    m.metal_ior = p.base_ior;
    m.metal_kappa = p.base_kappa;
    m.roughness_alpha = p.roughness_alpha;
    m.film_weight = p.film_weight;
    m.transmission = select(0.0, 1.0, p.transmission != 0u);
    m.occlusion = 1.0;
    m.specular_colour = vec3<f32>(1.0);
    m.lobes = select(0u, 1u, metal);
    m.bare_pane = 0u;
    return m;
}

// A light as one shading point sees it.
struct MaterialLightSample {
    // Unit vector from the point towards the light.
    towards: vec3<f32>,
    // Irradiance at normal incidence, linear RGB.
    irradiance: vec3<f32>,
}

// Light slot `slot` seen from `position`: slot 0 is the directional light of the uniform's
// light_* fields, slot k ≥ 1 is lights[k − 1] (KHR_lights_punctual, "Range Property" and
// "Inner and Outer Cone Angles": E = radiant · clamp(1 − (r/range)⁴, 0, 1)² / r² · t² for a
// point or spot light at distance r, E = radiant for a directional one).
fn material_light_sample(slot: u32, position: vec3<f32>) -> MaterialLightSample {
    var out: MaterialLightSample;
    if slot == 0u {
        out.towards = safe_normalize(view.light_direction, vec3<f32>(0.0, 1.0, 0.0));
        out.irradiance = sanitize_radiance(view.light_colour * finite_or(view.light_intensity, 0.0));
        return out;
    }
    let light = view.lights[min(slot - 1u, VIEW_MAX_LIGHTS - 1u)];
    if light.kind == VIEW_LIGHT_DIRECTIONAL {
        out.towards = safe_normalize(-light.direction, vec3<f32>(0.0, 1.0, 0.0));
        out.irradiance = sanitize_radiance(light.radiant);
        return out;
    }
    let d = light.position - position;
    let r2 = max(dot(d, d), 1e-12);
    out.towards = d * inverseSqrt(r2);
    let window = clamp(1.0 - r2 * r2 * light.inv_range4, 0.0, 1.0);
    let t = clamp(dot(light.direction, -out.towards) * light.cone_scale + light.cone_offset, 0.0, 1.0);
    out.irradiance = sanitize_radiance(light.radiant * (window * window * t * t / r2));
    return out;
}

// Shades one point of the film-coated surface with the uniform's material.
fn material_shade(s: SurfacePoint) -> ShadeResult {
    return material_shade_with(s, material_surface());
}

// Shades one point of the film-coated surface (see the header for the model) with the
// point's material `mat` (SurfaceMaterial: one or two lobes).
//
// Compile-time care: `film_colour` is called from exactly one place, inside a loop whose trip
// count (1 or 2, plus the lobe samples, times the lobes) is not a compile-time
// constant, so that shader compilers that inline every call (Mesa's NIR → LLVM in lavapipe)
// see one copy of the technique — film_fourier's loops, inlined several times, make LLVM's
// loop analyses take minutes. scene.wgsl and mesh.wgsl likewise call this from one place.
fn material_shade_with(s: SurfacePoint, mat: SurfaceMaterial) -> ShadeResult {
    let n = safe_normalize(s.normal, vec3<f32>(0.0, 1.0, 0.0));
    let v = safe_normalize(s.view_dir, n);
    let alpha = clamp(finite_or(mat.roughness_alpha, 0.0), MATERIAL_ALPHA_MIN, 1.0);
    let n_dot_v = clamp(dot(n, v), MATERIAL_COS_MIN, 1.0);
    let metallic = clamp(finite_or(mat.metallic, 0.0), 0.0, 1.0);
    let transmission = clamp(finite_or(mat.transmission, 0.0), 0.0, 1.0);
    let specular_scale = clamp(select(vec3<f32>(1.0), mat.specular_colour, vec3_is_finite(mat.specular_colour)), vec3<f32>(0.0), vec3<f32>(1.0));
    let occlusion = clamp(finite_or(mat.occlusion, 1.0), 0.0, 1.0);
    // The dielectric lobe's diffuse weight (1 − m)(1 − t); 0 for a metal or a thin shell.
    let diffuse_weight = (1.0 - metallic) * (1.0 - transmission);
    let albedo = select(vec3<f32>(0.0), clamp(mat.diffuse_colour, vec3<f32>(0.0), vec3<f32>(1.0)), diffuse_weight > 0.0 && all(vec3_is_finite(mat.diffuse_colour))) * diffuse_weight;
    let mode = select(MATERIAL_FILM_EVAL_CLASSIC, material_params.film_eval, material_params.film_eval <= MATERIAL_FILM_EVAL_EXACT);
    // Lobes: 0 the dielectric, 1 the metal; both when 0 < m < 1.
    let lobe_count = select(1u, 2u, mat.lobes == 2u);
    let first_lobe = select(0u, 1u, mat.lobes == 1u);

    // Per lobe: the film at n·v (environment, transmission, and every light for the
    // shortcut), the film of each light at its own v·h when the path evaluates the film per
    // light (light slot 0, the directional light, then the view's punctual lights), and for
    // the exact path at each of the lobe's MATERIAL_LOBE_SAMPLES visible
    // normals (see the header: the environment's distribution over the lobe, weighted by the
    // film). Each lobe's reflectance enters weighted by its share (1 − m or m).
    // (Separate variables, not arrays indexed by the lobe: lavapipe's LLVM back end of Mesa
    // 22 crashed on the divergent indexing.)
    var film_v_d: FilmOutput;
    var film_v_m: FilmOutput;
    // Each light's evaluation runs whether or not the light is above the surface (its
    // result is used only when it is): a trip count that varies per fragment made lavapipe
    // (Mesa 22.3, LLVM 15) crash compiling the mesh shader once its material varies per
    // fragment. The count of lights is the view's, the same for every fragment.
    let light_slots = 1u + min(view.light_count, VIEW_MAX_LIGHTS);
    let light_evaluations = select(0u, light_slots, mode != MATERIAL_FILM_EVAL_NV);
    let lobe_samples = select(0u, MATERIAL_LOBE_SAMPLES, mode == MATERIAL_FILM_EVAL_EXACT);
    let evaluations = 1u + light_evaluations + lobe_samples;
    // The lobe's frame (n = +z) and the view in it.
    let frame_up = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.x) > 0.9);
    let frame_t = safe_normalize(cross(frame_up, n), vec3<f32>(1.0, 0.0, 0.0));
    let frame_b = cross(n, frame_t);
    let wo = normalize(vec3<f32>(dot(v, frame_t), dot(v, frame_b), n_dot_v));
    let lambda_o = ggx_lambda(wo.z, alpha);
    var lobe_film_env = vec3<f32>(0.0);
    var lobe_film = vec3<f32>(0.0);
    // Σ over the lights of (specular + diffuse) · E · n·l, accumulated lobe by lobe.
    var light_radiance = vec3<f32>(0.0);
    for (var kk = 0u; kk < evaluations * lobe_count; kk++) {
        let lobe = first_lobe + kk / evaluations;
        let k = kk % evaluations;
        let base_ior = select(mat.dielectric_ior, mat.metal_ior, lobe == 1u);
        let base_kappa = select(mat.dielectric_kappa, mat.metal_kappa, lobe == 1u);
        let share = select(1.0, select(1.0 - metallic, metallic, lobe == 1u), lobe_count == 2u);
        let scale = select(specular_scale, vec3<f32>(1.0), lobe == 1u) * share;
        // A light's slot, its direction and half vector (slot 0 for the other evaluations:
        // their values are not used).
        let is_light = k >= 1u && k <= light_evaluations;
        let light = material_light_sample(select(0u, k - 1u, is_light), s.position);
        let h = safe_normalize(v + light.towards, n);
        let n_dot_l = dot(n, light.towards);
        var cos_theta = select(n_dot_v, clamp(dot(v, h), 0.0, 1.0), is_light);
        var lobe_weight = 0.0;
        var lobe_dir = n;
        var lobe_alpha = alpha;
        if k > light_evaluations {
            let i = k - 1u - light_evaluations;
            let u = vec2<f32>((f32(i) + 0.5) / f32(MATERIAL_LOBE_SAMPLES), fract(f32(i) * MATERIAL_LOBE_SPIRAL));
            let m = ggx_sample_vndf(wo, alpha, u);
            cos_theta = clamp(dot(wo, m), 0.0, 1.0);
            let l = 2.0 * cos_theta * m - wo;
            // G₂/G₁ = (1 + Λ(v)) / (1 + Λ(v) + Λ(l)); 0 below the horizon.
            lobe_weight = select(0.0, (1.0 + lambda_o) / (1.0 + lambda_o + ggx_lambda(l.z, alpha)), l.z > 0.0);
            lobe_dir = l.x * frame_t + l.y * frame_b + l.z * n;
            // The sample's footprint: α_i = k_FIS √(n·v (1 + Λ(v)) / (π N D(m))).
            let density = PI * f32(MATERIAL_LOBE_SAMPLES) * ggx_distribution(m.z, alpha);
            lobe_alpha = MATERIAL_LOBE_FIS_SCALE * sqrt(wo.z * (1.0 + lambda_o) / max(density, 1e-30));
        }
        let film = material_weight_film(film_colour(material_film_input(cos_theta, s.thickness_nm, s.sigma_thickness_nm, s.variation, base_ior, base_kappa)), cos_theta, mat.film_weight, lobe == 1u && lobe_count == 2u, base_ior, base_kappa, lobe == 0u && mat.bare_pane != 0u);
        if k == 0u {
            if lobe == 0u {
                film_v_d = film;
            } else {
                film_v_m = film;
            }
        } else if is_light {
            // The lobe's share of this light: its specular term with the film at v·h, and
            // for the dielectric lobe the diffuse base under what the film does not reflect.
            var f = ggx_distribution(dot(n, h), alpha) * ggx_visibility(n_dot_v, max(n_dot_l, 0.0), alpha) * film.reflectance * scale;
            if lobe == 0u {
                f += albedo / PI * max(vec3<f32>(1.0) - film.reflectance * specular_scale, vec3<f32>(0.0));
            }
            light_radiance += select(vec3<f32>(0.0), f * light.irradiance * n_dot_l, n_dot_l > 0.0);
        } else {
            let f = lobe_weight * film.reflectance * scale;
            lobe_film += f;
            lobe_film_env += f * env_prefiltered_radiance(lobe_dir, lobe_alpha);
        }
    }
    // The lobes' reflectances weighted by their shares (one lobe: itself, unscaled but for
    // the dielectric's specular colour).
    let one = vec3<f32>(1.0);
    let w_d = select(1.0, 1.0 - metallic, lobe_count == 2u) * f32(first_lobe == 0u);
    let w_m = select(1.0, metallic, lobe_count == 2u) * f32(first_lobe == 1u || lobe_count == 2u);
    let spec_d = specular_scale * w_d;
    let reflectance_v = film_v_d.reflectance * spec_d + film_v_m.reflectance * w_m;
    // What the dielectric lobe's film does not reflect reaches its diffuse base.
    let diffuse_v = max(one - film_v_d.reflectance * specular_scale, vec3<f32>(0.0));

    // Environment.
    let r = reflect(-v, n);
    var radiance = vec3<f32>(0.0);
    if mode == MATERIAL_FILM_EVAL_CLASSIC {
        // Specular at reflect(−v, n) with the film at n·v, diffuse at n.
        radiance = env_radiance(r, env_specular_lod(alpha)) * reflectance_v * ggx_albedo_scale(alpha);
        radiance += env_radiance(n, env_diffuse_lod()) * albedo * diffuse_v;
    } else {
        // Split sum: L̃(r, α) · E.
        let e_one = ggx_albedo(n_dot_v, alpha);
        var e_spec = reflectance_v * e_one;
        var mean_reflectance = film_v_d.reflectance * specular_scale;
        if mode == MATERIAL_FILM_EVAL_EXACT {
            let e_d = material_rough_film_albedo(n_dot_v, alpha, s.thickness_nm, mat.film_weight, false, mat.dielectric_ior, mat.dielectric_kappa, mat.bare_pane != 0u);
            let e_m = material_rough_film_albedo(n_dot_v, alpha, s.thickness_nm, mat.film_weight, lobe_count == 2u, mat.metal_ior, mat.metal_kappa, false);
            e_spec = e_d * spec_d + e_m * w_m;
            mean_reflectance = e_d * specular_scale / max(e_one, 1e-4);
        }
        var env_lobe = env_prefiltered_radiance(r, alpha);
        if mode == MATERIAL_FILM_EVAL_EXACT {
            // The film-weighted mean of the environment over the lobe (per channel), where
            // the lobe reflects anything; the prefiltered value otherwise.
            env_lobe = select(env_lobe, lobe_film_env / max(lobe_film, vec3<f32>(1e-8)), lobe_film > vec3<f32>(1e-6));
        }
        radiance = env_lobe * e_spec;
        radiance += env_radiance(n, env_diffuse_lod()) * albedo * max(one - mean_reflectance, vec3<f32>(0.0));
    }
    radiance *= occlusion;

    // The lights: evaluated in the loop above, or here with the film at n·v (the shortcut).
    if mode == MATERIAL_FILM_EVAL_NV {
        for (var j = 0u; j < light_slots; j++) {
            let light = material_light_sample(j, s.position);
            let n_dot_l = dot(n, light.towards);
            let h = safe_normalize(v + light.towards, n);
            let specular = ggx_distribution(dot(n, h), alpha) * ggx_visibility(n_dot_v, max(n_dot_l, 0.0), alpha) * reflectance_v;
            let diffuse = albedo / PI * diffuse_v;
            light_radiance += select(vec3<f32>(0.0), (specular + diffuse) * light.irradiance * n_dot_l, n_dot_l > 0.0);
        }
    }
    radiance += light_radiance;

    var out: ShadeResult;
    out.radiance = sanitize_radiance(radiance);
    out.transmittance = vec3<f32>(0.0);
    if transmission > 0.0 && first_lobe == 0u {
        out.transmittance = clamp(film_v_d.transmittance * transmission * w_d, vec3<f32>(0.0), one);
    }
    return out;
}

// ─── Output ──────────────────────────────────────────────────────────────────────────────

// Linear scene radiance → the sRGB-encoded colour written to the Rgba8Unorm target:
// exposure, PBR Neutral, sRGB. Non-finite or negative channels count as 0.
fn material_display(radiance: vec3<f32>) -> vec4<f32> {
    let exposed = sanitize_radiance(radiance * max(finite_or(view.exposure, 1.0), 0.0));
    let mapped = tone_map_pbr_neutral(exposed);
    return vec4<f32>(srgb_encode(mapped), 1.0);
}
