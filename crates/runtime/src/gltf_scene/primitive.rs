//! One triangle primitive (glTF §3.7.2): its accessors checked, its attributes read and
//! placed in world space, flat normals and MikkTSpace tangents where the file has none.

use super::error::GltfError;
use super::limits::{MAX_INDICES, MAX_VERTICES};
use super::model::{GltfMaterial, GltfPrimitive};
use crate::error::Result;
use std::path::Path;

/// Vertices and triangle corners read so far over the scene's primitives.
#[derive(Default)]
pub(super) struct Totals {
    vertices: usize,
    corners: usize,
}

/// Primitive `prim` (mode TRIANGLES) of `mesh` under the node transform `world`, read from
/// `buffers`; `materials` are the document's, the default one last. A mirroring transform
/// (negative determinant) reverses the winding (§3.5.3).
pub(super) fn read(
    path: &Path,
    mesh: &gltf::Mesh,
    prim: &gltf::Primitive,
    world: &[[f32; 4]; 4],
    buffers: &[Vec<u8>],
    materials: &[GltfMaterial],
    totals: &mut Totals,
) -> Result<GltfPrimitive> {
    let (m, p) = (mesh.index(), prim.index());
    let Some(pos_acc) = prim.get(&gltf::Semantic::Positions) else {
        return Err(GltfError::NoPosition {
            mesh: m,
            primitive: p,
        }
        .at(path));
    };
    let counts_differ = |semantic: &str, count: usize, positions: usize| {
        GltfError::CountMismatch {
            mesh: m,
            primitive: p,
            semantic: semantic.to_string(),
            count,
            positions,
        }
        .at(path)
    };
    check_accessor(path, &pos_acc, buffers)?;
    let float3 = |a: &gltf::Accessor, what: &str| {
        if a.data_type() == gltf::accessor::DataType::F32
            && a.dimensions() == gltf::accessor::Dimensions::Vec3
        {
            Ok(())
        } else {
            Err(GltfError::AccessorType {
                semantic: what.to_string(),
                accessor: a.index(),
                found: format!("{:?} {:?}", a.data_type(), a.dimensions()),
                expected: "float VEC3".to_string(),
            }
            .at(path))
        }
    };
    float3(&pos_acc, "POSITION")?;
    let normal_acc = prim.get(&gltf::Semantic::Normals);
    if let Some(a) = &normal_acc {
        check_accessor(path, a, buffers)?;
        float3(a, "NORMAL")?;
        if a.count() != pos_acc.count() {
            return Err(counts_differ("NORMAL", a.count(), pos_acc.count()));
        }
    }
    if let Some(a) = prim.indices() {
        check_accessor(path, &a, buffers)?;
    }
    let n_vertices = pos_acc.count();
    let n_corners = prim.indices().map_or(n_vertices, |a| a.count());
    totals.vertices = totals.vertices.saturating_add(n_vertices);
    totals.corners = totals.corners.saturating_add(n_corners);
    if totals.vertices > MAX_VERTICES || totals.corners > MAX_INDICES {
        return Err(GltfError::TooManyVertices {
            mesh: m,
            primitive: p,
            vertices: totals.vertices,
            corners: totals.corners,
            max_vertices: MAX_VERTICES,
            max_corners: MAX_INDICES,
        }
        .at(path));
    }
    if !n_corners.is_multiple_of(3) {
        return Err(GltfError::NotTriangles {
            mesh: m,
            primitive: p,
            corners: n_corners,
        }
        .at(path));
    }
    let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let positions: Vec<[f32; 3]> = reader
        .read_positions()
        .ok_or_else(|| {
            GltfError::Unreadable {
                mesh: m,
                primitive: p,
                semantic: "POSITION".to_string(),
            }
            .at(path)
        })?
        .map(|p| transform_point(world, p))
        .collect();
    if let Some(vertex) = positions
        .iter()
        .position(|v| !v.iter().all(|x| x.is_finite()))
    {
        return Err(GltfError::NonFinitePosition {
            mesh: m,
            primitive: p,
            vertex,
            value: positions[vertex],
        }
        .at(path));
    }
    let mut indices: Vec<u32> = match reader.read_indices() {
        Some(ix) => ix.into_u32().collect(),
        None => (0..n_vertices as u32).collect(),
    };
    if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
        return Err(GltfError::IndexOutOfRange {
            mesh: m,
            primitive: p,
            index: bad,
            vertices: positions.len(),
        }
        .at(path));
    }
    if determinant3(world) < 0.0 {
        // A mirroring transform turns counter-clockwise triangles clockwise.
        for tri in indices.chunks_exact_mut(3) {
            tri.swap(1, 2);
        }
    }
    let material = prim.material().index().unwrap_or(materials.len() - 1);
    let mut sets: [Vec<[f32; 2]>; 2] = [Vec::new(), Vec::new()];
    for (set, out) in sets.iter_mut().enumerate() {
        if let Some(a) = prim.get(&gltf::Semantic::TexCoords(set as u32)) {
            check_accessor(path, &a, buffers)?;
            if a.count() != positions.len() {
                return Err(counts_differ(
                    &format!("TEXCOORD_{set}"),
                    a.count(),
                    positions.len(),
                ));
            }
            *out = reader
                .read_tex_coords(set as u32)
                .map(|t| t.into_f32().collect())
                .unwrap_or_default();
        }
    }
    let [uv0, uv1] = sets;
    let uvs = if uv0.len() == positions.len() {
        uv0
    } else {
        vec![[0.0; 2]; positions.len()]
    };
    let uvs1 = if uv1.len() == positions.len() {
        uv1
    } else {
        uvs.clone()
    };
    let colours: Vec<[f32; 4]> = match prim.get(&gltf::Semantic::Colors(0)) {
        Some(a) => {
            check_accessor(path, &a, buffers)?;
            if a.count() != positions.len() {
                return Err(counts_differ("COLOR_0", a.count(), positions.len()));
            }
            reader
                .read_colors(0)
                .map(|c| c.into_rgba_f32().collect())
                .unwrap_or_default()
        }
        None => Vec::new(),
    };
    let colours = if colours.len() == positions.len() {
        colours
    } else {
        vec![[1.0; 4]; positions.len()]
    };
    let tangents: Vec<[f32; 4]> = match prim.get(&gltf::Semantic::Tangents) {
        Some(a) => {
            check_accessor(path, &a, buffers)?;
            if a.count() != positions.len() {
                return Err(counts_differ("TANGENT", a.count(), positions.len()));
            }
            reader
                .read_tangents()
                .map(|t| t.map(|t| transform_tangent(world, t)).collect())
                .unwrap_or_default()
        }
        None => Vec::new(),
    };
    let normals: Vec<[f32; 3]> = match prim.get(&gltf::Semantic::Normals) {
        Some(_) => reader
            .read_normals()
            .map(|n| n.map(|n| transform_normal(world, n)).collect())
            .unwrap_or_default(),
        None => Vec::new(),
    };
    let mut out = GltfPrimitive {
        tangents: if tangents.len() == positions.len() {
            tangents
        } else {
            Vec::new()
        },
        positions,
        normals,
        uvs,
        uvs1,
        colours,
        indices,
        material,
    };
    if out.normals.len() != out.positions.len() {
        out = flat_shaded(&out);
    }
    if materials[material].textures.normal.is_some() && out.tangents.is_empty() {
        generate_tangents(&mut out);
    }
    Ok(out)
}

