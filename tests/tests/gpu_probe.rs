//! GPU = CPU: every technique's `film_colour`, rendered by the probe pass into a float
//! target on whatever adapter wgpu finds (Mesa's lavapipe in CI), against the CPU methods
//! of `nacre color` (`lut:`, `fourier:M`, `samples:N`) at the same points.
//!
//! A missing adapter fails these tests: they never skip.

use nacre_bake::commands::color::{Method, Quantity};
use nacre_format::Manifest;
use nacre_format::film_lut::FilmLut;
use nacre_format::materials;
use nacre_optics::fourier::Harmonics;
use nacre_optics::{C64, Material};
use nacre_runtime::bindings::{SpectralSetup, TechniqueBinding, TechniqueOptions};
use nacre_runtime::probe::run_probe;
use nacre_runtime::{FilmInput, TableSet, Technique};
use std::sync::Arc;

#[path = "../../crates/runtime/tests/support/mod.rs"]
mod support;
use support::ctx;

mod probe_support;
use probe_support::{Lcg, cpu_colours, input, manifest, max_diff, random_points};

#[test]
fn film_lut_matches_the_cpu_lookup() {
    let ctx = ctx();
    for name in ["film-dielectric", "soap-film", "film-gold"] {
        let path = manifest(name);
        let tables = TableSet::load(ctx, &path).unwrap();
        let m = Manifest::read(&path).unwrap();
        let axes = m.film_lut().cloned().unwrap();
        let refl = m.load_table(&path, "reflectance").unwrap().unwrap();
        let trans = m.load_table(&path, "transmittance").unwrap();
        let binding = TechniqueBinding::new(
            ctx,
            &tables,
            Technique::Lut,
            &TechniqueOptions::default(),
            &tables.colorimeter().unwrap(),
        )
        .unwrap();
        let mut rng = Lcg(7);
        let mut points = Vec::new();
        for _ in 0..3000 {
            let c = rng.next();
            let d = axes.thickness_min_nm
                + rng.next() * (axes.thickness_max_nm - axes.thickness_min_nm);
            let n = axes.ior_min + rng.next() * (axes.ior_max - axes.ior_min);
            points.push((c, d, n));
        }
        // Texel centres and the domain's edges too.
        points.push((1.0, 0.0, axes.ior_min));
        points.push((0.0, axes.thickness_max_nm, axes.ior_max));
        let inputs: Vec<FilmInput> = points
            .iter()
            .map(|&(c, d, n)| input(c, d, n, 0.0, axes.ambient_index, C64::new(1.5, 0.0)))
            .collect();
        let gpu = run_probe(ctx, &binding, &inputs).unwrap();
        let cpu_r: Vec<[f64; 3]> = points
            .iter()
            .map(|&(c, d, n)| FilmLut::lookup(&axes, &refl, c, d, n))
            .collect();
        let gpu_r: Vec<[f32; 3]> = gpu.iter().map(|o| o.reflectance).collect();
        let (worst, at) = max_diff(&cpu_r, &gpu_r);
        eprintln!("{name} reflectance: max |GPU − CPU| = {worst:.2e}");
        assert!(worst <= 2e-3, "{name}: {worst:e} at {:?}", points[at]);
        if let Some(trans) = trans {
            let cpu_t: Vec<[f64; 3]> = points
                .iter()
                .map(|&(c, d, n)| FilmLut::lookup(&axes, &trans, c, d, n))
                .collect();
            let gpu_t: Vec<[f32; 3]> = gpu.iter().map(|o| o.transmittance).collect();
            let (worst, at) = max_diff(&cpu_t, &gpu_t);
            eprintln!("{name} transmittance: max |GPU − CPU| = {worst:.2e}");
            assert!(worst <= 2e-3, "{name} T: {worst:e} at {:?}", points[at]);
        }
    }
}

