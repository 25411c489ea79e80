// nacre · shaders/diffraction.wgsl
// import: diffraction_common
//
// Technique `diffraction`: Stam's diffraction BRDF (Stam 1999) from the Taylor terms of a
// height field (Dhillon et al. 2014), layout "terms" of a baked `diffraction` table
// (crates/bake/src/kinds/diffraction.rs says what every texel holds). The GPU twin of
// `nacre_optics::diffraction::DiffractionSurface::relative_reflectance` summed over a
// `SpectralGrid`. Needs diffraction_common.wgsl before it (`nacre_runtime::diffraction::DIFFRACTION`
// is the two together); declares bind group 1 only.
//
// Symbols (those of crates/optics/src/diffraction.rs)
//
//   symbol        code                     meaning
//   ω_i, ω_r      wi, wr                   unit vectors towards the light and the viewer, in the
//                                          grating frame: x across the lines, z the normal
//   (u, v, w)     uvw = −ω_i − ω_r         (Single 2014, Eq. 1.5); w < 0 above the surface
//   λ, k = 2π/λ   wavelength_nm, k_per_um  vacuum wavelength (nm) and wavenumber (rad/µm)
//   Tₙ[j]         diffraction_terms        DFT{(i h)ⁿ}[j] / M, DC at texel dc; layer l of the
//                                          array = (Re T₂ₗ, Im T₂ₗ, Re T₂ₗ₊₁, Im T₂ₗ₊₁)
//   κ_j = j·Δκ    dk_per_um                bin j's angular spatial frequency, Δκ = 2π/L (rad/µm)
//   σ_s           sigma_s_um               standard deviation of the Gaussian coherence window, µm
//   R             radius                   bins summed on each side of the nearest bin, per axis
//   u(λ)          diffraction_spectrum     M · CIE XYZ weight of the wavelength (RGB; ρ ≡ 1 → (1, 1, 1))
//
// Reconstruction, per wavelength λ of the grid (the table's, or a coarser one the host
// chose, each with its own CIE weights):
//
//   P_j   = Σₙ (k w)ⁿ/n! · Tₙ[j]                                   (Dhillon et al. 2014, Eq. 5)
//   P̃     = Σ_{j ∈ j₀ ± R} P_j · exp(−σ_s² |(k u, k v) − κ_j|² / 2),  j₀ = round((k u, k v)/Δκ)
//   ρ(λ)  = F²(θ_h) · G/w² · |P̃|²,  G/w² = (1 + ω_i·ω_r)² / (cos θ_i cos θ_r (cos θ_i + cos θ_r)²)
//   colour = Σ_λ ρ(λ) u(λ)
//
// Neighbourhood: the CPU sums every bin whose window weight is ≥ 10⁻¹⁰; here the host
// picks R per axis (`DiffractionParams.radius`) so that the largest dropped 1-D weight,
// exp(−(σ_s Δκ)² (R + ½)² / 2), stays below its stated tolerance (10⁻³ by default; the
// `cd-tracks` table, σ_s Δκ = π/2, gets R = 2 and drops at most 4.5 · 10⁻⁴ of a bin's
// amplitude). An axis with one bin (a 1-D grating) has R = 0: its window is the Gaussian
// falloff exp(−σ_s² (k v)² / 2) of the single row.
//
// F² is 1 (`fresnel_kind` 0, a perfect reflector) or the unpolarised Fresnel reflectance
// (|r_s|² + |r_p|²)/2 from air into a bulk material of complex index ñ = n + iκ at the
// angle θ_h between ω_i and the half vector (`fresnel_kind` 1), as `FresnelTerm::Index`.
//
// Robustness: non-finite directions, directions at or below the horizon and zero vectors
// give 0; huge components are rescaled before normalising; every loop bound comes from the
// host-checked uniform; the result is always finite.

// Largest Taylor order N the technique evaluates (the host refuses deeper tables).
const DIFFRACTION_MAX_ORDER: u32 = 63u;
const DIFFRACTION_TWO_PI: f32 = 6.28318530717959;

