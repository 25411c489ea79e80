// nacre · shaders/view.wgsl — group 0 of every scene: the view and the environment
// import: rough_lut_mapping
//
// What every scene pipeline binds at group 0 (`nacre_runtime::render::view_group_layout`):
// the analytic scenes and glTF meshes (material.wgsl, scene.wgsl, mesh.wgsl) and the
// diffraction scenes (diffraction_scene.wgsl). One uniform (the camera, the exposure, the
// directional light, the environment's intensity, the target size and the scene id) and the
// environment's textures. The diffraction scenes read the uniform, the environment and its
// sampler; the GGX-prefiltered layers, E₁ and the rough-film-lut are 1 × 1 placeholders there
// (and in the classic material path). Composed after rough_lut_mapping.wgsl (RoughLutParams).
//
// ─── Group 0: the view (changes per frame) ───────────────────────────────────────────────
//
// 656 bytes, uniform (mirrored by `ViewUniform` in crates/runtime/src/render/view.rs):
//
//   offset size field
//        0   64 inv_view_proj: mat4x4<f32>    clip (x, y ∈ [−1, 1], z ∈ [0, 1]) → world
//       64   12 eye_position: vec3<f32>       camera position, world units
//       76    4 exposure: f32                 linear factor 2^EV before tone mapping
//       80   12 light_direction: vec3<f32>    unit vector from the surface towards the light
//       92    4 light_intensity: f32          E_l = light_colour × light_intensity: the light's
//                                             irradiance at normal incidence
//       96   12 light_colour: vec3<f32>       linear RGB
//      108    4 env_intensity: f32            scale of the environment radiance
//      112    8 resolution: vec2<f32>         render target size, pixels
//      120    4 scene: u32                    scene.wgsl: 0 sphere, 1 bubble, 2 plane;
//                                             diffraction_scene.wgsl: 0 cd-disc, 1 snake-skin,
//                                             2 the bench pass
//      124    4 env_lod_max: f32              last mip level of env_map (GLSL ES cannot query it)
//      128    4 light_count: u32              how many of `lights` are drawn (≤ VIEW_MAX_LIGHTS)
//      144  512 lights: array<ViewLight, 8>   KHR_lights_punctual lights besides the
//                                             directional one (`LightUniform`, 64 bytes each)

// The most punctual lights a view draws (`MAX_PUNCTUAL_LIGHTS`).
const VIEW_MAX_LIGHTS: u32 = 8u;
const VIEW_LIGHT_DIRECTIONAL: u32 = 0u;
const VIEW_LIGHT_POINT: u32 = 1u;
const VIEW_LIGHT_SPOT: u32 = 2u;

// One KHR_lights_punctual light (`LightUniform`, 64 bytes).
struct ViewLight {
    // World position (point and spot).
    position: vec3<f32>,
    // VIEW_LIGHT_DIRECTIONAL, _POINT or _SPOT.
    kind: u32,
    // Unit direction the light shines along.
    direction: vec3<f32>,
    // 1 / range⁴, 0 for an unlimited range.
    inv_range4: f32,
    // Colour × intensity (lux for a directional light, candela otherwise).
    radiant: vec3<f32>,
    // The spot's angular factor t = clamp(cos θ · cone_scale + cone_offset, 0, 1), drawn as
    // t²; scale 0 and offset 1 for the other kinds.
    cone_scale: f32,
    cone_offset: f32,
}

struct ViewParams {
    inv_view_proj: mat4x4<f32>,
    eye_position: vec3<f32>,
    exposure: f32,
    light_direction: vec3<f32>,
    light_intensity: f32,
    light_colour: vec3<f32>,
    env_intensity: f32,
    resolution: vec2<f32>,
    scene: u32,
    env_lod_max: f32,
    light_count: u32,
    lights: array<ViewLight, 8>,
}

@group(0) @binding(0) var<uniform> view: ViewParams;
// Equirectangular HDR environment, Rgba16Float with a full mip chain. Row 0 is the zenith
// (+y); u = 0.5 looks down −z, u increases towards +x (env_direction_to_uv).
@group(0) @binding(1) var env_map: texture_2d<f32>;
// Linear min/mag/mip; u repeats, v clamps.
@group(0) @binding(2) var env_sampler: sampler;
// The GGX-prefiltered environment of the split sum (Rgba16Float, ENV_PREFILTER_LEVELS array
// layers of one size, layer k = the convolution with GGX of α_k = (k/(L − 1))², n = v = r;
// crates/runtime/src/ibl.rs). Same equirectangular layout and sampler as env_map.
@group(0) @binding(3) var env_prefiltered: texture_2d_array<f32>;
// E₁(μ_o, α): directional albedo of GGX with F = 1 (Rg16Float, GGX_ALBEDO_SIZE², x = μ_o,
// y = α, texel i at t = i/(n − 1), sampled at (t (n − 1) + 0.5)/n; r = E₁).
@group(0) @binding(4) var env_ggx_albedo: texture_2d<f32>;
// Linear, clamp to edge (env_ggx_albedo and the rough-film-lut).
@group(0) @binding(5) var env_lut_sampler: sampler;
// The rough-film-lut's reflected albedo E_r (Rgba16Float; layout and mapping in
// rough_lut_mapping.wgsl, which this module is composed after) and its axes. A 1×1×1
// placeholder unless the exact path is drawn.
@group(0) @binding(6) var env_rough_lut: texture_3d<f32>;
@group(0) @binding(7) var<uniform> env_rough_lut_params: RoughLutParams;
