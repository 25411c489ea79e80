//! `KHR_materials_iridescence` (and `KHR_materials_ior`) for Bevy's glTF loader.
//!
//! A [`GltfExtensionHandler`] that, for every glTF material with `KHR_materials_iridescence`,
//! adds a [`NacreMaterial`] (label `<material label>/nacre`) and gives the material's meshes
//! that instead of the `StandardMaterial` Bevy's own handler gave them. The extension's
//! parameters map one to one ([`film_from_gltf`]):
//!
//! | glTF | [`NacreFilm`] |
//! |---|---|
//! | `iridescenceFactor` (0) | `weight` |
//! | `iridescenceTexture` (R) | `weight_texture` |
//! | `iridescenceIor` (1.3) | `film_ior` |
//! | `iridescenceThicknessMinimum` / `Maximum` (100 / 400 nm) | `thickness` = `Gltf { min_nm, max_nm }` |
//! | `iridescenceThicknessTexture` (G) | `thickness_texture` |
//! | `KHR_materials_ior` `ior` (1.5) | `base_ior` (dielectric base) |
//! | metallic base colour | `base_ior` + i`base_kappa` per channel (Gulbrandsen 2014, edge tint = F₀) |
//!
//! Technique: the default film-lut table (film index 1.0–2.5, 0–1200 nm, air on a base of
//! index 1.5) where it covers the material exactly — a dielectric (`metallic` = 0) of index
//! 1.5 whose film index and thickness lie inside the table's axes — else `film_fourier`,
//! which takes any base.

use crate::material::{FilmTechnique, FilmThickness, NacreFilm, NacreMaterial};
use bevy::asset::{Handle, LoadContext};
use bevy::ecs::world::EntityWorldMut;
use bevy::gltf::GltfMaterial;
use bevy::gltf::extensions::{ErasedGltfExtensionHandler, GltfExtensionHandler};
use bevy::gltf::gltf;
use bevy::image::Image;
use bevy::math::Vec3;
use bevy::pbr::{ExtendedMaterial, MeshMaterial3d, StandardMaterial};
use std::collections::HashMap;

/// The extension's name.
pub const IRIDESCENCE: &str = "KHR_materials_iridescence";

/// Film axes of the default film-lut table (`tables/baked/film-dielectric.json`).
const LUT_IOR_RANGE: (f32, f32) = (1.0, 2.5);
const LUT_THICKNESS_MAX_NM: f32 = 1200.0;
const LUT_BASE_IOR: f32 = 1.5;

/// The loader hook (registered by [`crate::NacrePlugin`]).
#[derive(Default, Clone)]
pub struct NacreGltfHandler {
    /// glTF texture index → the image Bevy made of it, for the current file.
    textures: HashMap<usize, Handle<Image>>,
}

/// The complex index n + iκ whose normal-incidence reflectance from air is `f0` with edge
/// tint `g` (Gulbrandsen 2014, "Artist Friendly Metallic Fresnel", JCGT 3(4), Eq. 1–2; f0
/// clamped to [0, 0.99]), as nacre's runtime maps a glTF metal (`gltf_scene/metal.rs`).
pub fn metal_index_gulbrandsen2014(f0: f32, g: f32) -> (f32, f32) {
    let r = if f0.is_finite() {
        f0.clamp(0.0, 0.99)
    } else {
        0.5
    };
    let g = if g.is_finite() {
        g.clamp(0.0, 1.0)
    } else {
        0.5
    };
    let sr = r.sqrt();
    let n = g * (1.0 - r) / (1.0 + r) + (1.0 - g) * (1.0 + sr) / (1.0 - sr);
    let k2 = (r * (n + 1.0).powi(2) - (n - 1.0).powi(2)) / (1.0 - r);
    (n.max(1e-3), k2.max(0.0).sqrt())
}

fn number(v: &serde_json::Value, key: &str, default: f32) -> f32 {
    v.get(key)
        .and_then(serde_json::Value::as_f64)
        .map_or(default, |x| x as f32)
}

fn texture_index(v: &serde_json::Value, key: &str) -> Option<usize> {
    v.get(key)?
        .get("index")?
        .as_u64()
        .and_then(|i| usize::try_from(i).ok())
}