// Byte layout (64 bytes; `nacre_runtime::diffraction::DiffractionUniform` mirrors it):
//
//   offset size field
//        0    8 size: vec2<u32>          bins (nx, ny)
//        8    8 dc: vec2<i32>            texel of the DC bin (⌊nx/2⌋, ⌊ny/2⌋)
//       16    8 dk_per_um: vec2<f32>     Δκ = 2π / (L_x, L_y), rad/µm
//       24    8 radius: vec2<i32>        R per axis, bins
//       32    4 order: u32               N
//       36    4 sigma_s_um: f32          σ_s, µm
//       40    4 wavelength_count: u32    entries of diffraction_spectrum
//       44    4 fresnel_kind: u32        0: F² = 1; 1: Fresnel of fresnel_ior
//       48    8 fresnel_ior: vec2<f32>   (n, κ) of the bulk material (fresnel_kind 1)
//       56    8 _pad: vec2<f32>
struct DiffractionParams {
    size: vec2<u32>,
    dc: vec2<i32>,
    dk_per_um: vec2<f32>,
    radius: vec2<i32>,
    order: u32,
    sigma_s_um: f32,
    wavelength_count: u32,
    fresnel_kind: u32,
    fresnel_ior: vec2<f32>,
    _pad: vec2<f32>,
}

@group(1) @binding(0) var<uniform> diffraction: DiffractionParams;
// Rgba32Float, unfilterable: read with textureLoad only.
@group(1) @binding(1) var diffraction_terms: texture_2d_array<f32>;
// (λ nm, u_R, u_G, u_B) per wavelength of the grid.
@group(1) @binding(2) var<storage, read> diffraction_spectrum: array<vec4<f32>>;

// F² of the uniform's `fresnel_kind` and `fresnel_ior` at cos θ (diffraction_fresnel_of).
fn diffraction_fresnel(cos_theta: f32) -> f32 {
    return diffraction_fresnel_of(cos_theta, diffraction.fresnel_kind, diffraction.fresnel_ior);
}

// The Taylor sum P_j = Σₙ cₙ Tₙ[j] at texel (s, t) for coefficient pairs c = ((c₀, c₁), …).
fn diffraction_taylor_sum(texel: vec2<i32>, c: ptr<function, array<vec2<f32>, 32>>) -> vec2<f32> {
    let layers = (diffraction.order + 2u) / 2u;
    var p = vec2<f32>(0.0);
    for (var l = 0u; l < layers; l++) {
        let t = textureLoad(diffraction_terms, texel, i32(l), 0);
        let cl = (*c)[l];
        p += cl.x * t.xy + cl.y * t.zw;
    }
    return p;
}

// P̃(q) for wave number k (rad/µm) and (u, v, w), the windowed Taylor sum (header).
fn diffraction_transform(k_per_um: f32, uvw: vec3<f32>) -> vec2<f32> {
    // Taylor coefficients (k w)ⁿ / n!, in pairs (T₂ₗ, T₂ₗ₊₁) like the layers.
    var c: array<vec2<f32>, 32>;
    let kw = k_per_um * uvw.z;
    var term = 1.0;
    let order = min(diffraction.order, DIFFRACTION_MAX_ORDER);
    for (var n = 0u; n <= order; n++) {
        if n > 0u {
            term *= kw / f32(n);
        }
        if (n & 1u) == 0u {
            c[n / 2u].x = term;
        } else {
            c[n / 2u].y = term;
        }
    }
    let q = k_per_um * uvw.xy;
    let size = vec2<i32>(diffraction.size);
    let lo = -diffraction.dc;
    let hi = lo + size - vec2<i32>(1);
    let dk = diffraction.dk_per_um;
    let j_real = q / dk;
    let r = diffraction.radius;
    // Entirely outside the table (beyond its Nyquist limit): nothing to sum.
    let reach = vec2<f32>(lo - r) - 0.5;
    let reach_hi = vec2<f32>(hi + r) + 0.5;
    if any(j_real < reach) || any(j_real > reach_hi) || !diffraction_finite(j_real.x) || !diffraction_finite(j_real.y) {
        return vec2<f32>(0.0);
    }
    let j0 = vec2<i32>(round(j_real));
    let a = max(j0 - r, lo);
    let b = min(j0 + r, hi);
    let s2 = diffraction.sigma_s_um * diffraction.sigma_s_um;
    var sum = vec2<f32>(0.0);
    for (var jy = a.y; jy <= b.y; jy++) {
        let dy = q.y - f32(jy) * dk.y;
        let wy = exp(-0.5 * s2 * dy * dy);
        for (var jx = a.x; jx <= b.x; jx++) {
            let dx = q.x - f32(jx) * dk.x;
            let wx = exp(-0.5 * s2 * dx * dx);
            let p = diffraction_taylor_sum(vec2<i32>(jx, jy) + diffraction.dc, &c);
            sum += p * (wx * wy);
        }
    }
    return sum;
}

