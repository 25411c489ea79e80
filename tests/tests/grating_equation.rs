//! The grating equation holds in the rendered picture (issue 37): `nacre render --scene
//! grating-plane` — a flat 1200 lines/mm grating (`tables/recipes/grating-1200.toml`) under
//! its overhead directional light, the environment off — puts the first diffraction order
//! where ω_i·t + ω_r·t = mλ/d (Stam 1999: the peaks of |P̃(k u, k v)|² at u = mλ/d), measured
//! from the image's pixels alone:
//!
//! * every pixel is traced back through the scene's camera to its point on the plane, which
//!   gives its view direction ω_r and sin θ_r = ω_r·t (t = +z, across the grooves);
//! * a narrow-band bake of the same recipe (545–565 nm, the 5 nm grid) draws the order near
//!   555 nm only: the radiance-weighted mean angle θ_r of the lit pixels (radiance recovered
//!   from the sRGB bytes by inverting `output.wgsl`'s transfer and tone map) must sit within
//!   0.5° of asin(555 nm / d);
//! * with the full 380–780 nm table every lit pixel lies within the first order's span
//!   (sin θ_r from 380/833.3 to 780/833.3, widened by the coherence lobe), blue nearer the
//!   grating normal than red.
//!
//! The discs do the same along their circular tracks ([`disc_first_order`]): the CD
//! (`cd-disc`, d = 1.6 µm, under a light from beyond it) and the DVD (`dvd-disc`,
//! d = 0.74 µm, under the scene's own light, which brings its first orders onto the disc).
//!
//! A missing adapter fails the test: GPU tests never skip.

use nacre_optics::diffraction::FresnelTerm;
use nacre_runtime::diffraction::{
    DiffractionScene, DiffractionSceneOptions, DiffractionTables, render_diffraction_scene,
};
use std::path::Path;

#[path = "../../crates/runtime/tests/support/mod.rs"]
mod support;
use support::ctx;

/// The grating's period, µm (1/1200 mm).
const PERIOD_UM: f64 = 1.0 / 1.2;

/// One lit pixel: its point p on the surface (y = 0), the unit direction towards the eye,
/// sin θ_r = ω_r·t for the grating plane (t = +z), and its linear radiance (R, G, B) as
/// displayed.
struct Lit {
    p: [f64; 3],
    to_eye: [f64; 3],
    sin_theta_r: f64,
    rgb: [f64; 3],
}

