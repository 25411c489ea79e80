// nacre · shaders/mesh.wgsl — consumer: rasterised triangle meshes (glTF scenes)
// import: material
//
// A vertex shader (`mesh_vs`) that projects world-space vertices (position, normal, uv; the
// runtime applies the glTF node transforms on the CPU) with MeshParams.view_proj, and a
// fragment shader (`mesh_fs`) that shades each fragment with material.wgsl's
// `material_shade` and writes the tone-mapped, sRGB-encoded colour to an Rgba8Unorm target
// with a Depth32Float depth buffer (compare `less`). Composed after material.wgsl
// (crates/runtime/src/mesh.rs: `shaders::compose(technique, &[MATERIAL, MESH])`); scene.wgsl
// is the ray-cast alternative for the analytic scenes.
//
// Symbols
//
//   symbol   code              meaning
//   x        position          world-space vertex position, world units
//   n        normal            world-space unit normal, flipped to face the viewer (meshes
//                              are drawn double-sided, without culling)
//   v        view_dir          unit vector from the fragment towards the eye
//   uv       uv                texture coordinates of the thickness texture (glTF TEXCOORD_n;
//                              (0, 0) = the image's first texel)
//   g        moments.x         thickness-texture value E[g] (its green channel; the runtime
//                              binds a 1×1 map of g = 1 when the material has no texture, so
//                              d = d_max as glTF KHR_materials_iridescence prescribes)
//   d        thickness_nm      mix(d_min, d_max, g) (material_thickness_nm, mode 1)
//   σ_d      sigma_nm          from d's screen-space derivatives and the map's sub-pixel
//                              variance E[g²] − E[g]² (material_thickness_sigma)
//
// Transmission (thin shells, MaterialParams.transmission = 1): the fragment adds
// T_f · L_env(−v), the environment straight behind it (other meshes behind a transparent one
// are not seen: there is no order-independent transparency here).
//
// Bind groups: 0 view, 1 technique, 2 material (material.wgsl), 3 the mesh pass:
//
// 64 bytes, uniform, vertex stage (mirrored by `MeshUniform` in crates/runtime/src/mesh.rs):
//
//   offset size field
//        0   64 view_proj: mat4x4<f32>     world → clip (x, y ∈ [−1, 1], z ∈ [0, 1] near → far)
struct MeshParams {
    view_proj: mat4x4<f32>,
}

@group(3) @binding(0) var<uniform> mesh_params: MeshParams;

struct MeshVertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
}

@vertex
fn mesh_vs(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>, @location(2) uv: vec2<f32>) -> MeshVertexOut {
    var out: MeshVertexOut;
    out.uv = uv;
    out.clip = mesh_params.view_proj * vec4<f32>(position, 1.0);
    out.world = position;
    out.normal = normal;
    return out;
}

@fragment
fn mesh_fs(in: MeshVertexOut) -> @location(0) vec4<f32> {
    let v = safe_normalize(view.eye_position - in.world, vec3<f32>(0.0, 0.0, 1.0));
    let n_raw = safe_normalize(in.normal, v);
    // Double-sided: the shading normal faces the viewer.
    let n = select(n_raw, -n_raw, dot(n_raw, v) < 0.0);
    // The thickness texture's (E[g], E[g²]) for the pixel's footprint (uniform control flow:
    // implicit derivatives), then d and σ_d.
    let moments = material_sample_thickness_map(in.uv, dpdx(in.uv), dpdy(in.uv));
    let thickness_nm = material_thickness_nm(moments.x, 1.0);
    let sigma_nm = material_thickness_sigma(dpdx(thickness_nm), dpdy(thickness_nm), material_thickness_roughness_nm(moments));

    var surface: SurfacePoint;
    surface.normal = n;
    surface.view_dir = v;
    surface.thickness_nm = thickness_nm;
    surface.sigma_thickness_nm = sigma_nm;
    // The texture's one channel drives every film.
    surface.variation = vec3<f32>(2.0 * moments.x - 1.0);
    let shade = material_shade(surface);
    var radiance = shade.radiance;
    if any(shade.transmittance > vec3<f32>(0.0)) {
        radiance += shade.transmittance * env_radiance(-v, 0.0);
    }
    return material_display(radiance);
}
