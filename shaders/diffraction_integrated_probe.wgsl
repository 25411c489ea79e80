// nacre · shaders/diffraction_integrated_probe.wgsl
// import: diffraction_integrated
//
// The GPU = CPU probe of the layout "integrated" (compute; composed after
// diffraction_integrated.wgsl by `nacre_runtime::diffraction_integrated::run_probe`).
// Group 0 is empty, group 1 the technique, group 2 unused, group 3 the probe's buffers.
//
// Input i (three vec4 per case):
//   probe_in[3i]     = (ω_i.xyz, F² kind as a float: 0 or 1)    grating frame, any values
//   probe_in[3i + 1] = (ω_r.xyz, 0)
//   probe_in[3i + 2] = (n, κ of the Fresnel index, cos θ of the specular-colour call, 0)
// Output i (two vec4):
//   probe_out[2i]     = (diffraction_integrated_colour(ω_i, ω_r, F²), 0)
//   probe_out[2i + 1] = (diffraction_integrated_specular_colour(cos θ, F²), 0)

@group(3) @binding(0) var<storage, read> probe_in: array<vec4<f32>>;
@group(3) @binding(1) var<storage, read_write> probe_out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn diffraction_integrated_probe(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if 3u * i + 2u >= arrayLength(&probe_in) || 2u * i + 1u >= arrayLength(&probe_out) {
        return;
    }
    let a = probe_in[3u * i];
    let b = probe_in[3u * i + 1u];
    let c = probe_in[3u * i + 2u];
    let kind = select(0u, 1u, a.w > 0.5);
    probe_out[2u * i] = vec4<f32>(diffraction_integrated_colour(a.xyz, b.xyz, kind, c.xy), 0.0);
    probe_out[2u * i + 1u] = vec4<f32>(diffraction_integrated_specular_colour(c.z, kind, c.xy), 0.0);
}
