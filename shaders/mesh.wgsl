// nacre · shaders/mesh.wgsl — consumer: rasterised triangle meshes (glTF scenes)
// import: material
//
// A vertex shader (`mesh_vs`) that projects world-space vertices (the runtime applies the glTF
// node transforms on the CPU) with MeshParams.view_proj, and a fragment shader (`mesh_fs`)
// that reads the glTF 2.0 metallic-roughness material of the primitive — factors × textures ×
// vertex colour — and shades each fragment with material.wgsl's `material_shade_with`, then
// writes the tone-mapped, sRGB-encoded colour to an Rgba8Unorm target with a Depth32Float
// depth buffer (compare `less`). Composed after material.wgsl (crates/runtime/src/mesh.rs:
// `shaders::compose(technique, &[MATERIAL, MESH])`); scene.wgsl is the ray-cast alternative
// for the analytic scenes.
//
// The material (glTF 2.0 specification §3.9 "Materials" and Appendix B; the KHR extension
// specifications named):
//
//   baseColor   = baseColorFactor × baseColorTexture (sRGB-decoded by the Rgba8UnormSrgb
//                 format) × COLOR_0
//   metallic    = metallicFactor × metallicRoughnessTexture.b
//   roughness   = roughnessFactor × metallicRoughnessTexture.g,   GGX α = roughness²
//   n           = normalize(TBN (normalTexture.rgb × 2 − 1) × (scale, scale, 1)), TBN from
//                 TANGENT (xyz, w = bitangent sign) or MikkTSpace tangents made by the runtime
//   occlusion   = 1 + occlusionStrength (occlusionTexture.r − 1), on the environment only
//   emission    = emissiveFactor × emissiveStrength (KHR_materials_emissive_strength) ×
//                 emissiveTexture (sRGB), added to the radiance
//   alpha       = baseColor.a: MASK discards below alphaCutoff, BLEND outputs it (the
//                 pipeline blends src-alpha over what is behind), OPAQUE ignores it
//   film weight = iridescenceFactor × iridescenceTexture.r (KHR_materials_iridescence)
//   g           = iridescenceThicknessTexture.g → d = mix(d_min, d_max, g) (group 2's map)
//   specular    = specularFactor × specularTexture.a, × specularColorFactor ×
//                 specularColorTexture (sRGB) (KHR_materials_specular): the dielectric lobe's
//                 reflectance scale (material.wgsl, SurfaceMaterial)
//   clear coat  = KHR_materials_clearcoat: c = clearcoatFactor × clearcoatTexture.r,
//                 r_c = clearcoatRoughnessFactor × clearcoatRoughnessTexture.g (α_c = r_c²),
//                 n_c = the geometric normal, or clearcoatNormalTexture's (scaled) in the same
//                 tangent frame; the whole material below it (film, lobes, emission,
//                 transmission) is seen through it (the extension's "Layering"):
//                   L = L_base (1 − c F_c) + c L_coat,  F_c = 0.04 + 0.96 (1 − n_c·v)⁵
//                 (Schlick, coat index 1.5), L_coat the coat's GGX lobe of F0 = 0.04:
//                 per light D V F_schlick(v·h) E n_c·l, and from the environment the
//                 prefiltered radiance towards reflect(−v, n_c) at α_c times
//                 0.04 E₁ + 0.96 E₅ (split-sum paths: E₁ the F = 1 albedo, E₅ its (1 − v·h)⁵-
//                 weighted part, env_ggx_albedo .r and .g) or F_c (1 − 0.55 √α_c) (classic
//                 path: the box mip chain at α_c's level); occlusion applies to the
//                 environment's share. The coat's textures take slots the material leaves
//                 empty (coat_slots: crates/runtime/src/mesh/textures.rs coat_slots).
//   metal lobe  = the complex index whose normal-incidence reflectance is baseColor, per
//                 channel, with edge tint = baseColor (Gulbrandsen 2014, Eq. 1–2; the same
//                 inversion as crates/runtime/src/gltf_scene.rs metal_index_gulbrandsen2014)
//
// Texture coordinates: each texture reads TEXCOORD_0 or TEXCOORD_1 through its
// KHR_texture_transform, uv' = (a u + b v + c, d u + e v + f) (MeshParams.transforms).
//
// Transmission (KHR_materials_transmission, KHR_materials_volume): as the glTF Sample Viewer
// does, the runtime first draws every non-transmissive primitive into a linear-radiance
// picture of the scene (flag MESH_FLAG_LINEAR_OUTPUT), then draws the whole scene; a
// transmissive fragment adds T_f · baseColor · L_behind, L_behind the picture's radiance
// where the refracted ray leaves the volume (mesh_behind; the environment where the picture
// shows nothing). Neither the picture's blur by roughness nor transmissive surfaces behind
// transmissive ones are modelled.
//
// Coated glass (technique `glass`, crates/runtime/src/mesh/materials.rs glass_setup): a
// transmissive dielectric material is drawn by film_glass.wgsl with its own stack — air |
// the iridescence film (iridescenceIor, d from the thickness mapping) | an incoherent clear
// slab of index `ior` (thicknessFactor thick; thin-walled: 0) | air — so that R and T of the
// film_colour call are the whole pane's, both faces summed in intensity; the film-free share
// of w < 1 is the uncoated pane (MESH_FLAG_GLASS). mesh_behind then refracts and attenuates
// (attenuationColor over the path inside the volume) as for every transmissive material.
//
// Double-sided: the shading normal faces the viewer (a back face's normal and tangent frame
// are reversed, as glTF prescribes); single-sided materials are culled by the pipeline.
//
// Bind groups: 0 view, 1 technique, 2 material (material.wgsl), 3 the primitive's glTF
// material (MeshParams, 8 textures and their samplers, and at binding 17 the scene behind):
//
// 480 bytes, uniform (mirrored by `MeshUniform` in crates/runtime/src/mesh.rs):
//
//   offset size field
//        0   64 view_proj: mat4x4<f32>     world → clip (x, y ∈ [−1, 1], z ∈ [0, 1] near → far)
//       64   16 base_colour: vec4<f32>     baseColorFactor (linear RGBA)
//       80   12 emissive: vec3<f32>        emissiveFactor × emissiveStrength
//       92    4 metallic: f32              metallicFactor
//       96   12 specular_colour: vec3<f32> specularColorFactor
//      108    4 roughness: f32             roughnessFactor
//      112    4 specular: f32              specularFactor
//      116    4 normal_scale: f32          normalTexture.scale
//      120    4 occlusion_strength: f32    occlusionTexture.strength
//      124    4 alpha_cutoff: f32          alphaCutoff (MASK)
//      128    4 dielectric_ior: f32        ior (KHR_materials_ior)
//      132    4 iridescence: f32           iridescenceFactor
//      136    4 alpha_mode: u32            0 OPAQUE, 1 MASK, 2 BLEND
//      140    4 flags: u32                 bit 0: a normal texture is bound; MESH_FLAG_*
//      144    4 transmission: f32          transmissionFactor: the transmitting share of the
//                                          dielectric lobe
//      148    4 lobes: u32                 0 dielectric lobe only, 1 metal only, 2 both
//      152    4 volume_thickness: f32      thicknessFactor (KHR_materials_volume), world units
//      156    4 attenuation_distance: f32  attenuationDistance (0: no attenuation)
//      160   16 attenuation_colour: vec4   attenuationColor (rgb)
//      176    4 clearcoat: f32             clearcoatFactor (0: no coat)
//      180    4 clearcoat_roughness: f32   clearcoatRoughnessFactor
//      184    4 clearcoat_normal_scale: f32  clearcoatNormalTexture.scale
//      188    4 coat_slots: u32            the slots of clearcoatTexture, …RoughnessTexture,
//                                          …NormalTexture in bits 0–3, 4–7, 8–11 (15: none);
//                                          bits 16–23: slots lent to the coat (their own role
//                                          reads white)
//      192  288 transforms: array<TexTransform, 9>  per slot (MESH_TEX_*): rows (a, b, c, set),
//                                                     (d, e, f, 0)
struct TexTransform {
    row0: vec4<f32>,
    row1: vec4<f32>,
}

