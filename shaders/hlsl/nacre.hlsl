// nacre · shaders/hlsl/nacre.hlsl — the film-lut, fourier and rough-film-lut lookups in HLSL
//
// An HLSL translation of shaders/common.wgsl, lut_mapping.wgsl, film_lut.wgsl,
// film_fourier.wgsl and rough_lut_mapping.wgsl, function by function (every WGSL function `f`
// is `nacre_f` here; each technique's `film_colour` is `nacre_film_lut_colour` /
// `nacre_film_fourier_colour`; structs are `Nacre…`, constants `NACRE_…`): the same numbers
// in the same order, so it computes what nacre computes (tests/tests/engine_shaders_gpu.rs
// compiles it with glslang to SPIR-V and proves it on a GPU against the CPU lookups).
// Each section below starts with its WGSL module's header: symbols, equations, sources.
//
// Targets: Shader Model 4.0+ HLSL as Unity (2022.3 LTS, Unity 6; FXC or DXC) and Unreal
// Engine (5.3+: FXC for Direct3D SM5, DXC for SM6, Vulkan and Metal; HLSL 2018 and 2021
// rules alike: no vector `?:`, no vector `&&`) compile
// it; shaders/hlsl/unity/NacreShaderGraph.hlsl wraps it for Shader Graph's Custom Function
// node, and Unreal includes it from a plugin shader directory as a .ush
// (docs/engines/unreal.md). It declares no resources: every function takes its table
// (`Texture3D<float4>` + `SamplerState`: linear filtering, clamp to edge; the fourier table
// as `Texture2DArray<float4>`, read with Load) and the table's axes as arguments, so an
// engine binds them its own way.
//
// Axis parameters: NacreFilmLutParams, NacreFourierParams and NacreRoughLutParams carry the
// fields of the WGSL uniforms of the same names (a cbuffer holding one of them has the WGSL
// uniform's bytes), built from a table's manifest (or the sidecar written by `nacre export`)
// with nacre_make_*_params. docs/engines/ has the steps per engine.

#ifndef NACRE_HLSL
#define NACRE_HLSL

// Component-wise c ? t : f (HLSL 2021 has no vector ?:, and FXC has no select()).
float3 nacre_select3(float3 f, float3 t, bool3 c) {
    return float3(c.x ? t.x : f.x, c.y ? t.y : f.y, c.z ? t.z : f.z);
}

// (width, height, layers) of level 0 of a 2-D array texture (GLSL textureSize, WGSL
// textureDimensions).
uint3 nacre_texture_2d_array_size(Texture2DArray<float4> t) {
    uint width;
    uint height;
    uint layers;
    uint levels;
    t.GetDimensions(0, width, height, layers, levels);
    return uint3(width, height, layers);
}

// ═══ shaders/common.wgsl ═══
//
// Constants, complex arithmetic, Snell's law and the Fresnel amplitudes of one interface,
// the exact Airy reflectance/transmittance of one film at one wavelength, NaN guards, and
// the technique contract `FilmInput` / `FilmOutput` (shaders/README.md). First module of
// every composition (`nacre_runtime::shaders::compose`); defines no bindings.
//
// Symbols (those of crates/optics/src/fresnel.rs and stack.rs)
//
//   symbol            code                  meaning
//   ñ = n + iκ        vec2<f32> (n, κ)      complex refractive index, κ ≥ 0 absorbs
//   n₁                n1, ambient_ior       ambient index (real, non-absorbing)
//   n₂                n2, film_ior          film index
//   ñ₃                n3, base_ior/kappa    base (substrate) index
//   θ₁                cos_theta             incidence angle in the ambient
//   β = n₁ sin θ₁                           tangential wave-vector component / k₀ (Snell)
//   q_j = ñ_j cos θ_j q_j                   normal component / k₀ in medium j, q_j² = ñ_j² − β²
//   k₀ = 2π/λ                               vacuum wavenumber, λ in nm
//   δ = k₀ q₂ d                             phase thickness of the film
//   r_s r_p t_s t_p   FresnelInterface      amplitudes from medium i into medium j
//   Γ, τ              gamma, tau            reflection/transmission amplitude below the film
//
// Conventions: Byrnes' `tmm` (arXiv:1603.02720), as crates/optics/src/fresnel.rs:
//   * time dependence exp(−iωt); a forward wave in medium j is exp(i k₀ q_j z), so the
//     physical branch of q_j = ±√(ñ_j² − β²) has Im q_j > 0 (decays), or Re q_j ≥ 0 when
//     Im q_j is rounding noise (propagates into the medium);
//   * r_s = (q_i − q_j)/(q_i + q_j),  t_s = 2 q_i/(q_i + q_j),
//     r_p = (ñ_j² q_i − ñ_i² q_j)/(ñ_j² q_i + ñ_i² q_j),  t_p = 2 ñ_i ñ_j q_i/(ñ_j² q_i + ñ_i² q_j)
//     (Born & Wolf §1.5; Byrnes Eq. 5–8): at normal incidence r_p = −r_s;
//   * power transmittance T_s = |t_s|² Re(q_f)/Re(q_0),
//     T_p = |t_p|² Re(ñ_f conj(cos θ_f))/Re(ñ_0 conj(cos θ_0)) (Byrnes Eq. 21–22).
//
// Airy formula of one film (Heavens 1955 §4; Belcour & Barla 2017 Eq. 2; the recurrence of
// crates/optics/src/stack.rs for one film; Sussenbach 2013 §3.1):
//   r = (r₁₂ + Γ e^{2iδ}) / (1 + r₁₂ Γ e^{2iδ}),  t = t₁₂ τ e^{iδ} / (1 + r₁₂ Γ e^{2iδ}),
//   Γ = r₂₃, τ = t₂₃, δ = 2π d q₂ / λ.
//
// f32 care: q_j² is formed as (n_j − n₁)(n_j + n₁) − κ_j² + (n₁ cos θ)² + 2i n_j κ_j, which is
// ñ_j² − n₁² sin²θ without the cancellation of 1 − cos²θ near grazing incidence; phases are
// reduced with fract() in cycles before the multiplication by 2π.
//
// NaN guards: WGSL has no isnan, and `x != x` may be folded away by fast-math compilers, so
// finiteness is tested on the bits (exponent all ones = NaN or ±∞).

static const float NACRE_PI = 3.14159265358979;
static const float NACRE_TWO_PI = 6.28318530717959;
// Smallest cos θ₁ at which the physics is evaluated (the film-lut bake's
// `nacre_format::film_lut::MIN_COS_THETA`): at exactly 90° q₁ = 0 and the power factors divide
// by zero; the CPU solver rejects 90° altogether.
static const float NACRE_COS_THETA_MIN = 1e-6;
// Largest film thickness (and thickness standard deviation) accepted, nm; larger clamps.
static const float NACRE_THICKNESS_MAX_NM = 1e6;
// Range every refractive index (real part n and κ) is clamped into: keeps ñ² a normal f32.
static const float NACRE_IOR_MIN = 1e-3;
static const float NACRE_IOR_MAX = 1e3;
// Base index used when the consumer passes NaN or ±∞.
static const float NACRE_BASE_IOR_FALLBACK = 1.5;
// Relative size below which Im q is rounding noise when choosing the forward branch
// (100 × f32 ε; fresnel.rs uses 100 × f64 ε).
static const float NACRE_BRANCH_TOLERANCE = 1.1920929e-5;

// The technique contract (shaders/README.md): the same fields, in the same order, as
// FilmInput of common.wgsl (64 bytes in a StructuredBuffer or cbuffer).
struct NacreFilmInput {
    float cos_theta_i;
    float thickness_nm;
    float film_ior;
    float sigma_thickness_nm;
    float ambient_ior;
    // Spatial variation s = 2g − 1 ∈ [−1, 1] of a stack's lower films, from the thickness
    // map's channels R (or grey), G and B (film_stack only).
    float variation;
    float variation_g;
    float variation_b;
    float3 base_ior;
    float _pad3;
    float3 base_kappa;
    float _pad4;
};

// Colour of the film's unpolarised reflectance and of its transmittance into the base, in the
// tables' output space (a perfect reflector = white). Always finite; a channel may be negative
// for colours outside the gamut of a linear RGB output space.
struct NacreFilmOutput {
    float3 reflectance;
    float3 transmittance;
};

// A FilmInput from its fields (padding zeroed): cos θ₁, d nm, n₂, σ_d nm, n₁, and the base's
// n and κ per output channel.
NacreFilmInput nacre_make_film_input(float cos_theta_i, float thickness_nm, float film_ior, float sigma_thickness_nm, float ambient_ior, float3 base_ior, float3 base_kappa) {
    NacreFilmInput i;
    i.cos_theta_i = cos_theta_i;
    i.thickness_nm = thickness_nm;
    i.film_ior = film_ior;
    i.sigma_thickness_nm = sigma_thickness_nm;
    i.ambient_ior = ambient_ior;
    i.variation = 0.0;
    i.variation_g = 0.0;
    i.variation_b = 0.0;
    i.base_ior = base_ior;
    i._pad3 = 0.0;
    i.base_kappa = base_kappa;
    i._pad4 = 0.0;
    return i;
}

// True unless x is NaN or ±∞ (bit test: exponent all ones).
bool nacre_f32_is_finite(float x) {
    return (asuint(x) & 0x7f800000u) != 0x7f800000u;
}

// True when x is NaN (exponent all ones, mantissa non-zero).
bool nacre_f32_is_nan(float x) {
    uint b = asuint(x);
    return (b & 0x7f800000u) == 0x7f800000u && (b & 0x007fffffu) != 0u;
}

bool3 nacre_vec3_is_finite(float3 v) {
    return (asuint(v) & (uint3)0x7f800000u) != (uint3)0x7f800000u;
}

// x when finite, else `fallback`.
float nacre_finite_or(float x, float fallback) {
    return nacre_f32_is_finite(x) ? x : fallback;
}

// a / b, or 0 when b is 0.
float nacre_safe_div(float a, float b) {
    if (b == 0.0) {
        return 0.0;
    }
    return a / b;
}

