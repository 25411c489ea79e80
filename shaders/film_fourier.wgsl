// nacre · shaders/film_fourier.wgsl — technique `film_fourier`
// import: common
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
const FOURIER_MAX_HARMONICS: u32 = 128u;
// Tolerance ε of the auto stopping rule at a mean level of 1 (fourier.rs AUTO_TOLERANCE).
const FOURIER_AUTO_TOLERANCE: f32 = 1e-3;
// Lowest mean level the auto tolerance is scaled to (fourier.rs AUTO_LEVEL_FLOOR).
const FOURIER_AUTO_LEVEL_FLOOR: f32 = 0.01;
// Thickness over which fixed-harmonic evaluation blends the film index, nm
// (fourier.rs THIN_FILM_BLEND_NM).
const FOURIER_THIN_FILM_BLEND_NM: f32 = 30.0;
// Smallest 1 − |ρ|² used in the Airy coefficients.
const FOURIER_MIN_ONE_MINUS_RHO2: f32 = 1e-6;
// Variance of a unit-width box footprint (fourier_sigma_from_derivatives).
const FOURIER_BOX_VARIANCE: f32 = 0.0833333333333333;

// Mirror of `FourierAxes` and the harmonic count (48 bytes, uniform):
//
//   offset size field
//        0    4 max_opd_nm: f32               D_max, nm (u = μ / D_max)
//        4    4 level_count: u32              mip levels in the texture (≥ 1)
//        8    4 sigma1_nm: f32                level_sigma_nm[1], nm (unused when level_count < 2)
//       12    4 harmonics: u32                M; 0 = auto
//       16   12 carrier_nu_per_nm: vec3<f32>  ν̄_j, 1/nm
//       28    4 _pad0: f32
//       32   12 white: vec3<f32>              ‖s_j‖
//       44    4 _pad1: f32
//
// level_count must not exceed the texture's mip count (GLSL ES cannot query it).
struct FourierParams {
    max_opd_nm: f32,
    level_count: u32,
    sigma1_nm: f32,
    harmonics: u32,
    carrier_nu_per_nm: vec3<f32>,
    _pad0: f32,
    white: vec3<f32>,
    _pad1: f32,
}

// Rgba32Float, not filterable: layer 0 Re A_j, layer 1 Im A_j (rgb = channels); width N_k,
// height 1; mip k = level k.
@group(1) @binding(0) var fourier_table: texture_2d_array<f32>;
@group(1) @binding(1) var<uniform> fourier_params: FourierParams;

// One complex number per output channel.
struct ComplexRgb {
    re: vec3<f32>,
    im: vec3<f32>,
}

fn crgb_mul(a: ComplexRgb, b: ComplexRgb) -> ComplexRgb {
    return ComplexRgb(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re);
}

// Re(a conj b) per channel.
fn crgb_re_mul_conj(a: ComplexRgb, b: ComplexRgb) -> vec3<f32> {
    return a.re * b.re + a.im * b.im;
}

// Airy Fourier coefficients of one polarisation: R or T = c₀ + 2 Σ Re(c_m e^{imΦ}),
// c_m = ρ^{m−1} K (fourier.rs `AirySeries`).
struct AirySeries {
    c0: f32,
    k: vec2<f32>,
    rho: vec2<f32>,
}

// 1 / (1 − |ρ|²), guarded.
fn airy_inverse_loss(rho: vec2<f32>) -> f32 {
    return 1.0 / max(1.0 - c_abs2(rho), FOURIER_MIN_ONE_MINUS_RHO2);
}

// Reflectance series from the film-top amplitude r₁₂ and the base amplitude Γ.
fn airy_series_reflectance(r12: vec2<f32>, gamma: vec2<f32>) -> AirySeries {
    let one = vec2<f32>(1.0, 0.0);
    let beta = c_mul(c_mul(one - r12, one + r12), gamma);
    let rho = -c_mul(r12, gamma);
    let inv = airy_inverse_loss(rho);
    let b2 = c_abs2(beta);
    return AirySeries(c_abs2(r12) + b2 * inv, c_mul(beta, c_conj(r12)) + b2 * inv * rho, rho);
}

