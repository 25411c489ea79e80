// bevy_nacre · film_material.wgsl — fragment shader of `NacreMaterial`
// (`ExtendedMaterial<StandardMaterial, NacreFilm>`).
//
// Bevy's StandardMaterial lighting with nacre's thin-film reflectance in place of the Fresnel
// term of the specular lobe (Belcour & Barla 2017, "A Practical Extension to Microfacet
// Theory for the Modeling of Varying Iridescence"; glTF KHR_materials_iridescence: the
// film's Airy reflectance replaces Fresnel in the microfacet BRDF, evaluated at the
// microfacet angle cos θ = v·h). nacre's functions come from the repository's shaders,
// registered as naga_oil modules (src/shaders.rs): `film_lut::film_colour` (a baked
// film-lut table, bindings 100–103), `film_fourier::film_colour` (any film on any base,
// metals included, bindings 104–105) and `film_stack::film_colour` (a multilayer stack,
// bindings 111–113: its nodes, indices and StackParams; the thickness texture's R, G, B give
// its lower films' variations s_c = 2c − 1). The technique is a shader def from the material's
// pipeline key (`NACRE_FILM_LUT`, `NACRE_FILM_FOURIER` or `NACRE_FILM_STACK`,
// src/material.rs), so a pipeline compiles one of them. Bevy's functions are imported, never
// copied.
//
// Symbols
//
//   symbol        code                   meaning
//   μ = n·v       n_dot_v                cosine of the view angle (Bevy's max(n·v, 10⁻⁴))
//   v·h           cos_theta (per light)  cosine of the microfacet angle of a light
//   d             thickness_nm           film thickness, nm
//   g             thickness_g            thickness texture's green channel (1 without a texture)
//   w             weight                 film weight (KHR_materials_iridescence factor × texture R)
//   R_f(c), T_f   film.reflectance/…     the film's reflectance / transmittance colours at cos c
//   F₀            f0_base                the material's own F₀ (Bevy: 0.16 r² dielectric, base colour metal)
//   α             roughness              Bevy's perceptualRoughnessToRoughness(perceptual roughness)
//   D, V          lighting::D_GGX, lighting::V_SmithGGXCorrelated   Bevy's GGX and visibility
//   A, B          f_ab                   Bevy's split-sum terms lighting::F_AB(r_p, μ)
//   E_l           light colour           lux (directional) or cd·range falloff (point/spot), linear RGB
//
// Thickness (glTF KHR_materials_iridescence): d = mix(d_min, d_max, g); SVT form (nacre's
// `--thickness-mode svt`): d = d_avg + d_rel (2g − 1).
//
// Forward pass (exact). Bevy's `apply_pbr_lighting` runs with F₀ = 0 (reflectance 0,
// metallic 0, base colour (1 − m)·base): its Schlick Fresnel F₀ + (f₉₀ − F₀)(1 − l·h)⁵ with
// f₉₀ = saturate(16.5 ΣF₀) is then exactly 0, and so are its ambient and environment
// specular (F₀ A + B times that same f₉₀ occlusion), so it gives Bevy's diffuse (direct,
// ambient, environment, lightmaps, irradiance volumes), emissive and transmission unchanged
// and no specular. This shader adds the specular itself, looping over Bevy's lights as
// `apply_pbr_lighting` does (`mesh_view_bindings::lights.directional_lights`, then the
// fragment's cluster of `clustered_lights` for point and spot lights, their shadows through
// `bevy_pbr::shadows::fetch_*`), each light l:
//   F_l   = mix(Schlick(F₀, v·h), R_f(v·h), w)                   (Bevy's `lighting::fresnel`)
//   f_r,l = D(α_l, n·h) V(α_l, μ, n·l) F_l · s_l · (1 + F₀ₘ (1/(A + B) − 1))
//   L_o  += f_r,l · n·l · E_l · shadow_l · cone_l
// with F₀ₘ = mix(F₀, R_f(μ), w) in Bevy's multiple-scattering factor (`specular_multiscatter`);
// point and spot lights use Bevy's representative point (`compute_specular_layer_values_for_
// point_light`: direction l and α_l = mix(α, α', ·), s_l = (α/α')²) and sphere solid-angle
// term; directional lights α_l = α, s_l = 1. The environment (Bevy's ambient light and
// environment map), split sum with the film at μ in place of both Schlick end points:
//   E_spec = mix((F₀ A + B) saturate(16.5 ΣF₀), R_f(μ) (A + B), w)
//   L_o  += E_spec · (ambient colour · diffuse occlusion + radiance(env. map) · specular occlusion)
// Everything times the view's exposure, before Bevy's post-lighting steps (fog, alpha).
// Where the material transmits (specular_transmission > 0) the transmitted light (whose
// Fresnel factor is then 1) is tinted by mix(1, T_f(μ), w).
// nacre's film is evaluated once at μ (environment, transmittance, F₀ₘ) and once per light
// at its v·h (`nacre_light_lobe`).
// Not covered: clearcoat does not darken the film's lobe, anisotropy is ignored (isotropic
// lobe), light textures, atmosphere transmittance and contact shadows are not applied to
// the film's lobe, rectangle lights (AREA_LIGHT_LUTS) get no film specular, screen-space
// reflections are not used for the film, and Bevy's environment-map multiple-scattering
// diffuse term (FmsEms) and specular energy loss of the diffuse (Edss) use F₀ = 0.
//
// Deferred and prepass pipelines (approximate): the G-buffer holds one F₀, so the film is
// evaluated once at μ and Bevy's Schlick is given the F₀ that inverts Schlick at l·h = μ
// (the mirror configuration, where the lobe peaks):
//   F₀' = max((R_f(μ) − x)/(1 − x), 0), x = min((1 − μ)⁵, 0.99),
// F₀ = mix(F₀_base, F₀', w), set through `reflectance` (dielectrics: F₀ = 0.16 r²) and the
// base colour (metals); Bevy's Fresnel then equals R_f exactly at the mirror direction and
// follows Schlick's shape elsewhere.