struct MeshParams {
    view_proj: mat4x4<f32>,
    base_colour: vec4<f32>,
    emissive: vec3<f32>,
    metallic: f32,
    specular_colour: vec3<f32>,
    roughness: f32,
    specular: f32,
    normal_scale: f32,
    occlusion_strength: f32,
    alpha_cutoff: f32,
    dielectric_ior: f32,
    iridescence: f32,
    alpha_mode: u32,
    flags: u32,
    transmission: f32,
    lobes: u32,
    volume_thickness: f32,
    attenuation_distance: f32,
    attenuation_colour: vec4<f32>,
    clearcoat: f32,
    clearcoat_roughness: f32,
    clearcoat_normal_scale: f32,
    coat_slots: u32,
    transforms: array<TexTransform, 9>,
}

// Texture slots (bindings 1 + 2 k texture, 2 + 2 k sampler); slot 8 (the thickness texture,
// bound in group 2) has a transform only.
const MESH_TEX_BASE: u32 = 0u;
const MESH_TEX_METAL_ROUGH: u32 = 1u;
const MESH_TEX_NORMAL: u32 = 2u;
const MESH_TEX_OCCLUSION: u32 = 3u;
const MESH_TEX_EMISSIVE: u32 = 4u;
const MESH_TEX_IRIDESCENCE: u32 = 5u;
const MESH_TEX_SPECULAR: u32 = 6u;
const MESH_TEX_SPECULAR_COLOUR: u32 = 7u;
const MESH_TEX_THICKNESS: u32 = 8u;
const MESH_ALPHA_MASK: u32 = 1u;
const MESH_ALPHA_BLEND: u32 = 2u;
const MESH_FLAG_NORMAL_MAP: u32 = 1u;
// The draw writes linear radiance (the scene behind transmissive surfaces), not display colour.
const MESH_FLAG_LINEAR_OUTPUT: u32 = 2u;
// mesh_behind_tex holds the opaque scene's linear radiance (alpha 0 where nothing was drawn).
const MESH_FLAG_BEHIND: u32 = 4u;
// KHR_materials_unlit: the colour is base colour × texture × COLOR_0, unlit, without film.
const MESH_FLAG_UNLIT: u32 = 8u;
// Drawn by film_glass as a coated pane (crates/runtime/src/mesh/materials.rs glass_setup): the
// film-free share of a film weight w < 1 is the uncoated pane (SurfaceMaterial.bare_pane).
const MESH_FLAG_GLASS: u32 = 16u;
// Set by the pipeline (mesh/pipeline.rs Raster) for lines and points without normals: drawn
// unlit in their base colour, as KHR_materials_unlit draws (a line or point has no surface).
override MESH_PRIMITIVE_UNLIT: bool = false;
// MeshParams.coat_slots: no texture.
const MESH_COAT_SLOT_NONE: u32 = 15u;
// The clear coat's index 1.5: F0 = ((1.5 − 1)/(1.5 + 1))² (KHR_materials_clearcoat).
const MESH_COAT_F0: f32 = 0.04;

