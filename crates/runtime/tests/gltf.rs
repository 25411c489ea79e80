//! glTF scenes (`nacre_runtime::gltf_scene`, `mesh`, `gltf_scene::assets`, `shaders/mesh.wgsl`):
//!
//! * the committed sweeps under `tests/golden/gltf/` are what `gltf_scene::assets` writes, byte for
//!   byte (`NACRE_UPDATE_GOLDEN=1` rewrites them and the golden image);
//! * naga validates and translates the mesh pipeline of every technique (no GPU);
//! * every sweep renders with lut and fourier, the spheres show colour, and spheres whose
//!   parameters differ get different colours;
//! * one golden image (the thickness sweep, lut) under the thresholds of `tests/render.rs`;
//! * bad files (missing, truncated, absurd sizes, a LINES primitive of odd count) are errors;
//! * points, lines, line strips and line loops, indexed or not, are drawn where they lie.

use nacre_runtime::gltf_scene::assets::{SPHERE_SPACING, SWEEPS, sweep_glb};
use nacre_runtime::gltf_scene::{GltfError, GltfScene};
use nacre_runtime::mesh::{fit_camera, render_gltf};
use nacre_runtime::render::{FilmEval, RenderedImage, SceneKind, SceneOptions};
use nacre_runtime::shaders::{MATERIAL, MESH, compose};
use nacre_runtime::{TableSet, Technique};
use naga::valid::{Capabilities, ValidationFlags, Validator};
use std::path::{Path, PathBuf};

mod support;
use support::{ctx, film_tables, manifest, repo_root};

fn asset_dir() -> PathBuf {
    repo_root().join("tests/golden/gltf")
}

fn updating() -> bool {
    std::env::var("NACRE_UPDATE_GOLDEN").is_ok_and(|v| v == "1")
}

/// Image size of the sweep renders: five spheres in a row.
const SIZE: (u32, u32) = (200, 56);

fn options() -> SceneOptions {
    let mut o = SceneOptions::new(SceneKind::Sphere);
    (o.width, o.height) = SIZE;
    o
}

#[test]
fn committed_assets_are_reproduced_byte_for_byte() {
    if updating() {
        nacre_runtime::gltf_scene::assets::write_sweeps(&asset_dir()).unwrap();
    }
    for sweep in &SWEEPS {
        let path = asset_dir().join(sweep.file);
        let committed = std::fs::read(&path).unwrap_or_else(|e| {
            panic!(
                "{}: {e} (regenerate with NACRE_UPDATE_GOLDEN=1 cargo test -p nacre-runtime --test gltf)",
                path.display()
            )
        });
        assert!(
            committed == sweep_glb(sweep),
            "{} differs from gltf_scene::assets::sweep_glb",
            path.display()
        );
        assert!(
            committed.len() < 64 * 1024,
            "{} is not small",
            path.display()
        );
        let scene = GltfScene::load(&path).unwrap();
        assert_eq!(scene.primitives.len(), 5);
    }
}

#[test]
fn mesh_pipelines_validate_for_every_technique() {
    for technique in Technique::ALL {
        let name = format!("mesh + film_{}", technique.name());
        let source = compose(technique, &[MATERIAL, MESH]);
        let module = naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
        let info = Validator::new(ValidationFlags::all(), Capabilities::default())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
        // Both pipelines: lit, and unlit lines and points (MESH_PRIMITIVE_UNLIT).
        let variants = support::resolved(&name, &module, &info);
        assert_eq!(variants.len(), 2, "{name}: MESH_PRIMITIVE_UNLIT");
        for (module, info) in variants {
            naga::back::spv::write_vec(&module, &info, &Default::default(), None)
                .unwrap_or_else(|e| panic!("{name}: SPIR-V: {e}"));
        }
        for entry in ["mesh_vs", "mesh_fs"] {
            assert!(
                module.entry_points.iter().any(|e| e.name == entry),
                "{name}: {entry}"
            );
        }
    }
}

/// The image's pixel (x, y) of world point p under the renderer's fitted camera.
fn project(scene: &GltfScene, p: [f32; 3]) -> (u32, u32) {
    project_in(scene, p, SIZE)
}

/// [`project`] in an image of `size`.
fn project_in(scene: &GltfScene, p: [f32; 3], size: (u32, u32)) -> (u32, u32) {
    let (lo, hi) = scene.bounds();
    let cam = fit_camera(lo, hi, f64::from(size.0) / f64::from(size.1)).unwrap();
    let m = cam.view_proj;
    let c: [f32; 4] =
        std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r]);
    let (x, y) = (c[0] / c[3], c[1] / c[3]);
    (
        ((x * 0.5 + 0.5) * size.0 as f32) as u32,
        ((0.5 - y * 0.5) * size.1 as f32) as u32,
    )
}

/// The mean RGB of the 3×3 pixels around the front of sphere k (slightly above centre, off
/// the mirror image of the camera).
fn sphere_colour(scene: &GltfScene, image: &RenderedImage, k: usize) -> [f64; 3] {
    let (x, y) = project(scene, [(k as f32 - 2.0) * SPHERE_SPACING, 0.35, 0.9]);
    let mut sum = [0.0; 3];
    for dy in 0..3 {
        for dx in 0..3 {
            let i = (((y + dy - 1) * image.width + x + dx - 1) * 4) as usize;
            for (c, s) in sum.iter_mut().enumerate() {
                *s += f64::from(image.pixels[i + c]) / 9.0;
            }
        }
    }
    sum
}

fn pixel(image: &RenderedImage, (x, y): (u32, u32)) -> [f64; 3] {
    let i = ((y * image.width + x) * 4) as usize;
    [0, 1, 2].map(|c| f64::from(image.pixels[i + c]))
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f64::max)
}

#[test]
fn sweeps_render_and_parameters_change_colours() {
    let ctx = ctx();
    let tables = film_tables("film-dielectric");
    for technique in [Technique::Lut, Technique::Fourier] {
        for sweep in &SWEEPS {
            let name = format!("{} ({})", sweep.file, technique.name());
            let scene = GltfScene::load(&asset_dir().join(sweep.file)).unwrap();
            let out = render_gltf(ctx, &tables, technique, &scene, &options())
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let image = &out.image;
            assert_eq!((image.width, image.height), SIZE);
            let background = [image.pixels[0], image.pixels[1], image.pixels[2]];
            let covered = image
                .pixels
                .chunks_exact(4)
                .filter(|p| [p[0], p[1], p[2]] != background)
                .count();
            let fraction = covered as f64 / f64::from(SIZE.0 * SIZE.1);
            assert!(
                fraction > 0.2 && fraction < 0.9,
                "{name}: spheres cover {fraction}"
            );
            let colours: Vec<[f64; 3]> = (0..5).map(|k| sphere_colour(&scene, image, k)).collect();
            eprintln!("{name}: {colours:?}; notes {:?}", out.notes);
            let pairs: &[(usize, usize)] = match sweep.file {
                // Every thickness gives its own interference colour.
                "sweep-thickness.glb" => &[(0, 1), (1, 2), (2, 3), (3, 4), (0, 4)],
                // A film of index 1 (the ambient's) is no film; the others are.
                "sweep-iridescence-ior.glb" => &[(0, 2), (0, 4), (2, 4)],
                "sweep-base-ior.glb" => &[(0, 4)],
                "sweep-metallic.glb" => &[(0, 4)],
                "sweep-thickness-texture.glb" => &[(0, 4), (1, 3)],
                _ => &[(0, 4), (0, 2)],
            };
            for &(a, b) in pairs {
                let d = distance(colours[a], colours[b]);
                assert!(
                    d >= 4.0,
                    "{name}: spheres {a} and {b} look alike ({d}): {colours:?}"
                );
            }
            if sweep.file == "sweep-thickness-texture.glb" {
                // The texture's green channel runs from 0 (top) to 1 (bottom): d from 100 nm
                // to d_max, so the top and the bottom of each sphere differ in colour.
                assert!(out.notes.is_empty(), "{name}: {:?}", out.notes);
                for k in [2, 4] {
                    let x = (k as f32 - 2.0) * SPHERE_SPACING;
                    let top = pixel(image, project(&scene, [x, 0.75, 0.6]));
                    let bottom = pixel(image, project(&scene, [x, -0.75, 0.6]));
                    let d = distance(top, bottom);
                    assert!(d >= 8.0, "{name}: sphere {k} top {top:?} bottom {bottom:?}");
                }
            }
            if technique == Technique::Lut && sweep.file == "sweep-metallic.glb" {
                assert!(
                    out.notes
                        .iter()
                        .any(|n| n.to_string().contains("fourier instead of lut")),
                    "{name}: metals fall back to fourier with film-dielectric: {:?}",
                    out.notes
                );
            }
        }
    }
}