// x clamped to [0, 1], 0 when not finite (a power coefficient of a passive stack).
float nacre_unit_power(float x) {
    return nacre_f32_is_finite(x) ? clamp(x, 0.0, 1.0) : 0.0;
}

// Makes every field of a FilmInput usable:
//   cos_theta_i         NaN → 1 (normal incidence); clamped to [0, 1] (±∞ and cosines of
//                       back-facing directions go to the nearest end: 1 or 0 = grazing);
//   thickness_nm        NaN or ≤ 0 → 0; clamped to THICKNESS_MAX_NM (+∞ too);
//   sigma_thickness_nm  likewise;
//   ambient_ior         NaN, ±∞ or ≤ 0 → 1; clamped to [IOR_MIN, IOR_MAX];
//   film_ior            NaN, ±∞ or ≤ 0 → the (sanitised) ambient index; clamped likewise;
//   base_ior            NaN or ±∞ → BASE_IOR_FALLBACK (1.5); clamped to [IOR_MIN, IOR_MAX];
//   base_kappa          NaN, ±∞ or < 0 → 0; clamped to [0, IOR_MAX];
//   variation(_g, _b)   NaN → 0; clamped to [−1, 1];
//   _pad*               0.
// Techniques still evaluate the physics at max(cos_theta_i, COS_THETA_MIN).
NacreFilmInput nacre_sanitize_input(NacreFilmInput inp) {
    NacreFilmInput o;
    o.cos_theta_i = nacre_f32_is_nan(inp.cos_theta_i) ? 1.0 : clamp(inp.cos_theta_i, 0.0, 1.0);
    o.thickness_nm = (inp.thickness_nm > 0.0 && !nacre_f32_is_nan(inp.thickness_nm)) ? min(inp.thickness_nm, NACRE_THICKNESS_MAX_NM) : 0.0;
    o.sigma_thickness_nm = (inp.sigma_thickness_nm > 0.0 && !nacre_f32_is_nan(inp.sigma_thickness_nm)) ? min(inp.sigma_thickness_nm, NACRE_THICKNESS_MAX_NM) : 0.0;
    bool ambient_ok = nacre_f32_is_finite(inp.ambient_ior) && inp.ambient_ior > 0.0;
    o.ambient_ior = clamp(ambient_ok ? inp.ambient_ior : 1.0, NACRE_IOR_MIN, NACRE_IOR_MAX);
    bool film_ok = nacre_f32_is_finite(inp.film_ior) && inp.film_ior > 0.0;
    o.film_ior = clamp(film_ok ? inp.film_ior : o.ambient_ior, NACRE_IOR_MIN, NACRE_IOR_MAX);
    bool3 base_ok = nacre_vec3_is_finite(inp.base_ior);
    o.base_ior = clamp(nacre_select3((float3)NACRE_BASE_IOR_FALLBACK, inp.base_ior, base_ok), (float3)NACRE_IOR_MIN, (float3)NACRE_IOR_MAX);
    bool3 kappa_finite = nacre_vec3_is_finite(inp.base_kappa);
    bool3 kappa_ok = bool3(kappa_finite.x && inp.base_kappa.x > 0.0, kappa_finite.y && inp.base_kappa.y > 0.0, kappa_finite.z && inp.base_kappa.z > 0.0);
    o.base_kappa = nacre_select3((float3)0.0, min(inp.base_kappa, (float3)NACRE_IOR_MAX), kappa_ok);
    o.variation = nacre_f32_is_nan(inp.variation) ? 0.0 : clamp(inp.variation, -1.0, 1.0);
    o.variation_g = nacre_f32_is_nan(inp.variation_g) ? 0.0 : clamp(inp.variation_g, -1.0, 1.0);
    o.variation_b = nacre_f32_is_nan(inp.variation_b) ? 0.0 : clamp(inp.variation_b, -1.0, 1.0);
    o._pad3 = 0.0;
    o._pad4 = 0.0;
    return o;
}

// The complex index (n, κ) of a base channel, sanitised as in sanitize_input.
float2 nacre_sanitize_base_index(float n, float kappa) {
    float re = clamp(nacre_f32_is_finite(n) ? n : NACRE_BASE_IOR_FALLBACK, NACRE_IOR_MIN, NACRE_IOR_MAX);
    float im = (nacre_f32_is_finite(kappa) && kappa > 0.0) ? min(kappa, NACRE_IOR_MAX) : 0.0;
    return float2(re, im);
}

// Every channel that is NaN or ±∞ becomes 0. Negative channels are kept: they are the
// out-of-gamut colours of linear RGB spaces, exactly as the CPU methods return them (a
// consumer clamps after lighting and tone mapping, not before).
NacreFilmOutput nacre_sanitize_output(NacreFilmOutput outp) {
    NacreFilmOutput o;
    float3 zero = (float3)0.0;
    o.reflectance = nacre_select3(zero, outp.reflectance, nacre_vec3_is_finite(outp.reflectance));
    o.transmittance = nacre_select3(zero, outp.transmittance, nacre_vec3_is_finite(outp.transmittance));
    return o;
}

float2 nacre_c_real(float x) {
    return float2(x, 0.0);
}

