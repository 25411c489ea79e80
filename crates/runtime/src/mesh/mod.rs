//! The mesh renderer behind `nacre render --gltf`: rasterises a [`GltfScene`] with a depth
//! buffer and shades it with `shaders/material.wgsl` through `shaders/mesh.wgsl`, one
//! material uniform per primitive, the camera fitted to the scene's bounds.
//!
//! Techniques per primitive: `fourier` and `spectral` take any base (the material's index goes
//! to the shader); `glass` draws a transmissive dielectric as a coated pane, the material's own
//! stack in its own pass ([`glass_setup`]), and every other material with `fourier`. A `film-lut` table bakes its base, ambient and index range, so with the
//! `lut` technique a primitive is drawn with the table only when its material matches it —
//! a dielectric of the table's base index (film-dielectric: 1.5), or a gold-coloured metal
//! ([`crate::gltf_scene::is_gold_like`]) with a gold table (film-gold, whose baked base replaces the
//! Gulbrandsen 2014 index) — and its film index and thickness lie in the table; every other
//! primitive falls back to `fourier` (which needs the `fourier` table), and
//! [`MeshRender::notes`] says so.
//!
//! Bind groups: 0 view, 1 technique, 2 material (as the analytic scenes), 3 the mesh pass
//! (`MeshUniform`: view-projection).
//!
//! Files: `inputs.rs` (what a frame reads, loaded before the device: [`RenderInputs`]),
//! `frame.rs` (the GPU side of a frame, pass by pass), `camera.rs` (orbit and file cameras),
//! `lights.rs` (`KHR_lights_punctual`), `materials.rs` (the technique of each material),
//! `pipeline.rs` (the passes and their pipelines), `textures.rs` (glTF textures, samplers
//! and group 3); this file holds the uniform and the entry points ([`render`],
//! [`render_gltf_from`]).

mod camera;
mod frame;
mod inputs;
mod lights;
mod materials;
mod pipeline;
mod textures;

pub use camera::{
    DEFAULT_PITCH_DEG, FIT_FOV_X_DEG, FIT_FOV_Y_DEG, FittedCamera, Orbit, ViewPoint, file_camera,
    fit_camera, orbit_camera, view_camera,
};
pub use frame::MeshCache;
pub use inputs::{RenderInputs, TableFile, load_environment};
pub use lights::scene_lights;
pub use materials::{NM_PER_WORLD_UNIT, glass_setup};
pub use textures::{COAT_SLOT_NONE, CoatSlots, coat_slots, rgba8_mip_chain};

use crate::context::GpuContext;
use crate::error::Result;
use crate::gltf_scene::{
    AlphaMode, GltfMaterial, GltfPrimitive, GltfScene, IDENTITY_TRANSFORM, TextureRef,
};
use crate::image_io::RenderedImage;
use crate::render::SceneOptions;
use crate::shaders::Technique;
use crate::tables::TableSet;
use bytemuck::{Pod, Zeroable};
use nacre_format::param::Msg;

/// Depth buffer format.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Mirror of `MeshParams` (`shaders/mesh.wgsl`): 464 bytes, one per drawn material.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MeshUniform {
    /// World → clip, column-major.
    pub view_proj: [[f32; 4]; 4],
    /// `baseColorFactor`, linear RGBA.
    pub base_colour: [f32; 4],
    /// `emissiveFactor` × `emissiveStrength`.
    pub emissive: [f32; 3],
    /// `metallicFactor`.
    pub metallic: f32,
    /// `specularColorFactor`.
    pub specular_colour: [f32; 3],
    /// `roughnessFactor`.
    pub roughness: f32,
    /// `specularFactor`.
    pub specular: f32,
    /// `normalTexture.scale`.
    pub normal_scale: f32,
    /// `occlusionTexture.strength`.
    pub occlusion_strength: f32,
    /// `alphaCutoff`.
    pub alpha_cutoff: f32,
    /// `ior`.
    pub dielectric_ior: f32,
    /// `iridescenceFactor`.
    pub iridescence: f32,
    /// 0 OPAQUE, 1 MASK, 2 BLEND.
    pub alpha_mode: u32,
    /// Bit 0: a normal texture is bound; [`FLAG_LINEAR_OUTPUT`], [`FLAG_BEHIND`],
    /// [`FLAG_UNLIT`], [`FLAG_GLASS`].
    pub flags: u32,
    /// `transmissionFactor`.
    pub transmission: f32,
    /// The lobes every fragment evaluates: 0 dielectric, 1 metal, 2 both.
    pub lobes: u32,
    /// `KHR_materials_volume` `thicknessFactor` (0: thin-walled).
    pub volume_thickness: f32,
    /// `attenuationDistance` (0: no attenuation).
    pub attenuation_distance: f32,
    /// `attenuationColor` (rgb; w unused).
    pub attenuation_colour: [f32; 4],
    /// `KHR_materials_clearcoat` `clearcoatFactor` (0: no coat).
    pub clearcoat: f32,
    /// `clearcoatRoughnessFactor`.
    pub clearcoat_roughness: f32,
    /// `clearcoatNormalTexture.scale`.
    pub clearcoat_normal_scale: f32,
    /// The slots of the coat's textures and the borrowed slots ([`CoatSlots::packed`]).
    pub coat_slots: u32,
    /// Per texture slot ([`TEXTURE_SLOTS`] and the thickness texture): rows (a, b, c, set),
    /// (d, e, f, 0) of its `KHR_texture_transform`.
    pub transforms: [[[f32; 4]; 2]; 9],
}