@group(3) @binding(0) var<uniform> mesh_params: MeshParams;
@group(3) @binding(1) var mesh_base_tex: texture_2d<f32>;
@group(3) @binding(2) var mesh_base_smp: sampler;
@group(3) @binding(3) var mesh_mr_tex: texture_2d<f32>;
@group(3) @binding(4) var mesh_mr_smp: sampler;
@group(3) @binding(5) var mesh_normal_tex: texture_2d<f32>;
@group(3) @binding(6) var mesh_normal_smp: sampler;
@group(3) @binding(7) var mesh_occlusion_tex: texture_2d<f32>;
@group(3) @binding(8) var mesh_occlusion_smp: sampler;
@group(3) @binding(9) var mesh_emissive_tex: texture_2d<f32>;
@group(3) @binding(10) var mesh_emissive_smp: sampler;
@group(3) @binding(11) var mesh_iridescence_tex: texture_2d<f32>;
@group(3) @binding(12) var mesh_iridescence_smp: sampler;
@group(3) @binding(13) var mesh_specular_tex: texture_2d<f32>;
@group(3) @binding(14) var mesh_specular_smp: sampler;
@group(3) @binding(15) var mesh_specular_colour_tex: texture_2d<f32>;
@group(3) @binding(16) var mesh_specular_colour_smp: sampler;
// The opaque scene's linear radiance, read with textureLoad (no sampler).
@group(3) @binding(17) var mesh_behind_tex: texture_2d<f32>;