/// A point under the column-major transform `m`.
fn transform_point(m: &[[f32; 4]; 4], p: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r])
}

/// The normal matrix (inverse transpose of the upper 3×3) applied to n, normalised.
fn transform_normal(m: &[[f32; 4]; 4], n: [f32; 3]) -> [f32; 3] {
    let a = |r: usize, c: usize| f64::from(m[c][r]);
    // Cofactor matrix of the 3×3 = det × inverse transpose (the sign of det does not matter
    // after normalising, but a mirroring transform flips it: keep det's sign).
    let cof = |r: usize, c: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1)
    };
    let det: f64 = (0..3).map(|c| a(0, c) * cof(0, c)).sum();
    let s = if det < 0.0 { -1.0 } else { 1.0 };
    let v: [f64; 3] =
        std::array::from_fn(|r| s * (0..3).map(|c| cof(r, c) * f64::from(n[c])).sum::<f64>());
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if len > 1e-30 && len.is_finite() {
        v.map(|x| (x / len) as f32)
    } else {
        [0.0, 1.0, 0.0]
    }
}

/// A tangent (xyz, w) under the transform's upper 3 × 3, xyz normalised, w kept.
fn transform_tangent(m: &[[f32; 4]; 4], t: [f32; 4]) -> [f32; 4] {
    let v: [f32; 3] = std::array::from_fn(|r| m[0][r] * t[0] + m[1][r] * t[1] + m[2][r] * t[2]);
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if len > 1e-30 && len.is_finite() {
        [
            v[0] / len,
            v[1] / len,
            v[2] / len,
            if t[3] < 0.0 { -1.0 } else { 1.0 },
        ]
    } else {
        [1.0, 0.0, 0.0, 1.0]
    }
}

