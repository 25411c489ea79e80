//! Project-made glTF test assets: rows of five low-poly UV spheres, one parameter of
//! `KHR_materials_iridescence` / `KHR_materials_ior` / the metallic-roughness core swept
//! across the row (left to right), written as GLB files ([`write_sweeps`]). The committed
//! copies under `tests/golden/gltf/` are regenerated with
//! `NACRE_UPDATE_GOLDEN=1 cargo test -p nacre-runtime --test gltf`, and a test checks that
//! this code reproduces them byte for byte. Project-made, CC0.

use crate::error::{Error, Result};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// Longitude segments of the UV sphere.
pub const SPHERE_SEGMENTS: usize = 24;
/// Latitude rings of the UV sphere.
pub const SPHERE_RINGS: usize = 12;
/// Distance between sphere centres along x, world units (radius 1).
pub const SPHERE_SPACING: f32 = 2.4;

/// One sweep: a file name and the five materials' JSON (left to right).
pub struct Sweep {
    /// File name (`*.glb`).
    pub file: &'static str,
    /// What is swept, for documentation.
    pub parameter: &'static str,
    /// The swept values, left to right.
    pub values: [f32; 5],
}

/// The sweeps: iridescenceIor, iridescenceThicknessMaximum, base ior, metallic (gold base
/// colour), iridescenceFactor, and iridescenceThicknessMaximum again with a thickness texture
/// (g = v: 100 nm at the sphere's top pole to d_max at the bottom).
pub const SWEEPS: [Sweep; 6] = [
    Sweep {
        file: "sweep-iridescence-ior.glb",
        parameter: "iridescenceIor",
        values: [1.0, 1.333, 1.667, 2.0, 2.333],
    },
    Sweep {
        file: "sweep-thickness.glb",
        parameter: "iridescenceThicknessMaximum (nm)",
        values: [100.0, 375.0, 650.0, 925.0, 1200.0],
    },
    Sweep {
        file: "sweep-base-ior.glb",
        parameter: "ior (KHR_materials_ior)",
        values: [1.0, 1.25, 1.5, 1.75, 2.0],
    },
    Sweep {
        file: "sweep-metallic.glb",
        parameter: "metallicFactor (gold base colour)",
        values: [0.0, 0.25, 0.5, 0.75, 1.0],
    },
    Sweep {
        file: "sweep-iridescence-factor.glb",
        parameter: "iridescenceFactor",
        values: [0.0, 0.25, 0.5, 0.75, 1.0],
    },
    Sweep {
        file: "sweep-thickness-texture.glb",
        parameter: "iridescenceThicknessMaximum (nm) with a thickness texture",
        values: [400.0, 600.0, 800.0, 1000.0, 1200.0],
    },
];

/// Size of the thickness texture of `sweep-thickness-texture.glb`, texels (width, height).
pub const TEXTURE_SIZE: (u32, u32) = (4, 64);

/// The thickness texture: an RGB PNG whose green channel rises linearly from 0 (top row)
/// to 255 (bottom row); red and blue 0.
pub fn gradient_png() -> Vec<u8> {
    let (w, h) = TEXTURE_SIZE;
    let mut rgb = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        let g = ((y * 255 + (h - 1) / 2) / (h - 1)) as u8;
        for _ in 0..w {
            rgb.extend_from_slice(&[0, g, 0]);
        }
    }
    let mut bytes = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut bytes),
        &rgb,
        w,
        h,
        image::ExtendedColorType::Rgb8,
    )
    .expect("an RGB8 image of its own size encodes");
    bytes
}

/// The material of sphere `value` of `sweep`: by default a dark glazed dielectric (base
/// colour 0.02, roughness 0.2, ior 1.5) under a film of index 1.3 (the extension's default)
/// and 100–400 nm (d = 400 nm without a texture), weight 1.
fn material(sweep: &Sweep, k: usize) -> Value {
    let v = f64::from(sweep.values[k]);
    let mut base_colour = json!([0.02, 0.02, 0.025, 1.0]);
    let mut metallic = 0.0;
    let mut ior = 1.5;
    let mut iri = json!({
        "iridescenceFactor": 1.0,
        "iridescenceIor": 1.3,
        "iridescenceThicknessMinimum": 100.0,
        "iridescenceThicknessMaximum": 400.0,
    });
    match sweep.file {
        "sweep-iridescence-ior.glb" => iri["iridescenceIor"] = json!(v),
        "sweep-thickness.glb" => iri["iridescenceThicknessMaximum"] = json!(v),
        "sweep-thickness-texture.glb" => {
            iri["iridescenceThicknessMaximum"] = json!(v);
            iri["iridescenceThicknessTexture"] = json!({ "index": 0, "texCoord": 0 });
        }
        "sweep-base-ior.glb" => ior = v,
        "sweep-metallic.glb" => {
            metallic = v;
            base_colour = json!([1.0, 0.766, 0.336, 1.0]);
        }
        _ => iri["iridescenceFactor"] = json!(v),
    }
    json!({
        "name": format!("{} = {}", sweep.parameter, sweep.values[k]),
        "pbrMetallicRoughness": {
            "baseColorFactor": base_colour,
            "metallicFactor": metallic,
            "roughnessFactor": 0.2,
        },
        "extensions": {
            "KHR_materials_iridescence": iri,
            "KHR_materials_ior": { "ior": ior },
        },
    })
}

