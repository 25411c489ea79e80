//! The document's materials (glTF §3.9 and the extensions nacre implements) with the
//! textures they read, and the `iridescenceThicknessTexture` of each as a thickness map.

use super::error::GltfError;
use super::model::{AlphaMode, Clearcoat, GltfMaterial, Iridescence, MaterialTextures, Volume};
use super::textures::{
    GltfTexture, TextureFailure, TextureLoader, TextureRef, thickness_texture, transform_from_json,
};
use crate::error::Result;
use crate::thickness_map::ThicknessMap;
use std::path::Path;

/// The materials of a document: its own, then the default material (glTF §3.9.6: the
/// material of a primitive that names none), with what they read.
pub(super) struct Materials {
    /// The document's materials in order, the default one last.
    pub(super) materials: Vec<GltfMaterial>,
    /// Each material's thickness map (`iridescenceThicknessTexture`), where it has one
    /// that could be read.
    pub(super) thickness_maps: Vec<Option<ThicknessMap>>,
    /// The decoded textures the materials refer to.
    pub(super) textures: Vec<GltfTexture>,
    /// What was skipped, one line each (textures not decoded, thickness maps not read).
    pub(super) notes: Vec<String>,
}

/// Reads every material of `doc` (its textures from `buffers`; `path` names the file); a
/// broken `KHR_texture_basisu` texture is an error.
pub(super) fn read(doc: &gltf::Document, buffers: &[Vec<u8>], path: &Path) -> Result<Materials> {
    let mut loader = TextureLoader {
        doc,
        buffers,
        path,
        textures: Vec::new(),
        cache: Default::default(),
        notes: Vec::new(),
        broken: None,
    };
    let mut materials: Vec<GltfMaterial> =
        doc.materials().map(|m| material(&mut loader, &m)).collect();
    let TextureLoader {
        textures,
        mut notes,
        broken,
        ..
    } = loader;
    if let Some(error) = broken {
        return Err(error.at(path));
    }
    materials.push(GltfMaterial::default());
    let thickness_maps = materials
        .iter()
        .map(|m| thickness_map(doc, m, buffers, path, &mut notes))
        .collect::<std::result::Result<_, GltfError>>()
        .map_err(|e| e.at(path))?;
    Ok(Materials {
        materials,
        thickness_maps,
        textures,
        notes,
    })
}

/// One material: its factors, and its textures through `loader`.
fn material(loader: &mut TextureLoader, m: &gltf::Material) -> GltfMaterial {
    let pbr = m.pbr_metallic_roughness();
    let name = m.name().map_or_else(
        || format!("material {}", m.index().unwrap_or(0)),
        String::from,
    );
    let iridescence = read_iridescence(m);
    let iri_ext = m.extension_value("KHR_materials_iridescence");
    let specular = m.specular();
    let coat_ext = m.extension_value("KHR_materials_clearcoat");
    let coat_info = |key: &str| coat_ext.and_then(|e| e.get(key));
    let normal = m.normal_texture();
    let occlusion = m.occlusion_texture();
    let textures = MaterialTextures {
        base_colour: loader.info(&name, "baseColorTexture", pbr.base_color_texture(), true),
        metallic_roughness: loader.info(
            &name,
            "metallicRoughnessTexture",
            pbr.metallic_roughness_texture(),
            false,
        ),
        normal: normal.as_ref().and_then(|t| {
            let transform = transform_from_json(t.extension_value("KHR_texture_transform"));
            loader.get(
                &name,
                "normalTexture",
                t.texture().index(),
                t.tex_coord(),
                transform,
                false,
            )
        }),
        occlusion: occlusion.as_ref().and_then(|t| {
            let transform = transform_from_json(t.extension_value("KHR_texture_transform"));
            loader.get(
                &name,
                "occlusionTexture",
                t.texture().index(),
                t.tex_coord(),
                transform,
                false,
            )
        }),
        emissive: loader.info(&name, "emissiveTexture", m.emissive_texture(), true),
        iridescence: loader.json(
            &name,
            "iridescenceTexture",
            iri_ext.and_then(|e| e.get("iridescenceTexture")),
            false,
        ),
        thickness: iri_ext
            .and_then(|e| e.get("iridescenceThicknessTexture"))
            .and_then(|t| {
                let set = t
                    .get("texCoord")
                    .and_then(serde_json::Value::as_u64)
                    .unwrap_or(0);
                let (transform, over) = transform_from_json(
                    t.get("extensions")
                        .and_then(|e| e.get("KHR_texture_transform")),
                );
                let tex_coord = over.unwrap_or(set.min(u64::from(u32::MAX)) as u32);
                (tex_coord <= 1).then_some(TextureRef {
                    texture: usize::MAX,
                    tex_coord,
                    transform,
                })
            }),
        specular: loader.info(
            &name,
            "specularTexture",
            specular.as_ref().and_then(|s| s.specular_texture()),
            false,
        ),
        specular_colour: loader.info(
            &name,
            "specularColorTexture",
            specular.as_ref().and_then(|s| s.specular_color_texture()),
            true,
        ),
        clearcoat: loader.json(
            &name,
            "clearcoatTexture",
            coat_info("clearcoatTexture"),
            false,
        ),
        clearcoat_roughness: loader.json(
            &name,
            "clearcoatRoughnessTexture",
            coat_info("clearcoatRoughnessTexture"),
            false,
        ),
        clearcoat_normal: loader.json(
            &name,
            "clearcoatNormalTexture",
            coat_info("clearcoatNormalTexture"),
            false,
        ),
    };
    let strength = m.emissive_strength().unwrap_or(1.0);
    GltfMaterial {
        base_colour: pbr.base_color_factor(),
        metallic: pbr.metallic_factor(),
        roughness: pbr.roughness_factor(),
        ior: m.ior().unwrap_or(1.5),
        transmission: m.transmission().map_or(0.0, |t| t.transmission_factor()),
        volume: m.volume().map(|v| Volume {
            thickness: v.thickness_factor(),
            attenuation_distance: v.attenuation_distance(),
            attenuation_colour: v.attenuation_color(),
        }),
        iridescence,
        clearcoat: coat_ext.map(read_clearcoat),
        alpha_mode: match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask(m.alpha_cutoff().unwrap_or(0.5)),
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        },
        double_sided: m.double_sided(),
        emissive: m.emissive_factor().map(|e| e * strength),
        unlit: m.unlit(),
        specular: specular.as_ref().map_or(1.0, |s| s.specular_factor()),
        specular_colour: specular
            .as_ref()
            .map_or([1.0; 3], |s| s.specular_color_factor()),
        normal_scale: normal.as_ref().map_or(1.0, |t| t.scale()),
        occlusion_strength: occlusion.as_ref().map_or(1.0, |t| t.strength()),
        textures,
        name,
    }
}