/// [`MeshUniform::flags`]: the draw writes linear radiance (the scene behind transmissive
/// surfaces) instead of display colour (`shaders/mesh.wgsl` MESH_FLAG_LINEAR_OUTPUT).
pub const FLAG_LINEAR_OUTPUT: u32 = 2;

/// [`MeshUniform::flags`]: binding 17 holds the opaque scene's linear radiance
/// (`shaders/mesh.wgsl` MESH_FLAG_BEHIND).
pub const FLAG_BEHIND: u32 = 4;

/// [`MeshUniform::flags`]: the material is `KHR_materials_unlit` (`shaders/mesh.wgsl`
/// MESH_FLAG_UNLIT).
pub const FLAG_UNLIT: u32 = 8;

/// [`MeshUniform::flags`]: the material is drawn by `film_glass` as a coated pane
/// ([`glass_setup`]); its film-free share is the uncoated pane (`shaders/mesh.wgsl`
/// MESH_FLAG_GLASS).
pub const FLAG_GLASS: u32 = 16;

/// Format of the picture of the opaque scene that transmissive surfaces refract.
pub const BEHIND_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The texture slots of group 3 (`shaders/mesh.wgsl` MESH_TEX_*), in binding order.
pub const TEXTURE_SLOTS: [&str; 8] = [
    "baseColorTexture",
    "metallicRoughnessTexture",
    "normalTexture",
    "occlusionTexture",
    "emissiveTexture",
    "iridescenceTexture",
    "specularTexture",
    "specularColorTexture",
];

impl MeshUniform {
    /// The uniform of glTF material `m` seen through `view_proj`.
    pub fn new(view_proj: [[f32; 4]; 4], m: &GltfMaterial) -> MeshUniform {
        let t = &m.textures;
        let coat = textures::coat_slots(m);
        let in_order = coat.slots;
        let slots: [Option<TextureRef>; 9] =
            std::array::from_fn(|k| in_order.get(k).copied().unwrap_or(t.thickness));
        let transforms = slots.map(|slot| {
            let r = slot.unwrap_or(TextureRef {
                texture: 0,
                tex_coord: 0,
                transform: IDENTITY_TRANSFORM,
            });
            let [a, b] = r.transform;
            [
                [a[0], a[1], a[2], r.tex_coord as f32],
                [b[0], b[1], b[2], 0.0],
            ]
        });
        let (alpha_mode, alpha_cutoff) = match m.alpha_mode {
            AlphaMode::Opaque => (0, 0.5),
            AlphaMode::Mask(c) => (1, c),
            AlphaMode::Blend => (2, 0.5),
        };
        MeshUniform {
            view_proj,
            base_colour: m.base_colour,
            emissive: m.emissive,
            metallic: m.metallic,
            specular_colour: m.specular_colour,
            roughness: m.roughness,
            specular: m.specular,
            normal_scale: m.normal_scale,
            occlusion_strength: m.occlusion_strength,
            alpha_cutoff,
            dielectric_ior: m.dielectric_ior(),
            iridescence: m.iridescence.map_or(0.0, |i| i.factor),
            alpha_mode,
            flags: u32::from(t.normal.is_some()) | if m.unlit { FLAG_UNLIT } else { 0 },
            transmission: m.transmission,
            lobes: match m.metallic_range() {
                (_, hi) if hi <= 0.0 => 0,
                (lo, _) if lo >= 1.0 => 1,
                _ => 2,
            },
            volume_thickness: m.volume.map_or(0.0, |v| v.thickness),
            attenuation_distance: m.volume.map_or(0.0, |v| {
                if v.attenuation_distance.is_finite() {
                    v.attenuation_distance
                } else {
                    0.0
                }
            }),
            attenuation_colour: m.volume.map_or([1.0; 4], |v| {
                let [r, g, b] = v.attenuation_colour;
                [r, g, b, 1.0]
            }),
            clearcoat: m.clearcoat.map_or(0.0, |c| c.factor),
            clearcoat_roughness: m.clearcoat.map_or(0.0, |c| c.roughness),
            clearcoat_normal_scale: m.clearcoat.map_or(1.0, |c| c.normal_scale),
            coat_slots: coat.packed(),
            transforms,
        }
    }
}

