//! One primitive (glTF §3.7.2): its accessors checked, its attributes read and placed in
//! world space, its strips, fans and loops made lists; for triangles, flat normals and
//! MikkTSpace tangents where the file has none.

use super::accessor;
use super::draco::{self, DracoPrimitive};
use super::error::GltfError;
use super::limits::{MAX_INDICES, MAX_VERTICES};
use super::model::{GltfMaterial, GltfPrimitive, Topology};
use crate::error::Result;
use gltf::accessor::{DataType, Dimensions};
use std::collections::HashMap;
use std::path::Path;
use std::rc::Rc;

/// What the primitives of one document are read from, and the vertices and triangle
/// corners read so far over the scene's primitives.
pub(super) struct Primitives<'a> {
    /// The document (its buffer views hold `KHR_draco_mesh_compression` streams).
    doc: &'a gltf::Document,
    /// The file, named in errors.
    pub(super) path: &'a Path,
    /// The document's buffers.
    pub(super) buffers: &'a [Vec<u8>],
    /// The document's materials, the default one last.
    pub(super) materials: &'a [GltfMaterial],
    /// The file uses `KHR_mesh_quantization`: attributes may be integers (normalised or not).
    pub(super) quantized: bool,
    /// The file lists `KHR_draco_mesh_compression` in `extensionsRequired`: a Draco stream
    /// that does not decode is an error (else the uncompressed accessors are read, if any).
    draco_required: bool,
    /// Decoded Draco primitives by (mesh, primitive), decoded once however many nodes place
    /// the mesh (`None`: the stream fell back to the uncompressed accessors).
    draco: HashMap<(usize, usize), Option<Rc<DracoPrimitive>>>,
    /// What the reader noted (a Draco fallback), one line each.
    pub(super) notes: Vec<String>,
    vertices: usize,
    corners: usize,
}

/// The component types an accessor may have: `(type, normalized)`.
type Allowed = &'static [(DataType, bool)];
const FLOAT: Allowed = &[(DataType::F32, false)];
/// Float or any 8- or 16-bit integer, normalised or not (`KHR_mesh_quantization`'s POSITION
/// and TEXCOORD types).
const FLOAT_OR_SHORT: Allowed = &[
    (DataType::F32, false),
    (DataType::I8, false),
    (DataType::I8, true),
    (DataType::U8, false),
    (DataType::U8, true),
    (DataType::I16, false),
    (DataType::I16, true),
    (DataType::U16, false),
    (DataType::U16, true),
];
/// Float or a normalised signed 8- or 16-bit integer (`KHR_mesh_quantization`'s NORMAL and
/// TANGENT types).
const FLOAT_OR_SIGNED_NORMALIZED: Allowed = &[
    (DataType::F32, false),
    (DataType::I8, true),
    (DataType::I16, true),
];
/// Float or a normalised unsigned 8- or 16-bit integer (core glTF's TEXCOORD and COLOR
/// types).
const FLOAT_OR_UNSIGNED_NORMALIZED: Allowed = &[
    (DataType::F32, false),
    (DataType::U8, true),
    (DataType::U16, true),
];
/// The triangle list of a TRIANGLE_STRIP or TRIANGLE_FAN's vertices `v` (glTF 2.0
/// §3.7.2.1, "Topology Types"): strip triangle i = (v_i, v_{i+1+i%2}, v_{i+2−i%2}), fan
/// triangle i = (v_{i+1}, v_{i+2}, v_0); fewer than three vertices make none.
fn triangle_list(mode: gltf::mesh::Mode, v: &[u32]) -> Vec<u32> {
    let n = v.len().saturating_sub(2);
    let mut out = Vec::with_capacity(3 * n);
    for i in 0..n {
        let tri = if mode == gltf::mesh::Mode::TriangleFan {
            [v[i + 1], v[i + 2], v[0]]
        } else {
            [v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]]
        };
        out.extend_from_slice(&tri);
    }
    out
}

/// The line list of a LINE_STRIP or LINE_LOOP's vertices `v` (glTF 2.0 §3.7.2.1,
/// "Topology Types"): strip segment i = (v_i, v_{i+1}) for i < n − 1; a loop adds
/// (v_{n−1}, v_0), closing back to its first vertex; fewer than two vertices make none.
fn line_list(mode: gltf::mesh::Mode, v: &[u32]) -> Vec<u32> {
    let mut out: Vec<u32> = v.windows(2).flatten().copied().collect();
    if mode == gltf::mesh::Mode::LineLoop
        && let [first, .., last] = v
    {
        out.extend_from_slice(&[*last, *first]);
    }
    out
}

