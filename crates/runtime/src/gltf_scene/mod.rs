//! glTF 2.0 / GLB scenes for `nacre render --gltf`: triangle meshes (positions, normals,
//! tangents, two texture-coordinate sets, vertex colours, indexed or not, node transforms
//! applied) and their materials — the core metallic-roughness model with all its textures,
//! `KHR_materials_iridescence`, `KHR_materials_ior`, `KHR_materials_specular`,
//! `KHR_materials_emissive_strength`, `KHR_texture_transform`, `KHR_materials_transmission`
//! and `KHR_materials_volume` (thickness factor and attenuation) — mapped onto nacre's [`MaterialOptions`] (the uniform
//! parameters) and [`GltfMaterial`]'s textures (read per fragment by `shaders/mesh.wgsl`).
//!
//! # What is read (glTF 2.0 specification §3.7–§3.9)
//!
//! * `extensionsRequired`: accepted when every entry is in [`SUPPORTED_EXTENSIONS`], refused
//!   otherwise with a message naming the file and the extension (§3.12: a client that does
//!   not support a required extension must not load the file);
//! * primitives of mode TRIANGLES (4); points, lines, strips and fans are skipped with one
//!   note counting them; missing normals become flat normals, missing tangents of a
//!   normal-mapped primitive MikkTSpace tangents (`bevy_mikktspace`, as §3.7.2.1 prescribes),
//!   computed after the node transform; a mirroring node transform (negative determinant)
//!   reverses the triangles' winding (§3.5.3);
//! * textures ([`crate::gltf_textures`]): PNG and JPEG pictures (in buffer views, `data:` URIs or files), RGBA8, colour
//!   textures (base colour, emissive, specular colour) decoded from sRGB by the GPU's sRGB
//!   format, mipmaps made on upload; the texture's sampler (wrap modes, filters); KTX2/Basis
//!   (`KHR_texture_basisu`), WebP and others are not decoded (the texture is ignored with a
//!   note, its factor kept).
//!
//! # The mapping (glTF → [`MaterialOptions`])
//!
//! | glTF | nacre |
//! |---|---|
//! | `iridescenceIor` (default 1.3) | `film_ior` n₂ |
//! | `iridescenceThicknessMinimum` / `Maximum` (100 / 400 nm) | [`ThicknessMapping::Gltf`] d = mix(d_min, d_max, g) |
//! | `iridescenceThicknessTexture` (PNG) | g = its green channel at the primitive's `texCoord` set; without a texture g = 1, so d = d_max (the extension's rule) |
//! | `iridescenceFactor` (default 0 without the extension) | `film_weight` w: F = mix(F_base, F_film, w) |
//! | `iridescenceTexture` | its red channel multiplies w per fragment |
//! | `ior` (`KHR_materials_ior`, default 1.5) | a dielectric base of real index `ior` |
//! | `metallicFactor` m × texture B | per fragment mix(dielectric lobe, metal lobe, m) (glTF Appendix B), the film on both lobes |
//! | `metallicFactor` 1, no texture | the uniform's base: a metal from the base colour ([`rgb_metal_for`]) |
//! | `baseColorFactor` × texture × `COLOR_0` | the dielectric lobe's Lambertian albedo; the metal lobe's F0: the uniform's metal ([`rgb_metal_for`], each channel's F0 where its sensitivity lies) where the colour is the factor's alone, else [`metal_index_gulbrandsen2014`] of the fragment's colour |
//! | `roughnessFactor` r × texture G | GGX α = r² |
//! | `transmissionFactor` t | the share t of the dielectric lobe that transmits: the opaque scene behind, refracted in screen space (the environment where it shows nothing), tinted by the base colour |
//! | `KHR_materials_volume` `thicknessFactor`, `attenuationDistance`, `attenuationColor` | the refracted ray's length inside, and Beer–Lambert attenuation along it |
//! | `specularFactor` × `specularColorFactor` (+ textures) | scale of the dielectric lobe's reflectance |
//! | normal, occlusion, emissive (× `emissiveStrength`) | per fragment (`shaders/mesh.wgsl`) |
//!
//! Skins, morph targets, sparse accessors, quantised positions (`KHR_mesh_quantization`),
//! Draco, `transmissionTexture`, `thicknessTexture`, `KHR_materials_clearcoat`, `_sheen` and
//! `_anisotropy` are not read. The default scene's cameras (perspective and orthographic, placed by their
//! nodes: [`GltfScene::cameras`]) and `KHR_lights_punctual` lights ([`GltfScene::lights`])
//! are read; see `mesh/lights.rs` for how the renderer lights the scene with them.
//!
//! # Metals from a base colour
//!
//! glTF gives a metal only its reflectance at normal incidence F0 (= `baseColorFactor`), while
//! the film needs the metal's complex index n + iκ (the film changes the phase of the metal's
//! reflection). nacre inverts F0 per RGB channel with the "artist-friendly" mapping of
//! O. Gulbrandsen, "Artist Friendly Metallic Fresnel", JCGT 3(4), 2014, Eq. (1)–(2), with the
//! edge tint g equal to the base colour:
//!
//! ```text
//! n = g (1 − r)/(1 + r) + (1 − g) (1 + √r)/(1 − √r)
//! κ = √( (r (n + 1)² − (n − 1)²) / (1 − r) )          r = F0 ∈ [0, 0.99]
//! ```
//!
//! which reproduces F0 exactly at normal incidence. The result is an approximation: a real
//! metal's index varies inside each channel, and its edge tint is not its base colour.
//! `film_fourier` takes one index per channel (per fragment in `shaders/mesh.wgsl`, from the
//! textured base colour); `film_spectral` one per wavelength: [`rgb_metal_for`] builds a
//! piecewise-constant dispersion over three bands split where the colorimeter's channel
//! sensitivities cross, each band's reflectance chosen so that the spectrally integrated
//! colour of the bare metal is the glTF colour (see [`rgb_metal_for`]).

