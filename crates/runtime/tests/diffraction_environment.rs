//! The environment diffracted through a "terms" table's lobes
//! (`nacre_runtime::diffraction::lobes`, `scene_env_diffracted` in
//! `shaders/diffraction_scene.wgsl`):
//!
//! * the lobes keep every bin's power: for each default-set table, the lobes' efficiencies
//!   plus the specular order's |P_DC|² add up to Σ_j |P_j|² = 1 (Parseval) at every kw sample,
//!   and a periodic grating's orders are sharp lobes where the grating equation puts them;
//! * GPU against CPU: the `grating-plane` scene's centre pixel under a uniform and under a
//!   two-colour environment (blue towards −z, red towards +z, blended by a smooth step over
//!   z ∈ [−0.3, 0.3], so that the first order changes colour along its spectrum and a lobe
//!   read in the wrong place reads the wrong colour) against the integral ∫ L_env ρ (σ_s k)²/π du dv of
//!   `DiffractionSurface::relative_reflectance` over the whole upper hemisphere, summed over
//!   the same wavelength grid, by brute force on the CPU.
//!
//! A missing adapter fails these tests: they never skip.

use nacre_format::set::default_baked_dir;
use nacre_optics::diffraction::{DiffractionSurface, FresnelTerm, SpectralGrid, k_per_um};
use nacre_runtime::diffraction::lobes::LOBE_KW_SAMPLES;
use nacre_runtime::diffraction::{
    DiffractionScene, DiffractionSceneOptions, DiffractionTable, DiffractionTables,
    EnvironmentLobes, render_diffraction_scene_in, wavelength_grid,
};
use nacre_runtime::render::EnvironmentMap;
use rayon::prelude::*;

mod support;
use support::ctx;

fn load(name: &str) -> DiffractionTables {
    let path = default_baked_dir().join(format!("{name}.json"));
    DiffractionTables::load(ctx(), &path, FresnelTerm::Unity).unwrap()
}

fn terms(tables: &DiffractionTables) -> &DiffractionTable {
    match tables {
        DiffractionTables::Terms(t) => t,
        DiffractionTables::Integrated(_) => panic!("not a terms table"),
    }
}

#[test]
fn lobes_keep_the_scattered_power() {
    for name in ["grating-1200", "snake-ridges", "cd-tracks"] {
        let tables = load(name);
        let t = terms(&tables);
        let lobes = EnvironmentLobes::new(&t.terms, &t.record).unwrap();
        let (nx, ny) = t.terms.size();
        let dc = (ny / 2) * nx + nx / 2;
        let sharp = lobes.lobes.iter().filter(|l| l.sharp).count();
        eprintln!(
            "{name}: {} lobes ({sharp} sharp), scattered {:.4}, captured {:.6}",
            lobes.lobes.len(),
            lobes.scattered,
            lobes.captured
        );
        assert!(lobes.lobes.len() <= nacre_runtime::diffraction::lobes::MAX_LOBES);
        assert!(
            lobes.captured >= (1.0 - 1e-3) * lobes.scattered,
            "{name}: the lobes carry {} of {}",
            lobes.captured,
            lobes.scattered
        );
        // Parseval at every sample: Σ lobes η + |P_DC|² = Σ_j |P_j|² = 1 within the Taylor
        // truncation (the tables' tolerance, 10⁻³) and the dropped lobes.
        let mut worst: f64 = 0.0;
        for s in 0..LOBE_KW_SAMPLES {
            let kw = lobes.kw_min * (1.0 - s as f64 / (LOBE_KW_SAMPLES - 1) as f64);
            let series = t.terms.series(kw);
            let total: f64 = series.iter().map(|p| p.norm_sqr()).sum();
            let kept: f64 =
                lobes.lobes.iter().map(|l| l.efficiency[s]).sum::<f64>() + series[dc].norm_sqr();
            worst = worst.max((kept - total).abs());
        }
        eprintln!("{name}: worst |Σ η + |P_DC|² − Σ|P_j|²| = {worst:.2e}");
        assert!(worst <= 2e-3, "{name}: {worst}");
    }
    // The 1200 lines/mm grating: its strongest lobes are the orders m = ±1 at κ = ±2π/d.
    let tables = load("grating-1200");
    let t = terms(&tables);
    let lobes = EnvironmentLobes::new(&t.terms, &t.record).unwrap();
    let first = 2.0 * std::f64::consts::PI / (1.0 / 1.2);
    for l in &lobes.lobes[..2] {
        assert!(l.sharp);
        // The recipe's period is 0.833333 µm (4 · 10⁻⁷ short of 1/1.2).
        assert!(
            (l.centre_per_um[0].abs() / first - 1.0).abs() < 1e-5 && l.centre_per_um[1] == 0.0,
            "{:?}",
            l.centre_per_um
        );
    }
}

/// The two colours: red towards world +z (towards the camera, across the grooves), blue
/// towards −z, blended by [`blend`].
const RED: [f64; 3] = [1.0, 0.25, 0.1];
const BLUE: [f64; 3] = [0.1, 0.3, 1.0];