struct MeshVertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) tangent: vec4<f32>,
    @location(3) uv0: vec2<f32>,
    @location(4) uv1: vec2<f32>,
    @location(5) colour: vec4<f32>,
}

@vertex
fn mesh_vs(
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) tangent: vec4<f32>,
    @location(3) uv0: vec2<f32>,
    @location(4) uv1: vec2<f32>,
    @location(5) colour: vec4<f32>,
) -> MeshVertexOut {
    var out: MeshVertexOut;
    out.clip = mesh_params.view_proj * vec4<f32>(position, 1.0);
    out.world = position;
    out.normal = normal;
    out.tangent = tangent;
    out.uv0 = uv0;
    out.uv1 = uv1;
    out.colour = colour;
    return out;
}

// The coordinates of texture slot k: its set through its KHR_texture_transform (non-finite →
// (0, 0)).
fn mesh_uv(k: u32, uv0: vec2<f32>, uv1: vec2<f32>) -> vec2<f32> {
    let t = mesh_params.transforms[k];
    let uv = vec3<f32>(select(uv0, uv1, t.row0.w > 0.5), 1.0);
    let out = vec2<f32>(dot(t.row0.xyz, uv), dot(t.row1.xyz, uv));
    return select(vec2<f32>(0.0), out, vec3_is_finite(vec3<f32>(out, 0.0)).xy);
}

// The complex index n + iκ (returned as (n, κ) per channel in two vectors) whose
// normal-incidence reflectance from air is r = F0 with edge tint g = F0: Gulbrandsen 2014,
// "Artist Friendly Metallic Fresnel", JCGT 3(4), Eq. 1–2 (r clamped to [0, 0.99]).
struct MetalIndex {
    n: vec3<f32>,
    kappa: vec3<f32>,
}

fn mesh_metal_index(f0: vec3<f32>) -> MetalIndex {
    let r = clamp(select(vec3<f32>(0.5), f0, vec3_is_finite(f0)), vec3<f32>(0.0), vec3<f32>(0.99));
    let g = r;
    let sr = sqrt(r);
    let n = g * (1.0 - r) / (1.0 + r) + (1.0 - g) * (1.0 + sr) / (1.0 - sr);
    let k2 = (r * (n + 1.0) * (n + 1.0) - (n - 1.0) * (n - 1.0)) / (1.0 - r);
    return MetalIndex(max(n, vec3<f32>(1e-3)), sqrt(max(k2, vec3<f32>(0.0))));
}

// The picture of the opaque scene at uv ∈ [0, 1]² and mip level `lod` (fractional): bilinear
// within the two nearest levels of its box-filtered chain (mip_down.wgsl), linear between
// them, by textureLoad (the binding is a non-filterable float texture; no sampler).
fn mesh_behind_sample(uv: vec2<f32>, lod: f32) -> vec4<f32> {
    // The full chain's last level, ⌊log₂ max(w, h)⌋ (textureNumLevels has no GLSL ES 3.1
    // counterpart).
    let size = textureDimensions(mesh_behind_tex);
    let last_level = f32(firstLeadingBit(max(max(size.x, size.y), 1u)));
    let level = clamp(finite_or(lod, 0.0), 0.0, last_level);
    let l0 = u32(floor(level));
    let l1 = min(l0 + 1u, u32(last_level));
    return mix(mesh_behind_bilinear(uv, l0), mesh_behind_bilinear(uv, l1), level - floor(level));
}

// Level `level` of the picture at uv, bilinear between its four nearest texels (clamped to
// the edge).
fn mesh_behind_bilinear(uv: vec2<f32>, level: u32) -> vec4<f32> {
    let size = vec2<i32>(textureDimensions(mesh_behind_tex, level));
    let p = clamp(uv, vec2<f32>(0.0), vec2<f32>(1.0)) * vec2<f32>(size) - 0.5;
    let f = p - floor(p);
    let lo = clamp(vec2<i32>(floor(p)), vec2<i32>(0), size - 1);
    let hi = clamp(vec2<i32>(floor(p)) + 1, vec2<i32>(0), size - 1);
    let l = i32(level);
    let top = mix(textureLoad(mesh_behind_tex, lo, l), textureLoad(mesh_behind_tex, vec2<i32>(hi.x, lo.y), l), f.x);
    let bottom = mix(textureLoad(mesh_behind_tex, vec2<i32>(lo.x, hi.y), l), textureLoad(mesh_behind_tex, hi, l), f.x);
    return mix(top, bottom, f.y);
}