/// sRGB byte → linear [0, 1] (IEC 61966-2-1).
fn linear(byte: u8) -> f64 {
    let c = f64::from(byte) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Renders `scene` (a flat one in y = 0: the grating plane or the CD) with `table` (light
/// only) at `width × height` and returns its lit pixels.
fn lit_pixels(
    scene: DiffractionScene,
    table: &DiffractionTables,
    width: u32,
    height: u32,
    light_direction: Option<[f32; 3]>,
) -> Vec<Lit> {
    let mut options = DiffractionSceneOptions::new(scene);
    if let Some(d) = light_direction {
        options.light.direction = d;
    }
    (options.width, options.height) = (width, height);
    options.env_intensity = 0.0;
    options.env_samples = Some(0);
    options.technique.wavelength_step_nm = None;
    let image = render_diffraction_scene(ctx(), table, &options).unwrap();
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "{}-{}.png",
        scene.name(),
        table.name()
    ));
    image.write_png(&out).unwrap();
    eprintln!("wrote {}", out.display());
    // The camera's rays, as shaders/diffraction_scene.wgsl builds them (WGSL columns).
    let m = options
        .camera
        .inverse_view_projection(f64::from(width) / f64::from(height))
        .unwrap();
    let apply = |v: [f64; 4]| -> [f64; 3] {
        let mut r = [0.0; 4];
        for (row, out) in r.iter_mut().enumerate() {
            *out = (0..4).map(|c| f64::from(m[c][row]) * v[c]).sum();
        }
        [r[0] / r[3], r[1] / r[3], r[2] / r[3]]
    };
    let eye = options.camera.eye.map(f64::from);
    let mut lit = Vec::new();
    for py in 0..height {
        for px in 0..width {
            let i = 4 * (py * width + px) as usize;
            let mapped = [0, 1, 2].map(|c| linear(image.pixels[i + c]));
            let top = mapped.iter().cloned().fold(0.0, f64::max);
            if top < 0.02 {
                continue;
            }
            // Undo the tone map c/(1 + max c): max c = m/(1 − m).
            let rgb = mapped.map(|x| x / (1.0 - top.min(0.999)));
            let ndc = [
                (f64::from(px) + 0.5) / f64::from(width) * 2.0 - 1.0,
                1.0 - (f64::from(py) + 0.5) / f64::from(height) * 2.0,
            ];
            let near = apply([ndc[0], ndc[1], 0.0, 1.0]);
            let far = apply([ndc[0], ndc[1], 1.0, 1.0]);
            let dir = [0, 1, 2].map(|k| far[k] - near[k]);
            let t = -near[1] / dir[1];
            let p = [0, 1, 2].map(|k| near[k] + t * dir[k]);
            assert!(
                p[0].abs() <= 1.0 + 1e-3 && p[2].abs() <= 1.0 + 1e-3,
                "pixel ({px}, {py}) is lit off the surface at {p:?}"
            );
            let to_eye = [0, 1, 2].map(|k| eye[k] - p[k]);
            let len = to_eye.iter().map(|x| x * x).sum::<f64>().sqrt();
            let to_eye = to_eye.map(|x| x / len);
            lit.push(Lit {
                p,
                to_eye,
                sin_theta_r: to_eye[2],
                rgb,
            });
        }
    }
    lit
}

fn bake(dir: &Path, name: &str, text: String) -> DiffractionTables {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, &text).unwrap();
    let recipe = nacre_bake::kinds::parse_recipe(&path, text).unwrap();
    let manifest = recipe.bake(dir, &|| {}).unwrap();
    DiffractionTables::load(ctx(), &manifest, FresnelTerm::Unity).unwrap()
}

#[test]
fn first_order_sits_where_the_grating_equation_puts_it() {
    let recipe = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../tables/recipes/grating-1200.toml"),
    )
    .unwrap();
    assert!(recipe.contains("wavelengths = \"380:780:5\""));
    let dir = tempfile::tempdir().unwrap();

    // Narrow band around 555 nm: the band's position.
    let narrow = bake(
        dir.path(),
        "grating-1200-narrow",
        recipe.replace("380:780:5", "545:565:5"),
    );
    let lit = lit_pixels(DiffractionScene::GratingPlane, &narrow, 320, 240, None);
    assert!(lit.len() >= 20, "{} lit pixels", lit.len());
    let weight = |l: &Lit| l.rgb.iter().sum::<f64>();
    let total: f64 = lit.iter().map(weight).sum();
    let mean_deg = lit
        .iter()
        .map(|l| weight(l) * l.sin_theta_r.asin().to_degrees())
        .sum::<f64>()
        / total;
    let theory_deg = (0.555 / PERIOD_UM).asin().to_degrees();
    eprintln!(
        "narrow band 545–565 nm: {} lit pixels, first order at θ_r = {mean_deg:.3}° (theory at 555 nm {theory_deg:.3}°, error {:.3}°)",
        lit.len(),
        mean_deg - theory_deg
    );
    assert!(
        (mean_deg - theory_deg).abs() <= 0.5,
        "first order at {mean_deg}°, theory {theory_deg}°"
    );

    // The full table: nothing lit outside the first order's span; blue before red.
    let full = DiffractionTables::load(
        ctx(),
        &nacre_format::set::default_baked_dir().join("grating-1200.json"),
        FresnelTerm::Unity,
    )
    .unwrap();
    let lit = lit_pixels(DiffractionScene::GratingPlane, &full, 320, 240, None);
    assert!(lit.len() >= 100, "{} lit pixels", lit.len());
    // The coherence window (32 µm) widens each wavelength's peak by ~λ/32 µm in sin θ_r.
    let (lo, hi) = (0.380 / PERIOD_UM - 0.03, 0.780 / PERIOD_UM + 0.03);
    let outside: Vec<f64> = lit
        .iter()
        .map(|l| l.sin_theta_r)
        .filter(|s| !(lo..=hi).contains(s))
        .collect();
    assert!(
        outside.is_empty(),
        "{} pixels lit outside the first order (sin θ_r {lo:.3} … {hi:.3}): {:?}",
        outside.len(),
        &outside[..outside.len().min(8)]
    );
    let centre = |c: usize| {
        let w: f64 = lit.iter().map(|l| l.rgb[c]).sum();
        lit.iter()
            .map(|l| l.rgb[c] * l.sin_theta_r.asin().to_degrees())
            .sum::<f64>()
            / w
    };
    let (red, green, blue) = (centre(0), centre(1), centre(2));
    eprintln!(
        "full table: {} lit pixels; channel centroids θ_r: blue {blue:.2}°, green {green:.2}°, red {red:.2}°",
        lit.len()
    );
    assert!(blue < green && green < red, "{blue} {green} {red}");
}

