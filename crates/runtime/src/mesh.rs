//! The mesh renderer behind `nacre render --gltf`: rasterises a [`GltfScene`] with a depth
//! buffer and shades it with `shaders/material.wgsl` through `shaders/mesh.wgsl`, one
//! material uniform per primitive, the camera fitted to the scene's bounds.
//!
//! Techniques per primitive: `fourier` and `spectral` take any base (the material's index goes
//! to the shader). A `film-lut` table bakes its base, ambient and index range, so with the
//! `lut` technique a primitive is drawn with the table only when its material matches it —
//! a dielectric of the table's base index (film-dielectric: 1.5), or a gold-coloured metal
//! ([`is_gold_like`]) with a gold table (film-gold, whose baked base replaces the
//! Gulbrandsen 2014 index) — and its film index and thickness lie in the table; every other
//! primitive falls back to `fourier` (which needs the `fourier` table), and
//! [`MeshRender::notes`] says so.
//!
//! Bind groups: 0 view, 1 technique, 2 material (as the analytic scenes), 3 the mesh pass
//! (`MeshUniform`: view-projection).

use crate::bindings::TechniqueBinding;
use crate::context::BufferInitExt;
use crate::context::GpuContext;
use crate::environment::EnvironmentMap;
use crate::error::{Error, Result};
use crate::gltf_scene::{
    AlphaMode, GltfCamera, GltfMaterial, GltfProjection, GltfScene, GltfTexture,
    IDENTITY_TRANSFORM, LightKind, SamplerSpec, TextureRef, Wrap, is_gold_like,
};
use crate::gpu::read_texture;
use crate::gpu::{group_layout, uniform_texture_group, upload_mips};
use crate::image_io::RenderedImage;
use crate::render::{
    BaseKind, Light, MAX_PUNCTUAL_LIGHTS, MaterialOptions, MaterialUniform, PunctualKind,
    PunctualLight, SceneOptions, TARGET_FORMAT, ViewUniform, check_film_lut,
};
use crate::shaders::{self, Technique};
use crate::tables::TableSet;
use crate::thickness_map::ThicknessMap;
use bytemuck::{Pod, Zeroable};
use nacre_format::msg;
use nacre_format::param::{Msg, Param, Piece};
use std::sync::Arc;

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
    /// Bit 0: a normal texture is bound; [`FLAG_LINEAR_OUTPUT`], [`FLAG_BEHIND`].
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
        let slots = [
            t.base_colour,
            t.metallic_roughness,
            t.normal,
            t.occlusion,
            t.emissive,
            t.iridescence,
            t.specular,
            t.specular_colour,
            t.thickness,
        ];
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
            flags: u32::from(t.normal.is_some()),
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
            transforms,
        }
    }
}

/// A camera for the glTF renderer: eye, target, up and field of view (for the view uniform
/// and the background) and its view-projection (world → clip, column-major, depth in [0, 1]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FittedCamera {
    /// Eye position (for an orthographic camera, a point far behind it along the view
    /// direction, so that every view vector is nearly parallel).
    pub eye: [f32; 3],
    /// A point on the view axis in front of the eye (the box centre for an orbit camera).
    pub target: [f32; 3],
    /// The camera's up direction.
    pub up: [f32; 3],
    /// Vertical field of view, degrees (the background's; 1° for an orthographic camera).
    pub fov_y_deg: f32,
    /// World → clip.
    pub view_proj: [[f32; 4]; 4],
}

/// An orbit camera around the scene's bounding box: `nacre render --yaw --pitch --distance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// Rotation about +y of the direction from the box centre to the eye, degrees (0: the
    /// eye on the +z side; 90: on the +x side).
    pub yaw_deg: f64,
    /// Elevation of the eye above the box centre's horizontal plane, degrees, in (−89, 89).
    pub pitch_deg: f64,
    /// Distance from the box centre, world units (None: the smallest at which the whole box
    /// is in the frame, with a 5 % margin).
    pub distance: Option<f64>,
}

/// The default orbit's elevation: the direction (0, 0.2, 1), atan(0.2) = 11.31°.
pub const DEFAULT_PITCH_DEG: f64 = 11.309_932_474_020_215;

impl Default for Orbit {
    fn default() -> Self {
        Orbit {
            yaw_deg: 0.0,
            pitch_deg: DEFAULT_PITCH_DEG,
            distance: None,
        }
    }
}

/// Where the glTF renderer looks from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViewPoint {
    /// An orbit camera fitted to the scene's bounds.
    Orbit(Orbit),
    /// The file's camera K (0-based, [`GltfScene::cameras`]).
    File(usize),
}

impl Default for ViewPoint {
    fn default() -> Self {
        ViewPoint::Orbit(Orbit::default())
    }
}

/// Largest vertical field of view of the fitted camera, degrees.
pub const FIT_FOV_Y_DEG: f64 = 30.0;

/// Largest horizontal field of view of the fitted camera, degrees.
pub const FIT_FOV_X_DEG: f64 = 40.0;

/// Fits a camera to the box (lo, hi) for an image of aspect `aspect` (width / height): it
/// looks at the box centre along −z, from slightly above (the direction (0, 0.2, 1)), with
/// the field of view of [`FIT_FOV_Y_DEG`] × [`FIT_FOV_X_DEG`] at most, at the
/// smallest distance at which every corner lies inside the frame (5 % margin); near and far
/// planes enclose the box.
pub fn fit_camera(lo: [f32; 3], hi: [f32; 3], aspect: f64) -> Result<FittedCamera> {
    orbit_camera(lo, hi, aspect, &Orbit::default())
}