// What a transmissive surface at `world` (shading normal n, view direction v, dielectric
// index `ior`) lets through from behind it, before its own transmittance and colour: the glTF
// Sample Viewer's screen-space refraction (KHR_materials_transmission with
// KHR_materials_volume). The refracted ray d = refract(−v, n, 1/ior) leaves the volume at
// world + d · thickness (thin-walled, thickness 0: straight through, d = −v); the opaque
// scene's radiance at that point's pixel, or the environment along d where the scene shows
// nothing, attenuated by Beer–Lambert over the path inside, c^(thickness / distance)
// (KHR_materials_volume attenuationColor c, attenuationDistance; 0 = none).
// Rough surfaces see it blurred, as the glTF Sample Viewer draws them: at mip
// level log₂(width) · r · clamp(2 ior − 2, 0, 1) of the picture (r the perceptual roughness).
fn mesh_behind(world: vec3<f32>, n: vec3<f32>, v: vec3<f32>, ior: f32, roughness: f32) -> vec3<f32> {
    let q = mesh_params;
    let thickness = max(finite_or(q.volume_thickness, 0.0), 0.0);
    let bent = refract(-v, n, 1.0 / max(ior, 1.0));
    let d = select(-v, safe_normalize(bent, -v), thickness > 0.0 && dot(bent, bent) > 0.0);
    let exit = world + d * thickness;
    var behind = env_radiance(d, 0.0);
    if (q.flags & MESH_FLAG_BEHIND) != 0u {
        let clip = q.view_proj * vec4<f32>(exit, 1.0);
        if clip.w > 0.0 && f32_is_finite(clip.x / clip.w) && f32_is_finite(clip.y / clip.w) {
            let ndc = clip.xy / clip.w;
            let width = f32(textureDimensions(mesh_behind_tex).x);
            let lod = log2(width) * clamp(roughness, 0.0, 1.0) * clamp(2.0 * ior - 2.0, 0.0, 1.0);
            let uv = vec2<f32>(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y);
            let scene = mesh_behind_sample(uv, lod);
            // Premultiplied: the scene's radiance where it covers, the environment elsewhere.
            let coverage = clamp(finite_or(scene.a, 0.0), 0.0, 1.0);
            behind = behind * (1.0 - coverage) + sanitize_radiance(scene.rgb);
        }
    }
    let distance = finite_or(q.attenuation_distance, 0.0);
    if distance > 0.0 && thickness > 0.0 {
        let c = clamp(select(vec3<f32>(1.0), q.attenuation_colour.rgb, vec3_is_finite(q.attenuation_colour.rgb)), vec3<f32>(0.0), vec3<f32>(1.0));
        behind *= pow(c, vec3<f32>(thickness / distance));
    }
    return behind;
}

// Slot k's sample among the eight (k ≥ 8: white).
fn mesh_slot_sample(k: u32, s0: vec4<f32>, s1: vec4<f32>, s2: vec4<f32>, s3: vec4<f32>, s4: vec4<f32>, s5: vec4<f32>, s6: vec4<f32>, s7: vec4<f32>) -> vec4<f32> {
    var out = vec4<f32>(1.0);
    out = select(out, s0, k == 0u);
    out = select(out, s1, k == 1u);
    out = select(out, s2, k == 2u);
    out = select(out, s3, k == 3u);
    out = select(out, s4, k == 4u);
    out = select(out, s5, k == 5u);
    out = select(out, s6, k == 6u);
    out = select(out, s7, k == 7u);
    return out;
}

// What slot k's own role reads: its sample, or white where the slot is lent to the coat.
fn mesh_own(k: u32, sample: vec4<f32>) -> vec4<f32> {
    return select(sample, vec4<f32>(1.0), ((mesh_params.coat_slots >> (16u + k)) & 1u) != 0u);
}