/// The rough-film paths of issue 6 on glTF meshes: `nv` and `exact` render the thickness
/// sweep (roughnessFactor 0.2, GGX α 0.04) with the same coverage as `classic`, keep the
/// five thicknesses apart, stay close to `classic` at this low roughness (the paths differ
/// in how they light the environment, not in the film), and really are other paths (the
/// images differ). `exact` needs the rough-film-lut table and refuses to run without it.
#[test]
fn gltf_meshes_render_with_the_rough_film_paths() {
    let ctx = ctx();
    let mut tables = film_tables("film-dielectric");
    let scene = GltfScene::load(&asset_dir().join("sweep-thickness.glb")).unwrap();
    let render = |tables: &TableSet, film_eval: FilmEval| {
        let mut o = options();
        o.film_eval = film_eval;
        render_gltf(ctx, tables, Technique::Lut, &scene, &o)
    };
    let err = render(&tables, FilmEval::Exact)
        .err()
        .expect("exact without its table");
    assert!(err.to_string().contains("rough-film-lut"), "{err}");
    tables.add(ctx, &manifest("rough-film-dielectric")).unwrap();
    let classic = render(&tables, FilmEval::Classic).unwrap().image;
    let background = |image: &RenderedImage| [image.pixels[0], image.pixels[1], image.pixels[2]];
    let covered = |image: &RenderedImage| {
        let bg = background(image);
        image
            .pixels
            .chunks_exact(4)
            .filter(|p| [p[0], p[1], p[2]] != bg)
            .count()
    };
    let reference: Vec<[f64; 3]> = (0..5).map(|k| sphere_colour(&scene, &classic, k)).collect();
    for film_eval in [FilmEval::NormalView, FilmEval::Exact] {
        let name = format!("{film_eval:?}");
        let out = render(&tables, film_eval).unwrap_or_else(|e| panic!("{name}: {e}"));
        let image = &out.image;
        let (a, b) = (covered(image) as f64, covered(&classic) as f64);
        assert!(
            (a - b).abs() <= 0.02 * b,
            "{name}: covers {a} pixels, classic {b}"
        );
        assert_ne!(
            image.pixels, classic.pixels,
            "{name}: same image as classic"
        );
        let colours: Vec<[f64; 3]> = (0..5).map(|k| sphere_colour(&scene, image, k)).collect();
        eprintln!("{name}: {colours:?} (classic {reference:?})");
        for (k, (c, r)) in colours.iter().zip(&reference).enumerate() {
            let d = distance(*c, *r);
            assert!(d <= 20.0, "{name}: sphere {k} {c:?} vs classic {r:?} ({d})");
        }
        for (a, b) in [(0, 1), (1, 2), (2, 3), (3, 4), (0, 4)] {
            let d = distance(colours[a], colours[b]);
            assert!(d >= 4.0, "{name}: spheres {a} and {b} look alike ({d})");
        }
    }
}

/// RGB8 pixels of a PNG.
fn read_png_rgb(path: &Path) -> Option<(u32, u32, Vec<u8>)> {
    let image = image::ImageReader::open(path).ok()?.decode().ok()?;
    let image::DynamicImage::ImageRgb8(rgb) = image else {
        return None;
    };
    Some((rgb.width(), rgb.height(), rgb.into_raw()))
}

// Threshold as tests/render.rs's STRICT (set on Mesa lavapipe; no hardware adapter was
// available): mean ≤ 1.5 levels, at most 1 % of pixels (silhouettes of the rasterised
// spheres) beyond 24 levels.
#[test]
fn golden_image_of_the_thickness_sweep() {
    let ctx = ctx();
    let tables = film_tables("film-dielectric");
    let scene = GltfScene::load(&asset_dir().join("sweep-thickness.glb")).unwrap();
    let out = render_gltf(ctx, &tables, Technique::Lut, &scene, &options()).unwrap();
    let reference_path = asset_dir().join("sweep-thickness-lut.png");
    if updating() {
        out.image.write_png(&reference_path).unwrap();
        return;
    }
    let (w, h, reference) = read_png_rgb(&reference_path).unwrap_or_else(|| {
        panic!(
            "no reference {} (record it with NACRE_UPDATE_GOLDEN=1)",
            reference_path.display()
        )
    });
    assert_eq!((w, h), SIZE);
    let actual: Vec<u8> = out
        .image
        .pixels
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    let mut sum = 0u64;
    let mut over = 0usize;
    for (a, r) in actual.chunks_exact(3).zip(reference.chunks_exact(3)) {
        sum += (0..3).map(|c| u64::from(a[c].abs_diff(r[c]))).sum::<u64>();
        if (0..3).any(|c| a[c].abs_diff(r[c]) > 24) {
            over += 1;
        }
    }
    let mean = sum as f64 / actual.len() as f64;
    let over = over as f64 / (actual.len() / 3) as f64;
    if !(mean <= 1.5 && over <= 0.01) {
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("golden-gltf");
        std::fs::create_dir_all(&dir).unwrap();
        let actual_path = dir.join("sweep-thickness-lut-actual.png");
        out.image.write_png(&actual_path).unwrap();
        panic!(
            "sweep-thickness-lut: mean {mean:.3}, {:.2}% over 24; actual {}",
            100.0 * over,
            actual_path.display()
        );
    }
}

#[test]
fn bad_gltf_files_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let expect_err = |path: &Path, what: &str| {
        let e = GltfScene::load(path).expect_err(what);
        eprintln!("{what}: {e}");
        e
    };
    // The typed glTF error of `path`: the file named, the index and value carried.
    let gltf_err = |path: &Path, what: &str| match expect_err(path, what) {
        nacre_runtime::Error::Gltf { path: p, error } => {
            assert_eq!(p, path, "{what}");
            error
        }
        other => panic!("{what}: expected Error::Gltf, got {other:?}"),
    };
    expect_err(&dir.path().join("missing.glb"), "missing file");
    let good = sweep_glb(&SWEEPS[0]);
    let truncated = dir.path().join("truncated.glb");
    std::fs::write(&truncated, &good[..good.len() / 2]).unwrap();
    expect_err(&truncated, "truncated GLB");
    let garbage = dir.path().join("garbage.gltf");
    std::fs::write(&garbage, b"{ not json").unwrap();
    expect_err(&garbage, "not JSON");

    // Rewrite the JSON chunk of a good GLB.
    let patch = |edit: &dyn Fn(&mut serde_json::Value)| -> Vec<u8> {
        let json_len = u32::from_le_bytes(good[12..16].try_into().unwrap()) as usize;
        let mut doc: serde_json::Value = serde_json::from_slice(&good[20..20 + json_len]).unwrap();
        edit(&mut doc);
        let bin_start = 20 + json_len + 8;
        nacre_runtime::gltf_scene::assets::glb(&doc, &good[bin_start..])
    };
    let odd_lines = dir.path().join("odd-lines.glb");
    std::fs::write(
        &odd_lines,
        patch(&|d| {
            d["meshes"][0]["primitives"][0]["mode"] = 1.into();
            let indices = d["meshes"][0]["primitives"][0]["indices"].as_u64().unwrap();
            d["accessors"][indices as usize]["count"] = 3.into();
        }),
    )
    .unwrap();
    assert!(
        matches!(
            gltf_err(&odd_lines, "LINES of 3 ends"),
            GltfError::NotLines { ends: 3, .. }
        ),
        "LINES of 3 ends"
    );
    let huge = dir.path().join("huge.glb");
    std::fs::write(
        &huge,
        patch(&|d| d["accessors"][0]["count"] = 1_000_000_000u64.into()),
    )
    .unwrap();
    assert!(
        matches!(
            gltf_err(&huge, "absurd accessor count"),
            GltfError::AccessorBeyondView { accessor: 0, .. }
        ),
        "absurd accessor count"
    );
    let quantized = dir.path().join("quantized.glb");
    std::fs::write(
        &quantized,
        patch(&|d| d["accessors"][0]["componentType"] = 5123.into()),
    )
    .unwrap();
    let e = gltf_err(&quantized, "non-float positions");
    assert!(
        matches!(&e, GltfError::AccessorType { semantic, accessor: 0, found, .. } if semantic == "POSITION" && found.contains("U16")),
        "{e:?}"
    );
    let bad_index = dir.path().join("bad-index.glb");
    std::fs::write(
        &bad_index,
        patch(&|d| d["meshes"][0]["primitives"][0]["indices"] = 7.into()),
    )
    .unwrap();
    let e = gltf_err(&bad_index, "dangling accessor index");
    assert!(
        matches!(
            e,
            GltfError::NotGltf { .. } | GltfError::MissingAccessor { accessor: 7, .. }
        ),
        "{e:?}"
    );
    let required = dir.path().join("required.glb");
    std::fs::write(
        &required,
        patch(&|d| d["extensionsRequired"] = serde_json::json!(["EXT_nacre_unknown"])),
    )
    .unwrap();
    let e = gltf_err(&required, "unsupported required extension");
    assert!(
        matches!(&e, GltfError::UnsupportedExtension { extension, .. } if extension == "EXT_nacre_unknown"),
        "{e:?}"
    );
    assert!(e.to_string().contains("EXT_nacre_unknown"), "{e}");
    let far = dir.path().join("far.glb");
    std::fs::write(
        &far,
        patch(&|d| {
            d["nodes"][0]["translation"] = serde_json::json!([3e38, 3e38, 3e38]);
            d["nodes"][0]["scale"] = serde_json::json!([1e38, 1e38, 1e38]);
        }),
    )
    .unwrap();
    let e = gltf_err(&far, "overflowing position");
    assert!(
        matches!(e, GltfError::NonFinitePosition { value, .. } if value.iter().any(|x| !x.is_finite())),
        "{e:?}"
    );
    let nan = dir.path().join("nan.glb");
    std::fs::write(
        &nan,
        patch(&|d| d["nodes"][0]["scale"] = serde_json::json!([1e30, 1e30, 1e30])),
    )
    .unwrap();
    // A finite but absurd scale is accepted by the loader (bounds stay finite).
    let _ = GltfScene::load(&nan);

    // A thickness texture nacre cannot decode (GIF) is skipped with a note: d = d_max.
    let textured = sweep_glb(&SWEEPS[5]);
    let json_len = u32::from_le_bytes(textured[12..16].try_into().unwrap()) as usize;
    let mut doc: serde_json::Value = serde_json::from_slice(&textured[20..20 + json_len]).unwrap();
    doc["images"][0]["mimeType"] = "image/gif".into();
    let gif = dir.path().join("gif.glb");
    std::fs::write(
        &gif,
        nacre_runtime::gltf_scene::assets::glb(&doc, &textured[20 + json_len + 8..]),
    )
    .unwrap();
    let scene = GltfScene::load(&gif).unwrap();
    assert!(scene.thickness_maps.iter().all(Option::is_none));
    assert_eq!(scene.notes.len(), 5, "{:?}", scene.notes);
    assert!(
        scene.notes[0].contains("PNG or JPEG only"),
        "{:?}",
        scene.notes
    );

    // Absurd image sizes are refused before any GPU work.
    let scene = GltfScene::load(&asset_dir().join(SWEEPS[0].file)).unwrap();
    let tables = film_tables("film-dielectric");
    for width in [0, 100_000] {
        let mut o = options();
        o.width = width;
        assert!(render_gltf(ctx(), &tables, Technique::Fourier, &scene, &o).is_err());
    }
}