/// The radiance-weighted mean first-order angle asin|ω_i·t + ω_r·t| of a disc scene (the CD's
/// disc, circular tracks) rendered from a bake of `recipe` over the wavelengths `band_nm`
/// (its 5 nm grid) under `light` (the scene's own when `None`), and how many pixels it is
/// taken over: at every lit
/// pixel of the data area the tracks run in circles, so t is the radial direction of its
/// point and the grating equation reads |ω_i·t + ω_r·t| = mλ/d with ω_i·s + ω_r·s = 0 along
/// the tracks (s). The first-order pixels are those with |ω_i·s + ω_r·s| ≤ 0.02 (the orders
/// of the track pitch lie at 0 within the 32 µm window's lobe, ~λ/32 µm; elsewhere the light
/// is the pits' scatter along the tracks) and |ω_i·t + ω_r·t| in `first` (between the
/// zeroth and the second order).
fn disc_first_order(
    scene: DiffractionScene,
    recipe: &str,
    band_nm: [u32; 2],
    light: Option<[f32; 3]>,
    first: std::ops::RangeInclusive<f64>,
) -> (f64, usize) {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../tables/recipes/{recipe}.toml")),
    )
    .unwrap();
    assert!(text.contains("wavelengths = \"380:780:5\""));
    let dir = tempfile::tempdir().unwrap();
    let [lo, hi] = band_nm;
    let narrow = bake(
        dir.path(),
        &format!("{recipe}-{lo}-{hi}"),
        text.replace("380:780:5", &format!("{lo}:{hi}:5")),
    );
    let light_f32 = light.unwrap_or(DiffractionSceneOptions::new(scene).light.direction);
    let light = light_f32.map(f64::from);
    let len = light.iter().map(|x| x * x).sum::<f64>().sqrt();
    let omega_i = light.map(|x| x / len);
    let (mut weight, mut sum, mut count) = (0.0, 0.0, 0);
    for l in lit_pixels(scene, &narrow, 320, 240, Some(light_f32)) {
        let r = (l.p[0] * l.p[0] + l.p[2] * l.p[2]).sqrt();
        if !(0.38..=0.98).contains(&r) {
            continue;
        }
        let t = [l.p[0] / r, 0.0, l.p[2] / r];
        let along = [-t[2], 0.0, t[0]];
        let h = [0, 1, 2].map(|k| omega_i[k] + l.to_eye[k]);
        let u = (0..3).map(|k| h[k] * t[k]).sum::<f64>().abs();
        let v = (0..3).map(|k| h[k] * along[k]).sum::<f64>().abs();
        if v > 0.02 || !first.contains(&u) {
            continue;
        }
        let w = l.rgb.iter().sum::<f64>();
        weight += w;
        sum += w * u.asin().to_degrees();
        count += 1;
    }
    (sum / weight, count)
}

