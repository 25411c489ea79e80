//! `KHR_draco_mesh_compression` (`nacre_runtime::gltf_scene`, `draco.rs`), without a GPU:
//!
//! * the Draco asset made here (`tests/golden/gltf/draco/`: `source.gltf`, compressed by
//!   `scripts/draco-fixture.sh` into `source-draco.glb`) decodes to its source mesh: the same
//!   triangles over the same vertices, each attribute within its quantisation step;
//! * Khronos' Draco Box and Duck (`../shared/gltf-core-samples/`, see `../shared/DATA.md`;
//!   not part of this repository) decode to the vertices and triangles of their plain
//!   variants — the directory missing is a failure when `CI` is set, a skip elsewhere;
//! * the extension's rules: unique ids (not stream order) pick the attributes; a stream that
//!   does not decode is an error naming the primitive when the extension is required, and
//!   falls back to the uncompressed accessors with a note when it is optional; malformed
//!   extension objects and mismatched counts are errors.

use nacre_runtime::gltf_scene::{GltfError, GltfPrimitive, GltfScene};
use std::path::{Path, PathBuf};

mod support;
use support::{gltf_core_samples, repo_root};

fn fixture_dir() -> PathBuf {
    repo_root().join("tests/golden/gltf/draco")
}

/// A vertex: position, normal, first texture coordinates, colour.
type Vertex = [f32; 12];

/// The parts of a [`Vertex`].
const PARTS: [std::ops::Range<usize>; 4] = [0..3, 3..6, 6..8, 8..12];

fn vertex(p: &GltfPrimitive, i: usize) -> Vertex {
    let (x, n, t, c) = (p.positions[i], p.normals[i], p.uvs[i], p.colours[i]);
    [
        x[0], x[1], x[2], n[0], n[1], n[2], t[0], t[1], c[0], c[1], c[2], c[3],
    ]
}

/// Per vertex of `p`, the first vertex with exactly its attributes (a primitive may repeat a
/// vertex).
fn canonical(p: &GltfPrimitive) -> Vec<usize> {
    let mut first = std::collections::HashMap::new();
    (0..p.positions.len())
        .map(|i| *first.entry(vertex(p, i).map(f32::to_bits)).or_insert(i))
        .collect()
}

/// The triangles of `p` as vertex numbers (`number` of each index), each rotated to start at
/// its smallest, sorted.
fn triangle_set(p: &GltfPrimitive, number: impl Fn(usize) -> usize) -> Vec<[usize; 3]> {
    let mut out: Vec<[usize; 3]> = p
        .indices
        .chunks_exact(3)
        .map(|t| {
            let mut tri = [0, 1, 2].map(|k| number(t[k] as usize));
            let first = (0..3).min_by_key(|&k| tri[k]).unwrap();
            tri.rotate_left(first);
            tri
        })
        .collect();
    out.sort_unstable();
    out
}

/// Matches every vertex of `a` that a triangle uses to the nearest vertex of `b` (attributes
/// weighted by `scale`:
/// position, normal, uv, colour) and checks that the triangles of `a`, renumbered by the
/// match, are those of `b`. Returns the largest difference of a matched pair per part.
fn same_mesh(a: &GltfPrimitive, b: &GltfPrimitive, scale: [f32; 4]) -> [f32; 4] {
    let (ca, cb) = (canonical(a), canonical(b));
    let vb: Vec<(usize, Vertex)> = (0..b.positions.len())
        .filter(|&j| cb[j] == j)
        .map(|j| (j, vertex(b, j)))
        .collect();
    let weight = |k: usize| scale[PARTS.iter().position(|r| r.contains(&k)).unwrap()];
    let mut matched = vec![usize::MAX; a.positions.len()];
    let mut worst = [0.0f32; 4];
    let mut used = vec![false; a.positions.len()];
    for &i in &a.indices {
        used[ca[i as usize]] = true;
    }
    for i in (0..a.positions.len()).filter(|&i| used[i]) {
        let va = vertex(a, i);
        let distance =
            |v: &Vertex| -> f32 { (0..12).map(|k| ((va[k] - v[k]) / weight(k)).powi(2)).sum() };
        let (j, v) = vb
            .iter()
            .min_by(|x, y| distance(&x.1).total_cmp(&distance(&y.1)))
            .unwrap();
        matched[i] = *j;
        for (k, range) in PARTS.into_iter().enumerate() {
            for c in range {
                worst[k] = worst[k].max((va[c] - v[c]).abs());
            }
        }
    }
    assert_eq!(
        triangle_set(a, |i| matched[ca[i]]),
        triangle_set(b, |j| cb[j]),
        "the triangles differ"
    );
    worst
}