#[test]
fn film_fourier_matches_the_cpu_series() {
    let ctx = ctx();
    let path = manifest("fourier-srgb");
    let tables = TableSet::load(ctx, &path).unwrap();
    let colorimeter = tables.colorimeter().unwrap();
    let table = Arc::new(Manifest::read(&path).unwrap().load_fourier(&path).unwrap());
    // A free film (base 1.0) has the largest |ρ| of the dielectric bases: the most harmonics.
    let bases = [
        C64::new(1.5, 0.0),
        C64::new(2.2, 0.0),
        C64::new(1.0, 0.0),
        C64::new(0.27, 2.9),
        C64::new(1.2, 1.5),
    ];
    // 0: automatic harmonics, the runtime's default (`TechniqueOptions::default().harmonics`).
    for (harmonics, sigma) in [
        (1u32, 0.0),
        (2, 0.0),
        (3, 0.0),
        (3, 40.0),
        (0, 0.0),
        (0, 40.0),
    ] {
        let options = TechniqueOptions {
            harmonics,
            ..Default::default()
        };
        let binding =
            TechniqueBinding::new(ctx, &tables, Technique::Fourier, &options, &colorimeter)
                .unwrap();
        let h = if harmonics == 0 {
            Harmonics::Auto
        } else {
            Harmonics::Fixed(harmonics as usize)
        };
        let method = Method::Fourier(h, sigma, Some(table.clone()));
        for base in bases {
            let points = random_points(11 + harmonics as u64, 400, 10_000.0);
            let inputs: Vec<FilmInput> = points
                .iter()
                .map(|&(c, d, n)| input(c, d, n, sigma, 1.0, base))
                .collect();
            let gpu = run_probe(ctx, &binding, &inputs).unwrap();
            let material = Material::constant("base", base).unwrap();
            let cpu = cpu_colours(
                &method,
                &material,
                &points,
                Quantity::Reflectance,
                &colorimeter,
            );
            let gpu_r: Vec<[f32; 3]> = gpu.iter().map(|o| o.reflectance).collect();
            let (worst, at) = max_diff(&cpu, &gpu_r);
            eprintln!(
                "fourier M={harmonics} σ={sigma} base {base}: R max |GPU − CPU| = {worst:.2e}"
            );
            assert!(
                worst <= 1e-4,
                "M={harmonics} base {base}: {worst:e} at {:?}: CPU {:?} GPU {:?}",
                points[at],
                cpu[at],
                gpu_r[at]
            );
            if base.im == 0.0 {
                let cpu = cpu_colours(
                    &method,
                    &material,
                    &points,
                    Quantity::Transmittance,
                    &colorimeter,
                );
                let gpu_t: Vec<[f32; 3]> = gpu.iter().map(|o| o.transmittance).collect();
                let (worst, at) = max_diff(&cpu, &gpu_t);
                eprintln!(
                    "fourier M={harmonics} σ={sigma} base {base}: T max |GPU − CPU| = {worst:.2e}"
                );
                assert!(
                    worst <= 1e-4,
                    "T M={harmonics} base {base}: {worst:e} at {:?}",
                    points[at]
                );
            }
        }
    }
}

#[test]
fn film_spectral_matches_samples_n() {
    let ctx = ctx();
    let tables = TableSet::load(ctx, &manifest("fourier-srgb")).unwrap();
    let colorimeter = tables.colorimeter().unwrap();
    let gold = materials::resolve("au", "test", None).unwrap();
    let glass = Material::constant("1.5", C64::new(1.5, 0.0)).unwrap();
    for (samples, base) in [(30usize, glass.clone()), (30, gold), (5, glass)] {
        let options = TechniqueOptions {
            spectral: SpectralSetup {
                samples,
                base: base.clone(),
            },
            ..Default::default()
        };
        let binding =
            TechniqueBinding::new(ctx, &tables, Technique::Spectral, &options, &colorimeter)
                .unwrap();
        let points = random_points(23, 600, 2000.0);
        let inputs: Vec<FilmInput> = points
            .iter()
            .map(|&(c, d, n)| input(c, d, n, 0.0, 1.0, C64::new(1.5, 0.0)))
            .collect();
        let gpu = run_probe(ctx, &binding, &inputs).unwrap();
        for quantity in [Quantity::Reflectance, Quantity::Transmittance] {
            let cpu = cpu_colours(
                &Method::Samples(samples),
                &base,
                &points,
                quantity,
                &colorimeter,
            );
            let g: Vec<[f32; 3]> = gpu
                .iter()
                .map(|o| match quantity {
                    Quantity::Reflectance => o.reflectance,
                    Quantity::Transmittance => o.transmittance,
                })
                .collect();
            let (worst, at) = max_diff(&cpu, &g);
            eprintln!(
                "spectral N={samples} base {}: {quantity:?} max |GPU − CPU| = {worst:.2e}",
                base.name()
            );
            assert!(
                worst <= 1e-4,
                "N={samples} {quantity:?}: {worst:e} at {:?}",
                points[at]
            );
        }
    }
}

