//! `KHR_texture_basisu` (`nacre_runtime::gltf_scene::basisu`, `textures.rs`), on the assets
//! made by `scripts/gen_basisu_fixture.py` (`tests/golden/gltf/basisu/`: a 32 × 32 sRGB
//! picture of four ramped quadrants, encoded by Binomial's `basisu` as ETC1S/BasisLZ and as
//! UASTC/Zstandard, each the base colour texture of an unlit quad):
//!
//! * both KTX2 files decode to the source picture within each codec's error;
//! * both quads (one with the image by URI, one in a GLB buffer view, neither with a core
//!   `source`) load, and render their texels quadrant by quadrant (GPU);
//! * damaged KTX2 files (truncated, not KTX2, a plain vkFormat, a wrong or unknown
//!   supercompression scheme, a level outside the file, a 3-D texture, damaged payloads) are
//!   errors naming the texture and the image, never panics; so is a bad extension `source`.

use nacre_runtime::Technique;
use nacre_runtime::gltf_scene::basisu::decode;
use nacre_runtime::gltf_scene::{GltfError, GltfScene, Ktx2Error};
use nacre_runtime::mesh::{fit_camera, render_gltf};
use nacre_runtime::render::{RenderedImage, SceneKind, SceneOptions};
use std::path::PathBuf;

mod support;
use support::{ctx, film_tables, repo_root};

fn asset_dir() -> PathBuf {
    repo_root().join("tests/golden/gltf/basisu")
}

/// The source picture as RGBA8 texels (32 × 32).
fn source() -> Vec<u8> {
    let picture = image::open(asset_dir().join("source.png")).unwrap();
    assert_eq!((picture.width(), picture.height()), (32, 32));
    picture.into_rgba8().into_raw()
}

/// Mean and largest |decoded − source| over the RGB channels, 8-bit levels.
fn errors(decoded: &[u8], source: &[u8]) -> (f64, u8) {
    let mut sum = 0.0;
    let mut max = 0u8;
    let mut n = 0.0;
    for (d, s) in decoded.chunks(4).zip(source.chunks(4)) {
        for c in 0..3 {
            let e = d[c].abs_diff(s[c]);
            sum += f64::from(e);
            max = max.max(e);
            n += 1.0;
        }
        assert_eq!(d[3], 255, "opaque source, opaque texels");
    }
    (sum / n, max)
}

#[test]
fn both_codecs_decode_to_the_source_within_their_error() {
    let source = source();
    // (file, codec, mean and largest error allowed): ETC1S is the coarser codec (one colour
    // pair per block from a shared codebook), UASTC within a few levels.
    for (file, codec, mean_max, max_max) in [
        ("etc1s.ktx2", "ETC1S", 2.5, 12),
        ("uastc.ktx2", "UASTC", 0.5, 3),
    ] {
        let bytes = std::fs::read(asset_dir().join(file)).unwrap();
        let decoded = decode(&bytes).unwrap();
        assert_eq!(decoded.codec, codec);
        assert_eq!((decoded.width, decoded.height), (32, 32));
        let (mean, max) = errors(&decoded.rgba, &source);
        println!("{file}: {codec}, mean |error| {mean:.3} levels, largest {max}");
        assert!(
            mean <= mean_max && max <= max_max,
            "{file}: mean {mean}, largest {max}"
        );
        assert!(mean > 0.0, "{file}: a lossy codec decodes exactly?");
    }
}

/// Image size of the quad renders.
const SIZE: (u32, u32) = (96, 96);

/// The image's pixel of world point p under the renderer's fitted camera.
fn project(scene: &GltfScene, p: [f32; 3]) -> (u32, u32) {
    let (lo, hi) = scene.bounds();
    let cam = fit_camera(lo, hi, f64::from(SIZE.0) / f64::from(SIZE.1)).unwrap();
    let m = cam.view_proj;
    let c: [f32; 4] =
        std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r]);
    let (x, y) = (c[0] / c[3], c[1] / c[3]);
    (
        ((x * 0.5 + 0.5) * SIZE.0 as f32) as u32,
        ((0.5 - y * 0.5) * SIZE.1 as f32) as u32,
    )
}

/// The RGB of pixel (x, y).
fn pixel(image: &RenderedImage, (x, y): (u32, u32)) -> [f64; 3] {
    let i = ((y * image.width + x) * 4) as usize;
    [0, 1, 2].map(|c| f64::from(image.pixels[i + c]))
}

