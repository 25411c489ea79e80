// nacre · shaders/film_spectral.wgsl — technique `film_spectral`
// import: common
//
// Thin-film colour by brute force: the exact Airy reflectance and transmittance of one film on
// a base at each of N wavelengths, weighted per output channel and summed. The GPU twin of
// `nacre color --method samples:N` (crates/optics/src/spectral.rs: `sample_weights` supplies the
// wavelengths and weights, the stack recurrence of crates/optics/src/stack.rs evaluates the
// stack, which for one film is the Airy formula of common.wgsl). Needs common.wgsl.
//
// Symbols
//
//   symbol          code                           meaning
//   λ_k             SpectralSample.wavelength_nm   vacuum wavelength of sample k, nm
//   w_k,j           SpectralSample.weight.rgb      weight of sample k in channel j (Σ_k w_k = white)
//   ñ₃(λ_k)         base_ior + i base_kappa        base index at λ_k
//   n₁, n₂, d       FilmInput                      ambient index, film index, thickness nm
//   R, T            airy_film_power                unpolarised (s + p)/2 powers at λ_k
//
//   C_j = Σ_k w_k,j R(λ_k)   and likewise for T   (Sussenbach 2013 §4.3: N-sample shortcut)
//
// with r = (r₁₂ + r₂₃ e^{2iδ}) / (1 + r₁₂ r₂₃ e^{2iδ}), δ = 2π d q₂ / λ, and T = |t|² × the
// power factor of common.wgsl (Byrnes' tmm conventions), exact for absorbing bases, total
// internal reflection and evanescent films.
//
// FilmInput fields used: cos_theta_i, thickness_nm, film_ior, ambient_ior. The base comes
// from the samples (FilmInput.base_ior/base_kappa are ignored), and so does dispersion;
// sigma_thickness_nm is ignored. Samples with a non-finite or non-positive wavelength are
// skipped; their base index is sanitised like FilmInput's. Channels may come out negative
// (RGB weights can be negative: out-of-gamut colours), as on the CPU.

// One wavelength (32 bytes, array stride 32, storage):
//
//   offset size field
//        0    4 wavelength_nm: f32
//        4    4 base_ior: f32        real part n of the base index at λ
//        8    4 base_kappa: f32      imaginary part κ ≥ 0
//       12    4 _pad: f32
//       16   16 weight: vec4<f32>    rgb: per-channel weight; a: unused (0)
struct SpectralSample {
    wavelength_nm: f32,
    base_ior: f32,
    base_kappa: f32,
    _pad: f32,
    weight: vec4<f32>,
}

// (16 bytes, uniform)
//
//   offset size field
//        0    4 count: u32           samples to use (clamped to the array's length)
//        4   12 _pad0, _pad1, _pad2: u32
struct SpectralParams {
    count: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(1) @binding(0) var<storage, read> spectral_samples: array<SpectralSample>;
@group(1) @binding(1) var<uniform> spectral_params: SpectralParams;

fn film_colour(raw: FilmInput) -> FilmOutput {
    let input = sanitize_input(raw);
    let c = max(input.cos_theta_i, COS_THETA_MIN);
    let film = c_real(input.film_ior);
    let count = min(spectral_params.count, arrayLength(&spectral_samples));
    var r = vec3<f32>(0.0);
    var t = vec3<f32>(0.0);
    for (var k = 0u; k < count; k++) {
        let smp = spectral_samples[k];
        if !f32_is_finite(smp.wavelength_nm) || !(smp.wavelength_nm > 0.0) {
            continue;
        }
        let n3 = sanitize_base_index(smp.base_ior, smp.base_kappa);
        let power = airy_film_power(input.ambient_ior, film, n3, c, input.thickness_nm, smp.wavelength_nm);
        r += 0.5 * (power.x + power.y) * smp.weight.rgb;
        t += 0.5 * (power.z + power.w) * smp.weight.rgb;
    }
    return sanitize_output(FilmOutput(r, t));
}