/// `film_stack` against its CPU twin (`StackEvaluation`) over random pixels (incidence,
/// top-film thickness, variations s_R, s_G, s_B, the films on map channels R, G, B in
/// turn) for stacks of 1 to 8 films: dielectric, absorbing metal films (10 nm silver,
/// chromium), dispersive materials, and an ambient denser than its films (total internal
/// reflection and evanescent films), with the rule ladder and with a fixed rule: max |GPU − CPU| ≤ 1e-4 per channel.
#[test]
fn film_stack_matches_its_cpu_twin() {
    use nacre_optics::few_wavelengths::StackEvaluation;
    use nacre_runtime::bindings::StackSetup;
    let ctx = ctx();
    let tables = TableSet::load(ctx, &manifest("fourier-srgb")).unwrap();
    let colorimeter = tables.colorimeter().unwrap();
    let cases = probe_support::stack_cases();
    for (name, stack, samples) in cases {
        let films = stack.layers().len();
        let relative_nm: Vec<f64> = (0..films).map(|j| 15.0 * j as f64).collect();
        // One thickness-map channel per film (R, G, B in turn).
        let channels: Vec<usize> = (0..films).map(|j| j % 3).collect();
        let eval = StackEvaluation::new(&colorimeter, &stack, &relative_nm, samples)
            .unwrap()
            .with_channels(&channels)
            .unwrap();
        let options = TechniqueOptions {
            stack: StackSetup {
                stack,
                relative_nm,
                channels,
                samples,
            },
            ..Default::default()
        };
        let binding =
            TechniqueBinding::new(ctx, &tables, Technique::Stack, &options, &colorimeter).unwrap();
        let mut rng = Lcg(41);
        let pixels: Vec<(f64, f64, [f64; 3])> = (0..400)
            .map(|_| {
                let (c, d) = (rng.next(), 500.0 * rng.next());
                (c, d, [(); 3].map(|_| 2.0 * rng.next() - 1.0))
            })
            .collect();
        let inputs: Vec<FilmInput> = pixels
            .iter()
            .map(|&(c, d, s)| FilmInput {
                variation: s[0] as f32,
                variation_g: s[1] as f32,
                variation_b: s[2] as f32,
                ..input(c, d, 1.5, 0.0, 1.0, C64::new(1.5, 0.0))
            })
            .collect();
        let gpu = run_probe(ctx, &binding, &inputs).unwrap();
        // The CPU twin at the f32 inputs the GPU saw.
        let cpu: Vec<([f64; 3], [f64; 3])> = inputs
            .iter()
            .map(|i| {
                eval.colour(
                    f64::from(i.cos_theta_i),
                    f64::from(i.thickness_nm),
                    [i.variation, i.variation_g, i.variation_b].map(f64::from),
                )
            })
            .collect();
        for (quantity, pick) in [("R", 0usize), ("T", 1)] {
            let c: Vec<[f64; 3]> = cpu
                .iter()
                .map(|x| if pick == 0 { x.0 } else { x.1 })
                .collect();
            let g: Vec<[f32; 3]> = gpu
                .iter()
                .map(|o| {
                    if pick == 0 {
                        o.reflectance
                    } else {
                        o.transmittance
                    }
                })
                .collect();
            let (worst, at) = max_diff(&c, &g);
            eprintln!("stack {name}: {quantity} max |GPU − CPU| = {worst:.2e}");
            assert!(
                worst <= 1e-4,
                "{name} {quantity}: {worst:e} at {:?}",
                pixels[at]
            );
        }
    }
}

