//! glTF 2.0 / GLB scenes for `nacre render --gltf`: triangle meshes (positions, normals,
//! tangents, two texture-coordinate sets, vertex colours, indexed or not, node transforms
//! applied) and their materials — the core metallic-roughness model with all its textures,
//! `KHR_materials_iridescence`, `KHR_materials_ior`, `KHR_materials_specular`,
//! `KHR_materials_emissive_strength`, `KHR_materials_unlit`, `KHR_texture_transform`, `KHR_texture_basisu`, `KHR_materials_transmission`
//! and `KHR_materials_volume` (thickness factor and attenuation) — mapped onto nacre's [`MaterialOptions`] (the uniform
//! parameters) and [`GltfMaterial`]'s textures (read per fragment by `shaders/mesh.wgsl`).
//!
//! # What is read (glTF 2.0 specification §3.7–§3.9)
//!
//! * `extensionsRequired`: accepted when every entry is in [`SUPPORTED_EXTENSIONS`], refused
//!   otherwise with a message naming the file and the extension (§3.12: a client that does
//!   not support a required extension must not load the file);
//! * primitives of every mode of §3.7.2.1: TRIANGLES (4), TRIANGLE_STRIP (5) and
//!   TRIANGLE_FAN (6), strips and fans made triangle lists; POINTS (0), LINES (1), LINE_LOOP
//!   (2) and LINE_STRIP (3), strips and loops made line lists (a loop closes back to its
//!   first vertex) and drawn one pixel wide (wgpu has no point size or line width); lines and
//!   points without normals are drawn unlit in their base colour (the spec's flat normals
//!   are for triangles; a line or point has no surface to light); missing normals of
//!   triangles become flat normals, missing tangents of a
//!   normal-mapped primitive MikkTSpace tangents (`bevy_mikktspace`, as §3.7.2.1 prescribes),
//!   computed after the node transform; a mirroring node transform (negative determinant)
//!   reverses the triangles' winding (§3.5.3);
//! * textures ([`textures`]): PNG and JPEG pictures (in buffer views, `data:` URIs or files)
//!   and `KHR_texture_basisu` KTX2 files (ETC1S and UASTC, transcoded on the CPU: [`basisu`];
//!   a damaged one is an error), RGBA8, colour
//!   textures (base colour, emissive, specular colour) decoded from sRGB by the GPU's sRGB
//!   format, mipmaps made on upload; the texture's sampler (wrap modes, filters); WebP and
//!   others are not decoded (the texture is ignored with a note, its factor kept).
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
//! | `metallicFactor` 1, no texture | the uniform's base: a metal from the base colour ([`rgb_metal_for`], or [`per_channel_metal`] where its fit misses a channel: [`gltf_metal_for`]) |
//! | `baseColorFactor` × texture × `COLOR_0` | the dielectric lobe's Lambertian albedo; the metal lobe's F0: the uniform's metal ([`rgb_metal_for`], each channel's F0 where its sensitivity lies) where the colour is the factor's alone, else [`metal_index_gulbrandsen2014`] of the fragment's colour |
//! | `roughnessFactor` r × texture G | GGX α = r² |
//! | `transmissionFactor` t | the share t of the dielectric lobe that transmits: the opaque scene behind, refracted in screen space (the environment where it shows nothing), tinted by the base colour |
//! | `KHR_materials_volume` `thicknessFactor`, `attenuationDistance`, `attenuationColor` | the refracted ray's length inside, and Beer–Lambert attenuation along it |
//! | `specularFactor` × `specularColorFactor` (+ textures) | scale of the dielectric lobe's reflectance |
//! | normal, occlusion, emissive (× `emissiveStrength`) | per fragment (`shaders/mesh.wgsl`) |
//!
//! Accessors (`accessor.rs`) may be sparse (§3.6.2.3: the listed elements replace those of
//! the buffer view, or of zeros without one; indices out of range or not increasing are
//! errors) and, with `KHR_mesh_quantization`, positions, normals, tangents and texture
//! coordinates may be integers, normalised or not (the node transform dequantises them).
//! `KHR_draco_mesh_compression` primitives (`draco.rs`) are decoded by `draco-oxide-decoder`:
//! the extension's map of unique ids picks the attributes, the decoder dequantises them, and
//! an optional extension falls back to the uncompressed accessors when the stream does not
//! decode.
//!
//! Skins, morph targets,
//! `transmissionTexture`, `thicknessTexture`, `KHR_materials_clearcoat`, `_sheen` and
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
//! colour of the bare metal is the glTF colour (see [`rgb_metal_for`]). Where those bands,
//! read once per channel as `lut` and `fourier` read the uniform's base, miss the colour
//! (a saturated one: [`band_fit_misses`]), the uniform's metal is Gulbrandsen's per channel
//! instead ([`gltf_metal_for`], [`per_channel_metal`]), exact at normal incidence there.