// Normal n perturbed by a tangent-space normal texture's texel (rgb), scale s on x and y, in
// the tangent frame (t, b) of the fragment (already turned towards the viewer).
fn mesh_perturb(n: vec3<f32>, t: vec3<f32>, b: vec3<f32>, texel: vec3<f32>, s: f32) -> vec3<f32> {
    let m = (texel * 2.0 - 1.0) * vec3<f32>(s, s, 1.0);
    return safe_normalize(m.x * t + m.y * b + m.z * n, n);
}

// The clear coat's own radiance L_coat (header): its GGX lobe (F0 = 0.04, F90 = 1) of
// normal n_c and roughness α_c under every light and the environment (× occlusion).
fn mesh_coat_radiance(world: vec3<f32>, n_c: vec3<f32>, v: vec3<f32>, alpha_c: f32, occlusion: f32) -> vec3<f32> {
    let alpha = clamp(finite_or(alpha_c, 0.0), MATERIAL_ALPHA_MIN, 1.0);
    let n_dot_v = clamp(dot(n_c, v), MATERIAL_COS_MIN, 1.0);
    let r = reflect(-v, n_c);
    var env: vec3<f32>;
    if material_params.film_eval == MATERIAL_FILM_EVAL_CLASSIC {
        let fresnel = MESH_COAT_F0 + (1.0 - MESH_COAT_F0) * pow(1.0 - n_dot_v, 5.0);
        env = env_radiance(r, env_specular_lod(alpha)) * fresnel * ggx_albedo_scale(alpha);
    } else {
        // Split sum: L̃(r, α_c) (F0 E₁ + (1 − F0) E₅).
        let t = clamp(vec2<f32>(n_dot_v, alpha), vec2<f32>(0.0), vec2<f32>(1.0));
        let uv = (t * (GGX_ALBEDO_SIZE - 1.0) + 0.5) / GGX_ALBEDO_SIZE;
        let e = clamp(textureSampleLevel(env_ggx_albedo, env_lut_sampler, uv, 0.0).rg, vec2<f32>(0.0), vec2<f32>(1.0));
        env = env_prefiltered_radiance(r, alpha) * (MESH_COAT_F0 * e.x + (1.0 - MESH_COAT_F0) * e.y);
    }
    var out = env * clamp(finite_or(occlusion, 1.0), 0.0, 1.0);
    let light_slots = 1u + min(view.light_count, VIEW_MAX_LIGHTS);
    for (var j = 0u; j < light_slots; j++) {
        let light = material_light_sample(j, world);
        let n_dot_l = dot(n_c, light.towards);
        let h = safe_normalize(v + light.towards, n_c);
        let fresnel = MESH_COAT_F0 + (1.0 - MESH_COAT_F0) * pow(1.0 - clamp(dot(v, h), 0.0, 1.0), 5.0);
        let f = ggx_distribution(dot(n_c, h), alpha) * ggx_visibility(n_dot_v, max(n_dot_l, 0.0), alpha) * fresnel;
        out += select(vec3<f32>(0.0), f * light.irradiance * n_dot_l, n_dot_l > 0.0);
    }
    return sanitize_radiance(out);
}