/// `film_glass` against its CPU twin (`StackEvaluation` with an incoherent slab) over random
/// pixels (incidence, top-film thickness, variations): a spectacle lens with a four-film AR
/// coating on the front face and a three-film one on the back (dispersive, the slab N-BK7
/// 2 mm), a window with a silver low-e
/// coating on its back face, an absorbing slab first with a back coating, a slab in water
/// with a titania front film, and a stack without a slab (then `film_glass` is `film_stack`):
/// max |GPU − CPU| ≤ 1e-4 per channel, in reflection and transmission.
#[test]
fn film_glass_matches_its_cpu_twin() {
    use nacre_format::materials;
    use nacre_optics::few_wavelengths::StackEvaluation;
    use nacre_optics::{Layer, Stack};
    use nacre_runtime::bindings::StackSetup;
    let ctx = ctx();
    let tables = TableSet::load(ctx, &manifest("fourier-srgb")).unwrap();
    let colorimeter = tables.colorimeter().unwrap();
    let constant =
        |n: f64, k: f64| Material::constant(format!("{n}+{k}i"), C64::new(n, k)).unwrap();
    let bundled = |name: &str| materials::resolve(name, "test", None).unwrap();
    let layer = |material: Material, thickness_nm: f64| Layer {
        material,
        thickness_nm,
    };
    let ar = |reversed: bool| {
        let mut films = vec![
            layer(bundled("mgf2"), 95.0),
            layer(bundled("tio2"), 110.0),
            layer(bundled("mgf2"), 30.0),
            layer(bundled("tio2"), 12.0),
        ];
        if reversed {
            // The back face: the first three films mirrored (eight films in all).
            films.truncate(3);
            films.reverse();
        }
        films
    };
    let slab = |films: Vec<Layer>, at: usize, ambient: Material, base: Material| {
        let flags = (1..=films.len()).map(|j| j == at).collect();
        Stack::new(ambient, films, base)
            .unwrap()
            .with_incoherent(flags)
            .unwrap()
    };
    let spectacles = {
        let mut films = ar(false);
        films.push(layer(bundled("bk7"), 2e6));
        films.extend(ar(true));
        slab(films, 5, bundled("air"), bundled("air"))
    };
    let cases: Vec<(&str, Stack, Option<usize>)> = vec![
        ("spectacle lens, AR on both faces", spectacles, None),
        (
            "window, silver low-e on the back",
            slab(
                vec![
                    layer(constant(1.45, 0.0), 80.0),
                    layer(bundled("bk7"), 4e6),
                    layer(constant(2.0, 0.0), 35.0),
                    layer(bundled("ag"), 10.0),
                    layer(constant(2.0, 0.0), 35.0),
                ],
                2,
                constant(1.0, 0.0),
                constant(1.0, 0.0),
            ),
            None,
        ),
        (
            "absorbing slab first, fixed 24 nodes",
            slab(
                vec![
                    layer(constant(1.6, 2e-6), 1.5e6),
                    layer(constant(2.3, 0.0), 70.0),
                ],
                1,
                constant(1.0, 0.0),
                constant(1.0, 0.0),
            ),
            Some(24),
        ),
        (
            "slab in water",
            slab(
                vec![
                    layer(bundled("tio2"), 60.0),
                    layer(constant(1.52, 0.0), 3e6),
                ],
                2,
                bundled("water"),
                bundled("water"),
            ),
            None,
        ),
        (
            "no slab",
            Stack::new(
                constant(1.0, 0.0),
                vec![layer(constant(1.38, 0.0), 100.0), layer(bundled("cr"), 8.0)],
                bundled("bk7"),
            )
            .unwrap(),
            None,
        ),
    ];
    for (name, stack, samples) in cases {
        let films = stack.layers().len();
        let relative_nm: Vec<f64> = (0..films).map(|j| 10.0 * j as f64).collect();
        let eval = StackEvaluation::new(&colorimeter, &stack, &relative_nm, samples).unwrap();
        let options = TechniqueOptions {
            stack: StackSetup {
                stack,
                relative_nm,
                channels: Vec::new(),
                samples,
            },
            ..Default::default()
        };
        let binding =
            TechniqueBinding::new(ctx, &tables, Technique::Glass, &options, &colorimeter).unwrap();
        let mut rng = Lcg(31);
        let inputs: Vec<FilmInput> = (0..400)
            .map(|_| {
                let (c, d, s) = (rng.next(), 300.0 * rng.next(), 2.0 * rng.next() - 1.0);
                FilmInput {
                    variation: s as f32,
                    ..input(c, d, 1.5, 0.0, 1.0, C64::new(1.5, 0.0))
                }
            })
            .collect();
        let gpu = run_probe(ctx, &binding, &inputs).unwrap();
        let cpu: Vec<([f64; 3], [f64; 3])> = inputs
            .iter()
            .map(|i| {
                eval.colour(
                    f64::from(i.cos_theta_i),
                    f64::from(i.thickness_nm),
                    [f64::from(i.variation), 0.0, 0.0],
                )
            })
            .collect();
        for (quantity, pick) in [("R", 0usize), ("T", 1)] {
            let c: Vec<[f64; 3]> = cpu
                .iter()
                .map(|x| if pick == 0 { x.0 } else { x.1 })
                .collect();
            let g: Vec<[f32; 3]> = gpu
                .iter()
                .map(|o| {
                    if pick == 0 {
                        o.reflectance
                    } else {
                        o.transmittance
                    }
                })
                .collect();
            let (worst, at) = max_diff(&c, &g);
            eprintln!("glass {name}: {quantity} max |GPU − CPU| = {worst:.2e}");
            assert!(
                worst <= 1e-4,
                "{name} {quantity}: {worst:e} at {:?}",
                inputs[at]
            );
        }
    }
}