/// What a primitive of `mode` draws, and how many indices its list holds when `listed`
/// indices (or vertices) are given: strips and fans of n make 3 (n − 2) corners, line strips
/// 2 (n − 1) ends, line loops 2 n (none below two vertices).
fn listed_count(mode: gltf::mesh::Mode, listed: usize) -> (Topology, usize) {
    use gltf::mesh::Mode;
    match mode {
        Mode::Triangles => (Topology::Triangles, listed),
        Mode::TriangleStrip | Mode::TriangleFan => {
            (Topology::Triangles, 3 * listed.saturating_sub(2))
        }
        Mode::Lines => (Topology::Lines, listed),
        Mode::LineStrip => (Topology::Lines, 2 * listed.saturating_sub(1)),
        Mode::LineLoop => (Topology::Lines, if listed < 2 { 0 } else { 2 * listed }),
        Mode::Points => (Topology::Points, listed),
    }
}

/// What one accessor of a primitive may be (glTF §3.7.2.1 and `KHR_mesh_quantization`).
struct Rule {
    /// Its dimensions.
    dimensions: &'static [Dimensions],
    /// Its component types in core glTF.
    core: Allowed,
    /// Its component types in a file that uses `KHR_mesh_quantization`.
    quantized: Allowed,
}

/// The rules of the accessors nacre reads, one line each.
const POSITION: Rule = Rule {
    dimensions: &[Dimensions::Vec3],
    core: FLOAT,
    quantized: FLOAT_OR_SHORT,
};
const NORMAL: Rule = Rule {
    dimensions: &[Dimensions::Vec3],
    core: FLOAT,
    quantized: FLOAT_OR_SIGNED_NORMALIZED,
};
const TANGENT: Rule = Rule {
    dimensions: &[Dimensions::Vec4],
    core: FLOAT,
    quantized: FLOAT_OR_SIGNED_NORMALIZED,
};
const TEXCOORD: Rule = Rule {
    dimensions: &[Dimensions::Vec2],
    core: FLOAT_OR_UNSIGNED_NORMALIZED,
    quantized: FLOAT_OR_SHORT,
};
const COLOR: Rule = Rule {
    dimensions: &[Dimensions::Vec3, Dimensions::Vec4],
    core: FLOAT_OR_UNSIGNED_NORMALIZED,
    quantized: FLOAT_OR_UNSIGNED_NORMALIZED,
};
/// Unsigned integers, the component types of indices.
const UNSIGNED: Allowed = &[
    (DataType::U8, false),
    (DataType::U16, false),
    (DataType::U32, false),
];
/// Indices.
const INDICES: Rule = Rule {
    dimensions: &[Dimensions::Scalar],
    core: UNSIGNED,
    quantized: UNSIGNED,
};

impl<'a> Primitives<'a> {
    /// A reader of `path`'s primitives (of `doc`) from `buffers`.
    pub(super) fn new(
        doc: &'a gltf::Document,
        path: &'a Path,
        buffers: &'a [Vec<u8>],
        materials: &'a [GltfMaterial],
        quantized: bool,
        draco_required: bool,
    ) -> Self {
        Primitives {
            doc,
            path,
            buffers,
            materials,
            quantized,
            draco_required,
            draco: HashMap::new(),
            notes: Vec::new(),
            vertices: 0,
            corners: 0,
        }
    }

    /// Checks `a`'s component type and dimensions against `rule` (the accessor of
    /// `semantic`) and its byte ranges.
    fn check(&self, a: &gltf::Accessor, semantic: &str, rule: &Rule) -> Result<()> {
        let (allowed, dimensions) = (
            if self.quantized {
                rule.quantized
            } else {
                rule.core
            },
            rule.dimensions,
        );
        let normalized = a.normalized() && a.data_type() != DataType::F32;
        if !allowed.contains(&(a.data_type(), normalized)) || !dimensions.contains(&a.dimensions())
        {
            let types: Vec<String> = allowed
                .iter()
                .map(|(t, n)| format!("{t:?}{}", if *n { " normalized" } else { "" }))
                .collect();
            let dims: Vec<String> = dimensions.iter().map(|d| format!("{d:?}")).collect();
            return Err(GltfError::AccessorType {
                semantic: semantic.to_string(),
                accessor: a.index(),
                found: format!(
                    "{:?}{} {:?}",
                    a.data_type(),
                    if normalized { " normalized" } else { "" },
                    a.dimensions()
                ),
                expected: format!("{} {}", types.join(" / "), dims.join(" / ")),
            }
            .at(self.path));
        }
        accessor::check(self.path, a, self.buffers)
    }