// Transmittance series T = a/(1 − |ρ|²)·… from t₁₂, t₂₃ and the power factor.
fn airy_series_transmittance(t12: vec2<f32>, t23: vec2<f32>, factor: f32, rho: vec2<f32>) -> AirySeries {
    let a = c_abs2(c_mul(t12, t23)) * factor * airy_inverse_loss(rho);
    return AirySeries(a, a * rho, rho);
}

// The auto tolerance of a channel whose mean level is `level`: ε max(level, floor)^(2/3)
// (fourier.rs `auto_tolerance`).
fn airy_auto_tolerance(level: vec3<f32>) -> vec3<f32> {
    return FOURIER_AUTO_TOLERANCE * pow(max(level, vec3<f32>(FOURIER_AUTO_LEVEL_FLOOR)), vec3<f32>(2.0 / 3.0));
}

// Whether the terms after harmonic m are negligible for one polarisation: per channel
// 2|c_{m+1}|/(1 − |ρ|) · s_max ≤ tolerance, with c_m the m-th coefficient, s_max = max_j |Ŝ_j(m D)|
// (fourier.rs `AirySeries::tail_after`).
fn airy_tail_converged(cm: ComplexRgb, rho: ComplexRgb, s_max: f32, tolerance: vec3<f32>) -> bool {
    let r = sqrt(rho.re * rho.re + rho.im * rho.im);
    let cm_abs = sqrt(cm.re * cm.re + cm.im * cm.im);
    let tail = 2.0 * cm_abs * r / max(1.0 - r, vec3<f32>(1e-12)) * s_max;
    return all(tail <= tolerance);
}

// The fractional mip level for a prefilter width σ_μ, nm (`FourierAxes::lod`).
fn fourier_lod(sigma_mu_nm: f32) -> f32 {
    let p = fourier_params;
    let levels = max(p.level_count, 1u);
    if levels < 2u || !f32_is_finite(sigma_mu_nm) || !(sigma_mu_nm > 0.0) || !(p.sigma1_nm > 0.0) {
        return 0.0;
    }
    let s1 = p.sigma1_nm;
    var lod: f32;
    if sigma_mu_nm < s1 {
        lod = sigma_mu_nm / s1;
    } else {
        lod = 1.0 + log2(sigma_mu_nm / s1);
    }
    return min(lod, f32(levels - 1u));
}

// The envelope A_j at μ in level k: linear between texel centres, clamp to edge
// (`FourierTable::sample_level`).
fn fourier_sample_level(level: u32, mu_nm: f32) -> ComplexRgb {
    // N_k = max(N >> k, 1): the mip chain of the level-0 width (the bake's level sizes).
    // Computed rather than queried per level: Mesa's lavapipe (22.3) answers
    // textureDimensions(t, k) wrongly for a non-constant k on array textures.
    let n = max(textureDimensions(fourier_table).x >> min(level, 31u), 1u);
    let nf = f32(n);
    let d_max = fourier_params.max_opd_nm;
    let u = select(0.0, mu_nm / d_max, d_max > 0.0);
    let x = clamp(u * nf - 0.5, 0.0, nf - 1.0);
    let i0 = min(u32(floor(x)), n - 1u);
    let i1 = min(i0 + 1u, n - 1u);
    let f = x - f32(i0);
    // An i32 level: naga's GLSL backend passes a u32 level through to its bounds check's
    // textureSize(sampler2DArray, uint), which GLSL has no overload for.
    let level_i32 = i32(level);
    let re0 = textureLoad(fourier_table, vec2<u32>(i0, 0u), 0u, level_i32).rgb;
    let re1 = textureLoad(fourier_table, vec2<u32>(i1, 0u), 0u, level_i32).rgb;
    let im0 = textureLoad(fourier_table, vec2<u32>(i0, 0u), 1u, level_i32).rgb;
    let im1 = textureLoad(fourier_table, vec2<u32>(i1, 0u), 1u, level_i32).rgb;
    return ComplexRgb(mix(re0, re1, f), mix(im0, im1, f));
}