#import bevy_pbr::{
    pbr_fragment::pbr_input_from_standard_material,
    pbr_functions::alpha_discard,
    pbr_types::PbrInput,
}
#import nacre::common::{FilmInput, FilmOutput}
#import nacre::film_lut
#import nacre::film_fourier
#import nacre::film_stack

#ifdef PREPASS_PIPELINE
#import bevy_pbr::{
    prepass_io::{VertexOutput, FragmentOutput},
    pbr_deferred_functions::deferred_output,
}
#else
#import bevy_pbr::{
    forward_io::{VertexOutput, FragmentOutput},
    pbr_functions::{apply_pbr_lighting, main_pass_post_lighting_processing, calculate_F0},
    lighting,
    lighting::LAYER_BASE,
    mesh_view_bindings as view_bindings,
    mesh_view_types,
    clustered_forward as clustering,
    shadows,
    mesh_types::MESH_FLAGS_SHADOW_RECEIVER_BIT,
}
#ifdef ENVIRONMENT_MAP
#import bevy_pbr::environment_map
#endif
#endif

// Mirror of `NacreFilmUniform` (src/material.rs, 64 bytes).
struct NacreFilmUniform {
    // 0: film_lut, 1: film_fourier, 2: film_stack (the shader compiles one, chosen by shader
    // def).
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
#ifdef NACRE_FILM_STACK
    return film_stack::film_colour(input);
#else
#ifdef NACRE_FILM_FOURIER
    return film_fourier::film_colour(input);
#else
    return film_lut::film_colour(input);
#endif
#endif
}

// Film thickness d (nm) from the thickness texture's green channel g.
fn nacre_thickness_nm(g: f32) -> f32 {
    if nacre_film.thickness_mode == 1u {
        return nacre_film.thickness_a_nm + nacre_film.thickness_b_nm * (2.0 * g - 1.0);
    }
    return mix(nacre_film.thickness_a_nm, nacre_film.thickness_b_nm, g);
}

