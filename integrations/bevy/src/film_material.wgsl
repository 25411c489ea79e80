// bevy_nacre · film_material.wgsl — fragment shader of `NacreMaterial`
// (`ExtendedMaterial<StandardMaterial, NacreFilm>`).
//
// Bevy's StandardMaterial lighting with nacre's thin-film colour in place of the Fresnel
// term of the specular lobe. nacre's functions come from the repository's shaders, which
// bevy_nacre registers as naga_oil modules (src/shaders.rs): `film_lut::film_colour` (a
// baked film-lut table, bindings 100–103) and `film_fourier::film_colour` (any film on any
// base, metals included, bindings 104–105).
//
// Symbols
//
//   symbol        code                   meaning
//   μ = n·v       cos_theta              cosine of the view angle
//   d             thickness_nm           film thickness, nm
//   g             thickness_g            thickness texture's green channel (1 without a texture)
//   w             weight                 film weight (KHR_materials_iridescence factor × texture R)
//   R_f, T_f      film.reflectance/…     the film's reflectance and transmittance colours at μ
//   F₀            f0                     what Bevy's Schlick Fresnel is given
//   x = (1 − μ)⁵  schlick_x
//
// Thickness (glTF KHR_materials_iridescence): d = mix(d_min, d_max, g); SVT form (nacre's
// `--thickness-mode svt`): d = d_avg + d_rel (2g − 1).
//
// The film in place of Fresnel. Bevy evaluates F = F₀ + (f₉₀ − F₀)(1 − l·h)⁵ with
// f₉₀ = saturate(50·0.33 ΣF₀) for every light, and F₀ A + B (its split-sum DFG fit) for the
// environment. nacre's film colour already holds the whole angular dependence, so F₀ is the
// inverse of Schlick at l·h = μ (the mirror configuration, where the lobe peaks):
//   F₀ = (R_f − x)/(1 − x), x = (1 − μ)⁵ (clamped ≤ 0.99), F₀ ≥ 0,
// so that Bevy's Fresnel equals R_f exactly at the mirror direction of every light and of
// the environment, and follows Schlick's shape around it. The weight blends with the
// material's own F₀: F₀ = mix(F₀_base, F₀_film, w). Bevy forms F₀ from `reflectance` for
// dielectrics (F₀ = 0.16 r²) and from the base colour for metals, so both are set.
// Where the material transmits (specular_transmission > 0) the transmitted light is tinted
// by mix(1, T_f, w).

#import bevy_pbr::{
    pbr_fragment::pbr_input_from_standard_material,
    pbr_functions::alpha_discard,
}
#import nacre::common::{FilmInput, FilmOutput}
#import nacre::film_lut
#import nacre::film_fourier

#ifdef PREPASS_PIPELINE
#import bevy_pbr::{
    prepass_io::{VertexOutput, FragmentOutput},
    pbr_deferred_functions::deferred_output,
}
#else
#import bevy_pbr::{
    forward_io::{VertexOutput, FragmentOutput},
    pbr_functions::{apply_pbr_lighting, main_pass_post_lighting_processing},
}
#endif

// Mirror of `NacreFilmUniform` (src/material.rs, 64 bytes).
struct NacreFilmUniform {
    // 0: film_lut, 1: film_fourier.
    technique: u32,
    // 0: glTF d = mix(a, b, g); 1: SVT d = a + b (2g − 1).
    thickness_mode: u32,
    // Bit 0: a thickness texture is bound; bit 1: a weight texture is bound.
    flags: u32,
    _pad0: u32,
    film_ior: f32,
    // glTF: d_min; SVT: d_avg (nm).
    thickness_a_nm: f32,
    // glTF: d_max; SVT: d_rel (nm).
    thickness_b_nm: f32,
    weight: f32,
    base_ior: vec3<f32>,
    ambient_ior: f32,
    base_kappa: vec3<f32>,
    _pad1: f32,
}

