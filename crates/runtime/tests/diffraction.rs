//! The `diffraction` technique (`nacre_runtime::diffraction`, `shaders/diffraction.wgsl`):
//!
//! * GPU = CPU: the compute probe against `DiffractionSurface::relative_reflectance` summed
//!   over the same `SpectralGrid`, for the default set's CD and ridge tables, over in-plane
//!   sweeps that cross the grating orders and random out-of-plane directions;
//! * bad directions (NaN, ±∞, huge, zero, below the horizon) give finite colours;
//! * the loaders check kind, layout and SHA-256, and `DiffractionTables::load` dispatches on
//!   the layout;
//! * the `cd-disc`, `dvd-disc`, `snake-skin` and `grating-plane` scenes are deterministic and
//!   show diffraction colours (saturated pixels whose hue spans the rainbow), which the
//!   specular order alone cannot;
//! * the `cd-disc` scene from the integrated table `cd-tracks-fast` (the fast path) matches
//!   the one from the terms table `cd-tracks` of the same surface, rainbow included.
//!
//! A missing adapter fails these tests: they never skip.

use nacre_format::set::default_baked_dir;
use nacre_optics::C64;
use nacre_optics::diffraction::{DiffractionSurface, FresnelTerm, in_plane_directions};
use nacre_runtime::diffraction::{
    DEFAULT_ENV_SAMPLES, DiffractionBinding, DiffractionLayout, DiffractionOptions,
    DiffractionScene, DiffractionSceneOptions, DiffractionTable, DiffractionTables,
    render_diffraction_scene, run_probe,
};
use rayon::prelude::*;
use std::sync::OnceLock;

mod support;
use support::ctx;

/// A default-set table through the dispatching loader (an integrated one with F² = 1, the
/// `cd-disc` scene's).
fn tables(name: &str) -> &'static DiffractionTables {
    static CD: OnceLock<DiffractionTables> = OnceLock::new();
    static CD_FAST: OnceLock<DiffractionTables> = OnceLock::new();
    static RIDGES: OnceLock<DiffractionTables> = OnceLock::new();
    static GRATING: OnceLock<DiffractionTables> = OnceLock::new();
    static DVD: OnceLock<DiffractionTables> = OnceLock::new();
    let cell = match name {
        "cd-tracks" => &CD,
        "cd-tracks-fast" => &CD_FAST,
        "snake-ridges" => &RIDGES,
        "grating-1200" => &GRATING,
        "dvd-tracks" => &DVD,
        other => panic!("no table {other}"),
    };
    cell.get_or_init(|| {
        let path = default_baked_dir().join(format!("{name}.json"));
        DiffractionTables::load(ctx(), &path, FresnelTerm::Unity).unwrap()
    })
}

/// A default-set table of layout "terms".
fn table(name: &str) -> &'static DiffractionTable {
    match tables(name) {
        DiffractionTables::Terms(t) => t,
        DiffractionTables::Integrated(_) => panic!("{name} is not a terms table"),
    }
}

/// Deterministic uniform numbers in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// In-plane sweeps (incidences 0°, 20°, 40°; views −45° … 45° every 0.25°, crossing the
/// orders m = −2 … 2 of the 1.6 µm tracks) and `random` directions within 45° of the normal.
fn directions(random: usize) -> Vec<([f64; 3], [f64; 3])> {
    let mut pairs = Vec::new();
    for incidence in [0.0, 20.0, 40.0] {
        for i in 0..=360 {
            pairs.push(in_plane_directions(incidence, -45.0 + 0.25 * f64::from(i)));
        }
    }
    let mut rng = Lcg(11);
    let dir = |rng: &mut Lcg| {
        let theta = (rng.next() * 45.0).to_radians();
        let phi = rng.next() * std::f64::consts::TAU;
        [
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ]
    };
    for _ in 0..random {
        let wi = dir(&mut rng);
        // Views near the specular direction and anywhere.
        let wr = if rng.next() < 0.5 {
            let s = [-wi[0], -wi[1], wi[2]];
            let j = dir(&mut rng);
            let m = [s[0] + 0.05 * j[0], s[1] + 0.05 * j[1], s[2]];
            let l = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
            m.map(|x| x / l)
        } else {
            dir(&mut rng)
        };
        pairs.push((wi, wr));
    }
    pairs
}