/// Every technique returns finite colours for every input a host engine might send: NaN,
/// ±∞, negative, zero and huge values in every field, grazing and total internal reflection.
#[test]
fn every_technique_is_finite_for_hostile_inputs() {
    let ctx = ctx();
    let mut tables = TableSet::load(ctx, &manifest("soap-film")).unwrap();
    tables.add(ctx, &manifest("fourier-srgb")).unwrap();
    let colorimeter = tables.colorimeter().unwrap();
    let values = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        -1.0,
        0.0,
        1e-30,
        0.5,
        1.0,
        1.33,
        2.5,
        1e30,
        f32::MAX,
    ];
    let mut rng = Lcg(99);
    let mut pick = || values[(rng.next() * values.len() as f64) as usize];
    let mut inputs = Vec::new();
    for _ in 0..6000 {
        inputs.push(FilmInput {
            cos_theta_i: pick(),
            thickness_nm: pick() * 500.0,
            film_ior: pick(),
            sigma_thickness_nm: pick() * 50.0,
            ambient_ior: pick(),
            base_ior: [pick(), pick(), pick()],
            base_kappa: [pick(), pick(), pick()],
            ..Default::default()
        });
    }
    // Total internal reflection and evanescent films, exactly grazing.
    inputs.push(input(0.0, 300.0, 1.0, 0.0, 1.5, C64::new(1.0, 0.0)));
    inputs.push(input(0.1, 300.0, 1.2, 0.0, 1.5, C64::new(1.33, 0.0)));
    for technique in Technique::ALL {
        for harmonics in [0u32, 3] {
            let options = TechniqueOptions {
                harmonics,
                ..Default::default()
            };
            let binding =
                TechniqueBinding::new(ctx, &tables, technique, &options, &colorimeter).unwrap();
            let out = run_probe(ctx, &binding, &inputs).unwrap();
            for (i, o) in out.iter().enumerate() {
                assert!(
                    o.reflectance
                        .iter()
                        .chain(&o.transmittance)
                        .all(|v| v.is_finite()),
                    "{} (M = {harmonics}): {o:?} for {:?}",
                    technique.name(),
                    inputs[i]
                );
            }
        }
    }
}

/// A source the device rejects is reported at the module and line the error lies in, not at
/// the composed source's line.
#[test]
fn shader_errors_name_the_module_and_line() {
    use nacre_runtime::shaders::{self, Part};
    // Line 4 of "broken.wgsl" lacks an operand.
    let broken = "// broken.wgsl\n// import: common, <technique>\nfn broken() -> f32 {\n    return 1.0 +;\n}\n";
    let composed = shaders::resolve(
        &[Part::Source {
            label: "broken.wgsl",
            source: broken,
        }],
        Some(Part::Module("film_lut")),
    )
    .unwrap();
    let error = shaders::create_module(ctx(), "broken", &composed).expect_err("rejected");
    let message = error.to_string();
    assert!(message.contains("broken.wgsl:4:"), "{message}");
    assert!(message.contains("lines 1–"), "{message}");
}