/// The 32 × 32 texels bilinearly filtered at (u, v) (texel centres at (i + ½)/32, clamped to
/// the edge as the fixtures' sampler says), in their 8-bit values.
fn bilinear(rgba: &[u8], (u, v): (f64, f64)) -> [f64; 3] {
    let at = |x: i64, y: i64| {
        let i = ((y.clamp(0, 31) * 32 + x.clamp(0, 31)) * 4) as usize;
        [0, 1, 2].map(|c| f64::from(rgba[i + c]))
    };
    let (x, y) = (u * 32.0 - 0.5, v * 32.0 - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let (a, b, c, d) = (
        at(x0, y0),
        at(x0 + 1, y0),
        at(x0, y0 + 1),
        at(x0 + 1, y0 + 1),
    );
    std::array::from_fn(|k| {
        (a[k] * (1.0 - fx) + b[k] * fx) * (1.0 - fy) + (c[k] * (1.0 - fx) + d[k] * fx) * fy
    })
}

#[test]
fn basisu_quads_render_their_texels() {
    let tables = film_tables("film-dielectric");
    let mut options = SceneOptions::new(SceneKind::Sphere);
    (options.width, options.height) = SIZE;
    for file in ["quad-etc1s.gltf", "quad-uastc.glb"] {
        let scene = GltfScene::load(&asset_dir().join(file)).unwrap();
        assert!(scene.notes.is_empty(), "{file}: {:?}", scene.notes);
        assert_eq!(scene.textures.len(), 1, "{file}");
        let texture = &scene.textures[0];
        assert!(texture.srgb, "{file}: a base colour texture is sRGB");
        assert_eq!((texture.width, texture.height), (32, 32));
        assert_eq!(scene.materials[0].textures.base_colour.unwrap().texture, 0);
        let out = render_gltf(ctx(), &tables, Technique::Lut, &scene, &options).unwrap();
        let png = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("{file}.png"));
        image::save_buffer(
            &png,
            &out.image.pixels,
            SIZE.0,
            SIZE.1,
            image::ExtendedColorType::Rgba8,
        )
        .unwrap();
        // Each quadrant by region: the mean over 6 × 6 points of its middle half (uv within
        // 1/8 to 3/8 of the quad from the quadrant's edges), rendered and filtered from the
        // texels. The quad spans x, y in [−1, 1] with uv (0, 0) at its top left (−1, 1).
        let mut worst = 0.0f64;
        for quadrant in 0..4 {
            let (qu, qv) = (f64::from(quadrant % 2) * 0.5, f64::from(quadrant / 2) * 0.5);
            let (mut rendered, mut expected) = ([0.0; 3], [0.0; 3]);
            for i in 0..6 {
                for j in 0..6 {
                    let u = qu + 0.125 + 0.25 * f64::from(i) / 5.0;
                    let v = qv + 0.125 + 0.25 * f64::from(j) / 5.0;
                    let at = project(
                        &scene,
                        [(2.0 * u - 1.0) as f32, (1.0 - 2.0 * v) as f32, 0.0],
                    );
                    let (p, t) = (pixel(&out.image, at), bilinear(&texture.rgba, (u, v)));
                    for c in 0..3 {
                        rendered[c] += p[c] / 36.0;
                        expected[c] += t[c] / 36.0;
                    }
                }
            }
            let d = (0..3)
                .map(|c| (rendered[c] - expected[c]).abs())
                .fold(0.0, f64::max);
            worst = worst.max(d);
            // The pixel centre is up to half a pixel (½ texel) off the point projected, the
            // ramp climbs ≤ 1 level per texel, and 8-bit rounding.
            assert!(
                d <= 1.5,
                "{file}: quadrant {quadrant}: rendered {rendered:?}, texels {expected:?} ({})",
                png.display()
            );
        }
        println!("{file}: worst quadrant |rendered − texels| {worst:.2} levels");
    }
}

/// The error of loading the ETC1S quad (`broken.gltf`, in a temporary folder) whose KTX2
/// image (`etc1s.ktx2` beside it) is `ktx2` and whose texture's extension is `extension`.
fn load_with(ktx2: &[u8], extension: serde_json::Value) -> nacre_runtime::Error {
    let text = std::fs::read_to_string(asset_dir().join("quad-etc1s.gltf")).unwrap();
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    doc["textures"][0]["extensions"]["KHR_texture_basisu"] = extension;
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("etc1s.ktx2"), ktx2).unwrap();
    let path = dir.path().join("broken.gltf");
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    match GltfScene::load(&path) {
        Ok(_) => panic!("a broken KTX2 loaded"),
        Err(e) => e,
    }
}

fn ktx2_error(ktx2: &[u8]) -> Ktx2Error {
    match load_with(ktx2, serde_json::json!({"source": 0})) {
        nacre_runtime::Error::Gltf {
            error:
                GltfError::Basisu {
                    texture: 0,
                    image: 0,
                    error,
                },
            path,
        } => {
            assert!(path.ends_with("broken.gltf"), "{}", path.display());
            error
        }
        other => panic!("expected a Basisu error, got {other:?}"),
    }
}