/// Max |GPU − CPU| over channels and the pair where it occurs, and the largest CPU channel.
fn compare(
    name: &str,
    options: &DiffractionOptions,
    pairs: &[([f64; 3], [f64; 3])],
) -> (f64, f64, f64) {
    let ctx = ctx();
    let table = table(name);
    let binding = DiffractionBinding::new(ctx, table, options).unwrap();
    let colorimeter = table.colorimeter().unwrap();
    let surface = DiffractionSurface::new(table.terms.clone(), table.record.sigma_s_um).unwrap();
    let grid = &binding.grid;
    let f32s = |v: [f64; 3]| v.map(|x| x as f32);
    let gpu = run_probe(
        ctx,
        &binding,
        &pairs
            .iter()
            .map(|(i, r)| (f32s(*i), f32s(*r)))
            .collect::<Vec<_>>(),
    )
    .unwrap();
    let cpu: Vec<([f64; 3], [f64; 3])> = pairs
        .par_iter()
        .map(|(wi, wr)| {
            // The CPU sees the same f32-rounded directions as the GPU.
            let (wi, wr) = (
                wi.map(|x| f64::from(x as f32)),
                wr.map(|x| f64::from(x as f32)),
            );
            let rho: Vec<f64> = grid
                .wavelengths_nm()
                .iter()
                .map(|&l| surface.relative_reflectance(wi, wr, l, options.fresnel))
                .collect();
            let colour = colorimeter.output_from_xyz(grid.xyz(&rho));
            // The specular order at cos θ = ω_r.z: F² |P_DC(k w)|², w = −2 cos θ.
            let c = wr[2].clamp(0.0, 1.0);
            let spec: Vec<f64> = grid
                .wavelengths_nm()
                .iter()
                .map(|&l| {
                    if c <= 0.0 {
                        return 0.0;
                    }
                    let kw = -2.0 * c * std::f64::consts::TAU / (l * 1e-3);
                    let mut term = 1.0;
                    let mut p = C64::new(0.0, 0.0);
                    for n in 0..=table.terms.order() {
                        if n > 0 {
                            term *= kw / n as f64;
                        }
                        p += table.terms.bin(n, 0, 0).unwrap() * term;
                    }
                    options.fresnel.reflectance(c) * p.norm_sqr()
                })
                .collect();
            (colour, colorimeter.output_from_xyz(grid.xyz(&spec)))
        })
        .collect();
    let (mut worst, mut worst_spec, mut peak) = (0.0f64, 0.0f64, 0.0f64);
    let mut at = 0;
    for (k, (g, (c, s))) in gpu.iter().zip(&cpu).enumerate() {
        for ch in 0..3 {
            let d = (f64::from(g.colour[ch]) - c[ch]).abs();
            if d.is_nan() || d > worst {
                worst = d;
                at = k;
            }
            worst_spec = worst_spec.max((f64::from(g.specular_order[ch]) - s[ch]).abs());
            peak = peak.max(c[ch].abs());
        }
    }
    eprintln!(
        "{name} ({} wavelengths, {:?}): {} pairs, max |GPU − CPU| = {worst:.2e} at {:?} (GPU {:?}, CPU {:?}); specular order {worst_spec:.2e}; largest channel {peak:.3}",
        grid.wavelengths_nm().len(),
        options.fresnel,
        pairs.len(),
        pairs[at],
        gpu[at].colour,
        cpu[at].0
    );
    (worst, worst_spec, peak)
}

// Tolerances, set on Mesa lavapipe (llvmpipe, LLVM 15, Mesa 22.3.6), which measured
// 3.6 · 10⁻⁶ (colour) and 5.0 · 10⁻⁷ (specular order) for cd-tracks: the shader drops
// window weights ≤ 4.5 · 10⁻⁴ (R = 2 for both tables) where the CPU keeps every weight
// ≥ 10⁻¹⁰, and sums the Taylor series in f32 (rounding ≲ 10⁻⁶ · e^{max |kwh|}); colours are
// O(1) at the specular peak (the largest channel of the sweep is printed).
const COLOUR_TOLERANCE: f64 = 2e-5;
const SPECULAR_ORDER_TOLERANCE: f64 = 5e-6;

