//! Rough iridescent spheres against a Monte Carlo reference (issue 6; `shaders/material.wgsl`
//! split-sum paths, `nacre_runtime::rough_reference`):
//!
//! * the committed references `tests/golden/rough/sphere-alpha*.exr` (linear radiance, float
//!   OpenEXR, 96 × 96) are reproduced exactly by the integrator, checked on a sample of
//!   pixels (the whole image takes ~1 min on 2 cores); `NACRE_UPDATE_GOLDEN=1` recomputes and
//!   rewrites them, printing the time and the noise level;
//! * on the GPU (lavapipe without one; fails, never skips, without an adapter), the same
//!   sphere rendered to a linear float target by the exact path (`FilmEval::Exact`) and by the
//!   film-at-n·v shortcut (`FilmEval::NormalView`) is compared with the reference by mean
//!   CIEDE2000 over the sphere's pixels: the exact path must stay within
//!   [`EXACT_MEAN_DE_MAX`] = 1.0 (issue 6's target) at every α, and the shortcut must be
//!   [`EXACT_GAIN_MIN`] times worse at α ≥ 0.3; both figures are printed;
//! * on request (`cargo test --release -p nacre-runtime --test rough -- --ignored`), a CPU
//!   twin of the exact path's environment estimator with the exact film term, swept over
//!   the number of lobe samples: how the README's figures for 16, 32, 64 and 1024 samples
//!   were measured.

use nacre_runtime::render::{FilmEval, RenderOutput, Renderer, procedural_thickness_map};
use nacre_runtime::rough_reference::{
    COMPARISON_ALPHAS, COMPARISON_SAMPLES, COMPARISON_SEED, COMPARISON_SIZE, ReferenceScene,
    camera_rays, comparison_environment, comparison_options, film_term_of, hit_sphere,
    mean_delta_e_2000, read_linear_exr, render_reference, render_reference_pixels,
    write_linear_exr,
};
use nacre_runtime::{TableSet, Technique};
use std::f64::consts::PI;
use std::path::PathBuf;

mod support;
use support::ctx;

/// Largest mean ΔE2000 of the exact path against the reference at any α: issue 6's target.
/// Measured on lavapipe (llvmpipe, Mesa 22.3.6): 0.74 / 0.71 / 0.80 at α = 0.1 / 0.3 / 0.6
/// (README).
const EXACT_MEAN_DE_MAX: f64 = 1.0;

/// Smallest ratio shortcut ΔE / exact ΔE at α ≥ 0.3 (measured 11.4 and 15.6 on lavapipe).
const EXACT_GAIN_MIN: f64 = 5.0;

fn golden_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/golden/rough")
}

fn golden_path(alpha: f64) -> PathBuf {
    golden_dir().join(format!("sphere-alpha{alpha:.2}.exr"))
}

fn updating() -> bool {
    std::env::var("NACRE_UPDATE_GOLDEN").is_ok_and(|v| v == "1")
}

fn tables() -> TableSet {
    let baked = nacre_format::set::default_baked_dir();
    let mut t = TableSet::load(ctx(), &baked.join("film-dielectric.json")).unwrap();
    // NACRE_ROUGH_TABLE=PATH.json measures another rough-film-lut (e.g. one baked elsewhere).
    let rough = std::env::var_os("NACRE_ROUGH_TABLE")
        .map(PathBuf::from)
        .unwrap_or_else(|| baked.join("rough-film-dielectric.json"));
    t.add(ctx(), &rough)
        .unwrap_or_else(|e| panic!("the exact path needs the default rough-film-lut: {e}"));
    t
}

fn colorimeter() -> nacre_optics::colour::Colorimeter {
    let baked = nacre_format::set::default_baked_dir();
    let path = baked.join("film-dielectric.json");
    nacre_format::Manifest::read(&path)
        .unwrap()
        .colorimeter(&path)
        .unwrap()
}

/// The sphere's pixels (centre ray hits it).
fn mask() -> Vec<bool> {
    let o = comparison_options(0.1, FilmEval::Exact, COMPARISON_SIZE);
    camera_rays(&o.camera, o.width, o.height)
        .unwrap()
        .iter()
        .map(|r| hit_sphere(r).is_some())
        .collect()
}

