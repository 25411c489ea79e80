// nacre · shaders/diffraction_integrated_technique.wgsl
// import: diffraction_integrated
//
// Adapter: presents the layout "integrated" module (diffraction_integrated.wgsl, composed
// before this file) under the names the consumers of the terms technique call
// (diffraction_scene.wgsl: the cd-disc and snake-skin scenes, the bench pass, the probe),
// so that `diffraction_integrated.wgsl + this file + diffraction_scene.wgsl` is a complete
// pipeline source with group 1 = `nacre_runtime::diffraction_integrated::DiffractionIntegrated`
// instead of the terms table. F² comes from the uniform's `fresnel_kind` and `fresnel_ior`
// (the host's `FresnelTerm`, as the terms technique's uniform carries it).
//
//   diffraction_colour(ω_i, ω_r)              = diffraction_integrated_colour(ω_i, ω_r, F²)
//   diffraction_colour_footprint(ω_i, ω_r, σ_uv, λ_ref) = diffraction_colour(ω_i, ω_r): the
//                                               integrated tables are not filtered over the
//                                               footprint, and their bake summed ρ u(λ) over
//                                               the wavelengths without Stam's k², so the
//                                               (λ_ref/λ)² weight of the terms technique is
//                                               left out (it would need tables baked with it)
//   diffraction_specular_order_colour(cos θ)  = diffraction_integrated_specular_colour(cos θ, F²)
//                                               (the mirror-lobe peak; see its comment)
//   diffraction_fresnel(cos θ)                = diffraction_fresnel_of(cos θ, the uniform's F²)
//   (diffraction_frame and diffraction_finite3 come from diffraction_common.wgsl)

fn diffraction_fresnel(cos_theta: f32) -> f32 {
    return diffraction_fresnel_of(cos_theta, diffraction_integrated.fresnel_kind, diffraction_integrated.fresnel_ior);
}

fn diffraction_colour(wi: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    return diffraction_integrated_colour(wi, wr, diffraction_integrated.fresnel_kind, diffraction_integrated.fresnel_ior);
}

fn diffraction_colour_footprint(wi: vec3<f32>, wr: vec3<f32>, sigma_uv: vec2<f32>, reference_nm: f32) -> vec3<f32> {
    return diffraction_colour(wi, wr);
}

fn diffraction_specular_order_colour(cos_theta: f32) -> vec3<f32> {
    return diffraction_integrated_specular_colour(cos_theta, diffraction_integrated.fresnel_kind, diffraction_integrated.fresnel_ior);
}