/// The weight of red at world z: a smooth step over z ∈ [−0.3, 0.3] (smooth on the scale of
/// the environment's texels, 1.4°, so that the texture holds it).
fn blend(z: f64) -> f64 {
    let t = ((z + 0.3) / 0.6).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// An equirectangular environment of `colour(direction)` at its texel centres.
fn environment(colour: impl Fn([f64; 3]) -> [f64; 3]) -> EnvironmentMap {
    let (width, height) = (256, 128);
    let mut rgb = Vec::with_capacity(width * height);
    for j in 0..height {
        for i in 0..width {
            let d = nacre_runtime::ibl::env_uv_to_direction(
                (i as f64 + 0.5) / width as f64,
                (j as f64 + 0.5) / height as f64,
            );
            rgb.push(colour(d).map(|x| x as f32));
        }
    }
    EnvironmentMap { width, height, rgb }
}

/// The linear radiance of an sRGB8 pixel tone mapped c/(1 + max channel).
fn radiance(pixel: &[u8]) -> [f64; 3] {
    let lin = |c: u8| {
        let c = f64::from(c) / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let m = [lin(pixel[0]), lin(pixel[1]), lin(pixel[2])];
    let peak = m[0].max(m[1]).max(m[2]);
    let c_max = peak / (1.0 - peak);
    m.map(|x| x * (1.0 + c_max))
}

/// ∫ L_env(ω_i) ρ(ω_i, ω_r, λ) (σ_s k)²/π du dv over the upper hemisphere (du dv = the
/// projected solid angle of ω_i: (a, b) its tangential part, a = world z in the
/// grating-plane's frame), weighted by [`blend`]`(a)` and by 1 − [`blend`]`(a)`, per
/// wavelength of `grid`, as linear RGB of the table's output space: (red part, blue part).
fn cpu_integral(
    t: &DiffractionTable,
    grid: &SpectralGrid,
    omega_r: [f64; 3],
) -> ([f64; 3], [f64; 3]) {
    let surface = DiffractionSurface::new(t.terms.clone(), t.record.sigma_s_um).unwrap();
    let sigma = t.record.sigma_s_um;
    // The lobes lie along b = 0 (a one-row grating: its window along v is the Gaussian
    // exp(−σ_s²(kv)²), σ ≤ 0.011 at 780 nm); a step of 0.002 resolves the narrowest
    // (0.0053 at 380 nm) with the midpoint rule's spectral accuracy.
    let step = 0.002;
    let na = (2.0 / step) as i64;
    let nb = (0.1 / step) as i64;
    let per_wavelength: Vec<(f64, f64)> = grid
        .wavelengths_nm()
        .par_iter()
        .map(|&lambda| {
            let k = k_per_um(lambda);
            let gain = (sigma * k).powi(2) / std::f64::consts::PI * step * step;
            let (mut pos, mut neg) = (0.0, 0.0);
            for i in 0..na {
                let a = -1.0 + (i as f64 + 0.5) * step;
                for j in 0..nb {
                    let b = -0.05 + (j as f64 + 0.5) * step;
                    let s2 = a * a + b * b;
                    if s2 >= 1.0 {
                        continue;
                    }
                    let wi = [a, b, (1.0 - s2).sqrt()];
                    let rho = surface.relative_reflectance(wi, omega_r, lambda, FresnelTerm::Unity);
                    let w = blend(a);
                    pos += rho * gain * w;
                    neg += rho * gain * (1.0 - w);
                }
            }
            (pos, neg)
        })
        .collect();
    let colorimeter = t.colorimeter().unwrap();
    let rgb = |values: Vec<f64>| colorimeter.output_from_xyz(grid.xyz(&values));
    (
        rgb(per_wavelength.iter().map(|p| p.0).collect()),
        rgb(per_wavelength.iter().map(|p| p.1).collect()),
    )
}

#[test]
fn environment_diffraction_matches_the_cpu_integral() {
    let tables = load("grating-1200");
    let t = terms(&tables);
    let mut options = DiffractionSceneOptions::new(DiffractionScene::GratingPlane);
    // An odd size: the centre pixel's ray passes through the camera's target, the origin.
    (options.width, options.height) = (33, 33);
    options.light.intensity = 0.0;
    options.env_intensity = 1.0;
    options.technique.wavelength_step_nm = Some(20.0);
    let eye = options.camera.eye.map(f64::from);
    let len = (eye[0] * eye[0] + eye[1] * eye[1] + eye[2] * eye[2]).sqrt();
    // The grating frame: x across the grooves = world +z, y = n × x = world +x, z = n = +y.
    let omega_r = [eye[2] / len, eye[0] / len, eye[1] / len];
    let colorimeter = t.colorimeter().unwrap();
    let grid = SpectralGrid::new(
        &colorimeter,
        &wavelength_grid(&t.record, options.technique.wavelength_step_nm).unwrap(),
    )
    .unwrap();
    let (pos, neg) = cpu_integral(t, &grid, omega_r);
    let centre = |env: &EnvironmentMap| {
        let image = render_diffraction_scene_in(ctx(), &tables, &options, env).unwrap();
        let i = ((16 * 33 + 16) * 4) as usize;
        radiance(&image.pixels[i..i + 4])
    };
    let cases: [(&str, EnvironmentMap, [f64; 3]); 2] = [
        (
            "uniform",
            environment(|_| [1.0; 3]),
            std::array::from_fn(|c| pos[c] + neg[c]),
        ),
        (
            "two-colour",
            environment(|d| {
                std::array::from_fn(|c| RED[c] * blend(d[2]) + BLUE[c] * (1.0 - blend(d[2])))
            }),
            std::array::from_fn(|c| pos[c] * RED[c] + neg[c] * BLUE[c]),
        ),
    ];
    for (what, env, expected) in cases {
        let got = centre(&env);
        let scale = expected.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let error = (0..3).fold(0.0f64, |m, c| m.max((got[c] - expected[c]).abs())) / scale;
        eprintln!(
            "{what}: GPU {got:.4?}, CPU {expected:.4?}: largest difference {error:.4} of the largest channel"
        );
        assert!(error <= 0.02, "{what}: {error}");
    }
    // The red part is not negligible: the mirror image alone (blue) would fail.
    assert!(pos.iter().sum::<f64>() > 0.05, "no diffracted red: {pos:?}");
}