/// The thickness map of `m`'s `iridescenceThicknessTexture`, or None (with a note when it
/// has one that cannot be read: the film is then d_max thick), or the error of a broken
/// `KHR_texture_basisu` texture.
fn thickness_map(
    doc: &gltf::Document,
    m: &GltfMaterial,
    buffers: &[Vec<u8>],
    path: &Path,
    notes: &mut Vec<String>,
) -> std::result::Result<Option<ThicknessMap>, GltfError> {
    let iri = m.iridescence.unwrap_or_default();
    Ok(match iri.thickness_texture {
        Some((index, _)) => match thickness_texture(doc, index, buffers, path) {
            Ok(map) => Some(map),
            Err(TextureFailure::Broken(error)) => return Err(error),
            Err(TextureFailure::Skip(why)) => {
                notes.push(format!(
                    "{}: iridescenceThicknessTexture not read ({why}); the film is d_max = {} nm",
                    m.name, iri.thickness_max_nm
                ));
                None
            }
        },
        None => None,
    })
}

/// `KHR_materials_clearcoat` from its JSON object `ext`, the extension's defaults where a
/// value is missing or not a number.
fn read_clearcoat(ext: &serde_json::Value) -> Clearcoat {
    let num = |v: Option<&serde_json::Value>, default: f32| {
        v.and_then(serde_json::Value::as_f64)
            .map_or(default, |v| v as f32)
    };
    let d = Clearcoat::default();
    Clearcoat {
        factor: num(ext.get("clearcoatFactor"), d.factor),
        roughness: num(ext.get("clearcoatRoughnessFactor"), d.roughness),
        normal_scale: num(
            ext.get("clearcoatNormalTexture")
                .and_then(|t| t.get("scale")),
            d.normal_scale,
        ),
    }
}

/// `KHR_materials_iridescence` of `material`, its defaults where a value is missing; None
/// without the extension.
fn read_iridescence(material: &gltf::Material) -> Option<Iridescence> {
    let ext = material.extension_value("KHR_materials_iridescence")?;
    let num = |key: &str, default: f32| {
        ext.get(key)
            .and_then(serde_json::Value::as_f64)
            .map_or(default, |v| v as f32)
    };
    let d = Iridescence::default();
    Some(Iridescence {
        factor: num("iridescenceFactor", d.factor),
        ior: num("iridescenceIor", d.ior),
        thickness_min_nm: num("iridescenceThicknessMinimum", d.thickness_min_nm),
        thickness_max_nm: num("iridescenceThicknessMaximum", d.thickness_max_nm),
        has_thickness_texture: ext.get("iridescenceThicknessTexture").is_some(),
        thickness_texture: ext.get("iridescenceThicknessTexture").and_then(|t| {
            let index = t.get("index")?.as_u64()? as usize;
            let set = t
                .get("texCoord")
                .and_then(serde_json::Value::as_u64)
                .unwrap_or(0);
            Some((index, set as u32))
        }),
        has_texture: ext.get("iridescenceTexture").is_some(),
    })
}