@group(#{MATERIAL_BIND_GROUP}) @binding(106) var<uniform> nacre_film: NacreFilmUniform;
@group(#{MATERIAL_BIND_GROUP}) @binding(107) var nacre_thickness_texture: texture_2d<f32>;
@group(#{MATERIAL_BIND_GROUP}) @binding(108) var nacre_thickness_sampler: sampler;
@group(#{MATERIAL_BIND_GROUP}) @binding(109) var nacre_weight_texture: texture_2d<f32>;
@group(#{MATERIAL_BIND_GROUP}) @binding(110) var nacre_weight_sampler: sampler;

// The film's colour through the material's technique.
fn nacre_film_colour(input: FilmInput) -> FilmOutput {
    if nacre_film.technique == 0u {
        return film_lut::film_colour(input);
    }
    return film_fourier::film_colour(input);
}

// Film thickness d (nm) from the thickness texture's green channel g.
fn nacre_thickness_nm(g: f32) -> f32 {
    if nacre_film.thickness_mode == 1u {
        return nacre_film.thickness_a_nm + nacre_film.thickness_b_nm * (2.0 * g - 1.0);
    }
    return mix(nacre_film.thickness_a_nm, nacre_film.thickness_b_nm, g);
}

@fragment
fn fragment(
    in: VertexOutput,
    @builtin(front_facing) is_front: bool,
) -> FragmentOutput {
    var pbr_input = pbr_input_from_standard_material(in, is_front);
    pbr_input.material.base_color = alpha_discard(pbr_input.material, pbr_input.material.base_color);

    // Thickness and weight textures (glTF: iridescenceThicknessTexture.g,
    // iridescenceTexture.r), sampled in uniform control flow.
    var thickness_g = 1.0;
    var weight = nacre_film.weight;
#ifdef VERTEX_UVS_A
    let g = textureSample(nacre_thickness_texture, nacre_thickness_sampler, in.uv).g;
    let w = textureSample(nacre_weight_texture, nacre_weight_sampler, in.uv).r;
    if (nacre_film.flags & 1u) != 0u {
        thickness_g = g;
    }
    if (nacre_film.flags & 2u) != 0u {
        weight *= w;
    }
#endif
    weight = clamp(weight, 0.0, 1.0);

    let cos_theta = clamp(dot(pbr_input.N, pbr_input.V), 0.0, 1.0);
    var input: FilmInput;
    input.cos_theta_i = cos_theta;
    input.thickness_nm = nacre_thickness_nm(thickness_g);
    input.film_ior = nacre_film.film_ior;
    input.sigma_thickness_nm = 0.0;
    input.ambient_ior = nacre_film.ambient_ior;
    input.base_ior = nacre_film.base_ior;
    input.base_kappa = nacre_film.base_kappa;
    let film = nacre_film_colour(input);

    // Inverse Schlick at l·h = μ (see the header).
    let schlick_x = min(pow(1.0 - cos_theta, 5.0), 0.99);
    let f0_film = max((film.reflectance - vec3<f32>(schlick_x)) / (1.0 - schlick_x), vec3<f32>(0.0));
    let r = pbr_input.material.reflectance;
    let f0_dielectric = mix(0.16 * r * r, f0_film, weight);
    pbr_input.material.reflectance = sqrt(f0_dielectric / 0.16);
    let m = pbr_input.material.metallic;
    let base = pbr_input.material.base_color.rgb;
    pbr_input.material.base_color = vec4<f32>(mix(base, f0_film, m * weight), pbr_input.material.base_color.a);
    if pbr_input.material.specular_transmission > 0.0 {
        let t = mix(vec3<f32>(1.0), max(film.transmittance, vec3<f32>(0.0)), weight);
        pbr_input.material.base_color = vec4<f32>(pbr_input.material.base_color.rgb * t, pbr_input.material.base_color.a);
    }

#ifdef PREPASS_PIPELINE
    let out = deferred_output(in, pbr_input);
#else
    var out: FragmentOutput;
    out.color = apply_pbr_lighting(pbr_input);
    out.color = main_pass_post_lighting_processing(pbr_input, out.color);
#endif
    return out;
}
