// nacre · shaders/film_lut.wgsl — technique `film_lut`
// import: common, lut_mapping
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

@group(1) @binding(0) var film_lut_reflectance: texture_3d<f32>;
// A 1×1×1 zero texture when the base is opaque (FilmLutParams.has_transmittance = 0).
@group(1) @binding(1) var film_lut_transmittance: texture_3d<f32>;
// Linear min/mag/mip filtering, clamp-to-edge addressing.
@group(1) @binding(2) var film_lut_sampler: sampler;
@group(1) @binding(3) var<uniform> film_lut_params: FilmLutParams;

fn film_colour(raw: FilmInput) -> FilmOutput {
    let input = sanitize_input(raw);
    let p = film_lut_params;
    let t = lut_forward(p, input.cos_theta_i, input.thickness_nm, input.film_ior);
    let uvw = lut_texture_coordinate(t, lut_counts(p));
    var out: FilmOutput;
    out.reflectance = textureSampleLevel(film_lut_reflectance, film_lut_sampler, uvw, 0.0).rgb;
    out.transmittance = vec3<f32>(0.0);
    if p.has_transmittance != 0u {
        out.transmittance = textureSampleLevel(film_lut_transmittance, film_lut_sampler, uvw, 0.0).rgb;
    }
    return sanitize_output(out);
}