/// Checks that an accessor lies inside its buffer view and the view inside its buffer (the
/// `gltf` crate's reader would panic otherwise).
fn check_accessor(path: &Path, accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<()> {
    if accessor.sparse().is_some() {
        return Err(GltfError::Sparse {
            accessor: accessor.index(),
        }
        .at(path));
    }
    let Some(view) = accessor.view() else {
        return Err(GltfError::NoBufferView {
            accessor: accessor.index(),
        }
        .at(path));
    };
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
    let elem = accessor.size() as u64;
    let stride = view.stride().map_or(elem, |s| s as u64);
    let count = accessor.count() as u64;
    let end = if count == 0 {
        0
    } else {
        (accessor.offset() as u64)
            .saturating_add((count - 1).saturating_mul(stride))
            .saturating_add(elem)
    };
    if end > view.length() as u64 {
        return Err(GltfError::AccessorBeyondView {
            accessor: accessor.index(),
            needed: end,
            view_bytes: view.length() as u64,
        }
        .at(path));
    }
    Ok(())
}

/// Every triangle corner its own vertex (all attributes copied).
fn unwelded(p: &GltfPrimitive) -> GltfPrimitive {
    let pick = |k: usize| p.indices[k] as usize;
    let n = p.indices.len();
    let take4 = |v: &Vec<[f32; 4]>| -> Vec<[f32; 4]> {
        if v.is_empty() {
            Vec::new()
        } else {
            (0..n).map(|k| v[pick(k)]).collect()
        }
    };
    GltfPrimitive {
        positions: (0..n).map(|k| p.positions[pick(k)]).collect(),
        normals: if p.normals.len() == p.positions.len() {
            (0..n).map(|k| p.normals[pick(k)]).collect()
        } else {
            Vec::new()
        },
        tangents: take4(&p.tangents),
        uvs: (0..n).map(|k| p.uvs[pick(k)]).collect(),
        uvs1: (0..n).map(|k| p.uvs1[pick(k)]).collect(),
        colours: take4(&p.colours),
        indices: (0..n as u32).collect(),
        material: p.material,
    }
}

/// Flat normals (glTF: "when normals are not specified, client implementations MUST
/// calculate flat normals"): every triangle gets its own three vertices.
fn flat_shaded(p: &GltfPrimitive) -> GltfPrimitive {
    let mut out = unwelded(p);
    out.normals.clear();
    for tri in out.positions.chunks_exact(3) {
        let [a, b, c] = [tri[0], tri[1], tri[2]];
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let n = if len > 0.0 && len.is_finite() {
            n.map(|x| x / len)
        } else {
            [0.0, 1.0, 0.0]
        };
        out.normals.extend([n; 3]);
    }
    out
}

/// MikkTSpace tangents (glTF §3.7.2.1: "when tangents are not specified, client
/// implementations SHOULD calculate tangents using default MikkTSpace algorithms with the
/// specified vertex positions, normals, and texture coordinates associated with the normal
/// texture") from `bevy_mikktspace`, on the unwelded triangles (each corner gets its own).
/// The normal texture's coordinate set is TEXCOORD_0 here (a normal map on TEXCOORD_1
/// gets TEXCOORD_0's tangents).
fn generate_tangents(p: &mut GltfPrimitive) {
    struct Corners<'a>(&'a mut GltfPrimitive);
    impl bevy_mikktspace::Geometry for Corners<'_> {
        fn num_faces(&self) -> usize {
            self.0.positions.len() / 3
        }
        fn num_vertices_of_face(&self, _face: usize) -> usize {
            3
        }
        fn position(&self, face: usize, vert: usize) -> [f32; 3] {
            self.0.positions[face * 3 + vert]
        }
        fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
            self.0.normals[face * 3 + vert]
        }
        fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
            self.0.uvs[face * 3 + vert]
        }
        fn set_tangent(
            &mut self,
            tangent_space: Option<bevy_mikktspace::TangentSpace>,
            face: usize,
            vert: usize,
        ) {
            self.0.tangents[face * 3 + vert] =
                tangent_space.map_or([1.0, 0.0, 0.0, 1.0], |t| t.tangent_encoded());
        }
    }
    let mut out = unwelded(p);
    out.tangents = vec![[1.0, 0.0, 0.0, 1.0]; out.positions.len()];
    // The crate's error type has no values: generation cannot fail.
    let _ = bevy_mikktspace::generate_tangents(&mut Corners(&mut out));
    for t in &mut out.tangents {
        if !t.iter().all(|x| x.is_finite()) {
            *t = [1.0, 0.0, 0.0, 1.0];
        }
    }
    *p = out;
}

/// The determinant of the upper 3 × 3 of a column-major 4 × 4.
fn determinant3(m: &[[f32; 4]; 4]) -> f64 {
    let a = |r: usize, c: usize| f64::from(m[c][r]);
    a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1))
        - a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0))
        + a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0))
}
