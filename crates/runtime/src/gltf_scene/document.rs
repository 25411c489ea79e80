//! Opening a glTF 2.0 / GLB file: its version, its accessors' existence, `extensionsRequired`
//! (glTF §3.12), and its buffers (the GLB chunk, base64 `data:` URIs or files beside it).

use super::error::GltfError;
use super::limits::MAX_FILE_BYTES;
use crate::error::{Error, Result};
use std::path::Path;

/// The glTF extensions nacre implements: a file whose `extensionsRequired` lists only these
/// loads (`KHR_materials_transmission` and `_volume` refract the opaque scene in screen
/// space, as the glTF Sample Viewer does: `shaders/mesh.wgsl`).
pub const SUPPORTED_EXTENSIONS: [&str; 13] = [
    "KHR_draco_mesh_compression",
    "KHR_lights_punctual",
    "KHR_mesh_quantization",
    "KHR_materials_clearcoat",
    "KHR_materials_iridescence",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_emissive_strength",
    "KHR_materials_unlit",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_texture_basisu",
    "KHR_texture_transform",
];

/// The document of glTF or GLB `bytes`: a glTF 2.x asset whose primitives' attribute
/// accessors exist and whose `extensionsRequired` nacre implements (then cleared, since the
/// `gltf` crate knows only its own features' extensions), validated by the `gltf` crate, and
/// the `extensionsRequired` it listed.
pub(super) fn open(bytes: &[u8], path: &Path) -> Result<(gltf::Gltf, Vec<String>)> {
    let not_valid = |e: gltf::Error| {
        GltfError::NotGltf {
            reason: e.to_string(),
        }
        .at(path)
    };
    let raw = gltf::Gltf::from_slice_without_validation(bytes).map_err(not_valid)?;
    let json = raw.document.as_json();
    let version = &json.asset.version;
    if !version.starts_with("2.") {
        return Err(GltfError::Version {
            version: version.clone(),
        }
        .at(path));
    }
    // gltf-json 1.4 validates a primitive by indexing its POSITION accessor before
    // checking that it exists (a panic): check every attribute's accessor first.
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(index) = primitive
                .attributes
                .values()
                .find(|i| i.value() >= json.accessors.len())
            {
                return Err(GltfError::MissingAccessor {
                    mesh: m,
                    primitive: p,
                    accessor: index.value(),
                    count: json.accessors.len(),
                }
                .at(path));
            }
        }
    }
    // extensionsRequired (glTF §3.12): every entry must be one nacre implements; they
    // are checked here (the gltf crate knows only its own features' extensions).
    if let Some(ext) = json
        .extensions_required
        .iter()
        .find(|e| !SUPPORTED_EXTENSIONS.contains(&e.as_str()))
    {
        return Err(GltfError::UnsupportedExtension {
            extension: ext.clone(),
            supported: SUPPORTED_EXTENSIONS.join(", "),
        }
        .at(path));
    }
    let mut root = raw.document.into_json();
    let required = std::mem::take(&mut root.extensions_required);
    validate(&root).map_err(not_valid)?;
    Ok((
        gltf::Gltf {
            document: gltf::Document::from_json_without_validation(root),
            blob: raw.blob,
        },
        required,
    ))
}