#[test]
fn cd_tracks_gpu_matches_the_cpu() {
    let pairs = directions(400);
    let (worst, spec, peak) = compare("cd-tracks", &DiffractionOptions::default(), &pairs);
    assert!(peak > 0.1, "the sweep never reaches a bright order: {peak}");
    assert!(worst <= COLOUR_TOLERANCE, "{worst:e}");
    assert!(spec <= SPECULAR_ORDER_TOLERANCE, "{spec:e}");
    // A coarser grid (10 nm, its own weights) and a Fresnel factor of an aluminium-like index.
    let options = DiffractionOptions {
        wavelength_step_nm: Some(10.0),
        fresnel: FresnelTerm::Index(C64::new(1.2, 7.0)),
        ..DiffractionOptions::default()
    };
    let (worst, spec, _) = compare("cd-tracks", &options, &pairs[..600]);
    assert!(worst <= COLOUR_TOLERANCE, "{worst:e}");
    assert!(spec <= SPECULAR_ORDER_TOLERANCE, "{spec:e}");
}

#[test]
fn ridge_grating_gpu_matches_the_cpu() {
    let pairs = directions(400);
    let (worst, spec, peak) = compare("snake-ridges", &DiffractionOptions::default(), &pairs);
    assert!(peak > 0.1, "the sweep never reaches a bright order: {peak}");
    assert!(worst <= COLOUR_TOLERANCE, "{worst:e}");
    assert!(spec <= SPECULAR_ORDER_TOLERANCE, "{spec:e}");
}

#[test]
fn bad_directions_give_finite_colours() {
    let ctx = ctx();
    let binding =
        DiffractionBinding::new(ctx, table("cd-tracks"), &DiffractionOptions::default()).unwrap();
    let specials = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::MAX,
        -f32::MAX,
        1e30,
        -1e30,
        1e-38,
        0.0,
        -0.0,
        -1.0,
        1.0,
        0.5,
    ];
    let mut pairs = Vec::new();
    for &a in &specials {
        for &b in &specials {
            pairs.push(([a, b, 1.0], [0.3, 0.0, b]));
            pairs.push(([0.1, a, b], [a, 0.2, 0.9]));
            pairs.push(([a, a, a], [b, b, b]));
        }
    }
    let out = run_probe(ctx, &binding, &pairs).unwrap();
    for ((wi, wr), o) in pairs.iter().zip(&out) {
        for v in o.colour.iter().chain(&o.specular_order) {
            assert!(v.is_finite(), "{wi:?}, {wr:?} -> {o:?}: not finite");
        }
    }
    // Huge but valid directions are the unit ones.
    let unit = run_probe(ctx, &binding, &[([-0.2, 0.0, 0.9], [0.2, 0.0, 0.9])]).unwrap();
    let huge = run_probe(ctx, &binding, &[([-2e37, 0.0, 9e37], [2e37, 0.0, 9e37])]).unwrap();
    for c in 0..3 {
        assert!((unit[0].colour[c] - huge[0].colour[c]).abs() <= 1e-5 * unit[0].colour[c].max(1.0));
    }
}