@fragment
fn mesh_fs(in: MeshVertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let q = mesh_params;
    // Every texture is sampled first, in uniform control flow (implicit derivatives).
    let slot0 = textureSample(mesh_base_tex, mesh_base_smp, mesh_uv(MESH_TEX_BASE, in.uv0, in.uv1));
    let slot1 = textureSample(mesh_mr_tex, mesh_mr_smp, mesh_uv(MESH_TEX_METAL_ROUGH, in.uv0, in.uv1));
    let slot2 = textureSample(mesh_normal_tex, mesh_normal_smp, mesh_uv(MESH_TEX_NORMAL, in.uv0, in.uv1));
    let slot3 = textureSample(mesh_occlusion_tex, mesh_occlusion_smp, mesh_uv(MESH_TEX_OCCLUSION, in.uv0, in.uv1));
    let slot4 = textureSample(mesh_emissive_tex, mesh_emissive_smp, mesh_uv(MESH_TEX_EMISSIVE, in.uv0, in.uv1));
    let slot5 = textureSample(mesh_iridescence_tex, mesh_iridescence_smp, mesh_uv(MESH_TEX_IRIDESCENCE, in.uv0, in.uv1));
    let slot6 = textureSample(mesh_specular_tex, mesh_specular_smp, mesh_uv(MESH_TEX_SPECULAR, in.uv0, in.uv1));
    let slot7 = textureSample(mesh_specular_colour_tex, mesh_specular_colour_smp, mesh_uv(MESH_TEX_SPECULAR_COLOUR, in.uv0, in.uv1));
    let base_tex = mesh_own(MESH_TEX_BASE, slot0);
    let mr_tex = mesh_own(MESH_TEX_METAL_ROUGH, slot1);
    let normal_tex = mesh_own(MESH_TEX_NORMAL, slot2);
    let occlusion_tex = mesh_own(MESH_TEX_OCCLUSION, slot3);
    let emissive_tex = mesh_own(MESH_TEX_EMISSIVE, slot4);
    let iridescence_tex = mesh_own(MESH_TEX_IRIDESCENCE, slot5);
    let specular_tex = mesh_own(MESH_TEX_SPECULAR, slot6);
    let specular_colour_tex = mesh_own(MESH_TEX_SPECULAR_COLOUR, slot7);
    // The clear coat's textures, from the slots lent to them (white without).
    let coat_tex = mesh_slot_sample(q.coat_slots & 15u, slot0, slot1, slot2, slot3, slot4, slot5, slot6, slot7);
    let coat_rough_tex = mesh_slot_sample((q.coat_slots >> 4u) & 15u, slot0, slot1, slot2, slot3, slot4, slot5, slot6, slot7);
    let coat_normal_slot = (q.coat_slots >> 8u) & 15u;
    let coat_normal_tex = mesh_slot_sample(coat_normal_slot, slot0, slot1, slot2, slot3, slot4, slot5, slot6, slot7);
    // The thickness texture's (E[g], E[g²]) for the pixel's footprint, then d and σ_d.
    let thickness_uv = mesh_uv(MESH_TEX_THICKNESS, in.uv0, in.uv1);
    let moments = material_sample_thickness_map(thickness_uv, dpdx(thickness_uv), dpdy(thickness_uv));
    let thickness_nm = material_thickness_nm(moments.x, 1.0);
    let sigma_nm = material_thickness_sigma(dpdx(thickness_nm), dpdy(thickness_nm), material_thickness_roughness_nm(moments));

    let colour_ok = all(vec3_is_finite(in.colour.rgb)) && f32_is_finite(in.colour.a);
    let vertex_colour = select(vec4<f32>(1.0), in.colour, colour_ok);
    let base = clamp(q.base_colour * base_tex * vertex_colour, vec4<f32>(0.0), vec4<f32>(1.0));

    let v = safe_normalize(view.eye_position - in.world, vec3<f32>(0.0, 0.0, 1.0));
    let n_raw = safe_normalize(in.normal, v);
    // Double-sided: the shading normal faces the viewer; the tangent frame turns with it.
    let facing = select(1.0, -1.0, dot(n_raw, v) < 0.0);
    let n_geo = n_raw * facing;
    var n = n_geo;
    var n_coat = n_geo;
    let t_raw = in.tangent.xyz - n_geo * dot(n_geo, in.tangent.xyz);
    let t = safe_normalize(t_raw * facing, vec3<f32>(0.0));
    let b = cross(n_raw, t_raw) * select(1.0, -1.0, in.tangent.w < 0.0);
    let tb = safe_normalize(b * facing, vec3<f32>(0.0));
    if dot(t, t) > 0.5 {
        if (q.flags & MESH_FLAG_NORMAL_MAP) != 0u {
            n = mesh_perturb(n_geo, t, tb, normal_tex.rgb, finite_or(q.normal_scale, 1.0));
        }
        if coat_normal_slot != MESH_COAT_SLOT_NONE {
            n_coat = mesh_perturb(n_geo, t, tb, coat_normal_tex.rgb, finite_or(q.clearcoat_normal_scale, 1.0));
        }
    }

    let metallic = clamp(finite_or(q.metallic * mr_tex.b, 0.0), 0.0, 1.0);
    let roughness = clamp(finite_or(q.roughness * mr_tex.g, 1.0), 0.0, 1.0);
    // The metal lobe's index: where the colour is the factor's alone (no texture or vertex
    // colour changes it), the uniform's metal (built per channel where that channel's
    // sensitivity lies: gltf_scene/metal.rs), else Gulbrandsen's fit to the fragment's colour.
    let fitted_metal = mesh_metal_index(base.rgb);
    let from_factor = all(abs(base.rgb - clamp(q.base_colour.rgb, vec3<f32>(0.0), vec3<f32>(1.0))) <= vec3<f32>(1e-6));
    let uniform_metal = material_params.base_kind != MATERIAL_BASE_DIELECTRIC && from_factor;
    let metal = MetalIndex(select(fitted_metal.n, material_params.base_ior, uniform_metal), select(fitted_metal.kappa, material_params.base_kappa, uniform_metal));
    let ior = select(1.5, q.dielectric_ior, f32_is_finite(q.dielectric_ior) && q.dielectric_ior >= 1.0);
    var mat: SurfaceMaterial;
    mat.diffuse_colour = base.rgb;
    mat.metallic = metallic;
    mat.lobes = q.lobes;
    mat.dielectric_ior = vec3<f32>(ior);
    mat.dielectric_kappa = vec3<f32>(0.0);
    mat.metal_ior = metal.n;
    mat.metal_kappa = metal.kappa;
    mat.roughness_alpha = roughness * roughness;
    mat.film_weight = clamp(finite_or(q.iridescence * iridescence_tex.r, 0.0), 0.0, 1.0);
    mat.transmission = clamp(finite_or(q.transmission, 0.0), 0.0, 1.0);
    mat.occlusion = clamp(1.0 + finite_or(q.occlusion_strength, 1.0) * (occlusion_tex.r - 1.0), 0.0, 1.0);
    mat.specular_colour = clamp(q.specular * specular_tex.a * q.specular_colour * specular_colour_tex.rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    mat.bare_pane = select(0u, 1u, (q.flags & MESH_FLAG_GLASS) != 0u);

    var surface: SurfacePoint;
    surface.position = in.world;
    surface.normal = n;
    surface.view_dir = v;
    surface.thickness_nm = thickness_nm;
    surface.sigma_thickness_nm = sigma_nm;
    // The texture's one channel drives every film.
    surface.variation = vec3<f32>(2.0 * moments.x - 1.0);
    let shade = material_shade_with(surface, mat);
    var radiance = shade.radiance + sanitize_radiance(q.emissive * emissive_tex.rgb);
    if any(shade.transmittance > vec3<f32>(0.0)) {
        // glTF's specular BTDF is tinted by the base colour.
        radiance += shade.transmittance * base.rgb * mesh_behind(in.world, n, v, ior, roughness);
    }
    let unlit = (q.flags & MESH_FLAG_UNLIT) != 0u || MESH_PRIMITIVE_UNLIT;
    // The clear coat over everything below it (header).
    let coat = clamp(finite_or(q.clearcoat * coat_tex.r, 0.0), 0.0, 1.0);
    if coat > 0.0 {
        let coat_roughness = clamp(finite_or(q.clearcoat_roughness * coat_rough_tex.g, 0.0), 0.0, 1.0);
        let n_dot_v = clamp(dot(n_coat, v), 0.0, 1.0);
        let fresnel = MESH_COAT_F0 + (1.0 - MESH_COAT_F0) * pow(1.0 - n_dot_v, 5.0);
        radiance = radiance * (1.0 - coat * fresnel) + coat * mesh_coat_radiance(in.world, n_coat, v, coat_roughness * coat_roughness, mat.occlusion);
    }
    if unlit {
        radiance = base.rgb;
    }
    // MASK: below the cutoff the fragment is discarded (after the shading: lavapipe's
    // LLVM back end of Mesa 22 crashed compiling the shading loop after an early discard).
    if q.alpha_mode == MESH_ALPHA_MASK && !(base.a >= q.alpha_cutoff) {
        discard;
    }
    let alpha = select(1.0, base.a, q.alpha_mode == MESH_ALPHA_BLEND);
    if (q.flags & MESH_FLAG_LINEAR_OUTPUT) != 0u {
        return vec4<f32>(sanitize_radiance(radiance), alpha);
    }
    // Unlit: the base colour itself on screen (sRGB-encoded, no exposure or tone mapping).
    let colour = select(material_display(radiance).rgb, srgb_encode(base.rgb), unlit);
    return vec4<f32>(colour, alpha);
}