    /// The decoded `KHR_draco_mesh_compression` stream of `prim`, if it has one (decoded on
    /// the first call, then kept): `None` without the extension, or when the stream does not
    /// decode, the extension is optional and every accessor of the primitive has its
    /// uncompressed data (a buffer view or sparse values) — then with a note.
    fn draco(
        &mut self,
        mesh: &gltf::Mesh,
        prim: &gltf::Primitive,
    ) -> Result<Option<Rc<DracoPrimitive>>> {
        let (m, p) = (mesh.index(), prim.index());
        let path = self.path;
        let Some((view, unique_ids)) = draco::extension(prim).map_err(|what| {
            GltfError::DracoExtension {
                mesh: m,
                primitive: p,
                what,
            }
            .at(path)
        })?
        else {
            return Ok(None);
        };
        if let Some(decoded) = self.draco.get(&(m, p)) {
            return Ok(decoded.clone());
        }
        let fail = |what: String| {
            GltfError::Draco {
                mesh: m,
                primitive: p,
                view,
                what,
            }
            .at(path)
        };
        let Some(v) = self.doc.views().nth(view) else {
            return Err(fail(format!(
                "the file has {} buffer views",
                self.doc.views().len()
            )));
        };
        let data = self
            .buffers
            .get(v.buffer().index())
            .map_or(&[][..], Vec::as_slice);
        let end = v.offset().saturating_add(v.length());
        let Some(stream) = data.get(v.offset()..end) else {
            return Err(GltfError::ViewBeyondBuffer {
                view,
                end: end as u64,
                buffer_bytes: data.len() as u64,
            }
            .at(path));
        };
        let decoded = match draco::decode(stream, view, &unique_ids) {
            Ok(d) => Some(Rc::new(d)),
            Err(why) => {
                let uncompressed = prim
                    .attributes()
                    .map(|(_, a)| a)
                    .chain(prim.indices())
                    .all(|a| a.view().is_some() || a.sparse().is_some());
                if self.draco_required || !uncompressed {
                    return Err(fail(why));
                }
                self.notes.push(format!(
                    "mesh {m} primitive {p}: its KHR_draco_mesh_compression stream (buffer view {view}) does not decode ({why}); its uncompressed accessors are read instead"
                ));
                None
            }
        };
        self.draco.insert((m, p), decoded.clone());
        Ok(decoded)
    }

