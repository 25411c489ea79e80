//! Accessors read by hand (glTF 2.0 §3.6.2): elements from a buffer view (strided) or zeros
//! when there is none, then the sparse substitution (§3.6.2.3), then the components decoded —
//! floats as they are, integers as integers or, when `normalized`, mapped to [0, 1] / [−1, 1]
//! (§3.11, the types `KHR_mesh_quantization` allows for positions, normals, tangents and
//! texture coordinates). Every byte range is checked against its view and buffer first, and
//! every sparse index against the accessor's count, so a bad file is a [`GltfError`], never
//! a panic.

use super::error::GltfError;
use crate::error::Result;
use gltf::accessor::DataType;
use std::path::Path;

/// Checks that `offset + needed` bytes lie inside `view` and `view` inside its buffer.
fn check_range(
    path: &Path,
    view: &gltf::buffer::View,
    buffers: &[Vec<u8>],
    needed: u64,
    beyond_view: impl FnOnce(u64, u64) -> GltfError,
) -> Result<()> {
    let data_len = buffers.get(view.buffer().index()).map_or(0, Vec::len) as u64;
    let view_end = (view.offset() as u64).saturating_add(view.length() as u64);
    if view_end > data_len {
        return Err(GltfError::ViewBeyondBuffer {
            view: view.index(),
            end: view_end,
            buffer_bytes: data_len,
        }
        .at(path));
    }
    if needed > view.length() as u64 {
        return Err(beyond_view(needed, view.length() as u64).at(path));
    }
    Ok(())
}

/// Checks that the accessor's base elements and its sparse indices and values lie inside
/// their buffer views and the views inside their buffers (reads nothing, allocates nothing).
pub(super) fn check(path: &Path, accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<()> {
    let a = accessor.index();
    let elem = accessor.size() as u64;
    if let Some(view) = accessor.view() {
        let stride = view.stride().map_or(elem, |s| s as u64);
        let count = accessor.count() as u64;
        let end = if count == 0 {
            0
        } else {
            (accessor.offset() as u64)
                .saturating_add((count - 1).saturating_mul(stride))
                .saturating_add(elem)
        };
        check_range(path, &view, buffers, end, |needed, view_bytes| {
            GltfError::AccessorBeyondView {
                accessor: a,
                needed,
                view_bytes,
            }
        })?;
    }
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count() as u64;
        let indices = sparse.indices();
        let index_bytes = indices.index_type().size() as u64;
        for (part, view, offset, size) in [
            ("indices", indices.view(), indices.offset(), index_bytes),
            (
                "values",
                sparse.values().view(),
                sparse.values().offset(),
                elem,
            ),
        ] {
            let needed = (offset as u64).saturating_add(n.saturating_mul(size));
            check_range(path, &view, buffers, needed, |needed, view_bytes| {
                GltfError::SparseBeyondView {
                    accessor: a,
                    part: part.to_string(),
                    needed,
                    view_bytes,
                }
            })?;
        }
    }
    Ok(())
}

/// The accessor's elements tightly packed (`count × size` bytes): the view's elements (or
/// zeros without a view) with the sparse elements substituted. Call [`check`] first.
fn packed(path: &Path, accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<u8>> {
    let elem = accessor.size();
    let count = accessor.count();
    let mut out = vec![0u8; count * elem];
    if let Some(view) = accessor.view() {
        let data = &buffers[view.buffer().index()][view.offset()..view.offset() + view.length()];
        let stride = view.stride().unwrap_or(elem);
        for (k, dst) in out.chunks_exact_mut(elem).enumerate() {
            let start = accessor.offset() + k * stride;
            dst.copy_from_slice(&data[start..start + elem]);
        }
    }
    if let Some(sparse) = accessor.sparse() {
        let slice = |view: gltf::buffer::View, offset: usize| {
            &buffers[view.buffer().index()][view.offset() + offset..view.offset() + view.length()]
        };
        let ix = sparse.indices();
        let index_type = ix.index_type();
        let ix_bytes = slice(ix.view(), ix.offset());
        let values = slice(sparse.values().view(), sparse.values().offset());
        let isize = index_type.size();
        let mut previous: Option<u32> = None;
        for position in 0..sparse.count() {
            let b = &ix_bytes[position * isize..(position + 1) * isize];
            let index = match isize {
                1 => u32::from(b[0]),
                2 => u32::from(u16::from_le_bytes([b[0], b[1]])),
                _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            };
            if index as usize >= count {
                return Err(GltfError::SparseIndexOutOfRange {
                    accessor: accessor.index(),
                    position,
                    index,
                    count,
                }
                .at(path));
            }
            if let Some(previous) = previous.filter(|&p| index <= p) {
                return Err(GltfError::SparseIndicesNotIncreasing {
                    accessor: accessor.index(),
                    position,
                    previous,
                    index,
                }
                .at(path));
            }
            previous = Some(index);
            let i = index as usize;
            out[i * elem..(i + 1) * elem]
                .copy_from_slice(&values[position * elem..(position + 1) * elem]);
        }
    }
    Ok(out)
}

/// One component at the start of `b`: a float as it is; an integer as its value or, when
/// `normalized`, by glTF §3.11: f = c / 255 (u8), c / 65535 (u16), max(c / 127, −1) (i8),
/// max(c / 32767, −1) (i16).
pub(super) fn decode(t: DataType, normalized: bool, b: &[u8]) -> f32 {
    match t {
        DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
        DataType::I8 => {
            let c = f32::from(b[0] as i8);
            if normalized { (c / 127.0).max(-1.0) } else { c }
        }
        DataType::U8 => {
            let c = f32::from(b[0]);
            if normalized { c / 255.0 } else { c }
        }
        DataType::I16 => {
            let c = f32::from(i16::from_le_bytes([b[0], b[1]]));
            if normalized {
                (c / 32767.0).max(-1.0)
            } else {
                c
            }
        }
        DataType::U16 => {
            let c = f32::from(u16::from_le_bytes([b[0], b[1]]));
            if normalized { c / 65535.0 } else { c }
        }
    }
}

/// The accessor's elements as `N` floats each (its first `N` components, missing ones 1 —
/// an RGB colour read as RGBA gets alpha 1), decoded by [`decode`]. Call [`check`] first.
pub(super) fn read_f32<const N: usize>(
    path: &Path,
    accessor: &gltf::Accessor,
    buffers: &[Vec<u8>],
) -> Result<Vec<[f32; N]>> {
    let bytes = packed(path, accessor, buffers)?;
    let t = accessor.data_type();
    let cb = t.size();
    let dims = accessor.dimensions().multiplicity();
    let normalized = accessor.normalized();
    Ok(bytes
        .chunks_exact(accessor.size())
        .map(|e| {
            std::array::from_fn(|c| {
                if c < dims {
                    decode(t, normalized, &e[c * cb..])
                } else {
                    1.0
                }
            })
        })
        .collect())
}

/// A scalar unsigned-integer accessor (triangle indices) as `u32`. Call [`check`] first.
pub(super) fn read_u32(
    path: &Path,
    accessor: &gltf::Accessor,
    buffers: &[Vec<u8>],
) -> Result<Vec<u32>> {
    let bytes = packed(path, accessor, buffers)?;
    Ok(match accessor.data_type() {
        DataType::U8 | DataType::I8 => bytes.iter().map(|&b| u32::from(b)).collect(),
        DataType::U16 | DataType::I16 => bytes
            .chunks_exact(2)
            .map(|b| u32::from(u16::from_le_bytes([b[0], b[1]])))
            .collect(),
        DataType::U32 | DataType::F32 => bytes
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect(),
    })
}