/// The file's cameras and KHR_lights_punctual lights are read with their nodes' transforms;
/// `--camera N` past the last is refused naming the count; every light is drawn (up to
/// `MAX_PUNCTUAL_LIGHTS`, then the brightest at the scene's centre, with a note), and a file
/// without lights is lit by the environment alone.
#[test]
fn cameras_and_lights_come_from_the_file() {
    use nacre_runtime::gltf_scene::{GltfProjection, LightKind};
    use nacre_runtime::mesh::{ViewPoint, scene_lights, view_camera};
    use nacre_runtime::render::{MAX_PUNCTUAL_LIGHTS, PunctualKind};
    let dir = tempfile::tempdir().unwrap();
    let good = sweep_glb(&SWEEPS[0]);
    let json_len = u32::from_le_bytes(good[12..16].try_into().unwrap()) as usize;
    let mut doc: serde_json::Value = serde_json::from_slice(&good[20..20 + json_len]).unwrap();
    let bin = good[20 + json_len + 8..].to_vec();
    let plain = GltfScene::from_bytes(&good, &dir.path().join("plain.glb")).unwrap();
    assert!(plain.cameras.is_empty() && plain.lights.is_empty());
    let (light, punctual, note) = scene_lights(&plain);
    assert_eq!(
        light.intensity, 0.0,
        "no lights in the file: environment only"
    );
    assert!(punctual.is_empty() && note.is_none());
    let e = view_camera(&plain, ViewPoint::File(0), 1.0).unwrap_err();
    assert!(
        e.to_string().contains("camera = 0") || e.to_string().contains("0 camera"),
        "{e}"
    );

    doc["cameras"] = serde_json::json!([
        { "type": "perspective", "perspective": { "yfov": 0.5, "znear": 0.05 } },
        { "type": "orthographic", "orthographic": { "xmag": 2.0, "ymag": 1.0, "znear": 0.0, "zfar": 100.0 } }
    ]);
    doc["extensionsUsed"] = serde_json::json!(["KHR_lights_punctual"]);
    doc["extensions"] = serde_json::json!({ "KHR_lights_punctual": { "lights": [
        { "type": "directional", "color": [1.0, 0.9, 0.8], "intensity": 2.0, "name": "sun" },
        { "type": "point", "intensity": 5000.0, "name": "bulb", "range": 40.0 }
    ]}});
    let nodes = doc["nodes"].as_array_mut().unwrap();
    let first = nodes.len();
    // A camera 4 units along +z looking at the origin; a sun shining straight down (its −z
    // turned to −y); a bright bulb 10 units above.
    nodes.push(serde_json::json!({ "camera": 0, "translation": [0.0, 0.0, 4.0] }));
    nodes.push(serde_json::json!({ "camera": 1, "translation": [0.0, 0.0, 9.0] }));
    nodes.push(serde_json::json!({
        "rotation": [-std::f64::consts::FRAC_1_SQRT_2, 0.0, 0.0, std::f64::consts::FRAC_1_SQRT_2],
        "extensions": { "KHR_lights_punctual": { "light": 0 } }
    }));
    nodes.push(serde_json::json!({
        "translation": [0.0, 10.0, 0.0],
        "extensions": { "KHR_lights_punctual": { "light": 1 } }
    }));
    let scene_nodes = doc["scenes"][0]["nodes"].as_array_mut().unwrap();
    for k in first..first + 4 {
        scene_nodes.push(k.into());
    }
    let bytes = nacre_runtime::gltf_scene::assets::glb(&doc, &bin);
    let scene = GltfScene::from_bytes(&bytes, &dir.path().join("lit.glb")).unwrap();
    assert_eq!(scene.cameras.len(), 2);
    assert!(matches!(
        scene.cameras[0].projection,
        GltfProjection::Perspective { zfar: None, .. }
    ));
    assert!(matches!(
        scene.cameras[1].projection,
        GltfProjection::Orthographic { .. }
    ));
    let cam = view_camera(&scene, ViewPoint::File(0), 2.0).unwrap();
    assert_eq!(cam.eye, [0.0, 0.0, 4.0]);
    assert!((cam.fov_y_deg - 0.5f32.to_degrees()).abs() < 1e-3);
    assert!(view_camera(&scene, ViewPoint::File(1), 2.0).is_ok());
    let e = view_camera(&scene, ViewPoint::File(2), 2.0).unwrap_err();
    assert!(e.to_string().contains("2 camera(s)"), "{e}");

    assert_eq!(scene.lights.len(), 2);
    let sun = &scene.lights[0];
    assert_eq!(sun.kind, LightKind::Directional);
    assert!((sun.direction[1] + 1.0).abs() < 1e-6, "{:?}", sun.direction);
    assert_eq!(scene.lights[1].range, Some(40.0));
    assert_eq!(scene.lights[1].position, [0.0, 10.0, 0.0]);
    // Both drawn as they are, in the file's order; the directional light of the analytic
    // scenes is off.
    let (light, punctual, note) = scene_lights(&scene);
    assert_eq!(light.intensity, 0.0);
    assert!(note.is_none(), "{note:?}");
    assert_eq!(punctual.len(), 2);
    assert_eq!(punctual[0].kind, PunctualKind::Directional);
    assert_eq!(punctual[0].intensity, 2.0);
    assert_eq!(punctual[1].kind, PunctualKind::Point);
    assert_eq!(
        (punctual[1].position, punctual[1].range),
        ([0.0, 10.0, 0.0], Some(40.0))
    );

    // More lights than are drawn: the brightest at the centre, with a note. Ten bulbs along
    // +y at heights 10, 20, …, 100 and the sun: the sun (2 lx) outshines every bulb above
    // 50 (5000 cd / r² < 2 lx); the bulbs at 10–70 (≥ 1.0 lx) are kept, 80–100 are not.
    let lights: Vec<_> = (0..10)
        .map(|_| serde_json::json!({ "type": "point", "intensity": 5000.0 }))
        .chain([serde_json::json!({ "type": "directional", "intensity": 2.0 })])
        .collect();
    let mut many = doc.clone();
    many["extensions"]["KHR_lights_punctual"]["lights"] = lights.into();
    let nodes = many["nodes"].as_array_mut().unwrap();
    let first_light = nodes.len();
    for k in 0..11 {
        nodes.push(serde_json::json!({
            "translation": [0.0, 10.0 * (k + 1) as f64, 0.0],
            "extensions": { "KHR_lights_punctual": { "light": k } }
        }));
    }
    for k in first_light..first_light + 11 {
        many["scenes"][0]["nodes"]
            .as_array_mut()
            .unwrap()
            .push(k.into());
    }
    let bytes = nacre_runtime::gltf_scene::assets::glb(&many, &bin);
    let crowded = GltfScene::from_bytes(&bytes, &dir.path().join("many.glb")).unwrap();
    assert_eq!(crowded.lights.len(), 13);
    let (_, punctual, note) = scene_lights(&crowded);
    assert_eq!(punctual.len(), MAX_PUNCTUAL_LIGHTS);
    let note = note.expect("13 lights, 8 drawn");
    assert!(
        note.contains("13 lights") && note.contains("8 brightest"),
        "{note}"
    );
    let heights: Vec<f32> = punctual
        .iter()
        .filter(|l| l.kind == PunctualKind::Point)
        .map(|l| l.position[1])
        .collect();
    assert!(heights.iter().all(|&h| h <= 50.0), "{heights:?}");

    // A range that is not a positive number is refused, naming the light.
    let mut bad = doc.clone();
    bad["extensions"]["KHR_lights_punctual"]["lights"][1]["range"] = (-1.0).into();
    let bytes = nacre_runtime::gltf_scene::assets::glb(&bad, &bin);
    let e = GltfScene::from_bytes(&bytes, &dir.path().join("range.glb")).unwrap_err();
    assert!(
        e.to_string().contains("bulb") && e.to_string().contains("range"),
        "{e}"
    );
    // A dangling light index is an error, not a panic.
    doc["nodes"][first + 3]["extensions"]["KHR_lights_punctual"]["light"] = 7.into();
    let bytes = nacre_runtime::gltf_scene::assets::glb(&doc, &bin);
    assert!(GltfScene::from_bytes(&bytes, &dir.path().join("dangling.glb")).is_err());
}

