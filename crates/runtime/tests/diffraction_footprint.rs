//! The footprint filter of the diffraction scenes (issue 37, item 3: no aliasing;
//! `diffraction_colour_footprint` in `shaders/diffraction.wgsl`). A compact disc's spectrum
//! varies faster than a pixel's footprint: one point sample of the BRDF per pixel is noise
//! that changes with the resolution. With the filter the picture converges as the resolution
//! grows, and a disc far away shows its average colour, not speckle:
//!
//! * `cd-disc` (the `cd-tracks` table, 10 nm step, a directional light from beyond the disc
//!   whose first order crosses it, no environment) at 128² against the same scene at 512²
//!   box-averaged 4 × 4 down to 128² (display-linear RGB): the mean |Δ| with the filter must
//!   be at most half of that without;
//! * the disc 4 × farther away (about 30 pixels across at 128²): the pixel-to-pixel variance
//!   over the data area with the filter at most half of that without, and its mean |Δ| to the
//!   converged picture (512² with the filter, averaged down) at most half of the unfiltered
//!   one's.
//!
//! Measured numbers are in the constants' comments. A missing adapter fails the test: GPU tests
//! never skip.

use nacre_optics::diffraction::FresnelTerm;
use nacre_runtime::diffraction::{
    DiffractionScene, DiffractionSceneOptions, DiffractionTables, render_diffraction_scene,
};
use std::sync::OnceLock;

mod support;
use support::{ctx, manifest};

fn cd_tracks() -> &'static DiffractionTables {
    static TABLE: OnceLock<DiffractionTables> = OnceLock::new();
    TABLE.get_or_init(|| {
        DiffractionTables::load(ctx(), &manifest("cd-tracks"), FresnelTerm::Unity).unwrap()
    })
}

/// sRGB byte → linear [0, 1] (IEC 61966-2-1): the display-linear (tone-mapped) value.
fn linear(byte: u8) -> f64 {
    let c = f64::from(byte) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A rendered picture as display-linear RGB, row-major.
struct Picture {
    width: usize,
    height: usize,
    rgb: Vec<[f64; 3]>,
}

impl Picture {
    /// `factor × factor` box average (the supersampled picture at the lower resolution).
    fn downsample(&self, factor: usize) -> Picture {
        let (width, height) = (self.width / factor, self.height / factor);
        let mut rgb = vec![[0.0; 3]; width * height];
        for (i, out) in rgb.iter_mut().enumerate() {
            let (x, y) = (i % width, i / width);
            for dy in 0..factor {
                for dx in 0..factor {
                    let p = self.rgb[(y * factor + dy) * self.width + x * factor + dx];
                    for (o, v) in out.iter_mut().zip(p) {
                        *o += v / (factor * factor) as f64;
                    }
                }
            }
        }
        Picture { width, height, rgb }
    }

    /// Mean |Δ| over every pixel's channels.
    fn mean_difference(&self, other: &Picture) -> f64 {
        assert_eq!(self.rgb.len(), other.rgb.len());
        let sum: f64 = self
            .rgb
            .iter()
            .zip(&other.rgb)
            .map(|(a, b)| (0..3).map(|c| (a[c] - b[c]).abs()).sum::<f64>())
            .sum();
        sum / (3 * self.rgb.len()) as f64
    }
}

/// The cd-disc under a light from beyond it (its first order crosses the disc's near half,
/// as in tests/tests/grating_equation.rs), no environment, with the eye `distance` × as far
/// from the target as the scene's camera; the footprint filter on or off.
fn render(size: u32, distance: f32, filtered: bool) -> Picture {
    let mut options = DiffractionSceneOptions::new(DiffractionScene::CdDisc);
    (options.width, options.height) = (size, size);
    options.light.direction = [0.0, 0.95, -0.3];
    options.env_intensity = 0.0;
    options.env_samples = 0;
    let c = &mut options.camera;
    c.eye = [0, 1, 2].map(|k| c.target[k] + distance * (c.eye[k] - c.target[k]));
    if !filtered {
        options.technique.filter_radius = None;
    }
    let image = render_diffraction_scene(ctx(), cd_tracks(), &options).unwrap();
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "footprint-cd-{size}-x{distance}-{}.png",
        if filtered { "filtered" } else { "point" }
    ));
    image.write_png(&out).unwrap();
    eprintln!("wrote {} ({:.2} s)", out.display(), image.gpu_seconds);
    Picture {
        width: size as usize,
        height: size as usize,
        rgb: image
            .pixels
            .chunks_exact(4)
            .map(|p| [linear(p[0]), linear(p[1]), linear(p[2])])
            .collect(),
    }
}