/// The film of a glTF material's `KHR_materials_iridescence` object `ext` (glTF defaults for
/// missing keys) on a base of index `ior`, metallic `metallic` and linear base colour
/// `base_colour`; `texture` maps glTF texture indices to images.
pub fn film_from_gltf(
    ext: &serde_json::Value,
    ior: f32,
    metallic: f32,
    base_colour: Vec3,
    texture: impl Fn(usize) -> Option<Handle<Image>>,
) -> NacreFilm {
    let film_ior = number(ext, "iridescenceIor", 1.3);
    let min_nm = number(ext, "iridescenceThicknessMinimum", 100.0);
    let max_nm = number(ext, "iridescenceThicknessMaximum", 400.0);
    let thickness_texture = texture_index(ext, "iridescenceThicknessTexture").and_then(&texture);
    // Without a thickness texture the film is d_max thick (glTF), so d_min does not matter.
    let thickness_top = if thickness_texture.is_some() {
        min_nm.max(max_nm)
    } else {
        max_nm
    };
    let thickness_bottom = if thickness_texture.is_some() {
        min_nm.min(max_nm)
    } else {
        max_nm
    };
    let lut_covers = metallic == 0.0
        && (ior - LUT_BASE_IOR).abs() < 1e-6
        && (LUT_IOR_RANGE.0..=LUT_IOR_RANGE.1).contains(&film_ior)
        && thickness_bottom >= 0.0
        && thickness_top <= LUT_THICKNESS_MAX_NM;
    let (base_ior, base_kappa) = if metallic > 0.0 {
        let nk = base_colour
            .to_array()
            .map(|f| metal_index_gulbrandsen2014(f, f));
        (
            Vec3::new(nk[0].0, nk[1].0, nk[2].0),
            Vec3::new(nk[0].1, nk[1].1, nk[2].1),
        )
    } else {
        (Vec3::splat(ior), Vec3::ZERO)
    };
    NacreFilm {
        technique: if lut_covers {
            FilmTechnique::Lut
        } else {
            FilmTechnique::Fourier
        },
        film_ior,
        thickness: FilmThickness::Gltf { min_nm, max_nm },
        thickness_texture,
        weight: number(ext, "iridescenceFactor", 0.0),
        weight_texture: texture_index(ext, "iridescenceTexture").and_then(&texture),
        base_ior,
        base_kappa,
        ..Default::default()
    }
}

/// `StandardMaterial` of a `GltfMaterial` (the fields every Bevy build has; what Bevy's own
/// handler builds, less the textures of optional cargo features).
pub fn standard_material(m: &GltfMaterial) -> StandardMaterial {
    StandardMaterial {
        base_color: m.base_color,
        base_color_channel: m.base_color_channel.clone(),
        base_color_texture: m.base_color_texture.clone(),
        emissive: m.emissive,
        emissive_channel: m.emissive_channel.clone(),
        emissive_texture: m.emissive_texture.clone(),
        perceptual_roughness: m.perceptual_roughness,
        metallic: m.metallic,
        metallic_roughness_channel: m.metallic_roughness_channel.clone(),
        metallic_roughness_texture: m.metallic_roughness_texture.clone(),
        reflectance: m.reflectance,
        specular_tint: m.specular_tint,
        specular_transmission: m.specular_transmission,
        thickness: m.thickness,
        ior: m.ior,
        attenuation_distance: m.attenuation_distance,
        attenuation_color: m.attenuation_color,
        normal_map_channel: m.normal_map_channel.clone(),
        normal_map_texture: m.normal_map_texture.clone(),
        occlusion_channel: m.occlusion_channel.clone(),
        occlusion_texture: m.occlusion_texture.clone(),
        clearcoat: m.clearcoat,
        clearcoat_perceptual_roughness: m.clearcoat_perceptual_roughness,
        anisotropy_strength: m.anisotropy_strength,
        anisotropy_rotation: m.anisotropy_rotation,
        double_sided: m.double_sided,
        cull_mode: m.cull_mode,
        unlit: m.unlit,
        alpha_mode: m.alpha_mode,
        uv_transform: m.uv_transform,
        ..Default::default()
    }
}

fn nacre_label(material_label: &str) -> String {
    format!("{material_label}/nacre")
}

impl GltfExtensionHandler for NacreGltfHandler {
    fn dyn_clone(&self) -> Box<dyn ErasedGltfExtensionHandler> {
        Box::new(self.clone())
    }