/// Every punctual light lights the scene, with the specification's falloff: a point light in
/// front of the leftmost sphere lights it and barely the rightmost, one in front of the
/// rightmost the reverse, both together both; a spot aimed away, or a range that ends before
/// the spheres, gives nothing; the same spot aimed at the sphere lights it.
#[test]
fn every_punctual_light_is_drawn() {
    use nacre_runtime::gltf_scene::{GltfLight, LightKind};
    let plain = GltfScene::load(&asset_dir().join(SWEEPS[0].file)).unwrap();
    let point = |k: f32| GltfLight {
        name: format!("bulb {k}"),
        kind: LightKind::Point,
        position: [(k - 2.0) * SPHERE_SPACING, 0.6, 2.0],
        direction: [0.0, 0.0, -1.0],
        colour: [1.0, 1.0, 1.0],
        intensity: 6.0,
        range: None,
    };
    let render = |lights: Vec<GltfLight>| {
        let mut o = options();
        o.env_intensity = 0.0;
        let mut scene = plain.clone();
        scene.lights = lights;
        let out = render_gltf(
            ctx(),
            &film_tables("film-dielectric"),
            Technique::Fourier,
            &scene,
            &o,
        )
        .unwrap();
        let grey = |k| sphere_colour(&scene, &out.image, k).iter().sum::<f64>() / 3.0;
        (grey(0), grey(4))
    };
    let dark = render(Vec::new());
    assert!(dark.0 < 2.0 && dark.1 < 2.0, "no light: {dark:?}");
    let left = render(vec![point(0.0)]);
    let right = render(vec![point(4.0)]);
    let both = render(vec![point(0.0), point(4.0)]);
    eprintln!("left {left:?}, right {right:?}, both {both:?}");
    assert!(
        left.0 > 40.0 && left.0 > 3.0 * left.1,
        "left light: {left:?}"
    );
    assert!(
        right.1 > 40.0 && right.1 > 3.0 * right.0,
        "right light: {right:?}"
    );
    assert!(
        both.0 > left.0 - 1.0 && both.1 > right.1 - 1.0 && both.0 > 40.0 && both.1 > 40.0,
        "both: {both:?} (left {left:?}, right {right:?})"
    );
    // A spot pointing away from the spheres, and a point light whose range ends before them.
    let away = GltfLight {
        kind: LightKind::Spot {
            inner_cone_rad: 0.2,
            outer_cone_rad: 0.4,
        },
        direction: [0.0, 0.0, 1.0],
        ..point(0.0)
    };
    let short = GltfLight {
        range: Some(0.5),
        ..point(0.0)
    };
    for (name, light) in [("spot aimed away", away.clone()), ("short range", short)] {
        let lit = render(vec![light]);
        assert!(lit.0 < 2.0 && lit.1 < 2.0, "{name}: {lit:?}");
    }
    let norm = (0.09f32 + 1.0).sqrt();
    let toward = GltfLight {
        direction: [0.0, -0.3 / norm, -1.0 / norm],
        ..away
    };
    let lit = render(vec![toward]);
    assert!(lit.0 > 40.0, "spot aimed at the sphere: {lit:?}");
}

/// Little-endian bytes of `values`, each written by `le`.
fn bytes_of<T: Copy, const N: usize>(values: &[T], le: impl Fn(T) -> [u8; N]) -> Vec<u8> {
    values.iter().flat_map(|&v| le(v)).collect()
}

/// A GLB of one mesh with two primitives made of sparse accessors (glTF 2.0 §3.6.2.3):
/// primitive 0, a quad whose POSITION accessor (4 vertices in a buffer view) has vertex 2
/// replaced by (2, 2, 0); primitive 1, a triangle whose POSITION accessor has no buffer view
/// (zeros) and vertices 1 and 2 replaced by (1, 0, 0) and (0, 1, 0). `sparse_u8` is the
/// quad's sparse index, `sparse_u16` the triangle's two.
fn sparse_glb(sparse_u8: u8, sparse_u16: [u16; 2], quad_sparse_count: u32) -> Vec<u8> {
    let mut bin = bytes_of(
        &[
            0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0,
        ],
        f32::to_le_bytes,
    ); // 0..48
    bin.extend(bytes_of(&[0u16, 1, 2, 0, 2, 3], u16::to_le_bytes)); // 48..60
    bin.extend([sparse_u8, 0, 0, 0]); // 60..61 (padded to 64)
    bin.extend(bytes_of(&[2.0f32, 2.0, 0.0], f32::to_le_bytes)); // 64..76
    bin.extend(bytes_of(&sparse_u16, u16::to_le_bytes)); // 76..80
    bin.extend(bytes_of(
        &[1.0f32, 0.0, 0.0, 0.0, 1.0, 0.0],
        f32::to_le_bytes,
    )); // 80..104
    let doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": 0}, "indices": 1},
            {"attributes": {"POSITION": 2}}
        ]}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 12},
            {"buffer": 0, "byteOffset": 60, "byteLength": 1},
            {"buffer": 0, "byteOffset": 64, "byteLength": 12},
            {"buffer": 0, "byteOffset": 76, "byteLength": 4},
            {"buffer": 0, "byteOffset": 80, "byteLength": 24}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [2.0, 2.0, 0.0],
             "sparse": {"count": quad_sparse_count,
                        "indices": {"bufferView": 2, "componentType": 5121},
                        "values": {"bufferView": 3}}},
            {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
            {"componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0],
             "sparse": {"count": 2,
                        "indices": {"bufferView": 4, "componentType": 5123},
                        "values": {"bufferView": 5}}}
        ]
    });
    nacre_runtime::gltf_scene::assets::glb(&doc, &bin)
}

#[test]
fn sparse_accessors_replace_elements_of_the_view_or_of_zeros() {
    let path = Path::new("sparse.glb");
    let scene = GltfScene::from_bytes(&sparse_glb(2, [1, 2], 1), path).unwrap();
    assert_eq!(scene.primitives.len(), 2);
    // No normals: flat shading unwelds the triangles, so positions follow the indices.
    let quad = &scene.primitives[0].positions;
    let quad_vertices = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 2.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let expected: Vec<[f32; 3]> = [0, 1, 2, 0, 2, 3].map(|i| quad_vertices[i]).to_vec();
    assert_eq!(quad, &expected);
    let triangle = &scene.primitives[1].positions;
    assert_eq!(
        triangle,
        &vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    );
    assert_eq!(scene.primitives[1].normals[0], [0.0, 0.0, 1.0]);

    let err = |bytes: Vec<u8>| match GltfScene::from_bytes(&bytes, path) {
        Err(nacre_runtime::Error::Gltf { error, .. }) => error,
        other => panic!("expected a glTF error, got {other:?}"),
    };
    assert_eq!(
        err(sparse_glb(9, [1, 2], 1)),
        GltfError::SparseIndexOutOfRange {
            accessor: 0,
            position: 0,
            index: 9,
            count: 4
        }
    );
    assert_eq!(
        err(sparse_glb(2, [2, 1], 1)),
        GltfError::SparseIndicesNotIncreasing {
            accessor: 2,
            position: 1,
            previous: 2,
            index: 1
        }
    );
    assert_eq!(
        err(sparse_glb(2, [1, 1], 1)),
        GltfError::SparseIndicesNotIncreasing {
            accessor: 2,
            position: 1,
            previous: 1,
            index: 1
        }
    );
    // Five sparse entries need 5 index bytes of a 1-byte view.
    assert_eq!(
        err(sparse_glb(2, [1, 2], 5)),
        GltfError::SparseBeyondView {
            accessor: 0,
            part: "indices".to_string(),
            needed: 5,
            view_bytes: 1
        }
    );
}