use crate::error::{Error, Result};
pub use crate::gltf_textures::{
    GltfTexture, IDENTITY_TRANSFORM, MAX_TEXTURE_DIMENSION, SamplerSpec, TextureRef, Wrap,
    texture_transform,
};
use crate::render::{BaseKind, MaterialOptions, SceneKind, ThicknessMapping};
use crate::thickness_map::ThicknessMap;
pub(crate) use document::base64_decode;
use nacre_optics::colour::Colorimeter;
use nacre_optics::{C64, Material};
use std::path::{Path, PathBuf};

mod document;
mod materials;
mod nodes;
mod primitive;

/// The glTF extensions nacre implements: a file whose `extensionsRequired` lists only these
/// loads (`KHR_materials_transmission` and `_volume` refract the opaque scene in screen
/// space, as the glTF Sample Viewer does: `shaders/mesh.wgsl`).
pub const SUPPORTED_EXTENSIONS: [&str; 8] = [
    "KHR_lights_punctual",
    "KHR_materials_iridescence",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_emissive_strength",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_texture_transform",
];

/// Largest glTF/GLB file read, bytes (and largest external buffer).
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// Largest number of vertices over all primitives.
pub const MAX_VERTICES: usize = 4_000_000;

/// Largest number of triangle corners (indices) over all primitives.
pub const MAX_INDICES: usize = 12_000_000;

/// Linear base colour of gold at normal incidence (the glTF specification's reference metal
/// table, "gold": 1.000, 0.766, 0.336).
pub const GOLD_F0: [f32; 3] = [1.0, 0.766, 0.336];