/// 128² against 512² averaged down, mean |Δ| display-linear. Measured on Mesa llvmpipe
/// (LLVM 15, GL backend): without the filter 4.49e-3, with it 2.98e-3 (−34 %: the test's
/// bound of half is NOT met yet; work in progress on branch aa37).
#[test]
fn the_filtered_cd_disc_converges_with_resolution() {
    let mut gaps = [0.0; 2];
    for (i, filtered) in [false, true].into_iter().enumerate() {
        let coarse = render(128, 1.0, filtered);
        let fine = render(512, 1.0, filtered).downsample(4);
        gaps[i] = coarse.mean_difference(&fine);
        let lit = coarse.rgb.iter().filter(|p| p.iter().any(|&c| c > 0.02)).count();
        eprintln!(
            "filter {}: 128² against 512² → 128²: mean |Δ| {:.3e} ({lit} lit pixels)",
            if filtered { "on " } else { "off" },
            gaps[i]
        );
        assert!(lit >= 200, "{lit} lit pixels");
    }
    assert!(
        gaps[1] <= 0.5 * gaps[0],
        "with the filter {:.3e}, without {:.3e}",
        gaps[1],
        gaps[0]
    );
}

/// The pixels of `picture` (the cd-disc seen from `distance` × the scene's camera distance)
/// whose centre and right-hand neighbour's centre both see the data area
/// (0.38 ≤ r ≤ 0.98), traced as shaders/diffraction_scene.wgsl traces them.
fn data_area_pairs(size: u32, distance: f32) -> Vec<usize> {
    let options = DiffractionSceneOptions::new(DiffractionScene::CdDisc);
    let mut camera = options.camera;
    let target = camera.target;
    camera.eye = [0, 1, 2].map(|k| target[k] + distance * (camera.eye[k] - target[k]));
    let m = camera.inverse_view_projection(1.0).unwrap();
    let apply = |v: [f64; 4]| -> [f64; 3] {
        let mut r = [0.0; 4];
        for (row, out) in r.iter_mut().enumerate() {
            *out = (0..4).map(|c| f64::from(m[c][row]) * v[c]).sum();
        }
        [r[0] / r[3], r[1] / r[3], r[2] / r[3]]
    };
    let on_data = |px: u32, py: u32| -> bool {
        let n = f64::from(size);
        let ndc = [
            (f64::from(px) + 0.5) / n * 2.0 - 1.0,
            1.0 - (f64::from(py) + 0.5) / n * 2.0,
        ];
        let near = apply([ndc[0], ndc[1], 0.0, 1.0]);
        let far = apply([ndc[0], ndc[1], 1.0, 1.0]);
        let dir = [0, 1, 2].map(|k| far[k] - near[k]);
        let t = -near[1] / dir[1];
        if t <= 0.0 {
            return false;
        }
        let p = [0, 1, 2].map(|k| near[k] + t * dir[k]);
        (0.38..=0.98).contains(&(p[0] * p[0] + p[2] * p[2]).sqrt())
    };
    let mut pairs = Vec::new();
    for py in 0..size {
        for px in 0..size - 1 {
            if on_data(px, py) && on_data(px + 1, py) {
                pairs.push((py * size + px) as usize);
            }
        }
    }
    pairs
}

/// Mean of (L(x + 1) − L(x))² over `pairs`, L the display-linear luminance, divided by the
/// mean L² there: the speckle's pixel-to-pixel variance relative to the picture's level.
fn neighbour_variance(picture: &Picture, pairs: &[usize]) -> f64 {
    let lum = |p: [f64; 3]| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    let (mut d2, mut l2) = (0.0, 0.0);
    for &i in pairs {
        let (a, b) = (lum(picture.rgb[i]), lum(picture.rgb[i + 1]));
        d2 += (b - a) * (b - a);
        l2 += a * a;
    }
    d2 / l2.max(1e-30)
}

/// The disc 4 × farther away at 128². Fails on Mesa llvmpipe so far (numbers not yet
/// recorded; work in progress on branch aa37).
#[test]
fn a_distant_cd_shows_its_average_colour_not_noise() {
    const DISTANCE: f32 = 4.0;
    let pairs = data_area_pairs(128, DISTANCE);
    assert!(pairs.len() >= 200, "{} data-area pixel pairs", pairs.len());
    let point = render(128, DISTANCE, false);
    let filtered = render(128, DISTANCE, true);
    let converged = render(512, DISTANCE, true).downsample(4);
    let variance = [&point, &filtered, &converged].map(|p| neighbour_variance(p, &pairs));
    let gap = [&point, &filtered].map(|p| p.mean_difference(&converged));
    eprintln!(
        "disc at {DISTANCE} × ({} pixel pairs): relative neighbour variance {:.3} without the filter, {:.3} with it, {:.3} converged; mean |Δ| to converged {:.3e} without, {:.3e} with",
        pairs.len(),
        variance[0],
        variance[1],
        variance[2],
        gap[0],
        gap[1]
    );
    assert!(
        variance[1] <= 0.5 * variance[0],
        "neighbour variance {} with the filter, {} without",
        variance[1],
        variance[0]
    );
    assert!(
        gap[1] <= 0.5 * gap[0],
        "mean |Δ| to converged {} with the filter, {} without",
        gap[1],
        gap[0]
    );
}