/// [`fit_camera`] from any orbit: the eye in the direction (sin ψ cos φ, sin φ, cos ψ cos φ)
/// from the box centre (yaw ψ, pitch φ), at `orbit.distance` or the fitted distance.
pub fn orbit_camera(
    lo: [f32; 3],
    hi: [f32; 3],
    aspect: f64,
    orbit: &Orbit,
) -> Result<FittedCamera> {
    let bad = |message: String| Error::Invalid {
        context: "camera".into(),
        message,
    };
    if !lo.iter().chain(&hi).all(|x| x.is_finite()) || (0..3).any(|k| lo[k] > hi[k]) {
        return Err(bad(format!("scene bounds {lo:?} – {hi:?}")));
    }
    if !(aspect > 0.0 && aspect.is_finite()) {
        return Err(bad(format!("aspect ratio {aspect}")));
    }
    let refused = |param: Param, value: String, expected: &str| Error::Refused {
        context: "camera".into(),
        message: msg![param.given(value), format!(": expected {expected}")],
    };
    if !orbit.yaw_deg.is_finite() {
        return Err(refused(
            Param::Yaw,
            orbit.yaw_deg.to_string(),
            "a finite angle in degrees",
        ));
    }
    if orbit.pitch_deg.is_nan() || orbit.pitch_deg.abs() >= 89.0 {
        return Err(refused(
            Param::Pitch,
            orbit.pitch_deg.to_string(),
            "degrees between −89 and 89",
        ));
    }
    if let Some(d) = orbit.distance
        && !(d > 0.0 && d.is_finite())
    {
        return Err(refused(
            Param::Distance,
            d.to_string(),
            "a positive distance in the file's units",
        ));
    }
    let c: [f64; 3] = std::array::from_fn(|k| 0.5 * (f64::from(lo[k]) + f64::from(hi[k])));
    let extent: f64 = (0..3)
        .map(|k| f64::from(hi[k]) - f64::from(lo[k]))
        .fold(0.0, f64::max)
        .max(1e-6);
    let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let b = if *orbit == Orbit::default() {
        // The default direction exactly as before `Orbit` (golden images).
        let v = [0.0, 0.2, 1.0];
        let l = len(v);
        v.map(|x| x / l)
    } else {
        let (yaw, pitch) = (orbit.yaw_deg.to_radians(), orbit.pitch_deg.to_radians());
        [
            yaw.sin() * pitch.cos(),
            pitch.sin(),
            yaw.cos() * pitch.cos(),
        ]
    };
    // Basis: back b (towards the eye), right = up × b, true up = b × right.
    let right = {
        let v = [b[2], 0.0, -b[0]];
        let l = len(v);
        v.map(|x| x / l)
    };
    let up = [
        b[1] * right[2] - b[2] * right[1],
        b[2] * right[0] - b[0] * right[2],
        b[0] * right[1] - b[1] * right[0],
    ];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    // At most FIT_FOV_Y_DEG vertically and FIT_FOV_X_DEG horizontally (a wide image gets a
    // longer lens rather than the stretched edges of a wide angle).
    let ty = (0.5 * FIT_FOV_Y_DEG.to_radians())
        .tan()
        .min((0.5 * FIT_FOV_X_DEG.to_radians()).tan() / aspect);
    let tx = ty * aspect;
    let mut distance: f64 = 0.0;
    let mut depth: f64 = 0.0;
    for corner in 0..8 {
        let p: [f64; 3] = std::array::from_fn(|k| {
            let v = if corner >> k & 1 == 1 { hi[k] } else { lo[k] };
            f64::from(v) - c[k]
        });
        let (x, y, z) = (dot(p, right), dot(p, up), dot(p, b));
        distance = distance.max(z + (x.abs() / tx).max(y.abs() / ty));
        depth = depth.max(len(p));
    }
    let distance = orbit
        .distance
        .unwrap_or((distance * 1.05).max(extent * 1e-3));
    let eye: [f64; 3] = std::array::from_fn(|k| c[k] + distance * b[k]);
    let near = (distance - depth * 1.1).max(distance * 1e-3);
    let far = distance + depth * 1.1 + extent * 1e-3;
    let f = 1.0 / ty;
    let (pa, pb) = (far / (near - far), near * far / (near - far));
    // View: rows right, up, b; translation −(row · eye).
    let view = [
        [right[0], right[1], right[2], -dot(right, eye)],
        [up[0], up[1], up[2], -dot(up, eye)],
        [b[0], b[1], b[2], -dot(b, eye)],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let proj = [
        [f / aspect, 0.0, 0.0, 0.0],
        [0.0, f, 0.0, 0.0],
        [0.0, 0.0, pa, pb],
        [0.0, 0.0, -1.0, 0.0],
    ];
    let m: [[f64; 4]; 4] = std::array::from_fn(|r| {
        std::array::from_fn(|col| (0..4).map(|k| proj[r][k] * view[k][col]).sum())
    });
    Ok(FittedCamera {
        eye: eye.map(|x| x as f32),
        target: c.map(|x| x as f32),
        up: up.map(|x| x as f32),
        fov_y_deg: (2.0 * ty.atan()).to_degrees() as f32,
        view_proj: std::array::from_fn(|col| std::array::from_fn(|r| m[r][col] as f32)),
    })
}

/// The file's camera `camera` for an image of aspect `aspect` (glTF 2.0 §3.10): the node's
/// world transform with its scale removed (axes normalised, up re-orthogonalised) is the
/// camera-to-world transform, looking down −z. Perspective: `yfov` and the image's aspect
/// (not the file's `aspectRatio`, so the picture is never stretched), `znear`, and `zfar` or
/// an infinite far plane. Orthographic: `ymag` and a width of `ymag` × the aspect. The box
/// (lo, hi) sets the shading eye of an orthographic camera.
pub fn file_camera(
    camera: &GltfCamera,
    lo: [f32; 3],
    hi: [f32; 3],
    aspect: f64,
) -> Result<FittedCamera> {
    let bad = |message: String| Error::Invalid {
        context: format!("camera `{}`", camera.name),
        message,
    };
    if !(aspect > 0.0 && aspect.is_finite()) {
        return Err(bad(format!("aspect ratio {aspect}")));
    }
    let w = camera.world.map(|c| c.map(f64::from));
    let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let unit = |v: [f64; 3]| {
        let l = len(v);
        (l > 1e-12 && l.is_finite()).then(|| v.map(|x| x / l))
    };
    let axis = |k: usize| [w[k][0], w[k][1], w[k][2]];
    let eye = [w[3][0], w[3][1], w[3][2]];
    let (Some(b), Some(x)) = (unit(axis(2)), unit(axis(0))) else {
        return Err(bad("its node's transform has a zero axis".into()));
    };
    let Some(up) = unit(cross(b, x)) else {
        return Err(bad("its node's x and z axes are parallel".into()));
    };
    let right = cross(up, b);
    let extent: f64 = (0..3)
        .map(|k| f64::from(hi[k]) - f64::from(lo[k]))
        .fold(0.0, f64::max)
        .max(1e-6);
    let (proj, shading_eye, fov_y_deg) = match camera.projection {
        GltfProjection::Perspective {
            yfov_rad,
            znear,
            zfar,
        } => {
            let f = 1.0 / (0.5 * f64::from(yfov_rad)).tan();
            let near = f64::from(znear);
            let (pa, pb) = match zfar {
                Some(far) => {
                    let far = f64::from(far);
                    (far / (near - far), near * far / (near - far))
                }
                None => (-1.0, -near),
            };
            let proj = [
                [f / aspect, 0.0, 0.0, 0.0],
                [0.0, f, 0.0, 0.0],
                [0.0, 0.0, pa, pb],
                [0.0, 0.0, -1.0, 0.0],
            ];
            (proj, eye, f64::from(yfov_rad).to_degrees())
        }
        GltfProjection::Orthographic {
            ymag, znear, zfar, ..
        } => {
            let (near, far) = (f64::from(znear), f64::from(zfar));
            let ymag = f64::from(ymag);
            let proj = [
                [1.0 / (ymag * aspect), 0.0, 0.0, 0.0],
                [0.0, 1.0 / ymag, 0.0, 0.0],
                [0.0, 0.0, 1.0 / (near - far), near / (near - far)],
                [0.0, 0.0, 0.0, 1.0],
            ];
            let back = 1e4 * extent.max(far);
            (proj, std::array::from_fn(|k| eye[k] + back * b[k]), 1.0)
        }
    };
    let view = [
        [right[0], right[1], right[2], -dot(right, eye)],
        [up[0], up[1], up[2], -dot(up, eye)],
        [b[0], b[1], b[2], -dot(b, eye)],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let m: [[f64; 4]; 4] = std::array::from_fn(|r| {
        std::array::from_fn(|col| (0..4).map(|k| proj[r][k] * view[k][col]).sum())
    });
    if !m.iter().flatten().all(|x| x.is_finite()) {
        return Err(bad("its view-projection is not finite".into()));
    }
    Ok(FittedCamera {
        eye: shading_eye.map(|x| x as f32),
        target: std::array::from_fn(|k| (eye[k] - b[k]) as f32),
        up: up.map(|x| x as f32),
        fov_y_deg: fov_y_deg as f32,
        view_proj: std::array::from_fn(|col| std::array::from_fn(|r| m[r][col] as f32)),
    })
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

/// The fixed-function state of a mesh pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
struct PipelineState {
    /// Single-sided material: back faces culled.
    cull_back: bool,
    /// `alphaMode` BLEND: src-alpha blending, no depth writes.
    blend: bool,
    /// The picture of the opaque scene (linear radiance, [`BEHIND_FORMAT`]) rather than the
    /// display image.
    linear: bool,
}

fn mesh_pipeline(
    ctx: &GpuContext,
    technique: Technique,
    binding: &TechniqueBinding,
    view_layout: &wgpu::BindGroupLayout,
    material_layout: &wgpu::BindGroupLayout,
    mesh_layout: &wgpu::BindGroupLayout,
    state: PipelineState,
) -> Result<wgpu::RenderPipeline> {
    let device = &ctx.device;
    let source = shaders::film_pipeline(technique.module(), &["material", "mesh"])?;
    let module = shaders::create_module(ctx, "mesh", &source)?;
    ctx.checked("creating the mesh pipeline", || {
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mesh"),
            bind_group_layouts: &[
                Some(view_layout),
                Some(&binding.layout),
                Some(material_layout),
                Some(mesh_layout),
            ],
            immediate_size: 0,
        });
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("mesh"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("mesh_vs"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: (VERTEX_FLOATS * 4) as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![
                        0 => Float32x3, 1 => Float32x3, 2 => Float32x4,
                        3 => Float32x2, 4 => Float32x2, 5 => Float32x4
                    ],
                })],
            },
            primitive: wgpu::PrimitiveState {
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: state.cull_back.then_some(wgpu::Face::Back),
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                // Blended primitives test depth but do not write it.
                depth_write_enabled: Some(!state.blend),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("mesh_fs"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: if state.linear {
                        BEHIND_FORMAT
                    } else {
                        TARGET_FORMAT
                    },
                    blend: state.blend.then_some(wgpu::BlendState::ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    })
}

/// Whether the loaded `film-lut` table can draw `material` (see the module documentation);
/// a gold-like metal gets the table's base. `Err` holds the reason it cannot.
fn lut_material(
    tables: &TableSet,
    material: &MaterialOptions,
    base_colour: [f32; 3],
) -> std::result::Result<MaterialOptions, Msg> {
    let Some(lut) = &tables.film_lut else {
        return Err("no film-lut table is loaded".into());
    };
    // Errors are kept whole, so that a front end names their parameters its own way.
    let quoted = |e: Error| Msg::from_pieces(vec![Piece::Nested(Arc::new(e))]);
    let context = format!("{} (base)", lut.manifest_path.display());
    let table_base =
        nacre_format::materials::resolve(&lut.manifest.base, &context, lut.manifest_path.parent())
            .map_err(|e| quoted(e.into()))?;
    let table_kind = BaseKind::of(&table_base);
    let mut m = material.clone();
    match (material.base_kind, table_kind) {
        (BaseKind::Dielectric, BaseKind::Dielectric) => {
            let a = material
                .base
                .index_at(550.0)
                .map_err(|e| quoted(e.into()))?;
            let b = table_base.index_at(550.0).map_err(|e| quoted(e.into()))?;
            if (a - b).norm() > 1e-3 {
                return Err(format!(
                    "base index {} differs from the table `{}`'s {}",
                    a.re, lut.name, b.re
                )
                .into());
            }
        }
        (BaseKind::Metal, BaseKind::Metal) if is_gold_like(base_colour) => {
            m.base = table_base;
        }
        (BaseKind::Metal, _) => {
            return Err(format!(
                "a metal base needs a table baked on that metal (film-gold for a gold-coloured base), not `{}`",
                lut.name
            )
            .into());
        }
        _ => return Err(format!("the base differs from the table `{}`'s", lut.name).into()),
    }
    check_film_lut(tables, &m).map_err(quoted)?;
    Ok(m)
}

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

/// The lights the mesh renderer draws `scene` with, and a note when they are not all of the
/// file's lighting. As the glTF Sample Viewer does by default, a file without
/// `KHR_lights_punctual` lights is lit by the environment alone (the directional light's
/// intensity is 0). A file's lights are drawn as they are, at every shading point
/// ([`PunctualLight`]: position, cone, range and r² falloff of the specification), up to
/// [`MAX_PUNCTUAL_LIGHTS`]: beyond that, the brightest at the centre of the scene's bounds
/// (colour × intensity × falloff there), with a note naming how many are left out.
pub fn scene_lights(scene: &GltfScene) -> (Light, Vec<PunctualLight>, Option<String>) {
    let off = Light {
        intensity: 0.0,
        ..Light::default()
    };
    let (lo, hi) = scene.bounds();
    let centre: [f32; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
    let mut lights: Vec<(f32, PunctualLight)> = scene
        .lights
        .iter()
        .map(|light| {
            let punctual = PunctualLight {
                kind: match light.kind {
                    LightKind::Directional => PunctualKind::Directional,
                    LightKind::Point => PunctualKind::Point,
                    LightKind::Spot {
                        inner_cone_rad,
                        outer_cone_rad,
                    } => PunctualKind::Spot {
                        inner_cone_rad,
                        outer_cone_rad,
                    },
                },
                position: light.position,
                direction: light.direction,
                colour: light.colour,
                intensity: light.intensity,
                range: light.range,
            };
            (brightness_at(&punctual, centre), punctual)
        })
        .collect();
    let note = (lights.len() > MAX_PUNCTUAL_LIGHTS).then(|| {
        format!(
            "KHR_lights_punctual: {} lights; the {MAX_PUNCTUAL_LIGHTS} brightest at the scene's centre are drawn",
            lights.len()
        )
    });
    if lights.len() > MAX_PUNCTUAL_LIGHTS {
        // Brightest first; a stable sort keeps the file's order among equals.
        lights.sort_by(|a, b| b.0.total_cmp(&a.0));
        lights.truncate(MAX_PUNCTUAL_LIGHTS);
    }
    (off, lights.into_iter().map(|(_, l)| l).collect(), note)
}

/// The irradiance (summed over colour channels) `light` gives at `point` facing it: its
/// ranking when a file has more lights than are drawn.
fn brightness_at(light: &PunctualLight, point: [f32; 3]) -> f32 {
    let colour = light.colour.iter().sum::<f32>() * light.intensity;
    let value = match light.kind {
        PunctualKind::Directional => colour,
        PunctualKind::Point | PunctualKind::Spot { .. } => {
            let d: [f32; 3] = std::array::from_fn(|k| point[k] - light.position[k]);
            let r2 = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).max(1e-12);
            let window = light.range.map_or(1.0, |range| {
                (1.0 - (r2 / (range * range)).powi(2)).clamp(0.0, 1.0)
            });
            let cone = match light.kind {
                PunctualKind::Spot {
                    inner_cone_rad,
                    outer_cone_rad,
                } => {
                    let r = r2.sqrt();
                    let cos_angle = (0..3).map(|k| d[k] / r * light.direction[k]).sum::<f32>();
                    let (cos_inner, cos_outer) = (inner_cone_rad.cos(), outer_cone_rad.cos());
                    let t = ((cos_angle - cos_outer) / (cos_inner - cos_outer).max(1e-3))
                        .clamp(0.0, 1.0);
                    t * t
                }
                _ => 1.0,
            };
            colour * window * window * cone / r2
        }
    };
    if value.is_finite() { value } else { 0.0 }
}

/// The camera of `view` for `scene` and an image of aspect `aspect` (width / height): checks
/// the orbit's angles and distance, or that the file has the camera asked for.
pub fn view_camera(scene: &GltfScene, view: ViewPoint, aspect: f64) -> Result<FittedCamera> {
    let (lo, hi) = scene.bounds();
    match view {
        ViewPoint::Orbit(orbit) => orbit_camera(lo, hi, aspect, &orbit),
        ViewPoint::File(k) => match scene.cameras.get(k) {
            Some(c) => file_camera(c, lo, hi, aspect),
            None => Err(Error::Refused {
                context: format!("glTF {}", scene.path.display()),
                message: msg![
                    Param::Camera.given(k.to_string()),
                    format!(
                        ": the file has {} camera(s), numbered from 0",
                        scene.cameras.len()
                    )
                ],
            }),
        },
    }
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
    options.validate()?;
    let environment = match &options.environment {
        Some(path) => EnvironmentMap::load(path)?,
        None => EnvironmentMap::default_map()?,
    };
    let (width, height) = (options.width, options.height);
    let limit = ctx.device.limits().max_texture_dimension_2d;
    if width.max(height) > limit {
        return Err(Error::Limit {
            what: "render target".into(),
            needed: u64::from(width.max(height)),
            limit: u64::from(limit),
            adapter: ctx.info.name.clone(),
        });
    }
    let camera = view_camera(scene, view, f64::from(width) / f64::from(height))?;
    let mut view_options = options.clone();
    view_options.camera.eye = camera.eye;
    view_options.camera.target = camera.target;
    view_options.camera.up = camera.up;
    view_options.camera.fov_y_deg = camera.fov_y_deg;
    let (light, punctual_lights, light_note) = scene_lights(scene);
    view_options.light = light;
    view_options.punctual_lights = punctual_lights;

    // Materials: nacre's options and the technique that draws each.
    let colorimeter = tables.colorimeter()?;
    let used: Vec<usize> = {
        let mut v: Vec<usize> = scene.primitives.iter().map(|p| p.material).collect();
        v.sort_unstable();
        v.dedup();
        v
    };
    let used_name = |n: &str| {
        // A note about a material names it first (`name: …`); other notes are kept.
        let about = |i: usize| n.starts_with(&format!("{}:", scene.materials[i].name));
        !(0..scene.materials.len()).any(about) || used.iter().any(|&i| about(i))
    };
    let mut notes: Vec<Msg> = scene
        .notes
        .iter()
        .filter(|n| used_name(n))
        .map(|n| Msg::from(n.as_str()))
        .collect();
    let mut drawn = Vec::with_capacity(scene.materials.len());
    // Technique fallbacks, summarised in one line: (material, reason).
    let mut fallbacks: Vec<(String, Msg)> = Vec::new();
    for (i, gm) in scene.materials.iter().enumerate() {
        let (mut m, material_notes) = gm.material_options(&colorimeter)?;
        if used.contains(&i) {
            notes.extend(material_notes.into_iter().map(Msg::from));
        }
        let (lo, hi) = gm.metallic_range();
        let one_lobe = hi <= 0.0 || lo >= 1.0;
        let mut t = technique;
        if technique == Technique::Lut {
            let colour = [gm.base_colour[0], gm.base_colour[1], gm.base_colour[2]];
            let result = if one_lobe {
                lut_material(tables, &m, colour)
            } else {
                Err(Msg::from(
                    "its metallic value varies (a partial factor or a texture): the table bakes one base",
                ))
            };
            match result {
                Ok(lm) => m = lm,
                Err(why) => {
                    if used.contains(&i) {
                        fallbacks.push((gm.name.clone(), why));
                    }
                    t = Technique::Fourier;
                }
            }
        } else if technique == Technique::Spectral && !one_lobe {
            if used.contains(&i) {
                fallbacks.push((
                    gm.name.clone(),
                    Msg::from(
                        "it mixes a dielectric and a metal lobe; spectral holds one base per pass",
                    ),
                ));
            }
            t = Technique::Fourier;
        }
        if t == Technique::Lut {
            // The table's ambient (checked above) must be the material's.
            m.ambient_ior = tables
                .film_lut
                .as_ref()
                .map_or(1.0, |l| l.axes.ambient_index as f32);
        }
        drawn.push((m, t));
    }
    if let Some(note) = light_note {
        notes.push(Msg::from(note));
    }
    if let Some((name, why)) = fallbacks.first() {
        notes.push(msg![
            format!(
                "drawn with fourier instead of {}: {} of {} materials (e.g. `{name}`: ",
                technique.name(),
                fallbacks.len(),
                used.len()
            ),
            why.clone(),
            ")"
        ]);
    }

    // The passes: one per technique, except film_spectral, whose group-1 samples hold the
    // base index per wavelength: one pass (binding + pipeline) per distinct base.
    let key_of = |i: usize| {
        let (m, t) = &drawn[i];
        if *t == Technique::Spectral {
            (*t, m.base.name().to_string())
        } else {
            (*t, String::new())
        }
    };
    let state_of = |i: usize| PipelineState {
        cull_back: !scene.materials[i].double_sided,
        blend: scene.materials[i].alpha_mode == AlphaMode::Blend,
        linear: false,
    };
    // Transmissive materials see the opaque scene: a first pass draws everything else into a
    // picture of linear radiance (KHR_materials_transmission, as the glTF Sample Viewer does).
    let transmissive = |i: usize| {
        let t = scene.materials[i].transmission;
        t > 0.0 && t.is_finite()
    };
    let behind_needed = used.iter().any(|&i| transmissive(i));
    let mut pass_keys: Vec<(Technique, String)> = used.iter().map(|&i| key_of(i)).collect();
    pass_keys.sort_by(|a, b| (a.0.name(), &a.1).cmp(&(b.0.name(), &b.1)));
    pass_keys.dedup();
    let device = &ctx.device;
    let view_layout = crate::render::view_group_layout(device, "mesh view");
    let material_layout = group_layout(device, "mesh material");
    let mesh_layout = mesh_group_layout(device);
    let mut bindings = Vec::new();
    let mut pipelines: std::collections::BTreeMap<(usize, PipelineState), wgpu::RenderPipeline> =
        Default::default();
    for (k, key) in pass_keys.iter().enumerate() {
        let t = key.0;
        let mut technique_options = options.technique_options();
        if let Some(&i) = used.iter().find(|&&i| key_of(i) == *key) {
            technique_options.spectral.base = drawn[i].0.base.clone();
        }
        let binding = TechniqueBinding::new(ctx, tables, t, &technique_options, &colorimeter)?;
        let mut states: Vec<PipelineState> = Vec::new();
        for &i in used.iter().filter(|&&i| key_of(i) == *key) {
            states.push(state_of(i));
            if behind_needed && !transmissive(i) {
                states.push(PipelineState {
                    linear: true,
                    ..state_of(i)
                });
            }
        }
        states.sort_unstable();
        states.dedup();
        for state in states {
            let pipeline = mesh_pipeline(
                ctx,
                t,
                &binding,
                &view_layout,
                &material_layout,
                &mesh_layout,
                state,
            )?;
            pipelines.insert((k, state), pipeline);
        }
        bindings.push(binding);
    }
    let pass_of = |i: usize| {
        let key = key_of(i);
        pass_keys.iter().position(|k| *k == key).unwrap_or(0)
    };

    crate::render::check_film_eval(tables, options)?;
    let env = crate::render::EnvironmentTextures::new(
        ctx,
        &environment,
        options.film_eval,
        tables.rough_film_lut.as_ref(),
    )?;
    let view_uniform = ViewUniform::new(&view_options, env.env_levels)?;
    // Per material its thickness texture, or a 1×1 map of g = 1 (d = d_max) without one.
    let flat = ThicknessMap {
        width: 1,
        height: 1,
        values: vec![1.0],
        green_blue: None,
    };
    let flat_texture = upload_mips(
        ctx,
        "thickness map",
        wgpu::TextureFormat::Rg16Float,
        &flat.mip_chain(),
    )?;
    let mut thickness_textures = Vec::with_capacity(drawn.len());
    for i in 0..drawn.len() {
        thickness_textures.push(match scene.thickness_maps.get(i).and_then(Option::as_ref) {
            Some(map) if used.contains(&i) => Some(upload_mips(
                ctx,
                "thickness map",
                wgpu::TextureFormat::Rg16Float,
                &map.mip_chain(),
            )?),
            _ => None,
        });
    }
    let mut material_uniforms = Vec::with_capacity(drawn.len());
    for (m, _) in &drawn {
        let mut u = MaterialUniform::new(m, tables)?;
        u.film_eval = options.film_eval.id();
        material_uniforms.push(u);
    }
    // The glTF textures the used materials read, uploaded once each with their mip chains.
    let mut needed = vec![false; scene.textures.len()];
    for &i in &used {
        let t = &scene.materials[i].textures;
        for r in [
            t.base_colour,
            t.metallic_roughness,
            t.normal,
            t.occlusion,
            t.emissive,
            t.iridescence,
            t.specular,
            t.specular_colour,
        ]
        .into_iter()
        .flatten()
        {
            if let Some(n) = needed.get_mut(r.texture) {
                *n = true;
            }
        }
    }
    let mut gpu_textures: Vec<Option<wgpu::Texture>> = Vec::with_capacity(scene.textures.len());
    for (t, &need) in scene.textures.iter().zip(&needed) {
        gpu_textures.push(if need {
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

    let mip_down = if behind_needed {
        Some(MipDown::new(ctx)?)
    } else {
        None
    };
    let (target, submitted) = ctx.checked("rendering the glTF scene", || {
        let group = |layout: &wgpu::BindGroupLayout,
                     label: &str,
                     contents: &[u8],
                     texture: &wgpu::Texture,
                     repeat_v: bool| {
            uniform_texture_group(device, layout, label, contents, texture, repeat_v)
        };
        let view_group = env.bind_group(
            device,
            &view_layout,
            "mesh view",
            bytemuck::bytes_of(&view_uniform),
        );
        let material_groups: Vec<wgpu::BindGroup> = material_uniforms
            .iter()
            .zip(&thickness_textures)
            .map(|(u, t)| {
                group(
                    &material_layout,
                    "mesh material",
                    bytemuck::bytes_of(u),
                    t.as_ref().unwrap_or(&flat_texture),
                    true,
                )
            })
            .collect();
        // Group 3 per used material: its MeshUniform (with `extra_flags`), textures and
        // samplers, and the picture of the scene behind.
        let mut samplers: std::collections::BTreeMap<SamplerKey, wgpu::Sampler> =
            Default::default();
        for (i, gm) in scene.materials.iter().enumerate() {
            if used.contains(&i) {
                for slot in slots_of(gm) {
                    let spec = slot
                        .and_then(|r| Some((gpu_textures.get(r.texture)?.as_ref()?, r.texture)))
                        .map_or(SamplerSpec::default(), |(_, k)| scene.textures[k].sampler);
                    samplers
                        .entry(SamplerKey::of(spec))
                        .or_insert_with(|| create_sampler(device, spec));
                }
            }
        }
        let mesh_groups_with = |extra_flags: u32, behind: &wgpu::TextureView| {
            let mut mesh_groups: Vec<Option<wgpu::BindGroup>> = Vec::new();
            for (i, gm) in scene.materials.iter().enumerate() {
                if !used.contains(&i) {
                    mesh_groups.push(None);
                    continue;
                }
                let mut uniform = MeshUniform::new(camera.view_proj, gm);
                uniform.flags |= extra_flags;
                let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("mesh material (glTF)"),
                    contents: bytemuck::bytes_of(&uniform),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
                let mut views = Vec::with_capacity(TEXTURE_SLOTS.len());
                let mut keys = Vec::with_capacity(TEXTURE_SLOTS.len());
                for slot in slots_of(gm) {
                    let (texture, spec) = match slot
                        .and_then(|r| Some((gpu_textures.get(r.texture)?.as_ref()?, r.texture)))
                    {
                        Some((texture, k)) => (texture, scene.textures[k].sampler),
                        None => (&white, SamplerSpec::default()),
                    };
                    views.push(texture.create_view(&Default::default()));
                    keys.push(SamplerKey::of(spec));
                }
                let mut entries = vec![wgpu::BindGroupEntry {
                    binding: 0,
                    resource: buffer.as_entire_binding(),
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
                mesh_groups.push(Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("mesh material (glTF)"),
                    layout: &mesh_layout,
                    entries: &entries,
                })));
            }
            mesh_groups
        };
        let geometry: Vec<(wgpu::Buffer, wgpu::Buffer, u32, usize, f64)> = scene
            .primitives
            .iter()
            .filter(|p| !p.indices.is_empty())
            .map(|p| {
                let vertices = vertex_data(p);
                let vb = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("mesh vertices"),
                    contents: bytemuck::cast_slice(&vertices),
                    usage: wgpu::BufferUsages::VERTEX,
                });
                let ib = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("mesh indices"),
                    contents: bytemuck::cast_slice(&p.indices),
                    usage: wgpu::BufferUsages::INDEX,
                });
                (
                    vb,
                    ib,
                    p.indices.len() as u32,
                    p.material,
                    view_depth(&camera, p),
                )
            })
            .collect();
        // Draw order: opaque and masked primitives by pass, then blended ones back to front.
        let mut order: Vec<usize> = (0..geometry.len()).collect();
        order.sort_by(|&a, &b| {
            let (ma, mb) = (geometry[a].3, geometry[b].3);
            let (ba, bb) = (state_of(ma).blend, state_of(mb).blend);
            ba.cmp(&bb).then_with(|| {
                if ba {
                    geometry[b].4.total_cmp(&geometry[a].4)
                } else {
                    (pass_of(ma), state_of(ma)).cmp(&(pass_of(mb), state_of(mb)))
                }
            })
        });
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let extent = (size.width, size.height);
        let target = crate::gpu::render_target(device, "mesh target", extent, TARGET_FORMAT, true);
        let depth = crate::gpu::render_target(device, "mesh depth", extent, DEPTH_FORMAT, false);
        let target_view = target.create_view(&Default::default());
        let depth_view = depth.create_view(&Default::default());
        // The picture of the opaque scene (cleared to alpha 0: nothing drawn there), or a
        // 1 × 1 stand-in when no material transmits.
        let linear_texture = |label: &str, size: wgpu::Extent3d| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                // The full chain (mip_down.wgsl): rough surfaces refract a blurred picture.
                mip_level_count: size.max_mips(wgpu::TextureDimension::D2),
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: BEHIND_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
        };
        let one = wgpu::Extent3d {
            width: 1,
            height: 1,
            depth_or_array_layers: 1,
        };
        let behind = linear_texture("mesh scene behind", if behind_needed { size } else { one });
        let behind_view = behind.create_view(&Default::default());
        // Level k of the picture, alone: a render attachment holds one level.
        let behind_level = |k: u32| {
            behind.create_view(&wgpu::TextureViewDescriptor {
                base_mip_level: k,
                mip_level_count: Some(1),
                ..Default::default()
            })
        };
        let no_behind = linear_texture("mesh no scene behind", one);
        let no_behind_view = no_behind.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        // The stand-in is cleared once (alpha 0) so that it reads as "nothing behind".
        drop(crate::gpu::begin_pass(
            &mut encoder,
            "mesh no scene behind",
            &[crate::gpu::cleared_attachment(
                &no_behind_view,
                wgpu::Color::TRANSPARENT,
            )],
        ));
        // Draws `order`'s primitives into `colour` (cleared to `clear`; depth cleared), with
        // group-3 bind groups `groups`; `linear`: the picture of the opaque scene (transmissive
        // primitives skipped).
        let draw = |encoder: &mut wgpu::CommandEncoder,
                    colour: &wgpu::TextureView,
                    clear: wgpu::Color,
                    groups: &[Option<wgpu::BindGroup>],
                    linear: bool| {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("mesh"),
                color_attachments: &[crate::gpu::cleared_attachment(colour, clear)],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &view_group, &[]);
            let mut current: Option<(usize, PipelineState)> = None;
            for &g in &order {
                let (vb, ib, count, material, _) = &geometry[g];
                if linear && transmissive(*material) {
                    continue;
                }
                let (Some(mesh_group), k) = (&groups[*material], pass_of(*material)) else {
                    continue;
                };
                let key = (
                    k,
                    PipelineState {
                        linear,
                        ..state_of(*material)
                    },
                );
                let Some(pipeline) = pipelines.get(&key) else {
                    continue;
                };
                if current != Some(key) {
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(1, &bindings[k].bind_group, &[]);
                    current = Some(key);
                }
                pass.set_bind_group(2, &material_groups[*material], &[]);
                pass.set_bind_group(3, mesh_group, &[]);
                pass.set_vertex_buffer(0, vb.slice(..));
                pass.set_index_buffer(ib.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..*count, 0, 0..1);
            }
        };
        if behind_needed {
            let groups = mesh_groups_with(FLAG_LINEAR_OUTPUT, &no_behind_view);
            draw(
                &mut encoder,
                &behind_level(0),
                wgpu::Color::TRANSPARENT,
                &groups,
                true,
            );
            if let Some(mip_down) = &mip_down {
                mip_down.fill(
                    device,
                    &mut encoder,
                    &behind_level,
                    behind.mip_level_count(),
                );
            }
        }
        // The background: the environment seen by the camera is not drawn (a clear colour
        // keeps the spheres' silhouettes readable).
        let groups = if behind_needed {
            mesh_groups_with(FLAG_BEHIND, &behind_view)
        } else {
            mesh_groups_with(0, &no_behind_view)
        };
        draw(
            &mut encoder,
            &target_view,
            wgpu::Color {
                r: 0.18,
                g: 0.18,
                b: 0.2,
                a: 1.0,
            },
            &groups,
            false,
        );
        let _ = device.poll(wgpu::PollType::wait_indefinitely());
        let submitted = std::time::Instant::now();
        ctx.queue.submit([encoder.finish()]);
        (target, submitted)
    })?;
    ctx.wait("rendering the glTF scene")?;
    let gpu_seconds = submitted.elapsed().as_secs_f64();
    let mut pixels = read_texture(ctx, &target, 4)?;
    for p in pixels.chunks_exact_mut(4) {
        p[3] = 255;
    }
    Ok(MeshRender {
        image: RenderedImage {
            width,
            height,
            pixels,
            gpu_seconds,
        },
        notes,
    })
}