/// `KHR_materials_iridescence` of one material (defaults from the extension).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Iridescence {
    /// `iridescenceFactor` (default 0), the film weight.
    pub factor: f32,
    /// `iridescenceIor` (default 1.3), the film index.
    pub ior: f32,
    /// `iridescenceThicknessMinimum`, nm (default 100).
    pub thickness_min_nm: f32,
    /// `iridescenceThicknessMaximum`, nm (default 400).
    pub thickness_max_nm: f32,
    /// Whether an `iridescenceThicknessTexture` is given.
    pub has_thickness_texture: bool,
    /// The `iridescenceThicknessTexture`'s texture index and `texCoord` set.
    pub thickness_texture: Option<(usize, u32)>,
    /// Whether an `iridescenceTexture` is given (not read).
    pub has_texture: bool,
}

impl Default for Iridescence {
    fn default() -> Self {
        Iridescence {
            factor: 0.0,
            ior: 1.3,
            thickness_min_nm: 100.0,
            thickness_max_nm: 400.0,
            has_thickness_texture: false,
            thickness_texture: None,
            has_texture: false,
        }
    }
}

/// `alphaMode` (glTF §3.9.4).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AlphaMode {
    /// OPAQUE: alpha ignored.
    #[default]
    Opaque,
    /// MASK: fragments with alpha below the cutoff are discarded.
    Mask(f32),
    /// BLEND: composited over what is behind (drawn after opaque primitives, back to front).
    Blend,
}

/// The textures of one material (each `None` when absent or not decodable).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MaterialTextures {
    /// `baseColorTexture` (sRGB).
    pub base_colour: Option<TextureRef>,
    /// `metallicRoughnessTexture` (G roughness, B metallic).
    pub metallic_roughness: Option<TextureRef>,
    /// `normalTexture` (tangent space).
    pub normal: Option<TextureRef>,
    /// `occlusionTexture` (R).
    pub occlusion: Option<TextureRef>,
    /// `emissiveTexture` (sRGB).
    pub emissive: Option<TextureRef>,
    /// `iridescenceTexture` (R: film weight).
    pub iridescence: Option<TextureRef>,
    /// `iridescenceThicknessTexture` (G): decoded into [`GltfScene::thickness_maps`]; this
    /// holds its coordinates only.
    pub thickness: Option<TextureRef>,
    /// `specularTexture` (A).
    pub specular: Option<TextureRef>,
    /// `specularColorTexture` (sRGB).
    pub specular_colour: Option<TextureRef>,
}

/// `KHR_materials_volume`: the volume under a transmissive surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Volume {
    /// `thicknessFactor`: the volume's thickness, in the mesh's (local) units (default 0:
    /// thin-walled). Its `thicknessTexture` is not read.
    pub thickness: f32,
    /// `attenuationDistance`: the distance at which light takes `attenuation_colour`
    /// (default +∞: none).
    pub attenuation_distance: f32,
    /// `attenuationColor`, linear RGB (default 1).
    pub attenuation_colour: [f32; 3],
}

/// One glTF material's parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfMaterial {
    /// The material's name, or `material N` / `default material`.
    pub name: String,
    /// `baseColorFactor`, linear RGBA (default 1).
    pub base_colour: [f32; 4],
    /// `metallicFactor` (default 1).
    pub metallic: f32,
    /// `roughnessFactor`, perceptual (default 1).
    pub roughness: f32,
    /// `KHR_materials_ior` `ior` (default 1.5).
    pub ior: f32,
    /// `KHR_materials_transmission` `transmissionFactor` (default 0).
    pub transmission: f32,
    /// `KHR_materials_volume`, if present.
    pub volume: Option<Volume>,
    /// `KHR_materials_iridescence`, if present.
    pub iridescence: Option<Iridescence>,
    /// `alphaMode` and `alphaCutoff` (default 0.5).
    pub alpha_mode: AlphaMode,
    /// `doubleSided`.
    pub double_sided: bool,
    /// `emissiveFactor` × `KHR_materials_emissive_strength` `emissiveStrength`.
    pub emissive: [f32; 3],
    /// `KHR_materials_specular` `specularFactor` (default 1).
    pub specular: f32,
    /// `KHR_materials_specular` `specularColorFactor` (default 1).
    pub specular_colour: [f32; 3],
    /// `normalTexture.scale` (default 1).
    pub normal_scale: f32,
    /// `occlusionTexture.strength` (default 1).
    pub occlusion_strength: f32,
    /// The textures.
    pub textures: MaterialTextures,
}