#ifndef PREPASS_PIPELINE
// The film's specular light (forward pass, before exposure) and its transmittance at μ.
struct NacreSpecular {
    light: vec3<f32>,
    transmittance: vec3<f32>,
}

// The film's lobe for one light l: Bevy's GGX D and V with F_l = mix(Schlick(F₀, v·h),
// R_f(v·h), w) and Bevy's multiple-scattering factor (see the header), times n·l · E_l.
fn nacre_light_lobe(
    N: vec3<f32>,
    V: vec3<f32>,
    L: vec3<f32>,
    n_dot_v: f32,
    a: f32,
    intensity: f32,
    light: vec3<f32>,
    film_template: FilmInput,
    f0_base: vec3<f32>,
    f0_multiscatter: vec3<f32>,
    f_ab: vec2<f32>,
    weight: f32,
) -> vec3<f32> {
    let derived = lighting::derive_lighting_input(N, V, L);
    var film_input = film_template;
    film_input.cos_theta_i = saturate(dot(V, derived.H));
    let film = nacre_film_colour(film_input);
    let F = mix(lighting::fresnel(f0_base, derived.LdotH), film.reflectance, weight);
    let D = lighting::D_GGX(a, derived.NdotH);
    let vis = lighting::V_SmithGGXCorrelated(a, n_dot_v, derived.NdotL);
    let f_r = lighting::specular_multiscatter(D, vis, F, f0_multiscatter, f_ab, intensity);
    return f_r * derived.NdotL * light;
}

