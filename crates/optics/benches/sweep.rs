//! Throughput of the stack solver (issue target: ≥ 2×10⁷ single-film (angle, wavelength,
//! thickness) evaluations per second per core, both polarisations, f64).
//!
//! And the path from a spectrum call to the multilayer kernel (`spectrum_call`).
//!
//! Run: `cargo bench -p nacre-optics --bench sweep`. Figures are in BENCHMARKS.md.

mod common;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nacre_optics::{C64, Layer, Material, Power, SpectrumSweep, Stack};
use std::hint::black_box;

fn benches(c: &mut Criterion) {
    let angles = common::angles_deg();
    let wavelengths = common::wavelengths_5nm();
    let thicknesses = common::thicknesses_nm();
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();

    // Single lossless film (soap-like 1.33 on glass 1.5 in air): angle × wavelength × thickness.
    let film = common::soap_film();
    let n = (angles.len() * wavelengths.len() * thicknesses.len()) as u64;
    let mut g = c.benchmark_group("single-film");
    g.throughput(Throughput::Elements(n));
    g.sample_size(20);
    g.bench_function("90x81x100 one thread", |b| {
        one_thread.install(|| {
            b.iter(|| {
                black_box(
                    film.sweep_thickness(1, &angles, &wavelengths, &thicknesses)
                        .unwrap(),
                )
            })
        })
    });
    g.bench_function("90x81x100 all threads", |b| {
        b.iter(|| {
            black_box(
                film.sweep_thickness(1, &angles, &wavelengths, &thicknesses)
                    .unwrap(),
            )
        })
    });
    // Absorbing film on a metal: the complex exponential path.
    let metal = common::absorbing_film_on_metal();
    g.bench_function("absorbing film on metal 90x81x100 one thread", |b| {
        one_thread.install(|| {
            b.iter(|| {
                black_box(
                    metal
                        .sweep_thickness(1, &angles, &wavelengths, &thicknesses)
                        .unwrap(),
                )
            })
        })
    });
    g.finish();

    // Five dispersive layers on BK7 over angle × wavelength at 1 nm.
    let wavelengths_1nm = common::wavelengths_1nm();
    let five = common::five_layer_dispersive();
    let mut g = c.benchmark_group("five-layer-dispersive");
    g.throughput(Throughput::Elements(
        (angles.len() * wavelengths_1nm.len()) as u64,
    ));
    g.sample_size(20);
    g.bench_function("90x401 one thread", |b| {
        one_thread.install(|| b.iter(|| black_box(five.sweep(&angles, &wavelengths_1nm).unwrap())))
    });
    g.bench_function("90x401 all threads", |b| {
        b.iter(|| black_box(five.sweep(&angles, &wavelengths_1nm).unwrap()))
    });
    g.finish();

    // The same with no repeated medium (the second TiO₂ replaced by silicon).
    let distinct = common::five_distinct_dispersive();
    let mut g = c.benchmark_group("five-distinct-dispersive");
    g.throughput(Throughput::Elements(
        (angles.len() * wavelengths_1nm.len()) as u64,
    ));
    g.sample_size(20);
    g.bench_function("90x401 one thread", |b| {
        one_thread
            .install(|| b.iter(|| black_box(distinct.sweep(&angles, &wavelengths_1nm).unwrap())))
    });
    g.finish();
}

/// Film indices, top first (distinct, so that the kernel computes every medium).
const FILM_INDICES: [f64; 8] = [2.35, 1.38, 2.1, 1.46, 1.9, 1.6, 2.2, 1.7];

fn constant(n: f64) -> Material {
    Material::constant(format!("{n}"), C64::new(n, 0.0)).unwrap()
}

/// Thicknesses of `films` films, top first, nm.
fn thicknesses(films: usize, shift_nm: f64) -> Vec<f64> {
    (0..films)
        .map(|j| 60.0 + 17.0 * j as f64 + shift_nm)
        .collect()
}

/// `films` constant-index films on glass 1.52 in air.
fn film_stack(films: usize) -> Stack {
    let layers = FILM_INDICES[..films]
        .iter()
        .zip(thicknesses(films, 0.0))
        .map(|(&n, d)| Layer {
            material: constant(n),
            thickness_nm: d,
        })
        .collect();
    Stack::new(constant(1.0), layers, constant(1.52)).unwrap()
}

/// 10⁵ wavelengths, 380–780 nm.
fn wavelengths() -> Vec<f64> {
    (0..100_000).map(|i| 380.0 + 0.004 * i as f64).collect()
}

/// The path from a spectrum call to the multilayer kernel (issue 33, part 6: "every call as
/// fast as the kernel"): one angle × 10⁵ wavelengths of 1, 5 and 8 constant-index films on
/// one thread, three ways in one run —
///
/// * `kernel`: the kernel alone, [`SpectrumSweep::powers_into`] on a sweep prepared
///   beforehand into a buffer allocated beforehand (the throughput the others are held to);
/// * `stack sweep`: [`Stack::sweep`], the whole call of `nacre spectrum` and
///   `nacre.spectrum` (angles and indices resolved, the kernel's arrays laid out, a fresh
///   output vector);
/// * `fitting loop`: one step of a fit, [`SpectrumSweep::set_thicknesses_nm`] with new
///   thicknesses and [`SpectrumSweep::powers_into`] into the fit's buffer.
///
/// Target: `stack sweep` and `fitting loop` at ≥ 50 % of `kernel`'s throughput.
///
/// Run: `cargo bench -p nacre-optics --bench sweep -- spectrum-call`. Figures are in BENCHMARKS.md.
fn spectrum_call(c: &mut Criterion) {
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let angles = [30.0];
    let wl = wavelengths();
    let mut g = c.benchmark_group("spectrum-call");
    g.throughput(Throughput::Elements(wl.len() as u64));
    g.sample_size(20);
    for films in [1, 5, 8] {
        let stack = film_stack(films);
        let mut sweep = SpectrumSweep::new(&stack, &angles, &wl).unwrap();
        let mut out = vec![Power::default(); sweep.len()];
        g.bench_function(format!("{films} films 1x100000 kernel"), |b| {
            one_thread.install(|| b.iter(|| sweep.powers_into(black_box(&mut out)).unwrap()))
        });
        g.bench_function(format!("{films} films 1x100000 stack sweep"), |b| {
            one_thread.install(|| b.iter(|| black_box(stack.sweep(&angles, &wl).unwrap())))
        });
        let steps = [thicknesses(films, 0.0), thicknesses(films, 1.5)];
        let mut k = 0;
        g.bench_function(format!("{films} films 1x100000 fitting loop"), |b| {
            one_thread.install(|| {
                b.iter(|| {
                    k ^= 1;
                    sweep.set_thicknesses_nm(&steps[k]).unwrap();
                    sweep.powers_into(black_box(&mut out)).unwrap()
                })
            })
        });
    }
    g.finish();
}

criterion_group!(sweep, benches, spectrum_call);
criterion_main!(sweep);
