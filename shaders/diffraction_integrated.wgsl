// nacre · shaders/diffraction_integrated.wgsl
//
// Technique `diffraction`, layout "integrated" (the fast path of issue 7): Stam's
// diffraction BRDF (Stam 1999) with the Taylor expansion of Dhillon et al. 2014, summed over
// wavelengths at bake time into colour tables Iₚ(u, v), p = 0 … 2N. The GPU twin of
// `nacre_optics::diffraction::integrated::IntegratedTable::colour` (derivation, axes and
// point symmetry in crates/optics/src/diffraction/integrated.rs; what every texel holds in
// crates/bake/src/diffraction_integrated.rs). Self-contained; declares bind group 1 only,
// and every name it defines starts with `diffraction_integrated` (it can sit beside
// diffraction.wgsl in one source, though not in one pipeline: both use group 1).
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
//   F²(θ_h)       diffraction_integrated_fresnel  1, or unpolarised Fresnel of ñ = n + iκ
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
// Cost per call: 4 (2N + 1) texel loads (92 for the CD table, N = 11) and 3 (2N + 1)
// multiply-adds of the Horner sum; no loop over wavelengths.
//
// Robustness: non-finite or zero directions and directions at or below the horizon give 0;
// huge components are rescaled before normalising; the layer loop is bounded by the texture's
// own layer count; the result is always finite.

// Byte layout (32 bytes; `nacre_runtime::diffraction_integrated::DiffractionIntegratedUniform`
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
struct DiffractionIntegratedParams {
    size: vec2<u32>,
    layers: u32,
    fresnel_kind: u32,
    max_uv: f32,
    inv_gamma: f32,
    fresnel_ior: vec2<f32>,
}

@group(1) @binding(0) var<uniform> diffraction_integrated: DiffractionIntegratedParams;
// Rgba32Float 2-D array, (n/2) × n × (2N + 1), unfilterable: read with textureLoad only.
@group(1) @binding(1) var diffraction_integrated_table: texture_2d_array<f32>;

// True when x is neither NaN nor ±∞ (tested on the bits: fast-math may fold x != x).
fn diffraction_integrated_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

fn diffraction_integrated_finite3(v: vec3<f32>) -> bool {
    return diffraction_integrated_finite(v.x) && diffraction_integrated_finite(v.y) && diffraction_integrated_finite(v.z);
}

// A unit vector along v, or 0 when v is non-finite or zero (huge components are scaled down
// first so that |v|² does not overflow).
fn diffraction_integrated_unit(v: vec3<f32>) -> vec3<f32> {
    if !diffraction_integrated_finite3(v) {
        return vec3<f32>(0.0);
    }
    let m = max(abs(v.x), max(abs(v.y), abs(v.z)));
    if !(m > 0.0) {
        return vec3<f32>(0.0);
    }
    let s = v / m;
    return s * inverseSqrt(dot(s, s));
}

// The grating frame of a surface point: n the normal, t a direction across the grating
// lines (need not be unit or orthogonal to n). Rows: x across the lines, y along them,
// z = n; `frame * d` takes a world direction into the frame. Degenerate input gives an
// arbitrary frame. (The same convention as `diffraction_frame` of diffraction.wgsl.)
fn diffraction_integrated_frame(n_in: vec3<f32>, t_in: vec3<f32>) -> mat3x3<f32> {
    var n = diffraction_integrated_unit(n_in);
    if dot(n, n) == 0.0 {
        n = vec3<f32>(0.0, 0.0, 1.0);
    }
    var x = diffraction_integrated_unit(t_in - n * dot(t_in, n));
    if dot(x, x) == 0.0 {
        let a = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.x) > 0.9);
        x = normalize(a - n * dot(a, n));
    }
    let y = cross(n, x);
    return transpose(mat3x3<f32>(x, y, n));
}

fn diffraction_integrated_cdiv(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    let d = dot(b, b);
    if !(d > 0.0) {
        return vec2<f32>(1.0, 0.0);
    }
    return vec2<f32>(a.x * b.x + a.y * b.y, a.y * b.x - a.x * b.y) / d;
}

// F² at cos θ: 1 for `kind` 0; for `kind` 1 the unpolarised Fresnel reflectance
// (|r_s|² + |r_p|²)/2 from air into ñ = `ior` = (n, κ) (`FresnelTerm::Index`). Always in [0, 1].
fn diffraction_integrated_fresnel(cos_theta: f32, kind: u32, ior: vec2<f32>) -> f32 {
    if kind == 0u {
        return 1.0;
    }
    let c = select(0.0, clamp(cos_theta, 0.0, 1.0), diffraction_integrated_finite(cos_theta));
    // ñ² and q₂ = √(ñ² − sin²θ) (principal branch: Im q₂ ≥ 0 for κ ≥ 0).
    let n2 = vec2<f32>(ior.x * ior.x - ior.y * ior.y, 2.0 * ior.x * ior.y);
    let a = vec2<f32>(n2.x - (1.0 - c * c), n2.y);
    let r = sqrt(length(a));
    let half_angle = 0.5 * atan2(a.y, a.x);
    let q2 = r * vec2<f32>(cos(half_angle), sin(half_angle));
    let q1 = vec2<f32>(c, 0.0);
    let rs = diffraction_integrated_cdiv(q1 - q2, q1 + q2);
    let n2q1 = n2 * c;
    let rp = diffraction_integrated_cdiv(n2q1 - q2, n2q1 + q2);
    let f = 0.5 * (dot(rs, rs) + dot(rp, rp));
    return select(0.0, clamp(f, 0.0, 1.0), diffraction_integrated_finite(f));
}