    fn on_texture(&mut self, gltf_texture: &gltf::Texture, texture: Handle<Image>) {
        self.textures.insert(gltf_texture.index(), texture);
    }

    fn on_material(
        &mut self,
        load_context: &mut LoadContext<'_>,
        gltf_material: &gltf::Material,
        _material: Handle<GltfMaterial>,
        material_asset: &GltfMaterial,
        material_label: &str,
    ) {
        let Some(ext) = gltf_material.extension_value(IRIDESCENCE) else {
            return;
        };
        let base_colour = material_asset.base_color.to_linear();
        let film = film_from_gltf(
            ext,
            material_asset.ior,
            material_asset.metallic,
            Vec3::new(base_colour.red, base_colour.green, base_colour.blue),
            |i| self.textures.get(&i).cloned(),
        );
        load_context.add_labeled_asset(
            nacre_label(material_label),
            ExtendedMaterial {
                base: standard_material(material_asset),
                extension: film,
            },
        );
    }

    fn on_spawn_mesh_and_material(
        &mut self,
        load_context: &mut LoadContext<'_>,
        _primitive: &gltf::Primitive,
        _mesh: &gltf::Mesh,
        material: &gltf::Material,
        entity: &mut EntityWorldMut,
        material_label: &str,
    ) {
        if material.extension_value(IRIDESCENCE).is_none() {
            return;
        }
        let handle = load_context.get_label_handle::<NacreMaterial>(nacre_label(material_label));
        entity.remove::<MeshMaterial3d<StandardMaterial>>();
        entity.insert(MeshMaterial3d(handle));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn gltf_defaults_and_the_table_choice() {
        let film = film_from_gltf(&json!({}), 1.5, 0.0, Vec3::ONE, |_| None);
        assert_eq!(film.weight, 0.0);
        assert_eq!(film.film_ior, 1.3);
        assert_eq!(
            film.thickness,
            FilmThickness::Gltf {
                min_nm: 100.0,
                max_nm: 400.0
            }
        );
        assert_eq!(film.technique, FilmTechnique::Lut);
        // A base of another index, a film outside the table, a metal: fourier.
        let other_base = film_from_gltf(
            &json!({"iridescenceFactor": 1.0}),
            1.6,
            0.0,
            Vec3::ONE,
            |_| None,
        );
        assert_eq!(other_base.technique, FilmTechnique::Fourier);
        assert_eq!(other_base.base_ior, Vec3::splat(1.6));
        let thick = film_from_gltf(
            &json!({"iridescenceThicknessMaximum": 1500.0}),
            1.5,
            0.0,
            Vec3::ONE,
            |_| None,
        );
        assert_eq!(thick.technique, FilmTechnique::Fourier);
        let metal = film_from_gltf(&json!({}), 1.5, 1.0, Vec3::new(1.0, 0.78, 0.34), |_| None);
        assert_eq!(metal.technique, FilmTechnique::Fourier);
        assert!(metal.base_kappa.min_element() > 0.0);
    }

    #[test]
    fn textures_map_by_index() {
        let ext = json!({
            "iridescenceFactor": 0.5,
            "iridescenceTexture": {"index": 2},
            "iridescenceThicknessTexture": {"index": 7},
            "iridescenceThicknessMinimum": 200.0,
            "iridescenceThicknessMaximum": 800.0,
            "iridescenceIor": 1.8
        });
        let film = film_from_gltf(&ext, 1.5, 0.0, Vec3::ONE, |i| {
            (i == 7).then(Handle::default)
        });
        assert_eq!(film.weight, 0.5);
        assert_eq!(film.film_ior, 1.8);
        assert!(film.thickness_texture.is_some());
        assert!(
            film.weight_texture.is_none(),
            "texture 2 is not in the file"
        );
        assert_eq!(
            film.thickness,
            FilmThickness::Gltf {
                min_nm: 200.0,
                max_nm: 800.0
            }
        );
    }

    #[test]
    fn gulbrandsen_reproduces_f0() {
        for f0 in [0.04f32, 0.5, 0.9] {
            let (n, k) = metal_index_gulbrandsen2014(f0, f0);
            let r = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
            assert!((r - f0).abs() < 1e-4, "{f0}: {r}");
        }
    }
}