/// A rendered glTF scene and what the renderer had to approximate.
pub struct MeshRender {
    /// The image.
    pub image: RenderedImage,
    /// Notes (ignored textures, technique fallbacks), one line each; they may quote an
    /// error that names parameters (render them with a [`nacre_format::param::Naming`]).
    pub notes: Vec<Msg>,
}

/// Floats per vertex: position 3, normal 3, tangent 4, TEXCOORD_0 2, TEXCOORD_1 2, COLOR_0 4.
pub const VERTEX_FLOATS: usize = 18;

/// Renders `scene` with `technique` from `tables`. `options` gives the image size, the
/// environment, light, exposure and technique settings (its scene, camera, thickness map and
/// material are not used: the camera is fitted, the materials come from the file).
pub fn render_gltf(
    ctx: &GpuContext,
    tables: &TableSet,
    technique: Technique,
    scene: &GltfScene,
    options: &SceneOptions,
) -> Result<MeshRender> {
    render_gltf_from(ctx, tables, technique, scene, options, ViewPoint::default())
}

/// [`render_gltf`] seen from `view`: an orbit camera around the scene's bounds or one of the
/// file's cameras (an index past the last is an error naming how many the file has).
pub fn render_gltf_from(
    ctx: &GpuContext,
    tables: &TableSet,
    technique: Technique,
    scene: &GltfScene,
    options: &SceneOptions,
    view: ViewPoint,
) -> Result<MeshRender> {
    render(
        ctx,
        tables,
        technique,
        &RenderInputs::load(scene, options, view)?,
    )
}

/// Renders `inputs` (loaded and validated before the device: [`RenderInputs`]) with
/// `technique` from `tables`: uploads them and draws the frame pass by pass (`frame.rs`).
pub fn render(
    ctx: &GpuContext,
    tables: &TableSet,
    technique: Technique,
    inputs: &RenderInputs,
) -> Result<MeshRender> {
    frame::draw(ctx, tables, technique, inputs, &mut MeshCache::default())
}

/// [`render`] keeping the compiled passes in `cache` for the next frame: a frame whose
/// pipelines are those of the last (the same tables, technique and options, the same
/// materials' techniques, bases and states; only the camera, lights, environment or the
/// films' thicknesses and indices changed) compiles nothing. The picture is the same bytes
/// [`render`] gives.
pub fn render_cached(
    ctx: &GpuContext,
    tables: &TableSet,
    technique: Technique,
    inputs: &RenderInputs,
    cache: &mut MeshCache,
) -> Result<MeshRender> {
    frame::draw(ctx, tables, technique, inputs, cache)
}

/// The interleaved vertices of a primitive ([`VERTEX_FLOATS`] floats each).
fn vertex_data(p: &GltfPrimitive) -> Vec<f32> {
    let mut out = Vec::with_capacity(p.positions.len() * VERTEX_FLOATS);
    for k in 0..p.positions.len() {
        let x = p.positions[k];
        let n = p.normals.get(k).copied().unwrap_or([0.0, 1.0, 0.0]);
        let t = p.tangents.get(k).copied().unwrap_or([1.0, 0.0, 0.0, 1.0]);
        let uv = p.uvs.get(k).copied().unwrap_or([0.0; 2]);
        let uv1 = p.uvs1.get(k).copied().unwrap_or(uv);
        let c = p.colours.get(k).copied().unwrap_or([1.0; 4]);
        out.extend_from_slice(&x);
        out.extend_from_slice(&n);
        out.extend_from_slice(&t);
        out.extend_from_slice(&uv);
        out.extend_from_slice(&uv1);
        out.extend_from_slice(&c);
    }
    out
}
