//! The glTF textures on the GPU: uploads with mip chains built on the CPU, samplers, and the
//! mip chain of the picture of the opaque scene that transmissive surfaces refract.

use super::{BEHIND_FORMAT, TEXTURE_SLOTS};
use crate::context::GpuContext;
use crate::error::Result;
use crate::gltf_scene::{GltfMaterial, GltfScene, GltfTexture, SamplerSpec, TextureRef, Wrap};
use crate::shaders;

/// A material's textures in group 3's slot order ([`TEXTURE_SLOTS`]), with its
/// `KHR_materials_clearcoat` textures in slots it leaves empty ([`coat_slots`]).
pub(super) fn slots_of(gm: &GltfMaterial) -> [Option<TextureRef>; 8] {
    coat_slots(gm).slots
}

/// [`CoatSlots::slot`] of a coat texture that has no slot: the shader reads 1 (white).
pub const COAT_SLOT_NONE: u32 = 15;

/// Where a material's clearcoat textures are read from. Group 3 holds 8 material textures,
/// and wgpu's GL backend allows 16 sampled textures per shader stage, all of which the mesh
/// pipeline with the `lut` technique uses: instead of new bindings, the coat's textures take
/// slots the material leaves empty (a clearcoat texture that another slot of the material
/// already reads, with the same coordinates, shares that slot).
#[derive(Clone, Debug, PartialEq)]
pub struct CoatSlots {
    /// The textures per slot.
    pub slots: [Option<TextureRef>; 8],
    /// The slot of `clearcoatTexture`, `clearcoatRoughnessTexture`, `clearcoatNormalTexture`
    /// ([`COAT_SLOT_NONE`] where the material has none, or no slot was free).
    pub slot: [u32; 3],
    /// Bit k: slot k holds a coat texture in place of its own role (which reads white).
    pub borrowed: u32,
    /// The coat textures that found no free slot (their names), not read.
    pub dropped: Vec<&'static str>,
}

impl CoatSlots {
    /// `MeshUniform::coat_slots`: the three slots in bits 0–3, 4–7, 8–11, the borrowed
    /// slots' mask in bits 16–23 (`shaders/mesh.wgsl` mesh_coat_slot).
    pub fn packed(&self) -> u32 {
        self.slot[0] | self.slot[1] << 4 | self.slot[2] << 8 | self.borrowed << 16
    }
}

/// The slots of material `gm`'s own textures and of its clearcoat textures.
pub fn coat_slots(gm: &GltfMaterial) -> CoatSlots {
    let t = &gm.textures;
    let mut slots = [
        t.base_colour,
        t.metallic_roughness,
        t.normal,
        t.occlusion,
        t.emissive,
        t.iridescence,
        t.specular,
        t.specular_colour,
    ];
    let mut out = CoatSlots {
        slots,
        slot: [COAT_SLOT_NONE; 3],
        borrowed: 0,
        dropped: Vec::new(),
    };
    let coat = [
        ("clearcoatTexture", t.clearcoat),
        ("clearcoatRoughnessTexture", t.clearcoat_roughness),
        ("clearcoatNormalTexture", t.clearcoat_normal),
    ];
    for (k, (name, texture)) in coat.into_iter().enumerate() {
        let Some(texture) = texture else { continue };
        // The same texture (decoded in the same colour space: `texture` is per decoding)
        // with the same coordinates shares the slot.
        let shared = (0..8).find(|&s| slots[s] == Some(texture));
        // Otherwise the last empty slot (the specular and iridescence slots first).
        let free = || (0..8).rev().find(|&s| slots[s].is_none());
        match shared.or_else(free) {
            Some(s) => {
                if slots[s].is_none() {
                    slots[s] = Some(texture);
                    out.borrowed |= 1 << s;
                }
                out.slot[k] = s as u32;
            }
            None => out.dropped.push(name),
        }
    }
    out.slots = slots;
    out
}

/// A sampler's identity (wrap modes and filters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct SamplerKey([u8; 2], [bool; 4]);

impl SamplerKey {
    fn of(s: SamplerSpec) -> SamplerKey {
        let w = |w: Wrap| w as u8;
        SamplerKey(
            [w(s.wrap[0]), w(s.wrap[1])],
            [s.mag_linear, s.min_linear, s.mip_linear, s.mipmaps],
        )
    }
}