    /// Primitive `prim` (any mode: strips, fans and loops made lists) of `mesh` under the
    /// node transform `world`. A mirroring transform (negative determinant) reverses the
    /// triangles' winding (§3.5.3); quantised
    /// attributes are dequantised by the node transform (`KHR_mesh_quantization`), which
    /// applies to every attribute as to float ones.
    pub(super) fn read(
        &mut self,
        mesh: &gltf::Mesh,
        prim: &gltf::Primitive,
        world: &[[f32; 4]; 4],
    ) -> Result<GltfPrimitive> {
        let draco = self.draco(mesh, prim)?;
        let (path, buffers, materials) = (self.path, self.buffers, self.materials);
        let (m, p) = (mesh.index(), prim.index());
        // An attribute's values: from the Draco stream when it holds the semantic, else from
        // the accessor.
        let draco = draco.as_deref();
        fn values<const N: usize>(
            draco: Option<&DracoPrimitive>,
            (path, buffers): (&Path, &[Vec<u8>]),
            (m, p): (usize, usize),
            semantic: &str,
            a: &gltf::Accessor,
        ) -> Result<Vec<[f32; N]>> {
            match draco {
                Some(d) if d.has(semantic) => d.read_f32::<N>(path, m, p, semantic, a),
                _ => accessor::read_f32::<N>(path, a, buffers),
            }
        }
        let at = (path, buffers);
        let Some(pos_acc) = prim.get(&gltf::Semantic::Positions) else {
            return Err(GltfError::NoPosition {
                mesh: m,
                primitive: p,
            }
            .at(path));
        };
        let n_vertices = pos_acc.count();
        let counts_differ = |semantic: &str, a: &gltf::Accessor| {
            if a.count() == n_vertices {
                Ok(())
            } else {
                Err(GltfError::CountMismatch {
                    mesh: m,
                    primitive: p,
                    semantic: semantic.to_string(),
                    count: a.count(),
                    positions: n_vertices,
                }
                .at(path))
            }
        };
        self.check(&pos_acc, "POSITION", &POSITION)?;
        let normal_acc = prim.get(&gltf::Semantic::Normals);
        if let Some(a) = &normal_acc {
            self.check(a, "NORMAL", &NORMAL)?;
            counts_differ("NORMAL", a)?;
        }
        let tangent_acc = prim.get(&gltf::Semantic::Tangents);
        if let Some(a) = &tangent_acc {
            self.check(a, "TANGENT", &TANGENT)?;
            counts_differ("TANGENT", a)?;
        }
        let uv_accs = [0, 1].map(|set| prim.get(&gltf::Semantic::TexCoords(set)));
        for (set, a) in uv_accs.iter().enumerate() {
            if let Some(a) = a {
                let name = format!("TEXCOORD_{set}");
                self.check(a, &name, &TEXCOORD)?;
                counts_differ(&name, a)?;
            }
        }
        let colour_acc = prim.get(&gltf::Semantic::Colors(0));
        if let Some(a) = &colour_acc {
            self.check(a, "COLOR_0", &COLOR)?;
            counts_differ("COLOR_0", a)?;
        }
        if let Some(a) = prim.indices() {
            self.check(&a, "indices", &INDICES)?;
        }
        let listed = match (draco, prim.indices()) {
            (Some(d), Some(a)) if a.count() != d.indices.len() => {
                return Err(GltfError::Draco {
                    mesh: m,
                    primitive: p,
                    view: d.view,
                    what: format!(
                        "indices (accessor {}): the accessor declares {} corners, the stream decodes {}",
                        a.index(),
                        a.count(),
                        d.indices.len()
                    ),
                }
                .at(path));
            }
            (Some(d), _) => d.indices.len(),
            (None, a) => a.map_or(n_vertices, |a| a.count()),
        };
        let mode = prim.mode();
        use gltf::mesh::Mode;
        let list = matches!(mode, Mode::Triangles | Mode::Lines | Mode::Points);
        let (topology, n_corners) = listed_count(mode, listed);
        self.vertices = self.vertices.saturating_add(n_vertices);
        self.corners = self.corners.saturating_add(n_corners);
        if self.vertices > MAX_VERTICES || self.corners > MAX_INDICES {
            return Err(GltfError::TooManyVertices {
                mesh: m,
                primitive: p,
                vertices: self.vertices,
                corners: self.corners,
                max_vertices: MAX_VERTICES,
                max_corners: MAX_INDICES,
            }
            .at(path));
        }
        if topology == Topology::Triangles && !n_corners.is_multiple_of(3) {
            return Err(GltfError::NotTriangles {
                mesh: m,
                primitive: p,
                corners: n_corners,
            }
            .at(path));
        }
        if topology == Topology::Lines && !n_corners.is_multiple_of(2) {
            return Err(GltfError::NotLines {
                mesh: m,
                primitive: p,
                ends: n_corners,
            }
            .at(path));
        }
        let positions: Vec<[f32; 3]> = values::<3>(draco, at, (m, p), "POSITION", &pos_acc)?
            .into_iter()
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
        let mut indices: Vec<u32> = match (draco, prim.indices()) {
            (Some(d), _) => d.indices.clone(),
            (None, Some(a)) => accessor::read_u32(path, &a, buffers)?,
            (None, None) => (0..n_vertices as u32).collect(),
        };
        if !list {
            indices = match topology {
                Topology::Lines => line_list(mode, &indices),
                _ => triangle_list(mode, &indices),
            };
        }
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(GltfError::IndexOutOfRange {
                mesh: m,
                primitive: p,
                index: bad,
                vertices: positions.len(),
            }
            .at(path));
        }
        if topology == Topology::Triangles && determinant3(world) < 0.0 {
            // A mirroring transform turns counter-clockwise triangles clockwise.
            for tri in indices.chunks_exact_mut(3) {
                tri.swap(1, 2);
            }
        }
        let material = prim.material().index().unwrap_or(materials.len() - 1);
        let [uv0, uv1] = [0, 1].map(|set| {
            uv_accs[set]
                .as_ref()
                .map(|a| values::<2>(draco, at, (m, p), &format!("TEXCOORD_{set}"), a))
        });
        let uvs = match uv0.transpose()? {
            Some(uv) => uv,
            None => vec![[0.0; 2]; positions.len()],
        };
        let uvs1 = match uv1.transpose()? {
            Some(uv) => uv,
            None => uvs.clone(),
        };
        let colours = match &colour_acc {
            Some(a) => values::<4>(draco, at, (m, p), "COLOR_0", a)?,
            None => vec![[1.0; 4]; positions.len()],
        };
        let tangents = match &tangent_acc {
            Some(a) => values::<4>(draco, at, (m, p), "TANGENT", a)?
                .into_iter()
                .map(|t| transform_tangent(world, t))
                .collect(),
            None => Vec::new(),
        };
        let normals = match &normal_acc {
            Some(a) => values::<3>(draco, at, (m, p), "NORMAL", a)?
                .into_iter()
                .map(|n| transform_normal(world, n))
                .collect(),
            None => Vec::new(),
        };
        let mut out = GltfPrimitive {
            tangents,
            positions,
            normals,
            uvs,
            uvs1,
            colours,
            indices,
            material,
            topology,
        };
        if topology != Topology::Triangles {
            // Lines and points: no surface, so no flat normals or tangents (without normals
            // they are drawn unlit: mesh/pipeline.rs).
            return Ok(out);
        }
        if out.normals.len() != out.positions.len() {
            out = flat_shaded(&out);
        }
        if materials[material].textures.normal.is_some() && out.tangents.is_empty() {
            generate_tangents(&mut out);
        }
        Ok(out)
    }
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
        topology: p.topology,
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