#[test]
fn references_are_reproduced() {
    let env = comparison_environment();
    let c = colorimeter();
    for alpha in COMPARISON_ALPHAS {
        let options = comparison_options(alpha as f32, FilmEval::Exact, COMPARISON_SIZE);
        let path = golden_path(alpha);
        if updating() {
            let start = std::time::Instant::now();
            let film = film_term_of(&options, &c).unwrap();
            let scene = ReferenceScene {
                camera: options.camera,
                width: options.width,
                height: options.height,
                film: &film,
                alpha,
                light: options.light,
                environment: &env,
                env_intensity: f64::from(options.env_intensity),
            };
            let image = render_reference(&scene, COMPARISON_SAMPLES, COMPARISON_SEED).unwrap();
            eprintln!(
                "α {alpha}: {} samples per pixel in {:.1} s, mean relative standard error {:.2e}",
                COMPARISON_SAMPLES,
                start.elapsed().as_secs_f64(),
                image.mean_relative_error()
            );
            std::fs::create_dir_all(golden_dir()).unwrap();
            write_linear_exr(&path, image.width, image.height, &image.rgb).unwrap();
        }
        let (w, h, stored) = read_linear_exr(&path).unwrap_or_else(|e| {
            panic!("{e} (NACRE_UPDATE_GOLDEN=1 cargo test -p nacre-runtime --test rough regenerates it)")
        });
        assert_eq!((w, h), (COMPARISON_SIZE, COMPARISON_SIZE));
        // Every 97th pixel, recomputed with the same per-pixel streams: bit-identical.
        let film = film_term_of(&options, &c).unwrap();
        let scene = ReferenceScene {
            camera: options.camera,
            width: options.width,
            height: options.height,
            film: &film,
            alpha,
            light: options.light,
            environment: &env,
            env_intensity: f64::from(options.env_intensity),
        };
        let pixels: Vec<usize> = (0..(w * h) as usize).step_by(97).collect();
        let again =
            render_reference_pixels(&scene, &pixels, COMPARISON_SAMPLES, COMPARISON_SEED).unwrap();
        for (&p, got) in pixels.iter().zip(&again) {
            assert_eq!(*got, stored[p], "α {alpha}, pixel {p}");
        }
    }
}

