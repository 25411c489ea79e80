//! `nacre render --lighting both|light|environment` (issue 37: each source's picture measured
//! against its own reference). Rendering is linear in the sources, so under the diffraction
//! scenes' tone map c/(1 + max channel) — invertible — the light's picture plus the
//! environment's is the picture under both, to the 8-bit rounding; under the light alone the
//! background (the environment) is black. GPU: lavapipe without one; fails, never skips,
//! without an adapter.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn nacre(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nacre"))
        .args(args)
        .current_dir(repo_root())
        .output()
        .expect("nacre runs")
}

/// Renders `scene` at 40 × 30 under `lighting` into `dir` and returns its pixels, sRGB-encoded
/// values in [0, 1].
fn render(dir: &Path, scene: &str, lighting: &str) -> Vec<[f64; 3]> {
    render_at(dir, scene, lighting, 40, 30)
}

/// Renders `scene` at `width` × `height` under `lighting` into `dir` and returns its pixels,
/// sRGB-encoded values in [0, 1].
fn render_at(dir: &Path, scene: &str, lighting: &str, width: u32, height: u32) -> Vec<[f64; 3]> {
    let out = dir.join(format!("{scene}-{lighting}.png"));
    let o = nacre(&[
        "render",
        "--scene",
        scene,
        "--width",
        &width.to_string(),
        "--height",
        &height.to_string(),
        "--lighting",
        lighting,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        o.status.success(),
        "{scene} {lighting}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let picture = image::open(&out).unwrap().to_rgb8();
    picture
        .pixels()
        .map(|p| p.0.map(|c| f64::from(c) / 255.0))
        .collect()
}

fn srgb_to_linear(e: f64) -> f64 {
    if e <= 0.04045 {
        e / 12.92
    } else {
        ((e + 0.055) / 1.055).powf(2.4)
    }
}

/// The radiance behind a displayed diffraction-scene pixel: m = c/(1 + max c), so
/// c = m/(1 − max m).
fn radiance(displayed: [f64; 3]) -> [f64; 3] {
    let m = displayed.map(srgb_to_linear);
    let peak = m[0].max(m[1]).max(m[2]).min(0.995);
    m.map(|x| x / (1.0 - peak))
}

#[test]
fn the_light_and_the_environment_add_up_to_both() {
    let dir = tempfile::tempdir().unwrap();
    for scene in ["cd-disc", "dvd-disc", "snake-skin", "grating-plane"] {
        // The DVD's first orders are two thin lines: at 40 × 30 they light only 57 channels
        // that both sources light.
        let (w, h) = if scene == "dvd-disc" {
            (96, 72)
        } else {
            (40, 30)
        };
        let both = render_at(dir.path(), scene, "both", w, h);
        let light = render_at(dir.path(), scene, "light", w, h);
        let env = render_at(dir.path(), scene, "environment", w, h);
        let (mut worst, mut lit, mut env_lit, mut compared) = (0.0f64, 0usize, 0usize, 0usize);
        for ((b, l), e) in both.iter().zip(&light).zip(&env) {
            let (b, l, e) = (radiance(*b), radiance(*l), radiance(*e));
            lit += usize::from(l.iter().any(|&x| x > 0.01));
            env_lit += usize::from(e.iter().any(|&x| x > 0.01));
            // The brightest channel of the three pictures: c = m/(1 − max m) makes every
            // channel's radiance move with the peak's rounding, by c (1 + peak) per unit of m.
            let peak = [b, l, e]
                .iter()
                .flatten()
                .fold(0.0f64, |top, &x| top.max(x));
            for c in 0..3 {
                // One 8-bit step of each of the three pictures, in radiance: ∂c/∂m = 1 + peak
                // for the channel's own value, c (1 + peak) through the peak's (the peak
                // channel: (1 + c)², as before; a dim channel beside a bright one, such as the
                // DVD's saturated first-order line, much more than (1 + c)²).
                let step = 0.02 * (1.0 + b[c]) * (1.0 + peak);
                // A channel clipped at 0 (a spectral colour outside sRGB's gamut loses its
                // negative part, and the sources' negative parts add before the clip) gives
                // max(L + E, 0) ≤ max(L, 0) + max(E, 0); where no picture is clipped, equality.
                let excess = (b[c] - l[c] - e[c]) / step;
                if b[c] > 0.0 && l[c] > 0.0 && e[c] > 0.0 {
                    worst = worst.max(excess.abs());
                    compared += 1;
                } else {
                    worst = worst.max(excess);
                }
            }
        }
        assert!(
            worst <= 1.0,
            "{scene}: light + environment departs from both by {worst:.2} of the rounding bound"
        );
        assert!(
            compared >= 100,
            "{scene}: only {compared} unclipped channels lit by both sources"
        );
        // Each source lights part of the picture; the environment lights more of it (the
        // background among it), and under the light alone the corner (background) is black.
        assert!(
            lit > 0 && env_lit > lit,
            "{scene}: {lit} pixels lit by the light, {env_lit} by the environment"
        );
        assert_eq!(
            light[0], [0.0; 3],
            "{scene}: the background under the light alone"
        );
        assert!(
            env[0].iter().any(|&x| x > 0.0),
            "{scene}: the background under the environment"
        );
    }
}

#[test]
fn film_scenes_take_the_lighting_too() {
    let dir = tempfile::tempdir().unwrap();
    let light = render(dir.path(), "sphere", "light");
    let env = render(dir.path(), "sphere", "environment");
    let both = render(dir.path(), "sphere", "both");
    assert_eq!(light[0], [0.0; 3], "the background under the light alone");
    assert!(env[0].iter().any(|&x| x > 0.0));
    assert_eq!(env[0], both[0], "the background is the environment's");
    // The centre of the sphere: lit by both sources, brighter than by either alone.
    let centre = 15 * 40 + 20;
    let sum = |p: [f64; 3]| p.iter().sum::<f64>();
    assert!(sum(both[centre]) > sum(light[centre]) && sum(both[centre]) > sum(env[centre]));
}