/// The `gltf` crate's validation of `root` (what `gltf::Document::from_json` does), except
/// that an accessor of a `KHR_draco_mesh_compression` primitive may lack a buffer view: its
/// data is in the Draco stream (the extension's accessors have none), where gltf-json 1.4
/// wants every accessor to have a buffer view or sparse values; and a texture with
/// `KHR_texture_basisu` may lack `source` (the extension names its image; `source` is only a
/// fallback), where gltf-json 1.4 wants it. The extension's `source` must be an image.
fn validate(root: &gltf::json::Root) -> std::result::Result<(), gltf::Error> {
    use gltf::json::validation::{Error as Invalid, Validate};
    let mut basisu_textures = std::collections::BTreeSet::new();
    let mut errors = Vec::new();
    for (t, texture) in root.textures.iter().enumerate() {
        let at = || {
            gltf::json::Path::new()
                .field("textures")
                .index(t)
                .field("extensions")
                .field(super::basisu::EXTENSION)
                .field("source")
        };
        match super::basisu::basisu_source(texture) {
            Some(Ok(image)) if image < root.images.len() => {
                basisu_textures.insert(t);
            }
            Some(Ok(_)) => errors.push((at(), Invalid::IndexOutOfBounds)),
            Some(Err(_)) => errors.push((at(), Invalid::Invalid)),
            None => {}
        }
    }
    let mut compressed = std::collections::BTreeSet::new();
    for primitive in root.meshes.iter().flat_map(|m| &m.primitives) {
        let draco = primitive
            .extensions
            .as_ref()
            .is_some_and(|e| e.others.contains_key(super::draco::EXTENSION));
        if draco {
            compressed.extend(primitive.attributes.values().map(|a| a.value()));
            compressed.extend(primitive.indices.map(|a| a.value()));
        }
    }
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        let path = path();
        let missing = |what: String| matches!(error, Invalid::Missing) && path.as_str() == what;
        let draco_data = compressed
            .iter()
            .any(|a| missing(format!("accessors[{a}].bufferView")));
        let basisu_image = basisu_textures
            .iter()
            .any(|t| missing(format!("textures[{t}].source")));
        if !draco_data && !basisu_image {
            errors.push((path, error));
        }
    });
    if errors.is_empty() {
        Ok(())
    } else {
        Err(gltf::Error::Validation(errors))
    }
}

/// The bytes of every buffer of `gltf`, each at least as long as the file declares.
pub(super) fn read_buffers(gltf: &gltf::Gltf, path: &Path) -> Result<Vec<Vec<u8>>> {
    let doc = &gltf.document;
    let mut buffers = Vec::new();
    for buffer in doc.buffers() {
        let b = buffer.index();
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => gltf
                .blob
                .clone()
                .ok_or_else(|| GltfError::MissingGlbChunk { buffer: b }.at(path))?,
            gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let (_, b64) = rest
                        .split_once(";base64,")
                        .ok_or_else(|| GltfError::DataUri { buffer: b }.at(path))?;
                    base64_decode(b64).ok_or_else(|| GltfError::Base64 { buffer: b }.at(path))?
                } else {
                    let file = path.parent().unwrap_or(Path::new(".")).join(uri);
                    let len = std::fs::metadata(&file)
                        .map_err(|source| Error::Io {
                            path: file.clone(),
                            source,
                        })?
                        .len();
                    if len > MAX_FILE_BYTES {
                        return Err(GltfError::BufferTooLarge {
                            buffer: b,
                            uri: uri.to_string(),
                            bytes: len,
                            max: MAX_FILE_BYTES,
                        }
                        .at(path));
                    }
                    std::fs::read(&file).map_err(|source| Error::Io {
                        path: file.clone(),
                        source,
                    })?
                }
            }
        };
        if data.len() < buffer.length() {
            return Err(GltfError::BufferShort {
                buffer: b,
                bytes: data.len(),
                declared: buffer.length(),
            }
            .at(path));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// Decodes standard base64 (RFC 4648, `=` padding optional, no whitespace).
pub(crate) fn base64_decode(text: &str) -> Option<Vec<u8>> {
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => u32::from(c - b'A'),
            b'a'..=b'z' => u32::from(c - b'a') + 26,
            b'0'..=b'9' => u32::from(c - b'0') + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        })
    };
    let bytes = text.trim_end_matches('=').as_bytes();
    let mut out = Vec::with_capacity(bytes.len() * 3 / 4);
    for chunk in bytes.chunks(4) {
        let mut acc = 0u32;
        for (i, &c) in chunk.iter().enumerate() {
            acc |= value(c)? << (18 - 6 * i);
        }
        let n = match chunk.len() {
            4 => 3,
            3 => 2,
            2 => 1,
            _ => return None,
        };
        out.extend_from_slice(&acc.to_be_bytes()[1..1 + n]);
    }
    Some(out)
}