/// Bounds (min, max) of a scene, and the largest size of its box.
fn extent(scene: &GltfScene) -> f32 {
    let (lo, hi) = scene.bounds();
    (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f32::max)
}

#[test]
fn khronos_draco_box_and_duck_decode_to_their_plain_models() {
    let Some(dir) = gltf_core_samples() else {
        return;
    };
    // Box: exact (its stream's quantisation reproduces the plain file's values); Duck:
    // gltf-pipeline's defaults, position 11 bits, normal 8 bits octahedral, texcoord 10 bits.
    for (model, position_bits, normal_tol, uv_tol) in [
        ("Box", 14, 1e-6f32, 1e-6f32),
        ("Duck", 11, 1.6e-2, 1.0 / 1024.0),
    ] {
        let plain = GltfScene::load(&dir.join(format!("{model}/glTF/{model}.gltf"))).unwrap();
        let draco = GltfScene::load(&dir.join(format!("{model}/glTF-Draco/{model}.gltf"))).unwrap();
        assert!(draco.notes.is_empty(), "{model}: {:?}", draco.notes);
        assert_eq!(plain.primitives.len(), 1);
        assert_eq!(draco.primitives.len(), 1);
        let (p, d) = (&plain.primitives[0], &draco.primitives[0]);
        assert_eq!(p.positions.len(), d.positions.len(), "{model}: vertices");
        assert_eq!(p.indices.len(), d.indices.len(), "{model}: corners");
        // Positions quantised over the model's extent.
        let step = extent(&plain) / f32::from(1u16 << position_bits);
        let (pb, db) = (plain.bounds(), draco.bounds());
        for k in 0..3 {
            assert!(
                (pb.0[k] - db.0[k]).abs() <= step && (pb.1[k] - db.1[k]).abs() <= step,
                "{model}: bounds {pb:?} vs {db:?}"
            );
        }
        let worst = same_mesh(p, d, [step, normal_tol.max(1e-3), uv_tol.max(1e-3), 1.0]);
        eprintln!(
            "{model}: {} vertices, {} triangles; largest differences: position {:.2e} (step {step:.2e}), normal {:.2e}, uv {:.2e}",
            d.positions.len(),
            d.indices.len() / 3,
            worst[0],
            worst[1],
            worst[2]
        );
        assert!(
            worst[0] <= step,
            "{model}: positions differ by {}",
            worst[0]
        );
        assert!(
            worst[1] <= normal_tol,
            "{model}: normals differ by {}",
            worst[1]
        );
        assert!(worst[2] <= uv_tol, "{model}: uvs differ by {}", worst[2]);
    }
}

/// The source mesh of the Draco fixtures and the primitive of `file` (in the fixture dir).
fn fixture(file: &str) -> (GltfPrimitive, GltfScene) {
    let source = GltfScene::load(&fixture_dir().join("source.gltf")).unwrap();
    let scene = GltfScene::load(&fixture_dir().join(file)).unwrap();
    assert!(scene.notes.is_empty(), "{file}: {:?}", scene.notes);
    assert_eq!(scene.primitives.len(), 1);
    (source.primitives[0].clone(), scene)
}

#[test]
fn draco_fixtures_decode_to_their_source_mesh() {
    // gen_draco_fixture.py's quantisation: position 14 bits over the extent 2, texcoord 12
    // bits over 1, colour 8 bits over 1, normals 10-bit octahedral.
    let steps = [2.0 / 16384.0, 4.0 / 1024.0, 1.0 / 4096.0, 1.0 / 255.0];
    for file in ["source-edgebreaker.glb", "source-sequential.glb"] {
        let (source, scene) = fixture(file);
        let d = &scene.primitives[0];
        assert_eq!(d.indices.len(), source.indices.len(), "{file}: corners");
        let worst = same_mesh(&source, d, steps);
        eprintln!(
            "{file}: {} vertices ({} in the source), {} triangles; largest differences: position {:.2e}, normal {:.2e}, uv {:.2e}, colour {:.2e}",
            d.positions.len(),
            source.positions.len(),
            d.indices.len() / 3,
            worst[0],
            worst[1],
            worst[2],
            worst[3]
        );
        for k in 0..4 {
            assert!(
                worst[k] <= steps[k],
                "{file}: part {k} differs by {} (step {})",
                worst[k],
                steps[k]
            );
        }
    }
}