use crate::error::{Error, Result};
use crate::thickness_map::ThicknessMap;
use std::path::{Path, PathBuf};

mod accessor;
pub mod assets;
pub mod basisu;
mod document;
mod draco;
pub mod error;
mod limits;
mod materials;
pub mod metal;
mod model;
mod nodes;
mod primitive;
pub mod textures;

pub use document::SUPPORTED_EXTENSIONS;
pub use error::{GltfError, Ktx2Error};
pub use limits::{MAX_FILE_BYTES, MAX_INDICES, MAX_VERTICES};
pub use metal::{
    BAND_FIT_TOLERANCE_SRGB, GOLD_F0, MetalBands, band_fit_misses, gltf_metal_for, is_gold_like,
    metal_index_gulbrandsen2014, per_channel_metal, rgb_metal_for,
};
pub use model::{
    AlphaMode, Clearcoat, GltfCamera, GltfLight, GltfMaterial, GltfPrimitive, GltfProjection,
    Iridescence, LightKind, MaterialTextures, Topology, Volume,
};
pub use textures::{
    GltfTexture, IDENTITY_TRANSFORM, MAX_TEXTURE_DIMENSION, SamplerSpec, TextureRef, Wrap,
    texture_transform,
};

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

impl GltfError {
    /// This error about the file at `path`, as the runtime's [`Error`] (defined here, not in
    /// `error.rs`, which imports nothing of the crate).
    pub fn at(self, path: &Path) -> Error {
        Error::Gltf {
            path: path.to_path_buf(),
            error: self,
        }
    }
}

impl GltfScene {
    /// The least and greatest metallic value material `material` takes: its
    /// [`GltfMaterial::metallic_range`], narrowed by the decoded `metallicRoughnessTexture`'s
    /// blue channel (glTF 2.0 §3.9.2: metallic = `metallicFactor` × B), so that a texture
    /// whose B is 0 everywhere (IridescentDishWithOlives' `glassCover`) makes a dielectric.
    /// Without the texture's texels (skipped at load) the material's own bound stands.
    pub fn metallic_range(&self, material: usize) -> (f32, f32) {
        let Some(gm) = self.materials.get(material) else {
            return (0.0, 1.0);
        };
        let (lo, hi) = gm.metallic_range();
        let texels = gm
            .textures
            .metallic_roughness
            .and_then(|r| self.textures.get(r.texture))
            .filter(|t| !t.rgba.is_empty());
        match texels {
            Some(t) => {
                let (b_min, b_max) = t
                    .rgba
                    .chunks_exact(4)
                    .fold((u8::MAX, 0u8), |(a, b), px| (a.min(px[2]), b.max(px[2])));
                (hi * f32::from(b_min) / 255.0, hi * f32::from(b_max) / 255.0)
            }
            None => (lo, hi),
        }
    }

    /// Reads a `.gltf` (JSON, buffers embedded as `data:` URIs or in files beside it) or a
    /// `.glb` file.
    pub fn load(path: &Path) -> Result<GltfScene> {
        let io = |source| Error::Io {
            path: path.to_path_buf(),
            source,
        };
        let size = std::fs::metadata(path).map_err(io)?.len();
        if size > MAX_FILE_BYTES {
            return Err(GltfError::TooLarge {
                bytes: size,
                max: MAX_FILE_BYTES,
            }
            .at(path));
        }
        let bytes = std::fs::read(path).map_err(io)?;
        GltfScene::from_bytes(&bytes, path)
    }

    /// Parses glTF or GLB bytes; `path` names the file in errors and locates external buffers.
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<GltfScene> {
        let (gltf, required) = document::open(bytes, path)?;
        let buffers = document::read_buffers(&gltf, path)?;
        let materials::Materials {
            materials,
            thickness_maps,
            textures,
            mut notes,
        } = materials::read(&gltf.document, &buffers, path)?;
        let draco_required = required.iter().any(|e| e == draco::EXTENSION);
        let placed = nodes::place(&gltf.document, &buffers, path, &materials, draco_required)?;
        notes.extend(placed.notes);
        if placed.primitives.iter().all(|p| p.indices.is_empty()) {
            return Err(GltfError::NoTriangles.at(path));
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
