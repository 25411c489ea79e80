// nacre · shaders/rough_lut_mapping.wgsl
// import: (none)
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

// Mirror of `RoughLutAxes` (48 bytes, uniform):
//
//   offset size field
//        0    4 cos_theta_count: u32    texels along cos θ_o (width)
//        4    4 opd_count: u32          texels along Δ (height)
//        8    4 ior_count: u32          texels along n_f per α block
//       12    4 alpha_count: u32        α blocks (depth = alpha_count · ior_count)
//       16    4 thickness_max_nm: f32   d_max
//       20    4 ior_min: f32
//       24    4 ior_max: f32
//       28    4 alpha_min: f32
//       32    4 alpha_max: f32
//       36    4 ambient_index: f32      n₀
//       40    4 has_transmittance: u32  1 when a transmittance texture is bound, else 0
//       44    4 _pad0: u32
struct RoughLutParams {
    cos_theta_count: u32,
    opd_count: u32,
    ior_count: u32,
    alpha_count: u32,
    thickness_max_nm: f32,
    ior_min: f32,
    ior_max: f32,
    alpha_min: f32,
    alpha_max: f32,
    ambient_index: f32,
    has_transmittance: u32,
    _pad0: u32,
}

// Two texture coordinates (one per α block) and the weight of the second.
struct RoughLutCoords {
    uvw0: vec3<f32>,
    uvw1: vec3<f32>,
    blend: f32,
}

fn rough_lut_is_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

// t clamped to [0, 1], 0 when not finite.
fn rough_lut_unit(t: f32) -> f32 {
    return select(0.0, clamp(t, 0.0, 1.0), rough_lut_is_finite(t));
}

// Δ_max = 2 d_max n_max, nm.
fn rough_lut_opd_max_nm(p: RoughLutParams) -> f32 {
    return 2.0 * p.thickness_max_nm * p.ior_max;
}

// q(n, c) = √max(n² − n₀²(1 − c²), 0), formed as (n − n₀)(n + n₀) + (n₀ c)² (no cancellation
// near grazing incidence).
fn rough_lut_film_q(p: RoughLutParams, c: f32, film_ior: f32) -> f32 {
    let a = p.ambient_index;
    let ac = a * min(abs(c), 1.0);
    return sqrt(max((film_ior - a) * (film_ior + a) + ac * ac, 0.0));
}

// c_ref(cos θ_o, α) = cos θ_o + (2α − α²)(0.7 − 0.8 cos θ_o), clamped to [0, 1].
fn rough_lut_reference_cos(cos_theta_o: f32, alpha: f32) -> f32 {
    let c = clamp(cos_theta_o, 0.0, 1.0);
    let a = clamp(alpha, 0.0, 1.0);
    return clamp(c + a * (2.0 - a) * (0.7 - 0.8 * c), 0.0, 1.0);
}

// Δ = 2 d q(n_f, c_ref(cos θ_o, α)), nm.
fn rough_lut_opd_nm(p: RoughLutParams, cos_theta_o: f32, alpha: f32, thickness_nm: f32, film_ior: f32) -> f32 {
    return 2.0 * thickness_nm * rough_lut_film_q(p, rough_lut_reference_cos(cos_theta_o, alpha), film_ior);
}

// t_α of roughness α (0 when the table holds one roughness).
fn rough_lut_alpha_t(p: RoughLutParams, alpha: f32) -> f32 {
    let span = log(p.alpha_max / p.alpha_min);
    if span > 0.0 {
        return log(max(alpha, p.alpha_min) / p.alpha_min) / span;
    }
    return 0.0;
}

// Roughness α_a of block a: α_min (α_max/α_min)^(a/(count − 1)).
fn rough_lut_block_alpha(p: RoughLutParams, a: u32) -> f32 {
    let n = max(p.alpha_count, 1u);
    let t = select(0.0, f32(a) / f32(n - 1u), n > 1u);
    return p.alpha_min * pow(p.alpha_max / p.alpha_min, t);
}