// Ŝ_j(μ) prefiltered at σ_μ (`FourierTable::sample`): the envelope blended between the two
// levels around the fractional lod, times the carrier e^{−2πiμν̄_j}.
fn fourier_sample(mu_nm: f32, sigma_mu_nm: f32) -> ComplexRgb {
    let levels = max(fourier_params.level_count, 1u);
    let lod = fourier_lod(sigma_mu_nm);
    let k0 = u32(floor(lod));
    let f = lod - f32(k0);
    var a = fourier_sample_level(k0, mu_nm);
    if f > 0.0 && k0 + 1u < levels {
        let a1 = fourier_sample_level(k0 + 1u, mu_nm);
        a = ComplexRgb(mix(a.re, a1.re, f), mix(a.im, a1.im, f));
    }
    // μ ν̄_j in cycles, reduced before the 2π.
    let phi = -TWO_PI * fract(mu_nm * fourier_params.carrier_nu_per_nm);
    return crgb_mul(a, ComplexRgb(cos(phi), sin(phi)));
}

// The prefilter width σ_d (nm) for a consumer that knows the screen-space derivatives of the
// thickness (e.g. dpdx/dpdy of a thickness map, nm per pixel) and a sub-pixel thickness
// roughness (nm, std. dev.): σ_d = √(max(∂d/∂x, ∂d/∂y)² / 12 + roughness²). A thickness that
// varies linearly across a one-pixel box footprint with slope g is uniformly distributed over
// a width |g|, whose variance is g²/12 (FOURIER_BOX_VARIANCE); the larger axis is taken so
// that anisotropic footprints are not under-filtered, and independent roughness adds in
// quadrature. Non-finite inputs count as 0; the result is at most THICKNESS_MAX_NM.
fn fourier_sigma_from_derivatives(d_thickness_dx: f32, d_thickness_dy: f32, roughness_nm: f32) -> f32 {
    let gx = finite_or(d_thickness_dx, 0.0);
    let gy = finite_or(d_thickness_dy, 0.0);
    let r = finite_or(roughness_nm, 0.0);
    let g2 = max(gx * gx, gy * gy);
    return min(sqrt(g2 * FOURIER_BOX_VARIANCE + r * r), THICKNESS_MAX_NM);
}

// Evanescent film: the exact Airy R and T at each channel's centroid wavelength 1/ν̄_j
// (550 nm if ν̄_j is not positive), times ‖s_j‖. `input` is sanitised, cos_theta ≥ COS_THETA_MIN.
fn fourier_evanescent_colour(input: FilmInput, cos_theta: f32) -> FilmOutput {
    let p = fourier_params;
    var out: FilmOutput;
    for (var j = 0u; j < 3u; j++) {
        let nu = p.carrier_nu_per_nm[j];
        let wavelength_nm = select(550.0, 1.0 / nu, f32_is_finite(nu) && nu > 1e-6);
        let n3 = vec2<f32>(input.base_ior[j], input.base_kappa[j]);
        let power = airy_film_power(input.ambient_ior, c_real(input.film_ior), n3, cos_theta, input.thickness_nm, wavelength_nm);
        out.reflectance[j] = 0.5 * (power.x + power.y);
        out.transmittance[j] = select(0.0, 0.5 * (power.z + power.w), input.base_kappa[j] == 0.0);
    }
    out.reflectance *= p.white;
    out.transmittance *= p.white;
    return sanitize_output(out);
}