/// A GLB of one triangle with `KHR_mesh_quantization` attributes (declared when `declared`):
/// POSITION as normalised SHORT (0, 0, 0), (1, 0, 0), (0, 1, 0) (stride 8), NORMAL as
/// normalised BYTE (0, 0, 1) (stride 4), TEXCOORD_0 as unnormalised UNSIGNED_BYTE (0, 0),
/// (3, 0), (0, 5) (stride 4), under a node scaling by 2 and translating by (0, 0, 1).
fn quantized_glb(declared: bool) -> Vec<u8> {
    let mut bin = Vec::new();
    for p in [[0i16, 0, 0], [32767, 0, 0], [0, 32767, 0]] {
        bin.extend(bytes_of(&p, i16::to_le_bytes));
        bin.extend([0, 0]);
    } // 0..24
    for _ in 0..3 {
        bin.extend([0u8, 0, 127, 0]);
    } // 24..36
    for uv in [[0u8, 0], [3, 0], [0, 5]] {
        bin.extend([uv[0], uv[1], 0, 0]);
    } // 36..48
    let mut doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "scale": [2.0, 2.0, 2.0], "translation": [0.0, 0.0, 1.0]}],
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}}
        ]}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 24, "byteStride": 8},
            {"buffer": 0, "byteOffset": 24, "byteLength": 12, "byteStride": 4},
            {"buffer": 0, "byteOffset": 36, "byteLength": 12, "byteStride": 4}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5122, "normalized": true, "count": 3,
             "type": "VEC3", "min": [0, 0, 0], "max": [32767, 32767, 0]},
            {"bufferView": 1, "componentType": 5120, "normalized": true, "count": 3,
             "type": "VEC3"},
            {"bufferView": 2, "componentType": 5121, "count": 3, "type": "VEC2"}
        ]
    });
    if declared {
        doc["extensionsUsed"] = serde_json::json!(["KHR_mesh_quantization"]);
        doc["extensionsRequired"] = serde_json::json!(["KHR_mesh_quantization"]);
    }
    nacre_runtime::gltf_scene::assets::glb(&doc, &bin)
}

#[test]
fn quantized_attributes_are_dequantised_under_the_node_transform() {
    let path = Path::new("quantized.glb");
    let scene = GltfScene::from_bytes(&quantized_glb(true), path).unwrap();
    let p = &scene.primitives[0];
    assert_eq!(
        p.positions,
        vec![[0.0, 0.0, 1.0], [2.0, 0.0, 1.0], [0.0, 2.0, 1.0]]
    );
    assert_eq!(p.normals, vec![[0.0, 0.0, 1.0]; 3]);
    assert_eq!(p.uvs, vec![[0.0, 0.0], [3.0, 0.0], [0.0, 5.0]]);
    assert_eq!(p.indices, vec![0, 1, 2]);
    // Without the extension declared, integer positions are not glTF.
    match GltfScene::from_bytes(&quantized_glb(false), path) {
        Err(nacre_runtime::Error::Gltf {
            error:
                GltfError::AccessorType {
                    semantic,
                    accessor: 0,
                    found,
                    ..
                },
            ..
        }) => assert_eq!(
            (semantic.as_str(), found.as_str()),
            ("POSITION", "I16 normalized Vec3")
        ),
        other => panic!("expected an AccessorType error, got {other:?}"),
    }
}

#[test]
fn unlit_materials_show_their_base_colour() {
    // The sparse quad and triangle (`sparse_glb`) with one KHR_materials_unlit material.
    let good = sparse_glb(2, [1, 2], 1);
    let json_len = u32::from_le_bytes(good[12..16].try_into().unwrap()) as usize;
    let mut doc: serde_json::Value = serde_json::from_slice(&good[20..20 + json_len]).unwrap();
    let base = [0.2f32, 0.5, 0.8];
    doc["materials"] = serde_json::json!([{
        "pbrMetallicRoughness": {"baseColorFactor": [base[0], base[1], base[2], 1.0],
                                 "metallicFactor": 0.0},
        "extensions": {"KHR_materials_unlit": {}}
    }]);
    doc["extensionsUsed"] = serde_json::json!(["KHR_materials_unlit"]);
    doc["extensionsRequired"] = serde_json::json!(["KHR_materials_unlit"]);
    doc["meshes"][0]["primitives"][0]["material"] = 0.into();
    doc["meshes"][0]["primitives"][1]["material"] = 0.into();
    let bytes = nacre_runtime::gltf_scene::assets::glb(&doc, &good[20 + json_len + 8..]);
    let scene = GltfScene::from_bytes(&bytes, Path::new("unlit.glb")).unwrap();
    assert!(scene.materials[0].unlit);
    let out = render_gltf(
        ctx(),
        &film_tables("film-dielectric"),
        Technique::Lut,
        &scene,
        &options(),
    )
    .unwrap();
    let image = &out.image;
    let background = pixel(image, (0, 0));
    let expected = srgb_255(base);
    let mut covered = 0;
    for y in 0..image.height {
        for x in 0..image.width {
            let p = pixel(image, (x, y));
            if distance(p, background) > 0.0 {
                covered += 1;
                // Edge pixels mix with the background; inside, the colour is the base's.
                if distance(p, expected) > 1.5 {
                    let neighbours_covered =
                        [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)]
                            .iter()
                            .all(|&(dx, dy)| {
                                let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                                nx >= 0
                                    && ny >= 0
                                    && (nx as u32) < image.width
                                    && (ny as u32) < image.height
                                    && distance(pixel(image, (nx as u32, ny as u32)), background)
                                        > 0.0
                            });
                    assert!(
                        !neighbours_covered,
                        "({x}, {y}): {p:?}, expected {expected:?}"
                    );
                }
            }
        }
    }
    assert!(covered > 100, "{covered} pixels covered");
}

/// The sweep spheres (`sweep_glb`) with five materials of `KHR_materials_clearcoat`, each
/// `base` (a JSON material without the extension) with the extension's object `coats[k]`
/// (None: no extension). Texture 0 is a 2 × 2 PNG of (128, 64, 0) (clearcoat 0.502,
/// clearcoat roughness 0.251).
fn clearcoat_glb(materials: [(serde_json::Value, Option<serde_json::Value>); 5]) -> Vec<u8> {
    let sphere = sweep_glb(&SWEEPS[2]);
    let json_len = u32::from_le_bytes(sphere[12..16].try_into().unwrap()) as usize;
    let mut doc: serde_json::Value = serde_json::from_slice(&sphere[20..20 + json_len]).unwrap();
    let mut bin = sphere[20 + json_len + 8..].to_vec();
    let mut png = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut png),
        &[128, 64, 0].repeat(4),
        2,
        2,
        image::ExtendedColorType::Rgb8,
    )
    .unwrap();
    let offset = bin.len();
    bin.extend_from_slice(&png);
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    doc["buffers"][0]["byteLength"] = bin.len().into();
    doc["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({ "buffer": 0, "byteOffset": offset, "byteLength": png.len() }));
    doc["images"] = serde_json::json!([{ "bufferView": 2, "mimeType": "image/png" }]);
    doc["samplers"] = serde_json::json!([{ "magFilter": 9729, "minFilter": 9729 }]);
    doc["textures"] = serde_json::json!([{ "sampler": 0, "source": 0 }]);
    doc["extensionsUsed"] =
        serde_json::json!(["KHR_materials_iridescence", "KHR_materials_clearcoat"]);
    doc["materials"] = materials
        .into_iter()
        .map(|(mut m, coat)| {
            if let Some(coat) = coat {
                m["extensions"]["KHR_materials_clearcoat"] = coat;
            }
            m
        })
        .collect();
    nacre_runtime::gltf_scene::assets::glb(&doc, &bin)
}

/// The linear radiance of a pixel of the material scenes' display colour, in the range where
/// the display is invertible: sRGB decoded (IEC 61966-2-1), then Khronos PBR Neutral's
/// black offset 0.04 added back (identity above it while the largest channel stays under
/// 0.76; `shaders/output.wgsl`).
fn display_to_radiance(rgb: [f64; 3]) -> [f64; 3] {
    rgb.map(|c| {
        let e = c / 255.0;
        let linear = if e <= 0.04045 {
            e / 12.92
        } else {
            ((e + 0.055) / 1.055).powf(2.4)
        };
        assert!(
            (0.04..0.72).contains(&linear),
            "{rgb:?}: outside the invertible range"
        );
        linear + 0.04
    })
}

