// nacre · shaders/common.wgsl
// import: (none)
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

const PI: f32 = 3.14159265358979;
const TWO_PI: f32 = 6.28318530717959;

// Smallest cos θ₁ at which the physics is evaluated (the film-lut bake's
// `nacre_format::film_lut::MIN_COS_THETA`): at exactly 90° q₁ = 0 and the power factors divide
// by zero; the CPU solver rejects 90° altogether.
const COS_THETA_MIN: f32 = 1e-6;
// Largest film thickness (and thickness standard deviation) accepted, nm; larger clamps.
const THICKNESS_MAX_NM: f32 = 1e6;
// Range every refractive index (real part n and κ) is clamped into: keeps ñ² a normal f32.
const IOR_MIN: f32 = 1e-3;
const IOR_MAX: f32 = 1e3;
// Base index used when the consumer passes NaN or ±∞.
const BASE_IOR_FALLBACK: f32 = 1.5;
// Relative size below which Im q is rounding noise when choosing the forward branch
// (100 × f32 ε; fresnel.rs uses 100 × f64 ε).
const BRANCH_TOLERANCE: f32 = 1.1920929e-5;

// ─── The technique contract (shaders/README.md) ──────────────────────────────────────────
//
// Byte layout (64 bytes; a Rust #[repr(C)] bytemuck struct mirrors it, and so does WGSL's
// uniform/storage layout: vec3<f32> is 16-byte aligned, hence the explicit _pad3/_pad4):
//
//   offset size field
//        0    4 cos_theta_i: f32
//        4    4 thickness_nm: f32
//        8    4 film_ior: f32
//       12    4 sigma_thickness_nm: f32
//       16    4 ambient_ior: f32
//       20    4 variation: f32
//       24    4 variation_g: f32
//       28    4 variation_b: f32
//       32   12 base_ior: vec3<f32>
//       44    4 _pad3: f32
//       48   12 base_kappa: vec3<f32>
//       60    4 _pad4: f32
struct FilmInput {
    // Cosine of the incidence angle in the ambient (any value: clamped, see sanitize_input).
    cos_theta_i: f32,
    // Film thickness d, nm (negative or NaN → 0).
    thickness_nm: f32,
    // Real film index n₂.
    film_ior: f32,
    // Standard deviation of d inside the pixel, nm (film_fourier prefilter; others ignore it).
    sigma_thickness_nm: f32,
    // Ambient index n₁ (film_lut: baked into the table, this field is ignored).
    ambient_ior: f32,
    // Spatial variation s = 2g − 1 ∈ [−1, 1] of a stack's lower films, from the thickness
    // map's channel R (or grey), G and B (film_stack: film j ≥ 2 is d_j + r_j s_c for its
    // channel c; NaN → 0; the other techniques ignore them).
    variation: f32,
    variation_g: f32,
    variation_b: f32,
    // Base index per output channel, real part n (film_fourier; film_lut bakes the base and
    // film_spectral reads it per wavelength from its samples).
    base_ior: vec3<f32>,
    _pad3: f32,
    // Base index per output channel, imaginary part κ ≥ 0 (film_fourier).
    base_kappa: vec3<f32>,
    _pad4: f32,
}

// Colour of the film's unpolarised reflectance and of its transmittance into the base, in the
// tables' output space (a perfect reflector = white). Always finite; a channel may be negative
// for colours outside the gamut of a linear RGB output space.
struct FilmOutput {
    reflectance: vec3<f32>,
    transmittance: vec3<f32>,
}

// ─── NaN / infinity guards ───────────────────────────────────────────────────────────────

// True unless x is NaN or ±∞ (bit test: exponent all ones).
fn f32_is_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

// True when x is NaN (exponent all ones, mantissa non-zero).
fn f32_is_nan(x: f32) -> bool {
    let b = bitcast<u32>(x);
    return (b & 0x7f800000u) == 0x7f800000u && (b & 0x007fffffu) != 0u;
}

fn vec3_is_finite(v: vec3<f32>) -> vec3<bool> {
    return (bitcast<vec3<u32>>(v) & vec3<u32>(0x7f800000u)) != vec3<u32>(0x7f800000u);
}

// x when finite, else `fallback`.
fn finite_or(x: f32, fallback: f32) -> f32 {
    return select(fallback, x, f32_is_finite(x));
}