#[test]
fn loader_checks_kind_layout_and_checksums() {
    let ctx = ctx();
    let baked = default_baked_dir();
    let err = DiffractionTable::load(ctx, &baked.join("film-dielectric.json"))
        .err()
        .expect("a film-lut table is not a diffraction table");
    assert!(
        err.to_string().contains("not a `diffraction` table"),
        "{err}"
    );

    let dir = tempfile::tempdir().unwrap();
    let manifest = std::fs::read_to_string(baked.join("snake-ridges.json")).unwrap();
    for f in std::fs::read_dir(&baked).unwrap() {
        let f = f.unwrap();
        let name = f.file_name().to_string_lossy().into_owned();
        if name.starts_with("snake-ridges.") {
            std::fs::copy(f.path(), dir.path().join(&name)).unwrap();
        }
    }
    let path = dir.path().join("snake-ridges.json");
    DiffractionTable::load(ctx, &path).unwrap();
    // The dispatching loader reads either layout of the default set …
    for (name, layout) in [("snake-ridges", "terms"), ("cd-tracks-fast", "integrated")] {
        let t =
            DiffractionTables::load(ctx, &baked.join(format!("{name}.json")), FresnelTerm::Unity)
                .unwrap();
        assert_eq!((t.name(), t.layout().name()), (name, layout));
        assert_eq!(
            t.layout(),
            DiffractionLayout::of(t.record(), &path).unwrap()
        );
    }
    // … the terms loader refuses an integrated table and points to it …
    let err = DiffractionTable::load(ctx, &baked.join("cd-tracks-fast.json"))
        .err()
        .expect("an integrated table is not a terms table");
    assert!(
        err.to_string().contains("\"integrated\", not \"terms\"")
            && err.to_string().contains("DiffractionTables::load"),
        "{err}"
    );
    // … a manifest that says "integrated" without the integrated record is refused by both,
    // and an unknown layout is named in the error.
    for (layout, expected) in [
        ("integrated", "without its `integrated` record"),
        ("spectral", "layout `spectral`"),
    ] {
        std::fs::write(
            &path,
            manifest.replacen(
                "\"layout\": \"terms\"",
                &format!("\"layout\": \"{layout}\""),
                1,
            ),
        )
        .unwrap();
        let err = DiffractionTables::load(ctx, &path, FresnelTerm::Unity)
            .err()
            .expect("a bad layout");
        assert!(err.to_string().contains(expected), "{err}");
        let err = DiffractionTable::load(ctx, &path)
            .err()
            .expect("a bad layout");
        assert!(err.to_string().contains(expected), "{err}");
    }
    // A changed terms file fails its checksum.
    std::fs::write(&path, &manifest).unwrap();
    let exr = dir.path().join("snake-ridges.terms.exr");
    let mut bytes = std::fs::read(&exr).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0x55;
    std::fs::write(&exr, bytes).unwrap();
    let err = DiffractionTable::load(ctx, &path)
        .err()
        .expect("bad checksum");
    assert!(err.to_string().contains("SHA-256"), "{err}");
}

