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
    let out = dir.join(format!("{scene}-{lighting}.png"));
    let o = nacre(&[
        "render",
        "--scene",
        scene,
        "--width",
        "40",
        "--height",
        "30",
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
    for scene in ["cd-disc", "snake-skin", "grating-plane"] {
        let both = render(dir.path(), scene, "both");
        let light = render(dir.path(), scene, "light");
        let env = render(dir.path(), scene, "environment");
        let (mut worst, mut lit, mut env_lit, mut compared) = (0.0f64, 0usize, 0usize, 0usize);
        for ((b, l), e) in both.iter().zip(&light).zip(&env) {
            let (b, l, e) = (radiance(*b), radiance(*l), radiance(*e));
            lit += usize::from(l.iter().any(|&x| x > 0.01));
            env_lit += usize::from(e.iter().any(|&x| x > 0.01));
            for c in 0..3 {
                // One 8-bit step of each of the three pictures, in radiance.
                let step = 0.02 * (1.0 + b[c]) * (1.0 + b[c]);
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