float2 nacre_c_mul(float2 a, float2 b) {
    return float2(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

float2 nacre_c_conj(float2 a) {
    return float2(a.x, -a.y);
}

// |a|².
float nacre_c_abs2(float2 a) {
    return dot(a, a);
}

// |a|, scaled so that it neither overflows nor underflows.
float nacre_c_abs(float2 a) {
    float s = max(abs(a.x), abs(a.y));
    if (s == 0.0) {
        return 0.0;
    }
    float2 b = a / s;
    return s * sqrt(dot(b, b));
}

// a / b (Smith-style scaling by max(|Re b|, |Im b|)); 0 when b = 0.
float2 nacre_c_div(float2 a, float2 b) {
    float s = max(abs(b.x), abs(b.y));
    if (!(s > 0.0)) {
        return ((float2)(0.0));
    }
    float2 bs = b / s;
    float2 a_s = a / s;
    return float2(a_s.x * bs.x + a_s.y * bs.y, a_s.y * bs.x - a_s.x * bs.y) / dot(bs, bs);
}

float2 nacre_c_inv(float2 b) {
    return nacre_c_div(float2(1.0, 0.0), b);
}

// Principal square root (Re ≥ 0; Im with the sign of Im z, +0 counted as positive — WGSL does
// not promise signed zeros), without cancellation in either part.
float2 nacre_c_sqrt(float2 z) {
    float r = nacre_c_abs(z);
    if (r == 0.0) {
        return ((float2)(0.0));
    }
    if (z.x >= 0.0) {
        float t = sqrt(0.5 * (r + z.x));
        return float2(t, 0.5 * z.y / t);
    }
    float t = sqrt(0.5 * (r - z.x));
    return float2(0.5 * abs(z.y) / t, z.y >= 0.0 ? t : -t);
}

// r e^{iφ}.
float2 nacre_c_polar(float r, float phi) {
    return r * float2(cos(phi), sin(phi));
}

// e^{iz} = e^{−Im z} (cos Re z, sin Re z); finite for Im z ≥ 0.
float2 nacre_c_exp_i(float2 z) {
    return nacre_c_polar(exp(-z.y), z.x);
}

// e^{2πi x} for a phase x in cycles, reduced with fract() first so that large phases keep
// their fractional part.
float2 nacre_c_exp_i_cycles(float x) {
    float phi = NACRE_TWO_PI * frac(x);
    return float2(cos(phi), sin(phi));
}

// The sign of q describing a wave travelling or decaying towards +z: Im q > 0, or Re q ≥ 0
// when Im q is rounding noise (|Im q| ≤ BRANCH_TOLERANCE · max(|Re q|, |Im q|)).
float2 nacre_forward_branch(float2 q) {
    float scale = max(abs(q.x), abs(q.y));
    bool forward;
    if (abs(q.y) > NACRE_BRANCH_TOLERANCE * scale) {
        forward = q.y > 0.0;
    } else {
        forward = q.x >= 0.0;
    }
    return forward ? q : -q;
}

// q = √(ñ² − β²) on the forward branch, for a tangential component β = n₁ sin θ₁.
float2 nacre_normal_component(float2 n, float beta) {
    return nacre_forward_branch(nacre_c_sqrt(nacre_c_mul(n, n) - float2(beta * beta, 0.0)));
}

// The same q for β = n₁ sin θ₁ given as (n₁, cos θ₁), formed as
// (n − n₁)(n + n₁) − κ² + (n₁ cos θ₁)² + 2inκ: exact for ñ = n₁ (q = n₁ cos θ₁) and free of
// the cancellation in 1 − cos² θ₁ near grazing incidence.
float2 nacre_normal_component_cos(float2 n, float n_ambient, float cos_theta) {
    float a = n_ambient * cos_theta;
    float2 q2 = float2((n.x - n_ambient) * (n.x + n_ambient) - n.y * n.y + a * a, 2.0 * n.x * n.y);
    return nacre_forward_branch(nacre_c_sqrt(q2));
}

struct NacreFresnelInterface {
    float2 r_s;
    float2 r_p;
    float2 t_s;
    float2 t_p;
};

// From medium i (index n_i, normal component q_i) into medium j.
NacreFresnelInterface nacre_fresnel_interface(float2 n_i, float2 q_i, float2 n_j, float2 q_j) {
    NacreFresnelInterface o;
    float2 sum_s = q_i + q_j;
    o.r_s = nacre_c_div(q_i - q_j, sum_s);
    o.t_s = nacre_c_div(2.0 * q_i, sum_s);
    float2 a = nacre_c_mul(nacre_c_mul(n_j, n_j), q_i);
    float2 b = nacre_c_mul(nacre_c_mul(n_i, n_i), q_j);
    float2 sum_p = a + b;
    o.r_p = nacre_c_div(a - b, sum_p);
    o.t_p = nacre_c_div(2.0 * nacre_c_mul(nacre_c_mul(n_i, n_j), q_i), sum_p);
    return o;
}

// |t_s|² → T_s between incidence medium (q_0) and exit medium (q_f): Re(q_f) / Re(q_0).
float nacre_power_factor_s(float2 q_0, float2 q_f) {
    return nacre_safe_div(q_f.x, q_0.x);
}

// |t_p|² → T_p: Re(ñ_f conj(cos θ_f)) / Re(ñ_0 conj(cos θ_0)), cos θ = q / ñ.
float nacre_power_factor_p(float2 n_0, float2 q_0, float2 n_f, float2 q_f) {
    float num = nacre_c_mul(n_f, nacre_c_conj(nacre_c_div(q_f, n_f))).x;
    float den = nacre_c_mul(n_0, nacre_c_conj(nacre_c_div(q_0, n_0))).x;
    return nacre_safe_div(num, den);
}

// (R, |t|²) of one polarisation from the top interface (r₁₂, t₁₂), the base seen from the
// film (Γ, τ), e^{iδ} and e^{2iδ}: R = |r₁₂ + Γe^{2iδ}|² / |1 + r₁₂Γe^{2iδ}|²,
// |t|² = |t₁₂ τ e^{iδ}|² / |1 + r₁₂Γe^{2iδ}|².
float2 nacre_airy_polarisation(float2 r12, float2 t12, float2 gamma, float2 tau, float2 e1, float2 e2) {
    float2 ge2 = nacre_c_mul(gamma, e2);
    float2 num = r12 + ge2;
    float den = nacre_c_abs2(float2(1.0, 0.0) + nacre_c_mul(r12, ge2));
    float2 t = nacre_c_mul(nacre_c_mul(t12, tau), e1);
    return float2(nacre_safe_div(nacre_c_abs2(num), den), nacre_safe_div(nacre_c_abs2(t), den));
}

// Exact powers (R_s, R_p, T_s, T_p) of ambient n₁ | film ñ₂, d nm | base ñ₃ at vacuum
// wavelength λ nm and cos θ₁ (callers pass cos θ₁ ≥ COS_THETA_MIN). Each power is clamped
// to [0, 1] (non-finite → 0): the stack is passive.
float4 nacre_airy_film_power(float n1, float2 n2, float2 n3, float cos_theta, float thickness_nm, float wavelength_nm) {
    float2 a = nacre_c_real(n1);
    float2 q1 = nacre_c_real(n1 * cos_theta);
    float2 q2 = nacre_normal_component_cos(n2, n1, cos_theta);
    float2 q3 = nacre_normal_component_cos(n3, n1, cos_theta);
    NacreFresnelInterface top = nacre_fresnel_interface(a, q1, n2, q2);
    NacreFresnelInterface bottom = nacre_fresnel_interface(n2, q2, n3, q3);
    float x = nacre_safe_div(thickness_nm, wavelength_nm);
    float2 e1 = nacre_c_exp_i_cycles(x * q2.x) * exp(-NACRE_TWO_PI * x * q2.y);
    float2 e2 = nacre_c_exp_i_cycles(2.0 * x * q2.x) * exp(-2.0 * NACRE_TWO_PI * x * q2.y);
    float2 s = nacre_airy_polarisation(top.r_s, top.t_s, bottom.r_s, bottom.t_s, e1, e2);
    float2 p = nacre_airy_polarisation(top.r_p, top.t_p, bottom.r_p, bottom.t_p, e1, e2);
    float factor_s = nacre_power_factor_s(q1, q3);
    float factor_p = nacre_power_factor_p(a, q1, n3, q3);
    return float4(nacre_unit_power(s.x), nacre_unit_power(p.x), nacre_unit_power(s.y * factor_s), nacre_unit_power(p.y * factor_p));
}

// ═══ shaders/lut_mapping.wgsl ═══
//
// The film-lut axis mappings, forward (physical → t ∈ [0, 1]³) and inverse, mirroring
// `nacre_format::film_lut::FilmLutAxes` (crates/format/src/film_lut.rs, whose module docs derive
// them). Needs common.wgsl; defines no bindings.
//
// Symbols
//
//   symbol                 code                      meaning
//   θ                      cos_theta                 incidence angle in the ambient
//   n₀                     p.ambient_index           ambient index baked into the table
//   d                      thickness_nm              film thickness, nm
//   n                      film_ior                  real film index
//   q(n) = √(n² − n₀² sin²θ) lut_film_q              film normal component (= n cos θ_film)
//   Δ = 2 d q(n)           lut_opd_nm                optical path difference, nm
//   Δ_max = 2 d_max n_max  lut_opd_max_nm            top of the Δ axis, nm
//   t = (tₓ, t_y, t_z)     vec3<f32>                 normalised coordinates
//
// Mapping (film_lut.rs `forward` / `inverse`)
//
//   tₓ = √cos θ                       cos θ = tₓ²
//   t_y = Δ / Δ_max                   Δ = t_y Δ_max
//   t_z = √((q(n) − q_min)/(q_max − q_min)),  q_min/max = q(n_min/max) at the same θ
//   (t_z = 0 when q_max ≤ q_min); every non-finite t becomes 0, the rest clamp to [0, 1].
//
// Texel-centre convention (the same as the bake): on an axis of `count` texels texel i holds
// t = i / (count − 1), reached at texture coordinate u = (t (count − 1) + 0.5) / count, so a
// linear sampler with clamp-to-edge addressing reproduces `FilmLut::lookup`.
//
// f32 care: q² is formed as (n − n₀)(n + n₀) + (n₀ cos θ)², which is n² − n₀²(1 − cos²θ)
// without its cancellation near grazing incidence (where q_min → 0 and the t_z square root
// is steepest).

// Mirror of `FilmLutAxes` (48 bytes in a cbuffer): the fields of FilmLutParams.
struct NacreFilmLutParams {
    uint cos_theta_count;
    uint opd_count;
    uint ior_count;
    float thickness_min_nm;
    float thickness_max_nm;
    float ior_min;
    float ior_max;
    float ambient_index;
    uint has_transmittance;
    uint _pad0;
    uint _pad1;
    uint _pad2;
};

// The parameters from a table's axes (the manifest's `film_lut` record, or the sidecar of
// `nacre export`): counts, thickness and index ranges, ambient index, transmittance flag.
NacreFilmLutParams nacre_make_film_lut_params(uint3 counts, float2 thickness_range_nm, float2 ior_range, float ambient_index, bool has_transmittance) {
    NacreFilmLutParams p;
    p.cos_theta_count = counts.x;
    p.opd_count = counts.y;
    p.ior_count = counts.z;
    p.thickness_min_nm = thickness_range_nm.x;
    p.thickness_max_nm = thickness_range_nm.y;
    p.ior_min = ior_range.x;
    p.ior_max = ior_range.y;
    p.ambient_index = ambient_index;
    p.has_transmittance = has_transmittance ? 1u : 0u;
    p._pad0 = 0u;
    p._pad1 = 0u;
    p._pad2 = 0u;
    return p;
}

// Texel counts (x, y, z) as floats, at least 1.
float3 nacre_lut_counts(NacreFilmLutParams p) {
    return ((float3)(max(uint3(p.cos_theta_count, p.opd_count, p.ior_count), (uint3)1u)));
}

// Δ_max = 2 d_max n_max, nm.
float nacre_lut_opd_max_nm(NacreFilmLutParams p) {
    return 2.0 * p.thickness_max_nm * p.ior_max;
}

// q(n) = √max(n² − n₀² sin²θ, 0), with sin²θ = max(1 − cos²θ, 0) as in the Rust.
float nacre_lut_film_q(NacreFilmLutParams p, float cos_theta, float film_ior) {
    float c = min(abs(cos_theta), 1.0);
    float a = p.ambient_index;
    float ac = a * c;
    return sqrt(max((film_ior - a) * (film_ior + a) + ac * ac, 0.0));
}

// Δ = 2 d q(n), nm.
float nacre_lut_opd_nm(NacreFilmLutParams p, float cos_theta, float thickness_nm, float film_ior) {
    return 2.0 * thickness_nm * nacre_lut_film_q(p, cos_theta, film_ior);
}

// Forward mapping: physical (cos θ, d nm, n) → t ∈ [0, 1]³.
float3 nacre_lut_forward(NacreFilmLutParams p, float cos_theta, float thickness_nm, float film_ior) {
    if (nacre_f32_is_nan(cos_theta)) {
        return (float3)0.0;
    }
    float c = clamp(cos_theta, 0.0, 1.0);
    float tx = sqrt(c);
    float ty = nacre_lut_opd_nm(p, c, thickness_nm, film_ior) / nacre_lut_opd_max_nm(p);
    float q_min = nacre_lut_film_q(p, c, p.ior_min);
    float q_max = nacre_lut_film_q(p, c, p.ior_max);
    float tz = 0.0;
    if (q_max > q_min) {
        tz = sqrt(max((nacre_lut_film_q(p, c, film_ior) - q_min) / (q_max - q_min), 0.0));
    }
    float3 t = float3(tx, ty, tz);
    return nacre_select3((float3)0.0, clamp(t, (float3)0.0, (float3)1.0), nacre_vec3_is_finite(t));
}

// Inverse mapping: t → (cos θ, Δ nm, n).
float3 nacre_lut_inverse(NacreFilmLutParams p, float3 t) {
    float c = t.x * t.x;
    float q_min = nacre_lut_film_q(p, c, p.ior_min);
    float q_max = nacre_lut_film_q(p, c, p.ior_max);
    float q = q_min + t.z * t.z * (q_max - q_min);
    float a = p.ambient_index;
    float ac = a * c;
    float n = sqrt(max(q * q + a * a - ac * ac, 0.0));
    return float3(c, t.y * nacre_lut_opd_max_nm(p), n);
}

// Texture coordinate that samples t on axes of `counts` texels: (t (count − 1) + 0.5) / count.
float3 nacre_lut_texture_coordinate(float3 t, float3 counts) {
    float3 n = max(counts, (float3)1.0);
    return (t * (n - 1.0) + 0.5) / n;
}


// ═══ shaders/film_lut.wgsl ═══
//
// Thin-film colour by one trilinear lookup in a baked `film-lut` table
// (crates/format/src/film_lut.rs): texel (x, y, z) holds the colour of the unpolarised
// reflectance (binding 0) and transmittance into the base (binding 1) of
// `ambient | film(n, d) | fixed layers | base`, integrated exactly over 360–830 nm, at
// (cos θ, Δ, n) given by the forward mapping of lut_mapping.wgsl. Needs common.wgsl and
// lut_mapping.wgsl.
//
// Symbols
//
//   symbol      code                    meaning
//   t           lut_forward(…)          normalised coordinates ∈ [0, 1]³ (lut_mapping.wgsl)
//   uvw         lut_texture_coordinate  texture coordinate: (t (count − 1) + 0.5) / count
//   R, T        FilmOutput              colours in the table's output space
//
// `FilmLut::lookup` (trilinear between texel centres, clamp to edge) is what a linear
// sampler computes at uvw, up to the hardware's reduced-precision filter weights (commonly 8
// fractional bits) and the texture format (Rgba16Float rounds texels to ≈ 3 significant
// digits).
//
// FilmInput fields used: cos_theta_i, thickness_nm, film_ior. The ambient, the base and the
// fixed layers are baked into the table (FilmLutParams.ambient_index is the table's; the
// runtime checks that the material's ambient matches), and sigma_thickness_nm is ignored.

// `film_colour` of film_lut.wgsl with its bindings as arguments: `reflectance` and
// `transmittance` are the table's two 3-D textures (the second may be any texture when
// p.has_transmittance = 0), sampled with linear min/mag filtering and clamp-to-edge
// addressing; `p` mirrors the table's axes.
NacreFilmOutput nacre_film_lut_colour(Texture3D<float4> reflectance, SamplerState reflectance_sampler, Texture3D<float4> transmittance, SamplerState transmittance_sampler, NacreFilmLutParams p, NacreFilmInput raw) {
    NacreFilmInput inp = nacre_sanitize_input(raw);
    float3 t = nacre_lut_forward(p, inp.cos_theta_i, inp.thickness_nm, inp.film_ior);
    float3 uvw = nacre_lut_texture_coordinate(t, nacre_lut_counts(p));
    NacreFilmOutput o;
    o.reflectance = reflectance.SampleLevel(reflectance_sampler, uvw, 0.0).rgb;
    o.transmittance = (float3)0.0;
    if (p.has_transmittance != 0u) {
        o.transmittance = transmittance.SampleLevel(transmittance_sampler, uvw, 0.0).rgb;
    }
    return nacre_sanitize_output(o);
}

// ═══ shaders/film_fourier.wgsl ═══
//
// Thin-film colour by Belcour & Barla 2017, "A Practical Extension to Microfacet Theory for
// the Modeling of Varying Iridescence", Eq. 10, with exact Fresnel amplitudes and phases per
// polarisation and the sensitivities' Fourier transforms Ŝ_j read from a baked, prefiltered,
// mip-mapped `fourier` table. The GPU twin of `FilmOnBase::fourier_colour_with`
// (crates/optics/src/fourier.rs) fed by `FourierTable::sample`
// (crates/bake/src/kinds/fourier.rs). Needs common.wgsl.
//
// Symbols
//
//   symbol               code                 meaning
//   n₁, n₂, ñ₃           n1, n2, n3           ambient, film, base (per channel j) indices
//   q₂ = √(n₂² − n₁² sin²θ) q2               film normal component; q₂² ≤ 0: evanescent film
//   D = 2 d q₂           opd                  optical path difference, nm
//   τ = 2 q₂             tau                  dD/dd
//   r₁₂, Γ               top.r_*, bottom.r_*  film-top amplitude; base amplitude seen from the film
//   β = (1 − r₁₂²) Γ     (airy_series_*)
//   ρ = −r₁₂ Γ           AirySeries.rho       ratio of successive harmonics
//   c₀, K = c₁           AirySeries.c0, .k    Airy Fourier coefficients, c_m = ρ^{m−1} K
//   Ŝ_j(μ, σ_μ)          fourier_sample       transform of channel j's sensitivity at μ,
//                                             prefiltered by a Gaussian of std. dev. σ_μ in μ
//   A_j,k                the table            demodulated envelope Ŝ_j e^{+2πiμν̄_j} of level k
//   ν̄_j                  carrier_nu_per_nm    channel centroid frequency, 1/nm
//   ‖s_j‖                white                colour of a perfect reflector
//   σ_d                  sigma_thickness_nm   std. dev. of d in the pixel, nm
//   M                    harmonics            number of harmonics (0 = auto, the default)
//
// Eq. 10 in closed form (fourier.rs module docs), per polarisation, then averaged:
//
//   R:  c₀ = |r₁₂|² + |β|²/(1 − |ρ|²),  K = β r₁₂* + |β|² ρ/(1 − |ρ|²)
//   T:  c₀ = a,  K = a ρ,  a = |t₁₂ t₂₃|² × power factor / (1 − |ρ|²)   (dielectric base only)
//   C_j = ‖s_j‖ [c₀ + 2 Σ_{m=1}^{M} Re(c_m conj Ŝ_j(m D, m τ σ_d))]
//
// and Ŝ_j from the table (fourier_table.rs module docs; `FourierTable::sample`):
//
//   lod = σ_μ < σ₁ ? σ_μ/σ₁ : 1 + log2(σ_μ/σ₁), clamped to the last level (0 without levels)
//   A   = lerp between levels ⌊lod⌋ and ⌊lod⌋ + 1 by fract(lod) of the linear interpolation
//         within level k at x = μ/D_max · N_k − 0.5 (texel centres at (i + 0.5)/N_k),
//         clamped to [0, N_k − 1]
//   Ŝ_j = A_j e^{−2πi μ ν̄_j}
//
// read with textureLoad from a texture_2d_array (layer 0 Re A, layer 1 Im A; mip k = level k,
// N_k = max(N₀ >> k, 1) texels, N₀ the level-0 width): the same weights as the CPU, in f32.
//
// Details that follow the CPU exactly:
//   * fixed M: the film index is blended to the ambient's as the film vanishes,
//     n₂' = n₁ + (n₂ − n₁) smoothstep(0, 30 nm, d) (Belcour & Barla §4); auto M: no blend;
//   * auto M (harmonics = 0, the default): after each harmonic m, stop once for every channel
//     j and polarisation 2|c_{m+1}|/(1 − |ρ|) · max_j |Ŝ_j(m D)| ≤ ε max(c̄₀,j, 0.01)^(2/3),
//     ε = 1e-3 and c̄₀,j the s/p average of c₀ (fourier.rs module docs, "How many
//     harmonics"), at most FOURIER_MAX_HARMONICS (the CPU's MAX_AUTO_HARMONICS);
//     reflectance and transmittance stop separately, as the CPU's two calls do;
//   * prefiltering (§5): harmonic m sees σ_μ = m τ σ_d;
//   * total internal reflection at the base and conductor bases need nothing special: the
//     complex normal components carry them.
// Where this differs:
//   * a fixed M is clamped to FOURIER_MAX_HARMONICS too;
//   * transmittance is always computed, and is 0 for channels whose base absorbs (κ > 0; the
//     CPU refuses transmittance there);
//   * an evanescent film (q₂² ≤ 0, where the CPU returns None and `nacre color` falls back to
//     spectral integration) gets the exact Airy R and T of the film evaluated at each
//     channel's centroid wavelength 1/ν̄_j, times ‖s_j‖: the spectrum of an evanescent film
//     does not oscillate in 1/λ, so one wavelength per channel is close to the integral; at
//     d = 0 it is the bare base's Fresnel reflectance, at large d total reflection;
//   * 1 − |ρ|² is kept ≥ FOURIER_MIN_ONE_MINUS_RHO2 (f32 guard near grazing incidence).
//
// FilmInput fields used: all (cos_theta_i, thickness_nm, film_ior, sigma_thickness_nm,
// ambient_ior, base_ior, base_kappa).

// Largest number of harmonics summed, auto or fixed.
static const uint NACRE_FOURIER_MAX_HARMONICS = 128u;
// Tolerance ε of the auto stopping rule at a mean level of 1 (fourier.rs AUTO_TOLERANCE).
static const float NACRE_FOURIER_AUTO_TOLERANCE = 1e-3;
// Lowest mean level the auto tolerance is scaled to (fourier.rs AUTO_LEVEL_FLOOR).
static const float NACRE_FOURIER_AUTO_LEVEL_FLOOR = 0.01;
// Thickness over which fixed-harmonic evaluation blends the film index, nm
// (fourier.rs THIN_FILM_BLEND_NM).
static const float NACRE_FOURIER_THIN_FILM_BLEND_NM = 30.0;
// Smallest 1 − |ρ|² used in the Airy coefficients.
static const float NACRE_FOURIER_MIN_ONE_MINUS_RHO2 = 1e-6;
// Variance of a unit-width box footprint (fourier_sigma_from_derivatives).
static const float NACRE_FOURIER_BOX_VARIANCE = 0.0833333333333333;
// The runtime's default number of harmonics (`TechniqueOptions::harmonics` = 0, as
// `nacre color --method fourier`): 0 selects the automatic count, per pixel.
static const uint NACRE_FOURIER_DEFAULT_HARMONICS = 0u;

// Mirror of `FourierAxes` and the harmonic count (48 bytes in a cbuffer).
struct NacreFourierParams {
    float max_opd_nm;
    uint level_count;
    float sigma1_nm;
    uint harmonics;
    float3 carrier_nu_per_nm;
    float _pad0;
    float3 white;
    float _pad1;
};

// The parameters from a table's axes (the manifest's `fourier` record): D_max, the number of
// levels, level_sigma_nm[1] (0 with one level), the carriers ν̄_j, the white ‖s_j‖, and M.
NacreFourierParams nacre_make_fourier_params(float max_opd_nm, uint level_count, float sigma1_nm, float3 carrier_nu_per_nm, float3 white, uint harmonics) {
    NacreFourierParams p;
    p.max_opd_nm = max_opd_nm;
    p.level_count = level_count;
    p.sigma1_nm = sigma1_nm;
    p.harmonics = harmonics;
    p.carrier_nu_per_nm = carrier_nu_per_nm;
    p._pad0 = 0.0;
    p.white = white;
    p._pad1 = 0.0;
    return p;
}

// One complex number per output channel.
struct NacreComplexRgb {
    float3 re;
    float3 im;
};

NacreComplexRgb nacre_crgb_mul(NacreComplexRgb a, NacreComplexRgb b) {
    NacreComplexRgb o;
    o.re = a.re * b.re - a.im * b.im;
    o.im = a.re * b.im + a.im * b.re;
    return o;
}

// Re(a conj b) per channel.
float3 nacre_crgb_re_mul_conj(NacreComplexRgb a, NacreComplexRgb b) {
    return a.re * b.re + a.im * b.im;
}

// Airy Fourier coefficients of one polarisation: R or T = c₀ + 2 Σ Re(c_m e^{imΦ}),
// c_m = ρ^{m−1} K (fourier.rs `AirySeries`).
struct NacreAirySeries {
    float c0;
    float2 k;
    float2 rho;
};

// 1 / (1 − |ρ|²), guarded.
float nacre_airy_inverse_loss(float2 rho) {
    return 1.0 / max(1.0 - nacre_c_abs2(rho), NACRE_FOURIER_MIN_ONE_MINUS_RHO2);
}

// Reflectance series from the film-top amplitude r₁₂ and the base amplitude Γ.
NacreAirySeries nacre_airy_series_reflectance(float2 r12, float2 gamma) {
    float2 one = float2(1.0, 0.0);
    float2 beta = nacre_c_mul(nacre_c_mul(one - r12, one + r12), gamma);
    float2 rho = -nacre_c_mul(r12, gamma);
    float inv = nacre_airy_inverse_loss(rho);
    float b2 = nacre_c_abs2(beta);
    NacreAirySeries s;
    s.c0 = nacre_c_abs2(r12) + b2 * inv;
    s.k = nacre_c_mul(beta, nacre_c_conj(r12)) + b2 * inv * rho;
    s.rho = rho;
    return s;
}

// Transmittance series T = a/(1 − |ρ|²)·… from t₁₂, t₂₃ and the power factor.
NacreAirySeries nacre_airy_series_transmittance(float2 t12, float2 t23, float factor, float2 rho) {
    float a = nacre_c_abs2(nacre_c_mul(t12, t23)) * factor * nacre_airy_inverse_loss(rho);
    NacreAirySeries s;
    s.c0 = a;
    s.k = a * rho;
    s.rho = rho;
    return s;
}

// The auto tolerance of a channel whose mean level is `level`: ε max(level, floor)^(2/3)
// (fourier.rs `auto_tolerance`).
float3 nacre_airy_auto_tolerance(float3 level) {
    return NACRE_FOURIER_AUTO_TOLERANCE * pow(max(level, float3(NACRE_FOURIER_AUTO_LEVEL_FLOOR, NACRE_FOURIER_AUTO_LEVEL_FLOOR, NACRE_FOURIER_AUTO_LEVEL_FLOOR)), float3(2.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0));
}

// Whether the terms after harmonic m are negligible for one polarisation: per channel
// 2|c_{m+1}|/(1 − |ρ|) · s_max ≤ tolerance, with c_m the m-th coefficient, s_max = max_j |Ŝ_j(m D)|
// (fourier.rs `AirySeries::tail_after`).
bool nacre_airy_tail_converged(NacreComplexRgb cm, NacreComplexRgb rho, float s_max, float3 tolerance) {
    float3 r = sqrt(rho.re * rho.re + rho.im * rho.im);
    float3 cm_abs = sqrt(cm.re * cm.re + cm.im * cm.im);
    float3 tail = 2.0 * cm_abs * r / max(1.0 - r, float3(1e-12, 1e-12, 1e-12)) * s_max;
    return all(tail <= tolerance);
}

// The fractional mip level for a prefilter width σ_μ, nm (`FourierAxes::lod`).
float nacre_fourier_lod(NacreFourierParams p, float sigma_mu_nm) {
    uint levels = max(p.level_count, 1u);
    if (levels < 2u || !nacre_f32_is_finite(sigma_mu_nm) || !(sigma_mu_nm > 0.0) || !(p.sigma1_nm > 0.0)) {
        return 0.0;
    }
    float s1 = p.sigma1_nm;
    float lod;
    if (sigma_mu_nm < s1) {
        lod = sigma_mu_nm / s1;
    } else {
        lod = 1.0 + log2(sigma_mu_nm / s1);
    }
    return min(lod, float(levels - 1u));
}

// The envelope A_j at μ in level k: linear between texel centres, clamp to edge
// (`FourierTable::sample_level`).
NacreComplexRgb nacre_fourier_sample_level(Texture2DArray<float4> table, NacreFourierParams p, uint level, float mu_nm) {
    uint n = max(uint(nacre_texture_2d_array_size(table).x) >> min(level, 31u), 1u);
    float nf = float(n);
    float d_max = p.max_opd_nm;
    float u = d_max > 0.0 ? mu_nm / d_max : 0.0;
    float x = clamp(u * nf - 0.5, 0.0, nf - 1.0);
    uint i0 = min(uint(floor(x)), n - 1u);
    uint i1 = min(i0 + 1u, n - 1u);
    float f = x - float(i0);
    int lod = int(level);
    float3 re0 = table.Load(int4(int3(int(i0), 0, 0), lod)).rgb;
    float3 re1 = table.Load(int4(int3(int(i1), 0, 0), lod)).rgb;
    float3 im0 = table.Load(int4(int3(int(i0), 0, 1), lod)).rgb;
    float3 im1 = table.Load(int4(int3(int(i1), 0, 1), lod)).rgb;
    NacreComplexRgb o;
    o.re = lerp(re0, re1, f);
    o.im = lerp(im0, im1, f);
    return o;
}

// Ŝ_j(μ) prefiltered at σ_μ (`FourierTable::sample`): the envelope blended between the two
// levels around the fractional lod, times the carrier e^{−2πiμν̄_j}.
NacreComplexRgb nacre_fourier_sample(Texture2DArray<float4> table, NacreFourierParams p, float mu_nm, float sigma_mu_nm) {
    uint levels = max(p.level_count, 1u);
    float lod = nacre_fourier_lod(p, sigma_mu_nm);
    uint k0 = uint(floor(lod));
    float f = lod - float(k0);
    NacreComplexRgb a = nacre_fourier_sample_level(table, p, k0, mu_nm);
    if (f > 0.0 && k0 + 1u < levels) {
        NacreComplexRgb a1 = nacre_fourier_sample_level(table, p, k0 + 1u, mu_nm);
        a.re = lerp(a.re, a1.re, f);
        a.im = lerp(a.im, a1.im, f);
    }
    float3 phi = -NACRE_TWO_PI * frac(mu_nm * p.carrier_nu_per_nm);
    NacreComplexRgb carrier;
    carrier.re = cos(phi);
    carrier.im = sin(phi);
    return nacre_crgb_mul(a, carrier);
}

// The prefilter width σ_d (nm) for a consumer that knows the screen-space derivatives of the
// thickness (e.g. dpdx/dpdy of a thickness map, nm per pixel) and a sub-pixel thickness
// roughness (nm, std. dev.): σ_d = √(max(∂d/∂x, ∂d/∂y)² / 12 + roughness²). A thickness that
// varies linearly across a one-pixel box footprint with slope g is uniformly distributed over
// a width |g|, whose variance is g²/12 (FOURIER_BOX_VARIANCE); the larger axis is taken so
// that anisotropic footprints are not under-filtered, and independent roughness adds in
// quadrature. Non-finite inputs count as 0; the result is at most THICKNESS_MAX_NM.
float nacre_fourier_sigma_from_derivatives(float d_thickness_dx, float d_thickness_dy, float roughness_nm) {
    float gx = nacre_finite_or(d_thickness_dx, 0.0);
    float gy = nacre_finite_or(d_thickness_dy, 0.0);
    float r = nacre_finite_or(roughness_nm, 0.0);
    float g2 = max(gx * gx, gy * gy);
    return min(sqrt(g2 * NACRE_FOURIER_BOX_VARIANCE + r * r), NACRE_THICKNESS_MAX_NM);
}

// Evanescent film: the exact Airy R and T at each channel's centroid wavelength 1/ν̄_j
// (550 nm if ν̄_j is not positive), times ‖s_j‖. `input` is sanitised, cos_theta ≥ COS_THETA_MIN.
NacreFilmOutput nacre_fourier_evanescent_colour(NacreFourierParams p, NacreFilmInput inp, float cos_theta) {
    NacreFilmOutput o;
    for (int j = 0; j < 3; j++) {
        float nu = p.carrier_nu_per_nm[j];
        float wavelength_nm = (nacre_f32_is_finite(nu) && nu > 1e-6) ? 1.0 / nu : 550.0;
        float2 n3 = float2(inp.base_ior[j], inp.base_kappa[j]);
        float4 power = nacre_airy_film_power(inp.ambient_ior, nacre_c_real(inp.film_ior), n3, cos_theta, inp.thickness_nm, wavelength_nm);
        o.reflectance[j] = 0.5 * (power.x + power.y);
        o.transmittance[j] = inp.base_kappa[j] == 0.0 ? 0.5 * (power.z + power.w) : 0.0;
    }
    o.reflectance *= p.white;
    o.transmittance *= p.white;
    return nacre_sanitize_output(o);
}

// `film_colour` of film_fourier.wgsl with its bindings as arguments: `table` is the fourier
// table (RGBA32F 2-D array, layer 0 Re A, layer 1 Im A, mip k = level k; read with
// texelFetch, so any filter), `p` mirrors its axes and the harmonics M.
NacreFilmOutput nacre_film_fourier_colour(Texture2DArray<float4> table, NacreFourierParams p, NacreFilmInput raw) {
    NacreFilmInput inp = nacre_sanitize_input(raw);
    float c = max(inp.cos_theta_i, NACRE_COS_THETA_MIN);
    float n1 = inp.ambient_ior;
    float d = inp.thickness_nm;

    float n2 = inp.film_ior;
    if (p.harmonics != 0u) {
        float s = clamp(d / NACRE_FOURIER_THIN_FILM_BLEND_NM, 0.0, 1.0);
        n2 = n1 + (n2 - n1) * s * s * (3.0 - 2.0 * s);
    }
    float n1c = n1 * c;
    float q2_sq = (n2 - n1) * (n2 + n1) + n1c * n1c;
    if (!(q2_sq > 0.0)) {
        return nacre_fourier_evanescent_colour(p, inp, c);
    }
    float q2 = sqrt(q2_sq);
    float opd = 2.0 * d * q2;
    float tau = 2.0 * q2;
    float sigma_d = inp.sigma_thickness_nm;

    float2 a = nacre_c_real(n1);
    float2 q1 = nacre_c_real(n1c);
    float2 film = nacre_c_real(n2);
    float2 q2c = nacre_c_real(q2);
    NacreFresnelInterface top = nacre_fresnel_interface(a, q1, film, q2c);
    float3 c0_r = (float3)0.0;
    float3 c0_t = (float3)0.0;
    NacreComplexRgb k_rs;
    k_rs.re = (float3)0.0;
    k_rs.im = (float3)0.0;
    NacreComplexRgb k_rp = k_rs;
    NacreComplexRgb k_ts = k_rs;
    NacreComplexRgb k_tp = k_rs;
    NacreComplexRgb rho_s = k_rs;
    NacreComplexRgb rho_p = k_rs;
    NacreAirySeries rs;
    NacreAirySeries rp;
    NacreAirySeries ts;
    NacreAirySeries tp;
    float2 previous = float2(-1.0, -1.0);
    for (int j = 0; j < 3; j++) {
        float2 n3 = float2(inp.base_ior[j], inp.base_kappa[j]);
        if (any(n3 != previous)) {
            previous = n3;
            float2 q3 = nacre_normal_component_cos(n3, n1, c);
            NacreFresnelInterface bottom = nacre_fresnel_interface(film, q2c, n3, q3);
            rs = nacre_airy_series_reflectance(top.r_s, bottom.r_s);
            rp = nacre_airy_series_reflectance(top.r_p, bottom.r_p);
            bool transmits = inp.base_kappa[j] == 0.0;
            float factor_s = transmits ? nacre_power_factor_s(q1, q3) : 0.0;
            float factor_p = transmits ? nacre_power_factor_p(a, q1, n3, q3) : 0.0;
            ts = nacre_airy_series_transmittance(top.t_s, bottom.t_s, factor_s, rs.rho);
            tp = nacre_airy_series_transmittance(top.t_p, bottom.t_p, factor_p, rp.rho);
        }
        c0_r[j] = 0.5 * (rs.c0 + rp.c0);
        c0_t[j] = 0.5 * (ts.c0 + tp.c0);
        k_rs.re[j] = rs.k.x;
        k_rs.im[j] = rs.k.y;
        k_rp.re[j] = rp.k.x;
        k_rp.im[j] = rp.k.y;
        k_ts.re[j] = ts.k.x;
        k_ts.im[j] = ts.k.y;
        k_tp.re[j] = tp.k.x;
        k_tp.im[j] = tp.k.y;
        rho_s.re[j] = rs.rho.x;
        rho_s.im[j] = rs.rho.y;
        rho_p.re[j] = rp.rho.x;
        rho_p.im[j] = rp.rho.y;
    }
    bool automatic = p.harmonics == 0u;
    uint m_max = automatic ? NACRE_FOURIER_MAX_HARMONICS : min(p.harmonics, NACRE_FOURIER_MAX_HARMONICS);
    float3 tolerance_r = nacre_airy_auto_tolerance(c0_r);
    float3 tolerance_t = nacre_airy_auto_tolerance(c0_t);

    NacreComplexRgb cm_rs = k_rs;
    NacreComplexRgb cm_rp = k_rp;
    NacreComplexRgb cm_ts = k_ts;
    NacreComplexRgb cm_tp = k_tp;
    float3 sum_r = float3(0.0, 0.0, 0.0);
    float3 sum_t = float3(0.0, 0.0, 0.0);
    bool done_r = false;
    bool done_t = false;
    for (uint m = 1u; m <= m_max; m++) {
        if (m > 1u) {
            cm_rs = nacre_crgb_mul(cm_rs, rho_s);
            cm_rp = nacre_crgb_mul(cm_rp, rho_p);
            cm_ts = nacre_crgb_mul(cm_ts, rho_s);
            cm_tp = nacre_crgb_mul(cm_tp, rho_p);
        }
        float mf = float(m);
        NacreComplexRgb s_hat = nacre_fourier_sample(table, p, mf * opd, mf * tau * sigma_d);
        if (!done_r) {
            sum_r += nacre_crgb_re_mul_conj(cm_rs, s_hat) + nacre_crgb_re_mul_conj(cm_rp, s_hat);
        }
        if (!done_t) {
            sum_t += nacre_crgb_re_mul_conj(cm_ts, s_hat) + nacre_crgb_re_mul_conj(cm_tp, s_hat);
        }
        if (automatic) {
            float3 s_abs = sqrt(s_hat.re * s_hat.re + s_hat.im * s_hat.im);
            float s_max = max(s_abs.x, max(s_abs.y, s_abs.z));
            done_r = done_r || (nacre_airy_tail_converged(cm_rs, rho_s, s_max, tolerance_r)
                && nacre_airy_tail_converged(cm_rp, rho_p, s_max, tolerance_r));
            done_t = done_t || (nacre_airy_tail_converged(cm_ts, rho_s, s_max, tolerance_t)
                && nacre_airy_tail_converged(cm_tp, rho_p, s_max, tolerance_t));
            if (done_r && done_t) {
                break;
            }
        }
    }
    NacreFilmOutput o;
    o.reflectance = (c0_r + sum_r) * p.white;
    o.transmittance = nacre_select3((c0_t + sum_t) * p.white, (float3)0.0, (inp.base_kappa > (float3)0.0));
    return nacre_sanitize_output(o);
}

// ═══ shaders/rough_lut_mapping.wgsl ═══
//
// The rough-film-lut axis mappings, forward (physical → t ∈ [0, 1]⁴) and inverse, and the
// two-fetch lookup of the pre-integrated directional albedo, mirroring
// `nacre_format::rough_film_lut::{RoughLutAxes, RoughFilmLut::lookup}` (crates/bake/src/kinds/rough_film_lut/mod.rs,
// whose module docs derive them). Self-contained: needs no other module and defines no
// bindings (the caller passes its texture, sampler and parameters).
//
// Symbols
//
//   symbol                       code                        meaning
//   θ_o                          cos_theta_o                 view angle to the normal, cos θ_o = N·V
//   α                            alpha                       GGX roughness (perceptual roughness²)
//   n₀                           p.ambient_index             ambient index baked into the table
//   d                            thickness_nm                film thickness, nm
//   n_f                          film_ior                    real film index
//   q(n, c) = √(n² − n₀²(1 − c²)) rough_lut_film_q           film normal component at cosine c
//   c_ref(c, α) = c + (2α − α²)(0.7 − 0.8 c)                 rough_lut_reference_cos: the mean
//                                                             microfacet cosine of the GGX lobe
//   Δ = 2 d q(n_f, c_ref(cos θ_o, α))  rough_lut_opd_nm       optical path of the Δ axis, nm
//   Δ_max = 2 d_max n_max        rough_lut_opd_max_nm        top of the Δ axis, nm
//   E_r, E_t                     rgb of the two textures     reflected / transmitted albedo
//
// Mapping (rough_lut.rs `forward` / `inverse`)
//
//   t_x = √cos θ_o                                  cos θ_o = t_x²
//   t_y = Δ / Δ_max                                 Δ = t_y Δ_max
//   t_n = √((n_f − n_min)/(n_max − n_min))          n_f = n_min + t_n² (n_max − n_min)
//   t_α = ln(α/α_min) / ln(α_max/α_min)             α = α_min (α_max/α_min)^t_α
//   every non-finite t becomes 0, the rest clamp to [0, 1] (α below α_min reads α_min).
//
// Texture layout: per quantity one texture_3d, width = count(cos θ_o), height = count(Δ),
// depth = count(α) · count(n_f) in α-major blocks: slice z = i_α · count(n_f) + i_n.
// Texel-centre convention (as the bake): on an axis of `count` texels texel i holds
// t = i / (count − 1), reached at u = (t (count − 1) + 0.5) / count. Within α block a the
// index coordinate is w = (a · count(n_f) + t_n (count(n_f) − 1) + 0.5) / depth, which stays
// between the block's first and last texel centres, so a linear sampler (clamp to edge)
// filters x, y and n_f without mixing blocks. The Δ axis of block a refers to that block's
// own roughness α_a (c_ref(cos θ_o, α_a)), so t_y is computed per block. The two blocks
// around t_α are fetched and mixed:
//
//   s = t_α (count(α) − 1),  a₀ = min(⌊s⌋, count(α) − 2),  f = s − a₀
//   E = mix(sample(block a₀), sample(block a₀ + 1), f)
//
// How a renderer uses it (split sum): specular environment = prefiltered_env(R, α) · E_r;
// light entering a dielectric base = … · E_t.

// Mirror of `RoughLutAxes` (48 bytes in a cbuffer).
struct NacreRoughLutParams {
    uint cos_theta_count;
    uint opd_count;
    uint ior_count;
    uint alpha_count;
    float thickness_max_nm;
    float ior_min;
    float ior_max;
    float alpha_min;
    float alpha_max;
    float ambient_index;
    uint has_transmittance;
    uint _pad0;
};

// The parameters from a table's axes (the manifest's `rough_film_lut` record): counts
// (cos θ_o, Δ, n_f, α), d_max, the index and roughness ranges, the ambient index.
NacreRoughLutParams nacre_make_rough_lut_params(uint4 counts, float thickness_max_nm, float2 ior_range, float2 alpha_range, float ambient_index, bool has_transmittance) {
    NacreRoughLutParams p;
    p.cos_theta_count = counts.x;
    p.opd_count = counts.y;
    p.ior_count = counts.z;
    p.alpha_count = counts.w;
    p.thickness_max_nm = thickness_max_nm;
    p.ior_min = ior_range.x;
    p.ior_max = ior_range.y;
    p.alpha_min = alpha_range.x;
    p.alpha_max = alpha_range.y;
    p.ambient_index = ambient_index;
    p.has_transmittance = has_transmittance ? 1u : 0u;
    p._pad0 = 0u;
    return p;
}

// Two texture coordinates (one per α block) and the weight of the second.
struct NacreRoughLutCoords {
    float3 uvw0;
    float3 uvw1;
    float blend;
};

bool nacre_rough_lut_is_finite(float x) {
    return (asuint(x) & 0x7f800000u) != 0x7f800000u;
}

// t clamped to [0, 1], 0 when not finite.
float nacre_rough_lut_unit(float t) {
    return nacre_rough_lut_is_finite(t) ? clamp(t, 0.0, 1.0) : 0.0;
}

// Δ_max = 2 d_max n_max, nm.
float nacre_rough_lut_opd_max_nm(NacreRoughLutParams p) {
    return 2.0 * p.thickness_max_nm * p.ior_max;
}

// q(n, c) = √max(n² − n₀²(1 − c²), 0), formed as (n − n₀)(n + n₀) + (n₀ c)² (no cancellation
// near grazing incidence).
float nacre_rough_lut_film_q(NacreRoughLutParams p, float c, float film_ior) {
    float a = p.ambient_index;
    float ac = a * min(abs(c), 1.0);
    return sqrt(max((film_ior - a) * (film_ior + a) + ac * ac, 0.0));
}

// c_ref(cos θ_o, α) = cos θ_o + (2α − α²)(0.7 − 0.8 cos θ_o), clamped to [0, 1].
float nacre_rough_lut_reference_cos(float cos_theta_o, float alpha) {
    float c = clamp(cos_theta_o, 0.0, 1.0);
    float a = clamp(alpha, 0.0, 1.0);
    return clamp(c + a * (2.0 - a) * (0.7 - 0.8 * c), 0.0, 1.0);
}

// Δ = 2 d q(n_f, c_ref(cos θ_o, α)), nm.
float nacre_rough_lut_opd_nm(NacreRoughLutParams p, float cos_theta_o, float alpha, float thickness_nm, float film_ior) {
    return 2.0 * thickness_nm * nacre_rough_lut_film_q(p, nacre_rough_lut_reference_cos(cos_theta_o, alpha), film_ior);
}

// t_α of roughness α (0 when the table holds one roughness).
float nacre_rough_lut_alpha_t(NacreRoughLutParams p, float alpha) {
    float span = log(p.alpha_max / p.alpha_min);
    if (span > 0.0) {
        return log(max(alpha, p.alpha_min) / p.alpha_min) / span;
    }
    return 0.0;
}

// Roughness α_a of block a: α_min (α_max/α_min)^(a/(count − 1)).
float nacre_rough_lut_block_alpha(NacreRoughLutParams p, uint a) {
    uint n = max(p.alpha_count, 1u);
    float t = n > 1u ? float(a) / float(n - 1u) : 0.0;
    return p.alpha_min * pow(p.alpha_max / p.alpha_min, t);
}

// Forward mapping: physical (cos θ_o, α, d nm, n_f) → (t_x, t_y, t_n, t_α), t_y referred to α.
float4 nacre_rough_lut_forward(NacreRoughLutParams p, float cos_theta_o, float alpha, float thickness_nm, float film_ior) {
    uint b = asuint(cos_theta_o);
    bool nan = (b & 0x7f800000u) == 0x7f800000u && (b & 0x007fffffu) != 0u;
    float c = nan ? 0.0 : clamp(cos_theta_o, 0.0, 1.0);
    float a = max(alpha, p.alpha_min);
    float tx = nan ? 0.0 : sqrt(c);
    float ty = nan ? 0.0 : nacre_rough_lut_opd_nm(p, c, a, thickness_nm, film_ior) / nacre_rough_lut_opd_max_nm(p);
    float span = p.ior_max - p.ior_min;
    float tn = span > 0.0 ? sqrt(max((film_ior - p.ior_min) / span, 0.0)) : 0.0;
    float ta = nacre_rough_lut_alpha_t(p, a);
    return float4(nacre_rough_lut_unit(tx), nacre_rough_lut_unit(ty), nacre_rough_lut_unit(tn), nacre_rough_lut_unit(ta));
}

// Inverse mapping: t → (cos θ_o, Δ nm, n_f, α).
float4 nacre_rough_lut_inverse(NacreRoughLutParams p, float4 t) {
    return float4(
        t.x * t.x,
        t.y * nacre_rough_lut_opd_max_nm(p),
        p.ior_min + t.z * t.z * (p.ior_max - p.ior_min),
        p.alpha_min * pow(p.alpha_max / p.alpha_min, t.w));
}

// Texture coordinate of t on an axis of `count` texels: (t (count − 1) + 0.5) / count.
float nacre_rough_lut_texel_coordinate(float t, uint count) {
    float n = float(max(count, 1u));
    return (t * (n - 1.0) + 0.5) / n;
}

// The texture coordinates of the two α blocks around α and the blend weight of the second.
NacreRoughLutCoords nacre_rough_lut_coords(NacreRoughLutParams p, float cos_theta_o, float alpha, float thickness_nm, float film_ior) {
    float4 t = nacre_rough_lut_forward(p, cos_theta_o, alpha, thickness_nm, film_ior);
    uint n_alpha = max(p.alpha_count, 1u);
    uint n_ior = max(p.ior_count, 1u);
    uint a0 = 0u;
    float blend = 0.0;
    if (n_alpha > 1u) {
        float s = t.w * float(n_alpha - 1u);
        a0 = min(uint(floor(s)), n_alpha - 2u);
        blend = s - float(a0);
    }
    uint a1 = min(a0 + 1u, n_alpha - 1u);
    float depth = float(n_alpha * n_ior);
    float u = nacre_rough_lut_texel_coordinate(t.x, p.cos_theta_count);
    float k = t.z * float(n_ior - 1u) + 0.5;
    float ty0 = nacre_rough_lut_forward(p, cos_theta_o, nacre_rough_lut_block_alpha(p, a0), thickness_nm, film_ior).y;
    float ty1 = nacre_rough_lut_forward(p, cos_theta_o, nacre_rough_lut_block_alpha(p, a1), thickness_nm, film_ior).y;
    NacreRoughLutCoords o;
    o.uvw0 = float3(u, nacre_rough_lut_texel_coordinate(ty0, p.opd_count), (float(a0 * n_ior) + k) / depth);
    o.uvw1 = float3(u, nacre_rough_lut_texel_coordinate(ty1, p.opd_count), (float(a1 * n_ior) + k) / depth);
    o.blend = blend;
    return o;
}

// `rough_lut_sample` of rough_lut_mapping.wgsl: `table` is one quantity's 3-D texture (E_r or
// E_t), sampled with linear filtering and clamp-to-edge addressing, level 0.
float3 nacre_rough_lut_sample(Texture3D<float4> table, SamplerState table_sampler, NacreRoughLutParams p, float cos_theta_o, float alpha, float thickness_nm, float film_ior) {
    NacreRoughLutCoords k = nacre_rough_lut_coords(p, cos_theta_o, alpha, thickness_nm, film_ior);
    float3 e0 = table.SampleLevel(table_sampler, k.uvw0, 0.0).rgb;
    float3 e1 = table.SampleLevel(table_sampler, k.uvw1, 0.0).rgb;
    return lerp(e0, e1, k.blend);
}

// ═══ shaders/film_stack.wgsl ═══
//
// Real-time multilayer films: ambient | up to 8 films | base, every medium with a complex
// index that may vary with wavelength, evaluated per pixel by the exact per-polarisation
// recurrence of crates/optics/src/stack.rs at a few wavelengths chosen by the rule of
// crates/optics/src/few_wavelengths/mod.rs. The GPU twin of `nacre color --method stack`
// (`nacre_optics::few_wavelengths::StackEvaluation`); the capability of Sussenbach 2013 §4.2–4.3
// (Algorithms 3 and 4) without its limits (dielectric films only, 5 uniform wavelengths).
//
// Symbols
//
//   symbol          code                          meaning
//   m = 0 … M−1     medium index                  0 ambient, 1 … F films (top first), F+1 base
//   ñ_m(λ_k)        stack_indices[k M + m]        complex index (n, κ) of medium m at node k
//   d_j             thickness[j]                  film j's thickness at the pixel, nm
//   d_j⁰, r_j       StackParams.layers[j].xy      film j's thickness and relative thickness, nm
//   c_j             StackParams.layers[j].w       film j's thickness-map channel: 0 R, 1 G, 2 B
//   s_c             FilmInput.variation(_g, _b)   spatial variation 2g_c − 1 ∈ [−1, 1] of channel c
//   k_j             StackParams.layers[j].z       2 max_λ |ñ_j|: film j's OPD per nm
//   h               StackParams.finesse           the stack's finesse factor (few_wavelengths/mod.rs)
//   λ_k, W_k        StackNode                     node wavelength, per-channel weight
//   q_m             q[m]                          ñ_m cos θ_m = √(ñ_m² − (n₀ sin θ₀)²), forward branch
//   r, t            FresnelInterface              interface m → m+1 amplitudes (common.wgsl)
//   Γ_m, τ_m        gamma, tau                    composite amplitudes below interface m
//
// Films: d_1 = FilmInput.thickness_nm (the pixel's film thickness, as for every technique),
// d_j = max(0, d_j⁰ + r_j s_{c_j}) for j ≥ 2 (Sussenbach 2013 Eq. 4.3, d = d_avg + d_rel Δ(x),
// with one map for all layers — every c_j = 0 — or one channel per layer).
//
// Rule: OPD = h Σ_j k_j d_j; N = ⌈base_count + count_per_opd_nm · OPD⌉ rounded up to the
// ladder (StackParams.rule_size, increasing); the rule's nodes are stack_nodes[offset …
// offset + N). With `fixed_rule` = 1 rule 0 is always used (`stack:N`).
//
// Recurrence at each node (stack.rs, Heavens 1955 §4): Γ_F = r_{F,F+1}, τ_F = t_{F,F+1}; for
// m = F−1 … 0, with e = e^{iδ_{m+1}}, δ = 2π d q / λ,
//
//   Γ_m = (r + Γ_{m+1} e²) / (1 + r Γ_{m+1} e²),   τ_m = t τ_{m+1} e / (1 + r Γ_{m+1} e²)
//
// R = (|Γ_0,s|² + |Γ_0,p|²)/2, T = (|τ_0,s|² f_s + |τ_0,p|² f_p)/2 (the power factors of
// common.wgsl, Byrnes' tmm conventions); C = Σ_k W_k R(λ_k) and likewise for T. Only e^{+iδ}
// with Im δ ≥ 0 appears: thick, absorbing and evanescent (beyond the critical angle) films
// never overflow. When no medium is dispersive (StackParams.dispersive = 0) the q_m and the
// interfaces do not depend on λ and are computed once per pixel, before the wavelength loop
// (the thesis's precalculation of wavelength-invariant terms).
//
// FilmInput fields used: cos_theta_i, thickness_nm, variation, variation_g, variation_b. The ambient index comes from
// the stack (its real part), so do the base and the films; film_ior, ambient_ior, base_*
// and sigma_thickness_nm are ignored. Indices are sanitised like a base index.
//
// Engine libraries: the WGSL reads its nodes and indices from two storage buffers, which
// Shader Model 4 and GLSL ES 3.00 (WebGL 2) lack; here both live in one RGBA32F 2-D texture, the stack table
// (`nacre_format::gpu_params::StackGpu::texels`, the `texture` of the JSON that `nacre
// export --layer …` writes), read with Load (no filtering): 6 texels a row, row k = node k,
//
//   texel (0, k)      (λ_k nm, W_k,r, W_k,g, W_k,b)
//   texel (1 + i, k)  (n, κ) of medium 2i, (n, κ) of medium 2i + 1 (zeros past the base)
//
// and the number of nodes, arrayLength(&stack_nodes), is the table's height. The uniform is
// NacreStackParams (the JSON's `shader_params`; a cbuffer has the WGSL uniform's bytes). The
// texture is a `Texture2D<float4>` read with Load (no sampler).

// One node (32 bytes, array stride 32, storage):
//
//   offset size field
//        0    4 wavelength_nm: f32
//        4   12 _pad0, _pad1, _pad2: f32
//       16   16 weight: float4<f32>     rgb: per-channel weight W_k; a: unused (0)
struct NacreStackNode {
    float wavelength_nm;
    float _pad0;
    float _pad1;
    float _pad2;
    float4 weight;
};

// (288 bytes, uniform; `nacre_runtime::params::StackParams` mirrors it)
//
//   offset size field
//        0    4 films: u32              F (1 … 8)
//        4    4 dispersive: u32         1 when some index varies with λ
//        8    4 rule_count: u32         rules in the ladder (≤ 16)
//       12    4 fixed_rule: u32         1: always rule 0
//       16    4 base_count: f32         N at OPD 0
//       20    4 count_per_opd_nm: f32   samples per nm of OPD
//       24    4 finesse: f32            h
//       28    4 _pad0: f32
//       32   64 rule_offset: array<float4<u32>, 4>   first node of rule i (component i % 4 of i / 4)
//       96   64 rule_size: array<float4<u32>, 4>     nodes of rule i
//      160  128 layers: array<float4<f32>, 8>        film j: (d_j⁰, r_j, k_j, c_j)
struct NacreStackParams {
    uint films;
    uint dispersive;
    uint rule_count;
    uint fixed_rule;
    float base_count;
    float count_per_opd_nm;
    float finesse;
    float _pad0;
    uint4 rule_offset[4];
    uint4 rule_size[4];
    float4 layers[8];
};

static const uint NACRE_STACK_MAX_FILMS = 8u;

// Node k of the stack table (`stack_nodes[k]`).
NacreStackNode nacre_stack_node(Texture2D<float4> table, uint k) {
    float4 texel = table.Load(int3(0, int(k), 0));
    NacreStackNode n;
    n.wavelength_nm = texel.x;
    n._pad0 = 0.0;
    n._pad1 = 0.0;
    n._pad2 = 0.0;
    n.weight = float4(texel.yzw, 0.0);
    return n;
}

// Nodes in the stack table (arrayLength(&stack_nodes)): its height.
uint nacre_stack_node_count(Texture2D<float4> table) {
    uint width;
    uint height;
    table.GetDimensions(width, height);
    return height;
}

// Rule i's (first node, node count).
uint2 nacre_stack_rule(NacreStackParams p, uint i) {
    return uint2(p.rule_offset[i / 4u][i % 4u], p.rule_size[i / 4u][i % 4u]);
}

// The rule for the pixel's OPD: the first whose count reaches ⌈base + slope · OPD⌉, else the last.
uint nacre_stack_rule_for(NacreStackParams p, float opd_nm) {
    uint rules = clamp(p.rule_count, 1u, 16u);
    if (p.fixed_rule == 1u) {
        return 0u;
    }
    float needed = ceil(p.base_count + p.count_per_opd_nm * max(opd_nm, 0.0));
    for (uint i = 0u; i < rules; i++) {
        if (float(nacre_stack_rule(p, i).y) >= needed) {
            return i;
        }
    }
    return rules - 1u;
}

// Medium m's index at node k, sanitised.
float2 nacre_stack_index(Texture2D<float4> table, uint k, uint m, uint media) {
    float4 texel = table.Load(int3(int(1u + m / 2u), int(k), 0));
    float2 n = texel.zw;
    if ((m % 2u) == 0u) {
        n = texel.xy;
    }
    return nacre_sanitize_base_index(n.x, n.y);
}

// film_colour of film_stack.wgsl: `table` is the stack table, `p` its uniform.
NacreFilmOutput nacre_film_stack_colour(Texture2D<float4> table, NacreStackParams p, NacreFilmInput raw) {
    NacreFilmInput inp = nacre_sanitize_input(raw);
    float c = max(inp.cos_theta_i, NACRE_COS_THETA_MIN);
    uint films = clamp(p.films, 1u, NACRE_STACK_MAX_FILMS);
    uint media = films + 2u;
    // Films' thicknesses at the pixel and the rule's OPD.
    float thickness[8];
    float opd = 0.0;
    float3 variation = float3(inp.variation, inp.variation_g, inp.variation_b);
    for (uint j = 0u; j < films; j++) {
        float4 layer = p.layers[j];
        float d = inp.thickness_nm;
        if (j > 0u) {
            float s = variation[int(min(uint(clamp(layer.w, 0.0, 2.0)), 2u))];
            d = clamp(layer.x + layer.y * s, 0.0, NACRE_THICKNESS_MAX_NM);
            d = nacre_f32_is_finite(d) ? d : 0.0;
        }
        thickness[j] = d;
        opd += layer.z * d;
    }
    uint2 rule = nacre_stack_rule(p, nacre_stack_rule_for(p, opd * p.finesse));
    uint first = rule.x;
    uint node_count = nacre_stack_node_count(table);
    uint count = min(rule.y, node_count - min(first, node_count));
    float2 q[10];
    float2 r_s[9];
    float2 r_p[9];
    float2 t_s[9];
    float2 t_p[9];
    float factor_s = 0.0;
    float factor_p = 0.0;
    float3 r = (float3)0.0;
    float3 t = (float3)0.0;
    for (uint i = 0u; i < count; i++) {
        uint k = first + i;
        NacreStackNode node = nacre_stack_node(table, k);
        if (!nacre_f32_is_finite(node.wavelength_nm) || !(node.wavelength_nm > 0.0)) {
            continue;
        }
        if (i == 0u || p.dispersive != 0u) {
            // Normal components and interfaces (wavelength-invariant without dispersion).
            float n0 = nacre_stack_index(table, k, 0u, media).x;
            float2 prev = nacre_c_real(n0);
            q[0] = nacre_c_real(n0 * c);
            for (uint m = 1u; m < media; m++) {
                float2 n = nacre_stack_index(table, k, m, media);
                q[m] = nacre_normal_component_cos(n, n0, c);
                NacreFresnelInterface f = nacre_fresnel_interface(prev, q[m - 1u], n, q[m]);
                r_s[m - 1u] = f.r_s;
                r_p[m - 1u] = f.r_p;
                t_s[m - 1u] = f.t_s;
                t_p[m - 1u] = f.t_p;
                prev = n;
            }
            factor_s = nacre_power_factor_s(q[0], q[media - 1u]);
            factor_p = nacre_power_factor_p(nacre_c_real(n0), q[0], prev, q[media - 1u]);
        }
        float2 gamma_s = r_s[films];
        float2 gamma_p = r_p[films];
        float2 tau_s = t_s[films];
        float2 tau_p = t_p[films];
        for (uint jj = 0u; jj < films; jj++) {
            uint m = films - 1u - jj;
            // Film m + 1 (medium m + 1): e^{iδ} (phase in cycles reduced first) and
            // e^{2iδ} = (e^{iδ})², as stack.rs forms it.
            float2 qf = q[m + 1u];
            float x = nacre_safe_div(thickness[m], node.wavelength_nm);
            float2 e1 = nacre_c_exp_i_cycles(x * qf.x) * exp(-NACRE_TWO_PI * x * qf.y);
            float2 e2 = nacre_c_mul(e1, e1);
            float2 gs = nacre_c_mul(gamma_s, e2);
            float2 gp = nacre_c_mul(gamma_p, e2);
            float2 den_s = nacre_c_inv(float2(1.0, 0.0) + nacre_c_mul(r_s[m], gs));
            float2 den_p = nacre_c_inv(float2(1.0, 0.0) + nacre_c_mul(r_p[m], gp));
            gamma_s = nacre_c_mul(r_s[m] + gs, den_s);
            gamma_p = nacre_c_mul(r_p[m] + gp, den_p);
            tau_s = nacre_c_mul(nacre_c_mul(nacre_c_mul(t_s[m], tau_s), e1), den_s);
            tau_p = nacre_c_mul(nacre_c_mul(nacre_c_mul(t_p[m], tau_p), e1), den_p);
        }
        float reflectance = 0.5 * (nacre_unit_power(nacre_c_abs2(gamma_s)) + nacre_unit_power(nacre_c_abs2(gamma_p)));
        float transmittance = 0.5 * (nacre_unit_power(nacre_c_abs2(tau_s) * factor_s) + nacre_unit_power(nacre_c_abs2(tau_p) * factor_p));
        r += reflectance * node.weight.rgb;
        t += transmittance * node.weight.rgb;
    }
    NacreFilmOutput o;
    o.reflectance = r;
    o.transmittance = t;
    return nacre_sanitize_output(o);
}

#endif