/// The CD (`nacre render --scene cd-disc`, a directional light only) of a 545–565 nm bake of
/// `tables/recipes/cd-tracks.toml`, d = 1.6 µm ([`disc_first_order`]): the first-order pixels
/// must put their radiance-weighted mean diffraction angle asin|ω_i·t + ω_r·t| within 0.5°
/// of asin(555 nm / 1.6 µm).
#[test]
fn the_cds_first_order_sits_where_the_grating_equation_puts_it() {
    // A light from beyond the disc (−z), 17.5° from the zenith: the 555 nm first order
    // crosses the near half of the data area (the scene's own light puts it off the disc).
    // Between the zeroth order (0) and the second (2λ/d ≈ 0.69).
    let d_um: f64 = 1.6;
    let (mean_deg, count) = disc_first_order(
        DiffractionScene::CdDisc,
        "cd-tracks",
        [545, 565],
        Some([0.0, 0.95, -0.3]),
        0.17..=0.52,
    );
    assert!(count >= 10, "{count} first-order pixels");
    let theory_deg = (0.555 / d_um).asin().to_degrees();
    eprintln!(
        "CD, 545–565 nm: {count} first-order pixels at {mean_deg:.3}° (theory at 555 nm {theory_deg:.3}°, error {:.3}°)",
        mean_deg - theory_deg
    );
    assert!(
        (mean_deg - theory_deg).abs() <= 0.5,
        "first order at {mean_deg}°, theory {theory_deg}°"
    );
}

/// The DVD (`nacre render --scene dvd-disc` under its own light, a directional light only),
/// d = 0.74 µm ([`disc_first_order`]): the scene's light puts the first order on the disc in
/// view, violet to green on the near half of the data area and orange to red on the far
/// half. Two bakes of `tables/recipes/dvd-tracks.toml`, 485–505 nm (the near half's middle)
/// and 645–665 nm (the far half's), must each put their first-order pixels' radiance-weighted
/// mean diffraction angle asin|ω_i·t + ω_r·t| within 0.5° of asin(λ / 0.74 µm) at the band's
/// centre (41.98° at 495 nm, 62.27° at 655 nm). (At 555 nm the order reaches the data area's
/// inner edge, which cuts its coherence lobe on one side: 1.7° short.)
#[test]
fn the_dvds_first_orders_sit_where_the_grating_equation_puts_them() {
    let d_um: f64 = 0.74;
    for band_nm in [[485, 505], [645, 665]] {
        // Between the zeroth order (0) and the second (2λ/d ≥ 1.3, beyond the view).
        let (mean_deg, count) = disc_first_order(
            DiffractionScene::DvdDisc,
            "dvd-tracks",
            band_nm,
            None,
            0.4..=1.2,
        );
        assert!(count >= 10, "{band_nm:?}: {count} first-order pixels");
        let centre_um = f64::from(band_nm[0] + band_nm[1]) / 2.0 * 1e-3;
        let theory_deg = (centre_um / d_um).asin().to_degrees();
        eprintln!(
            "DVD, {}–{} nm: {count} first-order pixels at {mean_deg:.3}° (theory at {:.0} nm {theory_deg:.3}°, error {:.3}°)",
            band_nm[0],
            band_nm[1],
            centre_um * 1e3,
            mean_deg - theory_deg
        );
        assert!(
            (mean_deg - theory_deg).abs() <= 0.5,
            "{band_nm:?}: first order at {mean_deg}°, theory {theory_deg}°"
        );
    }
}