/// A wgpu sampler for a glTF sampler (no mipmaps: the level-0 texels only).
fn create_sampler(device: &wgpu::Device, s: SamplerSpec) -> wgpu::Sampler {
    let address = |w: Wrap| match w {
        Wrap::Repeat => wgpu::AddressMode::Repeat,
        Wrap::Mirror => wgpu::AddressMode::MirrorRepeat,
        Wrap::Clamp => wgpu::AddressMode::ClampToEdge,
    };
    let filter = |linear: bool| {
        if linear {
            wgpu::FilterMode::Linear
        } else {
            wgpu::FilterMode::Nearest
        }
    };
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("glTF sampler"),
        address_mode_u: address(s.wrap[0]),
        address_mode_v: address(s.wrap[1]),
        address_mode_w: wgpu::AddressMode::ClampToEdge,
        mag_filter: filter(s.mag_linear),
        min_filter: filter(s.min_linear),
        mipmap_filter: if s.mip_linear {
            wgpu::MipmapFilterMode::Linear
        } else {
            wgpu::MipmapFilterMode::Nearest
        },
        lod_max_clamp: if s.mipmaps { 32.0 } else { 0.0 },
        ..Default::default()
    })
}

/// sRGB-encoded byte → linear value (IEC 61966-2-1).
fn srgb_to_linear(v: u8) -> f32 {
    let c = f32::from(v) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear value → sRGB-encoded byte.
fn linear_to_srgb(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let e = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (e * 255.0 + 0.5) as u8
}

/// The mip chain of an RGBA8 picture: 2 × 2 box filters (an odd edge repeats its last
/// texel), averaged in linear light for sRGB colour textures (alpha and data linearly).
pub fn rgba8_mip_chain(
    width: u32,
    height: u32,
    rgba: &[u8],
    srgb: bool,
) -> Vec<(u32, u32, Vec<u8>)> {
    let lut: Vec<f32> = (0..=255u8).map(srgb_to_linear).collect();
    let mut levels = vec![(width, height, rgba.to_vec())];
    while let Some((w, h, texels)) = levels.last() {
        let (w, h) = (*w, *h);
        if w == 1 && h == 1 {
            break;
        }
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let mut next = Vec::with_capacity((nw * nh * 4) as usize);
        for y in 0..nh {
            for x in 0..nw {
                for c in 0..4 {
                    let mut sum = 0.0f32;
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let sx = (2 * x + dx).min(w - 1);
                        let sy = (2 * y + dy).min(h - 1);
                        let v = texels[((sy * w + sx) * 4 + c) as usize];
                        sum += if srgb && c < 3 {
                            lut[v as usize]
                        } else {
                            f32::from(v) / 255.0
                        };
                    }
                    let mean = sum / 4.0;
                    next.push(if srgb && c < 3 {
                        linear_to_srgb(mean)
                    } else {
                        (mean * 255.0 + 0.5) as u8
                    });
                }
            }
        }
        levels.push((nw, nh, next));
    }
    levels
}

/// Uploads a glTF texture as `Rgba8UnormSrgb` (colour: the GPU decodes sRGB before
/// filtering) or `Rgba8Unorm` (data), with its full mip chain.
fn upload_rgba8(ctx: &GpuContext, t: &GltfTexture) -> Result<wgpu::Texture> {
    let format = if t.srgb {
        wgpu::TextureFormat::Rgba8UnormSrgb
    } else {
        wgpu::TextureFormat::Rgba8Unorm
    };
    let levels = rgba8_mip_chain(t.width, t.height, &t.rgba, t.srgb);
    crate::gpu::upload_levels(ctx, &t.name, format, 4, &levels)
}

/// The box-filter pass of `shaders/mip_down.wgsl` and its one binding (level k, read).
pub(super) struct MipDown {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

impl MipDown {
    pub(super) fn new(ctx: &GpuContext) -> Result<MipDown> {
        let device = &ctx.device;
        let source = shaders::flatten("mip_down")?;
        let module = shaders::create_module(ctx, "mip_down", &source)?;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mip_down"),
            entries: &[crate::gpu::loaded_texture_entry(0)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mip_down"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = crate::gpu::fullscreen_pipeline(
            device,
            "mip_down",
            &module,
            &pipeline_layout,
            ("mip_down_vs", "mip_down_fs"),
            &[BEHIND_FORMAT],
        );
        Ok(MipDown { layout, pipeline })
    }

    /// Fills levels 1 … `levels` − 1 of a [`BEHIND_FORMAT`] picture, each the 2 × 2 box mean
    /// of the level above; `level(k)` is level k's one-level view.
    pub(super) fn fill(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        level: &dyn Fn(u32) -> wgpu::TextureView,
        levels: u32,
    ) {
        for k in 1..levels {
            let above = level(k - 1);
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("mip_down"),
                layout: &self.layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&above),
                }],
            });
            let target = level(k);
            let mut pass = crate::gpu::begin_pass(
                encoder,
                "mip_down",
                &[crate::gpu::cleared_attachment(
                    &target,
                    wgpu::Color::TRANSPARENT,
                )],
            );
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.draw(0..3, 0..1);
        }
    }
}