impl Default for GltfMaterial {
    /// The glTF default material (no `material` on a primitive).
    fn default() -> Self {
        GltfMaterial {
            name: "default material".into(),
            base_colour: [1.0; 4],
            metallic: 1.0,
            roughness: 1.0,
            ior: 1.5,
            transmission: 0.0,
            volume: None,
            iridescence: None,
            alpha_mode: AlphaMode::Opaque,
            double_sided: false,
            emissive: [0.0; 3],
            specular: 1.0,
            specular_colour: [1.0; 3],
            normal_scale: 1.0,
            occlusion_strength: 1.0,
            textures: MaterialTextures::default(),
        }
    }
}

pub use crate::gltf_metal::{MetalBands, is_gold_like, metal_index_gulbrandsen2014, rgb_metal_for};

impl GltfMaterial {
    /// The range (lowest, highest) of the per-fragment metallic value: `metallicFactor` × the
    /// texture's blue channel (0 to the factor with a texture).
    pub fn metallic_range(&self) -> (f32, f32) {
        let m = if self.metallic.is_finite() {
            self.metallic.clamp(0.0, 1.0)
        } else {
            1.0
        };
        if self.textures.metallic_roughness.is_some() {
            (0.0, m)
        } else {
            (m, m)
        }
    }

    /// The material as nacre's uniform holds it (the module's mapping table), plus notes
    /// about what was approximated or ignored. The uniform's base is a metal
    /// ([`rgb_metal_for`] of the base colour factor, bands of `colorimeter`) when every
    /// fragment is fully metallic, else the dielectric of index `ior`; the fragment shader
    /// mixes both lobes per fragment.
    pub fn material_options(
        &self,
        colorimeter: &Colorimeter,
    ) -> Result<(MaterialOptions, Vec<String>)> {
        let mut notes = Vec::new();
        let mut m = MaterialOptions::for_scene(SceneKind::Sphere);
        let clamp01 = |x: f32| {
            if x.is_finite() {
                x.clamp(0.0, 1.0)
            } else {
                0.0
            }
        };
        let rgb = [0, 1, 2].map(|j| clamp01(self.base_colour[j]));
        let iri = self.iridescence.unwrap_or_default();
        m.film_ior = iri.ior;
        m.thickness = ThicknessMapping::Gltf {
            min_nm: iri.thickness_min_nm,
            max_nm: iri.thickness_max_nm,
        };
        m.film_weight = clamp01(iri.factor);
        m.thickness_roughness_nm = 0.0;
        m.drain_nm = 0.0;
        m.ambient_ior = 1.0;
        let r = clamp01(self.roughness);
        m.roughness_alpha = r * r;
        // The uniform's base: a metal when the metallic factor is at least 0.5 (the metal
        // lobe's index wherever no texture or vertex colour changes the base colour:
        // shaders/mesh.wgsl), else the dielectric; the `lut` table's base and the one the
        // `spectral` technique integrates over.
        if clamp01(self.metallic) >= 0.5 {
            let bands = MetalBands::new(colorimeter);
            m.base = rgb_metal_for(
                &format!("{} (Gulbrandsen 2014, 3 bands)", self.name),
                rgb.map(f64::from),
                &bands,
            )?;
            m.base_kind = BaseKind::Metal;
            m.base_colour = [0.0; 3];
            m.transmission = false;
        } else {
            let ior = if self.ior.is_finite() && self.ior >= 1.0 {
                self.ior
            } else {
                // glTF allows ior = 0 (a "perfect mirror" hint); nacre needs a real index.
                notes.push(format!(
                    "{}: ior {} is not an index ≥ 1; using 1.5",
                    self.name, self.ior
                ));
                1.5
            };
            m.base = Material::constant(format!("{ior}"), C64::new(f64::from(ior), 0.0))
                .map_err(crate::Error::from)?;
            m.base_kind = BaseKind::Dielectric;
            // A thin shell when transmissionFactor ≥ 0.5 (the uniform has no partial share).
            m.transmission = clamp01(self.transmission) >= 0.5;
            m.base_colour = rgb;
        }
        m.validate().map_err(|e| Error::Invalid {
            context: format!("glTF material `{}`", self.name),
            message: e.to_string(),
        })?;
        Ok((m, notes))
    }

