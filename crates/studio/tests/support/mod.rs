//! What the studio's UI tests share: a studio on a headless view (whatever adapter wgpu
//! finds: lavapipe in CI; a missing adapter fails the tests, they never skip), its
//! `egui_kittest` harness, waiting for the view and the plots, and reading the picture.

// Each test file uses a part of it.
#![allow(dead_code)]

use egui_kittest::Harness;
use nacre_runtime::GpuContext;
use nacre_studio::curves::exact_colours;
use nacre_studio::doc::StackDoc;
use nacre_studio::view::{Lighting, uniform_sky_pixel};
use nacre_studio::{Studio, View};
use std::time::{Duration, Instant};

/// The view's picture size in the tests, pixels.
pub const VIEW: [u32; 2] = [96, 72];

/// A mirror-smooth roughness, so that the centre pixel is the film at normal incidence.
pub const ALPHA: f32 = 0.001;

/// The film_stack technique's few fitted wavelengths against the exact spectral sum, in
/// 8-bit sRGB levels at the sphere's centre (measured ≤ 3 over the thicknesses of ui.rs).
pub const TOLERANCE: i32 = 4;

/// A studio of `doc` on a headless view, its picture `size` pixels.
pub fn new_studio(doc: StackDoc, size: [u32; 2]) -> Studio {
    let ctx = GpuContext::new_headless().expect("a wgpu adapter (lavapipe in CI)");
    let view = View::new(ctx).expect("the default tables load");
    Studio::new(Ok(view), doc, size)
}

/// A studio of `doc` at [`VIEW`] under the uniform sky with a mirror-smooth film: the
/// sphere's centre is the film's reflectance colour ([`predicted`]).
pub fn studio(doc: StackDoc) -> Studio {
    let mut s = new_studio(doc, VIEW);
    s.settings.lighting = Lighting::Uniform;
    s.settings.roughness_alpha = ALPHA;
    s
}

/// The harness drawing `studio` in a window of `size` points.
pub fn harness_of(studio: Studio, size: [f32; 2]) -> Harness<'static, Studio> {
    Harness::builder()
        .with_size(size)
        .wgpu()
        .build_ui_state(|ui, s: &mut Studio| s.ui(ui), studio)
}

/// The harness of [`studio`]`(doc)` in a 1400 × 900 window.
pub fn harness(doc: StackDoc) -> Harness<'static, Studio> {
    harness_of(studio(doc), [1400.0, 900.0])
}

/// Steps until the plots show the current stack and a frame is drawn, at most 60 s.
pub fn settle(h: &mut Harness<'_, Studio>) {
    let start = Instant::now();
    loop {
        h.step();
        if h.state().curves_current() && h.state().frame.is_some() {
            h.step();
            return;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the plots never caught up: {:?}",
            h.state().curves_error
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The last frame's pixels, RGB.
pub fn pixels(s: &Studio) -> Vec<[u8; 3]> {
    let img = &s.frame.as_ref().expect("a frame").image;
    img.pixels
        .chunks_exact(4)
        .map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// The last frame's centre pixel.
pub fn centre(s: &Studio) -> [u8; 3] {
    let img = &s.frame.as_ref().expect("a frame").image;
    let (x, y) = (img.width as usize / 2, img.height as usize / 2);
    pixels(s)[y * img.width as usize + x]
}

/// The largest difference of two pixels' channels, 8-bit levels.
pub fn distance(a: [u8; 3], b: [u8; 3]) -> i32 {
    (0..3)
        .map(|k| (i32::from(a[k]) - i32::from(b[k])).abs())
        .max()
        .unwrap()
}

/// The centre pixel `nacre color` (the spectral method, [`exact_colours`]) predicts for
/// `doc` at 0° under the uniform sky ([`uniform_sky_pixel`]).
pub fn predicted(doc: &StackDoc) -> [u8; 3] {
    let rgb = exact_colours(&doc.build().unwrap(), &[0.0]).unwrap()[0];
    uniform_sky_pixel(rgb, f64::from(ALPHA))
}