// a / b, or 0 when b is 0.
fn safe_div(a: f32, b: f32) -> f32 {
    if b == 0.0 {
        return 0.0;
    }
    return a / b;
}

// x clamped to [0, 1], 0 when not finite (a power coefficient of a passive stack).
fn unit_power(x: f32) -> f32 {
    return select(0.0, clamp(x, 0.0, 1.0), f32_is_finite(x));
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
fn sanitize_input(input: FilmInput) -> FilmInput {
    var o: FilmInput;
    o.cos_theta_i = select(clamp(input.cos_theta_i, 0.0, 1.0), 1.0, f32_is_nan(input.cos_theta_i));
    o.thickness_nm = select(0.0, min(input.thickness_nm, THICKNESS_MAX_NM), input.thickness_nm > 0.0 && !f32_is_nan(input.thickness_nm));
    o.sigma_thickness_nm = select(0.0, min(input.sigma_thickness_nm, THICKNESS_MAX_NM), input.sigma_thickness_nm > 0.0 && !f32_is_nan(input.sigma_thickness_nm));
    let ambient_ok = f32_is_finite(input.ambient_ior) && input.ambient_ior > 0.0;
    o.ambient_ior = clamp(select(1.0, input.ambient_ior, ambient_ok), IOR_MIN, IOR_MAX);
    let film_ok = f32_is_finite(input.film_ior) && input.film_ior > 0.0;
    o.film_ior = clamp(select(o.ambient_ior, input.film_ior, film_ok), IOR_MIN, IOR_MAX);
    let base_ok = vec3_is_finite(input.base_ior);
    o.base_ior = clamp(select(vec3<f32>(BASE_IOR_FALLBACK), input.base_ior, base_ok), vec3<f32>(IOR_MIN), vec3<f32>(IOR_MAX));
    let kappa_ok = vec3_is_finite(input.base_kappa) & (input.base_kappa > vec3<f32>(0.0));
    o.base_kappa = select(vec3<f32>(0.0), min(input.base_kappa, vec3<f32>(IOR_MAX)), kappa_ok);
    o.variation = select(clamp(input.variation, -1.0, 1.0), 0.0, f32_is_nan(input.variation));
    o.variation_g = select(clamp(input.variation_g, -1.0, 1.0), 0.0, f32_is_nan(input.variation_g));
    o.variation_b = select(clamp(input.variation_b, -1.0, 1.0), 0.0, f32_is_nan(input.variation_b));
    o._pad3 = 0.0;
    o._pad4 = 0.0;
    return o;
}

// The complex index (n, κ) of a base channel, sanitised as in sanitize_input.
fn sanitize_base_index(n: f32, kappa: f32) -> vec2<f32> {
    let re = clamp(select(BASE_IOR_FALLBACK, n, f32_is_finite(n)), IOR_MIN, IOR_MAX);
    let im = select(0.0, min(kappa, IOR_MAX), f32_is_finite(kappa) && kappa > 0.0);
    return vec2<f32>(re, im);
}

// Every channel that is NaN or ±∞ becomes 0. Negative channels are kept: they are the
// out-of-gamut colours of linear RGB spaces, exactly as the CPU methods return them (a
// consumer clamps after lighting and tone mapping, not before).
fn sanitize_output(output: FilmOutput) -> FilmOutput {
    var o: FilmOutput;
    let zero = vec3<f32>(0.0);
    o.reflectance = select(zero, output.reflectance, vec3_is_finite(output.reflectance));
    o.transmittance = select(zero, output.transmittance, vec3_is_finite(output.transmittance));
    return o;
}

// ─── Complex arithmetic on vec2<f32> = (re, im) ─────────────────────────────────────────────

fn c_real(x: f32) -> vec2<f32> {
    return vec2<f32>(x, 0.0);
}

fn c_mul(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

fn c_conj(a: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(a.x, -a.y);
}

// |a|².
fn c_abs2(a: vec2<f32>) -> f32 {
    return dot(a, a);
}

// |a|, scaled so that it neither overflows nor underflows.
fn c_abs(a: vec2<f32>) -> f32 {
    let s = max(abs(a.x), abs(a.y));
    if s == 0.0 {
        return 0.0;
    }
    let b = a / s;
    return s * sqrt(dot(b, b));
}

// a / b (Smith-style scaling by max(|Re b|, |Im b|)); 0 when b = 0.
fn c_div(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    let s = max(abs(b.x), abs(b.y));
    if !(s > 0.0) {
        return vec2<f32>(0.0);
    }
    let bs = b / s;
    let a_s = a / s;
    return vec2<f32>(a_s.x * bs.x + a_s.y * bs.y, a_s.y * bs.x - a_s.x * bs.y) / dot(bs, bs);
}

fn c_inv(b: vec2<f32>) -> vec2<f32> {
    return c_div(vec2<f32>(1.0, 0.0), b);
}

// Principal square root (Re ≥ 0; Im with the sign of Im z, +0 counted as positive — WGSL does
// not promise signed zeros), without cancellation in either part.
fn c_sqrt(z: vec2<f32>) -> vec2<f32> {
    let r = c_abs(z);
    if r == 0.0 {
        return vec2<f32>(0.0);
    }
    if z.x >= 0.0 {
        let t = sqrt(0.5 * (r + z.x));
        return vec2<f32>(t, 0.5 * z.y / t);
    }
    let t = sqrt(0.5 * (r - z.x));
    return vec2<f32>(0.5 * abs(z.y) / t, select(-t, t, z.y >= 0.0));
}

// r e^{iφ}.
fn c_polar(r: f32, phi: f32) -> vec2<f32> {
    return r * vec2<f32>(cos(phi), sin(phi));
}

// e^{iz} = e^{−Im z} (cos Re z, sin Re z); finite for Im z ≥ 0.
fn c_exp_i(z: vec2<f32>) -> vec2<f32> {
    return c_polar(exp(-z.y), z.x);
}

// e^{2πi x} for a phase x in cycles, reduced with fract() first so that large phases keep
// their fractional part.
fn c_exp_i_cycles(x: f32) -> vec2<f32> {
    let phi = TWO_PI * fract(x);
    return vec2<f32>(cos(phi), sin(phi));
}

// ─── Snell's law (fresnel.rs `normal_component`, `forward_branch`) ──────────────────────────

// The sign of q describing a wave travelling or decaying towards +z: Im q > 0, or Re q ≥ 0
// when Im q is rounding noise (|Im q| ≤ BRANCH_TOLERANCE · max(|Re q|, |Im q|)).
fn forward_branch(q: vec2<f32>) -> vec2<f32> {
    let scale = max(abs(q.x), abs(q.y));
    var forward: bool;
    if abs(q.y) > BRANCH_TOLERANCE * scale {
        forward = q.y > 0.0;
    } else {
        forward = q.x >= 0.0;
    }
    return select(-q, q, forward);
}

// q = √(ñ² − β²) on the forward branch, for a tangential component β = n₁ sin θ₁.
fn normal_component(n: vec2<f32>, beta: f32) -> vec2<f32> {
    return forward_branch(c_sqrt(c_mul(n, n) - vec2<f32>(beta * beta, 0.0)));
}

// The same q for β = n₁ sin θ₁ given as (n₁, cos θ₁), formed as
// (n − n₁)(n + n₁) − κ² + (n₁ cos θ₁)² + 2inκ: exact for ñ = n₁ (q = n₁ cos θ₁) and free of
// the cancellation in 1 − cos² θ₁ near grazing incidence.
fn normal_component_cos(n: vec2<f32>, n_ambient: f32, cos_theta: f32) -> vec2<f32> {
    let a = n_ambient * cos_theta;
    let q2 = vec2<f32>((n.x - n_ambient) * (n.x + n_ambient) - n.y * n.y + a * a, 2.0 * n.x * n.y);
    return forward_branch(c_sqrt(q2));
}

// ─── Fresnel amplitudes of one interface (fresnel.rs `Interface::new`) ─────────────────────

struct FresnelInterface {
    r_s: vec2<f32>,
    r_p: vec2<f32>,
    t_s: vec2<f32>,
    t_p: vec2<f32>,
}

// From medium i (index n_i, normal component q_i) into medium j.
fn fresnel_interface(n_i: vec2<f32>, q_i: vec2<f32>, n_j: vec2<f32>, q_j: vec2<f32>) -> FresnelInterface {
    var o: FresnelInterface;
    let sum_s = q_i + q_j;
    o.r_s = c_div(q_i - q_j, sum_s);
    o.t_s = c_div(2.0 * q_i, sum_s);
    let a = c_mul(c_mul(n_j, n_j), q_i);
    let b = c_mul(c_mul(n_i, n_i), q_j);
    let sum_p = a + b;
    o.r_p = c_div(a - b, sum_p);
    o.t_p = c_div(2.0 * c_mul(c_mul(n_i, n_j), q_i), sum_p);
    return o;
}

// |t_s|² → T_s between incidence medium (q_0) and exit medium (q_f): Re(q_f) / Re(q_0).
fn power_factor_s(q_0: vec2<f32>, q_f: vec2<f32>) -> f32 {
    return safe_div(q_f.x, q_0.x);
}

// |t_p|² → T_p: Re(ñ_f conj(cos θ_f)) / Re(ñ_0 conj(cos θ_0)), cos θ = q / ñ.
fn power_factor_p(n_0: vec2<f32>, q_0: vec2<f32>, n_f: vec2<f32>, q_f: vec2<f32>) -> f32 {
    let num = c_mul(n_f, c_conj(c_div(q_f, n_f))).x;
    let den = c_mul(n_0, c_conj(c_div(q_0, n_0))).x;
    return safe_div(num, den);
}

// ─── One film at one wavelength (stack.rs, one film) ───────────────────────────────────────

// (R, |t|²) of one polarisation from the top interface (r₁₂, t₁₂), the base seen from the
// film (Γ, τ), e^{iδ} and e^{2iδ}: R = |r₁₂ + Γe^{2iδ}|² / |1 + r₁₂Γe^{2iδ}|²,
// |t|² = |t₁₂ τ e^{iδ}|² / |1 + r₁₂Γe^{2iδ}|².
fn airy_polarisation(r12: vec2<f32>, t12: vec2<f32>, gamma: vec2<f32>, tau: vec2<f32>, e1: vec2<f32>, e2: vec2<f32>) -> vec2<f32> {
    let ge2 = c_mul(gamma, e2);
    let num = r12 + ge2;
    let den = c_abs2(vec2<f32>(1.0, 0.0) + c_mul(r12, ge2));
    let t = c_mul(c_mul(t12, tau), e1);
    return vec2<f32>(safe_div(c_abs2(num), den), safe_div(c_abs2(t), den));
}

// Exact powers (R_s, R_p, T_s, T_p) of ambient n₁ | film ñ₂, d nm | base ñ₃ at vacuum
// wavelength λ nm and cos θ₁ (callers pass cos θ₁ ≥ COS_THETA_MIN). Each power is clamped
// to [0, 1] (non-finite → 0): the stack is passive.
fn airy_film_power(n1: f32, n2: vec2<f32>, n3: vec2<f32>, cos_theta: f32, thickness_nm: f32, wavelength_nm: f32) -> vec4<f32> {
    let a = c_real(n1);
    let q1 = c_real(n1 * cos_theta);
    let q2 = normal_component_cos(n2, n1, cos_theta);
    let q3 = normal_component_cos(n3, n1, cos_theta);
    let top = fresnel_interface(a, q1, n2, q2);
    let bottom = fresnel_interface(n2, q2, n3, q3);
    // δ = 2π (d/λ) q₂: e^{iδ} and e^{2iδ}, phases in cycles reduced before the 2π.
    let x = safe_div(thickness_nm, wavelength_nm);
    let e1 = c_exp_i_cycles(x * q2.x) * exp(-TWO_PI * x * q2.y);
    let e2 = c_exp_i_cycles(2.0 * x * q2.x) * exp(-2.0 * TWO_PI * x * q2.y);
    let s = airy_polarisation(top.r_s, top.t_s, bottom.r_s, bottom.t_s, e1, e2);
    let p = airy_polarisation(top.r_p, top.t_p, bottom.r_p, bottom.t_p, e1, e2);
    let factor_s = power_factor_s(q1, q3);
    let factor_p = power_factor_p(a, q1, n3, q3);
    return vec4<f32>(unit_power(s.x), unit_power(p.x), unit_power(s.y * factor_s), unit_power(p.y * factor_p));
}