    /// The dielectric index the fragment shader uses (`ior`, or 1.5 when not an index ≥ 1).
    pub fn dielectric_ior(&self) -> f32 {
        if self.ior.is_finite() && self.ior >= 1.0 {
            self.ior
        } else {
            1.5
        }
    }
}

/// One triangle list in world space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GltfPrimitive {
    /// World-space positions.
    pub positions: Vec<[f32; 3]>,
    /// World-space unit normals (one per position).
    pub normals: Vec<[f32; 3]>,
    /// World-space tangents (xyz unit, w = ±1 the bitangent's sign; one per position), from
    /// the file or MikkTSpace for normal-mapped primitives; empty when neither.
    pub tangents: Vec<[f32; 4]>,
    /// TEXCOORD_0 (one per position; zeros when the primitive has none).
    pub uvs: Vec<[f32; 2]>,
    /// TEXCOORD_1 (one per position; a copy of TEXCOORD_0 when the primitive has none).
    pub uvs1: Vec<[f32; 2]>,
    /// COLOR_0 as linear RGBA (one per position; white when the primitive has none).
    pub colours: Vec<[f32; 4]>,
    /// Triangle corners (three per triangle), indices into `positions`.
    pub indices: Vec<u32>,
    /// Index into [`GltfScene::materials`].
    pub material: usize,
}

/// A glTF scene flattened to world-space triangle lists.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GltfScene {
    /// The file it came from.
    pub path: PathBuf,
    /// The primitives of every mesh instance of the default scene (or of every root node when
    /// the file has no scene).
    pub primitives: Vec<GltfPrimitive>,
    /// The document's materials, then the default material.
    pub materials: Vec<GltfMaterial>,
    /// Per material, its decoded `iridescenceThicknessTexture` (green channel → g), if any.
    pub thickness_maps: Vec<Option<ThicknessMap>>,
    /// The decoded textures the materials refer to ([`TextureRef::texture`]).
    pub textures: Vec<GltfTexture>,
    /// What the loader could not read (textures it skipped), one line each.
    pub notes: Vec<String>,
    /// The `KHR_lights_punctual` lights placed by the default scene's nodes, in node index
    /// order.
    pub lights: Vec<GltfLight>,
    /// The cameras placed by the default scene's nodes, in node index order (a node used
    /// twice in the tree places its camera twice): `nacre render --camera N`.
    pub cameras: Vec<GltfCamera>,
}

/// The kind of a `KHR_lights_punctual` light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Infinitely far, shining along the node's −z; intensity in lux.
    Directional,
    /// At the node's position, in every direction; intensity in candela.
    Point,
    /// At the node's position, a cone about the node's −z; intensity in candela.
    Spot {
        /// Inner cone angle, radians.
        inner_cone_rad: f32,
        /// Outer cone angle, radians.
        outer_cone_rad: f32,
    },
}