// Relative reflectance ρ(ω_i, ω_r, λ) = F² G/w² |P̃|² for unit directions in the grating frame.
fn diffraction_rho(wi: vec3<f32>, wr: vec3<f32>, wavelength_nm: f32, fresnel: f32, g: f32) -> f32 {
    let uvw = -wi - wr;
    let k = DIFFRACTION_TWO_PI / (wavelength_nm * 1e-3);
    let p = diffraction_transform(k, uvw);
    return fresnel * g * dot(p, p);
}

// The colour Σ_λ ρ(λ) u(λ) for ω_i, ω_r in the grating frame (need not be unit). Always
// finite (0 for non-finite input or directions at or below the horizon); a channel may be
// negative for a colour outside the gamut of a linear RGB output space (a narrow band of
// wavelengths is more saturated than the sRGB primaries), as on the CPU.
fn diffraction_colour(wi_in: vec3<f32>, wr_in: vec3<f32>) -> vec3<f32> {
    let wi = diffraction_unit(wi_in);
    let wr = diffraction_unit(wr_in);
    let g = diffraction_geometry_over_w2(wi, wr);
    if !(g > 0.0) || !diffraction_finite(g) {
        return vec3<f32>(0.0);
    }
    let uvw = -wi - wr;
    let cos_h = -dot(wi, uvw) * inverseSqrt(dot(uvw, uvw));
    let fresnel = diffraction_fresnel(cos_h);
    var colour = vec3<f32>(0.0);
    let count = min(diffraction.wavelength_count, arrayLength(&diffraction_spectrum));
    for (var i = 0u; i < count; i++) {
        let s = diffraction_spectrum[i];
        colour += diffraction_rho(wi, wr, s.x, fresnel, g) * s.yzw;
    }
    return select(vec3<f32>(0.0), colour, diffraction_finite3(colour));
}

// The colour of the specular (zeroth) order's efficiency, Σ_λ F²(θ) |P_DC(k w)|² u(λ) with
// w = −2 cos θ: what a mirror-like view of an extended source (the environment) keeps of
// its radiance. Reads the DC texel only.
fn diffraction_specular_order_colour(cos_theta_in: f32) -> vec3<f32> {
    let cos_theta = select(0.0, clamp(cos_theta_in, 0.0, 1.0), diffraction_finite(cos_theta_in));
    if !(cos_theta > 0.0) {
        return vec3<f32>(0.0);
    }
    let fresnel = diffraction_fresnel(cos_theta);
    var colour = vec3<f32>(0.0);
    let count = min(diffraction.wavelength_count, arrayLength(&diffraction_spectrum));
    let order = min(diffraction.order, DIFFRACTION_MAX_ORDER);
    for (var i = 0u; i < count; i++) {
        let s = diffraction_spectrum[i];
        let kw = -2.0 * cos_theta * DIFFRACTION_TWO_PI / (s.x * 1e-3);
        var c: array<vec2<f32>, 32>;
        var term = 1.0;
        for (var n = 0u; n <= order; n++) {
            if n > 0u {
                term *= kw / f32(n);
            }
            if (n & 1u) == 0u {
                c[n / 2u].x = term;
            } else {
                c[n / 2u].y = term;
            }
        }
        let p = diffraction_taylor_sum(diffraction.dc, &c);
        colour += fresnel * dot(p, p) * s.yzw;
    }
    return select(vec3<f32>(0.0), colour, diffraction_finite3(colour));
}
