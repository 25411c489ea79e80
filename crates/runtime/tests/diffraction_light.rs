//! The directional light on a grating (`scene_shade` in `shaders/diffraction_scene.wgsl`, the
//! terms technique's `diffraction_colour_footprint`): the reflected radiance is Stam's BRDF
//! f = ρ (σ_s k)²/π times the irradiance the surface receives, E₀ cos θ_i, per wavelength —
//! what the Mitsuba reference (`nacre.mitsuba`, `nacre_grating`: `eval` = f cos θ at the
//! light) computes, so that a point-lit picture can match it.
//!
//! The `grating-plane` scene's centre pixel (the ray through the origin; no environment, the
//! footprint filter off so that the pixel is the BRDF at one pair of directions) under a
//! white directional light tilted across the grooves, against
//! E₀ Σ_λ `DiffractionSurface::relative_reflectance` (σ_s k)²/π cos θ_i u(λ) on the CPU over
//! the same wavelength grid. Three tilts put three orders in the pixel: the first order's
//! red (702 nm, where the light's former k at 555 nm for every wavelength read 1.6 × too
//! bright), the second order's blue (455 nm: 0.67 × too dark) and its green at cos θ_i =
//! 0.81 (the former missing cosine). Measured on lavapipe: largest difference 0.4 % of the
//! largest channel in each case (the 8-bit pixel's step); bound 2 % (the former light missed
//! by 60 %, 33 % and 23 %).
//!
//! A missing adapter fails this test: GPU tests never skip.

use nacre_optics::diffraction::{DiffractionSurface, FresnelTerm, SpectralGrid, k_per_um};
use nacre_runtime::diffraction::{
    DiffractionScene, DiffractionSceneOptions, DiffractionTables, render_diffraction_scene_in,
    wavelength_grid,
};
use nacre_runtime::render::EnvironmentMap;

mod support;
use support::{ctx, linear, manifest, radiance};

/// Scene size: odd, so that the centre pixel's ray passes through the camera's target.
const SIZE: u32 = 33;
/// The centre pixel's largest channel: the light's irradiance is set per case so that the
/// radiance sits there, in the tone map's near-linear range.
const PEAK: f64 = 0.5;

#[test]
fn the_light_reflects_stams_brdf_times_the_cosine() {
    let tables =
        DiffractionTables::load(ctx(), &manifest("grating-1200"), FresnelTerm::Unity).unwrap();
    let DiffractionTables::Terms(t) = &tables else {
        panic!("grating-1200 is a terms table");
    };
    let surface = DiffractionSurface::new(t.terms.clone(), t.record.sigma_s_um).unwrap();
    let sigma = t.record.sigma_s_um;
    let mut options = DiffractionSceneOptions::new(DiffractionScene::GratingPlane);
    (options.width, options.height) = (SIZE, SIZE);
    options.env_intensity = 0.0;
    options.env_samples = Some(0);
    options.exposure_ev = 0.0;
    options.technique.wavelength_step_nm = Some(5.0);
    options.technique.filter_radius = None;
    options.light.colour = [1.0; 3];
    let eye = options.camera.eye.map(f64::from);
    let len = (eye[0] * eye[0] + eye[1] * eye[1] + eye[2] * eye[2]).sqrt();
    // The grating frame: x across the grooves = world +z, y = world +x, z = n = +y.
    let omega_r = [eye[2] / len, eye[0] / len, eye[1] / len];
    let colorimeter = t.colorimeter().unwrap();
    let grid = SpectralGrid::new(
        &colorimeter,
        &wavelength_grid(&t.record, options.technique.wavelength_step_nm).unwrap(),
    )
    .unwrap();
    let env = EnvironmentMap {
        width: 1,
        height: 1,
        rgb: vec![[0.0; 3]],
    };
    // ω_i's component across the grooves: (u, v) = −(ω_i + ω_r)_t puts order m at
    // λ = −u d/m, d = 0.8333 µm, ω_r,x = 0.743.
    for (what, a) in [
        ("first order, 702 nm", 0.10),
        ("second order, 455 nm", 0.35),
        ("second order, 555 nm, cos θ_i 0.81", 0.589),
    ] {
        let cos_i = (1.0f64 - a * a).sqrt();
        let omega_i = [a, 0.0, cos_i];
        options.light.direction = [0.0, cos_i as f32, a as f32];
        let values: Vec<f64> = grid
            .wavelengths_nm()
            .iter()
            .map(|&lambda| {
                let rho =
                    surface.relative_reflectance(omega_i, omega_r, lambda, FresnelTerm::Unity);
                let f = rho * (sigma * k_per_um(lambda)).powi(2) / std::f64::consts::PI;
                f * cos_i
            })
            .collect();
        // Per unit irradiance; the scene clamps negative (out-of-gamut) channels before its
        // tone map.
        let unit = colorimeter
            .output_from_xyz(grid.xyz(&values))
            .map(|c| c.max(0.0));
        let top = unit.iter().fold(0.0f64, |m, x| m.max(*x));
        assert!(top > 0.0, "{what}: no light in the centre pixel ({unit:?})");
        let irradiance = (PEAK / top) as f32;
        options.light.intensity = irradiance;
        let expected = unit.map(|c| c * f64::from(irradiance));
        let image = render_diffraction_scene_in(ctx(), &tables, &options, &env).unwrap();
        let i = (((SIZE / 2) * SIZE + SIZE / 2) * 4) as usize;
        let p = &image.pixels[i..i + 3];
        let got = radiance([linear(p[0]), linear(p[1]), linear(p[2])]);
        let scale = expected.iter().fold(0.0f64, |m, x| m.max(*x));
        let error = (0..3).fold(0.0f64, |m, c| m.max((got[c] - expected[c]).abs())) / scale;
        eprintln!(
            "{what} (E₀ {irradiance:.3e}): GPU {got:.4?}, CPU f E₀ cos θ_i {expected:.4?}: largest difference {error:.4} of the largest channel"
        );
        assert!(error <= 0.02, "{what}: {error}");
    }
}