/// Group 3 of the mesh pipelines: 0 MeshParams (vertex + fragment), then per texture slot a
/// filterable 2-D texture (1 + 2k) and its sampler (2 + 2k).
pub(super) fn mesh_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let mut entries = vec![wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }];
    for k in 0..TEXTURE_SLOTS.len() as u32 {
        entries.push(crate::gpu::texture_entry(1 + 2 * k));
        entries.push(crate::gpu::sampler_entry(2 + 2 * k));
    }
    // The scene behind (textureLoad: a float texture that need not be filterable).
    entries.push(crate::gpu::loaded_texture_entry(BEHIND_BINDING));
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("mesh material (glTF)"),
        entries: &entries,
    })
}

/// Group 3's binding of the scene behind transmissive surfaces.
const BEHIND_BINDING: u32 = 1 + 2 * TEXTURE_SLOTS.len() as u32;

/// The glTF textures the used materials read, each uploaded once with its mip chain, and a
/// 1 × 1 white texture for the slots a material leaves empty.
pub(super) struct GltfTextures {
    /// Per texture of the file: on the GPU when a used material reads it.
    uploaded: Vec<Option<wgpu::Texture>>,
    white: wgpu::Texture,
}

/// One wgpu sampler per distinct glTF sampler.
pub(super) type Samplers = std::collections::BTreeMap<SamplerKey, wgpu::Sampler>;

impl GltfTextures {
    /// Uploads the textures that the materials `used` read.
    pub(super) fn upload(ctx: &GpuContext, scene: &GltfScene, used: &[usize]) -> Result<Self> {
        let mut needed = vec![false; scene.textures.len()];
        for &i in used {
            for r in slots_of(&scene.materials[i]).into_iter().flatten() {
                if let Some(n) = needed.get_mut(r.texture) {
                    *n = true;
                }
            }
        }
        let mut uploaded = Vec::with_capacity(scene.textures.len());
        for (t, &need) in scene.textures.iter().zip(&needed) {
            uploaded.push(if need {
                Some(upload_rgba8(ctx, t)?)
            } else {
                None
            });
        }
        let white = upload_rgba8(
            ctx,
            &GltfTexture {
                name: "white".into(),
                width: 1,
                height: 1,
                rgba: vec![255; 4],
                srgb: false,
                sampler: SamplerSpec::default(),
            },
        )?;
        Ok(GltfTextures { uploaded, white })
    }

    /// The texture and sampler a slot reads: the file's, or white with the default sampler.
    fn slot(&self, scene: &GltfScene, slot: Option<TextureRef>) -> (&wgpu::Texture, SamplerSpec) {
        slot.and_then(|r| Some((self.uploaded.get(r.texture)?.as_ref()?, r.texture)))
            .map_or((&self.white, SamplerSpec::default()), |(texture, k)| {
                (texture, scene.textures[k].sampler)
            })
    }

    /// The samplers of every slot of the materials `used`.
    pub(super) fn samplers(
        &self,
        device: &wgpu::Device,
        scene: &GltfScene,
        used: &[usize],
    ) -> Samplers {
        let mut samplers = Samplers::new();
        for &i in used {
            for slot in slots_of(&scene.materials[i]) {
                let (_, spec) = self.slot(scene, slot);
                samplers
                    .entry(SamplerKey::of(spec))
                    .or_insert_with(|| create_sampler(device, spec));
            }
        }
        samplers
    }

    /// Group 3 of material `gm` ([`mesh_group_layout`]): its `MeshParams` in `uniform`, its
    /// textures and samplers (from `samplers`, which holds every one it reads), and the
    /// picture `behind`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn mesh_group(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        scene: &GltfScene,
        gm: &GltfMaterial,
        samplers: &Samplers,
        uniform: &wgpu::Buffer,
        behind: &wgpu::TextureView,
    ) -> wgpu::BindGroup {
        let mut views = Vec::with_capacity(TEXTURE_SLOTS.len());
        let mut keys = Vec::with_capacity(TEXTURE_SLOTS.len());
        for slot in slots_of(gm) {
            let (texture, spec) = self.slot(scene, slot);
            views.push(texture.create_view(&Default::default()));
            keys.push(SamplerKey::of(spec));
        }
        let mut entries = vec![wgpu::BindGroupEntry {
            binding: 0,
            resource: uniform.as_entire_binding(),
        }];
        for (k, (view, key)) in views.iter().zip(&keys).enumerate() {
            entries.push(wgpu::BindGroupEntry {
                binding: 1 + 2 * k as u32,
                resource: wgpu::BindingResource::TextureView(view),
            });
            entries.push(wgpu::BindGroupEntry {
                binding: 2 + 2 * k as u32,
                resource: wgpu::BindingResource::Sampler(&samplers[key]),
            });
        }
        entries.push(wgpu::BindGroupEntry {
            binding: BEHIND_BINDING,
            resource: wgpu::BindingResource::TextureView(behind),
        });
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mesh material (glTF)"),
            layout,
            entries: &entries,
        })
    }
}