/// The interleaved vertices of a primitive ([`VERTEX_FLOATS`] floats each).
fn vertex_data(p: &crate::gltf_scene::GltfPrimitive) -> Vec<f32> {
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

/// The clip-space w (distance along the view axis) of a primitive's bounding-box centre:
/// the sort key of blended primitives (larger = farther, drawn first).
fn view_depth(camera: &FittedCamera, p: &crate::gltf_scene::GltfPrimitive) -> f64 {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for x in &p.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(x[k]);
            hi[k] = hi[k].max(x[k]);
        }
    }
    let c: [f32; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
    let m = camera.view_proj;
    let w = m[0][3] * c[0] + m[1][3] * c[1] + m[2][3] * c[2] + m[3][3];
    if w.is_finite() { f64::from(w) } else { 0.0 }
}

/// Group 3 of the mesh pipelines: 0 MeshParams (vertex + fragment), then per texture slot a
/// filterable 2-D texture (1 + 2k) and its sampler (2 + 2k).
fn mesh_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
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
    entries.push(wgpu::BindGroupLayoutEntry {
        binding: BEHIND_BINDING,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    });
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("mesh material (glTF)"),
        entries: &entries,
    })
}

/// The box-filter pass of `shaders/mip_down.wgsl` and its one binding (level k, read).
struct MipDown {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

impl MipDown {
    fn new(ctx: &GpuContext) -> Result<MipDown> {
        let device = &ctx.device;
        let source = shaders::flatten("mip_down")?;
        let module = shaders::create_module(ctx, "mip_down", &source)?;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mip_down"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            }],
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
    fn fill(
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

/// Group 3's binding of the scene behind transmissive surfaces.
const BEHIND_BINDING: u32 = 1 + 2 * TEXTURE_SLOTS.len() as u32;

/// A material's textures in group 3's slot order ([`TEXTURE_SLOTS`]).
fn slots_of(gm: &GltfMaterial) -> [Option<TextureRef>; 8] {
    let t = &gm.textures;
    [
        t.base_colour,
        t.metallic_roughness,
        t.normal,
        t.occlusion,
        t.emissive,
        t.iridescence,
        t.specular,
        t.specular_colour,
    ]
}

/// A sampler's identity (wrap modes and filters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct SamplerKey([u8; 2], [bool; 4]);

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
    let limit = ctx.device.limits().max_texture_dimension_2d;
    if t.width.max(t.height) > limit {
        return Err(Error::Limit {
            what: t.name.clone(),
            needed: u64::from(t.width.max(t.height)),
            limit: u64::from(limit),
            adapter: ctx.info.name.clone(),
        });
    }
    let levels = rgba8_mip_chain(t.width, t.height, &t.rgba, t.srgb);
    let format = if t.srgb {
        wgpu::TextureFormat::Rgba8UnormSrgb
    } else {
        wgpu::TextureFormat::Rgba8Unorm
    };
    ctx.checked(&format!("uploading {}", t.name), || {
        let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(&t.name),
            size: wgpu::Extent3d {
                width: t.width,
                height: t.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: levels.len() as u32,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        for (k, (w, h, texels)) in levels.iter().enumerate() {
            ctx.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: k as u32,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                texels,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(w * 4),
                    rows_per_image: Some(*h),
                },
                wgpu::Extent3d {
                    width: *w,
                    height: *h,
                    depth_or_array_layers: 1,
                },
            );
        }
        texture
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitted_camera_frames_every_corner() {
        let (lo, hi) = ([-5.0, -1.0, -1.0], [5.0, 1.0, 1.0]);
        let cam = fit_camera(lo, hi, 4.0).unwrap();
        let m = cam.view_proj;
        for corner in 0..8 {
            let p: [f32; 3] =
                std::array::from_fn(|k| if corner >> k & 1 == 1 { hi[k] } else { lo[k] });
            let clip: [f32; 4] =
                std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r]);
            let ndc = [clip[0] / clip[3], clip[1] / clip[3], clip[2] / clip[3]];
            assert!(ndc[0].abs() <= 1.0 && ndc[1].abs() <= 1.0, "{ndc:?}");
            assert!((0.0..=1.0).contains(&ndc[2]), "{ndc:?}");
        }
        assert!(fit_camera([0.0; 3], [f32::NAN; 3], 1.0).is_err());
    }

    fn project(m: &[[f32; 4]; 4], p: [f32; 3]) -> [f32; 3] {
        let clip: [f32; 4] =
            std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r]);
        [clip[0] / clip[3], clip[1] / clip[3], clip[2] / clip[3]]
    }

