//! Headless Bevy apps for the tests: Vulkan (Mesa's lavapipe in CI), no window, frames
//! driven by `App::update`, pictures read back with Bevy's screenshot API. A missing adapter
//! fails the test that asked for it.
#![allow(dead_code)]

use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::render::render_resource::TextureFormat;
use bevy::render::settings::{Backends, RenderCreation, WgpuSettings};
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

#[path = "../../examples/common/headless.rs"]
mod headless;

/// The repository root (`integrations/bevy/../..`).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A headless app with Bevy's default plugins (Vulkan backend, no window, no pipelined
/// rendering, synchronous pipeline compilation) and [`NacrePlugin`], reading assets under
/// `asset_root`. Panics, naming the cause, when no Vulkan adapter is found.
pub fn headless_app(asset_root: &Path) -> App {
    let app = headless::headless_app(
        asset_root,
        RenderPlugin {
            render_creation: RenderCreation::Automatic(Box::new(WgpuSettings {
                backends: Some(Backends::VULKAN),
                ..default()
            })),
            synchronous_pipeline_compilation: true,
            ..default()
        },
    );
    assert!(
        app.get_sub_app(bevy::render::RenderApp).is_some(),
        "no Vulkan adapter: Bevy could not create its renderer (install Mesa's lavapipe, \
         Debian package mesa-vulkan-drivers, or a GPU driver)"
    );
    app
}

/// An sRGB render target of `width` × `height`.
pub fn target(app: &mut App, width: u32, height: u32) -> Handle<Image> {
    let image = Image::new_target_texture(width, height, TextureFormat::Rgba8UnormSrgb, None);
    app.world_mut().resource_mut::<Assets<Image>>().add(image)
}

/// Runs `frames` frames, then captures `target` and runs until the picture comes back
/// (at most 100 more frames): its RGBA8 pixels.
pub fn capture(app: &mut App, target: &Handle<Image>, frames: usize) -> Vec<u8> {
    for _ in 0..frames {
        app.update();
    }
    let slot: Arc<Mutex<Option<Vec<u8>>>> = Arc::default();
    let sink = slot.clone();
    app.world_mut()
        .spawn(Screenshot::image(target.clone()))
        .observe(move |captured: On<ScreenshotCaptured>| {
            *sink.lock().unwrap() = captured.image.data.clone();
        });
    for _ in 0..100 {
        app.update();
        if let Some(pixels) = slot.lock().unwrap().take() {
            return pixels;
        }
    }
    panic!("the screenshot never came back");
}

/// Runs frames until `done` holds (at most `max` frames); false if it never did.
pub fn run_until(app: &mut App, max: usize, mut done: impl FnMut(&mut World) -> bool) -> bool {
    for _ in 0..max {
        app.update();
        if done(app.world_mut()) {
            return true;
        }
    }
    false
}

/// Writes RGBA8 pixels as a PNG under the test's temporary directory; its path.
pub fn write_png(name: &str, width: u32, height: u32, pixels: &[u8]) -> PathBuf {
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let file = std::fs::File::create(&path).unwrap();
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .write_header()
        .unwrap()
        .write_image_data(pixels)
        .unwrap();
    eprintln!("wrote {}", path.display());
    path
}

/// Hue (degrees), saturation and value of an RGBA8 pixel.
pub fn hsv(p: &[u8]) -> (f64, f64, f64) {
    let [r, g, b] = [p[0], p[1], p[2]].map(|c| f64::from(c) / 255.0);
    let max = r.max(g).max(b);
    let min = r.min(g).min(b);
    let d = max - min;
    let h = if d == 0.0 {
        0.0
    } else if max == r {
        60.0 * ((g - b) / d).rem_euclid(6.0)
    } else if max == g {
        60.0 * ((b - r) / d + 2.0)
    } else {
        60.0 * ((r - g) / d + 4.0)
    };
    (h, if max > 0.0 { d / max } else { 0.0 }, max)
}

/// Saturated pixels (s > 0.35, v > 0.1) and how many 30° hue sectors hold at least 2 of
/// them (the golden tests' hue-structure measure).
pub fn colourfulness(pixels: &[u8]) -> (usize, usize) {
    let mut sectors = [0usize; 12];
    let mut count = 0;
    for p in pixels.chunks_exact(4) {
        let (h, s, v) = hsv(p);
        if s > 0.35 && v > 0.1 {
            count += 1;
            sectors[(h / 30.0) as usize % 12] += 1;
        }
    }
    (count, sectors.iter().filter(|&&n| n >= 2).count())
}

/// `../shared/gltf-samples`, or `None` (skip) outside CI; a panic in CI (as the runtime's
/// `gltf_samples.rs` decides).
pub fn samples() -> Option<PathBuf> {
    let dir = repo_root().join("../shared/gltf-samples");
    if dir.is_dir() {
        return Some(dir);
    }
    if std::env::var_os("CI").is_some() {
        panic!(
            "{} is missing: CI must provide the Khronos glTF samples (../shared/DATA.md)",
            dir.display()
        );
    }
    eprintln!(
        "skipped: {} not found (the Khronos glTF samples of ../shared/DATA.md)",
        dir.display()
    );
    None
}