/// The JSON and BIN chunks of a GLB.
fn glb_parts(bytes: &[u8]) -> (serde_json::Value, Vec<u8>) {
    let le = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let json_len = le(12);
    let json = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin_at = 20 + json_len;
    (json, bytes[bin_at + 8..bin_at + 8 + le(bin_at)].to_vec())
}

/// The edgebreaker fixture with `edit` applied to its JSON (`bin` its BIN chunk).
fn edited(edit: impl FnOnce(&mut serde_json::Value, &mut Vec<u8>)) -> Vec<u8> {
    let bytes = std::fs::read(fixture_dir().join("source-edgebreaker.glb")).unwrap();
    let (mut json, mut bin) = glb_parts(&bytes);
    edit(&mut json, &mut bin);
    json["buffers"][0]["byteLength"] = bin.len().into();
    nacre_runtime::gltf_scene::assets::glb(&json, &bin)
}

/// The edgebreaker fixture with an uncompressed copy of its decoded mesh in buffer views
/// (texture coordinates doubled, to tell the copy from the stream), `KHR_draco_mesh_compression`
/// in `extensionsRequired` when `required`, its stream cut to `stream_bytes` when given.
fn with_uncompressed_copy(required: bool, stream_bytes: Option<usize>) -> Vec<u8> {
    let decoded = GltfScene::load(&fixture_dir().join("source-edgebreaker.glb")).unwrap();
    let d = decoded.primitives[0].clone();
    edited(|json, bin| {
        let floats = |v: Vec<f32>| -> Vec<u8> { v.iter().flat_map(|x| x.to_le_bytes()).collect() };
        let copies = [
            (1, floats(d.positions.iter().flatten().copied().collect())),
            (2, floats(d.normals.iter().flatten().copied().collect())),
            (3, floats(d.uvs.iter().flatten().map(|x| 2.0 * x).collect())),
            (4, floats(d.colours.iter().flatten().copied().collect())),
            (
                0,
                d.indices
                    .iter()
                    .flat_map(|&i| (i as u16).to_le_bytes())
                    .collect(),
            ),
        ];
        for (accessor, data) in copies {
            while bin.len() % 4 != 0 {
                bin.push(0);
            }
            let views = json["bufferViews"].as_array_mut().unwrap();
            views.push(serde_json::json!({
                "buffer": 0, "byteOffset": bin.len(), "byteLength": data.len()
            }));
            json["accessors"][accessor]["bufferView"] = (views.len() - 1).into();
            bin.extend(data);
        }
        if !required {
            json.as_object_mut().unwrap().remove("extensionsRequired");
        }
        if let Some(n) = stream_bytes {
            json["bufferViews"][0]["byteLength"] = n.into();
        }
    })
}

fn gltf_error(bytes: &[u8]) -> GltfError {
    match GltfScene::from_bytes(bytes, Path::new("draco.glb")) {
        Err(nacre_runtime::Error::Gltf { error, .. }) => error,
        other => panic!("expected a glTF error, got {other:?}"),
    }
}

#[test]
fn an_optional_draco_stream_is_read_and_falls_back_to_its_accessors() {
    let path = Path::new("draco.glb");
    let max_u = |scene: &GltfScene| {
        scene.primitives[0]
            .uvs
            .iter()
            .map(|t| t[0])
            .fold(0.0f32, f32::max)
    };
    // The stream decodes: its values, not the (doubled) copy's.
    let scene = GltfScene::from_bytes(&with_uncompressed_copy(false, None), path).unwrap();
    assert!(scene.notes.is_empty(), "{:?}", scene.notes);
    assert!((max_u(&scene) - 1.0).abs() < 1e-3, "{}", max_u(&scene));
    // A stream cut short: the uncompressed copy, with a note.
    let scene = GltfScene::from_bytes(&with_uncompressed_copy(false, Some(16)), path).unwrap();
    assert_eq!(scene.notes.len(), 1, "{:?}", scene.notes);
    assert!(
        scene.notes[0].starts_with(
            "mesh 0 primitive 0: its KHR_draco_mesh_compression stream (buffer view 0) does not decode ("
        ),
        "{}",
        scene.notes[0]
    );
    assert!((max_u(&scene) - 2.0).abs() < 1e-3, "{}", max_u(&scene));
    // Required: no fallback, the primitive and the decoder's reason.
    match gltf_error(&with_uncompressed_copy(true, Some(16))) {
        GltfError::Draco {
            mesh: 0,
            primitive: 0,
            view: 0,
            what,
        } => assert!(!what.is_empty()),
        other => panic!("expected a Draco error, got {other:?}"),
    }
    // Optional without an uncompressed copy: an error too.
    let cut = edited(|json, _| {
        json.as_object_mut().unwrap().remove("extensionsRequired");
        json["bufferViews"][0]["byteLength"] = 16.into();
    });
    assert!(matches!(gltf_error(&cut), GltfError::Draco { view: 0, .. }));
}