fn film_colour(raw: FilmInput) -> FilmOutput {
    let input = sanitize_input(raw);
    let p = fourier_params;
    let c = max(input.cos_theta_i, COS_THETA_MIN);
    let n1 = input.ambient_ior;
    let d = input.thickness_nm;

    // η₂ blend for a fixed number of harmonics (Belcour & Barla §4).
    var n2 = input.film_ior;
    if p.harmonics != 0u {
        let s = clamp(d / FOURIER_THIN_FILM_BLEND_NM, 0.0, 1.0);
        n2 = n1 + (n2 - n1) * s * s * (3.0 - 2.0 * s);
    }
    let n1c = n1 * c;
    let q2_sq = (n2 - n1) * (n2 + n1) + n1c * n1c;
    if !(q2_sq > 0.0) {
        return fourier_evanescent_colour(input, c);
    }
    let q2 = sqrt(q2_sq);
    let opd = 2.0 * d * q2;
    let tau = 2.0 * q2;
    let sigma_d = input.sigma_thickness_nm;

    // Airy series per channel and polarisation.
    let a = c_real(n1);
    let q1 = c_real(n1c);
    let film = c_real(n2);
    let q2c = c_real(q2);
    let top = fresnel_interface(a, q1, film, q2c);
    var c0_r = vec3<f32>(0.0);
    var c0_t = vec3<f32>(0.0);
    var k_rs = ComplexRgb(vec3<f32>(0.0), vec3<f32>(0.0));
    var k_rp = k_rs;
    var k_ts = k_rs;
    var k_tp = k_rs;
    var rho_s = k_rs;
    var rho_p = k_rs;
    // A base whose index is the same in every channel (any non-dispersive base) needs its
    // Fresnel terms once, not three times.
    var rs: AirySeries;
    var rp: AirySeries;
    var ts: AirySeries;
    var tp: AirySeries;
    var previous = vec2<f32>(-1.0, -1.0);
    for (var j = 0u; j < 3u; j++) {
        let n3 = vec2<f32>(input.base_ior[j], input.base_kappa[j]);
        if any(n3 != previous) {
            previous = n3;
            let q3 = normal_component_cos(n3, n1, c);
            let bottom = fresnel_interface(film, q2c, n3, q3);
            rs = airy_series_reflectance(top.r_s, bottom.r_s);
            rp = airy_series_reflectance(top.r_p, bottom.r_p);
            let transmits = input.base_kappa[j] == 0.0;
            let factor_s = select(0.0, power_factor_s(q1, q3), transmits);
            let factor_p = select(0.0, power_factor_p(a, q1, n3, q3), transmits);
            ts = airy_series_transmittance(top.t_s, bottom.t_s, factor_s, rs.rho);
            tp = airy_series_transmittance(top.t_p, bottom.t_p, factor_p, rp.rho);
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
    let automatic = p.harmonics == 0u;
    let m_max = select(min(p.harmonics, FOURIER_MAX_HARMONICS), FOURIER_MAX_HARMONICS, automatic);
    let tolerance_r = airy_auto_tolerance(c0_r);
    let tolerance_t = airy_auto_tolerance(c0_t);

    // Eq. 10: c_m = ρ^{m−1} K, summed against Ŝ_j(m D, m τ σ_d); auto stops R and T apart.
    var cm_rs = k_rs;
    var cm_rp = k_rp;
    var cm_ts = k_ts;
    var cm_tp = k_tp;
    var sum_r = vec3<f32>(0.0);
    var sum_t = vec3<f32>(0.0);
    var done_r = false;
    var done_t = false;
    for (var m = 1u; m <= m_max; m++) {
        if m > 1u {
            cm_rs = crgb_mul(cm_rs, rho_s);
            cm_rp = crgb_mul(cm_rp, rho_p);
            cm_ts = crgb_mul(cm_ts, rho_s);
            cm_tp = crgb_mul(cm_tp, rho_p);
        }
        let mf = f32(m);
        let s_hat = fourier_sample(mf * opd, mf * tau * sigma_d);
        // 2 Re(…) averaged over the two polarisations.
        if !done_r {
            sum_r += crgb_re_mul_conj(cm_rs, s_hat) + crgb_re_mul_conj(cm_rp, s_hat);
        }
        if !done_t {
            sum_t += crgb_re_mul_conj(cm_ts, s_hat) + crgb_re_mul_conj(cm_tp, s_hat);
        }
        if automatic {
            let s_abs = sqrt(s_hat.re * s_hat.re + s_hat.im * s_hat.im);
            let s_max = max(s_abs.x, max(s_abs.y, s_abs.z));
            done_r = done_r || (airy_tail_converged(cm_rs, rho_s, s_max, tolerance_r)
                && airy_tail_converged(cm_rp, rho_p, s_max, tolerance_r));
            done_t = done_t || (airy_tail_converged(cm_ts, rho_s, s_max, tolerance_t)
                && airy_tail_converged(cm_tp, rho_p, s_max, tolerance_t));
            if done_r && done_t {
                break;
            }
        }
    }
    var out: FilmOutput;
    out.reflectance = (c0_r + sum_r) * p.white;
    out.transmittance = select((c0_t + sum_t) * p.white, vec3<f32>(0.0), input.base_kappa > vec3<f32>(0.0));
    return sanitize_output(out);
}
