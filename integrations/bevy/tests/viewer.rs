//! The interactive viewer runs: `examples/viewer.rs`, as its `main` runs it, with
//! `--frames 20 --screenshot PATH`, opens its window (winit on X11: under `xvfb-run` where
//! there is no display, as test.sh runs it), draws the sphere row and IridescenceSuzanne on
//! Vulkan (Mesa's lavapipe in CI), saves its picture and exits by itself; the picture shows
//! the film: not black, colourful (≥ 3 hue sectors of 30°, the golden tests' measure), and
//! along the sphere row (0 … 700 nm) the hue at each sphere's centre is nacre's CPU hue at
//! normal incidence wherever that colour is saturated, as `tests/render.rs` checks it.
//!
//! A test without libtest's harness (`harness = false` in Cargo.toml): winit opens its
//! event loop on the main thread only. A missing display or adapter fails.

#[allow(dead_code)]
#[path = "../examples/viewer.rs"]
mod viewer;

mod support;

use bevy::camera::{CameraProjection, PerspectiveProjection};
use bevy::prelude::*;
use viewer::scene::{ROW, THICKNESS_MAX_NM};

fn main() {
    assert!(
        std::env::var_os("DISPLAY").is_some(),
        "no X display: run the viewer's test under `xvfb-run -a` (integrations/bevy/test.sh does)"
    );
    let path = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bevy-viewer.png");
    let _ = std::fs::remove_file(&path);
    let options = viewer::Options::parse(
        ["--frames", "20", "--screenshot"]
            .map(String::from)
            .into_iter()
            .chain([path.to_string_lossy().into_owned()]),
    )
    .unwrap();
    let exit = viewer::run(options);
    assert_eq!(exit, AppExit::Success, "the viewer failed");

    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(&path).expect("the viewer saved no screenshot"),
    ));
    let mut reader = decoder.read_info().unwrap();
    let mut rgb = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut rgb).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb, "an RGB8 screenshot");
    let (w, h) = (info.width as usize, info.height as usize);
    let rgba: Vec<u8> = rgb[..3 * w * h]
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    eprintln!("{}: {w} × {h}", path.display());

    // Not black.
    let lit = rgba
        .chunks_exact(4)
        .filter(|p| support::hsv(p).2 > 0.1)
        .count();
    eprintln!("{lit} pixels brighter than 0.1");
    assert!(lit * 20 > w * h, "the picture is black: {lit} lit pixels");
    let (count, sectors) = support::colourfulness(&rgba);
    eprintln!("{count} saturated pixels over {sectors} hue sectors of 30°");
    assert!(
        count >= 2000 && sectors >= 3,
        "{count} pixels, {sectors} sectors"
    );

    // Each sphere's centre, projected with the viewer's camera: there n·v = 1.
    let projection = PerspectiveProjection {
        aspect_ratio: w as f32 / h as f32,
        ..default()
    };
    let clip_from_world =
        projection.get_clip_from_view() * viewer::START.transform().to_matrix().inverse();
    let path = support::repo_root().join("tables/baked/film-dielectric.json");
    let manifest = nacre_format::Manifest::read(&path).unwrap();
    let axes = manifest.film_lut().cloned().unwrap();
    let table = manifest.load_table(&path, "reflectance").unwrap().unwrap();
    let mut hues = Vec::new();
    let mut compared = 0;
    for i in 0..ROW {
        let d = f64::from(THICKNESS_MAX_NM) * i as f64 / (ROW - 1) as f64;
        let centre = viewer::ROW_CENTRE + Vec3::X * (i as f32 - (ROW - 1) as f32 / 2.0);
        let ndc = clip_from_world.project_point3(centre);
        let x = ((ndc.x + 1.0) / 2.0 * w as f32) as usize;
        let y = ((1.0 - ndc.y) / 2.0 * h as f32) as usize;
        let (gpu_hue, gpu_s, gpu_v) = support::hsv(&rgba[4 * (y * w + x)..][..4]);
        let cpu = nacre_format::film_lut::FilmLut::lookup(&axes, &table, 1.0, d, 1.8);
        let p = cpu.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
        let (cpu_hue, cpu_s, _) = support::hsv(&[p[0], p[1], p[2], 255]);
        eprintln!(
            "d = {d:.0} nm at pixel ({x}, {y}): hue {gpu_hue:.0}° (s {gpu_s:.2}, v {gpu_v:.2}); nacre's CPU {cpu_hue:.0}° (s {cpu_s:.2})"
        );
        let diff = (gpu_hue - cpu_hue)
            .abs()
            .min(360.0 - (gpu_hue - cpu_hue).abs());
        if cpu_s > 0.2 {
            compared += 1;
            assert!(
                diff <= 30.0,
                "d = {d} nm: hue {gpu_hue:.0}° against nacre's {cpu_hue:.0}°"
            );
        }
        if gpu_s > 0.2 {
            hues.push((gpu_hue / 30.0) as usize % 12);
        }
    }
    hues.sort_unstable();
    hues.dedup();
    eprintln!("sphere centres in {} hue sectors", hues.len());
    assert!(
        compared >= 3,
        "{compared} spheres with a saturated film colour"
    );
    assert!(
        hues.len() >= 3,
        "the row's hues span {} sectors",
        hues.len()
    );
}