#[cfg(test)]
mod topology_tests {
    use super::{Topology, line_list, listed_count, triangle_list};
    use gltf::mesh::Mode;

    /// Strips alternate their winding back to counter-clockwise; fans turn about vertex 0
    /// (glTF 2.0 §3.7.2.1); fewer than three vertices make no triangle.
    #[test]
    fn strips_and_fans_become_lists() {
        assert_eq!(
            triangle_list(Mode::TriangleStrip, &[0, 1, 2, 3, 4]),
            [0, 1, 2, 1, 3, 2, 2, 3, 4]
        );
        assert_eq!(
            triangle_list(Mode::TriangleFan, &[0, 1, 2, 3]),
            [1, 2, 0, 2, 3, 0]
        );
        assert!(triangle_list(Mode::TriangleStrip, &[0, 1]).is_empty());
    }

    /// Line strips join consecutive vertices; loops also join the last to the first
    /// (glTF 2.0 §3.7.2.1); the counts match what the lists hold.
    #[test]
    fn line_strips_and_loops_become_lists() {
        assert_eq!(line_list(Mode::LineStrip, &[4, 5, 6]), [4, 5, 5, 6]);
        assert_eq!(line_list(Mode::LineLoop, &[4, 5, 6]), [4, 5, 5, 6, 6, 4]);
        assert!(line_list(Mode::LineStrip, &[4]).is_empty());
        assert!(line_list(Mode::LineLoop, &[4]).is_empty());
        for (mode, topology) in [
            (Mode::LineStrip, Topology::Lines),
            (Mode::LineLoop, Topology::Lines),
        ] {
            for n in 0..6u32 {
                let v: Vec<u32> = (0..n).collect();
                assert_eq!(
                    listed_count(mode, n as usize),
                    (topology, line_list(mode, &v).len()),
                    "{mode:?} of {n}"
                );
            }
        }
        for n in 0..6u32 {
            let v: Vec<u32> = (0..n).collect();
            for mode in [Mode::TriangleStrip, Mode::TriangleFan] {
                assert_eq!(
                    listed_count(mode, n as usize),
                    (Topology::Triangles, triangle_list(mode, &v).len())
                );
            }
        }
        assert_eq!(listed_count(Mode::Points, 7), (Topology::Points, 7));
        assert_eq!(listed_count(Mode::Lines, 8), (Topology::Lines, 8));
    }
}