    #[test]
    fn orbits_turn_around_the_box_and_still_frame_it() {
        let (lo, hi) = ([-1.0, -0.5, -2.0], [1.0, 0.5, 2.0]);
        assert_eq!(
            orbit_camera(lo, hi, 1.5, &Orbit::default()).unwrap(),
            fit_camera(lo, hi, 1.5).unwrap()
        );
        for (yaw, pitch) in [(90.0, 0.0), (-45.0, 60.0), (180.0, -30.0)] {
            let orbit = Orbit {
                yaw_deg: yaw,
                pitch_deg: pitch,
                distance: None,
            };
            let cam = orbit_camera(lo, hi, 1.5, &orbit).unwrap();
            // The eye lies in the orbit's direction from the centre.
            let d: [f32; 3] = std::array::from_fn(|k| cam.eye[k] - cam.target[k]);
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let (y, p) = (f64::to_radians(yaw), f64::to_radians(pitch));
            let want = [y.sin() * p.cos(), p.sin(), y.cos() * p.cos()];
            for k in 0..3 {
                assert!(
                    (f64::from(d[k] / len) - want[k]).abs() < 1e-5,
                    "{d:?} {want:?}"
                );
            }
            for corner in 0..8 {
                let q: [f32; 3] =
                    std::array::from_fn(|k| if corner >> k & 1 == 1 { hi[k] } else { lo[k] });
                let ndc = project(&cam.view_proj, q);
                assert!(
                    ndc[0].abs() <= 1.0 && ndc[1].abs() <= 1.0,
                    "{yaw} {pitch}: {ndc:?}"
                );
                assert!((0.0..=1.0).contains(&ndc[2]), "{ndc:?}");
            }
        }
        // A given distance is kept.
        let far = Orbit {
            distance: Some(40.0),
            ..Orbit::default()
        };
        let cam = orbit_camera(lo, hi, 1.0, &far).unwrap();
        let d: f32 = (0..3).map(|k| (cam.eye[k] - cam.target[k]).powi(2)).sum();
        assert!((d.sqrt() - 40.0).abs() < 1e-4);
        // Bad angles and distances name their parameter.
        for (orbit, param) in [
            (
                Orbit {
                    pitch_deg: 90.0,
                    ..Orbit::default()
                },
                Param::Pitch,
            ),
            (
                Orbit {
                    yaw_deg: f64::NAN,
                    ..Orbit::default()
                },
                Param::Yaw,
            ),
            (
                Orbit {
                    distance: Some(-1.0),
                    ..Orbit::default()
                },
                Param::Distance,
            ),
        ] {
            match orbit_camera(lo, hi, 1.0, &orbit) {
                Err(Error::Refused { message, .. }) => {
                    assert!(message.to_string().starts_with(param.name()), "{message}")
                }
                other => panic!("{orbit:?}: {other:?}"),
            }
        }
    }

