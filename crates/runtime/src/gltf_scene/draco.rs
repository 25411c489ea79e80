//! `KHR_draco_mesh_compression`: a primitive's triangles and attributes decoded from the
//! Draco stream in its `bufferView` (Khronos, "KHR_draco_mesh_compression", glTF extension
//! specification, 2019), by `draco-oxide-decoder` (a pure-Rust Draco decoder, bitstream 2.2,
//! the version Google's encoder has written since 2017).
//!
//! The extension's rules, as read here:
//!
//! * `bufferView` holds the Draco stream; `attributes` maps a glTF semantic (`POSITION`,
//!   `NORMAL`, `TEXCOORD_0`, …) to the **unique id** of a Draco attribute — the id the encoder
//!   stored, not the attribute's position in the stream;
//! * the primitive's own `attributes` and `indices` accessors still describe the data
//!   (component type, `normalized`, count): the decoded point count equals each compressed
//!   attribute's accessor `count`, and the decoded corner count the `indices` accessor's;
//! * a semantic of the primitive that the extension's map does not name is read from its
//!   accessor as usual;
//! * quantised and octahedral-encoded attributes are dequantised by the decoder (the
//!   extension leaves dequantisation to the Draco decoder: the accessors describe the
//!   decoded, float data); integer attributes keep their values and are normalised by the
//!   accessor's `normalized` flag as any accessor is (`accessor::decode`).
//!
//! The decoder runs under [`nacre_format::decode::guarded`]: a panic inside it (a damaged
//! stream it did not anticipate) is the primitive's error, never a crash.
//!
//! When the extension is only in `extensionsUsed` (optional), the file must keep an
//! uncompressed copy of every accessor of the primitive; a stream that does not decode then
//! falls back to that copy with a note (`Primitives::read`), where a required extension is an
//! error naming the primitive and the decoder's reason.

use super::accessor;
use super::error::GltfError;
use crate::error::Result;
use draco_oxide_core::attribute::ComponentDataType;
use gltf::accessor::DataType;
use std::collections::BTreeMap;
use std::path::Path;

/// The extension's name, as in `extensionsUsed` and a primitive's `extensions`.
pub(super) const EXTENSION: &str = "KHR_draco_mesh_compression";

/// One decoded Draco attribute: a value per point, each `components` components of type
/// `data_type`, little-endian and tightly packed (the layout of a glTF accessor's elements).
#[derive(Debug)]
struct Attribute {
    data_type: DataType,
    components: usize,
    bytes: Vec<u8>,
}

/// A primitive's Draco stream decoded: its triangle corners (point indices) and its
/// attributes by glTF semantic.
#[derive(Debug)]
pub(super) struct DracoPrimitive {
    /// The buffer view the stream came from (named in errors).
    pub(super) view: usize,
    /// Points (vertices) of the decoded mesh.
    pub(super) points: usize,
    /// Triangle corners, three per face, each a point index.
    pub(super) indices: Vec<u32>,
    attributes: BTreeMap<String, Attribute>,
}

/// A primitive's `KHR_draco_mesh_compression` object: the buffer view of the stream and the
/// semantic → unique id map.
pub(super) type Extension = (usize, BTreeMap<String, usize>);

/// The `KHR_draco_mesh_compression` object of a primitive, or `None` when the primitive
/// does not have the extension; `Err` names the malformed member.
pub(super) fn extension(prim: &gltf::Primitive) -> std::result::Result<Option<Extension>, String> {
    let Some(ext) = prim.extension_value(EXTENSION) else {
        return Ok(None);
    };
    let view = ext
        .get("bufferView")
        .and_then(|v| v.as_u64())
        .ok_or_else(|| {
            format!(
                "`bufferView` is {} (expected a buffer view index)",
                show(ext.get("bufferView"))
            )
        })?;
    let map = ext
        .get("attributes")
        .and_then(|a| a.as_object())
        .ok_or_else(|| {
            format!(
                "`attributes` is {} (expected an object)",
                show(ext.get("attributes"))
            )
        })?;
    let mut attributes = BTreeMap::new();
    for (semantic, id) in map {
        let id = id.as_u64().ok_or_else(|| {
            format!("`attributes.{semantic}` is {id} (expected a unique id, an integer ≥ 0)")
        })?;
        attributes.insert(semantic.clone(), id as usize);
    }
    Ok(Some((view as usize, attributes)))
}

/// A JSON value as the error messages show it.
fn show(v: Option<&serde_json::Value>) -> String {
    v.map_or_else(|| "missing".to_string(), |v| v.to_string())
}

/// The glTF component type of a Draco one; `None` for those glTF has no accessor type for.
fn data_type(t: ComponentDataType) -> Option<DataType> {
    Some(match t {
        ComponentDataType::I8 => DataType::I8,
        ComponentDataType::U8 => DataType::U8,
        ComponentDataType::I16 => DataType::I16,
        ComponentDataType::U16 => DataType::U16,
        ComponentDataType::U32 => DataType::U32,
        ComponentDataType::F32 => DataType::F32,
        _ => return None,
    })
}