/// `KHR_materials_clearcoat` in a uniform environment of radiance L (no lights): on every
/// sphere the coat turns the uncoated radiance L_base into L_base (1 − c F_c) + c L_coat,
/// F_c = 0.04 + 0.96 (1 − μ)⁵ and L_coat = L F_c (1 − 0.55 √α_c) on the classic path,
/// L (0.04 E₁ + 0.96 E₅)(μ, α_c) on the split-sum paths (the extension's layering; the
/// prefiltered environment of a constant is the constant). Checked at the front of each
/// sphere against the same render without the coat, on black and grey bases, a smooth and a
/// rough coat, a film under the coat, and factors from a texture; clearcoatFactor 0 gives the
/// bytes of no extension at all.
#[test]
fn clearcoat_layers_over_the_base_as_the_extension_says() {
    use nacre_runtime::environment::EnvironmentMap;
    use serde_json::json;
    let radiance_l = 3.0f64;
    let env_path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("uniform-environment.exr");
    EnvironmentMap {
        width: 16,
        height: 8,
        rgb: vec![[1.0; 3]; 16 * 8],
    }
    .write_exr(&env_path)
    .unwrap();
    let dielectric = |grey: f32| {
        json!({ "pbrMetallicRoughness": { "baseColorFactor": [grey, grey, grey, 1.0],
                "metallicFactor": 0.0, "roughnessFactor": 0.5 } })
    };
    let mut film = dielectric(0.05);
    film["extensions"]["KHR_materials_iridescence"] = json!({ "iridescenceFactor": 1.0, "iridescenceIor": 1.6, "iridescenceThicknessMaximum": 380.0 });
    let smooth = json!({ "clearcoatFactor": 1.0 });
    let bases = [
        dielectric(0.0),
        dielectric(0.1),
        dielectric(0.0),
        film,
        dielectric(0.0),
    ];
    let coats = [
        Some(smooth.clone()),
        Some(smooth.clone()),
        Some(json!({ "clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.5 })),
        Some(smooth),
        Some(
            json!({ "clearcoatFactor": 1.0, "clearcoatTexture": { "index": 0 },
                     "clearcoatRoughnessFactor": 1.0, "clearcoatRoughnessTexture": { "index": 0 } }),
        ),
    ];
    // Per sphere: the coat c and its roughness r_c (the texture's 128/255 and 64/255).
    let coat_of: [(f64, f64); 5] = [
        (1.0, 0.0),
        (1.0, 0.0),
        (1.0, 0.5),
        (1.0, 0.0),
        (128.0 / 255.0, 64.0 / 255.0),
    ];
    let load = |coats: [Option<serde_json::Value>; 5]| {
        let bytes = clearcoat_glb(std::array::from_fn(|k| {
            (bases[k].clone(), coats[k].clone())
        }));
        GltfScene::from_bytes(&bytes, Path::new("clearcoat.glb")).unwrap()
    };
    let bare = load(Default::default());
    let zero = load(std::array::from_fn(|_| {
        Some(json!({ "clearcoatFactor": 0.0 }))
    }));
    let coated = load(coats);
    assert_eq!(coated.materials[1].clearcoat.unwrap().factor, 1.0);
    let slots = nacre_runtime::mesh::coat_slots(&coated.materials[4]);
    assert_eq!(
        (slots.slot[0], slots.slot[1], slots.slot[2]),
        (7, 7, nacre_runtime::mesh::COAT_SLOT_NONE),
        "both coat textures share the last free slot"
    );
    let (lo, hi) = bare.bounds();
    let eye = fit_camera(lo, hi, f64::from(SIZE.0) / f64::from(SIZE.1))
        .unwrap()
        .eye;
    for eval in [FilmEval::Classic, FilmEval::NormalView] {
        let mut o = options();
        o.environment = Some(env_path.clone());
        o.env_intensity = radiance_l as f32;
        o.film_eval = eval;
        let render = |scene: &GltfScene| {
            render_gltf(
                ctx(),
                &film_tables("film-dielectric"),
                Technique::Fourier,
                scene,
                &o,
            )
            .unwrap()
            .image
        };
        let bare_image = render(&bare);
        assert!(
            render(&zero).pixels == bare_image.pixels,
            "{eval:?}: clearcoatFactor 0 changes the picture"
        );
        let coated_image = render(&coated);
        if std::env::var_os("NACRE_CLEARCOAT_PNG").is_some() {
            let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
            for (name, image) in [("bare", &bare_image), ("coated", &coated_image)] {
                image::save_buffer(
                    dir.join(format!("clearcoat-{name}-{eval:?}.png")),
                    &image.pixels,
                    image.width,
                    image.height,
                    image::ExtendedColorType::Rgba8,
                )
                .unwrap();
            }
        }
        for (k, &(c, r_c)) in coat_of.iter().enumerate() {
            // μ = n·v at the probe point (sphere_colour's: the unit sphere's normal there).
            let p = [(k as f64 - 2.0) * f64::from(SPHERE_SPACING), 0.35, 0.9];
            let n = {
                let q = [0.0, 0.35, 0.9f64];
                let l = (q[1] * q[1] + q[2] * q[2]).sqrt();
                [0.0, q[1] / l, q[2] / l]
            };
            let v = {
                let d = [0, 1, 2].map(|i| f64::from(eye[i]) - p[i]);
                let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                d.map(|x| x / l)
            };
            let mu = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
            let fresnel = 0.04 + 0.96 * (1.0 - mu).powi(5);
            let alpha_c = (r_c * r_c).max(1e-3);
            let coat_albedo = if eval == FilmEval::Classic {
                fresnel * (1.0 - 0.55 * alpha_c.sqrt())
            } else {
                let [e1, e5] = nacre_runtime::ibl::ggx_albedo_terms(mu, alpha_c);
                0.04 * e1 + 0.96 * e5
            };
            let base = display_to_radiance(sphere_colour(&bare, &bare_image, k));
            let got = display_to_radiance(sphere_colour(&coated, &coated_image, k));
            let expected = base.map(|b| b * (1.0 - c * fresnel) + c * radiance_l * coat_albedo);
            eprintln!(
                "{eval:?} sphere {k}: μ {mu:.3}, base {base:.3?}, coated {got:.3?}, expected {expected:.3?}"
            );
            for ch in 0..3 {
                assert!(
                    (got[ch] - expected[ch]).abs() <= 0.03 * expected[ch] + 0.004,
                    "{eval:?} sphere {k} channel {ch}: {got:?}, expected {expected:?} (base {base:?})"
                );
                // The coat adds white: more than the base attenuated alone.
                assert!(
                    got[ch] > base[ch] * (1.0 - c * fresnel) + 0.5 * c * radiance_l * coat_albedo
                );
            }
        }
    }
}

/// A GLB of eight one-primitive meshes without normals, each a unit square's outline
/// v0 = (0, 0), v1 = (1, 0), v2 = (1, 1), v3 = (0, 1) drawn with mode 0–3 (POINTS, LINES,
/// LINE_LOOP, LINE_STRIP; column `mode`, placed at x = 2 mode), not indexed (row 0: the
/// vertices in order) or indexed (row 1, at y = 2: the vertices stored v2, v0, v3, v1 and
/// indices 1, 3, 0, 2 naming them in order), each with its own material of base colour
/// `LINE_COLOURS[2 mode + row]`.
fn lines_glb() -> Vec<u8> {
    let square = [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let mut bin = bytes_of(square.as_flattened(), f32::to_le_bytes); // 0..48
    let stored = [square[2], square[0], square[3], square[1]];
    bin.extend(bytes_of(stored.as_flattened(), f32::to_le_bytes)); // 48..96
    bin.extend(bytes_of(&[1u16, 3, 0, 2], u16::to_le_bytes)); // 96..104
    let (mut meshes, mut nodes, mut materials) = (vec![], vec![], vec![]);
    for mode in 0..4u32 {
        for row in 0..2u32 {
            let k = (2 * mode + row) as usize;
            let [r, g, b] = LINE_COLOURS[k];
            materials.push(serde_json::json!({
                "pbrMetallicRoughness": {"baseColorFactor": [r, g, b, 1.0], "metallicFactor": 0.0}
            }));
            let mut primitive = serde_json::json!({
                "attributes": {"POSITION": row}, "mode": mode, "material": k
            });
            if row == 1 {
                primitive["indices"] = 2.into();
            }
            meshes.push(serde_json::json!({"primitives": [primitive]}));
            nodes.push(serde_json::json!({
                "mesh": k, "translation": [2.0 * mode as f32, 2.0 * row as f32, 0.0]
            }));
        }
    }
    let position = |view: u32| {
        serde_json::json!({"bufferView": view, "componentType": 5126, "count": 4,
                           "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]})
    };
    let doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": (0..8).collect::<Vec<u32>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 48},
            {"buffer": 0, "byteOffset": 96, "byteLength": 8}
        ],
        "accessors": [
            position(0),
            position(1),
            {"bufferView": 2, "componentType": 5123, "count": 4, "type": "SCALAR"}
        ]
    });
    nacre_runtime::gltf_scene::assets::glb(&doc, &bin)
}

/// The base colours of [`lines_glb`]'s eight primitives (linear RGB).
const LINE_COLOURS: [[f32; 3]; 8] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 0.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [1.0, 0.5, 0.0],
    [0.5, 0.0, 1.0],
];

/// sRGB encoding (IEC 61966-2-1) of a linear colour, 0–255.
fn srgb_255(rgb: [f32; 3]) -> [f64; 3] {
    rgb.map(|c| {
        let c = f64::from(c);
        255.0
            * if c <= 0.003_130_8 {
                12.92 * c
            } else {
                1.055 * c.powf(1.0 / 2.4) - 0.055
            }
    })
}

/// POINTS, LINES, LINE_LOOP and LINE_STRIP (glTF 2.0 §3.7.2.1), indexed or not, are drawn:
/// without normals, unlit in their base colour, one pixel wide, where their vertices and
/// segments lie — a loop closes back to its first vertex, a strip does not, a line list
/// joins pairs only, points draw no segment.
#[test]
fn points_and_lines_are_drawn_where_they_lie() {
    let scene = GltfScene::from_bytes(&lines_glb(), Path::new("lines.glb")).unwrap();
    assert!(scene.notes.is_empty(), "{:?}", scene.notes);
    assert_eq!(scene.primitives.len(), 8);
    let size = (240, 120);
    let mut o = options();
    (o.width, o.height) = size;
    let out = render_gltf(
        ctx(),
        &film_tables("film-dielectric"),
        Technique::Lut,
        &scene,
        &o,
    )
    .unwrap();
    let image = &out.image;
    // Whether a pixel of `colour` (within 1.5 of 255) lies within 2 pixels of world point p.
    let shows = |p: [f32; 3], colour: [f64; 3]| {
        let (x, y) = project_in(&scene, p, size);
        (y.saturating_sub(2)..=(y + 2).min(size.1 - 1)).any(|y| {
            (x.saturating_sub(2)..=(x + 2).min(size.0 - 1))
                .any(|x| distance(pixel(image, (x, y)), colour) <= 1.5)
        })
    };
    // Per mode: which of the edges v0v1, v1v2, v2v3, v3v0 are drawn.
    let edges_drawn = [
        [false; 4],                 // POINTS
        [true, false, true, false], // LINES: (v0, v1), (v2, v3)
        [true; 4],                  // LINE_LOOP
        [true, true, true, false],  // LINE_STRIP
    ];
    let corners = [[0.0f32, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let mut failures = Vec::new();
    for (mode, drawn) in edges_drawn.iter().enumerate() {
        for row in 0..2 {
            let colour = srgb_255(LINE_COLOURS[2 * mode + row]);
            let at = |[u, v]: [f32; 2]| [2.0 * mode as f32 + u, 2.0 * row as f32 + v, 0.0];
            if mode == 0 {
                for (c, corner) in corners.iter().enumerate() {
                    if !shows(at(*corner), colour) {
                        failures.push(format!("POINTS row {row}: vertex {c} not drawn"));
                    }
                }
            }
            for (e, &expected) in drawn.iter().enumerate() {
                let (a, b) = (corners[e], corners[(e + 1) % 4]);
                let mid = at([0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]);
                if shows(mid, colour) != expected {
                    failures.push(format!(
                        "mode {mode} row {row}: edge v{e}v{} {}",
                        (e + 1) % 4,
                        if expected { "not drawn" } else { "drawn" }
                    ));
                }
            }
        }
    }
    if !failures.is_empty() {
        let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("points-and-lines.png");
        image.write_png(&path).unwrap();
        panic!("{failures:?}; image {}", path.display());
    }
}

/// The sweep spheres (`sweep_glb`) with five glTF glass materials, `materials[k]` the JSON of
/// sphere k.
fn glass_glb(materials: [serde_json::Value; 5]) -> Vec<u8> {
    let sphere = sweep_glb(&SWEEPS[2]);
    let json_len = u32::from_le_bytes(sphere[12..16].try_into().unwrap()) as usize;
    let mut doc: serde_json::Value = serde_json::from_slice(&sphere[20..20 + json_len]).unwrap();
    let bin = sphere[20 + json_len + 8..].to_vec();
    doc["extensionsUsed"] = serde_json::json!([
        "KHR_materials_iridescence",
        "KHR_materials_transmission",
        "KHR_materials_volume",
        "KHR_materials_ior"
    ]);
    doc["materials"] = materials.into_iter().collect();
    nacre_runtime::gltf_scene::assets::glb(&doc, &bin)
}

/// A 16 × 8 equirectangular environment of radiance 1 towards +z (u < 1/4 or u > 3/4:
/// `env_direction_to_uv`, u = 0.5 + atan2(x, −z)/2π) and 0 towards −z, or the reverse.
fn half_environment(name: &str, towards_plus_z: bool) -> PathBuf {
    use nacre_runtime::environment::EnvironmentMap;
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let rgb = (0..16 * 8)
        .map(|i| {
            let u = ((i % 16) as f64 + 0.5) / 16.0;
            let plus_z = !(0.25..0.75).contains(&u);
            [if plus_z == towards_plus_z { 1.0 } else { 0.0 }; 3]
        })
        .collect();
    EnvironmentMap {
        width: 16,
        height: 8,
        rgb,
    }
    .write_exr(&path)
    .unwrap();
    path
}

/// glTF glass drawn by the technique `glass` (`nacre_runtime::mesh::glass_setup`: air | the
/// iridescence film | a clear incoherent slab of `ior` | air) against its CPU twin, the
/// coated pane's R and T by `StackEvaluation`: five smooth transmissive spheres — films of
/// 1.8 and 1.38 over panes of 1.5 and 1.7, thin-walled and 2 mm of volume, an uncoated pane,
/// and a film weight of 0.5 (half the film, half the uncoated pane) — rendered in an
/// environment lit only towards the camera (the pixel is L R E, E = 1 − 0.55 √α the classic
/// path's lobe scale; L = 2) and only away from it (the pixel is L T, the light behind the
/// pane; L = 0.6). At
/// the front of each sphere, R and T from the display bytes agree with the CPU's within 0.006
/// (the 8-bit display's step there is about 0.002); the pane's back face, which a single
/// interface lacks, is 0.035 to 0.07 of R.
#[test]
fn glass_materials_match_the_cpu_coated_pane() {
    use nacre_optics::few_wavelengths::StackEvaluation;
    use serde_json::json;
    let size = (400u32, 112u32);
    let glass = |ior: f64, film: Option<(f64, f64, f64)>, thickness: f64| {
        let mut m = json!({
            "pbrMetallicRoughness": { "baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                "metallicFactor": 0.0, "roughnessFactor": 0.0 },
            "extensions": {
                "KHR_materials_transmission": { "transmissionFactor": 1.0 },
                "KHR_materials_ior": { "ior": ior }
            }
        });
        if let Some((factor, film_ior, d_nm)) = film {
            m["extensions"]["KHR_materials_iridescence"] = json!({ "iridescenceFactor": factor,
                "iridescenceIor": film_ior, "iridescenceThicknessMaximum": d_nm });
        }
        if thickness > 0.0 {
            m["extensions"]["KHR_materials_volume"] = json!({ "thicknessFactor": thickness });
        }
        m
    };
    let bytes = glass_glb([
        glass(1.5, Some((1.0, 1.8, 300.0)), 0.0),
        glass(1.5, Some((1.0, 1.8, 300.0)), 0.002),
        glass(1.7, Some((1.0, 1.38, 450.0)), 0.0),
        glass(1.5, None, 0.0),
        glass(1.5, Some((0.5, 2.0, 250.0)), 0.0),
    ]);
    let scene = GltfScene::from_bytes(&bytes, Path::new("glass.glb")).unwrap();
    let tables = film_tables("film-dielectric");
    let colorimeter = tables.colorimeter().unwrap();
    let (lo, hi) = scene.bounds();
    let eye = fit_camera(lo, hi, f64::from(size.0) / f64::from(size.1))
        .unwrap()
        .eye;
    // The environment's radiance: the reflection's and the transmission's, each in the
    // display's invertible range.
    let (radiance_r, radiance_t) = (2.0f64, 0.6f64);
    let render = |towards_camera: bool, radiance_l: f64| {
        let mut o = options();
        (o.width, o.height) = size;
        o.environment = Some(half_environment(
            &format!("glass-environment-{towards_camera}.exr"),
            towards_camera,
        ));
        o.env_intensity = radiance_l as f32;
        o.film_eval = FilmEval::Classic;
        let r = render_gltf(ctx(), &tables, Technique::Glass, &scene, &o).unwrap();
        assert!(
            r.notes
                .iter()
                .all(|n| !n.to_string().contains("instead of")),
            "a glass material fell back: {:?}",
            r.notes.iter().map(|n| n.to_string()).collect::<Vec<_>>()
        );
        r.image
    };
    let reflected = render(true, radiance_r);
    let transmitted = render(false, radiance_t);
    // The lobe scale of the classic path at α = 10⁻³ (material.wgsl MATERIAL_ALPHA_MIN).
    let lobe_scale = 1.0 - 0.55 * 1e-3f64.sqrt();
    for k in 0..5 {
        let p = [(k as f64 - 2.0) * f64::from(SPHERE_SPACING), 0.35, 0.9];
        let (x, y) = project_in(&scene, p.map(|c| c as f32), size);
        let mean = |image: &RenderedImage, radiance_l: f64| {
            let mut sum = [0.0; 3];
            for dy in 0..3 {
                for dx in 0..3 {
                    let q = pixel(image, (x + dx - 1, y + dy - 1));
                    for c in 0..3 {
                        sum[c] += q[c] / 9.0;
                    }
                }
            }
            display_to_radiance(sum).map(|c| c / radiance_l)
        };
        let got_r = mean(&reflected, radiance_r).map(|c| c / lobe_scale);
        let got_t = mean(&transmitted, radiance_t);
        // μ = n·v at the probe point (the unit sphere's normal there).
        let n = {
            let l = (0.35f64 * 0.35 + 0.9 * 0.9).sqrt();
            [0.0, 0.35 / l, 0.9 / l]
        };
        let v = {
            let d = [0, 1, 2].map(|i| f64::from(eye[i]) - p[i]);
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            d.map(|x| x / l)
        };
        let mu = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
        let gm = &scene.materials[k];
        let setup = nacre_runtime::mesh::glass_setup(&scene, k).unwrap();
        let eval =
            StackEvaluation::new(&colorimeter, &setup.stack, &setup.relative_nm, None).unwrap();
        let d_nm = gm
            .iridescence
            .map_or(0.0, |i| f64::from(i.thickness_max_nm));
        let (film_r, film_t) = eval.colour(mu, d_nm, [1.0; 3]);
        let (pane_r, pane_t) = eval.colour(mu, 0.0, [1.0; 3]);
        let w = gm.iridescence.map_or(0.0, |i| f64::from(i.factor));
        let expected_r: [f64; 3] = std::array::from_fn(|c| w * film_r[c] + (1.0 - w) * pane_r[c]);
        let expected_t: [f64; 3] = std::array::from_fn(|c| w * film_t[c] + (1.0 - w) * pane_t[c]);
        // One interface of the same film over the pane's glass (no back face), for scale.
        let front = {
            let s = &setup.stack;
            let s = nacre_optics::Stack::new(
                s.ambient().clone(),
                vec![s.layers()[0].clone()],
                s.layers()[1].material.clone(),
            )
            .unwrap();
            StackEvaluation::new(&colorimeter, &s, &[0.0], None)
                .unwrap()
                .colour(mu, if w > 0.0 { d_nm } else { 0.0 }, [1.0; 3])
                .0
        };
        eprintln!(
            "glass sphere {k}: μ {mu:.3}, R {got_r:.4?} (CPU {expected_r:.4?}, one interface {front:.4?}), T {got_t:.4?} (CPU {expected_t:.4?})"
        );
        for c in 0..3 {
            assert!(
                (got_r[c] - expected_r[c]).abs() <= 0.006,
                "sphere {k} R channel {c}: GPU {got_r:?}, CPU {expected_r:?}"
            );
            assert!(
                (got_t[c] - expected_t[c]).abs() <= 0.006,
                "sphere {k} T channel {c}: GPU {got_t:?}, CPU {expected_t:?}"
            );
        }
    }
}

/// Metallic 0 everywhere is read from the `metallicRoughnessTexture`'s texels (glTF 2.0
/// §3.9.2: metallic = `metallicFactor` × B): a transmissive material whose factor is 1 but
/// whose texture's blue channel is 0 in every texel is glass (IridescentDishWithOlives'
/// cover); one texel of B = 51 makes the range reach 0.2 and the material no pane.
#[test]
fn a_metallic_texture_without_metal_makes_glass() {
    use nacre_runtime::gltf_scene::{
        GltfMaterial, GltfTexture, IDENTITY_TRANSFORM, SamplerSpec, TextureRef,
    };
    let texels = |b: [u8; 4]| GltfTexture {
        name: "texture 0".into(),
        width: 2,
        height: 2,
        rgba: b.iter().flat_map(|&b| [255, 26, b, 255]).collect(),
        srgb: false,
        sampler: SamplerSpec::default(),
    };
    let mut material = GltfMaterial {
        transmission: 1.0,
        metallic: 1.0,
        ..GltfMaterial::default()
    };
    material.textures.metallic_roughness = Some(TextureRef {
        texture: 0,
        tex_coord: 0,
        transform: IDENTITY_TRANSFORM,
    });
    let mut scene = GltfScene {
        materials: vec![material.clone()],
        textures: vec![texels([0; 4])],
        ..GltfScene::default()
    };
    assert_eq!(material.metallic_range(), (0.0, 1.0));
    assert_eq!(scene.metallic_range(0), (0.0, 0.0));
    assert!(nacre_runtime::mesh::glass_setup(&scene, 0).is_ok());

    scene.textures = vec![texels([0, 0, 51, 0])];
    assert_eq!(scene.metallic_range(0), (0.0, 0.2));
    let why = nacre_runtime::mesh::glass_setup(&scene, 0).unwrap_err();
    assert!(
        why.to_string().contains("metallic value reaches 0.2"),
        "{why}"
    );
    // Without texels (the loader skipped the texture) the factor's bound stands.
    scene.textures.clear();
    assert_eq!(scene.metallic_range(0), (0.0, 1.0));
}

/// `mesh::render_cached` keeps the compiled passes between frames: a new camera or film
/// thickness compiles nothing, another technique or base index compiles anew, and every
/// frame is the same bytes as an uncached `mesh::render` of the same inputs.
#[test]
fn a_mesh_cache_keeps_the_passes_and_draws_the_same_bytes() {
    use nacre_runtime::mesh::{MeshCache, Orbit, RenderInputs, ViewPoint, render, render_cached};
    let ctx = ctx();
    let tables = film_tables("film-dielectric");
    let scene = GltfScene::load(&asset_dir().join("sweep-thickness.glb")).unwrap();
    let orbit = |yaw_deg: f64| {
        ViewPoint::Orbit(Orbit {
            yaw_deg,
            ..Orbit::default()
        })
    };
    let mut cache = MeshCache::default();
    let frame =
        |scene: &GltfScene, technique: Technique, view: ViewPoint, cache: &mut MeshCache| {
            let inputs = RenderInputs::load(scene, &options(), view).unwrap();
            let cached = render_cached(ctx, &tables, technique, &inputs, cache).unwrap();
            let fresh = render(ctx, &tables, technique, &inputs).unwrap();
            assert!(
                cached.image.pixels == fresh.image.pixels,
                "{technique:?}: the cached frame differs from a fresh render"
            );
            cached.image.pixels
        };
    let first = frame(&scene, Technique::Lut, orbit(0.0), &mut cache);
    assert_eq!(cache.builds(), 1);

    // Another camera and thinner films (inside the table): uniforms only.
    let mut thinner = scene.clone();
    for m in &mut thinner.materials {
        if let Some(i) = &mut m.iridescence {
            i.thickness_max_nm *= 0.8;
        }
    }
    let moved = frame(&thinner, Technique::Lut, orbit(25.0), &mut cache);
    assert_eq!(
        cache.builds(),
        1,
        "a camera and a film thickness compile nothing"
    );
    assert_ne!(moved, first, "the frame follows the camera and the films");

    // Another technique, then another base index under spectral (its group 1 holds the
    // base's index per wavelength): compiled anew.
    frame(&thinner, Technique::Spectral, orbit(25.0), &mut cache);
    assert_eq!(cache.builds(), 2);
    let mut denser = thinner.clone();
    for m in &mut denser.materials {
        m.ior = 1.8;
    }
    frame(&denser, Technique::Spectral, orbit(25.0), &mut cache);
    assert_eq!(cache.builds(), 3, "a new base index compiles anew");
    frame(&denser, Technique::Spectral, orbit(50.0), &mut cache);
    assert_eq!(cache.builds(), 3);
}