#[test]
fn damaged_ktx2_files_are_errors_naming_the_texture() {
    let good = std::fs::read(asset_dir().join("etc1s.ktx2")).unwrap();
    let set_u32 = |offset: usize, value: u32| {
        let mut b = good.clone();
        b[offset..offset + 4].copy_from_slice(&value.to_le_bytes());
        b
    };
    let set_u64 = |offset: usize, value: u64| {
        let mut b = good.clone();
        b[offset..offset + 8].copy_from_slice(&value.to_le_bytes());
        b
    };
    let n = good.len();
    assert_eq!(
        ktx2_error(&good[..60]),
        Ktx2Error::Truncated {
            bytes: 60,
            need: 80
        }
    );
    assert_eq!(ktx2_error(b"\x89PNG\r\n\x1a\n0000"), Ktx2Error::NotKtx2);
    // VK_FORMAT_R8G8B8A8_SRGB (43): a plain KTX2 texture.
    assert_eq!(
        ktx2_error(&set_u32(12, 43)),
        Ktx2Error::VkFormat { vk_format: 43 }
    );
    // ZLIB (3) is a KTX2 scheme, not one of the extension's; Zstandard is not ETC1S's.
    assert_eq!(
        ktx2_error(&set_u32(44, 3)),
        Ktx2Error::Supercompression {
            scheme: 3,
            codec: None
        }
    );
    assert_eq!(
        ktx2_error(&set_u32(44, 99)),
        Ktx2Error::Supercompression {
            scheme: 99,
            codec: None
        }
    );
    match ktx2_error(&set_u32(44, 2)) {
        Ktx2Error::Supercompression {
            scheme: 2,
            codec: Some("ETC1S"),
        }
        | Ktx2Error::LevelSize { level: 0, .. }
        | Ktx2Error::Transcoder { .. } => {}
        other => panic!("ETC1S under Zstandard: {other:?}"),
    }
    // Level 0's byteOffset beyond the file, and a byteLength running past it.
    assert_eq!(
        ktx2_error(&set_u64(80, 1 << 40)),
        Ktx2Error::LevelOutside {
            level: 0,
            offset: 1 << 40,
            length: u64::from_le_bytes(good[88..96].try_into().unwrap()),
            bytes: n
        }
    );
    assert!(matches!(
        ktx2_error(&set_u64(88, u64::MAX)),
        Ktx2Error::LevelOutside { level: 0, .. }
    ));
    // levelCount 6 of a file cut inside the level index.
    assert_eq!(
        ktx2_error(&good[..100]),
        Ktx2Error::Truncated {
            bytes: 100,
            need: 80 + 6 * 24
        }
    );
    assert!(matches!(
        ktx2_error(&set_u32(28, 4)),
        Ktx2Error::NotTwoD { depth: 4, .. }
    ));
    assert!(matches!(
        ktx2_error(&set_u32(20, 0)),
        Ktx2Error::Dimensions { width: 0, .. }
    ));
    // Cut inside the level data: every level's index entry now points past the end.
    assert!(matches!(
        ktx2_error(&good[..n - 40]),
        Ktx2Error::LevelOutside { .. }
    ));
    // A Zstandard level claiming a huge uncompressed length (the transcoder would allocate
    // it: 2^40 bytes).
    let uastc = std::fs::read(asset_dir().join("uastc.ktx2")).unwrap();
    let mut huge = uastc.clone();
    huge[96..104].copy_from_slice(&(1u64 << 40).to_le_bytes());
    assert_eq!(
        decode(&huge),
        Err(Ktx2Error::LevelSize {
            level: 0,
            uncompressed: 1 << 40,
            expected: 8 * 8 * 16
        })
    );
    // Damaged payloads (the supercompression global data and the levels): an error or a
    // decoded picture, never a panic (the transcoder runs under the decoder guard).
    for file in ["etc1s.ktx2", "uastc.ktx2"] {
        let good = std::fs::read(asset_dir().join(file)).unwrap();
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        for _ in 0..300 {
            let mut bytes = good.clone();
            for _ in 0..4 {
                seed = seed
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                let at = 80 + (seed >> 33) as usize % (bytes.len() - 80);
                bytes[at] ^= (seed >> 24) as u8 | 1;
            }
            // Header fields are checked above; damage the index and the payload.
            let _ = decode(&bytes);
        }
    }
}

#[test]
fn a_bad_extension_source_is_an_error() {
    let good = std::fs::read(asset_dir().join("etc1s.ktx2")).unwrap();
    for extension in [
        serde_json::json!({"source": 7}),
        serde_json::json!({"source": "zero"}),
        serde_json::json!({}),
    ] {
        match load_with(&good, extension.clone()) {
            nacre_runtime::Error::Gltf {
                error: GltfError::NotGltf { reason },
                ..
            } => assert!(
                reason.contains("textures[0].extensions.KHR_texture_basisu.source"),
                "{extension}: {reason}"
            ),
            other => panic!("{extension}: {other:?}"),
        }
    }
}
