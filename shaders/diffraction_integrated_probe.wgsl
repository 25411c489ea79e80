// nacre · shaders/diffraction_integrated_probe.wgsl
// import: diffraction_integrated
//
// The GPU = CPU probe of the layout "integrated" (compute; composed after
// diffraction_integrated.wgsl by `nacre_runtime::diffraction_integrated::run_probe`).
// Group 0 is empty, group 1 the technique, group 2 unused, group 3 the probe's buffers.
//
// Input i (three vec4 per case):
//   probe_in[3i]     = (ω_i.xyz, F² kind as a float: 0 or 1)    grating frame, any values
//   probe_in[3i + 1] = (ω_r.xyz, σ_uv of the filtered call)
//   probe_in[3i + 2] = (n, κ of the Fresnel index, cos θ of the specular-colour call,
//                       σ_m² of the filtered call)
// Output i (four vec4: the host dispatches twice as many invocations as cases, so that the
// shared dispatcher's two vec4 per invocation make room; the extra ones find no input):
//   probe_out[4i]     = (diffraction_integrated_colour(ω_i, ω_r, F²), 0)
//   probe_out[4i + 1] = (diffraction_integrated_specular_colour(cos θ, F²), 0)
//   probe_out[4i + 2] = (diffraction_integrated_colour_filtered(ω_i, ω_r, σ_uv, σ_m², F²), 0)
//   probe_out[4i + 3]   unused

@group(3) @binding(0) var<storage, read> probe_in: array<vec4<f32>>;
@group(3) @binding(1) var<storage, read_write> probe_out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn diffraction_integrated_probe(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if 3u * i + 2u >= arrayLength(&probe_in) || 4u * i + 2u >= arrayLength(&probe_out) {
        return;
    }
    let a = probe_in[3u * i];
    let b = probe_in[3u * i + 1u];
    let c = probe_in[3u * i + 2u];
    let kind = select(0u, 1u, a.w > 0.5);
    probe_out[4u * i] = vec4<f32>(diffraction_integrated_colour(a.xyz, b.xyz, kind, c.xy), 0.0);
    probe_out[4u * i + 1u] = vec4<f32>(diffraction_integrated_specular_colour(c.z, kind, c.xy), 0.0);
    probe_out[4u * i + 2u] = vec4<f32>(diffraction_integrated_colour_filtered(a.xyz, b.xyz, b.w, c.w, kind, c.xy), 0.0);
}
