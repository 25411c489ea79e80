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
//   diffraction_colour_footprint(ω_i, ω_r, σ_uv, λ_ref) = diffraction_integrated_colour_filtered(
//                                               ω_i, ω_r, max(σ_u, σ_v), σ_m², F²): the prefiltered
//                                               levels read at σ² = max(σ_u, σ_v)² + w² σ_m²
//                                               (isotropic levels: the footprint's larger axis,
//                                               blurring the other more than it needs rather
//                                               than aliasing), σ_m² the uniform's
//                                               slope_variance (a rough grating); with the
//                                               uniform's footprint_filter 0 (`--footprint-filter off`
//                                               on a smooth grating), diffraction_colour. λ_ref
//                                               is not read: a table baked with Stam's k²
//                                               (manifest `k_squared_reference_nm`) holds the
//                                               (λ_ref/λ)² weight of the terms technique in its
//                                               layers, and the host's light gain takes k_ref at
//                                               the table's λ_ref (lobe_gain); a table without
//                                               it (an older bake) renders without the weight,
//                                               as it did
//   diffraction_specular_order_colour(cos θ)  = diffraction_integrated_specular_colour(cos θ, F²)
//                                               (the mirror-lobe peak from the unweighted Jₚ;
//                                               see its comment)
//   diffraction_fresnel(cos θ)                = diffraction_fresnel_of(cos θ, the uniform's F²)
//   (diffraction_frame and diffraction_finite3 come from diffraction_common.wgsl)

fn diffraction_fresnel(cos_theta: f32) -> f32 {
    return diffraction_fresnel_of(cos_theta, diffraction_integrated.fresnel_kind, diffraction_integrated.fresnel_ior);
}

fn diffraction_colour(wi: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    return diffraction_integrated_colour(wi, wr, diffraction_integrated.fresnel_kind, diffraction_integrated.fresnel_ior);
}

fn diffraction_colour_footprint(wi: vec3<f32>, wr: vec3<f32>, sigma_uv: vec2<f32>, reference_nm: f32) -> vec3<f32> {
    if diffraction_integrated.footprint_filter == 0u {
        return diffraction_colour(wi, wr);
    }
    return diffraction_integrated_colour_filtered(
        wi,
        wr,
        max(sigma_uv.x, sigma_uv.y),
        diffraction_integrated.slope_variance,
        diffraction_integrated.fresnel_kind,
        diffraction_integrated.fresnel_ior,
    );
}

fn diffraction_specular_order_colour(cos_theta: f32) -> vec3<f32> {
    return diffraction_integrated_specular_colour(cos_theta, diffraction_integrated.fresnel_kind, diffraction_integrated.fresnel_ior);
}