    #[test]
    fn file_cameras_look_down_their_nodes_minus_z() {
        // A perspective camera at (0, 1, 5), turned 90° about +y (it looks along −x), with a
        // uniform scale of 2 that must not matter.
        let (c, s) = (0.0f32, 1.0f32);
        let world = [
            [2.0 * c, 0.0, -2.0 * s, 0.0],
            [0.0, 2.0, 0.0, 0.0],
            [2.0 * s, 0.0, 2.0 * c, 0.0],
            [0.0, 1.0, 5.0, 1.0],
        ];
        let camera = GltfCamera {
            name: "test".into(),
            world,
            projection: GltfProjection::Perspective {
                yfov_rad: 0.8,
                znear: 0.1,
                zfar: Some(100.0),
            },
        };
        let cam = file_camera(&camera, [-1.0; 3], [1.0; 3], 2.0).unwrap();
        assert_eq!(cam.eye, [0.0, 1.0, 5.0]);
        let ahead = project(&cam.view_proj, [-3.0, 1.0, 5.0]);
        assert!(ahead[0].abs() < 1e-6 && ahead[1].abs() < 1e-6, "{ahead:?}");
        assert!((0.0..1.0).contains(&ahead[2]));
        // Up in the world is up in the picture; the field of view is yfov.
        let above = project(&cam.view_proj, [-3.0, 1.0 + 3.0 * (0.4f32).tan(), 5.0]);
        assert!((above[1] - 1.0).abs() < 1e-4, "{above:?}");
        assert!((cam.fov_y_deg - 0.8f32.to_degrees()).abs() < 1e-4);
        // Behind the camera is outside the depth range; an infinite far plane works.
        let behind = project(&cam.view_proj, [3.0, 1.0, 5.0]);
        assert!(!(0.0..=1.0).contains(&behind[2]) || behind[0].abs() > 1.0);
        let infinite = GltfCamera {
            projection: GltfProjection::Perspective {
                yfov_rad: 0.8,
                znear: 0.1,
                zfar: None,
            },
            ..camera.clone()
        };
        let cam = file_camera(&infinite, [-1.0; 3], [1.0; 3], 2.0).unwrap();
        let far_away = project(&cam.view_proj, [-1e5, 1.0, 5.0]);
        assert!((0.0..=1.0).contains(&far_away[2]), "{far_away:?}");
        // Orthographic: ymag is the half-height.
        let ortho = GltfCamera {
            projection: GltfProjection::Orthographic {
                xmag: 3.0,
                ymag: 1.5,
                znear: 0.0,
                zfar: 50.0,
            },
            ..camera
        };
        let cam = file_camera(&ortho, [-1.0; 3], [1.0; 3], 2.0).unwrap();
        let top = project(&cam.view_proj, [-10.0, 2.5, 5.0]);
        assert!((top[1] - 1.0).abs() < 1e-5, "{top:?}");
        let side = project(&cam.view_proj, [-10.0, 1.0, 5.0 - 3.0]);
        assert!((side[0].abs() - 1.0).abs() < 1e-5, "{side:?}");
    }
}