#[test]
fn draco_attributes_are_picked_by_unique_id_and_checked() {
    let draco = |what: &str| {
        let what = what.to_string();
        move |error: GltfError| match error {
            GltfError::Draco {
                mesh: 0,
                primitive: 0,
                view: 0,
                what: found,
            } => assert_eq!(found, what),
            other => panic!("expected a Draco error, got {other:?}"),
        }
    };
    let ext = |json: &mut serde_json::Value| -> serde_json::Value {
        json["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"].clone()
    };
    let set = |json: &mut serde_json::Value, member: &str, value: serde_json::Value| {
        let mut e = ext(json);
        e[member] = value;
        json["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"] = e;
    };
    // The fixture's map: POSITION 0, NORMAL 1, TEXCOORD_0 2, COLOR_0 3.
    draco("POSITION: the stream has no attribute of unique id 7 (its ids: 0, 1, 2, 3)")(
        gltf_error(&edited(|j, _| {
            let mut a = ext(j)["attributes"].clone();
            a["POSITION"] = 7.into();
            set(j, "attributes", a);
        })),
    );
    // TEXCOORD_0 given NORMAL's id: three components where the accessor declares two.
    draco("TEXCOORD_0 (accessor 3): decoded as 3 × F32, the accessor declares 2 × F32")(
        gltf_error(&edited(|j, _| {
            let mut a = ext(j)["attributes"].clone();
            a["TEXCOORD_0"] = 1.into();
            set(j, "attributes", a);
        })),
    );
    // Counts that differ from the stream's.
    draco(
        "POSITION (accessor 1): the accessor declares 114 elements, the stream decodes 115 points",
    )(gltf_error(&edited(|j, _| {
        for a in 1..5 {
            j["accessors"][a]["count"] = 114.into();
        }
    })));
    draco("indices (accessor 0): the accessor declares 501 corners, the stream decodes 504")(
        gltf_error(&edited(|j, _| j["accessors"][0]["count"] = 501.into())),
    );
    // A malformed extension object.
    match gltf_error(&edited(|j, _| set(j, "bufferView", "zero".into()))) {
        GltfError::DracoExtension {
            mesh: 0,
            primitive: 0,
            what,
        } => assert_eq!(
            what,
            "`bufferView` is \"zero\" (expected a buffer view index)"
        ),
        other => panic!("expected a DracoExtension error, got {other:?}"),
    }
    assert_eq!(
        gltf_error(&edited(|j, _| set(j, "bufferView", 5.into()))),
        GltfError::Draco {
            mesh: 0,
            primitive: 0,
            view: 5,
            what: "the file has 1 buffer views".into()
        }
    );
}

#[test]
fn damaged_draco_streams_are_errors_not_panics() {
    // Every cut of the stream, and every byte of it changed (three ways): an error or a mesh,
    // never a panic.
    let bytes = std::fs::read(fixture_dir().join("source-edgebreaker.glb")).unwrap();
    let (json, bin) = glb_parts(&bytes);
    let view_len = json["bufferViews"][0]["byteLength"].as_u64().unwrap() as usize;
    let load = |json: &serde_json::Value, bin: &[u8]| {
        let glb = nacre_runtime::gltf_scene::assets::glb(json, bin);
        let _ = GltfScene::from_bytes(&glb, Path::new("damaged.glb"));
    };
    let (mut errors, mut loads) = (0, 0);
    for n in 0..view_len {
        let mut j = json.clone();
        j["bufferViews"][0]["byteLength"] = n.into();
        load(&j, &bin);
    }
    for at in 0..view_len {
        for change in [|b: u8| b ^ 0x01, |b: u8| b ^ 0x80, |_| 0xff] {
            let mut b = bin.clone();
            b[at] = change(b[at]);
            let glb = nacre_runtime::gltf_scene::assets::glb(&json, &b);
            match GltfScene::from_bytes(&glb, Path::new("damaged.glb")) {
                Ok(_) => loads += 1,
                Err(_) => errors += 1,
            }
        }
    }
    eprintln!(
        "{view_len} cuts; {} changed bytes: {errors} errors, {loads} loads",
        3 * view_len
    );
}