/// Decodes the Draco stream `stream` (buffer view `view`) and picks the attributes that
/// `unique_ids` (semantic → Draco unique id) names. `Err` carries the reason, in words.
pub(super) fn decode(
    stream: &[u8],
    view: usize,
    unique_ids: &BTreeMap<String, usize>,
) -> std::result::Result<DracoPrimitive, String> {
    // The decoder (an alpha release) can panic on a damaged stream (an arithmetic overflow):
    // the guard makes that the primitive's error.
    let mesh = nacre_format::decode::guarded(
        || draco_oxide_decoder::decode_mesh(stream).map_err(|e| e.to_string()),
        || "malformed Draco data (the decoder failed)".to_string(),
    )?;
    let points = mesh.attributes.first().map_or(0, |a| a.len());
    let mut attributes = BTreeMap::new();
    for (semantic, &id) in unique_ids {
        let Some(a) = mesh.attributes.iter().find(|a| a.get_id().as_usize() == id) else {
            let ids: Vec<String> = mesh
                .attributes
                .iter()
                .map(|a| a.get_id().as_usize().to_string())
                .collect();
            return Err(format!(
                "{semantic}: the stream has no attribute of unique id {id} (its ids: {})",
                ids.join(", ")
            ));
        };
        let t = a.get_component_type();
        let data_type = data_type(t)
            .ok_or_else(|| format!("{semantic}: component type {t:?}, which glTF does not have"))?;
        let components = a.get_num_components();
        let elem = components * t.size();
        if a.len() != points {
            return Err(format!(
                "{semantic}: {} points, the stream's first attribute {points}",
                a.len()
            ));
        }
        let values = a.get_data_as_bytes();
        let unique = a.num_unique_values();
        if values.len() != unique * elem {
            return Err(format!(
                "{semantic}: {} bytes for {unique} values of {elem} bytes",
                values.len()
            ));
        }
        let bytes = match a.point_map_as_slice() {
            None => values.to_vec(),
            Some(map) => {
                let mut out = Vec::with_capacity(points * elem);
                for &v in map {
                    let v = usize::from(v);
                    let value = values.get(v * elem..(v + 1) * elem).ok_or_else(|| {
                        format!("{semantic}: a point refers to value {v} of {unique}")
                    })?;
                    out.extend_from_slice(value);
                }
                out
            }
        };
        attributes.insert(
            semantic.clone(),
            Attribute {
                data_type,
                components,
                bytes,
            },
        );
    }
    let mut indices = Vec::with_capacity(mesh.faces.len() * 3);
    for face in &mesh.faces {
        for &p in face {
            let p = usize::from(p);
            if p >= points {
                return Err(format!("a face refers to point {p} of {points}"));
            }
            indices.push(p as u32);
        }
    }
    Ok(DracoPrimitive {
        view,
        points,
        indices,
        attributes,
    })
}

impl DracoPrimitive {
    /// Whether the stream holds `semantic` (the extension's map names it).
    pub(super) fn has(&self, semantic: &str) -> bool {
        self.attributes.contains_key(semantic)
    }

    /// `semantic`'s decoded values as `N` floats each, as the accessor `a` describes them
    /// (its component type and dimensions must be the decoded ones; integers normalised by
    /// its `normalized` flag, missing components 1, as [`accessor::read_f32`] reads).
    pub(super) fn read_f32<const N: usize>(
        &self,
        path: &Path,
        mesh: usize,
        primitive: usize,
        semantic: &str,
        a: &gltf::Accessor,
    ) -> Result<Vec<[f32; N]>> {
        let bad = |what: String| {
            GltfError::Draco {
                mesh,
                primitive,
                view: self.view,
                what: format!("{semantic} (accessor {}): {what}", a.index()),
            }
            .at(path)
        };
        let Some(att) = self.attributes.get(semantic) else {
            return Err(bad("not in the extension's `attributes`".into()));
        };
        let dims = a.dimensions().multiplicity();
        if att.data_type != a.data_type() || att.components != dims {
            return Err(bad(format!(
                "decoded as {} × {:?}, the accessor declares {dims} × {:?}",
                att.components,
                att.data_type,
                a.data_type()
            )));
        }
        if a.count() != self.points {
            return Err(bad(format!(
                "the accessor declares {} elements, the stream decodes {} points",
                a.count(),
                self.points
            )));
        }
        let cb = att.data_type.size();
        let normalized = a.normalized();
        Ok(att
            .bytes
            .chunks_exact(dims * cb)
            .map(|e| {
                std::array::from_fn(|c| {
                    if c < dims {
                        accessor::decode(att.data_type, normalized, &e[c * cb..])
                    } else {
                        1.0
                    }
                })
            })
            .collect())
    }
}