// Forward mapping: physical (cos θ_o, α, d nm, n_f) → (t_x, t_y, t_n, t_α), t_y referred to α.
fn rough_lut_forward(p: RoughLutParams, cos_theta_o: f32, alpha: f32, thickness_nm: f32, film_ior: f32) -> vec4<f32> {
    // A NaN cosine gives t_x = t_y = 0, as in the Rust (where NaN propagates and becomes 0).
    let b = bitcast<u32>(cos_theta_o);
    let nan = (b & 0x7f800000u) == 0x7f800000u && (b & 0x007fffffu) != 0u;
    let c = select(clamp(cos_theta_o, 0.0, 1.0), 0.0, nan);
    let a = max(alpha, p.alpha_min);
    let tx = select(sqrt(c), 0.0, nan);
    let ty = select(rough_lut_opd_nm(p, c, a, thickness_nm, film_ior) / rough_lut_opd_max_nm(p), 0.0, nan);
    let span = p.ior_max - p.ior_min;
    let tn = select(0.0, sqrt(max((film_ior - p.ior_min) / span, 0.0)), span > 0.0);
    let ta = rough_lut_alpha_t(p, a);
    return vec4<f32>(rough_lut_unit(tx), rough_lut_unit(ty), rough_lut_unit(tn), rough_lut_unit(ta));
}

// Inverse mapping: t → (cos θ_o, Δ nm, n_f, α).
fn rough_lut_inverse(p: RoughLutParams, t: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(
        t.x * t.x,
        t.y * rough_lut_opd_max_nm(p),
        p.ior_min + t.z * t.z * (p.ior_max - p.ior_min),
        p.alpha_min * pow(p.alpha_max / p.alpha_min, t.w),
    );
}

// Texture coordinate of t on an axis of `count` texels: (t (count − 1) + 0.5) / count.
fn rough_lut_texel_coordinate(t: f32, count: u32) -> f32 {
    let n = f32(max(count, 1u));
    return (t * (n - 1.0) + 0.5) / n;
}

// The texture coordinates of the two α blocks around α and the blend weight of the second.
fn rough_lut_coords(p: RoughLutParams, cos_theta_o: f32, alpha: f32, thickness_nm: f32, film_ior: f32) -> RoughLutCoords {
    let t = rough_lut_forward(p, cos_theta_o, alpha, thickness_nm, film_ior);
    let n_alpha = max(p.alpha_count, 1u);
    let n_ior = max(p.ior_count, 1u);
    var a0 = 0u;
    var blend = 0.0;
    if n_alpha > 1u {
        let s = t.w * f32(n_alpha - 1u);
        a0 = min(u32(floor(s)), n_alpha - 2u);
        blend = s - f32(a0);
    }
    let a1 = min(a0 + 1u, n_alpha - 1u);
    let depth = f32(n_alpha * n_ior);
    let u = rough_lut_texel_coordinate(t.x, p.cos_theta_count);
    let k = t.z * f32(n_ior - 1u) + 0.5;
    // Each block's Δ axis refers to the block's own roughness.
    let ty0 = rough_lut_forward(p, cos_theta_o, rough_lut_block_alpha(p, a0), thickness_nm, film_ior).y;
    let ty1 = rough_lut_forward(p, cos_theta_o, rough_lut_block_alpha(p, a1), thickness_nm, film_ior).y;
    var out: RoughLutCoords;
    out.uvw0 = vec3<f32>(u, rough_lut_texel_coordinate(ty0, p.opd_count), (f32(a0 * n_ior) + k) / depth);
    out.uvw1 = vec3<f32>(u, rough_lut_texel_coordinate(ty1, p.opd_count), (f32(a1 * n_ior) + k) / depth);
    out.blend = blend;
    return out;
}

// The albedo colour of one quantity (the texture's rgb): two linear fetches mixed in α.
// `samp` must filter linearly with clamp-to-edge addressing; level 0 (the table has no mips).
fn rough_lut_sample(table: texture_3d<f32>, samp: sampler, p: RoughLutParams, cos_theta_o: f32, alpha: f32, thickness_nm: f32, film_ior: f32) -> vec3<f32> {
    let k = rough_lut_coords(p, cos_theta_o, alpha, thickness_nm, film_ior);
    let e0 = textureSampleLevel(table, samp, k.uvw0, 0.0).rgb;
    let e1 = textureSampleLevel(table, samp, k.uvw1, 0.0).rgb;
    return mix(e0, e1, k.blend);
}
