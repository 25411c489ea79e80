// plain.wgsl — the baseline "technique" of `nacre bench-gpu`: no film, Schlick's Fresnel
// import: common
// approximation for a dielectric base, so that a consumer shades exactly the same GGX
// material with and without a film term and the cost ratio isolates the film.
//
// Symbols
//   F0        normal-incidence reflectance ((n₁ − n₃)/(n₁ + n₃))², from the base index
//   cos θᵢ    cosine of the incidence angle in the ambient
// Equations
//   F = F0 + (1 − F0)(1 − cos θᵢ)⁵  (Schlick 1994, Eq. 24); T = 1 − F.
// Bind group 1 is empty.

fn film_colour(raw: FilmInput) -> FilmOutput {
    let input = sanitize_input(raw);
    let r = (input.ambient_ior - input.base_ior) / (input.ambient_ior + input.base_ior);
    let f0 = r * r;
    let m = 1.0 - input.cos_theta_i;
    let m2 = m * m;
    let f = f0 + (vec3<f32>(1.0) - f0) * (m2 * m2 * m);
    var out: FilmOutput;
    out.reflectance = f;
    out.transmittance = vec3<f32>(1.0) - f;
    return sanitize_output(out);
}