/// A unit UV sphere: interleaved (position, normal, uv) f32 vertices — u = longitude / 2π,
/// v = colatitude / π (0 at the top pole) — and u16 triangle indices.
pub fn uv_sphere(segments: usize, rings: usize) -> (Vec<[f32; 8]>, Vec<u16>) {
    let mut vertices = Vec::new();
    for i in 0..=rings {
        let theta = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..=segments {
            let phi = std::f64::consts::TAU * j as f64 / segments as f64;
            let n = [
                (theta.sin() * phi.sin()) as f32,
                theta.cos() as f32,
                (theta.sin() * phi.cos()) as f32,
            ];
            let (u, v) = (j as f32 / segments as f32, i as f32 / rings as f32);
            vertices.push([n[0], n[1], n[2], n[0], n[1], n[2], u, v]);
        }
    }
    let mut indices = Vec::new();
    let w = segments + 1;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (
                i * w + j,
                i * w + j + 1,
                (i + 1) * w + j,
                (i + 1) * w + j + 1,
            );
            // Counter-clockwise seen from outside.
            if i != 0 {
                indices.extend([a, c, b].map(|x| x as u16));
            }
            if i != rings - 1 {
                indices.extend([b, c, d].map(|x| x as u16));
            }
        }
    }
    (vertices, indices)
}

/// Packs a glTF JSON document and its binary buffer into GLB (glTF 2.0 binary container:
/// 12-byte header, JSON chunk padded with spaces, BIN chunk padded with zeros).
pub fn glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut json_bytes = serde_json::to_vec(json).expect("a JSON value serialises");
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    let mut bin = bin.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json_bytes.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

/// The GLB bytes of `sweep`: five spheres at x = (k − 2) × [`SPHERE_SPACING`], one mesh (and
/// material) each, sharing one vertex and one index accessor.
pub fn sweep_glb(sweep: &Sweep) -> Vec<u8> {
    let (vertices, indices) = uv_sphere(SPHERE_SEGMENTS, SPHERE_RINGS);
    let mut bin: Vec<u8> = bytemuck::cast_slice(&vertices).to_vec();
    let vertex_bytes = bin.len();
    bin.extend_from_slice(bytemuck::cast_slice(&indices));
    let index_bytes = bin.len() - vertex_bytes;
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let textured = sweep.file == "sweep-thickness-texture.glb";
    let image_offset = bin.len();
    if textured {
        bin.extend_from_slice(&gradient_png());
    }
    let image_bytes = bin.len() - image_offset;
    let materials: Vec<Value> = (0..5).map(|k| material(sweep, k)).collect();
    let meshes: Vec<Value> = (0..5)
        .map(|k| {
            json!({
                "name": format!("sphere {k}"),
                "primitives": [{
                    "attributes": { "POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 3 },
                    "indices": 2,
                    "material": k,
                }],
            })
        })
        .collect();
    let nodes: Vec<Value> = (0..5)
        .map(|k| {
            json!({
                "mesh": k,
                "translation": [(k as f32 - 2.0) * SPHERE_SPACING, 0.0, 0.0],
            })
        })
        .collect();
    let mut doc = json!({
        "asset": {
            "version": "2.0",
            "generator": "nacre_runtime::gltf_assets (do not edit; regenerate: NACRE_UPDATE_GOLDEN=1 cargo test -p nacre-runtime --test gltf)",
            "copyright": "project-made, CC0",
        },
        "extensionsUsed": ["KHR_materials_iridescence", "KHR_materials_ior"],
        "scene": 0,
        "scenes": [{ "nodes": [0, 1, 2, 3, 4] }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "buffers": [{ "byteLength": bin.len() }],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": vertex_bytes, "byteStride": 32, "target": 34962 },
            { "buffer": 0, "byteOffset": vertex_bytes, "byteLength": index_bytes, "target": 34963 },
        ],
        "accessors": [
            { "bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": vertices.len(),
              "type": "VEC3", "min": [-1.0, -1.0, -1.0], "max": [1.0, 1.0, 1.0] },
            { "bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": vertices.len(),
              "type": "VEC3" },
            { "bufferView": 1, "byteOffset": 0, "componentType": 5123, "count": indices.len(),
              "type": "SCALAR" },
            { "bufferView": 0, "byteOffset": 24, "componentType": 5126, "count": vertices.len(),
              "type": "VEC2" },
        ],
    });
    if textured {
        doc["bufferViews"]
            .as_array_mut()
            .expect("an array")
            .push(json!({ "buffer": 0, "byteOffset": image_offset, "byteLength": image_bytes }));
        doc["images"] = json!([{ "bufferView": 2, "mimeType": "image/png" }]);
        doc["samplers"] = json!([{ "magFilter": 9729, "minFilter": 9987 }]);
        doc["textures"] = json!([{ "sampler": 0, "source": 0 }]);
    }
    glb(&doc, &bin)
}

/// Writes every sweep of [`SWEEPS`] into `dir` (created if needed); returns the paths.
pub fn write_sweeps(dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut paths = Vec::new();
    for sweep in &SWEEPS {
        let path = dir.join(sweep.file);
        std::fs::write(&path, sweep_glb(sweep)).map_err(|source| Error::Io {
            path: path.clone(),
            source,
        })?;
        paths.push(path);
    }
    Ok(paths)
}