#[test]
fn exact_path_matches_the_reference() {
    let tables = tables();
    let c = tables.colorimeter().unwrap();
    let env = comparison_environment();
    let thickness = procedural_thickness_map(16);
    let base = comparison_options(0.1, FilmEval::Exact, COMPARISON_SIZE);
    let renderer = Renderer::new_with_output(
        ctx(),
        &tables,
        Technique::Lut,
        &base.technique_options(),
        RenderOutput::Linear,
    )
    .unwrap();
    let mask = mask();
    let out_dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("rough");
    std::fs::create_dir_all(&out_dir).unwrap();
    let mut failures = Vec::new();
    for alpha in COMPARISON_ALPHAS {
        let (_, _, reference) = read_linear_exr(&golden_path(alpha)).unwrap();
        let mut row = Vec::new();
        for eval in [FilmEval::Exact, FilmEval::NormalView] {
            let options = comparison_options(alpha as f32, eval, COMPARISON_SIZE);
            let image = renderer
                .render_linear_with(ctx(), &tables, &options, &env, &thickness)
                .unwrap();
            let de = mean_delta_e_2000(&image.rgb, &reference, &mask, &c);
            let path = out_dir.join(format!("sphere-alpha{alpha:.2}-{}.exr", eval.name()));
            write_linear_exr(&path, image.width, image.height, &image.rgb).unwrap();
            write_strip(&path.with_extension("png"), &image.rgb, &reference);
            row.push((eval, de));
            if eval == FilmEval::Exact && de > EXACT_MEAN_DE_MAX {
                failures.push(format!(
                    "α {alpha}: exact path mean ΔE2000 {de:.3} > {EXACT_MEAN_DE_MAX} (image: {})",
                    path.display()
                ));
            }
        }
        eprintln!(
            "α {alpha}: mean ΔE2000 vs Monte Carlo — exact {:.3}, film at n·v {:.3}",
            row[0].1, row[1].1
        );
        if alpha >= 0.3 && row[1].1 < EXACT_GAIN_MIN * row[0].1 {
            failures.push(format!(
                "α {alpha}: the shortcut's ΔE {:.3} is not {EXACT_GAIN_MIN} times the exact path's {:.3}",
                row[1].1, row[0].1
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A PNG beside a failure artefact: the GPU image, the reference and |difference| × 4, each
/// tone-mapped as `nacre render` does.
fn write_strip(path: &std::path::Path, gpu: &[[f32; 3]], reference: &[[f32; 3]]) {
    use nacre_runtime::render::RenderedImage;
    use nacre_runtime::rough_reference::display_colour;
    let n = COMPARISON_SIZE as usize;
    let mut pixels = vec![0u8; 3 * n * n * 4];
    for y in 0..n {
        for x in 0..n {
            let (a, b) = (gpu[y * n + x], reference[y * n + x]);
            let d: [f32; 3] = std::array::from_fn(|k| 4.0 * (a[k] - b[k]).abs());
            for (i, c) in [a, b, d].into_iter().enumerate() {
                let e = display_colour(c.map(f64::from));
                let at = (y * 3 * n + i * n + x) * 4;
                pixels[at..at + 3].copy_from_slice(&e);
                pixels[at + 3] = 255;
            }
        }
    }
    let image = RenderedImage {
        width: 3 * n as u32,
        height: n as u32,
        pixels,
        gpu_seconds: 0.0,
    };
    image.write_png(path).unwrap();
}

/// One CPU twin of the exact path's environment estimator (`shaders/material.wgsl`, header):
/// `samples` visible normals on a Fibonacci spiral (`grid`: a √N × √N grid of midpoints),
/// each read from the prefiltered layers at α_i = `fis_scale` √(Ω_i/(4π)) (`None`: at α/2,
/// the previous version), normalised by the rough-film-lut albedo.
struct LobeEstimator {
    samples: usize,
    grid: bool,
    fis_scale: Option<f64>,
}

/// Mean ΔE2000 of [`LobeEstimator`] + the directional light (closed form, as the reference)
/// against the committed reference at `alpha`.
fn twin_delta_e(estimator: &LobeEstimator, alpha: f64) -> f64 {
    use nacre_format::load::LoadedRoughLut;
    use nacre_format::rough_film_lut::RoughFilmLut;
    use nacre_optics::microfacet::{ggx_d, radiance_directional, sample_ggx_vndf, smith_lambda};
    use nacre_runtime::ibl::{
        PREFILTER_LEVELS, PrefilteredEnvironment, env_direction_to_uv, sample_level_bilinear,
        tangent_frame,
    };
    use nacre_runtime::rough_reference::{COMPARISON_FILM_IOR, COMPARISON_THICKNESS_NM};
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let c = colorimeter();
    let baked = nacre_format::set::default_baked_dir();
    let rough = LoadedRoughLut::load(&baked.join("rough-film-dielectric.json")).unwrap();
    let env = comparison_environment();
    let pre = PrefilteredEnvironment::cached(&env);
    let o = comparison_options(alpha as f32, FilmEval::Exact, COMPARISON_SIZE);
    let scale = f64::from(o.env_intensity);
    // L̃(d, α) as env_prefiltered_radiance samples it.
    let prefiltered = |d: [f64; 3], a: f64| -> [f64; 3] {
        let (u, v) = env_direction_to_uv(d);
        let last = (PREFILTER_LEVELS - 1) as f64;
        let k = (a.clamp(0.0, 1.0).sqrt() * last).clamp(0.0, last);
        let k0 = (k.floor() as usize).min(PREFILTER_LEVELS - 2);
        let f = k - k0 as f64;
        let lo = sample_level_bilinear(&pre.levels[k0], u, v);
        let hi = sample_level_bilinear(&pre.levels[k0 + 1], u, v);
        std::array::from_fn(|i| (lo[i] * (1.0 - f) + hi[i] * f) * scale)
    };
    let n = estimator.samples;
    let points: Vec<(f64, f64)> = if estimator.grid {
        let m = (n as f64).sqrt().round() as usize;
        let mid = |i: usize| (i as f64 + 0.5) / m as f64;
        (0..m * m).map(|i| (mid(i % m), mid(i / m))).collect()
    } else {
        let g = 0.5 * (3.0 - 5f64.sqrt());
        (0..n)
            .map(|i| ((i as f64 + 0.5) / n as f64, (i as f64 * g).fract()))
            .collect()
    };
    let film = film_term_of(&o, &c).unwrap();
    let light = o.light.direction.map(f64::from);
    let light = light.map(|x| x / dot(light, light).sqrt());
    let e_l: [f64; 3] =
        std::array::from_fn(|k| f64::from(o.light.colour[k]) * f64::from(o.light.intensity));
    let rays = camera_rays(&o.camera, o.width, o.height).unwrap();
    let image: Vec<[f32; 3]> = rays
        .iter()
        .map(|ray| {
            let Some(normal) = hit_sphere(ray) else {
                return [0.0; 3];
            };
            let (t, b) = tangent_frame(normal);
            let to_local = |w: [f64; 3]| [dot(w, t), dot(w, b), dot(w, normal)];
            let to_world = |w: [f64; 3]| -> [f64; 3] {
                std::array::from_fn(|k| w[0] * t[k] + w[1] * b[k] + w[2] * normal[k])
            };
            let mut wo = to_local(ray.dir.map(|x| -x));
            wo[2] = wo[2].max(1e-4);
            let wo = wo.map(|x| x / dot(wo, wo).sqrt());
            let lambda_o = smith_lambda(wo, alpha);
            let e_f = RoughFilmLut::lookup(
                &rough.lut.axes,
                &rough.lut.reflectance,
                wo[2],
                alpha,
                f64::from(COMPARISON_THICKNESS_NM),
                f64::from(COMPARISON_FILM_IOR),
            );
            let (mut num, mut den) = ([0.0f64; 3], [0.0f64; 3]);
            for &(u1, u2) in &points {
                let m = sample_ggx_vndf(wo, alpha, u1, u2);
                let cos_d = dot(wo, m);
                let wi: [f64; 3] = std::array::from_fn(|k| 2.0 * cos_d * m[k] - wo[k]);
                if wi[2] <= 0.0 || cos_d <= 0.0 {
                    continue;
                }
                let w = (1.0 + lambda_o) / (1.0 + lambda_o + smith_lambda(wi, alpha));
                let a_i = match estimator.fis_scale {
                    None => 0.5 * alpha,
                    Some(k) => {
                        k * (wo[2] * (1.0 + lambda_o) / (PI * n as f64 * ggx_d(m, alpha))).sqrt()
                    }
                };
                let r = film.reflectance_colour(cos_d);
                let l = prefiltered(to_world(wi), a_i);
                for k in 0..3 {
                    num[k] += w * r[k] * l[k];
                    den[k] += w * r[k];
                }
            }
            let direct = radiance_directional(&film, alpha, wo, to_local(light), 1.0);
            std::array::from_fn(|k| {
                let env = if den[k] > 1e-8 {
                    e_f[k] * num[k] / den[k]
                } else {
                    0.0
                };
                (env + direct[k] * e_l[k]) as f32
            })
        })
        .collect();
    let (_, _, reference) = read_linear_exr(&golden_path(alpha)).unwrap();
    mean_delta_e_2000(&image, &reference, &mask(), &c)
}

/// The README's sample-count sweep (CPU, ≈ 1 min in release): the error falls with the
/// number of lobe samples, and 32 spiral samples with filtered importance sampling (the
/// shader's choice) meet issue 6's target at every α.
#[test]
#[ignore = "a measurement on request: cargo test --release -p nacre-runtime --test rough -- --ignored"]
fn lobe_sample_count_sweep() {
    let cases = [
        (
            "16, 4 × 4 grid, α/2 (previous)",
            LobeEstimator {
                samples: 16,
                grid: true,
                fis_scale: None,
            },
        ),
        (
            "16, 4 × 4 grid, FIS k = 1",
            LobeEstimator {
                samples: 16,
                grid: true,
                fis_scale: Some(1.0),
            },
        ),
        (
            "32, spiral, FIS k = 0.7 (shader)",
            LobeEstimator {
                samples: 32,
                grid: false,
                fis_scale: Some(0.7),
            },
        ),
        (
            "64, spiral, FIS k = 0.7",
            LobeEstimator {
                samples: 64,
                grid: false,
                fis_scale: Some(0.7),
            },
        ),
        (
            "1024, spiral, FIS k = 0.7",
            LobeEstimator {
                samples: 1024,
                grid: false,
                fis_scale: Some(0.7),
            },
        ),
    ];
    for alpha in COMPARISON_ALPHAS {
        let de: Vec<f64> = cases.iter().map(|(_, e)| twin_delta_e(e, alpha)).collect();
        for ((name, _), d) in cases.iter().zip(&de) {
            eprintln!("α {alpha}: {name}: mean ΔE2000 {d:.3}");
        }
        assert!(de[2] <= EXACT_MEAN_DE_MAX, "α {alpha}: {:.3}", de[2]);
        assert!(
            de[4] < de[3] && de[3] < de[2] && de[2] < de[0],
            "α {alpha}: {de:?}"
        );
    }
}
