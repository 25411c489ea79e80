//! The loaded scene's data: materials (glTF §3.9 and the extensions nacre reads), world-space
//! triangle, line and point primitives, `KHR_lights_punctual` lights and cameras.

use super::metal::{MetalBands, gltf_metal_for};
use super::textures::TextureRef;
use crate::error::{Error, Result};
use crate::render::{BaseKind, MaterialOptions, SceneKind, ThicknessMapping};
use nacre_optics::colour::Colorimeter;
use nacre_optics::{C64, Material};

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

/// `KHR_materials_clearcoat` of one material (defaults from the extension): a clear
/// dielectric coat of index 1.5 (F0 = 0.04) over the whole material, with its own GGX
/// roughness and normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearcoat {
    /// `clearcoatFactor` (default 0), the coat's intensity.
    pub factor: f32,
    /// `clearcoatRoughnessFactor` (default 0), perceptual: GGX α = roughness².
    pub roughness: f32,
    /// `clearcoatNormalTexture.scale` (default 1).
    pub normal_scale: f32,
}

impl Default for Clearcoat {
    fn default() -> Self {
        Clearcoat {
            factor: 0.0,
            roughness: 0.0,
            normal_scale: 1.0,
        }
    }
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
    /// `clearcoatTexture` (R: × `clearcoatFactor`).
    pub clearcoat: Option<TextureRef>,
    /// `clearcoatRoughnessTexture` (G: × `clearcoatRoughnessFactor`).
    pub clearcoat_roughness: Option<TextureRef>,
    /// `clearcoatNormalTexture` (tangent space, the coat's own normal).
    pub clearcoat_normal: Option<TextureRef>,
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
    /// `KHR_materials_clearcoat`, if present.
    pub clearcoat: Option<Clearcoat>,
    /// `alphaMode` and `alphaCutoff` (default 0.5).
    pub alpha_mode: AlphaMode,
    /// `doubleSided`.
    pub double_sided: bool,
    /// `emissiveFactor` × `KHR_materials_emissive_strength` `emissiveStrength`.
    pub emissive: [f32; 3],
    /// `KHR_materials_unlit`: the fragment's colour is base colour × texture × `COLOR_0`,
    /// without light, film or emission.
    pub unlit: bool,
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
            clearcoat: None,
            alpha_mode: AlphaMode::Opaque,
            double_sided: false,
            emissive: [0.0; 3],
            unlit: false,
            specular: 1.0,
            specular_colour: [1.0; 3],
            normal_scale: 1.0,
            occlusion_strength: 1.0,
            textures: MaterialTextures::default(),
        }
    }
}
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
    /// ([`gltf_metal_for`] of the base colour factor, bands of `colorimeter`) when every
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
            (m.base, _) = gltf_metal_for(&self.name, rgb.map(f64::from), &bands)?;
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

/// What a primitive's indices draw (glTF 2.0 §3.7.2.1, "Topology Types"): strips, loops
/// and fans are made lists on loading, so three kinds remain.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Topology {
    /// TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN: three corners per triangle.
    #[default]
    Triangles,
    /// LINES, LINE_STRIP, LINE_LOOP: two ends per segment, drawn one pixel wide (wgpu has
    /// no wide lines).
    Lines,
    /// POINTS: one index per point, drawn one pixel in size (wgpu, like WebGPU, has no
    /// point size).
    Points,
}

/// One primitive in world space: a triangle, line or point list.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GltfPrimitive {
    /// World-space positions.
    pub positions: Vec<[f32; 3]>,
    /// World-space unit normals (one per position; flat normals for triangles without
    /// any; empty for lines and points without any, which are drawn unlit).
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
    /// Indices into `positions`: triangle corners (three per triangle), line ends (two per
    /// segment) or points, as `topology` says.
    pub indices: Vec<u32>,
    /// What the indices draw.
    pub topology: Topology,
    /// Index into [`GltfScene::materials`].
    pub material: usize,
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
