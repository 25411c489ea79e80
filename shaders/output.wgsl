// nacre · shaders/output.wgsl — display output: tone mapping and sRGB encoding
// import: (none)
//
// What the consumers that write an Rgba8Unorm target share (material.wgsl for the analytic
// scenes and glTF meshes, diffraction_scene.wgsl for the diffraction scenes): two tone
// mappers and the sRGB transfer function. No bindings; each consumer applies its own exposure
// and guards (they differ) before calling these.
//
// Tone mappers (linear in, linear out)
//
//   tone_map_pbr_neutral   Khronos PBR Neutral (KhronosGroup/ToneMapping, PBR_Neutral, 2024),
//                          used by material.wgsl. With x = min channel,
//                            offset = x − 6.25 x² if x < 0.08, else 0.04;  c ← c − offset
//                            p = max channel; identity when p < K_s = 0.8 − 0.04
//                            d = 1 − K_s;  p_n = 1 − d² / (p + d − K_s)
//                            g = 1 − 1 / (K_d (p − p_n) + 1),  K_d = 0.15
//                            out = mix(c · p_n / p, (p_n, p_n, p_n), g)
//                          hue-preserving, identity below 0.76 apart from the small black
//                          offset; output in [0, 1].
//   tone_map_max_channel   c / (1 + max(c.r, c.g, c.b)): Reinhard on the largest channel
//                          (hue-preserving), used by diffraction_scene.wgsl; for c ≥ 0 the
//                          output is in [0, 1).
//
// sRGB encoding (IEC 61966-2-1), linear → encoded:
//
//   srgb_transfer(c)  = 12.92 c                   if c ≤ 0.0031308
//                       1.055 c^(1/2.4) − 0.055   otherwise
//                       (per channel, for c already in [0, 1]; no clamp)
//   srgb_encode(c)    = srgb_transfer(clamp(c, 0, 1))

// Khronos PBR Neutral tone mapping (KhronosGroup/ToneMapping, PBR_Neutral; linear in,
// linear out, [0, 1]): hue-preserving, identity below 0.76 apart from a small black offset.
fn tone_map_pbr_neutral(colour: vec3<f32>) -> vec3<f32> {
    let start_compression = 0.8 - 0.04;
    let desaturation = 0.15;
    var c = colour;
    let x = min(c.r, min(c.g, c.b));
    let offset = select(0.04, x - 6.25 * x * x, x < 0.08);
    c -= offset;
    let peak = max(c.r, max(c.g, c.b));
    if peak < start_compression {
        return c;
    }
    let d = 1.0 - start_compression;
    let new_peak = 1.0 - d * d / (peak + d - start_compression);
    c *= new_peak / peak;
    let g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(c, vec3<f32>(new_peak), g);
}

// c / (1 + max channel): Reinhard on the largest channel (hue-preserving); c ≥ 0, finite.
fn tone_map_max_channel(c: vec3<f32>) -> vec3<f32> {
    let peak = max(c.r, max(c.g, c.b));
    return c / (1.0 + peak);
}

// The sRGB transfer function (IEC 61966-2-1) on a colour already in [0, 1].
fn srgb_transfer(c: vec3<f32>) -> vec3<f32> {
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, c <= vec3<f32>(0.0031308));
}

// The sRGB transfer function (IEC 61966-2-1), linear [0, 1] → encoded [0, 1] (clamped first).
fn srgb_encode(linear: vec3<f32>) -> vec3<f32> {
    let c = clamp(linear, vec3<f32>(0.0), vec3<f32>(1.0));
    return srgb_transfer(c);
}