/// Hue (degrees), saturation and value of an sRGB pixel.
fn hsv(p: &[u8]) -> (f64, f64, f64) {
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

/// Saturated pixels (s > 0.5, v > 0.15) and how many 30° hue sectors they fill.
fn colourfulness(pixels: &[u8]) -> (usize, usize) {
    let mut sectors = [0usize; 12];
    let mut count = 0;
    for p in pixels.chunks_exact(4) {
        let (h, s, v) = hsv(p);
        if s > 0.5 && v > 0.15 {
            count += 1;
            sectors[(h / 30.0) as usize % 12] += 1;
        }
    }
    (count, sectors.iter().filter(|&&n| n >= 2).count())
}

#[test]
fn scenes_show_rainbows_and_are_deterministic() {
    let ctx = ctx();
    for scene in DiffractionScene::ALL {
        let table = tables(scene.default_table());
        let mut options = DiffractionSceneOptions::new(scene);
        options.width = 100;
        options.height = 75;
        let a = render_diffraction_scene(ctx, table, &options).unwrap();
        let b = render_diffraction_scene(ctx, table, &options).unwrap();
        assert!(a.pixels == b.pixels, "{}: not deterministic", scene.name());
        // Written for inspection (also when an assertion below fails).
        let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
            .join(format!("diffraction-{}.png", scene.name()));
        a.write_png(&out).unwrap();
        eprintln!("wrote {}", out.display());
        let (count, sectors) = colourfulness(&a.pixels);
        eprintln!(
            "{}: {count} saturated pixels over {sectors} hue sectors of 30° ({:.2} s)",
            scene.name(),
            a.gpu_seconds
        );
        assert!(count >= 40, "{}: {count} saturated pixels", scene.name());
        assert!(sectors >= 5, "{}: hues in {sectors} sectors", scene.name());
        // Without the light and the environment samples only the specular order remains:
        // no rainbow.
        options.light.intensity = 0.0;
        options.env_samples = Some(0);
        let plain = render_diffraction_scene(ctx, table, &options).unwrap();
        let (count, sectors) = colourfulness(&plain.pixels);
        eprintln!(
            "{} without diffracted lights: {count} saturated pixels, {sectors} sectors",
            scene.name()
        );
        assert!(sectors < 5, "{}: {sectors} sectors", scene.name());
    }
}

#[test]
fn scene_settings_are_checked() {
    let ctx = ctx();
    let table = tables("cd-tracks");
    let mut options = DiffractionSceneOptions::new(DiffractionScene::CdDisc);
    options.width = 0;
    assert!(render_diffraction_scene(ctx, table, &options).is_err());
    let mut options = DiffractionSceneOptions::new(DiffractionScene::CdDisc);
    options.exposure_ev = f32::NAN;
    assert!(render_diffraction_scene(ctx, table, &options).is_err());
    let mut options = DiffractionSceneOptions::new(DiffractionScene::CdDisc);
    options.env_samples = Some(99);
    assert!(render_diffraction_scene(ctx, table, &options).is_err());
    let mut options = DiffractionSceneOptions::new(DiffractionScene::CdDisc);
    options.technique.wavelength_step_nm = Some(0.0);
    assert!(render_diffraction_scene(ctx, table, &options).is_err());
    options.technique.wavelength_step_nm = Some(f64::NAN);
    assert!(render_diffraction_scene(ctx, table, &options).is_err());
    let mut options = DiffractionSceneOptions::new(DiffractionScene::CdDisc);
    options.environment = Some("/nonexistent/env.exr".into());
    assert!(render_diffraction_scene(ctx, table, &options).is_err());
    assert!("disc".parse::<DiffractionScene>().is_err());
    assert_eq!(
        "CD-Disc".parse::<DiffractionScene>().unwrap(),
        DiffractionScene::CdDisc
    );
}

/// On llvmpipe (lavapipe), a terms-layout scene whose per-pixel loops would run past the
/// driver's 65,535-iteration cap (which silently cuts them short) is refused with the way
/// out; the integrated table of the same surface renders, and so does the default step. On
/// other adapters the fine step renders. The environment as four samples (each a full
/// `diffraction_colour`): the lobes' sum fits the cap at 5 nm (about 20,000 iterations).
#[test]
fn scenes_beyond_llvmpipes_loop_cap_are_refused_there() {
    let ctx = ctx();
    let mut options = DiffractionSceneOptions::new(DiffractionScene::CdDisc);
    (options.width, options.height) = (16, 12);
    options.env_samples = Some(DEFAULT_ENV_SAMPLES);
    let default_step = render_diffraction_scene(ctx, tables("cd-tracks"), &options);
    assert!(default_step.is_ok(), "{:?}", default_step.err());
    options.technique.wavelength_step_nm = Some(5.0);
    let fine = render_diffraction_scene(ctx, tables("cd-tracks"), &options);
    if ctx.info.name.contains("llvmpipe") {
        let error = fine.expect_err("refused on llvmpipe");
        // The way out names the parameters; the CLI spells them as its flags.
        if let nacre_runtime::Error::Refused { message, .. } = &error {
            let params = message.params();
            assert!(
                params.contains(&nacre_format::Param::WavelengthStep),
                "{params:?}"
            );
        } else {
            panic!("{error:?}");
        }
        let message = error.to_string();
        for needle in ["65535", "wavelength_step", "integrated"] {
            assert!(message.contains(needle), "{needle}: {message}");
        }
        options.technique.wavelength_step_nm = None;
        assert!(render_diffraction_scene(ctx, tables("cd-tracks-fast"), &options).is_ok());
    } else {
        assert!(fine.is_ok(), "{}: {:?}", ctx.info.name, fine.err());
    }
}

/// Linear value of an 8-bit sRGB-encoded channel (IEC 61966-2-1).
fn srgb_to_linear(c: u8) -> f64 {
    let c = f64::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Mean and largest |a − b| over the pixels' linear RGB channels.
fn linear_difference(a: &[u8], b: &[u8]) -> (f64, f64) {
    assert_eq!(a.len(), b.len());
    let (mut sum, mut max, mut n) = (0.0, 0.0f64, 0usize);
    for (p, q) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        for c in 0..3 {
            let d = (srgb_to_linear(p[c]) - srgb_to_linear(q[c])).abs();
            sum += d;
            max = max.max(d);
            n += 1;
        }
    }
    (sum / n as f64, max)
}

/// The fast path against the reference: `cd-disc` at 100 × 75 from `cd-tracks-fast` (layout
/// "integrated", summed over the table's 5 nm grid at bake time) and from `cd-tracks`
/// (layout "terms", the same surface) at the scene's default 10 nm step. Measured on Mesa
/// lavapipe (llvmpipe 15, x86-64): mean linear |Δ| 3.4 · 10⁻³ (largest 0.23, at a few pixels
/// on the rainbow's edges), 1 · 10⁻⁵ for the specular order alone; bound [`MEAN_BOUND`].
/// Both weight each wavelength by Stam's (λ₀/λ)² (λ₀ = 555 nm): the terms table's lights in
/// the shader, the integrated table in its bake (`k_squared_reference_nm`). Before the
/// integrated table had the weight the mean was 7.6 · 10⁻³ (largest 0.38; bound 1.2 · 10⁻²),
/// and before either had it 3.9 · 10⁻³.
/// Both show the rainbow; without the lights neither does. Both diffract the environment's
/// [`DEFAULT_ENV_SAMPLES`] brightest texels (an integrated table has no lobes to integrate
/// it with).
const MEAN_BOUND: f64 = 5e-3;

#[test]
fn fast_table_renders_the_cd_disc_like_the_terms_table() {
    let ctx = ctx();
    let mut options = DiffractionSceneOptions::new(DiffractionScene::CdDisc);
    options.width = 100;
    options.height = 75;
    options.env_samples = Some(DEFAULT_ENV_SAMPLES);
    // The integrated layout point-samples the BRDF per pixel: so does the terms table here
    // (its footprint filter off), so that the two compare the same picture.
    options.technique.filter_radius = None;
    let fast = render_diffraction_scene(ctx, tables("cd-tracks-fast"), &options).unwrap();
    let reference = render_diffraction_scene(ctx, tables("cd-tracks"), &options).unwrap();
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    fast.write_png(&dir.join("diffraction-cd-disc-fast.png"))
        .unwrap();
    let (mean, max) = linear_difference(&fast.pixels, &reference.pixels);
    eprintln!(
        "cd-disc, integrated vs terms (10 nm): mean |Δ| {mean:.2e}, max {max:.3} (linear); render passes {:.2} s (integrated), {:.2} s (terms)",
        fast.gpu_seconds, reference.gpu_seconds
    );
    assert!(mean <= MEAN_BOUND, "mean |Δ| {mean} > {MEAN_BOUND}");
    for (what, image) in [("integrated", &fast), ("terms", &reference)] {
        let (count, sectors) = colourfulness(&image.pixels);
        eprintln!("{what}: {count} saturated pixels over {sectors} hue sectors of 30°");
        assert!(count >= 40, "{what}: {count} saturated pixels");
        assert!(sectors >= 5, "{what}: hues in {sectors} sectors");
    }
    options.light.intensity = 0.0;
    options.env_samples = Some(0);
    let plain = render_diffraction_scene(ctx, tables("cd-tracks-fast"), &options).unwrap();
    let plain_terms = render_diffraction_scene(ctx, tables("cd-tracks"), &options).unwrap();
    let (specular_mean, _) = linear_difference(&plain.pixels, &plain_terms.pixels);
    let (count, sectors) = colourfulness(&plain.pixels);
    eprintln!(
        "integrated without diffracted lights: {count} saturated pixels, {sectors} sectors; mean |Δ| {specular_mean:.1e} against terms"
    );
    assert!(sectors < 5, "integrated: {sectors} sectors");
    assert!(
        specular_mean <= 1e-4,
        "specular order: mean |Δ| {specular_mean}"
    );
}

/// An integrated table holds its F² in its uniform: a scene whose Fresnel factor differs
/// from the one it was loaded with (the snake's keratin against the CD's F² = 1) is refused.
#[test]
fn integrated_table_with_another_fresnel_is_refused() {
    let ctx = ctx();
    let mut options = DiffractionSceneOptions::new(DiffractionScene::SnakeSkin);
    options.width = 8;
    options.height = 6;
    let err =
        render_diffraction_scene(ctx, tables("cd-tracks-fast"), &options).expect_err("another F²");
    assert!(err.to_string().contains("Fresnel"), "{err}");
}