/// A `KHR_lights_punctual` light placed by a node.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfLight {
    /// The light's `name`, or `light K`.
    pub name: String,
    /// Directional, point or spot.
    pub kind: LightKind,
    /// `color`, linear RGB (default 1).
    pub colour: [f32; 3],
    /// `intensity` (default 1): lux for a directional light, candela otherwise.
    pub intensity: f32,
    /// The node's world position (unused by a directional light).
    pub position: [f32; 3],
    /// Unit direction the light shines along (the node's world −z).
    pub direction: [f32; 3],
    /// `range`: the distance beyond which a point or spot light gives nothing (`None`:
    /// unlimited).
    pub range: Option<f32>,
}

/// How a glTF camera projects (glTF 2.0 §3.10).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GltfProjection {
    /// `yfov` radians, `znear`, `zfar` (None: infinite); the image's aspect is used.
    Perspective {
        /// Vertical field of view, radians.
        yfov_rad: f32,
        /// Near plane distance, world units.
        znear: f32,
        /// Far plane distance, world units (None: infinite projection).
        zfar: Option<f32>,
    },
    /// Half-width `xmag` and half-height `ymag` of the view volume, `znear`, `zfar`.
    Orthographic {
        /// Half the view's width, world units.
        xmag: f32,
        /// Half the view's height, world units.
        ymag: f32,
        /// Near plane distance, world units.
        znear: f32,
        /// Far plane distance, world units.
        zfar: f32,
    },
}

/// A camera placed by a node: it looks down the node's −z axis with +y up (§3.10).
#[derive(Clone, Debug, PartialEq)]
pub struct GltfCamera {
    /// The camera's `name`, or `camera K` (its index in the file).
    pub name: String,
    /// The node's world transform (column-major; scale is removed when the camera is used).
    pub world: [[f32; 4]; 4],
    /// Its projection.
    pub projection: GltfProjection,
}

fn invalid(path: &Path, message: impl Into<String>) -> Error {
    Error::Invalid {
        context: format!("glTF {}", path.display()),
        message: message.into(),
    }
}

impl GltfScene {
    /// Reads a `.gltf` (JSON, buffers embedded as `data:` URIs or in files beside it) or a
    /// `.glb` file.
    pub fn load(path: &Path) -> Result<GltfScene> {
        let io = |source| Error::Io {
            path: path.to_path_buf(),
            source,
        };
        let size = std::fs::metadata(path).map_err(io)?.len();
        if size > MAX_FILE_BYTES {
            return Err(invalid(
                path,
                format!("{size} bytes (at most {MAX_FILE_BYTES})"),
            ));
        }
        let bytes = std::fs::read(path).map_err(io)?;
        GltfScene::from_bytes(&bytes, path)
    }

    /// Parses glTF or GLB bytes; `path` names the file in errors and locates external buffers.
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<GltfScene> {
        let gltf = document::open(bytes, path)?;
        let buffers = document::read_buffers(&gltf, path)?;
        let materials::Materials {
            materials,
            thickness_maps,
            textures,
            mut notes,
        } = materials::read(&gltf.document, &buffers, path);
        let placed = nodes::place(&gltf.document, &buffers, path, &materials)?;
        if !placed.skipped.is_empty() {
            let total: usize = placed.skipped.values().sum();
            let kinds: Vec<String> = placed
                .skipped
                .iter()
                .map(|(k, n)| format!("{n} {k}"))
                .collect();
            notes.push(format!(
                "skipped {total} primitive(s) nacre does not draw ({}); only triangle lists are drawn",
                kinds.join(", ")
            ));
        }
        if placed.primitives.iter().all(|p| p.indices.is_empty()) {
            return Err(invalid(path, "the scene has no triangles"));
        }
        Ok(GltfScene {
            path: path.to_path_buf(),
            primitives: placed.primitives,
            materials,
            thickness_maps,
            textures,
            notes,
            cameras: placed.cameras,
            lights: placed.lights,
        })
    }

    /// The axis-aligned bounds (min, max) of every vertex, world units.
    pub fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for p in self.primitives.iter().flat_map(|p| &p.positions) {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }
}

#[cfg(test)]
mod tests;
