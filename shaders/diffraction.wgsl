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
//       56    8 filter_radius: vec2<i32> largest R per axis the footprint filter may grow to
//                                        (−1, −1: the filter is off)
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
    filter_radius: vec2<i32>,
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

// The Taylor coefficients (k w)ⁿ / n! of e^{i k w h} up to the table's order, in pairs
// (T₂ₗ, T₂ₗ₊₁) like the layers (header); `kw` = k w.
fn diffraction_taylor(kw: f32) -> array<vec2<f32>, 32> {
    var c: array<vec2<f32>, 32>;
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
    return c;
}

// P̃(q) for wave number k (rad/µm) and (u, v, w), the windowed Taylor sum (header).
fn diffraction_transform(k_per_um: f32, uvw: vec3<f32>) -> vec2<f32> {
    var c = diffraction_taylor(k_per_um * uvw.z);
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

// ─── Footprint filter (issue 37, item 3: no aliasing) ─────────────────────────────────────
//
// A pixel sees a spread of (u, v), not one point: the view direction and the grating frame
// (the CD's tracks curve) change across it. |P̃|² varies on the scale 1/σ_s in q = k (u, v)
// (the coherence lobe), finer than a pixel's footprint for a grating far away, so a point
// sample per pixel is noise. The filtered intensity is the mean of |P̃(q)|² over a Gaussian
// footprint q ~ N(q̄, diag(s_x², s_y²)), s = k σ_uv with σ_uv the footprint's standard deviation
// in (u, v) per axis of the grating frame (the scenes take it from ray differentials: the
// neighbouring pixels' rays, a box pixel's variance 1/12 of the difference²). Exactly, with
// g(q − κ) = exp(−σ_s² |q − κ|²/2) the window and A = 1 + 2 σ_s² s² per axis:
//
//   E|P̃|² = Σ_{j, j′} Re(P_j P_{j′}*) W(j, j′),   W = Π_axes E[g(q − κ_j) g(q − κ_{j′})]
//   E[g(q − a) g(q − b)] = A^{−½} exp(−σ_s² (a − b)²/4 − σ_s² (q̄ − (a + b)/2)²/A)      (1-D)
//
// (the product of two Gaussians g(q − a) g(q − b) = exp(−σ_s² (a − b)²/4) ·
// exp(−σ_s² (q − m)²), m = (a + b)/2, is a Gaussian at their midpoint; its mean over
// q ~ N(q̄, s²) is the convolution of two Gaussians, variances 1/(2σ_s²) and s² adding:
// (1 + 2σ_s² s²)^{−½} exp(−σ_s² (q̄ − m)²/(1 + 2σ_s² s²))). The footprint averages
// intensities, not amplitudes: P̃'s own mean over the footprint would cancel its speckle
// into darkness, which is why no mip chain of the terms can stand in for it. At s = 0,
// W = g g and the sum is |Σ_j P_j g_j|², the unfiltered P̃. The shader evaluates it as the
// unfiltered coherent sum plus the correction (W − g g) of the pairs at most two bins apart
// per axis (the diagonal and the 24 neighbours, each pair once): exact at s = 0 and for an
// isolated order; the pairs ≥ 3 bins apart keep their unfiltered weight g g ≤
// exp(−9 (σ_s Δκ)²/4) = 0.004 of a bin's amplitude² for the default tables (σ_s Δκ = π/2).
// The neighbourhood grows with the footprint, R_f = ⌈(R + ½) √A − ½⌉ per axis, capped by
// the uniform's filter_radius (the host keeps it within llvmpipe's loop budget); a footprint
// wider than the cap would lose the bins past it, so the result is then scaled by
// Σ_all W(j, j) / Σ_window W(j, j) per axis (the Gaussian's sum over every bin,
// A^{−½} √(π A)/(σ_s Δκ), over the part the window holds) — the energy is kept, not the
// detail. Only the Taylor sums load texels: the neighbourhood's cost is (2R_f + 1)² Taylor
// sums per wavelength; the pairs are arithmetic on amplitudes kept in three rows, written
// out without loops (llvmpipe counts loop iterations against its cap).
//
// The footprint itself comes from ray differentials (Igehy, "Tracing ray differentials",
// SIGGRAPH 1999), taken as finite differences: the scenes trace the neighbouring pixels'
// rays (`scene_footprint`, shaders/diffraction_scene.wgsl).

// Largest filter radius the shader holds (its row buffers; `MAX_FILTER_RADIUS` on the host).
const DIFFRACTION_MAX_FILTER_RADIUS: i32 = 8;

// Per-axis weights of the footprint filter, stored at window offset i + 2 (j = first + i;
// two zero entries on each side, so that a pair reaching past the window reads 0): the
// window g, and the pair means E[g_j g_{j+d}] for d = 0, 1, 2 (the header's 1-D mean).
struct DiffractionAxisWeights {
    g: array<f32, 21>,
    w0: array<f32, 21>,
    w1: array<f32, 21>,
    w2: array<f32, 21>,
    // Σ_all / Σ_window of the diagonal weights when the cap cut the window, else 1.
    renorm: f32,
}

// The 1-D pair mean E[g(q − κ_a) g(q − κ_b)] of the header, a = (first + i) Δκ,
// b = a + d Δκ; σ_s² = s2, A = a_fp.
fn diffraction_pair_mean(q: f32, dk: f32, j: i32, d: i32, a_fp: f32, s2: f32) -> f32 {
    let m = q - (f32(j) + 0.5 * f32(d)) * dk;
    let gap = f32(d) * dk;
    return inverseSqrt(a_fp) * exp(-0.25 * s2 * gap * gap - s2 * m * m / a_fp);
}

fn diffraction_axis_weights(q: f32, dk: f32, first: i32, count: i32, a: f32, s2: f32, cut: bool) -> DiffractionAxisWeights {
    var w: DiffractionAxisWeights;
    var held = 0.0;
    for (var i = 0; i < count; i++) {
        let j = first + i;
        let d = q - f32(j) * dk;
        w.g[i + 2] = exp(-0.5 * s2 * d * d);
        w.w0[i + 2] = diffraction_pair_mean(q, dk, j, 0, a, s2);
        held += w.w0[i + 2];
        w.w1[i + 2] = select(0.0, diffraction_pair_mean(q, dk, j, 1, a, s2), i + 1 < count);
        w.w2[i + 2] = select(0.0, diffraction_pair_mean(q, dk, j, 2, a, s2), i + 2 < count);
    }
    w.renorm = 1.0;
    if cut && held > 0.0 {
        let all = inverseSqrt(a) * sqrt(3.14159265358979 * a / s2) / dk;
        w.renorm = max(1.0, all / held);
    }
    return w;
}

// The pair weight E[g_a g_b] per axis for window offsets i and i + d, |d| ≤ 2 (stored
// offsets: i + 2).
fn diffraction_axis_pair(w: ptr<function, DiffractionAxisWeights>, i: i32, d: i32) -> f32 {
    let lo = min(i, i + d) + 2;
    switch abs(d) {
        case 0: {
            return (*w).w0[lo];
        }
        case 1: {
            return (*w).w1[lo];
        }
        default: {
            return (*w).w2[lo];
        }
    }
}

// The correction 2 Re(P_a P_b*) (W_x W_y − g_a g_b) of one pair to the coherent sum: bin
// a at (ix, iy) with amplitude p, bin b at (ix + dx, iy − dy) with amplitude p_b.
fn diffraction_pair_correction(
    p: vec2<f32>,
    p_b: vec2<f32>,
    wx: ptr<function, DiffractionAxisWeights>,
    wy: ptr<function, DiffractionAxisWeights>,
    ix: i32,
    iy: i32,
    dx: i32,
    dy: i32,
) -> f32 {
    let w = diffraction_axis_pair(wx, ix, dx) * diffraction_axis_pair(wy, iy, -dy);
    let gg = (*wx).g[ix + 2] * (*wx).g[ix + dx + 2] * (*wy).g[iy + 2] * (*wy).g[iy - dy + 2];
    return 2.0 * dot(p, p_b) * (w - gg);
}

// The corrections of bin (ix, iy), amplitude p, with the bins of `row` (dy rows back, window
// offsets stored at + 2) from dx = −2 to 2: straight-line code, no loop (llvmpipe counts
// loop iterations against its cap).
fn diffraction_row_corrections(
    p: vec2<f32>,
    row: ptr<function, array<vec2<f32>, 21>>,
    wx: ptr<function, DiffractionAxisWeights>,
    wy: ptr<function, DiffractionAxisWeights>,
    ix: i32,
    iy: i32,
    dy: i32,
) -> f32 {
    return diffraction_pair_correction(p, (*row)[ix], wx, wy, ix, iy, -2, dy)
        + diffraction_pair_correction(p, (*row)[ix + 1], wx, wy, ix, iy, -1, dy)
        + diffraction_pair_correction(p, (*row)[ix + 2], wx, wy, ix, iy, 0, dy)
        + diffraction_pair_correction(p, (*row)[ix + 3], wx, wy, ix, iy, 1, dy)
        + diffraction_pair_correction(p, (*row)[ix + 4], wx, wy, ix, iy, 2, dy);
}

// E|P̃|² over the footprint (above) for wave number k (rad/µm), (u, v, w) at the pixel's
// centre and σ_uv ≥ 0 the footprint's standard deviation in (u, v) per axis.
fn diffraction_filtered_intensity(k_per_um: f32, uvw: vec3<f32>, sigma_uv: vec2<f32>) -> f32 {
    var c = diffraction_taylor(k_per_um * uvw.z);
    let q = k_per_um * uvw.xy;
    let s = k_per_um * max(sigma_uv, vec2<f32>(0.0));
    let s2 = diffraction.sigma_s_um * diffraction.sigma_s_um;
    let a = vec2<f32>(1.0) + 2.0 * s2 * s * s;
    let size = vec2<i32>(diffraction.size);
    let lo = -diffraction.dc;
    let hi = lo + size - vec2<i32>(1);
    let dk = diffraction.dk_per_um;
    let j_real = q / dk;
    let r = diffraction.radius;
    let cap = clamp(diffraction.filter_radius, r, vec2<i32>(DIFFRACTION_MAX_FILTER_RADIUS));
    let need = ceil((vec2<f32>(r) + 0.5) * sqrt(a) - 0.5);
    let rf = vec2<i32>(clamp(need, vec2<f32>(r), vec2<f32>(cap)));
    let reach = vec2<f32>(lo - rf) - 0.5;
    let reach_hi = vec2<f32>(hi + rf) + 0.5;
    if any(j_real < reach) || any(j_real > reach_hi) || !diffraction_finite(j_real.x) || !diffraction_finite(j_real.y) || !diffraction_finite(a.x) || !diffraction_finite(a.y) {
        return 0.0;
    }
    let j0 = vec2<i32>(round(j_real));
    let first = j0 - rf;
    let count = 2 * rf + vec2<i32>(1);
    // The cap cut the window (and the table has bins past it on that axis).
    let cut = (need > vec2<f32>(rf)) & (size > count);
    var wx = diffraction_axis_weights(q.x, dk.x, first.x, count.x, a.x, s2, cut.x);
    var wy = diffraction_axis_weights(q.y, dk.y, first.y, count.y, a.y, s2, cut.y);
    // Rows of amplitudes at window offset + 2 (zero past the window): this row, one and two
    // rows back.
    var cur: array<vec2<f32>, 21>;
    var back1: array<vec2<f32>, 21>;
    var back2: array<vec2<f32>, 21>;
    var coherent_sum = vec2<f32>(0.0);
    var correction = 0.0;
    for (var iy = 0; iy < count.y; iy++) {
        let jy = first.y + iy;
        let gy = wy.g[iy + 2];
        for (var ix = 0; ix < count.x; ix++) {
            let jx = first.x + ix;
            var p = vec2<f32>(0.0);
            if jx >= lo.x && jx <= hi.x && jy >= lo.y && jy <= hi.y {
                p = diffraction_taylor_sum(vec2<i32>(jx, jy) + diffraction.dc, &c);
            }
            cur[ix + 2] = p;
            let gx = wx.g[ix + 2];
            coherent_sum += p * (gx * gy);
            // The bin with itself (counted once) and with the two before it in its row.
            correction += dot(p, p) * (wx.w0[ix + 2] * wy.w0[iy + 2] - gx * gx * gy * gy);
            correction += diffraction_pair_correction(p, cur[ix + 1], &wx, &wy, ix, iy, -1, 0);
            correction += diffraction_pair_correction(p, cur[ix], &wx, &wy, ix, iy, -2, 0);
            correction += diffraction_row_corrections(p, &back1, &wx, &wy, ix, iy, 1);
            correction += diffraction_row_corrections(p, &back2, &wx, &wy, ix, iy, 2);
        }
        back2 = back1;
        back1 = cur;
    }
    let e = (dot(coherent_sum, coherent_sum) + correction) * wx.renorm * wy.renorm;
    return select(0.0, max(e, 0.0), diffraction_finite(e));
}

// The colour Σ_λ (λ_ref/λ)² F² G/w² E|P̃|² u(λ) of a light seen through the grating,
// filtered over a pixel's footprint of standard deviation σ_uv in (u, v) per axis of the
// grating frame (the filter above), each wavelength weighted by (k/k_ref)² = (λ_ref/λ)²:
// Stam's BRDF is f = ρ (σ_s k)²/π (a flat mirror's lobe |P̃|² integrates to π/(σ_s k)² over
// (u, v)), and the caller's gain (σ_s k_ref)²/π takes k at λ_ref = `reference_nm` (the
// scenes: `nacre_runtime::diffraction::lobe_gain`, 555 nm), so the weight puts back k² at
// every wavelength. σ_uv = 0 is Σ_λ (λ_ref/λ)² ρ(λ) u(λ) (up to rounding). A table whose own
// radius R exceeds the shader's row buffers (DIFFRACTION_MAX_FILTER_RADIUS), and every
// table when the host turned the filter off (filter_radius −1), is evaluated unfiltered
// (the same weights). Always finite.
fn diffraction_colour_footprint(wi_in: vec3<f32>, wr_in: vec3<f32>, sigma_uv: vec2<f32>, reference_nm: f32) -> vec3<f32> {
    let wi = diffraction_unit(wi_in);
    let wr = diffraction_unit(wr_in);
    let g = diffraction_geometry_over_w2(wi, wr);
    if !(g > 0.0) || !diffraction_finite(g) || !diffraction_finite(sigma_uv.x) || !diffraction_finite(sigma_uv.y) || !diffraction_finite(reference_nm) {
        return vec3<f32>(0.0);
    }
    let filtered = !(any(diffraction.radius > vec2<i32>(DIFFRACTION_MAX_FILTER_RADIUS)) || diffraction.filter_radius.x < 0);
    let uvw = -wi - wr;
    let cos_h = -dot(wi, uvw) * inverseSqrt(dot(uvw, uvw));
    let fresnel = diffraction_fresnel(cos_h);
    var colour = vec3<f32>(0.0);
    let count = min(diffraction.wavelength_count, arrayLength(&diffraction_spectrum));
    for (var i = 0u; i < count; i++) {
        let sp = diffraction_spectrum[i];
        let k = DIFFRACTION_TWO_PI / (sp.x * 1e-3);
        let ratio = reference_nm / sp.x;
        var rho: f32;
        if filtered {
            rho = fresnel * g * diffraction_filtered_intensity(k, uvw, sigma_uv);
        } else {
            rho = diffraction_rho(wi, wr, sp.x, fresnel, g);
        }
        colour += (rho * ratio * ratio) * sp.yzw;
    }
    return select(vec3<f32>(0.0), colour, diffraction_finite3(colour));
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
    for (var i = 0u; i < count; i++) {
        let s = diffraction_spectrum[i];
        let kw = -2.0 * cos_theta * DIFFRACTION_TWO_PI / (s.x * 1e-3);
        var c = diffraction_taylor(kw);
        let p = diffraction_taylor_sum(diffraction.dc, &c);
        colour += fresnel * dot(p, p) * s.yzw;
    }
    return select(vec3<f32>(0.0), colour, diffraction_finite3(colour));
}