// The environment at μ, then Bevy's directional lights and the cluster's point and spot
// lights, each in a loop of its own as in `apply_pbr_lighting`.
fn nacre_specular(
    pbr_input: PbrInput,
    film_template: FilmInput,
    f0_base: vec3<f32>,
    weight: f32,
) -> NacreSpecular {
    let N = pbr_input.N;
    let V = pbr_input.V;
    let P = pbr_input.world_position.xyz;
    let n_dot_v = max(dot(N, V), 0.0001);
    let perceptual_roughness = pbr_input.material.perceptual_roughness;
    let roughness = lighting::perceptualRoughnessToRoughness(perceptual_roughness);
    let f_ab = lighting::F_AB(perceptual_roughness, n_dot_v);
    let receives_shadows = (pbr_input.flags & MESH_FLAGS_SHADOW_RECEIVER_BIT) != 0u;

    // Bevy's lighting input, for its representative-point and environment functions.
    var lighting_input: lighting::LightingInput;
    lighting_input.layers[LAYER_BASE].N = N;
    lighting_input.layers[LAYER_BASE].R = reflect(-V, N);
    lighting_input.layers[LAYER_BASE].NdotV = n_dot_v;
    lighting_input.layers[LAYER_BASE].perceptual_roughness = perceptual_roughness;
    lighting_input.layers[LAYER_BASE].roughness = roughness;
    lighting_input.P = P;
    lighting_input.V = V;
    lighting_input.diffuse_color = vec3<f32>(0.0);
    lighting_input.metallic = 0.0;
    lighting_input.F0_dielectric = f0_base;
    lighting_input.F0_metallic = f0_base;
    lighting_input.F_ab = f_ab;

    let view_z = dot(vec4<f32>(
        view_bindings::view.view_from_world[0].z,
        view_bindings::view.view_from_world[1].z,
        view_bindings::view.view_from_world[2].z,
        view_bindings::view.view_from_world[3].z
    ), pbr_input.world_position);
    let cluster_index = clustering::view_fragment_cluster_index(pbr_input.frag_coord.xy, view_z, pbr_input.is_orthographic);
    var ranges = clustering::unpack_clusterable_object_index_ranges(cluster_index);

    // Environment light reaching the split sum (ambient light and environment map).
    var environment = view_bindings::lights.ambient_color.rgb * pbr_input.diffuse_occlusion;
#ifdef ENVIRONMENT_MAP
    let radiances = environment_map::compute_radiances(lighting_input.layers[LAYER_BASE], &ranges, P, false);
    environment += radiances.radiance * pbr_input.specular_occlusion;
#endif

    // The film at μ: environment, transmittance, multiple scattering.
    var film_input = film_template;
    film_input.cos_theta_i = n_dot_v;
    let film_mu = nacre_film_colour(film_input);
    let e_spec = mix(
        lighting::EnvBRDFApprox(f0_base, f_ab) * saturate(dot(f0_base, vec3<f32>(50.0 * 0.33))),
        film_mu.reflectance * (f_ab.x + f_ab.y),
        weight,
    );
    var out: NacreSpecular;
    out.light = e_spec * environment;
    out.transmittance = mix(vec3<f32>(1.0), max(film_mu.transmittance, vec3<f32>(0.0)), weight);
    let f0_multiscatter = mix(f0_base, film_mu.reflectance, weight);

    // Directional lights.
    let n_directional = view_bindings::lights.n_directional_lights;
    for (var i = 0u; i < n_directional; i += 1u) {
        let directional = &view_bindings::lights.directional_lights[i];
        var light = (*directional).color.rgb;
        if receives_shadows && ((*directional).flags & mesh_view_types::DIRECTIONAL_LIGHT_FLAGS_SHADOWS_ENABLED_BIT) != 0u {
            light *= shadows::fetch_directional_shadow(i, pbr_input.world_position, pbr_input.world_normal, view_z, pbr_input.frag_coord.xy);
        }
        out.light += nacre_light_lobe(N, V, (*directional).direction_to_light, n_dot_v, roughness, 1.0, light,
            film_template, f0_base, f0_multiscatter, f_ab, weight);
    }

    // The cluster's point and spot lights.
    for (var index = ranges.first_point_light_index_offset; index < ranges.first_reflection_probe_index_offset; index += 1u) {
        let light_id = clustering::get_clusterable_object_id(index);
        let clustered = &view_bindings::clustered_lights.data[light_id];
        let light_to_frag = (*clustered).position_radius.xyz - P;
        let distance_squared = dot(light_to_frag, light_to_frag);
        let distance = sqrt(distance_squared);
        let radius = (*clustered).position_radius.w;
        let l_a = lighting::compute_specular_layer_values_for_point_light(&lighting_input, LAYER_BASE, V, light_to_frag, radius, distance);
        let L = l_a.xyz;
        let a = mix(roughness, l_a.w, lighting::specular_fix_remap(roughness));
        let intensity = (roughness / l_a.w) * (roughness / l_a.w);
        var light = (*clustered).color_inverse_square_range.rgb
            * lighting::getDistanceAttenuation(distance_squared, (*clustered).color_inverse_square_range.w);
        let n_dot_l = saturate(dot(N, L));
        if radius > 0.0 {
            let solid_angle = radius * radius / distance_squared;
            light *= saturate(n_dot_l / max(n_dot_l + solid_angle, 1e-4));
        }
        let shadowed = receives_shadows && ((*clustered).flags & mesh_view_types::POINT_LIGHT_FLAGS_SHADOWS_ENABLED_BIT) != 0u;
        if index < ranges.first_spot_light_index_offset {
            if shadowed {
                light *= shadows::fetch_point_shadow(light_id, pbr_input.world_position, pbr_input.world_normal, pbr_input.frag_coord.xy);
            }
        } else {
            // The spot's cone: the axis is stored as x, z and the sign of y.
            var axis = vec3<f32>((*clustered).light_custom_data.x, 0.0, (*clustered).light_custom_data.y);
            axis.y = sqrt(max(0.0, 1.0 - axis.x * axis.x - axis.z * axis.z));
            if ((*clustered).flags & mesh_view_types::POINT_LIGHT_FLAGS_SPOT_LIGHT_Y_NEGATIVE) != 0u {
                axis.y = -axis.y;
            }
            let cone = saturate(dot(-axis, normalize(light_to_frag)) * (*clustered).light_custom_data.z + (*clustered).light_custom_data.w);
            light *= cone * cone;
            if shadowed {
                light *= shadows::fetch_spot_shadow(light_id, pbr_input.world_position, pbr_input.world_normal, (*clustered).shadow_map_near_z, pbr_input.frag_coord.xy);
            }
        }
        out.light += nacre_light_lobe(N, V, L, n_dot_v, a, intensity, light,
            film_template, f0_base, f0_multiscatter, f_ab, weight);
    }
    return out;
}
#endif

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
    // film_stack: the thickness texture's R, G, B (1 without one) vary its lower films.
    var thickness_rgb = vec3<f32>(1.0);
    var weight = nacre_film.weight;
