// nacre · shaders/lut_mapping.wgsl
// import: common
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

// Mirror of `FilmLutAxes` (48 bytes, uniform):
//
//   offset size field
//        0    4 cos_theta_count: u32    texels along cos θ (x)
//        4    4 opd_count: u32          texels along Δ (y)
//        8    4 ior_count: u32          texels along the film index (z)
//       12    4 thickness_min_nm: f32
//       16    4 thickness_max_nm: f32
//       20    4 ior_min: f32
//       24    4 ior_max: f32
//       28    4 ambient_index: f32
//       32    4 has_transmittance: u32  1 when binding 1 holds a baked transmittance table, else 0
//       36   12 _pad0, _pad1, _pad2: u32
//
// The counts must equal the dimensions of the bound textures.
struct FilmLutParams {
    cos_theta_count: u32,
    opd_count: u32,
    ior_count: u32,
    thickness_min_nm: f32,
    thickness_max_nm: f32,
    ior_min: f32,
    ior_max: f32,
    ambient_index: f32,
    has_transmittance: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// Texel counts (x, y, z) as floats, at least 1.
fn lut_counts(p: FilmLutParams) -> vec3<f32> {
    return vec3<f32>(max(vec3<u32>(p.cos_theta_count, p.opd_count, p.ior_count), vec3<u32>(1u)));
}

// Δ_max = 2 d_max n_max, nm.
fn lut_opd_max_nm(p: FilmLutParams) -> f32 {
    return 2.0 * p.thickness_max_nm * p.ior_max;
}

// q(n) = √max(n² − n₀² sin²θ, 0), with sin²θ = max(1 − cos²θ, 0) as in the Rust.
fn lut_film_q(p: FilmLutParams, cos_theta: f32, film_ior: f32) -> f32 {
    let c = min(abs(cos_theta), 1.0);
    let a = p.ambient_index;
    let ac = a * c;
    return sqrt(max((film_ior - a) * (film_ior + a) + ac * ac, 0.0));
}

// Δ = 2 d q(n), nm.
fn lut_opd_nm(p: FilmLutParams, cos_theta: f32, thickness_nm: f32, film_ior: f32) -> f32 {
    return 2.0 * thickness_nm * lut_film_q(p, cos_theta, film_ior);
}

// Forward mapping: physical (cos θ, d nm, n) → t ∈ [0, 1]³.
fn lut_forward(p: FilmLutParams, cos_theta: f32, thickness_nm: f32, film_ior: f32) -> vec3<f32> {
    // A NaN cosine makes every coordinate NaN in the Rust, hence 0.
    if f32_is_nan(cos_theta) {
        return vec3<f32>(0.0);
    }
    let c = clamp(cos_theta, 0.0, 1.0);
    let tx = sqrt(c);
    let ty = lut_opd_nm(p, c, thickness_nm, film_ior) / lut_opd_max_nm(p);
    let q_min = lut_film_q(p, c, p.ior_min);
    let q_max = lut_film_q(p, c, p.ior_max);
    var tz = 0.0;
    if q_max > q_min {
        tz = sqrt(max((lut_film_q(p, c, film_ior) - q_min) / (q_max - q_min), 0.0));
    }
    let t = vec3<f32>(tx, ty, tz);
    return select(vec3<f32>(0.0), clamp(t, vec3<f32>(0.0), vec3<f32>(1.0)), vec3_is_finite(t));
}

// Inverse mapping: t → (cos θ, Δ nm, n).
fn lut_inverse(p: FilmLutParams, t: vec3<f32>) -> vec3<f32> {
    let c = t.x * t.x;
    let q_min = lut_film_q(p, c, p.ior_min);
    let q_max = lut_film_q(p, c, p.ior_max);
    let q = q_min + t.z * t.z * (q_max - q_min);
    // n² = q² + n₀² sin²θ = q² + n₀² − (n₀ cos θ)².
    let a = p.ambient_index;
    let ac = a * c;
    let n = sqrt(max(q * q + a * a - ac * ac, 0.0));
    return vec3<f32>(c, t.y * lut_opd_max_nm(p), n);
}

// Texture coordinate that samples t on axes of `counts` texels: (t (count − 1) + 0.5) / count.
fn lut_texture_coordinate(t: vec3<f32>, counts: vec3<f32>) -> vec3<f32> {
    let n = max(counts, vec3<f32>(1.0));
    return (t * (n - 1.0) + 0.5) / n;
}