// The warped coordinate t = (a/u_max)^{1/γ} ∈ [0, 1] of a ≥ 0 (a above u_max clamps to 1;
// a floor of 10⁻³⁰ keeps pow's argument positive: pow(0, y) is undefined in WGSL).
fn diffraction_integrated_warp(a: f32) -> f32 {
    let x = clamp(a / diffraction_integrated.max_uv, 1e-30, 1.0);
    return pow(x, diffraction_integrated.inv_gamma);
}

// S = Σₚ wᵖ Iₚ(u, v) (header): the fold, the warped coordinates, bilinear from four loads
// per layer, Horner from p = 2N down. 0 for non-finite input or an empty table.
fn diffraction_integrated_sum(uvw_in: vec3<f32>) -> vec3<f32> {
    if !diffraction_integrated_finite3(uvw_in) {
        return vec3<f32>(0.0);
    }
    let uvw = select(uvw_in, -uvw_in, uvw_in.x < 0.0);
    let dims = textureDimensions(diffraction_integrated_table);
    let cols = i32(min(diffraction_integrated.size.x, dims.x));
    let rows = i32(min(diffraction_integrated.size.y, dims.y));
    let layers = min(diffraction_integrated.layers, textureNumLayers(diffraction_integrated_table));
    if cols < 2 || rows < 2 || layers == 0u {
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
    var s = vec3<f32>(0.0);
    for (var k = 0u; k < layers; k++) {
        let p = i32(layers - 1u - k);
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

// The colour (the table's output space) of Stam's BRDF for ω_i, ω_r in the grating frame
// (need not be unit; any values) with F² of `fresnel_kind`, `fresnel_ior`
// (diffraction_integrated_fresnel). Always finite; 0 at or below the horizon. A channel may
// be negative for a colour outside the gamut of a linear RGB output space, as on the CPU.
fn diffraction_integrated_colour(wi_in: vec3<f32>, wr_in: vec3<f32>, fresnel_kind: u32, fresnel_ior: vec2<f32>) -> vec3<f32> {
    let wi = diffraction_integrated_unit(wi_in);
    let wr = diffraction_integrated_unit(wr_in);
    let ci = wi.z;
    let cr = wr.z;
    if !(ci > 0.0 && cr > 0.0) {
        return vec3<f32>(0.0);
    }
    let d = 1.0 + dot(wi, wr);
    let cs = ci + cr;
    let g = d * d / (ci * cr * cs * cs);
    let uvw = -wi - wr;
    // |uvw| ≥ −w = cos θ_i + cos θ_r > 0.
    let cos_h = -dot(wi, uvw) * inverseSqrt(dot(uvw, uvw));
    let f = diffraction_integrated_fresnel(cos_h, fresnel_kind, fresnel_ior);
    let colour = (f * g) * diffraction_integrated_sum(uvw);
    return select(vec3<f32>(0.0), colour, diffraction_integrated_finite3(colour));
}

// The colour at the centre of the mirror lobe for a view at cos θ from the normal:
// F²(θ) · Σₚ (−2 cos θ)ᵖ Iₚ(0, 0) (G/w² = 1 there): the colour of |P̃(0, 0)|², the zeroth
// order's efficiency as the coherence window sees it. It equals the terms layout's
// `diffraction_specular_order_colour` (F² |P_DC|²) when no other DFT bin lies within the
// window of DC (a 1-D grating whose period divides the patch); otherwise it also holds the
// window-weighted neighbouring bins (for the CD table 1.4 · 10⁻⁴ of the white, measured by
// crates/runtime/tests/diffraction_integrated.rs). Always finite; 0 for cos θ ≤ 0.
fn diffraction_integrated_specular_colour(cos_theta_in: f32, fresnel_kind: u32, fresnel_ior: vec2<f32>) -> vec3<f32> {
    let cos_theta = select(0.0, min(cos_theta_in, 1.0), diffraction_integrated_finite(cos_theta_in));
    if !(cos_theta > 0.0) {
        return vec3<f32>(0.0);
    }
    let f = diffraction_integrated_fresnel(cos_theta, fresnel_kind, fresnel_ior);
    let colour = f * diffraction_integrated_sum(vec3<f32>(0.0, 0.0, -2.0 * cos_theta));
    return select(vec3<f32>(0.0), colour, diffraction_integrated_finite3(colour));
}