#ifdef VERTEX_UVS_A
    let rgb = textureSample(nacre_thickness_texture, nacre_thickness_sampler, in.uv).rgb;
    let w = textureSample(nacre_weight_texture, nacre_weight_sampler, in.uv).r;
    if (nacre_film.flags & 1u) != 0u {
        thickness_g = rgb.g;
        thickness_rgb = rgb;
    }
    if (nacre_film.flags & 2u) != 0u {
        weight *= w;
    }
#endif
    weight = clamp(weight, 0.0, 1.0);

    var input: FilmInput;
    input.cos_theta_i = clamp(dot(pbr_input.N, pbr_input.V), 0.0, 1.0);
    input.thickness_nm = nacre_thickness_nm(thickness_g);
    input.film_ior = nacre_film.film_ior;
    input.sigma_thickness_nm = 0.0;
    input.ambient_ior = nacre_film.ambient_ior;
    input.base_ior = nacre_film.base_ior;
    input.base_kappa = nacre_film.base_kappa;
    input.variation = 2.0 * thickness_rgb.r - 1.0;
    input.variation_g = 2.0 * thickness_rgb.g - 1.0;
    input.variation_b = 2.0 * thickness_rgb.b - 1.0;
    let m = pbr_input.material.metallic;
    let base = pbr_input.material.base_color.rgb;
    let alpha = pbr_input.material.base_color.a;

#ifdef PREPASS_PIPELINE
    // Inverse Schlick at l·h = μ (see the header).
    let film = nacre_film_colour(input);
    let cos_theta = input.cos_theta_i;
    let schlick_x = min(pow(1.0 - cos_theta, 5.0), 0.99);
    let f0_film = max((film.reflectance - vec3<f32>(schlick_x)) / (1.0 - schlick_x), vec3<f32>(0.0));
    let r = pbr_input.material.reflectance;
    let f0_dielectric = mix(0.16 * r * r, f0_film, weight);
    pbr_input.material.reflectance = sqrt(f0_dielectric / 0.16);
    pbr_input.material.base_color = vec4<f32>(mix(base, f0_film, m * weight), alpha);
    if pbr_input.material.specular_transmission > 0.0 {
        let t = mix(vec3<f32>(1.0), max(film.transmittance, vec3<f32>(0.0)), weight);
        pbr_input.material.base_color = vec4<f32>(pbr_input.material.base_color.rgb * t, alpha);
    }
    let out = deferred_output(in, pbr_input);
#else
    // The film's lobe (see the header), then Bevy's lighting with F₀ = 0 for the rest.
    let f0_base = calculate_F0(base, m, pbr_input.material.reflectance);
    let specular = nacre_specular(pbr_input, input, f0_base, weight);
    var diffuse_base = base * (1.0 - m);
    if pbr_input.material.specular_transmission > 0.0 {
        diffuse_base *= specular.transmittance;
    }
    pbr_input.material.base_color = vec4<f32>(diffuse_base, alpha);
    pbr_input.material.metallic = 0.0;
    pbr_input.material.reflectance = vec3<f32>(0.0);
    var out: FragmentOutput;
    out.color = apply_pbr_lighting(pbr_input);
    out.color = vec4<f32>(out.color.rgb + view_bindings::view.exposure * specular.light, out.color.a);
    out.color = main_pass_post_lighting_processing(pbr_input, out.color);
#endif
    return out;
}
